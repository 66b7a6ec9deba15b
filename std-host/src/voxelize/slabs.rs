//! The two voxelization passes on all cores: the raster cut into pieces,
//! each built on its own by the core's single-threaded builder on rayon's
//! threads, and joined. A piece is a *slab* of whole brick layers with
//! every row ([`Counter::slab`]) or, where the raster has at most half as
//! many brick layers as the threads want pieces (flat scenes), a *band* of
//! whole brick rows of one brick layer ([`Counter::band`]).
//!
//! Every piece voxelizes, in object-id order, every object that can offer
//! a voxel in it ([`TableObject::cells`]; an object whose box lies outside
//! the raster goes to the nearest pieces, so that its voxelizer's refusal
//! is still seen), through a sink that keeps only the piece's rows and
//! layers ([`VoxelSink::rows`], [`VoxelSink::layers`]): each voxel gets
//! the offers it gets in a whole build, in the same order, so its record
//! and object list are the same. Bricks are numbered z-major and, within
//! a brick layer, row by row, so the pieces' bricks, records and lists
//! are contiguous parts of the whole raster's, in the same order; joining
//! them is arithmetic: each piece's directory entries move up by the
//! records before it, its list indices by the list entries before it
//! ([`shift_lists`]). The result is the same bytes whatever the number of
//! pieces or threads.
//!
//! Memory: a slab's plane is cut from the raster's plane in place, a band
//! builds its plane apart (one brick layer's rows, copied in after the
//! fill pass); the records and lists are allocated once for all pieces
//! (each fills its own range), and the pieces' directories are parts of
//! one directory with one spare entry per piece, closed up when they are
//! joined.
//!
//! [`VoxelSink::rows`]: rrt_core::voxelize::VoxelSink::rows
//! [`VoxelSink::layers`]: rrt_core::voxelize::VoxelSink::layers
//! [`TableObject::cells`]: super::objects::TableObject::cells

use std::ops::Range;
use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};

use indicatif::ProgressBar;
use rayon::ThreadPool;
use rayon::prelude::*;
use rrt_core::raster::{Extent, RasterMut};
use rrt_core::store::{BRICK, Counter, Limits, Sizing, brick_count, directory_len, shift_lists};
use rrt_core::voxel::VoxelRecord;
use rrt_core::voxelize::Separation;

use super::direct::DirectVolume;
use super::materials::MaterialTable;
use super::objects::TableObject;
use super::pass::Pass;
use super::plane::Plane;
use super::texture::MaterialTextures;
use super::{BuildError, alloc_err, try_vec};
use crate::frame::RasterFrame;
use crate::progress::Unit;

/// Pieces per thread: more pieces than threads, so that a thread whose
/// pieces hold little finds more work.
const PIECES_PER_THREAD: usize = 8;

/// A part of the raster built on its own: the rows `rows` of the layers
/// `layers`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Piece {
    /// Layers (z): whole brick layers.
    pub layers: Range<u32>,
    /// Rows (y): every row (a slab), or whole brick rows of one brick
    /// layer (a band).
    pub rows: Range<u32>,
}

