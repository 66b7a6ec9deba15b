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
//! bytes per voxel. Every non-transparent voxel adds one 20-byte record; a
//! voxel that `n ≥ 2` objects share adds an object list of `1 + n` `u32`s.
//!
//! # Object lists
//! A voxel's record holds its *owner's* attributes (the object whose
//! surface passes nearest the voxel centre, see *Overlap*): what shading
//! and the paper's discrete hit use. Exact verification needs every object
//! whose surface passes through the voxel, so a voxel offered by several
//! objects also gets a list of all of them, found in O(1) from the record
//! ([`RecordStore::objects`], the owner first; [`RecordStore::owner`]).
//! A voxel of one object pays nothing: its record holds the id itself.
//!
//! *Layout:* with bit 31 of [`VoxelRecord::object`] set, its low 31 bits
//! index the list array, where the list is `[n, owner, others…]`: `n ≥ 2`
//! ids, the others in increasing id order. Lists follow the records'
//! storage order without gaps, so the array is exactly as long as the
//! lists and a loaded file is checked in one pass
//! ([`RecordStore::with_lists`]). Object ids are below 2^31.
//!
//! *Capacity:* no per-voxel limit (a list holds every object that offered
//! the voxel, each once); at most [`MAX_LIST_ENTRIES`] entries in all.
//! Lists that do not fit the storage given refuse the scene
//! ([`BuildError::ListStorage`]): no object is ever dropped silently.
//!
//! # Building
//! The scene is voxelized twice through the same voxelizers:
//! 1. **count** ([`Counter`], a [`VoxelSink`]): clears the plane and the
//!    directory, sets [`cell::OPAQUE`] on each offered voxel (and
//!    [`cell::PROXIMITY`] on one offered again) and counts the newly set
//!    ones per brick in the directory itself. O(voxels offered).
//! 2. [`Counter::finish`] turns the counts into prefix offsets and gives the
//!    exact record count ([`Sizing::records`]) and a bound on the object
//!    lists' storage ([`Sizing::list_entries`]): an embedded caller sizes
//!    static arrays with them, a host refuses a scene that does not fit.
//! 3. **fill** ([`Filler`], a [`VoxelSink`]): the caller names each object
//!    with [`Filler::begin_object`] and voxelizes it again. A voxel's record
//!    goes to its brick's cursor, the directory entry itself (counting sort,
//!    no extra memory). A voxel offered again (by the same or another
//!    object) is found by scanning back from its brick's cursor; the offer
//!    nearer the surface keeps it (see *Overlap*), and an object not yet
//!    listed for it is linked in (dedup per voxel).
//! 4. [`Filler::finish`] restores the directory, sorts each brick's records
//!    by position, lays out the object lists in that order, writes the
//!    rank hints ([`write_rank_hints`]) and sets the proximity flags around
//!    every record ([`flag_proximity`], or the whole-plane pass for a dense
//!    scene, see [`DENSE_RATIO`]), giving a [`Built`] scene.
//!
//! While the passes run, the builder marks voxels in their own (opaque)
//! cells: PROXIMITY for "offered more than once", a distance bit for "has
//! its record"; `finish` rewrites every opaque cell, and transparent cells
//! keep distance bits 0.
//!
//! **Slabs.** [`Counter::slab`] builds the layers `z0 .. z0 + nz` of a
//! larger raster on their own: bricks are in z-major order, so the slab's
//! plane, directory, records and lists are contiguous ranges of the whole
//! scene's, and slabs built independently (on any number of threads) are
//! concatenated into exactly the bytes one whole build of the same slabs
//! gives. The slab's sinks name its layers
//! ([`VoxelSink::layers`](crate::voxelize::VoxelSink::layers)), so the
//! voxelizers skip the rest of the raster; [`Counter::slab_zeroed`] starts
//! on fresh zeroed memory without reading it.
//!
//! # Overlap
//! When two offers claim one voxel, the one whose surface is nearer the
//! voxel centre ([`Surfel::distance`], compared at the key's 1/128-voxel
//! quantization) owns it; on a tie the earlier offer stays. This makes the
//! owner independent of the order in which touching objects are
//! voxelized, up to ties; the list holds every one of them either way.
//!
//! # Bad input
//! Offers outside the raster are skipped and counted
//! ([`CountReport::outside`], [`FillReport::outside`]). A fill pass that
//! offers a voxel the count pass did not, offers without an object, or
//! leaves counted voxels without a record is refused by
//! [`Filler::finish`] with a [`BuildError`]. Nothing panics.
//!
//! [`VoxelRecord::key`]: crate::voxel::VoxelRecord::key
//! [`VoxelRecord::object`]: crate::voxel::VoxelRecord::object
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
//! let mut lists = vec![0u32; sizing.list_entries()];
//! let mut filler = sizing.fill_with_lists(&mut records, &mut lists, Limits { objects: 1, materials: 1 }).unwrap();
//! filler.begin_object(ObjectAttrs { object: 0, material: 0, color: [255, 0, 0] }).unwrap();
//! row(&mut filler);
//! let built = filler.finish().unwrap();
//! let store = built.store();
//! let index = extent.index([4, 3, 3]).unwrap();
//! assert_eq!(store.get(index).unwrap().color, [255, 0, 0]);
//! assert!(store.get(index + 64).is_none());
//! ```

// One concept per file: `brick` (the layout), `directory` (the store and
// its lookups), `list` (the object lists), `rank_hint`, `build` (the two
// passes), `proximity` (the flags around the records), `texture`, `error`.

mod brick;
mod build;
mod directory;
mod error;
mod list;
mod proximity;
mod rank_hint;
#[cfg(test)]
mod tests;
mod texture;

pub use brick::{BRICK, BRICK_BITS, BRICK_VOXELS, brick_count, brick_dims, directory_len};
pub use build::{
    Built, CountReport, Counter, FillReport, Filler, Limits, ObjectAttrs, Sizing, Textured,
    shift_lists,
};
pub use directory::{RecordStore, RecordStoreMut};
pub use error::{BuildError, StoreError};
pub use list::MAX_LIST_ENTRIES;
pub use proximity::{DENSE_RATIO, flag_proximity};
pub use rank_hint::{cell_hint, rank_hint, write_rank_hints};
pub use texture::Texture;
