//! The record store: a validated brick directory over sorted records, and
//! its lookups.

use super::brick::{BRICK_VOXELS, brick_of, brick_origin, directory_len, voxel_at};
use super::error::StoreError;
use super::list;
use super::rank_hint::{cell_hint, hint_window};
use crate::raster::{Extent, to_usize};
use crate::voxel::{VoxelRecord, brick_position};

/// A read-only record store: a validated brick directory over sorted
/// records, and the object lists of the voxels several objects share.
///
/// Invariants (checked by [`RecordStore::new`]): `dir.len() == bricks + 1`,
/// `dir[0] == 0`, entries non-decreasing with at most 512 records per brick,
/// `dir[last] == records.len()`, and inside each brick the records' position
/// bits strictly increase and name voxels inside the raster; the object
/// lists are laid out as [`crate::store`]'s *Object lists* says.
#[derive(Clone, Copy, Debug)]
pub struct RecordStore<'a> {
    pub(super) extent: Extent,
    pub(super) dir: &'a [u32],
    pub(super) records: &'a [VoxelRecord],
    pub(super) lists: &'a [u32],
}

/// Checks the store invariants (see [`RecordStore`]).
fn validate(
    extent: Extent,
    dir: &[u32],
    records: &[VoxelRecord],
    lists: &[u32],
) -> Result<(), StoreError> {
    validate_bricks(extent, dir, records)?;
    list::validate(records, lists)
}

/// The directory and key invariants.
fn validate_bricks(extent: Extent, dir: &[u32], records: &[VoxelRecord]) -> Result<(), StoreError> {
    let expected = directory_len(extent).ok_or(StoreError::TooManyBricks)?;
    if dir.len() != expected {
        return Err(StoreError::DirectoryLength {
            expected,
            found: dir.len(),
        });
    }
    if dir.first().copied() != Some(0) {
        return Err(StoreError::DirectoryStart);
    }
    let last = dir.last().copied().unwrap_or(0);
    if usize::try_from(last).ok() != Some(records.len()) {
        return Err(StoreError::DirectoryEnd {
            last,
            records: records.len(),
        });
    }
    for (brick, w) in dir.windows(2).enumerate() {
        let (lo, hi) = match *w {
            [lo, hi] => (lo, hi),
            _ => return Err(StoreError::DirectoryOrder { brick }),
        };
        if hi < lo || hi.wrapping_sub(lo) > BRICK_VOXELS {
            return Err(StoreError::DirectoryOrder { brick });
        }
        if hi == lo {
            continue;
        }
        let origin = brick_origin(extent, brick).ok_or(StoreError::DirectoryOrder { brick })?;
        let (lo, hi) = (to_usize(lo), to_usize(hi));
        let slice = records
            .get(lo..hi)
            .ok_or(StoreError::DirectoryOrder { brick })?;
        let mut prev: Option<u16> = None;
        for (k, r) in slice.iter().enumerate() {
            let pos = r.position();
            // lo + k < hi <= records.len(): no overflow.
            let record = lo.wrapping_add(k);
            if prev.is_some_and(|p| p >= pos) || !extent.contains(voxel_at(origin, pos)) {
                return Err(StoreError::BadKey { record });
            }
            prev = Some(pos);
        }
    }
    Ok(())
}

/// The record of voxel `v` among `records` under `dir`. With a rank `hint`
/// (see [`rank_hint`](super::rank_hint())) only the hint's window is scanned first; a record
/// not there (a stale or made-up hint) is found by the binary search, so a
/// hint changes the cost of a lookup, never its result.
pub(super) fn find(
    extent: Extent,
    dir: &[u32],
    records: &[VoxelRecord],
    v: [u32; 3],
    hint: Option<u8>,
) -> Option<usize> {
    if !extent.contains(v) {
        return None;
    }
    let b = brick_of(extent, v);
    let lo = to_usize(*dir.get(b)?);
    let hi = to_usize(*dir.get(b.checked_add(1)?)?);
    let slice = records.get(lo..hi)?;
    let pos = brick_position(v);
    if let Some(h) = hint {
        let (from, to) = hint_window(h, slice.len());
        if let Some(k) = slice
            .get(from..to)
            .and_then(|w| w.iter().position(|r| r.position() == pos))
        {
            return lo.checked_add(from)?.checked_add(k);
        }
    }
    let k = slice
        .binary_search_by_key(&pos, VoxelRecord::position)
        .ok()?;
    lo.checked_add(k)
}

