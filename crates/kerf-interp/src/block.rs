//! Blocks: the lines and arcs a program is made of, with the rotary axes along them, and the
//! constant-feed time-division interpolation of one block (paper 000 eq 1-12).

use kerf_kinematics::Axes;
use nalgebra::{Point3, Vector3};

use crate::error::{positive, InterpError, Result};
use crate::geometry::SpaceArc;
use crate::model::AxisModel;

/// Below this tip travel (mm) a block is a pure rotation ([`Geometry::Turn`]).
pub const MIN_TRAVEL: f64 = 1e-9;

/// One cutting point with everything the interpolator needs: the pose, its curve parameter
/// (when known) and the machine axes that reach it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Station {
    /// Tool tip, workpiece frame, mm.
    pub tip: Point3<f64>,
    /// Unit tool axis (tip toward head), workpiece frame.
    pub axis: Vector3<f64>,
    /// Curve parameter of the point (`params` of `kerf.toolpath/1`), if known.
    pub param: Option<f64>,
    /// Machine axes `[X, Y, Z, tilt, C]` (mm, degrees) that reach the pose.
    pub axes: Axes,
}

/// Solves the machine axes of a path's poses with continuity (each solution nearest the
/// previous one, the first nearest `start`), giving [`Station`]s.
///
/// `axes` are the unit tool axes (`None`: the tool stands along +z at every point, as for a
/// toolpath without normals); `params` the curve parameters, if known.
///
/// # Errors
/// [`InterpError::TooFewPoints`] for an empty path, [`InterpError::LengthMismatch`],
/// [`InterpError::NonFinite`], and [`InterpError::Kinematics`] with the point's index.
pub fn solve_stations<M: AxisModel + ?Sized>(
    model: &M,
    tips: &[Point3<f64>],
    axes: Option<&[Vector3<f64>]>,
    params: Option<&[f64]>,
    start: Option<&Axes>,
) -> Result<Vec<Station>> {
    if tips.is_empty() {
        return Err(InterpError::TooFewPoints { got: 0, need: 1 });
    }
    if let Some(a) = axes {
        if a.len() != tips.len() {
            return Err(InterpError::LengthMismatch {
                what: "tool axes",
                got: a.len(),
                expected: tips.len(),
            });
        }
    }
    if let Some(p) = params {
        if p.len() != tips.len() {
            return Err(InterpError::LengthMismatch {
                what: "params",
                got: p.len(),
                expected: tips.len(),
            });
        }
    }
    let mut out: Vec<Station> = Vec::with_capacity(tips.len());
    let mut prev = start.copied();
    for (i, tip) in tips.iter().enumerate() {
        let axis = axes.map_or(Vector3::z(), |a| a[i]);
        if !(tip.coords.iter().chain(axis.iter()).all(|v| v.is_finite())) {
            return Err(InterpError::NonFinite { index: i });
        }
        let q = model
            .inverse(tip, &axis, prev.as_ref())
            .map_err(|e| match e {
                InterpError::Kinematics { source, .. } => {
                    InterpError::Kinematics { index: i, source }
                }
                other => other,
            })?;
        prev = Some(q);
        out.push(Station {
            tip: *tip,
            axis,
            param: params.map(|p| p[i]),
            axes: q,
        });
    }
    Ok(out)
}

/// The shape of a block's tool-tip path.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Geometry {
    /// Space line (paper 000 eq 1-4).
    Line {
        /// Start point.
        start: Point3<f64>,
        /// End point.
        end: Point3<f64>,
    },
    /// Space arc through three points (paper 000 eq 5-12).
    Arc(SpaceArc),
    /// The tip stands still while the rotary axes turn (two poses at the same point). The
    /// block's path parameter is then the larger rotary travel in degrees.
    Turn {
        /// The tip.
        at: Point3<f64>,
    },
}

