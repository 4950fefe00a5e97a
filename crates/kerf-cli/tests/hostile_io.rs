//! The binary against hostile and unlucky I/O: option values out of range, an output that is
//! an input, special files and links as outputs, endless and oversized inputs, hostile ids,
//! a wrong `point_count`, and a set-points CSV far larger than the memory it may use.

use std::fs;
use std::os::unix::fs::{FileTypeExt, PermissionsExt};
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
mod common;
use common::{fixture, kerf};

fn bad(name: &str) -> PathBuf {
    fixture("bad/io").join(name)
}

fn run(c: &mut Command) -> (i32, String, String) {
    let o: Output = c.output().expect("kerf runs");
    (
        o.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&o.stdout).into_owned(),
        String::from_utf8_lossy(&o.stderr).into_owned(),
    )
}

fn ok(c: &mut Command) -> String {
    let (code, out, err) = run(c);
    assert_eq!(code, 0, "{c:?}: {err}");
    out
}

const MACHINE: &str = "machines/ac_head.json";

#[test]
fn option_values_out_of_range_are_usage_errors_naming_the_option() {
    let circle = fixture("circle.json");
    let axes = bad("axes_bom.json");
    let m = fixture(MACHINE);
    let cases: Vec<(Vec<&std::ffi::OsStr>, &str)> = vec![
        (
            vec![
                "discretize".as_ref(),
                circle.as_os_str(),
                "-t".as_ref(),
                "0".as_ref(),
            ],
            "--tolerance",
        ),
        (
            vec![
                "discretize".as_ref(),
                circle.as_os_str(),
                "-t".as_ref(),
                "nan".as_ref(),
            ],
            "--tolerance",
        ),
        (
            vec![
                "discretize".as_ref(),
                circle.as_os_str(),
                "--tolerance=-1".as_ref(),
            ],
            "--tolerance",
        ),
        (
            vec![
                "discretize".as_ref(),
                circle.as_os_str(),
                "--band".as_ref(),
                "1".as_ref(),
            ],
            "--band",
        ),
        (
            vec![
                "discretize".as_ref(),
                circle.as_os_str(),
                "--max-turn".as_ref(),
                "0".as_ref(),
            ],
            "--max-turn",
        ),
        (
            vec![
                "interpolate".as_ref(),
                axes.as_os_str(),
                "-m".as_ref(),
                m.as_os_str(),
                "-f".as_ref(),
                "1000".as_ref(),
                "--cycle".as_ref(),
                "1e9".as_ref(),
            ],
            "--cycle",
        ),
        (
            vec![
                "gcode".as_ref(),
                axes.as_os_str(),
                "-m".as_ref(),
                m.as_os_str(),
                "-f".as_ref(),
                "0".as_ref(),
                "-o".as_ref(),
                "-".as_ref(),
            ],
            "--feed",
        ),
        (
            vec![
                "run".as_ref(),
                circle.as_os_str(),
                "-m".as_ref(),
                m.as_os_str(),
                "--retract=-5".as_ref(),
            ],
            "--retract",
        ),
        (
            vec![
                "post".as_ref(),
                axes.as_os_str(),
                "-m".as_ref(),
                m.as_os_str(),
                "--max-rotary-step".as_ref(),
                "inf".as_ref(),
            ],
            "--max-rotary-step",
        ),
    ];
    for (args, option) in cases {
        let (code, _, err) = run(kerf().args(&args));
        assert_eq!(code, 2, "{args:?}: usage error, got {code}: {err}");
        assert!(err.contains(option), "{args:?}: names {option}: {err}");
    }
    let (_, _, err) = run(kerf().args([
        "interpolate".as_ref(),
        axes.as_os_str(),
        "-m".as_ref(),
        m.as_os_str(),
        "-f".as_ref(),
        "1000".as_ref(),
        "--cycle".as_ref(),
        "1e9".as_ref(),
    ]));
    assert!(
        err.contains("between 1e-5 s and 0.1 s"),
        "the range in readable numbers: {err}"
    );
}

