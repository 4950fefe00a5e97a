//! The verification: every rule of `kerf.toolpath/1` checked against the curves, every
//! segment's chord error measured by brute force ([`crate::measure`]).

//! The report types are in `report`; the rules in this module.

use std::collections::HashMap;

use kerf_format::CurveRecord;
use kerf_nurbs::{LocalCurve, NurbsCurve};
use nalgebra::Point3;

use crate::input::{RawPathRecord, RawToolpath};
use crate::measure::segment_chord_error;

mod offset;
mod report;
#[cfg(test)]
mod tests;

pub use report::{Defect, OffsetReport, PathReport, Report, Violation, WorstSegment};

/// Floating-point allowance of the chord-error comparisons, relative to the curve size: a
/// measured error may exceed the tolerance (or a claim) by this much before it counts, so that
/// rounding in the evaluation of a 3 m curve (about `1e-12` mm) does not flag a segment whose
/// true error is exactly the tolerance. The measurement runs about the curve's local origin
/// ([`kerf_nurbs::LocalCurve`]), so the rounding scales with the curve's size wherever it lies;
/// for weights off powers of two the representation term (`4 eps max |P_i|`) is added.
pub const ROUNDING_ALLOWANCE: f64 = 1e-14;

/// The most samples per knot span the checker takes ([`CheckOptions::samples`] is capped to
/// it). The work is samples x spans x segments: 1,000,000 took 47 s on a 700-segment toolpath,
/// and the refinement of the local maxima finds the worst point from 32 as well as from more.
pub const MAX_SAMPLES: usize = 10_000;

/// How strictly to check.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct CheckOptions {
    /// Samples per knot span within a segment before refinement (at least `4 (degree + 1)` are
    /// used, at most [`MAX_SAMPLES`]: a larger value is used as `MAX_SAMPLES`). Default 32.
    pub samples: usize,
    /// How far a point may lie from the curve at its param, relative to the curve size (the
    /// diagonal of its control points' bounding box). Default `1e-9`. Two ulps of the point's
    /// largest coordinate are allowed on top: a written double cannot come closer than half an
    /// ulp, which far from the origin can exceed the relative figure.
    pub point_tolerance: f64,
    /// How far a param may be from a domain end or a C0 knot and still count as it, relative
    /// to the width of the curve's domain. Default `1e-9`.
    pub param_tolerance: f64,
    /// How far the length of a normal may be from 1. Default
    /// [`kerf_format::toolpath::UNIT_NORMAL_TOLERANCE`] (`1e-6`).
    pub normal_tolerance: f64,
}

impl Default for CheckOptions {
    fn default() -> Self {
        Self {
            samples: 32,
            point_tolerance: 1e-9,
            param_tolerance: 1e-9,
            normal_tolerance: kerf_format::toolpath::UNIT_NORMAL_TOLERANCE,
        }
    }
}

impl CheckOptions {
    /// Sets [`samples`](Self::samples): samples per knot span within a segment before
    /// refinement (at least `4 (degree + 1)` are used, at most [`MAX_SAMPLES`]).
    pub fn with_samples(mut self, samples: usize) -> Self {
        self.samples = samples;
        self
    }

    /// Sets [`point_tolerance`](Self::point_tolerance): how far a point may lie from the
    /// curve at its param, relative to the curve size (the diagonal of its control points'
    /// bounding box).
    pub fn with_point_tolerance(mut self, point_tolerance: f64) -> Self {
        self.point_tolerance = point_tolerance;
        self
    }

    /// Sets [`param_tolerance`](Self::param_tolerance): how far a param may be from a
    /// domain end or a C0 knot and still count as it, relative to the width of the curve's
    /// domain.
    pub fn with_param_tolerance(mut self, param_tolerance: f64) -> Self {
        self.param_tolerance = param_tolerance;
        self
    }

    /// Sets [`normal_tolerance`](Self::normal_tolerance): how far the length of a normal
    /// may be from 1.
    pub fn with_normal_tolerance(mut self, normal_tolerance: f64) -> Self {
        self.normal_tolerance = normal_tolerance;
        self
    }
}

