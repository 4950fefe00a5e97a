//! The head against the part while it cuts (`kerf_process::check_cut`), against exact
//! distances: a hole in a floor near the foot of a vertical wall, whose distance to the
//! head's body is `x_wall - (r cos theta + 45)` at the hole's point of angle `theta`.

use kerf_kinematics::{Head, Pose};
use kerf_nurbs::NurbsSurface;
use kerf_process::{check_cut, HeadCheckOptions, Obstacles};
use nalgebra::{Point3, Vector3};

const HOLE_R: f64 = 5.0;
/// The default head's body: 45 mm radius from 26 mm above the cutting point (1 mm standoff
/// plus the 25 mm nozzle cone).
const BODY_R: f64 = 45.0;

fn floor() -> NurbsSurface {
    NurbsSurface::plane(
        Point3::new(-300.0, -300.0, 0.0),
        Vector3::x(),
        Vector3::y(),
        600.0,
        600.0,
    )
    .expect("floor")
}

/// A wall at `x`, 60 mm high, 600 mm long.
fn wall(x: f64) -> NurbsSurface {
    NurbsSurface::plane(
        Point3::new(x, -300.0, 0.0),
        Vector3::y(),
        Vector3::z(),
        600.0,
        60.0,
    )
    .expect("wall")
}

/// A hole of radius 5 about the origin, the beam vertical (axis tilted by `tilt_deg` about y).
fn hole(n: usize, tilt_deg: f64) -> Vec<Pose> {
    let a = tilt_deg.to_radians();
    (0..=n)
        .map(|k| {
            let t = std::f64::consts::TAU * k as f64 / n as f64;
            Pose {
                position: Point3::new(HOLE_R * t.cos(), HOLE_R * t.sin(), 0.0),
                axis: Vector3::new(a.sin(), 0.0, a.cos()),
            }
        })
        .collect()
}

/// The exact distance from the vertical head's body to the wall at `x` at angle `t`.
fn exact(x: f64, t: f64) -> f64 {
    x - (HOLE_R * t.cos() + BODY_R)
}

#[test]
fn a_flat_floor_alone_keeps_the_clearance_at_any_tilt_within_the_tip_zone() {
    let mut obs = Obstacles::new();
    obs.add_nurbs(floor());
    let head = Head::laser_default();
    for tilt in [0.0, 5.0, 10.0] {
        let r = check_cut(&obs, &head, &hole(32, tilt), &HeadCheckOptions::default());
        assert!(r.proven, "tilt {tilt}: proven");
        assert!(r.close.is_empty(), "tilt {tilt}: {:?}", r.close);
        let floor_mm = 1.0 - kerf_process::RESOLUTION_MM - kerf_process::SAMPLE_STEP_MM / 2.0;
        assert!(
            r.min_distance_mm >= floor_mm,
            "tilt {tilt}: bound {} below the clearance less the resolution",
            r.min_distance_mm
        );
        // The nozzle's lowest 1.4 mm or so is the tip zone at 10 degrees (docs/process.md).
        assert!(
            r.tip_zone_mm > 0.0 && r.tip_zone_mm < 3.0,
            "tip zone {}",
            r.tip_zone_mm
        );
    }
}

