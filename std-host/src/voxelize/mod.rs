//! From a scene to a voxelized raster: the paper's preprocessing phase
//! (voxelization and light visibility).
//!
//! [`build`] runs the whole pipeline, each pass on rayon's threads (the
//! `threads` of [`BuildOptions`]), with a result that does not depend on
//! their number:
//! 1. **fit** ([`crate::fit`]): the raster's frame, the memory estimate
//!    against the limit, every primitive and light in fixed point;
//! 2. **allocate** the plane ([`Plane`]: an anonymous map, with huge pages
//!    when it is small);
//! 3. **count pass** ([`slabs`]: the raster cut into z-slabs, each built on
//!    its own by the core's builder and joined): every object of the
//!    object table ([`objects::in_id_order`]) through its voxelizer into
//!    the [`Counter`](rrt_core::store::Counter) of each slab, with the
//!    separation the chosen rays need ([`Separation::for_rays`]); the exact
//!    record count is then checked against the memory limit before the
//!    records are allocated;
//! 4. **fill pass**: every object again, named with its object id,
//!    material and colour ([`materials`]; textured materials colour each
//!    voxel once, [`texture`]);
//!    [`Filler::finish`](rrt_core::store::Filler::finish) sorts the bricks
//!    and lays out the object lists; the slabs are joined;
//! 5. **finish** ([`finish_plane`]): the proximity distance field, which
//!    lets 26-runs skip empty space (and sets the proximity flags), the
//!    records' rank hints and the line level;
//! 6. **light visibility** ([`light`]): per record and light, one discrete
//!    shadow ray (the paper's two bits), or for a record of exact objects
//!    on an exact raster the shadow classification or nothing
//!    ([`LightParams::exact_records`]); then the precomputed ambient +
//!    diffuse illumination.
//!
//! The primitives are voxelized by their core voxelizers
//! ([`crate::shape`]); volumes ([`volume`]), `.vox` models ([`vox`]) and
//! CSG trees ([`csg`]) come after them, with object ids after theirs.
//!
//! The result, a [`VoxelScene`] ([`voxel_scene`]), holds everything
//! view-independent: the renderer ([`crate::trace`]) and the saved-raster
//! file ([`crate::output::rasterfile`]) both start from it.

pub mod csg;
pub mod direct;
pub mod light;
pub mod materials;
pub mod objects;
pub mod pass;
pub mod plane;
pub mod slabs;
pub mod texture;
pub mod volume;
pub mod vox;
pub mod voxel_scene;

use std::time::{Duration, Instant};

use indicatif::ProgressBar;
use rrt_core::connectivity::Connectivity;
use rrt_core::light::{ExactRecords, LightError, LightParams, LightReport};
use rrt_core::object_table::MAX_LIGHTS;
use rrt_core::store;
use rrt_core::voxel::VoxelRecord;
use rrt_core::voxelize::Separation;
use rrt_core::voxelize::error::VoxelizeError;

pub use self::materials::MAX_MATERIALS;
pub use self::voxel_scene::{
    DERIVE_MARGIN, VoxelScene, WorldLight, WorldObject, derive_plane, finish_plane, line_level,
    line_level_of_plane, plane_matches_records,
};

use self::light::{LightScene, ShadowLevel};
use self::materials::MaterialTable;
use self::plane::Plane;
use self::slabs::{Counted, Passes, Voxelized};
use self::texture::MaterialTextures;
use crate::fit::{self, Bytes, FitError, FitOptions};
use crate::progress::Unit;
use crate::scene::{Scene, SourceLoc};
use crate::world::Coord;

/// How to build.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BuildOptions {
    /// Raster size, bounds and memory limit.
    pub fit: FitOptions,
    /// The rays the raster is built for: decides the separation.
    pub connectivity: Connectivity,
    /// Shadow rays of the light pass, and what it computes for records of
    /// exact objects ([`LightParams::exact_records`]; only on an
    /// [`exact`](Self::exact) raster, the paper's bits otherwise).
    pub light: LightParams,
    /// Threads of the voxelization, the plane's last pass and the light
    /// pass; 0 for one per core. The result does not depend on it.
    pub threads: usize,
    /// Voxelize for exact intersection verification: every object
    /// conservatively ([`Separation::TwentySix`]: each voxel whose closed
    /// cube its surface meets, however small the object), and every voxel
    /// that several objects' surfaces pass through gets the list of all of
    /// them ([`rrt_core::store`], *Object lists*). Otherwise the paper's
    /// raster: the separation the rays need, one object per voxel.
    pub exact: bool,
}

