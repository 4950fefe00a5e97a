//! Shared test inputs: curves discretized by kerf-discretize, tool axes, and an independent
//! finite-difference check of set-points against the machine limits.
#![allow(dead_code, unreachable_pub)]

use kerf_discretize::{discretize, Options};
use kerf_interp::{solve_stations, AxisModel, PaperAcHead, Station};
use kerf_kinematics::Axes;
use kerf_nurbs::NurbsCurve;
use nalgebra::{Point3, Vector3};

/// Full circle of radius `r` about (cx, cy, z) as an exact rational quadratic (9 points).
pub fn circle(r: f64, cx: f64, cy: f64, z: f64) -> NurbsCurve {
    let h = std::f64::consts::FRAC_1_SQRT_2;
    let sq = [
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
    let pts = sq
        .iter()
        .map(|(x, y)| Point3::new(cx + r * x, cy + r * y, z))
        .collect();
    let w = (0..9).map(|i| if i % 2 == 0 { 1.0 } else { h }).collect();
    NurbsCurve::new(
        2,
        vec![0., 0., 0., 0.25, 0.25, 0.5, 0.5, 0.75, 0.75, 1., 1., 1.],
        pts,
        Some(w),
    )
}

/// A 3D free-form cubic (8 control points) wandering over about 200 x 120 x 40 mm.
pub fn freeform() -> NurbsCurve {
    let pts = vec![
        Point3::new(0.0, 0.0, 0.0),
        Point3::new(40.0, 60.0, 10.0),
        Point3::new(80.0, -30.0, 25.0),
        Point3::new(110.0, 40.0, 40.0),
        Point3::new(140.0, 90.0, 20.0),
        Point3::new(170.0, 20.0, 0.0),
        Point3::new(185.0, -20.0, 15.0),
        Point3::new(200.0, 10.0, 30.0),
    ];
    NurbsCurve::new(
        3,
        vec![0., 0., 0., 0., 0.2, 0.4, 0.55, 0.8, 1., 1., 1., 1.],
        pts,
        None,
    )
}

/// Cutting points of `curve` at chord tolerance `tol`: (params, points).
pub fn cut(curve: &NurbsCurve, tol: f64) -> (Vec<f64>, Vec<Point3<f64>>) {
    let d = discretize(curve, &Options::with_tolerance(tol)).expect("discretize");
    d.into_parts()
}

/// Stations of a curve with tool axes from `axis_of(point)`.
pub fn stations(
    m: &PaperAcHead,
    curve: &NurbsCurve,
    tol: f64,
    axis_of: impl Fn(&Point3<f64>) -> Vector3<f64>,
) -> Vec<Station> {
    let (params, points) = cut(curve, tol);
    let axes: Vec<Vector3<f64>> = points.iter().map(&axis_of).collect();
    solve_stations(m, &points, Some(&axes), Some(&params), None).expect("reachable")
}

/// Largest ratio, over every cycle and axis, of the finite-difference velocity and
/// acceleration to the machine's limits (rest before the first and after the last row).
/// Returns (velocity ratio, acceleration ratio, worst cycle of each).
pub fn limit_ratios(m: &dyn AxisModel, rows: &[Axes], t: f64) -> (f64, f64, usize, usize) {
    let lim = m.limits();
    let n = rows.len() as isize;
    let at = |i: isize| rows[i.clamp(0, n - 1) as usize];
    let (mut rv, mut ra, mut iv, mut ia) = (0.0f64, 0.0f64, 0, 0);
    for i in -1..=n {
        for k in 0..5 {
            let v = (at(i)[k] - at(i - 1)[k]) / t;
            let a = (at(i + 1)[k] - 2.0 * at(i)[k] + at(i - 1)[k]) / (t * t);
            if v.abs() / lim.max_velocity[k] > rv {
                rv = v.abs() / lim.max_velocity[k];
                iv = i.max(0) as usize;
            }
            if a.abs() / lim.max_acceleration[k] > ra {
                ra = a.abs() / lim.max_acceleration[k];
                ia = i.max(0) as usize;
            }
        }
    }
    (rv, ra, iv, ia)
}

/// Largest ratio of finite-difference velocity, acceleration and jerk to the limits over every
/// cycle, at rest before the first and after the last row.
pub fn ratios(m: &dyn AxisModel, rows: &[Axes], t: f64) -> [f64; 3] {
    let lim = m.limits();
    let n = rows.len() as isize;
    let at = |i: isize| rows[i.clamp(0, n - 1) as usize];
    let mut r = [0.0f64; 3];
    for i in -2..=n + 2 {
        for k in 0..5 {
            let v = (at(i)[k] - at(i - 1)[k]) / t;
            let a = (at(i + 1)[k] - 2.0 * at(i)[k] + at(i - 1)[k]) / (t * t);
            let j =
                (at(i + 1)[k] - 3.0 * at(i)[k] + 3.0 * at(i - 1)[k] - at(i - 2)[k]) / (t * t * t);
            r[0] = r[0].max(v.abs() / lim.max_velocity[k]);
            r[1] = r[1].max(a.abs() / lim.max_acceleration[k]);
            if let Some(jm) = lim.max_jerk {
                r[2] = r[2].max(j.abs() / jm[k]);
            }
        }
    }
    r
}

/// The large gantry of `fixtures/machines/gantry_ac.json`: 6 m/s^2 on X and Y, 40 m/min.
pub fn gantry() -> PaperAcHead {
    let mut m = PaperAcHead::paper_000();
    m.limits.max_velocity = [40000.0 / 60.0, 40000.0 / 60.0, 20000.0 / 60.0, 600.0, 600.0];
    m.limits.max_acceleration = [6000.0, 6000.0, 5000.0, 20000.0, 20000.0];
    m
}

/// [`gantry`] with its shipped jerk limits (10 ms jerk time: 600 m/s^3 on X and Y).
pub fn gantry_with_jerk() -> PaperAcHead {
    let mut m = gantry();
    m.limits.max_jerk = Some([600_000.0, 600_000.0, 500_000.0, 2_000_000.0, 2_000_000.0]);
    m
}

/// One line block per pose of `stations` (the generic dialect's fit: no arcs, no merged lines).
pub fn one_line_per_pose(m: &dyn AxisModel, stations: &[Station]) -> Vec<kerf_interp::Block> {
    let o = kerf_interp::FitOptions::default()
        .with_arcs(false)
        .with_merge_lines(false);
    kerf_interp::fit_blocks(m, stations, None, 0, &o).expect("one line per pose")
}
