//! The lockstep stepper: one iteration steps every live lane once, gathers
//! eight plane cells and tests them.
//
// Implementation notes. This is the scalar stepper (`discrete_ray/step.rs`)
// run for eight lanes, with the same rules (`discrete_ray/rules.rs`) on
// lane terms and lane masks. Each lane keeps its own drive frame, so the
// per-lane constants (increments, offsets, thresholds) are vectors and lanes
// with different driving axes or signs cost nothing extra. Every step is
// "move frame axes A, B, C" with lane masks: the terms change by
// `rules::term_steps`, and
//
//     rem_a −= A     rem_b −= B     rem_c −= C
//     idx += (A & off_a) + (B & off_b) + (C & off_c)
//
// A 6-step sets exactly one of A, B, C (`rules::six_moves`, the scalar's
// three branches); a 26-step sets A and the minors of
// `rules::twenty_six_moves` (the scalar's `diag` sums the same offsets).
// Adaptive selects per lane between the two by `rules::takes_six`.
//
// Bit identity, and what each lane keeps:
// * One visit per iteration for every live lane (a fresh lane visits its
//   entry voxel in the first iteration without stepping, the others step
//   first), so the budget is one counter for the packet and a lane's step
//   count is its count at the start plus the visits of this walk.
// * Exits. The scalar ends a ray instead of stepping along an axis with no
//   crossing left. Here the counters are decremented first and a lane exits
//   iff one of them went negative; the state before the step is still at
//   hand and is what is written back. This equals the scalar's test because
//   a 26-step never takes a minor crossing whose counter is zero: it takes
//   one only when it comes no later than the next driving crossing, which
//   lies before the exit (the counter of the driving axis is checked), and
//   with no tie pending every pending crossing lies after the current
//   parameter, so that crossing is still counted.
// * Lanes are not masked out of the arithmetic. A lane that ends (exit,
//   hit, out-of-plane cell, budget) has its state written back to its
//   `DiscreteRay` at that moment, and is then parked: its offsets and
//   increments become 0 and its index 0, so it keeps reading one cell and
//   never leaves the plane. Only in the first iteration, when fresh lanes
//   must not step while others do, are the new values blended.
// * `last` (the moved frame axes) is the three move masks of each lane's
//   latest step; `tie` is tracked per step only in Adaptive mode, where it
//   decides the next step. In Six mode it is recomputed when a lane is
//   written back (`rules::six_tie_after`); in TwentySix mode it is false
//   after any step. In TwentySix mode `e3` is not stepped either: it is
//   rebuilt at write-back from the minor crossings taken, the counters'
//   decrease (`rules::e3_after`).
// * Indices are `usize` values in 64-bit lanes: the offsets are the
//   scalar's wrapping `usize` offsets sign-extended, so lane arithmetic
//   modulo 2^64 truncated to `usize` is the scalar's wrapping arithmetic
//   modulo 2^usize::BITS, on 32- and 64-bit targets alike. Crossing
//   counters are `u32` in 64-bit lanes the same way.
// * Skipping. A skipping walk reads every cell through `skip::skip_cell`
//   (a line's stand-in where the line level allows, else the plane), as the
//   scalar skipping walk does, and keeps each lane's current cell. Where a
//   lane takes a 26-step (every lane in TwentySix, the lanes not taking a
//   6-step in Adaptive) and `skip::skip_count` allows k ≥ 2 steps, its
//   single step is replaced by the scalar jump (`skip::jump` on the lane's
//   own constants: its divisions and products are 64-bit, which the lanes
//   lack, so they run per lane). A jump is one visit, as in the scalar
//   walk, so step counts stay visit counts; and it never passes the exit
//   (k is at most the driving crossings left, and a 26-run never takes a
//   minor crossing past its counter), so the vector step's exit test holds.

use super::lanes::{BIT, I64x8, LANES, Mask8};
use super::{PacketEnd, RayPacket8};
use crate::discrete_ray::State;
use crate::discrete_ray::rules::{self, ADAPTIVE, Flag, SIX, TWENTY_SIX};
use crate::discrete_ray::skip::{self, Reciprocal};
use crate::raster::cell;

