//! [`Output`]: every stage's result of a job, and its files written to any writer or into one
//! directory, all or nothing.

use std::io::Write;
use std::path::Path;

use kerf_discretize::Discretization;
use kerf_format::toolpath::{self, ToolpathFile};
use kerf_format::FormatError;
use kerf_interp::{write_csv_to, AxisModel, MachineModel, Motion};
use kerf_io::DirEntry;
use kerf_kinematics::{AxesFile, SolvedPath};
use kerf_normals::Oriented;

use crate::error::{Error, Result};
use crate::place::Placed;
use crate::report::Report;
use crate::timing::{Lap, Timings};

/// One set-up's program: the part is clamped anew between set-ups, so each is a job of its
/// own for the machine.
#[derive(Debug)]
#[non_exhaustive]
pub struct SetupProgram {
    /// The program's file name in an output directory (`program.nc`, or `program-1.nc`, ...
    /// for several set-ups).
    pub name: String,
    /// The set-points' file name (`setpoints.csv`, `setpoints-1.csv`, ...).
    pub setpoints_name: String,
    /// The ids of its paths, in cutting order.
    pub ids: Vec<String>,
    /// The planned motion.
    pub motion: Motion,
    /// The G-code text.
    pub text: String,
}

impl SetupProgram {
    /// The programs of the set-ups in order, named `program.nc` or `program-1.nc`, ...
    pub(crate) fn numbered(
        motions: Vec<Motion>,
        texts: Vec<String>,
        ids: Vec<Vec<String>>,
    ) -> Vec<SetupProgram> {
        let names = program_names(motions.len());
        let csv_names = csv_names(motions.len());
        motions
            .into_iter()
            .zip(texts)
            .zip(ids)
            .enumerate()
            .map(|(k, ((motion, text), ids))| SetupProgram {
                name: names[k].clone(),
                setpoints_name: csv_names[k].clone(),
                ids,
                motion,
                text,
            })
            .collect()
    }
}

/// Every stage's result of a [`Job::run`](crate::Job::run).
#[derive(Debug)]
#[non_exhaustive]
pub struct Output {
    /// Stage 1: the cutting points of every curve, with their certified chord error.
    pub discretizations: Vec<Discretization>,
    /// Stage 2: the points with their normals (points inserted where the normal turns).
    pub oriented: Vec<Oriented>,
    /// Stages 1 and 2 as `kerf.toolpath/1` (part coordinates).
    pub toolpath: ToolpathFile,
    /// Where the part went on the machine, set-up by set-up.
    pub placement: Placed,
    /// Stage 3: every cut (lead-in, contour, lead-out) solved on the machine, in cutting
    /// order (workpiece coordinates).
    pub solved: Vec<SolvedPath>,
    /// Stage 3 as `kerf.axes/1`, lead-ins and lead-outs kept apart from the cuts.
    pub axes: AxesFile,
    /// Stage 4: one program per set-up.
    pub programs: Vec<SetupProgram>,
    /// The report (`report.json` is its JSON): the tolerance budget, every stage's figures,
    /// the placement, the cuts and the time each stage took ([`Report::timings`]; the CLI
    /// adds `read` before them with [`Output::prepend_timings`], and [`Output::write_dir`]
    /// adds `write` to what it writes).
    pub report: Report,
    /// The picture (`plot.svg`): the curves, points and tool axes, chord errors and the axes
    /// against the machine's limits.
    pub plot_svg: String,
    /// The interactive 3D view's scene (`view.html`, [`Output::write_view`]): the part, the
    /// cuts, the traverses and the planned motion of every set-up.
    pub scene: kerf_view::Scene,
    /// What the caller should be told: traverses that could not be checked against the part
    /// (they fall back to the unchecked retract traverse; `traverses.unchecked` in the report).
    pub warnings: Vec<String>,
    pub(crate) model: MachineModel,
    pub(crate) cycle_s: f64,
}

impl Output {
    /// Puts `earlier` (stages that ran before the job, such as reading its files) before the
    /// run's own stage times ([`Report::timings`]).
    pub fn prepend_timings(&mut self, earlier: Timings) {
        let mut t = earlier;
        t.merge(&self.report.timings);
        self.report.timings = t;
    }

