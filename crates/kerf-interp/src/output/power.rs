//! Laser power that follows the tool tip's speed: the rule and its words in each dialect.
//!
//! A cut needs a constant energy per millimetre of kerf: where the head slows (corners, small
//! holes, the lead-in's start, the pole) a constant power overburns the edge. The power is
//! `P(v) = clamp(P_cut * v / v_cut, P_min, 100)` percent of the source's, `v` the tip's
//! speed, `v_cut` the feed at which the technology gives `P_cut`.
//!
//! - **LinuxCNC**: the controller applies the rule to the *executed* speed, so that its own
//!   blends and accelerations are followed too. The program gives the joints' positions, so
//!   HAL recovers the tip's speed from the joints' speeds: for every kinematics kerf has, the
//!   linear axes are the tip turned by a rotation that depends on the rotary axes, plus
//!   terms of the rotary axes alone (`XYZ = R(t, C) P + o(t, C)`), so with the rotary axes
//!   momentarily fixed `|P'| = |XYZ' - (dL/dt) t' - (dL/dC) C'|`, `L(P, t, C)` the linear axes
//!   of [`crate::AxisModel::linear_axes`] differentiated at a fixed tip. HAL computes
//!   `v = |XYZ' + E2..4 t' + E5..7 C'|` and `power = clamp(E0 v, E1, 100)` every servo cycle
//!   (`ddt` of the five joints' commanded positions, `mult2`, `sum2`, `hypot`, `limit1`:
//!   docs/process.md "Power that follows the speed"). The program sets `E0 = P_cut / v_cut`
//!   (percent per mm/s) and the floor `E1` before each cut's descent, and the six rotary
//!   coefficients `E2..E7` (mm per degree, at the block's middle) with `M67` (synchronized:
//!   they change where the next block starts) wherever the last ones written would misjudge
//!   the block's tip travel by more than 0.5 %. They are linear in the joints' speeds, so the
//!   controller's blends between two blocks are followed too. During the pierce `E1` holds
//!   the pierce power (`M68`, immediate) and `E0` is 0. **linuxcnc-tcp** writes the same: under
//!   tool-tip kinematics the joints are still the machine's, and HAL reads the joints.
//! - **Generic** and **Fanuc**: an `S` word on every cutting block whose power changes, from
//!   kerf's planned speed of the block (the block's tip length over its planned time).
//! - **HEIDENHAIN**: not commanded ([`Dialect::commands_power`](super::Dialect::commands_power)
//!   is false): `S` is a `TOOL CALL` word and Q parameters are computed ahead of the motion, so
//!   nothing in Klartext acts with it; the header gives the technology's power and says so.
//! - **Sinumerik**: Siemens' laser-power pattern, the polynomial `FCTDEF(1, P_min, 100, 0, k)`
//!   evaluated every interpolation cycle on the path velocity by the synchronized action
//!   `ID=1 WHENEVER TRUE DO SYNFCT(1, $A_OUTA[1], $AC_VACTW)` (`k` in percent per mm/min of
//!   the tool tip under TRAORI). Not executed on a Sinumerik here.

use kerf_kinematics::Axes;

use crate::error::{InterpError, Result};

/// Laser power that follows the tool tip's speed (module docs): the cut's power at a
/// reference feed, a floor and the pierce power, percent of the source's power. Built with
/// [`LaserPower::new`] and the `with_*` setters; set on a program with
/// [`GcodeOptions::with_power`](super::GcodeOptions::with_power).
///
/// ```
/// use kerf_interp::LaserPower;
/// let p = LaserPower::new(80.0, 4500.0); // 80 % at 4500 mm/min
/// assert_eq!(p.at_speed(4500.0, 1.0), 80.0);
/// assert_eq!(p.at_speed(2250.0, 1.0), 40.0); // half the speed, half the power
/// assert_eq!(p.at_speed(0.0, 1.0), 16.0); // the floor: 20 % of the cut's
/// assert_eq!(p.at_speed(2250.0, 0.5), 20.0); // a small hole's factor
/// assert_eq!(p.at_speed(9000.0, 1.0), 100.0);
/// assert!(p.with_min_percent(90.0).validate().is_err()); // floor above the cut's power
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct LaserPower {
    /// The power at [`reference_feed_mm_per_min`](Self::reference_feed_mm_per_min), percent.
    pub cut_percent: f64,
    /// The tip speed at which the cut takes [`cut_percent`](Self::cut_percent), mm/min (the
    /// technology entry's feed).
    pub reference_feed_mm_per_min: f64,
    /// The least power while the beam cuts, percent (where the tip stops: a turn in place,
    /// the descent's start). Default 20 % of the cut's.
    pub min_percent: f64,
    /// The power while piercing, percent. Default the cut's.
    pub pierce_percent: f64,
}

