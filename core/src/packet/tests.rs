//! Unit tests of the ray packet; the large random property test lives in
//! `tests/packet.rs`.

use std::vec;
use std::vec::Vec;

use super::lanes::{I64x8, Mask8};
use super::*;
use crate::check_packet::{Walk, check_packet, check_packet_script};
use crate::fixed::{VOXEL, voxel_centre};
use crate::proximity::{coarse_extent, distance_field, flag_neighbourhood, line_distances};
use crate::raster::{RasterMut, line_count};
use crate::testkit::Rng;

#[track_caller]
fn check(raster: &Raster<'_>, packet: &RayPacket8, label: &str) {
    if let Err(v) = check_packet(raster, packet) {
        panic!("{label}: {v}\n{packet:#?}");
    }
}

fn plane_with(e: Extent, rng: &mut Rng, density: u64) -> Vec<u8> {
    let mut plane: Vec<u8> = (0..e.len())
        .map(|_| {
            if rng.below(100) < density {
                cell::OPAQUE
            } else {
                0
            }
        })
        .collect();
    let mut r = RasterMut::new(e, &mut plane).unwrap();
    flag_neighbourhood(&mut r);
    // Some stray proximity flags and some opaque voxels without them, so
    // that Adaptive switches in every way.
    for c in plane.iter_mut() {
        match rng.below(16) {
            0 => *c ^= cell::PROXIMITY,
            1 => *c |= cell::OPAQUE,
            _ => {}
        }
    }
    plane
}

#[test]
fn lane_masks_round_trip() {
    for bits in 0..=255u8 {
        assert_eq!(Mask8::from_bits(bits).bits(), bits);
    }
    let v = I64x8::new([-3, -1, 0, 1, 2, i64::MIN, i64::MAX, 5]);
    assert_eq!(v.lt0().bits(), 0b0010_0011);
    assert_eq!(v.gt(I64x8::splat(0)).bits(), 0b1101_1000);
    assert_eq!(v.eq_splat(1).bits(), 0b0000_1000);
    assert_eq!(v.add(I64x8::splat(1)).to_array()[6], i64::MIN); // wraps
    assert_eq!(v.to_array()[7], 5);
}

#[test]
fn empty_packet_ends_at_once() {
    let e = Extent::cube(4).unwrap();
    let plane = vec![0u8; e.len()];
    let r = Raster::new(e, &plane).unwrap();
    let mut p = RayPacket8::from_rays(e, [None; LANES]).unwrap();
    assert_eq!(p.lanes(), 0);
    let end = p.walk(&r, Connectivity::Six, 10, |_, _, _| true).unwrap();
    assert_eq!(end, PacketEnd::default());
    assert_eq!(p.hit(0), None);
}

#[test]
fn extent_mismatches_are_errors() {
    let e = Extent::cube(4).unwrap();
    let other = Extent::cube(5).unwrap();
    let ray = DiscreteRay::new(other, [0, 0, 0], [1, 1, 1]).unwrap();
    let mut rays = [None; LANES];
    rays[6] = ray;
    assert_eq!(
        RayPacket8::from_rays(e, rays),
        Err(LaneError {
            lane: 6,
            error: RayError::ExtentMismatch
        })
    );
    let mut p = RayPacket8::from_rays(other, rays).unwrap();
    let plane = vec![0u8; e.len()];
    let r = Raster::new(e, &plane).unwrap();
    assert_eq!(
        p.first_hit(&r, Connectivity::Six),
        Err(RayError::ExtentMismatch)
    );
    let far = [[1i64 << 50, 0, 0]; LANES];
    assert_eq!(
        RayPacket8::new(e, far, [[1, 0, 0]; LANES])
            .unwrap_err()
            .lane,
        0
    );
}

#[test]
fn lanes_with_different_frames_match_their_scalar_rays() {
    // Every driving axis and sign, axis-parallel and zero directions, and a
    // lane that misses: one packet.
    let e = Extent::new(9, 7, 5).unwrap();
    let mut rng = Rng(7);
    let plane = plane_with(e, &mut rng, 8);
    let r = Raster::new(e, &plane).unwrap();
    let c = voxel_centre;
    let origins = [
        [c(4), c(3), c(2)],
        [c(4), c(3), c(2)],
        [0, 0, 0],
        [9 * VOXEL, 7 * VOXEL, 5 * VOXEL],
        [c(1), VOXEL, c(2)],
        [-VOXEL, c(3), c(2)],
        [c(2), c(2), c(2)],
        [-VOXEL, -VOXEL, -VOXEL],
    ];
    let dirs = [
        [3 << 16, -(1 << 16), 5],
        [-7, 1 << 20, -(1 << 19)],
        [1, 1, 1],
        [-(1 << 16), -(1 << 16), -(1 << 16)],
        [0, 0, 1 << 16],
        [1 << 16, 0, 0],
        [0, 0, 0],
        [-1, 0, 0], // misses
    ];
    let p = RayPacket8::new(e, origins, dirs).unwrap();
    assert_eq!(p.lanes(), 0x7f);
    check(&r, &p, "frames");
}

