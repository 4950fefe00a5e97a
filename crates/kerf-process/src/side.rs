//! Which side of the sheet the head reaches a cut from: the nozzle's line along the tool axis
//! at the contour, on the side of the normals and on the other.

use nalgebra::Point3;

use crate::traverse::{Obstacles, TraverseOptions};
use crate::Pose;

/// Most contour points whose head lines [`head_lines`] looks at (spread along the contour,
/// both ends always).
pub const HEAD_LINE_POINTS: usize = 64;

/// How the head lines of one contour meet the part ([`head_lines`]).
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct HeadLines {
    /// How many of the contour's points were looked at.
    pub points: usize,
    /// At how many of them the head line on the side of the normal meets the part.
    pub given: usize,
    /// At how many of them the head line on the other side meets the part.
    pub other: usize,
    /// How far along the tool axis the given side's lines first meet the part, mm
    /// (infinite where they do not).
    pub given_from_mm: f64,
    /// The same on the other side, mm.
    pub other_from_mm: f64,
    /// The contour lies on a face of a sheet of known thickness and is cut from that side
    /// whatever its lines say ([`HeadLines::kept_on_sheet`]).
    pub on_sheet: bool,
}

impl Default for HeadLines {
    fn default() -> Self {
        Self {
            points: 0,
            given: 0,
            other: 0,
            given_from_mm: f64::INFINITY,
            other_from_mm: f64::INFINITY,
            on_sheet: false,
        }
    }
}

impl HeadLines {
    /// True if the head meets the part from the given side and nowhere from the other: the
    /// contour is better cut from the other side of the sheet.
    pub fn prefers_other_side(&self) -> bool {
        self.given > 0 && self.other == 0 && !self.on_sheet
    }

    /// The same lines for a contour on a face of a thick sheet (a recognised sheet's
    /// feature, the `sheet_thickness_mm` key): it is never turned to the other side, where
    /// the nozzle would stand off from the far face, inside the sheet.
    pub fn kept_on_sheet(self) -> Self {
        Self {
            on_sheet: true,
            ..self
        }
    }
}

/// The head lines of the contour `poses` (cutting points with their tool axes, in the frame of
/// `obs`) on both sides of the sheet: at up to [`HEAD_LINE_POINTS`] of its points (spread
/// evenly, both ends included), the line along the tool axis from three quarters of the
/// clearance to the retract plus the nozzle (where the nozzle is while it cuts there and
/// as it backs off), and the same line along the reversed axis. A line *meets the part* when a
/// surface of `obs` comes within half the clearance of it: the rule by which
/// [`crate::in_the_cuts_way`] leaves a cut's own surface out of its traverses (the head
/// cannot keep the clearance from it whatever the traverse does).
///
/// Sampled: each line at points a quarter of the clearance apart, so a surface within 3/8 of
/// the clearance of a line is always found, one within half of it where a sample comes that
/// close. The lines start at 3/4 of the clearance because their foot is on the part by design.
/// Options that [`crate::plan_traverse`] would refuse look at nothing.
pub fn head_lines(obs: &Obstacles, poses: &[Pose], opts: &TraverseOptions) -> HeadLines {
    let c = opts.clearance_mm;
    let n = poses.len();
    if n == 0 || obs.is_empty() || opts.validate().is_err() {
        return HeadLines::default();
    }
    let k = n.min(HEAD_LINE_POINTS);
    let picked: Vec<usize> = if k <= 1 {
        vec![0]
    } else {
        let mut v: Vec<usize> = (0..k).map(|j| j * (n - 1) / (k - 1)).collect();
        v.dedup();
        v
    };
    let reach = opts.retract_mm + opts.nozzle_mm;
    let steps = ((reach - 0.75 * c) / (0.25 * c)).ceil().clamp(1.0, 1e5) as usize;
    // The first offset along the line where it meets the part.
    let meets = |p: &Point3<f64>, axis: nalgebra::Vector3<f64>| {
        (0..=steps)
            .map(|j| 0.75 * c + (reach - 0.75 * c) * j as f64 / steps as f64)
            .find(|&s| obs.distance_below(&(p + axis * s), 0.5 * c) < 0.5 * c)
    };
    let mut out = HeadLines {
        points: picked.len(),
        ..HeadLines::default()
    };
    for &i in &picked {
        let p = poses[i].position;
        let Some(axis) = poses[i].axis.try_normalize(1e-12) else {
            continue;
        };
        if !p.coords.iter().all(|v| v.is_finite()) {
            continue;
        }
        if let Some(s) = meets(&p, axis) {
            out.given += 1;
            out.given_from_mm = out.given_from_mm.min(s);
        }
        if let Some(s) = meets(&p, -axis) {
            out.other += 1;
            out.other_from_mm = out.other_from_mm.min(s);
        }
    }
    out
}
