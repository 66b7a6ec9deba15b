//! The voxelized scene: what voxelization hands to the tracer and to the
//! saved-raster file. The raster (plane, line level, brick directory and
//! records) and the world side: each object's exact geometry (the world
//! object table, indexed by the records' object id as the paper's object
//! table is, for intersection verification), the distinct materials and
//! the lights in `f64` for shading.

use std::fmt::Write as _;

use glam::DVec3;
use rayon::prelude::*;
use rrt_core::light::ExactRecords;
use rrt_core::proximity::field::{self, Area};
use rrt_core::proximity::{coarse_bounds, coarse_extent, coarse_level, line_stand_ins};
use rrt_core::raster::{Extent, Raster, cell, line_count};
use rrt_core::store::{BRICK, RecordStore, StoreError, brick_dims, rank_hint};
use rrt_core::voxel::VoxelRecord;
use rrt_core::voxelize::Separation;

use super::direct::DirectVolume;
use super::plane::Plane;
use crate::frame::RasterFrame;
use crate::scene::{Material, View, light_intensity};
use crate::shape::Shape;

/// A voxelized scene: the raster, its records and everything the renderer
/// needs besides the view.
#[derive(Debug)]
pub struct VoxelScene {
    /// World ↔ raster mapping and the raster's dimensions.
    pub frame: RasterFrame,
    /// The separation the surfaces were voxelized with: rays of a
    /// connectivity that needs more (26-connected rays need
    /// [`Separation::TwentySix`]) could pass through them.
    pub separation: Separation,
    /// One cell per voxel ([`rrt_core::raster::cell`]).
    pub plane: Plane,
    /// The plane's line level ([`Raster::with_lines`], from [`line_level`]):
    /// computed from the plane, never saved.
    pub lines: Vec<u8>,
    /// The brick directory of the record store.
    pub directory: Vec<u32>,
    /// The voxel records, sorted by brick and position.
    pub records: Vec<VoxelRecord>,
    /// The object lists of the voxels several objects share (empty for the
    /// paper's raster, one object per voxel; see [`rrt_core::store`]).
    pub lists: Vec<u32>,
    /// Voxelized for exact verification
    /// ([`BuildOptions::exact`](super::BuildOptions::exact)): every exact
    /// object owns every voxel its surface passes through, and the voxels
    /// several objects share have their lists. Otherwise the paper's
    /// raster, one object per voxel.
    pub exact: bool,
    /// What the light bits of the records whose objects all have exact
    /// geometry hold ([`LightParams::exact_records`](rrt_core::light::LightParams::exact_records));
    /// every other record has the paper's bits.
    pub exact_records: ExactRecords,
    /// The world object table, indexed by the object ids of the records
    /// and lists ([`RecordStore::objects`]).
    pub objects: Vec<WorldObject>,
    /// Distinct materials, indexed by [`VoxelRecord::material`].
    pub materials: Vec<Material>,
    /// Lights, in file order (light `i` is bit pair `i` of the records).
    pub lights: Vec<WorldLight>,
    /// Background colour.
    pub background: DVec3,
    /// The scene's view (the renderer may override it).
    pub view: View,
    /// The volumes rendered directly, in object-id order: their samples
    /// at the voxel centres and transfer functions (not saved: a saved
    /// raster refuses them).
    pub direct: Vec<DirectVolume>,
}

impl VoxelScene {
    /// The raster's dimensions.
    #[must_use]
    pub fn extent(&self) -> Extent {
        self.frame.extent
    }

