//! Object lists: every object whose surface passes through a voxel, for
//! the voxels that several objects offered.
//!
//! # Layout
//! A record whose [`VoxelRecord::object`] has bit 31 ([`OBJECT_LIST`]) set
//! names, in its low 31 bits, an index `i` into the store's list array
//! (`u32`s). The list is `lists[i] = n` (`n ≥ 2`), then the `n` object ids:
//! the *owner* first (the object whose offer was nearest the voxel centre,
//! whose attributes the record holds), then the others in strictly
//! increasing id order. Lists are stored in the records' storage order, one
//! after the other without gaps, so the array is exactly as long as the
//! lists, a store loaded from a file is checked in one pass, and a z-slab of
//! bricks owns a contiguous range of it as it owns one of the records.
//! A record without the flag holds its one object's id and costs nothing
//! more: no list entry, no extra lookup.
//!
//! # Capacity
//! No per-voxel capacity: a list holds every object that offered the voxel
//! (each once). The array as a whole is indexed by 31 bits, so it holds at
//! most `2^31 − 1` entries; the builder refuses a scene whose lists do not
//! fit the storage it was given
//! ([`BuildError::ListStorage`](super::BuildError::ListStorage)), never
//! dropping an object silently.

use super::error::StoreError;
use crate::raster::to_usize;
use crate::voxel::{MAX_OBJECTS, OBJECT_LIST, VoxelRecord};

/// Largest number of `u32` entries a list array may hold (indices are 31
/// bits).
pub const MAX_LIST_ENTRIES: usize = (OBJECT_LIST - 1) as usize;

/// The list index of `rec`, if its object field names a list.
#[inline]
pub(super) const fn list_index(rec: &VoxelRecord) -> Option<usize> {
    if rec.object & OBJECT_LIST != 0 {
        Some(to_usize(rec.object & !OBJECT_LIST))
    } else {
        None
    }
}

/// The owner of `rec` under `lists` (an id no table holds, `u32::MAX`, for a
/// list index past the array, which a validated store rules out).
#[inline]
pub(super) fn owner(lists: &[u32], rec: &VoxelRecord) -> u32 {
    match list_index(rec) {
        None => rec.object,
        Some(i) => i
            .checked_add(1)
            .and_then(|j| lists.get(j))
            .copied()
            .unwrap_or(u32::MAX),
    }
}

/// All objects of `rec` under `lists`, the owner first (empty for a list
/// index past the array, which a validated store rules out).
#[inline]
pub(super) fn objects<'r>(lists: &'r [u32], rec: &'r VoxelRecord) -> &'r [u32] {
    match list_index(rec) {
        None => core::slice::from_ref(&rec.object),
        Some(i) => {
            let n = lists.get(i).map_or(0, |&n| to_usize(n));
            i.checked_add(1)
                .and_then(|a| lists.get(a..a.checked_add(n)?))
                .unwrap_or(&[])
        }
    }
}

/// Checks the list invariants of the module docs against `records` in
/// storage order: every flagged record's list starts where the previous
/// one ended, has `n ≥ 2` ids below [`MAX_OBJECTS`], the others strictly
/// increasing and different from the owner; the lists end exactly at the
/// array's end; unflagged records hold ids below [`MAX_OBJECTS`] by
/// construction of the flag.
pub(super) fn validate(records: &[VoxelRecord], lists: &[u32]) -> Result<(), StoreError> {
    if lists.len() > MAX_LIST_ENTRIES {
        return Err(StoreError::ListsTooLong { len: lists.len() });
    }
    let mut cursor = 0usize;
    for (record, r) in records.iter().enumerate() {
        let Some(i) = list_index(r) else { continue };
        let bad = StoreError::BadList { record };
        if i != cursor {
            return Err(bad);
        }
        let n = to_usize(*lists.get(i).ok_or(bad)?);
        let start = i.checked_add(1).ok_or(bad)?;
        let end = start.checked_add(n).ok_or(bad)?;
        let ids = lists.get(start..end).ok_or(bad)?;
        let [owner, others @ ..] = ids else {
            return Err(bad);
        };
        if others.is_empty() || *owner >= MAX_OBJECTS {
            return Err(bad);
        }
        let mut prev: Option<u32> = None;
        for &o in others {
            if o >= MAX_OBJECTS || o == *owner || prev.is_some_and(|p| p >= o) {
                return Err(bad);
            }
            prev = Some(o);
        }
        cursor = end;
    }
    if cursor != lists.len() {
        return Err(StoreError::ListsEnd {
            used: cursor,
            len: lists.len(),
        });
    }
    Ok(())
}
