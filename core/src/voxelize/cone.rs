//! Cones and cylinders ([`Cone`], NFF `c`): the open lateral surface, as in
//! the SPD, and the capped variant, a closed solid made of the lateral
//! surface and the two end discs.
//!
//! ```
//! use rrt_core::fixed::{voxel_centre, VOXEL};
//! use rrt_core::geometry::Cone;
//! use rrt_core::raster::Extent;
//! use rrt_core::voxelize::{cone, Separation, Surfel, VoxelSink};
//!
//! struct Count(u64);
//! impl VoxelSink for Count {
//!     fn offer(&mut self, _: [u32; 3], _: Surfel) { self.0 += 1; }
//! }
//! let c = voxel_centre(8);
//! let cyl = Cone { base: [c, c, 2 * VOXEL], base_radius: 4 * VOXEL, apex: [c, c, 14 * VOXEL], apex_radius: 4 * VOXEL };
//! let (mut open, mut closed) = (Count(0), Count(0));
//! let e = Extent::cube(16).unwrap();
//! cone::surface(&cyl, Separation::Six, e, &mut open).unwrap();
//! cone::capped(&cyl, Separation::Six, e, &mut closed).unwrap();
//! assert!(closed.0 > open.0);
//! ```
//!
//! # Which voxels
//! The surface is tessellated into a closed ring of planar trapezoids (the
//! generators are straight, so only the circles are approximated, by chords
//! within 1/16 voxel: exact rational points on the circle, see
//! `tessellate.rs`), and each triangle is voxelized by the lattice-step rule
//! of [`super::triangle`]. Rim vertices are shared exactly with the discs'
//! fans, so the capped cone is a closed mesh and its voxelization is
//! tunnel-free. Surfels are exact: the distance from the voxel centre to
//! the true cone (and discs), and the outward normal of the generator (or
//! disc) at the nearest point.
//!
//! # Accepted input and cost
//! Coordinates and radii within [`COORD_LIMIT`](super::error::COORD_LIMIT);
//! radii ≥ 0 and not both 0 ([`VoxelizeError::NonPositiveRadius`]); distinct
//! base and apex ([`VoxelizeError::Degenerate`]). At most 4096 chords per
//! circle (coarser for cones wider than about 2^23 voxels). Work is a
//! constant per chord plus the triangles' voxels.

use core::cell::Cell;

use super::error::VoxelizeError;
use super::fixmath::{
    H, bounds, centre, check_coord, check_point, dist_u32, div_trunc, dot, isqrt, sub, sub_along,
    unit,
};
use super::tessellate::{Emitter, circle, frame, quarter_segments, ring_point};
use super::triangle::Tri;
use super::{NORMAL_ONE, Separation, Surfel, VoxelSink};
use crate::geometry::Cone;
use crate::raster::Extent;

/// Voxelizes the open lateral surface of `cone` (no caps), clipped to
/// `extent`. Returns the number of offers (voxels along the chords between
/// trapezoids are offered once per trapezoid that reaches them).
///
/// # Errors
/// See the module documentation.
pub fn surface<S: VoxelSink + ?Sized>(
    cone: &Cone,
    separation: Separation,
    extent: Extent,
    sink: &mut S,
) -> Result<u64, VoxelizeError> {
    run(cone, separation, extent, sink, false)
}

/// Voxelizes the closed capped cone: the lateral surface plus the base and
/// apex discs (a disc of radius 0 is left out: the cone closes in its apex).
///
/// # Errors
/// See the module documentation.
pub fn capped<S: VoxelSink + ?Sized>(
    cone: &Cone,
    separation: Separation,
    extent: Extent,
    sink: &mut S,
) -> Result<u64, VoxelizeError> {
    run(cone, separation, extent, sink, true)
}

/// The validated cone in a frame `(u, v, w)`, `w` from base to apex.
pub(crate) struct Geo {
    b: [i128; 3],
    a: [i128; 3],
    r0: i128,
    r1: i128,
    frame: [[i128; 3]; 3],
    /// `|apex − base|`.
    len: i128,
    caps: bool,
}

