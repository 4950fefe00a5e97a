//! Unknown keys that look like misspellings of known ones.
//!
//! kerf's formats allow unknown keys (extensions), so they are never refused; but an optional
//! key misspelt is silently absent: `"weigths"` makes a circle a non-rational spline,
//! `"max_jerks"` plans a machine without its jerk limits. An unknown key is reported when it
//! is a near miss of a key the reader reads at the same place: the same ignoring case, or
//! within edit distance 2 (1 for keys of four letters or fewer, where 2 edits turn most short
//! words into each other). A key that resembles one also present in the same object is taken
//! for a deliberate extension.

use std::fmt;

use serde_json::{Map, Value};

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

/// Appends to `out` the keys of `map` that are not in `known` but are near misses of a known
/// key that `map` does not hold, in the map's order, each path `prefix` followed by the key
/// (`prefix` is `""` at the top level, `"curves[0]."` inside an array entry).
pub fn near_misses_in(
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
    fn distance_counts_swaps_once_and_stops_at_the_limit() {
        assert_eq!(distance("weigths", "weights", 2), Some(1), "a swap");
        assert_eq!(distance("Surface", "surface", 2), Some(0), "case");
        assert_eq!(distance("knts", "knots", 2), Some(1), "a deletion");
        assert_eq!(distance("vendor_note", "knots", 2), None, "far");
        assert_eq!(distance("x", "id", 1), None, "short keys allow one edit");
    }

    #[test]
    fn a_near_miss_beside_its_key_is_an_extension() {
        let map: Map<String, Value> =
            serde_json::from_str(r#"{"max_jerks": 1, "limts": 2, "limits": 3, "vendor": 4}"#)
                .expect("JSON");
        let mut out = Vec::new();
        near_misses_in(&map, &["limits", "max_jerk"], "m.", &mut out);
        let shown: Vec<String> = out.iter().map(ToString::to_string).collect();
        assert_eq!(
            shown,
            ["m.max_jerks: unknown key, did you mean \"max_jerk\"?"]
        );
    }
}
