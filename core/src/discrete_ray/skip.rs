//! Empty-space skipping: how far a 26-run may jump from a voxel, and the
//! exact crossing counts of a jump.
//
// A jump's length is read from the cell just loaded, so the next load waits
// for this one, while single steps compute their addresses without looking
// at the cells and overlap their loads: a jump pays only when it replaces
// several steps. That is what `MIN_JUMP` and `LINE_JUMP` trade; neither
// changes what a walk finds.

/// The shortest jump a skipping 26-run takes: it jumps from a voxel at
/// proximity distance `d > MIN_JUMP`, over `d − 1 ≥ MIN_JUMP` steps. Any
/// value of at least 1 gives the same hits, faces and resume states (see
/// [`skip_count`]); it changes only the speed and the `steps` count of a
/// skipping walk.
pub(crate) const MIN_JUMP: u8 = 3;

/// The smallest line stand-in ([`crate::raster::Raster::with_lines`]) a
/// skipping walk reads instead of the plane: one at distance 8 or more.
/// Nearer lines send the walk to the plane, whose cell may allow a longer
/// jump than the line's smallest distance (or any jump at all). As with
/// [`MIN_JUMP`], the value changes only the speed and the `steps` count.
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
pub(crate) fn skip_count(cur: u8, todo: u32) -> u32 {
    let d = crate::proximity::distance(cur);
    if d > MIN_JUMP {
        u32::from(d.wrapping_sub(1)).min(todo)
    } else {
        1
    }
}

/// An [`cell::EMPTY`](crate::raster::cell::EMPTY) plane cell as a walk
/// with a line level reads it: at
/// [`NEAR_LIMIT`](crate::proximity::NEAR_LIMIT), where the distance field
/// leaves cells empty.
const NEAR_CELL: u8 = crate::proximity::NEAR_LIMIT << crate::raster::cell::DISTANCE_SHIFT;

/// The cell a skipping walk reads for voxel `index`: the stand-in of its
/// line ([`crate::raster::Raster::with_lines`], empty `lines`: none) when
/// that is at least [`LINE_JUMP`], else the plane's cell, an empty one at
/// [`NEAR_LIMIT`](crate::proximity::NEAR_LIMIT) when there is a line
/// level (whose contract is a plane with its distance field); `None`
/// outside the plane.
///
/// The line level is read first, so that a walk far from surfaces reads
/// no plane cell there: a host may leave the plane's far pages unbacked
/// (the distance field never writes them), and reading one would map it.
#[inline(always)]
pub(crate) fn skip_cell(plane: &[u8], lines: &[u8], index: usize) -> Option<u8> {
    match lines.get(index >> crate::raster::LINE_BITS) {
        Some(&l) if l >= LINE_JUMP => Some(l),
        Some(_) => plane.get(index).map(|&c| {
            if c == crate::raster::cell::EMPTY {
                NEAR_CELL
            } else {
                c
            }
        }),
        None => plane.get(index).copied(),
    }
}

/// What `k ≥ 2` 26-steps taken at once do ([`jump`]).
#[derive(Clone, Copy)]
pub(crate) struct Jump {
    /// Crossings of minor axes b and c among the `k` steps.
    pub(crate) nb: i64,
    pub(crate) nc: i64,
    /// The threshold-shifted terms of b and c after them.
    pub(crate) f1: i64,
    pub(crate) f2: i64,
    /// Whether the last step crossed b, c.
    pub(crate) lb: bool,
    pub(crate) lc: bool,
}

impl Jump {
    /// The index offset of the jump: `k` steps along the driving axis and
    /// the minor crossings, from the per-axis offsets `off` (wrapping, as
    /// single steps add them).
    #[inline(always)]
    pub(crate) fn offset(&self, k: u32, off: [usize; 3]) -> usize {
        let [off_a, off_b, off_c] = off;
        let times = |off: usize, n: i64| off.wrapping_mul(usize::try_from(n).unwrap_or(0));
        times(off_a, i64::from(k))
            .wrapping_add(times(off_b, self.nb))
            .wrapping_add(times(off_c, self.nc))
    }
}

/// `k ≥ 2` 26-steps at once from the threshold-shifted terms `f = [f1, f2]`
/// of minor axes b and c, with the increments `inc = [inc_a, inc_b, inc_c]`
/// and `by_a` dividing by `inc_a` ([`jump_count`] per minor axis). The one
/// jump of the scalar stepper and of each packet lane.
#[inline(always)]
pub(crate) fn jump(f: [i64; 2], k: u32, by_a: Reciprocal, inc: [i64; 3]) -> Jump {
    let [inc_a, inc_b, inc_c] = inc;
    let [f1, f2] = f;
    let (nb, f1, lb) = jump_count(f1, k, by_a, inc_a, inc_b);
    let (nc, f2, lc) = jump_count(f2, k, by_a, inc_a, inc_c);
    Jump {
        nb,
        nc,
        f1,
        f2,
        lb,
        lc,
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
/// not positive. The values are below 2^58 (k < 2^8: a jump is at most
/// [`DISTANCE_LIMIT`](crate::proximity::DISTANCE_LIMIT) − 1 steps).
///
/// The last step (from a term `f'` already in that interval, as `k ≥ 2`)
/// took a crossing iff `f' > 0`, which leaves the new term in
/// `(inc_m − inc_a, 2·inc_m − inc_a]`; otherwise it lands in
/// `(2·inc_m − inc_a, inc_m]`. One comparison tells them apart.
#[inline(always)]
pub(crate) fn jump_count(
    f: i64,
    k: u32,
    by_a: Reciprocal,
    inc_a: i64,
    inc_m: i64,
) -> (i64, i64, bool) {
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
pub(crate) struct Reciprocal {
    d: u64,
    m: u64,
}

impl Reciprocal {
    pub(crate) fn new(d: i64) -> Self {
        let d = u64::try_from(d).unwrap_or(0).max(2);
        // ⌊(2^64 − 1) / d⌋ = ⌊2^64 / d⌋ unless d divides 2^64, when it is one
        // less: either way x·m/2^64 > x/d − 1, and a 64-bit division suffices.
        let m = u64::MAX.checked_div(d).unwrap_or(0);
        Self { d, m }
    }

    #[inline(always)]
    pub(crate) fn div(self, x: u64) -> u64 {
        let q = u64::try_from(u128::from(x).wrapping_mul(u128::from(self.m)) >> 64).unwrap_or(0);
        let r = x.wrapping_sub(q.wrapping_mul(self.d));
        if r >= self.d { q.wrapping_add(1) } else { q }
    }
}

#[cfg(test)]
mod tests {
    use super::{Reciprocal, jump_count};
    use crate::testkit::Rng;

    /// A jump's crossing count, term and last-step crossing are those of
    /// `k` single 26-steps, ties included (small increments make `f` hit
    /// the interval ends often).
    #[test]
    fn jump_count_is_k_single_steps() {
        let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
        let mut next = |m: u64| rng.below(m);
        for case in 0..200_000u32 {
            let big = case % 2 == 0;
            let inc_a = i64::try_from(if big { 2 + next(1 << 48) } else { 2 + next(12) }).unwrap();
            let inc_m = i64::try_from(next(u64::try_from(inc_a).unwrap() + 1)).unwrap();
            // Any reachable term: (−inc_a, inc_a].
            let f0 = i64::try_from(next(u64::try_from(2 * inc_a).unwrap())).unwrap() - inc_a + 1;
            let k = 2 + u32::try_from(next(154)).unwrap();
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
        let mut rng = Rng(0x0123_4567_89ab_cdef);
        let mut next = || rng.next_u64();
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
