//! World-space scenes, as read from NFF files.
//!
//! A [`Scene`] is what an NFF file (Eric Haines' Neutral File Format, the
//! format of the Standard Procedural Databases) describes, in `f64` world
//! coordinates: the view, the background, lights, materials and objects
//! (spheres, open cones and cylinders, polygons and polygonal patches), each
//! object referring to its material by index. Nothing here knows about the
//! raster: [`crate::fit`] maps a scene into raster coordinates, once.
//!
//! Read a scene with [`Scene::load`] (a file) or [`Scene::parse`] (bytes);
//! [`nff`] documents the format and the checks.

#![deny(missing_docs)]

mod error;
mod loc;
pub mod nff;

use std::sync::Arc;

use glam::DVec3;

pub use error::{Found, SceneError};
pub use loc::SourceLoc;
pub use nff::ParseOptions;

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

/// A sphere (`s`).
#[derive(Clone, Debug, PartialEq)]
pub struct Sphere {
    /// Centre.
    pub centre: DVec3,
    /// Radius (> 0).
    pub radius: f64,
    /// Index into [`Scene::materials`].
    pub material: usize,
    /// Where the `s` is.
    pub loc: SourceLoc,
}

/// A cone or cylinder (`c`), open at both ends as NFF defines it.
#[derive(Clone, Debug, PartialEq)]
pub struct Cone {
    /// Centre of the base disc.
    pub base: DVec3,
    /// Radius at the base (≥ 0).
    pub base_radius: f64,
    /// Centre of the apex disc (≠ `base`).
    pub apex: DVec3,
    /// Radius at the apex (≥ 0; not both radii 0).
    pub apex_radius: f64,
    /// Index into [`Scene::materials`].
    pub material: usize,
    /// Where the `c` is.
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
    /// Where the `p` or `pp` is.
    pub loc: SourceLoc,
}

impl Polygon {
    /// The vertex index range.
    #[must_use]
    pub fn range(&self) -> std::ops::Range<usize> {
        self.first..self.first.saturating_add(self.count)
    }
}

/// An axis-aligned box in world coordinates.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bounds {
    /// Lowest corner.
    pub min: DVec3,
    /// Highest corner.
    pub max: DVec3,
}

impl Bounds {
    /// The empty box (`min = +∞`, `max = −∞`): [`Bounds::include`] grows it.
    pub const EMPTY: Self = Self {
        min: DVec3::INFINITY,
        max: DVec3::NEG_INFINITY,
    };

    /// Grows the box to hold `lo..hi`.
    pub fn include(&mut self, lo: DVec3, hi: DVec3) {
        self.min = self.min.min(lo);
        self.max = self.max.max(hi);
    }

    /// Whether the box holds at least one point.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        !(self.min.cmple(self.max).all())
    }

    /// `max − min`.
    #[must_use]
    pub fn size(&self) -> DVec3 {
        self.max - self.min
    }
}

/// A scene in world coordinates (see the module docs).
///
/// The parser guarantees: every number is finite; every object's
/// `material` indexes [`Scene::materials`] (which is never empty); every
/// polygon's range lies inside [`Scene::vertices`]; [`Scene::normals`] is
/// as long as [`Scene::vertices`] (zero for plain polygons, non-zero for
/// patches); there is at least one object.
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
    /// Spheres.
    pub spheres: Vec<Sphere>,
    /// Cones and cylinders.
    pub cones: Vec<Cone>,
    /// Polygons and patches.
    pub polygons: Vec<Polygon>,
    /// All polygon vertices.
    pub vertices: Vec<DVec3>,
    /// Per-vertex normals as written (not normalised), parallel to
    /// [`Scene::vertices`]; zero for vertices of plain polygons.
    pub normals: Vec<DVec3>,
}

impl Scene {
    /// Reads and parses the NFF file at `path` with default limits.
    ///
    /// # Errors
    /// [`SceneError`] naming the file (and line, column and field where
    /// there is one): a missing or unreadable file, a directory, an empty
    /// file, binary data, and every syntax or range error of [`nff`].
    pub fn load(path: impl AsRef<std::path::Path>) -> Result<Self, SceneError> {
        nff::load(path.as_ref(), &ParseOptions::default())
    }

