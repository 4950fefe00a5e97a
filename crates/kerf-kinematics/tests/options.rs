//! Option and input checks of the path solver.

mod common;

use common::{fixture, polar};
use kerf_kinematics::{solve_path, KinematicsError, PathCurve, PathInput, PathOptions, Pose};
use nalgebra::Point3;

fn poses() -> Vec<Pose> {
    (0..3)
        .map(|k| Pose {
            position: Point3::new(k as f64, 0.0, 0.0),
            axis: polar(0.2, 0.0),
        })
        .collect()
}

#[test]
fn bad_options_are_named() {
    let m = fixture("ac_head.json");
    let p = poses();
    let input = PathInput {
        id: "p",
        poses: &p,
        curve: None,
    };
    for (options, name) in [
        (
            PathOptions::default().with_pole_tolerance_deg(f64::NAN),
            "pole_tolerance_deg",
        ),
        (
            PathOptions::default().with_pole_tolerance_deg(-1.0),
            "pole_tolerance_deg",
        ),
        (
            PathOptions::default().with_max_rotary_step_deg(0.0),
            "max_rotary_step_deg",
        ),
        (
            PathOptions::default().with_linearization_tolerance_mm(-0.1),
            "linearization_tolerance_mm",
        ),
        (
            PathOptions::default().with_linearization_tolerance_mm(f64::NAN),
            "linearization_tolerance_mm",
        ),
    ] {
        let err = solve_path(&m, &input, &options).unwrap_err();
        assert!(
            matches!(err, KinematicsError::BadOption { name: n, .. } if n == name),
            "{err}"
        );
    }
    assert!(
        PathOptions::default().validate().is_ok(),
        "defaults are valid"
    );
}

#[test]
fn bad_poses_are_named() {
    let m = fixture("ac_head.json");
    let mut p = poses();
    p[1].axis *= 2.0;
    let err = solve_path(
        &m,
        &PathInput {
            id: "p",
            poses: &p,
            curve: None,
        },
        &PathOptions::default(),
    )
    .unwrap_err();
    assert_eq!(
        err.to_string(),
        "path \"p\": point 1: the tool axis has length 2, not 1 (a toolpath without normals?)"
    );
    let mut p = poses();
    p[2].position.y = f64::INFINITY;
    let err = solve_path(
        &m,
        &PathInput {
            id: "p",
            poses: &p,
            curve: None,
        },
        &PathOptions::default(),
    )
    .unwrap_err();
    assert_eq!(
        err.to_string(),
        "path \"p\": point 2: the pose holds a non-finite value (inf)"
    );
    let p = poses();
    let params = [0.0, 1.0];
    let point = |t: f64| Point3::new(t, 0.0, 0.0);
    let curve = PathCurve {
        params: &params,
        point: &point,
    };
    let err = solve_path(
        &m,
        &PathInput {
            id: "p",
            poses: &p,
            curve: Some(curve),
        },
        &PathOptions::default(),
    )
    .unwrap_err();
    assert_eq!(
        err.to_string(),
        "path \"p\": point 0: 2 params for 3 poses (one param per pose)"
    );
    let params = [0.0, 1.0, 1.0];
    let curve = PathCurve {
        params: &params,
        point: &point,
    };
    let err = solve_path(
        &m,
        &PathInput {
            id: "p",
            poses: &p,
            curve: Some(curve),
        },
        &PathOptions::default(),
    )
    .unwrap_err();
    assert_eq!(
        err.to_string(),
        "path \"p\": point 2: param 1 is not finite or not above the previous one"
    );
}

#[test]
fn empty_and_single_point_paths() {
    let m = fixture("ac_head.json");
    let empty = solve_path(
        &m,
        &PathInput {
            id: "e",
            poses: &[],
            curve: None,
        },
        &PathOptions::default(),
    )
    .unwrap();
    assert!(empty.axes.is_empty(), "empty");
    let one = [Pose::new(0.0, 0.0, 100.0, 0.0, 0.0, 1.0)];
    let single = solve_path(
        &m,
        &PathInput {
            id: "one",
            poses: &one,
            curve: None,
        },
        &PathOptions::default(),
    )
    .unwrap();
    assert_eq!(single.axes.len(), 1, "one point");
    assert_eq!(single.axes[0].c, 0.0, "a lone pole point keeps C at zero");
    assert_eq!(single.pole_points, 1, "at the pole");
}
