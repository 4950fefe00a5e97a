//! The path the machine follows: the blocks of a program cut into *runs* at true corners, and
//! along each run a smooth (C2) interpolant of the poses.
//!
//! A run is a chain of blocks of one path with no true corner inside: the tool-tip tangent
//! turns by at most [`CORNER_DEG`] where two blocks meet. Rapid moves, pure rotations
//! ([`Geometry::Turn`]) and path changes also end a run. The planner brings the machine to rest
//! at every run end (a true corner cannot be passed at speed) and nowhere else.
//!
//! A rapid is a run of its own, straight in the machine's axes (the way a `G0` runs and its
//! traverse was checked; [`Run`]): its two splines are that line, not the tip's.
//!
//! Along a cutting run the tip is a clamped C2 cubic spline through the block ends, the arcs'
//! intermediate points and points of every arc at most [`ARC_NODE_DEG`] apart (so the spline
//! follows the arcs within a few micrometres), parameterized by `s`, which counts each block's
//! tip travel or, where larger, its rotary travel in millimetre equivalents
//! ([`block_param_length`]);
//! the rotary axes are a second clamped C2 cubic spline through the stations (block ends and arc
//! intermediate points). The linear axes follow from the machine model at every `s`. The ends
//! are clamped to the tangent of the first and last block, and a run's ends, and every block's
//! start, are returned exactly as the stations' axes.
//!
//! With a blend tolerance `e` (jerk-limited plans) the tip is the spline's mean over
//! `[s - w(s), s + w(s)]`, `w <= W = sqrt(6 e / max |p''|)` (so within `e` of the spline), tapered
//! to 0 at the run's ends: a curvature jump becomes a linear ramp over `2 W`. The rotary spline
//! interpolates the stations in the coordinates of [`SoftRange`], a C2 map onto the axis range,
//! so the rotary axes pass every station exactly and never leave their ranges. The math is in
//! `docs/interpolation.md`.

use kerf_kinematics::Axes;

use crate::block::{Block, Geometry};
use crate::model::AxisModel;
use nalgebra::{Point3, Vector3};

/// Windows of [`Spline::box_mean`] over at most this many pieces are integrated piece by piece
/// (the common case, exact to the rounding of the deviations), wider ones from the spline's
/// segment tree of piece integrals.
const BOX_MEAN_DIRECT: usize = 32;

/// Tangent turn (degrees) above which two blocks meet at a true corner.
pub(crate) const CORNER_DEG: f64 = 5.0;
/// Largest sweep (degrees) between two spline nodes on an arc.
pub(crate) const ARC_NODE_DEG: f64 = 5.0;

/// A clamped C2 cubic spline of `D` components in Hermite form (values and slopes at nodes).
#[derive(Debug, Clone)]
pub(crate) struct Spline<const D: usize> {
    s: Vec<f64>,
    y: Vec<[f64; D]>,
    m: Vec<[f64; D]>,
    /// The integrals of the pieces over their intervals, as a bottom-up segment tree (leaf `i`
    /// at `n - 1 + i` for `n - 1` pieces, node `k` the sum of `2k` and `2k + 1`), so that
    /// [`Spline::box_mean`] sums a window of many pieces in `O(log n)` from sums of pieces
    /// inside the window only.
    sums: Vec<[f64; D]>,
}

impl<const D: usize> Spline<D> {
    /// The C2 cubic through `(s[i], y[i])` with end slopes `m0` and `m1` (`s` increasing, at
    /// least two nodes): the slope equations
    /// `h_i m_{i-1} + 2 (h_{i-1} + h_i) m_i + h_{i-1} m_{i+1} = 3 (h_i d_{i-1} + h_{i-1} d_i)`
    /// solved by the Thomas algorithm (diagonally dominant, so stable).
    pub(crate) fn clamped(s: Vec<f64>, y: Vec<[f64; D]>, m0: [f64; D], m1: [f64; D]) -> Self {
        let n = s.len();
        let mut m = vec![[0.0; D]; n];
        m[0] = m0;
        m[n - 1] = m1;
        if n > 2 {
            let k = n - 2;
            let mut diag = vec![0.0; k];
            let mut upper = vec![0.0; k];
            let mut lower = vec![0.0; k];
            let mut rhs = vec![[0.0; D]; k];
            for r in 0..k {
                let i = r + 1;
                let h0 = s[i] - s[i - 1];
                let h1 = s[i + 1] - s[i];
                lower[r] = h1;
                diag[r] = 2.0 * (h0 + h1);
                upper[r] = h0;
                for d in 0..D {
                    let d0 = (y[i][d] - y[i - 1][d]) / h0;
                    let d1 = (y[i + 1][d] - y[i][d]) / h1;
                    rhs[r][d] = 3.0 * (h1 * d0 + h0 * d1);
                }
            }
            for d in 0..D {
                rhs[0][d] -= lower[0] * m0[d];
                rhs[k - 1][d] -= upper[k - 1] * m1[d];
            }
            // Forward elimination.
            for r in 1..k {
                let w = lower[r] / diag[r - 1];
                diag[r] -= w * upper[r - 1];
                for d in 0..D {
                    rhs[r][d] -= w * rhs[r - 1][d];
                }
            }
            for d in 0..D {
                m[k][d] = rhs[k - 1][d] / diag[k - 1];
            }
            for r in (0..k - 1).rev() {
                for d in 0..D {
                    m[r + 1][d] = (rhs[r][d] - upper[r] * m[r + 2][d]) / diag[r];
                }
            }
        }
        let pieces = n - 1;
        let mut sums = vec![[0.0; D]; 2 * pieces];
        for i in 0..pieces {
            let h = s[i + 1] - s[i];
            // The Hermite cubic's integral: h (y0 + y1) / 2 + h^2 (m0 - m1) / 12.
            sums[pieces + i] = std::array::from_fn(|d| {
                h * (y[i][d] + y[i + 1][d]) / 2.0 + h * h * (m[i][d] - m[i + 1][d]) / 12.0
            });
        }
        for k in (1..pieces).rev() {
            sums[k] = std::array::from_fn(|d| sums[2 * k][d] + sums[2 * k + 1][d]);
        }
        Self { s, y, m, sums }
    }

    /// The sum of the integrals of pieces `a..b` (`a < b`), from the fewest nodes of the
    /// segment tree that cover them: each node lies inside the range, so no sum is much
    /// larger than the range's own integral.
    fn piece_sum(&self, a: usize, b: usize) -> [f64; D] {
        let pieces = self.s.len() - 1;
        let (mut lo, mut hi) = (a + pieces, b + pieces);
        let mut acc = [0.0; D];
        while lo < hi {
            if lo & 1 == 1 {
                acc = std::array::from_fn(|d| acc[d] + self.sums[lo][d]);
                lo += 1;
            }
            if hi & 1 == 1 {
                hi -= 1;
                acc = std::array::from_fn(|d| acc[d] + self.sums[hi][d]);
            }
            lo /= 2;
            hi /= 2;
        }
        acc
    }

    /// The index of the interval holding `s` (the end intervals extended beyond the ends).
    #[inline]
    fn index(&self, s: f64) -> usize {
        self.s
            .partition_point(|&v| v <= s)
            .clamp(1, self.s.len() - 1)
            - 1
    }

