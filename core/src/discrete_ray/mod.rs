//! Discrete rays: a continuous fixed-point ray, clipped to the raster box in
//! integer arithmetic, traversed as a 6-connected, 26-connected or adaptive
//! 3D discrete line by one incremental stepper.
//!
//! # The ray
//! A ray is `P(t) = origin + t·dir` with `origin` in fixed units
//! ([`crate::fixed`], `FRAC_BITS` = 16 fractional bits per voxel) and `dir`
//! in fixed units per unit of `t`. [`DiscreteRay::new`] takes `t ≥ 0` (a
//! half-line), [`DiscreteRay::segment`] takes `t ∈ [0, 1]` (from one point to
//! another). Only the direction's ratios matter for a half-line, so hosts
//! should scale it to use the `i32` range for the best angular precision.
//!
//! **Accepted range.** Any `dir: [i32; 3]` (a zero direction is a ray that
//! stays in its origin voxel) and origins with `|origin| ≤ 2^47` fixed units
//! (`2^31` voxels) on every axis; a segment additionally needs
//! `end − origin` to fit in `i32`. Within that range no intermediate value
//! overflows (setup uses `i128`, stepping `i64`); anything else is refused
//! with [`RayError`].
//!
//! # The clipped endpoints
//! The ray is clipped to the raster box `[0, n·VOXEL)` per axis (voxels are
//! half-open, so the box's upper faces belong to no voxel) giving the
//! entry and exit parameters `t_in < t_out`, the paper's two endpoints. A ray
//! that only touches the box in a point or along an edge, points away from
//! it, or runs outside a slab it is parallel to passes through no voxel, and
//! the constructors return `Ok(None)`.
//!
//! # Connectivity
//! * **Six** visits, in order of the ray parameter, every voxel that holds
//!   ray points on an interval of positive length: exactly the voxels whose
//!   interior the ray passes through, plus, where the ray lies in a voxel
//!   face, the voxel on the face's upper side. Consecutive voxels are
//!   6-adjacent. **Tie rule:** when the ray crosses an edge or a corner
//!   exactly (several boundaries at the same `t`), it steps x before y
//!   before z; the intermediate voxel it visits then touches the ray only at
//!   that edge or corner.
//! * **TwentySix** is the enhanced double Bresenham of the paper: one unit
//!   step along the driving axis (the largest `|dir|` component, lowest axis
//!   on ties) per iteration, and a decision per minor axis, all from the
//!   sub-voxel entry point. It visits the entry voxel and then, of each
//!   slice across the driving axis, the voxel holding the ray just after it
//!   enters that slice (edge and corner ties go with the driving step). Its
//!   voxels are a subsequence of Six's, 26-adjacent, and
//!   `|Δdriving| + 1` of them (the paper's `n26 + 1`).
//! * **Adaptive** takes TwentySix steps while the current voxel's
//!   [`cell::PROXIMITY`] bit is clear and Six steps while it is set, from the
//!   same state (and a Six step to finish an edge or corner crossing that a
//!   Six step started). Its voxels are a subsequence of Six's. If every non-transparent voxel's 26-neighbourhood is flagged
//!   (see [`crate::proximity`]), it hits exactly the voxel the Six ray hits.
//!
//! Every step adds one precomputed offset (`±1`, `±nx`, `±nx·ny` or a sum of
//! those) to a single raster index; coordinates are never recomputed. A walk
//! ends at the exit point (counted crossings, never a comparison with an end
//! voxel), at a hit, or at the caller's step budget.
//!
//! ```
//! use rrt_core::discrete_ray::{Connectivity, DiscreteRay};
//! use rrt_core::fixed::{voxel_centre, VOXEL};
//! use rrt_core::raster::{cell, Extent, Raster};
//!
//! let extent = Extent::cube(8).unwrap();
//! let mut plane = vec![cell::EMPTY; extent.len()];
//! plane[extent.index([6, 3, 3]).unwrap()] = cell::OPAQUE;
//! let raster = Raster::new(extent, &plane).unwrap();
//!
//! // From outside the box, along +x through the row y = z = 3.
//! let origin = [-VOXEL, voxel_centre(3), voxel_centre(3)];
//! let mut ray = DiscreteRay::new(extent, origin, [VOXEL as i32, 0, 0]).unwrap().unwrap();
//! let hit = ray.first_hit(&raster, Connectivity::Six).unwrap().unwrap();
//! assert_eq!(hit.voxel, [6, 3, 3]);
//! assert_eq!(hit.steps, 7); // voxels 0..=6 visited
//! ```

