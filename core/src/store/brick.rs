//! The brick layout: the raster cut into 8×8×8 bricks, the directory's
//! length, and the voxel of a record's brick position.

use crate::raster::{Extent, to_usize};

/// Bits of a brick edge: bricks are `8 × 8 × 8` voxels.
pub const BRICK_BITS: u32 = 3;
/// Voxels along a brick edge.
pub const BRICK: u32 = 1 << BRICK_BITS;
/// Voxels in a brick.
pub const BRICK_VOXELS: u32 = BRICK * BRICK * BRICK;

/// Bricks along each axis: `ceil(n / 8)`.
///
/// ```
/// use rrt_core::raster::Extent;
/// use rrt_core::store::brick_dims;
/// assert_eq!(brick_dims(Extent::new(8, 9, 17).unwrap()), [1, 2, 3]);
/// ```
#[must_use]
pub fn brick_dims(extent: Extent) -> [u32; 3] {
    // n <= MAX_AXIS = 2^16: adding 7 cannot overflow.
    extent
        .dims()
        .map(|n| n.wrapping_add(BRICK - 1) >> BRICK_BITS)
}

/// Number of bricks of `extent`, or `None` if it does not fit `usize`.
#[must_use]
pub fn brick_count(extent: Extent) -> Option<usize> {
    let [a, b, c] = brick_dims(extent).map(to_usize);
    a.checked_mul(b)?.checked_mul(c)
}

/// Length of the directory of `extent`: one entry per brick plus one.
///
/// ```
/// use rrt_core::raster::Extent;
/// use rrt_core::store::directory_len;
/// assert_eq!(directory_len(Extent::cube(16).unwrap()), Some(9));
/// ```
#[must_use]
pub fn directory_len(extent: Extent) -> Option<usize> {
    brick_count(extent)?.checked_add(1)
}

/// Brick index of voxel `v` (which must lie in `extent`; otherwise the
/// result is meaningless but never panics).
pub(super) fn brick_of(extent: Extent, v: [u32; 3]) -> usize {
    let [bx, by, _] = brick_dims(extent).map(to_usize);
    let [x, y, z] = v.map(|c| to_usize(c >> BRICK_BITS));
    // For v inside the extent the result is below brick_count, which fits.
    x.wrapping_add(bx.wrapping_mul(y.wrapping_add(by.wrapping_mul(z))))
}

/// Coordinates of the low corner of brick `b`.
pub(super) fn brick_origin(extent: Extent, b: usize) -> Option<[u32; 3]> {
    let [bx, by, _] = brick_dims(extent).map(to_usize);
    let bx = core::num::NonZeroUsize::new(bx)?;
    let by = core::num::NonZeroUsize::new(by)?;
    let x = b % bx;
    let yz = b / bx;
    let y = yz % by;
    let z = yz / by;
    let c = |v: usize| -> Option<u32> { u32::try_from(v).ok()?.checked_mul(BRICK) };
    Some([c(x)?, c(y)?, c(z)?])
}

/// Voxel coordinates of position `pos` in a brick whose low corner is `o`.
pub(super) fn voxel_at(o: [u32; 3], pos: u16) -> [u32; 3] {
    let p = u32::from(pos);
    // o is a multiple of 8 below 2^16 and the offsets are below 8: no overflow.
    [
        o[0].wrapping_add(p & 7),
        o[1].wrapping_add((p >> 3) & 7),
        o[2].wrapping_add((p >> 6) & 7),
    ]
}
