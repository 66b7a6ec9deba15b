//! TOML scenes: what NFF cannot say.
//!
//! A TOML scene has a `[camera]`, `[[light]]`s, named `[material.NAME]`s
//! (optionally with a `texture`), named volume data `[volume.NAME]`, named
//! CSG leaves `[solid.NAME]` and a list of `[[object]]`s. Each object has
//! exactly one shape key and a `material` name:
//!
//! | key | what |
//! | --- | --- |
//! | `sphere = { centre, radius }` | NFF `s` |
//! | `cone = { base, base_radius, apex, apex_radius, capped }` | NFF `c` (open); `capped = true` makes it a closed solid |
//! | `polygon = [[x, y, z], …]` | NFF `p` |
//! | `box = { min, max }` | an axis-aligned box (six polygons) |
//! | `torus = { centre, axis, major, minor }` | a torus |
//! | `bezier = { file, steps }` | the bicubic patches of a `.bpt` file, each tessellated into `steps × steps` quads with the patch's exact normals (NFF `pp`) |
//! | `mesh = { file, smooth }` | an OBJ triangle mesh (`tobj`); `smooth` interpolates the file's (or averaged) vertex normals |
//! | `nff = "file.nff"` | every object, light and material of an NFF file (its view is ignored) |
//! | `volume = "NAME"` | a volume of `[volume.NAME]`: its iso-surface with gray-level normals, or direct volume rendering (`render` below) |
//! | `vox = { file, position, cell }` | a MagicaVoxel model |
//! | `csg = { difference = ["a", { union = ["b", "c"] }] }` | a CSG tree over `[solid.NAME]`s |
//!
//! Objects may also give `transform = { translate, scale, rotate_x, rotate_y, rotate_z }`
//! for meshes, Bézier patches and polygons (applied as scale, then the
//! rotations in x, y, z order, in degrees, then the translation).
//!
//! Paths are relative to the scene file's directory. A CSG tree's leaves
//! are names of `[solid.NAME]` tables, which cannot refer to CSG trees, so
//! a tree has no cycles by construction. A volume may take part in a CSG
//! tree only as the left operand of a difference or intersection whose
//! other operand has no volume (the paper's box cut out of the head): the
//! volume's voxels inside (or outside) the other operand count as
//! transparent before its boundary is found.
//!
//! A `[volume.NAME]` takes `iso`, `opacity = [[value, alpha], …]` and
//! `colours = [[value, r, g, b], …]` (values strictly increasing, alpha
//! and channels in 0–1) and `render = "iso" | "direct"`. `"iso"` draws
//! the iso-surface, the opacity ramp cutting it at ½; `"direct"` composites
//! the samples with the ramps as the transfer function
//! ([`crate::assets::volume::classify`], *Direct volume rendering*) and
//! needs `opacity`. Without `render`, a volume is rendered directly when an
//! opacity point lies strictly between 0 and 1 (a partial opacity only
//! direct rendering can show) and as an iso-surface otherwise. A volume
//! rendered directly cannot be a CSG leaf.
//!
//! # Errors
//! Unknown keys (`deny_unknown_fields`), wrong types (arrays of the wrong
//! length too, longer or shorter), missing keys, bad
//! values and the errors of the files a scene refers to are
//! [`SceneError::Toml`] naming the scene file, the line and column of the
//! value itself (from toml's spans) and its full key path
//! (`object[2].sphere.radius`, arrays counted from 0), inside inline
//! tables too. Sizes are checked before anything is
//! allocated: file sizes against their readers' limits, volume and vox
//! dimensions against [`Options`].

mod build;
mod csg;
mod material;
mod object;
mod schema;
mod spans;
mod volume;

use std::collections::BTreeMap;
use std::path::Path;
use std::sync::Arc;

use self::build::Builder;
use self::schema::Doc;
use self::spans::Spans;
use super::Scene;
use super::error::SceneError;
use super::text::{byte_loc, read_text};

/// Largest TOML scene file read, in bytes.
pub const MAX_FILE_BYTES: u64 = 16 << 20;

/// Limits of a TOML scene, checked before allocating.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Options {
    /// Limits for each volume's samples.
    pub volume: crate::assets::volume::Limits,
    /// Most `.vox` file bytes.
    pub max_vox_bytes: u64,
    /// Most vertices over all polygons (meshes, patches, NFF includes).
    pub max_vertices: usize,
    /// Most `steps` per Bézier patch side.
    pub max_patch_steps: u32,
    /// Whether files may be read at all (the fuzz target parses without).
    pub read_files: bool,
    /// Most bytes the scene's own data may take together: the samples of
    /// all its volumes and [`VERTEX_BYTES`] per polygon vertex (the memory
    /// limit `--max-memory` sets; half the machine's memory by default).
    pub max_memory: u64,
}

