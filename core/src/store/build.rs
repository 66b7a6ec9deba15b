//! The two-pass scene builder: the count pass sizes the records, the fill
//! pass writes them (see the [module docs](super)).

use super::brick::{BRICK_VOXELS, brick_of, directory_len};
use super::error::BuildError;
use super::proximity::{DENSE_RATIO, flag_proximity};
use super::texture::Texture;
use super::{RecordStore, RecordStoreMut};
use crate::raster::{Raster, RasterMut, cell, to_usize};
use crate::voxel::{KEY_POSITION_MASK, VoxelRecord, encode_normal, make_key};
use crate::voxelize::{Surfel, VoxelSink};

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
    /// Offers outside the raster, skipped.
    pub outside: u64,
}

/// The count pass: a [`VoxelSink`] that sets [`cell::OPAQUE`] and counts
/// new voxels per brick (module docs).
#[derive(Debug)]
pub struct Counter<'p, 'd> {
    raster: RasterMut<'p>,
    dir: &'d mut [u32],
    report: CountReport,
}

impl<'p, 'd> Counter<'p, 'd> {
    /// Starts a scene: clears the plane and the directory.
    ///
    /// # Errors
    /// [`BuildError::DirectoryLength`] unless `dir.len()` is
    /// [`directory_len`] of the raster.
    pub fn new(mut raster: RasterMut<'p>, dir: &'d mut [u32]) -> Result<Self, BuildError> {
        let expected = directory_len(raster.extent()).unwrap_or(usize::MAX);
        if dir.len() != expected {
            return Err(BuildError::DirectoryLength {
                expected,
                found: dir.len(),
            });
        }
        raster.plane_mut().fill(cell::EMPTY);
        dir.fill(0);
        Ok(Self {
            raster,
            dir,
            report: CountReport::default(),
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
        })
    }
}

