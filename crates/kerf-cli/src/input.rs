//! Reading the command's inputs (a file or standard input) and showing progress on a
//! terminal.

use std::io;
use std::path::{Path, PathBuf};

use kerf_format::{curves, CurvesFile};
use kerf_kinematics::{KinematicsError, Machine};
use kerf_pipeline::{Progress, Stage};

use crate::error::CliError;

/// Prints a command's `--json` summary: on standard output, unless the command's own output
/// `dest` goes there (`-`), then on standard error.
pub(crate) fn print_summary(summary: &impl std::fmt::Display, dest: Option<&Path>) {
    if dest.is_some_and(|d| d == Path::new("-")) {
        eprintln!("{summary}");
    } else {
        println!("{summary}");
    }
}

/// A command's default output, in the working directory (the input's folder may be
/// read-only): the input's file stem (`fallback` where it has none) less a trailing `strip`,
/// then `ext` (`dir/part.toolpath.json` to `part.axes.json` for `kerf post`).
pub(crate) fn default_output(input: &Path, fallback: &str, strip: &str, ext: &str) -> PathBuf {
    let stem = input.file_stem().map_or_else(
        || fallback.to_string(),
        |s| s.to_string_lossy().into_owned(),
    );
    let stem = stem
        .strip_suffix(strip)
        .filter(|_| !strip.is_empty())
        .unwrap_or(&stem);
    format!("{stem}{ext}").into()
}

/// Loads a curves file, or standard input for `-`, and prints its near-miss keys as warnings
/// ([`warn_unknown_keys`]).
pub(crate) fn load_curves(path: &Path) -> Result<CurvesFile, CliError> {
    let loaded = if path == Path::new("-") {
        curves::from_reader(io::stdin().lock(), Path::new(".")).map_err(|e| e.in_file("<stdin>"))
    } else {
        curves::load(path)
    }?;
    warn_unknown_keys(path, &loaded);
    Ok(loaded)
}

/// Prints the file's misspelt-looking keys on standard error, `warning: part.json:
/// curves[0].weigths: unknown key, did you mean "weights"?`. Also under `--quiet`: the document
/// was read without the key, which changes the result, and `--quiet` silences progress and
/// summaries, not defects of the input.
pub(crate) fn warn_unknown_keys(path: &Path, file: &CurvesFile) {
    for w in &file.warnings {
        eprintln!("warning: {}: {w}", path.display());
    }
}

/// Reads a machine file and prints its near-miss keys as warnings, like [`warn_unknown_keys`]
/// (`warning: machine.json: max_jerks: unknown key, did you mean "max_jerk"?`).
pub(crate) fn load_machine(path: &Path) -> Result<Machine, KinematicsError> {
    let machine = Machine::read(path)?;
    for w in &machine.warnings {
        eprintln!("warning: {}: {w}", path.display());
    }
    Ok(machine)
}

/// The job's progress as a bar on standard error, for batches long enough to wait for and
/// only when standard error is a terminal (never in pipes, logs or CI): the per-curve stages
/// of `items` curves get a bar each.
pub(crate) struct ProgressBar {
    bar: Option<indicatif::ProgressBar>,
}

impl ProgressBar {
    /// A bar for a job on `items` curves (hidden unless it is worth showing).
    pub(crate) fn new(items: usize) -> Self {
        use std::io::IsTerminal;
        let show = items >= 200 && io::stderr().is_terminal();
        let bar = show.then(|| {
            let bar = indicatif::ProgressBar::new(items as u64);
            if let Ok(style) = indicatif::ProgressStyle::with_template(
                "{msg} {bar:40} {pos}/{len} curves, {eta} left",
            ) {
                bar.set_style(style);
            }
            bar
        });
        Self { bar }
    }

    /// Shows `p`.
    pub(crate) fn update(&self, p: Progress) {
        let Some(bar) = &self.bar else { return };
        match p.stage {
            Stage::Discretize | Stage::Normals => {
                if p.done == 0 {
                    bar.reset();
                    bar.set_length(p.total as u64);
                    bar.set_message(if p.stage == Stage::Discretize {
                        "discretizing"
                    } else {
                        "normals"
                    });
                }
                bar.set_position(p.done as u64);
            }
            _ => bar.finish_and_clear(),
        }
    }

    /// Removes the bar.
    pub(crate) fn finish(&self) {
        if let Some(bar) = &self.bar {
            bar.finish_and_clear();
        }
    }
}
