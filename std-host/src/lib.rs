//! # rrt-host: discrete ray tracing on a host
//!
//! Scene loading, voxelization driving, the recursive discrete ray tracer,
//! intersection verification, parallel rendering, image and raster I/O, and
//! the `rrt` command-line tool, on top of the no_std core `rrt-core`.

pub mod cli;