    /// The cubic's coefficients on the interval holding `s` (the end intervals extended beyond
    /// the ends): `(t, h, [a, b, c, d])` with `p = a + b t + c t^2 + d t^3`, `t = (s - s_i) / h`.
    #[inline]
    fn piece(&self, s: f64) -> (f64, f64, [[f64; D]; 4]) {
        self.piece_at(self.index(s), s)
    }

    /// Like [`Spline::piece`], for the cubic of interval `i` (extrapolated outside it).
    #[inline]
    fn piece_at(&self, i: usize, s: f64) -> (f64, f64, [[f64; D]; 4]) {
        let h = self.s[i + 1] - self.s[i];
        let t = (s - self.s[i]) / h;
        let (y0, y1, m0, m1) = (&self.y[i], &self.y[i + 1], &self.m[i], &self.m[i + 1]);
        let mut c = [[0.0; D]; 4];
        for d in 0..D {
            c[0][d] = y0[d];
            c[1][d] = h * m0[d];
            c[2][d] = 3.0 * (y1[d] - y0[d]) - 2.0 * h * m0[d] - h * m1[d];
            c[3][d] = 2.0 * (y0[d] - y1[d]) + h * m0[d] + h * m1[d];
        }
        (t, h, c)
    }

    /// Each interval as `(s_i, s_{i+1}, Bezier control points)`: `y_i`, `y_i + h m_i / 3`,
    /// `y_{i+1} - h m_{i+1} / 3`, `y_{i+1}` (the Hermite cubic in Bernstein form).
    pub(crate) fn bezier_pieces(&self) -> impl Iterator<Item = (f64, f64, [[f64; D]; 4])> + '_ {
        (0..self.s.len() - 1).map(|i| {
            let h = self.s[i + 1] - self.s[i];
            let (y0, y1, m0, m1) = (self.y[i], self.y[i + 1], self.m[i], self.m[i + 1]);
            let b1 = std::array::from_fn(|d| y0[d] + h * m0[d] / 3.0);
            let b2 = std::array::from_fn(|d| y1[d] - h * m1[d] / 3.0);
            (self.s[i], self.s[i + 1], [y0, b1, b2, y1])
        })
    }

    /// The value at `s`.
    #[inline]
    pub(crate) fn at(&self, s: f64) -> [f64; D] {
        let (t, _, c) = self.piece(s);
        std::array::from_fn(|d| c[0][d] + t * (c[1][d] + t * (c[2][d] + t * c[3][d])))
    }

    /// The largest `|y''|` (Euclidean norm of the `D` components) anywhere: `y''` is linear on
    /// each interval, so its norm is largest at an interval's end.
    pub(crate) fn max_second_derivative(&self) -> f64 {
        let mut m = 0.0f64;
        for i in 0..self.s.len() - 1 {
            let (_, h, c) = self.piece_at(i, self.s[i]);
            for t in [0.0, 1.0] {
                let n2: f64 = (0..D)
                    .map(|d| ((2.0 * c[2][d] + 6.0 * t * c[3][d]) / (h * h)).powi(2))
                    .sum();
                m = m.max(n2.sqrt());
            }
        }
        m
    }

    /// The mean of the spline over `[s - w, s + w]` (`w > 0`), computed as `y(s)` plus the
    /// integral of `y(x) - y(s)` piece by piece, each piece expanded about `s` (so no large
    /// values cancel, however small `w`). A window over more than [`BOX_MEAN_DIRECT`] pieces
    /// takes its inner pieces' integrals from the segment tree (`O(log n)` instead of a loop
    /// over every piece: a blend over a run of 1e-6 mm pieces spent seconds here); there
    /// `sum - y(s) (s_b - s_a)` cancels to within `eps |y| log n`, the rounding of `y(s)`
    /// itself.
    pub(crate) fn box_mean(&self, s: f64, w: f64) -> [f64; D] {
        self.box_mean_over(s, w, BOX_MEAN_DIRECT)
    }

    /// [`Spline::box_mean`], summing windows over more than `direct` pieces from the tree.
    fn box_mean_over(&self, s: f64, w: f64, direct: usize) -> [f64; D] {
        let y = self.at(s);
        let (a, b) = (s - w, s + w);
        let (ia, ib) = (self.index(a), self.index(b));
        let mut acc = [0.0; D];
        let expanded = |j: usize, lo: f64, hi: f64, acc: &mut [f64; D]| {
            if hi <= lo {
                return;
            }
            let (t, h, c) = self.piece_at(j, s);
            let (l2, l3, l4) = (lo * lo, lo * lo * lo, lo * lo * lo * lo);
            let (h2, h3, h4) = (hi * hi, hi * hi * hi, hi * hi * hi * hi);
            for d in 0..D {
                // Taylor coefficients of piece j about s.
                let d0 = c[0][d] + t * (c[1][d] + t * (c[2][d] + t * c[3][d])) - y[d];
                let d1 = (c[1][d] + t * (2.0 * c[2][d] + 3.0 * t * c[3][d])) / h;
                let d2 = (2.0 * c[2][d] + 6.0 * t * c[3][d]) / (h * h);
                let d3 = 6.0 * c[3][d] / (h * h * h);
                acc[d] += d0 * (hi - lo)
                    + d1 * (h2 - l2) / 2.0
                    + d2 * (h3 - l3) / 6.0
                    + d3 * (h4 - l4) / 24.0;
            }
        };
        if ib - ia > direct {
            expanded(ia, a - s, self.s[ia + 1] - s, &mut acc);
            expanded(ib, self.s[ib] - s, b - s, &mut acc);
            let inner = self.piece_sum(ia + 1, ib);
            let span = self.s[ib] - self.s[ia + 1];
            for d in 0..D {
                acc[d] += inner[d] - y[d] * span;
            }
        } else {
            for j in ia..=ib {
                let lo = if j == ia { a } else { self.s[j] } - s;
                let hi = if j == ib { b } else { self.s[j + 1] } - s;
                expanded(j, lo, hi, &mut acc);
            }
        }
        std::array::from_fn(|d| y[d] + acc[d] / (2.0 * w))
    }

    /// The first three derivatives with respect to `s` at `s`.
    pub(crate) fn derivatives(&self, s: f64) -> [[f64; D]; 3] {
        let (t, h, c) = self.piece(s);
        [
            std::array::from_fn(|d| (c[1][d] + t * (2.0 * c[2][d] + 3.0 * t * c[3][d])) / h),
            std::array::from_fn(|d| (2.0 * c[2][d] + 6.0 * t * c[3][d]) / (h * h)),
            std::array::from_fn(|d| 6.0 * c[3][d] / (h * h * h)),
        ]
    }
}