/// TwentySix steps inside an Adaptive walk (`e3` is stepped too): a mode
/// value of this stepper only, distinct from the three of `rules`.
const TWENTY_SIX_KEEP_E3: u8 = 3;
const _: () = assert!(TWENTY_SIX_KEEP_E3 != SIX && TWENTY_SIX_KEEP_E3 != TWENTY_SIX);
const _: () = assert!(TWENTY_SIX_KEEP_E3 != ADAPTIVE);

/// A `usize` offset or index as a 64-bit lane value.
#[allow(clippy::cast_possible_wrap)] // two's-complement reinterpretation, see the notes
#[inline(always)]
pub(super) const fn lane_of(v: usize) -> i64 {
    v as isize as i64
}

/// A 64-bit lane value back as the `usize` the scalar stepper computes.
#[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)] // modular, see the notes
#[inline(always)]
pub(super) const fn index_of(v: i64) -> usize {
    v as usize
}

/// A crossing counter lane back as the scalar's `u32` (modulo 2^32).
#[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)] // modular, see the notes
#[inline(always)]
const fn rem_of(v: i64) -> u32 {
    v as u32
}

/// `0xff` in byte `l` for each lane `l` of `lanes`.
#[inline(always)]
fn lane_bytes(lanes: u8) -> u64 {
    let mut bytes = [0u8; LANES];
    for (b, &bit) in bytes.iter_mut().zip(BIT.iter()) {
        if lanes & bit != 0 {
            *b = 0xff;
        }
    }
    u64::from_le_bytes(bytes)
}

/// The lanes whose byte in `bytes` is non-zero.
#[inline(always)]
fn nonzero_bytes(bytes: u64) -> u8 {
    let mut out = 0u8;
    for (&b, &bit) in bytes.to_le_bytes().iter().zip(BIT.iter()) {
        if b != 0 {
            out |= bit;
        }
    }
    out
}

/// Bit 1 (PROXIMITY) of each byte of `cells`, as a lane bitmask.
#[inline(always)]
fn proximity_bits(cells: u64) -> u8 {
    const _: () = assert!(cell::PROXIMITY == 2);
    // One bit per byte, gathered into the top byte by one multiplication
    // (each bit lands on its own position: no carries).
    let ones = (cells >> 1) & 0x0101_0101_0101_0101;
    (ones.wrapping_mul(0x0102_0408_1020_4080) >> 56).to_le_bytes()[0]
}

/// The cell a walk reads for voxel `index`: with `SKIP` the skipping
/// walk's ([`skip::skip_cell`]: a line's stand-in or the plane's), else the
/// plane's; `None` outside the plane.
#[inline(always)]
fn cell_at<const SKIP: bool>(plane: &[u8], lines: &[u8], index: usize) -> Option<u8> {
    if SKIP {
        skip::skip_cell(plane, lines, index)
    } else {
        plane.get(index).copied()
    }
}

/// `a[lane]` (0 outside the array).
#[inline(always)]
fn at(a: &[i64; LANES], lane: usize) -> i64 {
    a.get(lane).copied().unwrap_or(0)
}

/// `a[lane] = v` (no-op outside the array).
#[inline(always)]
fn put(a: &mut [i64; LANES], lane: usize, v: i64) {
    if let Some(slot) = a.get_mut(lane) {
        *slot = v;
    }
}

