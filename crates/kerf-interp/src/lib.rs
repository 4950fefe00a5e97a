//! The interpolator of kerf: cutting points to motion, cycle by cycle, and to G-code.
//!
//! The last stage of the pipeline. A path's cutting points (poses with their machine axes,
//! [`Station`]s from [`solve_stations`] or from a `kerf.axes/1` file) become a program:
//!
//! 1. [`fit_blocks`]: runs of points become space arcs (or long lines) where the block stays
//!    within the tolerance of the points and of the curve; [`BlockCounts`] counts them.
//! 2. [`plan()`]: the time-optimal feed along a smooth interpolant of the poses between true
//!    corners, such that no axis exceeds its velocity, acceleration or (with
//!    [`AxisLimits::max_jerk`]) jerk limit in any cycle, stopping at the end;
//!    [`Motion::cycles`] is the program's cycle count, [`Motion::path_stats`] the time per path.
//! 3. [`Motion::iter`]: the set-points, one per interpolation cycle: the tip and the rotary
//!    axes on the smooth path through the blocks' points (exactly the stations' axes where the
//!    machine is at rest), the linear axes from the machine model (eq 16 for paper 000's head,
//!    [`AxisModel`] in general). [`Block::constant_feed`] keeps paper 000's own interpolation
//!    of one block (eq 3-12).
//! 4. [`write_csv`], [`gcode`]: the set-points CSV of `formats.md`, and G-code in every
//!    [`Dialect`]: generic, LinuxCNC (joint space and tool tip), Sinumerik, Fanuc (G43.4 and
//!    G43.5) and HEIDENHAIN (LN and axis blocks).
//!
//! The machine is any [`AxisModel`]: [`MachineModel`] for kerf's `kerf.machine/1` machines
//! (all four types, from `kerf-kinematics`; [`stations_from_solved`] takes its solved paths),
//! [`PaperAcHead`] as a small self-contained reference (paper 000's head).
//!
//! [`Block::constant_feed`] is paper 000's interpolator of one block at constant feed. Paper
//! 001's recursive spline interpolator (`NewBasisSegment`, `spline_setpoints`) and paper 000's
//! eq 19 (`paper_eq19`) are research code behind the cargo feature `research`. The maths, the tolerance budget
//! and the measured figures are in `docs/interpolation.md`.
//!
//! ```
//! use kerf_interp::{fit_blocks, plan, solve_stations, PaperAcHead, FitOptions, PlanOptions};
//! use nalgebra::{Point3, Vector3};
//!
//! let machine = PaperAcHead::paper_000();
//! // A half circle of radius 20 mm, tool vertical, 41 cutting points (chord error 0.0154 mm).
//! let tips: Vec<Point3<f64>> = (0..=40)
//!     .map(|i| {
//!         let a = std::f64::consts::PI * i as f64 / 40.0;
//!         Point3::new(20.0 * a.cos(), 20.0 * a.sin(), 0.0)
//!     })
//!     .collect();
//! let stations = solve_stations(&machine, &tips, None, None, None)?;
//! let blocks = fit_blocks(&machine, &stations, None, 0, &FitOptions::with_tolerance(0.02))?;
//! assert_eq!(blocks.len(), 1, "one arc");
//! let motion = plan(&machine, &blocks, &PlanOptions::new(6000.0, 0.001))?;
//! let rows = motion.setpoints(&machine);
//! assert_eq!(rows.len(), motion.cycles() + 1);
//! assert_eq!(*rows.last().unwrap(), stations[40].axes, "ends exactly on the last point");
//! # Ok::<(), kerf_interp::InterpError>(())
//! ```

mod block;
mod chord;
mod error;
mod fit;
mod geometry;
mod machine;
mod model;
mod output;
mod plan;
#[cfg(feature = "research")]
mod recursive;
pub(crate) mod smooth;
pub(crate) mod topp;

pub use block::{increments, solve_stations, starts_cut, Block, Geometry, Station, MIN_TRAVEL};
#[cfg(feature = "research")]
pub use chord::paper_eq19;
pub use chord::{chord_error, max_feed, max_step};
pub use error::{InterpError, Result};
pub use fit::{fit_blocks, BlockCounts, CurveFn, FitOptions};
pub use geometry::SpaceArc;
pub use machine::{stations_from_axes, stations_from_solved, MachineModel};
pub use model::{AxisLimits, AxisModel, PaperAcHead, RANGE_SLACK};
pub use output::{comment_text, write_atomic, MAX_COMMENT};

