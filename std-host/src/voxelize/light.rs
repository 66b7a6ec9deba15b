//! The light pass: light visibility and precomputed illumination for every
//! record ([`rrt_core::light::illuminate_run`]), in runs of records on
//! rayon's threads.
//!
//! One discrete shadow ray per record and light gives the record's two
//! visibility bits per light and its ambient + diffuse illumination (SPD
//! intensities `I = sqrt(nl)/(2·nl)`, ambient the same). Each record's
//! bits and illumination depend only on the (unchanged) store, so the
//! result is the serial pass's whatever the thread count. The runs write
//! into a copy of the records (one more record array while the pass
//! runs), since the store they read must stay whole.

use indicatif::ProgressBar;
use rayon::prelude::*;
use rrt_core::light::bricks::{ShadowBricks, shadow_bricks};
use rrt_core::light::{LightError, LightParams, LightReport, illuminate_run};
use rrt_core::object_table::{Light, Lights, Materials, Object, ObjectTable};
use rrt_core::proximity::coarse_extent;
use rrt_core::raster::Raster;
use rrt_core::store::RecordStore;
use rrt_core::voxel::VoxelRecord;

use super::BuildError;
use super::materials::{MAX_MATERIALS, MaterialTable, scalar};
use super::objects::TableObject;
use crate::fit::FittedLight;
use crate::scene::light_intensity;

/// Records per run of the parallel light pass, at most.
const LIGHT_RUN: usize = 1 << 14;

/// Records per run at least, when a pass has few records for its threads.
const LIGHT_RUN_MIN: usize = 1 << 8;

/// Runs per thread the pass aims for, so that threads that finish early
/// take more.
const RUNS_PER_THREAD: usize = 8;

/// Records per run of a pass over `records` records on `threads` threads:
/// [`RUNS_PER_THREAD`] runs per thread, within [`LIGHT_RUN_MIN`] and
/// [`LIGHT_RUN`]. Each record is lit on its own, so the runs change which
/// thread lights it, never the result.
fn run_length(records: usize, threads: usize) -> usize {
    records
        .div_ceil(threads.max(1) * RUNS_PER_THREAD)
        .clamp(LIGHT_RUN_MIN, LIGHT_RUN)
}

/// The shadow classification's brick level of a raster
/// ([`rrt_core::light::bricks`]): one byte and one owner per 8³ brick,
/// made from the records. The light pass and a renderer that classifies on
/// demand try it before a voxel's own walk; it changes no answer.
#[derive(Debug)]
pub struct ShadowLevel {
    plane: Vec<u8>,
    owners: Vec<u32>,
}

impl ShadowLevel {
    /// The level of `store`'s raster.
    ///
    /// # Errors
    /// [`BuildError::Alloc`] when its buffers cannot be allocated.
    pub fn of(store: &RecordStore<'_>) -> Result<Self, BuildError> {
        let n = coarse_extent(store.extent()).map_or(0, |e| e.len());
        let mut plane = super::try_vec(n, "shadow brick level")?;
        plane.resize(n, 0);
        let mut owners = super::try_vec(n, "shadow brick owners")?;
        owners.resize(n, 0);
        // The buffers have the brick count's length: this fills them.
        shadow_bricks(store, &mut owners, &mut plane);
        Ok(Self { plane, owners })
    }

