//! Saved rasters: a voxelized scene in one versioned, checksummed file, so
//! that the view-independent work (voxelization, light visibility,
//! precomputed illumination) is done once and the scene rendered from any
//! view (the paper's point).
//!
//! # Layout (versions 1 and 2)
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
//! The paper's raster (one object per voxel) is written as version 1,
//! byte for byte as before exact rasters existed; an exact raster
//! ([`VoxelScene::exact`]: conservative, with object lists, possibly none)
//! as version 2, which an rrt reading only version 1 refuses by its
//! version.
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
//! The crc32 (IEEE, `crc32fast`) of each section is in its table entry.
//!
//! # Loading
//! [`load`] refuses, with the file's name and what is wrong: a file that is
//! not a raster, another version, a header or section whose checksum does
//! not match (corrupt), a section that ends past the end of the file or a
//! file shorter than its last section's padding (truncated), bytes after
//! that padding, a section whose length disagrees with the counts, and contents
//! that break an invariant (dimensions, the record store's directory and
//! sort order, object and material indices, non-finite numbers). Sizes are
//! checked against the file's length before anything is allocated.
//! [`load_bytes`] does the same for the bytes of a file in memory, and
//! [`save_bytes`] gives the bytes [`save`] writes.
//!
//! The file is read, not memory-mapped: the checksums read every byte
//! anyway, and a plane read into anonymous memory gets huge pages
//! ([`Plane`]), which a file mapping does not.

use std::fs::File;
use std::io::{BufWriter, Read, Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};

use glam::DVec3;
use indicatif::ProgressBar;

use super::atomic::AtomicFile;
use rrt_core::light::ExactRecords;
use rrt_core::object_table::MAX_LIGHTS;
use rrt_core::raster::{Extent, LINE_CELLS};
use rrt_core::store::{RecordStore, directory_len};
use rrt_core::voxel::VoxelRecord;
use rrt_core::voxelize::Separation;

use crate::frame::RasterFrame;
use crate::scene::{Material, SourceLoc, View};
use crate::shape::{SLOTS, Shape, Slots};
use crate::voxelize::plane::Plane;
use crate::voxelize::{MAX_MATERIALS, VoxelScene, line_level};
use crate::voxelize::{WorldLight, WorldObject};

/// The file's first bytes.
pub const MAGIC: [u8; 8] = *b"RRTRASTR";
/// The newest version this code writes and reads (it reads version 1
/// too, and writes it for a raster without object lists).
pub const VERSION: u32 = 2;
/// Sections of a version 2 file (version 1 has the first 7).
const SECTIONS: usize = 8;
/// The header of a version 1 file.
const HEADER_LEN: u64 = 192;
/// The header of a version 2 file.
const HEADER2_LEN: u64 = 256;
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
/// A brick directory entry (a `u32` record offset).
const DIRECTORY_ENTRY_LEN: u64 = size_of::<u32>() as u64;
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

