//! Bounded reads.

use std::io::{self, Read};
use std::path::Path;

/// The largest input kerf reads, in bytes (1 GiB). A file or stream that is longer is refused
/// with an error instead of being read without end (`/dev/zero`) or exhausting memory.
///
/// 1 GiB is far above any real cut-contour file: the large-file benchmark of
/// `docs/performance.md` (100,000 curves) is about 60 MB, and a binary STL of 10 million
/// triangles is 500 MB.
pub const MAX_INPUT_BYTES: u64 = 1 << 30;

/// Reads at most `limit` bytes of `reader` to its end.
///
/// # Errors
/// The reader's error, or an error of kind [`io::ErrorKind::FileTooLarge`] whose message gives
/// the limit in readable units if the input holds more than `limit` bytes.
pub fn read_to_end(reader: impl Read, limit: u64) -> io::Result<Vec<u8>> {
    let mut bytes = Vec::new();
    // One byte more than the limit tells "exactly the limit" from "longer".
    reader
        .take(limit.saturating_add(1))
        .read_to_end(&mut bytes)?;
    if bytes.len() as u64 > limit {
        return Err(too_large(limit));
    }
    Ok(bytes)
}

/// Reads the file at `path` (at most [`MAX_INPUT_BYTES`]).
///
/// A FIFO or a character device (`/dev/stdin`, a pipe made by `mkfifo`) is read like a file,
/// up to the limit.
///
/// # Errors
/// The operating system's error (missing file, a directory, no permission), or the error of
/// [`read_to_end`] for an input above the limit. The caller names the file.
pub fn read_file(path: &Path) -> io::Result<Vec<u8>> {
    let file = std::fs::File::open(path)?;
    let meta = file.metadata()?;
    if meta.is_dir() {
        return Err(io::Error::new(
            io::ErrorKind::IsADirectory,
            "is a directory, not a file",
        ));
    }
    if meta.is_file() && meta.len() > MAX_INPUT_BYTES {
        return Err(too_large(MAX_INPUT_BYTES));
    }
    read_to_end(file, MAX_INPUT_BYTES)
}

/// Reads the file at `path` like [`read_file`], but only if it is a regular file (a symbolic
/// link is followed): for files named *inside* a document (an STL surface's `path`), which the
/// user did not hand to kerf on the command line and which must not make kerf wait or read
/// without end. A FIFO is refused before it is opened (opening one blocks until a writer
/// comes: an STL path naming a FIFO hung forever before this check), a device without reading from it
/// (`/dev/zero` was read 1 GiB deep before the limit refused it). The file is opened
/// non-blocking and checked again, so one swapped for a FIFO in between cannot block either.
///
/// # Errors
/// An error of kind [`io::ErrorKind::InvalidInput`] naming what the path is (a FIFO, a
/// character device, ...) if it is not a regular file; else as [`read_file`].
pub fn read_regular_file(path: &Path) -> io::Result<Vec<u8>> {
    let not_regular = |meta: &std::fs::Metadata| -> io::Result<()> {
        if meta.is_file() {
            return Ok(());
        }
        Err(io::Error::new(
            io::ErrorKind::InvalidInput,
            format!(
                "is {}, not a regular file (a file named inside a document must be a regular file)",
                file_kind(meta)
            ),
        ))
    };
    not_regular(&std::fs::metadata(path)?)?;
    let mut options = std::fs::OpenOptions::new();
    options.read(true);
    #[cfg(unix)]
    {
        use std::os::unix::fs::OpenOptionsExt;
        options.custom_flags(libc::O_NONBLOCK);
    }
    let file = options.open(path)?;
    let meta = file.metadata()?;
    not_regular(&meta)?;
    if meta.len() > MAX_INPUT_BYTES {
        return Err(too_large(MAX_INPUT_BYTES));
    }
    read_to_end(file, MAX_INPUT_BYTES)
}

/// What a file that is not a regular file is, for messages: `a FIFO`, `a directory`, ...
fn file_kind(meta: &std::fs::Metadata) -> &'static str {
    let t = meta.file_type();
    if t.is_dir() {
        return "a directory";
    }
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if t.is_fifo() {
            return "a FIFO";
        }
        if t.is_char_device() {
            return "a character device";
        }
        if t.is_block_device() {
            return "a block device";
        }
        if t.is_socket() {
            return "a socket";
        }
    }
    "not a file"
}

