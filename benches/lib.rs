//! Support code for the benchmarks: the rasters and ray sets of the peers'
//! `dda_bench` (same generator, same camera), and the baseline traversals we
//! compare against, all on the same raster and the same rays.
//!
//! Rays are kept in both forms: `f32` origin/direction clipped to the box
//! (what the baselines take) and the fixed-point `DiscreteRay` setup input
//! (what rrt takes), converted once from the same `f64` values.

use rrt_core::discrete_ray::DiscreteRay;
use rrt_core::fixed::VOXEL;
use rrt_core::raster::{Extent, cell};

pub use rrt_core::rng::Rng;

/// The seed of `dda_bench`'s generator (SplitMix64, as [`Rng`]), so the
/// random-sphere raster and the random rays match the C peer's.
pub const DDA_BENCH_SEED: u64 = 0x9E37_79B9_7F4A_7C15;

/// Uniform in [0, 1): the top 53 bits of the next draw.
pub fn unit(rng: &mut Rng) -> f64 {
    (rng.next_u64() >> 11) as f64 * (1.0 / 9_007_199_254_740_992.0)
}

/// Uniform direction (rejection sampling in the unit ball).
pub fn direction(rng: &mut Rng) -> [f64; 3] {
    loop {
        let v = [
            2.0 * unit(rng) - 1.0,
            2.0 * unit(rng) - 1.0,
            2.0 * unit(rng) - 1.0,
        ];
        let l = v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
        if l > 1e-6 && l <= 1.0 {
            let l = l.sqrt();
            return v.map(|c| c / l);
        }
    }
}

/// A cubic raster plane with every page written (so empty space is real
/// memory, as after a voxelization, not the kernel's shared zero page).
pub struct BenchRaster {
    /// Voxels per axis.
    pub n: u32,
    /// The plane, one cell per voxel, x fastest.
    pub plane: Vec<u8>,
    /// Non-transparent voxels.
    pub occupied: usize,
}

impl BenchRaster {
    /// `dda_bench`'s default scene: `count` random solid spheres of radius
    /// `10·n/256` voxels (a voxel belongs to a sphere when its centre is
    /// inside, and the voxel holding the centre is always set).
    #[must_use]
    pub fn random_spheres(n: u32, count: usize, rng: &mut Rng) -> Self {
        let len = (n as usize).pow(3);
        let mut plane = vec![0u8; len];
        touch_every_page(&mut plane);
        let r = 10.0 * f64::from(n) / 256.0;
        let nn = f64::from(n);
        for _ in 0..count {
            let c = [unit(rng) * nn, unit(rng) * nn, unit(rng) * nn];
            fill_sphere(&mut plane, n, c, r);
        }
        let occupied = plane.iter().filter(|&&c| c & cell::OPAQUE != 0).count();
        Self { n, plane, occupied }
    }

    /// The extent.
    #[must_use]
    pub fn extent(&self) -> Extent {
        Extent::cube(self.n).expect("bench raster size")
    }

    /// Linear index of `(x, y, z)`.
    #[must_use]
    pub fn index(&self, x: usize, y: usize, z: usize) -> usize {
        let n = self.n as usize;
        x + n * (y + n * z)
    }
}

/// Writes one byte in every 4 KiB page, through `black_box` so the write is
/// not elided on a calloc'ed buffer.
pub fn touch_every_page(buf: &mut [u8]) {
    for page in buf.chunks_mut(4096) {
        page[0] = std::hint::black_box(0);
    }
}

/// Resident set size of this process in MiB (Linux), to show the plane is
/// really in memory.
#[must_use]
pub fn rss_mib() -> Option<f64> {
    let s = std::fs::read_to_string("/proc/self/statm").ok()?;
    let pages: f64 = s.split_whitespace().nth(1)?.parse().ok()?;
    Some(pages * 4096.0 / 1_048_576.0)
}

