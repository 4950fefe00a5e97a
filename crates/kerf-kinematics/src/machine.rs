//! `kerf.machine/1`: a machine's kinematics, axis limits, velocities and accelerations.
//!
//! ```
//! use kerf_kinematics::{Axis, Machine};
//!
//! let machine = Machine::from_str(r#"{
//!   "format": "kerf.machine/1",
//!   "name": "paper-000 laser head",
//!   "kinematics": { "type": "ac-head", "r_a": 180.0, "r_c": 95.0 },
//!   "limits": { "X": [-1500, 1500], "Y": [-800, 800], "Z": [-100, 600], "A": [-135, 135], "C": null },
//!   "max_velocity": { "X": 60000, "Y": 60000, "Z": 30000, "A": 36000, "C": 36000 },
//!   "max_acceleration": { "X": 10000, "Y": 10000, "Z": 8000, "A": 20000, "C": 20000 }
//! }"#)?;
//! assert_eq!(machine.axis_names(), ["X", "Y", "Z", "A", "C"]);
//! assert!(machine.limit(Axis::C).is_none(), "C is continuous");
//!
//! let err = Machine::from_str(r#"{"format": "kerf.machine/1", "name": "m",
//!   "kinematics": { "type": "xyz" }}"#).unwrap_err();
//! assert_eq!(err.to_string(),
//!     "kinematics.type: unknown type \"xyz\" (known: ac-head, fork-head, table-table, head-table)");
//! # Ok::<(), kerf_kinematics::KinematicsError>(())
//! ```
//!
//! Reading is strict inside `kinematics`, `limits`, `max_velocity` and `max_acceleration`: a
//! key that is not a parameter of the type or an axis of the machine is an error (a misspelt
//! key must not silently become a default). Unknown top-level keys are ignored, so that a file
//! may carry comments or later optional keys. Every axis must be listed in `limits`,
//! `max_velocity` and `max_acceleration` (`null` in `limits` for an unlimited axis). The optional
//! `max_jerk` (mm/s^3, deg/s^3), when present, is read as strictly and must list every axis.

use std::path::Path;
use std::sync::Arc;

use serde_json::{Map, Value};

use crate::error::{KinematicsError, Result};
use crate::head::Head;
use crate::kinematics::Kinematics;
use crate::pose::{Axes, Axis};
use crate::registry;
use kerf_io::json_type_name;

/// The `format` value of a machine file.
pub const MACHINE_FORMAT: &str = "kerf.machine/1";

/// The closed range `[min, max]` of a limited axis.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Range {
    /// The lowest allowed value (mm or degrees).
    pub min: f64,
    /// The highest allowed value.
    pub max: f64,
}

impl Range {
    /// `[min, max]`.
    pub fn new(min: f64, max: f64) -> Self {
        Self { min, max }
    }

    /// True if `value` lies in `[min - slack, max + slack]`.
    pub fn contains(&self, value: f64, slack: f64) -> bool {
        value >= self.min - slack && value <= self.max + slack
    }
}

/// A five-axis machine: `kerf.machine/1`.
#[derive(Debug, Clone)]
pub struct Machine {
    /// The machine's name (copied into `kerf.axes/1`).
    pub name: String,
    /// The kinematic type with its parameters.
    pub kinematics: Arc<dyn Kinematics>,
    /// The limits of `[X, Y, Z, tilt, C]`; `None` for an unlimited (continuous) axis.
    pub limits: [Option<Range>; 5],
    /// The largest velocity of each axis, mm/min or deg/min.
    pub max_velocity: [f64; 5],
    /// The largest acceleration of each axis, mm/s^2 or deg/s^2.
    pub max_acceleration: [f64; 5],
    /// The largest jerk of each axis, mm/s^3 or deg/s^3 (optional key `max_jerk`): with it the
    /// interpolator plans a jerk-limited (S-curve) motion, without it acceleration-limited.
    pub max_jerk: Option<[f64; 5]>,
    /// The laser process codes of the optional `process` object; every field `None` when the
    /// file has none (the G-code writer then uses its dialect's defaults).
    pub process: Process,
    /// The cutting head of the optional `head` object (`None` without one: checks then use
    /// [`Head::laser_default`]).
    pub head: Option<Head>,
    /// The file's unknown top-level keys that look like misspellings of the format's
    /// (`max_jerks: unknown key, did you mean "max_jerk"?`): the machine was read without
    /// them, so a misspelt optional limit is absent. Empty for a machine built in code.
    pub warnings: Vec<kerf_io::UnknownKey>,
}

