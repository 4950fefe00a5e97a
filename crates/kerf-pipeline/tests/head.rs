//! The head against the part along the cuts (`kerf run --cut-clearance`): a hole 47 mm from a
//! wall's foot, whose nearest point is 42 mm from it, so that the default head's 45 mm body
//! passes 2 mm from the wall: clear at a 1 mm clearance, refused by name at 3 mm, a warning
//! with the stretch in the report when accepted.

use kerf_kinematics::Machine;
use kerf_pipeline::{Job, JobOptions};
use nalgebra::{Point3, Vector3};

mod common;
use common::fixture;

fn job(clearance: f64, accept: bool) -> Result<kerf_pipeline::Output, kerf_pipeline::Error> {
    let curves = kerf_format::curves::load(fixture("head_wall.json")).expect("curves");
    let machine = Machine::read(fixture("machines/gantry_ac.json")).expect("machine");
    Job::new(curves, machine)
        .with_options(
            JobOptions::default()
                .with_cut_clearance_mm(Some(clearance))
                .with_accept_head_collisions(accept),
        )
        .run()
}

#[test]
fn the_head_clears_the_wall_at_one_millimetre() {
    let out = job(1.0, false).expect("run");
    let head = &out.report.head;
    assert!(head.checked);
    for p in head.paths.as_ref().expect("paths") {
        let d = p.min_distance_mm.expect("bound");
        // Proven at least the clearance less the check's resolution, and never above the
        // exact 2 mm the body passes from the wall.
        assert!(
            d >= 1.0 - kerf_process::RESOLUTION_MM - kerf_process::SAMPLE_STEP_MM / 2.0,
            "{p:?}"
        );
        if p.path == "hole-near-wall" {
            assert!(d <= 2.0 + 1e-9, "{p:?}");
        }
        assert!(p.close.is_empty(), "{p:?}");
    }
}

#[test]
fn the_wall_is_named_when_the_clearance_is_three_millimetres() {
    let e = job(3.0, false).expect_err("refused");
    let text = e.to_string();
    assert!(
        text.contains("path \"hole-near-wall\": the head comes too close")
            && text.contains("surface wall")
            && text.contains("clearance 3 mm"),
        "{text}"
    );
    let out = job(3.0, true).expect("accepted");
    assert!(
        out.warnings
            .iter()
            .any(|w| w.contains("hole-near-wall") && w.contains("accepted")),
        "{:?}",
        out.warnings
    );
    // The picture marks the close stretch, once per view (top, front, side, iso), nothing
    // tilted.
    assert_eq!(
        out.plot_svg.matches("class=\"head-close\"").count(),
        4,
        "one band a view"
    );
    assert_eq!(
        out.plot_svg.matches("class=\"head-tilted\"").count(),
        0,
        "nothing tilted"
    );
    let paths = out.report.head.paths.as_ref().expect("paths");
    let near = paths
        .iter()
        .find(|p| p.path == "hole-near-wall")
        .expect("near");
    let close = &near.close;
    assert_eq!(close.len(), 1, "{near:?}");
    assert_eq!(close[0].surface.as_deref(), Some("wall"));
    // The exact stretch within 3 mm: 5 cos(theta) > 4, an arc of 2 x 0.6435 x 5 = 6.4 mm;
    // the reported one is witnessed inside it.
    let len = close[0].length_mm;
    assert!(len > 3.0 && len <= 6.44 + 1.0, "{near:?}");
    let far = paths.iter().find(|p| p.path == "hole-far").expect("far");
    assert!(far.close.is_empty(), "{far:?}");
}

/// An exact surface of the fixtures: a rectangle (origin, two edges) or the quarter cylinder
/// of `head_bend.json` (axis along y through x = 0, z = 20, radius 20, from the floor to the
/// flange, y in [-200, 200]).
enum Exact {
    Rect(Point3<f64>, Vector3<f64>, Vector3<f64>),
    Bend,
}

impl Exact {
    fn distance(&self, q: &Point3<f64>) -> f64 {
        match self {
            Exact::Rect(o, u, v) => {
                let w = q - o;
                let a = (w.dot(u) / u.norm_squared()).clamp(0.0, 1.0);
                let b = (w.dot(v) / v.norm_squared()).clamp(0.0, 1.0);
                (q - (o + u * a + v * b)).norm()
            }
            Exact::Bend => {
                let r = 20.0;
                // The angle from the bottom (0) to the flange (90 degrees), clamped to the arc.
                let (x, z) = (q.x, q.z - r);
                let t = x.atan2(-z).clamp(0.0, std::f64::consts::FRAC_PI_2);
                let y = q.y.clamp(-200.0, 200.0);
                let on = Point3::new(r * t.sin(), y, r - r * t.cos());
                (q - on).norm()
            }
        }
    }
}

