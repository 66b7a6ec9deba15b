//! Invariant checker for [`RayPacket8`]: every lane equals the scalar ray.
//!
//! Shared by the unit tests, the `tests/` crate and the cargo-fuzz target
//! `packet` (enable the `check` feature outside this crate's own tests).
//! Each check walks a packet and, beside it, each lane's scalar
//! [`DiscreteRay`] the same way, and after **every** walk compares, lane by
//! lane, how the walk ended, the voxels the test saw, the [`Hit`](crate::discrete_ray::Hit) and the
//! whole ray (constants and resume state, through `DiscreteRay`'s
//! equality). They allocate nothing and are bounded by the rays' lengths.

use crate::discrete_ray::{Connectivity, DiscreteRay, WalkEnd};
use crate::packet::{LANES, PacketEnd, RayPacket8};
use crate::raster::{Raster, cell};

/// What differed between a lane and its scalar ray.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum Mismatch {
    /// A walk returned an error.
    Setup,
    /// The lane ended differently ([`WalkEnd`], `None` for an empty lane).
    End {
        /// The scalar ray's outcome.
        scalar: Option<WalkEnd>,
        /// The lane's outcome.
        packet: Option<WalkEnd>,
    },
    /// The test saw another voxel (index and cell), or another number of
    /// voxels, in the lane than in the scalar walk.
    Visit {
        /// Index and cell the scalar test saw (`None`: no call).
        scalar: Option<(usize, u8)>,
        /// Index and cell the lane test saw.
        packet: Option<(usize, u8)>,
    },
    /// The lane's ray (resume state, or hit) differs from the scalar ray.
    State,
    /// The walks did not end within the rays' length.
    TooLong,
}

/// A lane that differed from its scalar ray, and when.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LaneViolation {
    /// The lane.
    pub lane: u8,
    /// The 1-based number of the walk after which it showed.
    pub walk: u32,
    /// The connectivity of that walk.
    pub mode: Connectivity,
    /// What differed.
    pub what: Mismatch,
}

impl core::fmt::Display for LaneViolation {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(
            f,
            "lane {} after walk {} ({}): {:?}",
            self.lane,
            self.walk,
            self.mode.name(),
            self.what
        )
    }
}

/// One walk of a script: its connectivity, its step budget, the cell bits
/// that make a voxel a hit (`cell & hit_bits != 0`; 0 never hits), and
/// whether it skips empty space (the packet's `walk_skipping` against the
/// scalar [`DiscreteRay::walk_skipping`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Walk {
    /// Connectivity of the walk.
    pub mode: Connectivity,
    /// Step budget of the walk.
    pub budget: u32,
    /// Cell bits that make a hit.
    pub hit_bits: u8,
    /// Skip empty space.
    pub skip: bool,
}

/// What a successful [`check_packet`] saw.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct PacketReport {
    /// Lane walks compared (one per walk and lane holding a ray).
    pub lane_walks: u32,
    /// Hits among them.
    pub hits: u32,
}

/// The compared state of the packet walk and its eight scalar twins.
struct Twins<'a, 'r> {
    raster: &'a Raster<'r>,
    packet: RayPacket8,
    rays: [Option<DiscreteRay>; LANES],
    walks: u32,
    report: PacketReport,
}

impl<'a, 'r> Twins<'a, 'r> {
    fn new(raster: &'a Raster<'r>, packet: &RayPacket8) -> Self {
        Self {
            raster,
            packet: packet.clone(),
            rays: core::array::from_fn(|l| packet.lane_ray(l)),
            walks: 0,
            report: PacketReport::default(),
        }
    }

    fn fail(&self, lane: usize, mode: Connectivity, what: Mismatch) -> LaneViolation {
        LaneViolation {
            lane: u8::try_from(lane).unwrap_or(u8::MAX),
            walk: self.walks,
            mode,
            what,
        }
    }

