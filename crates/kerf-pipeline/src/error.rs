//! [`Error`]: the one error type of a job, every stage's error with the place it happened.

use std::path::{Path, PathBuf};

/// Why a job (or one of its stages) failed.
///
/// Every variant keeps the stage crate's own error as its [`source`](std::error::Error::source)
/// and says where it happened: the input file (when the job was given one, see
/// [`crate::Job::with_source`]) and the curve's index and id in the form
/// `part.json: curves[3] ("outline"): ...`.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// An input file is unreadable or invalid; the message names the file and the JSON path of
    /// the defect. Fix: the file (see `docs/formats.md`).
    #[error(transparent)]
    Format(#[from] kerf_format::FormatError),
    /// A STEP file could not be read into contours ([`crate::Job::from_step`]); the message names
    /// the file and the entity (`#23805 COMPOSITE_CURVE: segment 12 (#23790): ...`). Fix: the
    /// file, or the import options (`--edges` for a solid without cut curves).
    #[error(transparent)]
    Step(#[from] kerf_step::FileError),
    /// An IGES file could not be read into contours ([`crate::Job::from_cad`]); the message
    /// names the file and the entity by its directory entry (`D45 (126 rational B-spline
    /// curve): ...`). Fix: the file, or the import options.
    #[error(transparent)]
    Iges(#[from] kerf_iges::FileError),
    /// A STEP or IGES import gave a curves document that does not pass `kerf.curves/1`'s
    /// checks (a reader defect, reported rather than run). Fix: report the file.
    #[error("{}: the import is not valid kerf.curves/1: {source}", file.display())]
    StepDocument {
        /// The STEP or IGES file.
        file: PathBuf,
        /// Why the document is invalid.
        #[source]
        source: kerf_format::FormatError,
    },
    /// A discretizer option is out of range; nothing was computed. Fix: the option named.
    #[error(transparent)]
    Options(kerf_discretize::DiscretizeError),
    /// An option of the job or of the motion stage lies outside its documented range
    /// ([`crate::ranges`]): `option feed_mm_per_min: must be > 0 mm/min and <= 1e6 mm/min (got
    /// 2e6; ...)`. Nothing was computed. Fix: a value within the range the message states.
    #[error("option {name}: {requirement}")]
    BadOption {
        /// The option, as its field is named (`traverse.clearance_mm`).
        name: &'static str,
        /// The value given.
        value: f64,
        /// The range and the value: `must be > 0 mm and <= 1000 mm (got 2e4)`.
        requirement: String,
    },
    /// A curve could not be discretized (too many points for the tolerance, a tolerance below
    /// the precision of the curve's coordinates, the work budget). Fix: the tolerance or
    /// `max_points`.
    #[error("{}curves[{index}] ({id:?}): {source}", at(file))]
    Discretize {
        /// The curves file, when known.
        file: Option<PathBuf>,
        /// Index of the curve in `curves`.
        index: usize,
        /// Its id.
        id: String,
        /// What went wrong.
        #[source]
        source: kerf_discretize::DiscretizeError,
    },
    /// The job needs more cutting points than its limit (`max_total_points` of
    /// [`crate::JobOptions`] or [`crate::discretize_curves_within`]), found from the
    /// discretizer's estimate before a curve's points are allocated or from the running total.
    /// Nothing after discretization was computed. Fix: a coarser tolerance, fewer curves, or a
    /// higher limit.
    #[error(
        "{}the job needs more than {limit} cutting points (at least {reached:.0} by curves[{index}] ({id:?})); raise the limit (max_total_points) or the tolerance",
        at(file)
    )]
    TooManyPoints {
        /// The curves file, when known.
        file: Option<PathBuf>,
        /// The job's limit on the total cutting points.
        limit: usize,
        /// The total reached or estimated when the limit was passed.
        reached: f64,
        /// Index of the curve that passed it (depends on the order the threads finished in).
        index: usize,
        /// Its id.
        id: String,
    },
    /// A curve's normals could not be found (a point off its surface, a reversed surface, ...),
    /// or a surface cannot give normals (a degenerate mesh). Fix: the surface or the curve.
    #[error("{}{place}: {source}", at(file))]
    Normals {
        /// The curves file, when known.
        file: Option<PathBuf>,
        /// Where: `curves[3] ("id")` or `surfaces[1] ("id")`.
        place: String,
        /// What went wrong.
        #[source]
        source: kerf_normals::NormalsError,
    },
    /// Normals were asked for a curve that names no surface
    /// ([`crate::MissingSurface::Error`]). Fix: add `"surface": "<id>"` to the curve, or cut it
    /// with a vertical beam ([`crate::MissingSurface::Vertical`]).
    #[error(
        "{}curves[{index}] ({id:?}): normals need a surface, but the curve names none (add \"surface\": \"<id>\")",
        at(file)
    )]
    MissingSurface {
        /// The curves file, when known.
        file: Option<PathBuf>,
        /// Index of the curve in `curves`.
        index: usize,
        /// Its id.
        id: String,
    },
    /// A curve or surface built in code is invalid (the reader refuses files with these
    /// defects): a NURBS defect, or a duplicate id or one with a control character (ids go
    /// into programs). Fix: the value named.
    #[error("{}{place}: {message}", at(file))]
    Invalid {
        /// The curves file, when known.
        file: Option<PathBuf>,
        /// Where: `curves[3] ("id")` or `surfaces[1] ("id")`.
        place: String,
        /// What is wrong.
        message: String,
    },
    /// A curve or surface could not be built (a NURBS defect). Fix: the value the message
    /// names.
    #[error(transparent)]
    Nurbs(#[from] kerf_nurbs::NurbsError),
    /// A curve names a surface the file does not have (possible only in a
    /// [`kerf_format::CurvesFile`] built in code: the reader refuses such files). Fix: add the
    /// surface to `surfaces` or correct the id.
    #[error("{}curves[{index}] ({id:?}): no surface with id {surface:?}", at(file))]
    UnknownSurface {
        /// The curves file, when known.
        file: Option<PathBuf>,
        /// Index of the curve in `curves`.
        index: usize,
        /// Its id.
        id: String,
        /// The surface id it names.
        surface: String,
    },
    /// A toolpath's points have no normals, so they cannot be put on a 5-axis machine. Fix:
    /// discretize with normals ([`crate::orient_curves`], `kerf discretize --normals`) curves
    /// that name their surface.
    #[error(
        "{}paths[{index}] ({id:?}): points have no normals; discretize with normals the curves that name their surface",
        at(file)
    )]
    NoNormals {
        /// The toolpath file, when known.
        file: Option<PathBuf>,
        /// Index of the path in `paths`.
        index: usize,
        /// Its id.
        id: String,
    },
    /// A toolpath could not be certified against its curves (`kerf gcode --curves`): its
    /// path has no curve of that id at that index, its params are refused by the certificate,
    /// or its points lie too far off the curve. Fix: discretize the curves again.
    #[error(
        "{}paths[{index}] ({id:?}): not certified against its curve: {reason}{}",
        at(file),
        source.as_ref().map(|e| format!(": {e}")).unwrap_or_default()
    )]
    NotCertified {
        /// The toolpath file, when known.
        file: Option<PathBuf>,
        /// Index of the path in `paths`.
        index: usize,
        /// Its id.
        id: String,
        /// What failed.
        reason: String,
        /// The certificate's refusal, if that is what failed (boxed: the error type stays
        /// small for every `Result` of the pipeline).
        #[source]
        source: Option<Box<kerf_discretize::DiscretizeError>>,
    },
    /// The machine file is invalid, a path cannot be solved on the machine (a pose out of
    /// reach, an axis limit), or no placement fits. Fix: as the message says.
    #[error("{}{source}", at(file))]
    Kinematics {
        /// The input file the path came from, when known.
        file: Option<PathBuf>,
        /// What went wrong.
        #[source]
        source: kerf_kinematics::BoxedKinematicsError,
    },
    /// The interpolator or the G-code writer refused (an option out of range, unusable process
    /// codes, a program the dialect cannot run). Fix: as the message says.
    #[error("{}{source}", at(file))]
    Interp {
        /// The input file, when known.
        file: Option<PathBuf>,
        /// What went wrong.
        #[source]
        source: kerf_interp::InterpError,
    },
    /// The cut planner refused (lead options out of range, a contour too short). Fix: the lead
    /// options or the contour.
    #[error("{}{source}", at(file))]
    Process {
        /// The curves file, when known.
        file: Option<PathBuf>,
        /// What went wrong.
        #[source]
        source: kerf_process::ProcessError,
    },
    /// The picture could not be made.
    #[error(transparent)]
    Plot(#[from] kerf_plot::PlotError),
    /// G-code was asked of a program planned for set-points only
    /// ([`crate::MotionOptions::dialect`] `None`). Fix: plan it with the dialect.
    #[error("this program was planned for set-points only (no dialect); plan it with a dialect to write G-code")]
    NoDialect,
    /// A job has no curve to cut. Fix: give it at least one curve.
    #[error("{}the job has no curve to cut", at(file))]
    NoCurves {
        /// The curves file, when known.
        file: Option<PathBuf>,
    },
    /// Stage results given to a later stage do not belong to its input (one discretization
    /// per curve, one cut per path). Fix: pass the results computed from the same input.
    #[error("inconsistent stage input: {0}")]
    Inconsistent(String),
    /// A file could not be read. Fix: the path or its permissions.
    #[error("{}: cannot read: {source}", path.display())]
    Read {
        /// The file.
        path: PathBuf,
        /// What went wrong.
        #[source]
        source: std::io::Error,
    },
    /// An output could not be written (a writer failed, or the all-or-nothing write of an
    /// output directory; the directory is then left as it was).
    #[error("{}cannot write: {source}", at(path))]
    Write {
        /// The file or directory, when known.
        path: Option<PathBuf>,
        /// What went wrong.
        #[source]
        source: std::io::Error,
    },
}

