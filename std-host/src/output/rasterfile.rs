//! Saved rasters: a voxelized scene in one versioned, checksummed file, so
//! that the view-independent work (voxelization, light visibility,
//! precomputed illumination) is done once and the scene rendered from any
//! view (the paper's point).
//!
//! # Layout (versions 1 and 2: dense)
//! All integers and floats are little-endian; floats are IEEE 754 `f64`.
//!
//! ```text
//! offset  size  field
//!      0     8  magic "RRTRASTR"
//!      8     4  version (1: the paper's raster, 2: an exact raster, with object lists)
//!     12     4  section count n (7 for version 1, 8 for version 2)
//!     16  24·n  section table: n × { kind u32, crc32 u32, offset u64, length u64 }
//! 16+24n     4  crc32 of the bytes before it
//! 20+24n     4  zero, then zeros up to H
//!      H        sections, in table order, each starting at a multiple of 64
//!               (H = 192 for version 1, 256 for version 2), zeros between
//!               them; the file ends with the last section padded with
//!               zeros to a multiple of 64
//! ```
//!
//! [`Format::Dense`] writes the paper's raster (one object per voxel) as
//! version 1 and an exact raster ([`VoxelScene::exact`]: conservative,
//! with object lists, possibly none) as version 2; [`Format::Sparse`], the
//! default, writes both as version 3 (below).
//!
//! | kind | section | contents |
//! |---|---|---|
//! | 1 | meta | `nx ny nz` u32; separation u8 (6 or 26); what the light bits of records of exact objects hold u8 (0 the paper's bits, 1 the shadow classification, 2 nothing: always 0 in version 1; [`VoxelScene::exact_records`]) + 2 zero bytes; world origin 3×f64; voxel size f64; background 3×f64; view: from, at, up 3×f64 each, angle f64, hither f64, resolution 2×u32; counts: records u64, objects u64, materials u32, lights u32 (192 bytes) |
//! | 2 | plane | one cell per voxel, x fastest ([`rrt_core::raster`]) |
//! | 3 | directory | brick directory, `bricks + 1` × u32 ([`rrt_core::store`]) |
//! | 4 | records | the 20-byte [`VoxelRecord`]s, field by field as in [`rrt_core::voxel`] |
//! | 5 | objects | per object 168 bytes: kind u32 (1 sphere, 2 cone, 3 triangle, 4 triangle with vertex normals, 5 voxels only: volume, `.vox` or CSG, slot 0 is 1 where the stored normals are interpolated (volumes, CSG) and 0 otherwise, the other slots 0, 6 torus), material u32, 20 × f64, the shape's saved form ([`crate::shape`]): sphere centre, radius; cone base, base radius, apex, apex radius; triangle v0 v1 v2, then n0 n1 n2; torus centre, axis, major, minor; unused slots 0 |
//! | 6 | materials | per material 8 × f64: colour r g b, Kd, Ks, Shine, T, index of refraction |
//! | 7 | lights | per light 6 × f64: position, colour |
//! | 8 | lists | version 2 only: the store's object-list array, u32 each ([`rrt_core::store`], *Object lists*) |
//!
//! # Layout (version 3: sparse, the default)
//! The header is version 1's with a wider section table and 320 bytes
//! long: `16 + 32·n` bytes of magic, version 3, section count 8 and
//! 8 × { kind u32, codec u32, crc32 u32, zero u32, offset u64, length
//! u64 }, then the crc32 of those bytes and zeros up to byte 320. The
//! sections are version 2's, in the same order and alignment, except:
//!
//! * meta: byte 14 is 1 for an exact raster, 0 for the paper's;
//! * kind 2, **plane bricks**, replaces the plane. The plane is not
//!   stored: its opaque voxels are the records', and everything else in
//!   it (distance field, PROXIMITY flags, rank hints) follows from them
//!   ([`derive_plane`]), so the loader makes it again, byte for byte
//!   (the line level too, as for every version). The writer makes it too
//!   and stores each 8×8×8 brick whose cells differ from what it made, as
//!   { brick index u64, 512 cells (x fastest, cells outside the raster 0) },
//!   in increasing brick order: none for a raster as `rrt voxelize` builds
//!   it.
//! * codec 1 (**blocks**), allowed for the plane bricks, directory,
//!   records and lists (the writer's default, [`Format::Sparse`]
//!   `compress`): entries u64, entries per block u32, blocks u32, each
//!   block's length u32, then the blocks. A block is its entries with each
//!   field replaced by its difference from the previous entry's (modulo
//!   the field's width; a record's fields as in the records row below, a
//!   directory or list entry one `u32`, a plane brick's index then each
//!   cell), their bytes grouped by place in the entry, LZ4-compressed
//!   (`lz4_flex` block format). Codec 0: the entries as in version 2.
//!
//! The crc32 (IEEE, `crc32fast`) of each section is in its table entry.
//!
//! # Loading
//! The file is mapped (`memmap2`), not read in full: loading reads the
//! sections it decodes and checks each one's checksum first. [`load`]
//! refuses, with the file's name and what is wrong (naming the section
//! and its bytes in the file where a section's contents are wrong): a
//! file that is
//! not a raster, another version, a header or section whose checksum does
//! not match (corrupt, with the section's bytes), a section that ends past the end of the file or a
//! file shorter than its last section's padding (truncated), bytes after
//! that padding, a section whose length disagrees with the counts, and contents
//! that break an invariant (dimensions, the record store's directory and
//! sort order, object and material indices, non-finite numbers, a block
//! that does not decompress to its entries, plane bricks out of order).
//! Sizes are checked against the file's length before anything is
//! allocated, and the memory the loaded raster needs against a limit
//! ([`default_max_memory`], or [`load_bytes_within`]'s): a version 3 file
//! is much smaller than its raster. [`load_bytes`] does the same for the
//! bytes of a file in memory, and [`save_bytes`] gives the bytes [`save`]
//! writes. [`verify`] (`rrt info --check`) checks every checksum and
//! padding byte.
//!
//! The plane is made in anonymous memory, which gets huge pages
//! ([`Plane`]): a version 1 or 2 plane is copied there from the mapping,
//! a version 3 plane made there.

use std::fs::File;
use std::io::{BufWriter, Read, Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};

use glam::DVec3;
use indicatif::ProgressBar;
use memmap2::Mmap;
use rayon::prelude::*;

use super::atomic::AtomicFile;
use rrt_core::light::ExactRecords;
use rrt_core::object_table::MAX_LIGHTS;
use rrt_core::raster::{Extent, LINE_CELLS};
use rrt_core::store::{
    BRICK, BRICK_VOXELS, RecordStore, StoreError, brick_count, brick_dims, directory_len,
};
use rrt_core::voxel::VoxelRecord;
use rrt_core::voxelize::Separation;

use crate::fit::{Bytes, default_max_memory};
use crate::frame::RasterFrame;
use crate::render::MAX_SIDE;
use crate::scene::{Material, SourceLoc, View, ViewDefect};
use crate::shape::{SLOTS, Shape, Slots};
use crate::voxelize::plane::Plane;
use crate::voxelize::{
    MAX_MATERIALS, VoxelScene, derive_plane, line_level, line_level_of_plane, plane_matches_records,
};
use crate::voxelize::{WorldLight, WorldObject};
use crate::world::{WORLD_LIMIT, within_world};

/// The file's first bytes.
pub const MAGIC: [u8; 8] = *b"RRTRASTR";
/// The newest version this code writes and reads (it reads versions 1
/// and 2 too, and writes them as [`Format::Dense`]).
pub const VERSION: u32 = 3;
/// Sections of a version 2 or 3 file (version 1 has the first 7).
const SECTIONS: usize = 8;
/// The header of a version 1 file.
const HEADER_LEN: u64 = 192;
/// The header of a version 2 file.
const HEADER2_LEN: u64 = 256;
/// The header of a version 3 file.
const HEADER3_LEN: u64 = 320;
const META_LEN: u64 = 192;
/// Every section starts at a multiple of this, and the file ends at one.
const SECTION_ALIGN: u64 = 64;
/// Kind, material and the shape's saved numbers.
const OBJECT_LEN: u64 = 8 + 8 * SLOTS as u64;
const MATERIAL_LEN: u64 = 64;
const LIGHT_LEN: u64 = 48;
/// A record in the file: its fields in order, as large as the core's
/// record.
const RECORD_LEN: u64 = size_of::<VoxelRecord>() as u64;
/// The widths of a record's fields in the file, in order.
const RECORD_FIELDS: &[usize] = &[4, 2, 2, 1, 1, 1, 1, 1, 1, 2, 2, 2];
/// A brick directory entry (a `u32` record offset).
const DIRECTORY_ENTRY_LEN: u64 = size_of::<u32>() as u64;
/// Cells of a brick.
const BRICK_CELLS: usize = BRICK_VOXELS as usize;
/// A brick of the plane in a version 3 file: its index (`u64`), its cells.
const PLANE_BRICK_LEN: u64 = 8 + BRICK_CELLS as u64;
/// Entries of a compressed section are coded in blocks of about this many
/// bytes; a block of more than [`MAX_BLOCK`] bytes is refused.
const BLOCK_BYTES: usize = 1 << 20;
const MAX_BLOCK: usize = 16 << 20;
/// Section codecs (version 3): the entries as they are, or in blocks.
const CODEC_RAW: u32 = 0;
const CODEC_BLOCKS: u32 = 1;
const NAMES: [&str; SECTIONS] = [
    "meta",
    "plane",
    "directory",
    "records",
    "objects",
    "materials",
    "lights",
    "lists",
];

/// The section count, header length and section table entry length of
/// `version` (1 to 3).
const fn layout(version: u32) -> (usize, u64, usize) {
    match version {
        1 => (SECTIONS - 1, HEADER_LEN, 24),
        2 => (SECTIONS, HEADER2_LEN, 24),
        _ => (SECTIONS, HEADER3_LEN, 32),
    }
}

/// How [`save_to`] and [`save_bytes_as`] write a raster.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    /// Version 3 (the default): the plane made again on load from the
    /// records (only the bricks that differ from that are stored), the
    /// directory, records, object lists and stored bricks compressed in
    /// blocks when `compress` is set.
    Sparse {
        /// Compress the large sections.
        compress: bool,
    },
    /// Version 1 (the paper's raster) or 2 (an exact raster): the dense
    /// plane, one byte per voxel, for an rrt that reads only those.
    Dense,
}

impl Default for Format {
    fn default() -> Self {
        Self::Sparse { compress: true }
    }
}

