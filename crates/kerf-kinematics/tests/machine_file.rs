//! `kerf.machine/1`: the fixtures, and every error path with its message.

mod common;

use std::sync::Arc;

use common::fixture;
use kerf_kinematics::{kinematics_types, AcHead, Axis, KinematicsError, Machine, Range};
use serde_json::{json, Value};

fn ac_head() -> Value {
    json!({
        "format": "kerf.machine/1",
        "name": "m",
        "kinematics": { "type": "ac-head", "r_a": 180.0, "r_c": 95.0 },
        "limits": { "X": [-1500, 1500], "Y": [-800, 800], "Z": [-100, 600], "A": [-135, 135], "C": null },
        "max_velocity": { "X": 60000, "Y": 60000, "Z": 30000, "A": 36000, "C": 36000 },
        "max_acceleration": { "X": 10000, "Y": 10000, "Z": 8000, "A": 20000, "C": 20000 }
    })
}

/// The message of reading `doc` after `edit`.
fn error_after(edit: impl FnOnce(&mut Value)) -> String {
    let mut doc = ac_head();
    edit(&mut doc);
    let err = Machine::from_value(&doc).expect_err("must be refused");
    assert!(matches!(err, KinematicsError::Document { .. }), "{err:?}");
    err.to_string()
}

#[test]
fn every_fixture_reads_and_writes_back() {
    for (file, kind, tilt) in [
        ("ac_head.json", "ac-head", "A"),
        ("fork_head.json", "fork-head", "B"),
        ("table_table.json", "table-table", "A"),
        ("head_table.json", "head-table", "B"),
        ("xyzac_trt.json", "table-table", "A"),
        ("bc_head_5axiskins.json", "fork-head", "B"),
    ] {
        let m = fixture(file);
        assert_eq!(m.kinematics.type_name(), kind, "{file}");
        assert_eq!(m.axis_name(Axis::Tilt), tilt, "{file}");
        let again = Machine::from_str(&m.to_json())
            .unwrap_or_else(|e| panic!("{file}: {e}\n{}", m.to_json()));
        assert_eq!(again.to_json(), m.to_json(), "{file}: round trip");
        assert_eq!(again.limits, m.limits, "{file}");
        assert_eq!(again.max_velocity, m.max_velocity, "{file}");
    }
    assert_eq!(
        kinematics_types(),
        ["ac-head", "fork-head", "table-table", "head-table"],
        "registry"
    );
    let m = fixture("ac_head.json");
    assert_eq!(m.name, "paper-000 laser head", "name");
    assert_eq!(m.limit(Axis::Tilt), Some(Range::new(-135.0, 135.0)), "A");
    assert_eq!(m.limit(Axis::C), None, "C continuous");
}

#[test]
fn format_and_shape_errors() {
    assert_eq!(
        error_after(|d| d["format"] = json!("kerf.machine/2")),
        "format: unknown format \"kerf.machine/2\" (this reader reads \"kerf.machine/1\")"
    );
    assert_eq!(
        error_after(|d| {
            d.as_object_mut().unwrap().remove("format");
        }),
        "format: missing (expected \"kerf.machine/1\")"
    );
    assert_eq!(
        Machine::from_value(&json!([1, 2])).unwrap_err().to_string(),
        "top level: expected an object {\"format\": \"kerf.machine/1\", ...}, found an array"
    );
    assert_eq!(
        error_after(|d| d["name"] = json!(3)),
        "name: expected a string, found a number"
    );
    assert_eq!(
        error_after(|d| d["name"] = json!("  ")),
        "name: must not be empty"
    );
    assert_eq!(
        error_after(|d| d["kinematics"] = json!("ac-head")),
        "kinematics: expected an object, found a string"
    );
    assert_eq!(
        error_after(|d| {
            d.as_object_mut().unwrap().remove("max_acceleration");
        }),
        "max_acceleration: missing"
    );
    // Unknown top-level keys are allowed (comments, later optional keys).
    let mut doc = ac_head();
    doc["comment"] = json!("hand-written");
    assert!(Machine::from_value(&doc).is_ok(), "extra top-level key");
}