/// Replaces, in the lanes of `lanes`, the single 26-step `s` (taken from
/// state `v`) by a jump of `ks[lane] ≥ 2` 26-steps: the scalar stepper's
/// jump ([`skip::jump`]) on each lane's own constants, so the lane lands on
/// the voxel, terms, counters and moves of the scalar jump. `e3` is kept
/// exact except in TwentySix walks, which rebuild it at write-back.
#[inline(never)]
fn jump_lanes<const MODE: u8>(
    pk: &RayPacket8,
    by_a: &mut [Option<Reciprocal>; LANES],
    v: &Lanes,
    s: &mut Step,
    lanes: u8,
    ks: &[u32; LANES],
) {
    let [e1, e2, e3] = v.e.map(I64x8::to_array);
    let [ra, rb, rc] = v.rem.map(I64x8::to_array);
    let idx = v.idx.to_array();
    let [mut n1, mut n2, mut n3] = s.next.e.map(I64x8::to_array);
    let [mut na, mut nb, mut nc] = s.next.rem.map(I64x8::to_array);
    let mut nidx = s.next.idx.to_array();
    let (mut lb, mut lc) = (0u8, 0u8);
    for (lane, ((&bit, ray), r)) in (0..LANES).zip(BIT.iter().zip(&pk.rays).zip(by_a.iter_mut())) {
        let (true, Some(ray), Some(&k)) = (lanes & bit != 0, ray, ks.get(lane)) else {
            continue;
        };
        let p = ray.params();
        let [inc_a, _, _] = p.inc;
        let [thr_b, thr_c] = p.thr;
        let by = *r.get_or_insert_with(|| Reciprocal::new(inc_a));
        let f = [
            at(&e1, lane).wrapping_sub(thr_b),
            at(&e2, lane).wrapping_sub(thr_c),
        ];
        let j = skip::jump(f, k, by, p.inc);
        put(&mut n1, lane, j.f1.wrapping_add(thr_b));
        put(&mut n2, lane, j.f2.wrapping_add(thr_c));
        if MODE != TWENTY_SIX {
            put(
                &mut n3,
                lane,
                rules::e3_after(at(&e3, lane), j.nb, j.nc, p.inc),
            );
        }
        put(&mut na, lane, at(&ra, lane).wrapping_sub(i64::from(k)));
        put(&mut nb, lane, at(&rb, lane).wrapping_sub(j.nb));
        put(&mut nc, lane, at(&rc, lane).wrapping_sub(j.nc));
        let i = index_of(at(&idx, lane)).wrapping_add(j.offset(k, p.off));
        put(&mut nidx, lane, lane_of(i));
        if j.lb {
            lb |= bit;
        }
        if j.lc {
            lc |= bit;
        }
    }
    s.next = Lanes {
        e: [n1, n2, n3].map(I64x8::new),
        rem: [na, nb, nc].map(I64x8::new),
        idx: I64x8::new(nidx),
    };
    let [a, b, c] = s.moves;
    s.moves = [
        a.or(Mask8::from_bits(lanes)),
        Mask8::from_bits((b.bits() & !lanes) | lb),
        Mask8::from_bits((c.bits() & !lanes) | lc),
    ];
}

/// How a packet walk decides which lanes hit.
pub(super) trait LaneTest {
    /// Bitmask of the lanes in `live` whose current voxel is a hit;
    /// `cells` holds lane `l`'s cell, `any` is the OR of all eight cells,
    /// `live_bytes` is [`lane_bytes`] of `live`.
    fn hits(
        &mut self,
        live: u8,
        live_bytes: u64,
        index: &[i64; LANES],
        cells: &[u8; LANES],
        any: u8,
    ) -> u8;
}

/// A caller's test, called once per live lane and voxel, lanes in order.
pub(super) struct Closure<T>(pub(super) T);

impl<T: FnMut(usize, usize, u8) -> bool> LaneTest for Closure<T> {
    #[inline(always)]
    fn hits(&mut self, live: u8, _: u64, index: &[i64; LANES], cells: &[u8; LANES], _: u8) -> u8 {
        let mut out = 0u8;
        for (lane, ((&bit, &i), &c)) in (0..LANES).zip(BIT.iter().zip(index).zip(cells.iter())) {
            if live & bit != 0 && (self.0)(lane, index_of(i), c) {
                out |= bit;
            }
        }
        out
    }
}

/// A voxel is a hit when its cell has any of these bits.
pub(super) struct CellBits(pub(super) u8);

impl LaneTest for CellBits {
    #[inline(always)]
    fn hits(
        &mut self,
        _: u8,
        live_bytes: u64,
        _: &[i64; LANES],
        cells: &[u8; LANES],
        any: u8,
    ) -> u8 {
        if any & self.0 == 0 {
            return 0;
        }
        let m = u64::from_le_bytes(*cells) & u64::from_le_bytes([self.0; LANES]) & live_bytes;
        if m == 0 { 0 } else { nonzero_bytes(m) }
    }
}

/// The vector stepping state of the lanes.
#[derive(Clone, Copy)]
struct Lanes {
    /// `[e1, e2, e3]` per lane (`e3` is not stepped in TwentySix mode).
    e: [I64x8; 3],
    /// Crossings left per frame axis (`u32` values).
    rem: [I64x8; 3],
    /// Raster index (see [`index_of`]).
    idx: I64x8,
}

