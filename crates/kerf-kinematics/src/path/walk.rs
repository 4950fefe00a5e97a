//! The walk along one path: the choice of solution pose by pose, the inserted points (rotary
//! step, linearization error, C turns at the pole) and the report of the solved path.

use nalgebra::Vector3;

use crate::choice::{nearest_solution, nearest_turn};
use crate::error::{KinematicsError, Result};
use crate::kinematics::Kinematics;
use crate::machine::Machine;
use crate::nonlinear::{linearization_error, slerp};
use crate::pose::{Axes, Axis, Pose};
use crate::rotation::angle_between;

use super::{PathCurve, PathOptions, SolvedPath, LIMIT_SLACK, MAX_PIECES};

/// Why the preferred solution of a pose cannot be used.
#[derive(Debug, Clone)]
struct Refusal {
    /// The axis out of its limits.
    axis: Axis,
    /// The preferred solution.
    axes: Axes,
    /// Why the other solution does not help.
    detail: String,
}

/// Why a point was inserted.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Reason {
    Cutting,
    RotaryStep,
    Linearization,
}

/// A point to reach.
#[derive(Debug, Clone, Copy)]
struct Node {
    pose: Pose,
    param: Option<f64>,
    source: Option<usize>,
    reason: Reason,
    /// `Some(c)` for a C turn at the pole: the pose stays, C is set.
    fixed_c: Option<f64>,
}

/// A point reached.
#[derive(Debug, Clone, Copy)]
struct Reached {
    node: Node,
    axes: Axes,
    pole: bool,
}

pub(super) struct Ctx<'a> {
    pub(super) machine: &'a Machine,
    pub(super) kin: &'a dyn Kinematics,
    pub(super) options: &'a PathOptions,
    pub(super) id: &'a str,
    pub(super) poses: &'a [Pose],
    pub(super) curve: Option<PathCurve<'a>>,
}

