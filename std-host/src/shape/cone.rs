//! Cones and cylinders: NFF `c` (open at both ends), and capped cones in
//! CSG trees.

use glam::DVec3;
use rrt_core::csg;
use rrt_core::geometry;
use rrt_core::object_table as table;
use rrt_core::voxelize::cone;

use super::{Primitive, Slots, SolidPrimitive, Surface, Unfit, get, non_negative, positive, put};
use crate::frame::RasterFrame;
use crate::world::{Bounds, Hit, Ray};

/// A cone or cylinder between two discs. As a surface (NFF `c`) it is
/// open at both ends; as a CSG solid it is closed by its end discs. Saved
/// as kind 2: base, base radius, apex, apex radius.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cone {
    /// Centre of the base disc.
    pub base: DVec3,
    /// Radius at the base (≥ 0).
    pub base_radius: f64,
    /// Centre of the apex disc (≠ `base`).
    pub apex: DVec3,
    /// Radius at the apex (≥ 0; not both radii 0).
    pub apex_radius: f64,
}

/// The saved kind of a cone.
const KIND: u32 = 2;

impl Cone {
    /// The box around the two end discs, each grown by its own radius: the
    /// box `embree_nff` fits its grid to (tighter than [`Primitive::bounds`],
    /// which grows both ends by the larger radius).
    #[must_use]
    pub fn disc_bounds(&self) -> Bounds {
        let mut b = Bounds::EMPTY;
        b.include(self.base - self.base_radius, self.base + self.base_radius);
        b.include(self.apex - self.apex_radius, self.apex + self.apex_radius);
        b
    }

    /// The cone in fixed point, each radius rounded (possibly to 0).
    fn to_core(self, frame: &RasterFrame) -> Option<geometry::Cone> {
        Some(geometry::Cone {
            base: frame.to_fixed(self.base)?,
            base_radius: frame.length_to_fixed(self.base_radius, 0)?,
            apex: frame.to_fixed(self.apex)?,
            apex_radius: frame.length_to_fixed(self.apex_radius, 0)?,
        })
    }
}

impl Primitive for Cone {
    const KIND: &'static str = "cone";

    fn validate(&self) -> Result<(), &'static str> {
        if !(self.base.is_finite() && self.apex.is_finite()) {
            return Err("base or apex not finite");
        }
        if self.base == self.apex {
            return Err("base equals apex");
        }
        if !(non_negative(self.base_radius) && non_negative(self.apex_radius)) {
            return Err("radius not a finite number ≥ 0");
        }
        if !positive(self.base_radius + self.apex_radius) {
            return Err("both radii 0");
        }
        Ok(())
    }

    fn bounds(&self) -> Bounds {
        let r = self.base_radius.max(self.apex_radius);
        Bounds {
            min: self.base.min(self.apex) - r,
            max: self.base.max(self.apex) + r,
        }
    }
}

impl Surface for Cone {
    type Fixed = geometry::Cone;

    /// A base and apex that round to the same point (a cone flatter than
    /// a fixed-point unit: an annulus or disc) keep one unit between them
    /// along the axis's largest component, so that the voxels the flat
    /// surface passes through are voxelized; radii that both round to 0
    /// keep 1/65536 voxel at the wider end.
    fn to_fixed(&self, frame: &RasterFrame) -> Result<geometry::Cone, Unfit> {
        let mut c = self.to_core(frame).ok_or(Unfit::OutOfRange)?;
        if c.base == c.apex {
            let axis = (self.apex - self.base).to_array();
            let k = (0..3)
                .max_by(|&a, &b| axis[a].abs().total_cmp(&axis[b].abs()))
                .unwrap_or(0);
            let step = if axis[k] < 0.0 { -1 } else { 1 };
            c.apex[k] += step;
            if c.apex[k].abs() > crate::frame::MAX_FIXED {
                return Err(Unfit::OutOfRange);
            }
        }
        if c.base_radius == 0 && c.apex_radius == 0 {
            // Thinner than 1/65536 voxel: keep the wider end's 1.
            if self.base_radius >= self.apex_radius {
                c.base_radius = 1;
            } else {
                c.apex_radius = 1;
            }
        }
        Ok(c)
    }

    // Voxelized by `cone::surface`: the open lateral surface.
    core_surface!(geometry::Cone, table::Shape::Cone, cone::surface);

