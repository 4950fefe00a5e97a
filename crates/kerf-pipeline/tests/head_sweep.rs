//! The head check against an independent sweep, on every fixture and real file on every
//! shipped machine (issue 28's "done when"). Each run checks the head at 1 mm and accepts what
//! comes closer as warnings, so that every run the machine can make writes its poses and says
//! where the head came close; then the machine's head model is swept along every written pose
//! of every cut (lead-in, contour, lead-out) and through the motion between them, against dense
//! samples of the part's surfaces, each sample's distance to the head taken in closed form in
//! the head's meridian plane. That is not kerf's method (cells of the head against exact NURBS
//! and mesh closest points), and a subset of the surface can only be farther: so wherever kerf
//! reports a cut clear, no sample may come closer than the distance kerf proved
//! (`head.paths[].min_distance_mm`, itself at least the clearance less the check's resolution);
//! and wherever kerf reports a close stretch, the sweep must find the head that close too, less
//! the samples' spacing (the refusals are real, not artefacts of the cells).

use std::collections::HashMap;

use kerf_format::{CurvesFile, SurfaceGeometry};
use kerf_kinematics::{Head, Machine, PathOptions};
use kerf_pipeline::{Job, JobOptions, Output, PlaceMode};
use nalgebra::{Point3, Vector3};

mod common;
use common::fixture;

/// The cutting clearance of every run, mm.
const CLEARANCE_MM: f64 = 1.0;

/// The largest distance between neighbouring samples of a surface, mm: every point of the
/// surface lies within about `SPACING_MM / sqrt(2)` of a sample.
const SPACING_MM: f64 = 0.8;

/// The largest motion of any head point between two sweep positions, mm (the check's own
/// sample step).
const STEP_MM: f64 = 0.5;

/// Samples of the part's surfaces, binned for the sweep: fine cells inside coarse ones, each
/// with its centre and radius so that a whole cell is skipped where the head is farther from
/// its centre than its radius plus the best distance found.
struct Cloud {
    /// The surface (index into the file's surfaces) of every bin's points.
    coarse: Vec<Bin>,
    /// The largest distance between neighbouring samples found while sampling, mm.
    spacing_mm: f64,
}

/// One cell of samples: its centre, the radius of the ball about it that holds them, and
/// either the samples or finer cells.
struct Bin {
    centre: Point3<f64>,
    radius: f64,
    points: Vec<(Point3<f64>, usize)>,
    fine: Vec<Bin>,
}

/// A bin over `points` (with their surfaces): its centre and radius.
fn bin(points: Vec<(Point3<f64>, usize)>, fine: Vec<Bin>) -> Bin {
    let all: Vec<Point3<f64>> = if fine.is_empty() {
        points.iter().map(|p| p.0).collect()
    } else {
        fine.iter()
            .flat_map(|b| b.points.iter().map(|p| p.0))
            .collect()
    };
    let centre = Point3::from(
        all.iter().fold(Vector3::zeros(), |s, p| s + p.coords) / all.len().max(1) as f64,
    );
    let radius = all.iter().map(|p| (p - centre).norm()).fold(0.0, f64::max);
    Bin {
        centre,
        radius,
        points,
        fine,
    }
}

/// Points of one NURBS surface on a grid whose neighbours lie at most about `SPACING_MM`
/// apart: each knot span divided by the longest polyline across it (eight rows), then the
/// largest neighbour distance measured.
fn sample_nurbs(s: &kerf_nurbs::NurbsSurface) -> (Vec<Point3<f64>>, f64) {
    let mut out = Vec::new();
    let mut gap: f64 = 0.0;
    for (_, u0, u1) in s.spans_u() {
        for (_, v0, v1) in s.spans_v() {
            let length = |along_u: bool| -> f64 {
                (0..=8)
                    .map(|i| {
                        let c = i as f64 / 8.0;
                        let pt = |t: f64| {
                            if along_u {
                                s.point(u0 + (u1 - u0) * t, v0 + (v1 - v0) * c)
                            } else {
                                s.point(u0 + (u1 - u0) * c, v0 + (v1 - v0) * t)
                            }
                        };
                        (0..32)
                            .map(|k| (pt((k + 1) as f64 / 32.0) - pt(k as f64 / 32.0)).norm())
                            .sum::<f64>()
                    })
                    .fold(0.0, f64::max)
            };
            let nu = ((length(true) / SPACING_MM).ceil() as usize).clamp(1, 4000);
            let nv = ((length(false) / SPACING_MM).ceil() as usize).clamp(1, 4000);
            let grid: Vec<Vec<Point3<f64>>> = (0..=nu)
                .map(|i| {
                    (0..=nv)
                        .map(|j| {
                            s.point(
                                u0 + (u1 - u0) * i as f64 / nu as f64,
                                v0 + (v1 - v0) * j as f64 / nv as f64,
                            )
                        })
                        .collect()
                })
                .collect();
            for i in 0..=nu {
                for j in 0..=nv {
                    if i < nu {
                        gap = gap.max((grid[i + 1][j] - grid[i][j]).norm());
                    }
                    if j < nv {
                        gap = gap.max((grid[i][j + 1] - grid[i][j]).norm());
                    }
                }
            }
            out.extend(grid.into_iter().flatten());
        }
    }
    (out, gap)
}