/// Checks `toolpath` against the curves it claims to discretize: the ids and their order,
/// params (finite, strictly increasing, first and last at the domain ends), points (3 or 6
/// finite numbers, on the curve at their param), normals (unit), C0 corners (each a cutting
/// point), the chord error of every segment (measured by [`segment_chord_error`], at most
/// the tolerance) and the `max_chord_error` claim (at least the measured maximum, at most the
/// tolerance).
///
/// Never fails: everything wrong is a [`Violation`] in the report, and every path that can be
/// measured is.
pub fn check(curves: &[CurveRecord], toolpath: &RawToolpath, opts: &CheckOptions) -> Report {
    let mut violations = Vec::new();
    let file_level = |defect| Violation {
        path: None,
        id: None,
        defect,
    };
    if toolpath.units.as_deref() != Some("mm") {
        violations.push(file_level(Defect::Units {
            found: toolpath.units.clone(),
        }));
    }
    let tolerance_ok = toolpath.tolerance.is_finite() && toolpath.tolerance > 0.0;
    if !tolerance_ok {
        violations.push(file_level(Defect::BadTolerance {
            value: toolpath.tolerance,
        }));
    }
    let by_id: HashMap<&str, usize> = curves
        .iter()
        .enumerate()
        .rev()
        .map(|(i, c)| (c.id.as_str(), i))
        .collect();
    let mut first_path: HashMap<&str, usize> = HashMap::new();
    let mut path_violations = Vec::new();
    let mut paths = Vec::with_capacity(toolpath.paths.len());
    for (index, path) in toolpath.paths.iter().enumerate() {
        let mut found = Vec::new();
        if let Some(&first) = first_path.get(path.id.as_str()) {
            found.push(Defect::DuplicateId { first });
        } else {
            first_path.insert(&path.id, index);
        }
        let curve = match curves.get(index) {
            Some(c) if c.id == path.id => Some(&c.curve),
            other => match by_id.get(path.id.as_str()) {
                Some(&k) => {
                    found.push(Defect::WrongOrder {
                        expected: other.map(|c| c.id.clone()),
                    });
                    Some(&curves[k].curve)
                }
                None => {
                    found.push(Defect::UnknownId);
                    None
                }
            },
        };
        let tolerance = tolerance_ok.then_some(toolpath.tolerance);
        let report = check_path(index, path, curve, tolerance, opts, &mut found);
        paths.push(report);
        path_violations.extend(found.into_iter().map(|defect| Violation {
            path: Some(index),
            id: Some(path.id.clone()),
            defect,
        }));
    }
    for (i, c) in curves.iter().enumerate() {
        if !first_path.contains_key(c.id.as_str()) {
            violations.push(Violation {
                path: None,
                id: Some(c.id.clone()),
                defect: Defect::MissingPath { curve: i },
            });
        }
    }
    violations.extend(path_violations);
    Report {
        tolerance: toolpath.tolerance,
        paths,
        violations,
    }
}

