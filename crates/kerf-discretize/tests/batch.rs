//! The contract of [`Batch`], the one loop that discretizes many curves (`discretize_all`, the
//! pipeline's `discretize_curves`, `kerf discretize`): results to the sink in input order on
//! the calling thread, the next group walked while the sink works, the pre-check before any
//! walk, the total limit refusing, the first error ending the batch. Walks are counted (the
//! progress reports each finished walk) and evaluations too (`eval-counter`), nothing is timed.

use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;

use kerf_discretize::{
    discretize, Batch, BatchError, BatchRefusal, DiscretizeError, Options, Result,
};
use kerf_nurbs::NurbsCurve;
use nalgebra::{Point3, Vector3};

fn circle(r: f64) -> NurbsCurve {
    NurbsCurve::circle(Point3::origin(), Vector3::z(), r).expect("circle")
}

/// Curves of different sizes, so that the threads finish them out of order.
fn mixed(n: usize) -> Vec<NurbsCurve> {
    let mut curves = kerf_nurbs::smooth_random_curves(3, n / 2, 7);
    curves.extend((0..n - n / 2).map(|k| circle(1.0 + 10.0 * (k % 5) as f64)));
    curves
}

/// A pool of `threads` threads.
fn pool(threads: usize) -> rayon::ThreadPool {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("pool")
}

#[test]
fn the_sink_sees_every_curve_in_input_order_on_the_calling_thread() {
    let curves = mixed(23);
    let opts = Options::with_tolerance(0.01);
    let caller = std::thread::current().id();
    let calls = Mutex::new(Vec::new());
    let progress = |done: usize, total: usize| calls.lock().unwrap().push((done, total));
    let mut seen = Vec::new();
    Batch::new(&curves, |c| c, &opts)
        .expect("checked")
        .in_groups_of(4)
        .each(&progress, |index, d| {
            assert_eq!(std::thread::current().id(), caller, "on the calling thread");
            assert_eq!(d, discretize(&curves[index], &opts), "curve {index}");
            seen.push(index);
            Ok::<(), DiscretizeError>(())
        })
        .expect("every curve");
    assert_eq!(seen, (0..curves.len()).collect::<Vec<_>>(), "input order");
    let mut calls = calls.into_inner().unwrap();
    assert_eq!(calls[0], (0, 23), "the start first");
    calls.sort_unstable();
    assert_eq!(
        calls,
        (0..=23).map(|d| (d, 23)).collect::<Vec<_>>(),
        "one call a walk"
    );
    // An empty batch, and a group of 0 (counted as 1).
    let none: [NurbsCurve; 0] = [];
    let ran = Batch::new(&none, |c| c, &opts)
        .expect("empty")
        .each(&|_, _| {}, |_, _| Err("no curve"));
    assert_eq!(ran, Ok(()));
    let mut seen = Vec::new();
    Batch::new(&curves[..3], |c| c, &opts)
        .expect("checked")
        .in_groups_of(0)
        .each(&|_, _| {}, |index, _| {
            seen.push(index);
            Ok::<(), ()>(())
        })
        .expect("every curve");
    assert_eq!(seen, [0, 1, 2]);
}

#[test]
fn the_next_group_is_walked_while_the_sink_works() {
    // The sink holds curve 0 until a curve of the second group has been walked (the pool is
    // the global one, the sink runs on this thread): without the overlap it would wait in vain.
    let curves: Vec<NurbsCurve> = (0..8).map(|k| circle(5.0 + k as f64)).collect();
    let done = AtomicUsize::new(0);
    let progress = |d: usize, _| {
        done.fetch_max(d, Ordering::Relaxed);
    };
    let mut overlapped = false;
    Batch::new(&curves, |c| c, &Options::with_tolerance(0.01))
        .expect("checked")
        .in_groups_of(4)
        .each(&progress, |index, _| {
            if index == 0 {
                let until = std::time::Instant::now() + std::time::Duration::from_secs(60);
                while done.load(Ordering::Relaxed) <= 4 && std::time::Instant::now() < until {
                    std::thread::yield_now();
                }
                overlapped = done.load(Ordering::Relaxed) > 4;
            }
            Ok::<(), ()>(())
        })
        .expect("every curve");
    assert!(
        overlapped,
        "the second group was walked while the sink held the first"
    );
}

#[test]
fn a_tolerance_a_late_curve_cannot_hold_is_refused_before_any_walk() {
    // The last curve is 1e12 mm long: its rounding margin (~0.1 mm) is known from its control
    // points. No curve is walked, on one thread, counted.
    let mut curves = mixed(10);
    curves.push(NurbsCurve::new(
        2,
        vec![0.0, 0.0, 0.0, 1.0, 1.0, 1.0],
        vec![
            Point3::new(0.0, 0.0, 0.0),
            Point3::new(1e12, 1.0, 0.0),
            Point3::new(1e12, 1e12, 0.0),
        ],
        None,
    ));
    let (refused, work) = pool(1).install(|| {
        kerf_nurbs::counted(|| {
            Batch::new(&curves, |c| c, &Options::with_tolerance(0.01)).map(|_| ())
        })
    });
    match refused {
        Err(BatchRefusal::Curve {
            index: 10,
            source: DiscretizeError::ToleranceBelowMargin { .. },
        }) => {}
        other => panic!("{other:?}"),
    }
    let work = work.expect("counted");
    assert!(work < 100, "{work} evaluations before refusing");
    // Options first.
    let bad = Batch::new(&curves, |c| c, &Options::with_tolerance(-1.0));
    assert!(
        matches!(
            bad,
            Err(BatchRefusal::Options(DiscretizeError::BadOption { .. }))
        ),
        "{bad:?}"
    );
}

