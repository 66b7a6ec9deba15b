//! The NFF parser.
//!
//! NFF (Eric Haines, "Neutral File Format", distributed with the Standard
//! Procedural Databases) is line oriented. Every directive the SPD
//! documentation defines is read:
//!
//! ```text
//! # comment                      (a `#` anywhere starts a comment to the end of the line)
//! b R G B                        background colour
//! v                              viewpoint, followed by exactly these lines in this order:
//! from Fx Fy Fz
//! at Ax Ay Az
//! up Ux Uy Uz
//! angle degrees                  between the centres of the first and last rows
//! hither distance
//! resolution xres yres
//! l X Y Z [R G B]                positional light, optional colour
//! f red green blue Kd Ks Shine T index_of_refraction
//! c                              cone or cylinder, open at both ends:
//! base.x base.y base.z base_radius     (on the `c` line itself, or on the next line)
//! apex.x apex.y apex.z apex_radius     (on the same line as the base, or on the next line)
//! s center.x center.y center.z radius
//! p total_vertices               polygon, one vertex per line:
//! vert.x vert.y vert.z
//! pp total_vertices              polygonal patch, one vertex and its normal per line:
//! vert.x vert.y vert.z norm.x norm.y norm.z
//! ```
//!
//! Objects take the material of the latest `f` before them. Objects before
//! any `f` take material 0, which is [`Material::DEFAULT`] when the file has
//! no `f` at all and the file's first `f` otherwise: exactly what
//! `peers/common/nff.h` (and so `embree_nff`) does, so images compare.
//!
//! # Strictness
//! A UTF-8 byte-order mark at the start of the file is skipped (columns
//! on the first line count from after it). Each field must be on the line
//! the format puts it on; a line with too
//! few or too many fields is an error at its end or at the extra token.
//! Numbers must be finite (`NaN`, `inf` and overflowing literals are
//! refused) and within [`WORLD_LIMIT`] (±1e60) in magnitude; counts and
//! pixel sizes must be whole numbers. Ranges: colours of `b` and `f` in
//! `[0, 1]`; light colours ≥ 0; `Kd`, `Ks`, `Shine` and the index of
//! refraction ≥ 0, `T` in `[0, 1]`, and an index of refraction > 0 when
//! `T > 0`; sphere radii > 0; a cone's two radii of one sign (NFF's
//! negative radii, "only the inside is visible", are read as their
//! magnitudes: rrt shades both sides of every surface, as `embree_nff`
//! does); `0 < angle < 180`; resolutions
//! from 1 to [`MAX_RESOLUTION`]. `v` and `b` may appear once. A view whose
//! `from` equals `at`, or whose `up` is parallel to the view direction, is
//! refused, as are cones whose base and apex coincide or whose radii are
//! both 0, and patch normals of length 0. Degenerate (zero-area) polygons
//! are kept: [`crate::fit`] drops the triangles that have no area.
//!
//! # Sizes
//! Nothing is allocated from a count before it is checked: a polygon's
//! vertex count must fit in the lines left in the file (each vertex takes
//! one), and the scene's total vertex count is capped by
//! [`ParseOptions::max_vertices`]. Files are capped by
//! [`ParseOptions::max_file_bytes`] before they are read.

use std::fs;
use std::path::Path;
use std::sync::Arc;

use glam::DVec3;
use indicatif::ProgressBar;

use super::error::{Found, SceneError};
use super::loc::SourceLoc;
use super::polygon::CutBudget;
use super::text::{byte_loc, without_bom};
use super::{Light, Material, Object, Polygon, Scene, View, ViewDefect};
use crate::shape::{Cone, Sphere};
use crate::world::WORLD_LIMIT;

/// Largest image width or height a `resolution` line may ask for: the
/// renderer's largest side (`crate::render::MAX_SIDE` is this).
pub const MAX_RESOLUTION: u32 = 32_768;

