//! Outputs: the set-points CSV of `formats.md` and G-code in two dialects, written atomically.
//!
//! - **CSV**: header `t,X,Y,Z,<tilt>,C`, one row per cycle, `t` in seconds, axes in mm and
//!   degrees; values are written in Rust's shortest round-trip form, so they read back exactly.
//! - **Generic G-code**: `G1 X Y Z A C F` with machine axis values, for a controller without
//!   tool-tip control. It interpolates the axes linearly between blocks, so arcs are written as
//!   chords within the chord tolerance (eq 18) and the tip deviates from the intended path by the
//!   non-linearity error between blocks (the kinematics' linearization tolerance is what bounds
//!   that; see `docs/interpolation.md`).
//! - **Sinumerik-style**: `TRAORI` with the tool tip and the orientation vector (`A3= B3= C3=`)
//!   in workpiece coordinates, arcs as `CIP X Y Z I1= J1= K1=` through the intermediate point.
//!
//! Both programs start with a header (units, tolerances, machine) and name the source curve in
//! a comment where each path starts.

use std::borrow::Borrow;
use std::fmt::Write as _;
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
    /// `G1 X Y Z A C F`: machine axes, linear axis interpolation.
    Generic,
    /// Sinumerik-style `TRAORI`: tool tip, orientation vector, `CIP` arcs.
    Sinumerik,
}

/// What goes into a program besides the blocks.
#[derive(Debug, Clone, PartialEq)]
pub struct GcodeOptions {
    /// Dialect.
    pub dialect: Dialect,
    /// Programmed feed, mm/min (the `F` word of cutting blocks unless `block_feeds` is given).
    pub feed: f64,
    /// The fit tolerance the blocks were made with, mm (header only).
    pub fit_tolerance: f64,
    /// Chord tolerance, mm: generic programs write arcs as chords within it.
    pub chord_tolerance: f64,
    /// Decimals of coordinates (default 6).
    pub decimals: usize,
}

impl GcodeOptions {
    /// Options for `dialect` at `feed` mm/min, with 0.001 mm tolerances and 6 decimals.
    pub fn new(dialect: Dialect, feed: f64) -> Self {
        Self {
            dialect,
            feed,
            fit_tolerance: 0.001,
            chord_tolerance: 0.001,
            decimals: 6,
        }
    }
}

