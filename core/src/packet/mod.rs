//! Eight discrete rays stepped together on SIMD lanes ([`RayPacket8`]).
//!
//! A packet holds up to eight [`DiscreteRay`]s over one raster extent and
//! walks them in lockstep: each iteration takes one step in every live lane
//! (in each lane's own drive frame and connectivity decision, so lanes may
//! have different driving axes and signs), gathers the eight plane cells,
//! and tests them. The scalar discrete ray is the packet's reference, and
//! the packet's guarantee is **bit identity**: each lane visits exactly the
//! voxels the scalar stepper visits for that ray in the same mode and with
//! the same budget, ends the same way ([`WalkEnd`]), reports the same
//! [`Hit`] (voxel, index, face, step count), and is left in the same resume
//! state, so [`RayPacket8::lane_ray`] returns the very `DiscreteRay` the
//! scalar walk leaves behind, and either may resume the walk.
//!
//! Skipping walks ([`RayPacket8::walk_skipping`],
//! [`RayPacket8::first_hit_skipping`]) are likewise lane by lane the
//! scalar [`DiscreteRay::walk_skipping`]: a lane taking a 26-step from a
//! voxel far from every non-transparent voxel jumps exactly as its scalar
//! ray does, so hits, faces, step counts and resume states stay identical.
//!
//! Lanes without a ray (a ray that misses the raster, or one left out) are
//! simply empty. Lanes that hit, exit or run out of budget drop out of the
//! walk; it returns when every lane has ended, with one [`PacketEnd`] bitmask
//! per outcome (bit `l` = lane `l`).
//!
//! Like the rest of the core it is `no_std`, integer-only and panic-free; on
//! targets without SIMD (`thumbv6m`, `thumbv7em`) `wide` falls back to
//! scalar code behind the same API.
//!
//! ```
//! use rrt_core::discrete_ray::{Connectivity, DiscreteRay};
//! use rrt_core::fixed::{voxel_centre, VOXEL};
//! use rrt_core::packet::RayPacket8;
//! use rrt_core::raster::{cell, Extent, Raster};
//!
//! let extent = Extent::cube(8).unwrap();
//! let mut plane = vec![cell::EMPTY; extent.len()];
//! plane[extent.index([6, 3, 3]).unwrap()] = cell::OPAQUE;
//! let raster = Raster::new(extent, &plane).unwrap();
//!
//! // Eight rays along +x through rows y = 0..8 at z = 3; lane 3 meets the
//! // opaque voxel.
//! let origins = core::array::from_fn(|l| [-VOXEL, voxel_centre(l as u32), voxel_centre(3)]);
//! let mut packet = RayPacket8::new(extent, origins, [[VOXEL as i32, 0, 0]; 8]).unwrap();
//! let hits = packet.first_hit(&raster, Connectivity::Adaptive).unwrap();
//! assert_eq!(hits, 1 << 3);
//! assert_eq!(packet.hit(3).unwrap().voxel, [6, 3, 3]);
//!
//! // Lane 3 is exactly the scalar ray walked the same way.
//! let mut ray = DiscreteRay::new(extent, origins[3], [VOXEL as i32, 0, 0]).unwrap().unwrap();
//! ray.first_hit(&raster, Connectivity::Adaptive).unwrap();
//! assert_eq!(packet.lane_ray(3), Some(ray));
//! ```
//
// Implementation notes: see step.rs (the lockstep stepper and why it is bit
// identical) and lanes.rs (the SIMD lanes).

mod lanes;
mod step;
#[cfg(test)]
mod tests;

use core::fmt;

use crate::discrete_ray::rules::{ADAPTIVE, SIX, TWENTY_SIX};
use crate::discrete_ray::{Connectivity, DiscreteRay, Hit, WalkEnd};
use crate::error::RayError;
use crate::raster::{Extent, Raster, cell};
use lanes::{BIT, I64x8};
use step::{CellBits, Closure, lane_of};

/// Number of lanes of a [`RayPacket8`].
pub const LANES: usize = lanes::LANES;

/// How the lanes of a packet walk ended: bit `l` of a field is lane `l`.
///
/// The three masks are disjoint, and together they hold exactly the lanes
/// that hold a ray ([`RayPacket8::lanes`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct PacketEnd {
    /// Lanes whose test accepted a voxel ([`WalkEnd::Hit`]).
    pub hit: u8,
    /// Lanes that reached their exit point ([`WalkEnd::Exit`]).
    pub exit: u8,
    /// Lanes that visited `budget` voxels in this walk ([`WalkEnd::Budget`]).
    pub budget: u8,
}

