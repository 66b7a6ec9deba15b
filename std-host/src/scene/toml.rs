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
//! | `volume = "NAME"` | a volume of `[volume.NAME]`: its iso-surface, gray-level normals |
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
//! # Errors
//! Unknown keys (`deny_unknown_fields`), wrong types, missing keys, bad
//! values and the errors of the files a scene refers to are
//! [`SceneError::Toml`] naming the scene file, line and column (from
//! toml's spans) and the key. Sizes are checked before anything is
//! allocated: file sizes against their readers' limits, volume and vox
//! dimensions against [`Options`].

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use ::toml::Spanned;
use glam::{DAffine3, DQuat, DVec3};
use rrt_core::csg::{CsgNode, MAX_NODES};
use serde::Deserialize;

use super::error::SceneError;
use super::loc::SourceLoc;
use super::objects::{Csg, CsgLeaf, SceneTexture, SceneVolume, Solid, TextureKind};
use super::objects::{VolumeObject, VoxObject};
use super::text::{byte_loc, read_text};
use super::{Light, Material, Object, Polygon, Scene, View, bpt, nff, obj};
use crate::shape::{Cone, Cuboid, Sphere, Torus};
use crate::texture::{AnyTexture, Blend, Checker, ImageTexture, Mapping, Marble, Wood, Wrap};
use crate::volume::computed::{self, Metaball, Metaballs};
use crate::volume::raw::{self, RawSpec};
use crate::volume::{self, Classifier, ColorRamp, Endian, Grid, Placement, Ramp, SampleType};

/// Largest TOML scene file read, in bytes.
pub const MAX_FILE_BYTES: u64 = 16 << 20;

/// Limits of a TOML scene, checked before allocating.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Options {
    /// Limits for each volume's samples.
    pub volume: volume::Limits,
    /// Most `.vox` file bytes.
    pub max_vox_bytes: u64,
    /// Most vertices over all polygons (meshes, patches, NFF includes).
    pub max_vertices: usize,
    /// Most `steps` per Bézier patch side.
    pub max_patch_steps: u32,
    /// Whether files may be read at all (the fuzz target parses without).
    pub read_files: bool,
}

impl Default for Options {
    fn default() -> Self {
        Self {
            volume: volume::Limits::default(),
            max_vox_bytes: 256 << 20,
            max_vertices: 1 << 26,
            max_patch_steps: 64,
            read_files: true,
        }
    }
}

// ---------------------------------------------------------------- schema

