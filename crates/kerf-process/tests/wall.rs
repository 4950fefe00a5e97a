//! Contours on a thin wall through the sheet (`wall_axis`), against exact geometry: a hole's
//! cylindrical wall (the tool axis must be the hole's axis, the scrap its inside), a round
//! part's edge face (scrap outside), and what is not a wall: a fillet as narrow (its normal
//! turns across it) and a bend as long as a flange.

use kerf_nurbs::NurbsSurface;
use kerf_process::{wall_axis, Pose, Side};
use nalgebra::{Point3, Vector3};

const R: f64 = 5.0;
const THICK: f64 = 2.0;

/// The hull of a NURBS surface (its control points) and its normal at the point nearest a
/// point, as the pipeline passes them.
fn hull(s: &NurbsSurface) -> Vec<Point3<f64>> {
    s.control_points().iter().flatten().copied().collect()
}

fn normal_near(s: &NurbsSurface) -> impl Fn(&Point3<f64>) -> Option<Vector3<f64>> + '_ {
    move |q| {
        let c = s.closest_point(q, None);
        s.normal(c.u, c.v)
    }
}

/// The rim of a wall about the z axis at height `z`, counter-clockwise seen from +z, 73 points
/// (closed), with the unit normal `sign * r` (`r` radial outward).
fn rim(z: f64, sign: f64) -> Vec<Pose> {
    (0..=72)
        .map(|k| {
            let a = f64::from(k) * std::f64::consts::TAU / 72.0;
            let (s, c) = a.sin_cos();
            Pose::new(R * c, R * s, z, sign * c, sign * s, 0.0)
        })
        .collect()
}

#[test]
fn a_hole_wall_is_cut_along_the_holes_axis_with_the_scrap_inside() {
    // The wall of a hole through a 2 mm sheet: Su x Sv outward from the axis; a hole's face
    // has the other orientation (out of the material, into the hole).
    let wall = NurbsSurface::cylinder(Point3::origin(), Vector3::z(), R, THICK).expect("cylinder");
    let into_hole = |q: &Point3<f64>| normal_near(&wall)(q).map(|n| -n);
    // The contour on the upper face (z = 2): the wall lies below it, the head above (+z); on
    // the lower face (z = 0) the other way. Seen from the head, a counter-clockwise rim has
    // the hole on the left from above, on the right from below.
    for (z, axis, scrap) in [(THICK, 1.0, Side::Left), (0.0, -1.0, Side::Right)] {
        let poses = rim(z, -1.0);
        let w = wall_axis(&hull(&wall), &poses, 4.0, &into_hole).expect("a thin wall");
        for p in &w.poses {
            let a = p.axis;
            assert!(
                (a - Vector3::z() * axis).norm() < 1e-9,
                "z = {z}: axis {a:?}"
            );
        }
        assert_eq!(w.scrap, scrap, "z = {z}");
        assert!((w.width_mm - THICK).abs() < 1e-9, "{}", w.width_mm);
        // The scrap side with the new axis is the hole's inside: at the rim's point (R, 0, z)
        // the tangent is +y, left is axis x tangent, the inside is -x.
        let left = (Vector3::z() * axis).cross(&Vector3::y());
        let side = if left.dot(&-Vector3::x()) > 0.0 {
            Side::Left
        } else {
            Side::Right
        };
        assert_eq!(side, scrap, "the inside is on the scrap side");
        // Wider than allowed: not a wall.
        assert!(wall_axis(&hull(&wall), &poses, 1.9, &into_hole).is_none());
    }
}

#[test]
fn a_round_parts_edge_face_is_cut_along_it_with_the_scrap_outside() {
    let edge = NurbsSurface::cylinder(Point3::origin(), Vector3::z(), R, THICK).expect("edge");
    let poses = rim(THICK, 1.0); // outward normals: the material is inside
    let w = wall_axis(&hull(&edge), &poses, 4.0, &normal_near(&edge)).expect("a thin wall");
    for p in &w.poses {
        assert!((p.axis - Vector3::z()).norm() < 1e-9);
    }
    // Head above, counter-clockwise: the outside is on the right.
    assert_eq!(w.scrap, Side::Right);
}

#[test]
fn a_fillet_and_a_long_bend_are_not_walls() {
    // A quarter-cylinder fillet of radius 1.5 along x (its normal turning from +z to +y
    // across it), the contour along its upper edge: 1.5 mm wide across, but not straight.
    let fillet = NurbsSurface::try_new(
        2,
        1,
        vec![0.0, 0.0, 0.0, 1.0, 1.0, 1.0],
        vec![0.0, 0.0, 1.0, 1.0],
        vec![
            vec![Point3::new(0.0, 0.0, 1.5), Point3::new(50.0, 0.0, 1.5)],
            vec![Point3::new(0.0, 1.5, 1.5), Point3::new(50.0, 1.5, 1.5)],
            vec![Point3::new(0.0, 1.5, 0.0), Point3::new(50.0, 1.5, 0.0)],
        ],
        Some(vec![
            vec![1.0, 1.0],
            vec![std::f64::consts::FRAC_1_SQRT_2; 2],
            vec![1.0, 1.0],
        ]),
    )
    .expect("fillet");
    let along: Vec<Pose> = (0..=50)
        .map(|k| Pose::new(f64::from(k), 0.0, 1.5, 0.0, 0.0, 1.0))
        .collect();
    let hull_f = hull(&fillet);
    assert!(
        wall_axis(&hull_f, &along, 4.0, &normal_near(&fillet)).is_none(),
        "the fillet's normal turns across it"
    );
    // Had it been straight across (the normal kept), the width alone would have passed: the
    // straightness test is what refuses it.
    let flat = |_: &Point3<f64>| Some(Vector3::z());
    assert!(wall_axis(&hull_f, &along, 4.0, &flat).is_some());
    // A bend 20 mm long (the flange's width), its edge arc: far wider than a sheet.
    let bend = NurbsSurface::cylinder(Point3::origin(), Vector3::z(), R, 20.0).expect("bend");
    assert!(wall_axis(&hull(&bend), &rim(20.0, 1.0), 4.0, &normal_near(&bend)).is_none());
}

#[test]
fn bad_input_is_not_a_wall() {
    let wall = NurbsSurface::cylinder(Point3::origin(), Vector3::z(), R, THICK).expect("cylinder");
    let near = normal_near(&wall);
    let poses = rim(THICK, 1.0);
    assert!(
        wall_axis(&hull(&wall), &poses[..1], 4.0, &near).is_none(),
        "one point"
    );
    assert!(wall_axis(&[], &poses, 4.0, &near).is_none(), "no hull");
    assert!(
        wall_axis(&hull(&wall), &poses, f64::NAN, &near).is_none(),
        "NaN width"
    );
    assert!(wall_axis(&hull(&wall), &poses, 0.0, &near).is_none(), "off");
    let mut bad = poses.clone();
    bad[5].position.x = f64::NAN;
    assert!(
        wall_axis(&hull(&wall), &bad, 4.0, &near).is_none(),
        "NaN point"
    );
    // The normal along the contour: no wall direction.
    let along: Vec<Pose> = (0..10)
        .map(|k| Pose::new(f64::from(k), 0.0, 0.0, 1.0, 0.0, 0.0))
        .collect();
    assert!(
        wall_axis(&hull(&wall), &along, 4.0, &near).is_none(),
        "normal along t"
    );
}
