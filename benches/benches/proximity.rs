//! Proximity flags on a 512³ raster holding a few spheres: the whole-plane
//! separable dilation (`proximity::flag_neighbourhood`) against the pass
//! over the records (`store::flag_proximity`, 27 cell writes per record).
//! The builder keeps the faster one; the figures are in the store docs.
//!
//! The spheres are voxelized by a plain brute-force voxelizer in this file
//! (the voxelizers of `core/src/voxelize/` are another work item); only the
//! flag passes are timed.

use criterion::{Criterion, criterion_group, criterion_main};
use rrt_core::fixed::VOXEL;
use rrt_core::proximity::flag_neighbourhood;
use rrt_core::raster::{Extent, RasterMut};
use rrt_core::store::{Counter, Limits, ObjectAttrs, RecordStore, directory_len, flag_proximity};
use rrt_core::voxel::VoxelRecord;
use rrt_core::voxelize::{NORMAL_ONE, Surfel, VoxelSink};
use std::hint::black_box;

/// 26-separating sphere surface by brute force over its bounding box.
fn sphere(centre: [f64; 3], radius: f64, sink: &mut impl VoxelSink) {
    let lo = centre.map(|c| (c - radius - 2.0).floor().max(0.0) as u32);
    let hi = centre.map(|c| ((c + radius + 2.0).ceil() as u32).min(511));
    for z in lo[2]..=hi[2] {
        for y in lo[1]..=hi[1] {
            for x in lo[0]..=hi[0] {
                let p = [x, y, z].map(|c| c as f64 + 0.5);
                let d = [p[0] - centre[0], p[1] - centre[1], p[2] - centre[2]];
                let len = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
                if len == 0.0 {
                    continue;
                }
                let n = d.map(|c| c / len);
                let half = 0.5 * (n[0].abs() + n[1].abs() + n[2].abs());
                let dist = len - radius;
                if dist.abs() <= half {
                    sink.offer(
                        [x, y, z],
                        Surfel {
                            normal: n.map(|c| (c * f64::from(NORMAL_ONE)).round() as i32),
                            distance: (dist.abs() * VOXEL as f64) as u32,
                        },
                    );
                }
            }
        }
    }
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
