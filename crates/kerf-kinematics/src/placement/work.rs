//! The shared work of one automatic placement: every path's solve with the linear axes free,
//! per orientation and side, made once (the candidates of a round, the groups and every level
//! of set-up splitting ask for the same solves again), each path's reachable orientations
//! made once, and a cheap test of the linear travel before any solve.

use std::collections::HashMap;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Mutex, OnceLock};

use rayon::prelude::*;

use nalgebra::{Matrix3, Rotation3};

use super::directions::{reachable_directions, up_directions};
use super::{AutoPlaceOptions, Shortfall};
use crate::error::Result;
use crate::machine::{Machine, Range};
use crate::path::solve_path;
use crate::path::{solve_paths, PathInput, SolvedPath};
use crate::pose::{Axes, Pose};

/// A solved path (linear axes free), or why it does not solve.
type Solve = Result<SolvedPath>;

/// A free solve's key: the path, the bits of the rotation's matrix, the side.
type Key = (usize, [u64; 9], bool);

/// The shared work of [`auto_place`](super::auto_place) and [`auto_setups`](super::auto_setups)
/// on one set of paths.
pub(super) struct Work<'a> {
    /// The machine, real limits.
    pub(super) machine: &'a Machine,
    /// Every path (indices below are into this).
    pub(super) paths: &'a [(&'a str, &'a [Pose])],
    /// The options.
    pub(super) options: &'a AutoPlaceOptions,
    /// The machine with the tilt range less its margin.
    pub(super) inset: Machine,
    /// `inset` with the linear axes unlimited.
    free: Machine,
    /// True if the linear axes follow the tip one to one at every pose (`M_n = I`, head
    /// machines): then a translation moves every pose's linear axes alike, and the extent of
    /// the linear axes over the poses must fit the travel.
    head: bool,
    /// The free solves, by path, rotation (the bits of its matrix) and side.
    solves: Mutex<HashMap<Key, Solve>>,
    /// Per path, per direction of [`up_directions`]: reachable once that direction points up.
    reach: OnceLock<Vec<Vec<bool>>>,
    /// Paths solved so far (free and against the real limits).
    pub(super) solved: AtomicUsize,
}

impl<'a> Work<'a> {
    pub(super) fn new(
        machine: &'a Machine,
        paths: &'a [(&'a str, &'a [Pose])],
        options: &'a AutoPlaceOptions,
    ) -> Self {
        // The tilt range less its margin (when the range is wide enough to keep one).
        let mut inset = machine.clone();
        if let Some(r) = inset.limits[3] {
            let m = options.tilt_margin_deg.max(0.0);
            if r.max - r.min > 4.0 * m {
                inset.limits[3] = Some(Range::new(r.min + m, r.max - m));
            }
        }
        let mut free = inset.clone();
        for k in 0..3 {
            free.limits[k] = None;
        }
        // M = I at a few rotary settings spread over the ranges: the head machines' linear
        // axes carry the head, so M is the identity everywhere for them and for no table.
        let head = [(0.0, 0.0), (30.0, 45.0), (-60.0, 200.0), (90.0, -120.0)]
            .iter()
            .all(|&(t, c)| {
                let m = super::shift::tip_to_axes(machine, &Axes::new(0.0, 0.0, 0.0, t, c));
                (m - Matrix3::identity()).amax() <= 1e-9
            });
        Self {
            machine,
            paths,
            options,
            inset,
            free,
            head,
            solves: Mutex::new(HashMap::new()),
            reach: OnceLock::new(),
            solved: AtomicUsize::new(0),
        }
    }

