//! Light visibility and the precomputed view-independent illumination.
//!
//! After the scene is built (the plane is complete), [`illuminate`] fires,
//! from every record's voxel centre and for every light, a discrete shadow
//! ray through the raster ([`DiscreteRay::segment`] towards the light,
//! clipped by the raster; a light outside the raster is reached when the
//! ray leaves it) and stores in the record's 2-bit field
//! ([`LightVisibility`]): visible, occluded, or visible through translucent
//! material only (blockers whose material has transmission `T > 0` and no
//! opaque blocker). Then it precomputes
//!
//! ```text
//! illum = I_a·Kd·C + Σ_{lights marked Visible, N·L > 0} I·L_rgb·Kd·C·(N·L)
//! ```
//!
//! in fixed point, saturating at 1.0 (C: the record's colour, Kd: its
//! material's, N: the stored normal, L: the unit direction from the voxel
//! centre to the light, normalized with an integer square root). Lights
//! marked translucent are left to the renderer, which fires their shadow ray
//! and adds their attenuated diffuse term.
//!
//! # Facing away
//! A light the stored normal faces away from (`N·L ≤ 0`) gets no light, as
//! in the SPD: on a closed shape ([`crate::object_table::Shape::is_closed`]) it is marked
//! occluded without firing a ray. An open shape (triangle, patch, open
//! cone) can be seen from both sides; for a light behind it the shadow ray is
//! fired from the back side (with `−N`) and the bits say whether the back
//! side sees the light. `illum` holds the front side's (the stored
//! normal's) sum only; a renderer that sees the back of an open surface adds
//! the diffuse terms of the lights on the back from their bits.
//!
//! # No self-shadowing acne
//! A voxelized surface is a layer about two voxels thick (up to
//! `2·½(|nx|+|ny|+|nz|) ≤ √3` voxels for a 26-separating one), so a shadow
//! ray leaving a surface voxel towards a light the surface faces, and more
//! so at grazing angles, runs through neighbouring voxels of the same
//! surface before it gets clear. Those must not count as blockers. The
//! rule: an opaque voxel `b` met by the shadow ray from voxel centre `c₀`
//! with (light-side) normal `N₀` is ignored when
//!
//! 1. its centre lies at most [`LightParams::slab`] (default 2 voxels)
//!    above `c₀`'s tangent plane: `(c_b − c₀)·N₀ ≤ slab`, **and**
//! 2. it belongs to the same object, or to a surface oriented like this one
//!    (stored normals within 60°, [`LightParams::same_surface_cos`]): the
//!    neighbouring triangle of a mesh or patch of a teapot.
//!
//! Why this is right: every voxel of a surface layer lies within its
//! half-thickness `w ≤ √3/2` of the surface, so near `c₀` the layer fills
//! heights `≤ 2w < 2` voxels above `c₀`'s tangent plane; a convex object
//! lies entirely below that plane plus `2w`, so it never shadows itself
//! where `N·L > 0` (the lone-sphere test: every voxel facing the light is
//! visible, every voxel facing away occluded). A **concave** object still
//! shadows itself: the far side of a torus's hole, the body of a teapot
//! under its spout, rise higher than two voxels above the tangent plane and
//! block. What the rule gives up is self-shadowing by parts of the surface
//! less than two voxels above the tangent plane, below the raster's
//! resolution. Condition 2 keeps contact shadows: a sphere resting on a
//! floor has, near the contact, normals facing the floor's, so its voxels
//! block the floor's shadow rays even within the slab.
//!
//! A voxel whose record is missing (a plane that does not match the store)
//! counts as an opaque blocker.
//!
//! # Shadow classification
//! On a raster with object lists, whose hits the renderer verifies against
//! each object's exact geometry, a record all of whose objects have exact
//! geometry can get a proof instead of the paper's guess
//! ([`ExactRecords::Classify`]; after Woo & Amanatides' voxel occlusion
//! testing). For a light `L` and a voxel `v` with objects `O`: a point of
//! a segment from any point of `v`'s closed cube to `L` lies within half a
//! voxel (chessboard) of the segment from `v`'s centre to `L`, so every
//! voxel such a segment passes through lies within chessboard distance 1
//! of a voxel of that centre segment's 6-connected line: the segment's
//! *tube* ([`DiscreteRay::walk_dilated`]). An object that blocks such a
//! segment has a surface point on it, and every voxel its surface passes
//! through lists it. So when every non-transparent voxel of the tube holds
//! only objects of `O`, nothing but `O` can shadow any point of `v`, and a
//! renderer needs to intersect only those: `Visible`. A foreign sphere in
//! the tube does not stand in the way when the segment from `v`'s centre
//! to `L` passes farther than its radius plus half the cube's diagonal
//! from its centre (with a margin for the rounding to fixed point): every
//! segment from a point of the cube to `L` then passes outside it. Nor
//! does a foreign triangle when the cube (with the same margin) lies
//! outside its shadow volume from `L`, the points whose segment to `L`
//! meets it: wholly on the light's side of its plane, or beyond one of
//! the three planes through `L` and an edge (as the neighbouring
//! triangles of a lit mesh often are). And an
//! opaque sphere met in the tube *occludes* the voxel (`Occluded`) when the
//! segment from `v`'s centre to `L` passes within its radius less half the
//! cube's diagonal and half a voxel of its centre, the cube lies that much
//! outside it, and it lies inside the raster: every segment from a point
//! of the cube to `L` (and the renderer's, which starts and ends within a
//! few ε of one) then enters it, from outside and inside the raster, where
//! an exact shadow ray meets it. Otherwise `Translucent`: a render-time
//! shadow ray decides. The answer does not
//! depend on the stored normal (the renderer decides which side faces the
//! light from the true normal), and the walk reads the distance field:
//! the plane must be finished before the pass. Given the raster's brick
//! level ([`bricks`]), the walk is first done once per brick over the
//! bricks: where it proves a brick of one object lit, its voxels need no
//! walk of their own, and the answer is the same.
//!
//! # Dark side
//! A point `p` of a sphere of centre `C` and radius `R` faces a light at
//! `L` exactly when `(p − C)·(L − C) > R²`: it lies beyond the plane of the
//! terminator. When a voxel's objects are all spheres and its whole cube
//! lies on the dark side of each (the cube's corner farthest along
//! `L − C` stays below that plane, with a margin for the rounding of `C`,
//! `R` and `L` to fixed point), no point of the cube faces the light from
//! outside: a renderer shading a lit-side hit starts its shadow ray just
//! off the surface towards the light, beyond the plane, so in another
//! voxel. The pair is left undecided without a walk, which is always a
//! correct answer (a render-time shadow ray decides, for a hit seen from
//! inside a sphere); it saves the walks of the half of a sphere's voxels
//! that face away from each light.

pub mod bricks;

use core::fmt;

use crate::discrete_ray::{Connectivity, DiscreteRay, WalkEnd};
use crate::error::RayError;
use crate::fixed::{VOXEL, voxel_centre};
use crate::geometry::{Sphere, Triangle};
use crate::object_table::{Lights, Materials, ObjectTable, SCALAR_BITS, Shape};
use crate::raster::{Extent, Raster, cell};
use crate::store::{RecordStore, RecordStoreMut};
use crate::voxel::{LightVisibility, MAX_LIGHTS, VoxelRecord, decode_normal, dot_unit, normalize};
use crate::voxelize::NORMAL_ONE;
use bricks::ShadowBricks;

/// Tuning of the shadow rays.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct LightParams {
    /// Connectivity of the shadow rays. 6-connected rays (the default) go
    /// through every voxel the continuous ray pierces, so a 6-tunnel-free
    /// scene cannot leak light. Adaptive rays meet the very opaque voxels
    /// 6-connected rays meet, in the same order, where the plane's
    /// [`cell::PROXIMITY`] flags are set around every opaque voxel (as
    /// [`crate::proximity::distance_field`] sets them: a 26-step leaves
    /// only a voxel with no opaque neighbour, and its corner-cutting skips
    /// only such neighbours), so on a finished plane they give the same
    /// answers, faster: they take 26-steps and skip empty space by the
    /// distance field away from surfaces.
    pub mode: Connectivity,
    /// Height above a voxel's tangent plane (fixed units) below which
    /// voxels of the same surface are ignored: 2 voxels by default (module
    /// docs).
    pub slab: i64,
    /// Two stored normals with dot product at least this
    /// ([`NORMAL_ONE`]-scaled) belong to one surface for the acne rule:
    /// `NORMAL_ONE / 2` (60°) by default.
    pub same_surface_cos: i32,
    /// What the pass computes for a record all of whose objects have
    /// exact geometry ([`Shape::is_exact`](crate::object_table::Shape::is_exact)),
    /// on a raster with object lists whose hits a renderer verifies.
    pub exact_records: ExactRecords,
}

