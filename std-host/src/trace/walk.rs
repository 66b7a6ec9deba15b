//! The discrete walk of a ray: the world ray as a 3D discrete line
//! clipped to the raster box (the paper's two endpoints), its walk to the
//! first non-transparent voxel (scalar with empty-space skipping, or eight
//! lanes in a [`RayPacket8`]), and resuming the walk past a voxel that is
//! not the hit.

use glam::DVec3;
use rrt_core::discrete_ray::{DiscreteRay, ORIGIN_LIMIT, WalkEnd};
use rrt_core::fixed::VOXEL;
use rrt_core::light::LeavingSurface;
use rrt_core::packet::RayPacket8;
use rrt_core::raster::{Extent, cell};
use rrt_core::store::RecordStore;
use rrt_core::voxel::VoxelRecord;

use super::verify::{Candidate, Mailbox, REACH_MARGIN, exit_param, slab};
use super::{BLOCK, Composite, RayStats, SurfaceHit, Tracer};
use crate::frame::round_to_i64;
use crate::world::Ray;

/// The first stage of a ray: its discrete walk to the first
/// non-transparent voxel (`None`: the ray misses the raster).
#[derive(Clone, Copy, Debug)]
pub struct FirstWalk {
    pub(super) ray: Option<DiscreteRay>,
    pub(super) end: WalkEnd,
    pub(super) steps: u64,
    /// The record of the hit voxel when the walk's hit test already
    /// fetched it (index, record), so that resolving does not look it up
    /// again.
    found: Option<(usize, VoxelRecord)>,
}

impl FirstWalk {
    /// The walk of a ray that misses the raster.
    const MISSED: Self = Self {
        ray: None,
        end: WalkEnd::Exit,
        steps: 0,
        found: None,
    };
}

/// `x` rounded to the nearest integer, halves away from zero, saturating:
/// `f64::round` is a library call on the baseline x86-64 target, and this
/// runs twice per axis for every ray. (The fixed-point ray is whatever this
/// gives: any deterministic rounding would do.)
#[inline]
fn round_to_int(x: f64) -> i64 {
    round_to_i64(x)
}