#[test]
fn a_wall_beside_the_hole_is_found_where_the_body_comes_within_the_clearance() {
    let head = Head::laser_default();
    let opts = HeadCheckOptions::default();
    let n = 72;
    let poses = hole(n, 0.0);
    for x in [53.0, 51.3, 50.5, 49.0] {
        let mut obs = Obstacles::new();
        obs.add_nurbs(floor());
        obs.add_nurbs(wall(x));
        let r = check_cut(&obs, &head, &poses, &opts);
        assert!(r.proven, "x {x}: proven");
        let truth = (0..=n)
            .map(|k| exact(x, std::f64::consts::TAU * k as f64 / n as f64))
            .fold(f64::INFINITY, f64::min);
        // The bound is a lower bound of the exact distance, over poses and the motion.
        if r.close.is_empty() {
            assert!(
                r.min_distance_mm <= truth + 1e-9,
                "x {x}: bound {} above the exact {truth}",
                r.min_distance_mm
            );
        }
        let inside = |k: usize| r.close.iter().any(|c| c.poses[0] <= k && k <= c.poses[1]);
        for k in 0..=n {
            let d = exact(x, std::f64::consts::TAU * k as f64 / n as f64);
            // Reported where a head point (a cell centre, within the resolution of the
            // nearest) is witnessed closer than the clearance.
            if d < opts.clearance_mm - kerf_process::RESOLUTION_MM {
                assert!(inside(k), "x {x}: pose {k} at {d} mm not reported");
            }
            // Not reported where the head clears by more than a sample step's slack.
            if d > opts.clearance_mm {
                assert!(!inside(k), "x {x}: pose {k} at {d} mm reported close");
            }
        }
        if truth >= opts.clearance_mm {
            assert!(r.close.is_empty(), "x {x}: {:?}", r.close);
        } else {
            let c = &r.close[0];
            assert_eq!(c.surface.as_deref(), Some("#1"), "x {x}: the wall is named");
            assert!(
                c.at_height_mm >= 25.0,
                "x {x}: the body ({} mm up) meets the wall",
                c.at_height_mm
            );
            // A head point witnessed within the clearance, no closer than the exact minimum.
            assert!(
                c.distance_mm < opts.clearance_mm && c.distance_mm >= truth - 1e-9,
                "x {x}: {c:?}"
            );
        }
    }
}

#[test]
fn a_slot_narrower_than_the_nozzle_is_close_everywhere_and_the_work_is_bounded() {
    let head = Head::laser_default();
    let mut obs = Obstacles::new();
    obs.add_nurbs(floor());
    obs.add_nurbs(wall(8.0));
    obs.add_nurbs(wall(-8.0));
    let poses = hole(24, 0.0);
    let r = check_cut(&obs, &head, &poses, &HeadCheckOptions::default());
    assert_eq!(r.close.len(), 1, "{:?}", r.close);
    assert_eq!(r.close[0].poses, [0, 24], "the whole hole");
    assert!(r.close[0].distance_mm < 1.0, "{:?}", r.close[0]);
    // The query budget bounds the work, whatever the geometry.
    let tight = HeadCheckOptions::default().with_max_queries(50);
    let r = check_cut(&obs, &head, &poses, &tight);
    assert!(!r.proven, "the budget ran out");
    assert!(r.queries <= 50, "{} queries", r.queries);
}

/// A low wall beside the nozzle cone (10 mm high, 3.6 mm from the axis): the cone's radius at
/// the wall's top (9 mm above the nozzle tip) is 1.5 + 5.5 x 9 / 25 = 3.48 mm, so the wall's
/// edge passes 0.12 mm from it, within the clearance less the resolution: a witness on the
/// nozzle, not the body.
#[test]
fn a_low_wall_beside_the_nozzle_cone_is_witnessed_on_the_cone() {
    let head = Head::laser_default();
    let mut obs = Obstacles::new();
    obs.add_nurbs(floor());
    obs.add_nurbs(
        NurbsSurface::plane(
            Point3::new(3.6, -100.0, 0.0),
            Vector3::y(),
            Vector3::z(),
            200.0,
            10.0,
        )
        .expect("low wall"),
    );
    let pose = [Pose {
        position: Point3::origin(),
        axis: Vector3::z(),
    }];
    let r = check_cut(&obs, &head, &pose, &HeadCheckOptions::default());
    assert_eq!(r.close.len(), 1, "{r:?}");
    let c = &r.close[0];
    assert!(c.at_height_mm < 25.0, "on the nozzle cone: {c:?}");
    assert!(c.distance_mm < 1.0 && c.distance_mm >= 0.11, "{c:?}");
}

