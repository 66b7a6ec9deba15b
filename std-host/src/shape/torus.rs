//! Tori: TOML `torus` objects, and solid tori in CSG trees.

use glam::DVec3;
use rrt_core::csg;
use rrt_core::geometry;
use rrt_core::object_table as table;
use rrt_core::voxelize::torus;

use super::roots::poly_roots;
use super::{Primitive, Slots, SolidPrimitive, Surface, Unfit, get, positive, put};
use crate::frame::{RasterFrame, unit_to_fixed};
use crate::world::{Bounds, Hit, Ray};

/// A torus (closed): the points at distance `minor` from the circle of
/// radius `major` about the unit `axis` through `centre`. Saved as kind 6:
/// centre, axis, major, minor.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Torus {
    /// Centre.
    pub centre: DVec3,
    /// Unit axis.
    pub axis: DVec3,
    /// Radius of the centre circle (> 0).
    pub major: f64,
    /// Radius of the tube (> 0).
    pub minor: f64,
}

/// The saved kind of a torus.
const KIND: u32 = 6;

impl Torus {
    /// The torus in fixed point, both radii at least 1/65536 voxel; `None`
    /// beyond the fixed-point range or for an axis that is no direction.
    fn to_core(self, frame: &RasterFrame) -> Option<geometry::Torus> {
        Some(geometry::Torus {
            centre: frame.to_fixed(self.centre)?,
            axis: unit_to_fixed(self.axis)?,
            major: frame.length_to_fixed(self.major, 1)?,
            minor: frame.length_to_fixed(self.minor, 1)?,
        })
    }
}

impl Primitive for Torus {
    const KIND: &'static str = "torus";

    fn validate(&self) -> Result<(), &'static str> {
        if !self.centre.is_finite() {
            return Err("centre not finite");
        }
        if !self.axis.is_normalized() {
            return Err("axis not a unit vector");
        }
        if !(positive(self.major) && positive(self.minor)) {
            return Err("radius not a finite number > 0");
        }
        Ok(())
    }

    fn bounds(&self) -> Bounds {
        let r = self.major + self.minor;
        Bounds {
            min: self.centre - r,
            max: self.centre + r,
        }
    }
}

impl Surface for Torus {
    type Fixed = geometry::Torus;

    fn to_fixed(&self, frame: &RasterFrame) -> Result<geometry::Torus, Unfit> {
        self.to_core(frame).ok_or(Unfit::OutOfRange)
    }

    // Voxelized by `torus::surface`: the closed surface.
    core_surface!(geometry::Torus, table::Shape::Torus, torus::surface);

    /// Ray–torus: the surface at distance `minor` from the circle of radius
    /// `major` about the unit `axis` through `centre`.
    ///
    /// Solves the quartic in a local frame, with the ray moved to where it
    /// enters the bounding sphere and its direction normalised, so the
    /// coefficients stay well scaled. Roots are isolated robustly: the
    /// polynomial is monotonic between consecutive roots of its derivative
    /// (found the same way, recursively), so each such interval holds at most
    /// one sign change, found by bisection to full precision; a critical point
    /// where the polynomial vanishes (a tangent ray) is a root too.
    fn intersect(&self, ray: &Ray, tmin: f64, tmax: f64) -> Option<Hit> {
        let Self {
            centre,
            axis,
            major,
            minor,
        } = *self;
        let len = ray.dir.length();
        let z = axis.try_normalize()?;
        if !(len > 0.0 && len.is_finite() && major > 0.0 && minor > 0.0 && ray.origin.is_finite()) {
            return None;
        }
        let (x, y) = z.any_orthonormal_pair();
        let to_local = |v: DVec3| DVec3::new(v.dot(x), v.dot(y), v.dot(z));
        let d = to_local(ray.dir / len);
        let o0 = to_local(ray.origin - centre);
        // Parameters along the unit direction.
        let (lo, hi) = (tmin * len, tmax * len);
        // Clip to the bounding sphere (with slack: a ray tangent to the torus'
        // outer equator is tangent to this sphere too).
        let bound = (major + minor) * (1.0 + 1e-9);
        let b = o0.dot(d);
        let disc = bound * bound - (o0 - d * b).length_squared();
        if !(disc >= 0.0) {
            return None;
        }
        let sq = disc.sqrt();
        let (s_in, s_out) = (-b - sq, -b + sq);
        let lo = lo.max(s_in - 1e-9 * bound);
        let hi = hi.min(s_out + 1e-9 * bound);
        if !(lo < hi) {
            return None;
        }
        // Shift the origin to the start of the interval.
        let shift = lo.max(s_in);
        let o = o0 + d * shift;
        let (r2, big2) = (minor * minor, major * major);
        let k = o.length_squared() + big2 - r2;
        let m = o.dot(d);
        let dxy = d.x * d.x + d.y * d.y;
        let oxy = o.x * o.x + o.y * o.y;
        let odxy = o.x * d.x + o.y * d.y;
        // (|p|² + R² − r²)² − 4R²(px² + py²), p = o + s·d, ascending powers.
        let poly = [
            k * k - 4.0 * big2 * oxy,
            4.0 * m * k - 8.0 * big2 * odxy,
            4.0 * m * m + 2.0 * k - 4.0 * big2 * dxy,
            4.0 * m,
            1.0,
        ];
        // Magnitudes of the terms summed into each coefficient: the scale of
        // their rounding errors (the constant term cancels heavily near a
        // tangent ray).
        let mag = [
            k * k + 4.0 * big2 * oxy,
            (4.0 * m * k).abs() + (8.0 * big2 * odxy).abs(),
            4.0 * m * m + 2.0 * k.abs() + 4.0 * big2 * dxy,
            (4.0 * m).abs(),
            1.0,
        ];
        let roots = poly_roots(&poly, &mag, lo - shift, hi - shift);
        let s = roots
            .iter()
            .map(|s| s + shift)
            .filter(|&s| s > tmin * len && s < tmax * len)
            .min_by(f64::total_cmp)?;
        let p = o0 + d * s;
        let ring = DVec3::new(p.x, p.y, 0.0).normalize_or(DVec3::X) * major;
        let n_local = (p - ring).normalize_or(DVec3::Z);
        let normal = x * n_local.x + y * n_local.y + z * n_local.z;
        Some(Hit::new(s / len, normal))
    }

    fn save(&self, slots: &mut Slots) -> u32 {
        put(slots, 0, self.centre);
        put(slots, 3, self.axis);
        slots[6] = self.major;
        slots[7] = self.minor;
        KIND
    }

    fn load(kind: u32, slots: &Slots) -> Option<Self> {
        (kind == KIND).then(|| Self {
            centre: get(slots, 0),
            axis: get(slots, 3),
            major: slots[6],
            minor: slots[7],
        })
    }
}

impl SolidPrimitive for Torus {
    fn solid(&self, frame: &RasterFrame) -> Option<Box<dyn csg::Solid>> {
        Some(Box::new(self.to_core(frame)?))
    }
}
