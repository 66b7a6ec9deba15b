//! Triangle meshes from Wavefront OBJ files, read with the `tobj` crate.
//!
//! Faces are cut into triangles as NFF polygons are
//! ([`super::polygon`]: the fan of a convex face, the ears of a non-convex
//! one), points and lines are ignored, and
//! per-vertex normals (`vn`) are kept when every face gives them. A UTF-8
//! byte-order mark at the start of the file is skipped (columns on the
//! first line count from after it, as editors show them). Groups,
//! objects and materials (`.mtl`) do not matter here: the scene gives the
//! mesh one material.
//!
//! # Bad input
//! Before `tobj` parses the file, a scan of its lines checks, reporting
//! the line and column: every face's indices against the vertex,
//! texture-coordinate and normal counts (1-based, negative indices
//! counting back from the latest element, 0 is never valid; positive ones
//! may name elements defined later, but before the face's object ends at
//! the next `o` or `g` line, where tobj resolves its faces), which tobj
//! reports without a location, or at the line that ends the object; that every face (`f`) has at least three
//! vertices (tobj takes shorter ones for points and lines and drops them)
//! and at most [`MAX_FACE_VERTICES`];
//! and that every vertex (`v`, including `x y z` divided by a weight `w`)
//! and normal (`vn`) coordinate is finite in single precision, in which
//! tobj stores them (so `1e308` is out of range, `nan` not finite). tobj
//! reads a line element (`l`) of three or more vertices as a face; it is
//! hidden from tobj so that lines stay ignored. Errors tobj finds on a
//! line (a malformed number, say) are located on the line tobj was
//! reading. Files are capped at [`MAX_FILE_BYTES`] and meshes at
//! [`MAX_TRIANGLES`] triangles.

use std::borrow::Cow;
use std::io::{BufRead, Read};
use std::path::Path;
use std::sync::Arc;

use glam::DVec3;

use super::error::SceneError;
use super::loc::SourceLoc;
use super::polygon::CutBudget;
use super::text::{read_text, without_bom};

/// The most vertices a face may have.
pub const MAX_FACE_VERTICES: usize = super::polygon::MAX_NONCONVEX_VERTICES;

/// Largest OBJ file read, in bytes.
pub const MAX_FILE_BYTES: u64 = 1 << 30;
/// Most triangles one mesh may have.
pub const MAX_TRIANGLES: usize = 1 << 24;

/// A triangle mesh.
#[derive(Clone, Debug, PartialEq)]
pub struct Mesh {
    /// Vertex positions.
    pub positions: Vec<DVec3>,
    /// Per-vertex normals (parallel to `positions`), if the file gives a
    /// normal for every face vertex.
    pub normals: Option<Vec<DVec3>>,
    /// Triangles as indices into `positions`, in the file's winding.
    pub triangles: Vec<[u32; 3]>,
}

/// Reads the OBJ file at `path`; `name` names it in messages. No memory
/// limit beyond [`MAX_FILE_BYTES`] (the caller's: [`load_within`]).
///
/// # Errors
/// [`SceneError`]s naming the file (and line and column where there is
/// one): I/O, size, binary data, an out-of-range index, a line tobj cannot
/// parse, a non-finite coordinate, a mesh without faces or with more than
/// [`MAX_TRIANGLES`] triangles.
pub fn load(path: &Path, name: &str) -> Result<Mesh, SceneError> {
    load_within(path, name, u64::MAX, &mut CutBudget::scene())
}

/// [`load`], refusing a file whose text, or whose elements once read
/// ([`READ_BYTES`] per element), would take more than `max_memory` bytes,
/// before they are read, and cutting its non-convex faces from the
/// scene's `budget`.
///
/// # Errors
/// As [`load`], and [`SceneError::FileTooLarge`] or
/// [`SceneError::TooMuchMemory`] for the memory limit, a
/// [`SceneError::Invalid`] face beyond the budget.
pub fn load_within(
    path: &Path,
    name: &str,
    max_memory: u64,
    budget: &mut CutBudget,
) -> Result<Mesh, SceneError> {
    let name: Arc<str> = Arc::from(name);
    let text = read_text(path, &name, "an OBJ mesh", MAX_FILE_BYTES.min(max_memory)).map_err(
        |e| match e {
            // The memory limit, not the format's, refused it.
            SceneError::FileTooLarge { file, size, .. } if max_memory < MAX_FILE_BYTES => {
                SceneError::TooMuchMemory {
                    file,
                    what: format!("its {size} bytes of text"),
                    bytes: size,
                    limit: max_memory,
                }
            }
            e => e,
        },
    )?;
    parse_within(&name, &text, max_memory, budget)
}

