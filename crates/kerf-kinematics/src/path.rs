//! Solving a whole path: continuous axes within the limits, the pole, rotary steps and the
//! non-linearity error.
//!
//! For each cutting point, in order, kerf takes both inverse solutions `(t, C)` and
//! `(-t, C + 180)`, moves each rotary angle by the multiple of 360 degrees nearest the previous
//! point's (continuity), and prefers the one with the least rotary travel
//! `|d tilt| + |d C|`. If the preferred one leaves the axis limits, the other is used, but only
//! if the move to it is continuous: the tool axis at the middle of the linear axis move must
//! stay within the angle between the two poses of the great-circle midpoint. (The other
//! solution of a pose far from the pole is a jump: the head would swing through the pole and
//! back while the laser cuts.) If neither fits, the error names the path, the point and the
//! axis the preferred solution violates.
//!
//! Where C is free (the first point of a path, which has no predecessor, and the first point
//! after the pole), every solution and every turn within the limits is a candidate, tried in
//! order of rotary travel (from the machine's zero, tilt 0 and C 0, at the start; from the pole
//! point when leaving the pole): the first whose continuation over the cutting points up to
//! the next pole point (or the end) stays within the limits is taken. So a C axis limited to
//! `[-400, 400]` starts a 700-degree spiral at -350 rather than failing at 400, and a trunnion
//! whose A only goes to -10 degrees turns C by 180 at the pole instead of tilting the wrong
//! way. A path that starts at the pole starts with the C it leaves the pole with.
//!
//! **The pole.** A pose whose tool axis is within `pole_tolerance_deg` of the C axis keeps the
//! previous C; its tilt is the one bringing the tool axis closest to the pose's, and X, Y, Z
//! put the tip exactly on the point. The tool axis is then off by at most `pole_tolerance_deg`;
//! [`SolvedPath::pole_tip_error`] reports `pivot_length * angle`: the tip error that angle
//! would cause had X, Y, Z been computed for the requested tool axis instead (kerf re-places
//! the tip, so what remains is the orientation error `angle`). Leaving the pole in a direction other than the kept C needs C to
//! turn: kerf turns it at the last pole point (repeated with the new C, split like any other
//! move), so that the tool axis never swings off the path.
//!
//! **Rotary steps.** Near the pole C moves as `1/sin(tilt)` for a given change of the tool
//! axis. Every move whose rotary step `max(|d tilt|, |d C|)` exceeds `max_rotary_step_deg`, and
//! every move whose non-linearity error ([`crate::nonlinear`]) exceeds
//! `linearization_tolerance_mm`, is split by inserting poses: the position on the curve when the
//! path has one ([`PathCurve`]), else on the straight segment; the tool axis on the great
//! circle ([`crate::nonlinear::slerp`]). Inserted poses are solved with the same continuity
//! rule, and split again if needed.

use rayon::prelude::*;

use crate::error::{KinematicsError, Result};
use crate::machine::Machine;
use crate::pose::{Axes, Pose};
use crate::tilt::{tilt_within_cone, TiltReport};

mod walk;

use walk::Ctx;

/// Slack allowed on the axis limits (mm or degrees), so that a value computed as
/// `360.0000000000001` for a limit of 360 still fits.
pub const LIMIT_SLACK: f64 = 1e-9;

/// How far from 1 the length of a tool axis may be before a pose is refused (normals written
/// with 6 decimals are within this).
pub const UNIT_AXIS_TOLERANCE: f64 = 1e-6;

/// The most poses one split may insert at once (larger splits happen in several rounds).
pub(super) const MAX_PIECES: f64 = 1024.0;

/// The default pole tolerance of [`PathOptions::pole_tolerance_deg`]: 1e-6 rad in degrees
/// (a tool axis this close to the C axis is at the pole; `docs/formats.md`).
pub const DEFAULT_POLE_TOLERANCE_DEG: f64 = 1e-6 * (180.0 / std::f64::consts::PI);

