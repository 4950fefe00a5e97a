//! The writer against the file system itself: modes compared with `File::create`, file types
//! read back with `symlink_metadata`, contents read back.

use std::fs;
use std::io::{self, Write};
use std::os::unix::fs::{FileTypeExt, PermissionsExt};
use std::path::Path;

use kerf_io::{same_file, write_dir_all_or_nothing, write_file, DirEntry};

fn text(s: &'static str) -> impl FnOnce(&mut dyn Write) -> io::Result<()> {
    move |w| w.write_all(s.as_bytes())
}

fn mode(p: &Path) -> u32 {
    fs::metadata(p).expect("metadata").permissions().mode() & 0o7777
}

fn entries_of(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = fs::read_dir(dir)
        .expect("read dir")
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

#[test]
fn a_new_file_gets_the_mode_of_any_created_file() {
    let dir = tempfile::tempdir().expect("temp dir");
    let reference = dir.path().join("reference");
    fs::File::create(&reference).expect("create");
    let dest = dir.path().join("out.nc");
    write_file(&dest, text("G1 X1\n")).expect("write");
    assert_eq!(
        fs::read_to_string(&dest).expect("read"),
        "G1 X1\n",
        "contents"
    );
    assert_eq!(mode(&dest), mode(&reference), "0o666 less the umask");
    assert_ne!(mode(&dest), 0o600, "not tempfile's private mode");
    assert_eq!(
        entries_of(dir.path()),
        ["out.nc", "reference"],
        "no temporary file"
    );
}

#[test]
fn a_replaced_file_keeps_its_mode() {
    let dir = tempfile::tempdir().expect("temp dir");
    let dest = dir.path().join("out.csv");
    fs::write(&dest, "old").expect("write");
    fs::set_permissions(&dest, fs::Permissions::from_mode(0o640)).expect("chmod");
    write_file(&dest, text("new")).expect("write");
    assert_eq!(fs::read_to_string(&dest).expect("read"), "new", "replaced");
    assert_eq!(mode(&dest), 0o640, "mode kept");
}

#[test]
fn a_failed_write_leaves_the_old_file_and_no_temporary() {
    let dir = tempfile::tempdir().expect("temp dir");
    let dest = dir.path().join("out.json");
    fs::write(&dest, "old").expect("write");
    let e = write_file(&dest, |w| {
        w.write_all(b"half")?;
        Err(io::Error::other("stage failed"))
    })
    .expect_err("fails");
    assert_eq!(e.to_string(), "stage failed", "the closure's error");
    assert_eq!(fs::read_to_string(&dest).expect("read"), "old", "untouched");
    assert_eq!(entries_of(dir.path()), ["out.json"], "no temporary file");
    let fresh = dir.path().join("fresh.json");
    write_file(&fresh, |_| Err(io::Error::other("no"))).expect_err("fails");
    assert!(!fresh.exists(), "no half-written new file");
}

#[test]
fn a_device_is_written_through_not_replaced() {
    let null = Path::new("/dev/null");
    write_file(null, text("discarded")).expect("write to /dev/null");
    let meta = fs::symlink_metadata(null).expect("metadata");
    assert!(
        meta.file_type().is_char_device(),
        "still a character device"
    );
}

#[test]
fn a_fifo_is_written_through() {
    let dir = tempfile::tempdir().expect("temp dir");
    let fifo = dir.path().join("pipe");
    let status = std::process::Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .expect("mkfifo runs");
    assert!(status.success(), "mkfifo");
    let reader = {
        let fifo = fifo.clone();
        std::thread::spawn(move || fs::read_to_string(fifo).expect("read the FIFO"))
    };
    write_file(&fifo, text("through the pipe")).expect("write");
    assert_eq!(
        reader.join().expect("reader"),
        "through the pipe",
        "read back"
    );
    assert!(
        fs::symlink_metadata(&fifo)
            .expect("metadata")
            .file_type()
            .is_fifo(),
        "still a FIFO"
    );
    assert_eq!(entries_of(dir.path()), ["pipe"], "no temporary file");
}

#[test]
fn a_symlink_is_followed_and_stays_a_link() {
    let dir = tempfile::tempdir().expect("temp dir");
    let sub = dir.path().join("real");
    fs::create_dir(&sub).expect("mkdir");
    let target = sub.join("target.nc");
    fs::write(&target, "old").expect("write");
    fs::set_permissions(&target, fs::Permissions::from_mode(0o604)).expect("chmod");
    let link = dir.path().join("link.nc");
    std::os::unix::fs::symlink("real/target.nc", &link).expect("symlink");
    write_file(&link, text("new")).expect("write");
    assert!(
        fs::symlink_metadata(&link)
            .expect("metadata")
            .file_type()
            .is_symlink(),
        "the link is still a link"
    );
    assert_eq!(
        fs::read_to_string(&target).expect("read"),
        "new",
        "target written"
    );
    assert_eq!(mode(&target), 0o604, "target's mode kept");
    assert_eq!(
        entries_of(&sub),
        ["target.nc"],
        "temporary file was in the target's dir"
    );
    // A dangling link: the target is created.
    let dangling = dir.path().join("dangling.nc");
    std::os::unix::fs::symlink("real/new.nc", &dangling).expect("symlink");
    write_file(&dangling, text("created")).expect("write");
    assert_eq!(
        fs::read_to_string(sub.join("new.nc")).expect("read"),
        "created",
        "target created"
    );
    // A loop is an error, not a hang.
    let a = dir.path().join("a");
    let b = dir.path().join("b");
    std::os::unix::fs::symlink(&b, &a).expect("symlink");
    std::os::unix::fs::symlink(&a, &b).expect("symlink");
    assert!(write_file(&a, text("x")).is_err(), "symlink loop refused");
}

#[test]
fn a_directory_or_a_missing_parent_is_an_error() {
    let dir = tempfile::tempdir().expect("temp dir");
    let e = write_file(dir.path(), text("x")).expect_err("a directory");
    assert!(e.to_string().contains("directory"), "{e}");
    let missing = dir.path().join("no").join("such.nc");
    assert!(write_file(&missing, text("x")).is_err(), "missing parent");
    assert!(!missing.exists(), "nothing written");
}

#[test]
fn same_file_sees_through_links_and_dots() {
    let dir = tempfile::tempdir().expect("temp dir");
    let a = dir.path().join("a.json");
    fs::write(&a, "{}").expect("write");
    let hard = dir.path().join("hard.json");
    fs::hard_link(&a, &hard).expect("hard link");
    let soft = dir.path().join("soft.json");
    std::os::unix::fs::symlink(&a, &soft).expect("symlink");
    let dotted = dir.path().join(".").join("a.json");
    for other in [&a, &hard, &soft, &dotted] {
        assert!(same_file(&a, other), "{}", other.display());
    }
    let b = dir.path().join("b.json");
    fs::write(&b, "{}").expect("write");
    assert!(!same_file(&a, &b), "different files with equal contents");
    assert!(!same_file(&a, &dir.path().join("none")), "missing");
    assert!(
        !same_file(Path::new("-"), Path::new("-")),
        "stdout is no file"
    );
}

fn entry<'a>(name: &'a str, s: &'static str) -> DirEntry<'a> {
    DirEntry {
        name,
        contents: Box::new(text(s)),
    }
}

#[test]
fn a_directory_is_written_all_or_nothing() {
    let dir = tempfile::tempdir().expect("temp dir");
    let out = dir.path().join("out");
    write_dir_all_or_nothing(&out, vec![entry("a.txt", "1"), entry("b.txt", "2")]).expect("write");
    assert_eq!(entries_of(&out), ["a.txt", "b.txt"], "both, no staging dir");
    fs::set_permissions(out.join("a.txt"), fs::Permissions::from_mode(0o640)).expect("chmod");
    // The second file fails: nothing changes.
    let e = write_dir_all_or_nothing(
        &out,
        vec![
            entry("a.txt", "new"),
            DirEntry {
                name: "b.txt",
                contents: Box::new(|_| Err(io::Error::other("disk full"))),
            },
        ],
    )
    .expect_err("fails");
    assert!(
        e.to_string().contains("b.txt") && e.to_string().contains("disk full"),
        "{e}"
    );
    assert_eq!(
        fs::read_to_string(out.join("a.txt")).expect("read"),
        "1",
        "old kept"
    );
    assert_eq!(entries_of(&out), ["a.txt", "b.txt"], "staging removed");
    write_dir_all_or_nothing(&out, vec![entry("a.txt", "3")]).expect("write");
    assert_eq!(mode(&out.join("a.txt")), 0o640, "mode kept");
}

#[test]
fn a_directory_write_refuses_links_and_special_files_in_the_way() {
    let dir = tempfile::tempdir().expect("temp dir");
    let elsewhere = dir.path().join("elsewhere.nc");
    fs::write(&elsewhere, "precious").expect("write");
    let out = dir.path().join("out");
    fs::create_dir(&out).expect("mkdir");
    std::os::unix::fs::symlink(&elsewhere, out.join("program.nc")).expect("symlink");
    let e = write_dir_all_or_nothing(
        &out,
        vec![entry("report.json", "{}"), entry("program.nc", "G1")],
    )
    .expect_err("refused");
    assert!(e.to_string().contains("symbolic link"), "{e}");
    assert_eq!(entries_of(&out), ["program.nc"], "nothing written");
    assert_eq!(
        fs::read_to_string(&elsewhere).expect("read"),
        "precious",
        "link target untouched"
    );
    let e = write_dir_all_or_nothing(&out, vec![entry("../x", "1")]).expect_err("bad name");
    assert!(e.to_string().contains("plain file name"), "{e}");
}
