//! Names and ids with control characters built in code are refused by the machine and the
//! axes writer. (The hostile files of `fixtures/bad/io/` go through every reader, these
//! included, in the workspace's `tests/hostile_io.rs`.)

use std::path::{Path, PathBuf};

use kerf_kinematics::{AxesFile, Machine};

fn dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/bad/io")
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
