//! Checkers for voxelized shapes, shared by unit tests, the `tests/` crate
//! and the `voxelize` fuzz target (enable the `check` feature outside this
//! crate's own tests).
//!
//! * [`PlaneSink`] writes every offered voxel into a raster plane as
//!   [`cell::OPAQUE`] and counts offers outside the raster instead of
//!   panicking.
//! * [`check_closed`] fires discrete rays from a point inside a closed
//!   voxelized shape towards many targets and requires each one to hit a
//!   non-transparent voxel before it leaves the raster: the shape is
//!   tunnel-free for that connectivity along those rays.
//! * [`probe_targets`] yields the standard targets: every voxel corner,
//!   edge midpoint and face centre on the surface of a cube around the
//!   origin, so rays pass straight through voxel corners and edges.
//!
//! Nothing here allocates; every loop is bounded by its arguments.

use crate::discrete_ray::{Connectivity, DiscreteRay, Hit};
use crate::error::RayError;
use crate::fixed::HALF_VOXEL;
use crate::raster::{Extent, Raster, cell};
use crate::voxelize::{Surfel, VoxelSink};

/// A [`VoxelSink`] that marks offered voxels [`cell::OPAQUE`] in a plane.
#[derive(Debug)]
pub struct PlaneSink<'a> {
    extent: Extent,
    plane: &'a mut [u8],
    /// Offers received (inside or outside the raster).
    pub offers: u64,
    /// Offers of voxels outside the extent (a voxelizer bug).
    pub outside: u64,
}

impl<'a> PlaneSink<'a> {
    /// Wraps `plane` (one byte per voxel of `extent`); `None` when the
    /// lengths differ.
    #[must_use]
    pub fn new(extent: Extent, plane: &'a mut [u8]) -> Option<Self> {
        (plane.len() == extent.len()).then_some(Self {
            extent,
            plane,
            offers: 0,
            outside: 0,
        })
    }
}

impl VoxelSink for PlaneSink<'_> {
    fn offer(&mut self, voxel: [u32; 3], _surfel: Surfel) {
        self.offers = self.offers.saturating_add(1);
        match self.extent.index(voxel).and_then(|i| self.plane.get_mut(i)) {
            Some(c) => *c |= cell::OPAQUE,
            None => self.outside = self.outside.saturating_add(1),
        }
    }
}

/// Why [`check_closed`] failed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum TunnelViolation {
    /// A ray left the raster without meeting a non-transparent voxel.
    Tunnel {
        /// The ray origin (fixed units).
        origin: [i64; 3],
        /// The ray direction.
        dir: [i32; 3],
        /// The connectivity walked.
        mode: Connectivity,
        /// The last voxel the ray visited.
        exit: [u32; 3],
    },
    /// The ray could not be set up or walked.
    Ray(RayError),
    /// The origin lies outside the raster.
    OriginOutside,
}

impl core::fmt::Display for TunnelViolation {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        core::fmt::Debug::fmt(self, f)
    }
}

/// Fires the half-line `origin + t·dir` (`t ≥ 0`) through `raster` in
/// `mode` and returns the first non-transparent voxel it meets. A zero
/// direction only tests the origin's voxel.
///
/// # Errors
/// [`TunnelViolation::Tunnel`] when the ray leaves the raster without a
/// hit, [`TunnelViolation::OriginOutside`] when `origin` is not inside the
/// raster, [`TunnelViolation::Ray`] when the ray cannot be set up.
pub fn ray_hits(
    raster: &Raster<'_>,
    origin: [i64; 3],
    dir: [i32; 3],
    mode: Connectivity,
) -> Result<Hit, TunnelViolation> {
    let extent = raster.extent();
    let inside = origin
        .iter()
        .zip(extent.dims())
        .all(|(&o, n)| o >= 0 && o < crate::fixed::voxel_low(n));
    if !inside {
        return Err(TunnelViolation::OriginOutside);
    }
    let mut ray = DiscreteRay::new(extent, origin, dir)
        .map_err(TunnelViolation::Ray)?
        .ok_or(TunnelViolation::OriginOutside)?;
    let start = ray;
    match ray.first_hit(raster, mode).map_err(TunnelViolation::Ray)? {
        Some(hit) => Ok(hit),
        None => Err(TunnelViolation::Tunnel {
            origin,
            dir,
            mode,
            exit: start.exit_voxel(),
        }),
    }
}

