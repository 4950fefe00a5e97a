//! `kerf check`: an independent verification of a `kerf.toolpath/1` file (from kerf or any
//! other tool) against the curves it claims to discretize. The checking itself is the
//! `kerf-check` crate; this module reads the files and prints the report.

use std::collections::HashMap;
use std::io::{self, Write};
use std::path::{Path, PathBuf};

use clap::Args;
use kerf_check::{check, CheckOptions, RawToolpath, Report, Violation};

use crate::error::CliError;

/// Violations listed in the text report; `--json` lists all.
const MAX_LISTED: usize = 50;

/// Violations of one kind on one path listed before the rest are summed up (reversed params
/// break every one of them).
const MAX_PER_KIND: usize = 3;

/// Arguments of `kerf check`.
#[derive(Debug, Args)]
pub(crate) struct CheckArgs {
    /// The kerf.curves/1 file the toolpath claims to discretize; `-` reads standard input.
    #[arg(value_name = "CURVES.json")]
    pub(crate) curves: PathBuf,

    /// The kerf.toolpath/1 file to verify; `-` reads standard input.
    #[arg(value_name = "TOOLPATH.json")]
    pub(crate) toolpath: PathBuf,

    /// Print the report as one JSON object on standard output (also on failure).
    #[arg(long)]
    pub(crate) json: bool,

    /// Samples per knot span in each segment before the local maxima are refined (default
    /// 32; at least 4 (degree + 1) are used).
    #[arg(long, value_name = "N", value_parser = crate::guard::samples)]
    pub(crate) samples: Option<usize>,
}

/// Runs `kerf check`: exit status 0 if every rule holds, 1 with the violations listed.
pub(crate) fn run(args: &CheckArgs) -> Result<(), CliError> {
    if args.curves == Path::new("-") && args.toolpath == Path::new("-") {
        return Err(CliError::Check(kerf_check::CheckError::Shape {
            path: "arguments".into(),
            message: "only one of CURVES.json and TOOLPATH.json can be `-` (standard input)".into(),
        }));
    }
    let curves = crate::input::load_curves(&args.curves)?;
    let toolpath = if args.toolpath == Path::new("-") {
        let bytes = kerf_io::read_to_end(io::stdin().lock(), kerf_io::MAX_INPUT_BYTES).map_err(
            |error| kerf_check::CheckError::Read {
                path: "<stdin>".into(),
                error,
            },
        )?;
        RawToolpath::from_slice(&bytes).map_err(|e| e.in_file("<stdin>"))?
    } else {
        RawToolpath::load(&args.toolpath)?
    };
    let defaults = CheckOptions::default();
    let opts = defaults.with_samples(args.samples.unwrap_or(defaults.samples));
    let report = check(&curves.curves, &toolpath, &opts);
    let stdout = io::stdout();
    let mut out = stdout.lock();
    if args.json {
        let mut json = report.to_json();
        if let serde_json::Value::Object(map) = &mut json {
            map.insert("curves".into(), args.curves.display().to_string().into());
            map.insert(
                "toolpath".into(),
                args.toolpath.display().to_string().into(),
            );
        }
        writeln!(out, "{json}")?;
    } else {
        print_text(&mut out, args, &report)?;
    }
    out.flush()?;
    if report.passed() {
        Ok(())
    } else {
        Err(CliError::CheckFailed {
            toolpath: args.toolpath.clone(),
            violations: report.violations.len(),
        })
    }
}

/// The human-readable report: a table of the paths, then the verdict or the violations.
fn print_text(out: &mut impl Write, args: &CheckArgs, report: &Report) -> io::Result<()> {
    writeln!(
        out,
        "{} against {}: tolerance {} mm, {} paths, {} segments measured",
        args.toolpath.display(),
        args.curves.display(),
        report.tolerance,
        report.paths.len(),
        report.segments()
    )?;
    let w = report
        .paths
        .iter()
        .map(|p| p.id.chars().count())
        .max()
        .unwrap_or(2)
        .clamp(2, 32);
    let worst: Vec<String> = report
        .paths
        .iter()
        .map(|p| {
            p.worst.map_or_else(
                || "-".to_owned(),
                |s| format!("{} ({:.6} .. {:.6})", s.segment, s.t0, s.t1),
            )
        })
        .collect();
    let heading = "worst segment (t0 .. t1)";
    let ww = worst
        .iter()
        .map(String::len)
        .chain([heading.len()])
        .max()
        .unwrap_or(0);
    writeln!(
        out,
        "  {:<w$}  {:>7}  {:>8}  {:>15}  {heading:<ww$}  claimed max_chord_error",
        "id", "points", "segments", "max chord error"
    )?;
    for (p, worst) in report.paths.iter().zip(&worst) {
        let claim = match (p.claimed, p.claim_holds) {
            (Some(c), Some(true)) => format!("{c:.4e} mm >= measured: ok"),
            (Some(c), Some(false)) => format!("{c:.4e} mm < measured: UNDERSTATED"),
            (Some(c), None) => format!("{c:.4e} mm (not measured)"),
            (None, _) => "missing".to_owned(),
        };
        let error = if p.measured {
            format!("{:.4e} mm", p.measured_chord_error)
        } else {
            "not measured".to_owned()
        };
        writeln!(
            out,
            "  {:<w$}  {:>7}  {:>8}  {:>15}  {:<ww$}  {claim}",
            p.id, p.points, p.segments, error, worst
        )?;
        if let Some(o) = &p.kerf_offset {
            writeln!(
                out,
                "  {:<w$}  kerf_offset {} mm: {} points, {} chords within {:.4e} mm of the exact offset, {} cut back at inside corners, at least {:.4} mm from the curve",
                "", o.offset_mm, o.points, o.segments, o.max_chord_error, o.cut_backs, o.min_distance_from_curve
            )?;
        }
    }
    if report.passed() {
        writeln!(
            out,
            "passed: every segment's chord error <= {} mm (largest measured {:.4e} mm), every \
             point on its curve at its param, every C0 corner a cutting point, every claim holds{}",
            report.tolerance,
            report.measured_chord_error(),
            if report.paths.iter().any(|p| p.kerf_offset.is_some()) {
                "; every kerf offset within the tolerance of the exact offset, never nearer the curve than the offset less the tolerance"
            } else {
                ""
            }
        )?;
        return Ok(());
    }
    writeln!(out, "FAILED: {} violations", report.violations.len())?;
    let key = |v: &Violation| (v.path, std::mem::discriminant(&v.defect));
    let mut totals = HashMap::new();
    for v in &report.violations {
        *totals.entry(key(v)).or_insert(0usize) += 1;
    }
    let mut seen = HashMap::new();
    let mut listed = 0;
    for v in &report.violations {
        let n = seen.entry(key(v)).or_insert(0usize);
        *n += 1;
        if *n > MAX_PER_KIND {
            continue;
        }
        if listed == MAX_LISTED {
            writeln!(out, "  ... (more; --json lists every violation)")?;
            break;
        }
        writeln!(out, "  {v}")?;
        listed += 1;
        let total = totals[&key(v)];
        if *n == MAX_PER_KIND && total > MAX_PER_KIND {
            writeln!(
                out,
                "  ... and {} more like this one (--json lists them all)",
                total - MAX_PER_KIND
            )?;
        }
    }
    Ok(())
}
