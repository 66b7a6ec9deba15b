//! Sampled volume blocks: the boundary layer of a thresholded scalar grid,
//! with normals from the gray-level gradient.
//!
//! ```
//! use rrt_core::raster::Extent;
//! use rrt_core::voxelize::volume::{self, Block};
//! use rrt_core::voxelize::{Separation, Surfel, VoxelSink};
//!
//! struct Count(u64);
//! impl VoxelSink for Count {
//!     fn offer(&mut self, _: [u32; 3], _: Surfel) { self.0 += 1; }
//! }
//! // A 4³ block with a 2³ bright core, placed at voxel (1, 1, 1).
//! let mut s = [0u16; 64];
//! for z in 1..3 { for y in 1..3 { for x in 1..3 { s[x + 4 * (y + 4 * z)] = 1000; } } }
//! let b = Block { samples: &s, dims: [4, 4, 4], offset: [1, 1, 1] };
//! let mut n = Count(0);
//! volume::boundary(&b, 500, Separation::TwentySix, Extent::cube(8).unwrap(), &mut n).unwrap();
//! assert_eq!(n.0, 8); // every core voxel touches the dark shell
//! ```
//!
//! # Which voxels
//! One sample is one voxel; the block's sample `(i, j, k)` lands on voxel
//! `offset + (i, j, k)`. A sample at or above the threshold is *inside*;
//! samples outside the block count as below it, so the object is closed
//! at the block's faces. The voxels offered are the inside voxels with an
//! outside neighbour: a 26-neighbour for [`Separation::TwentySix`] (the
//! boundary layer of the paper), a 6-neighbour for [`Separation::Six`].
//! Any discrete ray of the matching connectivity leaving the inside set
//! passes such a voxel, so the layer is tunnel-free by construction.
//!
//! # Attributes
//! The normal is the negated gray-level gradient (pointing from high to low
//! values) of a Zucker–Hummel operator over the 3×3×3 neighbourhood (the
//! paper's variation of Tiede et al.'s gray-level gradient): each axis
//! differences the two opposite 3×3 faces with weights 1, 1/√2, 1/√3 for
//! face, edge and corner neighbours (integers 256, 181, 148). The distance
//! estimates `(value − threshold) / |gradient|`, clamped to one voxel.
//!
//! # Accepted input and cost
//! `samples.len()` must equal the product of `dims`
//! ([`VoxelizeError::LengthMismatch`]); offsets within
//! [`COORD_LIMIT`] voxels. Work is linear in the
//! samples of the block that fall inside the raster (the input), with a
//! constant per sample.

use super::error::{COORD_LIMIT, VoxelizeError};
use super::fixmath::{Counter, V, dist_u32, dot, isqrt, unit, window};
use super::{NORMAL_ONE, Separation, Surfel, VoxelSink};
use crate::raster::Extent;

/// A block of samples, x fastest (`samples[i + nx·(j + ny·k)]`), placed at
/// an integer voxel offset in the raster.
#[derive(Clone, Copy, Debug)]
pub struct Block<'a, T> {
    /// The samples.
    pub samples: &'a [T],
    /// `[nx, ny, nz]` samples.
    pub dims: [u32; 3],
    /// Voxel coordinates of sample `(0, 0, 0)` (may be negative).
    pub offset: [i64; 3],
}

/// Zucker–Hummel weights for face, edge and corner neighbours (×256).
const W: [i64; 3] = [256, 181, 148];