/// The optional `process` object of `kerf.machine/1`: how the program switches the beam and
/// pierces. A `None` field was absent from the file and takes the dialect's documented default
/// (`kerf_interp::output`).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Process {
    /// Program lines that switch the beam on, written as given (e.g. `["M64 P0"]`); never
    /// empty, at most [`MAX_PROCESS_LINES`] lines of at most [`MAX_PROCESS_LINE_CHARS`]
    /// characters, each line non-empty, printable, without `;` or parentheses (they would start a
    /// comment in some dialects), and only process words ([`process_line_defect`]): no motion,
    /// feed, tool or program-flow word can enter a program through them.
    pub beam_on: Option<Vec<String>>,
    /// Program lines that switch the beam off, with the same rules.
    pub beam_off: Option<Vec<String>>,
    /// Seconds the head stands at the pierce point with the beam on before it moves, in
    /// `[0, MAX_PIERCE_DWELL_S]`.
    pub pierce_dwell_s: Option<f64>,
    /// mm along the tool axis above the start of a cut where the pierce happens, in
    /// `[0, MAX_PIERCE_STANDOFF_MM]`; the head then descends along the tool axis to the cutting
    /// height with the beam on.
    pub pierce_standoff: Option<f64>,
    /// The beam's kerf width, mm, in `(0, MAX_KERF_WIDTH_MM]`: with it `kerf run` offsets each
    /// path by half of it toward the scrap side (a run's own width wins).
    pub kerf_width_mm: Option<f64>,
    /// The nozzle tip's height above the surface while cutting, mm, in
    /// `[0, MAX_PIERCE_STANDOFF_MM]` (default [`DEFAULT_STANDOFF_MM`]): where the head model
    /// stands on each cutting pose when cuts are checked against the part.
    pub standoff_mm: Option<f64>,
    /// A `kerf.technology/1` table for this machine, as a path relative to the machine
    /// file's directory (one printable line of at most [`MAX_PROCESS_LINE_CHARS`]
    /// characters): the table `kerf run --material NAME` picks from when no `--technology` is
    /// given.
    pub technology: Option<String>,
}

/// The nozzle's standoff above the surface while cutting when a machine file gives none, mm
/// (fiber-laser cutting runs at 0.5-1.5 mm).
pub const DEFAULT_STANDOFF_MM: f64 = 1.0;

/// The widest kerf a machine file may give, mm: a plasma kerf is a few millimetres; beyond
/// this the number is a mistake, not a kerf.
pub const MAX_KERF_WIDTH_MM: f64 = 20.0;

/// The longest program line of a process code (`beam_on`, `beam_off`), characters: the
/// longest line LinuxCNC reads (255). A code is written as given into every cut of every
/// program, so its length is bounded like any other input: a 5 MB line was accepted before.
pub const MAX_PROCESS_LINE_CHARS: usize = 255;

/// The most program lines of one process code (`beam_on`, `beam_off`): switching a beam takes
/// a few output words; the list is written at every cut.
pub const MAX_PROCESS_LINES: usize = 64;

/// The longest pierce dwell a machine file may ask for, s: thick plate pierces in seconds; a
/// minute is beyond any process and keeps the program's timing meaningful.
pub const MAX_PIERCE_DWELL_S: f64 = 60.0;

/// The highest pierce standoff a machine file may ask for, mm: pierce heights are a few mm; a
/// standoff of metres would send the head far off the part with the beam on.
pub const MAX_PIERCE_STANDOFF_MM: f64 = 100.0;

