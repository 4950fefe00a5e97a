//! The `kerf` command-line tool (placeholder).

fn main() {}
