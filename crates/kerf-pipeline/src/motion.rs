//! The motion stage on files: a `kerf.axes/1` or `kerf.toolpath/1` document (format detected
//! from its `format` key), solved on the machine if needed, fitted and planned ([`Program`]);
//! G-code and set-points written to any [`std::io::Write`].
//!
//! The generic-dialect rule lives here and in [`fit_options`], and nowhere can a caller set it
//! aside: a program for a controller that interpolates the machine axes linearly (`generic`,
//! `linuxcnc`) gets one G1 per pose of the kinematics, whose non-linearity error is within the
//! linearization tolerance, and no arcs (their chords would move the rotary axes in steps
//! nobody checked) nor merged lines. With tool-tip control (Sinumerik TRAORI) arcs and merges
//! are safe: the controller keeps the tip on the programmed path. (`kerf-interp`'s G-code
//! writer refuses such blocks for those dialects too.)

use std::io::Write;
use std::path::Path;

use kerf_format::toolpath::{self, ToolpathFile};
use kerf_interp::{
    gcode_motion, stations_from_axes, stations_from_solved, write_csv_to, AxisModel, ChordTerm,
    Dialect, FitOptions, GcodeOptions, MachineModel, Motion, PlanOptions, ProgramPath,
};
use kerf_kinematics::{AxesFile, Machine, PathOptions};

use crate::certify::CertifiedToolpath;
use crate::error::{interp, kin, Error, Result};

/// The fit of a program for `dialect` (`None`: set-points only, run with tool-tip control):
/// the tolerance and retract given, arcs and merged lines only where the controller keeps the
/// tool tip on the programmed path (see the module documentation).
pub fn fit_options(tolerance_mm: f64, dialect: Option<Dialect>, retract_mm: f64) -> FitOptions {
    let raw_axes = dialect.is_some_and(Dialect::raw_axes);
    FitOptions::with_tolerance(tolerance_mm)
        .with_arcs(!raw_axes)
        .with_merge_lines(!raw_axes)
        .with_retract_mm(retract_mm)
}

/// What the motion stage reads: machine axes (`kerf.axes/1`, from `kerf post` or any tool), or
/// cutting points (`kerf.toolpath/1`), solved on the machine first.
#[derive(Debug, Clone)]
pub enum MotionInput {
    /// Machine axes, with the lead-ins and lead-outs the file records.
    Axes(AxesFile),
    /// Cutting points; points without normals get the tool axis +z. The program states the
    /// file's `tolerance` as a claim.
    Toolpath(ToolpathFile),
    /// Cutting points certified against their curves: the program states the certified bound.
    Certified(CertifiedToolpath),
}

impl MotionInput {
    /// Reads either document, choosing by its `format` key (anything but `kerf.axes/1` is read
    /// as a toolpath, whose reader then names what is wrong). `source` names the file in
    /// errors.
    ///
    /// # Errors
    /// [`Error::Format`] or [`Error::Kinematics`] naming the file and the defect.
    pub fn from_slice(bytes: &[u8], source: Option<&Path>) -> Result<Self> {
        let format = kerf_io::parse_json(bytes)
            .ok()
            .and_then(|v| v.get("format").and_then(|f| f.as_str()).map(str::to_owned))
            .unwrap_or_default();
        if format == kerf_kinematics::AXES_FORMAT {
            Ok(Self::Axes(
                AxesFile::from_slice(bytes).map_err(kin(source))?,
            ))
        } else {
            let tp = toolpath::from_reader(bytes);
            Ok(Self::Toolpath(match source {
                Some(f) => tp.map_err(|e| e.in_file(f))?,
                None => tp?,
            }))
        }
    }

    /// Reads the file at `path`.
    ///
    /// # Errors
    /// [`Error::Read`], then as [`MotionInput::from_slice`].
    pub fn read(path: impl AsRef<Path>) -> Result<Self> {
        let path = path.as_ref();
        let bytes = kerf_io::read_file(path).map_err(|source| Error::Read {
            path: path.to_path_buf(),
            source,
        })?;
        Self::from_slice(&bytes, Some(path))
    }
}

