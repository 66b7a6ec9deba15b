//! Direct volume rendering along the discrete ray: the samples of the
//! voxels a ray visits in a volume rendered directly
//! ([`DirectVolume`]), classified by its transfer function and composited
//! front to back (module docs of [`crate::trace`], *Direct volume
//! rendering*).
//!
//! ```
//! use glam::DVec3;
//! use rrt_host::trace::composite::{Composite, corrected_opacity};
//! // Three voxels of a slab whose opacity is 0.2 per sample spacing,
//! // crossed along an axis with the spacing equal to the voxel.
//! let mut c = Composite::default();
//! for _ in 0..3 {
//!     c.add(DVec3::ONE, corrected_opacity(0.2, 1.0, 1.0));
//! }
//! assert!((c.alpha - (1.0 - 0.8f64.powi(3))).abs() < 1e-15);
//! // Crossed diagonally (√3 voxels per voxel), each voxel is thicker.
//! assert!((corrected_opacity(0.2, 3f64.sqrt(), 1.0) - (1.0 - 0.8f64.powf(3f64.sqrt()))).abs() < 1e-15);
//! ```

use glam::DVec3;
use rrt_core::discrete_ray::Connectivity;
use rrt_core::voxel::VoxelRecord;

use super::Tracer;
use super::shading::{face_forward, local};
use super::verify::slab;
use crate::scene::Material;
use crate::voxelize::direct::DirectVolume;
use crate::world::Ray;

/// The accumulated opacity at which compositing stops (early ray
/// termination): what lies behind would add at most 1 % of its colour.
pub const OPAQUE_ENOUGH: f64 = 0.99;

/// The colour and opacity composited so far along a ray, front to back
/// (colours premultiplied by their opacity).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Composite {
    /// The composited colour.
    pub colour: DVec3,
    /// The composited opacity, in `[0, 1]`.
    pub alpha: f64,
}

impl Composite {
    /// Adds a sample of colour `colour` and opacity `alpha` behind what
    /// is composited: `C += (1 − A)·α·c`, `A += (1 − A)·α`.
    pub fn add(&mut self, colour: DVec3, alpha: f64) {
        let w = (1.0 - self.alpha) * alpha.clamp(0.0, 1.0);
        self.colour += colour * w;
        self.alpha += w;
    }

    /// Whether compositing stops here ([`OPAQUE_ENOUGH`]).
    #[must_use]
    pub fn done(&self) -> bool {
        self.alpha >= OPAQUE_ENOUGH
    }

    /// The colour of the ray with `behind` (the surface hit or the
    /// background) seen through what is composited.
    #[must_use]
    pub fn over(&self, behind: DVec3) -> DVec3 {
        self.colour + behind * (1.0 - self.alpha)
    }
}

/// The opacity of a length `length` of a material whose opacity is
/// `alpha` over `spacing` (both world lengths): `1 − (1 − α)^(ℓ / s)`.
#[must_use]
pub fn corrected_opacity(alpha: f64, length: f64, spacing: f64) -> f64 {
    if !(alpha > 0.0 && length > 0.0) {
        return 0.0;
    }
    if alpha >= 1.0 {
        return 1.0;
    }
    1.0 - (1.0 - alpha).powf(length / spacing)
}

/// The gradient magnitude, in gray levels per sample spacing, at and
/// above which a sample is fully shaded, as a share of the span of the
/// opacity ramp's values; below it the shading fades linearly into the
/// transfer function's colour.
pub const STRONG_GRADIENT: f64 = 0.1;

