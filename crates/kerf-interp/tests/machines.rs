//! kerf's machines through `MachineModel`: every kinematic type of `kerf.machine/1`, paths solved
//! by kerf-kinematics, planned within the limits.

use kerf_interp::{
    fit_blocks, plan, stations_from_axes, stations_from_solved, AxisModel, FitOptions,
    MachineModel, PaperAcHead, PlanOptions,
};
use kerf_kinematics::{solve_path, Axes, Machine, PathInput, PathOptions, Pose};
use nalgebra::{Point3, Vector3};

fn load(name: &str) -> MachineModel {
    let path = format!(
        "{}/../../fixtures/machines/{name}.json",
        env!("CARGO_MANIFEST_DIR")
    );
    MachineModel::new(Machine::read(path).expect("machine file")).expect("limits")
}

#[test]
fn ac_head_file_agrees_with_the_reference_head() {
    let m = load("ac_head");
    let r = PaperAcHead::paper_000();
    for (t, c) in [(0.0, 0.0), (30.0, 40.0), (-20.0, 200.0), (100.0, -75.0)] {
        let tip = Point3::new(12.0, -34.0, 56.0);
        let (a, b) = (m.linear_axes(&tip, t, c), r.linear_axes(&tip, t, c));
        for k in 0..3 {
            assert!((a[k] - b[k]).abs() < 1e-9, "({t}, {c}): {a:?} vs {b:?}");
        }
        assert!(
            (m.tool_axis(t, c) - r.tool_axis(t, c)).norm() < 1e-12,
            "tool axis"
        );
        let u = r.tool_axis(t, c);
        let q = m
            .inverse(&tip, &u, Some(&Axes::new(0.0, 0.0, 0.0, t, c)))
            .expect("reachable");
        assert!((q[3] - t).abs() < 1e-9 && (q[4] - c).abs() < 1e-9, "{q:?}");
    }
    assert_eq!(m.limits().max_velocity, r.limits.max_velocity, "per second");
}

#[test]
fn every_machine_type_plans_within_its_limits() {
    for (name, x0) in [
        ("ac_head", 0.0),
        ("fork_head", 0.0),
        ("head_table", 600.0),
        ("table_table", 0.0),
    ] {
        let m = load(name);
        let poses: Vec<Pose> = (0..=200)
            .map(|i| {
                let a = i as f64 / 200.0 * std::f64::consts::PI;
                let u = Vector3::new(0.3 * a.cos(), 0.2 * a.sin(), 1.0).normalize();
                Pose {
                    position: Point3::new(x0 + 40.0 * a.cos(), 40.0 * a.sin(), 5.0),
                    axis: u,
                }
            })
            .collect();
        let input = PathInput {
            id: "half-ring",
            poses: &poses,
            curve: None,
        };
        let solved = solve_path(&m.machine, &input, &PathOptions::default()).expect("solved");
        let params: Vec<f64> = (0..=200).map(|i| i as f64).collect();
        let st = stations_from_solved(&solved, Some(&params)).expect("stations");
        assert_eq!(
            st.len(),
            solved.axes.len(),
            "{name}: one station per solved point"
        );
        for s in &st {
            let xyz = m.linear_axes(&s.tip, s.axes[3], s.axes[4]);
            for k in 0..3 {
                assert!(
                    (xyz[k] - s.axes[k]).abs() < 1e-9,
                    "{name}: {xyz:?} vs {:?}",
                    s.axes
                );
            }
        }
        let blocks = fit_blocks(&m, &st, None, 0, &FitOptions::with_tolerance(0.005)).expect("fit");
        let motion = plan(&m, &blocks, &PlanOptions::new(6000.0, 0.001)).expect("plan");
        let rows = motion.setpoints(&m);
        let (lim, t) = (m.limits(), 0.001);
        for i in 1..rows.len() - 1 {
            for k in 0..5 {
                let v = (rows[i][k] - rows[i - 1][k]) / t;
                let a = (rows[i + 1][k] - 2.0 * rows[i][k] + rows[i - 1][k]) / (t * t);
                assert!(
                    v.abs() <= lim.max_velocity[k],
                    "{name}: cycle {i} axis {k} velocity {v}"
                );
                assert!(
                    a.abs() <= lim.max_acceleration[k],
                    "{name}: cycle {i} axis {k} acceleration {a}"
                );
            }
        }
        assert_eq!(
            rows[rows.len() - 1],
            st[st.len() - 1].axes,
            "{name}: ends on the last point"
        );
        // The same path through kerf.axes/1's arrays.
        let positions = solved.positions();
        let raw: Vec<[f64; 6]> = solved.poses.iter().map(Pose::to_array).collect();
        let again = stations_from_axes(&positions, &raw).expect("axes file stations");
        assert_eq!(again.len(), st.len(), "{name}: same stations");
        assert!(
            stations_from_axes(&positions[1..], &raw).is_err(),
            "length mismatch"
        );
    }
}

