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
use crate::voxelize::error::VoxelizeError;
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

/// A voxelizer's entry point, over the recording sink.
pub type Voxelizer<T> = fn(&T, Separation, Extent, &mut Offers) -> Result<u64, VoxelizeError>;

/// What `voxelize` makes of `shape` with `sep` in `extent`: its result and
/// the offers.
pub fn voxelized<T>(
    voxelize: Voxelizer<T>,
    shape: &T,
    sep: Separation,
    extent: Extent,
) -> (Result<u64, VoxelizeError>, Offers) {
    let mut offers = Offers::default();
    let r = voxelize(shape, sep, extent, &mut offers);
    (r, offers)
}

/// What `voxelize` makes of `shape` with `sep` in a 4³ raster.
pub fn voxelized_in_4<T>(
    voxelize: Voxelizer<T>,
    shape: &T,
    sep: Separation,
) -> Result<u64, VoxelizeError> {
    voxelized(voxelize, shape, sep, Extent::cube(4).unwrap()).0
}

/// `voxelize` refuses `shape` (6-separating, in a 4³ raster) with `want`.
#[track_caller]
pub fn assert_refused<T>(voxelize: Voxelizer<T>, shape: &T, want: VoxelizeError) {
    assert_eq!(voxelized_in_4(voxelize, shape, Separation::Six), Err(want));
}

/// `offers` are the voxels of `e` that `contains` accepts, each offered
/// once; `what` names the case.
#[track_caller]
pub fn assert_offers_are(
    offers: &Offers,
    e: Extent,
    contains: impl Fn([u32; 3]) -> bool,
    what: &str,
) {
    assert!(offers.0.values().all(|o| o.1 == 1), "{what}: offered twice");
    let [nx, ny, nz] = e.dims();
    let mut want = Vec::new();
    for z in 0..nz {
        for y in 0..ny {
            for x in 0..nx {
                if contains([x, y, z]) {
                    want.push([x, y, z]);
                }
            }
        }
    }
    for v in &want {
        assert!(offers.0.contains_key(v), "{what}: missing {v:?}");
    }
    assert_eq!(offers.0.len(), want.len(), "{what}: extra voxels");
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

/// [`sphere`], 6-separating, as a voxelizer for [`build`].
pub fn ball(extent: Extent, centre: [i64; 3], radius: i64) -> impl Fn(&mut dyn VoxelSink) {
    move |s| sphere(extent, centre, radius, Separation::Six, s)
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

/// [`plate`] facing up (`+z`), 6-separating, over the voxels `span × span`
/// at the mid-height of voxel layer `layer`, as a voxelizer for [`build`].
pub fn level_plate(
    extent: Extent,
    layer: i64,
    span: core::ops::Range<u32>,
) -> impl Fn(&mut dyn VoxelSink) {
    let z0 = layer * VOXEL + VOXEL / 2;
    move |s| {
        plate(
            extent,
            z0,
            span.clone(),
            span.clone(),
            false,
            Separation::Six,
            s,
        )
    }
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
