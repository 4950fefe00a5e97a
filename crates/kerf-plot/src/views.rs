//! The four views of the geometry (top, front, side, isometric) and their legend.

use nalgebra::{Point3, Vector3};

use crate::layout::Rect;
use crate::scale::{error_colour, gradient_stops, tick_label, ticks, ABOVE_TOLERANCE};
use crate::scene::Scene;
use crate::svg::{num, text_width, Doc};

/// Most tool axes drawn per view, spread over the paths in proportion to their points (at
/// least the two ends of each path); more would hide the geometry.
const MAX_NORMALS: usize = 400;

/// The colour of the tool axes.
const NORMAL_COLOUR: &str = "#1f6fb4";

/// A projection of the workpiece frame onto a view.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum View {
    /// Seen from +z: x right, y up.
    Top,
    /// Seen from -y: x right, z up.
    Front,
    /// Seen from +x: y right, z up.
    Side,
    /// Seen from (1, -1, 1): x toward the lower right, y toward the upper right, z up.
    Iso,
}

impl View {
    /// The group id in the SVG.
    pub(crate) fn id(self) -> &'static str {
        match self {
            View::Top => "view-top",
            View::Front => "view-front",
            View::Side => "view-side",
            View::Iso => "view-iso",
        }
    }

    fn title(self) -> &'static str {
        match self {
            View::Top => "Top view (XY, seen from +Z)",
            View::Front => "Front view (XZ, seen from \u{2212}Y)",
            View::Side => "Side view (YZ, seen from +X)",
            View::Iso => "Isometric view (seen from +X, \u{2212}Y, +Z)",
        }
    }

    fn axis_names(self) -> (&'static str, &'static str) {
        match self {
            View::Top => ("x / mm", "y / mm"),
            View::Front => ("x / mm", "z / mm"),
            View::Side => ("y / mm", "z / mm"),
            View::Iso => ("", ""),
        }
    }

    /// Screen coordinates `(u, v)` in mm, v up.
    fn project(self, p: &Point3<f64>) -> (f64, f64) {
        self.project_vec(&p.coords)
    }

    fn project_vec(self, p: &Vector3<f64>) -> (f64, f64) {
        match self {
            View::Top => (p.x, p.y),
            View::Front => (p.x, p.z),
            View::Side => (p.y, p.z),
            View::Iso => (
                (p.x + p.y) * std::f64::consts::FRAC_1_SQRT_2,
                (-p.x + p.y + 2.0 * p.z) / 6f64.sqrt(),
            ),
        }
    }
}

/// World `(u, v)` to pixels, same scale on both axes.
#[derive(Debug, Clone, Copy)]
struct Fit {
    frame: Rect,
    scale: f64,
    u0: f64,
    v0: f64,
}

impl Fit {
    /// The fit of the world box `[umin, umax] x [vmin, vmax]` into `frame`, centred, with 4 %
    /// margin; a flat box gets the other axis' extent for scale.
    fn new(frame: Rect, (umin, umax, vmin, vmax): (f64, f64, f64, f64)) -> Fit {
        let (mut su, mut sv) = (umax - umin, vmax - vmin);
        if !(su.is_finite() && sv.is_finite()) {
            return Fit {
                frame,
                scale: 1.0,
                u0: 0.0,
                v0: 0.0,
            };
        }
        let floor = (su.max(sv) * 1e-3).max(1e-9);
        su = su.max(floor);
        sv = sv.max(floor);
        let scale = (frame.w / (su * 1.08)).min(frame.h / (sv * 1.08));
        let (uc, vc) = ((umin + umax) / 2.0, (vmin + vmax) / 2.0);
        Fit {
            frame,
            scale,
            u0: uc - frame.w / (2.0 * scale),
            v0: vc - frame.h / (2.0 * scale),
        }
    }

    fn px(&self, (u, v): (f64, f64)) -> (f64, f64) {
        (
            self.frame.x + (u - self.u0) * self.scale,
            self.frame.y + self.frame.h - (v - self.v0) * self.scale,
        )
    }

    fn u_range(&self) -> (f64, f64) {
        (self.u0, self.u0 + self.frame.w / self.scale)
    }

    fn v_range(&self) -> (f64, f64) {
        (self.v0, self.v0 + self.frame.h / self.scale)
    }
}

