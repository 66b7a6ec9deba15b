//! Voxelization benchmarks.
//!
//! * `table2/*`: the paper's Table 2, voxelization time for 10 … 5000 random
//!   spheres of radius 10 voxels in a 256³ raster (seeded), with the number
//!   of voxels generated; criterion's throughput is voxels per second, so
//!   the time per voxel should stay flat.
//! * `spd/*`: the SPD sphereflakes balls2–balls4 (spheres and the floor
//!   polygon) and the teapot (`pp` triangles with normals, and the floor),
//!   scaled so that the scene's bounding box has 512 or 1024 voxels along
//!   its longest axis.
//!
//! The sink counts offers and writes OPAQUE into the plane, as the scene
//! builder's first pass does. A summary (voxels, plane bytes, one timed run
//! each) is printed before criterion runs, for the README.

use rrt_core::rng::Rng;
use std::hint::black_box;
use std::path::PathBuf;
use std::time::Instant;

use criterion::measurement::WallTime;
use criterion::{BenchmarkGroup, Criterion, Throughput, criterion_group, criterion_main};
use rrt_core::fixed::VOXEL;
use rrt_core::geometry::{Point, Sphere, Triangle};
use rrt_core::raster::{Extent, cell};
use rrt_core::voxelize::{NORMAL_ONE, Separation, Surfel, VoxelSink, sphere, triangle};

/// Nanoseconds this thread has spent on a CPU (Linux `schedstat`), so the
/// printed summary is not inflated by other processes sharing the machine;
/// `None` elsewhere.
fn cpu_ns() -> Option<u64> {
    let s = std::fs::read_to_string("/proc/thread-self/schedstat").ok()?;
    s.split_whitespace().next()?.parse().ok()
}

/// Runs `f` repeatedly for at least 0.3 s of wall-clock time (at least
/// once), returning its last result and the wall-clock and on-CPU seconds
/// per run.
fn timed<T>(mut f: impl FnMut() -> T) -> (T, f64, f64) {
    let (c0, t0) = (cpu_ns(), Instant::now());
    let mut runs = 1u32;
    let mut out = f();
    while t0.elapsed().as_secs_f64() < 0.3 {
        out = f();
        runs += 1;
    }
    let wall = t0.elapsed().as_secs_f64();
    let cpu = match (c0, cpu_ns()) {
        (Some(a), Some(b)) => (b - a) as f64 * 1e-9,
        _ => wall,
    };
    (out, wall / f64::from(runs), cpu / f64::from(runs))
}

/// Registers `run` in `group` as `id`, at `offers` elements a run.
fn bench_offers(
    group: &mut BenchmarkGroup<'_, WallTime>,
    id: String,
    offers: u64,
    mut run: impl FnMut() -> u64,
) {
    group.throughput(Throughput::Elements(offers));
    group.bench_function(id, |b| b.iter(&mut run));
}

/// Counts offers and marks voxels opaque in a plane.
struct CountingSink<'a> {
    extent: Extent,
    plane: &'a mut [u8],
    offers: u64,
}

impl CountingSink<'_> {
    /// The offers `voxelize` makes into `plane` (of `extent`).
    fn count(
        extent: Extent,
        plane: &mut [u8],
        voxelize: impl FnOnce(&mut CountingSink<'_>),
    ) -> u64 {
        let mut sink = CountingSink {
            extent,
            plane,
            offers: 0,
        };
        voxelize(&mut sink);
        sink.offers
    }
}

impl VoxelSink for CountingSink<'_> {
    fn offer(&mut self, v: [u32; 3], _: Surfel) {
        self.offers += 1;
        if let Some(c) = self.extent.index(v).and_then(|i| self.plane.get_mut(i)) {
            *c |= cell::OPAQUE;
        }
    }
}

