//! Tool-axis control within a tilt-tolerance cone.
//!
//! A laser does not need its beam exactly on the surface normal: a tilt of a degree changes
//! the cut very little, and following every wiggle of the normal costs rotary motion, above all
//! near the pole of a head, where C moves as `1 / sin(tilt)` for a given turn of the tool axis.
//! [`tilt_within_cone`] chooses, for each pose of a path, a tool axis within `tolerance` of the
//! pose's normal so that the rotary axes move as little and as evenly as possible.
//!
//! **Coordinates.** Every machine type of `kerf.machine/1` has its C axis along the workpiece
//! z, and its tilt is the tool axis' angle to that axis, so a tool axis is `(t, C)`: a signed
//! tilt `t` and an azimuth `C` taken modulo 180 degrees (`(t, C)` and `(-t, C + 180)` are the
//! same axis, the two inverse solutions). The machine's C differs from the azimuth by a
//! constant and a sign, its tilt from `t` by a sign: rotary travel in `(t, C)` is the
//! machine's.
//!
//! **Two taut strings.** With `s` the tool tip's path length, kerf first chooses `C(s)`, then
//! `t(s)`. The cone of half-angle `theta` around a normal at angle `phi` from the pole is seen
//! from the pole under the azimuths `c +- asin(sin theta / sin phi)` (every azimuth when
//! `phi <= theta`: the pole itself is in the cone). Through these intervals, one per pose,
//! kerf draws the *taut string*: the shortest curve in the `(s, C)` plane that passes every
//! interval. It is the curve that minimises `sum f(dC/ds) ds` for every convex `f` at once,
//! so it has the least C travel (`f = |.|`) and the least peak C rate at a given feed
//! (`f = max`): C is held while the cone allows it and turns at an even rate where it must.
//! Given `C`, the tilts whose axis lies in the cone form the interval `psi +- delta` with
//! `a = n_z`, `b = n_x cos C + n_y sin C`, `psi = atan2(b, a)` and
//! `delta = acos(cos theta / hypot(a, b))` (the meridian of azimuth `C` cut by the cone); a
//! second taut string through them gives `t(s)`. Both steps keep every pose in its cone by
//! construction; a final check measures each chosen axis against its normal.
//!
//! **Where the tip stands still** (a turn of the normal at a point, e.g. at a crease between
//! faces), the poses share one `s`: their intervals are intersected, and where the
//! intersection is empty (a jump wider than the cone) the string ends at the interval's bound
//! nearest the next one and starts again there: the axis turns at the point by the least
//! angle the cones allow.
//!
//! The derivation and the error budget are in `docs/kinematics.md` ("Tilt tolerance").

use std::f64::consts::FRAC_PI_2;

use nalgebra::Vector3;

use crate::pose::Pose;

/// The work allowed per gate of a taut string (gate visits), with [`STRING_WORK_FLOOR`]: a
/// string that needs more keeps the normals' own values for that string (a correct, unsmoothed
/// result) and the report says so.
const STRING_WORK_PER_GATE: usize = 256;
/// The work every taut string may use whatever its length.
const STRING_WORK_FLOOR: usize = 65_536;

/// The fraction of the tolerance the strings aim at: the controller interpolates the axes
/// linearly between poses, and the axis between two poses in the cone may leave it by a
/// second-order amount; the margin keeps it inside (`docs/kinematics.md`).
pub const TILT_WORKING_FRACTION: f64 = 0.95;

/// The chosen tool axes of one path and what the choice did.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct TiltChoice {
    /// The chosen unit tool axis of each pose, in order.
    pub axes: Vec<Vector3<f64>>,
    /// What the choice did.
    pub report: TiltReport,
}

/// What a tilt tolerance did to one path ([`tilt_within_cone`]).
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct TiltReport {
    /// The tolerance in force (degrees).
    pub tolerance_deg: f64,
    /// The largest angle between a chosen axis and its pose's normal (degrees).
    pub max_deviation_deg: f64,
    /// The pose where it occurs (an index into the poses given).
    pub max_deviation_at: usize,
    /// The rotary travel `sum |d t| + |d C|` (degrees) of the normals themselves, in the
    /// `(t, C)` coordinates of the module documentation (the tilt is exact and C is the
    /// normal's azimuth, held where the normal is within 1e-9 rad of the pole).
    pub rotary_travel_exact_deg: f64,
    /// The same for the chosen axes.
    pub rotary_travel_deg: f64,
    /// Gate visits of the taut strings: the work done, bounded by 256 per pose plus 65,536
    /// per string.
    pub work: usize,
    /// Strings that exceeded their work budget and kept the normals' own values.
    pub strings_over_budget: usize,
}

