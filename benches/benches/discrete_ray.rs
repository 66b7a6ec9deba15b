//! Discrete ray traversal: rrt's Six, TwentySix and Adaptive rays against a
//! float Amanatides & Woo, `line_drawing`'s `WalkVoxels` and `Bresenham3d`,
//! and a hand-written integer 3D Bresenham, on the same rays through the
//! same raster, in one run.
//!
//! ```text
//! cargo bench -p rrt-benches --bench discrete_ray            # ratio table + criterion
//! cargo bench -p rrt-benches --bench discrete_ray -- --table # ratio table only
//! ```
//!
//! Rasters: `dda_bench`'s default scene (1000 random solid spheres of radius
//! 10·N/256, seeded) at N = 256 and 512, with proximity flags for Adaptive,
//! every page of the plane written (RSS printed). Ray sets: 512×512 pinhole
//! camera rays (coherent) and 200 000 random rays from the box faces
//! (incoherent). Every ray stops at its first opaque voxel. rrt's figures
//! include the per-ray setup (exact integer clipping), as the baselines
//! include theirs.

use std::hint::black_box;
use std::time::{Duration, Instant};

use criterion::{BenchmarkId, Criterion, Throughput};
use rrt_benches::{
    BenchRaster, BenchRay, DDA_BENCH_SEED, Rng, Trace, baseline, camera_rays, random_rays, rss_mib,
};
use rrt_core::discrete_ray::{Connectivity, DiscreteRay};
use rrt_core::proximity::distance_field;
use rrt_core::raster::{Raster, RasterMut};

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Algo {
    Rrt(Connectivity),
    /// rrt with proximity-distance skipping, on the same raster.
    RrtSkip(Connectivity),
    AmanatidesWoo,
    WalkVoxels,
    Bresenham3d,
    IntBresenham,
}

const ALGOS: [Algo; 9] = [
    Algo::Rrt(Connectivity::Six),
    Algo::Rrt(Connectivity::TwentySix),
    Algo::Rrt(Connectivity::Adaptive),
    Algo::RrtSkip(Connectivity::TwentySix),
    Algo::RrtSkip(Connectivity::Adaptive),
    Algo::AmanatidesWoo,
    Algo::WalkVoxels,
    Algo::Bresenham3d,
    Algo::IntBresenham,
];

impl Algo {
    fn name(self) -> &'static str {
        match self {
            Self::Rrt(Connectivity::Six) => "rrt six",
            Self::Rrt(Connectivity::TwentySix) => "rrt twenty-six",
            Self::Rrt(Connectivity::Adaptive) => "rrt adaptive",
            Self::RrtSkip(Connectivity::TwentySix) => "rrt 26 + skip",
            Self::RrtSkip(_) => "rrt ada + skip",
            Self::AmanatidesWoo => "float A&W",
            Self::WalkVoxels => "ld WalkVoxels",
            Self::Bresenham3d => "ld Bresenham3d",
            Self::IntBresenham => "int Bresenham",
        }
    }
}