/// Limits that protect the parser's memory.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ParseOptions {
    /// Most polygon vertices in one scene (each costs 48 bytes here, and
    /// more downstream).
    pub max_vertices: u64,
    /// Largest file [`load`] reads, in bytes.
    pub max_file_bytes: u64,
    /// Whether a file without a view (`v` block) is refused. A scene
    /// read without one (a TOML scene's `nff = "x.nff"`, whose view is
    /// ignored) gets a placeholder view looking down −z from `(0, 0, 1)`.
    pub view_required: bool,
}

impl ParseOptions {
    /// Default [`ParseOptions::max_vertices`]: 2^24 (about 16.8 million).
    pub const DEFAULT_MAX_VERTICES: u64 = 1 << 24;
    /// Default [`ParseOptions::max_file_bytes`]: 1 GiB.
    pub const DEFAULT_MAX_FILE_BYTES: u64 = 1 << 30;
}

impl Default for ParseOptions {
    fn default() -> Self {
        Self {
            max_vertices: Self::DEFAULT_MAX_VERTICES,
            max_file_bytes: Self::DEFAULT_MAX_FILE_BYTES,
            view_required: true,
        }
    }
}

/// Reads and parses the NFF file at `path`.
///
/// # Errors
/// [`SceneError::Io`] (missing, unreadable), [`SceneError::IsDirectory`],
/// [`SceneError::FileTooLarge`], and everything [`parse_bytes`] refuses.
pub fn load(path: &Path, opts: &ParseOptions) -> Result<Scene, SceneError> {
    load_with(path, opts, &ProgressBar::hidden())
}

/// [`load`], counting the bytes parsed on `progress` (its length is set to
/// the file's).
///
/// # Errors
/// As [`load`].
pub fn load_with(
    path: &Path,
    opts: &ParseOptions,
    progress: &ProgressBar,
) -> Result<Scene, SceneError> {
    let io = |source| SceneError::Io {
        path: path.to_owned(),
        source,
    };
    let name: Arc<str> = Arc::from(path.display().to_string());
    let meta = fs::metadata(path).map_err(io)?;
    if meta.is_dir() {
        return Err(SceneError::IsDirectory {
            path: path.to_owned(),
            what: "an NFF file",
        });
    }
    let too_large = |size| SceneError::FileTooLarge {
        file: Arc::clone(&name),
        what: "an NFF file",
        size,
        limit: opts.max_file_bytes,
    };
    if meta.len() > opts.max_file_bytes {
        return Err(too_large(meta.len()));
    }
    let bytes =
        super::text::read_until_binary(fs::File::open(path).map_err(io)?, opts.max_file_bytes)
            .map_err(io)?;
    progress.set_length(bytes.len() as u64);
    parse_in(name, &bytes, opts, Some(progress))
}

/// Parses NFF held in memory; `file` names it in messages. This is the
/// entry point of the fuzz target: no input makes it panic, and its time
/// is linear in the input's length.
///
/// # Errors
/// [`SceneError::FileTooLarge`], [`SceneError::NotText`] (a NUL byte or
/// invalid UTF-8), [`SceneError::Empty`], and every error of the format
/// (see the module docs).
pub fn parse_bytes(file: &str, bytes: &[u8], opts: &ParseOptions) -> Result<Scene, SceneError> {
    parse_in(Arc::from(file), bytes, opts, None)
}

fn parse_in(
    file: Arc<str>,
    bytes: &[u8],
    opts: &ParseOptions,
    progress: Option<&ProgressBar>,
) -> Result<Scene, SceneError> {
    let size = u64::try_from(bytes.len()).unwrap_or(u64::MAX);
    if size > opts.max_file_bytes {
        return Err(SceneError::FileTooLarge {
            file,
            what: "an NFF file",
            size,
            limit: opts.max_file_bytes,
        });
    }
    if let Some(at) = bytes.iter().position(|&b| b == 0) {
        return Err(SceneError::NotText {
            loc: byte_loc(&file, bytes, at),
            what: "a NUL byte (binary data?)",
        });
    }
    let text = match std::str::from_utf8(bytes) {
        Ok(t) => t,
        Err(e) => {
            return Err(SceneError::NotText {
                loc: byte_loc(&file, bytes, e.valid_up_to()),
                what: "invalid UTF-8 (binary data?)",
            });
        }
    };
    let mut parser = Parser::new(file, without_bom(text), opts);
    parser.progress = progress.filter(|p| !p.is_hidden());
    parser.parse()
}

