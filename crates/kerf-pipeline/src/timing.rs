//! Where a run's time went: wall and CPU seconds per stage ([`Timings`]), for `report.json`'s
//! `timings` and the CLI's summary line.
//!
//! CPU time is the process's (every thread's: the parallel stages count each core they use), so
//! a stage's CPU time can exceed its wall time; on a loaded machine wall time grows and CPU time
//! does not, which makes CPU seconds the figure to compare between runs.

use std::time::{Duration, Instant};

/// One stage's time.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
#[non_exhaustive]
pub struct StageTime {
    /// The stage (`read`, `discretize`, `normals`, `sides`, `place`, `cuts`, `kinematics`,
    /// `head` (with a cut clearance), `traverses`, `plan`, `gcode`, `view`, `report`, `write`;
    /// `earlier placements` for the searches that a wider margin replaced).
    pub stage: &'static str,
    /// Wall-clock seconds.
    pub wall_s: f64,
    /// CPU seconds of the whole process (all threads) during the stage.
    pub cpu_s: f64,
}

/// The stages' times in the order they ran.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Timings {
    /// Each stage once (a stage run several times, such as the traverses and the plan of each
    /// set-up, is summed).
    pub stages: Vec<StageTime>,
}

impl Timings {
    /// Adds `wall_s` and `cpu_s` to `stage` (appended the first time it is seen).
    pub fn add(&mut self, stage: &'static str, wall_s: f64, cpu_s: f64) {
        match self.stages.iter_mut().find(|s| s.stage == stage) {
            Some(s) => {
                s.wall_s += wall_s;
                s.cpu_s += cpu_s;
            }
            None => self.stages.push(StageTime {
                stage,
                wall_s,
                cpu_s,
            }),
        }
    }

    /// Runs `f` as (part of) `stage` and adds its time.
    pub fn time<T>(&mut self, stage: &'static str, f: impl FnOnce() -> T) -> T {
        let lap = Lap::start();
        let out = f();
        lap.stop(self, stage);
        out
    }

    /// The times of `other` added stage by stage (its new stages appended).
    pub fn merge(&mut self, other: &Timings) {
        for s in &other.stages {
            self.add(s.stage, s.wall_s, s.cpu_s);
        }
    }

    /// Total wall seconds of the stages.
    pub fn wall_s(&self) -> f64 {
        self.stages.iter().map(|s| s.wall_s).sum()
    }

    /// Total CPU seconds of the stages.
    pub fn cpu_s(&self) -> f64 {
        self.stages.iter().map(|s| s.cpu_s).sum()
    }

    /// The stages that took the most CPU, largest first, as `plan 1.20 s, traverses 0.80 s`
    /// (at most `n`; stages under 5 % of the total left out).
    pub fn summary(&self, n: usize) -> String {
        let total = self.cpu_s();
        let mut s: Vec<&StageTime> = self
            .stages
            .iter()
            .filter(|s| s.cpu_s >= 0.05 * total)
            .collect();
        s.sort_by(|a, b| b.cpu_s.total_cmp(&a.cpu_s));
        s.iter()
            .take(n)
            .map(|s| format!("{} {:.2} s", s.stage, s.cpu_s))
            .collect::<Vec<_>>()
            .join(", ")
    }
}

/// `report.json`'s `timings`: `wall_s` and `cpu_s` (the totals) and `stages`, in the order
/// they ran, each `{stage, wall_s, cpu_s}`.
impl serde::Serialize for Timings {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        use serde::ser::SerializeStruct;
        let mut t = serializer.serialize_struct("Timings", 3)?;
        t.serialize_field("wall_s", &self.wall_s())?;
        t.serialize_field("cpu_s", &self.cpu_s())?;
        t.serialize_field("stages", &self.stages)?;
        t.end()
    }
}

/// A started measurement: wall clock and process CPU clock.
#[derive(Debug, Clone, Copy)]
pub struct Lap {
    wall: Instant,
    cpu: Duration,
}

impl Lap {
    /// Starts measuring now.
    pub fn start() -> Self {
        Self {
            wall: Instant::now(),
            cpu: process_cpu_time(),
        }
    }

    /// Adds the time since the start (or the last split) to `stage` of `timings`, and starts
    /// again: consecutive stages measured with one lap.
    pub fn split(&mut self, timings: &mut Timings, stage: &'static str) {
        let next = Lap::start();
        let cpu = next.cpu.saturating_sub(self.cpu);
        timings.add(
            stage,
            next.wall.duration_since(self.wall).as_secs_f64(),
            cpu.as_secs_f64(),
        );
        *self = next;
    }

    /// Adds the time since [`Lap::start`] to `stage` of `timings`.
    pub fn stop(self, timings: &mut Timings, stage: &'static str) {
        let cpu = process_cpu_time().saturating_sub(self.cpu);
        timings.add(stage, self.wall.elapsed().as_secs_f64(), cpu.as_secs_f64());
    }
}

/// The CPU time of the whole process so far (every thread, user and system), from
/// `CLOCK_PROCESS_CPUTIME_ID`; zero where the clock cannot be read.
pub fn process_cpu_time() -> Duration {
    let mut ts = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: `ts` is a valid, writable timespec and the clock id is a constant the C library
    // defines; clock_gettime writes nothing else.
    let rc = unsafe { libc::clock_gettime(libc::CLOCK_PROCESS_CPUTIME_ID, &mut ts) };
    if rc != 0 || ts.tv_sec < 0 || !(0..1_000_000_000).contains(&ts.tv_nsec) {
        return Duration::ZERO;
    }
    Duration::new(ts.tv_sec as u64, ts.tv_nsec as u32)
}
