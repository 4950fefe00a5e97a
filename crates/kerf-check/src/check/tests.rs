use super::*;
use kerf_format::CurvesFile;

fn mixed() -> CurvesFile {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../fixtures/mixed.json");
    kerf_format::curves::load(path).expect("fixture loads")
}

/// The discretizer's toolpath of every curve at `tol`.
fn toolpath(file: &CurvesFile, tol: f64) -> RawToolpath {
    let opts = kerf_discretize::Options::with_tolerance(tol);
    RawToolpath {
        units: Some("mm".into()),
        tolerance: tol,
        paths: file
            .curves
            .iter()
            .map(|c| {
                let d = kerf_discretize::discretize(&c.curve, &opts).expect("discretizes");
                RawPathRecord {
                    id: c.id.clone(),
                    params: d.params().to_vec(),
                    points: d.points().iter().map(|p| vec![p.x, p.y, p.z]).collect(),
                    claimed_chord_error: Some(d.max_chord_error()),
                    point_count: None,
                    kerf_offset: None,
                }
            })
            .collect(),
    }
}

fn defects(report: &Report, path: Option<usize>) -> Vec<&Defect> {
    report
        .violations
        .iter()
        .filter(|v| v.path == path)
        .map(|v| &v.defect)
        .collect()
}

fn index_of(file: &CurvesFile, id: &str) -> usize {
    file.curves
        .iter()
        .position(|c| c.id == id)
        .expect("curve exists")
}

#[test]
fn a_correct_toolpath_passes() {
    let file = mixed();
    let tp = toolpath(&file, 0.01);
    let report = check(&file.curves, &tp, &CheckOptions::default());
    assert!(report.passed(), "{:#?}", report.violations);
    for (p, rec) in report.paths.iter().zip(&tp.paths) {
        assert_eq!(
            p.segments,
            rec.points.len() - 1,
            "{}: every segment measured",
            p.id
        );
        assert!(
            p.claim_holds == Some(true),
            "{}: the certified bound holds",
            p.id
        );
        assert!(p.measured_chord_error <= 0.01, "{}: within tolerance", p.id);
        assert!(
            p.max_point_distance <= 1e-12,
            "{}: points on the curve",
            p.id
        );
    }
    // The discretizer fills the band [0.9, 1] of the tolerance on curved paths.
    let quintic = &report.paths[index_of(&file, "freeform-quintic")];
    assert!(quintic.measured_chord_error > 0.008, "{quintic:?}");
    assert_eq!(
        report.paths[index_of(&file, "v-corner")].c0_breaks,
        1,
        "the corner"
    );
    let json = report.to_json();
    assert_eq!(json["passed"], true, "{json}");
}

#[test]
fn a_removed_point_on_a_curved_path_is_caught() {
    let file = mixed();
    let mut tp = toolpath(&file, 0.01);
    let i = index_of(&file, "freeform-quintic");
    let path = &mut tp.paths[i];
    let k = path.points.len() / 2;
    path.points.remove(k);
    path.params.remove(k);
    let report = check(&file.curves, &tp, &CheckOptions::default());
    let found = defects(&report, Some(i));
    let chord = found
        .iter()
        .find_map(|d| match d {
            Defect::ChordError { segment, error, .. } => Some((*segment, *error)),
            _ => None,
        })
        .expect("the long segment exceeds the tolerance");
    assert_eq!(chord.0, k - 1, "the segment that lost its point");
    // Two segments merged: about four times the error of one.
    assert!(chord.1 > 0.02, "{chord:?}");
    assert!(
        found
            .iter()
            .any(|d| matches!(d, Defect::ClaimUnderstated { .. })),
        "the old claim understates: {found:?}"
    );
    let message = report
        .violations
        .iter()
        .find(|v| matches!(v.defect, Defect::ChordError { .. }))
        .map(ToString::to_string)
        .unwrap_or_default();
    let expected = format!("paths[{i}] (\"freeform-quintic\"): segment {} (t ", k - 1);
    assert!(message.starts_with(&expected), "{message}");
    assert!(message.contains("mm > tolerance 0.01 mm"), "{message}");
    assert_eq!(
        report.paths[i].worst.map(|w| w.segment),
        Some(k - 1),
        "worst segment"
    );
}

