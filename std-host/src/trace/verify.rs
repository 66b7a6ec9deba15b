//! Intersection verification: a discrete hit checked against the exact
//! object of the object table (module docs of [`crate::trace`]).

use glam::DVec3;
use rrt_core::light::LeavingSurface;
use rrt_core::raster::cell;
use rrt_core::voxel::VoxelRecord;

use super::{RayStats, SurfaceHit, Tracer};
use crate::frame::RasterFrame;
use crate::voxelize::WorldObject;
use crate::world::{Hit, Ray};

/// The slab intersection of the line `o + t·d` with the box `[lo, hi]`:
/// `(t_enter, t_exit)`, or `None` if the line misses it.
pub(super) fn slab(o: DVec3, d: DVec3, lo: DVec3, hi: DVec3) -> Option<(f64, f64)> {
    let mut t0 = f64::NEG_INFINITY;
    let mut t1 = f64::INFINITY;
    for k in 0..3 {
        if d[k] == 0.0 {
            if o[k] < lo[k] || o[k] > hi[k] {
                return None;
            }
        } else {
            let a = (lo[k] - o[k]) / d[k];
            let b = (hi[k] - o[k]) / d[k];
            t0 = t0.max(a.min(b));
            t1 = t1.min(a.max(b));
        }
    }
    (t0 <= t1).then_some((t0, t1))
}

/// The unit vector of a stored octahedral normal (unfolded in integers,
/// normalized in floating point).
fn decode(rec: &VoxelRecord) -> DVec3 {
    let n = rrt_core::voxel::unfold(rec.normal);
    DVec3::new(n[0] as f64, n[1] as f64, n[2] as f64).normalize_or(DVec3::Z)
}

/// The outcome of verifying one discrete hit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Verdict {
    /// The continuous ray meets the object near the voxel: the true hit.
    Hit(Hit),
    /// The continuous ray meets the object, but farther along than the
    /// voxel's neighbourhood (a ray grazing a surface's voxel layer): the
    /// walk goes on to the voxel that holds the intersection.
    Ahead,
    /// The continuous ray does not meet the object from the voxel on: the
    /// paper's *false hit*.
    False,
}

/// Intersection verification of a discrete hit at voxel `v` by the world
/// ray `ray` (unit direction): the exact intersection with `object` (with
/// `t > tmin`) whose point lies in the voxel's box grown by one voxel on
/// every side is the hit (module docs).
#[must_use]
pub fn verify(
    frame: &RasterFrame,
    object: &WorldObject,
    ray: &Ray,
    v: [u32; 3],
    tmin: f64,
) -> Verdict {
    let lo = DVec3::from(v.map(f64::from));
    let o_r = frame.world_to_raster(ray.origin);
    let vs = frame.voxel_size;
    let Some((a, b)) = slab(o_r, ray.dir, lo - 1.0, lo + 2.0) else {
        return Verdict::False;
    };
    let from = (a * vs).max(tmin);
    let first = object
        .shape
        .intersect(ray, from, f64::INFINITY)
        .filter(|hit| hit.normal.is_finite());
    match first {
        Some(hit) if hit.t < b * vs => Verdict::Hit(hit),
        Some(_) => Verdict::Ahead,
        None => Verdict::False,
    }
}

impl Tracer<'_> {
    /// The hit at voxel `v` with record `rec`, or `None` for a false hit.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn check_hit(
        &self,
        ray: &Ray,
        o_r: DVec3,
        vs: f64,
        v: [u32; 3],
        rec: &VoxelRecord,
        tmin: f64,
        leave: Option<&LeavingSurface>,
        stats: &mut RayStats,
    ) -> Option<SurfaceHit> {
        let lo = DVec3::from(v.map(f64::from));
        if self.opts.verify
            && let Some(obj) = self.objects.get(usize::try_from(rec.object).ok()?)
            && obj.shape.is_exact()
        {
            let verdict = verify(&self.frame, obj, ray, v, tmin);
            if let Verdict::Hit(hit) = verdict {
                return Some(SurfaceHit {
                    voxel: v,
                    rec: *rec,
                    point: ray.at(hit.t),
                    normal: hit.normal,
                    verified: true,
                });
            }
            if let Some(h) = self.verify_neighbours(ray, v, rec.object, tmin, leave) {
                stats.neighbour_hits += 1;
                return Some(h);
            }
            match verdict {
                Verdict::Ahead => stats.deferred += 1,
                _ => stats.false_hits += 1,
            }
            return None;
        }
        // The point where the ray entered the voxel (or, for a voxel the
        // continuous ray only grazes, its point nearest the voxel centre).
        let t = match slab(o_r, ray.dir, lo, lo + 1.0) {
            Some((t0, _)) => t0,
            None => (lo + 0.5 - o_r).dot(ray.dir),
        };
        let t = (t * vs).max(tmin.max(0.0));
        Some(SurfaceHit {
            voxel: v,
            rec: *rec,
            point: ray.at(t),
            normal: decode(rec),
            verified: false,
        })
    }

    /// When the hit voxel's own object fails verification: the nearest
    /// exact intersection, within the same window, with the objects that
    /// own the voxel's 26 neighbours (each object once, none the acne rule
    /// ignores). A voxel holds one object; where surfaces meet (a mesh's
    /// shared edges, touching spheres) the object the ray truly meets in
    /// this voxel may own only the voxel next to it.
    pub(super) fn verify_neighbours(
        &self,
        ray: &Ray,
        v: [u32; 3],
        own: u32,
        tmin: f64,
        leave: Option<&LeavingSurface>,
    ) -> Option<SurfaceHit> {
        let mut tried = [own; 27];
        let mut n_tried = 1;
        let mut best: Option<(f64, SurfaceHit)> = None;
        for dz in -1i32..=1 {
            for dy in -1i32..=1 {
                for dx in -1i32..=1 {
                    let (Some(x), Some(y), Some(z)) = (
                        v[0].checked_add_signed(dx),
                        v[1].checked_add_signed(dy),
                        v[2].checked_add_signed(dz),
                    ) else {
                        continue;
                    };
                    let Some(index) = self.extent.index([x, y, z]) else {
                        continue;
                    };
                    let c = self.raster.plane().get(index).copied().unwrap_or(0);
                    if c & cell::OPAQUE == 0 {
                        continue;
                    }
                    let Some(nrec) = self.store.get_hinted([x, y, z], c) else {
                        continue;
                    };
                    if tried[..n_tried].contains(&nrec.object)
                        || leave.is_some_and(|l| l.ignores(self.extent, index, nrec))
                    {
                        continue;
                    }
                    if let Some(slot) = tried.get_mut(n_tried) {
                        *slot = nrec.object;
                        n_tried += 1;
                    }
                    let Some(obj) = usize::try_from(nrec.object)
                        .ok()
                        .and_then(|i| self.objects.get(i))
                    else {
                        continue;
                    };
                    if let Verdict::Hit(hit) = verify(&self.frame, obj, ray, v, tmin)
                        && best.as_ref().is_none_or(|(t, _)| hit.t < *t)
                    {
                        best = Some((
                            hit.t,
                            SurfaceHit {
                                voxel: [x, y, z],
                                rec: *nrec,
                                point: ray.at(hit.t),
                                normal: hit.normal,
                                verified: true,
                            },
                        ));
                    }
                }
            }
        }
        best.map(|(_, h)| h)
    }
}