impl Tracer<'_> {
    /// The discrete ray of a world ray (unit direction), clipped to the
    /// raster; `None` if it misses the raster.
    pub(super) fn discrete(&self, ray: &Ray) -> Option<DiscreteRay> {
        let d = ray.dir;
        let m = d.abs().max_element();
        if !(m > 0.0 && m.is_finite()) {
            return None;
        }
        let one = f64::from(1u32 << 30);
        let dir = [d.x, d.y, d.z].map(|c| round_to_int(c / m * one) as i32);
        let mut o = self.frame.world_to_raster(ray.origin);
        // Origins beyond the core's range (a far camera) start just before
        // the raster box instead; the line is the same.
        let limit = (ORIGIN_LIMIT / VOXEL / 2) as f64;
        if !(o.abs().max_element() < limit) {
            let dims = DVec3::from(self.extent.dims().map(f64::from));
            let (t0, t1) = slab(o, d, DVec3::ZERO, dims)?;
            if t1 < 0.0 {
                return None;
            }
            o += d * (t0 - 1.0).max(0.0);
            if !(o.abs().max_element() < limit) {
                return None;
            }
        }
        let fx = |v: f64| round_to_int(v * VOXEL as f64);
        DiscreteRay::new(self.extent, [fx(o.x), fx(o.y), fx(o.z)], dir)
            .ok()
            .flatten()
    }

    /// The discrete ray the tracer walks for a world ray (unit direction),
    /// clipped to the raster; `None` if it misses the raster. For
    /// benchmarks and tools that walk the same rays themselves.
    #[must_use]
    pub fn discrete_ray(&self, ray: &Ray) -> Option<DiscreteRay> {
        self.discrete(ray)
    }

    /// Stage one of a primary ray: its walk to the first non-transparent
    /// voxel (what a ray packet does).
    #[must_use]
    pub fn first_walk(&self, ray: &Ray) -> FirstWalk {
        let Some(mut dray) = self.discrete(ray) else {
            return FirstWalk::MISSED;
        };
        let end = dray
            .walk_skipping(&self.raster, self.opts.connectivity, u32::MAX, |_, c| {
                c & cell::OPAQUE != 0
            })
            .unwrap_or(WalkEnd::Exit);
        FirstWalk {
            steps: u64::from(dray.steps()),
            ray: Some(dray),
            end,
            found: None,
        }
    }

    pub(super) fn secondary_walk(
        &self,
        ray: &Ray,
        rule: &LeavingSurface,
        stats: &mut RayStats,
    ) -> FirstWalk {
        let Some(mut dray) = self.discrete(ray) else {
            return FirstWalk::MISSED;
        };
        let raster = self.raster;
        let store = self.store;
        let extent = self.extent;
        let mut missing = 0u64;
        let mut found = None;
        let end = dray
            .walk_skipping(&raster, self.opts.connectivity, u32::MAX, |index, c| {
                hit_test(
                    &store,
                    extent,
                    Some(rule),
                    index,
                    c,
                    &mut missing,
                    &mut found,
                )
            })
            .unwrap_or(WalkEnd::Exit);
        stats.missing += missing;
        FirstWalk {
            steps: u64::from(dray.steps()),
            ray: Some(dray),
            end,
            found,
        }
    }

    /// Stage one for eight rays at once: a [`RayPacket8`] walks every lane
    /// to its first non-transparent voxel, skipping empty space; each
    /// lane's ray and step count are exactly those the scalar
    /// [`Tracer::first_walk`] leaves.
    pub(super) fn first_walks_packet(
        &self,
        rays: &[Option<Ray>; BLOCK],
    ) -> [Option<FirstWalk>; BLOCK] {
        let lanes: [Option<DiscreteRay>; BLOCK] =
            std::array::from_fn(|l| rays[l].as_ref().and_then(|r| self.discrete(r)));
        let hits = RayPacket8::from_rays(self.extent, lanes)
            .ok()
            .and_then(|mut p| {
                let hits = p
                    .first_hit_skipping(&self.raster, self.opts.connectivity)
                    .ok()?;
                Some((p, hits))
            });
        let Some((packet, hits)) = hits else {
            // Unreachable in practice (every lane is over this extent); fall
            // back to the scalar walk.
            return rays.map(|r| r.map(|r| self.first_walk(&r)));
        };
        std::array::from_fn(|l| {
            rays[l].as_ref()?;
            let ray = packet.lane_ray(l);
            Some(FirstWalk {
                steps: ray.map_or(0, |r| u64::from(r.steps())),
                end: if hits & (1 << l) != 0 {
                    WalkEnd::Hit
                } else {
                    WalkEnd::Exit
                },
                ray,
                found: None,
            })
        })
    }

    /// Resolves a ray's walk into its surface hit: checks the hit voxel
    /// (record, verification) and resumes the walk past false hits
    /// (verification: [`Tracer::resolve_verified`]).
    pub(super) fn resolve(
        &self,
        ray: &Ray,
        walk: &mut FirstWalk,
        tmin: f64,
        leave: Option<&LeavingSurface>,
        acc: &mut Composite,
        stats: &mut RayStats,
    ) -> Option<SurfaceHit> {
        let before = stats.false_hits;
        let hit = if self.opts.mode.verifies() {
            self.resolve_verified(ray, walk, tmin, leave, acc, stats)
        } else {
            self.resolve_walk(ray, walk, tmin, leave, acc, stats)
        };
        if stats.false_hits > before {
            stats.false_hit_rays += 1;
        }
        hit
    }

    /// The paper's raw mode: the first surface voxel is the hit; a voxel
    /// a volume rendered directly owns is composited into `acc` and
    /// passed (`None` once compositing stops).
    pub(super) fn resolve_walk(
        &self,
        ray: &Ray,
        walk: &mut FirstWalk,
        tmin: f64,
        leave: Option<&LeavingSurface>,
        acc: &mut Composite,
        stats: &mut RayStats,
    ) -> Option<SurfaceHit> {
        stats.steps += walk.steps;
        // Resumed in place: a discrete ray is a few hundred bytes.
        let dray = walk.ray.as_mut()?;
        let mut end = walk.end;
        let o_r = self.frame.world_to_raster(ray.origin);
        loop {
            if end != WalkEnd::Hit {
                return None;
            }
            let h = dray.hit();
            let rec = match walk.found.take() {
                Some((i, rec)) if i == h.index => Some(rec),
                _ => {
                    let c = self.raster.plane().get(h.index).copied().unwrap_or(0);
                    self.store.get_hinted(h.voxel, c).copied()
                }
            };
            match &rec {
                None => stats.missing += 1,
                Some(rec) => match self.direct_of(rec) {
                    Some(d) if self.store.owner(rec) == d.object => {
                        if self.composite_voxel(ray, o_r, h.voxel, d, tmin, f64::INFINITY, acc) {
                            stats.samples += 1;
                            if acc.done() {
                                return None;
                            }
                        }
                    }
                    _ => return Some(self.discrete_hit(ray, o_r, h.voxel, rec, tmin)),
                },
            }
            // Resume after this voxel.
            let before = dray.steps();
            let raster = self.raster;
            let store = self.store;
            let extent = self.extent;
            let mut missing = 0u64;
            end = dray
                .walk_skipping(&raster, self.opts.connectivity, u32::MAX, |index, c| {
                    hit_test(
                        &store,
                        extent,
                        leave,
                        index,
                        c,
                        &mut missing,
                        &mut walk.found,
                    )
                })
                .unwrap_or(WalkEnd::Exit);
            stats.missing += missing;
            stats.steps += u64::from(dray.steps().saturating_sub(before));
        }
    }

    /// Resolves a walk under verification (module docs, *Intersection
    /// verification*): at each opaque voxel reached, its objects are tested
    /// ([`Tracer::test_voxel`]); the nearest candidate is the hit as soon
    /// as its `t` is within the part of the ray the walk has reached (up to
    /// the continuous ray's exit from the current voxel, plus
    /// [`REACH_MARGIN`]); otherwise the walk goes on. A walk that leaves the
    /// raster with a candidate takes it. The sample of a voxel of a volume
    /// rendered directly is composited into `acc` up to the candidate
    /// accepted in it, if any (`None` once compositing stops).
    pub(super) fn resolve_verified(
        &self,
        ray: &Ray,
        walk: &mut FirstWalk,
        tmin: f64,
        leave: Option<&LeavingSurface>,
        acc: &mut Composite,
        stats: &mut RayStats,
    ) -> Option<SurfaceHit> {
        stats.steps += walk.steps;
        let dray = walk.ray.as_mut()?;
        let mut end = walk.end;
        let o_r = self.frame.world_to_raster(ray.origin);
        let vs = self.frame.voxel_size;
        let mut mail = Mailbox::default();
        let mut best: Option<Candidate> = None;
        if leave.is_none() {
            self.test_origin_voxels(ray, o_r, tmin, &mut mail, &mut best);
        }
        loop {
            if end != WalkEnd::Hit {
                return best.map(|c| self.accept(ray, &c, stats));
            }
            let h = dray.hit();
            // The volume rendered directly and the record, if one is
            // needed: a voxel of a volume alone has nothing to test.
            let looked = match self.direct_alone(h.voxel) {
                Some(d) => Some((Some(d), None)),
                None => {
                    let c = self.raster.plane().get(h.index).copied().unwrap_or(0);
                    let rec = self.store.get_hinted(h.voxel, c);
                    if rec.is_none() {
                        stats.missing += 1;
                    }
                    rec.map(|r| (self.direct_of(r), Some(r)))
                }
            };
            match looked {
                None => {}
                Some((direct, rec)) => {
                    if let Some(rec) = rec
                        && (direct.is_none() || self.store.objects(rec).len() > 1)
                    {
                        self.test_voxel(
                            ray, o_r, h.voxel, h.index, rec, tmin, leave, &mut mail, &mut best,
                        );
                    }
                    // The candidate's t when it lies within the part of
                    // the ray the walk has reached.
                    let here = best
                        .as_ref()
                        .map(|b| b.t)
                        .filter(|&t| t <= (exit_param(o_r, ray.dir, h.voxel) + REACH_MARGIN) * vs);
                    if let Some(d) = direct
                        && self.composite_voxel(
                            ray,
                            o_r,
                            h.voxel,
                            d,
                            tmin,
                            here.unwrap_or(f64::INFINITY),
                            acc,
                        )
                    {
                        stats.samples += 1;
                        if acc.done() {
                            return None;
                        }
                    }
                    match &best {
                        Some(b) if here.is_some() => return Some(self.accept(ray, b, stats)),
                        Some(_) => stats.deferred += 1,
                        None if direct.is_some() => {}
                        None => stats.false_hits += 1,
                    }
                }
            }
            let before = dray.steps();
            end = dray
                .walk_skipping(&self.raster, self.opts.connectivity, u32::MAX, |_, c| {
                    c & cell::OPAQUE != 0
                })
                .unwrap_or(WalkEnd::Exit);
            stats.steps += u64::from(dray.steps().saturating_sub(before));
        }
    }
}