    /// The core's view of the level for a raster of `store`'s extent.
    #[must_use]
    pub fn bricks(&self, store: &RecordStore<'_>) -> Option<ShadowBricks<'_>> {
        ShadowBricks::new(store.extent(), &self.plane, &self.owners)
    }
}

/// What the light pass reads besides the raster: the core's object-table
/// entries, material table and lights.
pub(super) struct LightScene {
    entries: Vec<Object>,
    /// Per object id: a volume rendered directly, whose records need no
    /// light (its samples are lit when composited).
    unlit: Vec<bool>,
    materials: Box<Materials<MAX_MATERIALS>>,
    lights: Lights,
}

impl LightScene {
    /// The core's tables for `objects` (in id order) and `lights`.
    pub fn new(
        objects: &[TableObject<'_>],
        materials: &MaterialTable,
        lights: &[FittedLight],
    ) -> Self {
        let intensity = scalar(light_intensity(lights.len()));
        let mut core_lights = Lights::new(intensity);
        for l in lights {
            let c = l.colour;
            // The builder refuses more than MAX_LIGHTS: no push fails.
            let _ = core_lights.push(Light {
                position: l.position,
                color: [c.x, c.y, c.z].map(scalar),
                intensity,
            });
        }
        Self {
            entries: objects
                .iter()
                .map(|o| Object {
                    shape: o.entry(),
                    material: materials.of(o.material()),
                })
                .collect(),
            unlit: objects
                .iter()
                .map(|o| matches!(o, TableObject::Volume(v) if v.data.classifier.is_direct()))
                .collect(),
            materials: materials.core(),
            lights: core_lights,
        }
    }

    /// The lit copy of `store`'s records, computed on `pool`'s threads, and
    /// the pass's counts; `progress` counts records as their runs finish.
    /// `level`, the raster's brick level, spares classification walks.
    ///
    /// # Errors
    /// The core's [`LightError`].
    pub fn illuminate(
        &self,
        raster: &Raster<'_>,
        store: &RecordStore<'_>,
        params: &LightParams,
        level: Option<&ShadowLevel>,
        pool: &rayon::ThreadPool,
        progress: &ProgressBar,
    ) -> Result<(Vec<VoxelRecord>, LightReport), BuildError> {
        let bricks = level.and_then(|l| l.bricks(store));
        let mut storage = vec![Object::UNUSED; self.entries.len()];
        let mut table = ObjectTable::new(&mut storage, &mut []);
        for o in &self.entries {
            // The storage holds exactly these objects: no push fails.
            let _ = table.push(*o);
        }
        // Copied on the pool's threads, as the copy is as large as the store.
        let mut out: Vec<VoxelRecord> = super::try_vec(store.len(), "lit records")?;
        pool.install(|| out.par_extend(store.records().par_iter().copied()));
        let run_len = run_length(out.len(), pool.current_num_threads());
        let reports: Vec<Result<LightReport, LightError>> = pool.install(|| {
            out.par_chunks_mut(run_len)
                .enumerate()
                .map(|(i, run)| {
                    let n = run.len() as u64;
                    let mut report = LightReport::default();
                    // The records of volumes rendered directly are left
                    // as they are: the rest in runs between them.
                    let mut start = 0;
                    while start < run.len() {
                        let lit = |r: &VoxelRecord| {
                            let id = usize::try_from(store.owner(r)).unwrap_or(usize::MAX);
                            !self.unlit.get(id).copied().unwrap_or(false)
                        };
                        let rest = run.get(start..).unwrap_or(&[]);
                        let skip = rest.iter().take_while(|r| !lit(r)).count();
                        start += skip;
                        let rest = run.get(start..).unwrap_or(&[]);
                        let len = rest.iter().take_while(|r| lit(r)).count();
                        if len == 0 {
                            continue;
                        }
                        if let Some(sub) = run.get_mut(start..start + len) {
                            report.add(&illuminate_run(
                                raster,
                                store,
                                i * run_len + start,
                                sub,
                                &table,
                                &self.materials,
                                &self.lights,
                                params,
                                bricks.as_ref(),
                            )?);
                        }
                        start += len;
                    }
                    progress.inc(n);
                    Ok(report)
                })
                .collect()
        });
        let mut report = LightReport::default();
        for r in reports {
            report.add(&r?);
        }
        Ok((out, report))
    }
}

#[cfg(test)]
mod tests {
    use super::{LIGHT_RUN, LIGHT_RUN_MIN, RUNS_PER_THREAD, run_length};

    #[test]
    fn runs_share_a_pass_out_within_their_bounds() {
        for threads in [0, 1, 2, 3, 8, 64] {
            for records in [0, 1, 255, 256, 10_444, 100_000, 4_390_966, usize::MAX / 256] {
                let run = run_length(records, threads);
                assert!(
                    (LIGHT_RUN_MIN..=LIGHT_RUN).contains(&run),
                    "{records} {threads}"
                );
                let runs = records.div_ceil(run);
                // As many runs as the threads want, unless runs would fall
                // below their least length.
                if run > LIGHT_RUN_MIN && run < LIGHT_RUN {
                    assert!(
                        runs >= threads.max(1) * RUNS_PER_THREAD - 1,
                        "{records} {threads}"
                    );
                }
            }
        }
        // Few records: more than one run for two threads.
        assert!(10_444usize.div_ceil(run_length(10_444, 2)) >= 8);
    }
}