/// `count` spheres of radius 10 voxels with centres uniform in the 256³
/// raster (fully inside), seeded.
fn random_spheres(count: usize) -> Vec<Sphere> {
    let mut rng = Rng(0x5eed_0000 + count as u64);
    (0..count)
        .map(|_| Sphere {
            centre: [0; 3].map(|_| 11 * VOXEL + (rng.next_u64() % (234 * VOXEL as u64)) as i64),
            radius: 10 * VOXEL,
        })
        .collect()
}

/// A scene in fixed-point raster coordinates.
struct Scene {
    extent: Extent,
    spheres: Vec<Sphere>,
    polygons: Vec<Vec<Point>>,
    triangles: Vec<Triangle>,
}

impl Scene {
    fn voxelize(&self, sep: Separation, sink: &mut CountingSink<'_>) {
        for s in &self.spheres {
            sphere::surface(s, sep, self.extent, sink).unwrap();
        }
        for p in &self.polygons {
            triangle::polygon(p, sep, self.extent, sink).unwrap();
        }
        for t in &self.triangles {
            let _ = triangle::triangle(t, sep, self.extent, sink);
        }
    }
}

/// The NFF subset the benchmark needs: `s`, `p`, `pp` (everything else is
/// skipped). The real parser lives in the host.
#[derive(Default)]
struct Nff {
    spheres: Vec<([f64; 3], f64)>,
    polygons: Vec<Vec<[f64; 3]>>,
    patches: Vec<Vec<([f64; 3], [f64; 3])>>,
}

fn parse_nff(text: &str) -> Nff {
    let mut out = Nff::default();
    let mut lines = text.lines();
    let nums = |l: &str| -> Vec<f64> {
        l.split_whitespace()
            .filter_map(|x| x.parse().ok())
            .collect()
    };
    while let Some(line) = lines.next() {
        let mut it = line.split_whitespace();
        match it.next() {
            Some("s") => {
                let v = nums(&line[1..]);
                out.spheres.push(([v[0], v[1], v[2]], v[3]));
            }
            Some("p") => {
                let n: usize = it.next().unwrap().parse().unwrap();
                let poly = (0..n)
                    .map(|_| {
                        let v = nums(lines.next().unwrap());
                        [v[0], v[1], v[2]]
                    })
                    .collect();
                out.polygons.push(poly);
            }
            Some("pp") => {
                let n: usize = it.next().unwrap().parse().unwrap();
                let poly = (0..n)
                    .map(|_| {
                        let v = nums(lines.next().unwrap());
                        ([v[0], v[1], v[2]], [v[3], v[4], v[5]])
                    })
                    .collect();
                out.patches.push(poly);
            }
            _ => {}
        }
    }
    out
}

/// Fits the scene's bounding box into a raster with `n` voxels along its
/// longest axis (cubic voxels, one voxel of margin).
fn fit(nff: &Nff, n: u32) -> Scene {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    let mut grow = |p: [f64; 3], r: f64| {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k] - r);
            hi[k] = hi[k].max(p[k] + r);
        }
    };
    nff.spheres.iter().for_each(|(c, r)| grow(*c, *r));
    nff.polygons.iter().flatten().for_each(|p| grow(*p, 0.0));
    nff.patches
        .iter()
        .flatten()
        .for_each(|(p, _)| grow(*p, 0.0));
    let size = (0..3).map(|k| hi[k] - lo[k]).fold(0.0, f64::max);
    let scale = f64::from(n - 2) * VOXEL as f64 / size;
    let dims =
        [0, 1, 2].map(|k| (((hi[k] - lo[k]) * scale / VOXEL as f64).ceil() as u32 + 2).max(1));
    let to = |p: [f64; 3]| -> Point { [0, 1, 2].map(|k| ((p[k] - lo[k]) * scale) as i64 + VOXEL) };
    let unit = |n: [f64; 3]| {
        let l = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt().max(1e-300);
        n.map(|c| (c / l * f64::from(NORMAL_ONE)) as i32)
    };
    let mut triangles = Vec::new();
    for poly in &nff.patches {
        for i in 1..poly.len() - 1 {
            let (a, b, c) = (poly[0], poly[i], poly[i + 1]);
            triangles.push(Triangle {
                vertices: [to(a.0), to(b.0), to(c.0)],
                normals: Some([unit(a.1), unit(b.1), unit(c.1)]),
            });
        }
    }
    Scene {
        extent: Extent::new(dims[0], dims[1], dims[2]).unwrap(),
        spheres: nff
            .spheres
            .iter()
            .map(|(c, r)| Sphere {
                centre: to(*c),
                radius: (r * scale) as i64,
            })
            .collect(),
        polygons: nff
            .polygons
            .iter()
            .map(|p| p.iter().map(|v| to(*v)).collect())
            .collect(),
        triangles,
    }
}

