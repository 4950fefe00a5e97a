//! The error type of the interpolator.

use thiserror::Error;

/// What can go wrong when interpolating, planning or writing a program.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum InterpError {
    /// A parameter is out of range: NaN, infinite, zero or negative where a positive finite value
    /// is needed (feed, cycle time, tolerance, limit). Fix: pass a finite positive value; the
    /// parameter's documentation gives its unit.
    #[error("{name}: {reason} (got {value})")]
    BadParameter {
        /// The parameter's name.
        name: &'static str,
        /// The value given.
        value: f64,
        /// What is wrong with it.
        reason: &'static str,
    },
    /// A point or axis vector holds NaN or an infinite coordinate. Fix: check the input file
    /// (the index counts points from 0 within the path).
    #[error("point {index}: non-finite coordinate")]
    NonFinite {
        /// Index of the offending point.
        index: usize,
    },
    /// The three points of a space arc are collinear or two of them coincide, so no circle
    /// passes through them. [`crate::Block::arc_or_line`] falls back to a line instead; fix for
    /// [`crate::SpaceArc::through`]: give three distinct, non-collinear points.
    #[error("arc points are collinear or coincide (|P1P2 x P2P3| = {cross:e} mm^2)")]
    CollinearArc {
        /// Norm of the cross product of the two chords.
        cross: f64,
    },
    /// A path has fewer points than the operation needs (1 for interpolation, 2 for a spline).
    /// Fix: drop the path or give it more points.
    #[error("path has {got} point(s), needs at least {need}")]
    TooFewPoints {
        /// Points given.
        got: usize,
        /// Points needed.
        need: usize,
    },
    /// Two parallel arrays (points and their parameters or axes) differ in length. Fix: give
    /// one entry per point.
    #[error("{what}: {got} entries for {expected} points")]
    LengthMismatch {
        /// Which array.
        what: &'static str,
        /// Its length.
        got: usize,
        /// The number of points.
        expected: usize,
    },
    /// The machine model could not reach a pose (inverse kinematics failed: outside the axis
    /// ranges, or not a unit tool axis). Fix: see the message from the kinematics.
    #[error("point {index}: kinematics: {source}")]
    Kinematics {
        /// Index of the pose within its path.
        index: usize,
        /// The kinematics' own error (boxed, so that no `Result` of the interpolator or of the
        /// pipeline grows by its size).
        #[source]
        source: kerf_kinematics::BoxedKinematicsError,
    },
    /// An interpolated set-point leaves an axis range of the machine (an arc bulging past a
    /// limit between two reachable points). Fix: move the part, or interpolate lines only
    /// ([`crate::FitOptions::arcs`] = false).
    #[error("cycle {cycle}: axis {axis} = {value} outside its range [{min}, {max}]")]
    OutOfRange {
        /// Cycle index of the set-point.
        cycle: usize,
        /// Axis name.
        axis: String,
        /// The set-point value.
        value: f64,
        /// Lower limit.
        min: f64,
        /// Upper limit.
        max: f64,
    },
    /// A pierce point, `pierce_standoff` above a cut's start along the tool axis, puts an axis
    /// outside its range (the cut itself is within them). Fix: a smaller `pierce_standoff` in
    /// the machine's `process`, or place the part farther from that limit.
    #[error(
        "path {path}: the pierce point {standoff_mm} mm above the cut's start puts {axis} at {value}, outside its range [{min}, {max}]"
    )]
    PierceOutOfRange {
        /// Index of the path whose cut it starts.
        path: usize,
        /// The pierce standoff, mm.
        standoff_mm: f64,
        /// Axis name.
        axis: String,
        /// The axis value at the pierce point.
        value: f64,
        /// Lower limit.
        min: f64,
        /// Upper limit.
        max: f64,
    },
    /// The retract after the program's last cut (along the tool axis, the larger of
    /// `pierce_standoff` and [`crate::EXIT_RETRACT_MIN_MM`]) puts an axis outside its range.
    /// The program ends with that move so that a beam-off synchronized with motion (LinuxCNC
    /// `M63`) takes effect. Fix: place the part farther from that limit.
    #[error(
        "path {path}: the retract of {retract_mm} mm along the tool axis after the last cut puts {axis} at {value}, outside its range [{min}, {max}]"
    )]
    RetractOutOfRange {
        /// Index of the path whose cut it ends.
        path: usize,
        /// The retract, mm.
        retract_mm: f64,
        /// Axis name.
        axis: String,
        /// The axis value at the retract's end.
        value: f64,
        /// Lower limit.
        min: f64,
        /// Upper limit.
        max: f64,
    },
    /// The feed plan did not bring every axis within its velocity, acceleration and jerk
    /// limits within [`crate::PlanOptions::max_refinements`] rounds of slowing the offending
    /// windows (each round slows harder, so a motion that slowing can bring within the limits
    /// is found well before): the path cannot be followed at any speed there, e.g. a jump of
    /// the axes between two poses, or limits so small against the cycle that the set-points'
    /// rounding exceeds them. Fix: check the poses around the block named and the machine's
    /// limits against the cycle.
    #[error(
        "feed plan: axis {axis} exceeds its {what} limit at cycle {cycle} (t = {time_s} s, block {block} of path {path}: {value} > {limit}) after {refinements} rounds of slowing it"
    )]
    LimitsNotMet {
        /// Axis name.
        axis: String,
        /// "velocity", "acceleration" or "jerk".
        what: &'static str,
        /// Cycle index.
        cycle: usize,
        /// Program time of the cycle, s.
        time_s: f64,
        /// Index of the block (of the planned program) the cycle falls in.
        block: usize,
        /// Index of that block's path.
        path: usize,
        /// Measured value (per second, second squared or second cubed).
        value: f64,
        /// The limit.
        limit: f64,
        /// The rounds of slowing done.
        refinements: usize,
    },
    /// The program would have more cycles than [`crate::PlanOptions::max_cycles`]: refused
    /// before any planning when even a lower bound of its time (its tip travel at the feed,
    /// each axis' travel at its velocity limit) is too long, else as soon as the plan is
    /// timed, before the set-points are computed. Fix: raise the feed or the cycle time, or
    /// raise the limit.
    #[error("program needs {cycles:.0} cycles, more than the limit {limit}")]
    TooManyCycles {
        /// Cycles needed: the plan's, or the lower bound's when refused before planning.
        cycles: f64,
        /// The limit.
        limit: usize,
    },
    /// Writing an output file failed. Fix: check that the directory exists and is writable.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: String,
        /// The operating system's error (its [`std::io::Error`] is the source of this one).
        #[source]
        source: kerf_kinematics::IoError,
    },
    /// The laser process codes given to the G-code writer are unusable (the message names the
    /// key, as `process.beam_on[0]: must not be empty`). Fix: correct the `process` object of
    /// the machine file.
    #[error("{0}")]
    Process(#[source] kerf_kinematics::BoxedKinematicsError),
    /// A program for a dialect whose blocks join neighbouring poses only holds an arc or a line
    /// merged over several poses: the raw-axis dialects (`generic`, `linuxcnc`: the controller
    /// interpolates every axis linearly, so the chords would move the rotary axes in steps the
    /// kinematics never checked against the linearization tolerance) and the tool-tip dialects
    /// that interpolate the rotary axes or the tool direction linearly in each block
    /// (`linuxcnc-tcp`, `fanuc`, `fanuc-ijk`, `heidenhain`, `heidenhain-axes`: the tool axis
    /// would leave the poses). Fix: fit
    /// the blocks with `arcs` and `merge_lines` off for such dialects
    /// (`kerf_pipeline::fit_options` does), or use Sinumerik TRAORI.
    #[error(
        "{dialect} programs join neighbouring poses only, but block {block} is {what}: fit the motion with arcs and merged lines off for this dialect"
    )]
    UncheckedBlock {
        /// The dialect's name.
        dialect: &'static str,
        /// Index of the block.
        block: usize,
        /// `an arc` or `a line merged over N poses`.
        what: String,
    },
    /// A rapid of a tool-tip dialect turns the rotary axes so far from the tip (many turns of
    /// C far from its axis) that [`crate::RAPID_TCP_MAX_PIECES`] straight `G0` pieces of the
    /// tip still leave the joint-space traverse kerf checked by more than
    /// [`crate::RAPID_TCP_TOLERANCE_MM`]. Fix: place the part nearer the C axis, or use the
    /// joint-space dialect of the controller.
    #[error("{dialect}: a rapid needs more than {pieces} G0 pieces to stay within {tolerance_mm} mm of its checked traverse ({deviation_mm:.3} mm with {pieces})")]
    RapidTooCurved {
        /// The dialect's name.
        dialect: &'static str,
        /// The pieces tried.
        pieces: usize,
        /// The largest distance of a piece's middle from the traverse, mm.
        deviation_mm: f64,
        /// The tolerance, mm.
        tolerance_mm: f64,
    },
    /// The dialect programs the tool tip for a controller that runs its own kinematics, and
    /// that controller has none that computes this machine as kerf does (or the model is not
    /// a `kerf.machine/1` machine). Fix: the reason names the mismatch; use a joint-space
    /// dialect for such a machine.
    #[error("dialect {dialect}: {reason}")]
    DialectMachine {
        /// The dialect's name.
        dialect: &'static str,
        /// What does not match.
        reason: String,
    },
    /// The controller's kerf compensation is switched on for a path whose first cutting
    /// block (the lead-in's first move, the controller's entry move) was fitted as an arc:
    /// LinuxCNC and Sinumerik select their compensation on a line. Fix: give the lead-in a
    /// straight start, or compensate in the computer.
    #[error("{path}: the controller's kerf compensation is switched on for the lead-in's first move, which was fitted as an arc; the controllers select it on a line: give the lead-in a straight start or compensate in the computer")]
    CompensationOnArc {
        /// The path's id (its curve's).
        path: String,
    },
}

