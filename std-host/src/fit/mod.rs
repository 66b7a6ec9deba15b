//! Fitting the 3D raster to a scene: world coordinates to fixed-point
//! raster coordinates, once.
//!
//! The raster's box is the box around all geometry ([`Scene::bounds`]:
//! spheres ± radius, polygon vertices, cone end discs ± radius) grown by a
//! margin of a few voxels on every side, or exactly the box the caller
//! gives. Voxels are cubes: `raster N` is the number of voxels along the
//! box's longest axis, and each other axis gets `ceil(extent / voxel)`
//! voxels (plus the margins), the geometry centred in it.
//!
//! [`fit`] then converts every object to the core's fixed-point geometry
//! ([`rrt_core::geometry`]: positions in 1/65536 voxel, unit normals
//! scaled by 2^30): spheres, triangles (polygons cut into triangles, `pp`
//! patches with their vertex normals normalised) and open cones; and
//! every light to a fixed-point position (lights may lie outside the
//! raster). [`RasterFrame`] keeps the mapping both ways.
//!
//! * [`size`]: the raster's frame for a scene ([`frame`]);
//! * [`memory`]: the memory estimate ([`estimate_memory`]), which counts
//!   the scene's own data too; the machine's memory and the default limit
//!   are in [`crate::memory`].
//!
//! Before anything is allocated, [`MemoryEstimate`] bounds what the
//! voxelized raster will take, and [`fit`] refuses a raster that would
//! exceed the caller's limit ([`default_max_memory`]: half the machine's
//! RAM).

pub mod memory;
pub mod size;

#[cfg(test)]
mod tests;

use glam::DVec3;
use rrt_core::geometry::Point;
use rrt_core::object_table as table;
use rrt_core::raster::MAX_AXIS;

pub use self::memory::{Dims, MemoryEstimate, SurfaceMeasure, estimate_memory};
pub use self::size::{DEFAULT_MARGIN, frame};
pub use self::size::{
    MAX_DEFAULT_RASTER, MIN_DEFAULT_RASTER, RasterNeed, VOXELS_PER_SAMPLE, default_raster,
};
pub use crate::memory::{Bytes, default_max_memory, parse_meminfo, total_memory};

use crate::frame::{MAX_FIXED_VOXEL_BITS, RasterFrame};
use crate::scene::{Object, Scene, SourceLoc};
use crate::shape::{Shape, Surface, Unfit};
use crate::world::{Bounds, Coord, WORLD_LIMIT, within_world};

/// How to fit the raster.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FitOptions {
    /// Voxels along the longest axis (1 to 65536).
    pub raster: u32,
    /// World box to fill instead of the geometry's bounds (used exactly,
    /// without margin).
    pub bounds: Option<Bounds>,
    /// Voxels of margin around computed bounds on every side.
    pub margin: u32,
    /// Refuse rasters whose estimated memory, with `image`, exceeds this
    /// many bytes.
    pub max_memory: u64,
    /// Bytes of the image the raster is rendered into, held beside it and
    /// counted against `max_memory` with it (0: none).
    pub image: u64,
    /// Count sphere interiors in the memory estimate (a voxelizer that
    /// fills solids); surfaces are always counted.
    pub solid_spheres: bool,
}

impl FitOptions {
    /// `raster` voxels along the longest axis, computed bounds with the
    /// default margin, half the machine's memory as the limit, solid
    /// spheres counted.
    #[must_use]
    pub fn new(raster: u32) -> Self {
        Self {
            raster,
            bounds: None,
            margin: DEFAULT_MARGIN,
            max_memory: default_max_memory(),
            image: 0,
            solid_spheres: true,
        }
    }
}