/// Traces every ray of `rays`; returns the per-ray results' totals.
#[inline(never)]
fn run(
    algo: Algo,
    raster: &Raster<'_>,
    n: u32,
    rays: &[BenchRay],
    hits: Option<&mut Vec<Option<usize>>>,
) -> (u64, u64) {
    let plane = raster.plane();
    let extent = raster.extent();
    let mut steps = 0u64;
    let mut nhits = 0u64;
    let mut record = hits;
    let mut each = |t: Trace| {
        steps += t.steps;
        nhits += u64::from(t.hit.is_some());
        if let Some(h) = record.as_deref_mut() {
            h.push(t.hit);
        }
    };
    match algo {
        Algo::Rrt(mode) | Algo::RrtSkip(mode) => {
            let skip = matches!(algo, Algo::RrtSkip(_));
            for r in rays {
                let Some(mut ray) = r.discrete(extent) else {
                    each(Trace::default());
                    continue;
                };
                let hit = if skip {
                    ray.first_hit_skipping(raster, mode)
                } else {
                    ray.first_hit(raster, mode)
                };
                each(Trace {
                    steps: u64::from(ray.steps()),
                    hit: hit.ok().flatten().map(|h| h.index),
                });
            }
        }
        Algo::AmanatidesWoo | Algo::WalkVoxels | Algo::Bresenham3d | Algo::IntBresenham => {
            let f = match algo {
                Algo::AmanatidesWoo => baseline::amanatides_woo,
                Algo::WalkVoxels => baseline::line_drawing_walk,
                Algo::Bresenham3d => baseline::line_drawing_bresenham,
                _ => baseline::integer_bresenham,
            };
            for r in rays {
                if r.in_box() {
                    each(f(plane, n, r));
                } else {
                    each(Trace::default());
                }
            }
        }
    }
    (steps, nhits)
}

struct Row {
    algo: Algo,
    secs: f64,
    steps: u64,
    hits: u64,
    agree: f64,
}

fn table(n: u32, set: &str, raster: &Raster<'_>, rays: &[BenchRay], rounds: usize) -> Vec<Row> {
    // Correctness first: hits of each algorithm against A&W.
    let mut reference = Vec::new();
    run(Algo::AmanatidesWoo, raster, n, rays, Some(&mut reference));
    let mut rows: Vec<Row> = ALGOS
        .iter()
        .map(|&algo| {
            let mut hits = Vec::new();
            let (steps, nhits) = run(algo, raster, n, rays, Some(&mut hits));
            let same = hits.iter().zip(&reference).filter(|(a, b)| a == b).count();
            Row {
                algo,
                secs: f64::INFINITY,
                steps,
                hits: nhits,
                agree: same as f64 / rays.len() as f64,
            }
        })
        .collect();
    // Timing: interleaved rounds, median per algorithm.
    let mut times: Vec<Vec<f64>> = vec![Vec::new(); rows.len()];
    for _ in 0..rounds {
        for (i, row) in rows.iter().enumerate() {
            let t = Instant::now();
            black_box(run(row.algo, raster, n, black_box(rays), None));
            times[i].push(t.elapsed().as_secs_f64());
        }
    }
    for (row, t) in rows.iter_mut().zip(&mut times) {
        t.sort_by(f64::total_cmp);
        row.secs = t[t.len() / 2];
    }
    let nrays = rays.len() as f64;
    println!(
        "\n{n}^3, {set} rays ({} rays, median of {rounds} interleaved rounds)",
        rays.len()
    );
    println!(
        "{:<15} {:>9} {:>9} {:>10} {:>8} {:>10}",
        "algorithm", "Mrays/s", "Msteps/s", "steps/ray", "hit%", "same hit as A&W"
    );
    for r in &rows {
        println!(
            "{:<15} {:>9.3} {:>9.1} {:>10.1} {:>7.2}% {:>9.2}%",
            r.algo.name(),
            nrays / r.secs * 1e-6,
            r.steps as f64 / r.secs * 1e-6,
            r.steps as f64 / nrays,
            100.0 * r.hits as f64 / nrays,
            100.0 * r.agree
        );
    }
    let speed = |a: Algo| {
        rows.iter()
            .find(|r| r.algo == a)
            .map_or(f64::NAN, |r| nrays / r.secs)
    };
    let ratio = |a: Algo, b: Algo| speed(a) / speed(b);
    let (six, tws, ada) = (
        Algo::Rrt(Connectivity::Six),
        Algo::Rrt(Connectivity::TwentySix),
        Algo::Rrt(Connectivity::Adaptive),
    );
    println!(
        "ratios (rays/s): twenty-six / int Bresenham {:.2}, / ld Bresenham3d {:.2}, / float A&W {:.2}; \
         six / float A&W {:.2}, / ld WalkVoxels {:.2}; adaptive / float A&W {:.2}; \
         with skipping: twenty-six / float A&W {:.2}, adaptive / float A&W {:.2}",
        ratio(tws, Algo::IntBresenham),
        ratio(tws, Algo::Bresenham3d),
        ratio(tws, Algo::AmanatidesWoo),
        ratio(six, Algo::AmanatidesWoo),
        ratio(six, Algo::WalkVoxels),
        ratio(ada, Algo::AmanatidesWoo),
        ratio(Algo::RrtSkip(Connectivity::TwentySix), Algo::AmanatidesWoo),
        ratio(Algo::RrtSkip(Connectivity::Adaptive), Algo::AmanatidesWoo),
    );
    rows
}

