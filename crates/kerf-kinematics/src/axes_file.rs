//! `kerf.axes/1`: the machine axis positions of every path, written atomically.
//!
//! ```json
//! {
//!   "format": "kerf.axes/1",
//!   "machine": "paper-000 laser head",
//!   "axes": ["X", "Y", "Z", "A", "C"],
//!   "paths": [
//!     { "id": "door-trim-1", "positions": [[0, 0, 0, 0, 0], ...], "poses": [[0, 0, 0, 0, 0, 1], ...],
//!       "inserted": 12, "max_rotary_step": 0.8, "max_linearization_error": 0.0049,
//!       "pole_tip_error": 0 }
//!   ]
//! }
//! ```
//!
//! `positions[n]` drives the machine to `poses[n]`; `poses` holds the cutting points plus the
//! inserted points, `inserted` counts the latter (kerf inserts against the non-linearity error
//! and, when `max_rotary_step` is set, against long rotary moves; both are counted). The last
//! three keys of a path are optional extensions (the report of [`crate::SolvedPath`]); readers
//! of the format may ignore them.
//!
//! Numbers are written with Rust's shortest round-trip formatting, so reading the file back
//! gives the same doubles. The file is written by [`kerf_io::write_file`]: to a temporary file
//! in the destination's directory, renamed over the destination once complete (a failure never
//! leaves a half-written file); a device or FIFO is written through.

use std::io::{self, BufWriter, Write};
use std::path::Path;

use serde::Deserialize;

use crate::error::{KinematicsError, Result};
use crate::machine::Machine;
use crate::path::SolvedPath;

/// The `format` value of an axes file.
pub const AXES_FORMAT: &str = "kerf.axes/1";

/// A `kerf.axes/1` document.
#[derive(Debug, Clone, PartialEq)]
pub struct AxesFile {
    /// The machine's name.
    pub machine: String,
    /// The axis names, `["X", "Y", "Z", "A" or "B", "C"]`.
    pub axes: [String; 5],
    /// One entry per path, in toolpath order.
    pub paths: Vec<AxesPath>,
}

/// The axes of one path.
/// Unknown keys are ignored: the format allows optional extensions.
#[derive(Debug, Clone, PartialEq, Deserialize)]
pub struct AxesPath {
    /// The path's id.
    pub id: String,
    /// `[X, Y, Z, tilt, C]` per point (mm, degrees).
    pub positions: Vec<[f64; 5]>,
    /// `[x, y, z, i, j, k]` per point.
    pub poses: Vec<[f64; 6]>,
    /// How many of the points were inserted.
    pub inserted: usize,
    /// Optional: the largest rotary step between two points (degrees).
    #[serde(default)]
    pub max_rotary_step: Option<f64>,
    /// Optional: the largest non-linearity error of a move (mm, estimated).
    #[serde(default)]
    pub max_linearization_error: Option<f64>,
    /// Optional: the largest tip error of the pole rule (mm).
    #[serde(default)]
    pub pole_tip_error: Option<f64>,
    /// Optional: the largest angle (degrees) between a pose's tool axis and the surface normal
    /// at its point, when a tilt tolerance was in force.
    #[serde(default)]
    pub tilt_max_deg: Option<f64>,
    /// Optional: the index into the curve's toolpath `points` where the cut begins (a closed
    /// path runs round to it again).
    #[serde(default)]
    pub start_point: Option<usize>,
    /// Optional: the move from the pierce point onto the curve (not on the curve; no
    /// chord-error claim).
    #[serde(default)]
    pub lead_in: Option<AxesMove>,
    /// Optional: the move off the curve after the cut (overcut and exit).
    #[serde(default)]
    pub lead_out: Option<AxesMove>,
    /// Optional: the rapid waypoints of the traverse before this path (from the retract
    /// above the previous path's end to the point above this path's pierce), checked to clear
    /// the part (`kerf-process`); the head runs each as a rapid, all axes linear.
    #[serde(default)]
    pub traverse: Option<AxesMove>,
}

