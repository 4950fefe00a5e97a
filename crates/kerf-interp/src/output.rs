//! Outputs: the set-points CSV of `formats.md` and G-code in three dialects, written atomically.
//!
//! - **CSV**: header `t,X,Y,Z,<tilt>,C`, one row per cycle, `t` in seconds, axes in mm and
//!   degrees; values are written in Rust's shortest round-trip form, so they read back exactly.
//! - **LinuxCNC** ([`Dialect::Linuxcnc`]): raw machine axes for a trivkins machine, cutting
//!   blocks in inverse-time feed (`G93`, an `F` on every block, `F = 60 / t` with `t` the
//!   block's planned time in seconds), `G64 P<q> Q0` with `q` the budget's controller-blending
//!   term on cuts, exact path (`G61`) on rapids, the safe preamble `G17 G21 G40 G49 G54 G80 G90`,
//!   `( ... )` comments, `M2` at the end.
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
//! path starts. Every cut (a maximal run of cutting blocks) is framed the same way: a rapid to
//! the pierce point `pierce_standoff` mm above the cut's start along the tool axis, the beam-on
//! lines, a dwell of `pierce_dwell_s`, the descent to the start with the beam on, the cut, and
//! the beam-off lines before the next rapid. No text of the input (curve ids, machine names,
//! file names) reaches a program except through [`comment_text`], which cannot open a new block
//! in any dialect.

use std::borrow::Borrow;
use std::io::Write;
use std::path::Path;

use crate::block::{Block, Geometry};
use crate::chord::max_step;
use crate::error::{positive, InterpError, Result};
use crate::model::AxisModel;

/// The CSV text: header `t,<names>` and one row `t,q0,...,q4` per set-point, row `i` at
/// `t = i * cycle` seconds (written with 9 decimals). Builds the whole text in memory; for
/// long programs stream with [`write_csv_to`] or [`write_csv`].
pub fn csv_string(names: [&str; 5], cycle: f64, rows: &[[f64; 5]]) -> String {
    let mut bytes = Vec::with_capacity(rows.len() * 80 + 32);
    // Writing into a Vec cannot fail.
    let _ = write_csv_to(&mut bytes, names, cycle, rows);
    // Only ASCII digits, signs, dots, commas and the axis names: valid UTF-8.
    String::from_utf8_lossy(&bytes).into_owned()
}

/// Streams the CSV of [`csv_string`] into `w`, one row at a time: memory stays bounded however
/// many set-points `rows` yields (give it [`crate::Motion::iter`]).
///
/// # Errors
/// The writer's error.
pub fn write_csv_to<R: Borrow<[f64; 5]>>(
    w: &mut dyn Write,
    names: [&str; 5],
    cycle: f64,
    rows: impl IntoIterator<Item = R>,
) -> std::io::Result<()> {
    w.write_all(b"t")?;
    for n in names {
        write!(w, ",{n}")?;
    }
    w.write_all(b"\n")?;
    for (i, q) in rows.into_iter().enumerate() {
        write!(w, "{:.9}", i as f64 * cycle)?;
        for v in q.borrow() {
            write!(w, ",{}", v + 0.0)?; // + 0.0 turns -0 into 0
        }
        w.write_all(b"\n")?;
    }
    Ok(())
}

/// Writes the CSV of [`csv_string`] to `path` (`-`: standard output) through
/// [`kerf_io::write_file`], streaming `rows` (memory stays bounded with
/// [`crate::Motion::iter`]): atomically onto a new path or a regular file, written through
/// to a device or FIFO.
///
/// # Errors
/// [`InterpError::Io`]; [`InterpError::BadParameter`] for a cycle that is not finite and > 0.
pub fn write_csv<R: Borrow<[f64; 5]>>(
    path: impl AsRef<Path>,
    names: [&str; 5],
    cycle: f64,
    rows: impl IntoIterator<Item = R>,
) -> Result<()> {
    positive("cycle", cycle)?;
    let path = path.as_ref();
    kerf_io::write_file(path, |w| write_csv_to(w, names, cycle, rows)).map_err(|e| {
        InterpError::Io {
            path: path.display().to_string(),
            message: e.to_string(),
        }
    })
}