/// Why `line` may not be a process line, if it may not: it must be words of a letter and a
/// number (`M64 P0`, `M3 S2000`) or Sinumerik system-variable assignments
/// (`$A_OUT[1]=1`), and no word may move the machine, set a feed, change a tool or its
/// offsets, or change the program's flow: `G` other than the dwell `G4` (motion and modes),
/// the axis and arc words `X Y Z A B C U V W I J K R`, `F` (except as a `G4` line's dwell time,
/// Sinumerik's `G4 F`), `T`, `D`, `H`, `L` (subprogram calls), `N`, `O` (o-words), `%` and `#`
/// (parameters), and the M-words that stop, end, call or return
/// (`M0 M1 M2 M6 M17 M30 M47 M60 M98 M99`). Allowed: other `M` words, `S`, and the parameters
/// `P Q E`.
pub fn process_line_defect(line: &str) -> Option<String> {
    const FLOW_M: [u32; 10] = [0, 1, 2, 6, 17, 30, 47, 60, 98, 99];
    let mut dwell = false;
    let mut feed = None;
    for token in line.split_whitespace() {
        if let Some(var) = token.strip_prefix('$') {
            if !system_variable_ok(var) {
                return Some(format!(
                    "{token:?} is not a system-variable assignment $NAME[INDEX]=NUMBER"
                ));
            }
            continue;
        }
        let b = token.as_bytes();
        let mut i = 0;
        while i < b.len() {
            let letter = b[i].to_ascii_uppercase();
            if !letter.is_ascii_alphabetic() {
                return Some(format!(
                    "{token:?}: expected words of a letter and a number"
                ));
            }
            i += 1;
            let start = i;
            while i < b.len()
                && (b[i].is_ascii_digit()
                    || b[i] == b'.'
                    || (i == start && matches!(b[i], b'-' | b'+')))
            {
                i += 1;
            }
            let number = &token[start..i];
            let Ok(value) = number.parse::<f64>() else {
                return Some(format!(
                    "{token:?}: the word {} needs a number",
                    letter as char
                ));
            };
            let refused = match letter {
                b'M' => value.fract() != 0.0 || (value >= 0.0 && FLOW_M.contains(&(value as u32))),
                b'G' if value == 4.0 => {
                    dwell = true;
                    false
                }
                b'F' => {
                    feed = Some(number.to_string());
                    false
                }
                b'S' | b'P' | b'Q' | b'E' => false,
                _ => true,
            };
            if refused {
                return Some(format!(
                    "{}{number} may not be a process word: it moves the machine, sets a feed or a tool, or changes the program's flow",
                    letter as char
                ));
            }
        }
    }
    match feed {
        Some(number) if !dwell => Some(format!(
            "F{number} may not be a process word: it moves the machine, sets a feed or a tool, or changes the program's flow"
        )),
        _ => None,
    }
}

/// `NAME[INDEX]=NUMBER` or `NAME=NUMBER` (after the `$`), `NAME` of letters, digits and `_`.
fn system_variable_ok(var: &str) -> bool {
    let Some((lhs, value)) = var.split_once('=') else {
        return false;
    };
    let (name, index) = match lhs.split_once('[') {
        Some((n, rest)) => match rest.strip_suffix(']') {
            Some(i) => (n, Some(i)),
            None => return false,
        },
        None => (lhs, None),
    };
    !name.is_empty()
        && name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_')
        && index.is_none_or(|i| !i.is_empty() && i.chars().all(|c| c.is_ascii_digit() || c == ','))
        && value.parse::<f64>().is_ok_and(f64::is_finite)
}

impl Process {
    /// The keys of the `process` object.
    pub const KEYS: [&'static str; 7] = [
        "beam_on",
        "beam_off",
        "pierce_dwell_s",
        "pierce_standoff",
        "kerf_width_mm",
        "standoff_mm",
        "technology",
    ];