/// The options of [`plan_program`], with the defaults of `kerf gcode`.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct MotionOptions {
    /// Programmed cutting feed, mm/min. Default 6000.
    pub feed_mm_per_min: f64,
    /// Interpolation cycle, s. Default 0.001.
    pub cycle_s: f64,
    /// The dialect the program is for; `None` plans for set-points only (tool-tip control:
    /// arcs allowed) and [`Program::gcode`] then refuses. The fit follows from it (see the
    /// module documentation). Default `Some(Dialect::Generic)`.
    pub dialect: Option<Dialect>,
    /// Arc-fit tolerance, mm. Default `None`: the toolpath's tolerance, else 0.001.
    pub fit_tolerance_mm: Option<f64>,
    /// Chord error allowed between two set-points on an arc, mm. Default `None`: the
    /// planner's (0.001).
    pub chord_tolerance_mm: Option<f64>,
    /// Retract between contours along the tool axis, mm. Default 10.
    pub retract_mm: f64,
    /// The controller's blending tolerance, mm. Default
    /// [`kerf_interp::DEFAULT_BLEND_TOLERANCE`]. It is also the planner's
    /// `PlanOptions::blend_tolerance_mm`: with jerk limits the set-points' tip leaves the smooth
    /// path by at most this much to blend curvature jumps (reported by
    /// `Motion::blend_deviation`).
    pub blend_tolerance_mm: f64,
    /// Run the traverse before a path through the waypoints an axes file records for it (its
    /// `traverse` key: checked by `kerf run` to clear the part), as `kerf run`'s own program
    /// does; a path without one gets the unchecked retract and straight traverse. False: the
    /// unchecked traverse everywhere (`kerf gcode --clearance 0`). Default true; a toolpath
    /// input records no traverses.
    pub recorded_traverses: bool,
}

impl Default for MotionOptions {
    fn default() -> Self {
        Self {
            feed_mm_per_min: 6000.0,
            cycle_s: 0.001,
            dialect: Some(Dialect::Generic),
            fit_tolerance_mm: None,
            chord_tolerance_mm: None,
            retract_mm: 10.0,
            blend_tolerance_mm: kerf_interp::DEFAULT_BLEND_TOLERANCE,
            recorded_traverses: true,
        }
    }
}

impl MotionOptions {
    /// With this feed, mm/min.
    pub fn with_feed_mm_per_min(mut self, feed: f64) -> Self {
        self.feed_mm_per_min = feed;
        self
    }
    /// With this cycle, s.
    pub fn with_cycle_s(mut self, cycle: f64) -> Self {
        self.cycle_s = cycle;
        self
    }
    /// For this dialect (`None`: set-points only).
    pub fn with_dialect(mut self, dialect: Option<Dialect>) -> Self {
        self.dialect = dialect;
        self
    }
    /// With this arc-fit tolerance, mm.
    pub fn with_fit_tolerance_mm(mut self, mm: Option<f64>) -> Self {
        self.fit_tolerance_mm = mm;
        self
    }
    /// With this set-point chord tolerance, mm.
    pub fn with_chord_tolerance_mm(mut self, mm: Option<f64>) -> Self {
        self.chord_tolerance_mm = mm;
        self
    }
    /// With this retract, mm.
    pub fn with_retract_mm(mut self, mm: f64) -> Self {
        self.retract_mm = mm;
        self
    }
    /// With this blending tolerance, mm.
    pub fn with_blend_tolerance_mm(mut self, mm: f64) -> Self {
        self.blend_tolerance_mm = mm;
        self
    }
    /// With or without the traverses an axes file records.
    pub fn with_recorded_traverses(mut self, recorded: bool) -> Self {
        self.recorded_traverses = recorded;
        self
    }

    /// Checks every option against its documented range ([`crate::ranges`]): the feed, the
    /// cycle, the arc-fit and set-point chord tolerances (when given), the retract and the
    /// blending tolerance. [`plan_program`] runs it before any work.
    ///
    /// # Errors
    /// [`Error::BadOption`] naming the option, its value and its range.
    pub fn validate(&self) -> Result<()> {
        use crate::ranges::{
            BLEND_TOLERANCE_MM, CYCLE_S, FEED_MM_PER_MIN, RETRACT_MM, TOLERANCE_MM,
        };
        FEED_MM_PER_MIN.check("feed_mm_per_min", self.feed_mm_per_min)?;
        CYCLE_S.check("cycle_s", self.cycle_s)?;
        if let Some(v) = self.fit_tolerance_mm {
            TOLERANCE_MM.check("fit_tolerance_mm", v)?;
        }
        if let Some(v) = self.chord_tolerance_mm {
            TOLERANCE_MM.check("chord_tolerance_mm", v)?;
        }
        RETRACT_MM.check("retract_mm", self.retract_mm)?;
        BLEND_TOLERANCE_MM.check("blend_tolerance_mm", self.blend_tolerance_mm)?;
        Ok(())
    }
}