mod params;
pub(crate) mod rules;
pub(crate) mod skip;
mod step;
#[cfg(test)]
mod tests;

use crate::error::RayError;
use crate::raster::{Extent, Raster, cell};
use params::Params;

pub use crate::connectivity::Connectivity;

/// Bits of the largest accepted `|origin|` coordinate, in fixed units.
pub const ORIGIN_LIMIT_BITS: u32 = 47;
/// Largest accepted `|origin|` coordinate, in fixed units (`2^31` voxels).
pub const ORIGIN_LIMIT: i64 = 1 << ORIGIN_LIMIT_BITS;

/// A face of a voxel, named by the side of the voxel it bounds.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Face {
    /// The face at the voxel's low x (entered by rays moving towards +x).
    XMin,
    /// The face at the voxel's high x.
    XMax,
    /// The face at the voxel's low y.
    YMin,
    /// The face at the voxel's high y.
    YMax,
    /// The face at the voxel's low z.
    ZMin,
    /// The face at the voxel's high z.
    ZMax,
}

impl Face {
    /// The face through which a ray moving along `axis` (rising or falling)
    /// enters a voxel.
    pub(crate) const fn entered(axis: usize, rising: bool) -> Self {
        match (axis, rising) {
            (0, true) => Self::XMin,
            (0, false) => Self::XMax,
            (1, true) => Self::YMin,
            (1, false) => Self::YMax,
            (_, true) => Self::ZMin,
            (_, false) => Self::ZMax,
        }
    }

    /// The axis the face is perpendicular to (0 = x).
    #[must_use]
    pub const fn axis(self) -> usize {
        match self {
            Self::XMin | Self::XMax => 0,
            Self::YMin | Self::YMax => 1,
            Self::ZMin | Self::ZMax => 2,
        }
    }

    /// The face's outward normal as a unit lattice vector.
    ///
    /// ```
    /// use rrt_core::discrete_ray::Face;
    /// assert_eq!(Face::XMin.normal(), [-1, 0, 0]);
    /// ```
    #[must_use]
    pub const fn normal(self) -> [i8; 3] {
        match self {
            Self::XMin => [-1, 0, 0],
            Self::XMax => [1, 0, 0],
            Self::YMin => [0, -1, 0],
            Self::YMax => [0, 1, 0],
            Self::ZMin => [0, 0, -1],
            Self::ZMax => [0, 0, 1],
        }
    }
}

/// How a walk ended (see [`DiscreteRay::walk`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum WalkEnd {
    /// The test accepted the current voxel ([`DiscreteRay::hit`] describes it).
    Hit,
    /// The ray reached its exit point; further walks return `Exit` again.
    Exit,
    /// The step budget ran out; a further walk continues with the next voxel.
    Budget,
}

/// A voxel where a walk stopped.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Hit {
    /// Voxel coordinates.
    pub voxel: [u32; 3],
    /// Linear raster index of the voxel.
    pub index: usize,
    /// The face the ray entered the voxel through: for a diagonal
    /// (26-connected) step the face of the last boundary crossed, which is
    /// the driving axis's; `None` for a first voxel that holds the ray origin.
    pub face: Option<Face>,
    /// Voxels visited since the ray's entry voxel, this one included.
    pub steps: u32,
}

/// One voxel of a discrete ray, as yielded by [`Voxels`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Visit {
    /// Linear raster index.
    pub index: usize,
    /// The raster cell.
    pub cell: u8,
    /// Movement from the previous voxel, `-1`, `0` or `1` per axis (all zero
    /// for the entry voxel).
    pub moved: [i8; 3],
    /// The face the ray entered this voxel through (see [`Hit::face`]).
    pub face: Option<Face>,
}

/// The mutable stepping state. Together with the parameters it is all that
/// is needed to resume a walk.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct State {
    pub(crate) index: usize,
    pub(crate) err: [i64; 3],
    pub(crate) rem: [u32; 3],
    pub(crate) steps: u32,
    /// Frame axes moved into the current voxel (bit 0 = driving axis).
    pub(crate) last: u8,
    /// The step into the current voxel crossed an edge or corner and left a
    /// crossing pending at the same ray parameter: the next step must be a
    /// 6-step (see step.rs).
    pub(crate) tie: bool,
    /// The current voxel has not been visited yet.
    pub(crate) fresh: bool,
    /// The ray has reached its exit.
    pub(crate) done: bool,
}

