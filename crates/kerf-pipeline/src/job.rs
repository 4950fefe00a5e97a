//! [`Job`] and [`JobOptions`]: what a run of the whole pipeline takes.

use std::path::{Path, PathBuf};

use kerf_discretize::Options;
use kerf_format::{CurveRecord, CurvesFile, SurfaceGeometry, SurfaceRecord, SurfaceSource};
use kerf_interp::Dialect;
use kerf_kinematics::{Machine, PathOptions};
use kerf_normals::NormalOptions;
use kerf_nurbs::{NurbsCurve, NurbsSurface};
use kerf_process::LeadOptions;

use crate::error::{Error, Result};
use crate::place::PlaceMode;

/// What the normals stage does with a curve that names no surface.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[non_exhaustive]
pub enum MissingSurface {
    /// The tool axis is +z at every point: flat 2D cutting with a vertical beam (the default
    /// of a [`Job`]).
    #[default]
    Vertical,
    /// The curve is refused with [`crate::Error::MissingSurface`] (what `kerf discretize
    /// --normals` does: a 3D part whose contour lost its surface must not be cut vertically).
    Error,
}

/// The options of the normals stage: the stage's own [`NormalOptions`], the crease angle of
/// mesh surfaces and what to do with curves without a surface.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct OrientOptions {
    /// The normals stage (on-surface tolerance, normal step, work budget). Default
    /// [`NormalOptions::default`].
    pub normals: NormalOptions,
    /// Mesh faces meeting at more than this angle form a sharp edge whose normals are not
    /// blended, degrees. Default [`kerf_normals::DEFAULT_CREASE_ANGLE_DEG`] (30).
    pub crease_angle_deg: f64,
    /// Curves without a surface. Default [`MissingSurface::Vertical`].
    pub missing_surface: MissingSurface,
}

impl Default for OrientOptions {
    fn default() -> Self {
        Self {
            normals: NormalOptions::default(),
            crease_angle_deg: kerf_normals::DEFAULT_CREASE_ANGLE_DEG,
            missing_surface: MissingSurface::Vertical,
        }
    }
}

impl OrientOptions {
    /// With these options of the normals stage.
    pub fn with_normals(mut self, normals: NormalOptions) -> Self {
        self.normals = normals;
        self
    }

    /// With this crease angle for mesh surfaces, degrees.
    pub fn with_crease_angle_deg(mut self, deg: f64) -> Self {
        self.crease_angle_deg = deg;
        self
    }

    /// With this rule for curves without a surface.
    pub fn with_missing_surface(mut self, rule: MissingSurface) -> Self {
        self.missing_surface = rule;
        self
    }
}