#[test]
fn unusable_inputs_are_not_proven_clear() {
    let head = Head::laser_default();
    let mut obs = Obstacles::new();
    obs.add_nurbs(floor());
    let poses = hole(8, 0.0);
    // A clearance whose tip zone swallows the nozzle: the check would see nothing of it.
    let r = check_cut(
        &obs,
        &head,
        &poses,
        &HeadCheckOptions::default().with_clearance_mm(30.0),
    );
    assert!(!r.proven, "{r:?}");
    assert!(
        r.unproven
            .as_deref()
            .is_some_and(|w| w.contains("too large for this head")),
        "{r:?}"
    );
    // A pose that is not finite, an infinite path deviation.
    let mut bad = poses.clone();
    bad[3].position.x = f64::NAN;
    assert!(!check_cut(&obs, &head, &bad, &HeadCheckOptions::default()).proven);
    let inf = HeadCheckOptions::default().with_path_deviation_mm(f64::INFINITY);
    assert!(!check_cut(&obs, &head, &poses, &inf).proven);
}

/// The tool axis of paper 000's A/C head at `a`, `c` (radians).
fn ac_axis(a: f64, c: f64) -> Vector3<f64> {
    Vector3::new(a.sin() * c.sin(), -a.sin() * c.cos(), a.cos())
}

#[test]
fn the_rotary_departure_bounds_the_linear_move_of_an_ac_head() {
    // Independent truth: the A/C head's axis under linear A and C interpolation, sampled
    // densely, against the great circle between its ends: the largest angle between them
    // never exceeds `rotary_departure_rad`, and on a 10-degree C step at 45 degrees of tilt
    // (the figure docs/process.md quoted, 0.11 deg) the bound is within a few times of it.
    let mut worst_ratio: f64 = 0.0;
    for (a0, a1, c0, c1) in [
        (45.0, 45.0, 0.0, 10.0),
        (10.0, 30.0, -20.0, 40.0),
        (80.0, 5.0, 0.0, 90.0),
        (1.0, 1.0, 0.0, 180.0),
        (30.0, 35.0, 100.0, 101.0),
        (60.0, -60.0, 0.0, 0.0),
    ] {
        let (a0, a1, c0, c1): (f64, f64, f64, f64) = (
            f64::to_radians(a0),
            f64::to_radians(a1),
            f64::to_radians(c0),
            f64::to_radians(c1),
        );
        let (p, q) = (ac_axis(a0, c0), ac_axis(a1, c1));
        let angle = p.angle(&q);
        let rot = nalgebra::UnitQuaternion::rotation_between(&p, &q)
            .unwrap_or_else(nalgebra::UnitQuaternion::identity);
        let mut worst: f64 = 0.0;
        for k in 0..=2000 {
            let s = k as f64 / 2000.0;
            let linear = ac_axis(a0 + (a1 - a0) * s, c0 + (c1 - c0) * s);
            let great = nalgebra::UnitQuaternion::identity().slerp(&rot, s) * p;
            worst = worst.max(linear.angle(&great));
        }
        let curvature = kerf_process::axis_curvature(a0, a1 - a0, c1 - c0);
        let bound = kerf_process::rotary_departure_rad(curvature, angle);
        assert!(
            worst <= bound,
            "A {a0}..{a1}, C {c0}..{c1}: {worst} > {bound}"
        );
        if worst > 1e-4 {
            worst_ratio = worst_ratio.max(bound / worst);
        }
    }
    let (a, c) = (45f64.to_radians(), 10f64.to_radians());
    let first = kerf_process::rotary_departure_rad(
        kerf_process::axis_curvature(a, 0.0, c),
        ac_axis(a, 0.0).angle(&ac_axis(a, c)),
    );
    assert!(first.to_degrees() < 0.5, "{}", first.to_degrees());
    assert!(
        worst_ratio < 8.0,
        "the bound is not wildly loose: {worst_ratio}"
    );
}

