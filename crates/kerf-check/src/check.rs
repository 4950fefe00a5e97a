//! The verification: every rule of `kerf.toolpath/1` checked against the curves, every
//! segment's chord error measured by brute force ([`crate::measure`]).

use std::collections::HashMap;
use std::fmt;

use kerf_format::CurveRecord;
use kerf_nurbs::NurbsCurve;
use nalgebra::Point3;
use serde::Serialize;
use serde_json::{json, Value};

use crate::input::{RawPathRecord, RawToolpath};
use crate::measure::segment_chord_error;

/// Floating-point allowance of the chord-error comparisons, relative to the curve size: a
/// measured error may exceed the tolerance (or a claim) by this much before it counts, so that
/// rounding in the evaluation of a 3 m curve (about `1e-12` mm) does not flag a segment whose
/// true error is exactly the tolerance.
pub const ROUNDING_ALLOWANCE: f64 = 1e-14;

/// How strictly to check.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CheckOptions {
    /// Samples per knot span within a segment before refinement (at least `4 (degree + 1)` are
    /// used). Default 32.
    pub samples: usize,
    /// How far a point may lie from the curve at its param, relative to the curve size (the
    /// diagonal of its control points' bounding box). Default `1e-9`.
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

/// The result of [`check`]: what was measured per path, and every violation found.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Report {
    /// The tolerance the toolpath claims, in mm.
    pub tolerance: f64,
    /// One entry per path of the toolpath, in file order.
    pub paths: Vec<PathReport>,
    /// Every violation, in the order found (file-level first, then path by path).
    pub violations: Vec<Violation>,
}

impl Report {
    /// True if no rule is violated.
    pub fn passed(&self) -> bool {
        self.violations.is_empty()
    }

    /// The largest measured chord error over all paths, in mm (0 for no segments).
    pub fn measured_chord_error(&self) -> f64 {
        self.paths
            .iter()
            .map(|p| p.measured_chord_error)
            .fold(0.0, f64::max)
    }

    /// The total number of measured segments.
    pub fn segments(&self) -> usize {
        self.paths.iter().map(|p| p.segments).sum()
    }

    /// The report as JSON: `passed`, `tolerance`, `max_chord_error`, `segments`, `paths` (each
    /// [`PathReport`]) and `violations` (each with `path`, `id`, `kind`, the kind's fields and
    /// the `message` printed by `kerf check`).
    pub fn to_json(&self) -> Value {
        json!({
            "passed": self.passed(),
            "tolerance": self.tolerance,
            "max_chord_error": self.measured_chord_error(),
            "segments": self.segments(),
            "paths": serde_json::to_value(&self.paths).unwrap_or(Value::Null),
            "violations": self.violations.iter().map(Violation::to_json).collect::<Vec<_>>(),
        })
    }
}

/// What was measured on one path.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PathReport {
    /// Index in the toolpath's `paths`.
    pub index: usize,
    /// The path's id.
    pub id: String,
    /// The number of points.
    pub points: usize,
    /// The number of segments whose chord error was measured (those with increasing, finite
    /// params and points); `points - 1` for a sound path.
    pub segments: usize,
    /// The largest measured chord error, in mm (the key `max_chord_error` of the JSON report).
    #[serde(rename = "max_chord_error")]
    pub measured_chord_error: f64,
    /// The segment where it occurs, if any segment was measured.
    pub worst: Option<WorstSegment>,
    /// The `max_chord_error` the file claims, if present.
    pub claimed: Option<f64>,
    /// Whether the claim is at least the measured maximum (`None` without a claim or without
    /// a curve to measure against).
    pub claim_holds: Option<bool>,
    /// The number of C0 corners (interior knots of multiplicity >= degree) of the curve.
    pub c0_breaks: usize,
    /// The largest distance of a point from the curve at its param, in mm.
    pub max_point_distance: f64,
    /// False if the path could not be measured (no curve with its id, or unusable points).
    pub measured: bool,
}

