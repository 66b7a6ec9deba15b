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
    /// precision. A tangent ray hits at its point of contact.
    fn intersect(&self, ray: &Ray, tmin: f64, tmax: f64) -> Option<Hit> {
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
        let t = nearest([t0 / len, t1 / len], tmin, tmax)?;
        let normal = (ray.at(t) - centre) / radius;
        Some(Hit::new(t, normal.normalize_or(DVec3::Z)))
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
