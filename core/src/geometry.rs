//! Fixed-point geometric primitives in raster coordinates.
//!
//! One definition per primitive, shared by the voxelizers
//! ([`crate::voxelize`]), constructive solid geometry, the object table and
//! the host's intersection verification. Positions and lengths are in fixed
//! units ([`crate::fixed`]: `VOXEL` = 2^16 per voxel); unit vectors are
//! scaled by [`NORMAL_ONE`]. The host converts world coordinates once, when
//! it fits the raster to the scene.

pub use crate::voxelize::NORMAL_ONE;

/// A point or vector in fixed units.
pub type Point = [i64; 3];

/// A unit vector scaled by [`NORMAL_ONE`].
pub type UnitVector = [i32; 3];

/// A sphere (NFF `s`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Sphere {
    /// Centre.
    pub centre: Point,
    /// Radius (> 0).
    pub radius: i64,
}

/// A triangle, optionally with per-vertex normals (NFF `pp` patches and
/// meshes with smooth normals; planar polygons are split into triangles
/// sharing their plane).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Triangle {
    /// Vertices; the front side is the one from which they run
    /// counter-clockwise (normal `(v1 − v0) × (v2 − v0)`).
    pub vertices: [Point; 3],
    /// Per-vertex unit normals, interpolated across the triangle; `None`
    /// for a flat triangle.
    pub normals: Option<[UnitVector; 3]>,
}

/// A truncated cone or cylinder, open at both ends (NFF `c`, as in the SPD:
/// no caps).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Cone {
    /// Centre of the base disc.
    pub base: Point,
    /// Radius at the base (≥ 0).
    pub base_radius: i64,
    /// Centre of the apex disc.
    pub apex: Point,
    /// Radius at the apex (≥ 0; equal to `base_radius` for a cylinder).
    pub apex_radius: i64,
}

/// An axis-aligned box.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Cuboid {
    /// Lowest corner.
    pub min: Point,
    /// Highest corner (each coordinate > `min`'s).
    pub max: Point,
}

/// A torus: the surface swept by a circle of radius `minor` whose centre
/// runs around a circle of radius `major` about `axis` through `centre`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Torus {
    /// Centre.
    pub centre: Point,
    /// Unit axis of symmetry.
    pub axis: UnitVector,
    /// Radius of the centre circle (> `minor` for a ring torus).
    pub major: i64,
    /// Radius of the tube (> 0).
    pub minor: i64,
}

/// A bicubic Bézier patch: 4 × 4 control points, `control[i][j]` for
/// parameters `u = i / 3`, `v = j / 3` at the corners.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct BezierPatch {
    /// Control points.
    pub control: [[Point; 4]; 4],
}

/// A 3D line segment.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Segment {
    /// One end.
    pub a: Point,
    /// The other end.
    pub b: Point,
}
