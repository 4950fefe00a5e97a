//! The fuzz harnesses of kerf, shared by the `cargo fuzz` targets (`fuzz_targets/`) and by the
//! corpus regression test of the workspace (`tests/fuzz_corpus.rs`), which includes this file.
//!
//! Each harness states what must hold besides "no panic":
//! - readers: a document that reads round-trips through its writer, and no id or name that
//!   could reach a program holds a control character;
//! - discretizer (structure-aware: a valid NURBS curve, tolerance 1e-4..1 mm): parameters
//!   strictly increasing from one end of the domain to the other, points on the curve, and
//!   no segment whose chord error, sampled at 32 points, exceeds the tolerance;
//! - normals (a planar curve on a tilted NURBS plane): every normal a unit vector parallel to
//!   the plane's normal;
//! - kinematics (a valid machine of every type, poses within 75 degrees of +z): forward
//!   kinematics of every solved axis set gives back its pose;
//! - STEP (bytes read as lossy UTF-8, as `kerf_step::import_file` does): the Part 21 parser
//!   alone (`check_syntax`) gives the same verdict with a byte-order mark in front, and no more
//!   instances than the text could hold; the whole import accepts only what the parser
//!   accepts (and refuses with the parser's own error what it refuses), and what it accepts is
//!   a valid `kerf.curves/1` document (`curves::from_raw`) of finite numbers and safe ids.
#![allow(missing_docs, unreachable_pub)]

use std::path::Path;

use arbitrary::{Arbitrary, Unstructured};
use kerf_discretize::Options;
use kerf_normals::{orient, NormalOptions, NurbsNormals};
use kerf_nurbs::{NurbsCurve, NurbsSurface};
use nalgebra::{Point3, Vector3};

/// A base directory that does not exist: STL paths in fuzzed curves files never reach the disk.
const NO_DIR: &str = "/nonexistent/kerf-fuzz";

fn safe(text: &str) -> bool {
    !text
        .chars()
        .any(|c| c.is_control() || c == '\u{2028}' || c == '\u{2029}')
}

pub fn read_curves(data: &[u8]) {
    if let Ok(file) = kerf_format::curves::from_reader(data, Path::new(NO_DIR)) {
        for c in &file.curves {
            assert!(safe(&c.id), "curve id with a control character: {:?}", c.id);
        }
    }
}

pub fn read_toolpath(data: &[u8]) {
    if let Ok(file) = kerf_format::toolpath::from_reader(data) {
        for p in &file.paths {
            assert!(safe(&p.id), "path id with a control character: {:?}", p.id);
        }
        let text = kerf_format::toolpath::to_string(&file).expect("a read toolpath writes");
        let again = kerf_format::toolpath::from_str(&text).expect("a written toolpath reads");
        assert_eq!(again, file, "toolpath round trip");
    }
    // The checker's independent loose reader must not panic either.
    let _ = kerf_check::RawToolpath::from_slice(data);
}

pub fn read_axes(data: &[u8]) {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    if let Ok(file) = kerf_kinematics::AxesFile::from_str(text) {
        assert!(safe(&file.machine), "machine name with a control character");
        for p in &file.paths {
            assert!(safe(&p.id), "axes id with a control character: {:?}", p.id);
        }
        let json = file.to_json().expect("a read axes file writes");
        let again = kerf_kinematics::AxesFile::from_str(&json).expect("a written axes file reads");
        assert_eq!(again, file, "axes round trip");
    }
}

pub fn read_machine(data: &[u8]) {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    if let Ok(m) = kerf_kinematics::Machine::from_str(text) {
        assert!(
            safe(&m.name),
            "machine name with a control character: {:?}",
            m.name
        );
    }
}

pub fn read_stl(data: &[u8]) {
    if let Ok(mesh) = kerf_format::stl::parse(data.to_vec()) {
        let n = mesh.vertices.len();
        for v in &mesh.vertices {
            assert!(v.coords.iter().all(|x| x.is_finite()), "finite vertex");
        }
        for t in &mesh.triangles {
            assert!(t.iter().all(|&i| (i as usize) < n), "index in range");
        }
    }
}

/// A valid NURBS curve and a tolerance, built from fuzz bytes.
#[derive(Debug, Clone)]
pub struct CurveCase {
    pub curve: NurbsCurve,
    pub tolerance: f64,
}

fn coordinate(u: &mut Unstructured<'_>, scale: f64) -> arbitrary::Result<f64> {
    Ok(f64::from(i16::arbitrary(u)?) / f64::from(i16::MAX) * scale)
}

