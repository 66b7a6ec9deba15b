//! Unit tests of the record store and the two-pass builder.

use core::ops::Range;
use std::collections::HashMap;
use std::format;
use std::vec;
use std::vec::Vec;

use super::brick::{brick_of, brick_origin, voxel_at};
use super::rank_hint::{HINT_SCALE, hint_window};
use super::*;
use crate::proximity::flag_neighbourhood;
use crate::raster::{Extent, RasterMut, cell};
use crate::testkit::Rng;
use crate::voxel::{VoxelRecord, brick_position};
use crate::voxelize::NORMAL_ONE;
use crate::voxelize::{Surfel, VoxelSink};

const UP: [i32; 3] = [0, 0, NORMAL_ONE];

fn surfel(distance: u32) -> Surfel {
    Surfel {
        normal: UP,
        distance,
    }
}

/// A scripted "voxelizer": a fixed list of offers per object.
type Script = Vec<Vec<([u32; 3], u32)>>;

fn random_script(extent: Extent, objects: usize, offers: usize, seed: u64) -> Script {
    let mut rng = Rng(seed);
    let [nx, ny, nz] = extent.dims();
    (0..objects)
        .map(|_| {
            (0..offers)
                .map(|_| {
                    (
                        [rng.below_u32(nx), rng.below_u32(ny), rng.below_u32(nz)],
                        rng.below_u32(1 << 16),
                    )
                })
                .collect()
        })
        .collect()
}

struct Scene {
    plane: Vec<u8>,
    dir: Vec<u32>,
    records: Vec<VoxelRecord>,
    lists: Vec<u32>,
    count: CountReport,
    fill: FillReport,
}

impl Scene {
    fn store(&self, extent: Extent) -> RecordStore<'_> {
        RecordStore::with_lists(extent, &self.dir, &self.records, &self.lists)
            .unwrap_or_else(|e| panic!("built store invalid: {e}"))
    }
}

fn build(extent: Extent, script: &Script) -> Result<Scene, BuildError> {
    build_with(extent, script, None)
}

/// [`build`] with `list_storage` entries of list storage (default: the
/// count pass's bound).
fn build_with(
    extent: Extent,
    script: &Script,
    list_storage: Option<usize>,
) -> Result<Scene, BuildError> {
    let mut plane = vec![0u8; extent.len()];
    let mut dir = vec![0u32; directory_len(extent).unwrap()];
    let mut counter = Counter::new(RasterMut::new(extent, &mut plane).unwrap(), &mut dir)?;
    for obj in script {
        for &(v, d) in obj {
            counter.offer(v, surfel(d));
        }
    }
    let count = counter.report();
    let sizing = counter.finish()?;
    assert_eq!(sizing.records() as u64, count.voxels);
    let mut records = vec![VoxelRecord::default(); sizing.records()];
    let mut lists = vec![0u32; list_storage.unwrap_or(sizing.list_entries())];
    let limits = Limits {
        objects: script.len() as u32,
        materials: 1,
    };
    let mut filler = sizing.fill_with_lists(&mut records, &mut lists, limits)?;
    for (id, obj) in script.iter().enumerate() {
        filler.begin_object(ObjectAttrs {
            object: id as u32,
            material: 0,
            color: [id as u8, 0, 0],
        })?;
        for &(v, d) in obj {
            filler.offer(v, surfel(d));
        }
    }
    let built = filler.finish()?;
    let fill = built.report();
    let used = built.lists().len();
    assert_eq!(used as u64, fill.list_entries);
    lists.truncate(used);
    Ok(Scene {
        plane,
        dir,
        records,
        lists,
        count,
        fill,
    })
}

/// The expected owner of every voxel: smallest quantized distance, first
/// offer on ties.
fn brute_force(script: &Script) -> HashMap<[u32; 3], (u32, u16)> {
    let mut m: HashMap<[u32; 3], (u32, u16)> = HashMap::new();
    for (id, obj) in script.iter().enumerate() {
        for &(v, d) in obj {
            let q = crate::voxel::quantize_distance(d);
            match m.get(&v) {
                Some(&(_, old)) if old <= q => {}
                _ => {
                    m.insert(v, (id as u32, q));
                }
            }
        }
    }
    m
}

#[test]
fn geometry_of_bricks() {
    let e = Extent::new(17, 8, 1).unwrap();
    assert_eq!(brick_dims(e), [3, 1, 1]);
    assert_eq!(brick_count(e), Some(3));
    assert_eq!(directory_len(e), Some(4));
    assert_eq!(brick_of(e, [16, 7, 0]), 2);
    assert_eq!(brick_origin(e, 2), Some([16, 0, 0]));
    let e = Extent::new(20, 20, 20).unwrap();
    assert_eq!(brick_of(e, [9, 17, 8]), 1 + 3 * (2 + 3));
    assert_eq!(brick_origin(e, 1 + 3 * (2 + 3)), Some([8, 16, 8]));
    assert_eq!(voxel_at([8, 16, 8], brick_position([9, 17, 8])), [9, 17, 8]);
}

