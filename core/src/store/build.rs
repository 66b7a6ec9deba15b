//! The two-pass scene builder: the count pass sizes the records, the fill
//! pass writes them (see the [module docs](super)).

use core::ops::Range;

use super::brick::{BRICK, BRICK_VOXELS, brick_of, directory_len};
use super::error::BuildError;
use super::list::{MAX_LIST_ENTRIES, list_index};
use super::proximity::{DENSE_RATIO, flag_proximity};
use super::rank_hint::set_opaque_cells;
use super::texture::Texture;
use super::{RecordStore, RecordStoreMut};
use crate::raster::{Extent, Raster, RasterMut, cell, to_usize};
use crate::voxel::{
    KEY_POSITION_MASK, MAX_OBJECTS, OBJECT_LIST, VoxelRecord, encode_normal, make_key,
};
use crate::voxelize::{Surfel, VoxelSink};

/// The fill pass's mark on a voxel that has its record (a distance bit:
/// opaque cells' distance bits are free until `finish` writes the rank
/// hints). The count pass marks a voxel offered more than once with
/// [`cell::PROXIMITY`]; `finish` rewrites both.
const FILLED: u8 = 1 << cell::DISTANCE_SHIFT;

/// Attributes shared by all voxels of one object in the fill pass.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct ObjectAttrs {
    /// Index into the object table.
    pub object: u32,
    /// Index into the material table.
    pub material: u16,
    /// Linear RGB colour, used as is or handed to a [`Texture`].
    pub color: [u8; 3],
}

/// Bounds that the fill pass checks object ids and materials against.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Limits {
    /// Number of entries in the object table.
    pub objects: u32,
    /// Number of entries in the material table.
    pub materials: u32,
}

/// What the count pass saw.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct CountReport {
    /// Offers received.
    pub offers: u64,
    /// Distinct voxels set (the record count).
    pub voxels: u64,
    /// Distinct voxels offered more than once (by one object or several).
    pub shared: u64,
    /// Offers outside the raster (or the slab), skipped.
    pub outside: u64,
}

impl CountReport {
    /// Repeat offers: offers inside the raster beyond each voxel's first.
    #[must_use]
    pub const fn repeats(&self) -> u64 {
        self.offers
            .saturating_sub(self.outside)
            .saturating_sub(self.voxels)
    }
}

/// The count pass: a [`VoxelSink`] that sets [`cell::OPAQUE`] and counts
/// new voxels per brick (module docs).
#[derive(Debug)]
pub struct Counter<'p, 'd> {
    raster: RasterMut<'p>,
    dir: &'d mut [u32],
    report: CountReport,
    slab: Option<Origin>,
}

/// Sets every element of `s` to zero unless all already are (a fresh
/// allocation: reading its zero pages is cheaper than writing them).
fn clear<T: Copy + PartialEq + Default>(s: &mut [T]) {
    let zero = T::default();
    if s.iter().any(|x| *x != zero) {
        s.fill(zero);
    }
}

impl<'p, 'd> Counter<'p, 'd> {
    /// Starts a scene: clears the plane and the directory.
    ///
    /// # Errors
    /// [`BuildError::DirectoryLength`] unless `dir.len()` is
    /// [`directory_len`] of the raster.
    pub fn new(raster: RasterMut<'p>, dir: &'d mut [u32]) -> Result<Self, BuildError> {
        Self::start(raster, dir, None, true)
    }

    /// Starts one *slab* of a scene: the layers `z0 .. z0 + nz` of a larger
    /// raster, where `raster` is the slab's own part of the plane (the
    /// larger raster's cells `z0·nx·ny ..`, with the slab's extent
    /// `nx × ny × nz`) and `dir` its own directory. Offers name voxels of
    /// the larger raster; those outside the slab are skipped and counted.
    /// Since `z0` is a multiple of the brick edge, the slab's bricks,
    /// records and object lists are contiguous parts of the larger
    /// raster's, in the same order: a caller builds slabs independently
    /// (on as many threads as it likes) and concatenates them
    /// (the fix-ups: add the earlier slabs' record count to the directory
    /// entries, and their list entries to the list indices, [`shift_lists`]).
    /// The built slab has no proximity flags (they depend on the
    /// neighbouring slabs): compute them on the whole plane afterwards
    /// ([`crate::proximity::flag_neighbourhood`] or
    /// [`crate::proximity::distance_field`]).
    ///
    /// # Errors
    /// [`BuildError::SlabOrigin`] unless `z0` is a multiple of 8, and as
    /// [`Counter::new`].
    pub fn slab(raster: RasterMut<'p>, dir: &'d mut [u32], z0: u32) -> Result<Self, BuildError> {
        if !z0.is_multiple_of(BRICK) {
            return Err(BuildError::SlabOrigin { z0 });
        }
        Self::start(raster, dir, Some([0, z0]), true)
    }

