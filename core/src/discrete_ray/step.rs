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
//
// Specialisation. A walk is a sequence of *runs*: a 26-run takes 26-steps
// and carries only the index, e1, e2 and the driving-axis counter (e3, the
// minor counters and the step count are linear in the numbers of crossings
// taken and are reconstructed exactly when the run ends); a 6-run takes
// 6-steps and derives its step count from the crossings it consumed. Six is
// one 6-run, TwentySix one 26-run, Adaptive alternates: a 26-run ends on a
// voxel whose PROXIMITY flag is set (the paper's "one test per step"), a
// 6-run on a voxel whose flag is clear with no tie pending. Walks whose
// budget can stop them (the iterator's, the checkers') instead track every
// variable at every step: they are the reference the checkers compare the
// reconstructing runs against, state for state.

use super::params::Params;
use super::{State, WalkEnd};
use crate::raster::cell;

pub(crate) const SIX: u8 = 0;
pub(crate) const TWENTY_SIX: u8 = 1;
pub(crate) const ADAPTIVE: u8 = 2;

/// How a run ended.
enum Run {
    /// The walk ends.
    End(WalkEnd),
    /// The current voxel asks for the other kind of step (Adaptive only).
    Switch,
}

/// Walks from the current state, visiting at most `budget` voxels. `cells`
/// reads the plane (a slice lookup for a real raster, `Some(EMPTY)` for the
/// empty raster of [`super::DiscreteRay::path`]).
///
/// On return `s` describes the last visited voxel (the hit voxel after a hit),
/// so that a later call continues exactly after it. Only the entry voxel is
/// ever pending (`fresh`): a budget stop never advances past a visited voxel.
#[inline(always)]
pub(crate) fn run<
    const MODE: u8,
    const SKIP: bool,
    C: Fn(usize) -> Option<u8> + Copy,
    T: FnMut(usize, u8) -> bool,
>(
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
    if s.fresh {
        // Visit the entry voxel.
        if left == 0 {
            return WalkEnd::Budget;
        }
        let Some(c) = cells(s.index) else {
            s.done = true;
            return WalkEnd::Exit;
        };
        left = left.wrapping_sub(1);
        s.fresh = false;
        s.steps = s.steps.wrapping_add(1);
        if test(s.index, c) {
            return WalkEnd::Hit;
        }
    }
    // A walk visits at most one voxel per crossing left: when the budget
    // covers them all it cannot stop the walk and need not be counted.
    let [ra, rb, rc] = s.rem;
    let most = u64::from(ra)
        .wrapping_add(u64::from(rb))
        .wrapping_add(u64::from(rc));
    let end = if u64::from(left) > most {
        drive::<MODE, SKIP, false, C, T>(p, s, cells, &mut left, &mut test)
    } else {
        drive::<MODE, SKIP, true, C, T>(p, s, cells, &mut left, &mut test)
    };
    if matches!(end, WalkEnd::Exit) {
        s.done = true;
    }
    end
}

/// Runs the mode's steps from a visited voxel until the walk ends.
#[inline(always)]
fn drive<
    const MODE: u8,
    const SKIP: bool,
    const BUDGETED: bool,
    C: Fn(usize) -> Option<u8> + Copy,
    T: FnMut(usize, u8) -> bool,
>(
    p: &Params,
    s: &mut State,
    cells: C,
    left: &mut u32,
    test: &mut T,
) -> WalkEnd {
    match MODE {
        SIX => match six_run::<BUDGETED, false, C, T>(p, s, cells, left, test) {
            Run::End(e) => e,
            Run::Switch => WalkEnd::Exit, // a pure Six run never switches
        },
        TWENTY_SIX => {
            match twenty_six_run::<BUDGETED, false, SKIP, C, T>(p, s, cells, left, test) {
                Run::End(e) => e,
                Run::Switch => WalkEnd::Exit,
            }
        }
        _ => loop {
            let Some(cur) = cells(s.index) else {
                return WalkEnd::Exit;
            };
            let r = if s.tie || cur & cell::PROXIMITY != 0 {
                six_run::<BUDGETED, true, C, T>(p, s, cells, left, test)
            } else {
                twenty_six_run::<BUDGETED, true, SKIP, C, T>(p, s, cells, left, test)
            };
            if let Run::End(e) = r {
                return e;
            }
        },
    }
}

