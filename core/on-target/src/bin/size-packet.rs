//! Flash of the traversal API with packets: everything `size-traversal`
//! links, plus `RayPacket8` set up from rays and walked to its first hits
//! and with a caller's test.
#![no_std]
#![no_main]

use rrt_core::discrete_ray::{Connectivity, DiscreteRay, WalkEnd};
use rrt_core::packet::RayPacket8;
use rrt_core::proximity::flag_neighbourhood;
use rrt_core::raster::{Extent, Raster, RasterMut};

include!("size/common.rs");
include!("size/traversal.rs");

fn drive() {
    let Some((extent, raster, m, ray, again)) = traverse() else {
        return;
    };
    let other = DiscreteRay::new(
        extent,
        point_at(84),
        [i32_at(108), i32_at(112), i32_at(116)],
    );
    let o = other.ok().flatten();
    let lanes = [Some(ray), o, None, o, Some(again), Some(ray), None, o];
    if let Ok(mut p) = RayPacket8::from_rays(extent, lanes) {
        while let Ok(hits) = p.first_hit(&raster, m) {
            if hits == 0 {
                break;
            }
            sink(u64::from(hits));
        }
        if let Ok(e) = p.walk(&raster, m, u32_at(120), |l, i, c| {
            (l as u8 ^ i as u8 ^ c) & 3 == 0
        }) {
            sink(u64::from(e.hit ^ e.budget));
        }
        for lane in 0..8 {
            if let Some(h) = p.hit(lane) {
                sink(h.index as u64);
            }
        }
    }
}
