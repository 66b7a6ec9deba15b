//! Voxelization: scan-converting objects into the 3D raster.
//!
//! A *voxelizer* turns one continuous object, given in fixed-point raster
//! coordinates ([`crate::fixed`]), into the set of voxels that best
//! approximates it, and hands each voxel to a [`VoxelSink`]. Voxelizers do
//! not know about planes, records or object ids; the sink (the scene
//! builder, a counter, a test harness) decides what to do with each voxel.
//!
//! # The tunnel-free contract
//! A surface voxelizer takes a [`Separation`]:
//! * [`Separation::Six`]: the voxelized surface is **6-tunnel-free**: no
//!   6-connected discrete ray passes from one side to the other without
//!   visiting one of its voxels;
//! * [`Separation::TwentySix`]: it is **26-tunnel-free**: not even a
//!   26-connected discrete ray passes through.
//!
//! **The rule: a voxel belongs to a surface when its *probe* meets the
//! surface.** For TwentySix the probe is the voxel's closed cube; for Six it
//! is the octahedron inscribed in the voxel (the sphere's Six voxelizer uses
//! the three segments through the centre, a subset). Why it is tunnel-free:
//! wherever the chain of a discrete ray's voxel centres crosses the surface,
//! it crosses within half a step of some centre, and that voxel's probe
//! meets the surface there. The argument holds for any union of objects,
//! so meshes are tunnel-free across shared edges and vertices.
//!
//! For a plane with unit normal `n` the rule is exactly the classic one: the
//! centre lies within `½·max(|nx|,|ny|,|nz|)` voxels of the plane for Six (a
//! *naive* digital plane) and within `½·(|nx|+|ny|+|nz|)` for TwentySix (a
//! *standard* one). Applied with the normal at the nearest point to a
//! *curved* surface, that distance rule can leave tunnels on small spheres
//! (up to about 0.17 voxel for Six and 0.35 for TwentySix at radius ½ voxel,
//! shrinking as 1/R²), which the probe rule does not. Ties (a face exactly
//! on voxel faces or centres) are decided as if the object were shifted by
//! an infinitesimal amount, so such faces get one layer, not two.
//! `tests/voxelize_thickness.rs` checks every voxelizer's thickness (voxels
//! per unit area) against the minimum the separation needs: between 0.9×
//! and 1.5× of it for every case of at least moderate size. Attributes (normal, colour) are sampled
//! at the voxel centre, as the paper does.
//!
//! # Cost
//! Every voxelizer does work linear in the number of voxels it generates
//! (plus a term linear in the object's extent along one axis), never in the
//! raster volume or the object's bounding-box volume.
//!
//! # Layers and rows
//! A sink may keep only some layers of the raster ([`VoxelSink::layers`]:
//! a builder working on one z-slab of it), and of those only some rows
//! ([`VoxelSink::rows`]: a band of a slab). Every voxelizer then offers the
//! voxels of those rows and layers exactly as it would without the hint,
//! in the same order, and the spheres, triangles, meshes, tessellated
//! surfaces (cones, tori, patches), boxes, volumes and CSG trees
//! ([`crate::csg::voxelize`]) skip the work for the other rows and layers,
//! so that cutting a raster into slabs and bands costs about what the
//! whole raster does. Other voxelizers may still offer voxels outside
//! them, which the sink drops.

use core::ops::Range;

use crate::connectivity::Connectivity;

/// Scale of the fixed-point unit normals in [`Surfel`]: a unit vector has
/// components in `[-NORMAL_ONE, NORMAL_ONE]` and Euclidean length
/// `NORMAL_ONE` (up to rounding).
pub const NORMAL_ONE: i32 = 1 << 30;

/// Which discrete rays a voxelized surface must stop.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub enum Separation {
    /// 6-tunnel-free: thick enough for 6-connected (and adaptive) rays.
    Six,
    /// 26-tunnel-free: thick enough for 26-connected rays too.
    #[default]
    TwentySix,
}

impl Separation {
    /// The separation a discrete ray of `mode` needs to never pass through a
    /// surface: 26 for [`Connectivity::TwentySix`], 6 otherwise (adaptive
    /// rays take 6-steps next to surfaces).
    #[must_use]
    pub const fn for_rays(mode: Connectivity) -> Self {
        match mode {
            Connectivity::TwentySix => Self::TwentySix,
            Connectivity::Six | Connectivity::Adaptive => Self::Six,
        }
    }
}

/// Surface attributes of one generated voxel, sampled at its centre.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Surfel {
    /// Unit normal of the surface at the point nearest the voxel centre,
    /// scaled by [`NORMAL_ONE`]. For open surfaces it points to the side the
    /// object's definition calls front (e.g. the polygon's winding); for
    /// closed surfaces and solids it points outward.
    pub normal: [i32; 3],
    /// Unsigned distance from the voxel centre to the surface, in fixed
    /// units (1 voxel = [`crate::fixed::VOXEL`]); 0 for interior voxels of a
    /// solid. Sinks use it to let the nearest surface own a voxel that two
    /// objects claim.
    pub distance: u32,
}

impl Surfel {
    /// The surfel offered to a sink that does not read surfels
    /// ([`VoxelSink::reads_surfels`]).
    pub const NONE: Self = Self {
        normal: [0, 0, NORMAL_ONE],
        distance: 0,
    };
}

/// Receives the voxels a voxelizer generates.
pub trait VoxelSink {
    /// Voxel `voxel` (inside the raster) belongs to the object being
    /// voxelized, with attributes `surfel`. A voxelizer may offer the same
    /// voxel more than once; the sink keeps the offer with the smallest
    /// distance.
    fn offer(&mut self, voxel: [u32; 3], surfel: Surfel);

    /// The layers (z coordinates) whose voxels the sink keeps; every layer
    /// unless the sink says otherwise. A hint that lets a voxelizer skip
    /// the work for the other layers (see *Layers and rows* in the
    /// [module docs](self)): the offers inside them are the same, in the
    /// same order, as without it, and offers outside them may still come.
    fn layers(&self) -> Range<u32> {
        0..u32::MAX
    }

    /// The rows (y coordinates) whose voxels the sink keeps; every row
    /// unless the sink says otherwise. A hint, as [`VoxelSink::layers`]:
    /// the offers inside them are the same, in the same order, as without
    /// it, and offers outside them may still come.
    fn rows(&self) -> Range<u32> {
        0..u32::MAX
    }

    /// Whether the sink reads the surfels it is offered. Voxelizers offer
    /// [`Surfel::NONE`] instead of computing surfels for a sink that does
    /// not (the builder's count pass counts voxels only); the voxels
    /// offered are the same.
    fn reads_surfels(&self) -> bool {
        true
    }
}

pub mod cone;
pub mod cuboid;
pub mod error;
mod fixmath;
pub(crate) use fixmath::{isqrt_u64, isqrt_u128, window_of};
pub mod line;
pub mod patch;
pub mod sphere;
mod tessellate;
pub mod torus;
pub mod triangle;
pub mod volume;

#[cfg(test)]
mod tests;
