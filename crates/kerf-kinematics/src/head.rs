//! The cutting head of `kerf.machine/1` (optional key `head`): solids of revolution along the
//! tool axis, listed from the nozzle tip upward, so that cuts and traverses can be checked
//! against the part.
//!
//! ```
//! use kerf_kinematics::Head;
//!
//! let head = Head::from_value(&serde_json::json!({ "solids": [
//!     { "type": "cone", "length": 25, "tip_diameter": 3, "top_diameter": 14 },
//!     { "type": "cylinder", "length": 180, "diameter": 90 } ] }))?;
//! assert_eq!(head.length_mm(), 205.0);
//! assert_eq!(head.radius_at(0.0), Some(1.5));
//! assert_eq!(head.radius_at(12.5), Some(4.25));
//! assert_eq!(head.radius_at(100.0), Some(45.0));
//! assert_eq!(head.radius_at(-1.0), None);
//!
//! let err = Head::from_value(&serde_json::json!({ "solids": [
//!     { "type": "cone", "length": 25, "tip_diameter": 3 } ] })).unwrap_err();
//! assert_eq!(err.to_string(),
//!     "head.solids[0]: a cone needs top_diameter or cone_angle_deg");
//! # Ok::<(), kerf_kinematics::KinematicsError>(())
//! ```

use serde_json::Value;

use crate::error::{KinematicsError, Result};
use kerf_io::json_type_name;

/// The most solids a head may list: a nozzle, a body and a few steps of it.
pub const MAX_HEAD_SOLIDS: usize = 16;

/// The largest length or diameter of one solid, mm: heads are centimetres to a metre long.
pub const MAX_HEAD_SIZE_MM: f64 = 5000.0;

/// One solid of a head: a frustum of a cone (a cylinder when its two diameters are equal)
/// along the tool axis.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HeadSolid {
    /// Its length along the tool axis, mm (> 0).
    pub length_mm: f64,
    /// Its diameter at its lower end (toward the nozzle tip), mm (>= 0).
    pub bottom_diameter_mm: f64,
    /// Its diameter at its upper end, mm (>= 0).
    pub top_diameter_mm: f64,
}

/// A cutting head: solids of revolution about the tool axis, stacked from the nozzle tip
/// upward (the first solid's lower end is the nozzle tip). Distances along the axis are
/// measured from the nozzle tip.
#[derive(Debug, Clone, PartialEq)]
pub struct Head {
    /// The solids from the tip upward.
    pub solids: Vec<HeadSolid>,
}

impl Head {
    /// A typical 3D fiber-laser cutting head, the default of a machine file without `head`: a
    /// copper nozzle cone 25 mm long from 3 mm at the tip to 14 mm (nozzles of 1-3 mm bore sit
    /// in 10-15 mm bodies), on a sensor ring and a head body of 90 mm diameter, 180 mm long
    /// (compact 3D heads are 80-100 mm across at the nozzle end). `docs/process.md` ("The
    /// head") gives the sources of the numbers.
    pub fn laser_default() -> Self {
        Self {
            solids: vec![
                HeadSolid {
                    length_mm: 25.0,
                    bottom_diameter_mm: 3.0,
                    top_diameter_mm: 14.0,
                },
                HeadSolid {
                    length_mm: 180.0,
                    bottom_diameter_mm: 90.0,
                    top_diameter_mm: 90.0,
                },
            ],
        }
    }

    /// The head's length along the tool axis, mm.
    pub fn length_mm(&self) -> f64 {
        self.solids.iter().map(|s| s.length_mm).sum()
    }

    /// The largest radius of the head, mm.
    pub fn max_radius_mm(&self) -> f64 {
        self.solids
            .iter()
            .map(|s| s.bottom_diameter_mm.max(s.top_diameter_mm) / 2.0)
            .fold(0.0, f64::max)
    }

    /// The head's radius at `h` mm above the nozzle tip (the larger one where two solids
    /// meet); `None` outside `[0, length]`.
    pub fn radius_at(&self, h: f64) -> Option<f64> {
        let mut base = 0.0;
        let mut found: Option<f64> = None;
        for s in &self.solids {
            let top = base + s.length_mm;
            if h >= base && h <= top {
                let r = (s.bottom_diameter_mm
                    + (s.top_diameter_mm - s.bottom_diameter_mm) * (h - base) / s.length_mm)
                    / 2.0;
                found = Some(found.map_or(r, |f| f.max(r)));
            }
            base = top;
        }
        found
    }

