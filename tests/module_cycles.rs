//! No module cycle within any crate: the top-level modules of each crate's `src/` (one file
//! `src/a.rs` or directory `src/a/` each) must depend on each other without a cycle, so that
//! a crate can be read module by module, each using only the ones before it (issue 14).
//!
//! A module depends on another where its source names it: `crate::b` (in `use` or in a path,
//! also inside `use crate::{b::X, c}`), `super::b` from a top-level module, or an item that the
//! crate root re-exports from `b` (`crate::X` with `pub use b::X` in `lib.rs`/`main.rs`).
//! Comments are skipped. Modules nested inside a top-level module (`src/a/x.rs`) count as `a`
//! in that graph: a parent and its children may use each other. The crate root itself is not a
//! node (it declares and re-exports every module).
//!
//! Siblings get the same rule one level down: the child modules of any module (`src/a/x.rs`,
//! `src/a/y.rs`, ...) must use each other without a cycle, where `x` uses `y` when its source
//! names `super::y` or `crate::a::y` (the parent, which declares them, is not a node). A glob
//! `use super::*` would hide which of the parent's imports a child uses, so no library module
//! has one (`no_library_module_imports_a_glob`; test modules, `tests.rs` files and inline
//! `mod tests`, use it for their own parent).

use std::collections::{BTreeMap, BTreeSet};
use std::fs;
use std::path::{Path, PathBuf};

/// The top-level module of each source file, and the file's text without comments.
fn sources(src: &Path) -> Vec<(Option<String>, String)> {
    let mut out = Vec::new();
    let mut stack = vec![src.to_path_buf()];
    while let Some(dir) = stack.pop() {
        for entry in fs::read_dir(&dir).expect("read src") {
            let path = entry.expect("entry").path();
            if path.is_dir() {
                stack.push(path);
            } else if path.extension().is_some_and(|e| e == "rs") {
                let rel = path.strip_prefix(src).expect("under src");
                let first = rel.components().next().expect("a component");
                let first = first.as_os_str().to_string_lossy();
                let module = match first.strip_suffix(".rs") {
                    Some("lib" | "main") => None,
                    Some(m) => Some(m.to_string()),
                    None => Some(first.to_string()),
                };
                let text = fs::read_to_string(&path).expect("read source");
                out.push((module, strip_comments(&text)));
            }
        }
    }
    out
}

/// The text without `//` comments (line and doc comments) and `/* */` blocks; string
/// literals are kept (a `//` inside a string is rare in these sources and harmless: it only
/// hides the rest of that line).
fn strip_comments(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    let mut rest = text;
    while !rest.is_empty() {
        if let Some(r) = rest.strip_prefix("/*") {
            rest = r.find("*/").map_or("", |k| &r[k + 2..]);
        } else if rest.starts_with("//") {
            rest = rest.find('\n').map_or("", |k| &rest[k..]);
        } else {
            let c = rest.chars().next().expect("non-empty");
            out.push(c);
            rest = &rest[c.len_utf8()..];
        }
    }
    out
}

fn is_ident(c: char) -> bool {
    c.is_alphanumeric() || c == '_'
}

/// The first path segments after each `prefix::` in `text`, reading `prefix::{a::X, b}` as
/// `a` and `b`.
fn first_segments(text: &str, prefix: &str) -> Vec<String> {
    let mut found = Vec::new();
    let pat = format!("{prefix}::");
    let mut at = 0;
    while let Some(k) = text[at..].find(&pat) {
        let start = at + k;
        at = start + pat.len();
        if start > 0 && text[..start].chars().next_back().is_some_and(is_ident) {
            continue; // `foo_crate::` is not `crate::`
        }
        if text[..start].ends_with("::") {
            continue; // `super::super::x` is not `super::x`
        }
        let rest = &text[at..];
        if let Some(group) = rest.strip_prefix('{') {
            // Top-level items of the group.
            let mut depth = 0;
            let mut item_start = true;
            let mut word = String::new();
            for c in group.chars() {
                match c {
                    '{' => depth += 1,
                    '}' if depth == 0 => break,
                    '}' => depth -= 1,
                    ',' if depth == 0 => item_start = true,
                    c if is_ident(c) && depth == 0 && item_start => word.push(c),
                    _ => {
                        if !word.is_empty() {
                            found.push(std::mem::take(&mut word));
                        }
                        if !c.is_whitespace() {
                            item_start = false;
                        }
                    }
                }
            }
            if !word.is_empty() {
                found.push(word);
            }
        } else {
            let word: String = rest.chars().take_while(|&c| is_ident(c)).collect();
            if !word.is_empty() {
                found.push(word);
            }
        }
    }
    found
}