/// One run: blocks `first..=last` of the program, smooth inside, at rest at both ends.
///
/// A cutting run moves the tip along its splines (the controller's tool-tip interpolation);
/// a rapid is one block, a run of its own, moved in the joints ([`Run::joint`]): the machine
/// runs a `G0` straight in its axes (the joint dialects write its end, the tool-tip ones split
/// it until it follows that line, `RAPID_TCP_TOLERANCE_MM`), and the traverse was checked
/// against the part along that line, so the plan moves the same way. Planned along the tip's
/// straight line instead, a rapid that turned a table by 251 degrees swung Z more than 470 mm
/// below both ends, out of the machine's travel (`docs/interpolation.md`).
#[derive(Debug, Clone)]
pub(crate) struct Run {
    /// First block (index into the planned blocks).
    pub(crate) first: usize,
    /// Last block.
    pub(crate) last: usize,
    /// Path parameter of each block's start along the run, and the run's length at the end.
    pub(crate) starts: Vec<f64>,
    /// Each block's own parameter (tip mm, degrees for a turn) per unit of the run's parameter:
    /// 1 where the tip's travel dominates, less where the rotary axes' does
    /// ([`block_param_length`]).
    pub(crate) ratio: Vec<f64>,
    /// Tip travel along the run, mm.
    pub(crate) tip_len: f64,
    /// True for cutting runs: the programmed feed caps the tip speed.
    pub(crate) cutting: bool,
    /// The tip moves (false for pure rotations and rapids: no feed or chord cap).
    pub(crate) moves_tip: bool,
    /// A rapid: `tip` holds the linear machine axes, not the tip, and the axes move straight
    /// from the block's start to its end (both splines linear).
    pub(crate) joint: bool,
    /// The share of the programmed feed this run cuts at (a small hole's feed factor, the
    /// least of its paths' [`crate::PlanOptions::feed_factors`]; 1 otherwise).
    pub(crate) feed_factor: f64,
    /// Where the tip turns sharply along the run (path parameters, sorted) and how far on
    /// each side the corner rule slows it, with its factor: `(corners, half-width, factor)`.
    pub(crate) corners: (Vec<f64>, f64, f64),
    /// The tip nodes' parameters (the planner's grid is refined from them).
    pub(crate) nodes: Vec<f64>,
    tip: Spline<3>,
    /// The rotary axes' spline, in the soft-limit coordinates of [`SoftRange`].
    rot: Spline<2>,
    /// The soft limits of the two rotary axes.
    soft: [SoftRange; 2],
    /// Half-width `W` of the blend (mm; 0: the tip follows its spline exactly).
    blend: f64,
}

impl Run {
    /// The share of the feed at parameter `s`: the corner rule's factor within its half-width
    /// of a corner, 1 elsewhere (the run's own [`Run::feed_factor`] comes on top).
    pub(crate) fn corner_factor(&self, s: f64) -> f64 {
        let (corners, half, factor) = &self.corners;
        let i = corners.partition_point(|&c| c < s - half);
        match corners.get(i) {
            Some(&c) if c <= s + half => *factor,
            _ => 1.0,
        }
    }

    /// Length of the run's path parameter (mm, degrees for a turn).
    pub(crate) fn len(&self) -> f64 {
        self.starts[self.starts.len() - 1]
    }

    /// Half-width of the blend's window at `s`: `W` in the middle, tapered to 0 at both ends
    /// by a C2 smooth step over `2 W`, so that the window `[s - w, s + w]` never leaves the run
    /// (`w(s) <= min(s, len - s)`) and the run's ends are exact.
    #[inline]
    pub(crate) fn blend_width(&self, s: f64) -> f64 {
        if self.blend <= 0.0 {
            return 0.0;
        }
        let step = |d: f64| {
            let t = (d / (2.0 * self.blend)).clamp(0.0, 1.0);
            t * t * t * (10.0 + t * (6.0 * t - 15.0))
        };
        self.blend * step(s) * step(self.len() - s)
    }

    /// The tip at `s`: the tip spline's mean over `[s - w(s), s + w(s)]` (the blend), or the
    /// spline itself.
    #[inline]
    fn tip_at(&self, s: f64) -> [f64; 3] {
        let w = self.blend_width(s);
        if w > 0.0 {
            self.tip.box_mean(s, w)
        } else {
            self.tip.at(s)
        }
    }

    /// The tip on the unblended spline at `s` (what the blend is measured against).
    pub(crate) fn spline_tip(&self, s: f64) -> Point3<f64> {
        let p = self.tip.at(s);
        Point3::new(p[0], p[1], p[2])
    }

    /// The tip spline (what the set-points follow before the blend).
    pub(crate) fn tip_spline(&self) -> &Spline<3> {
        &self.tip
    }

    /// True when the tip is blended (block starts are then not passed exactly).
    pub(crate) fn blended(&self) -> bool {
        self.blend > 0.0
    }

    /// Tip position and rotary axes `(tilt, C)` at `s`, the splines extended beyond the ends.
    #[inline]
    pub(crate) fn pose(&self, s: f64) -> (Point3<f64>, [f64; 2]) {
        let p = self.tip_at(s);
        let r = self.rot.at(s);
        (
            Point3::new(p[0], p[1], p[2]),
            [self.soft[0].apply(r[0]), self.soft[1].apply(r[1])],
        )
    }

    /// Machine axes at `s` without clamping (for derivatives by differences).
    #[inline]
    pub(crate) fn axes_raw<M: AxisModel + ?Sized>(&self, model: &M, s: f64) -> Axes {
        let (tip, r) = self.pose(s);
        if self.joint {
            return Axes::new(tip.x, tip.y, tip.z, r[0], r[1]);
        }
        let xyz = model.linear_axes(&tip, r[0], r[1]);
        Axes::new(xyz[0], xyz[1], xyz[2], r[0], r[1])
    }

    /// Machine axes at `s`: exactly the first block's start axes at `s <= 0`, the last block's
    /// end axes at `s >= len`, and a block's start axes at its start.
    #[inline]
    pub(crate) fn axes_at<M: AxisModel + ?Sized>(
        &self,
        model: &M,
        blocks: &[Block],
        s: f64,
    ) -> Axes {
        if s.is_nan() || s >= self.len() {
            return blocks[self.last].end_axes;
        }
        if s <= 0.0 {
            return blocks[self.first].start_axes;
        }
        let j = self.starts.partition_point(|&v| v < s);
        if !self.blended() && j < self.starts.len() && self.starts[j] == s {
            return blocks[self.first + j].start_axes;
        }
        self.axes_raw(model, s)
    }

    /// Tip derivatives `(t', t'')` with respect to `s`: of the blended tip by central
    /// differences, step 1e-3 mm or a quarter of the window, whichever is smaller, so that
    /// the differences stay inside the run (the window is at most `min(s, len - s)`); of the
    /// spline itself where the window is narrower than [`BLEND_MIN_MM`] (near a run's ends,
    /// where the mean is the spline to within `w^2 max |p''| / 6`, and differences over such a
    /// step would be rounding).
    pub(crate) fn tip_derivatives(&self, s: f64) -> (Vector3<f64>, Vector3<f64>) {
        let w = self.blend_width(s);
        if w >= BLEND_MIN_MM {
            let h = (0.25 * w).min(1e-3);
            let (a, b, c) = (self.tip_at(s - h), self.tip_at(s), self.tip_at(s + h));
            let d1 = Vector3::from(std::array::from_fn(|d| (c[d] - a[d]) / (2.0 * h)));
            let d2 = Vector3::from(std::array::from_fn(|d| {
                (c[d] - 2.0 * b[d] + a[d]) / (h * h)
            }));
            return (d1, d2);
        }
        let d = self.tip.derivatives(s);
        (Vector3::from(d[0]), Vector3::from(d[1]))
    }