/// The exact surfaces of a head fixture.
fn exact_surfaces(name: &str) -> Vec<Exact> {
    let p = Point3::new;
    let v = Vector3::new;
    match name {
        "head_wall.json" => vec![
            Exact::Rect(
                p(-200.0, -200.0, 0.0),
                v(252.0, 0.0, 0.0),
                v(0.0, 400.0, 0.0),
            ),
            Exact::Rect(p(52.0, -200.0, 0.0), v(0.0, 400.0, 0.0), v(0.0, 0.0, 60.0)),
        ],
        "head_channel.json" => vec![
            Exact::Rect(
                p(-50.0, -200.0, 0.0),
                v(100.0, 0.0, 0.0),
                v(0.0, 400.0, 0.0),
            ),
            Exact::Rect(p(-50.0, -200.0, 0.0), v(0.0, 0.0, 40.0), v(0.0, 400.0, 0.0)),
            Exact::Rect(p(50.0, -200.0, 0.0), v(0.0, 400.0, 0.0), v(0.0, 0.0, 40.0)),
        ],
        "head_bend.json" => vec![
            Exact::Rect(
                p(-150.0, -200.0, 0.0),
                v(150.0, 0.0, 0.0),
                v(0.0, 400.0, 0.0),
            ),
            Exact::Bend,
            Exact::Rect(p(20.0, -200.0, 20.0), v(0.0, 0.0, 13.0), v(0.0, 400.0, 0.0)),
        ],
        other => panic!("no exact surfaces for {other}"),
    }
}

/// The smallest distance from the default head (above `zone` mm over the nozzle tip, 1 mm
/// standoff), standing at each pose, to `surfaces`, by dense sampling of the head's surface
/// (every 0.5 mm along the axis, every degree around it) against the exact surfaces:
/// independent of the check's cells and closest points.
fn sampled_distance(poses: &[(Point3<f64>, Vector3<f64>)], zone: f64, surfaces: &[Exact]) -> f64 {
    let head = kerf_kinematics::Head::laser_default();
    let mut best = f64::INFINITY;
    for (p, a) in poses {
        let e1 = a
            .cross(&Vector3::y())
            .try_normalize(1e-9)
            .unwrap_or_else(|| a.cross(&Vector3::x()).normalize());
        let e2 = a.cross(&e1);
        let steps = (head.length_mm() / 0.5) as usize;
        for j in 0..=steps {
            let h = zone + (head.length_mm() - zone) * j as f64 / steps as f64;
            let r = head.radius_at(h).expect("on the head");
            for m in 0..360 {
                let phi = (m as f64).to_radians();
                let q = p + a * (1.0 + h) + (e1 * phi.cos() + e2 * phi.sin()) * r;
                for s in surfaces {
                    best = best.min(s.distance(&q));
                }
            }
        }
    }
    best
}

/// Every written pose of `id` (the cut, its lead-in and lead-out), in part coordinates.
fn written_poses(
    curves: &kerf_format::CurvesFile,
    out: &kerf_pipeline::Output,
    id: &str,
) -> Vec<(Point3<f64>, Vector3<f64>)> {
    let i = curves
        .curves
        .iter()
        .position(|c| c.id == id)
        .expect("curve");
    let pl = out.placement.placement_of(i);
    let (r, t) = (pl.rotation(), pl.translation_mm);
    let path = out.axes.paths.iter().find(|p| p.id == id).expect("path");
    let mut poses: Vec<[f64; 6]> = path.poses.clone();
    for m in [&path.lead_in, &path.lead_out].into_iter().flatten() {
        poses.extend(m.poses.iter().copied());
    }
    poses
        .iter()
        .map(|q| {
            (
                Point3::from(r.inverse() * (Point3::new(q[0], q[1], q[2]) - t)),
                r.inverse() * Vector3::new(q[3], q[4], q[5]),
            )
        })
        .collect()
}

/// A tip and its tool axis in part coordinates.
type Placed = (Point3<f64>, Vector3<f64>);

