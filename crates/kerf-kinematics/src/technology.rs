//! `kerf.technology/1`: laser cutting parameters by material and thickness (feed, power, gas,
//! focus, standoff, kerf, pierce, small holes), the table a run picks its entry from.
//!
//! ```
//! use kerf_kinematics::Technology;
//!
//! let t = Technology::from_str(r#"{ "format": "kerf.technology/1", "entries": [
//!   { "material": "mild steel", "thickness_mm": 1.5, "gas": "O2", "gas_pressure_bar": 0.6,
//!     "feed_mm_per_min": 4200, "power_percent": 100, "focus_mm": 0.5, "standoff_mm": 0.8,
//!     "kerf_width_mm": 0.15, "pierce": { "time_s": 0.3, "power_percent": 60, "height_mm": 3 },
//!     "small_hole": { "max_diameter_mm": 8, "feed_factor": 0.6, "power_factor": 0.7 } } ] }"#)?;
//! let e = t.entry("Mild Steel", Some(1.5))?;
//! assert_eq!(e.feed_mm_per_min, 4200.0);
//! let err = t.entry("copper", None).unwrap_err();
//! assert_eq!(err.to_string(),
//!     "technology: no entry for material \"copper\" (known: mild steel 1.5 mm)");
//! # Ok::<(), kerf_kinematics::KinematicsError>(())
//! ```

use std::path::Path;

use serde::{Deserialize, Serialize};
use serde_json::Value;

use crate::error::{KinematicsError, Result};
use kerf_io::json_type_name;

/// The `format` value of a technology file.
pub const TECHNOLOGY_FORMAT: &str = "kerf.technology/1";

/// The most entries a technology table may hold.
pub const MAX_TECHNOLOGY_ENTRIES: usize = 4096;

/// The share of an entry's cutting power that is its least power when the entry names none
/// (`power_min_percent`): 0.2, a common floor of laser controls' speed-following power.
pub const DEFAULT_POWER_MIN_SHARE: f64 = 0.2;

/// The pierce of an entry: how long and with what power the beam stands at the pierce point,
/// and how high above the surface.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Pierce {
    /// The dwell with the beam on before the head moves, s.
    pub time_s: f64,
    /// The laser power while piercing, percent of the source's.
    pub power_percent: f64,
    /// The pierce height above the surface along the tool axis, mm.
    pub height_mm: f64,
}

/// The small-hole rule of an entry: holes up to a diameter are cut slower with less power.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct SmallHole {
    /// Holes (closed contours) of at most this diameter follow the rule, mm.
    pub max_diameter_mm: f64,
    /// Their feed is the entry's times this, in (0, 1].
    pub feed_factor: f64,
    /// Their power is the entry's times this, in (0, 1].
    pub power_factor: f64,
}

/// The corner rule of an entry: near sharp corners the cut runs slower (the power, following
/// the speed, comes down with it).
#[derive(Debug, Clone, Copy, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct CornerRule {
    /// The least turn of the path that makes a corner, degrees, in (0, 180).
    pub min_turn_deg: f64,
    /// How far on each side of the corner the cut runs slower, mm, in (0, 100].
    pub length_mm: f64,
    /// The share of the feed there, in (0, 1].
    pub feed_factor: f64,
}

/// The micro-joints of an entry: the run's default for `--micro-joints`.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MicroJoints {
    /// The length left uncut, mm, in (0, 10].
    pub length_mm: f64,
    /// The path between joints, mm, in [1, 1e5] and longer than the joint.
    pub spacing_mm: f64,
}

/// One entry of a technology table: the cutting parameters of one material and thickness.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TechnologyEntry {
    /// The material's name, as a run names it (`--material`; compared without case).
    pub material: String,
    /// The sheet thickness, mm.
    pub thickness_mm: f64,
    /// The assist gas, e.g. `O2`, `N2`, `air`.
    #[serde(default)]
    pub gas: Option<String>,
    /// The assist gas pressure, bar.
    #[serde(default)]
    pub gas_pressure_bar: Option<f64>,
    /// The cutting feed, mm/min.
    pub feed_mm_per_min: f64,
    /// The cutting power at the entry's feed, percent of the source's; where the head runs
    /// slower the power follows the speed down to [`power_min_percent`](Self::power_min_percent).
    pub power_percent: f64,
    /// The least power while cutting, percent (the floor of the power that follows the
    /// speed, where the head slows at corners and stops at a pierce). Default:
    /// [`DEFAULT_POWER_MIN_SHARE`] of [`power_percent`](Self::power_percent).
    #[serde(default)]
    pub power_min_percent: Option<f64>,
    /// The focus position relative to the surface, mm (positive above).
    #[serde(default)]
    pub focus_mm: Option<f64>,
    /// The nozzle tip's height above the surface while cutting, mm.
    #[serde(default)]
    pub standoff_mm: Option<f64>,
    /// The kerf width, mm.
    #[serde(default)]
    pub kerf_width_mm: Option<f64>,
    /// The pierce.
    #[serde(default)]
    pub pierce: Option<Pierce>,
    /// The small-hole rule.
    #[serde(default)]
    pub small_hole: Option<SmallHole>,
    /// Micro-joints the run leaves unless it names its own.
    #[serde(default)]
    pub micro_joints: Option<MicroJoints>,
    /// The corner rule.
    #[serde(default)]
    pub corner: Option<CornerRule>,
}