/// Checks one path; pushes its defects to `found`.
fn check_path(
    index: usize,
    path: &RawPathRecord,
    curve: Option<&NurbsCurve>,
    tolerance: Option<f64>,
    opts: &CheckOptions,
    found: &mut Vec<Defect>,
) -> PathReport {
    let (n, m) = (path.points.len(), path.params.len());
    let mut report = PathReport {
        index,
        id: path.id.clone(),
        points: n,
        segments: 0,
        measured_chord_error: 0.0,
        worst: None,
        claimed: path.claimed_chord_error,
        claim_holds: None,
        c0_breaks: curve.map_or(0, |c| c.c0_breaks().len()),
        max_point_distance: 0.0,
        measured: false,
        kerf_offset: None,
    };
    if n != m {
        found.push(Defect::CountMismatch {
            points: n,
            params: m,
        });
    }
    if let Some(point_count) = path.point_count.filter(|&c| c != n) {
        found.push(Defect::PointCountMismatch {
            point_count,
            points: n,
        });
    }
    if n < 2 {
        found.push(Defect::TooFewPoints { points: n });
    }
    // Shape of the points.
    let first_len = path.points.first().map_or(3, Vec::len);
    let expected = (first_len == 3 || first_len == 6).then_some(first_len);
    for (i, p) in path.points.iter().enumerate() {
        let bad = match expected {
            Some(e) => p.len() != e,
            None => i == 0,
        };
        if bad {
            found.push(Defect::PointLength {
                point: i,
                len: p.len(),
                expected: expected.filter(|_| i > 0),
            });
        }
        for (k, x) in p.iter().enumerate() {
            if !x.is_finite() {
                found.push(Defect::NotFinite {
                    what: format!("points[{i}][{k}]"),
                });
            }
        }
        if p.len() == 6 {
            let norm = (p[3] * p[3] + p[4] * p[4] + p[5] * p[5]).sqrt();
            // Written so that a NaN length counts as not unit.
            let unit = (norm - 1.0).abs() <= opts.normal_tolerance;
            if !unit {
                found.push(Defect::NormalNotUnit { index: i, norm });
            }
        }
    }
    // Params: finite and increasing.
    for (i, &t) in path.params.iter().enumerate() {
        if !t.is_finite() {
            found.push(Defect::NotFinite {
                what: format!("params[{i}]"),
            });
        } else if i > 0 && path.params[i - 1].is_finite() && t <= path.params[i - 1] {
            found.push(Defect::ParamsNotIncreasing {
                index: i,
                value: t,
                previous: path.params[i - 1],
            });
        }
    }
    let increasing = path.params.windows(2).all(|w| w[1] > w[0]);
    if let Some(claimed) = path.claimed_chord_error {
        if let Some(tol) = tolerance {
            if claimed > tol {
                found.push(Defect::ClaimAboveTolerance {
                    claimed,
                    tolerance: tol,
                });
            }
        }
    } else {
        found.push(Defect::ClaimMissing);
    }
    let Some(curve) = curve else {
        return report;
    };
    if let Some(o) = &path.kerf_offset {
        report.kerf_offset = Some(offset::check_offset(index, curve, o, tolerance, found));
    }
    let k = n.min(m);
    let (a, b) = curve.domain();
    let ptol = opts.param_tolerance * (b - a);
    let size = curve.size().max(f64::MIN_POSITIVE);
    // Every distance is measured about the curve's local origin (an exact translation), so
    // that the rounding is relative to the curve's size even 1e6 mm from the origin. The
    // stored curve may differ from the file's by the representation term (weights off powers
    // of two), which a claim proven about the file's curve does not include.
    let local = LocalCurve::new(curve);
    let allowance = ROUNDING_ALLOWANCE * size + local.representation_mm();
    // Ends of the domain and interior params inside it.
    if let (Some(&first), Some(&last)) = (path.params.first(), path.params.last()) {
        let starts = (first - a).abs() <= ptol;
        let ends = (last - b).abs() <= ptol;
        if !starts {
            found.push(Defect::StartNotDomainStart {
                value: first,
                start: a,
            });
        }
        if !ends {
            found.push(Defect::EndNotDomainEnd {
                value: last,
                end: b,
            });
        }
    }
    for (i, &t) in path
        .params
        .iter()
        .enumerate()
        .take(m.saturating_sub(1))
        .skip(1)
    {
        if t.is_finite() && (t < a - ptol || t > b + ptol) {
            found.push(Defect::ParamOutsideDomain {
                index: i,
                value: t,
                start: a,
                end: b,
            });
        }
    }
    // C0 corners.
    for u in curve.c0_breaks() {
        let hit = path.params.iter().any(|&t| (t - u).abs() <= ptol);
        if !hit {
            let segment = if increasing {
                path.params.windows(2).position(|w| w[0] < u && u < w[1])
            } else {
                None
            };
            found.push(Defect::CornerMissed { param: u, segment });
        }
    }
    // Points on the curve.
    let positions: Vec<Option<Point3<f64>>> = path
        .points
        .iter()
        .map(|p| {
            (p.len() >= 3 && p[..3].iter().all(|x| x.is_finite()))
                .then(|| local.to_local(&Point3::new(p[0], p[1], p[2])))
        })
        .collect();
    for i in 0..k {
        let t = path.params[i];
        let (Some(p), true) = (positions[i], t.is_finite()) else {
            continue;
        };
        // A written coordinate is a double: it can only be within half an ulp of the curve,
        // which 1e9 mm from the origin is 6e-8 mm, more than 1e-9 of a small curve's size.
        let magnitude = path.points[i][..3]
            .iter()
            .fold(0.0, |m: f64, x| m.max(x.abs()));
        let allowed = opts.point_tolerance * size + 2.0 * f64::EPSILON * magnitude;
        let distance = (p - local.curve().point(t)).norm();
        report.max_point_distance = report.max_point_distance.max(distance);
        let on_curve = distance <= allowed;
        if !on_curve {
            found.push(Defect::PointOffCurve {
                index: i,
                param: t,
                distance,
                allowed,
            });
        }
    }
    // Chord errors.
    let mut exceeding = Vec::new();
    for s in 0..k.saturating_sub(1) {
        let (t0, t1) = (path.params[s], path.params[s + 1]);
        let (Some(p0), Some(p1)) = (positions[s], positions[s + 1]) else {
            continue;
        };
        if !(t0.is_finite() && t1.is_finite() && t1 > t0) {
            continue;
        }
        let e = segment_chord_error(
            local.curve(),
            t0,
            t1,
            &p0,
            &p1,
            opts.samples.min(MAX_SAMPLES),
        );
        report.segments += 1;
        report.measured = true;
        if report.worst.is_none_or(|w| e.error > w.error) {
            report.worst = Some(WorstSegment {
                segment: s,
                t0,
                t1,
                at: e.at,
                error: e.error,
            });
            report.measured_chord_error = e.error;
        }
        if let Some(tol) = tolerance {
            if e.error > tol + allowance {
                exceeding.push(Defect::ChordError {
                    segment: s,
                    t0,
                    t1,
                    at: e.at,
                    error: e.error,
                    tolerance: tol,
                });
            }
        }
    }
    found.extend(exceeding);
    if let (Some(claimed), true) = (path.claimed_chord_error, report.measured) {
        let holds = claimed >= report.measured_chord_error - allowance;
        report.claim_holds = Some(holds);
        if !holds {
            found.push(Defect::ClaimUnderstated {
                claimed,
                measured: report.measured_chord_error,
            });
        }
    }
    report
}
