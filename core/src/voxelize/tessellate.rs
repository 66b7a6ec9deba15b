//! Shared machinery of the surfaces voxelized through a fine integer
//! tessellation (cones, tori, Bézier patches): exact rational points on the
//! unit circle, orthonormal frames, tessellation density, and an emitter
//! that voxelizes triangles with [`Tri`], skipping those far from the
//! raster.
//!
//! A tessellation whose neighbouring triangles share their vertices exactly
//! (every vertex is a deterministic integer function of its grid indices)
//! is a closed mesh when the surface is closed, so the lattice-step rule of
//! [`super::triangle`] makes its voxelization tunnel-free.

use super::error::VoxelizeError;
use super::fixmath::{Counter, V, bounds, cross, isqrt, least_axis, low, round_div, unit, window};
use super::triangle::Tri;
use super::{Separation, Surfel, VoxelSink};
use crate::geometry::UnitVector;
use crate::raster::Extent;

/// Largest number of segments per quarter circle (so a full circle has at
/// most 4096 chords). Objects so large that this cannot meet the chord
/// tolerance get a coarser (still closed) tessellation.
pub(crate) const MAX_QUARTER: u32 = 1024;

/// Chord tolerance of the tessellations: 1/16 voxel.
pub(crate) const CHORD: i128 = V / 16;

/// Point `j` (`0 <= j < 4m`) of the unit circle as `(cos·d, sin·d, d)`:
/// exact rationals from `t = u/m` on each quarter, `(m² − u², 2um) / (m² +
/// u²)`, rotated by `j / m` quarter turns. Consecutive points are at most
/// `2/m` radians apart.
pub(crate) fn circle(j: u32, m: u32) -> [i128; 3] {
    let m = m.max(1);
    let q = j.checked_div(m).unwrap_or(0).checked_rem(4).unwrap_or(0);
    let u = i128::from(j.checked_rem(m).unwrap_or(0));
    let mm = i128::from(m);
    // m ≤ 2^10: every term below 2^21.
    let c = mm.saturating_mul(mm).saturating_sub(u.saturating_mul(u));
    let s = u.saturating_mul(mm).saturating_mul(2);
    let d = mm.saturating_mul(mm).saturating_add(u.saturating_mul(u));
    match q {
        0 => [c, s, d],
        1 => [s.saturating_neg(), c, d],
        2 => [c.saturating_neg(), s.saturating_neg(), d],
        _ => [s, c.saturating_neg(), d],
    }
}

/// Segments per quarter circle so that chords of a circle of `radius`
/// deviate at most [`CHORD`] from it: the sagitta of a chord spanning
/// `2/m` radians is at most `radius / (2m²)`.
pub(crate) fn quarter_segments(radius: i128) -> u32 {
    let need = isqrt(
        radius
            .max(0)
            .checked_div(CHORD.saturating_mul(2))
            .unwrap_or(0)
            .saturating_add(1),
    )
    .saturating_add(1);
    u32::try_from(need.clamp(2, i128::from(MAX_QUARTER))).unwrap_or(MAX_QUARTER)
}

/// An orthonormal frame `(u, v, w)` scaled by `2^30` with `w` along `axis`:
/// `None` for a zero axis.
pub(crate) fn frame(axis: [i128; 3]) -> Option<[[i128; 3]; 3]> {
    let w = unit(axis)?.map(i128::from);
    let u = unit(cross(w, least_axis(w)))?.map(i128::from);
    let v = unit(cross(w, u))?.map(i128::from);
    Some([u, v, w])
}

/// The point at angle `p = circle(j, m)` on the circle of radius `r`
/// around `c` in the plane of the frame vectors `u`, `v` (`2^30`-scaled):
/// `c + r·(cos·u + sin·v)`, each component rounded.
pub(crate) fn ring_point(c: [i128; 3], [u, v]: [[i128; 3]; 2], r: i128, p: [i128; 3]) -> [i128; 3] {
    let [cs, sn, d] = p;
    // r < 2^41, cs, sn < 2^21, u, v ≤ 2^30: products < 2^92.
    [0, 1, 2].map(|k| {
        let x = cs
            .saturating_mul(u[k])
            .saturating_add(sn.saturating_mul(v[k]));
        c[k].saturating_add(round_div(r.saturating_mul(x), d.saturating_mul(1 << 30)))
    })
}

