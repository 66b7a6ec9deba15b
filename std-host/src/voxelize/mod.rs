//! From a scene to a voxelized raster: the paper's preprocessing phase.
//!
//! [`build`] runs the whole pipeline:
//! 1. **fit** ([`crate::fit`]): the raster's frame, the memory estimate
//!    against the limit, every object and light in fixed point;
//! 2. **allocate** the plane ([`Plane`]: an anonymous map with huge pages)
//!    and the brick directory;
//! 3. **count pass**: every object through its core voxelizer into the
//!    [`Counter`], with the separation the chosen rays need
//!    ([`Separation::for_rays`]); the exact record count is then checked
//!    against the memory limit before the records are allocated;
//! 4. **fill pass**: every object again, named with its object id,
//!    material and colour; [`Filler::finish`](rrt_core::store::Filler::finish) sorts the bricks and sets the
//!    proximity flags; then (after step 5) the proximity distance field
//!    ([`distance_field`]), which lets 26-runs skip empty space;
//! 5. **light visibility** ([`rrt_core::light::illuminate_run`], in runs of
//!    records on rayon's threads): one discrete shadow ray per record and
//!    light, the two visibility bits and the precomputed ambient + diffuse
//!    illumination (SPD intensities `I = sqrt(nl)/(2·nl)`, ambient the
//!    same). The result does not depend on the thread count. The runs
//!    write into a copy of the records (20 bytes per record while the pass
//!    runs), since the store they read must stay whole.
//!
//! The result, a [`VoxelScene`], holds everything view-independent: the
//! renderer ([`crate::trace`]) and the saved-raster file
//! ([`crate::rasterfile`]) both start from it.
//!
//! Volumes, `.vox` models and CSG trees ([`objects`]) go
//! through both passes after the fitted primitives, with object ids after
//! theirs. Textured materials colour each voxel once, in the fill pass.
//!
//! Materials are deduplicated (NFF files repeat identical `f` lines): the
//! record's 16-bit material index then names a distinct material, and at
//! most [`MAX_MATERIALS`] distinct ones are accepted.

#![deny(missing_docs)]

pub mod objects;
pub mod plane;
pub mod texture;
pub mod volume;
pub mod vox;

use std::collections::HashMap;
use std::time::{Duration, Instant};

use glam::DVec3;
use indicatif::ProgressBar;
use rayon::prelude::*;
use rrt_core::connectivity::Connectivity;
use rrt_core::light::{LightError, LightParams, LightReport, illuminate_run};
use rrt_core::object_table::{
    self, Light, Lights, MAX_LIGHTS, Materials, Object, ObjectTable, SCALAR_ONE,
};
use rrt_core::proximity::{distance_field, line_distances};
use rrt_core::raster::{Extent, Raster, RasterMut, line_count};
use rrt_core::store::{
    self, Counter, Limits, ObjectAttrs, RecordStore, StoreError, directory_len, write_rank_hints,
};
use rrt_core::voxel::VoxelRecord;
use rrt_core::voxelize::Separation;
use rrt_core::voxelize::error::VoxelizeError;

use self::objects::Pass;
use self::plane::Plane;
use self::texture::InRaster;
use crate::fit::{self, Bytes, FitError, FitOptions, Fitted};
use crate::frame::RasterFrame;
use crate::object_table::{WorldLight, WorldObject};
use crate::scene::{Material, Scene, SourceLoc, TextureKind, View};
use crate::shade;
use crate::shape::{self, Shape};
use crate::texture::AnyTexture;

/// Records per run of the parallel light pass.
const LIGHT_RUN: usize = 1 << 14;

/// Most distinct materials a scene may have (the record's index is 16
/// bits; the table is kept small enough to copy per render).
pub const MAX_MATERIALS: usize = 4096;

/// A voxelized scene: the raster, its records and everything the renderer
/// needs besides the view.
#[derive(Debug)]
pub struct VoxelScene {
    /// World ↔ raster mapping and the raster's dimensions.
    pub frame: RasterFrame,
    /// The separation the surfaces were voxelized with: rays of a
    /// connectivity that needs more (26-connected rays need
    /// [`Separation::TwentySix`]) could pass through them.
    pub separation: Separation,
    /// One cell per voxel ([`rrt_core::raster::cell`]).
    pub plane: Plane,
    /// The plane's line level ([`Raster::with_lines`], from [`line_level`]):
    /// computed from the plane, never saved.
    pub lines: Vec<u8>,
    /// The brick directory of the record store.
    pub directory: Vec<u32>,
    /// The voxel records, sorted by brick and position.
    pub records: Vec<VoxelRecord>,
    /// The world object table, indexed by [`VoxelRecord::object`].
    pub objects: Vec<WorldObject>,
    /// Distinct materials, indexed by [`VoxelRecord::material`].
    pub materials: Vec<Material>,
    /// Lights, in file order (light `i` is bit pair `i` of the records).
    pub lights: Vec<WorldLight>,
    /// Background colour.
    pub background: DVec3,
    /// The scene's view (the renderer may override it).
    pub view: View,
}

