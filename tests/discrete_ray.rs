//! Exactness of the discrete ray against an exact rational oracle, and the
//! shared invariant checkers on many seeded random rays.
//!
//! Every random case derives from a printed seed: a failure names the seed,
//! and `RRT_SEED=<seed> cargo test -p rrt-tests --test discrete_ray` replays
//! just that case first.

use rrt_core::check::{check_adaptive_matches_six, check_lattice_counts, check_skipping};
use rrt_core::discrete_ray::Connectivity;
use rrt_core::fixed::{VOXEL, voxel_centre};
use rrt_core::proximity::{coarse_extent, distance_field, flag_neighbourhood, line_distances};
use rrt_core::raster::{Extent, Raster, RasterMut, cell, line_count};
use rrt_tests::oracle::{Case, check_exact, make_ray};
use rrt_tests::{Rng, env_count, random_opaque, replay_seed};

const DIR_SCALES: [u32; 6] = [0, 1, 8, 16, 24, 31];

fn random_dir(rng: &mut Rng) -> [i32; 3] {
    let mut d = [0i32; 3];
    let kind = rng.below(10);
    for (k, slot) in d.iter_mut().enumerate() {
        let bits = DIR_SCALES[rng.below(DIR_SCALES.len() as u64) as usize];
        let mag = if bits == 0 {
            1
        } else {
            rng.range(0, (1i64 << bits) - 1)
        };
        let v = if rng.chance(1, 2) { -mag } else { mag };
        *slot = v.clamp(i64::from(i32::MIN), i64::from(i32::MAX)) as i32;
        // Axis-parallel and planar rays, and ±1 components.
        if kind == 0 && k != 0 || kind == 1 && k == 2 {
            *slot = 0;
        }
        if kind == 2 && rng.chance(1, 2) {
            *slot = if rng.chance(1, 2) { 1 } else { -1 };
        }
    }
    if kind == 0 {
        d.rotate_right(rng.below(3) as usize);
    }
    if kind == 3 {
        // Equal magnitudes: exact diagonals through edges and corners.
        let m = rng.range(1, 1 << 20) as i32;
        d = [0, 1, 2].map(|_| if rng.chance(1, 2) { m } else { -m });
    }
    d
}

fn random_coord(rng: &mut Rng, n: u32) -> i64 {
    let size = i64::from(n) * VOXEL;
    match rng.below(6) {
        0 => rng.range(0, size - 1),                       // inside, sub-voxel
        1 => rng.range(0, i64::from(n)) * VOXEL,           // on a voxel face
        2 => voxel_centre(rng.below(u64::from(n)) as u32), // a voxel centre
        3 => rng.range(-3 * size, 4 * size),               // around the box
        4 => {
            if rng.chance(1, 2) {
                0
            } else {
                size
            }
        } // on the box faces
        _ => rng.range(-(1i64 << 40), 1i64 << 40),         // far away
    }
}

fn random_case(rng: &mut Rng) -> Case {
    let dims = [0; 3].map(|_| {
        if rng.chance(1, 8) {
            1
        } else {
            1 + rng.below(24) as u32
        }
    });
    let origin = [0, 1, 2].map(|k| random_coord(rng, dims[k]));
    let segment = rng.chance(1, 3);
    let mut dir = random_dir(rng);
    if !segment && rng.chance(1, 2) {
        // Aim at a random point of the box (or near it), scaled up so the
        // direction keeps its precision.
        let target = [0, 1, 2].map(|k| random_coord(rng, dims[k]).clamp(-(1 << 33), 1 << 33));
        let mut d = [0, 1, 2].map(|k| (target[k] - origin[k]) as i128);
        let m = d.iter().map(|v| v.unsigned_abs()).max().unwrap_or(0).max(1);
        let shift = (1u128 << 30) / m;
        if shift > 1 && rng.chance(1, 2) {
            d = d.map(|v| v * shift as i128);
        } else if m >= 1 << 30 {
            let div = (m >> 30) as i128 + 1;
            d = d.map(|v| v / div);
        }
        let fits = d.iter().all(|v| i32::try_from(*v).is_ok());
        if fits {
            dir = d.map(|v| v as i32);
        }
    }
    if segment {
        // Segments of bounded length, sometimes aimed at lattice points.
        for (k, d) in dir.iter_mut().enumerate() {
            let span = i64::from(dims[k]) * VOXEL * 3;
            *d = if rng.chance(1, 4) {
                (random_coord(rng, dims[k]) - origin[k]).clamp(-span, span) as i32
            } else {
                rng.range(-span, span) as i32
            };
        }
        if rng.chance(1, 20) {
            dir = [0; 3]; // length 0
        }
    }
    Case {
        dims,
        origin,
        dir,
        segment,
    }
}

fn random_plane(rng: &mut Rng, len: usize) -> Vec<u8> {
    let density = rng.below(4);
    (0..len)
        .map(|_| {
            let mut c = 0u8;
            if rng.below(16) < density {
                c |= cell::OPAQUE;
            }
            if rng.chance(1, 3) {
                c |= cell::PROXIMITY;
            }
            c
        })
        .collect()
}