    /// Parses NFF text held in memory; `file` names it in messages.
    ///
    /// # Errors
    /// As [`Scene::load`], less the file-system errors.
    pub fn parse(file: &str, bytes: &[u8]) -> Result<Self, SceneError> {
        nff::parse_bytes(file, bytes, &ParseOptions::default())
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

    /// Number of `pp` patches.
    #[must_use]
    pub fn patch_count(&self) -> usize {
        self.polygons.iter().filter(|p| p.patch).count()
    }

    /// Number of triangles after fan-triangulating every polygon.
    #[must_use]
    pub fn triangle_count(&self) -> usize {
        self.polygons
            .iter()
            .map(|p| p.count.saturating_sub(2))
            .sum()
    }

    /// The box around all geometry: spheres ± radius, polygon vertices,
    /// cone end discs ± their radius (the same box as `embree_nff`'s).
    #[must_use]
    pub fn bounds(&self) -> Bounds {
        let mut b = Bounds::EMPTY;
        for s in &self.spheres {
            b.include(s.centre - s.radius, s.centre + s.radius);
        }
        for c in &self.cones {
            b.include(c.base - c.base_radius, c.base + c.base_radius);
            b.include(c.apex - c.apex_radius, c.apex + c.apex_radius);
        }
        for p in &self.polygons {
            for &v in self.polygon_vertices(p) {
                b.include(v, v);
            }
        }
        b
    }
}

/// Checks the guarantees documented on [`Scene`]; for tests and fuzzing.
///
/// # Errors
/// A description of the first broken guarantee.
#[cfg(any(test, feature = "check"))]
pub fn check_scene(s: &Scene) -> Result<(), String> {
    let finite = |v: DVec3, what: &str| {
        if v.is_finite() {
            Ok(())
        } else {
            Err(format!("{what} not finite: {v}"))
        }
    };
    if s.materials.is_empty() {
        return Err("no materials".into());
    }
    if s.vertices.len() != s.normals.len() {
        return Err("normals not parallel to vertices".into());
    }
    if s.spheres.is_empty() && s.cones.is_empty() && s.polygons.is_empty() {
        return Err("no objects".into());
    }
    let v = &s.view;
    finite(v.from, "from")?;
    finite(v.at, "at")?;
    finite(v.up, "up")?;
    if !(v.angle > 0.0 && v.angle < 180.0) || v.resolution.contains(&0) {
        return Err(format!("bad view {v:?}"));
    }
    if (v.at - v.from).cross(v.up).length_squared() == 0.0 {
        return Err("degenerate view".into());
    }
    finite(s.background, "background")?;
    for l in &s.lights {
        finite(l.position, "light")?;
        finite(l.rgb(), "light colour")?;
    }
    for m in &s.materials {
        finite(m.colour, "material colour")?;
        let ok = [m.kd, m.ks, m.shine, m.transmittance, m.ior]
            .iter()
            .all(|x| x.is_finite() && *x >= 0.0);
        if !ok || m.transmittance > 1.0 || (m.transmittance > 0.0 && m.ior <= 0.0) {
            return Err(format!("bad material {m:?}"));
        }
    }
    let nm = s.materials.len();
    for o in &s.spheres {
        finite(o.centre, "sphere")?;
        if o.material >= nm || !(o.radius > 0.0 && o.radius.is_finite()) {
            return Err(format!("bad sphere {o:?}"));
        }
    }
    for c in &s.cones {
        finite(c.base, "cone")?;
        finite(c.apex, "cone")?;
        if c.material >= nm
            || c.base == c.apex
            || !(c.base_radius >= 0.0 && c.apex_radius >= 0.0)
            || c.base_radius + c.apex_radius <= 0.0
        {
            return Err(format!("bad cone {c:?}"));
        }
    }
    for p in &s.polygons {
        if p.material >= nm || p.count < 3 || s.vertices.get(p.range()).is_none() {
            return Err(format!("bad polygon {p:?}"));
        }
        for i in p.range() {
            finite(s.vertices[i], "vertex")?;
            let n = s.normals[i];
            if p.patch && n.try_normalize().is_none() {
                return Err(format!("bad patch normal {n}"));
            }
        }
    }
    Ok(())
}