/// The head's poses along every written traverse (part coordinates): the machine's
/// joint-linear moves from the previous path's last axes through the traverse's waypoints to
/// the path's first axes, 64 samples a move, through `machine`'s forward kinematics; and how
/// many traverses there were.
fn traverse_poses(
    machine: &Machine,
    curves: &kerf_format::CurvesFile,
    out: &kerf_pipeline::Output,
) -> (Vec<Placed>, usize) {
    use kerf_kinematics::Axes;
    let paths = &out.axes.paths;
    let mut poses = Vec::new();
    let mut count = 0;
    for k in 1..paths.len() {
        let Some(t) = &paths[k].traverse else {
            continue;
        };
        count += 1;
        let prev = &paths[k - 1];
        let last = prev
            .lead_out
            .as_ref()
            .and_then(|m| m.positions.last())
            .or(prev.positions.last())
            .expect("the previous path's end");
        let first = paths[k]
            .lead_in
            .as_ref()
            .and_then(|m| m.positions.first())
            .or(paths[k].positions.first())
            .expect("the path's start");
        let mut way: Vec<Axes> = vec![Axes::from(*last)];
        way.extend(t.positions.iter().map(|q| Axes::from(*q)));
        way.push(Axes::from(*first));
        let i = curves
            .curves
            .iter()
            .position(|c| c.id == paths[k].id)
            .expect("curve");
        let pl = out.placement.placement_of(i);
        let (r, shift) = (pl.rotation(), pl.translation_mm);
        for w in way.windows(2) {
            for j in 0..=64 {
                let q = machine
                    .kinematics
                    .forward(&w[0].lerp(&w[1], j as f64 / 64.0));
                poses.push((
                    Point3::from(r.inverse() * (q.position - shift)),
                    r.inverse() * q.axis.normalize(),
                ));
            }
        }
    }
    (poses, count)
}

/// A head fixture run with a tilt tolerance: every path clears by tilting (reported), and
/// dense sampling of the head at every written pose agrees; upright on the curve's own
/// normals (`normal` at each written point), the same sampling finds it closer than the
/// clearance: the tilt, not the sampling, made the difference.
fn tilted_fixture(
    name: &str,
    id: &str,
    clearance: f64,
    normal: impl Fn(&Point3<f64>) -> Vector3<f64>,
) -> (f64, usize) {
    let curves = kerf_format::curves::load(fixture(name)).expect("curves");
    let machine = Machine::read(fixture("machines/gantry_ac.json")).expect("machine");
    let run = |tilt: f64| {
        Job::new(curves.clone(), machine.clone())
            .with_options(
                JobOptions::default()
                    .with_cut_clearance_mm(Some(clearance))
                    .with_path(
                        kerf_kinematics::PathOptions::default().with_tilt_tolerance_deg(tilt),
                    ),
            )
            .run()
    };
    let e = run(0.0).expect_err("upright: refused").to_string();
    assert!(e.contains(id) && e.contains("would clear it"), "{e}");
    let out = run(10.0).expect("tilted to clear");
    let head = &out.report.head;
    let zone = head.tip_zone_mm.flatten().expect("zone");
    let entry = head
        .paths
        .as_ref()
        .expect("paths")
        .iter()
        .find(|p| p.path == id)
        .expect("path")
        .clone();
    let tilt = entry.tilted.max_tilt_deg;
    assert!(tilt > 0.5 && tilt <= 10.0, "{entry:?}");
    // The picture marks the tilted stretches in every view, and nothing close.
    let bands = out.plot_svg.matches("class=\"head-tilted\"").count();
    assert!(bands >= 4 && bands % 4 == 0, "{name}: {bands} tilted bands");
    assert_eq!(
        out.plot_svg.matches("class=\"head-close\"").count(),
        0,
        "nothing close"
    );
    let surfaces = exact_surfaces(name);
    let poses = written_poses(&curves, &out, id);
    let d = sampled_distance(&poses, zone, &surfaces);
    assert!(
        d >= clearance - kerf_process::RESOLUTION_MM - kerf_process::SAMPLE_STEP_MM / 2.0,
        "{name}: dense sampling finds the head within {d} mm of the part"
    );
    // The traverses too: the head model along the machine's moves keeps the clearance (the
    // head check of the traverses), by the same sampling.
    let (along, traverses) = traverse_poses(&machine, &curves, &out);
    if traverses > 0 {
        let proven = out
            .report
            .traverses
            .head_min_distance_mm
            .expect("the traverses' head distance");
        let t = sampled_distance(&along, zone, &surfaces);
        assert!(
            t >= clearance - kerf_process::RESOLUTION_MM - kerf_process::SAMPLE_STEP_MM / 2.0
                && t >= proven - 0.05,
            "{name}: along the traverses dense sampling finds the head within {t} mm (proven {proven})"
        );
    }
    let upright: Vec<(Point3<f64>, Vector3<f64>)> =
        poses.iter().map(|(p, _)| (*p, normal(p))).collect();
    let u = sampled_distance(&upright, zone, &surfaces);
    assert!(u < clearance, "{name}: upright the head keeps {u} mm");
    (tilt, traverses)
}