/// Issue 35: `--clearance 2e4` was accepted (exit 0) and left every traverse unchecked, while
/// other values out of range were usage errors. Every numeric option has an upper end: above
/// it (and below the lower end, and not finite) the value is a usage error, exit 2, naming the
/// option, the value and the range, before any input is read. The ranges are
/// `kerf_pipeline::ranges` and `crate::guard` of the binary.
#[test]
fn every_numeric_option_has_an_upper_end_and_says_its_range() {
    let circle = fixture("circle.json");
    let axes = bad("axes_bom.json");
    let m = fixture(MACHINE);
    let step = fixture("step/composite_mm.step");
    let dir = tempfile::tempdir().expect("temp dir");
    let out = dir.path().join("out");
    let c = circle.to_str().expect("UTF-8");
    let a = axes.to_str().expect("UTF-8");
    let mm = m.to_str().expect("UTF-8");
    let st = step.to_str().expect("UTF-8");
    let o = out.to_str().expect("UTF-8");
    let whole: Vec<&str> = vec!["run", c, "-m", mm, "--out", o, "-q"];
    let whole_step: Vec<&str> = vec!["run", st, "-m", mm, "--out", o, "-q"];
    let disc: Vec<&str> = vec!["discretize", c, "-o", o, "-q"];
    let post: Vec<&str> = vec!["post", a, "-m", mm, "-o", o, "-q"];
    let gcode: Vec<&str> = vec!["gcode", a, "-m", mm, "-f", "1000", "-o", o, "-q"];
    let interp: Vec<&str> = vec!["interpolate", a, "-m", mm, "-f", "1000", "-q"];
    let import: Vec<&str> = vec!["import", st, "-o", o, "-q"];
    // (command, option=value, the range the message states)
    let cases: Vec<(&Vec<&str>, &str, &str)> = vec![
        (
            &whole,
            "--clearance=2e4",
            "must be between 0 mm and 1000 mm (got 2e4)",
        ),
        (
            &whole,
            "--clearance=1e300",
            "must be between 0 mm and 1000 mm (got 1e300)",
        ),
        (
            &gcode,
            "--clearance=2e4",
            "must be between 0 mm and 1000 mm (got 2e4)",
        ),
        (
            &whole,
            "--retract=1e5",
            "must be between 0 mm and 1000 mm (got 1e5)",
        ),
        (
            &interp,
            "--retract=1e5",
            "must be between 0 mm and 1000 mm (got 1e5)",
        ),
        (
            &whole,
            "--max-wall=1000",
            "must be between 0 mm and 100 mm (got 1000",
        ),
        (
            &whole,
            "--tolerance=1e300",
            "must be > 0 mm and <= 10 mm (got 1e300)",
        ),
        (
            &disc,
            "--tolerance=11",
            "must be > 0 mm and <= 10 mm (got 11)",
        ),
        (
            &whole,
            "--feed=2e6",
            "must be > 0 mm/min and <= 1e6 mm/min (got 2e6",
        ),
        (
            &whole,
            "--cycle=1",
            "must be between 1e-5 s and 0.1 s (got 1",
        ),
        (
            &whole,
            "--blend-tolerance=-1",
            "must be > 0 mm and <= 10 mm (got -1)",
        ),
        (
            &gcode,
            "--blend-tolerance=1e300",
            "must be > 0 mm and <= 10 mm (got 1e300)",
        ),
        (
            &gcode,
            "--blend-tolerance=nan",
            "must be > 0 mm and <= 10 mm (got NaN)",
        ),
        (
            &whole,
            "--max-segment-length=1e300",
            "must be > 0 mm and <= 1e4 mm (got 1e300)",
        ),
        (
            &disc,
            "--min-segment-length=1e5",
            "must be > 0 mm and <= 1e4 mm (got 1e5)",
        ),
        (
            &whole,
            "--linearization-tolerance=100",
            "must be > 0 mm and <= 10 mm (got 100)",
        ),
        (
            &post,
            "--linearization-tolerance=100",
            "must be > 0 mm and <= 10 mm (got 100)",
        ),
        (
            &gcode,
            "--fit-tolerance=100",
            "must be > 0 mm and <= 10 mm (got 100)",
        ),
        (
            &interp,
            "--chord-tolerance=100",
            "must be > 0 mm and <= 10 mm (got 100)",
        ),
        (
            &whole,
            "--lead-in=2,2000",
            "RADIUS: must be between 0 mm and 1000 mm (got 2000)",
        ),
        (
            &whole,
            "--lead-out=1e9,1",
            "OVERCUT: must be between 0 mm and 1000 mm (got 1e9)",
        ),
        // The normals stage needs a step below a half turn: 180 used to pass the command line
        // and fail the stage (exit 1).
        (
            &whole,
            "--max-normal-step=180",
            "must be > 0 degrees and < 180 degrees (got 180)",
        ),
        (
            &whole,
            "--max-rotary-step=1000",
            "must be > 0 degrees and <= 180 degrees (got 1000)",
        ),
        (
            &post,
            "--pole-tolerance=10",
            "must be > 0 degrees and <= 5 degrees (got 10)",
        ),
        (
            &post,
            "--tilt-tolerance=45",
            "must be between 0 degrees and 10 degrees (got 45)",
        ),
        (
            &whole,
            "--tilt-tolerance=-1",
            "must be between 0 degrees and 10 degrees (got -1)",
        ),
        // STEP options were checked by the reader (exit 1); now by the command line, for
        // `import` and for `run` on a STEP file alike.
        (
            &import,
            "--close-gaps=-1",
            "must be between 0 mm and 10 mm (got -1)",
        ),
        (
            &import,
            "--close-gaps=inf",
            "must be between 0 mm and 10 mm (got inf)",
        ),
        (
            &import,
            "--close-gaps=11",
            "must be between 0 mm and 10 mm (got 11)",
        ),
        (
            &import,
            "--face-tolerance=nan",
            "must be > 0 mm and <= 10 mm (got NaN)",
        ),
        (
            &import,
            "--face-tolerance=20",
            "must be > 0 mm and <= 10 mm (got 20)",
        ),
        (
            &whole_step,
            "--face-tolerance=-0.1",
            "must be > 0 mm and <= 10 mm (got -0.1)",
        ),
        (
            &whole_step,
            "--close-gaps=1e9",
            "must be between 0 mm and 10 mm (got 1e9)",
        ),
    ];
    for (command, arg, range) in cases {
        let (option, value) = arg.split_once('=').expect("OPTION=VALUE");
        let (code, _, err) = run(kerf().args(command).arg(arg));
        assert_eq!(
            code, 2,
            "{command:?} {arg}: a usage error, got {code}: {err}"
        );
        assert!(
            err.contains(&format!("invalid value '{value}' for '{option} ")),
            "{arg}: names the option and the value: {err}"
        );
        assert!(
            err.contains(range),
            "{arg}: states the range {range:?}: {err}"
        );
        assert!(!out.exists(), "{arg}: nothing written");
    }
    // `--faces` that is not an entity number is a usage error too.
    let (code, _, err) = run(kerf().args(&import).args(["--edges", "--faces", "abc"]));
    assert_eq!(code, 2, "--faces abc: {err}");
    assert!(err.contains("--faces: \"abc\""), "{err}");
    // The ends of the ranges are accepted.
    for arg in [
        "--tolerance=10",
        "--blend-tolerance=10",
        "--max-wall=100",
        "--clearance=0",
        "--max-normal-step=179",
    ] {
        let (code, _, err) = run(kerf().args(&whole).arg(arg));
        assert_eq!(code, 0, "{arg}: {err}");
    }
}