/// Why a raster cannot be fitted.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum FitError {
    /// `raster N` out of range.
    #[error("raster {0}: expected 1 to {MAX_AXIS} voxels along the longest axis")]
    RasterSize(u32),
    /// `raster N` leaves nothing inside the margins.
    #[error("raster {raster}: too small for a margin of {margin} voxels on each side; use at least {}", 2 * u64::from(*margin) + 1)]
    RasterBelowMargin {
        /// The raster size.
        raster: u32,
        /// The margin.
        margin: u32,
    },
    /// Explicit bounds that are not a box.
    #[error(
        "bounds {min} to {max}: expected corners within ±{WORLD_LIMIT:e} with min < max on every axis"
    )]
    BadBounds {
        /// Lowest corner.
        min: DVec3,
        /// Highest corner.
        max: DVec3,
    },
    /// The geometry has no extent, is not finite, or reaches beyond
    /// [`WORLD_LIMIT`].
    #[error("{file}: {}", no_extent(*min, *max))]
    NoExtent {
        /// The scene file.
        file: String,
        /// Lowest corner.
        min: DVec3,
        /// Highest corner.
        max: DVec3,
    },
    /// The estimated memory exceeds the limit.
    #[error("raster {dims}: needs about {} ({estimate}), more than the limit of {}; use a smaller raster or a larger memory limit", Bytes(estimate.total()), Bytes(*limit))]
    TooMuchMemory {
        /// Voxels per axis, e.g. `1024×1024×87`.
        dims: Dims,
        /// The estimate.
        estimate: MemoryEstimate,
        /// The limit in bytes.
        limit: u64,
    },
    /// A light's position is not finite (scene readers refuse such
    /// numbers; this guards scenes built in code).
    #[error("{loc}: {what} position is not finite")]
    NotFinite {
        /// Where it is defined.
        loc: SourceLoc,
        /// What it is.
        what: &'static str,
    },
    /// An object or a light reaches beyond [`WORLD_LIMIT`].
    #[error(
        "{loc}: {what} reaches beyond ±{WORLD_LIMIT:e} world units, where the exact arithmetic of intersections and shading would overflow; scale the scene down"
    )]
    BeyondWorld {
        /// Where it is defined.
        loc: SourceLoc,
        /// What it is.
        what: &'static str,
    },
    /// The object table cannot be allocated (the memory estimate passed,
    /// but the system refused).
    #[error("cannot allocate {} for the object table of {objects} objects; use a smaller scene or free memory", Bytes(*bytes))]
    Alloc {
        /// Objects the table was to hold.
        objects: usize,
        /// Bytes asked for.
        bytes: u64,
    },
    /// An object lies too far from the raster for fixed point.
    #[error("{loc}: {what} lies more than 2^{MAX_FIXED_VOXEL_BITS} voxels from the raster")]
    OutOfRange {
        /// Where it is defined.
        loc: SourceLoc,
        /// What it is.
        what: &'static str,
    },
}

/// One object of the object table: its exact world geometry and, made of
/// it, the core's fixed-point geometry in the raster.
#[derive(Clone, Debug, PartialEq)]
pub struct FittedObject {
    /// The world geometry (what intersection verification intersects).
    pub shape: Shape,
    /// The core's object-table entry: the fixed-point geometry the
    /// voxelizer draws and the light pass reads.
    pub entry: table::Shape,
    /// Index into `Scene::materials`.
    pub material: usize,
    /// What the scene calls it (`sphere`, `cone`, `polygon`), for messages.
    pub kind: &'static str,
    /// Where the scene object is defined.
    pub loc: SourceLoc,
}

/// A light in fixed-point raster coordinates.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FittedLight {
    /// Position in fixed units ([`RasterFrame::light_to_fixed`]: within
    /// 2^44 voxels of the raster, a light farther away taken by its
    /// direction).
    pub position: Point,
    /// Colour (white if the file gives none).
    pub colour: DVec3,
}

/// Objects left out of the object table.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Dropped {
    /// Triangles and cones that have no area once in fixed point.
    pub degenerate: usize,
    /// Objects entirely outside explicit bounds.
    pub outside: usize,
}

/// A scene fitted to a raster.
#[derive(Clone, Debug, PartialEq)]
pub struct Fitted {
    /// The mapping between world and raster.
    pub frame: RasterFrame,
    /// The object table: spheres, then cones, then polygon triangles, each
    /// in file order.
    pub objects: Vec<FittedObject>,
    /// Lights in file order.
    pub lights: Vec<FittedLight>,
    /// The memory estimate that was checked.
    pub memory: MemoryEstimate,
    /// What was left out.
    pub dropped: Dropped,
}

