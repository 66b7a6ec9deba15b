//! The recursive discrete ray tracer (the paper's ray tracing phase).
//!
//! A ray is traced by stepping its 3D discrete line through the raster
//! ([`DiscreteRay`], clipped to the raster box: the paper's two endpoints)
//! until the first non-transparent voxel: the hit. Its record gives the
//! object, colour, stored normal, the precomputed ambient + diffuse
//! illumination and two visibility bits per light. The colour is then
//!
//! ```text
//! illum  +  Σ lights visible from the side seen   I·L·Ks·max(R·V, 0)^Shine
//!        +  Σ lights "visible through translucent material"   att·I·L·(Kd·C·(N·L) + Ks·(R·V)^Shine)
//!        +  Ks·reflected  +  T·refracted
//! ```
//!
//! as `embree_nff` shades (see [`crate::shade`]): `N` the stored normal
//! turned towards the viewer (two-sided shading), `R` the reflection of the
//! light direction `L`, `V` towards the eye. Shadow rays are fired at render
//! time only for lights whose bits say *translucent*; `att` multiplies the
//! transmittance `T` of each translucent object the shadow ray passes
//! (each object once). With [`TraceOptions::exact_shadows`] (and
//! verification), every verified hit fires a 6-connected shadow ray to each
//! light it faces and counts only objects the continuous segment really
//! intersects (voxels of objects without exact geometry count as they
//! are): exact shadow edges, at the cost of those rays. The reflected ray
//! (when `Ks > 0`) and the refracted ray (when `T > 0`: Snell's law with
//! the material's index of refraction,
//! total internal reflection falling back to the mirror direction) are
//! spawned from the stored normal and traced recursively to
//! [`TraceOptions::depth`] (the eye ray is depth 1). A ray that leaves the
//! raster takes the background colour.
//!
//! `illum` holds the lit side the stored normal faces. When the other
//! side of an open surface (a polygon, an open cone) is seen, or the inside
//! of a closed one, the ambient term and the diffuse terms of the lights
//! whose bits say that side sees them are computed here instead.
//!
//! # Intersection verification
//! With [`TraceOptions::verify`], a discrete hit is checked by intersecting
//! the continuous world ray with the hit voxel's object ([`WorldObject`],
//! indexed by the record's object id: the paper's object table). The
//! first intersection from the voxel on is the hit when it lies near the
//! voxel: within the voxel's box grown by one voxel on every side (a
//! voxelized surface layer is at most √3 voxels thick). When the ray does
//! not meet the object at all the hit is *false* (the paper's term): it is
//! counted and the discrete walk resumes after the voxel. When it meets
//! the object only farther on (a ray grazing a surface's voxel layer, whose
//! intersection lies many voxels along it) the walk also resumes, to stop
//! at the voxels near the intersection; accepting the far intersection at
//! once could skip a nearer object. Before either, the objects that own
//! the voxel's 26 neighbours are tried in the same window, and the nearest
//! intersection among them is the hit: voxels are atomic, one object each,
//! so where surfaces meet (the shared edges of a mesh, a small sphere on a
//! big one) the object the ray truly meets here may own only the voxel
//! next door; without this a ray would pass through the seam (a dark dot
//! on a teapot). With a hit, the true point and the true normal are used, and the diffuse terms are recomputed with the true
//! normal for the lights the bits say are visible (the precomputed `illum`
//! was sampled at the voxel centre).
//!
//! # No acne
//! A secondary ray starts on the surface it leaves: at the point where the
//! incoming ray entered the hit voxel, or at the true intersection under
//! verification. The surface's voxel layer is up to two voxels thick there,
//! so the ray would hit its own surface at once. The tracer applies the
//! light pass's rule ([`LeavingSurface`], see [`rrt_core::light`]): a voxel
//! met by a ray leaving voxel `c₀` towards the side of unit normal `N₀` is
//! ignored when its centre lies at most two voxels above `c₀`'s tangent
//! plane (`(c − c₀)·N₀ ≤ 2`) *and* it belongs to the same object or to a
//! surface oriented within 60° of this one. `N₀` is the side the ray goes
//! to: the viewer's side for reflections and the render-time shadow rays,
//! the other side for a refracted ray entering the object. Concave objects
//! still reflect and shadow themselves beyond the two-voxel slab (the far
//! side of a torus hole, a teapot's body seen in its spout); a refracted
//! ray still meets the far wall of a sphere. Under verification the exact
//! intersection with the object left additionally requires `t` above
//! 1/1000 voxel, so the surface point itself is never its own next hit.
//!
//! # Packets
//! [`Tracer::trace_block`] traces eight primary rays (a 4×2 pixel block)
//! in two stages: first every ray is walked to its first non-transparent
//! voxel, by a [`RayPacket8`] stepping the eight lanes together (or by the
//! scalar walk, [`TraceOptions::packets`]); then each ray's hit is resolved
//! (verification and resumption, shading, secondary rays) by the scalar
//! code, which resumes the very `DiscreteRay` the packet left in its lane.
//! The packet is bit-identical to the scalar walk, so the image does not
//! depend on the choice.
//!
//! # Empty-space skipping
//! The scalar walks use the plane's proximity distances
//! ([`rrt_core::proximity::distance_field`], computed by the builder):
//! where the nearest non-transparent voxel is `d ≥ 5` voxels away, a
//! 26-run takes `d − 1` steps at once, landing exactly where single steps
//! would. Far from surfaces they read the scene's line level instead of the
//! plane ([`rrt_core::raster::Raster::with_lines`]: one stand-in cell per
//! 64 plane cells, small enough to stay in cache). [`RayStats::steps`]
//! counts voxels visited, a jump as one.