    /// Checks every present value.
    ///
    /// # Errors
    /// [`KinematicsError::Document`] with the JSON path, as
    /// `process.pierce_dwell_s: must be finite and >= 0 (got -1)` or
    /// `process.beam_on[0]: must not be empty`.
    pub fn validate(&self) -> Result<()> {
        if let Some(t) = &self.technology {
            let chars = t.chars().count();
            if t.trim().is_empty()
                || chars > MAX_PROCESS_LINE_CHARS
                || kerf_io::check_text(t).is_err()
            {
                return Err(KinematicsError::doc(
                    "process.technology",
                    format!("must be one printable line of 1 to {MAX_PROCESS_LINE_CHARS} characters naming a file"),
                ));
            }
        }
        for (key, lines) in [("beam_on", &self.beam_on), ("beam_off", &self.beam_off)] {
            let Some(lines) = lines else { continue };
            if lines.is_empty() {
                return Err(KinematicsError::doc(
                    format!("process.{key}"),
                    "must list at least one program line",
                ));
            }
            if lines.len() > MAX_PROCESS_LINES {
                return Err(KinematicsError::doc(
                    format!("process.{key}"),
                    format!("{} lines, at most {MAX_PROCESS_LINES}", lines.len()),
                ));
            }
            for (i, line) in lines.iter().enumerate() {
                let path = format!("process.{key}[{i}]");
                // First, so that no later message quotes a huge line.
                let chars = line.chars().count();
                if chars > MAX_PROCESS_LINE_CHARS {
                    return Err(KinematicsError::doc(
                        path,
                        format!("{chars} characters, at most {MAX_PROCESS_LINE_CHARS}"),
                    ));
                }
                if line.trim().is_empty() {
                    return Err(KinematicsError::doc(path, "must not be empty"));
                }
                if let Some(c) = line
                    .chars()
                    .find(|c| c.is_control() || !c.is_ascii() || matches!(c, ';' | '(' | ')'))
                {
                    return Err(KinematicsError::doc(
                        path,
                        format!(
                            "must be one printable ASCII program line without comments (found {:?})",
                            c
                        ),
                    ));
                }
                if let Some(why) = process_line_defect(line) {
                    return Err(KinematicsError::doc(path, why));
                }
            }
        }
        if let Some(w) = self.kerf_width_mm {
            if !(w > 0.0 && w <= MAX_KERF_WIDTH_MM) {
                return Err(KinematicsError::doc(
                    "process.kerf_width_mm",
                    format!("must lie in (0, {MAX_KERF_WIDTH_MM}] (got {w})"),
                ));
            }
        }
        for (key, v, max) in [
            ("pierce_dwell_s", self.pierce_dwell_s, MAX_PIERCE_DWELL_S),
            (
                "pierce_standoff",
                self.pierce_standoff,
                MAX_PIERCE_STANDOFF_MM,
            ),
            ("standoff_mm", self.standoff_mm, MAX_PIERCE_STANDOFF_MM),
        ] {
            if let Some(v) = v {
                if !(v.is_finite() && (0.0..=max).contains(&v)) {
                    let got = if v.abs() < 1e9 {
                        format!("{v}")
                    } else {
                        format!("{v:e}")
                    };
                    return Err(KinematicsError::doc(
                        format!("process.{key}"),
                        format!("must lie in [0, {max}] (got {got})"),
                    ));
                }
            }
        }
        Ok(())
    }

    /// Reads the `process` object (`value` is its JSON value); unknown keys are refused.
    ///
    /// # Errors
    /// [`KinematicsError::Document`] with the JSON path of the first defect.
    pub fn from_value(value: &Value) -> Result<Self> {
        let Value::Object(map) = value else {
            return Err(KinematicsError::doc(
                "process",
                format!("expected an object, found {}", json_type_name(value)),
            ));
        };
        if let Some(extra) = map.keys().find(|k| !Self::KEYS.contains(&k.as_str())) {
            return Err(KinematicsError::doc(
                format!("process.{extra}"),
                format!("unknown key (known: {})", Self::KEYS.join(", ")),
            ));
        }
        let lines = |key: &str| -> Result<Option<Vec<String>>> {
            let Some(v) = map.get(key) else {
                return Ok(None);
            };
            let Value::Array(items) = v else {
                return Err(KinematicsError::doc(
                    format!("process.{key}"),
                    format!(
                        "expected a list of program lines, found {}",
                        json_type_name(v)
                    ),
                ));
            };
            items
                .iter()
                .enumerate()
                .map(|(i, item)| match item {
                    Value::String(s) => Ok(s.clone()),
                    other => Err(KinematicsError::doc(
                        format!("process.{key}[{i}]"),
                        format!("expected a string, found {}", json_type_name(other)),
                    )),
                })
                .collect::<Result<Vec<_>>>()
                .map(Some)
        };
        let number = |key: &str| crate::json::optional_number(map, "process", key);
        let p = Self {
            beam_on: lines("beam_on")?,
            beam_off: lines("beam_off")?,
            pierce_dwell_s: number("pierce_dwell_s")?,
            pierce_standoff: number("pierce_standoff")?,
            kerf_width_mm: number("kerf_width_mm")?,
            standoff_mm: number("standoff_mm")?,
            technology: match map.get("technology") {
                None => None,
                Some(Value::String(t)) => Some(t.clone()),
                Some(other) => {
                    return Err(KinematicsError::doc(
                        "process.technology",
                        format!("expected a file name, found {}", json_type_name(other)),
                    ))
                }
            },
        };
        p.validate()?;
        Ok(p)
    }