/// Names the crate root re-exports, with the top-level module each comes from.
fn root_reexports(root: &str) -> BTreeMap<String, String> {
    let mut map = BTreeMap::new();
    for stmt in root.split(';') {
        let stmt = stmt.trim();
        let Some(rest) = stmt
            .strip_prefix("pub use ")
            .or_else(|| stmt.strip_prefix("pub(crate) use "))
            .or_else(|| stmt.strip_prefix("pub(super) use "))
        else {
            continue;
        };
        let rest = rest.trim_start_matches("self::");
        let Some((module, items)) = rest.split_once("::") else {
            continue;
        };
        let items = items.trim().trim_start_matches('{').trim_end_matches('}');
        for item in items.split(',') {
            let name = item.rsplit(" as ").next().unwrap_or(item).trim();
            let name = name.rsplit("::").next().unwrap_or(name).trim();
            if !name.is_empty() {
                map.insert(name.to_string(), module.trim().to_string());
            }
        }
    }
    map
}

/// The dependency graph of the top-level modules of the crate whose sources are in `src`.
fn graph(src: &Path) -> BTreeMap<String, BTreeSet<String>> {
    let files = sources(src);
    let modules: BTreeSet<String> = files.iter().filter_map(|(m, _)| m.clone()).collect();
    let root: String = files
        .iter()
        .filter(|(m, _)| m.is_none())
        .map(|(_, t)| t.as_str())
        .collect();
    let reexports = root_reexports(&root);
    let mut g: BTreeMap<String, BTreeSet<String>> = modules
        .iter()
        .map(|m| (m.clone(), BTreeSet::new()))
        .collect();
    for (module, text) in &files {
        let Some(module) = module else { continue };
        let mut names = first_segments(text, "crate");
        // `super::` from a top-level module file is the crate root.
        let top_level_file = src.join(format!("{module}.rs")).exists();
        if top_level_file {
            names.extend(first_segments(text, "super"));
        }
        for name in names {
            let target = if modules.contains(&name) {
                Some(name)
            } else {
                reexports.get(&name).cloned()
            };
            if let Some(t) = target.filter(|t| t != module && modules.contains(t)) {
                g.get_mut(module).expect("node").insert(t);
            }
        }
    }
    g
}

/// A cycle of `g`, if it has one.
fn find_cycle(g: &BTreeMap<String, BTreeSet<String>>) -> Option<Vec<String>> {
    // 0 unvisited, 1 on the stack, 2 done.
    fn visit(
        g: &BTreeMap<String, BTreeSet<String>>,
        n: &str,
        state: &mut BTreeMap<String, u8>,
        stack: &mut Vec<String>,
    ) -> Option<Vec<String>> {
        state.insert(n.to_string(), 1);
        stack.push(n.to_string());
        for m in &g[n] {
            match state.get(m).copied().unwrap_or(0) {
                1 => {
                    let from = stack.iter().position(|s| s == m).expect("on stack");
                    let mut cycle = stack[from..].to_vec();
                    cycle.push(m.clone());
                    return Some(cycle);
                }
                0 => {
                    if let Some(c) = visit(g, m, state, stack) {
                        return Some(c);
                    }
                }
                _ => {}
            }
        }
        stack.pop();
        state.insert(n.to_string(), 2);
        None
    }
    let mut state = BTreeMap::new();
    for n in g.keys() {
        if state.get(n).copied().unwrap_or(0) == 0 {
            let mut stack = Vec::new();
            if let Some(c) = visit(g, n, &mut state, &mut stack) {
                return Some(c);
            }
        }
    }
    None
}