impl LaserPower {
    /// `cut_percent` at `reference_feed_mm_per_min`, a floor of 20 % of it and a pierce at it.
    pub fn new(cut_percent: f64, reference_feed_mm_per_min: f64) -> Self {
        Self {
            cut_percent,
            reference_feed_mm_per_min,
            min_percent: 0.2 * cut_percent,
            pierce_percent: cut_percent,
        }
    }

    /// Sets [`min_percent`](Self::min_percent): the floor, percent.
    pub fn with_min_percent(mut self, min_percent: f64) -> Self {
        self.min_percent = min_percent;
        self
    }

    /// Sets [`pierce_percent`](Self::pierce_percent): the pierce power, percent.
    pub fn with_pierce_percent(mut self, pierce_percent: f64) -> Self {
        self.pierce_percent = pierce_percent;
        self
    }

    /// The power at tip speed `v_mm_per_min` on a path whose power is scaled by `factor` (a
    /// small hole's power factor; 1 otherwise): `clamp(factor P_cut v / v_cut, P_min, 100)`.
    pub fn at_speed(&self, v_mm_per_min: f64, factor: f64) -> f64 {
        let p = factor * self.cut_percent * v_mm_per_min / self.reference_feed_mm_per_min;
        if p.is_finite() {
            p.clamp(self.min_percent.min(100.0), 100.0)
        } else {
            self.min_percent
        }
    }

    /// Percent per mm/s of tip speed: the slope of [`at_speed`](Self::at_speed) below its
    /// clamps, scaled by `factor`.
    pub fn per_mm_s(&self, factor: f64) -> f64 {
        factor * self.cut_percent / (self.reference_feed_mm_per_min / 60.0)
    }

    /// Checks every value: percentages in [0, 100], the floor at most the cut's power, the
    /// reference feed finite and > 0.
    ///
    /// # Errors
    /// [`InterpError::BadParameter`] naming the value.
    pub fn validate(&self) -> Result<()> {
        let percent = |name: &'static str, v: f64| {
            if v.is_finite() && (0.0..=100.0).contains(&v) {
                Ok(())
            } else {
                Err(InterpError::BadParameter {
                    name,
                    value: v,
                    reason: "must be a percentage in [0, 100]",
                })
            }
        };
        percent("power.cut_percent", self.cut_percent)?;
        percent("power.min_percent", self.min_percent)?;
        percent("power.pierce_percent", self.pierce_percent)?;
        if self.min_percent > self.cut_percent {
            return Err(InterpError::BadParameter {
                name: "power.min_percent",
                value: self.min_percent,
                reason: "must not exceed the cutting power",
            });
        }
        crate::error::positive(
            "power.reference_feed_mm_per_min",
            self.reference_feed_mm_per_min,
        )?;
        Ok(())
    }
}

