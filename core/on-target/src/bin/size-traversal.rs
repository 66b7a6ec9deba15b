//! Flash of the traversal API alone: rasters over a static plane, the
//! proximity flags, and discrete rays set up and walked in all three
//! connectivities (first hit, budgeted walk with a caller's test, voxel
//! iteration).
#![no_std]
#![no_main]

use rrt_core::discrete_ray::{Connectivity, DiscreteRay, WalkEnd};
use rrt_core::proximity::flag_neighbourhood;
use rrt_core::raster::{Extent, Raster, RasterMut};

include!("size/common.rs");
include!("size/traversal.rs");

fn drive() {
    let _ = traverse();
}