/// Voxelizes the boundary layer of `block` thresholded at `threshold`,
/// clipped to `extent`. Returns the number of offers (each voxel once).
///
/// # Errors
/// [`VoxelizeError::LengthMismatch`] when the sample count is not
/// `nx·ny·nz`, [`VoxelizeError::OutOfRange`] for offsets beyond
/// [`COORD_LIMIT`] voxels.
pub fn boundary<T, S>(
    block: &Block<'_, T>,
    threshold: T,
    separation: Separation,
    extent: Extent,
    sink: &mut S,
) -> Result<u64, VoxelizeError>
where
    T: Copy + Into<i64>,
    S: VoxelSink + ?Sized,
{
    let [bx, by, bz] = block.dims.map(|d| usize::try_from(d).unwrap_or(usize::MAX));
    let count = bx
        .checked_mul(by)
        .and_then(|p| p.checked_mul(bz))
        .ok_or(VoxelizeError::LengthMismatch)?;
    if count != block.samples.len() {
        return Err(VoxelizeError::LengthMismatch);
    }
    if block
        .offset
        .iter()
        .any(|o| o.unsigned_abs() > COORD_LIMIT.unsigned_abs())
    {
        return Err(VoxelizeError::OutOfRange);
    }
    let thr: i64 = threshold.into();
    let g = Grid {
        s: block.samples,
        n: block.dims.map(i64::from),
        below: thr.saturating_sub(1),
    };
    // Block sample range that lands inside the raster (along z, inside
    // the sink's layers), per axis.
    let win = window(extent, sink);
    let mut lo = [0i64; 3];
    let mut hi = [0i64; 3];
    for k in 0..3 {
        let (start, end) = win[k];
        lo[k] = i64::from(start).saturating_sub(block.offset[k]).max(0);
        hi[k] = (i64::from(end).saturating_sub(block.offset[k])).min(g.n[k]);
        if lo[k] >= hi[k] {
            return Ok(0);
        }
    }
    let mut n = Counter::default();
    for k in lo[2]..hi[2] {
        for j in lo[1]..hi[1] {
            for i in lo[0]..hi[0] {
                let f = g.at(i, j, k);
                if f < thr {
                    continue;
                }
                let edge = match separation {
                    Separation::Six => [
                        [1, 0, 0],
                        [-1, 0, 0],
                        [0, 1, 0],
                        [0, -1, 0],
                        [0, 0, 1],
                        [0, 0, -1],
                    ]
                    .iter()
                    .any(|d| {
                        g.at(
                            i.saturating_add(d[0]),
                            j.saturating_add(d[1]),
                            k.saturating_add(d[2]),
                        ) < thr
                    }),
                    Separation::TwentySix => (-1..=1i64).any(|dz| {
                        (-1..=1i64).any(|dy| {
                            (-1..=1i64).any(|dx| {
                                g.at(
                                    i.saturating_add(dx),
                                    j.saturating_add(dy),
                                    k.saturating_add(dz),
                                ) < thr
                            })
                        })
                    }),
                };
                if !edge {
                    continue;
                }
                let v = [i, j, k]
                    .into_iter()
                    .zip(block.offset)
                    .map(|(a, o)| a.saturating_add(o));
                let mut c = [0u32; 3];
                for (slot, x) in c.iter_mut().zip(v) {
                    *slot = u32::try_from(x).unwrap_or(u32::MAX);
                }
                if !extent.contains(c) {
                    continue;
                }
                let s = if sink.reads_surfels() {
                    g.surfel(i, j, k, f, thr)
                } else {
                    Surfel::NONE
                };
                sink.offer(c, s);
                n.bump();
            }
        }
    }
    Ok(n.0)
}

struct Grid<'a, T> {
    s: &'a [T],
    n: [i64; 3],
    /// Value of samples outside the block: just below the threshold.
    below: i64,
}