impl TechnologyEntry {
    /// The least power while cutting, percent: `power_min_percent` or
    /// [`DEFAULT_POWER_MIN_SHARE`] of the cutting power.
    pub fn power_min(&self) -> f64 {
        self.power_min_percent
            .unwrap_or(DEFAULT_POWER_MIN_SHARE * self.power_percent)
    }

    /// `mild steel 1.5 mm O2`: the entry's name for headers and messages.
    pub fn label(&self) -> String {
        let gas = self
            .gas
            .as_deref()
            .map_or(String::new(), |g| format!(" {g}"));
        format!("{} {} mm{gas}", self.material, self.thickness_mm)
    }

    /// Checks every value of the entry at `path` (`entries[2]`).
    fn validate(&self, path: &str) -> Result<()> {
        let bad = |key: &str, why: String| Err(KinematicsError::doc(format!("{path}.{key}"), why));
        let within = |key: &str, v: f64, lo: f64, lo_open: bool, hi: f64| -> Result<()> {
            let ok = v.is_finite() && (if lo_open { v > lo } else { v >= lo }) && v <= hi;
            if ok {
                Ok(())
            } else {
                bad(
                    key,
                    format!(
                        "must lie in {}{lo}, {hi}] (got {v})",
                        if lo_open { "(" } else { "[" }
                    ),
                )
            }
        };
        for (key, text) in [
            ("material", Some(&self.material)),
            ("gas", self.gas.as_ref()),
        ] {
            if let Some(t) = text {
                if t.trim().is_empty() {
                    return bad(key, "must not be empty".into());
                }
                if t.chars().count() > 64 || kerf_io::check_text(t).is_err() {
                    return bad(
                        key,
                        "must be one line of printable text of at most 64 characters".into(),
                    );
                }
            }
        }
        within("thickness_mm", self.thickness_mm, 0.0, true, 100.0)?;
        within("feed_mm_per_min", self.feed_mm_per_min, 0.0, true, 1e6)?;
        within("power_percent", self.power_percent, 0.0, true, 100.0)?;
        if let Some(v) = self.power_min_percent {
            within("power_min_percent", v, 0.0, false, self.power_percent)?;
        }
        if let Some(v) = self.gas_pressure_bar {
            within("gas_pressure_bar", v, 0.0, false, 100.0)?;
        }
        if let Some(v) = self.focus_mm {
            within("focus_mm", v, -100.0, false, 100.0)?;
        }
        if let Some(v) = self.standoff_mm {
            within("standoff_mm", v, 0.0, false, crate::MAX_PIERCE_STANDOFF_MM)?;
        }
        if let Some(v) = self.kerf_width_mm {
            within("kerf_width_mm", v, 0.0, true, crate::MAX_KERF_WIDTH_MM)?;
        }
        if let Some(p) = &self.pierce {
            within(
                "pierce.time_s",
                p.time_s,
                0.0,
                false,
                crate::MAX_PIERCE_DWELL_S,
            )?;
            within("pierce.power_percent", p.power_percent, 0.0, false, 100.0)?;
            within(
                "pierce.height_mm",
                p.height_mm,
                0.0,
                false,
                crate::MAX_PIERCE_STANDOFF_MM,
            )?;
        }
        if let Some(c) = &self.corner {
            if !(c.min_turn_deg.is_finite() && c.min_turn_deg > 0.0 && c.min_turn_deg < 180.0) {
                return bad(
                    "corner.min_turn_deg",
                    format!("must lie in (0, 180) (got {})", c.min_turn_deg),
                );
            }
            within("corner.length_mm", c.length_mm, 0.0, true, 100.0)?;
            within("corner.feed_factor", c.feed_factor, 0.0, true, 1.0)?;
        }
        if let Some(j) = &self.micro_joints {
            within("micro_joints.length_mm", j.length_mm, 0.0, true, 10.0)?;
            within("micro_joints.spacing_mm", j.spacing_mm, 1.0, false, 1e5)?;
            if j.length_mm >= j.spacing_mm {
                return bad(
                    "micro_joints.length_mm",
                    format!(
                        "must be less than the spacing ({} mm, got {})",
                        j.spacing_mm, j.length_mm
                    ),
                );
            }
        }
        if let Some(h) = &self.small_hole {
            within(
                "small_hole.max_diameter_mm",
                h.max_diameter_mm,
                0.0,
                true,
                1e4,
            )?;
            within("small_hole.feed_factor", h.feed_factor, 0.0, true, 1.0)?;
            within("small_hole.power_factor", h.power_factor, 0.0, true, 1.0)?;
        }
        Ok(())
    }
}

