//! `kerf import`: a STEP or IGES file's cut contours and the faces they lie on, as
//! `kerf.curves/1`. Also the loader that lets `kerf run` take a CAD file directly.

use std::path::{Path, PathBuf};
use std::time::Instant;

use clap::Args;
use kerf_format::{curves, CurvesFile};
use kerf_step::{Import, ImportOptions};
use serde_json::json;

use crate::error::CliError;

/// How contours and faces are taken from a STEP file (shared by `kerf import` and `kerf run`).
#[derive(Debug, Clone, Args)]
pub(crate) struct StepArgs {
    /// STEP: cut the boundary loops of faces (sheet-metal holes and outlines) instead of the
    /// curves of the geometric sets.
    #[arg(long)]
    pub(crate) edges: bool,

    /// STEP, with --edges: only these faces, by entity number (`--faces 120,#388`).
    #[arg(long, value_delimiter = ',', value_name = "ID,...", requires = "edges")]
    pub(crate) faces: Vec<String>,

    /// STEP: close gaps between a contour's segments up to this (mm, 0 to 10) by moving the
    /// shared pole; larger gaps open the contour.
    #[arg(long, default_value_t = 0.1, value_name = "MM", value_parser = crate::guard::close_gaps_mm)]
    pub(crate) close_gaps: f64,

    /// STEP: a contour lies on the faces within this distance (mm, > 0, at most 10) of every
    /// dense sample.
    #[arg(long, default_value_t = 0.01, value_name = "MM", value_parser = crate::guard::face_tolerance_mm)]
    pub(crate) face_tolerance: f64,

    /// STEP: write every face read as a surface, not only those a contour lies on.
    #[arg(long)]
    pub(crate) all_faces: bool,

    /// STEP, with --edges: cut every face loop, even where the faces form one sheet (by
    /// default a sheet-metal solid's through-features are cut once each, on one side).
    #[arg(long, requires = "edges")]
    pub(crate) every_face_loop: bool,
}

/// Arguments of `kerf import`.
#[derive(Debug, Args)]
pub(crate) struct ImportArgs {
    /// The CAD file: STEP (AP203, AP214, AP242; .step, .stp) or IGES (5.x; .igs, .iges).
    #[arg(value_name = "PART.step")]
    pub(crate) step: PathBuf,

    /// Output kerf.curves/1 file (`-` for standard output). Default: `<input stem>.curves.json`
    /// in the current directory.
    #[arg(short, long, value_name = "CURVES.json")]
    pub(crate) output: Option<PathBuf>,

    /// How contours and faces are taken.
    #[command(flatten)]
    pub(crate) step_args: StepArgs,

    /// Print the summary as JSON on standard output.
    #[arg(long)]
    pub(crate) json: bool,

    /// Print no summary.
    #[arg(short, long)]
    pub(crate) quiet: bool,
}

/// Whether `path` names a CAD file, STEP or IGES (by its extension).
pub(crate) fn is_cad(path: &Path) -> bool {
    kerf_pipeline::is_iges(path)
        || path
            .extension()
            .and_then(|e| e.to_str())
            .is_some_and(|e| matches!(e.to_ascii_lowercase().as_str(), "step" | "stp" | "p21"))
}

/// The import options the arguments ask for. The numbers were checked by their parsers
/// (`crate::guard`: a usage error, exit 2, before the file is read); a defensive check here
/// keeps a `StepArgs` built otherwise to the same ranges.
pub(crate) fn options(a: &StepArgs) -> Result<ImportOptions, CliError> {
    for (option, range, v) in [
        ("--close-gaps", crate::guard::CLOSE_GAPS_MM, a.close_gaps),
        (
            "--face-tolerance",
            crate::guard::FACE_TOLERANCE_MM,
            a.face_tolerance,
        ),
    ] {
        if !range.contains(v) {
            return Err(CliError::Usage(format!(
                "invalid value for {option}: {}",
                range.refusal(v)
            )));
        }
    }
    let mut o = ImportOptions::default()
        .with_close_gaps_mm(a.close_gaps)
        .with_face_tolerance_mm(a.face_tolerance)
        .with_all_faces(a.all_faces)
        .with_sheet(!a.every_face_loop);
    if a.edges {
        let ids = a
            .faces
            .iter()
            .map(|s| {
                s.trim()
                    .trim_start_matches('#')
                    .parse::<u64>()
                    .map_err(|_| {
                        CliError::Usage(format!(
                            "--faces: {s:?} is not an entity number like 120 or #120"
                        ))
                    })
            })
            .collect::<Result<Vec<_>, _>>()?;
        o = o.with_edges((!ids.is_empty()).then_some(ids));
    }
    Ok(o)
}

/// Reads a STEP or IGES file (by its extension) into a checked curves file (and the import's
/// account).
pub(crate) fn load_step(path: &Path, a: &StepArgs) -> Result<(CurvesFile, Import), CliError> {
    let opts = options(a)?;
    let import = if kerf_pipeline::is_iges(path) {
        kerf_iges::import_file(path, &opts)
            .map_err(|e| CliError::Input(crate::error::with_flags(e.to_string())))?
    } else {
        kerf_step::import_file(path, &opts)
            .map_err(|e| CliError::Input(crate::error::with_flags(e.to_string())))?
    };
    let file = import.to_curves().map_err(|e| {
        CliError::Input(format!(
            "{}: the import is not valid kerf.curves/1: {e}",
            path.display()
        ))
    })?;
    Ok((file, import))
}