    /// True when the file had no `process` object (or an empty one).
    pub fn is_empty(&self) -> bool {
        *self == Self::default()
    }
}

impl Machine {
    /// A machine from its parts, checked like a file.
    ///
    /// # Errors
    /// [`KinematicsError::Document`] naming the first bad value (`limits.A: min 10 > max -10`,
    /// `max_velocity.X: must be finite and > 0 (got 0)`, `name: must not be empty`).
    pub fn try_new(
        name: impl Into<String>,
        kinematics: Arc<dyn Kinematics>,
        limits: [Option<Range>; 5],
        max_velocity: [f64; 5],
        max_acceleration: [f64; 5],
    ) -> Result<Self> {
        let machine = Self {
            name: name.into(),
            kinematics,
            limits,
            max_velocity,
            max_acceleration,
            process: Process::default(),
            head: None,
            max_jerk: None,
            warnings: Vec::new(),
        };
        machine.validate()?;
        Ok(machine)
    }

    /// The same machine with jerk limits (mm/s^3, deg/s^3; `None` removes them), checked.
    ///
    /// # Errors
    /// [`KinematicsError::Document`] for a jerk that is not finite and > 0 (`max_jerk.X: ...`).
    pub fn with_max_jerk(mut self, max_jerk: Option<[f64; 5]>) -> Result<Self> {
        self.max_jerk = max_jerk;
        self.validate()?;
        Ok(self)
    }

    /// Checks the name, the limits, the velocities and the accelerations (the kinematic
    /// parameters are checked by each type's constructor).
    ///
    /// # Errors
    /// [`KinematicsError::Document`] naming the first bad value.
    pub fn validate(&self) -> Result<()> {
        if self.name.trim().is_empty() {
            return Err(KinematicsError::doc("name", "must not be empty"));
        }
        // The name is written into program headers.
        crate::json::check_text("name", &self.name)?;
        let names = self.axis_names();
        for axis in Axis::ALL {
            let name = names[axis.index()];
            if let Some(r) = self.limits[axis.index()] {
                for (k, v) in [r.min, r.max].into_iter().enumerate() {
                    if !v.is_finite() {
                        return Err(KinematicsError::doc(
                            format!("limits.{name}[{k}]"),
                            format!("must be finite (got {v}); use null for an unlimited axis"),
                        ));
                    }
                }
                if r.min > r.max {
                    return Err(KinematicsError::doc(
                        format!("limits.{name}"),
                        format!("min {} > max {}", r.min, r.max),
                    ));
                }
            }
            for (key, v) in [
                ("max_velocity", self.max_velocity[axis.index()]),
                ("max_acceleration", self.max_acceleration[axis.index()]),
            ] {
                if !(v.is_finite() && v > 0.0) {
                    return Err(KinematicsError::doc(
                        format!("{key}.{name}"),
                        format!("must be finite and > 0 (got {v})"),
                    ));
                }
            }
            if let Some(j) = self.max_jerk {
                let v = j[axis.index()];
                if !(v.is_finite() && v > 0.0) {
                    return Err(KinematicsError::doc(
                        format!("max_jerk.{name}"),
                        format!("must be finite and > 0 (got {v})"),
                    ));
                }
            }
        }
        if let Some(h) = &self.head {
            h.validate()?;
        }
        self.process.validate()
    }

    /// The axis names in file order, e.g. `["X", "Y", "Z", "A", "C"]`.
    pub fn axis_names(&self) -> [&'static str; 5] {
        let tilt = self.kinematics.tilt_name();
        Axis::ALL.map(|a| a.name(tilt))
    }