/// The G-code program of `blocks`.
///
/// `path_ids[b.path]` names the source curve of block `b` (missing ids are written as
/// `path <n>`); `block_feeds`, if given, is the `F` word (mm/min) of each block, e.g. the
/// planned speeds of [`crate::Motion::block_feed`]; otherwise every cutting block gets
/// `opts.feed`. Rapid blocks are `G0`.
///
/// # Errors
/// [`InterpError::BadParameter`] for a feed or chord tolerance that is not finite and > 0.
pub fn gcode<M: AxisModel + ?Sized>(
    model: &M,
    blocks: &[Block],
    path_ids: &[String],
    block_feeds: Option<&[f64]>,
    opts: &GcodeOptions,
) -> Result<String> {
    positive("feed", opts.feed)?;
    positive("chord_tolerance", opts.chord_tolerance)?;
    let d = opts.decimals.min(12);
    let names = model.axis_names();
    let counts = crate::fit::BlockCounts::of(blocks);
    let mut s = String::new();
    let (title, arcs_as) = match opts.dialect {
        Dialect::Generic => (
            format!(
                "kerf generic 5-axis program: machine axes {} {} {} {} {}, no tool-tip control",
                names[0], names[1], names[2], names[3], names[4]
            ),
            "arcs written as G1 chords",
        ),
        Dialect::Sinumerik => (
            "kerf Sinumerik-style program: TRAORI, tool tip X Y Z and orientation vector A3 B3 C3 in workpiece coordinates".to_string(),
            "arcs as CIP through the intermediate point",
        ),
    };
    let _ = writeln!(s, "; {title}");
    let _ = writeln!(s, "; machine: {}", model.name());
    let _ = writeln!(s, "; units: mm, degrees; F in mm/min of the tool tip");
    let _ = writeln!(
        s,
        "; tolerance: arc fit {} mm, chord {} mm",
        opts.fit_tolerance, opts.chord_tolerance
    );
    let _ = writeln!(
        s,
        "; blocks: {} lines, {} arcs, {} turns ({arcs_as})",
        counts.lines, counts.arcs, counts.turns
    );
    match opts.dialect {
        Dialect::Generic => s.push_str("G90 G94 G21\n"),
        Dialect::Sinumerik => s.push_str("G90 G94 G71 G64\nTRAORI\nORIWKS\nORIVECT\n"),
    }
    let mut last_path = usize::MAX;
    let mut last_f = f64::NAN;
    let num = |v: f64| {
        let t = format!("{:.*}", d, v);
        // No "-0.000000".
        match t.strip_prefix('-') {
            Some(rest) if rest.bytes().all(|c| c == b'0' || c == b'.') => rest.to_string(),
            _ => t,
        }
    };
    for (bi, b) in blocks.iter().enumerate() {
        // The comment comes before the rapid moves that lead to the curve (they carry the
        // next path's number).
        if b.path != last_path {
            last_path = b.path;
            let id = path_ids
                .get(b.path)
                .cloned()
                .unwrap_or_else(|| format!("path {}", b.path));
            let span = b
                .params
                .map_or(String::new(), |p| format!(", t = {}", p[0]));
            let _ = writeln!(
                s,
                "; curve {id} (from cutting point {}{span})",
                b.stations[0]
            );
        }
        if bi == 0 {
            // Position at the start.
            match opts.dialect {
                Dialect::Generic => {
                    let q = b.start_axes;
                    let _ = writeln!(s, "G0 {}", axis_words(&names, &q, &num));
                }
                Dialect::Sinumerik => {
                    let p = b.start_tip();
                    let u = model.tool_axis(b.start_axes[3], b.start_axes[4]);
                    let _ = writeln!(
                        s,
                        "G0 X{} Y{} Z{} A3={} B3={} C3={}",
                        num(p.x),
                        num(p.y),
                        num(p.z),
                        num(u.x),
                        num(u.y),
                        num(u.z)
                    );
                }
            }
        }
        let feed = block_feeds
            .and_then(|f| f.get(bi).copied())
            .unwrap_or(opts.feed);
        let fword = |s: &mut String, last_f: &mut f64| {
            if !b.rapid && (last_f.is_nan() || (feed - *last_f).abs() > 1e-9) {
                let _ = write!(s, " F{:.1}", feed);
                *last_f = feed;
            }
        };
        let g = if b.rapid { "G0" } else { "G1" };
        match opts.dialect {
            Dialect::Generic => {
                let mut ends = Vec::new();
                if let Geometry::Arc(a) = &b.geometry {
                    let k = (b.length() / max_step(a.radius, opts.chord_tolerance))
                        .ceil()
                        .max(1.0) as usize;
                    for i in 1..k {
                        ends.push(b.axes_at(model, b.length() * i as f64 / k as f64));
                    }
                }
                ends.push(b.end_axes);
                for q in ends {
                    s.push_str(g);
                    s.push(' ');
                    s.push_str(&axis_words(&names, &q, &num));
                    fword(&mut s, &mut last_f);
                    s.push('\n');
                }
            }
            Dialect::Sinumerik => {
                let p = b.end_tip();
                let u = b.end_tool_axis;
                match &b.geometry {
                    Geometry::Arc(a) if !b.rapid => {
                        let _ = write!(
                            s,
                            "CIP X{} Y{} Z{} I1={} J1={} K1={} A3={} B3={} C3={}",
                            num(p.x),
                            num(p.y),
                            num(p.z),
                            num(a.mid.x),
                            num(a.mid.y),
                            num(a.mid.z),
                            num(u.x),
                            num(u.y),
                            num(u.z)
                        );
                    }
                    _ => {
                        let _ = write!(
                            s,
                            "{g} X{} Y{} Z{} A3={} B3={} C3={}",
                            num(p.x),
                            num(p.y),
                            num(p.z),
                            num(u.x),
                            num(u.y),
                            num(u.z)
                        );
                    }
                }
                fword(&mut s, &mut last_f);
                s.push('\n');
            }
        }
    }
    if opts.dialect == Dialect::Sinumerik {
        s.push_str("TRAFOOF\n");
    }
    s.push_str("M30\n");
    Ok(s)
}

fn axis_words(names: &[&str; 5], q: &[f64; 5], num: &impl Fn(f64) -> String) -> String {
    format!(
        "{}{} {}{} {}{} {}{} {}{}",
        names[0],
        num(q[0]),
        names[1],
        num(q[1]),
        names[2],
        num(q[2]),
        names[3],
        num(q[3]),
        names[4],
        num(q[4])
    )
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
