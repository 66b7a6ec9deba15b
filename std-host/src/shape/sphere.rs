//! Spheres: NFF `s`, and balls in CSG trees.

use glam::DVec3;
use rrt_core::csg;
use rrt_core::geometry;
use rrt_core::object_table as table;
use rrt_core::voxelize::sphere;

use super::{Primitive, Slots, SolidPrimitive, Surface, Unfit, get, positive, put};
use crate::frame::RasterFrame;
use crate::world::{Bounds, Hit, Ray};

/// A sphere (closed): NFF `s`, or a ball in a CSG tree. Saved as kind 1:
/// centre, radius.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sphere {
    /// Centre.
    pub centre: DVec3,
    /// Radius (> 0).
    pub radius: f64,
}

/// The saved kind of a sphere.
const KIND: u32 = 1;

impl Primitive for Sphere {
    const KIND: &'static str = "sphere";

    fn validate(&self) -> Result<(), &'static str> {
        if !self.centre.is_finite() {
            return Err("centre not finite");
        }
        if !positive(self.radius) {
            return Err("radius not a finite number > 0");
        }
        Ok(())
    }

    fn bounds(&self) -> Bounds {
        Bounds {
            min: self.centre - self.radius,
            max: self.centre + self.radius,
        }
    }
}

impl Surface for Sphere {
    type Fixed = geometry::Sphere;

    /// The centre rounded to fixed point, the radius at least 1/65536
    /// voxel.
    fn to_fixed(&self, frame: &RasterFrame) -> Result<geometry::Sphere, Unfit> {
        Ok(geometry::Sphere {
            centre: frame.to_fixed(self.centre).ok_or(Unfit::OutOfRange)?,
            radius: frame
                .length_to_fixed(self.radius, 1)
                .ok_or(Unfit::OutOfRange)?,
        })
    }

    // Voxelized by `sphere::surface` as its shell.
    core_surface!(geometry::Sphere, table::Shape::Sphere, sphere::surface);

    /// Ray–sphere.
    ///
    /// Uses the numerically stable form: the discriminant from the squared
    /// distance of the centre to the ray's line, and the far root from the
    /// product of the roots, so rays far from small spheres keep their
    /// precision. A tangent ray hits at its point of contact. A line that
    /// passes the sphere by more than a relative margin far above the
    /// rounding of that form is refused first with products and sums
    /// only (`clearly_misses`), and so is, for `tmin ≥ 0`, a sphere
    /// clearly behind an origin clearly outside it (`clearly_behind`);
    /// every other ray gets the same answer as from the full form.
    #[inline]
    fn intersect(&self, ray: &Ray, tmin: f64, tmax: f64) -> Option<Hit> {
        let t = self.first_t(ray, tmin, tmax)?;
        let normal = (ray.at(t) - self.centre) / self.radius;
        Some(Hit::new(t, normal.normalize_or(DVec3::Z)))
    }

    fn first_t(&self, ray: &Ray, tmin: f64, tmax: f64) -> Option<f64> {
        if self.refuses(ray, tmin) {
            return None;
        }
        self.stable(ray, tmin, tmax)
    }

    fn save(&self, slots: &mut Slots) -> u32 {
        put(slots, 0, self.centre);
        slots[3] = self.radius;
        KIND
    }

    fn load(kind: u32, slots: &Slots) -> Option<Self> {
        (kind == KIND).then(|| Self {
            centre: get(slots, 0),
            radius: slots[3],
        })
    }
}

impl Sphere {
    /// The early refusal of [`Surface::first_t`] and
    /// [`Surface::intersect`]: `true` when `ray`'s line passes the sphere
    /// by a clear margin, or, for `tmin ≥ 0`, the sphere lies clearly
    /// behind an origin clearly outside it; then both answer `None` for
    /// every `tmax`. A sphere with a NaN centre or radius refuses nothing.
    #[inline]
    #[must_use]
    pub fn refuses(&self, ray: &Ray, tmin: f64) -> bool {
        let oc = ray.origin - self.centre;
        clearly_misses(oc, ray.dir, self.radius)
            || (tmin >= 0.0 && clearly_behind(oc, ray.dir, self.radius))
    }

