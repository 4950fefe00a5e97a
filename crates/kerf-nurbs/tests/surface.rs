//! Random NURBS surfaces against independent truth: partial derivatives against central finite
//! differences (Richardson-extrapolated), closest points against dense brute-force sampling
//! refined by a pattern search, warm starts against cold ones, and evaluation without heap
//! allocation.

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

use kerf_nurbs::NurbsSurface;
use nalgebra::{Point3, Vector3};
use proptest::prelude::*;

/// Counts the heap allocations of the current thread.
struct Counting;

thread_local! {
    static ALLOCATIONS: Cell<usize> = const { Cell::new(0) };
}

fn count() {
    let _ = ALLOCATIONS.try_with(|c| c.set(c.get() + 1));
}

// SAFETY: forwards every call to the system allocator unchanged.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        count();
        // SAFETY: same contract as the caller's.
        unsafe { System.alloc(layout) }
    }

    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        count();
        // SAFETY: same contract as the caller's.
        unsafe { System.alloc_zeroed(layout) }
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        count();
        // SAFETY: same contract as the caller's.
        unsafe { System.realloc(ptr, layout, new_size) }
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: same contract as the caller's.
        unsafe { System.dealloc(ptr, layout) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

fn allocations() -> usize {
    ALLOCATIONS.with(Cell::get)
}

/// SplitMix64: a small deterministic generator for building random surfaces from a seed.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^= z >> 31;
        (z >> 11) as f64 / (1u64 << 53) as f64
    }

    fn range(&mut self, a: f64, b: f64) -> f64 {
        a + (b - a) * self.next()
    }

    fn below(&mut self, n: usize) -> usize {
        ((self.next() * n as f64) as usize).min(n - 1)
    }
}

/// A random knot vector for `n` control points: clamped (with repeated interior knots) or
/// unclamped, over a random parameter range.
fn random_knots(rng: &mut Rng, degree: usize, n: usize) -> Vec<f64> {
    let len = n + degree + 1;
    let mut knots = Vec::with_capacity(len);
    let start = rng.range(-3.0, 3.0);
    if rng.next() < 0.7 {
        knots.extend(std::iter::repeat_n(start, degree + 1));
        let mut x = start;
        let mut run = 0;
        for _ in 0..(n - degree - 1) {
            if run == 0 || run >= degree || rng.next() < 0.7 {
                x += rng.range(0.05, 1.0);
                run = 0;
            }
            run += 1;
            knots.push(x);
        }
        let end = x + rng.range(0.05, 1.0);
        knots.extend(std::iter::repeat_n(end, degree + 1));
    } else {
        // Runs of up to degree + 1 equal knots: the surface may jump at an interior one.
        let mut x = start;
        let mut run = 0;
        for _ in 0..len {
            knots.push(x);
            run += 1;
            if run > degree || rng.next() < 0.8 {
                x += rng.range(0.05, 1.0);
                run = 0;
            }
        }
    }
    knots
}

/// A random surface: degrees 1..=5, up to 3 extra control points per direction, points in
/// `[-1, 1]^3`, log-uniform weights in `[0.05, 20]` (or none). `None` if the random knots
/// happen to be invalid (an over-repeated knot in an unclamped vector).
fn random_surface(seed: u64) -> Option<NurbsSurface> {
    let mut rng = Rng(seed);
    let (p, q) = (1 + rng.below(5), 1 + rng.below(5));
    let (nu, nv) = (p + 1 + rng.below(4), q + 1 + rng.below(4));
    let ku = random_knots(&mut rng, p, nu);
    let kv = random_knots(&mut rng, q, nv);
    let mut pts = Vec::with_capacity(nu);
    for _ in 0..nu {
        pts.push(
            (0..nv)
                .map(|_| {
                    Point3::new(
                        rng.range(-1.0, 1.0),
                        rng.range(-1.0, 1.0),
                        rng.range(-1.0, 1.0),
                    )
                })
                .collect(),
        );
    }
    let weights = (rng.next() < 0.7).then(|| {
        (0..nu)
            .map(|_| {
                (0..nv)
                    .map(|_| rng.range(0.05f64.ln(), 20f64.ln()).exp())
                    .collect()
            })
            .collect()
    });
    NurbsSurface::try_new(p, q, ku, kv, pts, weights).ok()
}