    /// [`Counter::slab`] over a plane part and a directory that are all
    /// zero already (fresh zeroed memory): they are not read to check, so
    /// the pages of a fresh anonymous map that no voxel falls in are never
    /// touched. A nonzero cell or entry makes the build wrong or refused,
    /// never unsafe.
    ///
    /// # Errors
    /// As [`Counter::slab`].
    pub fn slab_zeroed(
        raster: RasterMut<'p>,
        dir: &'d mut [u32],
        z0: u32,
    ) -> Result<Self, BuildError> {
        if !z0.is_multiple_of(BRICK) {
            return Err(BuildError::SlabOrigin { z0 });
        }
        Self::start(raster, dir, Some([0, z0]), false)
    }

    /// Starts one *band* of a scene: the rows `y0 .. y0 + ny` of the layers
    /// `z0 .. z0 + nz` (at most one brick layer, `nz ≤ 8`) of a larger
    /// raster, where `raster` is the band's own plane (`nx × ny × nz`,
    /// cleared here) and `dir` its own directory, as [`Counter::slab`]
    /// otherwise. Within one brick layer bricks are numbered row by row,
    /// so a band's bricks, records and object lists are contiguous parts
    /// of the larger raster's, in the same order, and bands join as slabs
    /// do; the caller copies the band's plane into the larger plane.
    /// Splitting a flat raster (few brick layers) into bands gives
    /// threads more, smaller pieces.
    ///
    /// # Errors
    /// [`BuildError::BandShape`] unless `y0` and `z0` are multiples of 8
    /// and `nz ≤ 8`, and as [`Counter::new`].
    pub fn band(
        raster: RasterMut<'p>,
        dir: &'d mut [u32],
        [y0, z0]: [u32; 2],
    ) -> Result<Self, BuildError> {
        let layers = raster.extent().dims()[2];
        if !y0.is_multiple_of(BRICK) || !z0.is_multiple_of(BRICK) || layers > BRICK {
            return Err(BuildError::BandShape { y0, z0, layers });
        }
        Self::start(raster, dir, Some([y0, z0]), true)
    }

    fn start(
        mut raster: RasterMut<'p>,
        dir: &'d mut [u32],
        slab: Option<Origin>,
        clearing: bool,
    ) -> Result<Self, BuildError> {
        let expected = directory_len(raster.extent()).unwrap_or(usize::MAX);
        if dir.len() != expected {
            return Err(BuildError::DirectoryLength {
                expected,
                found: dir.len(),
            });
        }
        if clearing {
            clear(raster.plane_mut());
            clear(dir);
        }
        Ok(Self {
            raster,
            dir,
            report: CountReport::default(),
            slab,
        })
    }

    /// What the pass has seen so far.
    #[must_use]
    pub const fn report(&self) -> CountReport {
        self.report
    }

    /// Ends the count pass: turns the per-brick counts into offsets.
    ///
    /// # Errors
    /// [`BuildError::TooManyRecords`] if the total exceeds `u32::MAX`.
    pub fn finish(self) -> Result<Sizing<'p, 'd>, BuildError> {
        let mut total: u32 = 0;
        for d in self.dir.iter_mut() {
            let count = *d;
            *d = total;
            total = total.checked_add(count).ok_or(BuildError::TooManyRecords)?;
        }
        // The last entry was 0 (no brick) and now holds the total.
        Ok(Sizing {
            raster: self.raster,
            dir: self.dir,
            total: to_usize(total),
            report: self.report,
            slab: self.slab,
        })
    }
}

/// Where a slab or band lies in the larger raster: its first row and its
/// first layer.
type Origin = [u32; 2];

/// `voxel` of the larger raster in a slab or band starting at `origin`,
/// or `None` before it.
#[inline]
fn local(voxel: [u32; 3], origin: Option<Origin>) -> Option<[u32; 3]> {
    match origin {
        None => Some(voxel),
        Some([y0, z0]) => Some([
            voxel[0],
            voxel[1].checked_sub(y0)?,
            voxel[2].checked_sub(z0)?,
        ]),
    }
}

/// The cell of `voxel` (of the larger raster, in a slab or band starting
/// at `slab`) in `raster`, with the voxel's local coordinates and its
/// brick; `None`, counted in `outside`, for a voxel outside the raster.
#[inline]
fn cell_of<'r>(
    raster: &'r mut RasterMut<'_>,
    slab: Option<Origin>,
    voxel: [u32; 3],
    outside: &mut u64,
) -> Option<([u32; 3], usize, &'r mut u8)> {
    let extent = raster.extent();
    let found = local(voxel, slab).and_then(|v| {
        let b = brick_of(extent, v);
        raster.cell_mut(v).map(|c| (v, b, c))
    });
    if found.is_none() {
        *outside = outside.saturating_add(1);
    }
    found
}