#[test]
fn a_removed_c0_corner_is_caught() {
    let file = mixed();
    let mut tp = toolpath(&file, 0.01);
    let i = index_of(&file, "v-corner");
    let path = &mut tp.paths[i];
    let k = path
        .params
        .iter()
        .position(|&t| t == 0.5)
        .expect("corner kept");
    path.points.remove(k);
    path.params.remove(k);
    let report = check(&file.curves, &tp, &CheckOptions::default());
    let found = defects(&report, Some(i));
    assert!(
        found.contains(&&Defect::CornerMissed {
            param: 0.5,
            segment: Some(k - 1)
        }),
        "{found:?}"
    );
    assert!(
        found
            .iter()
            .any(|d| matches!(d, Defect::ChordError { segment, at, .. } if *segment == k - 1 && *at == 0.5)),
        "the chord cuts the corner, largest at the knot: {found:?}"
    );
    let text = report
        .violations
        .iter()
        .map(ToString::to_string)
        .collect::<Vec<_>>();
    assert!(
        text.contains(&format!(
            "paths[{i}] (\"v-corner\"): C0 corner at t = 0.5 is not a cutting point (segment {} spans it)",
            k - 1
        )),
        "{text:#?}"
    );
}

#[test]
fn a_point_off_the_curve_is_caught() {
    let file = mixed();
    let mut tp = toolpath(&file, 0.01);
    let i = index_of(&file, "straight");
    tp.paths[i].points[1][2] += 1e-4;
    let report = check(&file.curves, &tp, &CheckOptions::default());
    let found = defects(&report, Some(i));
    assert!(
        matches!(found[0], Defect::PointOffCurve { index: 1, distance, .. } if (*distance - 1e-4).abs() < 1e-9),
        "{found:?}"
    );
    // The end point moved, so the chord moved: the (tiny) claim of a straight line no
    // longer holds either.
    assert!(
        matches!(found[1], Defect::ClaimUnderstated { measured, .. } if *measured > 9e-5),
        "{found:?}"
    );
    let message = report.violations[0].to_string();
    assert!(
        message.starts_with(&format!("paths[{i}] (\"straight\"): points[1]: 1.000e-4 mm from the curve's point at its param 1 (allowed 1.0e-7 mm)")),
        "{message}"
    );
}

#[test]
fn params_out_of_order_are_caught() {
    let file = mixed();
    // Two neighbouring params swapped.
    let mut tp = toolpath(&file, 0.01);
    let i = index_of(&file, "freeform-quintic");
    tp.paths[i].params.swap(3, 4);
    let report = check(&file.curves, &tp, &CheckOptions::default());
    let found = defects(&report, Some(i));
    assert!(
        found
            .iter()
            .any(|d| matches!(d, Defect::ParamsNotIncreasing { index: 4, .. })),
        "{found:?}"
    );
    assert!(
        found
            .iter()
            .any(|d| matches!(d, Defect::PointOffCurve { index: 3, .. })),
        "points no longer at their params: {found:?}"
    );
    // The whole path reversed: params and points.
    let mut tp = toolpath(&file, 0.01);
    tp.paths[i].params.reverse();
    tp.paths[i].points.reverse();
    let report = check(&file.curves, &tp, &CheckOptions::default());
    let found = defects(&report, Some(i));
    assert!(
        matches!(found[0], Defect::ParamsNotIncreasing { index: 1, .. }),
        "{found:?}"
    );
    assert!(
        found.iter().any(|d| matches!(d, Defect::StartNotDomainStart { value, start } if *value == 1.0 && *start == 0.0)),
        "{found:?}"
    );
    assert!(
        found.iter().any(
            |d| matches!(d, Defect::EndNotDomainEnd { value, end } if *value == 0.0 && *end == 1.0)
        ),
        "{found:?}"
    );
    assert_eq!(report.paths[i].segments, 0, "no segment can be measured");
    assert!(
        report.violations.iter().any(|v| v.to_string()
            == format!("paths[{i}] (\"freeform-quintic\"): params[0]: 1 is not the start of the curve's domain (0)")),
        "{:#?}",
        report.violations
    );
}

#[test]
fn ids_and_their_order_are_checked() {
    let file = mixed();
    let mut tp = toolpath(&file, 0.01);
    tp.paths.swap(0, 1);
    let report = check(&file.curves, &tp, &CheckOptions::default());
    assert_eq!(report.violations.len(), 2, "{:#?}", report.violations);
    assert!(
        matches!(&report.violations[0].defect, Defect::WrongOrder { expected: Some(e) } if e == "v-corner"),
        "{:?}",
        report.violations[0]
    );
    assert!(
        report.paths[0].measured,
        "still measured against its own curve"
    );

    let mut tp = toolpath(&file, 0.01);
    tp.paths.pop();
    tp.paths[0].id = "nope".into();
    tp.paths[1].id = tp.paths[2].id.clone();
    let report = check(&file.curves, &tp, &CheckOptions::default());
    let kinds: Vec<_> = report.violations.iter().map(|v| v.to_string()).collect();
    assert!(
        kinds.contains(&"curves[0] (\"v-corner\"): no path for this curve".to_string()),
        "{kinds:#?}"
    );
    assert!(
        kinds.contains(&"curves[3] (\"slot-on-plane\"): no path for this curve".to_string()),
        "{kinds:#?}"
    );
    assert!(
        kinds.contains(&"paths[0] (\"nope\"): no curve with this id".to_string()),
        "{kinds:#?}"
    );
    assert!(
        kinds.contains(&"paths[2] (\"freeform-quintic\"): same id as paths[1]".to_string()),
        "{kinds:#?}"
    );
    assert!(!report.paths[0].measured, "nothing to measure against");
}

