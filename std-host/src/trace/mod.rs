//! The recursive discrete ray tracer (the paper's ray tracing phase).
//!
//! A ray is traced by stepping its 3D discrete line through the raster
//! ([`DiscreteRay`](rrt_core::discrete_ray::DiscreteRay), clipped to the
//! raster box: the paper's two endpoints)
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
//! as `embree_nff` shades (see [`shading`]): `N` the normal (stored, or
//! true under verification) turned towards the viewer (two-sided
//! shading), `R` the reflection of the light direction `L`, `V` towards
//! the eye. In the paper's and the verified [`Mode`], lights are decided by
//! the precomputed bits, and shadow rays are fired at render time only for
//! lights whose bits say *translucent* (`att` multiplies the transmittance
//! `T` of each translucent object the shadow ray passes, each object
//! once). In the exact mode every light a verified hit faces is decided
//! exactly: where the voxel holding the shadow ray's start is proven lit by
//! the shadow classification ([`rrt_core::light`], *Shadow
//! classification*), only the voxel's own objects are intersected; where
//! it is proven occluded (an opaque sphere blocks every segment from the
//! voxel to the light), the light is blocked without a ray;
//! otherwise the object that last blocked a shadow ray towards the light
//! in the tile is tried (met inside the raster, it is the walk's answer
//! too), and else an exact shadow ray walks adaptively with empty-space skipping
//! (exact: every opaque voxel the segment's line passes through is
//! visited) and counts only objects of those voxels' lists that the
//! continuous segment really intersects (voxels of objects without exact
//! geometry count as they are). The reflected ray (when `Ks > 0`) and the
//! refracted ray (when `T > 0`: Snell's law with the material's index of
//! refraction, total internal reflection falling back to the mirror
//! direction) are traced recursively to [`TraceOptions::depth`] (the eye
//! ray is depth 1), each while its weight in the pixel is at least
//! [`TraceOptions::min_weight`]. A ray that leaves the raster takes the background
//! colour.
//!
//! `illum` holds the lit side the stored normal faces. When the other
//! side of an open surface (a polygon, an open cone) is seen, or the inside
//! of a closed one, the ambient term and the diffuse terms of the lights
//! whose bits say that side sees them are computed here instead.
//!
//! # Intersection verification
//! In the exact and the verified [`Mode`], on a raster voxelized for it
//! ([`BuildOptions::exact`](crate::voxelize::BuildOptions::exact): every
//! exact object owns every voxel whose closed cube its surface meets, and a
//! voxel several objects share lists all of them), the walk stops at every
//! opaque voxel and tests each object of the voxel's list
//! ([`RecordStore::objects`]) against the continuous world ray (the
//! paper's object table, [`WorldObject`]): its first intersection with
//! `t > tmin` anywhere along the ray. A per-ray mailbox keeps an object
//! from being intersected twice. The nearest intersection found so far is
//! the hit as soon as it lies in the part of the ray the walk has reached:
//! `t` at most the continuous ray's exit from the current voxel (plus a
//! hundred-thousandth of a voxel for the fixed-point line's rounding);
//! otherwise the walk goes on, and a walk that leaves the raster takes the
//! nearest intersection it found. Adaptive walks take 6-steps next to
//! every surface voxel and skip only empty space, so every opaque voxel
//! the line passes through is visited: the hit is the nearest exact
//! intersection over all objects, however small the objects or crowded
//! the voxels. An object without exact geometry (a volume, a `.vox` model,
//! a CSG tree) is hit where the ray enters its voxel. A hit takes the
//! true point and normal, and the attributes of the object hit (its own
//! record: the voxel's, or a neighbouring voxel's it owns); the diffuse
//! terms are recomputed with the true normal for the lights the bits say
//! are visible. An untextured object with exact geometry is shaded with
//! its material's colour itself, not the 8-bit colour its records store,
//! so its colour does not depend on the voxel a hit was found from, nor
//! on the raster. Voxels whose objects are all missed are the paper's
//! *false hits* ([`RayStats::false_hits`]).
//!
//! # No acne
//! A ray leaving a verified hit starts [`surface_offset`] off the surface,
//! towards the side it goes to, and counts every exact intersection after
//! its start, as `embree_nff`'s rays do; shadow rays end twice that short
//! of the light. The offset is never more than a tenth of the size of the
//! smallest object of the scene ([`crate::shape::Shape::radius`]; nor less
//! than 10⁻¹² of the hit point's largest coordinate, the rounding of the
//! point): a ray displaced from its surface by more than an object's size
//! could pass that object, so in a scene spanning many orders of magnitude
//! (a ground made huge to look infinite, a far object, small objects among
//! large ones) no object loses its shadow, its reflection or its
//! neighbours to the offset. A flat triangle or a sphere left from outside is not
//! tested against its own rays ([`crate::shape::Shape::meets_itself_leaving`]).
//! A ray leaving a discrete hit (the paper's mode, objects without exact
//! geometry) starts at the point where the incoming ray entered the hit
//! voxel; there the surface's voxel layer is up to two voxels thick, so the
//! ray would hit its own surface at once. The tracer applies the light
//! pass's rule ([`LeavingSurface`], see [`rrt_core::light`]): a voxel met
//! by a ray leaving voxel `c₀` towards the side of unit normal `N₀` is
//! ignored when its centre lies at most two voxels above `c₀`'s tangent
//! plane (`(c − c₀)·N₀ ≤ 2`) *and* its owner is the same object or its
//! surface is oriented within 60° of this one. `N₀` is the side the ray
//! goes to: the viewer's side for reflections and the render-time shadow
//! rays, the other side for a refracted ray entering the object. Concave
//! objects still reflect and shadow themselves beyond the two-voxel slab
//! in that mode.
//!
//! # Direct volume rendering
//! A volume rendered directly ([`Render::Direct`](crate::assets::volume::Render))
//! has every voxel whose sample has an opacity above 0 in the raster
//! ([`crate::voxelize::direct`]), so walks stop there and skip the empty
//! space around it; such a voxel is never a hit. Its sample (the volume's
//! value at the voxel centre) is classified by the transfer function and
//! composited front to back ([`composite::Composite`]:
//! `C += (1 − A)·α·c`, `A += (1 − A)·α`) by every ray that visits it: eye,
//! reflected and refracted rays. `α` is the transfer function's opacity
//! corrected for the length `ℓ` of the ray the sample stands for,
//! `1 − (1 − α)^(ℓ / spacing)` (the opacity is that of one sample spacing
//! of the data): for six-connected and adaptive walks, which visit every
//! voxel of the volume the line passes through, `ℓ` is the ray's chord
//! through the voxel (so the lengths add up to the length crossed, on
//! axis or diagonal steps alike); for 26-connected walks, one voxel per
//! slice across the driving axis, the ray's length across a slice. A
//! sample is shaded as a surface whose normal is the gray-level gradient
//! (central differences of the neighbouring voxels' samples, the volume's
//! material, lit by every light it faces, no shadows) where the gradient
//! is strong ([`composite::STRONG_GRADIENT`]) and shows its transfer
//! colour where the gray levels are flat, in between in proportion.
//! Compositing stops when the opacity reaches
//! [`composite::OPAQUE_ENOUGH`] (0.99; what lies behind would add at most
//! 1 % of its colour, and no further ray is traced). Otherwise the
//! surface the walk ends on is shaded as usual and seen through what was
//! composited, `C + (1 − A)·colour`; a surface inside the volume ends the
//! compositing at its depth (the voxel holding the hit contributes its
//! chord up to the hit). In the exact mode, shadow rays take the
//! transmittance `1 − α` of every voxel of such a volume they cross; in
//! the verified and paper modes the precomputed light bits count its
//! voxels as opaque. Everything is computed per ray in a fixed order, so
//! images are byte-identical for every thread count.
//!
//! # Packets
//! [`Tracer::trace_block`] traces eight primary rays (a 4×2 pixel block)
//! in two stages: first every ray is walked to its first non-transparent
//! voxel, by a [`RayPacket8`](rrt_core::packet::RayPacket8) stepping the
//! eight lanes together (or by the
//! scalar walk, [`TraceOptions::packets`]); then each ray's hit is resolved
//! (verification and resumption, shading, secondary rays) by the scalar
//! code, which resumes the very `DiscreteRay` the packet left in its lane.
//! The packet is bit-identical to the scalar walk, so the image does not
//! depend on the choice.
//!
//! # Empty-space skipping
//! The scalar walks use the plane's proximity distances
//! ([`rrt_core::proximity::distance_field`], computed by the builder):
//! where the nearest non-transparent voxel is `d ≥ 4` voxels away, a
//! 26-run takes `d − 1` steps at once, landing exactly where single steps
//! would. Far from surfaces they read the scene's line level instead of the
//! plane ([`rrt_core::raster::Raster::with_lines`]: one stand-in cell per
//! 64 plane cells, small enough to stay in cache). [`RayStats::steps`]
//! counts voxels visited, a jump as one.