#[test]
fn the_linear_rotary_move_widens_the_bound_by_its_departure() {
    // Two upright poses 1 mm apart beside a wall 1.75 mm from the head's body (exact): with
    // the great circle between them (the axes agree) the head is proven to keep the 1 mm
    // clearance (each sample standing for 0.5 mm of motion); with the rotary axes swinging
    // between them (a 40-degree C turn at 10 degrees of tilt: 0.0098 rad of departure, 0.51
    // mm at the body's lower rim, 52 mm from the cutting point, 2 mm at the head's top)
    // 1.75 mm no longer covers the motion, and the bound falls below the clearance, below the
    // exact distance less the departure of the body's rim: each head point counts the
    // departure at its own distance from the cutting point.
    let head = Head::laser_default();
    let mut obs = Obstacles::new();
    let x_wall = BODY_R + 1.0 + 1.75;
    obs.add_nurbs(wall(x_wall));
    let poses: Vec<Pose> = [0.0, 1.0]
        .iter()
        .map(|&x| Pose {
            position: Point3::new(x, 0.0, 0.0),
            axis: Vector3::z(),
        })
        .collect();
    let opts = HeadCheckOptions::default();
    let plain = kerf_process::check_cut_along(&obs, &head, &poses, &[], &opts);
    let curvature = kerf_process::axis_curvature(0.17, 0.0, 0.68);
    let swung = kerf_process::check_cut_along(&obs, &head, &poses, &[curvature], &opts);
    // The body's lower rim, the head points nearest the wall.
    let rim = (opts.standoff_mm + head.solids[0].length_mm).hypot(BODY_R);
    let departure = rim * kerf_process::rotary_departure_rad(curvature, 0.0);
    let exact = x_wall - BODY_R - 1.0; // the body at the pose x = 1
    assert!(plain.proven && swung.proven);
    assert!(departure > 0.5, "{departure}");
    assert!(
        plain.close.is_empty() && plain.min_distance_mm >= opts.clearance_mm,
        "{plain:?}"
    );
    assert!(
        swung.min_distance_mm < opts.clearance_mm
            && swung.min_distance_mm <= exact - departure + 1e-9,
        "{swung:?}, departure {departure} mm at the body's rim"
    );
    // A program whose blocks hold each pose's axis within 0.6 degrees only: every head point
    // that angle times its distance from the cutting point farther (0.54 mm at the body's
    // rim), the same loss of the proof.
    let fitted = opts.with_axis_deviation_deg(0.6);
    let held = kerf_process::check_cut_along(&obs, &head, &poses, &[], &fitted);
    assert!(
        held.proven
            && held.min_distance_mm < opts.clearance_mm
            && held.min_distance_mm <= exact - rim * 0.6f64.to_radians() + 1e-9,
        "{held:?}"
    );
    // A bound that is not a size is not proven, nor an axis deviation out of its range.
    let bad = kerf_process::check_cut_along(&obs, &head, &poses, &[f64::NAN], &opts);
    assert!(!bad.proven, "{bad:?}");
    let wild = opts.with_axis_deviation_deg(f64::INFINITY);
    assert!(!kerf_process::check_cut_along(&obs, &head, &poses, &[], &wild).proven);
}

/// The A/C head the traverse tests run on (150 mm pivot).
fn ac_head() -> kerf_kinematics::AcHead {
    kerf_kinematics::AcHead::try_new(150.0, 0.0).expect("head")
}

/// The gap from a hole at `y = -60` to one at `y = 60` on the floor (surface `#0`), the beam
/// vertical.
fn holes_gap(kin: &dyn kerf_kinematics::Kinematics) -> kerf_process::Gap {
    let up = Vector3::z();
    let (from, to) = (
        Pose::at(Point3::new(0.0, -60.0, 0.0), up),
        Pose::at(Point3::new(0.0, 60.0, 0.0), up),
    );
    kerf_process::Gap {
        from,
        from_axes: kin.inverse(&from)[0],
        to,
        to_axes: kin.inverse(&to)[0],
        from_contour: from.position,
        to_contour: to.position,
        from_surfaces: vec!["#0".into()],
        to_surfaces: vec!["#0".into()],
    }
}

