//! 3D line segments: 6-connected and 26-connected digital lines.
//!
//! ```
//! use rrt_core::fixed::voxel_centre;
//! use rrt_core::geometry::Segment;
//! use rrt_core::raster::Extent;
//! use rrt_core::voxelize::{line, Separation, Surfel, VoxelSink};
//!
//! struct Count(u64);
//! impl VoxelSink for Count {
//!     fn offer(&mut self, _: [u32; 3], _: Surfel) { self.0 += 1; }
//! }
//! let c = |v: [u32; 3]| v.map(voxel_centre);
//! let s = Segment { a: c([1, 2, 3]), b: c([9, 4, 6]) };
//! let e = Extent::cube(16).unwrap();
//! let (mut six, mut tws) = (Count(0), Count(0));
//! line::segment(&s, Separation::Six, e, &mut six).unwrap();
//! line::segment(&s, Separation::TwentySix, e, &mut tws).unwrap();
//! assert_eq!((six.0, tws.0), (1 + 8 + 2 + 3, 1 + 8));
//! ```
//!
//! A line is not a surface: here the separation selects the line's
//! connectivity. [`Separation::Six`] gives the 6-connected line, every voxel
//! holding points of the segment on an interval of positive length (the
//! voxels a 6-connected discrete ray visits; where the segment crosses a
//! voxel edge or corner exactly, the intermediate voxels are included, x
//! before y before z). [`Separation::TwentySix`] gives the 26-connected
//! line, one voxel per slice across the driving axis (the largest `|b − a|`
//! component): the voxel holding the segment point at the slice's centre
//! plane (clamped to the segment's ends).
//!
//! The surfel of a line voxel has the distance from the voxel centre to the
//! segment and, as normal, the direction from the segment's nearest point
//! to the centre (a perpendicular when the centre lies on the segment).
//!
//! # Accepted input and cost
//! Coordinates within [`COORD_LIMIT`](super::error::COORD_LIMIT). The
//! segment is clipped to the raster box first, so work is linear in the
//! voxels offered (plus a logarithmic term for the 26-connected clip).

use super::error::VoxelizeError;
use super::fixmath::{
    Counter, H, V, centre, check_point, cross, dist_u32, dot, least_axis, length, sub, unit,
};
use super::{NORMAL_ONE, Separation, Surfel, VoxelSink};
use crate::geometry::Segment;
use crate::raster::Extent;

/// Voxelizes `segment` as a 6- or 26-connected line, clipped to `extent`.
/// Returns the number of offers (each voxel once).
///
/// # Errors
/// [`VoxelizeError::OutOfRange`] beyond
/// [`COORD_LIMIT`](super::error::COORD_LIMIT).
pub fn segment<S: VoxelSink + ?Sized>(
    segment: &Segment,
    separation: Separation,
    extent: Extent,
    sink: &mut S,
) -> Result<u64, VoxelizeError> {
    let a = check_point(segment.a)?;
    let b = check_point(segment.b)?;
    let l = Line { a, b, d: sub(b, a) };
    let dims = extent.dims();
    let size = dims.map(super::fixmath::low);
    let mut n = Counter::default();
    if l.d == [0; 3] {
        if a.iter().zip(size).all(|(p, s)| *p >= 0 && *p < s) {
            let v = a.map(|p| u32::try_from(super::fixmath::cell_floor(p)).unwrap_or(0));
            l.offer(v, extent, sink, &mut n);
        }
        return Ok(n.0);
    }
    // Clip t ∈ [0, 1] to the box [0, size] per axis: t = num / den rationals.
    let mut t_in = (0i128, 1i128);
    let mut t_out = (1i128, 1i128);
    for k in 0..3 {
        let (p, dk) = (a[k], l.d[k]);
        if dk == 0 {
            if p < 0 || p >= size[k] {
                return Ok(0);
            }
            continue;
        }
        let (enter, exit) = if dk > 0 { (0, size[k]) } else { (size[k], 0) };
        let (ad, sgn) = (dk.saturating_abs(), dk.signum());
        let te = (enter.saturating_sub(p).saturating_mul(sgn), ad);
        let tx = (exit.saturating_sub(p).saturating_mul(sgn), ad);
        if less(t_in, te) {
            t_in = te;
        }
        if less(tx, t_out) {
            t_out = tx;
        }
    }
    if !less(t_in, t_out) {
        return Ok(0);
    }
    match separation {
        Separation::Six => l.six(t_in, t_out, extent, sink, &mut n),
        Separation::TwentySix => l.twenty_six(t_in, t_out, extent, sink, &mut n),
    }
    Ok(n.0)
}

