//! Values derived by hand in `docs/kinematics.md`, one section per type, checked both ways.

mod common;

use std::sync::Arc;

use common::{fixture, unlimited};
use kerf_kinematics::{Axes, ForkHead, ForkTilt, Kinematics, Pose};
use nalgebra::Vector3;

const H: f64 = 0.866_025_403_784_438_6; // cos 30 = sqrt(3)/2

/// forward(axes) = pose, and `axes` is solution `which` of inverse(pose).
fn check(kin: &dyn Kinematics, axes: [f64; 5], pose: [f64; 6], which: usize) {
    let q = Axes::from_array(axes);
    let p = kin.forward(&q).to_array();
    for k in 0..6 {
        assert!(
            (p[k] - pose[k]).abs() < 1e-12,
            "{}: forward {axes:?} = {p:?}, want {pose:?}",
            kin.type_name()
        );
    }
    let sol = kin.inverse(&Pose::from_array(pose))[which].to_array();
    for k in 0..5 {
        assert!(
            (sol[k] - axes[k]).abs() < 1e-12,
            "{}: inverse[{which}] of {pose:?} = {sol:?}, want {axes:?}",
            kin.type_name()
        );
    }
}

#[test]
fn ac_head_paper_000() {
    let m = fixture("ac_head.json");
    let kin = m.kinematics.as_ref();
    // A 30, C 90: u = (sin30 sin90, -sin30 cos90, cos30) = (0.5, 0, 0.866);
    // XYZ = P + 180 u - 95 (cos 90, sin 90, 0) = (100 + 90, 50 - 95, 20 + 155.885).
    check(
        kin,
        [190.0, -45.0, 20.0 + 180.0 * H, 30.0, 90.0],
        [100.0, 50.0, 20.0, 0.5, 0.0, H],
        0,
    );
    // The other solution (-30, 270) turns the r_c offset to (0, -95, 0): Y = 50 + 95.
    check(
        kin,
        [190.0, 145.0, 20.0 + 180.0 * H, -30.0, 270.0],
        [100.0, 50.0, 20.0, 0.5, 0.0, H],
        1,
    );
    // A 90, C 0: the tool axis is -y; XYZ = 0 + 180 (0, -1, 0) - 95 (1, 0, 0).
    check(
        kin,
        [-95.0, -180.0, 0.0, 90.0, 0.0],
        [0.0, 0.0, 0.0, 0.0, -1.0, 0.0],
        0,
    );
    // The pole with C kept at 0: XYZ = P + (0, 0, 180) - (95, 0, 0).
    let q = kin.inverse_with_c(&Pose::new(10.0, 20.0, 30.0, 0.0, 0.0, 1.0), 0.0);
    assert_eq!(q.to_array(), [-85.0, 20.0, 210.0, 0.0, 0.0], "pole");
}

#[test]
fn fork_head_fixture() {
    let m = fixture("fork_head.json");
    let kin = m.kinematics.as_ref();
    assert_eq!(kin.tilt_name(), "B", "tilt");
    // B 90, C 90: u = Rz(90) (1, 0, 0) = (0, 1, 0); Ry(90) (0, 0, -210) = (-210, 0, 0);
    // d + that = (-210, 35, -120); Rz(90) of it = (-35, -210, -120); XYZ = P - that.
    check(
        kin,
        [35.0, 210.0, 120.0, 90.0, 90.0],
        [0.0, 0.0, 0.0, 0.0, 1.0, 0.0],
        0,
    );
    // B 0, C 0 (at the pole, so only forward): XYZ = P - (d + (0, 0, -210)).
    let p = kin.forward(&Axes::new(1.0, -33.0, 333.0, 0.0, 0.0));
    assert!(
        (p.position.coords - Vector3::new(1.0, 2.0, 3.0)).norm() < 1e-12,
        "{p:?}"
    );
}

#[test]
fn fork_head_lateral_offset() {
    // Tilt A, L 100, no d, nozzle 5 mm off in x: A 90, C 0 gives Rx(90) (5, 0, -100) =
    // (5, 100, 0) from XYZ to the tip and u = Rx(90) ez = (0, -1, 0).
    let kin = ForkHead::try_new(ForkTilt::A, 100.0, Vector3::zeros(), [5.0, 0.0]).unwrap();
    check(
        &kin,
        [-5.0, -100.0, 0.0, 90.0, 0.0],
        [0.0, 0.0, 0.0, 0.0, -1.0, 0.0],
        0,
    );
    assert_eq!(kin.pivot_length(), 100.0, "lateral x is along the A axis");
    let m = unlimited(Arc::new(kin));
    assert_eq!(m.axis_names(), ["X", "Y", "Z", "A", "C"], "names");
}

