//! Counting the work of the evaluator, to test work budgets by counting rather than timing.
//!
//! With the cargo feature `eval-counter`, every curve or surface evaluation (a point, a set of
//! derivatives, a rational Bezier piece extracted from a span, a de Casteljau subdivision) adds
//! one to a per-thread counter. Tests read it before and after a call to assert that an adaptive
//! algorithm stayed within its budget. Without the feature (the default, and every release
//! build of the CLI) [`tick`] compiles to nothing and [`evaluations`] returns `None`.
//!
//! A second counter, [`knot_reads`], counts the knots that the knot-vector scans
//! ([`crate::multiplicity`], [`crate::interior_knots`]) read: a scan per knot is quadratic on a
//! curve with many knots, which the evaluation count alone does not show.

#[cfg(feature = "eval-counter")]
thread_local! {
    static EVALUATIONS: std::cell::Cell<u64> = const { std::cell::Cell::new(0) };
    static KNOT_READS: std::cell::Cell<u64> = const { std::cell::Cell::new(0) };
}

/// Counts one unit of work on the current thread (no-op without the `eval-counter` feature).
#[inline(always)]
pub fn tick() {
    #[cfg(feature = "eval-counter")]
    EVALUATIONS.with(|c| c.set(c.get() + 1));
}

/// The number of evaluations counted on the current thread so far, or `None` when the crate
/// was built without the `eval-counter` feature (then nothing is counted).
pub fn evaluations() -> Option<u64> {
    #[cfg(feature = "eval-counter")]
    {
        Some(EVALUATIONS.with(std::cell::Cell::get))
    }
    #[cfg(not(feature = "eval-counter"))]
    {
        None
    }
}

/// Runs `f` and returns its result with the evaluations it made on the current thread (`None`
/// without the `eval-counter` feature).
pub fn counted<T>(f: impl FnOnce() -> T) -> (T, Option<u64>) {
    let before = evaluations();
    let out = f();
    let after = evaluations();
    (out, after.zip(before).map(|(a, b)| a - b))
}

/// Counts `n` knots read by a scan of a knot vector (no-op without the `eval-counter` feature).
#[inline(always)]
pub fn tick_knots(n: usize) {
    #[cfg(feature = "eval-counter")]
    KNOT_READS.with(|c| c.set(c.get() + n as u64));
    #[cfg(not(feature = "eval-counter"))]
    let _ = n;
}

/// The number of knots read by knot-vector scans on the current thread so far, or `None`
/// without the `eval-counter` feature.
pub fn knot_reads() -> Option<u64> {
    #[cfg(feature = "eval-counter")]
    {
        Some(KNOT_READS.with(std::cell::Cell::get))
    }
    #[cfg(not(feature = "eval-counter"))]
    {
        None
    }
}