/// The options of every stage of a [`Job`], with documented defaults (those of `kerf run`).
///
/// Build with [`JobOptions::default`] and the `with_*` setters; new options may be added
/// without breaking callers. Units are in the names: `_mm`, `_s`, `_deg`, `_mm_per_min`; the
/// stage option structs document their own units.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct JobOptions {
    /// The discretizer. Default [`Options::default`]: chord tolerance 0.01 mm, no longest
    /// segment.
    pub discretize: Options,
    /// The normals stage. Default [`OrientOptions::default`] (vertical beam for curves without
    /// a surface).
    pub orient: OrientOptions,
    /// The kinematics. Default [`PathOptions::default`] with the tilt tolerance
    /// [`DEFAULT_TILT_TOLERANCE_DEG`]: linearization tolerance 0.005 mm, no rotary step limit.
    pub path: PathOptions,
    /// Where the part goes on the machine. Default [`PlaceMode::AsModelled`].
    pub place: PlaceMode,
    /// Lead-ins and lead-outs of every cut. Default [`LeadOptions::default`] (2 mm line and
    /// 1 mm arc in, 0.5 mm overcut and 1 mm exit).
    pub leads: LeadOptions,
    /// Programmed cutting feed, mm/min. Default 6000.
    pub feed_mm_per_min: f64,
    /// Interpolation cycle, s. Default 0.001.
    pub cycle_s: f64,
    /// The G-code dialect. Default [`Dialect::Generic`]. The fit of the motion follows from it
    /// (see [`crate::MotionOptions`]): a dialect that programs raw machine axes gets neither
    /// arcs nor merged lines, whatever else is set.
    pub dialect: Dialect,
    /// The controller's blending tolerance, mm: a term of the tolerance budget. Default
    /// [`kerf_interp::DEFAULT_BLEND_TOLERANCE`].
    pub blend_tolerance_mm: f64,
    /// Between two contours the head backs off this far along the tool axis, traverses and
    /// approaches the next start along its tool axis, mm (0: one straight rapid). Default 10.
    pub retract_mm: f64,
    /// Traverses between cuts checked against the part's surfaces (retract along the tool
    /// axis, travel at a clearance, approach; `kerf-process`), or `None` for the unchecked
    /// retract and straight traverse. Default `Some(TraverseOptions::default())`: 5 mm
    /// clearance, 20 mm nozzle; the run backs off as far as the larger of its retract and
    /// `retract_mm` ([`JobOptions::checked_traverse`]).
    pub traverse: Option<kerf_process::TraverseOptions>,
    /// The most cutting points of all curves together ([`crate::discretize_curves_within`]):
    /// a job that needs more is refused from the discretizer's estimate before the points are
    /// allocated, or as soon as the running total passes it. Every later stage (normals,
    /// machine axes, the program, the set-points, the plot) grows with the cutting points, at
    /// about 3 KB each in all: a 600-byte circle at `-t 1e-8` made 594,000 points,
    /// 1.9 GB and 55 s. Default [`DEFAULT_MAX_TOTAL_POINTS_RUN`] (1,000,000).
    pub max_total_points: usize,
    /// A contour whose only named surface is a wall at most this wide across it (a hole's or
    /// a slot's wall, the sheet's edge face: [`kerf_process::wall_axis`]) is cut with the beam
    /// along the wall, the scrap where the wall's normal points; 0 turns this off, mm.
    /// Default 4.
    pub wall_axis_max_mm: f64,
    /// The kerf width, mm: each path moves half of it toward the scrap side, so that the cut
    /// edge lands on the contour ([`kerf_process::offset`]). `None` (the default) takes the
    /// machine's `process.kerf_width_mm`; with neither, the path is the contour itself.
    pub kerf_width_mm: Option<f64>,
    /// With a kerf width, leave the compensation to the controller: the program holds the
    /// contours with LinuxCNC's `G41.1`/`G42.1 D` (every compensated cut must then stand the
    /// beam vertical with the rotary axes still) or Sinumerik's `CUT3DC` with `G41`/`G42` and
    /// `OFFN` (any orientation); other dialects are refused. Default false: compensate in the
    /// computer.
    pub kerf_in_control: bool,
    /// The distance the head (the machine file's `head`, else
    /// [`kerf_kinematics::Head::laser_default`]) must keep from the part's surfaces along
    /// every cut (contour, lead-in, lead-out), mm ([`kerf_process::check_cut`]), and along
    /// every traverse ([`kerf_process::TraverseHead`]: a route it does not clear is not
    /// taken). Default [`DEFAULT_CUT_CLEARANCE_MM`]; `None`: neither is checked against the
    /// head (the traverses against the tip and the nozzle line only).
    pub cut_clearance_mm: Option<f64>,
    /// With [`JobOptions::cut_clearance_mm`], cuts and traverses where the head comes closer
    /// are warnings instead of a refused run. Default false.
    pub accept_head_collisions: bool,
    /// Micro-joints: `Some((length_mm, spacing_mm))` leaves `length_mm` of each part's outline
    /// (and of each cut-out wider than `spacing_mm`) uncut every `spacing_mm` of path, away
    /// from corners and the lead-in, with the beam switched by codes synchronized with motion
    /// (docs/process.md "Micro-joints"). Default `None`.
    pub micro_joints: Option<(f64, f64)>,
    /// The technology entry the run cuts with ([`Job::with_technology`]), for the report and
    /// the program header. `None` by default.
    pub technology: Option<kerf_kinematics::TechnologyEntry>,
}

/// The tilt tolerance of a job unless it sets another (degrees): 0, the exact normal. A
/// tolerance (`--tilt-tolerance 1`: one degree leans the bottom edge of a 3 mm sheet 0.05 mm
/// and lets C stand still wherever the normal is within a degree of the pole,
/// `kerf_kinematics::tilt_within_cone`) is the user's choice for now: the taut strings bend C
/// and the tilt at points, and LinuxCNC's joint-space blends round those bends with the tool
/// axis up to 1.9 degrees off kerf's poses (tube_saddle and the propeller in
/// `tests/linuxcnc/check.py`, 0.007 and 0.19 degrees with the exact normals; kerf's own
/// set-points stay within 0.06 degrees). The default becomes 1 degree once the strings' bends are
/// rounded (`docs/kinematics.md`, "Tilt tolerance").
pub const DEFAULT_TILT_TOLERANCE_DEG: f64 = 0.0;

