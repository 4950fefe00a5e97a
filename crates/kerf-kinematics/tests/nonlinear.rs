//! The non-linearity error (paper 002) and the points inserted against it.

mod common;

use std::sync::Arc;

use common::{fixture, polar, unlimited};
use kerf_kinematics::linearization_error;
use kerf_kinematics::{
    solve_path, ForkHead, ForkTilt, KinematicsError, Machine, PathCurve, PathInput, PathOptions,
    Pose, SolvedPath,
};
use kerf_nurbs::distance_to_segment;
use nalgebra::{Point3, Vector3};

/// A fork head tilting A with a 200 mm pivot and no offsets: XYZ = P + 200 u.
fn pivot_200() -> Machine {
    unlimited(Arc::new(
        ForkHead::try_new(ForkTilt::A, 200.0, Vector3::zeros(), [0.0, 0.0]).unwrap(),
    ))
}

/// 1 mm along x while the tool tilts from vertical to A = 5 degrees.
fn one_mm_five_degrees() -> Vec<Pose> {
    let five = 5f64.to_radians();
    vec![
        Pose::new(0.0, 0.0, 0.0, 0.0, 0.0, 1.0),
        Pose::new(1.0, 0.0, 0.0, 0.0, -five.sin(), five.cos()),
    ]
}

/// Every move of the output re-measured.
fn worst_move(machine: &Machine, path: &SolvedPath) -> f64 {
    path.axes
        .windows(2)
        .map(|w| linearization_error(machine.kinematics.as_ref(), &w[0], &w[1]).distance)
        .fold(0.0, f64::max)
}

#[test]
fn one_mm_with_five_degrees_on_a_200_mm_pivot() {
    let machine = pivot_200();
    let kin = machine.kinematics.as_ref();
    let poses = one_mm_five_degrees();
    let a = kin.inverse_with_c(&poses[0], 0.0);
    let b = kin.inverse(&poses[1])[0];
    assert!((b.tilt - 5.0).abs() < 1e-12 && b.c.abs() < 1e-12, "{b:?}");
    // The tip is lerp(P) + 200 (lerp(u) - u(s)); at s = 1/2 that is the sagitta of a 5-degree
    // arc of radius 200, perpendicular to the x motion: 200 (1 - cos 2.5 deg) = 0.190356 mm.
    let expected = 200.0 * (1.0 - 2.5f64.to_radians().cos());
    assert!((expected - 0.190_356).abs() < 1e-6, "{expected}");
    let dev = linearization_error(kin, &a, &b);
    assert!(
        (dev.distance - expected).abs() < 1e-9,
        "{dev:?} vs {expected}"
    );
    assert!(
        (dev.at - 0.5).abs() < 1e-4,
        "the bulge peaks mid-move: {dev:?}"
    );

    // Insertion: n pieces of 5/n degrees bulge 200 (1 - cos(2.5/n deg)); n = 7 is the first
    // within 0.005 mm (0.00389), so 6 points are inserted.
    let options = PathOptions::default();
    let path = solve_path(
        &machine,
        &PathInput {
            id: "step",
            poses: &poses,
            curve: None,
        },
        &options,
    )
    .unwrap();
    assert_eq!(path.inserted, 6, "{path:?}");
    assert_eq!(
        path.inserted_for_linearization, 6,
        "all against the non-linearity"
    );
    let worst = worst_move(&machine, &path);
    let seventh = 200.0 * (1.0 - (2.5f64 / 7.0).to_radians().cos());
    assert!(worst <= 0.005, "{worst}");
    assert!((worst - seventh).abs() < 1e-9, "{worst} vs {seventh}");
    assert!(
        (path.max_linearization_error - worst).abs() < 1e-12,
        "report"
    );
    // Inserted positions lie on the straight segment (no curve given), axes on the arc.
    for (n, p) in path.poses.iter().enumerate() {
        assert!(
            p.position.y.abs() < 1e-15 && p.position.z.abs() < 1e-15,
            "point {n}"
        );
        let tilt = p.axis.y.atan2(p.axis.z).to_degrees().abs();
        assert!(
            (tilt - 5.0 * p.position.x).abs() < 1e-9,
            "point {n}: even spacing on the great circle"
        );
    }
}

#[test]
fn the_paper_000_head_bulges_by_its_r_a() {
    // The same move on the ac-head: the arm is r_a = 180 (the r_c offset does not turn with A).
    let machine = fixture("ac_head.json");
    let kin = machine.kinematics.as_ref();
    let mut poses = one_mm_five_degrees();
    for p in &mut poses {
        p.position.z += 100.0;
    }
    let a = kin.inverse_with_c(&poses[0], 0.0);
    let b = kin.inverse(&poses[1])[0];
    let expected = 180.0 * (1.0 - 2.5f64.to_radians().cos());
    let dev = linearization_error(kin, &a, &b).distance;
    assert!(
        (dev - expected).abs() < 1e-9,
        "{dev} vs {expected} (0.1713)"
    );
}

