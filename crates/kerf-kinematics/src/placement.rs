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
use crate::path::{solve_paths, PathInput, PathOptions, SolvedPath};
use crate::pose::{Axes, Pose};

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
    /// A message naming the bad field.
    pub fn parse(text: &str) -> std::result::Result<Self, String> {
        let fields: Vec<&str> = text.split(',').map(str::trim).collect();
        if fields.len() != 3 && fields.len() != 6 {
            return Err(format!(
                "expected X,Y,Z or X,Y,Z,RX,RY,RZ (mm, degrees) or auto, got {} values",
                fields.len()
            ));
        }
        let names = ["X", "Y", "Z", "RX", "RY", "RZ"];
        let mut v = [0.0; 6];
        for (k, f) in fields.iter().enumerate() {
            let x: f64 = f
                .parse()
                .map_err(|_| format!("{}: not a number: {f:?}", names[k]))?;
            if !x.is_finite() || x.abs() > 1e7 {
                return Err(format!(
                    "{}: must be finite and within 1e7 (got {f})",
                    names[k]
                ));
            }
            v[k] = x;
        }
        Ok(Self::new(
            Vector3::new(v[0], v[1], v[2]),
            [v[3], v[4], v[5]],
        ))
    }
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
    /// Distance kept from the tilt axis' limits, degrees (the interpolator's smooth motion
    /// between poses may swing slightly past a pose that sits on a limit). Default 0.5.
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
            tilt_margin_deg: 0.5,
            path_options: PathOptions::default(),
        }
    }
}

impl AutoPlaceOptions {
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
}