impl<T: Copy + Into<i64>> Grid<'_, T> {
    #[inline]
    fn at(&self, i: i64, j: i64, k: i64) -> i64 {
        if i < 0 || j < 0 || k < 0 || i >= self.n[0] || j >= self.n[1] || k >= self.n[2] {
            return self.below;
        }
        // In range: the index is below the slice length, which fits usize.
        let idx = i.saturating_add(
            self.n[0].saturating_mul(j.saturating_add(self.n[1].saturating_mul(k))),
        );
        usize::try_from(idx)
            .ok()
            .and_then(|x| self.s.get(x))
            .map_or(self.below, |v| (*v).into())
    }

    fn surfel(&self, i: i64, j: i64, k: i64, f: i64, thr: i64) -> Surfel {
        let mut grad = [0i128; 3];
        for dz in -1..=1i64 {
            for dy in -1..=1i64 {
                for dx in -1..=1i64 {
                    let d = [dx, dy, dz];
                    let v = i128::from(self.at(
                        i.saturating_add(dx),
                        j.saturating_add(dy),
                        k.saturating_add(dz),
                    ));
                    for (axis, gslot) in grad.iter_mut().enumerate() {
                        let s = d.get(axis).copied().unwrap_or(0);
                        if s == 0 {
                            continue;
                        }
                        // Other two offsets decide face/edge/corner weight.
                        let off = d
                            .iter()
                            .enumerate()
                            .filter(|(a, x)| *a != axis && **x != 0)
                            .count();
                        let w = i128::from(W.get(off).copied().unwrap_or(0));
                        // |v| < 2^63, w < 2^9: the sum of 18 terms fits.
                        *gslot =
                            gslot.saturating_add(w.saturating_mul(v).saturating_mul(i128::from(s)));
                    }
                }
            }
        }
        let neg = grad.map(i128::saturating_neg);
        let Some(normal) = unit(neg) else {
            return Surfel {
                normal: [0, 0, NORMAL_ONE],
                distance: 0,
            };
        };
        // |∇f| per voxel = |grad| / (2·1572); distance = (f − thr)/|∇f|.
        let g2 = dot(grad, grad);
        let glen = isqrt(g2).max(1);
        let excess = i128::from(f.saturating_sub(thr));
        let d = excess
            .saturating_mul(2 * 1572)
            .saturating_mul(V)
            .checked_div(glen)
            .unwrap_or(V);
        Surfel {
            normal,
            distance: dist_u32(d.min(V)),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testkit::Offers;
    use std::vec::Vec;

    #[test]
    fn ball_boundary_and_normals() {
        // A smooth radial field: value = 4000 − 100·r², r measured from the
        // block's centre (7.5, 7.5, 7.5); threshold 1500 (r = 5): the layer
        // is a spherical shell with outward normals. Doubled coordinates
        // keep everything integral.
        let n = 16u32;
        let r2x4 = |p: [u32; 3]| {
            p.iter()
                .map(|c| (2 * i64::from(*c) - 15).pow(2))
                .sum::<i64>()
        };
        let mut s = Vec::new();
        for k in 0..n {
            for j in 0..n {
                for i in 0..n {
                    s.push(u16::try_from((4000 - 25 * r2x4([i, j, k])).max(0)).unwrap());
                }
            }
        }
        let b = Block {
            samples: &s,
            dims: [n; 3],
            offset: [-2, 3, 0],
        };
        let e = Extent::cube(24).unwrap();
        let one = i128::from(NORMAL_ONE);
        for sep in [Separation::Six, Separation::TwentySix] {
            let mut c = Offers::default();
            boundary(&b, 1500u16, sep, e, &mut c).unwrap();
            assert!(c.0.len() > 100);
            assert!(c.0.values().all(|o| o.1 == 1), "a voxel offered twice");
            for (v, (sf, _)) in &c.0 {
                let p = [v[0] + 2, v[1] - 3, v[2]];
                let w = p.map(|c| i128::from(2 * i64::from(c) - 15));
                let len2: i128 = w.iter().map(|x| x * x).sum();
                // Inside r = 5 (doubled: 10), outside r = 3.2.
                assert!(len2 <= 100 && len2 > 40, "{v:?}");
                // cos(normal, radial) > 0.95.
                let dot: i128 = (0..3).map(|k| w[k] * i128::from(sf.normal[k])).sum();
                assert!(
                    dot > 0 && dot * dot * 10_000 > 9_025 * len2 * one * one,
                    "{v:?} {sf:?}"
                );
                assert!(sf.distance <= 65536);
            }
        }
        // Clipped: a block hanging off the raster offers only inside voxels.
        let b = Block {
            samples: &s,
            dims: [n; 3],
            offset: [-10, -10, -10],
        };
        let mut c = Offers::default();
        boundary(
            &b,
            1500u16,
            Separation::Six,
            Extent::cube(4).unwrap(),
            &mut c,
        )
        .unwrap();
        assert!(c.0.keys().all(|v| v.iter().all(|x| *x < 4)));
        let bad = Block {
            samples: &s[..5],
            dims: [n; 3],
            offset: [0; 3],
        };
        assert_eq!(
            boundary(&bad, 1u16, Separation::Six, e, &mut c),
            Err(VoxelizeError::LengthMismatch)
        );
    }
}
