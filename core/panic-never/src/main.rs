//! A bare-metal binary that drives rrt-core's public traversal API with
//! inputs the optimizer cannot see (volatile reads of static memory), linked
//! with a panic handler that calls a symbol defined nowhere.
//!
//! If any panic is reachable from the code below (an index out of bounds,
//! an overflow with overflow checks on, an unwrap, a division by zero), the
//! optimizer must keep the call to the panic handler, the handler references
//! `rrt_core_reachable_panic`, and the link fails with an undefined symbol.
//! A successful link is the proof. See core/panic-never/README.md for what
//! it does and does not cover.
#![no_std]
#![no_main]

use core::panic::PanicInfo;

use rrt_core::discrete_ray::{Connectivity, DiscreteRay, WalkEnd};
use rrt_core::packet::RayPacket8;
use rrt_core::proximity::flag_neighbourhood;
use rrt_core::raster::{Extent, Raster, RasterMut, line_count};

unsafe extern "C" {
    /// Deliberately undefined: referencing it fails the link.
    fn rrt_core_reachable_panic() -> !;
}

#[panic_handler]
fn panic(_: &PanicInfo<'_>) -> ! {
    // SAFETY: never linked; a reference to it is a link error.
    unsafe { rrt_core_reachable_panic() }
}

// The flash-size firmwares' opaque inputs, sink, plane and mode input.
include!("../../on-target/src/bin/size/input.rs");
include!("../../on-target/src/bin/size/plane.rs");

/// A line level for the plane, filled from the inputs.
static mut LINES: [u8; line_count(16384)] = [0; line_count(16384)];

fn drive() {
    let Ok(extent) = Extent::new(u32_at(0), u32_at(4), u32_at(8)) else {
        return sink(1);
    };
    sink(extent.len() as u64);
    sink(u64::from(
        extent.index([u32_at(12), u32_at(16), u32_at(20)]).is_some(),
    ));
    if let Some(c) = extent.coord(u32_at(24) as usize) {
        sink(u64::from(c[0] ^ c[1] ^ c[2]));
    }
    // SAFETY: the only reference to PLANE while `drive` runs.
    let plane: &mut [u8] = unsafe { &mut *addr_of_mut!(PLANE) };
    let len = (u32_at(28) as usize).min(plane.len());
    let plane = &mut plane[..len];
    if let Ok(mut r) = RasterMut::new(extent, plane) {
        flag_neighbourhood(&mut r);
    }
    // SAFETY: as above.
    let plane: &[u8] = unsafe { &*addr_of!(PLANE) };
    let raster = Raster::new(extent, &plane[..len]);
    // SAFETY: the only reference to LINES while `drive` runs.
    let lines: &mut [u8] = unsafe { &mut *addr_of_mut!(LINES) };
    for (k, l) in lines.iter_mut().enumerate() {
        *l = input::<1>(k)[0];
    }
    let lines: &[u8] = lines;
    let lined =
        raster.and_then(|r| r.with_lines(&lines[..(u32_at(108) as usize).min(lines.len())]));
    let origin = point_at(32);
    let dir = [i32_at(56), i32_at(60), i32_at(64)];
    let end = point_at(68);
    let m = mode(input::<1>(92)[0]);
    let budget = u32_at(96);
    let rays = [
        DiscreteRay::new(extent, origin, dir),
        DiscreteRay::segment(extent, origin, end),
    ];
    // The packet: both rays in several lanes, walked every way.
    if let (Ok(a), Ok(b), Ok(raster)) = (rays[0], rays[1], raster) {
        let lanes = [a, b, None, a, b, a, None, b];
        if let Ok(mut p) = RayPacket8::from_rays(extent, lanes) {
            let e = p
                .walk(&raster, m, budget, |l, i, c| {
                    (l as u8 ^ i as u8 ^ c) & 3 == 0
                })
                .unwrap_or_default();
            sink(u64::from(e.hit ^ e.exit ^ e.budget));
            let e = p
                .walk_until(
                    &raster,
                    mode(input::<1>(105)[0]),
                    budget,
                    input::<1>(106)[0],
                )
                .unwrap_or_default();
            sink(u64::from(e.hit ^ e.exit ^ e.budget));
            while let Ok(hits) = p.first_hit(&raster, m) {
                if hits == 0 {
                    break;
                }
                sink(u64::from(hits));
            }
            // Skipping, over the raster with its line level when it has one.
            let skipping = lined.unwrap_or(raster);
            if let Ok(mut q) = RayPacket8::from_rays(extent, lanes) {
                let e = q
                    .walk_skipping(&skipping, m, budget, |l, i, c| {
                        (l as u8 ^ i as u8 ^ c) & 5 == 1
                    })
                    .unwrap_or_default();
                sink(u64::from(e.hit ^ e.exit ^ e.budget));
                let e = q
                    .walk_until_skipping(&skipping, m, budget, input::<1>(106)[0])
                    .unwrap_or_default();
                sink(u64::from(e.hit ^ e.exit ^ e.budget));
                while let Ok(hits) = q.first_hit_skipping(&skipping, m) {
                    if hits == 0 {
                        break;
                    }
                    sink(u64::from(hits));
                }
            }
            for lane in 0..8 {
                if let (Some(h), Some(r)) = (p.hit(lane), p.lane_ray(lane)) {
                    sink(h.index as u64 ^ u64::from(r.steps()));
                }
            }
        }
        if let Ok(p) = RayPacket8::new(extent, [origin; 8], [dir; 8]) {
            sink(u64::from(p.lanes()));
        }
    }
    for ray in rays {
        let Ok(Some(mut ray)) = ray else { continue };
        sink(u64::from(ray.crossings()[0]) ^ ray.driving_axis() as u64);
        if let Some(f) = ray.entry_face() {
            sink(f.axis() as u64);
        }
        for v in ray.path(m).take(u32_at(100) as usize) {
            sink(v.index as u64);
        }
        let Ok(raster) = raster else { continue };
        // The tube walk (the raster dilated by one voxel), over the plane
        // and over a line level.
        for r in [Ok(raster), lined] {
            let Ok(r) = r else { continue };
            let mut tube = ray;
            match tube.walk_dilated(&r, budget, |i, c| (i as u8 ^ c) & 5 == 0) {
                Ok(WalkEnd::Hit) => sink(tube.hit().index as u64),
                Ok(WalkEnd::Budget | WalkEnd::Exit) => sink(u64::from(tube.steps())),
                Err(_) => sink(8),
            }
        }
        match ray.walk(&raster, m, budget, |i, c| (i as u8 ^ c) & 3 == 0) {
            Ok(WalkEnd::Hit) => sink(ray.hit().index as u64 ^ u64::from(ray.hit().steps)),
            Ok(WalkEnd::Budget | WalkEnd::Exit) => sink(u64::from(ray.steps())),
            Err(_) => sink(7),
        }
        while let Ok(Some(h)) = ray.first_hit(&raster, m) {
            sink(h.index as u64 ^ u64::from(h.voxel[2]));
        }
        if let Ok(vs) = ray.voxels(&raster, mode(input::<1>(104)[0])) {
            for v in vs {
                sink(v.index as u64 ^ u64::from(v.cell));
            }
        }
    }
}

/// Entry point (no runtime: this binary is only linked, never run).
#[unsafe(no_mangle)]
pub extern "C" fn _start() -> ! {
    loop {
        drive();
    }
}
