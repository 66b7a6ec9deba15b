//! Every lane of a `RayPacket8` equals the scalar discrete ray, in plain
//! and skipping walks: the shared checker (`rrt_core::check_packet`) on
//! many seeded random packets.
//!
//! Every packet derives from a printed seed: a failure names the seed, and
//! `RRT_SEED=<seed> cargo test -p rrt-tests --release --test packet` replays
//! just that case first. `RRT_PACKETS=<n>` changes the number of packets.

use rrt_core::check_packet::{Walk, check_packet, check_packet_script};
use rrt_core::discrete_ray::{Connectivity, DiscreteRay};
use rrt_core::fixed::{VOXEL, voxel_centre};
use rrt_core::packet::{LANES, RayPacket8};
use rrt_core::proximity::{coarse_extent, distance_field, flag_neighbourhood, line_distances};
use rrt_core::raster::{Extent, Raster, RasterMut, cell, line_count};
use rrt_tests::{Rng, env_count, random_opaque, replay_seed};

/// What the lanes of one packet look like.
#[derive(Clone, Copy, Debug)]
enum Bundle {
    /// Independent random rays.
    Mixed,
    /// Rays from one point, in nearby directions (a camera's 4×2 block).
    Coherent,
    /// Degenerate lanes: zero, axis-parallel, ±1 and exact diagonal
    /// directions, from faces, edges and corners of voxels and of the box.
    Degenerate,
    /// Segments (shadow rays), some of length zero.
    Segments,
}

/// A coordinate on one axis of a raster of `n` voxels: inside, on voxel
/// faces, at centres, on the box faces, around or far from the box.
fn coord(rng: &mut Rng, n: u32) -> i64 {
    let size = i64::from(n) * VOXEL;
    match rng.below(7) {
        0 => rng.range(0, size - 1),
        1 => rng.range(0, i64::from(n)) * VOXEL,
        2 => voxel_centre(rng.below(u64::from(n)) as u32),
        3 => {
            if rng.chance(1, 2) {
                0
            } else {
                size
            }
        }
        4 => rng.range(0, i64::from(n)) * VOXEL + rng.range(-1, 1),
        5 => rng.range(-3 * size, 4 * size),
        _ => rng.range(-(1i64 << 40), 1i64 << 40),
    }
}

fn random_dir(rng: &mut Rng) -> [i32; 3] {
    let scale = [1u32, 8, 16, 24, 30][rng.below(5) as usize];
    let mut d = [0; 3].map(|_| rng.range(-(1i64 << scale), 1i64 << scale) as i32);
    match rng.below(8) {
        0 => {
            // Axis-parallel.
            let k = rng.below(3) as usize;
            d = [0; 3];
            d[k] = if rng.chance(1, 2) { 1 << 16 } else { -1 };
        }
        1 => d[rng.below(3) as usize] = 0, // in a plane
        2 => d = [0; 3],                   // zero direction
        3 => {
            // Equal magnitudes: exact diagonals through edges and corners.
            let m = rng.range(1, 1 << 20) as i32;
            d = [0; 3].map(|_| if rng.chance(1, 2) { m } else { -m });
            if rng.chance(1, 3) {
                d[rng.below(3) as usize] = 0;
            }
        }
        4 => {
            // ±1 components beside a large one.
            for v in &mut d {
                if rng.chance(1, 2) {
                    *v = if rng.chance(1, 2) { 1 } else { -1 };
                }
            }
        }
        _ => {}
    }
    d
}

/// A direction from `o` towards a random point of (or near) the box.
fn aimed_dir(rng: &mut Rng, dims: [u32; 3], o: [i64; 3]) -> [i32; 3] {
    let t = [0, 1, 2].map(|k| coord(rng, dims[k]).clamp(-(1 << 33), 1 << 33));
    let d = [0, 1, 2].map(|k| i128::from(t[k]) - i128::from(o[k]));
    let m = d.iter().map(|v| v.unsigned_abs()).max().unwrap_or(1).max(1);
    // Scale into ±2^30 keeping the ratios as well as integers can.
    let d = d.map(|v| v * (1i128 << 30) / m as i128);
    d.map(|v| v as i32)
}

struct Packet {
    dims: [u32; 3],
    plane: Vec<u8>,
    /// A line level for the skipping walks (empty: none).
    lines: Vec<u8>,
    rays: [Option<DiscreteRay>; LANES],
    bundle: Bundle,
}

