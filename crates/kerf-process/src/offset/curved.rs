//! The offset's chord error proven where the contour is curved in space or the tool axis turns
//! (docs/process.md, "Kerf compensation", "The certificate": "On curved surfaces and with
//! turning axes").
//!
//! On a chord `[t0, t1]` the exact offset is `Q(t) = C(t) + r W(t)`, with `W` the unit offset
//! direction `s normalize(a x C')` slid along the beam onto the tangent plane
//! (`W = d - a (d . m) / (a . m)`), the axis `a` and normal `m` interpolated between the
//! chord's ends (`nlerp` in the fraction `f` of `[t0, t1]`). Let `u` be the direction of the
//! contour's chord `C0 C1` (length `L`) and `lambda(t) = (C(t) - C0) . u / L`. Where `lambda`
//! increases (the contour advances along its chord), it maps the chord onto `[0, 1]` and
//!
//! `Q(t) - lerp(Q0, Q1, lambda) = [C(t) - lerp(C0, C1, lambda)] + r [W(t) - lerp(W0, W1, lambda)]`.
//!
//! The first bracket is the contour's distance from the line of its chord, at most the
//! discretizer's certified `e`. The second is the error of linear interpolation of
//! `W~(lambda) = W(t(lambda))`, at most `sup |W~''| / 8`, and
//! `W~'' = (W'' lambda' - W' lambda'') / lambda'^3` (derivatives in any parameter of the
//! piece). So every point of the offset lies within `e + r sup|W~''| / 8` of a point of the
//! chord `Q0 Q1`. The suprema come from Bezier coefficients, piece by piece ([`bound`]).
//!
//! The interpolation bound needs `W~` once continuously differentiable: a knot inside the
//! chord where the contour is only C1 (its second derivative jumps) is where the chord is
//! split ([`Proof::SplitAt`]).

use kerf_discretize::chord_error;

use super::bound::exceeds;
use kerf_nurbs::{NurbsCurve, RationalBezier};
use nalgebra::{Point3, Vector3};

/// What the proof found for one chord.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum Proof {
    /// Every point of the exact offset lies within this distance, mm, of the chord.
    Bound(f64),
    /// A knot inside the chord where the contour is at most C1: split there.
    SplitAt(f64),
    /// Not proven here (the contour turns back along its chord, the offset direction or the
    /// slide degenerates, a rough knot lies too near an end): a shorter chord may be.
    Fails,
}

/// The chord's data the proof needs.
#[derive(Clone, Copy)]
pub(super) struct Chord<'a> {
    pub(super) curve: &'a NurbsCurve,
    pub(super) t0: f64,
    pub(super) t1: f64,
    /// The contour's chord ends.
    pub(super) c0: Point3<f64>,
    pub(super) c1: Point3<f64>,
    /// The tool axes and surface normals at the ends (unit).
    pub(super) a0: Vector3<f64>,
    pub(super) a1: Vector3<f64>,
    pub(super) m0: Vector3<f64>,
    pub(super) m1: Vector3<f64>,
    /// Whether the offset slides onto the tangent plane.
    pub(super) slide: bool,
    /// Half the kerf, mm.
    pub(super) r: f64,
    /// The curve's size, for the rounding allowance.
    pub(super) size: f64,
    /// Past this, the exact value does not matter (the chord is split anyway).
    pub(super) limit: f64,
}

/// The proof for one chord (module docs).
pub(super) fn bound(ch: &Chord<'_>) -> Proof {
    let (t0, t1) = (ch.t0, ch.t1);
    if ch.slide && !slides(&ch.a0, &ch.m0) && !slides(&ch.a1, &ch.m1) {
        // A wall: the beam more than 80 degrees from the normal at both ends. Where that holds
        // all along the chord the offset slides nowhere on it and is bounded as unslid; else
        // a shorter chord may tell.
        return if slides_nowhere(ch) {
            bound(&Chord {
                slide: false,
                ..*ch
            })
        } else {
            Proof::Fails
        };
    }
    if let Some(k) = rough_knot(ch.curve, t0, t1) {
        // A knot within rounding of an end leaves a sub-chord too short to split further.
        let room = 1e-9 * (t1 - t0);
        return if k - t0 > room && t1 - k > room {
            Proof::SplitAt(k)
        } else {
            Proof::Fails
        };
    }
    let chord = ch.c1 - ch.c0;
    let len = chord.norm();
    if !exceeds(len, 0.0) || !len.is_finite() {
        return Proof::Fails;
    }
    let u = chord / len;
    let mut sup: f64 = 0.0;
    let mut ok = true;
    ch.curve.for_each_bezier_piece(t0, t1, |b| {
        if !ok {
            return;
        }
        match piece_bound(ch, b, &u, len) {
            Some(g) => sup = sup.max(g),
            None => ok = false,
        }
    });
    if !ok || !sup.is_finite() {
        return Proof::Fails;
    }
    let term = ch.r * sup / 8.0 * (1.0 + 1e-9);
    if !exceeds(ch.limit, term) {
        return Proof::Fails;
    }
    let e = chord_error(ch.curve, t0, t1, &ch.c0, &ch.c1, ch.limit - term, 0.0).upper;
    // The chord ends' rounding and the pieces' translation and subdivision, as on the flat
    // case: a few ulps of the coordinates and of the curve's size.
    let coords = ch.c0.coords.amax() + ch.c1.coords.amax() + ch.r;
    let rounding = 64.0 * f64::EPSILON * (coords + ch.size);
    Proof::Bound(e + term + rounding)
}