#![deny(missing_docs)]
// `!(x < y)` is deliberate: it is true for NaN, which must be refused too.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

use glam::DVec3;
use rrt_core::discrete_ray::{Connectivity, DiscreteRay, ORIGIN_LIMIT, WalkEnd};
use rrt_core::fixed::VOXEL;
use rrt_core::light::{LeavingSurface, LightParams};
use rrt_core::packet::RayPacket8;
use rrt_core::raster::{Extent, Raster, cell};
use rrt_core::store::RecordStore;
use rrt_core::voxel::{LightVisibility, VoxelRecord};
use rrt_core::voxelize::NORMAL_ONE;

use crate::frame::{RasterFrame, round_to_i64, unit_to_fixed};
use crate::scene::Material;
use crate::shade;
use crate::voxelize::VoxelScene;
use crate::voxelize::{WorldLight, WorldObject};
use crate::world::Ray;

/// Rays per primary block: 4 × 2 pixels, the lanes of `RayPacket8`.
pub const BLOCK: usize = 8;
/// Width of a primary block in pixels.
pub const BLOCK_W: u32 = 4;
/// Height of a primary block in pixels.
pub const BLOCK_H: u32 = 2;

/// How rays are traced.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TraceOptions {
    /// Connectivity of the primary and secondary rays.
    pub connectivity: Connectivity,
    /// Maximum depth of the ray tree; the eye ray is depth 1.
    pub depth: u32,
    /// Intersection verification.
    pub verify: bool,
    /// The acne rule's slab and angle, and the connectivity of render-time
    /// shadow rays (those of the light pass by default).
    pub light: LightParams,
    /// Walk primary rays eight at a time in a [`RayPacket8`] instead of one
    /// by one with empty-space skipping. Both give the same image; the
    /// packet does not skip, and on balls4 (raster 2048, 512², one thread)
    /// the skipping scalar walk rendered in 0.37 s against the packets'
    /// 0.48 s (one run, medians of three), so it is the default.
    pub packets: bool,
    /// Exact shadows for verified hits (a quality option beyond the paper,
    /// which uses the precomputed light bits): from each verified hit a
    /// render-time shadow ray walks to every light the surface faces, and
    /// each object whose voxels it meets is intersected exactly with the
    /// continuous shadow ray; only a true intersection shadows. Shadow
    /// edges then follow the geometry instead of the receiving voxels.
    /// Needs `verify` (unverified hits keep the light bits).
    pub exact_shadows: bool,
}

