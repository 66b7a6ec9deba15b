//! Flash of the traversal API with the scene builder: everything
//! `size-traversal` links, plus every voxelizer (sphere, box, triangle,
//! cone, torus, Bézier patch, volume block), CSG, the two-pass record
//! store (with or without object lists), the light pass (the paper's
//! shadow rays and the shadow classification's tube walks) and a record
//! lookup at a hit.
#![no_std]
#![no_main]

use rrt_core::csg::{self, CsgNode, CsgTree, IgnoreLeaf, Solid};
use rrt_core::discrete_ray::{Connectivity, DiscreteRay};
use rrt_core::geometry::{BezierPatch, Cone, Cuboid, Sphere, Torus, Triangle};
use rrt_core::light::{ExactRecords, LightParams, illuminate};
use rrt_core::object_table::{Light, Lights, Material, Materials, Object, ObjectTable, Shape};
use rrt_core::raster::{Extent, RasterMut};
use rrt_core::store::{Counter, Limits, ObjectAttrs};
use rrt_core::voxel::VoxelRecord;
use rrt_core::voxelize::volume::{self, Block};
use rrt_core::voxelize::{Separation, VoxelSink, cone, cuboid, patch, sphere, torus, triangle};

include!("size/common.rs");

static mut PLANE: [u8; 16384] = [0; 16384];
static mut DIR: [u32; 65] = [0; 65];
static mut RECORDS: [VoxelRecord; 1024] = [bytemuck::zeroed(); 1024];
static mut LISTS: [u32; 256] = [0; 256];
static mut OBJECTS: [Object; 4] = [Object::UNUSED; 4];
static mut SAMPLES: [u16; 64] = [0; 64];

fn sep() -> Separation {
    if input::<1>(200)[0] & 1 == 0 {
        Separation::Six
    } else {
        Separation::TwentySix
    }
}

/// Every voxelizer into `sink`.
fn scene(e: Extent, s: &mut dyn VoxelSink) {
    let sep = sep();
    let r = i64_at(0);
    let _ = sphere::surface(
        &Sphere {
            centre: point_at(8),
            radius: r,
        },
        sep,
        e,
        s,
    );
    let _ = cuboid::solid(
        &Cuboid {
            min: point_at(32),
            max: point_at(56),
        },
        sep,
        e,
        s,
    );
    let tri = Triangle {
        vertices: [point_at(80), point_at(104), point_at(128)],
        normals: None,
    };
    let _ = triangle::triangle(&tri, sep, e, s);
    let c = Cone {
        base: point_at(8),
        base_radius: r,
        apex: point_at(32),
        apex_radius: i64_at(152),
    };
    let _ = cone::capped(&c, sep, e, s);
    let t = Torus {
        centre: point_at(56),
        axis: [i32_at(160), i32_at(164), i32_at(168)],
        major: i64_at(172),
        minor: r,
    };
    let _ = torus::surface(&t, sep, e, s);
    let control = core::array::from_fn(|i| core::array::from_fn(|j| point_at(8 * (i + 4 * j))));
    let _ = patch::surface(&BezierPatch { control }, sep, e, s);
    // SAFETY: read-only use of a static no one writes.
    let samples: &[u16] = unsafe { &*addr_of!(SAMPLES) };
    let b = Block {
        samples,
        dims: [4, 4, 4],
        offset: point_at(180),
    };
    let _ = volume::boundary(
        &b,
        input::<2>(204).iter().map(|&x| u16::from(x)).sum(),
        sep,
        e,
        s,
    );
}

fn drive() {
    let Ok(e) = Extent::new(u32_at(0) % 32 + 1, u32_at(4) % 32 + 1, u32_at(8) % 16 + 1) else {
        return sink(1);
    };
    // SAFETY: the only references to these statics while `drive` runs.
    let (plane, dir, records, lists, objects) = unsafe {
        (
            &mut *addr_of_mut!(PLANE),
            &mut *addr_of_mut!(DIR),
            &mut *addr_of_mut!(RECORDS),
            &mut *addr_of_mut!(LISTS),
            &mut *addr_of_mut!(OBJECTS),
        )
    };
    let n = e.len().min(plane.len());
    let Ok(raster) = RasterMut::new(e, &mut plane[..n]) else {
        return sink(2);
    };
    let d = rrt_core::store::directory_len(e)
        .unwrap_or(0)
        .min(dir.len());
    let Ok(mut counter) = Counter::new(raster, &mut dir[..d]) else {
        return sink(3);
    };
    scene(e, &mut counter);
    let leaves: [&dyn Solid; 2] = [
        &Sphere {
            centre: point_at(8),
            radius: i64_at(0),
        },
        &Cuboid {
            min: point_at(32),
            max: point_at(56),
        },
    ];
    let nodes = [
        CsgNode::Leaf(0),
        CsgNode::Leaf(1),
        CsgNode::Difference(0, 1),
    ];
    let tree = CsgTree::new(&nodes, &leaves);
    if let Ok(t) = tree {
        sink(csg::voxelize(&t, e, &mut IgnoreLeaf(&mut counter)).voxels);
    }
    let Ok(sizing) = counter.finish() else {
        return sink(4);
    };
    let limits = Limits {
        objects: 1,
        materials: 1,
    };
    let exact = input::<1>(201)[0];
    let filler = if exact & 1 == 0 {
        sizing.fill(records, limits)
    } else {
        sizing.fill_with_lists(records, lists, limits)
    };
    let Ok(mut filler) = filler else {
        return sink(5);
    };
    let _ = filler.begin_object(ObjectAttrs {
        object: 0,
        material: 0,
        color: input(210),
    });
    scene(e, &mut filler);
    let Ok(mut built) = filler.finish() else {
        return sink(6);
    };
    let mut table = ObjectTable::new(objects, &mut []);
    let _ = table.push(Object {
        shape: Shape::Sphere(Sphere {
            centre: point_at(8),
            radius: 9,
        }),
        material: 0,
    });
    let mut mats: Materials<1> = Materials::new();
    let _ = mats.push(Material {
        color: [u32_at(0); 3],
        kd: u32_at(4),
        ..Material::default()
    });
    let mut lights = Lights::new(u32_at(8));
    let _ = lights.push(Light {
        position: point_at(100),
        color: [u32_at(12); 3],
        intensity: u32_at(16),
    });
    let params = LightParams {
        exact_records: match exact >> 1 & 3 {
            0 => ExactRecords::Paper,
            1 => ExactRecords::Classify,
            _ => ExactRecords::Skip,
        },
        ..LightParams::default()
    };
    let (r, mut store) = built.split();
    if let Ok(rep) = illuminate(&r, &mut store, &table, &mats, &lights, &params) {
        sink(rep.visible);
    }
    let raster = built.raster();
    let store = built.store();
    let ray = DiscreteRay::new(e, point_at(20), [i32_at(44), i32_at(48), i32_at(52)]);
    if let Ok(Some(mut ray)) = ray
        && let Ok(Some(h)) = ray.first_hit(&raster, Connectivity::Adaptive)
    {
        let c = raster.plane().get(h.index).copied().unwrap_or(0);
        if let Some(rec) = store.get_hinted(h.voxel, c) {
            sink(u64::from(rec.illum[0]));
        }
    }
}