    /// The raster (the plane over the extent, with its line level when
    /// the scene has one).
    ///
    /// # Errors
    /// Only if the plane or the line level does not match the extent, which
    /// the constructors rule out.
    pub fn raster(&self) -> Result<Raster<'_>, rrt_core::RasterError> {
        let r = Raster::new(self.frame.extent, &self.plane)?;
        if self.lines.is_empty() {
            Ok(r)
        } else {
            r.with_lines(&self.lines)
        }
    }

    /// The record store, validated (O(bricks + records)).
    ///
    /// # Errors
    /// The first broken store invariant.
    pub fn store(&self) -> Result<RecordStore<'_>, StoreError> {
        RecordStore::with_lists(
            self.frame.extent,
            &self.directory,
            &self.records,
            &self.lists,
        )
    }

    /// A digest of everything a render of this scene reads besides the
    /// view and the render's options: the raster's place and dimensions,
    /// the separation, the records, object lists and brick directory, the
    /// object table, the materials (not where the file defines them), the
    /// lights, the background and the samples of volumes rendered
    /// directly. Left out is what is made from these: the plane and line
    /// level (from the records), and the records' light bits and
    /// illumination (from the geometry and the lights), of which only
    /// whether they are the paper's bits, which the image shows as they
    /// are, counts. So a scene and its saved raster (`rrt voxelize`) have
    /// the same digest, and two scenes that render differently from some
    /// view almost surely differ in it (a CRC-32 of each of three parts:
    /// 24 hex digits). Deterministic on every host.
    #[must_use]
    pub fn fingerprint(&self) -> String {
        let crc = |parts: &[&[u8]]| {
            let mut h = crc32fast::Hasher::new();
            for p in parts {
                h.update(&(p.len() as u64).to_le_bytes());
                h.update(p);
            }
            h.finalize()
        };
        // The light bits and the illumination they give are made from
        // the rest (the records' geometry, the objects and the lights);
        // whether they are the paper's, which the image shows, or only
        // the proofs of a renderer that finds the same shadows without
        // them, is `paper_bits`.
        let mut records = crc32fast::Hasher::new();
        let mut buffer = Vec::with_capacity(4096);
        for chunk in self.records.chunks(4096) {
            buffer.clear();
            buffer.extend(chunk.iter().map(|r| VoxelRecord {
                lights: 0,
                illum: [0; 3],
                ..*r
            }));
            records.update(bytemuck::cast_slice(&buffer));
        }
        let raster = crc(&[
            &records.finalize().to_le_bytes(),
            bytemuck::cast_slice(&self.lists),
            bytemuck::cast_slice(&self.directory),
        ]);
        let paper_bits = self.exact_records == ExactRecords::Paper;
        // The world side as text (`Debug` writes every `f64` exactly),
        // fed to the checksum piece by piece.
        let mut world = CrcText(crc32fast::Hasher::new());
        let _ = write!(
            world,
            "{:?}; {:?}; {}; {paper_bits}; {:?}; {:?}; ",
            self.frame, self.separation, self.exact, self.lights, self.background
        );
        for m in &self.materials {
            let _ = write!(
                world,
                "{:?} {:?} {:?} {:?} {:?} {:?}; ",
                m.colour, m.kd, m.ks, m.shine, m.transmittance, m.ior
            );
        }
        for o in &self.objects {
            let _ = write!(world, "{o:?}; ");
        }
        let mut direct = crc32fast::Hasher::new();
        for d in &self.direct {
            let head = format!(
                "{} {:?} {:?} {:?} {:?} {:?}",
                d.object, d.first, d.dims, d.classifier, d.base, d.spacing
            );
            direct.update(&crc(&[head.as_bytes(), bytemuck::cast_slice(&d.values)]).to_le_bytes());
        }
        format!(
            "{raster:08x}{:08x}{:08x}",
            world.0.finalize(),
            direct.finalize()
        )
    }

    /// The SPD intensity of each light and of the ambient term.
    #[must_use]
    pub fn intensity(&self) -> f64 {
        light_intensity(self.lights.len())
    }

    /// Bytes held by the plane, its line level, directory, records,
    /// object lists and the samples of volumes rendered directly.
    #[must_use]
    pub fn memory(&self) -> u64 {
        let dir = self.directory.len().saturating_mul(size_of::<u32>());
        let rec = self
            .records
            .len()
            .saturating_mul(std::mem::size_of::<VoxelRecord>());
        let bytes = self
            .plane
            .len()
            .saturating_add(self.lines.len())
            .saturating_add(dir)
            .saturating_add(rec)
            .saturating_add(self.lists.len().saturating_mul(size_of::<u32>()))
            .saturating_add(
                self.direct
                    .iter()
                    .map(|d| d.values.len().saturating_mul(size_of::<f32>()))
                    .fold(0usize, usize::saturating_add),
            );
        u64::try_from(bytes).unwrap_or(u64::MAX)
    }
}

