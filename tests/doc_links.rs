//! Every reference in the documentation resolves inside the repository: each relative
//! markdown link (`[text](path#anchor)`) to a file that exists and, for a markdown target, to
//! one of its headings; each path named in backticks from the repository's root (`docs/...`,
//! `crates/...`, `fixtures/...`, `scripts/...`, `examples/...`) to a file or directory that
//! exists; a crate-relative source, test or bench (`src/x.rs`, `tests/x.rs`, `benches/x.rs`)
//! to one at the root or in some crate. The CLI's `--help` texts are checked
//! the same way in `crates/kerf-cli/tests/help_links.rs`.

use std::collections::HashSet;
use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// The markdown files of the documentation: `docs/`, the README and every README under
/// `crates/`, `fixtures/` and `benches/`.
fn markdown_files() -> Vec<PathBuf> {
    let mut out = vec![root().join("README.md")];
    let mut stack = vec![
        root().join("docs"),
        root().join("crates"),
        root().join("fixtures"),
        root().join("benches"),
    ];
    while let Some(dir) = stack.pop() {
        let Ok(entries) = std::fs::read_dir(&dir) else {
            continue;
        };
        for e in entries.flatten() {
            let p = e.path();
            if p.is_dir() {
                if !p.ends_with("target") {
                    stack.push(p);
                }
            } else if p.extension().is_some_and(|x| x == "md") {
                out.push(p);
            }
        }
    }
    out.sort();
    out
}

/// GitHub's anchor of a heading: lower case, punctuation other than `-` and `_` dropped,
/// spaces as `-`.
fn slug(heading: &str) -> String {
    heading
        .trim()
        .to_lowercase()
        .chars()
        .filter(|c| c.is_alphanumeric() || matches!(c, '-' | '_' | ' '))
        .map(|c| if c == ' ' { '-' } else { c })
        .collect()
}

/// The anchors of a markdown file's headings (outside code blocks), repeated ones numbered as
/// GitHub numbers them.
fn anchors(text: &str) -> HashSet<String> {
    let mut seen: Vec<String> = Vec::new();
    let mut out = HashSet::new();
    let mut code = false;
    for line in text.lines() {
        if line.trim_start().starts_with("```") {
            code = !code;
        }
        if code || !line.starts_with('#') {
            continue;
        }
        let h = line.trim_start_matches('#');
        if !h.starts_with(' ') {
            continue;
        }
        let s = slug(h);
        let n = seen.iter().filter(|x| **x == s).count();
        out.insert(if n == 0 {
            s.clone()
        } else {
            format!("{s}-{n}")
        });
        seen.push(s);
    }
    out
}

/// The targets of the markdown links `](target)` in `text`.
fn links(text: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut rest = text;
    while let Some(i) = rest.find("](") {
        rest = &rest[i + 2..];
        let end = rest.find(')').unwrap_or(rest.len());
        let t = &rest[..end];
        if !t.is_empty() && !t.contains(char::is_whitespace) {
            out.push(t.to_string());
        }
    }
    out
}

/// The spans in backticks of `text` outside code blocks, paragraph by paragraph (a span may
/// wrap onto the next line, never past a blank one); a paragraph with an odd number of
/// backticks is an error (a stray backtick would turn the rest into unchecked prose).
fn code_spans(text: &str) -> Result<Vec<String>, String> {
    let mut prose = String::new();
    let mut code = false;
    for line in text.lines() {
        if line.trim_start().starts_with("```") {
            code = !code;
            prose.push('\n');
            continue;
        }
        if !code {
            prose.push_str(line);
        }
        prose.push('\n');
    }
    let mut out = Vec::new();
    for para in prose.split("\n\n") {
        if para.matches('`').count() % 2 == 1 {
            return Err(format!("a stray backtick in: {}", para.trim()));
        }
        out.extend(
            para.split('`')
                .skip(1)
                .step_by(2)
                .map(|s| s.replace('\n', " ")),
        );
    }
    Ok(out)
}

/// Paths the docs name in other projects' sources or as a pattern, not in kerf's: LinuxCNC's
/// kinematics modules (docs/linuxcnc.md), curvo's knot and curve code (docs/performance.md),
/// the module layout `src/a.rs` / `src/a/` (docs/architecture.md).
const OTHER_PROJECTS: [&str; 5] = [
    "src/emc/",
    "src/knot/",
    "src/curve/nurbs_curve.rs",
    "src/a.rs",
    "src/a/",
];