    /// The names of the files [`Output::write_dir`] writes, in order.
    pub fn file_names(&self) -> Vec<String> {
        let mut names = vec![OUTPUTS[0].to_string(), OUTPUTS[1].to_string()];
        for p in &self.programs {
            names.push(p.name.clone());
            names.push(p.setpoints_name.clone());
        }
        names.push(OUTPUTS[4].to_string());
        names.push(OUTPUTS[5].to_string());
        names.push(OUTPUTS[6].to_string());
        names
    }

    /// Writes the toolpath (`kerf.toolpath/1`) to `w`.
    ///
    /// # Errors
    /// [`Error::Format`] if `w` fails.
    pub fn write_toolpath(&self, w: impl Write) -> Result<()> {
        Ok(toolpath::to_writer(&self.toolpath, w)?)
    }

    /// Writes the machine axes (`kerf.axes/1`) to `w`.
    ///
    /// # Errors
    /// [`Error::Kinematics`] if `w` fails.
    pub fn write_axes(&self, w: impl Write) -> Result<()> {
        Ok(self.axes.to_writer(w)?)
    }

    /// Streams the set-points of set-up `setup` (CSV, one row per cycle) to `w`.
    ///
    /// # Errors
    /// [`Error::Write`] if `w` fails or there is no such set-up.
    pub fn write_setpoints(&self, setup: usize, mut w: impl Write) -> Result<()> {
        let p = self.setup(setup)?;
        write_csv_to(
            &mut w,
            self.model.axis_names(),
            self.cycle_s,
            p.motion.iter(&self.model),
        )
        .map_err(|source| Error::Write { path: None, source })
    }

    /// Writes the G-code program of set-up `setup` to `w`.
    ///
    /// # Errors
    /// [`Error::Write`] if `w` fails or there is no such set-up.
    pub fn write_program(&self, setup: usize, mut w: impl Write) -> Result<()> {
        let p = self.setup(setup)?;
        w.write_all(p.text.as_bytes())
            .map_err(|source| Error::Write { path: None, source })
    }

    /// Writes the report (pretty JSON) to `w`.
    ///
    /// # Errors
    /// [`Error::Write`] if `w` fails.
    pub fn write_report(&self, mut w: impl Write) -> Result<()> {
        w.write_all(self.report_text().as_bytes())
            .map_err(|source| Error::Write { path: None, source })
    }

    /// Writes the picture (SVG) to `w`.
    ///
    /// # Errors
    /// [`Error::Write`] if `w` fails.
    pub fn write_plot(&self, mut w: impl Write) -> Result<()> {
        w.write_all(self.plot_svg.as_bytes())
            .map_err(|source| Error::Write { path: None, source })
    }

    /// Writes the interactive 3D view (one self-contained HTML file, [`kerf_view::html`]) to
    /// `w`, with every warning of the report (`report["warnings"]`) beside it.
    ///
    /// # Errors
    /// [`Error::Write`] if `w` fails.
    pub fn write_view(&self, mut w: impl Write) -> Result<()> {
        w.write_all(self.view_html().as_bytes())
            .map_err(|source| Error::Write { path: None, source })
    }

    /// The page [`Output::write_view`] writes.
    pub fn view_html(&self) -> String {
        let mut scene = self.scene.clone();
        scene.warnings = self
            .report
            .warnings
            .iter()
            .map(|w| kerf_view::Warning::new(w))
            .collect();
        kerf_view::html(&scene)
    }

    fn setup(&self, setup: usize) -> Result<&SetupProgram> {
        self.programs.get(setup).ok_or_else(|| Error::Write {
            path: None,
            source: std::io::Error::new(
                std::io::ErrorKind::InvalidInput,
                format!("no set-up {setup} (there are {})", self.programs.len()),
            ),
        })
    }

    /// The report as pretty JSON text.
    pub fn report_text(&self) -> String {
        serde_json::to_string_pretty(&self.report).unwrap_or_default()
    }