    /// The block index (program) and the block's own parameter ([`Block::pose_at`]: tip mm,
    /// degrees for a turn) at run parameter `s`.
    pub(crate) fn block_at(&self, s: f64) -> (usize, f64) {
        let j = self
            .starts
            .partition_point(|&v| v <= s)
            .clamp(1, self.starts.len() - 1)
            - 1;
        (
            self.first + j,
            ((s - self.starts[j]) * self.ratio[j]).max(0.0),
        )
    }
}

/// Unit tangent of a block's tip path at its start (`at_end` false) or end, if it has one.
fn own_tangent(b: &Block, at_end: bool) -> Option<Vector3<f64>> {
    match &b.geometry {
        Geometry::Line { start, end } => Some((end - start).normalize()),
        Geometry::Arc(a) => Some(a.tangent_at_angle(if at_end { a.angle_end } else { 0.0 })),
        Geometry::Turn { .. } => None,
    }
}

/// The tangent of a line block at its end (or start), estimated from the circle through the
/// line and its neighbour's far end when the two have similar lengths (a polyline of cutting
/// points on a smooth curve: the circle's tangent is the curve's to second order); the line's
/// own direction otherwise (a long straight edge).
fn tangent(blocks: &[Block], b: usize, at_end: bool) -> Option<Vector3<f64>> {
    let blk = &blocks[b];
    let own = own_tangent(blk, at_end)?;
    if !matches!(blk.geometry, Geometry::Line { .. }) {
        return Some(own);
    }
    let nb = if at_end {
        b.checked_sub(1)
    } else {
        Some(b + 1).filter(|&n| n < blocks.len())
    };
    let Some(n) = nb.map(|n| &blocks[n]) else {
        return Some(own);
    };
    if n.rapid != blk.rapid || n.path != blk.path || matches!(n.geometry, Geometry::Turn { .. }) {
        return Some(own);
    }
    let ratio = n.length() / blk.length();
    if !(0.5..=2.0).contains(&ratio) {
        return Some(own);
    }
    let (p, q, r) = if at_end {
        (n.start_tip(), blk.start_tip(), blk.end_tip())
    } else {
        (blk.start_tip(), blk.end_tip(), n.end_tip())
    };
    match crate::geometry::SpaceArc::through(p, q, r) {
        Ok(a) => Some(a.tangent_at_angle(if at_end { a.angle_end } else { 0.0 })),
        Err(_) => Some(own),
    }
}

/// True when line `j` of a run, much longer than its neighbour line `n`, is a chord of the
/// curve that `n` and the line beyond it (`p`) sample, not a straight edge tangent to it.
///
/// On a polyline sampled from a smooth curve of curvature `k`, the chords turn by about
/// `k (a + b) / 2` where chords of lengths `a` and `b` meet. With `n` of length `a`, `p` of
/// length `a_p` and `j` of length `L`, the turn between `p` and `n` gives the curvature
/// `k_n = 2 theta_pn / (a + a_p)`, and the turn between `n` and `j` the curvature of `j`:
/// `k_j = (2 theta_nj - k_n a) / L`. An edge tangent to the curve has `k_j` about 0; a chord of
/// the curve (a short remainder chord of a discretized circle next to full ones) about `k_n`.
/// Chords of the curve are not graded: nodes on a chord pull the spline onto it, up to its
/// sagitta off the curve, and kink the curvature (the 70 mm hole, whose 0.17 mm span-end chords
/// sit between 1.66 mm ones, was slowed to 190 mm/s at each of them).
fn chord_of_curve(run: &[Block], j: usize, n: usize) -> bool {
    let Some(p) = (2 * n).checked_sub(j).filter(|&p| p < run.len()) else {
        return false;
    };
    let dir = |b: &Block| match &b.geometry {
        Geometry::Line { start, end } if (end - start).norm() > 0.0 => {
            Some(((end - start).normalize(), (end - start).norm()))
        }
        _ => None,
    };
    let (Some((dj, l)), Some((dn, a)), Some((dp, ap))) = (dir(&run[j]), dir(&run[n]), dir(&run[p]))
    else {
        return false;
    };
    // The turns p -> n and n -> j in the direction of travel must have the same sense (a
    // chord across an inflection is left to the length rule).
    let (pn, nj) = if j > n {
        (dp.cross(&dn), dn.cross(&dj))
    } else {
        (dn.cross(&dp), dj.cross(&dn))
    };
    if pn.dot(&nj) <= 0.0 {
        return false;
    }
    let (theta_pn, theta_nj) = (pn.norm().min(1.0).asin(), nj.norm().min(1.0).asin());
    let k_n = 2.0 * theta_pn / (a + ap);
    let k_j = (2.0 * theta_nj - k_n * a) / l;
    k_n > 0.0 && k_j >= 0.5 * k_n
}

/// Two neighbouring blocks whose lengths (in the run's parameter) differ by more than this
/// factor do not share a run: no grading of nodes (at most 4096 a block) can make the spacing
/// of an interpolating spline's nodes change gently across such a jump, and the C2 spline rings
/// (a 1 mm lead-in arc's 0.087 mm chord followed by a 1e-8 mm hole's chord swung the tip's
/// derivative to 9e5 and the run planned for 1,299 s).
pub(crate) const SPACING_BREAK: f64 = 1e5;

/// A line more than this many times a neighbour's node spacing is graded (`build`); where the
/// path parameter switches between the rotation and the tip's travel, a jump of the spacing
/// by more than this ends the run instead (`breaks`).
const GRADE_RATIO: f64 = 4.0;

/// True when blocks `a` and `a + 1` meet at a true corner (or must not share a run).
fn breaks(blocks: &[Block], a: usize, opts: &PathOptions) -> bool {
    let (x, y) = (&blocks[a], &blocks[a + 1]);
    // A rapid is a run of its own (a straight line of the joints, [`Run`]).
    if x.rapid || y.rapid || x.path != y.path {
        return true;
    }
    let (lx, ly) = (
        block_param_length(x, opts.rotary_mm_per_deg),
        block_param_length(y, opts.rotary_mm_per_deg),
    );
    if lx.max(ly) > SPACING_BREAK * lx.min(ly) {
        return true;
    }
    // Where the parameter switches between the rotation and the tip's travel (the tool turned
    // about a nearly still tip, and the tip starts to move, or the reverse), the tip's
    // derivative along `s` jumps from about 0 to 1 and the machine axes' direction turns: a
    // corner of the motion, whatever the tip's tangent says. Across a jump of the node
    // spacing there, the C2 tip spline can only be kept on the path by grading, at a cost of
    // nodes that grows with the jump (at a crease under the tilt cone: a 0.07 mm turn of a
    // 1.5e-8 mm tip next to a 8e-7 mm move, 21,000 nodes, 420,000 grid points planned).
    let rotation =
        |b: &Block, l: f64| !matches!(b.geometry, Geometry::Turn { .. }) && l > b.length();
    if rotation(x, lx) != rotation(y, ly) && lx.max(ly) > GRADE_RATIO * lx.min(ly) {
        return true;
    }
    // A corner of the rotary axes where the tip runs on smoothly: a bend of the surface ending
    // in a plane (the tilt turning 5.7 degrees per mm, then not at all). The C2 splines of a
    // run through such a kink overshoot the rotaries (measured: A to 113 degrees on a path
    // whose poses reach 90, the tool axis 66 degrees off them). The rotary axes' derivatives
    // along the path parameter, each in `[-1, 1]` in its millimetre equivalents, jumping by
    // more than ROTARY_KINK between two blocks end the run.
    let share = |b: &Block, l: f64| -> [f64; 2] {
        if l <= 0.0 {
            return [0.0; 2];
        }
        std::array::from_fn(|k| {
            (b.end_axes[3 + k] - b.start_axes[3 + k]) * opts.rotary_mm_per_deg[k] / l
        })
    };
    let (sx, sy) = (share(x, lx), share(y, ly));
    if (0..2).any(|k| (sx[k] - sy[k]).abs() > ROTARY_KINK) {
        return true;
    }
    let (Some(t0), Some(t1)) = (tangent(blocks, a, true), tangent(blocks, a + 1, false)) else {
        return true;
    };
    t0.dot(&t1) < CORNER_DEG.to_radians().cos()
}