/// `p < q` for rationals with positive denominators (< 2^43 each, numerators
/// < 2^43: the products fit).
fn less(p: (i128, i128), q: (i128, i128)) -> bool {
    p.0.saturating_mul(q.1) < q.0.saturating_mul(p.1)
}

struct Line {
    a: [i128; 3],
    b: [i128; 3],
    d: [i128; 3],
}

impl Line {
    fn offer<S: VoxelSink + ?Sized>(
        &self,
        v: [u32; 3],
        extent: Extent,
        sink: &mut S,
        n: &mut Counter,
    ) {
        if extent.contains(v) {
            sink.offer(v, self.surfel(v));
            n.bump();
        }
    }

    /// Cell on axis `k` of the point at `t = num/den`, taking the cell the
    /// segment enters just after `t` when the point lies on a face.
    fn cell_at(&self, k: usize, t: (i128, i128)) -> i128 {
        // a_k·den + num·d_k over den·V; den, num < 2^43, a, d < 2^42.
        let num = self.a[k]
            .saturating_mul(t.1)
            .saturating_add(t.0.saturating_mul(self.d[k]));
        let den = t.1.saturating_mul(V);
        let q = num.checked_div_euclid(den).unwrap_or(0);
        if self.d[k] < 0 && num.checked_rem_euclid(den) == Some(0) {
            q.saturating_sub(1)
        } else {
            q
        }
    }

    fn six<S: VoxelSink + ?Sized>(
        &self,
        t_in: (i128, i128),
        t_out: (i128, i128),
        extent: Extent,
        sink: &mut S,
        n: &mut Counter,
    ) {
        let dims = extent.dims();
        let mut cell = [0, 1, 2].map(|k| self.cell_at(k, t_in));
        for (c, dim) in cell.iter_mut().zip(dims) {
            *c = (*c).clamp(0, i128::from(dim).saturating_sub(1));
        }
        // Distance from a to the next boundary along each axis, and |d|.
        let ad = self.d.map(i128::saturating_abs);
        let mut next = [0, 1, 2].map(|k| {
            let bound = if self.d[k] > 0 {
                cell[k].saturating_add(1).saturating_mul(V)
            } else {
                cell[k].saturating_mul(V)
            };
            bound.saturating_sub(self.a[k]).saturating_abs()
        });
        // At most one step per boundary crossed inside the raster.
        let budget = dims
            .iter()
            .fold(1u64, |s, d| s.saturating_add(u64::from(*d)));
        for _ in 0..budget {
            if let Ok(v) = cell_u32(cell) {
                self.offer(v, extent, sink, n);
            }
            // Axis with the earliest crossing next[k]/ad[k], lowest on ties.
            let mut best: Option<usize> = None;
            for k in 0..3 {
                if ad[k] == 0 {
                    continue;
                }
                let better = best
                    .is_none_or(|j| next[k].saturating_mul(ad[j]) < next[j].saturating_mul(ad[k]));
                if better {
                    best = Some(k);
                }
            }
            let Some(k) = best else { return };
            // Stop when that crossing is at or beyond the clipped end.
            if !less((next[k], ad[k]), t_out) {
                return;
            }
            cell[k] = cell[k].saturating_add(self.d[k].signum());
            next[k] = next[k].saturating_add(V);
        }
    }

    fn twenty_six<S: VoxelSink + ?Sized>(
        &self,
        t_in: (i128, i128),
        t_out: (i128, i128),
        extent: Extent,
        sink: &mut S,
        n: &mut Counter,
    ) {
        let ad = self.d.map(i128::saturating_abs);
        let k = if ad[0] >= ad[1] && ad[0] >= ad[2] {
            0
        } else if ad[1] >= ad[2] {
            1
        } else {
            2
        };
        // Clipped segment ends along k (as exact rationals of t).
        let (s0, s1) = (self.cell_at(k, t_in), {
            // The cell holding the point just before t_out.
            let num = self.a[k]
                .saturating_mul(t_out.1)
                .saturating_add(t_out.0.saturating_mul(self.d[k]));
            let den = t_out.1.saturating_mul(V);
            let q = num.checked_div_euclid(den).unwrap_or(0);
            if self.d[k] > 0 && num.checked_rem_euclid(den) == Some(0) {
                q.saturating_sub(1)
            } else {
                q
            }
        });
        let (lo, hi) = (s0.min(s1), s0.max(s1));
        let (amin, amax) = (self.a[k].min(self.b[k]), self.a[k].max(self.b[k]));
        let dims = extent.dims();
        let mut i = lo;
        while i <= hi {
            // Sample at the slice's centre plane, clamped to the segment.
            let s = i.saturating_mul(V).saturating_add(H).clamp(amin, amax);
            let mut v = [0i128; 3];
            for (j, slot) in v.iter_mut().enumerate() {
                *slot = if j == k {
                    i
                } else {
                    // a_j + (s − a_k)·d_j/d_k, floored to a cell.
                    let num = self.a[j]
                        .saturating_mul(self.d[k])
                        .saturating_add(s.saturating_sub(self.a[k]).saturating_mul(self.d[j]));
                    let den = self.d[k].saturating_mul(V);
                    let (num, den) = if den < 0 {
                        (num.saturating_neg(), den.saturating_neg())
                    } else {
                        (num, den)
                    };
                    num.checked_div_euclid(den).unwrap_or(0)
                };
            }
            if let Ok(c) = cell_u32(v)
                && c.iter().zip(dims).all(|(x, d)| *x < d)
            {
                self.offer(c, extent, sink, n);
            }
            i = i.saturating_add(1);
        }
    }