/// The layers of the larger raster that a raster of `extent` holds as a
/// slab or band starting at `slab` (all of it for a whole raster).
fn layers_of(extent: Extent, slab: Option<Origin>) -> Range<u32> {
    let z0 = slab.map_or(0, |[_, z0]| z0);
    z0..z0.saturating_add(extent.dims()[2])
}

/// The rows of the larger raster that a raster of `extent` holds as a
/// slab or band starting at `slab`.
fn rows_of(extent: Extent, slab: Option<Origin>) -> Range<u32> {
    let y0 = slab.map_or(0, |[y0, _]| y0);
    y0..y0.saturating_add(extent.dims()[1])
}

impl VoxelSink for Counter<'_, '_> {
    fn layers(&self) -> Range<u32> {
        layers_of(self.raster.extent(), self.slab)
    }

    fn rows(&self) -> Range<u32> {
        rows_of(self.raster.extent(), self.slab)
    }

    fn reads_surfels(&self) -> bool {
        false
    }

    fn offer(&mut self, voxel: [u32; 3], _surfel: Surfel) {
        self.report.offers = self.report.offers.saturating_add(1);
        let outside = &mut self.report.outside;
        let Some((_, b, c)) = cell_of(&mut self.raster, self.slab, voxel, outside) else {
            return;
        };
        if *c & cell::OPAQUE != 0 {
            // A repeat offer: the first marks the voxel shared, which bounds
            // its object list and tells the fill pass to look for its record.
            if *c & cell::PROXIMITY == 0 {
                *c |= cell::PROXIMITY;
                self.report.shared = self.report.shared.saturating_add(1);
            }
            return;
        }
        *c |= cell::OPAQUE;
        self.report.voxels = self.report.voxels.saturating_add(1);
        if let Some(d) = self.dir.get_mut(b) {
            // At most 512 voxels per brick are ever counted.
            *d = d.saturating_add(1);
        }
    }
}

/// Between the passes: the exact record count is known.
#[derive(Debug)]
pub struct Sizing<'p, 'd> {
    raster: RasterMut<'p>,
    /// Invariant: exclusive prefix offsets, last entry = `total`.
    dir: &'d mut [u32],
    total: usize,
    report: CountReport,
    slab: Option<Origin>,
}

impl<'p, 'd> Sizing<'p, 'd> {
    /// Number of records the fill pass needs.
    #[must_use]
    pub const fn records(&self) -> usize {
        self.total
    }

    /// Bytes of record storage the fill pass needs (`records() · 20`),
    /// saturating.
    #[must_use]
    pub const fn record_bytes(&self) -> usize {
        self.total
            .saturating_mul(core::mem::size_of::<VoxelRecord>())
    }

    /// The count pass's report.
    #[must_use]
    pub const fn report(&self) -> CountReport {
        self.report
    }

    /// An upper bound on the `u32` entries of list storage the fill pass
    /// needs: `3·repeats + 2·shared` (saturating). A voxel offered `o ≥ 2`
    /// times has at most `o` objects: its final list takes at most
    /// `1 + o` entries, and the pass links each further object in with a
    /// node of 2 entries while it runs. 0 when no voxel is offered twice.
    #[must_use]
    pub fn list_entries(&self) -> usize {
        let r = self.report.repeats();
        let bound = r
            .saturating_mul(3)
            .saturating_add(self.report.shared.saturating_mul(2));
        usize::try_from(bound).unwrap_or(usize::MAX)
    }

    /// Starts the paper's fill pass into `records` (only its first
    /// [`Sizing::records`] entries are used): one object per voxel, its
    /// owner (see *Overlap* in [`crate::store`]), and no object lists.
    ///
    /// # Errors
    /// [`BuildError::RecordStorage`] if `records` is too short.
    pub fn fill(
        self,
        records: &mut [VoxelRecord],
        limits: Limits,
    ) -> Result<Filler<'p, 'd, '_>, BuildError> {
        self.start_fill(records, &mut [], limits, false)
    }

    /// Starts the fill pass into `records` (as [`Sizing::fill`]) and the
    /// object-list storage `lists` (working space while the pass runs; the
    /// finished lists are the front of it, [`Built::lists`]): every voxel
    /// several objects offered gets the list of all of them.
    /// [`Sizing::list_entries`] entries always suffice; fewer may (the
    /// bound is loose), and when they do not, [`Filler::finish`] says so
    /// ([`BuildError::ListStorage`]).
    ///
    /// # Errors
    /// [`BuildError::RecordStorage`] if `records` is too short.
    pub fn fill_with_lists<'r>(
        self,
        records: &'r mut [VoxelRecord],
        lists: &'r mut [u32],
        limits: Limits,
    ) -> Result<Filler<'p, 'd, 'r>, BuildError> {
        self.start_fill(records, lists, limits, true)
    }

    fn start_fill<'r>(
        self,
        records: &'r mut [VoxelRecord],
        lists: &'r mut [u32],
        limits: Limits,
        listing: bool,
    ) -> Result<Filler<'p, 'd, 'r>, BuildError> {
        let found = records.len();
        let records = records
            .get_mut(..self.total)
            .ok_or(BuildError::RecordStorage {
                needed: self.total,
                found,
            })?;
        let cap = lists.len().min(MAX_LIST_ENTRIES);
        let lists = lists.get_mut(..cap).unwrap_or(&mut []);
        Ok(Filler {
            raster: self.raster,
            dir: self.dir,
            records,
            lists,
            node_top: cap,
            limits,
            current: None,
            report: FillReport::default(),
            filled: 0,
            uncounted: 0,
            no_object: 0,
            unlisted: 0,
            listing,
            slab: self.slab,
            last_object: None,
            in_order: true,
            encoded: None,
        })
    }
}