/// A clamped knot vector for `n` points of degree `p`, interior multiplicities at most `p`.
fn knots(u: &mut Unstructured<'_>, p: usize, n: usize) -> arbitrary::Result<Vec<f64>> {
    let mut k = vec![0.0; p + 1];
    let mut t = 0.0;
    let mut run = 0;
    for _ in 0..n - p - 1 {
        let step = u.int_in_range(0u8..=4)?;
        if step == 0 && run < p - 1 {
            run += 1;
        } else {
            t += f64::from(step.max(1));
            run = 0;
        }
        k.push(t);
    }
    t += f64::from(u.int_in_range(1u8..=4)?);
    k.extend(std::iter::repeat_n(t, p + 1));
    Ok(k)
}

impl<'a> Arbitrary<'a> for CurveCase {
    fn arbitrary(u: &mut Unstructured<'a>) -> arbitrary::Result<Self> {
        let p = u.int_in_range(1usize..=5)?;
        let n = u.int_in_range(p + 1..=p + 8)?;
        let scale = [1.0, 10.0, 100.0, 1000.0][u.int_in_range(0usize..=3)?];
        let mut points = Vec::with_capacity(n);
        for _ in 0..n {
            points.push(Point3::new(
                coordinate(u, scale)?,
                coordinate(u, scale)?,
                coordinate(u, scale)?,
            ));
        }
        let weights = if bool::arbitrary(u)? {
            let mut w = Vec::with_capacity(n);
            for _ in 0..n {
                w.push(0.1 + f64::from(u.int_in_range(0u16..=990)?) / 100.0);
            }
            Some(w)
        } else {
            None
        };
        let tolerance = 10f64.powi(-i32::from(u.int_in_range(0u8..=4)?));
        let knots = knots(u, p, n)?;
        let curve = NurbsCurve::try_new(p, knots, points, weights)
            .map_err(|_| arbitrary::Error::IncorrectFormat)?;
        Ok(Self { curve, tolerance })
    }
}

fn options(tolerance: f64) -> Options {
    Options::with_tolerance(tolerance).with_max_points(200_000)
}

/// The chord error of the segment `[a, b]` sampled at 32 interior parameters: a lower bound of
/// the true error, so a value above the tolerance is a broken certificate.
fn sampled_chord_error(curve: &NurbsCurve, a: f64, b: f64) -> f64 {
    let (pa, pb) = (curve.point(a), curve.point(b));
    let d = pb - pa;
    let len2 = d.norm_squared();
    (1..32)
        .map(|i| {
            let q = curve.point(a + (b - a) * f64::from(i) / 32.0);
            let s = if len2 > 0.0 {
                ((q - pa).dot(&d) / len2).clamp(0.0, 1.0)
            } else {
                0.0
            };
            (q - (pa + d * s)).norm()
        })
        .fold(0.0, f64::max)
}

pub fn discretize(case: &CurveCase) {
    let curve = &case.curve;
    let Ok(d) = kerf_discretize::discretize(curve, &options(case.tolerance)) else {
        return;
    };
    let (t0, t1) = curve.domain();
    assert_eq!(d.params().first(), Some(&t0), "starts at the domain start");
    assert_eq!(d.params().last(), Some(&t1), "ends at the domain end");
    assert_eq!(
        d.params().len(),
        d.points().len(),
        "one point per parameter"
    );
    assert!(
        d.max_chord_error() <= case.tolerance,
        "certified within the tolerance"
    );
    // Rounding in evaluating the samples themselves: a few ulps of the curve's size.
    let size = curve
        .control_points()
        .iter()
        .map(|p| p.coords.amax())
        .fold(1.0, f64::max);
    let slack = 1e-9 * size;
    for (i, w) in d.params().windows(2).enumerate() {
        assert!(w[0] < w[1], "params[{i}..]: strictly increasing");
        let e = sampled_chord_error(curve, w[0], w[1]);
        assert!(
            e <= case.tolerance + slack,
            "segment {i} [{}, {}]: sampled chord error {e} > tolerance {}",
            w[0],
            w[1],
            case.tolerance
        );
    }
    for (t, p) in d.params().iter().zip(d.points()) {
        assert!(
            (curve.point(*t) - p).norm() <= slack,
            "point on the curve at {t}"
        );
    }
}

/// A planar curve on a tilted plane given as a NURBS surface.
#[derive(Debug, Clone)]
pub struct SurfaceCase {
    pub curve: NurbsCurve,
    pub surface: NurbsSurface,
    pub normal: Vector3<f64>,
    pub tolerance: f64,
}

