//! `--place auto` counts every move of the program, not only the cutting poses: on a machine
//! whose travel holds the cut poses with less than a millimetre to spare beyond the margin the
//! search keeps, every set-point of the program (leads, pierce points, retracts, traverses and
//! blends) stays within every range, checked from the CSV; where the moves off the cut do not
//! fit, the run is refused by the placement, not by a program that leaves the travel.

use std::f64::consts::TAU;

use kerf_kinematics::Machine;
use kerf_nurbs::{NurbsCurve, NurbsSurface};
use kerf_pipeline::{Job, JobOptions, PlaceMode};
use nalgebra::{Point3, Vector3};
use serde_json::Value;

mod common;
use common::{assert_setpoints_within_limits, fixture};

/// Three holes of radius 10 in a plate tilted 30 degrees about y.
fn job(machine: Machine) -> Job {
    let (s, c) = 30f64.to_radians().sin_cos();
    let (u, v) = (Vector3::new(c, 0.0, -s), Vector3::y());
    let origin = Point3::new(0.0, 0.0, 0.0);
    let plate =
        NurbsSurface::plane(origin - u * 40.0 - v * 40.0, u, v, 320.0, 80.0).expect("plate");
    let mut job = Job::on_machine(machine).with_surface("plate", plate, false);
    for (k, x) in [0.0, 100.0, 200.0].into_iter().enumerate() {
        let hole = NurbsCurve::arc(origin + u * (x + 20.0), u, v, 10.0, 0.0, TAU).expect("circle");
        job = job.with_curve(format!("hole-{k}"), hole, Some("plate"));
    }
    job.with_options(JobOptions::default().with_place(PlaceMode::Auto))
}

/// The shipped A/C head with its linear limits replaced.
fn machine_with(limits: [(f64, f64); 3], pierce_standoff: Option<f64>) -> Machine {
    let text = std::fs::read_to_string(fixture("machines/ac_head.json")).expect("machine");
    let mut v: Value = serde_json::from_str(&text).expect("json");
    for (name, (lo, hi)) in ["X", "Y", "Z"].iter().zip(limits) {
        v["limits"][name] = serde_json::json!([lo, hi]);
    }
    if let Some(h) = pierce_standoff {
        v["process"] = serde_json::json!({ "pierce_standoff": h });
    }
    Machine::from_value(&v).expect("machine")
}

/// The hull of the linear axes over the cutting poses, from a run on the roomy machine.
fn cut_hull() -> [(f64, f64); 3] {
    let roomy = Machine::read(fixture("machines/ac_head.json")).expect("machine");
    let out = job(roomy).run().expect("roomy run");
    let mut hull = [(f64::INFINITY, f64::NEG_INFINITY); 3];
    for p in &out.axes.paths {
        for q in &p.positions {
            for k in 0..3 {
                hull[k] = (hull[k].0.min(q[k]), hull[k].1.max(q[k]));
            }
        }
    }
    hull
}

#[test]
fn a_part_filling_the_travel_to_a_millimetre_gets_a_program_within_it() {
    let hull = cut_hull();
    // The margin the search keeps (the retract, 10 mm, and 1 mm) plus half a millimetre on
    // each side: the cut poses fill the travel to within a millimetre of that.
    let margin = 11.0 + 0.5;
    let limits = hull.map(|(lo, hi)| (lo - margin, hi + margin));
    let machine = machine_with(limits, None);
    let out = job(machine.clone()).run().expect("placed and planned");
    assert_setpoints_within_limits("tight travel", &machine, &out, 0.001);
    let p = &out.report.placement;
    assert_eq!(p.margin_mm, Some(11.0), "{p:?}");
    assert_eq!(p.searches, Some(1), "{p:?}");
}

#[test]
fn a_pierce_standoff_beyond_the_travel_is_refused_by_the_placement() {
    let hull = cut_hull();
    let limits = hull.map(|(lo, hi)| (lo - 11.5, hi + 11.5));
    // The pierce point 30 mm above each start along a tool axis 30 degrees off z: 26 mm up and
    // 15 mm along x, more than the 11.5 mm left.
    let machine = machine_with(limits, Some(30.0));
    match job(machine.clone()).run() {
        Ok(out) => assert_setpoints_within_limits("pierce", &machine, &out, 0.001),
        Err(e) => {
            let msg = e.to_string();
            assert!(
                msg.contains("no placement fits"),
                "the placement refuses, not the program: {msg}"
            );
        }
    }
}

/// One outline of radius 60 on the tilted plate, with `leads`: its lead-in starts outside it.
fn outline_job(machine: Machine, leads: kerf_process::LeadOptions) -> Job {
    let (s, c) = 30f64.to_radians().sin_cos();
    let (u, v) = (Vector3::new(c, 0.0, -s), Vector3::y());
    let origin = Point3::new(0.0, 0.0, 0.0);
    let plate =
        NurbsSurface::plane(origin - u * 100.0 - v * 100.0, u, v, 200.0, 200.0).expect("plate");
    let outline = NurbsCurve::arc(origin, u, v, 60.0, 0.0, TAU).expect("circle");
    Job::on_machine(machine)
        .with_surface("plate", plate, false)
        .with_curve("outline", outline, Some("plate"))
        .with_options(
            JobOptions::default()
                .with_place(PlaceMode::Auto)
                .with_leads(leads),
        )
}

#[test]
fn a_long_lead_in_the_search_did_not_see_makes_it_search_again() {
    // The hull of the outline's cutting poses alone (no leads).
    let roomy = Machine::read(fixture("machines/ac_head.json")).expect("machine");
    let none = kerf_process::LeadOptions::default()
        .with_lead_in(0.0, 0.0)
        .with_lead_out(0.0, 0.0);
    let out = outline_job(roomy, none).run().expect("roomy run");
    let mut hull = [(f64::INFINITY, f64::NEG_INFINITY); 3];
    for q in out.axes.paths.iter().flat_map(|p| &p.positions) {
        for k in 0..3 {
            hull[k] = (hull[k].0.min(q[k]), hull[k].1.max(q[k]));
        }
    }
    // 11.5 mm beyond that hull, and a 20 mm lead-in that starts outside the outline: beyond
    // what the search kept. The run must not end in a pose or set-point outside the travel.
    let machine = machine_with(hull.map(|(lo, hi)| (lo - 11.5, hi + 11.5)), None);
    let leads = kerf_process::LeadOptions::default().with_lead_in(20.0, 1.0);
    match outline_job(machine.clone(), leads).run() {
        Ok(out) => assert_setpoints_within_limits("lead", &machine, &out, 0.001),
        Err(e) => {
            let msg = e.to_string();
            assert!(
                msg.contains("no placement fits"),
                "the placement refuses: {msg}"
            );
        }
    }
}