    /// Writes every file ([`Output::file_names`]) into `dir` (created if needed), all or
    /// nothing (through [`kerf_io::write_dir_all_or_nothing`]): a failed write leaves `dir` as
    /// it was. Nothing is copied on the way: the toolpath, the axes, the report and the
    /// set-points are streamed into their files (the documents checked first, so that an
    /// invalid one is refused before any file is written), the program and the picture written
    /// from the texts held.
    ///
    /// # Errors
    /// [`Error::Format`] or [`Error::Kinematics`] for a toolpath or axes document its format
    /// refuses; [`Error::Write`] naming the file that failed.
    pub fn write_dir(&self, dir: impl AsRef<Path>) -> Result<()> {
        let dir = dir.as_ref();
        self.toolpath.validate()?;
        self.axes.validate()?;
        fn text(s: &str) -> kerf_io::Contents<'_> {
            Box::new(move |w| w.write_all(s.as_bytes()))
        }
        let axis_names = self.model.axis_names();
        let toolpath = &self.toolpath;
        let axes = &self.axes;
        let report = &self.report;
        // The files before `report.json` are written (in order) by the time its contents are
        // made: their time is the `write` stage it states.
        let lap = Lap::start();
        let mut entries = vec![
            DirEntry {
                name: OUTPUTS[0],
                contents: Box::new(move |w| {
                    toolpath::to_writer(toolpath, w).map_err(|e| match e {
                        FormatError::Write { error } => error,
                        e => std::io::Error::other(e),
                    })
                }),
            },
            DirEntry {
                name: OUTPUTS[1],
                contents: Box::new(move |w| {
                    axes.to_writer(w).map_err(|e| match e {
                        kerf_kinematics::KinematicsError::Io { source, .. } => {
                            std::io::Error::new(source.kind(), source.to_string())
                        }
                        e => std::io::Error::other(e),
                    })
                }),
            },
        ];
        for p in &self.programs {
            entries.push(DirEntry {
                name: p.name.as_str(),
                contents: text(&p.text),
            });
            let model = &self.model;
            let cycle = self.cycle_s;
            entries.push(DirEntry {
                name: p.setpoints_name.as_str(),
                contents: Box::new(move |w| {
                    write_csv_to(w, axis_names, cycle, p.motion.iter(model))
                }),
            });
        }
        entries.push(DirEntry {
            name: OUTPUTS[4],
            // The text of `report_text`, streamed.
            contents: Box::new(move |w| {
                let mut report = report.clone();
                lap.stop(&mut report.timings, "write");
                serde_json::to_writer_pretty(w, &report).map_err(std::io::Error::from)
            }),
        });
        entries.push(DirEntry {
            name: OUTPUTS[5],
            contents: text(&self.plot_svg),
        });
        let view = self.view_html();
        entries.push(DirEntry {
            name: OUTPUTS[6],
            contents: Box::new(move |w| w.write_all(view.as_bytes())),
        });
        kerf_io::write_dir_all_or_nothing(dir, entries).map_err(|e| Error::Write {
            path: Some(e.path),
            source: e.error,
        })
    }
}

/// `program.nc` for one set-up; `program-1.nc`, `program-2.nc`, ... for several (each set-up is
/// a job of its own: the part is clamped anew between them).
pub fn program_names(setups: usize) -> Vec<String> {
    if setups == 1 {
        vec!["program.nc".to_string()]
    } else {
        (1..=setups).map(|k| format!("program-{k}.nc")).collect()
    }
}

/// The set-point files matching [`program_names`].
pub fn csv_names(setups: usize) -> Vec<String> {
    if setups == 1 {
        vec!["setpoints.csv".to_string()]
    } else {
        (1..=setups).map(|k| format!("setpoints-{k}.csv")).collect()
    }
}

/// The files `kerf run` writes into its output directory for one set-up, all or nothing
/// (through [`kerf_io::write_dir_all_or_nothing`]); several set-ups number the program and
/// set-point files ([`program_names`], [`csv_names`]).
pub const OUTPUTS: [&str; 7] = [
    "toolpath.json",
    "axes.json",
    "program.nc",
    "setpoints.csv",
    "report.json",
    "plot.svg",
    "view.html",
];