/// The length of the drawn tool axes, in mm: 5 % of the largest extent of the geometry.
pub(crate) fn normal_length(scene: &Scene) -> f64 {
    let mut lo = Vector3::repeat(f64::INFINITY);
    let mut hi = Vector3::repeat(f64::NEG_INFINITY);
    for p in scene
        .paths
        .iter()
        .flat_map(|p| p.curve.iter().chain(&p.points))
    {
        lo = lo.inf(&p.coords);
        hi = hi.sup(&p.coords);
    }
    let extent = (hi - lo).max();
    if extent.is_finite() && extent > 0.0 {
        0.05 * extent
    } else {
        1.0
    }
}

/// Indices of the points of a path of `n` points (of `total` in the scene) whose tool axes are
/// drawn: evenly spread, both ends included.
pub(crate) fn normal_indices(n: usize, total: usize) -> Vec<usize> {
    if n == 0 {
        return Vec::new();
    }
    let share = (MAX_NORMALS as f64 * n as f64 / total.max(1) as f64).round() as usize;
    let k = share.clamp(2, n.max(2)).min(n);
    if k >= n {
        return (0..n).collect();
    }
    let mut out: Vec<usize> = (0..k)
        .map(|i| ((i as f64) * (n - 1) as f64 / (k - 1) as f64).round() as usize)
        .collect();
    out.dedup();
    out
}

/// Draws one view of the scene in `panel`.
pub(crate) fn draw_view(doc: &mut Doc, scene: &Scene, view: View, panel: Rect, normal_len: f64) {
    doc.open(&format!("id=\"{}\" class=\"view\"", view.id()));
    doc.rect(panel.x, panel.y, panel.w, panel.h, "class=\"panel\"");
    doc.text(panel.x + 14.0, panel.y + 24.0, view.title(), "class=\"h2\"");
    let frame = if view == View::Iso {
        panel.inset(16.0, 36.0, 16.0, 16.0)
    } else {
        panel.inset(66.0, 36.0, 16.0, 50.0)
    };
    // Bounds of everything drawn.
    let mut b = (
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
    );
    let mut grow = |(u, v): (f64, f64)| {
        if u.is_finite() && v.is_finite() {
            b = (b.0.min(u), b.1.max(u), b.2.min(v), b.3.max(v));
        }
    };
    for p in &scene.paths {
        p.curve
            .iter()
            .chain(&p.points)
            .for_each(|q| grow(view.project(q)));
        if let Some(normals) = &p.normals {
            for (q, n) in p.points.iter().zip(normals) {
                grow(view.project(&(q + n * normal_len)));
            }
        }
    }
    if let Some(process) = &scene.process {
        for c in &process.cuts {
            grow(view.project(&c.pierce));
            c.lead_in
                .iter()
                .chain(&c.lead_out)
                .for_each(|q| grow(view.project(q)));
        }
        process
            .traverses
            .iter()
            .flatten()
            .for_each(|q| grow(view.project(q)));
    }
    if !b.0.is_finite() {
        doc.empty_panel(frame, "no paths");
        return;
    }
    let fit = Fit::new(frame, b);
    if view != View::Iso {
        draw_grid(doc, &fit, view);
    }
    doc.rect(frame.x, frame.y, frame.w, frame.h, "class=\"frame\"");
    let clip = format!("clip-{}", view.id());
    doc.raw(&format!(
        "<clipPath id=\"{clip}\"><rect x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\"/></clipPath>\n",
        num(frame.x),
        num(frame.y),
        num(frame.w),
        num(frame.h)
    ));
    doc.open(&format!("clip-path=\"url(#{clip})\""));
    // Segments coloured by chord error, consecutive segments of one colour in one polyline.
    doc.open("class=\"chords\"");
    for p in &scene.paths {
        let mut run: Vec<(f64, f64)> = Vec::new();
        let mut colour = String::new();
        for (s, e) in p.segment_errors.iter().enumerate() {
            let c = error_colour(e / scene.tolerance);
            if c != colour && !run.is_empty() {
                doc.polyline(&run, &chord_style(&colour));
                run.clear();
            }
            if run.is_empty() {
                run.push(fit.px(view.project(&p.points[s])));
            }
            colour = c;
            run.push(fit.px(view.project(&p.points[s + 1])));
        }
        doc.polyline(&run, &chord_style(&colour));
    }
    doc.close();
    doc.open("class=\"curves\"");
    for p in &scene.paths {
        let pts: Vec<_> = p.curve.iter().map(|q| fit.px(view.project(q))).collect();
        doc.polyline(&pts, "");
    }
    doc.close();
    let total: usize = scene.paths.iter().map(|p| p.points.len()).sum();
    doc.open("class=\"normals\"");
    for p in &scene.paths {
        if let Some(normals) = &p.normals {
            for i in normal_indices(p.points.len().min(normals.len()), total) {
                let (x1, y1) = fit.px(view.project(&p.points[i]));
                let (x2, y2) = fit.px(view.project(&(p.points[i] + normals[i] * normal_len)));
                doc.line(x1, y1, x2, y2, "");
            }
        }
    }
    doc.close();
    let r = if total > 3000 { 1.2 } else { 1.9 };
    doc.open("class=\"points\"");
    for p in &scene.paths {
        for q in &p.points {
            let (x, y) = fit.px(view.project(q));
            doc.circle(x, y, r, "class=\"pt\"");
        }
    }
    doc.close();
    if let Some(process) = &scene.process {
        draw_process(doc, process, view, &fit);
    }
    if view == View::Top && scene.paths.len() <= 12 {
        doc.open("class=\"labels\"");
        // Beside each path's first point, moved down a line at a time while it would cover
        // a label already placed (paths often start side by side).
        let mut placed: Vec<(f64, f64, f64)> = Vec::new();
        for p in &scene.paths {
            if let Some(q) = p.points.first() {
                let (x, mut y) = fit.px(view.project(q));
                let (x, w) = (x + 5.0, text_width(&p.id, 11.0));
                y -= 5.0;
                for _ in 0..12 {
                    let clash = placed
                        .iter()
                        .any(|&(px, py, pw)| (py - y).abs() < 13.0 && x < px + pw && px < x + w);
                    if !clash {
                        break;
                    }
                    y += 13.0;
                }
                placed.push((x, y, w));
                doc.text(x, y, &p.id, "class=\"label\"");
            }
        }
        doc.close();
    }
    doc.close();
    if view == View::Iso {
        draw_triad(doc, frame);
        draw_scale_bar(doc, &fit);
    }
    doc.close();
}

