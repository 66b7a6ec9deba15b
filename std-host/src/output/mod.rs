//! Output: the rendered image in the format its extension names
//! ([`image`]: [`png`], [`ppm`] for PPM and PFM, [`exr`]) and the
//! voxelized scene as a saved raster ([`rasterfile`]), which `rrt render`
//! and `rrt info` read back to skip voxelization. Every file is written
//! through [`atomic::AtomicFile`]: a temporary file beside the output,
//! synced and renamed over it when complete, removed on an error or an
//! interruption, so the old output survives anything but success.

pub mod atomic;
pub mod band;
pub mod encoding;
pub mod exr;
pub mod image;
pub mod png;
pub mod ppm;
pub mod rasterfile;
pub mod stitch;