    /// The largest radius of the head over `[h0, h1]` mm above the tip (0 where the interval
    /// misses the head).
    pub fn max_radius_over(&self, h0: f64, h1: f64) -> f64 {
        let mut base = 0.0;
        let mut r: f64 = 0.0;
        for s in &self.solids {
            let top = base + s.length_mm;
            let (a, b) = (h0.max(base), h1.min(top));
            if a <= b {
                let at = |h: f64| {
                    (s.bottom_diameter_mm
                        + (s.top_diameter_mm - s.bottom_diameter_mm) * (h - base) / s.length_mm)
                        / 2.0
                };
                r = r.max(at(a)).max(at(b));
            }
            base = top;
        }
        r
    }

    /// Checks every solid.
    ///
    /// # Errors
    /// [`KinematicsError::Document`] with the JSON path, as
    /// `head.solids[1].diameter: must lie in (0, 5000] (got -3)`.
    pub fn validate(&self) -> Result<()> {
        if self.solids.is_empty() {
            return Err(KinematicsError::doc(
                "head.solids",
                "must list at least one solid",
            ));
        }
        if self.solids.len() > MAX_HEAD_SOLIDS {
            return Err(KinematicsError::doc(
                "head.solids",
                format!("{} solids, at most {MAX_HEAD_SOLIDS}", self.solids.len()),
            ));
        }
        for (i, s) in self.solids.iter().enumerate() {
            for (key, v, zero_ok) in [
                ("length", s.length_mm, false),
                ("bottom diameter", s.bottom_diameter_mm, true),
                ("top diameter", s.top_diameter_mm, true),
            ] {
                let ok =
                    v.is_finite() && v <= MAX_HEAD_SIZE_MM && (v > 0.0 || (zero_ok && v == 0.0));
                if !ok {
                    return Err(KinematicsError::doc(
                        format!("head.solids[{i}]"),
                        format!(
                            "{key} must lie in {}0, {MAX_HEAD_SIZE_MM}] mm (got {v})",
                            if zero_ok { "[" } else { "(" }
                        ),
                    ));
                }
            }
        }
        Ok(())
    }

    /// The keys of one solid.
    const SOLID_KEYS: [&'static str; 6] = [
        "type",
        "length",
        "diameter",
        "tip_diameter",
        "top_diameter",
        "cone_angle_deg",
    ];

