//! Integer helpers shared by the voxelizers: exact floor/ceil/rounded
//! divisions, square roots, cell ranges, clipping, `i128` vector arithmetic
//! and unit vectors.
//!
//! Every function here is total: out-of-range input gives `None` or a
//! saturated value, never a panic.

use super::NORMAL_ONE;
use super::error::{COORD_LIMIT, VoxelizeError};
use core::ops::Range;

use crate::fixed::{FRAC_BITS, HALF_VOXEL, VOXEL};
use crate::raster::Extent;

/// One voxel in fixed units, as `i128`.
pub(crate) const V: i128 = VOXEL as i128;
/// Half a voxel in fixed units, as `i128`.
pub(crate) const H: i128 = HALF_VOXEL as i128;

/// `Err(OutOfRange)` unless `|v| <= COORD_LIMIT`.
pub(crate) fn check_coord(v: i64) -> Result<i128, VoxelizeError> {
    if v.unsigned_abs() <= COORD_LIMIT.unsigned_abs() {
        Ok(i128::from(v))
    } else {
        Err(VoxelizeError::OutOfRange)
    }
}

/// A point checked against [`COORD_LIMIT`], widened to `i128`.
pub(crate) fn check_point(p: [i64; 3]) -> Result<[i128; 3], VoxelizeError> {
    Ok([check_coord(p[0])?, check_coord(p[1])?, check_coord(p[2])?])
}

/// `floor(n / V)` (an arithmetic shift: exact and total).
#[inline]
pub(crate) const fn cell_floor(n: i128) -> i128 {
    n >> FRAC_BITS
}

/// `ceil(n / V)`.
#[inline]
pub(crate) const fn cell_ceil(n: i128) -> i128 {
    // -floor(-n / V); for n = i128::MIN the negation would overflow, so
    // saturate first (no accepted coordinate is anywhere near).
    let m = n.saturating_neg();
    (m >> FRAC_BITS).saturating_neg()
}

/// Fixed-point centre of cell `i`, as `i128`.
#[inline]
pub(crate) fn centre(i: u32) -> i128 {
    // i < 2^32, so i·2^16 + 2^15 < 2^49.
    (i128::from(i) << FRAC_BITS) | H
}

/// Fixed-point low face of cell `i`, as `i128`.
#[inline]
pub(crate) fn low(i: u32) -> i128 {
    i128::from(i) << FRAC_BITS
}

/// Cells `[iV, (i+1)V]` (closed) that overlap the closed interval `[a, b]`:
/// `ceil(a / V) - 1 ..= floor(b / V)`.
#[inline]
pub(crate) const fn cells_overlapping(a: i128, b: i128) -> (i128, i128) {
    (cell_ceil(a).saturating_sub(1), cell_floor(b))
}

/// Cells whose centre `iV + V/2` lies in the closed interval `[a, b]`.
#[inline]
pub(crate) const fn centres_within(a: i128, b: i128) -> (i128, i128) {
    (
        cell_ceil(a.saturating_sub(H)),
        cell_floor(b.saturating_sub(H)),
    )
}

/// The cells a voxelizer scans along each axis, `start .. end`: the
/// raster's, along y only the rows and along z only the layers the sink
/// keeps ([`VoxelSink::rows`](super::VoxelSink::rows),
/// [`VoxelSink::layers`](super::VoxelSink::layers)).
pub(crate) fn window<S: super::VoxelSink + ?Sized>(extent: Extent, sink: &S) -> [(u32, u32); 3] {
    window_of(extent, sink.rows(), sink.layers())
}

/// The cells scanned along each axis, `start .. end`, of a sink keeping
/// the rows `rows` and the layers `layers` ([`window`]; CSG sinks too).
pub(crate) fn window_of(extent: Extent, rows: Range<u32>, layers: Range<u32>) -> [(u32, u32); 3] {
    let [nx, ny, nz] = extent.dims();
    let within = |r: Range<u32>, n: u32| {
        let end = r.end.min(n);
        (r.start.min(end), end)
    };
    [(0, nx), within(rows, ny), within(layers, nz)]
}

