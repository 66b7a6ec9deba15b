//! Intersection verification: the objects of each opaque voxel a ray's walk
//! reaches tested against the continuous ray, the nearest intersection the
//! walk has reached accepted (module docs of [`crate::trace`]).

use glam::DVec3;
use rrt_core::light::LeavingSurface;
use rrt_core::store::{BRICK_BITS, brick_dims};
use rrt_core::voxel::VoxelRecord;

use super::{Holds, OWNED_MARGIN, OWNED_SCAN_LIMIT, Owned, RayStats, SurfaceHit, Tracer, rgb};
use crate::frame::RasterFrame;
use crate::shape::Shape;
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
pub(super) fn decode(rec: &VoxelRecord) -> DVec3 {
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

/// The 26 neighbours of a voxel, nearest first (6 faces, 12 edges, 8
/// corners), each group in z, y, x order.
const NEIGHBOURS_BY_DISTANCE: [[i32; 3]; 26] = {
    let mut out = [[0i32; 3]; 26];
    let mut n = 0;
    let mut far = 1;
    while far <= 3 {
        let mut dz: i32 = -1;
        while dz <= 1 {
            let mut dy: i32 = -1;
            while dy <= 1 {
                let mut dx: i32 = -1;
                while dx <= 1 {
                    if dx.abs() + dy.abs() + dz.abs() == far {
                        out[n] = [dx, dy, dz];
                        n += 1;
                    }
                    dx += 1;
                }
                dy += 1;
            }
            dz += 1;
        }
        far += 1;
    }
    out
};

/// Objects one ray has already been tested against: its *mailbox*. A ray
/// meets an object in many voxels; each exact object is intersected once
/// per ray. It is a direct-mapped table of [`MAILBOX`] slots indexed by
/// the object id's low bits, so that a ray crossing voxels that share long
/// object lists (up to [`MAILBOX`] objects of neighbouring ids) tests each
/// once. An object whose slot another object took since may be tested
/// again, which costs time, never changes the answer (the nearest
/// candidate is kept apart).
#[derive(Clone, Copy, Debug)]
pub(super) struct Mailbox {
    /// The id of the object last recorded in each slot.
    keys: [u32; MAILBOX],
    /// Which slots hold an id (bit `s % 64` of word `s / 64`).
    used: [u64; MAILBOX / 64],
}

/// Slots of a `Mailbox`.
pub const MAILBOX: usize = 128;

impl Default for Mailbox {
    fn default() -> Self {
        Self {
            keys: [0; MAILBOX],
            used: [0; MAILBOX / 64],
        }
    }
}

impl Mailbox {
    /// Whether `id` was tested on this ray; if not, it is now recorded as
    /// tested (in its slot, in place of any object there).
    #[inline]
    pub(super) fn tested(&mut self, id: u32) -> bool {
        let slot = id as usize % MAILBOX;
        let bit = 1u64 << (slot % 64);
        let (Some(word), Some(key)) = (self.used.get_mut(slot / 64), self.keys.get_mut(slot))
        else {
            return false;
        };
        if *word & bit != 0 && *key == id {
            return true;
        }
        *key = id;
        *word |= bit;
        false
    }
}

/// How far (in voxels) past the continuous ray's exit from the current
/// voxel an intersection still counts as reached: the discrete line's
/// fixed-point rounding (well below this over any raster).
pub const REACH_MARGIN: f64 = 1e-5;

/// The nearest intersection a verified walk has found so far.
#[derive(Clone, Copy, Debug)]
pub(super) struct Candidate {
    /// World ray parameter.
    pub(super) t: f64,
    /// The object.
    object: u32,
    /// Its true unit normal (exact objects).
    normal: DVec3,
    /// The voxel it was found from, and that voxel's record.
    voxel: [u32; 3],
    rec: VoxelRecord,
    /// An exact intersection (else a hit at the voxel of an object without
    /// exact geometry).
    exact: bool,
    /// The voxel holds more than one object.
    shared: bool,
}

/// The world ray parameter at which the continuous ray `o_r + s·d` (raster
/// coordinates) leaves voxel `v`'s box, in voxels: the smallest exit-plane
/// parameter over the axes (defined even for a voxel the continuous ray
/// only grazes).
pub(super) fn exit_param(o_r: DVec3, d: DVec3, v: [u32; 3]) -> f64 {
    let mut t = f64::INFINITY;
    for k in 0..3 {
        let lo = f64::from(v[k]);
        if d[k] > 0.0 {
            t = t.min((lo + 1.0 - o_r[k]) / d[k]);
        } else if d[k] < 0.0 {
            t = t.min((lo - o_r[k]) / d[k]);
        }
    }
    t
}

/// The point (as a world ray parameter, in voxels) where the ray enters
/// voxel `v`, or, for a voxel the continuous ray only grazes, its point
/// nearest the voxel centre.
pub(super) fn entry_param(o_r: DVec3, d: DVec3, v: [u32; 3]) -> f64 {
    let lo = DVec3::from(v.map(f64::from));
    match slab(o_r, d, lo, lo + 1.0) {
        Some((t0, _)) => t0,
        None => (lo + 0.5 - o_r).dot(d),
    }
}

impl Tracer<'_> {
    /// The hit at voxel `v` with record `rec` for the paper's raw mode
    /// (no verification): the point where the ray entered the voxel, the
    /// stored normal.
    pub(super) fn discrete_hit(
        &self,
        ray: &Ray,
        o_r: DVec3,
        v: [u32; 3],
        rec: &VoxelRecord,
        tmin: f64,
    ) -> SurfaceHit {
        let t = (entry_param(o_r, ray.dir, v) * self.frame.voxel_size).max(tmin.max(0.0));
        SurfaceHit {
            voxel: v,
            rec: *rec,
            colour: rgb(rec.color),
            object: self.store.owner(rec),
            t,
            point: ray.at(t),
            normal: decode(rec),
            verified: false,
            smoothed: false,
        }
    }

    /// Verification at one opaque voxel `v` (plane index `index`, record
    /// `rec`) of the walk of `ray`: every object of the voxel not yet in
    /// `mail` is tested; an exact object by its first intersection with
    /// `t > tmin` anywhere on the ray before `best`'s (only such a one can
    /// replace it, and it is the object's first intersection past `tmin`
    /// when there is one), an object without exact geometry by the point
    /// where the ray enters this voxel (unless the acne rule `leave`
    /// ignores the voxel). The nearest is kept in `best`.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn test_voxel(
        &self,
        ray: &Ray,
        o_r: DVec3,
        v: [u32; 3],
        index: usize,
        rec: &VoxelRecord,
        tmin: f64,
        leave: Option<&LeavingSurface>,
        mail: &mut Mailbox,
        best: &mut Option<Candidate>,
    ) {
        let ids = self.store.objects(rec);
        let shared = ids.len() > 1;
        let vs = self.frame.voxel_size;
        for &id in ids {
            // A sphere the ray clearly misses is no candidate.
            if self.refused(id, ray, tmin) {
                continue;
            }
            let Some(obj) = usize::try_from(id).ok().and_then(|i| self.objects.get(i)) else {
                continue;
            };
            // A volume rendered directly is composited, never hit.
            if self.direct_volume(id).is_some() {
                continue;
            }
            let found = if obj.shape.is_exact() {
                if mail.tested(id) {
                    continue;
                }
                // Only a nearer hit can replace the candidate: the
                // intersection is sought before it (the same nearest root
                // when there is one there), so farther hits cost no normal.
                let tmax = best.as_ref().map_or(f64::INFINITY, |b| b.t);
                obj.shape
                    .intersect(ray, tmin, tmax)
                    .filter(|h| h.normal.is_finite() && h.t.is_finite())
                    .map(|h| (h.t, h.normal, true))
            } else if leave.is_some_and(|l| l.ignores(&self.store, index, rec)) {
                None
            } else {
                let t = (entry_param(o_r, ray.dir, v) * vs).max(tmin.max(0.0));
                Some((t, decode(rec), false))
            };
            if let Some((t, normal, exact)) = found
                && best.as_ref().is_none_or(|b| t < b.t)
            {
                *best = Some(Candidate {
                    t,
                    object: id,
                    normal,
                    voxel: v,
                    rec: *rec,
                    exact,
                    shared,
                });
            }
        }
    }

    /// The surface hit of an accepted candidate: its object's attributes
    /// (the voxel's record when the object owns the voxel, else the record
    /// of the nearest neighbouring voxel it owns, else its material's),
    /// its colour ([`Tracer::colour_of`]), the true point and normal.
    pub(super) fn candidate_hit(&self, ray: &Ray, c: &Candidate) -> SurfaceHit {
        let point = ray.at(c.t);
        let smooth = !c.exact
            && usize::try_from(c.object)
                .ok()
                .and_then(|i| self.objects.get(i))
                .is_some_and(|o| matches!(o.shape, Shape::Voxels { smooth: true }));
        let normal = smooth
            .then(|| self.smooth_normal(c.object, point))
            .flatten();
        let rec = self.attributes_of(c.object, c.voxel, &c.rec);
        SurfaceHit {
            voxel: c.voxel,
            rec,
            colour: self.colour_of(c, &rec),
            object: c.object,
            t: c.t,
            point,
            normal: normal.unwrap_or(c.normal),
            verified: c.exact,
            smoothed: normal.is_some(),
        }
    }

    /// The stored normals of object `id` interpolated at world point `p`:
    /// the object's voxels whose centres lie within 1.5 voxels of `p` on
    /// every axis, weighted by the product over the axes of the quadratic
    /// B-spline of the centre's offset (smooth, and zero at 1.5 voxels, so
    /// the interpolant does not jump as `p` moves); `None` where no voxel
    /// of the object is near, or the normals cancel. Volumes and CSG
    /// results, which have no exact normal, are shaded with it instead of
    /// one voxel's normal, so that their surfaces are not faceted.
    pub(super) fn smooth_normal(&self, id: u32, p: DVec3) -> Option<DVec3> {
        let q = self.frame.world_to_raster(p) - 0.5;
        let near = q.round();
        let dims = self.extent.dims();
        // The quadratic B-spline with support (−1.5, 1.5).
        let spline = |x: f64| {
            let x = x.abs();
            if x < 0.5 {
                0.75 - x * x
            } else if x < 1.5 {
                0.5 * (1.5 - x) * (1.5 - x)
            } else {
                0.0
            }
        };
        let mut sum = DVec3::ZERO;
        for dz in -1i32..=1 {
            for dy in -1i32..=1 {
                for dx in -1i32..=1 {
                    let c = near + DVec3::new(f64::from(dx), f64::from(dy), f64::from(dz));
                    let mut v = [0u32; 3];
                    let mut w = 1.0;
                    for k in 0..3 {
                        if !(c[k] >= 0.0 && c[k] < f64::from(dims[k])) {
                            w = 0.0;
                            break;
                        }
                        // In range: a whole number below the axis length.
                        v[k] = c[k] as u32;
                        w *= spline(q[k] - c[k]);
                    }
                    if w <= 0.0 {
                        continue;
                    }
                    let Some((_, cell)) = self.opaque_cell(v) else {
                        continue;
                    };
                    if let Some(rec) = self.store.get_hinted(v, cell)
                        && self.store.owner(rec) == id
                    {
                        sum += decode(rec) * w;
                    }
                }
            }
        }
        sum.try_normalize()
    }

    /// A record with object `id`'s attributes near voxel `v` (record
    /// `rec`): see [`Tracer::candidate_hit`]; of the neighbours it owns,
    /// the nearest ([`NEIGHBOURS_BY_DISTANCE`]); without one, `rec` with
    /// the object's material and that material's colour as an untextured
    /// object's records hold it. The neighbours are not searched where the
    /// records the object owns around it ([`Tracer::owned`]) say what the
    /// search would give: none, or only records whose material and colour
    /// are those, when they are all the shading reads.
    fn attributes_of(&self, id: u32, v: [u32; 3], rec: &VoxelRecord) -> VoxelRecord {
        if self.store.owner(rec) == id {
            return *rec;
        }
        let obj = usize::try_from(id).ok().and_then(|i| self.objects.get(i));
        let mut own = *rec;
        if let Some(obj) = obj {
            own.material = obj.material;
            if let Some(&c) = self.record_colours.get(usize::from(obj.material)) {
                own.color = c;
            }
        }
        let searched = match self.owned_around(id, v) {
            Some(Holds::Nothing) => false,
            Some(Holds::Plain) => !self.attributes_only,
            Some(Holds::Varied) | None => true,
        };
        if searched {
            for d in NEIGHBOURS_BY_DISTANCE {
                let (Some(x), Some(y), Some(z)) = (
                    v[0].checked_add_signed(d[0]),
                    v[1].checked_add_signed(d[1]),
                    v[2].checked_add_signed(d[2]),
                ) else {
                    continue;
                };
                let Some((_, c)) = self.opaque_cell([x, y, z]) else {
                    continue;
                };
                if let Some(n) = self.store.get_hinted([x, y, z], c)
                    && self.store.owner(n) == id
                {
                    return *n;
                }
            }
        }
        own
    }

    /// The colour candidate `c` with attributes `rec` is shaded with: for
    /// an object with exact geometry whose record holds its material's
    /// colour as an untextured object's records do, that colour itself
    /// (clamped to `[0, 1]` as the records' is), as the exact ray tracer
    /// shades it, whatever the raster; otherwise the record's 8-bit colour
    /// (a texture's, or a surface without exact geometry).
    fn colour_of(&self, c: &Candidate, rec: &VoxelRecord) -> DVec3 {
        let m = usize::from(rec.material);
        let plain = c.exact
            && self.record_colours.get(m) == Some(&rec.color)
            && usize::try_from(c.object)
                .ok()
                .and_then(|i| self.objects.get(i))
                .is_some_and(|o| o.material == rec.material);
        match self.materials.get(m) {
            Some(m) if plain => m.colour.clamp(DVec3::ZERO, DVec3::ONE),
            _ => rgb(rec.color),
        }
    }

    /// What the records object `id` owns hold around voxel `v`, when
    /// every neighbour of `v` lies in the box [`Tracer::owned`] keeps for
    /// it (found on first use).
    fn owned_around(&self, id: u32, v: [u32; 3]) -> Option<Holds> {
        let slot = usize::try_from(id).ok().and_then(|i| self.owned.get(i))?;
        let o = slot.get_or_init(|| self.owned_near(id)).as_ref()?;
        let dims = self.extent.dims();
        (0..3)
            .all(|a| {
                v[a].saturating_sub(1) >= o.lo[a]
                    && v[a].saturating_add(1).min(dims[a].saturating_sub(1)) < o.hi[a]
            })
            .then_some(o.holds)
    }

    /// [`Owned`] for object `id`: its bounds in voxels grown by
    /// [`OWNED_MARGIN`], and what the records it owns in the bricks
    /// meeting that box hold ([`Holds::Varied`] when those bricks hold more
    /// than [`OWNED_SCAN_LIMIT`] records: the search is then made as for a
    /// texture). `None` for an object without bounds.
    fn owned_near(&self, id: u32) -> Option<Owned> {
        let i = usize::try_from(id).ok()?;
        let obj = self.objects.get(i)?;
        let b = obj.shape.bounds()?;
        let (lo_w, hi_w) = (
            self.frame.world_to_raster(b.min),
            self.frame.world_to_raster(b.max),
        );
        if !(lo_w.is_finite() && hi_w.is_finite()) {
            return None;
        }
        let dims = self.extent.dims();
        // Clamped to the raster, so the conversions are exact.
        let lo: [u32; 3] = std::array::from_fn(|a| {
            (lo_w[a].floor() - OWNED_MARGIN).clamp(0.0, f64::from(dims[a])) as u32
        });
        let hi: [u32; 3] = std::array::from_fn(|a| {
            (hi_w[a].floor() + OWNED_MARGIN + 1.0).clamp(0.0, f64::from(dims[a])) as u32
        });
        let plain = (
            obj.material,
            self.record_colours.get(usize::from(obj.material)).copied(),
        );
        let mut holds = Holds::Nothing;
        let mut scanned = 0usize;
        if (0..3).all(|a| lo[a] < hi[a]) {
            let [nx, ny, _] = brick_dims(self.extent).map(|n| n as usize);
            let brick = |v: u32| (v >> BRICK_BITS) as usize;
            let records = self.store.records();
            'bricks: for bz in brick(lo[2])..=brick(hi[2] - 1) {
                for by in brick(lo[1])..=brick(hi[1] - 1) {
                    for bx in brick(lo[0])..=brick(hi[0] - 1) {
                        let k = ny
                            .checked_mul(bz)
                            .and_then(|k| k.checked_add(by))
                            .and_then(|k| k.checked_mul(nx))
                            .and_then(|k| k.checked_add(bx));
                        let (Some(&from), Some(&to)) = (
                            k.and_then(|k| self.directory.get(k)),
                            k.and_then(|k| self.directory.get(k.checked_add(1)?)),
                        ) else {
                            continue;
                        };
                        let span = records.get(from as usize..to as usize).unwrap_or(&[]);
                        scanned = scanned.saturating_add(span.len());
                        if scanned > OWNED_SCAN_LIMIT {
                            // Too large to be worth it: searched as before.
                            holds = Holds::Varied;
                            break 'bricks;
                        }
                        for r in span.iter().filter(|r| self.store.owner(r) == id) {
                            holds = if (r.material, Some(r.color)) == plain {
                                Holds::Plain
                            } else {
                                Holds::Varied
                            };
                            if holds == Holds::Varied {
                                break 'bricks;
                            }
                        }
                    }
                }
            }
        }
        Some(Owned { lo, hi, holds })
    }

    pub(super) fn accept(&self, ray: &Ray, c: &Candidate, stats: &mut RayStats) -> SurfaceHit {
        if c.shared {
            stats.shared_hits += 1;
        }
        self.candidate_hit(ray, c)
    }
}