/// Points of a triangle mesh, each triangle on a barycentric grid fine enough for
/// `SPACING_MM`.
fn sample_mesh(vertices: &[Point3<f64>], triangles: &[[u32; 3]]) -> (Vec<Point3<f64>>, f64) {
    let mut out = Vec::new();
    let mut gap: f64 = 0.0;
    for t in triangles {
        let [a, b, c] = t.map(|i| vertices[i as usize]);
        let longest = (b - a).norm().max((c - b).norm()).max((a - c).norm());
        let n = ((longest / SPACING_MM).ceil() as usize).max(1);
        gap = gap.max(longest / n as f64);
        for i in 0..=n {
            for j in 0..=(n - i) {
                let (x, y) = (i as f64 / n as f64, j as f64 / n as f64);
                out.push(a + (b - a) * x + (c - a) * y);
            }
        }
    }
    (out, gap)
}

impl Cloud {
    /// Samples of the file's surfaces whose indices `keep` holds.
    fn of(file: &CurvesFile, keep: &[usize]) -> Cloud {
        let mut points: Vec<(Point3<f64>, usize)> = Vec::new();
        let mut spacing: f64 = 0.0;
        for &k in keep {
            let (ps, gap) = match &file.surfaces[k].geometry {
                SurfaceGeometry::Nurbs(s) => sample_nurbs(s),
                SurfaceGeometry::Mesh {
                    vertices,
                    triangles,
                } => sample_mesh(vertices, triangles),
            };
            spacing = spacing.max(gap);
            points.extend(ps.into_iter().map(|p| (p, k)));
        }
        // Fine cells of 2 mm inside coarse cells of 16 mm.
        let key = |p: &Point3<f64>, size: f64| [p.x, p.y, p.z].map(|v| (v / size).floor() as i64);
        let mut fine: HashMap<[i64; 3], Vec<(Point3<f64>, usize)>> = HashMap::new();
        for p in points {
            fine.entry(key(&p.0, 2.0)).or_default().push(p);
        }
        let mut coarse: HashMap<[i64; 3], Vec<Bin>> = HashMap::new();
        for (_, ps) in fine {
            let b = bin(ps, Vec::new());
            coarse.entry(key(&b.centre, 16.0)).or_default().push(b);
        }
        Cloud {
            coarse: coarse.into_values().map(|f| bin(Vec::new(), f)).collect(),
            spacing_mm: spacing,
        }
    }

    /// The smallest distance from the head standing at `pose` to the samples, and the
    /// surface of the nearest, where it is below `cap`; else `cap` (bins farther are not
    /// opened: the sweep asks whether anything is nearer than a bound).
    fn distance(&self, head: &Meridian, pose: &Placed, cap: f64) -> (f64, Option<usize>) {
        let mut best = (cap, None);
        for c in &self.coarse {
            if head.distance(pose, &c.centre) - c.radius >= best.0 {
                continue;
            }
            for f in &c.fine {
                if head.distance(pose, &f.centre) - f.radius >= best.0 {
                    continue;
                }
                for (p, k) in &f.points {
                    let d = head.distance(pose, p);
                    if d < best.0 {
                        best = (d, Some(*k));
                    }
                }
            }
        }
        best
    }
}

/// A tip and its tool axis in part coordinates.
type Placed = (Point3<f64>, Vector3<f64>);

/// The head above its tip zone as its meridian section: per solid, the heights of its ends
/// above the nozzle tip and its radii there, the lowest one cut at the tip zone.
struct Meridian {
    standoff: f64,
    solids: Vec<[f64; 4]>,
}