/// A random extent of 1 to `max` voxels along each axis.
fn random_extent(rng: &mut Rng, max: u32) -> Extent {
    Extent::new(
        1 + rng.below_u32(max),
        1 + rng.below_u32(max),
        1 + rng.below_u32(max),
    )
    .unwrap()
}

#[test]
fn lookups_match_brute_force_on_random_sparse_rasters() {
    for seed in 0..20u64 {
        let mut rng = Rng(seed);
        let extent = random_extent(&mut rng, 40);
        let objects = 1 + rng.below_u32(4) as usize;
        let offers = rng.below_u32(3000) as usize;
        let script = random_script(extent, objects, offers, seed.wrapping_mul(77));
        let scene = build(extent, &script).unwrap_or_else(|e| panic!("seed {seed}: {e}"));
        let expect = brute_force(&script);
        assert_eq!(scene.count.voxels as usize, expect.len(), "seed {seed}");
        assert_eq!(scene.fill.records as usize, expect.len(), "seed {seed}");
        assert_eq!(scene.records.len(), expect.len(), "seed {seed}");
        let store = scene.store(extent);
        for i in 0..extent.len() {
            let v = extent.coord(i).unwrap();
            let got = store.get(i);
            let opaque = scene.plane[i] & cell::OPAQUE != 0;
            match expect.get(&v) {
                Some(&(owner, q)) => {
                    let r = got.unwrap_or_else(|| panic!("seed {seed}: {v:?} has no record"));
                    assert_eq!(store.owner(r), owner, "seed {seed}: owner of {v:?}");
                    assert_eq!(r.distance(), q, "seed {seed}: distance of {v:?}");
                    assert_eq!(r.color, [owner as u8, 0, 0]);
                    assert!(opaque);
                }
                None => {
                    assert!(got.is_none(), "seed {seed}: {v:?} should be transparent");
                    assert!(!opaque);
                }
            }
        }
        assert!(store.get(extent.len()).is_none());
        // iter() yields every record once, with its coordinates.
        let listed: Vec<_> = store.iter().map(|(v, r)| (v, store.owner(r))).collect();
        assert_eq!(listed.len(), expect.len());
        for (v, o) in listed {
            assert_eq!(expect[&v].0, o);
        }
        // iter_from(k) is iter() from the k-th record on, for any k.
        let all: Vec<_> = store.iter().collect();
        for k in (0..=all.len() + 1).step_by(1 + all.len() / 37) {
            let from: Vec<_> = store.iter_from(k).collect();
            assert_eq!(from, all.get(k..).unwrap_or(&[]), "seed {seed}: from {k}");
        }
    }
}

#[test]
fn overlapping_objects_keep_the_nearest_in_either_order() {
    let e = Extent::cube(8).unwrap();
    let near = 100u32; // quantizes to 0
    let far = 40_000u32; // quantizes to 78
    for order in [[near, far], [far, near]] {
        let script: Script = vec![vec![([3, 3, 3], order[0])], vec![([3, 3, 3], order[1])]];
        let s = build(e, &script).unwrap();
        let store = s.store(e);
        let r = store.get_voxel([3, 3, 3]).unwrap();
        let want = if order[0] == near { 0 } else { 1 };
        assert_eq!(store.owner(r), want, "order {order:?}");
        assert_eq!(store.objects(r), [want, 1 - want], "order {order:?}");
        assert_eq!(s.records.len(), 1);
        assert_eq!(s.fill.replaced + s.fill.kept, 1);
    }
    // Ties keep the first offer.
    let script: Script = vec![vec![([1, 2, 3], 5)], vec![([1, 2, 3], 5)]];
    let s = build(e, &script).unwrap();
    assert_eq!(s.store(e).owner(&s.records[0]), 0);
    assert_eq!(s.fill.kept, 1);
}

#[test]
fn same_object_repeat_offers_keep_the_nearest() {
    let e = Extent::cube(16).unwrap();
    let script: Script = vec![vec![
        ([9, 9, 9], 30_000),
        ([8, 9, 9], 1_000),
        ([9, 9, 9], 2_000),
        ([9, 9, 9], 20_000),
    ]];
    let s = build(e, &script).unwrap();
    let store = s.store(e);
    assert_eq!(store.get_voxel([9, 9, 9]).unwrap().distance(), 4);
    assert_eq!(s.fill.replaced, 1);
    assert_eq!(s.fill.kept, 1);
}

#[test]
fn offers_outside_the_raster_are_skipped_and_counted() {
    let e = Extent::new(10, 9, 8).unwrap();
    let script: Script = vec![vec![
        ([10, 0, 0], 0),
        ([0, 9, 0], 0),
        ([u32::MAX; 3], 0),
        ([9, 8, 7], 0),
    ]];
    let s = build(e, &script).unwrap();
    assert_eq!(s.count.outside, 3);
    assert_eq!(s.fill.outside, 3);
    assert_eq!(s.records.len(), 1);
}