/// Prints what an import took and skipped (`file`: the curves it gave), to standard error.
pub(crate) fn print_account(path: &Path, r: &kerf_step::Report, file: &CurvesFile) {
    eprintln!(
        "{}: {} ({}; lengths x{} to mm): {} contours on {} faces ({} faces read)",
        path.display(),
        r.schemas.join(", "),
        r.units.length_name,
        r.units.mm_per_length,
        file.curves.len(),
        file.surfaces.len(),
        r.faces_read
    );
    if let Some(u) = r.uncertainty_mm {
        // Six significant digits: an inch file's 3.937e-9 inch is 1.00000054e-7 mm.
        let sig6 = |x: f64| format!("{x:.5e}").parse::<f64>().unwrap_or(x);
        eprintln!(
            "  the file's length tolerance: {} mm (face-loop contours may lie up to {} mm from their faces)",
            sig6(u),
            sig6(u.min(kerf_format::MAX_CURVE_ON_SURFACE_TOLERANCE_MM))
        );
    }
    if let Some(s) = &r.sheet {
        match &s.not_a_sheet {
            Some(why) => eprintln!("  not one sheet ({why}): every face loop is cut"),
            None => {
                eprintln!(
                    "  one sheet {:.3} mm thick: {} features, each cut once on the side of faces {} (or on the other side where that side faces down: {} faces; {} walls not cut)",
                    s.thickness_mm,
                    s.features.len(),
                    ids(s.id_prefix, &s.side),
                    s.other_side.len(),
                    s.walls.len()
                );
                for f in &s.features {
                    eprintln!("  {f}");
                }
            }
        }
    }
    for t in &r.taken {
        eprintln!("  took {t}");
    }
    for s in &r.surfaces {
        eprintln!("  surface {s}");
    }
    if r.gaps_closed > 0 {
        eprintln!(
            "  closed {} gaps between segments, largest pole move {:.3e} mm",
            r.gaps_closed, r.largest_move
        );
    }
    for o in &r.opened {
        eprintln!("  opened {o}");
    }
    for w in &r.warnings {
        eprintln!("  warning: {w}");
    }
    for s in &r.skipped {
        eprintln!("  skipped {s}");
    }
}

/// Face ids as `#1, #2, ...`.
fn ids(prefix: &str, v: &[u64]) -> String {
    v.iter()
        .map(|i| format!("{prefix}{i}"))
        .collect::<Vec<_>>()
        .join(", ")
}

/// `kerf import --json`'s `sheet`: what sheet recognition found, or why the faces are not one
/// sheet; `null` when it did not run.
fn sheet_json(s: Option<&kerf_step::SheetReport>) -> serde_json::Value {
    match s {
        None => serde_json::Value::Null,
        Some(s) => json!({
            "not_a_sheet": s.not_a_sheet,
            "thickness_mm": s.thickness_mm,
            "side": s.side,
            "other_side": s.other_side,
            "walls": s.walls,
            "features": s.features,
        }),
    }
}

/// Runs `kerf import`.
pub(crate) fn run(args: &ImportArgs) -> Result<(), CliError> {
    let start = Instant::now();
    let (file, import) = load_step(&args.step, &args.step_args)?;
    let dest = args
        .output
        .clone()
        .unwrap_or_else(|| crate::input::default_output(&args.step, "part", "", ".curves.json"));
    curves::write_raw(&import.file, &dest)?;
    let r = &import.report;
    if args.json {
        let summary = json!({
            "file": args.step.display().to_string(),
            "output": dest.display().to_string(),
            "schemas": r.schemas,
            "length_unit": r.units.length_name,
            "mm_per_length_unit": r.units.mm_per_length,
            "rad_per_angle_unit": r.units.rad_per_angle,
            "uncertainty_mm": r.uncertainty_mm,
            "curves": import.file.curves.len(),
            "surfaces": import.file.surfaces.len(),
            "faces_read": r.faces_read,
            "taken": r.taken,
            "skipped": r.skipped,
            "warnings": r.warnings,
            "gaps_closed": r.gaps_closed,
            "largest_pole_move_mm": r.largest_move,
        "opened": r.opened,
            "sheet": sheet_json(r.sheet.as_ref()),
            "approximated": r.approximated.iter().map(|(id, a)| json!({
                "id": id,
                "position_mm": a.position_mm,
                "normal_rad": a.normal_rad,
            })).collect::<Vec<_>>(),
            "seconds": start.elapsed().as_secs_f64(),
        });
        crate::input::print_summary(&summary, Some(&dest));
    } else if !args.quiet {
        print_account(&args.step, &import.report, &file);
        eprintln!(
            "wrote {} in {:.3} s",
            dest.display(),
            start.elapsed().as_secs_f64()
        );
    }
    Ok(())
}
