//! The tilt tolerance, checked against the exact sphere of `fixtures/dome.json`: every pose
//! and every point between two poses (the axes interpolated linearly, as the controller does)
//! has its tool axis within the tolerance of the sphere's normal at the tool tip, measured by
//! forward kinematics, not from what the smoothing says of itself; and near the pole C stops
//! turning.

use std::f64::consts::TAU;

use kerf_kinematics::{Axes, PathOptions};
use kerf_nurbs::NurbsCurve;
use kerf_pipeline::{Job, JobOptions, Output};
use nalgebra::{Point3, Vector3};

mod common;
use common::fixture;

/// The sphere of `dome.json`: radius 100 about the origin.
const RADIUS: f64 = 100.0;

/// A latitude circle `polar_deg` from the sphere's top: exact, on the sphere.
fn latitude(polar_deg: f64) -> NurbsCurve {
    let (s, c) = polar_deg.to_radians().sin_cos();
    NurbsCurve::arc(
        Point3::new(0.0, 0.0, RADIUS * c),
        Vector3::x(),
        Vector3::y(),
        RADIUS * s,
        0.0,
        TAU,
    )
    .expect("circle")
}

fn run(machine: &str, tilt_deg: f64) -> (Output, kerf_kinematics::Machine) {
    let job = Job::from_files(fixture("dome.json"), fixture(machine))
        .expect("inputs")
        .with_curve("near-pole", latitude(0.6), Some("dome"))
        .with_options(
            JobOptions::default()
                .with_tolerance_mm(0.01)
                .with_path(PathOptions::default().with_tilt_tolerance_deg(tilt_deg)),
        );
    let machine = job.machine().clone();
    (job.run().expect("run"), machine)
}

/// The angle (degrees) between the tool axis that `axes` give and the sphere's normal at the
/// tool tip they give.
fn deviation_deg(machine: &kerf_kinematics::Machine, axes: &[f64; 5]) -> f64 {
    let pose = machine.kinematics.forward(&Axes::from_array(*axes));
    let normal = pose.position.coords.normalize();
    pose.axis.angle(&normal).to_degrees()
}

/// The C travel (degrees) of a path's cut.
fn c_travel(positions: &[[f64; 5]]) -> f64 {
    positions
        .windows(2)
        .map(|w| (w[1][4] - w[0][4]).abs())
        .sum()
}

#[test]
fn every_pose_and_every_move_stays_in_the_cone_of_the_true_normal() {
    for machine in ["machines/ac_head.json", "machines/fork_head.json"] {
        let tol = 1.0;
        let (out, m) = run(machine, tol);
        for path in &out.axes.paths {
            let q = &path.positions;
            let mut worst: f64 = 0.0;
            for (n, a) in q.iter().enumerate() {
                worst = worst.max(deviation_deg(&m, a));
                if n + 1 < q.len() {
                    // The controller moves every axis linearly between two positions.
                    for k in 1..8 {
                        let s = k as f64 / 8.0;
                        let mid: [f64; 5] =
                            std::array::from_fn(|i| q[n][i] + s * (q[n + 1][i] - q[n][i]));
                        worst = worst.max(deviation_deg(&m, &mid));
                    }
                }
            }
            assert!(worst <= tol, "{machine} {}: {worst} deg", path.id);
            let reported = path.tilt_max_deg.expect("tilt reported");
            assert!(
                reported <= tol && reported <= worst + 1e-6,
                "{reported} vs measured {worst}"
            );
        }
    }
}