/// What the fill pass did.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct FillReport {
    /// Offers received.
    pub offers: u64,
    /// Records written (equals [`Sizing::records`] after a complete pass).
    pub records: u64,
    /// Repeat offers nearer the surface that took over a record.
    pub replaced: u64,
    /// Repeat offers that lost to the record already there.
    pub kept: u64,
    /// Offers outside the raster (or the slab), skipped.
    pub outside: u64,
    /// Voxels with an object list (offered by more than one object); set
    /// by [`Filler::finish`].
    pub listed: u64,
    /// Entries of the finished object lists ([`Built::lists`]); set by
    /// [`Filler::finish`].
    pub list_entries: u64,
}

/// The fill pass: a [`VoxelSink`] that writes records (module docs).
#[derive(Debug)]
pub struct Filler<'p, 'd, 'r> {
    raster: RasterMut<'p>,
    /// Invariant: `dir[b]` is brick `b`'s cursor, between its start and end.
    dir: &'d mut [u32],
    /// Exactly the counted number of records.
    records: &'r mut [VoxelRecord],
    /// List storage, at most [`MAX_LIST_ENTRIES`] long. While the pass
    /// runs, nodes `[object, next]` fill it from the top down (`node_top`
    /// is the lowest used entry).
    lists: &'r mut [u32],
    node_top: usize,
    limits: Limits,
    current: Option<ObjectAttrs>,
    report: FillReport,
    filled: usize,
    uncounted: u64,
    no_object: u64,
    unlisted: u64,
    /// Whether voxels several objects offer get object lists
    /// ([`Sizing::fill_with_lists`]) or keep their owner only.
    listing: bool,
    slab: Option<Origin>,
    /// The largest object id begun so far.
    last_object: Option<u32>,
    /// Whether objects have been begun in increasing id order (repeats of
    /// the current one allowed), each object's offers in one run: then an
    /// object can only be in a voxel's chain as the chain's head node, the
    /// last one added to it (see [`Filler::listed`]).
    in_order: bool,
    /// The last normal encoded and its encoding: the voxels of a planar
    /// surface are offered with one normal, encoded once.
    encoded: Option<([i32; 3], [i16; 2])>,
}

/// While the fill pass runs, a record's `lights` and first two `illum`
/// bytes (zero until the light pass) hold the head of its voxel's chain of
/// list nodes: 0 for none, else the node's index plus one.
fn chain_head(r: &VoxelRecord) -> usize {
    to_usize(u32::from(r.lights) | (u32::from(u16::from_le_bytes([r.illum[0], r.illum[1]])) << 16))
}

fn set_chain_head(r: &mut VoxelRecord, head: usize) {
    let h = u32::try_from(head).unwrap_or(0);
    // Truncations on purpose: the head is split into its two halves.
    #[allow(clippy::cast_possible_truncation)]
    {
        r.lights = h as u16;
        let [a, b] = ((h >> 16) as u16).to_le_bytes();
        r.illum[0] = a;
        r.illum[1] = b;
    }
}

/// The objects of the chain starting at `head` (see [`chain_head`]).
fn chain(lists: &[u32], head: usize) -> impl Iterator<Item = (usize, u32)> + '_ {
    let mut next = head;
    // A chain is at most as long as the nodes that fit the storage.
    (0..lists.len() / 2).map_while(move |_| {
        let at = next.checked_sub(1)?;
        let object = *lists.get(at)?;
        next = to_usize(*lists.get(at.checked_add(1)?)?);
        Some((at, object))
    })
}

