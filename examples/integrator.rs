//! A CAM integrator's program: a contour and its surface built in code, discretized at
//! 0.01 mm, oriented, solved on a shipped machine, Sinumerik G-code in memory.
//! Run: `cargo run --release --example integrator > disc.mpf`.

use std::f64::consts::{FRAC_1_SQRT_2, FRAC_PI_4, SQRT_2};

use kerf::nalgebra::{Point3, Vector3};
use kerf::nurbs::{NurbsCurve, NurbsSurface};
use kerf::{interp::Dialect, kinematics::Machine, Job, JobOptions, Output};

/// A disc of radius 30 mm cut out of a plate tilted 20 degrees about y, on the paper-000
/// head (one closed contour is an outline: its lead-in starts outside, in the scrap).
pub fn cut_disc() -> Result<Output, kerf::Error> {
    let (s, c) = 20f64.to_radians().sin_cos();
    let at = |u: f64, v: f64| {
        Point3::new(150.0, 100.0, 50.0) + Vector3::new(c, 0.0, -s) * u + Vector3::y() * v
    };
    let k1 = || vec![0., 0., 1., 1.];
    let corners = [-60., 60.].map(|u| vec![at(u, -60.), at(u, 60.)]).to_vec();
    let plate = NurbsSurface::try_new(1, 1, k1(), k1(), corners, None)?;
    // The exact circle: rational quadratic, poles on a square (weight 1/sqrt 2 at its corners).
    let odd = |i: usize| i % 2 == 1;
    let radius = |i: usize| if odd(i) { 30.0 * SQRT_2 } else { 30.0 };
    let polar = (0..9).map(|i| (FRAC_PI_4 * i as f64, radius(i)));
    let poles = polar.map(|(a, r)| at(r * a.cos(), r * a.sin())).collect();
    let weights = (0..9)
        .map(|i| if odd(i) { FRAC_1_SQRT_2 } else { 1.0 })
        .collect();
    let knots = vec![0., 0., 0., 0.25, 0.25, 0.5, 0.5, 0.75, 0.75, 1., 1., 1.];
    let disc = NurbsCurve::try_new(2, knots, poles, Some(weights))?;
    let machine = Machine::read(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/fixtures/machines/ac_head.json"
    ))?;
    let options = JobOptions::default()
        .with_tolerance_mm(0.01)
        .with_dialect(Dialect::Sinumerik);
    let job = Job::on_machine(machine).with_surface("plate", plate, false);
    job.with_curve("disc", disc, Some("plate"))
        .with_options(options)
        .run()
}

fn main() -> Result<(), kerf::Error> {
    print!("{}", cut_disc()?.programs[0].text);
    Ok(())
}