fn fill_sphere(plane: &mut [u8], n: u32, c: [f64; 3], r: f64) {
    let n_i = i64::from(n);
    let lo = |v: f64| ((v - r).floor() as i64).clamp(0, n_i - 1);
    let hi = |v: f64| ((v + r).ceil() as i64).clamp(0, n_i - 1);
    let nu = n as usize;
    for z in lo(c[2])..=hi(c[2]) {
        for y in lo(c[1])..=hi(c[1]) {
            for x in lo(c[0])..=hi(c[0]) {
                let d = [
                    x as f64 + 0.5 - c[0],
                    y as f64 + 0.5 - c[1],
                    z as f64 + 0.5 - c[2],
                ];
                if d[0] * d[0] + d[1] * d[1] + d[2] * d[2] <= r * r {
                    plane[x as usize + nu * (y as usize + nu * z as usize)] = cell::OPAQUE;
                }
            }
        }
    }
    let ci = c.map(|v| v.floor() as i64);
    if ci.iter().all(|&v| (0..n_i).contains(&v)) {
        plane[ci[0] as usize + nu * (ci[1] as usize + nu * ci[2] as usize)] = cell::OPAQUE;
    }
}

/// A ray in both forms.
#[derive(Clone, Copy, Debug)]
pub struct BenchRay {
    /// Origin in voxel units.
    pub o: [f32; 3],
    /// Unit direction.
    pub d: [f32; 3],
    /// Parameters where the ray enters and leaves the box `[0, n]³`;
    /// `t1 <= t0` when it misses.
    pub t0: f32,
    /// See `t0`.
    pub t1: f32,
    /// Fixed-point origin for rrt.
    pub origin_fx: [i64; 3],
    /// Fixed-point direction for rrt (scaled to use the i32 range).
    pub dir_fx: [i32; 3],
}

impl BenchRay {
    /// From an `f64` origin (voxel units) and direction, clipped to `[0, n]³`.
    #[must_use]
    pub fn new(o: [f64; 3], d: [f64; 3], n: u32) -> Self {
        let of = o.map(|v| v as f32);
        let df = d.map(|v| v as f32);
        let (t0, t1) = clip(of, df, n as f32);
        let origin_fx = o.map(|v| (v * VOXEL as f64).round() as i64);
        let m = d
            .iter()
            .fold(0.0f64, |a, v| a.max(v.abs()))
            .max(f64::MIN_POSITIVE);
        let dir_fx = d.map(|v| (v / m * f64::from(1 << 30)).round() as i32);
        Self {
            o: of,
            d: df,
            t0,
            t1,
            origin_fx,
            dir_fx,
        }
    }

    /// Whether the float ray enters the box.
    #[must_use]
    pub fn in_box(&self) -> bool {
        self.t1 > self.t0
    }

    /// The rrt discrete ray (setup included: clipping in exact integers).
    #[must_use]
    pub fn discrete(&self, extent: Extent) -> Option<DiscreteRay> {
        DiscreteRay::new(extent, self.origin_fx, self.dir_fx)
            .ok()
            .flatten()
    }
}

fn clip(o: [f32; 3], d: [f32; 3], n: f32) -> (f32, f32) {
    let (mut t0, mut t1) = (0.0f32, f32::MAX);
    for k in 0..3 {
        if d[k] == 0.0 {
            if o[k] < 0.0 || o[k] > n {
                return (1.0, 0.0);
            }
            continue;
        }
        let inv = 1.0 / d[k];
        let (mut a, mut b) = ((0.0 - o[k]) * inv, (n - o[k]) * inv);
        if a > b {
            std::mem::swap(&mut a, &mut b);
        }
        t0 = t0.max(a);
        t1 = t1.min(b);
    }
    (t0, t1)
}

/// `dda_bench`'s camera set: `res × res` pinhole rays from
/// `centre + n·(1.2, 0.9, 0.7)` towards the centre, 50° field of view.
#[must_use]
pub fn camera_rays(n: u32, res: u32) -> Vec<BenchRay> {
    let nn = f64::from(n);
    let c = 0.5 * nn;
    let e: [f64; 3] = [1.2, 0.9, 0.7];
    let l = (e[0] * e[0] + e[1] * e[1] + e[2] * e[2]).sqrt();
    let eye = e.map(|v| c + nn * v);
    let fwd = e.map(|v| -v / l);
    let up0 = [0.0, 0.0, 1.0];
    let mut right = cross(fwd, up0);
    let rl = (right[0] * right[0] + right[1] * right[1]).sqrt();
    right = right.map(|v| v / rl);
    let up = cross(right, fwd);
    let pitch = 2.0 * (50.0f64.to_radians() / 2.0).tan() / f64::from(res - 1);
    let mut rays = Vec::with_capacity((res * res) as usize);
    for y in 0..res {
        for x in 0..res {
            let sx = (f64::from(x) - f64::from(res - 1) * 0.5) * pitch;
            let sy = (f64::from(res - 1) * 0.5 - f64::from(y)) * pitch;
            let d = [0, 1, 2].map(|k| fwd[k] + sx * right[k] + sy * up[k]);
            let l = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
            rays.push(BenchRay::new(eye, d.map(|v| v / l), n));
        }
    }
    rays
}

