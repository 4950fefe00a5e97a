//! The error type of the kinematics crate.
//!
//! Machine-file errors name the JSON path of the defect, e.g.
//! `kinematics.r_a: must be finite and >= 0 (got NaN)` or `limits.A: min 10 > max -10`; path
//! errors name the path id, the index of the cutting point and the axis, e.g.
//! `path "rim": point 73: C = 362 is outside its limits [-360, 360]; ...`.

use std::sync::Arc;

use thiserror::Error;

/// An operating-system error that kerf's error enums can hold, clone and compare while
/// keeping it as their [`source`](std::error::Error::source).
///
/// The [`std::io::Error`] is shared (clones point at the same one); two are equal when their
/// kind and message are (an `io::Error` itself is neither `Clone` nor `PartialEq`). It
/// dereferences to the `io::Error` and is deliberately not an [`std::error::Error`] itself, so
/// that a `#[source]` field of this type makes the `io::Error` the next link of the chain
/// (`downcast_ref::<std::io::Error>()` finds it).
#[derive(Debug, Clone)]
pub struct IoError(Arc<std::io::Error>);

impl IoError {
    /// Keeps `error`.
    pub fn new(error: std::io::Error) -> Self {
        Self(Arc::new(error))
    }
}

impl From<std::io::Error> for IoError {
    fn from(error: std::io::Error) -> Self {
        Self::new(error)
    }
}

impl std::ops::Deref for IoError {
    type Target = std::io::Error;
    fn deref(&self) -> &std::io::Error {
        &self.0
    }
}

impl PartialEq for IoError {
    fn eq(&self, other: &Self) -> bool {
        self.0.kind() == other.0.kind() && self.0.to_string() == other.0.to_string()
    }
}

impl std::fmt::Display for IoError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        self.0.fmt(f)
    }
}

/// A [`KinematicsError`] on the heap, for the error enums of later stages that keep one as
/// their source (`kerf_interp::InterpError::Kinematics`, the pipeline's error) without growing
/// every `Result` by its size.
///
/// It dereferences to the error and is deliberately not an [`std::error::Error`] itself: a
/// `#[source] Box<KinematicsError>` would make the *box* the next link of the chain, which
/// `downcast_ref::<KinematicsError>()` does not find; with this type the link is the
/// `KinematicsError`.
#[derive(Debug, Clone, PartialEq)]
pub struct BoxedKinematicsError(Box<KinematicsError>);

impl BoxedKinematicsError {
    /// The error, unboxed.
    pub fn into_inner(self) -> KinematicsError {
        *self.0
    }
}

impl From<KinematicsError> for BoxedKinematicsError {
    fn from(error: KinematicsError) -> Self {
        Self(Box::new(error))
    }
}

impl std::ops::Deref for BoxedKinematicsError {
    type Target = KinematicsError;
    fn deref(&self) -> &KinematicsError {
        &self.0
    }
}

impl std::fmt::Display for BoxedKinematicsError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        self.0.fmt(f)
    }
}

/// `Result` with [`KinematicsError`].
pub type Result<T> = std::result::Result<T, KinematicsError>;

