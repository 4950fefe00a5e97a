//! kerf: NURBS cut contours to the motion of a 5-axis laser cutting machine.
//!
//! The pipeline in one call: a [`Job`] of curves and surfaces (read from `kerf.curves/1` or
//! built in code) and a [`kinematics::Machine`], run in memory ([`Job::run`]), returns every
//! stage's result ([`Output`]: toolpath, machine axes, motion, program text, report), or one
//! [`Error`] that keeps the stage's own error and names the file and the curve. A contour and
//! its surface built in code, cut on a shipped machine, with Sinumerik G-code in memory
//! (`examples/integrator.rs`; a test checks its program against the circle and the axes by
//! forward kinematics):
//!
//! ```
#![doc = include_str!("../examples/integrator.rs")]
//! ```
//!
//! The stage crates are re-exported in pipeline order; read them in that order:
//!
//! 1. [`nurbs`]: rational curves and surfaces (evaluation, derivatives, Bezier pieces).
//! 2. [`format`](mod@format): `kerf.curves/1` in, `kerf.toolpath/1` out; [`step`] and
//!    [`iges`]: the same contours and faces read from a STEP or an IGES file.
//! 3. [`discretize`]: cutting points with a certified chord error.
//! 4. [`normals`]: the surface normal of every cutting point.
//! 5. [`kinematics`]: poses to machine axes, `kerf.axes/1`.
//! 6. [`process`]: scrap sides, start points, lead-ins, the cutting order, kerf offsets, the
//!    head's clearance and the checked traverses (it places and solves poses with
//!    [`kinematics`], so it comes after it).
//! 7. [`interp`]: time-division interpolation, feed planning, set-points and G-code.
//! 8. [`pipeline`]: the stages chained ([`Job`]); its items are also here at the top.
//!
//! Beside them: [`check`], the independent checker of any toolpath against its curves;
//! [`plot`], the SVG pictures; [`view`], the interactive 3D view (`view.html`); [`io`], the one reader and atomic writer; [`nalgebra`], the
//! maths types every API takes (so a caller need not match its version by hand).

pub use kerf_check as check;
pub use kerf_discretize as discretize;
pub use kerf_format as format;
pub use kerf_iges as iges;
pub use kerf_interp as interp;
pub use kerf_io as io;
pub use kerf_kinematics as kinematics;
pub use kerf_normals as normals;
pub use kerf_nurbs as nurbs;
pub use kerf_pipeline as pipeline;
pub use kerf_plot as plot;
pub use kerf_process as process;
pub use kerf_step as step;
pub use kerf_view as view;
pub use nalgebra;

pub use kerf_pipeline::{
    Error, Job, JobOptions, MissingSurface, MotionInput, MotionOptions, OrientOptions, Output,
    PlaceMode, Program, Progress, Result, SetupProgram, Stage,
};