/// The attributes of a run of segments of one colour; above the tolerance also thicker, so
/// that a short bad segment shows.
fn chord_style(colour: &str) -> String {
    if colour == ABOVE_TOLERANCE {
        format!("stroke=\"{colour}\" class=\"over\"")
    } else {
        format!("stroke=\"{colour}\"")
    }
}

/// Grid lines, tick labels and axis names of an orthographic view.
fn draw_grid(doc: &mut Doc, fit: &Fit, view: View) {
    let f = fit.frame;
    let (un, vn) = view.axis_names();
    let (u0, u1) = fit.u_range();
    let (v0, v1) = fit.v_range();
    let (tu, su) = ticks(u0, u1, (f.w / 90.0).round().max(2.0) as usize);
    let (tv, sv) = ticks(v0, v1, (f.h / 60.0).round().max(2.0) as usize);
    doc.open("class=\"grid\"");
    for &u in &tu {
        let (x, _) = fit.px((u, v0));
        doc.line(x, f.y, x, f.y + f.h, "");
    }
    for &v in &tv {
        let (_, y) = fit.px((u0, v));
        doc.line(f.x, y, f.x + f.w, y, "");
    }
    doc.close();
    doc.open("class=\"ticks\"");
    for &u in &tu {
        let (x, _) = fit.px((u, v0));
        doc.text(
            x,
            f.y + f.h + 15.0,
            &tick_label(u, su),
            "text-anchor=\"middle\"",
        );
    }
    for &v in &tv {
        let (_, y) = fit.px((u0, v));
        doc.text(
            f.x - 6.0,
            y + 4.0,
            &tick_label(v, sv),
            "text-anchor=\"end\"",
        );
    }
    doc.close();
    doc.text(
        f.x + f.w / 2.0,
        f.y + f.h + 36.0,
        un,
        "class=\"axis\" text-anchor=\"middle\"",
    );
    doc.vtext(f.x - 50.0, f.y + f.h / 2.0, vn, "class=\"axis\"");
}