/// The jump of a rotary axis' derivative along the path parameter (millimetre equivalents per
/// millimetre, at most 1 in size) between two blocks that ends a run (`breaks`).
const ROTARY_KINK: f64 = 0.5;

/// How the path is built: the rotary axes' ranges and the blend tolerance.
#[derive(Debug, Clone, Copy)]
pub(crate) struct PathOptions {
    /// Range of the tilt and the C axis (degrees), if limited.
    pub(crate) rotary_ranges: [Option<[f64; 2]>; 2],
    /// Largest distance of the blended tip from the tip spline, mm; 0 for no blend.
    pub(crate) blend_tolerance: f64,
    /// Millimetres of path parameter one degree of each rotary axis (tilt, C) counts for
    /// ([`block_param_length`]): the slowest linear axis' velocity limit over the rotary axis'
    /// own, over `plan::ROTATION_DOMINANCE` (5), so that the rotation counts only where it
    /// would take 5 times longer at its limit than the tip's travel at the linear one.
    pub(crate) rotary_mm_per_deg: [f64; 2],
}

/// The length of a block in the run's path parameter: the larger of its tip travel and its
/// rotary travel in millimetre equivalents (`max_k |dtheta_k| rotary_mm_per_deg_k`).
///
/// The tip's arc length alone is no parameter where the tool turns about a nearly fixed tip (a
/// pole, an edge the tool axis turns over): a block of 1e-6 mm that turns C by a degree has
/// `dC/ds` = 1e6 degrees per mm, its splines ring across the neighbouring blocks and the
/// planner crawls (a 201-pose trim line asked for 114 M cycles). Counting the rotation keeps
/// every axis' derivative bounded (`|q'_rot| <= 1 / rotary_mm_per_deg`), and the time-optimal
/// profile does not depend on the parameter. A rotation-free block keeps its tip length, so
/// programs whose tip travel dominates are planned as before.
pub(crate) fn block_param_length(b: &Block, rotary_mm_per_deg: [f64; 2]) -> f64 {
    let rot = (0..2)
        .map(|k| (b.end_axes[3 + k] - b.start_axes[3 + k]).abs() * rotary_mm_per_deg[k])
        .fold(0.0, f64::max);
    let rot = if b.is_arc() {
        // Piecewise through the middle station: the travel of both halves.
        (0..2)
            .map(|k| {
                ((b.mid_axes[3 + k] - b.start_axes[3 + k]).abs()
                    + (b.end_axes[3 + k] - b.mid_axes[3 + k]).abs())
                    * rotary_mm_per_deg[k]
            })
            .fold(rot, f64::max)
    } else {
        rot
    };
    match b.geometry {
        Geometry::Turn { .. } => {
            if rot > 0.0 {
                rot
            } else {
                b.length()
            }
        }
        _ => b.length().max(rot),
    }
}

/// Cuts the blocks into runs and builds each run's splines.
pub(crate) fn runs(blocks: &[Block], opts: &PathOptions) -> Vec<Run> {
    let mut out = Vec::new();
    let mut first = 0;
    for b in 0..blocks.len() {
        if b + 1 == blocks.len() || breaks(blocks, b, opts) {
            out.push(build(blocks, first, b, opts));
            first = b + 1;
        }
    }
    out
}

