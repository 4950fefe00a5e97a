//! From cutting points to blocks: runs of points become space arcs (or longer lines) wherever
//! the block stays within the tolerance of the points and of the curve.
//!
//! The discretizer's points are the ends of chords; a program of one line per chord has many
//! short blocks on round features. [`fit_blocks`] walks the points and, from each block start
//! `i`, finds the farthest `j` such that a single block from `i` to `j` is acceptable:
//!
//! - an **arc** through the tips of `i`, `m = (i + j) / 2` and `j`, or a **line** from `i` to
//!   `j`, whichever reaches farther (a line on a tie);
//! - every point in between lies within `tolerance` of the block and the points follow each
//!   other along it (no back-tracking);
//! - the tool axis interpolated at each point (rotary axes in proportion to the distance, or
//!   to the swept angle piecewise `i -> m -> j` on arcs) is within `orientation_tolerance_deg` of
//!   the point's own tool axis;
//! - **the polyline**: each piece of the block between neighbouring points lies within
//!   `tolerance` of their chord (a line: its points are within it, and so is every point of
//!   the chord between two of them; an arc: its sagitta over the chord plus the points' own
//!   distances). This is proven, so the block lies within `tolerance` plus the chord error of
//!   the curve: the budget's `chord + fit`;
//! - **the curve**: where the curve is known (a closure giving the curve point at a parameter,
//!   and both neighbouring points carry their parameters), `curve_samples` points of the curve
//!   between them also lie within `tolerance` of the block (sampled, so a check, not a
//!   bound).
//!
//! The search is exponential then bisecting in `j` (the acceptance is not strictly monotone in
//! `j`, so the result is a good, not necessarily the longest, block).

use nalgebra::Point3;

use crate::block::{Block, Station, MIN_TRAVEL};
use crate::error::{positive, InterpError, Result};
use crate::geometry::SpaceArc;
use crate::model::AxisModel;
use kerf_nurbs::{nearest_on_segment, CurvePoint};

/// Options of [`fit_blocks`].
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct FitOptions {
    /// Largest distance (mm) of a block from the points and the curve it replaces. Default
    /// 0.001 mm; the natural choice is the toolpath's own `tolerance`.
    pub tolerance_mm: f64,
    /// Largest angle (degrees) between the interpolated and the given tool axis at a point.
    /// Default 0.1.
    pub orientation_tolerance_deg: f64,
    /// Fit arcs (default true); false gives lines only (still merged when collinear).
    pub arcs: bool,
    /// Merge runs of collinear points into one line (default true).
    pub merge_lines: bool,
    /// Most cutting points one block may span (bounds the fitting cost). Default 1024.
    pub max_points: usize,
    /// Largest swept angle of an arc, degrees. Default 270 (a three-point arc cannot make a
    /// full turn; G-code `CIP` needs less than 360).
    pub max_sweep_deg: f64,
    /// Largest arc radius, mm; flatter runs are lines. Default 1e5.
    pub max_radius_mm: f64,
    /// Curve points tested between two neighbouring cutting points when the curve is known.
    /// Default 4.
    pub curve_samples: usize,
    /// Retract distance (mm) of the rapid moves between paths ([`crate::fit_program`]): the
    /// head backs off along the tool axis, traverses, and approaches the next start along its
    /// tool axis, instead of crossing at cutting height. Default 10; 0 gives one straight rapid.
    pub retract_mm: f64,
}

impl Default for FitOptions {
    fn default() -> Self {
        Self {
            tolerance_mm: 0.001,
            orientation_tolerance_deg: 0.1,
            arcs: true,
            merge_lines: true,
            max_points: 1024,
            max_sweep_deg: 270.0,
            max_radius_mm: 1e5,
            curve_samples: 4,
            retract_mm: 10.0,
        }
    }
}

impl FitOptions {
    /// Sets [`tolerance_mm`](Self::tolerance_mm): largest distance (mm) of a block from the
    /// points and the curve it replaces.
    pub fn with_tolerance_mm(mut self, tolerance_mm: f64) -> Self {
        self.tolerance_mm = tolerance_mm;
        self
    }

