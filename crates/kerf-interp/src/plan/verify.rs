//! The verification of a plan the way a test checks it: every cycle of the set-points against
//! every limit by finite differences, and every set-point against the axis ranges.

use super::motion::Motion;
use crate::error::{InterpError, Result};
use crate::model::AxisModel;

/// A cycle over a limit.
#[derive(Debug, Clone)]
pub(super) struct Violation {
    pub(super) cycle: usize,
    /// Program time of the cycle.
    pub(super) time: f64,
    pub(super) axis: usize,
    /// 0 velocity, 1 acceleration, 2 jerk.
    pub(super) kind: usize,
    pub(super) value: f64,
    pub(super) limit: f64,
}

/// Every cycle over a limit, worst first (at most one per cycle). Velocity at cycle `i` is
/// `(q_i - q_{i-1}) / T`, acceleration `(q_{i+1} - 2 q_i + q_{i-1}) / T^2`, jerk
/// `(q_{i+1} - 3 q_i + 3 q_{i-1} - q_{i-2}) / T^3`; rows before the first and after the last are
/// the first and the last (rest).
pub(super) fn verify<M: AxisModel + ?Sized>(motion: &Motion, model: &M) -> Vec<Violation> {
    let lim = model.limits();
    let t = motion.cycle;
    let mut out = Vec::new();
    let slack = 1.0 - 1e-6;
    let mut it = motion.iter(model);
    let n = it.size_hint().0;
    let Some(first) = it.next_full() else {
        return out;
    };
    // Rows i - 2, i - 1, i, i + 1 streamed, so memory does not grow with the program.
    let (mut r2, mut r1, mut r0) = (first, first, first);
    let mut r3 = it.next_full().unwrap_or(r0);
    for i in 0..=n + 1 {
        let (qmm, qm, q0, qp) = (r2.0, r1.0, r0.0, r3.0);
        let mut worst: Option<Violation> = None;
        for k in 0..5 {
            let v = ((q0[k] - qm[k]) / t).abs();
            let a = ((qp[k] - 2.0 * q0[k] + qm[k]) / (t * t)).abs();
            let j = ((qp[k] - 3.0 * q0[k] + 3.0 * qm[k] - qmm[k]) / (t * t * t)).abs();
            let checks = [
                (v, lim.max_velocity[k], 0),
                (a, lim.max_acceleration[k], 1),
                (j, lim.max_jerk.map_or(f64::INFINITY, |m| m[k]), 2),
            ];
            for (value, limit, kind) in checks {
                if value > limit * slack
                    && worst
                        .as_ref()
                        .is_none_or(|w| value / limit > w.value / w.limit)
                {
                    worst = Some(Violation {
                        cycle: i.min(n.saturating_sub(1)),
                        time: r0.1,
                        axis: k,
                        kind,
                        value,
                        limit,
                    });
                }
            }
        }
        out.extend(worst);
        (r2, r1, r0) = (r1, r0, r3);
        r3 = it.next_full().unwrap_or(r0);
    }
    out.sort_by(|a, b| (b.value / b.limit).total_cmp(&(a.value / a.limit)));
    out
}

pub(super) fn check_ranges<M: AxisModel + ?Sized>(motion: &Motion, model: &M) -> Result<()> {
    let lim = model.limits();
    for (i, q) in motion.iter(model).enumerate() {
        for k in 0..5 {
            if let Some([lo, hi]) = lim.range[k] {
                if !(q[k] >= lo - 1e-9 && q[k] <= hi + 1e-9) {
                    return Err(InterpError::OutOfRange {
                        cycle: i,
                        axis: model.axis_names()[k].to_string(),
                        value: q[k],
                        min: lo,
                        max: hi,
                    });
                }
            }
        }
    }
    Ok(())
}
