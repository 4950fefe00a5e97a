//! The head against the part along the cuts (`kerf run --cut-clearance`): a hole 47 mm from a
//! wall's foot, whose nearest point is 42 mm from it, so that the default head's 45 mm body
//! passes 2 mm from the wall: clear at a 1 mm clearance, refused by name at 3 mm, a warning
//! with the stretch in the report when accepted.

use kerf_kinematics::Machine;
use kerf_pipeline::{Job, JobOptions};
use nalgebra::{Point3, Vector3};

mod common;
use common::fixture;

fn job(clearance: f64, accept: bool) -> Result<kerf_pipeline::Output, kerf_pipeline::Error> {
    let curves = kerf_format::curves::load(fixture("head_wall.json")).expect("curves");
    let machine = Machine::read(fixture("machines/gantry_ac.json")).expect("machine");
    Job::new(curves, machine)
        .with_options(
            JobOptions::default()
                .with_cut_clearance_mm(Some(clearance))
                .with_accept_head_collisions(accept),
        )
        .run()
}

#[test]
fn the_head_clears_the_wall_at_one_millimetre() {
    let out = job(1.0, false).expect("run");
    let head = &out.report["head"];
    assert_eq!(head["checked"], true);
    for p in head["paths"].as_array().expect("paths") {
        let d = p["min_distance_mm"].as_f64().expect("bound");
        // Proven at least the clearance less the check's resolution, and never above the
        // exact 2 mm the body passes from the wall.
        assert!(
            d >= 1.0 - kerf_process::CLOSE_CELL_MM - kerf_process::SAMPLE_STEP_MM / 2.0,
            "{p}"
        );
        if p["path"] == "hole-near-wall" {
            assert!(d <= 2.0 + 1e-9, "{p}");
        }
        assert!(p["close"].as_array().expect("close").is_empty(), "{p}");
    }
}

#[test]
fn the_wall_is_named_when_the_clearance_is_three_millimetres() {
    let e = job(3.0, false).expect_err("refused");
    let text = e.to_string();
    assert!(
        text.contains("path \"hole-near-wall\": the head comes too close")
            && text.contains("surface wall")
            && text.contains("clearance 3 mm"),
        "{text}"
    );
    let out = job(3.0, true).expect("accepted");
    assert!(
        out.warnings
            .iter()
            .any(|w| w.contains("hole-near-wall") && w.contains("accepted")),
        "{:?}",
        out.warnings
    );
    let paths = out.report["head"]["paths"].as_array().expect("paths");
    let near = paths
        .iter()
        .find(|p| p["path"] == "hole-near-wall")
        .expect("near");
    let close = near["close"].as_array().expect("close");
    assert_eq!(close.len(), 1, "{near}");
    assert_eq!(close[0]["surface"], "wall");
    // The exact stretch within 3 mm: 5 cos(theta) > 4, an arc of 2 x 0.6435 x 5 = 6.4 mm;
    // the reported one is witnessed inside it.
    let len = close[0]["length_mm"].as_f64().expect("length");
    assert!(len > 3.0 && len <= 6.44 + 1.0, "{near}");
    let far = paths.iter().find(|p| p["path"] == "hole-far").expect("far");
    assert!(far["close"].as_array().expect("close").is_empty(), "{far}");
}

