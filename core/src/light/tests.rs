//! Unit tests of the light pass, on scenes voxelized by the brute-force
//! voxelizers of `testkit` (integer only).

use std::vec;
use std::vec::Vec;

use super::*;
use crate::fixed::VOXEL;
use crate::geometry::{Cuboid, Sphere, Torus, Triangle};
use crate::object_table::{Light, Material, Object, SCALAR_ONE, Shape};
use crate::store::{Limits, ObjectAttrs, RecordStore, RecordStoreMut};
use crate::testkit::{self, Scene, Voxelize};
use crate::voxelize::{Separation, Surfel, VoxelSink};

/// An object-table entry of material 0 that no shadow ray can meet (a
/// degenerate triangle): for objects whose own surface does not matter.
const NOWHERE: Object = Object {
    shape: Shape::Triangle(Triangle {
        vertices: [[0; 3]; 3],
        normals: None,
    }),
    material: 0,
};

fn vox(v: [i64; 3]) -> [i64; 3] {
    v.map(|c| c * VOXEL)
}

struct World {
    objects: Vec<Object>,
    materials: Materials<4>,
    lights: Lights,
}

impl World {
    fn new(lights: &[[i64; 3]]) -> Self {
        let mut materials = Materials::new();
        // 0: opaque, Kd 0.75, white.
        materials
            .push(Material {
                color: [SCALAR_ONE; 3],
                kd: SCALAR_ONE * 3 / 4,
                ..Material::default()
            })
            .unwrap();
        // 1: translucent.
        materials
            .push(Material {
                color: [SCALAR_ONE; 3],
                kd: SCALAR_ONE / 2,
                transmission: SCALAR_ONE / 2,
                ..Material::default()
            })
            .unwrap();
        // SPD: I = sqrt(nl) / (2 nl); for one light 0.5.
        let i = SCALAR_ONE / 2;
        let mut l = Lights::new(i);
        for p in lights {
            l.push(Light {
                position: *p,
                color: [SCALAR_ONE; 3],
                intensity: i,
            })
            .unwrap();
        }
        Self {
            objects: Vec::new(),
            materials,
            lights: l,
        }
    }

    fn run(&mut self, scene: &mut Scene) -> LightReport {
        self.run_with(scene, &LightParams::default())
    }

    fn run_with(&mut self, scene: &mut Scene, params: &LightParams) -> LightReport {
        let mut storage = vec![Object::UNUSED; self.objects.len()];
        let mut table = ObjectTable::new(&mut storage, &mut []);
        for o in &self.objects {
            table.push(*o).unwrap();
        }
        let raster = Raster::new(scene.extent, &scene.plane).unwrap();
        let mut store =
            RecordStoreMut::with_lists(scene.extent, &scene.dir, &mut scene.records, &scene.lists)
                .unwrap();
        illuminate(
            &raster,
            &mut store,
            &table,
            &self.materials,
            &self.lights,
            params,
        )
        .unwrap()
    }
}

fn attrs(object: u32, material: u16) -> ObjectAttrs {
    ObjectAttrs {
        object,
        material,
        color: [200, 100, 50],
    }
}

fn sphere_obj(c: [i64; 3], r: i64) -> Object {
    Object {
        shape: Shape::Sphere(Sphere {
            centre: vox(c),
            radius: r * VOXEL,
        }),
        material: 0,
    }
}

/// C·Kd·I_a for the red channel: 200 · 0.75 · 0.5.
const AMBIENT_ONLY: u8 = 75;

const LIM: Limits = Limits {
    objects: 16,
    materials: 2,
};

/// The acceptance test: a lone sphere lit by one light has every voxel
/// facing the light visible and every voxel facing away occluded.
#[test]
fn lone_sphere_has_no_acne() {
    let e = Extent::cube(64).unwrap();
    for sep in [Separation::Six, Separation::TwentySix] {
        for light in [vox([300, 250, 400]), vox([60, 4, 61]), vox([32, 32, -500])] {
            let vz = |s: &mut dyn VoxelSink| {
                testkit::sphere(e, vox([32, 32, 32]), 20 * VOXEL, sep, s);
            };
            let mut scene = testkit::build(e, &[(attrs(0, 0), &vz)], LIM);
            let mut w = World::new(&[light]);
            w.objects.push(sphere_obj([32, 32, 32], 20));
            let rep = w.run(&mut scene);
            let store = scene.store();
            let (mut lit, mut dark, mut grazing) = (0, 0, 0);
            for (v, r) in store.iter() {
                let c = v.map(voxel_centre);
                let l = normalize(sub(light, c)).unwrap();
                let n = r.normal_vector();
                let ndl = dot_unit(n, l);
                let vis = r.light(0);
                if ndl > 0 {
                    assert_eq!(
                        vis,
                        LightVisibility::Visible,
                        "{sep:?} light {light:?}: voxel {v:?} N·L = {ndl} self-shadowed"
                    );
                    lit += 1;
                    if i64::from(ndl) < i64::from(NORMAL_ONE) * 523 / 10_000 {
                        grazing += 1; // within 3° of grazing
                    }
                    // illum = C·Kd·(Ia + I·N·L), within rounding.
                    let ia = i128::from(SCALAR_ONE / 2);
                    let want = |c: u8| -> i128 {
                        let tot = ia * (1 << 16) + ia * (1 << 16) * i128::from(ndl) / (1 << 30);
                        (i128::from(c) * i128::from(SCALAR_ONE * 3 / 4) * tot + (1 << 47)) >> 48
                    };
                    for k in 0..3 {
                        let d = i128::from(r.illum[k]) - want(r.color[k]);
                        assert!(d.abs() <= 1, "illum {:?} at {v:?}", r.illum);
                    }
                } else {
                    assert_eq!(vis, LightVisibility::Occluded, "{v:?} faces away");
                    dark += 1;
                    // Ambient only.
                    assert_eq!(r.illum[0], AMBIENT_ONLY);
                }
            }
            assert!(lit > 1000 && dark > 1000, "{lit} lit, {dark} dark");
            assert!(grazing > 0);
            assert_eq!(rep.records as usize, store.len());
            assert_eq!(rep.visible, lit);
            assert_eq!(rep.facing_away, dark);
            assert_eq!(rep.rays, lit);
        }
    }
}

/// The same scene with the rule switched off (no slab): shadow rays from
/// lit voxels run into the sphere's own layer, so the test above is not
/// vacuous.
#[test]
fn without_the_rule_a_sphere_has_acne() {
    let e = Extent::cube(64).unwrap();
    let light = vox([300, 250, 400]);
    let vz = |s: &mut dyn VoxelSink| {
        testkit::sphere(e, vox([32, 32, 32]), 20 * VOXEL, Separation::TwentySix, s);
    };
    let mut scene = testkit::build(e, &[(attrs(0, 0), &vz)], LIM);
    let mut w = World::new(&[light]);
    w.objects.push(sphere_obj([32, 32, 32], 20));
    let off = LightParams {
        slab: i64::MIN,
        ..LightParams::default()
    };
    let rep = w.run_with(&mut scene, &off);
    std::println!("rule off: {rep:?}");
    assert!(rep.occluded * 10 > rep.rays, "{rep:?}");
}

