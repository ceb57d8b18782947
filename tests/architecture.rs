//! The crate's architecture, checked from its source: the `crate::`, `super::` and `self::`
//! paths of every file under `src/` make a graph of files, which must have no loop (two files
//! that need each other are one concept: make them one file, or move what both need below
//! them) and no edge from a lower layer to a higher one. The layers are written once, here.
//!
//! Test code obeys the layers too: a test that drives a layer through a higher one's harness
//! (a whole-frame test of a core) lives in the higher layer (`verify::core_tests`). A
//! `#[cfg(test)]` module's paths are read from inside it (`super::` in an inline `mod tests`
//! is the file's own module; a test file declared with `#[path]` is its declarer's child).

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// The top-level modules from the bottom up; a module may import from its own rank and below.
/// `bits`, `error`, `io` and `rng` know nothing of ray tracing; `rtl` is the HDL kernel, below
/// everything that describes a ray tracer; the commands are on top.
const LAYERS: &[&[&str]] = &[
    &["bits", "error", "io", "rng"],
    &["rtl"],
    &["params"],
    &["scene"],
    &["model"],
    &["render"],
    &["cores"],
    // Simulating the cores against the models, and synthesising them for FPGAs: peers, neither
    // needs the other.
    &["verify", "fpga"],
    // The files `fxrt gen` writes (a manifest gives the latency `verify` measures).
    &["generate"],
    // The board tops (generated files, placed and routed) and the sweeps (simulated and placed).
    &["board", "sweep"],
    &["fuzzing"],
    &["cli"],
];

/// A source file: its module path (`cores::top`) and what it imports.
struct File {
    module: Vec<String>,
    /// Module paths named, test code included (relative ones resolved).
    paths: Vec<Vec<String>>,
}

fn rank(top: &str) -> usize {
    LAYERS
        .iter()
        .position(|l| l.contains(&top))
        .unwrap_or_else(|| panic!("src/{top}: a top-level module the layers in tests/architecture.rs do not place"))
}

/// Every `.rs` file under `dir`, sorted.
fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    let mut entries: Vec<PathBuf> = std::fs::read_dir(dir).unwrap().map(|e| e.unwrap().path()).collect();
    entries.sort();
    for p in entries {
        if p.is_dir() {
            rust_files(&p, out);
        } else if p.extension().is_some_and(|e| e == "rs") {
            out.push(p);
        }
    }
}

fn module_of(src: &Path, file: &Path) -> Vec<String> {
    let rel = file.strip_prefix(src).unwrap().with_extension("");
    let mut parts: Vec<String> = rel.iter().map(|c| c.to_string_lossy().into_owned()).collect();
    if matches!(parts.last().map(String::as_str), Some("mod" | "lib" | "main")) {
        parts.pop();
    }
    parts
}

/// The text without line comments (doc comments name modules they do not import).
fn strip_comments(text: &str) -> String {
    text.lines().map(|l| l.find("//").map_or(l, |i| &l[..i])).collect::<Vec<_>>().join("\n")
}