    /// Walks the packet with the closure test and every scalar twin, and
    /// compares. With `budget == 1` each lane's test is called at most once,
    /// so the voxels seen are compared one by one; with larger budgets the
    /// last voxel seen per lane is compared (the states pin down the rest).
    fn walk(&mut self, w: Walk) -> Result<PacketEnd, LaneViolation> {
        self.walks = self.walks.saturating_add(1);
        let mut seen_p: [Option<(usize, u8)>; LANES] = [None; LANES];
        let mut calls_p = [0u32; LANES];
        let bits = w.hit_bits;
        let test = |lane: usize, index: usize, c: u8| {
            if let (Some(s), Some(n)) = (seen_p.get_mut(lane), calls_p.get_mut(lane)) {
                *s = Some((index, c));
                *n = n.saturating_add(1);
            }
            c & bits != 0
        };
        let end = if w.skip {
            self.packet
                .walk_skipping(self.raster, w.mode, w.budget, test)
        } else {
            self.packet.walk(self.raster, w.mode, w.budget, test)
        }
        .map_err(|_| self.fail(0, w.mode, Mismatch::Setup))?;
        for lane in 0..LANES {
            let mut seen_s = None;
            let mut calls_s = 0u32;
            let test = |index: usize, c: u8| {
                seen_s = Some((index, c));
                calls_s = calls_s.saturating_add(1);
                c & bits != 0
            };
            let scalar = match self.rays.get_mut(lane).and_then(Option::as_mut) {
                Some(ray) => Some(
                    if w.skip {
                        ray.walk_skipping(self.raster, w.mode, w.budget, test)
                    } else {
                        ray.walk(self.raster, w.mode, w.budget, test)
                    }
                    .map_err(|_| self.fail(lane, w.mode, Mismatch::Setup))?,
                ),
                None => None,
            };
            let packet = end.lane(lane);
            if scalar != packet {
                return Err(self.fail(lane, w.mode, Mismatch::End { scalar, packet }));
            }
            let seen_packet = seen_p.get(lane).copied().flatten();
            let calls_packet = calls_p.get(lane).copied().unwrap_or(0);
            if seen_s != seen_packet || calls_s != calls_packet {
                return Err(self.fail(
                    lane,
                    w.mode,
                    Mismatch::Visit {
                        scalar: seen_s,
                        packet: seen_packet,
                    },
                ));
            }
            let ray = self.rays.get(lane).copied().flatten();
            if ray != self.packet.lane_ray(lane) || ray.map(|r| r.hit()) != self.packet.hit(lane) {
                return Err(self.fail(lane, w.mode, Mismatch::State));
            }
            if scalar.is_some() {
                self.report.lane_walks = self.report.lane_walks.saturating_add(1);
            }
            if scalar == Some(WalkEnd::Hit) {
                self.report.hits = self.report.hits.saturating_add(1);
            }
        }
        Ok(end)
    }

    /// [`Twins::walk`], and beside it a clone of the packet through the
    /// cell-bits fast path ([`RayPacket8::walk_until`], or
    /// [`RayPacket8::walk_until_skipping`]), which must end and leave every
    /// lane the same way.
    fn walk_both(&mut self, w: Walk) -> Result<(), LaneViolation> {
        let mut fast = self.packet.clone();
        let fast_end = if w.skip {
            fast.walk_until_skipping(self.raster, w.mode, w.budget, w.hit_bits)
        } else {
            fast.walk_until(self.raster, w.mode, w.budget, w.hit_bits)
        }
        .map_err(|_| self.fail(0, w.mode, Mismatch::Setup))?;
        let end = self.walk(w)?;
        for lane in 0..LANES {
            if fast_end.lane(lane) != end.lane(lane) {
                return Err(self.fail(
                    lane,
                    w.mode,
                    Mismatch::End {
                        scalar: end.lane(lane),
                        packet: fast_end.lane(lane),
                    },
                ));
            }
            if fast.lane_ray(lane) != self.packet.lane_ray(lane) {
                return Err(self.fail(lane, w.mode, Mismatch::State));
            }
        }
        Ok(())
    }

