//! Placing the part on the machine: a rigid part-to-workpiece transform, chosen by hand or
//! automatically so that every pose of every contour is reachable within the axis limits.
//!
//! A part sits where its CAD model put it; the machine's travel is somewhere else. A
//! [`Placement`] maps part coordinates to workpiece coordinates, `p' = R p + t`, with
//! `R = Rz(rz) Ry(ry) Rx(rx)` (rotations about the fixed workpiece axes, first about x, then y,
//! then z; angles in degrees) and `t` in mm. Tool axes turn with `R`.
//!
//! [`auto_place`] searches for a placement (see `docs/kinematics.md`, "Placement"):
//!
//! 1. For each candidate rotation (the identity first, then the other 23 rotations that map
//!    the coordinate axes onto coordinate axes), each contour's side is chosen: on a sheet
//!    either normal is a valid beam direction, so a contour whose tool axes the tilt axis
//!    cannot reach is turned to the other side if that side is reachable (with
//!    [`AutoPlaceOptions::with_flip`]).
//! 2. The paths are solved with the linear axes unlimited. The rotary axes of every pose depend
//!    only on its tool axis, so they do not change when the part is translated; with them
//!    fixed, the linear axes are an affine function of the tip, `XYZ_n = M_n P_n + b_n`, with
//!    `M_n` a rotation (the identity for head machines). A translation `t` of the part moves
//!    every `XYZ_n` by `M_n t`.
//! 3. The translation solves `lo <= XYZ_n + M_n t <= hi` for every pose and linear axis. For
//!    head machines (all `M_n = I`) the feasible set is a box, and `t` is its centre: the part's
//!    motion envelope sits in the middle of the travel. Otherwise `t` minimises the largest
//!    normalised limit violation (a convex piecewise-linear function, minimised by the
//!    ellipsoid method), which also keeps the envelope away from the limits.
//! 4. The placement with the identity rotation is taken if it fits; else the fitting rotation
//!    with the largest clearance to the limits. Every candidate is checked by solving the
//!    placed paths against the real limits.
//!
//! If nothing fits, the error names the axis and how much travel is missing.

use nalgebra::{Matrix3, Point3, Rotation3, Vector3};

use crate::error::{KinematicsError, Result};
use crate::machine::{Machine, Range};
use crate::path::{PathOptions, SolvedPath};
use crate::pose::Pose;

mod directions;
mod setups;
mod shift;
mod work;

use directions::{turn_up, up_directions};
pub use setups::{auto_setups, Setup, SetupPlan};
use shift::translation;
use work::Work;

/// A rigid transform from part coordinates to workpiece coordinates: `p' = R p + t`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Placement {
    /// The translation `t`, mm.
    pub translation_mm: Vector3<f64>,
    /// The rotation angles `[rx, ry, rz]` in degrees: `R = Rz(rz) Ry(ry) Rx(rx)`.
    pub rotation_deg: [f64; 3],
}

impl Default for Placement {
    fn default() -> Self {
        Self::IDENTITY
    }
}

impl Placement {
    /// The part where its model put it.
    pub const IDENTITY: Placement = Placement {
        translation_mm: Vector3::new(0.0, 0.0, 0.0),
        rotation_deg: [0.0; 3],
    };

    /// A placement from a translation (mm) and rotation angles (degrees, `Rz Ry Rx`).
    pub fn new(translation_mm: Vector3<f64>, rotation_deg: [f64; 3]) -> Self {
        Self {
            translation_mm,
            rotation_deg,
        }
    }

