//! The whole kerf pipeline as a library: a [`Job`] of curves, surfaces and a machine, run in
//! memory from cutting points to G-code, every stage's result returned ([`Output`]) and any
//! failure one [`Error`] that keeps the stage's own error and names the file and the curve.
//!
//! The stages, in order (each a crate of its own, used here through its public API):
//!
//! 1. [`discretize_curves`]: cutting points with a certified chord error (`kerf-discretize`).
//! 2. [`orient_curves`]: the surface normal of every point, one normal source per surface,
//!    +z for curves without a surface (`kerf-normals`); [`toolpath_of_poses`] makes the
//!    `kerf.toolpath/1` document.
//! 3. [`place`]: where the part goes on the machine ([`PlaceMode`]); the cuts with their start
//!    points, lead-ins and lead-outs (`kerf-process`); the machine axes (`kerf-kinematics`).
//! 4. The motion, one program per set-up: fitted blocks, the feed plan, set-points and G-code
//!    (`kerf-interp`). The fit follows from the dialect ([`fit_options`]): a program that
//!    gives raw machine axes never gets unchecked arc chords or merged lines.
//! 5. The 3D view's scene (`kerf-view`), the report and the picture (`kerf-plot`).
//!
//! [`Job::run`] chains them; [`Output::write_dir`] writes `toolpath.json`, `axes.json`,
//! `program.nc`, `setpoints.csv`, `report.json`, `plot.svg` and `view.html` into a directory all or
//! nothing, and every part can be written to any [`std::io::Write`]. [`plan_program`] is the
//! motion stage alone, on a `kerf.axes/1` or `kerf.toolpath/1` document ([`MotionInput`]).
//! The `kerf` command line is argument parsing and printing over this crate.
//!
//! ```
//! use kerf_pipeline::{Job, JobOptions};
//! use kerf_interp::Dialect;
//!
//! let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/../../fixtures");
//! let job = Job::from_files(format!("{dir}/dome.json"), format!("{dir}/machines/ac_head.json"))?
//!     .with_options(JobOptions::default().with_tolerance_mm(0.01).with_dialect(Dialect::Sinumerik));
//! let out = job.run()?;
//! assert!(out.programs[0].text.contains("TRAORI"), "a Sinumerik program");
//! assert!(out.toolpath.paths.iter().all(|p| p.max_chord_error <= 0.01), "certified");
//! # Ok::<(), kerf_pipeline::Error>(())
//! ```

mod certify;
mod cuts;
mod discretize;
mod error;
mod head;
mod job;
mod motion;
mod output;
mod place;
mod post;
pub mod ranges;
mod report;
mod run;
mod stages;
mod timing;
mod traverses;
mod view;

pub use certify::CertifiedToolpath;
pub use discretize::{
    beyond_run_tolerance, curves_batch, discretize_batch, discretize_curves,
    discretize_curves_within, orient_curves, toolpath_of_points, toolpath_of_poses,
    DEFAULT_MAX_TOTAL_POINTS,
};
pub use error::{Error, Result};
pub use job::{
    is_iges, Job, JobOptions, MissingSurface, OrientOptions, DEFAULT_CUT_CLEARANCE_MM,
    DEFAULT_MAX_TOTAL_POINTS_RUN, DEFAULT_TILT_TOLERANCE_DEG,
};
pub use motion::{fit_options, plan_program, MotionInput, MotionOptions, Program};
pub use output::{csv_names, program_names, Output, SetupProgram, OUTPUTS};
pub use place::{place, PlaceMode, Placed, AUTO_CLEARANCE_MM};
pub use post::{post_toolpath, toolpath_poses, MissingNormals, Posted};
pub use ranges::OptionRange;
pub use report::{
    path_report, CompensationPath, CompensationReport, DiscretizeReport, HeadPath, HeadReport,
    HeadStretch, HeadTilt, InterpolationReport, KinematicsReport, MicroJoint, MicroJointPath,
    MicroJointsReport, NormalsReport, OwnSurfaces, PathMotion, PlacementReport, ProcessReport,
    ProgramReport, Report, SearchedTraverse, SetupReport, ShortenedLead, SideReport,
    TechnologyReport, TiltPath, TiltTotals, TraversesReport, UncheckedTraverse, WallReport,
};
pub use run::PLACEMENT_RETRIES;
pub use timing::{process_cpu_time, Lap, StageTime, Timings};

/// A stage of a job, as [`Progress`] reports it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum Stage {
    /// Cutting points, per curve.
    Discretize,
    /// Normals, per curve.
    Normals,
    /// Placement, cuts and machine axes.
    Kinematics,
    /// Interpolation and G-code.
    Interpolate,
    /// The report and the picture.
    Report,
}

/// How far a job is: `done` of `total` items of `stage` (curves for the per-curve stages, one
/// for the others).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub struct Progress {
    /// The stage.
    pub stage: Stage,
    /// Items done.
    pub done: usize,
    /// Items in the stage.
    pub total: usize,
}

impl Progress {
    /// `done` of `total` in `stage`.
    pub fn new(stage: Stage, done: usize, total: usize) -> Self {
        Self { stage, done, total }
    }
}