/// Whether the offset slides at an end: the beam within 80 degrees of the normal (`a . m`
/// above 0.17, as the offset's own slide decides).
fn slides(a: &Vector3<f64>, m: &Vector3<f64>) -> bool {
    exceeds(a.dot(m), 0.17)
}

/// Whether the normalized `a . m` stays at or below 0.17 all along the chord (so the offset
/// slides nowhere): `a~ . m~` is a quadratic in the fraction, at most its largest Bezier
/// coefficient, and a lerp of two unit vectors is at least `cos(angle / 2) = |x + y| / 2`
/// long.
fn slides_nowhere(ch: &Chord<'_>) -> bool {
    let (a0, a1, m0, m1) = (&ch.a0, &ch.a1, &ch.m0, &ch.m1);
    let h_max = a0
        .dot(m0)
        .max(0.5 * (a0.dot(m1) + a1.dot(m0)))
        .max(a1.dot(m1));
    let shortest = 0.5 * (a0 + a1).norm() * 0.5 * (m0 + m1).norm();
    h_max <= 0.0 || (shortest > 0.0 && h_max <= 0.17 * shortest * (1.0 - 1e-12))
}

/// The first knot strictly inside `(t0, t1)` at which the curve is at most C1 (multiplicity at
/// least `p - 1`; every knot of a polyline). The knots are sorted: a knot's multiplicity is
/// its run of equal values, read once (the knots inside one chord only).
fn rough_knot(curve: &NurbsCurve, t0: f64, t1: f64) -> Option<f64> {
    let p = curve.degree();
    let knots = curve.knots();
    let mut i = knots.partition_point(|&k| k <= t0);
    while i < knots.len() && knots[i] < t1 {
        let k = knots[i];
        let run = knots[i..].iter().take_while(|&&x| x == k).count();
        if run + 1 >= p {
            return Some(k);
        }
        i += run;
    }
    None
}

