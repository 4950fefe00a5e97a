//! The errors of the STEP reader. Every message names the place: a line of the file for syntax,
//! the entity (`#23805 COMPOSITE_CURVE: ...`) for content.

use std::path::PathBuf;

/// What can go wrong reading a STEP file.
#[derive(Debug, thiserror::Error)]
pub enum StepError {
    /// The file could not be read. Fix: check the path and permissions. (The message leaves
    /// the path to the [`FileError`] around it, which names the file once.)
    #[error("cannot read: {source}")]
    Read {
        /// The file.
        path: PathBuf,
        /// The I/O error.
        source: std::io::Error,
    },
    /// The exchange structure is malformed (Part 21 syntax). Fix: re-export the file from the
    /// CAD system; the line number shows where the text stops being STEP.
    #[error("line {line}: {message}")]
    Syntax {
        /// 1-based line number.
        line: usize,
        /// What was expected and found.
        message: String,
    },
    /// Two instances have the same `#id`. Fix: re-export the file; ids must be unique.
    #[error("line {line}: #{id} is defined twice")]
    DuplicateId {
        /// The id.
        id: u64,
        /// Line of the second definition.
        line: usize,
    },
    /// An entity kerf needs is malformed, refers to a missing instance, or describes geometry
    /// that cannot be converted (a zero radius, a segment gap too large to close). Fix: repair
    /// the entity named in the CAD system, or choose other contours.
    #[error("#{id} {name}: {message}")]
    Entity {
        /// The `#id`.
        id: u64,
        /// The entity name (complex instances: the partial names joined by `+`).
        name: String,
        /// The defect.
        message: String,
    },
    /// An entity's numbers do not make a valid curve or surface (knots out of order, a weight
    /// that is not positive, too few control points for the degree); the evaluator's error is
    /// the source. Fix: repair the entity named in the CAD system.
    #[error("#{id} {name}: {source}")]
    Geometry {
        /// The `#id`.
        id: u64,
        /// The entity name.
        name: String,
        /// What the evaluator refused (boxed: it is larger than every other variant).
        #[source]
        source: Box<kerf_nurbs::NurbsError>,
    },
    /// The file holds no contour kerf can cut: no curve in a geometric set or wireframe model
    /// (and, with `--edges`, no face with a boundary loop). Fix: export the cut lines as a
    /// geometric set / wireframe, or use `--edges` to cut the boundary loops of faces.
    #[error("no usable contour: {reason}")]
    NoContour {
        /// What was found instead, and what was skipped.
        reason: String,
    },
    /// The file asks for more work or memory than the reader grants any file: more entity
    /// instances, segments, control points or face tests than a budget allows. A real part
    /// stays far below each (`docs/step.md` lists them). Fix: export only the part to cut, or
    /// repair the entity named (a composite that uses its segments many times over).
    #[error("{place}: more {what} than the reader's budget of {limit}")]
    Budget {
        /// What was counted.
        what: String,
        /// The budget.
        limit: u64,
        /// Where it was crossed: the entity (`#23805 COMPOSITE_CURVE`) or the line.
        place: String,
    },
    /// An option is out of range. Fix: pass a finite positive value.
    #[error("{0}")]
    Options(String),
}

impl StepError {
    /// Adds the file path in front of a syntax or content error.
    pub fn in_file(self, path: impl Into<PathBuf>) -> FileError {
        FileError {
            path: path.into(),
            error: self,
        }
    }
}

/// A [`StepError`] with the file it came from.
#[derive(Debug, thiserror::Error)]
#[error("{}: {error}", path.display())]
pub struct FileError {
    /// The STEP file.
    pub path: PathBuf,
    /// What went wrong.
    #[source]
    pub error: StepError,
}

/// The result type of this crate.
pub type Result<T> = std::result::Result<T, StepError>;