/// Bytes that reading an OBJ file into a scene takes per element, beside
/// its text: per vertex, normal or texture coordinate line (the reader's
/// `f32`s), and per face corner (the reader's index and its lookup of
/// distinct corners, this module's `f64` positions, normals and
/// triangles, and the scene's vertex with its normal, which the mesh
/// becomes while it is still held).
pub const READ_BYTES: [u64; 2] = [12, 96];

/// The line (from 1) of face `k` (from 0) of `text`: its `k`-th `f`
/// statement, as the reader gives the faces in the file's order (1 when
/// there are fewer).
fn face_line(text: &str, k: usize) -> usize {
    text.lines()
        .enumerate()
        .filter(|(_, l)| l.split_whitespace().next() == Some("f"))
        .nth(k)
        .map_or(1, |(i, _)| i + 1)
}

fn invalid(
    file: &Arc<str>,
    line: usize,
    column: usize,
    field: &'static str,
    problem: &'static str,
) -> SceneError {
    SceneError::Invalid {
        loc: SourceLoc::new(
            Arc::clone(file),
            u32::try_from(line).unwrap_or(u32::MAX),
            u32::try_from(column).unwrap_or(u32::MAX),
        ),
        field,
        problem,
    }
}

/// The words of `line` with their 1-based columns (in characters),
/// counted on from the previous word: linear in the line's length however
/// many words it holds (a face of 200,000 vertices is one line).
fn words(line: &str) -> impl Iterator<Item = (usize, &str)> + Clone {
    // (byte offset, column) of the previous word's start.
    let mut last = (0, 1);
    line.split_whitespace().map(move |w| {
        let at = (w.as_ptr() as usize).saturating_sub(line.as_ptr() as usize);
        let column = last.1 + line.get(last.0..at).map_or(0, |s| s.chars().count());
        last = (at, column);
        (column, w)
    })
}

/// Why a number tobj reads as `f32` is not a finite `f32`, if it is not.
fn non_finite(word: &str, value: f32) -> Option<&'static str> {
    if value.is_finite() {
        None
    } else if word.parse::<f64>().is_ok_and(f64::is_finite) {
        Some(
            "coordinate out of range: meshes are read in single precision (magnitude at most 3.4e38)",
        )
    } else {
        Some("coordinate is not finite (NaN or infinity)")
    }
}

/// Checks `x y z [w]` of a `v` line (words after the `v`) or `x y z` of a
/// `vn` line as tobj reads them: every coordinate, the weight `w` and the
/// coordinates divided by `w` must be finite `f32`s. Words tobj cannot
/// parse are left to tobj, which reports them on this line.
fn check_coordinates<'a>(
    mut words: impl Iterator<Item = (usize, &'a str)>,
    with_weight: bool,
) -> Result<(), (usize, &'static str)> {
    let mut xyz = [0f32; 3];
    for c in &mut xyz {
        let Some((col, w)) = words.next() else {
            return Ok(());
        };
        let Ok(v) = w.parse::<f32>() else {
            return Ok(());
        };
        if let Some(why) = non_finite(w, v) {
            return Err((col, why));
        }
        *c = v;
    }
    if !with_weight {
        return Ok(());
    }
    // One more number is the weight w (three more are a colour).
    let (Some((col, w)), None) = (words.next(), words.next()) else {
        return Ok(());
    };
    let Ok(v) = w.parse::<f32>() else {
        return Ok(());
    };
    if let Some(why) = non_finite(w, v) {
        return Err((col, why));
    }
    if v != 0.0 && xyz.iter().any(|c| !(c / v).is_finite()) {
        return Err((
            col,
            "coordinate out of range once divided by w: meshes are read in single precision (magnitude at most 3.4e38)",
        ));
    }
    Ok(())
}

