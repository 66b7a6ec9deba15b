//! The stepper's rules, written once: the connectivity modes, the 6-step
//! and 26-step decisions, the term updates, the tie rule, Adaptive's choice
//! and the rebuild of what a run does not carry.
//!
//! Both steppers apply exactly these functions: the scalar discrete ray
//! ([`super::step`]) with `i64` terms and `bool` flags, the packet
//! ([`crate::packet`]) with eight-lane terms and lane masks. That is what
//! makes a packet lane bit-identical to its scalar ray.
//
// The terms, in the drive frame (a = driving axis, b < c the minor axes;
// see params.rs, none is ever zero, ties are folded in as ±1):
//
//     e1 = before(a, b) > 0  ⇔  b crosses before a
//     e2 = before(a, c) > 0  ⇔  c crosses before a
//     e3 = before(b, c) > 0  ⇔  c crosses before b
//
// With inc = 2·S·|D| per frame axis, crossing an axis changes them by
//     a: e1 += inc_b, e2 += inc_c
//     b: e1 −= inc_a, e3 += inc_c
//     c: e2 −= inc_a, e3 −= inc_b
// and a step that crosses several axes at once (a 26-step) adds the sum.
// The terms stay within ±(2·S·max|D| + 1) < 2^49, so the wrapping adds of
// `Term` never wrap; they are wrapping only so that no panic path exists.

/// Connectivity as a const parameter of the steppers: Six.
pub(crate) const SIX: u8 = 0;
/// TwentySix.
pub(crate) const TWENTY_SIX: u8 = 1;
/// Adaptive.
pub(crate) const ADAPTIVE: u8 = 2;

/// One flag per ray: `bool` for a scalar ray, a lane mask for a packet.
pub(crate) trait Flag: Copy {
    /// Set (in every lane).
    const SET: Self;
    /// Set in both.
    fn and(self, o: Self) -> Self;
    /// Set in either.
    fn or(self, o: Self) -> Self;
    /// Set in `o` but not in `self`.
    fn and_not(self, o: Self) -> Self;
    /// Not set.
    fn not(self) -> Self;
}

/// One decision term (or increment) per ray: `i64` for a scalar ray, eight
/// lanes for a packet. Arithmetic wraps (two's complement).
pub(crate) trait Term: Copy {
    /// The flag type of comparisons.
    type Flag: Flag;
    /// Wrapping `self + o`.
    fn add(self, o: Self) -> Self;
    /// Wrapping `self − o`.
    fn sub(self, o: Self) -> Self;
    /// `self < 0`.
    fn lt0(self) -> Self::Flag;
    /// `self > o`.
    fn gt(self, o: Self) -> Self::Flag;
    /// `self == v`.
    fn is(self, v: i64) -> Self::Flag;
    /// `self` where `f` is set, 0 elsewhere.
    fn keep(self, f: Self::Flag) -> Self;
}

impl Flag for bool {
    const SET: Self = true;
    #[inline(always)]
    fn and(self, o: Self) -> Self {
        self & o
    }
    #[inline(always)]
    fn or(self, o: Self) -> Self {
        self | o
    }
    #[inline(always)]
    fn and_not(self, o: Self) -> Self {
        !self & o
    }
    #[inline(always)]
    fn not(self) -> Self {
        !self
    }
}

impl Term for i64 {
    type Flag = bool;
    #[inline(always)]
    fn add(self, o: Self) -> Self {
        self.wrapping_add(o)
    }
    #[inline(always)]
    fn sub(self, o: Self) -> Self {
        self.wrapping_sub(o)
    }
    #[inline(always)]
    fn lt0(self) -> bool {
        self < 0
    }
    #[inline(always)]
    fn gt(self, o: Self) -> bool {
        self > o
    }
    #[inline(always)]
    fn is(self, v: i64) -> bool {
        self == v
    }
    #[inline(always)]
    fn keep(self, f: bool) -> Self {
        // A branch-free mask: all ones when set.
        self & i64::from(f).wrapping_neg()
    }
}

/// The frame axes `[a, b, c]` a step moves along.
pub(crate) type Moves<F> = [F; 3];

/// A 6-step along the driving axis a, as scalar flags.
pub(crate) const MOVE_A: Moves<bool> = [true, false, false];
/// A 6-step along minor axis b.
pub(crate) const MOVE_B: Moves<bool> = [false, true, false];
/// A 6-step along minor axis c.
pub(crate) const MOVE_C: Moves<bool> = [false, false, true];

/// The 6-step decision: the earliest crossing, exactly one axis. a if
/// `e1 < 0 && e2 < 0`, else b if `e1 > 0 && e3 < 0`, else c. (A term is
/// never zero, so `e1 > 0` is `!(e1 < 0)`.)
#[inline(always)]
pub(crate) fn six_moves<T: Term>(e: [T; 3]) -> Moves<T::Flag> {
    let [e1, e2, e3] = e;
    let a_first = e1.lt0();
    let a = a_first.and(e2.lt0());
    let b = a_first.and_not(e3.lt0());
    [a, b, a.or(b).not()]
}

