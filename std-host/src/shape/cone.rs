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

    /// Degenerate when base and apex round to the same point; radii that
    /// both round to 0 keep 1/65536 voxel at the wider end.
    fn to_fixed(&self, frame: &RasterFrame) -> Result<geometry::Cone, Unfit> {
        let mut c = self.to_core(frame).ok_or(Unfit::OutOfRange)?;
        if c.base == c.apex {
            return Err(Unfit::Degenerate);
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
    fn intersect(&self, ray: &Ray, tmin: f64, tmax: f64) -> Option<Hit> {
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
        Some(Hit::new(t, cone_normal(base, ax, r0, k, ray.at(t))))
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

impl SolidPrimitive for Cone {
    /// The solid closed by its end discs; a cone that rounds to nothing
    /// holds no voxel.
    fn solid(&self, frame: &RasterFrame) -> Option<Box<dyn csg::Solid>> {
        Some(Box::new(self.to_core(frame)?))
    }
}

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