/// The shadow rays of the light pass and of the renderer: the core's
/// defaults (the 6-connected line) walked adaptively, skipping empty
/// space. Both run on a finished plane ([`finish_plane`], or the plane a
/// saved raster makes on load), whose proximity flags make an adaptive
/// walk meet the opaque voxels of the 6-connected one, in the same order
/// ([`LightParams::mode`]): the same answers, in less time.
pub(crate) fn pass_light_params() -> LightParams {
    LightParams {
        mode: Connectivity::Adaptive,
        ..LightParams::default()
    }
}

impl BuildOptions {
    /// `raster` voxels along the longest axis, for adaptive rays, exact
    /// (object lists, and the shadow classification for records of exact
    /// objects: what every render mode can use), default limits.
    #[must_use]
    pub fn new(raster: u32) -> Self {
        Self {
            fit: FitOptions {
                solid_spheres: false,
                ..FitOptions::new(raster)
            },
            connectivity: Connectivity::Adaptive,
            light: LightParams {
                exact_records: ExactRecords::Classify,
                ..pass_light_params()
            },
            threads: 0,
            exact: true,
        }
    }

    /// The paper's raster: one object per voxel, as thick as the rays
    /// need, the paper's light bits for every record.
    #[must_use]
    pub fn paper(raster: u32) -> Self {
        Self {
            light: pass_light_params(),
            exact: false,
            ..Self::new(raster)
        }
    }
}

/// What the build did, and how long each phase took.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct BuildReport {
    /// Objects voxelized.
    pub objects: usize,
    /// Objects dropped by the fit (degenerate in fixed point, or outside
    /// explicit bounds).
    pub dropped: usize,
    /// Voxel offers inside the raster in the count pass.
    pub offers: u64,
    /// Records (non-transparent voxels).
    pub records: usize,
    /// The light pass's counts.
    pub light: LightReport,
    /// Fit, allocation and both voxelization passes (with proximity flags).
    pub voxelize: Duration,
    /// The light pass.
    pub lights: Duration,
}

