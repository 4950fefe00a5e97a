//! Shared helpers and proptest strategies of the kinematics tests.
#![allow(dead_code, unreachable_pub)]

use std::f64::consts::PI;
use std::sync::Arc;

use kerf_kinematics::{
    AcHead, ForkHead, ForkTilt, HeadTable, Kinematics, Machine, Pose, Range, TableTable,
};
use nalgebra::Vector3;
use proptest::prelude::*;

/// `fixtures/machines/<name>`.
pub fn fixture(name: &str) -> Machine {
    let path = format!(
        "{}/../../fixtures/machines/{name}",
        env!("CARGO_MANIFEST_DIR")
    );
    Machine::read(&path).unwrap_or_else(|e| panic!("{path}: {e}"))
}

/// A machine with no limits at all.
pub fn unlimited(kinematics: Arc<dyn Kinematics>) -> Machine {
    with_limits(kinematics, [None; 5])
}

/// A machine with the given limits.
pub fn with_limits(kinematics: Arc<dyn Kinematics>, limits: [Option<Range>; 5]) -> Machine {
    Machine::try_new("test", kinematics, limits, [1000.0; 5], [1000.0; 5]).expect("valid machine")
}

/// The unit vector at polar angle `theta` from +z and azimuth `phi` (radians).
pub fn polar(theta: f64, phi: f64) -> Vector3<f64> {
    Vector3::new(
        theta.sin() * phi.cos(),
        theta.sin() * phi.sin(),
        theta.cos(),
    )
}

/// One of the four types with random parameters.
pub fn any_kinematics() -> impl Strategy<Value = Arc<dyn Kinematics>> {
    let len = 0.0..500.0f64;
    let off = -500.0..500.0f64;
    let v3 = || {
        (-500.0..500.0f64, -500.0..500.0f64, -500.0..500.0f64)
            .prop_map(|(a, b, c)| Vector3::new(a, b, c))
    };
    prop_oneof![
        (len.clone(), len.clone())
            .prop_map(|(a, c)| Arc::new(AcHead::try_new(a, c).unwrap()) as Arc<dyn Kinematics>),
        (any::<bool>(), len.clone(), v3(), off.clone(), off.clone()).prop_map(
            |(b, l, d, tx, ty)| {
                let tilt = if b { ForkTilt::B } else { ForkTilt::A };
                Arc::new(ForkHead::try_new(tilt, l, d, [tx, ty]).unwrap()) as Arc<dyn Kinematics>
            }
        ),
        (v3(), off.clone(), off.clone(), off.clone(), any::<bool>()).prop_map(
            |(q, y, z, t, conv)| {
                Arc::new(TableTable::try_new(q, y, z, t, conv).unwrap()) as Arc<dyn Kinematics>
            }
        ),
        (len, v3(), any::<bool>(), any::<bool>()).prop_map(|(l, c, b, s)| {
            let sign = |x: bool| if x { 1.0 } else { -1.0 };
            Arc::new(HeadTable::try_new(l, c, sign(b), sign(s)).unwrap()) as Arc<dyn Kinematics>
        }),
    ]
}

/// A unit tool axis: random, or at the special tilts 0, 90 and 180 degrees, or 1e-9 rad from
/// either pole.
pub fn any_axis() -> impl Strategy<Value = Vector3<f64>> {
    let theta = prop_oneof![
        4 => 0.0..PI,
        1 => Just(0.0),
        1 => Just(PI / 2.0),
        1 => Just(PI),
        1 => Just(1e-9),
        1 => Just(PI - 1e-9),
        1 => 1e-12..1e-6f64,
    ];
    (theta, -PI..PI).prop_map(|(t, p)| polar(t, p))
}

/// A pose with a random tip in a 2 m cube and [`any_axis`].
pub fn any_pose() -> impl Strategy<Value = Pose> {
    (
        -1000.0..1000.0f64,
        -1000.0..1000.0f64,
        -1000.0..1000.0f64,
        any_axis(),
    )
        .prop_map(|(x, y, z, u)| Pose {
            position: nalgebra::Point3::new(x, y, z),
            axis: u,
        })
}