/// `dda_bench`'s random set: origins uniform on a random face of the box,
/// directions uniform over the inward hemisphere (incoherent).
#[must_use]
pub fn random_rays(n: u32, count: usize, rng: &mut Rng) -> Vec<BenchRay> {
    let nn = f64::from(n);
    (0..count)
        .map(|_| {
            let face = (rng.next_u64() % 6) as usize;
            let (ax, neg) = (face >> 1, face & 1 == 1);
            let mut o = [unit(rng) * nn, unit(rng) * nn, unit(rng) * nn];
            o[ax] = if neg { nn } else { 0.0 };
            let mut d;
            loop {
                d = direction(rng);
                if d[ax].abs() >= 1e-3 {
                    break;
                }
            }
            if (d[ax] > 0.0) == neg {
                d[ax] = -d[ax];
            }
            BenchRay::new(o, d, n)
        })
        .collect()
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// What one traversal did on one ray.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Trace {
    /// Voxels visited and tested.
    pub steps: u64,
    /// Index of the first occupied voxel, if any.
    pub hit: Option<usize>,
}

pub mod baseline {
    //! The baselines, written as their authors (or the peers) do.

    use super::{BenchRay, Trace};
    use line_drawing::{Bresenham3d, VoxelOrigin, WalkVoxels};
    use rrt_core::raster::cell;

    /// Amanatides & Woo (1987) with `f32` t-max/t-delta, a branchy minimum
    /// and an incremental index: `dda_bench`'s `aw`, in Rust. 6-connected.
    #[must_use]
    pub fn amanatides_woo(plane: &[u8], n: u32, r: &BenchRay) -> Trace {
        let ni = n as i32;
        let nu = n as usize;
        let mut ix = [0i32; 3];
        let mut st = [0i32; 3];
        let mut out = [0i32; 3];
        let mut tmax = [0f32; 3];
        let mut tdel = [0f32; 3];
        for k in 0..3 {
            let p = r.o[k] + r.t0 * r.d[k];
            let i = (p.floor() as i32).clamp(0, ni - 1);
            ix[k] = i;
            let d = r.d[k];
            if d > 0.0 {
                st[k] = 1;
                tdel[k] = 1.0 / d;
                tmax[k] = r.t0 + (i as f32 + 1.0 - p) * tdel[k];
                out[k] = ni;
            } else if d < 0.0 {
                st[k] = -1;
                tdel[k] = -1.0 / d;
                tmax[k] = r.t0 + (p - i as f32) * tdel[k];
                out[k] = -1;
            } else {
                tdel[k] = f32::INFINITY;
                tmax[k] = f32::INFINITY;
                out[k] = -2;
            }
        }
        let stride = [1isize, nu as isize, (nu * nu) as isize];
        let dx = st[0] as isize * stride[0];
        let dy = st[1] as isize * stride[1];
        let dz = st[2] as isize * stride[2];
        let [mut x, mut y, mut z] = ix;
        let [mut tx, mut ty, mut tz] = tmax;
        let mut idx = (x as usize + nu * (y as usize + nu * z as usize)) as isize;
        let mut steps = 0u64;
        // One step along axis `$k`: coordinate `$c`, index offset `$d`,
        // t-max `$t`; out of the loop when the ray leaves the box. (A macro:
        // the same code inline in each branch, as the original.)
        macro_rules! step {
            ($c:ident, $k:literal, $d:ident, $t:ident) => {{
                $c += st[$k];
                if $c == out[$k] {
                    break;
                }
                idx += $d;
                $t += tdel[$k];
            }};
        }
        loop {
            steps += 1;
            if plane[idx as usize] & cell::OPAQUE != 0 {
                return Trace {
                    steps,
                    hit: Some(idx as usize),
                };
            }
            if tx < ty {
                if tx < tz {
                    step!(x, 0, dx, tx)
                } else {
                    step!(z, 2, dz, tz)
                }
            } else if ty < tz {
                step!(y, 1, dy, ty)
            } else {
                step!(z, 2, dz, tz)
            }
        }
        Trace { steps, hit: None }
    }