/// Why a raster file could not be written or read.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum RasterFileError {
    /// An I/O error.
    #[error("{}: {what}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// What was being done.
        what: &'static str,
        /// Why.
        #[source]
        source: std::io::Error,
    },
    /// Not a raster file.
    #[error("{}: not an rrt raster file (no RRTRASTR header)", path.display())]
    NotRaster {
        /// The file.
        path: PathBuf,
    },
    /// Another version.
    #[error("{}: raster file version {found}; this rrt reads versions 1 to {VERSION}", path.display())]
    Version {
        /// The file.
        path: PathBuf,
        /// The version found.
        found: u32,
    },
    /// The file ends early.
    #[error("{}: truncated: {what}", path.display())]
    Truncated {
        /// The file.
        path: PathBuf,
        /// What is missing.
        what: String,
    },
    /// A checksum does not match.
    #[error("{}: corrupt: the {section} checksum does not match (bytes {start} to {end})", path.display())]
    Checksum {
        /// The file.
        path: PathBuf,
        /// Which section (or the header).
        section: &'static str,
        /// The checked bytes' first offset in the file.
        start: u64,
        /// The offset just past them.
        end: u64,
    },
    /// Loading needs more memory than the limit.
    #[error("{}: the raster needs {} once loaded, more than the limit of {}", path.display(), Bytes(*needed), Bytes(*limit))]
    TooLarge {
        /// The file.
        path: PathBuf,
        /// Bytes the loaded raster would hold.
        needed: u64,
        /// The limit.
        limit: u64,
    },
    /// The scene holds what the format cannot store.
    #[error("{}: cannot save {what} in a raster file; render the scene itself", path.display())]
    Unsupported {
        /// The file.
        path: PathBuf,
        /// What cannot be saved.
        what: String,
    },
    /// The contents break an invariant.
    #[error("{}: corrupt: {what}", path.display())]
    Invalid {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        what: String,
    },
}

/// Little-endian writer helpers.
#[derive(Default)]
struct Buf(Vec<u8>);

impl Buf {
    fn u32(&mut self, v: u32) {
        self.0.extend_from_slice(&v.to_le_bytes());
    }
    fn u64(&mut self, v: u64) {
        self.0.extend_from_slice(&v.to_le_bytes());
    }
    fn f64(&mut self, v: f64) {
        self.0.extend_from_slice(&v.to_le_bytes());
    }
    fn vec(&mut self, v: DVec3) {
        self.f64(v.x);
        self.f64(v.y);
        self.f64(v.z);
    }
    /// A section of one entry per item, each written by `write`.
    fn entries<T>(items: &[T], mut write: impl FnMut(&mut Self, &T)) -> Vec<u8> {
        let mut b = Self::default();
        for item in items {
            write(&mut b, item);
        }
        b.0
    }
}

/// Little-endian reader over a section.
struct Cursor<'a> {
    bytes: &'a [u8],
    at: usize,
}

impl<'a> Cursor<'a> {
    fn new(bytes: &'a [u8]) -> Self {
        Self { bytes, at: 0 }
    }
    fn take<const N: usize>(&mut self) -> [u8; N] {
        let mut out = [0u8; N];
        if let Some(s) = self.bytes.get(self.at..self.at + N) {
            out.copy_from_slice(s);
        }
        self.at += N;
        out
    }
    fn u8(&mut self) -> u8 {
        self.take::<1>()[0]
    }
    fn u32(&mut self) -> u32 {
        u32::from_le_bytes(self.take())
    }
    fn u64(&mut self) -> u64 {
        u64::from_le_bytes(self.take())
    }
    fn f64(&mut self) -> f64 {
        f64::from_le_bytes(self.take())
    }
    fn vec(&mut self) -> DVec3 {
        DVec3::new(self.f64(), self.f64(), self.f64())
    }
    /// Each `len`-byte entry of section `b`, read by `read`.
    fn entries<T>(b: &'a [u8], len: u64, mut read: impl FnMut(&mut Self) -> T) -> Vec<T> {
        b.chunks_exact(len as usize)
            .map(|entry| read(&mut Cursor::new(entry)))
            .collect()
    }
}

fn meta_bytes(s: &VoxelScene, version: u32) -> Vec<u8> {
    let mut b = Buf::default();
    for d in s.frame.extent.dims() {
        b.u32(d);
    }
    b.0.push(match s.separation {
        Separation::Six => 6,
        Separation::TwentySix => 26,
    });
    b.0.push(if s.exact {
        match s.exact_records {
            ExactRecords::Paper => 0,
            ExactRecords::Classify => 1,
            ExactRecords::Skip => 2,
        }
    } else {
        0
    });
    // Version 3 says here whether the raster is exact (versions 1 and 2
    // by their number).
    b.0.push(u8::from(version == 3 && s.exact));
    b.0.push(0);
    b.vec(s.frame.origin);
    b.f64(s.frame.voxel_size);
    b.vec(s.background);
    b.vec(s.view.from);
    b.vec(s.view.at);
    b.vec(s.view.up);
    b.f64(s.view.angle);
    b.f64(s.view.hither);
    b.u32(s.view.resolution[0]);
    b.u32(s.view.resolution[1]);
    b.u64(s.records.len() as u64);
    b.u64(s.objects.len() as u64);
    b.u32(u32::try_from(s.materials.len()).unwrap_or(u32::MAX));
    b.u32(u32::try_from(s.lights.len()).unwrap_or(u32::MAX));
    debug_assert_eq!(b.0.len() as u64, META_LEN);
    b.0
}

fn objects_bytes(s: &VoxelScene) -> Vec<u8> {
    Buf::entries(&s.objects, |b, o| {
        let (kind, slots) = o.shape.save();
        b.u32(kind);
        b.u32(u32::from(o.material));
        for v in slots {
            b.f64(v);
        }
    })
}

fn materials_bytes(s: &VoxelScene) -> Vec<u8> {
    Buf::entries(&s.materials, |b, m| {
        b.vec(m.colour);
        for v in [m.kd, m.ks, m.shine, m.transmittance, m.ior] {
            b.f64(v);
        }
    })
}

fn lights_bytes(s: &VoxelScene) -> Vec<u8> {
    Buf::entries(&s.lights, |b, l| {
        b.vec(l.position);
        b.vec(l.colour);
    })
}

fn record_bytes(r: &VoxelRecord, out: &mut Vec<u8>) {
    out.extend_from_slice(&r.object.to_le_bytes());
    out.extend_from_slice(&r.normal[0].to_le_bytes());
    out.extend_from_slice(&r.normal[1].to_le_bytes());
    out.extend_from_slice(&r.color);
    out.extend_from_slice(&r.illum);
    out.extend_from_slice(&r.lights.to_le_bytes());
    out.extend_from_slice(&r.material.to_le_bytes());
    out.extend_from_slice(&r.key.to_le_bytes());
}

fn record_from(b: &[u8]) -> VoxelRecord {
    let mut c = Cursor::new(b);
    let object = c.u32();
    let n0 = i16::from_le_bytes(c.take());
    let n1 = i16::from_le_bytes(c.take());
    let color = c.take::<3>();
    let illum = c.take::<3>();
    let lights = u16::from_le_bytes(c.take());
    let material = u16::from_le_bytes(c.take());
    let key = u16::from_le_bytes(c.take());
    VoxelRecord {
        object,
        normal: [n0, n1],
        color,
        illum,
        lights,
        material,
        key,
    }
}

/// A writer that checksums and counts what passes through.
struct Checked<'a, W: Write> {
    inner: W,
    crc: crc32fast::Hasher,
    len: u64,
    progress: &'a ProgressBar,
}

impl<W: Write> Checked<'_, W> {
    fn put(&mut self, b: &[u8]) -> std::io::Result<()> {
        self.crc.update(b);
        self.len += b.len() as u64;
        self.progress.inc(b.len() as u64);
        self.inner.write_all(b)
    }
}

/// Writes `scene` to `path` in the default [`Format`] (module docs for the
/// layout) through a temporary file renamed over `path` when complete
/// ([`AtomicFile`]); returns the file's length.
///
/// # Errors
/// [`RasterFileError::Io`] naming the file.
pub fn save(scene: &VoxelScene, path: &Path) -> Result<u64, RasterFileError> {
    let out = AtomicFile::create(path).map_err(|source| RasterFileError::Io {
        path: path.to_path_buf(),
        what: "cannot create",
        source,
    })?;
    save_to(scene, out, &ProgressBar::hidden(), Format::default())
}

/// Writes `scene` in `format` into `out`, opened earlier (so that an
/// unwritable output is reported before voxelizing), and commits it over
/// its target; returns the file's length. `progress` counts bytes.
///
/// # Errors
/// [`RasterFileError::Io`] naming the target; the target is untouched.
pub fn save_to(
    scene: &VoxelScene,
    out: AtomicFile,
    progress: &ProgressBar,
    format: Format,
) -> Result<u64, RasterFileError> {
    save_trusting(scene, out, progress, format, Trust::Any)
}

/// [`save_to`] for a scene exactly as [`build`](crate::voxelize::build)
/// returned it, its plane unchanged since: a version 3 file then checks
/// the plane against its records by its opaque cells alone
/// ([`plane_matches_records`]), one pass over the plane, instead of making
/// the plane again slab by slab (several whole derivations for a large
/// raster); were they to differ, the bricks are found as [`save_to`] finds
/// them. The file is the one [`save_to`] writes.
///
/// # Errors
/// As [`save_to`].
pub fn save_built_to(
    scene: &VoxelScene,
    out: AtomicFile,
    progress: &ProgressBar,
    format: Format,
) -> Result<u64, RasterFileError> {
    save_trusting(scene, out, progress, format, Trust::Built)
}

/// [`save_to`] and [`save_built_to`], with what the writer may assume of
/// the plane.
fn save_trusting(
    scene: &VoxelScene,
    mut out: AtomicFile,
    progress: &ProgressBar,
    format: Format,
    trust: Trust,
) -> Result<u64, RasterFileError> {
    let path = out.target().to_path_buf();
    refuse_direct(scene, &path)?;
    let io = |source| RasterFileError::Io {
        path: path.clone(),
        what: "cannot write",
        source,
    };
    let len = write_raster(scene, out.file().map_err(io)?, progress, format, trust).map_err(io)?;
    out.commit().map_err(io)?;
    Ok(len)
}

/// What a writer may assume of a scene's plane.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Trust {
    /// Anything: it is compared with the plane made from the records.
    Any,
    /// As the builder made it: its transparent cells are the distance
    /// field of its opaque ones ([`save_built_to`]).
    Built,
}

/// The bytes [`save`] writes for `scene` (named `path` in errors).
///
/// # Errors
/// [`RasterFileError::Unsupported`] for what a raster file cannot hold.
pub fn save_bytes(scene: &VoxelScene, path: &Path) -> Result<Vec<u8>, RasterFileError> {
    save_bytes_as(scene, path, Format::default())
}

/// The bytes of `scene` saved in `format` (named `path` in errors).
///
/// # Errors
/// [`RasterFileError::Unsupported`] for what a raster file cannot hold.
pub fn save_bytes_as(
    scene: &VoxelScene,
    path: &Path,
    format: Format,
) -> Result<Vec<u8>, RasterFileError> {
    refuse_direct(scene, path)?;
    let mut out = std::io::Cursor::new(Vec::new());
    write_raster(scene, &mut out, &ProgressBar::hidden(), format, Trust::Any).map_err(
        |source| RasterFileError::Io {
            path: path.to_path_buf(),
            what: "cannot write",
            source,
        },
    )?;
    Ok(out.into_inner())
}

/// Refuses a scene with volumes rendered directly: a raster file holds no
/// samples or transfer functions.
fn refuse_direct(scene: &VoxelScene, path: &Path) -> Result<(), RasterFileError> {
    match scene.direct.first() {
        Some(d) => Err(RasterFileError::Unsupported {
            path: path.to_path_buf(),
            what: format!(
                "a volume rendered directly (object {}: its samples and transfer function)",
                d.object
            ),
        }),
        None => Ok(()),
    }
}

/// The field widths of a stored plane brick: its index, then each cell.
const PLANE_BRICK_FIELDS: [usize; 1 + BRICK_CELLS] = {
    let mut f = [1; 1 + BRICK_CELLS];
    f[0] = 8;
    f
};