/// Where the current `object` sits in the chain starting at `head`, if it
/// does. With the objects begun in order ([`Filler`]'s `in_order`), only
/// the head node can hold it: nodes are added at the head, and while an
/// object's offers run only that object is added (a voxel's owner
/// re-joins the chain only where the current object leaves it, in place).
/// Otherwise the whole chain is searched.
fn listed(lists: &[u32], in_order: bool, head: usize, object: u32) -> Option<(usize, u32)> {
    if in_order {
        let at = head.checked_sub(1)?;
        let o = *lists.get(at)?;
        (o == object).then_some((at, o))
    } else {
        chain(lists, head).find(|&(_, o)| o == object)
    }
}

/// The voxel-centre position of `v` in fixed units.
fn centre(v: [u32; 3]) -> [i64; 3] {
    v.map(crate::fixed::voxel_centre)
}

/// How many records back from a brick's cursor a repeat offer searches at
/// most when its slot hint does not find the record: a brick holds at most
/// 512.
const SCAN_LIMIT: usize = BRICK_VOXELS as usize;

/// Shift of a filled cell's *slot hint* (the bits above [`FILLED`], free
/// until [`Filler::finish`] rewrites the cell): the record's slot divided
/// by [`SLOT_BLOCK`], modulo [`SLOT_BLOCKS`]. A brick's records lie within
/// 512 slots of its cursor, so the hint names the one block of 16 slots
/// below the cursor that holds the record: a repeat offer scans at most 16
/// records instead of the brick.
const SLOT_HINT_SHIFT: u32 = cell::DISTANCE_SHIFT + 1;
/// Slots per hinted block.
const SLOT_BLOCK: usize = 16;
/// Distinct hints (5 bits): `SLOT_BLOCK · SLOT_BLOCKS` = a brick's 512.
const SLOT_BLOCKS: usize = 32;

/// The hint bits of a record at `slot` ([`SLOT_HINT_SHIFT`]).
fn slot_hint(slot: usize) -> u8 {
    // Below 32: the truncation is the modulo.
    #[allow(clippy::cast_possible_truncation)]
    let h = ((slot / SLOT_BLOCK) % SLOT_BLOCKS) as u8;
    h << SLOT_HINT_SHIFT
}

/// The slots `lo..hi` of the block a cell's hint names, below the cursor
/// `at` (see [`SLOT_HINT_SHIFT`]); empty when `at` is 0.
fn hinted_block(c: u8, at: usize) -> core::ops::Range<usize> {
    let Some(last) = at.checked_sub(1) else {
        return 0..0;
    };
    let hint = usize::from(c >> SLOT_HINT_SHIFT);
    let top = last / SLOT_BLOCK;
    let back = top.wrapping_sub(hint) % SLOT_BLOCKS;
    let lo = top.saturating_sub(back).saturating_mul(SLOT_BLOCK);
    lo..lo.saturating_add(SLOT_BLOCK).min(at)
}

impl<'p, 'd, 'r> Filler<'p, 'd, 'r> {
    /// Names the object whose voxels the following offers are.
    ///
    /// # Errors
    /// [`BuildError::ObjectOutOfRange`] or [`BuildError::MaterialOutOfRange`]
    /// against the pass's [`Limits`]; the previous object stays current.
    pub fn begin_object(&mut self, attrs: ObjectAttrs) -> Result<(), BuildError> {
        let limit = self.limits.objects.min(MAX_OBJECTS);
        if attrs.object >= limit {
            return Err(BuildError::ObjectOutOfRange {
                object: attrs.object,
                limit,
            });
        }
        if u32::from(attrs.material) >= self.limits.materials {
            return Err(BuildError::MaterialOutOfRange {
                material: attrs.material,
                limit: self.limits.materials,
            });
        }
        self.current = Some(attrs);
        if self.last_object.is_some_and(|last| attrs.object < last) {
            self.in_order = false;
        }
        self.last_object = Some(
            self.last_object
                .map_or(attrs.object, |l| l.max(attrs.object)),
        );
        Ok(())
    }