impl Default for LightParams {
    fn default() -> Self {
        Self {
            mode: Connectivity::Six,
            slab: VOXEL.wrapping_mul(2),
            same_surface_cos: NORMAL_ONE / 2,
            exact_records: ExactRecords::Paper,
        }
    }
}

/// The light pass's answer for a record whose objects all have exact
/// geometry ([`LightParams::exact_records`]). Other records always get the
/// paper's bits.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum ExactRecords {
    /// The paper's bits, from one discrete shadow ray per light.
    #[default]
    Paper,
    /// The shadow classification (module docs, *Shadow classification*):
    /// [`LightVisibility::Visible`] where it is proven that only the
    /// voxel's own objects can stand between any point of the voxel and
    /// the light, [`LightVisibility::Occluded`] where an opaque sphere is
    /// proven to block every segment from the voxel to the light,
    /// [`LightVisibility::Translucent`] (a render-time shadow ray decides)
    /// elsewhere.
    Classify,
    /// No rays: every light [`LightVisibility::Translucent`], for a
    /// renderer that decides every light of a verified hit itself: with an
    /// exact shadow ray, or with the classification computed for the
    /// voxels its hits need ([`classify_voxel`]).
    Skip,
}

/// Why the light pass stopped.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum LightError {
    /// The raster and the store have different dimensions.
    ExtentMismatch,
    /// A shadow ray could not be set up (a light position beyond
    /// [`crate::discrete_ray::ORIGIN_LIMIT`] on an axis is clamped first, so
    /// this reports an internal limit).
    Ray(RayError),
}

impl fmt::Display for LightError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            Self::ExtentMismatch => f.write_str("raster and record store differ in size"),
            Self::Ray(e) => write!(f, "shadow ray: {e}"),
        }
    }
}

impl core::error::Error for LightError {}

impl From<RayError> for LightError {
    fn from(e: RayError) -> Self {
        Self::Ray(e)
    }
}

/// Counts from one light pass.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct LightReport {
    /// Records processed.
    pub records: u64,
    /// Shadow rays fired.
    pub rays: u64,
    /// (record, light) pairs marked visible.
    pub visible: u64,
    /// Pairs marked translucent.
    pub translucent: u64,
    /// Pairs blocked by an opaque voxel.
    pub occluded: u64,
    /// Pairs on a closed shape facing away from the light (occluded, no
    /// ray fired).
    pub facing_away: u64,
    /// Exact pairs whose voxel lies wholly on the dark side of its spheres
    /// (module docs, *Dark side*): left undecided (counted in
    /// `translucent` too) without a walk.
    pub dark_side: u64,
    /// Exact pairs proven lit by the brick level ([`bricks`]) without a
    /// walk of their own (counted in `visible` too).
    pub brick_proofs: u64,
    /// Records whose object id or material is not in the tables (treated
    /// as a closed, opaque, non-diffuse object).
    pub missing: u64,
}

/// Fires the shadow rays and fills [`VoxelRecord::lights`] and
/// [`VoxelRecord::illum`] of every record (module docs). Lights past
/// [`crate::voxel::MAX_LIGHTS`] cannot exist ([`Lights`] refuses them).
///
/// Work: one shadow ray per record and light, each bounded by the raster's
/// size.
///
/// # Errors
/// [`LightError::ExtentMismatch`] if `raster` and `store` differ in size.
pub fn illuminate<const N: usize>(
    raster: &Raster<'_>,
    store: &mut RecordStoreMut<'_>,
    objects: &ObjectTable<'_>,
    materials: &Materials<N>,
    lights: &Lights,
    params: &LightParams,
) -> Result<LightReport, LightError> {
    let extent = raster.extent();
    if store.as_store().extent() != extent {
        return Err(LightError::ExtentMismatch);
    }
    let mut report = LightReport::default();
    let mut proofs = BrickProofs::new(None);
    store.update_each(|view, v, rec| {
        shade_record(
            raster,
            &view,
            extent,
            objects,
            materials,
            lights,
            params,
            &mut proofs,
            None,
            v,
            rec,
            &mut report,
        )
        .map(Some)
    })?;
    Ok(report)
}

/// The light pass over one run of records, for hosts that split it
/// across threads: for the records `first..first + out.len()` of `store`
/// (fewer if the store ends first), writes into `out` each record with its
/// visibility bits and illumination set, exactly as [`illuminate`] sets
/// them. It reads only `store`, whose fields the shadow rays look at
/// (object, material, normal, position) the pass never changes, so runs
/// done in any order or in parallel give the records [`illuminate`] gives.
/// With the raster's brick level (`bricks`, [`bricks::shadow_bricks`]) the
/// shadow classification walks a brick's tube once per light and spares
/// the walks of the voxels it proves lit: the same records, faster on
/// surfaces of one object.
///
/// Stack: a run keeps a table of the records its shadow classifications
/// looked up (neighbouring records' tubes cross the same voxels), 2^10
/// pairs of `usize` (16 KiB on 64-bit targets, 8 KiB on 32-bit ones);
/// [`illuminate`] keeps none and its stack small. The records are the same
/// either way.
///
/// # Errors
/// [`LightError::ExtentMismatch`] if `raster`, `store` and `bricks` differ
/// in size.
#[allow(clippy::too_many_arguments)] // the pass's context
pub fn illuminate_run<const N: usize>(
    raster: &Raster<'_>,
    store: &RecordStore<'_>,
    first: usize,
    out: &mut [VoxelRecord],
    objects: &ObjectTable<'_>,
    materials: &Materials<N>,
    lights: &Lights,
    params: &LightParams,
    bricks: Option<&ShadowBricks<'_>>,
) -> Result<LightReport, LightError> {
    let extent = raster.extent();
    if store.extent() != extent || bricks.is_some_and(|b| b.extent() != extent) {
        return Err(LightError::ExtentMismatch);
    }
    let mut report = LightReport::default();
    let mut proofs = BrickProofs::new(bricks);
    let mut found = FoundRecords::new();
    for (slot, (v, rec)) in out.iter_mut().zip(store.iter_from(first)) {
        *slot = shade_record(
            raster,
            store,
            extent,
            objects,
            materials,
            lights,
            params,
            &mut proofs,
            Some(&mut found),
            v,
            *rec,
            &mut report,
        )?;
    }
    Ok(report)
}

/// The brick level's answers ([`ShadowBricks::proves_lit`]) for the brick
/// of the records being lit, per light: records come in brick order, so a
/// run walks each brick once per light.
struct BrickProofs<'l, 'b> {
    level: Option<&'l ShadowBricks<'b>>,
    brick: Option<usize>,
    lit: [Option<bool>; MAX_LIGHTS],
}

impl<'l, 'b> BrickProofs<'l, 'b> {
    const fn new(level: Option<&'l ShadowBricks<'b>>) -> Self {
        Self {
            level,
            brick: None,
            lit: [None; MAX_LIGHTS],
        }
    }

    /// Whether the brick level proves voxel `v` lit for light `i` at
    /// `light`; `false` without a level.
    fn lit(&mut self, v: [u32; 3], i: usize, light: [i64; 3]) -> Result<bool, LightError> {
        let Some(level) = self.level else {
            return Ok(false);
        };
        let b = level.brick_of(v);
        if b != self.brick {
            self.brick = b;
            self.lit = [None; MAX_LIGHTS];
        }
        if let Some(Some(known)) = self.lit.get(i) {
            return Ok(*known);
        }
        let lit = level.proves_lit(v, light)?;
        if let Some(slot) = self.lit.get_mut(i) {
            *slot = Some(lit);
        }
        Ok(lit)
    }
}

/// The records of the voxels the shadow classifications of one run
/// ([`illuminate_run`]) looked up, by linear index: neighbouring records'
/// tubes cross the same voxels (their own surface first), and a lookup
/// found here spares the brick directory's. A direct-mapped table of
/// [`FOUND_SLOTS`] entries; an entry is a pure function of the read-only
/// store, so the answers are the store's whatever the table holds.
struct FoundRecords {
    /// `(index, position)`: voxel `index` has the record at `position`
    /// ([`NO_RECORD`] for none); [`EMPTY_SLOT`] as the index marks an
    /// unused entry.
    slots: [(usize, usize); FOUND_SLOTS],
}

