//! Warnings for unknown keys that look like misspellings of known ones.
//!
//! The format allows unknown keys (extensions), so they are never refused; but an optional key
//! misspelt is silently absent: `"weigths"` makes a circle a non-rational spline, `"Surface"`
//! cuts with a vertical beam. An unknown key is reported when it is a near miss of a key kerf
//! reads at the same place: the same ignoring case, or within edit distance 2 (1 for keys of
//! four letters or fewer, where 2 edits turn most short words into each other). A key that
//! resembles one also present in the same object is taken for a deliberate extension.

use std::fmt;

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

/// An unknown key that looks like a misspelling of a known one: a warning, not an error (the
/// document is read as written, without the key). Displays as
/// `curves[0].weigths: unknown key, did you mean "weights"?`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct UnknownKey {
    /// JSON path of the key (`curves[0].weigths`); control characters in the key are escaped.
    pub path: String,
    /// The known key it resembles.
    pub resembles: &'static str,
}

impl fmt::Display for UnknownKey {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{}: unknown key, did you mean \"{}\"?",
            self.path, self.resembles
        )
    }
}

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
    check(doc, TOP, "", &mut out);
    let items = |key: &str| match doc.get(key) {
        Some(Value::Array(items)) => items.as_slice(),
        _ => &[],
    };
    for (k, curve) in items("curves").iter().enumerate() {
        if let Value::Object(map) = curve {
            check(map, CURVE, &format!("curves[{k}]."), &mut out);
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
        check(map, known, &format!("surfaces[{k}]."), &mut out);
    }
    out
}

fn check(
    map: &Map<String, Value>,
    known: &[&'static str],
    prefix: &str,
    out: &mut Vec<UnknownKey>,
) {
    for key in map.keys() {
        if known.contains(&key.as_str()) {
            continue;
        }
        if let Some(resembles) = resembled(key, known).filter(|k| !map.contains_key(*k)) {
            let shown: String = key.chars().flat_map(char::escape_debug).collect();
            out.push(UnknownKey {
                path: format!("{prefix}{shown}"),
                resembles,
            });
        }
    }
}

/// The known key `key` is a near miss of, the closest first.
fn resembled(key: &str, known: &[&'static str]) -> Option<&'static str> {
    if let Some(k) = known.iter().find(|k| k.eq_ignore_ascii_case(key)) {
        return Some(k);
    }
    known
        .iter()
        .filter_map(|&k| {
            let limit = if k.len() <= 4 { 1 } else { 2 };
            distance(key, k, limit).map(|d| (d, k))
        })
        .min_by_key(|&(d, _)| d)
        .map(|(_, k)| k)
}

/// The optimal-string-alignment distance between `a` and `b` (insertions, deletions,
/// substitutions and swaps of two neighbours, each 1), or `None` if it exceeds `limit`.
/// Case is ignored.
fn distance(a: &str, b: &str, limit: usize) -> Option<usize> {
    let a: Vec<char> = a.chars().map(|c| c.to_ascii_lowercase()).collect();
    let b: Vec<char> = b.chars().map(|c| c.to_ascii_lowercase()).collect();
    if a.len().abs_diff(b.len()) > limit {
        return None;
    }
    // d[i][j]: the distance between a[..i] and b[..j].
    let mut d = vec![vec![0usize; b.len() + 1]; a.len() + 1];
    for (i, row) in d.iter_mut().enumerate() {
        row[0] = i;
    }
    for j in 0..=b.len() {
        d[0][j] = j;
    }
    for i in 1..=a.len() {
        for j in 1..=b.len() {
            let cost = usize::from(a[i - 1] != b[j - 1]);
            let mut v = (d[i - 1][j] + 1)
                .min(d[i][j - 1] + 1)
                .min(d[i - 1][j - 1] + cost);
            if i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1] {
                v = v.min(d[i - 2][j - 2] + 1);
            }
            d[i][j] = v;
        }
    }
    let v = d[a.len()][b.len()];
    (v <= limit).then_some(v)
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
    fn distance_counts_swaps_once_and_stops_at_the_limit() {
        assert_eq!(distance("weigths", "weights", 2), Some(1), "a swap");
        assert_eq!(distance("Surface", "surface", 2), Some(0), "case");
        assert_eq!(distance("knts", "knots", 2), Some(1), "a deletion");
        assert_eq!(distance("vendor_note", "knots", 2), None, "far");
        assert_eq!(distance("x", "id", 1), None, "short keys allow one edit");
        let shown = near_misses(&serde_json::from_str(r#"{"unit\ns": "mm"}"#).expect("JSON"));
        assert_eq!(shown[0].path, "unit\\ns", "a control character is escaped");
    }
}