/// Checks, with their lines and columns, what tobj would drop or report
/// without a location (see the module docs): every vertex and normal
/// coordinate, the vertex count of every face and every face index.
fn prescan(file: &Arc<str>, text: &str, max_memory: u64) -> Result<(), SceneError> {
    // Another mesh format's text (which the OBJ reader would skip line by
    // line, to a mesh without faces).
    let first = text.split_whitespace().next().unwrap_or("");
    let other = match first {
        "ply" => Some("a PLY mesh, not OBJ: meshes are read from Wavefront OBJ files; convert it"),
        "solid" => {
            Some("an ASCII STL mesh, not OBJ: meshes are read from Wavefront OBJ files; convert it")
        }
        w if w.starts_with('{') => Some(
            "JSON (a glTF mesh?), not OBJ: meshes are read from Wavefront OBJ files; convert it",
        ),
        _ => None,
    };
    if let Some(problem) = other {
        return Err(invalid(file, 1, 1, "OBJ", problem));
    }
    // Totals for positive indices (tobj resolves them once the object is
    // complete, against everything read by then; the whole file bounds
    // that), running counts for negative ones; and the faces' corners.
    let mut totals = [0i64; 3];
    let mut corners = 0u64;
    for line in text.lines() {
        let mut words = line.split_whitespace();
        match words.next() {
            Some("v") => totals[0] += 1,
            Some("vt") => totals[1] += 1,
            Some("vn") => totals[2] += 1,
            Some("f") => corners += words.count() as u64,
            _ => {}
        }
    }
    let elements = totals.iter().map(|&n| n.unsigned_abs()).sum::<u64>();
    let bytes = (text.len() as u64)
        .saturating_add(elements.saturating_mul(READ_BYTES[0]))
        .saturating_add(corners.saturating_mul(READ_BYTES[1]));
    if bytes > max_memory {
        return Err(SceneError::TooMuchMemory {
            file: Arc::clone(file),
            what: format!("{elements} vertex, normal and texture lines and {corners} face corners"),
            bytes,
            limit: max_memory,
        });
    }
    let mut seen = [0i64; 3];
    // Positive indices past the elements read so far, with their line and
    // column: legal if the elements come before the object ends (an `o`
    // or `g` line after faces, or the end of the file), where tobj
    // resolves the object's faces.
    let mut ahead: Vec<(usize, i64, usize, usize)> = Vec::new();
    let mut faces = false;
    let resolve = |ahead: &mut Vec<(usize, i64, usize, usize)>, seen: &[i64; 3]| {
        let late = ahead.iter().find(|&&(k, i, _, _)| i > seen[k]).copied();
        ahead.clear();
        late.map_or(Ok(()), |(k, _, line, column)| {
            Err(invalid(file, line, column, "face", LATE[k]))
        })
    };
    const LATE: [&str; 3] = [
        "vertex index of a vertex defined after the face's object ends (faces are resolved at the next `o` or `g`)",
        "texture coordinate index of one defined after the face's object ends (faces are resolved at the next `o` or `g`)",
        "normal index of one defined after the face's object ends (faces are resolved at the next `o` or `g`)",
    ];
    const WHAT: [&str; 3] = [
        "vertex index out of range (indices count from 1; negative ones back from the latest vertex)",
        "texture coordinate index out of range",
        "normal index out of range",
    ];
    for (n, line) in text.lines().enumerate() {
        let mut words = words(line);
        let Some((first_col, first)) = words.next() else {
            continue;
        };
        let at = |column: usize, field: &'static str, problem: &'static str| {
            invalid(file, n + 1, column, field, problem)
        };
        match first {
            "o" | "g" if faces => {
                resolve(&mut ahead, &seen)?;
                faces = false;
            }
            "v" => {
                seen[0] += 1;
                check_coordinates(words, true).map_err(|(c, why)| at(c, "vertex", why))?;
            }
            "vt" => seen[1] += 1,
            "vn" => {
                seen[2] += 1;
                check_coordinates(words, false).map_err(|(c, why)| at(c, "normal", why))?;
            }
            "f" => {
                // tobj takes a face of one or two vertices for a point or
                // a line, and drops it.
                let few = match words.clone().count() {
                    0 => Some("a face needs at least 3 vertices, found none"),
                    1 => Some("a face needs at least 3 vertices, found 1"),
                    2 => Some("a face needs at least 3 vertices, found 2"),
                    n if n > MAX_FACE_VERTICES => Some(
                        "more than 65536 vertices (the most a face may have): split it into smaller faces",
                    ),
                    _ => None,
                };
                if let Some(problem) = few {
                    return Err(at(first_col, "face", problem));
                }
                faces = true;
                for (col, word) in words {
                    for (k, part) in word.split('/').enumerate().take(3) {
                        if part.is_empty() {
                            continue;
                        }
                        let Ok(i) = part.parse::<i64>() else {
                            // Malformed: tobj reports it on this line.
                            continue;
                        };
                        let ok = if i > 0 {
                            i <= totals[k]
                        } else {
                            i < 0 && seen[k] + i >= 0
                        };
                        if !ok {
                            return Err(at(col, "face", WHAT[k]));
                        }
                        if i > seen[k] {
                            ahead.push((k, i, n + 1, col));
                        }
                    }
                }
            }
            _ => {}
        }
    }
    Ok(())
}

/// A reader that counts the lines tobj has taken.
struct Counting<'a> {
    bytes: &'a [u8],
    at: usize,
    /// Newlines consumed.
    lines: usize,
}

