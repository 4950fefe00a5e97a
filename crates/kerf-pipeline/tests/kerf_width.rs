//! Kerf compensation end to end (`kerf run --kerf-width`): the cut poses the kinematics solved
//! (the axes file, placement undone) against the exact contours: holes shrink and outlines
//! grow by half the kerf, never closer to the part than that less the tolerance; sides checked
//! by the projected area, not by the report's word.

use kerf_format::CurvesFile;
use kerf_kinematics::Machine;
use kerf_nurbs::Segment;
use kerf_pipeline::{Job, JobOptions, Output, PlaceMode};
use nalgebra::{Point3, Vector3};

mod common;
use common::fixture;

const TOL: f64 = 0.01;

fn run(name: &str, kerf: Option<f64>, place: PlaceMode) -> (CurvesFile, Output) {
    let curves = kerf_format::curves::load(fixture(name)).expect("curves");
    let mut machine = Machine::read(fixture("machines/gantry_ac.json")).expect("machine");
    machine.process.kerf_width_mm = None;
    let out = Job::new(curves.clone(), machine)
        .with_options(
            JobOptions::default()
                .with_place(place)
                .with_kerf_width_mm(kerf)
                // The head check off for every run here (the offset is what is asserted): the
                // real files' bend and blade edges meet the head (refused by default).
                .with_cut_clearance_mm(None),
        )
        .run()
        .expect("run");
    (curves, out)
}

/// The cut poses of curve `id` (its lead-in and lead-out left out) in part coordinates.
fn cut_points(out: &Output, file: &CurvesFile, id: &str) -> Vec<Point3<f64>> {
    cut_poses(out, file, id).into_iter().map(|p| p.0).collect()
}

/// The cut poses with their tool axes, in part coordinates.
fn cut_poses(out: &Output, file: &CurvesFile, id: &str) -> Vec<(Point3<f64>, Vector3<f64>)> {
    let i = file.curves.iter().position(|c| c.id == id).expect("curve");
    let p = out.placement.placement_of(i);
    let (r, t) = (p.rotation(), p.translation_mm);
    let path = out.axes.paths.iter().find(|p| p.id == id).expect("path");
    path.poses
        .iter()
        .map(|q| {
            (
                Point3::from(r.inverse() * (Point3::new(q[0], q[1], q[2]) - t)),
                r.inverse() * Vector3::new(q[3], q[4], q[5]),
            )
        })
        .collect()
}

/// The contour sampled densely (4,000 chords and its corners).
fn dense(file: &CurvesFile, id: &str) -> Vec<Point3<f64>> {
    let c = &file
        .curves
        .iter()
        .find(|c| c.id == id)
        .expect("curve")
        .curve;
    let (a, b) = c.domain();
    // The corners are points of it.
    let mut t: Vec<f64> = (0..=4000)
        .map(|k| a + (b - a) * k as f64 / 4000.0)
        .chain(c.c0_breaks())
        .collect();
    t.sort_by(f64::total_cmp);
    t.iter().map(|&u| c.point(u)).collect()
}

fn distance(p: &Point3<f64>, poly: &[Point3<f64>]) -> f64 {
    poly.windows(2)
        .map(|w| Segment::between(&w[0], &w[1]).distance_to(p))
        .fold(f64::INFINITY, f64::min)
}

/// The area of a closed polyline (its Newell vector's length: the area of a plane polygon,
/// of its projection onto its best plane otherwise).
fn area(poly: &[Point3<f64>]) -> (f64, Vector3<f64>) {
    let o = poly[0].coords;
    let mut a = Vector3::zeros();
    for w in poly.windows(2) {
        a += (w[0].coords - o).cross(&(w[1].coords - o));
    }
    (
        0.5 * a.norm(),
        a.try_normalize(0.0).unwrap_or_else(Vector3::z),
    )
}

fn length(poly: &[Point3<f64>]) -> f64 {
    poly.windows(2).map(|w| (w[1] - w[0]).norm()).sum()
}