    /// [`Surface::first_t`] without the early refusal.
    fn stable(&self, ray: &Ray, tmin: f64, tmax: f64) -> Option<f64> {
        let Self { centre, radius } = *self;
        let len = ray.dir.length();
        if !(len > 0.0 && len.is_finite() && radius > 0.0) {
            return None;
        }
        let d = ray.dir / len;
        let oc = ray.origin - centre;
        let b = oc.dot(d);
        let perp = oc - d * b;
        let disc = radius * radius - perp.length_squared();
        if !(disc >= 0.0) {
            return None;
        }
        let sq = disc.sqrt();
        // (|oc| − r)(|oc| + r), accurate when the origin is near the surface.
        let dist = oc.length();
        let c = (dist - radius) * (dist + radius);
        let q = -b - sq.copysign(b);
        let (t0, t1) = if q == 0.0 { (0.0, 0.0) } else { (q, c / q) };
        nearest([t0 / len, t1 / len], tmin, tmax)
    }
}

/// Whether the line through `centre + oc` along `dir` passes a sphere of
/// `radius` about `centre` with room to spare: its squared distance from
/// the centre, times `|dir|²`, exceeds `r²·|dir|²` by more than `2^-32` of
/// `|oc|²·|dir|²`. The rounding of these products and of the stable form
/// in [`Sphere::intersect`] is a few units of `2^-52` of the same scale,
/// so a line refused here misses in exact arithmetic and in the stable
/// form alike. Origins inside the sphere are never refused, nor anything
/// non-finite, nor scales near overflow or underflow.
#[inline]
fn clearly_misses(oc: DVec3, dir: DVec3, radius: f64) -> bool {
    products(oc, dir).is_some_and(|p| {
        // |oc × dir|² = |oc|²|dir|² − (oc·dir)²: the squared distance times |dir|².
        let perp = p.scale - p.b * p.b;
        let r2 = radius * radius * p.dd;
        perp - r2 > p.scale * (1.0 / 4_294_967_296.0)
    })
}

/// The products both early refusals read: `|dir|²`, `oc·dir`, `|oc|²`
/// and `scale = |oc|²·|dir|²`; `None` unless the scale lies far from
/// overflow and from subnormals, where their rounding bounds hold.
struct Products {
    dd: f64,
    b: f64,
    oo: f64,
    scale: f64,
}

#[inline]
fn products(oc: DVec3, dir: DVec3) -> Option<Products> {
    let dd = dir.length_squared();
    let oo = oc.length_squared();
    let scale = oo * dd;
    (scale > 1e-200 && scale < 1e200).then(|| Products {
        dd,
        b: oc.dot(dir),
        oo,
        scale,
    })
}

/// Whether the sphere of `radius` about `centre` lies behind the origin
/// `centre + oc` of a ray along `dir` with room to spare: the origin is
/// outside it, `|oc|² > r²·(1 + 2^-30)`, and the centre is behind it,
/// `oc·dir > 2^-40·|oc|·|dir|` (both as computed). Then the stable form of
/// [`Sphere::intersect`] finds both roots below 0: its `b`, `oc` against
/// the rounded unit direction, is within a few units of `2^-52·|oc|` of
/// the exact `oc·dir / |dir|`, which exceeds `2^-41·|oc|`, so `b > 0`
/// and its near root `q = −b − √disc` is negative; its `|oc|`, rounded,
/// still exceeds `r`, so `c > 0` (or 0 by underflow) and the far root
/// `c / q` is not positive either. No root passes `t > tmin ≥ 0`. Nothing
/// non-finite is refused, nor scales near overflow or underflow.
#[inline]
fn clearly_behind(oc: DVec3, dir: DVec3, radius: f64) -> bool {
    products(oc, dir).is_some_and(|p| {
        p.b > 0.0
            && p.b * p.b > p.scale * (1.0 / 1_208_925_819_614_629_174_706_176.0)
            && p.oo > radius * radius * (1.0 + 1.0 / 1_073_741_824.0)
    })
}

impl SolidPrimitive for Sphere {
    fn solid(&self, frame: &RasterFrame) -> Option<Box<dyn csg::Solid>> {
        let s = self.to_fixed(frame).ok()?;
        Some(Box::new(s))
    }
}

