//! Measures a LinuxCNC simulator run of a `kerf run` output directory (the check in
//! `tests/linuxcnc/`): the tool tip of every servo cycle through kerf's forward kinematics,
//! its deviation from the cut, the beam output against the cuts, the axes' limits, velocities
//! and accelerations, and the time against kerf's plan. Prints one JSON object.
//!
//! ```sh
//! cargo run --release -p kerf-cli --example lcnc_measure -- MACHINE.json KERF_OUT_DIR SAMPLES.txt [PERIOD_S [CUTS]]
//! ```
//!
//! `SAMPLES.txt` is `halsampler -t` output: the sample number, the five joint positions (the
//! machine file's axis order) and the beam bit, one servo cycle per line. `KERF_OUT_DIR` holds
//! `axes.json`, `toolpath.json` and `report.json` of the same `kerf run`. With `CUTS` the
//! program ran only its first `CUTS` cuts (a long real part cut short for CI): only those paths
//! are measured, and kerf's time is theirs (the report's per-path durations).
//!
//! The tip is measured three ways while the beam is on: against the poses (the program's own
//! path, lead-ins and the pierce descent included), against the cutting points (placed with
//! the set-up's placement from the report), and against the designed NURBS curve itself (the
//! `kerf.curves/1` file the report names as its input; global closest point in part
//! coordinates), wherever the curve is nearer than the leads and the pierce descent: the last
//! is the end-to-end figure the tolerance budget is a claim about.
//!
//! With `KERF_COMPARE_DIR` (the output of the same job compensated in the computer,
//! `--kerf-width`) and `KERF_COMPARE_OFFSET_MM` (half the kerf), a program that leaves the
//! kerf to the controller (`--kerf-in-control`) is measured against kerf's own offset: the
//! beam-on samples at the offset distance from the designed curve, against the other run's
//! cut of the same contour (`kerf_compare`).
//!
//! With `KERF_HEAD_CHECK=1` the machine's head model (the machine file's `head`, standing at
//! its `process.standoff_mm`) is swept along every executed sample from the first beam-on to
//! the last beam-off, the traverses between included (a sample
//! kept where the tip has moved 0.25 mm or the tool axis turned 0.05 degrees since the last),
//! its surface sampled every 0.5 mm of height and 5 degrees (the flat ends of its solids every
//! millimetre of radius), above the tip zone the report states, and the least distance of
//! those points from the input's surfaces measured exactly: each must be a flat rectangle (a
//! degree 1 x 1 patch of 2 x 2 control points, as the head fixtures are), whose distance is
//! closed-form (`head_clearance`): independent of kerf's head check, its cells and its closest
//! points. The tip zone is left out on every sample (kerf checks a traverse's travel with the
//! whole head), and the figure is the least over the samples: the motion between two servo
//! cycles (up to 0.67 mm of the tip on a 40 m/min rapid) is not added. One set-up only.

use std::path::Path;

use kerf_kinematics::{Axes, AxesFile, Machine};
use kerf_nurbs::{distance_to_segment as seg_dist, nearest_on_segment};
use nalgebra::{Point3, Vector3};
use serde_json::{json, Value};

fn fail(msg: String) -> ! {
    eprintln!("lcnc_measure: {msg}");
    std::process::exit(1)
}

/// One cut: the tips of its poses (axes file), its cutting points (toolpath) and the tool axis
/// at its start.
type Cut = (Vec<Point3<f64>>, Vec<Point3<f64>>, Vector3<f64>);

/// What the beam-on samples of one cut are measured against besides its poses: the designed
/// curve (part coordinates) with the set-up's placement `p' = R p + t`, and the lead polylines
/// (workpiece frame), where the beam is off the curve by design.
struct Design {
    curve: Option<kerf_nurbs::NurbsCurve>,
    rot: nalgebra::Rotation3<f64>,
    shift: Vector3<f64>,
    leads: Vec<Vec<Point3<f64>>>,
}

/// Distance from `p` to the polyline `pts`, over all its segments (exact, no search window).
fn poly_dist(p: &Point3<f64>, pts: &[Point3<f64>]) -> f64 {
    if pts.len() == 1 {
        return (p - pts[0]).norm();
    }
    pts.windows(2)
        .map(|w| seg_dist(p, &w[0], &w[1]))
        .fold(f64::INFINITY, f64::min)
}

