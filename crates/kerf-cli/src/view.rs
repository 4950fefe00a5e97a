//! `kerf view`: the interactive 3D view of a `kerf run` output directory written again with
//! this version's viewer (`kerf-view`) and the directory's report warnings.

use crate::cli::ViewArgs;
use crate::error::CliError;

/// Runs `kerf view`.
pub(crate) fn run(args: &ViewArgs) -> Result<(), CliError> {
    let page_path = args.dir.join("view.html");
    let report_path = args.dir.join("report.json");
    let read = |p: &std::path::Path| {
        kerf_io::read_regular_file(p).map_err(|e| CliError::Input(format!("{}: {e}", p.display())))
    };
    let page = String::from_utf8(read(&page_path)?)
        .map_err(|_| CliError::Input(format!("{}: not UTF-8 text", page_path.display())))?;
    let mut scene = kerf_view::read_scene(&page)
        .map_err(|e| CliError::Input(format!("{}: {e}", page_path.display())))?;
    let report = kerf_io::parse_json(&read(&report_path)?)
        .map_err(|e| CliError::Input(format!("{}: {e}", report_path.display())))?;
    let warnings = report["warnings"].as_array().ok_or_else(|| {
        CliError::Input(format!(
            "{}: warnings: a list of the run's warnings expected",
            report_path.display()
        ))
    })?;
    scene["warnings"] = serde_json::to_value(
        warnings
            .iter()
            .filter_map(|w| w.as_str())
            .map(kerf_view::Warning::new)
            .collect::<Vec<_>>(),
    )
    .unwrap_or_default();
    let out = kerf_view::html_value(&scene);
    kerf_interp::write_atomic(&page_path, out.as_bytes())
        .map_err(|e| CliError::Input(format!("{}: {e}", page_path.display())))?;
    eprintln!("wrote {} ({} bytes)", page_path.display(), out.len());
    Ok(())
}