/// Checks every closed contour of `name` cut with a 0.2 mm kerf: every cut pose at most
/// `r + slack` and at least `r - TOL` from the contour (the beam's edge never enters the part),
/// and the enclosed area smaller by about `length * r` for holes and larger for outlines.
/// Returns the ids with their side, "hole" or "outline", as the geometry shows ("open" for
/// an open contour with a known scrap side, "along" for a loop the beam cuts along its plane).
fn check(name: &str, place: PlaceMode, slack: f64) -> Vec<(String, &'static str)> {
    let r = 0.1;
    let (file, out) = run(name, Some(0.2), place);
    let mut sides = Vec::new();
    let report = &out.report.compensation;
    assert_eq!(report.kerf_width_mm, Some(0.2), "{name}: the width used");
    for path in report.paths.as_ref().expect("paths") {
        let id = path.id.as_str();
        if path.side.is_none() {
            let why = path.reason.as_deref().expect("reason");
            assert!(
                why.contains("scrap side is not known"),
                "{name} {id}: {why}"
            );
            continue;
        }
        let contour = dense(&file, id);
        let poses = cut_poses(&out, &file, id);
        let cut: Vec<Point3<f64>> = poses.iter().map(|p| p.0).collect();
        // A cut-back inside corner keeps the beam farther off: r plus the material left.
        let most = r + slack.max(path.max_corner_material_mm.expect("material") + 1e-9);
        for p in &cut {
            let d = distance(p, &contour);
            assert!(
                d >= r - TOL - 1e-9 && d <= most,
                "{name} {id}: the cut pose {p} is {d:.5} mm from the contour (r = {r}, at most {most})"
            );
        }
        if (contour[0] - contour[contour.len() - 1]).norm() > 1e-6 {
            // An open contour with a known side (a wall's): the distances above only.
            sides.push((id.to_string(), "open"));
            continue;
        }
        // The area changes where the beam crosses the contour's plane (a hole in a sheet); a
        // beam along the plane (round a tube) moves the contour along the tube instead.
        let (a0, a1) = (area(&contour).0, area(&cut).0);
        let plane = area(&contour).1;
        let across = poses
            .iter()
            .map(|p| p.1.dot(&plane).abs())
            .fold(1.0, f64::min);
        if across < 0.5 {
            sides.push((id.to_string(), "along"));
            continue;
        }
        let change = length(&contour) * r;
        let kind = if a1 < a0 { "hole" } else { "outline" };
        // The cut is a chord polygon: its sag (at most the tolerance) takes up to
        // length * TOL of area more.
        assert!(
            ((a1 - a0).abs() - change).abs() <= 0.02 * change + length(&contour) * TOL,
            "{name} {id}: area {a0} -> {a1}, expected a change of {change}"
        );
        sides.push((id.to_string(), kind));
    }
    sides
}

#[test]
fn sheet_metal_holes_shrink_by_half_the_kerf_and_the_outline_grows() {
    let sides = check("sheet_metal_holes.json", PlaceMode::AsModelled, TOL + 1e-9);
    assert_eq!(sides.len(), 8);
    for (id, kind) in &sides {
        let want = if id == "outline" { "outline" } else { "hole" };
        assert_eq!(kind, &want, "{id}");
    }
    // Exactly: the circular holes' cut poses lie on circles R - r about their centres.
    let (file, out) = run("sheet_metal_holes.json", Some(0.2), PlaceMode::AsModelled);
    let (_, plain) = run("sheet_metal_holes.json", None, PlaceMode::AsModelled);
    for c in file.curves.iter().filter(|c| c.id.starts_with("hole-d")) {
        let (centre, radius) = circle_of(&c.curve);
        for (o, want) in [(&out, radius - 0.1), (&plain, radius)] {
            for p in cut_points(o, &file, &c.id) {
                let d = (p.coords - centre).norm();
                assert!((d - want).abs() <= TOL, "{}: {d} against {want}", c.id);
            }
        }
    }
    assert!(plain.report.compensation.kerf_width_mm.is_none());
    let header = &out.programs[0].text;
    assert!(
        header.contains(
            "kerf compensation in the computer: kerf 0.2 mm from the run's kerf_width_mm, 8 paths offset 0.1 mm"
        ),
        "{}",
        &header[..600]
    );
    assert!(
        plain.programs[0].text.contains(
            "kerf compensation: none, no kerf width given: the path is the contour itself"
        ),
        "no kerf"
    );
}

