//! The objects of the object table in id order, as both voxelization
//! passes see them: the fitted primitives (spheres, cones, polygon
//! triangles, tori, in scene order), then the objects whose voxels are
//! the object: sampled and computed volumes, MagicaVoxel models and CSG
//! trees.
//!
//! Each object is offered to the count pass and to the fill pass through
//! the same deterministic walk, so both passes see the same voxels. The
//! voxel objects have no exact geometry: their world object is
//! [`Shape::Voxels`], whose hits verification keeps.

use rrt_core::fixed::FRAC_BITS;
use rrt_core::geometry::Point;
use rrt_core::object_table as table;
use rrt_core::voxelize::Separation;

use super::pass::Pass;
use super::{BuildError, csg, direct, volume, vox};
use crate::fit::{Fitted, FittedObject};
use crate::frame::RasterFrame;
use crate::scene::{Csg, Scene, VolumeObject, VoxObject};
use crate::shape::{self, Shape};

/// One object of the object table; its id is its index in
/// [`in_id_order`]'s list.
#[derive(Clone, Copy, Debug)]
pub enum TableObject<'s> {
    /// A fitted primitive.
    Primitive(&'s FittedObject),
    /// A sampled or computed volume.
    Volume(&'s VolumeObject),
    /// A MagicaVoxel model.
    Vox(&'s VoxObject),
    /// A CSG tree.
    Csg(&'s Csg),
}

/// The objects of `scene` fitted as `fitted`, in object-id order.
#[must_use]
pub fn in_id_order<'s>(scene: &'s Scene, fitted: &'s Fitted) -> Vec<TableObject<'s>> {
    let primitives = fitted.objects.iter().map(TableObject::Primitive);
    let volumes = scene.volumes.iter().map(TableObject::Volume);
    let voxes = scene.voxes.iter().map(TableObject::Vox);
    let csgs = scene.csgs.iter().map(TableObject::Csg);
    primitives.chain(volumes).chain(voxes).chain(csgs).collect()
}

impl TableObject<'_> {
    /// Its scene material (a CSG tree's: its first leaf's).
    #[must_use]
    pub fn material(&self) -> usize {
        match self {
            Self::Primitive(o) => o.material,
            Self::Volume(v) => v.material,
            Self::Vox(v) => v.material,
            Self::Csg(c) => c.leaves.first().map_or(0, |l| l.material),
        }
    }

    /// The scene materials of its CSG leaves (none for other objects).
    pub fn leaf_materials(&self) -> impl Iterator<Item = usize> + '_ {
        let leaves = match self {
            Self::Csg(c) => &c.leaves[..],
            _ => &[],
        };
        leaves.iter().map(|l| l.material)
    }

    /// Its exact world geometry.
    #[must_use]
    pub fn shape(&self) -> Shape {
        match self {
            Self::Primitive(o) => o.shape,
            Self::Vox(_) => Shape::Voxels { smooth: false },
            Self::Volume(_) | Self::Csg(_) => Shape::Voxels { smooth: true },
        }
    }

    /// Its entry in the core's object table.
    #[must_use]
    pub fn entry(&self) -> table::Shape {
        match self {
            Self::Primitive(o) => o.entry,
            _ => table::Shape::Voxels,
        }
    }

    /// The cells, per axis and inclusive, outside which the object's
    /// voxelizer offers nothing: its fixed-point geometry's box grown by
    /// `BOX_MARGIN` voxels; `None` where that box is not known here
    /// (volumes, voxel models, CSG trees, Bézier patches): every cell.
    #[must_use]
    pub fn cells(&self) -> Option<[(i64, i64); 3]> {
        let Self::Primitive(o) = self else {
            return None;
        };
        let (lo, hi) = match o.entry {
            table::Shape::Sphere(s) => grown(&[s.centre], s.radius),
            table::Shape::Triangle(t) => grown(&t.vertices, 0),
            table::Shape::Cone(c) => grown(
                &[c.base, c.apex],
                c.base_radius
                    .saturating_abs()
                    .max(c.apex_radius.saturating_abs()),
            ),
            table::Shape::Cuboid(c) => grown(&[c.min, c.max], 0),
            table::Shape::Torus(t) => grown(
                &[t.centre],
                t.major
                    .saturating_abs()
                    .saturating_add(t.minor.saturating_abs()),
            ),
            table::Shape::Patch(_) | table::Shape::Volume(_) | table::Shape::Voxels => {
                return None;
            }
        };
        let cell = |p: i64| p >> FRAC_BITS;
        Some([0, 1, 2].map(|k| {
            (
                cell(lo[k]).saturating_sub(BOX_MARGIN),
                cell(hi[k]).saturating_add(BOX_MARGIN),
            )
        }))
    }

    /// Voxelizes the object into `pass`. A volume rendered directly is
    /// voxelized from `samples`, its samples over the raster
    /// ([`direct::DirectVolume::new`]; `None` where it misses the raster:
    /// no voxels); other objects ignore `samples`.
    ///
    /// # Errors
    /// A voxelizer's refusal with the object's location, the store's.
    pub fn voxelize(
        &self,
        frame: &RasterFrame,
        separation: Separation,
        samples: Option<&direct::DirectVolume>,
        pass: Pass<'_, '_, '_, '_>,
    ) -> Result<(), BuildError> {
        match *self {
            Self::Primitive(o) => primitive(o, frame, separation, pass),
            Self::Volume(v) if v.data.classifier.is_direct() => {
                samples.map_or(Ok(()), |d| direct::voxelize_object(d, pass))
            }
            Self::Volume(v) => volume::voxelize_object(v, frame, separation, None, pass),
            Self::Vox(v) => vox::voxelize_object(v, frame, pass),
            Self::Csg(c) => csg::voxelize_object(c, frame, separation, pass),
        }
    }
}

/// Voxels beyond a primitive's fixed-point box that its voxelizer may
/// still offer: the lattice-step probes reach half a voxel beyond the
/// surface, a closed cell touching the box counts; two leave room.
const BOX_MARGIN: i64 = 2;

/// The box of `points` grown by `r` (≥ 0) on every side (saturating).
fn grown(points: &[Point], r: i64) -> (Point, Point) {
    let r = r.saturating_abs();
    let mut lo = [i64::MAX; 3];
    let mut hi = [i64::MIN; 3];
    for p in points {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k].saturating_sub(r));
            hi[k] = hi[k].max(p[k].saturating_add(r));
        }
    }
    (lo, hi)
}

/// Voxelizes a fitted primitive through its core voxelizer; in the fill
/// pass coloured by its material's texture, if any.
fn primitive(
    o: &FittedObject,
    frame: &RasterFrame,
    separation: Separation,
    pass: Pass<'_, '_, '_, '_>,
) -> Result<(), BuildError> {
    let extent = frame.extent;
    let voxelized = match pass {
        Pass::Count(counter) => shape::voxelize(&o.entry, separation, extent, counter),
        Pass::Fill {
            filler,
            attrs,
            texture,
            ..
        } => {
            filler.begin_object(attrs)?;
            match texture {
                Some(t) => shape::voxelize(&o.entry, separation, extent, &mut filler.textured(t)),
                None => shape::voxelize(&o.entry, separation, extent, filler),
            }
        }
    };
    voxelized.map_err(|why| BuildError::Voxelize {
        loc: o.loc.clone(),
        what: o.kind,
        why,
    })?;
    Ok(())
}