impl Tracer<'_> {
    /// Verification of the voxels around the exact origin `o_r` (raster
    /// coordinates) of a ray that leaves no surface (a primary ray) when
    /// it lies within [`ORIGIN_ROUNDING`] of a voxel face: the discrete
    /// ray starts from the origin rounded to fixed point, which may lie
    /// across that face (an eye a hair above a floor lying on a voxel face
    /// starts in the voxel below it), so the walk may never visit the
    /// voxel holding the eye. Every opaque voxel the exact origin may lie
    /// in has its objects tested first. (A ray leaving a surface starts
    /// off it by the surface offset, thousands of fixed-point units.)
    fn test_origin_voxels(
        &self,
        ray: &Ray,
        o_r: DVec3,
        tmin: f64,
        mail: &mut Mailbox,
        best: &mut Option<Candidate>,
    ) {
        let base = o_r.floor();
        // Per axis, the voxel offsets the origin may lie in: 0, and -1 or
        // +1 across a face within rounding.
        let mut across = [0i64; 3];
        for k in 0..3 {
            let f = o_r[k] - base[k];
            if f < ORIGIN_ROUNDING {
                across[k] = -1;
            } else if f > 1.0 - ORIGIN_ROUNDING {
                across[k] = 1;
            }
        }
        if across == [0; 3] || !base.is_finite() {
            return;
        }
        let dims = self.extent.dims();
        for corner in 0..8u32 {
            let moved = |k: usize| corner & (1 << k) != 0;
            if (0..3).any(|k| moved(k) && across[k] == 0) {
                continue;
            }
            let mut v = [0u32; 3];
            let mut inside = true;
            for k in 0..3 {
                let step = if moved(k) { across[k] } else { 0 };
                // A whole number: the floor of a finite coordinate.
                match u32::try_from(base[k] as i64 + step) {
                    Ok(c) if c < dims[k] => v[k] = c,
                    _ => inside = false,
                }
            }
            if !inside {
                continue;
            }
            let Some((index, c)) = self.opaque_cell(v) else {
                continue;
            };
            if let Some(rec) = self.store.get_hinted(v, c) {
                self.test_voxel(ray, o_r, v, index, rec, tmin, None, mail, best);
            }
        }
    }
}

