// The traversal workload of `size-traversal`, which `size-packet` goes on
// from. Included with `include!` after `common.rs`.

include!("plane.rs");

/// What [`traverse`] hands on.
type Traversed = (
    Extent,
    Raster<'static>,
    Connectivity,
    DiscreteRay,
    DiscreteRay,
);

/// Rasters over the static plane (proximity flags set), a discrete ray
/// (`new` or `segment`) walked to each of its hits, walked again with a
/// caller's test and iterated voxel by voxel. Returns the extent, the
/// raster, the mode, the ray after its hits and its copy after the test
/// walk, for a firmware that goes on; `None` where the inputs end it.
fn traverse() -> Option<Traversed> {
    let Ok(extent) = Extent::new(u32_at(0), u32_at(4), u32_at(8)) else {
        sink(1);
        return None;
    };
    // SAFETY: the only reference to PLANE while `drive` runs.
    let plane: &mut [u8] = unsafe { &mut *addr_of_mut!(PLANE) };
    let len = (u32_at(12) as usize).min(plane.len());
    if let Ok(mut r) = RasterMut::new(extent, &mut plane[..len]) {
        flag_neighbourhood(&mut r);
    }
    let plane: &'static [u8] = plane;
    let Ok(raster) = Raster::new(extent, &plane[..len]) else {
        sink(2);
        return None;
    };
    let m = mode(input::<1>(16)[0]);
    let ray = match input::<1>(17)[0] & 1 {
        0 => DiscreteRay::new(extent, point_at(20), [i32_at(44), i32_at(48), i32_at(52)]),
        _ => DiscreteRay::segment(extent, point_at(20), point_at(56)),
    };
    let Ok(Some(mut ray)) = ray else {
        sink(3);
        return None;
    };
    while let Ok(Some(h)) = ray.first_hit(&raster, m) {
        sink(h.index as u64 ^ u64::from(h.steps));
    }
    let mut again = ray;
    if let Ok(WalkEnd::Hit) = again.walk(&raster, m, u32_at(80), |i, c| (i as u8 ^ c) & 3 == 0) {
        sink(again.hit().index as u64);
    }
    if let Ok(vs) = ray.voxels(&raster, m) {
        for v in vs {
            sink(v.index as u64);
        }
    }
    Some((extent, raster, m, ray, again))
}