#[test]
fn a_tilt_within_the_tolerance_clears_the_wall_and_dense_sampling_agrees() {
    let (tilt, traverses) =
        tilted_fixture("head_wall.json", "hole-near-wall", 3.0, |_| Vector3::z());
    assert_eq!(
        traverses, 1,
        "the traverse between the holes is sampled too"
    );
    assert!(tilt < 5.0, "{tilt}");
}

#[test]
fn a_trim_line_in_a_u_channel_is_tilted_away_from_the_nearer_wall() {
    tilted_fixture("head_channel.json", "channel-trim", 1.0, |_| Vector3::z());
}

#[test]
fn a_trim_line_on_a_bend_leans_away_from_the_flange() {
    // On the bend the normal points to its axis (x = 0, z = 20); on the floor it is +z.
    tilted_fixture("head_bend.json", "bend-trim", 1.0, |p| {
        if p.x > 1e-6 {
            Vector3::new(-p.x, 0.0, 20.0 - p.z).normalize()
        } else {
            Vector3::z()
        }
    });
}

#[test]
fn without_a_tilt_tolerance_the_refusal_says_which_tilt_would_clear() {
    let e = job(3.0, false).expect_err("refused").to_string();
    assert!(
        e.contains("deg away from surface wall would clear it")
            && e.contains("a tilt_tolerance_deg of"),
        "{e}"
    );
}

/// Two holes of radius 5 at `y = -60` and `y = 60` in a floor, and between them a rib 40 mm
/// high at `x = 30` (`y` from -10 to 10): the tip and the nozzle line pass it 25 mm off at any
/// retract, the head's 90 mm body (from 26 mm above the tip) meets it below 14 mm of retract.
fn rib_file() -> kerf_format::CurvesFile {
    let hole = |id: &str, y: f64| {
        format!(
            r#"{{"id": "{id}", "degree": 2, "knots": [0, 0, 0, 0.25, 0.25, 0.5, 0.5, 0.75, 0.75, 1, 1, 1],
            "control_points": [[5, {y}, 0], [5, {a}, 0], [0, {a}, 0], [-5, {a}, 0], [-5, {y}, 0], [-5, {b}, 0], [0, {b}, 0], [5, {b}, 0], [5, {y}, 0]],
            "weights": [1, 0.7071067811865476, 1, 0.7071067811865476, 1, 0.7071067811865476, 1, 0.7071067811865476, 1],
            "surface": "floor", "scrap": "left"}}"#,
            a = y + 5.0,
            b = y - 5.0
        )
    };
    let text = format!(
        r#"{{"format": "kerf.curves/1", "units": "mm", "curves": [{}, {}], "surfaces": [
        {{"type": "nurbs", "id": "floor", "degree_u": 1, "degree_v": 1, "knots_u": [0, 0, 1, 1], "knots_v": [0, 0, 1, 1],
          "control_points": [[[-200, -200, 0], [-200, 200, 0]], [[200, -200, 0], [200, 200, 0]]]}},
        {{"type": "nurbs", "id": "rib", "degree_u": 1, "degree_v": 1, "knots_u": [0, 0, 1, 1], "knots_v": [0, 0, 1, 1],
          "control_points": [[[30, -10, 0], [30, -10, 40]], [[30, 10, 0], [30, 10, 40]]]}}]}}"#,
        hole("hole-a", -60.0),
        hole("hole-b", 60.0)
    );
    kerf_format::curves::from_str(&text, std::path::Path::new(".")).expect("the rib file")
}

/// The rib's and the floor's exact surfaces.
fn rib_surfaces() -> Vec<Exact> {
    let p = Point3::new;
    let v = Vector3::new;
    vec![
        Exact::Rect(
            p(-200.0, -200.0, 0.0),
            v(400.0, 0.0, 0.0),
            v(0.0, 400.0, 0.0),
        ),
        Exact::Rect(p(30.0, -10.0, 0.0), v(0.0, 20.0, 0.0), v(0.0, 0.0, 40.0)),
    ]
}