/// The segment `pts[j] pts[j + 1]` nearest `p` and the fraction along it of the nearest point.
fn nearest_segment(p: &Point3<f64>, pts: &[Point3<f64>]) -> (usize, f64) {
    let mut best = (0, 0.0, f64::INFINITY);
    for (j, w) in pts.windows(2).enumerate() {
        let (dist, f) = nearest_on_segment(p, &w[0], &w[1]);
        if dist < best.2 {
            best = (j, f, dist);
        }
    }
    (best.0, best.1)
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.len() < 3 {
        fail("usage: lcnc_measure MACHINE.json KERF_OUT_DIR SAMPLES.txt [PERIOD_S]".into());
    }
    let machine = Machine::read(&args[0]).unwrap_or_else(|e| fail(e.to_string()));
    let dir = Path::new(&args[1]);
    let period: f64 = args.get(3).map_or(0.001, |s| s.parse().unwrap_or(0.001));
    // Measure only the first CUTS paths (a program cut short after its CUTS-th cut).
    let only: Option<usize> = args.get(4).map(|s| {
        s.parse()
            .unwrap_or_else(|_| fail(format!("CUTS: not a count: {s}")))
    });
    let read = |name: &str| {
        std::fs::read_to_string(dir.join(name))
            .unwrap_or_else(|e| fail(format!("{}: {e}", dir.join(name).display())))
    };
    let mut axes = AxesFile::from_str(&read("axes.json")).unwrap_or_else(|e| fail(e.to_string()));
    if let Some(k) = only {
        axes.paths.truncate(k);
    }
    let tp = kerf_format::toolpath::from_str(&read("toolpath.json"))
        .unwrap_or_else(|e| fail(e.to_string()));
    let report: Value =
        serde_json::from_str(&read("report.json")).unwrap_or_else(|e| fail(e.to_string()));
    // The designed curves, from the input `kerf run` read (its path as the report gives it);
    // a STEP input or a moved file leaves the curve measure out.
    let curves = report["input"]
        .as_str()
        .and_then(|f| kerf_format::curves::load(f).ok());
    let budget = report["tolerance_budget_mm"]["total"]
        .as_f64()
        .unwrap_or(f64::NAN);
    let duration = match only {
        None => report["interpolation"]["duration_s"]
            .as_f64()
            .unwrap_or(f64::NAN),
        // Each path's duration includes the rapids that lead to it; the first path's lead-in
        // rapid from the program start is outside the beam-on span measured.
        Some(k) => report["interpolation"]["paths"]
            .as_array()
            .map_or(f64::NAN, |p| {
                p.iter()
                    .take(k)
                    .map(|q| q["duration_s"].as_f64().unwrap_or(f64::NAN))
                    .sum()
            }),
    };
    let feed = report["interpolation"]["feed_mm_per_min"]
        .as_f64()
        .unwrap_or(f64::NAN);
    let dwell = report["program"]["pierce_dwell_s"].as_f64().unwrap_or(0.0);
    let standoff = report["program"]["pierce_standoff_mm"]
        .as_f64()
        .unwrap_or(0.0);

    // Samples.
    let text =
        std::fs::read_to_string(&args[2]).unwrap_or_else(|e| fail(format!("{}: {e}", args[2])));
    let mut q: Vec<[f64; 5]> = Vec::new();
    let mut beam: Vec<bool> = Vec::new();
    // The laser power output (HAL's speed-following power, percent), when sampled.
    let mut power: Vec<f64> = Vec::new();
    let mut gaps = 0usize;
    let mut last_n: Option<i64> = None;
    for (i, line) in text.lines().enumerate() {
        let v: Vec<&str> = line.split_whitespace().collect();
        if v.len() != 7 && v.len() != 8 {
            fail(format!(
                "{}:{}: expected 7 or 8 columns, found {}",
                args[2],
                i + 1,
                v.len()
            ));
        }
        let n: i64 = v[0]
            .parse()
            .unwrap_or_else(|_| fail(format!("line {}: sample number", i + 1)));
        if last_n.is_some_and(|l| n != l + 1) {
            gaps += 1;
        }
        last_n = Some(n);
        let mut a = [0.0; 5];
        for k in 0..5 {
            a[k] = v[k + 1]
                .parse()
                .unwrap_or_else(|_| fail(format!("line {}: number", i + 1)));
        }
        q.push(a);
        beam.push(v[6] != "0");
        if let Some(p) = v.get(7) {
            power.push(
                p.parse()
                    .unwrap_or_else(|_| fail(format!("line {}: power", i + 1))),
            );
        }
    }
    let tips: Vec<(Point3<f64>, Vector3<f64>)> = q
        .iter()
        .map(|a| {
            let p = machine.kinematics.forward(&Axes::from_array(*a));
            (p.position, p.axis)
        })
        .collect();

    // Beam intervals [first on, last on].
    let mut intervals: Vec<(usize, usize)> = Vec::new();
    for i in 0..beam.len() {
        if beam[i] && (i == 0 || !beam[i - 1]) {
            intervals.push((i, i));
        }
        if beam[i] {
            if let Some(l) = intervals.last_mut() {
                l.1 = i;
            }
        }
    }
    // Micro-joints: each cut's beam is off over its joints, so a cut with n joints is n + 1
    // intervals; each switch is measured against the joint's planned end, then the cut's
    // intervals are merged into one for the framing below.
    let (intervals, joints_fig) = group_joints(intervals, &report, &axes, &tips);
    // The toolpath is in part coordinates; the axes, the program and so the samples in the
    // workpiece frame of the path's set-up: `p' = R p + t` with `R = Rz Ry Rx` of the report's
    // `rotation_deg` (x, y, z) and `t` its `translation_mm` (none without a placement).
    let placement_of = |id: &str| -> (nalgebra::Rotation3<f64>, Vector3<f64>) {
        let setups = report["placement"]["setups"].as_array();
        let setup = setups.and_then(|s| {
            s.iter().find(|s| {
                s["paths"]
                    .as_array()
                    .is_some_and(|p| p.iter().any(|v| v.as_str() == Some(id)))
            })
        });
        let Some(setup) = setup else {
            return (nalgebra::Rotation3::identity(), Vector3::zeros());
        };
        let v3 = |key: &str| {
            let a = setup[key]
                .as_array()
                .unwrap_or_else(|| fail(format!("placement {key}")));
            let x = |k: usize| a.get(k).and_then(Value::as_f64).unwrap_or(0.0);
            Vector3::new(x(0), x(1), x(2))
        };
        let r = v3("rotation_deg").map(f64::to_radians);
        let rot = nalgebra::Rotation3::from_axis_angle(&Vector3::z_axis(), r.z)
            * nalgebra::Rotation3::from_axis_angle(&Vector3::y_axis(), r.y)
            * nalgebra::Rotation3::from_axis_angle(&Vector3::x_axis(), r.x);
        (rot, v3("translation_mm"))
    };
    // Paths run in cutting order (not the toolpath's): each with its lead-in, the cut from its
    // start point and its lead-out, against the lead polylines and the cutting points in the
    // same order.
    let designs: Vec<Design> = axes
        .paths
        .iter()
        .map(|a| {
            let (rot, shift) = placement_of(&a.id);
            let tip = |p: &[f64; 6]| Point3::new(p[0], p[1], p[2]);
            // Each lead as a polyline joined to the cut: the lead-in ends where the cut's first
            // pose begins, the lead-out starts at its last.
            let mut leads = Vec::new();
            if let (Some(m), Some(first)) = (&a.lead_in, a.poses.first()) {
                leads.push(m.poses.iter().chain([first]).map(tip).collect());
            }
            if let (Some(m), Some(last)) = (&a.lead_out, a.poses.last()) {
                leads.push([last].into_iter().chain(&m.poses).map(tip).collect());
            }
            let curve = curves.as_ref().and_then(|c| {
                c.curves
                    .iter()
                    .find(|c| c.id == a.id)
                    .map(|c| c.curve.clone())
            });
            Design {
                curve,
                rot,
                shift,
                leads,
            }
        })
        .collect();
    let cuts: Vec<Cut> =
        axes.paths
            .iter()
            .map(|a| {
                let t =
                    tp.paths.iter().find(|t| t.id == a.id).unwrap_or_else(|| {
                        fail(format!("path {:?} is not in toolpath.json", a.id))
                    });
                let (_, run) = a.run();
                let tip = |p: &[f64; 6]| Point3::new(p[0], p[1], p[2]);
                let poses: Vec<Point3<f64>> = run.iter().map(tip).collect();
                let n = t.points.len();
                let sp = a.start_point.unwrap_or(0).min(n.saturating_sub(1));
                let order: Vec<usize> = if sp > 0 {
                    (sp..n).chain(1..=sp).collect()
                } else {
                    (0..n).collect()
                };
                let mut pts: Vec<Point3<f64>> = Vec::new();
                if let Some(m) = &a.lead_in {
                    pts.extend(m.poses.iter().map(tip));
                }
                let (rot, shift) = placement_of(&a.id);
                pts.extend(order.iter().map(|&k| rot * t.points.position(k) + shift));
                if let Some(m) = &a.lead_out {
                    pts.extend(m.poses.iter().map(tip));
                }
                let u = Vector3::new(run[0][3], run[0][4], run[0][5]).normalize();
                (poses, pts, u)
            })
            .collect();

    let mut per_cut = Vec::new();
    let mut max_dev_union: f64 = 0.0;
    let mut max_dev_points: f64 = 0.0;
    let mut max_dev_orient_deg: f64 = 0.0;
    let mut max_dev_curve: Option<f64> = None;
    let mut framing_ok = intervals.len() == cuts.len();
    for (k, (iv, (poses, pts, u0))) in intervals.iter().zip(&cuts).enumerate() {
        let design = &designs[k];
        let start = poses[0];
        let end = *poses.last().unwrap_or(&start);
        let pierce = start + u0 * standoff;
        // The beam switches on where the head has come to rest at the pierce point and off
        // where it rests at the cut's end: in the last cycle before and the first cycle after
        // the switch the head is within 10 um of the point (LinuxCNC reports a move done
        // during its last creep of a few um, under 10 mm/s).
        let on_at = (tips[iv.0].0 - pierce).norm();
        let before = if iv.0 > 0 {
            (tips[iv.0 - 1].0 - pierce).norm()
        } else {
            f64::INFINITY
        };
        let off_at = (tips[iv.1].0 - end).norm();
        let after = tips
            .get(iv.1 + 1)
            .map_or(f64::INFINITY, |t| (t.0 - end).norm());
        // Every beam-on sample against the pierce segment and the cut together (where the beam
        // may be: the controller may round the corner between the descent and the cut); the
        // samples nearer the cut than the pierce segment also against the cutting points and
        // for the tool axis.
        let (_, run) = axes.paths[k].run();
        let mut dev_union: f64 = 0.0;
        let mut dev_points: f64 = 0.0;
        let mut dev_orient: f64 = 0.0;
        let mut dev_curve: Option<f64> = None;
        for (p, u) in tips.iter().take(iv.1 + 1).skip(iv.0) {
            let d_cut = poly_dist(p, poses);
            let d_pierce = seg_dist(p, &start, &pierce);
            dev_union = dev_union.max(d_cut.min(d_pierce));
            dev_points = dev_points.max(poly_dist(p, pts).min(d_pierce));
            // The tip against the designed curve itself (global closest point, in part
            // coordinates), where the curve is nearer than the pierce segment and the leads:
            // the end-to-end figure the budget bounds.
            if let Some(c) = &design.curve {
                let local = Point3::from(design.rot.inverse() * (p - Point3::from(design.shift)));
                let d = c.closest_point(&local).distance;
                let d_lead = design
                    .leads
                    .iter()
                    .map(|l| poly_dist(p, l))
                    .fold(d_pierce, f64::min);
                if d <= d_lead {
                    dev_curve = Some(dev_curve.map_or(d, |m| m.max(d)));
                }
            }
            if d_pierce < d_cut {
                continue;
            }
            // Tool axis against the poses' axes interpolated at the nearest point of the
            // nearest segment, degrees.
            let (j, f) = nearest_segment(p, poses);
            let ax = |n: usize| {
                let pj = &run[n.min(run.len() - 1)];
                Vector3::new(pj[3], pj[4], pj[5]).normalize()
            };
            let uj = (ax(j) * (1.0 - f) + ax(j + 1) * f).normalize();
            dev_orient = dev_orient.max(u.dot(&uj).clamp(-1.0, 1.0).acos().to_degrees());
        }
        max_dev_union = max_dev_union.max(dev_union);
        // The pierce: the beam on while the head stands at the pierce point for the dwell.
        let dwell_on = tips[iv.0..=iv.1]
            .iter()
            .take_while(|(p, _)| (p - pierce).norm() < 1e-2)
            .count() as f64
            * period;
        let ok = on_at < 1e-2
            && before < 1e-2
            && off_at < 1e-2
            && after < 1e-2
            // Two cycles of sampling and two of the HAL's beam delay (tests/linuxcnc's
            // make_config.py: the enable follows the joints, two servo periods behind the
            // trajectory that switches the output).
            && dwell_on >= dwell - 4.0 * period;
        framing_ok &= ok;
        max_dev_points = max_dev_points.max(dev_points);
        if let Some(d) = dev_curve {
            max_dev_curve = Some(max_dev_curve.map_or(d, |m| m.max(d)));
        }
        max_dev_orient_deg = max_dev_orient_deg.max(dev_orient);
        per_cut.push(json!({
            "id": axes.paths[k].id,
            "beam_on_sample": iv.0,
            "beam_off_sample": iv.1 + 1,
            "beam_on_distance_from_pierce_point_mm": on_at,
            "distance_from_pierce_point_before_beam_on_mm": before,
            "beam_off_distance_from_cut_end_mm": off_at,
            "distance_from_cut_end_after_beam_off_mm": after,
            "max_deviation_beam_on_mm": dev_union,
            "max_deviation_from_cutting_points_mm": dev_points,
            "max_deviation_from_curve_mm": dev_curve,
            "max_tool_axis_deviation_deg": dev_orient,
            "beam_on_at_pierce_point_s": dwell_on,
            "framing_ok": ok,
        }));
    }

    // The controller's kerf compensation against kerf's own (`KERF_COMPARE_DIR`: the output of
    // the same run compensated in the computer, `KERF_COMPARE_OFFSET_MM` half the kerf): every
    // beam-on sample within 0.02 mm of the offset distance from the designed curve (the
    // compensated contour, not the leads: nearer the curve than the leads by 5 um) against that
    // run's cut of the same contour.
    let compare = std::env::var("KERF_COMPARE_DIR").ok().map(|other| {
        let r: f64 = std::env::var("KERF_COMPARE_OFFSET_MM")
            .ok()
            .and_then(|v| v.parse().ok())
            .unwrap_or_else(|| fail("KERF_COMPARE_OFFSET_MM: half the kerf, mm".into()));
        let text = std::fs::read_to_string(Path::new(&other).join("axes.json"))
            .unwrap_or_else(|e| fail(format!("{other}/axes.json: {e}")));
        let theirs = AxesFile::from_str(&text).unwrap_or_else(|e| fail(e.to_string()));
        let (mut on, mut measured, mut worst) = (0usize, 0usize, 0.0_f64);
        let mut worst_at = (String::new(), Point3::origin(), 0.0);
        for (k, iv) in intervals.iter().enumerate().take(cuts.len()) {
            let id = &axes.paths[k].id;
            let Some(path) = theirs.paths.iter().find(|p| &p.id == id) else {
                fail(format!("{other}: no path {id:?}"))
            };
            let poly: Vec<Point3<f64>> = path
                .poses
                .iter()
                .map(|p| Point3::new(p[0], p[1], p[2]))
                .collect();
            let design = &designs[k];
            let Some(c) = &design.curve else { continue };
            for (p, _) in tips.iter().take(iv.1 + 1).skip(iv.0) {
                on += 1;
                let local = Point3::from(design.rot.inverse() * (p - Point3::from(design.shift)));
                let dc = c.closest_point(&local).distance;
                // Clearly nearer the contour than its (uncompensated) leads: the lead-in and
                // the overcut run half a kerf off the leads, and join the contour tangentially.
                let d_lead = design
                    .leads
                    .iter()
                    .map(|l| poly_dist(p, l))
                    .fold(f64::INFINITY, f64::min);
                if (dc - r).abs() <= 0.02 && dc <= d_lead - 0.005 {
                    measured += 1;
                    let d = poly_dist(p, &poly);
                    if d > worst {
                        worst = d;
                        worst_at = (id.clone(), *p, dc);
                    }
                }
            }
        }
        json!({
            "beam_on_samples": on,
            "samples_on_the_offset": measured,
            "max_distance_to_computer_offset_mm": worst,
            "worst": { "id": worst_at.0, "at": [worst_at.1.x, worst_at.1.y, worst_at.1.z], "distance_from_curve_mm": worst_at.2 },
        })
    });

    // Limits, velocities and accelerations (second differences of the commanded positions),
    // separately while the beam is off (rapids) and on (cuts).
    let names = machine.axis_names();
    let mut limit_violations = 0usize;
    for a in &q {
        if machine.violation(&Axes::from_array(*a), 1e-6).is_some() {
            limit_violations += 1;
        }
    }
    let mut vel_ratio = [0.0f64; 5];
    let mut acc_ratio_rapid = [0.0f64; 5];
    let mut acc_ratio_cut = [0.0f64; 5];
    for i in 1..q.len() {
        for k in 0..5 {
            let v = (q[i][k] - q[i - 1][k]) / period * 60.0;
            vel_ratio[k] = vel_ratio[k].max(v.abs() / machine.max_velocity[k]);
        }
    }
    for i in 1..q.len().saturating_sub(1) {
        for k in 0..5 {
            let a = (q[i + 1][k] - 2.0 * q[i][k] + q[i - 1][k]) / (period * period);
            let r = a.abs() / machine.max_acceleration[k];
            if beam[i] {
                acc_ratio_cut[k] = acc_ratio_cut[k].max(r);
            } else {
                acc_ratio_rapid[k] = acc_ratio_rapid[k].max(r);
            }
        }
    }
    // The tip's speed while the beam is on (first differences), mm/min: kerf's plan never
    // exceeds the programmed feed.
    let max_tip_speed = (1..tips.len())
        .filter(|&i| beam[i] && beam[i - 1])
        .map(|i| (tips[i].0 - tips[i - 1].0).norm() / period * 60.0)
        .fold(0.0, f64::max);
    let power_fig = measure_power(&report, &axes, &intervals, &tips, &beam, &power, period);
    let by_axis = |r: &[f64; 5]| -> Value {
        let m: serde_json::Map<String, Value> = names
            .iter()
            .zip(r)
            .map(|(n, v)| (n.to_string(), json!(v)))
            .collect();
        Value::Object(m)
    };

    // Time: from the first beam on to the last beam off, against kerf's plan plus the pierce
    // dwell and the descent of each cut.
    let (t_lcnc, predicted) = match (intervals.first(), intervals.last()) {
        (Some(a), Some(b)) => {
            let n = intervals.len() as f64;
            let descent = if standoff > 0.0 {
                standoff / (feed / 60.0)
            } else {
                0.0
            };
            (
                (b.1 + 1 - a.0) as f64 * period,
                duration + n * (dwell + descent),
            )
        }
        _ => (0.0, duration),
    };
    let out = json!({
        "samples": q.len(),
        "sample_gaps": gaps,
        "period_s": period,
        "cuts": cuts.len(),
        "beam_intervals": intervals.len(),
        // The beam output in the last sample, recorded 0.3 s after the program ended.
        "beam_on_at_end": beam.last().copied().unwrap_or(false),
        "framing_ok": framing_ok,
        "tolerance_budget_mm": budget,
        "max_deviation_beam_on_mm": max_dev_union,
        "max_deviation_from_cutting_points_mm": max_dev_points,
        "max_deviation_from_curve_mm": max_dev_curve,
        "max_tool_axis_deviation_deg": max_dev_orient_deg,
        "limit_violations": limit_violations,
        "max_tip_speed_beam_on_mm_per_min": max_tip_speed,
        "feed_mm_per_min": feed,
        "max_velocity_ratio": by_axis(&vel_ratio),
        "max_acceleration_ratio_rapids": by_axis(&acc_ratio_rapid),
        "max_acceleration_ratio_cuts": by_axis(&acc_ratio_cut),
        "linuxcnc_time_s": t_lcnc,
        "kerf_predicted_s": predicted,
        "kerf_motion_duration_s": duration,
        "time_ratio": t_lcnc / predicted,
        "per_cut": per_cut,
        "kerf_compare": compare,
        "power": power_fig,
        "micro_joints": joints_fig,
        "head_clearance": std::env::var("KERF_HEAD_CHECK").is_ok_and(|v| v == "1").then(|| {
            let design = curves.as_ref().unwrap_or_else(|| fail("KERF_HEAD_CHECK: the input curves file is not readable".into()));
            // One set-up: the samples mapped back to part coordinates with its placement.
            if report["placement"]["setups"].as_array().is_some_and(|s| s.len() > 1) {
                fail("KERF_HEAD_CHECK: the program holds one set-up's placement only".into());
            }
            let first = axes.paths.first().map(|a| a.id.clone()).unwrap_or_default();
            head_clearance(&machine, &report, design, &tips, &beam, placement_of(&first))
        }),
    });
    println!("{}", serde_json::to_string_pretty(&out).unwrap_or_default());
}