#[test]
fn normals_shapes_and_claims_are_checked() {
    let file = mixed();
    let mut tp = toolpath(&file, 0.01);
    tp.units = None;
    let p = &mut tp.paths[2];
    for q in &mut p.points {
        q.extend([0.0, 0.0, 1.0]);
    }
    p.points[1][5] = 0.5;
    p.points[2].truncate(3);
    tp.paths[1].claimed_chord_error = None;
    tp.paths[3].claimed_chord_error = Some(0.02);
    tp.paths[0].params.pop();
    let report = check(&file.curves, &tp, &CheckOptions::default());
    let found: Vec<_> = report
        .violations
        .iter()
        .map(|v| (v.path, v.defect.clone()))
        .collect();
    assert!(
        found.contains(&(None, Defect::Units { found: None })),
        "{found:#?}"
    );
    assert!(
        found.contains(&(
            Some(2),
            Defect::NormalNotUnit {
                index: 1,
                norm: 0.5
            }
        )),
        "{found:#?}"
    );
    assert!(
        found.contains(&(
            Some(2),
            Defect::PointLength {
                point: 2,
                len: 3,
                expected: Some(6)
            }
        )),
        "{found:#?}"
    );
    assert!(
        found.contains(&(Some(1), Defect::ClaimMissing)),
        "{found:#?}"
    );
    assert!(
        found.contains(&(
            Some(3),
            Defect::ClaimAboveTolerance {
                claimed: 0.02,
                tolerance: 0.01
            }
        )),
        "{found:#?}"
    );
    let n = tp.paths[0].points.len();
    assert!(
        found.contains(&(
            Some(0),
            Defect::CountMismatch {
                points: n,
                params: n - 1
            }
        )),
        "{found:#?}"
    );

    let mut tp = toolpath(&file, 0.01);
    tp.tolerance = 0.0;
    tp.paths[1].points.truncate(1);
    tp.paths[1].params.truncate(1);
    let report = check(&file.curves, &tp, &CheckOptions::default());
    let found: Vec<_> = report
        .violations
        .iter()
        .map(|v| (v.path, v.defect.clone()))
        .collect();
    assert!(
        found.contains(&(None, Defect::BadTolerance { value: 0.0 })),
        "{found:#?}"
    );
    assert!(
        found.contains(&(Some(1), Defect::TooFewPoints { points: 1 })),
        "{found:#?}"
    );
    let mut counted = toolpath(&file, 0.01);
    let n = counted.paths[0].points.len();
    counted.paths[0].point_count = Some(n + 1);
    counted.paths[1].point_count = Some(counted.paths[1].points.len());
    let report = check(&file.curves, &counted, &CheckOptions::default());
    assert_eq!(
        report
            .violations
            .iter()
            .map(|v| (v.path, v.defect.clone()))
            .collect::<Vec<_>>(),
        [(
            Some(0),
            Defect::PointCountMismatch {
                point_count: n + 1,
                points: n
            }
        )],
        "a wrong point_count is the only defect; a right one is none"
    );
    assert!(
        !found
            .iter()
            .any(|(_, d)| matches!(d, Defect::ChordError { .. })),
        "no comparison with a meaningless tolerance"
    );
}

#[test]
fn a_tighter_tolerance_flags_the_file() {
    // The same points claimed for a tolerance ten times tighter.
    let file = mixed();
    let mut tp = toolpath(&file, 0.01);
    tp.tolerance = 0.001;
    for p in &mut tp.paths {
        p.claimed_chord_error = Some(0.0);
    }
    let report = check(&file.curves, &tp, &CheckOptions::default());
    let chord = report
        .violations
        .iter()
        .filter(|v| matches!(v.defect, Defect::ChordError { .. }))
        .count();
    assert!(chord > 100, "most segments exceed 0.001: {chord}");
    let json = report.to_json();
    assert_eq!(json["passed"], false, "{json}");
    assert_eq!(
        json["violations"][0]["kind"], "chord_error",
        "{}",
        json["violations"][0]
    );
    assert!(
        json["violations"][0]["message"]
            .as_str()
            .unwrap_or("")
            .contains("> tolerance 0.001 mm"),
        "{json}"
    );
}

