//! The one shape model: each primitive described once, in world
//! coordinates, with every role the pipeline asks of it.
//!
//! A primitive is a world-space struct in its own file: [`Sphere`],
//! [`Cone`], [`Triangle`], [`Cuboid`], [`Torus`]. Its roles are traits:
//!
//! * [`Primitive`], every primitive: its name in messages, its world-space
//!   validation (what the parsers guarantee and a loaded raster file must
//!   satisfy) and its world box;
//! * [`Surface`], an object of the object table: its fixed-point geometry
//!   in the raster and the core object-table entry made of it
//!   ([`rrt_core::object_table::Shape`]), its core voxelizer call, its
//!   exact intersection for *intersection verification*, and its saved
//!   form in a raster file;
//! * [`SolidPrimitive`], a leaf of a CSG tree: its core solid
//!   ([`rrt_core::csg::Solid`]) in the raster.
//!
//! [`Shape`] is what the world object table holds: one surface primitive,
//! or [`Shape::Voxels`] for the objects whose voxels are the object
//! (volumes, `.vox` models, CSG results).
//!
//! # Exact intersections
//! [`Surface::intersect`] takes a [`Ray`] (the direction need not be unit
//! length; `t` is in units of it) and an open interval `(tmin, tmax)`, and
//! returns the nearest intersection with `tmin < t < tmax` and the
//! surface's true unit normal there:
//! * closed surfaces (spheres, tori) give the outward normal, also for a
//!   ray that starts inside;
//! * triangles give the normal of their winding, `(v1 − v0) × (v2 − v0)`,
//!   or the barycentric interpolation of their vertex normals;
//! * open cones give the outward normal of the lateral surface.
//!
//! None of them flips the normal towards the ray: shading does that
//! ([`crate::trace::shading::face_forward`]). Tangent (grazing) rays count as hits.
//! No input makes them panic; non-finite input gives `None`.

/// [`Surface::entry`] and [`Surface::voxelize`] for a primitive whose
/// fixed-point geometry `$fixed` is the core object-table entry `$entry`
/// and is voxelized by the core's `$voxelizer`.
macro_rules! core_surface {
    ($fixed:ty, $entry:path, $voxelizer:path) => {
        fn entry(fixed: $fixed) -> rrt_core::object_table::Shape {
            $entry(fixed)
        }

        fn voxelize(
            fixed: &$fixed,
            separation: rrt_core::voxelize::Separation,
            extent: rrt_core::raster::Extent,
            sink: &mut dyn rrt_core::voxelize::VoxelSink,
        ) -> Result<u64, rrt_core::voxelize::error::VoxelizeError> {
            $voxelizer(fixed, separation, extent, sink)
        }
    };
}

pub mod cone;
pub mod cuboid;
mod roots;
pub mod sphere;
pub mod torus;
pub mod triangle;

#[cfg(test)]
mod tests;

use glam::DVec3;
use rrt_core::csg;
use rrt_core::object_table as table;
use rrt_core::raster::Extent;
use rrt_core::voxelize::error::VoxelizeError;
use rrt_core::voxelize::{Separation, VoxelSink};

pub use cone::Cone;
pub use cuboid::Cuboid;
pub use sphere::Sphere;
pub use torus::Torus;
pub use triangle::Triangle;

use crate::frame::RasterFrame;
use crate::world::{Bounds, Hit, Ray};

/// Numbers in a primitive's saved form (a raster file's object slots).
pub const SLOTS: usize = 20;

/// A primitive's saved form: its numbers, unused ones 0.
pub type Slots = [f64; SLOTS];

/// The saved kind of [`Shape::Voxels`].
pub const VOXELS_KIND: u32 = 5;

/// Why a primitive has no place in the raster.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Unfit {
    /// A coordinate or length lies beyond the fixed-point range
    /// ([`crate::frame::MAX_FIXED`]).
    OutOfRange,
    /// Nothing is left of it in fixed point: a triangle without area, a
    /// cone whose end discs meet.
    Degenerate,
}

/// What every primitive has.
pub trait Primitive {
    /// What it is called in messages.
    const KIND: &'static str;

    /// Checks the world-space invariants: finite coordinates, radii in
    /// range, and the like.
    ///
    /// # Errors
    /// What is wrong, for a message.
    fn validate(&self) -> Result<(), &'static str>;

    /// A world box holding the primitive.
    fn bounds(&self) -> Bounds;
}

/// A primitive that is an object of the object table: a surface the
/// voxelizer draws and intersection verification intersects.
pub trait Surface: Primitive + Copy + Into<Shape> {
    /// The core's fixed-point geometry of it.
    type Fixed: Copy;

