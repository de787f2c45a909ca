//! The layout rule of the developers' guide: no source file imports a file that imports
//! it, directly or around a longer circle, in the app and in each library crate. A file's
//! imports are the modules its `crate::…` and `super::…` paths name (in `use` lines and
//! inline, comments and its `#[cfg(test)] mod tests` left out), and a `mod.rs`'s
//! `use child::…` lines; each path is resolved to the longest module prefix that is a
//! file.

use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

/// A module path: `["xr", "frame_loop"]` for `src/xr/frame_loop.rs`; `[]` for lib.rs.
type Module = Vec<String>;

/// Every file under `root` whose name ends in `.ext`, leaving out hidden folders and
/// `target`.
fn files_under(root: &Path, ext: &str) -> Vec<std::path::PathBuf> {
    let mut out = Vec::new();
    let mut dirs = vec![root.to_path_buf()];
    while let Some(dir) = dirs.pop() {
        for entry in std::fs::read_dir(&dir).unwrap() {
            let path = entry.unwrap().path();
            let name = path.file_name().unwrap().to_string_lossy();
            if path.is_dir() && !name.starts_with('.') && name != "target" {
                dirs.push(path);
            } else if path.extension().is_some_and(|e| e == ext) {
                out.push(path);
            }
        }
    }
    out
}

/// Every `.rs` file under `root` by module path, with its source.
fn modules(root: &Path) -> BTreeMap<Module, String> {
    let mut out = BTreeMap::new();
    for path in files_under(root, "rs") {
        let rel = path.strip_prefix(root).unwrap().with_extension("");
        let mut m: Module = rel.iter().map(|c| c.to_string_lossy().into()).collect();
        if matches!(m.last().map(String::as_str), Some("mod" | "lib" | "main")) {
            m.pop();
        }
        out.insert(m, std::fs::read_to_string(&path).unwrap());
    }
    out
}

/// `src` without comments and without its test module (from `#[cfg(test)]` on).
fn code(src: &str) -> String {
    let src = src.split("#[cfg(test)]").next().unwrap();
    src.lines()
        .map(|l| l.split("//").next().unwrap())
        .collect::<Vec<_>>()
        .join("\n")
}

/// The module paths `text` names after each `crate::` or `super::` (a `{a, b::c}` group
/// expanded one level), relative to the crate root, for a file of module `m`.
fn named_paths(text: &str, m: &Module) -> Vec<Module> {
    let mut out = Vec::new();
    for (head, prefix) in [
        ("crate::", Vec::new()),
        ("super::", m[..m.len().saturating_sub(1)].to_vec()),
    ] {
        for (at, _) in text.match_indices(head) {
            let before = text[..at].chars().next_back();
            if before.is_some_and(|c| c.is_alphanumeric() || c == '_') {
                continue;
            }
            let rest = &text[at + head.len()..];
            let path: String = rest
                .chars()
                .take_while(|c| c.is_alphanumeric() || *c == '_' || *c == ':')
                .collect();
            let mut base = prefix.clone();
            base.extend(path.split("::").filter(|s| !s.is_empty()).map(String::from));
            out.push(base.clone());
            if let Some(group) = rest[path.len()..].strip_prefix('{') {
                for item in group.split('}').next().unwrap().split(',') {
                    let item = item.split(" as ").next().unwrap().trim();
                    if !item.is_empty() && item != "self" {
                        let mut p = base.clone();
                        p.extend(item.split("::").map(String::from));
                        out.push(p);
                    }
                }
            }
        }
    }
    out
}

/// The files each file imports.
fn imports(files: &BTreeMap<Module, String>) -> BTreeMap<Module, BTreeSet<Module>> {
    let resolve = |p: &Module| {
        (0..=p.len())
            .rev()
            .map(|n| p[..n].to_vec())
            .find(|q| files.contains_key(q))
    };
    files
        .iter()
        .map(|(m, src)| {
            let text = code(src);
            let mut paths = named_paths(&text, m);
            // A mod.rs's (or lib.rs's) `use child::…`.
            for line in text.lines().filter_map(|l| l.trim().strip_prefix("use ")) {
                if let Some((first, _)) = line.split_once("::") {
                    let mut p = m.clone();
                    p.push(first.to_string());
                    paths.push(p);
                }
            }
            let targets = paths
                .iter()
                .filter_map(resolve)
                .filter(|t| t != m)
                .collect();
            (m.clone(), targets)
        })
        .collect()
}

/// A circle of imports, if there is one: the files around it, the first repeated last.
fn circle(edges: &BTreeMap<Module, BTreeSet<Module>>) -> Option<Vec<Module>> {
    fn visit(
        m: &Module,
        edges: &BTreeMap<Module, BTreeSet<Module>>,
        path: &mut Vec<Module>,
        done: &mut BTreeSet<Module>,
    ) -> Option<Vec<Module>> {
        if let Some(i) = path.iter().position(|p| p == m) {
            let mut c = path[i..].to_vec();
            c.push(m.clone());
            return Some(c);
        }
        if !done.insert(m.clone()) {
            return None;
        }
        path.push(m.clone());
        for t in edges.get(m).into_iter().flatten() {
            if let Some(c) = visit(t, edges, path, done) {
                return Some(c);
            }
        }
        path.pop();
        None
    }
    let mut done = BTreeSet::new();
    edges
        .keys()
        .find_map(|m| visit(m, edges, &mut Vec::new(), &mut done))
}

fn show(c: &[Module]) -> String {
    c.iter()
        .map(|m| {
            if m.is_empty() {
                "lib".into()
            } else {
                m.join("/")
            }
        })
        .collect::<Vec<_>>()
        .join(" -> ")
}