/// Entries of [`FoundRecords`]: `2^FOUND_BITS`.
const FOUND_SLOTS: usize = 1 << FOUND_BITS;
/// See [`FOUND_SLOTS`].
const FOUND_BITS: u32 = 10;
/// An index no raster holds (a raster's cells are fewer than `usize::MAX`).
const EMPTY_SLOT: usize = usize::MAX;
/// The position stored for a voxel without a record.
const NO_RECORD: usize = usize::MAX;

impl FoundRecords {
    const fn new() -> Self {
        Self {
            slots: [(EMPTY_SLOT, NO_RECORD); FOUND_SLOTS],
        }
    }

    /// The record of the opaque voxel `w` (linear index `index`, cell
    /// `c`) in `view`, as [`RecordStore::get_hinted`] finds it.
    fn get<'a>(
        &mut self,
        view: &RecordStore<'a>,
        index: usize,
        w: [u32; 3],
        c: u8,
    ) -> Option<&'a VoxelRecord> {
        // Fibonacci hashing: the top bits of the index times 2^64/φ.
        let h = u64::try_from(index)
            .unwrap_or(u64::MAX)
            .wrapping_mul(0x9e37_79b9_7f4a_7c15)
            >> u64::BITS.wrapping_sub(FOUND_BITS);
        let Some(slot) = self.slots.get_mut(usize::try_from(h).unwrap_or(0)) else {
            return view.get_hinted(w, c);
        };
        if slot.0 != index {
            *slot = (index, view.index_hinted(w, c).unwrap_or(NO_RECORD));
        }
        view.records().get(slot.1)
    }
}

impl LightReport {
    /// Adds the counts of `other` (another run of the same pass).
    pub fn add(&mut self, other: &Self) {
        self.records = self.records.saturating_add(other.records);
        self.rays = self.rays.saturating_add(other.rays);
        self.visible = self.visible.saturating_add(other.visible);
        self.translucent = self.translucent.saturating_add(other.translucent);
        self.occluded = self.occluded.saturating_add(other.occluded);
        self.facing_away = self.facing_away.saturating_add(other.facing_away);
        self.dark_side = self.dark_side.saturating_add(other.dark_side);
        self.brick_proofs = self.brick_proofs.saturating_add(other.brick_proofs);
        self.missing = self.missing.saturating_add(other.missing);
    }
}

#[allow(clippy::too_many_arguments)] // the pass's context, unpacked once
fn shade_record<const N: usize>(
    raster: &Raster<'_>,
    view: &RecordStore<'_>,
    extent: Extent,
    objects: &ObjectTable<'_>,
    materials: &Materials<N>,
    lights: &Lights,
    params: &LightParams,
    proofs: &mut BrickProofs<'_, '_>,
    mut found: Option<&mut FoundRecords>,
    v: [u32; 3],
    mut rec: VoxelRecord,
    report: &mut LightReport,
) -> Result<VoxelRecord, LightError> {
    report.records = report.records.saturating_add(1);
    let owner = view.owner(&rec);
    let object = objects.get(owner);
    let material = materials.get(rec.material);
    if object.is_none() || material.is_none() {
        report.missing = report.missing.saturating_add(1);
    }
    let closed = object.is_none_or(|o| o.shape.is_closed());
    let kd = material.map_or(0, |m| m.kd);
    let normal = rec.normal_vector();
    let c0 = v.map(voxel_centre);
    let start = extent.index(v);
    rec.lights = 0;
    // Every object of the voxel has exact geometry: the renderer verifies
    // its hits and may read a classification instead of the paper's bits.
    let original = rec;
    let own = view.objects(&original);
    let exact = params.exact_records != ExactRecords::Paper
        && own
            .iter()
            .all(|&id| objects.get(id).is_some_and(|o| o.shape.is_exact()));
    // Sum of I·L_rgb·(N·L) over visible front-side lights, 2^-32 units.
    let mut acc = [u128::from(lights.ambient) << SCALAR_BITS; 3];
    for (i, light) in lights.as_slice().iter().enumerate() {
        if exact && params.exact_records == ExactRecords::Skip {
            // Decided at render time by an exact shadow ray: no direction,
            // no ray, nothing lit here.
            rec.set_light(i, LightVisibility::Translucent);
            report.translucent = report.translucent.saturating_add(1);
            continue;
        }
        let to_light = sub(light.position, c0);
        // N·L from the unit direction to the light; without it where the
        // stored normal clearly faces away (any negative N·L decides as
        // this one would: no light, occluded on a closed shape, the back
        // side's ray on an open one). Computed when first needed: the
        // shadow classification does not read it, only a lit voxel's
        // illumination does.
        let mut known = None;
        let mut n_dot_l = || {
            *known.get_or_insert_with(|| {
                if facing_away(normal, to_light) {
                    (true, -1)
                } else {
                    let l = normalize(to_light);
                    (l.is_some(), l.map_or(0, |l| dot_unit(normal, l)))
                }
            })
        };
        let vis = match (exact, params.exact_records) {
            (true, _) if dark_side(shape_of(objects), own, v, light.position) => {
                report.dark_side = report.dark_side.saturating_add(1);
                LightVisibility::Translucent
            }
            (true, _) if proofs.lit(v, i, light.position)? => {
                report.brick_proofs = report.brick_proofs.saturating_add(1);
                LightVisibility::Visible
            }
            (true, _) => {
                report.rays = report.rays.saturating_add(1);
                classify(
                    raster,
                    view,
                    v,
                    own,
                    shape_of(objects),
                    opaque_sphere_of(objects, materials),
                    light.position,
                    found.as_deref_mut(),
                )?
            }
            (false, _) => {
                let (lit_dir, ndl) = n_dot_l();
                let side = if ndl > 0 {
                    normal
                } else if closed || ndl == 0 {
                    if lit_dir {
                        report.facing_away = report.facing_away.saturating_add(1);
                        rec.set_light(i, LightVisibility::Occluded);
                        continue;
                    }
                    // The light sits at the voxel centre: nothing can block it.
                    normal
                } else {
                    normal.map(i32::wrapping_neg)
                };
                report.rays = report.rays.saturating_add(1);
                shadow_ray(
                    raster,
                    view,
                    materials,
                    params,
                    start,
                    c0,
                    light.position,
                    side,
                    (rec.normal, normal),
                    owner,
                )?
            }
        };
        rec.set_light(i, vis);
        match vis {
            LightVisibility::Visible => {
                report.visible = report.visible.saturating_add(1);
                let (_, ndl) = n_dot_l();
                if ndl > 0 {
                    let ndl = u128::from(ndl.unsigned_abs());
                    for (a, c) in acc.iter_mut().zip(light.color.iter()) {
                        // I·L (2^-32) · N·L (2^-30) >> 30: 2^-32, < 2^66.
                        let term = u128::from(light.intensity)
                            .saturating_mul(u128::from(*c))
                            .saturating_mul(ndl)
                            >> 30;
                        *a = a.saturating_add(term);
                    }
                }
            }
            LightVisibility::Translucent => {
                report.translucent = report.translucent.saturating_add(1);
            }
            LightVisibility::Occluded | LightVisibility::Reserved => {
                report.occluded = report.occluded.saturating_add(1);
            }
        }
    }
    for ((out, a), c) in rec.illum.iter_mut().zip(acc.iter()).zip(rec.color.iter()) {
        // C (0..255) · Kd (2^-16) · acc (2^-32) → 0..255 after >> 48, rounded.
        let x = u128::from(*c)
            .saturating_mul(u128::from(kd))
            .saturating_mul(*a)
            .saturating_add(1 << 47)
            >> 48;
        *out = u8::try_from(x.min(255)).unwrap_or(u8::MAX);
    }
    Ok(rec)
}

/// Whether every object of `own` (at least one) is a sphere and voxel
/// `v`'s closed cube lies wholly on the dark side of each for a light at
/// `light` (module docs, *Dark side*).
///
/// A point `p` of a sphere of centre `C` and radius `R` faces a light at `L`
/// exactly when `(p − C)·(L − C) > R²` (it lies beyond the plane of the
/// terminator). The linear function `(q − C)·(L − C)` is largest over the
/// cube at one corner; the cube is on the dark side when that corner's value
/// stays below `R²` by a margin that covers the rounding of `C`, `R` and `L`
/// to fixed point by up to one unit per coordinate (the renderer's spheres
/// and lights are the exact ones).
fn dark_side(
    shape: impl Fn(u32) -> Option<Shape>,
    own: &[u32],
    v: [u32; 3],
    light: [i64; 3],
) -> bool {
    !own.is_empty()
        && own.iter().all(|&id| match shape(id) {
            Some(Shape::Sphere(s)) => cube_beyond_terminator(&s, v, light),
            _ => false,
        })
}

