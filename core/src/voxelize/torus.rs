//! Tori.
//!
//! ```
//! use rrt_core::fixed::{voxel_centre, VOXEL};
//! use rrt_core::geometry::Torus;
//! use rrt_core::raster::Extent;
//! use rrt_core::voxelize::{torus, Separation, Surfel, VoxelSink, NORMAL_ONE};
//!
//! struct Count(u64);
//! impl VoxelSink for Count {
//!     fn offer(&mut self, _: [u32; 3], _: Surfel) { self.0 += 1; }
//! }
//! let t = Torus { centre: [voxel_centre(12); 3], axis: [0, 0, NORMAL_ONE], major: 7 * VOXEL, minor: 3 * VOXEL };
//! let mut n = Count(0);
//! torus::surface(&t, Separation::Six, Extent::cube(24).unwrap(), &mut n).unwrap();
//! assert!(n.0 > 500);
//! ```
//!
//! # Which voxels
//! The torus is tessellated into a closed grid of quads whose vertices are
//! exact rational circle points (chords within 1/16 voxel of each circle,
//! see `tessellate.rs`), each quad voxelized as two triangles by the
//! lattice-step rule of [`super::triangle`]: the result is tunnel-free.
//! Surfels are exact: the distance from the voxel centre to the true torus
//! and the outward normal at the nearest point. Spindle and horn tori
//! (`major ≤ minor`) are voxelized as the self-touching surface they are.
//!
//! # Accepted input and cost
//! Coordinates and radii within [`COORD_LIMIT`](super::error::COORD_LIMIT),
//! `minor > 0` and `major ≥ 0` ([`VoxelizeError::NonPositiveRadius`]), a
//! nonzero axis ([`VoxelizeError::Degenerate`]; it need not be unit). At
//! most 4096 × 4096 quads; sectors of the ring that miss the raster are
//! skipped whole, so work is a constant per sector and per quad near the
//! raster plus the voxels offered.

use super::error::VoxelizeError;
use super::fixmath::{
    V, bounds, centre, check_coord, check_point, dist_u32, dot, isqrt, round_div, sub, sub_along,
    unit,
};
use super::tessellate::{Emitter, circle, frame, quarter_segments, ring_point};
use super::triangle::Tri;
use super::{NORMAL_ONE, Separation, Surfel, VoxelSink};
use crate::geometry::Torus;
use crate::raster::Extent;

