//! Axis-aligned boxes ([`Cuboid`]): the surface shell and the solid.
//!
//! ```
//! use rrt_core::fixed::VOXEL;
//! use rrt_core::geometry::Cuboid;
//! use rrt_core::raster::Extent;
//! use rrt_core::voxelize::{cuboid, Separation, Surfel, VoxelSink};
//!
//! struct Count(u64);
//! impl VoxelSink for Count {
//!     fn offer(&mut self, _: [u32; 3], _: Surfel) { self.0 += 1; }
//! }
//! // Faces through voxel centres: a one-voxel shell around 3³ voxels.
//! let b = Cuboid { min: [VOXEL * 3 / 2; 3], max: [VOXEL * 11 / 2; 3] };
//! let mut n = Count(0);
//! cuboid::surface(&b, Separation::TwentySix, Extent::cube(8).unwrap(), &mut n).unwrap();
//! assert_eq!(n.0, 5 * 5 * 5 - 3 * 3 * 3);
//! ```
//!
//! # Which voxels
//! As for triangles ([`super::triangle`]): a voxel belongs to the surface
//! when its probe (TwentySix: its closed cube; Six: its inscribed
//! octahedron) meets the box's boundary, i.e. meets the closed box without
//! lying inside the open box. [`solid`] adds the voxels inside, with
//! distance 0.
//!
//! # Accepted input and cost
//! Coordinates within [`COORD_LIMIT`](super::error::COORD_LIMIT) and
//! `min < max` on every axis ([`VoxelizeError::Degenerate`] otherwise).
//! Per column of the clipped projection one interval minus one interval:
//! work linear in the voxels offered.

use super::error::VoxelizeError;
use super::fixmath::{
    Counter, H, V, cells_overlapping, centre, centres_within, check_point, clip, dist_u32, length,
    low, split, unit_fast,
};
use super::{NORMAL_ONE, Separation, Surfel, VoxelSink};
use crate::geometry::Cuboid;
use crate::raster::Extent;

/// Voxelizes the surface of `cuboid`, clipped to `extent`. Returns the
/// number of offers (each voxel once).
///
/// # Errors
/// [`VoxelizeError::Degenerate`] unless `min < max` on every axis,
/// [`VoxelizeError::OutOfRange`] beyond
/// [`COORD_LIMIT`](super::error::COORD_LIMIT).
pub fn surface<S: VoxelSink + ?Sized>(
    cuboid: &Cuboid,
    separation: Separation,
    extent: Extent,
    sink: &mut S,
) -> Result<u64, VoxelizeError> {
    scan(cuboid, separation, extent, sink, false)
}

/// Voxelizes the solid box: the shell of [`surface`] plus the voxels inside
/// it, offered with distance 0.
///
/// # Errors
/// As [`surface`].
pub fn solid<S: VoxelSink + ?Sized>(
    cuboid: &Cuboid,
    separation: Separation,
    extent: Extent,
    sink: &mut S,
) -> Result<u64, VoxelizeError> {
    scan(cuboid, separation, extent, sink, true)
}

