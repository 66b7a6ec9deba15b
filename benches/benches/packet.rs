//! Rays per second of `RayPacket8` against the scalar discrete ray on the
//! same rays, in all three connectivities, walking plainly (every voxel)
//! and with empty-space skipping on both sides (the renderer's walk).
//!
//! Scene: a sphereflake built like SPD's `balls` at depth 4 (7381 solid
//! spheres, each with nine children of a third its radius; generated here
//! so that the bench needs neither `../shared/data` nor the host's
//! pipeline, and without balls4's floor polygon, so that every ray's walk
//! is decided by spheres), voxelized into a raster of 512 and of 1024
//! voxels along its longest axis, with proximity flags and the distance
//! field from `distance_field` and the line level from `line_distances`,
//! as the renderer's raster has them (the field writes every cell, so every
//! page of the plane is touched before timing: no calloc'ed zero pages).
//! The renderer's end-to-end comparison on the real `balls4.nff` is in the
//! README.
//!
//! Rays: coherent primary rays of a 512² camera in 4×2 pixel blocks (one
//! block = one packet), and incoherent rays (random origins in empty voxels,
//! random directions), also sorted by driving axis and signs. Each walk is
//! `first_hit` or `first_hit_skipping` (the first OPAQUE voxel); ray setup
//! is not timed (rays and packets are built beforehand and copied per
//! walk).
//!
//! Besides criterion's groups, the bench first prints a table of rays/s and
//! packet/scalar ratios measured in this one run, scalar and packet timed
//! alternately (best of several rounds each), and checks that both found
//! the same hits.
//!
//!     cargo bench -p rrt-benches --bench packet
//!     RUSTFLAGS="-C target-cpu=native" cargo bench -p rrt-benches --bench packet
//!
//! `RRT_BENCH_SIZES=512`, `RRT_BENCH_SETS=coherent,random,sorted`,
//! `RRT_BENCH_MODES=six,twenty-six,adaptive` and
//! `RRT_BENCH_WALKS=plain,skipping` limit what runs,
//! `RRT_BENCH_TABLE_ONLY=1` skips criterion.

use rrt_core::rng::Rng;
use std::hint::black_box;
use std::time::{Duration, Instant};

use criterion::{BenchmarkId, Criterion, Throughput};
use rrt_core::discrete_ray::{Connectivity, DiscreteRay};
use rrt_core::fixed::VOXEL;
use rrt_core::packet::{LANES, RayPacket8};
use rrt_core::proximity::{coarse_extent, distance_field, line_distances};
use rrt_core::raster::{Extent, Raster, RasterMut, cell, line_count};

/// A sphere in scene units.
#[derive(Clone, Copy, Debug)]
struct Sphere {
    c: [f64; 3],
    r: f64,
}

