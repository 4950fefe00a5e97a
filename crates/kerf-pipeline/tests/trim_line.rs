//! Issue 26's trim lines on every shipped machine, every dialect, placed by `--place auto`:
//! the domed panel whose normal passes within 0.5 degrees of vertical (the pole of every head),
//! the creases of 10 to 40 degrees with a wall up to 90 degrees, and the same as a STEP
//! composite curve. Each program is checked independently of the planner: every set-point of
//! the CSV within every axis' range, velocity and acceleration (finite differences of the
//! written numbers), and every cutting pose's tool axis, found by forward kinematics of its
//! axes, within the tilt tolerance of the true surface normal at the tip it gives (the
//! closest point on the curve's own NURBS faces).

use std::path::Path;

use kerf_format::curves::{self, CurvesFile, SurfaceGeometry};
use kerf_interp::Dialect;
use kerf_kinematics::PathOptions;
use kerf_kinematics::{Axes, Machine};
use kerf_pipeline::{Job, JobOptions, Output, PlaceMode};
use nalgebra::Vector3;

mod common;
use common::{assert_setpoints_within_limits, fixture, setpoint_rows};

const MACHINES: [&str; 5] = [
    "ac_head.json",
    "gantry_ac.json",
    "fork_head.json",
    "head_table.json",
    "table_table.json",
];
/// The tilt tolerance the trim lines are cut with (degrees).
const TILT_DEG: f64 = 1.0;
const DIALECTS: [Dialect; 3] = [Dialect::Generic, Dialect::Sinumerik, Dialect::Linuxcnc];

fn step(name: &str) -> CurvesFile {
    let import = kerf_step::import_file(fixture(name), &kerf_step::ImportOptions::default())
        .expect("STEP import");
    curves::from_raw(import.file, Path::new(".")).expect("valid document")
}

/// Every cutting pose's tool axis within `tol_deg` of the line of the surface normal at its
/// tip (the sides stage may cut from the other side of the sheet), measured on the faces the
/// curve names; at a crease, of the arc between the two faces' normals (the axis must turn
/// there, at the point).
fn assert_in_the_cone(
    what: &str,
    file: &CurvesFile,
    machine: &Machine,
    out: &Output,
    tol_deg: f64,
) {
    for path in &out.axes.paths {
        let k = file
            .curves
            .iter()
            .position(|c| c.id == path.id)
            .expect("curve of the path");
        let placement = out.placement.placement_of(k);
        let r_inv = placement.rotation().inverse();
        let faces: Vec<_> = file.curves[k]
            .surfaces
            .iter()
            .filter_map(|id| file.surfaces.iter().find(|s| &s.id == id))
            .filter_map(|s| match &s.geometry {
                SurfaceGeometry::Nurbs(n) => Some(n),
                _ => None,
            })
            .collect();
        assert!(!faces.is_empty(), "{what}: {} has its faces", path.id);
        let mut worst: f64 = 0.0;
        for (n, q) in path.positions.iter().enumerate() {
            let pose = machine.kinematics.forward(&Axes::from_array(*q));
            let tip = r_inv * (pose.position - placement.translation_mm);
            let axis = r_inv * pose.axis;
            let normals: Vec<Vector3<f64>> = faces
                .iter()
                .filter_map(|f| {
                    let p = f.closest_point(&tip, None);
                    (p.distance <= 0.02).then(|| f.normal(p.u, p.v)).flatten()
                })
                .collect();
            // On one face: the angle to its normal's line. Where faces meet (a crease) the
            // axis turns at the point from one face's cone to the other's: the angle to the
            // arc between their normals.
            let best = normals
                .iter()
                .flat_map(|a| normals.iter().map(move |b| (a, b)))
                .map(|(a, b)| {
                    [axis, -axis]
                        .iter()
                        .map(|u| angle_to_arc(u, a, b))
                        .fold(f64::INFINITY, f64::min)
                })
                .fold(f64::INFINITY, f64::min);
            assert!(
                best.is_finite(),
                "{what}: {} pose {n} is on no face",
                path.id
            );
            worst = worst.max(best);
        }
        assert!(
            worst <= tol_deg + 1e-6,
            "{what}: {}: {worst} deg off the normal",
            path.id
        );
    }
}

