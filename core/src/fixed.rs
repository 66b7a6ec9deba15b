//! Fixed-point raster coordinates.
//!
//! All positions handed to the core are integers in units of
//! `1 / 2^FRAC_BITS` voxel ("fixed units"). Voxel `i` on an axis spans the
//! half-open interval `[i * VOXEL, (i + 1) * VOXEL)` (the *corner*
//! convention: integer coordinates lie on voxel faces, voxel centres at
//! `i * VOXEL + VOXEL / 2`).

/// Number of fractional bits of every fixed-point raster coordinate.
pub const FRAC_BITS: u32 = 16;

/// One voxel edge in fixed units (`2^FRAC_BITS`).
pub const VOXEL: i64 = 1 << FRAC_BITS;

/// Half a voxel edge in fixed units.
pub const HALF_VOXEL: i64 = VOXEL / 2;

/// Fixed-point coordinate of the centre of voxel `i` on one axis.
///
/// ```
/// use rrt_core::fixed::{voxel_centre, VOXEL};
/// assert_eq!(voxel_centre(3), 3 * VOXEL + VOXEL / 2);
/// ```
#[must_use]
pub const fn voxel_centre(i: u32) -> i64 {
    // u32 * 2^16 + 2^15 < 2^49: cannot overflow i64.
    ((i as i64) << FRAC_BITS) | HALF_VOXEL
}

/// Fixed-point coordinate of the low face of voxel `i` on one axis.
///
/// ```
/// use rrt_core::fixed::{voxel_low, VOXEL};
/// assert_eq!(voxel_low(2), 2 * VOXEL);
/// ```
#[must_use]
pub const fn voxel_low(i: u32) -> i64 {
    (i as i64) << FRAC_BITS
}
