//! The voxel record's layout and the octahedral normal's angular error in
//! degrees (the core measures the same in integers, see `voxel.rs`).

use rrt_core::voxel::{VoxelRecord, decode_normal, encode_normal};
use rrt_core::voxelize::NORMAL_ONE;
use rrt_tests::Rng;
use std::mem::{align_of, offset_of, size_of};

#[test]
fn record_is_20_bytes_without_padding() {
    assert_eq!(size_of::<VoxelRecord>(), 20);
    assert_eq!(align_of::<VoxelRecord>(), 4);
    let offsets = [
        offset_of!(VoxelRecord, object),
        offset_of!(VoxelRecord, normal),
        offset_of!(VoxelRecord, color),
        offset_of!(VoxelRecord, illum),
        offset_of!(VoxelRecord, lights),
        offset_of!(VoxelRecord, material),
        offset_of!(VoxelRecord, key),
    ];
    assert_eq!(offsets, [0, 4, 8, 11, 14, 16, 18]);
    // The bytemuck byte view (field by field) is tested beside the type,
    // in `core/src/voxel.rs`.
}

fn to_fixed(v: [f64; 3]) -> [i32; 3] {
    v.map(|c| (c * f64::from(NORMAL_ONE)).round() as i32)
}

fn angle_deg(a: [f64; 3], b: [i32; 3]) -> f64 {
    let b = b.map(f64::from);
    let lb = (b[0] * b[0] + b[1] * b[1] + b[2] * b[2]).sqrt();
    let dot = (a[0] * b[0] + a[1] * b[1] + a[2] * b[2]) / lb;
    let cross = [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ];
    let c = (cross[0] * cross[0] + cross[1] * cross[1] + cross[2] * cross[2]).sqrt() / lb;
    c.atan2(dot).to_degrees()
}

#[test]
fn octahedral_error_in_degrees() {
    let mut rng = Rng::new(2024);
    let mut worst = 0.0f64;
    let mut sum = 0.0;
    let n = 1_000_000;
    let mut done = 0;
    while done < n {
        let v = [0; 3].map(|_| rng.next_u64() as f64 / u64::MAX as f64 * 2.0 - 1.0);
        let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        if !(1e-3..=1.0).contains(&l) {
            continue;
        }
        let u = v.map(|c| c / l);
        let e = angle_deg(u, decode_normal(encode_normal(to_fixed(u))));
        worst = worst.max(e);
        sum += e;
        done += 1;
    }
    // The diagonal is the worst case of the octahedral map.
    let d = 1.0 / 3f64.sqrt();
    let diag = angle_deg([d; 3], decode_normal(encode_normal(to_fixed([d; 3]))));
    println!(
        "octahedral snorm16: worst {worst:.6}° over {n} random normals, mean {:.6}°, diagonal {diag:.6}°",
        sum / f64::from(n)
    );
    assert!(worst.max(diag) < 0.003, "worst {worst}° diag {diag}°");
}