/// One motion block: the tip path, the rotary axes along it, and where it came from.
///
/// The path parameter `s` runs from 0 to [`Block::length`]: the tip's arc length in mm (degrees
/// of rotary travel for a [`Geometry::Turn`]). The rotary axes change in proportion to `s`
/// (lines, eq 4) or piecewise in proportion to the swept angle, from `P1` to `P2` and from `P2`
/// to `P3` (arcs, eq 9-12, driven by the angle itself, not by comparing axis values, so that a
/// decreasing axis works).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Block {
    /// The tip path.
    pub geometry: Geometry,
    /// Machine axes at the start (exactly the start station's).
    pub start_axes: Axes,
    /// Machine axes at the arc's intermediate point (equal to `start_axes` for lines).
    pub mid_axes: Axes,
    /// Machine axes at the end (exactly the end station's).
    pub end_axes: Axes,
    /// Tool axis at the end (for programs that give the orientation vector).
    pub end_tool_axis: Vector3<f64>,
    /// Tool axis at the arc's intermediate point (the end's for lines).
    pub mid_tool_axis: Vector3<f64>,
    /// Index of the source path in the program.
    pub path: usize,
    /// Indices of the first and last station of the source path this block covers.
    pub stations: [usize; 2],
    /// Curve parameters of the block's ends, when known.
    pub params: Option<[f64; 2]>,
    /// A laser-off positioning move between paths (G0), not a cut.
    pub rapid: bool,
    length: f64,
}

/// True where cutting block `k` of `blocks` starts a cut (a pierce, the beam switched on): it
/// is the first block, follows a rapid, or begins another path than the block before it (a
/// path may start where the last one ended, at the same axes, with no traverse between). The
/// one rule of the program writer, its pierce checks, the report's count and the view.
pub fn starts_cut(blocks: &[Block], k: usize) -> bool {
    let Some(b) = blocks.get(k) else {
        return false;
    };
    !b.rapid
        && match k.checked_sub(1).and_then(|j| blocks.get(j)) {
            None => true,
            Some(before) => before.rapid || before.path != b.path,
        }
}

impl Block {
    /// A line (or a [`Geometry::Turn`] when the tips coincide) from `a` to `b`.
    pub fn line(a: &Station, b: &Station) -> Self {
        let travel = (b.tip - a.tip).norm();
        let (geometry, length) = if travel > MIN_TRAVEL {
            (
                Geometry::Line {
                    start: a.tip,
                    end: b.tip,
                },
                travel,
            )
        } else {
            let rot = (b.axes.tilt - a.axes.tilt)
                .abs()
                .max((b.axes.c - a.axes.c).abs());
            (Geometry::Turn { at: a.tip }, rot)
        };
        Self {
            geometry,
            start_axes: a.axes,
            mid_axes: a.axes,
            end_axes: b.axes,
            end_tool_axis: b.axis,
            mid_tool_axis: b.axis,
            path: 0,
            stations: [0, 0],
            params: a.param.zip(b.param).map(|(p, q)| [p, q]),
            rapid: false,
            length,
        }
    }

    /// The space arc through the tips of `a`, `m`, `b`, with the rotary axes piecewise
    /// `a -> m -> b`.
    ///
    /// # Errors
    /// [`InterpError::CollinearArc`] as [`SpaceArc::through`].
    pub fn arc(a: &Station, m: &Station, b: &Station) -> Result<Self> {
        let arc = SpaceArc::through(a.tip, m.tip, b.tip)?;
        let mut block = Self::line(a, b);
        block.geometry = Geometry::Arc(arc);
        block.mid_axes = m.axes;
        block.mid_tool_axis = m.axis;
        block.length = arc.length();
        Ok(block)
    }

    /// The arc through `a`, `m`, `b`; when the three tips are collinear (or two coincide), the
    /// documented fallback: the line from `a` to `b`, with the rotary axes linear from `a` to
    /// `b` (the orientation at `m` is then not passed through).
    pub fn arc_or_line(a: &Station, m: &Station, b: &Station) -> Self {
        Self::arc(a, m, b).unwrap_or_else(|_| Self::line(a, b))
    }

    /// The path-parameter length: mm of tip travel (degrees for a turn).
    pub fn length(&self) -> f64 {
        self.length
    }

    /// True for an arc.
    pub fn is_arc(&self) -> bool {
        matches!(self.geometry, Geometry::Arc(_))
    }

    /// Start tip.
    pub fn start_tip(&self) -> Point3<f64> {
        match &self.geometry {
            Geometry::Line { start, .. } => *start,
            Geometry::Arc(a) => a.start,
            Geometry::Turn { at } => *at,
        }
    }

    /// End tip.
    pub fn end_tip(&self) -> Point3<f64> {
        match &self.geometry {
            Geometry::Line { end, .. } => *end,
            Geometry::Arc(a) => a.end,
            Geometry::Turn { at } => *at,
        }
    }

    /// Path parameter of the arc's intermediate point (`length` for lines and turns): the
    /// rotary axes have a kink there.
    pub fn mid_length(&self) -> f64 {
        match &self.geometry {
            Geometry::Arc(a) => a.length_to_mid(),
            _ => self.length,
        }
    }