    /// Reads the `head` object (`value` is its JSON value): `{"solids": [...]}`, each solid
    /// `{"type": "cylinder", "length", "diameter"}` or `{"type": "cone", "length",
    /// "tip_diameter", and "top_diameter" or "cone_angle_deg" (the full opening angle)}`, in
    /// mm from the nozzle tip upward; unknown keys are refused.
    ///
    /// # Errors
    /// [`KinematicsError::Document`] with the JSON path of the first defect.
    pub fn from_value(value: &Value) -> Result<Self> {
        let Value::Object(map) = value else {
            return Err(KinematicsError::doc(
                "head",
                format!("expected an object, found {}", json_type_name(value)),
            ));
        };
        if let Some(extra) = map.keys().find(|k| k.as_str() != "solids") {
            return Err(KinematicsError::doc(
                format!("head.{extra}"),
                "unknown key (known: solids)",
            ));
        }
        let items = match map.get("solids") {
            Some(Value::Array(items)) => items,
            Some(other) => {
                return Err(KinematicsError::doc(
                    "head.solids",
                    format!("expected a list of solids, found {}", json_type_name(other)),
                ))
            }
            None => return Err(KinematicsError::doc("head.solids", "missing")),
        };
        if items.len() > MAX_HEAD_SOLIDS {
            return Err(KinematicsError::doc(
                "head.solids",
                format!("{} solids, at most {MAX_HEAD_SOLIDS}", items.len()),
            ));
        }
        let mut solids = Vec::with_capacity(items.len());
        for (i, item) in items.iter().enumerate() {
            let path = format!("head.solids[{i}]");
            let Value::Object(s) = item else {
                return Err(KinematicsError::doc(
                    path,
                    format!("expected an object, found {}", json_type_name(item)),
                ));
            };
            if let Some(extra) = s.keys().find(|k| !Self::SOLID_KEYS.contains(&k.as_str())) {
                return Err(KinematicsError::doc(
                    format!("{path}.{extra}"),
                    format!("unknown key (known: {})", Self::SOLID_KEYS.join(", ")),
                ));
            }
            let number = |key: &str| crate::json::optional_number(s, &path, key);
            let needed = |key: &str| -> Result<f64> {
                number(key)?.ok_or_else(|| KinematicsError::doc(format!("{path}.{key}"), "missing"))
            };
            let refuse = |keys: &[&str], kind: &str| -> Result<()> {
                match keys.iter().find(|k| s.contains_key(**k)) {
                    Some(k) => Err(KinematicsError::doc(
                        format!("{path}.{k}"),
                        format!("not a key of a {kind}"),
                    )),
                    None => Ok(()),
                }
            };
            let length_mm = needed("length")?;
            let solid = match s.get("type").and_then(Value::as_str) {
                Some("cylinder") => {
                    refuse(
                        &["tip_diameter", "top_diameter", "cone_angle_deg"],
                        "cylinder",
                    )?;
                    let d = needed("diameter")?;
                    HeadSolid {
                        length_mm,
                        bottom_diameter_mm: d,
                        top_diameter_mm: d,
                    }
                }
                Some("cone") => {
                    refuse(&["diameter"], "cone")?;
                    let tip = needed("tip_diameter")?;
                    let top = match (number("top_diameter")?, number("cone_angle_deg")?) {
                        (Some(top), None) => top,
                        (None, Some(angle)) => {
                            if !(angle.is_finite() && (0.0..180.0).contains(&angle)) {
                                return Err(KinematicsError::doc(
                                    format!("{path}.cone_angle_deg"),
                                    format!("must lie in [0, 180) (got {angle})"),
                                ));
                            }
                            tip + 2.0 * length_mm * (angle.to_radians() / 2.0).tan()
                        }
                        (Some(_), Some(_)) => {
                            return Err(KinematicsError::doc(
                                path,
                                "a cone takes top_diameter or cone_angle_deg, not both",
                            ))
                        }
                        (None, None) => {
                            return Err(KinematicsError::doc(
                                path,
                                "a cone needs top_diameter or cone_angle_deg",
                            ))
                        }
                    };
                    HeadSolid {
                        length_mm,
                        bottom_diameter_mm: tip,
                        top_diameter_mm: top,
                    }
                }
                Some(other) => {
                    return Err(KinematicsError::doc(
                        format!("{path}.type"),
                        format!("unknown type {other:?} (known: cone, cylinder)"),
                    ))
                }
                None => {
                    return Err(KinematicsError::doc(
                        format!("{path}.type"),
                        "missing or not a string (known: cone, cylinder)",
                    ))
                }
            };
            solids.push(solid);
        }
        let head = Self { solids };
        head.validate()?;
        Ok(head)
    }

    /// The head as the JSON value of `kerf.machine/1`'s `head` (reads back to an equal head).
    pub fn to_value(&self) -> Value {
        let solids: Vec<Value> = self
            .solids
            .iter()
            .map(|s| {
                if s.bottom_diameter_mm == s.top_diameter_mm {
                    serde_json::json!({ "type": "cylinder", "length": s.length_mm, "diameter": s.top_diameter_mm })
                } else {
                    serde_json::json!({ "type": "cone", "length": s.length_mm,
                        "tip_diameter": s.bottom_diameter_mm, "top_diameter": s.top_diameter_mm })
                }
            })
            .collect();
        serde_json::json!({ "solids": solids })
    }
}

/// Serialized as `kerf.machine/1`'s `head` ([`Head::to_value`]).
impl serde::Serialize for Head {
    fn serialize<S: serde::Serializer>(
        &self,
        serializer: S,
    ) -> std::result::Result<S::Ok, S::Error> {
        self.to_value().serialize(serializer)
    }
}
