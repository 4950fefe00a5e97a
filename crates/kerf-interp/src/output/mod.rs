//! Outputs: the set-points CSV of `formats.md` and G-code in eight dialects (one file each under
//! `dialects/`, their decisions the `Rules` trait of `writer.rs`), written atomically.
//!
//! - **CSV**: header `t,X,Y,Z,<tilt>,C`, one row per cycle, `t` in seconds, axes in mm and
//!   degrees; values are written in Rust's shortest round-trip form, so they read back exactly.
//! - **LinuxCNC** ([`Dialect::Linuxcnc`]): raw machine axes for a trivkins machine, cutting
//!   blocks in inverse-time feed (`G93`, an `F` on every block, `F = 60 / t` with `t` the
//!   block's planned time in seconds), `G64 P<q> Q0` with `q` the budget's controller-blending
//!   term on cuts, exact path (`G61`) on rapids, the safe preamble `G17 G21 G40 G49 G54 G80 G90`,
//!   `( ... )` comments, `M2` at the end.
//! - **LinuxCNC tool tip** ([`Dialect::LinuxcncTcp`]): for a configuration whose kinematics
//!   module computes the machine ([`linuxcnc_kinematics`], named in the header with its HAL
//!   parameters): `X Y Z` the tool tip in the workpiece frame with the rotary axes, `G94` with
//!   `F` the tip's mean planned speed of the block in mm/min (deg/min of the rotary motion on a
//!   block where the tip stands), `G64 P<q> Q0` on cuts, `G61` on rapids, each rapid split so
//!   that its tip follows kerf's joint-space traverse within [`RAPID_TCP_TOLERANCE_MM`].
//! - **Fanuc** ([`Dialect::Fanuc`], [`Dialect::FanucIjk`]): tool center point control `G43.4`
//!   (the tip with the rotary axes) or `G43.5` (with `I J K`, head machines only), `G05.1 Q1`,
//!   `G94` tip feed, `S` power, `%` and `O1000` (`dialects/fanuc.rs`).
//! - **HEIDENHAIN** ([`Dialect::Heidenhain`], [`Dialect::HeidenhainAxes`]): Klartext under
//!   `FUNCTION TCPM`, numbered `LN X Y Z TX TY TZ F` (or `L` with the rotary axes) blocks,
//!   `CYCL DEF 32` from the blending term, `FMAX` rapids; no power (`dialects/heidenhain.rs`).
//! - **Generic** ([`Dialect::Generic`]): raw machine axes, `G94` feed in the RS274/NGC sense:
//!   `F` is mm/min of the combined X Y Z machine-axis motion (deg/min of the combined rotary
//!   motion on blocks without X Y Z motion), chosen so that each block takes its planned time.
//!   It is *not* the tool tip's speed.
//! - **Sinumerik-style** ([`Dialect::Sinumerik`]): `G54` frame, `SOFT`, `G642` with `CTOL`/`OTOL`
//!   from the blending term, `TRAORI` with the tool tip and the orientation vector
//!   (`A3= B3= C3=`) in workpiece coordinates, arcs as `CIP X Y Z I1= J1= K1=` through the
//!   intermediate point; `F` is the tool tip's mean planned speed of the block (TRAORI applies
//!   it to the tip).
//!
//! Every program starts with a header (machine, source, units, feed semantics, the tolerance
//! budget term by term, the process codes) and names the source curve in a comment where each
//! path starts. Every cut (a maximal run of cutting blocks of one path, [`crate::starts_cut`])
//! is framed the same way: a rapid to the pierce point `pierce_standoff` mm above the cut's
//! start along the tool axis, the beam-on lines, a dwell of `pierce_dwell_s`, the descent to
//! the start with the beam on, the cut, and the beam-off lines before the next rapid or the
//! next path. No text of the input (curve ids, machine names,
//! file names) reaches a program except through [`comment_text`], which cannot open a new block
//! in any dialect.

use std::path::Path;

use kerf_kinematics::Axes;