/// The parabola `y = x^2 / 64`, `x` in `[-32, 32]`, moved by `offset`: a quadratic Bezier with
/// exactly representable control points, and its cutting points at `x = -32, -24, ..., 32`
/// (parameter `(x + 32) / 64`), all exact in floating point even 3e6 mm from the origin.
fn parabola(offset: [f64; 3]) -> (CurveRecord, RawPathRecord) {
    let [ox, oy, oz] = offset;
    let curve = NurbsCurve::new(
        2,
        vec![0.0, 0.0, 0.0, 1.0, 1.0, 1.0],
        vec![
            Point3::new(ox - 32.0, oy + 16.0, oz),
            Point3::new(ox, oy - 16.0, oz),
            Point3::new(ox + 32.0, oy + 16.0, oz),
        ],
        None,
    );
    let xs: Vec<f64> = (0..9).map(|k| -32.0 + 8.0 * k as f64).collect();
    let record = RawPathRecord {
        id: "parabola".into(),
        params: xs.iter().map(|x| (x + 32.0) / 64.0).collect(),
        points: xs
            .iter()
            .map(|x| vec![ox + x, oy + x * x / 64.0, oz])
            .collect(),
        claimed_chord_error: None,
        point_count: None,
        kerf_offset: None,
    };
    let curve = CurveRecord::new("parabola", curve);
    (curve, record)
}

/// The exact chord error of the parabola `y = a x^2` between `x0` and `x1`: the largest
/// vertical gap `a (x1 - x0)^2 / 4` (at the middle) times the cosine of the chord's slope
/// `a (x0 + x1)`.
fn parabola_sagitta(x0: f64, x1: f64) -> f64 {
    let a = 1.0 / 64.0;
    a * (x1 - x0).powi(2) / 4.0 / (1.0 + (a * (x0 + x1)).powi(2)).sqrt()
}

#[test]
fn far_from_the_origin_the_measurement_keeps_the_curves_own_precision() {
    // The same parabola and points at the origin and 3e6 mm away (every coordinate exact):
    // both must measure the closed-form chord errors to the curve's own rounding (1e-13 of
    // its size), and a claim 1e-9 mm short of the truth must be caught far away too. In global
    // coordinates the far evaluation rounds by eps * 3e6 ~ 7e-10 mm: the claim's check then
    // failed on exact claims (the reviewer's false alarms) and could not see 1e-9 mm.
    let worst = (0..8)
        .map(|k| parabola_sagitta(-32.0 + 8.0 * k as f64, -24.0 + 8.0 * k as f64))
        .fold(0.0, f64::max);
    for offset in [[0.0, 0.0, 0.0], [1e6, -3e6, 2.5e5]] {
        let (curve, mut path) = parabola(offset);
        let size = curve.curve.size();
        let opts = CheckOptions::default();
        let report = |claim: f64, path: &mut RawPathRecord| {
            path.claimed_chord_error = Some(claim);
            let tp = RawToolpath {
                units: Some("mm".into()),
                tolerance: 0.3,
                paths: vec![path.clone()],
            };
            check(std::slice::from_ref(&curve), &tp, &opts)
        };
        let exact = report(worst, &mut path);
        assert!(exact.passed(), "{offset:?}: {:#?}", exact.violations);
        let p = &exact.paths[0];
        assert_eq!(p.segments, 8, "{offset:?}");
        assert!(
            (p.measured_chord_error - worst).abs() <= 1e-13 * size,
            "{offset:?}: measured {} vs exact {worst}",
            p.measured_chord_error
        );
        assert!(p.max_point_distance <= 1e-13 * size, "{offset:?}: {p:?}");
        let short = report(worst - 1e-9, &mut path);
        assert!(
            short
                .violations
                .iter()
                .any(|v| matches!(v.defect, Defect::ClaimUnderstated { .. })),
            "{offset:?}: a claim 1e-9 mm short is caught: {:#?}",
            short.violations
        );
    }
}

#[test]
fn certified_toolpaths_of_far_curves_pass() {
    // The discretizer's certified output for curves far from the origin (1e6 and 1e9 mm): the
    // checker measured them in global coordinates and raised false alarms (claims understated
    // by its own rounding; points off the curve by less than an ulp of their coordinates).
    for (name, tol) in [
        ("hostile_degree24_far.json", 1e-6),
        ("hostile_far_cubic.json", 1e-3),
        ("hostile_small_far_circle.json", 1e-4),
    ] {
        let path = format!(
            "{}/../../fixtures/hostile/{name}",
            env!("CARGO_MANIFEST_DIR")
        );
        let file = kerf_format::curves::load(&path).expect("fixture loads");
        let tp = toolpath(&file, tol);
        let report = check(&file.curves, &tp, &CheckOptions::default());
        assert!(report.passed(), "{name}: {:#?}", report.violations);
        assert!(report.paths.iter().all(|p| p.measured), "{name}: measured");
    }
}