    /// Entry and exit points nudged 1e-3 inside the box, as `dda_bench`
    /// and `line_drawing_bench` pass them to the integer walkers.
    fn seg_points(r: &BenchRay, n: u32) -> ([f32; 3], [f32; 3]) {
        let e = 1e-3f32;
        let hi = n as f32 - 1e-3;
        let p0 = [0, 1, 2].map(|k| (r.o[k] + (r.t0 + e) * r.d[k]).clamp(0.0, hi));
        let p1 = [0, 1, 2].map(|k| (r.o[k] + (r.t1 - e) * r.d[k]).clamp(0.0, hi));
        (p0, p1)
    }

    fn occupied(plane: &[u8], n: u32, x: i32, y: i32, z: i32) -> Option<usize> {
        let nu = n as usize;
        let i = x as usize + nu * (y as usize + nu * z as usize);
        (plane[i] & cell::OPAQUE != 0).then_some(i)
    }

    /// `line_drawing::Bresenham3d` between the entry and exit voxels
    /// (26-connected), indexing the plane from each `(x, y, z)`.
    #[must_use]
    pub fn line_drawing_bresenham(plane: &[u8], n: u32, r: &BenchRay) -> Trace {
        let (a, b) = seg_points(r, n);
        let a = (a[0] as i32, a[1] as i32, a[2] as i32);
        let b = (b[0] as i32, b[1] as i32, b[2] as i32);
        first_occupied(plane, n, Bresenham3d::new(a, b))
    }

    /// The walk of a voxel iterator to its first occupied voxel, indexing
    /// the plane from each `(x, y, z)`.
    fn first_occupied(
        plane: &[u8],
        n: u32,
        voxels: impl Iterator<Item = (i32, i32, i32)>,
    ) -> Trace {
        let mut steps = 0;
        for (x, y, z) in voxels {
            steps += 1;
            if let Some(i) = occupied(plane, n, x, y, z) {
                return Trace {
                    steps,
                    hit: Some(i),
                };
            }
        }
        Trace { steps, hit: None }
    }

    /// `line_drawing::WalkVoxels` (6-connected, `f32`), indexing the plane
    /// from each `(x, y, z)`.
    #[must_use]
    pub fn line_drawing_walk(plane: &[u8], n: u32, r: &BenchRay) -> Trace {
        let (a, b) = seg_points(r, n);
        first_occupied(
            plane,
            n,
            WalkVoxels::<f32, i32>::new(
                (a[0], a[1], a[2]),
                (b[0], b[1], b[2]),
                &VoxelOrigin::Corner,
            ),
        )
    }

    /// A straightforward integer 3D Bresenham with an incremental index
    /// (`dda_bench`'s `bres`, in Rust): 26-connected, between the entry and
    /// exit voxels.
    #[must_use]
    pub fn integer_bresenham(plane: &[u8], n: u32, r: &BenchRay) -> Trace {
        let (a, b) = seg_points(r, n);
        let (x, y, z) = (a[0] as i32, a[1] as i32, a[2] as i32);
        let (x1, y1, z1) = (b[0] as i32, b[1] as i32, b[2] as i32);
        let (lx, ly, lz) = ((x1 - x).abs(), (y1 - y).abs(), (z1 - z).abs());
        let (sx, sy, sz) = ((x1 - x).signum(), (y1 - y).signum(), (z1 - z).signum());
        let longest = lx.max(ly).max(lz);
        let (mut ex, mut ey, mut ez) = (longest / 2, longest / 2, longest / 2);
        let nu = n as isize;
        let (dx, dy, dz) = (sx as isize, sy as isize * nu, sz as isize * nu * nu);
        let mut idx = x as isize + nu * (y as isize + nu * z as isize);
        let mut steps = 0;
        for _ in 0..=longest {
            steps += 1;
            if plane[idx as usize] & cell::OPAQUE != 0 {
                return Trace {
                    steps,
                    hit: Some(idx as usize),
                };
            }
            ex -= lx;
            ey -= ly;
            ez -= lz;
            if ex < 0 {
                ex += longest;
                idx += dx;
            }
            if ey < 0 {
                ey += longest;
                idx += dy;
            }
            if ez < 0 {
                ez += longest;
                idx += dz;
            }
        }
        Trace { steps, hit: None }
    }
}