/// The per-lane constants of a walk; ended lanes are parked (all zero).
#[derive(Clone, Copy)]
struct Consts {
    inc: [I64x8; 3],
    off: [I64x8; 3],
    thr: [I64x8; 2],
}

/// What the lanes had when the walk started, and what the walk did, for
/// turning lanes back into scalar states.
struct Book {
    steps: [u32; LANES],
    last: [u8; LANES],
    /// `e3` and the minor counters at the start (TwentySix rebuilds `e3`).
    e3: [i64; LANES],
    rb: [i64; LANES],
    rc: [i64; LANES],
    tie: u8,
    /// Lanes still fresh (entry voxel not visited) at the walk's start.
    fresh: u8,
}

/// The moves of one step of every lane, and what they lead to.
struct Step {
    next: Lanes,
    moves: [Mask8; 3],
    /// Tie bits after the step (Adaptive only).
    tie: u8,
    /// Lanes for which the step would pass the exit: they end instead.
    exits: u8,
}

/// One step of every lane (committed by the caller).
#[inline(always)]
fn step<const MODE: u8>(v: &Lanes, k: &Consts, tie: u8, prox: u8) -> Step {
    let [e1, e2, e3] = v.e;
    let [ra, rb, rc] = v.rem;
    let [off_a, off_b, off_c] = k.off;
    let (moves, tie) = match MODE {
        SIX => (rules::six_moves(v.e), 0),
        TWENTY_SIX | TWENTY_SIX_KEEP_E3 => (rules::twenty_six_moves(e1, e2, k.thr), 0),
        _ => {
            let six = Mask8::from_bits(rules::takes_six(tie, prox));
            let [a6, b6, c6] = rules::six_moves(v.e);
            let [a26, b26, c26] = rules::twenty_six_moves(e1, e2, k.thr);
            // The 6-step lanes' tie flags, from the terms before the step.
            let t = rules::six_tie([a6, b6, c6], v.e).and(six);
            (
                [
                    six.select_mask(a6, a26),
                    six.select_mask(b6, b26),
                    six.select_mask(c6, c26),
                ],
                t.bits(),
            )
        }
    };
    let [a, b, c] = moves;
    let rem = [
        ra.add(a.as_minus_one()),
        rb.add(b.as_minus_one()),
        rc.add(c.as_minus_one()),
    ];
    let exits = match MODE {
        TWENTY_SIX | TWENTY_SIX_KEEP_E3 => rem[0].lt0().bits(),
        _ => rem[0].or(rem[1]).or(rem[2]).lt0().bits(),
    };
    let [s1, s2, s3] = rules::stepped(v.e, moves, k.inc);
    let next = Lanes {
        // TwentySix does not step e3: write-back rebuilds it.
        e: [
            s1,
            s2,
            match MODE {
                TWENTY_SIX => e3,
                _ => s3,
            },
        ],
        rem,
        idx: v
            .idx
            .add(a.keep(off_a))
            .add(b.keep(off_b))
            .add(c.keep(off_c)),
    };
    Step {
        next,
        moves,
        tie,
        exits,
    }
}

/// The whole walk state. Its address never escapes the inlined loop (the
/// cold write-back gets copies), so the compiler keeps it in registers.
struct Walker<'p, 'b> {
    plane: &'p [u8],
    /// The line level a skipping walk reads (empty: none, or no skipping).
    lines: &'p [u8],
    /// With skipping: each lane's current cell, and the division by its
    /// `inc_a` for jumps (made at the lane's first jump).
    cur: [u8; LANES],
    by_a: [Option<Reciprocal>; LANES],
    v: Lanes,
    k: Consts,
    book: &'b Book,
    /// Lanes that have taken at least one step in this walk.
    stepped: u8,
    /// Voxels visited per live lane in this walk.
    visits: u32,
    /// Move masks of each lane's latest step (valid in `book.stepped`).
    last: [Mask8; 3],
    /// Current tie bits (Adaptive; incoming elsewhere).
    tie: u8,
    /// PROXIMITY bits of the current voxels (Adaptive).
    prox: u8,
    live: u8,
    live_bytes: u64,
    left: u32,
    end: PacketEnd,
}