    /// The placement with rotation `r` (any proper rotation), its angles recovered as
    /// `Rz Ry Rx` (`ry` in [-90, 90] degrees).
    pub fn from_rotation(translation_mm: Vector3<f64>, r: &Rotation3<f64>) -> Self {
        let m = r.matrix();
        let ry = (-m[(2, 0)]).clamp(-1.0, 1.0).asin();
        let (rx, rz) = if m[(2, 0)].abs() < 1.0 - 1e-12 {
            (m[(2, 1)].atan2(m[(2, 2)]), m[(1, 0)].atan2(m[(0, 0)]))
        } else {
            // Gimbal lock: only rz - rx (or rz + rx) is determined; put it all in rz.
            (0.0, (-m[(0, 1)]).atan2(m[(1, 1)]))
        };
        let clean = |a: f64| {
            let d = a.to_degrees();
            let r = d.round();
            if (d - r).abs() < 1e-9 {
                r + 0.0
            } else {
                d
            }
        };
        Self::new(translation_mm, [clean(rx), clean(ry), clean(rz)])
    }

    /// The rotation matrix `Rz(rz) Ry(ry) Rx(rx)`.
    pub fn rotation(&self) -> Rotation3<f64> {
        let [rx, ry, rz] = self.rotation_deg.map(f64::to_radians);
        Rotation3::from_axis_angle(&Vector3::z_axis(), rz)
            * Rotation3::from_axis_angle(&Vector3::y_axis(), ry)
            * Rotation3::from_axis_angle(&Vector3::x_axis(), rx)
    }

    /// True if this is the identity (no rotation, no translation).
    pub fn is_identity(&self) -> bool {
        self.translation_mm == Vector3::zeros() && self.rotation_deg == [0.0; 3]
    }

    /// A point of the part in workpiece coordinates.
    pub fn apply_point(&self, p: &Point3<f64>) -> Point3<f64> {
        self.rotation() * p + self.translation_mm
    }

    /// A pose of the part (tip and tool axis) in workpiece coordinates.
    pub fn apply_pose(&self, pose: &Pose) -> Pose {
        let r = self.rotation();
        Pose {
            position: r * pose.position + self.translation_mm,
            axis: r * pose.axis,
        }
    }

    /// Reads `X,Y,Z` or `X,Y,Z,RX,RY,RZ` (mm and degrees), as the CLI's `--place` takes it.
    ///
    /// # Errors
    /// [`PlacementParseError`] naming the bad field.
    pub fn parse(text: &str) -> std::result::Result<Self, PlacementParseError> {
        let fields: Vec<&str> = text.split(',').map(str::trim).collect();
        if fields.len() != 3 && fields.len() != 6 {
            return Err(PlacementParseError::Count(fields.len()));
        }
        const NAMES: [&str; 6] = ["X", "Y", "Z", "RX", "RY", "RZ"];
        let mut v = [0.0; 6];
        for (k, f) in fields.iter().enumerate() {
            let field = NAMES[k];
            let text = (*f).to_owned();
            let x: f64 = f
                .parse()
                .map_err(|_| PlacementParseError::NotANumber { field, text })?;
            if !x.is_finite() || x.abs() > MAX_PLACEMENT_VALUE {
                let text = (*f).to_owned();
                return Err(PlacementParseError::OutOfRange { field, text });
            }
            v[k] = x;
        }
        Ok(Self::new(
            Vector3::new(v[0], v[1], v[2]),
            [v[3], v[4], v[5]],
        ))
    }
}

/// The largest magnitude of a value of a placement's text (mm or degrees).
pub const MAX_PLACEMENT_VALUE: f64 = 1e7;

/// What is wrong with a placement's text ([`Placement::parse`]).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum PlacementParseError {
    /// Neither three values nor six.
    #[error("expected X,Y,Z or X,Y,Z,RX,RY,RZ (mm, degrees) or auto, got {0} values")]
    Count(usize),
    /// A field that is not a number.
    #[error("{field}: not a number: {text:?}")]
    NotANumber {
        /// The field's name (`X`, ..., `RZ`).
        field: &'static str,
        /// Its text.
        text: String,
    },
    /// A field that is not finite or beyond [`MAX_PLACEMENT_VALUE`].
    #[error("{field}: must be finite and within {max:e} (got {text})", max = MAX_PLACEMENT_VALUE)]
    OutOfRange {
        /// The field's name (`X`, ..., `RZ`).
        field: &'static str,
        /// Its text.
        text: String,
    },
}