/// The fixed-point shape of object `id` of `objects`.
fn shape_of<'t>(objects: &'t ObjectTable<'_>) -> impl Fn(u32) -> Option<Shape> + 't {
    |id| Some(objects.get(id)?.shape)
}

/// The fixed-point sphere of object `id` of `objects` when its material
/// lets no light through (transmission 0), `None` for every other object.
fn opaque_sphere_of<'t, const N: usize>(
    objects: &'t ObjectTable<'_>,
    materials: &'t Materials<N>,
) -> impl Fn(u32) -> Option<Sphere> + 't {
    |id| {
        let o = objects.get(id)?;
        match o.shape {
            Shape::Sphere(s) if materials.get(o.material)?.transmission == 0 => Some(s),
            _ => None,
        }
    }
}

/// Half the diagonal of a voxel's cube, rounded up: every point of the
/// closed cube lies within it of the centre (√3/2 · 2^16 < 56756).
const HALF_DIAGONAL: i128 = 56_756;

/// What [`sphere_clears`] adds to a sphere's radius (and [`triangle_clears`]
/// to the cube's sides) for the rounding of
/// the renderer's exact sphere and light to fixed point (under one unit
/// per coordinate, and under 2^-11 voxel for a light taken by its
/// direction) and of the shading point to its voxel: 1/256 voxel.
const CLEARANCE_MARGIN_UNITS: i64 = VOXEL / 256;

/// [`CLEARANCE_MARGIN_UNITS`] in 128 bits, as the sphere tests use it.
const CLEARANCE_MARGIN: i128 = CLEARANCE_MARGIN_UNITS as i128;

/// The least shift that brings `big` below 2^28 (at most 100).
#[inline(always)]
fn shift_below_2_28(big: u128) -> u32 {
    128u32
        .saturating_sub(big.leading_zeros())
        .saturating_sub(28)
}

/// The offsets of a sphere's centre (`w`) and of the light (`u`) from
/// voxel `v`'s centre.
#[inline(always)]
fn offsets(s: &Sphere, v: [u32; 3], light: [i64; 3]) -> ([i128; 3], [i128; 3]) {
    let c = v.map(voxel_centre);
    let off = |p: [i64; 3]| -> [i128; 3] {
        core::array::from_fn(|k| i128::from(p[k]).saturating_sub(i128::from(c[k])))
    };
    (off(s.centre), off(light))
}

/// `w` and `u` shifted right by the least shift that brings every
/// coordinate of both below 2^28, and that shift.
#[inline(always)]
fn shifted(w: [i128; 3], u: [i128; 3]) -> ([i128; 3], [i128; 3], u32) {
    let big = w
        .iter()
        .chain(u.iter())
        .map(|x| x.unsigned_abs())
        .max()
        .unwrap_or(0);
    let shift = shift_below_2_28(big);
    (w.map(|x| x >> shift), u.map(|x| x >> shift), shift)
}

/// The dot product, saturating.
#[inline(always)]
fn dot3(a: [i128; 3], b: [i128; 3]) -> i128 {
    a.iter().zip(b.iter()).fold(0i128, |acc, (x, y)| {
        acc.saturating_add(x.saturating_mul(*y))
    })
}

/// The squared distance from point `w` to the segment from the origin to
/// `u` against `r2`: [`Ordering::Greater`](core::cmp::Ordering) when it
/// is larger. Exact for coordinates below 2^28 and `r2` below 2^58.
#[inline(always)]
fn segment_distance_cmp(w: [i128; 3], u: [i128; 3], r2: i128) -> core::cmp::Ordering {
    let (uu, wu) = (dot3(u, u), dot3(w, u));
    if wu <= 0 {
        // Nearest the segment's start.
        return dot3(w, w).cmp(&r2);
    }
    if wu >= uu {
        // Nearest the segment's end.
        let d = [0, 1, 2].map(|k| w[k].saturating_sub(u[k]));
        return dot3(d, d).cmp(&r2);
    }
    // Within: |w × u|² / |u|² is the squared distance to the line.
    let x = [
        w[1].saturating_mul(u[2])
            .saturating_sub(w[2].saturating_mul(u[1])),
        w[2].saturating_mul(u[0])
            .saturating_sub(w[0].saturating_mul(u[2])),
        w[0].saturating_mul(u[1])
            .saturating_sub(w[1].saturating_mul(u[0])),
    ];
    dot3(x, x).cmp(&r2.saturating_mul(uu))
}

/// Whether sphere `s` (of positive radius) provably meets no segment from
/// a point of voxel `v`'s closed cube to the light at `light`, with
/// [`CLEARANCE_MARGIN`] to spare: the segment from `v`'s centre `C` to
/// `L` stays farther than `R + HALF_DIAGONAL + CLEARANCE_MARGIN` from the
/// sphere's centre. Such a segment from a cube point `p` is within
/// `HALF_DIAGONAL` of it everywhere (`p + t(L − p)` is `(1 − t)(p − C)`
/// from `C + t(L − C)`), so it passes outside the sphere.
///
/// Integer arithmetic without overflow: the offsets of the sphere's centre
/// and the light from `C` are shifted right until every coordinate is
/// below 2^28; the floors move the centre and the segment by under `2√3`
/// shifted units, which the required clearance adds (4).
fn sphere_clears(s: &Sphere, v: [u32; 3], light: [i64; 3]) -> bool {
    // A table that holds no valid sphere proves nothing.
    if s.radius <= 0 {
        return false;
    }
    let (w, u) = offsets(s, v, light);
    let (w, u, shift) = shifted(w, u);
    let need = i128::from(s.radius)
        .saturating_add(HALF_DIAGONAL)
        .saturating_add(CLEARANCE_MARGIN);
    // ⌈need / 2^shift⌉ + 4, in shifted units.
    let step = 1i128 << shift;
    let need = need.saturating_add(step.saturating_sub(1)) >> shift;
    let need = need.saturating_add(4);
    if need >= 1 << 29 {
        return false;
    }
    segment_distance_cmp(w, u, need.saturating_mul(need)).is_gt()
}

/// Bound on the offsets of a triangle's vertices from a voxel's low
/// corner for [`triangle_clears`]: 2^29 units (8,192 voxels).
const TRIANGLE_REACH: u64 = 1 << 29;

/// Bound on the light's offset from a voxel's low corner for
/// [`triangle_clears`]: 2^50 units (2^34 voxels).
const LIGHT_REACH: u64 = 1 << 50;

/// `a · b`, exactly, in 128 bits.
#[inline(always)]
fn wide(a: i64, b: i64) -> i128 {
    i128::from(a).wrapping_mul(i128::from(b))
}