/// Intersects the cell range `lo ..= hi` with the cells `start .. end` of
/// an axis (of a [`window`]).
#[inline]
pub(crate) fn clip(lo: i128, hi: i128, (start, end): (u32, u32)) -> Option<(u32, u32)> {
    let lo = lo.max(i128::from(start));
    let hi = hi.min(i128::from(end).saturating_sub(1));
    if lo > hi {
        return None;
    }
    Some((u32::try_from(lo).ok()?, u32::try_from(hi).ok()?))
}

/// Splits the cell range `lo ..= hi` around the (possibly empty) range
/// `ex_lo ..= ex_hi`: the part below it, the part inside it, the part above
/// it. Lets a scan skip the inside of a solid without visiting it.
#[inline]
pub(crate) fn split(lo: u32, hi: u32, ex_lo: i128, ex_hi: i128) -> [Option<(u32, u32)>; 3] {
    let (l, h) = (i128::from(lo), i128::from(hi));
    let part = |a: i128, b: i128| -> Option<(u32, u32)> {
        let (a, b) = (a.max(l), b.min(h));
        (a <= b).then_some((u32::try_from(a).ok()?, u32::try_from(b).ok()?))
    };
    if ex_lo > ex_hi {
        return [part(l, h), None, None];
    }
    [
        part(l, ex_lo.saturating_sub(1)),
        part(ex_lo, ex_hi),
        part(ex_hi.saturating_add(1), h),
    ]
}

/// `⌊√x⌋` from an estimate `r` of it, in `r`'s and `x`'s unsigned type:
/// down while `r² > x`, up while `(r + 1)² ≤ x`. Exact whatever the
/// estimate; as many steps as it is off.
macro_rules! floor_root {
    ($r:expr, $x:expr) => {{
        let (mut r, x) = ($r, $x);
        while r.checked_mul(r).is_none_or(|q| q > x) {
            r = r.wrapping_sub(1);
        }
        while r
            .wrapping_add(1)
            .checked_mul(r.wrapping_add(1))
            .is_some_and(|q| q <= x)
        {
            r = r.wrapping_add(1);
        }
        r
    }};
}

/// `⌊√(t·2^24)⌋` for the top byte `t = 64 + i` of a normalized
/// argument of [`isqrt_u64`]: a root good to 8 bits, in `[2^15, 2^16)`.
const ROOTS: [u16; 192] = {
    let mut t = [0u16; 192];
    let mut i = 0;
    while i < t.len() {
        let v = ((i as u64) + 64) << 24;
        // v < 2^32: the root < 2^16.
        #[allow(clippy::cast_possible_truncation)]
        {
            t[i] = v.isqrt() as u16;
        }
        i += 1;
    }
    t
};

/// `⌊√x⌋`, always equal to [`u64::isqrt`]: a guess from the top byte of
/// the argument shifted to `[2^62, 2^64)` (a table), two integer Newton
/// steps (about 7 → 14 → 28 good bits, two divisions), the shift undone,
/// and a correction that moves the estimate to the exact floor whatever
/// it was (so the answer never depends on the estimate's precision, only
/// the number of correction steps does).
#[inline]
pub(crate) fn isqrt_u64(x: u64) -> u64 {
    if x < 4 {
        return u64::from(x != 0);
    }
    // An even shift, so that the root shifts back by half of it.
    let lz = x.leading_zeros() & !1;
    let xn = x << lz;
    // xn ≥ 2^62: its top byte is 64..=255.
    let top = usize::from(u8::try_from(xn >> 56).unwrap_or(u8::MAX));
    let guess = ROOTS.get(top.wrapping_sub(64)).copied().unwrap_or(u16::MAX);
    // Within 1/128 of √xn ∈ [2^31, 2^32); s ∈ (2^31, 2^32].
    let mut s = u64::from(guess).wrapping_add(1) << 16;
    for _ in 0..2 {
        // A Newton step from any s > 0 lands at or above ⌊√xn⌋ ≥ 2^31, so
        // s stays nonzero, and s + xn/s < 2^32 + 2^33.
        s = s.wrapping_add(xn.checked_div(s).unwrap_or(0)) >> 1;
    }
    // Within a few units of ⌊√x⌋, made exact.
    floor_root!(s >> (lz >> 1), x)
}

