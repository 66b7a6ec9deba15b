//! # rrt-host: discrete ray tracing on a host
//!
//! Everything around the integer core `rrt-core`, with std and `f64`:
//!
//! * [`scene`]: NFF scenes in world coordinates and their strict parser,
//!   with located errors.
//! * [`camera`]: the pinhole camera of `embree_nff` (rays through pixel
//!   centres), with supersampling positions.
//! * [`fit`]: fitting the 3D raster to a scene: world → fixed-point raster
//!   coordinates, once; the memory estimate and limit.
//! * [`shade`]: shading maths (SPD intensities, Phong, Whitted secondary
//!   rays, refraction), matching `embree_nff`.
//! * [`intersect`]: exact `f64` ray intersections for intersection
//!   verification and tests.
//! * `check` (feature `check`): invariant checkers shared by tests and
//!   fuzz targets.
//! * [`cli`]: the `rrt` command line (the binary only parses arguments).
//! * [`volume`]: sampled (NRRD, raw) and computed volumes, resampling,
//!   placement in the world and classification.
//! * [`texture`]: image maps and solid textures, precomputed per voxel.
//! * [`vox`]: MagicaVoxel `.vox` models.

#![forbid(unsafe_code)]

pub mod camera;
#[cfg(any(test, feature = "check"))]
pub mod check;
pub mod cli;
pub mod fit;
pub mod intersect;
pub mod scene;
pub mod shade;
pub mod texture;
pub mod volume;
pub mod vox;
