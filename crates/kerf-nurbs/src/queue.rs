//! The best-first queue of the global closest-point searches (curve pieces and surface
//! sub-patches): the entry with the smallest lower bound first, ties to the oldest, so that a
//! search is deterministic whatever the bounds.

use std::cmp::Ordering;
use std::collections::BinaryHeap;

/// Items waiting with a lower bound on the distance they can hold.
#[derive(Debug)]
pub(crate) struct BestFirst<T> {
    heap: BinaryHeap<Entry<T>>,
    /// The creation order of the next entry (ties go to the oldest).
    next: u64,
}

#[derive(Debug)]
struct Entry<T> {
    lower_bound: f64,
    order: u64,
    item: T,
}

impl<T> PartialEq for Entry<T> {
    fn eq(&self, other: &Self) -> bool {
        self.cmp(other) == Ordering::Equal
    }
}

impl<T> Eq for Entry<T> {}

impl<T> PartialOrd for Entry<T> {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}

impl<T> Ord for Entry<T> {
    /// Reversed, so that the max-heap pops the smallest lower bound (then the oldest entry).
    fn cmp(&self, other: &Self) -> Ordering {
        other
            .lower_bound
            .total_cmp(&self.lower_bound)
            .then(other.order.cmp(&self.order))
    }
}

impl<T> BestFirst<T> {
    /// An empty queue.
    pub(crate) fn new() -> Self {
        Self {
            heap: BinaryHeap::new(),
            next: 0,
        }
    }

    /// Queues `item` with its `lower_bound`.
    pub(crate) fn push(&mut self, lower_bound: f64, item: T) {
        self.heap.push(Entry {
            lower_bound,
            order: self.next,
            item,
        });
        self.next += 1;
    }

    /// The entry with the smallest lower bound (by `total_cmp`; the oldest of equal ones), with
    /// its bound.
    pub(crate) fn pop(&mut self) -> Option<(f64, T)> {
        self.heap.pop().map(|e| (e.lower_bound, e.item))
    }

    /// The number of entries waiting.
    pub(crate) fn len(&self) -> usize {
        self.heap.len()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Smallest bound first, ties in the order they came, NaN (by `total_cmp`) last.
    #[test]
    fn pops_the_smallest_bound_first_and_ties_in_arrival_order() {
        let mut q = BestFirst::new();
        for (b, name) in [
            (2.0, "a"),
            (1.0, "b"),
            (f64::NAN, "n"),
            (1.0, "c"),
            (0.5, "d"),
        ] {
            q.push(b, name);
        }
        assert_eq!(q.len(), 5);
        let order: Vec<&str> = std::iter::from_fn(|| q.pop().map(|(_, n)| n)).collect();
        assert_eq!(order, ["d", "b", "c", "a", "n"]);
    }
}