/// Writes lanes `lanes` back into their scalar rays, from state `v` whose
/// latest step moved `last` and left `tie`.
#[cold]
#[inline(never)]
#[allow(clippy::too_many_arguments)] // the walk state, passed by value on purpose
fn write_back<const MODE: u8>(
    pk: &mut RayPacket8,
    b: &Book,
    lanes: u8,
    v: Lanes,
    last: [Mask8; 3],
    tie: u8,
    stepped: u8,
    visits: u32,
    done: bool,
) {
    let e = v.e.map(I64x8::to_array);
    let rem = v.rem.map(I64x8::to_array);
    let idx = v.idx.to_array();
    let moved = last.map(Mask8::bits);
    for (lane, (slot, &bit)) in (0..LANES).zip(pk.rays.iter_mut().zip(BIT.iter())) {
        if lanes & bit == 0 {
            continue;
        }
        let Some(ray) = slot.as_mut() else { continue };
        let get = |a: &[i64; LANES]| a.get(lane).copied().unwrap_or(0);
        let stepped = stepped & bit != 0;
        let last = if stepped {
            rules::last_of(moved.map(|m| m & bit != 0))
        } else {
            b.last.get(lane).copied().unwrap_or(0)
        };
        let rem = rem.map(|r| get(&r));
        let mut err = e.map(|x| get(&x));
        let inc = ray.params().inc;
        if MODE == TWENTY_SIX
            && let Some(e3) = err.get_mut(2)
        {
            // The minor crossings taken: the counters' decrease.
            let nb = get(&b.rb).wrapping_sub(rem[1]);
            let nc = get(&b.rc).wrapping_sub(rem[2]);
            *e3 = rules::e3_after(get(&b.e3), nb, nc, inc);
        }
        let tie = match MODE {
            ADAPTIVE => tie & bit != 0,
            _ if !stepped => b.tie & bit != 0,
            SIX => rules::six_tie_after(last, err, inc),
            // 26-steps leave no tie pending.
            _ => false,
        };
        ray.set_state(State {
            index: index_of(get(&idx)),
            err,
            rem: rem.map(rem_of),
            // Wrapping like the scalar's per-visit `wrapping_add(1)`.
            steps: b.steps.get(lane).copied().unwrap_or(0).wrapping_add(visits),
            last,
            tie,
            fresh: b.fresh & bit != 0 && visits == 0,
            done,
        });
    }
}

impl Walker<'_, '_> {
    /// Ends lanes `lanes`: writes them back (from state `v` whose latest
    /// step moved `last` and left `tie`) and parks them.
    #[inline(always)]
    fn end_lanes<const MODE: u8>(
        &mut self,
        pk: &mut RayPacket8,
        lanes: u8,
        v: Lanes,
        last: [Mask8; 3],
        tie: u8,
        done: bool,
    ) {
        write_back::<MODE>(
            pk,
            self.book,
            lanes,
            v,
            last,
            tie,
            self.stepped,
            self.visits,
            done,
        );
        let keep = Mask8::from_bits(!lanes);
        self.k.inc = self.k.inc.map(|x| keep.keep(x));
        self.k.off = self.k.off.map(|x| keep.keep(x));
        self.v.idx = keep.keep(self.v.idx);
        self.live &= !lanes;
        self.live_bytes = lane_bytes(self.live);
    }