/// Bytes a polygon vertex takes in a [`Scene`]: its position and its
/// normal.
pub const VERTEX_BYTES: u64 = 2 * std::mem::size_of::<glam::DVec3>() as u64;

impl Default for Options {
    fn default() -> Self {
        Self {
            volume: crate::assets::volume::Limits::default(),
            max_vox_bytes: 256 << 20,
            max_vertices: 1 << 26,
            max_patch_steps: 64,
            read_files: true,
            max_memory: crate::memory::default_max_memory(),
        }
    }
}

/// Reads the TOML scene at `path`.
///
/// # Errors
/// [`SceneError`] naming the file, and the line, column and key for
/// everything wrong inside it (module docs).
pub fn load(path: &Path, opts: &Options) -> Result<Scene, SceneError> {
    let name: Arc<str> = Arc::from(path.to_string_lossy().as_ref());
    let text = read_text(path, &name, "a TOML scene", MAX_FILE_BYTES)?;
    let dir = path.parent().map(Path::to_path_buf).unwrap_or_default();
    parse(&name, &text, &dir, opts)
}

/// Parses TOML scene text; `file` names it in messages, relative paths are
/// taken from `dir`.
///
/// # Errors
/// As [`load`].
pub fn parse(file: &str, text: &str, dir: &Path, opts: &Options) -> Result<Scene, SceneError> {
    let file: Arc<str> = Arc::from(file);
    let doc: Doc = ::toml::from_str(text).map_err(|e| {
        let span = e.span().unwrap_or(0..0);
        let at = span.start;
        // The full path of the key or table at the error (an unknown key
        // inside an inline table, a wrong-typed value, a table missing a
        // key); the key at or before the error for a document that does
        // not parse.
        let spans = Spans::new(text);
        let path = spans.path_of(span);
        let mut msg = e.message().trim().to_owned();
        if spans.parsed() && path.is_empty() && msg == "missing field `camera`" {
            msg.push_str(": every scene needs a [camera] table (from, at, angle, resolution)");
        }
        SceneError::Toml {
            loc: byte_loc(&file, text.as_bytes(), at),
            key: if path.is_empty() && !spans.parsed() {
                key_near(text, at)
            } else {
                path
            },
            msg,
        }
    })?;
    Builder {
        file,
        text,
        spans: Spans::new(text),
        entry: std::cell::Cell::new(None),
        dir: dir.to_path_buf(),
        opts: *opts,
        materials: BTreeMap::new(),
        volumes: BTreeMap::new(),
        volume_bytes: std::cell::Cell::new(0),
        texture_bytes: std::cell::Cell::new(0),
        cut_budget: std::cell::Cell::new(super::polygon::CutBudget::scene()),
    }
    .build(&doc)
}

/// In a document that does not parse: the key whose value starts at byte
/// `at` (`key = value` on that line), or the key that starts at `at` (a
/// duplicate key), or else the key of the line `at` is on (an error deep
/// inside its value, such as nesting past toml's limit), or empty. A key
/// at the start of its line is given with the path of the table header
/// above it (`object[1].material`, counting `[[object]]` headers from 0),
/// a table header with its path.
fn key_near(text: &str, at: usize) -> String {
    let is_key = |c: char| c.is_ascii_alphanumeric() || c == '_' || c == '-' || c == '.';
    let Some(before) = text.get(..at) else {
        return String::new();
    };
    let line_start = before.rfind('\n').map_or(0, |i| i + 1);
    let line = &before[line_start..];
    let rest = text[at..].split('\n').next().unwrap_or("");
    // The key this line starts with (not a table header).
    let whole = format!("{line}{rest}");
    let lead = whole
        .split_once('=')
        .map(|(lhs, _)| lhs.trim())
        .filter(|k| !k.is_empty() && k.chars().all(is_key))
        .unwrap_or("");
    let with_table = |key: &str| match table_path(&text[..line_start]) {
        Some(t) => format!("{t}.{key}"),
        None => key.to_owned(),
    };
    if let Some(lhs) = line.trim_end().strip_suffix('=') {
        let lhs = lhs.trim_end();
        let start = lhs.rfind(|c: char| !is_key(c)).map_or(0, |i| i + 1);
        let key = lhs.get(start..).unwrap_or("");
        return if !key.is_empty() && key == lead && lhs.trim_start() == key {
            with_table(key)
        } else {
            key.to_owned()
        };
    }
    let after = text.get(at..).unwrap_or("");
    let key = &after[..after.find(|c: char| !is_key(c)).unwrap_or(after.len())];
    // Only a key followed by `=`.
    if !key.is_empty() && after[key.len()..].trim_start().starts_with('=') {
        if key == lead && line.trim().is_empty() {
            with_table(key)
        } else if let Some(inner) = (!lead.is_empty())
            .then(|| line.split_once('='))
            .flatten()
            .and_then(|(_, value)| inline_path(value))
        {
            // A key inside the line's inline tables: the path through them.
            format!("{}{inner}.{key}", with_table(lead))
        } else {
            key.to_owned()
        }
    } else if !lead.is_empty() {
        with_table(lead)
    } else if whole.trim_start().starts_with('[') {
        // A table header (defined twice, say): the table's own path.
        let end = line_start + whole.len();
        table_path(text.get(..end).unwrap_or("")).unwrap_or_default()
    } else {
        String::new()
    }
}