impl Default for TraceOptions {
    fn default() -> Self {
        Self {
            connectivity: Connectivity::Adaptive,
            depth: 3,
            verify: false,
            light: LightParams::default(),
            packets: false,
            exact_shadows: false,
        }
    }
}

/// Counts of one render.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RayStats {
    /// Eye rays.
    pub primary: u64,
    /// Reflected rays.
    pub reflected: u64,
    /// Refracted (or totally reflected) transmitted rays.
    pub refracted: u64,
    /// Render-time shadow rays (lights seen through translucent material).
    pub shadow: u64,
    /// Voxels visited by all rays (an empty-space jump counts as one).
    pub steps: u64,
    /// Rays that ended on a surface.
    pub hits: u64,
    /// Discrete hits that verification rejected: the continuous ray does
    /// not meet the voxel's object (the paper's false hits).
    pub false_hits: u64,
    /// Discrete hits whose own object failed verification but an object
    /// owning a neighbouring voxel passed it (see [`verify`]'s use in the
    /// module docs).
    pub neighbour_hits: u64,
    /// Rays (of any kind but shadow) that met at least one false hit.
    pub false_hit_rays: u64,
    /// Discrete hits whose object the continuous ray meets only farther
    /// on: the walk went on to the voxel of the intersection.
    pub deferred: u64,
    /// Opaque cells without a record (a damaged raster), stepped over.
    pub missing: u64,
}

impl RayStats {
    /// Adds `o` to `self`.
    pub fn add(&mut self, o: &Self) {
        self.primary += o.primary;
        self.reflected += o.reflected;
        self.refracted += o.refracted;
        self.shadow += o.shadow;
        self.steps += o.steps;
        self.hits += o.hits;
        self.false_hits += o.false_hits;
        self.deferred += o.deferred;
        self.neighbour_hits += o.neighbour_hits;
        self.false_hit_rays += o.false_hit_rays;
        self.missing += o.missing;
    }

    /// All rays traced.
    #[must_use]
    pub fn rays(&self) -> u64 {
        self.primary + self.reflected + self.refracted + self.shadow
    }
}

/// A surface hit.
#[derive(Clone, Copy, Debug)]
struct SurfaceHit {
    voxel: [u32; 3],
    rec: VoxelRecord,
    /// World point used for shading and secondary rays.
    point: DVec3,
    /// Unit normal (stored, or true under verification), not turned.
    normal: DVec3,
    verified: bool,
}

/// The first stage of a ray: its discrete walk to the first
/// non-transparent voxel (`None`: the ray misses the raster).
#[derive(Clone, Copy, Debug)]
pub struct FirstWalk {
    ray: Option<DiscreteRay>,
    end: WalkEnd,
    steps: u64,
    /// The record of the hit voxel when the walk's hit test already
    /// fetched it (index, record), so that resolving does not look it up
    /// again.
    found: Option<(usize, VoxelRecord)>,
}

