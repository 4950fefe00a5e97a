//! `kerf plot`: one SVG picture of a toolpath on its curves (four views, chord errors), and of
//! the machine axes when given. The drawing is the `kerf-plot` crate.

use std::path::{Path, PathBuf};

use clap::Args;
use kerf_format::{curves, toolpath, ToolpathFile, ToolpathPoints, ToolpathRecord};
use kerf_kinematics::AxesFile;
use kerf_plot::{render, write_svg, AxesChart, Scene, SceneOptions};

use crate::error::CliError;

/// Arguments of `kerf plot`.
#[derive(Debug, Args)]
pub(crate) struct PlotArgs {
    /// The kerf.curves/1 file.
    #[arg(value_name = "CURVES.json")]
    pub(crate) curves: PathBuf,

    /// The kerf.toolpath/1 file computed from it.
    #[arg(value_name = "TOOLPATH.json")]
    pub(crate) toolpath: PathBuf,

    /// A kerf.axes/1 file of the toolpath (from `kerf post`): adds a chart of the machine axes.
    #[arg(long, value_name = "AXES.json")]
    pub(crate) axes: Option<PathBuf>,

    /// The kerf.machine/1 file the axes were computed for: draws its axis limits.
    #[arg(short, long, value_name = "MACHINE.json", requires = "axes")]
    pub(crate) machine: Option<PathBuf>,

    /// Output SVG file (`-` for standard output). Default: `<toolpath stem>.svg` in the current
    /// directory.
    #[arg(short, long, value_name = "PLOT.svg")]
    pub(crate) output: Option<PathBuf>,

    /// Print no summary.
    #[arg(short, long)]
    pub(crate) quiet: bool,
}

/// Runs `kerf plot`.
pub(crate) fn run(args: &PlotArgs) -> Result<(), CliError> {
    let dest = args
        .output
        .clone()
        .unwrap_or_else(|| crate::input::default_output(&args.toolpath, "toolpath", "", ".svg"));
    let mut inputs = vec![args.curves.as_path(), args.toolpath.as_path()];
    inputs.extend(args.axes.as_deref());
    inputs.extend(args.machine.as_deref());
    crate::guard::refuse_overwrite("--output", &dest, &inputs)?;
    let curves_file = curves::load(&args.curves)?;
    crate::input::warn_unknown_keys(&args.curves, &curves_file);
    let tp = match toolpath::load(&args.toolpath) {
        Ok(tp) => tp,
        // A toolpath that breaks the format's rules (a chord error above the tolerance,
        // params out of order, ...) is still drawn if it has a usable shape: the picture is
        // how one looks at what is wrong.
        Err(strict) => {
            let loose = kerf_check::RawToolpath::load(&args.toolpath).ok();
            match loose.as_ref().and_then(drawable) {
                Some(tp) => {
                    eprintln!(
                        "warning: {strict}; drawing it anyway (`kerf check` lists every defect)"
                    );
                    tp
                }
                None => return Err(strict.into()),
            }
        }
    };
    let mut scene = Scene::new(&curves_file, &tp, &SceneOptions::default()).map_err(|e| {
        CliError::Plot(format!(
            "{} on {}: {e}",
            args.toolpath.display(),
            args.curves.display()
        ))
    })?;
    scene.title = format!("kerf plot \u{2014} {}", file_name(&args.toolpath));
    scene.subtitle = format!(
        "{} on {}: {}",
        args.toolpath.display(),
        args.curves.display(),
        scene.subtitle
    );
    if let Some(axes_path) = &args.axes {
        // The same front end as every reader: bounded, BOM skipped, duplicate keys refused.
        let axes = AxesFile::read(axes_path).map_err(|e| CliError::Plot(e.to_string()))?;
        let machine = args
            .machine
            .as_ref()
            .map(|m| crate::input::load_machine(m))
            .transpose()
            .map_err(|e| CliError::Plot(e.to_string()))?;
        let chart = AxesChart::new(&axes, machine.as_ref())
            .map_err(|e| CliError::Plot(format!("{}: {e}", axes_path.display())))?;
        scene.subtitle.push_str(&format!(
            "; axes {} ({})",
            axes_path.display(),
            axes.machine
        ));
        scene.axes = Some(chart);
    }
    let svg = render(&scene);
    write_svg(&dest, &svg)
        .map_err(|e| CliError::Plot(format!("{}: cannot write: {e}", dest.display())))?;
    if !args.quiet && dest != Path::new("-") {
        let points: usize = scene.paths.iter().map(|p| p.points.len()).sum();
        eprintln!(
            "{}: {} paths, {points} points{} -> {} ({} KiB)",
            args.toolpath.display(),
            scene.paths.len(),
            if scene.axes.is_some() {
                ", machine axes"
            } else {
                ""
            },
            dest.display(),
            svg.len().div_ceil(1024)
        );
    }
    Ok(())
}

/// A toolpath read leniently, as a [`ToolpathFile`] for drawing, if its points are all 3 or all
/// 6 numbers and its tolerance is positive.
fn drawable(loose: &kerf_check::RawToolpath) -> Option<ToolpathFile> {
    if !(loose.tolerance.is_finite() && loose.tolerance > 0.0) {
        return None;
    }
    let paths = loose
        .paths
        .iter()
        .map(|p| {
            let points = if p.points.iter().all(|q| q.len() == 3) {
                ToolpathPoints::Positions(p.points.iter().map(|q| [q[0], q[1], q[2]]).collect())
            } else if p.points.iter().all(|q| q.len() == 6) {
                ToolpathPoints::Poses(
                    p.points
                        .iter()
                        .map(|q| [q[0], q[1], q[2], q[3], q[4], q[5]])
                        .collect(),
                )
            } else {
                return None;
            };
            Some(ToolpathRecord {
                id: p.id.clone(),
                params: p.params.clone(),
                points,
                max_chord_error: p.claimed_chord_error.unwrap_or(0.0),
                kerf_offset: None,
            })
        })
        .collect::<Option<Vec<_>>>()?;
    Some(ToolpathFile {
        units: kerf_format::Units::Millimetres,
        tolerance: loose.tolerance,
        paths,
    })
}

/// The last component of `path`, for titles.
fn file_name(path: &Path) -> String {
    path.file_name().map_or_else(
        || path.display().to_string(),
        |s| s.to_string_lossy().into_owned(),
    )
}