impl PacketEnd {
    /// How lane `lane` ended, `None` for an empty lane (or `lane >= 8`).
    ///
    /// ```
    /// use rrt_core::discrete_ray::WalkEnd;
    /// use rrt_core::packet::PacketEnd;
    /// let end = PacketEnd { hit: 0b01, exit: 0b10, budget: 0 };
    /// assert_eq!(end.lane(1), Some(WalkEnd::Exit));
    /// assert_eq!(end.lane(2), None);
    /// ```
    #[must_use]
    pub fn lane(&self, lane: usize) -> Option<WalkEnd> {
        let bit = BIT.get(lane).copied().unwrap_or(0);
        if self.hit & bit != 0 {
            Some(WalkEnd::Hit)
        } else if self.exit & bit != 0 {
            Some(WalkEnd::Exit)
        } else if self.budget & bit != 0 {
            Some(WalkEnd::Budget)
        } else {
            None
        }
    }
}

/// A lane that could not be set up: its number and the scalar ray's error.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct LaneError {
    /// The lane (0..8).
    pub lane: u8,
    /// Why its ray was refused.
    pub error: RayError,
}

impl fmt::Display for LaneError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "packet lane {}: {}", self.lane, self.error)
    }
}

impl core::error::Error for LaneError {}

/// Eight discrete rays over one raster extent, stepped together on SIMD
/// lanes, each lane bit-identical to its scalar [`DiscreteRay`] (see the
/// [module docs](self)).
///
/// Cloning a packet snapshots all eight rays.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct RayPacket8 {
    extent: Extent,
    /// Lane rays: their constants, and between walks their exact state.
    rays: [Option<DiscreteRay>; LANES],
    /// Per lane and frame axis, the decision-term increments `2·S·|D|`
    /// (0 in empty lanes).
    inc: [I64x8; 3],
    /// Per lane and frame axis, the index offset of one step, sign-extended.
    off: [I64x8; 3],
    /// Per lane, the 26-step thresholds of minor axes b and c.
    thr: [I64x8; 2],
}

impl RayPacket8 {
    /// A packet of the given lane rays over `extent`; `None` lanes are empty.
    ///
    /// # Errors
    /// [`RayError::ExtentMismatch`] (with its lane) for a ray set up over
    /// another extent.
    ///
    /// ```
    /// use rrt_core::discrete_ray::DiscreteRay;
    /// use rrt_core::packet::RayPacket8;
    /// use rrt_core::raster::Extent;
    /// let e = Extent::cube(4).unwrap();
    /// let ray = DiscreteRay::new(e, [0, 0, 0], [1, 2, 3]).unwrap();
    /// let packet = RayPacket8::from_rays(e, [ray, None, None, None, None, None, None, ray]).unwrap();
    /// assert_eq!(packet.lanes(), 0b1000_0001);
    /// ```
    pub fn from_rays(
        extent: Extent,
        rays: [Option<DiscreteRay>; LANES],
    ) -> Result<Self, LaneError> {
        let mut inc = [[0i64; LANES]; 3];
        let mut off = [[0i64; LANES]; 3];
        let mut thr = [[0i64; LANES]; 2];
        for (lane, ray) in (0u8..8).zip(rays.iter()) {
            let Some(ray) = ray else { continue };
            if ray.extent() != extent {
                return Err(LaneError {
                    lane,
                    error: RayError::ExtentMismatch,
                });
            }
            let p = ray.params();
            let l = usize::from(lane);
            for f in 0..3 {
                set(&mut inc, f, l, p.inc.get(f).copied().unwrap_or(0));
                set(&mut off, f, l, lane_of(p.off.get(f).copied().unwrap_or(0)));
            }
            for f in 0..2 {
                set(&mut thr, f, l, p.thr.get(f).copied().unwrap_or(0));
            }
        }
        Ok(Self {
            extent,
            rays,
            inc: inc.map(I64x8::new),
            off: off.map(I64x8::new),
            thr: thr.map(I64x8::new),
        })
    }