    /// A sink that colours each voxel with `texture` instead of the
    /// object's flat colour.
    pub fn textured<'s, T: Texture>(&'s mut self, texture: &'s T) -> Textured<'s, 'p, 'd, 'r, T> {
        Textured {
            filler: self,
            texture,
        }
    }

    /// What the pass has done so far.
    #[must_use]
    pub const fn report(&self) -> FillReport {
        self.report
    }

    fn put<T: Texture + ?Sized>(&mut self, global: [u32; 3], surfel: Surfel, texture: Option<&T>) {
        self.report.offers = self.report.offers.saturating_add(1);
        let Some(attrs) = self.current else {
            self.no_object = self.no_object.saturating_add(1);
            return;
        };
        let outside = &mut self.report.outside;
        let Some((v, b, c)) = cell_of(&mut self.raster, self.slab, global, outside) else {
            return;
        };
        if *c & cell::OPAQUE == 0 {
            self.uncounted = self.uncounted.saturating_add(1);
            return;
        }
        let key = make_key(v, surfel.distance);
        let encoded = &mut self.encoded;
        let mut make = |attrs: ObjectAttrs| {
            let normal = match *encoded {
                Some((n, e)) if n == surfel.normal => e,
                _ => {
                    let e = encode_normal(surfel.normal);
                    *encoded = Some((surfel.normal, e));
                    e
                }
            };
            let color = match texture {
                Some(t) => t.color(centre(global), surfel.normal, attrs.color),
                None => attrs.color,
            };
            VoxelRecord {
                object: attrs.object,
                normal,
                color,
                illum: [0; 3],
                lights: 0,
                material: attrs.material,
                key,
            }
        };
        let Some(cursor) = self.dir.get_mut(b) else {
            self.uncounted = self.uncounted.saturating_add(1);
            return;
        };
        let at = to_usize(*cursor);
        if *c & FILLED == 0 {
            // First offer of this voxel in the fill pass. The count pass
            // counted every OPAQUE voxel of the brick once and each gets one
            // slot, so the cursor is still inside the brick's range.
            let Some(slot) = self.records.get_mut(at) else {
                self.uncounted = self.uncounted.saturating_add(1);
                return;
            };
            *slot = make(attrs);
            *c |= FILLED | slot_hint(at);
            *cursor = cursor.saturating_add(1);
            self.filled = self.filled.saturating_add(1);
            self.report.records = self.report.records.saturating_add(1);
            return;
        }
        if *c & cell::PROXIMITY == 0 {
            // The count pass saw this voxel once: the passes differ.
            self.uncounted = self.uncounted.saturating_add(1);
            return;
        }
        // Marked: its record is among this brick's filled records, just
        // below the cursor, in the block its hint names. Scanning that
        // block down from its top meets this brick's records before any
        // earlier brick's (positions repeat only across bricks); the whole
        // brick is the fallback.
        let pos = key & KEY_POSITION_MASK;
        let block = hinted_block(*c, at);
        let found = self
            .records
            .get(block.clone())
            .and_then(|b| b.iter().rposition(|r| r.position() == pos))
            .map(|i| block.start.saturating_add(i))
            .or_else(|| {
                let filled = self.records.get(..at)?;
                let back = filled
                    .iter()
                    .rev()
                    .take(SCAN_LIMIT)
                    .position(|r| r.position() == pos)?;
                at.checked_sub(back)?.checked_sub(1)
            });
        let Some(r) = found.and_then(|i| self.records.get_mut(i)) else {
            return;
        };
        let nearer = (key >> crate::voxel::KEY_DISTANCE_SHIFT) < r.distance();
        let owner = r.object;
        let mut head = chain_head(r);
        if self.listing && attrs.object != owner {
            // The chain holds every object of the voxel but its owner, once.
            let listed = listed(self.lists, self.in_order, head, attrs.object);
            let add = match (nearer, listed) {
                // The new owner leaves the chain, the old one joins it.
                (true, Some((at, _))) => {
                    if let Some(slot) = self.lists.get_mut(at) {
                        *slot = owner;
                    }
                    None
                }
                (true, None) => Some(owner),
                (false, None) => Some(attrs.object),
                (false, Some(_)) => None,
            };
            if let Some(object) = add {
                let node = self
                    .node_top
                    .checked_sub(2)
                    .and_then(|top| Some((top, self.lists.get_mut(top..self.node_top)?)));
                match node {
                    Some((top, [o, next])) => {
                        *o = object;
                        // head < 2^31: the storage is at most MAX_LIST_ENTRIES long.
                        *next = u32::try_from(head).unwrap_or(0);
                        self.node_top = top;
                        head = top.saturating_add(1);
                    }
                    _ => self.unlisted = self.unlisted.saturating_add(1),
                }
            }
        }
        if nearer {
            *r = make(attrs);
            self.report.replaced = self.report.replaced.saturating_add(1);
        } else {
            self.report.kept = self.report.kept.saturating_add(1);
        }
        set_chain_head(r, head);
    }

    /// Ends the fill pass: checks it matched the count pass, restores the
    /// directory, sorts each brick, lays out the object lists, writes the
    /// rank hints ([`super::write_rank_hints`]) and, for a whole raster (not
    /// a [`Counter::slab`]), sets the proximity flags.
    ///
    /// # Errors
    /// [`BuildError::OfferWithoutObject`], [`BuildError::PassMismatch`] or
    /// [`BuildError::FillIncomplete`] when the fill pass did not voxelize
    /// the scene the count pass did; [`BuildError::ListStorage`] when the
    /// object lists did not fit the list storage. The plane and directory
    /// are then in an unspecified (but memory-safe) state: start again with
    /// [`Counter`].
    pub fn finish(self) -> Result<Built<'p, 'd, 'r>, BuildError> {
        if self.no_object > 0 {
            return Err(BuildError::OfferWithoutObject {
                offers: self.no_object,
            });
        }
        if self.uncounted > 0 {
            return Err(BuildError::PassMismatch {
                uncounted: self.uncounted,
            });
        }
        // Each brick's writes are bounded by its count, so equal totals mean
        // every brick is full and each cursor sits at its brick's end.
        if self.filled != self.records.len() {
            return Err(BuildError::FillIncomplete {
                filled: self.filled,
                expected: self.records.len(),
            });
        }
        let cap = self.lists.len();
        // Two entries per node.
        let node_entries = cap.saturating_sub(self.node_top);
        if self.unlisted > 0 {
            return Err(BuildError::ListStorage {
                needed: cap.saturating_add(
                    usize::try_from(self.unlisted)
                        .unwrap_or(usize::MAX)
                        .saturating_mul(2),
                ),
                found: cap,
            });
        }
        let dir: &'d mut [u32] = self.dir;
        // dir[b] is now end(b) = start(b + 1): shift right by one.
        let bricks = dir.len().saturating_sub(1);
        let mut prev = 0u32;
        for d in dir.iter_mut().take(bricks) {
            prev = core::mem::replace(d, prev);
        }
        for w in dir.windows(2) {
            if let [lo, hi] = *w
                && let Some(s) = self.records.get_mut(to_usize(lo)..to_usize(hi))
            {
                s.sort_unstable_by_key(VoxelRecord::position);
            }
        }
        let mut report = self.report;
        let used = lay_out_lists(self.records, self.lists, self.node_top, &mut report).ok_or(
            BuildError::ListStorage {
                needed: list_space(self.records, node_entries / 2).saturating_add(node_entries),
                found: cap,
            },
        )?;
        let all: &'r [u32] = self.lists;
        let lists = all.get(..used).unwrap_or(&[]);
        let dir: &'d [u32] = dir;
        let mut raster = self.raster;
        let store = RecordStore {
            extent: raster.extent(),
            dir,
            records: self.records,
            lists,
        };
        if self.slab.is_some() {
            // Clears the fill and count marks; the flags come later.
            set_opaque_cells(&mut raster, &store, cell::OPAQUE);
        } else {
            set_opaque_cells(&mut raster, &store, cell::OPAQUE | cell::PROXIMITY);
            if store.len().saturating_mul(DENSE_RATIO) > raster.extent().len() {
                // Dense scene: the whole-plane pass is cheaper.
                crate::proximity::flag_neighbourhood(&mut raster);
            } else {
                flag_proximity(&mut raster, &store);
            }
        }
        Ok(Built {
            raster,
            dir,
            records: self.records,
            lists,
            report,
            slab: self.slab,
        })
    }
}