/// Fits a raster to `scene`, checks the memory estimate, and converts the
/// geometry and lights to fixed point.
///
/// # Errors
/// [`FitError`]: an absurd raster size, bad explicit bounds, geometry
/// without extent, an estimate above `opts.max_memory`, a light or
/// object too far from the raster, or geometry or a light beyond
/// [`WORLD_LIMIT`].
pub fn fit(scene: &Scene, opts: &FitOptions) -> Result<Fitted, FitError> {
    if opts.bounds.is_none() {
        // Named by its place before the scene's bounds would refuse it.
        beyond_world(scene)?;
    }
    let frame = frame(scene, opts)?;
    let memory = MemoryEstimate {
        image: opts.image,
        ..estimate_memory(scene, &frame, opts.solid_spheres)
    };
    if memory.total() > opts.max_memory {
        return Err(FitError::TooMuchMemory {
            dims: Dims(frame.dims()),
            estimate: memory,
            limit: opts.max_memory,
        });
    }
    let count = scene
        .spheres
        .len()
        .saturating_add(scene.cones.len())
        .saturating_add(scene.triangle_count())
        .saturating_add(scene.tori.len());
    let mut objects = Vec::new();
    objects
        .try_reserve_exact(count)
        .map_err(|_| FitError::Alloc {
            objects: count,
            bytes: u64::try_from(count.saturating_mul(size_of::<FittedObject>()))
                .unwrap_or(u64::MAX),
        })?;
    let mut table = Table {
        frame: &frame,
        world: frame.world_bounds(),
        objects,
        dropped: Dropped::default(),
    };
    table.add_all(&scene.spheres)?;
    table.add_all(&scene.cones)?;
    for p in &scene.polygons {
        if table.outside(scene.polygon_bounds(p)) {
            table.dropped.outside += p.triangle_count();
            continue;
        }
        for t in scene.polygon_triangles(p) {
            table.add(t, p.material, p.kind(), &p.loc)?;
        }
    }
    table.add_all(&scene.tori)?;
    let lights = scene
        .lights
        .iter()
        .map(|l| {
            if l.position.is_finite() && !within_world(l.position) {
                return Err(FitError::BeyondWorld {
                    loc: l.loc.clone(),
                    what: "light",
                });
            }
            Ok(FittedLight {
                position: frame
                    .light_to_fixed(l.position)
                    .ok_or(FitError::NotFinite {
                        loc: l.loc.clone(),
                        what: "light",
                    })?,
                colour: l.rgb(),
            })
        })
        .collect::<Result<_, FitError>>()?;
    let Table {
        objects, dropped, ..
    } = table;
    Ok(Fitted {
        frame,
        objects,
        lights,
        memory,
        dropped,
    })
}

/// The first sphere, cone, polygon or torus (in that order) that reaches
/// beyond [`WORLD_LIMIT`], as [`FitError::BeyondWorld`] at its place.
fn beyond_world(scene: &Scene) -> Result<(), FitError> {
    fn first<S: Surface>(list: &[Object<S>]) -> Result<(), FitError> {
        match list.iter().find(|o| !o.shape.bounds().within_world()) {
            Some(o) => Err(FitError::BeyondWorld {
                loc: o.loc.clone(),
                what: S::KIND,
            }),
            None => Ok(()),
        }
    }
    first(&scene.spheres)?;
    first(&scene.cones)?;
    if let Some(p) = scene
        .polygons
        .iter()
        .find(|p| !scene.polygon_bounds(p).within_world())
    {
        return Err(FitError::BeyondWorld {
            loc: p.loc.clone(),
            what: p.kind(),
        });
    }
    first(&scene.tori)
}

/// The object table as [`fit`] fills it.
struct Table<'f> {
    frame: &'f RasterFrame,
    /// The raster's world box.
    world: Bounds,
    objects: Vec<FittedObject>,
    dropped: Dropped,
}

