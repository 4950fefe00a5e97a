//! Placement of the part on the machine: the transform, and `auto_place` checked by solving
//! the placed paths against the real limits (the independent truth is the path solver with
//! every limit in force, and the exact extents of simple contours).

mod common;

use common::fixture;
use kerf_kinematics::{
    auto_place, auto_setups, axis_aligned_rotations, solve_path, AutoPlaceOptions, KinematicsError,
    Machine, PathInput, PathOptions, Placement, Pose,
};
use nalgebra::{Point3, Vector3};

/// A square contour of side `side` in the plane z = `z` around (`cx`, `cy`), tool axis `axis`.
fn square(cx: f64, cy: f64, z: f64, side: f64, axis: Vector3<f64>, n: usize) -> Vec<Pose> {
    let h = side / 2.0;
    let corners = [(-h, -h), (h, -h), (h, h), (-h, h), (-h, -h)];
    let mut out = Vec::new();
    for w in corners.windows(2) {
        for i in 0..n {
            let s = i as f64 / n as f64;
            let x = cx + w[0].0 + s * (w[1].0 - w[0].0);
            let y = cy + w[0].1 + s * (w[1].1 - w[0].1);
            out.push(Pose {
                position: Point3::new(x, y, z),
                axis,
            });
        }
    }
    out
}

/// Solves the placed paths against the machine's real limits; returns the linear axis extents.
fn solve_placed(machine: &Machine, paths: &[Vec<Pose>]) -> [[f64; 2]; 3] {
    let mut ext = [[f64::INFINITY, f64::NEG_INFINITY]; 3];
    for (i, p) in paths.iter().enumerate() {
        let id = format!("p{i}");
        let s = solve_path(
            machine,
            &PathInput {
                id: &id,
                poses: p,
                curve: None,
            },
            &PathOptions::default(),
        )
        .unwrap_or_else(|e| panic!("placed path {i} must solve within the limits: {e}"));
        for a in &s.axes {
            let q = a.to_array();
            for k in 0..3 {
                ext[k][0] = ext[k][0].min(q[k]);
                ext[k][1] = ext[k][1].max(q[k]);
            }
        }
    }
    ext
}

#[test]
fn transform_rotates_then_translates() {
    let p = Placement::new(Vector3::new(1.0, 2.0, 3.0), [0.0, 0.0, 90.0]);
    let q = p.apply_point(&Point3::new(1.0, 0.0, 0.0));
    assert!(
        (q - Point3::new(1.0, 3.0, 3.0)).norm() < 1e-12,
        "Rz(90) x = y: {q}"
    );
    // Rz Ry Rx order: x first. Rx(90) takes y to z, then Rz(90) leaves z.
    let p = Placement::new(Vector3::zeros(), [90.0, 0.0, 90.0]);
    let u = p.apply_pose(&Pose::new(0.0, 0.0, 0.0, 0.0, 1.0, 0.0));
    assert!((u.axis - Vector3::z()).norm() < 1e-12, "{:?}", u.axis);
    assert_eq!(
        Placement::parse("10, -20.5, 3").expect("three values"),
        Placement::new(Vector3::new(10.0, -20.5, 3.0), [0.0; 3])
    );
    assert_eq!(
        Placement::parse("0,0,0,90,0,-90")
            .expect("six values")
            .rotation_deg,
        [90.0, 0.0, -90.0]
    );
    for bad in ["1,2", "1,2,x", "1,2,3,4", "1,2,nan", "1,2,1e30"] {
        assert!(Placement::parse(bad).is_err(), "{bad} must be refused");
    }
}