impl<'a> RecordStore<'a> {
    /// Validates `dir` and `records` against `extent`, in
    /// O(bricks + records), for a store without object lists (a record
    /// naming a list is refused). A store loaded from a file goes through
    /// this or [`RecordStore::with_lists`], so a corrupt file cannot cause a
    /// wrong-brick lookup or a panic later.
    ///
    /// # Errors
    /// A [`StoreError`] naming the first broken invariant.
    ///
    /// ```
    /// use rrt_core::raster::Extent;
    /// use rrt_core::store::{RecordStore, StoreError};
    /// use rrt_core::voxel::VoxelRecord;
    /// let e = Extent::cube(8).unwrap();
    /// let recs = [VoxelRecord { key: 5, ..Default::default() }];
    /// assert!(RecordStore::new(e, &[0, 1], &recs).is_ok());
    /// assert_eq!(RecordStore::new(e, &[0, 2], &recs).unwrap_err(),
    ///            StoreError::DirectoryEnd { last: 2, records: 1 });
    /// ```
    pub fn new(
        extent: Extent,
        dir: &'a [u32],
        records: &'a [VoxelRecord],
    ) -> Result<Self, StoreError> {
        Self::with_lists(extent, dir, records, &[])
    }

    /// Validates like [`RecordStore::new`], with the object lists `lists`
    /// (O(bricks + records + list entries)).
    ///
    /// # Errors
    /// A [`StoreError`] naming the first broken invariant.
    ///
    /// ```
    /// use rrt_core::raster::Extent;
    /// use rrt_core::store::RecordStore;
    /// use rrt_core::voxel::{VoxelRecord, OBJECT_LIST};
    /// let e = Extent::cube(8).unwrap();
    /// // Voxel (5, 0, 0) holds object 3 alone; voxel (6, 0, 0) objects 7 (its owner), 2 and 4.
    /// let recs = [
    ///     VoxelRecord { key: 5, object: 3, ..Default::default() },
    ///     VoxelRecord { key: 6, object: OBJECT_LIST | 0, ..Default::default() },
    /// ];
    /// let lists = [3, 7, 2, 4];
    /// let store = RecordStore::with_lists(e, &[0, 2], &recs, &lists).unwrap();
    /// assert_eq!((store.owner(&recs[0]), store.objects(&recs[0])), (3, &[3][..]));
    /// assert_eq!((store.owner(&recs[1]), store.objects(&recs[1])), (7, &[7, 2, 4][..]));
    /// assert!(RecordStore::with_lists(e, &[0, 2], &recs, &[3, 7, 4, 2]).is_err());
    /// ```
    pub fn with_lists(
        extent: Extent,
        dir: &'a [u32],
        records: &'a [VoxelRecord],
        lists: &'a [u32],
    ) -> Result<Self, StoreError> {
        validate(extent, dir, records, lists)?;
        Ok(Self {
            extent,
            dir,
            records,
            lists,
        })
    }

    /// The owner of record `rec` (of this store): the object whose surface
    /// passes nearest the voxel centre, whose attributes the record holds.
    /// O(1); one read of the list array for a voxel several objects share.
    #[inline]
    #[must_use]
    pub fn owner(&self, rec: &VoxelRecord) -> u32 {
        list::owner(self.lists, rec)
    }