    /// The name of one axis.
    pub fn axis_name(&self, axis: Axis) -> &'static str {
        axis.name(self.kinematics.tilt_name())
    }

    /// The limits of one axis; `None` if unlimited.
    pub fn limit(&self, axis: Axis) -> Option<Range> {
        self.limits[axis.index()]
    }

    /// The first axis of `axes` outside its limits (with `slack` mm or degrees of tolerance),
    /// with its range.
    pub fn violation(&self, axes: &Axes, slack: f64) -> Option<(Axis, Range)> {
        Axis::ALL.into_iter().find_map(|axis| {
            let range = self.limits[axis.index()]?;
            (!range.contains(axes.get(axis), slack)).then_some((axis, range))
        })
    }

    /// Reads a machine file.
    ///
    /// # Errors
    /// [`KinematicsError::Io`] if the file cannot be read, else the errors of
    /// [`Machine::from_str`] wrapped in [`KinematicsError::File`], so that the message names
    /// the file: `machine.json: limits.A: min 10 > max -10`.
    pub fn read(path: impl AsRef<Path>) -> Result<Self> {
        crate::json::read_with(path.as_ref(), Self::from_slice)
    }

    /// Reads a machine from `kerf.machine/1` JSON text.
    ///
    /// # Errors
    /// As [`Machine::from_slice`].
    #[allow(clippy::should_implement_trait)] // FromStr would hide the error type's meaning.
    pub fn from_str(text: &str) -> Result<Self> {
        Self::from_slice(text.as_bytes())
    }

    /// Reads a machine from `kerf.machine/1` JSON bytes (a UTF-8 byte-order mark is skipped).
    ///
    /// # Errors
    /// [`KinematicsError::Syntax`] for malformed JSON, [`KinematicsError::Document`] naming
    /// the JSON path of the first defect (a key given twice in one object is one).
    pub fn from_slice(bytes: &[u8]) -> Result<Self> {
        Self::from_value(&crate::json::parse(bytes)?)
    }

    /// The top-level keys of `kerf.machine/1`.
    pub const KEYS: &'static [&'static str] = &[
        "format",
        "name",
        "kinematics",
        "limits",
        "max_velocity",
        "max_acceleration",
        "max_jerk",
        "process",
        "head",
    ];

    /// Reads a machine from a parsed JSON document. Unknown top-level keys are allowed
    /// (extensions); those that look like misspellings of the format's are in
    /// [`Machine::warnings`].
    ///
    /// # Errors
    /// [`KinematicsError::Document`] naming the JSON path of the first defect.
    pub fn from_value(value: &Value) -> Result<Self> {
        let top = crate::json::top_object(value, MACHINE_FORMAT)?;
        let name = match top.get("name") {
            Some(Value::String(s)) => s.clone(),
            Some(other) => {
                return Err(KinematicsError::doc(
                    "name",
                    format!("expected a string, found {}", json_type_name(other)),
                ))
            }
            None => return Err(KinematicsError::doc("name", "missing")),
        };
        let kinematics = registry::parse(required(top, "kinematics")?)?;
        let names = Axis::ALL.map(|a| a.name(kinematics.tilt_name()));
        let limits = per_axis(top, "limits", &names, |path, v| match v {
            Value::Null => Ok(None),
            Value::Array(items) if items.len() == 2 => {
                let number = |k: usize| {
                    items[k].as_f64().ok_or_else(|| {
                        KinematicsError::doc(
                            format!("{path}[{k}]"),
                            format!("expected a number, found {}", json_type_name(&items[k])),
                        )
                    })
                };
                Ok(Some(Range::new(number(0)?, number(1)?)))
            }
            other => Err(KinematicsError::doc(
                path,
                format!("expected [min, max] or null (unlimited), found {other}"),
            )),
        })?;
        let number = |path: String, v: &Value| {
            v.as_f64()
                .ok_or_else(|| KinematicsError::doc(path, format!("expected a number, found {v}")))
        };
        let max_velocity = per_axis(top, "max_velocity", &names, number)?;
        let max_acceleration = per_axis(top, "max_acceleration", &names, number)?;
        let max_jerk = match top.get("max_jerk") {
            None => None,
            Some(_) => Some(per_axis(top, "max_jerk", &names, number)?),
        };
        let mut machine = Self::try_new(name, kinematics, limits, max_velocity, max_acceleration)?
            .with_max_jerk(max_jerk)?;
        if let Some(p) = top.get("process") {
            machine.process = Process::from_value(p)?;
        }
        if let Some(h) = top.get("head") {
            machine.head = Some(Head::from_value(h)?);
        }
        kerf_io::near_misses_in(top, Self::KEYS, "", &mut machine.warnings);
        Ok(machine)
    }

    /// The machine as `kerf.machine/1` JSON text (reads back to an equal machine).
    pub fn to_json(&self) -> String {
        let names = self.axis_names();
        let mut kin = vec![format!("\"type\": {}", json(self.kinematics.type_name()))];
        for (key, value) in self.kinematics.parameters() {
            kin.push(format!("{}: {}", json(key), parameter_json(&value)));
        }
        let object = |values: Vec<String>| {
            let body: Vec<String> = names
                .iter()
                .zip(values)
                .map(|(n, v)| format!("\"{n}\": {v}"))
                .collect();
            format!("{{ {} }}", body.join(", "))
        };
        let limits = object(
            self.limits
                .iter()
                .map(|r| match r {
                    Some(r) => format!("[{}, {}]", json(r.min), json(r.max)),
                    None => "null".to_owned(),
                })
                .collect(),
        );
        let numbers = |v: &[f64; 5]| object(v.iter().map(|x| json(*x)).collect());
        let jerk = self.max_jerk.map_or(String::new(), |j| {
            format!(",\n  \"max_jerk\": {}", numbers(&j))
        });
        let mut process = Vec::new();
        let p = &self.process;
        for (key, lines) in [("beam_on", &p.beam_on), ("beam_off", &p.beam_off)] {
            if let Some(l) = lines {
                process.push(format!("\"{key}\": {}", json(l)));
            }
        }
        for (key, v) in [
            ("pierce_dwell_s", p.pierce_dwell_s),
            ("pierce_standoff", p.pierce_standoff),
            ("kerf_width_mm", p.kerf_width_mm),
            ("standoff_mm", p.standoff_mm),
        ] {
            if let Some(v) = v {
                process.push(format!("\"{key}\": {}", json(v)));
            }
        }
        if let Some(t) = &p.technology {
            process.push(format!("\"technology\": {}", json(t)));
        }
        let process = if process.is_empty() {
            String::new()
        } else {
            format!(",\n  \"process\": {{ {} }}", process.join(", "))
        };
        let head = self.head.as_ref().map_or(String::new(), |h| {
            format!(",\n  \"head\": {}", h.to_value())
        });
        format!(
            "{{\n  \"format\": \"{MACHINE_FORMAT}\",\n  \"name\": {},\n  \"kinematics\": {{ {} }},\n  \"limits\": {limits},\n  \"max_velocity\": {},\n  \"max_acceleration\": {}{jerk}{process}{head}\n}}\n",
            json(self.name.as_str()),
            kin.join(", "),
            numbers(&self.max_velocity),
            numbers(&self.max_acceleration),
        )
    }
}