use crate::block::{Block, Geometry};
use crate::error::{positive, InterpError, Result};
use crate::model::AxisModel;
use crate::DEFAULT_BLEND_TOLERANCE;

mod codes;
mod csv;
mod dialect;
mod dialects;
mod power;
mod writer;

pub use codes::{comment_text, ProcessCodes, MAX_COMMENT};
pub use csv::{csv_string, write_atomic, write_csv, write_csv_to};
pub use dialect::Dialect;
pub use dialects::{linuxcnc_kinematics, LinuxcncKinematics};
pub use power::LaserPower;
use writer::Writer;
pub use writer::{RAPID_TCP_MAX_PIECES, RAPID_TCP_MAX_STEP_DEG, RAPID_TCP_TOLERANCE_MM};

/// Where the tolerance budget's `chord` term (the cutting points' chord error against the
/// designed curve) comes from. A program states it in its header; only a bound kerf proved
/// itself may be stated without a qualifier.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub enum ChordTerm {
    /// A bound kerf certified, mm: the discretizer's tolerance (every segment proven within
    /// it), or a toolpath re-certified against its curves.
    Certified(f64),
    /// A figure an input file states and kerf has not verified, mm (a toolpath's `tolerance`
    /// read without its curves). The header says so.
    Claimed(f64),
    /// Not known: an axes file records no chord tolerance. The header says so and the total
    /// leaves it out.
    Unknown,
}

/// What goes into a program besides the blocks. Start from [`GcodeOptions::new`] (dialect
/// and feed) and the `with_*` setters.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct GcodeOptions {
    /// Dialect (given to [`GcodeOptions::new`]).
    pub dialect: Dialect,
    /// Programmed cutting feed, mm/min of the tool tip: the descent after the pierce, and the
    /// blocks' speed when no planned times are given (given to [`GcodeOptions::new`]).
    pub feed_mm_per_min: f64,
    /// The arc-fit tolerance, mm: arcs and merged lines (dialects with tool-tip control) lie
    /// within it of the cutting points. Default 0.001.
    pub fit_tolerance_mm: f64,
    /// The budget's `chord` term and where it comes from. Default [`ChordTerm::Unknown`]: a
    /// program states a chord bound only when told where it comes from. With arcs or merged
    /// lines (Sinumerik) the budget adds a `fit` term of [`fit_tolerance_mm`](Self::fit_tolerance_mm).
    pub chord_term: ChordTerm,
    /// Chord tolerance of arcs, mm: raw-axis programs write arcs as chords within it (the
    /// budget's `interpolation_chord` term). Default 0.001.
    pub chord_tolerance_mm: f64,
    /// The kinematics' linearization tolerance the axes were solved with, mm, if known (the
    /// budget's `linearization` term). Default `None`.
    pub linearization_tolerance_mm: Option<f64>,
    /// The controller's blending tolerance, mm (the budget's `controller_blending` term):
    /// `G64 P` on LinuxCNC, split half into `CTOL` and half into `OTOL` on Sinumerik. Default
    /// [`DEFAULT_BLEND_TOLERANCE`].
    pub blend_tolerance_mm: f64,
    /// The machine's pivot length, mm (tip to tilt axis): turns the orientation half of the
    /// blending term into Sinumerik's `OTOL` in degrees. Without it `OTOL` is not
    /// written. Default `None`.
    pub pivot_length_mm: Option<f64>,
    /// The machine file's `process` object (absent keys take the dialect's defaults). Default
    /// [`kerf_kinematics::Process::default`].
    pub process: kerf_kinematics::Process,
    /// The input file the program was made from (header only, escaped). Default `None`.
    pub source: Option<String>,
    /// Decimals of coordinates (default 6).
    pub decimals: usize,
    /// More header comment lines, written after the source (each through the same comment
    /// sanitizer), e.g. the placement of the part and its set-up (default none).
    pub header: Vec<String>,
    /// The controller's own cutter (kerf) compensation per path (indexed like the blocks'
    /// `path`): `Some` switches it on after the pierce descent, for the lead-in's first move
    /// (which must be a line), and off at the cut's end; the paths are then the contours
    /// themselves. LinuxCNC: `G41.1 D` / `G42.1 D`, `G40` before the beam goes off (LinuxCNC
    /// sets no output while it compensates). Sinumerik: `CUT3DC` and `G450` in the header,
    /// `OFFN=<kerf/2>` with `G41` / `G42`, `G40` and `OFFN=0` after the beam is off, `CUT2D`
    /// at the end. The other dialects refuse it ([`gcode_timed`]). Default none.
    pub cutter_compensation: Vec<Option<CutterCompensation>>,
    /// Laser power that follows the tip's speed ([`LaserPower`]; its module docs give each
    /// dialect's words). `None` (the default): the program switches the beam and commands
    /// no power.
    pub power: Option<LaserPower>,
    /// The power factor per path (indexed like the blocks' `path`; a small hole's factor from
    /// the technology's small-hole rule), 1 where missing. Default none.
    pub power_factors: Vec<f64>,
    /// Micro-joints per path (indexed like the blocks' `path`): `[start, end]` in mm of tip
    /// travel from the path's first cutting block, increasing and disjoint. The beam goes off
    /// over each with codes synchronized with motion (LinuxCNC `M63`/`M62` on the output the
    /// machine's beam codes name; the generic dialect writes the machine's own beam codes
    /// between the blocks); each block that a joint's end falls in is split there. The
    /// Sinumerik dialect refuses them. Default none.
    pub micro_joints: Vec<Vec<[f64; 2]>>,
}