/// Text written into a checksum ([`VoxelScene::fingerprint`]).
struct CrcText(crc32fast::Hasher);

impl std::fmt::Write for CrcText {
    fn write_str(&mut self, s: &str) -> std::fmt::Result {
        self.0.update(s.as_bytes());
        Ok(())
    }
}

/// The last pass over a voxelized plane, once its records (`store`) are
/// final: the proximity distance field (empty-space skipping for 26-runs;
/// it sets the same PROXIMITY flags the builder set), the records' rank
/// hints in their opaque cells (which the field clears; as
/// [`write_rank_hints`](rrt_core::store::write_rank_hints)), and the line
/// level, returned. On the current rayon pool; the bytes are those of
/// [`distance_field`](rrt_core::proximity::distance_field) and
/// `write_rank_hints` whatever the number of threads. A plane that does
/// not match the store's extent is left as it is, with no line level.
pub fn finish_plane(plane: &mut Plane, store: &RecordStore<'_>) -> Vec<u8> {
    let extent = store.extent();
    if plane.len() != extent.len() {
        return Vec::new();
    }
    let [_, _, nz] = extent.dims();
    back_field_rows(plane, store, 0, [0, nz]);
    let rows = BrickRows::of(extent, store.directory(), 0);
    distance_field(extent, plane, rows.as_ref());
    for_record_cells(store, plane, 0, [0, nz], |c, hint| {
        if *c & cell::OPAQUE != 0 {
            *c = (*c & (cell::OPAQUE | cell::PROXIMITY)) | (hint << cell::DISTANCE_SHIFT);
        }
    });
    line_level(extent, plane, store.directory())
}

/// Backs for writing ([`Plane::back_for_writing`]) the rows of `plane`
/// (the raster's slices from `z0`, a multiple of the brick edge, on) that
/// the distance field of the records of `store` in slices `slices[0]..
/// slices[1]` may write: those within [`field::FIELD_REACH`] rows and
/// slices of a row holding one of those records. The field reads rows
/// before it writes them; backed first, they are not copied from the zero
/// page on the write. The rows are the ones the field writes anyway (each
/// holds a cell within its reach), so no more memory is backed, except
/// where a row spans several pages of which the field writes only some.
/// Nothing is done (not even the search for rows) for a plane of huge
/// pages.
fn back_field_rows(plane: &Plane, store: &RecordStore<'_>, z0: u32, slices: [u32; 2]) {
    if plane.asks_for_huge_pages() {
        return;
    }
    let [nx, ny, _] = store.extent().dims().map(|n| n as usize);
    let Some(nz) = plane.len().checked_div(nx * ny) else {
        return;
    };
    // Rows holding a record, per brick layer of the plane on the pool.
    let mut rows = vec![false; nz * ny];
    let bz0 = (z0 / BRICK) as usize;
    rows.par_chunks_mut(ny * BRICK as usize)
        .enumerate()
        .for_each(|(l, rows)| {
            layer_cells(store, bz0 + l, slices, |i, _| {
                if let Some(r) = rows.get_mut(i / nx) {
                    *r = true;
                }
            });
        });
    let reach = field::FIELD_REACH as usize;
    let rows = dilate(&rows, ny, 1, reach);
    let rows = dilate(&rows, nz, ny, reach);
    // Runs of those rows, as byte ranges (runs go on across slices).
    let mut start = None;
    for (r, &back) in rows.iter().chain(std::iter::once(&false)).enumerate() {
        match (back, start) {
            (true, None) => start = Some(r),
            (false, Some(s)) => {
                plane.back_for_writing(s * nx..r * nx);
                start = None;
            }
            _ => {}
        }
    }
}