/// A plane and its line level (empty: none). The skipping walks jump on
/// the distance bits: exact fields, fields with cells disturbed, and random
/// distance bits all must give lanes equal to their scalar rays.
fn random_plane(rng: &mut Rng, e: Extent) -> (Vec<u8>, Vec<u8>) {
    let density = rng.below(30);
    let mut plane = random_opaque(rng, e.len(), density, 100);
    let mut lines = Vec::new();
    match rng.below(6) {
        // The distance field (and flags) as the renderer makes them, with a
        // line level or without, the field exact or disturbed.
        3..=5 => {
            let den = 1 + rng.below(400);
            let sparse = random_opaque(rng, e.len(), 1, den);
            for (c, s) in plane.iter_mut().zip(sparse) {
                *c = if density < 10 { s } else { *c | s };
            }
            distance_field(&mut RasterMut::new(e, &mut plane).unwrap());
            if rng.chance(1, 2) {
                lines = vec![0; line_count(plane.len())];
                let mut bricks = vec![0; coarse_extent(e).unwrap().len()];
                line_distances(&Raster::new(e, &plane).unwrap(), &mut bricks, &mut lines).unwrap();
            }
            if rng.chance(1, 3) {
                for c in &mut plane {
                    if rng.chance(1, 40) {
                        *c = rng.below(256) as u8;
                    }
                }
            }
        }
        // Proximity flags as the renderer sets them.
        0 => flag_neighbourhood(&mut RasterMut::new(e, &mut plane).unwrap()),
        // Random flags: Adaptive switches anywhere.
        1 => {
            for c in &mut plane {
                if rng.chance(1, 3) {
                    *c |= cell::PROXIMITY;
                }
            }
        }
        // Flags, then some flipped, and random distance bits.
        _ => {
            flag_neighbourhood(&mut RasterMut::new(e, &mut plane).unwrap());
            for c in &mut plane {
                if rng.chance(1, 10) {
                    *c ^= cell::PROXIMITY;
                }
                *c |= (rng.below(64) as u8) << cell::DISTANCE_SHIFT;
            }
        }
    }
    (plane, lines)
}

fn random_packet(seed: u64) -> Packet {
    let mut rng = Rng::new(seed);
    // Some rasters long enough for lines of the line level and long jumps.
    let most = if rng.chance(1, 4) { 80 } else { 20 };
    let dims = [0; 3].map(|_| {
        if rng.chance(1, 8) {
            1
        } else {
            1 + rng.below(most) as u32
        }
    });
    let e = Extent::new(dims[0], dims[1], dims[2]).unwrap();
    let (plane, lines) = random_plane(&mut rng, e);
    let bundle = [
        Bundle::Mixed,
        Bundle::Coherent,
        Bundle::Degenerate,
        Bundle::Segments,
    ][rng.below(4) as usize];
    let eye = [0, 1, 2].map(|k| coord(&mut rng, dims[k]));
    let centre_dir = aimed_dir(&mut rng, dims, eye);
    let rays = std::array::from_fn(|lane| {
        let origin = match bundle {
            Bundle::Coherent => eye,
            _ => [0, 1, 2].map(|k| coord(&mut rng, dims[k])),
        };
        match bundle {
            Bundle::Mixed => {
                let d = if rng.chance(1, 2) {
                    aimed_dir(&mut rng, dims, origin)
                } else {
                    random_dir(&mut rng)
                };
                DiscreteRay::new(e, origin, d).unwrap()
            }
            Bundle::Coherent => {
                // A 4×2 pixel block: small offsets of one direction.
                let (px, py) = ((lane % 4) as i32, (lane / 4) as i32);
                let step = 1 << rng.below(20);
                let d = [
                    centre_dir[0].saturating_add(px * step),
                    centre_dir[1].saturating_add(py * step),
                    centre_dir[2],
                ];
                DiscreteRay::new(e, origin, d).unwrap()
            }
            Bundle::Degenerate => {
                // Voxel and box faces, edges and corners.
                let o = [0, 1, 2].map(|k| {
                    let n = i64::from(dims[k]);
                    match rng.below(3) {
                        0 => rng.range(0, n) * VOXEL,
                        1 => voxel_centre(rng.below(dims[k] as u64) as u32),
                        _ => rng.range(-1, n + 1) * VOXEL,
                    }
                });
                DiscreteRay::new(e, o, random_dir(&mut rng)).unwrap()
            }
            Bundle::Segments => {
                let to = if rng.chance(1, 10) {
                    origin
                } else {
                    [0, 1, 2].map(|k| {
                        let span = i64::from(dims[k]) * VOXEL * 3;
                        (origin[k] + rng.range(-span, span)).clamp(-(1 << 47), 1 << 47)
                    })
                };
                DiscreteRay::segment(e, origin, to).unwrap()
            }
        }
    });
    Packet {
        dims,
        plane,
        lines,
        rays,
        bundle,
    }
}