/// A discrete ray: its constants and its resumable stepping state.
///
/// Cloning a ray snapshots its state; two clones walked the same way visit
/// the same voxels.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct DiscreteRay {
    p: Params,
    s: State,
}

impl DiscreteRay {
    /// The half-line `origin + t·dir`, `t ≥ 0`, clipped to `extent`.
    ///
    /// Returns `Ok(None)` when it passes through no voxel of the raster.
    ///
    /// # Errors
    /// [`RayError::OriginOutOfRange`] for `|origin| > ORIGIN_LIMIT`.
    ///
    /// ```
    /// use rrt_core::discrete_ray::DiscreteRay;
    /// use rrt_core::fixed::VOXEL;
    /// use rrt_core::raster::Extent;
    /// let e = Extent::cube(4).unwrap();
    /// // Pointing away from the box: no voxels.
    /// assert!(DiscreteRay::new(e, [-VOXEL, VOXEL, VOXEL], [-1, 0, 0]).unwrap().is_none());
    /// ```
    pub fn new(extent: Extent, origin: [i64; 3], dir: [i32; 3]) -> Result<Option<Self>, RayError> {
        params::setup(extent, origin, dir, false)
    }

    /// The segment from `from` to `to` (`t ∈ [0, 1]`), clipped to `extent`.
    ///
    /// # Errors
    /// [`RayError::OriginOutOfRange`] for an endpoint beyond `ORIGIN_LIMIT`,
    /// [`RayError::SegmentTooLong`] when `to − from` does not fit in `i32`.
    ///
    /// ```
    /// use rrt_core::discrete_ray::{Connectivity, DiscreteRay};
    /// use rrt_core::fixed::voxel_centre;
    /// use rrt_core::raster::Extent;
    /// let e = Extent::cube(16).unwrap();
    /// let c = |v: [u32; 3]| v.map(voxel_centre);
    /// let ray = DiscreteRay::segment(e, c([1, 2, 3]), c([9, 4, 6])).unwrap().unwrap();
    /// assert_eq!(ray.crossings(), [8, 2, 3]);
    /// ```
    pub fn segment(extent: Extent, from: [i64; 3], to: [i64; 3]) -> Result<Option<Self>, RayError> {
        let mut dir = [0i32; 3];
        for (axis, ((slot, &f), &t)) in (0u8..).zip(dir.iter_mut().zip(from.iter()).zip(to.iter()))
        {
            if f.unsigned_abs() > ORIGIN_LIMIT.unsigned_abs()
                || t.unsigned_abs() > ORIGIN_LIMIT.unsigned_abs()
            {
                return Err(RayError::OriginOutOfRange { axis });
            }
            // Both within ±2^47: the difference cannot overflow i64.
            let delta = t.wrapping_sub(f);
            *slot = i32::try_from(delta).map_err(|_| RayError::SegmentTooLong { axis })?;
        }
        params::setup(extent, from, dir, true)
    }

    /// The ray's constants (read by the packet stepper, [`crate::packet`]).
    pub(crate) const fn params(&self) -> &Params {
        &self.p
    }

    /// The ray's stepping state (read by the packet stepper).
    pub(crate) const fn state(&self) -> &State {
        &self.s
    }

    /// Replaces the stepping state: the packet stepper writes each lane's
    /// state back with this, so that lane and scalar ray stay one value.
    pub(crate) const fn set_state(&mut self, s: State) {
        self.s = s;
    }

    /// Walks the ray through `raster` until `test(index, cell)` accepts a
    /// voxel ([`WalkEnd::Hit`]), the ray leaves the raster
    /// ([`WalkEnd::Exit`]), or `budget` voxels have been visited in this call
    /// ([`WalkEnd::Budget`]).
    ///
    /// After any outcome the ray can be walked again: after a hit it resumes
    /// with the voxel after the hit (intersection verification does this on
    /// a false hit), after a budget stop with the next unvisited voxel.
    ///
    /// # Errors
    /// [`RayError::ExtentMismatch`] if `raster` has other dimensions than the
    /// extent the ray was set up in.
    pub fn walk<T: FnMut(usize, u8) -> bool>(
        &mut self,
        raster: &Raster<'_>,
        mode: Connectivity,
        budget: u32,
        test: T,
    ) -> Result<WalkEnd, RayError> {
        let plane = self.plane_of(raster)?;
        Ok(self.run::<false, _, _>(mode, |i| plane.get(i).copied(), budget, test))
    }

