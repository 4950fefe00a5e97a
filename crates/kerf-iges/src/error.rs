//! The errors of the IGES reader. Every message names the place: a line of the file for the
//! fixed-column layout, the entity (`D45 (126 rational B-spline curve): ...`) for content.

use std::path::PathBuf;

/// What can go wrong reading an IGES file.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum IgesError {
    /// The file could not be read. Fix: check the path and permissions. (The message leaves
    /// the path to the [`FileError`] around it, which names the file once.)
    #[error("cannot read: {source}")]
    Read {
        /// The file.
        path: PathBuf,
        /// The I/O error.
        source: std::io::Error,
    },
    /// The file is not laid out as IGES (80-column records, sections S G D P T in order,
    /// directory entries of two lines, parameters ending in the record delimiter). Fix:
    /// re-export the file from the CAD system; the line shows where the text stops being IGES.
    #[error("line {line}: {message}")]
    Syntax {
        /// 1-based line number.
        line: usize,
        /// What was expected and found.
        message: String,
    },
    /// An entity kerf needs is malformed, points at a missing entity, or describes geometry
    /// that cannot be converted. Fix: repair the entity named (by its directory entry number)
    /// in the CAD system, or choose other contours.
    #[error("D{de} ({kind}): {message}")]
    Entity {
        /// The directory entry number (the sequence number of its first `D` line).
        de: usize,
        /// The entity type and its name (`126 rational B-spline curve`).
        kind: String,
        /// The defect.
        message: String,
    },
    /// The file holds no contour kerf can cut. Fix: export the cut lines as curves, or use
    /// `--edges` to cut the boundary loops of the trimmed surfaces.
    #[error("no usable contour: {reason}")]
    NoContour {
        /// What was found instead, and what was skipped.
        reason: String,
    },
    /// The file asks for more work or memory than the reader grants any file (`docs/iges.md`
    /// lists the budgets). Fix: export only the part to cut.
    #[error("{place}: more {what} than the reader's budget of {limit}")]
    Budget {
        /// What was counted.
        what: String,
        /// The budget.
        limit: u64,
        /// Where it was crossed.
        place: String,
    },
    /// An option is out of range. Fix: pass a finite positive value.
    #[error("{0}")]
    Options(String),
}

impl IgesError {
    /// Adds the file path in front of the error.
    pub fn in_file(self, path: impl Into<PathBuf>) -> FileError {
        FileError {
            path: path.into(),
            error: self,
        }
    }
}

/// An [`IgesError`] with the file it came from.
#[derive(Debug, thiserror::Error)]
#[error("{}: {error}", path.display())]
pub struct FileError {
    /// The IGES file.
    pub path: PathBuf,
    /// What went wrong.
    #[source]
    pub error: IgesError,
}

/// The result type of this crate.
pub type Result<T> = std::result::Result<T, IgesError>;