/// A brick of the plane stored in a version 3 file: its index and its
/// cells (x fastest, the cells outside the raster 0).
#[derive(Clone, Debug, Default, PartialEq)]
struct PlaneBrick {
    brick: u64,
    cells: Vec<u8>,
}

/// Slices of the plane made at once when a raster is saved.
const SAVE_SLAB_BYTES: usize = 256 << 20;

/// The bricks of `scene`'s plane that differ from the plane made again
/// from its records ([`derive_plane`]), in brick order: none for a raster
/// as the builder makes it. Made slab by slab, so that the extra memory
/// is about [`SAVE_SLAB_BYTES`] plus the margins.
fn differing_bricks(
    scene: &VoxelScene,
    store: &RecordStore<'_>,
) -> std::io::Result<Vec<PlaneBrick>> {
    let extent = scene.extent();
    let [nx, ny, nz] = extent.dims();
    let [bx, by, _] = brick_dims(extent);
    let (nxu, nyu) = (nx as usize, ny as usize);
    let slab = ((SAVE_SLAB_BYTES / (nxu * nyu)).max(8) as u32) & !(BRICK - 1);
    let mut out = Vec::new();
    let mut z0 = 0;
    while z0 < nz {
        let z1 = z0.saturating_add(slab).min(nz);
        let (derived, d0) = derive_plane(store, [z0, z1])?;
        let rows: Vec<(u32, u32)> = (z0 / BRICK..z1.div_ceil(BRICK))
            .flat_map(|bz| (0..by).map(move |byi| (bz, byi)))
            .collect();
        let found: Vec<Vec<PlaneBrick>> = rows
            .par_iter()
            .map(|&(bz, byi)| {
                let mut row = Vec::new();
                for bxi in 0..bx {
                    let cells = |z: u32, y: u32| {
                        let x0 = (bxi * BRICK) as usize;
                        let x1 = (x0 + BRICK as usize).min(nxu);
                        let at = |z: u32| x0 + nxu * (y as usize + nyu * z as usize);
                        (at(z)..at(z) + x1 - x0, at(z - d0)..at(z - d0) + x1 - x0)
                    };
                    let voxels = || {
                        (bz * BRICK..(bz * BRICK + BRICK).min(nz)).flat_map(move |z| {
                            (byi * BRICK..(byi * BRICK + BRICK).min(ny)).map(move |y| (z, y))
                        })
                    };
                    if voxels().all(|(z, y)| {
                        let (a, b) = cells(z, y);
                        scene.plane[a] == derived[b]
                    }) {
                        continue;
                    }
                    let mut brick = vec![0u8; BRICK_CELLS];
                    for (z, y) in voxels() {
                        let (a, _) = cells(z, y);
                        let at = 8 * ((y - byi * BRICK) + 8 * (z - bz * BRICK)) as usize;
                        brick[at..at + a.len()].copy_from_slice(&scene.plane[a]);
                    }
                    row.push(PlaneBrick {
                        brick: u64::from(bxi)
                            + u64::from(bx) * (u64::from(byi) + u64::from(by) * u64::from(bz)),
                        cells: brick,
                    });
                }
                row
            })
            .collect();
        out.extend(found.into_iter().flatten());
        z0 = z1;
    }
    Ok(out)
}

/// The little-endian number in `b` (at most 8 bytes).
fn le_value(b: &[u8]) -> u64 {
    b.iter().rev().fold(0, |v, &x| (v << 8) | u64::from(x))
}

/// The low `w` bytes of a `u64` (w from 1 to 8).
fn width_mask(w: usize) -> u64 {
    if w >= 8 {
        u64::MAX
    } else {
        (1u64 << (8 * w)) - 1
    }
}

/// A block of entries (fields of the widths `fields`, in order) made
/// compressible: each field replaced by its difference from the previous
/// entry's (modulo its width), then the bytes grouped by their place in
/// the entry (all first bytes, all second bytes, …).
fn transposed(raw: &[u8], fields: &[usize]) -> Vec<u8> {
    let len: usize = fields.iter().sum();
    let m = raw.len() / len;
    let mut out = vec![0u8; m * len];
    let mut at = 0;
    for &w in fields {
        // The field's byte planes, filled entry by entry.
        let planes = &mut out[at * m..(at + w) * m];
        match w {
            1 => differences::<1>(raw, len, at, planes),
            2 => differences::<2>(raw, len, at, planes),
            4 => differences::<4>(raw, len, at, planes),
            8 => differences::<8>(raw, len, at, planes),
            _ => {
                let mut prev = 0u64;
                for (e, entry) in raw.chunks_exact(len).enumerate() {
                    let v = le_value(&entry[at..at + w]);
                    let d = v.wrapping_sub(prev);
                    prev = v;
                    for i in 0..w {
                        planes[i * m + e] = (d >> (8 * i)) as u8;
                    }
                }
            }
        }
        at += w;
    }
    out
}

/// The `W`-byte field at `at` of each entry (`len` bytes) of `raw` as
/// its difference from the previous entry's, byte `i` of entry `e` into
/// `planes[i·m + e]` (`m` entries): [`transposed`]'s work for one field.
fn differences<const W: usize>(raw: &[u8], len: usize, at: usize, planes: &mut [u8]) {
    let m = planes.len() / W;
    let mut prev = 0u64;
    let mut bytes: [&mut [u8]; W] = {
        let mut rest = planes;
        std::array::from_fn(|_| {
            let (plane, tail) = std::mem::take(&mut rest).split_at_mut(m);
            rest = tail;
            plane
        })
    };
    for (e, entry) in raw.chunks_exact(len).enumerate() {
        let mut b = [0u8; 8];
        b[..W].copy_from_slice(&entry[at..at + W]);
        let v = u64::from_le_bytes(b);
        let d = v.wrapping_sub(prev).to_le_bytes();
        prev = v;
        for (plane, byte) in bytes.iter_mut().zip(d) {
            plane[e] = byte;
        }
    }
}

/// The entries [`transposed`] made `t` from, into `raw` (as long): field
/// by field, each gathered from its byte planes and added to the field
/// before it, modulo its width, in one pass over the entries.
fn untransposed(t: &[u8], fields: &[usize], raw: &mut [u8]) {
    let len: usize = fields.iter().sum();
    if len == 0 {
        return;
    }
    let m = t.len() / len;
    let raw = &mut raw[..m * len];
    let mut at = 0;
    for &w in fields {
        let planes = &t[at * m..(at + w) * m];
        match w {
            1 => sums::<1>(planes, raw, len, at),
            2 => sums::<2>(planes, raw, len, at),
            4 => sums::<4>(planes, raw, len, at),
            8 => sums::<8>(planes, raw, len, at),
            _ => {
                let mask = width_mask(w);
                let mut prev = 0u64;
                for (e, entry) in raw.chunks_exact_mut(len).enumerate() {
                    let d = (0..w)
                        .rev()
                        .fold(0u64, |d, i| (d << 8) | u64::from(planes[i * m + e]));
                    prev = prev.wrapping_add(d) & mask;
                    entry[at..at + w].copy_from_slice(&prev.to_le_bytes()[..w]);
                }
            }
        }
        at += w;
    }
}

/// The `W`-byte field at `at` of each entry (`len` bytes) of `raw`: the
/// running sum, modulo `2^(8W)`, of the differences whose byte `i` for
/// entry `e` is `planes[i·m + e]` (`m` entries): [`untransposed`]'s work
/// for one field.
fn sums<const W: usize>(planes: &[u8], raw: &mut [u8], len: usize, at: usize) {
    let m = planes.len() / W;
    let bytes: [&[u8]; W] = std::array::from_fn(|i| &planes[i * m..(i + 1) * m]);
    let mask = width_mask(W);
    let mut prev = 0u64;
    for (e, entry) in raw.chunks_exact_mut(len).enumerate().take(m) {
        let mut b = [0u8; 8];
        for (x, plane) in b.iter_mut().zip(&bytes) {
            *x = plane[e];
        }
        prev = prev.wrapping_add(u64::from_le_bytes(b)) & mask;
        entry[at..at + W].copy_from_slice(&prev.to_le_bytes()[..W]);
    }
}

/// The bytes of a section of `n` entries with fields of the widths
/// `fields`, entry `i` appended to a buffer by `entry`: the entries as
/// they are, or (`compress`) in blocks ([`transposed`], then LZ4), after
/// a table: entries u64, entries per block u32, blocks u32, each block's
/// length u32.
fn encode_entries(
    n: usize,
    fields: &[usize],
    compress: bool,
    entry: impl Fn(usize, &mut Vec<u8>) + Sync,
) -> Vec<u8> {
    let len: usize = fields.iter().sum();
    let per = (BLOCK_BYTES / len).max(1);
    let blocks: Vec<Vec<u8>> = (0..n.div_ceil(per))
        .into_par_iter()
        .map(|b| {
            let mut raw = Vec::with_capacity(per * len);
            for i in b * per..((b + 1) * per).min(n) {
                entry(i, &mut raw);
            }
            if compress {
                lz4_flex::block::compress(&transposed(&raw, fields))
            } else {
                raw
            }
        })
        .collect();
    if !compress {
        return blocks.concat();
    }
    let mut out = Buf::default();
    out.u64(n as u64);
    out.u32(u32::try_from(per).unwrap_or(u32::MAX));
    out.u32(u32::try_from(blocks.len()).unwrap_or(u32::MAX));
    for b in &blocks {
        out.u32(u32::try_from(b.len()).unwrap_or(u32::MAX));
    }
    for b in &blocks {
        out.0.extend_from_slice(b);
    }
    out.0
}

/// The sections of a version 3 file: (codec, bytes) in kind order.
fn sparse_sections(
    scene: &VoxelScene,
    compress: bool,
    plane: Trust,
) -> std::io::Result<Vec<(u32, Vec<u8>)>> {
    let codec = if compress { CODEC_BLOCKS } else { CODEC_RAW };
    let store = scene.store().map_err(std::io::Error::other)?;
    let built = plane == Trust::Built && plane_matches_records(&scene.plane, &store);
    let bricks = if built {
        Vec::new()
    } else {
        differing_bricks(scene, &store)?
    };
    Ok(vec![
        (CODEC_RAW, meta_bytes(scene, 3)),
        (
            codec,
            encode_entries(bricks.len(), &PLANE_BRICK_FIELDS, compress, |i, b| {
                b.extend_from_slice(&bricks[i].brick.to_le_bytes());
                b.extend_from_slice(&bricks[i].cells);
            }),
        ),
        (
            codec,
            encode_entries(scene.directory.len(), &[4], compress, |i, b| {
                b.extend_from_slice(&scene.directory[i].to_le_bytes());
            }),
        ),
        (
            codec,
            encode_entries(scene.records.len(), RECORD_FIELDS, compress, |i, b| {
                record_bytes(&scene.records[i], b);
            }),
        ),
        (CODEC_RAW, objects_bytes(scene)),
        (CODEC_RAW, materials_bytes(scene)),
        (CODEC_RAW, lights_bytes(scene)),
        (
            codec,
            encode_entries(scene.lists.len(), &[4], compress, |i, b| {
                b.extend_from_slice(&scene.lists[i].to_le_bytes());
            }),
        ),
    ])
}

