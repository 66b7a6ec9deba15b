//! Invariant checkers for discrete rays, shared by unit tests, the `tests/`
//! crate and the cargo-fuzz targets (enable the `check` feature outside this
//! crate's own tests).
//!
//! Each checker walks a ray and returns `Err(Violation)` naming the first
//! broken invariant and the step where it broke. They allocate nothing and
//! are bounded by the ray's own length, so fuzzers can call them freely.

use crate::discrete_ray::{Connectivity, DiscreteRay, Face, Hit, WalkEnd};
use crate::raster::{Raster, cell, to_usize};

/// A broken invariant, with the 1-based number of the visit where it showed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum Violation {
    /// The iterator could not be created or a walk returned an error.
    Setup,
    /// The first voxel is not the ray's entry voxel.
    WrongEntry {
        /// Index visited first.
        index: usize,
    },
    /// A step moved no axis, moved an axis by more than one voxel, or moved
    /// against the direction's sign (which could revisit a voxel).
    BadMove {
        /// Visit number.
        step: u32,
        /// The movement reported.
        moved: [i8; 3],
    },
    /// A voxel outside the raster.
    OutOfRaster {
        /// Visit number.
        step: u32,
    },
    /// The raster index differs from `x + nx·y + nx·ny·z` of the tracked
    /// coordinates, or did not move by exactly the step's offset.
    IndexMismatch {
        /// Visit number.
        step: u32,
        /// Index reported by the stepper.
        index: usize,
        /// Index of the tracked coordinates.
        expected: usize,
    },
    /// A Six step (or an Adaptive step out of a flagged voxel) moved more
    /// than one axis.
    NotSixAdjacent {
        /// Visit number.
        step: u32,
    },
    /// A TwentySix step (or an Adaptive step out of an unflagged voxel) did
    /// not advance the driving axis.
    DrivingAxisStalled {
        /// Visit number.
        step: u32,
    },
    /// The face reported does not match the step taken.
    WrongFace {
        /// Visit number.
        step: u32,
    },
    /// More voxels than the connectivity allows between the endpoints, or
    /// the walk did not terminate within that bound.
    TooLong {
        /// Voxels visited before giving up.
        visits: u32,
        /// The bound.
        bound: u32,
    },
    /// Fewer (or more) voxels than the exact count for this connectivity.
    WrongCount {
        /// Voxels visited.
        visits: u32,
        /// Expected count.
        expected: u32,
    },
    /// The last voxel is not where the ray exits.
    WrongExit {
        /// Tracked coordinates of the last voxel.
        last: [u32; 3],
    },
    /// `walk` / `first_hit` disagree with the iterator about a hit, its step
    /// count, face, or the resumed sequence.
    HitMismatch {
        /// Number of the hit (1-based) in the resume sequence.
        nth: u32,
    },
    /// Walking with a small budget, resumed repeatedly, visited other voxels
    /// than the iterator.
    BudgetMismatch {
        /// Visit number.
        step: u32,
    },
    /// An Adaptive ray's hits differ from the Six ray's although the
    /// proximity flags cover every non-transparent voxel's neighbourhood.
    AdaptiveMissed {
        /// Number of the hit (1-based).
        nth: u32,
    },
    /// A voxel was visited by a skipping / packet walk but not by the
    /// reference walk, or vice versa.
    Diverged {
        /// Visit or hit number.
        step: u32,
    },
}

impl core::fmt::Display for Violation {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        core::fmt::Debug::fmt(self, f)
    }
}

/// What a successful [`check_ray`] saw.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RayReport {
    /// Voxels visited from entry to exit.
    pub visits: u32,
    /// Non-transparent voxels among them.
    pub opaque: u32,
    /// The first hit, as `first_hit` reported it.
    pub first_hit: Option<Hit>,
    /// The last voxel visited.
    pub last: [u32; 3],
}