/// Where `reference` (a path in backticks) should exist, if it names a repository path:
/// `None` when it is not one (a command, a key, a glob or a placeholder).
fn repository_path(reference: &str) -> Option<Vec<PathBuf>> {
    let r = reference.trim_end_matches(['.', ',', ':', ';']);
    let plain = r
        .chars()
        .all(|c| c.is_ascii_alphanumeric() || matches!(c, '_' | '.' | '/' | '-'));
    if !plain || r.contains("..") {
        return None;
    }
    if OTHER_PROJECTS.iter().any(|p| r.starts_with(p)) {
        return None;
    }
    let rooted = [
        "docs/",
        "crates/",
        "fixtures/",
        "scripts/",
        "examples/",
        ".ci/",
    ];
    if rooted.iter().any(|p| r.starts_with(p)) {
        return Some(vec![root().join(r)]);
    }
    if ["tests/", "benches/", "src/"]
        .iter()
        .any(|p| r.starts_with(p))
    {
        let mut places = vec![root().join(r)];
        if let Ok(crates) = std::fs::read_dir(root().join("crates")) {
            places.extend(crates.flatten().map(|c| c.path().join(r)));
        }
        return Some(places);
    }
    None
}

#[test]
fn every_reference_in_the_docs_resolves_inside_the_repository() {
    let files = markdown_files();
    assert!(files.len() > 20, "found {} markdown files", files.len());
    let mut broken = Vec::new();
    let mut checked = 0;
    for file in &files {
        let text = std::fs::read_to_string(file).expect("readable");
        let name = file
            .strip_prefix(root())
            .unwrap_or(file)
            .display()
            .to_string();
        for t in links(&text) {
            if t.contains("://") || t.starts_with("mailto:") {
                continue;
            }
            checked += 1;
            let (path, anchor) = t.split_once('#').unwrap_or((&t, ""));
            let target = if path.is_empty() {
                file.clone()
            } else {
                file.parent().unwrap_or(Path::new(".")).join(path)
            };
            if !target.exists() {
                broken.push(format!("{name}: link {t}: no such file"));
                continue;
            }
            if !anchor.is_empty() && target.extension().is_some_and(|x| x == "md") {
                let heads = anchors(&std::fs::read_to_string(&target).expect("readable"));
                if !heads.contains(anchor) {
                    broken.push(format!("{name}: link {t}: no heading #{anchor}"));
                }
            }
        }
        let spans = code_spans(&text).unwrap_or_else(|e| {
            broken.push(format!("{name}: {e}"));
            Vec::new()
        });
        for span in spans {
            let Some(places) = repository_path(&span) else {
                continue;
            };
            checked += 1;
            if !places.iter().any(|p| p.exists()) {
                broken.push(format!("{name}: `{span}`: no such path in the repository"));
            }
        }
    }
    assert!(checked > 300, "only {checked} references checked");
    assert!(
        broken.is_empty(),
        "{} broken:\n{}",
        broken.len(),
        broken.join("\n")
    );
}

/// The picture of the architecture names every crate of the workspace (redraw it with
/// `scripts/architecture_svg.py` when one is added).
#[test]
fn the_architecture_picture_names_every_crate() {
    let svg = std::fs::read_to_string(root().join("docs/architecture.svg")).expect("the picture");
    let crates: Vec<String> = std::fs::read_dir(root().join("crates"))
        .expect("crates/")
        .flatten()
        .filter(|e| e.path().join("Cargo.toml").exists())
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .collect();
    assert!(crates.len() >= 10, "{crates:?}");
    let missing: Vec<&String> = crates
        .iter()
        .filter(|c| !svg.contains(&format!(">{c}</text>")))
        .collect();
    assert!(
        missing.is_empty(),
        "not in docs/architecture.svg: {missing:?}"
    );
}

#[test]
fn the_checks_catch_what_they_look_for() {
    assert_eq!(slug(" The head along the cuts"), "the-head-along-the-cuts");
    assert_eq!(slug(" `report.json` (`kerf run`)"), "reportjson-kerf-run");
    let a = anchors("# A\n## B c\n```\n# not\n```\n## B c\n");
    assert!(a.contains("a") && a.contains("b-c") && a.contains("b-c-1") && !a.contains("not"));
    assert_eq!(
        links("see [x](docs/a.md#b) and [y](http://z)"),
        ["docs/a.md#b", "http://z"]
    );
    assert!(repository_path("docs/nothing-here.md").is_some_and(|p| !p[0].exists()));
    assert!(repository_path("kerf run --place auto").is_none());
    assert!(repository_path("fixtures/machines/*.json").is_none());
    assert_eq!(
        code_spans("a `b\nc` d `docs/x.md`\n```\n`not`\n```\n`e`").expect("balanced"),
        ["b c", "docs/x.md", "e"]
    );
    assert!(
        code_spans("a `b\n\nc` d").is_err(),
        "a span never crosses a blank line"
    );
}