#[test]
fn textured_fill_colours_from_centre_and_normal() {
    let e = Extent::cube(8).unwrap();
    let mut plane = vec![0u8; e.len()];
    let mut dir = vec![0u32; directory_len(e).unwrap()];
    let mut c = Counter::new(RasterMut::new(e, &mut plane).unwrap(), &mut dir).unwrap();
    for x in 0..8 {
        c.offer([x, 0, 0], surfel(0));
    }
    let sizing = c.finish().unwrap();
    let mut recs = vec![VoxelRecord::default(); 8];
    let mut f = sizing
        .fill(
            &mut recs,
            Limits {
                objects: 1,
                materials: 1,
            },
        )
        .unwrap();
    f.begin_object(ObjectAttrs::default()).unwrap();
    let checker = |p: [i64; 3], n: [i32; 3], base: [u8; 3]| {
        let x = (p[0] >> crate::fixed::FRAC_BITS) as u8;
        [x * 10, base[1], (n[2] >> 24) as u8]
    };
    {
        let mut t = f.textured(&checker);
        for x in 0..8 {
            t.offer([x, 0, 0], surfel(0));
        }
    }
    let built = f.finish().unwrap();
    let store = built.store();
    for x in 0..8u32 {
        assert_eq!(
            store.get_voxel([x, 0, 0]).unwrap().color,
            [x as u8 * 10, 0, 64]
        );
    }
}

#[test]
fn build_errors() {
    let e = Extent::cube(16).unwrap();
    let mut plane = vec![0u8; e.len()];
    // Wrong directory length.
    let mut short = vec![0u32; 8];
    assert_eq!(
        Counter::new(RasterMut::new(e, &mut plane).unwrap(), &mut short).unwrap_err(),
        BuildError::DirectoryLength {
            expected: 9,
            found: 8
        }
    );
    let mut dir = vec![0u32; 9];
    let counted = |plane: &mut Vec<u8>, dir: &mut Vec<u32>| {
        let mut c =
            Counter::new(RasterMut::new(e, slice_of(plane)).unwrap(), slice_of(dir)).unwrap();
        c.offer([1, 1, 1], surfel(0));
        c.offer([9, 1, 1], surfel(0));
        c.finish().unwrap().records()
    };
    assert_eq!(counted(&mut plane, &mut dir), 2);

    // Record storage too small.
    let mut c = Counter::new(RasterMut::new(e, &mut plane).unwrap(), &mut dir).unwrap();
    c.offer([1, 1, 1], surfel(0));
    c.offer([9, 1, 1], surfel(0));
    let mut one = vec![VoxelRecord::default(); 1];
    let lim = Limits {
        objects: 2,
        materials: 3,
    };
    assert_eq!(
        c.finish().unwrap().fill(&mut one, lim).unwrap_err(),
        BuildError::RecordStorage {
            needed: 2,
            found: 1
        }
    );

    // Object and material out of range; offers without an object; extra
    // voxels; missing voxels.
    let mut recs = vec![VoxelRecord::default(); 4];
    fn start<'p, 'd>(e: Extent, plane: &'p mut [u8], dir: &'d mut [u32]) -> Sizing<'p, 'd> {
        let mut c = Counter::new(RasterMut::new(e, plane).unwrap(), dir).unwrap();
        c.offer([1, 1, 1], surfel(0));
        c.offer([9, 1, 1], surfel(0));
        c.finish().unwrap()
    }
    let mut f = start(e, &mut plane, &mut dir).fill(&mut recs, lim).unwrap();
    let attrs = ObjectAttrs {
        object: 2,
        material: 0,
        color: [0; 3],
    };
    assert_eq!(
        f.begin_object(attrs).unwrap_err(),
        BuildError::ObjectOutOfRange {
            object: 2,
            limit: 2
        }
    );
    assert_eq!(
        f.begin_object(ObjectAttrs {
            object: 1,
            material: 3,
            ..attrs
        })
        .unwrap_err(),
        BuildError::MaterialOutOfRange {
            material: 3,
            limit: 3
        }
    );
    f.offer([1, 1, 1], surfel(0));
    assert_eq!(
        f.finish().unwrap_err(),
        BuildError::OfferWithoutObject { offers: 1 }
    );

    // Object 1 offers an extra voxel, or misses one.
    for (offered, want) in [
        (
            &[[1, 1, 1], [9, 1, 1], [2, 1, 1]][..],
            BuildError::PassMismatch { uncounted: 1 },
        ),
        (
            &[[1, 1, 1]][..],
            BuildError::FillIncomplete {
                filled: 1,
                expected: 2,
            },
        ),
    ] {
        let mut f = start(e, &mut plane, &mut dir).fill(&mut recs, lim).unwrap();
        f.begin_object(ObjectAttrs { object: 1, ..attrs }).unwrap();
        for &v in offered {
            f.offer(v, surfel(0));
        }
        assert_eq!(f.finish().unwrap_err(), want);
    }
}

/// Identity helper: reborrows a `Vec` as a slice (keeps the closures above
/// short).
fn slice_of<T>(v: &mut Vec<T>) -> &mut [T] {
    v.as_mut_slice()
}

