//! Shading a hit: the precomputed illumination or the local light of the
//! lights its bits say are visible, render-time shadow rays through
//! translucent objects (or exact shadow rays), and the reflected and
//! refracted rays, which leave the surface by the acne rule (module docs
//! of [`crate::trace`]).

use std::sync::atomic::Ordering;

use glam::DVec3;
use rrt_core::discrete_ray::{Connectivity, DiscreteRay, WalkEnd};
use rrt_core::geometry::Triangle as FixedTriangle;
use rrt_core::light::{LeavingSurface, classify_voxel};
use rrt_core::object_table::Shape as FixedShape;
use rrt_core::raster::cell;
use rrt_core::voxel::{LightVisibility, VoxelRecord};
use rrt_core::voxelize::NORMAL_ONE;

use super::verify::Mailbox;
use super::walk::surface_voxel;
use super::{Classification, RayStats, SurfaceHit, Tracer, rgb, shading};
use crate::frame::unit_to_fixed;
use crate::scene::Material;
use crate::shape::{Shape, Surface};
use crate::world::Ray;

impl Tracer<'_> {
    /// Where a ray leaving hit `h` towards the side `side` (a unit normal)
    /// starts, and the smallest ray parameter at which an exact
    /// intersection counts for it: it must not verify onto, or be shadowed
    /// by, the point it leaves. From a verified hit, the point
    /// [`surface_offset`](super::surface_offset) off the surface towards
    /// `side`, and any `t > 0` (as `embree_nff`); from a discrete hit, the
    /// hit point and a thousandth of a voxel.
    pub(super) fn leaving_point(&self, h: &SurfaceHit, side: DVec3) -> (DVec3, f64) {
        if h.verified {
            (h.point + side * self.offset_at(h), 0.0)
        } else {
            (h.point, 1e-3 * self.frame.voxel_size)
        }
    }

    /// How far rays leaving verified hit `h` start off the surface: the
    /// scene's [`surface_offset`](super::surface_offset), but no more than
    /// a tenth of the smallest object's size, nor less than 10⁻¹² of the
    /// hit point's largest coordinate (module docs, *No acne*).
    pub(super) fn offset_at(&self, h: &SurfaceHit) -> f64 {
        self.least_offset
            .max(1e-12 * h.point.abs().max_element())
            .min(self.offset)
    }

    /// The acne rule for a ray leaving hit `h` towards the side `side`.
    pub(super) fn leaving(&self, h: &SurfaceHit, side: DVec3) -> LeavingSurface {
        let side = unit_to_fixed(side).unwrap_or([0, 0, NORMAL_ONE]);
        LeavingSurface::new(&self.store, h.voxel, side, &h.rec, &self.opts.light)
    }

    /// The colour of hit `h` of `ray` at `depth` of the ray tree, with
    /// `weight` in the pixel (module docs).
    pub(super) fn shade(
        &self,
        ray: &Ray,
        h: &SurfaceHit,
        (depth, weight): (u32, f64),
        stats: &mut RayStats,
    ) -> DVec3 {
        let m = self
            .materials
            .get(usize::from(h.rec.material))
            .unwrap_or(&Material::DEFAULT);
        let d = ray.dir;
        let front = h.normal.dot(d) <= 0.0;
        let n = if front { h.normal } else { -h.normal };
        let c = h.colour;
        let i = self.intensity;
        // The precomputed illumination is the stored normal's side, at the
        // voxel centre: used as it is for the basic algorithm on that side.
        let use_illum = front && !h.verified && !h.smoothed;
        let mut local = if use_illum {
            rgb(h.rec.illum)
        } else {
            c * (i * m.kd)
        };
        let p = h.point;
        // Shadow and reflected rays leave towards the viewer's side.
        let (origin, tmin) = self.leaving_point(h, n);
        // The voxel holding `origin`, looked up for the first light that
        // asks the shadow classification.
        let mut origin_voxel = None;
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
            let exact = self.opts.mode.exact_shadows() && h.verified;
            let att = match vis {
                _ if exact => self.exact_light(h, n, origin, &mut origin_voxel, k, stats),
                LightVisibility::Visible => 1.0,
                LightVisibility::Translucent => {
                    stats.shadow += 1;
                    self.shadow(h, n, k, stats)
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
            // Whether a ray of weight `w` is traced, counted either way.
            let traced = |w: f64, count: &mut u64, pruned: &mut u64| {
                let heavy = w >= self.opts.min_weight;
                *if heavy { count } else { pruned } += 1;
                heavy
            };
            let w = weight * m.ks;
            if m.ks > 0.0 && traced(w, &mut stats.reflected, &mut stats.pruned) {
                let dir = shading::reflect(d, n).normalize_or(n);
                let rule = self.leaving(h, n);
                let r = Ray::new(origin, dir);
                reflected = self.trace(&r, (depth + 1, w), Some(&rule), tmin, stats);
            }
            let w = weight * m.transmittance;
            if m.transmittance > 0.0 && traced(w, &mut stats.refracted, &mut stats.pruned) {
                let dir = shading::refract(d, h.normal, m.ior).dir();
                let side = if dir.dot(n) > 0.0 { n } else { -n };
                let rule = self.leaving(h, side);
                let (from, tmin) = self.leaving_point(h, side);
                let r = Ray::new(from, dir);
                refracted = self.trace(&r, (depth + 1, w), Some(&rule), tmin, stats);
            }
        }
        shading::combine(m, local, reflected, refracted)
    }

    /// The discrete segment from `from` to light `k`, or `None` when
    /// there is none (the light or the point outside the fixed-point
    /// range, or a segment outside the raster: nothing in between).
    fn light_segment(&self, from: DVec3, k: usize) -> Option<Option<DiscreteRay>> {
        let (Some(Some(light)), Some(p)) = (self.lights_fx.get(k), self.frame.to_fixed(from))
        else {
            return None;
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
        Some(ray.ok().flatten())
    }

    /// A render-time shadow ray from hit `h` (seen side `n`) to light `k`
    /// (the paper's, for lights seen through translucent material): the
    /// product of the transmittances of the translucent objects in between
    /// (each object once), 0 if an opaque voxel blocks.
    pub(super) fn shadow(&self, h: &SurfaceHit, n: DVec3, k: usize, stats: &mut RayStats) -> f64 {
        let Some(ray) = self.light_segment(h.point, k) else {
            return 0.0;
        };
        let Some(mut dray) = ray else {
            return 1.0;
        };
        let rule = self.leaving(h, n);
        let store = self.store;
        let extent = self.extent;
        let materials = self.materials;
        let mut att = 1.0;
        let mut seen: Vec<u32> = Vec::new();
        let mut missing = 0u64;
        let end = dray
            .walk_skipping(&self.raster, self.opts.light.mode, u32::MAX, |index, c| {
                let Some(b) = surface_voxel(&store, extent, Some(&rule), index, c, &mut missing)
                else {
                    return false;
                };
                let t = materials
                    .get(usize::from(b.material))
                    .map_or(0.0, |m| m.transmittance);
                if t > 0.0 {
                    let owner = store.owner(b);
                    if !seen.contains(&owner) {
                        seen.push(owner);
                        att *= t;
                    }
                    return false;
                }
                true
            })
            .unwrap_or(WalkEnd::Exit);
        stats.steps += u64::from(dray.steps());
        stats.shadow_steps += u64::from(dray.steps());
        stats.missing += missing;
        if end == WalkEnd::Hit { 0.0 } else { att }
    }

    /// How much of light `k` reaches verified hit `h` (seen side `n`) in
    /// the exact mode, with `embree_nff`'s shadow ray: from `origin`
    /// ([`Tracer::leaving_point`], ε off the surface) in the direction
    /// from the hit to the light, ending `2ε` short of the light's
    /// distance. Where the voxel holding `origin` has the shadow
    /// classification's *lit* for the light (only the voxel's own objects
    /// can stand between any of its points and the light,
    /// [`rrt_core::light`]; from its record's bits, or computed on demand
    /// and kept, [`TraceOptions::classify_on_demand`](super::TraceOptions::classify_on_demand)),
    /// those objects are intersected with the
    /// segment and nothing is walked; where it has *occluded* (an opaque
    /// sphere blocks every segment from the voxel to the light, with half
    /// a voxel to spare, which covers the 3ε), the light is blocked and
    /// nothing is intersected; otherwise an exact shadow ray
    /// decides ([`Tracer::exact_shadow`]). Both give the exact answer: the
    /// segment stays within 3ε of the one from `origin` to the light,
    /// and the classification's tube covers that much and more while 3ε
    /// is under half a voxel (the tracer uses it only where ε is under an
    /// eighth of a voxel: rasters up to about 7,000 voxels across).
    fn exact_light<'s>(
        &'s self,
        h: &SurfaceHit,
        n: DVec3,
        origin: DVec3,
        origin_voxel: &mut Option<Option<OriginVoxel<'s>>>,
        k: usize,
        stats: &mut RayStats,
    ) -> f64 {
        let Some(light) = self.lights.get(k) else {
            return 0.0;
        };
        let to = light.position - h.point;
        let dist = to.length();
        if !(dist > 0.0) {
            return 1.0;
        }
        let segment = Ray::new(origin, to / dist);
        let tmax = dist - 2.0 * self.offset_at(h);
        let voxel = *origin_voxel.get_or_insert_with(|| self.origin_voxel(origin));
        let answer = voxel.map_or(Classified::Undecided, |v| self.classified(&v, k));
        if answer == Classified::Occluded {
            stats.occluded += 1;
            return 0.0;
        }
        if let Classified::Lit(own) = answer {
            stats.classified += 1;
            let mut att = 1.0;
            let skip = (!self.meets_itself(h, n)).then_some(h.object);
            for &id in own.iter().filter(|&&id| Some(id) != skip) {
                let Some(obj) = usize::try_from(id).ok().and_then(|i| self.objects.get(i)) else {
                    continue;
                };
                if obj.shape.first_t(&segment, 0.0, tmax).is_some() {
                    att *= self.transmittance(obj.material);
                }
            }
            return att;
        }
        stats.shadow += 1;
        self.exact_shadow(h, n, &segment, tmax, k, stats)
    }

    /// What the shadow classification says of voxel `o` (the one holding a
    /// shadow ray's origin, [`Tracer::origin_voxel`]) for light `k`: its
    /// record's bits for the light, or the answer computed on demand and
    /// kept; [`Classified::Undecided`] unless every object of the voxel has
    /// exact geometry.
    fn classified<'v>(&self, o: &OriginVoxel<'v>, k: usize) -> Classified<'v> {
        if !o.exact {
            return Classified::Undecided;
        }
        let answer = match &self.classification {
            Classification::Unavailable => Classification::UNDECIDED,
            Classification::Records => match o.rec.light(k) {
                LightVisibility::Visible => Classification::LIT,
                LightVisibility::Occluded => Classification::OCCLUDED,
                _ => Classification::UNDECIDED,
            },
            Classification::OnDemand(d) => {
                let (Some(slot), Some(Some(light)), Ok(shift)) = (
                    d.memo.get(o.at),
                    self.lights_fx.get(k),
                    u32::try_from(2 * k),
                ) else {
                    return Classified::Undecided;
                };
                if shift >= 16 {
                    return Classified::Undecided;
                }
                let known = (slot.load(Ordering::Relaxed) >> shift) & 3;
                if known == Classification::UNKNOWN {
                    // A sphere's or triangle's fixed-point geometry as the
                    // fit makes it, made when asked: no copy of the object
                    // table is kept.
                    let shape = |id: u32| match self.objects.get(usize::try_from(id).ok()?)?.shape {
                        Shape::Sphere(s) => s.to_fixed(&self.frame).ok().map(FixedShape::Sphere),
                        // Its vertices as the fit rounds them: the proofs
                        // read nothing else of a triangle.
                        Shape::Triangle(t) => {
                            let [a, b, c] = t.vertices.map(|p| self.frame.to_fixed(p));
                            Some(FixedShape::Triangle(FixedTriangle {
                                vertices: [a?, b?, c?],
                                normals: None,
                            }))
                        }
                        _ => None,
                    };
                    // The same, for the spheres that let no light through.
                    let blocker = |id: u32| {
                        let o = self.objects.get(usize::try_from(id).ok()?)?;
                        match o.shape {
                            Shape::Sphere(s) if self.transmittance(o.material) == 0.0 => {
                                s.to_fixed(&self.frame).ok()
                            }
                            _ => None,
                        }
                    };
                    let bricks = d.level.as_ref().and_then(|l| l.bricks(&self.store));
                    let answer = match classify_voxel(
                        &self.raster,
                        &self.store,
                        bricks.as_ref(),
                        shape,
                        blocker,
                        o.voxel,
                        o.rec,
                        *light,
                    ) {
                        Ok(LightVisibility::Visible) => Classification::LIT,
                        Ok(LightVisibility::Occluded) => Classification::OCCLUDED,
                        _ => Classification::UNDECIDED,
                    };
                    slot.fetch_or(answer << shift, Ordering::Relaxed);
                    answer
                } else {
                    known
                }
            }
        };
        match answer {
            Classification::LIT => Classified::Lit(o.own),
            Classification::OCCLUDED => Classified::Occluded,
            _ => Classified::Undecided,
        }
    }

    /// The opaque voxel holding world point `p` with its record, for the
    /// shadow classification ([`Tracer::classified_lit`]); `None` where
    /// there is no classification, or `p` lies outside the raster or in a
    /// transparent voxel or one without a record.
    fn origin_voxel(&self, p: DVec3) -> Option<OriginVoxel<'_>> {
        if matches!(self.classification, Classification::Unavailable) {
            return None;
        }
        let r = self.frame.world_to_raster(p).floor();
        let dims = self.extent.dims();
        let v: [u32; 3] = std::array::from_fn(|a| {
            let c = r[a];
            if c >= 0.0 && c < f64::from(dims[a]) {
                c as u32
            } else {
                u32::MAX
            }
        });
        let (_, c) = self.opaque_cell(v)?;
        let at = self.store.index_hinted(v, c)?;
        let rec = self.store.records().get(at)?;
        let own = self.store.objects(rec);
        let exact = own.iter().all(|&id| {
            usize::try_from(id)
                .ok()
                .and_then(|i| self.objects.get(i))
                .is_some_and(|o| o.shape.is_exact())
        });
        Some(OriginVoxel {
            voxel: v,
            at,
            rec,
            own,
            exact,
        })
    }

    /// Whether a ray leaving verified hit `h` towards the side `n` can
    /// meet the hit object again ([`Shape::meets_itself_leaving`](crate::shape::Shape::meets_itself_leaving)).
    fn meets_itself(&self, h: &SurfaceHit, n: DVec3) -> bool {
        usize::try_from(h.object)
            .ok()
            .and_then(|i| self.objects.get(i))
            .is_none_or(|o| o.shape.meets_itself_leaving(h.normal.dot(n) > 0.0))
    }

    /// The transmittance `T` of material `m` (0: opaque).
    fn transmittance(&self, m: u16) -> f64 {
        self.materials
            .get(usize::from(m))
            .map_or(0.0, |m| m.transmittance)
    }

    /// An exact shadow ray from verified hit `h` (seen side `n`) along
    /// `segment` (from the point off the surface towards light `k`, unit
    /// direction) up to `tmax`: the same walk and object tests as
    /// verification. The segment walks adaptively with empty-space
    /// skipping, which visits every opaque voxel the line passes through
    /// (proximity is set around every surface voxel); every object of
    /// each opaque voxel is tested once (a [`Mailbox`]) against the
    /// continuous segment `t ∈ (0, tmax)`. Any intersection with an opaque
    /// object is a shadow (any hit ends the walk); a translucent object
    /// attenuates once. An object without exact geometry counts at its
    /// voxels, unless the acne rule ignores them. Before walking, the
    /// object that last blocked a shadow ray towards the light in this
    /// tile ([`RayStats::blockers`]) is intersected: neighbouring hits
    /// mostly share their blocker, and meeting it inside the raster is the
    /// walk's answer too.
    pub(super) fn exact_shadow(
        &self,
        h: &SurfaceHit,
        n: DVec3,
        segment: &Ray,
        tmax: f64,
        k: usize,
        stats: &mut RayStats,
    ) -> f64 {
        let skip = (!self.meets_itself(h, n)).then_some(h.object);
        if self.opts.last_blocker
            && let Some(Some(id)) = stats.blockers.get(k).copied()
            && Some(id) != skip
            && self.blocks_inside(id, segment, tmax)
        {
            stats.last_blocker += 1;
            return 0.0;
        }
        let Some(ray) = self.light_segment(segment.origin, k) else {
            return 0.0;
        };
        let Some(mut dray) = ray else {
            return 1.0;
        };
        let rule = self.leaving(h, n);
        let store = self.store;
        let extent = self.extent;
        let materials = self.materials;
        let objects = self.objects;
        let tmin = 0.0;
        let o_r = self.frame.world_to_raster(segment.origin);
        let mut att = 1.0;
        let mut mail = Mailbox::default();
        let mut blocker = None;
        // Translucent objects already counted (each attenuates once).
        let mut seen: Vec<u32> = Vec::new();
        let mut missing = 0u64;
        let end = dray
            .walk_skipping(
                &self.raster,
                Connectivity::Adaptive,
                u32::MAX,
                |index, c| {
                    if c & cell::OPAQUE == 0 {
                        return false;
                    }
                    let Some(b) = extent.coord(index).and_then(|v| store.get_hinted(v, c)) else {
                        missing += 1;
                        return false;
                    };
                    for &id in store.objects(b) {
                        // A sphere the segment clearly misses neither
                        // blocks nor is a volume.
                        if self.refused(id, segment, tmin) {
                            continue;
                        }
                        if let Some(d) = self.direct_volume(id) {
                            // A volume rendered directly lets its
                            // transmittance through (its voxels are on the
                            // line: index has coordinates).
                            let v = extent.coord(index).unwrap_or([0; 3]);
                            att *= self.transmittance_through(segment, o_r, v, d, tmax);
                            if att <= 1.0 - super::composite::OPAQUE_ENOUGH {
                                return true;
                            }
                            continue;
                        }
                        let Some(obj) = usize::try_from(id).ok().and_then(|i| objects.get(i))
                        else {
                            continue;
                        };
                        // The surface left, where it cannot meet the
                        // segment again, is never tested.
                        let blocks = if obj.shape.is_exact() {
                            Some(id) != skip
                                && !mail.tested(id)
                                && obj.shape.first_t(segment, tmin, tmax).is_some()
                        } else {
                            !rule.ignores(&store, index, b)
                        };
                        if !blocks {
                            continue;
                        }
                        let t = materials
                            .get(usize::from(obj.material))
                            .map_or(0.0, |m| m.transmittance);
                        if t <= 0.0 {
                            blocker = obj.shape.is_exact().then_some(id);
                            return true;
                        }
                        if !seen.contains(&id) {
                            seen.push(id);
                            att *= t;
                        }
                    }
                    false
                },
            )
            .unwrap_or(WalkEnd::Exit);
        stats.steps += u64::from(dray.steps());
        stats.shadow_steps += u64::from(dray.steps());
        stats.missing += missing;
        if let (Some(id), Some(slot)) = (blocker, stats.blockers.get_mut(k)) {
            *slot = Some(id);
        }
        if end == WalkEnd::Hit { 0.0 } else { att }
    }

    /// Whether object `id`, opaque with exact geometry, meets `segment`
    /// for `t ∈ (0, tmax)` first at a point inside the raster box: then
    /// the exact shadow ray's walk, which visits every voxel of the
    /// segment inside the raster, meets it too, and the light is blocked.
    fn blocks_inside(&self, id: u32, segment: &Ray, tmax: f64) -> bool {
        let Some(obj) = usize::try_from(id).ok().and_then(|i| self.objects.get(i)) else {
            return false;
        };
        if !obj.shape.is_exact() || self.transmittance(obj.material) > 0.0 {
            return false;
        }
        let Some(t) = obj.shape.first_t(segment, 0.0, tmax) else {
            return false;
        };
        let r = self.frame.world_to_raster(segment.at(t));
        let dims = self.extent.dims();
        (0..3).all(|a| r[a] > 0.0 && r[a] < f64::from(dims[a]))
    }
}

/// What the shadow classification says of the voxel holding a shadow
/// ray's origin for one light ([`Tracer::classified`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Classified<'a> {
    /// Only the voxel's own objects (these) can stand between any of its
    /// points and the light.
    Lit(&'a [u32]),
    /// An opaque object blocks every segment from the voxel to the light.
    Occluded,
    /// A shadow ray decides.
    Undecided,
}

/// The voxel holding a hit's shadow-ray origin, looked up once for all
/// the lights of the hit ([`Tracer::origin_voxel`]).
#[derive(Clone, Copy, Debug)]
struct OriginVoxel<'a> {
    /// Its coordinates.
    voxel: [u32; 3],
    /// Its record's position in the store (the memo's index).
    at: usize,
    /// Its record.
    rec: &'a VoxelRecord,
    /// Its objects.
    own: &'a [u32],
    /// Whether every one of them has exact geometry (else no
    /// classification applies).
    exact: bool,
}
