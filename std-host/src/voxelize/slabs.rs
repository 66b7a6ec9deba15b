//! The two voxelization passes on all cores: the raster cut into z-slabs
//! of whole brick layers, each built on its own by the core's single-
//! threaded builder ([`Counter::slab`]) on rayon's threads, and joined.
//!
//! Every slab voxelizes every object, in object-id order, through a sink
//! that keeps only the slab's layers ([`VoxelSink::layers`]): each voxel
//! gets the offers it gets in a whole build, in the same order, so its
//! record and object list are the same. Bricks are numbered z-major, so a
//! slab's plane, bricks, records and lists are contiguous parts of the
//! whole raster's, in the same order; joining them is arithmetic: each
//! slab's directory entries move up by the records before it, its list
//! indices by the list entries before it ([`shift_lists`]). The result is
//! the same bytes whatever the number of slabs or threads.
//!
//! Memory: the plane is cut in place, the records and lists are allocated
//! once for all slabs (each slab fills its own range), and the slabs'
//! directories are parts of one directory with one spare entry per slab,
//! closed up when they are joined.

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

use super::BuildError;
use super::materials::MaterialTable;
use super::objects::TableObject;
use super::pass::Pass;
use super::texture::MaterialTextures;
use crate::frame::RasterFrame;
use crate::progress::Unit;

/// Slabs per thread: more slabs than threads, so that a thread whose slabs
/// hold little finds more work.
const SLABS_PER_THREAD: usize = 8;

/// The layers of each slab for `threads` threads (at least 1): whole brick
/// layers, about as many per slab; one slab for one thread.
#[must_use]
pub fn slab_layers(nz: u32, threads: usize) -> Vec<Range<u32>> {
    let brick_layers = nz.div_ceil(BRICK).max(1);
    let wanted = if threads <= 1 {
        1
    } else {
        threads.saturating_mul(SLABS_PER_THREAD)
    };
    let n = u32::try_from(wanted).unwrap_or(u32::MAX).min(brick_layers);
    (0..n)
        .map(|i| {
            // Brick layer boundaries spread evenly: i·L/n (L < 2^14).
            let at = |i: u32| (u64::from(i) * u64::from(brick_layers) / u64::from(n)) as u32;
            let z0 = at(i) * BRICK;
            let z1 = (at(i + 1) * BRICK).min(nz);
            z0..z1
        })
        .collect()
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
}

/// What the count pass found, for the caller's checks before the records
/// are allocated.
#[derive(Clone, Copy, Debug)]
pub(super) struct Counted {
    /// Records (non-transparent voxels).
    pub records: usize,
    /// Entries of list storage the fill pass needs (0 without lists).
    pub list_entries: usize,
    /// Entries of the slabs' directories while they are built.
    pub directory: usize,
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

/// One slab's parts of the plane and of the (padded) directory.
struct Part<'p, 'd> {
    z0: u32,
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
    /// Runs both passes over `plane` (the whole raster, zero) in the slabs
    /// of `layers`, on `pool`; `check` sees the count pass's sizes before
    /// anything more is allocated and may refuse the scene.
    ///
    /// # Errors
    /// `check`'s refusal, a voxelizer's (of the lowest object id), the
    /// store's.
    pub fn run(
        &self,
        plane: &mut [u8],
        layers: &[Range<u32>],
        pool: &ThreadPool,
        check: impl FnOnce(Counted) -> Result<(), BuildError>,
        progress: &ProgressBar,
    ) -> Result<Voxelized, BuildError> {
        let extent = self.frame.extent;
        let [nx, ny, _] = extent.dims();
        let bad = || BuildError::Raster("slabs do not fit the raster".into());
        let dir_len = directory_len(extent).ok_or_else(bad)?;
        let padded = dir_len
            .checked_add(layers.len().saturating_sub(1))
            .ok_or_else(bad)?;
        let mut directory = vec![0u32; padded];

        // Each slab's parts.
        let mut parts = Vec::with_capacity(layers.len());
        let (mut plane_rest, mut dir_rest) = (plane, &mut directory[..]);
        for l in layers {
            let e = Extent::new(nx, ny, l.end.saturating_sub(l.start)).map_err(|_| bad())?;
            let (p, pr) = plane_rest.split_at_mut_checked(e.len()).ok_or_else(bad)?;
            let d_len = directory_len(e).ok_or_else(bad)?;
            let (d, dr) = dir_rest.split_at_mut_checked(d_len).ok_or_else(bad)?;
            parts.push(Part {
                z0: l.start,
                extent: e,
                plane: p,
                dir: d,
            });
            (plane_rest, dir_rest) = (pr, dr);
        }
        let slabs = parts.len() as u64;
        let objects = self.objects.len() as u64;

        crate::progress::phase(
            progress,
            "voxelizing (count pass)",
            Unit::SlabObjects,
            objects.saturating_mul(slabs),
        );
        // Slabs in order: nothing says yet which hold more.
        let counted = heaviest_first(
            pool,
            parts,
            |_, i| u64::MAX - i as u64,
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
        })?;
        let offers = sizings.iter().map(|(_, o)| *o).sum();