/// A value as JSON text.
fn json(value: impl serde::Serialize) -> String {
    serde_json::to_string(&value).unwrap_or_else(|_| "null".to_owned())
}

fn required<'a>(top: &'a Map<String, Value>, key: &str) -> Result<&'a Value> {
    top.get(key)
        .ok_or_else(|| KinematicsError::doc(key, "missing"))
}

/// Reads an object with one entry per axis (`names`), every axis required, no other key.
fn per_axis<T>(
    top: &Map<String, Value>,
    key: &str,
    names: &[&'static str; 5],
    mut read: impl FnMut(String, &Value) -> Result<T>,
) -> Result<[T; 5]> {
    let value = required(top, key)?;
    let Value::Object(map) = value else {
        return Err(KinematicsError::doc(
            key,
            format!(
                "expected an object with the axes {}, found {}",
                names.join(", "),
                json_type_name(value)
            ),
        ));
    };
    if let Some(extra) = map.keys().find(|k| !names.contains(&k.as_str())) {
        return Err(KinematicsError::doc(
            format!("{key}.{extra}"),
            format!(
                "not an axis of this machine (its axes are {})",
                names.join(", ")
            ),
        ));
    }
    let mut out = Vec::with_capacity(5);
    for name in names {
        let path = format!("{key}.{name}");
        let Some(v) = map.get(*name) else {
            let hint = if key == "limits" {
                " (give [min, max], or null for an unlimited axis)"
            } else {
                ""
            };
            return Err(KinematicsError::doc(path, format!("missing{hint}")));
        };
        out.push(read(path, v)?);
    }
    out.try_into()
        .map_err(|_| KinematicsError::doc(key, "internal: wrong axis count"))
}

/// A machine type's parameter as JSON text, as `serde_json` writes the value (the machine
/// file's writer is the one place where the typed parameters become JSON).
fn parameter_json(p: &crate::kinematics::Parameter) -> String {
    use crate::kinematics::Parameter;
    let value = match p {
        Parameter::Number(v) => serde_json::Value::from(*v),
        Parameter::Numbers(v) => serde_json::Value::from(v.clone()),
        Parameter::Name(v) => serde_json::Value::from(*v),
        Parameter::Flag(v) => serde_json::Value::from(*v),
    };
    value.to_string()
}