/// The controller's cutter compensation of one path: the side the beam moves to, seen along
/// the path from above (the tool axis toward the viewer), and the kerf width.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CutterCompensation {
    /// True for the left of the path (`G41.1`, `G41`), false for the right (`G42.1`, `G42`).
    pub left: bool,
    /// The kerf width, mm: LinuxCNC's diameter `D`; Sinumerik's `OFFN` is half of it.
    pub kerf_width_mm: f64,
}

impl GcodeOptions {
    /// Sets [`cutter_compensation`](Self::cutter_compensation): the controller's kerf
    /// compensation per path.
    pub fn with_cutter_compensation(mut self, paths: Vec<Option<CutterCompensation>>) -> Self {
        self.cutter_compensation = paths;
        self
    }

    /// Sets [`power`](Self::power): laser power that follows the tip's speed.
    pub fn with_power(mut self, power: Option<LaserPower>) -> Self {
        self.power = power;
        self
    }

    /// Sets [`micro_joints`](Self::micro_joints): each path's micro-joints.
    pub fn with_micro_joints(mut self, joints: Vec<Vec<[f64; 2]>>) -> Self {
        self.micro_joints = joints;
        self
    }

    /// Sets [`power_factors`](Self::power_factors): each path's power factor.
    pub fn with_power_factors(mut self, factors: Vec<f64>) -> Self {
        self.power_factors = factors;
        self
    }

    /// Sets [`dialect`](Self::dialect): the G-code dialect.
    pub fn with_dialect(mut self, dialect: Dialect) -> Self {
        self.dialect = dialect;
        self
    }

    /// Sets [`feed_mm_per_min`](Self::feed_mm_per_min): programmed cutting feed, mm/min of
    /// the tool tip.
    pub fn with_feed_mm_per_min(mut self, feed_mm_per_min: f64) -> Self {
        self.feed_mm_per_min = feed_mm_per_min;
        self
    }

    /// Sets [`fit_tolerance_mm`](Self::fit_tolerance_mm): the arc-fit tolerance, mm.
    pub fn with_fit_tolerance_mm(mut self, fit_tolerance_mm: f64) -> Self {
        self.fit_tolerance_mm = fit_tolerance_mm;
        self
    }

    /// Sets [`chord_term`](Self::chord_term): the budget's `chord` term and where it comes
    /// from.
    pub fn with_chord_term(mut self, chord_term: ChordTerm) -> Self {
        self.chord_term = chord_term;
        self
    }