/// `flags` with each `true` spread over the `reach` elements on either
/// side along one axis, whose elements lie `stride` apart, `n` of them
/// (the array holds whole groups of `n · stride`).
fn dilate(flags: &[bool], n: usize, stride: usize, reach: usize) -> Vec<bool> {
    let mut out = flags.to_vec();
    let block = n * stride;
    if block == 0 {
        return out;
    }
    // Each shift by `d` elements along the axis, as one run of the group:
    // element k takes element k + d, for the k where both lie in it.
    for (src, dst) in flags.chunks(block).zip(out.chunks_mut(block)) {
        let len = src.len();
        for d in 1..=reach.min(n.saturating_sub(1)) {
            let shift = d * stride;
            if shift >= len {
                break;
            }
            for (o, &f) in dst[..len - shift].iter_mut().zip(&src[shift..]) {
                *o |= f;
            }
            for (o, &f) in dst[shift..].iter_mut().zip(&src[..len - shift]) {
                *o |= f;
            }
        }
    }
    out
}

/// Slices around a run of slices whose opaque voxels decide the run's
/// finished cells: the distance field stops at
/// [`NEAR_LIMIT`](rrt_core::proximity::NEAR_LIMIT), so an opaque voxel
/// this many slices away or more changes nothing (a multiple of the brick
/// edge, so that the slices are whole brick layers).
pub const DERIVE_MARGIN: u32 = 16;

/// The finished plane ([`finish_plane`]) of the raster whose opaque voxels
/// are exactly the records of `store`, computed for the slices
/// `slices[0]..slices[1]` with [`DERIVE_MARGIN`] slices on either side
/// (clipped to the raster): the cells of slices `z0..z1` of the raster in a
/// plane of `nx·ny·(z1 − z0)` cells, with `z0` (a multiple of the brick
/// edge). Its slices `slices[0]..slices[1]` are byte for byte the whole
/// raster's finished cells; with `slices = [0, nz]` the plane is the whole
/// raster's: distance field, PROXIMITY flags, OPAQUE cells with their
/// records' rank hints
/// ([`write_rank_hints`](rrt_core::store::write_rank_hints)). A saved raster's plane is
/// made on load so (the builder's plane is exactly this for the records
/// it made). On the current rayon pool.
///
/// # Errors
/// The system's refusal of the plane's memory.
pub fn derive_plane(store: &RecordStore<'_>, slices: [u32; 2]) -> std::io::Result<(Plane, u32)> {
    let extent = store.extent();
    let [nx, ny, nz] = extent.dims();
    let z0 = slices[0].min(nz).saturating_sub(DERIVE_MARGIN) & !(BRICK - 1);
    let z1 = slices[1].saturating_add(DERIVE_MARGIN).min(nz).max(z0 + 1);
    let sub = Extent::new(nx, ny, z1 - z0).map_err(std::io::Error::other)?;
    let mut plane = Plane::zeroed(sub.len())?;
    back_field_rows(&plane, store, z0, [z0, z1]);
    for_record_cells(store, &mut plane, z0, [z0, z1], |c, _| *c = cell::OPAQUE);
    let rows = BrickRows::of(extent, store.directory(), z0);
    distance_field(sub, &mut plane, rows.as_ref());
    for_record_cells(store, &mut plane, z0, [z0, z1], |c, hint| {
        *c = (*c & (cell::OPAQUE | cell::PROXIMITY)) | (hint << cell::DISTANCE_SHIFT);
    });
    Ok((plane, z0))
}