impl Meridian {
    /// The head's solids above `zone` mm over the nozzle tip, standing `standoff` mm above the
    /// cutting point.
    fn new(head: &Head, standoff: f64, zone: f64) -> Self {
        let mut base = 0.0;
        let mut solids = Vec::new();
        for s in &head.solids {
            let top = base + s.length_mm;
            let r = |h: f64| {
                (s.bottom_diameter_mm
                    + (s.top_diameter_mm - s.bottom_diameter_mm) * (h - base) / s.length_mm)
                    / 2.0
            };
            if top > zone {
                let lo = base.max(zone);
                solids.push([lo, r(lo), top, r(top)]);
            }
            base = top;
        }
        Self { standoff, solids }
    }

    /// The distance from `q` to the head standing at `(p, a)` (the cutting point and the unit
    /// tool axis): in the meridian half-plane through `q`, the distance from `(rho, zeta)` to
    /// the union of the solids' trapezoids; 0 inside.
    fn distance(&self, (p, a): &Placed, q: &Point3<f64>) -> f64 {
        let v = q - (p + a * self.standoff);
        let zeta = v.dot(a);
        let rho = (v - a * zeta).norm();
        let mut best = f64::INFINITY;
        for &[z0, r0, z1, r1] in &self.solids {
            // Inside: between the ends and within the radius there.
            if zeta >= z0 && zeta <= z1 && rho <= r0 + (r1 - r0) * (zeta - z0) / (z1 - z0) {
                return 0.0;
            }
            for (a0, a1) in [
                ((0.0, z0), (r0, z0)),
                ((r0, z0), (r1, z1)),
                ((r1, z1), (0.0, z1)),
            ] {
                best = best.min(segment_distance((rho, zeta), a0, a1));
            }
        }
        best
    }
}