impl VoxelScene {
    /// The raster's dimensions.
    #[must_use]
    pub fn extent(&self) -> Extent {
        self.frame.extent
    }

    /// The raster (the plane over the extent, with its line level when
    /// the scene has one).
    ///
    /// # Errors
    /// Only if the plane or the line level does not match the extent, which
    /// the constructors rule out.
    pub fn raster(&self) -> Result<Raster<'_>, rrt_core::RasterError> {
        let r = Raster::new(self.frame.extent, &self.plane)?;
        if self.lines.is_empty() {
            Ok(r)
        } else {
            r.with_lines(&self.lines)
        }
    }

    /// The record store, validated (O(bricks + records)).
    ///
    /// # Errors
    /// The first broken store invariant.
    pub fn store(&self) -> Result<RecordStore<'_>, StoreError> {
        RecordStore::new(self.frame.extent, &self.directory, &self.records)
    }

    /// The SPD intensity of each light and of the ambient term.
    #[must_use]
    pub fn intensity(&self) -> f64 {
        shade::light_intensity(self.lights.len())
    }

    /// Bytes held by the plane, its line level, directory and records.
    #[must_use]
    pub fn memory(&self) -> u64 {
        let dir = self.directory.len().saturating_mul(4);
        let rec = self
            .records
            .len()
            .saturating_mul(std::mem::size_of::<VoxelRecord>());
        let bytes = self
            .plane
            .len()
            .saturating_add(self.lines.len())
            .saturating_add(dir)
            .saturating_add(rec);
        u64::try_from(bytes).unwrap_or(u64::MAX)
    }
}

/// The last pass over a voxelized plane, once its records are final: the
/// proximity distance field (empty-space skipping for 26-runs; it sets the
/// same PROXIMITY flags the builder set), the records' rank hints in their
/// opaque cells (which the field clears), and the line level, returned.
/// A plane, directory or record array that does not match `extent` is left
/// as it is, with no line level.
pub fn finish_plane(
    extent: Extent,
    plane: &mut [u8],
    directory: &[u32],
    records: &[VoxelRecord],
) -> Vec<u8> {
    if let Ok(mut raster) = RasterMut::new(extent, plane) {
        distance_field(&mut raster);
        if let Ok(store) = RecordStore::new(extent, directory, records) {
            write_rank_hints(&mut raster, &store);
        }
    }
    line_level(extent, plane)
}

/// The line level of a plane over `extent` ([`line_distances`]): one
/// stand-in cell per 64 cells, which lets skipping walks stay off the plane
/// far from surfaces. Empty if the plane does not match the extent.
#[must_use]
pub fn line_level(extent: Extent, plane: &[u8]) -> Vec<u8> {
    let mut lines = vec![0u8; line_count(plane.len())];
    match Raster::new(extent, plane).map(|r| line_distances(&r, &mut lines)) {
        Ok(Ok(())) => lines,
        _ => Vec::new(),
    }
}

/// How to build.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BuildOptions {
    /// Raster size, bounds and memory limit.
    pub fit: FitOptions,
    /// The rays the raster is built for: decides the separation.
    pub connectivity: Connectivity,
    /// Shadow rays of the light pass.
    pub light: LightParams,
    /// Threads of the light pass; 0 for one per core.
    pub threads: usize,
}