impl Tracer<'_> {
    /// The volume rendered directly among the objects of record `rec`.
    pub(super) fn direct_of(&self, rec: &VoxelRecord) -> Option<&DirectVolume> {
        if self.direct.is_empty() {
            return None;
        }
        self.store
            .objects(rec)
            .iter()
            .find_map(|&id| self.direct_volume(id))
    }

    /// The volume rendered directly whose voxel `v` is, with no other
    /// object ([`DirectVolume::alone`]).
    pub(super) fn direct_alone(&self, v: [u32; 3]) -> Option<&DirectVolume> {
        self.direct.iter().find(|d| d.alone(v))
    }

    /// The volume rendered directly with object id `id`.
    pub(super) fn direct_volume(&self, id: u32) -> Option<&DirectVolume> {
        let i = self.direct.binary_search_by_key(&id, |d| d.object).ok()?;
        self.direct.get(i)
    }

    /// The part of `ray` (unit direction; `o_r` its origin in raster
    /// units) a sample of voxel `v` stands for, clipped to `[t0, t1]`:
    /// `(entry, length)` in world units. For six-connected and adaptive
    /// walks (which visit every voxel of a volume the line passes through:
    /// proximity is set around them) the ray's chord through the voxel;
    /// for 26-connected walks (one voxel per slice across the driving
    /// axis) the ray's length across one slice.
    pub(super) fn sample_span(
        &self,
        ray: &Ray,
        o_r: DVec3,
        v: [u32; 3],
        t0: f64,
        t1: f64,
    ) -> Option<(f64, f64)> {
        let vs = self.frame.voxel_size;
        let lo = DVec3::from(v.map(f64::from));
        let (a, b) = slab(o_r, ray.dir, lo, lo + 1.0)?;
        let exit = if self.opts.connectivity == Connectivity::TwentySix {
            a * vs + vs / ray.dir.abs().max_element()
        } else {
            b * vs
        };
        let from = (a * vs).max(t0);
        let len = exit.min(t1) - from;
        (len > 0.0).then_some((from, len))
    }

    /// Composites the sample of voxel `v` of the volume `d` into `acc`
    /// for the part of `ray` in `[t0, t1]`; returns whether a sample was
    /// added.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn composite_voxel(
        &self,
        ray: &Ray,
        o_r: DVec3,
        v: [u32; 3],
        d: &DirectVolume,
        t0: f64,
        t1: f64,
        acc: &mut Composite,
    ) -> bool {
        let Some(value) = d.value(v).map(f64::from) else {
            return false;
        };
        let alpha = d.classifier.sample_opacity(value);
        if !(alpha > 0.0) {
            return false;
        }
        let Some((from, len)) = self.sample_span(ray, o_r, v, t0, t1) else {
            return false;
        };
        let a = corrected_opacity(alpha, len, d.spacing);
        let c = d.classifier.color(value, d.base).map(f64::from);
        let c = DVec3::new(c[0], c[1], c[2]) / 255.0;
        let colour = self.shade_sample(ray, ray.at(from + 0.5 * len), v, d, c);
        acc.add(colour, a);
        true
    }

    /// The colour of a sample of transfer-function colour `c` at world
    /// point `p` of voxel `v`: lit by the lights as a surface whose normal
    /// is the gray-level gradient's (two-sided, the material's `kd`, `ks`
    /// and `shine`, no shadows) where the gradient is strong
    /// ([`STRONG_GRADIENT`]), `c` itself where the gray levels are flat,
    /// and in between in proportion to the gradient's magnitude.
    fn shade_sample(&self, ray: &Ray, p: DVec3, v: [u32; 3], d: &DirectVolume, c: DVec3) -> DVec3 {
        let g = d.gradient(v) * (d.spacing / self.frame.voxel_size);
        let span = d
            .classifier
            .opacity
            .as_ref()
            .and_then(|r| Some(r.points().last()?.0 - r.points().first()?.0))
            .unwrap_or(0.0);
        let strong = STRONG_GRADIENT * span;
        let m = g.length();
        let w = if strong > 0.0 {
            (m / strong).min(1.0)
        } else {
            1.0
        };
        // `(-g).try_normalize()`, from the length at hand.
        let rcp = m.recip();
        if !(w > 0.0 && rcp.is_finite() && rcp > 0.0) {
            return c;
        }
        let n = -g * rcp;
        let n = face_forward(n, ray.dir);
        let m = usize::try_from(d.object)
            .ok()
            .and_then(|i| self.objects.get(i))
            .and_then(|o| self.materials.get(usize::from(o.material)))
            .unwrap_or(&Material::DEFAULT);
        let m = Material {
            colour: c,
            kd: m.kd,
            ks: m.ks,
            shine: m.shine,
            ..Material::DEFAULT
        };
        let lights = self
            .lights
            .iter()
            .map(|l| ((l.position - p).normalize_or_zero(), l.colour));
        let lit = local(&m, n, ray.dir, lights, self.intensity);
        c * (1.0 - w) + lit * w
    }

    /// The share of light a shadow segment (`segment`, unit direction,
    /// `o_r` its origin in raster units) lets through voxel `v` of the
    /// volume `d`, for its part in `[0, tmax]`.
    pub(super) fn transmittance_through(
        &self,
        segment: &Ray,
        o_r: DVec3,
        v: [u32; 3],
        d: &DirectVolume,
        tmax: f64,
    ) -> f64 {
        self.sample_span(segment, o_r, v, 0.0, tmax)
            .map_or(1.0, |(_, len)| {
                let alpha = d
                    .value(v)
                    .map_or(0.0, |x| d.classifier.sample_opacity(f64::from(x)));
                1.0 - corrected_opacity(alpha, len, d.spacing)
            })
    }
}