/// Everything that can go wrong when reading a machine, solving a path or writing axes.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum KinematicsError {
    /// An error inside the file `file` (added by [`crate::Machine::read`]).
    /// Fix: see `error`.
    #[error("{file}: {error}")]
    File {
        /// The file, as given.
        file: String,
        /// What is wrong in it.
        #[source]
        error: Box<KinematicsError>,
    },
    /// A file could not be read or written (nothing was written to the destination).
    /// Fix: check the path, the directory and its permissions.
    #[error("{file}: cannot {action}: {source}")]
    Io {
        /// The file, as given.
        file: String,
        /// `"read"` or `"write"`.
        action: &'static str,
        /// The operating system's error (its [`std::io::Error`] is the source of this one).
        #[source]
        source: IoError,
    },
    /// The document is not well-formed JSON (or holds a number out of the range of a double,
    /// such as `1e400`). Fix: correct the text at the given line and column.
    #[error("invalid JSON at line {line}, column {column}: {message}")]
    Syntax {
        /// Line, from 1.
        line: usize,
        /// Column, from 1.
        column: usize,
        /// What the parser found wrong.
        message: String,
    },
    /// A value of a `kerf.machine/1` (or `kerf.axes/1`) document is missing, of the wrong type or
    /// out of range; `path` is its JSON path, e.g. `kinematics.r_a` or `limits.A`.
    /// Fix: see `docs/formats.md` and the message.
    #[error("{path}: {message}")]
    Document {
        /// The JSON path of the defect (`format`, `kinematics.type`, `limits.A[0]`, ...).
        path: String,
        /// What is wrong, and what was found.
        message: String,
    },
    /// An option is out of range. Fix: see the option's documentation in
    /// [`crate::PathOptions`].
    #[error("option {name}: {reason} (got {value})")]
    BadOption {
        /// The option's name.
        name: &'static str,
        /// The value given.
        value: f64,
        /// What is wrong with it.
        reason: &'static str,
    },
    /// A pose or the parameters of a path are unusable (not finite, a tool axis of length far
    /// from 1, params not increasing, ...). Fix: regenerate the toolpath with normals.
    #[error("path \"{path_id}\": point {index}: {reason}")]
    BadPose {
        /// The id of the path.
        path_id: String,
        /// The index of the cutting point.
        index: usize,
        /// What is wrong.
        reason: String,
    },
    /// No inverse solution of a cutting point (or of a point inserted before it) fits the axis
    /// limits while keeping the axes continuous. `axis` is the axis the preferred (least
    /// travel) solution violates; `detail` says why the other solution does not help either.
    /// Fix: move or re-fixture the part, or check the limits of the machine file.
    #[error("path \"{path_id}\": point {index}{}: {axis} = {value} is outside its limits [{min}, {max}]; {detail}", if *.inserted { " (at a point inserted before it)" } else { "" })]
    OutOfLimits {
        /// The id of the path.
        path_id: String,
        /// The index of the cutting point.
        index: usize,
        /// True if the failing point is one inserted between cutting points `index - 1` and
        /// `index`.
        inserted: bool,
        /// The axis name: `X`, `Y`, `Z`, `A`, `B` or `C`.
        axis: &'static str,
        /// The axis value the preferred solution needs.
        value: f64,
        /// The lower limit of that axis.
        min: f64,
        /// The upper limit of that axis.
        max: f64,
        /// Why the other solution is not used.
        detail: String,
    },
    /// The axes must jump between two poses that are (numerically) the same, so no number of
    /// inserted points makes the motion continuous. Fix: split the path at that point.
    #[error("path \"{path_id}\": point {index}: the axes jump ({detail}); split the path there")]
    Discontinuity {
        /// The id of the path.
        path_id: String,
        /// The index of the cutting point.
        index: usize,
        /// Which axes jump, and by how much.
        detail: String,
    },
    /// No placement of the part puts every pose within the machine's limits
    /// ([`crate::auto_place`]). `axis` is the axis that falls short for the best candidate and
    /// `missing` by how much (mm, or degrees for a rotary axis). Fix: a machine with more
    /// travel, or cut the part's contours in several set-ups.
    #[error("no placement fits the machine: {axis} is {missing:.3} short ({detail}; {rotations_tried} rotations tried)")]
    NoPlacement {
        /// The axis name.
        axis: &'static str,
        /// How much travel is missing, mm or degrees.
        missing: f64,
        /// What needs it.
        detail: String,
        /// How many rotations of the part were tried.
        rotations_tried: usize,
    },
    /// A single pose has no inverse solution within the axis ranges, or is no pose at all (a
    /// tool axis that is not a unit vector, a non-finite tip): what the point-by-point inverse
    /// of the interpolator's machine models reports. Fix: a tool axis of length 1, a point
    /// within reach of the machine (move the part), or solve the whole path with
    /// [`crate::solve_path`], which says which axis and limit.
    #[error("{reason}")]
    Unreachable {
        /// What is wrong, e.g. `no solution within the axis ranges`.
        reason: String,
    },
    /// More than [`crate::PathOptions::max_inserted`] points would have to be inserted in
    /// one path. Fix: raise `linearization_tolerance_mm` or `max_rotary_step_deg`, or the limit.
    #[error("path \"{path_id}\": more than {limit} points would have to be inserted (at point {index}); raise linearization_tolerance_mm or max_rotary_step_deg")]
    TooManyInserted {
        /// The id of the path.
        path_id: String,
        /// The index of the cutting point being reached.
        index: usize,
        /// The limit.
        limit: usize,
    },
}

impl KinematicsError {
    /// The error without the [`KinematicsError::File`] wrapper, for matching.
    pub fn without_file(&self) -> &KinematicsError {
        match self {
            KinematicsError::File { error, .. } => error.without_file(),
            other => other,
        }
    }

    /// A [`KinematicsError::Document`] error.
    pub(crate) fn doc(path: impl Into<String>, message: impl Into<String>) -> Self {
        KinematicsError::Document {
            path: path.into(),
            message: message.into(),
        }
    }
}