/// For every module directory under `src` (`src/a/`, `src/a/b/`, ...), the dependency graph of
/// its child modules: child `x` is `x.rs` and every file under `x/` (`mod.rs` included), and it
/// uses its sibling `y` where one of its files names `y` through the path that leads from that
/// file to the parent (`super::y` from `x.rs` or `x/mod.rs`, `super::super::y` from `x/z.rs`,
/// ...; or `crate::a::y`), directly or through an item the parent re-exports from `y`.
fn sibling_graphs(src: &Path) -> Vec<(PathBuf, BTreeMap<String, BTreeSet<String>>)> {
    let mut out = Vec::new();
    let mut stack: Vec<PathBuf> = fs::read_dir(src)
        .expect("read src")
        .map(|e| e.expect("entry").path())
        .filter(|p| p.is_dir())
        .collect();
    while let Some(dir) = stack.pop() {
        // Each child's files, with the number of `super::` that lead back to the parent.
        let mut children: BTreeMap<String, Vec<(usize, String)>> = BTreeMap::new();
        for entry in fs::read_dir(&dir).expect("read module dir") {
            let path = entry.expect("entry").path();
            let name = path
                .file_stem()
                .expect("a name")
                .to_string_lossy()
                .to_string();
            if path.is_dir() {
                stack.push(path.clone());
                let files = children.entry(name).or_default();
                let mut inner = vec![(path, 0usize)];
                while let Some((d, depth)) = inner.pop() {
                    for e in fs::read_dir(&d).expect("read module dir") {
                        let f = e.expect("entry").path();
                        if f.is_dir() {
                            inner.push((f, depth + 1));
                        } else if f.extension().is_some_and(|x| x == "rs") {
                            let is_mod = f.file_stem().is_some_and(|s| s == "mod");
                            let ups = depth + if is_mod { 1 } else { 2 };
                            let text = fs::read_to_string(&f).expect("read source");
                            files.push((ups, strip_comments(&text)));
                        }
                    }
                }
            } else if path.extension().is_some_and(|e| e == "rs") && name != "mod" {
                let text = fs::read_to_string(&path).expect("read source");
                children
                    .entry(name)
                    .or_default()
                    .push((1, strip_comments(&text)));
            }
        }
        // What the parent re-exports from its children.
        let parent_text = [dir.with_extension("rs"), dir.join("mod.rs")]
            .iter()
            .filter_map(|p| fs::read_to_string(p).ok())
            .map(|t| strip_comments(&t))
            .collect::<String>();
        let reexports = root_reexports(&parent_text);
        let module_path: Vec<String> = dir
            .strip_prefix(src)
            .expect("under src")
            .components()
            .map(|c| c.as_os_str().to_string_lossy().to_string())
            .collect();
        let absolute = format!("crate::{}", module_path.join("::"));
        let mut g: BTreeMap<String, BTreeSet<String>> = children
            .keys()
            .map(|m| (m.clone(), BTreeSet::new()))
            .collect();
        for (name, files) in &children {
            for (ups, text) in files {
                let up = vec!["super"; *ups].join("::");
                let mut used = first_segments(text, &up);
                used.extend(first_segments(text, &absolute));
                for u in used {
                    let target = if children.contains_key(&u) {
                        Some(u)
                    } else {
                        reexports.get(&u).cloned()
                    };
                    if let Some(t) = target.filter(|t| t != name && children.contains_key(t)) {
                        g.get_mut(name).expect("node").insert(t);
                    }
                }
            }
        }
        out.push((dir, g));
    }
    out
}