/// Voxelizes triangles of a tessellation into a sink.
pub(crate) struct Emitter<'a, S: ?Sized> {
    pub(crate) sep: Separation,
    pub(crate) extent: Extent,
    pub(crate) sink: &'a mut S,
    pub(crate) n: Counter,
    /// The box of the cells scanned (the raster, along z the sink's
    /// layers) grown by one voxel, for culling.
    lo: [i128; 3],
    hi: [i128; 3],
}

impl<'a, S: VoxelSink + ?Sized> Emitter<'a, S> {
    pub(crate) fn new(sep: Separation, extent: Extent, sink: &'a mut S) -> Self {
        let win = window(extent, sink);
        Self {
            sep,
            extent,
            sink,
            n: Counter::default(),
            lo: win.map(|(start, _)| low(start).saturating_sub(V)),
            hi: win.map(|(_, end)| low(end).saturating_add(V)),
        }
    }

    /// Whether the box `[lo, hi]` (grown by `reach`) misses the raster.
    pub(crate) fn culled(&self, lo: [i128; 3], hi: [i128; 3], reach: i128) -> bool {
        (0..3).any(|k| {
            hi.get(k).copied().unwrap_or(0).saturating_add(reach)
                < self.lo.get(k).copied().unwrap_or(0)
                || lo.get(k).copied().unwrap_or(0).saturating_sub(reach)
                    > self.hi.get(k).copied().unwrap_or(0)
        })
    }

    /// Voxelizes triangle `p` (skipped when degenerate or far from the
    /// raster) with surfels from `surfel`.
    pub(crate) fn tri<F>(
        &mut self,
        p: [[i128; 3]; 3],
        normals: Option<[UnitVector; 3]>,
        surfel: &F,
    ) -> Result<(), VoxelizeError>
    where
        F: Fn(&Tri, [u32; 3]) -> Surfel,
    {
        let (lo, hi) = bounds(&p);
        if self.culled(lo, hi, 0) {
            return Ok(());
        }
        match Tri::from_points(p, normals) {
            Ok(t) => t.scan_with(self.sep, self.extent, self.sink, &mut self.n, surfel, false),
            Err(VoxelizeError::Degenerate) => Ok(()),
            Err(e) => Err(e),
        }
    }

    /// Voxelizes the quad `p00, p10, p11, p01` as two triangles.
    pub(crate) fn quad<F>(
        &mut self,
        q: [[i128; 3]; 4],
        normals: Option<[UnitVector; 4]>,
        surfel: &F,
    ) -> Result<(), VoxelizeError>
    where
        F: Fn(&Tri, [u32; 3]) -> Surfel,
    {
        let [a, b, c, d] = q;
        let (na, nb) = match normals {
            Some([x, y, z, w]) => (Some([x, y, z]), Some([x, z, w])),
            None => (None, None),
        };
        self.tri([a, b, c], na, surfel)?;
        self.tri([a, c, d], nb, surfel)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::voxelize::fixmath::dot;

    #[test]
    fn circle_points_are_on_the_circle_and_close() {
        let m = 7u32;
        let mut prev = circle(4 * m - 1, m);
        for j in 0..4 * m {
            let [c, s, d] = circle(j, m);
            assert_eq!(c * c + s * s, d * d);
            // Chord to the previous point: 0 < gap ≤ 2/m (cross-multiplied).
            let [pc, ps, pd] = prev;
            let gx = c * pd - pc * d;
            let gy = s * pd - ps * d;
            let g2 = gx * gx + gy * gy;
            let mm = i128::from(m);
            assert!(g2 > 0 && g2 * mm * mm <= 4 * d * d * pd * pd, "{j}");
            prev = [c, s, d];
        }
        assert!(quarter_segments(100 * V) >= 20);
        assert_eq!(quarter_segments(i128::MAX), MAX_QUARTER);
    }

    #[test]
    fn frames_are_orthonormal() {
        for a in [[0, 0, 5], [3, -4, 12], [1 << 40, 1, -(1 << 39)]] {
            let [u, v, w] = frame(a).unwrap();
            let one = 1i128 << 30;
            for (x, y, want) in [
                (u, u, one * one),
                (v, v, one * one),
                (w, w, one * one),
                (u, v, 0),
                (u, w, 0),
                (v, w, 0),
            ] {
                assert!((dot(x, y) - want).abs() < one * 8, "{a:?}");
            }
        }
        assert!(frame([0, 0, 0]).is_none());
    }
}