/// Writes `bytes` to `path` through [`kerf_io::write_file`]: a temporary file in the same
/// directory renamed over `path` once complete (a reader never sees a half-written file), a
/// device or FIFO written through, a symbolic link's target written; new files get `0o666`
/// less the umask.
///
/// # Errors
/// [`InterpError::Io`] naming the path.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    kerf_io::write_file(path, |w| w.write_all(bytes)).map_err(|e| InterpError::Io {
        path: path.display().to_string(),
        message: e.to_string(),
    })
}

/// G-code dialect.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Dialect {
    /// `G1 X Y Z A C F` with machine axis values, `G94` feed of the machine axes
    /// (RS274/NGC rule), `;` comments, `M30`.
    Generic,
    /// Sinumerik-style `TRAORI`: tool tip, orientation vector, `CIP` arcs, `G54`, `SOFT`,
    /// `G642` with `CTOL`/`OTOL`, `;` comments, `M30`.
    Sinumerik,
    /// LinuxCNC (trivkins, the machine's axis letters): inverse-time feed `G93`, `G64 P` on
    /// cuts and `G61` on rapids, `( ... )` comments, `M2`.
    Linuxcnc,
}

impl Dialect {
    /// The dialect's name as the CLI spells it.
    pub fn name(self) -> &'static str {
        match self {
            Dialect::Generic => "generic",
            Dialect::Sinumerik => "sinumerik",
            Dialect::Linuxcnc => "linuxcnc",
        }
    }

    /// True for the dialects that program the raw machine axes (a controller that interpolates
    /// the axes linearly between blocks: no arcs may be fitted for them).
    pub fn raw_axes(self) -> bool {
        !matches!(self, Dialect::Sinumerik)
    }

    /// The process codes used when the machine file's `process` object lacks a key:
    ///
    /// | dialect | beam on | beam off | dwell | standoff |
    /// |---|---|---|---|---|
    /// | linuxcnc | `M64 P0` | `M65 P0` | 0.2 s | 1.5 mm |
    /// | generic | `M3` | `M5` | 0.2 s | 1.5 mm |
    /// | sinumerik | `M3` | `M5` | 0.2 s | 1.5 mm |
    ///
    /// LinuxCNC's `M64`/`M65` switch the output when every motion queued before them has
    /// finished (they break blending): the dwell after `M64` runs with the beam on and the
    /// beam goes off where the cut ends. (`M62`/`M63` would act at the start of the *next*
    /// motion: the dwell would run with the beam off, and a last `M63` would never fire.)
    pub fn default_process(self) -> ProcessCodes {
        let (on, off) = match self {
            Dialect::Linuxcnc => ("M64 P0", "M65 P0"),
            Dialect::Generic | Dialect::Sinumerik => ("M3", "M5"),
        };
        ProcessCodes {
            beam_on: vec![on.to_string()],
            beam_off: vec![off.to_string()],
            pierce_dwell_s: 0.2,
            pierce_standoff: 1.5,
        }
    }

    /// One whole-line comment in the dialect's syntax, its text escaped as by
    /// [`comment_text`] but not cut (text from the input must already have been through
    /// [`comment_text`], which cuts it).
    fn comment(self, text: &str) -> String {
        let text = escape(text, usize::MAX);
        match self {
            Dialect::Linuxcnc => format!("({text})"),
            Dialect::Generic | Dialect::Sinumerik => format!("; {text}"),
        }
    }
}

/// The process codes of a program, every value resolved (the machine file's `process` keys
/// over the dialect's [`Dialect::default_process`]).
#[derive(Debug, Clone, PartialEq)]
pub struct ProcessCodes {
    /// Lines that switch the beam on, written as given.
    pub beam_on: Vec<String>,
    /// Lines that switch the beam off.
    pub beam_off: Vec<String>,
    /// Dwell at the pierce point with the beam on, seconds.
    pub pierce_dwell_s: f64,
    /// Height of the pierce point above the cut's start along the tool axis, mm.
    pub pierce_standoff: f64,
}

impl ProcessCodes {
    /// `process` over the defaults of `dialect`, checked as the machine reader checks a file
    /// (a library caller may have built `process` by hand).
    ///
    /// # Errors
    /// [`InterpError::Process`] naming the key, as
    /// `process.pierce_dwell_s: must be finite and >= 0 (got -1)`.
    pub fn resolve(dialect: Dialect, process: &kerf_kinematics::Process) -> Result<Self> {
        process
            .validate()
            .map_err(|e| InterpError::Process(e.to_string()))?;
        let d = dialect.default_process();
        Ok(Self {
            beam_on: process.beam_on.clone().unwrap_or(d.beam_on),
            beam_off: process.beam_off.clone().unwrap_or(d.beam_off),
            pierce_dwell_s: process.pierce_dwell_s.unwrap_or(d.pierce_dwell_s),
            pierce_standoff: process.pierce_standoff.unwrap_or(d.pierce_standoff),
        })
    }

