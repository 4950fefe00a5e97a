//! The set-points CSV of `formats.md` and the atomic write of every output.

use std::borrow::Borrow;
use std::io::Write;
use std::path::Path;

use kerf_kinematics::Axes;

use crate::error::{positive, InterpError, Result};

/// The CSV text: header `t,<names>` and one row `t,q0,...,q4` per set-point, row `i` at
/// `t = i * cycle` seconds (written with 9 decimals). Builds the whole text in memory; for
/// long programs stream with [`write_csv_to`] or [`write_csv`].
pub fn csv_string(names: [&str; 5], cycle: f64, rows: &[Axes]) -> String {
    let mut bytes = Vec::with_capacity(rows.len() * 80 + 32);
    // Writing into a Vec cannot fail.
    let _ = write_csv_to(&mut bytes, names, cycle, rows);
    // Only ASCII digits, signs, dots, commas and the axis names: valid UTF-8.
    String::from_utf8_lossy(&bytes).into_owned()
}

/// Streams the CSV of [`csv_string`] into `w`, one row at a time: memory stays bounded however
/// many set-points `rows` yields (give it [`crate::Motion::iter`]).
///
/// # Errors
/// The writer's error.
pub fn write_csv_to<R: Borrow<Axes>>(
    w: &mut dyn Write,
    names: [&str; 5],
    cycle: f64,
    rows: impl IntoIterator<Item = R>,
) -> std::io::Result<()> {
    w.write_all(b"t")?;
    for n in names {
        write!(w, ",{n}")?;
    }
    w.write_all(b"\n")?;
    for (i, q) in rows.into_iter().enumerate() {
        write!(w, "{:.9}", i as f64 * cycle)?;
        for v in q.borrow().iter() {
            write!(w, ",{}", v + 0.0)?; // + 0.0 turns -0 into 0
        }
        w.write_all(b"\n")?;
    }
    Ok(())
}

/// Writes the CSV of [`csv_string`] to `path` (`-`: standard output) through
/// [`kerf_io::write_file`], streaming `rows` (memory stays bounded with
/// [`crate::Motion::iter`]): atomically onto a new path or a regular file, written through
/// to a device or FIFO.
///
/// # Errors
/// [`InterpError::Io`]; [`InterpError::BadParameter`] for a cycle that is not finite and > 0.
pub fn write_csv<R: Borrow<Axes>>(
    path: impl AsRef<Path>,
    names: [&str; 5],
    cycle: f64,
    rows: impl IntoIterator<Item = R>,
) -> Result<()> {
    positive("cycle", cycle)?;
    let path = path.as_ref();
    kerf_io::write_file(path, |w| write_csv_to(w, names, cycle, rows)).map_err(|e| {
        InterpError::Io {
            path: path.display().to_string(),
            source: e.into(),
        }
    })
}

/// Writes `bytes` to `path` through [`kerf_io::write_file`]: a temporary file in the same
/// directory renamed over `path` once complete (a reader never sees a half-written file), a
/// device or FIFO written through, a symbolic link's target written; new files get `0o666`
/// less the umask.
///
/// # Errors
/// [`InterpError::Io`] naming the path.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    kerf_io::write_file(path, |w| w.write_all(bytes)).map_err(|e| InterpError::Io {
        path: path.display().to_string(),
        source: e.into(),
    })
}