    /// Visits the current voxels of the live lanes: gathers their cells,
    /// ends lanes outside the plane, counts the visit and tests. Returns
    /// false when no lane is live any more.
    #[inline(always)]
    fn visit<const MODE: u8, const SKIP: bool, T: LaneTest>(
        &mut self,
        pk: &mut RayPacket8,
        test: &mut T,
    ) -> bool {
        let ia = self.v.idx.to_array();
        let mut cells = [0u8; LANES];
        let mut oob = 0u8;
        let mut any = 0u8;
        for ((slot, &i), &bit) in cells.iter_mut().zip(ia.iter()).zip(BIT.iter()) {
            match cell_at::<SKIP>(self.plane, self.lines, index_of(i)) {
                Some(c) => {
                    *slot = c;
                    any |= c;
                }
                None => oob |= bit,
            }
        }
        let oob = oob & self.live;
        if oob != 0 {
            // Unreachable for lanes set up on this extent; the scalar ends
            // the ray there, after the step, without counting a visit.
            let (v, last) = (self.v, self.last);
            self.end_lanes::<MODE>(pk, oob, v, last, self.tie, true);
            self.end.exit |= oob;
        }
        if self.live == 0 {
            return false;
        }
        self.left = self.left.wrapping_sub(1);
        self.visits = self.visits.wrapping_add(1);
        let hits = test.hits(self.live, self.live_bytes, &ia, &cells, any) & self.live;
        if hits != 0 {
            let (v, last) = (self.v, self.last);
            self.end_lanes::<MODE>(pk, hits, v, last, self.tie, false);
            self.end.hit |= hits;
            if self.live == 0 {
                return false;
            }
        }
        if SKIP {
            self.cur = cells;
        }
        if MODE == ADAPTIVE {
            self.prox = if any & cell::PROXIMITY == 0 {
                0
            } else {
                proximity_bits(u64::from_le_bytes(cells))
            };
        }
        if self.left == 0 {
            let (v, last, live) = (self.v, self.last, self.live);
            self.end_lanes::<MODE>(pk, live, v, last, self.tie, false);
            self.end.budget |= live;
            return false;
        }
        true
    }

    /// Steps the lanes of `stepping` (all live lanes unless `BLEND`); lanes
    /// that would pass their exit end instead. Returns false when no lane is
    /// live any more.
    #[inline(always)]
    fn advance<const MODE: u8, const SKIP: bool, const BLEND: bool>(
        &mut self,
        pk: &mut RayPacket8,
        stepping: u8,
    ) -> bool {
        let mut s = match MODE {
            // Where no lane is near a surface (or owes a tie), every lane of
            // an Adaptive walk takes a 26-step: the cheaper TwentySix step,
            // with e3 kept.
            ADAPTIVE if rules::takes_six(self.tie, self.prox) & stepping == 0 => {
                step::<{ TWENTY_SIX_KEEP_E3 }>(&self.v, &self.k, 0, 0)
            }
            _ => step::<MODE>(&self.v, &self.k, self.tie, self.prox),
        };
        if SKIP && MODE != SIX {
            // The lanes taking a 26-step, far enough from every
            // non-transparent voxel, jump as their scalar rays do.
            let runs = match MODE {
                ADAPTIVE => stepping & !rules::takes_six(self.tie, self.prox),
                _ => stepping,
            } & self.live;
            let [ra, _, _] = self.v.rem;
            let ra = ra.to_array();
            let mut ks = [0u32; LANES];
            let mut jumping = 0u8;
            for (((k, &c), &r), &bit) in ks.iter_mut().zip(&self.cur).zip(&ra).zip(&BIT) {
                *k = skip::skip_count(c, rem_of(r));
                if *k > 1 && runs & bit != 0 {
                    jumping |= bit;
                }
            }
            if jumping != 0 {
                jump_lanes::<MODE>(pk, &mut self.by_a, &self.v, &mut s, jumping, &ks);
            }
        }
        let exits = s.exits & stepping;
        if exits != 0 {
            // Written back before the step, with the old moves and ties.
            let (v, last) = (self.v, self.last);
            self.end_lanes::<MODE>(pk, exits, v, last, self.tie, true);
            self.end.exit |= exits;
            if self.live == 0 {
                return false;
            }
        }
        let stepping = stepping & self.live;
        if BLEND {
            let m = Mask8::from_bits(stepping);
            let old = self.v;
            let pick = |n: [I64x8; 3], o: [I64x8; 3]| {
                let [n0, n1, n2] = n;
                let [o0, o1, o2] = o;
                [m.select(n0, o0), m.select(n1, o1), m.select(n2, o2)]
            };
            self.v = Lanes {
                e: pick(s.next.e, old.e),
                rem: pick(s.next.rem, old.rem),
                idx: m.select(s.next.idx, old.idx),
            };
            let [a, b, c] = s.moves;
            let [la, lb, lc] = self.last;
            self.last = [
                m.select_mask(a, la),
                m.select_mask(b, lb),
                m.select_mask(c, lc),
            ];
        } else {
            self.v = s.next;
            self.last = s.moves;
        }
        if exits != 0 {
            // The exited lanes' new index came from before they were parked.
            self.v.idx = Mask8::from_bits(self.live).keep(self.v.idx);
        }
        if MODE == ADAPTIVE {
            self.tie = (self.tie & !stepping) | (s.tie & stepping);
        }
        self.stepped |= stepping;
        true
    }
}