/// Writes `scene` into `file` from its start (module docs for the layout);
/// returns the length written.
fn write_raster<F: Write + Seek>(
    scene: &VoxelScene,
    file: &mut F,
    progress: &ProgressBar,
    format: Format,
    plane: Trust,
) -> std::io::Result<u64> {
    let (version, sparse) = match format {
        Format::Sparse { compress } => (3, Some(sparse_sections(scene, compress, plane)?)),
        Format::Dense => (if scene.exact { 2 } else { 1 }, None),
    };
    let mut w = BufWriter::with_capacity(1 << 20, &mut *file);
    let (sections, header_len, _) = layout(version);
    w.write_all(&vec![0u8; header_len as usize])?;
    // Every section's bytes, as the writer below counts them.
    progress.set_length(match &sparse {
        Some(s) => s.iter().map(|(_, b)| b.len() as u64).sum(),
        None => {
            META_LEN
                + scene.plane.len() as u64
                + scene.directory.len() as u64 * DIRECTORY_ENTRY_LEN
                + scene.records.len() as u64 * RECORD_LEN
                + scene.objects.len() as u64 * OBJECT_LEN
                + scene.materials.len() as u64 * MATERIAL_LEN
                + scene.lights.len() as u64 * LIGHT_LEN
                + scene.lists.len() as u64 * 4
        }
    });
    progress.set_position(0);
    let mut table = Vec::with_capacity(sections);
    let mut offset = header_len;
    for kind in 1..=sections as u32 {
        let mut c = Checked {
            inner: &mut w,
            crc: crc32fast::Hasher::new(),
            len: 0,
            progress,
        };
        let mut codec = CODEC_RAW;
        match (&sparse, kind) {
            (Some(s), k) => {
                let (sc, b) = &s[k as usize - 1];
                codec = *sc;
                c.put(b)?;
            }
            (None, 1) => c.put(&meta_bytes(scene, version))?,
            (None, 2) => c.put(&scene.plane)?,
            (None, 3) => {
                let mut b =
                    Vec::with_capacity(scene.directory.len() * DIRECTORY_ENTRY_LEN as usize);
                for d in &scene.directory {
                    b.extend_from_slice(&d.to_le_bytes());
                }
                c.put(&b)?;
            }
            (None, 4) => {
                let mut b = Vec::with_capacity(1 << 20);
                for chunk in scene.records.chunks(1 << 15) {
                    b.clear();
                    for rec in chunk {
                        record_bytes(rec, &mut b);
                    }
                    c.put(&b)?;
                }
            }
            (None, 5) => c.put(&objects_bytes(scene))?,
            (None, 6) => c.put(&materials_bytes(scene))?,
            (None, 7) => c.put(&lights_bytes(scene))?,
            (None, _) => {
                let b: Vec<u8> = scene.lists.iter().flat_map(|v| v.to_le_bytes()).collect();
                c.put(&b)?;
            }
        }
        let (len, crc) = (c.len, c.crc.finalize());
        table.push((kind, codec, crc, offset, len));
        offset += len;
        let pad = offset.next_multiple_of(SECTION_ALIGN) - offset;
        w.write_all(&vec![0u8; pad as usize])?;
        offset += pad;
    }
    w.flush()?;
    drop(w);
    let mut h = Vec::with_capacity(header_len as usize);
    h.extend_from_slice(&MAGIC);
    h.extend_from_slice(&version.to_le_bytes());
    h.extend_from_slice(&(sections as u32).to_le_bytes());
    for (kind, codec, crc, off, len) in &table {
        h.extend_from_slice(&kind.to_le_bytes());
        if version == 3 {
            h.extend_from_slice(&codec.to_le_bytes());
        }
        h.extend_from_slice(&crc.to_le_bytes());
        if version == 3 {
            h.extend_from_slice(&0u32.to_le_bytes());
        }
        h.extend_from_slice(&off.to_le_bytes());
        h.extend_from_slice(&len.to_le_bytes());
    }
    let hcrc = crc32fast::hash(&h);
    h.extend_from_slice(&hcrc.to_le_bytes());
    h.resize(header_len as usize, 0);
    file.seek(SeekFrom::Start(0))?;
    file.write_all(&h)?;
    Ok(offset)
}

/// The (codec, crc, offset, length) of entry `k` of the section table of
/// a `version` file whose header is `h` (long enough).
fn table_entry(h: &[u8], version: u32, k: usize) -> (u32, u32, u64, u64) {
    let (_, _, entry) = layout(version);
    let at = 16 + entry * k;
    let u32_at = |i: usize| u32::from_le_bytes([h[i], h[i + 1], h[i + 2], h[i + 3]]);
    let u64_at = |i: usize| u64::from(u32_at(i)) | (u64::from(u32_at(i + 4)) << 32);
    if version == 3 {
        (
            u32_at(at + 4),
            u32_at(at + 8),
            u64_at(at + 16),
            u64_at(at + 24),
        )
    } else {
        (CODEC_RAW, u32_at(at + 4), u64_at(at + 8), u64_at(at + 16))
    }
}

/// Where entry `k`'s checksum is in the header of a `version` file.
#[cfg(any(test, feature = "check"))]
fn crc_at(version: u32, k: usize) -> usize {
    let (_, _, entry) = layout(version);
    16 + entry * k + if version == 3 { 8 } else { 4 }
}

/// Recomputes, in the bytes of a raster file, every checksum its section
/// table can reach (the sections inside the bytes, then the header's), so
/// that changed contents reach the loader's checks behind the checksums.
/// Bytes that are not a raster file's header are left as they are.
#[cfg(any(test, feature = "check"))]
pub fn reseal(bytes: &mut [u8]) {
    if bytes.len() < 16 || bytes[..8] != MAGIC {
        return;
    }
    let version = u32::from_le_bytes([bytes[8], bytes[9], bytes[10], bytes[11]]);
    if !(1..=VERSION).contains(&version) {
        return;
    }
    let (n, header_len, entry) = layout(version);
    if (bytes.len() as u64) < header_len {
        return;
    }
    for k in 0..n {
        let (_, _, off, len) = table_entry(bytes, version, k);
        let Some(range) = usize::try_from(off)
            .ok()
            .zip(usize::try_from(len).ok())
            .and_then(|(o, l)| Some(o..o.checked_add(l)?))
            .filter(|r| r.end <= bytes.len())
        else {
            continue;
        };
        let crc = crc32fast::hash(&bytes[range]);
        let at = crc_at(version, k);
        bytes[at..at + 4].copy_from_slice(&crc.to_le_bytes());
    }
    let at = 16 + entry * n;
    let crc = crc32fast::hash(&bytes[..at]);
    bytes[at..at + 4].copy_from_slice(&crc.to_le_bytes());
}

/// Whether `path` is read as a saved raster: its name ends in `.rrt`
/// (then a file that is not a whole raster is refused as a damaged one,
/// not read as a scene), or it is a regular file starting with the raster
/// magic ([`is_raster_file`]).
#[must_use]
pub fn names_raster(path: &Path) -> bool {
    path.extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("rrt"))
        || is_raster_file(path)
}

/// Whether `path` is a regular file starting with the raster magic. Only
/// a regular file is read: the first bytes of a pipe, a FIFO or a
/// terminal (`/dev/stdin`) read here would be lost to the scene parser
/// that reads it next, and a raster is mapped, which needs a regular
/// file anyway.
#[must_use]
pub fn is_raster_file(path: &Path) -> bool {
    let mut magic = [0u8; 8];
    File::open(path)
        .and_then(|mut f| {
            if !f.metadata()?.is_file() {
                return Ok(false);
            }
            f.read_exact(&mut magic)?;
            Ok(magic == MAGIC)
        })
        .unwrap_or(false)
}

/// The summary `rrt info` prints, read from the header and meta section
/// only.
#[derive(Clone, Debug, PartialEq)]
pub struct Info {
    /// The file's format version.
    pub version: u32,
    /// Whether the raster is exact (object lists, renders in every mode).
    pub exact: bool,
    /// Whether its large sections are compressed (version 3).
    pub compressed: bool,
    /// Bricks of the plane stored in the file (version 3: those that
    /// differ from the plane made again from the records).
    pub plane_bricks: u64,
    /// Entries of the object lists (0 for a raster without them).
    pub list_entries: u64,
    /// Voxels per axis.
    pub dims: [u32; 3],
    /// World position of the raster's lowest corner.
    pub origin: DVec3,
    /// World length of a voxel's edge.
    pub voxel_size: f64,
    /// The voxelization's separation.
    pub separation: Separation,
    /// What the light bits of records of exact objects hold.
    pub exact_records: ExactRecords,
    /// Records (non-transparent voxels).
    pub records: u64,
    /// Objects.
    pub objects: u64,
    /// Distinct materials.
    pub materials: u32,
    /// Lights.
    pub lights: u32,
    /// The file's length.
    pub file_bytes: u64,
    /// Memory for plane, its line level (built on load), directory,
    /// records and object lists once loaded.
    pub memory: u64,
}

struct Header {
    version: u32,
    file_len: u64,
    /// (codec, crc, offset, length) per section; the lists' is all zero
    /// in a version 1 file.
    sections: [(u32, u32, u64, u64); SECTIONS],
}

impl Header {
    /// `what` is wrong in section `k`: [`RasterFileError::Invalid`] naming
    /// the section and its bytes in the file.
    fn invalid_in(&self, path: &Path, k: usize, what: &str) -> RasterFileError {
        let (_, _, off, len) = self.sections[k];
        RasterFileError::Invalid {
            path: path.to_path_buf(),
            what: format!(
                "{} section (bytes {off} to {}): {what}",
                self.name(k),
                off.saturating_add(len)
            ),
        }
    }

    fn name(&self, k: usize) -> &'static str {
        if self.version == 3 && k == 1 {
            "plane bricks"
        } else {
            NAMES[k]
        }
    }
}

