//! The fuzz case of the cargo-fuzz target `packet` (`fuzz/fuzz_targets/
//! packet.rs`), shared with the replay test in `tests/packet.rs`: the same
//! `Arbitrary` decoding and the same checker run in both, so a crash file
//! found by the fuzzer replays exactly under `cargo test`.

use arbitrary::Arbitrary;
use rrt_core::check_packet::{Walk, check_packet, check_packet_script};
use rrt_core::discrete_ray::{Connectivity, DiscreteRay};
use rrt_core::error::RayError;
use rrt_core::packet::{LANES, RayPacket8};
use rrt_core::proximity::{coarse_extent, distance_field, flag_neighbourhood, line_distances};
use rrt_core::raster::{Extent, Raster, RasterMut, line_count};

use crate::fuzz::{Component, Coord, decode_ray, repeated_cells};

/// A walk: connectivity (mod 3) and skipping (bit 7), budget (255 =
/// unlimited) and hit bits.
#[derive(Arbitrary, Debug, Clone, Copy)]
pub struct WalkCase {
    /// 0 Six, 1 TwentySix, 2 Adaptive (mod 3); skips empty space when bit 7
    /// is set.
    pub mode: u8,
    /// Step budget; 255 is `u32::MAX`.
    pub budget: u8,
    /// A voxel is a hit when `cell & hit_bits != 0`.
    pub hit_bits: u8,
}

impl WalkCase {
    fn walk(self) -> Walk {
        Walk {
            mode: Connectivity::ALL[usize::from(self.mode % 3)],
            budget: if self.budget == u8::MAX {
                u32::MAX
            } else {
                u32::from(self.budget)
            },
            hit_bits: self.hit_bits,
            skip: self.mode & 0x80 != 0,
        }
    }
}

/// One lane: a half-line or segment, walked by itself before it joins the
/// packet (so that lanes start in different states).
#[derive(Arbitrary, Debug, Clone)]
pub struct LaneCase {
    /// Origin (or segment start).
    pub origin: [Coord; 3],
    /// Direction (or segment extent).
    pub dir: [Component; 3],
    /// A segment rather than a half-line.
    pub segment: bool,
    /// A scalar walk taken before packing.
    pub before: Option<WalkCase>,
}

/// A packet of up to eight lanes over a small raster with arbitrary cells,
/// and a script of walks.
#[derive(Arbitrary, Debug, Clone)]
pub struct PacketCase {
    /// Raster dimensions, each taken modulo 16, plus one.
    pub dims: [u8; 3],
    /// Cells, repeated over the plane (OPAQUE and PROXIMITY kept, unless
    /// `field` keeps them whole).
    pub cells: Vec<u8>,
    /// Bit 0: recompute the proximity flags from the opaque voxels; bit 1:
    /// keep the cells whole (arbitrary distance bits); bit 2: compute the
    /// distance field (and flags) from the opaque voxels; bit 3: give the
    /// raster its line level.
    pub field: u8,
    /// The lanes (`None`: empty).
    pub lanes: [Option<LaneCase>; LANES],
    /// Walks run on the packet and the scalar rays (at most 16 are used).
    pub script: Vec<WalkCase>,
}

/// Builds the packet of `case` and checks every lane against its scalar
/// ray in all three modes and through the script; panics on the first
/// violation (the fuzzer reports the panic as a crash).
pub fn run_packet_case(case: &PacketCase) {
    let dims = case.dims.map(|d| u32::from(d % 16) + 1);
    let Ok(extent) = Extent::new(dims[0], dims[1], dims[2]) else {
        unreachable!("dims in 1..=16")
    };
    let mut plane = if case.field & 2 != 0 {
        (0..extent.len())
            .map(|i| {
                case.cells
                    .get(i % case.cells.len().max(1))
                    .copied()
                    .unwrap_or(0)
            })
            .collect()
    } else {
        repeated_cells(&case.cells, extent.len())
    };
    if case.field & 1 != 0 {
        flag_neighbourhood(&mut RasterMut::new(extent, &mut plane).expect("plane length"));
    }
    if case.field & 4 != 0 {
        distance_field(&mut RasterMut::new(extent, &mut plane).expect("plane length"));
    }
    let mut lines = vec![0; line_count(plane.len())];
    let raster = Raster::new(extent, &plane).expect("plane length");
    let raster = if case.field & 8 != 0 {
        let mut bricks = vec![0; coarse_extent(extent).expect("coarse extent").len()];
        line_distances(&raster, &mut bricks, &mut lines).expect("line count");
        raster.with_lines(&lines).expect("line count")
    } else {
        raster
    };
    let rays: [Option<DiscreteRay>; LANES] = std::array::from_fn(|lane| {
        let l = case.lanes[lane].as_ref()?;
        let (_, _, set_up) = decode_ray(extent, l.origin, l.dir, l.segment);
        let mut ray = match set_up {
            Ok(ray) => ray?,
            Err(RayError::OriginOutOfRange { .. } | RayError::SegmentTooLong { .. }) => {
                return None;
            }
            Err(e) => panic!("lane {lane}: setup failed for an accepted input: {e:?}"),
        };
        if let Some(w) = l.before {
            let w = w.walk();
            let bits = w.hit_bits;
            let test = |_, c| c & bits != 0;
            if w.skip {
                ray.walk_skipping(&raster, w.mode, w.budget, test)
            } else {
                ray.walk(&raster, w.mode, w.budget, test)
            }
            .expect("same extent");
        }
        Some(ray)
    });
    let packet = RayPacket8::from_rays(extent, rays).expect("same extent");
    if let Err(v) = check_packet(&raster, &packet) {
        panic!("{v}");
    }
    let script: Vec<Walk> = case.script.iter().take(16).map(|w| w.walk()).collect();
    if let Err(v) = check_packet_script(&raster, &packet, &script) {
        panic!("{v} (script {script:?})");
    }
}