/// A planned program: the machine model, the path ids and the motion, with what it was
/// planned with.
#[derive(Debug)]
pub struct Program {
    /// The machine.
    pub model: MachineModel,
    /// The source curve of each path.
    pub ids: Vec<String>,
    /// The planned motion.
    pub motion: Motion,
    /// The tolerance the blocks were fitted with, mm.
    pub fit_tolerance_mm: f64,
    /// The budget's chord term: unknown for an axes file, the file's claim for a toolpath,
    /// certified for a [`CertifiedToolpath`].
    pub chord_term: ChordTerm,
    /// The linearization tolerance the axes were solved with, mm (`None` for an axes file,
    /// which does not record it).
    pub linearization_tolerance_mm: Option<f64>,
    options: MotionOptions,
    source: Option<String>,
}

/// Solves (for a toolpath), fits and plans `input` on `machine`; `source` names the input
/// file in errors and in the program's comments.
///
/// # Errors
/// [`Error::BadOption`] for options out of their range ([`MotionOptions::validate`]),
/// [`Error::Kinematics`] for a machine or path that cannot be solved, [`Error::Interp`] for a
/// path the interpolator refuses.
pub fn plan_program(
    machine: &Machine,
    input: &MotionInput,
    options: &MotionOptions,
    source: Option<&Path>,
) -> Result<Program> {
    options.validate()?;
    let model = MachineModel::new(machine.clone()).map_err(interp(source))?;
    if let Some(d) = options.dialect {
        d.check_machine(&model).map_err(interp(source))?;
    }
    let mut linearization = None;
    let mut traverses: Vec<Vec<kerf_interp::Station>> = Vec::new();
    let (ids, paths, file_tol, chord_term) = match input {
        MotionInput::Axes(axes) => {
            let mut paths = Vec::new();
            for p in &axes.paths {
                paths.push(ProgramPath {
                    id: p.id.clone(),
                    stations: {
                        // Lead-in, cut and lead-out, as the machine runs them.
                        let (positions, poses) = p.run();
                        stations_from_axes(&positions, &poses).map_err(interp(source))?
                    },
                    curve: None,
                });
            }
            // The traverse before each path but the first (empty: the unchecked one).
            for p in axes.paths.iter().skip(1) {
                traverses.push(match &p.traverse {
                    Some(m) if options.recorded_traverses => {
                        stations_from_axes(&m.positions, &m.poses).map_err(interp(source))?
                    }
                    _ => Vec::new(),
                });
            }
            (
                axes.paths.iter().map(|p| p.id.clone()).collect::<Vec<_>>(),
                paths,
                None,
                // An axes file records no chord tolerance.
                ChordTerm::Unknown,
            )
        }
        MotionInput::Toolpath(_) | MotionInput::Certified(_) => {
            let (tp, chord_term) = match input {
                MotionInput::Certified(c) => {
                    (c.toolpath(), ChordTerm::Certified(c.toolpath().tolerance))
                }
                MotionInput::Toolpath(tp) => (tp, ChordTerm::Claimed(tp.tolerance)),
                MotionInput::Axes(_) => unreachable!("matched above"),
            };
            // The job's default tilt tolerance, so that `kerf gcode TOOLPATH` and `kerf post`
            // then `kerf gcode AXES` make the same program.
            let path_options =
                PathOptions::default().with_tilt_tolerance_deg(crate::DEFAULT_TILT_TOLERANCE_DEG);
            linearization = Some(path_options.linearization_tolerance_mm);
            let posted = crate::post::post_toolpath(
                machine,
                tp,
                &path_options,
                crate::PlaceMode::AsModelled,
                crate::post::MissingNormals::Vertical,
                source,
            )?;
            let mut paths = Vec::new();
            for (p, solved) in tp.paths.iter().zip(&posted.solved) {
                paths.push(ProgramPath {
                    id: p.id.clone(),
                    stations: stations_from_solved(solved, Some(&p.params))
                        .map_err(interp(source))?,
                    curve: None,
                });
            }
            (
                tp.paths.iter().map(|p| p.id.clone()).collect(),
                paths,
                Some(tp.tolerance),
                chord_term,
            )
        }
    };
    let fit_tolerance = options.fit_tolerance_mm.or(file_tol).unwrap_or(0.001);
    let mut plan = PlanOptions::new(options.feed_mm_per_min, options.cycle_s);
    // One number bounds both blends: the controller's (G64 P, CTOL) and, with jerk limits,
    // the planner's blend of curvature jumps in the set-points.
    plan.blend_tolerance_mm = options.blend_tolerance_mm;
    if let Some(c) = options.chord_tolerance_mm {
        plan.chord_tolerance_mm = c;
    }
    let fit = fit_options(fit_tolerance, options.dialect, options.retract_mm);
    let motion = if traverses.is_empty() {
        kerf_interp::interpolate(&model, &paths, &fit, &plan)
    } else {
        kerf_interp::interpolate_through(&model, &paths, &traverses, &fit, &plan)
    }
    .map_err(interp(source))?;
    Ok(Program {
        model,
        ids,
        motion,
        fit_tolerance_mm: fit_tolerance,
        chord_term,
        linearization_tolerance_mm: linearization,
        options: *options,
        source: source.map(|s| s.display().to_string()),
    })
}