fn read_header(bytes: &[u8], path: &Path) -> Result<Header, RasterFileError> {
    let p = || path.to_path_buf();
    let file_len = bytes.len() as u64;
    let got = bytes.len();
    if got < 12 && got > 0 && (MAGIC.starts_with(&bytes[..got.min(8)])) {
        return Err(RasterFileError::Truncated {
            path: p(),
            what: format!("{got} bytes, shorter than the {HEADER_LEN}-byte header"),
        });
    }
    if got < 8 || bytes[..8] != MAGIC {
        return Err(RasterFileError::NotRaster { path: p() });
    }
    let version = u32::from_le_bytes([bytes[8], bytes[9], bytes[10], bytes[11]]);
    if !(1..=VERSION).contains(&version) {
        return Err(RasterFileError::Version {
            path: p(),
            found: version,
        });
    }
    let (n, header_len, entry) = layout(version);
    if (got as u64) < header_len {
        return Err(RasterFileError::Truncated {
            path: p(),
            what: format!("{got} bytes, shorter than the {header_len}-byte header"),
        });
    }
    let h = &bytes[..header_len as usize];
    let at = 16 + entry * n;
    let stored = u32::from_le_bytes([h[at], h[at + 1], h[at + 2], h[at + 3]]);
    if crc32fast::hash(&h[..at]) != stored {
        return Err(RasterFileError::Checksum {
            path: p(),
            section: "header",
            start: 0,
            end: at as u64,
        });
    }
    let count = u32::from_le_bytes([h[12], h[13], h[14], h[15]]);
    if count as usize != n {
        return Err(RasterFileError::Invalid {
            path: p(),
            what: format!("{count} sections, expected {n} for version {version}"),
        });
    }
    let mut header = Header {
        version,
        file_len,
        sections: [(0, 0, 0, 0); SECTIONS],
    };
    let mut end = header_len;
    for k in 0..n {
        let kind = u32::from_le_bytes(h[16 + entry * k..][..4].try_into().unwrap_or([0; 4]));
        let (codec, crc, off, len) = table_entry(h, version, k);
        let reserved = version == 3 && h[16 + entry * k + 12..][..4] != [0; 4];
        if kind as usize != k + 1 || off < end || reserved {
            return Err(RasterFileError::Invalid {
                path: p(),
                what: format!("section table entry {} is out of order", k + 1),
            });
        }
        let blocks_allowed = matches!(k, 1 | 2 | 3 | 7);
        if codec != CODEC_RAW && !(codec == CODEC_BLOCKS && blocks_allowed) {
            return Err(RasterFileError::Invalid {
                path: p(),
                what: format!("{} section with unknown codec {codec}", header.name(k)),
            });
        }
        let stop = off
            .checked_add(len)
            .ok_or_else(|| RasterFileError::Invalid {
                path: p(),
                what: format!("{} section length overflows", header.name(k)),
            })?;
        if stop > file_len {
            return Err(RasterFileError::Truncated {
                path: p(),
                what: format!(
                    "the {} section ends at byte {stop}, the file has {file_len}",
                    header.name(k)
                ),
            });
        }
        end = stop;
        header.sections[k] = (codec, crc, off, len);
    }
    // The writer pads the last section to a multiple of 64 like every
    // other: a shorter file lost bytes (of padding only, perhaps, but it
    // is not the file that was written), a longer one has something after
    // the raster.
    let written = end.next_multiple_of(SECTION_ALIGN);
    if file_len < written {
        return Err(RasterFileError::Truncated {
            path: p(),
            what: format!(
                "the file has {file_len} bytes, its sections and padding end at byte {written}"
            ),
        });
    }
    if file_len > written {
        return Err(RasterFileError::Invalid {
            path: p(),
            what: format!(
                "{} bytes after the end of the raster (byte {written})",
                file_len - written
            ),
        });
    }
    Ok(header)
}

/// The bytes of section `k`, its checksum checked (in pieces, each given
/// to `each` and counted on `progress`).
fn section<'b>(
    bytes: &'b [u8],
    path: &Path,
    h: &Header,
    k: usize,
    progress: &ProgressBar,
    mut each: impl FnMut(usize, &[u8]),
) -> Result<&'b [u8], RasterFileError> {
    let (_, crc, off, len) = h.sections[k];
    // Inside the file: read_header checked it.
    let b = &bytes[off as usize..(off + len) as usize];
    let mut hasher = crc32fast::Hasher::new();
    let mut at = 0;
    for piece in b.chunks(1 << 22) {
        hasher.update(piece);
        each(at, piece);
        at += piece.len();
        progress.inc(piece.len() as u64);
    }
    if hasher.finalize() != crc {
        return Err(RasterFileError::Checksum {
            path: path.to_path_buf(),
            section: h.name(k),
            start: off,
            end: off + len,
        });
    }
    Ok(b)
}

struct Meta {
    dims: [u32; 3],
    separation: Separation,
    exact: bool,
    exact_records: ExactRecords,
    origin: DVec3,
    voxel_size: f64,
    background: DVec3,
    view: View,
    records: u64,
    objects: u64,
    materials: u32,
    lights: u32,
}

fn read_meta(bytes: &[u8], path: &Path, h: &Header) -> Result<Meta, RasterFileError> {
    let invalid = |what: String| RasterFileError::Invalid {
        path: path.to_path_buf(),
        what,
    };
    if h.sections[0].3 != META_LEN {
        return Err(invalid(format!(
            "meta section of {} bytes, expected {META_LEN}",
            h.sections[0].3
        )));
    }
    let b = section(bytes, path, h, 0, &ProgressBar::hidden(), |_, _| {})?;
    let invalid = |what: String| h.invalid_in(path, 0, &what);
    let mut c = Cursor::new(b);
    let dims = [c.u32(), c.u32(), c.u32()];
    let separation = match c.u8() {
        6 => Separation::Six,
        26 => Separation::TwentySix,
        s => return Err(invalid(format!("separation {s}, expected 6 or 26"))),
    };
    let records_byte = c.u8();
    let exact = match (h.version, c.u8()) {
        (1, 0) => false,
        (2, 0) => true,
        (3, e @ (0 | 1)) => e == 1,
        (v, e) => {
            return Err(invalid(format!(
                "exact flag {e}, expected 0{} in a version {v} file",
                if v == 3 { " or 1" } else { "" }
            )));
        }
    };
    let exact_records = match (exact, records_byte) {
        (_, 0) => ExactRecords::Paper,
        (true, 1) => ExactRecords::Classify,
        (true, 2) => ExactRecords::Skip,
        (_, b) => {
            return Err(invalid(format!(
                "light bits of exact records {b}, expected 0{} in a version {} file",
                if exact { ", 1 or 2" } else { "" },
                h.version
            )));
        }
    };
    if c.u8() != 0 {
        return Err(invalid("meta byte 15 is not zero".into()));
    }
    let origin = c.vec();
    let voxel_size = c.f64();
    let background = c.vec();
    let from = c.vec();
    let at = c.vec();
    let up = c.vec();
    let angle = c.f64();
    let hither = c.f64();
    let resolution = [c.u32(), c.u32()];
    let m = Meta {
        dims,
        separation,
        exact,
        exact_records,
        origin,
        voxel_size,
        background,
        view: View {
            from,
            at,
            up,
            angle,
            hither,
            resolution,
            loc: SourceLoc::new(path.display().to_string(), 0, 0),
        },
        records: c.u64(),
        objects: c.u64(),
        materials: c.u32(),
        lights: c.u32(),
    };
    Extent::new(dims[0], dims[1], dims[2]).map_err(|e| invalid(e.to_string()))?;
    // The far corner finite and apart from the origin on every axis: the
    // voxels have a size in world coordinates. A fit makes frames of
    // geometry within the world's limit, grown by its margin of at most
    // DEFAULT_MARGIN voxels of at most the world's width a side.
    let far = origin + DVec3::from(dims.map(f64::from)) * voxel_size;
    let reach = WORLD_LIMIT * f64::from(1 + 2 * crate::fit::DEFAULT_MARGIN);
    if !(origin.is_finite()
        && voxel_size.is_normal()
        && voxel_size > 0.0
        && far.is_finite()
        && (far - origin).min_element() > 0.0
        && origin.abs().max_element() <= reach
        && far.abs().max_element() <= reach)
    {
        return Err(invalid(format!(
            "world frame (origin ({:e}, {:e}, {:e}), voxel size {voxel_size:e}) is not a finite box of voxels within ±{reach:e} world units",
            origin.x, origin.y, origin.z
        )));
    }
    if !unit_colour(background) {
        return Err(invalid("background colour channels not in [0, 1]".into()));
    }
    // The view rules of the scene formats, so that a saved view renders.
    if !(from.is_finite() && at.is_finite() && up.is_finite() && angle.is_finite()) {
        return Err(invalid("view is not finite".into()));
    }
    if !(within_world(from) && within_world(at)) {
        return Err(invalid(format!(
            "view from or at beyond ±{WORLD_LIMIT:e} world units"
        )));
    }
    if let Some(defect) = ViewDefect::of(from, at, up) {
        let key = match defect {
            ViewDefect::NoDirection => "at",
            ViewDefect::NoUp => "up",
        };
        return Err(invalid(format!("view {key}: {}", defect.problem())));
    }
    if !(angle > 0.0 && angle < 180.0) {
        return Err(invalid(format!(
            "view angle {angle}, expected between 0 and 180 degrees (exclusive)"
        )));
    }
    if !(hither >= 0.0 && hither.is_finite()) {
        return Err(invalid(format!(
            "view hither {hither}, expected a finite distance ≥ 0"
        )));
    }
    if resolution.iter().any(|r| !(1..=MAX_SIDE).contains(r)) {
        return Err(invalid(format!(
            "view resolution {}×{}, expected 1 to {MAX_SIDE} pixels",
            resolution[0], resolution[1]
        )));
    }
    if m.lights as usize > MAX_LIGHTS {
        return Err(invalid(format!(
            "{} lights, at most {MAX_LIGHTS}",
            m.lights
        )));
    }
    if m.materials as usize > MAX_MATERIALS || m.materials == 0 {
        return Err(invalid(format!(
            "{} materials, expected 1 to {MAX_MATERIALS}",
            m.materials
        )));
    }
    Ok(m)
}

/// A raster file's bytes: mapped, read (from a pipe or device, which
/// cannot be mapped), or none for an empty file.
enum Mapped {
    Map(Mmap),
    Read(Vec<u8>),
    Empty,
}

impl std::ops::Deref for Mapped {
    type Target = [u8];
    fn deref(&self) -> &[u8] {
        match self {
            Self::Map(m) => m,
            Self::Read(b) => b,
            Self::Empty => &[],
        }
    }
}

/// Maps the file at `path` (read-only, shared): its bytes are read from
/// the page cache as they are used, not read in full. A pipe or device
/// (`/dev/stdin`) is read in full instead, up to the default memory
/// limit; a directory is refused as one.
#[allow(unsafe_code)]
fn map(path: &Path) -> Result<Mapped, RasterFileError> {
    let io = |what, source| RasterFileError::Io {
        path: path.to_path_buf(),
        what,
        source,
    };
    let file = File::open(path).map_err(|e| io("cannot open", e))?;
    let meta = file.metadata().map_err(|e| io("cannot read", e))?;
    if meta.is_dir() {
        return Err(io(
            "cannot read",
            std::io::Error::other("a directory, not a raster file"),
        ));
    }
    if !meta.is_file() {
        let limit = default_max_memory();
        let mut bytes = Vec::new();
        std::io::Read::read_to_end(
            &mut std::io::Read::take(file, limit.saturating_add(1)),
            &mut bytes,
        )
        .map_err(|e| io("cannot read", e))?;
        if bytes.len() as u64 > limit {
            return Err(io(
                "cannot read",
                std::io::Error::other(format!(
                    "more than the memory limit of {} from a stream",
                    Bytes(limit)
                )),
            ));
        }
        return Ok(if bytes.is_empty() {
            Mapped::Empty
        } else {
            Mapped::Read(bytes)
        });
    }
    if meta.len() == 0 {
        return Ok(Mapped::Empty);
    }
    // SAFETY: the map is read-only (a shared mapping of the file); rrt
    // writes raster files to a temporary file renamed over the target
    // (so a file being replaced keeps its mapped inode). Another program
    // truncating the file in place while it is mapped would end the
    // process with SIGBUS; one changing it in place could change what is
    // read after the checksums were checked.
    let map = unsafe { Mmap::map(&file) }.map_err(|e| io("cannot map", e))?;
    Ok(Mapped::Map(map))
}

/// The number of entries of `len` bytes in a section of `codec` (its block
/// table's count, or its length over the entry's).
fn entry_count(b: &[u8], codec: u32, len: u64) -> Result<u64, String> {
    if codec == CODEC_BLOCKS {
        return Ok(Cursor::new(b).u64());
    }
    if !(b.len() as u64).is_multiple_of(len) {
        return Err(format!(
            "{} bytes, not a whole number of {len}-byte entries",
            b.len()
        ));
    }
    Ok(b.len() as u64 / len)
}

