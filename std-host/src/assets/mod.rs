//! The data a scene names besides its geometry, loaded and checked: image
//! and solid textures ([`texture`]), sampled and computed volumes
//! ([`volume`]: NRRD, raw, metaballs) and MagicaVoxel models ([`vox`]).
//!
//! Like the scene readers, nothing here knows the raster: their raster
//! side (a texture per voxel, a volume's samples at the voxel centres, a
//! model's cells as voxels) is voxelization's ([`crate::voxelize`]).

pub mod texture;
pub mod volume;
pub mod vox;
