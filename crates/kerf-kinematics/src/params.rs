//! What a kinematic type's module needs from the machine reader: the [`KinematicsType`]
//! entry, the [`Params`] reader of a `kinematics` object and the checks of one parameter.
//! A leaf module: the registry imports the type modules, the type modules import this, so no
//! module imports one that imports it back.

use std::sync::Arc;

use serde_json::{Map, Value};

use crate::error::{KinematicsError, Result};
use crate::kinematics::Kinematics;
use kerf_io::json_type_name;

/// A kinematic type: its `kinematics.type` name and how to read its parameters.
pub(crate) struct KinematicsType {
    /// The `kinematics.type` value.
    pub(crate) name: &'static str,
    /// Reads the parameters (every key but `type`) and checks them.
    pub(crate) parse: fn(&mut Params<'_>) -> Result<Arc<dyn Kinematics>>,
}

/// The parameters of a `kinematics` object, read key by key; [`Params::finish`] refuses the
/// keys nobody asked for (a misspelt parameter is an error, not a silent default).
pub(crate) struct Params<'a> {
    map: &'a Map<String, Value>,
    type_name: &'static str,
    used: Vec<&'static str>,
}

impl<'a> Params<'a> {
    /// The parameters of the `kinematics` object `map` of type `type_name` (its `type` key
    /// already read).
    pub(crate) fn new(map: &'a Map<String, Value>, type_name: &'static str) -> Self {
        Self {
            map,
            type_name,
            used: vec!["type"],
        }
    }

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

    /// An optional number: `None` when the key is absent.
    pub(crate) fn optional_number(&mut self, key: &'static str) -> Result<Option<f64>> {
        if self.map.contains_key(key) {
            self.number(key).map(Some)
        } else {
            self.used.push(key);
            Ok(None)
        }
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
    pub(crate) fn finish(self) -> Result<()> {
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
