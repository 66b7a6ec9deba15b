//! Eight 64-bit integer lanes on `wide`, and their lane masks.
//!
//! This is the packet's one SIMD API. [`I64x8`] is two `wide::i64x4`
//! halves; `wide` picks AVX2, SSE, NEON or plain scalar code at compile time
//! (on the thumb targets it is scalar), behind the same methods. The scalar
//! twin of everything built on it is the scalar discrete ray itself, which
//! the packet must reproduce bit for bit.
//
// Implementation notes. All arithmetic is two's-complement lane arithmetic:
// SIMD adds wrap by definition, exactly like `i64::wrapping_add`, and the
// stepper relies on that (its scalar twin uses wrapping ops throughout), so
// the operator uses below are allowed `arithmetic_side_effects`.

use wide::i64x4;

/// Bit `l` of a lane bitmask stands for lane `l`.
pub(crate) const LANES: usize = 8;

/// Eight `i64` lanes.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(crate) struct I64x8 {
    lo: i64x4,
    hi: i64x4,
}

/// A lane mask: every lane all ones (true) or all zeros (false).
///
/// Invariant: each lane is `0` or `-1`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(crate) struct Mask8(I64x8);

/// Bit `l` in lane `l`: turns a bitmask into a lane mask with one compare.
const LOW_BITS: i64x4 = i64x4::new([1, 2, 4, 8]);
const HIGH_BITS: i64x4 = i64x4::new([16, 32, 64, 128]);

#[allow(clippy::arithmetic_side_effects)] // lane arithmetic wraps, see above
impl I64x8 {
    /// All lanes zero.
    pub(crate) const ZERO: Self = Self::splat(0);

    /// All lanes `v`.
    #[inline(always)]
    pub(crate) const fn splat(v: i64) -> Self {
        Self {
            lo: i64x4::splat(v),
            hi: i64x4::splat(v),
        }
    }

    /// Lanes from an array (lane `l` = `a[l]`).
    #[inline(always)]
    pub(crate) const fn new(a: [i64; LANES]) -> Self {
        let [a0, a1, a2, a3, a4, a5, a6, a7] = a;
        Self {
            lo: i64x4::new([a0, a1, a2, a3]),
            hi: i64x4::new([a4, a5, a6, a7]),
        }
    }

    /// The lanes as an array.
    #[inline(always)]
    pub(crate) const fn to_array(self) -> [i64; LANES] {
        let [a0, a1, a2, a3] = self.lo.to_array();
        let [a4, a5, a6, a7] = self.hi.to_array();
        [a0, a1, a2, a3, a4, a5, a6, a7]
    }

    /// Lane `l` (0 for `l >= LANES`).
    #[inline(always)]
    pub(crate) fn lane(self, l: usize) -> i64 {
        self.to_array().get(l).copied().unwrap_or(0)
    }

    /// Lanewise wrapping `self + o`.
    #[inline(always)]
    pub(crate) fn add(self, o: Self) -> Self {
        Self {
            lo: self.lo + o.lo,
            hi: self.hi + o.hi,
        }
    }

    /// Lanewise wrapping `self - o`.
    #[inline(always)]
    pub(crate) fn sub(self, o: Self) -> Self {
        Self {
            lo: self.lo - o.lo,
            hi: self.hi - o.hi,
        }
    }

    /// Lanewise bitwise `self | o`.
    #[inline(always)]
    pub(crate) fn or(self, o: Self) -> Self {
        Self {
            lo: self.lo | o.lo,
            hi: self.hi | o.hi,
        }
    }

    /// Lanewise `self < 0`.
    #[inline(always)]
    pub(crate) fn lt0(self) -> Mask8 {
        Mask8(Self {
            lo: i64x4::ZERO.simd_gt(self.lo),
            hi: i64x4::ZERO.simd_gt(self.hi),
        })
    }