    /// The primitive in the raster `frame`.
    ///
    /// # Errors
    /// [`Unfit`]: beyond the fixed-point range, or nothing left of it.
    fn to_fixed(&self, frame: &RasterFrame) -> Result<Self::Fixed, Unfit>;

    /// Its entry in the core's object table (what the light pass reads).
    fn entry(fixed: Self::Fixed) -> table::Shape;

    /// Voxelizes it through its core voxelizer; returns the voxels offered.
    ///
    /// # Errors
    /// The voxelizer's refusal.
    fn voxelize(
        fixed: &Self::Fixed,
        separation: Separation,
        extent: Extent,
        sink: &mut dyn VoxelSink,
    ) -> Result<u64, VoxelizeError>;

    /// The exact intersection of `ray` in `(tmin, tmax)` (module docs).
    fn intersect(&self, ray: &Ray, tmin: f64, tmax: f64) -> Option<Hit>;

    /// The parameter of [`Surface::intersect`]'s hit, bit for bit, without
    /// its normal: what a shadow ray or a farther candidate needs.
    fn first_t(&self, ray: &Ray, tmin: f64, tmax: f64) -> Option<f64> {
        self.intersect(ray, tmin, tmax).map(|h| h.t)
    }

    /// Writes its saved form into `slots` (all 0 on entry) and returns its
    /// saved kind.
    fn save(&self, slots: &mut Slots) -> u32;

    /// The primitive a saved form describes, if `kind` is one of its own.
    fn load(kind: u32, slots: &Slots) -> Option<Self>;
}

/// A primitive that can be a leaf of a CSG tree.
pub trait SolidPrimitive {
    /// Its core solid in the raster `frame`; `None` beyond the fixed-point
    /// range.
    fn solid(&self, frame: &RasterFrame) -> Option<Box<dyn csg::Solid>>;
}

/// An object's exact geometry in world coordinates: an entry of the world
/// object table, indexed by the voxel records' object id as the paper's
/// object table is. Primitives are the scene's own geometry, before any
/// fixed-point rounding, so that verification intersects the true surface.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Shape {
    /// A sphere.
    Sphere(Sphere),
    /// An open cone or cylinder.
    Cone(Cone),
    /// A triangle of a polygon ([`crate::scene::polygon`]).
    Triangle(Triangle),
    /// A torus.
    Torus(Torus),
    /// No continuous definition: the voxels are the object (volumes,
    /// `.vox` models, CSG results). It has no exact intersection, so
    /// intersection verification keeps the discrete hit, shaded with the
    /// stored normals: interpolated between the neighbouring voxels of the
    /// object where `smooth` (volumes and CSG results, whose voxels sample
    /// a smooth surface), the hit voxel's own otherwise (`.vox` models,
    /// blocky by design).
    Voxels {
        /// Whether the stored normals are interpolated at the hit point.
        smooth: bool,
    },
}

/// Each surface primitive is a [`Shape`].
macro_rules! shape_from {
    ($($variant:ident),*) => {
        $(impl From<$variant> for Shape {
            fn from(s: $variant) -> Self {
                Self::$variant(s)
            }
        })*
    };
}

shape_from!(Sphere, Cone, Triangle, Torus);

/// `$body` with `$s` bound to the surface primitive in `$shape`, or
/// `$voxels` for [`Shape::Voxels`].
macro_rules! each_surface {
    ($shape:expr, $s:ident => $body:expr, voxels => $voxels:expr) => {
        match $shape {
            Shape::Sphere($s) => $body,
            Shape::Cone($s) => $body,
            Shape::Triangle($s) => $body,
            Shape::Torus($s) => $body,
            Shape::Voxels { .. } => $voxels,
        }
    };
}

