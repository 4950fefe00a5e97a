//! Paper 001's recursive interpolator: its table of coefficients, the accumulated-error claims
//! (600 and 5,000 steps; the 1,000,000-step row is in the example), and the spline mode.

use kerf_interp::{
    max_deviation, new_basis_coefficients, spline_setpoints, spline_through, CubicHermite,
    NewBasisSegment, Recurrence,
};
use kerf_interp::{solve_stations, PaperAcHead};
use nalgebra::{Point3, Vector3};

#[test]
fn coefficients_reproduce_the_papers_table() {
    // Paper 001, after eq 6 (six printed digits; OCR lost the sign of A3). The paper names the
    // coefficients A (constant), F (t), C (cos w t), B (sin w t), E (cos 2wt), D (sin 2wt).
    let paper: [[f64; 6]; 4] = [
        // [A, F, C, B, E, D]
        [-1.894638, 4.789276, 3.048948, -3.048948, -0.154310, 0.0],
        [2.894638, -4.789276, -3.048948, 3.048948, 0.154310, 0.0],
        [
            -1.852604, 2.894638, 1.929759, -1.119189, -0.077155, -0.043487,
        ],
        [
            -1.042034, 2.894638, 1.119189, -1.929759, -0.077155, 0.043487,
        ],
    ];
    let ours = new_basis_coefficients();
    for h in 0..4 {
        for j in 0..6 {
            // The paper's last digit is off by up to 2 units (rounding of pi in 1999).
            assert!(
                (ours[h][j] - paper[h][j]).abs() < 3e-6,
                "h{} coefficient {j}: {} vs {}",
                h + 1,
                ours[h][j],
                paper[h][j]
            );
        }
    }
}

/// Segments of the size of the paper's 3.5 m blade (same generator as the example).
/// End points and tangents `(q0, q1, d0, d1)` of one segment.
type Ends = ([f64; 5], [f64; 5], [f64; 5], [f64; 5]);

fn blade_segments() -> Vec<Ends> {
    let mut state = 2024u64;
    let mut next = move |lo: f64, hi: f64| {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        lo + (hi - lo) * ((state >> 11) as f64 / (1u64 << 53) as f64)
    };
    (0..20)
        .map(|_| {
            let q0: [f64; 5] = std::array::from_fn(|k| {
                if k < 3 {
                    next(-2000.0, 2000.0)
                } else {
                    next(-90.0, 90.0)
                }
            });
            let dir: [f64; 3] = std::array::from_fn(|_| next(-1.0, 1.0));
            let n = (dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]).sqrt();
            let len = next(1000.0, 3500.0);
            let q1: [f64; 5] = std::array::from_fn(|k| {
                if k < 3 {
                    q0[k] + len * dir[k] / n
                } else {
                    q0[k] + next(-60.0, 60.0)
                }
            });
            let d0: [f64; 5] = std::array::from_fn(|k| (q1[k] - q0[k]) + next(-0.5, 0.5) * len);
            let d1: [f64; 5] = std::array::from_fn(|k| (q1[k] - q0[k]) + next(-0.5, 0.5) * len);
            (q0, q1, d0, d1)
        })
        .collect()
}

fn worst(steps: usize) -> (f64, f64, f64) {
    let (mut a, mut b, mut c) = (0.0f64, 0.0f64, 0.0f64);
    for (q0, q1, d0, d1) in blade_segments() {
        let nb = NewBasisSegment::hermite(q0, q1, d0, d1);
        let cu = CubicHermite::hermite(q0, q1, d0, d1);
        a = a.max(max_deviation(
            nb.steps(steps, Recurrence::ThreeTerm),
            steps,
            |t| nb.eval(t),
        ));
        b = b.max(max_deviation(
            nb.steps(steps, Recurrence::Reinsch),
            steps,
            |t| nb.eval(t),
        ));
        c = c.max(max_deviation(cu.forward_differences(steps), steps, |t| {
            cu.eval(t)
        }));
    }
    (a, b, c)
}