    /// Sets [`chord_tolerance_mm`](Self::chord_tolerance_mm): chord tolerance of arcs, mm.
    pub fn with_chord_tolerance_mm(mut self, chord_tolerance_mm: f64) -> Self {
        self.chord_tolerance_mm = chord_tolerance_mm;
        self
    }

    /// Sets [`linearization_tolerance_mm`](Self::linearization_tolerance_mm): the
    /// kinematics' linearization tolerance the axes were solved with, mm, if known (the
    /// budget's `linearization` term). Default `None`.
    pub fn with_linearization_tolerance_mm(
        mut self,
        linearization_tolerance_mm: Option<f64>,
    ) -> Self {
        self.linearization_tolerance_mm = linearization_tolerance_mm;
        self
    }

    /// Sets [`blend_tolerance_mm`](Self::blend_tolerance_mm): the controller's blending
    /// tolerance, mm (the budget's `controller_blending` term).
    pub fn with_blend_tolerance_mm(mut self, blend_tolerance_mm: f64) -> Self {
        self.blend_tolerance_mm = blend_tolerance_mm;
        self
    }

    /// Sets [`pivot_length_mm`](Self::pivot_length_mm): the machine's pivot length, mm (tip
    /// to tilt axis).
    pub fn with_pivot_length_mm(mut self, pivot_length_mm: Option<f64>) -> Self {
        self.pivot_length_mm = pivot_length_mm;
        self
    }

    /// Sets [`process`](Self::process): the machine file's `process` object (absent keys
    /// take the dialect's defaults).
    pub fn with_process(mut self, process: kerf_kinematics::Process) -> Self {
        self.process = process;
        self
    }

    /// Sets [`source`](Self::source): the input file the program was made from (header
    /// only, escaped).
    pub fn with_source(mut self, source: Option<String>) -> Self {
        self.source = source;
        self
    }

    /// Sets [`decimals`](Self::decimals): decimals of coordinates (default 6).
    pub fn with_decimals(mut self, decimals: usize) -> Self {
        self.decimals = decimals;
        self
    }

    /// Sets [`header`](Self::header): more header comment lines, written after the source
    /// (each through the same comment sanitizer), e.g.
    pub fn with_header(mut self, header: Vec<String>) -> Self {
        self.header = header;
        self
    }

    /// Options for `dialect` at `feed` mm/min, with 0.001 mm tolerances, an unknown chord
    /// term, the default blending term, the dialect's default process codes and 6 decimals.
    pub fn new(dialect: Dialect, feed: f64) -> Self {
        Self {
            dialect,
            feed_mm_per_min: feed,
            fit_tolerance_mm: 0.001,
            chord_term: ChordTerm::Unknown,
            chord_tolerance_mm: 0.001,
            linearization_tolerance_mm: None,
            blend_tolerance_mm: DEFAULT_BLEND_TOLERANCE,
            pivot_length_mm: None,
            process: kerf_kinematics::Process::default(),
            source: None,
            decimals: 6,
            header: Vec::new(),
            cutter_compensation: Vec::new(),
            power: None,
            power_factors: Vec::new(),
            micro_joints: Vec::new(),
        }
    }

    /// The tolerance budget term by term, mm, named as in `report.json`: `chord` (`None` when
    /// unknown; claimed or certified as [`chord_term`](Self::chord_term) says), `fit` (only
    /// for dialects with tool-tip control, whose arcs and merged lines lie within
    /// [`fit_tolerance_mm`](Self::fit_tolerance_mm) of the polyline of cutting points, so
    /// within `chord + fit` of the curve), `linearization` (`None` when unknown),
    /// `interpolation_chord`, `controller_blending`.
    pub fn budget(&self) -> Vec<(&'static str, Option<f64>)> {
        let chord = match self.chord_term {
            ChordTerm::Certified(mm) | ChordTerm::Claimed(mm) => Some(mm),
            ChordTerm::Unknown => None,
        };
        let mut terms = vec![("chord", chord)];
        if !self.dialect.raw_axes() {
            terms.push(("fit", Some(self.fit_tolerance_mm)));
        }
        terms.extend([
            ("linearization", self.linearization_tolerance_mm),
            ("interpolation_chord", Some(self.chord_tolerance_mm)),
            ("controller_blending", Some(self.blend_tolerance_mm)),
        ]);
        terms
    }

