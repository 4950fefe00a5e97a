//! Many curves at once: the one loop behind [`crate::discretize_all`], the pipeline's
//! `discretize_curves` and `kerf discretize`.

use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

use kerf_nurbs::NurbsCurve;
use rayon::prelude::*;

use crate::{check_tolerance, discretize, Discretization, DiscretizeError, Options, Result};

/// The least allowance of one curve under a total limit, points: however little is left, a
/// curve may still be walked up to this many points before the limit refuses it.
const MIN_ALLOWANCE: usize = 1024;

/// A batch of curves, checked and ready to be discretized by [`Batch::each`].
///
/// Made by [`Batch::new`], which refuses what is known before any walk (invalid options, a
/// curve whose tolerance is below its rounding margin), so that a caller can decide what to
/// do before the first walk (open its output, say). The curves are any slice with a way to
/// reach the curve of an item: `&[NurbsCurve]` with `|c| c`, a curves file's records with
/// `|r| &r.curve`.
///
/// ```
/// use kerf_discretize::{Batch, Options};
/// use kerf_nurbs::NurbsCurve;
/// use nalgebra::{Point3, Vector3};
///
/// let circles: Vec<NurbsCurve> = (1..=3)
///     .map(|r| NurbsCurve::circle(Point3::origin(), Vector3::z(), r as f64).unwrap())
///     .collect();
/// let batch = Batch::new(&circles, |c| c, &Options::with_tolerance(0.01))?
///     .in_groups_of(2)
///     .with_max_total_points(1000);
/// let mut points = Vec::new();
/// batch.each(&|_done, _total| {}, |index, d| {
///     points.push((index, d?.points().len()));
///     Ok::<(), kerf_discretize::DiscretizeError>(())
/// })?;
/// assert_eq!(points.iter().map(|p| p.0).collect::<Vec<_>>(), [0, 1, 2], "input order");
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug)]
pub struct Batch<'a, T> {
    items: &'a [T],
    curve: fn(&T) -> &NurbsCurve,
    opts: Options,
    group: usize,
    max_total_points: Option<usize>,
}

/// Why [`Batch::new`] refused a batch: known before any walk.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum BatchRefusal {
    /// An option is out of range ([`Options::validate`]).
    #[error(transparent)]
    Options(DiscretizeError),
    /// The tolerance cannot be certified on the curve `index` ([`check_tolerance`]): the first
    /// such curve in input order. No curve was walked.
    #[error("curve {index}: {source}")]
    Curve {
        /// The curve's index in the batch.
        index: usize,
        /// Its refusal ([`DiscretizeError::ToleranceBelowMargin`]).
        #[source]
        source: DiscretizeError,
    },
}

/// Why [`Batch::each`] stopped.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum BatchError<E> {
    /// The curves together need more than the batch's total limit
    /// ([`Batch::with_max_total_points`]). The sink has seen the groups before the curve's.
    #[error("the curves need more than {limit} cutting points in all (at least {} by curve {index})", reached.round())]
    TooManyPoints {
        /// The limit.
        limit: usize,
        /// The total reached when the curve finished, or the total before it plus its
        /// estimate when the estimate refused it before its walk.
        reached: f64,
        /// The first curve of its group (in input order) that passed the limit.
        index: usize,
    },
    /// The sink returned an error for the curve `index`; the curves after it were not given
    /// to the sink.
    #[error("curve {index}: {source}")]
    Sink {
        /// The curve the sink was given.
        index: usize,
        /// The sink's error.
        #[source]
        source: E,
    },
}

/// What became of one curve of a group.
enum Slot {
    /// Discretized, or failed on its own.
    Done(Result<Discretization>),
    /// Passed the total limit: the total reached, or the total before it plus its estimate.
    Limit(f64),
    /// Not started: a curve passed the limit, or the sink failed.
    Stopped,
}

/// What the walks of one batch share.
struct Shared<'p> {
    /// Points of the curves finished so far (counted under a total limit only).
    used: AtomicUsize,
    /// Curves finished so far, for the progress.
    done: AtomicUsize,
    /// Set when a curve passes the limit or the sink fails: no curve starts after it.
    stop: AtomicBool,
    total: usize,
    progress: &'p (dyn Fn(usize, usize) + Sync),
}

