//! The optional `start` and `scrap` keys of `kerf.curves/1`: read, checked against the curve's
//! domain and closure, errors named by their JSON path.

use std::path::Path;

use kerf_format::{curves, ScrapSide};

/// A closed unit-square polygon (degree 1, domain [0, 4]) and an open line, with extra keys
/// spliced into the square (`square_extra`) and the line (`line_extra`).
fn doc(square_extra: &str, line_extra: &str) -> String {
    format!(
        r#"{{"format": "kerf.curves/1", "units": "mm", "curves": [
        {{"id": "line", "degree": 1, "knots": [0, 0, 1, 1],
          "control_points": [[0, 0, 0], [5, 0, 0]]{line_extra}}},
        {{"id": "square", "degree": 1, "knots": [0, 0, 1, 2, 3, 4, 4],
          "control_points": [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0, 0, 0]]{square_extra}}}
    ]}}"#
    )
}

fn read(text: &str) -> Result<curves::CurvesFile, String> {
    curves::from_str(text, Path::new(".")).map_err(|e| e.to_string())
}

#[test]
fn start_and_scrap_are_read_into_the_record() {
    let f = read(&doc(
        r#", "start": 2.5, "scrap": "left""#,
        r#", "scrap": "right""#,
    ))
    .expect("valid keys");
    assert_eq!(f.curves[1].start, Some(2.5), "the square's start parameter");
    assert_eq!(
        f.curves[1].scrap,
        Some(ScrapSide::Left),
        "the square's scrap side"
    );
    assert_eq!(f.curves[0].start, None, "no start on the line");
    assert_eq!(
        f.curves[0].scrap,
        Some(ScrapSide::Right),
        "an open curve may name its scrap"
    );
    let plain = read(&doc("", "")).expect("no keys");
    assert_eq!(
        (plain.curves[1].start, plain.curves[1].scrap),
        (None, None),
        "absent keys"
    );
}

#[test]
fn a_start_at_either_end_of_the_domain_is_accepted() {
    for t in ["0", "4"] {
        let f = read(&doc(&format!(r#", "start": {t}"#), "")).expect("domain ends");
        assert_eq!(f.curves[1].start, Some(t.parse().unwrap()), "start {t}");
    }
}

#[test]
fn a_start_outside_the_domain_is_named() {
    let e = read(&doc(r#", "start": 7.5"#, "")).unwrap_err();
    assert_eq!(
        e, "curves[1].start: 7.5 is outside the domain [0, 4]",
        "message"
    );
    let e = read(&doc(r#", "start": -0.25"#, "")).unwrap_err();
    assert_eq!(
        e, "curves[1].start: -0.25 is outside the domain [0, 4]",
        "message"
    );
}

#[test]
fn a_start_on_an_open_curve_is_refused() {
    let e = read(&doc("", r#", "start": 0.5"#)).unwrap_err();
    assert!(
        e.starts_with("curves[0].start: the curve is open (its ends are 5.000000 mm apart)"),
        "message: {e}"
    );
}

#[test]
fn a_bad_scrap_is_named() {
    let e = read(&doc(r#", "scrap": "Left""#, "")).unwrap_err();
    assert_eq!(
        e, r#"curves[1].scrap: expected "left" or "right", got "Left""#,
        "message"
    );
    // Text from the file is quoted as JSON in the message (a newline stays escaped).
    let e = read(&doc(r#", "scrap": "in\nside""#, "")).unwrap_err();
    assert!(e.ends_with(r#"got "in\nside""#), "escaped: {e}");
    let e = read(&doc(r#", "scrap": 1"#, "")).unwrap_err();
    assert!(
        e.starts_with("curves[1].scrap"),
        "wrong type named by path: {e}"
    );
    let e = read(&doc(r#", "start": "2""#, "")).unwrap_err();
    assert!(
        e.starts_with("curves[1].start"),
        "wrong type named by path: {e}"
    );
}

#[test]
fn the_keys_survive_a_raw_round_trip() {
    let raw = curves::raw_from_slice(doc(r#", "start": 1.5, "scrap": "right""#, "").as_bytes())
        .expect("raw");
    let text = serde_json::to_string(&raw).expect("serialise");
    let f = read(&text).expect("re-read");
    assert_eq!(f.curves[1].start, Some(1.5), "start kept");
    assert_eq!(f.curves[1].scrap, Some(ScrapSide::Right), "scrap kept");
    assert!(
        !text.contains("\"start\":null"),
        "absent keys are not written: {text}"
    );
}

#[test]
fn a_curves_own_on_surface_tolerance_is_read_checked_and_written_back() {
    let f = read(&doc(r#", "on_surface_tolerance_mm": 0.02"#, "")).expect("valid key");
    assert_eq!(f.curves[1].on_surface_tolerance_mm, Some(0.02));
    assert_eq!(f.curves[0].on_surface_tolerance_mm, None, "absent");
    let f = read(&doc(r#", "on_surface_tolerance_mm": 0.1"#, "")).expect("the largest");
    assert_eq!(f.curves[1].on_surface_tolerance_mm, Some(0.1));
    // Not a near miss: no warning for the key.
    assert!(f.warnings.is_empty(), "{:?}", f.warnings);
    for bad in ["0", "-0.01", "0.2", "1"] {
        let e =
            read(&doc(&format!(r#", "on_surface_tolerance_mm": {bad}"#), "")).expect_err("refused");
        assert!(
            e.contains("curves[1].on_surface_tolerance_mm")
                && e.contains("must be > 0 and at most 0.1 mm"),
            "{bad}: {e}"
        );
    }
    // The raw document keeps it: what `kerf import` writes, read back.
    let raw = curves::raw_from_slice(doc(r#", "on_surface_tolerance_mm": 0.02"#, "").as_bytes())
        .expect("raw");
    let text = serde_json::to_string(&raw).expect("JSON");
    assert!(text.contains(r#""on_surface_tolerance_mm":0.02"#), "{text}");
    assert_eq!(
        read(&text).expect("again").curves[1].on_surface_tolerance_mm,
        Some(0.02)
    );
}

#[test]
fn a_curves_sheet_thickness_is_read_checked_and_written_back() {
    let f = read(&doc(r#", "sheet_thickness_mm": 3"#, "")).expect("valid key");
    assert_eq!(f.curves[1].sheet_thickness_mm, Some(3.0));
    assert_eq!(f.curves[0].sheet_thickness_mm, None, "absent");
    assert!(f.warnings.is_empty(), "not a near miss: {:?}", f.warnings);
    for bad in ["0", "-2", "1000.5", "1e300"] {
        let e = read(&doc(&format!(r#", "sheet_thickness_mm": {bad}"#), "")).expect_err("refused");
        assert!(
            e.contains("curves[1].sheet_thickness_mm")
                && e.contains("must be > 0 and at most 1000 mm"),
            "{bad}: {e}"
        );
    }
    let raw =
        curves::raw_from_slice(doc(r#", "sheet_thickness_mm": 2.5"#, "").as_bytes()).expect("raw");
    let text = serde_json::to_string(&raw).expect("JSON");
    assert!(text.contains(r#""sheet_thickness_mm":2.5"#), "{text}");
    assert_eq!(
        read(&text).expect("again").curves[1].sheet_thickness_mm,
        Some(2.5)
    );
}