fn build(blocks: &[Block], first: usize, last: usize, opts: &PathOptions) -> Run {
    if first == last && blocks[first].rapid {
        return build_rapid(blocks, first, opts);
    }
    let run = &blocks[first..=last];
    let mut starts = Vec::with_capacity(run.len() + 1);
    let mut ratio = Vec::with_capacity(run.len());
    let plen: Vec<f64> = run
        .iter()
        .map(|b| block_param_length(b, opts.rotary_mm_per_deg))
        .collect();
    let mut s = 0.0;
    for (b, &l) in run.iter().zip(&plen) {
        starts.push(s);
        ratio.push(b.length() / l);
        s += l;
    }
    starts.push(s);
    // Node spacing of each block (before line subdivision).
    let arc_parts = |b: &Block| match &b.geometry {
        Geometry::Arc(a) => (a.angle_end.to_degrees() / ARC_NODE_DEG).ceil().max(2.0) as usize,
        _ => 1,
    };
    // Node spacing of each block: an arc's own; a line's at most twice its neighbours' largest
    // (a line much longer than both is an edge, not a chord of a curve), and graded where it is
    // more than 4 times a neighbour's. A C2 interpolating
    // spline rings where the node spacing jumps: a 10 mm edge next to 0.78 mm nodes of a rounded
    // corner swung 0.11 mm off the contour. Chords of a smooth curve, whose lengths change by
    // less than 4 times from one to the next, get no nodes on them (a node on a chord pulls the
    // spline onto it, up to the chord's sagitta off the curve).
    let is_line = |b: &Block| matches!(b.geometry, Geometry::Line { .. });
    let own: Vec<f64> = run
        .iter()
        .zip(&plen)
        .map(|(b, l)| l / arc_parts(b) as f64)
        .collect();
    let mut spacing = own.clone();
    for j in 0..run.len() {
        if is_line(&run[j]) {
            let nb = [j.checked_sub(1), Some(j + 1).filter(|&n| n < run.len())]
                .into_iter()
                .flatten()
                .map(|n| own[n])
                .fold(0.0, f64::max);
            if nb > 0.0 {
                spacing[j] = spacing[j].min(2.0 * nb);
            }
        }
    }
    // A line is graded at an end where it is more than 4 times the neighbour's node spacing at
    // that end (or, once graded at one end, wherever it is more than twice a neighbour's): its
    // nodes start there at twice the neighbour's spacing and double away from it
    // ([`graded_nodes`]), up to the line's spacing. End spacings only decrease, so the passes
    // end; at most 64 of them.
    let mut ends: Vec<[Option<f64>; 2]> = vec![[None; 2]; run.len()];
    let end_spacing =
        |ends: &[[Option<f64>; 2]], n: usize, side: usize| match graded_evenly(plen[n], ends[n]) {
            Some(e) => e,
            None => ends[n][side].unwrap_or(spacing[n]),
        };
    for _ in 0..64 {
        let mut changed = false;
        for j in 0..run.len() {
            if !is_line(&run[j]) || spacing[j] <= 0.0 {
                continue;
            }
            // Side 0 is the line's start (its neighbour's end, side 1), side 1 its end.
            for (side, n) in [
                (0, j.checked_sub(1)),
                (1, Some(j + 1).filter(|&n| n < run.len())),
            ] {
                let Some(n) = n else { continue };
                let h = end_spacing(&ends, n, 1 - side);
                let here = end_spacing(&ends, j, side);
                let graded = ends[j].iter().any(Option::is_some);
                if h > 0.0
                    && here > 2.0 * h
                    && (graded || (own[j] > GRADE_RATIO * h && !chord_of_curve(run, j, n)))
                {
                    ends[j][side] = Some(2.0 * h);
                    changed = true;
                }
            }
        }
        if !changed {
            break;
        }
    }
    let mut ts = Vec::new();
    let mut ty: Vec<[f64; 3]> = Vec::new();
    let mut rs = Vec::new();
    let mut ry: Vec<[f64; 2]> = Vec::new();
    let moves_tip = run
        .iter()
        .all(|b| !matches!(b.geometry, Geometry::Turn { .. }));
    for (j, b) in run.iter().enumerate() {
        let s0 = starts[j];
        // Fractions of the block where the tip spline gets a node (its start first).
        let fractions: Vec<f64> = match &b.geometry {
            Geometry::Arc(_) => {
                let parts = arc_parts(b);
                (0..parts).map(|k| k as f64 / parts as f64).collect()
            }
            // Lines longer than their spacing get nodes on the line, so that the spline does
            // not bulge between far-apart nodes.
            Geometry::Line { .. } if spacing[j] > 0.0 => graded_nodes(plen[j], spacing[j], ends[j]),
            Geometry::Line { .. } | Geometry::Turn { .. } => vec![0.0],
        };
        for f in fractions {
            let sk = s0 + plen[j] * f;
            let (tip, _, _) = b.pose_at(b.length() * f);
            ts.push(sk);
            ty.push([tip.x, tip.y, tip.z]);
        }
        rs.push(s0);
        ry.push([b.start_axes.tilt, b.start_axes.c]);
        let mid = b.mid_length();
        if b.is_arc() && mid > 0.0 && mid < b.length() {
            rs.push(s0 + mid / ratio[j]);
            ry.push([b.mid_axes.tilt, b.mid_axes.c]);
        }
    }
    let end = &run[run.len() - 1];
    ts.push(s);
    let e = end.end_tip();
    ty.push([e.x, e.y, e.z]);
    rs.push(s);
    ry.push([end.end_axes.tilt, end.end_axes.c]);
    let (m0, m1) = if moves_tip {
        // The curve's tangent where it can be estimated (circle through the neighbours), the
        // neighbour taken inside the run only: a run of one block ends at corners on both
        // sides, and the circle through the block and the next run's block (across the
        // corner) tilted a 275 mm edge's end slopes enough to bulge it 35 mm off the contour.
        let end_tangent = |b: usize, at_end: bool| {
            if first == last {
                own_tangent(&blocks[b], at_end)
            } else {
                tangent(blocks, b, at_end)
            }
        };
        // Unit tangents per tip mm, times the tip mm per unit of the run's parameter.
        let a = end_tangent(first, false).unwrap_or_else(Vector3::zeros) * ratio[0];
        let b = end_tangent(last, true).unwrap_or_else(Vector3::zeros) * ratio[ratio.len() - 1];
        ([a.x, a.y, a.z], [b.x, b.y, b.z])
    } else {
        ([0.0; 3], [0.0; 3])
    };
    // The rotary spline runs through the stations' soft-limit coordinates.
    let soft = opts.rotary_ranges.map(SoftRange::new);
    for r in &mut ry {
        *r = [soft[0].invert(r[0]), soft[1].invert(r[1])];
    }
    let slope = |i: usize, j: usize| -> [f64; 2] {
        let h = rs[j] - rs[i];
        [(ry[j][0] - ry[i][0]) / h, (ry[j][1] - ry[i][1]) / h]
    };
    let n = rs.len();
    let (r0, r1) = (slope(0, 1), slope(n - 2, n - 1));
    let tip = Spline::clamped(ts.clone(), ty, m0, m1);
    // The blend's half-width: the mean over [s - w, s + w] is within w^2 / 6 max |p''| of p(s)
    // (Taylor: |p(s + x) - p(s) - x p'(s)| <= x^2 / 2 max |p''|, the linear term averages out).
    let blend = if moves_tip && opts.blend_tolerance > 0.0 {
        let m = tip.max_second_derivative();
        let w = if m > 0.0 {
            (6.0 * opts.blend_tolerance / m).sqrt().min(BLEND_MAX_MM)
        } else {
            BLEND_MAX_MM
        };
        // A narrower window blends nothing: it belongs to curvatures of over `6 e / W^2`
        // (radii under a nanometre at 5 um), and the derivatives of the mean by differences
        // would be rounding (a 1e-8 mm hole's window was 5e-20 mm).
        if w >= BLEND_MIN_MM {
            w
        } else {
            0.0
        }
    } else {
        0.0
    };
    Run {
        first,
        last,
        cutting: !run[0].rapid,
        moves_tip,
        joint: false,
        feed_factor: 1.0,
        corners: (Vec::new(), 0.0, 1.0),
        nodes: ts,
        tip,
        rot: Spline::clamped(rs, ry, r0, r1),
        soft,
        blend,
        starts,
        ratio,
        tip_len: if moves_tip {
            run.iter().map(Block::length).sum()
        } else {
            0.0
        },
    }
}

/// The run of rapid `b`: its joints straight from the start to the end ([`Run::joint`]), over
/// the block's path parameter ([`block_param_length`]).
fn build_rapid(blocks: &[Block], b: usize, opts: &PathOptions) -> Run {
    let blk = &blocks[b];
    let len = block_param_length(blk, opts.rotary_mm_per_deg);
    let (q0, q1) = (blk.start_axes, blk.end_axes);
    // Straight in the rotary axes themselves (both ends are within their ranges, so is the
    // line), not in the soft-limit coordinates of a cutting run.
    let soft = [SoftRange::new(None), SoftRange::new(None)];
    let (r0, r1) = ([q0[3], q0[4]], [q1[3], q1[4]]);
    let slope = |a: &[f64], b: &[f64]| -> Vec<f64> {
        a.iter().zip(b).map(|(a, b)| (b - a) / len).collect()
    };
    let (l0, l1) = (q0.to_array(), q1.to_array());
    let (dl, dr) = (slope(&l0[..3], &l1[..3]), slope(&r0, &r1));
    let dl = [dl[0], dl[1], dl[2]];
    let dr = [dr[0], dr[1]];
    Run {
        first: b,
        last: b,
        cutting: false,
        moves_tip: false,
        joint: true,
        feed_factor: 1.0,
        corners: (Vec::new(), 0.0, 1.0),
        nodes: vec![0.0, len],
        tip: Spline::clamped(
            vec![0.0, len],
            vec![[q0[0], q0[1], q0[2]], [q1[0], q1[1], q1[2]]],
            dl,
            dl,
        ),
        rot: Spline::clamped(vec![0.0, len], vec![r0, r1], dr, dr),
        soft,
        blend: 0.0,
        starts: vec![0.0, len],
        ratio: vec![blk.length() / len],
        tip_len: 0.0,
    }
}

