//! The integrator example (`examples/integrator.rs`, also the facade's doc example) checked
//! against independent truth: the exact circle it cuts out, the plate's plane and normal, and the
//! machine's forward kinematics after the pipeline's inverse.

use std::f64::consts::TAU;

use kerf::nalgebra::{Point3, Vector3};

#[allow(dead_code, unreachable_pub)]
#[path = "../examples/integrator.rs"]
mod integrator;

/// The words of a G-code line: `X1.5 A3=0.2` -> [("X", 1.5), ("A3", 0.2)].
fn words(line: &str) -> Vec<(String, f64)> {
    line.split_whitespace()
        .skip(1)
        .filter_map(|w| {
            let (k, v) = match w.split_once('=') {
                Some((k, v)) => (k.to_string(), v),
                None => (w[..1].to_string(), &w[1..]),
            };
            v.parse().ok().map(|v| (k, v))
        })
        .collect()
}

fn get(w: &[(String, f64)], k: &str) -> Option<f64> {
    w.iter().find(|(n, _)| n == k).map(|(_, v)| *v)
}

#[test]
fn the_integrator_program_cuts_the_circle_within_the_tolerance() {
    let out = integrator::cut_disc().expect("the example runs");
    let text = &out.programs[0].text;
    assert!(
        text.contains("TRAORI"),
        "a Sinumerik program with tool-tip control"
    );
    // The plate and the disc as the example builds them, independently: centre, unit normal,
    // radius.
    let (s, c) = 20f64.to_radians().sin_cos();
    let centre = Point3::new(150.0, 100.0, 50.0);
    let normal = Vector3::new(c, 0.0, -s).cross(&Vector3::y());
    let r = 30.0;
    let tol = 0.01;
    let digits = 1e-3; // the program's rounding, generously
    let (beam_on, beam_off) = (&out.report.program.beam_on, &out.report.program.beam_off);
    let radial = |p: &Point3<f64>| {
        let d = p - centre;
        (d - normal * d.dot(&normal)).norm()
    };
    // Cutting points lie on the circle; the overcut's end and fitted arcs within the tolerance.
    let on_circle = |p: &Point3<f64>| (radial(p) - r).abs() <= tol + digits;
    let angle = |p: &Point3<f64>| {
        let d = p - centre;
        d.dot(&Vector3::y()).atan2(d.dot(&Vector3::new(c, 0.0, -s)))
    };
    let turn = |a: &Point3<f64>, b: &Point3<f64>| {
        let t = (angle(b) - angle(a)).rem_euclid(TAU);
        t.min(TAU - t)
    };
    let mut cutting = false;
    let mut last: Option<Point3<f64>> = None;
    let (mut blocks, mut swept) = (0, 0.0);
    for line in text.lines() {
        let line = line.trim();
        if beam_on.iter().any(|c| c == line) {
            cutting = true;
            continue;
        }
        if beam_off.iter().any(|c| c == line) {
            cutting = false;
            continue;
        }
        let head = line.split_whitespace().next().unwrap_or("");
        if !matches!(head, "G0" | "G1" | "CIP") {
            continue;
        }
        let w = words(line);
        let (Some(x), Some(y), Some(z)) = (get(&w, "X"), get(&w, "Y"), get(&w, "Z")) else {
            continue;
        };
        let p = Point3::new(x, y, z);
        if cutting && head != "G0" {
            blocks += 1;
            let axis = Vector3::new(
                get(&w, "A3").expect("A3"),
                get(&w, "B3").expect("B3"),
                get(&w, "C3").expect("C3"),
            );
            assert!(
                (axis.normalize() - normal).norm() < digits,
                "{line}: the tool axis is the plate's normal {normal:?}"
            );
            assert!(
                (p - centre).dot(&normal).abs() < digits,
                "{line}: the tip lies on the plate"
            );
            assert!(
                radial(&p) >= r - tol - digits,
                "{line}: never inside the disc (the lead-ins are on the scrap side, outside)"
            );
            if let Some(a) = last.filter(|a| on_circle(a) && on_circle(&p)) {
                if head == "CIP" {
                    let mid = Point3::new(
                        get(&w, "I1").expect("I1"),
                        get(&w, "J1").expect("J1"),
                        get(&w, "K1").expect("K1"),
                    );
                    assert!(on_circle(&mid), "{line}: the arc is the circle itself");
                    swept += turn(&a, &mid) + turn(&mid, &p);
                } else {
                    let t = turn(&a, &p);
                    let sagitta = r * (1.0 - (t / 2.0).cos());
                    assert!(sagitta <= tol + digits, "{line}: chord error {sagitta} mm");
                    swept += t;
                }
            }
        }
        last = Some(p);
    }
    assert!(blocks > 3, "the program cuts ({blocks} blocks)");
    assert!(
        swept >= TAU - 1e-6,
        "the whole circle is cut on the contour: {swept} rad"
    );
    // The toolpath points lie on the circle; the certified bound holds.
    for p in &out.toolpath.paths {
        assert!(p.max_chord_error <= tol, "certified {}", p.max_chord_error);
        for n in 0..p.points.len() {
            let q = p.points.position(n);
            assert!(
                (radial(&q) - r).abs() < 1e-9,
                "cutting point {n} on the circle"
            );
        }
    }
}

