//! The scene-building half of voxelization end to end: count and fill
//! passes, record lookups, proximity seen by the adaptive stepper, light
//! visibility on a lone sphere (the acne test) and bad input.
//!
//! Spheres are voxelized here by a plain brute-force float voxelizer
//! (`sphere_surface`), a stand-in until `voxelize::sphere` is merged.

use std::collections::HashMap;

use rrt_core::check::check_adaptive_matches_six;
use rrt_core::csg::{CsgError, CsgNode, CsgTree, Solid};
use rrt_core::discrete_ray::DiscreteRay;
use rrt_core::fixed::VOXEL;
use rrt_core::geometry::Sphere;
use rrt_core::light::{LightParams, illuminate};
use rrt_core::object_table::{
    Light, Lights, Material, Materials, Object, ObjectTable, SCALAR_ONE, Shape,
};
use rrt_core::raster::{Extent, Raster, RasterMut, cell};
use rrt_core::store::{
    BuildError, Counter, Limits, ObjectAttrs, RecordStore, RecordStoreMut, directory_len,
};
use rrt_core::voxel::{LightVisibility, VoxelRecord};
use rrt_core::voxelize::{NORMAL_ONE, Separation, Surfel, VoxelSink};
use rrt_tests::Rng;

/// A sphere surface through the real voxelizer, from voxel-unit inputs.
/// It clips only to the largest raster, so that a sphere reaching past the
/// test's raster sends offers outside it to the builder, which must count
/// and skip them.
fn sphere_surface(c: [f64; 3], r: f64, sep: Separation, sink: &mut dyn VoxelSink) {
    let fx = |v: f64| (v * VOXEL as f64).round() as i64;
    let sphere = Sphere {
        centre: c.map(fx),
        radius: fx(r),
    };
    let extent = Extent::cube(1 << 16).expect("extent");
    rrt_core::voxelize::sphere::surface(&sphere, sep, extent, sink).expect("sphere");
}

fn fixed(v: f64) -> i64 {
    (v * VOXEL as f64).round() as i64
}

fn scalar(v: f64) -> u32 {
    (v * f64::from(SCALAR_ONE)).round() as u32
}

struct Scene {
    extent: Extent,
    plane: Vec<u8>,
    dir: Vec<u32>,
    records: Vec<VoxelRecord>,
    outside: u64,
}

