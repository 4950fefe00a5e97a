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
    assert!(e.to_string().contains("max_total_points"), "{e}");
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

/// Issue 35: options out of their documented range (`kerf_pipeline::ranges`) are refused
/// before any work with [`Error::BadOption`] naming the option, the value and the range. A
/// clearance of 2e4 mm used to fail every traverse's own check, so that every traverse fell
/// back to the unchecked straight rapid with only a warning.
#[test]
fn job_options_out_of_range_are_refused_before_any_work() {
    use kerf_pipeline::JobOptions;
    use kerf_process::{LeadOptions, TraverseOptions};
    let d = JobOptions::default();
    d.validate().expect("the defaults are in range");
    let cases: Vec<(JobOptions, &str, &str)> = vec![
        (
            d.clone()
                .with_traverse(Some(TraverseOptions::default().with_clearance(2e4))),
            "traverse.clearance_mm",
            "option traverse.clearance_mm: must be > 0 mm and <= 1000 mm (got 2e4)",
        ),
        (
            d.clone().with_retract_mm(1e5),
            "retract_mm",
            "option retract_mm: must be between 0 mm and 1000 mm (got 1e5)",
        ),
        (
            d.clone().with_feed_mm_per_min(2e6),
            "feed_mm_per_min",
            "option feed_mm_per_min: must be > 0 mm/min and <= 1e6 mm/min (got 2e6; 16.7 m/s, above any laser cutting machine)",
        ),
        (
            d.clone().with_cycle_s(1e9),
            "cycle_s",
            "option cycle_s: must be between 1e-5 s and 0.1 s (got 1e9; 10 microseconds to 100 milliseconds, the range of real interpolators)",
        ),
        (
            d.clone().with_blend_tolerance_mm(f64::NAN),
            "blend_tolerance_mm",
            "option blend_tolerance_mm: must be > 0 mm and <= 10 mm (got NaN)",
        ),
        (
            d.clone().with_wall_axis_max_mm(1000.0),
            "wall_axis_max_mm",
            "option wall_axis_max_mm: must be between 0 mm and 100 mm (got 1000; a wall through the sheet is as wide as the sheet is thick)",
        ),
        (
            d.clone().with_tolerance_mm(1e300),
            "tolerance_mm",
            "option tolerance_mm: must be > 0 mm and <= 10 mm (got 1e300)",
        ),
        (
            d.clone()
                .with_leads(LeadOptions::default().with_lead_in(2.0, 2000.0)),
            "leads.lead_in_radius_mm",
            "option leads.lead_in_radius_mm: must be between 0 mm and 1000 mm (got 2000)",
        ),
    ];
    for (options, name, message) in cases {
        let e = options.validate().expect_err(name);
        assert!(
            matches!(&e, Error::BadOption { name: n, .. } if *n == name),
            "{name}: {e:?}"
        );
        assert_eq!(e.to_string(), message, "{name}");
        // Job::run refuses them before the first stage, whatever the curves.
        let job = Job::on_machine(machine())
            .with_curve(
                "c",
                kerf_nurbs::NurbsCurve::circle(Point3::origin(), Vector3::z(), 50.0)
                    .expect("circle"),
                None,
            )
            .with_options(options);
        let e = job.run().expect_err(name);
        assert_eq!(e.to_string(), message, "{name}: through run");
    }
    // A stage's own check is run up front too: a retract below 1.25 times the clearance.
    let e = d
        .clone()
        .with_retract_mm(0.0)
        .with_traverse(Some(TraverseOptions::default().with_retract_mm(1.0)))
        .validate()
        .expect_err("retract below the clearance");
    assert!(
        matches!(&e, Error::Process { .. }) && e.to_string().contains("retract_mm"),
        "{e}"
    );
    // An infinite linearization tolerance (insert no points) and no segment limit stay allowed.
    let mut open = d.clone();
    open.path.linearization_tolerance_mm = f64::INFINITY;
    open.discretize.max_segment_length_mm = f64::INFINITY;
    open.validate().expect("no limits");
}

/// The motion stage alone checks its options the same way ([`MotionOptions::validate`]).
#[test]
fn motion_options_out_of_range_are_refused() {
    use kerf_pipeline::{plan_program, MotionInput, MotionOptions};
    let d = MotionOptions::default();
    d.validate().expect("the defaults are in range");
    for (options, name) in [
        (d.with_feed_mm_per_min(2e6), "feed_mm_per_min"),
        (d.with_cycle_s(0.0), "cycle_s"),
        (d.with_fit_tolerance_mm(Some(100.0)), "fit_tolerance_mm"),
        (d.with_chord_tolerance_mm(Some(-1.0)), "chord_tolerance_mm"),
        (d.with_retract_mm(1e5), "retract_mm"),
        (d.with_blend_tolerance_mm(1e300), "blend_tolerance_mm"),
    ] {
        let e = options.validate().expect_err(name);
        assert!(
            matches!(&e, Error::BadOption { name: n, .. } if *n == name),
            "{name}: {e:?}"
        );
        let input = MotionInput::read(fixture("bad/io/axes_bom.json")).expect("axes");
        let e = plan_program(&machine(), &input, &options, None).expect_err(name);
        assert!(
            e.to_string().starts_with(&format!("option {name}: ")),
            "{e}"
        );
    }
}

/// A curve built in code is held to the reader's rule: a curve whose control points all lie
/// at one place is a point, refused by index and id before any work
/// (`kerf_format::curves::is_a_point`), not cut as a slit of its lead-in and lead-out.
#[test]
fn a_point_curve_built_in_code_is_refused_by_name() {
    use kerf_nurbs::NurbsCurve;
    let p = Point3::new(5.0, 5.0, 0.0);
    let dot = NurbsCurve::try_new(1, vec![0.0, 0.0, 1.0, 1.0], vec![p, p], None).expect("valid");
    let circle = NurbsCurve::circle(Point3::origin(), Vector3::z(), 50.0).expect("circle");
    let job = Job::on_machine(machine())
        .with_curve("outline", circle, None)
        .with_curve("dot", dot, None)
        .with_source("part.json");
    let e = job.run().expect_err("a point");
    assert!(matches!(&e, Error::Invalid { .. }), "{e:?}");
    assert_eq!(
        e.to_string(),
        r#"part.json: curves[1] ("dot"): all control points coincide: a point, not a contour"#,
        "message"
    );
    // A tiny real circle is a contour: validation passes (planning it is another issue's).
    let tiny = NurbsCurve::circle(Point3::origin(), Vector3::z(), 1e-8).expect("circle");
    Job::on_machine(machine())
        .with_curve("tiny", tiny, None)
        .validate()
        .expect("a circle of radius 1e-8 mm is a contour");
}