#[test]
fn corrupt_directories_are_rejected() {
    let e = Extent::new(16, 8, 8).unwrap(); // 2 bricks
    let r = |pos: u16| VoxelRecord {
        key: pos,
        ..VoxelRecord::default()
    };
    let recs = [r(1), r(7), r(3)];
    assert!(RecordStore::new(e, &[0, 2, 3], &recs).is_ok());
    assert_eq!(
        RecordStore::new(e, &[0, 2], &recs).unwrap_err(),
        StoreError::DirectoryLength {
            expected: 3,
            found: 2
        }
    );
    assert_eq!(
        RecordStore::new(e, &[1, 2, 3], &recs).unwrap_err(),
        StoreError::DirectoryStart
    );
    assert_eq!(
        RecordStore::new(e, &[0, 2, 4], &recs).unwrap_err(),
        StoreError::DirectoryEnd {
            last: 4,
            records: 3
        }
    );
    assert_eq!(
        RecordStore::new(e, &[0, 4, 3], &recs).unwrap_err(),
        StoreError::DirectoryOrder { brick: 0 }
    );
    // Unsorted inside a brick.
    let bad = [r(7), r(1), r(3)];
    assert_eq!(
        RecordStore::new(e, &[0, 2, 3], &bad).unwrap_err(),
        StoreError::BadKey { record: 1 }
    );
    // Repeated position.
    let dup = [r(1), r(1), r(3)];
    assert_eq!(
        RecordStore::new(e, &[0, 2, 3], &dup).unwrap_err(),
        StoreError::BadKey { record: 1 }
    );
    // A position outside a partial brick.
    let e2 = Extent::new(10, 8, 8).unwrap(); // second brick is 2 wide
    let outside = [r(1), r(2)]; // x = 8 + 2 = 10: outside
    assert_eq!(
        RecordStore::new(e2, &[0, 1, 2], &outside).unwrap_err(),
        StoreError::BadKey { record: 1 }
    );
    // A brick claiming more records than it has voxels.
    let many = vec![VoxelRecord::default(); 513];
    let e3 = Extent::cube(8).unwrap();
    assert_eq!(
        RecordStore::new(e3, &[0, 513], &many).unwrap_err(),
        StoreError::DirectoryOrder { brick: 0 }
    );
    // Random corruption never panics and never validates a wrong store.
    let script = random_script(e, 2, 200, 5);
    let s = build(e, &script).unwrap();
    let mut rng = Rng(9);
    for _ in 0..2000 {
        let mut dir = s.dir.clone();
        let mut recs = s.records.clone();
        match rng.below_u32(3) {
            0 => {
                let i = rng.below_u32(dir.len() as u32) as usize;
                dir[i] = rng.below_u32(400);
            }
            1 => {
                if !recs.is_empty() {
                    let i = rng.below_u32(recs.len() as u32) as usize;
                    recs[i].key = rng.below_u32(1 << 16) as u16;
                }
            }
            _ => {
                recs.truncate(rng.below_u32(recs.len() as u32 + 1) as usize);
            }
        }
        if let Ok(st) = RecordStore::new(e, &dir, &recs) {
            for i in 0..e.len() {
                let _ = st.get(i);
            }
        }
    }
}

#[test]
fn proximity_after_build_is_the_26_neighbourhood() {
    for seed in 0..12u64 {
        let mut rng = Rng(seed + 100);
        let extent = random_extent(&mut rng, 30);
        // Even seeds sparse (per-record pass), odd seeds dense (whole plane).
        let offers = if seed % 2 == 0 {
            rng.below_u32(200) as usize
        } else {
            extent.len() / 2
        };
        let script = random_script(extent, 2, offers, seed);
        let dense = script.iter().flatten().count() * DENSE_RATIO > extent.len();
        let s = build(extent, &script).unwrap();
        if seed % 2 == 1 {
            assert!(dense && s.records.len() * DENSE_RATIO > extent.len());
        }
        // Reference: the whole-plane dilation on the OPAQUE bits alone.
        let mut reference: Vec<u8> = s.plane.iter().map(|c| c & cell::OPAQUE).collect();
        flag_neighbourhood(&mut RasterMut::new(extent, &mut reference).unwrap());
        // Opaque cells carry their rank hints, transparent ones distance 0.
        let flags: Vec<u8> = s
            .plane
            .iter()
            .map(|c| c & (cell::OPAQUE | cell::PROXIMITY))
            .collect();
        assert_eq!(flags, reference, "seed {seed}");
        assert!(
            s.plane
                .iter()
                .all(|c| c & cell::OPAQUE != 0 || c >> cell::DISTANCE_SHIFT == 0),
            "seed {seed}"
        );
        // And the definition: chessboard distance <= 1 from an opaque voxel.
        let [nx, ny, nz] = extent.dims().map(i64::from);
        for i in 0..extent.len() {
            let v = extent.coord(i).unwrap().map(i64::from);
            let mut near = false;
            for dz in -1..=1 {
                for dy in -1..=1 {
                    for dx in -1..=1 {
                        let w = [v[0] + dx, v[1] + dy, v[2] + dz];
                        if w.iter().zip([nx, ny, nz]).all(|(c, n)| (0..n).contains(c)) {
                            let j = extent.index(w.map(|c| c as u32)).unwrap();
                            near |= s.plane[j] & cell::OPAQUE != 0;
                        }
                    }
                }
            }
            assert_eq!(
                s.plane[i] & cell::PROXIMITY != 0,
                near,
                "seed {seed} voxel {v:?}"
            );
        }
    }
}