/// The default controller-blending term (the planner's and the G-code writer's, so it lives
/// at the root, used by both) of the tolerance budget, mm: LinuxCNC's `G64 P`,
/// Sinumerik's `CTOL` plus the tip error of `OTOL`.
pub const DEFAULT_BLEND_TOLERANCE: f64 = 0.005;

/// The shortest retract (mm, along the tool axis) that ends a program whose last block is a
/// cut: a real move after the last beam-off, which a beam-off synchronized with motion needs.
pub const EXIT_RETRACT_MIN_MM: f64 = 1.0;

pub use output::{
    csv_string, gcode, gcode_motion, gcode_timed, linuxcnc_kinematics, write_csv, write_csv_to,
    write_gcode, ChordTerm, CutterCompensation, Dialect, GcodeOptions, LaserPower,
    LinuxcncKinematics, ProcessCodes, RAPID_TCP_MAX_PIECES, RAPID_TCP_MAX_STEP_DEG,
    RAPID_TCP_TOLERANCE_MM,
};
pub use plan::{
    link_paths, link_paths_through, link_paths_with_retract, plan, plan_owned, CornerSlowdown,
    Cycles, Motion, PathStats, PlanOptions, PlanWork,
};
pub use plan::{ACCELERATION_MARGIN, JERK_CROSS_SHARE, JERK_FILTER_WIDTH, JERK_STATIC_SHARE};
#[cfg(feature = "research")]
pub use recursive::{
    max_deviation, new_basis_coefficients, spline_setpoints, spline_through, CubicHermite,
    ForwardDifferences, NewBasisSegment, Recurrence, RecurrenceSteps, OMEGA,
};

/// One path of a program (the interpolator's input; `kerf_kinematics::PathInput` is the inverse
/// solver's): its id (the source curve's), its stations and, when known, the
/// curve itself.
pub struct ProgramPath<'a> {
    /// The id of the source curve (written in G-code comments).
    pub id: String,
    /// The cutting points with their machine axes.
    pub stations: Vec<Station>,
    /// The curve point at a parameter, for the arc fit's curve test (`None`: the polyline
    /// stands in for the curve).
    pub curve: Option<CurveFn<'a>>,
}

impl std::fmt::Debug for ProgramPath<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("ProgramPath")
            .field("id", &self.id)
            .field("stations", &self.stations.len())
            .field("curve", &self.curve.is_some())
            .finish()
    }
}

/// Fits every path ([`fit_blocks`], path `n` numbered `n`) and links them with rapid moves
/// ([`link_paths`]): the blocks of one program, ready for [`plan()`] and [`gcode`]. Paths with a
/// single point give no block.
///
/// # Errors
/// As [`fit_blocks`].
pub fn fit_program<M: AxisModel + ?Sized>(
    model: &M,
    paths: &[ProgramPath<'_>],
    opts: &FitOptions,
) -> Result<Vec<Block>> {
    let mut all = Vec::with_capacity(paths.len());
    for (n, p) in paths.iter().enumerate() {
        all.push(fit_blocks(model, &p.stations, p.curve, n, opts)?);
    }
    Ok(plan::link_paths_with_retract(model, all, opts.retract_mm))
}

/// [`interpolate`] with the rapid moves between consecutive paths running through the given
/// waypoints ([`link_paths_through`]; `traverses[k]` lies between `paths[k]` and
/// `paths[k + 1]`).
///
/// # Errors
/// As [`interpolate`].
pub fn interpolate_through<M: AxisModel + ?Sized>(
    model: &M,
    paths: &[ProgramPath<'_>],
    traverses: &[Vec<Station>],
    fit: &FitOptions,
    plan_options: &PlanOptions,
) -> Result<Motion> {
    let mut all = Vec::with_capacity(paths.len());
    for (n, p) in paths.iter().enumerate() {
        all.push(fit_blocks(model, &p.stations, p.curve, n, fit)?);
    }
    let blocks = plan::link_paths_through(model, all, traverses, fit.retract_mm);
    plan::plan_owned(model, blocks, plan_options)
}

/// What `kerf interpolate` does once its inputs are read: [`fit_program`] then [`plan()`].
/// The returned [`Motion`] has the blocks ([`Motion::blocks`], [`Motion::counts`]), the program's
/// cycle count ([`Motion::cycles`]) and the set-points ([`Motion::setpoints`], [`Motion::iter`]).
///
/// # Errors
/// As [`fit_blocks`] and [`plan()`].
pub fn interpolate<M: AxisModel + ?Sized>(
    model: &M,
    paths: &[ProgramPath<'_>],
    fit: &FitOptions,
    plan_options: &PlanOptions,
) -> Result<Motion> {
    let blocks = fit_program(model, paths, fit)?;
    plan::plan_owned(model, blocks, plan_options)
}
