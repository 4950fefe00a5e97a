//! [`Job::run`]: the whole pipeline in memory. Discretize (certified chord error), normals,
//! placement, cuts, machine axes, interpolation and G-code, with a report and a picture
//! ([`Output`]); [`Output::write_dir`] writes them all into one directory only once every
//! stage has succeeded.

use std::time::Instant;

use crate::error::Result;
use crate::job::Job;
use crate::output::Output;
use crate::stages::{self, Clock, Run};
use crate::timing::{Lap, Timings};
use crate::Progress;

impl Job {
    /// Runs every stage in memory.
    ///
    /// # Errors
    /// The first stage's [`Error`](crate::Error), naming the file (see [`Job::with_source`]) and the curve.
    pub fn run(&self) -> Result<Output> {
        self.run_with_progress(&|_| {})
    }

    /// [`Job::run`], calling `progress` as the stages advance (from several threads in the
    /// parallel stages: per curve in [`Stage::Discretize`](crate::Stage::Discretize) and
    /// [`Stage::Normals`](crate::Stage::Normals), once per stage elsewhere).
    ///
    /// # Errors
    /// As [`Job::run`].
    pub fn run_with_progress(&self, progress: &(dyn Fn(Progress) + Sync)) -> Result<Output> {
        run(self, progress)
    }
}

/// How many times `--place auto` is tried again with a wider margin when the program's motion
/// (a lead, a retract, a traverse, a pierce point or a blend) leaves a linear axis' travel.
pub const PLACEMENT_RETRIES: usize = 3;

/// The stages of [`Job::run_with_progress`], in order. A placement that `auto` chose must hold
/// every move of the program, not only the cutting poses it was checked with: the search keeps
/// the retract (or the pierce standoff, if longer) plus 1 mm from every linear limit, and if
/// the motion still leaves a linear axis' range by `d` mm (a lead's pose, a set-point or a
/// pierce point), the placement is searched again keeping `d + 1` mm more, at most
/// [`PLACEMENT_RETRIES`] times; then the search's own refusal ("no placement fits") or the
/// range error stands. Each search runs the whole job again (a failure case only). A placement
/// the user gave is never moved: its range error is reported as it is.
fn run(job: &Job, progress: &(dyn Fn(Progress) + Sync)) -> Result<Output> {
    let mut extra = 0.0;
    let mut attempt = 0;
    // The searches a wider margin replaced, timed as one stage before the others.
    let mut earlier = Timings::default();
    loop {
        let lap = Lap::start();
        match run_placed(job, progress, extra, attempt) {
            Err(e)
                if job.options.place == crate::PlaceMode::Auto && attempt < PLACEMENT_RETRIES =>
            {
                match linear_overshoot(&e) {
                    Some(d) => {
                        extra += d + 1.0;
                        attempt += 1;
                        lap.stop(&mut earlier, "earlier placements");
                    }
                    None => return Err(e),
                }
            }
            Ok(mut out) => {
                if !earlier.stages.is_empty() {
                    out.prepend_timings(earlier);
                }
                return Ok(out);
            }
            r => return r,
        }
    }
}

/// How far (mm) the program's motion leaves a linear axis' range, if that is the error: a
/// set-point or pierce point of the plan, or a pose of a lead the placement search did not see.
fn linear_overshoot(e: &crate::Error) -> Option<f64> {
    let over = |axis: &str, value: f64, min: f64, max: f64| {
        let over = (min - value).max(value - max);
        (matches!(axis, "X" | "Y" | "Z") && over.is_finite() && over > 0.0).then_some(over)
    };
    let source = match e {
        crate::Error::Interp { source, .. } => source,
        // A lead-in, lead-out or inserted pose the search did not see.
        crate::Error::Kinematics { source, .. } => {
            return match source.without_file() {
                kerf_kinematics::KinematicsError::OutOfLimits {
                    axis,
                    value,
                    min,
                    max,
                    ..
                } => over(axis, *value, *min, *max),
                _ => None,
            };
        }
        _ => return None,
    };
    let (axis, value, min, max) = match source {
        kerf_interp::InterpError::OutOfRange {
            axis,
            value,
            min,
            max,
            ..
        }
        | kerf_interp::InterpError::PierceOutOfRange {
            axis,
            value,
            min,
            max,
            ..
        }
        | kerf_interp::InterpError::RetractOutOfRange {
            axis,
            value,
            min,
            max,
            ..
        } => (axis, *value, *min, *max),
        _ => return None,
    };
    over(axis, value, min, max)
}

/// The stages once, the placement search keeping `extra_margin_mm` more from the linear
/// limits (`attempt` is reported). Each stage is a function of `stages.rs` with typed input
/// and output; the clock splits the run's time by stage.
fn run_placed(
    job: &Job,
    progress: &(dyn Fn(Progress) + Sync),
    extra_margin_mm: f64,
    attempt: usize,
) -> Result<Output> {
    let started = Instant::now();
    let mut clock = Clock::start();
    // The options checked, the kerf decided, a dialect that cannot program the machine
    // refused before any work.
    let run = Run::new(job, progress)?;
    // 1. Cutting points with a certified chord error; where closed cuts start.
    let points = stages::discretize(&run)?;
    clock.split("discretize");
    // 2. Normals.
    let mut normals = stages::orient(&run, &points)?;
    clock.split("normals");
    // 3a, 3b. Which side of the sheet each contour is cut from; where the part goes on the
    // machine (from here on, workpiece coordinates).
    let part = stages::place(&run, &normals, extra_margin_mm, &mut clock)?;
    // 3c. The cuts: start points, leads, order, the kerf offset.
    let cuts = stages::plan_cuts(&run, &points, &normals, &part)?;
    stages::record_offsets(&mut normals.toolpath, &cuts.compensated);
    // 3d. Machine axes, micro-joints, the head along the cuts.
    let solved = stages::solve(&run, &cuts, &part, &mut clock)?;
    // 4. Per set-up: traverses routed and checked, the motion planned, the G-code.
    let programs = stages::programs(&run, &cuts, &part, &solved, &normals, &mut clock)?;
    // 5. The 3D view, the picture and the report.
    stages::output(
        &run,
        (points, normals, part, cuts, solved, programs),
        attempt,
        started,
        clock,
    )
}
