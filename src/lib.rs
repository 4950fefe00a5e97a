//! kerf: NURBS cut contours to the motion of a 5-axis laser cutting machine.
//!
//! This facade re-exports the stage crates in pipeline order; read them in that order:
//!
//! 1. [`nurbs`]: rational curves and surfaces (evaluation, derivatives, Bezier pieces).
//! 2. [`format`](mod@format): `kerf.curves/1` in, `kerf.toolpath/1` out; [`step`]: the same
//!    contours and faces read from a STEP file.
//! 3. [`discretize`]: cutting points with a certified chord error.
//! 4. [`normals`]: the surface normal of every cutting point.
//! 5. [`kinematics`]: poses to machine axes, `kerf.axes/1`.
//! 6. [`interp`]: time-division interpolation, feed planning, set-points and G-code.

pub use kerf_discretize as discretize;
pub use kerf_format as format;
pub use kerf_interp as interp;
pub use kerf_kinematics as kinematics;
pub use kerf_normals as normals;
pub use kerf_nurbs as nurbs;
pub use kerf_step as step;
