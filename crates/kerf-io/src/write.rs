//! The one output writer: atomic where a rename is safe, written through where it is not.

use std::fmt;
use std::fs::{self, OpenOptions, Permissions};
use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};

/// Where the bytes for a destination path really go.
#[derive(Debug)]
enum Target {
    /// Nothing there yet: a new file, created atomically.
    New(PathBuf),
    /// A regular file: replaced atomically, keeping its permissions.
    Regular(PathBuf, Permissions),
    /// A device, FIFO or socket: opened and written through, never replaced.
    Special(PathBuf),
}

/// Symbolic links followed before giving up (Linux's own limit is 40).
const MAX_LINKS: usize = 40;

/// Follows symbolic links from `dest` to what a write must really touch.
fn resolve(dest: &Path) -> io::Result<Target> {
    let mut p = dest.to_path_buf();
    for _ in 0..=MAX_LINKS {
        let meta = match fs::symlink_metadata(&p) {
            Ok(m) => m,
            Err(e) if e.kind() == io::ErrorKind::NotFound => return Ok(Target::New(p)),
            Err(e) => return Err(e),
        };
        let kind = meta.file_type();
        if kind.is_symlink() {
            let link = fs::read_link(&p)?;
            // A relative link is relative to the directory holding the link.
            p = match p.parent() {
                Some(dir) if link.is_relative() => dir.join(link),
                _ => link,
            };
        } else if kind.is_file() {
            return Ok(Target::Regular(p, meta.permissions()));
        } else if kind.is_dir() {
            return Err(io::Error::new(
                io::ErrorKind::IsADirectory,
                "is a directory; give a file name",
            ));
        } else {
            return Ok(Target::Special(p));
        }
    }
    Err(io::Error::other(format!(
        "more than {MAX_LINKS} symbolic links to follow"
    )))
}

/// The directory a temporary file for `path` goes into: the same one, so the rename is atomic.
fn dir_of(path: &Path) -> &Path {
    match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    }
}

/// Writes the output `dest` through `contents`, which receives a buffered writer.
///
/// `-` is standard output. A new path or a regular file is written to a temporary file
/// (`.kerf-*.tmp`) in the same directory, flushed, synced and renamed over `dest`: a reader
/// never sees a half-written file, and if `contents` or any step fails, `dest` is untouched
/// and the temporary file is removed. A device, FIFO or socket is opened and written through
/// (a rename would replace `/dev/null` by a regular file). A symbolic link is followed to its
/// target (created if the link dangles), and the link is left in place.
///
/// A created file gets mode `0o666` less the umask, as any file the user creates; a replaced
/// regular file keeps its mode.
///
/// Memory stays bounded: `contents` streams into an 8 KiB buffer.
///
/// # Errors
/// The error of `contents`, or the operating system's (no such directory, no permission, no
/// space, a directory given as `dest`). The caller names the file.
pub fn write_file(
    dest: &Path,
    contents: impl FnOnce(&mut dyn Write) -> io::Result<()>,
) -> io::Result<()> {
    if dest == Path::new("-") {
        let stdout = io::stdout();
        let mut w = BufWriter::new(stdout.lock());
        contents(&mut w)?;
        return w.flush();
    }
    match resolve(dest)? {
        Target::Special(p) => {
            let file = OpenOptions::new().write(true).open(p)?;
            let mut w = BufWriter::new(file);
            contents(&mut w)?;
            w.flush()
        }
        Target::New(p) => atomic(&p, None, contents),
        Target::Regular(p, perms) => atomic(&p, Some(perms), contents),
    }
}

/// Writes `path` through a temporary file beside it, renamed over it when complete.
fn atomic(
    path: &Path,
    keep: Option<Permissions>,
    contents: impl FnOnce(&mut dyn Write) -> io::Result<()>,
) -> io::Result<()> {
    let mut builder = tempfile::Builder::new();
    builder.prefix(".kerf-").suffix(".tmp");
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        // Like File::create: 0o666 less the umask (tempfile's own default is 0o600).
        builder.permissions(Permissions::from_mode(0o666));
    }
    let mut tmp = builder.tempfile_in(dir_of(path))?;
    if let Some(perms) = keep {
        // fchmod is not subject to the umask, so the old mode is kept exactly.
        tmp.as_file().set_permissions(perms)?;
    }
    {
        let mut w = BufWriter::new(tmp.as_file_mut());
        contents(&mut w)?;
        w.flush()?;
    }
    // The data reaches the disk before the rename does, so that after a crash or power loss
    // `path` names the old file or the whole new one, never an empty or partial one (ext4's
    // delayed allocation, XFS): part of the atomicity promised, not durability (the directory
    // is not synced; docs/io.md, "Why the fsync before the rename stays").
    tmp.as_file().sync_all()?;
    tmp.persist(path).map_err(|e| e.error)?;
    Ok(())
}

/// Whether `a` and `b` name the same existing file (the same device and inode on Unix, the
/// same canonical path elsewhere): an output that is also an input would destroy it. `-` and
/// paths that do not exist are never the same file.
pub fn same_file(a: &Path, b: &Path) -> bool {
    if a == Path::new("-") || b == Path::new("-") {
        return false;
    }
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        match (fs::metadata(a), fs::metadata(b)) {
            (Ok(x), Ok(y)) => x.dev() == y.dev() && x.ino() == y.ino(),
            _ => false,
        }
    }
    #[cfg(not(unix))]
    {
        match (fs::canonicalize(a), fs::canonicalize(b)) {
            (Ok(x), Ok(y)) => x == y,
            _ => false,
        }
    }
}

