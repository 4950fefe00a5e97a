//! kerf: NURBS cut contours to the motion of a 5-axis laser cutting machine.
//!
//! This facade re-exports the stage crates in pipeline order.

pub use kerf_discretize as discretize;
pub use kerf_format as format;
pub use kerf_nurbs as nurbs;