    /// Sets [`orientation_tolerance_deg`](Self::orientation_tolerance_deg): largest angle
    /// (degrees) between the interpolated and the given tool axis at a point.
    pub fn with_orientation_tolerance_deg(mut self, orientation_tolerance_deg: f64) -> Self {
        self.orientation_tolerance_deg = orientation_tolerance_deg;
        self
    }

    /// Sets [`arcs`](Self::arcs): fit arcs (default true).
    pub fn with_arcs(mut self, arcs: bool) -> Self {
        self.arcs = arcs;
        self
    }

    /// Sets [`merge_lines`](Self::merge_lines): merge runs of collinear points into one
    /// line (default true).
    pub fn with_merge_lines(mut self, merge_lines: bool) -> Self {
        self.merge_lines = merge_lines;
        self
    }

    /// Sets [`max_points`](Self::max_points): most cutting points one block may span
    /// (bounds the fitting cost).
    pub fn with_max_points(mut self, max_points: usize) -> Self {
        self.max_points = max_points;
        self
    }

    /// Sets [`max_sweep_deg`](Self::max_sweep_deg): largest swept angle of an arc, degrees.
    pub fn with_max_sweep_deg(mut self, max_sweep_deg: f64) -> Self {
        self.max_sweep_deg = max_sweep_deg;
        self
    }

    /// Sets [`max_radius_mm`](Self::max_radius_mm): largest arc radius, mm.
    pub fn with_max_radius_mm(mut self, max_radius_mm: f64) -> Self {
        self.max_radius_mm = max_radius_mm;
        self
    }

    /// Sets [`curve_samples`](Self::curve_samples): curve points tested between two
    /// neighbouring cutting points when the curve is known.
    pub fn with_curve_samples(mut self, curve_samples: usize) -> Self {
        self.curve_samples = curve_samples;
        self
    }

    /// Sets [`retract_mm`](Self::retract_mm): retract distance (mm) of the rapid moves
    /// between paths ([`crate::fit_program`]).
    pub fn with_retract_mm(mut self, retract_mm: f64) -> Self {
        self.retract_mm = retract_mm;
        self
    }

    /// The defaults with this tolerance (mm): a constructor, the start of a chain of the
    /// `with_*` setters (`FitOptions::with_tolerance(0.01).with_arcs(false)`).
    pub fn with_tolerance(tolerance_mm: f64) -> Self {
        Self::default().with_tolerance_mm(tolerance_mm)
    }

    fn validate(&self) -> Result<()> {
        positive("tolerance_mm", self.tolerance_mm)?;
        positive("orientation_tolerance_deg", self.orientation_tolerance_deg)?;
        positive("max_sweep_deg", self.max_sweep_deg)?;
        positive("max_radius_mm", self.max_radius_mm)?;
        Ok(())
    }
}

/// How many blocks of each kind.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct BlockCounts {
    /// Space lines.
    pub lines: usize,
    /// Space arcs.
    pub arcs: usize,
    /// Pure rotations (tip at rest).
    pub turns: usize,
}

impl BlockCounts {
    /// The counts of `blocks` (rapid moves excluded).
    pub fn of(blocks: &[Block]) -> Self {
        let mut c = Self::default();
        for b in blocks.iter().filter(|b| !b.rapid) {
            match b.geometry {
                crate::block::Geometry::Line { .. } => c.lines += 1,
                crate::block::Geometry::Arc(_) => c.arcs += 1,
                crate::block::Geometry::Turn { .. } => c.turns += 1,
            }
        }
        c
    }

    /// Total number of blocks.
    pub fn total(&self) -> usize {
        self.lines + self.arcs + self.turns
    }
}

/// A path's curve for the arc fit's curve test: any [`CurvePoint`] (a NURBS curve, a
/// closure `|t| curve.point(t)`, a placed or offset contour).
pub type CurveFn<'a> = &'a dyn CurvePoint;