#[test]
fn an_output_that_is_an_input_is_refused_and_the_input_kept() {
    let dir = tempfile::tempdir().expect("temp dir");
    let curves = dir.path().join("part.json");
    fs::copy(fixture("circle.json"), &curves).expect("copy");
    let before = fs::read(&curves).expect("read");
    let link = dir.path().join("link.json");
    std::os::unix::fs::symlink(&curves, &link).expect("symlink");
    let dotted = dir.path().join(".").join("part.json");
    for out in [&curves, &link, &dotted] {
        let (code, _, err) = run(kerf().arg("discretize").arg(&curves).arg("-o").arg(out));
        assert_eq!(code, 2, "{}: {err}", out.display());
        assert!(err.contains("would destroy the input"), "{err}");
    }
    // The toolpath as the output of post, the machine as the program of gcode.
    let tp = dir.path().join("part.toolpath.json");
    fs::copy(bad("toolpath_bom.json"), &tp).expect("copy");
    let machine = dir.path().join("machine.json");
    fs::copy(fixture(MACHINE), &machine).expect("copy");
    let (code, _, err) = run(kerf()
        .arg("post")
        .arg(&tp)
        .arg("-m")
        .arg(&machine)
        .arg("-o")
        .arg(&tp));
    assert_eq!(code, 2, "post: {err}");
    let (code, _, err) = run(kerf()
        .arg("gcode")
        .arg(&tp)
        .args(["-m"])
        .arg(&machine)
        .args(["-f", "1000", "-o"])
        .arg(&machine));
    assert_eq!(code, 2, "gcode: {err}");
    // kerf run into the directory that holds its input under one of its output names.
    let inside = dir.path().join("toolpath.json");
    fs::copy(fixture("circle.json"), &inside).expect("copy");
    let (code, _, err) = run(kerf()
        .arg("run")
        .arg(&inside)
        .arg("-m")
        .arg(&machine)
        .arg("--out")
        .arg(dir.path()));
    assert_eq!(code, 2, "run: {err}");
    assert_eq!(fs::read(&curves).expect("read"), before, "input untouched");
    assert_eq!(fs::read(&inside).expect("read"), before, "input untouched");
}