/// Why a scene could not be built.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum BuildError {
    /// The raster could not be fitted (size, bounds, memory estimate).
    #[error(transparent)]
    Fit(#[from] FitError),
    /// The explicit bounds hold no surface voxel of any object.
    #[error(
        "{file}: the bounds [{}, {}, {}] to [{}, {}, {}] contain no geometry: the image would be empty",
        Coord(bounds.min.x), Coord(bounds.min.y), Coord(bounds.min.z),
        Coord(bounds.max.x), Coord(bounds.max.y), Coord(bounds.max.z)
    )]
    EmptyBounds {
        /// The scene file.
        file: String,
        /// The bounds asked for.
        bounds: crate::world::Bounds,
    },
    /// More lights than the records have visibility bits for.
    #[error(
        "{loc}: light {index}: rrt supports at most {MAX_LIGHTS} lights (2 visibility bits each in a voxel record)"
    )]
    TooManyLights {
        /// The first light too many.
        loc: SourceLoc,
        /// Its index (from 1).
        index: usize,
    },
    /// More distinct materials than the table holds.
    #[error("{loc}: material {count}: rrt supports at most {MAX_MATERIALS} distinct materials")]
    TooManyMaterials {
        /// The first material too many.
        loc: SourceLoc,
        /// Its number among the distinct ones.
        count: usize,
    },
    /// A voxelizer refused an object.
    #[error("{loc}: {what}: cannot voxelize: {why}")]
    Voxelize {
        /// Where the object is defined.
        loc: SourceLoc,
        /// What it is.
        what: &'static str,
        /// Why.
        why: VoxelizeError,
    },
    /// A CSG leaf or capped cone with no inside at the raster's fixed-point
    /// precision (thinner or smaller than the core can represent).
    #[error(
        "{loc}: {what}: too thin or too small to have an inside at the raster's precision (a degenerate solid)"
    )]
    DegenerateSolid {
        /// Where the solid is defined.
        loc: SourceLoc,
        /// What it is.
        what: &'static str,
    },
    /// A `.vox` cell wider than [`vox::MAX_VOX_SCALE`] raster voxels.
    #[error(
        "{loc}: vox cell: {voxels} raster voxels across, more than {}; give a coarser --raster or a smaller cell",
        vox::MAX_VOX_SCALE
    )]
    VoxCell {
        /// Where the model is placed.
        loc: SourceLoc,
        /// Raster voxels per cell.
        voxels: f64,
    },
    /// The exact record count exceeds the memory limit.
    #[error("raster {dims}: the scene has {records} surface voxels; plane, directory, records and object table need {}{}, more than the limit of {}; use a smaller raster or a larger memory limit", Bytes(*needed), if *image > 0 { format!(" beside the image's {}", Bytes(*image)) } else { String::new() }, Bytes(*limit))]
    TooMuchMemory {
        /// Voxels per axis.
        dims: fit::Dims,
        /// Records counted.
        records: usize,
        /// Bytes the raster needs.
        needed: u64,
        /// Bytes of the image beside it ([`FitOptions::image`]).
        image: u64,
        /// The limit.
        limit: u64,
    },
    /// Memory could not be had from the system.
    #[error("cannot allocate {} for the {what}", Bytes(*bytes))]
    Alloc {
        /// What.
        what: &'static str,
        /// How much.
        bytes: u64,
        /// The system's error.
        #[source]
        source: std::io::Error,
    },
    /// The core builder refused (a pass mismatch: a bug, reported).
    #[error("scene builder: {0}")]
    Store(#[from] store::BuildError),
    /// The light pass failed.
    #[error("light visibility: {0}")]
    Light(#[from] LightError),
    /// The raster or store did not validate (a bug, reported).
    #[error("raster: {0}")]
    Raster(String),
}

impl BuildError {
    /// A light, object or `.vox` placement beyond the fixed-point range.
    pub(crate) fn out_of_range(loc: &SourceLoc, what: &'static str) -> Self {
        Self::Fit(FitError::OutOfRange {
            loc: loc.clone(),
            what,
        })
    }

    /// A CSG tree the core refuses.
    pub(crate) fn csg(loc: &SourceLoc, e: &rrt_core::csg::CsgError) -> Self {
        Self::Raster(format!("{loc}: CSG tree: {e}"))
    }
}

/// An empty vector with room for `len` values, or [`BuildError::Alloc`]
/// naming `what` when the allocation fails.
fn try_vec<T>(len: usize, what: &'static str) -> Result<Vec<T>, BuildError> {
    let mut v = Vec::new();
    v.try_reserve_exact(len).map_err(|e| {
        alloc_err(what, len.saturating_mul(size_of::<T>()))(std::io::Error::new(
            std::io::ErrorKind::OutOfMemory,
            e,
        ))
    })?;
    Ok(v)
}

fn alloc_err(what: &'static str, bytes: usize) -> impl FnOnce(std::io::Error) -> BuildError {
    move |source| BuildError::Alloc {
        what,
        bytes: u64::try_from(bytes).unwrap_or(u64::MAX),
        source,
    }
}

/// Builds the voxelized scene (module docs). `progress` shows the passes
/// (pass [`ProgressBar::hidden`] for none).
///
/// # Errors
/// [`BuildError`]: the fit's refusals, too many lights or materials, a
/// voxelizer's refusal with the object's location, the memory limit, an
/// allocation failure.
pub fn build(
    scene: &Scene,
    opts: &BuildOptions,
    progress: &ProgressBar,
) -> Result<(VoxelScene, BuildReport), BuildError> {
    let t0 = Instant::now();
    if let Some(l) = scene.lights.get(MAX_LIGHTS) {
        return Err(BuildError::TooManyLights {
            loc: l.loc.clone(),
            index: MAX_LIGHTS + 1,
        });
    }
    let materials = MaterialTable::new(scene)?;
    let fitted = fit::fit(scene, &opts.fit)?;
    let frame = fitted.frame;
    let extent = frame.extent;
    let separation = if opts.exact {
        Separation::TwentySix
    } else {
        Separation::for_rays(opts.connectivity)
    };
    let objects = objects::in_id_order(scene, &fitted);
    let n = objects.len();
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(opts.threads)
        .build()
        .map_err(|e| BuildError::Raster(format!("cannot start threads: {e}")))?;

    let mut plane = Plane::zeroed(extent.len()).map_err(alloc_err("raster plane", extent.len()))?;
    let textures = MaterialTextures::new(scene, frame);
    // Sampled once: the passes offer their voxels from these samples, and
    // the tracer composites them.
    let mut direct =
        pool.install(|| direct_volumes(&objects, &frame, scene, opts.fit.max_memory))?;
    let passes = Passes {
        objects: &objects,
        frame: &frame,
        separation,
        materials: &materials,
        textures: &textures,
        exact: opts.exact,
        direct: &direct,
    };
    let pieces = slabs::pieces(extent.dims(), pool.current_num_threads());
    // Refused after the count pass, before the records are allocated: an
    // empty box, or more memory than the limit for the exact record count
    // (and the lists' working storage, the count pass's bound, see
    // `Sizing::list_entries`).
    let check = |c: Counted| {
        if let Some(bounds) = opts.fit.bounds
            && c.records == 0
        {
            return Err(BuildError::EmptyBounds {
                file: scene.file.to_string(),
                bounds,
            });
        }
        let needed = u64::try_from(
            extent
                .len()
                .saturating_add(c.band_planes)
                // The directory and the shadow classification's brick
                // level (a byte and an owner per brick).
                .saturating_add(c.directory.saturating_mul(2 * size_of::<u32>() + 1))
                // The records, and the light pass's lit copy of them.
                .saturating_add(c.records.saturating_mul(2 * size_of::<VoxelRecord>()))
                .saturating_add(c.list_entries.saturating_mul(size_of::<u32>())),
        )
        .unwrap_or(u64::MAX)
        // The object table's forms (fitted, the core's, the world's).
        .saturating_add((n as u64).saturating_mul(fit::memory::OBJECT_BYTES));
        if needed.saturating_add(opts.fit.image) > opts.fit.max_memory {
            return Err(BuildError::TooMuchMemory {
                dims: fit::Dims(extent.dims()),
                records: c.records,
                needed,
                image: opts.fit.image,
                limit: opts.fit.max_memory,
            });
        }
        Ok(())
    };
    let Voxelized {
        directory,
        mut records,
        lists,
        offers,
    } = passes.run(&mut plane, &pieces, &pool, check, progress)?;
    let records_n = records.len();
    // The light pass changes no cell and no record's place: the plane can
    // be finished first, so that its walks read the distance field and
    // the rank hints.
    let store = rrt_core::store::RecordStore::with_lists(extent, &directory, &records, &lists)
        .map_err(|e| BuildError::Raster(e.to_string()))?;
    for d in &mut direct {
        d.mark_alone(&store);
    }
    let lines = pool.install(|| finish_plane(&mut plane, &store));
    let voxelize = t0.elapsed();

    let t1 = Instant::now();
    let light = LightParams {
        exact_records: if opts.exact {
            opts.light.exact_records
        } else {
            ExactRecords::Paper
        },
        ..opts.light
    };
    crate::progress::phase(progress, "light visibility", Unit::Voxels, records_n as u64);
    let raster = rrt_core::raster::Raster::new(extent, &plane)
        .and_then(|r| r.with_lines(&lines))
        .map_err(|e| BuildError::Raster(e.to_string()))?;
    // The brick level serves the shadow classification only.
    let level = match light.exact_records {
        ExactRecords::Classify => Some(ShadowLevel::of(&store)?),
        ExactRecords::Paper | ExactRecords::Skip => None,
    };
    let (lit, light_report) = LightScene::new(&objects, &materials, &fitted.lights).illuminate(
        &raster,
        &store,
        &light,
        level.as_ref(),
        &pool,
        progress,
    )?;
    records = lit;
    let lights_time = t1.elapsed();

    let world_objects = objects
        .iter()
        .map(|o| WorldObject {
            shape: o.shape(),
            material: materials.of(o.material()),
        })
        .collect();
    let world_lights = scene
        .lights
        .iter()
        .map(|l| WorldLight {
            position: l.position,
            colour: l.rgb(),
        })
        .collect();
    let report = BuildReport {
        objects: n,
        dropped: fitted.dropped.degenerate + fitted.dropped.outside,
        offers,
        records: records_n,
        light: light_report,
        voxelize,
        lights: lights_time,
    };
    Ok((
        VoxelScene {
            frame,
            separation,
            plane,
            lines,
            directory,
            records,
            lists,
            exact: opts.exact,
            exact_records: light.exact_records,
            objects: world_objects,
            materials: materials.list,
            lights: world_lights,
            background: scene.background,
            view: scene.view.clone(),
            direct,
        },
        report,
    ))
}

/// The samples and transfer functions of the volumes rendered directly
/// ([`direct::DirectVolume`]), in object-id order.
fn direct_volumes(
    objects: &[objects::TableObject<'_>],
    frame: &crate::frame::RasterFrame,
    scene: &Scene,
    max_bytes: u64,
) -> Result<Vec<direct::DirectVolume>, BuildError> {
    let mut out = Vec::new();
    for (id, o) in objects.iter().enumerate() {
        let objects::TableObject::Volume(v) = o else {
            continue;
        };
        if !v.data.classifier.is_direct() {
            continue;
        }
        let base = scene.materials.get(v.material).map_or([255; 3], |m| {
            [m.colour.x, m.colour.y, m.colour.z].map(|c| (c.clamp(0.0, 1.0) * 255.0).round() as u8)
        });
        let id = u32::try_from(id).map_err(|_| BuildError::Raster("too many objects".into()))?;
        let d = direct::DirectVolume::new(id, &v.data, frame, base, max_bytes)
            .map_err(|e| BuildError::Raster(format!("{}: volume: {e}", v.loc)))?;
        out.extend(d);
    }
    Ok(out)
}