struct Scene {
    n: u32,
    raster: BenchRaster,
    camera: Vec<BenchRay>,
    random: Vec<BenchRay>,
}

fn scene(n: u32) -> Scene {
    let mut rng = Rng::new(DDA_BENCH_SEED);
    let before = rss_mib().unwrap_or(0.0);
    let mut raster = BenchRaster::random_spheres(n, 1000, &mut rng);
    let extent = raster.extent();
    // Proximity distances (and the proximity flags, the same as
    // flag_neighbourhood's): Adaptive reads the flags, skipping the distances.
    distance_field(&mut RasterMut::new(extent, &mut raster.plane).expect("plane"));
    let after = rss_mib().unwrap_or(0.0);
    println!(
        "\nraster {n}^3: 1000 random solid spheres r = {:.1}, {:.2}% occupied; every page written (RSS +{:.0} MiB for a {:.0} MiB plane)",
        10.0 * f64::from(n) / 256.0,
        100.0 * raster.occupied as f64 / raster.plane.len() as f64,
        after - before,
        raster.plane.len() as f64 / 1_048_576.0
    );
    let camera = camera_rays(n, 512);
    let random = random_rays(n, 200_000, &mut rng);
    Scene {
        n,
        raster,
        camera,
        random,
    }
}

fn criterion_groups(c: &mut Criterion, s: &Scene) {
    let raster = Raster::new(s.raster.extent(), &s.raster.plane).expect("raster");
    let extent = raster.extent();
    let sample: Vec<BenchRay> = s.camera.iter().step_by(64).copied().collect();
    let mut g = c.benchmark_group(format!("setup/{}", s.n));
    g.throughput(Throughput::Elements(sample.len() as u64));
    g.bench_function("DiscreteRay::new", |b| {
        b.iter(|| {
            for r in &sample {
                black_box(
                    DiscreteRay::new(extent, black_box(r.origin_fx), black_box(r.dir_fx)).ok(),
                );
            }
        });
    });
    g.finish();
    let mut g = c.benchmark_group(format!("camera/{}", s.n));
    g.throughput(Throughput::Elements(sample.len() as u64));
    g.sample_size(20)
        .measurement_time(Duration::from_secs(2))
        .warm_up_time(Duration::from_millis(500));
    for algo in ALGOS {
        g.bench_with_input(
            BenchmarkId::from_parameter(algo.name()),
            &sample,
            |b, rays| {
                b.iter(|| run(algo, &raster, s.n, black_box(rays), None));
            },
        );
    }
    g.finish();
}

fn main() {
    let table_only = std::env::args().any(|a| a == "--table");
    // Criterion parses the remaining arguments (filters, --save-baseline…).
    let mut c = if table_only {
        Criterion::default()
    } else {
        Criterion::default().configure_from_args()
    };
    for n in [256, 512] {
        let s = scene(n);
        let raster = Raster::new(s.raster.extent(), &s.raster.plane).expect("raster");
        table(n, "camera (coherent)", &raster, &s.camera, 5);
        table(n, "random (incoherent)", &raster, &s.random, 5);
        if !table_only {
            criterion_groups(&mut c, &s);
        }
    }
    c.final_summary();
}
