//! The architecture's invariants (docs/architecture.md), checked on the workspace's sources:
//! the core crate has no user-interface dependency; only the named platform edges name a
//! target; no source file or function is too long; no module imports a module that imports
//! it.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// The workspace's root.
fn workspace() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../..")
        .canonicalize()
        .expect("the workspace is two folders up")
}

/// The crates' source folders, by crate: each crate's `src` (and the web entry's and the
/// Python package's).
fn crate_sources() -> Vec<PathBuf> {
    let root = workspace();
    let mut dirs: Vec<PathBuf> = std::fs::read_dir(root.join("crates"))
        .expect("crates/")
        .filter_map(|e| e.ok().map(|e| e.path().join("src")))
        .filter(|p| p.is_dir())
        .collect();
    dirs.push(root.join("web/src"));
    dirs.push(root.join("python/src"));
    dirs.sort();
    dirs
}

/// Every file under `dir` whose name ends with `ext`.
fn files(dir: &Path, ext: &str) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let Ok(entries) = std::fs::read_dir(dir) else {
        return out;
    };
    for entry in entries.flatten() {
        let path = entry.path();
        if path.is_dir() {
            out.extend(files(&path, ext));
        } else if path.to_string_lossy().ends_with(ext) {
            out.push(path);
        }
    }
    out.sort();
    out
}

fn relative(path: &Path) -> String {
    path.strip_prefix(workspace())
        .unwrap_or(path)
        .to_string_lossy()
        .into_owned()
}

/// The core crate depends on nothing of a user interface: no window toolkit, no command
/// line parser, no progress bar, no browser bindings of its own (wgpu brings those it needs
/// in a web page).
#[test]
fn the_core_has_no_user_interface_dependency() {
    const FORBIDDEN: [&str; 9] = [
        "egui",
        "eframe",
        "winit",
        "clap",
        "indicatif",
        "web-sys",
        "fourfold-viewer",
        "fourfold-cli",
        "pyo3",
    ];
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let out = std::process::Command::new(cargo)
        .current_dir(workspace())
        .args(["tree", "-p", "fourfold", "-e", "normal", "--prefix", "none"])
        .arg("--offline")
        .output()
        .expect("cargo tree runs");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let tree = String::from_utf8_lossy(&out.stdout);
    assert!(tree.contains("wgpu v"), "cargo tree listed nothing: {tree}");
    // (web-sys comes in with wgpu for the browser; the core itself must not ask for it.)
    let manifest = std::fs::read_to_string(workspace().join("crates/fourfold/Cargo.toml")).unwrap();
    for name in FORBIDDEN {
        let listed = tree.lines().any(|l| l.starts_with(&format!("{name} v")));
        assert!(
            !listed || name == "web-sys",
            "the core depends on {name}: {}",
            tree.lines()
                .filter(|l| l.contains(name))
                .collect::<Vec<_>>()
                .join("; ")
        );
        assert!(
            !manifest
                .lines()
                .any(|l| l.trim_start().starts_with(&format!("{name} "))
                    || l.trim_start().starts_with(&format!("{name}."))),
            "crates/fourfold/Cargo.toml names {name}"
        );
    }
}

/// The files that may compile differently for a web page and a native program.
const PLATFORM_EDGES: [&str; 4] = [
    "crates/fourfold/src/lib.rs",
    "crates/fourfold/src/platform.rs",
    "crates/viewer/src/platform/mod.rs",
    "web/src/lib.rs",
];

#[test]
fn only_the_platform_edges_name_a_target() {
    let mut offenders = Vec::new();
    for dir in crate_sources() {
        for path in files(&dir, ".rs") {
            let text = std::fs::read_to_string(&path).unwrap();
            let code_names_target = text
                .lines()
                .filter(|l| !l.trim_start().starts_with("//"))
                .any(|l| l.contains("target_arch") || l.contains("target_os"));
            if code_names_target && !PLATFORM_EDGES.contains(&relative(&path).as_str()) {
                offenders.push(relative(&path));
            }
        }
    }
    assert!(
        offenders.is_empty(),
        "these files name a target outside the platform edges ({PLATFORM_EDGES:?}): {offenders:?}"
    );
}

/// The longest source file, in lines.
const MAX_FILE_LINES: usize = 600;