/// The slab intersection of the line `o + t·d` with the box `[lo, hi]`:
/// `(t_enter, t_exit)`, or `None` if the line misses it.
fn slab(o: DVec3, d: DVec3, lo: DVec3, hi: DVec3) -> Option<(f64, f64)> {
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

/// `x` rounded to the nearest integer, halves away from zero, saturating:
/// `f64::round` is a library call on the baseline x86-64 target, and this
/// runs twice per axis for every ray. (The fixed-point ray is whatever this
/// gives: any deterministic rounding would do.)
#[inline]
fn round_to_int(x: f64) -> i64 {
    round_to_i64(x)
}

/// The unit vector of a stored octahedral normal (unfolded in integers,
/// normalized in floating point).
fn decode(rec: &VoxelRecord) -> DVec3 {
    let n = rrt_core::voxel::unfold(rec.normal);
    DVec3::new(n[0] as f64, n[1] as f64, n[2] as f64).normalize_or(DVec3::Z)
}

fn rgb(c: [u8; 3]) -> DVec3 {
    DVec3::new(f64::from(c[0]), f64::from(c[1]), f64::from(c[2])) / 255.0
}

/// The outcome of verifying one discrete hit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Verdict {
    /// The continuous ray meets the object near the voxel: the true hit.
    Hit(crate::world::Hit),
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

/// The renderer over one voxelized scene.
#[derive(Clone, Debug)]
pub struct Tracer<'s> {
    raster: Raster<'s>,
    store: RecordStore<'s>,
    extent: Extent,
    frame: RasterFrame,
    objects: &'s [WorldObject],
    materials: &'s [Material],
    lights: &'s [WorldLight],
    lights_fx: Vec<Option<[i64; 3]>>,
    background: DVec3,
    intensity: f64,
    opts: TraceOptions,
}

/// Why a tracer cannot be set up.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum TraceError {
    /// The raster or its records are inconsistent.
    #[error("raster: {0}")]
    Raster(String),
    /// The surfaces are too thin for the rays asked for.
    #[error(
        "the raster was voxelized for 6-connected or adaptive rays; 26-connected rays would pass through its surfaces (voxelize again with --connectivity twenty-six)"
    )]
    Separation,
    /// A depth of 0.
    #[error("depth: expected at least 1 (the eye ray), found 0")]
    Depth,
}

impl<'s> Tracer<'s> {
    /// A tracer over `scene`.
    ///
    /// # Errors
    /// [`TraceError`]: an inconsistent raster, 26-connected rays through
    /// surfaces voxelized for 6-connected ones, depth 0.
    pub fn new(scene: &'s VoxelScene, opts: TraceOptions) -> Result<Self, TraceError> {
        if opts.depth == 0 {
            return Err(TraceError::Depth);
        }
        if opts.connectivity == Connectivity::TwentySix
            && scene.separation != rrt_core::voxelize::Separation::TwentySix
        {
            return Err(TraceError::Separation);
        }
        let raster = scene
            .raster()
            .map_err(|e| TraceError::Raster(e.to_string()))?;
        let store = scene
            .store()
            .map_err(|e| TraceError::Raster(e.to_string()))?;
        let lights_fx = scene
            .lights
            .iter()
            .map(|l| scene.frame.to_fixed(l.position))
            .collect();
        Ok(Self {
            raster,
            store,
            extent: scene.frame.extent,
            frame: scene.frame,
            objects: &scene.objects,
            materials: &scene.materials,
            lights: &scene.lights,
            lights_fx,
            background: scene.background,
            intensity: scene.intensity(),
            opts,
        })
    }

    /// The options in use.
    #[must_use]
    pub const fn options(&self) -> &TraceOptions {
        &self.opts
    }