/// The default of [`JobOptions::cut_clearance_mm`]: the head keeps 1 mm from the part along
/// every cut and traverse, a margin for the part's deviation from its model (a bent part's
/// springback, its fixture). The nozzle tip itself stands `process.standoff_mm` over the
/// sheet, and the head below the tip zone is left out (docs/process.md, "The head along the
/// cuts").
pub const DEFAULT_CUT_CLEARANCE_MM: Option<f64> = Some(1.0);

/// The default of [`JobOptions::max_total_points`]: one million cutting points, about 3 GB
/// through every stage of a run (a sheet-metal part with hundreds of holes at 0.01 mm needs
/// tens of thousands).
pub const DEFAULT_MAX_TOTAL_POINTS_RUN: usize = 1_000_000;

impl Default for JobOptions {
    fn default() -> Self {
        Self {
            discretize: Options::default(),
            orient: OrientOptions::default(),
            path: PathOptions::default().with_tilt_tolerance_deg(DEFAULT_TILT_TOLERANCE_DEG),
            place: PlaceMode::AsModelled,
            leads: LeadOptions::default(),
            feed_mm_per_min: 6000.0,
            cycle_s: 0.001,
            dialect: Dialect::Generic,
            blend_tolerance_mm: kerf_interp::DEFAULT_BLEND_TOLERANCE,
            retract_mm: 10.0,
            traverse: Some(kerf_process::TraverseOptions::default()),
            max_total_points: DEFAULT_MAX_TOTAL_POINTS_RUN,
            wall_axis_max_mm: 4.0,
            kerf_width_mm: None,
            kerf_in_control: false,
            cut_clearance_mm: DEFAULT_CUT_CLEARANCE_MM,
            accept_head_collisions: false,
            micro_joints: None,
            technology: None,
        }
    }
}

impl JobOptions {
    /// With this chord tolerance, mm: every segment's chord error is at most this (certified).
    pub fn with_tolerance_mm(mut self, mm: f64) -> Self {
        self.discretize.tolerance_mm = mm;
        self
    }

    /// With these discretizer options.
    pub fn with_discretize(mut self, options: Options) -> Self {
        self.discretize = options;
        self
    }

    /// With these normals-stage options.
    pub fn with_orient(mut self, options: OrientOptions) -> Self {
        self.orient = options;
        self
    }

    /// With these kinematics options.
    pub fn with_path(mut self, options: PathOptions) -> Self {
        self.path = options;
        self
    }

    /// With this placement of the part on the machine.
    pub fn with_place(mut self, place: PlaceMode) -> Self {
        self.place = place;
        self
    }

    /// With these lead-in and lead-out options.
    pub fn with_leads(mut self, leads: LeadOptions) -> Self {
        self.leads = leads;
        self
    }

    /// With this programmed feed, mm/min.
    pub fn with_feed_mm_per_min(mut self, feed: f64) -> Self {
        self.feed_mm_per_min = feed;
        self
    }

    /// With this interpolation cycle, s.
    pub fn with_cycle_s(mut self, cycle: f64) -> Self {
        self.cycle_s = cycle;
        self
    }

    /// With this G-code dialect.
    pub fn with_dialect(mut self, dialect: Dialect) -> Self {
        self.dialect = dialect;
        self
    }

    /// With this controller blending tolerance, mm.
    pub fn with_blend_tolerance_mm(mut self, mm: f64) -> Self {
        self.blend_tolerance_mm = mm;
        self
    }

    /// With this retract between contours, mm.
    pub fn with_retract_mm(mut self, mm: f64) -> Self {
        self.retract_mm = mm;
        self
    }

    /// With this limit on the cutting points of all curves together
    /// ([`JobOptions::max_total_points`]).
    pub fn with_max_total_points(mut self, points: usize) -> Self {
        self.max_total_points = points;
        self
    }

    /// With this widest wall cut along itself, mm (0: off; see
    /// [`JobOptions::wall_axis_max_mm`]).
    pub fn with_wall_axis_max_mm(mut self, mm: f64) -> Self {
        self.wall_axis_max_mm = mm;
        self
    }