/// The x, y, z directions of the isometric view, in its lower right corner.
fn draw_triad(doc: &mut Doc, frame: Rect) {
    let (cx, cy) = (frame.x + frame.w - 60.0, frame.y + frame.h - 40.0);
    doc.open("class=\"triad\"");
    for (name, dir, colour) in [
        ("x", Vector3::x(), "#d62728"),
        ("y", Vector3::y(), "#2ca02c"),
        ("z", Vector3::z(), "#1f6fb4"),
    ] {
        let (u, v) = View::Iso.project_vec(&dir);
        let (x, y) = (cx + 28.0 * u, cy - 28.0 * v);
        doc.line(
            cx,
            cy,
            x,
            y,
            &format!("stroke=\"{colour}\" stroke-width=\"2\""),
        );
        doc.text(
            cx + 38.0 * u,
            cy - 38.0 * v + 4.0,
            name,
            &format!("style=\"fill:{colour}\" text-anchor=\"middle\" font-weight=\"bold\""),
        );
    }
    doc.close();
}

/// A round-length scale bar in the lower left corner of a view.
fn draw_scale_bar(doc: &mut Doc, fit: &Fit) {
    let f = fit.frame;
    let target = f.w / 5.0 / fit.scale;
    let mag = 10f64.powf(target.log10().floor());
    let len = [5.0, 2.0, 1.0]
        .iter()
        .map(|k| k * mag)
        .find(|&l| l <= target)
        .unwrap_or(mag);
    let px = len * fit.scale;
    let (x, y) = (f.x + 16.0, f.y + f.h - 16.0);
    doc.open("class=\"scalebar\"");
    doc.line(x, y, x + px, y, "stroke=\"#222\" stroke-width=\"2\"");
    doc.line(x, y - 5.0, x, y + 5.0, "stroke=\"#222\"");
    doc.line(x + px, y - 5.0, x + px, y + 5.0, "stroke=\"#222\"");
    doc.text(
        x + px / 2.0,
        y - 8.0,
        &format!("{} mm", tick_label(len, len)),
        "text-anchor=\"middle\"",
    );
    doc.close();
}

/// The legend of the views: the colour scale of the chord error and the symbols.
pub(crate) fn draw_legend(doc: &mut Doc, scene: &Scene, area: Rect) {
    doc.open("id=\"legend-error\" class=\"legend\"");
    doc.raw(&format!(
        "<defs><linearGradient id=\"error-scale\">{}</linearGradient></defs>\n",
        gradient_stops()
    ));
    let y = area.y + 22.0;
    doc.text(
        area.x,
        y + 10.0,
        "chord error / tolerance",
        "class=\"axis\"",
    );
    let bx = area.x + 170.0;
    let bw = 260.0;
    doc.rect(
        bx,
        y,
        bw,
        12.0,
        "fill=\"url(#error-scale)\" stroke=\"#555\" stroke-width=\"0.5\"",
    );
    for k in 0..=4 {
        let f = f64::from(k) / 4.0;
        let x = bx + f * bw;
        doc.line(x, y + 12.0, x, y + 17.0, "stroke=\"#555\"");
        doc.text(x, y + 30.0, &tick_label(f, 0.25), "text-anchor=\"middle\"");
    }
    let rx = bx + bw + 16.0;
    doc.rect(rx, y, 24.0, 12.0, &format!("fill=\"{ABOVE_TOLERANCE}\""));
    doc.text(rx + 30.0, y + 10.0, "> 1: above the tolerance", "");
    // Symbols.
    let mut x = rx + 30.0 + text_width("> 1: above the tolerance", 12.0) + 36.0;
    let sy = y + 6.0;
    doc.line(
        x,
        sy,
        x + 26.0,
        sy,
        &format!("stroke=\"{}\" stroke-width=\"2.6\"", error_colour(0.95)),
    );
    doc.text(x + 32.0, sy + 4.0, "segment (chord)", "");
    x += 32.0 + text_width("segment (chord)", 12.0) + 24.0;
    doc.line(x, sy, x + 26.0, sy, "stroke=\"#333\" stroke-width=\"0.8\"");
    doc.text(x + 32.0, sy + 4.0, "curve (sampled)", "");
    x += 32.0 + text_width("curve (sampled)", 12.0) + 24.0;
    doc.circle(x + 6.0, sy, 3.0, "fill=\"#fff\" stroke=\"#111\"");
    doc.text(x + 16.0, sy + 4.0, "cutting point", "");
    x += 16.0 + text_width("cutting point", 12.0) + 24.0;
    if scene.paths.iter().any(|p| p.normals.is_some()) {
        doc.line(
            x,
            sy,
            x + 26.0,
            sy,
            &format!("stroke=\"{NORMAL_COLOUR}\" stroke-width=\"1.2\""),
        );
        doc.text(x + 32.0, sy + 4.0, "tool axis (toward the head)", "");
    }
    let mut note = "Chord error of a segment: largest distance from the curve to its chord, \
                    estimated by sampling (kerf check measures it). Views to scale."
        .to_owned();
    if scene.paths.iter().any(|p| p.normals.is_some()) {
        note.push_str(&format!(
            " At most {MAX_NORMALS} tool axes drawn per view, spread over the paths."
        ));
    }
    doc.text(area.x, y + 52.0, &note, "class=\"note\"");
    doc.close();
}

