//! The check of a path's `kerf_offset`: every chord against the exact offset of the curve (or
//! the arc about a corner), and the whole path against the curve for the gouge, by sampling:
//! a measurement of what the writer claims, not a second proof.
//!
//! The exact offset at `t` is `C(t) + s r normalize(a x C'(t))` (`r` the offset, `s` = +1 for the
//! left, `a` the tool axis, interpolated between the chord's ends): the beam's centre half a kerf
//! from the contour at right angles to the path and the beam (`docs/process.md`, "Kerf
//! compensation"). Between two points of the same parameter it is the arc of radius `r` about
//! the corner `C(t)` in the plane across the axis. A chord whose parameters straddle a C0
//! corner, or over which the exact offset runs backwards (a rounding tighter than the offset),
//! was cut back: there the exact offsets run into the part, so the chord is checked for the
//! gouge only.

use kerf_format::{KerfOffset, ScrapSide};
use kerf_nurbs::{distance_to_segment, NurbsCurve};
use nalgebra::{Point3, Vector3};

use super::{Defect, OffsetReport};

/// Samples inside each chord.
const SAMPLES: usize = 32;

/// Checks `o` against `curve`; pushes its defects to `found`.
pub(super) fn check_offset(
    index: usize,
    curve: &NurbsCurve,
    o: &KerfOffset,
    tolerance: Option<f64>,
    found: &mut Vec<Defect>,
) -> OffsetReport {
    let mut report = OffsetReport {
        offset_mm: o.offset_mm,
        points: o.points.len(),
        segments: 0,
        cut_backs: 0,
        max_chord_error: 0.0,
        min_distance_from_curve: f64::INFINITY,
    };
    if let Err(e) = o.validate(index) {
        found.push(Defect::OffsetShape {
            reason: e.to_string(),
        });
        return report;
    }
    let (a, b) = curve.domain();
    let slack = 1e-9 * (b - a);
    if o.params[0] < a - slack || o.params[o.params.len() - 1] > b + slack {
        found.push(Defect::OffsetShape {
            reason: format!(
                "params run over [{}, {}], outside the curve's domain [{a}, {b}]",
                o.params[0],
                o.params[o.params.len() - 1]
            ),
        });
        return report;
    }
    let r = o.offset_mm;
    let sign = match o.side {
        ScrapSide::Left => 1.0,
        ScrapSide::Right => -1.0,
    };
    let breaks = curve.c0_breaks();
    let tol = tolerance.unwrap_or(f64::INFINITY);
    let allowance = 1e-12 * curve.size().max(1.0);
    let pos = |p: &[f64; 6]| Point3::new(p[0], p[1], p[2]);
    let axis = |p: &[f64; 6]| Vector3::new(p[3], p[4], p[5]).normalize();
    let mut worst_gouge: Option<(Point3<f64>, f64)> = None;
    let mut gouge = |q: Point3<f64>, report: &mut OffsetReport| {
        let d = curve.closest_point(&q).distance;
        report.min_distance_from_curve = report.min_distance_from_curve.min(d);
        if d < r - tol - allowance && worst_gouge.is_none_or(|w| d < w.1) {
            worst_gouge = Some((q, d));
        }
    };
    for j in 0..o.points.len() - 1 {
        let (p0, p1) = (pos(&o.points[j]), pos(&o.points[j + 1]));
        let (a0, a1) = (axis(&o.points[j]), axis(&o.points[j + 1]));
        let (t0, t1) = (o.params[j], o.params[j + 1]);
        for k in 0..8 {
            gouge(p0 + (p1 - p0) * (k as f64 / 8.0), &mut report);
        }
        let straddles = breaks.iter().any(|&u| t0 < u - slack && u + slack < t1);
        if straddles {
            report.cut_backs += 1;
            continue;
        }
        let mut error = 0.0_f64;
        if t1 - t0 <= slack {
            // An arc about the corner C(t0), in the plane across the axis.
            let c = curve.point(t0);
            let across = |v: Vector3<f64>| v - a0 * v.dot(&a0);
            let (Some(u0), Some(u1)) = (
                across(p0 - c).try_normalize(1e-300),
                across(p1 - c).try_normalize(1e-300),
            ) else {
                continue;
            };
            let angle = u0.angle(&u1);
            let turn = u0.cross(&u1).try_normalize(1e-300).unwrap_or(a0);
            for k in 1..SAMPLES {
                let th = angle * k as f64 / SAMPLES as f64;
                let u = u0 * th.cos() + turn.cross(&u0) * th.sin();
                error = nan_max(error, distance_to_segment(&(c + u * r), &p0, &p1));
            }
        } else {
            let mut samples = Vec::with_capacity(SAMPLES);
            for k in 1..SAMPLES {
                let f = k as f64 / SAMPLES as f64;
                let t = t0 + (t1 - t0) * f;
                let ax = (a0 * (1.0 - f) + a1 * f).normalize();
                let (c, d1) = curve.eval_d1(t);
                let Some(d) = ax.cross(&d1).try_normalize(1e-300) else {
                    continue;
                };
                samples.push((c + d * (sign * r), d1));
            }
            // Where the exact offset runs backwards against the curve, the curve bends toward
            // the scrap tighter than the offset: the path was cut back across it.
            if samples
                .windows(2)
                .any(|w| (w[1].0 - w[0].0).dot(&w[0].1) < 0.0)
            {
                report.cut_backs += 1;
                continue;
            }
            for (q, _) in &samples {
                error = nan_max(error, distance_to_segment(q, &p0, &p1));
            }
        }
        report.segments += 1;
        report.max_chord_error = nan_max(report.max_chord_error, error);
        if error.is_nan() || error > tol + allowance {
            found.push(Defect::OffsetChordError {
                segment: j,
                error,
                tolerance: tol,
            });
        }
    }
    gouge(pos(&o.points[o.points.len() - 1]), &mut report);
    if let Some((q, d)) = worst_gouge {
        found.push(Defect::OffsetGouge {
            at: [q.x, q.y, q.z],
            distance: d,
            least: r - tol,
        });
    }
    if report.max_chord_error.is_nan() || o.max_chord_error < report.max_chord_error - allowance {
        found.push(Defect::OffsetClaimUnderstated {
            claimed: o.max_chord_error,
            measured: report.max_chord_error,
        });
    }
    report
}

/// The larger of two distances, NaN if either is: a NaN never passes for a small error.
fn nan_max(a: f64, b: f64) -> f64 {
    if a.is_nan() || b.is_nan() {
        f64::NAN
    } else {
        a.max(b)
    }
}