#[cfg(test)]
mod tests {
    use super::{MAILBOX, Mailbox};
    use std::collections::HashSet;

    #[test]
    fn mailbox_never_claims_an_untested_object() {
        // Ids spread over a few neighbourhoods and colliding slots, in a
        // fixed pseudo-random order.
        let mut mail = Mailbox::default();
        let mut seen = HashSet::new();
        let mut x = 0x2545_f491_u32;
        for _ in 0..20_000 {
            x ^= x << 13;
            x ^= x >> 17;
            x ^= x << 5;
            let id = (x % 700).wrapping_mul(if x & 1 == 0 { 1 } else { MAILBOX as u32 + 1 });
            let claimed = mail.tested(id);
            assert!(!claimed || seen.contains(&id), "{id} claimed untested");
            seen.insert(id);
        }
        assert!(!Mailbox::default().tested(0));
        assert!(!Mailbox::default().tested(u32::MAX));
    }

    #[test]
    fn mailbox_keeps_a_long_list_of_neighbouring_ids() {
        // A ray crossing voxels that share one long object list tests each
        // object once.
        let mut mail = Mailbox::default();
        let ids = 1000..1000 + MAILBOX as u32;
        assert!(ids.clone().all(|id| !mail.tested(id)));
        for _ in 0..3 {
            assert!(ids.clone().all(|id| mail.tested(id)));
        }
    }
}
