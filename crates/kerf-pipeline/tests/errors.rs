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

/// The review's 600-byte circle at `-t 1e-8`: 594,000 cutting points went through every stage
/// (55 s, 1.9 GB). A job has a limit on its total cutting points: a curve the discretizer
/// estimates above what is left is refused before its points are made, and curves that
/// together pass the limit stop the job with the total they reached.
#[test]
fn a_job_above_its_point_limit_is_refused_before_the_points_are_made() {
    use kerf_discretize::Options;
    use kerf_nurbs::NurbsCurve;
    let circle = |r: f64| NurbsCurve::circle(Point3::origin(), Vector3::z(), r).expect("circle");
    // One circle of radius 700 at 1e-9 mm: about 1.85 million points, estimated.
    let job = Job::on_machine(machine())
        .with_curve("big", circle(700.0), None)
        .with_options(
            kerf_pipeline::JobOptions::default()
                .with_tolerance_mm(1e-9)
                .with_max_total_points(1000),
        );
    let e = job.run().expect_err("above the limit");
    match &e {
        Error::TooManyPoints {
            limit, reached, id, ..
        } => {
            assert_eq!((*limit, id.as_str()), (1000, "big"), "{e}");
            assert!(*reached > 1.8e6, "the discretizer's estimate: {e}");
        }
        other => panic!("not TooManyPoints: {other:?}"),
    }
    assert!(e.to_string().contains("--max-total-points"), "{e}");
    // Forty circles of 50 mm at 0.01 mm: 157 points each, 6,280 in all. Each fits, together
    // they do not.
    let mut file = kerf_pipeline::Job::on_machine(machine());
    for k in 0..40 {
        file = file.with_curve(format!("c{k}"), circle(50.0), None);
    }
    let curves = file.curves();
    let opts = Options::with_tolerance(0.01);
    let all = kerf_pipeline::discretize_curves_within(curves, &opts, 10_000, None, &|_| {})
        .expect("within the limit");
    let total: usize = all.iter().map(|d| d.points().len()).sum();
    assert!(total > 5_000 && total < 10_000, "{total} points");
    let e = kerf_pipeline::discretize_curves_within(curves, &opts, total - 1, None, &|_| {})
        .expect_err("one point short");
    assert!(
        matches!(e, Error::TooManyPoints { limit, .. } if limit == total - 1),
        "{e:?}"
    );
    let exact = kerf_pipeline::discretize_curves_within(curves, &opts, total, None, &|_| {});
    assert!(exact.is_ok(), "exactly the limit fits: {exact:?}");
}

#[test]
fn a_tolerance_a_later_curve_cannot_hold_is_refused_before_any_curve_is_walked() {
    // door_trim's third curve cannot be certified at 1e-10 mm (its rounding margin is about
    // 8.5e-11): the job used to walk the first two for about 110 s of CPU before refusing it.
    // Now no curve is discretized: the progress never counts one done.
    let curves = kerf_format::curves::load(fixture("door_trim.json")).expect("fixture");
    let done = std::sync::atomic::AtomicUsize::new(0);
    let opts = kerf_discretize::Options::with_tolerance(1e-10);
    let e = kerf_pipeline::discretize_curves(&curves, &opts, None, &|p| {
        done.fetch_max(p.done, std::sync::atomic::Ordering::Relaxed);
    })
    .expect_err("below the margin");
    assert!(
        matches!(
            &e,
            Error::Discretize {
                index: 2,
                source: kerf_discretize::DiscretizeError::ToleranceBelowMargin { .. },
                ..
            }
        ),
        "{e:?}"
    );
    assert_eq!(done.into_inner(), 0, "no curve walked");
}