    /// Every object whose surface passes through the voxel of record `rec`
    /// (of this store), each once, the owner first and the others in
    /// increasing id order. O(1); a one-element slice of the record itself
    /// for a voxel of one object.
    #[inline]
    #[must_use]
    pub fn objects<'r>(&self, rec: &'r VoxelRecord) -> &'r [u32]
    where
        'a: 'r,
    {
        list::objects(self.lists, rec)
    }

    /// The object list array (see [`crate::store`]).
    #[must_use]
    pub const fn lists(&self) -> &'a [u32] {
        self.lists
    }

    /// The record of the voxel with linear raster index `index`, or `None`
    /// for a transparent voxel or an index past the raster. O(log 512).
    #[must_use]
    pub fn get(&self, index: usize) -> Option<&'a VoxelRecord> {
        self.get_voxel(self.extent.coord(index)?)
    }

    /// The record of voxel `v`, or `None` for a transparent voxel or `v`
    /// outside the raster.
    #[must_use]
    pub fn get_voxel(&self, v: [u32; 3]) -> Option<&'a VoxelRecord> {
        let i = find(self.extent, self.dir, self.records, v, None)?;
        self.records.get(i)
    }

    /// [`RecordStore::get_voxel`] for a voxel whose plane cell is `c`: an
    /// opaque cell's rank hint ([`write_rank_hints`](super::write_rank_hints)) narrows the search.
    /// The same result as `get_voxel` whatever `c` holds.
    #[must_use]
    pub fn get_hinted(&self, v: [u32; 3], c: u8) -> Option<&'a VoxelRecord> {
        self.records.get(self.index_hinted(v, c)?)
    }

    /// The position in [`records`](Self::records) of voxel `v`'s record
    /// (`None` for a transparent or outside voxel), found as
    /// [`get_hinted`](Self::get_hinted) finds it: a host keeps per-record
    /// data beside the store under this index.
    #[must_use]
    pub fn index_hinted(&self, v: [u32; 3], c: u8) -> Option<usize> {
        find(self.extent, self.dir, self.records, v, cell_hint(c))
    }

    /// The raster's dimensions.
    #[must_use]
    pub const fn extent(&self) -> Extent {
        self.extent
    }

    /// The brick directory.
    #[must_use]
    pub const fn directory(&self) -> &'a [u32] {
        self.dir
    }

    /// All records, sorted by brick and position.
    #[must_use]
    pub const fn records(&self) -> &'a [VoxelRecord] {
        self.records
    }

    /// Number of records (non-transparent voxels).
    #[must_use]
    pub const fn len(&self) -> usize {
        self.records.len()
    }

    /// Whether the store holds no record.
    #[must_use]
    pub const fn is_empty(&self) -> bool {
        self.records.is_empty()
    }

    /// The records from index `first` on, with their voxel coordinates, in
    /// storage order (a brick is found by binary search of the directory):
    /// for hosts that split a pass over the records into runs.
    ///
    /// ```
    /// use rrt_core::raster::Extent;
    /// use rrt_core::store::RecordStore;
    /// use rrt_core::voxel::VoxelRecord;
    /// let e = Extent::new(16, 8, 8).unwrap();
    /// // Two bricks: voxel (1, 0, 0) in the first, (9, 0, 0) and (10, 0, 0) in the second.
    /// let recs = [1u16, 1, 2].map(|key| VoxelRecord { key, ..Default::default() });
    /// let store = RecordStore::new(e, &[0, 1, 3], &recs).unwrap();
    /// let from_1: Vec<[u32; 3]> = store.iter_from(1).map(|(v, _)| v).collect();
    /// assert_eq!(from_1, [[9, 0, 0], [10, 0, 0]]);
    /// assert_eq!(store.iter_from(3).count(), 0);
    /// ```
    pub fn iter_from(
        &self,
        first: usize,
    ) -> impl Iterator<Item = ([u32; 3], &'a VoxelRecord)> + 'a {
        let extent = self.extent;
        let dir = self.dir;
        let records = self.records.get(first..).unwrap_or(&[]);
        // The brick holding record `first`: the last with dir[b] <= first.
        let mut b = dir
            .partition_point(|&d| to_usize(d) <= first)
            .saturating_sub(1);
        // The brick's origin, computed again only when the brick changes.
        let mut origin = brick_origin(extent, b).unwrap_or([0; 3]);
        records.iter().enumerate().map(move |(k, r)| {
            let k = first.saturating_add(k);
            let b0 = b;
            while dir
                .get(b.saturating_add(1))
                .is_some_and(|&end| to_usize(end) <= k)
            {
                b = b.saturating_add(1);
            }
            if b != b0 {
                origin = brick_origin(extent, b).unwrap_or([0; 3]);
            }
            (voxel_at(origin, r.position()), r)
        })
    }

    /// Every record with its voxel coordinates, in storage order.
    pub fn iter(&self) -> impl Iterator<Item = ([u32; 3], &'a VoxelRecord)> + 'a {
        let extent = self.extent;
        let records = self.records;
        self.dir
            .windows(2)
            .enumerate()
            .filter(|(_, w)| w.first() != w.get(1))
            .flat_map(move |(b, w)| {
                let origin = brick_origin(extent, b).unwrap_or([0; 3]);
                let lo = to_usize(w.first().copied().unwrap_or(0));
                let hi = to_usize(w.get(1).copied().unwrap_or(0));
                records
                    .get(lo..hi)
                    .unwrap_or(&[])
                    .iter()
                    .map(move |r| (voxel_at(origin, r.position()), r))
            })
    }
}

/// A record store whose records can be updated in place (the light pass
/// writes visibility and illumination; the object lists stay as they are).
/// Same invariants as [`RecordStore`].
#[derive(Debug)]
pub struct RecordStoreMut<'a> {
    pub(super) extent: Extent,
    pub(super) dir: &'a [u32],
    pub(super) records: &'a mut [VoxelRecord],
    pub(super) lists: &'a [u32],
}