    /// Eight half-lines `origins[l] + t·dirs[l]`, `t ≥ 0`, as
    /// [`DiscreteRay::new`] sets them up; lanes that miss the raster are
    /// empty.
    ///
    /// # Errors
    /// The first lane whose [`DiscreteRay::new`] fails, with its error.
    ///
    /// ```
    /// use rrt_core::fixed::VOXEL;
    /// use rrt_core::packet::RayPacket8;
    /// use rrt_core::raster::Extent;
    /// let e = Extent::cube(4).unwrap();
    /// let mut dirs = [[1, 0, 0]; 8];
    /// dirs[5] = [-1, 0, 0]; // points away from the box
    /// let packet = RayPacket8::new(e, [[-VOXEL, VOXEL, VOXEL]; 8], dirs).unwrap();
    /// assert_eq!(packet.lanes(), 0b1101_1111);
    /// ```
    pub fn new(
        extent: Extent,
        origins: [[i64; 3]; LANES],
        dirs: [[i32; 3]; LANES],
    ) -> Result<Self, LaneError> {
        let mut rays = [None; LANES];
        for (lane, ((slot, &o), &d)) in (0u8..8).zip(rays.iter_mut().zip(&origins).zip(&dirs)) {
            *slot = DiscreteRay::new(extent, o, d).map_err(|error| LaneError { lane, error })?;
        }
        Self::from_rays(extent, rays)
    }

    /// Eight segments `from[l]` to `to[l]`, as [`DiscreteRay::segment`] sets
    /// them up (shadow rays towards a light, for instance); lanes that miss
    /// the raster are empty.
    ///
    /// # Errors
    /// The first lane whose [`DiscreteRay::segment`] fails, with its error.
    ///
    /// ```
    /// use rrt_core::discrete_ray::Connectivity;
    /// use rrt_core::fixed::voxel_centre;
    /// use rrt_core::packet::RayPacket8;
    /// use rrt_core::raster::{cell, Extent, Raster};
    /// let e = Extent::cube(8).unwrap();
    /// let mut plane = vec![cell::EMPTY; e.len()];
    /// plane[e.index([4, 4, 4]).unwrap()] = cell::OPAQUE;
    /// let raster = Raster::new(e, &plane).unwrap();
    /// // Shadow rays from eight points towards a light at (7, 7, 7).
    /// let from = core::array::from_fn(|l| [voxel_centre(l as u32); 3]);
    /// let light = [voxel_centre(7); 3];
    /// let mut packet = RayPacket8::segments(e, from, [light; 8]).unwrap();
    /// let blocked = packet.first_hit(&raster, Connectivity::Six).unwrap();
    /// assert_eq!(blocked, 0b0001_1111); // lanes 0..=4 pass (4, 4, 4)
    /// ```
    pub fn segments(
        extent: Extent,
        from: [[i64; 3]; LANES],
        to: [[i64; 3]; LANES],
    ) -> Result<Self, LaneError> {
        let mut rays = [None; LANES];
        for (lane, ((slot, &f), &t)) in (0u8..8).zip(rays.iter_mut().zip(&from).zip(&to)) {
            *slot =
                DiscreteRay::segment(extent, f, t).map_err(|error| LaneError { lane, error })?;
        }
        Self::from_rays(extent, rays)
    }

    /// The raster extent of every lane.
    #[must_use]
    pub const fn extent(&self) -> Extent {
        self.extent
    }

    /// Bitmask of the lanes that hold a ray.
    #[must_use]
    pub fn lanes(&self) -> u8 {
        self.mask(|_| true)
    }

    /// Bitmask of the lanes whose ray has reached its exit point.
    #[must_use]
    pub fn done(&self) -> u8 {
        self.mask(DiscreteRay::is_done)
    }

    fn mask(&self, f: impl Fn(&DiscreteRay) -> bool) -> u8 {
        let mut m = 0;
        for (ray, &bit) in self.rays.iter().zip(BIT.iter()) {
            if ray.as_ref().is_some_and(&f) {
                m |= bit;
            }
        }
        m
    }

    /// Lane `lane`'s ray in its current state, `None` for an empty lane: the
    /// same value the scalar ray has after the same walks.
    #[must_use]
    pub fn lane_ray(&self, lane: usize) -> Option<DiscreteRay> {
        self.rays.get(lane).copied().flatten()
    }

