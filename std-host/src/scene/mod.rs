//! World-space scenes, as read from NFF or TOML scene files.
//!
//! A [`Scene`] is the description the pipeline ([`crate::fit`],
//! [`crate::voxelize`])
//! takes, in `f64` world coordinates: the view, the background, lights,
//! materials (with optional textures) and objects, each object referring
//! to its material by index. Two front-ends make one:
//!
//! * [`nff`]: an NFF file (Eric Haines' Neutral File Format, the format of
//!   the Standard Procedural Databases): spheres, open cones and
//!   cylinders, polygons and polygonal patches;
//! * [`toml`]: a TOML scene file, for what NFF cannot say: everything NFF
//!   has plus tori, boxes (as polygons), capped cones (as one-solid CSG
//!   trees), Bézier patches (`.bpt` files, tessellated into `pp`
//!   patches), OBJ meshes, included NFF files, sampled and computed
//!   volumes, MagicaVoxel models, CSG trees and textured materials.
//!
//! Nothing here knows about the raster: [`crate::fit`] maps a scene into
//! raster coordinates, once.
//!
//! Read a scene with [`Scene::load`] (a file, NFF or TOML by its
//! extension) or [`Scene::parse`] (NFF bytes).

pub mod bezier;
pub mod bpt;
#[cfg(any(test, feature = "check"))]
mod check;
pub(crate) mod error;
pub(crate) mod loc;
pub mod nff;
pub mod obj;
pub mod objects;
pub mod path;
pub mod polygon;
pub(crate) mod text;
pub mod toml;

use std::collections::BTreeMap;
use std::sync::Arc;

use glam::DVec3;

use crate::shape::{Cone, Primitive, Sphere, Torus, Triangle};
use crate::world::Bounds;

#[cfg(any(test, feature = "check"))]
pub use check::check_scene;
pub use error::{Found, SceneError};
pub use loc::SourceLoc;
pub use nff::ParseOptions;
pub use objects::{
    Csg, CsgLeaf, SceneTexture, SceneVolume, Solid, TextureKind, VolumeObject, VoxObject,
};

/// The NFF viewpoint (`v` block). The parser guarantees `from ≠ at`, `up`
/// not parallel to `at − from`, `0 < angle < 180` and a resolution of at
/// least 1 × 1.
#[derive(Clone, Debug, PartialEq)]
pub struct View {
    /// Eye position.
    pub from: DVec3,
    /// A point the eye looks at (it appears at the image centre).
    pub at: DVec3,
    /// Up direction (need not be perpendicular to the view direction).
    pub up: DVec3,
    /// Angle in degrees between the centres of the first and the last
    /// pixel rows (and columns, for a square image).
    pub angle: f64,
    /// Distance of the hither (near) plane from the eye. Parsed and kept;
    /// like `embree_nff`, the renderer does not clip with it.
    pub hither: f64,
    /// Image size in pixels, `[width, height]`.
    pub resolution: [u32; 2],
    /// Where the `v` is.
    pub loc: SourceLoc,
}

/// What makes `from`, `at` and `up` no view (the parsers' check, which
/// every view [`crate::render::camera::Camera`] accepts passes).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum ViewDefect {
    /// `at` equals `from`.
    NoDirection,
    /// `up` is zero or parallel to `at − from`.
    NoUp,
}

impl ViewDefect {
    /// The defect of `from`, `at`, `up`, if any.
    pub(crate) fn of(from: DVec3, at: DVec3, up: DVec3) -> Option<Self> {
        // The camera's own normalization (`world::unit`), so that every
        // view accepted here makes a camera.
        let Some(forward) = crate::world::unit(at - from) else {
            return Some(Self::NoDirection);
        };
        let up = crate::world::unit(up).unwrap_or(DVec3::ZERO);
        (forward.cross(up).length_squared() < 1e-24).then_some(Self::NoUp)
    }

    /// What is wrong, for a message about `at` or `up`.
    pub(crate) fn problem(self) -> &'static str {
        match self {
            Self::NoDirection => "equals `from`: the view has no direction",
            Self::NoUp => "zero or parallel to the view direction (at − from): the image has no up",
        }
    }
}