/// Voxelizes the surface of `torus`, clipped to `extent`. Returns the
/// number of offers (voxels along shared quad edges are offered once per
/// triangle that reaches them).
///
/// # Errors
/// See the module documentation.
pub fn surface<S: VoxelSink + ?Sized>(
    torus: &Torus,
    separation: Separation,
    extent: Extent,
    sink: &mut S,
) -> Result<u64, VoxelizeError> {
    let c = check_point(torus.centre)?;
    if torus.minor <= 0 || torus.major < 0 {
        return Err(VoxelizeError::NonPositiveRadius);
    }
    let big = check_coord(torus.major)?;
    let r = check_coord(torus.minor)?;
    let fr = frame(torus.axis.map(i128::from)).ok_or(VoxelizeError::Degenerate)?;
    let [u, v, w] = fr;
    let m1 = quarter_segments(big.saturating_add(r));
    let m2 = quarter_segments(r);
    let (n1, n2) = (m1.saturating_mul(4), m2.saturating_mul(4));
    let mut em = Emitter::new(separation, extent, sink);
    let outer = big.saturating_add(r);
    if em.culled(c, c, outer.saturating_add(V)) {
        return Ok(0);
    }
    // Minor circle: (radial offset, axial offset) per j.
    let minor = |j: u32| -> (i128, i128) {
        let [cs, sn, d] = circle(j, m2);
        (
            big.saturating_add(round_div(r.saturating_mul(cs), d)),
            round_div(r.saturating_mul(sn), d),
        )
    };
    let dir = |i: u32| circle(i, m1);
    let point = |i: u32, j: u32| -> [i128; 3] {
        let (rho, z) = minor(j);
        let p = ring_point(c, [u, v], rho, dir(i));
        [0, 1, 2].map(|k| p[k].saturating_add(round_div(z.saturating_mul(w[k]), 1 << 30)))
    };
    let surfel = |_: &Tri, vx: [u32; 3]| -> Surfel {
        let p = sub(vx.map(centre), c);
        let h = dot(p, w) >> 30;
        let radial = sub_along(p, w, h);
        let rhat = unit(radial).map_or(u, |x| x.map(i128::from));
        let d = sub_along(p, rhat, big);
        let len = isqrt(dot(d, d));
        Surfel {
            normal: unit(d).unwrap_or_else(|| rhat.map(|x| i32::try_from(x).unwrap_or(NORMAL_ONE))),
            distance: dist_u32(len.saturating_sub(r)),
        }
    };
    let next = |i: u32, n: u32| {
        if i.saturating_add(1) >= n {
            0
        } else {
            i.saturating_add(1)
        }
    };
    // Sector reach: tube radius plus the major chord's sagitta and a voxel.
    let reach = r
        .saturating_add(
            outer
                .checked_div(
                    i128::from(m1)
                        .saturating_mul(i128::from(m1))
                        .saturating_mul(2),
                )
                .unwrap_or(0),
        )
        .saturating_add(V);
    for i in 0..n1 {
        let i1 = next(i, n1);
        let ends = [dir(i), dir(i1)].map(|p| ring_point(c, [u, v], big, p));
        let (lo, hi) = bounds(&ends);
        if em.culled(lo, hi, reach) {
            continue;
        }
        for j in 0..n2 {
            let j1 = next(j, n2);
            em.quad(
                [point(i, j), point(i1, j), point(i1, j1), point(i, j1)],
                None,
                &surfel,
            )?;
        }
    }
    Ok(em.n.0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fixed::VOXEL;
    use crate::testkit::{assert_refused, voxelized, voxelized_in_4};

    #[test]
    fn surfels_match_the_true_torus() {
        let c = 12 * VOXEL + 321;
        let t = Torus {
            centre: [c; 3],
            axis: [0, 0, 77],
            major: 7 * VOXEL,
            minor: 3 * VOXEL + 99,
        };
        let e = Extent::cube(25).unwrap();
        let (r, col) = voxelized(surface, &t, Separation::TwentySix, e);
        r.unwrap();
        for (v, (s, _)) in &col.0 {
            let p = [0, 1, 2].map(|k| centre(v[k]) - i128::from(c));
            let rho = isqrt(p[0] * p[0] + p[1] * p[1]);
            let d = isqrt((rho - 7 * V).pow(2) + p[2] * p[2]) - (3 * V + 99);
            assert!(
                (i128::from(s.distance) - d.abs()).abs() < 8,
                "{v:?} {s:?} {d}"
            );
            // 26: within half a voxel diagonal (+ chord tolerance).
            assert!(d.abs() < 57_000 + 4096, "{v:?} at {d}");
        }
        assert!(col.0.len() > 1000);
    }

    #[test]
    fn bad_input() {
        let base = Torus {
            centre: [0; 3],
            axis: [0, 0, NORMAL_ONE],
            major: VOXEL,
            minor: VOXEL,
        };
        let refused = |t: Torus, want| assert_refused(surface, &t, want);
        refused(Torus { minor: 0, ..base }, VoxelizeError::NonPositiveRadius);
        refused(
            Torus {
                axis: [0; 3],
                ..base
            },
            VoxelizeError::Degenerate,
        );
        refused(
            Torus {
                major: 1 << 41,
                ..base
            },
            VoxelizeError::OutOfRange,
        );
        let huge = Torus {
            centre: [1 << 39; 3],
            axis: [1, 2, 3],
            major: 1 << 39,
            minor: 1 << 30,
        };
        assert!(voxelized_in_4(surface, &huge, Separation::TwentySix).is_ok());
    }
}
