//! Every file the `--help` texts name lies in the repository: the paths (`docs/...`,
//! `fixtures/...`, `crates/...`, `scripts/...`) in the help of `kerf` and of each of its
//! commands. The documentation's own references are checked in `tests/doc_links.rs` at the
//! repository's root.

use std::path::PathBuf;
use std::process::Command;

fn help(args: &[&str]) -> String {
    let out = Command::new(env!("CARGO_BIN_EXE_kerf"))
        .args(args)
        .arg("--help")
        .output()
        .expect("kerf runs");
    assert!(out.status.success(), "kerf {args:?} --help: {out:?}");
    String::from_utf8(out.stdout).expect("utf-8")
}

/// The commands `kerf --help` lists (the lines under `Commands:`).
fn commands(top: &str) -> Vec<String> {
    top.lines()
        .skip_while(|l| !l.starts_with("Commands:"))
        .skip(1)
        .take_while(|l| l.starts_with("  "))
        .filter_map(|l| l.split_whitespace().next().map(str::to_string))
        .filter(|c| c != "help")
        .collect()
}

/// The repository paths a text names.
fn paths(text: &str) -> Vec<String> {
    text.split_whitespace()
        .map(|w| {
            w.trim_matches(|c: char| matches!(c, '(' | ')' | ',' | ';' | ':' | '`' | '\'' | '"'))
                .trim_end_matches('.')
        })
        .filter(|w| {
            ["docs/", "fixtures/", "crates/", "scripts/"]
                .iter()
                .any(|p| w.starts_with(p))
                && !w.contains('*')
                && !w.contains('<')
        })
        .map(str::to_string)
        .collect()
}

#[test]
fn the_help_texts_name_only_files_the_repository_has() {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..");
    let top = help(&[]);
    let cmds = commands(&top);
    assert!(cmds.len() >= 10, "commands: {cmds:?}");
    let mut named = paths(&top);
    for c in &cmds {
        named.extend(paths(&help(&[c])));
    }
    assert!(
        named.iter().any(|p| p == "docs/formats.md"),
        "the help names the formats: {named:?}"
    );
    let missing: Vec<&String> = named.iter().filter(|p| !root.join(p).exists()).collect();
    assert!(
        missing.is_empty(),
        "named in --help, not in the repository: {missing:?}"
    );
}

#[test]
fn the_path_finder_finds_paths() {
    assert_eq!(
        paths("File formats: docs/formats.md (kerf.curves/1 in). Try `fixtures/dome.json`, x/y"),
        ["docs/formats.md", "fixtures/dome.json"]
    );
}
