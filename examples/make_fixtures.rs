//! Writes the "real work" fixtures of `fixtures/`: a car door trim on a doubly curved panel, a
//! tube saddle on the exact cylinder and on an STL of it, a 3.5 m turbine-blade edge, a
//! sheet-metal part with holes on an STL of the plate, and the two trim lines of issue 26 (one
//! over a stamped panel whose normal passes near the vertical again and again, one over creases
//! and up a vertical flange).
//!
//! ```text
//! cargo run --release --example make_fixtures            # rewrites fixtures/*.json, *.stl
//! cargo run --release --example make_fixtures -- OUTDIR  # writes them into OUTDIR instead
//! ```
//!
//! The output is deterministic: the same build writes the same bytes. Every curve is built so
//! that it lies on its surface:
//!
//! - exactly where the geometry allows it: conics on planes (rational quadratics), the blade
//!   edge as the `v = 0` boundary row of its ruled surface (same knots, control points and
//!   weights, so the isoparametric curve *is* the edge), the stamped panel's trim line as a
//!   parameter-space curve composed into the panel (a polynomial B-spline of degree 12), the
//!   creased trim line as lines and arcs drawn in the flat pattern and folded with its faces
//!   (these two are measured within 1e-9 mm of their surfaces, their points rounded to 1e-12);
//! - otherwise (a contour drawn on a free-form panel, the intersection of two cylinders, which
//!   is no rational curve) by interpolating many points computed *on* the surface with a cubic
//!   B-spline; the generator then measures the curve's largest distance from the surface
//!   (densely, against the exact surface) and refuses to write a fixture whose curves are
//!   farther than 1e-5 mm from it.
//!
//! `fixtures/README.md` describes each file and what it tests. Fitted control points are rounded
//! to 1e-9 mm so that the files stay readable; the measurements are made on the written files.

use std::f64::consts::{PI, TAU};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use kerf::format::curves::{self, RawCurve, RawCurvesFile, RawNurbsSurface, RawStl, RawSurface};
use kerf::nurbs::{basis_funs, find_span, NurbsCurve, NurbsSurface, MAX_ORDER};
use nalgebra::{DMatrix, Matrix3x2, Point2, Point3, Vector2, Vector3};

/// The largest curve-to-surface distance the generator accepts, mm (kerf's default on-surface
/// tolerance is 0.01 mm; the fixtures stay three orders of magnitude inside it).
const MAX_OFF_SURFACE: f64 = 1e-5;

fn main() {
    let out: PathBuf = std::env::args_os().nth(1).map_or_else(
        || Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures"),
        PathBuf::from,
    );
    std::fs::create_dir_all(&out).expect("create the output directory");
    door_trim(&out);
    tube_saddle(&out);
    turbine_blade_edge(&out);
    sheet_metal_holes(&out);
    trim_panel(&out);
    trim_creases(&out);
}

// ---------------------------------------------------------------------------------------------
// Numbers and files.
// ---------------------------------------------------------------------------------------------

/// Rounds to 1e-9 mm (exact for |x| < 9e6: the product stays below 2^53).
fn r9(x: f64) -> f64 {
    (x * 1e9).round() / 1e9
}

fn r9p(p: Point3<f64>) -> [f64; 3] {
    [r9(p.x), r9(p.y), r9(p.z)]
}

/// Serialises `doc` as JSON with every array of numbers on one line (wrapped at ten numbers
/// when long), so that a control point reads `[x, y, z]`.
fn write_json(path: &Path, doc: &RawCurvesFile) {
    let pretty = serde_json::to_string_pretty(doc).expect("serialise");
    let lines: Vec<&str> = pretty.lines().collect();
    let mut out = String::with_capacity(pretty.len() / 2);
    let mut i = 0;
    while i < lines.len() {
        let line = lines[i];
        if line.ends_with('[') {
            let mut nums = Vec::new();
            let mut j = i + 1;
            let mut close = None;
            while j < lines.len() {
                let t = lines[j].trim();
                if t == "]" || t == "]," {
                    close = Some(j);
                    break;
                }
                let v = t.trim_end_matches(',');
                if v.parse::<f64>().is_err() {
                    break;
                }
                nums.push(v);
                j += 1;
            }
            if let (Some(j), false) = (close, nums.is_empty()) {
                let closing = lines[j];
                let joined = nums.join(", ");
                if line.len() + joined.len() < 100 {
                    writeln!(out, "{line}{joined}{}", closing.trim_start()).expect("string");
                } else {
                    let indent = &closing[..closing.len() - closing.trim_start().len()];
                    writeln!(out, "{line}").expect("string");
                    let rows: Vec<String> = nums.chunks(10).map(|c| c.join(", ")).collect();
                    for (k, row) in rows.iter().enumerate() {
                        let comma = if k + 1 < rows.len() { "," } else { "" };
                        writeln!(out, "{indent}  {row}{comma}").expect("string");
                    }
                    writeln!(out, "{closing}").expect("string");
                }
                i = j + 1;
                continue;
            }
        }
        out.push_str(line);
        out.push('\n');
        i += 1;
    }
    std::fs::write(path, out).expect("write the fixture");
}

/// Writes a binary STL: 80-byte header, facet count, 50 bytes per facet (normal, three
/// vertices as little-endian f32, a zero attribute word).
fn write_stl(path: &Path, header: &str, tris: &[[Point3<f64>; 3]]) {
    let mut bytes = Vec::with_capacity(84 + 50 * tris.len());
    let mut head = [b' '; 80];
    head[..header.len()].copy_from_slice(header.as_bytes());
    bytes.extend_from_slice(&head);
    bytes.extend_from_slice(&u32::try_from(tris.len()).expect("facets").to_le_bytes());
    for t in tris {
        let n = (t[1] - t[0]).cross(&(t[2] - t[0])).normalize();
        for v in [n.x, n.y, n.z] {
            bytes.extend_from_slice(&(v as f32).to_le_bytes());
        }
        for p in t {
            for v in [p.x, p.y, p.z] {
                bytes.extend_from_slice(&(v as f32).to_le_bytes());
            }
        }
        bytes.extend_from_slice(&[0, 0]);
    }
    std::fs::write(path, bytes).expect("write the STL");
}

/// A triangle wound counter-clockwise seen from `outward`.
fn facet(
    a: Point3<f64>,
    b: Point3<f64>,
    c: Point3<f64>,
    outward: Vector3<f64>,
) -> [Point3<f64>; 3] {
    if (b - a).cross(&(c - a)).dot(&outward) >= 0.0 {
        [a, b, c]
    } else {
        [a, c, b]
    }
}

fn curve(
    id: &str,
    degree: usize,
    knots: Vec<f64>,
    cps: Vec<[f64; 3]>,
    w: Option<Vec<f64>>,
    surface: &str,
) -> RawCurve {
    RawCurve::new(id, degree, knots, cps)
        .with_weights(w)
        .with_surface(Some(surface.into()))
}

fn document(curves: Vec<RawCurve>, surfaces: Vec<RawSurface>) -> RawCurvesFile {
    RawCurvesFile {
        format: "kerf.curves/1".into(),
        units: "mm".into(),
        curves,
        surfaces,
    }
}

/// Loads a written fixture through kerf's reader (all checks) and returns it.
fn reload(path: &Path) -> curves::CurvesFile {
    curves::load(path).unwrap_or_else(|e| panic!("the generator wrote an invalid file: {e}"))
}

/// Dense parameters over a curve's domain: `per_span` samples in every knot span.
fn dense_params(c: &kerf::nurbs::NurbsCurve, per_span: usize) -> Vec<f64> {
    let mut ts = Vec::new();
    for (_, a, b) in c.spans() {
        for k in 0..per_span {
            ts.push(a + (b - a) * k as f64 / per_span as f64);
        }
    }
    ts.push(c.domain().1);
    ts
}

fn report(path: &Path, file: &curves::CurvesFile, off_surface: f64, note: &str) {
    let bytes = std::fs::metadata(path).expect("written").len();
    println!(
        "{}: {} curves, {} KiB, largest curve-to-surface distance {off_surface:.2e} mm{note}",
        path.display(),
        file.curves.len(),
        bytes.div_ceil(1024)
    );
    for c in &file.curves {
        println!(
            "  {:<22} degree {}, {:>4} control points, {:>8.2} mm, {} C0 corners, closed: {}",
            c.id,
            c.curve.degree(),
            c.curve.len(),
            c.curve.arc_length(),
            c.curve.c0_breaks().len(),
            c.curve.is_closed()
        );
    }
    assert!(
        off_surface <= MAX_OFF_SURFACE,
        "{}: a curve is {off_surface:e} mm off its surface",
        path.display()
    );
}

// ---------------------------------------------------------------------------------------------
// Plane contours: lines and circular arcs, filleted polygons.
// ---------------------------------------------------------------------------------------------

/// A piece of a plane contour.
#[derive(Debug, Clone, Copy)]
enum Seg2 {
    Line(Point2<f64>, Point2<f64>),
    /// Centre, radius, start angle, signed sweep (radians, positive counter-clockwise).
    Arc(Point2<f64>, f64, f64, f64),
}

fn dir(a: f64) -> Vector2<f64> {
    Vector2::new(a.cos(), a.sin())
}

impl Seg2 {
    fn len(&self) -> f64 {
        match *self {
            Seg2::Line(a, b) => (b - a).norm(),
            Seg2::Arc(_, r, _, s) => r * s.abs(),
        }
    }

    /// The point at fraction `f` of the piece and the unit tangent there.
    fn at(&self, f: f64) -> (Point2<f64>, Vector2<f64>) {
        match *self {
            Seg2::Line(a, b) => (a + (b - a) * f, (b - a).normalize()),
            Seg2::Arc(c, r, a0, s) => {
                let a = a0 + s * f;
                (c + dir(a) * r, Vector2::new(-a.sin(), a.cos()) * s.signum())
            }
        }
    }
}

