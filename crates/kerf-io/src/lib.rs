//! The one input front end and the one output writer of kerf.
//!
//! Every kerf reader (curves, toolpath, machine, axes, STL, the checker's loose toolpath) and
//! every writer (toolpath, axes, SVG, set-points CSV, G-code, the `kerf run` directory) goes
//! through this crate, so that the rules below hold for every file kerf touches:
//!
//! **Reading** ([`read_file`], [`read_regular_file`], [`read_to_end`], [`parse_json`]):
//! - at most [`MAX_INPUT_BYTES`] are read from any file or stream (`/dev/zero` as input is an
//!   error after 1 GiB, not an endless read);
//! - a file named inside a document (an STL surface's `path`) must be a regular file: a FIFO or
//!   a device there is refused before it is read (a FIFO is never opened);
//! - a UTF-8 byte-order mark is skipped ([`strip_bom`]);
//! - a key given twice in one JSON object is refused with its JSON path
//!   (`curves[0].id: key given twice in one object`), since readers disagree on which copy wins;
//! - syntax errors carry line, column and the JSON path of the value being read.
//!
//! **Text** ([`check_text`]): ids and names that may reach a program (a G-code comment, an SVG
//! title, a terminal) must be one line of printable text: no C0 or C1 control character (`\n`,
//! `\r`, NUL, ESC, DEL, U+0085, ...) and no line or paragraph separator (U+2028, U+2029).
//!
//! **Writing** ([`write_file`], [`write_dir_all_or_nothing`]):
//! - `-` is standard output;
//! - a new path or a regular file is written atomically: a temporary file in the same
//!   directory, flushed and synced, then renamed over the destination; on any failure the
//!   destination is untouched and no temporary file remains;
//! - a character or block device, a FIFO or a socket is written through (opened for writing,
//!   never replaced: as root, `-o /dev/null` stays a device);
//! - a symbolic link is followed: its target (created if the link dangles) is written by the
//!   same rules, in the target's directory, and the link stays a link;
//! - a new file gets the permissions of any file the user creates (`0o666` less the umask); a
//!   replaced regular file keeps its mode.
//!
//! [`same_file`] tells whether an output would overwrite an input (same device and inode).
//!
//! **Near misses** ([`near_misses_in`]): an unknown key that looks like a misspelt known one
//! (`weigths`, `max_jerks`) is reported as an [`UnknownKey`] warning by every reader.

mod json;
mod keys;
mod read;
mod shape;
mod text;
mod write;

pub use json::{json_type_name, parse_json, path_at, JsonError, StrictValue};
pub use keys::{near_misses_in, UnknownKey};
pub use read::{read_file, read_regular_file, read_to_end, strip_bom, MAX_INPUT_BYTES};
pub use shape::{deserialize_at, duplicate_key_message, JsonProblem, ShapeError};
pub use text::{check_text, decimal, TextDefect};
pub use write::{same_file, write_dir_all_or_nothing, write_file, Contents, DirEntry, DirError};