impl VoxelSink for Counter<'_, '_> {
    fn offer(&mut self, voxel: [u32; 3], _surfel: Surfel) {
        self.report.offers = self.report.offers.saturating_add(1);
        let extent = self.raster.extent();
        let b = brick_of(extent, voxel);
        let Some(c) = self.raster.cell_mut(voxel) else {
            self.report.outside = self.report.outside.saturating_add(1);
            return;
        };
        if *c & cell::OPAQUE != 0 {
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

    /// Starts the fill pass into `records` (only its first
    /// [`Sizing::records`] entries are used).
    ///
    /// # Errors
    /// [`BuildError::RecordStorage`] if `records` is too short.
    pub fn fill<'r>(
        self,
        records: &'r mut [VoxelRecord],
        limits: Limits,
    ) -> Result<Filler<'p, 'd, 'r>, BuildError> {
        let found = records.len();
        let records = records
            .get_mut(..self.total)
            .ok_or(BuildError::RecordStorage {
                needed: self.total,
                found,
            })?;
        Ok(Filler {
            raster: self.raster,
            dir: self.dir,
            records,
            limits,
            current: None,
            report: FillReport::default(),
            filled: 0,
            uncounted: 0,
            no_object: 0,
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
    /// Offers outside the raster, skipped.
    pub outside: u64,
}

/// The fill pass: a [`VoxelSink`] that writes records (module docs).
#[derive(Debug)]
pub struct Filler<'p, 'd, 'r> {
    raster: RasterMut<'p>,
    /// Invariant: `dir[b]` is brick `b`'s cursor, between its start and end.
    dir: &'d mut [u32],
    /// Exactly the counted number of records.
    records: &'r mut [VoxelRecord],
    limits: Limits,
    current: Option<ObjectAttrs>,
    report: FillReport,
    filled: usize,
    uncounted: u64,
    no_object: u64,
}

/// The voxel-centre position of `v` in fixed units.
fn centre(v: [u32; 3]) -> [i64; 3] {
    v.map(crate::fixed::voxel_centre)
}

/// How many records back from a brick's cursor a repeat offer searches at
/// most: a brick holds at most 512.
const SCAN_LIMIT: usize = BRICK_VOXELS as usize;

impl<'p, 'd, 'r> Filler<'p, 'd, 'r> {
    /// Names the object whose voxels the following offers are.
    ///
    /// # Errors
    /// [`BuildError::ObjectOutOfRange`] or [`BuildError::MaterialOutOfRange`]
    /// against the pass's [`Limits`]; the previous object stays current.
    pub fn begin_object(&mut self, attrs: ObjectAttrs) -> Result<(), BuildError> {
        if attrs.object >= self.limits.objects {
            return Err(BuildError::ObjectOutOfRange {
                object: attrs.object,
                limit: self.limits.objects,
            });
        }
        if u32::from(attrs.material) >= self.limits.materials {
            return Err(BuildError::MaterialOutOfRange {
                material: attrs.material,
                limit: self.limits.materials,
            });
        }
        self.current = Some(attrs);
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

    fn put<T: Texture + ?Sized>(&mut self, v: [u32; 3], surfel: Surfel, texture: Option<&T>) {
        self.report.offers = self.report.offers.saturating_add(1);
        let Some(attrs) = self.current else {
            self.no_object = self.no_object.saturating_add(1);
            return;
        };
        let extent = self.raster.extent();
        let b = brick_of(extent, v);
        let Some(c) = self.raster.cell_mut(v) else {
            self.report.outside = self.report.outside.saturating_add(1);
            return;
        };
        if *c & cell::OPAQUE == 0 {
            self.uncounted = self.uncounted.saturating_add(1);
            return;
        }
        let key = make_key(v, surfel.distance);
        let make = |attrs: ObjectAttrs| {
            let color = match texture {
                Some(t) => t.color(centre(v), surfel.normal, attrs.color),
                None => attrs.color,
            };
            VoxelRecord {
                object: attrs.object,
                normal: encode_normal(surfel.normal),
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
        if *c & cell::PROXIMITY == 0 {
            // First offer of this voxel in the fill pass. The count pass
            // counted every OPAQUE voxel of the brick once and each gets one
            // slot, so the cursor is still inside the brick's range.
            let Some(slot) = self.records.get_mut(at) else {
                self.uncounted = self.uncounted.saturating_add(1);
                return;
            };
            *slot = make(attrs);
            *c |= cell::PROXIMITY;
            *cursor = cursor.saturating_add(1);
            self.filled = self.filled.saturating_add(1);
            self.report.records = self.report.records.saturating_add(1);
        } else {
            // Marked: its record is among this brick's filled records, just
            // below the cursor; scan back to it.
            let pos = key & KEY_POSITION_MASK;
            let Some(filled) = self.records.get_mut(..at) else {
                return;
            };
            let found = filled
                .iter_mut()
                .rev()
                .take(SCAN_LIMIT)
                .find(|r| r.position() == pos);
            if let Some(r) = found {
                if (key >> crate::voxel::KEY_DISTANCE_SHIFT) < r.distance() {
                    *r = make(attrs);
                    self.report.replaced = self.report.replaced.saturating_add(1);
                } else {
                    self.report.kept = self.report.kept.saturating_add(1);
                }
            }
        }
    }

    /// Ends the fill pass: checks it matched the count pass, restores the
    /// directory, sorts each brick and sets the proximity flags.
    ///
    /// # Errors
    /// [`BuildError::OfferWithoutObject`], [`BuildError::PassMismatch`] or
    /// [`BuildError::FillIncomplete`] when the fill pass did not voxelize
    /// the scene the count pass did. The plane and directory are then in an
    /// unspecified (but memory-safe) state: start again with [`Counter`].
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
        let dir: &'d [u32] = dir;
        let mut raster = self.raster;
        let store = RecordStore {
            extent: raster.extent(),
            dir,
            records: self.records,
        };
        if store.len().saturating_mul(DENSE_RATIO) > raster.extent().len() {
            // Dense scene: the whole-plane pass is cheaper. It recomputes
            // PROXIMITY from OPAQUE, which also clears the fill marks.
            crate::proximity::flag_neighbourhood(&mut raster);
        } else {
            flag_proximity(&mut raster, &store);
        }
        Ok(Built {
            raster,
            dir,
            records: self.records,
            report: self.report,
        })
    }
}

impl VoxelSink for Filler<'_, '_, '_> {
    fn offer(&mut self, voxel: [u32; 3], surfel: Surfel) {
        self.put::<dyn Texture>(voxel, surfel, None);
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
}

/// A built scene: the plane (with OPAQUE and PROXIMITY set) and the store.
#[derive(Debug)]
pub struct Built<'p, 'd, 'r> {
    raster: RasterMut<'p>,
    dir: &'d [u32],
    records: &'r mut [VoxelRecord],
    report: FillReport,
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
            },
        )
    }
}