impl AutoPlacement {
    /// The placed poses of every path (flips applied), ready for [`solve_paths`].
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
/// for the best candidate; the errors of [`solve_paths`] for unusable poses.
pub fn auto_place(
    machine: &Machine,
    paths: &[(&str, &[Pose])],
    options: &AutoPlaceOptions,
) -> Result<AutoPlacement> {
    options.path_options.validate()?;
    if !(options.margin_mm.is_finite() && options.margin_mm >= 0.0) {
        return Err(KinematicsError::BadOption {
            name: "margin_mm",
            value: options.margin_mm,
            reason: "must be finite and >= 0 (mm)",
        });
    }
    let owned: Vec<Vec<Pose>> = paths.iter().map(|(_, p)| p.to_vec()).collect();
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
            general_orientations(machine, &owned, options.flip)
        } else {
            break;
        };
        round += 1;
        let mut best: Option<AutoPlacement> = None;
        for rot in candidates {
            tried += 1;
            match try_rotation(machine, paths, &owned, &rot, options) {
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
/// Fibonacci lattice of 2,048 directions, each checked on up to 64 poses per contour), the
/// closest to the modelled up direction first, each with 8 turns about the vertical.
fn general_orientations(machine: &Machine, paths: &[Vec<Pose>], flip: bool) -> Vec<Rotation3<f64>> {
    let lattice = up_directions();
    let fits = reachable_directions(machine, paths, flip, &lattice);
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

fn try_rotation(
    real: &Machine,
    paths: &[(&str, &[Pose])],
    owned: &[Vec<Pose>],
    rot: &Rotation3<f64>,
    options: &AutoPlaceOptions,
) -> std::result::Result<AutoPlacement, TryError> {
    // The tilt range less its margin (when the range is wide enough to keep one).
    let mut inset = real.clone();
    if let Some(r) = inset.limits[3] {
        let m = options.tilt_margin_deg.max(0.0);
        if r.max - r.min > 4.0 * m {
            inset.limits[3] = Some(Range::new(r.min + m, r.max - m));
        }
    }
    let machine = &inset;
    let tilt_name = machine.kinematics.tilt_name();
    let rotation = Placement::from_rotation(Vector3::zeros(), rot);
    let rotated = place_paths(&rotation, &[], owned);
    // 1. The side of each contour.
    let mut flipped = vec![false; rotated.len()];
    for (i, poses) in rotated.iter().enumerate() {
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
            flipped[i] = true;
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
                    paths[i].0,
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
    // 2. Solve with the linear axes unlimited.
    let mut free = machine.clone();
    for k in 0..3 {
        free.limits[k] = None;
    }
    let solved = solve(&free, paths, &sided, &options.path_options).map_err(|e| match e {
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
    let placed = place_paths(&placement, &flipped, owned);
    let check = solve(machine, paths, &placed, &options.path_options).map_err(|e| match e {
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
    })
}

fn solve(
    machine: &Machine,
    paths: &[(&str, &[Pose])],
    poses: &[Vec<Pose>],
    options: &PathOptions,
) -> Result<Vec<SolvedPath>> {
    let inputs: Vec<PathInput<'_>> = paths
        .iter()
        .zip(poses)
        .map(|((id, _), p)| PathInput {
            id,
            poses: p,
            curve: None,
        })
        .collect();
    solve_paths(machine, &inputs, options)
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

/// `M` of a pose: how the linear axes move when the tip moves, with the rotary axes fixed
/// (`XYZ = M P + b`). The forward kinematics is affine in `XYZ` at fixed rotaries, so the
/// columns of its matrix `N` are exact differences, and `M = N^-1`.
fn tip_to_axes(machine: &Machine, axes: &Axes) -> Matrix3<f64> {
    let base = machine.kinematics.forward(axes).position;
    let mut n = Matrix3::zeros();
    for k in 0..3 {
        let mut q = axes.to_array();
        q[k] += 1.0;
        let p = machine.kinematics.forward(&Axes::from_array(q)).position;
        n.set_column(k, &(p - base));
    }
    n.try_inverse().unwrap_or_else(Matrix3::identity)
}

/// The translation that puts every solved pose within the linear limits (less the margin),
/// centred; see the module documentation.
fn translation(
    machine: &Machine,
    solved: &[SolvedPath],
    margin: f64,
) -> std::result::Result<Vector3<f64>, Shortfall> {
    let names = machine.axis_names();
    // The linear axis values and their sensitivity to a translation of the part.
    let mut rows: Vec<(Vector3<f64>, Matrix3<f64>)> = Vec::new();
    let mut all_identity = true;
    for s in solved {
        for a in &s.axes {
            let m = tip_to_axes(machine, a);
            if (m - Matrix3::identity()).amax() > 1e-9 {
                all_identity = false;
            }
            rows.push((a.xyz(), m));
        }
    }
    if rows.is_empty() {
        return Ok(Vector3::zeros());
    }
    let ranges: [Option<Range>; 3] = [machine.limits[0], machine.limits[1], machine.limits[2]];
    if all_identity {
        let mut t = Vector3::zeros();
        for k in 0..3 {
            let Some(r) = ranges[k] else { continue };
            let lo = rows.iter().map(|(q, _)| q[k]).fold(f64::INFINITY, f64::min);
            let hi = rows
                .iter()
                .map(|(q, _)| q[k])
                .fold(f64::NEG_INFINITY, f64::max);
            let need = hi - lo;
            let have = (r.max - r.min) - 2.0 * margin;
            if need > have {
                return Err(Shortfall {
                    axis: names[k],
                    missing: need - have,
                    detail: format!(
                        "the part's motion needs {need:.3} mm of {} travel, the machine has {:.3} mm less a margin of {margin} mm on each side: {:.3} mm short",
                        names[k],
                        r.max - r.min,
                        need - have
                    ),
                });
            }
            t[k] = 0.5 * (r.min + r.max) - 0.5 * (lo + hi);
        }
        return Ok(t);
    }
    // Table machines: minimise the largest normalised violation f(t) =
    // max over poses n and limited axes k of (lo_k + margin - (q_nk + (M_n t)_k)) / w_k and
    // ((q_nk + (M_n t)_k) - hi_k + margin) / w_k, w_k the half-width of the travel. Convex and
    // piecewise linear: the central-cut ellipsoid method with subgradient cuts.
    let eval = |t: &Vector3<f64>| -> (f64, Vector3<f64>, usize) {
        let mut worst = f64::NEG_INFINITY;
        let mut grad = Vector3::zeros();
        let mut axis = 0;
        for (q, m) in &rows {
            let x = q + m * t;
            for k in 0..3 {
                let Some(r) = ranges[k] else { continue };
                let w = 0.5 * (r.max - r.min).max(1e-9);
                let low = (r.min + margin - x[k]) / w;
                let high = (x[k] - r.max + margin) / w;
                if low > worst {
                    worst = low;
                    grad = -m.row(k).transpose() / w;
                    axis = k;
                }
                if high > worst {
                    worst = high;
                    grad = m.row(k).transpose() / w;
                    axis = k;
                }
            }
        }
        (worst, grad, axis)
    };
    // Start at the translation that puts the mean axis position at the middle of the travel
    // (for the average M), inside a ball of the machine's size plus the part's distance.
    let mut centre = Vector3::zeros();
    let mut radius: f64 = 1.0;
    for k in 0..3 {
        if let Some(r) = ranges[k] {
            radius = radius.max(r.max.abs()).max(r.min.abs());
        }
    }
    for (q, _) in &rows {
        radius = radius.max(q.norm());
    }
    radius *= 4.0;
    let mut shape = Matrix3::identity() * (radius * radius);
    let (mut best_f, _, mut best_axis) = eval(&centre);
    let mut best_t = centre;
    let n = 3.0;
    for _ in 0..2000 {
        let (f, g, axis) = eval(&centre);
        if f < best_f {
            best_f = f;
            best_t = centre;
            best_axis = axis;
        }
        let pg = shape * g;
        let gpg = g.dot(&pg);
        if gpg.is_nan() || gpg <= 0.0 || gpg.sqrt() < 1e-12 {
            break;
        }
        let step = pg / gpg.sqrt();
        centre -= step / (n + 1.0);
        shape = (shape - step * step.transpose() * (2.0 / (n + 1.0))) * (n * n / (n * n - 1.0));
        // Stop when the ellipsoid is smaller than a micrometre.
        if shape.trace().sqrt() < 1e-4 {
            break;
        }
    }
    if best_f > 0.0 {
        let r = ranges[best_axis].unwrap_or(Range::new(0.0, 0.0));
        let missing = best_f * 0.5 * (r.max - r.min);
        return Err(Shortfall {
            axis: names[best_axis],
            missing,
            detail: format!(
                "no translation keeps every pose within the limits: the best leaves {} {missing:.3} mm outside [{}, {}] (margin {margin} mm)",
                names[best_axis], r.min, r.max
            ),
        });
    }
    Ok(best_t)
}

/// One set-up: contours cut with the part clamped in one placement.
#[derive(Debug, Clone, PartialEq)]
pub struct Setup {
    /// The indices of the paths cut in this set-up, in input order.
    pub paths: Vec<usize>,
    /// The placement of the part for these paths.
    pub placement: Placement,
    /// The smallest distance of any of its poses to a linear limit, mm.
    pub clearance_mm: f64,
}

/// The set-ups [`auto_setups`] chose: one when the whole part fits in one placement.
#[derive(Debug, Clone, PartialEq)]
pub struct SetupPlan {
    /// The set-ups, in cutting order.
    pub setups: Vec<Setup>,
    /// For each path, true if its tool axes were turned to the other side of the sheet.
    pub flipped: Vec<bool>,
    /// How many orientations were tried in all.
    pub rotations_tried: usize,
}

impl SetupPlan {
    /// The set-up that cuts path `path`.
    pub fn setup_of(&self, path: usize) -> usize {
        self.setups
            .iter()
            .position(|s| s.paths.contains(&path))
            .unwrap_or(0)
    }

    /// The placement of path `path`.
    pub fn placement_of(&self, path: usize) -> Placement {
        self.setups
            .get(self.setup_of(path))
            .map_or(Placement::IDENTITY, |s| s.placement)
    }

    /// The placed poses of every path (each with its set-up's placement, flips applied).
    pub fn apply(&self, paths: &[Vec<Pose>]) -> Vec<Vec<Pose>> {
        paths
            .iter()
            .enumerate()
            .map(|(i, p)| {
                let placed = place_paths(
                    &self.placement_of(i),
                    &[self.flipped.get(i).copied().unwrap_or(false)],
                    std::slice::from_ref(p),
                );
                placed.into_iter().next().unwrap_or_default()
            })
            .collect()
    }
}

/// Places the part in as few set-ups as it takes: the whole part in one placement if any fits
/// ([`auto_place`]); else the contours are grouped by the orientation that serves them (greedily:
/// the up direction that brings the most remaining contours within the tilt range takes them),
/// and a group that does not fit the travel in one placement is halved at the median of its
/// contours' centres along its longest extent, recursively, down to single contours.
///
/// # Errors
/// [`KinematicsError::NoPlacement`] for a single contour that fits in no placement (naming the
/// contour, the axis and the shortfall), and the errors of [`auto_place`].
pub fn auto_setups(
    machine: &Machine,
    paths: &[(&str, &[Pose])],
    options: &AutoPlaceOptions,
) -> Result<SetupPlan> {
    let mut plan = SetupPlan {
        setups: Vec::new(),
        flipped: vec![false; paths.len()],
        rotations_tried: 0,
    };
    let all: Vec<usize> = (0..paths.len()).collect();
    if place_group(machine, paths, &all, options, &mut plan)? {
        return Ok(plan);
    }
    if paths.len() <= 1 {
        // The whole part's error.
        auto_place(machine, paths, options)?;
        return Ok(plan);
    }
    let owned: Vec<Vec<Pose>> = paths.iter().map(|(_, p)| p.to_vec()).collect();
    for group in orientation_groups(machine, &owned, options.flip) {
        bisect(machine, paths, &group, options, &mut plan)?;
    }
    Ok(plan)
}

/// Places `group` as one set-up if it fits (true), else false; other errors pass through.
fn place_group(
    machine: &Machine,
    paths: &[(&str, &[Pose])],
    group: &[usize],
    options: &AutoPlaceOptions,
    plan: &mut SetupPlan,
) -> Result<bool> {
    let sub: Vec<(&str, &[Pose])> = group.iter().map(|&i| paths[i]).collect();
    match auto_place(machine, &sub, options) {
        Ok(found) => {
            plan.rotations_tried += found.rotations_tried;
            for (k, &i) in group.iter().enumerate() {
                plan.flipped[i] = found.flipped[k];
            }
            plan.setups.push(Setup {
                paths: group.to_vec(),
                placement: found.placement,
                clearance_mm: found.clearance_mm,
            });
            Ok(true)
        }
        Err(KinematicsError::NoPlacement {
            rotations_tried, ..
        }) => {
            plan.rotations_tried += rotations_tried;
            Ok(false)
        }
        Err(e) => Err(e),
    }
}

/// Places `group`, halving it spatially until every piece fits (see [`auto_setups`]).
fn bisect(
    machine: &Machine,
    paths: &[(&str, &[Pose])],
    group: &[usize],
    options: &AutoPlaceOptions,
    plan: &mut SetupPlan,
) -> Result<()> {
    if place_group(machine, paths, group, options, plan)? {
        return Ok(());
    }
    if group.len() == 1 {
        // The reason, for this contour alone.
        auto_place(machine, &[paths[group[0]]], options)?;
        return Ok(());
    }
    let centre = |i: usize| {
        let mut lo = Vector3::repeat(f64::INFINITY);
        let mut hi = Vector3::repeat(f64::NEG_INFINITY);
        for q in paths[i].1 {
            lo = lo.inf(&q.position.coords);
            hi = hi.sup(&q.position.coords);
        }
        0.5 * (lo + hi)
    };
    let centres: Vec<Vector3<f64>> = group.iter().map(|&i| centre(i)).collect();
    let mut lo = Vector3::repeat(f64::INFINITY);
    let mut hi = Vector3::repeat(f64::NEG_INFINITY);
    for c in &centres {
        lo = lo.inf(c);
        hi = hi.sup(c);
    }
    let axis = (hi - lo).imax();
    let mut order: Vec<usize> = (0..group.len()).collect();
    order.sort_by(|&a, &b| {
        centres[a][axis]
            .total_cmp(&centres[b][axis])
            .then(a.cmp(&b))
    });
    let half = group.len() / 2;
    let mut first: Vec<usize> = order[..half].iter().map(|&k| group[k]).collect();
    let mut second: Vec<usize> = order[half..].iter().map(|&k| group[k]).collect();
    first.sort_unstable();
    second.sort_unstable();
    bisect(machine, paths, &first, options, plan)?;
    bisect(machine, paths, &second, options, plan)
}

/// The directions of the part that may be turned to point up: a Fibonacci lattice of 2,048
/// unit vectors, evenly spread over the sphere (neighbours about 4.5 degrees apart).
fn up_directions() -> Vec<Vector3<f64>> {
    const DIRECTIONS: usize = 2048;
    let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    (0..DIRECTIONS)
        .map(|i| {
            let z = 1.0 - 2.0 * (i as f64 + 0.5) / DIRECTIONS as f64;
            let r = (1.0 - z * z).max(0.0).sqrt();
            Vector3::new(
                r * (golden * i as f64).cos(),
                r * (golden * i as f64).sin(),
                z,
            )
        })
        .collect()
}

/// The rotation that turns direction `d` of the part to +z (a half turn about x for -z).
fn turn_up(d: &Vector3<f64>) -> Rotation3<f64> {
    Rotation3::rotation_between(d, &Vector3::z())
        .unwrap_or_else(|| Rotation3::from_axis_angle(&Vector3::x_axis(), std::f64::consts::PI))
}

/// For each path and each lattice direction: can the tilt axis reach every tool axis of the
/// path (on one side of the sheet, or the other with `flip`) once that direction points up?
/// Checked on up to 256 poses per path, 1 degree inside the limits so that the tool axes
/// between the samples are covered too (the final solve checks them all).
fn reachable_directions(
    machine: &Machine,
    paths: &[Vec<Pose>],
    flip: bool,
    lattice: &[Vector3<f64>],
) -> Vec<Vec<bool>> {
    const PER_PATH: usize = 256;
    const INSET_DEG: f64 = 1.0;
    let turns: Vec<Rotation3<f64>> = lattice.iter().map(turn_up).collect();
    paths
        .iter()
        .map(|p| {
            let step = p.len().div_ceil(PER_PATH).max(1);
            let axes: Vec<Vector3<f64>> = p.iter().step_by(step).map(|q| q.axis).collect();
            turns
                .iter()
                .map(|up| {
                    let side = |sign: f64| {
                        axes.iter().all(|a| {
                            let pose = Pose {
                                position: Point3::origin(),
                                axis: up * (a * sign),
                            };
                            tilt_reachable_within(machine, &pose, INSET_DEG).is_ok()
                        })
                    };
                    side(1.0) || (flip && side(-1.0))
                })
                .collect()
        })
        .collect()
}

/// Groups of paths that one orientation serves: greedily, the lattice direction that brings the
/// most of the remaining paths within the tilt range (ties: the one nearest the modelled up
/// direction) takes them. Paths no direction serves come last, one group each (their
/// placement then fails with the reason).
fn orientation_groups(machine: &Machine, paths: &[Vec<Pose>], flip: bool) -> Vec<Vec<usize>> {
    let lattice = up_directions();
    let fits = reachable_directions(machine, paths, flip, &lattice);
    let mut left: Vec<usize> = (0..paths.len()).collect();
    let mut out = Vec::new();
    while !left.is_empty() {
        let mut best: Option<(usize, usize, f64)> = None;
        for (d, dir) in lattice.iter().enumerate() {
            let n = left.iter().filter(|&&i| fits[i][d]).count();
            let angle = dir.angle(&Vector3::z());
            if n > 0 && best.is_none_or(|(bn, _, ba)| n > bn || (n == bn && angle < ba - 1e-12)) {
                best = Some((n, d, angle));
            }
        }
        match best {
            Some((_, d, _)) => {
                let (take, rest): (Vec<usize>, Vec<usize>) =
                    left.iter().partition(|&&i| fits[i][d]);
                out.push(take);
                left = rest;
            }
            None => {
                out.extend(left.iter().map(|&i| vec![i]));
                left.clear();
            }
        }
    }
    out
}
