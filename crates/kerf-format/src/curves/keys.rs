//! Warnings for unknown keys that look like misspellings of known ones: the keys `kerf.curves/1`
//! reads at each place, for [`kerf_io::near_misses_in`] (the rule is there). A misspelt optional
//! key is silently absent otherwise: `"weigths"` makes a circle a non-rational spline,
//! `"Surface"` cuts with a vertical beam.

use kerf_io::near_misses_in;
use serde_json::{Map, Value};

use crate::error::FormatError;

/// The keys of the document's top level.
const TOP: &[&str] = &["format", "units", "curves", "surfaces"];
/// The keys of one entry of `curves`.
const CURVE: &[&str] = &[
    "id",
    "degree",
    "knots",
    "control_points",
    "weights",
    "surface",
    "start",
    "scrap",
    "on_surface_tolerance_mm",
    "sheet_thickness_mm",
];
/// The keys of a `"type": "nurbs"` surface.
const NURBS: &[&str] = &[
    "id",
    "type",
    "degree_u",
    "degree_v",
    "knots_u",
    "knots_v",
    "control_points",
    "weights",
    "flip",
];
/// The keys of a `"type": "mesh"` surface.
const MESH: &[&str] = &["id", "type", "vertices", "triangles", "flip"];
/// The keys of a `"type": "stl"` surface.
const STL: &[&str] = &["id", "type", "path", "flip"];

pub use kerf_io::UnknownKey;

/// A missing required key whose object holds a near miss of it (`knot` for `knots`) says so:
/// `curves[0].knots: required key is missing (the object has "knot": a misspelling of it?)`.
/// Any other error is returned as it is.
pub(super) fn name_the_misspelling(error: FormatError, near: &[UnknownKey]) -> FormatError {
    let FormatError::Shape { path, message } = error else {
        return error;
    };
    let (parent, field) = match path.rsplit_once('.') {
        Some((parent, field)) => (format!("{parent}."), field),
        None => (String::new(), path.as_str()),
    };
    let found = (message == MISSING)
        .then(|| {
            near.iter().find_map(|w| {
                w.path
                    .strip_prefix(&parent)
                    .filter(|_| w.resembles == field)
            })
        })
        .flatten();
    let message = match found {
        Some(key) => format!("{MISSING} (the object has \"{key}\": a misspelling of it?)"),
        None => message,
    };
    FormatError::Shape { path, message }
}

/// The message of a missing required key (`kerf_io::deserialize_at`'s wording).
const MISSING: &str = "required key is missing";

/// The near-miss keys of a parsed `kerf.curves/1` document, in document order.
pub(super) fn near_misses(doc: &Map<String, Value>) -> Vec<UnknownKey> {
    let mut out = Vec::new();
    near_misses_in(doc, TOP, "", &mut out);
    let items = |key: &str| match doc.get(key) {
        Some(Value::Array(items)) => items.as_slice(),
        _ => &[],
    };
    for (k, curve) in items("curves").iter().enumerate() {
        if let Value::Object(map) = curve {
            near_misses_in(map, CURVE, &format!("curves[{k}]."), &mut out);
        }
    }
    for (k, surface) in items("surfaces").iter().enumerate() {
        let Value::Object(map) = surface else {
            continue;
        };
        let known = match map.get("type").and_then(Value::as_str) {
            Some("nurbs") => NURBS,
            Some("mesh") => MESH,
            Some("stl") => STL,
            _ => continue,
        };
        near_misses_in(map, known, &format!("surfaces[{k}]."), &mut out);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn near_misses_are_found_and_extensions_left_alone() {
        let doc: Map<String, Value> = serde_json::from_str(
            r#"{"format": "kerf.curves/1", "Units": "mm", "comment": "x",
                "curves": [{"id": "a", "weigths": [], "Surface": "s", "strat": 0,
                            "control-points": [], "vendor_note": 1, "idx": 2},
                           {"id": "b", "weights": [], "weight": []}],
                "surfaces": [{"id": "s", "type": "stl", "pth": "x.stl", "flipp": true},
                             {"id": "t", "type": "other", "pth": 1}]}"#,
        )
        .expect("JSON");
        let mut found: Vec<String> = near_misses(&doc).iter().map(ToString::to_string).collect();
        found.sort();
        assert_eq!(
            found,
            [
                "Units: unknown key, did you mean \"units\"?",
                "curves[0].Surface: unknown key, did you mean \"surface\"?",
                "curves[0].control-points: unknown key, did you mean \"control_points\"?",
                "curves[0].strat: unknown key, did you mean \"start\"?",
                "curves[0].weigths: unknown key, did you mean \"weights\"?",
                "surfaces[0].flipp: unknown key, did you mean \"flip\"?",
                "surfaces[0].pth: unknown key, did you mean \"path\"?",
            ],
            "the near misses, sorted (idx and weight resemble keys present beside them)"
        );
    }

    #[test]
    fn control_characters_in_a_key_are_escaped() {
        let shown = near_misses(&serde_json::from_str(r#"{"unit\ns": "mm"}"#).expect("JSON"));
        assert_eq!(shown[0].path, "unit\\ns", "a control character is escaped");
    }
}
