//! The inverse-solution choice, the one rule every solver of kerf applies (the path solver of
//! this crate, the interpolator's machine models): a pose has two solutions (`(t, C)` and
//! `(-t, C + 180)`), each angle is free by whole turns; the axes to use are the candidate, at
//! the turns nearest the previous axes, with the least rotary travel from them
//! ([`Axes::rotary_travel`], degrees) among those the machine's limits accept.

use crate::pose::Axes;

/// `value + 360 k` nearest `reference` (degrees).
#[inline]
pub fn nearest_turn(value: f64, reference: f64) -> f64 {
    value + 360.0 * ((reference - value) / 360.0).round()
}

/// The turns of `value` worth trying from `reference` (degrees): the nearest, then one turn
/// below and one above it (for an axis whose limits exclude the nearest).
#[inline]
pub fn turns_near(value: f64, reference: f64) -> [f64; 3] {
    let near = nearest_turn(value, reference);
    [near, near - 360.0, near + 360.0]
}

/// Of the `candidates` (inverse solutions of one pose), with tilt and C each taken at the
/// turns [`turns_near`] the `previous` axes, the one with the least
/// [`Axes::rotary_travel`] from `previous` that `fits` accepts; on a tie the earlier
/// candidate and the nearer turn. X, Y and Z are kept as given: they do not depend on whole
/// turns. `None` when `fits` accepts no candidate at any of those turns.
pub fn nearest_solution(
    candidates: impl IntoIterator<Item = Axes>,
    previous: &Axes,
    fits: impl Fn(&Axes) -> bool,
) -> Option<Axes> {
    let mut best: Option<(Axes, f64)> = None;
    for q in candidates {
        for tilt in turns_near(q.tilt, previous.tilt) {
            for c in turns_near(q.c, previous.c) {
                let turned = Axes { tilt, c, ..q };
                if !fits(&turned) {
                    continue;
                }
                let travel = previous.rotary_travel(&turned);
                if best.as_ref().is_none_or(|(_, t)| travel < *t) {
                    best = Some((turned, travel));
                }
            }
        }
    }
    best.map(|(q, _)| q)
}
