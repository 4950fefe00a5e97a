//! Five-axis kinematics: poses `(x, y, z, i, j, k)` to machine axes `[X, Y, Z, A|B, C]`.
//!
//! The stage after the discretizer (and its normals): a cutting point with its tool axis is a
//! [`Pose`]; a [`Machine`] (`kerf.machine/1`, `docs/formats.md`) turns it into [`Axes`] by
//! inverse kinematics, and [`solve_path`] does so along a whole path, keeping the axes
//! continuous and within their limits, handling the pole, and inserting poses where the
//! controller's linear axis interpolation would take the tool tip off the path
//! ([`linearization_error`], paper 002). [`AxesFile`] writes the result as `kerf.axes/1`.
//!
//! Four kinematic types, one file each: [`AcHead`] (the laser head of paper 000),
//! [`ForkHead`] (a double swing head), [`TableTable`] (LinuxCNC's `xyzac-trt`) and
//! [`HeadTable`] (a B head over a C table). Each implements [`Kinematics`]; a fifth is one
//! new file and one line in the registry. The derivations, hand-checked values and the error
//! budget are in `docs/kinematics.md`.
//!
//! ```
//! use kerf_kinematics::{solve_path, Kinematics, Machine, PathInput, PathOptions, Pose};
//!
//! let machine = Machine::read(concat!(env!("CARGO_MANIFEST_DIR"), "/../../fixtures/machines/ac_head.json"))?;
//! // Tip at (100, 50, 20), tool axis tilted 30 degrees toward +x.
//! let pose = Pose::new(100.0, 50.0, 20.0, 0.5, 0.0, 0.75_f64.sqrt());
//! let [first, second] = machine.kinematics.inverse(&pose);
//! assert!((first.tilt - 30.0).abs() < 1e-12 && (first.c - 90.0).abs() < 1e-12, "{first:?}");
//! assert!((second.tilt + 30.0).abs() < 1e-12 && (second.c - 270.0).abs() < 1e-12, "{second:?}");
//! let back = machine.kinematics.forward(&first);
//! assert!((back.position - pose.position).norm() < 1e-12, "forward undoes inverse");
//!
//! let poses = [pose, Pose::new(101.0, 50.0, 20.0, 0.5, 0.0, 0.75_f64.sqrt())];
//! let input = PathInput { id: "demo", poses: &poses, curve: None };
//! let solved = solve_path(&machine, &input, &PathOptions::default())?;
//! assert_eq!(solved.axes.len(), 2, "a pure translation needs no inserted point");
//! # Ok::<(), kerf_kinematics::KinematicsError>(())
//! ```

mod ac_head;
mod axes_file;
mod choice;
mod error;
mod fork_head;
mod head;
mod head_table;
mod json;
mod kinematics;
mod machine;
mod nonlinear;
mod params;
mod path;
mod placement;
mod pose;
mod registry;
mod rotation;
mod table_table;
mod technology;
mod tilt;

pub use ac_head::AcHead;
pub use axes_file::{AxesFile, AxesMove, AxesPath, AXES_FORMAT};
pub use choice::{nearest_solution, nearest_turn, turns_near};
pub use error::{BoxedKinematicsError, IoError, KinematicsError, Result};
pub use fork_head::{ForkHead, ForkTilt};
pub use head::{Head, HeadSolid, MAX_HEAD_SIZE_MM, MAX_HEAD_SOLIDS};
pub use head_table::HeadTable;
pub use kinematics::{Kinematics, Parameter};
pub use machine::{
    process_line_defect, Machine, Process, Range, DEFAULT_STANDOFF_MM, MACHINE_FORMAT,
    MAX_KERF_WIDTH_MM, MAX_PIERCE_DWELL_S, MAX_PIERCE_STANDOFF_MM, MAX_PROCESS_LINES,
    MAX_PROCESS_LINE_CHARS,
};
pub use nonlinear::{interpolate, linearization_error, slerp, Deviation};
pub use path::{solve_path, solve_paths, PathCurve, PathInput, PathOptions, SolvedPath};
pub use path::{
    DEFAULT_POLE_TOLERANCE_DEG, LIMIT_SLACK, MAX_TILT_TOLERANCE_DEG, UNIT_AXIS_TOLERANCE,
};
pub use placement::{
    auto_place, auto_setups, axis_aligned_rotations, place_paths, AutoPlaceOptions, AutoPlacement,
    Placement, PlacementParseError, Setup, SetupPlan, MAX_PLACEMENT_VALUE,
};
pub use pose::{Axes, Axis, Pose};
pub use registry::kinematics_types;
pub use table_table::TableTable;
pub use technology::{
    CornerRule, MicroJoints, Pierce, SmallHole, Technology, TechnologyEntry,
    DEFAULT_POWER_MIN_SHARE, MAX_TECHNOLOGY_ENTRIES, TECHNOLOGY_FORMAT,
};
pub use tilt::{
    tilt_within_cone, tilt_within_cones, Cone, TiltChoice, TiltReport, TILT_WORKING_FRACTION,
};