/// The distance from `x` to the segment `a b` in the plane.
fn segment_distance(x: (f64, f64), a: (f64, f64), b: (f64, f64)) -> f64 {
    let (dx, dy) = (b.0 - a.0, b.1 - a.1);
    let l2 = dx * dx + dy * dy;
    let t = if l2 > 0.0 {
        (((x.0 - a.0) * dx + (x.1 - a.1) * dy) / l2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    ((x.0 - a.0 - t * dx).powi(2) + (x.1 - a.1 - t * dy).powi(2)).sqrt()
}

/// The written poses of path `k` (lead-in, contour, lead-out: the order of the check's pose
/// indices) in the part's coordinates.
fn written_poses(out: &Output, file: &CurvesFile, k: usize) -> Vec<Placed> {
    let path = &out.axes.paths[k];
    let i = file
        .curves
        .iter()
        .position(|c| c.id == path.id)
        .expect("the path's curve");
    let pl = out.placement.placement_of(i);
    let (r, t) = (pl.rotation(), pl.translation_mm);
    let mut poses: Vec<[f64; 6]> = Vec::new();
    for m in [&path.lead_in].into_iter().flatten() {
        poses.extend(m.poses.iter().copied());
    }
    poses.extend(path.poses.iter().copied());
    for m in [&path.lead_out].into_iter().flatten() {
        poses.extend(m.poses.iter().copied());
    }
    poses
        .iter()
        .map(|q| {
            (
                Point3::from(r.inverse() * (Point3::new(q[0], q[1], q[2]) - t)),
                (r.inverse() * Vector3::new(q[3], q[4], q[5])).normalize(),
            )
        })
        .collect()
}

/// The positions from pose `a` to pose `b` (tip along the chord, axis along the great circle)
/// no head point of `reach` mm moves more than [`STEP_MM`] between, `a` included, `b` not.
fn between(a: &Placed, b: &Placed, reach: f64) -> Vec<Placed> {
    let angle = a.1.angle(&b.1);
    let motion = (b.0 - a.0).norm() + reach * angle;
    let n = ((motion / STEP_MM).ceil() as usize).clamp(1, 100_000);
    (0..n)
        .map(|j| {
            let s = j as f64 / n as f64;
            let axis = if angle > 1e-12 {
                (a.1 * ((1.0 - s) * angle).sin() + b.1 * (s * angle).sin()) / angle.sin()
            } else {
                a.1
            };
            (a.0 + (b.0 - a.0) * s, axis.normalize())
        })
        .collect()
}

/// What the sweep found on one run.
#[derive(Default)]
struct Swept {
    /// Paths checked.
    paths: usize,
    /// Sweep positions.
    positions: usize,
    /// Close stretches kerf reported (and the sweep confirmed).
    close: usize,
    /// The file has no surface: nothing to sweep against.
    bare: bool,
    /// Seconds of the run and of the sweep (for the summary only: nothing is timed).
    seconds: [f64; 2],
}

/// Runs `job` with the head checked at [`CLEARANCE_MM`] (collisions accepted) and sweeps the
/// head along every cut; `None` where the machine cannot make the run for another reason.
fn sweep(
    name: &str,
    job: Job,
    options: JobOptions,
    clouds: &mut HashMap<Vec<usize>, Cloud>,
) -> Option<Swept> {
    let file = job.curves().clone();
    let machine = job.machine().clone();
    let start = std::time::Instant::now();
    let out = match job
        .with_options(
            options
                .with_cut_clearance_mm(Some(CLEARANCE_MM))
                .with_accept_head_collisions(true),
        )
        .run()
    {
        Ok(out) => out,
        Err(e) => {
            // Collisions are accepted: a refusal for the head would be a defect; anything else
            // (the machine's travel, its reach) leaves the run out (the runs made are counted
            // by the tests).
            let head_refusal = matches!(
                &e,
                kerf_pipeline::Error::Process {
                    source: kerf_process::ProcessError::HeadTooClose { .. }
                        | kerf_process::ProcessError::TraverseHeadTooClose { .. },
                    ..
                }
            );
            assert!(
                !head_refusal,
                "{name}: refused for the head although collisions are accepted: {e}"
            );
            return None;
        }
    };
    let ran = start.elapsed().as_secs_f64();
    let report = &out.report.head;
    assert!(report.checked, "{name}: the head was not checked");
    let head = machine.head.clone().unwrap_or_else(Head::laser_default);
    let standoff = report.standoff_mm.expect("the standoff");
    let zone = report.tip_zone_mm.flatten().unwrap_or(0.0);
    let meridian = Meridian::new(&head, standoff, zone);
    let reach = (head.length_mm() + standoff).hypot(head.max_radius_mm());
    let entries = report.paths.as_ref().expect("the head's paths");
    // The part of each surface (kerf's definition of the part a cut lies on: surfaces joined
    // at their boundaries), for the surfaces a cut is swept against.
    let all = kerf_process::Obstacles::from_all_surfaces(&file, |p| *p).expect("obstacles");
    let parts = all.parts(0.05);
    let mut swept = Swept::default();
    for (k, path) in out.axes.paths.iter().enumerate() {
        let entry = entries
            .iter()
            .find(|e| e.path == path.id)
            .unwrap_or_else(|| panic!("{name}: path {} has no head entry", path.id));
        let curve = file
            .curves
            .iter()
            .find(|c| c.id == path.id)
            .expect("the path's curve");
        let seeds: Vec<usize> = file
            .surfaces
            .iter()
            .enumerate()
            .filter(|(_, s)| curve.surfaces.contains(&s.id))
            .map(|(j, _)| parts[j])
            .collect();
        let keep: Vec<usize> = (0..file.surfaces.len())
            .filter(|&j| seeds.is_empty() || seeds.contains(&parts[j]))
            .collect();
        let cloud = clouds
            .entry(keep.clone())
            .or_insert_with(|| Cloud::of(&file, &keep));
        // Every point of a surface lies within this of a sample (a grid cell's corners are at
        // most its spacing apart; 0.1 mm for the surface's bulge over a cell).
        let slack = cloud.spacing_mm / std::f64::consts::SQRT_2 + 0.1;
        let poses = written_poses(&out, &file, k);
        assert!(
            entry.proven,
            "{name}: path {} not proven: {:?}",
            path.id, entry
        );
        let inside = |i: usize| {
            entry
                .close
                .iter()
                .any(|c| c.poses[0] <= i && i <= c.poses[1])
        };
        // Clear poses and the motion to the next one (where both are clear).
        // kerf's proven bound outside the close stretches; where nothing is close, at least
        // the clearance less the check's resolution (0.5 mm), half a sample step (0.25 mm)
        // and the path's deviation (under 0.1 mm with these options).
        // No bound: no sample was shown clear (the whole cut is one close stretch), or the
        // file has no surface at all.
        let bound = match entry.min_distance_mm {
            Some(b) => b,
            None => {
                assert!(
                    file.surfaces.is_empty() || (0..poses.len()).all(inside),
                    "{name}: path {}: no bound, yet poses outside its close stretches",
                    path.id
                );
                f64::INFINITY
            }
        };
        if file.surfaces.is_empty() {
            swept.bare = true;
            swept.paths += 1;
            continue;
        }
        if entry.close.is_empty() {
            assert!(
                bound.is_finite() && bound >= CLEARANCE_MM - 0.85,
                "{name}: path {} reported clear with a bound of {bound} mm",
                path.id
            );
        }
        // The sweep sees the part: the surface a cut lies on passes through each of its
        // cutting points, `standoff + tip zone` from the head's lowest point on the axis, so at
        // every eighth pose of the contour the sweep finds the head at most that (plus the
        // samples' slack and the inserted poses' chord deviation) from it.
        if !curve.surfaces.is_empty() {
            let near = standoff + zone + slack + 0.05;
            let lead = path.lead_in.as_ref().map_or(0, |m| m.poses.len());
            let seen = poses[lead..lead + path.poses.len()]
                .iter()
                .step_by(8)
                .map(|pose| cloud.distance(&meridian, pose, near + 1.0).0)
                .fold(0.0, f64::max);
            assert!(
                seen <= near,
                "{name}: path {}: at a cutting point the sweep saw no surface within {near} mm of the head ({seen})",
                path.id
            );
        }
        for i in 0..poses.len() {
            if inside(i) {
                continue;
            }
            let steps = if i + 1 < poses.len() && !inside(i + 1) {
                between(&poses[i], &poses[i + 1], reach)
            } else {
                vec![poses[i]]
            };
            for pose in &steps {
                swept.positions += 1;
                let (d, near) = cloud.distance(&meridian, pose, bound);
                assert!(
                    d >= bound - 1e-9,
                    "{name}: path {} pose {i} (at {:?}): the sweep finds the head {d:.4} mm from \
                     surface {:?}, closer than the {bound:.4} mm kerf proved",
                    path.id,
                    pose.0,
                    near.map(|j| &file.surfaces[j].id)
                );
            }
        }
        // Every close stretch is close in the sweep too: within the clearance, less the
        // samples' spacing and half a step of the sweep.
        for c in &entry.close {
            let [a, b] = c.poses;
            // kerf's witness stands at one of its samples, at most half a step of head motion
            // from a sweep position.
            let within = c.distance_mm.max(0.0) + slack + STEP_MM / 2.0 + 1e-9;
            let mut least = f64::INFINITY;
            'stretch: for i in a..=b.min(poses.len() - 1) {
                let steps = if i < b && i + 1 < poses.len() {
                    between(&poses[i], &poses[i + 1], reach)
                } else {
                    vec![poses[i]]
                };
                for pose in &steps {
                    swept.positions += 1;
                    least = least.min(cloud.distance(&meridian, pose, within + 1.0).0);
                    if least <= within {
                        break 'stretch;
                    }
                }
            }
            assert!(
                least <= within,
                "{name}: path {} poses {a}..{b}: kerf found the head {:.4} mm from {:?}, the \
                 sweep no nearer than {least:.4} mm",
                path.id,
                c.distance_mm,
                c.surface
            );
            swept.close += 1;
        }
        swept.paths += 1;
    }
    swept.seconds = [ran, start.elapsed().as_secs_f64() - ran];
    Some(swept)
}

/// The shipped machines.
fn machines() -> Vec<(String, Machine)> {
    let mut names: Vec<_> = std::fs::read_dir(fixture("machines"))
        .expect("machines")
        .map(|e| e.expect("entry").path())
        .filter(|p| p.extension().is_some_and(|x| x == "json"))
        .collect();
    names.sort();
    names
        .iter()
        .map(|p| {
            (
                p.file_stem().expect("name").to_string_lossy().into_owned(),
                Machine::read(p).expect("machine"),
            )
        })
        .collect()
}

/// Sweeps `file` (a curves file or a CAD file read by its edges) on every shipped machine with
/// `options`; returns the runs made and how many positions, paths and close stretches.
fn sweep_everywhere(file: &str, options: JobOptions) -> Vec<(String, Swept)> {
    let path = fixture(file);
    let machines = machines();
    // Two threads (the machine's two cores), each with its own samples of the part.
    let half = machines.len().div_ceil(2);
    std::thread::scope(|scope| {
        let handles: Vec<_> = machines
            .chunks(half)
            .map(|chunk| {
                let (path, options) = (&path, &options);
                scope.spawn(move || {
                    let mut clouds = HashMap::new();
                    let mut made = Vec::new();
                    for (name, machine) in chunk {
                        let job = if file.ends_with(".json") {
                            let curves = kerf_format::curves::load(path).expect("curves");
                            Job::new(curves, machine.clone())
                        } else {
                            let opts = kerf_step::ImportOptions::default().with_edges(None);
                            Job::from_cad(path, machine.clone(), &opts)
                                .expect("import")
                                .0
                        };
                        let label = format!("{file} on {name}");
                        if let Some(s) = sweep(&label, job, options.clone(), &mut clouds) {
                            made.push((label, s));
                        }
                    }
                    made
                })
            })
            .collect();
        handles
            .into_iter()
            .flat_map(|h| h.join().expect("a sweep thread"))
            .collect()
    })
}

/// The curves files among the fixtures, by name.
fn curve_fixtures() -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(fixture(""))
        .expect("fixtures")
        .map(|e| e.expect("entry").path())
        .filter(|p| p.extension().is_some_and(|x| x == "json"))
        .map(|p| p.file_name().expect("name").to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

/// Prints what the sweep did and checks that it did something: exactly `made` runs (the runs
/// every machine can make, counted on 2026-12-05: a run left out for another reason fails it).
fn summarise(what: &str, runs: &[(String, Swept)], made: usize) {
    for (label, s) in runs {
        eprintln!(
            "{label}: {} paths, {} positions, {} close stretches confirmed ({:.2} s run, {:.2} s sweep)",
            s.paths, s.positions, s.close, s.seconds[0], s.seconds[1]
        );
    }
    assert_eq!(runs.len(), made, "{what}: runs made");
    assert!(
        runs.iter()
            .all(|(_, s)| s.paths > 0 && (s.bare || s.positions > 0)),
        "{what}: a run with nothing swept"
    );
}

/// Every curves fixture as modelled on every shipped machine, and the head fixtures again with
/// a 10-degree tilt tolerance (the avoidance's tilted poses swept too).
#[test]
fn every_fixture_on_every_machine_keeps_what_the_check_proves() {
    let mut runs = Vec::new();
    for name in curve_fixtures() {
        runs.extend(sweep_everywhere(&name, JobOptions::default()));
        if name.starts_with("head_") {
            let tilt = JobOptions::default()
                .with_path(PathOptions::default().with_tilt_tolerance_deg(10.0));
            runs.extend(
                sweep_everywhere(&name, tilt)
                    .into_iter()
                    .map(|(l, s)| (format!("{l}, tilt 10 deg"), s)),
            );
        }
    }
    summarise("fixtures", &runs, 110);
    // Close stretches only where the head meets the part as drawn: `head_bend` and
    // `head_channel` upright (and `head_channel` tilted on `head_table`, whose tilt cannot
    // clear it; `head_wall` is clear at 1 mm), the slot that
    // nothing clears, `mixed`'s curves under its tilted plane, the trim line's flange; every
    // other fixture runs clear on every machine that reaches it.
    let close: std::collections::BTreeSet<&str> = runs
        .iter()
        .filter(|(_, s)| s.close > 0)
        .map(|(l, _)| l.split(" on ").next().unwrap_or(l))
        .collect();
    assert_eq!(
        close.into_iter().collect::<Vec<_>>(),
        [
            "head_bend.json",
            "head_channel.json",
            "head_slot.json",
            "mixed.json",
            "trim_creases.json"
        ],
        "the fixtures with close stretches"
    );
    assert!(
        runs.iter()
            .filter(|(l, _)| l.contains("tilt") && !l.starts_with("head_slot"))
            .all(|(l, s)| s.close == 0 || l.starts_with("head_channel.json on head_table")),
        "a tilted head fixture left close"
    );
}

/// The real files (`fixtures/realdata`: the sheet-metal bend edges, the propeller's edges, the
/// two sheet-metal STEP parts by their edges) placed automatically on every shipped machine.
#[test]
fn every_real_file_on_every_machine_keeps_what_the_check_proves() {
    let auto = JobOptions::default().with_place(PlaceMode::Auto);
    let mut runs = Vec::new();
    for name in [
        "realdata/nori_sheetmetal.json",
        "realdata/occt_propeller.json",
        "realdata/step/S06298.stp",
        "realdata/step/S01094.stp",
    ] {
        runs.extend(sweep_everywhere(name, auto.clone()));
    }
    summarise("real files", &runs, 28);
    // Each real file meets the head somewhere on every machine: the default check refuses
    // them (bend and blade edges; the sheet parts' outlines over tight inner bends).
    assert!(
        runs.iter().all(|(_, s)| s.close > 0),
        "a real file ran clear: the docs say the default refuses every one"
    );
}