fn scan<S: VoxelSink + ?Sized>(
    b: &Cuboid,
    sep: Separation,
    extent: Extent,
    sink: &mut S,
    fill: bool,
) -> Result<u64, VoxelizeError> {
    let lo = check_point(b.min)?;
    let hi = check_point(b.max)?;
    if lo.iter().zip(hi.iter()).any(|(l, h)| l >= h) {
        return Err(VoxelizeError::Degenerate);
    }
    let dims = extent.dims();
    let mut n = Counter::default();
    // Cells strictly inside the open box along one axis.
    let strict = |k: usize| -> (i128, i128) {
        // low(i) > lo and low(i) + V < hi.
        (
            super::fixmath::cell_floor(lo[k]).saturating_add(1),
            super::fixmath::cell_ceil(hi[k]).saturating_sub(2),
        )
    };
    // Probe reach beyond the box along one axis, given what the other axes
    // used up (Six: L1 budget; TwentySix: a full half voxel each).
    let range = |k: usize, budget: i128| -> (i128, i128) {
        match sep {
            Separation::TwentySix => cells_overlapping(lo[k], hi[k]),
            Separation::Six => {
                centres_within(lo[k].saturating_sub(budget), hi[k].saturating_add(budget))
            }
        }
    };
    let out_dist = |k: usize, c: i128| -> i128 {
        if c < lo[k] {
            lo[k].saturating_sub(c)
        } else if c > hi[k] {
            c.saturating_sub(hi[k])
        } else {
            0
        }
    };
    let (yl, yh) = range(1, H);
    let Some((y0, y1)) = clip(yl, yh, dims[1]) else {
        return Ok(0);
    };
    let (sy0, sy1) = strict(1);
    let (sx0, sx1) = strict(0);
    let (sz0, sz1) = strict(2);
    for y in y0..=y1 {
        let dy = out_dist(1, centre(y));
        let (xl, xh) = range(0, H.saturating_sub(dy));
        let Some((x0, x1)) = clip(xl, xh, dims[0]) else {
            continue;
        };
        let yi = i128::from(y);
        for x in x0..=x1 {
            let dx = out_dist(0, centre(x));
            let budget = H.saturating_sub(dy).saturating_sub(dx);
            if budget < 0 && sep == Separation::Six {
                continue;
            }
            let (zl, zh) = range(2, budget);
            let Some((z0, z1)) = clip(zl, zh, dims[2]) else {
                continue;
            };
            let xi = i128::from(x);
            let inner_col = (sx0..=sx1).contains(&xi) && (sy0..=sy1).contains(&yi);
            // Cells strictly inside are skipped (surface) or filled (solid)
            // without visiting them one by one.
            let (el, eh) = if inner_col { (sz0, sz1) } else { (1, 0) };
            let [below, inside, above] = split(z0, z1, el, eh);
            for (a, b) in below.into_iter().chain(above) {
                for z in a..=b {
                    let v = [x, y, z];
                    sink.offer(v, surfel(lo, hi, v));
                    n.bump();
                }
            }
            if let (true, Some((a, b))) = (fill, inside) {
                for z in a..=b {
                    let v = [x, y, z];
                    let s = surfel(lo, hi, v);
                    sink.offer(v, Surfel { distance: 0, ..s });
                    n.bump();
                }
            }
        }
    }
    Ok(n.0)
}

/// Whether voxel `v`'s probe meets the surface of `cuboid`: the membership
/// rule of [`surface`], evaluated directly.
///
/// # Errors
/// As [`surface`].
pub fn contains(
    cuboid: &Cuboid,
    separation: Separation,
    v: [u32; 3],
) -> Result<bool, VoxelizeError> {
    let lo = check_point(cuboid.min)?;
    let hi = check_point(cuboid.max)?;
    if lo.iter().zip(hi.iter()).any(|(l, h)| l >= h) {
        return Err(VoxelizeError::Degenerate);
    }
    let mut meets = true;
    let mut l1 = 0i128;
    let mut inside = true;
    for k in 0..3 {
        let c = centre(v[k]);
        let d = if c < lo[k] {
            lo[k].saturating_sub(c)
        } else if c > hi[k] {
            c.saturating_sub(hi[k])
        } else {
            0
        };
        l1 = l1.saturating_add(d);
        meets &= d <= H;
        let l = low(v[k]);
        inside &= l > lo[k] && l.saturating_add(V) < hi[k];
    }
    let meets = match separation {
        Separation::TwentySix => meets,
        Separation::Six => l1 <= H,
    };
    Ok(meets && !inside)
}

