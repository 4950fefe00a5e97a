//! What [`super::check`] reports: per-path measurements, the worst segment and every
//! violation with its [`Defect`].

use std::fmt;

use serde::Serialize;
use serde_json::{json, Value};

/// The result of [`check`](crate::check): what was measured per path, and every violation found.
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
    /// What the check of the path's `kerf_offset` found, if it has one.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub kerf_offset: Option<OffsetReport>,
}

/// The check of a path's `kerf_offset` ([`crate::check()`]).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct OffsetReport {
    /// Half the kerf the file states, mm.
    pub offset_mm: f64,
    /// The number of offset points.
    pub points: usize,
    /// Chords measured against the exact offset (the curve's offset, or the arc about a
    /// corner).
    pub segments: usize,
    /// Chords that cross an inside corner or a rounding tighter than the offset, where the path
    /// was cut back: measured for the gouge only (the exact offset there runs into the part).
    pub cut_backs: usize,
    /// The largest measured distance from the exact offset to its chord, mm.
    pub max_chord_error: f64,
    /// The smallest distance from the path (its points and 8 points along each chord) to the
    /// curve, mm: at least the offset less the tolerance where the beam's edge stays out of
    /// the part.
    pub min_distance_from_curve: f64,
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
    /// The `kerf_offset` breaks a rule of its shape ([`kerf_format::KerfOffset::validate`]).
    OffsetShape {
        /// What is wrong.
        reason: String,
    },
    /// A chord of the `kerf_offset` lies farther than the tolerance from the exact offset.
    OffsetChordError {
        /// The chord's index in the offset.
        segment: usize,
        /// The measured distance, mm.
        error: f64,
        /// The tolerance, mm.
        tolerance: f64,
    },
    /// The `kerf_offset` comes closer to the curve than the offset less the tolerance: the
    /// beam's edge would cut into the part there.
    OffsetGouge {
        /// Where, mm.
        at: [f64; 3],
        /// Its distance from the curve, mm.
        distance: f64,
        /// The least distance allowed (offset less tolerance), mm.
        least: f64,
    },
    /// The `kerf_offset`'s `max_chord_error` is below a measured chord's.
    OffsetClaimUnderstated {
        /// The claimed value, mm.
        claimed: f64,
        /// The measured maximum, mm.
        measured: f64,
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
            Defect::OffsetShape { reason } => write!(f, "kerf_offset: {reason}"),
            Defect::OffsetChordError {
                segment,
                error,
                tolerance,
            } => write!(
                f,
                "kerf_offset: chord {segment} is {error:.6e} mm from the exact offset > tolerance {tolerance} mm"
            ),
            Defect::OffsetGouge {
                at,
                distance,
                least,
            } => write!(
                f,
                "kerf_offset: at ({:.4}, {:.4}, {:.4}) the path is {distance:.6} mm from the curve, less than {least:.6} mm: the beam's edge cuts into the part",
                at[0], at[1], at[2]
            ),
            Defect::OffsetClaimUnderstated { claimed, measured } => write!(
                f,
                "kerf_offset.max_chord_error: claims {claimed:.6e} mm but a chord measures {measured:.6e} mm"
            ),
        }
    }
}