impl<'a> RecordStoreMut<'a> {
    /// Validates like [`RecordStore::new`].
    ///
    /// # Errors
    /// As [`RecordStore::new`].
    pub fn new(
        extent: Extent,
        dir: &'a [u32],
        records: &'a mut [VoxelRecord],
    ) -> Result<Self, StoreError> {
        Self::with_lists(extent, dir, records, &[])
    }

    /// Validates like [`RecordStore::with_lists`].
    ///
    /// # Errors
    /// As [`RecordStore::with_lists`].
    pub fn with_lists(
        extent: Extent,
        dir: &'a [u32],
        records: &'a mut [VoxelRecord],
        lists: &'a [u32],
    ) -> Result<Self, StoreError> {
        RecordStore::with_lists(extent, dir, records, lists)?;
        Ok(Self {
            extent,
            dir,
            records,
            lists,
        })
    }

    /// A read-only view.
    #[must_use]
    pub fn as_store(&self) -> RecordStore<'_> {
        RecordStore {
            extent: self.extent,
            dir: self.dir,
            records: self.records,
            lists: self.lists,
        }
    }

    /// Calls `f` once per record, in storage order, with a read-only view of
    /// the whole store, the record's voxel and a copy of the record; a
    /// returned record replaces it. `f` must not change the key (the light
    /// pass changes only visibility and illumination); a changed key or
    /// object field is restored so the store stays valid.
    ///
    /// # Errors
    /// The first error `f` returns; records visited before it keep their
    /// updates.
    pub(crate) fn update_each<E, F>(&mut self, mut f: F) -> Result<(), E>
    where
        F: FnMut(RecordStore<'_>, [u32; 3], VoxelRecord) -> Result<Option<VoxelRecord>, E>,
    {
        let extent = self.extent;
        let dir = self.dir;
        for (b, w) in dir.windows(2).enumerate() {
            let [lo, hi] = *w else { continue };
            if hi <= lo {
                continue;
            }
            let Some(origin) = brick_origin(extent, b) else {
                continue;
            };
            for k in to_usize(lo)..to_usize(hi) {
                let Some(r) = self.records.get(k).copied() else {
                    continue;
                };
                let view = RecordStore {
                    extent,
                    dir,
                    records: self.records,
                    lists: self.lists,
                };
                if let Some(mut new) = f(view, voxel_at(origin, r.position()), r)?
                    && let Some(slot) = self.records.get_mut(k)
                {
                    new.key = r.key;
                    new.object = r.object;
                    *slot = new;
                }
            }
        }
        Ok(())
    }

    /// The record of voxel `v`, mutably.
    pub fn get_voxel_mut(&mut self, v: [u32; 3]) -> Option<&mut VoxelRecord> {
        let i = find(self.extent, self.dir, self.records, v, None)?;
        self.records.get_mut(i)
    }
}
