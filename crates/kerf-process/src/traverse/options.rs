//! The options of the traverses.

use nalgebra::Vector3;

use crate::{ProcessError, Result};

/// Options of the traverses.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct TraverseOptions {
    /// No point of the travel (tip or nozzle) comes closer to the part than this, mm
    /// (default 5).
    pub clearance_mm: f64,
    /// How far the head first backs off along the tool axis, mm; at least 1.25 times the
    /// clearance, raised where the retract point is not clear (default 7.5). A
    /// `kerf_pipeline::Job` raises it to its own `retract_mm`, the one retract of a run.
    pub retract_mm: f64,
    /// Length of the nozzle, a segment from the tip along the tool axis toward the head that
    /// must keep the clearance too, mm (default 20).
    pub nozzle_mm: f64,
    /// The direction in the workpiece frame that is "up" (away from the fixture, toward the
    /// free space): a lifted travel runs in the plane perpendicular to it above every
    /// surface (default +z).
    pub up: Vector3<f64>,
    /// Where no route shape (straight, lifted, over the safe plane) clears, search for a path
    /// around the part with the head turned to one tool axis for the travel, within a counted
    /// work budget (default true; `docs/process.md`, "The search around the part").
    pub search: bool,
}

impl Default for TraverseOptions {
    fn default() -> Self {
        Self {
            clearance_mm: 5.0,
            retract_mm: 7.5,
            nozzle_mm: 20.0,
            up: Vector3::z(),
            search: true,
        }
    }
}

impl TraverseOptions {
    /// Sets [`clearance_mm`](Self::clearance_mm): no point of the travel (tip or nozzle)
    /// comes closer to the part than this, mm (default 5).
    pub fn with_clearance_mm(mut self, clearance_mm: f64) -> Self {
        self.clearance_mm = clearance_mm;
        self
    }

    /// Sets [`retract_mm`](Self::retract_mm): how far the head first backs off along the
    /// tool axis, mm.
    pub fn with_retract_mm(mut self, retract_mm: f64) -> Self {
        self.retract_mm = retract_mm;
        self
    }

    /// Sets [`nozzle_mm`](Self::nozzle_mm): length of the nozzle, a segment from the tip
    /// along the tool axis toward the head that must keep the clearance too, mm (default
    /// 20).
    pub fn with_nozzle_mm(mut self, nozzle_mm: f64) -> Self {
        self.nozzle_mm = nozzle_mm;
        self
    }

    /// Sets [`up`](Self::up): the direction in the workpiece frame that is "up" (away from
    /// the fixture, toward the free space).
    pub fn with_up(mut self, up: Vector3<f64>) -> Self {
        self.up = up;
        self
    }

    /// Sets [`search`](Self::search): whether a search around the part runs where no route
    /// shape clears.
    pub fn with_search(mut self, search: bool) -> Self {
        self.search = search;
        self
    }

    /// With this clearance, mm; the retract becomes 1.5 times it (so that [`Self::validate`]
    /// holds, the clearance is at most 1e4 / 1.5 mm; `kerf_pipeline` allows 1000 mm).
    pub fn with_clearance(mut self, clearance_mm: f64) -> Self {
        self.clearance_mm = clearance_mm;
        self.retract_mm = 1.5 * clearance_mm;
        self
    }

    /// Checks every option: clearance and retract finite, > 0 and <= 1e4 mm with the retract
    /// at least 1.25 times the clearance, the nozzle in `[0, 1e4]` mm, `up` finite and not
    /// zero. Every traverse check runs it (and a traverse whose options fail is not checked);
    /// a caller should run it once before any work, as `kerf_pipeline::JobOptions::validate`
    /// does, so that options out of range are refused instead of leaving every traverse
    /// unchecked.
    ///
    /// # Errors
    /// [`ProcessError::BadOption`] naming the first option out of range.
    pub fn validate(&self) -> Result<()> {
        let check = |name: &'static str, v: f64, ok: bool| {
            if ok {
                Ok(())
            } else {
                Err(ProcessError::BadOption {
                    name,
                    value: v,
                    reason: "must be finite, > 0 and <= 1e4 (retract_mm >= 1.25 clearance_mm)",
                })
            }
        };
        let fine = |v: f64| v.is_finite() && v > 0.0 && v <= 1e4;
        check("clearance_mm", self.clearance_mm, fine(self.clearance_mm))?;
        check(
            "retract_mm",
            self.retract_mm,
            fine(self.retract_mm) && self.retract_mm >= 1.25 * self.clearance_mm,
        )?;
        check(
            "nozzle_mm",
            self.nozzle_mm,
            self.nozzle_mm.is_finite() && (0.0..=1e4).contains(&self.nozzle_mm),
        )?;
        let up_ok = self.up.iter().all(|v| v.is_finite()) && self.up.norm() > 1e-9;
        check("up", self.up.norm(), up_ok)
    }

    /// The height step of the lifted routes above the surfaces' boxes (two of them), mm.
    pub(super) fn step(&self) -> f64 {
        self.clearance_mm / 8.0
    }

    /// The margin of the checks, mm: a sample closer than the clearance plus this is taken
    /// as blocked (so the sphere tracing advances by at least half of it, which bounds its
    /// work). A sixty-fourth of the clearance: a route that keeps 1.02 times the clearance is
    /// found, and the claim (the clearance) does not depend on it.
    pub(super) fn margin(&self) -> f64 {
        self.clearance_mm / 64.0
    }
}
