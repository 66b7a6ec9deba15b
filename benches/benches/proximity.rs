//! Proximity flags on a 512³ raster holding a few spheres: the whole-plane
//! separable dilation (`proximity::flag_neighbourhood`) against the pass
//! over the records (`store::flag_proximity`, 27 cell writes per record).
//! The builder keeps the faster one; the figures are in the store docs.
//!
//! Only the flag passes are timed.

use criterion::{Criterion, criterion_group, criterion_main};
use rrt_core::fixed::VOXEL;
use rrt_core::geometry::Sphere;
use rrt_core::proximity::flag_neighbourhood;
use rrt_core::raster::{Extent, RasterMut};
use rrt_core::store::{Counter, Limits, ObjectAttrs, RecordStore, directory_len, flag_proximity};
use rrt_core::voxel::VoxelRecord;
use rrt_core::voxelize::{Separation, VoxelSink};
use std::hint::black_box;

/// A 26-separating sphere surface through the real voxelizer.
fn sphere(centre: [f64; 3], radius: f64, sink: &mut impl VoxelSink) {
    let fx = |v: f64| (v * VOXEL as f64).round() as i64;
    let s = Sphere {
        centre: centre.map(fx),
        radius: fx(radius),
    };
    rrt_core::voxelize::sphere::surface(
        &s,
        Separation::TwentySix,
        Extent::cube(512).unwrap(),
        sink,
    )
    .unwrap();
}

const SPHERES: [([f64; 3], f64); 4] = [
    ([160.0, 160.0, 160.0], 60.0),
    ([350.0, 180.0, 300.0], 80.0),
    ([256.0, 380.0, 120.0], 40.0),
    ([120.0, 400.0, 400.0], 70.0),
];

fn bench(c: &mut Criterion) {
    let e = Extent::cube(512).unwrap();
    let mut plane = vec![0u8; e.len()];
    let mut dir = vec![0u32; directory_len(e).unwrap()];
    let mut counter = Counter::new(RasterMut::new(e, &mut plane).unwrap(), &mut dir).unwrap();
    for (c, r) in SPHERES {
        sphere(c, r, &mut counter);
    }
    let sizing = counter.finish().unwrap();
    let mut records = vec![VoxelRecord::default(); sizing.records()];
    let mut filler = sizing
        .fill(
            &mut records,
            Limits {
                objects: 4,
                materials: 1,
            },
        )
        .unwrap();
    for (i, (c, r)) in SPHERES.into_iter().enumerate() {
        filler
            .begin_object(ObjectAttrs {
                object: i as u32,
                material: 0,
                color: [255; 3],
            })
            .unwrap();
        sphere(c, r, &mut filler);
    }
    filler.finish().unwrap();
    println!(
        "512^3 raster, {} spheres, {} records ({:.2}% of the voxels)",
        SPHERES.len(),
        records.len(),
        100.0 * records.len() as f64 / e.len() as f64,
    );
    let store = RecordStore::new(e, &dir, &records).unwrap();
    // Both passes give the same flags.
    let mut a = plane.clone();
    flag_neighbourhood(&mut RasterMut::new(e, &mut a).unwrap());
    assert_eq!(
        a, plane,
        "the builder's flags differ from the whole-plane dilation"
    );
    drop(a);

    let mut g = c.benchmark_group("proximity_512");
    g.sample_size(10);
    g.bench_function("flag_neighbourhood (whole plane)", |b| {
        b.iter(|| flag_neighbourhood(&mut RasterMut::new(e, black_box(&mut plane)).unwrap()))
    });
    g.bench_function("flag_proximity (per record)", |b| {
        b.iter(|| {
            flag_proximity(
                &mut RasterMut::new(e, black_box(&mut plane)).unwrap(),
                &store,
            )
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