impl InterpError {
    /// A [`InterpError::Kinematics`] at point 0 (callers that know the point set the index)
    /// for a pose the point-wise inverse cannot solve.
    pub(crate) fn unreachable(reason: impl Into<String>) -> Self {
        InterpError::Kinematics {
            index: 0,
            source: kerf_kinematics::KinematicsError::Unreachable {
                reason: reason.into(),
            }
            .into(),
        }
    }
}

/// `Result` with [`InterpError`].
pub type Result<T> = std::result::Result<T, InterpError>;

/// Checks that `value` is finite and > 0.
pub(crate) fn positive(name: &'static str, value: f64) -> Result<f64> {
    if !value.is_finite() {
        return Err(InterpError::BadParameter {
            name,
            value,
            reason: "must be finite",
        });
    }
    if value <= 0.0 {
        return Err(InterpError::BadParameter {
            name,
            value,
            reason: "must be > 0",
        });
    }
    Ok(value)
}

/// Every factor of `factors` (per path) within (0, 1].
pub(crate) fn unit_factors(name: &'static str, factors: &[f64]) -> Result<()> {
    match factors
        .iter()
        .find(|f| !(f.is_finite() && **f > 0.0 && **f <= 1.0))
    {
        Some(f) => Err(InterpError::BadParameter {
            name,
            value: *f,
            reason: "each path's factor must lie in (0, 1]",
        }),
        None => Ok(()),
    }
}