/// Fits blocks to the stations of one path (see the module documentation). Without a curve
/// (or when a station has no parameter) the polyline stands in for the curve.
///
/// The blocks are numbered as path `path`; consecutive blocks share their end stations, the
/// first starts at station 0 and the last ends at the last station. A single station gives no
/// block.
///
/// # Errors
/// [`InterpError::BadParameter`] for invalid options, [`InterpError::NonFinite`] for a station
/// with NaN or infinite data.
pub fn fit_blocks<M: AxisModel + ?Sized>(
    model: &M,
    stations: &[Station],
    curve: Option<CurveFn<'_>>,
    path: usize,
    opts: &FitOptions,
) -> Result<Vec<Block>> {
    opts.validate()?;
    for (i, s) in stations.iter().enumerate() {
        let finite = s
            .tip
            .coords
            .iter()
            .chain(s.axis.iter())
            .all(|v| v.is_finite())
            && s.axes.is_finite()
            && s.param.is_none_or(f64::is_finite);
        if !finite {
            return Err(InterpError::NonFinite { index: i });
        }
    }
    let n = stations.len();
    // Curve samples between each pair of neighbours, where the curve and both parameters are
    // known (points inserted by the kinematics may carry no parameter).
    let samples: Vec<Option<Vec<Point3<f64>>>> = stations
        .windows(2)
        .map(|w| {
            let f = curve?;
            let (a, b) = (w[0].param?, w[1].param?);
            let k = opts.curve_samples;
            Some(
                (1..=k)
                    .map(|m| f.point_at(a + (b - a) * m as f64 / (k + 1) as f64))
                    .collect(),
            )
        })
        .collect();
    let fitter = Fitter {
        model,
        st: stations,
        samples: &samples,
        opts,
    };
    let mut blocks = Vec::new();
    let mut i = 0;
    while i + 1 < n {
        let limit = (i + opts.max_points.max(2)).min(n - 1);
        let line_j = if opts.merge_lines {
            longest(i + 1, limit, |j| fitter.line_fits(i, j))
        } else {
            i + 1
        };
        let arc_j = if opts.arcs && i + 2 <= limit && fitter.arc_fits(i, i + 2) {
            longest(i + 2, limit, |j| fitter.arc_fits(i, j))
        } else {
            0
        };
        let mut block = if arc_j > line_j {
            let m = (i + arc_j) / 2;
            let b = Block::arc_or_line(&stations[i], &stations[m], &stations[arc_j]);
            i = arc_j;
            b
        } else {
            let b = Block::line(&stations[i], &stations[line_j]);
            i = line_j;
            b
        };
        block.path = path;
        block.stations = [blocks.last().map_or(0, |b: &Block| b.stations[1]), i];
        blocks.push(block);
    }
    Ok(blocks)
}

/// The largest `j` in `[lo, hi]` with `fits(j)`, given `fits(lo)` (exponential then
/// bisecting search).
fn longest(lo: usize, hi: usize, fits: impl Fn(usize) -> bool) -> usize {
    let mut good = lo;
    let mut step = 1;
    let mut bad = None;
    while good < hi {
        let j = (good + step).min(hi);
        if fits(j) {
            good = j;
            step *= 2;
        } else {
            bad = Some(j);
            break;
        }
    }
    if let Some(mut bad) = bad {
        while bad - good > 1 {
            let mid = (good + bad) / 2;
            if fits(mid) {
                good = mid;
            } else {
                bad = mid;
            }
        }
    }
    good
}

struct Fitter<'a, M: ?Sized> {
    model: &'a M,
    st: &'a [Station],
    /// Curve samples of each segment `k -> k + 1`, `None` where the curve is not known.
    samples: &'a [Option<Vec<Point3<f64>>>],
    opts: &'a FitOptions,
}

