//! The lockstep stepper: one iteration steps every live lane once, gathers
//! eight plane cells and tests them.
//
// Implementation notes. This is `discrete_ray/step.rs` written once for
// eight lanes. Each lane keeps its own drive frame, so the per-lane
// constants (increments, offsets, thresholds) are vectors and lanes with
// different driving axes or signs cost nothing extra. Every step is written
// as "move frame axes A, B, C" with lane masks:
//
//     e1 += (A & inc_b) − (B & inc_a)      rem_a −= A     idx += (A & off_a)
//     e2 += (A & inc_c) − (C & inc_a)      rem_b −= B          + (B & off_b)
//     e3 += (B & inc_c) − (C & inc_b)      rem_c −= C          + (C & off_c)
//
// A 6-step sets exactly one of A, B, C (the scalar's three branches); a
// 26-step sets A and B = e1 > thr_b, C = e2 > thr_c (the scalar's `diag`
// sums the same offsets). Adaptive selects per lane between the two by
// `tie | PROXIMITY`. The formula above then reproduces the scalar updates
// term by term, with the same wrapping two's-complement arithmetic.
//
// Bit identity, and what each lane keeps:
// * One visit per iteration for every live lane (a fresh lane visits its
//   entry voxel in the first iteration without stepping, the others step
//   first), so the budget is one counter for the packet and a lane's step
//   count is its count at the start plus the visits of this walk.
// * Lanes are not masked out of the arithmetic. A lane that ends (exit
//   before a step, hit or out-of-plane cell after one, budget) has its state
//   written back to its `DiscreteRay` at that moment; afterwards its lanes
//   hold garbage that is never read again. Only in the first iteration, when
//   fresh lanes must not step while others do, are the new values blended.
// * `last` (the moved frame axes) is kept as the three move masks of each
//   lane's latest step; `tie` is tracked per step only in Adaptive mode,
//   where it decides the next step. In Six mode it is recomputed when a lane
//   is written back, from the step it took and the terms after it (the
//   updates are invertible); in TwentySix mode it is false after any step.
// * Indices are `usize` offsets in 64-bit lanes: the offsets are the
//   scalar's wrapping `usize` offsets sign-extended, so lane arithmetic
//   modulo 2^64 truncated to `usize` is the scalar's wrapping arithmetic
//   modulo 2^usize::BITS, on 32- and 64-bit targets alike. Crossing
//   counters are `u32` in 64-bit lanes the same way.

use super::lanes::{I64x8, LANES, Mask8};
use super::{PacketEnd, RayPacket8};
use crate::discrete_ray::State;
use crate::raster::cell;

/// Connectivity as a const parameter (as in the scalar stepper).
pub(super) const SIX: u8 = 0;
pub(super) const TWENTY_SIX: u8 = 1;
pub(super) const ADAPTIVE: u8 = 2;

/// Bit of each lane in a lane bitmask.
pub(super) const BIT: [u8; LANES] = [1, 2, 4, 8, 16, 32, 64, 128];

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

/// How a packet walk decides which lanes hit.
pub(super) trait LaneTest {
    /// Bitmask of the lanes in `live` whose current voxel (`index`, `cell`)
    /// is a hit.
    fn hits(&mut self, live: u8, index: &[i64; LANES], cells: &[u8; LANES]) -> u8;
}

/// A caller's test, called once per live lane and voxel, lanes in order.
pub(super) struct Closure<T>(pub(super) T);

