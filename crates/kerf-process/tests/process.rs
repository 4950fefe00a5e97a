//! Sides, start points, lead-ins and the cut order against exact geometry: circles and squares
//! whose inside and outside are known, tangents known in closed form.

use kerf_process::{plan_cuts, Contour, LeadOptions, Pose, Side};

/// A circle of radius `r` about (`cx`, `cy`) in z = 0, `n` segments, counter-clockwise seen from
/// +z if `ccw`, normal +z; closed (the first point repeated).
fn circle(cx: f64, cy: f64, r: f64, n: usize, ccw: bool) -> Vec<Pose> {
    (0..=n)
        .map(|i| {
            let a = std::f64::consts::TAU * (i % n) as f64 / n as f64;
            let a = if ccw { a } else { -a };
            Pose::new(cx + r * a.cos(), cy + r * a.sin(), 0.0, 0.0, 0.0, 1.0)
        })
        .collect()
}

/// A square of side `s` about the origin with `k` points per edge, counter-clockwise.
fn square(s: f64, k: usize) -> Vec<Pose> {
    let h = s / 2.0;
    let c = [(-h, -h), (h, -h), (h, h), (-h, h)];
    let mut out = Vec::new();
    for e in 0..4 {
        let (a, b) = (c[e], c[(e + 1) % 4]);
        for i in 0..k {
            let t = i as f64 / k as f64;
            out.push(Pose::new(
                a.0 + t * (b.0 - a.0),
                a.1 + t * (b.1 - a.1),
                0.0,
                0.0,
                0.0,
                1.0,
            ));
        }
    }
    out.push(out[0]);
    out
}

fn contour<'a>(id: &'a str, poses: &'a [Pose]) -> Contour<'a> {
    Contour {
        id,
        poses,
        scrap: None,
        start: None,
    }
}

fn r_of(p: &Pose, cx: f64, cy: f64) -> f64 {
    ((p.position.x - cx).powi(2) + (p.position.y - cy).powi(2)).sqrt()
}

#[test]
fn holes_first_lead_ins_in_the_scrap_and_tangent() {
    let outline = circle(0.0, 0.0, 50.0, 400, true);
    let holes = [
        (30.0, 0.0, 5.0, true),
        (-30.0, 10.0, 6.0, false),
        (0.0, -30.0, 4.0, true),
    ];
    let hole_pts: Vec<Vec<Pose>> = holes
        .iter()
        .map(|&(x, y, r, ccw)| circle(x, y, r, 120, ccw))
        .collect();
    // The outline first in the file: the order must still put it last.
    let ids = ["outline", "h0", "h1", "h2"];
    let mut cs = vec![contour(ids[0], &outline)];
    for (k, h) in hole_pts.iter().enumerate() {
        cs.push(contour(ids[k + 1], h));
    }
    let plan = plan_cuts(&cs, &LeadOptions::default()).expect("plan");
    assert!(!plan.is_hole(0), "the outline is no hole");
    for k in 1..4 {
        assert!(plan.is_hole(k), "{} is a hole", ids[k]);
    }
    let pos = |i: usize| plan.order.iter().position(|&o| o == i).expect("in order");
    for k in 1..4 {
        assert!(
            pos(k) < pos(0),
            "hole {} before the outline: {:?}",
            ids[k],
            plan.order
        );
    }
    // Sides: inside of each hole, outside of the outline, whatever the direction.
    assert_eq!(
        plan.sides[0],
        Some(Side::Right),
        "ccw outline: scrap outside is right"
    );
    assert_eq!(
        plan.sides[1],
        Some(Side::Left),
        "ccw hole: scrap inside is left"
    );
    assert_eq!(
        plan.sides[2],
        Some(Side::Right),
        "cw hole: scrap inside is right"
    );
    for (k, &(x, y, r, _)) in holes.iter().enumerate() {
        let l = &plan.leads[k + 1];
        assert!(
            !l.lead_in.is_empty() && !l.pierce_on_contour,
            "{}: a lead-in",
            ids[k + 1]
        );
        // The lead-in and the exit (the overcut before it runs on the contour itself).
        for p in l.lead_in.iter().chain(l.lead_out.last()) {
            assert!(
                r_of(p, x, y) < r - 1e-9,
                "{}: lead point {p:?} not inside",
                ids[k + 1]
            );
        }
        for p in &l.lead_out[..l.lead_out.len() - 1] {
            assert!(
                (r_of(p, x, y) - r).abs() < 0.01,
                "{}: overcut {p:?} on the contour",
                ids[k + 1]
            );
        }
        // The pierce point is well off the contour (full-size lead-in: 2 mm line + 1 mm arc).
        let pierce = l.pierce(&hole_pts[k]);
        assert!(
            r - r_of(&pierce, x, y) > 1.9,
            "{}: pierce {pierce:?}",
            ids[k + 1]
        );
    }
    for p in plan.leads[0]
        .lead_in
        .iter()
        .chain(plan.leads[0].lead_out.last())
    {
        assert!(
            r_of(p, 0.0, 0.0) > 50.0 + 1e-9,
            "outline lead point {p:?} not outside"
        );
    }
    // Tangential join: the last lead-in chord against the circle's exact tangent at the start
    // (perpendicular to the radius, along the cut); the arc's polyline at 0.001 mm on a 1 mm
    // radius turns by at most 2.6 deg per chord.
    let centres = [(0.0, 0.0), (30.0, 0.0), (-30.0, 10.0), (0.0, -30.0)];
    for (i, pts) in std::iter::once(&outline).chain(hole_pts.iter()).enumerate() {
        let l = &plan.leads[i];
        let cut = plan.cut(i, pts);
        let last = l.lead_in.last().expect("lead-in");
        let a = [
            cut[0].position.x - last.position.x,
            cut[0].position.y - last.position.y,
        ];
        let (cx, cy) = centres[i];
        let radial = [cut[0].position.x - cx, cut[0].position.y - cy];
        let mut t = [-radial[1], radial[0]];
        let along = [
            cut[1].position.x - cut[0].position.x,
            cut[1].position.y - cut[0].position.y,
        ];
        if t[0] * along[0] + t[1] * along[1] < 0.0 {
            t = [-t[0], -t[1]];
        }
        let cos = (a[0] * t[0] + a[1] * t[1]) / (a[0].hypot(a[1]) * t[0].hypot(t[1]));
        assert!(
            cos > 2.6f64.to_radians().cos(),
            "contour {i}: joins at {} deg",
            cos.acos().to_degrees()
        );
        assert_eq!(cut.first(), cut.last(), "a closed cut ends where it starts");
        assert_eq!(
            cut.len(),
            pts.len(),
            "every cutting point once (and the start twice)"
        );
    }
    assert!(
        plan.traverse_mm <= plan.file_order_traverse_mm + 1e-9,
        "order no worse than the file"
    );
    // Deterministic.
    assert_eq!(
        plan,
        plan_cuts(&cs, &LeadOptions::default()).expect("again"),
        "same plan"
    );
}

