//! Continuity along a path: multi-turn C, limits, the pole, rotary steps.

mod common;

use std::sync::Arc;

use common::{fixture, polar, unlimited, with_limits};
use kerf_kinematics::{
    solve_path, AcHead, KinematicsError, Machine, PathInput, PathOptions, Pose, Range, SolvedPath,
};
use nalgebra::Point3;

fn solve(
    machine: &Machine,
    id: &str,
    poses: &[Pose],
    options: &PathOptions,
) -> kerf_kinematics::Result<SolvedPath> {
    solve_path(
        machine,
        &PathInput {
            id,
            poses,
            curve: None,
        },
        options,
    )
}

/// Every point: the axes put the tip exactly on the pose, and the tool axis on the pose's
/// (within the pole tolerance at the pole).
fn assert_exact(machine: &Machine, path: &SolvedPath, options: &PathOptions) {
    for (n, (pose, q)) in path.poses.iter().zip(&path.axes).enumerate() {
        let back = machine.kinematics.forward(q);
        let dp = (back.position - pose.position).norm();
        assert!(dp < 1e-9, "point {n}: tip off by {dp:e}");
        let angle = back
            .axis
            .cross(&pose.axis)
            .norm()
            .atan2(back.axis.dot(&pose.axis));
        assert!(
            angle <= options.pole_tolerance_deg.to_radians() + 1e-12,
            "point {n}: axis off by {angle:e}"
        );
    }
}

fn max_step(path: &SolvedPath) -> (f64, f64) {
    let mut out: (f64, f64) = (0.0, 0.0);
    for w in path.axes.windows(2) {
        out.0 = out.0.max((w[1].tilt - w[0].tilt).abs());
        out.1 = out.1.max((w[1].c - w[0].c).abs());
    }
    out
}

/// A helix of radius 300 around z, the tool tilted 45 degrees outward, `turn` degrees long in
/// steps of 2 degrees, starting at azimuth `start`. On the ac-head C = azimuth + 90.
fn spiral(start: f64, turn: f64) -> Vec<Pose> {
    let n = (turn / 2.0).round() as usize;
    (0..=n)
        .map(|k| {
            let th = (start + 2.0 * k as f64).to_radians();
            let u = polar(45f64.to_radians(), th);
            Pose {
                position: Point3::new(300.0 * th.cos(), 300.0 * th.sin(), 0.05 * k as f64),
                axis: u,
            }
        })
        .collect()
}

#[test]
fn c_turns_through_720_degrees_on_a_continuous_axis() {
    let machine = fixture("ac_head.json");
    let options = PathOptions::default();
    let poses = spiral(0.0, 720.0);
    let path = solve(&machine, "spiral", &poses, &options).expect("C is continuous");
    assert_exact(&machine, &path, &options);
    let (_, dc) = max_step(&path);
    assert!(
        dc <= 2.0 + 1e-9,
        "no C step beyond the 2-degree spacing: {dc}"
    );
    for (q, src) in path.axes.iter().zip(&path.source) {
        // Inserted tool axes lie on great circles, which dip 0.004 degrees toward the pole
        // between two cutting points 2 degrees apart on the 45-degree cone.
        let tol = if src.is_some() { 1e-9 } else { 0.005 };
        assert!((q.tilt - 45.0).abs() < tol, "the tilt stays at 45: {q:?}");
    }
    let first = path.axes[0];
    let last = path.axes[path.axes.len() - 1];
    assert!(
        (first.tilt - 45.0).abs() < 1e-9 && (first.c - 90.0).abs() < 1e-9,
        "{first:?}"
    );
    assert!(
        (last.c - first.c - 720.0).abs() < 1e-9,
        "two full turns: {first:?} -> {last:?}"
    );
    for w in path.axes.windows(2) {
        assert!(w[1].c >= w[0].c - 1e-9, "C never turns back");
    }
    assert!(
        (path.max_rotary_step_between_cutting_points - 2.0).abs() < 1e-9,
        "report"
    );
}