pub mod composite;
pub mod shade;
pub mod shading;
pub mod verify;
pub mod walk;

use std::fmt;
use std::sync::atomic::AtomicU16;
use std::sync::{Arc, OnceLock};

use glam::DVec3;
use rrt_core::discrete_ray::Connectivity;
use rrt_core::light::{ExactRecords, LeavingSurface, LightParams};
use rrt_core::raster::{Extent, Raster, cell};
use rrt_core::store::RecordStore;
use rrt_core::voxel::VoxelRecord;

pub use self::composite::Composite;
pub use self::verify::{Verdict, verify};
pub use self::walk::FirstWalk;

use crate::frame::RasterFrame;
use crate::scene::Material;
use crate::shape::{Shape, Sphere};
use crate::voxelize::{VoxelScene, WorldLight, WorldObject};
use crate::world::{Bounds, Ray};

/// Rays per primary block: 4 × 2 pixels, the lanes of `RayPacket8`.
pub const BLOCK: usize = 8;
/// Width of a primary block in pixels.
pub const BLOCK_W: u32 = 4;
/// Height of a primary block in pixels.
pub const BLOCK_H: u32 = 2;

/// What a hit is and how it is lit: the renderer's modes.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum Mode {
    /// The default, on an exact raster
    /// ([`VoxelScene::exact`](crate::voxelize::VoxelScene::exact)): every
    /// object of each opaque voxel a ray reaches is intersected exactly
    /// (intersection verification over the object lists; module docs), the
    /// true point and normal are shaded, and every light a verified hit
    /// faces is decided exactly: by the shadow classification where it
    /// proves the voxel lit (only the voxel's own objects are
    /// intersected), else by an exact shadow ray. Secondary rays leave the
    /// surface as `embree_nff`'s do. The image is the exact ray tracer's
    /// for every object with exact geometry.
    #[default]
    Exact,
    /// The paper's intersection verification: exact hit point and normal
    /// (on an exact raster), lit by the precomputed light visibility.
    Verified,
    /// The paper's raw discrete mode: the first surface voxel is the hit,
    /// shaded with its stored normal, precomputed illumination and light
    /// visibility bits. The fastest.
    Paper,
}