    /// Ray–open cone or cylinder (NFF `c`: no end caps), a port of
    /// `embree_nff`'s `cone_hit` and `cone_normal` in `f64`. Radii are taken
    /// as absolute values; `base ≠ apex`. The nappe beyond the apex (where the
    /// radius would be negative) is not part of the surface.
    ///
    /// A line that passes the axis line farther than the larger radius, by
    /// a relative margin far above the rounding of that test, is refused
    /// first with products and sums only (`clearly_misses`); every other
    /// ray gets the answer of the full form.
    fn intersect(&self, ray: &Ray, tmin: f64, tmax: f64) -> Option<Hit> {
        let (t, ax, k) = self.refused_or_full(ray, tmin, tmax)?;
        let normal = cone_normal(self.base, ax, self.base_radius.abs(), k, ray.at(t));
        Some(Hit::new(t, normal))
    }

    fn first_t(&self, ray: &Ray, tmin: f64, tmax: f64) -> Option<f64> {
        self.refused_or_full(ray, tmin, tmax).map(|(t, _, _)| t)
    }

    fn save(&self, slots: &mut Slots) -> u32 {
        put(slots, 0, self.base);
        slots[3] = self.base_radius;
        put(slots, 4, self.apex);
        slots[7] = self.apex_radius;
        KIND
    }

    fn load(kind: u32, slots: &Slots) -> Option<Self> {
        (kind == KIND).then(|| Self {
            base: get(slots, 0),
            base_radius: slots[3],
            apex: get(slots, 4),
            apex_radius: slots[7],
        })
    }
}

/// Whether the line through `base + co` along `dir` passes the line through
/// `base` along `axis` farther than `rmax`, with room to spare: with
/// `n = dir × axis`, `(co·n)²` (the squared distance of the lines times
/// `|n|²`) exceeds `rmax²·|n|²` by more than `2^-30` of
/// `|co|²·|dir|²·|axis|²`, which bounds `(co·n)²`. The rounding of these
/// products is a few units of `2^-52` of the same scale, so a refused line
/// misses the cylinder of radius `rmax` about the axis line, which holds
/// the cone, in exact arithmetic. Parallel lines, anything non-finite and
/// scales near overflow or underflow are never refused.
#[inline]
fn clearly_misses(co: DVec3, dir: DVec3, axis: DVec3, rmax: f64) -> bool {
    let n = dir.cross(axis);
    let scale = co.length_squared() * dir.length_squared() * axis.length_squared();
    if !(scale > 1e-200 && scale < 1e200) {
        return false;
    }
    let s = co.dot(n);
    s * s - rmax * rmax * n.length_squared() > scale * (1.0 / 1_073_741_824.0)
}

impl Cone {
    /// [`Cone::full`] after the early refusal ([`Surface::intersect`]).
    #[inline(always)]
    fn refused_or_full(&self, ray: &Ray, tmin: f64, tmax: f64) -> Option<(f64, DVec3, f64)> {
        let rmax = self.base_radius.abs().max(self.apex_radius.abs());
        if clearly_misses(ray.origin - self.base, ray.dir, self.apex - self.base, rmax) {
            return None;
        }
        self.full(ray, tmin, tmax)
    }

    /// [`Surface::intersect`] without the early refusal and the normal: the
    /// hit's `t`, with the unit axis and the slope its normal needs.
    fn full(&self, ray: &Ray, tmin: f64, tmax: f64) -> Option<(f64, DVec3, f64)> {
        let Self {
            base,
            base_radius,
            apex,
            apex_radius,
        } = *self;
        let axis = apex - base;
        let h = axis.length();
        if !(h > 0.0 && h.is_finite()) {
            return None;
        }
        let ax = axis / h;
        let (r0, r1) = (base_radius.abs(), apex_radius.abs());
        let k = (r1 - r0) / h;
        let d = ray.dir;
        let co = ray.origin - base;
        let dy = d.dot(ax);
        let oy = co.dot(ax);
        let dp = d - ax * dy;
        let op = co - ax * oy;
        let rr = r0 + k * oy;
        let qa = dp.dot(dp) - k * k * dy * dy;
        let qb = op.dot(dp) - k * dy * rr;
        let qc = op.dot(op) - rr * rr;
        if h <= FLAT * r0.max(r1) {
            // Flatter than the quadratic can resolve (its slope `k` above
            // 1e7): the annulus between the radii on the plane halfway up,
            // within `h / 2` of the surface.
            if dy == 0.0 {
                return None;
            }
            let t = (0.5 * h - oy) / dy;
            let rho = (op + dp * t).length();
            return (t > tmin && t < tmax && (r0.min(r1)..=r0.max(r1)).contains(&rho))
                .then_some((t, ax, k));
        }
        let dd = d.dot(d);
        let mut roots = [f64::NAN; 2];
        if qa.abs() < 1e-12 * dd {
            // One nappe's line is parallel to the ray: a linear equation.
            if qb.abs() <= 1e-15 * dd.sqrt() * (op.length() + rr.abs()) {
                return None;
            }
            roots[0] = -qc / (2.0 * qb);
        } else {
            let disc = qb * qb - qa * qc;
            if !(disc >= 0.0) {
                return None;
            }
            let sq = disc.sqrt();
            // Stable roots of qa·t² + 2·qb·t + qc.
            let q = -qb - sq.copysign(qb);
            let (t0, t1) = if q == 0.0 {
                (0.0, 0.0)
            } else {
                (q / qa, qc / q)
            };
            roots = if t0 <= t1 { [t0, t1] } else { [t1, t0] };
        }
        let t = roots.into_iter().find(|&t| {
            let y = oy + t * dy;
            t > tmin && t < tmax && (0.0..=h).contains(&y) && rr + k * dy * t >= 0.0
        })?;
        Some((t, ax, k))
    }
}