/// The raster of a packet case, with its line level if it has one.
fn raster_of(p: &Packet) -> Raster<'_> {
    let e = Extent::new(p.dims[0], p.dims[1], p.dims[2]).unwrap();
    let r = Raster::new(e, &p.plane).unwrap();
    if p.lines.is_empty() {
        r
    } else {
        r.with_lines(&p.lines).unwrap()
    }
}

fn seed_of(i: u64) -> u64 {
    0x9AC4_E700_0000_0000 ^ i.wrapping_mul(0x9E37_79B9_7F4A_7C15)
}

#[test]
fn random_packets_equal_their_scalar_rays() {
    let n = env_count("RRT_PACKETS").unwrap_or(100_000);
    let mut lanes = 0u64;
    let mut hits = 0u64;
    let mut lane_walks = 0u64;
    let mut checked = 0u64;
    for seed in replay_seed().into_iter().chain((0..n).map(seed_of)) {
        let p = random_packet(seed);
        let e = Extent::new(p.dims[0], p.dims[1], p.dims[2]).unwrap();
        let r = raster_of(&p);
        let packet = RayPacket8::from_rays(e, p.rays).unwrap();
        lanes += u64::from(packet.lanes().count_ones());
        let report = check_packet(&r, &packet)
            .unwrap_or_else(|v| panic!("seed {seed} ({:?}): {v}", p.bundle));
        hits += u64::from(report.hits);
        lane_walks += u64::from(report.lane_walks);
        checked += 1;
    }
    println!("{checked} packets, {lanes} lanes, {lane_walks} lane walks, {hits} hits");
    // Guard against a generator that only produces empty lanes or no hits.
    assert!(
        lanes > checked * 3,
        "only {lanes} lanes in {checked} packets"
    );
    assert!(hits > checked, "only {hits} hits in {checked} packets");
}

/// Scripts of walks that change mode, budget and hit test between walks,
/// on lanes in different states (fresh, part-way, done).
#[test]
fn random_walk_scripts_equal_their_scalar_rays() {
    let n = env_count("RRT_PACKETS").map_or(20_000, |v| v / 5);
    for i in 0..n {
        let seed = seed_of(i) ^ 0x5C1;
        let p = random_packet(seed);
        let mut rng = Rng::new(seed);
        let e = Extent::new(p.dims[0], p.dims[1], p.dims[2]).unwrap();
        let r = raster_of(&p);
        let mut rays = p.rays;
        for ray in rays.iter_mut().flatten() {
            let mode = Connectivity::ALL[rng.below(3) as usize];
            let budget = rng.below(6) as u32;
            let _ = if rng.chance(1, 2) {
                ray.walk_skipping(&r, mode, budget, |_, c| c & cell::OPAQUE != 0)
            } else {
                ray.walk(&r, mode, budget, |_, c| c & cell::OPAQUE != 0)
            };
        }
        let packet = RayPacket8::from_rays(e, rays).unwrap();
        let script: Vec<Walk> = (0..rng.below(8))
            .map(|_| Walk {
                mode: Connectivity::ALL[rng.below(3) as usize],
                budget: [0, 1, 2, 3, 7, u32::MAX][rng.below(6) as usize],
                hit_bits: [0, cell::OPAQUE, cell::PROXIMITY, 0xff][rng.below(4) as usize],
                skip: rng.chance(1, 2),
            })
            .collect();
        check_packet_script(&r, &packet, &script)
            .unwrap_or_else(|v| panic!("seed {seed} ({:?}): {v}, script {script:?}", p.bundle));
    }
}

/// Replays the inputs of the cargo-fuzz target `packet` kept in
/// `tests/fuzz_regressions/packet/` through the fuzzer's own decoding and
/// checker (see the README there).
#[test]
fn packet_fuzz_inputs_replay() {
    use arbitrary::{Arbitrary, Unstructured};
    use rrt_tests::packet_case::{PacketCase, run_packet_case};
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("fuzz_regressions/packet");
    let mut files: Vec<_> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|e| e.unwrap().path())
        .collect();
    files.sort();
    assert!(!files.is_empty(), "no inputs in {}", dir.display());
    for path in files {
        let bytes = std::fs::read(&path).unwrap();
        let case = PacketCase::arbitrary_take_rest(Unstructured::new(&bytes))
            .unwrap_or_else(|e| panic!("{}: does not decode: {e}", path.display()));
        run_packet_case(&case);
    }
}
