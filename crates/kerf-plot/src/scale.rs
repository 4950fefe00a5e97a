//! Axis ticks and the chord-error colour scale.

/// Round tick values covering `[lo, hi]`, about `target` of them, and the step between them.
pub(crate) fn ticks(lo: f64, hi: f64, target: usize) -> (Vec<f64>, f64) {
    if !(lo.is_finite() && hi.is_finite()) || hi <= lo {
        return (vec![if lo.is_finite() { lo } else { 0.0 }], 1.0);
    }
    let raw = (hi - lo) / target.max(1) as f64;
    let mag = 10f64.powf(raw.log10().floor());
    let norm = raw / mag;
    let step = mag
        * if norm <= 1.0 {
            1.0
        } else if norm <= 2.0 {
            2.0
        } else if norm <= 2.5 {
            2.5
        } else if norm <= 5.0 {
            5.0
        } else {
            10.0
        };
    let first = (lo / step).ceil();
    let last = (hi / step).floor();
    let mut out = Vec::new();
    let mut k = first;
    while k <= last && out.len() < 100 {
        // Avoid -0 and accumulated drift: each tick is an integer multiple of the step.
        let v = k * step;
        out.push(if v == 0.0 { 0.0 } else { v });
        k += 1.0;
    }
    (out, step)
}

/// A tick label: as many decimals as the step needs, or scientific notation for very small
/// or very large values.
pub(crate) fn tick_label(value: f64, step: f64) -> String {
    if value == 0.0 {
        return "0".into();
    }
    let a = value.abs().max(step.abs());
    if !(1e-4..1e6).contains(&a) {
        let digits = ((a.log10().floor() - step.abs().log10().floor()).max(0.0) as usize).min(6);
        return format!("{value:.digits$e}");
    }
    let decimals = (-(step.abs().log10()).floor()).max(0.0) as usize;
    // 2.5, 0.25, ... need one decimal more than their magnitude says.
    let scaled = step / 10f64.powi(-(decimals as i32));
    let extra = usize::from((scaled - scaled.round()).abs() > 1e-9);
    format!("{value:.prec$}", prec = (decimals + extra).min(12))
}

/// `x` with `digits` significant digits, trailing zeros dropped (`0.5`, `0.6372`, `1.2e-7`).
pub(crate) fn significant(x: f64, digits: usize) -> String {
    if x == 0.0 || !x.is_finite() {
        return if x.is_finite() {
            "0".into()
        } else {
            x.to_string()
        };
    }
    let mag = x.abs().log10().floor();
    if !(-4.0..6.0).contains(&mag) {
        return format!("{x:.prec$e}", prec = digits.saturating_sub(1));
    }
    let decimals = (digits as f64 - 1.0 - mag).max(0.0) as usize;
    let s = format!("{x:.decimals$}");
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_owned()
    } else {
        s
    }
}

/// The viridis colour map, truncated before its palest yellow so that thin lines stay visible
/// on white: stops at 0, 0.25, 0.5, 0.75, 1.
const STOPS: [(f64, [u8; 3]); 5] = [
    (0.0, [0x44, 0x01, 0x54]),
    (0.25, [0x3b, 0x52, 0x8b]),
    (0.5, [0x21, 0x91, 0x8c]),
    (0.75, [0x5e, 0xc9, 0x62]),
    (1.0, [0xc2, 0xdf, 0x23]),
];

/// The colour of segments whose chord error exceeds the tolerance.
pub(crate) const ABOVE_TOLERANCE: &str = "#e4001b";

/// The colour of a chord error `ratio` = error / tolerance: viridis from 0 to 1, red above 1.
pub(crate) fn error_colour(ratio: f64) -> String {
    if ratio > 1.0 {
        return ABOVE_TOLERANCE.to_owned();
    }
    let r = if ratio.is_finite() {
        ratio.max(0.0)
    } else {
        0.0
    };
    let mut k = 0;
    while k + 2 < STOPS.len() && r > STOPS[k + 1].0 {
        k += 1;
    }
    let (a, ca) = STOPS[k];
    let (b, cb) = STOPS[k + 1];
    let s = ((r - a) / (b - a)).clamp(0.0, 1.0);
    let mix =
        |i: usize| (f64::from(ca[i]) + s * (f64::from(cb[i]) - f64::from(ca[i]))).round() as u8;
    format!("#{:02x}{:02x}{:02x}", mix(0), mix(1), mix(2))
}

/// The gradient stops of [`error_colour`] for an SVG `linearGradient`.
pub(crate) fn gradient_stops() -> String {
    STOPS
        .iter()
        .map(|(o, c)| {
            format!(
                "<stop offset=\"{}\" stop-color=\"#{:02x}{:02x}{:02x}\"/>",
                o, c[0], c[1], c[2]
            )
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ticks_are_round() {
        let (t, step) = ticks(0.0, 0.0107, 5);
        assert_eq!(step, 0.0025, "{t:?}");
        assert_eq!(t.len(), 5, "{t:?}");
        assert_eq!(
            tick_label(t[1], step),
            "0.0025",
            "a 2.5 step keeps its digit"
        );
        let (t, step) = ticks(-37.0, 112.0, 6);
        assert_eq!(step, 25.0, "{t:?}");
        assert_eq!(t[0], -25.0, "first inside");
        assert_eq!(tick_label(t[0], step), "-25", "integers");
        assert_eq!(ticks(1.0, 1.0, 5).0, vec![1.0], "degenerate range");
        assert_eq!(ticks(f64::NAN, 1.0, 5).0, vec![0.0], "NaN");
        assert_eq!(
            tick_label(2e-6, 1e-6),
            "2e-6",
            "tiny values in scientific notation"
        );
    }

    #[test]
    fn colours_run_from_purple_to_yellow_then_red() {
        assert_eq!(error_colour(0.0), "#440154", "start");
        assert_eq!(error_colour(1.0), "#c2df23", "end");
        assert_eq!(error_colour(1.01), ABOVE_TOLERANCE, "above");
        assert_eq!(error_colour(f64::NAN), "#440154", "NaN");
        assert_eq!(error_colour(0.5), "#21918c", "middle stop");
    }
}