/// Chooses a tool axis within `tolerance_deg` of each pose's axis (its surface normal) so that
/// the rotary axes move least (see the module documentation). `tolerance_deg <= 0` (or not
/// finite, or no poses) returns the poses' own axes. The axes must be unit vectors (as
/// [`crate::solve_path`] makes them).
pub fn tilt_within_cone(poses: &[Pose], tolerance_deg: f64) -> TiltChoice {
    let normals: Vec<Vector3<f64>> = poses.iter().map(|p| p.axis).collect();
    if !(tolerance_deg.is_finite() && tolerance_deg > 0.0) || poses.is_empty() {
        return unchanged(poses, tolerance_deg);
    }
    let theta = tolerance_deg.to_radians().min(FRAC_PI_2);
    choose(poses, &normals, &vec![theta; poses.len()], tolerance_deg)
}

/// The poses' own axes, with the report of a choice that changed nothing.
fn unchanged(poses: &[Pose], tolerance_deg: f64) -> TiltChoice {
    let axes: Vec<Vector3<f64>> = poses.iter().map(|p| p.axis).collect();
    let travel = Coords::of(&axes).travel_deg();
    TiltChoice {
        axes,
        report: TiltReport {
            tolerance_deg: tolerance_deg.max(0.0),
            max_deviation_deg: 0.0,
            max_deviation_at: 0,
            rotary_travel_exact_deg: travel,
            rotary_travel_deg: travel,
            work: 0,
            strings_over_budget: 0,
        },
    }
}

/// A cone of tool axes: its unit centre axis and its half-angle (degrees).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Cone {
    /// The centre (unit).
    pub axis: Vector3<f64>,
    /// The half-angle, degrees.
    pub half_angle_deg: f64,
}

/// [`tilt_within_cone`] with a cone of its own for each pose: the chosen axis of pose `i` lies
/// within `cones[i]` (a cone of half-angle <= 0 holds its centre alone), the rotary axes
/// moving least. The poses' own axes (their normals) are what the report measures against;
/// `tolerance_deg` is the tolerance it states. So a caller narrows a pose's choice, e.g. to
/// the axes that keep the head clear of a wall, inside the normal's tolerance cone. `cones`
/// must hold one cone per pose (else the poses' own axes are returned).
pub fn tilt_within_cones(poses: &[Pose], cones: &[Cone], tolerance_deg: f64) -> TiltChoice {
    if poses.is_empty() || cones.len() != poses.len() {
        return unchanged(poses, tolerance_deg);
    }
    let centres: Vec<Vector3<f64>> = cones.iter().map(|c| c.axis.normalize()).collect();
    let thetas: Vec<f64> = cones
        .iter()
        .map(|c| {
            if c.half_angle_deg.is_finite() && c.half_angle_deg > 0.0 {
                c.half_angle_deg.to_radians().min(FRAC_PI_2)
            } else {
                0.0
            }
        })
        .collect();
    choose(poses, &centres, &thetas, tolerance_deg)
}