/// A rib 40 mm high and 20 mm long at `x = 30`, standing on the floor.
fn rib() -> NurbsSurface {
    NurbsSurface::plane(
        Point3::new(30.0, -10.0, 0.0),
        Vector3::y(),
        Vector3::z(),
        20.0,
        40.0,
    )
    .expect("rib")
}

/// The one gap `gap` planned by `plan_rapids` with the default traverse options (the
/// machine's `limits`, the head `th` if any).
fn plan_one(
    kin: &dyn kerf_kinematics::Kinematics,
    obs: &Obstacles,
    gap: &kerf_process::Gap,
    limits: &[Option<(f64, f64)>; 5],
    th: Option<&kerf_process::TraverseHead<'_>>,
) -> (kerf_process::Traverse, kerf_process::RapidMoves) {
    let opts = kerf_process::TraverseOptions::default();
    let (t, r, _) =
        kerf_process::plan_rapids(kin, limits, obs, std::slice::from_ref(gap), &opts, th)
            .into_iter()
            .next()
            .expect("one gap")
            .expect("a route the tip and nozzle line clear");
    (t, r)
}

/// The floor and the rib as obstacles (`#0`, `#1`), with their parts.
fn floor_and_rib() -> (Obstacles, Vec<usize>) {
    let mut obs = Obstacles::new();
    obs.add_nurbs(floor());
    obs.add_nurbs(rib());
    let parts = obs.parts(0.05);
    (obs, parts)
}

/// The exact distance from `p` to the floor (`z = 0`) or the rib, whichever is nearer.
fn floor_or_rib(p: &Point3<f64>) -> f64 {
    let dy = (p.y.abs() - 10.0).max(0.0);
    let dz = (p.z - 40.0).max(-p.z).max(0.0);
    let rib = ((p.x - 30.0).powi(2) + dy * dy + dz * dz).sqrt();
    rib.min(p.z.abs())
}

/// The least exact distance from the default head, sampled densely (the surface of each
/// solid every 0.5 mm of height and 3 degrees, the flat ends every 1 mm of radius), standing
/// on every pose of the machine's joint-linear moves through `axes` (200 samples a move),
/// to the floor and the rib; the nozzle's lowest `zone` mm (the tip zone) left out.
fn head_sweep_distance(
    kin: &dyn kerf_kinematics::Kinematics,
    axes: &[kerf_kinematics::Axes],
    standoff: f64,
    zone: f64,
) -> f64 {
    let head = Head::laser_default();
    // Head points as (height above the nozzle tip, radius).
    let mut rings: Vec<(f64, f64)> = Vec::new();
    let len = head.length_mm();
    let mut h = zone;
    while h <= len {
        rings.push((h, head.radius_at(h).expect("on the head")));
        h += 0.5;
    }
    // The body's flat bottom (at 25 mm, from the cone's 7 mm to the body's 45 mm) and top.
    for k in 0..=38 {
        rings.push((25.0, 7.0 + k as f64));
    }
    for k in 0..=45 {
        rings.push((len, k as f64));
    }
    let mut least = f64::INFINITY;
    for w in axes.windows(2) {
        for j in 0..=200 {
            let p = kin.forward(&w[0].lerp(&w[1], j as f64 / 200.0));
            let a = p.axis.normalize();
            let e1 = a
                .cross(&Vector3::x())
                .try_normalize(1e-9)
                .unwrap_or_else(|| a.cross(&Vector3::y()).normalize());
            let e2 = a.cross(&e1);
            for &(h, r) in &rings {
                let c = p.position + a * (standoff + h);
                for k in 0..120 {
                    let t = std::f64::consts::TAU * k as f64 / 120.0;
                    least = least.min(floor_or_rib(&(c + (e1 * t.cos() + e2 * t.sin()) * r)));
                }
            }
        }
    }
    least
}