/// `⌊√n⌋`, always equal to [`u128::isqrt`]: [`isqrt_u64`] below 2^64;
/// above, the root of the argument's top 62 to 64 bits shifted back
/// (`r₀ ≤ √n`, good to 31 bits), one Newton step (in 64-bit division
/// while the remainder `n − r₀²` fits, as it does below 2^94) and the
/// correction to the exact floor.
#[inline]
pub(crate) fn isqrt_u128(n: u128) -> u128 {
    if let Ok(small) = u64::try_from(n) {
        return u128::from(isqrt_u64(small));
    }
    // n ≥ 2^64: an even shift leaves 63 or 64 bits.
    let bits = 128u32.saturating_sub(n.leading_zeros());
    let s = bits.saturating_sub(63) & !1;
    let hi = u128::from(isqrt_u64(u64::try_from(n >> s).unwrap_or(u64::MAX)));
    // hi ≥ 2^31 and hi² ≤ n >> s: r0² ≤ n, r0 ≥ 2^31.
    let r0 = hi << (s >> 1);
    let rem = n.wrapping_sub(r0.wrapping_mul(r0));
    // ⌊(r0 + n/r0)/2⌋ = r0 + ⌊rem/(2·r0)⌋: at or above ⌊√n⌋.
    let step = match (u64::try_from(rem), u64::try_from(r0 << 1)) {
        (Ok(a), Ok(b)) => u128::from(a.checked_div(b).unwrap_or(0)),
        _ => rem.checked_div(r0 << 1).unwrap_or(0),
    };
    floor_root!(r0.wrapping_add(step), n)
}

/// `floor(sqrt(n))`, 0 for negative `n`.
#[inline]
pub(crate) fn isqrt(n: i128) -> i128 {
    if n <= 0 {
        return 0;
    }
    match u64::try_from(n) {
        Ok(small) => i128::from(isqrt_u64(small)),
        // n < 2^127, so its root is < 2^64 and fits.
        Err(_) => i128::try_from(isqrt_u128(n.unsigned_abs())).unwrap_or(i128::MAX),
    }
}

/// `ceil(sqrt(n))`, 0 for negative `n`.
#[inline]
pub(crate) fn ceil_sqrt(n: i128) -> i128 {
    let s = isqrt(n);
    // s ≤ 2^64, so s² and s + 1 cannot overflow i128.
    if s.saturating_mul(s) < n {
        s.saturating_add(1)
    } else {
        s
    }
}

/// Saturating conversion of a non-negative fixed-point length to `u32`.
#[inline]
pub(crate) fn dist_u32(d: i128) -> u32 {
    u32::try_from(d.unsigned_abs()).unwrap_or(u32::MAX)
}

/// Scales `v` to a unit vector of length [`NORMAL_ONE`]; `None` for the zero
/// vector. Components are first shifted (up or down) so the largest lies in
/// `[2^29, 2^30)`; then 64-bit arithmetic suffices and the result is accurate
/// to about `2^-29` relative, even for tiny vectors.
#[inline]
pub(crate) fn unit(v: [i128; 3]) -> Option<[i32; 3]> {
    let m = v.iter().map(|c| c.unsigned_abs()).max().unwrap_or(0);
    if m == 0 {
        return None;
    }
    let bits = 128u32.saturating_sub(m.leading_zeros());
    let w = if bits > 30 {
        v.map(|c| c >> bits.saturating_sub(30))
    } else {
        // |c| < 2^bits: shifting left by 30 − bits stays below 2^30.
        v.map(|c| c << 30u32.saturating_sub(bits))
    };
    normalize64(w.map(|c| i64::try_from(c).unwrap_or(0)))
}

/// Unit vector of `w` with every `|w_k| < 2^31`.
#[inline]
fn normalize64(w: [i64; 3]) -> Option<[i32; 3]> {
    normalize64_len(w).1
}

/// `floor(|w|)` and the unit vector of `w` ([`normalize64`]), for every
/// `|w_k| < 2^31`.
#[inline]
fn normalize64_len(w: [i64; 3]) -> (i64, Option<[i32; 3]>) {
    // |w_k| < 2^31: squares < 2^62, their sum < 2^64.
    let len2 = w.iter().fold(0u64, |acc, c| {
        acc.wrapping_add(c.unsigned_abs().wrapping_mul(c.unsigned_abs()))
    });
    let len = i64::try_from(isqrt_u64(len2)).unwrap_or(i64::MAX);
    (len, unit_of_len(w, len))
}