/// The segment with the largest chord error of a path.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct WorstSegment {
    /// The segment index (segment `s` joins points `s` and `s + 1`).
    pub segment: usize,
    /// Its start param.
    pub t0: f64,
    /// Its end param.
    pub t1: f64,
    /// The param of the largest distance.
    pub at: f64,
    /// The measured chord error, in mm.
    pub error: f64,
}

/// One broken rule, located in the file.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Violation {
    /// Index of the path in `paths`, or `None` for a rule about the whole file.
    pub path: Option<usize>,
    /// The path's (or for [`Defect::MissingPath`] the curve's) id.
    pub id: Option<String>,
    /// What is wrong.
    #[serde(flatten)]
    pub defect: Defect,
}

impl Violation {
    /// The violation as a JSON object: `path`, `id`, `kind`, the kind's fields, `message`.
    pub fn to_json(&self) -> Value {
        let mut v = serde_json::to_value(self).unwrap_or_else(|_| json!({}));
        if let Value::Object(map) = &mut v {
            map.insert("message".into(), Value::String(self.to_string()));
        }
        v
    }
}

impl fmt::Display for Violation {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match (&self.defect, self.path, &self.id) {
            (Defect::MissingPath { curve }, _, Some(id)) => {
                write!(f, "curves[{curve}] ({id:?}): ")?
            }
            (_, Some(i), Some(id)) => write!(f, "paths[{i}] ({id:?}): ")?,
            (_, Some(i), None) => write!(f, "paths[{i}]: ")?,
            _ => {}
        }
        write!(f, "{}", self.defect)
    }
}

/// A broken rule. Each variant says what the file should hold instead.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Defect {
    /// `units` is missing or not `"mm"`: kerf works in millimetres only.
    Units {
        /// The value found.
        found: Option<String>,
    },
    /// `tolerance` is not finite and > 0; chord errors are then not compared with it.
    BadTolerance {
        /// The value found.
        value: f64,
    },
    /// A curve has no path: every curve must have one, in curve order.
    MissingPath {
        /// The curve's index in the curves file.
        curve: usize,
    },
    /// No curve has the path's id; the path is not measured.
    UnknownId,
    /// The path's id is not the id of the curve at the same index (paths must follow the
    /// curves' order); it is measured against the curve with its id.
    WrongOrder {
        /// The id of the curve at this index, if there is one.
        expected: Option<String>,
    },
    /// Two paths have the same id.
    DuplicateId {
        /// The index of the first path with this id.
        first: usize,
    },
    /// `points` and `params` differ in length (one param per point).
    CountMismatch {
        /// Number of points.
        points: usize,
        /// Number of params.
        params: usize,
    },
    /// The optional `point_count` differs from the number of points (a truncated or edited
    /// file): the count must equal the length of `points`.
    PointCountMismatch {
        /// The `point_count` written.
        point_count: usize,
        /// Number of points.
        points: usize,
    },
    /// Fewer than two points: a path holds at least the two ends of the domain.
    TooFewPoints {
        /// Number of points.
        points: usize,
    },
    /// A point is not 3 numbers (`x, y, z`) or 6 (with the normal), or its length differs from
    /// the first point's.
    PointLength {
        /// The point's index.
        point: usize,
        /// Its length.
        len: usize,
        /// The first point's length, if that one is 3 or 6.
        expected: Option<usize>,
    },
    /// A param or a coordinate is not finite.
    NotFinite {
        /// Which value, as a JSON path inside the path (`params[3]`, `points[2][1]`).
        what: String,
    },
    /// A param is not greater than the one before it.
    ParamsNotIncreasing {
        /// The param's index.
        index: usize,
        /// Its value.
        value: f64,
        /// The param before it.
        previous: f64,
    },
    /// An interior param lies outside the curve's domain.
    ParamOutsideDomain {
        /// The param's index.
        index: usize,
        /// Its value.
        value: f64,
        /// The domain start.
        start: f64,
        /// The domain end.
        end: f64,
    },
    /// The first param is not the start of the curve's domain.
    StartNotDomainStart {
        /// The first param.
        value: f64,
        /// The domain start.
        start: f64,
    },
    /// The last param is not the end of the curve's domain.
    EndNotDomainEnd {
        /// The last param.
        value: f64,
        /// The domain end.
        end: f64,
    },
    /// A point is not the curve's point at its param.
    PointOffCurve {
        /// The point's index.
        index: usize,
        /// Its param.
        param: f64,
        /// Its distance from `C(param)`, in mm.
        distance: f64,
        /// The distance allowed, in mm.
        allowed: f64,
    },
    /// A normal is not a unit vector.
    NormalNotUnit {
        /// The point's index.
        index: usize,
        /// The normal's length.
        norm: f64,
    },
    /// A C0 corner of the curve (an interior knot of multiplicity >= degree) is not a cutting
    /// point.
    CornerMissed {
        /// The knot.
        param: f64,
        /// The segment that spans it, if the params are in order.
        segment: Option<usize>,
    },
    /// A segment's measured chord error exceeds the tolerance.
    ChordError {
        /// The segment index (joins points `segment` and `segment + 1`).
        segment: usize,
        /// Its start param.
        t0: f64,
        /// Its end param.
        t1: f64,
        /// The param of the largest distance.
        at: f64,
        /// The measured chord error, in mm.
        error: f64,
        /// The file's tolerance, in mm.
        tolerance: f64,
    },
    /// `max_chord_error` is missing.
    ClaimMissing,
    /// `max_chord_error` is below the measured maximum: the file understates its error.
    ClaimUnderstated {
        /// The claimed value, in mm.
        claimed: f64,
        /// The measured maximum, in mm.
        measured: f64,
    },
    /// `max_chord_error` is above the tolerance (the format requires it to be at most the
    /// tolerance).
    ClaimAboveTolerance {
        /// The claimed value, in mm.
        claimed: f64,
        /// The tolerance, in mm.
        tolerance: f64,
    },
}