/// A traverse between two holes on either side of a rib that the tip and nozzle line pass
/// 30 mm from, but the head's 90 mm body runs through: with the head model
/// (`kerf_process::TraverseHead`), the straight route at the retract height is refused and
/// a higher one taken;
/// a dense sampling of the head along the machine's moves, against the exact floor and rib,
/// finds the straight route's head inside the rib and the chosen route's at least the
/// clearance less the check's resolution away.
#[test]
fn the_head_model_keeps_a_traverse_off_a_rib_the_nozzle_line_clears() {
    use kerf_process::{plan_rapids, Route, TraverseHead, TraverseOptions, RESOLUTION_MM};
    let kin = ac_head();
    let (obs, parts) = floor_and_rib();
    assert_eq!(parts[0], parts[1], "the rib stands on the floor: one part");
    let gap = holes_gap(&kin);
    let opts = TraverseOptions::default();
    let hopts = HeadCheckOptions::default();
    let head = Head::laser_default();
    let limits = [None; 5];
    let moves = |with_head: bool| {
        let th = TraverseHead::new(&head, hopts, &obs, &parts);
        let planned = plan_rapids(
            &kin,
            &limits,
            &obs,
            std::slice::from_ref(&gap),
            &opts,
            with_head.then_some(&th),
        );
        let (t, r, _) = planned
            .into_iter()
            .next()
            .expect("one gap")
            .expect("a route");
        let mut axes = vec![gap.from_axes];
        axes.extend_from_slice(&r.axes);
        axes.push(gap.to_axes);
        // The highest point of the tip on the way.
        let top = t
            .waypoints
            .iter()
            .map(|w| w.position.z)
            .fold(f64::MIN, f64::max);
        (t.route, top, r.head_min_distance_mm, axes)
    };
    let zone = kerf_process::tip_zone_mm(&head, &hopts);
    let (route, low, none, axes) = moves(false);
    assert_eq!(route, Route::Straight, "the nozzle line clears the rib");
    assert_eq!(low, opts.retract_mm, "at the retract height");
    assert_eq!(none, None, "no head model, no head distance");
    let straight = head_sweep_distance(&kin, &axes, hopts.standoff_mm, zone);
    assert!(straight < 0.01, "the body runs through the rib: {straight}");
    let (_, high, proven, axes) = moves(true);
    // The body's bottom (26 mm above the tip) over the rib's top (40 mm) and the clearance.
    assert!(
        high >= 40.0 + hopts.clearance_mm - 26.0,
        "the head refuses the route at the retract height: {high}"
    );
    let proven = proven.expect("a head distance");
    let sampled = head_sweep_distance(&kin, &axes, hopts.standoff_mm, zone);
    assert!(
        proven >= hopts.clearance_mm - RESOLUTION_MM - 0.5 * kerf_process::SAMPLE_STEP_MM,
        "proven {proven}"
    );
    assert!(
        sampled >= proven - 0.05,
        "sampled {sampled} below the proven {proven}"
    );
    assert!(
        sampled >= hopts.clearance_mm - RESOLUTION_MM,
        "sampled {sampled}"
    );
}

/// The same rib where the machine's Z travel ends 2 mm above the retract height: every
/// route the machine reaches passes the rib at the retract height, so the head clears none;
/// the route the tip and nozzle line clear is returned with where the head comes too close
/// (the rib), for the caller to refuse or accept, and no head distance is claimed.
#[test]
fn where_the_head_clears_no_route_the_traverse_says_where() {
    use kerf_kinematics::Kinematics;
    use kerf_process::{plan_rapids, Route, TraverseHead, TraverseOptions};
    let kin = ac_head();
    let (obs, parts) = floor_and_rib();
    let opts = TraverseOptions::default();
    let above = Pose::at(Point3::new(0.0, 0.0, opts.retract_mm), Vector3::z());
    let top = kin.inverse(&above)[0].z;
    let mut limits = [None; 5];
    limits[2] = Some((top - 100.0, top + 2.0));
    let gap = holes_gap(&kin);
    let head = Head::laser_default();
    let th = TraverseHead::new(&head, HeadCheckOptions::default(), &obs, &parts);
    let plan = |h: Option<&TraverseHead<'_>>| {
        plan_rapids(&kin, &limits, &obs, std::slice::from_ref(&gap), &opts, h)
            .into_iter()
            .next()
            .expect("one gap")
            .expect("the nozzle line clears")
    };
    let (t, r, _) = plan(Some(&th));
    assert_eq!(t.route, Route::Straight);
    let top_z = t
        .waypoints
        .iter()
        .map(|w| w.position.z)
        .fold(f64::MIN, f64::max);
    assert_eq!(top_z, opts.retract_mm, "the machine reaches no higher");
    let close = r.head_too_close.expect("the head clears no route");
    assert!(close.distance_mm.expect("witnessed") < 1.0, "{close:?}");
    assert_eq!(close.surface.as_deref(), Some("#1"), "the rib: {close:?}");
    assert_eq!(r.head_min_distance_mm, None, "no distance claimed");
    let (t2, r2, _) = plan(None);
    assert_eq!(
        t2.waypoints, t.waypoints,
        "the route the nozzle line's check takes"
    );
    assert_eq!(r2.head_too_close, None);
}