/// Whether triangle `t` provably meets no segment from a point of voxel
/// `v`'s closed cube, grown by [`CLEARANCE_MARGIN`] on every side (for the
/// rounding of the renderer's exact triangle and light to fixed point and
/// of the shading point to its voxel, as in [`sphere_clears`]), to the
/// light at `light`.
///
/// A segment from `p` to `L` meets `t` exactly when `p` lies in `t`'s
/// *shadow volume* from `L`: on the far side of `t`'s plane from `L` (or
/// on it), and on `t`'s side of each of the three planes through `L` and
/// an edge of `t` (or on it). The triangle is cleared when the grown cube
/// lies strictly outside one of those four closed half-spaces (every
/// corner outside it): on the light's side of the triangle's plane, with
/// the light off that plane by the margin; or beyond one of the planes
/// through the light and an edge.
///
/// Exact: with the vertices within [`TRIANGLE_REACH`] and the light within
/// [`LIGHT_REACH`] of the voxel's low corner (anything farther is not
/// cleared), edges are below 2^30, the triangle's normal below 2^61, an
/// edge plane's normal below 2^83 and every product formed below 2^114,
/// so the wrapping arithmetic never wraps.
fn triangle_clears(t: &Triangle, v: [u32; 3], light: [i64; 3]) -> bool {
    // The voxel's low corner: below 2^48.
    let lo: [i64; 3] = v.map(|k| i64::from(k).wrapping_mul(VOXEL));
    // Offsets from it, `None` beyond `reach`.
    let rel = |p: [i64; 3], reach: u64| -> Option<[i64; 3]> {
        let mut out = [0i64; 3];
        for ((o, &x), &c) in out.iter_mut().zip(p.iter()).zip(lo.iter()) {
            *o = x.checked_sub(c).filter(|d| d.unsigned_abs() < reach)?;
        }
        Some(out)
    };
    let (Some(d0), Some(d1), Some(d2), Some(l)) = (
        rel(t.vertices[0], TRIANGLE_REACH),
        rel(t.vertices[1], TRIANGLE_REACH),
        rel(t.vertices[2], TRIANGLE_REACH),
        rel(light, LIGHT_REACH),
    ) else {
        return false;
    };
    let d = [d0, d1, d2];
    let diff = |a: [i64; 3], b: [i64; 3]| -> [i64; 3] {
        [
            a[0].wrapping_sub(b[0]),
            a[1].wrapping_sub(b[1]),
            a[2].wrapping_sub(b[2]),
        ]
    };
    // The grown cube, relative to the voxel's low corner: [b0, b1] per axis.
    let (b0, b1) = (
        CLEARANCE_MARGIN_UNITS.wrapping_neg(),
        VOXEL.wrapping_add(CLEARANCE_MARGIN_UNITS),
    );
    // The largest value of a·(p − q) over the grown cube: at the corner
    // whose bound on each axis the coefficient's sign picks.
    let box_max = |a: [i128; 3], q: [i64; 3]| -> i128 {
        (0..3).fold(0i128, |acc, k| {
            let b = if a[k] > 0 { b1 } else { b0 };
            acc.wrapping_add(a[k].wrapping_mul(i128::from(b.wrapping_sub(q[k]))))
        })
    };
    // `a`, or `−a` where the light lies on the positive side of the
    // triangle's plane.
    let away = |a: [i128; 3], positive: bool| -> [i128; 3] {
        if positive {
            a.map(i128::wrapping_neg)
        } else {
            a
        }
    };
    // The triangle's plane: n = (d1 − d0) × (d2 − d0), each component a
    // difference of two products below 2^60.
    let (e1, e2) = (diff(d1, d0), diff(d2, d0));
    let n: [i64; 3] = [
        e1[1]
            .wrapping_mul(e2[2])
            .wrapping_sub(e1[2].wrapping_mul(e2[1])),
        e1[2]
            .wrapping_mul(e2[0])
            .wrapping_sub(e1[0].wrapping_mul(e2[2])),
        e1[0]
            .wrapping_mul(e2[1])
            .wrapping_sub(e1[1].wrapping_mul(e2[0])),
    ];
    let to_light = diff(l, d0);
    let at_light = (0..3).fold(0i128, |acc, k| acc.wrapping_add(wide(n[k], to_light[k])));
    let l1 = n.iter().fold(0i128, |acc, x| {
        acc.wrapping_add(i128::from(x.unsigned_abs()))
    });
    if at_light.wrapping_abs() <= l1.wrapping_mul(CLEARANCE_MARGIN) {
        // The light (nearly) in the triangle's plane: no proof.
        return false;
    }
    let positive = at_light > 0;
    // Every point of the grown cube strictly on the light's side:
    // −s·n·(p − d0) < 0 everywhere, s the sign of n·(L − d0).
    if box_max(away(n.map(i128::from), positive), d0) < 0 {
        return true;
    }
    // The plane through the light and edge (d_i, d_j), normal m = (d_i −
    // L) × (d_j − d_i); the triangle lies on the side where m·(p − d_i)
    // has the sign of m·(d_k − d_i) = (d_i − L)·n = −n·(L − d0), the
    // opposite of `s` (for the three edges in cyclic order,
    // (d_j − d_i) × (d_k − d_i) = n). m is normal to d_i − L, so
    // m·(p − d_i) is m·(p − L).
    [(0, 1), (1, 2), (2, 0)].iter().any(|&(i, j)| {
        let u = diff(d[i], l);
        let e = diff(d[j], d[i]);
        let m = [
            wide(u[1], e[2]).wrapping_sub(wide(u[2], e[1])),
            wide(u[2], e[0]).wrapping_sub(wide(u[0], e[2])),
            wide(u[0], e[1]).wrapping_sub(wide(u[1], e[0])),
        ];
        // The cube beyond the plane: −s·m·(p − d_i) < 0 everywhere.
        box_max(away(m, positive), d[i]) < 0
    })
}

/// What [`sphere_blocks`] keeps between a sphere's surface and the
/// segments it proves blocked, and between the sphere and the voxel's
/// cube: half a voxel. It covers the renderer's exact shadow segment,
/// which starts ε off the surface in the voxel and ends `2ε` short of the
/// light in the direction from the hit point (within `3ε` of the segment
/// from its start to the light, ε under an eighth of a voxel where the
/// renderer reads the classification), the shading point's rounding to
/// its voxel and the rounding of the sphere and the light to fixed point
/// ([`CLEARANCE_MARGIN`]).
const BLOCK_MARGIN: i128 = (VOXEL as i128) / 2;

/// Whether sphere `s` (of positive radius) provably blocks every segment
/// from a point of voxel `v`'s closed cube to the light at `light`: the
/// segment from `v`'s centre `C` to `L` passes within `R − HALF_DIAGONAL −
/// BLOCK_MARGIN` of the sphere's centre, while `C` lies farther than `R +
/// HALF_DIAGONAL + BLOCK_MARGIN` from it, and the ball with its margin lies
/// inside the raster box of `dims`. A segment from a cube point `p` (or
/// within [`BLOCK_MARGIN`] of one) is everywhere within `HALF_DIAGONAL +
/// BLOCK_MARGIN` of the centre's (as in [`sphere_clears`]), so it passes
/// through the sphere's interior, entering it at a positive distance from
/// `p` and inside the raster, where a walk along it meets a voxel that
/// lists the sphere.
///
/// Integer arithmetic without overflow: the cube's distance and the
/// direction exactly; the segment's distance shifted as in
/// [`sphere_clears`], whose floors move the centre and the segment by
/// under `2√3` shifted units, which the bound gives away (4).
fn sphere_blocks(s: &Sphere, v: [u32; 3], light: [i64; 3], dims: [u32; 3]) -> bool {
    let r = i128::from(s.radius);
    let inner = r.saturating_sub(HALF_DIAGONAL).saturating_sub(BLOCK_MARGIN);
    if inner <= 0 {
        return false;
    }
    let (w, u) = offsets(s, v, light);
    // The cube outside, and the sphere ahead of it towards the light
    // (first: most spheres met in a tube touch the voxel). Unshifted: the
    // products of the offsets (below 2^64) saturate only where the sphere
    // lies far outside the raster, which the next test refuses, and a
    // saturated direction test only refuses.
    let outer = r.saturating_add(HALF_DIAGONAL).saturating_add(BLOCK_MARGIN);
    if dot3(w, w) <= outer.saturating_mul(outer) || dot3(w, u) <= 0 {
        return false;
    }
    let reach = r.saturating_add(BLOCK_MARGIN);
    let inside = (0..3).all(|k| {
        let (Some(&c), Some(&n)) = (s.centre.get(k), dims.get(k)) else {
            return false;
        };
        let c = i128::from(c);
        c.saturating_sub(reach) >= 0
            && c.saturating_add(reach) <= i128::from(n).saturating_mul(i128::from(VOXEL))
    });
    if !inside {
        return false;
    }
    let (w, u, shift) = shifted(w, u);
    // The segment's distance, rounded down, less 4 (shifted units).
    let inner = (inner >> shift).saturating_sub(4);
    inner > 0 && segment_distance_cmp(w, u, inner.saturating_mul(inner)).is_lt()
}

/// Whether one of `objects` outside `own` is a sphere of `blocker` that
/// blocks every segment from voxel `v`'s cube to the light
/// ([`sphere_blocks`]). Out of line: a classification asks at most once,
/// where its walk ends.
#[inline(never)]
fn blocks_all(
    objects: &[u32],
    own: &[u32],
    blocker: impl Fn(u32) -> Option<Sphere>,
    v: [u32; 3],
    light: [i64; 3],
    dims: [u32; 3],
) -> bool {
    objects.iter().any(|&o| {
        !own.contains(&o) && blocker(o).is_some_and(|s| sphere_blocks(&s, v, light, dims))
    })
}