#[test]
fn no_file_imports_a_file_that_imports_it() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    for src in [
        "src",
        "crates/sim/src",
        "crates/scalpel/src",
        "crates/xr/src",
        "crates/test-gate/src",
    ] {
        let files = modules(&root.join(src));
        assert!(files.len() > 1, "{src}: no sources found");
        if let Some(c) = circle(&imports(&files)) {
            panic!("{src}: a circle of imports: {}", show(&c));
        }
    }
}

/// The app's top-level modules from the floor up: a module imports only modules below it
/// (issue 32: types live on the floor where they are used, presentation above the bodies).
const APP_LAYERS: &[&str] = &[
    "quantile",
    "provenance",
    "progress",
    "interrupt",
    "scene",
    "report",
    "sim_body",
    "pictures",
    "run",
    "exercise",
    "experiment",
    "compare",
    "mesh_cmd",
    "bench",
    "xr",
    "preview",
    "doctor",
    "cli",
];

/// Imports from a top-level module to one at or above its own layer in `layers` (the
/// crate root, not in `layers`, sits on top), as "file -> imported file" lines.
fn upward_imports(files: &BTreeMap<Module, String>, layers: &[&str]) -> Vec<String> {
    let layer = |m: &Module| match m.first() {
        None => Some(layers.len()),
        Some(top) => layers.iter().position(|l| l == top),
    };
    let mut out = Vec::new();
    for (from, targets) in imports(files) {
        let lf = layer(&from)
            .unwrap_or_else(|| panic!("{}: no layer", show(std::slice::from_ref(&from))));
        for to in targets {
            let lt = layer(&to)
                .unwrap_or_else(|| panic!("{}: no layer", show(std::slice::from_ref(&to))));
            if lt > lf || (lt == lf && from.first() != to.first()) {
                out.push(show(&[from.clone(), to]));
            }
        }
    }
    out
}

#[test]
fn no_app_module_imports_one_above_it() {
    let files = modules(&Path::new(env!("CARGO_MANIFEST_DIR")).join("src"));
    let up = upward_imports(&files, APP_LAYERS);
    assert!(
        up.is_empty(),
        "imports that run up the layers ({}):\n{}",
        APP_LAYERS.join(" < "),
        up.join("\n")
    );
}

#[test]
fn an_upward_import_is_found() {
    let files: BTreeMap<Module, String> = [
        (vec![], "mod a;\nmod b;".to_string()),
        (vec!["a".into()], "use crate::b::Thing;".into()),
        (vec!["b".into()], "fn f() {}".into()),
    ]
    .into();
    assert_eq!(upward_imports(&files, &["b", "a"]), Vec::<String>::new());
    assert_eq!(
        upward_imports(&files, &["a", "b"]),
        vec!["a -> b".to_string()]
    );
}

#[test]
fn a_circle_of_imports_is_found() {
    let files: BTreeMap<Module, String> = [
        (vec![], "mod a;\nmod b;\nmod c;".to_string()),
        (vec!["a".into()], "use crate::b::Thing;".into()),
        (vec!["b".into()], "use super::{c::Other, x};".into()),
        (
            vec!["c".into()],
            "fn f() { crate::a::go() } // crate::b".into(),
        ),
    ]
    .into();
    let c = circle(&imports(&files)).expect("the circle a -> b -> c -> a");
    assert_eq!(show(&c), "a -> b -> c -> a");
    let mut cut = files.clone();
    cut.insert(vec!["c".into()], "// crate::a::go()".into());
    assert_eq!(circle(&imports(&cut)), None, "a comment is not an import");
}

/// Every `include_str!`/`include_bytes!` in the `.rs` files under `src`, as (including
/// file, included file) with the included path resolved against the including file.
fn includes(src: &Path) -> Vec<(std::path::PathBuf, std::path::PathBuf)> {
    let mut out = Vec::new();
    for path in files_under(src, "rs") {
        let text = std::fs::read_to_string(&path).unwrap();
        for part in text.split("include_").skip(1) {
            let Some(rest) = part
                .strip_prefix("str!(\"")
                .or_else(|| part.strip_prefix("bytes!(\""))
            else {
                continue;
            };
            let name = &rest[..rest.find('"').unwrap()];
            out.push((path.clone(), path.parent().unwrap().join(name)));
        }
    }
    out
}

/// Each crate stands alone: what it compiles in (`include_str!`, `include_bytes!`) lies
/// inside its own folder (the app's: outside `crates/`), and every WGSL file of the
/// repository is compiled in by a module of the crate it sits in.
#[test]
fn each_crate_compiles_in_only_its_own_files_and_every_shader_is_used() {
    let root = std::fs::canonicalize(env!("CARGO_MANIFEST_DIR")).unwrap();
    let mut used = BTreeSet::new();
    for krate in ["", "crates/sim", "crates/scalpel", "crates/xr"] {
        let home = root.join(krate);
        for (from, file) in includes(&home.join("src")) {
            let file = std::fs::canonicalize(&file)
                .unwrap_or_else(|e| panic!("{}: {}: {e}", from.display(), file.display()));
            let inside = file.starts_with(&home)
                && (!krate.is_empty() || !file.starts_with(root.join("crates")));
            assert!(
                inside,
                "{} compiles in {}, outside its crate {}",
                from.display(),
                file.display(),
                home.display()
            );
            used.insert(file);
        }
    }
    let shaders = files_under(&root, "wgsl");
    assert!(
        shaders.len() >= 18,
        "only {} WGSL files found",
        shaders.len()
    );
    for s in shaders {
        let s = std::fs::canonicalize(&s).unwrap();
        assert!(
            used.contains(&s),
            "{} is compiled in by no module",
            s.display()
        );
    }
}
