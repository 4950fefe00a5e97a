//! The translation that puts the placed part's poses within the linear limits.

use nalgebra::{Matrix3, Vector3};

use super::Shortfall;
use crate::machine::{Machine, Range};
use crate::path::SolvedPath;
use crate::pose::Axes;
/// `M` of a pose: how the linear axes move when the tip moves, with the rotary axes fixed
/// (`XYZ = M P + b`). The forward kinematics is affine in `XYZ` at fixed rotaries, so the
/// columns of its matrix `N` are exact differences, and `M = N^-1`.
pub(super) fn tip_to_axes(machine: &Machine, axes: &Axes) -> Matrix3<f64> {
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

/// Rows a round adds to the working set of [`translation`].
const WORKING_ADD: usize = 64;
/// Rounds of the working set before [`translation`] minimises over every row (as it does
/// once the set holds more than a quarter of the rows).
const WORKING_ROUNDS: usize = 64;

/// The translation that puts every solved pose within the linear limits (less the margin),
/// centred; see the module documentation.
pub(super) fn translation(
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
    let (best_f, best_t, best_axis, _) = minimax(&rows, &ranges, margin, true);
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

/// The minimiser of the table machines' `f(t)` over `rows` (the linear axes of each pose and
/// their sensitivity to the translation; see [`translation`]): `(f, t, worst axis)`. With
/// `working_set`, over a working set of the rows that grows until it certifies its minimiser
/// for every row; without, over every row at each cut (the reference the tests compare with).
/// The last value is true where the working set's certificate ended it.
fn minimax(
    rows: &[(Vector3<f64>, Matrix3<f64>)],
    ranges: &[Option<Range>; 3],
    margin: f64,
    working_set: bool,
) -> (f64, Vector3<f64>, usize, bool) {
    // Table machines: minimise the largest normalised violation f(t) =
    // max over poses n and limited axes k of (lo_k + margin - (q_nk + (M_n t)_k)) / w_k and
    // ((q_nk + (M_n t)_k) - hi_k + margin) / w_k, w_k the half-width of the travel. Convex and
    // piecewise linear: the central-cut ellipsoid method with subgradient cuts, on a working
    // set of rows (below).
    let row_value = |(q, m): &(Vector3<f64>, Matrix3<f64>), t: &Vector3<f64>| {
        let x = q + m * t;
        let mut worst = (f64::NEG_INFINITY, Vector3::zeros(), 0);
        for k in 0..3 {
            let Some(r) = ranges[k] else { continue };
            let w = 0.5 * (r.max - r.min).max(1e-9);
            let low = (r.min + margin - x[k]) / w;
            let high = (x[k] - r.max + margin) / w;
            if low > worst.0 {
                worst = (low, -m.row(k).transpose() / w, k);
            }
            if high > worst.0 {
                worst = (high, m.row(k).transpose() / w, k);
            }
        }
        worst
    };
    // f, a subgradient and the worst axis over the rows `set`.
    let eval = |set: &[usize], t: &Vector3<f64>| -> (f64, Vector3<f64>, usize) {
        let mut worst = (f64::NEG_INFINITY, Vector3::zeros(), 0);
        for &i in set {
            let v = row_value(&rows[i], t);
            if v.0 > worst.0 {
                worst = v;
            }
        }
        worst
    };
    // Start at the origin inside a ball of the machine's size plus the part's distance.
    let mut radius: f64 = 1.0;
    for k in 0..3 {
        if let Some(r) = ranges[k] {
            radius = radius.max(r.max.abs()).max(r.min.abs());
        }
    }
    for (q, _) in rows {
        radius = radius.max(q.norm());
    }
    radius *= 4.0;
    let minimise = |set: &[usize]| -> (f64, Vector3<f64>, usize) {
        let mut centre = Vector3::zeros();
        let mut shape = Matrix3::identity() * (radius * radius);
        let (mut best_f, _, mut best_axis) = eval(set, &centre);
        let mut best_t = centre;
        let n = 3.0;
        for _ in 0..2000 {
            let (f, g, axis) = eval(set, &centre);
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
        (best_f, best_t, best_axis)
    };
    // The working set: the rows extreme in each axis at t = 0, then, round by round, the rows
    // worse at the set's minimiser than the set's own worst (at most WORKING_ADD a round,
    // worst first). When none is, the minimiser's value over every row is the set's, which
    // is at most the minimum over every row (a subset's minimum is a lower bound): it is the
    // minimiser of the whole. After WORKING_ROUNDS rounds, every row.
    let all: Vec<usize> = (0..rows.len()).collect();
    let mut set: Vec<usize> = Vec::new();
    for k in 0..3 {
        let key = |i: &usize| rows[*i].0[k];
        let lo = all.iter().copied().min_by(|a, b| key(a).total_cmp(&key(b)));
        let hi = all.iter().copied().max_by(|a, b| key(a).total_cmp(&key(b)));
        set.extend(lo.into_iter().chain(hi));
    }
    set.sort_unstable();
    set.dedup();
    let mut in_set = vec![false; rows.len()];
    for &i in &set {
        in_set[i] = true;
    }
    let mut round = 0;
    loop {
        // Past a quarter of the rows a working set costs more than every row.
        if !working_set || round == WORKING_ROUNDS || 4 * set.len() > rows.len() {
            let (f, t, axis) = minimise(&all);
            break (f, t, axis, false);
        }
        round += 1;
        let (f, t, axis) = minimise(&set);
        let own = eval(&set, &t).0;
        let mut worse: Vec<(f64, usize)> = all
            .iter()
            .filter(|&&i| !in_set[i])
            .map(|&i| (row_value(&rows[i], &t).0, i))
            .filter(|&(v, _)| v > own)
            .collect();
        if worse.is_empty() {
            break (f, t, axis, true);
        }
        worse.sort_unstable_by(|a, b| b.0.total_cmp(&a.0).then(a.1.cmp(&b.1)));
        for &(_, i) in worse.iter().take(WORKING_ADD) {
            in_set[i] = true;
            set.push(i);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The working set's minimiser is the whole's: on rows like a trunnion table's (linear
    /// axes of poses spread over a part, sensitivities rotations about x then z), the value
    /// over every row at the working set's answer is the reference's minimum, to the
    /// ellipsoid's accuracy.
    #[test]
    fn the_working_set_finds_the_minimum_over_every_row() {
        let ranges = [
            Some(Range::new(-400.0, 400.0)),
            Some(Range::new(-300.0, 300.0)),
            Some(Range::new(-200.0, 400.0)),
        ];
        // A small deterministic generator (no dependency for one test).
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        for case in 0..6 {
            let spread = 100.0 + 60.0 * case as f64;
            let rows: Vec<(Vector3<f64>, Matrix3<f64>)> = (0..3000)
                .map(|_| {
                    let (a, c) = (next() * 1.6, next() * 6.3);
                    let m = *(nalgebra::Rotation3::from_axis_angle(&Vector3::z_axis(), c)
                        * nalgebra::Rotation3::from_axis_angle(&Vector3::x_axis(), a))
                    .matrix();
                    let q = Vector3::new(
                        (next() - 0.5) * spread,
                        (next() - 0.5) * spread,
                        (next() - 0.5) * spread,
                    );
                    (q, m)
                })
                .collect();
            let (fw, tw, _, certified) = minimax(&rows, &ranges, 2.0, true);
            let (fr, _, _, _) = minimax(&rows, &ranges, 2.0, false);
            assert!(
                certified,
                "case {case}: ended by the certificate, not every row"
            );
            let all: f64 = rows
                .iter()
                .flat_map(|(q, m)| {
                    let x = q + m * tw;
                    (0..3).flat_map(move |k| {
                        let r = ranges[k].expect("limited");
                        let w = 0.5 * (r.max - r.min);
                        [(r.min + 2.0 - x[k]) / w, (x[k] - r.max + 2.0) / w]
                    })
                })
                .fold(f64::NEG_INFINITY, f64::max);
            assert!(
                (all - fw).abs() < 1e-12,
                "case {case}: the answer's value over every row {all} is the set's {fw}"
            );
            assert!(
                fw <= fr + 1e-6,
                "case {case}: working set {fw} vs every row {fr}"
            );
        }
    }
}