/// The taut strings through the cones `(centres[i], thetas[i])` (unit centres, radians), the
/// report measured against the poses' own axes.
fn choose(
    poses: &[Pose],
    centres: &[Vector3<f64>],
    thetas: &[f64],
    tolerance_deg: f64,
) -> TiltChoice {
    let TiltChoice {
        mut axes,
        mut report,
    } = unchanged(poses, tolerance_deg);
    let normals = axes.clone();
    let centre_coords = Coords::of(centres);
    let s = path_length(poses);
    let mut strings = Strings::default();

    // 1. The azimuth: intervals of C seen from the pole.
    let (c_lo, c_hi): (Vec<f64>, Vec<f64>) = (0..poses.len())
        .map(|i| {
            let working = thetas[i] * TILT_WORKING_FRACTION;
            let phi = centre_coords.pole_angle[i];
            let half = if phi <= working {
                FRAC_PI_2 // the pole is in the cone: every line through it (C modulo 180)
            } else {
                (working.sin() / phi.sin()).clamp(0.0, 1.0).asin()
            };
            (centre_coords.c[i] - half, centre_coords.c[i] + half)
        })
        .unzip();
    let c = strings.solve(&s, &c_lo, &c_hi, &centre_coords.c);

    // 2. The tilt along each chosen azimuth.
    let (t_lo, t_hi): (Vec<f64>, Vec<f64>) = (0..poses.len())
        .map(|i| {
            let working = thetas[i] * TILT_WORKING_FRACTION;
            let n = centres[i];
            let (sin_c, cos_c) = c[i].sin_cos();
            let a = n.z;
            let b = n.x * cos_c + n.y * sin_c;
            let psi = b.atan2(a);
            let r = a.hypot(b);
            let delta = if r > 0.0 {
                (working.cos() / r).clamp(-1.0, 1.0).acos()
            } else {
                0.0
            };
            (psi - delta, psi + delta)
        })
        .unzip();
    let t_mid: Vec<f64> = t_lo.iter().zip(&t_hi).map(|(l, h)| 0.5 * (l + h)).collect();
    let t = strings.solve(&s, &t_lo, &t_hi, &t_mid);

    // 3. The axes, each measured against its cone; one outside it (only rounding could put it
    // there) takes the cone's centre. The report measures against the normals.
    for i in 0..poses.len() {
        let (sin_t, cos_t) = t[i].sin_cos();
        let (sin_c, cos_c) = c[i].sin_cos();
        let u = Vector3::new(sin_t * cos_c, sin_t * sin_c, cos_t);
        axes[i] = if angle(&u, &centres[i]) <= thetas[i] {
            u
        } else {
            centres[i]
        };
        let dev = angle(&axes[i], &normals[i]);
        if dev > report.max_deviation_deg.to_radians() {
            report.max_deviation_deg = dev.to_degrees();
            report.max_deviation_at = i;
        }
    }
    report.rotary_travel_deg = Coords::of(&axes).travel_deg();
    report.work = strings.work;
    report.strings_over_budget = strings.over_budget;
    TiltChoice { axes, report }
}

/// The angle between two unit vectors (radians), accurate at small angles.
fn angle(a: &Vector3<f64>, b: &Vector3<f64>) -> f64 {
    a.cross(b).norm().atan2(a.dot(b))
}

/// The tool tip's path length at each pose (mm).
fn path_length(poses: &[Pose]) -> Vec<f64> {
    let mut s = Vec::with_capacity(poses.len());
    let mut acc = 0.0;
    for (i, p) in poses.iter().enumerate() {
        if i > 0 {
            acc += (p.position - poses[i - 1].position).norm();
        }
        s.push(acc);
    }
    s
}

/// Tool axes in `(t, C)`: signed tilt and azimuth unwrapped modulo 180 degrees (radians).
struct Coords {
    /// The signed tilt.
    t: Vec<f64>,
    /// The azimuth, continuous modulo pi.
    c: Vec<f64>,
    /// The angle between the axis' line and the pole (z), in `[0, pi/2]`.
    pole_angle: Vec<f64>,
}

/// Below this angle to the pole (radians) an axis' azimuth is noise: the previous one is kept.
const AZIMUTH_NOISE_RAD: f64 = 1e-9;

impl Coords {
    fn of(axes: &[Vector3<f64>]) -> Self {
        let mut out = Coords {
            t: Vec::with_capacity(axes.len()),
            c: Vec::with_capacity(axes.len()),
            pole_angle: Vec::with_capacity(axes.len()),
        };
        let mut prev_c: Option<f64> = None;
        for u in axes {
            let phi = u.xy().norm().atan2(u.z); // [0, pi]
            let pole_angle = phi.min(std::f64::consts::PI - phi);
            let (c, t) = if phi > AZIMUTH_NOISE_RAD && pole_angle > 0.0 {
                let raw = u.y.atan2(u.x);
                match prev_c {
                    // The nearest of raw + k pi; an odd k flips the tilt's sign.
                    Some(p) => {
                        let k = ((p - raw) / std::f64::consts::PI).round();
                        let c = raw + k * std::f64::consts::PI;
                        let sign = if (k as i64).rem_euclid(2) == 0 {
                            1.0
                        } else {
                            -1.0
                        };
                        (c, sign * phi)
                    }
                    None => (raw, phi),
                }
            } else {
                // At the pole (+z or -z): C is free; keep the previous one.
                (prev_c.unwrap_or(0.0), phi)
            };
            if pole_angle > AZIMUTH_NOISE_RAD {
                prev_c = Some(c);
            }
            out.t.push(t);
            out.c.push(c);
            out.pole_angle.push(pole_angle);
        }
        // Poses at the pole before the first one off it take its azimuth.
        if let Some(first) = out.pole_angle.iter().position(|&a| a > AZIMUTH_NOISE_RAD) {
            let c0 = out.c[first];
            for c in &mut out.c[..first] {
                *c = c0;
            }
        }
        out
    }