#[test]
fn near_the_pole_c_stands_still_and_the_cut_is_faster() {
    let (exact, m) = run("machines/ac_head.json", 0.0);
    let (cone, _) = run("machines/ac_head.json", 1.0);
    let path = |o: &Output| {
        o.axes
            .paths
            .iter()
            .find(|p| p.id == "near-pole")
            .expect("path")
            .clone()
    };
    let (e, c) = (path(&exact), path(&cone));
    // The exact normal is 0.6 degrees off the pole: C turns a full circle with it.
    assert!(c_travel(&e.positions) > 350.0, "{}", c_travel(&e.positions));
    // Within a 1-degree cone the pole is in every pose's cone: C need not move.
    assert!(c_travel(&c.positions) < 1.0, "{}", c_travel(&c.positions));
    for a in &c.positions {
        assert!(deviation_deg(&m, a) <= 1.0);
    }
    // The other paths (30 and 64 degrees off the pole) keep their exact normals' C travel,
    // up to the cone.
    let duration = |o: &Output| o.programs.iter().map(|p| p.motion.duration()).sum::<f64>();
    assert!(
        duration(&cone) < duration(&exact),
        "{} s with the cone, {} s exact",
        duration(&cone),
        duration(&exact)
    );
    assert!(e.tilt_max_deg.is_none(), "no tolerance, no tilt reported");
    assert!(exact.report.kinematics.tilt.is_none());
    // The report: the largest deviation, where, and the rotary travel it saved.
    let t = cone.report.kinematics.tilt.as_ref().expect("a tilt report");
    assert_eq!(t.tolerance_deg, 1.0);
    let max = t.max_deg;
    assert!(max > 0.0 && max <= 1.0, "{t:?}");
    let at = t.max_at_mm.expect("where");
    let r = at.iter().map(|x| x * x).sum::<f64>().sqrt();
    assert!(
        (r - RADIUS).abs() < 0.1,
        "the place is a tip on the sphere: {t:?}"
    );
    let (before, after) = (t.rotary_travel_exact_deg, t.rotary_travel_deg);
    assert!(after < before - 300.0, "{t:?}");
}

/// The shipped propeller's blade edge `prop-propeller-e40` on a fork head with a B tilt, a
/// 200 mm pivot, no offsets and no limits: with the exact normals C spins where the edge's
/// normal passes near vertical (11 degrees of C for 0.03 degrees of tool axis); within the
/// 1-degree cone no move turns C by more than 2 degrees and 5 times the tool axis' turn.
#[test]
fn the_propeller_edge_makes_no_rotary_jumps_within_the_cone() {
    let mut v: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(fixture("machines/fork_head.json")).expect("machine"),
    )
    .expect("json");
    v["kinematics"] = serde_json::json!({
        "type": "fork-head", "tilt": "B", "L": 200.0, "d": [0.0, 0.0, 0.0], "tool_lateral": [0.0, 0.0]
    });
    for axis in ["X", "Y", "Z", "B", "C"] {
        v["limits"][axis] = serde_json::Value::Null;
    }
    let machine = kerf_kinematics::Machine::from_value(&v).expect("machine");
    let jumps = |tilt_deg: f64| {
        let curves =
            kerf_format::curves::load(fixture("realdata/occt_propeller.json")).expect("part");
        let out = Job::new(curves, machine.clone())
            .with_options(
                JobOptions::default()
                    .with_tolerance_mm(0.01)
                    .with_path(PathOptions::default().with_tilt_tolerance_deg(tilt_deg))
                    // The blade edges by the hub meet the head (refused by default).
                    .with_cut_clearance_mm(None),
            )
            .run()
            .expect("run");
        let p = out
            .axes
            .paths
            .iter()
            .find(|p| p.id == "prop-propeller-e40")
            .expect("path");
        (1..p.positions.len())
            .filter(|&i| {
                let d_c = (p.positions[i][4] - p.positions[i - 1][4]).abs();
                let (a, b) = (&p.poses[i - 1], &p.poses[i]);
                let turn = Vector3::new(a[3], a[4], a[5])
                    .angle(&Vector3::new(b[3], b[4], b[5]))
                    .to_degrees();
                d_c > 2.0 && d_c > 5.0 * turn
            })
            .count()
    };
    assert!(jumps(0.0) >= 5, "the exact normals spin C");
    assert_eq!(jumps(1.0), 0);
}
