//! Output: the rendered image as PNG ([`png`]) and the voxelized scene as
//! a saved raster ([`rasterfile`]), which `rrt render` and `rrt info` read
//! back to skip voxelization. Both are written to a temporary file beside
//! the output and renamed over it, so a failed run leaves nothing
//! truncated under the output's name.

pub mod png;
pub mod rasterfile;
