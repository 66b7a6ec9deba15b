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
//! lying inside the open box, with ties (faces on voxel faces or centres)
//! decided by the infinitesimal shift of [`super::triangle`]: one layer per
//! face. [`solid`] adds the voxels inside, with distance 0.
//!
//! # Accepted input and cost
//! Coordinates within [`COORD_LIMIT`](super::error::COORD_LIMIT) and
//! `min < max` on every axis ([`VoxelizeError::Degenerate`] otherwise).
//! Per column of the clipped projection one interval minus one interval:
//! work linear in the voxels offered.

use super::error::VoxelizeError;
use super::fixmath::{
    Counter, H, cell_floor, centre, centres_within, check_point, clip, dist_u32, length, split,
    sub, unit, window,
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
    let bx = BoxTies::new(b)?;
    let (lo, hi) = (bx.lo, bx.hi);
    let win = window(extent, sink);
    let reads = sink.reads_surfels();
    let mut n = Counter::default();
    // Candidate cells along one axis: TwentySix exactly (half-open per the
    // tie rule); Six closed within the L1 budget left by the other axes,
    // ties then settled per cell by `meets_six`.
    let range = |k: usize, budget: i128| -> (i128, i128) {
        match sep {
            Separation::TwentySix => (cell_floor(lo[k]), cell_floor(hi[k])),
            Separation::Six => {
                centres_within(lo[k].saturating_sub(budget), hi[k].saturating_add(budget))
            }
        }
    };
    let (yl, yh) = range(1, H);
    let (zl, zh) = range(2, H);
    let (Some((y0, y1)), Some(_)) = (clip(yl, yh, win[1]), clip(zl, zh, win[2])) else {
        return Ok(0);
    };
    let (sy0, sy1) = bx.strict(1);
    let (sx0, sx1) = bx.strict(0);
    let (sz0, sz1) = bx.strict(2);
    for y in y0..=y1 {
        let dy = out_dist(lo[1], hi[1], centre(y));
        let (xl, xh) = range(0, H.saturating_sub(dy));
        let Some((x0, x1)) = clip(xl, xh, win[0]) else {
            continue;
        };
        let yi = i128::from(y);
        for x in x0..=x1 {
            let dx = out_dist(lo[0], hi[0], centre(x));
            let budget = H.saturating_sub(dy).saturating_sub(dx);
            if budget < 0 && sep == Separation::Six {
                continue;
            }
            let (zl, zh) = range(2, budget);
            let Some((z0, z1)) = clip(zl, zh, win[2]) else {
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
                    if sep == Separation::Six && !bx.meets_six(v) {
                        continue;
                    }
                    let s = if reads {
                        surfel(lo, hi, v)
                    } else {
                        Surfel::NONE
                    };
                    sink.offer(v, s);
                    n.bump();
                }
            }
            if let (true, Some((a, b))) = (fill, inside) {
                for z in a..=b {
                    let v = [x, y, z];
                    let s = if reads {
                        Surfel {
                            distance: 0,
                            ..surfel(lo, hi, v)
                        }
                    } else {
                        Surfel::NONE
                    };
                    sink.offer(v, s);
                    n.bump();
                }
            }
        }
    }
    Ok(n.0)
}

/// Distance from `c` to `[lo, hi]` on one axis.
#[inline]
fn out_dist(lo: i128, hi: i128, c: i128) -> i128 {
    if c < lo {
        lo.saturating_sub(c)
    } else if c > hi {
        c.saturating_sub(hi)
    } else {
        0
    }
}

/// A validated box with the tie rule of [`super::triangle`]: the box is
/// shifted by an infinitesimal `ε = (ε1, ε2, ε3)`, `ε1 ≫ ε2 ≫ ε3 > 0`.
struct BoxTies {
    lo: [i128; 3],
    hi: [i128; 3],
}

impl BoxTies {
    fn new(b: &Cuboid) -> Result<Self, VoxelizeError> {
        let lo = check_point(b.min)?;
        let hi = check_point(b.max)?;
        if lo.iter().zip(hi.iter()).any(|(l, h)| l >= h) {
            return Err(VoxelizeError::Degenerate);
        }
        Ok(Self { lo, hi })
    }

