//! The pipeline's [`kerf_pipeline::Error`] keeps every stage's error as its source: the chain
//! of [`std::error::Error::source`] reaches the kinematics' own error and the operating
//! system's [`std::io::Error`], not only their messages.

use kerf_interp::{solve_stations, MachineModel};
use kerf_kinematics::KinematicsError;
use kerf_pipeline::{Error, Job};
use nalgebra::{Point3, Vector3};

mod common;
use common::{fixture, machine};

/// Every error in the chain of `e`, itself first.
fn chain(e: &Error) -> Vec<&(dyn std::error::Error + 'static)> {
    let mut out: Vec<&(dyn std::error::Error + 'static)> = vec![e];
    while let Some(next) = out[out.len() - 1].source() {
        out.push(next);
    }
    out
}

#[test]
fn an_unreachable_pose_keeps_the_kinematics_error_as_source() {
    let model = MachineModel::new(machine()).expect("model");
    // A tool axis pointing down: no tilt of the A axis reaches it.
    let tips = [Point3::origin(), Point3::new(1.0, 0.0, 0.0)];
    let axes = [Vector3::z(), -Vector3::z()];
    let interp = solve_stations(&model, &tips, Some(&axes), None, None).expect_err("unreachable");
    let e = Error::Interp {
        file: None,
        source: interp,
    };
    let kin = chain(&e)
        .into_iter()
        .find_map(|s| s.downcast_ref::<KinematicsError>());
    assert!(
        matches!(kin, Some(KinematicsError::Unreachable { .. })),
        "the chain reaches the kinematics' error: {e:?}"
    );
    assert!(e.to_string().contains("point 1: kinematics:"), "{e}");
}

#[test]
fn a_missing_machine_file_keeps_the_io_error() {
    let dir = tempfile::tempdir().expect("tempdir");
    let missing = dir.path().join("no_machine.json");
    let e = Job::from_files(fixture("door_trim.json"), &missing).expect_err("missing");
    let links = chain(&e);
    assert!(
        links
            .iter()
            .any(|s| s.downcast_ref::<KinematicsError>().is_some()),
        "{e:?}"
    );
    let io = links
        .iter()
        .find_map(|s| s.downcast_ref::<std::io::Error>())
        .map(std::io::Error::kind);
    assert_eq!(io, Some(std::io::ErrorKind::NotFound), "{e:?}");
}

#[test]
fn a_missing_curves_file_keeps_the_io_error() {
    let dir = tempfile::tempdir().expect("tempdir");
    let e = Job::from_files(
        dir.path().join("none.json"),
        fixture("machines/ac_head.json"),
    )
    .expect_err("missing");
    let io = chain(&e)
        .into_iter()
        .find_map(|s| s.downcast_ref::<std::io::Error>())
        .map(std::io::Error::kind);
    assert_eq!(io, Some(std::io::ErrorKind::NotFound), "{e:?}");
}