    /// Lanewise `self > o`.
    #[inline(always)]
    pub(crate) fn gt(self, o: Self) -> Mask8 {
        Mask8(Self {
            lo: self.lo.simd_gt(o.lo),
            hi: self.hi.simd_gt(o.hi),
        })
    }

    /// Lanewise `self == o`.
    #[inline(always)]
    pub(crate) fn eq(self, o: Self) -> Mask8 {
        Mask8(Self {
            lo: self.lo.simd_eq(o.lo),
            hi: self.hi.simd_eq(o.hi),
        })
    }

    /// Lanewise `self == v`.
    #[inline(always)]
    pub(crate) fn eq_splat(self, v: i64) -> Mask8 {
        self.eq(Self::splat(v))
    }
}

#[allow(clippy::arithmetic_side_effects)] // bitwise lane operators, no arithmetic
impl Mask8 {
    /// No lane set.
    pub(crate) const NONE: Self = Self(I64x8::ZERO);
    /// Every lane set.
    pub(crate) const ALL: Self = Self(I64x8::splat(-1));

    /// The mask with lane `l` set iff bit `l` of `bits` is.
    #[inline(always)]
    pub(crate) fn from_bits(bits: u8) -> Self {
        let b = i64x4::splat(i64::from(bits));
        Self(I64x8 {
            lo: (b & LOW_BITS).simd_eq(LOW_BITS),
            hi: (b & HIGH_BITS).simd_eq(HIGH_BITS),
        })
    }

    /// The bitmask with bit `l` set iff lane `l` is.
    #[inline(always)]
    pub(crate) fn bits(self) -> u8 {
        let lo = self.0.lo.to_bitmask() & 0xf;
        let hi = self.0.hi.to_bitmask() & 0xf;
        // Two 4-bit masks: the result fits in a byte.
        u8::try_from(lo | (hi << 4)).unwrap_or(0)
    }

    /// Lanes set in both.
    #[inline(always)]
    pub(crate) fn and(self, o: Self) -> Self {
        Self(I64x8 {
            lo: self.0.lo & o.0.lo,
            hi: self.0.hi & o.0.hi,
        })
    }

    /// Lanes set in either.
    #[inline(always)]
    pub(crate) fn or(self, o: Self) -> Self {
        Self(I64x8 {
            lo: self.0.lo | o.0.lo,
            hi: self.0.hi | o.0.hi,
        })
    }

    /// Lanes set in `o` but not in `self`.
    #[inline(always)]
    pub(crate) fn and_not(self, o: Self) -> Self {
        Self(I64x8 {
            lo: !self.0.lo & o.0.lo,
            hi: !self.0.hi & o.0.hi,
        })
    }

    /// Lanes not set.
    #[inline(always)]
    pub(crate) fn not(self) -> Self {
        Self(I64x8 {
            lo: !self.0.lo,
            hi: !self.0.hi,
        })
    }

    /// `v` in set lanes, 0 elsewhere.
    #[inline(always)]
    pub(crate) fn keep(self, v: I64x8) -> I64x8 {
        I64x8 {
            lo: self.0.lo & v.lo,
            hi: self.0.hi & v.hi,
        }
    }

    /// `t` in set lanes, `f` elsewhere.
    #[inline(always)]
    pub(crate) fn select(self, t: I64x8, f: I64x8) -> I64x8 {
        I64x8 {
            lo: self.0.lo.select(t.lo, f.lo),
            hi: self.0.hi.select(t.hi, f.hi),
        }
    }

    /// `t` in set lanes, `f` elsewhere.
    #[inline(always)]
    pub(crate) fn select_mask(self, t: Self, f: Self) -> Self {
        Self(self.select(t.0, f.0))
    }

    /// `-1` in set lanes, `0` elsewhere, as a value (adding it decrements).
    #[inline(always)]
    pub(crate) const fn as_minus_one(self) -> I64x8 {
        self.0
    }
}
