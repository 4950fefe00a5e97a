//! The 3D view's scene ([`kerf_view::Scene`]) from a run: the part's surfaces tessellated in
//! each set-up's workpiece frame, the cuts and traverses from the planned blocks, the pierce
//! points, and the planned motion sampled from the set-points the controller gets.

use kerf_format::{CurvesFile, SurfaceGeometry};
use kerf_interp::{AxisModel, MachineModel, Motion};
use kerf_kinematics::{Head, Placement};
use kerf_view::{Cut, Scene, Setup, SurfaceMesh, Timeline, SAMPLE_LEN};
use nalgebra::Point3;

use crate::cuts::CutPath;

/// Beam directions drawn per cut at most.
const BEAMS_PER_CUT: usize = 48;

/// Points per traverse block (the tip's curve under joint-space interpolation).
const TRAVERSE_SAMPLES: usize = 16;

/// What a set-up's view needs besides the file.
pub(crate) struct SetupInput<'a> {
    pub(crate) placement: Placement,
    pub(crate) motion: &'a Motion,
    pub(crate) ids: &'a [String],
    pub(crate) program: &'a str,
}

/// The scene of a run: `cuts` (every path's lead-in, contour and lead-out, in part
/// coordinates) give the lead lengths; the warnings are set when the page is written.
#[allow(clippy::too_many_arguments)]
pub(crate) fn scene(
    title: &str,
    file: &CurvesFile,
    cuts: &[CutPath],
    setups: &[SetupInput<'_>],
    model: &MachineModel,
    head: &Head,
    head_standoff_mm: f64,
    feed_mm_per_min: f64,
    pierce_standoff_mm: f64,
) -> Scene {
    let mut s = Scene::default();
    s.title = title.to_string();
    s.machine = model.name().to_string();
    s.feed_mm_per_min = feed_mm_per_min;
    s.axis_names = model.axis_names().iter().map(|n| n.to_string()).collect();
    s.head_standoff_mm = head_standoff_mm;
    s.head = head
        .solids
        .iter()
        .map(|h| [h.length_mm, h.bottom_diameter_mm, h.top_diameter_mm])
        .collect();
    // The lead lengths of each path, by id.
    let leads = |id: &str| -> (f64, f64) {
        cuts.iter()
            .find(|c| file.curves[c.curve].id == id)
            .map_or((0.0, 0.0), |c| {
                let [m, n, _] = c.counts;
                let len = |a: usize, b: usize| -> f64 {
                    crate::cuts::polyline_length(&c.poses[a..b.min(c.poses.len())])
                };
                let lead_in = if m > 0 { len(0, m + 1) } else { 0.0 };
                let lead_out = if m + n < c.poses.len() {
                    len(m + n - 1, c.poses.len())
                } else {
                    0.0
                };
                (lead_in, lead_out)
            })
    };
    let grid = grid_size(file);
    s.setups = setups
        .iter()
        .map(|su| {
            let mut out = Setup::default();
            out.program = su.program.to_string();
            out.surfaces = file
                .surfaces
                .iter()
                .map(|r| tessellate(&r.id, &r.geometry, grid, &su.placement))
                .collect();
            let (cuts, traverses) = paths(su, model, &leads, pierce_standoff_mm);
            out.cuts = cuts;
            out.traverses = traverses;
            out.timeline = timeline(su.motion, model, feed_mm_per_min);
            out
        })
        .collect();
    s
}

/// The grid of a NURBS surface's tessellation per direction, at most: every surface at 24,
/// fewer when the file has so many that the triangles would pass [`kerf_view::MAX_TRIANGLES`].
fn grid_size(file: &CurvesFile) -> usize {
    let n = file.surfaces.len().max(1);
    let per = kerf_view::MAX_TRIANGLES / n / 2;
    ((per as f64).sqrt() as usize).clamp(2, 24)
}

/// A surface as triangles in the set-up's frame: a NURBS surface on a grid of `(u, v)` (two
/// points per direction for a flat bilinear patch, more for curved ones, at most `grid`); a
/// mesh as it is.
fn tessellate(id: &str, g: &SurfaceGeometry, grid: usize, placement: &Placement) -> SurfaceMesh {
    let mut m = SurfaceMesh::default();
    m.id = id.to_string();
    let mut push = |p: Point3<f64>| {
        let q = placement.apply_point(&p);
        m.positions.extend([mm(q.x), mm(q.y), mm(q.z)]);
    };
    match g {
        SurfaceGeometry::Nurbs(n) => {
            let (u0, u1) = n.domain_u();
            let (v0, v1) = n.domain_v();
            let spans = |knots: &[f64], degree: usize| {
                let distinct = knots.windows(2).filter(|w| w[1] > w[0]).count();
                if degree <= 1 {
                    distinct + 1
                } else {
                    distinct * 4 + 1
                }
            };
            let nu = spans(n.knots_u(), n.degree_u()).clamp(2, grid);
            let nv = spans(n.knots_v(), n.degree_v()).clamp(2, grid);
            for i in 0..nu {
                let u = u0 + (u1 - u0) * i as f64 / (nu - 1) as f64;
                for j in 0..nv {
                    let v = v0 + (v1 - v0) * j as f64 / (nv - 1) as f64;
                    push(n.point(u, v));
                }
            }
            let at = |i: usize, j: usize| (i * nv + j) as u32;
            for i in 0..nu - 1 {
                for j in 0..nv - 1 {
                    m.indices.extend([at(i, j), at(i + 1, j), at(i + 1, j + 1)]);
                    m.indices.extend([at(i, j), at(i + 1, j + 1), at(i, j + 1)]);
                }
            }
        }
        SurfaceGeometry::Mesh {
            vertices,
            triangles,
        } => {
            for v in vertices {
                push(*v);
            }
            m.indices = triangles.iter().flatten().copied().collect();
        }
    }
    m
}

/// The cuts (maximal runs of cutting blocks of one path, [`kerf_interp::starts_cut`]) and the
/// traverses between them of a set-up's planned blocks.
fn paths(
    su: &SetupInput<'_>,
    model: &MachineModel,
    leads: &dyn Fn(&str) -> (f64, f64),
    standoff: f64,
) -> (Vec<Cut>, Vec<Vec<f32>>) {
    let blocks = su.motion.blocks();
    let mut cuts: Vec<Cut> = Vec::new();
    let mut traverses: Vec<Vec<f32>> = Vec::new();
    let mut rapid: Vec<f32> = Vec::new();
    let mut beams: Vec<[f32; 6]> = Vec::new();
    let flat = |p: &Point3<f64>| [mm(p.x), mm(p.y), mm(p.z)];
    let mut in_cut = false;
    for (k, b) in blocks.iter().enumerate() {
        if in_cut && kerf_interp::starts_cut(blocks, k) {
            // Another path starting where the last one ended: a cut of its own.
            finish_beams(cuts.last_mut(), &mut beams);
            in_cut = false;
        }
        if b.rapid {
            if in_cut {
                finish_beams(cuts.last_mut(), &mut beams);
                in_cut = false;
            }
            for j in 0..=TRAVERSE_SAMPLES {
                let f = j as f64 / TRAVERSE_SAMPLES as f64;
                rapid.extend(flat(&model.tip(&b.start_axes.lerp(&b.end_axes, f))));
            }
            continue;
        }
        if !in_cut {
            // A traverse is the rapid motion between two cuts.
            if !cuts.is_empty() && !rapid.is_empty() {
                traverses.push(std::mem::take(&mut rapid));
            }
            rapid.clear();
            let id = su.ids.get(b.path).map_or("", String::as_str);
            let (lead_in, lead_out) = leads(id);
            let u = model.tool_axis(b.start_axes.tilt, b.start_axes.c);
            let pierce = b.start_tip() + u * standoff;
            let mut c = Cut::default();
            c.id = id.to_string();
            c.pierce = flat(&pierce);
            c.lead_in_mm = lead_in as f32;
            c.lead_out_mm = lead_out as f32;
            c.points.extend(flat(&b.start_tip()));
            cuts.push(c);
            in_cut = true;
        }
        let c = cuts.last_mut().expect("a cut was started");
        // Arcs in a few chords each; lines and turns by their end.
        let n = if b.mid_length() < b.length() { 8 } else { 1 };
        for j in 1..=n {
            let (tip, tilt, cc) = b.pose_at(b.length() * j as f64 / n as f64);
            c.points.extend(flat(&tip));
            beams.push(pose_numbers(&tip, &model.tool_axis(tilt, cc)));
        }
    }
    if in_cut {
        finish_beams(cuts.last_mut(), &mut beams);
    }
    (cuts, traverses)
}

/// At most [`BEAMS_PER_CUT`] of a cut's beam directions, evenly spread, into `cut`.
fn finish_beams(cut: Option<&mut Cut>, beams: &mut Vec<[f32; 6]>) {
    if let Some(c) = cut {
        let step = beams.len().div_ceil(BEAMS_PER_CUT).max(1);
        for b in beams.iter().step_by(step) {
            c.beams.extend(b);
        }
    }
    beams.clear();
}

/// The planned motion sampled every few cycles (at most [`kerf_view::MAX_TIMELINE_SAMPLES`]
/// samples): each sample the tip and tool axis at that cycle's set-point, the speed over the
/// cycle before it as a share of the feed, whether the block is a traverse, and the set-point's
/// machine axes.
fn timeline(motion: &Motion, model: &MachineModel, feed_mm_per_min: f64) -> Timeline {
    let cycles = motion.cycles();
    let stride = (cycles + 1)
        .div_ceil(kerf_view::MAX_TIMELINE_SAMPLES)
        .max(1);
    let cycle = motion.cycle();
    let feed = (feed_mm_per_min / 60.0).max(1e-9);
    let mut t = Timeline::default();
    t.duration_s = motion.duration();
    t.step_s = stride as f64 * cycle;
    t.cycle_s = cycle;
    let mut prev: Option<Point3<f64>> = None;
    t.samples.reserve((cycles / stride + 2) * SAMPLE_LEN);
    for (i, q) in motion.iter(model).enumerate() {
        // The tip only where a sample needs it: at the sample and the cycle before (its speed).
        let sample = i % stride == 0;
        if !sample && (i + 1) % stride != 0 {
            continue;
        }
        let tip = model.tip(&q);
        if sample {
            let speed = prev.map_or(0.0, |p| (tip - p).norm() / cycle);
            let (block, _) = motion.locate(i as f64 * cycle);
            let rapid = motion.blocks().get(block).is_some_and(|b| b.rapid);
            t.samples
                .extend(pose_numbers(&tip, &model.tool_axis(q.tilt, q.c)));
            t.samples
                .extend([unit(speed / feed), if rapid { 1.0 } else { 0.0 }]);
            t.samples.extend(q.iter().map(mm));
        }
        prev = Some(tip);
    }
    t
}

/// A tip and a unit direction as the view holds them: `x, y, z, i, j, k`.
fn pose_numbers(tip: &Point3<f64>, u: &nalgebra::Vector3<f64>) -> [f32; 6] {
    [
        mm(tip.x),
        mm(tip.y),
        mm(tip.z),
        unit(u.x),
        unit(u.y),
        unit(u.z),
    ]
}

/// A coordinate as the view holds it: to the micrometre (the page's text stays short; the
/// view is a picture, the set-points and the program hold the numbers).
fn mm(v: f64) -> f32 {
    ((v * 1e3).round() / 1e3) as f32
}

/// A direction component or a share to four decimals.
fn unit(v: f64) -> f32 {
    ((v * 1e4).round() / 1e4) as f32
}