/// True if the surface jumps somewhere: an interior knot of multiplicity `degree + 1`.
fn has_jumps(s: &NurbsSurface) -> bool {
    let jumps = |degree: usize, knots: &[f64], (a, b): (f64, f64)| {
        knots
            .iter()
            .any(|&k| k > a && k < b && knots.iter().filter(|&&x| x == k).count() > degree)
    };
    jumps(s.degree_u(), s.knots_u(), s.domain_u()) || jumps(s.degree_v(), s.knots_v(), s.domain_v())
}

/// The span `(start, end)` of `spans` that holds `t`.
fn span_of(spans: &[(usize, f64, f64)], t: f64) -> (f64, f64) {
    spans
        .iter()
        .find(|s| t >= s.1 && t < s.2)
        .map_or((spans[0].1, spans[0].2), |s| (s.1, s.2))
}

/// Central difference of `f` at `t` with step `h`, extrapolated (Richardson) from steps `h`
/// and `h / 2`; also returns the difference of the two plain estimates (an error scale).
fn central(f: impl Fn(f64) -> Vector3<f64>, t: f64, h: f64) -> (Vector3<f64>, f64) {
    let d = |h: f64| (f(t + h) - f(t - h)) / (2.0 * h);
    let (d1, d2) = (d(h), d(0.5 * h));
    ((4.0 * d2 - d1) / 3.0, (d1 - d2).norm())
}

/// Brute force: the best of a `n x n` grid of samples, refined by a pattern search (8
/// neighbours, step halved when none is better).
fn brute_force(s: &NurbsSurface, p: &Point3<f64>, n: usize) -> f64 {
    let (ua, ub) = s.domain_u();
    let (va, vb) = s.domain_v();
    let dist = |u: f64, v: f64| (s.point(u.clamp(ua, ub), v.clamp(va, vb)) - p).norm();
    let mut best = (f64::INFINITY, ua, va);
    for i in 0..=n {
        for j in 0..=n {
            let u = ua + (ub - ua) * (i as f64 / n as f64);
            let v = va + (vb - va) * (j as f64 / n as f64);
            let d = dist(u, v);
            if d < best.0 {
                best = (d, u, v);
            }
        }
    }
    let (mut hu, mut hv) = ((ub - ua) / n as f64, (vb - va) / n as f64);
    while hu > 1e-14 * (ub - ua) {
        let mut moved = false;
        for (du, dv) in [
            (1.0, 0.0),
            (-1.0, 0.0),
            (0.0, 1.0),
            (0.0, -1.0),
            (1.0, 1.0),
            (1.0, -1.0),
            (-1.0, 1.0),
            (-1.0, -1.0),
        ] {
            let (u, v) = (
                (best.1 + du * hu).clamp(ua, ub),
                (best.2 + dv * hv).clamp(va, vb),
            );
            let d = dist(u, v);
            if d < best.0 {
                best = (d, u, v);
                moved = true;
            }
        }
        if !moved {
            hu *= 0.5;
            hv *= 0.5;
        }
    }
    best.0
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    #[test]
    fn derivatives_match_finite_differences(
        seed in any::<u64>(),
        x in 0.1f64..0.9,
        y in 0.1f64..0.9,
        su in any::<prop::sample::Index>(),
        sv in any::<prop::sample::Index>(),
    ) {
        let s = random_surface(seed);
        prop_assume!(s.is_some());
        let s = s.expect("assumed");
        // A point well inside a knot-span cell, so that the differences do not cross a knot.
        let spans_u = s.spans_u();
        let spans_v = s.spans_v();
        let (u0, u1) = { let c = spans_u[su.index(spans_u.len())]; (c.1, c.2) };
        let (v0, v1) = { let c = spans_v[sv.index(spans_v.len())]; (c.1, c.2) };
        let (u, v) = (u0 + x * (u1 - u0), v0 + y * (v1 - v0));
        prop_assert_eq!(span_of(&spans_u, u), (u0, u1));
        let (hu, hv) = (0.02 * (u1 - u0), 0.02 * (v1 - v0));
        let d = s.derivatives(u, v);
        let scale = s.size().max(1e-300);
        let check = |name: &str, analytic: Vector3<f64>, (fd, spread): (Vector3<f64>, f64), h: f64| {
            let tol = 1e-7 * (analytic.norm() + scale / h) + 2.0 * spread;
            prop_assert!(
                (analytic - fd).norm() <= tol,
                "{} at ({}, {}): analytic {} vs finite difference {} (tol {})",
                name, u, v, analytic, fd, tol
            );
            Ok(())
        };
        let s = &s;
        let pt = |u: f64, v: f64| s.point(u, v).coords;
        let der = |k: usize, l: usize| move |u: f64, v: f64| s.derivatives(u, v)[k][l];
        prop_assert!((pt(u, v) - d[0][0]).norm() <= 1e-14 * (1.0 + d[0][0].norm()), "point");
        check("Su", d[1][0], central(|t| pt(t, v), u, hu), hu)?;
        check("Sv", d[0][1], central(|t| pt(u, t), v, hv), hv)?;
        for k in 0..3 {
            for l in 0..3 {
                if k >= 1 {
                    let f = der(k - 1, l);
                    check(&format!("S[{k}][{l}] along u"), d[k][l], central(|t| f(t, v), u, hu), hu)?;
                }
                if l >= 1 {
                    let f = der(k, l - 1);
                    check(&format!("S[{k}][{l}] along v"), d[k][l], central(|t| f(u, t), v, hv), hv)?;
                }
            }
        }
        let (p1, su1, sv1) = s.eval_d1(u, v);
        prop_assert_eq!((p1.coords, su1, sv1), (d[0][0], d[1][0], d[0][1]));
        // The normal is the unit Su x Sv wherever that is well conditioned.
        let n = d[1][0].cross(&d[0][1]);
        if n.norm() > 1e-6 * d[1][0].norm() * d[0][1].norm() {
            let unit = s.normal(u, v).expect("regular point");
            prop_assert!((unit - n.normalize()).norm() < 1e-9, "normal {} vs {}", unit, n);
        }
    }

}