    /// The discrete ray of a world ray (unit direction), clipped to the
    /// raster; `None` if it misses the raster.
    fn discrete(&self, ray: &Ray) -> Option<DiscreteRay> {
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
            return FirstWalk {
                ray: None,
                end: WalkEnd::Exit,
                steps: 0,
                found: None,
            };
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

    /// Resolves a ray's walk into its surface hit: checks the hit voxel
    /// (record, verification) and resumes the walk past false hits.
    fn resolve(
        &self,
        ray: &Ray,
        walk: &mut FirstWalk,
        tmin: f64,
        leave: Option<&LeavingSurface>,
        stats: &mut RayStats,
    ) -> Option<SurfaceHit> {
        let before = stats.false_hits;
        let hit = self.resolve_walk(ray, walk, tmin, leave, stats);
        if stats.false_hits > before {
            stats.false_hit_rays += 1;
        }
        hit
    }

    fn resolve_walk(
        &self,
        ray: &Ray,
        walk: &mut FirstWalk,
        tmin: f64,
        leave: Option<&LeavingSurface>,
        stats: &mut RayStats,
    ) -> Option<SurfaceHit> {
        stats.steps += walk.steps;
        // Resumed in place: a discrete ray is a few hundred bytes.
        let dray = walk.ray.as_mut()?;
        let mut end = walk.end;
        let o_r = self.frame.world_to_raster(ray.origin);
        let vs = self.frame.voxel_size;
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
            let accepted = match &rec {
                None => {
                    stats.missing += 1;
                    None
                }
                Some(rec) => self.check_hit(ray, o_r, vs, h.voxel, rec, tmin, leave, stats),
            };
            if accepted.is_some() {
                return accepted;
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

    /// The hit at voxel `v` with record `rec`, or `None` for a false hit.
    #[allow(clippy::too_many_arguments)]
    fn check_hit(
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
    fn verify_neighbours(
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

    /// Traces one ray (unit direction) at `depth` and returns its colour.
    fn trace(
        &self,
        ray: &Ray,
        depth: u32,
        leave: Option<&LeavingSurface>,
        stats: &mut RayStats,
    ) -> DVec3 {
        let mut walk = match leave {
            None => self.first_walk(ray),
            Some(rule) => self.secondary_walk(ray, rule, stats),
        };
        let tmin = if leave.is_some() {
            self.leaving_tmin()
        } else {
            0.0
        };
        match self.resolve(ray, &mut walk, tmin, leave, stats) {
            None => self.background,
            Some(h) => {
                stats.hits += 1;
                self.shade(ray, &h, depth, stats)
            }
        }
    }

    fn secondary_walk(&self, ray: &Ray, rule: &LeavingSurface, stats: &mut RayStats) -> FirstWalk {
        let Some(mut dray) = self.discrete(ray) else {
            return FirstWalk {
                ray: None,
                end: WalkEnd::Exit,
                steps: 0,
                found: None,
            };
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

    /// The smallest ray parameter at which an exact intersection counts
    /// for a ray leaving a surface (a thousandth of a voxel): it must not
    /// verify onto, or be shadowed by, the point it leaves.
    fn leaving_tmin(&self) -> f64 {
        1e-3 * self.frame.voxel_size
    }

    /// The acne rule for a ray leaving hit `h` towards the side `side`.
    fn leaving(&self, h: &SurfaceHit, side: DVec3) -> LeavingSurface {
        let side = unit_to_fixed(side).unwrap_or([0, 0, NORMAL_ONE]);
        LeavingSurface::new(self.extent, h.voxel, side, &h.rec, &self.opts.light)
    }

    /// The colour of hit `h` of `ray` at `depth` (module docs).
    fn shade(&self, ray: &Ray, h: &SurfaceHit, depth: u32, stats: &mut RayStats) -> DVec3 {
        let m = self
            .materials
            .get(usize::from(h.rec.material))
            .unwrap_or(&Material::DEFAULT);
        let d = ray.dir;
        let front = h.normal.dot(d) <= 0.0;
        let n = if front { h.normal } else { -h.normal };
        let c = rgb(h.rec.color);
        let i = self.intensity;
        // The precomputed illumination is the stored normal's side, at the
        // voxel centre: used as it is for the basic algorithm on that side.
        let use_illum = front && !h.verified;
        let mut local = if use_illum {
            rgb(h.rec.illum)
        } else {
            c * (i * m.kd)
        };
        let p = h.point;
        for (k, light) in self.lights.iter().enumerate() {
            let to = light.position - p;
            let dist = to.length();
            if !(dist > 0.0) {
                continue;
            }
            let l = to / dist;
            let ndl = n.dot(l);
            if ndl <= 0.0 {
                continue;
            }
            let vis = h.rec.light(k);
            let exact = self.opts.exact_shadows && h.verified;
            let att = match vis {
                _ if exact => {
                    stats.shadow += 1;
                    self.shadow(h, n, k, Some((l, dist)), stats)
                }
                LightVisibility::Visible => 1.0,
                LightVisibility::Translucent => {
                    stats.shadow += 1;
                    self.shadow(h, n, k, None, stats)
                }
                LightVisibility::Occluded | LightVisibility::Reserved => 0.0,
            };
            if att <= 0.0 {
                continue;
            }
            let lc = light.colour * (i * att);
            if !use_illum || vis == LightVisibility::Translucent {
                local += lc * c * (m.kd * ndl);
            }
            if m.ks > 0.0 {
                let r = n * (2.0 * ndl) - l;
                let rv = -r.dot(d);
                if rv > 0.0 {
                    local += lc * (m.ks * rv.powf(m.shine));
                }
            }
        }
        let mut reflected = DVec3::ZERO;
        let mut refracted = DVec3::ZERO;
        if depth < self.opts.depth {
            if m.ks > 0.0 {
                stats.reflected += 1;
                let dir = shade::reflect(d, n).normalize_or(n);
                let rule = self.leaving(h, n);
                reflected = self.trace(&Ray::new(p, dir), depth + 1, Some(&rule), stats);
            }
            if m.transmittance > 0.0 {
                stats.refracted += 1;
                let dir = shade::refract(d, h.normal, m.ior).dir();
                let side = if dir.dot(n) > 0.0 { n } else { -n };
                let rule = self.leaving(h, side);
                refracted = self.trace(&Ray::new(p, dir), depth + 1, Some(&rule), stats);
            }
        }
        shade::combine(m, local, reflected, refracted)
    }

    /// A render-time shadow ray from hit `h` (seen side `n`) to light `k`:
    /// the product of the transmittances of the translucent objects in
    /// between (each object once), 0 if an opaque voxel blocks.
    ///
    /// `exact` (unit direction and distance to the light) makes it an
    /// exact shadow ray ([`TraceOptions::exact_shadows`]): a 6-connected
    /// walk, which meets every voxel the continuous segment passes
    /// through, and a voxel counts only if the continuous segment
    /// intersects its object (each object tested once); voxels of objects
    /// without exact geometry (volumes, voxel models) count as they are.
    fn shadow(
        &self,
        h: &SurfaceHit,
        n: DVec3,
        k: usize,
        exact: Option<(DVec3, f64)>,
        stats: &mut RayStats,
    ) -> f64 {
        let (Some(Some(light)), Some(p)) = (self.lights_fx.get(k), self.frame.to_fixed(h.point))
        else {
            return 0.0;
        };
        let delta = [0, 1, 2].map(|a| i128::from(light[a]) - i128::from(p[a]));
        let span = delta.iter().map(|v| v.unsigned_abs()).max().unwrap_or(0);
        let ray = if span <= u128::from(i32::MAX.unsigned_abs()) {
            DiscreteRay::segment(self.extent, p, *light)
        } else {
            // Scale the direction into i32; the walk ends where the ray
            // leaves the raster (a light inside a raster wider than 2^15
            // voxels is treated as if it were outside).
            let shift = 128u32
                .saturating_sub(span.leading_zeros())
                .saturating_sub(31);
            let dir = delta.map(|v| i32::try_from(v >> shift).unwrap_or(0));
            DiscreteRay::new(self.extent, p, dir)
        };
        let Ok(Some(mut dray)) = ray else {
            return 1.0;
        };
        let rule = self.leaving(h, n);
        let store = self.store;
        let extent = self.extent;
        let materials = self.materials;
        let mut att = 1.0;
        let mut seen: Vec<u32> = Vec::new();
        // Objects the exact segment was found not to intersect.
        let mut clear: Vec<u32> = Vec::new();
        let segment = exact.map(|(l, dist)| (Ray::new(h.point, l), dist));
        let tmin = self.leaving_tmin();
        let objects = self.objects;
        let mode = if exact.is_some() {
            Connectivity::Six
        } else {
            self.opts.light.mode
        };
        let mut missing = 0u64;
        let end = dray
            .walk_skipping(&self.raster, mode, u32::MAX, |index, c| {
                let Some(b) = surface_voxel(&store, extent, Some(&rule), index, c, &mut missing)
                else {
                    return false;
                };
                if let Some((ray, dist)) = &segment
                    && let Some(obj) = usize::try_from(b.object)
                        .ok()
                        .and_then(|i| objects.get(i))
                        .filter(|o| o.shape.is_exact())
                {
                    if seen.contains(&b.object) || clear.contains(&b.object) {
                        return false;
                    }
                    if obj.shape.intersect(ray, tmin, *dist).is_none() {
                        clear.push(b.object);
                        return false;
                    }
                }
                let t = materials
                    .get(usize::from(b.material))
                    .map_or(0.0, |m| m.transmittance);
                if t > 0.0 {
                    if !seen.contains(&b.object) {
                        seen.push(b.object);
                        att *= t;
                    }
                    return false;
                }
                true
            })
            .unwrap_or(WalkEnd::Exit);
        stats.steps += u64::from(dray.steps());
        stats.missing += missing;
        if end == WalkEnd::Hit { 0.0 } else { att }
    }

    /// Traces up to eight primary rays (a 4×2 pixel block; `None` lanes lie
    /// outside the image) and returns their colours (black for `None`).
    /// Stage one walks every ray to its first non-transparent voxel; stage
    /// two resolves and shades each (module docs, *For packets*).
    pub fn trace_block(&self, rays: &[Option<Ray>; BLOCK], stats: &mut RayStats) -> [DVec3; BLOCK] {
        let mut out = [DVec3::ZERO; BLOCK];
        if self.opts.packets {
            let mut walks = self.first_walks_packet(rays);
            for ((o, r), w) in out.iter_mut().zip(rays).zip(walks.iter_mut()) {
                if let (Some(r), Some(w)) = (r, w.as_mut()) {
                    *o = self.primary(r, w, stats);
                }
            }
        } else {
            // One lane at a time: no array of walks to move around (a
            // first walk does not touch the counts, so the order is the
            // packet path's).
            for (o, r) in out.iter_mut().zip(rays) {
                if let Some(r) = r {
                    let mut w = self.first_walk(r);
                    *o = self.primary(r, &mut w, stats);
                }
            }
        }
        out
    }

    /// Stage two of a primary ray: resolve its walk and shade the hit.
    fn primary(&self, r: &Ray, w: &mut FirstWalk, stats: &mut RayStats) -> DVec3 {
        stats.primary += 1;
        match self.resolve(r, w, 0.0, None, stats) {
            None => self.background,
            Some(h) => {
                stats.hits += 1;
                self.shade(r, &h, 1, stats)
            }
        }
    }

    /// Stage one for eight rays at once: a [`RayPacket8`] walks every lane
    /// to its first non-transparent voxel; each lane's ray is left exactly
    /// as the scalar [`Tracer::first_walk`] leaves it.
    fn first_walks_packet(&self, rays: &[Option<Ray>; BLOCK]) -> [Option<FirstWalk>; BLOCK] {
        let lanes: [Option<DiscreteRay>; BLOCK] =
            std::array::from_fn(|l| rays[l].as_ref().and_then(|r| self.discrete(r)));
        let hits = RayPacket8::from_rays(self.extent, lanes)
            .ok()
            .and_then(|mut p| {
                let hits = p.first_hit(&self.raster, self.opts.connectivity).ok()?;
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

    /// Traces one primary ray (unit direction) and returns its colour.
    pub fn trace_primary(&self, ray: &Ray, stats: &mut RayStats) -> DVec3 {
        stats.primary += 1;
        self.trace(ray, 1, None, stats)
    }
}

/// The hit test of a secondary walk ([`surface_voxel`]); a hit leaves its
/// index and record in `found`.
fn hit_test(
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
fn surface_voxel<'s>(
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
        .is_none_or(|l| !l.ignores_voxel(v, rec))
        .then_some(rec)
}