#[test]
fn accumulated_error_claims() {
    let (three600, reinsch600, fd600) = worst(600);
    let (three5k, reinsch5k, fd5k) = worst(5000);
    println!(
        "600: {three600:e} {reinsch600:e} {fd600:e}; 5000: {three5k:e} {reinsch5k:e} {fd5k:e} (mm)"
    );
    // Paper 001: 600 steps match direct evaluation to 0.1 um; 5,000 steps accumulate less
    // than 0.1 um. Measured (docs/interpolation.md): 3e-5 um and 2e-3 um. Margins x100+.
    assert!(three600 < 1e-7, "three-term, 600 steps: {three600} mm");
    assert!(
        three5k < 1e-4 / 20.0,
        "three-term, 5000 steps: {three5k} mm"
    );
    // ...but the three-term form does accumulate: quadratically in the step count.
    let growth = three5k / three600;
    assert!(
        growth > 20.0,
        "three-term error grows like n^2: x{growth} for x8.3 steps"
    );
    // The Reinsch form of the same recurrence does not amplify round-off.
    assert!(reinsch5k < 1e-9, "Reinsch, 5000 steps: {reinsch5k} mm");
    // Forward differences in double precision: linear growth, far below the paper's bound.
    assert!(fd5k < 1e-8, "forward differences, 5000 steps: {fd5k} mm");
    assert!(
        reinsch5k < three5k / 1000.0 && fd5k < three5k / 100.0,
        "ordering"
    );
}

#[test]
fn spline_mode_passes_through_the_points_c2() {
    let m = PaperAcHead::paper_000();
    let tips: Vec<Point3<f64>> = (0..12)
        .map(|i| {
            let a = i as f64 * 0.4;
            Point3::new(30.0 * a.cos() + i as f64, 20.0 * a.sin(), 2.0 * i as f64)
        })
        .collect();
    let axes: Vec<Vector3<f64>> = tips
        .iter()
        .map(|p| Vector3::new(p.x / 200.0, p.y / 150.0, 1.0).normalize())
        .collect();
    let st = solve_stations(&m, &tips, Some(&axes), None, None).expect("reachable");
    let segs = spline_through(&st).expect("spline");
    // C2 at every joint, in the chord-length parameter u = h t.
    for w in segs.windows(2) {
        let ((a, ha), (b, hb)) = (&w[0], &w[1]);
        let (pa, pb) = (a.eval(1.0), b.eval(0.0));
        let (da, db) = (a.derivative(1.0), b.derivative(0.0));
        let (sa, sb) = (a.second_derivative(1.0), b.second_derivative(0.0));
        for k in 0..5 {
            assert!((pa[k] - pb[k]).abs() < 1e-9, "C0");
            assert!(
                (da[k] / ha - db[k] / hb).abs() < 1e-9 * (1.0 + da[k].abs() / ha),
                "C1"
            );
            assert!(
                (sa[k] / (ha * ha) - sb[k] / (hb * hb)).abs()
                    < 1e-7 * (1.0 + sa[k].abs() / (ha * ha)),
                "C2 axis {k}"
            );
        }
    }
    let rows = spline_setpoints(&m, &st, 3000.0, 0.002, Recurrence::Reinsch).expect("set-points");
    assert_eq!(rows[0], st[0].axes, "starts on the first point");
    assert_eq!(
        rows[rows.len() - 1],
        st[11].axes,
        "ends exactly on the last point"
    );
    for s in &st {
        assert!(
            rows.contains(&s.axes),
            "passes exactly through every station"
        );
    }
    // Errors: too few points, coincident tips, bad feed.
    assert!(spline_through(&st[..1]).is_err(), "one point");
    let dup = [st[0], st[0], st[1]];
    assert!(spline_through(&dup).is_err(), "coincident tips");
    assert!(
        spline_setpoints(&m, &st, f64::NAN, 0.002, Recurrence::ThreeTerm).is_err(),
        "NaN feed"
    );
}