/// 6-steps from the current voxel. With `ADAPTIVE`, the run also ends (with
/// [`Run::Switch`]) after visiting a voxel whose PROXIMITY flag is clear
/// when no tie is pending.
///
/// Not inlined: a run is called once per walk (or per switch), and its loop
/// gets the registers to itself.
#[inline(never)]
fn six_run<
    const BUDGETED: bool,
    const ADAPTIVE: bool,
    C: Fn(usize) -> Option<u8> + Copy,
    T: FnMut(usize, u8) -> bool,
>(
    p: &Params,
    s: &mut State,
    cells: C,
    left: &mut u32,
    test: &mut T,
) -> Run {
    let start = *s;
    let mut idx = s.index;
    let [mut e1, mut e2, mut e3] = s.err;
    let [mut ra, mut rb, mut rc] = s.rem;
    let mut steps = s.steps;
    let mut last = s.last;
    let mut tie = s.tie;
    let [off_a, off_b, off_c] = p.off;
    let [inc_a, inc_b, inc_c] = p.inc;
    // Track the tie flag at every step when someone reads it during the run.
    let track = BUDGETED || ADAPTIVE;

    let end = loop {
        if BUDGETED {
            if *left == 0 {
                break Run::End(WalkEnd::Budget);
            }
            *left = left.wrapping_sub(1);
        }
        // ---- advance: the earliest crossing ----
        if e1 < 0 && e2 < 0 {
            if ra == 0 {
                break Run::End(WalkEnd::Exit);
            }
            ra = ra.wrapping_sub(1);
            if track {
                tie = e1 == -1 || e2 == -1;
            }
            idx = idx.wrapping_add(off_a);
            e1 = e1.wrapping_add(inc_b);
            e2 = e2.wrapping_add(inc_c);
            last = 1;
        } else if e1 > 0 && e3 < 0 {
            if rb == 0 {
                break Run::End(WalkEnd::Exit);
            }
            rb = rb.wrapping_sub(1);
            if track {
                tie = e1 == 1 || e3 == -1;
            }
            idx = idx.wrapping_add(off_b);
            e1 = e1.wrapping_sub(inc_a);
            e3 = e3.wrapping_add(inc_c);
            last = 2;
        } else {
            if rc == 0 {
                break Run::End(WalkEnd::Exit);
            }
            rc = rc.wrapping_sub(1);
            if track {
                // c never wins a tie against b (b < c), only against a.
                tie = e2 == 1;
            }
            idx = idx.wrapping_add(off_c);
            e2 = e2.wrapping_sub(inc_a);
            e3 = e3.wrapping_sub(inc_b);
            last = 4;
        }
        if BUDGETED {
            steps = steps.wrapping_add(1);
        }
        // ---- visit ----
        let Some(c) = cells(idx) else {
            // Unreachable for a ray set up on this extent (the crossing counts
            // keep the index inside); ending is the panic-free answer.
            break Run::End(WalkEnd::Exit);
        };
        if test(idx, c) {
            break Run::End(WalkEnd::Hit);
        }
        if ADAPTIVE && !tie && c & cell::PROXIMITY == 0 {
            break Run::Switch;
        }
    };

    if !BUDGETED {
        // One voxel per crossing consumed.
        let taken = start
            .rem
            .iter()
            .zip([ra, rb, rc])
            .fold(0u32, |t, (&r0, r)| t.wrapping_add(r0.wrapping_sub(r)));
        steps = start.steps.wrapping_add(taken);
        if !track && taken > 0 {
            // The tie test of the last step, on the terms before it.
            tie = match last {
                1 => e1.wrapping_sub(inc_b) == -1 || e2.wrapping_sub(inc_c) == -1,
                2 => e1.wrapping_add(inc_a) == 1 || e3.wrapping_sub(inc_c) == -1,
                _ => e2.wrapping_add(inc_a) == 1,
            };
        }
    }
    s.index = idx;
    s.err = [e1, e2, e3];
    s.rem = [ra, rb, rc];
    s.steps = steps;
    s.last = last;
    s.tie = tie;
    end
}

