//! The directions of the part that may point up, and which of them the machine's tilt axis
//! serves for each path: what the set-up search and the candidate solves share.

use nalgebra::{Point3, Rotation3, Vector3};

use super::tilt_reachable_within;
use crate::machine::Machine;
use crate::pose::Pose;

/// The directions of the part that may be turned to point up: a Fibonacci lattice of 2,048
/// unit vectors, evenly spread over the sphere (neighbours about 4.5 degrees apart).
pub(super) fn up_directions() -> Vec<Vector3<f64>> {
    const DIRECTIONS: usize = 2048;
    let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    (0..DIRECTIONS)
        .map(|i| {
            let z = 1.0 - 2.0 * (i as f64 + 0.5) / DIRECTIONS as f64;
            let r = (1.0 - z * z).max(0.0).sqrt();
            Vector3::new(
                r * (golden * i as f64).cos(),
                r * (golden * i as f64).sin(),
                z,
            )
        })
        .collect()
}

/// The rotation that turns direction `d` of the part to +z (a half turn about x for -z).
pub(super) fn turn_up(d: &Vector3<f64>) -> Rotation3<f64> {
    Rotation3::rotation_between(d, &Vector3::z())
        .unwrap_or_else(|| Rotation3::from_axis_angle(&Vector3::x_axis(), std::f64::consts::PI))
}

/// For each path and each lattice direction: can the tilt axis reach every tool axis of the
/// path (on one side of the sheet, or the other with `flip`) once that direction points up?
/// Checked on up to 256 poses per path, 1 degree inside the limits so that the tool axes
/// between the samples are covered too (the final solve checks them all).
pub(super) fn reachable_directions(
    machine: &Machine,
    paths: &[Vec<Pose>],
    flip: bool,
    lattice: &[Vector3<f64>],
) -> Vec<Vec<bool>> {
    const PER_PATH: usize = 256;
    const INSET_DEG: f64 = 1.0;
    let turns: Vec<Rotation3<f64>> = lattice.iter().map(turn_up).collect();
    paths
        .iter()
        .map(|p| {
            let step = p.len().div_ceil(PER_PATH).max(1);
            let axes: Vec<Vector3<f64>> = p.iter().step_by(step).map(|q| q.axis).collect();
            turns
                .iter()
                .map(|up| {
                    let side = |sign: f64| {
                        axes.iter().all(|a| {
                            let pose = Pose {
                                position: Point3::origin(),
                                axis: up * (a * sign),
                            };
                            tilt_reachable_within(machine, &pose, INSET_DEG).is_ok()
                        })
                    };
                    side(1.0) || (flip && side(-1.0))
                })
                .collect()
        })
        .collect()
}