/// Splits off test code: returns the text before an inline `#[cfg(test)] mod` (which the
/// shared convention puts last), that module's name and text, and the files its `#[cfg(test)]`
/// module declarations name (by `#[path]` or by module name) with their module paths.
#[allow(clippy::type_complexity)]
fn split_tests(
    src: &Path,
    file: &Path,
    module: &[String],
    text: &str,
) -> (String, Option<(String, String)>, Vec<(PathBuf, Vec<String>)>) {
    let mut test_files = Vec::new();
    let mut keep = String::new();
    let mut rest = text;
    while let Some(i) = rest.find("#[cfg(test)]") {
        keep.push_str(&rest[..i]);
        let after = &rest[i + "#[cfg(test)]".len()..];
        // Further attributes, then the item.
        let mut item = after.trim_start();
        let mut path_attr = None;
        while item.starts_with("#[") {
            let end = item.find(']').unwrap();
            if let Some(p) = item[..end].strip_prefix("#[path = \"") {
                path_attr = Some(p.trim_end_matches('"').to_string());
            }
            item = item[end + 1..].trim_start();
        }
        let item = item.strip_prefix("pub ").unwrap_or(item);
        if let Some(decl) = item.strip_prefix("mod ") {
            let name: String = decl.chars().take_while(|c| c.is_alphanumeric() || *c == '_').collect();
            let rest_of_decl = decl[name.len()..].trim_start();
            if let Some(body) = rest_of_decl.strip_prefix('{') {
                // An inline test module: the shared convention puts it last.
                return (keep, Some((name, body.to_string())), test_files);
            }
            let mut m = module.to_vec();
            m.push(name);
            let dir = file.parent().unwrap();
            let child = match path_attr {
                Some(p) => dir.join(p),
                None => {
                    let base = src.join(m.join("/"));
                    let flat = base.with_extension("rs");
                    if flat.exists() { flat } else { base.join("mod.rs") }
                }
            };
            test_files.push((child, m));
        }
        rest = after;
    }
    keep.push_str(rest);
    (keep, None, test_files)
}

/// `a::{b, c::{d, e}}` → `a::b`, `a::c::d`, `a::c::e` (`self` inside braces is the head).
fn expand(body: &str) -> Vec<String> {
    let body: String = body.split_whitespace().collect();
    let Some(open) = body.find('{') else {
        return vec![body.split(" as ").next().unwrap().to_string()];
    };
    let head = body[..open].trim_end_matches(':').to_string();
    let inner = &body[open + 1..body.rfind('}').unwrap()];
    let (mut parts, mut depth, mut cur) = (Vec::new(), 0, String::new());
    for ch in inner.chars() {
        match ch {
            '{' => depth += 1,
            '}' => depth -= 1,
            _ => {}
        }
        if ch == ',' && depth == 0 {
            parts.push(std::mem::take(&mut cur));
        } else {
            cur.push(ch);
        }
    }
    parts.push(cur);
    let mut out = Vec::new();
    for p in parts.iter().map(|p| p.trim()).filter(|p| !p.is_empty()) {
        if p == "self" {
            out.push(head.clone());
        } else {
            out.extend(expand(&format!("{head}::{p}")));
        }
    }
    out
}

/// A path as written (`crate::a::b`, `super::super::c`, `self::d`) made absolute.
fn absolute(module: &[String], path: &str) -> Option<Vec<String>> {
    let mut parts: Vec<&str> = path.split("::").filter(|p| !p.is_empty()).collect();
    let mut base: Vec<String> = match *parts.first()? {
        "crate" => {
            parts.remove(0);
            Vec::new()
        }
        "self" => {
            parts.remove(0);
            module.to_vec()
        }
        "super" => module.to_vec(),
        _ => return None,
    };
    while parts.first() == Some(&"super") {
        parts.remove(0);
        base.pop()?;
    }
    base.extend(parts.iter().map(|s| s.split(" as ").next().unwrap().trim().to_string()));
    Some(base)
}

/// Every module path `text` names through `crate::`, `super::` or `self::`.
fn named_paths(module: &[String], text: &str) -> Vec<Vec<String>> {
    let mut out = Vec::new();
    // use statements, with their braces.
    let mut rest = text;
    while let Some(i) = rest.find("use ") {
        let before = rest[..i].chars().last();
        let tail = &rest[i + 4..];
        rest = tail;
        if before.is_some_and(|c| c.is_alphanumeric() || c == '_') {
            continue;
        }
        let tail = tail.trim_start();
        if !["crate::", "super::", "self::"].iter().any(|p| tail.starts_with(p)) {
            continue;
        }
        let Some(end) = tail.find(';') else { continue };
        out.extend(expand(&tail[..end]).iter().filter_map(|p| absolute(module, p)));
    }
    // Paths written inline.
    for key in ["crate::", "super::"] {
        let mut from = 0;
        while let Some(i) = text[from..].find(key) {
            let at = from + i;
            from = at + key.len();
            let before = text[..at].chars().last();
            if before.is_some_and(|c| c.is_alphanumeric() || c == '_' || c == ':') {
                continue;
            }
            let path: String =
                text[at..].chars().take_while(|c| c.is_alphanumeric() || *c == '_' || *c == ':').collect();
            out.extend(absolute(module, &path));
        }
    }
    out
}