/// A closed polygon with a fillet radius per vertex (0 = sharp corner), as lines and arcs
/// starting at vertex 0 (at its fillet's start if it has one). Each piece comes with whether it
/// starts at a sharp corner. Vertices run counter-clockwise for a positive area.
fn rounded_polygon(verts: &[(f64, f64, f64)]) -> Vec<(Seg2, bool)> {
    let n = verts.len();
    let p = |i: usize| Point2::new(verts[i % n].0, verts[i % n].1);
    // Per vertex: the tangent points T1 (end of the incoming line), T2 and the arc between.
    let corners: Vec<(Point2<f64>, Point2<f64>, Option<Seg2>)> = (0..n)
        .map(|i| {
            let v = p(i);
            let r = verts[i].2;
            if r == 0.0 {
                return (v, v, None);
            }
            let d_in = (v - p(i + n - 1)).normalize();
            let d_out = (p(i + 1) - v).normalize();
            let turn = d_in.perp(&d_out).atan2(d_in.dot(&d_out));
            let t = r * (turn.abs() / 2.0).tan();
            assert!(
                t <= 0.5 * (v - p(i + n - 1)).norm() + 1e-9
                    && t <= 0.5 * (p(i + 1) - v).norm() + 1e-9,
                "fillet {i} too large"
            );
            let t1 = v - d_in * t;
            let t2 = v + d_out * t;
            let left = Vector2::new(-d_in.y, d_in.x);
            let c = t1 + left * (r * turn.signum());
            let a0 = (t1 - c).y.atan2((t1 - c).x);
            (t1, t2, Some(Seg2::Arc(c, r, a0, turn)))
        })
        .collect();
    let mut segs = Vec::new();
    for i in 0..n {
        let (_, t2, arc) = corners[i];
        if let Some(a) = arc {
            segs.push((a, false));
        }
        let next = corners[(i + 1) % n].0;
        if (next - t2).norm() > 1e-9 {
            segs.push((Seg2::Line(t2, next), verts[i].2 == 0.0));
        }
    }
    segs
}

/// A slot: two half circles of radius `r` whose centres are `length` apart, centred at `c`,
/// turned by `angle` degrees.
fn slot(c: (f64, f64), length: f64, r: f64, angle: f64) -> Vec<(Seg2, bool)> {
    let (s, co) = angle.to_radians().sin_cos();
    let at = |x: f64, y: f64| (c.0 + co * x - s * y, c.1 + s * x + co * y, r);
    let h = 0.5 * length + r;
    rounded_polygon(&[at(-h, -r), at(h, -r), at(h, r), at(-h, r)])
}

/// A full circle as one arc, starting at angle 0.
fn circle(c: (f64, f64), r: f64) -> Vec<(Seg2, bool)> {
    vec![(Seg2::Arc(Point2::new(c.0, c.1), r, 0.0, TAU), false)]
}

/// The exact rational quadratic NURBS of a closed plane contour at height `z`: lines as
/// quadratics with their middle point, arcs in pieces of at most 90 degrees with middle weight
/// `cos(sweep / 2)`; knots at the cumulative length fractions, doubled at every joint.
fn exact_quadratic(segs: &[(Seg2, bool)], z: f64) -> (Vec<f64>, Vec<[f64; 3]>, Vec<f64>) {
    // Bezier pieces: (P0, P1, P2, w1, length).
    let mut pieces = Vec::new();
    for (s, _) in segs {
        match *s {
            Seg2::Line(a, b) => pieces.push((a, nalgebra::center(&a, &b), b, 1.0, s.len())),
            Seg2::Arc(c, r, a0, sweep) => {
                let k = (sweep.abs() / (0.5 * PI) - 1e-9).ceil() as usize;
                let d = sweep / k as f64;
                for m in 0..k {
                    let (b0, b1) = (a0 + d * m as f64, a0 + d * (m + 1) as f64);
                    let mid = c + dir(0.5 * (b0 + b1)) * (r / (0.5 * d).cos());
                    pieces.push((
                        c + dir(b0) * r,
                        mid,
                        c + dir(b1) * r,
                        (0.5 * d).cos(),
                        r * d.abs(),
                    ));
                }
            }
        }
    }
    let total: f64 = pieces.iter().map(|p| p.4).sum();
    let mut kn = vec![0.0; 3];
    let mut cps = vec![];
    let mut w = vec![];
    let mut acc = 0.0;
    let p3 = |p: Point2<f64>| [r9(p.x), r9(p.y), z];
    for (i, (a, m, _, wm, _)) in pieces.iter().enumerate() {
        if i > 0 {
            acc += pieces[i - 1].4;
            let k = r9(acc / total);
            kn.extend([k, k]);
        }
        cps.extend([p3(*a), p3(*m)]);
        w.extend([1.0, *wm]);
    }
    // Close the loop on the very first point, so that the curve ends exactly where it starts.
    cps.push(cps[0]);
    w.push(1.0);
    kn.extend([1.0; 3]);
    (kn, cps, w)
}

// ---------------------------------------------------------------------------------------------
// Cubic B-spline interpolation of points computed on a surface.
// ---------------------------------------------------------------------------------------------

/// Solves the square system `a x = b` (three right-hand sides) by LU with partial pivoting.
fn solve(a: DMatrix<f64>, b: DMatrix<f64>) -> DMatrix<f64> {
    a.lu().solve(&b).expect("non-singular interpolation system")
}

/// A clamped cubic B-spline through `q[k]` at parameters `t[k]` (knots at every parameter)
/// whose end derivatives are `d0` and `d1`: the "complete" cubic spline. Returns the knots and
/// control points (`q.len() + 2` of them).
fn complete_cubic(
    t: &[f64],
    q: &[Point3<f64>],
    d0: Vector3<f64>,
    d1: Vector3<f64>,
) -> (Vec<f64>, Vec<Point3<f64>>) {
    let n = q.len() - 1;
    let m = n + 3;
    let mut kn = vec![t[0]; 4];
    kn.extend_from_slice(&t[1..n]);
    kn.extend([t[n]; 4]);
    let mut a = DMatrix::zeros(m, m);
    let mut b = DMatrix::zeros(m, 3);
    let set = |b: &mut DMatrix<f64>, row: usize, v: Vector3<f64>| {
        for c in 0..3 {
            b[(row, c)] = v[c];
        }
    };
    a[(0, 0)] = 1.0;
    set(&mut b, 0, q[0].coords);
    let s0 = 3.0 / (kn[4] - kn[1]);
    a[(1, 0)] = -s0;
    a[(1, 1)] = s0;
    set(&mut b, 1, d0);
    for k in 1..n {
        let span = find_span(3, &kn, m, t[k]);
        let mut nb = [0.0; MAX_ORDER];
        basis_funs(span, t[k], 3, &kn, &mut nb);
        for j in 0..4 {
            a[(k + 1, span - 3 + j)] = nb[j];
        }
        set(&mut b, k + 1, q[k].coords);
    }
    let s1 = 3.0 / (kn[m + 2] - kn[m - 1]);
    a[(m - 2, m - 2)] = -s1;
    a[(m - 2, m - 1)] = s1;
    set(&mut b, m - 2, d1);
    a[(m - 1, m - 1)] = 1.0;
    set(&mut b, m - 1, q[n].coords);
    let x = solve(a, b);
    let cps = (0..m)
        .map(|i| Point3::new(x[(i, 0)], x[(i, 1)], x[(i, 2)]))
        .collect();
    (kn, cps)
}

/// A plane contour lifted onto a surface by `lift(plan point) -> (point, d point / d plan)`
/// and fitted by one clamped cubic: each line or arc is interpolated by a complete cubic spline
/// through points at most `step` mm apart (in plan), with the exact end derivatives; the pieces
/// meet C1 (knot of multiplicity 2) where the contour is tangent-continuous and C0 (multiplicity
/// 3) at its sharp corners. The parameter is the plan length fraction.
fn lifted_cubic(
    segs: &[(Seg2, bool)],
    step: f64,
    lift: &dyn Fn(Point2<f64>) -> (Point3<f64>, Matrix3x2<f64>),
) -> (Vec<f64>, Vec<[f64; 3]>) {
    let total: f64 = segs.iter().map(|s| s.0.len()).sum();
    let mut kn: Vec<f64> = Vec::new();
    let mut cps: Vec<Point3<f64>> = Vec::new();
    let mut s_a = 0.0;
    for (i, (seg, sharp)) in segs.iter().enumerate() {
        let len = seg.len();
        let s_b = if i + 1 == segs.len() {
            total
        } else {
            s_a + len
        };
        // Parameters rounded to 1e-9 before the fit, so that the knots read well and the fit
        // interpolates at exactly the written values.
        let (a, b) = (r9(s_a / total), r9(s_b / total));
        let h = match seg {
            Seg2::Line(..) => step,
            Seg2::Arc(_, r, ..) => step.min(0.2 * r),
        };
        let n = (len / h).ceil().max(1.0) as usize;
        let ts: Vec<f64> = (0..=n)
            .map(|k| r9(a + (b - a) * k as f64 / n as f64))
            .collect();
        let mut q = Vec::with_capacity(n + 1);
        let mut ds = Vec::with_capacity(n + 1);
        for k in 0..=n {
            let (p2, tan) = seg.at(k as f64 / n as f64);
            let (p, jac) = lift(p2);
            q.push(p);
            ds.push(jac * tan * total);
        }
        let (pk, pc) = complete_cubic(&ts, &q, ds[0], ds[n]);
        if i == 0 {
            kn.extend_from_slice(&pk[..pk.len() - 4]);
            cps.extend_from_slice(&pc);
        } else {
            // Join at the shared end point: the triple knot and control point of a C0 joint;
            // where the contour is tangent-continuous the derivatives agree, so the curve is C1
            // there and one copy of the knot and the joint's control point go (exact knot
            // removal: the joint lies on the line of its neighbours at the knot ratio).
            let joint = pk[0];
            if *sharp {
                kn.extend([joint; 3]);
            } else {
                kn.extend([joint; 2]);
                cps.pop();
            }
            kn.extend_from_slice(&pk[4..pk.len() - 4]);
            cps.extend_from_slice(&pc[1..]);
        }
        s_a = s_b;
    }
    kn.extend([1.0; 4]);
    let mut cps: Vec<[f64; 3]> = cps.into_iter().map(r9p).collect();
    // The contour is closed: end exactly on the first point.
    let last = cps.len() - 1;
    cps[last] = cps[0];
    (kn, cps)
}