/// The section count and header length of `version` (1 or 2).
const fn layout(version: u32) -> (usize, u64) {
    if version == 1 {
        (SECTIONS - 1, HEADER_LEN)
    } else {
        (SECTIONS, HEADER2_LEN)
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
    #[error("{}: corrupt: the {section} checksum does not match", path.display())]
    Checksum {
        /// The file.
        path: PathBuf,
        /// Which section (or the header).
        section: &'static str,
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

fn meta_bytes(s: &VoxelScene) -> Vec<u8> {
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
    b.0.extend_from_slice(&[0; 2]);
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

/// Writes `scene` to `path` (module docs for the layout) through a
/// temporary file renamed over `path` when complete
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
    save_to(scene, out, &ProgressBar::hidden())
}

/// Writes `scene` into `out`, opened earlier (so that an unwritable
/// output is reported before voxelizing), and commits it over its target;
/// returns the file's length. `progress` counts bytes.
///
/// # Errors
/// [`RasterFileError::Io`] naming the target; the target is untouched.
pub fn save_to(
    scene: &VoxelScene,
    mut out: AtomicFile,
    progress: &ProgressBar,
) -> Result<u64, RasterFileError> {
    let path = out.target().to_path_buf();
    refuse_direct(scene, &path)?;
    let io = |source| RasterFileError::Io {
        path: path.clone(),
        what: "cannot write",
        source,
    };
    let len = write_raster(scene, out.file(), progress).map_err(io)?;
    out.commit().map_err(io)?;
    Ok(len)
}

/// The bytes [`save`] writes for `scene` (named `path` in errors).
///
/// # Errors
/// [`RasterFileError::Unsupported`] for what a raster file cannot hold.
pub fn save_bytes(scene: &VoxelScene, path: &Path) -> Result<Vec<u8>, RasterFileError> {
    refuse_direct(scene, path)?;
    let mut out = std::io::Cursor::new(Vec::new());
    write_raster(scene, &mut out, &ProgressBar::hidden()).map_err(|source| {
        RasterFileError::Io {
            path: path.to_path_buf(),
            what: "cannot write",
            source,
        }
    })?;
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

/// Writes `scene` into `file` from its start (module docs for the layout);
/// returns the length written.
fn write_raster<F: Write + Seek>(
    scene: &VoxelScene,
    file: &mut F,
    progress: &ProgressBar,
) -> std::io::Result<u64> {
    let mut w = BufWriter::with_capacity(1 << 20, &mut *file);
    let version = if scene.exact { 2 } else { 1 };
    let (sections, header_len) = layout(version);
    w.write_all(&vec![0u8; header_len as usize])?;
    // Every section's bytes, as the writer below counts them.
    progress.set_length(
        META_LEN
            + scene.plane.len() as u64
            + scene.directory.len() as u64 * DIRECTORY_ENTRY_LEN
            + scene.records.len() as u64 * RECORD_LEN
            + scene.objects.len() as u64 * OBJECT_LEN
            + scene.materials.len() as u64 * MATERIAL_LEN
            + scene.lights.len() as u64 * LIGHT_LEN
            + scene.lists.len() as u64 * 4,
    );
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
        match kind {
            1 => c.put(&meta_bytes(scene))?,
            2 => c.put(&scene.plane)?,
            3 => {
                let mut b =
                    Vec::with_capacity(scene.directory.len() * DIRECTORY_ENTRY_LEN as usize);
                for d in &scene.directory {
                    b.extend_from_slice(&d.to_le_bytes());
                }
                c.put(&b)?;
            }
            4 => {
                let mut b = Vec::with_capacity(1 << 20);
                for chunk in scene.records.chunks(1 << 15) {
                    b.clear();
                    for rec in chunk {
                        record_bytes(rec, &mut b);
                    }
                    c.put(&b)?;
                }
            }
            5 => c.put(&objects_bytes(scene))?,
            6 => c.put(&materials_bytes(scene))?,
            7 => c.put(&lights_bytes(scene))?,
            _ => {
                let b: Vec<u8> = scene.lists.iter().flat_map(|v| v.to_le_bytes()).collect();
                c.put(&b)?;
            }
        }
        let (len, crc) = (c.len, c.crc.finalize());
        table.push((kind, crc, offset, len));
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
    for (kind, crc, off, len) in &table {
        h.extend_from_slice(&kind.to_le_bytes());
        h.extend_from_slice(&crc.to_le_bytes());
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
    let (n, header_len) = layout(version);
    if (bytes.len() as u64) < header_len {
        return;
    }
    let le64 = |b: &[u8], at: usize| {
        let mut x = [0u8; 8];
        x.copy_from_slice(&b[at..at + 8]);
        u64::from_le_bytes(x)
    };
    for k in 0..n {
        let at = 16 + 24 * k;
        let (off, len) = (le64(bytes, at + 8), le64(bytes, at + 16));
        let Some(range) = usize::try_from(off)
            .ok()
            .zip(usize::try_from(len).ok())
            .and_then(|(o, l)| Some(o..o.checked_add(l)?))
            .filter(|r| r.end <= bytes.len())
        else {
            continue;
        };
        let crc = crc32fast::hash(&bytes[range]);
        bytes[at + 4..at + 8].copy_from_slice(&crc.to_le_bytes());
    }
    let at = 16 + 24 * n;
    let crc = crc32fast::hash(&bytes[..at]);
    bytes[at..at + 4].copy_from_slice(&crc.to_le_bytes());
}

/// Whether the file at `path` starts with the raster magic.
#[must_use]
pub fn is_raster_file(path: &Path) -> bool {
    let mut magic = [0u8; 8];
    File::open(path)
        .and_then(|mut f| f.read_exact(&mut magic))
        .is_ok_and(|()| magic == MAGIC)
}

/// The summary `rrt info` prints, read from the header and meta section
/// only.
#[derive(Clone, Debug, PartialEq)]
pub struct Info {
    /// The file's format version.
    pub version: u32,
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
    /// What the light bits of records of exact objects hold (version 2).
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
    /// Memory for plane, its line level (built on load), directory and
    /// records once loaded.
    pub memory: u64,
}

struct Header {
    version: u32,
    file_len: u64,
    /// (crc, offset, length) per section; the lists' is all zero in a
    /// version 1 file.
    sections: [(u32, u64, u64); SECTIONS],
}

fn read_header<R: Read>(
    file: &mut R,
    file_len: u64,
    path: &Path,
) -> Result<Header, RasterFileError> {
    let p = || path.to_path_buf();
    let mut h = [0u8; HEADER2_LEN as usize];
    let got = read_up_to(file, &mut h).map_err(|source| RasterFileError::Io {
        path: p(),
        what: "cannot read",
        source,
    })?;
    if got < 12 && got > 0 && (MAGIC.starts_with(&h[..got.min(8)])) {
        return Err(RasterFileError::Truncated {
            path: p(),
            what: format!("{got} bytes, shorter than the {HEADER_LEN}-byte header"),
        });
    }
    if got < 8 || h[..8] != MAGIC {
        return Err(RasterFileError::NotRaster { path: p() });
    }
    let mut c = Cursor::new(&h[8..]);
    let version = c.u32();
    if !(1..=VERSION).contains(&version) {
        return Err(RasterFileError::Version {
            path: p(),
            found: version,
        });
    }
    let (n, header_len) = layout(version);
    if (got as u64) < header_len {
        return Err(RasterFileError::Truncated {
            path: p(),
            what: format!("{got} bytes, shorter than the {header_len}-byte header"),
        });
    }
    let at = 16 + 24 * n;
    let stored = u32::from_le_bytes([h[at], h[at + 1], h[at + 2], h[at + 3]]);
    if crc32fast::hash(&h[..at]) != stored {
        return Err(RasterFileError::Checksum {
            path: p(),
            section: "header",
        });
    }
    let count = c.u32();
    if count as usize != n {
        return Err(RasterFileError::Invalid {
            path: p(),
            what: format!("{count} sections, expected {n} for version {version}"),
        });
    }
    let mut sections = [(0u32, 0u64, 0u64); SECTIONS];
    let mut end = header_len;
    for (k, s) in sections.iter_mut().take(n).enumerate() {
        let kind = c.u32();
        let crc = c.u32();
        let off = c.u64();
        let len = c.u64();
        if kind as usize != k + 1 || off < end {
            return Err(RasterFileError::Invalid {
                path: p(),
                what: format!("section table entry {} is out of order", k + 1),
            });
        }
        let stop = off
            .checked_add(len)
            .ok_or_else(|| RasterFileError::Invalid {
                path: p(),
                what: format!("{} section length overflows", NAMES[k]),
            })?;
        if stop > file_len {
            return Err(RasterFileError::Truncated {
                path: p(),
                what: format!(
                    "the {} section ends at byte {stop}, the file has {file_len}",
                    NAMES[k]
                ),
            });
        }
        end = stop;
        *s = (crc, off, len);
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
    Ok(Header {
        version,
        file_len,
        sections,
    })
}

fn read_up_to<R: Read>(file: &mut R, buf: &mut [u8]) -> std::io::Result<usize> {
    let mut got = 0;
    while got < buf.len() {
        match file.read(&mut buf[got..]) {
            Ok(0) => break,
            Ok(n) => got += n,
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
            Err(e) => return Err(e),
        }
    }
    Ok(got)
}

/// Reads section `k` into `buf` (whose length is the section's) and checks
/// its checksum; `progress` counts the bytes read.
fn read_section<R: Read + Seek>(
    file: &mut R,
    path: &Path,
    h: &Header,
    k: usize,
    buf: &mut [u8],
    progress: &ProgressBar,
) -> Result<(), RasterFileError> {
    let (crc, off, _) = h.sections[k];
    let io = |source| RasterFileError::Io {
        path: path.to_path_buf(),
        what: "cannot read",
        source,
    };
    file.seek(SeekFrom::Start(off)).map_err(io)?;
    // In pieces, so that the bar moves while a large plane is read.
    let mut hasher = crc32fast::Hasher::new();
    for piece in buf.chunks_mut(1 << 22) {
        file.read_exact(piece).map_err(io)?;
        hasher.update(piece);
        progress.inc(piece.len() as u64);
    }
    if hasher.finalize() != crc {
        return Err(RasterFileError::Checksum {
            path: path.to_path_buf(),
            section: NAMES[k],
        });
    }
    Ok(())
}

struct Meta {
    dims: [u32; 3],
    separation: Separation,
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

fn read_meta<R: Read + Seek>(
    file: &mut R,
    path: &Path,
    h: &Header,
) -> Result<Meta, RasterFileError> {
    let invalid = |what: String| RasterFileError::Invalid {
        path: path.to_path_buf(),
        what,
    };
    if h.sections[0].2 != META_LEN {
        return Err(invalid(format!(
            "meta section of {} bytes, expected {META_LEN}",
            h.sections[0].2
        )));
    }
    let mut b = vec![0u8; META_LEN as usize];
    read_section(file, path, h, 0, &mut b, &ProgressBar::hidden())?;
    let mut c = Cursor::new(&b);
    let dims = [c.u32(), c.u32(), c.u32()];
    let separation = match c.u8() {
        6 => Separation::Six,
        26 => Separation::TwentySix,
        s => return Err(invalid(format!("separation {s}, expected 6 or 26"))),
    };
    let exact_records = match (h.version, c.u8()) {
        (_, 0) => ExactRecords::Paper,
        (2, 1) => ExactRecords::Classify,
        (2, 2) => ExactRecords::Skip,
        (v, b) => {
            return Err(invalid(format!(
                "light bits of exact records {b}, expected 0{} in a version {v} file",
                if v == 2 { ", 1 or 2" } else { "" }
            )));
        }
    };
    c.take::<2>();
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
    if !(origin.is_finite() && voxel_size > 0.0 && voxel_size.is_finite()) {
        return Err(invalid("world frame is not finite".into()));
    }
    if !unit_colour(background) {
        return Err(invalid("background colour channels not in [0, 1]".into()));
    }
    if !(from.is_finite() && at.is_finite() && up.is_finite() && angle.is_finite()) {
        return Err(invalid("view is not finite".into()));
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

/// Opens `path` for reading, with its length.
fn open(path: &Path) -> Result<(File, u64), RasterFileError> {
    let file = File::open(path).map_err(|source| RasterFileError::Io {
        path: path.to_path_buf(),
        what: "cannot open",
        source,
    })?;
    let len = file
        .metadata()
        .map_err(|source| RasterFileError::Io {
            path: path.to_path_buf(),
            what: "cannot read",
            source,
        })?
        .len();
    Ok((file, len))
}

/// The header and meta section of a raster file.
///
/// # Errors
/// As [`load`], for the header and meta section.
pub fn info(path: &Path) -> Result<Info, RasterFileError> {
    let (mut file, len) = open(path)?;
    let h = read_header(&mut file, len, path)?;
    let m = read_meta(&mut file, path, &h)?;
    Ok(Info {
        version: h.version,
        list_entries: h.sections[7].2 / 4,
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
        memory: h.sections[1].2
            + h.sections[1].2.div_ceil(LINE_CELLS as u64)
            + h.sections[2].2
            + m.records * std::mem::size_of::<VoxelRecord>() as u64
            + h.sections[7].2,
    })
}

/// Checks every section's checksum and that everything between and after
/// the sections (the header's last word, the padding) is zero, reading
/// the file once in 1 MiB pieces (nothing is kept); `progress` counts
/// bytes.
///
/// # Errors
/// As [`load`] for the header, then [`RasterFileError::Checksum`] naming
/// the first section that does not match, or [`RasterFileError::Invalid`]
/// for a non-zero padding byte.
pub fn verify(path: &Path, progress: &ProgressBar) -> Result<(), RasterFileError> {
    let io = |source| RasterFileError::Io {
        path: path.to_path_buf(),
        what: "cannot read",
        source,
    };
    let (mut file, len) = open(path)?;
    let h = read_header(&mut file, len, path)?;
    progress.set_length(h.file_len);
    progress.set_position(0);
    let (n, header_len) = layout(h.version);
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by_key(|&k| h.sections[k].1);
    // The zero bytes after the header's checksum, then each section and
    // the padding after it (to the next section or the end of the file).
    let checksum_end = 16 + 24 * n as u64 + 4;
    let mut pieces = vec![(None, checksum_end, header_len - checksum_end)];
    for (n, &k) in order.iter().enumerate() {
        let (_, off, len) = h.sections[k];
        let end = off.saturating_add(len);
        let next = order
            .get(n + 1)
            .map_or(h.file_len, |&j| h.sections[j].1)
            .max(end);
        pieces.push((Some(k), off, len));
        pieces.push((None, end, next - end));
    }
    let mut buf = vec![0u8; 1 << 20];
    for (section, off, len) in pieces {
        file.seek(SeekFrom::Start(off)).map_err(io)?;
        let mut hasher = crc32fast::Hasher::new();
        let mut left = len;
        while left > 0 {
            let take = usize::try_from(left).map_or(buf.len(), |l| l.min(buf.len()));
            file.read_exact(&mut buf[..take]).map_err(io)?;
            if section.is_none() && buf[..take].iter().any(|&b| b != 0) {
                return Err(RasterFileError::Invalid {
                    path: path.to_path_buf(),
                    what: format!("non-zero padding between bytes {off} and {}", off + len),
                });
            }
            hasher.update(&buf[..take]);
            left -= take as u64;
            progress.inc(take as u64);
        }
        if let Some(k) = section
            && hasher.finalize() != h.sections[k].0
        {
            return Err(RasterFileError::Checksum {
                path: path.to_path_buf(),
                section: NAMES[k],
            });
        }
    }
    Ok(())
}

/// Loads a raster file (module docs).
///
/// # Errors
/// [`RasterFileError`] naming the file and what is wrong.
pub fn load(path: &Path) -> Result<VoxelScene, RasterFileError> {
    load_with(path, &ProgressBar::hidden())
}

/// [`load`], counting the bytes read on `progress` (its length is set to
/// the file's).
///
/// # Errors
/// As [`load`].
pub fn load_with(path: &Path, progress: &ProgressBar) -> Result<VoxelScene, RasterFileError> {
    let (file, len) = open(path)?;
    load_from(file, len, path, progress)
}

/// [`load`] from the bytes of a raster file in memory, named `path` in
/// errors.
///
/// # Errors
/// As [`load`].
pub fn load_bytes(path: &Path, bytes: &[u8]) -> Result<VoxelScene, RasterFileError> {
    load_from(
        std::io::Cursor::new(bytes),
        bytes.len() as u64,
        path,
        &ProgressBar::hidden(),
    )
}

/// [`load_with`] from `file` of `len` bytes, named `path` in errors.
fn load_from<R: Read + Seek>(
    mut file: R,
    len: u64,
    path: &Path,
    progress: &ProgressBar,
) -> Result<VoxelScene, RasterFileError> {
    let invalid = |what: String| RasterFileError::Invalid {
        path: path.to_path_buf(),
        what,
    };
    let h = read_header(&mut file, len, path)?;
    let m = read_meta(&mut file, path, &h)?;
    progress.set_length(h.file_len);
    progress.set_position(0);
    let extent =
        Extent::new(m.dims[0], m.dims[1], m.dims[2]).map_err(|e| invalid(e.to_string()))?;
    let expect = |k: usize, len: u64| -> Result<usize, RasterFileError> {
        if h.sections[k].2 != len {
            return Err(invalid(format!(
                "{} section of {} bytes, the counts say {len}",
                NAMES[k], h.sections[k].2
            )));
        }
        usize::try_from(len).map_err(|_| invalid(format!("{} section too large", NAMES[k])))
    };
    // Every length below is checked against the section table, whose
    // sections all lie inside the file: no allocation exceeds its size.
    let plane_len = expect(1, extent.len() as u64)?;
    let dir_n = directory_len(extent).ok_or_else(|| invalid("too many bricks".into()))?;
    let dir_len = expect(2, dir_n as u64 * DIRECTORY_ENTRY_LEN)?;
    let rec_len = expect(3, m.records.saturating_mul(RECORD_LEN))?;
    let obj_len = expect(4, m.objects.saturating_mul(OBJECT_LEN))?;
    let mat_len = expect(5, u64::from(m.materials) * MATERIAL_LEN)?;
    let light_len = expect(6, u64::from(m.lights) * LIGHT_LEN)?;
    let lists_bytes = h.sections[7].2;
    if lists_bytes % 4 != 0 {
        return Err(invalid(format!(
            "lists section of {lists_bytes} bytes, not a whole number of u32 entries"
        )));
    }
    let lists_len = expect(7, lists_bytes)?;
    let section = |file: &mut R, k: usize, len: usize| -> Result<Vec<u8>, RasterFileError> {
        let mut b = vec![0u8; len];
        read_section(file, path, &h, k, &mut b, progress)?;
        Ok(b)
    };

    let mut plane = Plane::zeroed(plane_len).map_err(|source| RasterFileError::Io {
        path: path.to_path_buf(),
        what: "cannot allocate the raster plane",
        source,
    })?;
    read_section(&mut file, path, &h, 1, &mut plane, progress)?;
    let directory = directory_from(&section(&mut file, 2, dir_len)?);
    let records = read_records(&mut file, path, &h, rec_len, progress)?;
    let materials = materials_from(&section(&mut file, 5, mat_len)?).map_err(invalid)?;
    let objects =
        objects_from(&section(&mut file, 4, obj_len)?, materials.len()).map_err(invalid)?;
    let lights = lights_from(&section(&mut file, 6, light_len)?).map_err(invalid)?;
    let lists: Vec<u32> = if lists_len == 0 {
        Vec::new()
    } else {
        section(&mut file, 7, lists_len)?
            .chunks_exact(4)
            .map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]]))
            .collect()
    };
    let store = RecordStore::with_lists(extent, &directory, &records, &lists)
        .map_err(|e| invalid(e.to_string()))?;
    for (i, r) in records.iter().enumerate() {
        let ids = store.objects(r);
        if ids.iter().any(|&o| o as usize >= objects.len())
            || usize::from(r.material) >= materials.len()
        {
            return Err(invalid(format!(
                "record {i} names object {} and material {}, beyond the tables",
                ids.iter().max().copied().unwrap_or(u32::MAX),
                r.material
            )));
        }
    }
    Ok(VoxelScene {
        frame: RasterFrame {
            extent,
            origin: m.origin,
            voxel_size: m.voxel_size,
        },
        separation: m.separation,
        exact: h.version == 2,
        exact_records: m.exact_records,
        lines: line_level(extent, &plane),
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

/// The brick directory section.
fn directory_from(b: &[u8]) -> Vec<u32> {
    b.chunks_exact(4)
        .map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]]))
        .collect()
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
        !(l.position.is_finite() && l.colour.is_finite() && l.colour.cmpge(DVec3::ZERO).all())
    }) {
        return Err("a light is not finite, or has a negative colour channel".into());
    }
    Ok(lights)
}

fn read_records<R: Read + Seek>(
    file: &mut R,
    path: &Path,
    h: &Header,
    len: usize,
    progress: &ProgressBar,
) -> Result<Vec<VoxelRecord>, RasterFileError> {
    let (crc, off, _) = h.sections[3];
    let io = |source| RasterFileError::Io {
        path: path.to_path_buf(),
        what: "cannot read",
        source,
    };
    file.seek(SeekFrom::Start(off)).map_err(io)?;
    let n = len / RECORD_LEN as usize;
    let mut records = Vec::with_capacity(n);
    let mut hasher = crc32fast::Hasher::new();
    let mut buf = vec![0u8; (1 << 15) * RECORD_LEN as usize];
    let mut left = len;
    while left > 0 {
        let take = left.min(buf.len());
        file.read_exact(&mut buf[..take]).map_err(io)?;
        hasher.update(&buf[..take]);
        records.extend(
            buf[..take]
                .chunks_exact(RECORD_LEN as usize)
                .map(record_from),
        );
        left -= take;
        progress.inc(take as u64);
    }
    if hasher.finalize() != crc {
        return Err(RasterFileError::Checksum {
            path: path.to_path_buf(),
            section: "records",
        });
    }
    Ok(records)
}