#[test]
fn a_small_sphere_shadows_a_big_one() {
    let e = Extent::cube(64).unwrap();
    let light = vox([32, 32, 1000]);
    let big = |s: &mut dyn VoxelSink| {
        testkit::sphere(e, vox([32, 32, 20]), 12 * VOXEL, Separation::Six, s)
    };
    let small = |s: &mut dyn VoxelSink| {
        testkit::sphere(e, vox([32, 32, 45]), 4 * VOXEL, Separation::Six, s)
    };
    for blocker_material in [0u16, 1] {
        let mut scene = testkit::build(
            e,
            &[(attrs(0, 0), &big), (attrs(1, blocker_material), &small)],
            LIM,
        );
        let mut w = World::new(&[light]);
        w.objects.push(sphere_obj([32, 32, 20], 12));
        w.objects.push(Object {
            material: blocker_material,
            ..sphere_obj([32, 32, 45], 4)
        });
        w.run(&mut scene);
        let store = scene.store();
        // The top of the big sphere lies in the small one's shadow.
        let top = (0..64)
            .rev()
            .find_map(|z| store.get_voxel([32, 32, z]).filter(|r| store.owner(r) == 0))
            .unwrap();
        let want = if blocker_material == 0 {
            LightVisibility::Occluded
        } else {
            LightVisibility::Translucent
        };
        assert_eq!(top.light(0), want);
        // Translucent and occluded lights add no diffuse: ambient only.
        assert_eq!(top.illum[0], AMBIENT_ONLY);
        // The big sphere's side, out of the shadow, is lit.
        let side = store
            .get_voxel([32 + 11, 32, 24])
            .or(store.get_voxel([32 + 12, 32, 24]));
        assert_eq!(side.unwrap().light(0), LightVisibility::Visible);
    }
}

#[test]
fn an_opaque_blocker_behind_a_translucent_one_occludes() {
    let e = Extent::cube(64).unwrap();
    let light = vox([32, 32, 1000]);
    let floor = testkit::level_plate(e, 10, 20..44);
    let glass = testkit::level_plate(e, 30, 28..36);
    let lid = testkit::level_plate(e, 40, 30..34);
    let mut scene = testkit::build(
        e,
        &[
            (attrs(0, 0), &floor),
            (attrs(1, 1), &glass),
            (attrs(2, 0), &lid),
        ],
        LIM,
    );
    let tri = NOWHERE;
    let mut w = World::new(&[light]);
    w.objects.extend([tri, Object { material: 1, ..tri }, tri]);
    w.run(&mut scene);
    let store = scene.store();
    let at = |x, y| store.get_voxel([x, y, 10]).unwrap().light(0);
    assert_eq!(at(22, 22), LightVisibility::Visible);
    assert_eq!(at(29, 29), LightVisibility::Translucent);
    assert_eq!(at(32, 32), LightVisibility::Occluded);
}

#[test]
fn open_surfaces_lit_from_behind_see_the_light_from_their_back() {
    let e = Extent::cube(32).unwrap();
    // A plate facing up, the light below it, another plate in between for
    // half of it.
    let top = testkit::level_plate(e, 20, 4..28);
    let mid = |s: &mut dyn VoxelSink| {
        testkit::plate(
            e,
            10 * VOXEL + VOXEL / 2,
            4..12,
            4..28,
            true,
            Separation::Six,
            s,
        )
    };
    let mut scene = testkit::build(e, &[(attrs(0, 0), &top), (attrs(1, 0), &mid)], LIM);
    let tri = NOWHERE;
    let mut w = World::new(&[vox([16, 16, -2000])]);
    w.objects.extend([tri, tri]);
    let rep = w.run(&mut scene);
    assert_eq!(rep.facing_away, 0);
    let store = scene.store();
    let r = store.get_voxel([20, 16, 20]).unwrap();
    assert_eq!(r.light(0), LightVisibility::Visible);
    // The light is behind the stored normal: no diffuse in illum.
    assert_eq!(r.illum[0], AMBIENT_ONLY);
    let shadowed = store.get_voxel([6, 16, 20]).unwrap();
    assert_eq!(shadowed.light(0), LightVisibility::Occluded);
    // A closed shape facing away is occluded without a ray.
    let cube = Object {
        shape: Shape::Cuboid(Cuboid {
            min: [0; 3],
            max: [1; 3],
        }),
        material: 0,
    };
    let mut scene = testkit::build(e, &[(attrs(0, 0), &top)], LIM);
    let mut w = World::new(&[vox([16, 16, -2000])]);
    w.objects.push(cube);
    let rep = w.run(&mut scene);
    assert_eq!(rep.rays, 0);
    assert!(rep.facing_away > 0);
}

#[test]
fn adjacent_pieces_of_one_surface_do_not_shadow_each_other() {
    // A floor made of two objects (mesh triangles); light at a grazing 4°.
    let e = Extent::new(96, 32, 16).unwrap();
    let z = 5 * VOXEL + VOXEL / 3;
    let a =
        |s: &mut dyn VoxelSink| testkit::plate(e, z, 0..48, 0..32, false, Separation::TwentySix, s);
    let b = |s: &mut dyn VoxelSink| {
        testkit::plate(e, z, 48..96, 0..32, false, Separation::TwentySix, s)
    };
    let mut scene = testkit::build(e, &[(attrs(0, 0), &a), (attrs(1, 0), &b)], LIM);
    let tri = NOWHERE;
    // tan 4° ≈ 0.07: 100 000 voxels away, 7 000 up.
    let mut w = World::new(&[vox([-100_000, 16, 7_000])]);
    w.objects.extend([tri, tri]);
    let rep = w.run(&mut scene);
    assert_eq!(rep.occluded, 0, "{rep:?}");
    assert_eq!(rep.visible, rep.records);
}

#[test]
fn a_sphere_on_a_floor_casts_a_contact_shadow() {
    let e = Extent::cube(64).unwrap();
    let floor = testkit::level_plate(e, 10, 0..64);
    let ball = testkit::ball(e, vox([32, 32, 20]).map(|c| c + VOXEL / 2), 10 * VOXEL);
    let mut scene = testkit::build(e, &[(attrs(0, 0), &floor), (attrs(1, 0), &ball)], LIM);
    let tri = NOWHERE;
    let mut w = World::new(&[vox([32, 32, 5000])]);
    w.objects.extend([tri, sphere_obj([32, 32, 20], 10)]);
    w.run(&mut scene);
    let store = scene.store();
    // Under the ball, around the contact: occluded; far away: visible.
    for x in [29, 32, 35] {
        let r = store.get_voxel([x, 32, 10]).unwrap();
        assert_eq!(store.owner(r), 0);
        assert_eq!(r.light(0), LightVisibility::Occluded, "x = {x}");
    }
    assert_eq!(
        store.get_voxel([5, 5, 10]).unwrap().light(0),
        LightVisibility::Visible
    );
}

/// A concave object still shadows itself: light grazing through a torus's
/// hole is blocked by the near side of the ring.
#[test]
fn a_torus_shadows_itself() {
    let e = Extent::cube(64).unwrap();
    let centre = vox([32, 32, 32]).map(|c| c + VOXEL / 2);
    let t = |s: &mut dyn VoxelSink| {
        testkit::torus(e, centre, 18 * VOXEL, 6 * VOXEL, Separation::Six, s)
    };
    let mut scene = testkit::build(e, &[(attrs(0, 0), &t)], LIM);
    let mut w = World::new(&[vox([4000, 32, 32])]);
    w.objects.push(Object {
        shape: Shape::Torus(Torus {
            centre,
            axis: [0, 0, NORMAL_ONE],
            major: 18 * VOXEL,
            minor: 6 * VOXEL,
        }),
        material: 0,
    });
    w.run(&mut scene);
    let store = scene.store();
    // Inner wall on the far (−x) side faces +x, towards the light, but the
    // near side of the ring is in the way.
    let inner_far = (0..32)
        .rev()
        .find_map(|x| store.get_voxel([x, 32, 32]).map(|r| (x, *r)))
        .unwrap();
    assert!(
        inner_far.1.normal_vector()[0] > NORMAL_ONE / 2,
        "{inner_far:?}"
    );
    assert_eq!(
        inner_far.1.light(0),
        LightVisibility::Occluded,
        "{inner_far:?}"
    );
    // Outer wall on the near (+x) side: lit.
    let outer_near = (32..64)
        .rev()
        .find_map(|x| store.get_voxel([x, 32, 32]))
        .unwrap();
    assert_eq!(outer_near.light(0), LightVisibility::Visible);
}