/// `sup |W~''|` over one Bezier piece of the chord, or `None` where a condition fails.
fn piece_bound(ch: &Chord<'_>, b: &RationalBezier, u: &Vector3<f64>, len: f64) -> Option<f64> {
    let cpw = b.homogeneous();
    let p = cpw.len() - 1;
    if p == 0 {
        return None;
    }
    let w_min = cpw.iter().map(|h| h.w).fold(f64::INFINITY, f64::min);
    let w_max = cpw.iter().map(|h| h.w).fold(0.0, f64::max);
    if !exceeds(w_min, 0.0) {
        return None;
    }
    // The piece translated to its first point: A_k = (P_k - P_0) w_k.
    let o = cpw[0].xyz() / cpw[0].w;
    let a: Vec<Vector3<f64>> = cpw.iter().map(|h| h.xyz() - o * h.w).collect();
    let w: Vec<f64> = cpw.iter().map(|h| h.w).collect();
    // N = A' w - A w' (C' = N / w^2) with each coefficient's rounding bound.
    let coeffs = super::bound::numerator(cpw);
    let n: Vec<Vector3<f64>> = coeffs.iter().map(|c| c.0).collect();
    let size = a.iter().map(|x| x.norm()).fold(0.0, f64::max) + 1e-300;
    // The coefficients' rounding, and a generous multiple of the products' size for what the
    // bounds below compute from them.
    let slack = coeffs.iter().map(|c| c.1).fold(0.0, f64::max)
        + 64.0 * (p as f64 + 1.0) * f64::EPSILON * size * w_max;
    // lambda' = (N . u) / (w^2 L): bounded below by the least coefficient, above by the
    // largest norm.
    let nu_min = n.iter().map(|x| x.dot(u)).fold(f64::INFINITY, f64::min) - slack;
    if !exceeds(nu_min, 0.0) {
        return None;
    }
    let n_max = n.iter().map(|x| x.norm()).fold(0.0, f64::max) + slack;
    let lam1_min = nu_min / (w_max * w_max * len);
    let lam1_max = n_max / (w_min * w_min * len);
    // lambda'' = C'' . u / L, C'' = (A'' - 2 C' w' - C w'') / w.
    let d2a = if p >= 2 {
        second_differences(&a).fold(0.0, f64::max) * (p * (p - 1)) as f64
    } else {
        0.0
    };
    let dw1 = w
        .windows(2)
        .map(|x| (x[1] - x[0]).abs())
        .fold(0.0, f64::max)
        * p as f64;
    let dw2 = if p >= 2 {
        w.windows(3)
            .map(|x| (x[2] - 2.0 * x[1] + x[0]).abs())
            .fold(0.0, f64::max)
            * (p * (p - 1)) as f64
    } else {
        0.0
    };
    let c_max = (0..=p).map(|k| a[k].norm() / w[k]).fold(0.0, f64::max);
    let c1_max = n_max / (w_min * w_min);
    // (The slack of N's coefficients is in N's units, which are C'' times w^2.)
    let c2_max =
        (d2a + 2.0 * c1_max * dw1 + c_max * dw2) / w_min * (1.0 + 1e-12) + slack / (w_min * w_min);
    let lam2_max = c2_max / len;
    // The axis and normal along the piece: lerps in the chord's fraction f, affine in the
    // piece's parameter (scaling `a` or `m` changes neither `d` nor the slide).
    let span = ch.t1 - ch.t0;
    let (f0, f1) = ((b.t0 - ch.t0) / span, (b.t1 - ch.t0) / span);
    let df = f1 - f0;
    let lerp = |x: &Vector3<f64>, y: &Vector3<f64>, f: f64| x * (1.0 - f) + y * f;
    let (aa, ab) = (lerp(&ch.a0, &ch.a1, f0), lerp(&ch.a0, &ch.a1, f1));
    // V = a~ x N, of degree 2p (N of degree 2p - 1 times a~ of degree 1).
    let m = n.len() - 1;
    let v: Vec<Vector3<f64>> = (0..=m + 1)
        .map(|k| {
            let mut x = Vector3::zeros();
            if k <= m {
                x += aa.cross(&n[k]) * ((m + 1 - k) as f64 / (m + 1) as f64);
            }
            if k >= 1 {
                x += ab.cross(&n[k - 1]) * (k as f64 / (m + 1) as f64);
            }
            x
        })
        .collect();
    let v_slack = 2.0 * slack + 16.0 * f64::EPSILON * n_max;
    let mean: Vector3<f64> = v.iter().sum();
    let omega = mean.try_normalize(0.0)?;
    let v_min = v
        .iter()
        .map(|x| x.dot(&omega))
        .fold(f64::INFINITY, f64::min)
        - v_slack;
    if !exceeds(v_min, 0.0) {
        return None;
    }
    let deg = (m + 1) as f64;
    let v1 = v
        .windows(2)
        .map(|x| (x[1] - x[0]).norm())
        .fold(0.0, f64::max)
        * deg
        + 2.0 * v_slack * deg;
    let v2 = if m + 1 >= 2 {
        second_differences(&v).fold(0.0, f64::max) * deg * (deg - 1.0)
            + 4.0 * v_slack * deg * (deg - 1.0)
    } else {
        0.0
    };
    // d = V / |V|: |d'| <= |V'| / |V|, |d''| <= |V''| / |V| + 3 |V'|^2 / |V|^2.
    let d1 = v1 / v_min;
    let d2 = v2 / v_min + 3.0 * d1 * d1;
    let (w1, w2) = if ch.slide {
        // W = d - a~ g, g = (d . m~) / h, h = a~ . m~ (quadratic in the piece's parameter).
        let (ma, mb) = (lerp(&ch.m0, &ch.m1, f0), lerp(&ch.m0, &ch.m1, f1));
        let h = [aa.dot(&ma), 0.5 * (aa.dot(&mb) + ab.dot(&ma)), ab.dot(&mb)];
        // The slide holds where the normalized a . m stays at 0.17 or more; |a~|, |m~| <= 1,
        // so h >= 0.17 proves it.
        let h_min = h.iter().copied().fold(f64::INFINITY, f64::min) * (1.0 - 1e-12);
        if !exceeds(h_min, 0.17) {
            return None;
        }
        let h1 = 2.0 * (h[1] - h[0]).abs().max((h[2] - h[1]).abs());
        let h2 = 2.0 * (h[2] - 2.0 * h[1] + h[0]).abs();
        let a1 = (ch.a1 - ch.a0).norm() * df;
        let m1 = (ch.m1 - ch.m0).norm() * df;
        let (k1, k2) = (d1 + m1, d2 + 2.0 * d1 * m1);
        let g0 = 1.0 / h_min;
        let g1 = k1 / h_min + h1 / (h_min * h_min);
        let g2 = k2 / h_min
            + 2.0 * k1 * h1 / (h_min * h_min)
            + h2 / (h_min * h_min)
            + 2.0 * h1 * h1 / (h_min * h_min * h_min);
        (d1 + a1 * g0 + g1, d2 + 2.0 * a1 * g1 + g2)
    } else {
        (d1, d2)
    };
    let g = (w2 * lam1_max + w1 * lam2_max) / (lam1_min * lam1_min * lam1_min);
    g.is_finite().then_some(g)
}