type V3 = [f64; 3];

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Doc {
    camera: Spanned<CameraDef>,
    #[serde(default)]
    background: Option<V3>,
    #[serde(default)]
    light: Vec<Spanned<LightDef>>,
    #[serde(default)]
    material: BTreeMap<String, Spanned<MaterialDef>>,
    #[serde(default)]
    volume: BTreeMap<String, Spanned<VolumeDef>>,
    #[serde(default)]
    solid: BTreeMap<String, Spanned<SolidDef>>,
    #[serde(default)]
    object: Vec<Spanned<ObjectDef>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct CameraDef {
    from: V3,
    at: V3,
    #[serde(default = "default_up")]
    up: V3,
    angle: f64,
    #[serde(default = "default_hither")]
    hither: f64,
    resolution: [u32; 2],
}

const fn default_up() -> V3 {
    [0.0, 0.0, 1.0]
}
const fn default_hither() -> f64 {
    1.0
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct LightDef {
    position: V3,
    #[serde(default)]
    colour: Option<V3>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct MaterialDef {
    #[serde(default = "default_colour")]
    colour: V3,
    #[serde(default = "one")]
    kd: f64,
    #[serde(default)]
    ks: f64,
    #[serde(default = "one")]
    shine: f64,
    #[serde(default)]
    transmittance: f64,
    #[serde(default = "one")]
    ior: f64,
    #[serde(default)]
    texture: Option<Spanned<TextureDef>>,
}

const fn default_colour() -> V3 {
    [0.8, 0.8, 0.8]
}
const fn one() -> f64 {
    1.0
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct TextureDef {
    #[serde(default)]
    modulate: bool,
    #[serde(default)]
    checker: Option<CheckerDef>,
    #[serde(default)]
    marble: Option<NoiseDef>,
    #[serde(default)]
    wood: Option<NoiseDef>,
    #[serde(default)]
    image: Option<ImageDef>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct CheckerDef {
    #[serde(default)]
    origin: V3,
    size: f64,
    colours: [[u8; 3]; 2],
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct NoiseDef {
    #[serde(default)]
    seed: u64,
    #[serde(default)]
    origin: V3,
    #[serde(default = "default_up")]
    direction: V3,
    period: f64,
    #[serde(default = "one")]
    noise_scale: f64,
    #[serde(default = "one")]
    turbulence: f64,
    #[serde(default = "default_octaves")]
    octaves: u32,
    colours: [[u8; 3]; 2],
}

const fn default_octaves() -> u32 {
    4
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ImageDef {
    file: Spanned<String>,
    #[serde(default)]
    wrap: Option<String>,
    #[serde(default)]
    planar: Option<PlanarDef>,
    #[serde(default)]
    cylindrical: Option<AxisDef>,
    #[serde(default)]
    spherical: Option<AxisDef>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct PlanarDef {
    origin: V3,
    u: V3,
    v: V3,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct AxisDef {
    centre: V3,
    axis: V3,
    reference: V3,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct VolumeDef {
    #[serde(default)]
    file: Option<Spanned<String>>,
    #[serde(default)]
    raw: Option<RawDef>,
    #[serde(default)]
    metaballs: Option<MetaballsDef>,
    iso: f64,
    #[serde(default)]
    opacity: Option<Vec<[f64; 2]>>,
    #[serde(default)]
    colours: Option<Vec<[f64; 4]>>,
    #[serde(default)]
    fit: Option<BoxDef>,
    #[serde(default)]
    translate: Option<V3>,
    #[serde(default)]
    scale: Option<f64>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawDef {
    file: Spanned<String>,
    dims: [u32; 3],
    #[serde(rename = "type")]
    sample_type: String,
    #[serde(default = "default_spacing")]
    spacing: V3,
    #[serde(default)]
    big_endian: bool,
    #[serde(default)]
    skip: u64,
}

const fn default_spacing() -> V3 {
    [1.0, 1.0, 1.0]
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct MetaballsDef {
    dims: [u32; 3],
    min: V3,
    max: V3,
    /// `[x, y, z, radius, strength]` each.
    balls: Vec<[f64; 5]>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct BoxDef {
    min: V3,
    max: V3,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct SphereDef {
    centre: V3,
    radius: f64,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ConeDef {
    base: V3,
    base_radius: f64,
    apex: V3,
    apex_radius: f64,
    #[serde(default)]
    capped: bool,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct TorusDef {
    centre: V3,
    #[serde(default = "default_up")]
    axis: V3,
    major: f64,
    minor: f64,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct SolidDef {
    #[serde(default)]
    material: Option<Spanned<String>>,
    #[serde(default)]
    sphere: Option<SphereDef>,
    #[serde(default, rename = "box")]
    cuboid: Option<BoxDef>,
    #[serde(default)]
    cone: Option<ConeDef>,
    #[serde(default)]
    torus: Option<TorusDef>,
    #[serde(default)]
    volume: Option<Spanned<String>>,
}

#[derive(Deserialize)]
#[serde(untagged)]
enum CsgExpr {
    Leaf(String),
    Op(CsgOp),
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct CsgOp {
    #[serde(default)]
    union: Option<Vec<CsgExpr>>,
    #[serde(default)]
    intersection: Option<Vec<CsgExpr>>,
    #[serde(default)]
    difference: Option<Vec<CsgExpr>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct TransformDef {
    #[serde(default)]
    translate: V3,
    #[serde(default = "one")]
    scale: f64,
    #[serde(default)]
    rotate_x: f64,
    #[serde(default)]
    rotate_y: f64,
    #[serde(default)]
    rotate_z: f64,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct BezierDef {
    file: Spanned<String>,
    #[serde(default = "default_steps")]
    steps: u32,
}

const fn default_steps() -> u32 {
    8
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct MeshDef {
    file: Spanned<String>,
    #[serde(default)]
    smooth: bool,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct VoxDef {
    file: Spanned<String>,
    #[serde(default)]
    position: V3,
    #[serde(default = "one")]
    cell: f64,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ObjectDef {
    #[serde(default)]
    material: Option<Spanned<String>>,
    #[serde(default)]
    transform: Option<TransformDef>,
    #[serde(default)]
    sphere: Option<SphereDef>,
    #[serde(default)]
    cone: Option<ConeDef>,
    #[serde(default)]
    polygon: Option<Vec<V3>>,
    #[serde(default, rename = "box")]
    cuboid: Option<BoxDef>,
    #[serde(default)]
    torus: Option<TorusDef>,
    #[serde(default)]
    bezier: Option<BezierDef>,
    #[serde(default)]
    mesh: Option<MeshDef>,
    #[serde(default)]
    nff: Option<Spanned<String>>,
    #[serde(default)]
    volume: Option<Spanned<String>>,
    #[serde(default)]
    vox: Option<VoxDef>,
    #[serde(default)]
    csg: Option<Spanned<CsgOp>>,
}

// ---------------------------------------------------------------- reading

/// Reads the TOML scene at `path`.
///
/// # Errors
/// [`SceneError`] naming the file, and the line, column and key for
/// everything wrong inside it (module docs).
pub fn load(path: &Path, opts: &Options) -> Result<Scene, SceneError> {
    let name: Arc<str> = Arc::from(path.to_string_lossy().as_ref());
    let text = read_text(path, &name, MAX_FILE_BYTES)?;
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
        let at = e.span().map_or(0, |s| s.start);
        SceneError::Toml {
            loc: byte_loc(&file, text.as_bytes(), at),
            key: key_before(text, at),
            msg: e.message().trim().to_owned(),
        }
    })?;
    Builder {
        file,
        text,
        dir: dir.to_path_buf(),
        opts: *opts,
        materials: BTreeMap::new(),
        volumes: BTreeMap::new(),
    }
    .build(doc)
}

struct Builder<'t> {
    file: Arc<str>,
    text: &'t str,
    dir: PathBuf,
    opts: Options,
    materials: BTreeMap<String, usize>,
    volumes: BTreeMap<String, SceneVolume>,
}

fn finite3(v: V3) -> Option<DVec3> {
    let d = DVec3::from(v);
    d.is_finite().then_some(d)
}

impl Builder<'_> {
    fn loc(&self, span: std::ops::Range<usize>) -> SourceLoc {
        byte_loc(&self.file, self.text.as_bytes(), span.start)
    }

    fn err(&self, span: std::ops::Range<usize>, key: &str, msg: impl Into<String>) -> SceneError {
        SceneError::Toml {
            loc: self.loc(span),
            key: key.to_owned(),
            msg: msg.into(),
        }
    }

    fn vec3(&self, span: &std::ops::Range<usize>, key: &str, v: V3) -> Result<DVec3, SceneError> {
        finite3(v).ok_or_else(|| self.err(span.clone(), key, "expected finite numbers"))
    }

    fn path(&self, p: &Spanned<String>, key: &str) -> Result<(PathBuf, String), SceneError> {
        if !self.opts.read_files {
            return Err(self.err(p.span(), key, "files are not read here"));
        }
        let full = self.dir.join(p.get_ref());
        if !full.is_file() {
            return Err(self.err(p.span(), key, format!("{}: no such file", full.display())));
        }
        let shown = full.to_string_lossy().into_owned();
        Ok((full, shown))
    }

    fn build(mut self, doc: Doc) -> Result<Scene, SceneError> {
        let cs = doc.camera.span();
        let c = doc.camera.get_ref();
        let view = View {
            from: self.vec3(&cs, "camera.from", c.from)?,
            at: self.vec3(&cs, "camera.at", c.at)?,
            up: self.vec3(&cs, "camera.up", c.up)?,
            angle: c.angle,
            hither: c.hither,
            resolution: c.resolution,
            loc: self.loc(cs.clone()),
        };
        if view.from == view.at {
            return Err(self.err(cs, "camera.at", "equals camera.from"));
        }
        if view.up.cross(view.at - view.from).length_squared() == 0.0 {
            return Err(self.err(cs, "camera.up", "parallel to the view direction"));
        }
        if !(view.angle > 0.0 && view.angle < 180.0) {
            return Err(self.err(cs, "camera.angle", "expected 0 < angle < 180"));
        }
        if !view.hither.is_finite() {
            return Err(self.err(cs, "camera.hither", "expected a finite number"));
        }
        if view.resolution.contains(&0) || view.resolution.iter().any(|&r| r > 1 << 15) {
            return Err(self.err(cs, "camera.resolution", "expected 1 to 32768 pixels"));
        }
        let mut scene = Scene::empty(Arc::clone(&self.file), view);
        if let Some(b) = doc.background {
            scene.background = finite3(b)
                .filter(|b| b.cmpge(DVec3::ZERO).all() && b.cmple(DVec3::ONE).all())
                .ok_or_else(|| {
                    self.err(0..0, "background", "expected colour channels in [0, 1]")
                })?;
        }
        for l in &doc.light {
            let s = l.span();
            let d = l.get_ref();
            scene.lights.push(Light {
                position: self.vec3(&s, "light.position", d.position)?,
                colour: d
                    .colour
                    .map(|c| self.vec3(&s, "light.colour", c))
                    .transpose()?,
                loc: self.loc(s),
            });
        }
        for (name, m) in &doc.material {
            self.material(&mut scene, name, m)?;
        }
        for (name, v) in &doc.volume {
            let sv = self.volume(name, v)?;
            self.volumes.insert(name.clone(), sv);
        }
        for o in &doc.object {
            self.object(&mut scene, &doc, o)?;
        }
        if scene.has_no_objects() {
            return Err(SceneError::NoObjects {
                file: Arc::clone(&self.file),
            });
        }
        if scene.materials.is_empty() {
            scene.materials.push(Material::DEFAULT);
        }
        Ok(scene)
    }

    fn material(
        &mut self,
        scene: &mut Scene,
        name: &str,
        m: &Spanned<MaterialDef>,
    ) -> Result<(), SceneError> {
        let s = m.span();
        let d = m.get_ref();
        let key = |k: &str| format!("material.{name}.{k}");
        let colour = self.vec3(&s, &key("colour"), d.colour)?;
        if !(colour.cmpge(DVec3::ZERO).all() && colour.cmple(DVec3::ONE).all()) {
            return Err(self.err(s, &key("colour"), "expected channels in [0, 1]"));
        }
        for (k, v) in [
            ("kd", d.kd),
            ("ks", d.ks),
            ("shine", d.shine),
            ("ior", d.ior),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(self.err(s, &key(k), "expected a finite number ≥ 0"));
            }
        }
        if !(0.0..=1.0).contains(&d.transmittance) || (d.transmittance > 0.0 && d.ior <= 0.0) {
            return Err(self.err(
                s,
                &key("transmittance"),
                "expected 0 to 1 (and ior > 0 when > 0)",
            ));
        }
        let index = scene.materials.len();
        scene.materials.push(Material {
            colour,
            kd: d.kd,
            ks: d.ks,
            shine: d.shine,
            transmittance: d.transmittance,
            ior: d.ior,
            loc: Some(self.loc(s)),
        });
        if let Some(t) = &d.texture {
            let tex = self.texture(&key("texture"), t)?;
            scene.material_textures.insert(index, scene.textures.len());
            scene.textures.push(tex);
        }
        self.materials.insert(name.to_owned(), index);
        Ok(())
    }

    fn texture(&self, key: &str, t: &Spanned<TextureDef>) -> Result<SceneTexture, SceneError> {
        let s = t.span();
        let d = t.get_ref();
        let n = usize::from(d.checker.is_some())
            + usize::from(d.marble.is_some())
            + usize::from(d.wood.is_some())
            + usize::from(d.image.is_some());
        if n != 1 {
            return Err(self.err(
                s,
                key,
                "expected exactly one of checker, marble, wood, image",
            ));
        }
        let bad = |e: crate::texture::TextureError| self.err(s.clone(), key, e.to_string());
        let any = if let Some(c) = &d.checker {
            AnyTexture::Checker(
                Checker::new(self.vec3(&s, key, c.origin)?, c.size, c.colours).map_err(bad)?,
            )
        } else if let Some(m) = &d.marble {
            AnyTexture::Marble(
                Marble::new(
                    m.seed,
                    self.vec3(&s, key, m.direction)?,
                    m.period,
                    m.noise_scale,
                    m.turbulence,
                    m.octaves,
                    m.colours,
                )
                .map_err(bad)?,
            )
        } else if let Some(w) = &d.wood {
            AnyTexture::Wood(
                Wood::new(
                    w.seed,
                    self.vec3(&s, key, w.origin)?,
                    self.vec3(&s, key, w.direction)?,
                    w.period,
                    w.noise_scale,
                    w.turbulence,
                    w.octaves,
                    w.colours,
                )
                .map_err(bad)?,
            )
        } else if let Some(i) = &d.image {
            let mapping = match (&i.planar, &i.cylindrical, &i.spherical) {
                (Some(p), None, None) => Mapping::Planar {
                    origin: self.vec3(&s, key, p.origin)?,
                    u_axis: self.vec3(&s, key, p.u)?,
                    v_axis: self.vec3(&s, key, p.v)?,
                },
                (None, Some(a), None) => Mapping::Cylindrical {
                    origin: self.vec3(&s, key, a.centre)?,
                    axis: self.vec3(&s, key, a.axis)?,
                    reference: self.vec3(&s, key, a.reference)?,
                },
                (None, None, Some(a)) => Mapping::Spherical {
                    centre: self.vec3(&s, key, a.centre)?,
                    pole: self.vec3(&s, key, a.axis)?,
                    reference: self.vec3(&s, key, a.reference)?,
                },
                _ => {
                    return Err(self.err(
                        s,
                        key,
                        "an image needs exactly one of planar, cylindrical, spherical",
                    ));
                }
            };
            let wrap = match i.wrap.as_deref() {
                None | Some("repeat") => Wrap::Repeat,
                Some("mirror") => Wrap::Mirror,
                Some("clamp") => Wrap::Clamp,
                Some(_) => {
                    return Err(self.err(s, key, "wrap: expected repeat, mirror or clamp"));
                }
            };
            let (path, _) = self.path(&i.file, &format!("{key}.image.file"))?;
            let img = ImageTexture::open(&path, mapping).map_err(|e| {
                self.err(i.file.span(), &format!("{key}.image.file"), e.to_string())
            })?;
            AnyTexture::Image(img.with_wrap(wrap))
        } else {
            return Err(self.err(s, key, "no texture"));
        };
        Ok(SceneTexture {
            kind: TextureKind::World(any),
            blend: if d.modulate {
                Blend::Modulate
            } else {
                Blend::Replace
            },
            loc: self.loc(s),
        })
    }

    fn volume(&self, name: &str, v: &Spanned<VolumeDef>) -> Result<SceneVolume, SceneError> {
        let s = v.span();
        let d = v.get_ref();
        let key = |k: &str| format!("volume.{name}.{k}");
        let sources = usize::from(d.file.is_some())
            + usize::from(d.raw.is_some())
            + usize::from(d.metaballs.is_some());
        if sources != 1 {
            return Err(self.err(
                s,
                &key("file"),
                "expected exactly one of file (NRRD), raw, metaballs",
            ));
        }
        let data = if let Some(f) = &d.file {
            let (path, _) = self.path(f, &key("file"))?;
            volume::nrrd::read(&path, &self.opts.volume)
                .map_err(|e| self.err(f.span(), &key("file"), e.to_string()))?
        } else if let Some(r) = &d.raw {
            let sample_type = match r.sample_type.as_str() {
                "uint8" | "u8" => SampleType::U8,
                "int16" | "i16" => SampleType::I16,
                "uint16" | "u16" => SampleType::U16,
                "float" | "f32" => SampleType::F32,
                _ => {
                    return Err(self.err(
                        s,
                        &key("raw.type"),
                        "expected uint8, int16, uint16 or float",
                    ));
                }
            };
            let (path, _) = self.path(&r.file, &key("raw.file"))?;
            let spec = RawSpec {
                dims: r.dims,
                sample_type,
                endian: if r.big_endian {
                    Endian::Big
                } else {
                    Endian::Little
                },
                grid: Grid::axis_aligned(r.spacing, DVec3::ZERO),
                skip: r.skip,
            };
            raw::read(&path, &spec, &self.opts.volume)
                .map_err(|e| self.err(r.file.span(), &key("raw"), e.to_string()))?
        } else if let Some(m) = &d.metaballs {
            let lo = self.vec3(&s, &key("metaballs.min"), m.min)?;
            let hi = self.vec3(&s, &key("metaballs.max"), m.max)?;
            let n = m.dims.map(|d| f64::from(d.max(2) - 1));
            let spacing = [
                (hi.x - lo.x) / n[0],
                (hi.y - lo.y) / n[1],
                (hi.z - lo.z) / n[2],
            ];
            let mut balls = Vec::with_capacity(m.balls.len().min(1024));
            for b in &m.balls {
                if !(b.iter().all(|x| x.is_finite()) && b[3] > 0.0) {
                    return Err(self.err(
                        s,
                        &key("metaballs.balls"),
                        "expected finite [x, y, z, radius > 0, strength]",
                    ));
                }
                balls.push(Metaball {
                    centre: DVec3::new(b[0], b[1], b[2]),
                    radius: b[3],
                    strength: b[4],
                });
            }
            computed::sample(
                &Metaballs(balls),
                m.dims,
                Grid::axis_aligned(spacing, lo),
                &self.opts.volume,
            )
            .map_err(|e| self.err(s.clone(), &key("metaballs"), e.to_string()))?
        } else {
            return Err(self.err(s, &key("file"), "no data"));
        };
        let mut classifier = Classifier::iso(d.iso);
        if let Some(o) = &d.opacity {
            let ramp = Ramp::new(o.iter().map(|p| (p[0], p[1])).collect())
                .map_err(|e| self.err(s.clone(), &key("opacity"), e.to_string()))?;
            classifier = classifier.with_opacity(ramp);
        }
        if let Some(c) = &d.colours {
            let mut pts = Vec::with_capacity(c.len().min(4096));
            for p in c {
                if !p.iter().all(|x| x.is_finite())
                    || p[1..].iter().any(|&x| !(0.0..=1.0).contains(&x))
                {
                    return Err(self.err(
                        s,
                        &key("colours"),
                        "expected [value, r, g, b] with channels in [0, 1]",
                    ));
                }
                let ch = |x: f64| (x * 255.0).round() as u8;
                pts.push((p[0], [ch(p[1]), ch(p[2]), ch(p[3])]));
            }
            let ramp = ColorRamp::new(pts)
                .map_err(|e| self.err(s.clone(), &key("colours"), e.to_string()))?;
            classifier = classifier.with_color(ramp);
        }
        classifier
            .validate()
            .map_err(|e| self.err(s.clone(), &key("iso"), e.to_string()))?;
        let placement = match (&d.fit, d.translate, d.scale) {
            (Some(b), None, None) => Placement::fit_into(
                &data,
                crate::world::Bounds {
                    min: self.vec3(&s, &key("fit.min"), b.min)?,
                    max: self.vec3(&s, &key("fit.max"), b.max)?,
                },
            ),
            (None, t, sc) => Placement::new(
                self.vec3(&s, &key("translate"), t.unwrap_or_default())?,
                sc.unwrap_or(1.0),
            ),
            _ => {
                return Err(self.err(s, &key("fit"), "give fit, or translate and scale, not both"));
            }
        }
        .map_err(|e| self.err(s.clone(), &key("fit"), e.to_string()))?;
        Ok(SceneVolume {
            volume: Arc::new(data),
            placement,
            classifier,
        })
    }

    fn material_of(
        &self,
        m: Option<&Spanned<String>>,
        at: &std::ops::Range<usize>,
        key: &str,
    ) -> Result<usize, SceneError> {
        let Some(m) = m else {
            return Err(self.err(at.clone(), key, "missing: every object names a material"));
        };
        self.materials.get(m.get_ref()).copied().ok_or_else(|| {
            self.err(
                m.span(),
                key,
                format!("no [material.{}] in this scene", m.get_ref()),
            )
        })
    }

    fn push_polygon(
        &self,
        scene: &mut Scene,
        vertices: &[DVec3],
        normals: Option<&[DVec3]>,
        material: usize,
        loc: &SourceLoc,
        span: &std::ops::Range<usize>,
    ) -> Result<(), SceneError> {
        if scene.vertices.len().saturating_add(vertices.len()) > self.opts.max_vertices {
            return Err(self.err(
                span.clone(),
                "object",
                format!("more than {} vertices in the scene", self.opts.max_vertices),
            ));
        }
        let first = scene.vertices.len();
        scene.vertices.extend_from_slice(vertices);
        match normals {
            Some(n) => scene.normals.extend_from_slice(n),
            None => scene
                .normals
                .extend(std::iter::repeat_n(DVec3::ZERO, vertices.len())),
        }
        scene.polygons.push(Polygon {
            first,
            count: vertices.len(),
            patch: normals.is_some(),
            material,
            loc: loc.clone(),
        });
        Ok(())
    }

    #[allow(clippy::too_many_lines)]
    fn object(
        &self,
        scene: &mut Scene,
        doc: &Doc,
        o: &Spanned<ObjectDef>,
    ) -> Result<(), SceneError> {
        let s = o.span();
        let d = o.get_ref();
        let loc = self.loc(s.clone());
        let shapes = [
            d.sphere.is_some(),
            d.cone.is_some(),
            d.polygon.is_some(),
            d.cuboid.is_some(),
            d.torus.is_some(),
            d.bezier.is_some(),
            d.mesh.is_some(),
            d.nff.is_some(),
            d.volume.is_some(),
            d.vox.is_some(),
            d.csg.is_some(),
        ];
        if shapes.iter().filter(|&&b| b).count() != 1 {
            return Err(self.err(
                s,
                "object",
                "expected exactly one of sphere, cone, polygon, box, torus, bezier, mesh, nff, volume, vox, csg",
            ));
        }
        let transform = match &d.transform {
            None => DAffine3::IDENTITY,
            Some(t) => {
                let tr = self.vec3(&s, "object.transform.translate", t.translate)?;
                let angles_ok = [t.rotate_x, t.rotate_y, t.rotate_z]
                    .iter()
                    .all(|a| a.is_finite());
                if !(t.scale.is_finite() && t.scale > 0.0 && angles_ok) {
                    return Err(self.err(
                        s,
                        "object.transform",
                        "expected scale > 0 and finite angles",
                    ));
                }
                let q = DQuat::from_rotation_z(t.rotate_z.to_radians())
                    * DQuat::from_rotation_y(t.rotate_y.to_radians())
                    * DQuat::from_rotation_x(t.rotate_x.to_radians());
                DAffine3::from_scale_rotation_translation(DVec3::splat(t.scale), q, tr)
            }
        };
        if d.transform.is_some() && !(d.polygon.is_some() || d.bezier.is_some() || d.mesh.is_some())
        {
            return Err(self.err(
                s,
                "object.transform",
                "only polygons, bezier patches and meshes take a transform",
            ));
        }
        if let Some(n) = &d.nff {
            if d.material.is_some() {
                return Err(self.err(s, "object.material", "an NFF file brings its own materials"));
            }
            let (path, _) = self.path(n, "object.nff")?;
            let inc = nff::load(&path, &nff::ParseOptions::default())
                .map_err(|e| self.err(n.span(), "object.nff", e.to_string()))?;
            return self.include(scene, inc, &s);
        }
        if let Some(c) = &d.csg {
            return self.csg(scene, doc, c, d.material.as_ref(), &s);
        }
        let material = self.material_of(d.material.as_ref(), &s, "object.material")?;
        if let Some(sp) = &d.sphere {
            let centre = self.vec3(&s, "object.sphere.centre", sp.centre)?;
            if !(sp.radius.is_finite() && sp.radius > 0.0) {
                return Err(self.err(s, "object.sphere.radius", "expected a number > 0"));
            }
            scene.spheres.push(Object {
                shape: Sphere {
                    centre,
                    radius: sp.radius,
                },
                material,
                loc,
            });
        } else if let Some(c) = &d.cone {
            let shape = self.cone(c, &s, "object.cone")?;
            if c.capped {
                scene
                    .csgs
                    .push(single_leaf(Solid::Cone(shape), material, loc));
            } else {
                scene.cones.push(Object {
                    shape,
                    material,
                    loc,
                });
            }
        } else if let Some(p) = &d.polygon {
            if p.len() < 3 || p.len() > 1 << 16 {
                return Err(self.err(s, "object.polygon", "expected 3 to 65536 vertices"));
            }
            let v = p
                .iter()
                .map(|&q| {
                    self.vec3(&s, "object.polygon", q)
                        .map(|q| transform.transform_point3(q))
                })
                .collect::<Result<Vec<_>, _>>()?;
            self.push_polygon(scene, &v, None, material, &loc, &s)?;
        } else if let Some(b) = &d.cuboid {
            let lo = self.vec3(&s, "object.box.min", b.min)?;
            let hi = self.vec3(&s, "object.box.max", b.max)?;
            if !lo.cmplt(hi).all() {
                return Err(self.err(s, "object.box", "expected min < max on every axis"));
            }
            for face in box_faces(lo, hi) {
                self.push_polygon(scene, &face, None, material, &loc, &s)?;
            }
        } else if let Some(t) = &d.torus {
            scene.tori.push(Object {
                shape: self.torus(t, &s, "object.torus")?,
                material,
                loc,
            });
        } else if let Some(b) = &d.bezier {
            if b.steps == 0 || b.steps > self.opts.max_patch_steps {
                return Err(self.err(
                    s,
                    "object.bezier.steps",
                    format!("expected 1 to {}", self.opts.max_patch_steps),
                ));
            }
            let (path, shown) = self.path(&b.file, "object.bezier.file")?;
            let patches = bpt::load(&path, &shown)
                .map_err(|e| self.err(b.file.span(), "object.bezier.file", e.to_string()))?;
            let per = (b.steps as usize + 1).pow(2);
            if patches
                .len()
                .saturating_mul(per)
                .saturating_add(scene.vertices.len())
                > self.opts.max_vertices
            {
                return Err(self.err(s, "object.bezier", "too many vertices"));
            }
            for p in &patches {
                let c = p.map(|row| row.map(|q| transform.transform_point3(q)));
                for (quad, normals) in tessellate_patch(&c, b.steps) {
                    self.push_polygon(scene, &quad, Some(&normals), material, &loc, &s)?;
                }
            }
        } else if let Some(m) = &d.mesh {
            let (path, shown) = self.path(&m.file, "object.mesh.file")?;
            let mesh = obj::load(&path, &shown)
                .map_err(|e| self.err(m.file.span(), "object.mesh.file", e.to_string()))?;
            if mesh
                .triangles
                .len()
                .saturating_mul(3)
                .saturating_add(scene.vertices.len())
                > self.opts.max_vertices
            {
                return Err(self.err(s, "object.mesh", "too many vertices"));
            }
            let normals = if m.smooth {
                Some(
                    mesh.normals
                        .clone()
                        .unwrap_or_else(|| obj::smooth_normals(&mesh)),
                )
            } else {
                None
            };
            let pos: Vec<DVec3> = mesh
                .positions
                .iter()
                .map(|&p| transform.transform_point3(p))
                .collect();
            for t in &mesh.triangles {
                let idx = t.map(|i| i as usize);
                let (Some(a), Some(b2), Some(c)) =
                    (pos.get(idx[0]), pos.get(idx[1]), pos.get(idx[2]))
                else {
                    return Err(self.err(s, "object.mesh", "index out of range"));
                };
                let n = normals.as_ref().map(|n| {
                    idx.map(|i| {
                        let v = n.get(i).copied().unwrap_or(DVec3::ZERO);
                        transform.transform_vector3(v).normalize_or_zero()
                    })
                });
                // A vertex without a usable normal: the flat triangle.
                let n = n.filter(|n| n.iter().all(|v| v.length_squared() > 0.5));
                self.push_polygon(
                    scene,
                    &[*a, *b2, *c],
                    n.as_ref().map(|n| &n[..]),
                    material,
                    &loc,
                    &s,
                )?;
            }
        } else if let Some(v) = &d.volume {
            let data = self.volumes.get(v.get_ref()).ok_or_else(|| {
                self.err(
                    v.span(),
                    "object.volume",
                    format!("no [volume.{}] in this scene", v.get_ref()),
                )
            })?;
            scene.volumes.push(VolumeObject {
                data: data.clone(),
                material,
                loc,
            });
        } else if let Some(v) = &d.vox {
            let (path, _) = self.path(&v.file, "object.vox.file")?;
            let size = std::fs::metadata(&path)
                .map(|m| m.len())
                .unwrap_or(u64::MAX);
            if size > self.opts.max_vox_bytes {
                return Err(self.err(
                    v.file.span(),
                    "object.vox.file",
                    format!(
                        "{size} bytes, more than the limit of {}",
                        self.opts.max_vox_bytes
                    ),
                ));
            }
            let vox = crate::vox::read(&path)
                .map_err(|e| self.err(v.file.span(), "object.vox.file", e.to_string()))?;
            let position = self.vec3(&s, "object.vox.position", v.position)?;
            if !(v.cell.is_finite() && v.cell > 0.0) {
                return Err(self.err(s, "object.vox.cell", "expected a number > 0"));
            }
            scene.voxes.push(VoxObject {
                vox: Arc::new(vox),
                position,
                cell: v.cell,
                material,
                loc,
            });
        }
        Ok(())
    }

    fn cone(&self, c: &ConeDef, s: &std::ops::Range<usize>, key: &str) -> Result<Cone, SceneError> {
        let base = self.vec3(s, key, c.base)?;
        let apex = self.vec3(s, key, c.apex)?;
        let ok = base != apex
            && c.base_radius.is_finite()
            && c.apex_radius.is_finite()
            && c.base_radius >= 0.0
            && c.apex_radius >= 0.0
            && c.base_radius + c.apex_radius > 0.0;
        if !ok {
            return Err(self.err(
                s.clone(),
                key,
                "expected base ≠ apex and radii ≥ 0, not both 0",
            ));
        }
        Ok(Cone {
            base,
            base_radius: c.base_radius,
            apex,
            apex_radius: c.apex_radius,
        })
    }

    fn torus(
        &self,
        t: &TorusDef,
        s: &std::ops::Range<usize>,
        key: &str,
    ) -> Result<Torus, SceneError> {
        let centre = self.vec3(s, key, t.centre)?;
        let axis = self
            .vec3(s, key, t.axis)?
            .try_normalize()
            .ok_or_else(|| self.err(s.clone(), &format!("{key}.axis"), "zero axis"))?;
        if !(t.major.is_finite() && t.minor.is_finite() && t.major > 0.0 && t.minor > 0.0) {
            return Err(self.err(s.clone(), key, "expected major > 0 and minor > 0"));
        }
        Ok(Torus {
            centre,
            axis,
            major: t.major,
            minor: t.minor,
        })
    }

    fn solid(
        &self,
        doc: &Doc,
        name: &str,
        at: &std::ops::Range<usize>,
        default_material: Option<usize>,
    ) -> Result<CsgLeaf, SceneError> {
        let Some(def) = doc.solid.get(name) else {
            return Err(self.err(
                at.clone(),
                "object.csg",
                format!("no [solid.{name}] in this scene"),
            ));
        };
        let s = def.span();
        let d = def.get_ref();
        let key = format!("solid.{name}");
        let material = match (&d.material, default_material) {
            (Some(m), _) => self.material_of(Some(m), &s, &format!("{key}.material"))?,
            (None, Some(m)) => m,
            (None, None) => {
                return Err(self.err(
                    s,
                    &format!("{key}.material"),
                    "missing: give the solid or the CSG object a material",
                ));
            }
        };
        let n = usize::from(d.sphere.is_some())
            + usize::from(d.cuboid.is_some())
            + usize::from(d.cone.is_some())
            + usize::from(d.torus.is_some())
            + usize::from(d.volume.is_some());
        if n != 1 {
            return Err(self.err(
                s,
                &key,
                "expected exactly one of sphere, box, cone, torus, volume",
            ));
        }
        let shape = if let Some(sp) = &d.sphere {
            let centre = self.vec3(&s, &key, sp.centre)?;
            if !(sp.radius.is_finite() && sp.radius > 0.0) {
                return Err(self.err(s, &format!("{key}.sphere.radius"), "expected a number > 0"));
            }
            Solid::Sphere(Sphere {
                centre,
                radius: sp.radius,
            })
        } else if let Some(b) = &d.cuboid {
            let min = self.vec3(&s, &key, b.min)?;
            let max = self.vec3(&s, &key, b.max)?;
            if !min.cmplt(max).all() {
                return Err(self.err(s, &format!("{key}.box"), "expected min < max on every axis"));
            }
            Solid::Cuboid(Cuboid { min, max })
        } else if let Some(c) = &d.cone {
            Solid::Cone(self.cone(c, &s, &format!("{key}.cone"))?)
        } else if let Some(t) = &d.torus {
            Solid::Torus(self.torus(t, &s, &format!("{key}.torus"))?)
        } else if let Some(v) = &d.volume {
            Solid::Volume(self.volumes.get(v.get_ref()).cloned().ok_or_else(|| {
                self.err(
                    v.span(),
                    &format!("{key}.volume"),
                    format!("no [volume.{}] in this scene", v.get_ref()),
                )
            })?)
        } else {
            return Err(self.err(s, &key, "no shape"));
        };
        Ok(CsgLeaf {
            shape,
            material,
            loc: self.loc(s),
        })
    }

    fn csg(
        &self,
        scene: &mut Scene,
        doc: &Doc,
        root: &Spanned<CsgOp>,
        material: Option<&Spanned<String>>,
        s: &std::ops::Range<usize>,
    ) -> Result<(), SceneError> {
        let default_material = match material {
            Some(m) => Some(self.material_of(Some(m), s, "object.material")?),
            None => None,
        };
        let mut csg = Csg {
            nodes: Vec::new(),
            leaves: Vec::new(),
            loc: self.loc(s.clone()),
        };
        self.csg_op(
            doc,
            root.get_ref(),
            &root.span(),
            default_material,
            &mut csg,
            0,
        )?;
        // The volume rule (module docs).
        let leaf_has_volume = |l: u16| {
            matches!(
                csg.leaves.get(usize::from(l)).map(|l| &l.shape),
                Some(Solid::Volume(_))
            )
        };
        let volumes = csg
            .leaves
            .iter()
            .filter(|l| matches!(l.shape, Solid::Volume(_)))
            .count();
        if volumes > 0 {
            let ok = volumes == 1
                && match csg.nodes.last() {
                    Some(CsgNode::Difference(a, _) | CsgNode::Intersection(a, _)) => matches!(
                        csg.nodes.get(usize::from(*a)),
                        Some(CsgNode::Leaf(l)) if leaf_has_volume(*l)
                    ),
                    _ => false,
                };
            if !ok {
                return Err(self.err(
                    root.span(),
                    "object.csg",
                    "a volume may only be the first operand of the tree's top difference or intersection (and only one volume per tree)",
                ));
            }
        }
        scene.csgs.push(csg);
        Ok(())
    }

    fn csg_op(
        &self,
        doc: &Doc,
        d: &CsgOp,
        at: &std::ops::Range<usize>,
        material: Option<usize>,
        csg: &mut Csg,
        depth: usize,
    ) -> Result<u16, SceneError> {
        let s = at.clone();
        let too_big = || {
            self.err(
                s.clone(),
                "object.csg",
                format!("more than {MAX_NODES} nodes"),
            )
        };
        if depth > MAX_NODES {
            return Err(too_big());
        }
        let (kind, args) = match (&d.union, &d.intersection, &d.difference) {
            (Some(a), None, None) => (0, a),
            (None, Some(a), None) => (1, a),
            (None, None, Some(a)) => (2, a),
            _ => {
                return Err(self.err(
                    s,
                    "object.csg",
                    "expected exactly one of union, intersection, difference",
                ));
            }
        };
        if args.len() < 2 || args.len() > MAX_NODES {
            return Err(self.err(s, "object.csg", "an operation takes 2 or more operands"));
        }
        let mut acc: Option<u16> = None;
        for a in args {
            let id = match a {
                CsgExpr::Leaf(name) => {
                    let leaf = self.solid(doc, name, at, material)?;
                    let l = u16::try_from(csg.leaves.len()).map_err(|_| too_big())?;
                    csg.leaves.push(leaf);
                    if csg.nodes.len() >= MAX_NODES {
                        return Err(too_big());
                    }
                    csg.nodes.push(CsgNode::Leaf(l));
                    u16::try_from(csg.nodes.len() - 1).map_err(|_| too_big())?
                }
                CsgExpr::Op(inner) => self.csg_op(doc, inner, at, material, csg, depth + 1)?,
            };
            acc = Some(match acc {
                None => id,
                Some(prev) => {
                    if csg.nodes.len() >= MAX_NODES {
                        return Err(too_big());
                    }
                    csg.nodes.push(match kind {
                        0 => CsgNode::Union(prev, id),
                        1 => CsgNode::Intersection(prev, id),
                        _ => CsgNode::Difference(prev, id),
                    });
                    u16::try_from(csg.nodes.len() - 1).map_err(|_| too_big())?
                }
            });
        }
        acc.ok_or_else(too_big)
    }

    fn include(
        &self,
        scene: &mut Scene,
        inc: Scene,
        s: &std::ops::Range<usize>,
    ) -> Result<(), SceneError> {
        if scene.vertices.len().saturating_add(inc.vertices.len()) > self.opts.max_vertices {
            return Err(self.err(s.clone(), "object.nff", "too many vertices"));
        }
        let m0 = scene.materials.len();
        let v0 = scene.vertices.len();
        scene.materials.extend(inc.materials);
        scene.lights.extend(inc.lights);
        scene.vertices.extend(inc.vertices);
        scene.normals.extend(inc.normals);
        scene.spheres.extend(inc.spheres.into_iter().map(|mut o| {
            o.material += m0;
            o
        }));
        scene.cones.extend(inc.cones.into_iter().map(|mut o| {
            o.material += m0;
            o
        }));
        scene.polygons.extend(inc.polygons.into_iter().map(|mut o| {
            o.material += m0;
            o.first += v0;
            o
        }));
        Ok(())
    }
}

/// The key whose value starts at byte `at` (`key = value` on that line),
/// or empty: names the key of a wrong-typed value, which toml's message
/// does not.
fn key_before(text: &str, at: usize) -> String {
    let Some(before) = text.get(..at) else {
        return String::new();
    };
    let line = before.rsplit('\n').next().unwrap_or("");
    let Some(lhs) = line.trim_end().strip_suffix('=') else {
        return String::new();
    };
    let lhs = lhs.trim_end();
    let start = lhs
        .rfind(|c: char| !(c.is_ascii_alphanumeric() || c == '_' || c == '-' || c == '.'))
        .map_or(0, |i| i + 1);
    lhs.get(start..).unwrap_or("").to_owned()
}

/// A CSG tree of one solid: a capped cone.
fn single_leaf(shape: Solid, material: usize, loc: SourceLoc) -> Csg {
    Csg {
        nodes: vec![CsgNode::Leaf(0)],
        leaves: vec![CsgLeaf {
            shape,
            material,
            loc: loc.clone(),
        }],
        loc,
    }
}

/// The six faces of a box, wound counter-clockwise seen from outside.
fn box_faces(lo: DVec3, hi: DVec3) -> [[DVec3; 4]; 6] {
    let p = |x: bool, y: bool, z: bool| {
        DVec3::new(
            if x { hi.x } else { lo.x },
            if y { hi.y } else { lo.y },
            if z { hi.z } else { lo.z },
        )
    };
    let (f, t) = (false, true);
    [
        [p(f, f, f), p(f, t, f), p(t, t, f), p(t, f, f)], // z = lo
        [p(f, f, t), p(t, f, t), p(t, t, t), p(f, t, t)], // z = hi
        [p(f, f, f), p(t, f, f), p(t, f, t), p(f, f, t)], // y = lo
        [p(f, t, f), p(f, t, t), p(t, t, t), p(t, t, f)], // y = hi
        [p(f, f, f), p(f, f, t), p(f, t, t), p(f, t, f)], // x = lo
        [p(t, f, f), p(t, t, f), p(t, t, t), p(t, f, t)], // x = hi
    ]
}

fn bernstein(t: f64) -> ([f64; 4], [f64; 4]) {
    let s = 1.0 - t;
    (
        [s * s * s, 3.0 * t * s * s, 3.0 * t * t * s, t * t * t],
        [
            -3.0 * s * s,
            3.0 * s * s - 6.0 * t * s,
            6.0 * t * s - 3.0 * t * t,
            3.0 * t * t,
        ],
    )
}

/// The point and unit normal (`∂u × ∂v`, zero where degenerate) of a
/// bicubic patch at `(u, v)`.
#[must_use]
pub fn patch_point(c: &bpt::Control, u: f64, v: f64) -> (DVec3, DVec3) {
    let (bu, du) = bernstein(u);
    let (bv, dv) = bernstein(v);
    let mut p = DVec3::ZERO;
    let mut pu = DVec3::ZERO;
    let mut pv = DVec3::ZERO;
    for i in 0..4 {
        for j in 0..4 {
            let q = c[i][j];
            p += q * bu[i] * bv[j];
            pu += q * du[i] * bv[j];
            pv += q * bu[i] * dv[j];
        }
    }
    (p, pu.cross(pv).normalize_or_zero())
}

/// A patch as `steps × steps` quads with the patch's normals at their
/// corners; a corner with a degenerate normal (a pole) takes its quad's
/// average of the others, and quads without any usable normal are flat
/// (all-zero normals are replaced by the quad's plane normal).
fn tessellate_patch(c: &bpt::Control, steps: u32) -> Vec<([DVec3; 4], [DVec3; 4])> {
    let n = steps as usize;
    let grid: Vec<(DVec3, DVec3)> = (0..=n)
        .flat_map(|i| {
            (0..=n).map(move |j| patch_point(c, i as f64 / n as f64, j as f64 / n as f64))
        })
        .collect();
    let at = |i: usize, j: usize| grid[i * (n + 1) + j];
    let mut out = Vec::with_capacity(n * n);
    for i in 0..n {
        for j in 0..n {
            let k = [at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)];
            let quad = k.map(|x| x.0);
            let mut normals = k.map(|x| x.1);
            let sum: DVec3 = normals.iter().copied().sum();
            let fill = sum.try_normalize().unwrap_or_else(|| {
                (quad[2] - quad[0])
                    .cross(quad[3] - quad[1])
                    .try_normalize()
                    .unwrap_or(DVec3::Z)
            });
            for m in &mut normals {
                if m.length_squared() < 0.5 {
                    *m = fill;
                }
            }
            out.push((quad, normals));
        }
    }
    out
}