/// A 16³ raster holding a ball of radius 4 voxels about voxel (8, 8, 8)'s
/// corner, object `object` of material 0.
fn small_ball(object: u32) -> Scene {
    let e = Extent::cube(16).unwrap();
    let ball = testkit::ball(e, vox([8, 8, 8]), 4 * VOXEL);
    testkit::build(e, &[(attrs(object, 0), &ball)], LIM)
}

#[test]
fn missing_tables_and_extent_mismatch() {
    let e = Extent::cube(16).unwrap();
    let mut scene = small_ball(3);
    // Object 3 is not in the (empty) table: counted, not a panic.
    let mut w = World::new(&[vox([8, 8, 100])]);
    let rep = w.run(&mut scene);
    assert_eq!(rep.missing, rep.records);
    let other = Extent::cube(8).unwrap();
    let plane = vec![0u8; other.len()];
    let raster = Raster::new(other, &plane).unwrap();
    let mut store =
        RecordStoreMut::with_lists(e, &scene.dir, &mut scene.records, &scene.lists).unwrap();
    let mut objs = [Object::UNUSED; 1];
    let table = ObjectTable::new(&mut objs, &mut []);
    assert_eq!(
        illuminate(
            &raster,
            &mut store,
            &table,
            &w.materials,
            &w.lights,
            &LightParams::default()
        )
        .unwrap_err(),
        LightError::ExtentMismatch
    );
}

#[test]
fn far_lights_and_huge_coordinates_do_not_fail() {
    let mut scene = small_ball(0);
    let mut w = World::new(&[
        [i64::MAX, i64::MIN, 0],
        [1 << 40, 1 << 41, -(1 << 45)],
        vox([8, 8, 8]).map(|c| c + VOXEL / 2), // at a voxel centre inside the sphere
    ]);
    w.objects.push(sphere_obj([8, 8, 8], 4));
    let rep = w.run(&mut scene);
    assert_eq!(rep.records as usize, scene.records.len());
}

/// Runs of records in any order give what the serial pass gives: the
/// contract hosts rely on to run the pass on threads.
#[test]
fn runs_in_any_order_equal_the_serial_pass() {
    let e = Extent::cube(64).unwrap();
    let big = |s: &mut dyn VoxelSink| {
        testkit::sphere(e, vox([32, 32, 20]), 12 * VOXEL, Separation::Six, s)
    };
    let small = |s: &mut dyn VoxelSink| {
        testkit::sphere(e, vox([32, 32, 45]), 4 * VOXEL, Separation::Six, s)
    };
    let mut scene = testkit::build(e, &[(attrs(0, 0), &big), (attrs(1, 1), &small)], LIM);
    let mut w = World::new(&[vox([32, 32, 1000]), vox([-40, 10, 30])]);
    w.objects.push(sphere_obj([32, 32, 20], 12));
    w.objects.push(Object {
        material: 1,
        ..sphere_obj([32, 32, 45], 4)
    });
    let unlit = scene.records.clone();
    let serial_report = w.run(&mut scene);
    let serial = scene.records.clone();

    let mut storage = vec![Object::UNUSED; w.objects.len()];
    let mut table = ObjectTable::new(&mut storage, &mut []);
    for o in &w.objects {
        table.push(*o).unwrap();
    }
    let raster = Raster::new(e, &scene.plane).unwrap();
    let store = RecordStore::with_lists(e, &scene.dir, &unlit, &scene.lists).unwrap();
    let (out, report) = pass_in_runs(&raster, &store, &table, &w, &LightParams::default(), None);
    assert_eq!(out, serial);
    assert_eq!(report, serial_report);
    assert!(report.translucent > 0 && report.visible > 0);
}

/// The tube rule of the module docs (*Shadow classification*), written
/// out: `Visible` exactly when no voxel within chessboard distance 1 of a
/// voxel of the 6-connected segment from `v`'s centre to `light`
/// (clipped to the raster) is opaque and holds an object not among `v`'s
/// own or has no record.
fn tube_rule(raster: &Raster<'_>, store: &RecordStore<'_>, v: [u32; 3], light: [i64; 3]) -> bool {
    let e = raster.extent();
    let own = store.objects(store.get_voxel(v).unwrap());
    let Some(ray) = DiscreteRay::segment(e, v.map(voxel_centre), light).unwrap() else {
        return true;
    };
    for p in ray.voxels(raster, Connectivity::Six).unwrap() {
        let p = e.coord(p.index).unwrap();
        for dz in -1..=1 {
            for dy in -1..=1 {
                for dx in -1..=1 {
                    let w = [
                        p[0].wrapping_add_signed(dx),
                        p[1].wrapping_add_signed(dy),
                        p[2].wrapping_add_signed(dz),
                    ];
                    if !e.contains(w) || w == v || raster.cell(w).unwrap() & cell::OPAQUE == 0 {
                        continue;
                    }
                    match store.get_voxel(w) {
                        Some(r) if store.objects(r).iter().all(|o| own.contains(o)) => {}
                        _ => return false,
                    }
                }
            }
        }
    }
    true
}

/// The light pass over `store` by [`illuminate_run`] in runs of 97
/// records (not a divisor of the record count, not a brick size), the last
/// run first, to show the order does not matter: the lit records and the
/// added reports.
fn pass_in_runs(
    raster: &Raster<'_>,
    store: &RecordStore<'_>,
    table: &ObjectTable<'_>,
    w: &World,
    params: &LightParams,
    level: Option<&bricks::ShadowBricks<'_>>,
) -> (Vec<VoxelRecord>, LightReport) {
    let mut out = store.records().to_vec();
    let mut report = LightReport::default();
    let starts: Vec<usize> = (0..out.len()).step_by(97).collect();
    for &first in starts.iter().rev() {
        let end = (first + 97).min(out.len());
        let r = illuminate_run(
            raster,
            store,
            first,
            &mut out[first..end],
            table,
            &w.materials,
            &w.lights,
            params,
            level,
        )
        .unwrap();
        report.add(&r);
    }
    (out, report)
}

/// The exact raster of `balls` (centre, radius; object `i` for ball `i`)
/// in `e`, with its distance field.
fn balls_scene(e: Extent, balls: &[([i64; 3], i64)]) -> Scene {
    let shapes: Vec<_> = balls
        .iter()
        .map(|&(c, r)| {
            move |s: &mut dyn VoxelSink| testkit::sphere(e, c, r, Separation::TwentySix, s)
        })
        .collect();
    let objects: Vec<Voxelize<'_>> = shapes
        .iter()
        .enumerate()
        .map(|(i, f)| (attrs(i as u32, 0), f as &dyn Fn(&mut dyn VoxelSink)))
        .collect();
    let mut scene = testkit::build(e, &objects, LIM);
    crate::proximity::distance_field(
        &mut crate::raster::RasterMut::new(e, &mut scene.plane).unwrap(),
    );
    scene
}

/// Three lights inside a raster of `dims` voxels, or up to twice its size
/// away.
fn random_lights(rng: &mut testkit::Rng, dims: [u32; 3]) -> Vec<[i64; 3]> {
    (0..3)
        .map(|_| {
            dims.map(|n| {
                let n = i64::from(n) * VOXEL;
                rng.range(-2 * n, 3 * n)
            })
        })
        .collect()
}