/// A closed, C2 everywhere, uniform cubic B-spline through `q` (periodic interpolation):
/// unclamped knots `(j - 3) / N`, `N + 3` control points of which the last three repeat the
/// first three; domain `[0, 1]`, `q[i]` at parameter `i / N`.
fn periodic_cubic(q: &[Point3<f64>]) -> (Vec<f64>, Vec<[f64; 3]>) {
    let n = q.len();
    let mut a = DMatrix::zeros(n, n);
    let mut b = DMatrix::zeros(n, 3);
    for i in 0..n {
        a[(i, (i + n - 1) % n)] = 1.0 / 6.0;
        a[(i, i)] = 4.0 / 6.0;
        a[(i, (i + 1) % n)] = 1.0 / 6.0;
        for c in 0..3 {
            b[(i, c)] = q[i][c];
        }
    }
    let r = solve(a, b);
    let cps = (0..n + 3)
        .map(|j| {
            let i = (j + n - 1) % n;
            [r9(r[(i, 0)]), r9(r[(i, 1)]), r9(r[(i, 2)])]
        })
        .collect();
    let kn = (0..n + 7).map(|j| (j as f64 - 3.0) / n as f64).collect();
    (kn, cps)
}

// ---------------------------------------------------------------------------------------------
// door_trim.json
// ---------------------------------------------------------------------------------------------

/// The door panel: a bicubic B-spline graph `z = H(x, y)` over `[-400, 400] x [-250, 250]`
/// whose x and y control coordinates sit at the Greville abscissae, so that `x(u)` and `y(v)`
/// are exactly linear and a plan point maps to `(u, v)` without a projection.
struct Panel {
    surface: NurbsSurface,
    raw: RawNurbsSurface,
}

const PANEL_X: (f64, f64) = (-400.0, 800.0);
const PANEL_Y: (f64, f64) = (-250.0, 500.0);

fn greville(kn: &[f64], n: usize, p: usize) -> Vec<f64> {
    (0..n)
        .map(|i| kn[i + 1..=i + p].iter().sum::<f64>() / p as f64)
        .collect()
}

fn panel() -> Panel {
    let ku = vec![0.0, 0.0, 0.0, 0.0, 0.25, 0.5, 0.75, 1.0, 1.0, 1.0, 1.0];
    let kv = vec![0.0, 0.0, 0.0, 0.0, 0.5, 1.0, 1.0, 1.0, 1.0];
    let (gu, gv) = (greville(&ku, 7, 3), greville(&kv, 5, 3));
    // Crowned both ways (radii of curvature about 1.6 m along x and 1 m along y), slightly
    // twisted and asymmetric, 10 to 100 mm above the table.
    let h = |x: f64, y: f64| {
        let (a, b) = (x / 400.0, y / 250.0);
        100.0 - 50.0 * a * a - 30.0 * b * b + 10.0 * a * b + 6.0 * a * a * a
    };
    let cps: Vec<Vec<[f64; 3]>> = gu
        .iter()
        .map(|&u| {
            gv.iter()
                .map(|&v| {
                    let (x, y) = (PANEL_X.0 + PANEL_X.1 * u, PANEL_Y.0 + PANEL_Y.1 * v);
                    [r9(x), r9(y), r9(h(x, y))]
                })
                .collect()
        })
        .collect();
    let pts = cps
        .iter()
        .map(|r| r.iter().map(|p| Point3::from(*p)).collect())
        .collect();
    Panel {
        surface: NurbsSurface::new(3, 3, ku.clone(), kv.clone(), pts, None),
        raw: RawNurbsSurface {
            id: "door-panel".into(),
            degree_u: 3,
            degree_v: 3,
            knots_u: ku,
            knots_v: kv,
            control_points: cps,
            weights: None,
            flip: false,
        },
    }
}

impl Panel {
    fn uv(p: Point2<f64>) -> (f64, f64) {
        ((p.x - PANEL_X.0) / PANEL_X.1, (p.y - PANEL_Y.0) / PANEL_Y.1)
    }

    fn lift(&self, p: Point2<f64>) -> (Point3<f64>, Matrix3x2<f64>) {
        let (u, v) = Self::uv(p);
        assert!(
            (0.0..=1.0).contains(&u) && (0.0..=1.0).contains(&v),
            "{p} off the panel"
        );
        let (s, su, sv) = self.surface.eval_d1(u, v);
        (
            s,
            Matrix3x2::from_columns(&[su / PANEL_X.1, sv / PANEL_Y.1]),
        )
    }

    /// The vertical gap between a point and the panel (an upper bound of its distance).
    fn gap(&self, p: &Point3<f64>) -> f64 {
        let (u, v) = Self::uv(Point2::new(p.x, p.y));
        let s = self.surface.point(u, v);
        assert!(
            (s.x - p.x).abs() < 1e-9 && (s.y - p.y).abs() < 1e-9,
            "x(u), y(v) linear"
        );
        (s.z - p.z).abs()
    }
}

fn door_trim(out: &Path) {
    let panel = panel();
    let lift = |p: Point2<f64>| panel.lift(p);
    // The trim opening, counter-clockwise seen from above: four sharp corners (two of them
    // concave: the armrest step), four fillets of radius 25 to 80.
    let outline = rounded_polygon(&[
        (-360.0, -200.0, 0.0),
        (-40.0, -200.0, 25.0),
        (0.0, -140.0, 0.0),
        (340.0, -140.0, 60.0),
        (360.0, 60.0, 0.0),
        (250.0, 210.0, 30.0),
        (-300.0, 210.0, 80.0),
        (-370.0, 100.0, 0.0),
    ]);
    // A window-switch cut-out: a rounded rectangle 90 x 36, corners r = 8, turned 10 degrees.
    let (s, c) = 10f64.to_radians().sin_cos();
    let sw = |x: f64, y: f64| (220.0 + c * x - s * y, 40.0 + s * x + c * y, 8.0);
    let switch = rounded_polygon(&[
        sw(-45.0, -18.0),
        sw(45.0, -18.0),
        sw(45.0, 18.0),
        sw(-45.0, 18.0),
    ]);
    let speaker = circle((-200.0, -60.0), 70.0);
    let mut cs = Vec::new();
    for (id, segs) in [
        ("speaker-hole", &speaker),
        ("switch-cutout", &switch),
        ("trim-outline", &outline),
    ] {
        let (kn, cps) = lifted_cubic(segs, 4.0, &lift);
        cs.push(curve(id, 3, kn, cps, None, "door-panel"));
    }
    let path = out.join("door_trim.json");
    write_json(
        &path,
        &document(cs, vec![RawSurface::Nurbs(panel.raw.clone())]),
    );
    let file = reload(&path);
    let mut worst: f64 = 0.0;
    for c in &file.curves {
        for t in dense_params(&c.curve, 16) {
            worst = worst.max(panel.gap(&c.curve.point(t)));
        }
    }
    report(&path, &file, worst, " (vertical gap to the panel)");
}

// ---------------------------------------------------------------------------------------------
// tube_saddle.json, tube_saddle_stl.json, tube_main.stl
// ---------------------------------------------------------------------------------------------

const MAIN_R: f64 = 60.0;
const MAIN_Z: f64 = 60.0; // the main tube lies on the table: axis at z = 60
const MAIN_X: f64 = 150.0; // main tube from x = -150 to 150
const BRANCH_R: f64 = 30.0;

/// A cylinder ([`NurbsSurface::revolve`] of a line): the line from `c0 + r e1` to
/// `c0 + r e1 + axis` turned a full turn about the axis through `c0` along `axis`, so `u` goes
/// round from `c0 + r e1` towards `e2` (the exact 9-point rational quadratic circle) and `v`
/// runs along the axis. With `e1 x e2 = axis / |axis|` the normal `Su x Sv` points outward.
/// ([`NurbsSurface::cylinder`] would choose the seam itself; here it is placed away from the
/// cut.)
fn cylinder(
    id: &str,
    c0: Vector3<f64>,
    axis: Vector3<f64>,
    e1: Vector3<f64>,
    e2: Vector3<f64>,
    r: f64,
) -> RawNurbsSurface {
    assert!(
        (e1.cross(&e2) - axis.normalize()).norm() < 1e-12,
        "{id}: e1 x e2 must be the axis direction"
    );
    let foot = Point3::from(c0 + e1 * r);
    let line = NurbsCurve::line(foot, foot + axis).expect("the cylinder's line");
    let surface = NurbsSurface::revolve(&line, Point3::from(c0), axis, TAU).expect("the cylinder");
    raw_surface(id, &surface)
}

/// The `kerf.curves/1` record of `surface`, its control points rounded to 1e-9 mm (the shape
/// constructors' points differ from the exact corners by rounding only: regenerated, the
/// fixtures are byte-identical to the committed ones).
fn raw_surface(id: &str, surface: &NurbsSurface) -> RawNurbsSurface {
    RawNurbsSurface {
        id: id.into(),
        degree_u: surface.degree_u(),
        degree_v: surface.degree_v(),
        knots_u: surface.knots_u().to_vec(),
        knots_v: surface.knots_v().to_vec(),
        control_points: surface
            .control_points()
            .iter()
            // `+ 0.0` writes a rounded -0 as 0, as the exact corners are.
            .map(|row| row.iter().map(|p| r9p(*p).map(|v| v + 0.0)).collect())
            .collect(),
        weights: surface.is_rational().then(|| surface.weights()),
        flip: false,
    }
}

