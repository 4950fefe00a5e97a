//! Writes a large seeded `kerf.curves/1` file for timing the CLI: `n` smooth random curves
//! (default 20,000) of about 200 mm each, 12 control points, clamped uniform knots.
//!
//! The degree is 3 by default; a third argument `LO-HI` (e.g. `2-7`) cycles the degrees
//! `LO, LO + 1, ..., HI, LO, ...` over the curves (the corpus of issue 15's benchmark,
//! `benches/discretize_vs_occt.py`).
//!
//! Run: `cargo run --release --example large_fixture -- 20000 /tmp/large.json`
//! or `cargo run --release --example large_fixture -- 5000 /tmp/mixed.json 2-7`

use std::fmt::Write as _;

fn main() {
    let mut args = std::env::args().skip(1);
    let n: usize = args.next().and_then(|s| s.parse().ok()).unwrap_or(20_000);
    let out = args.next().unwrap_or_else(|| "large.json".into());
    let (lo, hi) = match args.next() {
        None => (3, 3),
        Some(s) => {
            let parsed = s
                .split_once('-')
                .and_then(|(a, b)| Some((a.parse::<usize>().ok()?, b.parse::<usize>().ok()?)))
                .or_else(|| s.parse::<usize>().ok().map(|d| (d, d)));
            match parsed {
                Some((a, b)) if (1..=11).contains(&a) && a <= b && b <= 11 => (a, b),
                _ => {
                    eprintln!(
                        "large_fixture: degrees must be LO-HI with 1 <= LO <= HI <= 11, got {s:?}"
                    );
                    std::process::exit(2);
                }
            }
        }
    };
    let mut s = 0x9e37_79b9_7f4a_7c15u64;
    let mut rnd = move || {
        s = s
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (s >> 11) as f64 / (1u64 << 53) as f64
    };
    let mut text =
        String::from("{\"format\": \"kerf.curves/1\", \"units\": \"mm\", \"curves\": [\n");
    for c in 0..n {
        let m = 12;
        let p = lo + c % (hi - lo + 1);
        let pts: Vec<String> = (0..m)
            .map(|i| {
                format!(
                    "[{:.6}, {:.6}, {:.6}]",
                    20.0 * i as f64 + 10.0 * rnd(),
                    60.0 * rnd(),
                    20.0 * rnd()
                )
            })
            .collect();
        let mut knots = vec!["0".to_string(); p + 1];
        knots.extend((1..m - p).map(|i| format!("{:.6}", i as f64 / (m - p) as f64)));
        knots.extend(vec!["1".to_string(); p + 1]);
        let _ = write!(
            text,
            "{{\"id\": \"c{c}\", \"degree\": {p}, \"knots\": [{}], \"control_points\": [{}]}}{}",
            knots.join(", "),
            pts.join(", "),
            if c + 1 < n { ",\n" } else { "\n" }
        );
    }
    text.push_str("]}\n");
    std::fs::write(&out, text).expect("writes the file");
    eprintln!("wrote {n} curves (degrees {lo}-{hi}) to {out}");
}