#[test]
fn special_files_and_links_are_written_through_not_replaced() {
    let circle = fixture("circle.json");
    // /dev/null stays a device (the test runs as root in CI, where a rename would succeed).
    ok(kerf()
        .arg("discretize")
        .arg(&circle)
        .args(["-q", "-o", "/dev/null"]));
    assert!(
        fs::symlink_metadata("/dev/null")
            .expect("stat")
            .file_type()
            .is_char_device(),
        "/dev/null is still a device"
    );
    let dir = tempfile::tempdir().expect("temp dir");
    // A FIFO: the program comes out of the pipe.
    let fifo = dir.path().join("program.fifo");
    assert!(
        Command::new("mkfifo")
            .arg(&fifo)
            .status()
            .expect("mkfifo")
            .success(),
        "mkfifo"
    );
    let reader = {
        let fifo = fifo.clone();
        std::thread::spawn(move || fs::read_to_string(fifo).expect("read FIFO"))
    };
    ok(kerf()
        .arg("gcode")
        .arg(bad("axes_bom.json"))
        .arg("-m")
        .arg(fixture(MACHINE))
        .args(["-f", "1000", "-q", "-o"])
        .arg(&fifo));
    let program = reader.join().expect("reader");
    assert!(
        program.contains("G1"),
        "the program went through the FIFO: {program}"
    );
    assert!(
        fs::symlink_metadata(&fifo)
            .expect("stat")
            .file_type()
            .is_fifo(),
        "still a FIFO"
    );
    // A symlink: its target is written, the link stays.
    let target = dir.path().join("real.toolpath.json");
    fs::write(&target, "old").expect("write");
    let link = dir.path().join("out.toolpath.json");
    std::os::unix::fs::symlink(&target, &link).expect("symlink");
    ok(kerf()
        .arg("discretize")
        .arg(&circle)
        .arg("-q")
        .arg("-o")
        .arg(&link));
    assert!(
        fs::symlink_metadata(&link)
            .expect("stat")
            .file_type()
            .is_symlink(),
        "still a link"
    );
    assert!(
        fs::read_to_string(&target)
            .expect("read")
            .contains("kerf.toolpath/1"),
        "target written"
    );
}