fn add(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}
fn scale(a: [f64; 3], s: f64) -> [f64; 3] {
    a.map(|v| v * s)
}
fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}
fn norm(a: [f64; 3]) -> [f64; 3] {
    let l = (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt();
    scale(a, 1.0 / l)
}

/// A sphereflake: a sphere with nine children of a third its radius on its
/// surface (six around the equator, three above), recursively, `depth`
/// levels below the root (depth 4: 7381 spheres, like SPD `balls`).
fn sphereflake(depth: u32) -> Vec<Sphere> {
    fn grow(out: &mut Vec<Sphere>, s: Sphere, up: [f64; 3], depth: u32) {
        out.push(s);
        if depth == 0 {
            return;
        }
        let side = if up[0].abs() < 0.9 {
            [1.0, 0.0, 0.0]
        } else {
            [0.0, 1.0, 0.0]
        };
        let u = norm(cross(up, side));
        let v = cross(up, u);
        let r = s.r / 3.0;
        for i in 0..9 {
            let (az, el): (f64, f64) = if i < 6 {
                (f64::from(i) * std::f64::consts::FRAC_PI_3, 0.0)
            } else {
                (
                    f64::from(i - 6) * 2.0 * std::f64::consts::FRAC_PI_3 + 0.5,
                    0.95,
                )
            };
            let dir = norm(add(
                add(scale(u, az.cos() * el.cos()), scale(v, az.sin() * el.cos())),
                scale(up, el.sin()),
            ));
            let child = Sphere {
                c: add(s.c, scale(dir, s.r + r)),
                r,
            };
            grow(out, child, dir, depth - 1);
        }
    }
    let mut out = Vec::new();
    grow(
        &mut out,
        Sphere {
            c: [0.0; 3],
            r: 1.0,
        },
        [0.0, 0.0, 1.0],
        depth,
    );
    out
}

/// A voxelized scene.
struct Scene {
    n: u32,
    extent: Extent,
    plane: Vec<u8>,
    /// The line level of the plane.
    lines: Vec<u8>,
    /// Scene units → voxels: `voxel = (p - lo) * k`.
    lo: [f64; 3],
    k: f64,
}

fn voxelize(spheres: &[Sphere], n: u32) -> Scene {
    let mut lo = [f64::MAX; 3];
    let mut hi = [f64::MIN; 3];
    for s in spheres {
        for a in 0..3 {
            lo[a] = lo[a].min(s.c[a] - s.r);
            hi[a] = hi[a].max(s.c[a] + s.r);
        }
    }
    let longest = (0..3).map(|a| hi[a] - lo[a]).fold(0.0, f64::max);
    let k = f64::from(n) / longest;
    let dims = [0, 1, 2].map(|a| (((hi[a] - lo[a]) * k).ceil() as u32).clamp(1, n));
    let extent = Extent::new(dims[0], dims[1], dims[2]).unwrap();
    let mut plane = vec![cell::EMPTY; extent.len()];
    for s in spheres {
        let c = [0, 1, 2].map(|a| (s.c[a] - lo[a]) * k);
        let r = s.r * k;
        let lo_v = c.map(|v| ((v - r).floor().max(0.0)) as u32);
        let hi_v = [0, 1, 2].map(|a| ((c[a] + r).ceil() as u32).min(dims[a] - 1));
        for z in lo_v[2]..=hi_v[2] {
            for y in lo_v[1]..=hi_v[1] {
                for x in lo_v[0]..=hi_v[0] {
                    let p = [x, y, z].map(|v| f64::from(v) + 0.5);
                    let d2: f64 = (0..3).map(|a| (p[a] - c[a]).powi(2)).sum();
                    if d2 <= r * r {
                        plane[extent.index([x, y, z]).unwrap()] = cell::OPAQUE;
                    }
                }
            }
        }
    }
    // Writes every cell: every page of the plane is touched.
    distance_field(&mut RasterMut::new(extent, &mut plane).unwrap());
    let mut lines = vec![0; line_count(plane.len())];
    let mut bricks = vec![0; coarse_extent(extent).unwrap().len()];
    line_distances(
        &Raster::new(extent, &plane).unwrap(),
        &mut bricks,
        &mut lines,
    )
    .unwrap();
    Scene {
        n,
        extent,
        plane,
        lines,
        lo,
        k,
    }
}

/// A direction scaled so that its largest component is about 2^30.
fn fixed_dir(d: [f64; 3]) -> [i32; 3] {
    let m = d.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    d.map(|v| (v / m * f64::from(1 << 30)).round() as i32)
}

fn fixed_point(p: [f64; 3]) -> [i64; 3] {
    p.map(|v| (v * VOXEL as f64).round() as i64)
}

/// Primary rays of a `w`×`h` camera, in 4×2 pixel blocks of eight rays.
fn camera_rays(scene: &Scene, w: u32, h: u32) -> Vec<([i64; 3], [i32; 3])> {
    let to_vox = |p: [f64; 3]| [0, 1, 2].map(|a| (p[a] - scene.lo[a]) * scene.k);
    let eye = to_vox([2.1, 2.8, 1.7]);
    let at = to_vox([0.0, 0.0, 0.0]);
    let fwd = norm([at[0] - eye[0], at[1] - eye[1], at[2] - eye[2]]);
    let right = norm(cross(fwd, [0.0, 0.0, 1.0]));
    let up = cross(right, fwd);
    let half = (22.0f64).to_radians().tan();
    let origin = fixed_point(eye);
    let mut rays = Vec::with_capacity((w * h) as usize);
    for by in (0..h).step_by(2) {
        for bx in (0..w).step_by(4) {
            for dy in 0..2 {
                for dx in 0..4 {
                    let (px, py) = (bx + dx, by + dy);
                    let sx = (2.0 * (f64::from(px) + 0.5) / f64::from(w) - 1.0) * half;
                    let sy = (1.0 - 2.0 * (f64::from(py) + 0.5) / f64::from(h)) * half;
                    let d = add(add(fwd, scale(right, sx)), scale(up, sy));
                    rays.push((origin, fixed_dir(d)));
                }
            }
        }
    }
    rays
}

/// Random rays from random points of empty voxels in random directions.
fn random_rays(scene: &Scene, count: usize, seed: u64) -> Vec<([i64; 3], [i32; 3])> {
    let mut rng = Rng(seed);
    let dims = scene.extent.dims();
    let mut rays = Vec::with_capacity(count);
    while rays.len() < count {
        let o = dims.map(|n| (rng.next_u64() % (u64::from(n) << 16)) as i64);
        let v = o.map(|c| (c >> 16) as u32);
        if scene.plane[scene.extent.index(v).unwrap()] & cell::OPAQUE != 0 {
            continue;
        }
        let d = [0; 3].map(|_| (rng.next_u64() >> 33) as i32 - (1 << 30));
        if d == [0; 3] {
            continue;
        }
        rays.push((o, d));
    }
    rays
}

/// The same rays with their frames grouped: sorted by driving axis and the
/// signs of the direction.
fn sorted_by_frame(rays: &[([i64; 3], [i32; 3])]) -> Vec<([i64; 3], [i32; 3])> {
    let mut out = rays.to_vec();
    out.sort_by_key(|(_, d)| {
        let a = d.map(|v| v.unsigned_abs());
        let drive = if a[1] > a[0] {
            if a[2] > a[1] { 2 } else { 1 }
        } else if a[2] > a[0] {
            2
        } else {
            0
        };
        let signs = d.map(|v| u32::from(v < 0));
        drive * 8 + signs[0] * 4 + signs[1] * 2 + signs[2]
    });
    out
}

/// Rays set up for both steppers.
struct RaySet {
    name: &'static str,
    rays: Vec<DiscreteRay>,
    packets: Vec<RayPacket8>,
    count: u64,
}

fn ray_set(name: &'static str, scene: &Scene, rays: &[([i64; 3], [i32; 3])]) -> RaySet {
    let mut scalar = Vec::new();
    let mut packets = Vec::new();
    for chunk in rays.chunks(LANES) {
        let mut lanes = [None; LANES];
        for (slot, &(o, d)) in lanes.iter_mut().zip(chunk) {
            *slot = DiscreteRay::new(scene.extent, o, d).unwrap();
        }
        scalar.extend(lanes.iter().flatten().copied());
        packets.push(RayPacket8::from_rays(scene.extent, lanes).unwrap());
    }
    RaySet {
        name,
        count: scalar.len() as u64,
        rays: scalar,
        packets,
    }
}

/// Every voxel (`plain`), or skipping empty space.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Walk {
    Plain,
    Skipping,
}