#[test]
fn no_source_file_is_too_long() {
    let root = workspace();
    let mut all: Vec<PathBuf> = crate_sources()
        .iter()
        .flat_map(|d| files(d, ".rs"))
        .collect();
    all.extend(files(&root.join("crates/fourfold/templates"), ".wgsl"));
    let long: Vec<String> = all
        .iter()
        .filter_map(|p| {
            let lines = std::fs::read_to_string(p).unwrap().lines().count();
            (lines > MAX_FILE_LINES).then(|| format!("{} ({lines} lines)", relative(p)))
        })
        .collect();
    assert!(long.is_empty(), "over {MAX_FILE_LINES} lines: {long:?}");
}

/// The longest function, in lines (tables are statics, not functions).
const MAX_FUNCTION_LINES: usize = 120;

/// The functions of `text` as (name, first line, lines), by their braces.
fn functions(text: &str) -> Vec<(String, usize, usize)> {
    let lines: Vec<&str> = text.lines().collect();
    let mut out = Vec::new();
    for (start, line) in lines.iter().enumerate() {
        let code = line.split("//").next().unwrap_or("");
        let Some(at) = code.find("fn ") else { continue };
        let before = code[..at].trim();
        let is_item = before.is_empty()
            || before.split_whitespace().all(|w| {
                [
                    "pub",
                    "pub(crate)",
                    "pub(super)",
                    "const",
                    "async",
                    "unsafe",
                    "extern",
                ]
                .contains(&w)
            });
        if !is_item {
            continue;
        }
        let name: String = code[at + 3..]
            .chars()
            .take_while(|c| c.is_alphanumeric() || *c == '_')
            .collect();
        let (mut depth, mut opened) = (0i32, false);
        for (end, l) in lines.iter().enumerate().skip(start) {
            let l = l.split("//").next().unwrap_or("");
            let mut in_string = false;
            for c in l.chars() {
                match c {
                    '"' => in_string = !in_string,
                    '{' if !in_string => {
                        depth += 1;
                        opened = true;
                    }
                    '}' if !in_string => depth -= 1,
                    _ => {}
                }
            }
            if !opened && l.trim_end().ends_with(';') {
                break;
            }
            if opened && depth <= 0 {
                out.push((name.clone(), start + 1, end - start + 1));
                break;
            }
        }
    }
    out
}

#[test]
fn no_function_is_too_long() {
    let mut long = Vec::new();
    for dir in crate_sources() {
        for path in files(&dir, ".rs") {
            let text = std::fs::read_to_string(&path).unwrap();
            for (name, line, count) in functions(&text) {
                if count > MAX_FUNCTION_LINES {
                    long.push(format!("{}:{line} {name} ({count} lines)", relative(&path)));
                }
            }
        }
    }
    assert!(long.is_empty(), "over {MAX_FUNCTION_LINES} lines: {long:?}");
}

/// One source file as a module of its crate: its path in the crate (`["render", "gpu"]`),
/// the items it defines, what it re-exports (name → path), and the paths it uses.
#[derive(Debug, Default)]
struct Module {
    file: String,
    defines: BTreeSet<String>,
    reexports: BTreeMap<String, Vec<String>>,
    /// The uses (absolute module paths with an item) of its code and its private `use`s.
    uses: Vec<Vec<String>>,
}

/// The module path of `file` under the crate's `src`.
fn module_path(src: &Path, file: &Path) -> Vec<String> {
    let rel = file.strip_prefix(src).unwrap();
    let mut parts: Vec<String> = rel
        .components()
        .map(|c| c.as_os_str().to_string_lossy().into_owned())
        .collect();
    let last = parts.pop().unwrap();
    if !["mod.rs", "lib.rs", "main.rs"].contains(&last.as_str()) {
        parts.push(last.trim_end_matches(".rs").to_string());
    }
    parts
}

/// The `use` statements of `text` (joined across lines), with whether each is a re-export.
fn use_statements(text: &str) -> Vec<(bool, String)> {
    let mut out = Vec::new();
    let mut current: Option<(bool, String)> = None;
    for line in text.lines() {
        let code = line.split("//").next().unwrap_or("").trim();
        if let Some((_, s)) = &mut current {
            s.push(' ');
            s.push_str(code);
        } else if let Some(rest) = code.strip_prefix("use ") {
            current = Some((false, rest.to_string()));
        } else if let Some(rest) = ["pub use ", "pub(crate) use ", "pub(super) use "]
            .iter()
            .find_map(|p| code.strip_prefix(p))
        {
            current = Some((true, rest.to_string()));
        } else {
            continue;
        }
        if current.as_ref().is_some_and(|(_, s)| s.ends_with(';')) {
            let (public, s) = current.take().unwrap();
            out.push((public, s.trim_end_matches(';').to_string()));
        }
    }
    out
}