impl Table<'_> {
    /// Whether world box `b` lies entirely outside the raster.
    fn outside(&self, b: Bounds) -> bool {
        b.max.cmplt(self.world.min).any() || b.min.cmpgt(self.world.max).any()
    }

    /// Adds `shape` of a scene object (`kind` at `loc`), or counts it as
    /// dropped when nothing of it is left in fixed point.
    fn add<S: Surface>(
        &mut self,
        shape: S,
        material: usize,
        kind: &'static str,
        loc: &SourceLoc,
    ) -> Result<(), FitError> {
        if !shape.bounds().within_world() {
            return Err(FitError::BeyondWorld {
                loc: loc.clone(),
                what: kind,
            });
        }
        match shape.to_fixed(self.frame) {
            Ok(fixed) => self.objects.push(FittedObject {
                shape: shape.into(),
                entry: S::entry(fixed),
                material,
                kind,
                loc: loc.clone(),
            }),
            // An object with area in the world that rounds to none in
            // fixed point (a cone or a sliver thinner than 1/65536 voxel):
            // voxelized as a box around it, so that it keeps the voxels
            // it lies in, and verified against its exact shape.
            Err(Unfit::Degenerate) => match self.enclosing_box(&shape.into()) {
                Some(b) => self.objects.push(FittedObject {
                    shape: shape.into(),
                    entry: table::Shape::Cuboid(b),
                    material,
                    kind,
                    loc: loc.clone(),
                }),
                None => self.dropped.degenerate += 1,
            },
            Err(Unfit::OutOfRange) => {
                return Err(FitError::OutOfRange {
                    loc: loc.clone(),
                    what: kind,
                });
            }
        }
        Ok(())
    }

    /// A fixed-point box holding `shape` with a unit to spare on every
    /// side, for a shape that has area in the world (`None` for one that
    /// has none: a triangle whose vertices are collinear, a cone whose
    /// base is its apex; or one out of the fixed-point range).
    fn enclosing_box(&self, shape: &Shape) -> Option<rrt_core::geometry::Cuboid> {
        let flat = match shape {
            Shape::Triangle(t) => {
                let [a, b, c] = t.vertices;
                (b - a).cross(c - a) == DVec3::ZERO
            }
            Shape::Cone(c) => c.base == c.apex,
            _ => false,
        };
        if flat {
            return None;
        }
        let b = shape.bounds()?;
        let lo = self.frame.to_fixed(b.min)?;
        let hi = self.frame.to_fixed(b.max)?;
        Some(rrt_core::geometry::Cuboid {
            min: lo.map(|v| v.saturating_sub(1)),
            max: hi.map(|v| v.saturating_add(1)),
        })
    }

    /// Adds every object of `list` that does not lie outside the raster.
    fn add_all<S: Surface>(&mut self, list: &[Object<S>]) -> Result<(), FitError> {
        for o in list {
            if self.outside(o.shape.bounds()) {
                self.dropped.outside += 1;
                continue;
            }
            self.add(o.shape, o.material, S::KIND, &o.loc)?;
        }
        Ok(())
    }
}

/// What is wrong with geometry bounds `min` to `max` that fit no raster.
fn no_extent(min: DVec3, max: DVec3) -> String {
    let p = |v: DVec3| format!("({}, {}, {})", Coord(v.x), Coord(v.y), Coord(v.z));
    if min.cmpgt(max).any() {
        "nothing to fit a raster to: every object is empty (an empty CSG result, a .vox model without voxels)".to_string()
    } else if !(max - min).is_finite() {
        format!(
            "the geometry's bounds {} to {} are too far apart to fit a raster to",
            p(min),
            p(max)
        )
    } else if !(within_world(min) && within_world(max)) {
        format!(
            "the geometry's bounds {} to {} reach beyond ±{WORLD_LIMIT:e} world units, where the exact arithmetic of intersections and shading would overflow; scale the scene down",
            p(min),
            p(max)
        )
    } else {
        format!(
            "the geometry's bounds {} to {} have no size to fit a raster to",
            p(min),
            p(max)
        )
    }
}