    /// The sum of the known budget terms, mm, rounded to 1e-12 mm: the binary sum of decimal
    /// terms carries noise (0.01 + 0.01 + 0.005 + 0.001 + 0.005 is 0.031000000000000003),
    /// which neither the program's header nor report.json should state.
    pub fn budget_total(&self) -> f64 {
        let sum: f64 = self.budget().iter().filter_map(|(_, v)| *v).sum();
        if sum.is_finite() {
            (sum * 1e12).round() / 1e12
        } else {
            sum
        }
    }
}

/// The G-code program of `blocks`.
///
/// `path_ids[b.path]` names the source curve of block `b` (missing ids are written as
/// `path <n>`); `block_feeds`, if given, is the planned tip speed (mm/min) of each block, from
/// which its time is `length / feed`; otherwise every cutting block runs at
/// `opts.feed_mm_per_min`. For
/// the planned block times of a [`crate::Motion`] use [`gcode_motion`].
///
/// # Errors
/// As [`gcode_timed`].
pub fn gcode<M: AxisModel>(
    model: &M,
    blocks: &[Block],
    path_ids: &[String],
    block_feeds: Option<&[f64]>,
    opts: &GcodeOptions,
) -> Result<String> {
    positive("feed_mm_per_min", opts.feed_mm_per_min)?;
    let times: Vec<f64> = blocks
        .iter()
        .enumerate()
        .map(|(i, b)| {
            let f = block_feeds
                .and_then(|f| f.get(i).copied())
                .filter(|f| f.is_finite() && *f > 0.0)
                .unwrap_or(opts.feed_mm_per_min);
            b.length() / (f / 60.0)
        })
        .collect();
    gcode_timed(model, blocks, path_ids, &times, opts)
}

/// The G-code program of a planned motion: every cutting block takes the time the plan gives
/// it ([`crate::Motion::block_duration`]).
///
/// # Errors
/// As [`gcode_timed`].
pub fn gcode_motion<M: AxisModel>(
    model: &M,
    motion: &crate::Motion,
    path_ids: &[String],
    opts: &GcodeOptions,
) -> Result<String> {
    let times: Vec<f64> = (0..motion.blocks().len())
        .map(|b| motion.block_duration(b))
        .collect();
    gcode_timed(model, motion.blocks(), path_ids, &times, opts)
}

/// The generic-dialect rule: a dialect that programs the raw machine axes runs only blocks
/// between neighbouring poses of the kinematics (whose non-linearity error was checked), never
/// an arc nor a line merged over several poses.
fn refuse_unchecked_blocks(blocks: &[Block], dialect: Dialect) -> Result<()> {
    if !dialect.raw_axes() {
        return Ok(());
    }
    for (k, b) in blocks.iter().enumerate() {
        if b.rapid {
            continue;
        }
        let what = match b.geometry {
            Geometry::Arc(_) => "an arc".to_string(),
            _ if b.stations[1] > b.stations[0] + 1 => format!(
                "a line merged over {} poses",
                b.stations[1] - b.stations[0] + 1
            ),
            _ => continue,
        };
        return Err(InterpError::UncheckedBlock {
            dialect: dialect.name(),
            block: k,
            what,
        });
    }
    Ok(())
}

