//! The one line stepper. Six, TwentySix and Adaptive differ only in the
//! decision taken from the same three terms; every step adds one
//! precomputed offset to the single raster index.
//
// Implementation notes. In the drive frame (a = driving axis, b < c the
// minor axes) the state holds
//
//     e1 = before(a, b) > 0  ⇔  b crosses before a
//     e2 = before(a, c) > 0  ⇔  c crosses before a
//     e3 = before(b, c) > 0  ⇔  c crosses before b
//
// (see params.rs; none is ever zero, ties are already folded in).
//
// * A 6-step takes the earliest crossing: a if e1 < 0 && e2 < 0, else b if
//   e1 > 0 && e3 < 0, else c. It ends the ray if that axis has no crossing
//   left before the exit point.
// * A 26-step takes the a-crossing and, with it, every minor crossing that
//   comes no later (t_m ≤ t_a: e1 > thr_b, e2 > thr_c, where the threshold
//   undoes the tie bias so that exact ties go with the driving step). Since
//   |D_b|, |D_c| ≤ |D_a| at most one crossing per minor axis can come first,
//   so the step is 26-adjacent and lands on the voxel holding the ray just
//   after it enters the next a-slice, a voxel of the 6-ray. It ends the ray
//   when a has no crossing left.
// * Adaptive takes a 6-step when the current voxel's PROXIMITY bit is set and
//   a 26-step otherwise. Because both keep the terms exact, switching costs
//   nothing and every adaptive voxel is a voxel of the 6-ray.
// * Ties. A 6-step across an edge or corner (another axis crossing at the
//   same t, |e| = 1 for that pair) lands on an intermediate voxel and leaves
//   that crossing pending *at the current t*. A 26-step from there could owe
//   two crossings on one minor axis (when |D_m| = |D_a|), so `tie` records it
//   and the next step is a 6-step whatever the proximity flag says. Pure
//   26-steps never leave a tie pending: they take ties with the driving step.
//   With no tie pending, every pending crossing lies strictly after the
//   current t, which is what bounds a 26-step to one crossing per axis.
//
// Increments after crossing an axis (inc = 2·S·|D| per frame axis):
//     a: e1 += inc_b, e2 += inc_c
//     b: e1 -= inc_a, e3 += inc_c
//     c: e2 -= inc_a, e3 -= inc_b
// The terms stay within ±(2·S·max|D| + 1) < 2^49, so the wrapping adds below
// never wrap; they are wrapping only so that no panic path exists.

use super::params::Params;
use super::{State, WalkEnd};
use crate::raster::cell;

pub(crate) const SIX: u8 = 0;
pub(crate) const TWENTY_SIX: u8 = 1;
pub(crate) const ADAPTIVE: u8 = 2;

/// Moved-axes mask of a 6-step along frame axis `f`.
const fn bit(f: u32) -> u8 {
    1 << f
}