#[test]
fn twenty_four_distinct_axis_rotations_identity_first() {
    let r = axis_aligned_rotations();
    assert_eq!(r.len(), 24, "the rotation group of the cube");
    assert_eq!(r[0], [0.0; 3], "identity first");
    for (i, a) in r.iter().enumerate() {
        let ma = Placement::new(Vector3::zeros(), *a).rotation().into_inner();
        assert!((ma.determinant() - 1.0).abs() < 1e-12, "proper rotation");
        for b in &r[i + 1..] {
            let mb = Placement::new(Vector3::zeros(), *b).rotation().into_inner();
            assert!(
                (ma - mb).amax() > 0.5,
                "{a:?} and {b:?} are the same rotation"
            );
        }
    }
}

#[test]
fn head_machine_centres_the_motion_envelope() {
    let m = fixture("ac_head.json");
    // A 400 mm square 1,000 mm below the travel, tool axis tilted 20 deg: reachable only
    // after a translation.
    let a = 20f64.to_radians();
    let axis = Vector3::new(a.sin(), 0.0, a.cos());
    let paths = vec![square(3000.0, -2000.0, -1000.0, 400.0, axis, 10)];
    let refs: Vec<(&str, &[Pose])> = vec![("sq", &paths[0])];
    let found = auto_place(&m, &refs, &AutoPlaceOptions::default()).expect("fits");
    assert_eq!(found.placement.rotation_deg, [0.0; 3], "no rotation needed");
    assert_eq!(found.flipped, [false], "the given side is reachable");
    let ext = solve_placed(&m, &found.apply(&paths));
    for k in 0..3 {
        let r = m.limits[k].expect("limited");
        let mid_env = 0.5 * (ext[k][0] + ext[k][1]);
        let mid_travel = 0.5 * (r.min + r.max);
        assert!(
            (mid_env - mid_travel).abs() < 1e-6,
            "axis {k}: envelope centre {mid_env} vs travel centre {mid_travel}"
        );
    }
    assert!(
        found.clearance_mm >= 1.0 - 1e-9,
        "margin kept: {}",
        found.clearance_mm
    );
}

#[test]
fn too_tall_part_names_the_axis_and_the_shortfall() {
    let m = fixture("ac_head.json"); // Z travel [-100, 600]: 700 mm.
    let up = Vector3::z();
    // Two flat squares 2,000 mm apart in z.
    let paths = vec![
        square(0.0, 0.0, 0.0, 100.0, up, 4),
        square(0.0, 0.0, 2000.0, 100.0, up, 4),
    ];
    let refs: Vec<(&str, &[Pose])> = vec![("low", &paths[0]), ("high", &paths[1])];
    let err = auto_place(&m, &refs, &AutoPlaceOptions::default().with_rotate(false))
        .expect_err("2,000 mm of Z motion cannot fit 700 mm of travel");
    match &err {
        KinematicsError::NoPlacement { axis, missing, .. } => {
            assert_eq!(*axis, "Z", "{err}");
            // Tool axis vertical: the Z axis moves exactly as the tip does.
            assert!((missing - (2000.0 - (700.0 - 2.0))).abs() < 1e-6, "{err}");
        }
        other => panic!("expected NoPlacement, got {other}"),
    }
    assert!(err.to_string().contains("Z is 1302.000 short"), "{err}");
    // Rotating the part lays the stack down: the 2,000 mm go along X (3,000 mm of travel); the
    // flat squares become vertical walls, their tool axes horizontal (A = 90 deg, reachable).
    let found = auto_place(&m, &refs, &AutoPlaceOptions::default()).expect("fits rotated");
    assert_ne!(
        found.placement.rotation_deg, [0.0; 3],
        "a rotation was needed"
    );
    let placed = found.apply(&paths);
    let ext = solve_placed(&m, &placed);
    assert!(ext[2][1] - ext[2][0] < 700.0, "Z envelope {ext:?}");
}