/// 26-steps from the current voxel. With `ADAPTIVE`, the run also ends (with
/// [`Run::Switch`]) after visiting a voxel whose PROXIMITY flag is set.
///
/// Not inlined, as [`six_run`].
#[inline(never)]
fn twenty_six_run<
    const BUDGETED: bool,
    const ADAPTIVE: bool,
    const SKIP: bool,
    C: Fn(usize) -> Option<u8> + Copy,
    T: FnMut(usize, u8) -> bool,
>(
    p: &Params,
    s: &mut State,
    cells: C,
    left: &mut u32,
    test: &mut T,
) -> Run {
    let start = *s;
    let mut idx = s.index;
    let [mut e1, mut e2, mut e3] = s.err;
    let [mut ra, mut rb, mut rc] = s.rem;
    let mut steps = s.steps;
    let mut last = s.last;
    let [inc_a, inc_b, inc_c] = p.inc;
    let diag = p.diag;
    // Decide on the terms shifted by their thresholds, f = e − thr, so that
    // f > 0 ⇔ the minor axis crosses no later than the driving axis.
    let [thr_b, thr_c] = p.thr;
    let mut f1 = e1.wrapping_sub(thr_b);
    let mut f2 = e2.wrapping_sub(thr_c);
    // Minor axes of the last step (bit 0 = b, bit 1 = c).
    let mut minors = 0usize;
    // Driving-axis crossings left before the exit.
    let mut todo = ra;
    // With skipping: the current voxel's cell, and the voxels visited (a
    // jump visits one voxel for k steps).
    let mut cur = if SKIP { cells(idx).unwrap_or(0) } else { 0 };
    let mut visits = 0u32;
    // Division by inc_a for the jumps (inc_a > 0 whenever a jump is taken).
    // Made at the first jump: most runs never jump.
    let mut by_a: Option<Reciprocal> = None;

    // How the loop ended: exits write it, the loop body never does.
    // The budget is checked before the exit, as in `six_run`: a call that
    // visited its last budgeted voxel reports Budget, the next one Exit.
    let mut end = Run::End(WalkEnd::Exit);
    loop {
        if BUDGETED {
            if *left == 0 {
                end = Run::End(WalkEnd::Budget);
                break;
            }
            *left = left.wrapping_sub(1);
        }
        // ---- advance: the driving crossing and the minors no later ----
        if todo == 0 {
            break;
        }
        // Far from every non-transparent voxel, take k 26-steps at once.
        let k = if SKIP { skip_count(cur, todo) } else { 1 };
        if SKIP && k > 1 {
            let by_a = *by_a.get_or_insert_with(|| Reciprocal::new(inc_a));
            let (nb, f1k, lb) = jump_count(f1, k, by_a, inc_a, inc_b);
            let (nc, f2k, lc) = jump_count(f2, k, by_a, inc_a, inc_c);
            let kk = i64::from(k);
            f1 = f1k;
            f2 = f2k;
            let [off_a, off_b, off_c] = p.off;
            let times = |off: usize, n: i64| off.wrapping_mul(usize::try_from(n).unwrap_or(0));
            idx = idx
                .wrapping_add(times(off_a, kk))
                .wrapping_add(times(off_b, nb))
                .wrapping_add(times(off_c, nc));
            todo = todo.wrapping_sub(k);
            minors = usize::from(lb) | (usize::from(lc) << 1);
            if BUDGETED {
                e3 = e3
                    .wrapping_add(nb.wrapping_mul(inc_c))
                    .wrapping_sub(nc.wrapping_mul(inc_b));
                rb = rb.wrapping_sub(u32::try_from(nb).unwrap_or(0));
                rc = rc.wrapping_sub(u32::try_from(nc).unwrap_or(0));
                steps = steps.wrapping_add(1);
                last = 1 | (u8::from(lb) << 1) | (u8::from(lc) << 2);
            }
        } else {
            todo = todo.wrapping_sub(1);
            let sb = usize::from(f1 > 0);
            let sc = usize::from(f2 > 0);
            // inc_a masked to zero unless the minor axis steps too.
            let mask = |m: usize| i64::from(m != 0).wrapping_neg();
            f1 = f1.wrapping_add(inc_b).wrapping_sub(inc_a & mask(sb));
            f2 = f2.wrapping_add(inc_c).wrapping_sub(inc_a & mask(sc));
            minors = sb | (sc << 1);
            // `& 3` keeps the table lookup free of a bounds check.
            idx = idx.wrapping_add(diag[minors & 3]);
            if BUDGETED {
                let (mb, mc) = (mask(sb), mask(sc));
                e3 = e3.wrapping_add(inc_c & mb).wrapping_sub(inc_b & mc);
                rb = rb.wrapping_sub(u32::from(sb != 0));
                rc = rc.wrapping_sub(u32::from(sc != 0));
                steps = steps.wrapping_add(1);
                last = 1 | (u8::from(sb != 0) << 1) | (u8::from(sc != 0) << 2);
            }
        }
        if SKIP {
            // Every advance, one step or a jump, visits one voxel.
            visits = visits.wrapping_add(1);
        }
        // ---- visit ----
        let Some(c) = cells(idx) else {
            break;
        };
        if test(idx, c) {
            end = Run::End(WalkEnd::Hit);
            break;
        }
        if ADAPTIVE && c & cell::PROXIMITY != 0 {
            end = Run::Switch;
            break;
        }
        if SKIP {
            cur = c;
        }
    }
    e1 = f1.wrapping_add(thr_b);
    e2 = f2.wrapping_add(thr_c);
    ra = todo;

    let k = start.rem[0].wrapping_sub(ra);
    if !BUDGETED && k > 0 {
        // e1 = e1₀ + k·inc_b − n_b·inc_a, and likewise for c: solve for the
        // numbers of minor crossings (exact: inc_a > 0 since the ray moved).
        // |k·inc| < 2^65, so this is done in i128, once per run.
        let kb = i128::from(k);
        // The numerator is n·inc_a with n ≤ 2^16 and inc_a < 2^48: it fits
        // u64, and the exact division by inc_a is one hardware division.
        let ua = u64::try_from(inc_a).unwrap_or(1).max(1);
        let count = |e0: i64, e: i64, inc: i64| -> u32 {
            let num = i128::from(e0)
                .wrapping_add(kb.wrapping_mul(i128::from(inc)))
                .wrapping_sub(i128::from(e));
            let n = u64::try_from(num).unwrap_or(0).checked_div(ua).unwrap_or(0);
            u32::try_from(n).unwrap_or(0)
        };
        let nb = count(start.err[0], e1, inc_b);
        let nc = count(start.err[1], e2, inc_c);
        rb = start.rem[1].wrapping_sub(nb);
        rc = start.rem[2].wrapping_sub(nc);
        e3 = start.err[2]
            .wrapping_add(inc_c.wrapping_mul(i64::from(nb)))
            .wrapping_sub(inc_b.wrapping_mul(i64::from(nc)));
        steps = start.steps.wrapping_add(if SKIP { visits } else { k });
        last = 1 | (u8::try_from(minors).unwrap_or(0) << 1);
    }
    s.index = idx;
    s.err = [e1, e2, e3];
    s.rem = [ra, rb, rc];
    s.steps = steps;
    s.last = last;
    if k > 0 {
        // 26-steps take ties with the driving step: none is left pending.
        s.tie = false;
    }
    end
}