/// The laser power against the tip's speed while the beam cuts (issue 29): with a technology
/// in the report and the power sampled, every beam-on sample whose power lies strictly between
/// the floor and 100 % is compared with the rule `power = factor P_cut v / v_ref`, `v` the tip
/// speed from the same two samples the controller's `ddt` differentiated. Samples within
/// `POWER_SETTLE` cycles of a beam switch are left out (the beam's own edge); the samples of
/// the pierce (beam on, head still) give the range of the pierce power. `null` without a
/// technology or a power column.
fn measure_power(
    report: &Value,
    axes: &AxesFile,
    intervals: &[(usize, usize)],
    tips: &[(Point3<f64>, Vector3<f64>)],
    beam: &[bool],
    power: &[f64],
    period: f64,
) -> Value {
    const POWER_SETTLE: usize = 2;
    let t = &report["technology"];
    let (Some(p_cut), Some(v_ref), Some(floor)) = (
        t["power_percent"].as_f64(),
        t["feed_mm_per_min"].as_f64(),
        t["power_min_percent"].as_f64(),
    ) else {
        return Value::Null;
    };
    if power.len() != beam.len() {
        return Value::Null;
    }
    let small: Vec<&str> = t["small_holes"]
        .as_array()
        .map_or(Vec::new(), |a| a.iter().filter_map(Value::as_str).collect());
    let factor = t["small_hole"]["power_factor"].as_f64().unwrap_or(1.0);
    let feed_factor = t["small_hole"]["feed_factor"].as_f64().unwrap_or(1.0);
    let descent = report["program"]["pierce_standoff_mm"]
        .as_f64()
        .unwrap_or(0.0);
    let mut checked = 0usize;
    let mut at_floor = 0usize;
    let mut worst = 0.0f64;
    let mut worst_at = Value::Null;
    let mut per_cut = Vec::new();
    let mut pierce = (f64::INFINITY, f64::NEG_INFINITY);
    for (k, &(on, off)) in intervals.iter().enumerate() {
        let Some(path) = axes.paths.get(k) else { break };
        let f = if small.contains(&path.id.as_str()) {
            factor
        } else {
            1.0
        };
        let slope = f * p_cut / v_ref;
        let mut cut_worst = 0.0f64;
        let mut speeds = Vec::new();
        // The pierce: from the beam's switch until the head first moves, at the pierce power;
        // then the descent (the pierce standoff, at the programmed feed), left out of the peak.
        let mut moving = false;
        let mut travel = 0.0;
        for i in on + POWER_SETTLE..off.saturating_sub(POWER_SETTLE) {
            if !(beam[i] && beam[i - 1]) {
                continue;
            }
            let v = (tips[i].0 - tips[i - 1].0).norm() / period * 60.0;
            if !moving && v == 0.0 {
                pierce.0 = pierce.0.min(power[i]);
                pierce.1 = pierce.1.max(power[i]);
                continue;
            }
            moving = true;
            travel += v * period / 60.0;
            let descending = travel <= descent + 1e-3;
            let p = power[i];
            if p <= floor * 1.001 + 1e-9 {
                at_floor += 1;
                continue;
            }
            if p >= 99.999 {
                continue;
            }
            checked += 1;
            if !descending {
                speeds.push(v);
            }
            let err = (p / (slope * v) - 1.0).abs();
            cut_worst = cut_worst.max(err);
            if err > worst {
                worst = err;
                worst_at = json!({ "id": path.id, "sample": i, "power_percent": p, "tip_speed_mm_per_min": v });
            }
        }
        let peak = speeds.iter().copied().fold(0.0, f64::max);
        per_cut.push(json!({
            "id": path.id,
            "small_hole": f != 1.0,
            "max_ratio_error": cut_worst,
            "peak_tip_speed_mm_per_min": peak, // after the descent
        }));
    }
    json!({
        "cut_percent": p_cut,
        "reference_feed_mm_per_min": v_ref,
        "floor_percent": floor,
        "small_hole_power_factor": factor,
        "small_hole_feed_factor": feed_factor,
        "samples_checked": checked,
        "samples_at_floor": at_floor,
        "pierce_power_percent": [pierce.0, pierce.1],
        "pierce_expected_percent": t["pierce"]["power_percent"].as_f64().unwrap_or(p_cut),
        "max_ratio_error": worst,
        "worst": worst_at,
        "per_cut": per_cut,
    })
}