    /// The plane of `raster`, which must have the ray's extent.
    fn plane_of<'r>(&self, raster: &Raster<'r>) -> Result<&'r [u8], RayError> {
        if raster.extent() == self.p.extent {
            Ok(raster.plane())
        } else {
            Err(RayError::ExtentMismatch)
        }
    }

    fn run<const SKIP: bool, C: Fn(usize) -> Option<u8> + Copy, T: FnMut(usize, u8) -> bool>(
        &mut self,
        mode: Connectivity,
        cells: C,
        budget: u32,
        test: T,
    ) -> WalkEnd {
        let (p, s) = (&self.p, &mut self.s);
        match mode {
            Connectivity::Six => step::run::<{ rules::SIX }, SKIP, C, T>(p, s, cells, budget, test),
            Connectivity::TwentySix => {
                step::run::<{ rules::TWENTY_SIX }, SKIP, C, T>(p, s, cells, budget, test)
            }
            Connectivity::Adaptive => {
                step::run::<{ rules::ADAPTIVE }, SKIP, C, T>(p, s, cells, budget, test)
            }
        }
    }

    /// The ray's voxels in an *empty* raster of its extent (every cell
    /// [`cell::EMPTY`], so Adaptive steps like TwentySix), without needing a
    /// plane: for tools that list a ray's voxels, and for rasters too large
    /// to allocate. Yields the same voxels as [`DiscreteRay::voxels`] over an
    /// all-empty plane.
    ///
    /// ```
    /// use rrt_core::discrete_ray::{Connectivity, DiscreteRay};
    /// use rrt_core::raster::Extent;
    /// let huge = Extent::cube(65536).unwrap(); // 2^48 voxels: never allocated
    /// let ray = DiscreteRay::new(huge, [0, 0, 0], [1, 1, 1]).unwrap().unwrap();
    /// assert_eq!(ray.path(Connectivity::TwentySix).count(), 65536);
    /// ```
    #[must_use]
    pub fn path(self, mode: Connectivity) -> Path {
        Path { ray: self, mode }
    }

    /// As [`DiscreteRay::walk`], with **empty-space skipping**: where the
    /// raster's proximity distance (see
    /// [`crate::proximity::distance_field`]) at the current voxel is large
    /// enough (`d ≥ 4`), a run of 26-steps (TwentySix, and Adaptive away from
    /// surfaces) advances `d − 1` steps at once, exactly: it lands on the
    /// voxel, with the state, that `d − 1` single steps reach. Six walks do
    /// not skip.
    ///
    /// **Contract:** `test` must reject every cell without [`cell::OPAQUE`]
    /// (skipped voxels are not tested). Then the hits, their faces and the
    /// resume state after each are those of [`DiscreteRay::walk`]; only
    /// `steps` differs: it counts the voxels actually visited, one per jump.
    /// A plane without distances (all distance bits 0) never skips.
    ///
    /// The distance field stores distances only near surfaces (below
    /// [`crate::proximity::NEAR_LIMIT`]), so far from them the plane alone
    /// gives no jumps. With a line level ([`Raster::with_lines`]) a voxel
    /// whose line is at distance 8 or more from every non-transparent voxel
    /// is decided from the line's stand-in cell, without reading the plane;
    /// its jump is the line's (smaller or equal) distance less one; in a
    /// nearer line an empty plane cell reads as at the near limit.
    ///
    /// # Errors
    /// As [`DiscreteRay::walk`].
    pub fn walk_skipping<T: FnMut(usize, u8) -> bool>(
        &mut self,
        raster: &Raster<'_>,
        mode: Connectivity,
        budget: u32,
        test: T,
    ) -> Result<WalkEnd, RayError> {
        let plane = self.plane_of(raster)?;
        let lines = raster.lines();
        Ok(if lines.is_empty() {
            self.run::<true, _, _>(mode, |i| plane.get(i).copied(), budget, test)
        } else {
            // A line's stand-in where the line is far from surfaces, else
            // the plane.
            let cells = |i: usize| skip::skip_cell(plane, lines, i);
            self.run::<true, _, _>(mode, cells, budget, test)
        })
    }

    /// Walks the ray's *tube*: the voxels within chessboard distance 1 of
    /// its 6-connected path. `test(index, cell)` is called, in path order,
    /// for every voxel of the Six path that has a non-transparent voxel
    /// within chessboard distance 1 (`cell` is the plane's own cell), and
    /// the walk ends at the first it accepts ([`WalkEnd::Hit`]), or when the
    /// ray leaves the raster or the budget is spent. So a walk that is never
    /// stopped proves that no non-transparent voxel lies within distance 1
    /// of the path, except those `test` looked at and let pass.
    ///
    /// It is [`DiscreteRay::walk_skipping`] in
    /// [`Connectivity::Adaptive`] over the raster dilated by one voxel
    /// ([`crate::proximity::dilated`]): 26-steps and jumps far from the
    /// dilated voxels, 6-steps near them, so it visits every dilated voxel
    /// of the Six path. Without a distance field the walk takes 6-steps
    /// everywhere (still exact).
    ///
    /// ```
    /// use rrt_core::discrete_ray::{DiscreteRay, WalkEnd};
    /// use rrt_core::fixed::{voxel_centre, VOXEL};
    /// use rrt_core::proximity::distance_field;
    /// use rrt_core::raster::{cell, Extent, RasterMut};
    ///
    /// let e = Extent::cube(32).unwrap();
    /// let mut plane = vec![cell::EMPTY; e.len()];
    /// plane[e.index([20, 6, 5]).unwrap()] = cell::OPAQUE; // one voxel off the row
    /// let mut r = RasterMut::new(e, &mut plane).unwrap();
    /// distance_field(&mut r);
    /// let r = r.as_raster();
    /// let origin = [0, voxel_centre(5), voxel_centre(5)];
    /// let mut ray = DiscreteRay::new(e, origin, [VOXEL as i32, 0, 0]).unwrap().unwrap();
    /// let mut met = Vec::new();
    /// let end = ray.walk_dilated(&r, u32::MAX, |i, _| { met.push(e.coord(i).unwrap()); false }).unwrap();
    /// assert_eq!(end, WalkEnd::Exit);
    /// assert_eq!(met, [[19, 5, 5], [20, 5, 5], [21, 5, 5]]);
    /// ```
    ///
    /// # Errors
    /// As [`DiscreteRay::walk`].
    pub fn walk_dilated<T: FnMut(usize, u8) -> bool>(
        &mut self,
        raster: &Raster<'_>,
        budget: u32,
        mut test: T,
    ) -> Result<WalkEnd, RayError> {
        use crate::proximity::dilated;
        let plane = self.plane_of(raster)?;
        let lines = raster.lines();
        // The test sees the plane's cell; the stepper the dilated one.
        let mut test_plane = |i: usize, c: u8| {
            c & cell::OPAQUE != 0 && test(i, plane.get(i).copied().unwrap_or(cell::OPAQUE))
        };
        Ok(if lines.is_empty() {
            let cells = |i: usize| plane.get(i).copied().map(dilated);
            self.run::<true, _, _>(Connectivity::Adaptive, cells, budget, &mut test_plane)
        } else {
            let cells = |i: usize| skip::skip_cell(plane, lines, i).map(dilated);
            self.run::<true, _, _>(Connectivity::Adaptive, cells, budget, &mut test_plane)
        })
    }

    /// [`DiscreteRay::first_hit`] with empty-space skipping (see
    /// [`DiscreteRay::walk_skipping`]).
    ///
    /// ```
    /// use rrt_core::discrete_ray::{Connectivity, DiscreteRay};
    /// use rrt_core::fixed::{voxel_centre, VOXEL};
    /// use rrt_core::proximity::{coarse_extent, distance_field, line_distances};
    /// use rrt_core::raster::{cell, line_count, Extent, RasterMut};
    ///
    /// let e = Extent::cube(64).unwrap();
    /// let mut plane = vec![cell::EMPTY; e.len()];
    /// plane[e.index([60, 9, 9]).unwrap()] = cell::OPAQUE;
    /// let mut r = RasterMut::new(e, &mut plane).unwrap();
    /// distance_field(&mut r);
    /// let r = r.as_raster();
    /// // The line level: jumps far from surfaces.
    /// let mut bricks = vec![0; coarse_extent(e).unwrap().len()];
    /// let mut lines = vec![0; line_count(e.len())];
    /// line_distances(&r, &mut bricks, &mut lines).unwrap();
    /// let r = r.with_lines(&lines).unwrap();
    /// let origin = [0, voxel_centre(9), voxel_centre(9)];
    /// let ray = DiscreteRay::new(e, origin, [VOXEL as i32, 1, 0]).unwrap().unwrap();
    /// let (mut plain, mut skipping) = (ray, ray);
    /// let a = plain.first_hit(&r, Connectivity::Adaptive).unwrap().unwrap();
    /// let b = skipping.first_hit_skipping(&r, Connectivity::Adaptive).unwrap().unwrap();
    /// assert_eq!((a.voxel, a.face), (b.voxel, b.face));
    /// assert_eq!(a.steps, 61);
    /// assert!(b.steps < 10);
    /// ```
    ///
    /// # Errors
    /// As [`DiscreteRay::walk`].
    pub fn first_hit_skipping(
        &mut self,
        raster: &Raster<'_>,
        mode: Connectivity,
    ) -> Result<Option<Hit>, RayError> {
        let end = self.walk_skipping(raster, mode, u32::MAX, |_, c| c & cell::OPAQUE != 0)?;
        Ok(self.hit_after(end))
    }

    /// Walks to the first non-transparent ([`cell::OPAQUE`]) voxel, with no
    /// budget beyond the ray's own length. `Ok(None)` when the ray leaves the
    /// raster without a hit. Call again to resume after the returned voxel.
    ///
    /// # Errors
    /// As [`DiscreteRay::walk`].
    pub fn first_hit(
        &mut self,
        raster: &Raster<'_>,
        mode: Connectivity,
    ) -> Result<Option<Hit>, RayError> {
        let end = self.walk(raster, mode, u32::MAX, |_, c| c & cell::OPAQUE != 0)?;
        Ok(self.hit_after(end))
    }

    /// The hit after a walk that ended with `end`.
    fn hit_after(&self, end: WalkEnd) -> Option<Hit> {
        matches!(end, WalkEnd::Hit).then(|| self.hit())
    }

    /// The current voxel: after [`WalkEnd::Hit`] the hit voxel, after
    /// [`WalkEnd::Budget`] the last one visited (or, before any walk, the
    /// entry voxel with `steps == 0`).
    #[must_use]
    pub fn hit(&self) -> Hit {
        Hit {
            voxel: self.p.extent.coord(self.s.index).unwrap_or(self.p.entry),
            index: self.s.index,
            face: self.face(),
            steps: self.s.steps,
        }
    }

    /// An iterator over the voxels of the ray from its current state, ignoring
    /// opacity. It shares the stepper with [`DiscreteRay::walk`].
    ///
    /// # Errors
    /// [`RayError::ExtentMismatch`] as for [`DiscreteRay::walk`].
    pub fn voxels<'r>(
        self,
        raster: &'r Raster<'r>,
        mode: Connectivity,
    ) -> Result<Voxels<'r>, RayError> {
        self.plane_of(raster)?;
        Ok(Voxels {
            ray: self,
            raster: *raster,
            mode,
        })
    }

    /// The raster extent the ray was set up in.
    #[must_use]
    pub const fn extent(&self) -> Extent {
        self.p.extent
    }

    /// The fixed-point origin.
    #[must_use]
    pub const fn origin(&self) -> [i64; 3] {
        self.p.origin
    }

    /// The fixed-point direction (for a segment, `end − origin`).
    #[must_use]
    pub const fn dir(&self) -> [i32; 3] {
        self.p.dir
    }

    /// The voxel holding the ray just after its entry point.
    #[must_use]
    pub const fn entry_voxel(&self) -> [u32; 3] {
        self.p.entry
    }

    /// The voxel holding the ray just before its exit point.
    #[must_use]
    pub const fn exit_voxel(&self) -> [u32; 3] {
        self.p.exit
    }

    /// The face of the raster box the ray entered through, `None` when its
    /// origin lies strictly inside the box.
    #[must_use]
    pub const fn entry_face(&self) -> Option<Face> {
        self.p.entry_face
    }

    /// The driving axis (0 = x): the largest `|dir|` component, the lowest
    /// axis on ties.
    #[must_use]
    pub fn driving_axis(&self) -> usize {
        usize::from(self.p.perm[0])
    }

    /// Voxel-boundary crossings between the entry and exit points, per axis
    /// (x, y, z), counted from the ray's start. The Six ray visits
    /// `1 + x + y + z` voxels, the TwentySix ray `1 + crossings[driving]`.
    #[must_use]
    pub fn crossings(&self) -> [u32; 3] {
        let mut out = [0u32; 3];
        for (axis, slot) in out.iter_mut().enumerate() {
            *slot = self.p.extent.dims().get(axis).map_or(0, |_| {
                let e = self.p.entry.get(axis).copied().unwrap_or(0);
                let x = self.p.exit.get(axis).copied().unwrap_or(0);
                e.abs_diff(x)
            });
        }
        out
    }

    /// Voxels visited so far.
    #[must_use]
    pub const fn steps(&self) -> u32 {
        self.s.steps
    }

    /// Whether the ray has reached its exit point.
    #[must_use]
    pub const fn is_done(&self) -> bool {
        self.s.done
    }

    /// Movement into the current voxel, per real axis.
    #[must_use]
    pub fn last_move(&self) -> [i8; 3] {
        let mut m = [0i8; 3];
        for f in 0..3u32 {
            if self.s.last & (1 << f) != 0 {
                let axis = usize::from(self.p.perm.get(f as usize).copied().unwrap_or(0));
                let sign: i8 = if self.p.dir.get(axis).copied().unwrap_or(0) < 0 {
                    -1
                } else {
                    1
                };
                if let Some(slot) = m.get_mut(axis) {
                    *slot = sign;
                }
            }
        }
        m
    }

    /// The current voxel as a [`Visit`], unless the walk ended.
    fn visit(&self, end: WalkEnd, cell: u8) -> Option<Visit> {
        match end {
            WalkEnd::Exit => None,
            WalkEnd::Hit | WalkEnd::Budget => Some(Visit {
                index: self.s.index,
                cell,
                moved: self.last_move(),
                face: self.face(),
            }),
        }
    }

    fn face(&self) -> Option<Face> {
        let last = self.s.last;
        if last == 0 {
            return self.p.entry_face;
        }
        // A diagonal step always includes the driving axis, whose crossing is
        // the last one; a single-axis step names its own axis.
        let f = if last & 1 != 0 {
            0
        } else if last & 2 != 0 {
            1
        } else {
            2
        };
        let axis = usize::from(self.p.perm.get(f).copied().unwrap_or(0));
        Some(Face::entered(
            axis,
            self.p.dir.get(axis).copied().unwrap_or(0) > 0,
        ))
    }
}