impl std::fmt::Display for Placement {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let t = self.translation_mm;
        let [rx, ry, rz] = self.rotation_deg;
        write!(
            f,
            "translation ({:.3}, {:.3}, {:.3}) mm, rotation Rz({rz}) Ry({ry}) Rx({rx}) deg",
            t.x, t.y, t.z
        )
    }
}

/// Options of [`auto_place`].
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct AutoPlaceOptions {
    /// Try the 24 axis-aligned rotations when the part does not fit as modelled. Default true.
    pub rotate: bool,
    /// Turn a contour to the other side of its sheet when the machine cannot reach the given
    /// side. Default true.
    pub flip: bool,
    /// Distance kept from every linear limit, mm. Default 1.
    pub margin_mm: f64,
    /// Distance kept from the tilt axis' limits, degrees. Default 0: the interpolator splines
    /// the rotary axes in coordinates mapped onto their ranges, so its motion between poses
    /// never leaves a range even where a pose sits exactly on a limit (kerf-interp
    /// `tests/jerk.rs`); a margin is only needed for a controller that interpolates past the
    /// poses itself.
    pub tilt_margin_deg: f64,
    /// The options the paths are solved with (the same as for the final solve).
    pub path_options: PathOptions,
}

impl Default for AutoPlaceOptions {
    fn default() -> Self {
        Self {
            rotate: true,
            flip: true,
            margin_mm: 1.0,
            tilt_margin_deg: 0.0,
            path_options: PathOptions::default(),
        }
    }
}

impl AutoPlaceOptions {
    /// Sets [`tilt_margin_deg`](Self::tilt_margin_deg): distance kept from the tilt axis'
    /// limits, degrees (the interpolator's smooth motion between poses may swing slightly
    /// past a pose that sits on a limit).
    pub fn with_tilt_margin_deg(mut self, tilt_margin_deg: f64) -> Self {
        self.tilt_margin_deg = tilt_margin_deg;
        self
    }

    /// With or without trying rotations.
    pub fn with_rotate(mut self, rotate: bool) -> Self {
        self.rotate = rotate;
        self
    }
    /// With or without turning contours to the reachable side.
    pub fn with_flip(mut self, flip: bool) -> Self {
        self.flip = flip;
        self
    }
    /// With this clearance to the linear limits, mm.
    pub fn with_margin_mm(mut self, margin_mm: f64) -> Self {
        self.margin_mm = margin_mm;
        self
    }
    /// With these path options.
    pub fn with_path_options(mut self, path_options: PathOptions) -> Self {
        self.path_options = path_options;
        self
    }
}

/// What [`auto_place`] chose.
#[derive(Debug, Clone, PartialEq)]
pub struct AutoPlacement {
    /// The placement.
    pub placement: Placement,
    /// For each path, true if its tool axes were turned to the other side of the sheet.
    pub flipped: Vec<bool>,
    /// The smallest distance of any pose to any linear limit, mm (>= the margin).
    pub clearance_mm: f64,
    /// How many rotations were tried.
    pub rotations_tried: usize,
    /// How many paths were solved in all (with the linear axes free, and against the real
    /// limits): the work the search cost.
    pub paths_solved: usize,
}

impl AutoPlacement {
    /// The placed poses of every path (flips applied), ready for [`solve_paths`](crate::path::solve_paths).
    pub fn apply(&self, paths: &[Vec<Pose>]) -> Vec<Vec<Pose>> {
        place_paths(&self.placement, &self.flipped, paths)
    }
}

/// `paths` placed by `placement`, each path's tool axes reversed where `flipped` says so.
pub fn place_paths(placement: &Placement, flipped: &[bool], paths: &[Vec<Pose>]) -> Vec<Vec<Pose>> {
    paths
        .iter()
        .enumerate()
        .map(|(i, poses)| {
            let flip = flipped.get(i).copied().unwrap_or(false);
            poses
                .iter()
                .map(|p| {
                    let q = placement.apply_pose(p);
                    if flip {
                        Pose {
                            position: q.position,
                            axis: -q.axis,
                        }
                    } else {
                        q
                    }
                })
                .collect()
        })
        .collect()
}