    /// Time of the descent from the pierce point to the cut's start, seconds, at `feed`
    /// mm/min (the writer programs the descent at the cutting feed).
    pub fn descent_s(&self, feed: f64) -> f64 {
        if self.pierce_standoff > 0.0 && feed > 0.0 {
            self.pierce_standoff / (feed / 60.0)
        } else {
            0.0
        }
    }
}

/// The longest comment text [`comment_text`] returns, in bytes (the rest is cut and `...`
/// appended): LinuxCNC refuses lines over 255 characters.
pub const MAX_COMMENT: usize = 160;

/// Text made safe for a comment in every dialect: printable ASCII is kept except `(` and `)`,
/// which become `[` and `]` (a parenthesis would close or nest a LinuxCNC comment); every
/// other character (line feed, carriage return, NUL, tab, other control characters, Unicode
/// line separators, any non-ASCII) becomes the visible escape `\u{hex}`. The result has no
/// character that can end a line or a comment, so it can never start a new block; it is cut to
/// [`MAX_COMMENT`] bytes.
///
/// ```
/// use kerf_interp::comment_text;
/// assert_eq!(comment_text("hole\nG0 X1400\nM30"), "hole\\u{a}G0 X1400\\u{a}M30");
/// assert_eq!(comment_text(")G0X1("), "]G0X1[");
/// assert_eq!(comment_text("Stoßblech"), "Sto\\u{df}blech");
/// ```
pub fn comment_text(text: &str) -> String {
    escape(text, MAX_COMMENT)
}

/// The escaping of [`comment_text`], cut at `max` bytes.
fn escape(text: &str, max: usize) -> String {
    let mut out = String::with_capacity(text.len().min(max) + 8);
    for c in text.chars() {
        let piece = match c {
            '(' => "[".to_string(),
            ')' => "]".to_string(),
            ' '..='~' => c.to_string(),
            _ => format!("\\u{{{:x}}}", c as u32),
        };
        if out.len() + piece.len() > max {
            out.push_str("...");
            break;
        }
        out.push_str(&piece);
    }
    out
}

/// The default controller-blending term of the tolerance budget, mm: LinuxCNC's `G64 P`,
/// Sinumerik's `CTOL` plus the tip error of `OTOL`.
pub const DEFAULT_BLEND_TOLERANCE: f64 = 0.005;

/// What goes into a program besides the blocks.
#[derive(Debug, Clone, PartialEq)]
pub struct GcodeOptions {
    /// Dialect.
    pub dialect: Dialect,
    /// Programmed cutting feed, mm/min of the tool tip: the descent after the pierce, and the
    /// blocks' speed when no planned times are given.
    pub feed: f64,
    /// The discretizer's chord tolerance (also the arc-fit tolerance), mm: the budget's
    /// `chord` term.
    pub fit_tolerance: f64,
    /// Chord tolerance of arcs, mm: raw-axis programs write arcs as chords within it (the
    /// budget's `interpolation_chord` term).
    pub chord_tolerance: f64,
    /// The kinematics' linearization tolerance the axes were solved with, mm, if known (the
    /// budget's `linearization` term).
    pub linearization_tolerance: Option<f64>,
    /// The controller's blending tolerance, mm (the budget's `controller_blending` term):
    /// `G64 P` on LinuxCNC, split half into `CTOL` and half into `OTOL` on Sinumerik.
    pub blend_tolerance: f64,
    /// The machine's pivot length, mm (tip to tilt axis): turns the orientation half of the
    /// blending term into Sinumerik's `OTOL` in degrees. Without it `OTOL` is not written.
    pub pivot_length: Option<f64>,
    /// The machine file's `process` object (absent keys take the dialect's defaults).
    pub process: kerf_kinematics::Process,
    /// The input file the program was made from (header only, escaped).
    pub source: Option<String>,
    /// Decimals of coordinates (default 6).
    pub decimals: usize,
    /// More header comment lines, written after the source (each through the same comment
    /// sanitizer), e.g. the placement of the part and its set-up (default none).
    pub header: Vec<String>,
}