    /// `sum |d t| + |d C|` in degrees.
    fn travel_deg(&self) -> f64 {
        let step = |v: &[f64]| v.windows(2).map(|w| (w[1] - w[0]).abs()).sum::<f64>();
        (step(&self.t) + step(&self.c)).to_degrees()
    }
}

/// Taut strings with a shared work count.
#[derive(Default)]
struct Strings {
    work: usize,
    over_budget: usize,
}

/// One gate of a string: the poses `first..=last` (at one `s`), the interval they share.
#[derive(Debug, Clone, Copy)]
struct Gate {
    x: f64,
    lo: f64,
    hi: f64,
    first: usize,
    last: usize,
}

impl Strings {
    /// The value at every pose: a taut string through the intervals `[lo, hi]` over `s`,
    /// `reference` (inside each interval) where a string's budget runs out.
    fn solve(&mut self, s: &[f64], lo: &[f64], hi: &[f64], reference: &[f64]) -> Vec<f64> {
        let n = s.len();
        let mut out = reference.to_vec();
        // Gates: poses at one s share a gate while their intervals intersect; a pose whose
        // interval misses the gate's starts a new gate at the same s (a break).
        let scale = 1e-12 * (1.0 + s.last().copied().unwrap_or(0.0).abs());
        let mut gates: Vec<Gate> = Vec::new();
        for i in 0..n {
            if let Some(g) = gates.last_mut() {
                if (s[i] - g.x).abs() <= scale {
                    let (l, h) = (g.lo.max(lo[i]), g.hi.min(hi[i]));
                    if l <= h {
                        *g = Gate {
                            lo: l,
                            hi: h,
                            last: i,
                            ..*g
                        };
                        continue;
                    }
                }
            }
            gates.push(Gate {
                x: s[i],
                lo: lo[i],
                hi: hi[i],
                first: i,
                last: i,
            });
        }
        // Strings: runs of gates between breaks; at a break, each side ends at its bound
        // nearest the other side.
        let mut start = 0;
        while start < gates.len() {
            let mut end = start;
            while end + 1 < gates.len() && (gates[end + 1].x - gates[end].x).abs() > scale {
                end += 1;
            }
            let mut run: Vec<Gate> = gates[start..=end].to_vec();
            if start > 0 {
                let (prev, g) = (gates[start - 1], &mut run[0]);
                let pin = if prev.hi < g.lo { g.lo } else { g.hi };
                g.lo = pin;
                g.hi = pin;
            }
            if end + 1 < gates.len() {
                let (next, g) = (gates[end + 1], run.last_mut().expect("non-empty"));
                let pin = if g.hi < next.lo { g.hi } else { g.lo };
                g.lo = pin;
                g.hi = pin;
            }
            let budget = STRING_WORK_FLOOR + STRING_WORK_PER_GATE * run.len();
            match taut_string(&run, budget, &mut self.work) {
                Some(values) => {
                    for (g, v) in run.iter().zip(values) {
                        out[g.first..=g.last].fill(v);
                    }
                }
                None => {
                    self.over_budget += 1;
                    // The reference values, moved into the pinned ends' single values.
                    for g in &run {
                        for v in &mut out[g.first..=g.last] {
                            *v = v.clamp(g.lo, g.hi);
                        }
                    }
                }
            }
            start = end + 1;
        }
        out
    }
}

