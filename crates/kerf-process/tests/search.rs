//! Where no route shape clears: the search around the part and the proof that no route can
//! exist, against exact geometry (flat rectangles as bilinear NURBS patches, whose distance is
//! known in closed form).

mod common;

use kerf_nurbs::NurbsSurface;
use kerf_process::{
    plan_traverse, plan_traverse_within, Obstacles, Pose, ProcessError, Route, TraverseOptions,
};
use nalgebra::{Point3, Vector3};

/// A rectangle: corner `o`, edges `u` and `v` (perpendicular).
#[derive(Debug, Clone, Copy)]
struct Rect {
    o: Point3<f64>,
    u: Vector3<f64>,
    v: Vector3<f64>,
}

impl Rect {
    fn new(o: [f64; 3], u: [f64; 3], v: [f64; 3]) -> Self {
        Self {
            o: Point3::from(o),
            u: Vector3::from(u),
            v: Vector3::from(v),
        }
    }

    fn nurbs(&self) -> NurbsSurface {
        let cps = vec![
            vec![self.o, self.o + self.v],
            vec![self.o + self.u, self.o + self.u + self.v],
        ];
        NurbsSurface::try_new(
            1,
            1,
            vec![0.0, 0.0, 1.0, 1.0],
            vec![0.0, 0.0, 1.0, 1.0],
            cps,
            None,
        )
        .expect("valid patch")
    }

    /// The exact distance from `p` (the nearest point: the projection clamped to the edges).
    fn distance(&self, p: &Point3<f64>) -> f64 {
        let d = p - self.o;
        let (lu, lv) = (self.u.norm(), self.v.norm());
        let a = d.dot(&self.u).clamp(0.0, lu * lu) / (lu * lu);
        let b = d.dot(&self.v).clamp(0.0, lv * lv) / (lv * lv);
        (p - (self.o + self.u * a + self.v * b)).norm()
    }
}

fn obstacles(rects: &[Rect]) -> Obstacles {
    let mut o = Obstacles::new();
    for r in rects {
        o.add_nurbs(r.nurbs());
    }
    o
}

/// The smallest exact distance to `rects` over a dense sampling of the route.
fn dense_min(rects: &[Rect], way: &[Pose], nozzle: f64) -> f64 {
    common::dense_min(way, nozzle, 80, &|q| {
        rects
            .iter()
            .map(|r| r.distance(q))
            .fold(f64::INFINITY, f64::min)
    })
}

/// A floor (z = 0) and a roof 40 mm above it over `x` in [-30, 30]: a pierce on the floor
/// under the roof, an exit on the roof's top, both with the tool axis up.
fn roof() -> (Vec<Rect>, Pose, Pose) {
    let floor = Rect::new([-100.0, -100.0, 0.0], [200.0, 0.0, 0.0], [0.0, 200.0, 0.0]);
    let roof = Rect::new([-30.0, -100.0, 40.0], [60.0, 0.0, 0.0], [0.0, 200.0, 0.0]);
    let exit = Pose::new(0.0, 0.0, 40.0, 0.0, 0.0, 1.0);
    let pierce = Pose::new(0.0, 0.0, 0.0, 0.0, 0.0, 1.0);
    (vec![floor, roof], exit, pierce)
}

#[test]
fn a_pierce_under_a_roof_is_reached_around_the_roofs_edge() {
    let (rects, exit, pierce) = roof();
    let obs = obstacles(&rects);
    let opts = TraverseOptions::default();
    // Every route shape runs through the roof: straight from above it, lifted and over the
    // safe plane coming down onto the pierce through it.
    let e = plan_traverse(&obs, &exit, &pierce, &opts.with_search(false))
        .expect_err("no route shape clears");
    assert!(
        e.to_string().contains("measured closer than the clearance"),
        "{e}"
    );
    let t = plan_traverse(&obs, &exit, &pierce, &opts).expect("a path around the edge");
    assert_eq!(t.route, Route::Searched);
    let exact = dense_min(&rects, &t.waypoints, opts.nozzle_mm);
    assert!(
        exact >= opts.clearance_mm,
        "dense exact check: {exact} mm against the {} mm clearance",
        opts.clearance_mm
    );
    assert!(
        t.min_distance_mm >= opts.clearance_mm,
        "{}",
        t.min_distance_mm
    );
    // It leaves along the exit's axis and arrives above the pierce on its axis, and goes
    // round the roof's edge (beyond x = 30 by the clearance).
    let (first, last) = (t.waypoints[0], t.waypoints[t.waypoints.len() - 1]);
    assert!(
        first.position.x.abs() < 1e-9 && first.position.y.abs() < 1e-9 && first.position.z > 40.0
    );
    assert!(
        last.position.x.abs() < 1e-9
            && last.position.y.abs() < 1e-9
            && last.position.z > 0.0
            && last.position.z < 40.0
    );
    let out = t
        .waypoints
        .iter()
        .map(|w| w.position.x.abs().max(w.position.y.abs() - 100.0))
        .fold(0.0, f64::max);
    assert!(
        out >= 30.0 + opts.clearance_mm,
        "goes round the edge: {out}"
    );
    // The length counts the retract, the path and the approach.
    let mut pts = vec![exit.position];
    pts.extend(t.waypoints.iter().map(|w| w.position));
    pts.push(pierce.position);
    let length: f64 = pts.windows(2).map(|w| (w[1] - w[0]).norm()).sum();
    assert!((t.length_mm - length).abs() < 1e-9);
}

