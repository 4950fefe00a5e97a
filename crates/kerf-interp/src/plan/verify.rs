//! The verification of a plan the way a test checks it: every cycle of the set-points against
//! every limit by finite differences, and every set-point against the axis ranges.

use kerf_kinematics::Axes;

use super::motion::Motion;
use crate::error::InterpError;
use crate::model::AxisModel;

/// Rounding of one set-point, in units of the largest `|q|` of the stencil: the set-points come
/// from a few roundings each (splines, the blend, the kinematics), and a finite difference of
/// `n`-th order over cycle `T` amplifies them by the sum of its coefficients (2, 4, 8) over `T^n`.
/// At a 10 us cycle a 1e-13 mm rounding of a 500 mm coordinate is a jerk of 8e2 mm/s^3, so
/// a check without this allowance chased rounding: it lowered the plan's caps round after round
/// (a 189 s circle grew to 819 s and was refused).
pub(super) const ROUNDING_ULPS: f64 = 16.0;

/// Cycles over a limit, close together: one window to slow down.
#[derive(Debug, Clone)]
pub(super) struct Violation {
    /// The worst cycle of the window.
    pub(super) cycle: usize,
    /// Program time of the worst cycle.
    pub(super) time: f64,
    /// Program times of the window's first and last bad cycle.
    pub(super) window: [f64; 2],
    /// The window's worst value over limit, per kind (velocity, acceleration, jerk; 0: none).
    pub(super) ratios: [f64; 3],
    pub(super) axis: usize,
    /// 0 velocity, 1 acceleration, 2 jerk.
    pub(super) kind: usize,
    pub(super) value: f64,
    pub(super) limit: f64,
}

/// Every cycle over a limit, worst first, each its own window up to [`MAX_WINDOWS`], then bad
/// cycles less than [`MERGE_CYCLES`] apart merged into one window (so memory stays bounded: a
/// plan over its jerk in 18 M cycles held 18 M violations). A cycle is over a limit when its value exceeds the limit
/// (1e-6 relative slack) by more than the rounding of the set-points can
/// ([`ROUNDING_ULPS`]). Velocity at cycle `i` is
/// `(q_i - q_{i-1}) / T`, acceleration `(q_{i+1} - 2 q_i + q_{i-1}) / T^2`, jerk
/// `(q_{i+1} - 3 q_i + 3 q_{i-1} - q_{i-2}) / T^3`; rows before the first and after the last are
/// the first and the last (rest).
///
/// The same pass checks every set-point against the axis ranges: the first one outside is
/// returned as [`InterpError::OutOfRange`] (1e-9 slack), so that a program is
/// computed once for both checks.
pub(super) fn verify<M: AxisModel + ?Sized>(
    motion: &Motion,
    model: &M,
) -> (Vec<Violation>, Option<InterpError>) {
    let lim = model.limits();
    let mut range_error = None;
    let t = motion.cycle;
    let mut out = Vec::new();
    let slack = 1.0 - 1e-6;
    let ulp = ROUNDING_ULPS * f64::EPSILON;
    let gap = MERGE_CYCLES as f64 * t;
    let mut it = motion.iter(model);
    let n = it.size_hint().0;
    let Some(first) = it.next_full() else {
        return (out, None);
    };
    // Rows i - 2, i - 1, i, i + 1 streamed, so memory does not grow with the program.
    let (mut r2, mut r1, mut r0) = (first, first, first);
    let mut r3 = it.next_full().unwrap_or(r0);
    for i in 0..=n + 1 {
        let (qmm, qm, q0, qp) = (r2.0, r1.0, r0.0, r3.0);
        if i < n && range_error.is_none() {
            range_error = out_of_range(model, i, &q0);
        }
        let mut worst: Option<Violation> = None;
        let mut cycle_ratios = [0.0f64; 3];
        for k in 0..5 {
            let scale = qmm[k]
                .abs()
                .max(qm[k].abs())
                .max(q0[k].abs())
                .max(qp[k].abs())
                * ulp;
            let v = ((q0[k] - qm[k]) / t).abs();
            let a = ((qp[k] - 2.0 * q0[k] + qm[k]) / (t * t)).abs();
            let j = ((qp[k] - 3.0 * q0[k] + 3.0 * qm[k] - qmm[k]) / (t * t * t)).abs();
            let checks = [
                (v, lim.max_velocity[k], 0, 2.0 * scale / t),
                (a, lim.max_acceleration[k], 1, 4.0 * scale / (t * t)),
                (
                    j,
                    lim.max_jerk.map_or(f64::INFINITY, |m| m[k]),
                    2,
                    8.0 * scale / (t * t * t),
                ),
            ];
            for (value, limit, kind, rounding) in checks {
                let over = value > limit * slack + rounding;
                if over {
                    cycle_ratios[kind] = cycle_ratios[kind].max(value / limit);
                }
                if over
                    && worst
                        .as_ref()
                        .is_none_or(|w| value / limit > w.value / w.limit)
                {
                    worst = Some(Violation {
                        cycle: i.min(n.saturating_sub(1)),
                        time: r0.1,
                        window: [r0.1, r0.1],
                        ratios: [0.0; 3],
                        axis: k,
                        kind,
                        value,
                        limit,
                    });
                }
            }
        }
        let out_len = out.len();
        if let Some(mut w) = worst {
            w.ratios = cycle_ratios;
            match out.last_mut() {
                Some(last) if out_len >= MAX_WINDOWS && w.time - last.window[1] <= gap => {
                    last.window[1] = w.time;
                    for k in 0..3 {
                        last.ratios[k] = last.ratios[k].max(w.ratios[k]);
                    }
                    if w.value / w.limit > last.value / last.limit {
                        let (window, ratios) = (last.window, last.ratios);
                        *last = Violation {
                            window,
                            ratios,
                            ..w
                        };
                    }
                }
                _ => out.push(w),
            }
        }
        (r2, r1, r0) = (r1, r0, r3);
        r3 = it.next_full().unwrap_or(r0);
    }
    out.sort_by(|a, b| (b.value / b.limit).total_cmp(&(a.value / a.limit)));
    (out, range_error)
}

/// [`InterpError::OutOfRange`] if set-point `cycle` leaves an axis range (1e-9 slack).
fn out_of_range<M: AxisModel + ?Sized>(model: &M, cycle: usize, q: &Axes) -> Option<InterpError> {
    let lim = model.limits();
    (0..5).find_map(|k| {
        let [lo, hi] = lim.range[k]?;
        (!lim.contains(k, q[k])).then(|| InterpError::OutOfRange {
            cycle,
            axis: model.axis_names()[k].to_string(),
            value: q[k],
            min: lo,
            max: hi,
        })
    })
}

/// Once [`MAX_WINDOWS`] windows are held, bad cycles at most this many cycles apart share one
/// window ([`verify`]).
pub(super) const MERGE_CYCLES: usize = 6;
/// Windows of one bad cycle each, each slowed by its own excess, up to this many; beyond,
/// neighbouring bad cycles share a window slowed by the worst excess among them (which slows
/// more than needed, so only where memory asks for it: merged from the first, a jerk-limited
/// tilted slot planned 2 % longer).
pub(super) const MAX_WINDOWS: usize = 100_000;