    /// With this kerf width, mm (`None`: the machine's, if it gives one; see
    /// [`JobOptions::kerf_width_mm`]).
    pub fn with_kerf_width_mm(mut self, mm: Option<f64>) -> Self {
        self.kerf_width_mm = mm;
        self
    }

    /// With the controller's kerf compensation instead of the computer's (see
    /// [`JobOptions::kerf_in_control`]).
    pub fn with_kerf_in_control(mut self, in_control: bool) -> Self {
        self.kerf_in_control = in_control;
        self
    }

    /// With the head checked along every cut at this clearance, mm (`None`: not checked; see
    /// [`JobOptions::cut_clearance_mm`]).
    pub fn with_cut_clearance_mm(mut self, mm: Option<f64>) -> Self {
        self.cut_clearance_mm = mm;
        self
    }

    /// With micro-joints of `length_mm` every `spacing_mm` (see [`JobOptions::micro_joints`]).
    pub fn with_micro_joints(mut self, joints: Option<(f64, f64)>) -> Self {
        self.micro_joints = joints;
        self
    }

    /// With head collisions along the cuts reported as warnings instead of refused (see
    /// [`JobOptions::accept_head_collisions`]).
    pub fn with_accept_head_collisions(mut self, accept: bool) -> Self {
        self.accept_head_collisions = accept;
        self
    }

    /// With these traverse checks (`None`: unchecked traverses).
    pub fn with_traverse(mut self, traverse: Option<kerf_process::TraverseOptions>) -> Self {
        self.traverse = traverse;
        self
    }

    /// The traverse checks as the run applies them: [`traverse`](Self::traverse) with its
    /// retract raised to [`retract_mm`](Self::retract_mm), the job's one retract (the
    /// traverse's own, 1.5 times its clearance by default and at least 1.25 times it, is what
    /// a checked traverse needs to clear the part; the program backs off as far as the larger
    /// of the two).
    pub fn checked_traverse(&self) -> Option<kerf_process::TraverseOptions> {
        self.traverse.map(|t| {
            let retract_mm = t.retract_mm.max(self.retract_mm);
            t.with_retract_mm(retract_mm)
        })
    }

    /// Checks every option against its documented range ([`crate::ranges`]) and the stages'
    /// own checks, before any work ([`Job::validate`] runs it, and so [`Job::run`]): the
    /// discretizer's ([`Options::validate`]), the chord tolerance and the segment lengths, the
    /// on-surface and linearization tolerances (the kinematics' [`PathOptions::validate`];
    /// an infinite linearization tolerance, no points inserted, stays allowed), the feed, the
    /// cycle, the blending tolerance, the retract, the wall width, the leads (and
    /// [`LeadOptions::validate`]) and the traverse checks' clearance (and
    /// [`kerf_process::TraverseOptions::validate`], with the retract raised to
    /// [`JobOptions::retract_mm`] as the run does). Out of range used to mean quiet
    /// misbehaviour: a clearance of 2e4 mm failed every traverse's check, and every traverse
    /// fell back to the unchecked straight rapid with only a warning.
    ///
    /// # Errors
    /// [`Error::BadOption`] naming the option, its value and its range; [`Error::Options`],
    /// [`Error::Kinematics`] or [`Error::Process`] for what a stage's own check refuses.
    pub fn validate(&self) -> Result<()> {
        use crate::ranges::{
            BLEND_TOLERANCE_MM, CLEARANCE_MM, CYCLE_S, FEED_MM_PER_MIN, LEAD_MM, RETRACT_MM,
            SEGMENT_LENGTH_MM, TOLERANCE_MM, WALL_MM,
        };
        let process = |source| Error::Process { file: None, source };
        let d = &self.discretize;
        d.validate().map_err(Error::Options)?;
        TOLERANCE_MM.check("tolerance_mm", d.tolerance_mm)?;
        if d.max_segment_length_mm.is_finite() {
            SEGMENT_LENGTH_MM.check("max_segment_length_mm", d.max_segment_length_mm)?;
        }
        if d.min_segment_length_mm > 0.0 {
            SEGMENT_LENGTH_MM.check("min_segment_length_mm", d.min_segment_length_mm)?;
        }
        TOLERANCE_MM.check(
            "on_surface_tolerance_mm",
            self.orient.normals.on_surface_tolerance_mm,
        )?;
        self.path.validate()?;
        if self.path.linearization_tolerance_mm.is_finite() {
            TOLERANCE_MM.check(
                "linearization_tolerance_mm",
                self.path.linearization_tolerance_mm,
            )?;
        }
        FEED_MM_PER_MIN.check("feed_mm_per_min", self.feed_mm_per_min)?;
        CYCLE_S.check("cycle_s", self.cycle_s)?;
        BLEND_TOLERANCE_MM.check("blend_tolerance_mm", self.blend_tolerance_mm)?;
        RETRACT_MM.check("retract_mm", self.retract_mm)?;
        WALL_MM.check("wall_axis_max_mm", self.wall_axis_max_mm)?;
        if let Some(w) = self.kerf_width_mm {
            crate::ranges::KERF_WIDTH_MM.check("kerf_width_mm", w)?;
        }
        if let Some(c) = self.cut_clearance_mm {
            CLEARANCE_MM.check("cut_clearance_mm", c)?;
        }
        if let Some((length, spacing)) = self.micro_joints {
            crate::ranges::MICRO_JOINT_MM.check("micro_joints.length_mm", length)?;
            crate::ranges::MICRO_JOINT_SPACING_MM.check("micro_joints.spacing_mm", spacing)?;
            if length >= spacing {
                return Err(Error::BadOption {
                    name: "micro_joints.length_mm",
                    value: length,
                    requirement: format!("must be less than the spacing ({spacing} mm)"),
                });
            }
        }
        let l = &self.leads;
        for (name, v) in [
            ("leads.lead_in_mm", l.lead_in_mm),
            ("leads.lead_in_radius_mm", l.lead_in_radius_mm),
            ("leads.overcut_mm", l.overcut_mm),
            ("leads.lead_out_mm", l.lead_out_mm),
        ] {
            LEAD_MM.check(name, v)?;
        }
        l.validate().map_err(process)?;
        if let Some(t) = self.checked_traverse() {
            CLEARANCE_MM.check("traverse.clearance_mm", t.clearance_mm)?;
            t.validate().map_err(process)?;
        }
        Ok(())
    }
}