/// Entries the finished lists of `records` take: `1 + n` per voxel of `n`
/// objects (its chain's length plus the owner), from the `nodes` the
/// chains hold between them: every node the fill pass adds becomes the
/// head of its voxel's chain, so each lies on exactly one chain, and
/// `2` per listed voxel (its length and owner) plus `nodes` is the sum
/// without walking a chain.
fn list_space(records: &[VoxelRecord], nodes: usize) -> usize {
    records
        .iter()
        .filter(|r| chain_head(r) != 0)
        .count()
        .saturating_mul(2)
        .saturating_add(nodes)
}

/// Writes the finished object lists to the front of `lists`, in the
/// records' (final) order, from the chains of nodes at `node_top..`; points
/// each listed record at its list and clears the chain heads. `None` (and
/// nothing changed) when the lists would reach the nodes not yet read.
fn lay_out_lists(
    records: &mut [VoxelRecord],
    lists: &mut [u32],
    node_top: usize,
    report: &mut FillReport,
) -> Option<usize> {
    let nodes = lists.len().saturating_sub(node_top) / 2;
    if list_space(records, nodes) > node_top {
        return None;
    }
    let mut w = 0usize;
    for r in records.iter_mut() {
        let head = chain_head(r);
        set_chain_head(r, 0);
        if head == 0 {
            continue;
        }
        // The lists written so far end below every node (checked above).
        let start = w;
        // Never onto a node (the count above makes that impossible).
        let mut put = |lists: &mut [u32], x: u32| {
            if let Some(slot) = lists.get_mut(w).filter(|_| w < node_top) {
                *slot = x;
            }
            w = w.saturating_add(1);
        };
        put(lists, 0);
        put(lists, r.object);
        let mut n = 1u32;
        let mut next = head;
        while let Some(at) = next.checked_sub(1) {
            let (Some(&o), Some(&nx)) = (lists.get(at), lists.get(at.saturating_add(1))) else {
                break;
            };
            put(lists, o);
            n = n.saturating_add(1);
            next = to_usize(nx);
        }
        if let Some(len) = lists.get_mut(start) {
            *len = n;
        }
        if let Some(others) = lists.get_mut(start.saturating_add(2)..w) {
            others.sort_unstable();
        }
        // start < w <= node_top <= MAX_LIST_ENTRIES < 2^31.
        r.object = OBJECT_LIST | u32::try_from(start).unwrap_or(0);
        report.listed = report.listed.saturating_add(1);
    }
    report.list_entries = u64::try_from(w).unwrap_or(u64::MAX);
    Some(w)
}

