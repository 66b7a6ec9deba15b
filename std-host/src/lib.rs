//! # rrt-host: discrete ray tracing on a host
//!
//! Everything around the integer core `rrt-core`, with std and `f64`:
//!
//! * [`scene`]: NFF and TOML scenes in world coordinates and their strict
//!   parsers, with located errors.
//! * [`camera`]: the pinhole camera of `embree_nff` (rays through pixel
//!   centres), with supersampling positions.
//! * [`fit`]: fitting the 3D raster to a scene: world → fixed-point raster
//!   coordinates, once; the memory estimate and limit.
//! * [`shade`]: shading maths (SPD intensities, Phong, Whitted secondary
//!   rays, refraction), matching `embree_nff`.
//! * [`shape`]: the shape model: each primitive's validation, fixed-point
//!   geometry, voxelizer call and exact intersection for verification.
//! * [`object_table`]: the world object table (each object's exact
//!   geometry) and lights, indexed by the voxel records.
//! * [`build`]: the preprocessing pipeline, scene → fitted raster →
//!   count and fill passes → proximity flags → light visibility, giving a
//!   [`build::VoxelScene`]; [`plane`]: the plane's huge-page memory.
//! * [`trace`]: the recursive discrete ray tracer, intersection
//!   verification, the acne rule for secondary rays.
//! * [`render`]: tiles on rayon, 4×2 primary blocks (ray packets),
//!   supersampling, deterministic for any thread count; [`output`]: PNG.
//! * [`rasterfile`]: saved rasters (versioned, checksummed).
//! * `check` (feature `check`): invariant checkers shared by tests and
//!   fuzz targets.
//! * [`cli`]: the `rrt` command line (the binary only parses arguments).
//! * [`volume`]: sampled (NRRD, raw) and computed volumes, resampling,
//!   placement in the world and classification.
//! * [`texture`]: image maps and solid textures, precomputed per voxel.
//! * [`vox`]: MagicaVoxel `.vox` models.
//! * [`voxel_objects`]: volumes, `.vox` models and CSG trees in the build
//!   pipeline.

#![forbid(unsafe_code)]

#[cfg(any(test, feature = "check"))]
pub mod check;
pub mod cli;
pub mod fit;
pub mod frame;
pub mod output;
pub mod render;
pub mod scene;
pub mod shape;
pub mod texture;
pub mod trace;
pub mod volume;
pub mod vox;
pub mod voxelize;
pub mod world;