impl Mode {
    /// Every mode, in the order of `--mode`'s help.
    pub const ALL: [Self; 3] = [Self::Exact, Self::Verified, Self::Paper];

    /// Whether hits are verified against the objects' exact geometry
    /// (which needs an exact raster).
    #[must_use]
    pub const fn verifies(self) -> bool {
        !matches!(self, Self::Paper)
    }

    /// Whether verified hits are lit by exact shadow rays rather than the
    /// precomputed bits.
    #[must_use]
    pub const fn exact_shadows(self) -> bool {
        matches!(self, Self::Exact)
    }

    /// The mode's name on the command line.
    #[must_use]
    pub const fn name(self) -> &'static str {
        match self {
            Self::Exact => "exact",
            Self::Verified => "verified",
            Self::Paper => "paper",
        }
    }
}

/// How rays are traced.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TraceOptions {
    /// What a hit is and how it is lit.
    pub mode: Mode,
    /// Connectivity of the primary and secondary rays.
    pub connectivity: Connectivity,
    /// Maximum depth of the ray tree; the eye ray is depth 1.
    pub depth: u32,
    /// The least weight of a traced reflected or refracted ray: its
    /// weight is the product of the `Ks` and `T` factors that scale it on
    /// its way to the eye (1 for the eye ray), so the colour it adds to a
    /// pixel is that weight times what it sees. A ray lighter than this
    /// is not traced (it adds nothing) and is counted in
    /// [`RayStats::pruned`]. The default, 2⁻¹⁶, is below one step of a
    /// 16-bit linear image for a ray that sees at most white. A material
    /// with both `Ks` and `T` doubles the ray tree at every level until
    /// the weights fall below this (with factors near 1, until `depth`).
    /// 0 traces the whole tree to `depth`.
    pub min_weight: f64,
    /// The acne rule's slab and angle, and the connectivity of render-time
    /// shadow rays: by default those of the light pass, adaptive rays that
    /// meet the opaque voxels of the 6-connected line in its order (the
    /// plane's proximity flags are set around every opaque voxel), so
    /// they give the 6-connected rays' answers.
    pub light: LightParams,
    /// Walk primary rays eight at a time in a
    /// [`RayPacket8`](rrt_core::packet::RayPacket8) instead of one by one.
    /// Both skip empty space and give the same image (each lane is
    /// bit-identical to the scalar skipping walk); the scalar walk, the
    /// faster of the two where it was measured, is the default.
    pub packets: bool,
    /// Before an exact shadow ray walks, try the object that last blocked
    /// a shadow ray towards the same light in the tile
    /// ([`RayStats::blockers`]). On by default; the image is the same
    /// without it (every shadow ray then walks).
    pub last_blocker: bool,
    /// On a raster whose light pass left the records of exact objects
    /// unclassified ([`ExactRecords::Skip`], what `rrt render SCENE`
    /// builds), compute the shadow classification of a hit's voxel for a
    /// light when a hit first needs it and keep it for the render
    /// ([`rrt_core::light::classify_voxel`]): a voxel proven lit is then
    /// lit for every later hit in it without a shadow ray. On by default;
    /// the image is the same without it (every light of every hit then
    /// fires an exact shadow ray).
    pub classify_on_demand: bool,
}