#[test]
fn the_integrator_axes_give_back_the_poses_by_forward_kinematics() {
    let out = integrator::cut_disc().expect("the example runs");
    let machine = kerf::kinematics::Machine::read(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/fixtures/machines/ac_head.json"
    ))
    .expect("machine");
    let mut checked = 0;
    for path in &out.axes.paths {
        let (positions, poses) = path.run();
        for (q, pose) in positions.iter().zip(&poses) {
            let back = machine
                .kinematics
                .forward(&kerf::kinematics::Axes::from_array(*q))
                .to_array();
            for k in 0..3 {
                assert!(
                    (back[k] - pose[k]).abs() < 1e-9,
                    "tip {k}: {back:?} vs {pose:?}"
                );
            }
            for k in 3..6 {
                assert!(
                    (back[k] - pose[k]).abs() < 1e-9,
                    "axis {k}: {back:?} vs {pose:?}"
                );
            }
            assert!(
                machine
                    .violation(&kerf::kinematics::Axes::from_array(*q), 1e-9)
                    .is_none(),
                "within the limits"
            );
            checked += 1;
        }
    }
    assert!(checked > 10, "{checked} poses checked");
}

#[test]
fn a_step_part_runs_through_the_library_in_a_few_lines() {
    // fixtures/step/composite_mm.step: five composite contours on their faces (checked against
    // Open CASCADE by scripts/step_check.py). Through `Job::from_step`: one cut per contour,
    // each on the faces the import named, the file named in the program.
    let step =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures/step/composite_mm.step");
    let out = integrator::cut_step(&step, false).expect("the example runs");
    assert_eq!(out.toolpath.paths.len(), 5);
    assert_eq!(out.report.program.cuts, 5, "{:?}", out.report.program);
    assert!(
        out.programs[0].text.contains("composite_mm.step"),
        "the program names its source"
    );
    // A defect names the file and the entity, through the pipeline's error.
    let bad = std::env::temp_dir().join(format!("kerf-bad-{}.step", std::process::id()));
    std::fs::write(
        &bad,
        "ISO-10303-21;\nHEADER;\nFILE_SCHEMA(('AUTOMOTIVE_DESIGN'));\nENDSEC;\nDATA;\n#1=CIRCLE('',#9,5.);\n#2=GEOMETRIC_CURVE_SET('',(#1));\nENDSEC;\nEND-ISO-10303-21;\n",
    )
    .expect("temp file");
    let e = integrator::cut_step(&bad, false).unwrap_err();
    std::fs::remove_file(&bad).ok();
    assert!(matches!(e, kerf::Error::Step(_)), "{e:?}");
    assert!(e.to_string().contains("#1 CIRCLE"), "{e}");
}
