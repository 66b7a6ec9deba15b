//! Rank hints: an opaque cell's distance bits carry its record's rank in
//! its brick, which narrows a lookup from the plane.

use super::RecordStore;
use super::brick::{brick_origin, voxel_at};
use crate::raster::{RasterMut, cell, to_usize};

/// Ranks with hint `h` among `n` records: `⌈h·n/64⌉ .. ⌈(h+1)·n/64⌉`.
pub(super) fn hint_window(h: u8, n: usize) -> (usize, usize) {
    let at = |h: usize| h.saturating_mul(n).saturating_add(HINT_SCALE - 1) / HINT_SCALE;
    let h = usize::from(h);
    (at(h), at(h.saturating_add(1)))
}

/// Rank hints take the 64 values of a cell's distance bits.
pub(super) const HINT_SCALE: usize = cell::DISTANCE_MASK as usize + 1;

/// The rank hint of the record of rank `rank` among its brick's `n`
/// records: `⌊rank·64/n⌋`, in `0..64`. An opaque cell carries its record's
/// hint in its distance bits ([`write_rank_hints`]), so that a lookup
/// ([`RecordStore::get_hinted`]) scans a window of about `n/64 + 1`
/// records (one for bricks of at most 64) instead of binary-searching up
/// to 512.
///
/// ```
/// use rrt_core::store::rank_hint;
/// assert_eq!(rank_hint(0, 10), 0);
/// assert_eq!(rank_hint(9, 10), 57);
/// assert_eq!(rank_hint(511, 512), 63);
/// ```
#[must_use]
pub fn rank_hint(rank: usize, n: usize) -> u8 {
    let h = rank.saturating_mul(HINT_SCALE).checked_div(n).unwrap_or(0);
    u8::try_from(h.min(HINT_SCALE - 1)).unwrap_or(0)
}

/// The rank hint an opaque cell carries (`None` for a transparent cell,
/// whose distance bits hold a proximity distance).
#[must_use]
pub const fn cell_hint(c: u8) -> Option<u8> {
    if c & cell::OPAQUE != 0 {
        Some((c >> cell::DISTANCE_SHIFT) & cell::DISTANCE_MASK)
    } else {
        None
    }
}

/// Writes every record's [`rank_hint`] into its opaque cell's distance
/// bits, keeping the OPAQUE and PROXIMITY bits. O(records). Run it after
/// [`crate::proximity::distance_field`], which clears them. A raster
/// without hints (or with wrong ones) gives the same lookups, only slower.
///
/// ```
/// use rrt_core::raster::{cell, Extent, RasterMut};
/// use rrt_core::store::{cell_hint, write_rank_hints, RecordStore};
/// use rrt_core::voxel::VoxelRecord;
/// let e = Extent::cube(8).unwrap();
/// // Voxels (1, 0, 0) and (2, 0, 0): ranks 0 and 1 of 2.
/// let recs = [1u16, 2].map(|key| VoxelRecord { key, ..Default::default() });
/// let store = RecordStore::new(e, &[0, 2], &recs).unwrap();
/// let mut plane = vec![cell::EMPTY; e.len()];
/// plane[1] = cell::OPAQUE | cell::PROXIMITY;
/// plane[2] = cell::OPAQUE | cell::PROXIMITY;
/// write_rank_hints(&mut RasterMut::new(e, &mut plane).unwrap(), &store);
/// assert_eq!((cell_hint(plane[1]), cell_hint(plane[2])), (Some(0), Some(32)));
/// assert_eq!(store.get_hinted([2, 0, 0], plane[2]), Some(&recs[1]));
/// ```
pub fn write_rank_hints(raster: &mut RasterMut<'_>, store: &RecordStore<'_>) {
    set_opaque_cells(raster, store, cell::OPAQUE | cell::PROXIMITY);
}

/// Sets each record's cell to its bits in `keep` plus its rank hint.
pub(super) fn set_opaque_cells(raster: &mut RasterMut<'_>, store: &RecordStore<'_>, keep: u8) {
    let extent = raster.extent();
    if store.extent() != extent {
        return;
    }
    let plane = raster.plane_mut();
    for (b, w) in store.dir.windows(2).enumerate() {
        let (lo, hi) = match w {
            [lo, hi] => (to_usize(*lo), to_usize(*hi)),
            _ => continue,
        };
        let Some(slice) = store.records.get(lo..hi).filter(|s| !s.is_empty()) else {
            continue;
        };
        let Some(origin) = brick_origin(extent, b) else {
            continue;
        };
        for (rank, r) in slice.iter().enumerate() {
            let hint = rank_hint(rank, slice.len());
            if let Some(c) = extent
                .index(voxel_at(origin, r.position()))
                .and_then(|i| plane.get_mut(i))
                .filter(|c| **c & cell::OPAQUE != 0)
            {
                *c = (*c & keep) | (hint << cell::DISTANCE_SHIFT);
            }
        }
    }
}