impl Walk {
    fn name(self) -> &'static str {
        match self {
            Walk::Plain => "plain",
            Walk::Skipping => "skipping",
        }
    }

    fn scalar(
        self,
        ray: &mut DiscreteRay,
        raster: &Raster<'_>,
        mode: Connectivity,
    ) -> Option<rrt_core::discrete_ray::Hit> {
        match self {
            Walk::Plain => ray.first_hit(raster, mode),
            Walk::Skipping => ray.first_hit_skipping(raster, mode),
        }
        .unwrap()
    }

    fn packet(self, p: &mut RayPacket8, raster: &Raster<'_>, mode: Connectivity) -> u8 {
        match self {
            Walk::Plain => p.first_hit(raster, mode),
            Walk::Skipping => p.first_hit_skipping(raster, mode),
        }
        .unwrap()
    }
}

/// First hits of every ray, one at a time; a checksum of the hits.
fn walk_scalar(raster: &Raster<'_>, rays: &[DiscreteRay], mode: Connectivity, walk: Walk) -> u64 {
    let mut sum = 0u64;
    for ray in rays {
        let mut r = *ray;
        if let Some(h) = walk.scalar(&mut r, raster, mode) {
            sum = sum.wrapping_add(h.index as u64 ^ u64::from(h.steps) << 40);
        }
    }
    sum
}