impl<'a, T: Sync> Batch<'a, T> {
    /// The batch of `items`, whose curves `curve` reaches, at `opts`, checked before any walk:
    /// the options, then every curve's tolerance against its rounding margin
    /// ([`check_tolerance`], control points only, in parallel), so that a curve late in the
    /// batch that cannot be certified is refused at once, not after the walks of the curves
    /// before it. By default the batch is one group and has no total limit (each curve is
    /// still limited by [`Options::max_points`]).
    ///
    /// # Errors
    /// [`BatchRefusal::Options`], then [`BatchRefusal::Curve`] naming the first curve in input
    /// order that cannot hold the tolerance.
    pub fn new(
        items: &'a [T],
        curve: fn(&T) -> &NurbsCurve,
        opts: &Options,
    ) -> std::result::Result<Self, BatchRefusal> {
        opts.validate().map_err(BatchRefusal::Options)?;
        let refused = items
            .par_iter()
            .enumerate()
            .find_map_first(|(index, item)| {
                check_tolerance(curve(item), opts.tolerance_mm)
                    .err()
                    .map(|source| BatchRefusal::Curve { index, source })
            });
        match refused {
            Some(refusal) => Err(refusal),
            None => Ok(Self {
                items,
                curve,
                opts: *opts,
                group: usize::MAX,
                max_total_points: None,
            }),
        }
    }

    /// This batch discretized in groups of `group` curves (0 counts as 1): the curves of a
    /// group are discretized in parallel, and the sink of [`Batch::each`] works through one
    /// group while the thread pool discretizes the next, so that at most two groups'
    /// discretizations are held at once besides what the sink keeps (`kerf discretize` writes
    /// a large file in groups of 256). Groups only change when the walks run, not what they
    /// make. One group (the default) keeps every thread busy to the end of the batch.
    pub fn in_groups_of(mut self, group: usize) -> Self {
        self.group = group.max(1);
        self
    }

    /// This batch with at most `limit` cutting points over all curves together
    /// ([`Options::max_points`] still limits each curve).
    ///
    /// Each curve is discretized with its `max_points` lowered to twice what was left of the
    /// limit when it started (the limit minus the points of the curves finished by then), but
    /// not below 1,024: a curve whose estimate (the discretizer's own, before it allocates
    /// anything) is above that is refused at once, and a walk that passes it stops there. The
    /// estimate is not a bound, so the total itself is counted exactly: a curve that finishes
    /// with the total above the limit passes it (its points are dropped), and then no curve
    /// starts. So a batch that succeeds made at most `limit` points, and the points held at
    /// once (by the batch, and by a sink that keeps them all) are at most the limit plus, for
    /// each curve being walked (one per thread), twice what was left of the limit when it
    /// started (at least 1,024): three times the limit on one thread, twice the limit more per
    /// further thread. Which curve is named when the limit is passed, and whether a curve near
    /// the limit is refused by its estimate, depend on the order the threads finish in.
    pub fn with_max_total_points(mut self, limit: usize) -> Self {
        self.max_total_points = Some(limit);
        self
    }