/// A job: the curves (with their surfaces), the machine and the options of every stage.
/// [`Job::run`] runs the whole pipeline in memory and returns every stage's result
/// ([`crate::Output`]).
#[derive(Debug, Clone)]
pub struct Job {
    pub(crate) curves: CurvesFile,
    pub(crate) machine: Machine,
    pub(crate) options: JobOptions,
    pub(crate) source: Option<PathBuf>,
    /// What reading the input said that the user must see (a STEP file's assumed units), for
    /// the report's `warnings`.
    pub(crate) input_warnings: Vec<String>,
}

impl Job {
    /// A job with the default options on `curves` (read from a file or built in code) and
    /// `machine`.
    pub fn new(curves: CurvesFile, machine: Machine) -> Self {
        Self {
            curves,
            machine,
            options: JobOptions::default(),
            source: None,
            input_warnings: Vec::new(),
        }
    }

    /// A job on a `kerf.curves/1` file and a `kerf.machine/1` file; errors name the curves
    /// file.
    ///
    /// # Errors
    /// [`crate::Error::Format`] for an unreadable or invalid curves file,
    /// [`crate::Error::Kinematics`] for the machine file.
    pub fn from_files(curves: impl AsRef<Path>, machine: impl AsRef<Path>) -> Result<Self> {
        let path = curves.as_ref();
        let file = kerf_format::curves::load(path)?;
        let machine = Machine::read(machine)?;
        Ok(Self::new(file, machine).with_source(path))
    }

    /// A job on the contours of a STEP file (AP203, AP214, AP242) read with `opts`
    /// ([`kerf_step::import_file`]: geometric sets' curves, or with
    /// [`kerf_step::ImportOptions::with_edges`] the faces' boundary loops, a sheet-metal solid's
    /// features once each) and `machine`; errors name the STEP file, and what the import had to
    /// assume (units) is among the report's warnings. The import's account (what was taken,
    /// skipped, closed; the sheet found) is returned beside the job.
    ///
    /// # Errors
    /// [`crate::Error::Step`] naming the file and the entity,
    /// [`crate::Error::StepDocument`] if the import's document fails `kerf.curves/1`'s checks.
    pub fn from_step(
        step: impl AsRef<Path>,
        machine: Machine,
        opts: &kerf_step::ImportOptions,
    ) -> Result<(Self, kerf_step::Report)> {
        let path = step.as_ref();
        let import = kerf_step::import_file(path, opts)?;
        Self::from_import(path, import, machine)
    }