fn tube_saddle(out: &Path) {
    // The saddle where a vertical branch tube (radius 30, axis the z axis) meets the main tube
    // (radius 60, axis along x at height 60): x = 30 cos(th), y = 30 sin(th),
    // z = 60 + sqrt(60^2 - y^2). It is the intersection of two cylinders of different radii, a
    // quartic of genus 1 that no rational curve parametrises, so it is interpolated: 160 points
    // on the exact intersection, periodic cubic (C2 also at the start point).
    let n = 160;
    let q: Vec<Point3<f64>> = (0..n)
        .map(|i| {
            let th = TAU * i as f64 / n as f64;
            let (x, y) = (BRANCH_R * th.cos(), BRANCH_R * th.sin());
            Point3::new(x, y, MAIN_Z + (MAIN_R * MAIN_R - y * y).sqrt())
        })
        .collect();
    let (kn, cps) = periodic_cubic(&q);
    // Main tube: u around, starting at the bottom (the seam is far from the cut), v along +x.
    let main = cylinder(
        "main-tube",
        Vector3::new(-MAIN_X, 0.0, MAIN_Z),
        Vector3::new(2.0 * MAIN_X, 0.0, 0.0),
        -Vector3::z(),
        Vector3::y(),
        MAIN_R,
    );
    // Branch tube: u around (counter-clockwise from +x seen from above), v up from z = 100 to
    // 250; its seam at x = -30 crosses the curve.
    let branch = cylinder(
        "branch-tube",
        Vector3::new(0.0, 0.0, 100.0),
        Vector3::new(0.0, 0.0, 150.0),
        Vector3::x(),
        Vector3::y(),
        BRANCH_R,
    );
    let hole = curve(
        "main-tube-hole",
        3,
        kn.clone(),
        cps.clone(),
        None,
        "main-tube",
    );
    let end = curve(
        "branch-tube-end",
        3,
        kn.clone(),
        cps.clone(),
        None,
        "branch-tube",
    );
    let path = out.join("tube_saddle.json");
    write_json(
        &path,
        &document(
            vec![hole, end],
            vec![RawSurface::Nurbs(main), RawSurface::Nurbs(branch)],
        ),
    );
    let file = reload(&path);
    let (mut d_main, mut d_branch): (f64, f64) = (0.0, 0.0);
    for t in dense_params(&file.curves[0].curve, 32) {
        let p = file.curves[0].curve.point(t);
        d_main = d_main.max((p.y.hypot(p.z - MAIN_Z) - MAIN_R).abs());
        d_branch = d_branch.max((p.x.hypot(p.y) - BRANCH_R).abs());
    }
    report(
        &path,
        &file,
        d_main.max(d_branch),
        &format!(" (main tube {d_main:.1e}, branch tube {d_branch:.1e})"),
    );

    // The main tube as an STL: a hollow tube (wall 4 mm) closed by its two end rings, 200
    // facets around with their vertices on the exact circles. A facet's chord then lies at most
    // the sagitta R (1 - cos(pi / 200)) = 0.0074 mm inside the true surface.
    let k = 200;
    let ring = |r: f64, i: usize, x: f64| {
        let a = TAU * i as f64 / k as f64;
        Point3::new(x, r * a.sin(), MAIN_Z + r * a.cos())
    };
    let (ri, x0, x1) = (MAIN_R - 4.0, -MAIN_X, MAIN_X);
    let mut tris = Vec::new();
    for i in 0..k {
        let j = (i + 1) % k;
        let mid = TAU * (i as f64 + 0.5) / k as f64;
        let radial = Vector3::new(0.0, mid.sin(), mid.cos());
        for (r, normal) in [(MAIN_R, radial), (ri, -radial)] {
            let (a, b, c, d) = (
                ring(r, i, x0),
                ring(r, i, x1),
                ring(r, j, x1),
                ring(r, j, x0),
            );
            tris.push(facet(a, b, c, normal));
            tris.push(facet(a, c, d, normal));
        }
        for (x, normal) in [(x0, -Vector3::x()), (x1, Vector3::x())] {
            let (a, b, c, d) = (
                ring(MAIN_R, i, x),
                ring(MAIN_R, j, x),
                ring(ri, j, x),
                ring(ri, i, x),
            );
            tris.push(facet(a, b, c, normal));
            tris.push(facet(a, c, d, normal));
        }
    }
    write_stl(
        &out.join("tube_main.stl"),
        "kerf fixture tube_main.stl: R60 x 300 mm, wall 4, 200 facets around",
        &tris,
    );
    let stl = curve("main-tube-hole", 3, kn, cps, None, "main-tube-stl");
    let path = out.join("tube_saddle_stl.json");
    write_json(
        &path,
        &document(
            vec![stl],
            vec![RawSurface::Stl(RawStl {
                id: "main-tube-stl".into(),
                path: "tube_main.stl".into(),
                flip: false,
            })],
        ),
    );
    let file = reload(&path);
    let sagitta = MAIN_R * (1.0 - (PI / k as f64).cos());
    report(
        &path,
        &file,
        d_main,
        &format!(
            " (to the exact tube; {} facets, sagitta {sagitta:.4} mm)",
            tris.len()
        ),
    );
}

// ---------------------------------------------------------------------------------------------
// turbine_blade_edge.json
// ---------------------------------------------------------------------------------------------

fn turbine_blade_edge(out: &Path) {
    // The leading edge of a large blade, 3.5 m long: a rational quintic with 24 control points
    // on non-uniform knots. It bows in y, rises in z, and the blade twists from -12 to +26
    // degrees along it while its chord shrinks from 220 to 120 mm.
    let m = 24;
    let p = 5;
    let interior = m - p - 1;
    let mut kn = vec![0.0; p + 1];
    for j in 1..=interior {
        let f = j as f64 / (interior + 1) as f64;
        kn.push(r9(f + 0.012 * (TAU * f).sin()));
    }
    kn.extend(vec![1.0; p + 1]);
    let g = greville(&kn, m, p);
    let mut edge = Vec::with_capacity(m);
    let mut inner = Vec::with_capacity(m);
    let mut w = Vec::with_capacity(m);
    for (i, &s) in g.iter().enumerate() {
        let x = -1740.0 + 3480.0 * s;
        let y = -40.0 + 80.0 * s * s + 12.0 * (3.0 * PI * s).sin();
        let z = 60.0 + 150.0 * s * s;
        let twist = (-12.0 + 38.0 * s).to_radians();
        let chord = 220.0 - 100.0 * s;
        let e = [r9(x), r9(y), r9(z)];
        edge.push(e);
        inner.push([
            e[0],
            r9(e[1] + chord * twist.cos()),
            r9(e[2] + chord * twist.sin()),
        ]);
        w.push(r9(1.0 + 0.1 * (0.7 * i as f64).sin()));
    }
    // The blade near the edge: ruled (linear in v) from the edge (v = 0) to a line 120 to 220 mm
    // into the blade. The v = 0 row is the edge's control polygon with the edge's weights, so
    // the isoparametric curve S(u, 0) is the edge itself.
    let blade = RawNurbsSurface {
        id: "blade".into(),
        degree_u: p,
        degree_v: 1,
        knots_u: kn.clone(),
        knots_v: vec![0.0, 0.0, 1.0, 1.0],
        control_points: edge.iter().zip(&inner).map(|(a, b)| vec![*a, *b]).collect(),
        weights: Some(w.iter().map(|&w| vec![w, w]).collect()),
        flip: false,
    };
    let c = curve("blade-leading-edge", p, kn, edge, Some(w), "blade");
    let path = out.join("turbine_blade_edge.json");
    write_json(&path, &document(vec![c], vec![RawSurface::Nurbs(blade)]));
    let file = reload(&path);
    let kerf::format::SurfaceGeometry::Nurbs(s) = &file.surfaces[0].geometry else {
        unreachable!("a NURBS surface")
    };
    let mut worst: f64 = 0.0;
    for t in dense_params(&file.curves[0].curve, 32) {
        worst = worst.max((file.curves[0].curve.point(t) - s.point(t, 0.0)).norm());
    }
    report(&path, &file, worst, " (edge against S(u, 0))");
}

// ---------------------------------------------------------------------------------------------
// sheet_metal_holes.json, sheet_plate.stl
// ---------------------------------------------------------------------------------------------

const PLATE: (f64, f64, f64) = (250.0, 160.0, 3.0); // half length, half width, thickness