fn seed_of(i: u64) -> u64 {
    0x5EED_0000_0000_0000 ^ i.wrapping_mul(0x9E37_79B9_7F4A_7C15)
}

#[test]
fn random_rays_match_the_exact_oracle() {
    let n = env_count("RRT_RAYS").unwrap_or(100_000);
    let seeds = replay_seed().into_iter().chain((0..n).map(seed_of));
    let mut hit_rays = 0u64;
    for seed in seeds {
        let mut rng = Rng::new(seed);
        let case = random_case(&mut rng);
        let len = (case.dims[0] * case.dims[1] * case.dims[2]) as usize;
        let plane = random_plane(&mut rng, len);
        check_exact(&case, Some(&plane), &format!("seed {seed}"));
        if make_ray(&case).is_some() {
            hit_rays += 1;
        }
    }
    // Guard against a generator that only produces misses.
    assert!(
        hit_rays > n / 4,
        "only {hit_rays} of {n} random rays entered the raster"
    );
}

#[test]
fn random_rays_adaptive_hits_equal_six_hits_with_proximity_flags() {
    for i in 0..20_000u64 {
        let seed = seed_of(i) ^ 0xADA;
        let mut rng = Rng::new(seed);
        let case = random_case(&mut rng);
        let e = Extent::new(case.dims[0], case.dims[1], case.dims[2]).unwrap();
        let density = 1 + rng.below(40);
        let mut plane = random_opaque(&mut rng, e.len(), density, 400);
        let mut rm = RasterMut::new(e, &mut plane).unwrap();
        flag_neighbourhood(&mut rm);
        let r = rm.as_raster();
        if let Some(ray) = make_ray(&case)
            && let Err(v) = check_adaptive_matches_six(&r, &ray)
        {
            panic!("seed {seed}: {v:?}, {case:?}");
        }
    }
}

/// The hand-made hard cases of the issue, on a 9×7×5 raster and on big ones.
#[test]
fn hard_cases() {
    let dims = [9u32, 7, 5];
    let e = Extent::new(dims[0], dims[1], dims[2]).unwrap();
    let mut rng = Rng::new(42);
    let plane = random_plane(&mut rng, e.len());
    let size = dims.map(|n| i64::from(n) * VOXEL);
    let mut cases = Vec::new();
    // Interesting coordinates per axis: faces, edges, centres, just off them.
    let spots = |k: usize| {
        vec![
            0,
            1,
            VOXEL - 1,
            VOXEL,
            VOXEL + 1,
            voxel_centre(2),
            3 * VOXEL,
            size[k] - 1,
            size[k],
            size[k] + 1,
            -1,
            -VOXEL,
        ]
    };
    let dirs: Vec<[i32; 3]> = {
        let mut v = Vec::new();
        for d in [[1, 0, 0], [0, 1, 0], [0, 0, 1]] {
            v.push(d);
            v.push(d.map(|x| -x));
        }
        for (a, b) in [(0, 1), (0, 2), (1, 2)] {
            for (sa, sb) in [(1, 1), (1, -1), (-1, 1), (-1, -1), (3, 1), (1, 5)] {
                let mut d = [0; 3];
                d[a] = sa * 65536;
                d[b] = sb * 65536;
                v.push(d);
            }
        }
        for s in [[1, 1, 1], [1, -1, 1], [-1, -1, -1], [1, 1, -1]] {
            v.push(s.map(|x| x * 65536));
            v.push(s); // ±1 unit of the last fractional bit
        }
        v.push([65536, 1, -1]);
        v.push([1, 65536, 1]);
        v.push([-1, 1, 1 << 30]);
        v.push([0, 0, 0]);
        v.push([i32::MAX, i32::MIN, 1]);
        v
    };
    let (sx, sy, sz) = (spots(0), spots(1), spots(2));
    for &x in &sx {
        for &y in &sy {
            for &z in sz.iter().step_by(3) {
                for d in &dirs {
                    cases.push(Case {
                        dims,
                        origin: [x, y, z],
                        dir: *d,
                        segment: false,
                    });
                }
            }
        }
    }
    // Segments between lattice points, and of length zero.
    for _ in 0..2000 {
        let a = [0, 1, 2].map(|k| rng.range(0, i64::from(dims[k])) * VOXEL);
        let b = [0, 1, 2].map(|k| rng.range(0, i64::from(dims[k])) * VOXEL);
        let dir = [0, 1, 2].map(|k| (b[k] - a[k]) as i32);
        cases.push(Case {
            dims,
            origin: a,
            dir,
            segment: true,
        });
        cases.push(Case {
            dims,
            origin: a,
            dir: [0, 0, 0],
            segment: true,
        });
    }
    for (i, c) in cases.iter().enumerate() {
        check_exact(c, Some(&plane), &format!("hard case {i}"));
    }
    // Lattice endpoints: the paper's n6 and n26.
    let r = Raster::new(e, &plane).unwrap();
    for _ in 0..2000 {
        let a = [0, 1, 2].map(|k| rng.below(u64::from(dims[k])) as u32);
        let b = [0, 1, 2].map(|k| rng.below(u64::from(dims[k])) as u32);
        check_lattice_counts(&r, a, b).unwrap_or_else(|v| panic!("{a:?} -> {b:?}: {v:?}"));
    }
}