    /// Lane `lane`'s current voxel as [`DiscreteRay::hit`] describes it
    /// (after a hit, the hit), `None` for an empty lane.
    #[must_use]
    pub fn hit(&self, lane: usize) -> Option<Hit> {
        self.lane_ray(lane).map(|r| r.hit())
    }

    /// Walks every lane until `test(lane, index, cell)` accepts its voxel,
    /// it leaves the raster, or it has visited `budget` voxels in this call:
    /// per lane exactly [`DiscreteRay::walk`]. The test is called once per
    /// live lane and visited voxel, lanes in increasing order within a step.
    ///
    /// After any outcome the packet can be walked again; each lane resumes
    /// as its scalar ray would.
    ///
    /// # Errors
    /// [`RayError::ExtentMismatch`] if `raster` has another extent than the
    /// packet.
    ///
    /// ```
    /// use rrt_core::discrete_ray::Connectivity;
    /// use rrt_core::fixed::voxel_centre;
    /// use rrt_core::packet::RayPacket8;
    /// use rrt_core::raster::{Extent, Raster};
    /// let e = Extent::cube(16).unwrap();
    /// let plane = vec![0u8; e.len()];
    /// let raster = Raster::new(e, &plane).unwrap();
    /// let o = [voxel_centre(0); 3];
    /// let dirs = core::array::from_fn(|l| [1000, 100 * l as i32, 7]);
    /// let mut packet = RayPacket8::new(e, [o; 8], dirs).unwrap();
    /// let end = packet.walk(&raster, Connectivity::TwentySix, 5, |_, _, _| false).unwrap();
    /// assert_eq!(end.budget, 0xff);
    /// assert!((0..8).all(|l| packet.hit(l).unwrap().steps == 5));
    /// ```
    pub fn walk<T: FnMut(usize, usize, u8) -> bool>(
        &mut self,
        raster: &Raster<'_>,
        mode: Connectivity,
        budget: u32,
        test: T,
    ) -> Result<PacketEnd, RayError> {
        self.run::<false, _>(raster, mode, budget, &mut Closure(test))
    }

    /// [`RayPacket8::walk`] with the test "the cell has any bit of `bits`"
    /// (`cell & bits != 0`), evaluated for eight lanes at once.
    ///
    /// # Errors
    /// As [`RayPacket8::walk`].
    ///
    /// ```
    /// use rrt_core::discrete_ray::Connectivity;
    /// use rrt_core::fixed::{voxel_centre, VOXEL};
    /// use rrt_core::packet::RayPacket8;
    /// use rrt_core::raster::{cell, Extent, Raster};
    /// let e = Extent::cube(8).unwrap();
    /// let mut plane = vec![cell::EMPTY; e.len()];
    /// plane[e.index([5, 2, 2]).unwrap()] = cell::PROXIMITY;
    /// let raster = Raster::new(e, &plane).unwrap();
    /// let o = [-VOXEL, voxel_centre(2), voxel_centre(2)];
    /// let mut packet = RayPacket8::new(e, [o; 8], [[VOXEL as i32, 0, 0]; 8]).unwrap();
    /// // Stop at the first flagged voxel.
    /// let end = packet.walk_until(&raster, Connectivity::TwentySix, 100, cell::PROXIMITY).unwrap();
    /// assert_eq!(end.hit, 0xff);
    /// assert_eq!(packet.hit(7).unwrap().voxel, [5, 2, 2]);
    /// // Resume: every lane runs to its exit.
    /// let end = packet.walk_until(&raster, Connectivity::TwentySix, 100, cell::PROXIMITY).unwrap();
    /// assert_eq!((end.exit, packet.done()), (0xff, 0xff));
    /// ```
    pub fn walk_until(
        &mut self,
        raster: &Raster<'_>,
        mode: Connectivity,
        budget: u32,
        bits: u8,
    ) -> Result<PacketEnd, RayError> {
        self.run::<false, _>(raster, mode, budget, &mut CellBits(bits))
    }

    /// Walks every lane to its first non-transparent ([`cell::OPAQUE`])
    /// voxel, as [`DiscreteRay::first_hit`] does, and returns the bitmask of
    /// the lanes that hit ([`RayPacket8::hit`] describes each). Call again to
    /// resume the lanes after their hits.
    ///
    /// # Errors
    /// As [`RayPacket8::walk`].
    pub fn first_hit(&mut self, raster: &Raster<'_>, mode: Connectivity) -> Result<u8, RayError> {
        Ok(self.walk_until(raster, mode, u32::MAX, cell::OPAQUE)?.hit)
    }