/// The records of `store` in brick layer `bz` whose voxels lie in slices
/// `slices[0]..slices[1]`, in storage order: `f(i, hint)` with `i` the
/// voxel's index among the layer's cells (x fastest, from the layer's
/// first slice) and its record's rank hint.
fn layer_cells(store: &RecordStore<'_>, bz: usize, slices: [u32; 2], mut f: impl FnMut(usize, u8)) {
    let extent = store.extent();
    let [nx, ny, _] = extent.dims().map(|n| n as usize);
    let [bx, by, _] = brick_dims(extent).map(|b| b as usize);
    let (directory, records) = (store.directory(), store.records());
    let first = bz * bx * by;
    for b in first..first + bx * by {
        let (Some(&lo), Some(&hi)) = (directory.get(b), directory.get(b + 1)) else {
            return;
        };
        let Some(brick) = records.get(lo as usize..hi as usize) else {
            continue;
        };
        let origin = [(b % bx) * BRICK as usize, (b / bx % by) * BRICK as usize];
        for (j, r) in brick.iter().enumerate() {
            let p = usize::from(r.position());
            let (x, y, dz) = (origin[0] + (p & 7), origin[1] + ((p >> 3) & 7), p >> 6);
            let z = bz * BRICK as usize + dz;
            // A valid store's voxels lie in the raster.
            if z < slices[0] as usize || z >= slices[1] as usize || x >= nx || y >= ny {
                continue;
            }
            f((dz * ny + y) * nx + x, rank_hint(j, brick.len()));
        }
    }
}

/// Calls `f(cell, hint)` on the cell of every record of `store` in slices
/// `slices[0]..slices[1]`, with its rank hint; `plane` holds the cells of
/// the raster's slices from `z0` (a multiple of the brick edge, at most
/// `slices[0]`) on. Brick layers on the current rayon pool: each writes
/// only its own slices.
fn for_record_cells(
    store: &RecordStore<'_>,
    plane: &mut [u8],
    z0: u32,
    slices: [u32; 2],
    f: impl Fn(&mut u8, u8) + Sync,
) {
    let [nx, ny, _] = store.extent().dims().map(|n| n as usize);
    let layer = nx * ny * BRICK as usize;
    let bz0 = (z0 / BRICK) as usize;
    plane
        .par_chunks_mut(layer)
        .enumerate()
        .for_each(|(l, cells)| {
            layer_cells(store, bz0 + l, slices, |i, hint| {
                if let Some(c) = cells.get_mut(i) {
                    f(c, hint);
                }
            });
        });
}

/// Whether `plane` is the plane [`derive_plane`] makes from the records
/// of `store`, given that its transparent cells are the distance field
/// ([`finish_plane`]) of its opaque ones, as the builder leaves a plane:
/// then it is exactly when the opaque cells are the records' voxels, each
/// with its rank hint. One pass over the records and one over the plane,
/// on the current rayon pool, instead of making the plane again.
#[must_use]
pub fn plane_matches_records(plane: &[u8], store: &RecordStore<'_>) -> bool {
    let extent = store.extent();
    if plane.len() != extent.len() {
        return false;
    }
    let finished = cell::OPAQUE | cell::PROXIMITY;
    let [nx, ny, nz] = extent.dims().map(|n| n as usize);
    // Per brick layer: whether every record's cell is opaque with its
    // hint, with the count of records and of opaque cells.
    let layers: Vec<(bool, usize, usize)> = plane
        .par_chunks(nx * ny * BRICK as usize)
        .enumerate()
        .map(|(bz, cells)| {
            let (mut ok, mut count) = (true, 0usize);
            layer_cells(store, bz, [0, nz as u32], |i, hint| {
                ok &= cells.get(i) == Some(&(finished | (hint << cell::DISTANCE_SHIFT)));
                count += 1;
            });
            let opaque = cells.iter().filter(|&&b| b & cell::OPAQUE != 0).count();
            (ok, count, opaque)
        })
        .collect();
    let ok = layers.iter().all(|l| l.0);
    let count: usize = layers.iter().map(|l| l.1).sum();
    let opaque: usize = layers.iter().map(|l| l.2).sum();
    ok && count == store.len() && opaque == count
}

/// Boxes of fewer cells than this are relaxed on one thread.
const PARALLEL_CELLS: usize = 1 << 15;

/// Per brick of a record store's directory, whether it holds a record.
fn holds_records(directory: &[u32]) -> impl Iterator<Item = bool> + '_ {
    directory.windows(2).map(|w| w[0] < w[1])
}