    fn surfel(&self, v: [u32; 3]) -> Surfel {
        let c = v.map(centre);
        let w = sub(c, self.a);
        let dd = dot(self.d, self.d).max(1);
        let wd = dot(w, self.d);
        let num = wd.clamp(0, dd);
        // Nearest point a + d·num/dd (d·num < 2^84).
        let r = [0, 1, 2].map(|k| {
            let f = self.d[k].saturating_mul(num).checked_div(dd).unwrap_or(0);
            w[k].saturating_sub(f)
        });
        let normal = unit(r)
            .or_else(|| {
                // On the segment: any perpendicular, d × (the axis of least |d|).
                unit(cross(self.d, least_axis(self.d)))
            })
            .unwrap_or([0, 0, NORMAL_ONE]);
        Surfel {
            normal,
            distance: dist_u32(length(r)),
        }
    }
}

fn cell_u32(c: [i128; 3]) -> Result<[u32; 3], core::num::TryFromIntError> {
    Ok([
        u32::try_from(c[0])?,
        u32::try_from(c[1])?,
        u32::try_from(c[2])?,
    ])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::discrete_ray::{Connectivity, DiscreteRay};
    use crate::raster::Raster;
    use crate::testkit::Rng;
    use std::vec::Vec;

    struct Collect(Vec<[u32; 3]>);
    impl VoxelSink for Collect {
        fn offer(&mut self, v: [u32; 3], _: Surfel) {
            self.0.push(v);
        }
    }

    #[test]
    fn six_line_matches_the_six_ray_and_connectivity_holds() {
        let e = Extent::new(20, 17, 15).unwrap();
        let plane = std::vec![0u8; e.len()];
        let r = Raster::new(e, &plane).unwrap();
        let mut rng = Rng(5u64);
        let mut next = |m: i64| rng.range(0, m - 1);
        for case in 0..400 {
            let snap = |x: i64| match case % 4 {
                0 => x & !0xffff,
                1 => (x & !0xffff) | 0x8000,
                _ => x,
            };
            let a = [0; 3].map(|_| snap(next(26 * 65536) - 3 * 65536));
            let b = [0; 3].map(|_| snap(next(26 * 65536) - 3 * 65536));
            let s = Segment { a, b };
            let mut six = Collect(Vec::new());
            segment(&s, Separation::Six, e, &mut six).unwrap();
            let mut tws = Collect(Vec::new());
            segment(&s, Separation::TwentySix, e, &mut tws).unwrap();
            for (line, six_conn) in [(&six.0, true), (&tws.0, false)] {
                for w in line.windows(2) {
                    let d: Vec<u32> = (0..3).map(|k| w[0][k].abs_diff(w[1][k])).collect();
                    assert!(
                        d.iter().all(|x| *x <= 1) && d.contains(&1),
                        "case {case}: {w:?}"
                    );
                    if six_conn {
                        assert_eq!(d.iter().sum::<u32>(), 1, "case {case}: {w:?}");
                    }
                }
            }
            // Away from the segment's ends the 6-line is the 6-ray's voxels.
            let inside = |p: [i64; 3]| {
                p.iter()
                    .zip(e.dims())
                    .all(|(c, n)| *c > 0 && *c < i64::from(n) * 65536)
            };
            let d: [i64; 3] = [0, 1, 2].map(|k| b[k] - a[k]);
            if inside(a) && inside(b) && d != [0; 3] {
                let ray = DiscreteRay::segment(e, a, b).unwrap();
                if let Some(ray) = ray {
                    let want: Vec<[u32; 3]> = ray
                        .voxels(&r, Connectivity::Six)
                        .unwrap()
                        .map(|v| e.coord(v.index).unwrap())
                        .collect();
                    assert_eq!(six.0, want, "case {case}: {s:?}");
                }
            }
        }
    }
}