/// A lead-in or lead-out of a path in `kerf.axes/1`: axis vectors and the poses they give.
#[derive(Debug, Clone, PartialEq, Deserialize)]
pub struct AxesMove {
    /// `[X, Y, Z, tilt, C]` per point.
    pub positions: Vec<[f64; 5]>,
    /// `[x, y, z, i, j, k]` per point.
    pub poses: Vec<[f64; 6]>,
}

impl AxesPath {
    /// The axis vectors and poses as the machine runs them: lead-in, cut, lead-out.
    pub fn run(&self) -> (Vec<[f64; 5]>, Vec<[f64; 6]>) {
        let mut q = Vec::new();
        let mut p = Vec::new();
        if let Some(m) = &self.lead_in {
            q.extend_from_slice(&m.positions);
            p.extend_from_slice(&m.poses);
        }
        q.extend_from_slice(&self.positions);
        p.extend_from_slice(&self.poses);
        if let Some(m) = &self.lead_out {
            q.extend_from_slice(&m.positions);
            p.extend_from_slice(&m.poses);
        }
        (q, p)
    }
}

#[derive(Deserialize)]
struct Document {
    format: String,
    machine: String,
    axes: [String; 5],
    paths: Vec<AxesPath>,
}

impl AxesFile {
    /// The document for solved paths on `machine`.
    pub fn new(machine: &Machine, paths: &[SolvedPath]) -> Self {
        Self {
            machine: machine.name.clone(),
            axes: machine.axis_names().map(str::to_owned),
            paths: paths
                .iter()
                .map(|p| AxesPath {
                    id: p.id.clone(),
                    positions: p.positions(),
                    poses: p.poses.iter().map(|q| q.to_array()).collect(),
                    inserted: p.inserted,
                    max_rotary_step: Some(p.max_rotary_step),
                    max_linearization_error: Some(p.max_linearization_error),
                    pole_tip_error: Some(p.pole_tip_error),
                    tilt_max_deg: p.tilt.map(|t| t.max_deviation_deg),
                    start_point: None,
                    lead_in: None,
                    lead_out: None,
                    traverse: None,
                })
                .collect(),
        }
    }

    /// Checks the document: one position per pose, finite numbers, `inserted` at most the
    /// number of points, the axis names `X, Y, Z, A|B, C`.
    ///
    /// # Errors
    /// [`KinematicsError::Document`] naming the JSON path of the defect.
    pub fn validate(&self) -> Result<()> {
        let tilt_ok = self.axes[3] == "A" || self.axes[3] == "B";
        if self.axes[0] != "X"
            || self.axes[1] != "Y"
            || self.axes[2] != "Z"
            || !tilt_ok
            || self.axes[4] != "C"
        {
            return Err(KinematicsError::doc(
                "axes",
                format!(
                    "expected [\"X\", \"Y\", \"Z\", \"A\" or \"B\", \"C\"], found {:?}",
                    self.axes
                ),
            ));
        }
        // The machine name and the path ids are written into program comments.
        crate::json::check_text("machine", &self.machine)?;
        for (n, p) in self.paths.iter().enumerate() {
            let at = |key: &str| format!("paths[{n}].{key}");
            crate::json::check_text(&at("id"), &p.id)?;
            for (key, m) in [
                ("lead_in", &p.lead_in),
                ("lead_out", &p.lead_out),
                ("traverse", &p.traverse),
            ] {
                if let Some(m) = m {
                    if m.positions.len() != m.poses.len() {
                        return Err(KinematicsError::doc(
                            at(key),
                            format!(
                                "{} positions for {} poses",
                                m.positions.len(),
                                m.poses.len()
                            ),
                        ));
                    }
                    if m.positions
                        .iter()
                        .flatten()
                        .chain(m.poses.iter().flatten())
                        .any(|v| !v.is_finite())
                    {
                        return Err(KinematicsError::doc(at(key), "holds a non-finite number"));
                    }
                }
            }
            if p.positions.len() != p.poses.len() {
                return Err(KinematicsError::doc(
                    at("positions"),
                    format!(
                        "{} positions for {} poses",
                        p.positions.len(),
                        p.poses.len()
                    ),
                ));
            }
            if p.inserted > p.poses.len() {
                return Err(KinematicsError::doc(
                    at("inserted"),
                    format!("{} inserted of {} points", p.inserted, p.poses.len()),
                ));
            }
            for (key, rows) in [
                (
                    "positions",
                    p.positions.iter().map(|r| r.as_slice()).collect::<Vec<_>>(),
                ),
                ("poses", p.poses.iter().map(|r| r.as_slice()).collect()),
            ] {
                for (i, row) in rows.iter().enumerate() {
                    if let Some(k) = row.iter().position(|v| !v.is_finite()) {
                        return Err(KinematicsError::doc(
                            format!("paths[{n}].{key}[{i}][{k}]"),
                            format!("must be finite (got {})", row[k]),
                        ));
                    }
                }
            }
            for (key, v) in [
                ("max_rotary_step", p.max_rotary_step),
                ("max_linearization_error", p.max_linearization_error),
                ("pole_tip_error", p.pole_tip_error),
                ("tilt_max_deg", p.tilt_max_deg),
            ] {
                if let Some(v) = v.filter(|v| !v.is_finite()) {
                    return Err(KinematicsError::doc(
                        at(key),
                        format!("must be finite (got {v})"),
                    ));
                }
            }
        }
        Ok(())
    }