/// Full diagonals of 4096-long rasters: the 4096³ raster (64 GiB of plane)
/// is walked as an empty raster, without a plane, against the oracle; a
/// 4096 × 4096 × 8 raster with a real (zeroed) plane runs the checkers too.
#[test]
fn full_diagonals_of_4096_rasters() {
    let n = 4096 * VOXEL;
    for (origin, dir, segment) in [
        ([0, 0, 0], [1, 1, 1], false),
        ([n - 1, n - 1, n - 1], [-1, -1, -1], false),
        ([-5, -7, -11], [65536, 65535, 65537], false),
        ([0, n, 0], [1, -1, 1], false),
        ([0, 0, 0], [(n - 1) as i32; 3], true),
        (
            [n - 1, 0, n - 1],
            [-(n - 1) as i32, (n - 1) as i32, -(n - 1) as i32],
            true,
        ),
    ] {
        let case = Case {
            dims: [4096; 3],
            origin,
            dir,
            segment,
        };
        check_exact(&case, None, "4096³ diagonal");
        let ray = make_ray(&case).unwrap();
        assert_eq!(ray.path(Connectivity::Six).count(), 3 * 4095 + 1);
        assert_eq!(ray.path(Connectivity::TwentySix).count(), 4096);
    }
    let dims = [4096u32, 4096, 8];
    let e = Extent::new(dims[0], dims[1], dims[2]).unwrap();
    let plane = vec![0u8; e.len()];
    let far = dims.map(|n| i64::from(n) * VOXEL);
    for segment in [false, true] {
        let dir = [0, 1, 2].map(|k| (far[k] - 1) as i32);
        check_exact(
            &Case {
                dims,
                origin: [0, 0, 0],
                dir,
                segment,
            },
            Some(&plane),
            "4096 diagonal",
        );
        let dir = [0, 1, 2].map(|k| -((far[k] - 1) as i32));
        check_exact(
            &Case {
                dims,
                origin: far.map(|f| f - 1),
                dir,
                segment,
            },
            Some(&plane),
            "4096 diagonal back",
        );
    }
}

/// Skipping through the proximity distances finds the same hits, faces and
/// resume states as plain walking, on sparse random rasters big enough for
/// long jumps.
#[test]
fn skipping_changes_nothing_but_the_step_count() {
    let (mut plain_steps, mut skipping_steps, mut line_steps) = (0u64, 0u64, 0u64);
    for i in 0..4_000u64 {
        let seed = seed_of(i) ^ 0x5_1C1F;
        let mut rng = Rng::new(seed);
        let mut case = random_case(&mut rng);
        // Larger rasters than the oracle test's, so that distances reach 63.
        case.dims = case.dims.map(|d| d * 4);
        let e = Extent::new(case.dims[0], case.dims[1], case.dims[2]).unwrap();
        let per_100k = rng.below(40);
        let mut plane = random_opaque(&mut rng, e.len(), per_100k, 100_000);
        let mut rm = RasterMut::new(e, &mut plane).unwrap();
        distance_field(&mut rm);
        let r = rm.as_raster();
        let mut lines = vec![0u8; line_count(e.len())];
        let mut bricks = vec![0u8; coarse_extent(e).unwrap().len()];
        line_distances(&r, &mut bricks, &mut lines).unwrap();
        let rl = r.with_lines(&lines).unwrap();
        let Some(ray) = make_ray(&case) else { continue };
        for (raster, what) in [(r, "plane"), (rl, "line level")] {
            for mode in Connectivity::ALL {
                if let Err(v) = check_skipping(&raster, &ray, mode) {
                    panic!("seed {seed} {mode:?} ({what}): {v:?}, {case:?}");
                }
            }
        }
        let (mut a, mut b, mut c) = (ray, ray, ray);
        a.first_hit(&r, Connectivity::Adaptive).unwrap();
        b.first_hit_skipping(&r, Connectivity::Adaptive).unwrap();
        c.first_hit_skipping(&rl, Connectivity::Adaptive).unwrap();
        plain_steps += u64::from(a.steps());
        skipping_steps += u64::from(b.steps());
        line_steps += u64::from(c.steps());
    }
    // Guard against a generator whose rays never get to jump (the plane
    // alone jumps only near surfaces, where the field stores distances;
    // the line level far from them too).
    println!(
        "adaptive first hits: {plain_steps} steps plain, {skipping_steps} skipping, \
         {line_steps} skipping through the line level"
    );
    assert!(
        plain_steps > skipping_steps + skipping_steps / 2 && plain_steps > 4 * line_steps,
        "skipping saved too little: {plain_steps} vs {skipping_steps} / {line_steps} steps"
    );
}