fn rib_run(
    machine: &Machine,
    clearance: Option<f64>,
    accept: bool,
) -> Result<kerf_pipeline::Output, kerf_pipeline::Error> {
    Job::new(rib_file(), machine.clone())
        .with_options(
            JobOptions::default()
                .with_cut_clearance_mm(clearance)
                .with_accept_head_collisions(accept),
        )
        .run()
}

/// With the head check, the traverse between the holes rises over the rib (the head model
/// along the traverse, `kerf_process::TraverseHead`): dense sampling of the head along the
/// machine's written moves against the exact rib finds at least the clearance less the
/// check's resolution, and not less than the distance the report claims proven; without the
/// head check the same sampling finds the body in the rib.
#[test]
fn the_traverse_rises_over_a_rib_the_head_would_meet() {
    let machine = Machine::read(fixture("machines/gantry_ac.json")).expect("machine");
    let curves = rib_file();
    let surfaces = rib_surfaces();
    let out = rib_run(&machine, Some(1.0), false).expect("clear");
    let zone = out.report.head.tip_zone_mm.flatten().expect("zone");
    let (along, n) = traverse_poses(&machine, &curves, &out);
    assert_eq!(n, 1);
    let proven = out
        .report
        .traverses
        .head_min_distance_mm
        .expect("the head checked along the traverse");
    assert_eq!(out.report.traverses.head_too_close, Some(0));
    let d = sampled_distance(&along, zone, &surfaces);
    assert!(
        d >= 1.0 - kerf_process::RESOLUTION_MM - kerf_process::SAMPLE_STEP_MM / 2.0
            && d >= proven - 0.05,
        "sampled {d}, proven {proven}"
    );
    let plain = rib_run(&machine, None, false).expect("without the head check");
    let (along, n) = traverse_poses(&machine, &curves, &plain);
    assert_eq!(n, 1);
    let d = sampled_distance(&along, zone, &surfaces);
    assert!(
        d < 0.5,
        "the body meets the rib without the head check: {d}"
    );
}

/// The same part on a machine whose Z travel ends 2 mm above the retract point: no route the
/// machine reaches clears the head, and the run is refused naming the traverse and the rib;
/// accepted, the route the nozzle line clears is taken with a warning, counted in the report.
#[test]
fn a_traverse_the_head_clears_on_no_route_is_refused_by_name() {
    let mut machine = Machine::read(fixture("machines/gantry_ac.json")).expect("machine");
    let plain = rib_run(&machine, None, false).expect("without the head check");
    let z = plain.axes.paths[1]
        .traverse
        .as_ref()
        .expect("traverse")
        .positions[0][2];
    machine.limits[2] = Some(kerf_kinematics::Range {
        min: z - 100.0,
        max: z + 2.0,
    });
    let e = rib_run(&machine, Some(1.0), false)
        .expect_err("refused")
        .to_string();
    let named = |m: &str| {
        m.contains("the traverse from \"hole-b\" to \"hole-a\"")
            || m.contains("the traverse from \"hole-a\" to \"hole-b\"")
    };
    assert!(named(&e) && e.contains("surface rib"), "{e}");
    let out = rib_run(&machine, Some(1.0), true).expect("accepted");
    assert_eq!(out.report.traverses.head_too_close, Some(1));
    assert!(
        out.warnings
            .iter()
            .any(|w| named(w) && w.contains("accepted")),
        "{:?}",
        out.warnings
    );
}

/// `fixtures/head_slot.json`: a hole at the bottom of a slot 10 mm wide, narrower than the
/// nozzle's cone (14 mm across at its top) and with walls above the body's lower face: no tilt
/// clears it, and the run is refused by default naming the path, the whole hole, a wall of the
/// slot and the tilt search's failure, upright and with a 10-degree tilt tolerance.
#[test]
fn a_hole_in_a_slot_narrower_than_the_nozzle_is_refused_by_name() {
    let curves = kerf_format::curves::load(fixture("head_slot.json")).expect("curves");
    let machine = Machine::read(fixture("machines/gantry_ac.json")).expect("machine");
    for tilt in [0.0, 10.0] {
        let path = kerf_kinematics::PathOptions::default().with_tilt_tolerance_deg(tilt);
        let err = Job::new(curves.clone(), machine.clone())
            .with_options(JobOptions::default().with_path(path))
            .run()
            .expect_err("no tilt clears the slot");
        let msg = err.to_string();
        assert!(
            msg.contains("path \"hole-in-slot\": the head comes too close to the part: poses 0..")
                && (msg.contains("surface slot-left") || msg.contains("surface slot-right"))
                && msg.contains("no tilt up to 60 deg"),
            "tilt tolerance {tilt}: {msg}"
        );
    }
}