/// Iterator over the voxels of a [`DiscreteRay`] in an empty raster, see
/// [`DiscreteRay::path`].
#[derive(Clone, Debug)]
pub struct Path {
    ray: DiscreteRay,
    mode: Connectivity,
}

impl Path {
    /// The ray in its current state.
    #[must_use]
    pub const fn ray(&self) -> &DiscreteRay {
        &self.ray
    }
}

impl Iterator for Path {
    type Item = Visit;

    fn next(&mut self) -> Option<Visit> {
        let end = self
            .ray
            .run::<false, _, _>(self.mode, |_| Some(cell::EMPTY), 1, |_, _| false);
        self.ray.visit(end, cell::EMPTY)
    }
}

/// Iterator over the voxels of a [`DiscreteRay`], see [`DiscreteRay::voxels`].
#[derive(Clone, Debug)]
pub struct Voxels<'r> {
    ray: DiscreteRay,
    raster: Raster<'r>,
    mode: Connectivity,
}

impl Voxels<'_> {
    /// The ray in its current state.
    #[must_use]
    pub const fn ray(&self) -> &DiscreteRay {
        &self.ray
    }
}

impl Iterator for Voxels<'_> {
    type Item = Visit;

    fn next(&mut self) -> Option<Visit> {
        let mut seen = None;
        let end = self
            .ray
            .walk(&self.raster, self.mode, 1, |_, cell| {
                seen = Some(cell);
                false
            })
            .ok()?;
        self.ray.visit(end, seen?)
    }
}