/// Walks `ray` from its start in `mode` and checks every stepping invariant:
///
/// * the first voxel is the entry voxel;
/// * each step moves every axis by 0 or 1 voxel in the direction's sign and
///   at least one axis (so no voxel repeats), and the index moves by exactly
///   the matching offset and equals `x + nx·y + nx·ny·z` of independently
///   tracked coordinates, which stay inside the raster;
/// * Six steps and Adaptive steps out of flagged voxels move one axis;
///   TwentySix steps and Adaptive steps out of unflagged voxels advance the
///   driving axis; the reported face is the one the step entered through;
/// * Six visits exactly `1 + Σ crossings` voxels and ends at the exit voxel,
///   TwentySix exactly `1 + crossings[driving]` and ends in the exit slice,
///   Adaptive at most `1 + Σ crossings` and ends in the exit slice;
/// * `first_hit` and its resumption find the opaque voxels of the iteration
///   in order, with the same step counts, faces and whole resume state;
/// * walking with budget 1 and 3, resumed until done, visits the same voxels.
///
/// # Errors
/// The first [`Violation`] found.
pub fn check_ray(
    raster: &Raster<'_>,
    ray: &DiscreteRay,
    mode: Connectivity,
) -> Result<RayReport, Violation> {
    let extent = raster.extent();
    let strides = extent.strides();
    let dir = ray.dir();
    let drive = ray.driving_axis();
    let crossings = ray.crossings();
    let six_count = crossings.iter().fold(1u32, |a, &c| a.saturating_add(c));
    let drive_count = crossings.get(drive).copied().unwrap_or(0).saturating_add(1);
    let (bound, exact) = match mode {
        Connectivity::Six => (six_count, Some(six_count)),
        Connectivity::TwentySix => (drive_count, Some(drive_count)),
        Connectivity::Adaptive => (six_count, None),
    };

    let voxels = (*ray).voxels(raster, mode).map_err(|_| Violation::Setup)?;
    let mut coord = ray.entry_voxel();
    let mut prev_index = 0usize;
    let mut prev_cell = 0u8;
    let mut prev_single = false;
    let mut visits = 0u32;
    let mut opaque = 0u32;
    let mut first_opaque: Option<(usize, u32, Option<Face>)> = None;
    // Run one past the bound so that non-termination is caught.
    for v in voxels.take(to_usize(bound.saturating_add(1))) {
        visits = visits.saturating_add(1);
        let step = visits;
        if visits == 1 {
            let expected = extent.index(coord).ok_or(Violation::OutOfRaster { step })?;
            if v.index != expected || v.moved != [0; 3] {
                return Err(Violation::WrongEntry { index: v.index });
            }
            if v.face != ray.entry_face() {
                return Err(Violation::WrongFace { step });
            }
        } else {
            let mut n_moved = 0u32;
            let mut offset = 0usize;
            for axis in 0..3 {
                let m = v.moved.get(axis).copied().unwrap_or(0);
                let d = dir.get(axis).copied().unwrap_or(0);
                if m == 0 {
                    continue;
                }
                if !((m == 1 && d > 0) || (m == -1 && d < 0)) {
                    return Err(Violation::BadMove {
                        step,
                        moved: v.moved,
                    });
                }
                n_moved = n_moved.saturating_add(1);
                let stride = strides.get(axis).copied().unwrap_or(0);
                let c = coord.get_mut(axis).ok_or(Violation::OutOfRaster { step })?;
                if m > 0 {
                    *c = c.checked_add(1).ok_or(Violation::OutOfRaster { step })?;
                    offset = offset.wrapping_add(stride);
                } else {
                    *c = c.checked_sub(1).ok_or(Violation::OutOfRaster { step })?;
                    offset = offset.wrapping_sub(stride);
                }
            }
            if n_moved == 0 {
                return Err(Violation::BadMove {
                    step,
                    moved: v.moved,
                });
            }
            let expected = extent.index(coord).ok_or(Violation::OutOfRaster { step })?;
            if v.index != expected || prev_index.wrapping_add(offset) != v.index {
                return Err(Violation::IndexMismatch {
                    step,
                    index: v.index,
                    expected,
                });
            }
            let wants_six = match mode {
                Connectivity::Six => true,
                Connectivity::TwentySix => false,
                Connectivity::Adaptive => prev_cell & cell::PROXIMITY != 0,
            };
            let drive_moved = v.moved.get(drive).copied().unwrap_or(0) != 0;
            if wants_six && n_moved != 1 {
                return Err(Violation::NotSixAdjacent { step });
            }
            // An adaptive single-axis step out of an unflagged voxel is allowed
            // only to finish an edge/corner crossing a 6-step started (the
            // subsequence check against Six below pins down which).
            let finishing_tie = mode == Connectivity::Adaptive && n_moved == 1 && prev_single;
            if !wants_six && !drive_moved && !finishing_tie {
                return Err(Violation::DrivingAxisStalled { step });
            }
            prev_single = n_moved == 1;
            let face_axis = if n_moved == 1 {
                v.moved.iter().position(|&m| m != 0).unwrap_or(0)
            } else {
                drive
            };
            let want_face = face_entered(face_axis, dir.get(face_axis).copied().unwrap_or(0) > 0);
            if v.face != Some(want_face) {
                return Err(Violation::WrongFace { step });
            }
        }
        if v.cell & cell::OPAQUE != 0 {
            opaque = opaque.saturating_add(1);
            if first_opaque.is_none() {
                first_opaque = Some((v.index, step, v.face));
            }
        }
        prev_index = v.index;
        prev_cell = v.cell;
    }
    if visits > bound {
        return Err(Violation::TooLong { visits, bound });
    }
    if let Some(expected) = exact
        && visits != expected
    {
        return Err(Violation::WrongCount { visits, expected });
    }
    let exit = ray.exit_voxel();
    let exit_ok = match mode {
        Connectivity::Six => coord == exit,
        _ => coord.get(drive) == exit.get(drive),
    };
    if !exit_ok {
        return Err(Violation::WrongExit { last: coord });
    }

    if mode == Connectivity::Adaptive {
        check_subsequence_of_six(raster, ray)?;
    }

    // Hits through walk / first_hit, resumed, against the iteration.
    let first_hit = check_hit_sequence(raster, ray, mode, first_opaque, opaque)?;
    check_budget_walks(raster, ray, mode, visits)?;
    Ok(RayReport {
        visits,
        opaque,
        first_hit,
        last: coord,
    })
}