/// A rapid is planned as the machine runs a `G0`: straight in the joints. On a table-table
/// machine at A = 90 degrees a rapid between two points 5 mm apart on the part that turns C
/// by 200 degrees swings the part's point about the C axis: planned along the tip's straight
/// line, the linear axes followed that swing (Z went more than 470 mm below both ends and left the
/// machine's travel on a real sheet-metal part); planned in the joints, every set-point of the
/// rapid lies on the straight line between its ends.
#[test]
fn a_rapid_is_planned_straight_in_the_joints() {
    let m = load("table_table");
    let station = |tip: Point3<f64>, a: f64, c: f64| {
        let xyz = m.linear_axes(&tip, a, c);
        let q = [xyz[0], xyz[1], xyz[2], a, c];
        let u = m.tool_axis(a, c);
        (q, [tip.x, tip.y, tip.z, u.x, u.y, u.z])
    };
    let path = |tips: [Point3<f64>; 2], c: f64| {
        let (q0, p0) = station(tips[0], 90.0, c);
        let (q1, p1) = station(tips[1], 90.0, c);
        let st = stations_from_axes(&[q0, q1], &[p0, p1]).expect("stations");
        kerf_interp::link_paths(vec![
            fit_blocks(&m, &st, None, 0, &FitOptions::default()).expect("fit")
        ])
    };
    let first = path(
        [Point3::new(150.0, 0.0, 0.0), Point3::new(150.0, 10.0, 0.0)],
        0.0,
    );
    let mut second = path(
        [Point3::new(150.0, 15.0, 0.0), Point3::new(150.0, 25.0, 0.0)],
        200.0,
    );
    for b in &mut second {
        b.path = 1;
    }
    let blocks = kerf_interp::link_paths(vec![first, second]);
    let r = blocks.iter().position(|b| b.rapid).expect("a rapid");
    let (q0, q1) = (blocks[r].start_axes, blocks[r].end_axes);
    assert!((q1[4] - q0[4]).abs() > 150.0, "C turns: {q0:?} -> {q1:?}");
    let motion = plan(&m, &blocks, &PlanOptions::new(6000.0, 0.001)).expect("plan");
    let rows = motion.setpoints(&m);
    let mut seen = 0;
    for (i, q) in rows.iter().enumerate() {
        let (b, _) = motion.locate(i as f64 * motion.cycle());
        if b != r {
            continue;
        }
        seen += 1;
        // Where on the line (by the largest travel), and how far each axis is from it.
        let k = (0..5)
            .max_by(|&a, &b| (q1[a] - q0[a]).abs().total_cmp(&(q1[b] - q0[b]).abs()))
            .unwrap();
        let f = (q[k] - q0[k]) / (q1[k] - q0[k]);
        assert!((-1e-6..=1.0 + 1e-6).contains(&f), "cycle {i}: {f}");
        for j in 0..5 {
            let on_line = q0[j] + f * (q1[j] - q0[j]);
            assert!(
                (q[j] - on_line).abs() < 1e-6,
                "cycle {i} axis {j}: {} off the joint line ({q:?}, {q0:?} -> {q1:?})",
                q[j] - on_line
            );
        }
    }
    assert!(seen > 10, "the rapid's set-points were checked ({seen})");
}