#[test]
fn contours_facing_down_are_cut_from_the_reachable_side() {
    let m = fixture("gantry_ac.json"); // A within +-135 deg: straight down is out of reach.
    let down = -Vector3::z();
    let paths = vec![
        square(0.0, 0.0, 0.0, 50.0, down, 4),
        square(200.0, 0.0, 0.0, 50.0, Vector3::z(), 4),
    ];
    let refs: Vec<(&str, &[Pose])> = vec![("down", &paths[0]), ("up", &paths[1])];
    let found = auto_place(&m, &refs, &AutoPlaceOptions::default()).expect("fits");
    assert_eq!(
        found.flipped,
        [true, false],
        "only the downward contour turns over"
    );
    let placed = found.apply(&paths);
    assert!(
        placed[0].iter().all(|p| p.axis.z > 0.999),
        "beam from above"
    );
    solve_placed(&m, &placed);
    // Without flipping, the downward contour cannot be reached: the error says by how much.
    let err = auto_place(
        &m,
        &refs,
        &AutoPlaceOptions::default()
            .with_flip(false)
            .with_rotate(false),
    )
    .expect_err("A would need 180 deg");
    assert!(
        // 180 deg against 135 (the default tilt margin is 0).
        matches!(err, KinematicsError::NoPlacement { axis: "A", missing, .. } if (missing - 45.0).abs() < 1e-6),
        "{err}"
    );
}

#[test]
fn tilt_out_of_reach_on_both_sides_is_a_named_error() {
    let text = r#"{"format": "kerf.machine/1", "name": "shallow head",
        "kinematics": { "type": "ac-head", "r_a": 150.0, "r_c": 0.0 },
        "limits": { "X": [-1000, 1000], "Y": [-1000, 1000], "Z": [-500, 500], "A": [-30, 30], "C": null },
        "max_velocity": { "X": 60000, "Y": 60000, "Z": 30000, "A": 36000, "C": 36000 },
        "max_acceleration": { "X": 10000, "Y": 10000, "Z": 8000, "A": 20000, "C": 20000 }}"#;
    let m = Machine::from_str(text).expect("machine");
    let wall = vec![square(0.0, 0.0, 0.0, 20.0, Vector3::x(), 3)];
    let refs: Vec<(&str, &[Pose])> = vec![("wall", &wall[0])];
    let err = auto_place(&m, &refs, &AutoPlaceOptions::default().with_rotate(false))
        .expect_err("90 deg of tilt on a 30 deg head");
    assert!(
        // 90 deg against 30 (the default tilt margin is 0).
        matches!(err, KinematicsError::NoPlacement { axis: "A", missing, .. } if (missing - 60.0).abs() < 1e-6),
        "{err}"
    );
    // With rotations the wall is laid flat and fits.
    let found = auto_place(&m, &refs, &AutoPlaceOptions::default()).expect("rotated");
    solve_placed(&m, &found.apply(&wall));
}

#[test]
fn table_machine_placement_is_verified_against_the_limits() {
    for file in ["table_table.json", "head_table.json"] {
        let m = fixture(file);
        let a = 30f64.to_radians();
        // Tilted tool axes around a contour far from the table's centre.
        let mut poses = Vec::new();
        for i in 0..36 {
            let phi = (i as f64 * 10.0).to_radians();
            poses.push(Pose {
                position: Point3::new(900.0 + 60.0 * phi.cos(), -700.0 + 60.0 * phi.sin(), 300.0),
                axis: Vector3::new(a.sin() * phi.cos(), a.sin() * phi.sin(), a.cos()),
            });
        }
        let paths = vec![poses];
        let refs: Vec<(&str, &[Pose])> = vec![("ring", &paths[0])];
        let found = auto_place(&m, &refs, &AutoPlaceOptions::default())
            .unwrap_or_else(|e| panic!("{file}: {e}"));
        assert!(
            found.clearance_mm >= 1.0 - 1e-6,
            "{file}: {}",
            found.clearance_mm
        );
        solve_placed(&m, &found.apply(&paths));
    }
}

/// Four small flat squares (tool axis +z) in a row along x, `spacing` apart: a row too long
/// for the machine, each half of it short enough.
fn row(spacing: f64) -> Vec<Vec<Pose>> {
    (0..4)
        .map(|i| square(spacing * f64::from(i), 0.0, 0.0, 10.0, Vector3::z(), 4))
        .collect()
}