fn crate_dirs() -> Vec<PathBuf> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut dirs: Vec<PathBuf> = fs::read_dir(root.join("crates"))
        .expect("crates/")
        .map(|e| e.expect("entry").path().join("src"))
        .filter(|p| p.is_dir())
        .collect();
    dirs.push(root.join("src"));
    dirs.sort();
    dirs
}

#[test]
fn no_crate_has_a_module_cycle() {
    let mut cycles = Vec::new();
    for src in crate_dirs() {
        if let Some(c) = find_cycle(&graph(&src)) {
            cycles.push(format!("{}: {}", src.display(), c.join(" -> ")));
        }
    }
    assert!(cycles.is_empty(), "module cycles:\n{}", cycles.join("\n"));
}

/// Every `.rs` file under `dir`, recursively.
fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for e in fs::read_dir(dir).expect("readable").flatten() {
        let p = e.path();
        if p.is_dir() {
            rust_files(&p, out);
        } else if p.extension().is_some_and(|x| x == "rs") {
            out.push(p);
        }
    }
}

/// The glob imports of the crate's own modules (`use super::*;`, `use crate::a::*;`,
/// `use self::b::{*, X};`, at any visibility, over several lines) in a library file's module
/// scope: `use` items that start at column 0 (an inline `mod tests` indents its own). Another
/// crate's prelude (`rayon::prelude::*`) is not one of them.
fn module_globs(text: &str) -> Vec<String> {
    let text = strip_comments(text);
    let mut out = Vec::new();
    let mut lines = text.lines();
    while let Some(line) = lines.next() {
        let head = line
            .strip_prefix("pub(crate) ")
            .or_else(|| line.strip_prefix("pub(super) "))
            .or_else(|| line.strip_prefix("pub "))
            .unwrap_or(line);
        let Some(path) = head.strip_prefix("use ") else {
            continue;
        };
        // The whole item, to its `;`.
        let mut item = path.to_string();
        while !item.contains(';') {
            match lines.next() {
                Some(l) => item.push_str(l.trim()),
                None => break,
            }
        }
        let own = ["super::", "crate::", "self::"]
            .iter()
            .any(|k| item.starts_with(k));
        let glob = item.contains("::*") || item.contains("{*") || item.contains(", *");
        if own && glob {
            out.push(format!("use {}", item.trim()));
        }
    }
    out
}

#[test]
fn no_library_module_imports_a_glob() {
    assert_eq!(
        module_globs(
            "use super::*;\n    use super::*;\nuse a::b;\nuse rayon::prelude::*;\n\
             pub(super) use crate::{\n    a::*,\n    b,\n};\nuse self::c::{*, D}; // x\n"
        ),
        [
            "use super::*;",
            "use crate::{a::*,b,};",
            "use self::c::{*, D};"
        ]
    );
    let mut found = Vec::new();
    for src in crate_dirs() {
        let mut files = Vec::new();
        rust_files(&src, &mut files);
        for f in files {
            if f.file_name().is_some_and(|n| n == "tests.rs") {
                continue;
            }
            let text = fs::read_to_string(&f).expect("readable");
            found.extend(
                module_globs(&text)
                    .into_iter()
                    .map(|g| format!("{}: {g}", f.display())),
            );
        }
    }
    assert!(
        found.is_empty(),
        "glob imports hide which modules a module uses:\n{}",
        found.join("\n")
    );
}

#[test]
fn no_module_has_a_cycle_among_its_children() {
    let mut cycles = Vec::new();
    for src in crate_dirs() {
        for (dir, g) in sibling_graphs(&src) {
            if let Some(c) = find_cycle(&g) {
                cycles.push(format!("{}: {}", dir.display(), c.join(" -> ")));
            }
        }
    }
    assert!(cycles.is_empty(), "module cycles:\n{}", cycles.join("\n"));
}