/// The brick rows (a z-layer and y-row of bricks) of a raster that hold a
/// record or lie beside one that does, from its store's directory: the
/// plane rows outside them hold no opaque voxel, and in a plane as the
/// builder or the loader leaves it (opaque cells and the PROXIMITY flags
/// around them) nothing at all.
struct BrickRows {
    /// Per brick row, `bz · by + by_row`: whether a brick of it, or of a
    /// brick row beside it (±1 in y and z), holds a record.
    held: Vec<bool>,
    /// Per brick, `(bz · by + by_row) · bx + bx_col`: whether a brick
    /// within [`NEAR_BRICKS`] bricks of it on every axis holds a record.
    /// Only cells of such bricks lie within
    /// [`FIELD_REACH`](field::FIELD_REACH) of an opaque voxel, so only
    /// they can change when a slice is relaxed from its neighbour.
    near: Vec<bool>,
    /// Bricks per brick row.
    bx: usize,
    /// Brick rows per brick layer.
    by: usize,
    /// The first slice of the plane the field is computed over (a
    /// multiple of the brick edge).
    z0: usize,
}

impl BrickRows {
    /// From a valid directory over `extent`, for a plane starting at
    /// slice `z0`; `None` if the directory does not match.
    fn of(extent: Extent, directory: &[u32], z0: u32) -> Option<Self> {
        let [bx, by, bz] = brick_dims(extent).map(|b| b as usize);
        if directory.len() != bx * by * bz + 1 {
            return None;
        }
        let bricks: Vec<bool> = holds_records(directory).collect();
        let own: Vec<bool> = bricks.chunks(bx).map(|row| row.contains(&true)).collect();
        let near = dilate(&bricks, bx, 1, NEAR_BRICKS);
        let near = dilate(&near, by, bx, NEAR_BRICKS);
        let near = dilate(&near, bz, bx * by, NEAR_BRICKS);
        let at = |y: usize, z: usize| own.get(z * by + y).copied().unwrap_or(false);
        let held = (0..bz * by)
            .map(|b| {
                let (y, z) = (b % by, b / by);
                (y.saturating_sub(1)..=(y + 1).min(by - 1))
                    .any(|yy| (z.saturating_sub(1)..=(z + 1).min(bz - 1)).any(|zz| at(yy, zz)))
            })
            .collect();
        Some(Self {
            held,
            near,
            bx,
            by,
            z0: z0 as usize,
        })
    }

    /// The runs of columns `[x0, x1)` of the brick row holding row `y` of
    /// slice `z` (of the plane) whose bricks are near a record: outside
    /// them no cell of the row lies within reach of an opaque voxel.
    fn near_columns(&self, z: usize, y: usize) -> impl Iterator<Item = [usize; 2]> + '_ {
        let b = ((self.z0 + z) / BRICK as usize * self.by + y / BRICK as usize) * self.bx;
        let row = self.near.get(b..b + self.bx).unwrap_or(&[]);
        let edge = BRICK as usize;
        let mut at = 0;
        std::iter::from_fn(move || {
            let start = at + row.get(at..)?.iter().position(|&n| n)?;
            let len = row[start..]
                .iter()
                .position(|&n| !n)
                .unwrap_or(row.len() - start);
            at = start + len;
            Some([start * edge, at * edge])
        })
    }

    /// Whether row `y` of slice `z` (of the plane) may hold an opaque voxel.
    fn may_hold(&self, z: usize, y: usize) -> bool {
        let b = (self.z0 + z) / BRICK as usize * self.by + y / BRICK as usize;
        self.held.get(b).copied().unwrap_or(true)
    }
}

/// Bricks on either side of a brick holding a record whose cells may lie
/// within [`FIELD_REACH`](field::FIELD_REACH) of its voxels: the reach
/// spans at most this many brick edges.
const NEAR_BRICKS: usize = (field::FIELD_REACH as usize).div_ceil(BRICK as usize);