#[test]
fn store_mut_updates_in_place() {
    let e = Extent::cube(8).unwrap();
    let script: Script = vec![vec![([1, 2, 3], 0), ([4, 4, 4], 0)]];
    let mut s = build(e, &script).unwrap();
    let mut st = RecordStoreMut::new(e, &s.dir, &mut s.records).unwrap();
    st.get_voxel_mut([4, 4, 4]).unwrap().illum = [1, 2, 3];
    assert!(st.get_voxel_mut([4, 4, 5]).is_none());
    assert_eq!(st.as_store().get_voxel([4, 4, 4]).unwrap().illum, [1, 2, 3]);
}

/// With rank hints written, hinted lookups find every record through its
/// window (checked by counting window hits); with any other cell contents
/// (stale, made up, transparent) they still give `get_voxel`'s answer.
#[test]
fn hinted_lookups_are_plain_lookups() {
    for seed in 0..12u64 {
        let mut rng = Rng(seed ^ 0xabcd);
        let extent = random_extent(&mut rng, 40);
        // Dense enough that bricks hold well over 64 records.
        let offers = rng.below_u32(40_000) as usize;
        let script = random_script(extent, 2, offers, seed.wrapping_mul(31));
        let mut scene = build(extent, &script).unwrap();
        let store =
            RecordStore::with_lists(extent, &scene.dir, &scene.records, &scene.lists).unwrap();
        write_rank_hints(
            &mut RasterMut::new(extent, &mut scene.plane).unwrap(),
            &store,
        );
        let mut in_window = 0usize;
        for i in 0..extent.len() {
            let v = extent.coord(i).unwrap();
            let c = scene.plane[i];
            let plain = store.get_voxel(v);
            assert_eq!(store.get_hinted(v, c), plain, "seed {seed}: {v:?}");
            if let (Some(h), Some(r)) = (cell_hint(c), plain) {
                let b = brick_of(extent, v);
                let lo = scene.dir[b] as usize;
                let n = scene.dir[b + 1] as usize - lo;
                let rank = (r as *const VoxelRecord as usize - scene.records.as_ptr() as usize)
                    / core::mem::size_of::<VoxelRecord>()
                    - lo;
                let (from, to) = hint_window(h, n);
                assert!(
                    (from..to).contains(&rank),
                    "seed {seed}: rank {rank} of {n}, hint {h}"
                );
                assert!(to - from <= n.div_ceil(HINT_SCALE) + 1);
                in_window += 1;
            }
            for junk in [0u8, 0xff, cell::OPAQUE, rng.below_u32(256) as u8] {
                assert_eq!(
                    store.get_hinted(v, junk),
                    plain,
                    "seed {seed}: {v:?} {junk:#x}"
                );
            }
        }
        assert_eq!(in_window, scene.records.len());
    }
}

/// Every object that offered each voxel, by brute force.
fn offering_objects(script: &Script) -> HashMap<[u32; 3], Vec<u32>> {
    let mut m: HashMap<[u32; 3], Vec<u32>> = HashMap::new();
    for (id, obj) in script.iter().enumerate() {
        for &(v, _) in obj {
            let l = m.entry(v).or_default();
            if !l.contains(&(id as u32)) {
                l.push(id as u32);
            }
        }
    }
    m
}

#[test]
fn object_lists_hold_every_offering_object_once_owner_first() {
    for seed in 0..40u64 {
        let mut rng = Rng(seed ^ 0x5eed);
        let extent = random_extent(&mut rng, 24);
        let objects = 1 + rng.below_u32(7) as usize;
        let offers = rng.below_u32(4000) as usize;
        let mut script = random_script(extent, objects, offers, seed.wrapping_mul(91));
        // Same-object repeats too: each object offers a part of its voxels again.
        for obj in script.iter_mut() {
            let again: Vec<_> = obj.iter().step_by(3).map(|&(v, d)| (v, d / 2)).collect();
            obj.extend(again);
        }
        let s = build(extent, &script).unwrap_or_else(|e| panic!("seed {seed}: {e}"));
        let store = s.store(extent);
        let owners = brute_force(&script);
        let all = offering_objects(&script);
        let mut listed = 0u64;
        for (v, r) in store.iter() {
            let objs = store.objects(r);
            let want = &all[&v];
            assert_eq!(store.owner(r), owners[&v].0, "seed {seed}: owner of {v:?}");
            assert_eq!(objs[0], store.owner(r), "seed {seed}: owner first at {v:?}");
            assert_eq!(
                objs.len(),
                want.len(),
                "seed {seed}: {v:?}: {objs:?} vs {want:?}"
            );
            assert!(want.iter().all(|o| objs.contains(o)), "seed {seed}: {v:?}");
            assert!(
                objs[1..].windows(2).all(|w| w[0] < w[1]),
                "seed {seed}: {v:?}"
            );
            if want.len() == 1 {
                // One object: the record holds the id itself.
                assert_eq!(r.object, want[0]);
            } else {
                listed += 1;
            }
        }
        assert_eq!(s.fill.listed, listed, "seed {seed}");
        assert!(s.lists.len() <= 3 * s.count.repeats() as usize + 2 * s.count.shared as usize);
    }
}