    /// As [`RayPacket8::walk`], with **empty-space skipping**: per lane
    /// exactly [`DiscreteRay::walk_skipping`] (the same jumps from the
    /// proximity distances and the line level, so the same voxels tested,
    /// hits, faces, step counts and resume states). The test is called once
    /// per live lane and visited voxel, lanes in increasing order within an
    /// iteration.
    ///
    /// **Contract** (as for the scalar walk): `test` must reject every cell
    /// without [`cell::OPAQUE`], or skipped voxels go untested; each lane
    /// still equals its scalar skipping walk either way.
    ///
    /// # Errors
    /// As [`RayPacket8::walk`].
    pub fn walk_skipping<T: FnMut(usize, usize, u8) -> bool>(
        &mut self,
        raster: &Raster<'_>,
        mode: Connectivity,
        budget: u32,
        test: T,
    ) -> Result<PacketEnd, RayError> {
        self.run::<true, _>(raster, mode, budget, &mut Closure(test))
    }

    /// [`RayPacket8::walk_skipping`] with the test "the cell has any bit of
    /// `bits`", evaluated for eight lanes at once.
    ///
    /// # Errors
    /// As [`RayPacket8::walk`].
    pub fn walk_until_skipping(
        &mut self,
        raster: &Raster<'_>,
        mode: Connectivity,
        budget: u32,
        bits: u8,
    ) -> Result<PacketEnd, RayError> {
        self.run::<true, _>(raster, mode, budget, &mut CellBits(bits))
    }

    /// [`RayPacket8::first_hit`] with empty-space skipping: per lane exactly
    /// [`DiscreteRay::first_hit_skipping`].
    ///
    /// ```
    /// use rrt_core::discrete_ray::{Connectivity, DiscreteRay};
    /// use rrt_core::fixed::{voxel_centre, VOXEL};
    /// use rrt_core::packet::RayPacket8;
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
    /// let origins = core::array::from_fn(|l| [0, voxel_centre(9), voxel_centre(9) + l as i64]);
    /// let mut packet = RayPacket8::new(e, origins, [[VOXEL as i32, 1, 0]; 8]).unwrap();
    /// assert_eq!(packet.first_hit_skipping(&r, Connectivity::Adaptive).unwrap(), 0xff);
    /// // Lane 0 is the scalar skipping walk, jumps and all.
    /// let mut ray = DiscreteRay::new(e, origins[0], [VOXEL as i32, 1, 0]).unwrap().unwrap();
    /// let hit = ray.first_hit_skipping(&r, Connectivity::Adaptive).unwrap().unwrap();
    /// assert_eq!(packet.hit(0), Some(hit));
    /// assert!(hit.steps < 10);
    /// ```
    ///
    /// # Errors
    /// As [`RayPacket8::walk`].
    pub fn first_hit_skipping(
        &mut self,
        raster: &Raster<'_>,
        mode: Connectivity,
    ) -> Result<u8, RayError> {
        Ok(self
            .walk_until_skipping(raster, mode, u32::MAX, cell::OPAQUE)?
            .hit)
    }

    fn run<const SKIP: bool, T: step::LaneTest>(
        &mut self,
        raster: &Raster<'_>,
        mode: Connectivity,
        budget: u32,
        test: &mut T,
    ) -> Result<PacketEnd, RayError> {
        if raster.extent() != self.extent {
            return Err(RayError::ExtentMismatch);
        }
        let plane = raster.plane();
        // A plain walk reads the plane only.
        let lines = if SKIP { raster.lines() } else { &[] };
        Ok(match mode {
            Connectivity::Six => step::run::<SIX, SKIP, T>(self, plane, lines, budget, test),
            Connectivity::TwentySix => {
                step::run::<TWENTY_SIX, SKIP, T>(self, plane, lines, budget, test)
            }
            Connectivity::Adaptive => {
                step::run::<ADAPTIVE, SKIP, T>(self, plane, lines, budget, test)
            }
        })
    }
}

/// `table[f][lane] = v` (no-op outside the table).
fn set<const N: usize>(table: &mut [[i64; LANES]; N], f: usize, lane: usize, v: i64) {
    if let Some(slot) = table.get_mut(f).and_then(|row| row.get_mut(lane)) {
        *slot = v;
    }
}
