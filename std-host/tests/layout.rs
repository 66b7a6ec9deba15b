//! The layout of `src/` keeps the pipeline's one-way data flow: no module
//! names a sibling that names it back (directly or around a loop), and the
//! scene readers and asset loaders name no raster type.
//!
//! The module graph is read from the source text: every `crate::`,
//! `super::` and `self::` path (use groups expanded, comments skipped),
//! resolved to the deepest module it names. Within each folder, the
//! children's subtrees are collapsed to one node each, and those nodes must
//! form no cycle. (A module naming its own descendants or its ancestors is
//! not an edge between siblings.)

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

type Module = Vec<String>;

fn sources(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let p = entry.unwrap().path();
        if p.is_dir() {
            if p.file_name().is_some_and(|n| n != "bin") {
                sources(&p, out);
            }
        } else if p.extension().is_some_and(|e| e == "rs") {
            out.push(p);
        }
    }
}

fn module_of(src: &Path, file: &Path) -> Module {
    let rel = file.strip_prefix(src).unwrap().with_extension("");
    let mut m: Module = rel
        .components()
        .map(|c| c.as_os_str().to_string_lossy().into_owned())
        .collect();
    if m.last().is_some_and(|l| l == "mod" || l == "lib") {
        m.pop();
    }
    m
}

/// The source without `//` comments (doc comments included).
fn code(text: &str) -> String {
    text.lines()
        .map(|l| l.find("//").map_or(l, |i| &l[..i]))
        .collect::<Vec<_>>()
        .join("\n")
}

/// `a::{b, c::{d, e}}` as `a::b`, `a::c::d`, `a::c::e`.
fn expand(path: &str) -> Vec<String> {
    let Some(open) = path.find('{') else {
        return vec![path.to_owned()];
    };
    let (head, body) = (
        &path[..open],
        &path[open + 1..path.rfind('}').unwrap_or(path.len())],
    );
    let mut parts = Vec::new();
    let (mut depth, mut cur) = (0, String::new());
    for ch in body.chars() {
        match ch {
            '{' => depth += 1,
            '}' => depth -= 1,
            ',' if depth == 0 => {
                parts.push(std::mem::take(&mut cur));
                continue;
            }
            _ => {}
        }
        cur.push(ch);
    }
    parts.push(cur);
    parts
        .iter()
        .map(|p| p.trim())
        .filter(|p| !p.is_empty())
        .flat_map(|p| expand(p).into_iter().map(move |q| format!("{head}{q}")))
        .collect()
}

/// The deepest module of `modules` that `path`, written in `from`, names.
fn resolve(modules: &BTreeSet<Module>, from: &Module, path: &str) -> Module {
    let parts: Vec<&str> = path
        .split("::")
        .map(|p| p.trim().split(" as ").next().unwrap_or("").trim())
        .collect();
    let (mut base, rest) = if parts[0] == "crate" {
        (Module::new(), &parts[1..])
    } else {
        let mut base = from.clone();
        let mut i = 0;
        while i < parts.len() && (parts[i] == "super" || parts[i] == "self") {
            if parts[i] == "super" {
                base.pop();
            }
            i += 1;
        }
        (base, &parts[i..])
    };
    for p in rest {
        let mut next = base.clone();
        next.push((*p).to_owned());
        if !modules.contains(&next) {
            break;
        }
        base = next;
    }
    base
}

/// The crate's modules, the paths between them, and each module's code.
struct Graph {
    modules: BTreeSet<Module>,
    edges: BTreeSet<(Module, Module)>,
    texts: BTreeMap<Module, String>,
}