/// `w·2^30 / len` per component (truncated), for `|w_k| ≤ len < 2^31`;
/// `None` for `len = 0`.
#[inline]
fn unit_of_len(w: [i64; 3], len: i64) -> Option<[i32; 3]> {
    if len == 0 {
        return None;
    }
    let one = i64::from(NORMAL_ONE);
    let mut out = [0i32; 3];
    for (o, c) in out.iter_mut().zip(w) {
        // |c| < 2^31: c·2^30 < 2^61; |c| ≤ len keeps the quotient ≤ 2^30.
        *o = i32::try_from(c.wrapping_mul(one).checked_div(len)?).ok()?;
    }
    Some(out)
}

/// Length `floor(sqrt(v·v))` and unit direction of `v`. Vectors with a
/// component in `[2^20, 2^31)` (the common case: more than 1/64 voxel) take
/// one 64-bit square root for both; shorter ones too, scaled as [`unit()`]
/// scales them (the root of the scaled length, shifted back, is the
/// floored length: `⌊⌊2^s·x⌋ / 2^s⌋ = ⌊x⌋`); longer ones go through
/// [`length`] and [`unit()`].
#[inline]
pub(crate) fn radial(v: [i128; 3]) -> (i128, Option<[i32; 3]>) {
    let m = v.iter().map(|c| c.unsigned_abs()).max().unwrap_or(0);
    if (1..1 << 20).contains(&m) {
        // As `unit`: the largest component scaled to 30 bits.
        let s = 30u32.saturating_sub(128u32.saturating_sub(m.leading_zeros()));
        let w = v.map(|c| i64::try_from(c << s).unwrap_or(0));
        let (len, u) = normalize64_len(w);
        return (i128::from(len >> s), u);
    }
    if (1 << 20..1 << 31).contains(&m) {
        let w = v.map(|c| i64::try_from(c).unwrap_or(0));
        let len2 = w.iter().fold(0u64, |acc, c| {
            acc.wrapping_add(c.unsigned_abs().wrapping_mul(c.unsigned_abs()))
        });
        let len = i64::try_from(isqrt_u64(len2)).unwrap_or(i64::MAX);
        let one = i64::from(NORMAL_ONE);
        let mut out = [0i32; 3];
        for (o, c) in out.iter_mut().zip(w) {
            // len ≥ 2^20: relative error of the floored root ≤ 2^-20.
            *o = i32::try_from(c.wrapping_mul(one).checked_div(len).unwrap_or(0)).unwrap_or(0);
        }
        (i128::from(len), Some(out))
    } else {
        (length(v), unit(v))
    }
}

/// Euclidean length `floor(sqrt(v·v))` (saturating for huge `v`).
#[inline]
pub(crate) fn length(v: [i128; 3]) -> i128 {
    isqrt(dot(v, v))
}

/// `a − b` per axis, saturating.
#[inline]
pub(crate) fn sub(a: [i128; 3], b: [i128; 3]) -> [i128; 3] {
    [
        a[0].saturating_sub(b[0]),
        a[1].saturating_sub(b[1]),
        a[2].saturating_sub(b[2]),
    ]
}

/// `a + b` per axis, saturating.
#[inline]
pub(crate) fn add(a: [i128; 3], b: [i128; 3]) -> [i128; 3] {
    [
        a[0].saturating_add(b[0]),
        a[1].saturating_add(b[1]),
        a[2].saturating_add(b[2]),
    ]
}

/// `a·b`, saturating (summed in axis order).
#[inline]
pub(crate) fn dot(a: [i128; 3], b: [i128; 3]) -> i128 {
    // Below 2^62 per factor, each product is below 2^124 and the sum below
    // 2^126: exact, nothing to saturate, and no overflow checks to pay.
    const SMALL: u128 = 1 << 62;
    if a.iter().chain(b.iter()).all(|v| v.unsigned_abs() < SMALL) {
        return a[0]
            .wrapping_mul(b[0])
            .wrapping_add(a[1].wrapping_mul(b[1]))
            .wrapping_add(a[2].wrapping_mul(b[2]));
    }
    a.iter()
        .zip(b)
        .fold(0i128, |s, (x, y)| s.saturating_add(x.saturating_mul(y)))
}