    /// Tip and rotary axes `(tilt, C)` at path parameter `s` (clamped to `[0, length]`; the
    /// ends are returned exactly).
    #[inline]
    pub fn pose_at(&self, s: f64) -> (Point3<f64>, f64, f64) {
        let (q0, q1, q2) = (&self.start_axes, &self.mid_axes, &self.end_axes);
        if s.is_nan() || s >= self.length {
            return (self.end_tip(), q2[3], q2[4]);
        }
        if s <= 0.0 {
            return (self.start_tip(), q0[3], q0[4]);
        }
        match &self.geometry {
            Geometry::Line { start, end } => {
                let f = s / self.length;
                let tip = start + (end - start) * f;
                (
                    tip,
                    q0[3] + f * (q2[3] - q0[3]),
                    q0[4] + f * (q2[4] - q0[4]),
                )
            }
            Geometry::Turn { at } => {
                let f = s / self.length;
                (
                    *at,
                    q0[3] + f * (q2[3] - q0[3]),
                    q0[4] + f * (q2[4] - q0[4]),
                )
            }
            Geometry::Arc(arc) => {
                let theta = s / arc.radius;
                let tip = arc.point_at_angle(theta);
                // Eq 9-12, selected by the swept angle.
                if theta < arc.angle_mid {
                    let f = theta / arc.angle_mid;
                    (
                        tip,
                        q0[3] + f * (q1[3] - q0[3]),
                        q0[4] + f * (q1[4] - q0[4]),
                    )
                } else {
                    let f = (theta - arc.angle_mid) / (arc.angle_end - arc.angle_mid);
                    (
                        tip,
                        q1[3] + f * (q2[3] - q1[3]),
                        q1[4] + f * (q2[4] - q1[4]),
                    )
                }
            }
        }
    }

    /// Machine axes at path parameter `s`: the tip and rotary axes of [`Block::pose_at`]
    /// through [`AxisModel::linear_axes`]. At `s >= length` exactly `end_axes`, at `s <= 0`
    /// exactly `start_axes`.
    #[inline]
    pub fn axes_at<M: AxisModel + ?Sized>(&self, model: &M, s: f64) -> Axes {
        if s.is_nan() || s >= self.length {
            return self.end_axes;
        }
        if s <= 0.0 {
            return self.start_axes;
        }
        let (tip, tilt, c) = self.pose_at(s);
        let xyz = model.linear_axes(&tip, tilt, c);
        Axes::new(xyz[0], xyz[1], xyz[2], tilt, c)
    }

    /// Paper 000's time-division interpolation of this block alone at constant feed: the
    /// set-points of cycles `0..=n` (cycle 0 is the start), the tip advancing `dl = F T` per
    /// cycle, the last step shortened so that the last set-point is exactly the block's end.
    /// Positions are `start + (i dl) * direction` (and angle `i dl / R` on arcs), computed from
    /// the block start, never by summing increments, so nothing drifts.
    ///
    /// `feed` in mm/min (in deg/min of the larger rotary travel for a turn), `cycle` in
    /// seconds. There is no acceleration here (the paper's interpolator); see
    /// [`crate::plan()`] for a program within the machine's limits.
    ///
    /// # Errors
    /// [`InterpError::BadParameter`] for a feed or cycle that is not finite and > 0, and
    /// [`InterpError::TooManyCycles`] beyond 100 million cycles.
    pub fn constant_feed<M: AxisModel + ?Sized>(
        &self,
        model: &M,
        feed: f64,
        cycle: f64,
    ) -> Result<Vec<Axes>> {
        let dl = positive("feed", feed)? / 60.0 * positive("cycle", cycle)?;
        let steps = (self.length / dl).ceil();
        if steps.is_nan() || steps > 1e8 {
            return Err(InterpError::TooManyCycles {
                cycles: steps,
                limit: 100_000_000,
            });
        }
        let n = (steps as usize).max(1);
        let mut out = Vec::with_capacity(n + 1);
        for i in 0..=n {
            let s = if i == n { self.length } else { i as f64 * dl };
            out.push(self.axes_at(model, s));
        }
        Ok(out)
    }
}

/// Per-cycle increments of a set-point sequence: `q[i] - q[i - 1]` for `i = 1..`; what a
/// time-division interpolator sends to the axis drives (paper 000, after eq 16).
pub fn increments(setpoints: &[Axes]) -> Vec<[f64; 5]> {
    setpoints
        .windows(2)
        .map(|w| std::array::from_fn(|k| w[1][k] - w[0][k]))
        .collect()
}