impl Default for TraceOptions {
    fn default() -> Self {
        Self {
            mode: Mode::Exact,
            connectivity: Connectivity::Adaptive,
            depth: 3,
            min_weight: DEFAULT_MIN_WEIGHT,
            light: crate::voxelize::pass_light_params(),
            packets: false,
            last_blocker: true,
            classify_on_demand: true,
        }
    }
}

impl TraceOptions {
    /// Refuses options that no raster can honour, before any raster is
    /// made: a depth of 0, and 26-connected rays in a verifying mode.
    ///
    /// # Errors
    /// [`TraceError::Depth`], [`TraceError::DiagonalSteps`].
    pub fn check(&self) -> Result<(), TraceError> {
        if self.depth == 0 {
            return Err(TraceError::Depth);
        }
        if self.connectivity == Connectivity::TwentySix && self.mode.verifies() {
            return Err(TraceError::DiagonalSteps(self.mode.name()));
        }
        Ok(())
    }
}

/// [`TraceOptions::min_weight`]'s default: 2⁻¹⁶.
pub const DEFAULT_MIN_WEIGHT: f64 = 1.0 / 65536.0;

/// Counts of one render.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RayStats {
    /// Eye rays.
    pub primary: u64,
    /// Reflected rays.
    pub reflected: u64,
    /// Refracted (or totally reflected) transmitted rays.
    pub refracted: u64,
    /// Reflected and refracted rays not traced: lighter than
    /// [`TraceOptions::min_weight`].
    pub pruned: u64,
    /// Render-time shadow rays (lights seen through translucent material;
    /// in the exact mode, every light of a verified hit the shadow
    /// classification proves neither lit nor occluded).
    pub shadow: u64,
    /// Lights of verified hits (exact mode) that the shadow classification
    /// proved lit: only the voxel's own objects were intersected, no ray
    /// walked.
    pub classified: u64,
    /// Lights of verified hits (exact mode) that the shadow classification
    /// proved occluded: an opaque object blocks every segment from the
    /// voxel to the light; nothing intersected, no ray walked.
    pub occluded: u64,
    /// Voxels visited by all rays (an empty-space jump counts as one).
    pub steps: u64,
    /// Of `steps`, the voxels visited by render-time shadow rays.
    pub shadow_steps: u64,
    /// Rays that ended on a surface.
    pub hits: u64,
    /// Discrete hits that verification rejected: the continuous ray does
    /// not meet the voxel's object (the paper's false hits).
    pub false_hits: u64,
    /// Verified hits in voxels that hold more than one object (found
    /// through the voxel's object list).
    pub shared_hits: u64,
    /// Rays (of any kind but shadow) that met at least one false hit.
    pub false_hit_rays: u64,
    /// Discrete hits whose object the continuous ray meets only farther
    /// on: the walk went on to the voxel of the intersection.
    pub deferred: u64,
    /// Opaque cells without a record (a damaged raster), stepped over.
    pub missing: u64,
    /// Samples of volumes rendered directly composited along rays.
    pub samples: u64,
    /// Of `shadow`, the rays found blocked by the object that last blocked
    /// a shadow ray towards the same light in this tile, without a walk.
    pub last_blocker: u64,
    /// Per light (the first [`BLOCKER_LIGHTS`]), the opaque object with
    /// exact geometry that last blocked a render-time shadow ray of this
    /// tile: tried first by the next one (an intersection with it is a
    /// shadow whatever else lies between). Not a count: [`RayStats::add`]
    /// leaves it, and no answer depends on it.
    pub blockers: [Option<u32>; BLOCKER_LIGHTS],
}

/// Lights whose last blocker a tile keeps ([`RayStats::blockers`]).
pub const BLOCKER_LIGHTS: usize = 8;