impl<T: FnMut(usize, usize, u8) -> bool> LaneTest for Closure<T> {
    #[inline(always)]
    fn hits(&mut self, live: u8, index: &[i64; LANES], cells: &[u8; LANES]) -> u8 {
        let mut out = 0u8;
        for (lane, ((&bit, &i), &c)) in BIT.iter().zip(index).zip(cells).enumerate() {
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
    fn hits(&mut self, live: u8, _: &[i64; LANES], cells: &[u8; LANES]) -> u8 {
        live & lane_bits(cells, self.0)
    }
}

/// Bitmask of the lanes whose cell has any bit of `mask`.
#[inline(always)]
fn lane_bits(cells: &[u8; LANES], mask: u8) -> u8 {
    let mut out = 0u8;
    for (&bit, &c) in BIT.iter().zip(cells) {
        if c & mask != 0 {
            out |= bit;
        }
    }
    out
}

/// The vector stepping state of the live lanes.
#[derive(Clone, Copy)]
struct Lanes {
    /// `[e1, e2, e3]` per lane.
    e: [I64x8; 3],
    /// Crossings left per frame axis (`u32` values).
    rem: [I64x8; 3],
    /// Raster index (see [`index_of`]).
    idx: I64x8,
}

/// What a lane had when the walk started, for writing it back.
#[derive(Clone, Copy, Default)]
struct Incoming {
    steps: [u32; LANES],
    last: [u8; LANES],
}

/// The per-walk bookkeeping that turns lanes back into scalar states.
struct Book {
    inc: Incoming,
    /// Lanes still fresh (entry voxel not visited) at the walk's start.
    fresh: u8,
    /// Lanes that have taken at least one step in this walk.
    stepped: u8,
    /// Tie bits: incoming, and in Adaptive mode kept current.
    tie: u8,
    /// Move masks of each lane's latest step (valid in `stepped` lanes).
    last: [Mask8; 3],
    /// Voxels visited per live lane in this walk.
    visits: u32,
}

impl RayPacket8 {
    /// Writes lane `lane`'s state back into its scalar ray.
    #[inline(never)]
    fn write_back<const MODE: u8>(&mut self, lane: usize, v: &Lanes, b: &Book, done: bool) {
        let Some(ray) = self.rays.get_mut(lane).and_then(Option::as_mut) else {
            return;
        };
        let bit = BIT.get(lane).copied().unwrap_or(0);
        let e = v.e.map(|x| x.lane(lane));
        let stepped = b.stepped & bit != 0;
        let last = if stepped {
            let [a, bb, c] = b.last.map(|m| m.bits() & bit != 0);
            u8::from(a) | (u8::from(bb) << 1) | (u8::from(c) << 2)
        } else {
            b.inc.last.get(lane).copied().unwrap_or(0)
        };
        let tie_in = b.tie & bit != 0;
        let tie = match MODE {
            ADAPTIVE => tie_in,
            SIX if stepped => six_tie(last, e, ray.params().inc),
            TWENTY_SIX if stepped => false,
            _ => tie_in,
        };
        let s = State {
            index: index_of(v.idx.lane(lane)),
            err: e,
            rem: v.rem.map(|x| rem_of(x.lane(lane))),
            // Wrapping like the scalar's per-visit `wrapping_add(1)`.
            steps: b
                .inc
                .steps
                .get(lane)
                .copied()
                .unwrap_or(0)
                .wrapping_add(b.visits),
            last,
            tie,
            fresh: b.fresh & bit != 0 && b.visits == 0,
            done,
        };
        ray.set_state(s);
    }

    /// Writes back every lane of `lanes`.
    fn write_back_all<const MODE: u8>(&mut self, lanes: u8, v: &Lanes, b: &Book, done: bool) {
        for (lane, &bit) in BIT.iter().enumerate() {
            if lanes & bit != 0 {
                self.write_back::<MODE>(lane, v, b, done);
            }
        }
    }
}

/// The tie flag a 6-step along the frame axis in `last` leaves, from the
/// terms after it (`e`) and the ray's increments: the step's updates undone,
/// then the scalar's test.
fn six_tie(last: u8, e: [i64; 3], inc: [i64; 3]) -> bool {
    let [e1, e2, e3] = e;
    let [inc_a, inc_b, inc_c] = inc;
    match last {
        1 => e1.wrapping_sub(inc_b) == -1 || e2.wrapping_sub(inc_c) == -1,
        2 => e1.wrapping_add(inc_a) == 1 || e3.wrapping_sub(inc_c) == -1,
        4 => e2.wrapping_add(inc_a) == 1,
        _ => false,
    }
}

/// Walks the packet from its lanes' states; see [`RayPacket8::walk`].
#[inline(always)]
pub(super) fn run<const MODE: u8, T: LaneTest>(
    pk: &mut RayPacket8,
    plane: &[u8],
    budget: u32,
    test: &mut T,
) -> PacketEnd {
    let mut end = PacketEnd::default();
    let mut live = 0u8;
    let mut book = Book {
        inc: Incoming::default(),
        fresh: 0,
        stepped: 0,
        tie: 0,
        last: [Mask8::NONE; 3],
        visits: 0,
    };
    // PROXIMITY bits of the current voxels (Adaptive).
    let mut prox = 0u8;
    let mut e = [[0i64; LANES]; 3];
    let mut rem = [[0i64; LANES]; 3];
    let mut idx = [0i64; LANES];

    // ---- load: the scalar stepper's prologue, lane by lane ----
    for (lane, (slot, &bit)) in pk.rays.iter_mut().zip(BIT.iter()).enumerate() {
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
            let Some(&c) = plane.get(s.index) else {
                ray.set_state(State { done: true, ..s });
                end.exit |= bit;
                continue;
            };
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
        for f in 0..3 {
            if let (Some(el), Some(rl)) = (e.get_mut(f), rem.get_mut(f))
                && let (Some(ev), Some(rv)) = (el.get_mut(lane), rl.get_mut(lane))
            {
                *ev = s.err.get(f).copied().unwrap_or(0);
                *rv = i64::from(s.rem.get(f).copied().unwrap_or(0));
            }
        }
        if let Some(iv) = idx.get_mut(lane) {
            *iv = lane_of(s.index);
        }
        if let (Some(st), Some(la)) = (book.inc.steps.get_mut(lane), book.inc.last.get_mut(lane)) {
            *st = s.steps;
            *la = s.last;
        }
    }
    if live == 0 {
        return end;
    }

    let mut v = Lanes {
        e: e.map(I64x8::new),
        rem: rem.map(I64x8::new),
        idx: I64x8::new(idx),
    };
    let [inc_a, inc_b, inc_c] = pk.inc;
    let [off_a, off_b, off_c] = pk.off;
    let [thr_b, thr_c] = pk.thr;
    let mut left = budget;
    let mut stepping = live & !book.fresh;

    loop {
        // ---- advance: every stepping lane moves one step ----
        if stepping != 0 {
            let [e1, e2, e3] = v.e;
            let [ra, rb, rc] = v.rem;
            // The scalar's three 6-step branches as masks. The terms are odd
            // (±1 plus even increments), never zero, so e1 > 0 is !(e1 < 0).
            let six_moves = || {
                let n1 = e1.lt0();
                let a = n1.and(e2.lt0());
                let b = n1.and_not(e3.lt0());
                (a, b, a.or(b).not())
            };
            let (a, b, c, exit, tie) = match MODE {
                SIX => {
                    let (a, b, c) = six_moves();
                    let exit = a
                        .and(ra.eq_splat(0))
                        .or(b.and(rb.eq_splat(0)))
                        .or(c.and(rc.eq_splat(0)));
                    (a, b, c, exit, 0)
                }
                TWENTY_SIX => (Mask8::ALL, e1.gt(thr_b), e2.gt(thr_c), ra.eq_splat(0), 0),
                _ => {
                    let six = Mask8::from_bits(book.tie | prox);
                    let (a6, b6, c6) = six_moves();
                    let a = six.select_mask(a6, Mask8::ALL);
                    let b = six.select_mask(b6, e1.gt(thr_b));
                    let c = six.select_mask(c6, e2.gt(thr_c));
                    // A 26-step may take a minor crossing without checking
                    // its counter; compare the counters as `u32`s.
                    let low = I64x8::splat(0xffff_ffff);
                    let rb0 = low.and(rb).eq_splat(0);
                    let rc0 = low.and(rc).eq_splat(0);
                    let exit = a.and(ra.eq_splat(0)).or(six.and(b.and(rb0).or(c.and(rc0))));
                    // The 6-step tie flags, from the terms before the step.
                    let tie = a6
                        .and(e1.eq_splat(-1).or(e2.eq_splat(-1)))
                        .or(b6.and(e1.eq_splat(1).or(e3.eq_splat(-1))))
                        .or(c6.and(e2.eq_splat(1)))
                        .and(six);
                    (a, b, c, exit, tie.bits())
                }
            };
            let exits = exit.bits() & stepping;
            if exits != 0 {
                // Written back before the step, with their old tie flags.
                pk.write_back_all::<MODE>(exits, &v, &book, true);
                end.exit |= exits;
                live &= !exits;
                stepping &= !exits;
                if live == 0 {
                    break;
                }
            }
            if MODE == ADAPTIVE {
                book.tie = (book.tie & !stepping) | (tie & stepping);
            }
            let next = Lanes {
                e: [
                    e1.add(a.keep(inc_b)).sub(b.keep(inc_a)),
                    e2.add(a.keep(inc_c)).sub(c.keep(inc_a)),
                    e3.add(b.keep(inc_c)).sub(c.keep(inc_b)),
                ],
                rem: [
                    ra.add(a.as_minus_one()),
                    rb.add(b.as_minus_one()),
                    rc.add(c.as_minus_one()),
                ],
                idx: v
                    .idx
                    .add(a.keep(off_a))
                    .add(b.keep(off_b))
                    .add(c.keep(off_c)),
            };
            if live & !stepping == 0 {
                v = next;
                book.last = [a, b, c];
            } else {
                // First iteration with fresh lanes: only `stepping` moves.
                let m = Mask8::from_bits(stepping);
                v = Lanes {
                    e: [0, 1, 2].map(|f| m.select(pick(next.e, f), pick(v.e, f))),
                    rem: [0, 1, 2].map(|f| m.select(pick(next.rem, f), pick(v.rem, f))),
                    idx: m.select(next.idx, v.idx),
                };
                book.last = [
                    m.select_mask(a, book.last[0]),
                    m.select_mask(b, book.last[1]),
                    m.select_mask(c, book.last[2]),
                ];
            }
            book.stepped |= stepping;
        }

        // ---- visit: gather the eight cells ----
        let ia = v.idx.to_array();
        let mut cells = [0u8; LANES];
        let mut oob = 0u8;
        for ((slot, &i), &bit) in cells.iter_mut().zip(ia.iter()).zip(BIT.iter()) {
            match plane.get(index_of(i)) {
                Some(&c) => *slot = c,
                None => oob |= bit,
            }
        }
        let oob = oob & live;
        if oob != 0 {
            // Unreachable for lanes set up on this extent; the scalar ends
            // the ray there, after the step, without counting a visit.
            pk.write_back_all::<MODE>(oob, &v, &book, true);
            end.exit |= oob;
            live &= !oob;
            if live == 0 {
                break;
            }
        }
        left = left.wrapping_sub(1);
        book.visits = book.visits.wrapping_add(1);
        let hits = test.hits(live, &ia, &cells) & live;
        if hits != 0 {
            pk.write_back_all::<MODE>(hits, &v, &book, false);
            end.hit |= hits;
            live &= !hits;
            if live == 0 {
                break;
            }
        }
        if MODE == ADAPTIVE {
            prox = lane_bits(&cells, cell::PROXIMITY);
        }
        if left == 0 {
            pk.write_back_all::<MODE>(live, &v, &book, false);
            end.budget |= live;
            break;
        }
        stepping = live;
    }
    end
}

/// Frame axis `f` of a per-axis vector triple.
#[inline(always)]
fn pick(v: [I64x8; 3], f: usize) -> I64x8 {
    v.get(f).copied().unwrap_or(I64x8::ZERO)
}