/// The 26-step decision: the driving axis a, with every minor axis whose
/// crossing comes no later than a's (exact ties go with the driving step):
/// b iff `e1 > thr_b`, c iff `e2 > thr_c`, with the thresholds of
/// `Params::thr`. Shifting a term and its threshold alike keeps the
/// decision: the scalar 26-run passes `f = e − thr` against thresholds 0.
///
/// Since `|D_b|, |D_c| ≤ |D_a|`, at most one crossing per minor axis comes
/// first when no tie is pending, so the step is 26-adjacent and lands on
/// the voxel holding the ray just after it enters the next a-slice.
#[inline(always)]
pub(crate) fn twenty_six_moves<T: Term>(e1: T, e2: T, thr: [T; 2]) -> Moves<T::Flag> {
    let [thr_b, thr_c] = thr;
    [T::Flag::SET, e1.gt(thr_b), e2.gt(thr_c)]
}

/// How a step that moves `moves` changes the terms `[e1, e2, e3]`, given
/// the increments `inc = [inc_a, inc_b, inc_c]` (the table in the notes):
/// what it adds to each term, and what it takes.
#[inline(always)]
pub(crate) fn term_steps<T: Term>(moves: Moves<T::Flag>, inc: [T; 3]) -> ([T; 3], [T; 3]) {
    let [a, b, c] = moves;
    let [inc_a, inc_b, inc_c] = inc;
    (
        [inc_b.keep(a), inc_c.keep(a), inc_c.keep(b)],
        [inc_a.keep(b), inc_a.keep(c), inc_b.keep(c)],
    )
}

/// The terms after a step that moves `moves`.
#[inline(always)]
pub(crate) fn stepped<T: Term>(e: [T; 3], moves: Moves<T::Flag>, inc: [T; 3]) -> [T; 3] {
    let [e1, e2, e3] = e;
    let ([p1, p2, p3], [m1, m2, m3]) = term_steps(moves, inc);
    [e1.add(p1).sub(m1), e2.add(p2).sub(m2), e3.add(p3).sub(m3)]
}

/// The terms before a step that moved `moves`, from those after it.
#[inline(always)]
pub(crate) fn unstepped<T: Term>(e: [T; 3], moves: Moves<T::Flag>, inc: [T; 3]) -> [T; 3] {
    let [e1, e2, e3] = e;
    let ([p1, p2, p3], [m1, m2, m3]) = term_steps(moves, inc);
    [e1.sub(p1).add(m1), e2.sub(p2).add(m2), e3.sub(p3).add(m3)]
}

/// The tie rule. A 6-step crosses an edge or a corner exactly when another
/// axis crosses at the same ray parameter (its term with the stepping axis
/// is ±1, the tie bias); the step then lands on an intermediate voxel and
/// leaves that crossing pending at the current parameter, and the next step
/// must be a 6-step: from there a 26-step could owe two crossings on one
/// minor axis. From the terms *before* the 6-step `moves`:
///
/// * a step along a ties with b if `e1 = −1`, with c if `e2 = −1`;
/// * along b, with a if `e1 = 1`, with c if `e3 = −1`;
/// * along c, with a if `e2 = 1` (c never wins a tie against b, as b < c).
///
/// 26-steps take ties with the driving step and never leave one pending.
#[inline(always)]
pub(crate) fn six_tie<T: Term>(moves: Moves<T::Flag>, e: [T; 3]) -> T::Flag {
    let [a, b, c] = moves;
    let [e1, e2, e3] = e;
    let along_a = e1.is(-1).or(e2.is(-1));
    let along_b = e1.is(1).or(e3.is(-1));
    let along_c = e2.is(1);
    a.and(along_a).or(b.and(along_b)).or(c.and(along_c))
}

/// The tie flag the 6-step into the current voxel left, from its moves
/// (`last`, see [`last_of`]), the terms after it and the increments: the
/// step undone, then [`six_tie`]. False when `last` moved no axis.
#[inline(always)]
pub(crate) fn six_tie_after(last: u8, e: [i64; 3], inc: [i64; 3]) -> bool {
    let moves = moves_of(last);
    six_tie(moves, unstepped(e, moves, inc))
}

/// Adaptive's choice: a 6-step from a voxel whose PROXIMITY flag is set
/// (`near`) or while a tie is pending, a 26-step otherwise. Because both
/// steps keep the terms exact, switching costs nothing and every Adaptive
/// voxel is a voxel of the Six ray.
#[inline(always)]
pub(crate) fn takes_six<F: core::ops::BitOr<Output = F>>(tie: F, near: F) -> F {
    tie | near
}

/// `e3` after a run that took `nb` crossings of b and `nc` of c, from `e3`
/// before it: each b crossing adds `inc_c`, each c crossing takes `inc_b`,
/// driving crossings leave it alone ([`term_steps`]). Runs that do not
/// step `e3` rebuild it with this when they end.
#[inline(always)]
pub(crate) const fn e3_after(e3: i64, nb: i64, nc: i64, inc: [i64; 3]) -> i64 {
    let [_, inc_b, inc_c] = inc;
    e3.wrapping_add(nb.wrapping_mul(inc_c))
        .wrapping_sub(nc.wrapping_mul(inc_b))
}

/// `State::last` of a step that moved `moves`: bit 0 = a, 1 = b, 2 = c.
#[inline(always)]
pub(crate) const fn last_of(moves: Moves<bool>) -> u8 {
    let [a, b, c] = moves;
    (a as u8) | ((b as u8) << 1) | ((c as u8) << 2)
}

/// The moves recorded in `State::last`.
#[inline(always)]
pub(crate) const fn moves_of(last: u8) -> Moves<bool> {
    [last & 1 != 0, last & 2 != 0, last & 4 != 0]
}
