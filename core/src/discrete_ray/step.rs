//! The one line stepper. Six, TwentySix and Adaptive differ only in the
//! decision taken from the same three terms; every step adds one
//! precomputed offset to the single raster index.
//
// Implementation notes. The decisions, the term updates and the tie rule
// are those of rules.rs (shared with the packet stepper); this file is how
// the scalar ray runs them.
//
// * A 6-step takes the earliest crossing ([`rules::six_moves`]) and ends the
//   ray if that axis has no crossing left before the exit point.
// * A 26-step takes the a-crossing and every minor crossing no later
//   ([`rules::twenty_six_moves`]) and ends the ray when a has no crossing
//   left. With no tie pending every pending crossing lies strictly after the
//   current t, which bounds a 26-step to one crossing per axis, so its voxel
//   is a voxel of the 6-ray.
// * Adaptive chooses per voxel ([`rules::takes_six`]); a 6-step across an
//   edge or corner leaves a tie pending ([`rules::six_tie`]) and forces the
//   next step to be a 6-step.
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
use super::rules::{self, MOVE_A, MOVE_B, MOVE_C, Moves, SIX, TWENTY_SIX};
use super::skip::{Reciprocal, jump, skip_count};
use super::{State, WalkEnd};
use crate::raster::cell;

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
            let r = if rules::takes_six(s.tie, cur & cell::PROXIMITY != 0) {
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
    let mut e = s.err;
    let [mut ra, mut rb, mut rc] = s.rem;
    let mut steps = s.steps;
    let mut last = s.last;
    let mut tie = s.tie;
    let [off_a, off_b, off_c] = p.off;
    let inc = p.inc;
    // Track the tie flag at every step when someone reads it during the run.
    let track = BUDGETED || ADAPTIVE;
    // The terms, the tie flag and `last` after the 6-step `moves` (a
    // constant in each branch below, so each branch keeps only its updates).
    let take = |e: &mut [i64; 3], tie: &mut bool, last: &mut u8, moves: Moves<bool>| {
        if track {
            *tie = rules::six_tie(moves, *e);
        }
        *e = rules::stepped(*e, moves, inc);
        *last = rules::last_of(moves);
    };

    let end = loop {
        if BUDGETED {
            if *left == 0 {
                break Run::End(WalkEnd::Budget);
            }
            *left = left.wrapping_sub(1);
        }
        // ---- advance: the earliest crossing ----
        let [a, b, _] = rules::six_moves(e);
        if a {
            if ra == 0 {
                break Run::End(WalkEnd::Exit);
            }
            ra = ra.wrapping_sub(1);
            idx = idx.wrapping_add(off_a);
            take(&mut e, &mut tie, &mut last, MOVE_A);
        } else if b {
            if rb == 0 {
                break Run::End(WalkEnd::Exit);
            }
            rb = rb.wrapping_sub(1);
            idx = idx.wrapping_add(off_b);
            take(&mut e, &mut tie, &mut last, MOVE_B);
        } else {
            if rc == 0 {
                break Run::End(WalkEnd::Exit);
            }
            rc = rc.wrapping_sub(1);
            idx = idx.wrapping_add(off_c);
            take(&mut e, &mut tie, &mut last, MOVE_C);
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
        if ADAPTIVE && !rules::takes_six(tie, c & cell::PROXIMITY != 0) {
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
            tie = rules::six_tie_after(last, e, inc);
        }
    }
    s.index = idx;
    s.err = e;
    s.rem = [ra, rb, rc];
    s.steps = steps;
    s.last = last;
    s.tie = tie;
    end
}

/// What a 26-run carries from step to step. With `BUDGETED` it tracks every
/// variable of [`State`]; otherwise `e3`, the minor counters, `steps` and
/// `last` keep their start values and [`Run26::finish`] rebuilds them.
struct Run26 {
    idx: usize,
    /// The threshold-shifted terms `f = e − thr` of the minor axes b and c:
    /// `f > 0` ⇔ that axis crosses no later than the driving axis.
    f1: i64,
    f2: i64,
    e3: i64,
    /// Driving-axis crossings left before the exit.
    todo: u32,
    rb: u32,
    rc: u32,
    steps: u32,
    last: u8,
    /// Minor axes of the last step (bit 0 = b, bit 1 = c).
    minors: usize,
    /// With skipping: the current voxel's cell, and the voxels visited (a
    /// jump visits one voxel for k steps).
    cur: u8,
    visits: u32,
    /// Division by inc_a for the jumps (inc_a > 0 whenever a jump is
    /// taken). Made at the first jump: most runs never jump.
    by_a: Option<Reciprocal>,
}

impl Run26 {
    #[inline(always)]
    fn new<const SKIP: bool, C: Fn(usize) -> Option<u8>>(p: &Params, s: &State, cells: C) -> Self {
        let [e1, e2, e3] = s.err;
        let [thr_b, thr_c] = p.thr;
        let [ra, rb, rc] = s.rem;
        Self {
            idx: s.index,
            f1: e1.wrapping_sub(thr_b),
            f2: e2.wrapping_sub(thr_c),
            e3,
            todo: ra,
            rb,
            rc,
            steps: s.steps,
            last: s.last,
            minors: 0,
            cur: if SKIP { cells(s.index).unwrap_or(0) } else { 0 },
            visits: 0,
            by_a: None,
        }
    }

    /// One 26-step.
    #[inline(always)]
    fn step<const BUDGETED: bool>(&mut self, p: &Params) {
        self.todo = self.todo.wrapping_sub(1);
        // On the shifted terms the thresholds are 0.
        let moves = rules::twenty_six_moves(self.f1, self.f2, [0, 0]);
        let [_, sb, sc] = moves;
        let [f1, f2, e3] = rules::stepped([self.f1, self.f2, self.e3], moves, p.inc);
        self.f1 = f1;
        self.f2 = f2;
        self.minors = usize::from(sb) | (usize::from(sc) << 1);
        // `& 3` keeps the table lookup free of a bounds check.
        self.idx = self.idx.wrapping_add(p.diag[self.minors & 3]);
        if BUDGETED {
            self.e3 = e3;
            self.rb = self.rb.wrapping_sub(u32::from(sb));
            self.rc = self.rc.wrapping_sub(u32::from(sc));
            self.steps = self.steps.wrapping_add(1);
            self.last = rules::last_of(moves);
        }
    }

    /// `k ≥ 2` 26-steps at once (see [`skip_count`]), landing on the voxel
    /// and the terms that `k` single steps reach.
    #[inline(always)]
    fn jump<const BUDGETED: bool>(&mut self, p: &Params, k: u32) {
        let [inc_a, _, _] = p.inc;
        let by_a = *self.by_a.get_or_insert_with(|| Reciprocal::new(inc_a));
        let j = jump([self.f1, self.f2], k, by_a, p.inc);
        self.f1 = j.f1;
        self.f2 = j.f2;
        self.idx = self.idx.wrapping_add(j.offset(k, p.off));
        self.todo = self.todo.wrapping_sub(k);
        self.minors = usize::from(j.lb) | (usize::from(j.lc) << 1);
        if BUDGETED {
            self.e3 = rules::e3_after(self.e3, j.nb, j.nc, p.inc);
            self.rb = self.rb.wrapping_sub(u32::try_from(j.nb).unwrap_or(0));
            self.rc = self.rc.wrapping_sub(u32::try_from(j.nc).unwrap_or(0));
            self.steps = self.steps.wrapping_add(1);
            self.last = rules::last_of([true, j.lb, j.lc]);
        }
    }

    /// Writes the run's end state into `s`, rebuilding what an unbudgeted
    /// run did not carry.
    #[inline(always)]
    fn finish<const BUDGETED: bool, const SKIP: bool>(
        self,
        p: &Params,
        start: &State,
        s: &mut State,
    ) {
        let [thr_b, thr_c] = p.thr;
        let e1 = self.f1.wrapping_add(thr_b);
        let e2 = self.f2.wrapping_add(thr_c);
        let ra = self.todo;
        let (mut e3, mut rb, mut rc) = (self.e3, self.rb, self.rc);
        let (mut steps, mut last) = (self.steps, self.last);
        let k = start.rem[0].wrapping_sub(ra);
        if !BUDGETED && k > 0 {
            let [inc_a, inc_b, inc_c] = p.inc;
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
            e3 = rules::e3_after(start.err[2], i64::from(nb), i64::from(nc), p.inc);
            steps = start.steps.wrapping_add(if SKIP { self.visits } else { k });
            last = rules::last_of([true, self.minors & 1 != 0, self.minors & 2 != 0]);
        }
        s.index = self.idx;
        s.err = [e1, e2, e3];
        s.rem = [ra, rb, rc];
        s.steps = steps;
        s.last = last;
        if k > 0 {
            // 26-steps take ties with the driving step: none is left pending.
            s.tie = false;
        }
    }
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
    let mut w = Run26::new::<SKIP, C>(p, s, cells);
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
        if w.todo == 0 {
            break;
        }
        // Far from every non-transparent voxel, take k 26-steps at once.
        let k = if SKIP { skip_count(w.cur, w.todo) } else { 1 };
        if SKIP && k > 1 {
            w.jump::<BUDGETED>(p, k);
        } else {
            w.step::<BUDGETED>(p);
        }
        if SKIP {
            // Every advance, one step or a jump, visits one voxel.
            w.visits = w.visits.wrapping_add(1);
        }
        // ---- visit ----
        let Some(c) = cells(w.idx) else {
            break;
        };
        if test(w.idx, c) {
            end = Run::End(WalkEnd::Hit);
            break;
        }
        if ADAPTIVE && rules::takes_six(false, c & cell::PROXIMITY != 0) {
            end = Run::Switch;
            break;
        }
        if SKIP {
            w.cur = c;
        }
    }
    w.finish::<BUDGETED, SKIP>(p, &start, s);
    end
}