#[test]
fn kinematics_errors() {
    assert_eq!(
        error_after(|d| d["kinematics"]["type"] = json!("xyz")),
        "kinematics.type: unknown type \"xyz\" (known: ac-head, fork-head, table-table, head-table)"
    );
    assert_eq!(
        error_after(|d| {
            d["kinematics"].as_object_mut().unwrap().remove("type");
        }),
        "kinematics.type: missing (known: ac-head, fork-head, table-table, head-table)"
    );
    assert_eq!(
        error_after(|d| d["kinematics"]["r_a"] = json!(-1.0)),
        "kinematics.r_a: must be finite and >= 0 (got -1)"
    );
    assert_eq!(
        error_after(|d| d["kinematics"]["r_a"] = json!("180")),
        "kinematics.r_a: expected a number, found a string"
    );
    assert_eq!(
        error_after(|d| {
            d["kinematics"].as_object_mut().unwrap().remove("r_c");
        }),
        "kinematics.r_c: missing (type \"ac-head\" needs it)"
    );
    assert_eq!(
        error_after(|d| d["kinematics"]["r_b"] = json!(1.0)),
        "kinematics.r_b: unknown parameter of type \"ac-head\" (its parameters: r_a, r_c)"
    );
    // Not reachable from JSON (no NaN there), but from code.
    let err = AcHead::try_new(f64::NAN, 95.0).unwrap_err();
    assert_eq!(
        err.to_string(),
        "kinematics.r_a: must be finite and >= 0 (got NaN)"
    );

    let fork = |edit: &dyn Fn(&mut Value)| {
        error_after(|d| {
            d["kinematics"] = json!({ "type": "fork-head", "tilt": "B", "L": 210.0, "d": [0, 0, 0], "tool_lateral": [0, 0] });
            d["limits"]["B"] = d["limits"]["A"].take();
            d["limits"].as_object_mut().unwrap().remove("A");
            for key in ["max_velocity", "max_acceleration"] {
                d[key]["B"] = json!(1000);
                d[key].as_object_mut().unwrap().remove("A");
            }
            edit(d);
        })
    };
    assert_eq!(
        fork(&|d| d["kinematics"]["tilt"] = json!("C")),
        "kinematics.tilt: expected \"A\" or \"B\", found \"C\""
    );
    assert_eq!(
        fork(&|d| d["kinematics"]["d"] = json!([0, 0])),
        "kinematics.d: expected an array of 3 numbers, found [0,0]"
    );
    assert_eq!(
        fork(&|d| d["kinematics"]["L"] = json!(-5)),
        "kinematics.L: must be finite and >= 0 (got -5)"
    );
    // The tilt axis of a B machine is B: an A limit is refused.
    assert_eq!(
        fork(&|d| d["limits"]["A"] = json!(null)),
        "limits.A: not an axis of this machine (its axes are X, Y, Z, B, C)"
    );

    // The optional tilt_sign: +1 or -1, written back only where it is -1.
    assert_eq!(
        fork(&|d| d["kinematics"]["tilt_sign"] = json!(0)),
        "kinematics.tilt_sign: must be +1 or -1 (got 0)"
    );
    assert!(!fixture("fork_head.json").to_json().contains("tilt_sign"));
    assert!(fixture("bc_head_5axiskins.json")
        .to_json()
        .contains("\"tilt_sign\": -1"));
    let head_table = error_after(|d| {
        d["kinematics"] = json!({ "type": "head-table", "L": 180, "c_point": [0, 0, 0], "b_sign": 2, "c_sign": 1 });
    });
    assert_eq!(head_table, "kinematics.b_sign: must be +1 or -1 (got 2)");
    let table = error_after(|d| {
        d["kinematics"] = json!({ "type": "table-table", "rot_point": [0, 0, 0], "y_offset": 0, "z_offset": 0, "tool_offset": 0, "conventional": "yes" });
    });
    assert_eq!(
        table,
        "kinematics.conventional: expected true or false, found \"yes\""
    );
}

#[test]
fn limit_velocity_and_acceleration_errors() {
    assert_eq!(
        error_after(|d| d["limits"]["A"] = json!([10, -10])),
        "limits.A: min 10 > max -10"
    );
    assert_eq!(
        error_after(|d| d["limits"]["A"] = json!([1])),
        "limits.A: expected [min, max] or null (unlimited), found [1]"
    );
    assert_eq!(
        error_after(|d| d["limits"]["A"] = json!([0, "x"])),
        "limits.A[1]: expected a number, found a string"
    );
    assert_eq!(
        error_after(|d| {
            d["limits"].as_object_mut().unwrap().remove("C");
        }),
        "limits.C: missing (give [min, max], or null for an unlimited axis)"
    );
    assert_eq!(
        error_after(|d| d["limits"]["B"] = json!(null)),
        "limits.B: not an axis of this machine (its axes are X, Y, Z, A, C)"
    );
    assert_eq!(
        error_after(|d| d["max_velocity"]["X"] = json!(0)),
        "max_velocity.X: must be finite and > 0 (got 0)"
    );
    assert_eq!(
        error_after(|d| d["max_acceleration"]["C"] = json!(-1)),
        "max_acceleration.C: must be finite and > 0 (got -1)"
    );
    assert_eq!(
        error_after(|d| d["max_velocity"]["Y"] = json!(null)),
        "max_velocity.Y: expected a number, found null"
    );
    let mut m = fixture("ac_head.json");
    m.limits[0] = Some(Range::new(f64::NAN, 1.0));
    assert_eq!(
        m.validate().unwrap_err().to_string(),
        "limits.X[0]: must be finite (got NaN); use null for an unlimited axis"
    );
    let err = Machine::try_new(
        "m",
        Arc::new(AcHead::try_new(1.0, 1.0).unwrap()),
        [None; 5],
        [1.0; 5],
        [f64::INFINITY; 5],
    )
    .unwrap_err();
    assert_eq!(
        err.to_string(),
        "max_acceleration.X: must be finite and > 0 (got inf)"
    );
}