impl RayStats {
    /// Adds `o` to `self`.
    pub fn add(&mut self, o: &Self) {
        self.primary += o.primary;
        self.reflected += o.reflected;
        self.refracted += o.refracted;
        self.pruned += o.pruned;
        self.shadow += o.shadow;
        self.classified += o.classified;
        self.occluded += o.occluded;
        self.steps += o.steps;
        self.shadow_steps += o.shadow_steps;
        self.hits += o.hits;
        self.false_hits += o.false_hits;
        self.deferred += o.deferred;
        self.shared_hits += o.shared_hits;
        self.false_hit_rays += o.false_hit_rays;
        self.missing += o.missing;
        self.samples += o.samples;
        self.last_blocker += o.last_blocker;
    }

    /// All rays traced.
    #[must_use]
    pub fn rays(&self) -> u64 {
        self.primary + self.reflected + self.refracted + self.shadow
    }
}

/// What a ray sees: its colour and how much of it the background is not.
///
/// `alpha` is the ray's coverage, 1 − its transmittance to the background:
/// 1 when it ends on a surface (any surface: what is seen through a
/// translucent one or in a mirror is part of the picture) or when the
/// volumes rendered directly along it are opaque enough to end it
/// ([`composite::OPAQUE_ENOUGH`]); the opacity they composited when it
/// leaves the raster; 0 when it meets nothing. `foreground` is the colour
/// without the background, premultiplied by `alpha`, and `colour` the
/// colour with the background behind:
/// `colour = foreground + (1 − alpha) · background`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Traced {
    /// The linear colour, the background included.
    pub colour: DVec3,
    /// The linear colour without the background, premultiplied by `alpha`.
    pub foreground: DVec3,
    /// The coverage, in `[0, 1]`.
    pub alpha: f64,
}

/// A surface hit.
#[derive(Clone, Copy, Debug)]
struct SurfaceHit {
    voxel: [u32; 3],
    /// The attributes of the object hit (its record).
    rec: VoxelRecord,
    /// The colour it is shaded with (linear, `[0, 1]`).
    colour: DVec3,
    /// The object hit.
    object: u32,
    /// The ray parameter of `point`.
    t: f64,
    /// World point used for shading and secondary rays.
    point: DVec3,
    /// Unit normal (stored, or true under verification), not turned.
    normal: DVec3,
    verified: bool,
    /// The normal is interpolated between voxels (an object without exact
    /// geometry): the precomputed illumination, which is the hit voxel's,
    /// is not used.
    smoothed: bool,
}

/// What a ray hits ([`Tracer::hit`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RayHit {
    /// The object's id in the object table ([`VoxelScene::objects`]).
    pub object: u32,
    /// The ray parameter (world units along the unit direction).
    pub t: f64,
    /// The world point.
    pub point: DVec3,
    /// The unit normal there (the object's true normal when verified, the
    /// stored one otherwise), not turned towards the ray.
    pub normal: DVec3,
    /// The voxel the hit was found from.
    pub voxel: [u32; 3],
    /// Verified against the object's exact geometry.
    pub verified: bool,
}

/// How far a ray leaving a verified hit starts off the surface at most,
/// along the normal towards the side it goes to (less where the scene has
/// objects smaller than ten times this: module docs, *No acne*):
/// `embree_nff`'s ε, 10⁻⁵ of the
/// diagonal of the box of the scene's geometry (the objects' boxes; the
/// raster's box where some object has no geometry of its own, a volume
/// or `.vox` model, or there is none), so that it does not depend on the
/// raster. Near the contact of two objects (the spheres of a sphereflake
/// touch their parents) which of them a grazing secondary ray meets
/// depends on where it starts; starting where the exact tracer does gives
/// its answer.
#[must_use]
pub fn surface_offset(scene: &VoxelScene) -> f64 {
    let mut b = Bounds::EMPTY;
    for o in &scene.objects {
        match o.shape.bounds() {
            Some(ob) => b.include_bounds(ob),
            None => b.include_bounds(scene.frame.world_bounds()),
        }
    }
    if b.is_empty() || !b.size().is_finite() {
        b = scene.frame.world_bounds();
    }
    1e-5 * b.size().length()
}

