//! `kerf.axes/1` output: content, round trip, atomic writing.

mod common;

use common::{fixture, polar};
use kerf_kinematics::{
    solve_paths, AxesFile, KinematicsError, PathInput, PathOptions, Pose, AXES_FORMAT,
};
use nalgebra::Point3;

fn solved() -> AxesFile {
    let machine = fixture("fork_head.json");
    let a: Vec<Pose> = (0..5)
        .map(|k| Pose {
            position: Point3::new(k as f64 * 3.0, 0.0, 10.0),
            axis: polar(0.1 * k as f64, 0.5),
        })
        .collect();
    let b = vec![Pose {
        position: Point3::new(0.0, 1.0, 2.0),
        axis: polar(0.0, 0.0),
    }];
    let inputs = [
        PathInput {
            id: "first",
            poses: &a,
            curve: None,
        },
        PathInput {
            id: "second \"quoted\"",
            poses: &b,
            curve: None,
        },
    ];
    let paths = solve_paths(&machine, &inputs, &PathOptions::default()).unwrap();
    assert!(paths[0].inserted > 0, "the tilt change inserts points");
    AxesFile::new(&machine, &paths)
}

#[test]
fn writes_the_format_and_reads_back_identically() {
    let file = solved();
    let text = file.to_json().unwrap();
    assert!(text.starts_with("{\n  \"format\": \"kerf.axes/1\",\n  \"machine\": \"fork head B/C, 210 mm pivot\",\n  \"axes\": [\"X\", \"Y\", \"Z\", \"B\", \"C\"],\n  \"paths\": ["), "{text}");
    let value: serde_json::Value = serde_json::from_str(&text).unwrap();
    assert_eq!(value["format"], AXES_FORMAT, "format");
    let p = &value["paths"][0];
    assert_eq!(p["id"], "first", "id");
    assert_eq!(
        p["positions"].as_array().unwrap().len(),
        p["poses"].as_array().unwrap().len(),
        "one position per pose"
    );
    assert_eq!(
        p["inserted"].as_u64().unwrap() as usize,
        file.paths[0].inserted,
        "inserted"
    );
    assert_eq!(
        p["positions"].as_array().unwrap().len(),
        5 + file.paths[0].inserted,
        "cutting + inserted"
    );
    assert_eq!(value["paths"][1]["id"], "second \"quoted\"", "escaped id");
    let back = AxesFile::from_str(&text).unwrap();
    assert_eq!(
        back, file,
        "exact round trip (shortest round-trip number formatting)"
    );
}

#[test]
fn writes_atomically_and_replaces() {
    let dir = tempfile::tempdir().unwrap();
    let dest = dir.path().join("out.axes.json");
    std::fs::write(&dest, "old").unwrap();
    let file = solved();
    file.write(&dest).unwrap();
    let text = std::fs::read_to_string(&dest).unwrap();
    assert_eq!(AxesFile::from_str(&text).unwrap(), file, "replaced");
    let names: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(names.len(), 1, "no temporary file left: {names:?}");

    // An invalid document writes nothing and leaves the old file.
    let mut bad = file.clone();
    bad.paths[0].positions[1][3] = f64::NAN;
    let err = bad.write(&dest).unwrap_err();
    assert_eq!(
        err.to_string(),
        "paths[0].positions[1][3]: must be finite (got NaN)"
    );
    assert_eq!(std::fs::read_to_string(&dest).unwrap(), text, "untouched");

    // A missing directory is an I/O error naming the file.
    let err = file
        .write(dir.path().join("no/such/dir/out.json"))
        .unwrap_err();
    assert!(
        matches!(
            &err,
            KinematicsError::Io {
                action: "write",
                ..
            }
        ),
        "{err:?}"
    );
    // The operating system's error is kept as the source, not only its message.
    let io = std::iter::successors(Some(&err as &dyn std::error::Error), |e| e.source())
        .find_map(|e| e.downcast_ref::<std::io::Error>());
    assert_eq!(
        io.map(std::io::Error::kind),
        Some(std::io::ErrorKind::NotFound),
        "{err:?}"
    );
}

#[test]
fn validation_errors() {
    let mut file = solved();
    file.paths[0].poses.pop();
    assert!(
        file.validate()
            .unwrap_err()
            .to_string()
            .starts_with("paths[0].positions: "),
        "count"
    );
    let mut file = solved();
    file.paths[1].inserted = 5;
    assert_eq!(
        file.validate().unwrap_err().to_string(),
        "paths[1].inserted: 5 inserted of 1 points"
    );
    let mut file = solved();
    file.axes[3] = "Q".into();
    assert!(
        file.validate()
            .unwrap_err()
            .to_string()
            .starts_with("axes: "),
        "names"
    );
    let err = AxesFile::from_str("{\"format\": \"kerf.toolpath/1\"}").unwrap_err();
    assert_eq!(
        err.to_string(),
        "format: unknown format \"kerf.toolpath/1\" (this reader reads \"kerf.axes/1\")"
    );
}

#[test]
fn extra_optional_keys_are_accepted_as_the_contract_allows() {
    let text = r#"{"format": "kerf.axes/1", "machine": "m", "axes": ["X", "Y", "Z", "A", "C"],
        "comment": "written by another tool",
        "paths": [{"id": "p", "positions": [[0, 0, 0, 0, 0], [1, 0, 0, 0, 0]],
                   "poses": [[0, 0, 0, 0, 0, 1], [1, 0, 0, 0, 0, 1]], "inserted": 0,
                   "feed": 3000}]}"#;
    let file = kerf_kinematics::AxesFile::from_str(text).expect("extra keys are fine");
    assert_eq!(file.paths[0].positions.len(), 2, "read the path");
}
