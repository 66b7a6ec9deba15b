//! Eight 64-bit integer lanes, and their lane masks.
//!
//! This is the packet's one SIMD API, with one backend switch (glam's
//! pattern): where `wide` has SIMD (SSE2/AVX2 on x86, NEON on aarch64,
//! simd128 on wasm) [`I64x8`] is two `wide::i64x4` halves; elsewhere (the
//! thumb targets, where `wide` itself would fall back to scalar code, or
//! with the `scalar-lanes` feature) it is a plain `[i64; 8]` with the same
//! methods, which keeps the core's
//! link-time no-panic proof (`core/panic-never`) free of `wide`'s debug
//! precondition checks. The scalar twin of everything built on it is the
//! scalar discrete ray itself, which the packet must reproduce bit for bit.
//
// Implementation notes. All arithmetic is two's-complement lane arithmetic:
// SIMD adds wrap by definition, exactly like `i64::wrapping_add`, and the
// stepper relies on that (its scalar twin uses wrapping ops throughout), so
// the operator uses below are allowed `arithmetic_side_effects`.

use crate::discrete_ray::rules::{Flag, Term};

/// Bit `l` of a lane bitmask stands for lane `l`.
pub(crate) const LANES: usize = 8;

/// Bit of each lane in a lane bitmask.
pub(crate) const BIT: [u8; LANES] = [1, 2, 4, 8, 16, 32, 64, 128];

/// A lane mask: every lane all ones (true) or all zeros (false).
///
/// Invariant: each lane is `0` or `-1`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(crate) struct Mask8(I64x8);

pub(crate) use backend::I64x8;

#[cfg(all(
    any(
        target_feature = "sse2",
        target_feature = "neon",
        target_feature = "simd128"
    ),
    not(feature = "scalar-lanes")
))]
mod backend {
    use super::{LANES, Mask8};
    use wide::i64x4;

    /// Eight `i64` lanes: two `wide::i64x4`.
    #[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
    pub(crate) struct I64x8 {
        lo: i64x4,
        hi: i64x4,
    }

    /// Bit `l` in lane `l`: turns a bitmask into a lane mask with one compare.
    const LOW_BITS: i64x4 = i64x4::new([1, 2, 4, 8]);
    const HIGH_BITS: i64x4 = i64x4::new([16, 32, 64, 128]);

    #[allow(clippy::arithmetic_side_effects)] // lane arithmetic wraps, see above
    impl I64x8 {
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

        /// Lanewise bitwise `self & o`.
        #[inline(always)]
        pub(crate) fn and(self, o: Self) -> Self {
            Self {
                lo: self.lo & o.lo,
                hi: self.hi & o.hi,
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

        /// Lanewise bitwise `!self & o`.
        #[inline(always)]
        pub(crate) fn and_not(self, o: Self) -> Self {
            Self {
                lo: !self.lo & o.lo,
                hi: !self.hi & o.hi,
            }
        }

        /// Lanewise bitwise `!self`.
        #[inline(always)]
        pub(crate) fn not(self) -> Self {
            Self {
                lo: !self.lo,
                hi: !self.hi,
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

        /// `t` where `self` (a mask) is set, `f` elsewhere.
        #[inline(always)]
        pub(crate) fn select(self, t: Self, f: Self) -> Self {
            Self {
                lo: self.lo.select(t.lo, f.lo),
                hi: self.hi.select(t.hi, f.hi),
            }
        }

        /// The bitmask of a mask's set lanes.
        #[inline(always)]
        pub(crate) fn mask_bits(self) -> u8 {
            let lo = self.lo.to_bitmask() & 0xf;
            let hi = self.hi.to_bitmask() & 0xf;
            // Two 4-bit masks: the result fits in a byte.
            u8::try_from(lo | (hi << 4)).unwrap_or(0)
        }

        /// The mask with lane `l` set iff bit `l` of `bits` is.
        #[inline(always)]
        pub(crate) fn mask_from_bits(bits: u8) -> Self {
            let b = i64x4::splat(i64::from(bits));
            Self {
                lo: (b & LOW_BITS).simd_eq(LOW_BITS),
                hi: (b & HIGH_BITS).simd_eq(HIGH_BITS),
            }
        }
    }
}

#[cfg(not(all(
    any(
        target_feature = "sse2",
        target_feature = "neon",
        target_feature = "simd128"
    ),
    not(feature = "scalar-lanes")
)))]
mod backend {
    use super::{BIT, LANES, Mask8};

    /// Eight `i64` lanes: a plain array (no SIMD on this target).
    #[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
    pub(crate) struct I64x8([i64; LANES]);

    /// Lanewise `f(a, b)`.
    #[inline(always)]
    fn zip(a: I64x8, b: I64x8, f: impl Fn(i64, i64) -> i64) -> I64x8 {
        let [a0, a1, a2, a3, a4, a5, a6, a7] = a.0;
        let [b0, b1, b2, b3, b4, b5, b6, b7] = b.0;
        I64x8([
            f(a0, b0),
            f(a1, b1),
            f(a2, b2),
            f(a3, b3),
            f(a4, b4),
            f(a5, b5),
            f(a6, b6),
            f(a7, b7),
        ])
    }

    /// A lane of a mask.
    const fn m(t: bool) -> i64 {
        if t { -1 } else { 0 }
    }

    impl I64x8 {
        /// All lanes `v`.
        #[inline(always)]
        pub(crate) const fn splat(v: i64) -> Self {
            Self([v; LANES])
        }

        /// Lanes from an array (lane `l` = `a[l]`).
        #[inline(always)]
        pub(crate) const fn new(a: [i64; LANES]) -> Self {
            Self(a)
        }