/// The renderer over one voxelized scene.
#[derive(Clone, Debug)]
pub struct Tracer<'s> {
    raster: Raster<'s>,
    store: RecordStore<'s>,
    extent: Extent,
    frame: RasterFrame,
    objects: &'s [WorldObject],
    /// The sphere of each object that is one, by object id up to the last
    /// sphere, and a NaN sphere for every other object, which refuses
    /// nothing ([`Tracer::refused`]): 32 bytes an object, so that the
    /// spheres a ray clearly misses are passed over without reading the
    /// object table.
    spheres: Arc<[Sphere]>,
    /// The brick directory of `store`.
    directory: &'s [u32],
    /// By object id, what the records it owns around it hold, found when a
    /// hit on it in a voxel it does not own first asks
    /// ([`Tracer::attributes_of`]); a function of the records alone.
    owned: Arc<[OnceLock<Option<Owned>>]>,
    /// Whether a verified hit's shading reads nothing of its record but
    /// the material and the colour: the exact mode (the light bits give
    /// way to exact shadows, the precomputed illumination to the true
    /// normal) with every object exact (a ray leaving a hit reads the
    /// record's normal and owner only at voxels of objects without exact
    /// geometry, for the acne rule).
    attributes_only: bool,
    materials: &'s [Material],
    /// By material, the 8-bit colour an untextured object's records hold
    /// ([`record_colour`](crate::voxelize::materials::record_colour)).
    record_colours: Arc<[[u8; 3]]>,
    lights: &'s [WorldLight],
    lights_fx: Vec<Option<[i64; 3]>>,
    /// The volumes rendered directly, by object id.
    direct: &'s [crate::voxelize::direct::DirectVolume],
    /// Where the shadow classification of exact records comes from, when
    /// the shadow segments stay close enough to the ones it covers
    /// ([`Tracer::exact_light`]) to use it.
    classification: Classification,
    /// How far rays leaving a verified hit start off the surface
    /// ([`Tracer::leaving`]) at most.
    offset: f64,
    /// The offset of rays leaving a surface ([`Tracer::offset_at`]):
    /// `offset`, or a tenth of the smallest object's size where that is
    /// less.
    least_offset: f64,
    background: DVec3,
    intensity: f64,
    opts: TraceOptions,
}

/// [`Tracer::spheres`] of `objects`: each sphere's, NaN for every other
/// object, as far as the last sphere.
fn sphere_table(objects: &[WorldObject]) -> Arc<[Sphere]> {
    let nan = Sphere {
        centre: DVec3::NAN,
        radius: f64::NAN,
    };
    let len = objects
        .iter()
        .rposition(|o| matches!(o.shape, Shape::Sphere(_)))
        .map_or(0, |i| i + 1);
    objects
        .iter()
        .take(len)
        .map(|o| match o.shape {
            Shape::Sphere(s) => s,
            _ => nan,
        })
        .collect()
}

/// An 8-bit colour as values in `[0, 1]`.
fn rgb(c: [u8; 3]) -> DVec3 {
    DVec3::new(f64::from(c[0]), f64::from(c[1]), f64::from(c[2])) / 255.0
}

/// What the records an object owns in a box of voxels around it hold
/// ([`Tracer::owned`]): any record the search of [`Tracer::attributes_of`]
/// can find for a hit whose neighbouring voxels all lie in the box is one
/// of them.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) struct Owned {
    /// The box: voxels `lo..hi` on each axis.
    lo: [u32; 3],
    hi: [u32; 3],
    holds: Holds,
}

/// See [`Owned`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Holds {
    /// No record.
    Nothing,
    /// Records, each with the object's material and its colour as an
    /// untextured object's records hold it.
    Plain,
    /// Records, some with other attributes (a texture).
    Varied,
}

/// Voxels the box of [`Owned`] reaches beyond the object's bounds, so that
/// the voxels hits on the object are found from lie within it with their
/// neighbours (where one does not, the neighbours are searched).
const OWNED_MARGIN: f64 = 3.0;

/// Records an object's [`Owned`] reads at most, once: each object's scan
/// is bounded whatever its size (an object whose box holds more has its
/// neighbours searched).
const OWNED_SCAN_LIMIT: usize = 1 << 16;

/// The source of the shadow classification of a render
/// ([`Tracer::exact_light`]). Clones share what was computed.
#[derive(Clone)]
enum Classification {
    /// None: every light of a verified hit fires an exact shadow ray.
    Unavailable,
    /// The records' light bits hold it ([`ExactRecords::Classify`]).
    Records,
    /// Computed when a hit first needs it, per record and light, and kept:
    /// two bits per light and record (index as in
    /// [`RecordStore::records`]), [`Classification::UNKNOWN`],
    /// [`Classification::LIT`], [`Classification::OCCLUDED`] or
    /// [`Classification::UNDECIDED`]. The
    /// answer is a function of the record and the light alone, so the
    /// order in which threads fill it in changes nothing.
    OnDemand(Arc<OnDemand>),
}