#[test]
fn an_approach_line_blocked_at_every_height_is_proven_impossible() {
    // A ceiling 32 mm over the floor: the head at the first retract height (7.5 mm) reaches
    // 27.5 mm with its nozzle, 4.5 mm from the ceiling; from 9.5 mm up the approach itself
    // sweeps within half the clearance of it. No route can end above the pierce.
    let floor = Rect::new([-100.0, -100.0, 0.0], [400.0, 0.0, 0.0], [0.0, 200.0, 0.0]);
    let opts = TraverseOptions::default();
    let pierce = Pose::new(100.0, 0.0, 0.0, 0.0, 0.0, 1.0);
    let exit = Pose::new(0.0, 0.0, 0.0, 0.0, 0.0, 1.0);
    for (height, proven) in [(32.0, true), (33.5, false)] {
        let ceiling = Rect::new([50.0, -100.0, height], [250.0, 0.0, 0.0], [0.0, 200.0, 0.0]);
        let rects = [floor, ceiling];
        let obs = obstacles(&rects);
        let got = plan_traverse(&obs, &exit, &pierce, &opts);
        if !proven {
            // 6 mm from the ceiling at 7.5 mm: a route exists (the straight travel).
            let t = got.expect("a route");
            assert!(dense_min(&rects, &t.waypoints, opts.nozzle_mm) >= opts.clearance_mm);
            continue;
        }
        let e = got.expect_err("no route");
        let text = e.to_string();
        assert!(
            text.contains("proven, no route can exist: the approach to the pierce"),
            "{text}"
        );
        // The route shapes were measured too.
        assert!(
            text.contains("measured closer than the clearance"),
            "{text}"
        );
        let ProcessError::TraverseBlocked(b) = &e else {
            panic!("{e}")
        };
        let at = Point3::from(b.at);
        let exact = rects
            .iter()
            .map(|r| r.distance(&at))
            .fold(f64::INFINITY, f64::min);
        assert!((exact - b.distance_mm).abs() < 1e-9, "{exact} vs {text}");
        assert!(b.distance_mm < 0.5 * opts.clearance_mm, "{text}");
        assert!(
            (at.x - 100.0).abs() < 1e-9 && at.y.abs() < 1e-9,
            "on the line: {text}"
        );
    }
}

#[test]
fn the_search_stops_within_its_budget() {
    // A wall 2 km square between the exit and the pierce, and the machine's reach (here:
    // nothing above z = 100) rules out the routes over it: the only way round is a kilometre
    // off, far beyond what the search may spend.
    let wall = Rect::new(
        [0.0, -1000.0, -1000.0],
        [0.0, 2000.0, 0.0],
        [0.0, 0.0, 2000.0],
    );
    let obs = obstacles(&[wall]);
    let opts = TraverseOptions::default();
    let exit = Pose::new(0.0, 0.0, 0.0, 1.0, 0.0, 0.0);
    let pierce = Pose::new(0.0, 10.0, 0.0, -1.0, 0.0, 0.0);
    let low = |w: &[Pose]| w.iter().all(|p| p.position.z < 100.0);
    let start = std::time::Instant::now();
    let e = plan_traverse_within(&obs, &exit, &pierce, &opts, &low).expect_err("no route");
    let text = e.to_string();
    assert!(
        text.contains("found 0 paths in 524288 of its 524288 work units"),
        "{text}"
    );
    // Every distance query was counted against a budget: the search's, the route shapes'.
    assert!(obs.queries() < 2_000_000, "{} queries", obs.queries());
    assert!(start.elapsed().as_secs() < 60, "{:?}", start.elapsed());
}
