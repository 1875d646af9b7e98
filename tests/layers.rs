//! The crate's layers, checked from its source (ARCHITECTURE.md, "Layers").
//!
//! Reads every file under `crate/src` and fails when
//!
//! * a top-level module names (`crate::NAME`, outside comments) a module of
//!   its own layer or of a layer above it: imports run down the table
//!   below, so there is no circle between top-level modules;
//! * anything below the session layer names `crate::lab`, or anything but
//!   the bindings names `crate::bindings`;
//! * the files of one folder import each other in a circle (`super::NAME`
//!   of a sibling file);
//! * a module the table does not know appears (add it to its layer);
//! * a bindings file names any module but `lab` (the boundary converts
//!   only: the plain value types it needs, `lab` re-exports), or builds
//!   JSON by hand (`json!`) instead of serialising what `lab` returns.
//!
//! Native only: the wasm build of the tests has no file system.
#![cfg(not(target_arch = "wasm32"))]

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// The layers, bottom first. A module may name modules of lower layers
/// only. `formats` reads robots' files into the lab's own types (a log's
/// scans are `slam`'s, a saved map is what `merge` merges), so it stands
/// above `slam` and below `merge`.
const LAYERS: &[&[&str]] = &[
    &["geom", "rng", "palette"],
    &["kinematics", "world", "maze"],
    &["scenario", "sensors"],
    &["odometry", "follower", "camera", "surf", "slam"],
    &["sim", "formats"],
    &["render", "merge"],
    &["lab"],
    &["bindings"],
];

fn src_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("src")
}

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    let mut entries: Vec<PathBuf> = std::fs::read_dir(dir)
        .expect("crate/src is readable")
        .map(|e| e.expect("a directory entry").path())
        .collect();
    entries.sort();
    for p in entries {
        if p.is_dir() {
            rust_files(&p, out);
        } else if p.extension().is_some_and(|e| e == "rs") {
            out.push(p);
        }
    }
}

/// `text` without comments (`//` to the end of the line; the crate has no
/// block comments).
fn strip_comments(text: &str) -> String {
    text.lines()
        .map(|l| match l.find("//") {
            // Keep `//` inside string literals ("http://..."): cut only
            // where no quote precedes it on the line.
            Some(i) if !l[..i].contains('"') => &l[..i],
            _ => l,
        })
        .collect::<Vec<_>>()
        .join("\n")
}

fn code_of(path: &Path) -> String {
    strip_comments(&std::fs::read_to_string(path).expect("a source file"))
}

/// The identifiers following `prefix` in `code` (`crate::` gives `geom`,
/// `lab`, ...).
fn names_after(code: &str, prefix: &str) -> BTreeSet<String> {
    let mut out = BTreeSet::new();
    let mut rest = code;
    while let Some(i) = rest.find(prefix) {
        let before = rest[..i].chars().last();
        rest = &rest[i + prefix.len()..];
        if before.is_some_and(|c| c.is_alphanumeric() || c == '_' || c == ':') {
            continue;
        }
        let ident = |t: &str| -> String {
            t.trim_start()
                .chars()
                .take_while(|c| c.is_alphanumeric() || *c == '_')
                .collect()
        };
        if let Some(group) = rest.strip_prefix('{') {
            // `crate::{a::X, b}`: every first-level name of the group.
            let (mut depth, mut start) = (0usize, 0usize);
            for (k, c) in group.char_indices() {
                match c {
                    '{' => depth += 1,
                    '}' if depth == 0 => {
                        out.insert(ident(&group[start..k]));
                        break;
                    }
                    '}' => depth -= 1,
                    ',' if depth == 0 => {
                        out.insert(ident(&group[start..k]));
                        start = k + 1;
                    }
                    _ => {}
                }
            }
            out.remove("");
        } else {
            let name = ident(rest);
            if !name.is_empty() {
                out.insert(name);
            }
        }
    }
    out
}

fn layer_of(module: &str) -> Option<usize> {
    LAYERS.iter().position(|l| l.contains(&module))
}

/// `crate/src/merge/job.rs` → ("merge", Some("merge"), "job"): the
/// top-level module, the folder, the file's own name (`mod` for mod.rs).
fn place(path: &Path) -> (String, Option<String>, String) {
    let rel = path.strip_prefix(src_dir()).expect("under src");
    let parts: Vec<String> = rel
        .iter()
        .map(|p| p.to_string_lossy().trim_end_matches(".rs").to_string())
        .collect();
    let folder = (parts.len() > 1).then(|| parts[..parts.len() - 1].join("/"));
    (parts[0].clone(), folder, parts[parts.len() - 1].clone())
}