/// The shortest jump worth taking. A jump's length is read from the cell
/// just loaded, so the next load waits for this one, while single steps
/// compute their addresses without looking at the cells and overlap their
/// loads; a jump pays only when it replaces several steps. Measured on
/// balls4 (raster 1024, 512², one thread, seven interleaved runs, jumps of
/// `d − 1`): minimum jumps of 2, 3 and 4 rendered in 0.156, 0.148 and
/// 0.143 s (medians) with 13.5, 14.5 and 15.9 camera-ray steps per ray.
pub(crate) const MIN_JUMP: u8 = 4;

/// The smallest line stand-in ([`crate::raster::Raster::with_lines`]) a
/// skipping walk reads instead of the plane: one at distance 8 or more.
/// Nearer lines send the walk to the plane, whose cell may allow a longer
/// jump than the line's smallest distance (or any jump at all). Measured on
/// balls4 (raster 1024, 512², one thread, seven interleaved runs): stand-ins
/// from distance 5 (the shortest jump), 8 and 16 rendered in 0.136, 0.132
/// and 0.137 s (medians) with 15.1, 14.9 and 14.7 steps per ray; camera rays
/// take 16.6 steps at 5 and 16.25 at 8, against 15.9 reading only the plane.
pub(crate) const LINE_JUMP: u8 = 8 << crate::raster::cell::DISTANCE_SHIFT;