/// [`classify_voxel`] is the tube rule, on random overlapping balls cut by
/// the faces of small rasters (voxels on the faces, where the walk's test
/// clips the neighbourhood, and inside), with lights inside the raster and
/// outside it.
#[test]
fn classification_is_the_tube_rule() {
    let mut rng = testkit::Rng(0x5eed_c1a5_5f1e);
    let (mut lit, mut undecided) = (0u32, 0u32);
    for _ in 0..30 {
        let dims = [0; 3].map(|_| 4 + rng.below_u32(14));
        let e = Extent::new(dims[0], dims[1], dims[2]).unwrap();
        let balls: Vec<([i64; 3], i64)> = (0..2 + rng.below(4))
            .map(|_| {
                let c = dims.map(|n| rng.range(-VOXEL, i64::from(n) * VOXEL + VOXEL));
                (c, rng.range(VOXEL / 2, 4 * VOXEL))
            })
            .collect();
        let scene = balls_scene(e, &balls);
        let raster = Raster::new(e, &scene.plane).unwrap();
        let store = scene.store();
        let lights = random_lights(&mut rng, dims);
        for z in 0..dims[2] {
            for y in 0..dims[1] {
                for x in 0..dims[0] {
                    let v = [x, y, z];
                    let Some(rec) = store.get_voxel(v) else {
                        continue;
                    };
                    for &light in &lights {
                        // No shapes: the tube rule alone.
                        let got = classify_voxel(
                            &raster,
                            &store,
                            None,
                            |_| None,
                            |_| None,
                            v,
                            rec,
                            light,
                        )
                        .unwrap();
                        let want = tube_rule(&raster, &store, v, light);
                        assert_eq!(
                            got == LightVisibility::Visible,
                            want,
                            "{dims:?} {balls:?} voxel {v:?} light {light:?}"
                        );
                        if want {
                            lit += 1;
                        } else {
                            undecided += 1;
                        }
                    }
                }
            }
        }
    }
    assert!(
        lit > 1000 && undecided > 1000,
        "{lit} lit, {undecided} undecided"
    );
}

/// The facing-away shortcut is sound: where it fires, the normalized
/// direction's N·L is negative, as the pass would have found it; over
/// directions of every magnitude (2^0 to 2^62 units) and stored normals,
/// grazing ones included, it fires for most of the directions facing away.
#[test]
fn facing_away_implies_a_negative_n_dot_l() {
    let mut rng = testkit::Rng(0xface_a3a7);
    let (mut fired, mut away) = (0u32, 0u32);
    for case in 0..200_000u32 {
        let n = crate::voxel::decode_normal([
            rng.range(-32768, 32768) as i16,
            rng.range(-32768, 32768) as i16,
        ]);
        let bits = case % 63;
        let mut d: [i64; 3] = [0; 3].map(|_| rng.range(-(1i64 << bits), 1i64 << bits));
        if case % 5 == 0 {
            // Nearly in the tangent plane: d minus its part along n.
            let dn: i128 = (0..3).map(|k| i128::from(d[k]) * i128::from(n[k])).sum();
            for k in 0..3 {
                d[k] -= i64::try_from((dn * i128::from(n[k])) >> 60).unwrap_or(0);
            }
        }
        let Some(l) = normalize(d) else { continue };
        let ndl = dot_unit(n, l);
        if facing_away(n, d) {
            fired += 1;
            assert!(ndl < 0, "n {n:?} d {d:?}: N·L {ndl}");
        }
        away += u32::from(ndl < -(1 << 20));
    }
    assert!(
        fired > away / 2 && away > 50_000,
        "{fired} fired, {away} facing away"
    );
}

/// The brick level changes no classification and spares walks: on random
/// scenes of a few large balls (surfaces of one object over many bricks)
/// and small ones beside them, in rasters of several bricks whose sides
/// are not multiples of the brick edge, with lights inside and outside,
/// [`classify_voxel`] with the level gives the tube rule's answer for
/// every voxel and light, and the level proves a good part of them lit.
#[test]
fn brick_level_changes_no_classification() {
    use super::bricks::{NO_RECORD, SEVERAL, ShadowBricks, shadow_bricks};
    let mut rng = testkit::Rng(0xb1c4_5ead);
    let (mut proven, mut lit, mut pairs, mut centred) = (0u32, 0u32, 0u32, 0u32);
    for _ in 0..12 {
        let dims = [0; 3].map(|_| 20 + rng.below_u32(21));
        let e = Extent::new(dims[0], dims[1], dims[2]).unwrap();
        let mut balls: Vec<([i64; 3], i64)> = Vec::new();
        for big in 0..2 + rng.below(4) {
            let c = dims.map(|n| rng.range(0, i64::from(n) * VOXEL));
            let r = if big < 2 {
                rng.range(6 * VOXEL, 14 * VOXEL)
            } else {
                rng.range(VOXEL / 2, 2 * VOXEL)
            };
            balls.push((c, r));
        }
        let scene = balls_scene(e, &balls);
        let raster = Raster::new(e, &scene.plane).unwrap();
        let store = scene.store();
        let n = crate::proximity::coarse_extent(e).unwrap().len();
        let (mut owners, mut plane) = (vec![0u32; n], vec![0u8; n]);
        assert!(shadow_bricks(&store, &mut owners, &mut plane));
        assert!(!shadow_bricks(&store, &mut owners[1..], &mut plane[1..]));
        let bricks = ShadowBricks::new(e, &plane, &owners).unwrap();
        // The owners are the records' objects, brick by brick.
        for (v, rec) in store.iter() {
            let o = bricks.owner(bricks.brick_of(v).unwrap());
            assert_ne!(o, NO_RECORD);
            assert!(o == SEVERAL || store.objects(rec) == [o - 1], "{v:?}");
        }
        let mut lights = random_lights(&mut rng, dims);
        // And one at the centre of a brick of one object beside a brick
        // of another: a brick segment of length 0, where only the brick's
        // neighbourhood can tell.
        let ce = crate::proximity::coarse_extent(e).unwrap();
        let beside_another = |v: [u32; 3]| {
            let o = bricks.owner(bricks.brick_of(v).unwrap());
            let u = v.map(|c| c >> 3);
            o != SEVERAL
                && (0..27).any(|k| {
                    let w = [k % 3, k / 3 % 3, k / 9].map(|d| d as i64 - 1);
                    let n = [0, 1, 2].map(|a| u[a] as i64 + w[a]);
                    n.iter().all(|&c| c >= 0)
                        && ce.index(n.map(|c| c as u32)).is_some_and(|i| {
                            let p = bricks.owner(i);
                            p != NO_RECORD && p != o
                        })
                })
        };
        if let Some((v, _)) = store.iter().find(|(v, _)| beside_another(*v)) {
            lights.push(v.map(|c| i64::from(c & !7) * VOXEL + 4 * VOXEL));
            centred += 1;
        }
        for (v, rec) in store.iter() {
            for &light in &lights {
                let with = classify_voxel(
                    &raster,
                    &store,
                    Some(&bricks),
                    |_| None,
                    |_| None,
                    v,
                    rec,
                    light,
                );
                let want = tube_rule(&raster, &store, v, light);
                assert_eq!(
                    with.unwrap() == LightVisibility::Visible,
                    want,
                    "{dims:?} {balls:?} voxel {v:?} light {light:?}"
                );
                pairs += 1;
                lit += u32::from(want);
                proven += u32::from(bricks.proves_lit(v, light).unwrap());
            }
        }
    }
    assert!(
        proven > pairs / 20 && proven < lit && centred > 3,
        "{proven} proven by bricks, {lit} lit, {pairs} pairs, {centred} lights at a brick's centre"
    );
}