#[test]
fn every_output_gets_the_mode_of_any_created_file() {
    let dir = tempfile::tempdir().expect("temp dir");
    let reference = dir.path().join("reference");
    fs::File::create(&reference).expect("create");
    let mode = |p: &Path| fs::metadata(p).expect("stat").permissions().mode() & 0o777;
    let nc = dir.path().join("p.nc");
    let csv = dir.path().join("p.csv");
    let tp = dir.path().join("p.toolpath.json");
    ok(kerf()
        .arg("gcode")
        .arg(bad("axes_bom.json"))
        .arg("-m")
        .arg(fixture(MACHINE))
        .args(["-f", "1000", "-q", "-o"])
        .arg(&nc));
    ok(kerf()
        .arg("interpolate")
        .arg(bad("axes_bom.json"))
        .arg("-m")
        .arg(fixture(MACHINE))
        .args(["-f", "1000", "-q", "--csv"])
        .arg(&csv));
    ok(kerf()
        .arg("discretize")
        .arg(fixture("circle.json"))
        .arg("-q")
        .arg("-o")
        .arg(&tp));
    // With normals, then `kerf post` (the axes writer) and `kerf run` (every file of its
    // output directory, written all or nothing).
    let normals = dir.path().join("dome.toolpath.json");
    ok(kerf()
        .arg("discretize")
        .arg(fixture("dome.json"))
        .args(["--normals", "-q", "-o"])
        .arg(&normals));
    let axes = dir.path().join("dome.axes.json");
    ok(kerf()
        .arg("post")
        .arg(&normals)
        .arg("-m")
        .arg(fixture(MACHINE))
        .args(["-q", "-o"])
        .arg(&axes));
    let run = dir.path().join("run");
    ok(kerf()
        .arg("run")
        .arg(fixture("dome.json"))
        .arg("--machine")
        .arg(fixture(MACHINE))
        .args(["-q", "--out"])
        .arg(&run));
    let mut written = vec![nc, csv, tp, normals, axes];
    for entry in fs::read_dir(&run).expect("run output") {
        written.push(entry.expect("entry").path());
    }
    assert!(written.len() >= 9, "kerf run wrote its files: {written:?}");
    for p in &written {
        assert_eq!(mode(p), mode(&reference), "{}", p.display());
    }
}

#[test]
fn endless_and_oversized_inputs_end_in_an_error() {
    let (code, _, err) = run(kerf().args(["validate", "/dev/zero"]));
    assert_eq!(code, 1, "{err}");
    assert!(
        err.contains("/dev/zero") && err.contains("larger than 1 GiB"),
        "{err}"
    );
    let dir = tempfile::tempdir().expect("temp dir");
    let huge = dir.path().join("huge.json");
    fs::File::create(&huge)
        .expect("create")
        .set_len((1 << 30) + 1)
        .expect("sparse file");
    let (code, _, err) = run(kerf().arg("validate").arg(&huge));
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("larger than 1 GiB"), "{err}");
}

#[test]
fn hostile_ids_and_names_never_reach_a_program() {
    let dir = tempfile::tempdir().expect("temp dir");
    let m = fixture(MACHINE);
    for dialect in ["generic", "sinumerik"] {
        let out = dir.path().join(format!("{dialect}.nc"));
        for (input, machine) in [
            (bad("axes_id_newline_gcode.json"), m.clone()),
            (bad("toolpath_id_newline_gcode.json"), m.clone()),
            (bad("axes_bom.json"), bad("machine_name_newline_gcode.json")),
        ] {
            let (code, _, err) = run(kerf()
                .arg("gcode")
                .arg(&input)
                .arg("-m")
                .arg(&machine)
                .args(["-f", "1000", "--dialect", dialect, "-o"])
                .arg(&out));
            assert_eq!(code, 1, "{}: {err}", input.display());
            assert!(
                err.contains("contains the control character U+000A"),
                "{err}"
            );
            assert_eq!(
                err.lines().count(),
                1,
                "one line, nothing smuggled: {err:?}"
            );
            assert!(!out.exists(), "no program written");
        }
    }
    let out = dir.path().join("out");
    let (code, _, err) = run(kerf()
        .arg("run")
        .arg(bad("curves_id_newline_gcode.json"))
        .arg("-m")
        .arg(&m)
        .arg("--out")
        .arg(&out));
    assert_eq!(code, 1, "{err}");
    assert!(!out.exists(), "no output directory");
}

#[test]
fn check_refuses_the_point_count_that_post_refuses() {
    let tp = bad("toolpath_point_count.json");
    let (code, _, err) = run(kerf()
        .arg("post")
        .arg(&tp)
        .arg("-m")
        .arg(fixture(MACHINE))
        .arg("-o")
        .arg("-"));
    assert_eq!(code, 1, "post: {err}");
    assert!(
        err.contains("point_count is 3 but there are 2 points"),
        "{err}"
    );
    let (code, out, err) = run(kerf().arg("check").arg(bad("curves_bom.json")).arg(&tp));
    assert_eq!(code, 1, "check: {out}{err}");
    assert!(
        format!("{out}{err}").contains("point_count is 3 but there are 2 points"),
        "{out}{err}"
    );
}