impl View {
    /// Frame `k` of an orbit of `n` frames: the eye at [`View::from`]
    /// rotated by 360°·k/n about the axis through [`View::at`] along
    /// [`View::up`] (right-handed about `up`); `at`, `up`, `angle`,
    /// `hither` and the resolution unchanged. Frame 0 (and every multiple
    /// of `n`) is this view itself, bit for bit; `n = 0` is taken as 1.
    /// The result keeps the parser's guarantees: the eye keeps its distance
    /// from `at` and its angle to `up`.
    ///
    /// ```
    /// use glam::DVec3;
    /// use rrt_host::scene::View;
    /// let view = View {
    ///     from: DVec3::new(1.0, 0.0, 0.0),
    ///     at: DVec3::ZERO,
    ///     up: DVec3::Z,
    ///     angle: 45.0,
    ///     hither: 0.0,
    ///     resolution: [64, 64],
    ///     loc: rrt_host::scene::SourceLoc::new("doc", 1, 1),
    /// };
    /// assert_eq!(view.orbit(0, 4), view);
    /// assert!(view.orbit(1, 4).from.distance(DVec3::Y) < 1e-12);
    /// assert_eq!(view.orbit(4, 4), view);
    /// ```
    #[must_use]
    pub fn orbit(&self, k: u64, n: u64) -> View {
        let n = n.max(1);
        let k = k % n;
        if k == 0 {
            return self.clone();
        }
        let axis = self.up.normalize();
        let theta = std::f64::consts::TAU * (k as f64) / (n as f64);
        let (sin, cos) = theta.sin_cos();
        let v = self.from - self.at;
        let rotated = v * cos + axis.cross(v) * sin + axis * axis.dot(v) * (1.0 - cos);
        View {
            from: self.at + rotated,
            ..self.clone()
        }
    }
}

/// A positional light (`l`).
#[derive(Clone, Debug, PartialEq)]
pub struct Light {
    /// Position (may lie anywhere, also outside the objects' bounds).
    pub position: DVec3,
    /// Colour, if the file gives one.
    pub colour: Option<DVec3>,
    /// Where the `l` is.
    pub loc: SourceLoc,
}

impl Light {
    /// The light's colour: as given, or white.
    #[must_use]
    pub fn rgb(&self) -> DVec3 {
        self.colour.unwrap_or(DVec3::ONE)
    }
}

/// The SPD light intensity for `n_lights` lights: `sqrt(nl) / (2·nl)`,
/// with `nl` at least 1. The ambient intensity is the same.
///
/// ```
/// use rrt_host::scene::light_intensity;
/// assert_eq!(light_intensity(1), 0.5);
/// assert_eq!(light_intensity(4), 0.25);
/// ```
#[must_use]
pub fn light_intensity(n_lights: usize) -> f64 {
    let nl = n_lights.max(1) as f64;
    nl.sqrt() / (2.0 * nl)
}

/// Fill colour and shading parameters (`f r g b Kd Ks Shine T
/// index_of_refraction`).
#[derive(Clone, Debug, PartialEq)]
pub struct Material {
    /// Colour, each channel in `[0, 1]`.
    pub colour: DVec3,
    /// Diffuse weight (≥ 0).
    pub kd: f64,
    /// Specular weight (≥ 0): the Phong highlight and the mirror reflection.
    pub ks: f64,
    /// Phong exponent (≥ 0).
    pub shine: f64,
    /// Transmittance in `[0, 1]`: the weight of the refracted ray.
    pub transmittance: f64,
    /// Index of refraction (≥ 0; > 0 when `transmittance > 0`).
    pub ior: f64,
    /// Where the `f` is; `None` for [`Material::DEFAULT`].
    pub loc: Option<SourceLoc>,
}

impl Material {
    /// The material of objects in a file without any `f` (as
    /// `peers/common/nff.h`): grey 0.8, `Kd` 1, nothing else.
    pub const DEFAULT: Self = Self {
        colour: DVec3::splat(0.8),
        kd: 1.0,
        ks: 0.0,
        shine: 1.0,
        transmittance: 0.0,
        ior: 1.0,
        loc: None,
    };
}

/// An object of the scene: a primitive of the shape model
/// ([`crate::shape`]), its material and where it is defined.
#[derive(Clone, Debug, PartialEq)]
pub struct Object<S> {
    /// The primitive, in world coordinates.
    pub shape: S,
    /// Index into [`Scene::materials`].
    pub material: usize,
    /// Where the object is defined.
    pub loc: SourceLoc,
}