fn face_entered(axis: usize, rising: bool) -> Face {
    match (axis, rising) {
        (0, true) => Face::XMin,
        (0, false) => Face::XMax,
        (1, true) => Face::YMin,
        (1, false) => Face::YMax,
        (_, true) => Face::ZMin,
        (_, false) => Face::ZMax,
    }
}

/// Every voxel of the Adaptive ray is a voxel of the Six ray, in order.
fn check_subsequence_of_six(raster: &Raster<'_>, ray: &DiscreteRay) -> Result<(), Violation> {
    let mut six = (*ray)
        .voxels(raster, Connectivity::Six)
        .map_err(|_| Violation::Setup)?;
    let adaptive = (*ray)
        .voxels(raster, Connectivity::Adaptive)
        .map_err(|_| Violation::Setup)?;
    for (n, v) in (1u32..).zip(adaptive) {
        if !six.any(|s| s.index == v.index) {
            return Err(Violation::Diverged { step: n });
        }
    }
    Ok(())
}

/// `first_hit` repeatedly (resuming after each hit) must find exactly the
/// opaque voxels of the iteration, in order.
fn check_hit_sequence(
    raster: &Raster<'_>,
    ray: &DiscreteRay,
    mode: Connectivity,
    first_opaque: Option<(usize, u32, Option<Face>)>,
    opaque: u32,
) -> Result<Option<Hit>, Violation> {
    let mut walker = *ray;
    let mut iter = (*ray).voxels(raster, mode).map_err(|_| Violation::Setup)?;
    let mut first = None;
    let mut nth = 0u32;
    loop {
        let got = walker
            .first_hit(raster, mode)
            .map_err(|_| Violation::Setup)?;
        // The next opaque voxel of the plain iteration, with its position.
        let want = loop {
            match iter.next() {
                Some(v) if v.cell & cell::OPAQUE != 0 => break Some((v, iter.ray().steps())),
                Some(_) => {}
                None => break None,
            }
        };
        nth = nth.saturating_add(1);
        match (got, want) {
            (None, None) => break,
            (Some(h), Some((v, steps))) => {
                // The whole resume state must agree, not just the hit: the
                // unbounded walk reconstructs what its loop did not carry.
                if h.index != v.index
                    || h.steps != steps
                    || h.face != v.face
                    || walker != *iter.ray()
                {
                    return Err(Violation::HitMismatch { nth });
                }
                if first.is_none() {
                    if first_opaque != Some((h.index, h.steps, h.face)) {
                        return Err(Violation::HitMismatch { nth });
                    }
                    first = Some(h);
                }
            }
            _ => return Err(Violation::HitMismatch { nth }),
        }
        if nth > opaque.saturating_add(1) {
            return Err(Violation::HitMismatch { nth });
        }
    }
    Ok(first)
}