#[test]
fn too_little_list_storage_is_refused_never_dropped() {
    let e = Extent::cube(16).unwrap();
    // Three objects share two voxels: lists [3, a, b, c] twice = 8 entries,
    // laid out while the 2 nodes of 2 entries per voxel are still live.
    let script: Script = (0..3)
        .map(|o| vec![([1, 1, 1], 10_000 * o), ([9, 9, 9], 30_000 - 10_000 * o)])
        .collect();
    let full = build(e, &script).unwrap();
    assert_eq!(full.lists.len(), 8);
    let store = full.store(e);
    let r = store.get_voxel([9, 9, 9]).unwrap();
    assert_eq!(store.objects(r), [2, 0, 1]);
    assert_eq!(
        store.objects(store.get_voxel([1, 1, 1]).unwrap()),
        [0, 1, 2]
    );
    // Just enough working space: 8 list entries + 8 of nodes.
    assert!(build_with(e, &script, Some(16)).is_ok());
    for short in [0, 3, 7, 15] {
        match build_with(e, &script, Some(short)) {
            Err(BuildError::ListStorage { needed, found }) => {
                assert_eq!(found, short);
                assert!(needed > short, "{needed} <= {short}");
            }
            other => panic!("{short} entries: {:?}", other.map(|s| s.lists)),
        }
    }
    // No shared voxel: no list storage at all.
    let alone: Script = vec![vec![([1, 1, 1], 0)], vec![([2, 1, 1], 0)]];
    assert_eq!(build_with(e, &alone, Some(0)).unwrap().lists.len(), 0);
}

#[test]
fn corrupt_object_lists_are_rejected() {
    use crate::voxel::OBJECT_LIST;
    let e = Extent::cube(8).unwrap();
    let rec = |key: u16, object: u32| VoxelRecord {
        key,
        object,
        ..VoxelRecord::default()
    };
    let recs = [rec(1, OBJECT_LIST), rec(2, 5), rec(3, OBJECT_LIST | 3)];
    let ok = [2, 4, 1, 3, 9, 2, 7];
    assert!(RecordStore::with_lists(e, &[0, 3], &recs, &ok).is_ok());
    // Without lists, a listed record is refused.
    assert_eq!(
        RecordStore::new(e, &[0, 3], &recs).unwrap_err(),
        StoreError::BadList { record: 0 }
    );
    let bad = |lists: &[u32]| RecordStore::with_lists(e, &[0, 3], &recs, lists).unwrap_err();
    // Unsorted others, the owner among them, a single object, an id with bit 31.
    assert_eq!(
        bad(&[2, 4, 1, 3, 9, 7, 2]),
        StoreError::BadList { record: 2 }
    );
    assert_eq!(
        bad(&[2, 4, 4, 3, 9, 2, 7]),
        StoreError::BadList { record: 0 }
    );
    assert_eq!(
        bad(&[1, 4, 3, 3, 9, 2, 7]),
        StoreError::BadList { record: 0 }
    );
    assert_eq!(
        bad(&[2, OBJECT_LIST, 1, 3, 9, 2, 7]),
        StoreError::BadList { record: 0 }
    );
    // A gap, a list past the end, entries left over.
    let gap = [rec(1, OBJECT_LIST), rec(2, 5), rec(3, OBJECT_LIST | 4)];
    assert_eq!(
        RecordStore::with_lists(e, &[0, 3], &gap, &[2, 4, 1, 0, 3, 9, 2, 7]).unwrap_err(),
        StoreError::BadList { record: 2 }
    );
    assert_eq!(bad(&[2, 4, 1, 3, 9, 2]), StoreError::BadList { record: 2 });
    assert_eq!(
        bad(&[2, 4, 1, 3, 9, 2, 7, 0]),
        StoreError::ListsEnd { used: 7, len: 8 }
    );
}

/// Runs of offers, each begun with its object id.
type Runs = Vec<(u32, Vec<([u32; 3], u32)>)>;

/// Builds with lists from `runs` of offers, each run begun with its
/// object id, in the order given; the sorted objects of each voxel.
fn objects_of_runs(extent: Extent, runs: &Runs) -> HashMap<[u32; 3], Vec<u32>> {
    let mut plane = vec![0u8; extent.len()];
    let mut dir = vec![0u32; directory_len(extent).unwrap()];
    let mut counter = Counter::new(RasterMut::new(extent, &mut plane).unwrap(), &mut dir).unwrap();
    for (_, offers) in runs {
        for &(v, d) in offers {
            counter.offer(v, surfel(d));
        }
    }
    let sizing = counter.finish().unwrap();
    let mut records = vec![VoxelRecord::default(); sizing.records()];
    let mut lists = vec![0u32; sizing.list_entries()];
    let objects = runs.iter().map(|r| r.0 + 1).max().unwrap_or(1);
    let limits = Limits {
        objects,
        materials: 1,
    };
    let mut filler = sizing
        .fill_with_lists(&mut records, &mut lists, limits)
        .unwrap();
    for (id, offers) in runs {
        filler
            .begin_object(ObjectAttrs {
                object: *id,
                material: 0,
                color: [0; 3],
            })
            .unwrap();
        for &(v, d) in offers {
            filler.offer(v, surfel(d));
        }
    }
    let built = filler.finish().unwrap();
    let store = built.store();
    store
        .iter()
        .map(|(v, r)| {
            let mut objs = store.objects(r).to_vec();
            objs.sort_unstable();
            (v, objs)
        })
        .collect()
}