/// Walks from the current state, visiting at most `budget` voxels. `cells`
/// reads the plane (a slice lookup for a real raster, `Some(EMPTY)` for the
/// empty raster of [`super::DiscreteRay::path`]).
///
/// On return `s` describes the last visited voxel (the hit voxel after a hit),
/// so that a later call continues exactly after it. Only the entry voxel is
/// ever pending (`fresh`): a budget stop never advances past a visited voxel.
#[inline(always)]
pub(crate) fn run<const MODE: u8, C: Fn(usize) -> Option<u8>, T: FnMut(usize, u8) -> bool>(
    p: &Params,
    s: &mut State,
    cells: C,
    budget: u32,
    mut test: T,
) -> WalkEnd {
    if s.done {
        return WalkEnd::Exit;
    }
    let mut left = budget;
    let mut idx = s.index;
    let [mut e1, mut e2, mut e3] = s.err;
    let [mut ra, mut rb, mut rc] = s.rem;
    let mut steps = s.steps;
    let mut last = s.last;
    let mut tie = s.tie;
    let [off_a, off_b, off_c] = p.off;
    let [inc_a, inc_b, inc_c] = p.inc;
    let diag = p.diag;
    let [thr_b, thr_c] = p.thr;

    // The cell of the current voxel: needed by Adaptive to choose the step.
    let mut cur: u8;
    if s.fresh {
        // Visit the entry voxel.
        if left == 0 {
            return WalkEnd::Budget;
        }
        let Some(c) = cells(idx) else {
            s.done = true;
            return WalkEnd::Exit;
        };
        left = left.wrapping_sub(1);
        steps = steps.wrapping_add(1);
        s.fresh = false;
        s.steps = steps;
        if test(idx, c) {
            return WalkEnd::Hit;
        }
        cur = c;
    } else {
        let Some(c) = cells(idx) else {
            s.done = true;
            return WalkEnd::Exit;
        };
        cur = c;
    }

    let end = loop {
        if left == 0 {
            break WalkEnd::Budget;
        }
        // ---- advance: one step, one offset ----
        let six = match MODE {
            SIX => true,
            TWENTY_SIX => false,
            _ => tie || cur & cell::PROXIMITY != 0,
        };
        if six {
            if e1 < 0 && e2 < 0 {
                if ra == 0 {
                    break WalkEnd::Exit;
                }
                ra = ra.wrapping_sub(1);
                tie = e1 == -1 || e2 == -1;
                idx = idx.wrapping_add(off_a);
                e1 = e1.wrapping_add(inc_b);
                e2 = e2.wrapping_add(inc_c);
                last = bit(0);
            } else if e1 > 0 && e3 < 0 {
                if rb == 0 {
                    break WalkEnd::Exit;
                }
                rb = rb.wrapping_sub(1);
                tie = e1 == 1 || e3 == -1;
                idx = idx.wrapping_add(off_b);
                e1 = e1.wrapping_sub(inc_a);
                e3 = e3.wrapping_add(inc_c);
                last = bit(1);
            } else {
                if rc == 0 {
                    break WalkEnd::Exit;
                }
                rc = rc.wrapping_sub(1);
                // c never wins a tie against b (b < c), only against a.
                tie = e2 == 1;
                idx = idx.wrapping_add(off_c);
                e2 = e2.wrapping_sub(inc_a);
                e3 = e3.wrapping_sub(inc_b);
                last = bit(2);
            }
        } else {
            if ra == 0 {
                break WalkEnd::Exit;
            }
            ra = ra.wrapping_sub(1);
            tie = false;
            let sb = e1 > thr_b;
            let sc = e2 > thr_c;
            // All-ones when the minor axis steps, zero otherwise.
            let mb = i64::from(sb).wrapping_neg();
            let mc = i64::from(sc).wrapping_neg();
            e1 = e1.wrapping_add(inc_b).wrapping_sub(inc_a & mb);
            e2 = e2.wrapping_add(inc_c).wrapping_sub(inc_a & mc);
            e3 = e3.wrapping_add(inc_c & mb).wrapping_sub(inc_b & mc);
            rb = rb.wrapping_sub(u32::from(sb));
            rc = rc.wrapping_sub(u32::from(sc));
            let m = usize::from(sb) | (usize::from(sc) << 1);
            idx = idx.wrapping_add(*diag.get(m).unwrap_or(&off_a));
            last = 1 | (u8::from(sb) << 1) | (u8::from(sc) << 2);
        }

        // ---- visit ----
        let Some(c) = cells(idx) else {
            // Unreachable for a ray set up on this extent (the crossing counts
            // keep the index inside); ending is the panic-free answer.
            break WalkEnd::Exit;
        };
        left = left.wrapping_sub(1);
        steps = steps.wrapping_add(1);
        if test(idx, c) {
            break WalkEnd::Hit;
        }
        cur = c;
    };

    if matches!(end, WalkEnd::Exit) {
        s.done = true;
    }
    s.index = idx;
    s.err = [e1, e2, e3];
    s.rem = [ra, rb, rc];
    s.steps = steps;
    s.last = last;
    s.tie = tie;
    end
}
