//! The cutting order: holes before the contours around them, then the shortest traverse.

use crate::lead::{LeadIn, Leads};
use crate::{Contour, Pose, Side};

/// Most cost evaluations (each one pass over the order) the 2-opt improvement may spend: the
/// work budget that keeps large files fast.
const TWO_OPT_BUDGET: usize = 20_000_000;

/// The process plan of a set of contours.
#[derive(Debug, Clone, PartialEq)]
pub struct CutPlan {
    /// The contours' indices in cutting order.
    pub order: Vec<usize>,
    /// Per contour (input order): the chosen start, lead-in and lead-out.
    pub leads: Vec<LeadIn>,
    /// Per contour: the scrap side (`None` for an open contour without a `scrap` key).
    pub sides: Vec<Option<Side>>,
    /// Per contour: true if it is closed.
    pub closed: Vec<bool>,
    /// Per contour: the closed contours it lies inside (a hole of an odd number of them).
    pub inside: Vec<Vec<usize>>,
    /// Straight-line length of the traverses in this order, from each cut's exit to the next
    /// pierce point, mm.
    pub traverse_mm: f64,
    /// The same in file order with each contour's first start candidate, mm.
    pub file_order_traverse_mm: f64,
}

impl CutPlan {
    /// True if contour `i` is a hole (inside an odd number of closed contours).
    pub fn is_hole(&self, i: usize) -> bool {
        self.inside[i].len() % 2 == 1
    }

    /// The cut of contour `i` as it runs: for a closed contour from its start all the way
    /// round to the start again; an open contour as it is.
    pub fn cut(&self, i: usize, poses: &[Pose]) -> Vec<Pose> {
        let s = self.leads[i].start;
        if !self.closed[i] || s == 0 {
            return poses.to_vec();
        }
        let mut out = Vec::with_capacity(poses.len());
        out.extend_from_slice(&poses[s..]);
        out.extend_from_slice(&poses[1..=s]);
        out
    }
}

fn dist(a: &Pose, b: &Pose) -> f64 {
    (a.position - b.position).norm()
}

pub(crate) fn plan(
    contours: &[Contour<'_>],
    inside: &[Vec<usize>],
    sides: Vec<Option<Side>>,
    leads: Vec<Leads>,
) -> CutPlan {
    let n = contours.len();
    // before[a][b]: a must be cut before b (a lies inside b).
    let mut must_before = vec![Vec::<usize>::new(); n];
    for (a, outers) in inside.iter().enumerate() {
        for &b in outers {
            must_before[b].push(a);
        }
    }
    let entry = |i: usize, k: usize| leads[i].options[k].pierce(contours[i].poses);
    let exit = |i: usize, k: usize| leads[i].options[k].exit(contours[i].poses);
    // File order with the first candidates.
    let mut file_cost = 0.0;
    for i in 1..n {
        file_cost += dist(&exit(i - 1, 0), &entry(i, 0));
    }
    // Nearest neighbour, the start chosen with the step.
    let mut done = vec![false; n];
    let mut order = Vec::with_capacity(n);
    let mut choice = vec![0usize; n];
    let mut here: Option<Pose> = None;
    while order.len() < n {
        let mut best: Option<(f64, usize, usize)> = None;
        for i in 0..n {
            if done[i] || must_before[i].iter().any(|&a| !done[a]) {
                continue;
            }
            for k in 0..leads[i].options.len() {
                let d = here.map_or(0.0, |h| dist(&h, &entry(i, k)));
                if best.is_none_or(|(bd, _, _)| d < bd - 1e-12) {
                    best = Some((d, i, k));
                }
            }
            if here.is_none() {
                break; // the first available contour in file order starts the program
            }
        }
        let Some((_, i, k)) = best else { break };
        done[i] = true;
        choice[i] = k;
        order.push(i);
        here = Some(exit(i, k));
    }
    // 2-opt on the order, the starts fixed, keeping holes before their outlines.
    let pos_of = |order: &[usize]| {
        let mut p = vec![0usize; n];
        for (k, &i) in order.iter().enumerate() {
            p[i] = k;
        }
        p
    };
    let cost = |order: &[usize], choice: &[usize]| -> f64 {
        order
            .windows(2)
            .map(|w| dist(&exit(w[0], choice[w[0]]), &entry(w[1], choice[w[1]])))
            .sum()
    };
    let valid = |order: &[usize]| {
        let p = pos_of(order);
        (0..n).all(|b| must_before[b].iter().all(|&a| p[a] < p[b]))
    };
    let mut current = cost(&order, &choice);
    let mut work = 0usize;
    let mut improved = true;
    while improved && work < TWO_OPT_BUDGET {
        improved = false;
        'outer: for i in 0..n.saturating_sub(1) {
            for j in i + 1..n {
                work += n;
                if work >= TWO_OPT_BUDGET {
                    break 'outer;
                }
                let mut trial = order.clone();
                trial[i..=j].reverse();
                let c = cost(&trial, &choice);
                if c < current - 1e-9 && valid(&trial) {
                    order = trial;
                    current = c;
                    improved = true;
                }
            }
        }
    }
    // Starts again, given the order: each the candidate nearest to where the head comes from.
    let mut here: Option<Pose> = None;
    for &i in &order {
        if let Some(h) = here {
            let k = (0..leads[i].options.len())
                .min_by(|&a, &b| {
                    dist(&h, &entry(i, a))
                        .total_cmp(&dist(&h, &entry(i, b)))
                        .then(a.cmp(&b))
                })
                .unwrap_or(0);
            choice[i] = k;
        }
        here = Some(exit(i, choice[i]));
    }
    let traverse = cost(&order, &choice);
    CutPlan {
        order,
        leads: leads
            .iter()
            .enumerate()
            .map(|(i, l)| l.options[choice[i]].clone())
            .collect(),
        sides,
        closed: leads.iter().map(|l| l.closed).collect(),
        inside: inside.to_vec(),
        traverse_mm: traverse,
        file_order_traverse_mm: file_cost,
    }
}