/// The path, from the value that `value` starts, to the inline table open
/// at its end (`.sphere`, `.difference[1]`, empty at the value's own
/// table): each open table adds the key it is the value of, each open
/// array the index of its element; `None` when `value` is not inside an
/// inline table.
fn inline_path(value: &str) -> Option<String> {
    // Open containers: an inline table or an array, with the path's
    // length when it opened.
    enum Open {
        Table,
        Array(usize),
    }
    let mut open: Vec<(Open, usize)> = Vec::new();
    let mut path: Vec<String> = Vec::new();
    let mut word = String::new();
    let mut chars = value.chars();
    while let Some(c) = chars.next() {
        match c {
            '"' | '\'' => {
                // A quoted key or a string value: skipped whole.
                let mut quoted = String::new();
                let mut escaped = false;
                for q in chars.by_ref() {
                    if q == c && !escaped {
                        break;
                    }
                    escaped = c == '"' && q == '\\' && !escaped;
                    quoted.push(q);
                }
                word = quoted;
            }
            '=' => {
                if matches!(open.last(), Some((Open::Table, _))) && !word.is_empty() {
                    path.push(format!(".{}", std::mem::take(&mut word)));
                }
            }
            '{' => open.push((Open::Table, path.len())),
            '[' => {
                open.push((Open::Array(0), path.len()));
                path.push("[0]".to_owned());
            }
            ',' => match open.last_mut() {
                Some((Open::Table, at)) => path.truncate(*at),
                Some((Open::Array(i), at)) => {
                    *i = i.saturating_add(1);
                    path.truncate(*at);
                    path.push(format!("[{i}]"));
                }
                None => {}
            },
            '}' | ']' => {
                if let Some((_, at)) = open.pop() {
                    path.truncate(at);
                }
            }
            c if c.is_whitespace() => continue,
            c => {
                if !(c.is_ascii_alphanumeric() || c == '_' || c == '-' || c == '.') {
                    word.clear();
                } else {
                    word.push(c);
                }
                continue;
            }
        }
        if c != '"' && c != '\'' {
            word.clear();
        }
    }
    matches!(open.last(), Some((Open::Table, _))).then(|| path.concat())
}