/// How close (in voxels) an exact ray origin may lie to a voxel face for
/// its fixed-point rounding to put the discrete ray's start across it:
/// two fixed-point units.
const ORIGIN_ROUNDING: f64 = 2.0 / VOXEL as f64;

/// The hit test of a secondary walk ([`surface_voxel`]); a hit leaves its
/// index and record in `found`.
pub(super) fn hit_test(
    store: &RecordStore<'_>,
    extent: Extent,
    leave: Option<&LeavingSurface>,
    index: usize,
    c: u8,
    missing: &mut u64,
    found: &mut Option<(usize, VoxelRecord)>,
) -> bool {
    let rec = surface_voxel(store, extent, leave, index, c, missing);
    if let Some(rec) = rec {
        *found = Some((index, *rec));
    }
    rec.is_some()
}

/// The record of the voxel at `index` (plane cell `c`) if it is a surface
/// a ray leaving `leave` can hit: opaque, with a record (one missing is
/// counted in `missing`), and not part of the surface being left (the acne
/// rule). The one test of every ray that leaves a surface: reflected,
/// refracted and render-time shadow rays.
pub(super) fn surface_voxel<'s>(
    store: &RecordStore<'s>,
    extent: Extent,
    leave: Option<&LeavingSurface>,
    index: usize,
    c: u8,
    missing: &mut u64,
) -> Option<&'s VoxelRecord> {
    if c & cell::OPAQUE == 0 {
        return None;
    }
    // The voxel being left is never a hit (and has a record: it was hit).
    if leave.is_some_and(|l| l.start == Some(index)) {
        return None;
    }
    let v = extent.coord(index)?;
    let Some(rec) = store.get_hinted(v, c) else {
        *missing += 1;
        return None;
    };
    leave
        .is_none_or(|l| !l.ignores_voxel(store, v, rec))
        .then_some(rec)
}