impl fmt::Display for Defect {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Defect::Units { found: Some(u) } => {
                write!(f, "units: {u:?}, expected \"mm\"")
            }
            Defect::Units { found: None } => write!(f, "units: missing, expected \"mm\""),
            Defect::BadTolerance { value } => {
                write!(f, "tolerance: {value} is not a positive number")
            }
            Defect::MissingPath { .. } => write!(f, "no path for this curve"),
            Defect::UnknownId => write!(f, "no curve with this id"),
            Defect::WrongOrder { expected: Some(e) } => {
                write!(f, "out of order: the curve at this index is {e:?}")
            }
            Defect::WrongOrder { expected: None } => {
                write!(f, "out of order: there are fewer curves than paths")
            }
            Defect::DuplicateId { first } => write!(f, "same id as paths[{first}]"),
            Defect::CountMismatch { points, params } => {
                write!(
                    f,
                    "{points} points but {params} params (one param per point)"
                )
            }
            Defect::PointCountMismatch {
                point_count,
                points,
            } => write!(
                f,
                "point_count is {point_count} but there are {points} points"
            ),
            Defect::TooFewPoints { points } => {
                write!(
                    f,
                    "{points} points; a path has at least 2 (the ends of the domain)"
                )
            }
            Defect::PointLength {
                point,
                len,
                expected: Some(e),
            } => write!(f, "points[{point}]: {len} numbers, but points[0] has {e}"),
            Defect::PointLength { point, len, .. } => {
                write!(f, "points[{point}]: {len} numbers, expected 3 or 6")
            }
            Defect::NotFinite { what } => write!(f, "{what}: not a finite number"),
            Defect::ParamsNotIncreasing {
                index,
                value,
                previous,
            } => write!(
                f,
                "params[{index}]: params must increase strictly ({value} after {previous})"
            ),
            Defect::ParamOutsideDomain {
                index,
                value,
                start,
                end,
            } => write!(
                f,
                "params[{index}]: {value} is outside the domain [{start}, {end}]"
            ),
            Defect::StartNotDomainStart { value, start } => write!(
                f,
                "params[0]: {value} is not the start of the curve's domain ({start})"
            ),
            Defect::EndNotDomainEnd { value, end } => write!(
                f,
                "last param: {value} is not the end of the curve's domain ({end})"
            ),
            Defect::PointOffCurve {
                index,
                param,
                distance,
                allowed,
            } => write!(
                f,
                "points[{index}]: {distance:.3e} mm from the curve's point at its param {param} \
                 (allowed {allowed:.1e} mm)"
            ),
            Defect::NormalNotUnit { index, norm } => {
                write!(f, "points[{index}]: normal has length {norm}, not 1")
            }
            Defect::CornerMissed {
                param,
                segment: Some(s),
            } => write!(
                f,
                "C0 corner at t = {param} is not a cutting point (segment {s} spans it)"
            ),
            Defect::CornerMissed {
                param,
                segment: None,
            } => write!(f, "C0 corner at t = {param} is not a cutting point"),
            Defect::ChordError {
                segment,
                t0,
                t1,
                at,
                error,
                tolerance,
            } => write!(
                f,
                "segment {segment} (t {t0} .. {t1}): chord error {error:.6e} mm > tolerance \
                 {tolerance} mm (largest at t = {at})"
            ),
            Defect::ClaimMissing => write!(f, "max_chord_error: missing"),
            Defect::ClaimUnderstated { claimed, measured } => write!(
                f,
                "max_chord_error: claims {claimed:.6e} mm but a segment measures {measured:.6e} mm"
            ),
            Defect::ClaimAboveTolerance { claimed, tolerance } => write!(
                f,
                "max_chord_error: {claimed:.6e} mm is above the tolerance {tolerance} mm"
            ),
        }
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
    let k = n.min(m);
    let (a, b) = curve.domain();
    let ptol = opts.param_tolerance * (b - a);
    let size = curve.size().max(f64::MIN_POSITIVE);
    let allowance = ROUNDING_ALLOWANCE * size;
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
                .then(|| Point3::new(p[0], p[1], p[2]))
        })
        .collect();
    let allowed = opts.point_tolerance * size;
    for i in 0..k {
        let t = path.params[i];
        let (Some(p), true) = (positions[i], t.is_finite()) else {
            continue;
        };
        let distance = (p - curve.point(t)).norm();
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
        let e = segment_chord_error(curve, t0, t1, &p0, &p1, opts.samples);
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

#[cfg(test)]
mod tests {
    use super::*;
    use kerf_format::CurvesFile;

    fn mixed() -> CurvesFile {
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../fixtures/mixed.json");
        kerf_format::curves::load(path).expect("fixture loads")
    }

    /// The discretizer's toolpath of every curve at `tol`.
    fn toolpath(file: &CurvesFile, tol: f64) -> RawToolpath {
        let opts = kerf_discretize::Options::with_tolerance(tol);
        RawToolpath {
            units: Some("mm".into()),
            tolerance: tol,
            paths: file
                .curves
                .iter()
                .map(|c| {
                    let d = kerf_discretize::discretize(&c.curve, &opts).expect("discretizes");
                    RawPathRecord {
                        id: c.id.clone(),
                        params: d.params().to_vec(),
                        points: d.points().iter().map(|p| vec![p.x, p.y, p.z]).collect(),
                        claimed_chord_error: Some(d.max_chord_error()),
                        point_count: None,
                    }
                })
                .collect(),
        }
    }

    fn defects(report: &Report, path: Option<usize>) -> Vec<&Defect> {
        report
            .violations
            .iter()
            .filter(|v| v.path == path)
            .map(|v| &v.defect)
            .collect()
    }

    fn index_of(file: &CurvesFile, id: &str) -> usize {
        file.curves
            .iter()
            .position(|c| c.id == id)
            .expect("curve exists")
    }

    #[test]
    fn a_correct_toolpath_passes() {
        let file = mixed();
        let tp = toolpath(&file, 0.01);
        let report = check(&file.curves, &tp, &CheckOptions::default());
        assert!(report.passed(), "{:#?}", report.violations);
        for (p, rec) in report.paths.iter().zip(&tp.paths) {
            assert_eq!(
                p.segments,
                rec.points.len() - 1,
                "{}: every segment measured",
                p.id
            );
            assert!(
                p.claim_holds == Some(true),
                "{}: the certified bound holds",
                p.id
            );
            assert!(p.measured_chord_error <= 0.01, "{}: within tolerance", p.id);
            assert!(
                p.max_point_distance <= 1e-12,
                "{}: points on the curve",
                p.id
            );
        }
        // The discretizer fills the band [0.9, 1] of the tolerance on curved paths.
        let quintic = &report.paths[index_of(&file, "freeform-quintic")];
        assert!(quintic.measured_chord_error > 0.008, "{quintic:?}");
        assert_eq!(
            report.paths[index_of(&file, "v-corner")].c0_breaks,
            1,
            "the corner"
        );
        let json = report.to_json();
        assert_eq!(json["passed"], true, "{json}");
    }

    #[test]
    fn a_removed_point_on_a_curved_path_is_caught() {
        let file = mixed();
        let mut tp = toolpath(&file, 0.01);
        let i = index_of(&file, "freeform-quintic");
        let path = &mut tp.paths[i];
        let k = path.points.len() / 2;
        path.points.remove(k);
        path.params.remove(k);
        let report = check(&file.curves, &tp, &CheckOptions::default());
        let found = defects(&report, Some(i));
        let chord = found
            .iter()
            .find_map(|d| match d {
                Defect::ChordError { segment, error, .. } => Some((*segment, *error)),
                _ => None,
            })
            .expect("the long segment exceeds the tolerance");
        assert_eq!(chord.0, k - 1, "the segment that lost its point");
        // Two segments merged: about four times the error of one.
        assert!(chord.1 > 0.02, "{chord:?}");
        assert!(
            found
                .iter()
                .any(|d| matches!(d, Defect::ClaimUnderstated { .. })),
            "the old claim understates: {found:?}"
        );
        let message = report
            .violations
            .iter()
            .find(|v| matches!(v.defect, Defect::ChordError { .. }))
            .map(ToString::to_string)
            .unwrap_or_default();
        let expected = format!("paths[{i}] (\"freeform-quintic\"): segment {} (t ", k - 1);
        assert!(message.starts_with(&expected), "{message}");
        assert!(message.contains("mm > tolerance 0.01 mm"), "{message}");
        assert_eq!(
            report.paths[i].worst.map(|w| w.segment),
            Some(k - 1),
            "worst segment"
        );
    }

    #[test]
    fn a_removed_c0_corner_is_caught() {
        let file = mixed();
        let mut tp = toolpath(&file, 0.01);
        let i = index_of(&file, "v-corner");
        let path = &mut tp.paths[i];
        let k = path
            .params
            .iter()
            .position(|&t| t == 0.5)
            .expect("corner kept");
        path.points.remove(k);
        path.params.remove(k);
        let report = check(&file.curves, &tp, &CheckOptions::default());
        let found = defects(&report, Some(i));
        assert!(
            found.contains(&&Defect::CornerMissed {
                param: 0.5,
                segment: Some(k - 1)
            }),
            "{found:?}"
        );
        assert!(
            found
                .iter()
                .any(|d| matches!(d, Defect::ChordError { segment, at, .. } if *segment == k - 1 && *at == 0.5)),
            "the chord cuts the corner, largest at the knot: {found:?}"
        );
        let text = report
            .violations
            .iter()
            .map(ToString::to_string)
            .collect::<Vec<_>>();
        assert!(
            text.contains(&format!(
                "paths[{i}] (\"v-corner\"): C0 corner at t = 0.5 is not a cutting point (segment {} spans it)",
                k - 1
            )),
            "{text:#?}"
        );
    }

    #[test]
    fn a_point_off_the_curve_is_caught() {
        let file = mixed();
        let mut tp = toolpath(&file, 0.01);
        let i = index_of(&file, "straight");
        tp.paths[i].points[1][2] += 1e-4;
        let report = check(&file.curves, &tp, &CheckOptions::default());
        let found = defects(&report, Some(i));
        assert!(
            matches!(found[0], Defect::PointOffCurve { index: 1, distance, .. } if (*distance - 1e-4).abs() < 1e-9),
            "{found:?}"
        );
        // The end point moved, so the chord moved: the (tiny) claim of a straight line no
        // longer holds either.
        assert!(
            matches!(found[1], Defect::ClaimUnderstated { measured, .. } if *measured > 9e-5),
            "{found:?}"
        );
        let message = report.violations[0].to_string();
        assert!(
            message.starts_with(&format!("paths[{i}] (\"straight\"): points[1]: 1.000e-4 mm from the curve's point at its param 1 (allowed 1.0e-7 mm)")),
            "{message}"
        );
    }

    #[test]
    fn params_out_of_order_are_caught() {
        let file = mixed();
        // Two neighbouring params swapped.
        let mut tp = toolpath(&file, 0.01);
        let i = index_of(&file, "freeform-quintic");
        tp.paths[i].params.swap(3, 4);
        let report = check(&file.curves, &tp, &CheckOptions::default());
        let found = defects(&report, Some(i));
        assert!(
            found
                .iter()
                .any(|d| matches!(d, Defect::ParamsNotIncreasing { index: 4, .. })),
            "{found:?}"
        );
        assert!(
            found
                .iter()
                .any(|d| matches!(d, Defect::PointOffCurve { index: 3, .. })),
            "points no longer at their params: {found:?}"
        );
        // The whole path reversed: params and points.
        let mut tp = toolpath(&file, 0.01);
        tp.paths[i].params.reverse();
        tp.paths[i].points.reverse();
        let report = check(&file.curves, &tp, &CheckOptions::default());
        let found = defects(&report, Some(i));
        assert!(
            matches!(found[0], Defect::ParamsNotIncreasing { index: 1, .. }),
            "{found:?}"
        );
        assert!(
            found.iter().any(|d| matches!(d, Defect::StartNotDomainStart { value, start } if *value == 1.0 && *start == 0.0)),
            "{found:?}"
        );
        assert!(
            found.iter().any(|d| matches!(d, Defect::EndNotDomainEnd { value, end } if *value == 0.0 && *end == 1.0)),
            "{found:?}"
        );
        assert_eq!(report.paths[i].segments, 0, "no segment can be measured");
        assert!(
            report.violations.iter().any(|v| v.to_string()
                == format!("paths[{i}] (\"freeform-quintic\"): params[0]: 1 is not the start of the curve's domain (0)")),
            "{:#?}",
            report.violations
        );
    }

    #[test]
    fn ids_and_their_order_are_checked() {
        let file = mixed();
        let mut tp = toolpath(&file, 0.01);
        tp.paths.swap(0, 1);
        let report = check(&file.curves, &tp, &CheckOptions::default());
        assert_eq!(report.violations.len(), 2, "{:#?}", report.violations);
        assert!(
            matches!(&report.violations[0].defect, Defect::WrongOrder { expected: Some(e) } if e == "v-corner"),
            "{:?}",
            report.violations[0]
        );
        assert!(
            report.paths[0].measured,
            "still measured against its own curve"
        );

        let mut tp = toolpath(&file, 0.01);
        tp.paths.pop();
        tp.paths[0].id = "nope".into();
        tp.paths[1].id = tp.paths[2].id.clone();
        let report = check(&file.curves, &tp, &CheckOptions::default());
        let kinds: Vec<_> = report.violations.iter().map(|v| v.to_string()).collect();
        assert!(
            kinds.contains(&"curves[0] (\"v-corner\"): no path for this curve".to_string()),
            "{kinds:#?}"
        );
        assert!(
            kinds.contains(&"curves[3] (\"slot-on-plane\"): no path for this curve".to_string()),
            "{kinds:#?}"
        );
        assert!(
            kinds.contains(&"paths[0] (\"nope\"): no curve with this id".to_string()),
            "{kinds:#?}"
        );
        assert!(
            kinds.contains(&"paths[2] (\"freeform-quintic\"): same id as paths[1]".to_string()),
            "{kinds:#?}"
        );
        assert!(!report.paths[0].measured, "nothing to measure against");
    }

    #[test]
    fn normals_shapes_and_claims_are_checked() {
        let file = mixed();
        let mut tp = toolpath(&file, 0.01);
        tp.units = None;
        let p = &mut tp.paths[2];
        for q in &mut p.points {
            q.extend([0.0, 0.0, 1.0]);
        }
        p.points[1][5] = 0.5;
        p.points[2].truncate(3);
        tp.paths[1].claimed_chord_error = None;
        tp.paths[3].claimed_chord_error = Some(0.02);
        tp.paths[0].params.pop();
        let report = check(&file.curves, &tp, &CheckOptions::default());
        let found: Vec<_> = report
            .violations
            .iter()
            .map(|v| (v.path, v.defect.clone()))
            .collect();
        assert!(
            found.contains(&(None, Defect::Units { found: None })),
            "{found:#?}"
        );
        assert!(
            found.contains(&(
                Some(2),
                Defect::NormalNotUnit {
                    index: 1,
                    norm: 0.5
                }
            )),
            "{found:#?}"
        );
        assert!(
            found.contains(&(
                Some(2),
                Defect::PointLength {
                    point: 2,
                    len: 3,
                    expected: Some(6)
                }
            )),
            "{found:#?}"
        );
        assert!(
            found.contains(&(Some(1), Defect::ClaimMissing)),
            "{found:#?}"
        );
        assert!(
            found.contains(&(
                Some(3),
                Defect::ClaimAboveTolerance {
                    claimed: 0.02,
                    tolerance: 0.01
                }
            )),
            "{found:#?}"
        );
        let n = tp.paths[0].points.len();
        assert!(
            found.contains(&(
                Some(0),
                Defect::CountMismatch {
                    points: n,
                    params: n - 1
                }
            )),
            "{found:#?}"
        );

        let mut tp = toolpath(&file, 0.01);
        tp.tolerance = 0.0;
        tp.paths[1].points.truncate(1);
        tp.paths[1].params.truncate(1);
        let report = check(&file.curves, &tp, &CheckOptions::default());
        let found: Vec<_> = report
            .violations
            .iter()
            .map(|v| (v.path, v.defect.clone()))
            .collect();
        assert!(
            found.contains(&(None, Defect::BadTolerance { value: 0.0 })),
            "{found:#?}"
        );
        assert!(
            found.contains(&(Some(1), Defect::TooFewPoints { points: 1 })),
            "{found:#?}"
        );
        let mut counted = toolpath(&file, 0.01);
        let n = counted.paths[0].points.len();
        counted.paths[0].point_count = Some(n + 1);
        counted.paths[1].point_count = Some(counted.paths[1].points.len());
        let report = check(&file.curves, &counted, &CheckOptions::default());
        assert_eq!(
            report
                .violations
                .iter()
                .map(|v| (v.path, v.defect.clone()))
                .collect::<Vec<_>>(),
            [(
                Some(0),
                Defect::PointCountMismatch {
                    point_count: n + 1,
                    points: n
                }
            )],
            "a wrong point_count is the only defect; a right one is none"
        );
        assert!(
            !found
                .iter()
                .any(|(_, d)| matches!(d, Defect::ChordError { .. })),
            "no comparison with a meaningless tolerance"
        );
    }

    #[test]
    fn a_tighter_tolerance_flags_the_file() {
        // The same points claimed for a tolerance ten times tighter.
        let file = mixed();
        let mut tp = toolpath(&file, 0.01);
        tp.tolerance = 0.001;
        for p in &mut tp.paths {
            p.claimed_chord_error = Some(0.0);
        }
        let report = check(&file.curves, &tp, &CheckOptions::default());
        let chord = report
            .violations
            .iter()
            .filter(|v| matches!(v.defect, Defect::ChordError { .. }))
            .count();
        assert!(chord > 100, "most segments exceed 0.001: {chord}");
        let json = report.to_json();
        assert_eq!(json["passed"], false, "{json}");
        assert_eq!(
            json["violations"][0]["kind"], "chord_error",
            "{}",
            json["violations"][0]
        );
        assert!(
            json["violations"][0]["message"]
                .as_str()
                .unwrap_or("")
                .contains("> tolerance 0.001 mm"),
            "{json}"
        );
    }
}