#[test]
fn small_hole_shrinks_its_lead_in_and_stays_inside() {
    let hole = circle(0.0, 0.0, 0.8, 64, true);
    let plate = circle(0.0, 0.0, 20.0, 200, true);
    let cs = [contour("hole", &hole), contour("plate", &plate)];
    let plan = plan_cuts(&cs, &LeadOptions::default()).expect("plan");
    let l = &plan.leads[0];
    assert!(l.scale < 1.0 && l.scale > 0.0, "shrunk: {}", l.scale);
    for p in l.lead_in.iter().chain(l.lead_out.last()) {
        assert!(r_of(p, 0.0, 0.0) < 0.8, "inside the 0.8 mm hole: {p:?}");
    }
}

#[test]
fn start_is_never_at_a_corner() {
    let sq = square(40.0, 10);
    let cs = [contour("sq", &sq)];
    let plan = plan_cuts(&cs, &LeadOptions::default()).expect("plan");
    let s = plan.leads[0].start;
    let k = s % 10;
    assert!(
        (3..=7).contains(&k),
        "start {s} is {k} points from a corner"
    );
}

#[test]
fn the_file_scrap_key_wins_and_open_contours_lead_along_their_tangent() {
    let c = circle(0.0, 0.0, 10.0, 100, true);
    let mut one = contour("c", &c);
    one.scrap = Some(Side::Left); // an outline whose inside is scrap (a plug cut out)
    let plan = plan_cuts(&[one], &LeadOptions::default()).expect("plan");
    assert_eq!(plan.sides[0], Some(Side::Left));
    assert!(
        plan.leads[0]
            .lead_in
            .iter()
            .all(|p| r_of(p, 0.0, 0.0) < 10.0),
        "inside"
    );
    let line: Vec<Pose> = (0..=10)
        .map(|i| Pose::new(i as f64, 0.0, 0.0, 0.0, 0.0, 1.0))
        .collect();
    let plan = plan_cuts(&[contour("trim", &line)], &LeadOptions::default()).expect("plan");
    let l = &plan.leads[0];
    assert_eq!(l.lead_in.len(), 1, "one straight move");
    assert!(
        (l.lead_in[0].position.x + 3.0).abs() < 1e-12 && l.lead_in[0].position.y == 0.0,
        "{:?}",
        l.lead_in
    );
    assert!(
        (l.lead_out[0].position.x - 11.5).abs() < 1e-12,
        "{:?}",
        l.lead_out
    );
}

