//! Test-only helpers: plain brute-force integer voxelizers (standing in for
//! the real ones in `voxelize/` in this crate's unit tests) and a scene
//! builder over `Vec` storage.

use std::vec;
use std::vec::Vec;

use crate::fixed::{VOXEL, voxel_centre};
use crate::raster::{Extent, RasterMut};
use crate::store::{Counter, Limits, ObjectAttrs, directory_len};
use crate::voxel::{VoxelRecord, normalize};
use crate::voxelize::{NORMAL_ONE, Separation, Surfel, VoxelSink};

/// Euclidean length of a fixed-point vector, fixed units.
pub fn length(v: [i64; 3]) -> i64 {
    let s: u128 = v
        .iter()
        .map(|c| c.unsigned_abs() as u128 * c.unsigned_abs() as u128)
        .sum();
    s.isqrt() as i64
}

/// Half the separating thickness for normal `n` (fixed units): the
/// voxelize module's rule.
pub fn half_thickness(n: [i32; 3], sep: Separation) -> i64 {
    let a = n.map(|c| i64::from(c).abs());
    let m = match sep {
        Separation::Six => a[0].max(a[1]).max(a[2]),
        Separation::TwentySix => a[0] + a[1] + a[2],
    };
    // m / NORMAL_ONE voxels, halved.
    (m * VOXEL / i64::from(NORMAL_ONE)) / 2
}

/// Brute force over a box of voxels: offers voxels whose centre's signed
/// distance `f(c) -> (d, normal)` is within the half thickness.
pub fn surface_by_distance(
    extent: Extent,
    lo: [i64; 3],
    hi: [i64; 3],
    sep: Separation,
    sink: &mut dyn VoxelSink,
    f: &dyn Fn([i64; 3]) -> Option<(i64, [i32; 3])>,
) {
    let dims = extent.dims();
    let clamp = |v: i64, k: usize| v.clamp(0, i64::from(dims[k]) - 1);
    let a: [i64; 3] = core::array::from_fn(|k| clamp((lo[k] >> 16) - 2, k));
    let b: [i64; 3] = core::array::from_fn(|k| clamp((hi[k] >> 16) + 2, k));
    for z in a[2]..=b[2] {
        for y in a[1]..=b[1] {
            for x in a[0]..=b[0] {
                let v = [x as u32, y as u32, z as u32];
                let c = v.map(voxel_centre);
                if let Some((d, n)) = f(c)
                    && d.abs() <= half_thickness(n, sep)
                {
                    sink.offer(
                        v,
                        Surfel {
                            normal: n,
                            distance: d.unsigned_abs() as u32,
                        },
                    );
                }
            }
        }
    }
}

/// Sphere surface, brute force.
pub fn sphere(
    extent: Extent,
    centre: [i64; 3],
    radius: i64,
    sep: Separation,
    sink: &mut dyn VoxelSink,
) {
    let lo = centre.map(|c| c - radius);
    let hi = centre.map(|c| c + radius);
    surface_by_distance(extent, lo, hi, sep, sink, &|c| {
        let d = [c[0] - centre[0], c[1] - centre[1], c[2] - centre[2]];
        Some((length(d) - radius, normalize(d)?))
    });
}

/// Torus around the z axis, brute force.
pub fn torus(
    extent: Extent,
    centre: [i64; 3],
    major: i64,
    minor: i64,
    sep: Separation,
    sink: &mut dyn VoxelSink,
) {
    let r = major + minor;
    let lo = [centre[0] - r, centre[1] - r, centre[2] - minor];
    let hi = [centre[0] + r, centre[1] + r, centre[2] + minor];
    surface_by_distance(extent, lo, hi, sep, sink, &|c| {
        let d = [c[0] - centre[0], c[1] - centre[1], c[2] - centre[2]];
        let rad = length([d[0], d[1], 0]);
        if rad == 0 {
            return None;
        }
        // Nearest point of the tube's centre circle.
        let k = [d[0] * major / rad, d[1] * major / rad, 0];
        let q = [d[0] - k[0], d[1] - k[1], d[2]];
        Some((length(q) - minor, normalize(q)?))
    });
}

/// An axis-aligned rectangle `z = z0`, `x, y` in the given voxel ranges,
/// normal `+z` (or `−z` with `down`).
pub fn plate(
    extent: Extent,
    z0: i64,
    xs: core::ops::Range<u32>,
    ys: core::ops::Range<u32>,
    down: bool,
    sep: Separation,
    sink: &mut dyn VoxelSink,
) {
    let n = [0, 0, if down { -NORMAL_ONE } else { NORMAL_ONE }];
    let lo = [i64::from(xs.start) << 16, i64::from(ys.start) << 16, z0];
    let hi = [
        (i64::from(xs.end) << 16) - 1,
        (i64::from(ys.end) << 16) - 1,
        z0,
    ];
    surface_by_distance(extent, lo, hi, sep, sink, &|c| {
        let inside = (xs.start..xs.end).contains(&((c[0] >> 16) as u32))
            && (ys.start..ys.end).contains(&((c[1] >> 16) as u32));
        inside.then_some((c[2] - z0, n))
    });
}

/// A built scene over owned storage.
pub struct Scene {
    pub extent: Extent,
    pub plane: Vec<u8>,
    pub dir: Vec<u32>,
    pub records: Vec<VoxelRecord>,
}

/// One object to build: its attributes and its voxelizer.
pub type Voxelize<'a> = (ObjectAttrs, &'a dyn Fn(&mut dyn VoxelSink));

/// Runs both passes over `objects`.
pub fn build(extent: Extent, objects: &[Voxelize<'_>], limits: Limits) -> Scene {
    let mut plane = vec![0u8; extent.len()];
    let mut dir = vec![0u32; directory_len(extent).unwrap()];
    let mut counter = Counter::new(RasterMut::new(extent, &mut plane).unwrap(), &mut dir).unwrap();
    for (_, f) in objects {
        f(&mut counter);
    }
    let sizing = counter.finish().unwrap();
    let mut records = vec![VoxelRecord::default(); sizing.records()];
    let mut filler = sizing.fill(&mut records, limits).unwrap();
    for (attrs, f) in objects {
        filler.begin_object(*attrs).unwrap();
        f(&mut filler);
    }
    filler.finish().unwrap();
    Scene {
        extent,
        plane,
        dir,
        records,
    }
}
