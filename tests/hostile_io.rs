//! The hostile I/O fixtures of `fixtures/bad/io/` (listed with their expected outcome in
//! `expect.tsv`) through every reader of kerf's documents, one harness for all: the curves and
//! toolpath readers (`kerf-format`), the machine and axes readers (`kerf-kinematics`), the
//! checker's lenient toolpath reader (`kerf-check`) and the motion stage's axes-or-toolpath
//! reader (`kerf-pipeline`); a byte-order mark is accepted by each. Plus inputs above the
//! size limit made at test time (names and ids built in code: `crates/kerf-kinematics/tests/hostile_io.rs`).

use std::path::{Path, PathBuf};

use kerf::check::RawToolpath;
use kerf::format::{curves, toolpath};
use kerf::kinematics::{AxesFile, Machine};
use kerf::pipeline::MotionInput;

fn dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures/bad/io")
}

/// `(file, expected)` rows of `expect.tsv` for `reader`.
fn cases(reader: &str) -> Vec<(PathBuf, String)> {
    let text = std::fs::read_to_string(dir().join("expect.tsv")).expect("expect.tsv");
    text.lines()
        .filter(|l| !l.starts_with('#') && !l.trim().is_empty())
        .map(|l| l.split('\t').collect::<Vec<_>>())
        .filter(|f| f[1] == reader)
        .map(|f| (dir().join(f[0]), f[2].to_owned()))
        .collect()
}

fn run(reader: &str, read: impl Fn(&Path) -> Result<(), String>) {
    let rows = cases(reader);
    assert!(rows.len() >= 4, "{reader}: fixtures listed");
    for (file, expected) in rows {
        match (read(&file), expected.as_str()) {
            (Ok(()), "ok") => {}
            (Ok(()), _) => panic!("{}: read, but expected {expected:?}", file.display()),
            (Err(e), "ok") => panic!("{}: expected to read, got {e}", file.display()),
            (Err(e), _) => {
                assert!(
                    e.contains(&expected),
                    "{}: {e:?} lacks {expected:?}",
                    file.display()
                );
                assert!(
                    e.starts_with(&file.display().to_string()),
                    "the message names the file: {e}"
                );
                assert!(
                    !e.contains('\n'),
                    "one line, no raw control character: {e:?}"
                );
            }
        }
    }
}

#[test]
fn hostile_curves_files() {
    run("curves", |p| {
        curves::load(p).map(drop).map_err(|e| e.to_string())
    });
}

#[test]
fn hostile_toolpath_files() {
    run("toolpath", |p| {
        toolpath::load(p).map(drop).map_err(|e| e.to_string())
    });
}

#[test]
fn the_bom_file_reads_as_the_file_without_it() {
    let with = curves::load(dir().join("curves_bom.json")).expect("BOM file");
    let bytes = std::fs::read(dir().join("curves_bom.json")).expect("read");
    assert_eq!(
        &bytes[..3],
        b"\xEF\xBB\xBF",
        "the fixture starts with a BOM"
    );
    let without = curves::from_reader(&bytes[3..], Path::new(".")).expect("without BOM");
    assert_eq!(with.curves.len(), without.curves.len(), "same curves");
    assert_eq!(with.curves[0].id, without.curves[0].id, "same id");
}

#[test]
fn a_file_above_the_size_limit_is_refused_without_reading_it() {
    let dir = tempfile::tempdir().expect("temp dir");
    let huge = dir.path().join("huge.json");
    // A sparse file: 1 GiB + 1 byte of size, no disk space, no memory.
    let f = std::fs::File::create(&huge).expect("create");
    f.set_len(kerf::io::MAX_INPUT_BYTES + 1).expect("set_len");
    for e in [
        curves::load(&huge)
            .map(drop)
            .expect_err("too large")
            .to_string(),
        toolpath::load(&huge)
            .map(drop)
            .expect_err("too large")
            .to_string(),
    ] {
        assert!(e.contains("larger than 1 GiB"), "{e}");
        assert!(
            e.starts_with(&huge.display().to_string()),
            "names the file: {e}"
        );
    }
}

#[test]
fn a_stream_above_a_limit_stops_there() {
    // The readers take at most MAX_INPUT_BYTES of a stream; the same code with a small limit
    // shows that an endless stream (like /dev/zero) ends in an error, not a hang.
    let e = kerf::io::read_to_end(std::io::repeat(b' '), 1 << 16).expect_err("endless");
    assert_eq!(e.kind(), std::io::ErrorKind::FileTooLarge, "{e}");
}

#[test]
fn hostile_machine_files() {
    run("machine", |p| {
        Machine::read(p).map(drop).map_err(|e| e.to_string())
    });
}

#[test]
fn hostile_axes_files() {
    run("axes", |p| {
        AxesFile::read(p).map(drop).map_err(|e| e.to_string())
    });
}

#[test]
fn every_reader_accepts_a_byte_order_mark() {
    // The four document readers are in `expect.tsv` (`*_bom.json ... ok`); the checker's
    // and the motion stage's readers read the same files.
    let bom = |name: &str| {
        let path = dir().join(name);
        let bytes = std::fs::read(&path).expect("read");
        assert_eq!(&bytes[..3], b"\xEF\xBB\xBF", "{name} starts with a BOM");
        path
    };
    RawToolpath::load(bom("toolpath_bom.json")).expect("the checker reads a BOM toolpath");
    let tp = MotionInput::read(bom("toolpath_bom.json")).expect("motion stage, toolpath");
    assert!(
        matches!(tp, MotionInput::Toolpath(_)),
        "told apart as a toolpath"
    );
    let axes = MotionInput::read(bom("axes_bom.json")).expect("motion stage, axes");
    assert!(matches!(axes, MotionInput::Axes(_)), "told apart as axes");
}
