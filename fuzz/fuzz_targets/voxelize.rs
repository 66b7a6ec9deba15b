//! Fuzz target `voxelize`: arbitrary bytes become a raster size, a
//! separation and one primitive with arbitrary parameters (huge
//! coordinates, degenerate triangles, zero or negative radii, shapes partly
//! or wholly outside the raster). The primitive is voxelized into a plane and
//! checked:
//!
//! * no panic (any input; refusals are error values);
//! * every offered voxel lies inside the raster and within one voxel of the
//!   object's bounding box (no runaway offers), and shapes that promise one
//!   offer per voxel never offer a voxel twice;
//! * closed shapes (sphere, box, torus, capped cone) lying inside the raster
//!   are tunnel-free along the probe rays of `rrt_core::check_voxelize` fired
//!   from a voxel inside them, in the connectivity matching the separation
//!   (and Adaptive over proximity flags for Six).

#![no_main]

use libfuzzer_sys::fuzz_target;
use rrt_tests::voxelize_case::{Input, run};

fuzz_target!(|input: Input| run(input));