/// The distance field of `plane` (as long as `extent`) on the current
/// rayon pool: the core's steps ([`field`]) with the slices of step 1
/// shared out, then the rows of each slice in steps 2 and 3, each slice
/// relaxed only over the box its neighbours' opaque voxels reach. With
/// `rows`, a fresh plane whose opaque voxels lie in those brick rows: the
/// other rows are not read where no opaque voxel is near, and steps 2 and
/// 3 relax only the bricks near one holding a record.
fn distance_field(extent: Extent, plane: &mut [u8], rows: Option<&BrickRows>) {
    let [nx, ny, nz] = extent.dims().map(|d| d as usize);
    let slice = nx * ny;
    let opaque: Vec<Area> = plane
        .par_chunks_mut(slice)
        .enumerate()
        .map(|(z, s)| match rows {
            Some(r) => field::slice_distances_in(s, nx, |y| r.may_hold(z, y)),
            None => field::slice_distances(s, nx),
        })
        .collect();
    let reach = field::FIELD_REACH as usize;
    let reached = |zs: std::ops::Range<usize>| {
        opaque[zs]
            .iter()
            .fold(Area::EMPTY, |a, &b| a.union(b))
            .reached(nx, ny)
    };
    for z in 1..nz {
        let area = reached(z.saturating_sub(reach)..z);
        relax_slice(plane, [nx, ny], z, z - 1, area, rows);
    }
    for z in (0..nz.saturating_sub(1)).rev() {
        let area = reached(z + 1..(z + 1 + reach).min(nz));
        relax_slice(plane, [nx, ny], z, z + 1, area, rows);
    }
}

/// Relaxes the box `area` of slice `z` of `plane` from its neighbour
/// `from` ([`field::relax_rows`]), its rows shared out among the pool's
/// threads; with `rows`, only the columns of each brick row that lie near
/// a record ([`BrickRows::near_columns`]), the only ones that can change.
fn relax_slice(
    plane: &mut [u8],
    [nx, ny]: [usize; 2],
    z: usize,
    from: usize,
    area: Area,
    rows: Option<&BrickRows>,
) {
    if area.is_empty() {
        return;
    }
    let slice = nx * ny;
    let (cur, src): (&mut [u8], &[u8]) = if from < z {
        let (lo, hi) = plane.split_at_mut(z * slice);
        (&mut hi[..slice], &lo[from * slice..][..slice])
    } else {
        let (lo, hi) = plane.split_at_mut(from * slice);
        (&mut lo[z * slice..][..slice], &hi[..slice])
    };
    let [y0, y1] = area.y;
    let parallel = (y1 - y0) * (area.x[1] - area.x[0]) >= PARALLEL_CELLS;
    let Some(near) = rows else {
        let rows = &mut cur[y0 * nx..y1 * nx];
        if !parallel {
            field::relax_rows(rows, src, nx, y0, area);
            return;
        }
        // A few bands of rows per thread.
        let band = (y1 - y0).div_ceil(4 * rayon::current_num_threads()).max(1);
        rows.par_chunks_mut(band * nx)
            .enumerate()
            .for_each(|(i, rows)| field::relax_rows(rows, src, nx, y0 + i * band, area));
        return;
    };
    // Brick rows: each relaxed over its near runs of columns.
    let edge = BRICK as usize;
    let first = y0 / edge * edge;
    let brick_row = |(i, rows): (usize, &mut [u8])| {
        let r0 = first + i * edge;
        for [x0, x1] in near.near_columns(z, r0) {
            let part = Area {
                x: [x0.max(area.x[0]), x1.min(area.x[1])],
                y: area.y,
            };
            field::relax_rows(rows, src, nx, r0, part);
        }
    };
    let rows = &mut cur[first * nx..y1 * nx];
    if parallel {
        rows.par_chunks_mut(edge * nx)
            .enumerate()
            .for_each(brick_row);
    } else {
        rows.chunks_mut(edge * nx).enumerate().for_each(brick_row);
    }
}