fn build(extent: Extent, spheres: &[([f64; 3], f64)], sep: Separation) -> Scene {
    let mut plane = vec![0u8; extent.len()];
    let mut dir = vec![0u32; directory_len(extent).unwrap()];
    let mut counter = Counter::new(RasterMut::new(extent, &mut plane).unwrap(), &mut dir).unwrap();
    for &(c, r) in spheres {
        sphere_surface(c, r, sep, &mut counter);
    }
    let outside = counter.report().outside;
    let sizing = counter.finish().unwrap();
    let mut records = vec![VoxelRecord::default(); sizing.records()];
    let limits = Limits {
        objects: spheres.len() as u32,
        materials: 1,
    };
    let mut filler = sizing.fill(&mut records, limits).unwrap();
    for (i, &(c, r)) in spheres.iter().enumerate() {
        filler
            .begin_object(ObjectAttrs {
                object: i as u32,
                material: 0,
                color: [255, 128, 64],
            })
            .unwrap();
        sphere_surface(c, r, sep, &mut filler);
    }
    let rep = filler.finish().unwrap().report();
    assert_eq!(rep.outside, outside);
    Scene {
        extent,
        plane,
        dir,
        records,
        outside,
    }
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn unit(v: [f64; 3]) -> [f64; 3] {
    let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    v.map(|c| c / l)
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// The acceptance test of the acne rule: a lone sphere lit by SPD lights.
/// Every voxel whose normal faces a light by more than 3° is visible, every
/// voxel facing away is occluded, and `illum` matches the float formula.
#[test]
fn lone_sphere_lit_by_spd_lights_has_no_acne() {
    let e = Extent::cube(96).unwrap();
    let centre = [48.3, 47.6, 48.1];
    let radius = 30.0;
    // Light positions in voxel units: far outside, just outside, inside.
    let light_sets: [&[[f64; 3]]; 3] = [
        &[[400.0, 300.0, 500.0]],
        &[
            [95.0, 2.0, 90.0],
            [-300.0, 48.0, 48.0],
            [48.0, 48.0, -1000.0],
        ],
        &[[90.0, 90.0, 10.0], [5.0, 5.0, 5.0]],
    ];
    for sep in [Separation::Six, Separation::TwentySix] {
        for lights_v in light_sets {
            let mut scene = build(e, &[(centre, radius)], sep);
            let nl = lights_v.len() as f64;
            let intensity = nl.sqrt() / (2.0 * nl); // SPD
            let (kd, color) = (0.8, [1.0, 0.5, 0.25]);
            let mut lights = Lights::new(scalar(intensity));
            for p in lights_v {
                lights
                    .push(Light {
                        position: p.map(fixed),
                        color: [SCALAR_ONE; 3],
                        intensity: scalar(intensity),
                    })
                    .unwrap();
            }
            let mut materials: Materials<1> = Materials::new();
            materials
                .push(Material {
                    color: color.map(scalar),
                    kd: scalar(kd),
                    ..Material::default()
                })
                .unwrap();
            let mut storage = [Object::UNUSED; 1];
            let mut table = ObjectTable::new(&mut storage, &mut []);
            table
                .push(Object {
                    shape: Shape::Sphere(Sphere {
                        centre: centre.map(fixed),
                        radius: fixed(radius),
                    }),
                    material: 0,
                })
                .unwrap();
            let raster = Raster::new(e, &scene.plane).unwrap();
            let mut store = RecordStoreMut::new(e, &scene.dir, &mut scene.records).unwrap();
            let rep = illuminate(
                &raster,
                &mut store,
                &table,
                &materials,
                &lights,
                &LightParams::default(),
            )
            .unwrap();
            let store = RecordStore::new(e, &scene.dir, &scene.records).unwrap();
            let (mut lit, mut grazing_lit, mut dark) = (0, 0, 0);
            for (v, r) in store.iter() {
                let c = v.map(|x| x as f64 + 0.5);
                let n = r
                    .normal_vector()
                    .map(|x| f64::from(x) / f64::from(NORMAL_ONE));
                let mut want_illum = [intensity; 3];
                for (i, p) in lights_v.iter().enumerate() {
                    let l = unit(sub(*p, c));
                    let ndl = dot(n, l);
                    let vis = r.light(i);
                    if ndl > 3f64.to_radians().sin() {
                        assert_eq!(
                            vis,
                            LightVisibility::Visible,
                            "{sep:?} {v:?} light {i}: N·L {ndl}"
                        );
                        lit += 1;
                    } else if ndl <= 0.0 {
                        assert_eq!(vis, LightVisibility::Occluded, "{sep:?} {v:?} light {i}");
                        dark += 1;
                    } else if vis == LightVisibility::Visible {
                        grazing_lit += 1;
                    }
                    if vis == LightVisibility::Visible && ndl > 0.0 {
                        for w in &mut want_illum {
                            *w += intensity * ndl;
                        }
                    }
                }
                for ((got, c), w) in r.illum.iter().zip(r.color).zip(want_illum) {
                    let want = (f64::from(c) * kd * w).min(255.0);
                    assert!(
                        (f64::from(*got) - want).abs() <= 1.0,
                        "{v:?}: illum {:?}, expected {want}",
                        r.illum
                    );
                }
            }
            println!(
                "{sep:?}, {} lights: {} records, {lit} lit pairs (+{grazing_lit} within 3° of grazing, all visible: {}), {dark} facing away; {rep:?}",
                lights_v.len(),
                store.len(),
                grazing_lit as u64 + lit as u64 == rep.visible,
            );
            assert!(lit > 1000 && dark > 1000);
        }
    }
}

/// The builder's proximity flags are what the adaptive stepper needs: it
/// finds the same hits as 6-connected rays.
#[test]
fn adaptive_rays_match_six_in_a_built_scene() {
    let e = Extent::new(80, 64, 72).unwrap();
    let spheres = [
        ([20.5, 30.0, 30.0], 12.0),
        ([50.0, 20.0, 40.0], 9.3),
        ([60.0, 45.0, 20.0], 15.0),
        ([40.0, 40.0, 60.0], 6.0),
    ];
    let scene = build(e, &spheres, Separation::Six);
    let raster = Raster::new(e, &scene.plane).unwrap();
    let mut rng = Rng::new(11);
    for i in 0..3000 {
        let origin = [0; 3].map(|_| rng.range(-20 * VOXEL, 100 * VOXEL));
        let dir = [0; 3].map(|_| rng.range(-(1 << 24), 1 << 24) as i32);
        let Some(ray) = DiscreteRay::new(e, origin, dir).unwrap() else {
            continue;
        };
        check_adaptive_matches_six(&raster, &ray)
            .unwrap_or_else(|v| panic!("ray {i}: {origin:?} {dir:?}: {v:?}"));
    }
    // Every plane cell is OPAQUE exactly where a record is; a transparent
    // cell holds at most PROXIMITY (an opaque cell's distance bits carry its
    // record's rank hint).
    let store = RecordStore::new(e, &scene.dir, &scene.records).unwrap();
    for (i, c) in scene.plane.iter().enumerate() {
        assert_eq!(c & cell::OPAQUE != 0, store.get(i).is_some());
        if c & cell::OPAQUE == 0 {
            assert_eq!(c & !cell::PROXIMITY, 0);
        }
    }
}

/// Store lookups on random sparse rasters against a brute-force map.
#[test]
fn store_lookup_matches_a_map() {
    for seed in 0..6u64 {
        let mut rng = Rng::new(seed);
        let dims = [0; 3].map(|_| 1 + rng.below(120) as u32);
        let e = Extent::new(dims[0], dims[1], dims[2]).unwrap();
        let mut plane = vec![0u8; e.len()];
        let mut dir = vec![0u32; directory_len(e).unwrap()];
        let offers: Vec<([u32; 3], u32, u32)> = (0..rng.below(40_000))
            .map(|_| {
                (
                    dims.map(|n| rng.below(u64::from(n)) as u32),
                    rng.below(3) as u32,
                    rng.below(1 << 16) as u32,
                )
            })
            .collect();
        let mut map: HashMap<[u32; 3], (u32, u16)> = HashMap::new();
        for &(v, o, d) in &offers {
            let q = rrt_core::voxel::quantize_distance(d);
            if map.get(&v).is_none_or(|&(_, old)| q < old) {
                map.insert(v, (o, q));
            }
        }
        let mut counter = Counter::new(RasterMut::new(e, &mut plane).unwrap(), &mut dir).unwrap();
        let s = |d| Surfel {
            normal: [0, 0, NORMAL_ONE],
            distance: d,
        };
        for &(v, _, d) in &offers {
            counter.offer(v, s(d));
        }
        let sizing = counter.finish().unwrap();
        assert_eq!(sizing.records(), map.len());
        let mut records = vec![VoxelRecord::default(); sizing.records()];
        let lim = Limits {
            objects: 3,
            materials: 1,
        };
        let mut filler = sizing.fill(&mut records, lim).unwrap();
        for &(v, o, d) in &offers {
            filler
                .begin_object(ObjectAttrs {
                    object: o,
                    ..ObjectAttrs::default()
                })
                .unwrap();
            filler.offer(v, s(d));
        }
        filler.finish().unwrap();
        let store = RecordStore::new(e, &dir, &records).unwrap();
        for i in 0..e.len() {
            let v = e.coord(i).unwrap();
            match (map.get(&v), store.get(i)) {
                (Some(&(o, q)), Some(r)) => {
                    assert_eq!((r.object, r.distance()), (o, q), "seed {seed} {v:?}")
                }
                (None, None) => {}
                (w, g) => panic!("seed {seed} {v:?}: expected {w:?}, got {g:?}"),
            }
        }
        // Memory: plane + directory per voxel, records per record.
        let per_voxel = (plane.len() + 4 * dir.len()) as f64 / e.len() as f64;
        assert!(per_voxel <= 1.1 || e.len() < 4096, "{per_voxel} B/voxel");
    }
}

#[test]
fn bad_input_is_refused_or_clipped_never_a_panic() {
    // A sphere hanging over the raster's far corner: clipped, skipped count
    // reported, the rest built.
    let e = Extent::cube(32).unwrap();
    let scene = build(e, &[([30.0, 29.0, 28.0], 10.0)], Separation::TwentySix);
    assert!(scene.outside > 100, "{}", scene.outside);
    assert!(!scene.records.is_empty());
    assert!(RecordStore::new(scene.extent, &scene.dir, &scene.records).is_ok());
    // Wholly outside: nothing but skipped offers.
    let scene = build(e, &[([100.0, 2.0, 3.0], 10.0)], Separation::Six);
    assert!(scene.records.is_empty() && scene.outside > 0);

    // More lights than the record has bits for.
    let mut lights = Lights::new(0);
    for _ in 0..8 {
        lights.push(Light::default()).unwrap();
    }
    assert!(lights.push(Light::default()).is_err());
    // More objects than the table holds.
    let mut storage = vec![Object::UNUSED; 2];
    let mut table = ObjectTable::new(&mut storage, &mut []);
    let obj = Object {
        shape: Shape::Voxels,
        material: 0,
    };
    assert!(table.push(obj).is_ok() && table.push(obj).is_ok());
    assert_eq!(table.push(obj), Err(obj));
    // More materials than the table holds.
    let mut m: Materials<1> = Materials::new();
    m.push(Material::default()).unwrap();
    assert!(m.push(Material::default()).is_err());
    // Zero and negative radii: refused by CSG; a voxelizer offering nothing
    // builds an empty scene.
    for r in [0, -VOXEL] {
        let s = Sphere {
            centre: [VOXEL; 3],
            radius: r,
        };
        let leaves: [&dyn Solid; 1] = [&s];
        assert_eq!(
            CsgTree::new(&[CsgNode::Leaf(0)], &leaves).unwrap_err(),
            CsgError::Degenerate { leaf: 0 }
        );
    }
    // Too little record storage; an object id past the table.
    let mut plane = vec![0u8; e.len()];
    let mut dir = vec![0u32; directory_len(e).unwrap()];
    let mut c = Counter::new(RasterMut::new(e, &mut plane).unwrap(), &mut dir).unwrap();
    sphere_surface([16.0; 3], 5.0, Separation::Six, &mut c);
    let sizing = c.finish().unwrap();
    let need = sizing.records();
    let mut short = vec![VoxelRecord::default(); need - 1];
    let lim = Limits {
        objects: 1,
        materials: 1,
    };
    assert_eq!(
        sizing.fill(&mut short, lim).unwrap_err(),
        BuildError::RecordStorage {
            needed: need,
            found: need - 1
        }
    );
    let mut c = Counter::new(RasterMut::new(e, &mut plane).unwrap(), &mut dir).unwrap();
    sphere_surface([16.0; 3], 5.0, Separation::Six, &mut c);
    let mut recs = vec![VoxelRecord::default(); need];
    let mut f = c.finish().unwrap().fill(&mut recs, lim).unwrap();
    assert_eq!(
        f.begin_object(ObjectAttrs {
            object: 1,
            ..ObjectAttrs::default()
        })
        .unwrap_err(),
        BuildError::ObjectOutOfRange {
            object: 1,
            limit: 1
        }
    );
    // A directory of the wrong length.
    let mut wrong = vec![0u32; 3];
    assert!(matches!(
        Counter::new(RasterMut::new(e, &mut plane).unwrap(), &mut wrong),
        Err(BuildError::DirectoryLength { .. })
    ));
}