        // Written (and its pages first touched) on the pool's threads: the
        // records are the build's largest allocation.
        let mut records: Vec<VoxelRecord> = pool.install(|| {
            (0..records_n)
                .into_par_iter()
                .map(|_| VoxelRecord::default())
                .collect()
        });
        let mut lists = vec![0u32; list_n];
        let record_counts: Vec<usize> = sizings.iter().map(|(s, _)| s.records()).collect();
        let mut jobs = Vec::with_capacity(sizings.len());
        let (mut rec_rest, mut list_rest) = (&mut records[..], &mut lists[..]);
        for ((sizing, _), &l) in sizings.into_iter().zip(&list_sizes) {
            let (r, rr) = rec_rest.split_at_mut(sizing.records());
            let (s, sr) = list_rest.split_at_mut(l);
            jobs.push((sizing, r, s));
            (rec_rest, list_rest) = (rr, sr);
        }
        crate::progress::phase(
            progress,
            "voxelizing (fill pass)",
            Unit::SlabObjects,
            objects.saturating_mul(slabs),
        );
        // The slabs with the most records first.
        let filled = heaviest_first(
            pool,
            jobs,
            |(_, r, _), _| r.len() as u64,
            |(sizing, r, s)| self.fill(sizing, r, s, progress),
        );
        let lists_used = first_error(filled)?;

        // Join: directory entries up by the records before, lists closed up
        // and their indices shifted by the entries before.
        let mut brick = 0usize;
        let mut from = 0usize;
        let mut base = 0usize;
        let mut list_from = 0usize;
        let mut list_to = 0usize;
        for (((l, &n), &bound), &used) in layers
            .iter()
            .zip(&record_counts)
            .zip(&list_sizes)
            .zip(&lists_used)
        {
            let e = Extent::new(nx, ny, l.end.saturating_sub(l.start)).map_err(|_| bad())?;
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

    /// The count pass of one slab: its sizing and the offers inside it.
    fn count<'p, 'd>(
        &self,
        part: Part<'p, 'd>,
        progress: &ProgressBar,
    ) -> Result<(Sizing<'p, 'd>, u64), (usize, BuildError)> {
        let raster = RasterMut::new(part.extent, part.plane)
            .map_err(|e| (0, BuildError::Raster(e.to_string())))?;
        // The plane is a fresh zeroed map, the directory fresh zeros.
        let mut counter =
            Counter::slab_zeroed(raster, part.dir, part.z0).map_err(|e| (0, e.into()))?;
        for (id, o) in self.objects.iter().enumerate() {
            o.voxelize(self.frame, self.separation, Pass::Count(&mut counter))
                .map_err(|e| (id, e))?;
            progress.inc(1);
        }
        let r = counter.report();
        let sizing = counter
            .finish()
            .map_err(|e| (self.objects.len(), e.into()))?;
        Ok((sizing, r.offers.saturating_sub(r.outside)))
    }

    /// The fill pass of one slab into its records and list storage:
    /// the list entries its finished lists take.
    fn fill(
        &self,
        sizing: Sizing<'_, '_>,
        records: &mut [VoxelRecord],
        lists: &mut [u32],
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
        for (id, o) in self.objects.iter().enumerate() {
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
            o.voxelize(self.frame, self.separation, pass)
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
    fn slabs_are_whole_brick_layers_covering_the_raster() {
        for (nz, threads) in [
            (1, 1),
            (61, 2),
            (64, 2),
            (1024, 2),
            (20, 8),
            (9, 3),
            (1000, 3),
        ] {
            let s = slab_layers(nz, threads);
            assert_eq!(s.first().map(|l| l.start), Some(0), "{nz} {threads}");
            assert_eq!(s.last().map(|l| l.end), Some(nz), "{nz} {threads}");
            for w in s.windows(2) {
                assert_eq!(w[0].end, w[1].start);
                assert_eq!(w[0].end % BRICK, 0);
            }
            assert!(s.iter().all(|l| l.start < l.end), "{nz} {threads}: {s:?}");
            if threads == 1 {
                assert_eq!(s.len(), 1);
            }
        }
    }
}