#[test]
fn table_table_fixture() {
    let m = fixture("table_table.json");
    let kin = m.kinematics.as_ref();
    // conventional: s = -1, so P = Rz(C) [q_a + Rx(A) (T - q_a)], q_a = (0, 0, 80),
    // u = Rz(C) Rx(A) ez.
    // A 90, C 0, XYZ (10, 20, 30): T - q_a = (10, 20, -50); Rx(90) of it = (10, 50, 20);
    // + q_a = (10, 50, 100); u = (0, -1, 0).
    check(
        kin,
        [10.0, 20.0, 30.0, 90.0, 0.0],
        [10.0, 50.0, 100.0, 0.0, -1.0, 0.0],
        0,
    );
    // Same with C 90: Rz(90) (10, 50, 100) = (-50, 10, 100), u = Rz(90) (0, -1, 0) = (1, 0, 0).
    check(
        kin,
        [10.0, 20.0, 30.0, 90.0, 90.0],
        [-50.0, 10.0, 100.0, 1.0, 0.0, 0.0],
        0,
    );
    // A 30, C 90 with the tip on the A axis: P = q_a, u = (0.5, 0, 0.866); both solutions
    // share X, Y, Z since the tip lies on both rotary axes.
    check(
        kin,
        [0.0, 0.0, 80.0, 30.0, 90.0],
        [0.0, 0.0, 80.0, 0.5, 0.0, H],
        0,
    );
    check(
        kin,
        [0.0, 0.0, 80.0, -30.0, 270.0],
        [0.0, 0.0, 80.0, 0.5, 0.0, H],
        1,
    );
}

#[test]
fn table_table_directions() {
    // Not conventional: s = +1, u = Rz(-C) Rx(-A) ez: A 90, C 0 tilts the tool axis to +y.
    let kin = kerf_kinematics::TableTable::try_new(Vector3::zeros(), 0.0, 0.0, 0.0, false).unwrap();
    let u = kin.forward(&Axes::new(0.0, 0.0, 0.0, 90.0, 0.0)).axis;
    assert!((u - Vector3::new(0.0, 1.0, 0.0)).norm() < 1e-15, "{u}");
}

#[test]
fn head_table_fixture() {
    let m = fixture("head_table.json");
    let kin = m.kinematics.as_ref();
    // b_sign 1, c_sign -1, c_point (600, 0, 0), L 180. B 90, C 90, XYZ (700, 0, 50):
    // tip = XYZ + Ry(90) (0, 0, -180) = (520, 0, 50); Rz(-90) (tip - c_point) =
    // Rz(-90) (-80, 0, 50) = (0, 80, 50); P = (600, 80, 50); u = Rz(-90) (1, 0, 0) = (0, -1, 0).
    check(
        kin,
        [700.0, 0.0, 50.0, 90.0, 90.0],
        [600.0, 80.0, 50.0, 0.0, -1.0, 0.0],
        0,
    );
    // B 0, C 123: the tool is vertical and the tip is 180 below XYZ; the table turns it about
    // c_point, so a tip on c_point stays put.
    let p = kin.forward(&Axes::new(600.0, 0.0, 180.0, 0.0, 123.0));
    assert!(
        (p.position.coords - Vector3::new(600.0, 0.0, 0.0)).norm() < 1e-12,
        "{p:?}"
    );
}

#[test]
fn pivot_lengths() {
    assert_eq!(
        fixture("ac_head.json").kinematics.pivot_length(),
        180.0,
        "r_a"
    );
    assert_eq!(
        fixture("fork_head.json").kinematics.pivot_length(),
        210.0,
        "L"
    );
    assert_eq!(
        fixture("table_table.json").kinematics.pivot_length(),
        80.0,
        "z_offset"
    );
    assert_eq!(
        fixture("head_table.json").kinematics.pivot_length(),
        180.0,
        "L"
    );
}
