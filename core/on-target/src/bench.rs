//! The workloads whose instructions per step are measured: the same code
//! on the target (counted by QEMU) and on the host (counted by callgrind).
//! Each returns the number of voxels its walks visited ([`dilated`]: of
//! the 6-connected paths whose tubes it walks).

use rrt_core::discrete_ray::{Connectivity, DiscreteRay, WalkEnd};
use rrt_core::packet::{LANES, RayPacket8};
use rrt_core::raster::Raster;

use crate::rays::{Spec, spec};
use crate::scene;
use crate::traversal::{RAYS, SEED, dilated_test};

/// Draws every ray's inputs from the seed into `out` (outside the
/// measured workloads).
pub fn specs(raster: &Raster<'_>, out: &mut [Spec]) {
    let e = raster.extent();
    for (i, s) in (0..RAYS).zip(out.iter_mut()) {
        *s = spec(e, SEED, i);
    }
}

/// Sets up every ray of `specs` (the part of [`walk`] and [`packet`] that
/// is not stepping); returns the number that enter the raster.
#[inline(never)]
pub fn setup(raster: &Raster<'_>, specs: &[Spec]) -> u64 {
    let e = raster.extent();
    let mut n = 0;
    for s in specs {
        if let Ok(Some(r)) = s.ray(e) {
            n += u64::from(core::hint::black_box(r).steps() == 0);
        }
    }
    n
}

/// Sets up every ray and walks it to each of its hits and on to its exit
/// (`first_hit`, resumed); returns the voxels visited.
#[inline(never)]
pub fn walk(raster: &Raster<'_>, specs: &[Spec], mode: Connectivity) -> u64 {
    let e = raster.extent();
    let mut steps = 0;
    for s in specs {
        let Ok(Some(mut r)) = s.ray(e) else { continue };
        while let Ok(Some(_)) = r.first_hit(raster, mode) {}
        steps += u64::from(r.steps());
    }
    steps
}

/// The same rays in packets of eight, walked the same way; returns the
/// voxels visited by all lanes.
#[inline(never)]
pub fn packet(raster: &Raster<'_>, specs: &[Spec], mode: Connectivity) -> u64 {
    let e = raster.extent();
    let mut steps = 0;
    for group in specs.chunks(LANES) {
        let rays: [Option<DiscreteRay>; LANES] =
            core::array::from_fn(|l| group.get(l).and_then(|s| s.ray(e).ok().flatten()));
        if let Ok(mut p) = RayPacket8::from_rays(e, rays) {
            while let Ok(hits) = p.first_hit(raster, mode) {
                if hits == 0 {
                    break;
                }
            }
            steps += lane_steps(&p);
        }
    }
    steps
}

/// Sets up every ray and walks its tube ([`DiscreteRay::walk_dilated`],
/// the shadow classification's walk) to each of its hits
/// ([`dilated_test`]) and on to its exit; returns the voxels of the rays'
/// 6-connected paths (`1 +` the crossings: the walk's own step count
/// counts a jump as one step).
#[inline(never)]
pub fn dilated(raster: &Raster<'_>, specs: &[Spec]) -> u64 {
    let e = raster.extent();
    let mut voxels = 0;
    for s in specs {
        let Ok(Some(mut r)) = s.ray(e) else { continue };
        while let Ok(WalkEnd::Hit) = r.walk_dilated(raster, u32::MAX, dilated_test) {}
        voxels += 1 + r.crossings().iter().map(|&c| u64::from(c)).sum::<u64>();
    }
    voxels
}

fn lane_steps(p: &RayPacket8) -> u64 {
    (0..LANES)
        .filter_map(|l| p.lane_ray(l))
        .map(|r| u64::from(r.steps()))
        .sum()
}

/// The integrator's camera rays (the 64×64 image of [`crate::scene`]), eye
/// and direction per pixel, into `out` (outside the measured workloads).
pub fn camera(out: &mut [([i64; 3], [i32; 3])]) {
    for (n, c) in out.iter_mut().enumerate() {
        *c = scene::camera(n % scene::SIZE, n / scene::SIZE);
    }
}

/// Sets up the camera rays (the part of [`camera_walk`] that is not
/// stepping).
#[inline(never)]
pub fn camera_setup(raster: &Raster<'_>, rays: &[([i64; 3], [i32; 3])]) -> u64 {
    let e = raster.extent();
    let mut n = 0;
    for &(eye, d) in rays {
        if let Ok(Some(r)) = DiscreteRay::new(e, eye, d) {
            n += u64::from(core::hint::black_box(r).steps() == 0);
        }
    }
    n
}

/// Each camera ray walked to its first hit with `first_hit` in the
/// scene's mode; returns the voxels visited. Neighbouring pixels' rays are
/// coherent, as a renderer's are.
#[inline(never)]
pub fn camera_walk(raster: &Raster<'_>, rays: &[([i64; 3], [i32; 3])]) -> u64 {
    let e = raster.extent();
    let mut steps = 0;
    for &(eye, d) in rays {
        if let Ok(Some(mut r)) = DiscreteRay::new(e, eye, d) {
            let _ = r.first_hit(raster, scene::MODE);
            steps += u64::from(r.steps());
        }
    }
    steps
}

/// The same camera rays in packets of eight horizontally adjacent pixels;
/// returns the voxels visited by all lanes.
#[inline(never)]
pub fn camera_packet(raster: &Raster<'_>, rays: &[([i64; 3], [i32; 3])]) -> u64 {
    let e = raster.extent();
    let mut steps = 0;
    for group in rays.chunks_exact(LANES) {
        let origins = core::array::from_fn(|l| group[l].0);
        let dirs = core::array::from_fn(|l| group[l].1);
        if let Ok(mut p) = RayPacket8::new(e, origins, dirs) {
            let _ = p.first_hit(raster, scene::MODE);
            steps += lane_steps(&p);
        }
    }
    steps
}
