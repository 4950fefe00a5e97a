//! The path the machine follows: the blocks of a program cut into *runs* at true corners, and
//! along each run a smooth (C2) interpolant of the poses.
//!
//! A run is a chain of blocks of one path with no true corner inside: the tool-tip tangent
//! turns by at most [`CORNER_DEG`] where two blocks meet. Rapid moves, pure rotations
//! ([`Geometry::Turn`]) and path changes also end a run. The planner brings the machine to rest
//! at every run end (a true corner cannot be passed at speed) and nowhere else.
//!
//! Along a run the tip is a clamped C2 cubic spline through the block ends, the arcs'
//! intermediate points and points of every arc at most [`ARC_NODE_DEG`] apart (so the spline
//! follows the arcs within a few micrometres), parameterized by the blocks' own arc length `s`;
//! the rotary axes are a second clamped C2 cubic spline through the stations (block ends and arc
//! intermediate points). The linear axes follow from the machine model at every `s`. The ends
//! are clamped to the tangent of the first and last block, and a run's ends, and every block's
//! start, are returned exactly as the stations' axes. The math is in `docs/interpolation.md`.

use crate::block::{Block, Geometry};
use crate::model::AxisModel;
use nalgebra::{Point3, Vector3};

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
        Self { s, y, m }
    }

    /// The cubic's coefficients on the interval holding `s` (the end intervals extended beyond
    /// the ends): `(t, h, [a, b, c, d])` with `p = a + b t + c t^2 + d t^3`, `t = (s - s_i) / h`.
    #[inline]
    fn piece(&self, s: f64) -> (f64, f64, [[f64; D]; 4]) {
        let n = self.s.len();
        let i = self.s.partition_point(|&v| v <= s).clamp(1, n - 1) - 1;
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

    /// The value at `s`.
    #[inline]
    pub(crate) fn at(&self, s: f64) -> [f64; D] {
        let (t, _, c) = self.piece(s);
        std::array::from_fn(|d| c[0][d] + t * (c[1][d] + t * (c[2][d] + t * c[3][d])))
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
#[derive(Debug, Clone)]
pub(crate) struct Run {
    /// First block (index into the planned blocks).
    pub(crate) first: usize,
    /// Last block.
    pub(crate) last: usize,
    /// Path parameter of each block's start along the run, and the run's length at the end.
    pub(crate) starts: Vec<f64>,
    /// True for cutting runs: the programmed feed caps the tip speed.
    pub(crate) cutting: bool,
    /// The tip moves (false for pure rotations: no feed or chord cap).
    pub(crate) moves_tip: bool,
    /// The tip nodes' parameters (the planner's grid is refined from them).
    pub(crate) nodes: Vec<f64>,
    tip: Spline<3>,
    rot: Spline<2>,
}

impl Run {
    /// Length of the run's path parameter (mm, degrees for a turn).
    pub(crate) fn len(&self) -> f64 {
        self.starts[self.starts.len() - 1]
    }

    /// Tip position and rotary axes `(tilt, C)` at `s`, the splines extended beyond the ends.
    #[inline]
    pub(crate) fn pose(&self, s: f64) -> (Point3<f64>, [f64; 2]) {
        let p = self.tip.at(s);
        (Point3::new(p[0], p[1], p[2]), self.rot.at(s))
    }

    /// Machine axes at `s` without clamping (for derivatives by differences).
    #[inline]
    pub(crate) fn axes_raw<M: AxisModel + ?Sized>(&self, model: &M, s: f64) -> [f64; 5] {
        let (tip, r) = self.pose(s);
        let xyz = model.linear_axes(&tip, r[0], r[1]);
        [xyz[0], xyz[1], xyz[2], r[0], r[1]]
    }

    /// Machine axes at `s`: exactly the first block's start axes at `s <= 0`, the last block's
    /// end axes at `s >= len`, and a block's start axes at its start.
    #[inline]
    pub(crate) fn axes_at<M: AxisModel + ?Sized>(
        &self,
        model: &M,
        blocks: &[Block],
        s: f64,
    ) -> [f64; 5] {
        if s.is_nan() || s >= self.len() {
            return blocks[self.last].end_axes;
        }
        if s <= 0.0 {
            return blocks[self.first].start_axes;
        }
        let j = self.starts.partition_point(|&v| v < s);
        if j < self.starts.len() && self.starts[j] == s {
            return blocks[self.first + j].start_axes;
        }
        self.axes_raw(model, s)
    }

    /// Tip derivatives `(t', t'')` with respect to `s`.
    pub(crate) fn tip_derivatives(&self, s: f64) -> (Vector3<f64>, Vector3<f64>) {
        let d = self.tip.derivatives(s);
        (Vector3::from(d[0]), Vector3::from(d[1]))
    }

    /// The block index (program) and the parameter within it at run parameter `s`.
    pub(crate) fn block_at(&self, s: f64) -> (usize, f64) {
        let j = self
            .starts
            .partition_point(|&v| v <= s)
            .clamp(1, self.starts.len() - 1)
            - 1;
        (self.first + j, (s - self.starts[j]).max(0.0))
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

/// True when blocks `a` and `a + 1` meet at a true corner (or must not share a run).
fn breaks(blocks: &[Block], a: usize) -> bool {
    let (x, y) = (&blocks[a], &blocks[a + 1]);
    if x.rapid != y.rapid || x.path != y.path {
        return true;
    }
    let (Some(t0), Some(t1)) = (tangent(blocks, a, true), tangent(blocks, a + 1, false)) else {
        return true;
    };
    t0.dot(&t1) < CORNER_DEG.to_radians().cos()
}

/// Cuts the blocks into runs and builds each run's splines.
pub(crate) fn runs(blocks: &[Block]) -> Vec<Run> {
    let mut out = Vec::new();
    let mut first = 0;
    for b in 0..blocks.len() {
        if b + 1 == blocks.len() || breaks(blocks, b) {
            out.push(build(blocks, first, b));
            first = b + 1;
        }
    }
    out
}

fn build(blocks: &[Block], first: usize, last: usize) -> Run {
    let run = &blocks[first..=last];
    let mut starts = Vec::with_capacity(run.len() + 1);
    let mut s = 0.0;
    for b in run {
        starts.push(s);
        s += b.length();
    }
    starts.push(s);
    // Node spacing of each block (before line subdivision).
    let arc_parts = |b: &Block| match &b.geometry {
        Geometry::Arc(a) => (a.angle_end.to_degrees() / ARC_NODE_DEG).ceil().max(2.0) as usize,
        _ => 1,
    };
    let spacing: Vec<f64> = run
        .iter()
        .map(|b| b.length() / arc_parts(b) as f64)
        .collect();
    let mut ts = Vec::new();
    let mut ty: Vec<[f64; 3]> = Vec::new();
    let mut rs = Vec::new();
    let mut ry: Vec<[f64; 2]> = Vec::new();
    let moves_tip = run
        .iter()
        .all(|b| !matches!(b.geometry, Geometry::Turn { .. }));
    for (j, b) in run.iter().enumerate() {
        let s0 = starts[j];
        let parts = match &b.geometry {
            Geometry::Arc(_) => arc_parts(b),
            Geometry::Line { .. } => {
                // Lines much longer than their neighbours' node spacing get nodes on the line,
                // so that the spline does not bulge between far-apart nodes.
                let nb = [j.checked_sub(1), Some(j + 1).filter(|&n| n < run.len())]
                    .into_iter()
                    .flatten()
                    .map(|n| spacing[n])
                    .fold(0.0, f64::max);
                if nb > 0.0 {
                    ((b.length() / (2.0 * nb)).ceil() as usize).clamp(1, 4096)
                } else {
                    1
                }
            }
            Geometry::Turn { .. } => 1,
        };
        for k in 0..parts {
            let sk = s0 + b.length() * k as f64 / parts as f64;
            let (tip, _, _) = b.pose_at(sk - s0);
            ts.push(sk);
            ty.push([tip.x, tip.y, tip.z]);
        }
        rs.push(s0);
        ry.push([b.start_axes[3], b.start_axes[4]]);
        let mid = b.mid_length();
        if b.is_arc() && mid > 0.0 && mid < b.length() {
            rs.push(s0 + mid);
            ry.push([b.mid_axes[3], b.mid_axes[4]]);
        }
    }
    let end = &run[run.len() - 1];
    ts.push(s);
    let e = end.end_tip();
    ty.push([e.x, e.y, e.z]);
    rs.push(s);
    ry.push([end.end_axes[3], end.end_axes[4]]);
    let (m0, m1) = if moves_tip {
        // The curve's tangent where it can be estimated (circle through the neighbours).
        let a = tangent(blocks, first, false).unwrap_or_else(Vector3::zeros);
        let b = tangent(blocks, last, true).unwrap_or_else(Vector3::zeros);
        ([a.x, a.y, a.z], [b.x, b.y, b.z])
    } else {
        ([0.0; 3], [0.0; 3])
    };
    let slope = |i: usize, j: usize| -> [f64; 2] {
        let h = rs[j] - rs[i];
        [(ry[j][0] - ry[i][0]) / h, (ry[j][1] - ry[i][1]) / h]
    };
    let n = rs.len();
    let (r0, r1) = (slope(0, 1), slope(n - 2, n - 1));
    Run {
        first,
        last,
        cutting: !run[0].rapid,
        moves_tip,
        nodes: ts.clone(),
        tip: Spline::clamped(ts, ty, m0, m1),
        rot: Spline::clamped(rs, ry, r0, r1),
        starts,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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
