//! How far the set-points' smooth path may lie from the blocks: a proven bound.

use kerf_nurbs::distance_to_segment;
use nalgebra::Point3;

use super::motion::Motion;
use crate::block::Geometry;

/// Halvings of each spline piece before its control points are measured: 8 sub-pieces, whose
/// hull bound exceeds the true deviation by a few per cent at most on smooth paths.
const HULL_LEVELS: u32 = 3;

impl Motion {
    /// A proven bound (mm) of how far the tip spline the set-points follow (before the blend
    /// of [`Motion::blend_deviation`]) lies from the blocks of the cutting runs.
    ///
    /// The spline between two neighbouring nodes is a cubic whose Bezier control points are the
    /// nodes and the nodes moved by a third of the interval along their slopes; after
    /// `HULL_LEVELS` de Casteljau halvings, every sub-piece lies in the convex hull of its control
    /// points, and the distance to the nodes' chord is convex, so the largest control-point
    /// distance bounds the piece. The nodes lie on the blocks (block ends, arc points, points
    /// graded onto lines); on an arc block the chord of two nodes `h` apart along it lies within
    /// the arc's sagitta `R (1 - cos(h / 2R))` of the arc, which is added. So every set-point
    /// lies within this bound plus the blend of the blocks, and within that plus the blocks'
    /// own budget terms (chord, fit) of the curve (`docs/interpolation.md`, section 8).
    pub fn spline_deviation_bound(&self) -> f64 {
        let mut worst = 0.0f64;
        for run in self.runs.iter().filter(|r| r.cutting && r.moves_tip) {
            for (s0, s1, b) in run.tip_spline().bezier_pieces() {
                let ends = (Point3::from(b[0]), Point3::from(b[3]));
                let mut bound = hull_distance(&b, &ends, HULL_LEVELS);
                let (block, _) = run.block_at(0.5 * (s0 + s1));
                if let Geometry::Arc(arc) = &self.blocks[block].geometry {
                    bound += arc.radius * (1.0 - (0.5 * (s1 - s0) / arc.radius).cos());
                }
                worst = worst.max(bound);
            }
        }
        worst
    }
}

/// The largest distance of the control points of `b` (after `levels` halvings) from the
/// segment `ends`.
fn hull_distance(b: &[[f64; 3]; 4], ends: &(Point3<f64>, Point3<f64>), levels: u32) -> f64 {
    if levels == 0 {
        return b
            .iter()
            .map(|p| distance_to_segment(&Point3::from(*p), &ends.0, &ends.1))
            .fold(0.0, f64::max);
    }
    let mid =
        |p: &[f64; 3], q: &[f64; 3]| -> [f64; 3] { std::array::from_fn(|d| 0.5 * (p[d] + q[d])) };
    let (p01, p12, p23) = (mid(&b[0], &b[1]), mid(&b[1], &b[2]), mid(&b[2], &b[3]));
    let (p012, p123) = (mid(&p01, &p12), mid(&p12, &p23));
    let m = mid(&p012, &p123);
    let left = [b[0], p01, p012, m];
    let right = [m, p123, p23, b[3]];
    hull_distance(&left, ends, levels - 1).max(hull_distance(&right, ends, levels - 1))
}
