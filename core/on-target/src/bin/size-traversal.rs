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

static mut PLANE: [u8; 16384] = [0; 16384];

fn mode(b: u8) -> Connectivity {
    match b % 3 {
        0 => Connectivity::Six,
        1 => Connectivity::TwentySix,
        _ => Connectivity::Adaptive,
    }
}

fn drive() {
    let Ok(extent) = Extent::new(u32_at(0), u32_at(4), u32_at(8)) else {
        return sink(1);
    };
    // SAFETY: the only reference to PLANE while `drive` runs.
    let plane: &mut [u8] = unsafe { &mut *addr_of_mut!(PLANE) };
    let len = (u32_at(12) as usize).min(plane.len());
    if let Ok(mut r) = RasterMut::new(extent, &mut plane[..len]) {
        flag_neighbourhood(&mut r);
    }
    let Ok(raster) = Raster::new(extent, &plane[..len]) else {
        return sink(2);
    };
    let m = mode(input::<1>(16)[0]);
    let ray = match input::<1>(17)[0] & 1 {
        0 => DiscreteRay::new(extent, point_at(20), [i32_at(44), i32_at(48), i32_at(52)]),
        _ => DiscreteRay::segment(extent, point_at(20), point_at(56)),
    };
    let Ok(Some(mut ray)) = ray else {
        return sink(3);
    };
    while let Ok(Some(h)) = ray.first_hit(&raster, m) {
        sink(h.index as u64 ^ u64::from(h.steps));
    }
    let mut again = ray;
    if let Ok(WalkEnd::Hit) = again.walk(&raster, m, u32_at(80), |i, c| (i as u8 ^ c) & 3 == 0) {
        sink(again.hit().index as u64);
    }
    if let Ok(vs) = ray.voxels(&raster, m) {
        for v in vs {
            sink(v.index as u64);
        }
    }
}