/// The `count` entries (fields of the widths `fields`) of a section of
/// `codec` whose bytes are `b` (at byte `off` of the file), each made by
/// `parse` from its bytes; on the current rayon pool.
fn decode_entries<T: Clone + Default + Send>(
    b: &[u8],
    off: u64,
    codec: u32,
    fields: &[usize],
    count: u64,
    parse: impl Fn(&[u8]) -> T + Sync,
) -> Result<Vec<T>, String> {
    let len: usize = fields.iter().sum();
    let n = usize::try_from(count).map_err(|_| format!("{count} entries"))?;
    if codec == CODEC_RAW {
        if b.len() != n.saturating_mul(len) {
            return Err(format!("{} bytes for {n} entries of {len}", b.len()));
        }
        return Ok(b.par_chunks_exact(len).map(&parse).collect());
    }
    let mut c = Cursor::new(b);
    let _ = c.u64();
    let (per, blocks) = (c.u32() as usize, c.u32() as usize);
    if per == 0 || per.saturating_mul(len) > MAX_BLOCK || blocks != n.div_ceil(per) {
        return Err(format!(
            "block table of {blocks} blocks of {per} entries for {n} entries"
        ));
    }
    let table_end = 16usize.saturating_add(blocks.saturating_mul(4));
    if table_end > b.len() {
        return Err(format!(
            "block table of {blocks} blocks past the section's end"
        ));
    }
    let mut ranges = Vec::with_capacity(blocks);
    let mut at = table_end;
    for _ in 0..blocks {
        let l = c.u32() as usize;
        let end = at.saturating_add(l);
        if end > b.len() {
            return Err(format!(
                "block at byte {} ends past the section",
                off + at as u64
            ));
        }
        ranges.push(at..end);
        at = end;
    }
    if at != b.len() {
        return Err(format!("{} bytes after the last block", b.len() - at));
    }
    let mut out = vec![T::default(); n];
    // Each job's blocks share two buffers: a fresh block-sized allocation
    // per block would be mapped, faulted in and unmapped every time.
    out.par_chunks_mut(per)
        .zip(ranges.par_iter())
        .try_for_each_init(
            || (Vec::new(), Vec::new()),
            |(t, raw): &mut (Vec<u8>, Vec<u8>), (dst, r)| {
                let fail = || {
                    format!(
                        "the block at byte {} does not decompress",
                        off + r.start as u64
                    )
                };
                t.resize(dst.len() * len, 0);
                let got = lz4_flex::block::decompress_into(&b[r.clone()], t).map_err(|_| fail())?;
                if got != t.len() {
                    return Err(fail());
                }
                raw.resize(t.len(), 0);
                untransposed(t, fields, raw);
                for (d, e) in dst.iter_mut().zip(raw.chunks_exact(len)) {
                    *d = parse(e);
                }
                Ok(())
            },
        )?;
    Ok(out)
}

fn u32_from(b: &[u8]) -> u32 {
    u32::from_le_bytes([b[0], b[1], b[2], b[3]])
}

/// The header and meta section of a raster file (and the counts of its
/// version 3 block tables).
///
/// # Errors
/// As [`load`], for the header and meta section.
pub fn info(path: &Path) -> Result<Info, RasterFileError> {
    info_from(&map(path)?, path)
}

/// [`info`], and with `check`, [`verify`] and a full [`load_with`] on
/// `check`'s progress bar, from one reading of the file (so that a pipe,
/// which can be read once, is checked too).
///
/// # Errors
/// As [`info`], [`verify`] and [`load`].
pub fn inspect(path: &Path, check: Option<&ProgressBar>) -> Result<Info, RasterFileError> {
    let bytes = map(path)?;
    let info = info_from(&bytes, path)?;
    if let Some(progress) = check {
        verify_from(&bytes, path, progress)?;
        load_from(&bytes, path, progress, default_max_memory())?;
    }
    Ok(info)
}

/// [`info`] of the file's `bytes`.
fn info_from(bytes: &[u8], path: &Path) -> Result<Info, RasterFileError> {
    let h = read_header(bytes, path)?;
    let m = read_meta(bytes, path, &h)?;
    let count = |k: usize, len: u64| {
        let (codec, _, off, l) = h.sections[k];
        entry_count(&bytes[off as usize..(off + l) as usize], codec, len).unwrap_or(0)
    };
    let voxels = u64::from(m.dims[0]) * u64::from(m.dims[1]) * u64::from(m.dims[2]);
    let lists = count(7, 4);
    let dir = count(2, DIRECTORY_ENTRY_LEN);
    Ok(Info {
        version: h.version,
        exact: m.exact,
        compressed: h.sections.iter().any(|s| s.0 == CODEC_BLOCKS),
        plane_bricks: if h.version == 3 {
            count(1, PLANE_BRICK_LEN)
        } else {
            0
        },
        list_entries: lists,
        dims: m.dims,
        origin: m.origin,
        voxel_size: m.voxel_size,
        separation: m.separation,
        exact_records: m.exact_records,
        records: m.records,
        objects: m.objects,
        materials: m.materials,
        lights: m.lights,
        file_bytes: h.file_len,
        memory: memory_needed(voxels, dir, m.records, lists),
    })
}

/// Bytes of a loaded raster: plane, line level, directory, records, lists.
fn memory_needed(voxels: u64, directory: u64, records: u64, lists: u64) -> u64 {
    voxels
        .saturating_add(voxels.div_ceil(LINE_CELLS as u64))
        .saturating_add(directory.saturating_mul(DIRECTORY_ENTRY_LEN))
        .saturating_add(records.saturating_mul(size_of::<VoxelRecord>() as u64))
        .saturating_add(lists.saturating_mul(4))
}

/// Checks every section's checksum and that everything between and after
/// the sections (the header's last word, the padding) is zero, reading
/// the mapped file once (nothing is kept); `progress` counts bytes.
/// `rrt info --check` then loads the raster, which decodes and checks
/// every entry.
///
/// # Errors
/// As [`load`] for the header, then [`RasterFileError::Checksum`] naming
/// the first section that does not match, or [`RasterFileError::Invalid`]
/// for a non-zero padding byte.
pub fn verify(path: &Path, progress: &ProgressBar) -> Result<(), RasterFileError> {
    verify_from(&map(path)?, path, progress)
}

/// [`verify`] of the file's `bytes`.
fn verify_from(bytes: &[u8], path: &Path, progress: &ProgressBar) -> Result<(), RasterFileError> {
    let h = read_header(bytes, path)?;
    progress.set_length(h.file_len);
    progress.set_position(0);
    let (n, header_len, entry) = layout(h.version);
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by_key(|&k| h.sections[k].2);
    // The zero bytes after the header's checksum, then the padding after
    // each section (to the next section or the end of the file).
    let checksum_end = (16 + entry * n + 4) as u64;
    let mut gaps = vec![(checksum_end, header_len)];
    for (i, &k) in order.iter().enumerate() {
        section(bytes, path, &h, k, progress, |_, _| {})?;
        let (_, _, off, len) = h.sections[k];
        let end = off + len;
        let next = order
            .get(i + 1)
            .map_or(h.file_len, |&j| h.sections[j].2)
            .max(end);
        gaps.push((end, next));
    }
    for (from, to) in gaps {
        if bytes[from as usize..to as usize].iter().any(|&b| b != 0) {
            return Err(RasterFileError::Invalid {
                path: path.to_path_buf(),
                what: format!("non-zero padding between bytes {from} and {to}"),
            });
        }
        progress.inc(to - from);
    }
    Ok(())
}

/// Loads a raster file (module docs), refusing one that needs more memory
/// than [`default_max_memory`].
///
/// # Errors
/// [`RasterFileError`] naming the file and what is wrong.
pub fn load(path: &Path) -> Result<VoxelScene, RasterFileError> {
    load_with(path, &ProgressBar::hidden())
}

/// [`load`], counting the bytes checked on `progress` (its length is set
/// to the file's).
///
/// # Errors
/// As [`load`].
pub fn load_with(path: &Path, progress: &ProgressBar) -> Result<VoxelScene, RasterFileError> {
    load_within(path, progress, default_max_memory())
}

/// [`load_with`], refusing a raster that needs more than `max_memory`
/// bytes once loaded ([`RasterFileError::TooLarge`]) before allocating it.
///
/// # Errors
/// As [`load`].
pub fn load_within(
    path: &Path,
    progress: &ProgressBar,
    max_memory: u64,
) -> Result<VoxelScene, RasterFileError> {
    let bytes = map(path)?;
    load_from(&bytes, path, progress, max_memory)
}

/// [`load`] from the bytes of a raster file in memory, named `path` in
/// errors.
///
/// # Errors
/// As [`load`].
pub fn load_bytes(path: &Path, bytes: &[u8]) -> Result<VoxelScene, RasterFileError> {
    load_bytes_within(path, bytes, default_max_memory())
}

/// [`load_bytes`], refusing a raster that needs more than `max_memory`
/// bytes once loaded ([`RasterFileError::TooLarge`]) before allocating it.
///
/// # Errors
/// As [`load`].
pub fn load_bytes_within(
    path: &Path,
    bytes: &[u8],
    max_memory: u64,
) -> Result<VoxelScene, RasterFileError> {
    load_from(bytes, path, &ProgressBar::hidden(), max_memory)
}

/// The plane, directory, records and lists of a raster file.
struct Raster {
    plane: Plane,
    directory: Vec<u32>,
    records: Vec<VoxelRecord>,
    lists: Vec<u32>,
    /// Whether the plane is the records' derived plane, no brick stored
    /// over it (its opaque voxels are then exactly the records').
    derived: bool,
}