/// The classification computed on demand: the memo (two bits per light
/// and record, [`Classification::OnDemand`]) and the raster's brick level,
/// which spares the walks of voxels it proves lit (`None` if its buffers
/// could not be allocated: the same answers, from the voxels' walks).
struct OnDemand {
    memo: Box<[AtomicU16]>,
    level: Option<crate::voxelize::light::ShadowLevel>,
}

impl fmt::Debug for Classification {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Unavailable => f.write_str("Unavailable"),
            Self::Records => f.write_str("Records"),
            Self::OnDemand(d) => write!(f, "OnDemand({} records)", d.memo.len()),
        }
    }
}

impl Classification {
    const UNKNOWN: u16 = 0;
    const LIT: u16 = 1;
    const UNDECIDED: u16 = 2;
    const OCCLUDED: u16 = 3;

    /// The classification a tracer over `scene` with `opts` can use.
    fn of(scene: &VoxelScene, store: &RecordStore<'_>, opts: &TraceOptions) -> Self {
        if !scene.exact || surface_offset(scene) >= scene.frame.voxel_size / 8.0 {
            return Self::Unavailable;
        }
        match scene.exact_records {
            ExactRecords::Classify => Self::Records,
            ExactRecords::Skip if opts.classify_on_demand && opts.mode.exact_shadows() => {
                Self::OnDemand(Arc::new(OnDemand {
                    memo: (0..store.len()).map(|_| AtomicU16::new(0)).collect(),
                    level: crate::voxelize::light::ShadowLevel::of(store).ok(),
                }))
            }
            _ => Self::Unavailable,
        }
    }
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
    /// 26-connected rays in a verifying mode: they step diagonally past
    /// voxels the ray passes through, where verification would then miss
    /// the objects (holes in thin and small objects).
    #[error(
        "26-connected rays step diagonally past voxels the ray passes through, so the {0} mode's verification would miss the objects there (holes in thin and small objects): render with --connectivity adaptive (the default: 26-steps away from surfaces, the exact image) or six, or with --mode paper"
    )]
    DiagonalSteps(&'static str),
    /// A depth of 0.
    #[error("depth: expected at least 1 (the eye ray), found 0")]
    Depth,
    /// A verifying mode on the paper's raster, which has no object lists.
    #[error(
        "the {0} mode verifies hits against every object of a voxel, but this raster was voxelized for the paper's mode (one object per voxel): render it with --mode paper, or voxelize it again without --mode paper"
    )]
    NotExact(&'static str),
}