/// The location of byte `at`, whose prefix is valid UTF-8 up to the last
/// line start (columns of an invalid prefix count bytes).
fn to_u32(n: usize) -> u32 {
    u32::try_from(n).unwrap_or(u32::MAX)
}

/// A token on the current line: its text and byte offset in the line.
#[derive(Clone, Copy, Debug)]
struct Tok<'a> {
    text: &'a str,
    at: usize,
}

/// The view keywords, in the order a `v` block needs them.
const VIEW_KEYWORDS: [&str; 6] = ["from", "at", "up", "angle", "hither", "resolution"];

struct Parser<'a> {
    file: Arc<str>,
    opts: ParseOptions,
    text: &'a str,
    /// Byte offset of the next unread line in `text`.
    next: usize,
    /// Number of the current line (0 before the first).
    line_no: u32,
    /// Lines consumed so far, blank and comment lines included.
    consumed: u64,
    /// Lines in the whole text (a last line without `\n` counts).
    total_lines: u64,
    /// The current line, comment removed.
    line: &'a str,
    /// Read position in `line`.
    pos: usize,
    /// Whether any line held a directive.
    any: bool,
    view: Option<View>,
    background: Option<(DVec3, u32)>,
    material: Option<usize>,
    scene: Builder,
    /// Counts the bytes parsed (every few thousand lines).
    progress: Option<&'a ProgressBar>,
}

#[derive(Default)]
struct Builder {
    lights: Vec<Light>,
    materials: Vec<Material>,
    spheres: Vec<Object<Sphere>>,
    cones: Vec<Object<Cone>>,
    polygons: Vec<Polygon>,
    vertices: Vec<DVec3>,
    normals: Vec<DVec3>,
    /// What cutting non-convex polygons may still cost.
    cut_budget: CutBudget,
}

type R<T> = Result<T, SceneError>;

impl<'a> Parser<'a> {
    fn new(file: Arc<str>, text: &'a str, opts: &ParseOptions) -> Self {
        let newlines = text.bytes().filter(|&b| b == b'\n').count();
        let unterminated = usize::from(!text.is_empty() && !text.ends_with('\n'));
        Self {
            file,
            opts: *opts,
            text,
            next: 0,
            line_no: 0,
            consumed: 0,
            total_lines: u64::try_from(newlines + unterminated).unwrap_or(u64::MAX),
            line: "",
            pos: 0,
            any: false,
            view: None,
            background: None,
            material: None,
            scene: Builder::default(),
            progress: None,
        }
    }

    // ---------------------------------------------------------------- lines

    /// Moves to the next line holding a token (skipping blank and comment
    /// lines); `false` at the end of the text.
    fn advance_line(&mut self) -> bool {
        while let Some(rest) = self.text.get(self.next..) {
            if rest.is_empty() {
                break;
            }
            let (raw, len) = match rest.find('\n') {
                Some(i) => (&rest[..i], i + 1),
                None => (rest, rest.len()),
            };
            self.next += len;
            self.consumed = self.consumed.saturating_add(1);
            if self.consumed.is_multiple_of(4096)
                && let Some(p) = self.progress
            {
                p.set_position(self.next as u64);
            }
            let content = raw.find('#').map_or(raw, |h| &raw[..h]);
            if content.bytes().any(|b| !b.is_ascii_whitespace()) {
                self.line_no = u32::try_from(self.consumed).unwrap_or(u32::MAX);
                self.line = content;
                self.pos = 0;
                self.any = true;
                return true;
            }
        }
        false
    }

    /// Lines after the current one (an upper bound on the lines that can
    /// still hold data).
    fn remaining_lines(&self) -> u64 {
        self.total_lines.saturating_sub(self.consumed)
    }