impl Program {
    /// The G-code options of the program: its dialect, the budget terms, the machine's process
    /// codes and pivot length, the source file's name.
    ///
    /// # Errors
    /// [`Error::NoDialect`] for a program planned for set-points only.
    pub fn gcode_options(&self) -> Result<GcodeOptions> {
        let dialect = self.options.dialect.ok_or(Error::NoDialect)?;
        Ok(gcode_options(
            &self.model,
            dialect,
            self.options.feed_mm_per_min,
            self.options.blend_tolerance_mm,
            self.source.as_deref(),
        )
        .with_fit_tolerance_mm(self.fit_tolerance_mm)
        .with_chord_term(self.chord_term)
        .with_chord_tolerance_mm(self.options.chord_tolerance_mm.unwrap_or(0.001))
        .with_linearization_tolerance_mm(self.linearization_tolerance_mm))
    }

    /// The program text in its dialect.
    ///
    /// # Errors
    /// [`Error::NoDialect`]; [`Error::Interp`] for unusable process codes.
    pub fn gcode(&self) -> Result<String> {
        let opts = self.gcode_options()?;
        gcode_motion(&self.model, &self.motion, &self.ids, &opts)
            .map_err(interp(self.source.as_deref().map(Path::new)))
    }

    /// Writes the program text to `w`.
    ///
    /// # Errors
    /// As [`Program::gcode`]; [`Error::Write`] if `w` fails.
    pub fn write_gcode(&self, mut w: impl Write) -> Result<()> {
        let text = self.gcode()?;
        w.write_all(text.as_bytes())
            .map_err(|source| Error::Write { path: None, source })
    }

    /// Streams the set-points CSV (one row per cycle, `t,X,Y,Z,<tilt>,C`) to `w`: memory stays
    /// bounded however long the program runs.
    ///
    /// # Errors
    /// [`Error::Write`] if `w` fails.
    pub fn write_setpoints(&self, mut w: impl Write) -> Result<()> {
        write_csv_to(
            &mut w,
            self.model.axis_names(),
            self.options.cycle_s,
            self.motion.iter(&self.model),
        )
        .map_err(|source| Error::Write { path: None, source })
    }

    /// The options it was planned with.
    pub fn options(&self) -> &MotionOptions {
        &self.options
    }
}

/// The G-code options of a program for `dialect`: the budget terms, the machine's process
/// codes and pivot length, the source file's name.
pub(crate) fn gcode_options(
    model: &MachineModel,
    dialect: Dialect,
    feed: f64,
    blend_tolerance: f64,
    source: Option<&str>,
) -> GcodeOptions {
    GcodeOptions::new(dialect, feed)
        .with_blend_tolerance_mm(blend_tolerance)
        .with_pivot_length_mm(Some(model.machine.kinematics.pivot_length()))
        .with_process(model.machine.process.clone())
        .with_source(source.map(str::to_owned))
}