/// Adds `by` to the list index of every record of `records` that names an
/// object list: the fix-up when slabs' lists are concatenated (see
/// [`Counter::slab`]).
///
/// # Errors
/// [`BuildError::ListStorage`] when an index would pass
/// [`MAX_LIST_ENTRIES`](super::MAX_LIST_ENTRIES); the records are then
/// partly shifted.
pub fn shift_lists(records: &mut [VoxelRecord], by: usize) -> Result<(), BuildError> {
    if by == 0 {
        return Ok(());
    }
    for r in records.iter_mut() {
        if let Some(i) = list_index(r) {
            let j = i
                .checked_add(by)
                .filter(|&j| j < MAX_LIST_ENTRIES)
                .and_then(|j| u32::try_from(j).ok())
                .ok_or(BuildError::ListStorage {
                    needed: i.saturating_add(by),
                    found: MAX_LIST_ENTRIES,
                })?;
            r.object = OBJECT_LIST | j;
        }
    }
    Ok(())
}

impl VoxelSink for Filler<'_, '_, '_> {
    fn offer(&mut self, voxel: [u32; 3], surfel: Surfel) {
        self.put::<dyn Texture>(voxel, surfel, None);
    }

    fn layers(&self) -> Range<u32> {
        layers_of(self.raster.extent(), self.slab)
    }

    fn rows(&self) -> Range<u32> {
        rows_of(self.raster.extent(), self.slab)
    }
}

/// A fill-pass sink that colours voxels with a [`Texture`]
/// ([`Filler::textured`]).
#[derive(Debug)]
pub struct Textured<'s, 'p, 'd, 'r, T: Texture> {
    filler: &'s mut Filler<'p, 'd, 'r>,
    texture: &'s T,
}

impl<T: Texture> VoxelSink for Textured<'_, '_, '_, '_, T> {
    fn offer(&mut self, voxel: [u32; 3], surfel: Surfel) {
        self.filler.put(voxel, surfel, Some(self.texture));
    }

    fn layers(&self) -> Range<u32> {
        self.filler.layers()
    }

    fn rows(&self) -> Range<u32> {
        self.filler.rows()
    }
}

/// A built scene: the plane (with OPAQUE, the rank hints and, for a whole
/// raster, PROXIMITY set) and the store.
#[derive(Debug)]
pub struct Built<'p, 'd, 'r> {
    raster: RasterMut<'p>,
    dir: &'d [u32],
    records: &'r mut [VoxelRecord],
    lists: &'r [u32],
    report: FillReport,
    slab: Option<Origin>,
}

impl<'p, 'd, 'r> Built<'p, 'd, 'r> {
    /// The raster (read-only).
    #[must_use]
    pub fn raster(&self) -> Raster<'_> {
        self.raster.as_raster()
    }

    /// The record store (read-only).
    #[must_use]
    pub fn store(&self) -> RecordStore<'_> {
        RecordStore {
            extent: self.raster.extent(),
            dir: self.dir,
            records: self.records,
            lists: self.lists,
        }
    }

    /// The finished object lists: the front of the list storage given to
    /// [`Sizing::fill`], [`FillReport::list_entries`] long.
    #[must_use]
    pub const fn lists(&self) -> &'r [u32] {
        self.lists
    }

    /// For a slab ([`Counter::slab`]) or band ([`Counter::band`]), its
    /// first layer in the larger raster; `None` for a whole raster.
    #[must_use]
    pub const fn slab(&self) -> Option<u32> {
        match self.slab {
            Some([_, z0]) => Some(z0),
            None => None,
        }
    }

    /// The raster and a writable store at once (for the light pass).
    pub fn split(&mut self) -> (Raster<'_>, RecordStoreMut<'_>) {
        (
            self.raster.as_raster(),
            RecordStoreMut {
                extent: self.raster.extent(),
                dir: self.dir,
                records: self.records,
                lists: self.lists,
            },
        )
    }

    /// The fill pass's report.
    #[must_use]
    pub const fn report(&self) -> FillReport {
        self.report
    }

    /// Gives back the writable raster and the store.
    pub fn into_parts<'a>(self) -> (RasterMut<'p>, RecordStoreMut<'a>)
    where
        'd: 'a,
        'r: 'a,
    {
        let extent = self.raster.extent();
        (
            self.raster,
            RecordStoreMut {
                extent,
                dir: self.dir,
                records: self.records,
                lists: self.lists,
            },
        )
    }
}