/// The path of the table that the text after `before` continues: its last
/// header, `[name]` as `name`, the k-th `[[name]]` as `name[k]` (from 0);
/// `None` at the top level.
fn table_path(before: &str) -> Option<String> {
    let header = |l: &str| {
        let l = l.trim();
        let l = l.split_once('#').map_or(l, |(h, _)| h.trim_end());
        l.starts_with('[').then(|| l.to_owned())
    };
    let last = before.lines().rev().find_map(header)?;
    if let Some(name) = last.strip_prefix("[[").and_then(|n| n.strip_suffix("]]")) {
        let k = before
            .lines()
            .filter_map(header)
            .filter(|h| *h == last)
            .count();
        Some(format!("{}[{}]", name.trim(), k.saturating_sub(1)))
    } else {
        let name = last.strip_prefix('[')?.strip_suffix(']')?;
        (!name.contains(['[', ']'])).then(|| name.trim().to_owned())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const CAMERA: &str =
        "[camera]\nfrom = [0, -6, 2]\nat = [0, 0, 0]\nangle = 40\nresolution = [8, 8]\n";
    const OBJECT: &str =
        "[material.m]\n[[object]]\nmaterial = \"m\"\nsphere = { centre = [0, 0, 0], radius = 1 }\n";

    /// Errors of a document that does not parse name the key with the
    /// table it is in, as far as the text shows it: a duplicate key, a bad
    /// value, nesting past toml's limit (deep inside the value, at the key
    /// of its line).
    #[test]
    fn unparsed_documents_name_the_key_and_its_table() {
        let two = format!("{CAMERA}{OBJECT}[[object]]\nmaterial = \"m\"\nmaterial = \"m\"\n");
        let e = error(&two);
        assert!(
            e.starts_with("x.toml:12:1: object[1].material: duplicate key"),
            "{e}"
        );
        let deep = format!(
            "{CAMERA}{OBJECT}[[object]]\nmaterial = \"m\"\ncsg = {}\"a\"{}\n",
            "{ union = [\"a\", ".repeat(60),
            "] }".repeat(60)
        );
        let e = error(&deep);
        assert!(e.starts_with("x.toml:12:"), "{e}");
        assert!(e.contains(": object[1].csg: "), "{e}");
        // A key inside inline tables: the path through them.
        let e = error(&format!("{CAMERA}[[light]]\nposition = {{ x = }}\n"));
        assert!(e.starts_with("x.toml:7:"), "{e}");
        let e = error(&format!(
            "{CAMERA}[material.m]\n[[object]]\nmaterial = \"m\"\nsphere = {{ centre = [0,0,0], radius = 1, radius = 2 }}\n"
        ));
        assert!(
            e.starts_with("x.toml:9:42: object[0].sphere.radius: duplicate key"),
            "{e}"
        );
        let e = error(&format!(
            "{CAMERA}[material.m]\n[[object]]\nmaterial = \"m\"\ncsg = {{ difference = [\"a\", {{ union = [\"b\", \"c\"], union = [] }}] }}\n"
        ));
        assert!(
            e.contains(": object[0].csg.difference[1].union: duplicate key"),
            "{e}"
        );
        let e = error(&format!(
            "{CAMERA}[volume.v]\nmetaballs = {{ dims = [2, 2, 2], \"min\" = [0, 0, 0], min = [1, 1, 1] }}\n"
        ));
        assert!(e.contains(": volume.v.metaballs.min: duplicate key"), "{e}");
        // A table defined twice: the table; a broken header: nothing.
        let e = error(&format!("{CAMERA}{OBJECT}[material.m]\n"));
        assert!(
            e.starts_with("x.toml:10:11: material.m: duplicate key"),
            "{e}"
        );
        let e = error(&format!("{CAMERA}[[object]\n"));
        assert!(e.starts_with("x.toml:6:10: unclosed array table"), "{e}");
        let e = error(&CAMERA.replace("angle = 40", "angle = 4 0"));
        assert!(e.starts_with("x.toml:4:"), "{e}");
        assert!(e.contains(": camera.angle: "), "{e}");
    }

    /// The error of `text`, read without files.
    fn error(text: &str) -> String {
        let opts = Options {
            read_files: false,
            ..Options::default()
        };
        match parse("x.toml", text, Path::new("."), &opts) {
            Ok(_) => panic!("accepted:\n{text}"),
            Err(e) => e.to_string(),
        }
    }

    /// `text` with `from` replaced by `to` is refused at the first `[` of
    /// `to` (1-based line and column), naming `key` and the lengths.
    fn assert_refused(text: &str, from: &str, to: &str, key: &str, found: usize, want: usize) {
        assert_eq!(text.matches(from).count(), 1, "{from} in\n{text}");
        let bad = text.replace(from, to);
        let at = bad.find(to).unwrap() + to.find('[').unwrap();
        let line = bad[..at].matches('\n').count() + 1;
        let col = at - bad[..at].rfind('\n').map_or(0, |i| i + 1) + 1;
        let msg = error(&bad);
        assert_eq!(
            msg,
            format!(
                "x.toml:{line}:{col}: {key}: invalid length {found}, expected an array of length {want}"
            ),
            "{bad}"
        );
    }

    #[test]
    fn too_long_fixed_arrays_are_refused_with_location_and_key() {
        let scene = format!("{CAMERA}{OBJECT}");
        // The reproducer: a sphere centre with extra elements of any type.
        let centre = "centre = [0, 0, 0]";
        assert_refused(
            &scene,
            centre,
            "centre = [0, 0, 0, [1], {a=1}]",
            "object[0].sphere.centre",
            5,
            3,
        );
        assert_refused(&scene, "[8, 8]", "[64, 64, 64]", "camera.resolution", 3, 2);
        assert_refused(&scene, "[0, -6, 2]", "[0, -6, 2, 5]", "camera.from", 4, 3);
        let colour = format!(
            "{CAMERA}[material.m]\ncolour = [0.8, 0.5, 0.3]\n{}",
            &OBJECT[13..]
        );
        assert_refused(
            &colour,
            "[0.8, 0.5, 0.3]",
            "[0.8, 0.5, 0.3, 1]",
            "material.m.colour",
            4,
            3,
        );
        let light =
            format!("{CAMERA}[[light]]\nposition = [3, -4, 8]\ncolour = [1, 1, 1]\n{OBJECT}");
        assert_refused(&light, "[1, 1, 1]", "[1, 1, 1, 1]", "light[0].colour", 4, 3);
        assert_refused(
            &light,
            "[3, -4, 8]",
            "[3, -4, 8, 0]",
            "light[0].position",
            4,
            3,
        );
        let background = format!("background = [0, 0, 0.5]\n{CAMERA}{OBJECT}");
        assert_refused(
            &background,
            "[0, 0, 0.5]",
            "[0, 0, 0.5, 0]",
            "background",
            4,
            3,
        );
        let raw = format!(
            "{CAMERA}{OBJECT}[volume.v]\nraw = {{ file = \"raw16.bin\", dims = [16, 16, 16], type = \"uint8\" }}\niso = 100\n"
        );
        assert_refused(
            &raw,
            "[16, 16, 16]",
            "[16,16,16,1]",
            "volume.v.raw.dims",
            4,
            3,
        );
        let polygon = format!(
            "{CAMERA}[material.m]\n[[object]]\nmaterial = \"m\"\npolygon = [[0, 0, 0], [1, 0, 0], [0, 1, 0]]\n"
        );
        assert_refused(
            &polygon,
            "[1, 0, 0]",
            "[1, 0, 0, 7]",
            "object[0].polygon[1]",
            4,
            3,
        );
        // Nested: one colour of a checker's pair, and the pair itself.
        let checker = format!(
            "{CAMERA}[material.m]\ntexture = {{ checker = {{ size = 1, colours = [[0, 0, 0], [255, 255, 255]] }} }}\n{}",
            &OBJECT[13..]
        );
        let key = "material.m.texture.checker.colours";
        assert_refused(
            &checker,
            "[255, 255, 255]",
            "[255, 255, 255, 9]",
            &format!("{key}[1]"),
            4,
            3,
        );
        assert_refused(
            &checker,
            "[[0, 0, 0], [255, 255, 255]]",
            "[[0, 0, 0], [255, 255, 255], [1, 1, 1]]",
            key,
            3,
            2,
        );
        // Lists of fixed-length points.
        let ramps = format!(
            "{CAMERA}{OBJECT}[volume.v]\nmetaballs = {{ dims = [8, 8, 8], min = [-1, -1, -1], max = [1, 1, 1], balls = [[0, 0, 0, 1, 1]] }}\nopacity = [[0, 0], [1, 1]]\ncolours = [[0, 1, 1, 1]]\n"
        );
        assert_refused(
            &ramps,
            "[0, 0, 0, 1, 1]",
            "[0, 0, 0, 1, 1, 1]",
            "volume.v.metaballs.balls[0]",
            6,
            5,
        );
        assert_refused(&ramps, "[1, 1]]", "[1, 1, 0]]", "volume.v.opacity[1]", 3, 2);
        assert_refused(
            &ramps,
            "[0, 1, 1, 1]",
            "[0, 1, 1, 1, 1]",
            "volume.v.colours[0]",
            5,
            4,
        );
    }

    #[test]
    fn too_short_fixed_arrays_are_refused_and_exact_ones_accepted() {
        let scene = format!("{CAMERA}{OBJECT}");
        assert_refused(
            &scene,
            "centre = [0, 0, 0]",
            "centre = [0, 0]",
            "object[0].sphere.centre",
            2,
            3,
        );
        assert_refused(&scene, "[8, 8]", "[]", "camera.resolution", 0, 2);
        let opts = Options {
            read_files: false,
            ..Options::default()
        };
        let s = parse("x.toml", &scene, Path::new("."), &opts).unwrap();
        assert_eq!(s.view.resolution, [8, 8]);
    }

    /// Every fixed-length array of the schema is an [`schema::Exact`]: a
    /// plain `[T; N]` would silently drop extra elements.
    #[test]
    fn the_schema_has_no_plain_arrays() {
        let src = include_str!("schema.rs");
        for ty in [
            "f64", "f32", "u8", "u16", "u32", "u64", "i32", "i64", "bool", "String",
        ] {
            assert!(
                !src.contains(&format!("[{ty};")),
                "a plain [{ty}; N] in schema.rs"
            );
        }
    }
}