/// A planned micro-joint: its start and end tip points and its length, mm.
type PlannedJoint = (Point3<f64>, Point3<f64>, f64);

/// Merges each cut's beam intervals over its micro-joints (the report's `micro_joints`) into
/// one, and measures every joint: where the beam went off and on again against the joint's
/// planned start and end (the distance from the planned point to the tip's move over the
/// servo cycle in which the output switched), and the tip's travel with the beam off. When
/// the intervals do not number the cuts plus their joints, they are returned unmerged (the
/// framing check then fails on the count).
fn group_joints(
    intervals: Vec<(usize, usize)>,
    report: &Value,
    axes: &AxesFile,
    tips: &[(Point3<f64>, Vector3<f64>)],
) -> (Vec<(usize, usize)>, Value) {
    let Some(paths) = report["micro_joints"]["paths"].as_array() else {
        return (intervals, Value::Null);
    };
    let point = |v: &Value| {
        let x = |k: usize| v.get(k).and_then(Value::as_f64).unwrap_or(f64::NAN);
        Point3::new(x(0), x(1), x(2))
    };
    let per_path: Vec<Vec<PlannedJoint>> = axes
        .paths
        .iter()
        .map(|a| {
            paths
                .iter()
                .find(|p| p["id"].as_str() == Some(a.id.as_str()))
                .and_then(|p| p["joints"].as_array())
                .map_or(Vec::new(), |j| {
                    j.iter()
                        .map(|j| {
                            let len = j["end_mm"].as_f64().unwrap_or(f64::NAN)
                                - j["start_mm"].as_f64().unwrap_or(f64::NAN);
                            (point(&j["start"]), point(&j["end"]), len)
                        })
                        .collect()
                })
        })
        .collect();
    let expected: usize = per_path.iter().map(|j| j.len() + 1).sum();
    let planned: usize = per_path.iter().map(Vec::len).sum();
    if intervals.len() != expected {
        return (intervals, json!({ "planned": planned, "grouped": false }));
    }
    // Distance from `p` to the tip's move over the cycle ending at sample `i`.
    let at_switch = |p: &Point3<f64>, i: usize| seg_dist(p, &tips[i - 1].0, &tips[i].0);
    let mut merged = Vec::new();
    let mut worst_switch = 0.0f64;
    let mut worst_length = 0.0f64;
    let mut k = 0;
    for joints in &per_path {
        let group = &intervals[k..k + joints.len() + 1];
        for (j, (start, end, len)) in joints.iter().enumerate() {
            let off = group[j].1 + 1; // the first sample with the beam off
            let on = group[j + 1].0; // the first sample with the beam on again
            worst_switch = worst_switch
                .max(at_switch(start, off))
                .max(at_switch(end, on));
            let dark: f64 = (off..on).map(|i| (tips[i].0 - tips[i - 1].0).norm()).sum();
            worst_length = worst_length.max((dark - len).abs());
        }
        merged.push((group[0].0, group[group.len() - 1].1));
        k += joints.len() + 1;
    }
    (
        merged,
        json!({
            "planned": planned,
            "grouped": true,
            "max_switch_distance_mm": worst_switch,
            "max_dark_length_error_mm": worst_length,
        }),
    )
}