/// How many 26-steps a run may take at once from a voxel whose cell is
/// `cur`, with `todo` driving crossings left: `d − 1` for a proximity
/// distance `d ≥ MIN_JUMP + 1`, else 1.
///
/// Why `d − 1`: after `i` 26-steps the ray is at chessboard distance at
/// most `i` from the current voxel, so the voxels a jump passes over (steps
/// `1 ..= d − 2`) lie at distance at least 2 from every non-transparent
/// voxel: transparent and unflagged. Single steps would have visited them,
/// decided nothing on them (no hit, no switch to 6-steps), and arrived at
/// the same state; the voxel the jump lands on (step `d − 1`, possibly
/// flagged) is visited as single steps would visit it.
#[inline(always)]
fn skip_count(cur: u8, todo: u32) -> u32 {
    let d = crate::proximity::distance(cur);
    if d > MIN_JUMP {
        u32::from(d.wrapping_sub(1)).min(todo)
    } else {
        1
    }
}

/// The number of crossings `n` of a minor axis among the next `k ≥ 2`
/// 26-steps from the threshold-shifted term `f`, the term after them, and
/// whether the last of those steps took a crossing.
///
/// A 26-step maps `f` to `f + inc_m − inc_a·[f > 0]`, which keeps it in
/// `(inc_m − inc_a, inc_m]` after the first step from any reachable
/// `f ∈ (−inc_a, inc_a]`; so after `i ≥ 1` steps the count is the unique
/// `n_i` putting `f + i·inc_m − n_i·inc_a` in that interval:
/// `n_i = ⌈(f + (i − 1)·inc_m) / inc_a⌉`, which is 0 when the numerator is
/// not positive. The values are below 2^55 (k ≤ 62).
///
/// The last step (from a term `f'` already in that interval, as `k ≥ 2`)
/// took a crossing iff `f' > 0`, which leaves the new term in
/// `(inc_m − inc_a, 2·inc_m − inc_a]`; otherwise it lands in
/// `(2·inc_m − inc_a, inc_m]`. One comparison tells them apart.
#[inline(always)]
fn jump_count(f: i64, k: u32, by_a: Reciprocal, inc_a: i64, inc_m: i64) -> (i64, i64, bool) {
    let x = f.wrapping_add(i64::from(k.wrapping_sub(1)).wrapping_mul(inc_m));
    let n = match u64::try_from(x.wrapping_sub(1)) {
        // ⌈x / inc_a⌉ = ⌊(x − 1) / inc_a⌋ + 1 for x > 0.
        Ok(x1) if x > 0 => i64::try_from(by_a.div(x1)).unwrap_or(0).wrapping_add(1),
        _ => 0,
    };
    let after = x.wrapping_add(inc_m).wrapping_sub(n.wrapping_mul(inc_a));
    let took = after <= inc_m.wrapping_mul(2).wrapping_sub(inc_a);
    (n, after, took)
}