/// A ceiling plate 210 mm up over the second hole: the head standing on the hole (its top 206
/// mm up) clears it, the head at every retract point above the hole (7.5 to 120 mm up) does
/// not, so no route can clear the head: the traverse the nozzle line's check takes comes back
/// with the ceiling named (the tip and the nozzle, 20 mm long, never come near it). (Whether
/// the routes were tried with the head first is not observable here: the pre-check and each
/// route's check of its retract points give the same witness.)
#[test]
fn where_the_head_clears_no_retract_point_the_traverse_names_what_is_in_the_way() {
    use kerf_process::TraverseHead;
    let kin = ac_head();
    let mut obs = Obstacles::new();
    obs.add_nurbs(floor());
    // The ceiling, joined to the floor by a post at its far end (one part).
    obs.add_nurbs(
        NurbsSurface::plane(
            Point3::new(-60.0, 30.0, 210.0),
            Vector3::x(),
            Vector3::y(),
            120.0,
            80.0,
        )
        .expect("ceiling"),
    );
    obs.add_nurbs(
        NurbsSurface::plane(
            Point3::new(-60.0, 110.0, 0.0),
            Vector3::x(),
            Vector3::z(),
            120.0,
            210.0,
        )
        .expect("post"),
    );
    let parts = obs.parts(0.05);
    assert!(
        parts[0] == parts[2] && parts[1] == parts[2],
        "one part: {parts:?}"
    );
    let gap = holes_gap(&kin);
    let head = Head::laser_default();
    let hopts = HeadCheckOptions::default();
    let standing = check_cut(&obs, &head, &[gap.to], &hopts);
    assert!(
        standing.close.is_empty() && standing.proven,
        "the head clears the hole itself"
    );
    let th = TraverseHead::new(&head, hopts, &obs, &parts);
    let (_, r) = plan_one(&kin, &obs, &gap, &[None; 5], Some(&th));
    let w = r.head_too_close.expect("no route can clear the head");
    assert_eq!(w.surface.as_deref(), Some("#1"), "the ceiling: {w:?}");
    // The lowest retract point: the head's top 1 + 205 + 7.5 mm up, 3.5 mm into the ceiling.
    let d = w.distance_mm.expect("witnessed");
    assert!(d < hopts.clearance_mm, "{w:?}");
    assert!(
        (w.at.z - 210.0).abs() < 5.0 && w.at.y > 30.0,
        "on the ceiling: {w:?}"
    );
    assert_eq!(r.head_min_distance_mm, None);
}