/// The light pass with the brick level gives the records it gives without
/// (runs in any order), and its count of brick proofs.
#[test]
fn light_pass_with_bricks_is_the_pass_without() {
    use super::bricks::{ShadowBricks, shadow_bricks};
    let e = Extent::new(43, 37, 29).unwrap();
    let w = World::new(&[
        [-30 * VOXEL, 20 * VOXEL, 80 * VOXEL],
        [20 * VOXEL, -40 * VOXEL, 10 * VOXEL],
    ]);
    let balls = [
        (vox([20, 18, 14]), 11 * VOXEL),
        (vox([36, 8, 24]), 3 * VOXEL),
    ];
    let scene = balls_scene(e, &balls);
    let mut storage = vec![Object::UNUSED; 2];
    let mut table = ObjectTable::new(&mut storage, &mut []);
    for (centre, radius) in balls {
        table
            .push(Object {
                shape: Shape::Sphere(Sphere { centre, radius }),
                material: 0,
            })
            .unwrap();
    }
    let raster = Raster::new(e, &scene.plane).unwrap();
    let store = scene.store();
    let n = crate::proximity::coarse_extent(e).unwrap().len();
    let (mut owners, mut plane) = (vec![0u32; n], vec![0u8; n]);
    assert!(shadow_bricks(&store, &mut owners, &mut plane));
    let bricks = ShadowBricks::new(e, &plane, &owners).unwrap();
    let params = LightParams {
        exact_records: ExactRecords::Classify,
        ..LightParams::default()
    };
    let pass = |level| pass_in_runs(&raster, &store, &table, &w, &params, level);
    let (plain, plain_report) = pass(None);
    let (fast, fast_report) = pass(Some(&bricks));
    assert_eq!(plain, fast);
    assert_eq!(plain_report.brick_proofs, 0);
    assert!(fast_report.brick_proofs > 0, "{fast_report:?}");
    assert_eq!(
        fast_report.rays + fast_report.brick_proofs,
        plain_report.rays,
        "{fast_report:?} {plain_report:?}"
    );
    assert_eq!(fast_report.visible, plain_report.visible);
    // A level of another raster is refused.
    let other = Extent::new(44, 37, 29).unwrap();
    let m = crate::proximity::coarse_extent(other).unwrap().len();
    let (o2, p2) = (vec![0u32; m], vec![0u8; m]);
    let wrong = ShadowBricks::new(other, &p2, &o2).unwrap();
    let mut out = store.records().to_vec();
    assert_eq!(
        illuminate_run(
            &raster,
            &store,
            0,
            &mut out,
            &table,
            &w.materials,
            &w.lights,
            &params,
            Some(&wrong)
        ),
        Err(LightError::ExtentMismatch)
    );
}

/// The dark-side rule is sound and fires: a cube it finds dark has every
/// corner (so every point) strictly on the dark side of the terminator
/// plane for every rounding of the sphere's centre and radius and of the
/// light by up to one unit per coordinate (the worst one computed exactly:
/// the corner's value is a sum of one term per axis); spheres whose
/// terminator plane passes within a few margins of the cube test the
/// margin; a cube whose corners all lie well inside the dark side is found
/// dark.
#[test]
fn dark_side_cubes_lie_beyond_the_terminator() {
    let mut rng = testkit::Rng(0xda4c_51de);
    let (mut dark, mut checked, mut close) = (0u32, 0u32, 0u32);
    for case in 0..6000 {
        let centre: [i64; 3] = [0; 3].map(|_| rng.range(50 * VOXEL, 60 * VOXEL));
        let mut light: [i64; 3] = if rng.below(4) == 0 {
            // Far away, as a light at infinity is.
            [0; 3].map(|_| rng.range(-(1 << 58), 1 << 58))
        } else {
            [0; 3].map(|_| rng.range(-200 * VOXEL, 300 * VOXEL))
        };
        if rng.below(4) == 0 {
            // In line with the centre on one axis, within rounding: there
            // a rounding can make the other corner the farthest.
            let k = rng.below(3) as usize;
            light[k] = centre[k] + rng.range(-2, 3);
        }
        let mut r = rng.range(VOXEL / 4, 40 * VOXEL);
        // A voxel near the sphere's surface.
        let v =
            centre.map(|c| u32::try_from((c + rng.range(-r - VOXEL, r + VOXEL)) / VOXEL).unwrap());
        // Corner `corner`'s term on axis `k` for centre offset `ec` and
        // light offset `el`.
        let term = |k: usize, corner: u32, ec: i128, el: i128| -> i128 {
            let lo = i128::from(v[k]) * i128::from(VOXEL);
            let q = lo + i128::from(VOXEL) * i128::from((corner >> k) & 1);
            let c = i128::from(centre[k]) + ec;
            (q - c) * (i128::from(light[k]) + el - c)
        };
        let value = |corner: u32| -> i128 { (0..3).map(|k| term(k, corner, 0, 0)).sum() };
        let top = (0..8).map(value).max().unwrap();
        if case % 2 == 1 && top > 0 {
            // A sphere whose terminator plane passes near the cube's
            // farthest corner: within a few margins of the rule.
            let m = i128::from(r) * 64
                + (0..3)
                    .map(|k| (i128::from(light[k]) - i128::from(centre[k])).abs())
                    .sum::<i128>();
            let target = (top + i128::from(rng.range(-4, 5)) * m / 4).max(1);
            r = i64::try_from(target.isqrt()).unwrap_or(i64::MAX).max(1);
        }
        let s = Sphere { centre, radius: r };
        let found = cube_beyond_terminator(&s, v, light);
        checked += 1;
        if found {
            dark += 1;
            // The worst rounding: per axis the largest term, and R − 1.
            let worst = (0..8)
                .map(|corner| {
                    (0..3)
                        .map(|k| {
                            (-1..=1)
                                .flat_map(|ec| (-1..=1).map(move |el| (ec, el)))
                                .map(|(ec, el)| term(k, corner, ec, el))
                                .max()
                                .unwrap()
                        })
                        .sum::<i128>()
                })
                .max()
                .unwrap();
            let least = i128::from(r - 1) * i128::from(r - 1);
            assert!(
                worst < least,
                "{s:?} voxel {v:?} light {light:?}: a rounding puts a corner on the lit side"
            );
            if least - top < 1 << 40 {
                close += 1;
            }
        } else {
            // Not found: some corner comes within a small margin of the
            // plane (a thousandth of a voxel times the lengths involved).
            let d1: i128 = (0..3)
                .map(|k| (i128::from(light[k]) - i128::from(centre[k])).abs())
                .sum();
            let slack = (d1 + 8 * i128::from(r) + i128::from(VOXEL) * 200) * 64;
            assert!(
                top + slack >= i128::from(r) * i128::from(r),
                "{s:?} voxel {v:?} light {light:?}: a dark cube was missed"
            );
        }
    }
    // About half the voxels around a sphere face away from a light, and
    // the spheres set near the rule's margin test it.
    assert!(dark > checked / 5, "{dark} of {checked}");
    assert!(close > 100, "{close} dark cubes near the plane");
}