        /// The lanes as an array.
        #[inline(always)]
        pub(crate) const fn to_array(self) -> [i64; LANES] {
            self.0
        }

        /// Lanewise wrapping `self + o`.
        #[inline(always)]
        pub(crate) fn add(self, o: Self) -> Self {
            zip(self, o, i64::wrapping_add)
        }

        /// Lanewise wrapping `self - o`.
        #[inline(always)]
        pub(crate) fn sub(self, o: Self) -> Self {
            zip(self, o, i64::wrapping_sub)
        }

        /// Lanewise bitwise `self & o`.
        #[inline(always)]
        pub(crate) fn and(self, o: Self) -> Self {
            zip(self, o, |a, b| a & b)
        }

        /// Lanewise bitwise `self | o`.
        #[inline(always)]
        pub(crate) fn or(self, o: Self) -> Self {
            zip(self, o, |a, b| a | b)
        }

        /// Lanewise bitwise `!self & o`.
        #[inline(always)]
        pub(crate) fn and_not(self, o: Self) -> Self {
            zip(self, o, |a, b| !a & b)
        }

        /// Lanewise bitwise `!self`.
        #[inline(always)]
        pub(crate) fn not(self) -> Self {
            Self(self.0.map(|a| !a))
        }

        /// Lanewise `self < 0`.
        #[inline(always)]
        pub(crate) fn lt0(self) -> Mask8 {
            Mask8(Self(self.0.map(|a| m(a < 0))))
        }

        /// Lanewise `self > o`.
        #[inline(always)]
        pub(crate) fn gt(self, o: Self) -> Mask8 {
            Mask8(zip(self, o, |a, b| m(a > b)))
        }

        /// Lanewise `self == o`.
        #[inline(always)]
        pub(crate) fn eq(self, o: Self) -> Mask8 {
            Mask8(zip(self, o, |a, b| m(a == b)))
        }

        /// `t` where `self` (a mask) is set, `f` elsewhere.
        #[inline(always)]
        pub(crate) fn select(self, t: Self, f: Self) -> Self {
            self.and(t).or(self.and_not(f))
        }

        /// The bitmask of a mask's set lanes.
        #[inline(always)]
        pub(crate) fn mask_bits(self) -> u8 {
            let mut out = 0u8;
            for (&a, &bit) in self.0.iter().zip(BIT.iter()) {
                if a < 0 {
                    out |= bit;
                }
            }
            out
        }

        /// The mask with lane `l` set iff bit `l` of `bits` is.
        #[inline(always)]
        pub(crate) fn mask_from_bits(bits: u8) -> Self {
            Self(BIT.map(|bit| m(bits & bit != 0)))
        }
    }
}

impl I64x8 {
    /// All lanes zero.
    pub(crate) const ZERO: Self = Self::splat(0);

    /// Lanewise `self == v`.
    #[inline(always)]
    pub(crate) fn eq_splat(self, v: i64) -> Mask8 {
        self.eq(Self::splat(v))
    }
}

impl Mask8 {
    /// No lane set.
    pub(crate) const NONE: Self = Self(I64x8::ZERO);
    /// Every lane set.
    pub(crate) const ALL: Self = Self(I64x8::splat(-1));

    /// The mask with lane `l` set iff bit `l` of `bits` is.
    #[inline(always)]
    pub(crate) fn from_bits(bits: u8) -> Self {
        Self(I64x8::mask_from_bits(bits))
    }

    /// The bitmask with bit `l` set iff lane `l` is.
    #[inline(always)]
    pub(crate) fn bits(self) -> u8 {
        self.0.mask_bits()
    }

    /// `v` in set lanes, 0 elsewhere.
    #[inline(always)]
    pub(crate) fn keep(self, v: I64x8) -> I64x8 {
        self.0.and(v)
    }

    /// `t` in set lanes, `f` elsewhere.
    #[inline(always)]
    pub(crate) fn select(self, t: I64x8, f: I64x8) -> I64x8 {
        self.0.select(t, f)
    }

    /// `t` in set lanes, `f` elsewhere.
    #[inline(always)]
    pub(crate) fn select_mask(self, t: Self, f: Self) -> Self {
        Self(self.0.select(t.0, f.0))
    }

    /// `-1` in set lanes, `0` elsewhere, as a value (adding it decrements).
    #[inline(always)]
    pub(crate) const fn as_minus_one(self) -> I64x8 {
        self.0
    }
}

/// Lane masks as the stepper rules' flags.
impl Flag for Mask8 {
    const SET: Self = Self::ALL;
    #[inline(always)]
    fn and(self, o: Self) -> Self {
        Self(self.0.and(o.0))
    }
    #[inline(always)]
    fn or(self, o: Self) -> Self {
        Self(self.0.or(o.0))
    }
    #[inline(always)]
    fn and_not(self, o: Self) -> Self {
        Self(self.0.and_not(o.0))
    }
    #[inline(always)]
    fn not(self) -> Self {
        Self(self.0.not())
    }
}

/// Lanes as the stepper rules' terms: the rules run on eight rays at once.
impl Term for I64x8 {
    type Flag = Mask8;
    #[inline(always)]
    fn add(self, o: Self) -> Self {
        Self::add(self, o)
    }
    #[inline(always)]
    fn sub(self, o: Self) -> Self {
        Self::sub(self, o)
    }
    #[inline(always)]
    fn lt0(self) -> Mask8 {
        Self::lt0(self)
    }
    #[inline(always)]
    fn gt(self, o: Self) -> Mask8 {
        Self::gt(self, o)
    }
    #[inline(always)]
    fn is(self, v: i64) -> Mask8 {
        self.eq_splat(v)
    }
    #[inline(always)]
    fn keep(self, f: Mask8) -> Self {
        f.keep(self)
    }
}