/// `a · b`, or `None` when a product or a sum overflows.
#[inline]
pub(crate) fn checked_dot(a: [i128; 3], b: [i128; 3]) -> Option<i128> {
    a.iter()
        .zip(b)
        .try_fold(0i128, |s, (x, y)| s.checked_add(x.checked_mul(y)?))
}

/// `a × b`, saturating.
#[inline]
pub(crate) fn cross(a: [i128; 3], b: [i128; 3]) -> [i128; 3] {
    let m = |x: i128, y: i128| x.saturating_mul(y);
    [
        m(a[1], b[2]).saturating_sub(m(a[2], b[1])),
        m(a[2], b[0]).saturating_sub(m(a[0], b[2])),
        m(a[0], b[1]).saturating_sub(m(a[1], b[0])),
    ]
}

/// The unit lattice vector along the axis on which `v` is smallest in
/// magnitude (the first of equals): a direction never parallel to `v`.
#[inline]
pub(crate) fn least_axis(v: [i128; 3]) -> [i128; 3] {
    let a = v.map(i128::unsigned_abs);
    if a[0] <= a[1] && a[0] <= a[2] {
        [1, 0, 0]
    } else if a[1] <= a[2] {
        [0, 1, 0]
    } else {
        [0, 0, 1]
    }
}

/// `a × b`, or `None` if a product or difference overflows.
#[inline]
pub(crate) fn checked_cross(a: [i128; 3], b: [i128; 3]) -> Option<[i128; 3]> {
    let c = |i: i128, j: i128, k: i128, l: i128| i.checked_mul(j)?.checked_sub(k.checked_mul(l)?);
    Some([
        c(a[1], b[2], a[2], b[1])?,
        c(a[2], b[0], a[0], b[2])?,
        c(a[0], b[1], a[1], b[0])?,
    ])
}

/// `p − s·u`, where `u` is a [`NORMAL_ONE`]-scaled unit vector and `s` a
/// length (each component's product floored by the scale), saturating.
#[inline]
pub(crate) fn sub_along(p: [i128; 3], u: [i128; 3], s: i128) -> [i128; 3] {
    [0, 1, 2].map(|k| p[k].saturating_sub(u[k].saturating_mul(s) >> NORMAL_SHIFT))
}

/// Bits of [`NORMAL_ONE`].
const NORMAL_SHIFT: u32 = NORMAL_ONE.trailing_zeros();

/// The per-axis minimum and maximum of `points` (`[0; 3]` twice for none).
#[inline]
pub(crate) fn bounds<'a, I>(points: I) -> ([i128; 3], [i128; 3])
where
    I: IntoIterator<Item = &'a [i128; 3]>,
    I::IntoIter: Clone,
{
    let it = points.into_iter();
    let lo = [0, 1, 2].map(|k| it.clone().map(|p| p[k]).min().unwrap_or(0));
    let hi = [0, 1, 2].map(|k| it.clone().map(|p| p[k]).max().unwrap_or(0));
    (lo, hi)
}

/// `round(n / d)` (halves up) for `d > 0`; 0 otherwise.
#[inline]
pub(crate) fn round_div(n: i128, d: i128) -> i128 {
    if d <= 0 {
        return 0;
    }
    div_euclid(n.saturating_add(d >> 1), d).unwrap_or(0)
}

/// `n.checked_div_euclid(d)`, in 64 bits when both fit (a 128-bit
/// division is a library call many times slower; the result is the same).
#[inline]
pub(crate) fn div_euclid(n: i128, d: i128) -> Option<i128> {
    if let (Ok(a), Ok(b)) = (i64::try_from(n), i64::try_from(d))
        && let Some(q) = a.checked_div_euclid(b)
    {
        return Some(i128::from(q));
    }
    n.checked_div_euclid(d)
}