impl<M: AxisModel + ?Sized> Fitter<'_, M> {
    fn orientation_ok(&self, k: usize, tilt: f64, c: f64) -> bool {
        let u = self.model.tool_axis(tilt, c);
        let cos = u.dot(&self.st[k].axis).clamp(-1.0, 1.0);
        cos.acos().to_degrees() <= self.opts.orientation_tolerance_deg
    }

    fn distinct_tips(&self, i: usize, j: usize) -> bool {
        (i..j).all(|k| (self.st[k + 1].tip - self.st[k].tip).norm() > MIN_TRAVEL)
    }

    fn line_fits(&self, i: usize, j: usize) -> bool {
        if j == i + 1 {
            return true;
        }
        let (a, b) = (&self.st[i], &self.st[j]);
        let tol = self.opts.tolerance_mm;
        if (b.tip - a.tip).norm() <= MIN_TRAVEL || !self.distinct_tips(i, j) {
            return false;
        }
        let mut last_t = 0.0;
        for k in i + 1..j {
            let (d, t) = nearest_on_segment(&self.st[k].tip, &a.tip, &b.tip);
            if d > tol || t <= last_t || t >= 1.0 {
                return false;
            }
            last_t = t;
            let tilt = a.axes.tilt + t * (b.axes.tilt - a.axes.tilt);
            let c = a.axes.c + t * (b.axes.c - a.axes.c);
            if !self.orientation_ok(k, tilt, c) {
                return false;
            }
        }
        for seg in self.samples[i..j].iter().flatten() {
            if seg
                .iter()
                .any(|p| nearest_on_segment(p, &a.tip, &b.tip).0 > tol)
            {
                return false;
            }
        }
        true
    }

    fn arc_fits(&self, i: usize, j: usize) -> bool {
        let m = (i + j) / 2;
        let (a, mid, b) = (&self.st[i], &self.st[m], &self.st[j]);
        let Ok(arc) = SpaceArc::through(a.tip, mid.tip, b.tip) else {
            return false;
        };
        if arc.radius > self.opts.max_radius_mm
            || arc.angle_end.to_degrees() > self.opts.max_sweep_deg
        {
            return false;
        }
        if !self.distinct_tips(i, j) {
            return false;
        }
        let tol = self.opts.tolerance_mm;
        let mut last = (0.0, 0.0); // (angle, distance) of the previous point
        for k in i + 1..=j {
            let (d, theta) = if k == j {
                (0.0, arc.angle_end)
            } else if k == m {
                (0.0, arc.angle_mid)
            } else {
                arc.distance(&self.st[k].tip)
            };
            if d > tol || theta <= last.0 || theta > arc.angle_end {
                return false;
            }
            // The arc piece between neighbours stays within the tolerance of their chord
            // (its sagitta over the chord plus the points' own distances): the proven half of
            // the budget's `chord + fit`, the chord being within the certified chord error of
            // the curve. The curve samples below only keep the arc near the curve too.
            let sagitta = arc.radius * (1.0 - (0.5 * (theta - last.0)).cos());
            if sagitta + d.max(last.1) > tol * (1.0 + 1e-9) {
                return false;
            }
            last = (theta, d);
            if k < j && k != m {
                let (tilt, c) = if theta < arc.angle_mid {
                    let f = theta / arc.angle_mid;
                    (
                        a.axes.tilt + f * (mid.axes.tilt - a.axes.tilt),
                        a.axes.c + f * (mid.axes.c - a.axes.c),
                    )
                } else {
                    let f = (theta - arc.angle_mid) / (arc.angle_end - arc.angle_mid);
                    (
                        mid.axes.tilt + f * (b.axes.tilt - mid.axes.tilt),
                        mid.axes.c + f * (b.axes.c - mid.axes.c),
                    )
                };
                if !self.orientation_ok(k, tilt, c) {
                    return false;
                }
            }
        }
        for seg in self.samples[i..j].iter().flatten() {
            if seg.iter().any(|p| arc.distance(p).0 > tol) {
                return false;
            }
        }
        true
    }
}