    /// Checks the document and writes it as JSON to `writer`.
    ///
    /// # Errors
    /// Any error of [`AxesFile::validate`], or [`KinematicsError::Io`].
    pub fn to_writer(&self, writer: impl Write) -> Result<()> {
        self.validate()?;
        let mut w = BufWriter::new(writer);
        self.write_json(&mut w)
            .and_then(|()| w.flush())
            .map_err(|e| io_error("<writer>", e))
    }

    /// Checks the document and returns it as JSON text.
    ///
    /// # Errors
    /// Any error of [`AxesFile::validate`].
    pub fn to_json(&self) -> Result<String> {
        let mut bytes = Vec::new();
        self.to_writer(&mut bytes)?;
        Ok(String::from_utf8_lossy(&bytes).into_owned())
    }

    /// Checks the document and writes it to `dest` atomically (a temporary file in the same
    /// directory, renamed over `dest` once complete); `-` writes to standard output.
    ///
    /// # Errors
    /// Any error of [`AxesFile::validate`], or [`KinematicsError::Io`] (nothing was written to
    /// `dest`).
    pub fn write(&self, dest: impl AsRef<Path>) -> Result<()> {
        let dest = dest.as_ref();
        self.validate()?;
        kerf_io::write_file(dest, |mut w| self.write_json(&mut w))
            .map_err(|e| io_error(&dest.display().to_string(), e))
    }

    /// Reads a `kerf.axes/1` file (at most [`kerf_io::MAX_INPUT_BYTES`]).
    ///
    /// # Errors
    /// [`KinematicsError::Io`] if the file cannot be read, else the errors of
    /// [`AxesFile::from_slice`] wrapped in [`KinematicsError::File`] naming the file.
    pub fn read(path: impl AsRef<Path>) -> Result<Self> {
        crate::json::read_with(path.as_ref(), Self::from_slice)
    }

    /// Reads `kerf.axes/1` JSON text.
    ///
    /// # Errors
    /// [`KinematicsError::Syntax`], or [`KinematicsError::Document`] for a wrong format, a
    /// wrong shape or a failed [`AxesFile::validate`].
    #[allow(clippy::should_implement_trait)] // as Machine::from_str
    pub fn from_str(text: &str) -> Result<Self> {
        Self::from_slice(text.as_bytes())
    }

    /// Reads `kerf.axes/1` JSON bytes (a UTF-8 byte-order mark is skipped, a key given twice
    /// in one object is refused).
    ///
    /// # Errors
    /// As [`AxesFile::from_str`].
    pub fn from_slice(bytes: &[u8]) -> Result<Self> {
        let value = crate::json::parse(bytes)?;
        match value.get("format") {
            Some(serde_json::Value::String(s)) if s == AXES_FORMAT => {}
            other => {
                return Err(KinematicsError::doc(
                    "format",
                    format!(
                        "unknown format {} (this reader reads \"{AXES_FORMAT}\")",
                        other.map_or("(missing)".to_owned(), |v| v.to_string())
                    ),
                ))
            }
        }
        let doc: Document = serde_json::from_value(value)
            .map_err(|e| KinematicsError::doc("top level", e.to_string()))?;
        debug_assert_eq!(doc.format, AXES_FORMAT, "checked above");
        let file = AxesFile {
            machine: doc.machine,
            axes: doc.axes,
            paths: doc.paths,
        };
        file.validate()?;
        Ok(file)
    }