/// `(n.checked_div_euclid(d), n.checked_rem_euclid(d))`, in 64 bits when
/// both fit ([`div_euclid`]).
#[inline]
pub(crate) fn div_rem_euclid(n: i128, d: i128) -> Option<(i128, i128)> {
    if let (Ok(a), Ok(b)) = (i64::try_from(n), i64::try_from(d))
        && let (Some(q), Some(r)) = (a.checked_div_euclid(b), a.checked_rem_euclid(b))
    {
        return Some((i128::from(q), i128::from(r)));
    }
    Some((n.checked_div_euclid(d)?, n.checked_rem_euclid(d)?))
}

/// `n.checked_div(d)` (truncating), in 64 bits when both fit
/// ([`div_euclid`]).
#[inline]
pub(crate) fn div_trunc(n: i128, d: i128) -> Option<i128> {
    if let (Ok(a), Ok(b)) = (i64::try_from(n), i64::try_from(d))
        && let Some(q) = a.checked_div(b)
    {
        return Some(i128::from(q));
    }
    n.checked_div(d)
}

/// Counts offers; saturating, so it never overflows.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct Counter(pub(crate) u64);

impl Counter {
    #[inline]
    pub(crate) fn bump(&mut self) {
        self.0 = self.0.saturating_add(1);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The 64-bit fast paths divide exactly as `i128` does, at the edges
    /// of `i64` (where its division overflows) and beyond them.
    #[test]
    fn fast_divisions_are_the_i128_ones() {
        let m = i128::from(i64::MAX);
        let edges = [
            0,
            1,
            -1,
            2,
            -2,
            7,
            -7,
            V,
            -V,
            m,
            -m,
            m + 1,
            -m - 1,
            -m - 2,
            m * 3,
            -m * 5,
            i128::MAX,
            i128::MIN,
        ];
        let mut rng = crate::testkit::Rng(0xd1f1);
        let mut values: std::vec::Vec<i128> = edges.to_vec();
        for _ in 0..200 {
            let x = rng.next_u64() as i64;
            values.push(i128::from(x >> (x as u64 % 64)));
        }
        for &n in &values {
            for &d in &values {
                assert_eq!(div_euclid(n, d), n.checked_div_euclid(d), "{n} {d}");
                assert_eq!(div_trunc(n, d), n.checked_div(d), "{n} {d}");
                let want = n.checked_div_euclid(d).zip(n.checked_rem_euclid(d));
                assert_eq!(div_rem_euclid(n, d), want, "{n} {d}");
            }
        }
    }

    #[test]
    fn cell_ranges() {
        assert_eq!(cell_floor(-1), -1);
        assert_eq!(cell_ceil(1), 1);
        assert_eq!(cell_ceil(V), 1);
        assert_eq!(cells_overlapping(V, V), (0, 1));
        assert_eq!(cells_overlapping(V + 1, 2 * V - 1), (1, 1));
        assert_eq!(centres_within(0, V), (0, 0));
        assert_eq!(centres_within(H + 1, V + H - 1), (1, 0));
        assert_eq!(clip(-5, 3, (0, 2)), Some((0, 1)));
        assert_eq!(clip(4, 9, (0, 2)), None);
        assert_eq!(clip(-5, 9, (3, 5)), Some((3, 4)));
        // A sink keeping the rows and layers `.0`.
        struct Keep([core::ops::Range<u32>; 2]);
        impl crate::voxelize::VoxelSink for Keep {
            fn offer(&mut self, _: [u32; 3], _: crate::voxelize::Surfel) {}
            fn rows(&self) -> core::ops::Range<u32> {
                self.0[0].clone()
            }
            fn layers(&self) -> core::ops::Range<u32> {
                self.0[1].clone()
            }
        }
        let e = Extent::new(4, 5, 6).unwrap();
        let all = 0..u32::MAX;
        assert_eq!(
            window(e, &Keep([all.clone(), all.clone()])),
            [(0, 4), (0, 5), (0, 6)]
        );
        assert_eq!(
            window(e, &Keep([all.clone(), 2..4])),
            [(0, 4), (0, 5), (2, 4)]
        );
        assert_eq!(window(e, &Keep([1..3, 2..4])), [(0, 4), (1, 3), (2, 4)]);
        assert_eq!(
            window(e, &Keep([3..9, all.clone()])),
            [(0, 4), (3, 5), (0, 6)]
        );
        assert_eq!(clip(0, 9, window(e, &Keep([all.clone(), 8..16]))[2]), None);
        assert_eq!(clip(0, 9, window(e, &Keep([7..9, all]))[1]), None);
    }

    #[test]
    fn splits() {
        assert_eq!(
            split(0, 9, 3, 5),
            [Some((0, 2)), Some((3, 5)), Some((6, 9))]
        );
        assert_eq!(split(4, 9, 3, 5), [None, Some((4, 5)), Some((6, 9))]);
        assert_eq!(split(0, 9, 1, 0), [Some((0, 9)), None, None]);
        assert_eq!(split(0, 2, -9, 99), [None, Some((0, 2)), None]);
    }

    #[test]
    fn fast_root_is_the_floor_root() {
        let mut rng = crate::testkit::Rng(0x15_9e7);
        let near = |r: u64| {
            [
                r.wrapping_mul(r).wrapping_sub(1),
                r.wrapping_mul(r),
                r.wrapping_mul(r) + 1,
            ]
        };
        for x in 0..200_000u64 {
            assert_eq!(isqrt_u64(x), x.isqrt(), "{x}");
        }
        for bits in 0..64u32 {
            for _ in 0..20_000 {
                let x = rng.next_u64() >> (63 - bits);
                assert_eq!(isqrt_u64(x), x.isqrt(), "{x}");
            }
            let r = 1u64 << (bits / 2);
            for x in near(r).into_iter().chain(near(r.saturating_sub(1) | r)) {
                assert_eq!(isqrt_u64(x), x.isqrt(), "{x}");
            }
        }
        for r in (u64::from(u32::MAX) - 2000)..u64::from(u32::MAX) {
            for x in near(r) {
                assert_eq!(isqrt_u64(x), x.isqrt(), "{x}");
            }
        }
        for x in [u64::MAX, u64::MAX - 1, 1 << 62, (1 << 62) - 1, 1 << 63] {
            assert_eq!(isqrt_u64(x), x.isqrt(), "{x}");
        }
    }

    #[test]
    fn fast_wide_root_is_the_floor_root() {
        let mut rng = crate::testkit::Rng(0x15_9e7_128);
        let near = |r: u128| {
            let sq = r.wrapping_mul(r);
            [sq.wrapping_sub(1), sq, sq.wrapping_add(1)]
        };
        for bits in 0..128u32 {
            for _ in 0..5_000 {
                let x = ((u128::from(rng.next_u64()) << 64) | u128::from(rng.next_u64()))
                    >> (127 - bits);
                assert_eq!(isqrt_u128(x), x.isqrt(), "{x}");
            }
            let r = 1u128 << (bits / 2);
            for x in near(r)
                .into_iter()
                .chain(near(r - 1))
                .chain(near(r | (r >> 1)))
            {
                assert_eq!(isqrt_u128(x), x.isqrt(), "{x}");
            }
        }
        for x in [
            u128::MAX,
            u128::MAX - 1,
            1 << 64,
            (1 << 64) - 1,
            1 << 127,
            (1 << 94) - 1,
        ] {
            assert_eq!(isqrt_u128(x), x.isqrt(), "{x}");
        }
    }

    #[test]
    fn roots() {
        for n in [0i128, 1, 2, 3, 4, 15, 16, 17, (1 << 70) + 5] {
            let s = isqrt(n);
            assert!(s * s <= n && (s + 1) * (s + 1) > n);
            let c = ceil_sqrt(n);
            assert!(c * c >= n && (c == 0 || (c - 1) * (c - 1) < n));
        }
        assert_eq!(isqrt(-4), 0);
    }

    #[test]
    fn units() {
        let one = i128::from(NORMAL_ONE);
        assert_eq!(unit([0, 0, 5]), Some([0, 0, NORMAL_ONE]));
        assert_eq!(unit([0, 0, 0]), None);
        let u = unit([1 << 100, 1 << 100, 0]).unwrap();
        let len2: i128 = u.iter().map(|c| i128::from(*c) * i128::from(*c)).sum();
        assert!((len2 - one * one).abs() < one * 4);
        // Tiny vectors are scaled up first: (1, 1, 1) is not (1, 1, 1)·2^30.
        // Fuzz regression: a zero-length segment at the origin gave the
        // centre offset (h, h, h), whose floored root (56755) left the
        // normal 1.4e-5 too long before the scaling.
        for v in [
            [1i128, 1, 1],
            [1, 0, 0],
            [3, -7, 2],
            [1 << 25, 1 << 25, 5],
            [32768, 32768, 32768],
        ] {
            for u in [unit(v).unwrap(), radial(v).1.unwrap()] {
                let l2: i128 = u.iter().map(|c| i128::from(*c).pow(2)).sum();
                assert!(
                    (l2 - one * one).abs() < one * one / (1 << 18),
                    "{v:?} {u:?}"
                );
            }
        }
    }

    #[test]
    fn radial_is_length_and_unit() {
        // Below 2^20 the very numbers of `length` and `unit`; above, the
        // length and a unit vector from it (within 2^-20).
        let mut rng = crate::testkit::Rng(0x4ad1_a100);
        let check = |v: [i128; 3]| {
            let (len, u) = radial(v);
            assert_eq!(len, length(v), "{v:?}");
            if v.iter().all(|c| c.unsigned_abs() < 1 << 20) {
                assert_eq!(u, unit(v), "{v:?}");
            }
        };
        check([0; 3]);
        for bits in 0..40u32 {
            for _ in 0..200 {
                let mut c = || i128::from(rng.range(-(1i64 << bits), 1i64 << bits));
                check([c(), c(), c()]);
            }
            check([1i128 << bits, 0, 0]);
            check([(1i128 << bits) - 1, -((1i128 << bits) - 1), 1]);
        }
    }
}

/// `floor(n / d)` for `d > 0`.
#[inline]
pub(crate) fn floor_div(n: i128, d: i128) -> Option<i128> {
    if d <= 0 {
        return None;
    }
    div_euclid(n, d)
}

/// `ceil(n / d)` for `d > 0`.
#[inline]
pub(crate) fn ceil_div(n: i128, d: i128) -> Option<i128> {
    floor_div(n.checked_neg()?, d)?.checked_neg()
}

/// Incremental floor division: `floor((n0 + j·dn) / d)` for `j = 0, 1, …`,
/// one addition and one comparison per step (the scan-line decision
/// mechanism: no division inside the loop).
#[derive(Clone, Copy, Debug)]
pub(crate) struct IncDiv {
    /// Current quotient.
    pub(crate) q: i128,
    /// Remainder, `0 <= r < d`.
    r: i128,
    dq: i128,
    dr: i128,
    d: i128,
}

impl IncDiv {
    /// The per-step quotient and remainder of `dn / d`, for
    /// [`IncDiv::with_step`]: computed once for many divisions with the
    /// same `dn` and `d`. `None` for `d <= 0` or out-of-range operands.
    pub(crate) fn step_of(dn: i128, d: i128) -> Option<(i128, i128)> {
        if d <= 0 {
            return None;
        }
        div_rem_euclid(dn, d)
    }

    /// `floor((n0 + j·dn) / d)` from `j = 0`, the step of `dn` given as
    /// [`IncDiv::step_of`]`(dn, d)`. `None` for `d <= 0` or out-of-range
    /// operands.
    #[inline]
    pub(crate) fn with_step(n0: i128, (dq, dr): (i128, i128), d: i128) -> Option<Self> {
        if d <= 0 {
            return None;
        }
        let (q, r) = div_rem_euclid(n0, d)?;
        Some(Self { q, r, dq, dr, d })
    }

    /// Advances to the next `j`.
    #[inline]
    pub(crate) fn step(&mut self) {
        // 0 <= r, dr < d, so r + dr < 2d cannot overflow; q moves by dq or
        // dq + 1 per step and stays near the exact quotients, which the
        // caller's ranges keep far from the i128 limits (saturating anyway).
        self.r = self.r.wrapping_add(self.dr);
        let carry = if self.r >= self.d {
            self.r = self.r.wrapping_sub(self.d);
            1
        } else {
            0
        };
        self.q = self.q.saturating_add(self.dq).saturating_add(carry);
    }
}