/// `file: ` or nothing.
fn at(file: &Option<PathBuf>) -> String {
    file.as_deref()
        .map_or_else(String::new, |f| format!("{}: ", f.display()))
}

impl Error {
    /// The error with `file` as the input it is about, where it names no file yet (a stage
    /// error from a job built in code, reported for a file the caller read).
    pub fn in_file(mut self, path: impl AsRef<Path>) -> Self {
        let path = path.as_ref().to_path_buf();
        match &mut self {
            Error::Discretize { file, .. }
            | Error::Normals { file, .. }
            | Error::MissingSurface { file, .. }
            | Error::UnknownSurface { file, .. }
            | Error::NoNormals { file, .. }
            | Error::Kinematics { file, .. }
            | Error::Interp { file, .. }
            | Error::Process { file, .. }
            | Error::NoCurves { file }
            | Error::Invalid { file, .. } => {
                file.get_or_insert(path);
            }
            Error::Write { path: p, .. } => {
                p.get_or_insert(path);
            }
            _ => {}
        }
        self
    }
}

impl From<kerf_kinematics::KinematicsError> for Error {
    fn from(e: kerf_kinematics::KinematicsError) -> Self {
        Error::Kinematics {
            file: None,
            source: e.into(),
        }
    }
}

/// The result of a job or a stage.
pub type Result<T, E = Error> = std::result::Result<T, E>;

/// Maps a stage error to [`Error`] naming `file`.
pub(crate) fn kin(file: Option<&Path>) -> impl Fn(kerf_kinematics::KinematicsError) -> Error + '_ {
    move |e| Error::Kinematics {
        file: file.map(Path::to_path_buf),
        source: e.into(),
    }
}

/// Maps an interpolator error to [`Error`] naming `file`.
pub(crate) fn interp(file: Option<&Path>) -> impl Fn(kerf_interp::InterpError) -> Error + '_ {
    move |e| Error::Interp {
        file: file.map(Path::to_path_buf),
        source: e,
    }
}
