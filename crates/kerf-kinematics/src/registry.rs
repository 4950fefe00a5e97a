//! The registry of kinematic types: `kinematics.type` name to parser.
//!
//! Adding a fifth type is one new file (a struct implementing [`crate::Kinematics`] and a
//! `TYPE` constant, see `ac_head.rs`) and one line in [`TYPES`].

use std::sync::Arc;

use serde_json::{Map, Value};

use crate::error::{json_type_name, KinematicsError, Result};
use crate::kinematics::Kinematics;
use crate::{ac_head, fork_head, head_table, table_table};

/// A kinematic type: its `kinematics.type` name and how to read its parameters.
pub(crate) struct KinematicsType {
    /// The `kinematics.type` value.
    pub(crate) name: &'static str,
    /// Reads the parameters (every key but `type`) and checks them.
    pub(crate) parse: fn(&mut Params<'_>) -> Result<Arc<dyn Kinematics>>,
}

/// Every known kinematic type, in the order of `shared/formats.md`.
pub(crate) const TYPES: &[KinematicsType] = &[
    ac_head::TYPE,
    fork_head::TYPE,
    table_table::TYPE,
    head_table::TYPE,
];

/// The names of the known kinematic types (`ac-head`, `fork-head`, `table-table`,
/// `head-table`).
pub fn kinematics_types() -> Vec<&'static str> {
    TYPES.iter().map(|t| t.name).collect()
}

/// Reads the `kinematics` object of a machine file.
pub(crate) fn parse(value: &Value) -> Result<Arc<dyn Kinematics>> {
    let Value::Object(map) = value else {
        return Err(KinematicsError::doc(
            "kinematics",
            format!("expected an object, found {}", json_type_name(value)),
        ));
    };
    let known = || kinematics_types().join(", ");
    let name = match map.get("type") {
        Some(Value::String(s)) => s.as_str(),
        Some(other) => {
            return Err(KinematicsError::doc(
                "kinematics.type",
                format!(
                    "expected a string, found {} (known: {})",
                    json_type_name(other),
                    known()
                ),
            ))
        }
        None => {
            return Err(KinematicsError::doc(
                "kinematics.type",
                format!("missing (known: {})", known()),
            ))
        }
    };
    let Some(kind) = TYPES.iter().find(|t| t.name == name) else {
        return Err(KinematicsError::doc(
            "kinematics.type",
            format!("unknown type {:?} (known: {})", name, known()),
        ));
    };
    let mut params = Params {
        map,
        type_name: kind.name,
        used: vec!["type"],
    };
    let kinematics = (kind.parse)(&mut params)?;
    params.finish()?;
    Ok(kinematics)
}

/// The parameters of a `kinematics` object, read key by key; [`Params::finish`] refuses the
/// keys nobody asked for (a misspelt parameter is an error, not a silent default).
pub(crate) struct Params<'a> {
    map: &'a Map<String, Value>,
    type_name: &'static str,
    used: Vec<&'static str>,
}

impl<'a> Params<'a> {
    fn get(&mut self, key: &'static str) -> Result<&'a Value> {
        self.used.push(key);
        self.map.get(key).ok_or_else(|| {
            KinematicsError::doc(
                format!("kinematics.{key}"),
                format!("missing (type {:?} needs it)", self.type_name),
            )
        })
    }

    /// A required number (any JSON number is finite).
    pub(crate) fn number(&mut self, key: &'static str) -> Result<f64> {
        let value = self.get(key)?;
        value.as_f64().ok_or_else(|| {
            KinematicsError::doc(
                format!("kinematics.{key}"),
                format!("expected a number, found {}", json_type_name(value)),
            )
        })
    }

    /// A required array of `N` numbers.
    pub(crate) fn numbers<const N: usize>(&mut self, key: &'static str) -> Result<[f64; N]> {
        let value = self.get(key)?;
        let bad = || {
            KinematicsError::doc(
                format!("kinematics.{key}"),
                format!("expected an array of {N} numbers, found {value}"),
            )
        };
        let Value::Array(items) = value else {
            return Err(bad());
        };
        if items.len() != N {
            return Err(bad());
        }
        let mut out = [0.0; N];
        for (n, item) in items.iter().enumerate() {
            out[n] = item.as_f64().ok_or_else(bad)?;
        }
        Ok(out)
    }

    /// A required boolean.
    pub(crate) fn boolean(&mut self, key: &'static str) -> Result<bool> {
        let value = self.get(key)?;
        value.as_bool().ok_or_else(|| {
            KinematicsError::doc(
                format!("kinematics.{key}"),
                format!("expected true or false, found {value}"),
            )
        })
    }

    /// A required string.
    pub(crate) fn string(&mut self, key: &'static str) -> Result<&'a str> {
        let value = self.get(key)?;
        value.as_str().ok_or_else(|| {
            KinematicsError::doc(
                format!("kinematics.{key}"),
                format!("expected a string, found {value}"),
            )
        })
    }

    /// Refuses keys that were not read.
    fn finish(self) -> Result<()> {
        for key in self.map.keys() {
            if !self.used.contains(&key.as_str()) {
                let known: Vec<&str> = self.used.iter().copied().filter(|k| *k != "type").collect();
                return Err(KinematicsError::doc(
                    format!("kinematics.{key}"),
                    format!(
                        "unknown parameter of type {:?} (its parameters: {})",
                        self.type_name,
                        known.join(", ")
                    ),
                ));
            }
        }
        Ok(())
    }
}

/// Checks a parameter: `Ok` if `ok`, else `kinematics.<key>: must be <requirement> (got v)`.
pub(crate) fn require(key: &str, value: f64, ok: bool, requirement: &str) -> Result<()> {
    if ok {
        Ok(())
    } else {
        Err(KinematicsError::doc(
            format!("kinematics.{key}"),
            format!("must be {requirement} (got {value})"),
        ))
    }
}

/// `kinematics.<key>` must be finite.
pub(crate) fn finite(key: &str, value: f64) -> Result<()> {
    require(key, value, value.is_finite(), "finite")
}

/// `kinematics.<key>` must be finite and >= 0.
pub(crate) fn non_negative(key: &str, value: f64) -> Result<()> {
    require(
        key,
        value,
        value.is_finite() && value >= 0.0,
        "finite and >= 0",
    )
}

/// `kinematics.<key>` must be +1 or -1.
pub(crate) fn sign(key: &str, value: f64) -> Result<()> {
    require(key, value, value == 1.0 || value == -1.0, "+1 or -1")
}