/// A use tree (`a::{b, c::{d, e as f}}`) expanded to its paths, with their local names.
fn expand(tree: &str) -> Vec<(Vec<String>, String)> {
    let tree = tree.trim();
    let segments = |path: &str| -> Vec<String> {
        path.split("::")
            .map(str::trim)
            .filter(|s| !s.is_empty())
            .map(String::from)
            .collect()
    };
    let Some(open) = tree.find('{') else {
        let (path, alias) = match tree.split_once(" as ") {
            Some((p, a)) => (p, Some(a.trim().to_string())),
            None => (tree, None),
        };
        let segs = segments(path);
        let name = alias.or_else(|| segs.last().cloned()).unwrap_or_default();
        return vec![(segs, name)];
    };
    let prefix = segments(&tree[..open]);
    let inner = &tree[open + 1..tree.rfind('}').unwrap_or(tree.len())];
    let mut parts = Vec::new();
    let (mut depth, mut from) = (0, 0);
    for (i, c) in inner.char_indices() {
        match c {
            '{' => depth += 1,
            '}' => depth -= 1,
            ',' if depth == 0 => {
                parts.push(&inner[from..i]);
                from = i + 1;
            }
            _ => {}
        }
    }
    parts.push(&inner[from..]);
    parts
        .into_iter()
        .filter(|p| !p.trim().is_empty())
        .flat_map(expand)
        .map(|(segs, name)| {
            if segs == ["self"] {
                let name = if name == "self" {
                    prefix.last().cloned().unwrap_or_default()
                } else {
                    name
                };
                (prefix.clone(), name)
            } else {
                (prefix.iter().cloned().chain(segs).collect(), name)
            }
        })
        .collect()
}

/// `path` (from a use or the code, starting with `crate`, `super` or `self`) made absolute
/// from the module at `at` (`is_dir`: a folder's module, whose `super` is its parent).
fn absolute(path: &[String], at: &[String]) -> Option<Vec<String>> {
    let mut here: Vec<String> = at.to_vec();
    let mut segs = path.iter().peekable();
    match segs.peek().map(|s| s.as_str()) {
        Some("crate") => {
            here.clear();
            segs.next();
        }
        Some("super") => {
            while segs.peek().is_some_and(|s| *s == "super") {
                here.pop()?;
                segs.next();
            }
        }
        Some("self") => {
            segs.next();
        }
        _ => return None,
    }
    here.extend(segs.cloned());
    Some(here)
}

/// The files the item at `path` is defined in, following re-exports.
fn resolve(modules: &BTreeMap<Vec<String>, Module>, path: &[String], depth: usize) -> Vec<String> {
    if depth > 16 {
        return Vec::new();
    }
    // The longest prefix that is a module.
    let Some(k) = (0..=path.len())
        .rev()
        .find(|&k| modules.contains_key(&path[..k]))
    else {
        return Vec::new();
    };
    let module = &modules[&path[..k]];
    let Some(item) = path.get(k) else {
        // A module itself: what its file re-exports and defines.
        let mut files: Vec<String> = module
            .reexports
            .values()
            .flat_map(|p| resolve(modules, p, depth + 1))
            .collect();
        files.push(module.file.clone());
        return files;
    };
    if module.defines.contains(item) {
        return vec![module.file.clone()];
    }
    match module.reexports.get(item) {
        Some(target) => resolve(modules, target, depth + 1),
        None => vec![module.file.clone()],
    }
}