/// A technology table: `kerf.technology/1`.
#[derive(Debug, Clone, PartialEq)]
pub struct Technology {
    /// The entries, in file order.
    pub entries: Vec<TechnologyEntry>,
}

impl Technology {
    /// Reads a technology file.
    ///
    /// # Errors
    /// [`KinematicsError::Io`] if it cannot be read, else the errors of
    /// [`Technology::from_slice`] wrapped in [`KinematicsError::File`] (the message names the
    /// file).
    pub fn read(path: impl AsRef<Path>) -> Result<Self> {
        crate::json::read_with(path.as_ref(), Self::from_slice)
    }

    /// Reads a table from its JSON text.
    ///
    /// # Errors
    /// As [`Technology::from_slice`].
    #[allow(clippy::should_implement_trait)] // FromStr would hide the error type's meaning.
    pub fn from_str(text: &str) -> Result<Self> {
        Self::from_slice(text.as_bytes())
    }

    /// Reads a table from JSON bytes: `format`, `entries` (at least one, at most
    /// [`MAX_TECHNOLOGY_ENTRIES`]); unknown keys refused with their JSON path; every number
    /// in its range (`entries[0].power_percent: must lie in (0, 100] (got 120)`); two entries
    /// of one material and thickness refused.
    ///
    /// # Errors
    /// [`KinematicsError::Syntax`] for malformed JSON, [`KinematicsError::Document`] with the
    /// JSON path of the first defect.
    pub fn from_slice(bytes: &[u8]) -> Result<Self> {
        let value = crate::json::parse(bytes)?;
        let top = crate::json::top_object(&value, TECHNOLOGY_FORMAT)?;
        if let Some(extra) = top
            .keys()
            .find(|k| !["format", "entries"].contains(&k.as_str()))
        {
            return Err(KinematicsError::doc(
                extra.as_str(),
                "unknown key (known: format, entries)",
            ));
        }
        let items = match top.get("entries") {
            Some(Value::Array(items)) => items,
            Some(other) => {
                return Err(KinematicsError::doc(
                    "entries",
                    format!(
                        "expected a list of entries, found {}",
                        json_type_name(other)
                    ),
                ))
            }
            None => return Err(KinematicsError::doc("entries", "missing")),
        };
        if items.is_empty() || items.len() > MAX_TECHNOLOGY_ENTRIES {
            return Err(KinematicsError::doc(
                "entries",
                format!(
                    "{} entries, expected 1 to {MAX_TECHNOLOGY_ENTRIES}",
                    items.len()
                ),
            ));
        }
        let mut entries: Vec<TechnologyEntry> = Vec::with_capacity(items.len());
        for (i, item) in items.iter().enumerate() {
            let path = format!("entries[{i}]");
            let e: TechnologyEntry = kerf_io::deserialize_at(item.clone(), &path)
                .map_err(|e| KinematicsError::doc(e.path.clone(), e.message.clone()))?;
            e.validate(&path)?;
            if let Some(j) = entries.iter().position(|o| {
                o.material.eq_ignore_ascii_case(&e.material) && o.thickness_mm == e.thickness_mm
            }) {
                return Err(KinematicsError::doc(
                    path,
                    format!("{} is also entries[{j}]", e.label()),
                ));
            }
            entries.push(e);
        }
        Ok(Self { entries })
    }

    /// The entry of `material` (without case) and `thickness_mm`; without a thickness, the
    /// material's only entry.
    ///
    /// # Errors
    /// [`KinematicsError::Document`] at `technology` naming what is known: the materials, or
    /// the material's thicknesses.
    pub fn entry(&self, material: &str, thickness_mm: Option<f64>) -> Result<&TechnologyEntry> {
        let of: Vec<&TechnologyEntry> = self
            .entries
            .iter()
            .filter(|e| e.material.eq_ignore_ascii_case(material.trim()))
            .collect();
        let known = |list: &[&TechnologyEntry]| -> String {
            list.iter()
                .map(|e| format!("{} {} mm", e.material, e.thickness_mm))
                .collect::<Vec<_>>()
                .join(", ")
        };
        let all: Vec<&TechnologyEntry> = self.entries.iter().collect();
        let shown = kerf_io::check_text(material)
            .map(|_| format!("{material:?}"))
            .unwrap_or_else(|_| "(not printable)".into());
        match (of.as_slice(), thickness_mm) {
            ([], _) => Err(KinematicsError::doc(
                "technology",
                format!("no entry for material {shown} (known: {})", known(&all)),
            )),
            ([one], None) => Ok(one),
            (_, None) => Err(KinematicsError::doc(
                "technology",
                format!(
                    "material {shown} has several entries: give the thickness (known: {})",
                    known(&of)
                ),
            )),
            (_, Some(t)) => of
                .iter()
                .find(|e| (e.thickness_mm - t).abs() <= 1e-9 * t.abs().max(1.0))
                .copied()
                .ok_or_else(|| {
                    KinematicsError::doc(
                        "technology",
                        format!(
                            "no entry for material {shown} at {t} mm (known: {})",
                            known(&of)
                        ),
                    )
                }),
        }
    }
}