/// A polygon (`p`) or polygonal patch (`pp`): its vertices are
/// `Scene::vertices[first..first + count]`, with per-vertex normals at the
/// same indices of `Scene::normals` for a patch.
#[derive(Clone, Debug, PartialEq)]
pub struct Polygon {
    /// Index of the first vertex in [`Scene::vertices`].
    pub first: usize,
    /// Number of vertices (≥ 3).
    pub count: usize,
    /// A `pp` patch, with per-vertex normals.
    pub patch: bool,
    /// Index into [`Scene::materials`].
    pub material: usize,
    /// How it is cut into triangles ([`polygon`]): `None` for the fan from
    /// its first vertex, which covers it exactly once; else its triangles,
    /// as indices of its vertices.
    pub cut: Option<Box<[[u32; 3]]>>,
    /// Where the `p` or `pp` is.
    pub loc: SourceLoc,
}

impl Polygon {
    /// What the polygon is called in messages: `polygonal patch` for a
    /// patch with vertex normals (NFF `pp`, a tessellated Bézier patch,
    /// a smooth mesh's face), `polygon` otherwise.
    #[must_use]
    pub const fn kind(&self) -> &'static str {
        if self.patch {
            "polygonal patch"
        } else {
            "polygon"
        }
    }

    /// The vertex index range.
    #[must_use]
    pub fn range(&self) -> std::ops::Range<usize> {
        self.first..self.first.saturating_add(self.count)
    }

    /// The number of its triangles ([`Scene::polygon_triangles`]).
    #[must_use]
    pub fn triangle_count(&self) -> usize {
        self.cut
            .as_ref()
            .map_or(self.count.saturating_sub(2), |c| c.len())
    }
}

/// A scene in world coordinates (see the module docs).
///
/// The parsers guarantee: every number is finite; every object's
/// `material` indexes [`Scene::materials`] (which is never empty); every
/// polygon's range lies inside [`Scene::vertices`]; [`Scene::normals`] is
/// as long as [`Scene::vertices`] (zero for plain polygons, non-zero for
/// patches); every texture index of [`Scene::material_textures`] indexes
/// [`Scene::textures`]; CSG trees are valid core trees
/// ([`rrt_core::csg::CsgTree`]: children before parents, at most
/// [`rrt_core::csg::MAX_NODES`] nodes, every leaf present); there is at
/// least one object. `check_scene` (feature `check`) checks all of it.
/// Geometry, lights and the eye beyond
/// [`WORLD_LIMIT`](crate::world::WORLD_LIMIT) are refused by the NFF and
/// TOML readers where they read the number, and otherwise (meshes,
/// transforms, scenes built in code) by [`crate::fit`] and the camera.
#[derive(Clone, Debug, PartialEq)]
pub struct Scene {
    /// The file name the scene was read from, as given.
    pub file: Arc<str>,
    /// The viewpoint.
    pub view: View,
    /// Background colour (`b`; black if the file has none).
    pub background: DVec3,
    /// Lights, in file order.
    pub lights: Vec<Light>,
    /// Materials, in file order; [`Material::DEFAULT`] alone if the file
    /// has no `f`.
    pub materials: Vec<Material>,
    /// Spheres (NFF `s`).
    pub spheres: Vec<Object<Sphere>>,
    /// Open cones and cylinders (NFF `c`).
    pub cones: Vec<Object<Cone>>,
    /// Polygons and patches.
    pub polygons: Vec<Polygon>,
    /// Tori.
    pub tori: Vec<Object<Torus>>,
    /// All polygon vertices.
    pub vertices: Vec<DVec3>,
    /// Per-vertex normals as written (not normalised), parallel to
    /// [`Scene::vertices`]; zero for vertices of plain polygons.
    pub normals: Vec<DVec3>,
    /// Sampled and computed volumes.
    pub volumes: Vec<VolumeObject>,
    /// MagicaVoxel models.
    pub voxes: Vec<VoxObject>,
    /// CSG trees.
    pub csgs: Vec<Csg>,
    /// Textures, referred to by [`Scene::material_textures`].
    pub textures: Vec<SceneTexture>,
    /// The texture of each textured material: material index → index into
    /// [`Scene::textures`]. The texture's colour replaces (or modulates)
    /// the material's colour in each voxel record, computed once per voxel
    /// at voxelization.
    pub material_textures: BTreeMap<usize, usize>,
}

impl Scene {
    /// A scene with a view and nothing else (no material, no object):
    /// what the front-ends start from.
    #[must_use]
    pub fn empty(file: Arc<str>, view: View) -> Self {
        Self {
            file,
            view,
            background: DVec3::ZERO,
            lights: Vec::new(),
            materials: Vec::new(),
            spheres: Vec::new(),
            cones: Vec::new(),
            polygons: Vec::new(),
            tori: Vec::new(),
            vertices: Vec::new(),
            normals: Vec::new(),
            volumes: Vec::new(),
            voxes: Vec::new(),
            csgs: Vec::new(),
            textures: Vec::new(),
            material_textures: BTreeMap::new(),
        }
    }