#[test]
fn imports_run_down_the_layers_only() {
    let mut files = Vec::new();
    rust_files(&src_dir(), &mut files);
    let mut wrong = Vec::new();
    for f in &files {
        let (top, _, _) = place(f);
        if top == "lib" {
            continue;
        }
        let Some(own) = layer_of(&top) else {
            wrong.push(format!("module `{top}` is in no layer of tests/layers.rs"));
            continue;
        };
        for used in names_after(&code_of(f), "crate::") {
            if used == top {
                continue;
            }
            match layer_of(&used) {
                Some(l) if l < own => {}
                Some(_) => wrong.push(format!(
                    "{} names crate::{used}, which is not below `{top}`",
                    f.display()
                )),
                None => wrong.push(format!(
                    "{} names crate::{used}, in no layer of tests/layers.rs",
                    f.display()
                )),
            }
        }
    }
    assert!(wrong.is_empty(), "\n{}", wrong.join("\n"));
}

#[test]
fn bindings_name_only_the_session_and_build_no_json() {
    let mut files = Vec::new();
    rust_files(&src_dir().join("bindings"), &mut files);
    assert!(files.len() >= 5, "the bindings folder has its files");
    let mut wrong = Vec::new();
    for f in &files {
        let code = code_of(f);
        for used in names_after(&code, "crate::") {
            if used != "lab" {
                wrong.push(format!(
                    "{} names crate::{used}: bindings call `lab` only",
                    f.display()
                ));
            }
        }
        if code.contains("json!") {
            wrong.push(format!(
                "{} builds JSON by hand: views are built in `lab`",
                f.display()
            ));
        }
    }
    assert!(wrong.is_empty(), "\n{}", wrong.join("\n"));
}

#[test]
fn no_folder_has_files_importing_each_other_in_a_circle() {
    let mut files = Vec::new();
    rust_files(&src_dir(), &mut files);
    // Per folder: file -> the sibling files it names through `super::`.
    let mut graphs: BTreeMap<String, BTreeMap<String, BTreeSet<String>>> = BTreeMap::new();
    for f in &files {
        let (_, Some(folder), name) = place(f) else {
            continue;
        };
        if name == "mod" {
            continue;
        }
        let siblings: BTreeSet<String> = names_after(&code_of(f), "super::");
        graphs.entry(folder).or_default().insert(name, siblings);
    }
    let mut circles = Vec::new();
    for (folder, graph) in &graphs {
        // Depth-first search for a back edge among the folder's files.
        fn visit(
            n: &str,
            g: &BTreeMap<String, BTreeSet<String>>,
            state: &mut BTreeMap<String, u8>,
            path: &mut Vec<String>,
            found: &mut Vec<String>,
        ) {
            state.insert(n.to_string(), 1);
            path.push(n.to_string());
            for m in g
                .get(n)
                .into_iter()
                .flatten()
                .filter(|m| g.contains_key(*m))
            {
                match state.get(m.as_str()).copied().unwrap_or(0) {
                    0 => visit(m, g, state, path, found),
                    1 => {
                        let start = path.iter().position(|p| p == m).unwrap_or(0);
                        found.push(format!("{} -> {m}", path[start..].join(" -> ")));
                    }
                    _ => {}
                }
            }
            path.pop();
            state.insert(n.to_string(), 2);
        }
        let mut state = BTreeMap::new();
        for n in graph.keys() {
            if state.get(n.as_str()).copied().unwrap_or(0) == 0 {
                let mut found = Vec::new();
                visit(n, graph, &mut state, &mut Vec::new(), &mut found);
                circles.extend(found.into_iter().map(|c| format!("{folder}: {c}")));
            }
        }
    }
    assert!(circles.is_empty(), "\n{}", circles.join("\n"));
}

#[test]
fn the_scanner_finds_names_outside_comments_and_the_table_is_ordered() {
    // The scanner itself: a use of the session is found, a comment is not,
    // and the layer table orders what ARCHITECTURE.md says.
    let code = "use crate::lab::Lab; // crate::bindings\nlet x = crate::geom::Pose2::IDENTITY;";
    let got: Vec<String> = names_after(&strip_comments(code), "crate::")
        .into_iter()
        .collect();
    assert_eq!(got, vec!["geom".to_string(), "lab".to_string()]);
    assert!(names_after(code, "crate::").contains("bindings"));
    let group = "use crate::{lab::Lab, geom::{Pose2, wrap_angle}};";
    let got: Vec<String> = names_after(group, "crate::").into_iter().collect();
    assert_eq!(got, vec!["geom".to_string(), "lab".to_string()]);
    let order = ["geom", "sim", "merge", "lab", "bindings"];
    let ranks: Vec<usize> = order.iter().map(|m| layer_of(m).expect("known")).collect();
    assert!(ranks.windows(2).all(|w| w[0] < w[1]), "{ranks:?}");
    assert_eq!(layer_of("render"), layer_of("merge"));
}