#[test]
fn object_lists_do_not_depend_on_the_order_objects_are_begun_in() {
    for seed in 0..30u64 {
        let mut rng = Rng(seed ^ 0x0dd);
        let extent = Extent::new(
            1 + rng.below_u32(16),
            1 + rng.below_u32(16),
            1 + rng.below_u32(16),
        )
        .unwrap();
        let objects = 2 + rng.below_u32(6) as usize;
        let offers = rng.below_u32(3000) as usize;
        let script = random_script(extent, objects, offers, seed.wrapping_mul(7919));
        let in_order: Runs = script
            .iter()
            .enumerate()
            .map(|(id, o)| (id as u32, o.clone()))
            .collect();
        // Each object's offers in two runs: every first half in order,
        // then every second half backwards (objects begun again, out of
        // order).
        let halves = |back: bool| -> Runs {
            let mut v: Runs = script
                .iter()
                .enumerate()
                .map(|(id, o)| {
                    let (a, b) = o.split_at(o.len() / 2);
                    (id as u32, if back { b.to_vec() } else { a.to_vec() })
                })
                .collect();
            if back {
                v.reverse();
            }
            v
        };
        let mut split = halves(false);
        split.extend(halves(true));
        let want = offering_objects(&script)
            .into_iter()
            .map(|(v, mut o)| {
                o.sort_unstable();
                (v, o)
            })
            .collect::<HashMap<_, _>>();
        assert_eq!(
            objects_of_runs(extent, &in_order),
            want,
            "seed {seed}: in order"
        );
        assert_eq!(
            objects_of_runs(extent, &split),
            want,
            "seed {seed}: split runs"
        );
    }
}

/// Builds `script` in the slabs starting at `starts` (multiples of 8, the
/// first 0) and joins them as a caller does: directory entries moved up by
/// the records before, list indices by the list entries before.
fn build_in_slabs(extent: Extent, script: &Script, starts: &[u32]) -> Scene {
    let [_, ny, nz] = extent.dims();
    let pieces: Vec<_> = starts
        .iter()
        .enumerate()
        .map(|(i, &z0)| (0..ny, z0..starts.get(i + 1).copied().unwrap_or(nz)))
        .collect();
    build_in_pieces(extent, script, &pieces)
}

/// Builds `script` in `pieces` (rows, layers), in raster order: slabs of
/// every row, or bands of one brick layer, starting on multiples of 8; a
/// band builds its own plane, copied into the raster's after its fill
/// pass. Joined as [`build_in_slabs`].
fn build_in_pieces(extent: Extent, script: &Script, pieces: &[(Range<u32>, Range<u32>)]) -> Scene {
    let [nx, ny, _] = extent.dims();
    let (row, slice) = (nx as usize, (nx * ny) as usize);
    let mut plane = vec![0u8; extent.len()];
    let mut dir = vec![0u32; 1];
    let mut records = Vec::new();
    let mut lists = Vec::new();
    let limits = Limits {
        objects: script.len() as u32,
        materials: 1,
    };
    for (i, (rows, layers)) in pieces.iter().enumerate() {
        let (y0, z0) = (rows.start, layers.start);
        let band = *rows != (0..ny);
        let e = Extent::new(nx, rows.end - y0, layers.end - z0).unwrap();
        let mut own = vec![0u8; if band { e.len() } else { 0 }];
        let part = if band {
            &mut own[..]
        } else {
            &mut plane[z0 as usize * slice..layers.end as usize * slice]
        };
        let mut sdir = vec![0u32; directory_len(e).unwrap()];
        let raster = RasterMut::new(e, part).unwrap();
        // Fresh zeros: the unchecked start (every other slab checks).
        let mut counter = if band {
            Counter::band(raster, &mut sdir, [y0, z0]).unwrap()
        } else if i % 2 == 0 {
            Counter::slab_zeroed(raster, &mut sdir, z0).unwrap()
        } else {
            Counter::slab(raster, &mut sdir, z0).unwrap()
        };
        assert_eq!(counter.layers(), layers.clone());
        assert_eq!(counter.rows(), rows.clone());
        for obj in script {
            for &(v, d) in obj {
                counter.offer(v, surfel(d));
            }
        }
        let sizing = counter.finish().unwrap();
        let mut srec = vec![VoxelRecord::default(); sizing.records()];
        let mut slists = vec![0u32; sizing.list_entries()];
        let mut filler = sizing
            .fill_with_lists(&mut srec, &mut slists, limits)
            .unwrap();
        assert_eq!(filler.rows(), rows.clone());
        for (id, obj) in script.iter().enumerate() {
            filler
                .begin_object(ObjectAttrs {
                    object: id as u32,
                    material: 0,
                    color: [id as u8, 0, 0],
                })
                .unwrap();
            for &(v, d) in obj {
                filler.offer(v, surfel(d));
            }
        }
        let built = filler.finish().unwrap();
        assert_eq!(built.slab(), Some(z0));
        let used = built.lists().len();
        if band {
            let n = (rows.end - y0) as usize * row;
            for (z, layer) in layers.clone().zip(own.chunks_exact(n)) {
                let at = z as usize * slice + y0 as usize * row;
                plane[at..at + n].copy_from_slice(layer);
            }
        }
        let base = records.len() as u32;
        dir.pop();
        dir.extend(sdir.iter().map(|d| d + base));
        shift_lists(&mut srec, lists.len()).unwrap();
        records.extend(srec);
        lists.extend_from_slice(&slists[..used]);
    }
    Scene {
        plane,
        dir,
        records,
        lists,
        count: CountReport::default(),
        fill: FillReport::default(),
    }
}

