//! The charts: chord error per segment against the tolerance, and machine axes over the
//! point index with their limits.

use crate::layout::Rect;
use crate::scale::{error_colour, significant, tick_label, ticks, ABOVE_TOLERANCE};
use crate::scene::{AxesChart, Scene};
use crate::svg::{num, text_width, Doc};

/// Colours of the five axes `X, Y, Z, tilt, C`.
const AXIS_COLOURS: [&str; 5] = ["#1f6fb4", "#2ca02c", "#9467bd", "#ff7f0e", "#8c564b"];

/// A linear map from data to pixels.
#[derive(Debug, Clone, Copy)]
struct Linear {
    d0: f64,
    d1: f64,
    p0: f64,
    p1: f64,
}

impl Linear {
    fn new(d0: f64, d1: f64, p0: f64, p1: f64) -> Self {
        let d1 = if d1 > d0 { d1 } else { d0 + 1.0 };
        Linear { d0, d1, p0, p1 }
    }

    fn at(&self, d: f64) -> f64 {
        self.p0 + (d - self.d0) / (self.d1 - self.d0) * (self.p1 - self.p0)
    }
}

/// Vertical separators between paths (dotted), with their ids on top where they fit.
fn path_bands(
    doc: &mut Doc,
    frame: Rect,
    x: &Linear,
    bands: &[(String, usize, usize)],
    labels: bool,
) {
    doc.open("class=\"bands\"");
    for (i, (id, start, end)) in bands.iter().enumerate() {
        let (xa, xb) = (x.at(*start as f64 - 0.5), x.at(*end as f64 - 0.5));
        if i > 0 {
            doc.line(xa, frame.y, xa, frame.y + frame.h, "class=\"sep\"");
        }
        if labels && xb - xa > text_width(id, 11.0) + 8.0 {
            doc.text(
                (xa + xb) / 2.0,
                frame.y + 14.0,
                id,
                "class=\"band halo\" text-anchor=\"middle\"",
            );
        }
    }
    doc.close();
}

/// Horizontal grid and tick labels for `y`.
fn y_axis(doc: &mut Doc, frame: Rect, y: &Linear, n: usize, grid: bool) {
    let (lo, hi) = (y.d0, y.d1);
    let (t, step) = ticks(lo, hi, n);
    for v in t {
        let py = y.at(v);
        if grid {
            doc.line(frame.x, py, frame.x + frame.w, py, "class=\"gridline\"");
        }
        doc.text(
            frame.x - 6.0,
            py + 4.0,
            &tick_label(v, step),
            "class=\"tick\" text-anchor=\"end\"",
        );
    }
}

/// Integer ticks along `x` (point or segment indices) under `frame`.
fn x_axis(doc: &mut Doc, frame: Rect, x: &Linear, count: usize, label: &str) {
    let (t, step) = ticks(
        0.0,
        count.saturating_sub(1).max(1) as f64,
        (frame.w / 100.0) as usize,
    );
    let step = step.max(1.0).round();
    for v in t {
        if v.fract() != 0.0 || v > count.saturating_sub(1) as f64 {
            continue;
        }
        let px = x.at(v);
        doc.line(
            px,
            frame.y + frame.h,
            px,
            frame.y + frame.h + 4.0,
            "stroke=\"#888\"",
        );
        doc.text(
            px,
            frame.y + frame.h + 17.0,
            &tick_label(v, step),
            "class=\"tick\" text-anchor=\"middle\"",
        );
    }
    doc.text(
        frame.x + frame.w / 2.0,
        frame.y + frame.h + 38.0,
        label,
        "class=\"axis\" text-anchor=\"middle\"",
    );
}