/// The line level of a plane over `extent` with its distance field
/// ([`line_stand_ins`]): one stand-in cell per 64 cells, which lets
/// skipping walks stay off the plane far from surfaces, from the coarse
/// level of the bricks holding records (`directory`, the record store's:
/// a built or derived plane's opaque voxels are exactly its records'); on
/// the current rayon pool. Empty if the plane or the directory does not
/// match the extent.
#[must_use]
pub fn line_level(extent: Extent, plane: &[u8], directory: &[u32]) -> Vec<u8> {
    let Ok(coarse) = coarse_extent(extent) else {
        return Vec::new();
    };
    if plane.len() != extent.len()
        || coarse.dims() != brick_dims(extent)
        || directory.len() != coarse.len() + 1
    {
        return Vec::new();
    }
    let mut bricks: Vec<u8> = holds_records(directory)
        .map(|held| if held { cell::OPAQUE } else { cell::EMPTY })
        .collect();
    distance_field(coarse, &mut bricks, None);
    coarse_bounds(&mut bricks);
    stand_ins(extent, plane, &bricks)
}

/// [`line_level`] for a plane whose opaque voxels are not known to be the
/// records' (a dense saved plane): the coarse level from the plane's own
/// cells.
#[must_use]
pub fn line_level_of_plane(extent: Extent, plane: &[u8]) -> Vec<u8> {
    let (Ok(coarse), Ok(raster)) = (coarse_extent(extent), Raster::new(extent, plane)) else {
        return Vec::new();
    };
    let mut bricks = vec![cell::EMPTY; coarse.len()];
    if coarse_level(&raster, &mut bricks).is_err() {
        return Vec::new();
    }
    stand_ins(extent, plane, &bricks)
}

/// The stand-ins of every line from the coarse level `bricks`, in parts
/// on the current rayon pool.
fn stand_ins(extent: Extent, plane: &[u8], bricks: &[u8]) -> Vec<u8> {
    let Ok(raster) = Raster::new(extent, plane) else {
        return Vec::new();
    };
    let mut lines = vec![0u8; line_count(plane.len())];
    const LINES_PER_PART: usize = 1 << 12;
    let ok = lines
        .par_chunks_mut(LINES_PER_PART)
        .enumerate()
        .all(|(k, l)| line_stand_ins(&raster, bricks, k * LINES_PER_PART, l).is_ok());
    if ok { lines } else { Vec::new() }
}

/// One entry of the world object table.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WorldObject {
    /// Exact geometry.
    pub shape: Shape,
    /// Index into the scene's material list.
    pub material: u16,
}

/// A point light in world coordinates.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WorldLight {
    /// Position.
    pub position: DVec3,
    /// Colour (white unless the file gives one).
    pub colour: DVec3,
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The dilation along each axis of a 3D box of flags is the brute
    /// force's: a flag is set where one lies within `reach` along the
    /// axis, in the same column.
    #[test]
    fn dilate_spreads_along_one_axis() {
        let dims = [7usize, 5, 9];
        let len = dims.iter().product::<usize>();
        let mut rng = rrt_core::rng::Rng::new(0x9e37_79b9);
        // About one in eight set.
        let flags: Vec<bool> = (0..len).map(|_| rng.chance(1, 8)).collect();
        let at = |x: usize, y: usize, z: usize| (z * dims[1] + y) * dims[0] + x;
        for axis in 0..3 {
            let stride = dims[..axis].iter().product::<usize>();
            for reach in [0, 1, 2, 4, 14] {
                let got = dilate(&flags, dims[axis], stride, reach);
                for z in 0..dims[2] {
                    for y in 0..dims[1] {
                        for x in 0..dims[0] {
                            let p = [x, y, z];
                            let want = (0..dims[axis]).any(|k| {
                                let mut q = p;
                                q[axis] = k;
                                k.abs_diff(p[axis]) <= reach && flags[at(q[0], q[1], q[2])]
                            });
                            assert_eq!(got[at(x, y, z)], want, "axis {axis} reach {reach} {p:?}");
                        }
                    }
                }
            }
        }
    }
}
