//! The world side of a voxelized scene: each object's exact geometry in
//! world coordinates (for intersection verification), the materials and
//! lights in `f64` for shading.
//!
//! [`WorldObject`]s are indexed by the voxel records' object id, as the
//! paper's object table is. They are the scene's own NFF geometry, before
//! any fixed-point rounding, so that verification intersects the true
//! surface; a saved raster ([`crate::rasterfile`]) stores them as they are.

#![deny(missing_docs)]

use glam::DVec3;

use crate::fit::{FittedObject, Source};
use crate::frame::{self, RasterFrame};
use crate::intersect;
use crate::scene::Scene;
use crate::world::{Hit, Ray};

/// An object's exact geometry in world coordinates.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum WorldShape {
    /// A sphere (closed).
    Sphere {
        /// Centre.
        centre: DVec3,
        /// Radius (> 0).
        radius: f64,
    },
    /// An open cone or cylinder (NFF `c`).
    Cone {
        /// Centre of the base disc.
        base: DVec3,
        /// Radius at the base.
        base_radius: f64,
        /// Centre of the apex disc.
        apex: DVec3,
        /// Radius at the apex.
        apex_radius: f64,
    },
    /// A triangle of a polygon's fan, with the patch's vertex normals (as
    /// written, not normalised) if it comes from a `pp`.
    Triangle {
        /// Vertices, in the polygon's winding.
        vertices: [DVec3; 3],
        /// Per-vertex normals, interpolated by [`intersect::triangle`].
        normals: Option<[DVec3; 3]>,
    },
    /// No continuous definition: the voxels are the object (volumes,
    /// `.vox` models, CSG results). It has no exact intersection, so
    /// intersection verification keeps the discrete hit with the stored
    /// normal.
    Voxels,
}

impl WorldShape {
    /// The exact intersection of `ray` with the shape in `(tmin, tmax)`, with
    /// the true normal there ([`crate::intersect`] conventions: outward or
    /// along the winding, not turned towards the ray).
    #[must_use]
    pub fn intersect(&self, ray: &Ray, tmin: f64, tmax: f64) -> Option<Hit> {
        match *self {
            Self::Sphere { centre, radius } => intersect::sphere(ray, centre, radius, tmin, tmax),
            Self::Cone {
                base,
                base_radius,
                apex,
                apex_radius,
            } => intersect::cone(ray, base, base_radius, apex, apex_radius, tmin, tmax),
            Self::Triangle { vertices, normals } => {
                intersect::triangle(ray, vertices, normals, tmin, tmax)
            }
            Self::Voxels => None,
        }
    }

    /// Whether the shape bounds a solid (only its outside is ever lit).
    #[must_use]
    pub const fn is_closed(&self) -> bool {
        matches!(self, Self::Sphere { .. } | Self::Voxels)
    }

    /// Whether the shape has exact geometry to verify hits against (all
    /// but [`WorldShape::Voxels`]).
    #[must_use]
    pub const fn is_exact(&self) -> bool {
        !matches!(self, Self::Voxels)
    }

    /// Every coordinate is finite, radii are non-negative and a sphere's is
    /// positive: what a loaded file must satisfy.
    #[must_use]
    pub fn is_valid(&self) -> bool {
        match *self {
            Self::Sphere { centre, radius } => {
                centre.is_finite() && radius > 0.0 && radius.is_finite()
            }
            Self::Cone {
                base,
                base_radius,
                apex,
                apex_radius,
            } => {
                base.is_finite()
                    && apex.is_finite()
                    && base_radius >= 0.0
                    && apex_radius >= 0.0
                    && base_radius.is_finite()
                    && apex_radius.is_finite()
            }
            Self::Triangle { vertices, normals } => {
                vertices.iter().all(|v| v.is_finite())
                    && normals.is_none_or(|n| n.iter().all(|v| v.is_finite()))
            }
            Self::Voxels => true,
        }
    }

    /// The core's fixed-point geometry in `frame` (as [`fit::fit`] makes
    /// it), or `None` when a coordinate lies beyond the fixed-point range
    /// or the shape is [`WorldShape::Voxels`].
    #[must_use]
    pub fn to_fixed(&self, frame: &RasterFrame) -> Option<crate::fit::Shape> {
        Some(match *self {
            Self::Sphere { centre, radius } => {
                crate::fit::Shape::Sphere(rrt_core::geometry::Sphere {
                    centre: frame.to_fixed(centre)?,
                    radius: frame.length_to_fixed(radius, 1)?,
                })
            }
            Self::Cone {
                base,
                base_radius,
                apex,
                apex_radius,
            } => crate::fit::Shape::Cone(rrt_core::geometry::Cone {
                base: frame.to_fixed(base)?,
                base_radius: frame.length_to_fixed(base_radius, 0)?,
                apex: frame.to_fixed(apex)?,
                apex_radius: frame.length_to_fixed(apex_radius, 0)?,
            }),
            Self::Triangle { vertices, normals } => {
                let v = [
                    frame.to_fixed(vertices[0])?,
                    frame.to_fixed(vertices[1])?,
                    frame.to_fixed(vertices[2])?,
                ];
                let n = match normals {
                    Some(n) => Some([
                        frame::unit_to_fixed(n[0])?,
                        frame::unit_to_fixed(n[1])?,
                        frame::unit_to_fixed(n[2])?,
                    ]),
                    None => None,
                };
                crate::fit::Shape::Triangle(rrt_core::geometry::Triangle {
                    vertices: v,
                    normals: n,
                })
            }
            Self::Voxels => return None,
        })
    }
}

/// One entry of the world object table.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WorldObject {
    /// Exact geometry.
    pub shape: WorldShape,
    /// Index into the scene's material list.
    pub material: u16,
}

impl WorldObject {
    /// The world object a fitted object comes from (its [`Source`] in
    /// `scene`), with material index `material`; `None` if the source does
    /// not exist in `scene`.
    #[must_use]
    pub fn from_fitted(scene: &Scene, object: &FittedObject, material: u16) -> Option<Self> {
        let shape = match object.source {
            Source::Sphere(i) => {
                let s = scene.spheres.get(i)?;
                WorldShape::Sphere {
                    centre: s.centre,
                    radius: s.radius,
                }
            }
            Source::Cone(i) => {
                let c = scene.cones.get(i)?;
                WorldShape::Cone {
                    base: c.base,
                    base_radius: c.base_radius,
                    apex: c.apex,
                    apex_radius: c.apex_radius,
                }
            }
            Source::Polygon { polygon, triangle } => {
                let p = scene.polygons.get(polygon)?;
                let v = scene.polygon_vertices(p);
                let idx = [0, triangle.checked_add(1)?, triangle.checked_add(2)?];
                let vertices = [*v.get(idx[0])?, *v.get(idx[1])?, *v.get(idx[2])?];
                let normals = match scene.polygon_normals(p) {
                    Some(n) => Some([*n.get(idx[0])?, *n.get(idx[1])?, *n.get(idx[2])?]),
                    None => None,
                };
                WorldShape::Triangle { vertices, normals }
            }
        };
        Some(Self { shape, material })
    }
}

/// A point light in world coordinates.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WorldLight {
    /// Position.
    pub position: DVec3,
    /// Colour (white unless the file gives one).
    pub colour: DVec3,
}
