//! Knot-vector validation and queries shared by curves and surfaces.

use crate::error::{NurbsError, Result};
use crate::MAX_DEGREE;

/// Checks a degree and a knot vector for `n_points` control points.
///
/// `field` names the knot vector in error messages (`knots`, `knots_u`, `knots_v`) and
/// `degree_field` the degree (`degree`, `degree_u`, `degree_v`).
///
/// # Errors
/// [`NurbsError::DegreeZero`], [`NurbsError::DegreeTooHigh`], [`NurbsError::TooFewPoints`],
/// [`NurbsError::KnotCount`], [`NurbsError::KnotNotFinite`], [`NurbsError::KnotsDecreasing`],
/// [`NurbsError::KnotMultiplicity`] or [`NurbsError::EmptyDomain`].
pub fn validate(
    degree: usize,
    knots: &[f64],
    n_points: usize,
    degree_field: &'static str,
    field: &'static str,
    points_field: &'static str,
) -> Result<()> {
    if degree == 0 {
        return Err(NurbsError::DegreeZero {
            field: degree_field,
        });
    }
    if degree > MAX_DEGREE {
        return Err(NurbsError::DegreeTooHigh {
            field: degree_field,
            degree,
            max: MAX_DEGREE,
        });
    }
    if n_points < degree + 1 {
        return Err(NurbsError::TooFewPoints {
            field: points_field,
            got: n_points,
            degree,
            needed: degree + 1,
        });
    }
    let expected = n_points + degree + 1;
    if knots.len() != expected {
        return Err(NurbsError::KnotCount {
            field,
            expected,
            got: knots.len(),
        });
    }
    for (index, &value) in knots.iter().enumerate() {
        if !value.is_finite() {
            return Err(NurbsError::KnotNotFinite {
                field,
                index,
                value,
            });
        }
    }
    let mut run = 1;
    for index in 1..knots.len() {
        let (previous, value) = (knots[index - 1], knots[index]);
        if value < previous {
            return Err(NurbsError::KnotsDecreasing {
                field,
                index,
                value,
                previous,
            });
        }
        run = if value == previous { run + 1 } else { 1 };
        if run > degree + 1 {
            let multiplicity = knots.iter().filter(|&&k| k == value).count();
            return Err(NurbsError::KnotMultiplicity {
                field,
                index,
                value,
                multiplicity,
                max: degree + 1,
            });
        }
    }
    let (start, end) = (knots[degree], knots[n_points]);
    if end <= start {
        return Err(NurbsError::EmptyDomain { field, start, end });
    }
    Ok(())
}

/// The knot span index `i` with `knots[i] <= u < knots[i + 1]`, restricted to the domain
/// spans `degree ..= n_points - 1` (The NURBS Book A2.1). Parameters outside the domain are
/// mapped to the first or last span; the domain end maps to the last non-empty span.
#[inline]
pub fn find_span(degree: usize, knots: &[f64], n_points: usize, u: f64) -> usize {
    let n = n_points - 1;
    if u >= knots[n] {
        // Last non-empty span (knots[n] < knots[n + 1] is guaranteed by validation of the
        // domain; walk down past repeated knots so that the span is non-empty).
        let mut i = n;
        while i > degree && knots[i] >= knots[n + 1] {
            i -= 1;
        }
        return i;
    }
    if u <= knots[degree] {
        let mut i = degree;
        while knots[i + 1] <= knots[degree] {
            i += 1;
        }
        return i;
    }
    // Binary search in [degree, n]: knots[lo] <= u < knots[hi].
    let (mut lo, mut hi) = (degree, n + 1);
    while hi - lo > 1 {
        let mid = (lo + hi) / 2;
        if u < knots[mid] {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    lo
}

/// How many times `u` occurs in `knots` (exact comparison).
pub fn multiplicity(knots: &[f64], u: f64) -> usize {
    crate::work::tick_knots(knots.len());
    knots.iter().filter(|&&k| k == u).count()
}

/// The distinct knot values strictly inside the domain `(start, end)` with their multiplicity.
pub fn interior_knots(degree: usize, knots: &[f64], n_points: usize) -> Vec<(f64, usize)> {
    let (start, end) = (knots[degree], knots[n_points]);
    crate::work::tick_knots(knots.len());
    let mut out: Vec<(f64, usize)> = Vec::new();
    for &k in knots {
        if k <= start || k >= end {
            continue;
        }
        match out.last_mut() {
            Some((v, m)) if *v == k => *m += 1,
            _ => out.push((k, 1)),
        }
    }
    out
}