impl<'a> Arbitrary<'a> for SurfaceCase {
    fn arbitrary(u: &mut Unstructured<'a>) -> arbitrary::Result<Self> {
        let base = CurveCase::arbitrary(u)?;
        let tilt = f64::from(u.int_in_range(0u8..=80)?).to_radians();
        let turn = f64::from(u.int_in_range(0u16..=359)?).to_radians();
        let offset = coordinate(u, 500.0)?;
        // Plane frame: e1, e2 in the plane, n its normal.
        let n = Vector3::new(tilt.sin() * turn.cos(), tilt.sin() * turn.sin(), tilt.cos());
        let e1 = n
            .cross(&Vector3::z())
            .try_normalize(1e-12)
            .unwrap_or(Vector3::x());
        let e2 = n.cross(&e1);
        let origin = Point3::from(n * offset);
        let to_plane = |x: f64, y: f64| origin + e1 * x + e2 * y;
        let points: Vec<Point3<f64>> = base
            .curve
            .control_points()
            .iter()
            .map(|p| to_plane(p.x, p.y))
            .collect();
        let curve = NurbsCurve::try_new(
            base.curve.degree(),
            base.curve.knots().to_vec(),
            points,
            Some(base.curve.weights()),
        )
        .map_err(|_| arbitrary::Error::IncorrectFormat)?;
        let r = 4000.0;
        let surface = NurbsSurface::try_new(
            1,
            1,
            vec![0.0, 0.0, 1.0, 1.0],
            vec![0.0, 0.0, 1.0, 1.0],
            vec![
                vec![to_plane(-r, -r), to_plane(-r, r)],
                vec![to_plane(r, -r), to_plane(r, r)],
            ],
            None,
        )
        .map_err(|_| arbitrary::Error::IncorrectFormat)?;
        Ok(Self {
            curve,
            surface,
            normal: n,
            tolerance: base.tolerance,
        })
    }
}

pub fn normals(case: &SurfaceCase) {
    let dopts = options(case.tolerance);
    let Ok(d) = kerf_discretize::discretize(&case.curve, &dopts) else {
        return;
    };
    let source = NurbsNormals::new(case.surface.clone(), false);
    let Ok(o) = orient(&case.curve, &d, &source, &dopts, &NormalOptions::default()) else {
        return;
    };
    assert_eq!(o.params().len(), o.normals().len(), "one normal per point");
    for (i, nv) in o.normals().iter().enumerate() {
        assert!(
            (nv.norm() - 1.0).abs() < 1e-9,
            "normals[{i}] is a unit vector"
        );
        assert!(
            nv.cross(&case.normal).norm() < 1e-6,
            "normals[{i}] = {nv:?} is parallel to the plane normal {:?}",
            case.normal
        );
    }
}

/// A valid machine and a list of poses.
#[derive(Debug, Clone)]
pub struct MachineCase {
    pub json: String,
    pub poses: Vec<kerf_kinematics::Pose>,
}

impl<'a> Arbitrary<'a> for MachineCase {
    fn arbitrary(u: &mut Unstructured<'a>) -> arbitrary::Result<Self> {
        let len = |u: &mut Unstructured<'a>| -> arbitrary::Result<f64> {
            Ok(f64::from(u.int_in_range(0u16..=400)?))
        };
        let mut tilt = "A";
        let kin = match u.int_in_range(0u8..=3)? {
            0 => format!(
                r#"{{"type": "ac-head", "r_a": {}, "r_c": {}}}"#,
                len(u)?,
                len(u)?
            ),
            1 => {
                if bool::arbitrary(u)? {
                    tilt = "B";
                }
                format!(
                    r#"{{"type": "fork-head", "tilt": "{tilt}", "L": {}, "d": [{}, {}, {}], "tool_lateral": [0.0, 0.0]}}"#,
                    len(u)? + 1.0,
                    coordinate(u, 100.0)?,
                    coordinate(u, 100.0)?,
                    coordinate(u, 100.0)?
                )
            }
            2 => {
                tilt = "B";
                format!(
                    r#"{{"type": "head-table", "L": {}, "c_point": [{}, {}, 0.0], "b_sign": {}, "c_sign": {}}}"#,
                    len(u)? + 1.0,
                    coordinate(u, 500.0)?,
                    coordinate(u, 500.0)?,
                    if bool::arbitrary(u)? { 1 } else { -1 },
                    if bool::arbitrary(u)? { 1 } else { -1 }
                )
            }
            _ => format!(
                r#"{{"type": "table-table", "rot_point": [{}, {}, {}], "y_offset": {}, "z_offset": {}, "tool_offset": {}, "conventional": {}}}"#,
                coordinate(u, 100.0)?,
                coordinate(u, 100.0)?,
                coordinate(u, 100.0)?,
                coordinate(u, 50.0)?,
                coordinate(u, 200.0)?,
                coordinate(u, 50.0)?,
                bool::arbitrary(u)?
            ),
        };
        let json = format!(
            r#"{{"format": "kerf.machine/1", "name": "fuzz", "kinematics": {kin},
                "limits": {{"X": null, "Y": null, "Z": null, "{tilt}": [-120, 120], "C": null}},
                "max_velocity": {{"X": 60000, "Y": 60000, "Z": 30000, "{tilt}": 36000, "C": 36000}},
                "max_acceleration": {{"X": 10000, "Y": 10000, "Z": 8000, "{tilt}": 20000, "C": 20000}}}}"#
        );
        let n = u.int_in_range(1usize..=12)?;
        let mut poses = Vec::with_capacity(n);
        for _ in 0..n {
            let tilt = f64::from(u.int_in_range(0u16..=750)?).to_radians() / 10.0;
            let turn = f64::from(u.int_in_range(0u16..=3599)?).to_radians() / 10.0;
            poses.push(kerf_kinematics::Pose::new(
                coordinate(u, 1000.0)?,
                coordinate(u, 1000.0)?,
                coordinate(u, 300.0)?,
                tilt.sin() * turn.cos(),
                tilt.sin() * turn.sin(),
                tilt.cos(),
            ));
        }
        Ok(Self { json, poses })
    }
}

