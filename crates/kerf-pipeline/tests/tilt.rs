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
    assert!(exact.report["kinematics"]["tilt"].is_null());
    // The report: the largest deviation, where, and the rotary travel it saved.
    let t = &cone.report["kinematics"]["tilt"];
    assert_eq!(t["tolerance_deg"], 1.0);
    let max = t["max_deg"].as_f64().expect("max_deg");
    assert!(max > 0.0 && max <= 1.0, "{t}");
    let at = t["max_at_mm"].as_array().expect("where");
    let r = (0..3)
        .map(|i| at[i].as_f64().expect("mm").powi(2))
        .sum::<f64>()
        .sqrt();
    assert!(
        (r - RADIUS).abs() < 0.1,
        "the place is a tip on the sphere: {t}"
    );
    let (before, after) = (
        t["rotary_travel_exact_deg"].as_f64().expect("exact"),
        t["rotary_travel_deg"].as_f64().expect("chosen"),
    );
    assert!(after < before - 300.0, "{t}");
}