/// Through [`classify_voxel`] with the object shapes: a lone sphere's
/// voxels wholly on the dark side are undecided without a walk, every
/// other voxel gets the tube rule's answer.
#[test]
fn classification_leaves_the_dark_side_undecided() {
    let e = Extent::cube(48).unwrap();
    let (c, r) = (vox([24, 24, 24]), 15 * VOXEL + 1234);
    let vz = |s: &mut dyn VoxelSink| testkit::sphere(e, c, r, Separation::TwentySix, s);
    let mut scene = testkit::build(e, &[(attrs(0, 0), &vz)], LIM);
    crate::proximity::distance_field(
        &mut crate::raster::RasterMut::new(e, &mut scene.plane).unwrap(),
    );
    let raster = Raster::new(e, &scene.plane).unwrap();
    let store = scene.store();
    let sphere = Sphere {
        centre: c,
        radius: r,
    };
    let shape = |id: u32| (id == 0).then_some(Shape::Sphere(sphere));
    let (mut dark, mut walked) = (0u32, 0u32);
    for light in [vox([200, 90, 30]), vox([24, 24, -40]), vox([30, 20, 26])] {
        for (v, rec) in store.iter() {
            let got =
                classify_voxel(&raster, &store, None, shape, |_| None, v, rec, light).unwrap();
            if cube_beyond_terminator(&sphere, v, light) {
                assert_eq!(got, LightVisibility::Translucent, "voxel {v:?}");
                dark += 1;
            } else {
                let tube = tube_rule(&raster, &store, v, light);
                assert_eq!(got == LightVisibility::Visible, tube, "voxel {v:?}");
                walked += 1;
            }
        }
    }
    assert!(dark > 2000 && walked > 2000, "{dark} dark, {walked} walked");
}

/// On a finished plane (proximity flags and distances set) adaptive shadow
/// rays, which take 26-steps and skip empty space away from surfaces,
/// give the light bits of 6-connected ones ([`LightParams::mode`]):
/// random overlapping opaque and translucent balls and scattered single
/// voxels (which a 26-step could pass between), lights inside and outside
/// the raster.
#[test]
fn adaptive_shadow_rays_on_a_finished_plane_are_six_connected_ones() {
    let mut rng = testkit::Rng(0xada9_71fe);
    let mut compared = 0usize;
    let mut total = LightReport::default();
    for _ in 0..40 {
        let dims = [0; 3].map(|_| 12 + rng.below_u32(40));
        let e = Extent::new(dims[0], dims[1], dims[2]).unwrap();
        let balls: Vec<([i64; 3], i64)> = (0..3 + rng.below(6))
            .map(|_| {
                let c = dims.map(|n| rng.range(0, i64::from(n) * VOXEL));
                (c, rng.range(VOXEL, 6 * VOXEL))
            })
            .collect();
        let shapes: Vec<_> = balls
            .iter()
            .map(|&(c, r)| {
                move |s: &mut dyn VoxelSink| testkit::sphere(e, c, r, Separation::Six, s)
            })
            .collect();
        let dust: Vec<[u32; 3]> = (0..e.len() / 1000)
            .map(|_| dims.map(|n| rng.below_u32(n)))
            .collect();
        let scatter = |s: &mut dyn VoxelSink| {
            for &v in &dust {
                s.offer(
                    v,
                    Surfel {
                        normal: [0, 0, crate::voxelize::NORMAL_ONE],
                        distance: 0,
                    },
                );
            }
        };
        let mut objects: Vec<Voxelize<'_>> = shapes
            .iter()
            .enumerate()
            .map(|(i, f)| {
                let m = u16::from(i % 3 == 2);
                (attrs(i as u32, m), f as &dyn Fn(&mut dyn VoxelSink))
            })
            .collect();
        objects.push((attrs(balls.len() as u32, 0), &scatter));
        let mut scene = testkit::build(e, &objects, LIM);
        crate::proximity::distance_field(
            &mut crate::raster::RasterMut::new(e, &mut scene.plane).unwrap(),
        );
        let lights: Vec<[i64; 3]> = (0..2)
            .map(|_| {
                dims.map(|n| {
                    let n = i64::from(n) * VOXEL;
                    rng.range(-2 * n, 3 * n)
                })
            })
            .collect();
        let mut w = World::new(&lights);
        for (i, &(c, r)) in balls.iter().enumerate() {
            w.objects.push(Object {
                shape: Shape::Sphere(Sphere {
                    centre: c,
                    radius: r,
                }),
                material: u16::from(i % 3 == 2),
            });
        }
        w.objects.push(NOWHERE);
        let unlit = scene.records.clone();
        let six = w.run(&mut scene);
        let by_six = core::mem::replace(&mut scene.records, unlit);
        let adaptive = w.run_with(
            &mut scene,
            &LightParams {
                mode: Connectivity::Adaptive,
                ..LightParams::default()
            },
        );
        assert_eq!(scene.records, by_six, "{dims:?} {balls:?} {lights:?}");
        assert_eq!(adaptive, six);
        compared += by_six.len();
        total.add(&six);
    }
    assert!(compared > 15_000, "{compared}");
    assert!(
        total.occluded > 100 && total.visible > 100 && total.translucent > 100,
        "{total:?}"
    );
}

/// The eight corners of voxel `v`'s closed cube, in fixed units.
fn cube_corners(v: [u32; 3]) -> Vec<[i64; 3]> {
    let lo = v.map(|k| i64::from(k) * VOXEL);
    (0..8)
        .map(|c| core::array::from_fn(|k| lo[k] + ((c >> k) & 1) * VOXEL))
        .collect()
}

