//! The work of the traverse checks, counted (exact distance queries, not time): the routes that
//! run into the part before the one taken are not traced to their blockage.

use kerf_nurbs::NurbsSurface;
use kerf_process::{plan_traverse, Obstacles, Pose, Route, TraverseOptions};
use nalgebra::{Point3, Vector3};

/// A sheet at z = 0 (x from -50 to 450) with a flange standing 40 mm high across it at
/// x = 400: the shape of a sheet-metal part whose next cut lies beyond a bend.
fn sheet_with_flange() -> Obstacles {
    let mut o = Obstacles::new();
    o.add_nurbs(
        NurbsSurface::plane(
            Point3::new(-50.0, -50.0, 0.0),
            Vector3::x(),
            Vector3::y(),
            500.0,
            100.0,
        )
        .expect("sheet"),
    );
    o.add_nurbs(
        NurbsSurface::plane(
            Point3::new(400.0, -50.0, 0.0),
            Vector3::y(),
            Vector3::z(),
            100.0,
            40.0,
        )
        .expect("flange"),
    );
    o
}

/// The exact distance from `p` to the sheet and the flange (closed form: the nearest point of
/// each rectangle, its coordinates clamped).
fn distance(p: &Point3<f64>) -> f64 {
    let sheet = Point3::new(p.x.clamp(-50.0, 450.0), p.y.clamp(-50.0, 50.0), 0.0);
    let flange = Point3::new(400.0, p.y.clamp(-50.0, 50.0), p.z.clamp(0.0, 40.0));
    (p - sheet).norm().min((p - flange).norm())
}

#[test]
fn routes_running_into_the_flange_are_not_traced_to_it() {
    // From an exit at the origin to a pierce beyond the flange, both with the tool axis up.
    // The straight routes from the lower retract heights are shorter than the one taken and
    // run along the sheet into the flange. Traced in turn, as before, they cost 8,775 exact
    // queries (counted with the code of facc66f); now a point of each is measured closer than
    // the clearance first (a probe, or the flange point measured for an earlier route), and
    // only the route taken is traced, rising away from the sheet.
    let obs = sheet_with_flange();
    let opts = TraverseOptions::default();
    let from = Pose::new(0.0, 0.0, 0.0, 0.0, 0.0, 1.0);
    let to = Pose::new(430.0, 0.0, 0.0, 0.0, 0.0, 1.0);
    let t = plan_traverse(&obs, &from, &to, &opts).expect("over the flange");
    // The route taken is the one taken before: straight from the lowest retract point over
    // the exit to the one at 60 mm over the pierce.
    assert_eq!(t.route, Route::Straight);
    assert_eq!(t.waypoints.len(), 2);
    assert!(
        (t.waypoints[0].position.z - 7.5).abs() < 1e-12,
        "{:?}",
        t.waypoints
    );
    assert!(
        (t.waypoints[1].position.z - 60.0).abs() < 1e-12,
        "{:?}",
        t.waypoints
    );
    // It keeps the clearance (tip and nozzle every 0.05 mm, against the closed form).
    let (a, b) = (t.waypoints[0], t.waypoints[1]);
    let mut least = f64::INFINITY;
    for j in 0..=10_000 {
        let f = f64::from(j) / 10_000.0;
        for s in 0..=40 {
            let q = Point3::new(
                a.position.x + (b.position.x - a.position.x) * f,
                a.position.y + (b.position.y - a.position.y) * f,
                a.position.z
                    + (b.position.z - a.position.z) * f
                    + opts.nozzle_mm * f64::from(s) / 40.0,
            );
            least = least.min(distance(&q));
        }
    }
    assert!(least >= opts.clearance_mm, "{least}");
    let queries = obs.queries();
    assert!(queries < 200, "{queries} exact queries (8,775 before)");
}