#[test]
fn door_trim_and_tube_saddle_are_compensated_on_their_curved_surfaces() {
    // Off a plane the tip stays r from the contour in the plane across the tool axis, a
    // little less in space where the axis leans along it.
    let door = check("door_trim.json", PlaceMode::AsModelled, TOL + 2e-3);
    assert_eq!(
        door,
        [
            ("speaker-hole".to_string(), "hole"),
            ("switch-cutout".to_string(), "hole"),
            ("trim-outline".to_string(), "outline"),
        ]
    );
    // The hole in the main tube shrinks (the file names its inside the scrap: a closed
    // contour inside no other would be taken for an outline); the branch tube's end runs round
    // the tube, where the winding tells no side: cut on the contour, with the reason.
    let saddle = check("tube_saddle.json", PlaceMode::AsModelled, TOL + 2e-3);
    assert_eq!(saddle, [("main-tube-hole".to_string(), "hole")]);
    // Every chord of every offset on these curved surfaces is proven within the tolerance
    // (the second-derivative bound of docs/process.md), not only measured.
    for name in ["door_trim.json", "tube_saddle.json"] {
        let (_, out) = run(name, Some(0.2), PlaceMode::AsModelled);
        let paths = out.report.compensation.paths.as_ref().expect("paths");
        let offset: Vec<_> = paths.iter().filter(|p| p.proven.is_some()).collect();
        assert!(!offset.is_empty(), "{name}: offset paths");
        for p in offset {
            assert_eq!(p.proven, Some(true), "{name} {}: proven", p.id);
        }
    }
}

#[test]
fn the_real_parts_run_with_a_kerf_and_say_which_contours_were_not_compensated() {
    for name in [
        "realdata/nori_sheetmetal.json",
        "realdata/occt_propeller.json",
    ] {
        let sides = check(name, PlaceMode::Auto, TOL + 2e-3);
        assert!(!sides.is_empty(), "{name}: some closed contours");
        let (_, out) = run(name, Some(0.2), PlaceMode::Auto);
        let open = out
            .report
            .compensation
            .paths
            .as_ref()
            .expect("paths")
            .iter()
            .filter(|p| p.reason.is_some())
            .count();
        if open > 0 {
            assert!(
                out.warnings
                    .iter()
                    .any(|w| w.contains("not kerf-compensated")),
                "{name}: {:?}",
                out.warnings
            );
        }
    }
}

#[test]
fn the_machine_files_kerf_width_is_used_and_the_runs_wins() {
    let curves = kerf_format::curves::load(fixture("circle.json")).expect("curves");
    let mut machine = Machine::read(fixture("machines/gantry_ac.json")).expect("machine");
    machine.process.kerf_width_mm = Some(0.3);
    let out = Job::new(curves.clone(), machine.clone())
        .run()
        .expect("run");
    let c = &out.report.compensation;
    assert_eq!(c.kerf_width_mm, Some(0.3));
    assert!(c.source.as_deref().expect("source").contains("machine"));
    let out = Job::new(curves, machine)
        .with_options(JobOptions::default().with_kerf_width_mm(Some(0.1)))
        .run()
        .expect("run");
    assert_eq!(out.report.compensation.kerf_width_mm, Some(0.1));
    let e = JobOptions::default()
        .with_kerf_width_mm(Some(-1.0))
        .validate()
        .expect_err("negative kerf");
    assert!(e.to_string().contains("kerf_width_mm"), "{e}");
}

fn in_control(
    name: &str,
    dialect: kerf_interp::Dialect,
) -> Result<(CurvesFile, Output), kerf_pipeline::Error> {
    let curves = kerf_format::curves::load(fixture(name)).expect("curves");
    let machine = Machine::read(fixture("machines/gantry_ac.json")).expect("machine");
    let out = Job::new(curves.clone(), machine)
        .with_options(
            JobOptions::default()
                .with_dialect(dialect)
                .with_kerf_width_mm(Some(0.2))
                .with_kerf_in_control(true),
        )
        .run()?;
    Ok((curves, out))
}