/// The 24 rotations that map coordinate axes onto coordinate axes, as `[rx, ry, rz]` degrees,
/// the identity first, then by the number of non-zero angles and the angles themselves.
pub fn axis_aligned_rotations() -> Vec<[f64; 3]> {
    let quarter = [0.0, 90.0, 180.0, 270.0];
    let mut all: Vec<[f64; 3]> = Vec::new();
    for &rx in &quarter {
        for &ry in &quarter {
            for &rz in &quarter {
                all.push([rx, ry, rz]);
            }
        }
    }
    all.sort_by(|a, b| {
        let nz = |r: &[f64; 3]| r.iter().filter(|v| **v != 0.0).count();
        nz(a)
            .cmp(&nz(b))
            .then(a.partial_cmp(b).unwrap_or(std::cmp::Ordering::Equal))
    });
    let mut out: Vec<[f64; 3]> = Vec::new();
    let mut seen: Vec<Matrix3<f64>> = Vec::new();
    for r in all {
        let m = Placement::new(Vector3::zeros(), r).rotation().into_inner();
        let m = m.map(f64::round);
        if !seen.contains(&m) {
            seen.push(m);
            out.push(r);
        }
    }
    out
}

/// Why one candidate rotation does not fit.
#[derive(Debug, Clone)]
struct Shortfall {
    /// The axis name.
    axis: &'static str,
    /// How much is missing (mm or degrees).
    missing: f64,
    /// What it is about.
    detail: String,
}

/// Chooses one rigid placement of the part (and the side of each contour) so that every pose of
/// every path is reachable within the machine's limits, preferring the part as modelled and the
/// middle of the travel; see the module documentation for the method.
///
/// # Errors
/// [`KinematicsError::NoPlacement`] naming the axis and how much travel (or tilt) is missing
/// for the best candidate; the errors of [`solve_paths`](crate::path::solve_paths) for unusable poses.
pub fn auto_place(
    machine: &Machine,
    paths: &[(&str, &[Pose])],
    options: &AutoPlaceOptions,
) -> Result<AutoPlacement> {
    validate(options)?;
    let work = Work::new(machine, paths, options);
    let all: Vec<usize> = (0..paths.len()).collect();
    let found = search(&work, &all, false)?;
    Ok(AutoPlacement {
        paths_solved: work.solved.load(std::sync::atomic::Ordering::Relaxed),
        ..found
    })
}

/// Checks the options [`auto_place`] and [`auto_setups`] take.
fn validate(options: &AutoPlaceOptions) -> Result<()> {
    options.path_options.validate()?;
    if !(options.margin_mm.is_finite() && options.margin_mm >= 0.0) {
        return Err(KinematicsError::BadOption {
            name: "margin_mm",
            value: options.margin_mm,
            reason: "must be finite and >= 0 (mm)",
        });
    }
    Ok(())
}