/// Nearest point on the box surface: outside, the clamped point and the
/// direction to it; inside, the nearest face.
fn surfel(lo: [i128; 3], hi: [i128; 3], v: [u32; 3]) -> Surfel {
    let c = v.map(centre);
    let q = [0, 1, 2].map(|k| c[k].clamp(lo[k], hi[k]));
    let w = [0, 1, 2].map(|k| c[k].saturating_sub(q[k]));
    if w != [0; 3] {
        return Surfel {
            normal: unit_fast(w).unwrap_or([0, 0, NORMAL_ONE]),
            distance: dist_u32(length(w)),
        };
    }
    let mut best = (i128::MAX, [0, 0, NORMAL_ONE]);
    for k in 0..3 {
        let down = c[k].saturating_sub(lo[k]);
        let up = hi[k].saturating_sub(c[k]);
        let mut n = [0i32; 3];
        let (d, s) = if up < down {
            (up, NORMAL_ONE)
        } else {
            (down, -NORMAL_ONE)
        };
        if let Some(slot) = n.get_mut(k) {
            *slot = s;
        }
        if d < best.0 {
            best = (d, n);
        }
    }
    Surfel {
        normal: best.1,
        distance: dist_u32(best.0),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::HashMap;
    use std::vec::Vec;

    struct Collect(HashMap<[u32; 3], (Surfel, u32)>);
    impl VoxelSink for Collect {
        fn offer(&mut self, v: [u32; 3], s: Surfel) {
            self.0.entry(v).or_insert((s, 0)).1 += 1;
        }
    }

    #[test]
    fn scan_matches_membership() {
        let e = Extent::new(11, 10, 9).unwrap();
        let mut seed = 11u64;
        let mut next = |m: i64| {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            i64::try_from(seed >> 33).unwrap() % m
        };
        for case in 0..120 {
            let mut lo = [0i64; 3];
            let mut hi = [0i64; 3];
            for k in 0..3 {
                let a = next(13 * 65536) - 2 * 65536;
                let b = next(13 * 65536) - 2 * 65536;
                let snap = |x: i64| match case % 3 {
                    0 => x & !0xffff,
                    1 => (x & !0xffff) | 0x8000,
                    _ => x,
                };
                lo[k] = snap(a.min(b));
                hi[k] = snap(a.max(b)) + 1 + (case % 2) * 65536;
            }
            let b = Cuboid { min: lo, max: hi };
            for sep in [Separation::Six, Separation::TwentySix] {
                let mut c = Collect(HashMap::new());
                surface(&b, sep, e, &mut c).unwrap();
                assert!(c.0.values().all(|v| v.1 == 1));
                let [nx, ny, nz] = e.dims();
                let mut want = Vec::new();
                for z in 0..nz {
                    for y in 0..ny {
                        for x in 0..nx {
                            if contains(&b, sep, [x, y, z]).unwrap() {
                                want.push([x, y, z]);
                            }
                        }
                    }
                }
                for v in &want {
                    assert!(
                        c.0.contains_key(v),
                        "case {case} {sep:?}: missing {v:?} of {b:?}"
                    );
                }
                assert_eq!(c.0.len(), want.len(), "case {case} {sep:?}");
                let mut s = Collect(HashMap::new());
                solid(&b, sep, e, &mut s).unwrap();
                for (v, (sf, _)) in &s.0 {
                    if !c.0.contains_key(v) {
                        assert_eq!(sf.distance, 0);
                        for k in 0..3 {
                            assert!(
                                centre(v[k]) > i128::from(lo[k])
                                    && centre(v[k]) < i128::from(hi[k])
                            );
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn surfels_and_bad_input() {
        let v = 65536i64;
        let b = Cuboid {
            min: [v; 3],
            max: [5 * v; 3],
        };
        let s = surfel(
            check_point(b.min).unwrap(),
            check_point(b.max).unwrap(),
            [1, 3, 3],
        );
        assert_eq!(s.normal, [-NORMAL_ONE, 0, 0]);
        assert_eq!(s.distance, (v / 2) as u32);
        let s = surfel(
            check_point(b.min).unwrap(),
            check_point(b.max).unwrap(),
            [0, 0, 3],
        );
        assert!(s.normal[0] < 0 && s.normal[1] < 0 && s.normal[2] == 0);
        let e = Extent::cube(4).unwrap();
        let mut c = Collect(HashMap::new());
        let flat = Cuboid {
            min: [0; 3],
            max: [v, 0, v],
        };
        assert_eq!(
            surface(&flat, Separation::Six, e, &mut c),
            Err(VoxelizeError::Degenerate)
        );
    }
}
