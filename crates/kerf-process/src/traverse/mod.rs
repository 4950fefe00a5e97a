//! Traverses between cuts that clear the part: retract along the tool axis, travel at a
//! clearance the part's surfaces cannot reach, approach along the next tool axis, checked
//! against the surfaces (NURBS through the global closest point, meshes through parry3d).
//!
//! The check rests on one fact: the distance `d(x)` from a point to a set of surfaces is
//! 1-Lipschitz, `|d(x) - d(y)| <= |x - y|`. So if samples spaced at most `h` apart along a
//! segment all have `d >= c + h / 2`, every point of the segment has `d >= c`. The distances
//! come from exact queries (the NURBS closest point's global search, parry's triangle
//! projection), so the claim is as good as those queries; surfaces whose bounding box (of
//! the control points for a NURBS surface, which contains it) is farther than the threshold
//! are not queried. The derivation and the routes are in `docs/process.md`.

mod boxes;
mod check;
mod obstacles;
mod options;
mod probe;
mod proof;
mod routes;
mod search;
mod tessellated;

pub use check::check_move;
pub use obstacles::Obstacles;
pub use options::TraverseOptions;
pub use routes::{plan_traverse, plan_traverse_within, Route, Traverse};
pub(crate) use routes::{plan_traverse_accepting, retract_heights, Refusal};