/// Walks the packet from its lanes' states; see [`RayPacket8::walk`].
#[inline(always)]
pub(super) fn run<const MODE: u8, const SKIP: bool, T: LaneTest>(
    pk: &mut RayPacket8,
    plane: &[u8],
    lines: &[u8],
    budget: u32,
    test: &mut T,
) -> PacketEnd {
    let mut end = PacketEnd::default();
    let mut live = 0u8;
    let mut book = Book {
        steps: [0; LANES],
        last: [0; LANES],
        e3: [0; LANES],
        rb: [0; LANES],
        rc: [0; LANES],
        tie: 0,
        fresh: 0,
    };
    let mut prox = 0u8;
    let mut cur = [0u8; LANES];
    let mut e = [[0i64; LANES]; 3];
    let mut rem = [[0i64; LANES]; 3];
    let mut idx = [0i64; LANES];

    // ---- load: the scalar stepper's prologue, lane by lane ----
    for (lane, (slot, &bit)) in (0..LANES).zip(pk.rays.iter_mut().zip(BIT.iter())) {
        let Some(ray) = slot else { continue };
        let s = *ray.state();
        if s.done {
            end.exit |= bit;
            continue;
        }
        if s.fresh {
            if budget == 0 {
                end.budget |= bit;
                continue;
            }
            book.fresh |= bit;
        } else {
            let Some(c) = cell_at::<SKIP>(plane, lines, s.index) else {
                ray.set_state(State { done: true, ..s });
                end.exit |= bit;
                continue;
            };
            if let Some(slot) = cur.get_mut(lane) {
                *slot = c;
            }
            if budget == 0 {
                end.budget |= bit;
                continue;
            }
            if c & cell::PROXIMITY != 0 {
                prox |= bit;
            }
        }
        if s.tie {
            book.tie |= bit;
        }
        live |= bit;
        let put = |a: &mut [i64; LANES], v: i64| {
            if let Some(slot) = a.get_mut(lane) {
                *slot = v;
            }
        };
        let [e1, e2, e3] = s.err;
        let [ra, rb, rc] = s.rem.map(i64::from);
        let [ea, eb, ec] = &mut e;
        let [qa, qb, qc] = &mut rem;
        put(ea, e1);
        put(eb, e2);
        put(ec, e3);
        put(qa, ra);
        put(qb, rb);
        put(qc, rc);
        put(&mut book.e3, e3);
        put(&mut book.rb, rb);
        put(&mut book.rc, rc);
        put(&mut idx, lane_of(s.index));
        if let (Some(st), Some(la)) = (book.steps.get_mut(lane), book.last.get_mut(lane)) {
            *st = s.steps;
            *la = s.last;
        }
    }
    if live == 0 {
        return end;
    }

    // Empty and already ended lanes are parked from the start.
    let keep = Mask8::from_bits(live);
    let tie = book.tie;
    let mut w = Walker {
        plane,
        lines,
        cur,
        by_a: [None; LANES],
        v: Lanes {
            e: e.map(I64x8::new),
            rem: rem.map(I64x8::new),
            idx: keep.keep(I64x8::new(idx)),
        },
        k: Consts {
            inc: pk.inc.map(|x| keep.keep(x)),
            off: pk.off.map(|x| keep.keep(x)),
            thr: pk.thr,
        },
        book: &book,
        stepped: 0,
        visits: 0,
        last: [Mask8::NONE; 3],
        tie,
        prox,
        live,
        live_bytes: lane_bytes(live),
        left: budget,
        end,
    };

    // The first iteration: fresh lanes visit their entry voxel, the others
    // step first.
    let stepping = live & !w.book.fresh;
    let going = if stepping == 0 {
        true
    } else if stepping == live {
        w.advance::<MODE, SKIP, false>(pk, stepping)
    } else {
        w.advance::<MODE, SKIP, true>(pk, stepping)
    };
    if going && w.visit::<MODE, SKIP, T>(pk, test) {
        // Every live lane steps in every further iteration.
        while w.advance::<MODE, SKIP, false>(pk, w.live) && w.visit::<MODE, SKIP, T>(pk, test) {}
    }
    w.end
}