/// The search of [`auto_place`] over the paths `idx` of `work`. With `bound`, a candidate
/// whose poses cannot fit the linear travel in any translation ([`Work::envelope_short`]) is
/// refused before it is solved; its shortfall is then only a lower bound, so the error names
/// the exact shortfall only without it (set-ups only ask whether a group fits).
fn search(work: &Work<'_>, idx: &[usize], bound: bool) -> Result<AutoPlacement> {
    let options = work.options;
    let mut best_short: Option<Shortfall> = None;
    let mut tried = 0;
    // Rounds of candidates: the part as modelled; quarter turns; general orientations that
    // bring every contour within the tilt range. Within a round the candidate with the largest
    // clearance wins; the first round with a fit ends the search.
    let rounds: Vec<Vec<Rotation3<f64>>> = if options.rotate {
        let quarter: Vec<Rotation3<f64>> = axis_aligned_rotations()
            .into_iter()
            .skip(1)
            .map(|r| Placement::new(Vector3::zeros(), r).rotation())
            .collect();
        vec![vec![Rotation3::identity()], quarter]
    } else {
        vec![vec![Rotation3::identity()]]
    };
    let mut general_done = !options.rotate;
    let mut round = 0;
    loop {
        let candidates = if round < rounds.len() {
            rounds[round].clone()
        } else if !general_done {
            general_done = true;
            general_orientations(&work.reach(idx))
        } else {
            break;
        };
        round += 1;
        let mut best: Option<AutoPlacement> = None;
        for rot in candidates {
            tried += 1;
            match try_rotation(work, idx, &rot, bound) {
                Ok(found) => {
                    if best
                        .as_ref()
                        .is_none_or(|b| found.clearance_mm > b.clearance_mm + 1e-9)
                    {
                        best = Some(found);
                    }
                }
                Err(TryError::Short(s)) => {
                    if best_short.as_ref().is_none_or(|b| s.missing < b.missing) {
                        best_short = Some(s);
                    }
                }
                Err(TryError::Hard(e)) => return Err(e),
            }
        }
        if let Some(b) = best {
            return Ok(AutoPlacement {
                rotations_tried: tried,
                ..b
            });
        }
    }
    let s = best_short.unwrap_or(Shortfall {
        axis: "X",
        missing: 0.0,
        detail: "no candidate orientation".into(),
    });
    Err(KinematicsError::NoPlacement {
        axis: s.axis,
        missing: s.missing,
        detail: s.detail,
        rotations_tried: tried,
    })
}

/// Orientations of the part in which every contour's tool axes (on one side of the sheet or
/// the other) are within the tilt range: directions `d` of the part that could point up (a
/// Fibonacci lattice of 2,048 directions; `fits`, per path and direction, from
/// [`Work::reach`]), the closest to the modelled up direction first, each with 8 turns about
/// the vertical.
fn general_orientations(fits: &[&[bool]]) -> Vec<Rotation3<f64>> {
    let lattice = up_directions();
    let mut good: Vec<(f64, Vector3<f64>)> = lattice
        .iter()
        .enumerate()
        .filter(|(d, _)| fits.iter().all(|f| f[*d]))
        .map(|(_, d)| (d.angle(&Vector3::z()), *d))
        .collect();
    good.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut picked: Vec<Vector3<f64>> = Vec::new();
    for (_, d) in good {
        if picked.iter().all(|p| p.angle(&d) > 10f64.to_radians()) {
            picked.push(d);
        }
        if picked.len() == 4 {
            break;
        }
    }
    let mut out = Vec::new();
    for d in picked {
        let up = turn_up(&d);
        for k in 0..8 {
            let yaw =
                Rotation3::from_axis_angle(&Vector3::z_axis(), (45.0 * k as f64).to_radians());
            out.push(yaw * up);
        }
    }
    out
}

enum TryError {
    Short(Shortfall),
    Hard(KinematicsError),
}

/// A pose's tilt reachable with either inverse solution.
fn tilt_reachable(machine: &Machine, pose: &Pose) -> std::result::Result<(), f64> {
    tilt_reachable_within(machine, pose, 0.0)
}

/// A pose's tilt reachable with either inverse solution, `inset` degrees inside the limits.
fn tilt_reachable_within(
    machine: &Machine,
    pose: &Pose,
    inset: f64,
) -> std::result::Result<(), f64> {
    let Some(range) = machine.limits[3] else {
        return Ok(());
    };
    let range = Range::new(range.min + inset, range.max - inset);
    let sols = machine.kinematics.inverse(pose);
    let mut miss = f64::INFINITY;
    for s in sols {
        let t = s.tilt;
        let m = if t < range.min {
            range.min - t
        } else if t > range.max {
            t - range.max
        } else {
            0.0
        };
        miss = miss.min(m);
    }
    if miss <= 1e-9 {
        Ok(())
    } else {
        Err(miss)
    }
}