/// The centre and radius of a fixture's circle: its control polygon is a regular one closed
/// on itself, so the centre is the mean of its distinct control points.
fn circle_of(curve: &kerf_nurbs::NurbsCurve) -> (Vector3<f64>, f64) {
    let cps = curve.control_points();
    let centre = cps[..cps.len() - 1]
        .iter()
        .fold(Vector3::zeros(), |s, p| s + p.coords)
        / (cps.len() - 1) as f64;
    (centre, (cps[0].coords - centre).norm())
}

/// The paths are the contours themselves: every cut pose of the holes on its circle.
fn holes_cut_on_their_circles(out: &Output, file: &CurvesFile) {
    for curve in file.curves.iter().filter(|c| c.id.starts_with("hole-d")) {
        let (centre, radius) = circle_of(&curve.curve);
        for p in cut_points(out, file, &curve.id) {
            assert!(
                ((p.coords - centre).norm() - radius).abs() <= TOL,
                "{}",
                curve.id
            );
        }
    }
}

#[test]
fn the_controller_compensates_the_contours_themselves_with_g41_and_g42() {
    let (file, out) =
        in_control("sheet_metal_holes.json", kerf_interp::Dialect::Linuxcnc).expect("run");
    let c = &out.report.compensation;
    assert_eq!(c.mode.as_deref(), Some("controller"), "{c:?}");
    // The sides the computer's offset takes (checked by the geometry above).
    let (_, computer) = run("sheet_metal_holes.json", Some(0.2), PlaceMode::AsModelled);
    let sides = |o: &Output| -> Vec<(String, Option<String>)> {
        o.report
            .compensation
            .paths
            .as_ref()
            .expect("paths")
            .iter()
            .map(|p| (p.id.clone(), p.side.clone()))
            .collect()
    };
    assert_eq!(sides(&out), sides(&computer), "the same sides");
    // The paths are the contours: the holes' cut poses on their circles.
    holes_cut_on_their_circles(&out, &file);
    // Every cut: beam on, the descent, G41.1 (scrap on the left) or G42.1 before the lead-in,
    // G40 before the beam goes off; holes (left of their counter-clockwise contour) G41.1.
    let text = &out.programs[0].text;
    let lines: Vec<&str> = text.lines().map(str::trim).collect();
    let on: Vec<usize> = (0..lines.len()).filter(|&i| lines[i] == "M64 P0").collect();
    assert_eq!(on.len(), 8, "eight cuts");
    let left = lines.iter().filter(|l| l.starts_with("G41.1 D0.2")).count();
    let right = lines.iter().filter(|l| l.starts_with("G42.1 D0.2")).count();
    let want_left = sides(&out)
        .iter()
        .filter(|s| s.1.as_deref() == Some("left"))
        .count();
    assert_eq!(
        (left, right),
        (want_left, 8 - want_left),
        "one compensation per cut"
    );
    for &i in &on {
        let comp = (i..lines.len())
            .find(|&j| lines[j].starts_with("G41.1") || lines[j].starts_with("G42.1"))
            .expect("compensation on");
        let off = (i..lines.len())
            .find(|&j| lines[j] == "M65 P0")
            .expect("beam off");
        assert!(comp < off, "on within the cut");
        assert_eq!(lines[off - 1], "G40", "off before the beam");
        // Between the beam and the compensation: the pierce dwell, the blend mode and the
        // descent only.
        assert!(comp - i <= 4, "{:?}", &lines[i..=comp]);
    }
    assert!(
        text.contains(
            "kerf compensation in the controller: G41.1/G42.1 D0.2 from the run's kerf_width_mm on 8 paths"
        ),
        "header"
    );
}

/// A number after `word` (`X`, `A3=`, `OFFN=`) in a Sinumerik line.
fn word(line: &str, word: &str) -> Option<f64> {
    line.split_whitespace()
        .find_map(|w| w.strip_prefix(word))
        .and_then(|v| v.parse().ok())
}