#[test]
fn lanes_in_different_states_resume_like_their_scalar_rays() {
    // Lanes that are fresh, part-way, just hit, or done, in one packet: the
    // first packet iteration steps some lanes and only visits others.
    let e = Extent::cube(12).unwrap();
    let mut rng = Rng(99);
    for case in 0..200 {
        let density = 3 + rng.below(10);
        let plane = plane_with(e, &mut rng, density);
        let r = Raster::new(e, &plane).unwrap();
        let rays: [Option<DiscreteRay>; LANES] = core::array::from_fn(|_| {
            let o = [0; 3].map(|_| rng.range(-VOXEL, 13 * VOXEL));
            let d = [0; 3].map(|_| rng.range(-(1 << 20), 1 << 20) as i32);
            let mut ray = DiscreteRay::new(e, o, d).unwrap()?;
            let mode = Connectivity::ALL[rng.below(3) as usize];
            match rng.below(4) {
                0 => {}
                1 => {
                    let _ = ray.walk(&r, mode, rng.below(8) as u32, |_, _| false);
                }
                2 => {
                    let _ = ray.first_hit(&r, mode);
                }
                _ => while ray.first_hit(&r, mode).unwrap().is_some() {},
            }
            Some(ray)
        });
        let p = RayPacket8::from_rays(e, rays).unwrap();
        check(&r, &p, &std::format!("case {case}"));
        let script: Vec<Walk> = (0..6)
            .map(|_| Walk {
                mode: Connectivity::ALL[rng.below(3) as usize],
                budget: [0, 1, 2, 5, u32::MAX][rng.below(5) as usize],
                hit_bits: [0, cell::OPAQUE, cell::PROXIMITY][rng.below(3) as usize],
                skip: rng.chance(1, 2),
            })
            .collect();
        if let Err(v) = check_packet_script(&r, &p, &script) {
            panic!("case {case}: {v}, script {script:?}");
        }
    }
}

#[test]
fn exact_edge_and_corner_crossings_keep_their_ties() {
    // Diagonals through lattice points: every step of the Six ray is a tie,
    // and Adaptive must carry the tie flag across proximity boundaries.
    let e = Extent::cube(10).unwrap();
    let mut rng = Rng(3);
    let plane = plane_with(e, &mut rng, 15);
    let r = Raster::new(e, &plane).unwrap();
    let m = 1 << 16;
    let dirs = [
        [m, m, m],
        [m, -m, m],
        [-m, -m, -m],
        [m, m, 0],
        [0, -m, m],
        [2 * m, m, m],
        [m, 2 * m, 2 * m],
        [m, m, -2 * m],
    ];
    for origin in [[0, 0, 0], [VOXEL, 2 * VOXEL, 3 * VOXEL], [5 * VOXEL; 3]] {
        let p = RayPacket8::new(e, [origin; LANES], dirs).unwrap();
        check(&r, &p, "ties");
    }
}

#[test]
fn small_random_packets_match_their_scalar_rays() {
    for seed in 0..300u64 {
        let mut rng = Rng(seed);
        let dims = [0; 3].map(|_| 1 + rng.below(14) as u32);
        let e = Extent::new(dims[0], dims[1], dims[2]).unwrap();
        let density = rng.below(20);
        let plane = plane_with(e, &mut rng, density);
        let r = Raster::new(e, &plane).unwrap();
        let origins = core::array::from_fn(|_| {
            [0, 1, 2].map(|k| {
                let size = i64::from(dims[k]) * VOXEL;
                match rng.below(4) {
                    0 => rng.range(0, size),
                    1 => rng.range(0, i64::from(dims[k])) * VOXEL,
                    _ => rng.range(-2 * size, 3 * size),
                }
            })
        });
        let dirs = core::array::from_fn(|_| {
            [0; 3].map(|_| match rng.below(5) {
                0 => 0,
                1 => rng.range(-1, 1) as i32,
                _ => rng.range(-(1 << 30), 1 << 30) as i32,
            })
        });
        let p = RayPacket8::new(e, origins, dirs).unwrap();
        check(&r, &p, &std::format!("seed {seed}"));
    }
}