/// The set-points' tilt and C within the range the program's positions span (cuts, leads and
/// traverses), up to 0.1 degree: the planner's splines do not swing the rotary axes past the
/// poses (a bend ending in a plane once made A overshoot by 23 degrees, the tool axis 66
/// degrees off the poses, with the tip on the path).
fn assert_rotaries_within_the_poses(what: &str, out: &Output) {
    let mut range = [(f64::INFINITY, f64::NEG_INFINITY); 2];
    for p in &out.axes.paths {
        let parts = [Some(&p.positions), p.lead_in.as_ref().map(|m| &m.positions)]
            .into_iter()
            .chain([
                p.lead_out.as_ref().map(|m| &m.positions),
                p.traverse.as_ref().map(|m| &m.positions),
            ]);
        for q in parts.flatten().flatten() {
            for k in 0..2 {
                range[k] = (range[k].0.min(q[3 + k]), range[k].1.max(q[3 + k]));
            }
        }
    }
    for setup in 0..out.programs.len() {
        for (i, v) in setpoint_rows(out, setup).iter().enumerate() {
            for k in 0..2 {
                let (lo, hi) = range[k];
                assert!(
                    v[3 + k] >= lo - 0.1 && v[3 + k] <= hi + 0.1,
                    "{what}: cycle {i}: rotary axis {k} at {} beyond the poses' [{lo}, {hi}]",
                    v[3 + k]
                );
            }
        }
    }
}

/// The angle (degrees) from the unit vector `u` to the shorter great-circle arc from `a` to `b`
/// (unit vectors; `a == b` is the angle to `a`).
fn angle_to_arc(u: &Vector3<f64>, a: &Vector3<f64>, b: &Vector3<f64>) -> f64 {
    let ends = u.angle(a).min(u.angle(b));
    let n = a.cross(b);
    if n.norm() < 1e-12 {
        return ends.to_degrees();
    }
    let n = n.normalize();
    // The projection of u onto the arc's plane lies on the arc if it is between a and b.
    let q = u - n * u.dot(&n);
    if q.norm() < 1e-12 {
        return ends.to_degrees();
    }
    let q = q.normalize();
    let on_arc = (q.angle(a) + q.angle(b) - a.angle(b)).abs() < 1e-9;
    if on_arc {
        u.angle(&q).to_degrees()
    } else {
        ends.to_degrees()
    }
}

fn trim_line(name: &str, file: CurvesFile) {
    for m in MACHINES {
        let machine = Machine::read(fixture(&format!("machines/{m}"))).expect("machine");
        for dialect in DIALECTS {
            let what = format!("{name} on {m}, {}", dialect.name());
            // The head check off for every file here (the tilt cone's motion is asserted): up
            // trim_creases' flange the head's body meets the panel's faces (refused by
            // default; the head check has its own tests).
            let options = JobOptions::default()
                .with_place(PlaceMode::Auto)
                .with_dialect(dialect)
                .with_path(PathOptions::default().with_tilt_tolerance_deg(TILT_DEG))
                .with_cut_clearance_mm(None);
            let out = Job::new(file.clone(), machine.clone())
                .with_options(options)
                .run()
                .unwrap_or_else(|e| panic!("{what}: {e}"));
            assert_setpoints_within_limits(&what, &machine, &out, 0.001);
            assert_rotaries_within_the_poses(&what, &out);
            assert_in_the_cone(&what, &file, &machine, &out, TILT_DEG);
        }
    }
}

#[test]
fn the_domed_panel_through_the_pole_on_every_machine() {
    let file = curves::load(fixture("trim_panel.json")).expect("fixture");
    trim_line("trim_panel.json", file);
}

#[test]
fn the_creases_and_the_wall_on_every_machine() {
    let file = curves::load(fixture("trim_creases.json")).expect("fixture");
    trim_line("trim_creases.json", file);
}

#[test]
fn the_step_composite_over_six_faces_on_every_machine() {
    trim_line("step/trim_composite.step", step("step/trim_composite.step"));
}