#[test]
fn pure_translation_has_no_error() {
    let machine = fixture("head_table.json");
    let u = polar(0.3, 0.2);
    let poses = [
        Pose {
            position: Point3::new(600.0, 0.0, 0.0),
            axis: u,
        },
        Pose {
            position: Point3::new(610.0, 5.0, 1.0),
            axis: u,
        },
    ];
    let kin = machine.kinematics.as_ref();
    let (a, b) = (kin.inverse(&poses[0])[0], kin.inverse(&poses[1])[0]);
    assert_eq!(a.tilt, b.tilt, "same orientation, same rotaries");
    assert!(
        linearization_error(kin, &a, &b).distance < 1e-12,
        "no rotary motion, no bulge"
    );
    let path = solve_path(
        &machine,
        &PathInput {
            id: "line",
            poses: &poses,
            curve: None,
        },
        &PathOptions::default(),
    )
    .unwrap();
    assert_eq!(path.inserted, 0, "nothing to insert");
}

#[test]
fn inserted_points_lie_on_the_curve_when_it_is_known() {
    // A quarter circle of radius 50 at z = 0 in 4 chords, the tool turning from vertical to
    // 30 degrees outward: the inserted points must be on the circle.
    let machine = fixture("fork_head.json");
    let circle = |t: f64| Point3::new(50.0 * t.cos(), 50.0 * t.sin(), 0.0);
    let params: Vec<f64> = (0..=4)
        .map(|k| k as f64 * std::f64::consts::FRAC_PI_8)
        .collect();
    let poses: Vec<Pose> = params
        .iter()
        .map(|&t| Pose {
            position: circle(t),
            axis: polar(t / std::f64::consts::FRAC_PI_2 * 30f64.to_radians(), t),
        })
        .collect();
    let curve = PathCurve {
        params: &params,
        point: &circle,
    };
    let options = PathOptions::default().with_linearization_tolerance_mm(0.001);
    let on_curve = solve_path(
        &machine,
        &PathInput {
            id: "arc",
            poses: &poses,
            curve: Some(curve),
        },
        &options,
    )
    .unwrap();
    assert!(on_curve.inserted > 0, "the tilt change needs points");
    for p in &on_curve.poses {
        let r = p.position.coords.xy().norm();
        assert!(
            (r - 50.0).abs() < 1e-9,
            "inserted point off the circle: r = {r}"
        );
    }
    assert!(
        worst_move(&machine, &on_curve) <= 0.001,
        "within the tolerance"
    );
    // Without the curve the inserted points lie on the chords instead.
    let on_chords = solve_path(
        &machine,
        &PathInput {
            id: "arc",
            poses: &poses,
            curve: None,
        },
        &options,
    )
    .unwrap();
    let mut last_cut = 0;
    for (n, p) in on_chords.poses.iter().enumerate() {
        match on_chords.source[n] {
            Some(k) => last_cut = k,
            None => {
                let d = distance_to_segment(
                    &p.position,
                    &poses[last_cut].position,
                    &poses[last_cut + 1].position,
                );
                assert!(d < 1e-9, "point {n} off its chord by {d}");
            }
        }
    }
}

#[test]
fn infinite_tolerance_inserts_nothing_and_still_reports() {
    let machine = pivot_200();
    let options = PathOptions::default().with_linearization_tolerance_mm(f64::INFINITY);
    let poses = one_mm_five_degrees();
    let path = solve_path(
        &machine,
        &PathInput {
            id: "step",
            poses: &poses,
            curve: None,
        },
        &options,
    )
    .unwrap();
    assert_eq!(path.inserted, 0, "off");
    assert!(
        (path.max_linearization_error - 0.190_356).abs() < 1e-6,
        "{}",
        path.max_linearization_error
    );
}

#[test]
fn too_many_inserted_points_is_an_error() {
    let machine = pivot_200();
    let options = PathOptions::default()
        .with_linearization_tolerance_mm(1e-7)
        .with_max_inserted(10);
    let poses = one_mm_five_degrees();
    let err = solve_path(
        &machine,
        &PathInput {
            id: "step",
            poses: &poses,
            curve: None,
        },
        &options,
    )
    .unwrap_err();
    assert!(
        matches!(
            err,
            KinematicsError::TooManyInserted {
                limit: 10,
                index: 1,
                ..
            }
        ),
        "{err}"
    );
    assert!(
        err.to_string().contains("raise linearization_tolerance_mm"),
        "{err}"
    );
}