#[test]
fn bands_joined_are_the_whole_scene() {
    let mut rng = Rng(0xba4d_0001);
    for case in 0..30u64 {
        let extent = Extent::new(
            1 + rng.below_u32(13),
            1 + rng.below_u32(40),
            1 + rng.below_u32(20),
        )
        .unwrap();
        let [_, ny, nz] = extent.dims();
        let script = random_script(extent, 2 + case as usize % 6, 40, case);
        let whole = build(extent, &script).unwrap();
        // Each brick layer a slab or cut into bands at random brick rows.
        let mut pieces = Vec::new();
        for z0 in (0..nz).step_by(8) {
            let layers = z0..(z0 + 8).min(nz);
            let mut y0 = 0;
            while y0 < ny {
                let y1 = if rng.below_u32(3) == 0 {
                    ny
                } else {
                    (y0 + 8 * (1 + rng.below_u32(2))).min(ny)
                };
                pieces.push((y0..y1, layers.clone()));
                y0 = y1;
            }
        }
        let banded = build_in_pieces(extent, &script, &pieces);
        assert_joined_is_whole(&banded, &whole, &format!("case {case} {pieces:?}"));
    }
}

#[test]
fn a_band_starts_on_bricks_and_holds_one_brick_layer() {
    let mut plane = vec![0u8; 16 * 16 * 9];
    let e = Extent::new(16, 16, 9).unwrap();
    let mut dir = vec![0u32; directory_len(e).unwrap()];
    let err = Counter::band(RasterMut::new(e, &mut plane).unwrap(), &mut dir, [0, 0]).unwrap_err();
    assert_eq!(
        err,
        BuildError::BandShape {
            y0: 0,
            z0: 0,
            layers: 9
        }
    );
    let e = Extent::new(16, 16, 8).unwrap();
    let mut plane = vec![0u8; e.len()];
    let mut dir = vec![0u32; directory_len(e).unwrap()];
    for origin in [[4, 0], [0, 4], [8, 12]] {
        let raster = RasterMut::new(e, &mut plane).unwrap();
        let err = Counter::band(raster, &mut dir, origin).unwrap_err();
        assert_eq!(
            err,
            BuildError::BandShape {
                y0: origin[0],
                z0: origin[1],
                layers: 8
            }
        );
    }
    let raster = RasterMut::new(e, &mut plane).unwrap();
    assert!(Counter::band(raster, &mut dir, [8, 16]).is_ok());
}

#[test]
fn slabs_joined_are_the_whole_scene() {
    let mut rng = Rng(0x51ab_0001);
    for case in 0..30u64 {
        let extent = Extent::new(
            1 + rng.below_u32(13),
            1 + rng.below_u32(11),
            1 + rng.below_u32(40),
        )
        .unwrap();
        let nz = extent.dims()[2];
        // Many objects over few voxels: shared voxels and object lists.
        let script = random_script(extent, 2 + case as usize % 6, 40, case);
        let whole = build(extent, &script).unwrap();
        let mut starts = vec![0u32];
        let mut z = 0u32;
        loop {
            z += 8 * (1 + rng.below_u32(3));
            if z >= nz {
                break;
            }
            starts.push(z);
        }
        let slabs = build_in_slabs(extent, &script, &starts);
        assert_joined_is_whole(&slabs, &whole, &format!("case {case} {starts:?}"));
    }
}

/// `joined` (slabs or bands built apart and joined) is the whole build:
/// the same directory, records and lists, and every cell the same (OPAQUE
/// and the rank hints) but for the proximity flags, which pieces leave to
/// a later pass.
#[track_caller]
fn assert_joined_is_whole(joined: &Scene, whole: &Scene, what: &str) {
    assert_eq!(joined.dir, whole.dir, "{what}");
    assert_eq!(joined.records, whole.records, "{what}");
    assert_eq!(joined.lists, whole.lists, "{what}");
    let unflagged = |p: &[u8]| p.iter().map(|c| c & !cell::PROXIMITY).collect::<Vec<_>>();
    assert_eq!(unflagged(&joined.plane), unflagged(&whole.plane), "{what}");
}