    /// The paths `idx`, turned by `rot` and sided by `flipped`, solved with the linear axes
    /// free: each (path, rotation, side) solved once; the first error in `idx` order.
    pub(super) fn free_solve(
        &self,
        idx: &[usize],
        rot: &Rotation3<f64>,
        flipped: &[bool],
        sided: &[Vec<Pose>],
    ) -> Result<Vec<SolvedPath>> {
        let bits = {
            let m = rot.matrix();
            std::array::from_fn(|k| m[(k % 3, k / 3)].to_bits())
        };
        let keys: Vec<Key> = idx
            .iter()
            .zip(flipped)
            .map(|(&i, &f)| (i, bits, f))
            .collect();
        let mut out: Vec<Option<Solve>> = {
            let known = self.solves.lock().unwrap_or_else(|e| e.into_inner());
            keys.iter().map(|k| known.get(k).cloned()).collect()
        };
        let missing: Vec<usize> = (0..keys.len()).filter(|&k| out[k].is_none()).collect();
        let fresh: Vec<(usize, Solve)> = missing
            .par_iter()
            .map(|&k| {
                let input = PathInput {
                    id: self.paths[idx[k]].0,
                    poses: &sided[k],
                    curve: None,
                };
                (
                    k,
                    solve_path(&self.free, &input, &self.options.path_options),
                )
            })
            .collect();
        self.solved.fetch_add(fresh.len(), Ordering::Relaxed);
        let mut known = self.solves.lock().unwrap_or_else(|e| e.into_inner());
        for (k, s) in fresh {
            known.insert(keys[k], s.clone());
            out[k] = Some(s);
        }
        out.into_iter().flatten().collect()
    }

    /// The paths `idx` with `poses` solved against the real limits (tilt margin kept).
    pub(super) fn check_solve(
        &self,
        idx: &[usize],
        poses: &[Vec<Pose>],
    ) -> Result<Vec<SolvedPath>> {
        self.solved.fetch_add(idx.len(), Ordering::Relaxed);
        let inputs: Vec<PathInput<'_>> = idx
            .iter()
            .zip(poses)
            .map(|(&i, p)| PathInput {
                id: self.paths[i].0,
                poses: p,
                curve: None,
            })
            .collect();
        solve_paths(&self.inset, &inputs, &self.options.path_options)
    }

    /// On a head machine, a linear axis whose travel the sided poses cannot fit in any
    /// translation, before any solve. Each cutting point's solved linear axes lie in a range
    /// known without solving: off the pole they are one of the two inverse solutions (a C
    /// turn of a full circle moves no linear axis); at the pole C is free and the head turns
    /// about the C axis, so each linear axis is `a + b cos C + c sin C`, whose range
    /// `a +- sqrt(b^2 + c^2)` follows from C = 0, 90, 180 and 270 (checked at 45 degrees: a
    /// pose where that model does not hold is left out). The solved extent of axis `k` is then
    /// at least `max_n lo_nk - min_n hi_nk` (inserted points only widen it). A lower bound of
    /// the shortfall, or `None`.
    pub(super) fn envelope_short(&self, sided: &[Vec<Pose>]) -> Option<Shortfall> {
        if !self.head {
            return None;
        }
        let kin = self.machine.kinematics.as_ref();
        let pole = self.options.path_options.pole_tolerance_deg.to_radians();
        let mut low = [f64::NEG_INFINITY; 3]; // max over poses of the range's low end
        let mut high = [f64::INFINITY; 3]; // min over poses of the range's high end
        for pose in sided.iter().flatten() {
            let Some(range) = self.axes_range(kin, pose, pole) else {
                continue;
            };
            for k in 0..3 {
                low[k] = low[k].max(range[k].0);
                high[k] = high[k].min(range[k].1);
            }
        }
        let names = self.machine.axis_names();
        (0..3)
            .filter_map(|k| {
                let r = self.machine.limits[k]?;
                let need = low[k] - high[k];
                let have = (r.max - r.min) - 2.0 * self.options.margin_mm;
                (need.is_finite() && need > have).then(|| Shortfall {
                    axis: names[k],
                    missing: need - have,
                    detail: format!(
                        "the part's motion needs at least {need:.3} mm of {} travel, the machine has {:.3} mm less a margin of {} mm on each side",
                        names[k],
                        r.max - r.min,
                        self.options.margin_mm
                    ),
                })
            })
            .max_by(|a, b| a.missing.total_cmp(&b.missing))
    }