/// [`load_with`] from the bytes of a file, named `path` in errors.
fn load_from(
    bytes: &[u8],
    path: &Path,
    progress: &ProgressBar,
    max_memory: u64,
) -> Result<VoxelScene, RasterFileError> {
    let invalid = |what: String| RasterFileError::Invalid {
        path: path.to_path_buf(),
        what,
    };
    let h = read_header(bytes, path)?;
    let m = read_meta(bytes, path, &h)?;
    progress.set_length(h.file_len);
    progress.set_position(0);
    let extent =
        Extent::new(m.dims[0], m.dims[1], m.dims[2]).map_err(|e| invalid(e.to_string()))?;
    let expect = |k: usize, len: u64| -> Result<(), RasterFileError> {
        if h.sections[k].3 != len {
            return Err(invalid(format!(
                "{} section of {} bytes, the counts say {len}",
                h.name(k),
                h.sections[k].3
            )));
        }
        Ok(())
    };
    let dir_n = directory_len(extent).ok_or_else(|| invalid("too many bricks".into()))?;
    expect(4, m.objects.saturating_mul(OBJECT_LEN))?;
    expect(5, u64::from(m.materials) * MATERIAL_LEN)?;
    expect(6, u64::from(m.lights) * LIGHT_LEN)?;
    let raw = |k: usize| section(bytes, path, &h, k, progress, |_, _| {});
    let materials = materials_from(raw(5)?).map_err(|e| h.invalid_in(path, 5, &e))?;
    let objects = objects_from(raw(4)?, materials.len()).map_err(|e| h.invalid_in(path, 4, &e))?;
    let lights = lights_from(raw(6)?).map_err(|e| h.invalid_in(path, 6, &e))?;
    let tables = (objects.len(), materials.len());
    let Raster {
        plane,
        directory,
        records,
        lists,
        derived,
    } = if h.version == 3 {
        load_sparse(bytes, path, &h, &m, extent, tables, progress, max_memory)?
    } else {
        // Every length below is checked against the section table, whose
        // sections all lie inside the file.
        expect(1, extent.len() as u64)?;
        expect(2, dir_n as u64 * DIRECTORY_ENTRY_LEN)?;
        expect(3, m.records.saturating_mul(RECORD_LEN))?;
        if !h.sections[7].3.is_multiple_of(4) {
            return Err(invalid(format!(
                "lists section of {} bytes, not a whole number of u32 entries",
                h.sections[7].3
            )));
        }
        let needed = memory_needed(
            extent.len() as u64,
            dir_n as u64,
            m.records,
            h.sections[7].3 / 4,
        );
        if needed > max_memory {
            return Err(RasterFileError::TooLarge {
                path: path.to_path_buf(),
                needed,
                limit: max_memory,
            });
        }
        let mut plane = Plane::zeroed(extent.len()).map_err(|source| RasterFileError::Io {
            path: path.to_path_buf(),
            what: "cannot allocate the raster plane",
            source,
        })?;
        section(bytes, path, &h, 1, progress, |at, piece| {
            plane[at..at + piece.len()].copy_from_slice(piece);
        })?;
        let words = |b: &[u8]| b.chunks_exact(4).map(u32_from).collect::<Vec<u32>>();
        let raster = Raster {
            plane,
            directory: words(raw(2)?),
            records: raw(3)?
                .par_chunks_exact(RECORD_LEN as usize)
                .map(record_from)
                .collect(),
            lists: words(raw(7)?),
            derived: false,
        };
        let store =
            RecordStore::with_lists(extent, &raster.directory, &raster.records, &raster.lists)
                .map_err(|e| h.invalid_in(path, store_section(e), &e.to_string()))?;
        in_tables(&store, tables).map_err(|e| h.invalid_in(path, 3, &e))?;
        raster
    };
    Ok(VoxelScene {
        frame: RasterFrame {
            extent,
            origin: m.origin,
            voxel_size: m.voxel_size,
        },
        separation: m.separation,
        exact: m.exact,
        exact_records: m.exact_records,
        // The coarse level from the records where they are the opaque
        // voxels by construction, else from the plane's cells.
        lines: if derived {
            line_level(extent, &plane, &directory)
        } else {
            line_level_of_plane(extent, &plane)
        },
        plane,
        directory,
        records,
        lists,
        objects,
        materials,
        lights,
        background: m.background,
        view: m.view,
        direct: Vec::new(),
    })
}

/// Whether every record of `store` names objects and a material within
/// tables of `(objects, materials)` entries; the first that does not, in
/// words.
fn in_tables(store: &RecordStore<'_>, (objects, materials): (usize, usize)) -> Result<(), String> {
    for (i, r) in store.records().iter().enumerate() {
        let ids = store.objects(r);
        if ids.iter().any(|&o| o as usize >= objects) || usize::from(r.material) >= materials {
            return Err(format!(
                "record {i} names object {} and material {}, beyond the tables",
                ids.iter().max().copied().unwrap_or(u32::MAX),
                r.material
            ));
        }
    }
    Ok(())
}

/// The section (its index in the table) holding what `e` finds wrong:
/// the brick directory, the records or the object lists.
fn store_section(e: StoreError) -> usize {
    match e {
        StoreError::TooManyBricks
        | StoreError::DirectoryLength { .. }
        | StoreError::DirectoryStart
        | StoreError::DirectoryOrder { .. }
        | StoreError::DirectoryEnd { .. } => 2,
        StoreError::ListsEnd { .. } | StoreError::ListsTooLong { .. } => 7,
        _ => 3,
    }
}

/// The raster of a version 3 file: its entries decoded and validated (a
/// store whose records name objects and materials within `tables`), the
/// plane made from the records ([`derive_plane`]) and its stored bricks
/// written over it.
#[allow(clippy::too_many_arguments)] // the file's parts, read once
fn load_sparse(
    bytes: &[u8],
    path: &Path,
    h: &Header,
    m: &Meta,
    extent: Extent,
    tables: (usize, usize),
    progress: &ProgressBar,
    max_memory: u64,
) -> Result<Raster, RasterFileError> {
    let invalid = |k: usize, what: String| RasterFileError::Invalid {
        path: path.to_path_buf(),
        what: format!(
            "{} section (bytes {} to {}): {what}",
            h.name(k),
            h.sections[k].2,
            h.sections[k].2 + h.sections[k].3
        ),
    };
    let mut secs = Vec::with_capacity(4);
    for k in [1, 2, 3, 7] {
        let b = section(bytes, path, h, k, progress, |_, _| {})?;
        let len = [PLANE_BRICK_LEN, DIRECTORY_ENTRY_LEN, RECORD_LEN, 4][secs.len()];
        let n = entry_count(b, h.sections[k].0, len).map_err(|e| invalid(k, e))?;
        secs.push((k, b, n));
    }
    let [
        (_, bricks_b, bricks_n),
        (_, dir_b, dir_n),
        (_, rec_b, rec_n),
        (_, lists_b, lists_n),
    ] = secs[..]
    else {
        return Err(invalid(1, "sections missing".into()));
    };
    let bricks_total = brick_count(extent).unwrap_or(usize::MAX) as u64;
    if dir_n != bricks_total + 1 {
        return Err(invalid(
            2,
            format!("{dir_n} entries, the raster has {bricks_total} bricks"),
        ));
    }
    if rec_n != m.records {
        return Err(invalid(
            3,
            format!("{rec_n} records, the meta section says {}", m.records),
        ));
    }
    if bricks_n > bricks_total {
        return Err(invalid(
            1,
            format!("{bricks_n} bricks, the raster has {bricks_total}"),
        ));
    }
    let needed = memory_needed(extent.len() as u64, dir_n, rec_n, lists_n)
        .saturating_add(bricks_n.saturating_mul(PLANE_BRICK_LEN + 24));
    if needed > max_memory {
        return Err(RasterFileError::TooLarge {
            path: path.to_path_buf(),
            needed,
            limit: max_memory,
        });
    }
    let at = |k: usize| h.sections[k].2;
    let directory = decode_entries(dir_b, at(2), h.sections[2].0, &[4], dir_n, u32_from)
        .map_err(|e| invalid(2, e))?;
    let records = decode_entries(
        rec_b,
        at(3),
        h.sections[3].0,
        RECORD_FIELDS,
        rec_n,
        record_from,
    )
    .map_err(|e| invalid(3, e))?;
    let lists = decode_entries(lists_b, at(7), h.sections[7].0, &[4], lists_n, u32_from)
        .map_err(|e| invalid(7, e))?;
    let bricks = decode_entries(
        bricks_b,
        at(1),
        h.sections[1].0,
        &PLANE_BRICK_FIELDS,
        bricks_n,
        |e| PlaneBrick {
            brick: le_value(&e[..8]),
            cells: e[8..].to_vec(),
        },
    )
    .map_err(|e| invalid(1, e))?;
    let store = RecordStore::with_lists(extent, &directory, &records, &lists)
        .map_err(|e| invalid(store_section(e), e.to_string()))?;
    in_tables(&store, tables).map_err(|e| invalid(3, e))?;
    let nz = extent.dims()[2];
    let (mut plane, _) = derive_plane(&store, [0, nz]).map_err(|source| RasterFileError::Io {
        path: path.to_path_buf(),
        what: "cannot make the raster plane",
        source,
    })?;
    let [bx, by, _] = brick_dims(extent).map(u64::from);
    let mut prev = None;
    for (i, b) in bricks.iter().enumerate() {
        if b.brick >= bricks_total || prev.is_some_and(|p| p >= b.brick) {
            return Err(invalid(
                1,
                format!("brick {i} (index {}) out of order or range", b.brick),
            ));
        }
        prev = Some(b.brick);
        let o = [b.brick % bx, (b.brick / bx) % by, b.brick / (bx * by)].map(|v| (v * 8) as u32);
        for (c, &v) in b.cells.iter().enumerate() {
            let p = [
                o[0] + (c as u32 & 7),
                o[1] + ((c as u32 >> 3) & 7),
                o[2] + (c as u32 >> 6),
            ];
            match extent.index(p) {
                Some(idx) => plane[idx] = v,
                None if v != 0 => {
                    return Err(invalid(
                        1,
                        format!("brick {i} has a non-zero cell outside the raster"),
                    ));
                }
                None => {}
            }
        }
    }
    Ok(Raster {
        plane,
        directory,
        records,
        lists,
        derived: bricks.is_empty(),
    })
}

/// The materials section, each value in range.
fn materials_from(b: &[u8]) -> Result<Vec<Material>, String> {
    let materials = Cursor::entries(b, MATERIAL_LEN, |c| Material {
        colour: c.vec(),
        kd: c.f64(),
        ks: c.f64(),
        shine: c.f64(),
        transmittance: c.f64(),
        ior: c.f64(),
        loc: None,
    });
    for (i, mt) in materials.iter().enumerate() {
        // What the scene readers accept: colour channels and the
        // transmittance in [0, 1], the rest finite and ≥ 0, an index of
        // refraction > 0 where light is transmitted.
        let ok = unit_colour(mt.colour)
            && [mt.kd, mt.ks, mt.shine, mt.transmittance, mt.ior]
                .iter()
                .all(|v| v.is_finite() && *v >= 0.0)
            && mt.transmittance <= 1.0
            && (mt.transmittance == 0.0 || mt.ior > 0.0);
        if !ok {
            return Err(format!("material {i} has a value out of range"));
        }
    }
    Ok(materials)
}

/// The objects section: each shape's saved form ([`Shape::load`]), valid,
/// with a material among the `materials`.
fn objects_from(b: &[u8], materials: usize) -> Result<Vec<WorldObject>, String> {
    let mut objects = Vec::with_capacity(b.len() / OBJECT_LEN as usize);
    for (i, chunk) in b.chunks_exact(OBJECT_LEN as usize).enumerate() {
        let mut c = Cursor::new(chunk);
        let kind = c.u32();
        let material = c.u32();
        let slots: Slots = std::array::from_fn(|_| c.f64());
        let Some(shape) = Shape::load(kind, &slots) else {
            return Err(format!("object {i} has unknown kind {kind}"));
        };
        let material = u16::try_from(material)
            .ok()
            .filter(|&mt| usize::from(mt) < materials)
            .ok_or_else(|| format!("object {i} names material {material}, beyond the table"))?;
        if let Err(e) = shape.validate() {
            return Err(format!("object {i}: {}: {e}", shape.kind()));
        }
        if !shape.bounds().is_none_or(|b| b.within_world()) {
            return Err(format!(
                "object {i}: {} reaches beyond ±{WORLD_LIMIT:e} world units",
                shape.kind()
            ));
        }
        objects.push(WorldObject { shape, material });
    }
    Ok(objects)
}

/// Whether every channel of `c` lies in `[0, 1]` (so is finite).
fn unit_colour(c: DVec3) -> bool {
    c.cmpge(DVec3::ZERO).all() && c.cmple(DVec3::ONE).all()
}