/// The modules of the crate whose sources are in `src`.
fn crate_modules(src: &Path) -> BTreeMap<Vec<String>, Module> {
    let item = |line: &str| -> Option<String> {
        let code = line.trim_end();
        if code.starts_with(' ') || code.starts_with('}') {
            return None;
        }
        let words: Vec<&str> = code.split_whitespace().collect();
        let at = words.iter().position(|w| {
            [
                "fn", "struct", "enum", "trait", "type", "const", "static", "mod", "union",
            ]
            .contains(w)
        })?;
        let name: String = words
            .get(at + 1)?
            .chars()
            .take_while(|c| c.is_alphanumeric() || *c == '_')
            .collect();
        (!name.is_empty()).then_some(name)
    };
    let mut modules = BTreeMap::new();
    for file in files(src, ".rs") {
        let text = std::fs::read_to_string(&file).unwrap();
        let at = module_path(src, &file);
        let mut module = Module {
            file: relative(&file),
            defines: text.lines().filter_map(item).collect(),
            ..Module::default()
        };
        for (public, statement) in use_statements(&text) {
            for (segs, name) in expand(&statement) {
                let Some(path) = absolute(&segs, &at) else {
                    continue;
                };
                if public {
                    module.reexports.insert(name, path);
                } else {
                    module.uses.push(path);
                }
            }
        }
        // Paths written in the code: `crate::a::B`, `super::c::D`.
        for line in text.lines().filter(|l| !l.trim_start().starts_with("//")) {
            for (i, _) in line
                .match_indices("crate::")
                .chain(line.match_indices("super::"))
            {
                if line[..i].ends_with(|c: char| c.is_alphanumeric() || c == '_' || c == ':') {
                    continue;
                }
                let segs: Vec<String> = line[i..]
                    .split(|c: char| !(c.is_alphanumeric() || c == '_' || c == ':'))
                    .next()
                    .unwrap_or("")
                    .split("::")
                    .filter(|s| !s.is_empty())
                    .map(String::from)
                    .collect();
                if let Some(path) = absolute(&segs, &at) {
                    module.uses.push(path);
                }
            }
        }
        modules.insert(at, module);
    }
    modules
}

/// Each file's imports, resolved to the files that define what it imports.
fn import_graph(src: &Path) -> BTreeMap<String, BTreeSet<String>> {
    let modules = crate_modules(src);
    modules
        .values()
        .map(|m| {
            let targets = m
                .uses
                .iter()
                .flat_map(|p| resolve(&modules, p, 0))
                .filter(|f| *f != m.file)
                .collect();
            (m.file.clone(), targets)
        })
        .collect()
}

/// The strongly connected components of more than one file (Tarjan's algorithm).
fn cycles(graph: &BTreeMap<String, BTreeSet<String>>) -> Vec<Vec<String>> {
    struct State<'a> {
        graph: &'a BTreeMap<String, BTreeSet<String>>,
        index: BTreeMap<&'a str, usize>,
        low: BTreeMap<&'a str, usize>,
        stack: Vec<&'a str>,
        on_stack: BTreeSet<&'a str>,
        found: Vec<Vec<String>>,
    }
    fn visit<'a>(s: &mut State<'a>, v: &'a str) {
        let n = s.index.len();
        s.index.insert(v, n);
        s.low.insert(v, n);
        s.stack.push(v);
        s.on_stack.insert(v);
        for w in s.graph.get(v).into_iter().flatten() {
            let w = w.as_str();
            if !s.graph.contains_key(w) {
                continue;
            }
            if !s.index.contains_key(w) {
                visit(s, w);
                let low = s.low[w].min(s.low[v]);
                s.low.insert(v, low);
            } else if s.on_stack.contains(w) {
                let low = s.index[w].min(s.low[v]);
                s.low.insert(v, low);
            }
        }
        if s.low[v] == s.index[v] {
            let mut component = Vec::new();
            while let Some(w) = s.stack.pop() {
                s.on_stack.remove(w);
                component.push(w.to_string());
                if w == v {
                    break;
                }
            }
            if component.len() > 1 {
                component.sort();
                s.found.push(component);
            }
        }
    }
    let mut s = State {
        graph,
        index: BTreeMap::new(),
        low: BTreeMap::new(),
        stack: Vec::new(),
        on_stack: BTreeSet::new(),
        found: Vec::new(),
    };
    for v in graph.keys() {
        if !s.index.contains_key(v.as_str()) {
            visit(&mut s, v);
        }
    }
    s.found
}

#[test]
fn no_module_imports_a_module_that_imports_it() {
    let mut found = Vec::new();
    for src in crate_sources() {
        found.extend(cycles(&import_graph(&src)));
    }
    assert!(found.is_empty(), "import cycles: {found:#?}");
}

/// The checker itself finds a cycle where there is one.
#[test]
fn the_cycle_checker_sees_a_cycle() {
    let graph: BTreeMap<String, BTreeSet<String>> = [
        ("a", vec!["b"]),
        ("b", vec!["c"]),
        ("c", vec!["a"]),
        ("d", vec!["a"]),
    ]
    .into_iter()
    .map(|(k, v)| (k.to_string(), v.into_iter().map(String::from).collect()))
    .collect();
    assert_eq!(cycles(&graph), vec![vec!["a", "b", "c"]]);
    let paths = expand("super::{a::B, c::{D, E as F}, self}");
    assert!(paths.contains(&(vec!["super".into(), "c".into(), "E".into()], "F".into())));
    assert!(paths.contains(&(vec!["super".into()], "super".into())));
}
