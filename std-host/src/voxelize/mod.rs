//! From a scene to a voxelized raster: the paper's preprocessing phase
//! (voxelization and light visibility).
//!
//! [`build`] runs the whole pipeline:
//! 1. **fit** ([`crate::fit`]): the raster's frame, the memory estimate
//!    against the limit, every primitive and light in fixed point;
//! 2. **allocate** the plane ([`Plane`]: an anonymous map with huge pages)
//!    and the brick directory;
//! 3. **count pass**: every object of the object table
//!    ([`objects::in_id_order`]) through its voxelizer into the
//!    [`Counter`], with the separation the chosen rays need
//!    ([`Separation::for_rays`]); the exact record count is then checked
//!    against the memory limit before the records are allocated;
//! 4. **fill pass**: every object again, named with its object id,
//!    material and colour ([`materials`]; textured materials colour each
//!    voxel once, [`texture`]);
//!    [`Filler::finish`](rrt_core::store::Filler::finish) sorts the bricks
//!    and sets the proximity flags;
//! 5. **finish** ([`finish_plane`]): the proximity distance field, which
//!    lets 26-runs skip empty space, the records' rank hints and the line
//!    level;
//! 6. **light visibility** ([`light`]): per record and light, one discrete
//!    shadow ray (the paper's two bits), or for a record of exact objects
//!    on an exact raster the shadow classification or nothing
//!    ([`LightParams::exact_records`]); then the precomputed ambient +
//!    diffuse illumination; on rayon's threads; the result does not
//!    depend on the thread count.
//!
//! The primitives are voxelized by their core voxelizers
//! ([`crate::shape`]); volumes ([`volume`]), `.vox` models ([`vox`]) and
//! CSG trees ([`csg`]) come after them, with object ids after theirs.
//!
//! The result, a [`VoxelScene`] ([`voxel_scene`]), holds everything
//! view-independent: the renderer ([`crate::trace`]) and the saved-raster
//! file ([`crate::output::rasterfile`]) both start from it.

pub mod csg;
pub mod light;
pub mod materials;
pub mod objects;
pub mod pass;
pub mod plane;
pub mod texture;
pub mod volume;
pub mod vox;
pub mod voxel_scene;

use std::time::{Duration, Instant};

use indicatif::ProgressBar;
use rrt_core::connectivity::Connectivity;
use rrt_core::light::{ExactRecords, LightError, LightParams, LightReport};
use rrt_core::object_table::MAX_LIGHTS;
use rrt_core::raster::RasterMut;
use rrt_core::store::{self, Built, Counter, Limits, Sizing, directory_len};
use rrt_core::voxel::VoxelRecord;
use rrt_core::voxelize::Separation;
use rrt_core::voxelize::error::VoxelizeError;

pub use self::materials::MAX_MATERIALS;
pub use self::voxel_scene::{VoxelScene, WorldLight, WorldObject, finish_plane, line_level};