impl BuildOptions {
    /// `raster` voxels along the longest axis, for adaptive rays, default
    /// limits.
    #[must_use]
    pub fn new(raster: u32) -> Self {
        Self {
            fit: FitOptions {
                solid_spheres: false,
                ..FitOptions::new(raster)
            },
            connectivity: Connectivity::Adaptive,
            light: LightParams::default(),
            threads: 0,
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

/// A scalar in `[0, ∞)` as the core's 16.16 fixed point, saturating.
fn scalar(v: f64) -> u32 {
    let s = (v * f64::from(SCALAR_ONE)).round();
    if s.is_nan() || s <= 0.0 {
        0
    } else if s >= f64::from(u32::MAX) {
        u32::MAX
    } else {
        s as u32
    }
}

/// The core's fixed-point material.
fn core_material(m: &Material) -> object_table::Material {
    object_table::Material {
        color: [m.colour.x, m.colour.y, m.colour.z].map(scalar),
        kd: scalar(m.kd),
        ks: scalar(m.ks),
        shine: scalar(m.shine),
        transmission: scalar(m.transmittance),
        ior: scalar(m.ior),
    }
}

/// Distinct materials of `scene` and, per scene material, its index among
/// them.
fn distinct_materials(scene: &Scene) -> Result<(Vec<Material>, Vec<u16>), BuildError> {
    let mut seen: HashMap<[u64; 8], u16> = HashMap::new();
    let mut list = Vec::new();
    let mut index = Vec::with_capacity(scene.materials.len());
    for m in &scene.materials {
        let key = [
            m.colour.x,
            m.colour.y,
            m.colour.z,
            m.kd,
            m.ks,
            m.shine,
            m.transmittance,
            m.ior,
        ]
        .map(f64::to_bits);
        let i = match seen.get(&key) {
            Some(&i) => i,
            None => {
                if list.len() >= MAX_MATERIALS {
                    return Err(BuildError::TooManyMaterials {
                        loc: m
                            .loc
                            .clone()
                            .unwrap_or_else(|| SourceLoc::new(scene.file.clone(), 0, 0)),
                        count: list.len() + 1,
                    });
                }
                // Below MAX_MATERIALS = 4096: fits u16.
                let i = u16::try_from(list.len()).unwrap_or(u16::MAX);
                seen.insert(key, i);
                list.push(Material {
                    loc: None,
                    ..m.clone()
                });
                i
            }
        };
        index.push(i);
    }
    Ok((list, index))
}

/// The scene material of extra object `e` (volumes, then `.vox` models,
/// then CSG trees, in scene order): a CSG tree's is its first leaf's.
fn extra_material(scene: &Scene, e: usize) -> usize {
    let nv = scene.volumes.len();
    let nx = scene.voxes.len();
    if let Some(v) = scene.volumes.get(e) {
        v.material
    } else if let Some(v) = scene.voxes.get(e.wrapping_sub(nv)) {
        v.material
    } else {
        scene
            .csgs
            .get(e.wrapping_sub(nv + nx))
            .and_then(|c| c.leaves.first())
            .map_or(0, |l| l.material)
    }
}

/// Voxelizes extra object `e` (see [`extra_material`]) into `pass`.
fn extra(
    scene: &Scene,
    e: usize,
    frame: &RasterFrame,
    separation: Separation,
    pass: Pass<'_, '_, '_, '_>,
) -> Result<(), BuildError> {
    let nv = scene.volumes.len();
    let nx = scene.voxes.len();
    if let Some(v) = scene.volumes.get(e) {
        objects::volume(v, frame, separation, pass)
    } else if let Some(v) = scene.voxes.get(e.wrapping_sub(nv)) {
        objects::vox(v, frame, pass)
    } else if let Some(c) = scene.csgs.get(e.wrapping_sub(nv + nx)) {
        objects::csg(c, frame, separation, pass)
    } else {
        Ok(())
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
    let (materials, material_index) = distinct_materials(scene)?;
    let fitted: Fitted = fit::fit(scene, &opts.fit)?;
    let frame = fitted.frame;
    let extent = frame.extent;
    let separation = Separation::for_rays(opts.connectivity);
    let mat_of = |scene_material: usize| material_index.get(scene_material).copied().unwrap_or(0);

    let mut plane = Plane::zeroed(extent.len()).map_err(alloc_err("raster plane", extent.len()))?;
    let dir_len =
        directory_len(extent).ok_or_else(|| BuildError::Raster("too many bricks".into()))?;
    let mut directory = vec![0u32; dir_len];

    let n_fitted = fitted.objects.len();
    let extras = scene.volumes.len() + scene.voxes.len() + scene.csgs.len();
    let n = n_fitted + extras;
    progress.set_length(u64::try_from(2 * n).unwrap_or(u64::MAX));
    // Each texture once, in the raster.
    let textures: Vec<InRaster<AnyTexture>> = scene
        .textures
        .iter()
        .map(|t| match &t.kind {
            TextureKind::World(w) => objects::in_raster(w, frame, t.blend),
        })
        .collect();
    let texture_of = |m: usize| {
        scene
            .material_textures
            .get(&m)
            .and_then(|&t| textures.get(t))
    };
    progress.set_message("voxelizing (count pass)");
    let raster =
        RasterMut::new(extent, &mut plane).map_err(|e| BuildError::Raster(e.to_string()))?;
    let mut counter = Counter::new(raster, &mut directory)?;
    for o in &fitted.objects {
        shape::voxelize(&o.entry, separation, extent, &mut counter).map_err(|source| {
            BuildError::Voxelize {
                loc: o.loc.clone(),
                what: o.kind,
                source,
            }
        })?;
        progress.inc(1);
    }
    for e in 0..extras {
        extra(scene, e, &frame, separation, Pass::Count(&mut counter))?;
        progress.inc(1);
    }
    let offers = counter.report().offers;
    let sizing = counter.finish()?;
    let records_n = sizing.records();
    let needed = u64::try_from(
        extent
            .len()
            .saturating_add(dir_len.saturating_mul(4))
            .saturating_add(sizing.record_bytes()),
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
    let limits = Limits {
        objects: u32::try_from(n).unwrap_or(u32::MAX),
        materials: u32::try_from(materials.len()).unwrap_or(u32::MAX),
    };
    progress.set_message("voxelizing (fill pass)");
    let mut filler = sizing.fill(&mut records, limits)?;
    for (id, o) in fitted.objects.iter().enumerate() {
        let material = mat_of(o.material);
        let colour = materials
            .get(usize::from(material))
            .map_or([0; 3], |m| core_material(m).color_u8());
        filler.begin_object(ObjectAttrs {
            object: u32::try_from(id).unwrap_or(u32::MAX),
            material,
            color: colour,
        })?;
        let voxelized = match texture_of(o.material) {
            Some(t) => shape::voxelize(&o.entry, separation, extent, &mut filler.textured(t)),
            None => shape::voxelize(&o.entry, separation, extent, &mut filler),
        };
        voxelized.map_err(|source| BuildError::Voxelize {
            loc: o.loc.clone(),
            what: o.kind,
            source,
        })?;
        progress.inc(1);
    }
    let attrs_of = |id: usize, scene_material: usize| {
        let material = mat_of(scene_material);
        ObjectAttrs {
            object: u32::try_from(id).unwrap_or(u32::MAX),
            material,
            color: materials
                .get(usize::from(material))
                .map_or([0; 3], |m| core_material(m).color_u8()),
        }
    };
    for e in 0..extras {
        let id = n_fitted + e;
        let m = extra_material(scene, e);
        let leaves = scene
            .csgs
            .get(e.wrapping_sub(scene.volumes.len() + scene.voxes.len()))
            .map(|c| c.leaves.iter().map(|l| attrs_of(id, l.material)).collect())
            .unwrap_or_default();
        let pass = Pass::Fill {
            filler: &mut filler,
            attrs: attrs_of(id, m),
            leaves,
            texture: texture_of(m),
        };
        extra(scene, e, &frame, separation, pass)?;
        progress.inc(1);
    }
    let built = filler.finish()?;
    let voxelize = t0.elapsed();

    // Light visibility and precomputed illumination.
    let t1 = Instant::now();
    progress.set_message("light visibility");
    let mut storage = vec![Object::UNUSED; n];
    let mut table = ObjectTable::new(&mut storage);
    for o in &fitted.objects {
        // The storage holds exactly the n objects: no push can fail.
        let _ = table.push(Object {
            shape: o.entry,
            material: mat_of(o.material),
        });
    }
    for e in 0..extras {
        let _ = table.push(Object {
            shape: object_table::Shape::Voxels,
            material: mat_of(extra_material(scene, e)),
        });
    }
    let mut core_materials: Box<Materials<MAX_MATERIALS>> = Box::default();
    for m in &materials {
        let _ = core_materials.push(core_material(m));
    }
    let mut light_report = LightReport::default();
    let intensity = scalar(shade::light_intensity(scene.lights.len()));
    let mut lights = Lights::new(intensity);
    for l in &fitted.lights {
        let c = l.colour;
        let _ = lights.push(Light {
            position: l.position,
            color: [c.x, c.y, c.z].map(scalar),
            intensity,
        });
    }
    // Runs of records on rayon's threads: each record's bits and
    // illumination depend only on the (unchanged) store, so the result is
    // the serial pass's whatever the thread count.
    let lit: Vec<VoxelRecord> = {
        let raster = built.raster();
        let store = built.store();
        let mut out = store.records().to_vec();
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(opts.threads)
            .build()
            .map_err(|e| BuildError::Raster(format!("cannot start threads: {e}")))?;
        let reports: Vec<Result<LightReport, LightError>> = pool.install(|| {
            out.par_chunks_mut(LIGHT_RUN)
                .enumerate()
                .map(|(i, run)| {
                    illuminate_run(
                        &raster,
                        &store,
                        i * LIGHT_RUN,
                        run,
                        &table,
                        &core_materials,
                        &lights,
                        &opts.light,
                    )
                })
                .collect()
        });
        for r in reports {
            light_report.add(&r?);
        }
        out
    };
    records = lit;
    let lights_time = t1.elapsed();

    let t2 = Instant::now();
    let lines = finish_plane(extent, &mut plane, &directory, &records);
    let voxelize = voxelize + t2.elapsed();

    let objects: Vec<WorldObject> = fitted
        .objects
        .iter()
        .map(|o| WorldObject {
            shape: o.shape,
            material: mat_of(o.material),
        })
        .chain((0..extras).map(|e| WorldObject {
            shape: Shape::Voxels,
            material: mat_of(extra_material(scene, e)),
        }))
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
            objects,
            materials,
            lights: world_lights,
            background: scene.background,
            view: scene.view.clone(),
        },
        report,
    ))
}
