//! The raster's frame: where the 3D raster lies in the world, and the
//! conversions between world coordinates (`f64`), continuous raster
//! coordinates (voxel units) and the core's fixed point (1/65536 voxel).
//!
//! [`RasterFrame`] is made once, by fitting ([`crate::fit`]), and read by
//! every phase after it: the shape model's fixed-point geometry
//! ([`crate::shape`]), voxelization, the tracer and the saved-raster file.

use glam::DVec3;
use rrt_core::discrete_ray::{ORIGIN_LIMIT, ORIGIN_LIMIT_BITS};
use rrt_core::fixed::{FRAC_BITS, VOXEL};
use rrt_core::geometry::{NORMAL_ONE, Point, UnitVector};
use rrt_core::raster::Extent;

use crate::world::{Bounds, Ray};

/// Farthest any fixed-point coordinate may lie from the raster's origin:
/// the core's discrete-ray origin limit ([`ORIGIN_LIMIT`], 2^31 voxels),
/// so that every point the host converts is a valid ray origin and
/// products of coordinates stay far from `i64` limits.
pub const MAX_FIXED: i64 = ORIGIN_LIMIT;

/// How far a light's fixed-point position may lie from the raster's
/// origin, per axis: 2^60 fixed units, 2^44 voxels
/// ([`RasterFrame::light_to_fixed`]).
pub const FAR_LIGHT_FIXED: i64 = 1 << 60;

/// `log2` of [`MAX_FIXED`] in voxels, for messages.
pub const MAX_FIXED_VOXEL_BITS: u32 = ORIGIN_LIMIT_BITS - FRAC_BITS;

/// The raster's place in the world: voxel `(i, j, k)` spans
/// `origin + [i, i+1) × [j, j+1) × [k, k+1) · voxel_size`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RasterFrame {
    /// Voxels per axis.
    pub extent: Extent,
    /// World position of the raster's lowest corner.
    pub origin: DVec3,
    /// World length of a voxel's edge.
    pub voxel_size: f64,
}

impl RasterFrame {
    /// Voxels per axis.
    #[must_use]
    pub fn dims(&self) -> [u32; 3] {
        self.extent.dims()
    }

    /// The raster's box in world coordinates.
    #[must_use]
    pub fn world_bounds(&self) -> Bounds {
        let n = DVec3::from(self.dims().map(f64::from));
        Bounds {
            min: self.origin,
            max: self.origin + n * self.voxel_size,
        }
    }

    /// A world point in voxel units (continuous raster coordinates).
    #[must_use]
    pub fn world_to_raster(&self, p: DVec3) -> DVec3 {
        (p - self.origin) / self.voxel_size
    }

    /// A point in voxel units back in the world.
    #[must_use]
    pub fn raster_to_world(&self, p: DVec3) -> DVec3 {
        self.origin + p * self.voxel_size
    }

    /// A world point in fixed units (rounded to the nearest 1/65536
    /// voxel); `None` if it lies more than [`MAX_FIXED`] away or is not
    /// finite.
    #[must_use]
    pub fn to_fixed(&self, p: DVec3) -> Option<Point> {
        let q = self.world_to_raster(p) * VOXEL as f64;
        let c = |v: f64| {
            let r = round(v);
            // The range check makes the conversion exact.
            (r.abs() <= MAX_FIXED as f64).then_some(r as i64)
        };
        Some([c(q.x)?, c(q.y)?, c(q.z)?])
    }

    /// A light's world position in fixed units, for the shadow rays
    /// towards it; `None` only if it is not finite. Within 2^44 voxels
    /// ([`FAR_LIGHT_FIXED`]) of the raster's origin, the position rounded
    /// to the nearest 1/65536 voxel as [`RasterFrame::to_fixed`] rounds it;
    /// beyond, a light is taken by its direction: the point 2^44 voxels
    /// from the raster's centre towards it (a sun, a light "at infinity").
    /// From any point of a raster up to 2^15 voxels wide the directions to
    /// that point and to the light differ by less than 2^-27 radians, so
    /// a shadow ray towards either stays within 2^-11 voxel of the other
    /// across the raster. The core takes lights anywhere in `i64` (its
    /// shadow rays towards a light far outside the raster go by direction),
    /// so no light is refused for its distance.
    #[must_use]
    pub fn light_to_fixed(&self, p: DVec3) -> Option<Point> {
        if !p.is_finite() {
            return None;
        }
        let limit = FAR_LIGHT_FIXED as f64;
        let q = self.world_to_raster(p) * VOXEL as f64;
        if q.abs().max_element() <= limit {
            return Some(q.to_array().map(|v| round(v) as i64));
        }
        // Halves keep the difference finite for any finite coordinates.
        let centre = DVec3::from(self.dims().map(f64::from)) * 0.5;
        let d = 0.5 * p - 0.5 * self.raster_to_world(centre);
        let m = d.abs().max_element();
        let u = (d / m).normalize_or_zero();
        if u == DVec3::ZERO {
            return None;
        }
        // |centre| ≤ 2^15 voxels: every coordinate within 2^61, exact in
        // `i64`.
        let far = (centre * VOXEL as f64 + u * limit).to_array();
        Some(far.map(|v| round(v) as i64))
    }