proptest! {
    // Each case compares with 40 401 samples, refined: fewer cases.
    #![proptest_config(ProptestConfig::with_cases(48))]

    #[test]
    fn closest_point_matches_brute_force(
        seed in any::<u64>(),
        q in prop::array::uniform3(-1.6f64..1.6),
        x in 0.0f64..1.0,
        y in 0.0f64..1.0,
        near in any::<bool>(),
    ) {
        let s = random_surface(seed);
        prop_assume!(s.is_some());
        let s = s.expect("assumed");
        let (ua, ub) = s.domain_u();
        let (va, vb) = s.domain_v();
        let p = if near {
            s.point(ua + x * (ub - ua), va + y * (vb - va)) + Vector3::from(q) * 0.03
        } else {
            Point3::from(q)
        };
        let cold = s.closest_point(&p, None);
        let truth = brute_force(&s, &p, 200);
        let tol = 1e-10 * (1.0 + s.size());
        prop_assert!(
            cold.distance <= truth + tol,
            "closest point {:?} is farther than brute force {}", cold, truth
        );
        prop_assert!(cold.u >= ua && cold.u <= ub && cold.v >= va && cold.v <= vb, "in the domain");
        prop_assert_eq!(cold.point, s.point(cold.u, cold.v));
        prop_assert_eq!(cold.distance, (cold.point - p).norm());
        prop_assert_eq!(s.closest_point(&p, None), cold, "deterministic");
        // Warm starts at and next to the answer give the same distance.
        let at = s.closest_point(&p, Some((cold.u, cold.v)));
        prop_assert!(at.distance <= cold.distance + 1e-14 * (1.0 + cold.distance), "{:?} {:?}", at, cold);
        // Next to the answer (unless a jump of the surface separates the two).
        if !has_jumps(&s) {
            let (du, dv) = (1e-6 * (ub - ua), 1e-6 * (vb - va));
            let next = s.closest_point(&p, Some((cold.u + du, cold.v - dv)));
            prop_assert!(
                (next.distance - cold.distance).abs() <= 1e-9 * (1.0 + cold.distance),
                "warm {:?} vs cold {:?}", next, cold
            );
        }
    }
}