    fn token(&mut self) -> Option<Tok<'a>> {
        let line = self.line;
        let rest = line.get(self.pos..)?;
        let skip = rest.find(|c: char| !c.is_ascii_whitespace())?;
        let start = self.pos + skip;
        let tail = &line[start..];
        let len = tail
            .find(|c: char| c.is_ascii_whitespace())
            .unwrap_or(tail.len());
        self.pos = start + len;
        Some(Tok {
            text: &tail[..len],
            at: start,
        })
    }

    fn at_eol(&self) -> bool {
        self.line
            .get(self.pos..)
            .is_none_or(|r| r.bytes().all(|b| b.is_ascii_whitespace()))
    }

    fn loc_at(&self, byte: usize) -> SourceLoc {
        let column = self.line.get(..byte).map_or(byte, |s| s.chars().count());
        SourceLoc::new(Arc::clone(&self.file), self.line_no, to_u32(column + 1))
    }

    /// Just past the last token of the current line.
    fn eol_loc(&self) -> SourceLoc {
        self.loc_at(
            self.line
                .trim_end_matches(|c: char| c.is_ascii_whitespace())
                .len(),
        )
    }

    fn bad(&self, tok: Tok<'_>, field: &'static str, expected: &'static str) -> SceneError {
        SceneError::BadField {
            loc: self.loc_at(tok.at),
            field,
            expected,
            found: Found::token(tok.text),
        }
    }

    fn missing(&self, field: &'static str, expected: &'static str, found: Found) -> SceneError {
        SceneError::BadField {
            loc: self.eol_loc(),
            field,
            expected,
            found,
        }
    }

    /// The line must hold nothing more.
    fn expect_eol(&mut self, field: &'static str) -> R<()> {
        match self.token() {
            None => Ok(()),
            Some(t) => Err(self.bad(t, field, "end of line")),
        }
    }

    /// Moves to the next line, which must exist: `field` is what it holds.
    fn record_line(&mut self, field: &'static str, expected: &'static str) -> R<()> {
        if self.advance_line() {
            Ok(())
        } else {
            Err(self.missing(field, expected, Found::EndOfFile))
        }
    }

    // -------------------------------------------------------------- numbers

    fn number_tok(&mut self, field: &'static str) -> R<(f64, Tok<'a>)> {
        let Some(tok) = self.token() else {
            return Err(self.missing(field, "a number", Found::EndOfLine));
        };
        match tok.text.parse::<f64>() {
            Ok(v) if v.abs() <= WORLD_LIMIT => Ok((v, tok)),
            Ok(v) if v.is_finite() => Err(self.bad(tok, field, "a number within ±1e60")),
            Ok(_) => Err(self.bad(tok, field, "a finite number")),
            Err(_) => Err(self.bad(tok, field, "a number")),
        }
    }

    fn number(&mut self, field: &'static str) -> R<f64> {
        Ok(self.number_tok(field)?.0)
    }

    /// A number satisfying `ok`, else `expected`.
    fn number_where(
        &mut self,
        field: &'static str,
        expected: &'static str,
        ok: impl Fn(f64) -> bool,
    ) -> R<f64> {
        let (v, tok) = self.number_tok(field)?;
        if ok(v) {
            Ok(v)
        } else {
            Err(self.bad(tok, field, expected))
        }
    }

    fn vec3(&mut self, field: &'static str) -> R<DVec3> {
        Ok(DVec3::new(
            self.number(field)?,
            self.number(field)?,
            self.number(field)?,
        ))
    }

    fn colour(&mut self, field: &'static str) -> R<DVec3> {
        let c = |p: &mut Self| {
            p.number_where(field, "a number from 0 to 1", |v| (0.0..=1.0).contains(&v))
        };
        Ok(DVec3::new(c(self)?, c(self)?, c(self)?))
    }

    /// A whole number in `lo..=hi`.
    fn whole(
        &mut self,
        field: &'static str,
        expected: &'static str,
        lo: u64,
        hi: u64,
    ) -> R<(u64, Tok<'a>)> {
        let Some(tok) = self.token() else {
            return Err(self.missing(field, expected, Found::EndOfLine));
        };
        match tok.text.parse::<u64>() {
            Ok(v) if (lo..=hi).contains(&v) => Ok((v, tok)),
            _ => Err(self.bad(tok, field, expected)),
        }
    }

    // ----------------------------------------------------------- directives

    fn parse(mut self) -> R<Scene> {
        while self.advance_line() {
            let Some(tok) = self.token() else { continue };
            match tok.text {
                "b" => self.background(tok)?,
                "v" => self.view(tok)?,
                "l" => self.light(tok)?,
                "f" => self.material(tok)?,
                "s" => self.sphere(tok)?,
                "c" => self.cone(tok)?,
                "p" => self.polygon(tok, false)?,
                "pp" => self.polygon(tok, true)?,
                word => {
                    let loc = self.loc_at(tok.at);
                    return Err(match VIEW_KEYWORDS.iter().find(|k| **k == word) {
                        Some(keyword) => SceneError::Misplaced { loc, keyword },
                        None => SceneError::UnknownDirective {
                            loc,
                            found: Found::token(word),
                        },
                    });
                }
            }
        }
        self.finish()
    }

    fn finish(self) -> R<Scene> {
        if !self.any {
            return Err(SceneError::Empty { file: self.file });
        }
        let view = match self.view {
            Some(view) => view,
            None if !self.opts.view_required => View {
                from: DVec3::Z,
                at: DVec3::ZERO,
                up: DVec3::Y,
                angle: 45.0,
                hither: 0.0,
                resolution: [1, 1],
                loc: SourceLoc::new(Arc::clone(&self.file), 1, 1),
            },
            None => return Err(SceneError::MissingView { file: self.file }),
        };
        let mut b = self.scene;
        if b.spheres.is_empty() && b.cones.is_empty() && b.polygons.is_empty() {
            return Err(SceneError::NoObjects { file: self.file });
        }
        if b.materials.is_empty() {
            b.materials.push(Material::DEFAULT);
        }
        Ok(Scene {
            background: self.background.map_or(DVec3::ZERO, |(c, _)| c),
            lights: b.lights,
            materials: b.materials,
            spheres: b.spheres,
            cones: b.cones,
            polygons: b.polygons,
            vertices: b.vertices,
            normals: b.normals,
            ..Scene::empty(self.file, view)
        })
    }

    fn background(&mut self, tok: Tok<'_>) -> R<()> {
        if let Some((_, first_line)) = self.background {
            return Err(SceneError::Duplicate {
                loc: self.loc_at(tok.at),
                what: "background (b)",
                first_line,
            });
        }
        let c = self.colour("background colour")?;
        self.expect_eol("background")?;
        self.background = Some((c, self.line_no));
        Ok(())
    }

    /// Starts the next line of a `v` block, which must begin with `keyword`.
    fn view_line(&mut self, keyword: &'static str, expected: &'static str) -> R<()> {
        self.record_line("view", expected)?;
        match self.token() {
            Some(t) if t.text == keyword => Ok(()),
            Some(t) => Err(self.bad(t, "view", expected)),
            None => Err(self.missing("view", expected, Found::EndOfLine)),
        }
    }

    fn view(&mut self, tok: Tok<'_>) -> R<()> {
        let loc = self.loc_at(tok.at);
        if let Some(first) = &self.view {
            return Err(SceneError::Duplicate {
                loc,
                what: "view (v)",
                first_line: first.loc.line,
            });
        }
        self.expect_eol("view")?;

        self.view_line("from", "a `from` line")?;
        let from = self.vec3("view from")?;
        self.expect_eol("view from")?;

        self.view_line("at", "an `at` line")?;
        let at_line = self.line_no;
        let at = self.vec3("view at")?;
        self.expect_eol("view at")?;
        if at == from {
            return Err(SceneError::Invalid {
                loc: SourceLoc::new(Arc::clone(&self.file), at_line, 1),
                field: "view at",
                problem: ViewDefect::NoDirection.problem(),
            });
        }

        self.view_line("up", "an `up` line")?;
        let up_line = self.line_no;
        let up = self.vec3("view up")?;
        self.expect_eol("view up")?;
        if let Some(defect) = ViewDefect::of(from, at, up) {
            return Err(SceneError::Invalid {
                loc: SourceLoc::new(Arc::clone(&self.file), up_line, 1),
                field: "view up",
                problem: defect.problem(),
            });
        }

        self.view_line("angle", "an `angle` line")?;
        let angle = self.number_where(
            "view angle",
            "an angle in degrees between 0 and 180 (exclusive)",
            |a| a > 0.0 && a < 180.0,
        )?;
        self.expect_eol("view angle")?;

        self.view_line("hither", "a `hither` line")?;
        let hither = self.number_where("view hither", "a distance ≥ 0", |h| h >= 0.0)?;
        self.expect_eol("view hither")?;

        self.view_line("resolution", "a `resolution` line")?;
        const PIXELS: &str = "a whole number of pixels from 1 to 32768";
        let max = u64::from(MAX_RESOLUTION);
        let (w, _) = self.whole("view resolution", PIXELS, 1, max)?;
        let (h, _) = self.whole("view resolution", PIXELS, 1, max)?;
        self.expect_eol("view resolution")?;

        self.view = Some(View {
            from,
            at,
            up,
            angle,
            hither,
            resolution: [w, h].map(|v| u32::try_from(v).unwrap_or(MAX_RESOLUTION)),
            loc,
        });
        Ok(())
    }

    fn light(&mut self, tok: Tok<'_>) -> R<()> {
        let loc = self.loc_at(tok.at);
        let position = self.vec3("light position")?;
        let colour = if self.at_eol() {
            None
        } else {
            let c = |p: &mut Self| p.number_where("light colour", "a number ≥ 0", |v| v >= 0.0);
            Some(DVec3::new(c(self)?, c(self)?, c(self)?))
        };
        self.expect_eol("light")?;
        self.scene.lights.push(Light {
            position,
            colour,
            loc,
        });
        Ok(())
    }

    fn material(&mut self, tok: Tok<'_>) -> R<()> {
        let loc = self.loc_at(tok.at);
        let colour = self.colour("material colour")?;
        let nonneg = |v: f64| v >= 0.0;
        let kd = self.number_where("material Kd", "a number ≥ 0", nonneg)?;
        let ks = self.number_where("material Ks", "a number ≥ 0", nonneg)?;
        let shine = self.number_where("material Shine", "a number ≥ 0", nonneg)?;
        let transmittance = self.number_where("material T", "a number from 0 to 1", |v| {
            (0.0..=1.0).contains(&v)
        })?;
        let (ior, ior_tok) = self.number_tok("material index of refraction")?;
        if ior < 0.0 {
            return Err(self.bad(ior_tok, "material index of refraction", "a number ≥ 0"));
        }
        if transmittance > 0.0 && ior <= 0.0 {
            return Err(self.bad(
                ior_tok,
                "material index of refraction",
                "a number > 0 (the material transmits: T > 0)",
            ));
        }
        self.expect_eol("material")?;
        self.material = Some(self.scene.materials.len());
        self.scene.materials.push(Material {
            colour,
            kd,
            ks,
            shine,
            transmittance,
            ior,
            loc: Some(loc),
        });
        Ok(())
    }

    fn current_material(&self) -> usize {
        self.material.unwrap_or(0)
    }

    fn sphere(&mut self, tok: Tok<'_>) -> R<()> {
        let loc = self.loc_at(tok.at);
        let centre = self.vec3("sphere centre")?;
        let radius = self.number_where("sphere radius", "a positive number", |r| r > 0.0)?;
        self.expect_eol("sphere")?;
        let material = self.current_material();
        self.scene.spheres.push(Object {
            shape: Sphere { centre, radius },
            material,
            loc,
        });
        Ok(())
    }

    fn cone(&mut self, tok: Tok<'_>) -> R<()> {
        let loc = self.loc_at(tok.at);
        const BASE: &str = "base.x base.y base.z base_radius";
        const APEX: &str = "apex.x apex.y apex.z apex_radius";
        if self.at_eol() {
            self.record_line("cone base", BASE)?;
        }
        let base = self.vec3("cone base")?;
        let base_radius = self.number("cone base radius")?;
        if self.at_eol() {
            self.record_line("cone apex", APEX)?;
        }
        let apex = self.vec3("cone apex")?;
        // NFF's negative radii (an inside-out cone: only its inside
        // visible) come in pairs; rrt shades both sides of every surface.
        let apex_radius = if base_radius < 0.0 {
            self.number_where(
                "cone apex radius",
                "a number ≤ 0 (the base radius is negative: an inside-out cone)",
                |r| r <= 0.0,
            )?
        } else if base_radius > 0.0 {
            self.number_where(
                "cone apex radius",
                "a number ≥ 0 (the base radius is positive)",
                |r| r >= 0.0,
            )?
        } else {
            self.number("cone apex radius")?
        };
        let (base_radius, apex_radius) = (base_radius.abs(), apex_radius.abs());
        self.expect_eol("cone")?;
        if base == apex {
            return Err(SceneError::Invalid {
                loc,
                field: "cone",
                problem: "base and apex coincide: the cone has no axis",
            });
        }
        if base_radius == 0.0 && apex_radius == 0.0 {
            return Err(SceneError::Invalid {
                loc,
                field: "cone",
                problem: "both radii are 0: the cone has no surface",
            });
        }
        let material = self.current_material();
        self.scene.cones.push(Object {
            shape: Cone {
                base,
                base_radius,
                apex,
                apex_radius,
            },
            material,
            loc,
        });
        Ok(())
    }

    fn polygon(&mut self, tok: Tok<'_>, patch: bool) -> R<()> {
        let loc = self.loc_at(tok.at);
        let (count_field, vertex_field, line_expected) = if patch {
            (
                "patch vertex count",
                "patch vertex",
                "a line `vert.x vert.y vert.z norm.x norm.y norm.z`",
            )
        } else {
            (
                "polygon vertex count",
                "polygon vertex",
                "a line `vert.x vert.y vert.z`",
            )
        };
        let (count, count_tok) = self.whole(
            count_field,
            "a whole number of vertices, at least 3",
            3,
            u64::MAX,
        )?;
        self.expect_eol(count_field)?;
        let count_loc = self.loc_at(count_tok.at);
        // Refuse before allocating: each vertex takes a line.
        let remaining = self.remaining_lines();
        if count > remaining {
            return Err(SceneError::CountExceedsInput {
                loc: self.loc_at(count_tok.at),
                field: count_field,
                count,
                remaining,
            });
        }
        let have = u64::try_from(self.scene.vertices.len()).unwrap_or(u64::MAX);
        let total = have.saturating_add(count);
        if total > self.opts.max_vertices {
            return Err(SceneError::TooManyVertices {
                loc: self.loc_at(count_tok.at),
                field: count_field,
                count,
                total,
                limit: self.opts.max_vertices,
            });
        }
        // `count` ≤ the lines left, which fit in memory: the conversion holds.
        let n = usize::try_from(count).unwrap_or(0);
        let first = self.scene.vertices.len();
        self.scene.vertices.reserve(n);
        self.scene.normals.reserve(n);
        for _ in 0..n {
            self.record_line(vertex_field, line_expected)?;
            let v = self.vec3(vertex_field)?;
            let normal = if patch {
                let at = self.pos;
                let nrm = self.vec3("patch normal")?;
                if nrm.try_normalize().is_none() {
                    let skip = self.line.get(at..).map_or(0, |r| {
                        r.len()
                            - r.trim_start_matches(|c: char| c.is_ascii_whitespace())
                                .len()
                    });
                    return Err(SceneError::Invalid {
                        loc: self.loc_at(at + skip),
                        field: "patch normal",
                        problem: "zero (or too large) vector: it has no direction",
                    });
                }
                nrm
            } else {
                DVec3::ZERO
            };
            self.expect_eol(vertex_field)?;
            self.scene.vertices.push(v);
            self.scene.normals.push(normal);
        }
        let vertices = self.scene.vertices.get(first..).unwrap_or_default();
        let cut = super::polygon::cut(vertices, &mut self.scene.cut_budget).map_err(|problem| {
            SceneError::Invalid {
                loc: count_loc,
                field: count_field,
                problem,
            }
        })?;
        let material = self.current_material();
        self.scene.polygons.push(Polygon {
            first,
            count: n,
            patch,
            material,
            cut,
            loc,
        });
        Ok(())
    }
}