/// Budgeted walks, resumed until the exit, must visit the same voxels as the
/// iterator and stop exactly at their budgets.
fn check_budget_walks(
    raster: &Raster<'_>,
    ray: &DiscreteRay,
    mode: Connectivity,
    visits: u32,
) -> Result<(), Violation> {
    for budget in [1u32, 3] {
        let mut walker = *ray;
        let mut reference = (*ray).voxels(raster, mode).map_err(|_| Violation::Setup)?;
        let mut seen = 0u32;
        let mut mismatch = false;
        loop {
            let mut in_call = 0u32;
            let end = walker
                .walk(raster, mode, budget, |index, _| {
                    in_call = in_call.saturating_add(1);
                    seen = seen.saturating_add(1);
                    match reference.next() {
                        Some(v) if v.index == index => {}
                        _ => mismatch = true,
                    }
                    false
                })
                .map_err(|_| Violation::Setup)?;
            if mismatch {
                return Err(Violation::BudgetMismatch { step: seen });
            }
            match end {
                WalkEnd::Budget if in_call == budget => {}
                WalkEnd::Exit => break,
                _ => return Err(Violation::BudgetMismatch { step: seen }),
            }
            if seen > visits {
                return Err(Violation::BudgetMismatch { step: seen });
            }
        }
        if seen != visits || reference.next().is_some() {
            return Err(Violation::BudgetMismatch { step: seen });
        }
    }
    Ok(())
}

/// Checks the paper's step counts for a segment between two voxel centres
/// inside the raster: the Six ray visits `|Δx| + |Δy| + |Δz| + 1` voxels
/// from `from` to `to`, the TwentySix ray `max(|Δx|, |Δy|, |Δz|) + 1`,
/// starting at `from` and ending in `to`'s slice across the driving axis.
///
/// # Errors
/// [`Violation::WrongCount`], [`Violation::WrongEntry`] or
/// [`Violation::WrongExit`], or any violation of [`check_ray`].
pub fn check_lattice_counts(
    raster: &Raster<'_>,
    from: [u32; 3],
    to: [u32; 3],
) -> Result<(), Violation> {
    let centre = |v: [u32; 3]| v.map(crate::fixed::voxel_centre);
    let ray = DiscreteRay::segment(raster.extent(), centre(from), centre(to))
        .map_err(|_| Violation::Setup)?
        .ok_or(Violation::Setup)?;
    let delta = [0, 1, 2].map(|k| {
        from.get(k)
            .copied()
            .unwrap_or(0)
            .abs_diff(to.get(k).copied().unwrap_or(0))
    });
    let n6 = delta.iter().fold(0u32, |a, &d| a.saturating_add(d));
    let n26 = delta.iter().copied().max().unwrap_or(0);
    if ray.entry_voxel() != from {
        return Err(Violation::WrongEntry { index: 0 });
    }
    if ray.exit_voxel() != to {
        return Err(Violation::WrongExit {
            last: ray.exit_voxel(),
        });
    }
    for (mode, expected) in [(Connectivity::Six, n6), (Connectivity::TwentySix, n26)] {
        let report = check_ray(raster, &ray, mode)?;
        if report.visits != expected.saturating_add(1) {
            return Err(Violation::WrongCount {
                visits: report.visits,
                expected: expected.saturating_add(1),
            });
        }
    }
    check_ray(raster, &ray, Connectivity::Adaptive)?;
    Ok(())
}