impl GcodeOptions {
    /// Options for `dialect` at `feed` mm/min, with 0.001 mm tolerances, the default blending
    /// term, the dialect's default process codes and 6 decimals.
    pub fn new(dialect: Dialect, feed: f64) -> Self {
        Self {
            dialect,
            feed,
            fit_tolerance: 0.001,
            chord_tolerance: 0.001,
            linearization_tolerance: None,
            blend_tolerance: DEFAULT_BLEND_TOLERANCE,
            pivot_length: None,
            process: kerf_kinematics::Process::default(),
            source: None,
            decimals: 6,
            header: Vec::new(),
        }
    }

    /// The tolerance budget term by term, mm, named as in `report.json`: `chord`,
    /// `linearization` (`None` when unknown), `interpolation_chord`, `controller_blending`.
    pub fn budget(&self) -> [(&'static str, Option<f64>); 4] {
        [
            ("chord", Some(self.fit_tolerance)),
            ("linearization", self.linearization_tolerance),
            ("interpolation_chord", Some(self.chord_tolerance)),
            ("controller_blending", Some(self.blend_tolerance)),
        ]
    }

    /// The sum of the known budget terms, mm.
    pub fn budget_total(&self) -> f64 {
        self.budget().iter().filter_map(|(_, v)| *v).sum()
    }
}

/// The G-code program of `blocks`.
///
/// `path_ids[b.path]` names the source curve of block `b` (missing ids are written as
/// `path <n>`); `block_feeds`, if given, is the planned tip speed (mm/min) of each block, from
/// which its time is `length / feed`; otherwise every cutting block runs at `opts.feed`. For
/// the planned block times of a [`crate::Motion`] use [`gcode_motion`].
///
/// # Errors
/// As [`gcode_timed`].
pub fn gcode<M: AxisModel + ?Sized>(
    model: &M,
    blocks: &[Block],
    path_ids: &[String],
    block_feeds: Option<&[f64]>,
    opts: &GcodeOptions,
) -> Result<String> {
    positive("feed", opts.feed)?;
    let times: Vec<f64> = blocks
        .iter()
        .enumerate()
        .map(|(i, b)| {
            let f = block_feeds
                .and_then(|f| f.get(i).copied())
                .filter(|f| f.is_finite() && *f > 0.0)
                .unwrap_or(opts.feed);
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
pub fn gcode_motion<M: AxisModel + ?Sized>(
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

/// The G-code program of `blocks`, cutting block `b` taking `block_times[b]` seconds (a
/// missing, zero or non-finite time falls back to `length / opts.feed`); rapid blocks are
/// `G0` at the controller's rapid rate.
///
/// # Errors
/// [`InterpError::BadParameter`] for a feed, chord or blending tolerance that is not finite
/// and > 0; [`InterpError::Process`] for unusable process codes;
/// [`InterpError::UncheckedBlock`] for an arc or a merged line in a program for a dialect that
/// gives the raw machine axes ([`Dialect::raw_axes`]).
pub fn gcode_timed<M: AxisModel + ?Sized>(
    model: &M,
    blocks: &[Block],
    path_ids: &[String],
    block_times: &[f64],
    opts: &GcodeOptions,
) -> Result<String> {
    positive("feed", opts.feed)?;
    positive("chord_tolerance", opts.chord_tolerance)?;
    positive("blend_tolerance", opts.blend_tolerance)?;
    refuse_unchecked_blocks(blocks, opts.dialect)?;
    let process = ProcessCodes::resolve(opts.dialect, &opts.process)?;
    let mut w = Writer {
        model,
        opts,
        process,
        names: model.axis_names(),
        d: opts.decimals.min(12),
        s: String::new(),
        last: None,
        in_cut: false,
        last_f: None,
    };
    w.header(blocks);
    let mut last_path = usize::MAX;
    for (bi, b) in blocks.iter().enumerate() {
        if b.rapid && w.in_cut {
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
            w.start_cut(b);
        }
        let t = block_times
            .get(bi)
            .copied()
            .filter(|t| t.is_finite() && *t > 0.0)
            .unwrap_or_else(|| b.length() / (opts.feed / 60.0));
        w.cut(b, t);
    }
    if w.in_cut {
        w.end_cut();
    }
    match opts.dialect {
        Dialect::Linuxcnc => w.line("M2"),
        Dialect::Generic => w.line("M30"),
        Dialect::Sinumerik => {
            w.line("TRAFOOF");
            w.line("M30");
        }
    }
    Ok(w.s)
}

/// The state of one program being written.
struct Writer<'a, M: AxisModel + ?Sized> {
    model: &'a M,
    opts: &'a GcodeOptions,
    process: ProcessCodes,
    names: [&'a str; 5],
    d: usize,
    s: String,
    /// The axis words last written (raw-axis dialects), as printed, for feed and zero-move
    /// decisions on the values the controller reads.
    last: Option<[f64; 5]>,
    in_cut: bool,
    /// The last `F` written (Sinumerik, modal).
    last_f: Option<String>,
}

impl<M: AxisModel + ?Sized> Writer<'_, M> {
    fn line(&mut self, l: &str) {
        self.s.push_str(l.trim_end());
        self.s.push('\n');
    }

    fn comment(&mut self, text: &str) {
        let l = self.opts.dialect.comment(text);
        self.line(&l);
    }

    /// A coordinate as written (no `-0`).
    fn num(&self, v: f64) -> String {
        let t = format!("{:.*}", self.d, v);
        match t.strip_prefix('-') {
            Some(rest) if rest.bytes().all(|c| c == b'0' || c == b'.') => rest.to_string(),
            _ => t,
        }
    }

    /// Axis values rounded as the program writes them.
    fn printed(&self, q: &[f64; 5]) -> [f64; 5] {
        q.map(|v| self.num(v).parse().unwrap_or(v))
    }

    fn axis_words(&self, q: &[f64; 5]) -> String {
        let n = &self.names;
        format!(
            "{}{} {}{} {}{} {}{} {}{}",
            n[0],
            self.num(q[0]),
            n[1],
            self.num(q[1]),
            n[2],
            self.num(q[2]),
            n[3],
            self.num(q[3]),
            n[4],
            self.num(q[4])
        )
    }

    fn tip_words(&self, p: &nalgebra::Point3<f64>, u: &nalgebra::Vector3<f64>) -> String {
        format!(
            "X{} Y{} Z{} A3={} B3={} C3={}",
            self.num(p.x),
            self.num(p.y),
            self.num(p.z),
            self.num(u.x),
            self.num(u.y),
            self.num(u.z)
        )
    }

    fn header(&mut self, blocks: &[Block]) {
        let o = self.opts;
        let n = self.names;
        let counts = crate::fit::BlockCounts::of(blocks);
        let (title, feed, arcs_as) = match o.dialect {
            Dialect::Linuxcnc => (
                format!(
                    "kerf LinuxCNC program: trivkins machine axes {} {} {} {} {}, no tool-tip control",
                    n[0], n[1], n[2], n[3], n[4]
                ),
                "feed: G93 inverse time on every cutting block, F = 60 / planned block time in s,\nfeed: so the tool tip moves at kerf's planned speed; rapids G0 in exact path G61".to_string(),
                "arcs written as G1 chords",
            ),
            Dialect::Generic => (
                format!(
                    "kerf generic 5-axis program: machine axes {} {} {} {} {}, no tool-tip control",
                    n[0], n[1], n[2], n[3], n[4]
                ),
                format!(
                    "feed: G94, F in mm/min of the combined {} {} {} machine-axis motion, NOT of the tool tip;\nfeed: on blocks without {} {} {} motion F is deg/min of the combined rotary motion (RS274/NGC rule);\nfeed: each F makes its block take kerf's planned time",
                    n[0], n[1], n[2], n[0], n[1], n[2]
                ),
                "arcs written as G1 chords",
            ),
            Dialect::Sinumerik => (
                "kerf Sinumerik-style program: TRAORI, tool tip X Y Z and orientation vector A3 B3 C3 in workpiece coordinates".to_string(),
                "feed: G94, F in mm/min of the tool tip (TRAORI), the block's mean planned speed".to_string(),
                "arcs as CIP through the intermediate point",
            ),
        };
        self.comment(&title);
        let machine = format!("machine: {}", comment_text(self.model.name()));
        self.comment(&machine);
        if let Some(src) = &o.source {
            self.comment(&format!("source: {}", comment_text(src)));
        }
        for line in &o.header {
            self.comment(&comment_text(line));
        }
        let unit = if o.dialect == Dialect::Sinumerik {
            "G71"
        } else {
            "G21"
        };
        self.comment(&format!("units: mm ({unit}), degrees, seconds"));
        for part in feed.split('\n') {
            self.comment(part);
        }
        let terms: Vec<String> = o
            .budget()
            .iter()
            .map(|(k, v)| match v {
                Some(v) => format!("{k} {v}"),
                None => format!("{k} unknown"),
            })
            .collect();
        let unknown = if o.linearization_tolerance.is_none() {
            " (the known terms; the axes file does not record the linearization tolerance)"
        } else {
            ""
        };
        self.comment(&format!(
            "tolerance budget mm: {} = {}{unknown}",
            terms.join(" + "),
            o.budget_total()
        ));
        self.comment(&format!(
            "blocks: {} lines, {} arcs, {} turns, {arcs_as}",
            counts.lines, counts.arcs, counts.turns
        ));
        let p = self.process.clone();
        let pm = format!(
            "process: beam on {}; beam off {};",
            comment_text(&p.beam_on.join(" / ")),
            comment_text(&p.beam_off.join(" / ")),
        );
        self.comment(&pm);
        let pm = format!(
            "process: pierce {} mm above the cut start along the tool axis, dwell {} s, descent at {} mm/min",
            p.pierce_standoff, p.pierce_dwell_s, o.feed
        );
        self.comment(&pm);
        match o.dialect {
            Dialect::Linuxcnc => {
                self.line("G17 G21 G40 G49 G54 G80 G90 G94");
                self.line("G93");
                self.line("G61");
            }
            Dialect::Generic => self.line("G17 G21 G40 G90 G94"),
            Dialect::Sinumerik => {
                self.line("G17 G71 G90 G94 G40");
                self.line("G54");
                self.line("SOFT");
                let ctol = o.blend_tolerance / 2.0;
                match o.pivot_length.filter(|l| l.is_finite() && *l > 0.0) {
                    Some(l) => {
                        let otol = (ctol / l).to_degrees();
                        self.line(&format!("CTOL={ctol} OTOL={otol:.6}"));
                    }
                    None => self.line(&format!("CTOL={}", o.blend_tolerance)),
                }
                self.line("TRAORI");
                self.line("ORIWKS");
                self.line("ORIVECT");
                self.line("G60");
            }
        }
        // The beam is off before the first move, whatever state the controller was left in.
        for l in self.process.beam_off.clone() {
            self.line(&l);
        }
    }

    /// A rapid to the axes `q` (tip `p`, tool axis `u`).
    fn rapid(&mut self, p: nalgebra::Point3<f64>, q: [f64; 5], u: nalgebra::Vector3<f64>) {
        let l = match self.opts.dialect {
            Dialect::Sinumerik => format!("G0 {}", self.tip_words(&p, &u)),
            _ => format!("G0 {}", self.axis_words(&q)),
        };
        self.line(&l);
        self.last = Some(self.printed(&q));
    }

    /// Rapid to the pierce point of the cut starting with `b`, beam on, dwell, descent.
    fn start_cut(&mut self, b: &Block) {
        let (tilt, c) = (b.start_axes[3], b.start_axes[4]);
        let start = b.start_tip();
        let u = self.model.tool_axis(tilt, c);
        let h = self.process.pierce_standoff;
        let pierce = start + u * h;
        let lin = self.model.linear_axes(&pierce, tilt, c);
        let qp = if h > 0.0 {
            [lin[0], lin[1], lin[2], tilt, c]
        } else {
            b.start_axes
        };
        self.rapid(pierce, qp, u);
        for l in self.process.beam_on.clone() {
            self.line(&l);
        }
        let dwell = self.process.pierce_dwell_s;
        if dwell > 0.0 {
            let l = match self.opts.dialect {
                Dialect::Sinumerik => format!("G4 F{dwell}"),
                _ => format!("G4 P{dwell}"),
            };
            self.line(&l);
        }
        match self.opts.dialect {
            Dialect::Linuxcnc => {
                let l = format!("G64 P{} Q0", self.opts.blend_tolerance);
                self.line(&l);
            }
            Dialect::Sinumerik => self.line("G642"),
            Dialect::Generic => {}
        }
        self.in_cut = true;
        if h > 0.0 {
            let t = self.process.descent_s(self.opts.feed);
            match self.opts.dialect {
                Dialect::Sinumerik => {
                    let f = format!("{:.1}", self.opts.feed);
                    let l = format!("G1 {} F{f}", self.tip_words(&start, &u));
                    self.line(&l);
                    self.last_f = Some(f);
                }
                _ => self.raw_move(b.start_axes, t),
            }
        }
    }

    fn end_cut(&mut self) {
        for l in self.process.beam_off.clone() {
            self.line(&l);
        }
        match self.opts.dialect {
            Dialect::Linuxcnc => self.line("G61"),
            Dialect::Sinumerik => self.line("G60"),
            Dialect::Generic => {}
        }
        self.in_cut = false;
    }

    /// One `G1` of a raw-axis dialect to `q`, taking `t` seconds; nothing if the printed axes
    /// do not change.
    fn raw_move(&mut self, q: [f64; 5], t: f64) {
        let qp = self.printed(&q);
        let prev = self.last.unwrap_or(qp);
        if prev == qp {
            return;
        }
        let f = match self.opts.dialect {
            Dialect::Linuxcnc => 60.0 / t,
            _ => {
                let lin = ((qp[0] - prev[0]).powi(2)
                    + (qp[1] - prev[1]).powi(2)
                    + (qp[2] - prev[2]).powi(2))
                .sqrt();
                let rot = ((qp[3] - prev[3]).powi(2) + (qp[4] - prev[4]).powi(2)).sqrt();
                let len = if lin > 0.0 { lin } else { rot };
                len / t * 60.0
            }
        };
        let l = format!("G1 {} F{}", self.axis_words(&q), feed_number(f));
        self.line(&l);
        self.last = Some(qp);
    }

    /// The cutting block `b`, taking `t` seconds.
    fn cut(&mut self, b: &Block, t: f64) {
        match self.opts.dialect {
            Dialect::Generic | Dialect::Linuxcnc => {
                // Arcs become chords within the chord tolerance (eq 18), the block's time
                // shared in proportion to the path parameter.
                let mut ends = Vec::new();
                if let Geometry::Arc(a) = &b.geometry {
                    let k = (b.length() / max_step(a.radius, self.opts.chord_tolerance))
                        .ceil()
                        .max(1.0) as usize;
                    for i in 1..k {
                        let s = b.length() * i as f64 / k as f64;
                        ends.push((s, b.axes_at(self.model, s)));
                    }
                }
                ends.push((b.length(), b.end_axes));
                let mut s0 = 0.0;
                for (s, q) in ends {
                    let share = if b.length() > 0.0 {
                        (s - s0) / b.length()
                    } else {
                        1.0
                    };
                    self.raw_move(q, t * share);
                    s0 = s;
                }
            }
            Dialect::Sinumerik => {
                let p = b.end_tip();
                let u = b.end_tool_axis;
                let mut l = match &b.geometry {
                    Geometry::Arc(a) => format!(
                        "CIP X{} Y{} Z{} I1={} J1={} K1={} A3={} B3={} C3={}",
                        self.num(p.x),
                        self.num(p.y),
                        self.num(p.z),
                        self.num(a.mid.x),
                        self.num(a.mid.y),
                        self.num(a.mid.z),
                        self.num(u.x),
                        self.num(u.y),
                        self.num(u.z)
                    ),
                    _ => format!("G1 {}", self.tip_words(&p, &u)),
                };
                if !matches!(b.geometry, Geometry::Turn { .. }) {
                    let f = format!("{:.1}", b.length() / t * 60.0);
                    if self.last_f.as_deref() != Some(f.as_str()) {
                        l.push_str(" F");
                        l.push_str(&f);
                        self.last_f = Some(f);
                    }
                }
                self.line(&l);
            }
        }
    }
}

/// A feed value with six significant digits in plain decimal notation (controllers read no
/// exponents), never written as 0.
fn feed_number(f: f64) -> String {
    let f = if f.is_finite() { f.max(1e-9) } else { 1e9 };
    let mag = f.log10().floor() as i32;
    let decimals = (5 - mag).clamp(0, 12) as usize;
    format!("{f:.decimals$}")
}

/// Writes [`gcode`] to `path` atomically.
///
/// # Errors
/// As [`gcode`], plus [`InterpError::Io`].
pub fn write_gcode<M: AxisModel + ?Sized>(
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