/// The stylesheet used by the views.
/// The process over a view: traverses dashed, lead-ins and lead-outs, then the pierces with
/// their numbers in cutting order on top.
fn draw_process(doc: &mut Doc, process: &crate::ProcessPicture, view: View, fit: &Fit) {
    let line = |pts: &[Point3<f64>]| -> Vec<(f64, f64)> {
        pts.iter().map(|q| fit.px(view.project(q))).collect()
    };
    doc.open("class=\"process\"");
    for t in &process.traverses {
        if t.len() >= 2 {
            doc.polyline(&line(t), "class=\"traverse\"");
        }
    }
    // Under the leads (over the path, translucent): the stretches the head check tilted, and
    // those where it found the head too close, as wide bands along the path.
    for c in &process.cuts {
        for t in c.head_tilted.iter().filter(|t| t.len() >= 2) {
            doc.polyline(&line(t), "class=\"head-tilted\"");
        }
        for t in c.head_close.iter().filter(|t| t.len() >= 2) {
            doc.polyline(&line(t), "class=\"head-close\"");
        }
    }
    for c in &process.cuts {
        if c.lead_in.len() >= 2 {
            doc.polyline(&line(&c.lead_in), "class=\"lead-in\"");
        }
        if c.lead_out.len() >= 2 {
            doc.polyline(&line(&c.lead_out), "class=\"lead-out\"");
        }
        // A joint is a fraction of a millimetre: drawn as a bar across the path's line width.
        for j in &c.micro_joints {
            doc.polyline(&line(j), "class=\"micro-joint\"");
        }
    }
    for (k, c) in process.cuts.iter().enumerate() {
        let (x, y) = fit.px(view.project(&c.pierce));
        if !(x.is_finite() && y.is_finite()) {
            continue;
        }
        let order = k + 1;
        doc.circle(
            x,
            y,
            3.2,
            &format!("class=\"pierce\" data-order=\"{order}\""),
        );
        doc.text(x + 4.5, y - 4.5, &order.to_string(), "class=\"order\"");
    }
    doc.close();
}

pub(crate) const STYLE: &str = concat!(
    ".panel{fill:#fcfcfc;stroke:#d0d0d0}",
    ".frame{fill:none;stroke:#888;stroke-width:0.8}",
    ".grid line{stroke:#e6e6e6;stroke-width:0.8}",
    ".chords polyline{stroke-width:2.6;stroke-linecap:round;stroke-linejoin:round}",
    ".chords .over{stroke-width:5}",
    ".curves polyline{stroke:#333;stroke-width:0.7}",
    ".normals line{stroke:#1f6fb4;stroke-width:1;stroke-opacity:0.7}",
    ".pt{fill:#fff;stroke:#111;stroke-width:0.8}",
    ".label{font-size:11px;fill:#222;stroke:#fff;stroke-width:3px;paint-order:stroke}",
    ".traverse{stroke:#777;stroke-width:0.9;stroke-dasharray:5 4}",
    ".lead-in{stroke:#e07b00;stroke-width:1.8}",
    ".lead-out{stroke:#8e44ad;stroke-width:1.4;stroke-dasharray:2 2}",
    ".pierce{fill:#d62728;stroke:#fff;stroke-width:0.8}",
    ".micro-joint{stroke:#0a8f3c;stroke-width:6;stroke-linecap:round}",
    ".head-tilted{stroke:#f2b134;stroke-width:9;stroke-opacity:0.55;stroke-linecap:round;stroke-linejoin:round}",
    ".head-close{stroke:#d62728;stroke-width:11;stroke-opacity:0.45;stroke-linecap:round;stroke-linejoin:round}",
    ".order{font-size:10px;font-weight:bold;fill:#d62728;stroke:#fff;stroke-width:2.5px;paint-order:stroke}",
);