/// Options of [`solve_path`].
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct PathOptions {
    /// A pose whose tool axis is within this angle (degrees) of the C axis is at the pole: C
    /// keeps its previous value. Finite and >= 0; default [`DEFAULT_POLE_TOLERANCE_DEG`]
    /// (1e-6 rad).
    pub pole_tolerance_deg: f64,
    /// The largest move of a rotary axis between two points (degrees); longer moves are
    /// split. > 0; default `f64::INFINITY` (no limit).
    pub max_rotary_step_deg: f64,
    /// The largest non-linearity error (mm) of a move; moves with more are split. > 0;
    /// `f64::INFINITY` turns the insertion off. Default 0.005.
    pub linearization_tolerance_mm: f64,
    /// Refuse a path that needs more inserted points than this (protects against a tolerance
    /// typed in the wrong unit). Default 1,000,000.
    pub max_inserted: usize,
    /// The tilt tolerance (degrees): the tool axis may deviate this much from each pose's
    /// axis (its surface normal) so that the rotary axes move least ([`crate::tilt_within_cone`]).
    /// In `[0, MAX_TILT_TOLERANCE_DEG]`; 0 (the default here) keeps the normals exactly.
    pub tilt_tolerance_deg: f64,
}

/// The largest tilt tolerance (degrees): beyond it the beam no longer cuts the edge the CAD
/// model draws (a 10-degree tilt puts the bottom edge of a 2 mm sheet 0.35 mm off).
pub const MAX_TILT_TOLERANCE_DEG: f64 = 10.0;

impl Default for PathOptions {
    fn default() -> Self {
        Self {
            pole_tolerance_deg: DEFAULT_POLE_TOLERANCE_DEG,
            max_rotary_step_deg: f64::INFINITY,
            linearization_tolerance_mm: 0.005,
            max_inserted: 1_000_000,
            tilt_tolerance_deg: 0.0,
        }
    }
}

impl PathOptions {
    /// Sets [`pole_tolerance_deg`](Self::pole_tolerance_deg): a pose whose tool axis is
    /// within this angle (degrees) of the C axis is at the pole.
    pub fn with_pole_tolerance_deg(mut self, pole_tolerance_deg: f64) -> Self {
        self.pole_tolerance_deg = pole_tolerance_deg;
        self
    }

    /// Sets [`max_rotary_step_deg`](Self::max_rotary_step_deg): the largest move of a
    /// rotary axis between two points (degrees).
    pub fn with_max_rotary_step_deg(mut self, max_rotary_step_deg: f64) -> Self {
        self.max_rotary_step_deg = max_rotary_step_deg;
        self
    }

    /// Sets [`linearization_tolerance_mm`](Self::linearization_tolerance_mm): the largest
    /// non-linearity error (mm) of a move.
    pub fn with_linearization_tolerance_mm(mut self, linearization_tolerance_mm: f64) -> Self {
        self.linearization_tolerance_mm = linearization_tolerance_mm;
        self
    }

    /// Sets [`max_inserted`](Self::max_inserted): refuse a path that needs more inserted
    /// points than this (protects against a tolerance typed in the wrong unit).
    pub fn with_max_inserted(mut self, max_inserted: usize) -> Self {
        self.max_inserted = max_inserted;
        self
    }

    /// Sets [`tilt_tolerance_deg`](Self::tilt_tolerance_deg): how far (degrees) the tool axis
    /// may deviate from the surface normal to save rotary motion.
    pub fn with_tilt_tolerance_deg(mut self, tilt_tolerance_deg: f64) -> Self {
        self.tilt_tolerance_deg = tilt_tolerance_deg;
        self
    }