#[test]
fn a_group_past_the_total_limit_is_refused_before_the_sink_sees_it() {
    // Forty circles of 50 mm at 0.01 mm, 157 points each, in groups of 10, on one thread (the
    // curves finish in input order, so the curve named is the last).
    let curves: Vec<NurbsCurve> = (0..40).map(|_| circle(50.0)).collect();
    let opts = Options::with_tolerance(0.01);
    let each = discretize(&curves[0], &opts).unwrap().points().len();
    let total = 40 * each;
    let run = |limit: usize| {
        let mut seen = Vec::new();
        let walks = AtomicUsize::new(0);
        let progress = |d: usize, _| {
            walks.fetch_max(d, Ordering::Relaxed);
        };
        let r = pool(1).install(|| {
            Batch::new(&curves, |c| c, &opts)
                .expect("checked")
                .in_groups_of(10)
                .with_max_total_points(limit)
                .each(&progress, |index, d: Result<_>| {
                    d.expect("each fits");
                    seen.push(index);
                    Ok::<(), ()>(())
                })
        });
        (r, seen, walks.into_inner())
    };
    let (r, seen, walks) = run(total - 1);
    assert_eq!(
        r,
        Err(BatchError::TooManyPoints {
            limit: total - 1,
            reached: total as f64,
            index: 39,
        })
    );
    assert_eq!(
        seen,
        (0..30).collect::<Vec<_>>(),
        "the groups before the last"
    );
    assert_eq!(walks, 40);
    let (r, seen, _) = run(total);
    assert_eq!(r, Ok(()), "exactly the limit fits");
    assert_eq!(seen.len(), 40);
    // Past the limit in the first group: the curves after it are not walked.
    let (r, seen, walks) = run(3 * each + 10);
    assert!(
        matches!(r, Err(BatchError::TooManyPoints { index: 3, .. })),
        "{r:?}"
    );
    assert!(seen.is_empty(), "{seen:?}");
    assert_eq!(
        walks, 4,
        "the curves after the one that passed it are not walked"
    );
}

#[test]
fn a_curve_estimated_above_twice_what_is_left_is_refused_without_its_walk() {
    // A circle of radius 700 at 1e-9 mm needs about 1.85 million points; under a total limit
    // of 1,000 it is refused from its estimate, counted on one thread: far fewer evaluations
    // than points. Around it, lines of two points.
    let line = NurbsCurve::new(
        1,
        vec![0.0, 0.0, 1.0, 1.0],
        vec![Point3::origin(), Point3::new(10.0, 0.0, 0.0)],
        None,
    );
    let curves = [line.clone(), circle(700.0), line];
    let opts = Options::with_tolerance(1e-9);
    let (r, work) = pool(1).install(|| {
        kerf_nurbs::counted(|| {
            Batch::new(&curves, |c| c, &opts)
                .expect("checked")
                .with_max_total_points(1000)
                .each(&|_, _| {}, |_, _| Ok::<(), ()>(()))
        })
    });
    match r {
        Err(BatchError::TooManyPoints {
            limit: 1000,
            reached,
            index: 1,
        }) => assert!(reached > 1.8e6, "the estimate: {reached}"),
        other => panic!("{other:?}"),
    }
    let work = work.expect("counted");
    assert!(work < 200_000, "{work} evaluations");
}

#[test]
fn a_failing_sink_ends_the_batch_and_the_groups_after_the_next_are_not_walked() {
    // On one thread the next group is walked after the sink returns: it fails at curve 5 (the
    // second group), so the third group's curves are stopped before their walks and the
    // fourth is never started.
    let curves = mixed(16);
    let walks = AtomicUsize::new(0);
    let progress = |d: usize, _| {
        walks.fetch_max(d, Ordering::Relaxed);
    };
    let mut seen = Vec::new();
    let r = pool(1).install(|| {
        Batch::new(&curves, |c| c, &Options::with_tolerance(0.01))
            .expect("checked")
            .in_groups_of(4)
            .each(&progress, |index, _| {
                seen.push(index);
                if index == 5 {
                    return Err("full disk");
                }
                Ok(())
            })
    });
    assert_eq!(
        r,
        Err(BatchError::Sink {
            index: 5,
            source: "full disk"
        })
    );
    assert_eq!(seen, [0, 1, 2, 3, 4, 5]);
    assert_eq!(walks.into_inner(), 8, "two groups walked, no more");
}

#[test]
fn failed_curves_go_to_the_sink_which_may_go_on() {
    // Curve 1 needs more than max_points; a sink that keeps every result sees it in its place.
    let curves = [circle(1.0), circle(500.0), circle(2.0)];
    let opts = Options::with_tolerance(0.01).with_max_points(200);
    let mut results = Vec::new();
    Batch::new(&curves, |c| c, &opts)
        .expect("checked")
        .each(&|_, _| {}, |_, r| {
            results.push(r);
            Ok::<(), ()>(())
        })
        .expect("the sink goes on");
    assert!(results[0].is_ok() && results[2].is_ok(), "{results:?}");
    assert!(
        matches!(
            results[1],
            Err(DiscretizeError::TooManyPoints { limit: 200, .. })
        ),
        "{:?}",
        results[1]
    );
    // The error keeps its source.
    let e: BatchError<DiscretizeError> = BatchError::Sink {
        index: 1,
        source: results.swap_remove(1).unwrap_err(),
    };
    let source = std::error::Error::source(&e).expect("source");
    assert!(source.to_string().contains("more than 200"), "{source}");
}