/// An exact flat rectangle: a corner and its two edges (at right angles).
struct Rect {
    id: String,
    origin: Point3<f64>,
    u: Vector3<f64>,
    v: Vector3<f64>,
}

impl Rect {
    /// The rectangle of a degree 1 x 1 NURBS patch of 2 x 2 control points with equal weights
    /// whose fourth corner closes the parallelogram and whose edges are at right angles.
    fn of(s: &kerf_format::SurfaceRecord) -> Option<Rect> {
        let kerf_format::SurfaceGeometry::Nurbs(n) = &s.geometry else {
            return None;
        };
        if n.degree_u() != 1 || n.degree_v() != 1 {
            return None;
        }
        let cp = n.control_points();
        if cp.len() != 2 || cp.iter().any(|r| r.len() != 2) {
            return None;
        }
        let w = n.weights();
        let w0 = w[0][0];
        if w.iter()
            .flatten()
            .any(|x| (x - w0).abs() > 1e-12 * w0.abs())
        {
            return None;
        }
        let (o, u, v) = (cp[0][0], cp[1][0] - cp[0][0], cp[0][1] - cp[0][0]);
        let size = u.norm() + v.norm();
        let closes = (cp[1][1] - (o + u + v)).norm() <= 1e-9 * size;
        let square = u.dot(&v).abs() <= 1e-9 * u.norm() * v.norm();
        (closes && square).then(|| Rect {
            id: s.id.clone(),
            origin: o,
            u,
            v,
        })
    }