    /// A job on the contours of a CAD file, STEP or IGES by its extension ([`is_iges`]: `.igs`,
    /// `.iges`; anything else is read as STEP, [`Job::from_step`]), read with `opts`: with
    /// [`kerf_step::ImportOptions::with_edges`] the faces' boundary loops are the contours
    /// (for IGES, the trimmed surfaces' loops; IGES has no topology to recognise a sheet by).
    ///
    /// # Errors
    /// [`crate::Error::Step`] or [`crate::Error::Iges`] naming the file and the entity,
    /// [`crate::Error::StepDocument`] if the import's document fails `kerf.curves/1`'s checks.
    pub fn from_cad(
        path: impl AsRef<Path>,
        machine: Machine,
        opts: &kerf_step::ImportOptions,
    ) -> Result<(Self, kerf_step::Report)> {
        let path = path.as_ref();
        if is_iges(path) {
            let import = kerf_iges::import_file(path, opts)?;
            Self::from_import(path, import, machine)
        } else {
            Self::from_step(path, machine, opts)
        }
    }

    fn from_import(
        path: &Path,
        import: kerf_step::Import,
        machine: Machine,
    ) -> Result<(Self, kerf_step::Report)> {
        let file = import
            .to_curves()
            .map_err(|source| crate::Error::StepDocument {
                file: path.to_path_buf(),
                source,
            })?;
        let job = Self::new(file, machine)
            .with_source(path)
            .with_input_warnings(import.report.warnings.clone());
        Ok((job, import.report))
    }

    /// A job on `machine` with no curves yet: add them with [`Job::with_surface`] and
    /// [`Job::with_curve`] (geometry built in code).
    pub fn on_machine(machine: Machine) -> Self {
        Self::new(
            CurvesFile {
                units: kerf_format::Units::Millimetres,
                curves: Vec::new(),
                surfaces: Vec::new(),
                warnings: Vec::new(),
            },
            machine,
        )
    }

    /// With one more surface (coordinates in mm; the normal is `Su x Sv`, `flip` reverses it).
    pub fn with_surface(
        mut self,
        id: impl Into<String>,
        surface: NurbsSurface,
        flip: bool,
    ) -> Self {
        self.curves.surfaces.push(SurfaceRecord {
            id: id.into(),
            geometry: SurfaceGeometry::Nurbs(surface),
            source: SurfaceSource::Inline,
            flip,
        });
        self
    }

    /// With one more cut contour (coordinates in mm) on the surface with id `surface` (`None`:
    /// cut with a vertical beam, see [`MissingSurface`]).
    pub fn with_curve(
        mut self,
        id: impl Into<String>,
        curve: NurbsCurve,
        surface: Option<&str>,
    ) -> Self {
        self.curves.curves.push(
            CurveRecord::new(id, curve)
                .with_surfaces(surface.map(str::to_owned).into_iter().collect()),
        );
        self
    }