/// The pieces for `threads` threads (at least 1) over a raster of `dims`,
/// in raster order: about `PIECES_PER_THREAD` per thread, slabs of about
/// as many whole brick layers each; where the raster has no more than half
/// as many brick layers, each brick layer cut into bands of about as many
/// whole brick rows. One slab for one thread.
#[must_use]
pub fn pieces(dims: [u32; 3], threads: usize) -> Vec<Piece> {
    let [_, ny, nz] = dims;
    let brick_layers = nz.div_ceil(BRICK).max(1);
    let brick_rows = ny.div_ceil(BRICK).max(1);
    let wanted = if threads <= 1 {
        1
    } else {
        u32::try_from(threads.saturating_mul(PIECES_PER_THREAD)).unwrap_or(u32::MAX)
    };
    let slabs = wanted.min(brick_layers);
    // Bands where whole layers give at most half the pieces wanted:
    // cutting each brick layer in two or more pays only then (a band
    // re-visits the objects it shares with its neighbours, and its plane
    // is copied in).
    let bands = if slabs.saturating_mul(2) <= wanted {
        wanted.div_ceil(slabs).min(brick_rows)
    } else {
        1
    };
    // Boundaries spread evenly over whole bricks: i·total/n (total < 2^29).
    let at = |i: u32, total: u32, n: u32| (u64::from(i) * u64::from(total) / u64::from(n)) as u32;
    let mut out = Vec::new();
    for i in 0..slabs {
        let layers =
            at(i, brick_layers, slabs) * BRICK..(at(i + 1, brick_layers, slabs) * BRICK).min(nz);
        for j in 0..bands {
            let rows =
                at(j, brick_rows, bands) * BRICK..(at(j + 1, brick_rows, bands) * BRICK).min(ny);
            out.push(Piece {
                layers: layers.clone(),
                rows,
            });
        }
    }
    out
}

/// What the passes see of the scene.
pub(super) struct Passes<'a> {
    /// The objects, in id order.
    pub objects: &'a [TableObject<'a>],
    /// The raster frame.
    pub frame: &'a RasterFrame,
    /// The separation every object is voxelized with.
    pub separation: Separation,
    /// The distinct materials.
    pub materials: &'a MaterialTable,
    /// The materials' textures.
    pub textures: &'a MaterialTextures<'a>,
    /// Object lists for the voxels several objects share.
    pub exact: bool,
    /// The samples of the volumes rendered directly, in object-id order
    /// (their voxels are read from them).
    pub direct: &'a [DirectVolume],
}

/// What the count pass found, for the caller's checks before the records
/// are allocated.
#[derive(Clone, Copy, Debug)]
pub(super) struct Counted {
    /// Records (non-transparent voxels).
    pub records: usize,
    /// Entries of list storage the fill pass needs (0 without lists).
    pub list_entries: usize,
    /// Entries of the pieces' directories while they are built.
    pub directory: usize,
    /// Bytes of the bands' own planes while they are built.
    pub band_planes: usize,
}

/// The joined result of both passes.
pub(super) struct Voxelized {
    /// The brick directory.
    pub directory: Vec<u32>,
    /// The records, sorted by brick and position.
    pub records: Vec<VoxelRecord>,
    /// The object lists.
    pub lists: Vec<u32>,
    /// Offers inside the raster in the count pass.
    pub offers: u64,
}

/// One piece's plane, part of the (padded) directory and objects.
struct Part<'p, 'd, 'm> {
    z0: u32,
    /// A band's first row; `None` for a slab.
    band: Option<u32>,
    /// The ids of the objects the slab voxelizes, in order.
    members: &'m [usize],
    extent: Extent,
    plane: &'p mut [u8],
    dir: &'d mut [u32],
}

/// Runs `job` on every item of `items` on `pool`'s threads, each item
/// taken by the next free thread, the heaviest by `weight(item, index)`
/// first (longest first keeps the threads busy to the end); the results in
/// the items' order.
fn heaviest_first<T: Send, R: Send>(
    pool: &ThreadPool,
    items: Vec<T>,
    weight: impl Fn(&T, usize) -> u64,
    job: impl Fn(T) -> R + Sync,
) -> Vec<Option<R>> {
    let mut order: Vec<usize> = (0..items.len()).collect();
    order.sort_by_key(|&i| std::cmp::Reverse(weight(&items[i], i)));
    let slots: Vec<Mutex<Option<T>>> = items.into_iter().map(|t| Mutex::new(Some(t))).collect();
    let results: Vec<Mutex<Option<R>>> = slots.iter().map(|_| Mutex::new(None)).collect();
    let next = AtomicUsize::new(0);
    pool.broadcast(|_| {
        while let Some(&i) = order.get(next.fetch_add(1, Ordering::Relaxed)) {
            let item = slots[i].lock().ok().and_then(|mut s| s.take());
            if let Some(item) = item {
                let r = job(item);
                if let Ok(mut slot) = results[i].lock() {
                    *slot = Some(r);
                }
            }
        }
    });
    // Every job ran (a panic in one would have been passed on here).
    results
        .into_iter()
        .map(|m| m.into_inner().ok().flatten())
        .collect()
}