/// The lights section: positions finite, colour channels finite and ≥ 0
/// (as the scene readers accept).
fn lights_from(b: &[u8]) -> Result<Vec<WorldLight>, String> {
    let lights = Cursor::entries(b, LIGHT_LEN, |c| WorldLight {
        position: c.vec(),
        colour: c.vec(),
    });
    if lights.iter().any(|l| {
        !(within_world(l.position) && l.colour.is_finite() && l.colour.cmpge(DVec3::ZERO).all())
    }) {
        return Err(format!(
            "a light is not finite or beyond ±{WORLD_LIMIT:e} world units, or has a negative colour channel"
        ));
    }
    Ok(lights)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::Scene;
    use crate::voxelize::{BuildOptions, build};
    use rrt_core::raster::cell;

    const SCENE: &str = "v\nfrom 0 -5 2\nat 0 0 0.5\nup 0 0 1\nangle 40\nhither 0.1\nresolution 8 8\n\
        b 0.1 0.2 0.3\nl 3 -4 6\nf 0.9 0.4 0.2 0.8 0.2 20 0 1\ns 0 0 0.7 0.7\ns 0.9 0.2 0.3 0.3\n\
        c -1 0 0 0.3 -1 0 1 0.1\np 3\n-2 -2 0\n2 -2 0\n2 2 0\n";

    fn built(opts: BuildOptions) -> VoxelScene {
        let scene = Scene::parse("t.nff", SCENE.as_bytes()).unwrap();
        build(
            &scene,
            &BuildOptions { threads: 2, ..opts },
            &ProgressBar::hidden(),
        )
        .unwrap()
        .0
    }

    fn same(a: &VoxelScene, b: &VoxelScene) {
        assert_eq!(&a.plane[..], &b.plane[..]);
        assert_eq!(a.lines, b.lines);
        assert_eq!(a.directory, b.directory);
        assert_eq!(a.records, b.records);
        assert_eq!(a.lists, b.lists);
        assert_eq!(a.objects, b.objects);
        assert_eq!(a.frame, b.frame);
        assert_eq!((a.exact, a.exact_records), (b.exact, b.exact_records));
    }

    /// Every format of an exact and a paper raster (of 40 voxels, and of
    /// 70, more than one saving slab's margin): what loads is what was
    /// saved, and saves again to the same bytes.
    #[test]
    fn every_format_loads_what_was_saved() {
        let p = Path::new("t.rrt");
        for opts in [
            BuildOptions::new(40),
            BuildOptions::paper(40),
            BuildOptions::new(70),
        ] {
            let s = built(opts);
            for format in [
                Format::default(),
                Format::Sparse { compress: false },
                Format::Dense,
            ] {
                let bytes = save_bytes_as(&s, p, format).unwrap();
                let version = u32::from_le_bytes(bytes[8..12].try_into().unwrap());
                let expected = match (format, s.exact) {
                    (Format::Dense, true) => 2,
                    (Format::Dense, false) => 1,
                    _ => 3,
                };
                assert_eq!(version, expected);
                let back = load_bytes(p, &bytes).unwrap();
                same(&s, &back);
                assert_eq!(save_bytes_as(&back, p, format).unwrap(), bytes);
            }
        }
    }

    /// The compressed file of a built raster stores no plane brick and is
    /// smaller than the dense one.
    #[test]
    fn a_built_raster_stores_no_plane_brick() {
        let s = built(BuildOptions::new(64));
        assert!(
            differing_bricks(&s, &s.store().unwrap())
                .unwrap()
                .is_empty()
        );
        let sparse = save_bytes(&s, Path::new("t.rrt")).unwrap();
        let dense = save_bytes_as(&s, Path::new("t.rrt"), Format::Dense).unwrap();
        assert!(
            sparse.len() * 4 < dense.len(),
            "{} {}",
            sparse.len(),
            dense.len()
        );
    }

    /// A file whose contents break an invariant is refused naming the
    /// section and its bytes: an object naming a material beyond the
    /// table, a light that is not finite, a record naming an object beyond
    /// the table, a brick directory not starting at 0 (every version).
    #[test]
    fn corrupt_contents_name_their_section_and_bytes() {
        let s = built(BuildOptions::new(37));
        let path = Path::new("t.rrt");
        for format in [Format::Sparse { compress: false }, Format::Dense] {
            let good = save_bytes_as(&s, path, format).unwrap();
            let version = u32::from_le_bytes(good[8..12].try_into().unwrap());
            // The sections' places in the table: the same in every version.
            let (dir, recs, objs, lights) = (2, 3, 4, 6);
            let range = |k: usize| {
                let (_, _, off, len) = table_entry(&good, version, k);
                (usize::try_from(off).unwrap(), off + len)
            };
            let name = |k: usize| {
                if version == 3 && k == 1 {
                    "plane bricks"
                } else {
                    NAMES[k]
                }
            };
            let cases: [(usize, usize, &[u8], &str); 4] = [
                (objs, 4, &99u32.to_le_bytes(), "object 0 names material 99"),
                (lights, 0, &f64::NAN.to_le_bytes(), "a light is not finite"),
                (
                    recs,
                    0,
                    &0x7fff_fff0u32.to_le_bytes(),
                    "record 0 names object",
                ),
                (
                    dir,
                    0,
                    &1u32.to_le_bytes(),
                    "brick directory does not start at 0",
                ),
            ];
            for (k, at, value, want) in cases {
                let mut b = good.clone();
                let (off, end) = range(k);
                b[off + at..off + at + value.len()].copy_from_slice(value);
                reseal(&mut b);
                let e = load_bytes(path, &b).unwrap_err().to_string();
                let section = format!(
                    "t.rrt: corrupt: {} section (bytes {off} to {end}): ",
                    name(k)
                );
                assert!(e.starts_with(&section), "version {version}: {e}");
                assert!(e.contains(want), "version {version}: {e}");
            }
        }
    }

    /// A plane that is not the one made from the records (cells changed
    /// in two bricks, one at the raster's edge) keeps its cells through
    /// a version 3 file: those bricks are stored.
    #[test]
    fn changed_plane_cells_are_stored_as_bricks() {
        let mut s = built(BuildOptions::new(37));
        let e = s.extent();
        let [nx, ny, nz] = e.dims();
        let far = e.index([nx - 1, ny - 1, nz - 1]).unwrap();
        let mid = e.index([nx / 3, ny / 2, nz / 2]).unwrap();
        s.plane[far] ^= 0x04;
        s.plane[mid] ^= 0x08;
        let bricks = differing_bricks(&s, &s.store().unwrap()).unwrap();
        assert_eq!(bricks.len(), 2);
        for format in [Format::default(), Format::Sparse { compress: false }] {
            let bytes = save_bytes_as(&s, Path::new("t.rrt"), format).unwrap();
            let back = load_bytes(Path::new("t.rrt"), &bytes).unwrap();
            assert_eq!(&back.plane[..], &s.plane[..]);
            assert_eq!(back.lines, line_level(e, &s.plane, &s.directory));
        }
    }

    /// A built scene saved as built writes the bytes of the full check;
    /// a plane whose opaque cells are not its records' (a rank hint
    /// changed, an opaque cell cleared, a transparent one made opaque) is
    /// not taken for built, and its bricks are stored.
    #[test]
    fn saving_as_built_checks_the_opaque_cells() {
        let bytes = |s: &VoxelScene, trust: Trust| {
            let mut out = std::io::Cursor::new(Vec::new());
            write_raster(
                s,
                &mut out,
                &ProgressBar::hidden(),
                Format::default(),
                trust,
            )
            .unwrap();
            out.into_inner()
        };
        let s = built(BuildOptions::new(37));
        let matches = |s: &VoxelScene| plane_matches_records(&s.plane, &s.store().unwrap());
        assert!(matches(&s));
        assert_eq!(bytes(&s, Trust::Built), bytes(&s, Trust::Any));
        let opaque: Vec<usize> = (0..s.plane.len())
            .filter(|&i| s.plane[i] & cell::OPAQUE != 0)
            .collect();
        let clear = (0..s.plane.len())
            .find(|&i| s.plane[i] & (cell::OPAQUE | cell::PROXIMITY) == 0)
            .unwrap();
        let edits: [(usize, u8); 3] = [
            (opaque[opaque.len() / 2], 0x3f << cell::DISTANCE_SHIFT),
            (opaque[0], cell::OPAQUE),
            (clear, cell::OPAQUE),
        ];
        for (i, bits) in edits {
            let mut t = built(BuildOptions::new(37));
            t.plane[i] ^= bits;
            assert!(!matches(&t), "cell {i} ^ {bits:#x}");
            let b = bytes(&t, Trust::Built);
            assert_eq!(b, bytes(&t, Trust::Any));
            let back = load_bytes(Path::new("t.rrt"), &b).unwrap();
            assert_eq!(&back.plane[..], &t.plane[..]);
        }
    }

    #[test]
    fn transposed_entries_come_back() {
        let fields = [4, 2, 1, 8, 1, 3];
        let raw: Vec<u8> = (0..19u32 * 37)
            .map(|i| (i.wrapping_mul(2654435761) >> 13) as u8)
            .collect();
        let t = transposed(&raw, &fields);
        let mut back = vec![0u8; raw.len()];
        untransposed(&t, &fields, &mut back);
        assert_eq!(back, raw);
    }

    /// A raster needing more memory than the limit is refused before its
    /// plane is made.
    #[test]
    fn the_memory_limit_is_kept() {
        let s = built(BuildOptions::new(40));
        let bytes = save_bytes(&s, Path::new("t.rrt")).unwrap();
        let e = load_bytes_within(Path::new("t.rrt"), &bytes, 1000)
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("t.rrt: the raster needs"), "{e}");
        assert!(e.contains("more than the limit of 1000 B"), "{e}");
    }

    /// A frame far beyond any a fit makes of geometry within the world's
    /// limit (a voxel size written over) is refused, not rendered empty.
    #[test]
    fn a_frame_beyond_the_world_limit_is_refused() {
        let mut s = built(BuildOptions::new(24));
        let good = save_bytes(&s, Path::new("t.rrt")).unwrap();
        assert!(load_bytes(Path::new("t.rrt"), &good).is_ok());
        // 24 voxels of 5e59 reach 1.2e61.
        for size in [5e59, 1e300] {
            s.frame.voxel_size = size;
            let bytes = save_bytes(&s, Path::new("t.rrt")).unwrap();
            let Err(e) = load_bytes(Path::new("t.rrt"), &bytes).map(drop) else {
                panic!("voxel size {size:e} loaded");
            };
            let e = e.to_string();
            assert!(
                e.contains("is not a finite box of voxels within ±5e60 world units"),
                "{size:e}: {e}"
            );
        }
    }

    #[test]
    fn objects_and_lights_beyond_the_world_limit_are_refused() {
        let mut vs = built(BuildOptions::new(24));
        let lights = |vs: &VoxelScene| lights_from(&lights_bytes(vs));
        let objects = |vs: &VoxelScene| objects_from(&objects_bytes(vs), vs.materials.len());
        assert!(lights(&vs).is_ok() && objects(&vs).is_ok());
        vs.lights[0].position.z = WORLD_LIMIT;
        assert!(lights(&vs).is_ok());
        vs.lights[0].position.z = 2e60;
        assert!(lights(&vs).unwrap_err().contains("beyond ±1e60"));
        let Shape::Sphere(s) = &mut vs.objects[0].shape else {
            panic!("{:?}", vs.objects[0].shape);
        };
        s.radius = 1e61;
        let e = objects(&vs).unwrap_err();
        assert_eq!(e, "object 0: sphere reaches beyond ±1e60 world units");
    }
}