/// Exact division by a constant through a multiplication: `⌊x / d⌋` for
/// `x < 2^64`, `d ≥ 2`, from `m = ⌊(2^64 − 1) / d⌋` (one 64-bit division,
/// at a run's first jump). `⌊x·m / 2^64⌋` is `⌊x / d⌋` or one less, since
/// `x/d − 1 < x·m/2^64 ≤ x/d`; one comparison corrects it.
#[derive(Clone, Copy)]
struct Reciprocal {
    d: u64,
    m: u64,
}

impl Reciprocal {
    fn new(d: i64) -> Self {
        let d = u64::try_from(d).unwrap_or(0).max(2);
        // ⌊(2^64 − 1) / d⌋ = ⌊2^64 / d⌋ unless d divides 2^64, when it is one
        // less: either way x·m/2^64 > x/d − 1, and a 64-bit division suffices.
        let m = u64::MAX.checked_div(d).unwrap_or(0);
        Self { d, m }
    }

    #[inline(always)]
    fn div(self, x: u64) -> u64 {
        let q = u64::try_from(u128::from(x).wrapping_mul(u128::from(self.m)) >> 64).unwrap_or(0);
        let r = x.wrapping_sub(q.wrapping_mul(self.d));
        if r >= self.d { q.wrapping_add(1) } else { q }
    }
}

#[cfg(test)]
mod tests {
    use super::{Reciprocal, jump_count};

    /// A jump's crossing count, term and last-step crossing are those of
    /// `k` single 26-steps, ties included (small increments make `f` hit
    /// the interval ends often).
    #[test]
    fn jump_count_is_k_single_steps() {
        let mut x = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = |m: u64| {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            x % m
        };
        for case in 0..200_000u32 {
            let big = case % 2 == 0;
            let inc_a = i64::try_from(if big { 2 + next(1 << 40) } else { 2 + next(12) }).unwrap();
            let inc_m = i64::try_from(next(u64::try_from(inc_a).unwrap() + 1)).unwrap();
            // Any reachable term: (−inc_a, inc_a].
            let f0 = i64::try_from(next(u64::try_from(2 * inc_a).unwrap())).unwrap() - inc_a + 1;
            let k = 2 + u32::try_from(next(61)).unwrap();
            let (mut f, mut n, mut took) = (f0, 0i64, false);
            for _ in 0..k {
                took = f > 0;
                if took {
                    n += 1;
                    f -= inc_a;
                }
                f += inc_m;
            }
            let by_a = Reciprocal::new(inc_a);
            assert_eq!(
                jump_count(f0, k, by_a, inc_a, inc_m),
                (n, f, took),
                "f0 {f0} k {k} inc_a {inc_a} inc_m {inc_m}"
            );
        }
    }

    #[test]
    fn reciprocal_division_is_exact() {
        let mut x = 0x0123_4567_89ab_cdefu64;
        let mut next = || {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            x
        };
        for _ in 0..200_000 {
            let d = (next() >> (1 + next() % 62)).max(2);
            let r = Reciprocal::new(i64::try_from(d >> 1).unwrap().max(2));
            let n = next() >> (next() % 64);
            assert_eq!(r.div(n), n / r.d, "{n} / {}", r.d);
            for edge in [
                0,
                1,
                r.d - 1,
                r.d,
                r.d + 1,
                u64::MAX,
                u64::MAX - 1,
                r.d.wrapping_mul(r.m),
            ] {
                assert_eq!(r.div(edge), edge / r.d, "{edge} / {}", r.d);
            }
        }
    }
}
