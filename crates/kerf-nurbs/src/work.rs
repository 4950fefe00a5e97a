//! Counting the work of the evaluator, to test work budgets by counting rather than timing.
//!
//! With the cargo feature `eval-counter`, every curve or surface evaluation (a point, a set of
//! derivatives, a rational Bezier piece extracted from a span, a de Casteljau subdivision) adds
//! one to a per-thread counter. Tests read it before and after a call to assert that an adaptive
//! algorithm stayed within its budget. Without the feature (the default, and every release
//! build of the CLI) [`tick`] compiles to nothing and [`evaluations`] returns `None`.

#[cfg(feature = "eval-counter")]
thread_local! {
    static EVALUATIONS: std::cell::Cell<u64> = const { std::cell::Cell::new(0) };
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