    /// A fixed-point point back in the world.
    #[must_use]
    pub fn fixed_to_world(&self, p: Point) -> DVec3 {
        self.raster_to_world(DVec3::from(p.map(|v| v as f64)) / VOXEL as f64)
    }

    /// A world length in fixed units, rounded, at least `min`; `None` if
    /// longer than [`MAX_FIXED`].
    #[must_use]
    pub fn length_to_fixed(&self, l: f64, min: i64) -> Option<i64> {
        let v = round(l / self.voxel_size * VOXEL as f64);
        (v.abs() <= MAX_FIXED as f64).then_some((v as i64).max(min))
    }

    /// A world ray in voxel units (same parameter `t`).
    #[must_use]
    pub fn ray_to_raster(&self, r: &Ray) -> Ray {
        Ray::new(self.world_to_raster(r.origin), r.dir / self.voxel_size)
    }
}

/// A unit vector scaled by 2^30 and rounded; `None` for a zero or
/// non-finite vector.
#[must_use]
pub fn unit_to_fixed(n: DVec3) -> Option<UnitVector> {
    let u = n.try_normalize()? * f64::from(NORMAL_ONE);
    // |component| ≤ 2^30 after normalising: fits an i32.
    Some([u.x, u.y, u.z].map(|c| round(c) as i32))
}

/// `x.round()` (halves away from zero), exactly, without the libm call
/// that `f64::round` compiles to on the baseline x86-64 target (no SSE4.1),
/// and without a data-dependent branch: it runs for every ray.
#[inline]
#[must_use]
pub fn round(x: f64) -> f64 {
    // From 2^52 up every f64 is an integer (and inf and NaN stay as they are).
    if x.abs() < 4_503_599_627_370_496.0 {
        // The sign of x keeps −0.0 for −0.5 < x ≤ −0.0, as f64::round does.
        (round_to_i64(x) as f64).copysign(x)
    } else {
        x
    }
}

/// `x.round() as i64` (halves away from zero, saturating, NaN → 0),
/// exactly, branch-free: the truncation `t` is exact for `|x| < 2^63` and
/// so is `x − t`, which decides the step away from zero.
#[inline]
#[must_use]
pub fn round_to_i64(x: f64) -> i64 {
    let t = x as i64;
    let r = x - t as f64;
    t.saturating_add(i64::from(r >= 0.5))
        .saturating_sub(i64::from(r <= -0.5))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A light too far for fixed point is the point 2^44 voxels from the
    /// raster's centre towards it: from every corner of the widest raster
    /// the directions to that point and to the light differ by less than
    /// 2^-27 radians, and nearer lights keep their rounded position.
    #[test]
    fn far_lights_keep_their_direction() {
        let frame = RasterFrame {
            extent: Extent::new(32768, 32768, 32768).unwrap(),
            origin: DVec3::new(-3.0, 5.0, 7.0),
            voxel_size: 0.25,
        };
        let n = 32768.0;
        for dir in [
            DVec3::new(1.0, 0.0, 0.0),
            DVec3::new(-1.0, 2.0, 0.5),
            DVec3::new(0.3, -0.2, -1.0),
        ] {
            for dist in [1e20, 1e200, 1e308] {
                let light = dir.normalize() * dist;
                let p = frame.light_to_fixed(light).unwrap();
                let proxy = DVec3::from(p.map(|v| v as f64)) / VOXEL as f64;
                for corner in 0..8 {
                    let c = DVec3::new(
                        f64::from(corner & 1) * n,
                        f64::from((corner >> 1) & 1) * n,
                        f64::from((corner >> 2) & 1) * n,
                    );
                    let angle = (proxy - c).angle_between(dir);
                    assert!(angle < 2f64.powi(-27), "{dir} {dist} {corner}: {angle}");
                }
            }
        }
        let near = DVec3::new(1e9, -2e9, 3e9);
        let q = frame.world_to_raster(near) * VOXEL as f64;
        assert_eq!(
            frame.light_to_fixed(near),
            Some(q.to_array().map(|v| v.round() as i64))
        );
        assert_eq!(frame.light_to_fixed(DVec3::new(f64::NAN, 0.0, 0.0)), None);
        assert_eq!(
            frame.light_to_fixed(DVec3::new(f64::INFINITY, 0.0, 0.0)),
            None
        );
    }

    #[test]
    fn round_is_f64_round() {
        let mut vals = vec![
            0.0,
            -0.0,
            0.5,
            -0.5,
            1.5,
            -1.5,
            2.5,
            0.49999999999999994,
            -0.49999999999999994,
            4503599627370495.5,
            4503599627370497.0,
            9.3e18,
            -9.3e18,
            1e300,
            f64::MAX,
            f64::MIN,
            f64::INFINITY,
            f64::NEG_INFINITY,
            1e-300,
            -1e-300,
        ];
        let mut x = 0x9e37_79b9_7f4a_7c15_u64;
        for _ in 0..100_000 {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            let v = f64::from_bits(x);
            if v.is_finite() {
                vals.push(v);
                vals.push((x % 4_000_001) as f64 / 8.0 - 250_000.0);
            }
        }
        for v in vals {
            assert_eq!(round(v).to_bits(), v.round().to_bits(), "{v:e}");
            assert_eq!(round_to_i64(v), v.round() as i64, "{v:e}");
        }
        assert_eq!(round_to_i64(f64::NAN), 0);
        assert!(round(f64::NAN).is_nan());
    }
}