impl Geo {
    fn new(c: &Cone, caps: bool) -> Result<Self, VoxelizeError> {
        let b = check_point(c.base)?;
        let a = check_point(c.apex)?;
        if c.base_radius < 0 || c.apex_radius < 0 || (c.base_radius == 0 && c.apex_radius == 0) {
            return Err(VoxelizeError::NonPositiveRadius);
        }
        let r0 = check_coord(c.base_radius)?;
        let r1 = check_coord(c.apex_radius)?;
        let axis = sub(a, b);
        let frame = frame(axis).ok_or(VoxelizeError::Degenerate)?;
        let len = isqrt(dot(axis, axis));
        Ok(Self {
            b,
            a,
            r0,
            r1,
            frame,
            len,
            caps,
        })
    }

    /// Point `j` of the circle of radius `r` around `c`.
    fn ring(&self, c: [i128; 3], r: i128, j: u32, m: u32) -> [i128; 3] {
        let [u, v, _] = self.frame;
        ring_point(c, [u, v], r, circle(j, m))
    }

    /// Exact surfel of voxel `v`: nearest point on the lateral surface (and
    /// on the discs, when capped).
    pub(crate) fn surfel(&self, v: [u32; 3]) -> Surfel {
        let c = v.map(centre);
        let [u, _, w] = self.frame;
        let p = sub(c, self.b);
        let t = dot(p, w) >> 30;
        let rho = isqrt(dot(p, p).saturating_sub(t.saturating_mul(t)).max(0));
        let radial = sub_along(p, w, t);
        let rhat = unit(radial).map_or(u, |r| r.map(i128::from));
        // Lateral: 2D segment (0, r0) – (len, r1) in (t, rho).
        let (gt, gr) = (self.len, self.r1.saturating_sub(self.r0));
        let g2 = gt
            .saturating_mul(gt)
            .saturating_add(gr.saturating_mul(gr))
            .max(1);
        let s = t
            .saturating_mul(gt)
            .saturating_add(rho.saturating_sub(self.r0).saturating_mul(gr))
            .clamp(0, g2);
        let qt = div_trunc(gt.saturating_mul(s), g2).unwrap_or(0);
        let qr = self
            .r0
            .saturating_add(div_trunc(gr.saturating_mul(s), g2).unwrap_or(0));
        let (dt, dr) = (t.saturating_sub(qt), rho.saturating_sub(qr));
        let mut best_d = isqrt(dt.saturating_mul(dt).saturating_add(dr.saturating_mul(dr)));
        // Outward generator normal: (−gr, gt) in (t, rho).
        let lateral = [0, 1, 2].map(|k| {
            gr.saturating_neg()
                .saturating_mul(w[k])
                .saturating_add(gt.saturating_mul(rhat[k]))
        });
        let mut best_n = unit(lateral).unwrap_or([0, 0, NORMAL_ONE]);
        if self.caps {
            for (at, r, sign) in [(0i128, self.r0, -1i128), (self.len, self.r1, 1)] {
                if r <= 0 {
                    continue;
                }
                let dz = t.saturating_sub(at);
                let over = rho.saturating_sub(r).max(0);
                let d = isqrt(
                    dz.saturating_mul(dz)
                        .saturating_add(over.saturating_mul(over)),
                );
                if d < best_d {
                    best_d = d;
                    best_n = w.map(|x| i32::try_from(x.saturating_mul(sign)).unwrap_or(0));
                }
            }
        }
        Surfel {
            normal: best_n,
            distance: dist_u32(best_d),
        }
    }
}

/// Bits of the number of surfels [`run`] keeps.
const MEMO_BITS: u32 = 8;
/// Surfels [`run`] keeps.
const MEMO: usize = 1 << MEMO_BITS;

