//! A tree of the surfaces' boxes, for the distance queries: which boxes lie within a distance
//! of a point, and the nearest of those that do not, without looking at every box.
//!
//! Each node's box is the union of its children's (the least and greatest coordinates, taken
//! exactly), so a box inside it is at least as far from any point, coordinate by coordinate and
//! so also in floating point: a node at least the limit away holds no box nearer.

use nalgebra::Point3;

use kerf_nurbs::distance_to_box;

/// Boxes per leaf.
const LEAF: usize = 4;

/// A node: its box, and either its two children or its boxes (`start..end` of `order`).
#[derive(Debug, Clone)]
struct Node {
    lo: Point3<f64>,
    hi: Point3<f64>,
    /// The children (`None` for a leaf).
    children: Option<(usize, usize)>,
    start: usize,
    end: usize,
}

/// A bounding-volume tree over a list of boxes.
#[derive(Debug, Clone, Default)]
pub(super) struct BoxTree {
    nodes: Vec<Node>,
    /// The boxes' indices, each leaf's together.
    order: Vec<usize>,
    boxes: Vec<(Point3<f64>, Point3<f64>)>,
}

impl BoxTree {
    /// The tree of `boxes` (`(min, max)` each), split at the median of the centres along the
    /// longest side of theirs.
    pub(super) fn new(boxes: Vec<(Point3<f64>, Point3<f64>)>) -> Self {
        let mut tree = Self {
            nodes: Vec::new(),
            order: (0..boxes.len()).collect(),
            boxes,
        };
        if !tree.boxes.is_empty() {
            tree.build(0, tree.boxes.len());
        }
        tree
    }

    /// Builds the node over `order[start..end]`, returning its index.
    fn build(&mut self, start: usize, end: usize) -> usize {
        let mut lo = Point3::from([f64::INFINITY; 3]);
        let mut hi = Point3::from([f64::NEG_INFINITY; 3]);
        let mut clo = lo;
        let mut chi = hi;
        for &i in &self.order[start..end] {
            let (a, b) = self.boxes[i];
            lo = lo.inf(&a);
            hi = hi.sup(&b);
            let c = nalgebra::center(&a, &b);
            clo = clo.inf(&c);
            chi = chi.sup(&c);
        }
        let at = self.nodes.len();
        self.nodes.push(Node {
            lo,
            hi,
            children: None,
            start,
            end,
        });
        if end - start > LEAF {
            let axis = (chi - clo).imax();
            let boxes = &self.boxes;
            let centre = |i: usize| 0.5 * (boxes[i].0[axis] + boxes[i].1[axis]);
            let mid = start + (end - start) / 2;
            self.order[start..end]
                .select_nth_unstable_by(mid - start, |&a, &b| centre(a).total_cmp(&centre(b)));
            let left = self.build(start, mid);
            let right = self.build(mid, end);
            self.nodes[at].children = Some((left, right));
        }
        at
    }

    /// Calls `found(i, g)` for every box `i` whose distance `g` from `p` ([`distance_to_box`]) is
    /// below `limit`.
    pub(super) fn within(&self, p: &Point3<f64>, limit: f64, mut found: impl FnMut(usize, f64)) {
        self.search(p, limit, |i, g, _| {
            if g < limit {
                found(i, g);
            }
        });
    }

    /// The least distance from `p` of the boxes at least `limit` away, where it is below
    /// `bound`; otherwise `bound` (or more).
    pub(super) fn nearest_beyond(&self, p: &Point3<f64>, limit: f64, bound: f64) -> f64 {
        self.search(p, bound, |_, g, best| {
            if g >= limit {
                *best = best.min(g);
            }
        })
    }

    /// The tree's walk: every node nearer `p` than `bound` is opened, and at a leaf `leaf(i,
    /// g, &mut bound)` is called for each of its boxes `i` (`g` its distance from `p`), which
    /// may lower the bound the rest of the walk prunes with; returns the final bound. Depth
    /// first on a fixed stack of 64 (a deeper node is searched as a leaf).
    fn search(
        &self,
        p: &Point3<f64>,
        mut bound: f64,
        mut leaf: impl FnMut(usize, f64, &mut f64),
    ) -> f64 {
        if self.nodes.is_empty() {
            return bound;
        }
        let mut stack = [0usize; 64];
        let mut top = 1;
        while top > 0 {
            top -= 1;
            let node = &self.nodes[stack[top]];
            if distance_to_box(p, &node.lo, &node.hi) >= bound {
                continue;
            }
            match node.children {
                Some((a, b)) if top + 2 <= stack.len() => {
                    stack[top] = a;
                    stack[top + 1] = b;
                    top += 2;
                }
                _ => {
                    for &i in &self.order[node.start..node.end] {
                        let (lo, hi) = self.boxes[i];
                        leaf(i, distance_to_box(p, &lo, &hi), &mut bound);
                    }
                }
            }
        }
        bound
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The tree finds every box a scan of the list finds, with the same distances, and the
    /// same nearest box beyond the limit.
    #[test]
    fn the_tree_finds_what_the_scan_finds() {
        let mut seed = 0x9e37_79b9_7f4a_7c15_u64;
        let mut next = || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        for n in [0usize, 1, 3, 4, 5, 17, 75, 300] {
            let boxes: Vec<(Point3<f64>, Point3<f64>)> = (0..n)
                .map(|_| {
                    let a = Point3::new(400.0 * next(), 300.0 * next(), 100.0 * next());
                    let s = nalgebra::Vector3::new(60.0 * next(), 60.0 * next(), 5.0 * next());
                    (a, a + s)
                })
                .collect();
            let tree = BoxTree::new(boxes.clone());
            for _ in 0..200 {
                let p = Point3::new(500.0 * next() - 50.0, 400.0 * next() - 50.0, 150.0 * next());
                for limit in [0.0, 5.0, 30.0, f64::INFINITY] {
                    let mut found = Vec::new();
                    tree.within(&p, limit, |i, g| found.push((i, g.to_bits())));
                    found.sort_unstable();
                    let scan: Vec<(usize, u64)> = boxes
                        .iter()
                        .enumerate()
                        .map(|(i, (lo, hi))| (i, distance_to_box(&p, lo, hi)))
                        .filter(|&(_, g)| g < limit)
                        .map(|(i, g)| (i, g.to_bits()))
                        .collect();
                    assert_eq!(found, scan, "{n} {p} {limit}");
                    let beyond = boxes
                        .iter()
                        .map(|(lo, hi)| distance_to_box(&p, lo, hi))
                        .filter(|&g| g >= limit)
                        .fold(f64::INFINITY, f64::min);
                    let tree_beyond = tree.nearest_beyond(&p, limit, f64::INFINITY);
                    assert_eq!(tree_beyond.to_bits(), beyond.to_bits(), "{n} {p} {limit}");
                }
            }
        }
    }
}
