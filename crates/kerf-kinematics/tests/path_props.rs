//! Property tests of the path solver on random machines and random smooth paths: every output
//! point is exact, every rotary step and every non-linearity error is within its option, and
//! the result does not depend on threads.

mod common;

use common::{any_kinematics, unlimited};
use kerf_kinematics::{linearization_error, solve_path, solve_paths, PathInput, PathOptions, Pose};
use nalgebra::{Point3, Vector3};
use proptest::prelude::*;

/// 25 poses along a random quadratic, the tool axis a random quadratic normalised (it may
/// pass near or through the pole).
fn smooth_path() -> impl Strategy<Value = Vec<Pose>> {
    let v =
        || (-1.0..1.0f64, -1.0..1.0f64, -1.0..1.0f64).prop_map(|(a, b, c)| Vector3::new(a, b, c));
    (v(), v(), v(), v(), v(), v(), 0.5..1.0f64).prop_filter_map(
        "axis vanishes",
        |(p1, p2, n0, n1, n2, p0, up)| {
            let n0 = n0 + Vector3::new(0.0, 0.0, up);
            let poses: Vec<Pose> = (0..25)
                .map(|k| {
                    let t = k as f64 / 24.0;
                    let p = p0 * 100.0 + p1 * 80.0 * t + p2 * 40.0 * t * t;
                    let u = n0 + n1 * t + n2 * 0.5 * t * t;
                    Some(Pose {
                        position: Point3::from(p),
                        axis: u.try_normalize(1e-3)?,
                    })
                })
                .collect::<Option<Vec<_>>>()?;
            Some(poses)
        },
    )
}

/// 25 poses whose tool axis crosses the pole exactly at point `m` (signed tilt `s (k - m)`)
/// while its azimuth turns slowly: the pole in the middle, at an end, or not at all (m > 24).
fn through_pole_path() -> impl Strategy<Value = Vec<Pose>> {
    (
        0usize..30,
        0.5..4.0f64,
        -std::f64::consts::PI..std::f64::consts::PI,
        -0.1..0.1f64,
        -1.0..1.0f64,
        -1.0..1.0f64,
    )
        .prop_map(|(m, s, phi0, w, dx, dy)| {
            (0..25)
                .map(|k| {
                    let theta = (s * (k as f64 - m as f64)).to_radians();
                    let phi = phi0 + w * k as f64;
                    let u = Vector3::new(
                        theta.sin() * phi.cos(),
                        theta.sin() * phi.sin(),
                        theta.cos(),
                    );
                    Pose {
                        position: Point3::new(dx * k as f64, dy * k as f64, 0.1 * k as f64),
                        axis: u,
                    }
                })
                .collect()
        })
}

fn any_path() -> impl Strategy<Value = Vec<Pose>> {
    prop_oneof![smooth_path(), through_pole_path()]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(40))]

    #[test]
    fn solved_paths_are_exact_continuous_and_within_tolerance(
        kin in any_kinematics(),
        poses in any_path(),
        max_step in 2.0..30.0f64,
        tol in 0.005..0.1f64,
    ) {
        let machine = unlimited(kin);
        let options = PathOptions::default().with_max_rotary_step_deg(max_step).with_linearization_tolerance_mm(tol);
        let path = solve_path(&machine, &PathInput { id: "p", poses: &poses, curve: None }, &options)
            .map_err(|e| TestCaseError::fail(e.to_string()))?;
        let kin = machine.kinematics.as_ref();
        prop_assert_eq!(path.poses.len(), path.axes.len(), "one axis vector per pose");
        let cutting: Vec<usize> = path.source.iter().flatten().copied().collect();
        prop_assert_eq!(cutting, (0..poses.len()).collect::<Vec<_>>(), "every cutting point once, in order");
        prop_assert_eq!(path.inserted, path.poses.len() - poses.len(), "inserted count");
        for (n, (pose, q)) in path.poses.iter().zip(&path.axes).enumerate() {
            let back = kin.forward(q);
            prop_assert!((back.position - pose.position).norm() < 1e-9, "point {}: tip", n);
            let angle = back.axis.cross(&pose.axis).norm().atan2(back.axis.dot(&pose.axis));
            prop_assert!(angle <= options.pole_tolerance_deg.to_radians() + 1e-12, "point {}: axis off by {:e}", n, angle);
        }
        for (n, w) in path.axes.windows(2).enumerate() {
            prop_assert!(w[0].rotary_step(&w[1]) <= max_step + 1e-9, "move {}: step {}", n, w[0].rotary_step(&w[1]));
            let dev = linearization_error(kin, &w[0], &w[1]).distance;
            prop_assert!(dev <= tol, "move {}: non-linearity {} > {}", n, dev, tol);
        }
        // Deterministic, and the same through the parallel entry point.
        let again = solve_paths(&machine, &[PathInput { id: "p", poses: &poses, curve: None }; 3], &options)
            .map_err(|e| TestCaseError::fail(e.to_string()))?;
        for other in &again {
            prop_assert_eq!(other, &path, "same result every time");
        }
    }
}