/// The test of [`dark_side`] for one sphere.
fn cube_beyond_terminator(s: &Sphere, v: [u32; 3], light: [i64; 3]) -> bool {
    let mut f: i128 = 0;
    // Σ|q − C| over the axes at the chosen corner, and Σ|L − C|.
    let mut spread: i128 = 0;
    let mut reach: i128 = 0;
    for k in 0..3 {
        let (Some(&c), Some(&l), Some(&vk)) = (s.centre.get(k), light.get(k), v.get(k)) else {
            return false;
        };
        let (c, l) = (i128::from(c), i128::from(l));
        let lo = i128::from(vk).saturating_mul(i128::from(VOXEL));
        let d = l.saturating_sub(c);
        let q = if d > 0 {
            lo.saturating_add(i128::from(VOXEL))
        } else {
            lo
        };
        let w = q.saturating_sub(c);
        f = f.saturating_add(w.saturating_mul(d));
        spread = spread.saturating_add(w.saturating_abs());
        reach = reach.saturating_add(d.saturating_abs());
    }
    let r = i128::from(s.radius);
    // With C', L' within one unit per axis, (q − C')·(L' − C') differs from
    // f by at most 2·spread + reach + 6, and another corner can be the
    // farthest only on an axis where |L − C| ≤ 2, by at most 2·VOXEL there;
    // R'² ≥ R² − 2R + 1.
    let margin = spread
        .saturating_mul(2)
        .saturating_add(reach)
        .saturating_add(r.saturating_mul(2))
        .saturating_add(i128::from(VOXEL).saturating_mul(6))
        .saturating_add(8);
    f.saturating_add(margin) <= r.saturating_mul(r)
}

/// Whether the unit normal `n` ([`NORMAL_ONE`]-scaled) surely faces away
/// from direction `d`: `n·d < −2·|d|₁`. Then `dot_unit(n, normalize(d))`
/// is negative: each component of `normalize(d)` is within one unit of
/// `2^30·d/|d|` (and 2^-9 more for the truncation of components beyond
/// 40 bits), which moves the sum of products by at most `1.01·|n|₁ <
/// 2^31`, while `2^30·n·d/|d| < −2^31` (as `|d| ≤ |d|₁`).
fn facing_away(n: [i32; 3], d: [i64; 3]) -> bool {
    let (mut dot, mut l1) = (0i128, 0i128);
    for (a, b) in n.iter().zip(d.iter()) {
        // |a| ≤ 2^30, |b| < 2^63: each product below 2^93.
        dot = dot.saturating_add(i128::from(*a).saturating_mul(i128::from(*b)));
        l1 = l1.saturating_add(i128::from(b.unsigned_abs()));
    }
    dot < l1.saturating_mul(-2)
}

/// `a − b` per axis, saturating.
fn sub(a: [i64; 3], b: [i64; 3]) -> [i64; 3] {
    [
        a[0].saturating_sub(b[0]),
        a[1].saturating_sub(b[1]),
        a[2].saturating_sub(b[2]),
    ]
}

/// Whether fixed-point point `p` lies in the raster box.
fn inside_box(extent: Extent, p: [i64; 3]) -> bool {
    p.iter()
        .zip(extent.dims())
        .all(|(c, n)| *c >= 0 && *c < i64::from(n).saturating_mul(VOXEL))
}

/// Outcome of walking one shadow ray piece.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Piece {
    Clear,
    Blocked,
}

#[allow(clippy::too_many_arguments)] // one ray's context
fn shadow_ray<const N: usize>(
    raster: &Raster<'_>,
    view: &RecordStore<'_>,
    materials: &Materials<N>,
    params: &LightParams,
    start: Option<usize>,
    c0: [i64; 3],
    light: [i64; 3],
    side: [i32; 3],
    (stored, stored_normal): ([i16; 2], [i32; 3]),
    object: u32,
) -> Result<LightVisibility, LightError> {
    let extent = raster.extent();
    let mut translucent = false;
    let rule = LeavingSurface {
        start,
        c0,
        side,
        stored,
        stored_normal: Some(stored_normal),
        object,
        slab: params.slab,
        same_surface_cos: params.same_surface_cos,
    };
    // Transparent voxels, most of a walk, are decided here; an opaque one
    // out of line, so that the stepper's loop stays small.
    let mut test = |index: usize, c: u8| -> bool {
        c & cell::OPAQUE != 0 && blocks(view, materials, &rule, index, c, &mut translucent)
    };
    let outcome = to_light(extent, c0, light, |ray| {
        walk_piece(raster, params.mode, ray, &mut test)
    })?;
    Ok(match (outcome, translucent) {
        (Piece::Blocked, _) => LightVisibility::Occluded,
        (Piece::Clear, true) => LightVisibility::Translucent,
        (Piece::Clear, false) => LightVisibility::Visible,
    })
}

/// Whether the opaque voxel at `index` (cell `c`) blocks a shadow ray
/// leaving a surface by `rule`: not when it is part of that surface, nor
/// when its material transmits light (then `translucent` is set). A voxel
/// without a record blocks.
#[inline(never)]
fn blocks<const N: usize>(
    view: &RecordStore<'_>,
    materials: &Materials<N>,
    rule: &LeavingSurface,
    index: usize,
    c: u8,
    translucent: &mut bool,
) -> bool {
    let Some(vb) = view.extent().coord(index) else {
        return true;
    };
    // The cell's rank hint narrows the lookup; the record is the same.
    let Some(b) = view.get_hinted(vb, c) else {
        return true;
    };
    if Some(index) == rule.start || rule.ignores_voxel(view, vb, b) {
        return false;
    }
    if materials
        .get(b.material)
        .is_some_and(|m| m.transmission > 0)
    {
        *translucent = true;
        return false;
    }
    true
}

/// The shadow classification of the voxel `v` holding record `rec` for a
/// light at `light` (fixed units), as the light pass computes it for a
/// record all of whose objects have exact geometry
/// ([`ExactRecords::Classify`], module docs, *Shadow classification* and
/// *Dark side*): [`LightVisibility::Visible`] when only `rec`'s own objects
/// can stand between any point of the voxel's closed cube and the light,
/// [`LightVisibility::Occluded`] when an opaque sphere met in the tube
/// blocks every segment from the cube to the light,
/// [`LightVisibility::Translucent`] (undecided) otherwise, and undecided
/// without a walk when the cube lies wholly on the dark side of its
/// objects, all spheres. `shape` gives the fixed-point shape of an
/// object by id, as the object table holds it (`None` where it is not
/// known): its spheres decide the dark side, and its spheres and
/// triangles which foreign objects in the tube stand clear of the cube's
/// segments to the light. `blocker` gives
/// the same sphere for the objects whose material lets no light through
/// (transmission 0), `None` for every other object: those may prove the
/// voxel occluded. A renderer that
/// skipped the classification in the pass ([`ExactRecords::Skip`])
/// computes it here for the voxels its hits need;
/// the answer depends on nothing but the raster, the store, the shapes,
/// `v` and the light, so it may be memoized and computed in any order. The
/// caller checks that the objects are exact. The raster's brick level
/// (`bricks`, [`bricks::shadow_bricks`]), when given, is tried before the
/// voxel's own walk; it never changes the answer.
///
/// Work: one walk of the brick tube and at most one of the segment's
/// tube, bounded by the raster's size.
///
/// # Errors
/// [`LightError::ExtentMismatch`] if `raster`, `store` and `bricks` differ
/// in size; [`LightError::Ray`] for a light beyond the fixed-point range.
#[allow(clippy::too_many_arguments)] // the voxel, its light, and what the proofs read
pub fn classify_voxel(
    raster: &Raster<'_>,
    store: &RecordStore<'_>,
    bricks: Option<&ShadowBricks<'_>>,
    shape: impl Fn(u32) -> Option<Shape>,
    blocker: impl Fn(u32) -> Option<Sphere>,
    v: [u32; 3],
    rec: &VoxelRecord,
    light: [i64; 3],
) -> Result<LightVisibility, LightError> {
    let extent = raster.extent();
    if store.extent() != extent || bricks.is_some_and(|b| b.extent() != extent) {
        return Err(LightError::ExtentMismatch);
    }
    let own = store.objects(rec);
    if dark_side(&shape, own, v, light) {
        return Ok(LightVisibility::Translucent);
    }
    if let Some(b) = bricks
        && b.proves_lit(v, light)?
    {
        return Ok(LightVisibility::Visible);
    }
    classify(raster, store, v, own, shape, blocker, light, None)
}

