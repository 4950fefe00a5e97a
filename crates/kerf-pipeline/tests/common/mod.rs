//! Helpers shared by the pipeline's tests: the fixtures and the shipped AC-head machine.

#![allow(dead_code)] // each test file uses its own subset

use std::path::{Path, PathBuf};

use kerf_kinematics::Machine;
use kerf_nurbs::NurbsCurve;
use kerf_pipeline::Output;
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

/// Every set-point of every program within the machine's ranges, velocities and
/// accelerations, read back from the CSV text.
pub(crate) fn assert_setpoints_within_limits(
    what: &str,
    machine: &Machine,
    out: &Output,
    cycle: f64,
) {
    for setup in 0..out.programs.len() {
        let rows = setpoint_rows(out, setup);
        assert!(rows.len() > 10, "{what}: a real program");
        for (i, r) in rows.iter().enumerate() {
            for k in 0..5 {
                if let Some(range) = machine.limits[k] {
                    assert!(
                        r[k] >= range.min - 1e-9 && r[k] <= range.max + 1e-9,
                        "{what}: cycle {i} axis {k} = {} outside [{}, {}]",
                        r[k],
                        range.min,
                        range.max
                    );
                }
                if i > 0 {
                    let v = (r[k] - rows[i - 1][k]) / cycle;
                    let vmax = machine.max_velocity[k] / 60.0;
                    assert!(
                        v.abs() <= vmax * (1.0 + 1e-9) + 1e-9,
                        "{what}: cycle {i} axis {k} velocity {v} > {vmax}"
                    );
                }
                if i > 0 && i + 1 < rows.len() {
                    let a = (rows[i + 1][k] - 2.0 * r[k] + rows[i - 1][k]) / (cycle * cycle);
                    let amax = machine.max_acceleration[k];
                    assert!(
                        a.abs() <= amax * (1.0 + 1e-6),
                        "{what}: cycle {i} axis {k} acceleration {a} > {amax}"
                    );
                }
            }
        }
    }
}

/// The set-points of set-up `setup` as the CSV writes them: `[X, Y, Z, tilt, C]` per cycle,
/// read back from the text.
pub(crate) fn setpoint_rows(out: &Output, setup: usize) -> Vec<[f64; 5]> {
    let mut text = Vec::new();
    out.write_setpoints(setup, &mut text).expect("csv");
    String::from_utf8(text)
        .expect("utf-8")
        .lines()
        .skip(1)
        .map(|l| {
            let v: Vec<f64> = l.split(',').map(|x| x.parse().expect("number")).collect();
            [v[1], v[2], v[3], v[4], v[5]]
        })
        .collect()
}
