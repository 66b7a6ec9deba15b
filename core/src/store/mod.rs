//! Voxel records that scale: a dense brick directory over a sorted record
//! array, and the two-pass scene builder that fills them.
//!
//! # Layout
//! The raster is cut into 8×8×8 *bricks* (partial at the high faces), in
//! linear order `bx + nbx·(by + nby·bz)`. Records exist only for
//! non-transparent voxels; they are sorted by brick, and inside a brick by
//! the position bits of [`VoxelRecord::key`]. The *directory* holds one
//! `u32` offset per brick plus one: brick `b`'s records are
//! `records[dir[b]..dir[b + 1]]`, and `dir[last] == records.len()`. A lookup
//! finds the brick from the coordinates and binary-searches the position
//! among at most 512 records: O(log 512). An opaque cell's distance bits
//! carry its record's *rank hint* ([`write_rank_hints`]), which narrows a
//! lookup from the plane ([`RecordStore::get_hinted`]) to a window of about
//! `n/64 + 1` of the brick's `n` records.
//!
//! **Memory.** Everything that scales with the raster volume is the plane
//! (1 byte per voxel) and the directory (4 bytes per 512 voxels): 1.008
//! bytes per voxel. Every non-transparent voxel adds one 20-byte record.
//!
//! # Building
//! The scene is voxelized twice through the same voxelizers:
//! 1. **count** ([`Counter`], a [`VoxelSink`]): clears the plane and the
//!    directory, sets [`cell::OPAQUE`] on each offered voxel and counts the
//!    newly set ones per brick in the directory itself. O(voxels offered).
//! 2. [`Counter::finish`] turns the counts into prefix offsets and gives the
//!    exact record count ([`Sizing::records`]): an embedded caller sizes a
//!    static array with it, a host refuses a scene that does not fit.
//! 3. **fill** ([`Filler`], a [`VoxelSink`]): the caller names each object
//!    with [`Filler::begin_object`] and voxelizes it again. A voxel's record
//!    goes to its brick's cursor, the directory entry itself (counting sort,
//!    no extra memory). A voxel offered again (by the same or another
//!    object) is found by scanning back from its brick's cursor, and the
//!    offer nearer the surface keeps it (see *Overlap*).
//! 4. [`Filler::finish`] restores the directory, sorts each brick's records
//!    by position and sets the proximity flags around every record
//!    ([`flag_proximity`], or the whole-plane pass for a dense scene, see
//!    [`DENSE_RATIO`]), giving a [`Built`] scene.
//!
//! During the fill pass the builder uses the plane's [`cell::PROXIMITY`]
//! bit to mark voxels that already have a record; `finish` recomputes the
//! flag, so the plane's bits 2..8 (the reserved proximity distance) are
//! never touched.
//!
//! # Overlap
//! When two offers claim one voxel, the one whose surface is nearer the
//! voxel centre ([`Surfel::distance`], compared at the key's 1/128-voxel
//! quantization) owns it; on a tie the earlier offer stays. This makes the
//! result independent of the order in which touching objects are
//! voxelized, up to ties.
//!
//! # Bad input
//! Offers outside the raster are skipped and counted
//! ([`CountReport::outside`], [`FillReport::outside`]). A fill pass that
//! offers a voxel the count pass did not, offers without an object, or
//! leaves counted voxels without a record is refused by
//! [`Filler::finish`] with a [`BuildError`]. Nothing panics.
//!
//! [`VoxelRecord::key`]: crate::voxel::VoxelRecord::key
//! [`VoxelSink`]: crate::voxelize::VoxelSink
//! [`Surfel::distance`]: crate::voxelize::Surfel::distance
//! [`cell::OPAQUE`]: crate::raster::cell::OPAQUE
//! [`cell::PROXIMITY`]: crate::raster::cell::PROXIMITY
//!
//! ```
//! use rrt_core::raster::{Extent, RasterMut};
//! use rrt_core::store::{directory_len, Counter, Limits, ObjectAttrs};
//! use rrt_core::voxel::VoxelRecord;
//! use rrt_core::voxelize::{Surfel, VoxelSink, NORMAL_ONE};
//!
//! // A tiny "voxelizer": one row of voxels.
//! fn row(sink: &mut impl VoxelSink) {
//!     for x in 2..6 {
//!         sink.offer([x, 3, 3], Surfel { normal: [0, 0, NORMAL_ONE], distance: 0 });
//!     }
//! }
//! let extent = Extent::cube(16).unwrap();
//! let mut plane = vec![0u8; extent.len()];
//! let mut dir = vec![0u32; directory_len(extent).unwrap()];
//! let mut counter = Counter::new(RasterMut::new(extent, &mut plane).unwrap(), &mut dir).unwrap();
//! row(&mut counter);
//! let sizing = counter.finish().unwrap();
//! let mut records = vec![VoxelRecord::default(); sizing.records()];
//! let mut filler = sizing.fill(&mut records, Limits { objects: 1, materials: 1 }).unwrap();
//! filler.begin_object(ObjectAttrs { object: 0, material: 0, color: [255, 0, 0] }).unwrap();
//! row(&mut filler);
//! let built = filler.finish().unwrap();
//! let store = built.store();
//! let index = extent.index([4, 3, 3]).unwrap();
//! assert_eq!(store.get(index).unwrap().color, [255, 0, 0]);
//! assert!(store.get(index + 64).is_none());
//! ```

// One concept per file: `brick` (the layout), `directory` (the store and
// its lookups), `rank_hint`, `build` (the two passes), `proximity` (the
// flags around the records), `texture`, `error`.

mod brick;
mod build;
mod directory;
mod error;
mod proximity;
mod rank_hint;
#[cfg(test)]
mod tests;
mod texture;

pub use brick::{BRICK, BRICK_BITS, BRICK_VOXELS, brick_count, brick_dims, directory_len};
pub use build::{
    Built, CountReport, Counter, FillReport, Filler, Limits, ObjectAttrs, Sizing, Textured,
};
pub use directory::{RecordStore, RecordStoreMut};
pub use error::{BuildError, StoreError};
pub use proximity::{DENSE_RATIO, flag_proximity};
pub use rank_hint::{cell_hint, rank_hint, write_rank_hints};
pub use texture::Texture;
