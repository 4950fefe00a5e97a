//! The side of the sheet a contour is cut from, chosen by its head lines (`--place auto`
//! with checked traverses): a hole's edge whose wall normal points into a hole narrower than
//! the nozzle's reach is cut from the other side, and its lead-in stays on the scrap side the
//! file names with the wall's own normal (checked in closed form in part coordinates).

use kerf_format::{
    CurveRecord, CurvesFile, ScrapSide, SurfaceGeometry, SurfaceRecord, SurfaceSource,
};
use kerf_kinematics::Machine;
use kerf_nurbs::{NurbsCurve, NurbsSurface};
use kerf_pipeline::{Job, JobOptions, PlaceMode};
use nalgebra::{Point3, Vector3};

mod common;
use common::fixture;

const R: f64 = 3.0;

/// A hole of radius `R` through a 2 mm sheet (its wall about the z axis, `0 <= z <= 2`, the
/// normal flipped to point into the hole: the wall's outward normal as a CAD face has it),
/// its edge at `z = 0` cut with the scrap on `side` (seen along the edge with the wall's
/// normal toward the viewer).
fn hole(side: ScrapSide) -> CurvesFile {
    let wall = NurbsSurface::cylinder(Point3::origin(), Vector3::z(), R, 2.0).expect("wall");
    let edge = NurbsCurve::circle(Point3::origin(), Vector3::z(), R).expect("edge");
    CurvesFile {
        warnings: Vec::new(),
        units: kerf_format::Units::Millimetres,
        curves: vec![CurveRecord::new("edge", edge)
            .with_surfaces(vec!["wall".into()])
            .with_scrap(Some(side))],
        surfaces: vec![SurfaceRecord {
            id: "wall".into(),
            geometry: SurfaceGeometry::Nurbs(wall),
            source: SurfaceSource::Inline,
            flip: true,
        }],
    }
}

/// The lead-in's points and tool axes in part coordinates (the placement undone).
fn lead_in(out: &kerf_pipeline::Output) -> Vec<(Point3<f64>, Vector3<f64>)> {
    let p = out.placement.placement_of(0);
    let (r, t) = (p.rotation(), p.translation_mm);
    out.axes.paths[0]
        .lead_in
        .as_ref()
        .expect("a lead-in")
        .poses
        .iter()
        .map(|q| {
            let pos = r.inverse() * (Point3::new(q[0], q[1], q[2]) - t);
            let axis = r.inverse() * Vector3::new(q[3], q[4], q[5]);
            (Point3::from(pos), axis)
        })
        .collect()
}

fn run(side: ScrapSide, checked: bool) -> kerf_pipeline::Output {
    let machine = Machine::read(fixture("machines/gantry_ac.json")).expect("machine");
    // The nozzle stands inside a 6 mm hole here (the wall alone stands for the part): the head
    // check would refuse it; the side choice is what is asserted.
    let mut opts = JobOptions::default()
        .with_place(PlaceMode::Auto)
        .with_cut_clearance_mm(None);
    if !checked {
        opts = opts.with_traverse(None);
    }
    Job::new(hole(side), machine)
        .with_options(opts)
        .run()
        .expect("run")
}

#[test]
fn a_hole_edge_is_cut_from_the_other_side_and_its_lead_in_stays_in_the_scrap() {
    for side in [ScrapSide::Left, ScrapSide::Right] {
        let out = run(side, true);
        assert_eq!(out.placement.plan.flipped, [true], "{side:?}: turned");
        let sides = &out.report.placement.sides;
        assert_eq!(sides[0].id, "edge", "{sides:?}");
        assert_eq!(sides[0].side, "other", "{sides:?}");
        assert!(
            sides[0].reason.contains("from the given side at"),
            "{sides:?}"
        );
        // Closed form: the edge runs counter-clockwise about +z, the wall's normal n points
        // to the axis, so n x t = -z: the left (scrap) side is below the sheet (z < 0), the
        // right side along the wall (z > 0). The lead-in lies in the tangent plane at its
        // start, which holds z: every point but the last (the start, on the edge) strictly
        // on the scrap side.
        let lead = lead_in(&out);
        assert!(lead.len() > 2, "{side:?}: {} lead-in points", lead.len());
        let sign = match side {
            ScrapSide::Left => -1.0,
            ScrapSide::Right => 1.0,
        };
        // The start: the cut's first point, on the edge.
        let pl = out.placement.placement_of(0);
        let q = out.axes.paths[0].poses[0];
        let start = pl.rotation().inverse() * (Point3::new(q[0], q[1], q[2]) - pl.translation_mm);
        assert!(
            (start.coords.xy().norm() - R).abs() < 1e-6 && start.z.abs() < 1e-6,
            "{start}"
        );
        let radial = Vector3::new(start.x, start.y, 0.0).normalize();
        for (p, axis) in &lead[..lead.len() - 1] {
            assert!(
                p.z * sign > 1e-6,
                "{side:?}: lead-in point {p} off the scrap side"
            );
            // The tool axis (the normal at the start) is reversed: out of the hole, within
            // the default tilt tolerance.
            assert!(
                axis.dot(&radial)
                    >= kerf_pipeline::DEFAULT_TILT_TOLERANCE_DEG.to_radians().cos() - 1e-12,
                "{side:?}: axis {axis} at {p}"
            );
        }
        // The same lead-in as without the side choice (unchecked traverses keep the given
        // side): turning the tool axes does not move it.
        let plain = run(side, false);
        assert_eq!(plain.placement.plan.flipped, [false], "{side:?}");
        let other = lead_in(&plain);
        assert_eq!(other.len(), lead.len(), "{side:?}");
        for ((p, a), (q, b)) in lead.iter().zip(&other) {
            assert!((p - q).norm() < 1e-6, "{side:?}: {p} against {q}");
            assert!((a + b).norm() < 1e-6, "{side:?}: axes {a} and {b} opposite");
        }
    }
}