fn spd_dir() -> Option<PathBuf> {
    let p = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../shared/data/spd");
    p.is_dir().then_some(p)
}

fn table2(c: &mut Criterion) {
    let extent = Extent::cube(256).unwrap();
    let mut plane = vec![0u8; extent.len()];
    let mut group = c.benchmark_group("table2");
    group.sample_size(10);
    println!("Table 2: random spheres of radius 10 in 256^3 (mean of runs over >= 0.3 s)");
    for sep in [Separation::TwentySix, Separation::Six] {
        for count in [10usize, 100, 200, 400, 1000, 5000] {
            let spheres = random_spheres(count);
            let run = |plane: &mut [u8]| {
                CountingSink::count(extent, plane, |sink| {
                    for s in &spheres {
                        sphere::surface(black_box(s), sep, extent, sink).unwrap();
                    }
                })
            };
            let _ = run(&mut plane); // warm up
            let (offers, wall, cpu) = timed(|| run(&mut plane));
            println!(
                "  {sep:?} {count:>5} spheres: {offers:>9} voxels, wall {:>9.3} ms, cpu {:>9.3} ms, {:>6.1} ns/voxel (cpu)",
                wall * 1e3,
                cpu * 1e3,
                cpu * 1e9 / offers as f64
            );
            bench_offers(&mut group, format!("{sep:?}/{count}"), offers, || {
                run(&mut plane)
            });
        }
    }
    group.finish();
}

fn spd(c: &mut Criterion) {
    let Some(dir) = spd_dir() else {
        println!("SKIPPED: ../shared/data/spd not found");
        return;
    };
    let mut group = c.benchmark_group("spd");
    group.sample_size(10);
    println!("SPD scenes (TwentySix; mean of runs over >= 0.3 s)");
    for name in ["balls2", "balls3", "balls4", "teapot"] {
        let nff = parse_nff(&std::fs::read_to_string(dir.join(format!("{name}.nff"))).unwrap());
        for n in [512u32, 1024] {
            let scene = fit(&nff, n);
            let mut plane = vec![0u8; scene.extent.len()];
            let run = |plane: &mut [u8]| {
                CountingSink::count(scene.extent, plane, |sink| {
                    scene.voxelize(Separation::TwentySix, sink);
                })
            };
            let (offers, wall, cpu) = timed(|| run(&mut plane));
            let opaque = plane.iter().filter(|c| **c & cell::OPAQUE != 0).count();
            println!(
                "  {name} at {n}: raster {:?} (plane {:.1} MiB), {offers} offers, {opaque} voxels, wall {:.1} ms, cpu {:.1} ms, {:.1} ns/offer (cpu)",
                scene.extent.dims(),
                scene.extent.len() as f64 / (1 << 20) as f64,
                wall * 1e3,
                cpu * 1e3,
                cpu * 1e9 / offers as f64
            );
            bench_offers(&mut group, format!("{name}/{n}"), offers, || {
                run(&mut plane)
            });
        }
    }
    group.finish();
}

criterion_group!(benches, table2, spd);
criterion_main!(benches);