impl SolidPrimitive for Cone {
    /// The solid closed by its end discs; a cone that rounds to nothing
    /// holds no voxel.
    fn solid(&self, frame: &RasterFrame) -> Option<Box<dyn csg::Solid>> {
        Some(Box::new(self.to_core(frame)?))
    }
}

/// A cone whose height is at most this fraction of its larger radius is
/// intersected as the flat annulus it nearly is ([`Cone::full`]).
const FLAT: f64 = 1e-7;

/// `embree_nff`'s `cone_normal`: the outward normal of the lateral surface
/// at `p` (radial direction tilted by the slope `k`).
fn cone_normal(base: DVec3, ax: DVec3, r0: f64, k: f64, p: DVec3) -> DVec3 {
    let q = p - base;
    let y = q.dot(ax);
    let radial = q - ax * y;
    let r = r0 + k * y;
    (radial - ax * (r * k))
        .try_normalize()
        // At a point apex the normal is undefined: use the slope alone.
        .unwrap_or_else(|| (-ax * k.signum()).normalize_or(ax))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// SplitMix64 in `[0, 1)`.
    struct Rng(u64);
    impl Rng {
        fn unit(&mut self) -> f64 {
            self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
            let mut z = self.0;
            z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
            ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
        }
        fn vec(&mut self, scale: f64) -> DVec3 {
            DVec3::new(self.unit() - 0.5, self.unit() - 0.5, self.unit() - 0.5) * (2.0 * scale)
        }
    }

    /// The early refusal changes no answer: on random cones, cylinders and
    /// thin twigs at scales from 2^-20 to 2^20, and random rays, near-grazing
    /// ones among them (aimed at a point of the surface, nudged sideways by
    /// a relative 2^-40 to 2^-20) and ones nearly parallel to the axis,
    /// every ray it refuses misses by the full form; and it refuses most
    /// misses.
    #[test]
    fn refusal_is_the_full_answer() {
        let mut rng = Rng(11);
        let (mut refused, mut misses) = (0u32, 0u32);
        for i in 0..200_000u32 {
            let scale = 2f64.powi((i % 41) as i32 - 20);
            let base = rng.vec(scale * 4.0);
            let apex = base + rng.vec(scale * 2.0);
            let thin = if i % 5 == 0 { 1e-3 } else { 1.0 };
            let (r0, r1) = match i % 3 {
                0 => (scale * thin * rng.unit(), scale * thin * rng.unit()),
                1 => {
                    let r = scale * thin * (0.01 + rng.unit());
                    (r, r)
                }
                _ => (scale * thin * (0.01 + rng.unit()), 0.0),
            };
            let c = Cone {
                base,
                base_radius: r0,
                apex,
                apex_radius: r1,
            };
            let origin = base + rng.vec(scale * 8.0);
            let dir = match i % 4 {
                0 => {
                    // Towards a point of the lateral surface, grazing it.
                    let y = rng.unit();
                    let axis = (apex - base).normalize();
                    let radial = axis.any_orthonormal_vector();
                    let target = base + (apex - base) * y + radial * (r0 + (r1 - r0) * y);
                    let nudge = 2f64.powi(-20 - (i % 21) as i32);
                    (target - origin) + radial.cross(axis) * (scale * nudge)
                }
                1 => (apex - base) + rng.vec(scale * 1e-9),
                _ => rng.vec(1.0) * 2f64.powi((i % 7) as i32 - 3),
            };
            let ray = Ray::new(origin, dir);
            let full = c.full(&ray, 0.0, f64::INFINITY).map(|(t, _, _)| t);
            if clearly_misses(origin - base, dir, apex - base, r0.max(r1)) {
                refused += 1;
                assert_eq!(full, None, "{c:?} {ray:?}");
            }
            misses += u32::from(full.is_none());
            assert_eq!(c.first_t(&ray, 0.0, f64::INFINITY), full);
            assert_eq!(c.intersect(&ray, 0.0, f64::INFINITY).map(|h| h.t), full);
        }
        assert!(refused > misses / 2, "{refused} of {misses} misses refused");
    }
}