#[test]
fn syntax_and_io_errors() {
    let err =
        Machine::from_str("{\n  \"format\": \"kerf.machine/1\"\n  \"name\": 1\n}").unwrap_err();
    assert!(
        matches!(err, KinematicsError::Syntax { line: 3, .. }),
        "{err:?}"
    );
    let err = Machine::from_str("{\"format\": 1e400}").unwrap_err();
    assert!(err.to_string().contains("number out of range"), "{err}");
    let dir = tempfile::tempdir().unwrap();
    let bad = dir.path().join("bad.json");
    let mut doc = ac_head();
    doc["limits"]["A"] = json!([10, -10]);
    std::fs::write(&bad, doc.to_string()).unwrap();
    let err = Machine::read(&bad).unwrap_err();
    assert_eq!(
        err.to_string(),
        format!("{}: limits.A: min 10 > max -10", bad.display())
    );
    assert!(
        matches!(err.without_file(), KinematicsError::Document { .. }),
        "{err:?}"
    );
    let err = Machine::read("/nonexistent/machine.json").unwrap_err();
    assert!(
        matches!(&err, KinematicsError::Io { action: "read", .. }),
        "{err:?}"
    );
    assert!(
        err.to_string()
            .starts_with("/nonexistent/machine.json: cannot read: "),
        "{err}"
    );
}

#[test]
fn optional_max_jerk_is_read_strictly_and_written_back() {
    // Absent: acceleration-limited.
    let plain = Machine::from_value(&ac_head()).expect("valid");
    assert_eq!(plain.max_jerk, None, "no key, no jerk limit");
    assert!(
        !plain.to_json().contains("max_jerk"),
        "not written when absent"
    );
    let mut doc = ac_head();
    doc["max_jerk"] = json!({ "X": 200000, "Y": 200000, "Z": 150000, "A": 400000, "C": 400000 });
    let m = Machine::from_value(&doc).expect("valid with jerk");
    assert_eq!(
        m.max_jerk,
        Some([200000.0, 200000.0, 150000.0, 400000.0, 400000.0])
    );
    let again = Machine::from_str(&m.to_json()).expect("round trip");
    assert_eq!(again.max_jerk, m.max_jerk, "written back");
    assert_eq!(
        error_after(|d| d["max_jerk"] = json!({ "X": 1, "Y": 1, "Z": 1, "A": 1 })),
        "max_jerk.C: missing"
    );
    assert_eq!(
        error_after(|d| d["max_jerk"] = json!({ "X": 1, "Y": 1, "Z": 1, "A": 1, "C": 0 })),
        "max_jerk.C: must be finite and > 0 (got 0)"
    );
    assert_eq!(
        error_after(|d| d["max_jerk"] = json!({ "X": 1, "Y": 1, "Z": 1, "A": 1, "C": 1, "B": 1 })),
        "max_jerk.B: not an axis of this machine (its axes are X, Y, Z, A, C)"
    );
    assert_eq!(
        error_after(|d| d["max_jerk"] = json!(5)),
        "max_jerk: expected an object with the axes X, Y, Z, A, C, found a number"
    );
    assert!(plain
        .with_max_jerk(Some([1.0, 1.0, f64::NAN, 1.0, 1.0]))
        .is_err());
}

#[test]
fn misspelt_optional_keys_are_warned_about_and_extensions_are_not() {
    // A misspelt optional key is read as absent: the machine below has no jerk limit and
    // default process codes. Each gets a warning naming the key it resembles.
    let mut doc = ac_head();
    doc["max_jerks"] = json!({ "X": 1e6, "Y": 1e6, "Z": 1e6, "A": 1e6, "C": 1e6 });
    doc["Process"] = json!({ "pierce_dwell_s": 0.5 });
    doc["vendor_notes"] = json!("an extension: not a near miss of anything");
    let m = Machine::from_value(&doc).expect("extensions and near misses are allowed");
    assert!(m.max_jerk.is_none(), "read without the misspelt key");
    let shown: Vec<String> = m.warnings.iter().map(ToString::to_string).collect();
    assert_eq!(
        shown,
        [
            "Process: unknown key, did you mean \"process\"?",
            "max_jerks: unknown key, did you mean \"max_jerk\"?",
        ]
    );
    // Next to the real key, a near miss is taken for a deliberate extension.
    doc["max_jerk"] = doc["max_jerks"].clone();
    doc["process"] = json!({});
    let m = Machine::from_value(&doc).expect("valid");
    assert!(m.warnings.is_empty(), "{:?}", m.warnings);
    for file in [
        "ac_head.json",
        "fork_head.json",
        "gantry_ac.json",
        "table_table.json",
        "head_table.json",
    ] {
        assert!(fixture(file).warnings.is_empty(), "{file}");
    }
}