pub fn kinematics(case: &MachineCase) {
    let machine =
        kerf_kinematics::Machine::from_str(&case.json).expect("the built machine is valid");
    let input = kerf_kinematics::PathInput {
        id: "fuzz",
        poses: &case.poses,
        curve: None,
    };
    let Ok(solved) =
        kerf_kinematics::solve_path(&machine, &input, &kerf_kinematics::PathOptions::default())
    else {
        return;
    };
    assert_eq!(
        solved.poses.len(),
        solved.axes.len(),
        "one axis set per pose"
    );
    for (i, (pose, axes)) in solved.poses.iter().zip(&solved.axes).enumerate() {
        let back = machine.kinematics.forward(axes);
        let dp = (back.position - pose.position).norm();
        let da = back.axis.angle(&pose.axis);
        assert!(
            dp < 1e-6,
            "poses[{i}]: forward kinematics misses the tip by {dp} mm"
        );
        assert!(
            da < 1e-7,
            "poses[{i}]: forward kinematics misses the axis by {da} rad"
        );
        assert!(
            machine.violation(axes, 1e-9).is_none(),
            "poses[{i}]: axes {axes:?} outside the limits"
        );
    }
}

/// The Part 21 parser alone: `kerf_step::check_syntax` on the bytes as lossy UTF-8.
pub fn step_syntax(data: &[u8]) {
    let text = String::from_utf8_lossy(data);
    let verdict = kerf_step::check_syntax(&text);
    if let Ok(n) = verdict {
        // An instance takes at least `#1=` and a `;`.
        assert!(
            n.saturating_mul(4) <= text.len(),
            "{n} instances in {} bytes",
            text.len()
        );
    }
    // One leading byte-order mark is skipped: the same verdict with one in front.
    if !text.starts_with('\u{feff}') {
        let again = kerf_step::check_syntax(&format!("\u{feff}{text}"));
        match (&verdict, &again) {
            (Ok(a), Ok(b)) => assert_eq!(a, b, "instance count with a byte-order mark"),
            (Err(a), Err(b)) => {
                assert_eq!(a.to_string(), b.to_string(), "error with a byte-order mark")
            }
            _ => panic!("a byte-order mark changes the verdict: {verdict:?} then {again:?}"),
        }
    }
}

/// The options of a `step_import` input, chosen by a leading selector byte (removed before
/// the text is read): `0x01` the boundary loops of every face (`--edges`), `0x02` the
/// geometric sets with every face written as a surface (`--all-faces`); any other first byte
/// (a STEP file starts with `I`) is part of the text, read with the default options.
pub fn step_options(data: &[u8]) -> (kerf_step::ImportOptions, &[u8]) {
    let defaults = kerf_step::ImportOptions::default();
    match data.split_first() {
        Some((1, rest)) => (defaults.with_edges(None), rest),
        Some((2, rest)) => (defaults.with_all_faces(true), rest),
        _ => (defaults, data),
    }
}