/// The most nodes one line gets from [`graded_nodes`].
const MAX_LINE_NODES: usize = 4096;

/// A graded line that takes at most this many nodes at its smallest end spacing gets them
/// evenly spaced (the spline then follows the line closely all along: a long chord at an
/// inflection of a free-form curve stays within its certified distance); more, and the nodes
/// grow geometrically from the graded ends.
const EVEN_GRADE_NODES: f64 = 64.0;

/// The spacing of a graded line's even nodes (its smallest end spacing) when it takes at most
/// [`EVEN_GRADE_NODES`] of them; `None` for an ungraded line or a geometric grading.
fn graded_evenly(len: f64, ends: [Option<f64>; 2]) -> Option<f64> {
    let e = ends.iter().flatten().copied().reduce(f64::min)?;
    (len / e <= EVEN_GRADE_NODES).then_some(e)
}

/// The nodes of a line of length `len` (the run's parameter) as fractions of it, its start
/// first and its end left out: at most `spacing` apart; graded to end spacings `e` (`ends`:
/// start, end) evenly at the smaller where that takes few nodes ([`graded_evenly`]), else
/// growing geometrically from each graded end: the spacing at distance `x` from that end
/// is `e + x`, so each step is at most twice the one before it and a line graded from `e` to
/// `spacing` takes `log2(spacing / e)` nodes, not `spacing / e` (a 0.07 mm line after a
/// 1e-6 mm one got 4,096 uniform nodes, and the planner seconds of work on them).
///
/// The two ends march towards each other, the one with the smaller step first, until the gap
/// they leave is at most twice the smaller next step; the gap is then split into one or two
/// equal steps (each more than half the last one).
/// Past [`MAX_LINE_NODES`] the line is split evenly into that many.
fn graded_nodes(len: f64, spacing: f64, ends: [Option<f64>; 2]) -> Vec<f64> {
    let uniform = |h: f64| -> Vec<f64> {
        let parts = ((len / h * (1.0 - 1e-12)).ceil() as usize).clamp(1, MAX_LINE_NODES);
        (0..parts).map(|k| k as f64 / parts as f64).collect()
    };
    if ends == [None, None] {
        return uniform(spacing);
    }
    if let Some(e) = graded_evenly(len, ends) {
        return uniform(e);
    }
    let step = |e: Option<f64>, x: f64| e.map_or(spacing, |e| (e + x).min(spacing));
    let (mut lo, mut hi) = (vec![0.0], vec![len]);
    loop {
        let (xl, xr) = (lo[lo.len() - 1], hi[hi.len() - 1]);
        let (sl, sr) = (step(ends[0], xl), step(ends[1], len - xr));
        let gap = xr - xl;
        if lo.len() + hi.len() > MAX_LINE_NODES {
            return uniform(len / MAX_LINE_NODES as f64);
        }
        let least = sl.min(sr);
        if gap <= 2.0 * least {
            let parts = ((gap / least * (1.0 - 1e-12)).ceil() as usize).max(1);
            for k in 1..parts {
                lo.push(xl + gap * k as f64 / parts as f64);
            }
            break;
        }
        if sl <= sr {
            lo.push(xl + sl);
        } else {
            hi.push(xr - sr);
        }
    }
    // `hi` holds the end itself first: the line's end is the next block's start node.
    lo.extend(hi.iter().skip(1).rev());
    lo.iter().map(|x| x / len).collect()
}

/// Largest half-width of the blend, mm (bounds the pieces one mean spans).
const BLEND_MAX_MM: f64 = 10.0;
/// Smallest half-width of the blend, mm: below it the tip follows its spline unblended.
const BLEND_MIN_MM: f64 = 1e-4;
/// Width of the soft band inside a rotary axis' limits, degrees (at most a quarter of the range).
pub(crate) const ROTARY_SOFT_DEG: f64 = 0.5;

/// A C2, non-decreasing map `phi` of the real line onto an axis range `[lo, hi]`: the identity
/// on `[lo + m, hi - m]`, on the upper band `phi(y) = hi - m + m psi((y - hi + m) / m)` with
/// `psi(t) = t + 4 t^3 - 7 t^4 + 3 t^5` (`psi(0) = 0`, `psi'(0) = 1`, `psi''(0) = 0`,
/// `psi(1) = 1`, `psi'(1) = psi''(1) = 0`, `psi' = (1 - t)^2 (15 t^2 + 2 t + 1) >= 0`), `hi`
/// beyond, the lower band mirrored. The rotary spline interpolates `phi^-1` of the stations, so
/// the axis passes every station exactly and, whatever the spline does between stations, never
/// leaves `[lo, hi]`.
#[derive(Debug, Clone, Copy)]
pub(crate) struct SoftRange {
    range: Option<[f64; 2]>,
    band: f64,
}

impl SoftRange {
    pub(crate) fn new(range: Option<[f64; 2]>) -> Self {
        let band = range.map_or(0.0, |[lo, hi]| ROTARY_SOFT_DEG.min(0.25 * (hi - lo)));
        Self {
            range: range.filter(|[lo, hi]| hi > lo && lo.is_finite() && hi.is_finite()),
            band,
        }
    }

    /// `hi - m + m psi(t)` for `y` in the upper band of `hi` (identity below, `hi` above).
    #[inline]
    fn upper(y: f64, hi: f64, m: f64) -> f64 {
        let t = (y - (hi - m)) / m;
        if t <= 0.0 {
            y
        } else if t >= 1.0 {
            hi
        } else {
            let psi = t + t * t * t * (4.0 + t * (3.0 * t - 7.0));
            (hi - m + m * psi).min(hi)
        }
    }

    /// `phi(y)`.
    #[inline]
    pub(crate) fn apply(&self, y: f64) -> f64 {
        match self.range {
            Some([lo, hi]) => -Self::upper(-Self::upper(y, hi, self.band), -lo, self.band),
            None => y,
        }
    }