/// The chord error of every segment (all paths, in order) against the tolerance.
pub(crate) fn draw_chord_chart(doc: &mut Doc, scene: &Scene, panel: Rect) {
    doc.open("id=\"chart-chord-error\" class=\"chart\"");
    doc.rect(panel.x, panel.y, panel.w, panel.h, "class=\"panel\"");
    doc.text(
        panel.x + 14.0,
        panel.y + 24.0,
        "Chord error per segment (sampled estimate) against the tolerance",
        "class=\"h2\"",
    );
    // Legend, top right.
    let lx = panel.x + panel.w - 520.0;
    doc.circle(
        lx,
        panel.y + 20.0,
        3.0,
        &format!("fill=\"{}\"", error_colour(0.95)),
    );
    doc.text(
        lx + 9.0,
        panel.y + 24.0,
        "segment, coloured by error / tolerance",
        "",
    );
    let tx = lx + 9.0 + text_width("segment, coloured by error / tolerance", 12.0) + 22.0;
    doc.line(
        tx,
        panel.y + 20.0,
        tx + 28.0,
        panel.y + 20.0,
        "class=\"tol\"",
    );
    doc.text(tx + 34.0, panel.y + 24.0, "tolerance", "");
    let frame = panel.inset(84.0, 40.0, 22.0, 56.0);
    let mut bands = Vec::new();
    let mut total = 0;
    for p in &scene.paths {
        bands.push((p.id.clone(), total, total + p.segment_errors.len()));
        total += p.segment_errors.len();
    }
    if total == 0 {
        doc.empty_panel(frame, "no segments");
        return;
    }
    let worst = scene
        .paths
        .iter()
        .flat_map(|p| p.segment_errors.iter().copied())
        .filter(|e| e.is_finite())
        .fold(0.0, f64::max);
    // Up to 2.5 tolerances: a far outlier (a missing point) must not squash the band every
    // other segment sits in; it is drawn as a triangle on the top edge instead.
    let top = (worst.max(scene.tolerance) * 1.2).min(scene.tolerance * 2.5);
    let top = if top.is_finite() && top > 0.0 {
        top
    } else {
        worst.max(1e-9) * 1.2
    };
    let x = Linear::new(-0.5, total as f64 - 0.5, frame.x, frame.x + frame.w);
    let y = Linear::new(0.0, top, frame.y + frame.h, frame.y);
    doc.open("class=\"grid\"");
    y_axis(doc, frame, &y, 6, true);
    doc.close();
    doc.rect(frame.x, frame.y, frame.w, frame.h, "class=\"frame\"");
    path_bands(doc, frame, &x, &bands, true);
    let r = ((frame.w / total as f64) * 0.45).clamp(0.9, 2.4);
    doc.open("class=\"dots\"");
    let mut s = 0;
    let mut above = 0;
    for p in &scene.paths {
        for &e in &p.segment_errors {
            let c = error_colour(e / scene.tolerance);
            let px = x.at(s as f64);
            if e > top {
                above += 1;
                let py = frame.y + 1.0;
                doc.raw(&format!(
                    "<polygon class=\"off\" points=\"{},{} {},{} {},{}\" fill=\"{c}\"/>\n",
                    num(px - 5.0),
                    num(py + 8.0),
                    num(px + 5.0),
                    num(py + 8.0),
                    num(px),
                    num(py)
                ));
            } else {
                doc.circle(px, y.at(e.max(0.0)), r, &format!("fill=\"{c}\""));
            }
            s += 1;
        }
    }
    doc.close();
    if above > 0 {
        doc.text(
            frame.x + 8.0,
            frame.y + 30.0,
            &format!(
                "\u{25B2} {above} segment{} above the chart, largest {} mm",
                if above == 1 { "" } else { "s" },
                significant(worst, 4)
            ),
            &format!("style=\"fill:{ABOVE_TOLERANCE}\" class=\"halo\" font-weight=\"bold\""),
        );
    }
    let ty = y.at(scene.tolerance);
    doc.line(frame.x, ty, frame.x + frame.w, ty, "class=\"tol\"");
    doc.text(
        frame.x + frame.w - 6.0,
        ty - 6.0,
        &format!("tolerance {} mm", scene.tolerance),
        &format!("text-anchor=\"end\" style=\"fill:{ABOVE_TOLERANCE}\" class=\"halo\""),
    );
    x_axis(
        doc,
        frame,
        &x,
        total,
        "segment index (all paths, in file order; dotted lines separate paths)",
    );
    doc.vtext(
        panel.x + 20.0,
        frame.y + frame.h / 2.0,
        "chord error / mm",
        "class=\"axis\"",
    );
    doc.close();
}