#[test]
fn the_scanner_sees_a_cycle_between_children() {
    // `a/x.rs` uses its sibling `y` through `super::`, `y` uses `x` through `crate::a::`.
    let dir = tempfile::tempdir().expect("tempdir");
    let src = dir.path();
    fs::create_dir(src.join("a")).expect("mkdir");
    fs::write(src.join("lib.rs"), "mod a;\n").expect("write");
    fs::write(src.join("a.rs"), "mod x; mod y;\n").expect("write");
    fs::write(src.join("a/x.rs"), "use super::y::Y;\npub struct X;\n").expect("write");
    fs::write(src.join("a/y.rs"), "use crate::a::x::X;\npub struct Y;\n").expect("write");
    let graphs = sibling_graphs(src);
    assert_eq!(graphs.len(), 1);
    let g = &graphs[0].1;
    assert!(g["x"].contains("y") && g["y"].contains("x"), "{g:?}");
    assert!(find_cycle(g).is_some(), "x <-> y");
    // The top-level graph does not see it (both are `a`).
    assert_eq!(find_cycle(&graph(src)), None);
    fs::write(src.join("a/y.rs"), "pub struct Y;\n").expect("write");
    assert_eq!(find_cycle(&sibling_graphs(src)[0].1), None, "no cycle left");
    // Through the parent's re-export, from a child kept as a directory (its `mod.rs` and a
    // file below it, whose way back to the parent is `super::super::`).
    fs::write(
        src.join("a.rs"),
        "mod x; mod y; mod z;\npub(crate) use x::X;\n",
    )
    .expect("write");
    fs::create_dir(src.join("a/z")).expect("mkdir");
    fs::write(src.join("a/z/mod.rs"), "mod w;\n").expect("write");
    fs::write(src.join("a/z/w.rs"), "use super::super::X;\n").expect("write");
    fs::write(src.join("a/y.rs"), "use super::X;\npub struct Y;\n").expect("write");
    let graphs = sibling_graphs(src);
    let g = &graphs.iter().find(|(d, _)| d.ends_with("a")).expect("a").1;
    assert!(
        g["y"].contains("x"),
        "y uses x through a's re-export: {g:?}"
    );
    assert!(g["z"].contains("x"), "z's file below it uses x: {g:?}");
    assert!(find_cycle(g).is_some(), "x <-> y through the re-export");
}

#[test]
fn the_scanner_sees_a_cycle_and_the_kinds_of_use() {
    // Two modules that use each other, one through a group, one through a re-export of the
    // root, and a third used through `super::`.
    let dir = tempfile::tempdir().expect("tempdir");
    let src = dir.path();
    fs::write(
        src.join("lib.rs"),
        "mod a; mod b; mod c;\npub use b::Thing;\n",
    )
    .expect("write");
    fs::write(
        src.join("a.rs"),
        "// use crate::c::Nothing; (a comment)\nuse crate::{Thing, self as _};\nfn f() { super::c::g() }\n",
    )
    .expect("write");
    fs::write(
        src.join("b.rs"),
        "pub struct Thing;\nuse crate::{c::X, a::f};\n",
    )
    .expect("write");
    fs::write(src.join("c.rs"), "pub fn g() {}\n").expect("write");
    let g = graph(src);
    assert_eq!(
        g["a"],
        ["b", "c"].iter().map(|s| s.to_string()).collect(),
        "a uses b through the root's re-export and c through super"
    );
    assert_eq!(
        g["b"],
        ["a", "c"].iter().map(|s| s.to_string()).collect(),
        "b uses a and c through one group"
    );
    let cycle = find_cycle(&g).expect("a <-> b is a cycle");
    assert_eq!(cycle.first(), cycle.last(), "a closed cycle: {cycle:?}");
    // Without b's use of a there is none.
    fs::write(src.join("b.rs"), "pub struct Thing;\nuse crate::c::X;\n").expect("write");
    assert_eq!(find_cycle(&graph(src)), None, "no cycle left");
}