/// The six rotary coefficients of a LinuxCNC block from the printed axes `a` to `b` (module
/// docs): `-dL/dt` then `-dL/dC` at the block's middle, mm per degree, by central differences
/// of [`crate::AxisModel::linear_axes`] at the tip there (found from the affine map
/// `P -> L(P, t, C)` at the middle's rotary axes).
pub(super) fn rotary_coefficients<M: crate::AxisModel + ?Sized>(
    model: &M,
    a: &Axes,
    b: &Axes,
) -> [f64; 6] {
    use nalgebra::{Matrix3, Point3, Vector3};
    let m = Axes::from_array(std::array::from_fn(|k| 0.5 * (a[k] + b[k])));
    let (t, c) = (m[3], m[4]);
    let l = |p: &Point3<f64>, t: f64, c: f64| Vector3::from(model.linear_axes(p, t, c));
    let o = l(&Point3::origin(), t, c);
    let r = Matrix3::from_columns(&[
        l(&Point3::new(1.0, 0.0, 0.0), t, c) - o,
        l(&Point3::new(0.0, 1.0, 0.0), t, c) - o,
        l(&Point3::new(0.0, 0.0, 1.0), t, c) - o,
    ]);
    let Some(inv) = r.try_inverse() else {
        return [0.0; 6];
    };
    let tip = Point3::from(inv * (Vector3::new(m[0], m[1], m[2]) - o));
    const H: f64 = 1e-4;
    let dt = (l(&tip, t + H, c) - l(&tip, t - H, c)) / (-2.0 * H);
    let dc = (l(&tip, t, c + H) - l(&tip, t, c - H)) / (-2.0 * H);
    let out = [dt.x, dt.y, dt.z, dc.x, dc.y, dc.z];
    if out.iter().all(|v| v.is_finite()) {
        out
    } else {
        [0.0; 6]
    }
}

/// The tip's travel as the controller's HAL computes it from a joint move `d` (linear mm,
/// rotary degrees) with the rotary coefficients `c`: `|dXYZ + c[0..3] dt + c[3..6] dC|`.
pub(super) fn tip_travel(d: &[f64; 5], c: &[f64; 6]) -> f64 {
    (0..3)
        .map(|j| (d[j] + c[j] * d[3] + c[3 + j] * d[4]).powi(2))
        .sum::<f64>()
        .sqrt()
}

/// The most pieces [`pieces`] cuts one block into (five halvings).
pub(super) const MAX_POWER_PIECES: usize = 32;

/// How far the tip speed the controller computes from a piece's middle coefficients may be
/// from the true one at the piece's ends, as a share of it: 2.5 %.
pub(super) const POWER_SPEED_TOLERANCE: f64 = 0.025;

/// The pieces a LinuxCNC block from `a` to `b` is written in (each a line in joint space, so
/// the motion is the same) so that the tip speed the controller computes from each piece's
/// coefficients ([`rotary_coefficients`] at its middle) is within [`POWER_SPEED_TOLERANCE`]
/// of the true one at the piece's ends (the coefficients turn with C: near the pole a block
/// can swing C by tens of degrees). Each piece as its end's fraction of the block and its
/// coefficients; at most [`MAX_POWER_PIECES`]. A block whose rotary axes do not move is one
/// piece.
pub(super) fn pieces<M: crate::AxisModel + ?Sized>(
    model: &M,
    a: &Axes,
    b: &Axes,
) -> Vec<(f64, [f64; 6])> {
    let at = |f: f64| a.lerp(b, f);
    let d: [f64; 5] = std::array::from_fn(|k| b[k] - a[k]);
    let speed = |c: &[f64; 6]| tip_travel(&d, c);
    let mut out = Vec::new();
    // Depth-first over [f0, f1], left pieces first.
    let mut stack = vec![(0.0f64, 1.0f64)];
    while let Some((f0, f1)) = stack.pop() {
        let (qa, qb) = (at(f0), at(f1));
        let mid = rotary_coefficients(model, &qa, &qb);
        let rotates = d[3] != 0.0 || d[4] != 0.0;
        // No piece so short that its printed ends (6 decimals) could coincide.
        let within = !rotates
            || (f1 - f0) * (MAX_POWER_PIECES as f64) <= 1.0 + 1e-9
            || (f1 - f0) * d.iter().fold(0.0f64, |m, v| m.max(v.abs())) < 2e-4
            || [qa, qb].iter().all(|q| {
                let exact = speed(&rotary_coefficients(model, q, q));
                (speed(&mid) - exact).abs() <= POWER_SPEED_TOLERANCE * exact
            });
        if within {
            out.push((f1, mid));
        } else {
            let fm = 0.5 * (f0 + f1);
            stack.push((fm, f1));
            stack.push((f0, fm));
        }
    }
    out
}

/// A power or scale value as written: four decimals, no `-0`.
pub(super) fn power_number(v: f64) -> String {
    let t = format!("{v:.4}");
    let t = t.trim_end_matches('0').trim_end_matches('.').to_string();
    if t == "-0" || t.is_empty() {
        "0".into()
    } else {
        t
    }
}
