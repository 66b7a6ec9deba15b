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

#![forbid(unsafe_code)]

pub mod build;
pub mod camera;
#[cfg(any(test, feature = "check"))]
pub mod check;
pub mod cli;
pub mod fit;
pub mod intersect;
pub mod output;
pub mod plane;
pub mod rasterfile;
pub mod render;
pub mod scene;
pub mod shade;
pub mod trace;
pub mod world;