    /// Checks the options ([`JobOptions::validate`]), then what the reader checks of a file
    /// but a model built in code may lack: at least one curve, unique ids without control
    /// characters, no curve that is a point ([`kerf_format::curves::is_a_point`]: all its
    /// control points at one place; it would be cut as a slit of its lead-in and lead-out),
    /// every surface named present. [`Job::run`] runs it first.
    ///
    /// # Errors
    /// As [`JobOptions::validate`]; [`Error::NoCurves`], [`Error::Invalid`],
    /// [`Error::UnknownSurface`].
    pub fn validate(&self) -> Result<()> {
        self.options.validate()?;
        let file = || self.source.clone();
        if self.curves.curves.is_empty() {
            return Err(Error::NoCurves { file: file() });
        }
        let ids = self
            .curves
            .curves
            .iter()
            .map(|c| ("curves", &c.id))
            .enumerate()
            .chain(
                self.curves
                    .surfaces
                    .iter()
                    .map(|s| ("surfaces", &s.id))
                    .enumerate(),
            );
        let mut seen = std::collections::HashSet::new();
        for (i, (list, id)) in ids {
            let invalid = |message: String| Error::Invalid {
                file: file(),
                place: format!("{list}[{i}] ({id:?})"),
                message,
            };
            if let Err(d) = kerf_io::check_text(id) {
                return Err(invalid(format!("the id {d}")));
            }
            if !seen.insert((list, id)) {
                return Err(invalid(format!(
                    "a second {} with this id",
                    &list[..list.len() - 1]
                )));
            }
        }
        for (i, c) in self.curves.curves.iter().enumerate() {
            let invalid = |message: String| Error::Invalid {
                file: file(),
                place: format!("curves[{i}] ({:?})", c.id),
                message,
            };
            if kerf_format::curves::is_a_point(&c.curve) {
                return Err(invalid(kerf_format::curves::POINT_CURVE.to_owned()));
            }
            // A curve built in code states its own lengths as a file must.
            if let Some((key, message)) = kerf_format::curves::length_key_error(
                c.on_surface_tolerance_mm,
                c.sheet_thickness_mm,
            ) {
                return Err(invalid(format!("{key} {message}")));
            }
        }
        for (i, c) in self.curves.curves.iter().enumerate() {
            for sid in c.surface.iter().chain(&c.surfaces) {
                if self.curves.surface(sid).is_none() {
                    return Err(Error::UnknownSurface {
                        file: file(),
                        index: i,
                        id: c.id.clone(),
                        surface: sid.clone(),
                    });
                }
            }
        }
        Ok(())
    }

    /// With these options.
    pub fn with_options(mut self, options: JobOptions) -> Self {
        self.options = options;
        self
    }

    /// Cuts with a technology entry (`kerf.technology/1`): its feed becomes the job's feed, and
    /// its pierce (time, height), standoff and kerf width replace the machine file's
    /// `process` values where the entry gives them (a run's own `--kerf-width` still wins:
    /// [`JobOptions::kerf_width_mm`]). Call it after [`Job::with_options`], then set a feed
    /// the user gave explicitly. Its micro-joints apply where the options name none. The entry
    /// is named in the report and the program header; its
    /// power is commanded following the tip's speed and its small-hole rule slows the holes
    /// it names (docs/process.md "Technology").
    pub fn with_technology(mut self, entry: kerf_kinematics::TechnologyEntry) -> Self {
        self.options.feed_mm_per_min = entry.feed_mm_per_min;
        let p = &mut self.machine.process;
        if let Some(pierce) = &entry.pierce {
            p.pierce_dwell_s = Some(pierce.time_s);
            p.pierce_standoff = Some(pierce.height_mm);
        }
        if let Some(s) = entry.standoff_mm {
            p.standoff_mm = Some(s);
        }
        if let Some(k) = entry.kerf_width_mm {
            p.kerf_width_mm = Some(k);
        }
        if let (None, Some(j)) = (self.options.micro_joints, entry.micro_joints) {
            self.options.micro_joints = Some((j.length_mm, j.spacing_mm));
        }
        self.options.technology = Some(entry);
        self
    }

    /// With this feed, mm/min (after [`Job::with_technology`], a feed the user gave wins over
    /// the entry's).
    pub fn with_feed_mm_per_min(mut self, feed_mm_per_min: f64) -> Self {
        self.options.feed_mm_per_min = feed_mm_per_min;
        self
    }

    /// With `path` named as the curves' file: in every error, in the report and in the
    /// program's comments.
    pub fn with_source(mut self, path: impl AsRef<Path>) -> Self {
        self.source = Some(path.as_ref().to_path_buf());
        self
    }

    /// With `warnings` from reading the input (a STEP import's, such as units it had to
    /// assume) listed first among the report's `warnings`, each prefixed `input: `.
    pub fn with_input_warnings(mut self, warnings: Vec<String>) -> Self {
        self.input_warnings = warnings;
        self
    }

    /// The curves and surfaces.
    pub fn curves(&self) -> &CurvesFile {
        &self.curves
    }

    /// The machine.
    pub fn machine(&self) -> &Machine {
        &self.machine
    }

    /// The options.
    pub fn options(&self) -> &JobOptions {
        &self.options
    }

    /// The file named by [`Job::with_source`].
    pub fn source(&self) -> Option<&Path> {
        self.source.as_deref()
    }
}

/// Whether `path` names an IGES file by its extension (`.igs`, `.iges`, any case).
pub fn is_iges(path: &Path) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| matches!(e.to_ascii_lowercase().as_str(), "igs" | "iges"))
}