    /// The items of the batch, as given to [`Batch::new`] (the index `sink` is given is an
    /// index into them).
    pub fn items(&self) -> &'a [T] {
        self.items
    }

    /// Discretizes every curve (in parallel, in groups: [`Batch::in_groups_of`]) and gives
    /// each result to `sink` on the calling thread, in input order, with its index: the
    /// discretization, identical to [`discretize`] of the curve, or the curve's own error. The
    /// sink of a group runs while the pool discretizes the next group. `progress` is called
    /// with `(0, total)` first, then `(done, total)` from the pool's threads as each curve's
    /// discretization finishes (in the order they finish).
    ///
    /// The batch stops at the first error: when the sink returns one (a caller that wants
    /// every result returns `Ok` for failed curves too), or when a group passes the total
    /// limit ([`Batch::with_max_total_points`]), before any curve of that group is given to
    /// the sink. The curves not yet started are then not walked (those already being walked
    /// finish first).
    ///
    /// # Errors
    /// [`BatchError::TooManyPoints`], [`BatchError::Sink`].
    pub fn each<E>(
        &self,
        progress: &(dyn Fn(usize, usize) + Sync),
        mut sink: impl FnMut(usize, Result<Discretization>) -> std::result::Result<(), E>,
    ) -> std::result::Result<(), BatchError<E>> {
        let shared = Shared {
            used: AtomicUsize::new(0),
            done: AtomicUsize::new(0),
            stop: AtomicBool::new(false),
            total: self.items.len(),
            progress,
        };
        progress(0, shared.total);
        let groups: Vec<&[T]> = self.items.chunks(self.group.max(1)).collect();
        let mut slots = groups
            .first()
            .map_or_else(Vec::new, |g| self.walk_group(g, &shared));
        let mut start = 0;
        for (g, group) in groups.iter().enumerate() {
            // A group that passed the limit is refused before the sink sees any of it, and
            // before the next group is started.
            if let Some((k, reached)) = slots.iter().enumerate().find_map(|(k, s)| match s {
                Slot::Limit(reached) => Some((k, *reached)),
                _ => None,
            }) {
                return Err(self.too_many(start + k, reached));
            }
            let mut next = Vec::new();
            // The pool discretizes the next group while this thread gives this one to the
            // sink; the scope waits for it, also when the sink fails.
            let sunk = rayon::in_place_scope(|s| {
                if let Some(following) = groups.get(g + 1) {
                    let next = &mut next;
                    let shared = &shared;
                    s.spawn(move |_| *next = self.walk_group(following, shared));
                }
                let sunk = self.sink_group(start, slots, &mut sink, &shared);
                if sunk.is_err() {
                    shared.stop.store(true, Ordering::Relaxed);
                }
                sunk
            });
            sunk?;
            slots = next;
            start += group.len();
        }
        Ok(())
    }

    /// Gives the slots of the group starting at `start` to the sink, in order.
    fn sink_group<E>(
        &self,
        start: usize,
        slots: Vec<Slot>,
        sink: &mut impl FnMut(usize, Result<Discretization>) -> std::result::Result<(), E>,
        shared: &Shared<'_>,
    ) -> std::result::Result<(), BatchError<E>> {
        for (k, slot) in slots.into_iter().enumerate() {
            let index = start + k;
            match slot {
                Slot::Done(r) => {
                    sink(index, r).map_err(|source| BatchError::Sink { index, source })?
                }
                // Not reached: a curve is stopped only once another of its group passed the
                // limit (refused before the sink) or the sink failed (which ends the batch
                // before the next group is given to it).
                Slot::Limit(_) | Slot::Stopped => {
                    return Err(self.too_many(index, shared.used.load(Ordering::Relaxed) as f64))
                }
            }
        }
        Ok(())
    }

    /// The limit passed by curve `index` with the total `reached`.
    fn too_many<E>(&self, index: usize, reached: f64) -> BatchError<E> {
        BatchError::TooManyPoints {
            limit: self.max_total_points.unwrap_or(usize::MAX),
            reached,
            index,
        }
    }

    /// Discretizes a group in parallel; results in input order.
    fn walk_group(&self, group: &[T], shared: &Shared<'_>) -> Vec<Slot> {
        group
            .par_iter()
            .map(|item| self.walk((self.curve)(item), shared))
            .collect()
    }

    /// Discretizes one curve within what is left of the total limit.
    fn walk(&self, curve: &NurbsCurve, shared: &Shared<'_>) -> Slot {
        if shared.stop.load(Ordering::Relaxed) {
            return Slot::Stopped;
        }
        let slot = match self.max_total_points {
            None => Slot::Done(discretize(curve, &self.opts)),
            Some(limit) => {
                let before = shared.used.load(Ordering::Relaxed);
                let left = limit.saturating_sub(before);
                let allowed = left.saturating_mul(2).max(MIN_ALLOWANCE);
                let bound_by_total = allowed < self.opts.max_points;
                let opts = self.opts.with_max_points(allowed.min(self.opts.max_points));
                match discretize(curve, &opts) {
                    Ok(d) => {
                        let n = d.points().len();
                        let now = shared.used.fetch_add(n, Ordering::Relaxed) + n;
                        if now > limit {
                            shared.stop.store(true, Ordering::Relaxed);
                            Slot::Limit(now as f64)
                        } else {
                            Slot::Done(Ok(d))
                        }
                    }
                    Err(DiscretizeError::TooManyPoints { estimate, .. }) if bound_by_total => {
                        shared.stop.store(true, Ordering::Relaxed);
                        Slot::Limit(before as f64 + estimate)
                    }
                    Err(e) => Slot::Done(Err(e)),
                }
            }
        };
        let done = shared.done.fetch_add(1, Ordering::Relaxed) + 1;
        (shared.progress)(done, shared.total);
        slot
    }
}