impl Shape {
    /// What it is called in messages.
    #[must_use]
    pub fn kind(&self) -> &'static str {
        fn kind<S: Primitive>(_: &S) -> &'static str {
            S::KIND
        }
        each_surface!(self, s => kind(s), voxels => "voxels")
    }

    /// The exact intersection of `ray` with the shape in `(tmin, tmax)`,
    /// with the true normal there (module docs); `None` for
    /// [`Shape::Voxels`].
    #[must_use]
    #[inline(always)]
    pub fn intersect(&self, ray: &Ray, tmin: f64, tmax: f64) -> Option<Hit> {
        each_surface!(self, s => s.intersect(ray, tmin, tmax), voxels => None)
    }

    /// [`Shape::intersect`]'s `t`, bit for bit, without computing the
    /// normal ([`Surface::first_t`]); `None` for [`Shape::Voxels`].
    #[must_use]
    #[inline]
    pub fn first_t(&self, ray: &Ray, tmin: f64, tmax: f64) -> Option<f64> {
        each_surface!(self, s => s.first_t(ray, tmin, tmax), voxels => None)
    }

    /// The radius of a ball that holds the shape, half the diagonal of its
    /// [`Primitive::bounds`]: its size (infinite for [`Shape::Voxels`],
    /// which has no geometry of its own).
    #[must_use]
    pub fn radius(&self) -> f64 {
        self.bounds()
            .map_or(f64::INFINITY, |b| 0.5 * (b.max - b.min).length())
    }

    /// A world box holding the shape ([`Primitive::bounds`]); `None` for
    /// [`Shape::Voxels`], which has no geometry of its own.
    #[must_use]
    pub fn bounds(&self) -> Option<Bounds> {
        each_surface!(self, s => Some(s.bounds()), voxels => None)
    }

    /// Whether the shape has exact geometry to verify hits against (all
    /// but [`Shape::Voxels`]).
    #[must_use]
    pub const fn is_exact(&self) -> bool {
        !matches!(self, Self::Voxels { .. })
    }

    /// Whether a ray leaving a point of this shape's surface, towards the
    /// side its normal there faces, can meet the shape again: `front` says
    /// that side is the one the shape's own normal points to (the outside
    /// of a closed shape). A flat triangle (whose normal is its plane's)
    /// never meets its plane again, a sphere left from outside never meets
    /// itself again (it is convex); everything else may, a triangle with
    /// interpolated normals too (its shading normal is not its plane's).
    #[must_use]
    pub const fn meets_itself_leaving(&self, front: bool) -> bool {
        match self {
            Self::Triangle(t) => t.normals.is_some(),
            Self::Sphere(_) => !front,
            Self::Cone(_) | Self::Torus(_) | Self::Voxels { .. } => true,
        }
    }

    /// Checks the world-space invariants of its primitive.
    ///
    /// # Errors
    /// What is wrong, for a message.
    pub fn validate(&self) -> Result<(), &'static str> {
        each_surface!(self, s => s.validate(), voxels => Ok(()))
    }

    /// Its saved form: the kind and the numbers.
    #[must_use]
    pub fn save(&self) -> (u32, Slots) {
        let mut slots = [0.0; SLOTS];
        let kind = each_surface!(self, s => s.save(&mut slots), voxels => VOXELS_KIND);
        if let Self::Voxels { smooth: true } = self {
            slots[0] = 1.0;
        }
        (kind, slots)
    }

    /// The shape a saved form describes; `None` for an unknown kind.
    #[must_use]
    pub fn load(kind: u32, slots: &Slots) -> Option<Self> {
        if kind == VOXELS_KIND {
            return Some(Self::Voxels {
                smooth: slots[0] != 0.0,
            });
        }
        Sphere::load(kind, slots)
            .map(Self::Sphere)
            .or_else(|| Cone::load(kind, slots).map(Self::Cone))
            .or_else(|| Triangle::load(kind, slots).map(Self::Triangle))
            .or_else(|| Torus::load(kind, slots).map(Self::Torus))
    }
}

/// Voxelizes an object-table entry made by [`Surface::entry`] through its
/// primitive's core voxelizer; entries without a surface of their own
/// (voxel objects voxelize themselves) offer nothing.
///
/// # Errors
/// The voxelizer's refusal.
pub fn voxelize(
    entry: &table::Shape,
    separation: Separation,
    extent: Extent,
    sink: &mut dyn VoxelSink,
) -> Result<u64, VoxelizeError> {
    match entry {
        table::Shape::Sphere(s) => Sphere::voxelize(s, separation, extent, sink),
        table::Shape::Cone(c) => Cone::voxelize(c, separation, extent, sink),
        table::Shape::Triangle(t) => Triangle::voxelize(t, separation, extent, sink),
        table::Shape::Torus(t) => Torus::voxelize(t, separation, extent, sink),
        // The box around an object that has no area in fixed point
        // (`crate::fit`).
        table::Shape::Cuboid(c) => rrt_core::voxelize::cuboid::surface(c, separation, extent, sink),
        _ => Ok(0),
    }
}

/// Writes `v` into `slots[at..at + 3]`.
fn put(slots: &mut Slots, at: usize, v: DVec3) {
    slots[at] = v.x;
    slots[at + 1] = v.y;
    slots[at + 2] = v.z;
}

/// The vector in `slots[at..at + 3]`.
fn get(slots: &Slots, at: usize) -> DVec3 {
    DVec3::new(slots[at], slots[at + 1], slots[at + 2])
}

/// Whether `x` is a finite number ≥ 0.
fn non_negative(x: f64) -> bool {
    x >= 0.0 && x.is_finite()
}

/// Whether `x` is a finite number > 0.
fn positive(x: f64) -> bool {
    x > 0.0 && x.is_finite()
}
