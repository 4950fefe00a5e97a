//! The translation that puts the placed part's poses within the linear limits.

use super::*;
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
