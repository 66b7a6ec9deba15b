//! SplitMix64: the seeded generator both sides draw their inputs from.

/// The core's SplitMix64 generator ([`rrt_core::rng::Rng`], Steele, Lea &
/// Flood 2014: 64-bit state, one multiply-xorshift finalizer per output,
/// identical on every target) with independent streams and the draws the
/// ray set and the checks use.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Rng(rrt_core::rng::Rng);

impl Rng {
    /// The generator for `seed`, stream `stream` (independent streams for
    /// item `i` of a set, so that items can be drawn in any order).
    #[must_use]
    pub const fn new(seed: u64, stream: u64) -> Self {
        Self(rrt_core::rng::Rng::new(
            seed ^ stream.wrapping_mul(0x9e37_79b9_7f4a_7c15).rotate_left(17),
        ))
    }

    /// The next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.0.next_u64()
    }

    /// A value in `0..n` (`0` for `n == 0`), by the high bits of a 64×64
    /// product (Lemire's method without the rejection step: the tiny bias is
    /// the same on every target).
    pub fn below(&mut self, n: u64) -> u64 {
        ((u128::from(self.next_u64()) * u128::from(n)) >> 64) as u64
    }

    /// A value in `lo..=hi` (`lo` when `hi < lo`).
    pub fn range(&mut self, lo: i64, hi: i64) -> i64 {
        if hi <= lo {
            return lo;
        }
        let span = hi.abs_diff(lo).saturating_add(1);
        lo.wrapping_add(self.below(span) as i64)
    }

    /// `true` with probability `num / den`.
    pub fn chance(&mut self, num: u64, den: u64) -> bool {
        self.below(den) < num
    }

    /// `1` or `-1`.
    pub fn sign(&mut self) -> i64 {
        if self.next_u64() & 1 == 0 { 1 } else { -1 }
    }
}