/// Checks every compensated cut of a Sinumerik program against the part, not against kerf's
/// own choice of side, and returns how many there are and the largest tilt of the beam (degrees
/// from +z) among them: `OFFN` of half the kerf before `G41`/`G42`, which come after the beam
/// is on; `G40` and `OFFN=0` after it is off. The tips of each compensated stretch (lead-in,
/// contour, lead-out; a `CIP` arc's intermediate point before its end) run round their loop
/// one way or the other seen down the stretch's mean tool axis (`A3 B3 C3`), and `G41`, the
/// left of the path seen from the tool's side, must put the beam inside every cut-out (its
/// scrap) and outside `outline`.
fn sinumerik_sides(text: &str, outline: &str) -> (usize, f64) {
    let lines: Vec<&str> = text.lines().map(str::trim).collect();
    let (mut cuts, mut tilt) = (0, 0.0f64);
    for (i, l) in lines.iter().enumerate() {
        let left = match *l {
            "G41" => true,
            "G42" => false,
            _ => continue,
        };
        cuts += 1;
        let offn = word(lines[i - 1], "OFFN=").expect("OFFN before G41/G42");
        assert!((offn - 0.1).abs() < 1e-9, "half the kerf: {offn}");
        let id = lines[..i]
            .iter()
            .rev()
            .find_map(|l| l.strip_prefix("; curve ").and_then(|r| r.split(',').next()))
            .expect("the cut's curve");
        let m5 = (i..lines.len())
            .find(|&j| lines[j] == "M5")
            .expect("beam off");
        assert_eq!(&lines[m5 + 1..m5 + 3], ["G40", "OFFN=0"], "{id}");
        assert!(
            lines[..i].iter().rev().take(8).any(|l| *l == "M3"),
            "{id}: on after the beam"
        );
        let stretch = &lines[i + 1..m5];
        let point = |l: &str, x: &str, y: &str, z: &str| {
            Some(Point3::new(word(l, x)?, word(l, y)?, word(l, z)?))
        };
        let tips: Vec<Point3<f64>> = stretch
            .iter()
            .flat_map(|l| {
                point(l, "I1=", "J1=", "K1=")
                    .into_iter()
                    .chain(point(l, "X", "Y", "Z"))
            })
            .collect();
        assert!(tips.len() >= 6, "{id}: {} points", tips.len());
        let axis = stretch
            .iter()
            .filter_map(|l| point(l, "A3=", "B3=", "C3="))
            .fold(Vector3::zeros(), |s, a| s + a.coords)
            .normalize();
        for l in stretch {
            if let Some(a) = point(l, "A3=", "B3=", "C3=") {
                tilt = tilt.max(a.coords.normalize().z.clamp(-1.0, 1.0).acos().to_degrees());
            }
        }
        // Twice the loop's area seen down the mean axis (about its centroid: Newell's sum).
        let c = tips.iter().fold(Vector3::zeros(), |s, p| s + p.coords) / tips.len() as f64;
        let turn: f64 = tips
            .iter()
            .zip(tips.iter().cycle().skip(1))
            .map(|(a, b)| (a.coords - c).cross(&(b.coords - c)).dot(&axis))
            .sum();
        let cut_out = id != outline;
        assert_eq!(
            left,
            (turn > 0.0) == cut_out,
            "{id}: turn {turn}, cut-out {cut_out}"
        );
    }
    (cuts, tilt)
}

/// Sinumerik's `CUT3DC` compensates at right angles to the path and the tool orientation, so
/// the leaning, turning beam of the door trim is compensated too; the sides are checked on
/// both parts against the part ([`sinumerik_sides`]).
#[test]
fn sinumerik_compensates_with_cut3dc_offn_and_g41_or_g42_on_the_scrap_side() {
    let (file, out) =
        in_control("sheet_metal_holes.json", kerf_interp::Dialect::Sinumerik).expect("run");
    let text = &out.programs[0].text;
    let lines: Vec<&str> = text.lines().map(str::trim).collect();
    let at = |l: &str| lines.iter().position(|x| *x == l);
    let traori = at("TRAORI").expect("TRAORI");
    assert_eq!(
        lines[traori + 3],
        "CUT3DC",
        "CUT3DC after the orientation modes"
    );
    assert_eq!(lines[traori + 4], "G450", "circles at outside corners");
    assert!(at("CUT2D").expect("CUT2D") < at("TRAFOOF").expect("TRAFOOF"));
    assert!(text.contains(
        "kerf compensation in the controller: CUT3DC G41/G42 OFFN=0.1 [active D radius 0; 3D TRC option] from the run's kerf_width_mm on 8 paths"
    ));
    let (cuts, tilt) = sinumerik_sides(text, "outline");
    assert_eq!(cuts, 8, "one compensation per cut");
    assert!(
        tilt < 1e-3,
        "the gantry's beam stands vertical here: {tilt}"
    );
    // The paths are the contours themselves (the holes' cut poses on their circles).
    holes_cut_on_their_circles(&out, &file);
    // The door trim's beam leans (5 to 16 degrees) and turns: G41.1 cannot, CUT3DC can.
    let (_, door) = in_control("door_trim.json", kerf_interp::Dialect::Sinumerik).expect("door");
    let (cuts, tilt) = sinumerik_sides(&door.programs[0].text, "trim-outline");
    assert_eq!(cuts, door.solved.len(), "every cut compensated");
    assert!(tilt > 4.0, "a leaning beam: {tilt} deg");
    assert_eq!(door.report.compensation.mode.as_deref(), Some("controller"));
}

