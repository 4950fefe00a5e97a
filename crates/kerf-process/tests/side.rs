//! Which side of the sheet the head reaches a cut from (`head_lines`), against closed-form
//! geometry: a hole's wall (an exact NURBS cylinder) cut along its edge with the wall's
//! normal pointing into the hole, so the nozzle's line crosses the hole and meets the far
//! wall; from the other side nothing is there, unless a plate is put in the way.

use kerf_nurbs::NurbsSurface;
use kerf_process::{head_lines, Obstacles, Pose, TraverseOptions};
use nalgebra::{Point3, Vector3};

const R: f64 = 3.0;

/// The hole's wall: radius `R` about the z axis, `0 <= z <= 2`.
fn wall() -> NurbsSurface {
    NurbsSurface::cylinder(Point3::origin(), Vector3::z(), R, 2.0).expect("cylinder")
}

/// The hole's edge at `z = 0`, `n` points, the tool axis the wall's normal into the hole.
fn edge(n: usize) -> Vec<Pose> {
    (0..=n)
        .map(|k| {
            let a = std::f64::consts::TAU * k as f64 / n as f64;
            Pose::new(R * a.cos(), R * a.sin(), 0.0, -a.cos(), -a.sin(), 0.0)
        })
        .collect()
}

#[test]
fn a_nozzle_across_a_narrow_hole_meets_its_far_wall_and_the_other_side_is_clear() {
    let opts = TraverseOptions::default();
    let mut obs = Obstacles::new();
    obs.add_nurbs(wall());
    let h = head_lines(&obs, &edge(40), &opts);
    assert_eq!(h.points, 41, "every point of a short contour");
    // Closed form: the line into the hole from 3/4 of the clearance (3.75 mm) on is
    // 2R - 3.75 = 2.25 mm from the far wall there, under half the clearance (2.5 mm).
    assert_eq!(h.given, 41, "{h:?}");
    assert!(
        (h.given_from_mm - 0.75 * opts.clearance_mm).abs() < 1e-12,
        "{h:?}"
    );
    // Outwards the nearest point of the wall is the line's foot: s >= 3.75 mm away.
    assert_eq!(h.other, 0, "{h:?}");
    assert!(h.prefers_other_side());
}

#[test]
fn a_plate_on_the_other_side_makes_both_sides_meet_the_part() {
    // A plate across x = R + 15: the outward line from angle a reaches x = (R + s) cos a, so
    // it comes within half the clearance of the plate (its end, s = retract + nozzle, is its
    // nearest point) where (R + 15) - (R + 27.5) cos a < 2.5.
    let opts = TraverseOptions::default();
    let mut obs = Obstacles::new();
    obs.add_nurbs(wall());
    let x = R + 15.0;
    obs.add_nurbs(
        NurbsSurface::plane(
            Point3::new(x, -200.0, -200.0),
            Vector3::y(),
            Vector3::z(),
            400.0,
            400.0,
        )
        .expect("plate"),
    );
    let poses = edge(40);
    let reach = opts.retract_mm + opts.nozzle_mm;
    let want = poses
        .iter()
        .filter(|p| x - (R + reach) * (-p.axis.x) < 0.5 * opts.clearance_mm)
        .count();
    assert!(
        want > 0 && want < 41,
        "the plate is in reach of some lines: {want}"
    );
    let h = head_lines(&obs, &poses, &opts);
    assert_eq!((h.given, h.other), (41, want), "{h:?}");
    assert!(!h.prefers_other_side(), "both sides meet the part");
    // The first meeting: along the line at angle 0, past s = 15 - 2.5 = 12.5 mm (strictly
    // closer than half the clearance), found by samples a quarter of the clearance apart.
    assert!(
        h.other_from_mm > 12.5 && h.other_from_mm <= 12.5 + 1.25 + 1e-9,
        "{h:?}"
    );
}

#[test]
fn a_flat_sheet_meets_nothing_and_bad_input_is_harmless() {
    let opts = TraverseOptions::default();
    let mut obs = Obstacles::new();
    obs.add_nurbs(
        NurbsSurface::plane(
            Point3::new(-50.0, -50.0, 0.0),
            Vector3::x(),
            Vector3::y(),
            100.0,
            100.0,
        )
        .expect("sheet"),
    );
    let on_sheet: Vec<Pose> = (0..10)
        .map(|k| Pose::new(f64::from(k), 0.0, 0.0, 0.0, 0.0, 1.0))
        .collect();
    let h = head_lines(&obs, &on_sheet, &opts);
    assert_eq!((h.points, h.given, h.other), (10, 0, 0), "{h:?}");
    assert!(!h.prefers_other_side());
    // No points, a zero axis, a non-finite point: nothing counted, no panic.
    assert_eq!(head_lines(&obs, &[], &opts).points, 0);
    let bad = [
        Pose::new(0.0, 0.0, 0.0, 0.0, 0.0, 0.0),
        Pose::new(f64::NAN, 0.0, 0.0, 0.0, 0.0, 1.0),
    ];
    let h = head_lines(&obs, &bad, &opts);
    assert_eq!((h.given, h.other), (0, 0), "{h:?}");
}