    /// The range `(lo, hi)` of each linear axis the solver can give `pose` (see
    /// [`Work::envelope_short`]), or `None` where it is not known.
    fn axes_range(
        &self,
        kin: &dyn crate::Kinematics,
        pose: &Pose,
        pole: f64,
    ) -> Option<[(f64, f64); 3]> {
        if kin.pole_angle(&pose.axis) > pole {
            let [a, b] = kin.inverse(pose);
            let (a, b) = (a.xyz(), b.xyz());
            return Some(std::array::from_fn(|k| (a[k].min(b[k]), a[k].max(b[k]))));
        }
        let at = |c: f64| kin.inverse_with_c(pose, c).xyz();
        let (q0, q90, q180, q270, q45) = (at(0.0), at(90.0), at(180.0), at(270.0), at(45.0));
        let mut out = [(0.0, 0.0); 3];
        let h = std::f64::consts::FRAC_1_SQRT_2;
        for k in 0..3 {
            let a = 0.25 * (q0[k] + q90[k] + q180[k] + q270[k]);
            let (b, c) = (0.5 * (q0[k] - q180[k]), 0.5 * (q90[k] - q270[k]));
            let model = a + (b + c) * h;
            let scale = 1.0 + a.abs() + b.abs() + c.abs();
            let sinusoid = (q45[k] - model).abs() <= 1e-9 * scale;
            if !sinusoid {
                return None;
            }
            let rho = b.hypot(c);
            out[k] = (a - rho, a + rho);
        }
        Some(out)
    }

    /// For each of the paths `idx` and each direction of [`up_directions`]: can the tilt axis
    /// reach every tool axis of the path once that direction points up (made once for all
    /// paths, see [`reachable_directions`]).
    pub(super) fn reach(&self, idx: &[usize]) -> Vec<&[bool]> {
        let all = self.reach.get_or_init(|| {
            let owned: Vec<Vec<Pose>> = self.paths.iter().map(|(_, p)| p.to_vec()).collect();
            reachable_directions(self.machine, &owned, self.options.flip, &up_directions())
        });
        idx.iter().map(|&i| all[i].as_slice()).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Point3, Vector3};

    /// The ranges the cheap bound rests on hold the solver's own choice: every solved cutting
    /// point's linear axes lie in its range, on and off the pole, on both head types.
    #[test]
    fn the_solved_axes_lie_in_the_ranges_of_the_travel_bound() {
        let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/../../fixtures/machines/");
        for file in ["gantry_ac.json", "ac_head.json", "fork_head.json"] {
            let machine = Machine::read(format!("{dir}{file}")).expect("machine");
            // A ring whose tool axes lean from vertical (the pole) to 60 degrees and back,
            // turning about z, with a stretch of vertical ones.
            let poses: Vec<Pose> = (0..200)
                .map(|i| {
                    let t = f64::from(i) / 200.0 * std::f64::consts::TAU;
                    let lean = if i < 40 {
                        0.0
                    } else {
                        60f64.to_radians() * (0.5 * t).sin().abs()
                    };
                    Pose {
                        position: Point3::new(300.0 * t.cos(), 200.0 * t.sin(), 50.0 * t),
                        axis: Vector3::new(
                            lean.sin() * (2.0 * t).cos(),
                            lean.sin() * (2.0 * t).sin(),
                            lean.cos(),
                        ),
                    }
                })
                .collect();
            let paths = [("ring", poses.as_slice())];
            let options = AutoPlaceOptions::default();
            let work = Work::new(&machine, &paths, &options);
            let kin = machine.kinematics.as_ref();
            let solved = work
                .free_solve(
                    &[0],
                    &Rotation3::identity(),
                    &[false],
                    std::slice::from_ref(&poses),
                )
                .expect("solves")
                .pop()
                .expect("one path");
            let mut pole = 0;
            for (a, src) in solved.axes.iter().zip(&solved.source) {
                let Some(n) = src else { continue };
                let range = work
                    .axes_range(
                        kin,
                        &poses[*n],
                        options.path_options.pole_tolerance_deg.to_radians(),
                    )
                    .expect("a known range");
                pole += usize::from(kin.pole_angle(&poses[*n].axis) <= 1e-6);
                let q = a.xyz();
                for k in 0..3 {
                    assert!(
                        q[k] >= range[k].0 - 1e-6 && q[k] <= range[k].1 + 1e-6,
                        "{file}: point {n} axis {k}: {} outside {:?}",
                        q[k],
                        range[k]
                    );
                }
            }
            assert!(pole >= 40, "{file}: the pole is exercised ({pole})");
        }
    }
}