#[test]
fn island_in_a_hole_and_a_shorter_order_than_the_file() {
    let outline = circle(0.0, 0.0, 100.0, 400, true);
    let hole = circle(0.0, 0.0, 40.0, 200, true);
    let island = circle(0.0, 0.0, 20.0, 100, true);
    let cs = [
        contour("outline", &outline),
        contour("hole", &hole),
        contour("island", &island),
    ];
    let plan = plan_cuts(&cs, &LeadOptions::default()).expect("plan");
    assert_eq!(plan.order, [2, 1, 0], "innermost first");
    assert!(
        plan.is_hole(1) && !plan.is_hole(2),
        "island inside two contours is no hole"
    );
    assert!(
        plan.leads[2]
            .lead_in
            .iter()
            .all(|p| r_of(p, 0.0, 0.0) > 20.0),
        "island scrap outside"
    );
    // A row of holes listed in a zig-zag file order.
    let centres: Vec<f64> = vec![0.0, 80.0, 10.0, 70.0, 20.0, 60.0, 30.0, 50.0, 40.0];
    let holes: Vec<Vec<Pose>> = centres
        .iter()
        .map(|&x| circle(x, 0.0, 2.0, 40, true))
        .collect();
    let ids: Vec<String> = (0..holes.len()).map(|i| format!("h{i}")).collect();
    let cs: Vec<Contour<'_>> = holes
        .iter()
        .zip(&ids)
        .map(|(h, id)| contour(id, h))
        .collect();
    let plan = plan_cuts(&cs, &LeadOptions::default()).expect("plan");
    assert!(
        plan.traverse_mm < 0.5 * plan.file_order_traverse_mm,
        "{} vs file order {}",
        plan.traverse_mm,
        plan.file_order_traverse_mm
    );
}

/// `n` cutting points (and the first again) of a loop of radius 20 around the z axis, the tool
/// axes radial.
fn tube_loop(n: usize) -> Vec<Pose> {
    (0..=n)
        .map(|i| {
            let a = std::f64::consts::TAU * (i % n) as f64 / n as f64;
            Pose::new(20.0 * a.cos(), 20.0 * a.sin(), 0.0, a.cos(), a.sin(), 0.0)
        })
        .collect()
}

/// A loop around a tube (radius 20 about the z axis, normals radial): the tool axes turn all
/// the way round, so the projection along the (Newell) normal folds the sides onto the loop.
/// With `scrap` on either side, the lead-in and lead-out lie on that side along the tube
/// (`n x t` is +z for this loop, so left is +z), not on the contour.
#[test]
fn a_loop_around_a_tube_leads_in_on_its_scrap_side() {
    let ring = tube_loop(96);
    for (side, sign) in [(Side::Left, 1.0), (Side::Right, -1.0)] {
        let c = Contour {
            id: "cut-off",
            poses: &ring,
            scrap: Some(side),
            start: None,
        };
        let plan = plan_cuts(&[c], &LeadOptions::default()).expect("plan");
        let l = &plan.leads[0];
        assert!(!l.pierce_on_contour, "{side:?}: a lead-in fits: {l:?}");
        assert!((l.scale - 1.0).abs() < 1e-12, "{side:?}: full size");
        let pierce = l.lead_in[0];
        assert!(
            pierce.position.z * sign > 2.0,
            "{side:?}: the pierce is up/down the tube: {pierce:?}"
        );
        for q in l.lead_in.iter().chain(&l.lead_out) {
            assert!(
                q.position.z * sign >= -1e-9,
                "{side:?}: on the scrap side: {q:?}"
            );
        }
    }
}

/// The overcut ends inside a chord of the loop around a tube; its tool axis there is the chord's
/// two axes interpolated at the same fraction as the point. On this loop the normals are the
/// radial directions, so that axis is exactly the direction of the overcut's end point from
/// the tube's axis (position = radius x normal at both ends of the chord). The exit keeps it.
/// (With the far end's axis the beam stood off by up to a chord's turn, 3.75 deg here.)
#[test]
fn the_overcut_ends_with_the_axis_of_where_it_ends() {
    let ring = tube_loop(96);
    let c = Contour {
        id: "cut-off",
        poses: &ring,
        scrap: Some(Side::Left),
        start: None,
    };
    let opts = LeadOptions::default();
    let plan = plan_cuts(&[c], &opts).expect("plan");
    let l = &plan.leads[0];
    assert_eq!(l.lead_out.len(), 2, "the overcut's end and the exit: {l:?}");
    let end = l.lead_out[0];
    let (p, a) = (
        nalgebra::Vector3::new(end.position.x, end.position.y, end.position.z),
        end.axis,
    );
    // The overcut's end lies inside the first chord after the start, not on a cutting point.
    let s = l.start;
    let along =
        (p - nalgebra::Vector3::new(ring[s].position.x, ring[s].position.y, ring[s].position.z))
            .norm();
    assert!(
        (along - opts.overcut_mm).abs() < 1e-9,
        "{along} mm past the start"
    );
    assert!(
        ring.iter().all(|q| (q.axis - a).norm() > 1e-3),
        "the axis is not a cutting point's: {a:?}"
    );
    let radial = nalgebra::Vector3::new(p.x, p.y, 0.0).normalize();
    assert!(
        (a - radial).norm() < 1e-12,
        "axis {a:?}, radial at the overcut's end {radial:?}"
    );
    let exit = l.lead_out[1];
    assert_eq!(exit.axis, end.axis, "the exit keeps the overcut's axis");
}