fn finite_weights(what: &str, w: &[f64]) {
    for (i, x) in w.iter().enumerate() {
        assert!(
            x.is_finite() && *x > 0.0,
            "{what}: weight {i} = {x} is not finite and positive"
        );
    }
}

fn finite(what: &str, values: impl IntoIterator<Item = f64>) {
    for (i, x) in values.into_iter().enumerate() {
        assert!(x.is_finite(), "{what}: value {i} = {x} is not finite");
    }
}

fn safe_id(what: &str, id: &str) {
    if let Err(defect) = kerf_io::check_text(id) {
        panic!("{what} {id:?}: {defect}");
    }
}

/// The whole STEP import (`kerf_step::import`), options chosen by [`step_options`].
pub fn step_import(data: &[u8]) {
    use kerf_step::StepError;

    let (opts, body) = step_options(data);
    let text = String::from_utf8_lossy(body);
    let syntax = kerf_step::check_syntax(&text);
    let result = kerf_step::import(&text, &opts);
    // The import runs the parser first: it accepts only what the parser accepts, refuses with
    // the parser's error what the parser refuses, and finds no syntax error the parser missed.
    match (&syntax, &result) {
        (Err(s), Ok(_)) => panic!("import accepts a file check_syntax refuses: {s}"),
        (Err(s), Err(i)) => assert_eq!(
            s.to_string(),
            i.to_string(),
            "import and check_syntax refuse for different reasons"
        ),
        (Ok(n), Err(e @ (StepError::Syntax { .. } | StepError::DuplicateId { .. }))) => {
            panic!(
                "import finds a syntax error in a file check_syntax accepts ({n} instances): {e}"
            )
        }
        _ => {}
    }
    let Ok(import) = result else {
        return;
    };
    let instances = syntax.expect("accepted above");
    assert!(instances >= 1, "a contour from a file of no instance");
    check_import(&import, &opts);
}

/// The IGES reader (`kerf_iges::import`) on arbitrary bytes, options chosen by the first byte
/// as for `step_import`; an accepted import must pass [`check_import`]'s checks.
pub fn iges_import(data: &[u8]) {
    let (opts, body) = step_options(data);
    if let Ok(import) = kerf_iges::import(body, &opts) {
        check_import(&import, &opts);
    }
}

/// What every accepted CAD import must be: a valid `kerf.curves/1` document with a contour,
/// only NURBS surfaces, every number finite (weights > 0), no id with a control character, one
/// report line per surface, the largest gap-closing move within `close_gaps_mm`.
fn check_import(import: &kerf_step::Import, opts: &kerf_step::ImportOptions) {
    use kerf_format::curves::{RawSurface, SurfaceRef};
    let file = &import.file;
    assert!(!file.curves.is_empty(), "an accepted import has a contour");
    for c in &file.curves {
        safe_id("curve id", &c.id);
        finite(&format!("curve {:?} knots", c.id), c.knots.iter().copied());
        finite(
            &format!("curve {:?} control points", c.id),
            c.control_points.iter().flatten().copied(),
        );
        if let Some(w) = &c.weights {
            finite_weights(&format!("curve {:?}", c.id), w);
        }
        match &c.surface {
            Some(SurfaceRef::One(s)) => safe_id("surface ref", s),
            Some(SurfaceRef::Many(v)) => v.iter().for_each(|s| safe_id("surface ref", s)),
            None => {}
        }
    }
    for s in &file.surfaces {
        let RawSurface::Nurbs(n) = s else {
            panic!("the CAD readers write NURBS surfaces only, got {s:?}");
        };
        safe_id("surface id", &n.id);
        finite(
            &format!("surface {:?} knots", n.id),
            n.knots_u.iter().chain(&n.knots_v).copied(),
        );
        finite(
            &format!("surface {:?} control points", n.id),
            n.control_points.iter().flatten().flatten().copied(),
        );
        if let Some(w) = &n.weights {
            let all: Vec<f64> = w.iter().flatten().copied().collect();
            finite_weights(&format!("surface {:?}", n.id), &all);
        }
    }
    let report = &import.report;
    assert_eq!(
        report.surfaces.len(),
        file.surfaces.len(),
        "one report line per surface written"
    );
    assert!(
        report.largest_move >= 0.0 && report.largest_move <= opts.close_gaps_mm,
        "largest pole move {} mm outside [0, close_gaps_mm = {}]",
        report.largest_move,
        opts.close_gaps_mm
    );
    if let Err(e) = kerf_format::curves::from_raw(file.clone(), Path::new(NO_DIR)) {
        panic!("the imported document is not valid kerf.curves/1: {e}");
    }
}