/// Every pierce point (the rapid's end above each cut's start) within the machine's axis
/// ranges: the blocks were planned within them, the pierce standoff is added here.
fn refuse_pierces_out_of_range<M: AxisModel + ?Sized>(
    model: &M,
    blocks: &[Block],
    process: &ProcessCodes,
) -> Result<()> {
    for (k, b) in blocks.iter().enumerate() {
        if !crate::starts_cut(blocks, k) {
            continue;
        }
        let (_, q, _) = writer::pierce_point(model, process, b);
        if let Some((axis, value, [min, max])) = out_of_range(model, &q) {
            return Err(InterpError::PierceOutOfRange {
                path: b.path,
                standoff_mm: process.pierce_standoff,
                axis,
                value,
                min,
                max,
            });
        }
    }
    Ok(())
}

/// The first axis of `q` outside its range: its name, value and range.
fn out_of_range<M: AxisModel + ?Sized>(model: &M, q: &Axes) -> Option<(String, f64, [f64; 2])> {
    let names = model.axis_names();
    model
        .limits()
        .range
        .iter()
        .enumerate()
        .find_map(|(axis, range)| {
            let [min, max] = (*range)?;
            (!(q[axis] >= min && q[axis] <= max))
                .then(|| (names[axis].to_string(), q[axis], [min, max]))
        })
}

