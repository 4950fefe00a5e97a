//! The certified bound of the tangent's turn over a segment.

use super::Certifier;
use kerf_nurbs::RationalBezier;
use nalgebra::Vector3;

impl Certifier<'_> {
    /// A certified upper bound (radians) of the largest angle between the tangents at any two
    /// points of `[t0, t1]`, refined until it is `<= limit` or cannot be brought below it; `PI`
    /// where the tangent may reverse (a cusp).
    ///
    /// The derivative of a rational Bezier piece is `C' = sum_{i<k} w_i w_k (B_i B_k' - B_k B_i')
    /// (Q_k - Q_i) / w^2`, and `B_i B_k' - B_k B_i' >= 0` for `i < k` (the ratio `B_k / B_i`
    /// increases), so every tangent lies in the cone spanned by the control polygon's edges
    /// `Q_{j+1} - Q_j`. If every edge is within `theta < 90` degrees of one direction `d`, so is
    /// every tangent, and two tangents differ by at most `2 theta`. Halving a piece (de
    /// Casteljau) shrinks its cone to the tangents actually taken; at most `32 + 2 * pieces`
    /// halvings.
    pub fn turn_bound(&self, t0: f64, t1: f64, limit: f64) -> f64 {
        let mut pieces: Vec<(RationalBezier, f64)> = Vec::new();
        let mut d = self.local.point(t1) - self.local.point(t0);
        if d.norm() == 0.0 {
            self.local.for_each_bezier_piece(t0, t1, |bez| {
                if d.norm() == 0.0 {
                    if let Some(e) = edges(bez).find(|e| e.norm() > 0.0) {
                        d = e;
                    }
                }
            });
        }
        if d.norm() == 0.0 || !d.norm().is_finite() {
            return 0.0;
        }
        let spread = |bez: &RationalBezier| {
            edges(bez)
                .filter(|e| e.norm() > 0.0)
                .map(|e| e.angle(&d))
                .fold(0.0f64, f64::max)
        };
        self.local.for_each_bezier_piece(t0, t1, |bez| {
            pieces.push((*bez, spread(bez)));
        });
        let budget = 32 + 2 * pieces.len();
        for _ in 0..=budget {
            let (worst, theta) = pieces
                .iter()
                .enumerate()
                .map(|(i, p)| (i, p.1))
                .fold((0, 0.0f64), |acc, x| if x.1 > acc.1 { x } else { acc });
            let bound = if theta >= std::f64::consts::FRAC_PI_2 || theta.is_nan() {
                std::f64::consts::PI
            } else {
                2.0 * theta
            };
            if bound <= limit {
                return bound;
            }
            let mut right = pieces[worst].0;
            let mut left = right;
            left.subdivide_in_place(&mut right, 0.5);
            pieces[worst] = (left, spread(&left));
            pieces.push((right, spread(&right)));
            if pieces.len() > budget + 2 {
                break;
            }
        }
        let theta = pieces.iter().map(|p| p.1).fold(0.0f64, f64::max);
        if theta >= std::f64::consts::FRAC_PI_2 || theta.is_nan() {
            std::f64::consts::PI
        } else {
            2.0 * theta
        }
    }
}

/// The edges `Q_{j+1} - Q_j` of a piece's projected control polygon.
fn edges(bez: &RationalBezier) -> impl Iterator<Item = Vector3<f64>> + '_ {
    let h = bez.homogeneous();
    h.windows(2)
        .map(|w| w[1].xyz() / w[1].w - w[0].xyz() / w[0].w)
}