    /// Reads and parses the scene file at `path` with default limits: a
    /// TOML scene ([`toml`]) when its name ends in `.toml`, NFF ([`nff`])
    /// otherwise, except the files a TOML scene refers to (`.obj`, `.bpt`,
    /// `.vox`, `.nrrd`, `.nhdr`, `.raw`), which are not scenes: they are
    /// refused with the TOML that draws them
    /// ([`SceneError::NotAScene`]), not parsed as NFF.
    ///
    /// # Errors
    /// [`SceneError`] naming the file (and line, column and field or key
    /// where there is one): a missing or unreadable file, a directory, an
    /// empty file, binary data, a mesh, model or volume file, and every
    /// syntax or range error of the format (and of the files a TOML scene
    /// refers to).
    pub fn load(path: impl AsRef<std::path::Path>) -> Result<Self, SceneError> {
        Self::load_with(path, &indicatif::ProgressBar::hidden())
    }

    /// [`Scene::load`], counting an NFF file's bytes parsed on `progress`
    /// (a TOML scene is parsed in one step: nothing is counted).
    ///
    /// # Errors
    /// As [`Scene::load`].
    pub fn load_with(
        path: impl AsRef<std::path::Path>,
        progress: &indicatif::ProgressBar,
    ) -> Result<Self, SceneError> {
        Self::load_within(path, progress, crate::memory::default_max_memory())
    }

