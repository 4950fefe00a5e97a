//! The hostile I/O fixtures of `fixtures/bad/io/` (listed in `expect.tsv`) through the public
//! machine and axes readers.

use std::path::{Path, PathBuf};

use kerf_kinematics::{AxesFile, Machine};

fn dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/bad/io")
}

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
    assert!(rows.len() >= 3, "{reader}: fixtures listed");
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
                assert!(!e.contains('\n'), "one line: {e:?}");
            }
        }
    }
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
fn a_machine_built_in_code_with_a_newline_in_its_name_is_refused() {
    let good = Machine::read(dir().join("machine_bom.json")).expect("valid");
    let e = Machine::try_new(
        "laser\nM30",
        good.kinematics.clone(),
        good.limits,
        good.max_velocity,
        good.max_acceleration,
    )
    .map(drop)
    .expect_err("refused");
    assert!(
        e.to_string()
            .starts_with("name: contains the control character U+000A"),
        "{e}"
    );
}

#[test]
fn an_axes_file_with_a_hostile_id_is_not_written() {
    let mut axes = AxesFile::read(dir().join("axes_bom.json")).expect("valid");
    axes.paths[0].id = "hole\nG0 X1400\nM30".to_owned();
    let dir = tempfile::tempdir().expect("temp dir");
    let dest = dir.path().join("out.axes.json");
    let e = axes.write(&dest).expect_err("refused");
    assert!(
        e.to_string()
            .contains("paths[0].id: contains the control character"),
        "{e}"
    );
    assert!(!dest.exists(), "nothing written");
}