    /// The JSON text, one point per line.
    fn write_json(&self, w: &mut impl Write) -> io::Result<()> {
        writeln!(w, "{{")?;
        writeln!(w, "  \"format\": \"{AXES_FORMAT}\",")?;
        writeln!(w, "  \"machine\": {},", json_string(&self.machine))?;
        let axes: Vec<String> = self.axes.iter().map(|a| json_string(a)).collect();
        writeln!(w, "  \"axes\": [{}],", axes.join(", "))?;
        write!(w, "  \"paths\": [")?;
        for (n, p) in self.paths.iter().enumerate() {
            if n > 0 {
                write!(w, ",")?;
            }
            writeln!(w)?;
            writeln!(w, "    {{")?;
            writeln!(w, "      \"id\": {},", json_string(&p.id))?;
            write_rows(w, "positions", p.positions.iter().map(|r| r.as_slice()))?;
            write_rows(w, "poses", p.poses.iter().map(|r| r.as_slice()))?;
            write!(w, "      \"inserted\": {}", p.inserted)?;
            for (key, v) in [
                ("max_rotary_step", p.max_rotary_step),
                ("max_linearization_error", p.max_linearization_error),
                ("pole_tip_error", p.pole_tip_error),
                ("tilt_max_deg", p.tilt_max_deg),
            ] {
                if let Some(v) = v {
                    write!(w, ",\n      \"{key}\": {v}")?;
                }
            }
            if let Some(sp) = p.start_point {
                write!(w, ",\n      \"start_point\": {sp}")?;
            }
            for (key, m) in [
                ("lead_in", &p.lead_in),
                ("lead_out", &p.lead_out),
                ("traverse", &p.traverse),
            ] {
                if let Some(m) = m {
                    writeln!(w, ",\n      \"{key}\": {{")?;
                    write_rows(w, "positions", m.positions.iter().map(|r| r.as_slice()))?;
                    // `poses` is the last key: drop write_rows' trailing comma.
                    let mut rows = Vec::new();
                    write_rows(&mut rows, "poses", m.poses.iter().map(|r| r.as_slice()))?;
                    let text = String::from_utf8_lossy(&rows);
                    let text = text.trim_end().trim_end_matches(',');
                    write!(w, "{text}\n      }}")?;
                }
            }
            write!(w, "\n    }}")?;
        }
        if !self.paths.is_empty() {
            writeln!(w)?;
            write!(w, "  ")?;
        }
        writeln!(w, "]")?;
        writeln!(w, "}}")
    }
}

/// `"key": [[...], ...],` one row per line.
fn write_rows<'a>(
    w: &mut impl Write,
    key: &str,
    rows: impl Iterator<Item = &'a [f64]>,
) -> io::Result<()> {
    write!(w, "      \"{key}\": [")?;
    for (i, row) in rows.enumerate() {
        if i > 0 {
            write!(w, ",")?;
        }
        write!(w, "\n        [")?;
        for (k, v) in row.iter().enumerate() {
            if k > 0 {
                write!(w, ", ")?;
            }
            // Display of f64 is the shortest text that reads back to the same double, and is
            // valid JSON for finite values (checked by validate).
            write!(w, "{v}")?;
        }
        write!(w, "]")?;
    }
    writeln!(w, "\n      ],")
}

fn json_string(s: &str) -> String {
    serde_json::to_string(s).unwrap_or_else(|_| "\"\"".to_owned())
}

fn io_error(file: &str, e: io::Error) -> KinematicsError {
    KinematicsError::Io {
        file: file.to_owned(),
        action: "write",
        source: e.into(),
    }
}