    /// [`Scene::load_with`], refusing a TOML scene whose own data (its
    /// volumes' samples and its vertices, [`toml::Options::max_memory`])
    /// would take more than `max_memory` bytes, before they are read or
    /// made.
    ///
    /// # Errors
    /// As [`Scene::load`].
    pub fn load_within(
        path: impl AsRef<std::path::Path>,
        progress: &indicatif::ProgressBar,
        max_memory: u64,
    ) -> Result<Self, SceneError> {
        let path = path.as_ref();
        let name = path
            .file_name()
            .map_or_else(String::new, |n| n.to_string_lossy().into_owned());
        if let Some((what, how)) = not_a_scene(path, &name) {
            return Err(SceneError::NotAScene {
                file: Arc::from(path.display().to_string()),
                what,
                how,
            });
        }
        if path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("toml"))
        {
            toml::load(
                path,
                &toml::Options {
                    max_memory,
                    ..toml::Options::default()
                },
            )
        } else {
            nff::load_with(path, &ParseOptions::default(), progress)
        }
    }

    /// Parses NFF text held in memory; `file` names it in messages.
    ///
    /// # Errors
    /// As [`Scene::load`], less the file-system errors.
    pub fn parse(file: &str, bytes: &[u8]) -> Result<Self, SceneError> {
        nff::parse_bytes(file, bytes, &ParseOptions::default())
    }

    /// Bytes the scene's own data takes: the samples of its volumes (each
    /// counted once, however many objects and CSG leaves share it) and
    /// [`toml::VERTEX_BYTES`] per polygon vertex.
    #[must_use]
    pub fn data_bytes(&self) -> u64 {
        let mut seen = std::collections::HashSet::new();
        let leaves = self
            .csgs
            .iter()
            .flat_map(|c| &c.leaves)
            .filter_map(|l| match &l.shape {
                Solid::Volume(v) => Some(v),
                _ => None,
            });
        let mut bytes = (self.vertices.len() as u64).saturating_mul(toml::VERTEX_BYTES);
        for v in self.volumes.iter().map(|o| &o.data).chain(leaves) {
            if seen.insert(Arc::as_ptr(&v.volume)) {
                let n = v.volume.samples().len() as u64;
                bytes = bytes.saturating_add(n.saturating_mul(v.volume.sample_type().size()));
            }
        }
        bytes
    }

    /// The vertices of `polygon` (empty if its range is out of bounds,
    /// which the parser never produces).
    #[must_use]
    pub fn polygon_vertices(&self, polygon: &Polygon) -> &[DVec3] {
        self.vertices.get(polygon.range()).unwrap_or(&[])
    }

    /// The per-vertex normals of a patch, as written; `None` for a plain
    /// polygon.
    #[must_use]
    pub fn polygon_normals(&self, polygon: &Polygon) -> Option<&[DVec3]> {
        if polygon.patch {
            self.normals.get(polygon.range())
        } else {
            None
        }
    }

    /// The box around the vertices of `polygon`.
    #[must_use]
    pub fn polygon_bounds(&self, polygon: &Polygon) -> Bounds {
        Bounds::around(self.polygon_vertices(polygon).iter().copied())
    }

    /// The triangles of `polygon` ([`polygon`]): the fan from
    /// vertex 0 where it covers the polygon exactly once (every convex
    /// polygon), else the polygon cut into ears; each triangle winds like
    /// the polygon (its normal on the side of the polygon's Newell normal),
    /// which decides whether a refracted ray enters or leaves, with the
    /// patch's vertex normals (as written) for a `pp`.
    pub fn polygon_triangles<'a>(
        &'a self,
        polygon: &'a Polygon,
    ) -> impl Iterator<Item = Triangle> + 'a {
        let v = self.polygon_vertices(polygon);
        let n = self.polygon_normals(polygon);
        polygon::triangles(v, polygon.cut.as_deref()).filter_map(move |[a, b, c]| {
            Some(Triangle {
                vertices: [*v.get(a)?, *v.get(b)?, *v.get(c)?],
                normals: n.and_then(|n| Some([*n.get(a)?, *n.get(b)?, *n.get(c)?])),
            })
        })
    }

    /// Number of `pp` patches.
    #[must_use]
    pub fn patch_count(&self) -> usize {
        self.polygons.iter().filter(|p| p.patch).count()
    }

    /// The texture of material `material`, if it has one.
    #[must_use]
    pub fn texture_of(&self, material: usize) -> Option<&SceneTexture> {
        self.textures.get(*self.material_textures.get(&material)?)
    }

    /// Whether the scene has no object at all.
    #[must_use]
    pub fn has_no_objects(&self) -> bool {
        self.spheres.is_empty()
            && self.cones.is_empty()
            && self.polygons.is_empty()
            && self.tori.is_empty()
            && self.volumes.is_empty()
            && self.voxes.is_empty()
            && self.csgs.is_empty()
    }

    /// Number of triangles of every polygon ([`Polygon::triangle_count`]).
    #[must_use]
    pub fn triangle_count(&self) -> usize {
        self.polygons.iter().map(Polygon::triangle_count).sum()
    }

    /// The box around all geometry: spheres ± radius, polygon vertices,
    /// cone end discs ± their radius (the same box as `embree_nff`'s for
    /// NFF scenes); tori; the cells of volumes and `.vox` models, and CSG trees
    /// ([`Csg::world_bounds`]).
    #[must_use]
    pub fn bounds(&self) -> Bounds {
        let mut b = Bounds::EMPTY;
        for s in &self.spheres {
            b.include_bounds(s.shape.bounds());
        }
        for c in &self.cones {
            b.include_bounds(c.shape.disc_bounds());
        }
        for p in &self.polygons {
            for &v in self.polygon_vertices(p) {
                b.include(v, v);
            }
        }
        for t in &self.tori {
            b.include_bounds(t.shape.bounds());
        }
        for v in &self.volumes {
            b.include_bounds(v.data.world_bounds());
        }
        for w in self.voxes.iter().filter_map(VoxObject::world_bounds) {
            b.include_bounds(w);
        }
        for w in self.csgs.iter().filter_map(Csg::world_bounds) {
            b.include_bounds(w);
        }
        b
    }
}

/// What the file at `path` is, and how a TOML scene draws it (naming it
/// `name`), when its extension names a file a TOML scene refers to rather
/// than a scene.
pub(crate) fn not_a_scene(path: &std::path::Path, name: &str) -> Option<(&'static str, String)> {
    let ext = path.extension()?.to_str()?.to_ascii_lowercase();
    let object = |key: &str| format!("[[object]] {key} = {{ file = {name:?} }}");
    let volume = |data: String| {
        format!("[volume.NAME] {data}, iso or opacity, and [[object]] volume = \"NAME\"")
    };
    Some(match ext.as_str() {
        "obj" => ("an OBJ mesh", object("mesh")),
        "bpt" => ("a Bézier patch file", object("bezier")),
        "vox" => ("a MagicaVoxel model", object("vox")),
        "nrrd" | "nhdr" => ("a NRRD volume", volume(format!("file = {name:?}"))),
        "raw" => (
            "raw volume samples",
            volume(format!("raw = {{ file = {name:?}, dims, type }}")),
        ),
        _ => return None,
    })
}