    /// Voxels the longest lane can still visit in `mode`, plus slack: a
    /// bound on the walks needed to finish every lane.
    fn bound(&self) -> u32 {
        self.rays
            .iter()
            .flatten()
            .map(|r| r.crossings().iter().fold(3u32, |a, &c| a.saturating_add(c)))
            .max()
            .unwrap_or(2)
    }

    fn all_done(&self) -> bool {
        self.rays.iter().flatten().all(DiscreteRay::is_done)
    }

    /// Repeats `w` until every lane is done.
    fn until_done(&mut self, w: Walk) -> Result<(), LaneViolation> {
        let bound = self.bound();
        let mut n = 0u32;
        while !self.all_done() {
            n = n.saturating_add(1);
            if n > bound {
                return Err(self.fail(0, w.mode, Mismatch::TooLong));
            }
            self.walk_both(w)?;
        }
        // One more walk after the end: every lane must report Exit again.
        self.walk_both(w)
    }
}

/// Checks that every lane of `packet` walks exactly like its scalar ray in
/// `mode`, from the packet's current state:
///
/// * stepping with budget 1 until every lane is done, comparing after each
///   step the outcome, the voxel (index and cell) the test saw, the hit and
///   the whole resume state of every lane;
/// * walking to the first [`cell::OPAQUE`] voxel and resuming after each hit
///   until done, with the same comparisons (both with a closure test and the
///   cell-bits test of [`RayPacket8::walk_until`]);
/// * both again with empty-space skipping, against the scalar
///   [`DiscreteRay::walk_skipping`] (the raster's distances and line level
///   decide the jumps; any cells are compared, not only valid fields).
///
/// # Errors
/// The first [`LaneViolation`].
pub fn check_packet_mode(
    raster: &Raster<'_>,
    packet: &RayPacket8,
    mode: Connectivity,
) -> Result<PacketReport, LaneViolation> {
    let mut total = PacketReport::default();
    for skip in [false, true] {
        for (budget, hit_bits) in [(1, 0), (u32::MAX, cell::OPAQUE)] {
            let mut t = Twins::new(raster, packet);
            t.until_done(Walk {
                mode,
                budget,
                hit_bits,
                skip,
            })?;
            total.lane_walks = total.lane_walks.saturating_add(t.report.lane_walks);
            total.hits = total.hits.saturating_add(t.report.hits);
        }
    }
    Ok(total)
}

/// Runs a script of walks (modes, budgets and hit tests may change from one
/// walk to the next, as a renderer resuming after a false hit does; skipping
/// or not) on
/// `packet` and on each lane's scalar ray, comparing every lane after every
/// walk as [`check_packet_mode`] does; then finishes every lane with
/// budget-1 steps in the last walk's mode.
///
/// # Errors
/// The first [`LaneViolation`].
pub fn check_packet_script(
    raster: &Raster<'_>,
    packet: &RayPacket8,
    script: &[Walk],
) -> Result<PacketReport, LaneViolation> {
    let mut t = Twins::new(raster, packet);
    let mut mode = Connectivity::Adaptive;
    let mut skip = false;
    for &w in script {
        t.walk_both(w)?;
        mode = w.mode;
        skip = w.skip;
    }
    t.until_done(Walk {
        mode,
        budget: 1,
        hit_bits: cell::OPAQUE,
        skip,
    })?;
    Ok(t.report)
}

/// [`check_packet_mode`] in all three connectivities.
///
/// # Errors
/// The first [`LaneViolation`].
pub fn check_packet(
    raster: &Raster<'_>,
    packet: &RayPacket8,
) -> Result<PacketReport, LaneViolation> {
    let mut total = PacketReport::default();
    for mode in Connectivity::ALL {
        let r = check_packet_mode(raster, packet, mode)?;
        total.lane_walks = total.lane_walks.saturating_add(r.lane_walks);
        total.hits = total.hits.saturating_add(r.hits);
    }
    Ok(total)
}