/// The norms of the second differences of a sequence of vectors.
fn second_differences(x: &[Vector3<f64>]) -> impl Iterator<Item = f64> + '_ {
    x.windows(3).map(|y| (y[2] - 2.0 * y[1] + y[0]).norm())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A space curve (cubic, C2, seven spans), polynomial or rational (weights 0.5 to 2).
    fn setup(rational: bool) -> NurbsCurve {
        let pts = [
            Point3::new(0.0, 0.0, 0.0),
            Point3::new(8.0, 3.0, 1.0),
            Point3::new(14.0, -2.0, 4.0),
            Point3::new(22.0, 5.0, 2.0),
            Point3::new(28.0, 12.0, -3.0),
            Point3::new(33.0, 6.0, 1.0),
            Point3::new(40.0, 9.0, 5.0),
            Point3::new(46.0, 2.0, 3.0),
            Point3::new(52.0, 7.0, 0.0),
            Point3::new(60.0, 4.0, 2.0),
        ];
        let mut knots = vec![0.0; 4];
        knots.extend((1..7).map(|k| k as f64));
        knots.extend(vec![7.0; 4]);
        let weights = rational.then(|| vec![1.0, 2.0, 0.5, 1.5, 1.0, 0.7, 1.8, 1.0, 0.6, 1.0]);
        NurbsCurve::try_new(3, knots, pts.to_vec(), weights).expect("curve")
    }

    fn axis(t: f64) -> Vector3<f64> {
        Vector3::new(0.25 * (0.7 * t).sin(), 0.25 * (0.5 * t).cos(), 1.0).normalize()
    }

    fn normal(t: f64) -> Vector3<f64> {
        Vector3::new(-0.15 * (0.4 * t).cos(), 0.1, 1.0).normalize()
    }

    /// The exact offset point at `t` of the chord `[t0, t1]` (`r` signed: the side), written
    /// out again: the axis and normal `nlerp`ed in the chord's fraction, `d = normalize(a x
    /// C')`, slid along `a` onto the plane through `C` across `m`.
    fn offset_point(c: &NurbsCurve, t0: f64, t1: f64, t: f64, r: f64, slide: bool) -> Point3<f64> {
        let f = (t - t0) / (t1 - t0);
        let a = (axis(t0) * (1.0 - f) + axis(t1) * f).normalize();
        let m = (normal(t0) * (1.0 - f) + normal(t1) * f).normalize();
        let (p, d1) = c.eval_d1(t);
        let q = p + a.cross(&d1).normalize() * r;
        if slide {
            q - a * ((q - p).dot(&m) / a.dot(&m))
        } else {
            q
        }
    }

    /// Every bound the proof gives is at least the distance a dense sampling (4,000 points
    /// per chord) finds between the exact offset and the chord, on chords from 0.05 to 1 of
    /// the parameter (0.3 mm to 12 mm), on a polynomial and a rational curve, on both sides,
    /// with and without the slide; and it is within 10 times of it on the short ones.
    #[test]
    fn the_bound_holds_against_a_dense_sampling_of_the_exact_offset() {
        let mut proven = 0;
        let mut short = 0;
        let mut tight: f64 = f64::INFINITY;
        for rational in [false, true] {
            let c = setup(rational);
            for (slide, side) in [(false, 1.0), (true, 1.0), (true, -1.0)] {
                let r = 0.15;
                for (k, len) in [0.05, 0.1, 0.2, 0.35, 0.6, 1.0].iter().enumerate() {
                    let mut t0 = 0.07 * k as f64;
                    while t0 + len < 7.0 {
                        let t1 = t0 + len;
                        let ch = Chord {
                            curve: &c,
                            t0,
                            t1,
                            c0: c.point(t0),
                            c1: c.point(t1),
                            a0: axis(t0),
                            a1: axis(t1),
                            m0: normal(t0),
                            m1: normal(t1),
                            slide,
                            r,
                            size: c.size(),
                            limit: 10.0,
                        };
                        let at = |t: f64| offset_point(&c, t0, t1, t, side * r, slide);
                        let seg = kerf_nurbs::Segment::between(&at(t0), &at(t1));
                        let dense = (1..4000)
                            .map(|j| seg.distance_to(&at(t0 + len * j as f64 / 4000.0)))
                            .fold(0.0, f64::max);
                        if let Proof::Bound(b) = bound(&ch) {
                            proven += 1;
                            assert!(
                                b >= dense,
                                "[{t0}, {t1}] rational {rational} slide {slide} side {side}: bound {b:.3e} below the sampled {dense:.3e}"
                            );
                            if *len <= 0.1 {
                                short += 1;
                                tight = tight.min(dense / b);
                            }
                        }
                        t0 += len;
                    }
                }
            }
        }
        assert!(proven > 600, "most chords proven ({proven})");
        assert!(short > 300, "the short chords proven ({short})");
        // Looser on the rational curve: its weights' derivatives enter C'' term by term.
        assert!(
            tight > 0.1,
            "the bound within 10x of the truth on short chords ({tight:.3})"
        );
    }

    /// Where the beam is more than 80 degrees from the surface's normal all along a chord (a
    /// wall), the exact offset does not slide: the chord is bounded as unslid. Where the
    /// normal turns toward the axis inside the chord (it slides there), no proof.
    #[test]
    fn a_beam_along_a_wall_is_proven_without_the_slide() {
        let c = setup(false);
        let ch = Chord {
            curve: &c,
            t0: 1.2,
            t1: 1.3,
            c0: c.point(1.2),
            c1: c.point(1.3),
            a0: Vector3::z(),
            a1: Vector3::z(),
            m0: Vector3::x(),
            m1: Vector3::y(),
            slide: true,
            r: 0.1,
            size: c.size(),
            limit: 10.0,
        };
        let no_slide = Chord { slide: false, ..ch };
        assert!(
            matches!(bound(&no_slide), Proof::Bound(_)),
            "without the slide it is proven"
        );
        assert_eq!(
            bound(&ch),
            bound(&no_slide),
            "the wall is bounded as unslid"
        );
        // The axis and the normal trade places: a . m is 0 at both ends and 1 in the middle.
        let swap = Chord {
            a0: Vector3::z(),
            m0: Vector3::x(),
            a1: Vector3::x(),
            m1: Vector3::z(),
            ..ch
        };
        assert_eq!(bound(&swap), Proof::Fails, "it slides inside: not proven");
    }

    /// A knot where the curve is only C1 inside a chord is where it is split.
    #[test]
    fn a_c1_knot_inside_a_chord_splits_it() {
        // Degree 3 with a double knot at 2 (C1 there).
        let pts: Vec<Point3<f64>> = (0..7)
            .map(|k| Point3::new(k as f64 * 5.0, ((k * k) % 5) as f64, 0.0))
            .collect();
        let c = NurbsCurve::try_new(
            3,
            vec![0.0, 0.0, 0.0, 0.0, 1.0, 2.0, 2.0, 3.0, 3.0, 3.0, 3.0],
            pts,
            None,
        )
        .expect("curve");
        let ch = |t0: f64, t1: f64| Chord {
            curve: &c,
            t0,
            t1,
            c0: c.point(t0),
            c1: c.point(t1),
            a0: Vector3::z(),
            a1: Vector3::z(),
            m0: Vector3::z(),
            m1: Vector3::z(),
            slide: false,
            r: 0.1,
            size: c.size(),
            limit: 10.0,
        };
        assert_eq!(bound(&ch(1.9, 2.1)), Proof::SplitAt(2.0), "the double knot");
        assert!(
            !matches!(bound(&ch(0.9, 1.1)), Proof::SplitAt(_)),
            "a simple knot of a cubic is C2: no split"
        );
    }
}