fn sheet_metal_holes(out: &Path) {
    // The blank: a 500 x 320 x 3 mm plate, its top face a 10 x 8 grid of squares (two facets
    // each), its four sides and bottom meeting the top at 90 degrees.
    let (hx, hy, t) = PLATE;
    let (nx, ny) = (10, 8);
    let v = |i: usize, j: usize, z: f64| {
        Point3::new(
            -hx + 2.0 * hx * i as f64 / nx as f64,
            -hy + 2.0 * hy * j as f64 / ny as f64,
            z,
        )
    };
    let mut tris = Vec::new();
    for i in 0..nx {
        for j in 0..ny {
            for (z, n) in [(t, Vector3::z()), (0.0, -Vector3::z())] {
                let (a, b, c, d) = (
                    v(i, j, z),
                    v(i + 1, j, z),
                    v(i + 1, j + 1, z),
                    v(i, j + 1, z),
                );
                tris.push(facet(a, b, c, n));
                tris.push(facet(a, c, d, n));
            }
        }
    }
    let mut side = |a: Point3<f64>, b: Point3<f64>, n: Vector3<f64>| {
        let (a1, b1) = (Point3::new(a.x, a.y, t), Point3::new(b.x, b.y, t));
        tris.push(facet(a, b, b1, n));
        tris.push(facet(a, b1, a1, n));
    };
    for i in 0..nx {
        side(v(i, 0, 0.0), v(i + 1, 0, 0.0), -Vector3::y());
        side(v(i, ny, 0.0), v(i + 1, ny, 0.0), Vector3::y());
    }
    for j in 0..ny {
        side(v(0, j, 0.0), v(0, j + 1, 0.0), -Vector3::x());
        side(v(nx, j, 0.0), v(nx, j + 1, 0.0), Vector3::x());
    }
    write_stl(
        &out.join("sheet_plate.stl"),
        "kerf fixture sheet_plate.stl: plate 500 x 320 x 3 mm",
        &tris,
    );

    // The part, cut from the top face (z = 3): holes first, the outline last.
    let outline = rounded_polygon(&[
        (-235.0, -145.0, 0.0),
        (245.0, -145.0, 0.0),
        (245.0, -45.0, 0.0),
        (230.0, -30.0, 0.0), // a 15 mm chamfer
        (40.0, -30.0, 15.0), // concave fillet
        (40.0, 145.0, 0.0),
        (-235.0, 145.0, 0.0),
        (-235.0, 40.0, 0.0), // a rectangular notch, 35 x 50
        (-200.0, 40.0, 0.0),
        (-200.0, -10.0, 0.0),
        (-235.0, -10.0, 0.0),
    ]);
    let parts: Vec<(&str, Vec<(Seg2, bool)>)> = vec![
        ("hole-d10-1", circle((-210.0, -120.0), 5.0)),
        ("hole-d10-2", circle((215.0, -120.0), 5.0)),
        ("hole-d10-3", circle((15.0, 120.0), 5.0)),
        ("hole-d10-4", circle((-210.0, 120.0), 5.0)),
        ("hole-d70", circle((-90.0, 60.0), 35.0)),
        ("slot-60x12", slot((120.0, -90.0), 60.0, 6.0, 0.0)),
        ("slot-40x10-tilted", slot((-110.0, -80.0), 40.0, 5.0, 30.0)),
        ("outline", outline),
    ];
    let cs = parts
        .iter()
        .map(|(id, segs)| {
            let (kn, cps, w) = exact_quadratic(segs, t);
            curve(id, 2, kn, cps, Some(w), "plate")
        })
        .collect();
    let surface = RawSurface::Stl(RawStl {
        id: "plate".into(),
        path: "sheet_plate.stl".into(),
        flip: false,
    });
    let path = out.join("sheet_metal_holes.json");
    write_json(&path, &document(cs, vec![surface]));
    let file = reload(&path);
    let mut worst: f64 = 0.0;
    for c in &file.curves {
        for s in dense_params(&c.curve, 16) {
            worst = worst.max((c.curve.point(s).z - t).abs());
        }
    }
    report(
        &path,
        &file,
        worst,
        &format!(" (to the top face; {} facets)", tris.len()),
    );
}

// ---------------------------------------------------------------------------------------------
// trim_panel.json: exact composition of a parameter-space curve into a bicubic panel
// ---------------------------------------------------------------------------------------------

/// Rounds to 1e-12 mm: the exact fixtures (`trim_panel`, `trim_creases`) keep their curves on
/// their surfaces within 1e-9 mm, which rounding to 1e-9 could not guarantee.
fn r12(x: f64) -> f64 {
    (x * 1e12).round() / 1e12 + 0.0
}

fn r12p(p: Point3<f64>) -> [f64; 3] {
    [r12(p.x), r12(p.y), r12(p.z)]
}

/// A clamped uniform knot vector of `spans` spans on [0, 1].
fn uniform_clamped(spans: usize, p: usize) -> Vec<f64> {
    let mut k = vec![0.0; p + 1];
    k.extend((1..spans).map(|i| i as f64 / spans as f64));
    k.extend(vec![1.0; p + 1]);
    k
}

/// The blossom of the B-spline (`degree`, `knots`, `ctrl`) restricted to knot span `span`, at
/// `args` (de Boor's algorithm with a different parameter at each level). With `args` all
/// equal it is the curve's point; with `a` and `b` the span's ends it gives its Bezier points.
fn blossom_bspline(
    degree: usize,
    knots: &[f64],
    ctrl: &[Vector3<f64>],
    span: usize,
    args: &[f64],
) -> Vector3<f64> {
    let p = degree;
    let mut d: Vec<Vector3<f64>> = (0..=p).map(|j| ctrl[span - p + j]).collect();
    for r in 1..=p {
        for j in (r..=p).rev() {
            let i = span - p + j;
            let alpha = (args[r - 1] - knots[i]) / (knots[i + p + 1 - r] - knots[i]);
            d[j] = d[j - 1] * (1.0 - alpha) + d[j] * alpha;
        }
    }
    d[p]
}

/// The blossom of a Bezier piece (control points `b` on the parameter interval `[a0, a1]`) at
/// `args` (de Casteljau with a different parameter at each level).
fn blossom_bezier(b: &[Vector3<f64>], a0: f64, a1: f64, args: &[f64]) -> Vector3<f64> {
    let mut d = b.to_vec();
    let n = b.len() - 1;
    for (r, &x) in args.iter().enumerate() {
        let s = (x - a0) / (a1 - a0);
        for j in 0..n - r {
            d[j] = d[j] * (1.0 - s) + d[j + 1] * s;
        }
    }
    d[0]
}

/// The product of two polynomials in Bernstein form on [0, 1].
fn bern_mul(a: &[f64], b: &[f64]) -> Vec<f64> {
    let (m, n) = (a.len() - 1, b.len() - 1);
    let c = |n: usize, k: usize| kerf::nurbs::binomial(n, k);
    let mut out = vec![0.0; m + n + 1];
    for i in 0..=m {
        for j in 0..=n {
            out[i + j] += c(m, i) * c(n, j) / c(m + n, i + j) * a[i] * b[j];
        }
    }
    out
}

/// `C(3, i) s^i (1 - s)^(3 - i)` for `i = 0..=3`, where `s` is a polynomial in Bernstein form.
fn cubic_basis_of(s: &[f64]) -> Vec<Vec<f64>> {
    let one_minus: Vec<f64> = s.iter().map(|x| 1.0 - x).collect();
    (0..=3)
        .map(|i| {
            let mut acc = vec![kerf::nurbs::binomial(3, i)];
            for _ in 0..i {
                acc = bern_mul(&acc, s);
            }
            for _ in i..3 {
                acc = bern_mul(&acc, &one_minus);
            }
            acc
        })
        .collect()
}

/// A bicubic (polynomial) B-spline surface as Bezier patches, for exact composition.
struct BicubicPatches {
    ku: Vec<f64>,
    kv: Vec<f64>,
    net: Vec<Vec<Vector3<f64>>>,
}

impl BicubicPatches {
    /// The span indices (as in `find_span`) of the patch holding `(u, v)`.
    fn spans(&self, u: f64, v: f64) -> (usize, usize) {
        (
            find_span(3, &self.ku, self.net.len(), u),
            find_span(3, &self.kv, self.net[0].len(), v),
        )
    }

    /// The 4 x 4 Bezier net of patch `(su, sv)`, by blossoming in u then v.
    fn bezier(&self, su: usize, sv: usize) -> [[Vector3<f64>; 4]; 4] {
        let (ua, ub) = (self.ku[su], self.ku[su + 1]);
        let (va, vb) = (self.kv[sv], self.kv[sv + 1]);
        let args = |a: f64, b: f64, k: usize| -> Vec<f64> {
            (0..3).map(|r| if r < 3 - k { a } else { b }).collect()
        };
        let cols = self.net[0].len();
        // Bezier in u for every v column.
        let rows: Vec<Vec<Vector3<f64>>> = (0..4)
            .map(|k| {
                (0..cols)
                    .map(|j| {
                        let col: Vec<Vector3<f64>> = self.net.iter().map(|r| r[j]).collect();
                        blossom_bspline(3, &self.ku, &col, su, &args(ua, ub, k))
                    })
                    .collect()
            })
            .collect();
        let mut out = [[Vector3::zeros(); 4]; 4];
        for (k, row) in rows.iter().enumerate() {
            for l in 0..4 {
                out[k][l] = blossom_bspline(3, &self.kv, row, sv, &args(va, vb, l));
            }
        }
        out
    }

    /// The exact degree-12 Bezier piece `S(q(s))` of the quadratic parameter-space Bezier `q`
    /// (lying inside patch `(su, sv)`).
    fn compose(&self, q: &[Vector2<f64>; 3], su: usize, sv: usize) -> Vec<Vector3<f64>> {
        let (ua, ub) = (self.ku[su], self.ku[su + 1]);
        let (va, vb) = (self.kv[sv], self.kv[sv + 1]);
        let s: Vec<f64> = q.iter().map(|p| (p.x - ua) / (ub - ua)).collect();
        let r: Vec<f64> = q.iter().map(|p| (p.y - va) / (vb - va)).collect();
        let (bu, bv) = (cubic_basis_of(&s), cubic_basis_of(&r));
        let net = self.bezier(su, sv);
        let mut out = vec![Vector3::zeros(); 13];
        for i in 0..4 {
            for j in 0..4 {
                let prod = bern_mul(&bu[i], &bv[j]);
                for (o, c) in out.iter_mut().zip(&prod) {
                    *o += net[i][j] * *c;
                }
            }
        }
        out
    }
}