    /// Checks every option.
    ///
    /// # Errors
    /// [`KinematicsError::BadOption`] naming the first bad option.
    pub fn validate(&self) -> Result<()> {
        let bad = |name, value, reason| {
            Err(KinematicsError::BadOption {
                name,
                value,
                reason,
            })
        };
        if !(self.pole_tolerance_deg.is_finite() && self.pole_tolerance_deg >= 0.0) {
            return bad(
                "pole_tolerance_deg",
                self.pole_tolerance_deg,
                "must be finite and >= 0 (degrees)",
            );
        }
        if self.max_rotary_step_deg.is_nan() || self.max_rotary_step_deg <= 0.0 {
            return bad(
                "max_rotary_step_deg",
                self.max_rotary_step_deg,
                "must be > 0 (degrees; infinity for no limit)",
            );
        }
        if self.linearization_tolerance_mm.is_nan() || self.linearization_tolerance_mm <= 0.0 {
            return bad(
                "linearization_tolerance_mm",
                self.linearization_tolerance_mm,
                "must be > 0 (mm; infinity to insert no points)",
            );
        }
        if !(0.0..=MAX_TILT_TOLERANCE_DEG).contains(&self.tilt_tolerance_deg) {
            return bad(
                "tilt_tolerance_deg",
                self.tilt_tolerance_deg,
                "must be in [0, 10] (degrees)",
            );
        }
        Ok(())
    }
}

/// The curve a path was discretized from, so that inserted points lie on it.
#[derive(Clone, Copy)]
pub struct PathCurve<'a> {
    /// The curve parameter of each cutting point (`params` of `kerf.toolpath/1`); strictly
    /// increasing, one per pose.
    pub params: &'a [f64],
    /// The curve point at a parameter (any [`kerf_nurbs::CurvePoint`]: a NURBS curve, a
    /// closure, a placed or offset contour).
    pub point: &'a (dyn kerf_nurbs::CurvePoint + Sync),
}

impl std::fmt::Debug for PathCurve<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("PathCurve")
            .field("params", &self.params)
            .finish_non_exhaustive()
    }
}

/// One path to solve.
#[derive(Debug, Clone, Copy)]
pub struct PathInput<'a> {
    /// The path's id (for messages and the output).
    pub id: &'a str,
    /// The cutting points with their tool axes.
    pub poses: &'a [Pose],
    /// The curve, if known; else inserted points go on the straight segments.
    pub curve: Option<PathCurve<'a>>,
}

/// A solved path: the axes for every cutting point and every inserted point.
#[derive(Debug, Clone, PartialEq)]
pub struct SolvedPath {
    /// The path's id.
    pub id: String,
    /// The poses: the cutting points (tool axes normalised) and the inserted points, in path
    /// order.
    pub poses: Vec<Pose>,
    /// `axes[n]` puts the tool at `poses[n]` (exactly for the tip; within the pole tolerance
    /// for the tool axis at the pole).
    pub axes: Vec<Axes>,
    /// For each point, the index of the cutting point it is, or `None` if inserted.
    pub source: Vec<Option<usize>>,
    /// The number of inserted points (`poses.len()` minus the cutting points).
    pub inserted: usize,
    /// How many of them were inserted to keep rotary steps within `max_rotary_step_deg`
    /// (including the C turns at the pole).
    pub inserted_for_rotary_step: usize,
    /// How many were inserted against the non-linearity error.
    pub inserted_for_linearization: usize,
    /// The largest rotary move `max(|d tilt|, |d C|)` between two neighbouring cutting points
    /// (degrees): what one segment of the toolpath asks of the rotary axes, however it was
    /// split.
    pub max_rotary_step_between_cutting_points: f64,
    /// The largest rotary step between two neighbouring points of the output (degrees).
    pub max_rotary_step: f64,
    /// The largest non-linearity error of a move of the output (mm, estimated).
    pub max_linearization_error: f64,
    /// The number of points (cutting or inserted) at the pole.
    pub pole_points: usize,
    /// The largest `pivot_length * angle` over the pole points, `angle` being the angle
    /// between the pose's tool axis and the one the axes give (mm).
    pub pole_tip_error: f64,
    /// What the tilt tolerance did, when one was in force: the largest angle between a
    /// chosen tool axis and the surface normal (`max_deviation_at` indexes the cutting
    /// points) and the rotary travel with and without it. `None` with a tolerance of 0.
    pub tilt: Option<TiltReport>,
}