#[test]
fn a_contour_under_a_roof_keeps_its_side_when_the_head_cannot_reach_the_other() {
    // A circle on a floor (normal +z) under a roof 10 mm up that another contour names: the
    // nozzle's line up meets the roof, the line down meets nothing, but a tool axis pointing
    // straight down is 180 degrees from up, beyond the head's +-135: the contour keeps its
    // side, and the report says why.
    let plate = |z: f64| {
        NurbsSurface::plane(
            Point3::new(-50.0, -50.0, z),
            Vector3::x(),
            Vector3::y(),
            100.0,
            100.0,
        )
        .expect("plate")
    };
    let (floor, roof) = (plate(0.0), plate(10.0));
    let record = |id: &str, curve: NurbsCurve, surface: &str| {
        CurveRecord::new(id, curve).with_surfaces(vec![surface.into()])
    };
    let surface = |id: &str, s: NurbsSurface| SurfaceRecord {
        id: id.into(),
        geometry: SurfaceGeometry::Nurbs(s),
        source: SurfaceSource::Inline,
        flip: false,
    };
    let file = CurvesFile {
        warnings: Vec::new(),
        units: kerf_format::Units::Millimetres,
        curves: vec![
            record(
                "under",
                NurbsCurve::circle(Point3::origin(), Vector3::z(), 20.0).expect("circle"),
                "floor",
            ),
            record(
                "on-roof",
                NurbsCurve::circle(Point3::new(0.0, 0.0, 10.0), Vector3::z(), 5.0).expect("circle"),
                "roof",
            ),
        ],
        surfaces: vec![surface("floor", floor), surface("roof", roof)],
    };
    let machine = Machine::read(fixture("machines/gantry_ac.json")).expect("machine");
    let out = Job::new(file, machine)
        .with_options(JobOptions::default().with_place(PlaceMode::Auto))
        .run()
        .expect("run");
    assert_eq!(out.placement.plan.flipped, [false, false]);
    let sides = &out.report.placement.sides;
    assert_eq!(sides.len(), 1, "{sides:?}");
    assert_eq!(sides[0].id, "under");
    assert_eq!(sides[0].side, "given");
    let why = &sides[0].reason;
    assert!(why.contains("cannot reach the other side"), "{why}");
    // The head lines (part coordinates): every point's line up meets the roof.
    let h = out.placement.head_lines[0];
    assert_eq!((h.given, h.other), (h.points, 0), "{h:?}");
}

#[test]
fn a_hole_wall_without_a_scrap_key_is_cut_along_the_holes_axis() {
    // The same hole, no scrap key: its wall (2 mm wide across the edge, straight across) is a
    // wall through the sheet. The beam runs along the hole's axis (z), the lead-in lies in the
    // sheet's face (z = 0) inside the hole, where the wall's normal points. With the rule off,
    // the tool axis is the wall's radial normal, as before.
    let machine = Machine::read(fixture("machines/gantry_ac.json")).expect("machine");
    let mut file = hole(ScrapSide::Left);
    file.curves[0].scrap = None;
    for max_wall in [4.0, 0.0] {
        let out = Job::new(file.clone(), machine.clone())
            .with_options(
                JobOptions::default()
                    .with_place(PlaceMode::Auto)
                    .with_wall_axis_max_mm(max_wall)
                    // The wall alone stands for the part; a radial beam puts the nozzle
                    // inside the hole (the head check would refuse it).
                    .with_cut_clearance_mm(None),
            )
            .run()
            .expect("run");
        let pl = out.placement.placement_of(0);
        let r = pl.rotation().inverse();
        let walls = out.report.placement.walls.as_ref().expect("walls");
        for q in &out.axes.paths[0].poses {
            let axis = r * Vector3::new(q[3], q[4], q[5]);
            if max_wall > 0.0 {
                // Either face of the sheet (the side is chosen for reach): along z.
                assert!((axis.z.abs() - 1.0).abs() < 1e-9, "axis {axis}");
            } else {
                assert!(axis.z.abs() < 1e-9, "the wall's normal: {axis}");
            }
        }
        if max_wall == 0.0 {
            assert!(walls.is_empty(), "{walls:?}");
            continue;
        }
        assert_eq!(walls.len(), 1, "{walls:?}");
        assert_eq!(walls[0].id, "edge");
        assert!((walls[0].width_mm - 2.0).abs() < 1e-9);
        let lead = lead_in(&out);
        assert!(lead.len() > 2, "{} lead-in points", lead.len());
        for (p, _) in &lead[..lead.len() - 1] {
            assert!(p.z.abs() < 1e-9, "in the sheet's face: {p}");
            assert!(p.coords.xy().norm() < R - 1e-6, "inside the hole: {p}");
        }
    }
}