#[test]
fn c_turns_through_720_degrees_on_a_limited_axis_fails_clearly() {
    let mut machine = fixture("ac_head.json");
    machine.limits[4] = Some(Range::new(-360.0, 360.0));
    let poses = spiral(0.0, 720.0);
    let err = solve(&machine, "spiral", &poses, &PathOptions::default()).unwrap_err();
    let text = err.to_string();
    match err {
        KinematicsError::OutOfLimits {
            path_id,
            index,
            axis,
            min,
            max,
            detail,
            ..
        } => {
            assert_eq!(
                (path_id.as_str(), axis, min, max),
                ("spiral", "C", -360.0, 360.0),
                "{text}"
            );
            assert!(index > 0 && index < poses.len(), "{text}");
            assert!(
                detail.contains("jump"),
                "the other solution fits the limits only by a jump: {text}"
            );
        }
        other => panic!("expected OutOfLimits, got {other:?}"),
    }
    assert!(text.starts_with("path \"spiral\": point "), "{text}");
    assert!(text.contains("is outside its limits [-360, 360]"), "{text}");
}

#[test]
fn a_limited_c_starts_where_the_whole_stretch_fits() {
    // 700 degrees of C within [-400, 400]: only a start at C = -330 fits (C = azimuth + 90
    // - 360 with the first azimuth -60).
    let mut machine = fixture("ac_head.json");
    machine.limits[4] = Some(Range::new(-400.0, 400.0));
    let options = PathOptions::default();
    let path = solve(&machine, "spiral", &spiral(-60.0, 700.0), &options).expect("a start fits");
    assert_exact(&machine, &path, &options);
    let (first, last) = (path.axes[0], path.axes[path.axes.len() - 1]);
    assert!((first.c + 330.0).abs() < 1e-9, "{first:?}");
    assert!((last.c - 370.0).abs() < 1e-9, "{last:?}");
}

/// Through the pole along the great circle at azimuth -60 (C = 30 on the ac-head): tilt from
/// +20 to -20 degrees, one degree per mm. `middle` replaces the pole point's tool axis.
fn through_the_pole(middle: Option<nalgebra::Vector3<f64>>) -> Vec<Pose> {
    (0..=40)
        .map(|k| {
            let theta = (20.0 - k as f64).to_radians();
            let mut u = polar(theta, (-60f64).to_radians());
            if k == 20 {
                u = middle.unwrap_or(u);
            }
            Pose {
                position: Point3::new(k as f64, 0.0, 0.0),
                axis: u,
            }
        })
        .collect()
}

#[test]
fn a_path_through_the_pole_does_not_swing_c() {
    let machine = fixture("ac_head.json");
    let options = PathOptions::default();
    // Exactly through the pole, and 1e-9 rad beside it (within the pole tolerance).
    // Beside the pole, the inserted great-circle points next to it have azimuths off by up to
    // 1e-9 rad / 0.5 degree, i.e. 6e-8 rad: C follows them by that much.
    for (middle, c_tol) in [(None, 1e-9), (Some(polar(1e-9, 30f64.to_radians())), 1e-5)] {
        let poses = through_the_pole(middle);
        let path = solve(&machine, "dome", &poses, &options).expect("reachable");
        assert_exact(&machine, &path, &options);
        for (n, q) in path.axes.iter().enumerate() {
            assert!(
                (q.c - 30.0).abs() < c_tol,
                "{middle:?}: point {n}: C = {}",
                q.c
            );
        }
        for (n, src) in path.source.iter().enumerate() {
            if let Some(k) = src {
                let want = 20.0 - *k as f64;
                assert!(
                    (path.axes[n].tilt - want).abs() < 1e-6,
                    "cutting point {k}: A = {}",
                    path.axes[n].tilt
                );
            }
        }
        assert!(path.pole_points >= 1, "the middle point is at the pole");
        assert!(
            path.pole_tip_error <= 180.0 * 1e-9 + 1e-12,
            "tip error {}",
            path.pole_tip_error
        );
    }
}