/// Joins Bezier pieces (`(t0, t1, control points)`, all of one degree, consecutive) into one
/// clamped B-spline whose interior knot at each joint has multiplicity `degree - continuity`
/// (`continuity[k]` for the joint after piece `k`): each control point is the blossom of a
/// piece at its knots, which is exact where the pieces do join with that continuity.
fn join_bezier_pieces(
    pieces: &[(f64, f64, Vec<Vector3<f64>>)],
    continuity: &[usize],
) -> (Vec<f64>, Vec<Vector3<f64>>) {
    let d = pieces[0].2.len() - 1;
    let mut kn = vec![pieces[0].0; d + 1];
    for (k, piece) in pieces.iter().enumerate().skip(1) {
        kn.extend(vec![piece.0; d - continuity[k - 1]]);
    }
    kn.extend(vec![pieces[pieces.len() - 1].1; d + 1]);
    let n = kn.len() - d - 1;
    let cps = (0..n)
        .map(|i| {
            let args = &kn[i + 1..=i + d];
            // The piece that needs the least extrapolation: the most arguments inside it.
            let best = pieces
                .iter()
                .max_by_key(|(a, b, _)| args.iter().filter(|&&x| x >= *a && x <= *b).count())
                .expect("pieces");
            blossom_bezier(&best.2, best.0, best.1, args)
        })
        .collect();
    (kn, cps)
}

/// The stamped panel of `trim_panel.json`: a bicubic B-spline graph over
/// `[-300, 300] x [-200, 200]` (10 x 8 uniform spans, control x and y at the Greville
/// abscissae, so x(u) and y(v) are linear up to the 1e-9 rounding of the net), a shallow dome
/// with dents and humps sampled onto the net.
const TP_X: (f64, f64) = (-300.0, 600.0);
const TP_Y: (f64, f64) = (-200.0, 400.0);

/// Humps (positive) and dents (negative) of the panel: centre x, y, height mm, width (sigma) mm.
const TP_BUMPS: [(f64, f64, f64, f64); 6] = [
    (215.0, 10.0, 8.0, 45.0),
    (110.0, 125.0, -7.0, 45.0),
    (-110.0, 120.0, 8.0, 45.0),
    (-215.0, -10.0, -6.5, 45.0),
    (-100.0, -120.0, 7.5, 45.0),
    (110.0, -125.0, 7.0, 45.0),
];

fn tp_height(x: f64, y: f64) -> f64 {
    let mut z = 40.0 - x * x / (2.0 * 4500.0) - y * y / (2.0 * 4000.0) + 0.01 * x;
    for (bx, by, a, s) in TP_BUMPS {
        z += a * (-((x - bx).powi(2) + (y - by).powi(2)) / (2.0 * s * s)).exp();
    }
    z
}

fn tp_surface() -> (NurbsSurface, RawNurbsSurface, BicubicPatches) {
    let (ku, kv) = (uniform_clamped(10, 3), uniform_clamped(8, 3));
    let (gu, gv) = (greville(&ku, 13, 3), greville(&kv, 11, 3));
    let cps: Vec<Vec<[f64; 3]>> = gu
        .iter()
        .map(|&u| {
            gv.iter()
                .map(|&v| {
                    let (x, y) = (TP_X.0 + TP_X.1 * u, TP_Y.0 + TP_Y.1 * v);
                    [r9(x) + 0.0, r9(y) + 0.0, r9(tp_height(x, y))]
                })
                .collect()
        })
        .collect();
    let pts: Vec<Vec<Point3<f64>>> = cps
        .iter()
        .map(|r| r.iter().map(|p| Point3::from(*p)).collect())
        .collect();
    let patches = BicubicPatches {
        ku: ku.clone(),
        kv: kv.clone(),
        net: pts
            .iter()
            .map(|r| r.iter().map(|p| p.coords).collect())
            .collect(),
    };
    (
        NurbsSurface::new(3, 3, ku.clone(), kv.clone(), pts, None),
        RawNurbsSurface {
            id: "stamped-panel".into(),
            degree_u: 3,
            degree_v: 3,
            knots_u: ku,
            knots_v: kv,
            control_points: cps,
            weights: None,
            flip: false,
        },
        patches,
    )
}

fn tp_uv(p: Point2<f64>) -> Vector2<f64> {
    Vector2::new((p.x - TP_X.0) / TP_X.1, (p.y - TP_Y.0) / TP_Y.1)
}

/// The angle between the panel's normal at plan point `p` and the vertical, degrees.
fn tp_tilt(s: &NurbsSurface, p: Point2<f64>) -> f64 {
    let uv = tp_uv(p);
    let (_, su, sv) = s.eval_d1(uv.x, uv.y);
    let n = su.cross(&sv);
    n.xy().norm().atan2(n.z).to_degrees()
}

/// The points where the panel's normal is vertical (`z_u = z_v = 0`), in plan: local minima
/// of the tilt on a 4 mm grid, refined by Newton's method.
fn tp_critical_points(s: &NurbsSurface) -> Vec<(Point2<f64>, f64)> {
    let step = 4.0;
    let (nx, ny) = (146, 96);
    let at = |i: usize, j: usize| Point2::new(-292.0 + step * i as f64, -192.0 + step * j as f64);
    let grid: Vec<Vec<f64>> = (0..=nx)
        .map(|i| (0..=ny).map(|j| tp_tilt(s, at(i, j))).collect())
        .collect();
    let mut out: Vec<(Point2<f64>, f64)> = Vec::new();
    for i in 1..nx {
        for j in 1..ny {
            let t = grid[i][j];
            let lower = (0..9).all(|k| {
                let (a, b) = (i + k / 3 - 1, j + k % 3 - 1);
                (a, b) == (i, j) || grid[a][b] > t
            });
            if !lower || t > 1.0 {
                continue;
            }
            let mut uv = tp_uv(at(i, j));
            for _ in 0..30 {
                let d = s.derivatives(uv.x, uv.y);
                let g = Vector2::new(d[1][0].z, d[0][1].z);
                let h = nalgebra::Matrix2::new(d[2][0].z, d[1][1].z, d[1][1].z, d[0][2].z);
                uv -= h.lu().solve(&g).expect("regular critical point");
            }
            let p = Point2::new(TP_X.0 + TP_X.1 * uv.x, TP_Y.0 + TP_Y.1 * uv.y);
            let d = s.derivatives(uv.x, uv.y);
            let det = d[2][0].z * d[0][2].z - d[1][1].z * d[1][1].z;
            let kind = if det < 0.0 {
                0.0
            } else if d[2][0].z < 0.0 {
                1.0
            } else {
                -1.0
            };
            if !out.iter().any(|(q, _)| (q - p).norm() < 1.0) {
                out.push((p, kind));
            }
        }
    }
    out
}

/// A quadratic Bezier in the plane at `s`.
fn quad_at(q: &[Point2<f64>; 3], s: f64) -> Point2<f64> {
    let m = 1.0 - s;
    Point2::from(q[0].coords * (m * m) + q[1].coords * (2.0 * m * s) + q[2].coords * (s * s))
}

/// The pieces of the closed uniform quadratic B-spline with control polygon `q`: piece `i` is
/// the Bezier `[mid(q[i-1], q[i]), q[i], mid(q[i], q[i+1])]`; consecutive pieces join C1.
fn closed_quadratic_pieces(q: &[Point2<f64>]) -> Vec<[Point2<f64>; 3]> {
    let n = q.len();
    (0..n)
        .map(|i| {
            let (a, b, c) = (q[(i + n - 1) % n], q[i], q[(i + 1) % n]);
            [nalgebra::center(&a, &b), b, nalgebra::center(&b, &c)]
        })
        .collect()
}

/// The control polygon of the trim line: around each pass point `p[k]` two control points
/// `p[k] -+ a[k] e[k]`, so that the curve runs through `p[k]` along `e[k]`.
fn tp_polygon(p: &[Point2<f64>], e: &[Vector2<f64>], a: &[f64]) -> Vec<Point2<f64>> {
    (0..p.len())
        .flat_map(|k| [p[k] - e[k] * a[k], p[k] + e[k] * a[k]])
        .collect()
}

/// The smallest tilt on the two pieces that meet at pass point `k`, degrees.
fn tp_pass_tilt(s: &NurbsSurface, pieces: &[[Point2<f64>; 3]], k: usize) -> f64 {
    let mut best = f64::INFINITY;
    for (h, piece) in pieces[2 * k..2 * k + 2].iter().enumerate() {
        for i in 0..=200 {
            let f = 0.5 * (1.0 - h as f64 + i as f64 / 200.0);
            best = best.min(tp_tilt(s, quad_at(piece, f)));
        }
    }
    best
}

/// Where the quadratic Bezier `f(s)` (scalar control values `c`) crosses `level` in (0, 1):
/// sign changes on a fine grid, refined by bisection.
fn quad_crossings(c: [f64; 3], level: f64) -> Vec<f64> {
    let f = |s: f64| {
        let m = 1.0 - s;
        c[0] * m * m + c[1] * 2.0 * m * s + c[2] * s * s - level
    };
    let n = 64;
    let mut out = Vec::new();
    for i in 0..n {
        let (mut a, mut b) = (i as f64 / n as f64, (i + 1) as f64 / n as f64);
        if f(a) == 0.0 && i > 0 {
            out.push(a);
            continue;
        }
        if (f(a) < 0.0) == (f(b) < 0.0) {
            continue;
        }
        for _ in 0..200 {
            let m = 0.5 * (a + b);
            if m <= a || m >= b {
                break;
            }
            if (f(a) < 0.0) == (f(m) < 0.0) {
                a = m;
            } else {
                b = m;
            }
        }
        out.push(0.5 * (a + b));
    }
    out
}