/// The rib again with the beam leaning 20 degrees at both holes, toward -x at the first and
/// toward +y at the second: the traverse turns C a quarter turn on its travel. A dense
/// sampling of the head along the machine's own moves (the joint values interpolated, forward
/// kinematics) against the exact floor and rib finds no point closer than the bound the check
/// proved for the whole traverse. (The least bound is likely set near the holes, where the
/// head stands as it cut; the rotary departure's own bound is tested on its own by
/// `the_linear_rotary_move_widens_the_bound_by_its_departure`.)
#[test]
fn a_traverse_that_turns_the_head_keeps_the_bound_it_proves() {
    use kerf_kinematics::Kinematics;
    use kerf_process::{TraverseHead, RESOLUTION_MM};
    let kin = ac_head();
    let (obs, parts) = floor_and_rib();
    let t = 20f64.to_radians();
    let mut gap = holes_gap(&kin);
    gap.from = Pose::at(gap.from.position, Vector3::new(-t.sin(), 0.0, t.cos()));
    gap.to = Pose::at(gap.to.position, Vector3::new(0.0, t.sin(), t.cos()));
    gap.from_axes = kin.inverse(&gap.from)[0];
    gap.to_axes = kin.inverse(&gap.to)[0];
    let turn = (gap.to_axes.c - gap.from_axes.c).abs() % 360.0;
    assert!(
        (turn - 90.0).abs() < 1e-6 || (turn - 270.0).abs() < 1e-6,
        "C turns: {turn}"
    );
    let head = Head::laser_default();
    let hopts = HeadCheckOptions::default();
    let th = TraverseHead::new(&head, hopts, &obs, &parts);
    let (_, r) = plan_one(&kin, &obs, &gap, &[None; 5], Some(&th));
    let proven = r.head_min_distance_mm.expect("the head cleared a route");
    let mut axes = vec![gap.from_axes];
    axes.extend_from_slice(&r.axes);
    axes.push(gap.to_axes);
    let zone = kerf_process::tip_zone_mm(&head, &hopts);
    let sampled = head_sweep_distance(&kin, &axes, hopts.standoff_mm, zone);
    assert!(
        sampled >= proven - 1e-6,
        "sampled {sampled} below the proven {proven}"
    );
    assert!(
        proven >= hopts.clearance_mm - RESOLUTION_MM - kerf_process::SAMPLE_STEP_MM,
        "proven {proven}"
    );
}

/// The tool turning 10 degrees about a tip that stands still on a floor (a crease's turn): the
/// head's top sweeps 37 mm, so the samples lie 0.5 mm of the top's motion apart (74 of them),
/// while the nozzle near the floor moves a few hundredths of that. Each cell counting its own
/// motion (its farthest point from the cutting point times the turn), one check of the whole
/// turn clears the nozzle (2 mm above the floor at the tip zone, 1 mm of margin over about
/// 0.4 mm of motion), where the whole head's figure (18 mm from the middle of the turn to its
/// ends) splits it down to single samples, each refined near the floor. The work is counted;
/// the bound holds against the exact distance of the tilted cone to the floor.
#[test]
fn a_turn_about_a_standing_tip_is_cleared_by_each_cells_own_motion() {
    let head = Head::laser_default();
    let mut obs = Obstacles::new();
    obs.add_nurbs(floor());
    let turn = 10f64.to_radians();
    let poses: Vec<Pose> = [0.0, turn]
        .iter()
        .map(|&a| Pose {
            position: Point3::origin(),
            axis: Vector3::new(a.sin(), 0.0, a.cos()),
        })
        .collect();
    let opts = HeadCheckOptions::default();
    let r = check_cut(&obs, &head, &poses, &opts);
    assert!(r.proven && r.close.is_empty(), "{r:?}");
    assert!(r.samples >= 70, "{} samples", r.samples);
    // The exact least distance over the turn: the cone's lowest rim point above the tip zone,
    // at the full tilt (its height above the floor falls with the tilt).
    let zone = r.tip_zone_mm;
    let rim = head.radius_at(zone).expect("on the nozzle");
    let exact = (opts.standoff_mm + zone) * turn.cos() - rim * turn.sin();
    assert!(
        r.min_distance_mm >= opts.clearance_mm - 0.5 && r.min_distance_mm <= exact + 1e-9,
        "bound {} against the exact {exact}",
        r.min_distance_mm
    );
    // The work: 186 queries for the whole turn (2026-12-05); with the whole head's motion on
    // every cell the same check took 8,863.
    assert!(r.queries <= 1_000, "{} queries", r.queries);
}
