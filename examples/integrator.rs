//! A CAM integrator's program: a contour and its surface built in code, discretized at
//! 0.01 mm, oriented, solved on a shipped machine, Sinumerik G-code in memory; and a STEP part
//! from CAD through the same library, placed on the machine automatically.
//! Run: `cargo run --release --example integrator > disc.mpf`, or with a STEP file as the
//! argument (`-- PART.step`) for that part's first program.

use std::f64::consts::TAU;

use kerf::nalgebra::{Point3, Vector3};
use kerf::nurbs::{NurbsCurve, NurbsSurface};
use kerf::{interp::Dialect, kinematics::Machine, Job, JobOptions, Output, PlaceMode};

/// A disc of radius 30 mm cut out of a plate tilted 20 degrees about y, on the paper-000
/// head (one closed contour is an outline: its lead-in starts outside, in the scrap).
pub fn cut_disc() -> Result<Output, kerf::Error> {
    let (s, c) = 20f64.to_radians().sin_cos();
    let centre = Point3::new(150.0, 100.0, 50.0);
    let (u, v) = (Vector3::new(c, 0.0, -s), Vector3::y()); // the plate's axes
    let corner = centre - (u + v) * 60.0;
    let plate = NurbsSurface::plane(corner, u, v, 120.0, 120.0)?;
    let disc = NurbsCurve::arc(centre, u, v, 30.0, 0.0, TAU)?; // the exact circle
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/fixtures/machines");
    let machine = Machine::read(format!("{dir}/ac_head.json"))?;
    let options = JobOptions::default()
        .with_tolerance_mm(0.01)
        .with_dialect(Dialect::Sinumerik);
    let job = Job::on_machine(machine).with_surface("plate", plate, false);
    job.with_curve("disc", disc, Some("plate"))
        .with_options(options)
        .run()
}

/// A STEP part's contours (the curves of its geometric sets; `edges` for a solid without them:
/// a sheet-metal part's through-features, each once) on the shipped gantry, placed where the
/// machine reaches every cut.
pub fn cut_step(step: &std::path::Path, edges: bool) -> Result<Output, kerf::Error> {
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/fixtures/machines");
    let machine = Machine::read(format!("{dir}/gantry_ac.json"))?;
    let mut import = kerf::step::ImportOptions::default();
    if edges {
        import = import.with_edges(None);
    }
    let (job, _account) = Job::from_step(step, machine, &import)?;
    job.with_options(JobOptions::default().with_place(PlaceMode::Auto))
        .run()
}

fn main() -> Result<(), kerf::Error> {
    let out = match std::env::args_os().nth(1) {
        Some(step) => cut_step(std::path::Path::new(&step), true)?,
        None => cut_disc()?,
    };
    print!("{}", out.programs[0].text);
    Ok(())
}