/// The earliest failure: the one of the lowest object id (then of the
/// lowest slab), which is the one a single whole build reports.
fn first_error<T>(
    results: Vec<Option<Result<T, (usize, BuildError)>>>,
) -> Result<Vec<T>, BuildError> {
    let mut ok = Vec::with_capacity(results.len());
    let mut err: Option<(usize, BuildError)> = None;
    for r in results {
        let r = r.ok_or_else(|| BuildError::Raster("a slab was not built".into()))?;
        match r {
            Ok(t) => ok.push(t),
            Err((id, e)) => {
                if err.as_ref().is_none_or(|(best, _)| id < *best) {
                    err = Some((id, e));
                }
            }
        }
    }
    match err {
        Some((_, e)) => Err(e),
        None => Ok(ok),
    }
}

impl Passes<'_> {
    /// Runs both passes over `plane` (the whole raster, zero) in the
    /// `pieces` (of [`pieces`]), on `pool`; `check` sees the count pass's
    /// sizes before anything more is allocated and may refuse the scene.
    ///
    /// # Errors
    /// `check`'s refusal, a voxelizer's (of the lowest object id), the
    /// store's.
    pub fn run(
        &self,
        plane: &mut [u8],
        pieces: &[Piece],
        pool: &ThreadPool,
        check: impl FnOnce(Counted) -> Result<(), BuildError>,
        progress: &ProgressBar,
    ) -> Result<Voxelized, BuildError> {
        let extent = self.frame.extent;
        let [nx, ny, _] = extent.dims();
        let bad = || BuildError::Raster("slabs do not fit the raster".into());
        let dir_len = directory_len(extent).ok_or_else(bad)?;
        let padded = dir_len
            .checked_add(pieces.len().saturating_sub(1))
            .ok_or_else(bad)?;
        let mut directory = vec![0u32; padded];
        let members = self.members(pieces);
        let extents = pieces
            .iter()
            .map(|p| {
                let len = |r: &Range<u32>| r.end.saturating_sub(r.start);
                Extent::new(nx, len(&p.rows), len(&p.layers)).map_err(|_| bad())
            })
            .collect::<Result<Vec<_>, _>>()?;
        let is_band = |p: &Piece| p.rows != (0..ny);
        // The bands' own planes (zero pages until written, as the raster's).
        let mut band_planes = pieces
            .iter()
            .zip(&extents)
            .map(|(p, e)| {
                is_band(p)
                    .then(|| Plane::zeroed(e.len()).map_err(alloc_err("band plane", e.len())))
                    .transpose()
            })
            .collect::<Result<Vec<_>, _>>()?;
        let band_bytes = band_planes.iter().flatten().map(|b| b.len()).sum::<usize>();

        // Each piece's parts: a slab's plane cut from the raster's, a
        // band's its own; the raster's layers of the bands are passed by.
        let mut parts = Vec::with_capacity(pieces.len());
        let (mut plane_rest, mut dir_rest) = (&mut *plane, &mut directory[..]);
        for (((pc, m), &e), own) in pieces
            .iter()
            .zip(&members)
            .zip(&extents)
            .zip(&mut band_planes)
        {
            let cut = if !is_band(pc) {
                e.len()
            } else if pc.rows.end == ny {
                // The last band of its layers: the raster's cells of those
                // layers are passed by.
                extent.len() / extent.dims()[2] as usize * e.dims()[2] as usize
            } else {
                0
            };
            let (p, pr) = plane_rest.split_at_mut_checked(cut).ok_or_else(bad)?;
            plane_rest = pr;
            let p = match own {
                Some(band) => &mut band[..],
                None => p,
            };
            let d_len = directory_len(e).ok_or_else(bad)?;
            let (d, dr) = dir_rest.split_at_mut_checked(d_len).ok_or_else(bad)?;
            parts.push(Part {
                z0: pc.layers.start,
                band: is_band(pc).then_some(pc.rows.start),
                members: m,
                extent: e,
                plane: p,
                dir: d,
            });
            dir_rest = dr;
        }
        let visits = members.iter().map(|m| m.len() as u64).sum::<u64>();

        crate::progress::phase(
            progress,
            "voxelizing (count pass)",
            Unit::SlabObjects,
            visits,
        );
        // The pieces with the most objects to voxelize first (ties in
        // raster order): the records are not counted yet.
        let counted = heaviest_first(
            pool,
            parts,
            |p, _| p.members.len() as u64,
            |p| self.count(p, progress),
        );
        let sizings = first_error(counted)?;
        let records_n = sizings
            .iter()
            .try_fold(0usize, |a, (s, _)| a.checked_add(s.records()))
            .filter(|&n| u32::try_from(n).is_ok())
            .ok_or(BuildError::Store(
                rrt_core::store::BuildError::TooManyRecords,
            ))?;
        let list_sizes: Vec<usize> = sizings
            .iter()
            .map(|(s, _)| if self.exact { s.list_entries() } else { 0 })
            .collect();
        let list_n = list_sizes
            .iter()
            .try_fold(0usize, |a, &n| a.checked_add(n))
            .unwrap_or(usize::MAX);
        check(Counted {
            records: records_n,
            list_entries: list_n,
            directory: padded,
            band_planes: band_bytes,
        })?;
        let offers = sizings.iter().map(|(_, o)| *o).sum();

        // Written (and its pages first touched) on the pool's threads: the
        // records are the build's largest allocation.
        let mut records: Vec<VoxelRecord> = try_vec(records_n, "records")?;
        pool.install(|| {
            records.par_extend(
                (0..records_n)
                    .into_par_iter()
                    .map(|_| VoxelRecord::default()),
            );
        });
        let mut lists: Vec<u32> = try_vec(list_n, "object lists")?;
        lists.resize(list_n, 0);
        let record_counts: Vec<usize> = sizings.iter().map(|(s, _)| s.records()).collect();
        let mut jobs = Vec::with_capacity(sizings.len());
        let (mut rec_rest, mut list_rest) = (&mut records[..], &mut lists[..]);
        for (((sizing, _), &l), m) in sizings.into_iter().zip(&list_sizes).zip(&members) {
            let (r, rr) = rec_rest.split_at_mut(sizing.records());
            let (s, sr) = list_rest.split_at_mut(l);
            jobs.push((sizing, r, s, &m[..]));
            (rec_rest, list_rest) = (rr, sr);
        }
        crate::progress::phase(
            progress,
            "voxelizing (fill pass)",
            Unit::SlabObjects,
            visits,
        );
        // The slabs with the most records first.
        let filled = heaviest_first(
            pool,
            jobs,
            |(_, r, _, _), _| r.len() as u64,
            |(sizing, r, s, m)| self.fill(sizing, r, s, m, progress),
        );
        let lists_used = first_error(filled)?;

        // The bands' planes into the raster's.
        let row = nx as usize;
        for (pc, own) in pieces.iter().zip(&band_planes) {
            let Some(own) = own else {
                continue;
            };
            let rows = pc.rows.end.saturating_sub(pc.rows.start) as usize;
            for (z, layer) in pc.layers.clone().zip(own.chunks_exact(row * rows)) {
                let at = (z as usize * ny as usize + pc.rows.start as usize) * row;
                let dst = plane.get_mut(at..at + layer.len()).ok_or_else(bad)?;
                // Only the pages that hold something: the raster's are
                // zero, and untouched pages stay unbacked.
                for (d, s) in dst.chunks_mut(4096).zip(layer.chunks(4096)) {
                    if s.iter().any(|&c| c != 0) {
                        d.copy_from_slice(s);
                    }
                }
            }
        }
        drop(band_planes);

        // Join: directory entries up by the records before, lists closed up
        // and their indices shifted by the entries before.
        let mut brick = 0usize;
        let mut from = 0usize;
        let mut base = 0usize;
        let mut list_from = 0usize;
        let mut list_to = 0usize;
        for (((&e, &n), &bound), &used) in extents
            .iter()
            .zip(&record_counts)
            .zip(&list_sizes)
            .zip(&lists_used)
        {
            let bricks = brick_count(e).ok_or_else(bad)?;
            let offset = u32::try_from(base).map_err(|_| bad())?;
            for k in 0..bricks {
                // Moving down: the entry read is at or above every one
                // written so far.
                directory[brick + k] = directory[from + k] + offset;
            }
            lists.copy_within(list_from..list_from + used, list_to);
            shift_lists(&mut records[base..base + n], list_to)?;
            brick += bricks;
            from += bricks + 1;
            base += n;
            list_from += bound;
            list_to += used;
        }
        directory[brick] = u32::try_from(base).map_err(|_| bad())?;
        directory.truncate(dir_len);
        lists.truncate(list_to);
        lists.shrink_to_fit();
        Ok(Voxelized {
            directory,
            records,
            lists,
            offers,
        })
    }

    /// The ids of the objects each of `pieces` voxelizes, in order: those
    /// whose cells ([`TableObject::cells`], clamped to the raster) meet the
    /// piece. Every object is in at least one piece.
    fn members(&self, pieces: &[Piece]) -> Vec<Vec<usize>> {
        let [_, ny, nz] = self.frame.extent.dims();
        let top = |n: u32| i64::from(n).saturating_sub(1).max(0);
        let (ty, tz) = (top(ny), top(nz));
        let meets = |(lo, hi): (i64, i64), r: &Range<u32>| {
            lo < i64::from(r.end) && hi >= i64::from(r.start)
        };
        let mut members = vec![Vec::new(); pieces.len()];
        for (id, o) in self.objects.iter().enumerate() {
            let (y, z) = o.cells().map_or(((0, ty), (0, tz)), |[_, y, z]| {
                (
                    (y.0.clamp(0, ty), y.1.clamp(0, ty)),
                    (z.0.clamp(0, tz), z.1.clamp(0, tz)),
                )
            });
            for (m, p) in members.iter_mut().zip(pieces) {
                if meets(y, &p.rows) && meets(z, &p.layers) {
                    m.push(id);
                }
            }
        }
        members
    }

    /// The count pass of one piece: its sizing and the offers inside it.
    fn count<'p, 'd>(
        &self,
        part: Part<'p, 'd, '_>,
        progress: &ProgressBar,
    ) -> Result<(Sizing<'p, 'd>, u64), (usize, BuildError)> {
        let raster = RasterMut::new(part.extent, part.plane)
            .map_err(|e| (0, BuildError::Raster(e.to_string())))?;
        // The plane is fresh zeroed memory, the directory fresh zeros.
        let counter = match part.band {
            None => Counter::slab_zeroed(raster, part.dir, part.z0),
            Some(y0) => Counter::band(raster, part.dir, [y0, part.z0]),
        };
        let mut counter = counter.map_err(|e| (0, e.into()))?;
        for &id in part.members {
            let o = &self.objects[id];
            o.voxelize(
                self.frame,
                self.separation,
                self.samples(id),
                Pass::Count(&mut counter),
            )
            .map_err(|e| (id, e))?;
            progress.inc(1);
        }
        let r = counter.report();
        let sizing = counter
            .finish()
            .map_err(|e| (self.objects.len(), e.into()))?;
        Ok((sizing, r.offers.saturating_sub(r.outside)))
    }

    /// The samples of object `id` if it is a volume rendered directly.
    fn samples(&self, id: usize) -> Option<&DirectVolume> {
        let i = self
            .direct
            .binary_search_by_key(&id, |d| usize::try_from(d.object).unwrap_or(usize::MAX))
            .ok()?;
        self.direct.get(i)
    }

    /// The fill pass of one piece into its records and list storage:
    /// the list entries its finished lists take.
    fn fill(
        &self,
        sizing: Sizing<'_, '_>,
        records: &mut [VoxelRecord],
        lists: &mut [u32],
        members: &[usize],
        progress: &ProgressBar,
    ) -> Result<usize, (usize, BuildError)> {
        let limits = Limits {
            objects: u32::try_from(self.objects.len()).unwrap_or(u32::MAX),
            materials: u32::try_from(self.materials.list.len()).unwrap_or(u32::MAX),
        };
        let started = if self.exact {
            sizing.fill_with_lists(records, lists, limits)
        } else {
            sizing.fill(records, limits)
        };
        let mut filler = started.map_err(|e| (0, e.into()))?;
        for &id in members {
            let o = &self.objects[id];
            let m = o.material();
            let pass = Pass::Fill {
                filler: &mut filler,
                attrs: self.materials.attrs(id, m),
                leaves: o
                    .leaf_materials()
                    .map(|l| self.materials.attrs(id, l))
                    .collect(),
                texture: self.textures.of(m),
            };
            o.voxelize(self.frame, self.separation, self.samples(id), pass)
                .map_err(|e| (id, e))?;
            progress.inc(1);
        }
        let built = filler
            .finish()
            .map_err(|e| (self.objects.len(), e.into()))?;
        Ok(built.lists().len())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pieces_cover_the_raster_in_brick_order() {
        for (dims, threads) in [
            ([5, 5, 1], 1),
            ([100, 90, 61], 2),
            ([64, 64, 64], 2),
            ([10, 10, 1024], 2),
            ([517, 517, 21], 2),
            ([1024, 1024, 61], 2),
            ([30, 20, 20], 8),
            ([9, 9, 9], 3),
            ([40, 1000, 8], 16),
            ([40, 3, 1000], 3),
        ] {
            let [_, ny, nz] = dims;
            let p = pieces(dims, threads);
            let what = format!("{dims:?} {threads}: {p:?}");
            if threads == 1 {
                assert_eq!(
                    p,
                    [Piece {
                        layers: 0..nz,
                        rows: 0..ny
                    }],
                    "{what}"
                );
            }
            let mut at = (0, 0);
            for piece in &p {
                // Next in raster order, starting on a brick boundary.
                if piece.rows.start == 0 {
                    assert_eq!(piece.layers.start, at.1, "{what}");
                } else {
                    assert_eq!((piece.rows.start, piece.layers.start), at, "{what}");
                }
                assert!(piece.layers.start < piece.layers.end, "{what}");
                assert!(piece.rows.start < piece.rows.end, "{what}");
                assert_eq!(piece.layers.start % BRICK, 0, "{what}");
                assert_eq!(piece.rows.start % BRICK, 0, "{what}");
                assert!(
                    piece.layers.end == nz || piece.layers.end % BRICK == 0,
                    "{what}"
                );
                assert!(
                    piece.rows.end == ny || piece.rows.end % BRICK == 0,
                    "{what}"
                );
                // A band lies in one brick layer.
                if piece.rows != (0..ny) {
                    assert!(piece.layers.end - piece.layers.start <= BRICK, "{what}");
                }
                at = if piece.rows.end == ny {
                    (0, piece.layers.end)
                } else {
                    (piece.rows.end, piece.layers.start)
                };
            }
            assert_eq!(at, (0, nz), "{what}");
            // Flat rasters are cut into bands when the threads want at
            // least twice as many pieces as there are brick layers.
            let wanted = if threads > 1 {
                threads * PIECES_PER_THREAD
            } else {
                1
            };
            let layers = nz.div_ceil(BRICK) as usize;
            let most = (ny.div_ceil(BRICK) as usize) * layers;
            if 2 * layers <= wanted {
                assert!(p.len() >= wanted.min(most), "{what}");
            } else {
                assert_eq!(p.len(), wanted.min(layers), "{what}");
            }
        }
    }
}