/// First hits of every ray, eight at a time; the same checksum.
fn walk_packets(
    raster: &Raster<'_>,
    packets: &[RayPacket8],
    mode: Connectivity,
    walk: Walk,
) -> u64 {
    let mut sum = 0u64;
    for packet in packets {
        let mut p = packet.clone();
        let hits = walk.packet(&mut p, raster, mode);
        for lane in 0..LANES {
            if hits & (1 << lane) != 0 {
                let h = p.hit(lane).unwrap();
                sum = sum.wrapping_add(h.index as u64 ^ u64::from(h.steps) << 40);
            }
        }
    }
    sum
}

/// Voxels visited by the scalar rays (a jump visits one).
fn visits(raster: &Raster<'_>, rays: &[DiscreteRay], mode: Connectivity, walk: Walk) -> u64 {
    rays.iter()
        .map(|ray| {
            let mut r = *ray;
            let _ = walk.scalar(&mut r, raster, mode);
            u64::from(r.steps())
        })
        .sum()
}

fn best_of(rounds: u32, mut f: impl FnMut() -> u64) -> (Duration, u64) {
    let mut best = Duration::MAX;
    let mut sum = 0;
    for _ in 0..rounds {
        let t = Instant::now();
        sum = black_box(f());
        best = best.min(t.elapsed());
    }
    (best, sum)
}

fn table(scenes: &[(Scene, Vec<RaySet>)]) {
    println!(
        "| raster | rays | mode | walk | voxels/ray | scalar Mrays/s | packet Mrays/s | packet/scalar |"
    );
    println!("|---|---|---|---|---|---|---|---|");
    for (scene, sets) in scenes {
        let raster = raster_of(scene);
        for set in sets {
            for (mode, walk) in modes()
                .into_iter()
                .flat_map(|m| walks().into_iter().map(move |w| (m, w)))
            {
                // Alternate the two, so that noise from other processes
                // hits both alike; best of the rounds.
                let mut ts = Duration::MAX;
                let mut tp = Duration::MAX;
                let (mut cs, mut cp) = (0, 0);
                for _ in 0..4 {
                    let (t, c) = best_of(1, || walk_scalar(&raster, &set.rays, mode, walk));
                    ts = ts.min(t);
                    cs = c;
                    let (t, c) = best_of(1, || walk_packets(&raster, &set.packets, mode, walk));
                    tp = tp.min(t);
                    cp = c;
                }
                assert_eq!(cs, cp, "packet and scalar hits differ");
                let per_ray = visits(&raster, &set.rays, mode, walk) as f64 / set.count as f64;
                let rs = set.count as f64 / ts.as_secs_f64() / 1e6;
                let rp = set.count as f64 / tp.as_secs_f64() / 1e6;
                println!(
                    "| {}³-ish ({:?}) | {} | {} | {} | {:.0} | {:.3} | {:.3} | {:.2}× |",
                    scene.n,
                    scene.extent.dims(),
                    set.name,
                    mode.name(),
                    walk.name(),
                    per_ray,
                    rs,
                    rp,
                    rp / rs
                );
            }
        }
    }
}

