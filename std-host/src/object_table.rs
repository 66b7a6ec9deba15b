//! The world side of a voxelized scene: the world object table (each
//! object's exact geometry, for intersection verification) and the lights
//! in `f64` for shading.
//!
//! [`WorldObject`]s are indexed by the voxel records' object id, as the
//! paper's object table is; a saved raster ([`crate::rasterfile`]) stores
//! them as they are.

use glam::DVec3;

use crate::shape::Shape;

/// One entry of the world object table.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WorldObject {
    /// Exact geometry.
    pub shape: Shape,
    /// Index into the scene's material list.
    pub material: u16,
}

/// A point light in world coordinates.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WorldLight {
    /// Position.
    pub position: DVec3,
    /// Colour (white unless the file gives one).
    pub colour: DVec3,
}