/// With proximity flags covering the 26-neighbourhood of every opaque voxel
/// (as [`crate::proximity::flag_neighbourhood`] sets them), an Adaptive ray
/// must find the same sequence of opaque voxels as the Six ray, hit by hit
/// through resumption.
///
/// # Errors
/// [`Violation::AdaptiveMissed`] with the number of the first differing hit.
pub fn check_adaptive_matches_six(raster: &Raster<'_>, ray: &DiscreteRay) -> Result<(), Violation> {
    let mut six = *ray;
    let mut adaptive = *ray;
    let mut nth = 0u32;
    let limit = ray
        .crossings()
        .iter()
        .fold(2u32, |a, &c| a.saturating_add(c));
    loop {
        nth = nth.saturating_add(1);
        let a = six
            .first_hit(raster, Connectivity::Six)
            .map_err(|_| Violation::Setup)?;
        let b = adaptive
            .first_hit(raster, Connectivity::Adaptive)
            .map_err(|_| Violation::Setup)?;
        match (a, b) {
            (None, None) => return Ok(()),
            (Some(x), Some(y)) if x.index == y.index && x.face == y.face => {}
            _ => return Err(Violation::AdaptiveMissed { nth }),
        }
        if nth > limit {
            return Err(Violation::TooLong {
                visits: nth,
                bound: limit,
            });
        }
    }
}

/// Empty-space skipping must not change what a ray finds: with the proximity
/// distances of [`crate::proximity::distance_field`] in the plane,
/// [`DiscreteRay::first_hit_skipping`] and [`DiscreteRay::first_hit`] find the
/// same hits, hit by hit through resumption, with the same faces and the same
/// resume state (all but the step count, which counts visits). Budgeted
/// skipping walks (1 and 3 voxels per call, the reference that tracks every
/// variable) must agree with the unbounded ones the same way.
///
/// # Errors
/// [`Violation::Diverged`] with the number of the first differing hit.
pub fn check_skipping(
    raster: &Raster<'_>,
    ray: &DiscreteRay,
    mode: Connectivity,
) -> Result<(), Violation> {
    let without_steps = |r: &DiscreteRay| {
        let mut s = *r.state();
        s.steps = 0;
        s
    };
    let limit = ray
        .crossings()
        .iter()
        .fold(2u32, |a, &c| a.saturating_add(c));
    let mut plain = *ray;
    let mut skipping = *ray;
    let mut nth = 0u32;
    loop {
        nth = nth.saturating_add(1);
        let a = plain
            .first_hit(raster, mode)
            .map_err(|_| Violation::Setup)?;
        let b = skipping
            .first_hit_skipping(raster, mode)
            .map_err(|_| Violation::Setup)?;
        match (a, b) {
            (None, None) => break,
            (Some(x), Some(y)) if x.index == y.index && x.face == y.face => {}
            _ => return Err(Violation::Diverged { step: nth }),
        }
        if without_steps(&plain) != without_steps(&skipping) {
            return Err(Violation::Diverged { step: nth });
        }
        if nth > limit {
            return Err(Violation::TooLong {
                visits: nth,
                bound: limit,
            });
        }
    }
    // Budgeted skipping walks against unbounded ones.
    for budget in [1u32, 3] {
        let mut unbounded = *ray;
        let mut budgeted = *ray;
        let mut nth = 0u32;
        loop {
            nth = nth.saturating_add(1);
            let a = unbounded
                .first_hit_skipping(raster, mode)
                .map_err(|_| Violation::Setup)?;
            let end = loop {
                match budgeted.walk_skipping(raster, mode, budget, |_, c| c & cell::OPAQUE != 0) {
                    Ok(WalkEnd::Budget) => {}
                    Ok(e) => break e,
                    Err(_) => return Err(Violation::Setup),
                }
            };
            match (a, end) {
                (None, WalkEnd::Exit) => break,
                (Some(h), WalkEnd::Hit) if h == budgeted.hit() && unbounded == budgeted => {}
                _ => return Err(Violation::Diverged { step: nth }),
            }
            if nth > limit {
                return Err(Violation::TooLong {
                    visits: nth,
                    bound: limit,
                });
            }
        }
    }
    Ok(())
}