    /// The exact distance from `q`.
    fn distance(&self, q: &Point3<f64>) -> f64 {
        let w = q - self.origin;
        let a = (w.dot(&self.u) / self.u.norm_squared()).clamp(0.0, 1.0);
        let b = (w.dot(&self.v) / self.v.norm_squared()).clamp(0.0, 1.0);
        (q - (self.origin + self.u * a + self.v * b)).norm()
    }
}

/// The head swept along the executed samples (`tips`, workpiece frame, mapped to part
/// coordinates by `placement`) against the input's rectangles: the least distance of the
/// sampled head surface above the report's tip zone, where and when.
fn head_clearance(
    machine: &Machine,
    report: &Value,
    design: &kerf_format::CurvesFile,
    tips: &[(Point3<f64>, Vector3<f64>)],
    beam: &[bool],
    placement: (nalgebra::Rotation3<f64>, Vector3<f64>),
) -> Value {
    let rects: Vec<Rect> = design
        .surfaces
        .iter()
        .map(|s| {
            Rect::of(s).unwrap_or_else(|| {
                fail(format!(
                    "KERF_HEAD_CHECK: surface {} is not a flat rectangle",
                    s.id
                ))
            })
        })
        .collect();
    let head = machine
        .head
        .clone()
        .unwrap_or_else(kerf_kinematics::Head::laser_default);
    let standoff = machine
        .process
        .standoff_mm
        .unwrap_or(kerf_kinematics::DEFAULT_STANDOFF_MM);
    let zone = report["head"]["tip_zone_mm"].as_f64().unwrap_or(0.0);
    // Head points as (height above the nozzle tip, radius): its surface every 0.5 mm of
    // height, and the flat ends where one solid meets the next (and the top) every mm.
    let len = head.length_mm();
    let mut rings: Vec<(f64, f64)> = Vec::new();
    let steps = ((len - zone) / 0.5).ceil().max(1.0) as usize;
    for j in 0..=steps {
        let h = zone + (len - zone) * j as f64 / steps as f64;
        rings.push((h, head.radius_at(h).unwrap_or(0.0)));
    }
    let mut base = 0.0;
    for (i, sld) in head.solids.iter().enumerate() {
        let below = if i == 0 {
            0.0
        } else {
            head.solids[i - 1].top_diameter_mm / 2.0
        };
        let (lo, hi) = {
            let r = sld.bottom_diameter_mm / 2.0;
            (below.min(r), below.max(r))
        };
        if base >= zone {
            let n = (hi - lo).ceil() as usize;
            for k in 0..=n {
                rings.push((base, lo + (hi - lo) * k as f64 / n.max(1) as f64));
            }
        }
        base += sld.length_mm;
    }
    let top = head.solids.last().map_or(0.0, |s| s.top_diameter_mm / 2.0);
    for k in 0..=(top.ceil() as usize) {
        rings.push((len, (k as f64).min(top)));
    }
    let angles: Vec<(f64, f64)> = (0..72)
        .map(|k| (f64::from(k) * 5.0).to_radians().sin_cos())
        .collect();
    let (rot, shift) = placement;
    let mut least = f64::INFINITY;
    let mut at: Option<(usize, Point3<f64>, String)> = None;
    let mut checked = 0usize;
    let mut last: Option<(Point3<f64>, Vector3<f64>)> = None;
    // From the first beam-on to the last beam-off: the cuts and the traverses between them
    // (the move from wherever the machine stood before the program, and the one after it, are
    // not kerf's).
    let first_on = beam.iter().position(|&b| b).unwrap_or(tips.len());
    let last_on = beam.iter().rposition(|&b| b).unwrap_or(0);
    for (i, (p, a)) in tips.iter().enumerate() {
        if i < first_on || i > last_on {
            continue;
        }
        if let Some((lp, la)) = last {
            if (p - lp).norm() < 0.25 && a.angle(&la) < 0.05f64.to_radians() {
                continue;
            }
        }
        last = Some((*p, *a));
        checked += 1;
        let tip = Point3::from(rot.inverse() * (p - shift));
        let axis = (rot.inverse() * a).normalize();
        let e1 = axis
            .cross(&Vector3::y())
            .try_normalize(1e-9)
            .unwrap_or_else(|| axis.cross(&Vector3::x()).normalize());
        let e2 = axis.cross(&e1);
        for &(h, r) in &rings {
            let c = tip + axis * (standoff + h);
            for &(sn, cs) in &angles {
                let q = c + (e1 * cs + e2 * sn) * r;
                for rc in &rects {
                    let d = rc.distance(&q);
                    if d < least {
                        least = d;
                        at = Some((i, q, rc.id.clone()));
                    }
                }
            }
        }
    }
    json!({
        "min_distance_mm": least,
        "sample": at.as_ref().map(|a| a.0),
        "beam_on": at.as_ref().map(|a| beam.get(a.0).copied().unwrap_or(false)),
        "at": at.as_ref().map(|a| [a.1.x, a.1.y, a.1.z]),
        "surface": at.as_ref().map(|a| a.2.clone()),
        "tip_zone_mm": zone,
        "samples_checked": checked,
        "points_per_sample": rings.len() * angles.len(),
    })
}