#[test]
fn the_controller_compensation_is_refused_where_it_cannot_hold() {
    let Err(e) = in_control("sheet_metal_holes.json", kerf_interp::Dialect::Generic) else {
        panic!("generic has no compensation")
    };
    assert!(e.to_string().contains("dialects only"), "{e}");
    // The door trim's beam leans and turns: G41.1 offsets X and Y only.
    let Err(e) = in_control("door_trim.json", kerf_interp::Dialect::Linuxcnc) else {
        panic!("a turning beam")
    };
    assert!(e.to_string().contains("needs the beam vertical"), "{e}");
    // Both controllers engage on the lead-in's first line, which must be longer than half
    // the kerf at right angles to the tool axis: a 0.05 mm straight start is refused by name.
    for dialect in [
        kerf_interp::Dialect::Linuxcnc,
        kerf_interp::Dialect::Sinumerik,
    ] {
        let curves = kerf_format::curves::load(fixture("sheet_metal_holes.json")).expect("curves");
        let machine = Machine::read(fixture("machines/gantry_ac.json")).expect("machine");
        let e = Job::new(curves, machine)
            .with_options(
                JobOptions::default()
                    .with_dialect(dialect)
                    .with_kerf_width_mm(Some(0.2))
                    .with_kerf_in_control(true)
                    .with_leads(kerf_process::LeadOptions::default().with_lead_in(0.05, 0.0)),
            )
            .run()
            .expect_err("too short an entry move");
        let text = e.to_string();
        assert!(
            text.contains("longer than half the kerf (0.1 mm) at right angles to the tool axis")
                && text.contains("here it is 0.0500 mm"),
            "{dialect:?}: {text}"
        );
    }
}

#[test]
fn kerf_check_measures_the_offset_and_catches_a_wrong_one() {
    use kerf_check::{check, CheckOptions, Defect, RawToolpath};
    for name in ["sheet_metal_holes.json", "door_trim.json"] {
        let (file, out) = run(name, Some(0.2), PlaceMode::AsModelled);
        let raw = RawToolpath::from(&out.toolpath);
        let report = check(&file.curves, &raw, &CheckOptions::default());
        assert!(report.passed(), "{name}: {:?}", report.violations);
        for p in &report.paths {
            let o = p.kerf_offset.expect("every closed contour offset");
            assert!(o.max_chord_error <= TOL, "{name} {}: {o:?}", p.id);
            assert!(
                o.min_distance_from_curve >= 0.1 - TOL,
                "{name} {}: {o:?}",
                p.id
            );
            assert_eq!(o.segments + o.cut_backs + 1, o.points, "{name} {}", p.id);
        }
        // Written and read back: the key survives the file.
        let text = kerf_format::toolpath::to_string(&out.toolpath).expect("write");
        let back = kerf_format::toolpath::from_str(&text).expect("read");
        assert_eq!(back, out.toolpath, "{name}: the toolpath round-trips");
        // The wrong side: every chord far from the exact offset.
        let mut wrong = raw.clone();
        let o = wrong.paths[0].kerf_offset.as_mut().expect("offset");
        o.side = match o.side {
            kerf_format::ScrapSide::Left => kerf_format::ScrapSide::Right,
            kerf_format::ScrapSide::Right => kerf_format::ScrapSide::Left,
        };
        let report = check(&file.curves, &wrong, &CheckOptions::default());
        assert!(
            report
                .violations
                .iter()
                .any(|v| matches!(v.defect, Defect::OffsetChordError { .. })),
            "{name}: the wrong side"
        );
        // One point pushed 0.05 mm toward the part: a gouge.
        let mut gouged = raw.clone();
        let o = gouged.paths[0].kerf_offset.as_mut().expect("offset");
        let c = file.curves[0].curve.point(o.params[3]);
        let p = &mut o.points[3];
        let toward = (c - Point3::new(p[0], p[1], p[2])).normalize() * 0.05;
        p[0] += toward.x;
        p[1] += toward.y;
        p[2] += toward.z;
        let report = check(&file.curves, &gouged, &CheckOptions::default());
        assert!(
            report
                .violations
                .iter()
                .any(|v| matches!(v.defect, Defect::OffsetGouge { .. })),
            "{name}: {:?}",
            report.violations
        );
    }
}