/// Whether the segment from `p` to `l` passes farther than `r` from `c`,
/// exactly (offsets below 2^38, so every product fits).
fn passes_outside(p: [i64; 3], l: [i64; 3], c: [i64; 3], r: i64) -> bool {
    let w: [i128; 3] = core::array::from_fn(|k| i128::from(c[k] - p[k]));
    let u: [i128; 3] = core::array::from_fn(|k| i128::from(l[k] - p[k]));
    let dot = |a: [i128; 3], b: [i128; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let r2 = i128::from(r) * i128::from(r);
    let (uu, wu) = (dot(u, u), dot(w, u));
    if wu <= 0 {
        return dot(w, w) > r2;
    }
    if wu >= uu {
        let d = [w[0] - u[0], w[1] - u[1], w[2] - u[2]];
        return dot(d, d) > r2;
    }
    let x = [
        w[1] * u[2] - w[2] * u[1],
        w[2] * u[0] - w[0] * u[2],
        w[0] * u[1] - w[1] * u[0],
    ];
    dot(x, x) > r2 * uu
}

/// [`sphere_clears`] never clears a sphere that a segment from a point of
/// the cube (corners, centre, random points) to the light meets: random
/// spheres near the voxel, lights near and up to 2^36 units away (the
/// offsets then shifted before the products).
#[test]
fn a_cleared_sphere_meets_no_segment_from_the_cube() {
    let mut rng = testkit::Rng(0xc1ea_4a9c);
    let (mut cleared, mut close) = (0u32, 0u32);
    for case in 0..20_000 {
        let v = [0; 3].map(|_| rng.below_u32(64));
        let centre = [0; 3].map(|_| rng.range(0, 64 * VOXEL));
        let radius = rng.range(VOXEL / 8, 8 * VOXEL);
        let light = if case % 2 == 0 {
            [0; 3].map(|_| rng.range(-64 * VOXEL, 128 * VOXEL))
        } else {
            [0; 3].map(|_| rng.range(-(1 << 36), 1 << 36))
        };
        let s = Sphere { centre, radius };
        if !sphere_clears(&s, v, light) {
            continue;
        }
        cleared += 1;
        let lo = v.map(|k| i64::from(k) * VOXEL);
        let mut points = cube_corners(v);
        points.push(v.map(voxel_centre));
        for _ in 0..8 {
            points.push(core::array::from_fn(|k| lo[k] + rng.range(0, VOXEL + 1)));
        }
        for p in points {
            assert!(
                passes_outside(p, light, centre, radius),
                "{s:?} cleared for voxel {v:?} and light {light:?}, but the segment from {p:?} meets it"
            );
        }
        // Within about two voxels of the rule's bound (radius plus half
        // the diagonal): the rule does not only clear far spheres.
        if !passes_outside(v.map(voxel_centre), light, centre, radius + 3 * VOXEL) {
            close += 1;
        }
    }
    assert!(
        cleared > 5_000 && close > 200,
        "{cleared} cleared, {close} close"
    );
}

/// The sign of `(b − a) × (c − a) · (d − a)`, exactly (offsets below
/// 2^40).
fn orient(a: [i64; 3], b: [i64; 3], c: [i64; 3], d: [i64; 3]) -> i128 {
    let u: [i128; 3] = core::array::from_fn(|k| i128::from(b[k] - a[k]));
    let v: [i128; 3] = core::array::from_fn(|k| i128::from(c[k] - a[k]));
    let w: [i128; 3] = core::array::from_fn(|k| i128::from(d[k] - a[k]));
    let x = [
        u[1] * v[2] - u[2] * v[1],
        u[2] * v[0] - u[0] * v[2],
        u[0] * v[1] - u[1] * v[0],
    ];
    (x[0] * w[0] + x[1] * w[1] + x[2] * w[2]).signum()
}

/// Whether the closed segment from `p` to `q` meets the closed triangle
/// `t`, exactly; a segment in the triangle's plane counts as meeting it.
fn segment_meets_triangle(p: [i64; 3], q: [i64; 3], t: &Triangle) -> bool {
    let [a, b, c] = t.vertices;
    let (sp, sq) = (orient(a, b, c, p), orient(a, b, c, q));
    if sp == 0 && sq == 0 {
        return true;
    }
    if sp == sq {
        return false;
    }
    let s = [orient(p, q, a, b), orient(p, q, b, c), orient(p, q, c, a)];
    s.iter().all(|&x| x >= 0) || s.iter().all(|&x| x <= 0)
}

/// [`triangle_clears`] never clears a triangle that a segment from a point
/// of the cube grown by the margin (its corners, the cube's corners and
/// centre, random points) to the light meets: random triangles near the
/// voxel, some sharing an edge through the cube's neighbourhood (a mesh's
/// neighbours), lights near and up to 2^36 units away. And it clears
/// triangles next to the voxel, not only far ones.
#[test]
fn a_cleared_triangle_meets_no_segment_from_the_cube() {
    let mut rng = testkit::Rng(0x7a1a_c1ea);
    let (mut cleared, mut near, mut tested) = (0u32, 0u32, 0u32);
    let m = CLEARANCE_MARGIN_UNITS;
    for case in 0..60_000 {
        let v = [0; 3].map(|_| 4 + rng.below_u32(56));
        let lo = v.map(|k| i64::from(k) * VOXEL);
        let around = |rng: &mut testkit::Rng, reach: i64| -> [i64; 3] {
            core::array::from_fn(|k| lo[k] + rng.range(-reach * VOXEL, (reach + 1) * VOXEL))
        };
        let mut vertices = [
            around(&mut rng, 4),
            around(&mut rng, 4),
            around(&mut rng, 4),
        ];
        if case % 3 == 0 {
            // Two vertices on either side of the cube, within a voxel of
            // it: an edge passing by, as a neighbouring triangle's does.
            vertices[0] = around(&mut rng, 1);
            vertices[1] = around(&mut rng, 1);
        }
        let t = Triangle {
            vertices,
            normals: None,
        };
        let light = if case % 2 == 0 {
            around(&mut rng, 64)
        } else {
            [0; 3].map(|_| rng.range(-(1 << 36), 1 << 36))
        };
        tested += 1;
        if !triangle_clears(&t, v, light) {
            continue;
        }
        cleared += 1;
        let mut points = Vec::new();
        for c in 0..8i64 {
            let corner = |lo: i64, hi: i64| -> [i64; 3] {
                core::array::from_fn(|k| if (c >> k) & 1 == 0 { lo } else { hi })
            };
            let plain = corner(0, VOXEL);
            let grown = corner(-m, VOXEL + m);
            points.push(core::array::from_fn(|k| lo[k] + plain[k]));
            points.push(core::array::from_fn(|k| lo[k] + grown[k]));
        }
        points.push(v.map(voxel_centre));
        for _ in 0..6 {
            points.push(core::array::from_fn(|k| {
                lo[k] + rng.range(-m, VOXEL + m + 1)
            }));
        }
        for p in points {
            assert!(
                !segment_meets_triangle(p, light, &t),
                "{t:?} cleared for voxel {v:?} and light {light:?}, but the segment from {p:?} meets it"
            );
        }
        // A vertex within two voxels of the cube.
        if t.vertices
            .iter()
            .any(|p| (0..3).all(|k| (p[k] - lo[k]).abs() <= 2 * VOXEL))
        {
            near += 1;
        }
    }
    assert!(
        cleared > tested / 4 && near > 2_000,
        "{cleared} cleared of {tested}, {near} near"
    );
}

/// The triangles' proofs read only offsets they can form exactly: far
/// vertices or lights, or a light in the triangle's plane, clear nothing,
/// and huge coordinates do not fail.
#[test]
fn far_or_flat_triangles_are_not_cleared() {
    let v = [3, 4, 5];
    let lo = v.map(|k| i64::from(k) * VOXEL);
    let near = |d: [i64; 3]| -> [i64; 3] { core::array::from_fn(|k| lo[k] + d[k] * VOXEL) };
    // Beside the cube, a light straight above: the plane test clears it.
    let t = Triangle {
        vertices: [near([3, 0, 0]), near([4, 0, 0]), near([3, 1, 0])],
        normals: None,
    };
    let above = near([0, 0, 50]);
    assert!(triangle_clears(&t, v, above));
    // The light in the triangle's plane.
    assert!(!triangle_clears(&t, v, near([9, 9, 0])));
    // A vertex beyond the reach, a light beyond it, the extremes.
    let mut far = t;
    far.vertices[2] = near([3, 1 << 14, 0]);
    assert!(!triangle_clears(&far, v, above));
    assert!(!triangle_clears(&t, v, [0, 0, 1 << 51]));
    let huge = Triangle {
        vertices: [[i64::MAX; 3], [i64::MIN; 3], [0, i64::MAX, i64::MIN]],
        normals: None,
    };
    assert!(!triangle_clears(&huge, v, [i64::MIN; 3]));
    assert!(!triangle_clears(&t, [u32::MAX; 3], [i64::MAX; 3]));
}

/// [`shift_below_2_28`] is the least shift that brings its argument below
/// 2^28.
#[test]
fn the_shift_is_the_least_that_brings_below_2_28() {
    let mut rng = testkit::Rng(0x5_41f7);
    let mut values = vec![0u128, 1, (1 << 28) - 1, 1 << 28, (1 << 29) - 1, u128::MAX];
    for _ in 0..10_000 {
        let bits = rng.below_u32(128);
        values.push(((u128::from(rng.next_u64()) << 64) | u128::from(rng.next_u64())) >> bits);
    }
    for big in values {
        let s = shift_below_2_28(big);
        assert!(big >> s < 1 << 28, "{big}");
        assert!(s == 0 || big >> (s - 1) >= 1 << 28, "{big}");
    }
}

/// [`sphere_blocks`] blocks only spheres that every segment from a point
/// of the cube (or within 1/256 voxel of it) to a point within 3/8 voxel
/// of the light (the renderer's ε-shifted segment) enters, from outside,
/// and that lie inside the raster; and it blocks every sphere that does so
/// with an eighth of a voxel to spare beyond its margins. Random spheres
/// near the voxel, lights near and up to 2^36 units away.
#[test]
fn a_blocking_sphere_stands_on_every_segment_from_the_cube() {
    let mut rng = testkit::Rng(0xb10c_4ed5);
    let dims = [64; 3];
    let (mut blocked, mut due) = (0u32, 0u32);
    let slack = VOXEL / 8;
    for case in 0..40_000 {
        let v = [0; 3].map(|_| rng.below_u32(64));
        let c0 = v.map(voxel_centre);
        let radius = rng.range(VOXEL / 8, 16 * VOXEL);
        let light = if case % 2 == 0 {
            [0; 3].map(|_| rng.range(-64 * VOXEL, 128 * VOXEL))
        } else {
            [0; 3].map(|_| rng.range(-(1 << 36), 1 << 36))
        };
        // Anywhere, or near the segment to the light (most cases).
        let centre = if case % 4 == 3 {
            [0; 3].map(|_| rng.range(0, 64 * VOXEL))
        } else {
            // `along` units from the voxel's centre towards the light.
            let d: [i128; 3] = core::array::from_fn(|k| i128::from(light[k] - c0[k]));
            let len = ((d[0] * d[0] + d[1] * d[1] + d[2] * d[2])
                .unsigned_abs()
                .isqrt() as i128)
                .max(1);
            let along = i128::from(rng.range(0, 40 * VOXEL));
            let jitter = 2 * radius;
            core::array::from_fn(|k| {
                c0[k] + (d[k] * along / len) as i64 + rng.range(-jitter, jitter + 1)
            })
        };
        let s = Sphere { centre, radius };
        let outer = HALF_DIAGONAL as i64 + BLOCK_MARGIN as i64;
        let inside = (0..3).all(|k| {
            centre[k] - radius - BLOCK_MARGIN as i64 - slack >= 0
                && centre[k] + radius + BLOCK_MARGIN as i64 + slack <= 64 * VOXEL
        });
        let clearly = inside
            && radius > outer + slack
            && passes_outside(c0, c0, centre, radius + outer + slack)
            && !passes_outside(c0, light, centre, radius - outer - slack);
        if !sphere_blocks(&s, v, light, dims) {
            assert!(
                !clearly,
                "{s:?} not blocking voxel {v:?} for light {light:?}, with room to spare"
            );
            continue;
        }
        blocked += 1;
        if clearly {
            due += 1;
        }
        for c in centre {
            assert!(c - radius >= 0 && c + radius <= 64 * VOXEL);
        }
        let lo = v.map(|k| i64::from(k) * VOXEL);
        let mut points = cube_corners(v);
        points.push(c0);
        for _ in 0..8 {
            let m = VOXEL / 256;
            points.push(core::array::from_fn(|k| {
                lo[k] + rng.range(-m, VOXEL + m + 1)
            }));
        }
        for p in points {
            // Outside, and the segment to a point near the light enters it.
            assert!(
                passes_outside(p, p, centre, radius),
                "{s:?} blocking voxel {v:?} holds {p:?}"
            );
            let reach = 3 * VOXEL / 8 / 2;
            let l: [i64; 3] = core::array::from_fn(|k| light[k] + rng.range(-reach, reach + 1));
            assert!(
                !passes_outside(p, l, centre, radius - 1),
                "{s:?} blocking voxel {v:?} for light {light:?}, but the segment from {p:?} to {l:?} misses it"
            );
        }
    }
    assert!(blocked > 500 && due > 300, "{blocked} blocked, {due} due");
}

/// A sphere in the tube of a voxel's segment to the light, but clear of
/// every segment from the voxel's cube, does not undecide it: the voxels
/// on top of a ball under a light straight above, beside a small ball
/// whose voxels reach into their tube, are lit; without the small ball's
/// geometry they are undecided. Every voxel lit either way has segments
/// from its cube that pass outside the small ball.
#[test]
fn a_clear_sphere_in_the_tube_leaves_the_voxel_lit() {
    let e = Extent::cube(48).unwrap();
    let a = Sphere {
        centre: [20, 24, 24].map(voxel_centre),
        radius: 9 * VOXEL / 2,
    };
    // 2 voxels beside the column x = 20.5 above the ball, radius 0.9: its
    // voxels x = 21..=23 are within 1 of the column's, its surface 1.1
    // voxels from it.
    let b = Sphere {
        centre: [voxel_centre(22), voxel_centre(40), voxel_centre(24)],
        radius: 9 * VOXEL / 10,
    };
    let light = [voxel_centre(20), 400 * VOXEL, voxel_centre(24)];
    let va =
        |s: &mut dyn VoxelSink| testkit::sphere(e, a.centre, a.radius, Separation::TwentySix, s);
    let vb =
        |s: &mut dyn VoxelSink| testkit::sphere(e, b.centre, b.radius, Separation::TwentySix, s);
    let mut scene = testkit::build(e, &[(attrs(0, 0), &va), (attrs(1, 0), &vb)], LIM);
    crate::proximity::distance_field(
        &mut crate::raster::RasterMut::new(e, &mut scene.plane).unwrap(),
    );
    let raster = Raster::new(e, &scene.plane).unwrap();
    let store = scene.store();
    let only_a = |id: u32| (id == 0).then_some(Shape::Sphere(a));
    let both = |id: u32| match id {
        0 => Some(Shape::Sphere(a)),
        1 => Some(Shape::Sphere(b)),
        _ => None,
    };
    let mut gained = 0;
    for (v, rec) in store.iter() {
        if store.objects(rec) != [0] {
            continue;
        }
        let without =
            classify_voxel(&raster, &store, None, only_a, |_| None, v, rec, light).unwrap();
        let with = classify_voxel(&raster, &store, None, both, |_| None, v, rec, light).unwrap();
        if without == LightVisibility::Visible {
            assert_eq!(with, LightVisibility::Visible, "voxel {v:?}");
        }
        if with == LightVisibility::Visible {
            for p in cube_corners(v) {
                assert!(passes_outside(p, light, b.centre, b.radius), "voxel {v:?}");
            }
            if without != LightVisibility::Visible {
                gained += 1;
            }
        }
    }
    assert!(
        gained > 0,
        "no voxel lit thanks to the small ball's geometry"
    );
}

/// The table of looked-up records answers as the store does, for far more
/// voxels than it has entries (so entries are replaced), in an order that
/// repeats voxels: every opaque voxel of a few balls, then random ones,
/// opaque or not, among them again.
#[test]
fn found_records_answer_as_the_store() {
    let e = Extent::cube(48).unwrap();
    let balls = [([14, 20, 18], 9), ([30, 28, 24], 11), ([24, 12, 36], 7)];
    let scene = balls_scene(e, &balls.map(|(c, r)| (vox(c), r * VOXEL)));
    let store = RecordStore::with_lists(e, &scene.dir, &scene.records, &scene.lists).unwrap();
    let opaque: Vec<usize> = (0..e.len())
        .filter(|&i| scene.plane[i] & cell::OPAQUE != 0)
        .collect();
    assert!(opaque.len() > 4 * FOUND_SLOTS, "{}", opaque.len());
    let mut rng = testkit::Rng(0xf0_0d);
    let mut order = opaque.clone();
    for _ in 0..20_000 {
        let i = if rng.range(0, 1) == 0 {
            opaque[rng.range(0, opaque.len() as i64 - 1) as usize]
        } else {
            rng.range(0, e.len() as i64 - 1) as usize
        };
        order.push(i);
    }
    let mut found = FoundRecords::new();
    for i in order {
        let w = e.coord(i).unwrap();
        let c = scene.plane[i];
        let want = store.get_hinted(w, c);
        assert_eq!(found.get(&store, i, w, c), want, "voxel {w:?}");
        assert_eq!(found.get(&store, i, w, c), want, "voxel {w:?}, again");
    }
}