/// The modes to run (`RRT_BENCH_MODES=six,adaptive`; default all three).
fn modes() -> Vec<Connectivity> {
    let want = std::env::var("RRT_BENCH_MODES").unwrap_or_default();
    Connectivity::ALL
        .into_iter()
        .filter(|m| want.is_empty() || want.split(',').any(|w| w.trim() == m.name()))
        .collect()
}

/// The walks to run (`RRT_BENCH_WALKS=plain,skipping`; default both).
fn walks() -> Vec<Walk> {
    let want = std::env::var("RRT_BENCH_WALKS").unwrap_or_default();
    [Walk::Plain, Walk::Skipping]
        .into_iter()
        .filter(|w| want.is_empty() || want.split(',').any(|x| x.trim() == w.name()))
        .collect()
}

/// The scene's raster with its line level.
fn raster_of(scene: &Scene) -> Raster<'_> {
    Raster::new(scene.extent, &scene.plane)
        .unwrap()
        .with_lines(&scene.lines)
        .unwrap()
}

fn main() {
    let sizes: Vec<u32> = std::env::var("RRT_BENCH_SIZES")
        .ok()
        .map(|s| s.split(',').filter_map(|v| v.trim().parse().ok()).collect())
        .unwrap_or_else(|| vec![512, 1024]);
    let flake = sphereflake(4);
    let mut scenes = Vec::new();
    for &n in &sizes {
        let t = Instant::now();
        let scene = voxelize(&flake, n);
        let opaque = scene
            .plane
            .iter()
            .filter(|&&c| c & cell::OPAQUE != 0)
            .count();
        eprintln!(
            "sphereflake: {} spheres in {:?} voxels, {:.1}% opaque, built in {:.1?}",
            flake.len(),
            scene.extent.dims(),
            100.0 * opaque as f64 / scene.plane.len() as f64,
            t.elapsed()
        );
        let camera = camera_rays(&scene, 512, 512);
        let random = random_rays(&scene, 1 << 16, 0x5EED ^ u64::from(n));
        let want = std::env::var("RRT_BENCH_SETS").unwrap_or_default();
        let sets: Vec<RaySet> = [
            ("coherent", "coherent 512² camera, 4×2 blocks", camera),
            ("random", "incoherent random", random.clone()),
            (
                "sorted",
                "incoherent, sorted by frame",
                sorted_by_frame(&random),
            ),
        ]
        .into_iter()
        .filter(|(key, _, _)| want.is_empty() || want.split(',').any(|w| w.trim() == *key))
        .map(|(_, name, rays)| ray_set(name, &scene, &rays))
        .collect();
        scenes.push((scene, sets));
    }
    table(&scenes);
    if std::env::var_os("RRT_BENCH_TABLE_ONLY").is_some() {
        return;
    }

    let mut c = Criterion::default()
        .sample_size(10)
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(4))
        .configure_from_args();
    for (scene, sets) in &scenes {
        let raster = raster_of(scene);
        for set in sets {
            let mut g = c.benchmark_group(format!("packet/{}/{}", scene.n, set.name));
            g.throughput(Throughput::Elements(set.count));
            for mode in modes() {
                for walk in walks() {
                    let id = format!("{}/{}", mode.name(), walk.name());
                    g.bench_with_input(BenchmarkId::new("scalar", &id), &mode, |b, &m| {
                        b.iter(|| walk_scalar(&raster, &set.rays, m, walk));
                    });
                    g.bench_with_input(BenchmarkId::new("packet", &id), &mode, |b, &m| {
                        b.iter(|| walk_packets(&raster, &set.packets, m, walk));
                    });
                }
            }
            g.finish();
        }
    }
    c.final_summary();
}
