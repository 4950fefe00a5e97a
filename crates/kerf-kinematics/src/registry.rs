//! The registry of kinematic types: `kinematics.type` name to parser.
//!
//! Adding a fifth type is one new file (a struct implementing [`crate::Kinematics`] and a
//! `TYPE` constant, see `ac_head.rs`) and one line in [`TYPES`].

use std::sync::Arc;

use serde_json::Value;

use crate::error::{KinematicsError, Result};
use crate::kinematics::Kinematics;
use crate::params::{KinematicsType, Params};
use crate::{ac_head, fork_head, head_table, table_table};
use kerf_io::json_type_name;

/// Every known kinematic type, in the order of `docs/formats.md`.
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
    let mut params = Params::new(map, kind.name);
    let kinematics = (kind.parse)(&mut params)?;
    params.finish()?;
    Ok(kinematics)
}