impl<'s> Tracer<'s> {
    /// A tracer over `scene`.
    ///
    /// # Errors
    /// [`TraceError`]: an inconsistent raster, 26-connected rays through
    /// surfaces voxelized for 6-connected ones or in a verifying mode,
    /// depth 0.
    pub fn new(scene: &'s VoxelScene, opts: TraceOptions) -> Result<Self, TraceError> {
        opts.check()?;
        if opts.mode.verifies() && !scene.exact {
            return Err(TraceError::NotExact(opts.mode.name()));
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
            .map(|l| scene.frame.light_to_fixed(l.position))
            .collect();
        let offset = surface_offset(scene);
        Ok(Self {
            raster,
            store,
            extent: scene.frame.extent,
            frame: scene.frame,
            objects: &scene.objects,
            spheres: sphere_table(&scene.objects),
            directory: &scene.directory,
            owned: (0..scene.objects.len()).map(|_| OnceLock::new()).collect(),
            attributes_only: opts.mode.exact_shadows()
                && scene.objects.iter().all(|o| o.shape.is_exact()),
            materials: &scene.materials,
            record_colours: scene
                .materials
                .iter()
                .map(crate::voxelize::materials::record_colour)
                .collect(),
            lights: &scene.lights,
            lights_fx,
            direct: &scene.direct,
            classification: Classification::of(scene, &store, &opts),
            offset,
            least_offset: scene
                .objects
                .iter()
                .map(|o| 0.1 * o.shape.radius())
                .fold(offset, f64::min),
            background: scene.background,
            intensity: scene.intensity(),
            opts,
        })
    }

    /// Whether object `id` is a sphere whose exact tests refuse `ray` for
    /// `t > tmin` before any root is sought ([`Sphere::refuses`]): then
    /// [`Surface::first_t`](crate::shape::Surface::first_t) and
    /// [`Surface::intersect`](crate::shape::Surface::intersect) answer
    /// `None` for every `tmax`, and the object need not be read.
    #[inline]
    pub(super) fn refused(&self, id: u32, ray: &Ray, tmin: f64) -> bool {
        usize::try_from(id)
            .ok()
            .and_then(|i| self.spheres.get(i))
            .is_some_and(|s| s.refuses(ray, tmin))
    }

    /// The raster index and cell of voxel `v` when it lies in the raster
    /// and is non-transparent (its record is then looked up by the cell's
    /// rank hint).
    pub(super) fn opaque_cell(&self, v: [u32; 3]) -> Option<(usize, u8)> {
        let index = self.extent.index(v)?;
        let c = self.raster.plane().get(index).copied()?;
        (c & cell::OPAQUE != 0).then_some((index, c))
    }

    /// The options in use.
    #[must_use]
    pub const fn options(&self) -> &TraceOptions {
        &self.opts
    }

    /// Traces one ray (unit direction) at `depth` of the ray tree, whose
    /// colour adds to the pixel with `weight` ([`TraceOptions::min_weight`]),
    /// and returns its colour; a ray leaving a surface has its acne rule
    /// `leave` and counts exact intersections from `tmin` on
    /// ([`Tracer::leaving`]).
    fn trace(
        &self,
        ray: &Ray,
        (depth, weight): (u32, f64),
        leave: Option<&LeavingSurface>,
        tmin: f64,
        stats: &mut RayStats,
    ) -> DVec3 {
        let mut walk = match leave {
            Some(rule) if !self.opts.mode.verifies() => self.secondary_walk(ray, rule, stats),
            // Verification tests every object of every opaque voxel with
            // t > tmin: no voxel is skipped by the acne rule on the way.
            _ => self.first_walk(ray),
        };
        let mut acc = Composite::default();
        let hit = self.resolve(ray, &mut walk, tmin, leave, &mut acc, stats);
        self.behind(ray, hit, (depth, weight), &acc, stats).colour
    }

    /// What a ray whose walk composited `acc` and ended on `hit` (or left
    /// the raster) sees: the hit shaded, or the background, seen through
    /// what was composited (nothing more once compositing stopped), and
    /// its coverage ([`Traced`]).
    fn behind(
        &self,
        ray: &Ray,
        hit: Option<SurfaceHit>,
        depth: (u32, f64),
        acc: &Composite,
        stats: &mut RayStats,
    ) -> Traced {
        let (foreground, alpha) = if acc.done() {
            (acc.colour, 1.0)
        } else if let Some(h) = hit {
            stats.hits += 1;
            (acc.over(self.shade(ray, &h, depth, stats)), 1.0)
        } else {
            (acc.colour, acc.alpha)
        };
        Traced {
            colour: foreground + self.background * (1.0 - alpha),
            foreground,
            alpha,
        }
    }

    /// Traces up to eight primary rays (a 4×2 pixel block; `None` lanes lie
    /// outside the image) and returns what each sees ([`Traced`]; nothing,
    /// black and uncovered, for `None`). Stage one walks every ray to its
    /// first non-transparent voxel; stage two resolves and shades each
    /// (module docs, *For packets*).
    pub fn trace_block(
        &self,
        rays: &[Option<Ray>; BLOCK],
        stats: &mut RayStats,
    ) -> [Traced; BLOCK] {
        let mut out = [Traced::default(); BLOCK];
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
    fn primary(&self, r: &Ray, w: &mut FirstWalk, stats: &mut RayStats) -> Traced {
        stats.primary += 1;
        let mut acc = Composite::default();
        let hit = self.resolve(r, w, 0.0, None, &mut acc, stats);
        self.behind(r, hit, (1, 1.0), &acc, stats)
    }

    /// The surface a primary ray (unit direction) hits, resolved as the
    /// renderer resolves it (the discrete hit, or under verification the
    /// nearest exact intersection), without shading; `None` when it leaves
    /// the raster or the volumes rendered directly in front of the surface
    /// are opaque enough to end it. Counts go to `stats` as for a traced
    /// ray.
    pub fn hit(&self, ray: &Ray, stats: &mut RayStats) -> Option<RayHit> {
        let mut walk = self.first_walk(ray);
        let mut acc = Composite::default();
        self.resolve(ray, &mut walk, 0.0, None, &mut acc, stats)
            .map(|h| RayHit {
                object: h.object,
                t: h.t,
                point: h.point,
                normal: h.normal,
                voxel: h.voxel,
                verified: h.verified,
            })
    }

    /// Traces one primary ray (unit direction) and returns its colour.
    pub fn trace_primary(&self, ray: &Ray, stats: &mut RayStats) -> DVec3 {
        stats.primary += 1;
        self.trace(ray, (1, 1.0), None, 0.0, stats)
    }
}