impl SolvedPath {
    /// The axis vectors `[X, Y, Z, tilt, C]`.
    pub fn positions(&self) -> Vec<[f64; 5]> {
        self.axes.iter().map(Axes::to_array).collect()
    }
}

/// Solves every path (in parallel; the result does not depend on the number of threads).
///
/// # Errors
/// The error of the first path (in input order) that fails; see [`solve_path`].
pub fn solve_paths(
    machine: &Machine,
    paths: &[PathInput<'_>],
    options: &PathOptions,
) -> Result<Vec<SolvedPath>> {
    options.validate()?;
    let results: Vec<Result<SolvedPath>> = paths
        .par_iter()
        .map(|p| solve_path(machine, p, options))
        .collect();
    results.into_iter().collect()
}

/// Solves one path: continuous axes within the limits, poses inserted against large rotary
/// steps and the non-linearity error (see the module documentation).
///
/// # Errors
/// [`KinematicsError::BadOption`], [`KinematicsError::BadPose`] (a non-finite value, a tool
/// axis not of unit length, params not matching the poses), [`KinematicsError::OutOfLimits`],
/// [`KinematicsError::Discontinuity`], [`KinematicsError::TooManyInserted`].
pub fn solve_path(
    machine: &Machine,
    input: &PathInput<'_>,
    options: &PathOptions,
) -> Result<SolvedPath> {
    options.validate()?;
    let mut poses = checked_poses(input)?;
    let mut tilt = None;
    if options.tilt_tolerance_deg > 0.0 {
        let choice = tilt_within_cone(&poses, options.tilt_tolerance_deg);
        for (pose, axis) in poses.iter_mut().zip(&choice.axes) {
            pose.axis = *axis;
        }
        tilt = Some(choice.report);
    }
    let ctx = Ctx {
        machine,
        kin: machine.kinematics.as_ref(),
        options,
        id: input.id,
        poses: &poses,
        curve: input.curve,
    };
    if poses.is_empty() {
        return Ok(ctx.empty());
    }
    let mut solved = ctx.walk()?;
    solved.tilt = tilt;
    Ok(solved)
}

/// Checks the poses (finite, unit tool axes) and the curve's params; returns the poses with
/// normalised axes.
fn checked_poses(input: &PathInput<'_>) -> Result<Vec<Pose>> {
    let bad = |index, reason: String| KinematicsError::BadPose {
        path_id: input.id.to_owned(),
        index,
        reason,
    };
    let mut out = Vec::with_capacity(input.poses.len());
    for (n, pose) in input.poses.iter().enumerate() {
        if let Some(v) = pose.to_array().into_iter().find(|v| !v.is_finite()) {
            return Err(bad(n, format!("the pose holds a non-finite value ({v})")));
        }
        let norm = pose.axis.norm();
        if (norm - 1.0).abs() > UNIT_AXIS_TOLERANCE {
            return Err(bad(
                n,
                format!("the tool axis has length {norm}, not 1 (a toolpath without normals?)"),
            ));
        }
        out.push(Pose {
            position: pose.position,
            axis: pose.axis / norm,
        });
    }
    if let Some(curve) = &input.curve {
        if curve.params.len() != out.len() {
            return Err(bad(
                0,
                format!(
                    "{} params for {} poses (one param per pose)",
                    curve.params.len(),
                    out.len()
                ),
            ));
        }
        for (n, &t) in curve.params.iter().enumerate() {
            if !t.is_finite() || (n > 0 && t <= curve.params[n - 1]) {
                return Err(bad(
                    n,
                    format!("param {t} is not finite or not above the previous one"),
                ));
            }
        }
    }
    Ok(out)
}