fn graph() -> Graph {
    let src = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = Vec::new();
    sources(&src, &mut files);
    let texts: BTreeMap<Module, String> = files
        .iter()
        .map(|f| {
            (
                module_of(&src, f),
                code(&std::fs::read_to_string(f).unwrap()),
            )
        })
        .collect();
    let modules: BTreeSet<Module> = texts.keys().cloned().collect();
    let mut edges = BTreeSet::new();
    for (m, text) in &texts {
        let mut paths = Vec::new();
        // `use` items: a line that starts one (after any visibility), up to
        // its `;`.
        let mut rest = text.as_str();
        while let Some(at) = rest.find("use ") {
            let line_start = rest[..at].rfind('\n').map_or(0, |i| i + 1);
            let before = rest[line_start..at].trim();
            let item = before.is_empty() || before.starts_with("pub");
            let after = &rest[at + 4..];
            let end = after.find(';').unwrap_or(after.len());
            if item {
                let stmt: String = after[..end]
                    .split_whitespace()
                    .collect::<Vec<_>>()
                    .join(" ");
                paths.extend(expand(&stmt));
            }
            rest = if item { &after[end..] } else { after };
        }
        for (i, _) in text.match_indices("::") {
            let start = text[..i]
                .rfind(|c: char| !(c.is_alphanumeric() || c == '_' || c == ':'))
                .map_or(0, |s| s + 1);
            let end = text[i..]
                .find(|c: char| !(c.is_alphanumeric() || c == '_' || c == ':'))
                .map_or(text.len(), |e| i + e);
            paths.push(text[start..end].to_owned());
        }
        for p in paths {
            let first = p.split("::").next().unwrap_or("");
            if matches!(first, "crate" | "super" | "self") {
                edges.insert((m.clone(), resolve(&modules, m, &p)));
            }
        }
    }
    Graph {
        modules,
        edges,
        texts,
    }
}

/// The sibling modules of each folder that reach each other.
fn cycles(modules: &BTreeSet<Module>, edges: &BTreeSet<(Module, Module)>) -> Vec<String> {
    let folders: BTreeSet<Module> = modules
        .iter()
        .flat_map(|m| (0..m.len()).map(|k| m[..k].to_vec()))
        .collect();
    let mut found = Vec::new();
    for folder in &folders {
        let n = folder.len();
        let mut next: BTreeMap<&str, BTreeSet<&str>> = BTreeMap::new();
        for (a, b) in edges {
            if a.len() > n
                && b.len() > n
                && a[..n] == folder[..]
                && b[..n] == folder[..]
                && a[n] != b[n]
            {
                next.entry(&a[n]).or_default().insert(&b[n]);
            }
        }
        // Each child that reaches itself through its siblings.
        for start in next.keys() {
            let mut seen = BTreeSet::new();
            let mut todo: Vec<&str> = next[start].iter().copied().collect();
            while let Some(x) = todo.pop() {
                if x == *start {
                    found.push(format!("crate::{}: {start}", folder.join("::")));
                    break;
                }
                if seen.insert(x) {
                    todo.extend(next.get(x).into_iter().flatten().copied());
                }
            }
        }
    }
    found
}

#[test]
fn no_module_reaches_a_sibling_that_reaches_it() {
    let Graph { modules, edges, .. } = graph();
    assert!(modules.len() > 40, "{} modules found", modules.len());
    assert!(edges.len() > 100, "{} paths found", edges.len());
    let found = cycles(&modules, &edges);
    assert!(
        found.is_empty(),
        "modules on a cycle of siblings: {found:#?}"
    );
}

#[test]
fn the_cycle_check_finds_a_cycle() {
    let m = |s: &str| s.split("::").map(str::to_owned).collect::<Module>();
    let modules: BTreeSet<Module> = ["a", "a::x", "b", "c"].iter().map(|s| m(s)).collect();
    let edges: BTreeSet<(Module, Module)> = [("a::x", "b"), ("b", "c"), ("c", "a")]
        .iter()
        .map(|(x, y)| (m(x), m(y)))
        .collect();
    assert_eq!(cycles(&modules, &edges).len(), 3);
    assert_eq!(
        resolve(&modules, &m("a::x"), "super::super::b::Thing"),
        m("b")
    );
    assert_eq!(
        expand("super::{a, b::{c, d}}"),
        ["super::a", "super::b::c", "super::b::d"]
    );
}

#[test]
fn scene_readers_and_asset_loaders_name_no_raster_type() {
    let Graph { edges, texts, .. } = graph();
    let raster_side = ["frame", "fit", "voxelize", "trace", "render", "output"];
    for (m, text) in &texts {
        if !matches!(m.first().map(String::as_str), Some("scene" | "assets")) {
            continue;
        }
        for (a, b) in &edges {
            if a == m {
                let to = b.first().map_or("", String::as_str);
                assert!(
                    !raster_side.contains(&to),
                    "crate::{} names crate::{}",
                    m.join("::"),
                    b.join("::")
                );
            }
        }
        for ty in [
            "RasterFrame",
            "VoxelSink",
            "store::Texture",
            "Extent",
            "RasterMut",
        ] {
            assert!(
                !text.contains(ty),
                "crate::{} names the raster type {ty}",
                m.join("::")
            );
        }
    }
}