/// The G-code program of `blocks`, cutting block `b` taking `block_times[b]` seconds (a
/// missing, zero or non-finite time falls back to
/// `length / opts.feed_mm_per_min`); rapid blocks are
/// `G0` at the controller's rapid rate.
///
/// # Errors
/// [`InterpError::BadParameter`] for a feed, chord or blending tolerance that is not finite
/// and > 0; [`InterpError::Process`] for unusable process codes;
/// [`InterpError::UncheckedBlock`] for an arc or a merged line in a program for a dialect that
/// gives the raw machine axes ([`Dialect::raw_axes`]); [`InterpError::PierceOutOfRange`] for a
/// pierce point (the standoff above a cut's start) outside an axis range;
/// [`InterpError::RetractOutOfRange`] for the retract that ends a program whose last block is
/// a cut (so that a beam-off synchronized with motion fires) outside an axis range;
/// [`InterpError::DialectMachine`] for [`Dialect::LinuxcncTcp`] on a machine no LinuxCNC
/// kinematics module computes ([`linuxcnc_kinematics`]).
pub fn gcode_timed<M: AxisModel>(
    model: &M,
    blocks: &[Block],
    path_ids: &[String],
    block_times: &[f64],
    opts: &GcodeOptions,
) -> Result<String> {
    positive("feed_mm_per_min", opts.feed_mm_per_min)?;
    positive("chord_tolerance_mm", opts.chord_tolerance_mm)?;
    positive("blend_tolerance_mm", opts.blend_tolerance_mm)?;
    refuse_unchecked_blocks(blocks, opts.dialect)?;
    let rules = opts.dialect.rules();
    let model: &dyn AxisModel = model;
    let machine_lines = rules.machine_lines(model)?;
    let compensating = opts.cutter_compensation.iter().any(Option::is_some);
    if compensating && !rules.controller_compensation() {
        return Err(InterpError::BadParameter {
            name: "cutter_compensation",
            value: 1.0,
            reason: "the controller's kerf compensation is written for the linuxcnc (G41.1/G42.1) and sinumerik (CUT3DC with G41/G42) dialects only; compensate in the computer for the others",
        });
    }
    let process = ProcessCodes::resolve(opts.dialect, &opts.process)?;
    if let Some(power) = &opts.power {
        power.validate()?;
    }
    crate::error::unit_factors("power_factors", &opts.power_factors)?;
    let joint_codes = if opts.micro_joints.iter().any(|j| !j.is_empty()) {
        let refuse = |reason: &'static str| InterpError::BadParameter {
            name: "micro_joints",
            value: 1.0,
            reason,
        };
        if compensating {
            return Err(refuse("micro-joints are not written while the controller compensates the kerf (LinuxCNC sets no output then); compensate in the computer"));
        }
        Some(rules.joint_codes(&process).map_err(refuse)?)
    } else {
        None
    };
    refuse_pierces_out_of_range(model, blocks, &process)?;
    let mut w = Writer::new(model, opts, process, joint_codes, machine_lines);
    w.header(blocks);
    let mut last_path = usize::MAX;
    for (bi, b) in blocks.iter().enumerate() {
        // A cut ends at a rapid, and where the next path starts without one (it starts where
        // the last path ended, at the same axes): each path is pierced and compensated as its
        // own cut, with its own power factor and micro-joints ([`crate::starts_cut`]).
        if w.in_cut && (b.rapid || crate::starts_cut(blocks, bi)) {
            w.end_cut();
        }
        if b.path != last_path {
            last_path = b.path;
            let id = path_ids
                .get(b.path)
                .cloned()
                .unwrap_or_else(|| format!("path {}", b.path));
            let span = b
                .params
                .map_or(String::new(), |p| format!(", t = {}", p[0]));
            let line = opts.dialect.comment(&format!(
                "curve {}, from cutting point {}{span}",
                comment_text(&id),
                b.stations[0]
            ));
            w.line(&line);
        }
        if b.rapid {
            // The approach that ends where a cut starts is replaced by the rapid to that
            // cut's pierce point (on the approach line, `pierce_standoff` above the start).
            let approach = blocks.get(bi + 1).is_some_and(|n| !n.rapid);
            if !approach {
                w.rapid(b.end_tip(), b.end_axes, b.end_tool_axis);
            }
            continue;
        }
        if !w.in_cut {
            w.factor = opts.power_factors.get(b.path).copied().unwrap_or(1.0);
            w.joints = opts.micro_joints.get(b.path).cloned().unwrap_or_default();
            w.path_s = 0.0;
            w.start_cut(b);
            if let Some(Some(c)) = opts.cutter_compensation.get(b.path) {
                // The controllers select their compensation on a line (LinuxCNC's entry move,
                // Sinumerik's G41/G42 in a G1 block), not on an arc.
                if matches!(b.geometry, Geometry::Arc(_)) {
                    return Err(InterpError::CompensationOnArc {
                        path: path_ids
                            .get(b.path)
                            .cloned()
                            .unwrap_or_else(|| format!("path {}", b.path)),
                    });
                }
                w.compensation_on(c);
            }
        }
        let t = block_times
            .get(bi)
            .copied()
            .filter(|t| t.is_finite() && *t > 0.0)
            .unwrap_or_else(|| b.length() / (opts.feed_mm_per_min / 60.0));
        w.cut(b, t);
    }
    if w.in_cut {
        w.end_cut();
    }
    // A program whose last block is a cut ends with a move: a beam-off synchronized with
    // motion (LinuxCNC `M63`) takes effect only when the next move starts, and after `M2`
    // none would, leaving the beam on.
    if let Some(b) = blocks.last().filter(|b| !b.rapid) {
        let (p, q, u, h) = writer::exit_point(model, &w.process, b);
        if let Some((axis, value, [min, max])) = out_of_range(model, &q) {
            return Err(InterpError::RetractOutOfRange {
                path: b.path,
                retract_mm: h,
                axis,
                value,
                min,
                max,
            });
        }
        w.rapid(p, q, u);
    }
    if let Some(deviation_mm) = w.rapid_too_curved {
        return Err(InterpError::RapidTooCurved {
            dialect: rules.name(),
            pieces: RAPID_TCP_MAX_PIECES,
            deviation_mm,
            tolerance_mm: RAPID_TCP_TOLERANCE_MM,
        });
    }
    if w.power().is_some() {
        rules.power_off(&mut w);
    }
    rules.footer(&mut w);
    Ok(rules.finish(w.finish()))
}

/// Writes [`gcode`] to `path` atomically.
///
/// # Errors
/// As [`gcode`], plus [`InterpError::Io`].
pub fn write_gcode<M: AxisModel>(
    path: impl AsRef<Path>,
    model: &M,
    blocks: &[Block],
    path_ids: &[String],
    block_feeds: Option<&[f64]>,
    opts: &GcodeOptions,
) -> Result<()> {
    let text = gcode(model, blocks, path_ids, block_feeds, opts)?;
    write_atomic(path.as_ref(), text.as_bytes())
}