#[test]
fn passing_just_outside_the_pole_tolerance_stays_continuous() {
    // 1e-4 rad beside the pole, sideways: C must turn by about 90 degrees within one step.
    let machine = fixture("ac_head.json");
    let options = PathOptions::default().with_max_rotary_step_deg(5.0);
    let poses = through_the_pole(Some(polar(1e-4, 30f64.to_radians())));
    let path = solve(&machine, "beside", &poses, &options).expect("reachable");
    assert_exact(&machine, &path, &options);
    let (dt, dc) = max_step(&path);
    assert!(dt <= 5.0 + 1e-9 && dc <= 5.0 + 1e-9, "steps {dt} {dc}");
    assert!(
        path.max_rotary_step_between_cutting_points > 80.0,
        "C turns fast there: {}",
        path.max_rotary_step_between_cutting_points
    );
    assert!(
        path.inserted_for_rotary_step >= 16,
        "{} inserted",
        path.inserted_for_rotary_step
    );
    assert!(
        path.max_rotary_step <= 5.0 + 1e-9,
        "report {}",
        path.max_rotary_step
    );
}

#[test]
fn leaving_the_pole_sideways_turns_c_at_the_pole() {
    // Tilt down to the pole along C = 0, stay there, leave along C = 90.
    let machine = fixture("ac_head.json");
    let options = PathOptions::default().with_max_rotary_step_deg(5.0);
    let mut poses = Vec::new();
    for k in 0..15 {
        let u = match k {
            0..=4 => polar((2.0 * (5 - k) as f64).to_radians(), (-90f64).to_radians()),
            5..=9 => polar(0.0, 0.0),
            _ => polar((2.0 * (k - 9) as f64).to_radians(), 0.0),
        };
        poses.push(Pose {
            position: Point3::new(k as f64, 0.0, 0.0),
            axis: u,
        });
    }
    let path = solve(&machine, "corner", &poses, &options).expect("reachable");
    assert_exact(&machine, &path, &options);
    let (dt, dc) = max_step(&path);
    assert!(dt <= 5.0 + 1e-9 && dc <= 5.0 + 1e-9, "steps {dt} {dc}");
    // The turn happens with the tool standing at cutting point 9.
    let at9 = path
        .source
        .iter()
        .position(|s| *s == Some(9))
        .expect("point 9");
    let at10 = path
        .source
        .iter()
        .position(|s| *s == Some(10))
        .expect("point 10");
    let turn: Vec<usize> = (at9 + 1..at10)
        .filter(|&n| path.poses[n] == poses[9])
        .collect();
    assert!(turn.len() >= 17, "{} turn points", turn.len());
    assert!((path.axes[at9].c).abs() < 1e-9, "C kept through the pole");
    let c_after = path.axes[at10].c;
    assert!(
        (c_after.abs() - 90.0).abs() < 1e-9,
        "C = +-90 after the turn: {c_after}"
    );
    for q in &path.axes[turn[turn.len() - 1]..] {
        assert!(
            (q.c - c_after).abs() < 1e-9,
            "no more C motion after the turn"
        );
    }
}

#[test]
fn a_trunnion_turns_c_at_the_pole_rather_than_tilt_below_its_limit() {
    // A in [-10, 120]: through the pole, the natural continuation (A negative) would reach
    // -30; C turns 180 at the pole instead and A stays positive.
    let machine = fixture("table_table.json");
    let options = PathOptions::default().with_max_rotary_step_deg(10.0);
    let poses: Vec<Pose> = (0..=60)
        .map(|k| {
            let theta = (30.0 - k as f64).to_radians();
            Pose {
                position: Point3::new(k as f64 - 20.0, 5.0, 20.0),
                axis: polar(theta, 0.3),
            }
        })
        .collect();
    let path = solve(&machine, "over-the-top", &poses, &options).expect("reachable");
    assert_exact(&machine, &path, &options);
    for q in &path.axes {
        assert!(q.tilt >= -10.0 - 1e-9, "A = {}", q.tilt);
    }
    let (first, last) = (path.axes[0], path.axes[path.axes.len() - 1]);
    assert!(
        ((last.c - first.c).abs() - 180.0).abs() < 1e-6,
        "{first:?} -> {last:?}"
    );
    let (_, dc) = max_step(&path);
    assert!(dc <= 10.0 + 1e-9, "the C turn is split: {dc}");
}