/// `bytes` without a leading UTF-8 byte-order mark (`EF BB BF`). Editors on Windows like to
/// start UTF-8 files with one; JSON forbids it but it carries no information.
pub fn strip_bom(bytes: &[u8]) -> &[u8] {
    bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(bytes)
}

fn too_large(limit: u64) -> io::Error {
    io::Error::new(
        io::ErrorKind::FileTooLarge,
        format!(
            "the input is larger than {} (the input size limit of kerf, kerf_io::MAX_INPUT_BYTES)",
            readable_bytes(limit)
        ),
    )
}

/// `1073741824` as `1 GiB`, `1536` as `1.5 KiB`.
fn readable_bytes(n: u64) -> String {
    const UNITS: [&str; 4] = ["bytes", "KiB", "MiB", "GiB"];
    let mut value = n as f64;
    let mut unit = 0;
    while value >= 1024.0 && unit + 1 < UNITS.len() {
        value /= 1024.0;
        unit += 1;
    }
    if unit == 0 {
        format!("{n} bytes")
    } else {
        format!("{} {}", (value * 10.0).round() / 10.0, UNITS[unit])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn limit_is_exact() {
        assert_eq!(
            read_to_end(&[1u8; 10][..], 10).expect("at the limit").len(),
            10,
            "exactly the limit is read"
        );
        let e = read_to_end(&[1u8; 11][..], 10).expect_err("above the limit");
        assert_eq!(e.kind(), io::ErrorKind::FileTooLarge, "{e}");
        assert!(e.to_string().contains("10 bytes"), "{e}");
    }

    #[test]
    fn an_endless_stream_stops_at_the_limit() {
        // io::repeat never ends, like /dev/zero.
        let e = read_to_end(io::repeat(0), 1 << 20).expect_err("endless");
        assert!(e.to_string().contains("1 MiB"), "{e}");
    }

    #[test]
    fn readable_units() {
        assert_eq!(readable_bytes(MAX_INPUT_BYTES), "1 GiB", "limit");
        assert_eq!(readable_bytes(1536), "1.5 KiB", "fraction");
        assert_eq!(readable_bytes(12), "12 bytes", "small");
    }

    #[cfg(unix)]
    #[test]
    fn a_referenced_file_must_be_regular() {
        let dir = tempfile::tempdir().expect("temporary directory");
        let fifo = dir.path().join("fifo");
        let made = std::process::Command::new("mkfifo")
            .arg(&fifo)
            .status()
            .expect("mkfifo runs");
        assert!(made.success(), "mkfifo made {}", fifo.display());
        // No writer ever comes: reading the FIFO as a file would block in open() forever.
        let e = read_regular_file(&fifo).expect_err("a FIFO");
        assert_eq!(e.kind(), io::ErrorKind::InvalidInput, "{e}");
        assert!(
            e.to_string().contains("is a FIFO, not a regular file"),
            "{e}"
        );
        let e = read_regular_file(Path::new("/dev/zero")).expect_err("a device");
        assert!(e.to_string().contains("a character device"), "{e}");
        let e = read_regular_file(dir.path()).expect_err("a directory");
        assert!(e.to_string().contains("a directory"), "{e}");
        // A link to a regular file is followed.
        let file = dir.path().join("part.stl");
        std::fs::write(&file, b"solid x").expect("write");
        let link = dir.path().join("link.stl");
        std::os::unix::fs::symlink(&file, &link).expect("symlink");
        assert_eq!(
            read_regular_file(&link).expect("a link to a file"),
            b"solid x",
            "read"
        );
    }

    #[test]
    fn bom_is_stripped_once() {
        assert_eq!(strip_bom(b"\xEF\xBB\xBF{}"), b"{}", "one BOM");
        assert_eq!(strip_bom(b"{}"), b"{}", "none");
        assert_eq!(strip_bom(b"\xEF\xBB"), b"\xEF\xBB", "a partial BOM is kept");
    }
}