use self::light::LightScene;
use self::materials::MaterialTable;
use self::objects::TableObject;
use self::pass::Pass;
use self::plane::Plane;
use self::texture::MaterialTextures;
use crate::fit::{self, Bytes, FitError, FitOptions};
use crate::frame::RasterFrame;
use crate::progress::Unit;
use crate::scene::{Scene, SourceLoc};

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
    /// Threads of the light pass; 0 for one per core.
    pub threads: usize,
    /// Voxelize for exact intersection verification: every object
    /// conservatively ([`Separation::TwentySix`]: each voxel whose closed
    /// cube its surface meets, however small the object), and every voxel
    /// that several objects' surfaces pass through gets the list of all of
    /// them ([`rrt_core::store`], *Object lists*). Otherwise the paper's
    /// raster: the separation the rays need, one object per voxel.
    pub exact: bool,
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
                ..LightParams::default()
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
            light: LightParams::default(),
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
    /// Voxel offers in the count pass.
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
        bounds.min.x, bounds.min.y, bounds.min.z, bounds.max.x, bounds.max.y, bounds.max.z
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
    #[error("{loc}: {what}: cannot voxelize: {source}")]
    Voxelize {
        /// Where the object is defined.
        loc: SourceLoc,
        /// What it is.
        what: &'static str,
        /// Why.
        #[source]
        source: VoxelizeError,
    },
    /// The exact record count exceeds the memory limit.
    #[error("raster {dims}: the scene has {records} surface voxels; plane, directory and records need {}, more than the limit of {}; use a smaller raster or a larger memory limit", Bytes(*needed), Bytes(*limit))]
    TooMuchMemory {
        /// Voxels per axis.
        dims: fit::Dims,
        /// Records counted.
        records: usize,
        /// Bytes needed.
        needed: u64,
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

    let mut plane = Plane::zeroed(extent.len()).map_err(alloc_err("raster plane", extent.len()))?;
    let dir_len =
        directory_len(extent).ok_or_else(|| BuildError::Raster("too many bricks".into()))?;
    let mut directory = vec![0u32; dir_len];

    let (sizing, offers) = count_pass(
        &objects,
        &frame,
        separation,
        &mut plane,
        &mut directory,
        progress,
    )?;
    let records_n = sizing.records();
    if let Some(bounds) = opts.fit.bounds
        && records_n == 0
    {
        return Err(BuildError::EmptyBounds {
            file: scene.file.to_string(),
            bounds,
        });
    }
    // The lists' working storage: the count pass's bound (see
    // `Sizing::list_entries`), only for an exact raster.
    let list_n = if opts.exact { sizing.list_entries() } else { 0 };
    let needed = u64::try_from(
        extent
            .len()
            .saturating_add(dir_len.saturating_mul(size_of::<u32>()))
            .saturating_add(sizing.record_bytes())
            .saturating_add(list_n.saturating_mul(size_of::<u32>())),
    )
    .unwrap_or(u64::MAX);
    if needed > opts.fit.max_memory {
        return Err(BuildError::TooMuchMemory {
            dims: fit::Dims(extent.dims()),
            records: records_n,
            needed,
            limit: opts.fit.max_memory,
        });
    }
    let mut records = vec![VoxelRecord::default(); records_n];
    let mut lists = vec![0u32; list_n];
    let textures = MaterialTextures::new(scene, frame);
    let built = fill_pass(
        &objects,
        &frame,
        separation,
        sizing,
        (&mut records, opts.exact.then_some(&mut lists[..])),
        &materials,
        &textures,
        progress,
    )?;
    let lists_used = built.lists().len();
    lists.truncate(lists_used);
    lists.shrink_to_fit();
    // The light pass changes no cell and no record's place: the plane can
    // be finished first, so that its walks read the distance field and
    // the rank hints.
    let lines = finish_plane(extent, &mut plane, &directory, &records, &lists);
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
    let store = rrt_core::store::RecordStore::with_lists(extent, &directory, &records, &lists)
        .map_err(|e| BuildError::Raster(e.to_string()))?;
    let (lit, light_report) = LightScene::new(&objects, &materials, &fitted.lights).illuminate(
        &raster,
        &store,
        &light,
        opts.threads,
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
        },
        report,
    ))
}

/// The count pass: every object's voxels counted into the plane and the
/// brick directory. Returns the sizing of the records and the voxels
/// offered.
fn count_pass<'p, 'd>(
    objects: &[TableObject<'_>],
    frame: &RasterFrame,
    separation: Separation,
    plane: &'p mut [u8],
    directory: &'d mut [u32],
    progress: &ProgressBar,
) -> Result<(Sizing<'p, 'd>, u64), BuildError> {
    crate::progress::phase(
        progress,
        "voxelizing (count pass)",
        Unit::Objects,
        objects.len() as u64,
    );
    let raster =
        RasterMut::new(frame.extent, plane).map_err(|e| BuildError::Raster(e.to_string()))?;
    let mut counter = Counter::new(raster, directory)?;
    for o in objects {
        o.voxelize(frame, separation, Pass::Count(&mut counter))?;
        progress.inc(1);
    }
    let offers = counter.report().offers;
    Ok((counter.finish()?, offers))
}

/// The fill pass: every object again, into `records` (and, given list
/// storage, the object lists), named with its object id, material and
/// colour (a textured material's colour computed per voxel). Returns the
/// store, its bricks sorted and proximity flags set.
#[allow(clippy::too_many_arguments)]
fn fill_pass<'p, 'd, 'r>(
    objects: &[TableObject<'_>],
    frame: &RasterFrame,
    separation: Separation,
    sizing: Sizing<'p, 'd>,
    (records, lists): (&'r mut [VoxelRecord], Option<&'r mut [u32]>),
    materials: &MaterialTable,
    textures: &MaterialTextures,
    progress: &ProgressBar,
) -> Result<Built<'p, 'd, 'r>, BuildError> {
    crate::progress::phase(
        progress,
        "voxelizing (fill pass)",
        Unit::Objects,
        objects.len() as u64,
    );
    let limits = Limits {
        objects: u32::try_from(objects.len()).unwrap_or(u32::MAX),
        materials: u32::try_from(materials.list.len()).unwrap_or(u32::MAX),
    };
    let mut filler = match lists {
        Some(lists) => sizing.fill_with_lists(records, lists, limits)?,
        None => sizing.fill(records, limits)?,
    };
    for (id, o) in objects.iter().enumerate() {
        let m = o.material();
        let pass = Pass::Fill {
            filler: &mut filler,
            attrs: materials.attrs(id, m),
            leaves: o.leaf_materials().map(|l| materials.attrs(id, l)).collect(),
            texture: textures.of(m),
        };
        o.voxelize(frame, separation, pass)?;
        progress.inc(1);
    }
    Ok(filler.finish()?)
}