/// A writer of one file's contents, called once with a buffered writer.
pub type Contents<'a> = Box<dyn FnOnce(&mut dyn Write) -> io::Result<()> + 'a>;

/// One file of [`write_dir_all_or_nothing`].
pub struct DirEntry<'a> {
    /// The file name inside the directory (no path separator).
    pub name: &'a str,
    /// Writes the contents.
    pub contents: Contents<'a>,
}

impl fmt::Debug for DirEntry<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("DirEntry")
            .field("name", &self.name)
            .finish()
    }
}

/// The file and the error of a failed [`write_dir_all_or_nothing`].
#[derive(Debug)]
pub struct DirError {
    /// The file or directory the failure is about.
    pub path: PathBuf,
    /// What went wrong.
    pub error: io::Error,
}

impl fmt::Display for DirError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: cannot write: {}", self.path.display(), self.error)
    }
}

impl std::error::Error for DirError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        Some(&self.error)
    }
}

/// Writes every entry into `dir` (created if needed), all or nothing.
///
/// Every existing file of the same name must be a regular file; a symbolic link, device, FIFO
/// or directory there is refused before anything is written (a program or CSV silently going
/// through a link into another directory is not what an output directory means). The new files
/// are written (streamed) into a staging directory `.kerf-run-*` inside `dir`; then, file by
/// file, an old file is moved aside into the staging directory and the new one renamed into
/// place. If any step fails, the files already placed are removed and the old ones put back,
/// so `dir` is left as it was. (A crash between two renames can still leave a mix; the staging
/// directory then remains.) New files get `0o666` less the umask; replaced files keep their
/// mode.
///
/// # Errors
/// [`DirError`] naming the file: a name with a path separator, a non-regular file in the way,
/// or any error of writing, syncing or renaming.
pub fn write_dir_all_or_nothing(dir: &Path, entries: Vec<DirEntry<'_>>) -> Result<(), DirError> {
    let fail = |path: &Path, error: io::Error| DirError {
        path: path.to_path_buf(),
        error,
    };
    let mut modes = Vec::with_capacity(entries.len());
    for e in &entries {
        let to = dir.join(e.name);
        if e.name.is_empty() || Path::new(e.name).components().count() != 1 || e.name == ".." {
            return Err(fail(
                &to,
                io::Error::new(io::ErrorKind::InvalidInput, "not a plain file name"),
            ));
        }
        match fs::symlink_metadata(&to) {
            Ok(m) if m.file_type().is_file() => modes.push(Some(m.permissions())),
            Ok(m) => {
                let what = if m.file_type().is_symlink() {
                    "a symbolic link"
                } else if m.is_dir() {
                    "a directory"
                } else {
                    "a device, FIFO or socket"
                };
                return Err(fail(
                    &to,
                    io::Error::new(
                        io::ErrorKind::AlreadyExists,
                        format!(
                            "is {what}; an output directory is written with regular files \
                             only (remove it or choose another output directory)"
                        ),
                    ),
                ));
            }
            Err(e) if e.kind() == io::ErrorKind::NotFound => modes.push(None),
            Err(e) => return Err(fail(&to, e)),
        }
    }
    fs::create_dir_all(dir).map_err(|e| fail(dir, e))?;
    let stage = tempfile::Builder::new()
        .prefix(".kerf-run-")
        .tempdir_in(dir)
        .map_err(|e| fail(dir, e))?;
    let mut names = Vec::with_capacity(entries.len());
    for (e, mode) in entries.into_iter().zip(modes) {
        let p = stage.path().join(e.name);
        let write = || -> io::Result<()> {
            let file = fs::File::create(&p)?;
            if let Some(perms) = mode {
                file.set_permissions(perms)?;
            }
            let mut w = BufWriter::new(file);
            (e.contents)(&mut w)?;
            let file = w.into_inner().map_err(io::IntoInnerError::into_error)?;
            file.sync_all()
        };
        write().map_err(|err| fail(&dir.join(e.name), err))?;
        names.push(e.name);
    }
    let mut old: Vec<(PathBuf, PathBuf)> = Vec::new();
    let mut placed: Vec<PathBuf> = Vec::new();
    let mut swap = || -> Result<(), DirError> {
        for name in &names {
            let to = dir.join(name);
            if fs::symlink_metadata(&to).is_ok() {
                let aside = stage.path().join(format!("{name}.old"));
                fs::rename(&to, &aside).map_err(|e| fail(&to, e))?;
                old.push((aside, to.clone()));
            }
            fs::rename(stage.path().join(name), &to).map_err(|e| fail(&to, e))?;
            placed.push(to);
        }
        Ok(())
    };
    let result = swap();
    if result.is_err() {
        for p in placed.iter().rev() {
            let _ = fs::remove_file(p);
        }
        for (aside, to) in old.iter().rev() {
            let _ = fs::rename(aside, to);
        }
    }
    result
}