#[test]
fn tilt_beyond_both_solutions_names_the_tilt_axis() {
    let machine = fixture("ac_head.json"); // A in [-135, 135]
    let poses = vec![
        Pose {
            position: Point3::new(0.0, 0.0, 200.0),
            axis: polar(120f64.to_radians(), 0.0),
        },
        Pose {
            position: Point3::new(1.0, 0.0, 200.0),
            axis: polar(140f64.to_radians(), 0.0),
        },
    ];
    let err = solve(&machine, "undercut", &poses, &PathOptions::default()).unwrap_err();
    let text = err.to_string();
    assert!(
        matches!(
            &err,
            KinematicsError::OutOfLimits {
                axis: "A",
                index: 1,
                ..
            }
        ),
        "{text}"
    );
    // The other solution (-140, C + 180) is quoted at its turn nearest the previous A (120):
    // 220.
    assert!(
        text.contains("A = 140 is outside its limits [-135, 135]"),
        "{text}"
    );
    assert!(
        text.contains("has A = 220 outside [-135, 135] too"),
        "{text}"
    );
}

#[test]
fn first_point_out_of_reach_is_point_0() {
    let machine = fixture("ac_head.json");
    let poses = vec![Pose {
        position: Point3::new(5000.0, 0.0, 0.0),
        axis: polar(0.1, 0.0),
    }];
    let err = solve(&machine, "far", &poses, &PathOptions::default()).unwrap_err();
    assert!(
        matches!(
            &err,
            KinematicsError::OutOfLimits {
                axis: "X",
                index: 0,
                ..
            }
        ),
        "{err}"
    );
}

#[test]
fn long_rotary_moves_are_split() {
    let machine = unlimited(Arc::new(AcHead::try_new(180.0, 95.0).unwrap()));
    let options = PathOptions::default()
        .with_max_rotary_step_deg(10.0)
        .with_linearization_tolerance_mm(f64::INFINITY);
    let poses = vec![
        Pose {
            position: Point3::origin(),
            axis: polar(30f64.to_radians(), 0.0),
        },
        Pose {
            position: Point3::new(10.0, 0.0, 0.0),
            axis: polar(30f64.to_radians(), 90f64.to_radians()),
        },
    ];
    let path = solve(&machine, "turn", &poses, &options).expect("reachable");
    assert_exact(&machine, &path, &options);
    assert!(
        (path.max_rotary_step_between_cutting_points - 90.0).abs() < 1e-9,
        "{}",
        path.max_rotary_step_between_cutting_points
    );
    assert!(
        path.max_rotary_step <= 10.0 + 1e-9,
        "{}",
        path.max_rotary_step
    );
    assert_eq!(
        path.inserted, path.inserted_for_rotary_step,
        "all for the step"
    );
    assert!(path.inserted >= 8, "{}", path.inserted);
    assert_eq!(path.inserted_for_linearization, 0, "insertion off");
}

#[test]
fn limits_on_a_generic_machine() {
    // The same spiral on a C limited to one turn fails at the point where C leaves it.
    let machine = with_limits(
        Arc::new(AcHead::try_new(180.0, 95.0).unwrap()),
        [None, None, None, None, Some(Range::new(0.0, 360.0))],
    );
    let err = solve(&machine, "s", &spiral(0.0, 400.0), &PathOptions::default()).unwrap_err();
    match err {
        KinematicsError::OutOfLimits {
            axis: "C", value, ..
        } => assert!(value > 360.0, "{value}"),
        other => panic!("{other:?}"),
    }
}