/// The crate's files and their imports, test code included.
fn read_crate(src: &Path) -> BTreeMap<PathBuf, File> {
    let mut paths = Vec::new();
    rust_files(src, &mut paths);
    let texts: Vec<String> = paths.iter().map(|p| strip_comments(&std::fs::read_to_string(p).unwrap())).collect();
    // A test file's module is its declarer's child (a `#[path]` may name any file).
    let mut declared = BTreeMap::new();
    for (p, text) in paths.iter().zip(&texts) {
        declared.extend(split_tests(src, p, &module_of(src, p), text).2);
    }
    let mut files = BTreeMap::new();
    for (p, text) in paths.iter().zip(&texts) {
        let module = declared.get(p).cloned().unwrap_or_else(|| module_of(src, p));
        let (code, inline, _) = split_tests(src, p, &module, text);
        let mut named = named_paths(&module, &code);
        if let Some((name, body)) = inline {
            let inner: Vec<String> = module.iter().cloned().chain([name]).collect();
            named.extend(named_paths(&inner, &body));
        }
        files.insert(p.clone(), File { module, paths: named });
    }
    // The binary dispatches through `fxrt::`.
    files.remove(&src.join("main.rs"));
    files
}

/// File → the files it imports (the longest module path that is a file).
fn graph(files: &BTreeMap<PathBuf, File>) -> BTreeMap<PathBuf, BTreeSet<PathBuf>> {
    let by_module: BTreeMap<&[String], &PathBuf> = files.iter().map(|(p, f)| (f.module.as_slice(), p)).collect();
    let mut edges = BTreeMap::new();
    for (p, f) in files {
        let mut to = BTreeSet::new();
        for path in &f.paths {
            let target = (1..=path.len()).rev().find_map(|k| by_module.get(&path[..k]));
            if let Some(&t) = target.filter(|&&t| t != p) {
                to.insert(t.clone());
            }
        }
        edges.insert(p.clone(), to);
    }
    edges
}

/// Strongly connected sets of more than one file (Tarjan).
fn loops(edges: &BTreeMap<PathBuf, BTreeSet<PathBuf>>) -> Vec<Vec<PathBuf>> {
    struct Tarjan<'a> {
        edges: &'a BTreeMap<PathBuf, BTreeSet<PathBuf>>,
        index: BTreeMap<&'a PathBuf, usize>,
        low: BTreeMap<&'a PathBuf, usize>,
        stack: Vec<&'a PathBuf>,
        on: BTreeSet<&'a PathBuf>,
        out: Vec<Vec<PathBuf>>,
    }
    impl<'a> Tarjan<'a> {
        fn visit(&mut self, v: &'a PathBuf) {
            let i = self.index.len();
            self.index.insert(v, i);
            self.low.insert(v, i);
            self.stack.push(v);
            self.on.insert(v);
            for w in &self.edges[v] {
                if !self.index.contains_key(w) {
                    self.visit(w);
                    let lw = self.low[w];
                    let lv = self.low.get_mut(v).unwrap();
                    *lv = (*lv).min(lw);
                } else if self.on.contains(w) {
                    let iw = self.index[w];
                    let lv = self.low.get_mut(v).unwrap();
                    *lv = (*lv).min(iw);
                }
            }
            if self.low[v] == self.index[v] {
                let mut set = Vec::new();
                loop {
                    let w = self.stack.pop().unwrap();
                    self.on.remove(w);
                    set.push(w.clone());
                    if w == v {
                        break;
                    }
                }
                if set.len() > 1 {
                    set.sort();
                    self.out.push(set);
                }
            }
        }
    }
    let mut t = Tarjan {
        edges,
        index: BTreeMap::new(),
        low: BTreeMap::new(),
        stack: Vec::new(),
        on: BTreeSet::new(),
        out: Vec::new(),
    };
    for v in edges.keys() {
        if !t.index.contains_key(v) {
            t.visit(v);
        }
    }
    t.out
}