fn trim_panel(out: &Path) {
    let (surface, raw, patches) = tp_surface();
    let crit = tp_critical_points(&surface);
    // The trim line runs past six of the panel's points of vertical normal (hump tops, the
    // bottom of a dent, a saddle), each at the offset (at most 30 mm) that makes its smallest
    // tilt near there the target in degrees where the panel allows it, and through one via
    // point (no target) over a dent. The points are found on the surface, then matched here.
    let passes: [((f64, f64), Option<f64>); 7] = [
        ((190.0, 2.0), Some(0.5)),
        ((124.0, 153.0), Some(1.0)),
        ((-91.0, 103.0), Some(3.0)),
        ((-205.0, -5.0), None),
        ((-75.0, -102.0), Some(0.7)),
        ((105.0, -103.0), Some(2.0)),
        ((140.0, -43.0), Some(4.0)),
    ];
    let n = passes.len();
    let c: Vec<Point2<f64>> = passes
        .iter()
        .map(|&((x, y), target)| {
            let want = Point2::new(x, y);
            if target.is_none() {
                return want;
            }
            let (p, _) = crit
                .iter()
                .min_by(|a, b| (a.0 - want).norm().total_cmp(&(b.0 - want).norm()))
                .expect("critical points");
            assert!(
                (p - want).norm() < 10.0,
                "no critical point near ({x}, {y})"
            );
            *p
        })
        .collect();
    let e: Vec<Vector2<f64>> = (0..n)
        .map(|k| (c[(k + 1) % n] - c[(k + n - 1) % n]).normalize())
        .collect();
    let a: Vec<f64> = (0..n)
        .map(|k| {
            0.3 * (c[(k + 1) % n] - c[k])
                .norm()
                .min((c[k] - c[(k + n - 1) % n]).norm())
        })
        .collect();
    // Offsets to the left of the direction, by bisection, in a few Gauss-Seidel sweeps (each
    // pass point's pieces also depend on its neighbours').
    let mut d = vec![0.0; n];
    for _ in 0..4 {
        for k in 0..n {
            let Some(target) = passes[k].1 else { continue };
            let (mut lo, mut hi) = (0.0, 30.0);
            for _ in 0..60 {
                let mid = 0.5 * (lo + hi);
                d[k] = mid;
                let p: Vec<Point2<f64>> = (0..n)
                    .map(|j| c[j] + Vector2::new(-e[j].y, e[j].x) * d[j])
                    .collect();
                let pieces = closed_quadratic_pieces(&tp_polygon(&p, &e, &a));
                if tp_pass_tilt(&surface, &pieces, k) < target {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            d[k] = 0.5 * (lo + hi);
        }
    }
    let p: Vec<Point2<f64>> = (0..n)
        .map(|j| c[j] + Vector2::new(-e[j].y, e[j].x) * d[j])
        .collect();
    let plan = closed_quadratic_pieces(&tp_polygon(&p, &e, &a));
    // In parameter space (the plan mapped by the nominal linear x(u), y(v): still quadratic),
    // split where the pieces cross the panel's knot lines, each part composed exactly.
    let m = plan.len();
    let mut pieces: Vec<(f64, f64, Vec<Vector3<f64>>)> = Vec::new();
    let mut continuity = Vec::new();
    let uv_plan: Vec<[Vector2<f64>; 3]> = plan.iter().map(|q| q.map(tp_uv)).collect();
    for (i, q) in uv_plan.iter().enumerate() {
        let mut cuts: Vec<f64> = Vec::new();
        for (axis, knots) in [(0, &patches.ku), (1, &patches.kv)] {
            for &k in &knots[4..knots.len() - 4] {
                cuts.extend(quad_crossings([q[0][axis], q[1][axis], q[2][axis]], k));
            }
        }
        cuts.sort_by(f64::total_cmp);
        let mut bounds = vec![0.0];
        bounds.extend(cuts);
        bounds.push(1.0);
        for w in bounds.windows(2) {
            let (s0, s1) = (w[0], w[1]);
            assert!(s1 - s0 > 1e-6, "a crossing at a joint");
            // The sub-piece by blossoming: q(s0, s0), q(s0, s1), q(s1, s1).
            let bl = |x: f64, y: f64| {
                q[0] * ((1.0 - x) * (1.0 - y))
                    + q[1] * ((1.0 - x) * y + x * (1.0 - y))
                    + q[2] * (x * y)
            };
            let sub = [bl(s0, s0), bl(s0, s1), bl(s1, s1)];
            let mid = bl(0.5 * (s0 + s1), 0.5 * (s0 + s1));
            let (su, sv) = patches.spans(mid.x, mid.y);
            let t0 = (i as f64 + s0) / m as f64;
            let t1 = (i as f64 + s1) / m as f64;
            if !pieces.is_empty() {
                continuity.push(if s0 == 0.0 { 1 } else { 2 });
            }
            pieces.push((t0, t1, patches.compose(&sub, su, sv)));
        }
    }
    let (kn, cps) = join_bezier_pieces(&pieces, &continuity);
    let mut cps: Vec<[f64; 3]> = cps.into_iter().map(|v| r12p(Point3::from(v))).collect();
    let last = cps.len() - 1;
    cps[last] = cps[0];
    let line = curve("trim-line", 12, kn, cps, None, "stamped-panel");
    let path = out.join("trim_panel.json");
    write_json(&path, &document(vec![line], vec![RawSurface::Nurbs(raw)]));
    let file = reload(&path);
    let written = &file.curves[0].curve;
    // The written curve against S(u(t), v(t)), and the tilt along it.
    let mut worst: f64 = 0.0;
    let samples = 20000;
    let mut tilts = Vec::with_capacity(samples + 1);
    for k in 0..=samples {
        let t = k as f64 / samples as f64;
        let i = ((t * m as f64) as usize).min(m - 1);
        let s = t * m as f64 - i as f64;
        let uv = quad_at(&plan[i].map(|p| Point2::from(tp_uv(p))), s);
        worst = worst.max((written.point(t) - surface.point(uv.x, uv.y)).norm());
        tilts.push(tp_tilt(&surface, quad_at(&plan[i], s)));
    }
    let minima: Vec<f64> = (0..samples)
        .filter(|&k| {
            let prev = tilts[(k + samples - 1) % samples];
            tilts[k] < prev && tilts[k] <= tilts[k + 1] && tilts[k] < 5.0
        })
        .map(|k| tilts[k])
        .collect();
    let mut at = Vec::new();
    for k in 0..samples {
        let prev = tilts[(k + samples - 1) % samples];
        if tilts[k] < prev && tilts[k] <= tilts[k + 1] && tilts[k] < 5.0 {
            let pt = written.point(k as f64 / samples as f64);
            at.push(format!("{:.2} at ({:.0}, {:.0})", tilts[k], pt.x, pt.y));
        }
    }
    let max_tilt = tilts.iter().copied().fold(0.0, f64::max);
    let mut slope: f64 = 0.0;
    for i in 0..=300 {
        for j in 0..=200 {
            let q = Point2::new(-300.0 + 2.0 * i as f64, -200.0 + 2.0 * j as f64);
            slope = slope.max(tp_tilt(&surface, q));
        }
    }
    report(
        &path,
        &file,
        worst,
        &format!(
            " (against S(u(t), v(t)); {} pieces; panel slope up to {slope:.2} deg, along the \
             line {:.2} to {max_tilt:.2} deg, {} local minima of the tilt: {})",
            pieces.len(),
            tilts.iter().copied().fold(90.0, f64::min),
            minima.len(),
            minima
                .iter()
                .map(|t| format!("{t:.2}"))
                .collect::<Vec<_>>()
                .join(", ")
        ),
    );
    assert!(worst <= 1e-9, "trim_panel: {worst:e} mm off the panel");
    println!("  tilt minima, deg: {}", at.join(", "));
    println!("  pass offsets, mm: {d:.3?}");
}

// ---------------------------------------------------------------------------------------------
// trim_creases.json: a trim line over folded faces, a bend and a vertical flange
// ---------------------------------------------------------------------------------------------

/// One face of the folded panel, in its flat pattern: `s` runs across the folds, `y` along
/// them. A flat face starts at profile point `p` (x, z) with direction angle `phi`; the bend
/// turns counter-clockwise (concave up) about centre `p` with radius `r` from angle `phi`.
#[derive(Debug, Clone, Copy)]
enum FoldFace {
    Flat {
        s0: f64,
        s1: f64,
        p: Vector2<f64>,
        phi: f64,
    },
    Bend {
        s0: f64,
        s1: f64,
        c: Vector2<f64>,
        r: f64,
        phi: f64,
    },
}

const FOLD_Y: (f64, f64) = (-120.0, 120.0);

impl FoldFace {
    fn range(&self) -> (f64, f64) {
        match *self {
            FoldFace::Flat { s0, s1, .. } | FoldFace::Bend { s0, s1, .. } => (s0, s1),
        }
    }

    /// The profile point (x, z) at `s` (extended beyond the face by its own formula).
    fn profile(&self, s: f64) -> Vector2<f64> {
        match *self {
            FoldFace::Flat { s0, p, phi, .. } => p + Vector2::new(phi.cos(), phi.sin()) * (s - s0),
            FoldFace::Bend { s0, c, r, phi, .. } => {
                let a = phi + (s - s0) / r;
                c + Vector2::new(a.sin(), -a.cos()) * r
            }
        }
    }

    fn at(&self, s: f64, y: f64) -> Point3<f64> {
        let q = self.profile(s);
        Point3::new(q.x, y, q.y)
    }

    /// The outward (upper) unit normal at `s`.
    fn normal(&self, s: f64) -> Vector3<f64> {
        let a = match *self {
            FoldFace::Flat { phi, .. } => phi,
            FoldFace::Bend { s0, r, phi, .. } => phi + (s - s0) / r,
        };
        Vector3::new(-a.sin(), 0.0, a.cos())
    }

    /// The face as a NURBS surface: u across (s), v along y; `Su x Sv` is the upper normal.
    fn raw(&self, id: &str) -> RawNurbsSurface {
        let (s0, s1) = self.range();
        let row = |p: Point3<f64>| {
            vec![
                r12p(Point3::new(p.x, FOLD_Y.0, p.z)),
                r12p(Point3::new(p.x, FOLD_Y.1, p.z)),
            ]
        };
        let (degree_u, control_points, weights) = match *self {
            FoldFace::Flat { .. } => (1, vec![row(self.at(s0, 0.0)), row(self.at(s1, 0.0))], None),
            FoldFace::Bend { c, r, phi, .. } => {
                let half = 0.5 * (s1 - s0) / r;
                let m =
                    c + Vector2::new((phi + half).sin(), -(phi + half).cos()) * (r / half.cos());
                let w = half.cos();
                (
                    2,
                    vec![
                        row(self.at(s0, 0.0)),
                        row(Point3::new(m.x, 0.0, m.y)),
                        row(self.at(s1, 0.0)),
                    ],
                    Some(vec![vec![1.0, 1.0], vec![w, w], vec![1.0, 1.0]]),
                )
            }
        };
        let mut knots_u = vec![0.0; degree_u + 1];
        knots_u.extend(vec![1.0; degree_u + 1]);
        RawNurbsSurface {
            id: id.into(),
            degree_u,
            degree_v: 1,
            knots_u,
            knots_v: vec![0.0, 0.0, 1.0, 1.0],
            control_points,
            weights,
            flip: false,
        }
    }

    /// The distance of `p` from the face's surface (plane or cylinder), mm.
    fn distance(&self, p: &Point3<f64>) -> f64 {
        match *self {
            FoldFace::Flat { s0, .. } => (p - self.at(s0, p.y)).dot(&self.normal(s0)).abs(),
            FoldFace::Bend { c, r, .. } => ((Vector2::new(p.x, p.z) - c).norm() - r).abs(),
        }
    }
}

/// The folded panel: four flat faces rising at 20, 10, -15 and 25 degrees (creases of 10, 25
/// and 40 degrees), a bend of radius 10 up to the vertical, and a 50 mm flange.
fn fold_faces() -> Vec<(&'static str, FoldFace)> {
    let mut out = Vec::new();
    let mut p = Vector2::new(-200.0, 10.0);
    let mut s = 0.0;
    for (id, deg, len) in [
        ("face-1", 20.0f64, 120.0),
        ("face-2", 10.0, 100.0),
        ("face-3", -15.0, 110.0),
        ("face-4", 25.0, 90.0),
    ] {
        let f = FoldFace::Flat {
            s0: s,
            s1: s + len,
            p,
            phi: deg.to_radians(),
        };
        p = f.profile(s + len);
        s += len;
        out.push((id, f));
    }
    let (phi, r) = (25f64.to_radians(), 10.0);
    let sweep = 90f64.to_radians() - phi;
    let bend = FoldFace::Bend {
        s0: s,
        s1: s + r * sweep,
        c: p + Vector2::new(-phi.sin(), phi.cos()) * r,
        r,
        phi,
    };
    s += r * sweep;
    p = bend.profile(s);
    out.push(("bend", bend));
    out.push((
        "flange",
        FoldFace::Flat {
            s0: s,
            s1: s + 50.0,
            p,
            phi: 90f64.to_radians(),
        },
    ));
    out
}

fn trim_creases(out: &Path) {
    let faces = fold_faces();
    let s_wall = faces[5].1.range().0;
    let face_of = |s: f64| {
        faces
            .iter()
            .position(|(_, f)| f.range().0 <= s && s <= f.range().1)
            .expect("on the panel")
    };
    // The trim line in the flat pattern, counter-clockwise: along y = -90 over every crease,
    // the bend and 35 mm up the flange, along the flange, back down over the bend at y = 70,
    // then obliquely (about 10 degrees to the s direction) over the three creases, and down
    // on face 1. Fillets stay inside one face.
    let outline = rounded_polygon(&[
        (20.0, -90.0, 15.0),
        (s_wall + 35.0, -90.0, 8.0),
        (s_wall + 35.0, 70.0, 8.0),
        (370.0, 70.0, 15.0),
        (20.0, 10.0, 15.0),
    ]);
    // Rational quadratic Bezier pieces in 3D, each with its face: (P0, P1, P2, w1, length, face).
    type Piece = (Point3<f64>, Point3<f64>, Point3<f64>, f64, f64, usize);
    let mut pieces: Vec<Piece> = Vec::new();
    let bounds: Vec<f64> = faces.iter().map(|(_, f)| f.range().1).collect();
    for (seg, _) in &outline {
        match *seg {
            Seg2::Line(a, b) => {
                let mut cuts = vec![0.0, 1.0];
                for &sb in &bounds[..bounds.len() - 1] {
                    let f = (sb - a.x) / (b.x - a.x);
                    if f > 1e-9 && f < 1.0 - 1e-9 {
                        cuts.push(f);
                    }
                }
                cuts.sort_by(f64::total_cmp);
                for w in cuts.windows(2) {
                    let (p, q) = (a + (b - a) * w[0], a + (b - a) * w[1]);
                    let k = face_of(0.5 * (p.x + q.x));
                    let face = faces[k].1;
                    match face {
                        FoldFace::Flat { .. } => {
                            let (p3, q3) = (face.at(p.x, p.y), face.at(q.x, q.y));
                            pieces.push((
                                p3,
                                nalgebra::center(&p3, &q3),
                                q3,
                                1.0,
                                (q3 - p3).norm(),
                                k,
                            ));
                        }
                        FoldFace::Bend { c, r, phi, s0, .. } => {
                            assert!(p.y == q.y, "the line crosses the bend square");
                            let (ap, aq) = (phi + (p.x - s0) / r, phi + (q.x - s0) / r);
                            let half = 0.5 * (aq - ap);
                            let am = 0.5 * (ap + aq);
                            let m = c + Vector2::new(am.sin(), -am.cos()) * (r / half.cos());
                            pieces.push((
                                face.at(p.x, p.y),
                                Point3::new(m.x, p.y, m.y),
                                face.at(q.x, q.y),
                                half.cos(),
                                r * (aq - ap).abs(),
                                k,
                            ));
                        }
                    }
                }
            }
            Seg2::Arc(c, r, a0, sweep) => {
                let k = face_of(c.x);
                let face = faces[k].1;
                let (lo, hi) = face.range();
                assert!(
                    c.x - r >= lo && c.x + r <= hi && matches!(face, FoldFace::Flat { .. }),
                    "a fillet inside one flat face"
                );
                let parts = (sweep.abs() / (0.5 * PI) - 1e-9).ceil() as usize;
                let d = sweep / parts as f64;
                for m in 0..parts {
                    let (b0, b1) = (a0 + d * m as f64, a0 + d * (m + 1) as f64);
                    let mid = c + dir(0.5 * (b0 + b1)) * (r / (0.5 * d).cos());
                    let (p0, p2) = (c + dir(b0) * r, c + dir(b1) * r);
                    pieces.push((
                        face.at(p0.x, p0.y),
                        face.at(mid.x, mid.y),
                        face.at(p2.x, p2.y),
                        (0.5 * d).cos(),
                        r * d.abs(),
                        k,
                    ));
                }
            }
        }
    }
    let total: f64 = pieces.iter().map(|p| p.4).sum();
    let mut kn = vec![0.0; 3];
    let mut cps = Vec::new();
    let mut w = Vec::new();
    let mut acc = 0.0;
    for (i, piece) in pieces.iter().enumerate() {
        if i > 0 {
            acc += pieces[i - 1].4;
            let k = r9(acc / total);
            kn.extend([k, k]);
        }
        cps.extend([r12p(piece.0), r12p(piece.1)]);
        w.extend([1.0, piece.3]);
    }
    cps.push(cps[0]);
    w.push(1.0);
    kn.extend([1.0; 3]);
    let ids: Vec<String> = faces.iter().map(|(id, _)| (*id).to_string()).collect();
    let line = RawCurve::new("trim-over-creases", 2, kn, cps)
        .with_weights(Some(w))
        .with_surface(Some(curves::SurfaceRef::Many(ids)));
    let surfaces = faces
        .iter()
        .map(|(id, f)| RawSurface::Nurbs(f.raw(id)))
        .collect();
    let path = out.join("trim_creases.json");
    write_json(&path, &document(vec![line], surfaces));
    let file = reload(&path);
    let written = &file.curves[0].curve;
    // Every piece against its own face, and the tilt along the line.
    let spans = written.spans();
    assert_eq!(spans.len(), pieces.len(), "one span per piece");
    let (mut worst, mut max_tilt): (f64, f64) = (0.0, 0.0);
    for ((_, a, b), piece) in spans.iter().zip(&pieces) {
        let face = faces[piece.5].1;
        for k in 0..=64 {
            let p = written.point(a + (b - a) * k as f64 / 64.0);
            worst = worst.max(face.distance(&p));
            let s = match face {
                FoldFace::Flat { .. } => face.range().0,
                FoldFace::Bend { c, r, phi, s0, .. } => {
                    let v = Vector2::new(p.x, p.z) - c;
                    s0 + r * (v.x.atan2(-v.y) - phi)
                }
            };
            max_tilt = max_tilt.max(face.normal(s).z.clamp(-1.0, 1.0).acos().to_degrees());
        }
    }
    // Crease angles (between neighbouring flat faces' normals) and the line's turn there.
    let creases: Vec<String> = (0..3)
        .map(|k| {
            let (f, g) = (faces[k].1, faces[k + 1].1);
            let a = f.normal(0.0).angle(&g.normal(0.0)).to_degrees();
            format!("{a:.1}")
        })
        .collect();
    let mut turns = Vec::new();
    for pair in pieces.windows(2) {
        if pair[0].5 != pair[1].5 && pair[0].5 < 4 && pair[1].5 < 4 {
            let t_in = (pair[0].2 - pair[0].1).normalize();
            let t_out = (pair[1].1 - pair[1].0).normalize();
            turns.push(format!("{:.1}", t_in.angle(&t_out).to_degrees()));
        }
    }
    report(
        &path,
        &file,
        worst,
        &format!(
            " (each piece to its face; {} pieces; creases {} deg; the line turns {} deg at \
             them; tilt up to {max_tilt:.1} deg)",
            pieces.len(),
            creases.join(", "),
            turns.join(", ")
        ),
    );
    assert!(worst <= 1e-9, "trim_creases: {worst:e} mm off a face");
}
