//! Test-only helpers: the seeded generator of the unit tests (the crate's
//! [`Rng`]), a sink that
//! records offers, shorthands over the real voxelizers and a scene builder
//! over `Vec` storage.

use std::collections::HashMap;
use std::vec;
use std::vec::Vec;

use crate::fixed::VOXEL;
use crate::geometry::{Sphere, Torus};
use crate::raster::{Extent, RasterMut};
use crate::store::{Counter, Limits, ObjectAttrs, directory_len};
use crate::voxel::VoxelRecord;
use crate::voxelize::{NORMAL_ONE, Separation, Surfel, VoxelSink};

pub use crate::rng::Rng;

/// A sink that records every voxel offered: how often, and the offer
/// nearest the surface (the first of equals).
#[derive(Default)]
pub struct Offers(pub HashMap<[u32; 3], (Surfel, u32)>);

impl VoxelSink for Offers {
    fn offer(&mut self, v: [u32; 3], s: Surfel) {
        let e = self.0.entry(v).or_insert((s, 0));
        e.1 += 1;
        if s.distance < e.0.distance {
            e.0 = s;
        }
    }
}

/// Sphere surface, through the real voxelizer.
pub fn sphere(
    extent: Extent,
    centre: [i64; 3],
    radius: i64,
    sep: Separation,
    sink: &mut dyn VoxelSink,
) {
    let s = Sphere { centre, radius };
    crate::voxelize::sphere::surface(&s, sep, extent, sink).expect("test sphere");
}

/// Torus around the z axis, through the real voxelizer.
pub fn torus(
    extent: Extent,
    centre: [i64; 3],
    major: i64,
    minor: i64,
    sep: Separation,
    sink: &mut dyn VoxelSink,
) {
    let t = Torus {
        centre,
        axis: [0, 0, NORMAL_ONE],
        major,
        minor,
    };
    crate::voxelize::torus::surface(&t, sep, extent, sink).expect("test torus");
}

/// An axis-aligned rectangle `z = z0` spanning the given voxel ranges in x
/// and y, normal `+z` (or `−z` with `down`), through the real polygon
/// voxelizer.
pub fn plate(
    extent: Extent,
    z0: i64,
    xs: core::ops::Range<u32>,
    ys: core::ops::Range<u32>,
    down: bool,
    sep: Separation,
    sink: &mut dyn VoxelSink,
) {
    let (x0, x1) = (i64::from(xs.start) * VOXEL, i64::from(xs.end) * VOXEL);
    let (y0, y1) = (i64::from(ys.start) * VOXEL, i64::from(ys.end) * VOXEL);
    // Counter-clockwise seen from +z: normal +z.
    let mut v = [[x0, y0, z0], [x1, y0, z0], [x1, y1, z0], [x0, y1, z0]];
    if down {
        v.reverse();
    }
    crate::voxelize::triangle::polygon(&v, sep, extent, sink).expect("test plate");
}

/// A built scene over owned storage.
pub struct Scene {
    pub extent: Extent,
    pub plane: Vec<u8>,
    pub dir: Vec<u32>,
    pub records: Vec<VoxelRecord>,
    pub lists: Vec<u32>,
}

impl Scene {
    /// The built store.
    pub fn store(&self) -> crate::store::RecordStore<'_> {
        crate::store::RecordStore::with_lists(self.extent, &self.dir, &self.records, &self.lists)
            .expect("built store")
    }
}

/// One object to build: its attributes and its voxelizer.
pub type Voxelize<'a> = (ObjectAttrs, &'a dyn Fn(&mut dyn VoxelSink));

/// Runs both passes over `objects`.
pub fn build(extent: Extent, objects: &[Voxelize<'_>], limits: Limits) -> Scene {
    let mut plane = vec![0u8; extent.len()];
    let mut dir = vec![0u32; directory_len(extent).unwrap()];
    let mut counter = Counter::new(RasterMut::new(extent, &mut plane).unwrap(), &mut dir).unwrap();
    for (_, f) in objects {
        f(&mut counter);
    }
    let sizing = counter.finish().unwrap();
    let mut records = vec![VoxelRecord::default(); sizing.records()];
    let mut lists = vec![0u32; sizing.list_entries()];
    let mut filler = sizing
        .fill_with_lists(&mut records, &mut lists, limits)
        .unwrap();
    for (attrs, f) in objects {
        filler.begin_object(*attrs).unwrap();
        f(&mut filler);
    }
    let used = filler.finish().unwrap().lists().len();
    lists.truncate(used);
    Scene {
        extent,
        plane,
        dir,
        records,
        lists,
    }
}
