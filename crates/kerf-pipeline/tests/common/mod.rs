//! Helpers shared by the pipeline's tests: the fixtures and the shipped AC-head machine.

#![allow(dead_code)] // each test file uses its own subset

use std::path::{Path, PathBuf};

use kerf_kinematics::Machine;
use kerf_nurbs::NurbsCurve;
use nalgebra::Point3;

/// A file under `fixtures/`.
pub(crate) fn fixture(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../fixtures")
        .join(name)
}

/// `fixtures/machines/ac_head.json`.
pub(crate) fn machine() -> Machine {
    Machine::read(fixture("machines/ac_head.json")).expect("machine")
}

/// A circle of radius `r` about `(cx, cy, 0)`: the exact rational quadratic, nine control
/// points.
pub(crate) fn circle(cx: f64, cy: f64, r: f64) -> NurbsCurve {
    let w = 0.5f64.sqrt();
    let corners = [
        (1., 0.),
        (1., 1.),
        (0., 1.),
        (-1., 1.),
        (-1., 0.),
        (-1., -1.),
        (0., -1.),
        (1., -1.),
        (1., 0.),
    ];
    NurbsCurve::try_new(
        2,
        vec![0., 0., 0., 0.25, 0.25, 0.5, 0.5, 0.75, 0.75, 1., 1., 1.],
        corners
            .iter()
            .map(|(a, b)| Point3::new(cx + r * a, cy + r * b, 0.0))
            .collect(),
        Some(vec![1., w, 1., w, 1., w, 1., w, 1.]),
    )
    .expect("a circle")
}