fn run<S: VoxelSink + ?Sized>(
    cone: &Cone,
    sep: Separation,
    extent: Extent,
    sink: &mut S,
    caps: bool,
) -> Result<u64, VoxelizeError> {
    let g = Geo::new(cone, caps)?;
    let m = quarter_segments(g.r0.max(g.r1));
    let mut em = Emitter::new(sep, extent, sink);
    // Whole-cone cull: the bounding box of both end discs.
    let reach = g.r0.max(g.r1).saturating_add(H);
    let (lo, hi) = bounds(&[g.b, g.a]);
    if em.culled(lo, hi, reach) {
        return Ok(0);
    }
    // A voxel near a generator or the rim is offered by each triangle that
    // reaches it, and its surfel depends on the voxel alone: the last few
    // hundred are kept (direct-mapped; a key outside any raster marks an
    // empty slot).
    let memo: [Cell<([u32; 3], Surfel)>; MEMO] =
        core::array::from_fn(|_| Cell::new(([u32::MAX; 3], Surfel::NONE)));
    let f = |_: &Tri, v: [u32; 3]| {
        let slot = v[0]
            .wrapping_mul(0x9e37_79b1)
            .wrapping_add(v[1].wrapping_mul(0x85eb_ca77))
            .wrapping_add(v[2].wrapping_mul(0xc2b2_ae3d))
            >> (32 - MEMO_BITS);
        let Some(cell) = memo.get(crate::raster::to_usize(slot)) else {
            return g.surfel(v);
        };
        let (key, kept) = cell.get();
        if key == v {
            return kept;
        }
        let s = g.surfel(v);
        cell.set((v, s));
        s
    };
    let total = m.saturating_mul(4);
    // Each rim point once: a chord's end is the next chord's start.
    let (first_b, first_a) = (g.ring(g.b, g.r0, 0, m), g.ring(g.a, g.r1, 0, m));
    let (mut b0, mut a0) = (first_b, first_a);
    for j in 0..total {
        let j1 = j.saturating_add(1);
        let (b1, a1) = if j1 == total {
            (first_b, first_a)
        } else {
            (g.ring(g.b, g.r0, j1, m), g.ring(g.a, g.r1, j1, m))
        };
        em.quad([b0, b1, a1, a0], None, &f)?;
        if caps {
            if g.r0 > 0 {
                em.tri([g.b, b1, b0], None, &f)?;
            }
            if g.r1 > 0 {
                em.tri([g.a, a0, a1], None, &f)?;
            }
        }
        (b0, a0) = (b1, a1);
    }
    Ok(em.n.0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fixed::VOXEL;
    use crate::testkit::{Offers, assert_refused, voxelized_in_4};
    use crate::voxelize::fixmath::V;

    #[test]
    fn cylinder_shell_is_thin_and_surfels_are_exact() {
        let c = 10 * VOXEL + 1234;
        let r = 6 * VOXEL + 777;
        let cyl = Cone {
            base: [c, c, 2 * VOXEL],
            base_radius: r,
            apex: [c, c, 18 * VOXEL],
            apex_radius: r,
        };
        let e = Extent::cube(21).unwrap();
        let one = i128::from(NORMAL_ONE);
        for sep in [Separation::Six, Separation::TwentySix] {
            let mut col = Offers::default();
            surface(&cyl, sep, e, &mut col).unwrap();
            for (v, (s, _)) in &col.0 {
                let z = centre(v[2]);
                if !(2 * V..=18 * V).contains(&z) {
                    continue;
                }
                let dx = centre(v[0]) - i128::from(c);
                let dy = centre(v[1]) - i128::from(c);
                let rho = isqrt(dx * dx + dy * dy);
                let want = (rho - i128::from(r)).abs();
                assert!(
                    (i128::from(s.distance) - want).abs() < 4,
                    "{v:?} {s:?} {want}"
                );
                // Within half a voxel diagonal (+ chord tolerance).
                assert!(want <= 57_000 + 4096, "{sep:?}: {v:?} too far: {want}");
                // Radial normal: cos > 0.999.
                let dot = dx * i128::from(s.normal[0]) + dy * i128::from(s.normal[1]);
                assert!(dot * 1000 > 999 * rho * one, "{v:?} {s:?}");
            }
        }
    }

    #[test]
    fn bad_input() {
        let z = Cone {
            base: [0; 3],
            base_radius: 0,
            apex: [0, 0, VOXEL],
            apex_radius: 0,
        };
        assert_refused(surface, &z, VoxelizeError::NonPositiveRadius);
        let n = Cone {
            base_radius: -1,
            apex_radius: 5,
            ..z
        };
        assert_refused(capped, &n, VoxelizeError::NonPositiveRadius);
        let d = Cone {
            base_radius: 9,
            apex: [0; 3],
            apex_radius: 5,
            ..z
        };
        assert_refused(surface, &d, VoxelizeError::Degenerate);
        let far = Cone {
            base: [1 << 40; 3],
            base_radius: 1 << 40,
            apex: [-(1 << 40); 3],
            apex_radius: 1 << 39,
        };
        assert!(voxelized_in_4(capped, &far, Separation::TwentySix).is_ok());
    }
}