fn path_tilt_shortfall(machine: &Machine, poses: &[Pose]) -> f64 {
    poses
        .iter()
        .filter_map(|p| tilt_reachable(machine, p).err())
        .fold(0.0, f64::max)
}

/// One candidate rotation for the paths `idx` of `work`: the side of each path, the solve with
/// the linear axes free, the translation, and the check against the real limits. With
/// `bound`, refused before any solve where [`Work::envelope_short`] says the travel is short.
fn try_rotation(
    work: &Work<'_>,
    idx: &[usize],
    rot: &Rotation3<f64>,
    bound: bool,
) -> std::result::Result<AutoPlacement, TryError> {
    let options = work.options;
    let machine = &work.inset;
    let tilt_name = machine.kinematics.tilt_name();
    let rotation = Placement::from_rotation(Vector3::zeros(), rot);
    let owned: Vec<Vec<Pose>> = idx.iter().map(|&i| work.paths[i].1.to_vec()).collect();
    let rotated = place_paths(&rotation, &[], &owned);
    // 1. The side of each contour.
    let mut flipped = vec![false; rotated.len()];
    for (k, poses) in rotated.iter().enumerate() {
        let short = path_tilt_shortfall(machine, poses);
        if short == 0.0 {
            continue;
        }
        let reversed: Vec<Pose> = poses
            .iter()
            .map(|p| Pose {
                position: p.position,
                axis: -p.axis,
            })
            .collect();
        let short_rev = path_tilt_shortfall(machine, &reversed);
        if options.flip && short_rev == 0.0 {
            flipped[k] = true;
        } else {
            let missing = if options.flip {
                short.min(short_rev)
            } else {
                short
            };
            return Err(TryError::Short(Shortfall {
                axis: tilt_name,
                missing,
                detail: format!(
                    "path \"{}\": its tool axes need {missing:.3} deg more {tilt_name} travel{}",
                    work.paths[idx[k]].0,
                    if options.flip {
                        " on either side of the sheet"
                    } else {
                        ""
                    }
                ),
            }));
        }
    }
    let sided = place_paths(&Placement::IDENTITY, &flipped, &rotated);
    // 2. The linear travel, cheaply (a lower bound); then the solve with the linear axes free.
    if bound {
        if let Some(s) = work.envelope_short(&sided) {
            return Err(TryError::Short(s));
        }
    }
    let solved = work
        .free_solve(idx, rot, &flipped, &sided)
        .map_err(|e| match e {
            KinematicsError::OutOfLimits {
                axis,
                value,
                min,
                max,
                ref path_id,
                ..
            } => TryError::Short(Shortfall {
                axis,
                missing: (min - value).max(value - max),
                detail: format!("path \"{path_id}\": {e}"),
            }),
            other => TryError::Hard(other),
        })?;
    // 3. The translation.
    let t = translation(machine, &solved, options.margin_mm).map_err(TryError::Short)?;
    let placement = Placement::new(t, rotation.rotation_deg);
    // 4. Check against the real limits.
    let placed = place_paths(&placement, &flipped, &owned);
    let check = work.check_solve(idx, &placed).map_err(|e| match e {
        KinematicsError::OutOfLimits {
            axis,
            value,
            min,
            max,
            ..
        } => TryError::Short(Shortfall {
            axis,
            missing: (min - value).max(value - max),
            detail: e.to_string(),
        }),
        other => TryError::Hard(other),
    })?;
    let clearance_mm = clearance(machine, &check);
    Ok(AutoPlacement {
        placement,
        flipped,
        clearance_mm,
        rotations_tried: 0,
        paths_solved: 0,
    })
}

/// The smallest distance of any solved linear axis value to its limits.
fn clearance(machine: &Machine, solved: &[SolvedPath]) -> f64 {
    let mut c = f64::INFINITY;
    for s in solved {
        for a in &s.axes {
            let q = a.to_array();
            for k in 0..3 {
                if let Some(r) = machine.limits[k] {
                    c = c.min(q[k] - r.min).min(r.max - q[k]);
                }
            }
        }
    }
    c
}
