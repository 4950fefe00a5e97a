//! Property tests: forward(inverse(pose)) = pose for every type and both solutions, and
//! inverse(forward(axes)) contains the axes.

mod common;

use common::{any_kinematics, any_pose};
use kerf_kinematics::Axes;
use proptest::prelude::*;

proptest! {
    #![proptest_config(ProptestConfig::with_cases(2048))]

    #[test]
    fn forward_undoes_inverse_for_both_solutions(kin in any_kinematics(), pose in any_pose()) {
        let sols = kin.inverse(&pose);
        for (n, q) in sols.iter().enumerate() {
            let back = kin.forward(q);
            let dp = (back.position - pose.position).norm();
            let du = (back.axis - pose.axis).norm();
            prop_assert!(dp <= 1e-9, "{} solution {n}: tip off by {dp:e} ({q:?})", kin.type_name());
            prop_assert!(du <= 1e-9, "{} solution {n}: axis off by {du:e} ({q:?})", kin.type_name());
        }
        // The two solutions are (t, C) and (-t, C + 180).
        prop_assert!((sols[1].tilt + sols[0].tilt).abs() <= 1e-12, "tilt negated");
        prop_assert!((sols[1].c - sols[0].c - 180.0).abs() <= 1e-12, "C + 180");
    }

    #[test]
    fn inverse_with_c_places_the_tip_and_is_exact_for_the_right_c(kin in any_kinematics(), pose in any_pose(), c in -720.0..720.0f64) {
        let q = kin.inverse_with_c(&pose, c);
        prop_assert_eq!(q.c, c, "C is kept");
        let back = kin.forward(&q);
        prop_assert!((back.position - pose.position).norm() <= 1e-9, "tip exact");
        // With the C of an exact solution, the tool axis is exact too.
        let exact = kin.inverse(&pose)[0];
        let q = kin.inverse_with_c(&pose, exact.c);
        prop_assert!((kin.forward(&q).axis - pose.axis).norm() <= 1e-9, "axis exact for the solution's C");
    }

    #[test]
    fn inverse_recovers_the_axes(
        kin in any_kinematics(),
        xyz in (-1000.0..1000.0f64, -1000.0..1000.0f64, -1000.0..1000.0f64),
        tilt in prop_oneof![-179.0..-0.01f64, 0.01..179.0f64],
        c in -720.0..720.0f64,
    ) {
        let axes = Axes::new(xyz.0, xyz.1, xyz.2, tilt, c);
        let pose = kin.forward(&axes);
        let found = kin.inverse(&pose).iter().any(|q| {
            let dc = (q.c - c) / 360.0;
            (q.tilt - tilt).abs() < 1e-7
                && (dc - dc.round()).abs() * 360.0 < 1e-7
                && (q.xyz() - axes.xyz()).norm() < 1e-9
        });
        prop_assert!(found, "{}: {axes:?} not among {:?}", kin.type_name(), kin.inverse(&pose));
    }
}