#[test]
fn a_long_set_points_csv_streams_in_bounded_memory() {
    // A 100 mm line at 5 mm/min: 1200 s of motion, 1.2 million cycles, a CSV of about 51 MB.
    // Built in memory (rows, then text) it needed about twice that; streamed, the whole
    // process runs in a 40 MB address space (`ulimit -v`), less than the file it writes.
    let dir = tempfile::tempdir().expect("temp dir");
    let tp = dir.path().join("line.toolpath.json");
    fs::write(
        &tp,
        r#"{"format": "kerf.toolpath/1", "units": "mm", "tolerance": 0.01, "paths": [
            {"id": "line", "max_chord_error": 0, "params": [0, 1],
             "points": [[0, 0, 0, 0, 0, 1], [100, 0, 0, 0, 0, 1]]}]}"#,
    )
    .expect("write");
    let csv = dir.path().join("line.csv");
    let script = format!(
        "ulimit -v 40000 && exec {:?} interpolate {:?} -m {:?} --feed 5 --csv {:?} -q",
        env!("CARGO_BIN_EXE_kerf"),
        tp,
        fixture(MACHINE),
        csv
    );
    let (code, _, err) = run(Command::new("bash").arg("-c").arg(&script));
    assert_eq!(code, 0, "{script}: {err}");
    let size = fs::metadata(&csv).expect("csv").len();
    assert!(
        size > 45_000_000,
        "the CSV is larger than the whole address space allowed ({size} bytes)"
    );
    let text = fs::read_to_string(&csv).expect("read");
    let rows = text.lines().count() - 1;
    assert!(
        rows >= 1_200_000,
        "one row per 1 ms cycle over 1200 s: {rows}"
    );
    assert!(text.starts_with("t,X,Y,Z,A,C\n"), "header");
}

/// Issue 35: a beam code of 5 MB was accepted and would be written into every cut. Each line
/// of a process code is at most 255 characters (LinuxCNC's longest line): the machine is
/// refused with the key, the count and the limit, and the message does not quote the line.
#[test]
fn a_beam_code_of_megabytes_is_refused_by_name() {
    let dir = tempfile::tempdir().expect("temp dir");
    let mut machine: serde_json::Value =
        serde_json::from_str(&fs::read_to_string(fixture(MACHINE)).expect("read")).expect("JSON");
    let huge = format!("M64 P{}", "0".repeat(5_000_000 - 5));
    machine["process"] = serde_json::json!({ "beam_on": [huge] });
    let m = dir.path().join("machine.json");
    fs::write(&m, machine.to_string()).expect("write");
    let out = dir.path().join("out");
    let (code, _, err) = run(kerf()
        .arg("run")
        .arg(fixture("circle.json"))
        .arg("-m")
        .arg(&m)
        .arg("--out")
        .arg(&out)
        .arg("-q"));
    assert_eq!(code, 1, "{err}");
    assert!(
        err.contains("process.beam_on[0]: 5000000 characters, at most 255"),
        "{}",
        &err[..err.len().min(500)]
    );
    assert!(
        err.len() < 1000,
        "the line is not quoted: {} bytes",
        err.len()
    );
    assert!(!out.exists(), "nothing written");
}

#[test]
fn the_library_names_its_options_and_the_command_line_its_flags() {
    // A job over its point budget: the pipeline's message names the option
    // (`max_total_points`), the command line adds the flags that change it.
    let out = tempfile::tempdir().expect("temporary directory");
    let (code, _, err) = run(kerf()
        .arg("run")
        .arg(fixture("circle.json"))
        .arg("-m")
        .arg(fixture(MACHINE))
        .arg("--max-total-points")
        .arg("4")
        .arg("--out")
        .arg(out.path().join("o")));
    assert_eq!(code, 1, "{err}");
    assert!(
        err.contains("raise the limit (max_total_points)")
            && err.contains("[options: a larger --tolerance, or a larger point limit (--max-total-points of kerf run)]"),
        "{err}"
    );
    assert!(!out.path().join("o").exists(), "nothing written");
}