    /// Cells strictly inside the (shifted) open box on axis `k`: `iV > lo`
    /// and `(i+1)V ≤ hi`.
    fn strict(&self, k: usize) -> (i128, i128) {
        let (lo, hi) = (
            self.lo.get(k).copied().unwrap_or(0),
            self.hi.get(k).copied().unwrap_or(0),
        );
        (
            cell_floor(lo).saturating_add(1),
            cell_floor(hi).saturating_sub(1),
        )
    }

    /// Whether voxel `v` lies strictly inside the shifted open box.
    fn inside(&self, v: [u32; 3]) -> bool {
        (0..3).all(|k| {
            let (a, b) = self.strict(k);
            (a..=b).contains(&i128::from(v.get(k).copied().unwrap_or(0)))
        })
    }

    /// Whether the closed cube of `v` meets the shifted closed box: per axis
    /// `iV ≤ hi` and `(i+1)V > lo`.
    fn meets_cube(&self, v: [u32; 3]) -> bool {
        (0..3).all(|k| {
            let i = i128::from(v.get(k).copied().unwrap_or(0));
            let (lo, hi) = (
                self.lo.get(k).copied().unwrap_or(0),
                self.hi.get(k).copied().unwrap_or(0),
            );
            (cell_floor(lo)..=cell_floor(hi)).contains(&i)
        })
    }

    /// Whether the inscribed octahedron of `v` meets the shifted closed box:
    /// L1 distance from the centre below half a voxel, or equal to it with
    /// the shift moving the box closer (the first axis whose distance
    /// depends on ε decides).
    fn meets_six(&self, v: [u32; 3]) -> bool {
        let mut d1 = 0i128;
        let mut first: Option<bool> = None;
        for k in 0..3 {
            let c = centre(v.get(k).copied().unwrap_or(0));
            let (lo, hi) = (
                self.lo.get(k).copied().unwrap_or(0),
                self.hi.get(k).copied().unwrap_or(0),
            );
            d1 = d1.saturating_add(out_dist(lo, hi, c));
            // d/dε_k of the distance: +1 at or below lo, −1 above hi.
            let closer = if c <= lo {
                Some(false)
            } else if c > hi {
                Some(true)
            } else {
                None
            };
            if first.is_none() {
                first = closer;
            }
        }
        d1 < H || (d1 == H && first.unwrap_or(true))
    }
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
    let b = BoxTies::new(cuboid)?;
    let meets = match separation {
        Separation::TwentySix => b.meets_cube(v),
        Separation::Six => b.meets_six(v),
    };
    Ok(meets && !b.inside(v))
}

/// Nearest point on the box surface: outside, the clamped point and the
/// direction to it; inside, the nearest face.
fn surfel(lo: [i128; 3], hi: [i128; 3], v: [u32; 3]) -> Surfel {
    let c = v.map(centre);
    let q = [0, 1, 2].map(|k| c[k].clamp(lo[k], hi[k]));
    let w = sub(c, q);
    if w != [0; 3] {
        return Surfel {
            normal: unit(w).unwrap_or([0, 0, NORMAL_ONE]),
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
    use crate::testkit::{Offers, Rng, assert_offers_are, assert_refused, voxelized};
    use std::format;

    #[test]
    fn scan_matches_membership() {
        let e = Extent::new(11, 10, 9).unwrap();
        let mut rng = Rng(11u64);
        let mut next = |m: i64| rng.range(0, m - 1);
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
                let (r, c) = voxelized(surface, &b, sep, e);
                r.unwrap();
                let inside = |v| contains(&b, sep, v).unwrap();
                assert_offers_are(&c, e, inside, &format!("case {case} {sep:?} {b:?}"));
                let mut s = Offers::default();
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
        let flat = Cuboid {
            min: [0; 3],
            max: [v, 0, v],
        };
        assert_refused(surface, &flat, VoxelizeError::Degenerate);
    }
}
