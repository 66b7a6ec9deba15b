//! The paper's MRI head as a [`VoxelScene`]: the host has no scene-file
//! syntax for volumes yet, so this runs the builder's steps directly on the
//! volume library (`rrt_host::assets::volume`): the iso-surface layer of the
//! classified samples through the core's volume voxelizer (count pass, fill
//! pass), light visibility, the proximity distance field.
//!
//! The voxels carry the gray-level gradient normals; there is no exact
//! geometry, so the scene has no world objects and is rendered without
//! verification.

use std::error::Error;
use std::path::Path;
use std::time::Instant;

use glam::DVec3;
use rrt_core::light::{LightParams, LightReport, illuminate_run};
use rrt_core::object_table::{
    self, Light, Lights, Materials, Object, ObjectTable, SCALAR_ONE, Shape,
};
use rrt_core::raster::{Extent, RasterMut};
use rrt_core::store::{Counter, Limits, ObjectAttrs, directory_len};
use rrt_core::voxel::VoxelRecord;
use rrt_core::voxelize::Separation;
use rrt_host::assets::volume::{Classifier, Limits as VolumeLimits, Placement, nrrd};
use rrt_host::frame::RasterFrame;
use rrt_host::scene::{Material, View, light_intensity};
use rrt_host::voxelize::WorldLight;
use rrt_host::voxelize::plane::Plane;
use rrt_host::voxelize::{MAX_MATERIALS, VoxelScene, finish_plane};

/// The iso-value separating head from air (data README).
pub const ISO: f64 = 20.0;

/// A built head and its build times in seconds.
pub struct Head {
    /// The scene.
    pub scene: VoxelScene,
    /// Both voxelization passes and the distance field.
    pub voxelize: f64,
    /// The light pass.
    pub lights: f64,
}

fn scalar(v: f64) -> u32 {
    (v * f64::from(SCALAR_ONE))
        .round()
        .clamp(0.0, f64::from(u32::MAX)) as u32
}

/// Builds the head of `nrrd_path` in a raster of `raster` voxels along its
/// longest side, seen from the front; `view` is a template (its location
/// and resolution are kept).
///
/// # Errors
/// The reader's, voxelizer's, builder's or light pass's error.
pub fn build(
    nrrd_path: &Path,
    raster: u32,
    template: &View,
    threads: usize,
) -> Result<Head, Box<dyn Error>> {
    let volume = nrrd::read(nrrd_path, &VolumeLimits::default())?;

    let t0 = Instant::now();
    let placed = Placement::IDENTITY.place(&volume);
    let b = placed.world_bounds();
    let size = b.max - b.min;
    let voxel_size = size.max_element() / f64::from(raster);
    let dims = (size / voxel_size).ceil().as_uvec3();
    let extent = Extent::new(dims.x.max(1), dims.y.max(1), dims.z.max(1))?;
    let frame = RasterFrame {
        extent,
        origin: b.min,
        voxel_size,
    };
    let classifier = Classifier::iso(ISO);
    let separation = Separation::TwentySix;
    let material = Material {
        colour: DVec3::new(0.9, 0.75, 0.65),
        kd: 0.9,
        ks: 0.0,
        ..Material::DEFAULT
    };
    let core_mat = object_table::Material {
        color: [material.colour.x, material.colour.y, material.colour.z].map(scalar),
        kd: scalar(material.kd),
        ks: 0,
        shine: scalar(material.shine),
        transmission: 0,
        ior: scalar(1.0),
    };

    let mut plane = Plane::zeroed(extent.len())?;
    let mut directory = vec![0u32; directory_len(extent).ok_or("too many bricks")?];
    let raster_mut = RasterMut::new(extent, &mut plane)?;
    let mut counter = Counter::new(raster_mut, &mut directory)?;
    placed.voxelize(&frame, &classifier, separation, 64 << 20, &mut counter)?;
    let sizing = counter.finish()?;
    let mut records = vec![VoxelRecord::default(); sizing.records()];
    let mut filler = sizing.fill(
        &mut records,
        Limits {
            objects: 1,
            materials: 1,
        },
    )?;
    filler.begin_object(ObjectAttrs {
        object: 0,
        material: 0,
        color: core_mat.color_u8(),
    })?;
    placed.voxelize(&frame, &classifier, separation, 64 << 20, &mut filler)?;
    let built = filler.finish()?;
    let mut voxelize = t0.elapsed().as_secs_f64();

    // One light beside the eye, as the SPD scenes light themselves.
    let centre = (b.min + b.max) * 0.5;
    let from = centre + DVec3::new(0.0, 3.2, 0.6) * size.max_element();
    let light_pos = from + DVec3::new(size.x, 0.0, size.z);
    let t1 = Instant::now();
    let mut storage = [Object {
        shape: Shape::Voxels,
        material: 0,
    }];
    let table = ObjectTable::new(&mut storage, &mut []);
    let mut mats: Box<Materials<MAX_MATERIALS>> = Box::default();
    let _ = mats.push(core_mat);
    let intensity = scalar(light_intensity(1));
    let mut lights = Lights::new(intensity);
    let position = frame.to_fixed(light_pos).ok_or("light out of range")?;
    let _ = lights.push(Light {
        position,
        color: [SCALAR_ONE; 3],
        intensity,
    });
    let params = LightParams::default();
    let lit: Vec<VoxelRecord> = {
        let raster = built.raster();
        let store = built.store();
        let mut out = store.records().to_vec();
        const RUN: usize = 1 << 14;
        let pool = rayon_pool(threads)?;
        let reports: Vec<Result<LightReport, _>> = pool.install(|| {
            use rayon::prelude::*;
            out.par_chunks_mut(RUN)
                .enumerate()
                .map(|(i, run)| {
                    illuminate_run(
                        &raster,
                        &store,
                        i * RUN,
                        run,
                        &table,
                        &mats,
                        &lights,
                        &params,
                        None,
                    )
                })
                .collect()
        });
        for r in reports {
            r?;
        }
        out
    };
    records = lit;
    let lights_time = t1.elapsed().as_secs_f64();
    let t2 = Instant::now();
    let store = rrt_core::store::RecordStore::new(extent, &directory, &records)
        .map_err(|e| e.to_string())?;
    let lines = finish_plane(&mut plane, &store);
    voxelize += t2.elapsed().as_secs_f64();

    let view = View {
        from,
        at: centre,
        up: DVec3::Z,
        angle: 22.0,
        ..template.clone()
    };
    Ok(Head {
        scene: VoxelScene {
            frame,
            separation,
            lines,
            plane,
            directory,
            records,
            lists: Vec::new(),
            exact: false,
            exact_records: rrt_core::light::ExactRecords::Paper,
            objects: Vec::new(),
            materials: vec![material],
            lights: vec![WorldLight {
                position: light_pos,
                colour: DVec3::ONE,
            }],
            background: DVec3::new(0.078, 0.361, 0.753),
            view,
            direct: Vec::new(),
        },
        voxelize,
        lights: lights_time,
    })
}

fn rayon_pool(threads: usize) -> Result<rayon::ThreadPool, Box<dyn Error>> {
    Ok(rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()?)
}