/// What breaks the architecture in the crate at `src`: loops between files, and imports from
/// a lower layer to a higher one. Also the number of edges read (so a parser that reads
/// nothing cannot pass).
fn violations(src: &Path) -> (Vec<String>, usize) {
    let files = read_crate(src);
    let edges = graph(&files);
    let name = |p: &Path| p.strip_prefix(src).unwrap().display().to_string();
    let mut out: Vec<String> = loops(&edges)
        .iter()
        .map(|set| format!("loop: {}", set.iter().map(|p| name(p)).collect::<Vec<_>>().join(" ↔ ")))
        .collect();
    for (from, to) in &edges {
        let Some(top) = files[from].module.first() else { continue };
        for t in to {
            let Some(other) = files[t].module.first() else { continue };
            if rank(other) > rank(top) {
                out.push(format!("upward: {} imports {} ({top} is below {other})", name(from), name(t)));
            }
        }
    }
    (out, edges.values().map(BTreeSet::len).sum())
}

#[test]
fn no_file_imports_in_a_loop_or_from_a_higher_layer() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let (bad, edges) = violations(&src);
    assert!(edges > 300, "only {edges} imports read: the reader of tests/architecture.rs is broken");
    assert!(bad.is_empty(), "{} violations:\n{}", bad.len(), bad.join("\n"));
}

/// The reader itself on a small crate with one loop and upward imports, in code and tests.
#[test]
fn the_check_finds_a_loop_and_an_upward_import() {
    let dir = tempfile::tempdir().unwrap();
    let src = dir.path();
    let write = |p: &str, text: &str| {
        let path = src.join(p);
        std::fs::create_dir_all(path.parent().unwrap()).unwrap();
        std::fs::write(path, text).unwrap();
    };
    write("lib.rs", "pub mod rtl;\npub mod scene;\n");
    write(
        "rtl/mod.rs",
        "pub mod a;\npub mod b;\npub use self::a::X;\n#[cfg(test)]\n#[path = \"t.rs\"]\nmod t;\n#[cfg(test)]\nmod u;\n",
    );
    // Comments may name a higher layer; test code may not. `super::` in an inline test module
    // is the file's module (read as `rtl`, it would make a loop with rtl/mod.rs).
    write(
        "rtl/a.rs",
        "use super::b::{X, self};\n// use crate::scene::rom;\n#[cfg(test)]\nmod tests { use super::*; use crate::scene::rom; }\n",
    );
    write("rtl/b.rs", "pub fn f() { super::a::g(); crate::scene::rom::h(); }\n");
    write("rtl/t.rs", "use crate::scene::rom;\n");
    write("rtl/u.rs", "use super::b::f;\n");
    write("scene/mod.rs", "pub mod rom;\n");
    write("scene/rom.rs", "pub fn h() {}\n");
    let (bad, _) = violations(src);
    assert_eq!(
        bad,
        [
            "loop: rtl/a.rs ↔ rtl/b.rs",
            "upward: rtl/a.rs imports scene/rom.rs (rtl is below scene)",
            "upward: rtl/b.rs imports scene/rom.rs (rtl is below scene)",
            "upward: rtl/t.rs imports scene/rom.rs (rtl is below scene)",
        ],
    );
}