#[test]
fn warm_starts_are_local_and_never_beat_the_global_search() {
    // Random surfaces; a point moving along a line, each query warm-started from the previous
    // answer. On wild surfaces the global minimum may jump to another basin, which a warm
    // start need not follow; but it never ends farther than its start point, and never
    // closer than the global answer.
    let mut total = 0;
    for seed in 0..12u64 {
        let Some(s) = random_surface(seed) else {
            continue;
        };
        let mut prev: Option<(f64, f64)> = None;
        for i in 0..=20 {
            let t = i as f64 / 20.0;
            let p = Point3::new(-1.2 + 2.4 * t, 0.3 * t, 0.8 - t);
            let warm = s.closest_point(&p, prev);
            let cold = s.closest_point(&p, None);
            assert!(
                warm.distance >= cold.distance - 1e-12,
                "warm beats cold on seed {seed}: {warm:?} {cold:?}"
            );
            if let Some((u, v)) = prev {
                let start = (s.point(u, v) - p).norm();
                assert!(
                    warm.distance <= start + 1e-12,
                    "warm start got worse on seed {seed}: {warm:?} from {start}"
                );
            }
            prev = Some((warm.u, warm.v));
            total += 1;
        }
    }
    assert!(total > 150, "enough queries ({total})");
}

/// The cold search reads each cell's Bezier net from a cache filled on the first query. The
/// cache must not show: the first query of a fresh surface, every later query, a query on a
/// clone taken after the cache filled and one on a surface rebuilt from the same data all give
/// the same bits, and the surfaces compare equal whichever of them has filled its cache.
#[test]
fn the_cell_net_cache_changes_no_answer() {
    let mut compared = 0;
    for seed in 0..40u64 {
        let Some(s) = random_surface(seed) else {
            continue;
        };
        let rebuild = || {
            let (pts, w) = (s.control_points(), s.weights());
            NurbsSurface::try_new(
                s.degree_u(),
                s.degree_v(),
                s.knots_u().to_vec(),
                s.knots_v().to_vec(),
                pts,
                Some(w),
            )
            .expect("the same surface")
        };
        let points: Vec<Point3<f64>> = (0..8)
            .map(|i| {
                let t = i as f64 / 7.0;
                Point3::new(-1.3 + 2.6 * t, 0.9 - 1.7 * t, 0.4 * t - 0.2)
            })
            .collect();
        // Each point on a fresh surface: its first query fills the cache.
        let first: Vec<_> = points
            .iter()
            .map(|p| rebuild().closest_point(p, None))
            .collect();
        let fresh = rebuild();
        assert_eq!(fresh, s, "seed {seed}: rebuilt surface equals the original");
        let _ = s.closest_point(&points[0], None);
        let copy = s.clone();
        assert_eq!(
            fresh, copy,
            "seed {seed}: a filled cache takes no part in equality"
        );
        for (p, want) in points.iter().zip(&first) {
            assert_eq!(s.closest_point(p, None), *want, "seed {seed}: filled cache");
            assert_eq!(copy.closest_point(p, None), *want, "seed {seed}: clone");
            compared += 1;
        }
    }
    assert!(compared > 200, "enough queries ({compared})");
}

#[test]
fn evaluation_does_not_allocate() {
    let surfaces: Vec<NurbsSurface> = (0..40).filter_map(random_surface).collect();
    assert!(surfaces.len() > 10, "enough random surfaces");
    let before = allocations();
    let mut acc = Vector3::zeros();
    for s in &surfaces {
        let (ua, ub) = s.domain_u();
        let (va, vb) = s.domain_v();
        for i in 0..=20 {
            for j in 0..=20 {
                let u = ua + (ub - ua) * (i as f64 / 20.0);
                let v = va + (vb - va) * (j as f64 / 20.0);
                acc += s.point(u, v).coords;
                acc += s.derivatives(u, v)[1][1];
                acc += s.eval_d1(u, v).1;
                acc += s.normal(u, v).unwrap_or_default();
            }
        }
    }
    let after = allocations();
    assert_eq!(after - before, 0, "evaluation allocated ({acc})");
}