/// `auto_setups` on `paths`: the plan, every set-up verified by solving its placed paths
/// against the real limits.
fn setups_verified(
    m: &Machine,
    paths: &[Vec<Pose>],
    options: &AutoPlaceOptions,
) -> kerf_kinematics::SetupPlan {
    let ids: Vec<String> = (0..paths.len()).map(|i| format!("p{i}")).collect();
    let refs: Vec<(&str, &[Pose])> = ids
        .iter()
        .map(String::as_str)
        .zip(paths.iter().map(Vec::as_slice))
        .collect();
    let plan = auto_setups(m, &refs, options).expect("set-ups");
    let placed = plan.apply(paths);
    for s in &plan.setups {
        let group: Vec<Vec<Pose>> = s.paths.iter().map(|&i| placed[i].clone()).collect();
        solve_placed(m, &group);
    }
    plan
}

#[test]
fn set_ups_solve_each_path_once_per_orientation_however_many_levels_try_it() {
    // A table machine (no cheap travel bound: the linear axes do not follow the tip one to
    // one), the part as modelled only: 4 squares 500 mm apart along x need 1,510 mm of X, the
    // machine has 800. The whole part is solved (4 paths) and does not fit; its one
    // orientation group is the whole part again (no new solve), then each half fits: its
    // paths' free solves are the ones already made, only the check against the limits is
    // new (4). Each path: one free solve, one check: 8 in all (16 if every level solved
    // again).
    let m = fixture("table_table.json");
    let plan = setups_verified(
        &m,
        &row(500.0),
        &AutoPlaceOptions::default().with_rotate(false),
    );
    assert_eq!(plan.setups.len(), 2, "{plan:?}");
    assert_eq!(plan.paths_solved, 8, "{plan:?}");
}

#[test]
fn orientations_that_cannot_fit_the_travel_are_refused_before_any_solve() {
    // A head machine: 4 squares 2,000 mm apart along x need 6,010 mm of travel in some axis
    // whichever way the part is turned (5,000 mm of X at most). Every candidate orientation of
    // the whole part (24 quarter turns and the general ones) is refused by the travel of its
    // cutting points alone; each half fits as modelled: 2 solves per path (free, check), 8 in
    // all. Solving each refused candidate would cost 4 paths each.
    let m = fixture("gantry_ac.json");
    let plan = setups_verified(&m, &row(2000.0), &AutoPlaceOptions::default());
    assert_eq!(plan.setups.len(), 2, "{plan:?}");
    assert!(plan.rotations_tried > 24, "{}", plan.rotations_tried);
    assert_eq!(plan.paths_solved, 8, "{plan:?}");
    // auto_place's error solves (no bound): the shortfall of the best candidate, at most that
    // of the part as modelled, laid along X (6,010 - 4,998 mm: the tool axes are vertical,
    // so X moves exactly as the tips do).
    let paths = row(2000.0);
    let refs: Vec<(&str, &[Pose])> = paths.iter().map(|p| ("p", p.as_slice())).collect();
    let err = auto_place(&m, &refs, &AutoPlaceOptions::default()).expect_err("too long");
    let as_modelled = auto_place(&m, &refs, &AutoPlaceOptions::default().with_rotate(false))
        .expect_err("too long");
    assert!(
        matches!(as_modelled, KinematicsError::NoPlacement { axis: "X", missing, .. } if (missing - (6010.0 - 4998.0)).abs() < 1e-6),
        "{as_modelled}"
    );
    match &err {
        KinematicsError::NoPlacement { axis, missing, .. } => {
            assert_eq!(*axis, "X", "{err}");
            assert!(
                *missing > 0.0 && *missing <= 6010.0 - 4998.0 + 1e-6,
                "{err}"
            );
        }
        other => panic!("expected NoPlacement, got {other}"),
    }
}