/// The taut string through `gates` (strictly increasing `x`, `lo <= hi`): the value at each
/// gate, or `None` once `budget` gate visits are spent. A free end (an interval wider than a
/// point) is held by a virtual pin far beyond it, so that the string leaves the last bend
/// level (the natural end condition of the shortest string) up to a slope of
/// `range / (1e6 span)`.
fn taut_string(gates: &[Gate], budget: usize, work: &mut usize) -> Option<Vec<f64>> {
    let n = gates.len();
    if n == 1 {
        let g = gates[0];
        return Some(vec![if g.lo.is_finite() && g.hi.is_finite() {
            0.5 * (g.lo + g.hi)
        } else {
            g.lo.max(g.hi.min(0.0))
        }]);
    }
    let span = gates[n - 1].x - gates[0].x;
    let far = 1e6 * (span + 1.0);
    let mid = |g: &Gate| 0.5 * (g.lo + g.hi);
    // The points of the string: a virtual pin, the gates, a virtual pin.
    let mut xs = Vec::with_capacity(n + 2);
    let mut los = Vec::with_capacity(n + 2);
    let mut his = Vec::with_capacity(n + 2);
    let first = gates[0];
    xs.push(first.x - far);
    los.push(mid(&first));
    his.push(mid(&first));
    for g in gates {
        xs.push(g.x);
        los.push(g.lo);
        his.push(g.hi);
    }
    let last = gates[n - 1];
    xs.push(last.x + far);
    los.push(mid(&last));
    his.push(mid(&last));
    let m = xs.len();
    let mut y = vec![0.0; m];
    let mut spent = 0usize;
    // The string from an apex: the tightest rays to the upper and the lower bounds seen so
    // far; when a gate lies wholly above the upper ray (below the lower one) the string bends
    // at the upper (lower) bound that made the ray, which becomes the next apex.
    let mut apex = 0;
    y[0] = los[0];
    // The first and the last bend at a real gate (indices into xs).
    let (mut first_bend, mut last_bend) = (None, None);
    'outer: while apex + 1 < m {
        let (xa, ya) = (xs[apex], y[apex]);
        let (mut up, mut up_at) = (f64::INFINITY, apex);
        let (mut down, mut down_at) = (f64::NEG_INFINITY, apex);
        for i in apex + 1..m {
            spent += 1;
            if spent > budget {
                *work += spent;
                return None;
            }
            let dx = xs[i] - xa;
            let su = (his[i] - ya) / dx;
            let sl = (los[i] - ya) / dx;
            if sl > up {
                // Bend down at the upper bound `up_at`.
                fill(&mut y, &xs, apex, up_at, up);
                apex = up_at;
                bent(apex, &mut first_bend, &mut last_bend, m);
                continue 'outer;
            }
            if su < down {
                fill(&mut y, &xs, apex, down_at, down);
                apex = down_at;
                bent(apex, &mut first_bend, &mut last_bend, m);
                continue 'outer;
            }
            if su < up {
                up = su;
                up_at = i;
            }
            if sl > down {
                down = sl;
                down_at = i;
            }
        }
        // Every gate to the end lies between the rays: the last pin is reached straight.
        let slope = (los[m - 1] - ya) / (xs[m - 1] - xa);
        fill(&mut y, &xs, apex, m - 1, slope);
        break;
    }
    *work += spent;
    // The free ends exactly level: before the first bend and after the last one the string
    // holds the bend's value (the virtual pins left a slope of at most range / far there).
    // Without any bend, one value fits every gate: it is the middle of their intersection
    // nearest the string.
    match (first_bend, last_bend) {
        (Some(b), Some(e)) => {
            let (yb, ye) = (y[b], y[e]);
            for i in 1..b {
                y[i] = yb;
            }
            for i in e + 1..=n {
                y[i] = ye;
            }
        }
        _ => {
            let lo = los[1..=n].iter().copied().fold(f64::NEG_INFINITY, f64::max);
            let hi = his[1..=n].iter().copied().fold(f64::INFINITY, f64::min);
            if lo <= hi {
                let v = (0.5 * (y[1] + y[n])).clamp(lo, hi);
                y[1..=n].fill(v);
            }
        }
    }
    // The values at the gates, kept inside them against rounding.
    Some((1..=n).map(|i| y[i].clamp(los[i], his[i])).collect())
}

/// Records a bend of the string at `at` (an index into the gates with their virtual pins,
/// `m` of them): the first and the last bend at a real gate.
fn bent(at: usize, first: &mut Option<usize>, last: &mut Option<usize>, m: usize) {
    if at > 0 && at + 1 < m {
        first.get_or_insert(at);
        *last = Some(at);
    }
}

/// The string from `from` to `to` on the line of slope `slope` through `(xs[from], y[from])`.
fn fill(y: &mut [f64], xs: &[f64], from: usize, to: usize, slope: f64) {
    let (x0, y0) = (xs[from], y[from]);
    for i in from + 1..=to {
        y[i] = y0 + slope * (xs[i] - x0);
    }
}

#[cfg(test)]
mod tests;