/// The shadow classification of voxel `v` (objects `own`) for a light at
/// `light` (module docs, *Shadow classification*):
/// [`LightVisibility::Visible`] when every non-transparent voxel within
/// chessboard distance 1 of the 6-connected segment from `v`'s centre to
/// the light holds only objects of `own` and spheres and triangles
/// (`shape`) that no segment from the cube to the light meets
/// ([`sphere_clears`], [`triangle_clears`]);
/// [`LightVisibility::Occluded`] when a foreign object of the first
/// voxel of the tube that holds any is a sphere of `blocker` that blocks
/// every such segment ([`sphere_blocks`]); else
/// [`LightVisibility::Translucent`] (undecided: a render-time shadow ray
/// decides). A voxel without a record undecides too.
#[allow(clippy::too_many_arguments)] // the voxel, its light, and what the walk reads
fn classify(
    raster: &Raster<'_>,
    view: &RecordStore<'_>,
    v: [u32; 3],
    own: &[u32],
    shape: impl Fn(u32) -> Option<Shape>,
    blocker: impl Fn(u32) -> Option<Sphere>,
    light: [i64; 3],
    mut found: Option<&mut FoundRecords>,
) -> Result<LightVisibility, LightError> {
    let c0 = v.map(voxel_centre);
    let extent = raster.extent();
    let plane = raster.plane();
    // The voxel tested last: when the walk moves to a face neighbour of
    // it, only the new face of the neighbourhood needs a look (the rest
    // was found to hold only `own` objects). A voxel of the path between
    // two tested voxels that are not neighbours is not within 1 of an
    // opaque voxel, so every opaque voxel near the path is looked up once.
    let mut last: Option<(usize, [u32; 3])> = None;
    let strides = extent.strides();
    let signed = strides.map(usize::cast_signed);
    let dims = extent.dims();
    let own_index = extent.index(v);
    // The last objects found clear of every segment from the cube to the
    // light ([`sphere_clears`], [`triangle_clears`]), replaced in turn:
    // neighbouring tube voxels mostly hold them (a mesh's few triangles
    // near the voxel).
    let cleared = core::cell::Cell::new([u32::MAX; CLEARED]);
    let next_slot = core::cell::Cell::new(0usize);
    let clear = |o: u32| -> bool {
        if cleared.get().contains(&o) {
            return true;
        }
        let yes = match shape(o) {
            Some(Shape::Sphere(s)) => sphere_clears(&s, v, light),
            Some(Shape::Triangle(t)) => triangle_clears(&t, v, light),
            _ => false,
        };
        if yes {
            let mut ids = cleared.get();
            let at = next_slot.get() % CLEARED;
            if let Some(slot) = ids.get_mut(at) {
                *slot = o;
            }
            cleared.set(ids);
            next_slot.set(at.wrapping_add(1));
        }
        yes
    };
    // The objects of the voxel where the walk found a foreign object,
    // asked after the walk whether one blocks every segment from the cube
    // to the light ([`sphere_blocks`]).
    let foreign_objects: core::cell::Cell<&[u32]> = core::cell::Cell::new(&[]);
    // Whether the opaque voxel `w` (cell `c`) has no record or holds an
    // object not in `own` that may meet a segment from the cube to the
    // light.
    let mut holds_foreign = |wi: usize, w: [u32; 3], c: u8| -> bool {
        let rec = match found.as_deref_mut() {
            Some(memo) => memo.get(view, wi, w, c),
            None => view.get_hinted(w, c),
        };
        rec.is_none_or(|rec| {
            let objects = view.objects(rec);
            let foreign = !objects.iter().all(|&o| own.contains(&o) || clear(o));
            if foreign {
                foreign_objects.set(objects);
            }
            foreign
        })
    };
    let mut foreign = |index: usize, _: u8| -> bool {
        let (u, from) = match last.and_then(|(at, p)| face_step(extent, strides, at, p, index)) {
            Some((u, step)) => (u, Some(step)),
            None => match extent.coord(index) {
                Some(u) => (u, None),
                None => return true,
            },
        };
        last = Some((index, u));
        let interior = (0..3).all(|k| u[k] > 0 && u[k].saturating_add(1) < dims[k]);
        if interior {
            // Every neighbour is inside the raster: counted loops over
            // the offsets, no clipping.
            // The neighbours at offsets `lo..hi` on axis `k` and −1..2 on
            // the other two.
            let mut scan = |k: usize, lo: i8, hi: i8| -> bool {
                let k = k.min(2);
                let (j1, j2) = match k {
                    0 => (1, 2),
                    1 => (0, 2),
                    _ => (0, 1),
                };
                for a in lo..hi {
                    let ka = isize::from(a).wrapping_mul(signed[k]);
                    for b in -1i8..2 {
                        let jb = ka.wrapping_add(isize::from(b).wrapping_mul(signed[j1]));
                        for d in -1i8..2 {
                            let wi = index
                                .wrapping_add_signed(jb)
                                .wrapping_add_signed(isize::from(d).wrapping_mul(signed[j2]));
                            let c = plane.get(wi).copied().unwrap_or(0);
                            if c & cell::OPAQUE == 0 || Some(wi) == own_index {
                                continue;
                            }
                            let mut w = u;
                            w[k] = w[k].wrapping_add_signed(i32::from(a));
                            w[j1] = w[j1].wrapping_add_signed(i32::from(b));
                            w[j2] = w[j2].wrapping_add_signed(i32::from(d));
                            if holds_foreign(wi, w, c) {
                                return true;
                            }
                        }
                    }
                }
                false
            };
            return match from {
                Some((k, true)) => scan(k, 1, 2),
                Some((k, false)) => scan(k, -1, 0),
                None => scan(2, -1, 2),
            };
        }
        let [xs, ys, zs] = neighbour_offsets(extent, u, from);
        for dz in zs {
            for dy in ys.clone() {
                for dx in xs.clone() {
                    // Inside the raster by the offsets' ranges.
                    let wi = index
                        .wrapping_add_signed(isize::from(dz).wrapping_mul(signed[2]))
                        .wrapping_add_signed(isize::from(dy).wrapping_mul(signed[1]))
                        .wrapping_add_signed(isize::from(dx));
                    let c = plane.get(wi).copied().unwrap_or(0);
                    if c & cell::OPAQUE == 0 || Some(wi) == own_index {
                        continue;
                    }
                    let w = [
                        u[0].wrapping_add_signed(i32::from(dx)),
                        u[1].wrapping_add_signed(i32::from(dy)),
                        u[2].wrapping_add_signed(i32::from(dz)),
                    ];
                    if holds_foreign(wi, w, c) {
                        return true;
                    }
                }
            }
        }
        false
    };
    let outcome = to_light(extent, c0, light, |ray| {
        let Some(mut ray) = ray else {
            return Ok(Piece::Clear);
        };
        Ok(match ray.walk_dilated(raster, u32::MAX, &mut foreign)? {
            WalkEnd::Hit => Piece::Blocked,
            WalkEnd::Exit | WalkEnd::Budget => Piece::Clear,
        })
    })?;
    Ok(match outcome {
        Piece::Clear => LightVisibility::Visible,
        Piece::Blocked if blocks_all(foreign_objects.get(), own, &blocker, v, light, dims) => {
            LightVisibility::Occluded
        }
        Piece::Blocked => LightVisibility::Translucent,
    })
}

/// How many of the objects last cleared a classification remembers.
const CLEARED: usize = 8;

/// The offsets (per axis, each in −1..=1) of the voxels within chessboard
/// distance 1 of `u` inside `extent` (`u` among them); with
/// `from = Some((axis, up))`, for `u` entered from its face neighbour
/// below (`up`) or above on `axis`, only of those not within distance 1 of
/// that neighbour: the nine on `u`'s far side.
fn neighbour_offsets(
    extent: Extent,
    u: [u32; 3],
    from: Option<(usize, bool)>,
) -> [core::ops::RangeInclusive<i8>; 3] {
    let dims = extent.dims();
    core::array::from_fn(|k| {
        let (c, n) = (u[k], dims[k]);
        let lo: i8 = if c > 0 { -1 } else { 0 };
        let hi: i8 = if c.saturating_add(1) < n { 1 } else { 0 };
        // The far side only, which is empty where `u` lies on the
        // raster's face (then `0..=-1` or `1..=0`).
        match from {
            Some((axis, true)) if axis == k => hi..=hi.wrapping_mul(2).wrapping_sub(1),
            Some((axis, false)) if axis == k => lo.wrapping_mul(2).wrapping_add(1)..=lo,
            _ => lo..=hi,
        }
    })
}

/// The voxel at `index` with the axis and direction (`true`: up) of the
/// step to it from voxel `p` (at index `at`), when they are face
/// neighbours; found from the index difference, without a division (a
/// voxel inside the raster whose index is `index` is the voxel at `index`).
fn face_step(
    extent: Extent,
    strides: [usize; 3],
    at: usize,
    p: [u32; 3],
    index: usize,
) -> Option<([u32; 3], (usize, bool))> {
    let d = index.wrapping_sub(at);
    let dims = extent.dims();
    (0..3).find_map(|k| {
        let (stride, c, n) = (*strides.get(k)?, *p.get(k)?, *dims.get(k)?);
        let (c, up) = if d == stride {
            (c.checked_add(1)?, true)
        } else if d == stride.wrapping_neg() {
            (c.checked_sub(1)?, false)
        } else {
            return None;
        };
        if c >= n {
            return None;
        }
        let mut u = p;
        *u.get_mut(k)? = c;
        Some((u, (k, up)))
    })
}