impl Read for Counting<'_> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let avail = self.fill_buf()?;
        let n = avail.len().min(buf.len());
        buf[..n].copy_from_slice(&avail[..n]);
        self.consume(n);
        Ok(n)
    }
}

impl BufRead for Counting<'_> {
    fn fill_buf(&mut self) -> std::io::Result<&[u8]> {
        Ok(self.bytes.get(self.at..).unwrap_or(&[]))
    }
    fn consume(&mut self, amt: usize) {
        let end = self.at.saturating_add(amt).min(self.bytes.len());
        let taken = self.bytes.get(self.at..end).unwrap_or(&[]);
        self.lines += taken.iter().filter(|&&b| b == b'\n').count();
        self.at = end;
    }
}

/// Parses OBJ text; `file` names it in messages, with no memory limit
/// (the same answer on every machine; the caller's: [`parse_within`]).
///
/// # Errors
/// As [`load`], less the file-system errors.
pub fn parse(file: &str, text: &str) -> Result<Mesh, SceneError> {
    parse_within(file, text, u64::MAX, &mut CutBudget::scene())
}

/// [`parse`], refusing text whose elements would take more than
/// `max_memory` bytes with it, and cutting its non-convex faces from the
/// scene's `budget` ([`load_within`]).
///
/// # Errors
/// As [`load_within`], less the file-system errors.
pub fn parse_within(
    file: &str,
    text: &str,
    max_memory: u64,
    budget: &mut CutBudget,
) -> Result<Mesh, SceneError> {
    let file: Arc<str> = Arc::from(file);
    // tobj takes `\u{feff}v` for an unknown statement and drops that
    // vertex, renumbering every one after it.
    let text = without_bom(text);
    prescan(&file, text, max_memory)?;
    // tobj reads `l` like `f`, as a face when it has three vertices or
    // more; lines are ignored, so `l` becomes `#` (same byte, same lines).
    let polyline = |line: &str| line.split_whitespace().next() == Some("l");
    let text: Cow<'_, str> = if text.lines().any(polyline) {
        let mut hidden = String::with_capacity(text.len());
        for line in text.split_inclusive('\n') {
            match line.find('l') {
                Some(at) if polyline(line) => {
                    hidden.push_str(line.get(..at).unwrap_or_default());
                    hidden.push('#');
                    hidden.push_str(line.get(at + 1..).unwrap_or_default());
                }
                _ => hidden.push_str(line),
            }
        }
        Cow::Owned(hidden)
    } else {
        Cow::Borrowed(text)
    };
    let mut reader = Counting {
        bytes: text.as_bytes(),
        at: 0,
        lines: 0,
    };
    let options = tobj::LoadOptions {
        single_index: true,
        // Faces are cut into triangles here, as NFF polygons are.
        triangulate: false,
        ignore_points: true,
        ignore_lines: true,
    };
    let result = tobj::load_obj_buf(&mut reader, &options, |_| {
        Err(tobj::LoadError::OpenFileFailed)
    });
    let models = match result {
        Ok((models, _)) => models,
        Err(e) => {
            // The line being read when tobj stopped (the last one read in
            // full, or the unterminated last line).
            let line = if text.ends_with('\n') || reader.at < text.len() {
                reader.lines.max(1)
            } else {
                reader.lines + 1
            };
            let (field, problem) = match e {
                tobj::LoadError::PositionParseError => ("vertex", "malformed position"),
                tobj::LoadError::NormalParseError => ("normal", "malformed normal"),
                tobj::LoadError::TexcoordParseError => {
                    ("texture coordinate", "malformed texture coordinate")
                }
                tobj::LoadError::FaceParseError => ("face", "malformed face"),
                tobj::LoadError::ColorParseError => ("vertex", "malformed colour"),
                tobj::LoadError::ScalingByZeroError => ("vertex", "weight w = 0"),
                tobj::LoadError::InvalidPolygon => ("face", "fewer than three vertices"),
                // `prescan` checks the indices, not the colours, which
                // tobj requires on every vertex or none.
                tobj::LoadError::FaceColorOutOfBounds => (
                    "face",
                    "a vertex without a colour, where others have one (`v x y z r g b`): give colours on every v line or on none",
                ),
                tobj::LoadError::FaceVertexOutOfBounds
                | tobj::LoadError::FaceTexCoordOutOfBounds
                | tobj::LoadError::FaceNormalOutOfBounds => ("face", "index out of range"),
                _ => ("OBJ", "not a readable OBJ file"),
            };
            return Err(invalid(&file, line, 1, field, problem));
        }
    };
    let mut mesh = Mesh {
        positions: Vec::new(),
        normals: Some(Vec::new()),
        triangles: Vec::new(),
    };
    // Faces read so far, over all models: the reader keeps the file's order.
    let mut faces_before = 0usize;
    for m in &models {
        let m = &m.mesh;
        let base = mesh.positions.len();
        let count = m.positions.len() / 3;
        // Every face has 3 to MAX_FACE_VERTICES vertices (`prescan`); tobj
        // gives no arities when all are triangles.
        let arities: Vec<usize> = if m.face_arities.is_empty() {
            vec![3; m.indices.len() / 3]
        } else {
            m.face_arities.iter().map(|&k| k as usize).collect()
        };
        let triangles: usize = arities.iter().map(|k| k.saturating_sub(2)).sum();
        if mesh.triangles.len() + triangles > MAX_TRIANGLES {
            return Err(SceneError::Invalid {
                loc: SourceLoc::new(Arc::clone(&file), 1, 1),
                field: "OBJ",
                problem: "more triangles than a mesh may have (2^24)",
            });
        }
        for p in m.positions.chunks_exact(3) {
            let v = DVec3::new(f64::from(p[0]), f64::from(p[1]), f64::from(p[2]));
            if !v.is_finite() {
                // A guard: `prescan` refuses these with their line.
                return Err(SceneError::Invalid {
                    loc: SourceLoc::new(Arc::clone(&file), 1, 1),
                    field: "OBJ",
                    problem: "a vertex position is not finite",
                });
            }
            mesh.positions.push(v);
        }
        if m.normals.len() == m.positions.len() {
            if let Some(ns) = mesh.normals.as_mut() {
                ns.extend(
                    m.normals
                        .chunks_exact(3)
                        .map(|n| DVec3::new(f64::from(n[0]), f64::from(n[1]), f64::from(n[2]))),
                );
            }
        } else {
            mesh.normals = None;
        }
        let mut first = 0usize;
        let mut face = Vec::new();
        for k in arities {
            // Its line, found only for a message.
            let face_index = faces_before;
            let at = || face_line(&text, face_index);
            faces_before += 1;
            let idx = m.indices.get(first..first + k).unwrap_or_default();
            first += k;
            if idx.len() != k || idx.iter().any(|&i| i as usize >= count) {
                return Err(invalid(&file, at(), 1, "face", "index out of range"));
            }
            let global = |i: u32| base + i as usize;
            face.clear();
            face.extend(
                idx.iter()
                    .filter_map(|&i| mesh.positions.get(global(i)).copied()),
            );
            let off = |i: usize| {
                idx.get(i)
                    .and_then(|&j| u32::try_from(global(j)).ok())
                    .unwrap_or(u32::MAX)
            };
            // A face has at most MAX_FACE_VERTICES vertices (`prescan`).
            let cut = super::polygon::cut(&face, budget)
                .map_err(|problem| invalid(&file, at(), 1, "face", problem))?;
            mesh.triangles
                .extend(super::polygon::triangles(&face, cut.as_deref()).map(|t| t.map(off)));
        }
    }
    if mesh.triangles.is_empty() {
        return Err(SceneError::Invalid {
            loc: SourceLoc::new(Arc::clone(&file), 1, 1),
            field: "OBJ",
            problem: "no faces: the file holds no triangle mesh",
        });
    }
    // Normals that cannot be normalised are dropped with the rest.
    if mesh
        .normals
        .as_ref()
        .is_some_and(|ns| ns.iter().any(|n| n.try_normalize().is_none()))
    {
        mesh.normals = None;
    }
    Ok(mesh)
}