/// Fires one ray from `origin` towards each point of `targets` and requires
/// every one to hit. Returns the number of rays fired.
///
/// A ray is skipped (not fired, not counted) when its direction is zero or
/// does not fit `i32`, or when `starts_inside` rejects its entry voxel: the
/// voxel holding the ray just after its origin, which for an origin on a
/// voxel face, edge or corner depends on the direction. The caller makes
/// sure that `starts_inside` accepts only voxels whose centre lies inside a
/// closed voxelized shape that fits in the raster; then a miss is a tunnel.
///
/// # Errors
/// The first failing ray, as [`ray_hits`] reports it.
pub fn check_closed<I, F>(
    raster: &Raster<'_>,
    origin: [i64; 3],
    mode: Connectivity,
    targets: I,
    mut starts_inside: F,
) -> Result<u32, TunnelViolation>
where
    I: IntoIterator<Item = [i64; 3]>,
    F: FnMut([u32; 3]) -> bool,
{
    let mut fired = 0u32;
    for t in targets {
        let mut dir = [0i32; 3];
        let mut ok = true;
        for ((d, &tk), &ok_) in dir.iter_mut().zip(t.iter()).zip(origin.iter()) {
            match tk.checked_sub(ok_).and_then(|v| i32::try_from(v).ok()) {
                Some(v) => *d = v,
                None => ok = false,
            }
        }
        if !ok || dir == [0; 3] {
            continue;
        }
        let entry = DiscreteRay::new(raster.extent(), origin, dir)
            .map_err(TunnelViolation::Ray)?
            .map(|r| r.entry_voxel());
        if !entry.is_some_and(&mut starts_inside) {
            continue;
        }
        ray_hits(raster, origin, dir, mode)?;
        fired = fired.saturating_add(1);
    }
    Ok(fired)
}

/// The voxel corners, edge midpoints and face centres (every multiple of
/// half a voxel) on the surface of the cube of `2·reach` voxels centred on
/// `centre` (fixed units): `6·(4·reach)² + 2` points, so rays aimed at them
/// pass straight through voxel corners and edges. Points are snapped to the
/// half-voxel lattice.
pub fn probe_targets(centre: [i64; 3], reach: u16) -> impl Iterator<Item = [i64; 3]> {
    let m = i64::from(reach).saturating_mul(2);
    let snap = centre.map(|c| c.div_euclid(HALF_VOXEL).saturating_mul(HALF_VOXEL));
    let side = m.saturating_mul(2).saturating_add(1);
    let count = side.saturating_mul(side).saturating_mul(side);
    (0..count).filter_map(move |i| {
        let x = i.rem_euclid(side).saturating_sub(m);
        let y = i.div_euclid(side).rem_euclid(side).saturating_sub(m);
        let z = i.div_euclid(side.saturating_mul(side)).saturating_sub(m);
        let on_surface = x.abs() == m || y.abs() == m || z.abs() == m;
        on_surface.then(|| {
            let [sx, sy, sz] = snap;
            [
                sx.saturating_add(x.saturating_mul(HALF_VOXEL)),
                sy.saturating_add(y.saturating_mul(HALF_VOXEL)),
                sz.saturating_add(z.saturating_mul(HALF_VOXEL)),
            ]
        })
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fixed::{VOXEL, voxel_centre};
    use crate::geometry::Sphere;
    use crate::voxelize::{Separation, sphere};
    use std::vec;

    #[test]
    fn sphere_is_closed_and_a_hole_is_found() {
        let e = Extent::cube(24).unwrap();
        let c = [voxel_centre(12); 3];
        let s = Sphere {
            centre: c,
            radius: 7 * VOXEL + 1234,
        };
        for (sep, mode) in [
            (Separation::TwentySix, Connectivity::TwentySix),
            (Separation::Six, Connectivity::Six),
        ] {
            let mut plane = vec![0u8; e.len()];
            let mut sink = PlaneSink::new(e, &mut plane).unwrap();
            sphere::surface(&s, sep, e, &mut sink).unwrap();
            assert_eq!(sink.outside, 0);
            let r = Raster::new(e, &plane).unwrap();
            let n = check_closed(&r, c, mode, probe_targets(c, 3), |_| true).unwrap();
            assert_eq!(n, 6 * 12 * 12 + 2);
            // Punch a hole on the +x axis: the axis ray must now escape.
            let mut holed = plane.clone();
            for x in 0..24 {
                holed[e.index([x, 12, 12]).unwrap()] = 0;
            }
            let r = Raster::new(e, &holed).unwrap();
            let v = ray_hits(&r, c, [1, 0, 0], mode);
            assert!(matches!(v, Err(TunnelViolation::Tunnel { .. })), "{v:?}");
        }
    }
}