/// The acne rule of the module docs, for any ray that leaves a surface
/// voxel: the light pass's shadow rays, and the renderer's reflected,
/// refracted and render-time shadow rays, so that one rule decides for all
/// of them which voxels of the surface being left do not count as hits.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct LeavingSurface {
    /// Linear index of the voxel the ray leaves (never a hit).
    pub start: Option<usize>,
    /// Centre of that voxel, fixed units.
    pub c0: [i64; 3],
    /// Unit normal ([`NORMAL_ONE`]-scaled) of the side the ray leaves
    /// towards: heights are measured along it.
    pub side: [i32; 3],
    /// The stored normal of the voxel left, encoded as in
    /// [`VoxelRecord::normal`] (for the same-surface test; decoded only
    /// when a voxel of another object is met).
    pub stored: [i16; 2],
    /// `decode_normal(stored)`, when the caller has it at hand (the light
    /// pass, which decodes every record's normal anyway); `None` decodes
    /// it when the same-surface test needs it. Any other value makes that
    /// test wrong.
    pub stored_normal: Option<[i32; 3]>,
    /// The owner of the voxel left ([`RecordStore::owner`]).
    pub object: u32,
    /// Height above the tangent plane, fixed units, below which voxels of
    /// the same surface are ignored ([`LightParams::slab`]).
    pub slab: i64,
    /// [`LightParams::same_surface_cos`].
    pub same_surface_cos: i32,
}

impl LeavingSurface {
    /// The rule for a ray leaving voxel `v` (with record `rec`) towards the
    /// side of unit normal `side`, with the slab and angle of `params`.
    ///
    /// ```
    /// use rrt_core::light::{LeavingSurface, LightParams};
    /// use rrt_core::raster::Extent;
    /// use rrt_core::voxel::{encode_normal, VoxelRecord};
    /// use rrt_core::voxelize::NORMAL_ONE;
    /// use rrt_core::store::RecordStore;
    /// let e = Extent::cube(8).unwrap();
    /// let up = [0, 0, NORMAL_ONE];
    /// let rec = VoxelRecord { object: 3, normal: encode_normal(up), ..Default::default() };
    /// let store = RecordStore::new(e, &[0, 0], &[]).unwrap();
    /// let rule = LeavingSurface::new(&store, [4, 4, 4], up, &rec, &LightParams::default());
    /// // The neighbour in the same layer is the surface itself; one 3 voxels up is not.
    /// assert!(rule.ignores(&store, e.index([5, 4, 4]).unwrap(), &rec));
    /// assert!(!rule.ignores(&store, e.index([4, 4, 7]).unwrap(), &rec));
    /// ```
    #[must_use]
    pub fn new(
        store: &RecordStore<'_>,
        v: [u32; 3],
        side: [i32; 3],
        rec: &VoxelRecord,
        params: &LightParams,
    ) -> Self {
        Self {
            start: store.extent().index(v),
            c0: v.map(voxel_centre),
            side,
            stored: rec.normal,
            stored_normal: None,
            object: store.owner(rec),
            slab: params.slab,
            same_surface_cos: params.same_surface_cos,
        }
    }

    /// Whether the opaque voxel at `index` with record `b` (of `store`) is
    /// part of the surface being left, and so no hit: the start voxel
    /// itself, or a voxel at most `slab` above the tangent plane whose owner
    /// is the left voxel's owner or whose surface is oriented like this one.
    /// The rule compares owners, not object lists: a voxel shared with
    /// another object (a sphere's contact with the floor) keeps blocking the
    /// other object's shadow rays.
    #[must_use]
    pub fn ignores(&self, store: &RecordStore<'_>, index: usize, b: &VoxelRecord) -> bool {
        if Some(index) == self.start {
            return true;
        }
        store
            .extent()
            .coord(index)
            .is_some_and(|vb| self.ignores_voxel(store, vb, b))
    }

    /// [`ignores`](Self::ignores) for a voxel given by its coordinates `vb`
    /// (a caller that has them saves the division of
    /// [`Extent::coord`]); the start voxel is recognized by its index only,
    /// so a caller checks `Some(index) == self.start` first.
    #[must_use]
    pub fn ignores_voxel(&self, store: &RecordStore<'_>, vb: [u32; 3], b: &VoxelRecord) -> bool {
        let d = sub(vb.map(voxel_centre), self.c0);
        // (c_b − c₀)·N₀ in fixed units: |d| < 2^33, |N| <= 2^30.
        let height = d
            .iter()
            .zip(self.side.iter())
            .map(|(a, n)| i128::from(*a).saturating_mul(i128::from(*n)))
            .fold(0i128, i128::saturating_add)
            >> 30;
        if height > i128::from(self.slab) {
            return false;
        }
        store.owner(b) == self.object
            || dot_unit(
                b.normal_vector(),
                self.stored_normal
                    .unwrap_or_else(|| decode_normal(self.stored)),
            ) >= self.same_surface_cos
    }
}

fn walk_piece<T: FnMut(usize, u8) -> bool>(
    raster: &Raster<'_>,
    mode: Connectivity,
    ray: Option<DiscreteRay>,
    test: &mut T,
) -> Result<Piece, LightError> {
    let Some(mut ray) = ray else {
        return Ok(Piece::Clear);
    };
    // `test` rejects every transparent cell, so a skipping walk meets the
    // opaque voxels a plain one meets (six-connected walks never jump).
    let end = match mode {
        Connectivity::Six => ray.walk(raster, mode, u32::MAX, &mut *test)?,
        _ => ray.walk_skipping(raster, mode, u32::MAX, &mut *test)?,
    };
    match end {
        WalkEnd::Hit => Ok(Piece::Blocked),
        WalkEnd::Exit => Ok(Piece::Clear),
        // u32::MAX voxels exceed any raster's diagonal; treat as clear.
        WalkEnd::Budget => Ok(Piece::Clear),
    }
}

/// Walks the segment from `c0` to `light` (fixed units) through a raster
/// of `extent` in the pieces `walk` is given: one segment when its extent
/// fits `i32`; the half-line towards a far light outside the raster (which
/// leaves the raster where the segment would); a light inside a raster
/// wider than 2^15 voxels in up to 4 pieces. `Blocked` as soon as a piece
/// is.
fn to_light(
    extent: Extent,
    c0: [i64; 3],
    light: [i64; 3],
    mut walk: impl FnMut(Option<DiscreteRay>) -> Result<Piece, LightError>,
) -> Result<Piece, LightError> {
    let delta = [0, 1, 2].map(|k| {
        i128::from(light.get(k).copied().unwrap_or(0))
            .saturating_sub(i128::from(c0.get(k).copied().unwrap_or(0)))
    });
    let span = delta.iter().map(|d| d.unsigned_abs()).max().unwrap_or(0);
    let limit = u128::from(i32::MAX.unsigned_abs());
    if span <= limit {
        return walk(DiscreteRay::segment(extent, c0, light)?);
    }
    if !inside_box(extent, light) {
        let shift = 128u32
            .saturating_sub(span.leading_zeros())
            .saturating_sub(31);
        let dir = delta.map(|d| i32::try_from(d >> shift).unwrap_or(0));
        return walk(DiscreteRay::new(extent, c0, dir)?);
    }
    let pieces = span.div_ceil(limit).max(1);
    let pieces_i = i128::try_from(pieces).unwrap_or(1);
    let at = |j: i128| -> [i64; 3] {
        [0, 1, 2].map(|k| {
            let d = delta.get(k).copied().unwrap_or(0);
            let c = i128::from(c0.get(k).copied().unwrap_or(0));
            // |d·j| < 2^35 · 4: fits; the result lies between c0 and light.
            let p = c.saturating_add(d.saturating_mul(j).checked_div(pieces_i).unwrap_or(0));
            i64::try_from(p).unwrap_or(0)
        })
    };
    for j in 0..pieces_i {
        if walk(DiscreteRay::segment(
            extent,
            at(j),
            at(j.saturating_add(1)),
        )?)? == Piece::Blocked
        {
            return Ok(Piece::Blocked);
        }
    }
    Ok(Piece::Clear)
}

#[cfg(test)]
mod tests;