/// The nearest of `roots` in `(tmin, tmax)`.
fn nearest(roots: impl IntoIterator<Item = f64>, tmin: f64, tmax: f64) -> Option<f64> {
    roots
        .into_iter()
        .filter(|&t| t > tmin && t < tmax)
        .min_by(f64::total_cmp)
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
        /// A sphere about the origin's neighbourhood at scale 2^-20 to
        /// 2^20, by `i`.
        fn sphere(&mut self, i: u32) -> (Sphere, f64) {
            let scale = 2f64.powi((i % 41) as i32 - 20);
            let centre = self.vec(scale * 4.0);
            let radius = scale * (0.01 + self.unit());
            (Sphere { centre, radius }, scale)
        }
    }

    /// The early refusal changes no answer: on random rays, near-tangent
    /// ones among them (aimed at a point of the surface, nudged by a
    /// relative 2^-40 to 2^-20), at scales from 2^-20 to 2^20, every ray it
    /// refuses misses by the full form; and it refuses most clear misses.
    #[test]
    fn refusal_is_the_stable_answer() {
        let mut rng = Rng(7);
        let (mut refused, mut misses) = (0u32, 0u32);
        for i in 0..200_000u32 {
            let (s, scale) = rng.sphere(i);
            let origin = s.centre + rng.vec(scale * 8.0);
            let dir = if i % 3 == 0 {
                // Towards a point of the surface, grazing it.
                let normal = rng.vec(1.0).normalize_or(DVec3::Z);
                let target = s.centre + normal * s.radius;
                let nudge = 2f64.powi(-20 - (i % 21) as i32);
                (target - origin) + normal.any_orthonormal_vector() * (s.radius * nudge)
            } else {
                rng.vec(1.0) * 2f64.powi((i % 7) as i32 - 3)
            };
            let ray = Ray::new(origin, dir);
            let full = s.stable(&ray, 0.0, f64::INFINITY);
            if clearly_misses(origin - s.centre, dir, s.radius) {
                refused += 1;
                assert_eq!(full, None, "{s:?} {ray:?}");
            }
            misses += u32::from(full.is_none());
            assert_eq!(s.first_t(&ray, 0.0, f64::INFINITY), full);
        }
        assert!(refused > misses / 2, "{refused} of {misses} misses refused");
    }

    /// Spheres behind the origin are refused only where the full form
    /// finds no root past `tmin ≥ 0`: rays leaving points on or near the
    /// surface (outside and inside it by relative 2^-45 to 2^-10, and
    /// exactly on it as rounded), in every direction, nearly along the
    /// tangent plane among them, at scales from 2^-20 to 2^20; and most
    /// rays leaving the sphere's outside away from it are refused.
    #[test]
    fn spheres_behind_are_refused_only_when_the_stable_form_misses() {
        let mut rng = Rng(11);
        let (mut refused, mut away) = (0u32, 0u32);
        for i in 0..300_000u32 {
            let (s, scale) = rng.sphere(i);
            let normal = rng.vec(1.0).normalize_or(DVec3::Z);
            let lift = match i % 4 {
                0 => 0.0,
                1 => 2f64.powi(-10 - (i % 36) as i32),
                2 => -(2f64.powi(-10 - (i % 36) as i32)),
                _ => rng.unit() * 4.0,
            };
            let origin = s.centre + normal * (s.radius * (1.0 + lift));
            let dir = if i % 5 == 0 {
                // Nearly along the tangent plane, either way.
                let side = normal.any_orthonormal_vector();
                let tilt = 2f64.powi(-((i % 50) as i32)) * if i % 2 == 0 { 1.0 } else { -1.0 };
                side + normal * tilt
            } else {
                rng.vec(1.0) * 2f64.powi((i % 7) as i32 - 3)
            };
            let ray = Ray::new(origin, dir);
            let tmin = if i % 3 == 0 {
                0.0
            } else {
                rng.unit() * scale * 1e-6
            };
            let full = s.stable(&ray, tmin, f64::INFINITY);
            if clearly_behind(origin - s.centre, dir, s.radius) {
                refused += 1;
                assert_eq!(full, None, "{s:?} {ray:?} {tmin}");
            }
            away += u32::from(lift > 1e-3 && (origin - s.centre).dot(dir) > 0.0);
            assert_eq!(s.first_t(&ray, tmin, f64::INFINITY), full, "{s:?} {ray:?}");
        }
        assert!(refused > away / 2, "{refused} of {away} refused");
    }
}