impl Ctx<'_> {
    pub(super) fn empty(&self) -> SolvedPath {
        SolvedPath {
            id: self.id.to_owned(),
            poses: Vec::new(),
            axes: Vec::new(),
            source: Vec::new(),
            inserted: 0,
            inserted_for_rotary_step: 0,
            inserted_for_linearization: 0,
            max_rotary_step_between_cutting_points: 0.0,
            max_rotary_step: 0.0,
            max_linearization_error: 0.0,
            pole_points: 0,
            pole_tip_error: 0.0,
            tilt: None,
        }
    }

    fn is_pole(&self, pose: &Pose) -> bool {
        self.kin.pole_angle(&pose.axis) <= self.options.pole_tolerance_deg.to_radians()
    }

    fn cutting(&self, n: usize) -> Node {
        Node {
            pose: self.poses[n],
            param: self.curve.map(|c| c.params[n]),
            source: Some(n),
            reason: Reason::Cutting,
            fixed_c: None,
        }
    }

    /// The values `value + 360 k` worth trying for a rotary axis free to choose its turn
    /// (at the start, or leaving the pole): the one nearest `reference`, and for a limited
    /// axis also its neighbours within the limits.
    fn turns(&self, value: f64, reference: f64, axis: Axis) -> Vec<f64> {
        let near = nearest_turn(value, reference);
        let Some(range) = self.machine.limit(axis) else {
            return vec![near];
        };
        let mut v: Vec<f64> = [0.0, -360.0, 360.0, -720.0, 720.0]
            .iter()
            .map(|k| near + k)
            .filter(|x| range.contains(*x, LIMIT_SLACK))
            .collect();
        if v.is_empty() {
            // Nothing fits: keep the nearest, whose violation is then reported.
            v.push(near);
        }
        v
    }

    fn out_of_limits(&self, index: usize, inserted: bool, r: Refusal) -> KinematicsError {
        let range = self
            .machine
            .limit(r.axis)
            .unwrap_or(crate::machine::Range::new(f64::NAN, f64::NAN));
        KinematicsError::OutOfLimits {
            path_id: self.id.to_owned(),
            index,
            inserted,
            axis: self.machine.axis_name(r.axis),
            value: round6(r.axes.get(r.axis)),
            min: range.min,
            max: range.max,
            detail: r.detail,
        }
    }

    fn describe(&self, q: &Axes) -> String {
        format!(
            "{} = {}, C = {}",
            self.kin.tilt_name(),
            round6(q.tilt),
            round6(q.c)
        )
    }

    /// The axes for `node`, continuing from `prev` (`n` is the cutting point being reached).
    fn choose(&self, prev: &Reached, node: &Node, n: usize) -> Result<Axes> {
        let inserted = node.source.is_none();
        if let Some(c) = node.fixed_c {
            return self.at_c(prev, node, c, n);
        }
        if self.is_pole(&node.pose) {
            return self.at_c(prev, node, prev.axes.c, n);
        }
        if prev.pole {
            // Leaving the pole: C is free, so both solutions and every turn within the limits
            // are candidates, as at the start.
            let next = if inserted { n } else { n + 1 };
            return self
                .decide(&prev.axes, &node.pose, next)
                .map_err(|(j, r)| self.out_of_limits(j.unwrap_or(n), j.is_none() && inserted, r));
        }
        self.continue_to(&prev.axes, &prev.node.pose.axis, &node.pose)
            .map_err(|r| self.out_of_limits(n, inserted, r))
    }

    /// The continuity rule off the pole: of both solutions, each at the turn nearest `prev`,
    /// the one with the least rotary travel; the other if that one leaves the limits and the
    /// move to the other is continuous.
    fn continue_to(
        &self,
        prev: &Axes,
        prev_axis: &Vector3<f64>,
        pose: &Pose,
    ) -> std::result::Result<Axes, Refusal> {
        let sols = self.kin.inverse(pose).map(|mut q| {
            q.tilt = nearest_turn(q.tilt, prev.tilt);
            q.c = nearest_turn(q.c, prev.c);
            q
        });
        // The preferred solution by the one choice rule, limits aside (they are checked next,
        // so that a refusal can say which axis and what the other solution would do).
        let second =
            nearest_solution(sols, prev, |_| true).is_some_and(|q| q == sols[1] && q != sols[0]);
        let (pref, other) = if second {
            (sols[1], sols[0])
        } else {
            (sols[0], sols[1])
        };
        let Some((axis, _)) = self.machine.violation(&pref, LIMIT_SLACK) else {
            return Ok(pref);
        };
        let detail = match self.machine.violation(&other, LIMIT_SLACK) {
            Some((other_axis, r)) => format!(
                "the other solution ({}) has {} = {} outside [{}, {}] too",
                self.describe(&other),
                self.machine.axis_name(other_axis),
                round6(other.get(other_axis)),
                r.min,
                r.max
            ),
            None => {
                if self.continuous(prev, prev_axis, &other, &pose.axis) {
                    return Ok(other);
                }
                format!(
                    "the other solution ({}) fits the limits but is a jump from the previous \
                     point ({}): the axes cannot stay continuous",
                    self.describe(&other),
                    self.describe(prev)
                )
            }
        };
        Err(Refusal {
            axis,
            axes: pref,
            detail,
        })
    }

    /// Follows the continuity rule from `q` (the axes of `pose`) over the cutting points from
    /// `next` up to the next pole point or the end; the first refusal, with its index.
    fn dry_run(
        &self,
        q: Axes,
        pose: &Pose,
        next: usize,
    ) -> std::result::Result<(), (usize, Refusal)> {
        let (mut q, mut axis) = (q, pose.axis);
        for j in next..self.poses.len() {
            let p = &self.poses[j];
            if self.is_pole(p) {
                break;
            }
            q = self.continue_to(&q, &axis, p).map_err(|r| (j, r))?;
            axis = p.axis;
        }
        Ok(())
    }

    /// A free choice (the start, or leaving the pole): every solution of `pose` and every
    /// turn within the limits, by rotary travel from `from`; the first whose continuation to
    /// the next pole point (or the end) stays within the limits. On failure, the refusal that
    /// came furthest (`None` for the index: at `pose` itself).
    fn decide(
        &self,
        from: &Axes,
        pose: &Pose,
        next: usize,
    ) -> std::result::Result<Axes, (Option<usize>, Refusal)> {
        let mut candidates: Vec<Axes> = Vec::new();
        for q in self.kin.inverse(pose) {
            for t in self.turns(q.tilt, from.tilt, Axis::Tilt) {
                for c in self.turns(q.c, from.c, Axis::C) {
                    candidates.push(Axes { tilt: t, c, ..q });
                }
            }
        }
        candidates.sort_by(|a, b| from.rotary_travel(a).total_cmp(&from.rotary_travel(b)));
        let mut furthest: Option<(Option<usize>, Refusal)> = None;
        for q in candidates {
            let failure = match self.machine.violation(&q, LIMIT_SLACK) {
                Some((axis, _)) => (
                    None,
                    Refusal {
                        axis,
                        axes: q,
                        detail: "no solution of this point fits the limits".to_owned(),
                    },
                ),
                None => match self.dry_run(q, pose, next) {
                    Ok(()) => return Ok(q),
                    Err((j, r)) => (Some(j), r),
                },
            };
            if furthest.as_ref().is_none_or(|(j, _)| failure.0 > *j) {
                furthest = Some(failure);
            }
        }
        Err(furthest.unwrap_or((
            None,
            Refusal {
                axis: Axis::C,
                axes: *from,
                detail: "no candidate".to_owned(),
            },
        )))
    }

    /// The axes of the first point: at the pole, with the C its path leaves the pole with;
    /// else by [`Self::decide`] from the machine's zero.
    fn start(&self) -> Result<Axes> {
        let home = Axes::default();
        let first = &self.poses[0];
        if !self.is_pole(first) {
            return self
                .decide(&home, first, 1)
                .map_err(|(j, r)| self.out_of_limits(j.unwrap_or(0), false, r));
        }
        let c = match (1..self.poses.len()).find(|&m| !self.is_pole(&self.poses[m])) {
            Some(m) => self
                .decide(&home, &self.poses[m], m + 1)
                .map_or(0.0, |q| q.c),
            None => 0.0,
        };
        let mut q = self.kin.inverse_with_c(first, c);
        q.tilt = nearest_turn(q.tilt, 0.0);
        match self.machine.violation(&q, LIMIT_SLACK) {
            None => Ok(q),
            Some((axis, _)) => Err(self.out_of_limits(
                0,
                false,
                Refusal {
                    axis,
                    axes: q,
                    detail: "the first point is at the pole".to_owned(),
                },
            )),
        }
    }

    /// The axes for `node` with C fixed at `c` (the pole, or a C turn at the pole).
    fn at_c(&self, prev: &Reached, node: &Node, c: f64, index: usize) -> Result<Axes> {
        let mut q = self.kin.inverse_with_c(&node.pose, c);
        q.tilt = nearest_turn(q.tilt, prev.axes.tilt);
        match self.machine.violation(&q, LIMIT_SLACK) {
            None => Ok(q),
            Some((axis, _)) => Err(self.out_of_limits(
                index,
                node.source.is_none(),
                Refusal {
                    axis,
                    axes: q,
                    detail: format!(
                        "the pose is at the pole, where C keeps its previous value {}",
                        round6(c)
                    ),
                },
            )),
        }
    }

    /// True if the linear axis move from `prev` (tool axis `ua`) to `q` (tool axis `ub`)
    /// keeps the tool axis near the great circle: at the middle of the move it is within the
    /// angle between the two poses (or the pole tolerance) of the great-circle midpoint.
    fn continuous(&self, prev: &Axes, ua: &Vector3<f64>, q: &Axes, ub: &Vector3<f64>) -> bool {
        let mid = self.kin.forward(&prev.lerp(q, 0.5)).axis;
        let great = slerp(ua, ub, 0.5);
        angle_between(&mid, &great)
            <= angle_between(ua, ub).max(self.options.pole_tolerance_deg.to_radians()) + 1e-12
    }

    /// The node a fraction `s` of the way from `a` to `b`.
    fn between(&self, a: &Node, b: &Node, s: f64, reason: Reason, index: usize) -> Result<Node> {
        let param = match (a.param, b.param) {
            (Some(ta), Some(tb)) => Some(ta + s * (tb - ta)),
            _ => None,
        };
        let position = match (param, self.curve) {
            (Some(t), Some(curve)) => {
                let p = curve.point.point_at(t);
                if !(p.x.is_finite() && p.y.is_finite() && p.z.is_finite()) {
                    return Err(KinematicsError::BadPose {
                        path_id: self.id.to_owned(),
                        index,
                        reason: format!("the curve gives a non-finite point at t = {t}"),
                    });
                }
                p
            }
            _ => a.pose.position + s * (b.pose.position - a.pose.position),
        };
        Ok(Node {
            pose: Pose {
                position,
                axis: slerp(&a.pose.axis, &b.pose.axis, s),
            },
            param,
            source: None,
            reason,
            fixed_c: None,
        })
    }

    /// Solves the path from the start axes `start`.
    pub(super) fn walk(&self) -> Result<SolvedPath> {
        let opts = self.options;
        let first = self.cutting(0);
        let start = self.start()?;
        let mut reached = Vec::with_capacity(self.poses.len() + self.poses.len() / 4);
        reached.push(Reached {
            node: first,
            axes: start,
            pole: self.is_pole(&first.pose),
        });
        let mut max_dev: f64 = 0.0;
        let mut inserted = 0usize;
        let mut stack: Vec<Node> = Vec::new();
        for n in 1..self.poses.len() {
            stack.clear();
            stack.push(self.cutting(n));
            while let Some(&node) = stack.last() {
                let prev = reached[reached.len() - 1];
                let q = self.choose(&prev, &node, n)?;
                let step = prev.axes.rotary_step(&q);
                let dev = linearization_error(self.kin, &prev.axes, &q).distance;
                let rotary_ok = step <= opts.max_rotary_step_deg + LIMIT_SLACK;
                let linear_ok = dev <= opts.linearization_tolerance_mm;
                if rotary_ok && linear_ok {
                    max_dev = max_dev.max(dev);
                    if node.source.is_none() {
                        inserted += 1;
                        if inserted > opts.max_inserted {
                            return Err(KinematicsError::TooManyInserted {
                                path_id: self.id.to_owned(),
                                index: n,
                                limit: opts.max_inserted,
                            });
                        }
                    }
                    let pole = node.fixed_c.is_some() || self.is_pole(&node.pose);
                    reached.push(Reached {
                        node,
                        axes: q,
                        pole,
                    });
                    stack.pop();
                    continue;
                }
                if stack.len() > opts.max_inserted {
                    return Err(KinematicsError::TooManyInserted {
                        path_id: self.id.to_owned(),
                        index: n,
                        limit: opts.max_inserted,
                    });
                }
                let reason = if rotary_ok {
                    Reason::Linearization
                } else {
                    Reason::RotaryStep
                };
                let mut pieces: f64 = 2.0;
                if !rotary_ok {
                    pieces = pieces.max((step / opts.max_rotary_step_deg).ceil());
                }
                if !linear_ok {
                    pieces = pieces.max((dev / opts.linearization_tolerance_mm).sqrt().ceil());
                }
                let pieces = pieces.min(MAX_PIECES) as usize;
                let dc = q.c - prev.axes.c;
                if let Some(c) = node.fixed_c {
                    // Splitting a C turn at the pole: same pose, C in between.
                    let c0 = prev.axes.c;
                    if (c - c0).abs() < 1e-9 {
                        return Err(self.jump(n, &prev.axes, &q));
                    }
                    for k in (1..pieces).rev() {
                        let s = k as f64 / pieces as f64;
                        stack.push(Node {
                            fixed_c: Some(c0 + s * (c - c0)),
                            reason,
                            source: None,
                            ..node
                        });
                    }
                } else if prev.pole && !self.is_pole(&node.pose) && dc.abs() > 1e-9 {
                    // Leaving the pole toward another C: turn C at the pole first.
                    stack.push(Node {
                        fixed_c: Some(q.c),
                        reason: Reason::RotaryStep,
                        source: None,
                        ..prev.node
                    });
                } else {
                    let moved = (node.pose.position - prev.node.pose.position).norm();
                    let turned = angle_between(&node.pose.axis, &prev.node.pose.axis);
                    if moved < 1e-9 && turned < 1e-12 {
                        return Err(self.jump(n, &prev.axes, &q));
                    }
                    for k in (1..pieces).rev() {
                        let s = k as f64 / pieces as f64;
                        stack.push(self.between(&prev.node, &node, s, reason, n)?);
                    }
                }
            }
        }
        Ok(self.report(reached, max_dev))
    }

    fn jump(&self, index: usize, a: &Axes, b: &Axes) -> KinematicsError {
        KinematicsError::Discontinuity {
            path_id: self.id.to_owned(),
            index,
            detail: format!("from {} to {}", self.describe(a), self.describe(b)),
        }
    }

    fn report(&self, reached: Vec<Reached>, max_dev: f64) -> SolvedPath {
        let mut path = self.empty();
        let pivot = self.kin.pivot_length();
        let mut last_cutting: Option<Axes> = None;
        let mut prev: Option<Axes> = None;
        for r in &reached {
            if let Some(p) = prev {
                path.max_rotary_step = path.max_rotary_step.max(p.rotary_step(&r.axes));
            }
            prev = Some(r.axes);
            match r.node.source {
                Some(_) => {
                    if let Some(p) = last_cutting {
                        path.max_rotary_step_between_cutting_points = path
                            .max_rotary_step_between_cutting_points
                            .max(p.rotary_step(&r.axes));
                    }
                    last_cutting = Some(r.axes);
                }
                None => match r.node.reason {
                    Reason::Linearization => path.inserted_for_linearization += 1,
                    _ => path.inserted_for_rotary_step += 1,
                },
            }
            if r.pole {
                path.pole_points += 1;
                let achieved = self.kin.forward(&r.axes).axis;
                let angle = angle_between(&achieved, &r.node.pose.axis);
                path.pole_tip_error = path.pole_tip_error.max(pivot * angle);
            }
            path.poses.push(r.node.pose);
            path.axes.push(r.axes);
            path.source.push(r.node.source);
        }
        path.inserted = path.inserted_for_linearization + path.inserted_for_rotary_step;
        path.max_linearization_error = max_dev;
        path
    }
}

/// Rounds to 6 decimals for messages (so that 360.00000000000006 reads 360).
fn round6(v: f64) -> f64 {
    (v * 1e6).round() / 1e6
}