/// The height of the axes chart.
pub(crate) fn axes_chart_height() -> f64 {
    46.0 + 5.0 * 118.0 + 60.0
}

/// The machine axes over the point index, one row per axis, with limits dashed.
pub(crate) fn draw_axes_chart(doc: &mut Doc, chart: &AxesChart, panel: Rect) {
    doc.open("id=\"chart-axes\" class=\"chart\"");
    doc.rect(panel.x, panel.y, panel.w, panel.h, "class=\"panel\"");
    doc.text(
        panel.x + 14.0,
        panel.y + 24.0,
        &format!(
            "Machine axes over the point index \u{2014} {}",
            chart.machine
        ),
        "class=\"h2\"",
    );
    let lx = panel.x + panel.w - 330.0;
    doc.line(
        lx,
        panel.y + 20.0,
        lx + 28.0,
        panel.y + 20.0,
        "stroke=\"#555\" stroke-width=\"1.5\"",
    );
    doc.text(lx + 34.0, panel.y + 24.0, "axis position", "");
    let tx = lx + 34.0 + text_width("axis position", 12.0) + 22.0;
    doc.line(
        tx,
        panel.y + 20.0,
        tx + 28.0,
        panel.y + 20.0,
        "class=\"limit\"",
    );
    doc.text(tx + 34.0, panel.y + 24.0, "axis limit", "");

    let mut bands = Vec::new();
    let mut total = 0;
    for (id, pos) in &chart.paths {
        bands.push((id.clone(), total, total + pos.len()));
        total += pos.len();
    }
    let inner = panel.inset(84.0, 46.0, 22.0, 60.0);
    let row_h = inner.h / 5.0;
    let x = Linear::new(
        0.0,
        total.saturating_sub(1).max(1) as f64,
        inner.x,
        inner.x + inner.w,
    );
    for axis in 0..5 {
        let frame = Rect {
            x: inner.x,
            y: inner.y + axis as f64 * row_h,
            w: inner.w,
            h: row_h - 16.0,
        };
        let unit = if axis < 3 { "mm" } else { "deg" };
        let name = &chart.names[axis];
        doc.open(&format!("class=\"axis-row\" id=\"axis-{}\"", axis_id(name)));
        let values = chart
            .paths
            .iter()
            .flat_map(|(_, p)| p.iter().map(move |q| q[axis]))
            .filter(|v| v.is_finite());
        let (mut lo, mut hi) = values.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
            (a.min(v), b.max(v))
        });
        if !lo.is_finite() {
            (lo, hi) = (0.0, 1.0);
        }
        let span = (hi - lo).max(if axis < 3 { 1.0 } else { 5.0 });
        let limit = chart.limits[axis];
        // A limit is drawn to scale when it is within one data span of the data; farther
        // ones would squash the curve to a line, so they are written out instead.
        let mut off_scale = Vec::new();
        if let Some((a, b)) = limit {
            for (v, word) in [(a, "min"), (b, "max")] {
                if v >= lo - span && v <= hi + span {
                    lo = lo.min(v);
                    hi = hi.max(v);
                } else {
                    off_scale.push(format!("{word} {}", tick_label(v, 1.0)));
                }
            }
        }
        let pad = (hi - lo).max(span) * 0.08;
        let y = Linear::new(lo - pad, hi + pad, frame.y + frame.h, frame.y);
        doc.open("class=\"grid\"");
        y_axis(doc, frame, &y, 4, true);
        doc.close();
        doc.rect(frame.x, frame.y, frame.w, frame.h, "class=\"frame\"");
        path_bands(doc, frame, &x, &bands, axis == 0);
        let mut s = 0usize;
        for (_, p) in &chart.paths {
            let pts: Vec<(f64, f64)> = p
                .iter()
                .enumerate()
                .filter(|(_, q)| q[axis].is_finite())
                .map(|(k, q)| (x.at((s + k) as f64), y.at(q[axis])))
                .collect();
            if pts.len() == 1 {
                doc.circle(
                    pts[0].0,
                    pts[0].1,
                    2.0,
                    &format!("fill=\"{}\"", AXIS_COLOURS[axis]),
                );
            }
            doc.polyline(
                &pts,
                &format!("stroke=\"{}\" class=\"series\"", AXIS_COLOURS[axis]),
            );
            s += p.len();
        }
        if let Some((a, b)) = limit {
            for (v, word) in [(a, "min"), (b, "max")] {
                if v >= y.d0 && v <= y.d1 {
                    let py = y.at(v);
                    doc.line(frame.x, py, frame.x + frame.w, py, "class=\"limit\"");
                    let dy = if word == "max" { 13.0 } else { -5.0 };
                    doc.text(
                        frame.x + frame.w - 6.0,
                        py + dy,
                        &format!("{word} {} {unit}", tick_label(v, 1.0)),
                        &format!(
                            "text-anchor=\"end\" style=\"fill:{ABOVE_TOLERANCE}\" class=\"halo\""
                        ),
                    );
                }
            }
        }
        let note = match (limit, chart.limits_known) {
            (_, false) => Some("limits unknown (no machine file)".to_owned()),
            (None, true) => Some("continuous axis: no limits".to_owned()),
            (Some(_), true) if !off_scale.is_empty() => {
                Some(format!("{} {unit}: off scale", off_scale.join(", ")))
            }
            _ => None,
        };
        if let Some(note) = note {
            // Bottom left, or top left if the curve passes there.
            let right = frame.x + 16.0 + text_width(&note, 11.0);
            let mut s = 0usize;
            let near_bottom = chart.paths.iter().any(|(_, p)| {
                let hit = p.iter().enumerate().any(|(k, q)| {
                    let px = x.at((s + k) as f64);
                    px <= right && y.at(q[axis]) > frame.y + frame.h - 20.0
                });
                s += p.len();
                hit
            });
            let ny = if near_bottom {
                frame.y + 14.0
            } else {
                frame.y + frame.h - 6.0
            };
            doc.text(frame.x + 8.0, ny, &note, "class=\"note halo\"");
        }
        doc.vtext(
            panel.x + 22.0,
            frame.y + frame.h / 2.0,
            &format!("{name} / {unit}"),
            &format!("class=\"axis\" style=\"fill:{}\"", AXIS_COLOURS[axis]),
        );
        if axis == 4 {
            x_axis(
                doc,
                frame,
                &x,
                total,
                "point index (all paths of the axes file, in order; kerf.axes/1 carries no time)",
            );
        }
        doc.close();
    }
    doc.close();
}

/// A safe id fragment for an axis name.
fn axis_id(name: &str) -> String {
    name.chars().filter(char::is_ascii_alphanumeric).collect()
}

/// The stylesheet used by the charts.
pub(crate) const STYLE: &str = concat!(
    ".gridline{stroke:#e6e6e6;stroke-width:0.8}",
    ".sep{stroke:#999;stroke-width:0.8;stroke-dasharray:2 3}",
    ".band{font-size:11px;fill:#555}",
    ".tol{stroke:#e4001b;stroke-width:1.4;stroke-dasharray:7 4}",
    ".limit{stroke:#e4001b;stroke-width:1.2;stroke-dasharray:6 4}",
    ".series{stroke-width:1.5}",
    ".halo{stroke:#fff;stroke-width:3px;paint-order:stroke}",
);