    /// `phi^-1(y)` for `y` in `[lo, hi]` (by bisection: `phi` is increasing on the bands, with
    /// `phi(y) >= y` on the upper band); `y` itself outside the range.
    pub(crate) fn invert(&self, y: f64) -> f64 {
        let Some([lo, hi]) = self.range else {
            return y;
        };
        let m = self.band;
        if !(y > lo && y < hi) || (y >= lo + m && y <= hi - m) {
            return y;
        }
        // Upper band: phi^-1(y) in [hi - m, y]; lower band: in [y, lo + m].
        let (mut a, mut b) = if y > hi - m { (hi - m, y) } else { (y, lo + m) };
        for _ in 0..200 {
            let mid = 0.5 * (a + b);
            if mid <= a || mid >= b {
                break;
            }
            if self.apply(mid) < y {
                a = mid;
            } else {
                b = mid;
            }
        }
        b
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_soft_range_keeps_a_swinging_spline_inside_and_passes_every_station() {
        // A tent of tilts peaking exactly on the limit: the plain C2 spline swings past it, the
        // spline of the soft-range coordinates mapped back does not, and hits every station.
        let hi = 30.0;
        let s: Vec<f64> = (0..=40).map(|i| i as f64).collect();
        // Steeper up than down: the spline's slope at the peak is not 0.
        let tent = |v: f64| {
            hi - if v < 20.0 {
                0.75 * (20.0 - v)
            } else {
                0.25 * (v - 20.0)
            }
        };
        let y: Vec<[f64; 1]> = s.iter().map(|&v| [tent(v)]).collect();
        let plain = Spline::clamped(s.clone(), y.clone(), [0.75], [-0.25]);
        let over = (0..=4000)
            .map(|i| plain.at(i as f64 * 0.01)[0])
            .fold(f64::NEG_INFINITY, f64::max);
        println!("plain spline peak {over}");
        assert!(over > hi + 0.01, "the plain spline overshoots: {over}");
        let soft = SoftRange::new(Some([-hi, hi]));
        let z: Vec<[f64; 1]> = y.iter().map(|v| [soft.invert(v[0])]).collect();
        let sp = Spline::clamped(s.clone(), z, [0.75], [-0.25]);
        for i in 0..=4000 {
            let v = soft.apply(sp.at(i as f64 * 0.01)[0]);
            assert!(v <= hi && v >= -hi, "{v}");
        }
        for (si, yi) in s.iter().zip(&y) {
            let v = soft.apply(sp.at(*si)[0]);
            assert!((v - yi[0]).abs() < 1e-12, "station {si}: {v} vs {}", yi[0]);
        }
        // The map is C2 where its bands meet the identity and the limit.
        let m = ROTARY_SOFT_DEG;
        for y0 in [hi - m, hi] {
            let h = 1e-4;
            let d2 =
                |y: f64| (soft.apply(y + h) - 2.0 * soft.apply(y) + soft.apply(y - h)) / (h * h);
            assert!(
                (d2(y0 - 2.0 * h) - d2(y0 + 2.0 * h)).abs() < 0.05,
                "y'' at {y0}"
            );
        }
    }

    #[test]
    fn graded_nodes_double_from_the_graded_ends() {
        // Steps within a factor 2 of each other (3 where the ends meet), the graded end's first
        // step as asked, none over the spacing, and a count logarithmic in spacing / e.
        for (len, spacing, ends) in [
            (0.07, 0.07, [Some(2e-6), None]),
            (0.07, 0.07, [None, Some(2e-6)]),
            (1.0, 0.1, [Some(1e-9), Some(3e-7)]),
            (5e-6, 5e-6, [Some(2e-6), Some(2e-6)]),
            (10.0, 1.5, [None, None]),
        ] {
            let f = graded_nodes(len, spacing, ends);
            let mut x: Vec<f64> = f.iter().map(|v| v * len).collect();
            x.push(len);
            let steps: Vec<f64> = x.windows(2).map(|w| w[1] - w[0]).collect();
            assert_eq!(f[0], 0.0);
            assert!(
                steps
                    .iter()
                    .all(|&h| h > 0.0 && h <= spacing * (1.0 + 1e-12)),
                "{steps:?}"
            );
            for w in steps.windows(2) {
                let r = w[1] / w[0];
                assert!((1.0 / 3.0..=3.0).contains(&r), "{len} {ends:?}: {steps:?}");
            }
            for (e, h) in [(ends[0], steps[0]), (ends[1], steps[steps.len() - 1])] {
                if let Some(e) = e {
                    assert!(h <= e * (1.0 + 1e-9), "{len} {ends:?}: {h} from {e}");
                }
            }
            let e = ends.iter().flatten().fold(spacing, |a, &b| a.min(b));
            let most = 2.0 * (spacing / e).log2() + len / spacing + 4.0;
            assert!(
                (steps.len() as f64) <= most,
                "{len} {ends:?}: {} steps",
                steps.len()
            );
        }
    }

    #[test]
    fn the_box_mean_of_a_cubic_is_exact() {
        // The mean of p(x) = x^3 over [s - w, s + w] is s^3 + s w^2 (the odd moments vanish),
        // across pieces and however small w.
        let f = |s: f64| [s * s * s];
        let s: Vec<f64> = vec![0.0, 0.3, 1.1, 1.5, 2.6, 3.0];
        let y: Vec<[f64; 1]> = s.iter().map(|&v| f(v)).collect();
        let sp = Spline::clamped(s, y, [0.0], [27.0]);
        for (c, w) in [(1.0, 0.9), (1.4, 0.05), (2.0, 1e-9), (0.5, 0.49)] {
            let got = sp.box_mean(c, w)[0];
            let want = c * c * c + c * w * w;
            assert!((got - want).abs() < 1e-12, "{c} {w}: {got} vs {want}");
        }
        // Windows over many pieces (the inner ones summed from the segment tree), at nodes
        // spaced irregularly from 1e-6 to 0.1: still exact, and equal to the sum piece by piece.
        let mut s = vec![0.0];
        let mut h = 1e-6;
        while s[s.len() - 1] < 3.0 {
            s.push(s[s.len() - 1] + h);
            h = if h > 0.1 { 1e-6 } else { h * 1.7 };
        }
        let y: Vec<[f64; 1]> = s.iter().map(|&v| f(v)).collect();
        let end = s[s.len() - 1];
        let sp = Spline::clamped(s.clone(), y, [0.0], [3.0 * end * end]);
        for (c, w) in [(1.0, 0.9), (1.4, 0.35), (2.0, 0.6), (0.5, 0.49)] {
            let (ia, ib) = (sp.index(c - w), sp.index(c + w));
            assert!(ib - ia > BOX_MEAN_DIRECT, "{c} {w}: {} pieces", ib - ia);
            let got = sp.box_mean(c, w)[0];
            let want = c * c * c + c * w * w;
            let by_piece = sp.box_mean_over(c, w, usize::MAX)[0];
            assert!(
                (got - by_piece).abs() < 1e-14,
                "{c} {w}: {got} vs {by_piece}"
            );
            // The spline through nodes 1e-6 apart is the cubic to within rounding (5e-12).
            assert!((got - want).abs() < 1e-10, "{c} {w}: {got} vs {want}");
        }
    }

    #[test]
    fn spline_reproduces_a_cubic_and_is_c2() {
        // A clamped spline through samples of a cubic with its exact end slopes is that cubic.
        let f = |s: f64| [s * s * s - 2.0 * s, 0.5 * s * s];
        let df = |s: f64| [3.0 * s * s - 2.0, s];
        let s: Vec<f64> = vec![0.0, 0.3, 1.1, 1.5, 2.6, 3.0];
        let y: Vec<[f64; 2]> = s.iter().map(|&v| f(v)).collect();
        let sp = Spline::clamped(s, y, df(0.0), df(3.0));
        for i in 0..=60 {
            let v = i as f64 * 0.05;
            let (a, b) = (sp.at(v), f(v));
            assert!(
                (a[0] - b[0]).abs() < 1e-12 && (a[1] - b[1]).abs() < 1e-12,
                "{v}"
            );
            let d = sp.derivatives(v);
            assert!((d[1][0] - 6.0 * v).abs() < 1e-9, "second derivative at {v}");
            assert!((d[2][0] - 6.0).abs() < 1e-9, "third derivative at {v}");
        }
    }
}