/// Area-weighted vertex normals of `mesh` (for smooth shading of a file
/// without `vn`); a vertex of only degenerate triangles gets the first
/// triangle's direction or +z.
#[must_use]
pub fn smooth_normals(mesh: &Mesh) -> Vec<DVec3> {
    let mut acc = vec![DVec3::ZERO; mesh.positions.len()];
    for t in &mesh.triangles {
        let [a, b, c] = t.map(|i| {
            mesh.positions
                .get(i as usize)
                .copied()
                .unwrap_or(DVec3::ZERO)
        });
        // The cross product's length is twice the area: area weighting.
        let n = (b - a).cross(c - a);
        for &i in t {
            if let Some(s) = acc.get_mut(i as usize) {
                *s += n;
            }
        }
    }
    acc.into_iter()
        .map(|n| n.try_normalize().unwrap_or(DVec3::Z))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A mesh whose text or elements would take more than the memory
    /// limit is refused before it is read, naming the limit.
    /// A face refused as it is cut is located at its own `f` line.
    /// Another mesh format's text is named, not read as an OBJ without
    /// faces.
    #[test]
    fn other_mesh_formats_are_named() {
        for (text, what) in [
            ("ply\nformat ascii 1.0\nelement vertex 3\n", "a PLY mesh"),
            ("solid cube\n facet normal 0 0 1\n", "an ASCII STL mesh"),
            ("{\"asset\": {\"version\": \"2.0\"}}", "JSON (a glTF mesh?)"),
        ] {
            let e = parse("m.obj", text).unwrap_err().to_string();
            assert!(
                e.starts_with(&format!("m.obj:1:1: OBJ: {what}, not OBJ")),
                "{e}"
            );
        }
    }

    #[test]
    fn a_face_beyond_the_cut_budget_is_located_at_its_line() {
        let text = "v 0 0 0\nv 4 0 0\nv 4 3 0\nv 3 3 0\nv 3 1 0\nv 2 1 0\nv 2 3 0\nv 0 3 0\n\
                    f 1 2 3\ng second\n# a comment\nf 1 2 3 4 5 6 7 8\n";
        let e = parse_within("t.obj", text, u64::MAX, &mut CutBudget::with_left(63))
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with("t.obj:12:1: face: non-convex, and cutting it"),
            "{e}"
        );
        parse_within("t.obj", text, u64::MAX, &mut CutBudget::with_left(64)).unwrap();
    }

    #[test]
    fn meshes_keep_the_memory_limit() {
        let text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 2 3\n";
        // 40 bytes of text, 3 vertices (36 bytes), 6 corners (576 bytes).
        let budget = &mut CutBudget::scene();
        assert_eq!(
            parse_within("t.obj", text, 652, budget)
                .unwrap()
                .triangles
                .len(),
            2
        );
        let e = parse_within("t.obj", text, 651, budget)
            .unwrap_err()
            .to_string();
        assert_eq!(
            e,
            "t.obj: 3 vertex, normal and texture lines and 6 face corners take about 652 B to read, more than the memory limit of 651 B (--max-memory)"
        );
        let dir = std::env::temp_dir().join(format!("rrt-obj-limit-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let p = dir.join("t.obj");
        std::fs::write(&p, text).unwrap();
        let e = load_within(&p, "t.obj", 39, &mut CutBudget::scene())
            .unwrap_err()
            .to_string();
        assert_eq!(
            e,
            "t.obj: its 40 bytes of text take about 40 B to read, more than the memory limit of 39 B (--max-memory)"
        );
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn indices_are_checked_with_their_line() {
        let ok = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf -3 -2 -1\n";
        let m = parse("t.obj", ok).unwrap();
        let refused = |text: &str| parse("t.obj", text).unwrap_err().to_string();
        assert_eq!(m.triangles.len(), 2);
        assert_eq!(m.normals, None);
        let e = refused("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n");
        assert!(
            e.starts_with("t.obj:4:7: face: vertex index out of range"),
            "{e}"
        );
        let e = refused("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n");
        assert!(e.starts_with("t.obj:4:3: face: vertex index"), "{e}");
        let e = refused("v 0 0 0\nf -2 1 1\nv 1 0 0\nv 0 1 0\n");
        assert!(e.starts_with("t.obj:2:3:"), "{e}");
        let e = refused("v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2//0 3//1\n");
        // The column of the face vertex `2//0` that holds the bad index.
        assert!(e.starts_with("t.obj:5:8: face: normal index"), "{e}");
        let e = refused("v 0 0 0\nv 1 x 0\nv 0 1 0\nf 1 2 3\n");
        assert_eq!(e, "t.obj:2:1: vertex: malformed position");
        let e = refused("# nothing\n");
        assert!(e.contains("no faces"), "{e}");
    }

    #[test]
    fn faces_of_fewer_than_three_vertices_are_refused_on_their_line() {
        let refused = |text: &str| parse("t.obj", text).unwrap_err().to_string();
        let tri = "v 0 0 0\nv 1 0 0\nv 0 0 1\nf 1 2 3\n";
        assert_eq!(
            refused(&format!("{tri}f 1 2 3 3\nf 2 3\nf 1\n")),
            "t.obj:6:1: face: a face needs at least 3 vertices, found 2"
        );
        assert_eq!(
            refused(&format!("{tri}  f 1\n")),
            "t.obj:5:3: face: a face needs at least 3 vertices, found 1"
        );
        assert_eq!(
            refused(&format!("{tri}f\n")),
            "t.obj:5:1: face: a face needs at least 3 vertices, found none"
        );
        // Only such a face: that face, not \"no faces\".
        assert_eq!(
            refused("v 0 0 0\nv 1 0 0\nf 1 2\n"),
            "t.obj:3:1: face: a face needs at least 3 vertices, found 2"
        );
        // Points and lines stay ignored, whatever their length.
        let m = parse(
            "t.obj",
            &format!("{tri}l 1 2\np 1\n l 1 2 3\r\nl 3 2 1 3\n"),
        )
        .unwrap();
        assert_eq!(m.triangles.len(), 1);
        let e = refused("v 0 0 0\nv 1 0 0\nv 0 0 1\nl 1 2 3\n");
        assert!(e.contains("no faces"), "{e}");
        // Lines do not shift the lines tobj's errors are reported on.
        let e = refused(&format!("l 1 2 3\n{tri}v 1 y 0\n"));
        assert_eq!(e, "t.obj:6:1: vertex: malformed position");
    }

    #[test]
    fn bad_coordinates_are_refused_on_their_line_and_column() {
        let refused = |text: &str| parse("t.obj", text).unwrap_err().to_string();
        let e = refused("v 0 0 0\nv 1 0 0\nv 0 0 1\n\n\nv 0 nan 0\nf 1 2 4\n");
        assert_eq!(
            e,
            "t.obj:6:5: vertex: coordinate is not finite (NaN or infinity)"
        );
        // Unused, it is still refused.
        let e = refused("v 0 0 0\nv 1 0 0\nv 0 0 1\nv inf 0 0\nf 1 2 3\n");
        assert!(
            e.starts_with("t.obj:4:3: vertex: coordinate is not finite"),
            "{e}"
        );
        // Finite in f64 but not in f32, which tobj reads.
        let e = refused("v 0 0 0\nv 1 0 0\nv 0 0 1\nv 0 0 -1e308\nf 1 2 4\n");
        assert!(
            e.starts_with(
                "t.obj:4:7: vertex: coordinate out of range: meshes are read in single precision"
            ),
            "{e}"
        );
        let e = refused("v 0 0 0\nv 1 0 0\nv 0 0 1 NaN\nf 1 2 3\n");
        assert!(
            e.starts_with("t.obj:3:9: vertex: coordinate is not finite"),
            "{e}"
        );
        let e = refused("v 0 0 0\nv 1 0 0\nv 0 0 1e30 1e-30\nf 1 2 3\n");
        assert!(
            e.starts_with("t.obj:3:12: vertex: coordinate out of range once divided by w"),
            "{e}"
        );
        let e = refused("v 0 0 0\nv 1 0 0\nv 0 0 1\nvn 0 0 1\nvn 0 nan 1\nf 1//1 2//1 3//1\n");
        assert!(
            e.starts_with("t.obj:5:6: normal: coordinate is not finite"),
            "{e}"
        );
        // Large but single-precision values, and a weight, are fine.
        let m = parse("t.obj", "v 0 0 0\nv 3e38 0 0\nv 0 0 2 2\nf 1 2 3\n").unwrap();
        assert_eq!(m.positions.len(), 3);
        assert!(m.positions.iter().any(|p| *p == DVec3::new(0.0, 0.0, 1.0)));
    }

    /// A face naming a vertex defined in a later object is refused at the
    /// index, not at the `o` line where tobj finds it; within its own
    /// object a forward reference is fine.
    #[test]
    fn forward_references_past_the_object_are_located() {
        let e = parse(
            "t.obj",
            "o a\nf 1 2 3\no b\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
        )
        .unwrap_err()
        .to_string();
        assert!(
            e.starts_with(
                "t.obj:2:3: face: vertex index of a vertex defined after the face's object ends"
            ),
            "{e}"
        );
        let e = parse("t.obj", "v 0 0 0\nv 1 0 0\ng a\nf 1 2 3\ng b\nv 0 1 0\n")
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with("t.obj:4:7: face: vertex index of a vertex defined after"),
            "{e}"
        );
        let m = parse("t.obj", "o a\nf 1 2 3\nv 0 0 0\nv 1 0 0\nv 0 1 0\no b\n").unwrap();
        assert_eq!(m.triangles.len(), 1);
    }

    /// Vertex colours on some vertices but not all are named as such, not
    /// as a face index out of range (the indices are all valid).
    #[test]
    fn colours_on_some_vertices_only() {
        let e = parse("t.obj", "v 0 0 0 1 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with("t.obj:4:1: face: a vertex without a colour, where others have one"),
            "{e}"
        );
        // On every vertex they are fine (and ignored).
        let m = parse(
            "t.obj",
            "v 0 0 0 1 0 0\nv 1 0 0 0 1 0\nv 0 1 0 0 0 1\nf 1 2 3\n",
        )
        .unwrap();
        assert_eq!(m.triangles.len(), 1);
    }

    /// Columns count characters, however many words precede them.
    #[test]
    fn word_columns() {
        let got: Vec<(usize, &str)> = words("  f é1\t2  ü/3 4").collect();
        assert_eq!(got, [(3, "f"), (5, "é1"), (8, "2"), (11, "ü/3"), (15, "4")]);
        // Cloned part-way, each goes on from where it was.
        let mut w = words("a b c");
        w.next();
        let rest: Vec<_> = w.clone().collect();
        assert_eq!(rest, [(3, "b"), (5, "c")]);
        assert_eq!(w.count(), 2);
    }

    /// A face of the most vertices a face may have, on one line, is read in
    /// linear time (the columns of its words were counted from the line's
    /// start, each, which took minutes for a 2 MB line); one more is
    /// refused at the face.
    #[test]
    fn one_long_face_is_read_in_linear_time() {
        let n = MAX_FACE_VERTICES;
        let mut text = String::new();
        for i in 0..n {
            let a = std::f64::consts::TAU * i as f64 / n as f64;
            text.push_str(&format!("v {} {} 0\n", a.cos(), a.sin()));
        }
        text.push('f');
        for i in 1..=n {
            text.push_str(&format!(" {i}"));
        }
        text.push('\n');
        let t = std::time::Instant::now();
        let m = parse("fan.obj", &text).unwrap();
        assert_eq!(m.triangles.len(), n - 2);
        assert!(t.elapsed().as_secs() < 5, "{:?}", t.elapsed());
        // An error at the end of that line still has its column.
        let e = parse("fan.obj", &format!("{}0\n", text.trim_end()))
            .unwrap_err()
            .to_string();
        let column = text.lines().last().unwrap().rfind(' ').unwrap() + 2;
        assert!(
            e.starts_with(&format!("fan.obj:{}:{column}: face: vertex index", n + 1)),
            "{e}"
        );
        let more = format!("v 0 0 1\n{} 1\n", text.trim_end());
        assert_eq!(
            parse("fan.obj", &more).unwrap_err().to_string(),
            format!(
                "fan.obj:{}:1: face: more than 65536 vertices (the most a face may have): split it \
                 into smaller faces",
                n + 2
            )
        );
    }

    /// A non-convex face is cut into its ears, as an NFF polygon is: a comb
    /// whose fan from vertex 1 would cover its notches.
    #[test]
    fn a_non_convex_face_is_its_ears() {
        let comb = crate::scene::polygon::tests::COMB;
        let mut text: String = comb.iter().map(|(x, y)| format!("v {x} {y} 0\n")).collect();
        text += "f";
        for i in 1..=comb.len() {
            text += &format!(" {i}");
        }
        text += "\n";
        let m = parse("comb.obj", &text).unwrap();
        assert_eq!(m.triangles.len(), comb.len() - 2);
        let mut area = 0.0;
        for t in &m.triangles {
            let [a, b, c] = t.map(|i| m.positions[i as usize]);
            let twice = (b - a).cross(c - a).z;
            assert!(twice > 0.0, "{t:?} winds against the face");
            area += twice / 2.0;
            let centre = (a + b + c) / 3.0;
            assert!(
                !(centre.y > 1.0
                    && ((0.5..1.0).contains(&centre.x) || (2.0..3.0).contains(&centre.x))),
                "{t:?} covers a notch"
            );
        }
        assert!((area - 9.0).abs() < 1e-9, "{area}");
    }

    /// A byte-order mark does not hide the first vertex: the triangle is
    /// the file's, not one of the vertices after it.
    #[test]
    fn a_byte_order_mark_is_skipped() {
        let text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\n";
        let plain = parse("t.obj", text).unwrap();
        let marked = parse("t.obj", &format!("\u{feff}{text}")).unwrap();
        assert_eq!(marked, plain);
        assert_eq!(marked.positions[0], DVec3::ZERO);
        let e = parse("t.obj", "\u{feff}v 0 0 nan\n")
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with("t.obj:1:7: vertex: coordinate is not finite"),
            "{e}"
        );
    }

    #[test]
    fn normals_and_quads() {
        let m = parse(
            "q.obj",
            "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2//1 3//1 4//1\n",
        )
        .unwrap();
        assert_eq!(m.triangles.len(), 2);
        assert_eq!(m.normals.as_ref().map(Vec::len), Some(m.positions.len()));
        let s = smooth_normals(&m);
        assert!(s.iter().all(|n| (*n - DVec3::Z).length() < 1e-12));
    }
}