/// A sparse plane with its distance field, its line level (jumps of up to
/// `DISTANCE_LIMIT` voxels), and some cells disturbed so that the field is
/// no longer exact: lanes must still equal their scalar skipping walks.
fn skipping_plane(e: Extent, rng: &mut Rng, per_mille: u64, disturb: bool) -> (Vec<u8>, Vec<u8>) {
    let mut plane: Vec<u8> = (0..e.len())
        .map(|_| {
            if rng.below(1000) < per_mille {
                cell::OPAQUE
            } else {
                0
            }
        })
        .collect();
    distance_field(&mut RasterMut::new(e, &mut plane).unwrap());
    let mut lines = vec![0u8; line_count(plane.len())];
    let raster = Raster::new(e, &plane).unwrap();
    let mut bricks = vec![0u8; coarse_extent(e).unwrap().len()];
    line_distances(&raster, &mut bricks, &mut lines).unwrap();
    if disturb {
        for c in plane.iter_mut() {
            if rng.chance(1, 50) {
                *c = rng.next_u64().to_le_bytes()[0];
            }
        }
    }
    (plane, lines)
}

#[test]
fn skipping_packets_match_their_scalar_skipping_walks() {
    for seed in 0..120u64 {
        let mut rng = Rng(seed ^ 0x5_1DE);
        let dims = [0; 3].map(|_| 1 + rng.below(90) as u32);
        let e = Extent::new(dims[0], dims[1], dims[2]).unwrap();
        let per_mille = rng.below(4);
        let (plane, lines) = skipping_plane(e, &mut rng, per_mille, seed % 3 == 0);
        let plain = Raster::new(e, &plane).unwrap();
        let with_lines = plain.with_lines(&lines).unwrap();
        // A camera-like block: one origin, nearby directions.
        let eye = [0, 1, 2]
            .map(|k| rng.range(-i64::from(dims[k]) * VOXEL, 2 * i64::from(dims[k]) * VOXEL));
        let aim = [0, 1, 2].map(|k| rng.range(0, i64::from(dims[k]) * VOXEL) - eye[k]);
        let m = aim.iter().map(|v| v.unsigned_abs()).max().unwrap().max(1);
        let d = aim.map(|v| (i128::from(v) * (1 << 28) / i128::from(m)) as i32);
        let dirs = core::array::from_fn(|l| {
            let (px, py) = ((l % 4) as i32, (l / 4) as i32);
            [d[0] + px * 40_000, d[1] + py * 40_000, d[2] - px * 9_000]
        });
        let p = RayPacket8::new(e, [eye; LANES], dirs).unwrap();
        for r in [&plain, &with_lines] {
            check(r, &p, &std::format!("seed {seed}"));
        }
    }
}

/// Skipping lanes really jump: a camera block through empty space visits
/// few voxels (through the line level, as the renderer walks), each lane
/// as many as its scalar skipping walk.
#[test]
fn skipping_lanes_jump() {
    let e = Extent::cube(96).unwrap();
    let mut plane = vec![cell::EMPTY; e.len()];
    for y in 40..56 {
        for z in 40..56 {
            plane[e.index([90, y, z]).unwrap()] = cell::OPAQUE;
        }
    }
    distance_field(&mut RasterMut::new(e, &mut plane).unwrap());
    let r = Raster::new(e, &plane).unwrap();
    let mut bricks = vec![0u8; coarse_extent(e).unwrap().len()];
    let mut lines = vec![0u8; line_count(plane.len())];
    line_distances(&r, &mut bricks, &mut lines).unwrap();
    let r = r.with_lines(&lines).unwrap();
    let origin = [0, voxel_centre(47), voxel_centre(47)];
    let dirs = core::array::from_fn(|l| [1 << 28, (l as i32 - 4) << 20, 3 << 18]);
    let mut p = RayPacket8::new(e, [origin; LANES], dirs).unwrap();
    for mode in Connectivity::ALL {
        let mut q = p.clone();
        assert_eq!(q.first_hit_skipping(&r, mode).unwrap(), 0xff, "{mode:?}");
        for (lane, dir) in dirs.iter().enumerate() {
            let mut ray = DiscreteRay::new(e, origin, *dir).unwrap().unwrap();
            let hit = ray.first_hit_skipping(&r, mode).unwrap().unwrap();
            assert_eq!(q.hit(lane), Some(hit));
            assert_eq!(q.lane_ray(lane), Some(ray));
            if mode != Connectivity::Six {
                assert!(hit.steps < 30, "{mode:?} lane {lane}: {} steps", hit.steps);
            }
        }
    }
    check(&r, &p, "wall");
    assert_eq!(p.first_hit(&r, Connectivity::TwentySix).unwrap(), 0xff);
    assert_eq!(p.hit(0).unwrap().steps, 91);
}