/// A square hole of half-size `h` about `(0, 0, 0)` with corners rounded to `rho` (lines and
/// rational quarter circles, degree 2), clockwise seen from +z: no outline around it, so the
/// file says its inside is scrap (`scrap: right` of a clockwise contour).
fn rounded_hole(h: f64, rho: f64) -> kerf_nurbs::NurbsCurve {
    let w = std::f64::consts::FRAC_1_SQRT_2;
    let e = h - rho;
    let ccw = [
        (h, -e, 1.0),
        (h, 0.0, 1.0),
        (h, e, 1.0),
        (h, h, w),
        (e, h, 1.0),
        (0.0, h, 1.0),
        (-e, h, 1.0),
        (-h, h, w),
        (-h, e, 1.0),
        (-h, 0.0, 1.0),
        (-h, -e, 1.0),
        (-h, -h, w),
        (-e, -h, 1.0),
        (0.0, -h, 1.0),
        (e, -h, 1.0),
        (h, -h, w),
        (h, -e, 1.0),
    ];
    let pts: Vec<_> = ccw.iter().rev().collect();
    let mut knots = vec![0.0; 3];
    for k in 1..8 {
        knots.extend([k as f64, k as f64]);
    }
    knots.extend([8.0; 3]);
    kerf_nurbs::NurbsCurve::new(
        2,
        knots,
        pts.iter().map(|p| Point3::new(p.0, p.1, 0.0)).collect(),
        Some(pts.iter().map(|p| p.2).collect()),
    )
}

#[test]
fn a_hole_with_roundings_tighter_than_the_kerf_is_cut_back_and_checked() {
    let machine = Machine::read(fixture("machines/gantry_ac.json")).expect("machine");
    let mut curves = Job::on_machine(machine.clone())
        .with_curve("slot", rounded_hole(10.0, 0.05), None)
        .curves()
        .clone();
    curves.curves[0].scrap = Some(kerf_format::ScrapSide::Right);
    let out = Job::new(curves.clone(), machine)
        .with_options(JobOptions::default().with_kerf_width_mm(Some(0.2)))
        .run()
        .expect("run");
    let p = &out.report.compensation.paths.as_ref().expect("paths")[0];
    assert_eq!(p.inside_corners, Some(4), "{p:?}");
    assert_eq!(p.side.as_deref(), Some("right"), "{p:?}");
    let raw = kerf_check::RawToolpath::from(&out.toolpath);
    let report = kerf_check::check(&curves.curves, &raw, &kerf_check::CheckOptions::default());
    assert!(report.passed(), "{:?}", report.violations);
    let o = report.paths[0].kerf_offset.expect("offset");
    // Three chords straddle a rounding; the fourth cut-back is where the path closes, split
    // between its first and last chords.
    assert_eq!(o.cut_backs, 3, "{o:?}");
    assert_eq!(o.segments + o.cut_backs + 1, o.points, "{o:?}");
    assert!(o.min_distance_from_curve >= 0.1 - TOL, "{o:?}");
}