/// The smallest distance from the default head (above `zone` mm over the nozzle tip, 1 mm
/// standoff), standing at each pose, to the floor and the wall of `head_wall.json`, by dense
/// sampling of the head's surface against the exact rectangles: independent of the check's
/// cells and closest points.
fn sampled_distance(poses: &[(Point3<f64>, Vector3<f64>)], zone: f64) -> f64 {
    let head = kerf_kinematics::Head::laser_default();
    // The rectangles: origin, two edges.
    let rects = [
        (
            Point3::new(-200.0, -200.0, 0.0),
            Vector3::new(252.0, 0.0, 0.0),
            Vector3::new(0.0, 400.0, 0.0),
        ),
        (
            Point3::new(52.0, -200.0, 0.0),
            Vector3::new(0.0, 400.0, 0.0),
            Vector3::new(0.0, 0.0, 60.0),
        ),
    ];
    let to_rect = |q: &Point3<f64>| -> f64 {
        rects
            .iter()
            .map(|(o, u, v)| {
                let w = q - o;
                let a = (w.dot(u) / u.norm_squared()).clamp(0.0, 1.0);
                let b = (w.dot(v) / v.norm_squared()).clamp(0.0, 1.0);
                (q - (o + u * a + v * b)).norm()
            })
            .fold(f64::INFINITY, f64::min)
    };
    let mut best = f64::INFINITY;
    for (p, a) in poses {
        let e1 = a.cross(&Vector3::y()).normalize();
        let e2 = a.cross(&e1);
        let steps = (head.length_mm() / 0.5) as usize;
        for j in 0..=steps {
            let h = zone + (head.length_mm() - zone) * j as f64 / steps as f64;
            let r = head.radius_at(h).expect("on the head");
            for m in 0..360 {
                let phi = (m as f64).to_radians();
                let q = p + a * (1.0 + h) + (e1 * phi.cos() + e2 * phi.sin()) * r;
                best = best.min(to_rect(&q));
            }
        }
    }
    best
}

#[test]
fn a_tilt_within_the_tolerance_clears_the_wall_and_dense_sampling_agrees() {
    let curves = kerf_format::curves::load(fixture("head_wall.json")).expect("curves");
    let machine = Machine::read(fixture("machines/gantry_ac.json")).expect("machine");
    let out = Job::new(curves.clone(), machine)
        .with_options(
            JobOptions::default()
                .with_cut_clearance_mm(Some(3.0))
                .with_path(kerf_kinematics::PathOptions::default().with_tilt_tolerance_deg(10.0)),
        )
        .run()
        .expect("tilted to clear");
    let head = &out.report["head"];
    let zone = head["tip_zone_mm"].as_f64().expect("zone");
    let near = head["paths"]
        .as_array()
        .expect("paths")
        .iter()
        .find(|p| p["path"] == "hole-near-wall")
        .expect("near")
        .clone();
    let tilt = near["tilted"]["max_tilt_deg"].as_f64().expect("tilt");
    assert!(tilt > 0.5 && tilt <= 10.0, "{near}");
    // Every written pose of the cut, its lead-in and lead-out, in part coordinates, against
    // the exact floor and wall: the clearance less the check's resolution.
    let i = curves
        .curves
        .iter()
        .position(|c| c.id == "hole-near-wall")
        .expect("curve");
    let pl = out.placement.placement_of(i);
    let (r, t) = (pl.rotation(), pl.translation_mm);
    let path = out
        .axes
        .paths
        .iter()
        .find(|p| p.id == "hole-near-wall")
        .expect("path");
    let mut poses: Vec<[f64; 6]> = path.poses.clone();
    for m in [&path.lead_in, &path.lead_out].into_iter().flatten() {
        poses.extend(m.poses.iter().copied());
    }
    let poses: Vec<(Point3<f64>, Vector3<f64>)> = poses
        .iter()
        .map(|q| {
            (
                Point3::from(r.inverse() * (Point3::new(q[0], q[1], q[2]) - t)),
                r.inverse() * Vector3::new(q[3], q[4], q[5]),
            )
        })
        .collect();
    let d = sampled_distance(&poses, zone);
    assert!(
        d >= 3.0 - kerf_process::CLOSE_CELL_MM - kerf_process::SAMPLE_STEP_MM / 2.0,
        "dense sampling: the head within {d} mm of the part"
    );
    // Without the tilt the same sampling finds the wall closer than the clearance: the
    // tilt, not the sampling, made the difference.
    let upright: Vec<(Point3<f64>, Vector3<f64>)> =
        poses.iter().map(|(p, _)| (*p, Vector3::z())).collect();
    assert!(sampled_distance(&upright, zone) < 2.5);
}

#[test]
fn without_a_tilt_tolerance_the_refusal_says_which_tilt_would_clear() {
    let e = job(3.0, false).expect_err("refused").to_string();
    assert!(
        e.contains("deg away from surface wall would clear it") && e.contains("--tilt-tolerance"),
        "{e}"
    );
}
