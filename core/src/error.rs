//! Small `Copy` error values returned by the core.
//!
//! Every fallible public function of `rrt-core` returns one of these instead
//! of panicking. They carry just enough to say what was wrong; the host turns
//! them into messages with file and line.

use core::fmt;

/// Why a raster could not be built over the given dimensions and plane.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum RasterError {
    /// A dimension was zero.
    ZeroDimension {
        /// 0 = x, 1 = y, 2 = z.
        axis: u8,
    },
    /// A dimension exceeded [`crate::raster::MAX_AXIS`].
    DimensionTooLarge {
        /// 0 = x, 1 = y, 2 = z.
        axis: u8,
        /// The rejected value.
        value: u32,
    },
    /// `nx * ny * nz` does not fit in `usize` on this target.
    VolumeOverflow,
    /// The plane slice does not hold exactly one byte per voxel.
    PlaneLength {
        /// `nx * ny * nz`.
        expected: usize,
        /// The slice length given.
        found: usize,
    },
    /// The line level does not hold exactly one byte per line of
    /// [`crate::raster::LINE_CELLS`] cells.
    LineLength {
        /// `ceil(plane length / LINE_CELLS)`.
        expected: usize,
        /// The slice length given.
        found: usize,
    },
}

impl fmt::Display for RasterError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            Self::ZeroDimension { axis } => {
                write!(f, "raster dimension {} is zero", axis_name(axis))
            }
            Self::DimensionTooLarge { axis, value } => write!(
                f,
                "raster dimension {} = {value} exceeds the limit of {}",
                axis_name(axis),
                crate::raster::MAX_AXIS
            ),
            Self::VolumeOverflow => f.write_str("raster volume nx*ny*nz overflows usize"),
            Self::PlaneLength { expected, found } => {
                write!(
                    f,
                    "raster plane holds {found} bytes, expected {expected} (one per voxel)"
                )
            }
            Self::LineLength { expected, found } => write!(
                f,
                "raster line level holds {found} bytes, expected {expected} (one per {} cells)",
                crate::raster::LINE_CELLS
            ),
        }
    }
}

impl core::error::Error for RasterError {}

/// Why a discrete ray could not be set up or walked.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum RayError {
    /// An origin (or segment end) coordinate lies outside
    /// `±`[`crate::discrete_ray::ORIGIN_LIMIT`].
    OriginOutOfRange {
        /// 0 = x, 1 = y, 2 = z.
        axis: u8,
    },
    /// A segment's extent `end - origin` does not fit the `i32` direction.
    SegmentTooLong {
        /// 0 = x, 1 = y, 2 = z.
        axis: u8,
    },
    /// The raster passed to a walk has other dimensions than the one the ray
    /// was set up for.
    ExtentMismatch,
    /// An intermediate value left its integer type. The documented input
    /// limits rule this out; it is reported instead of panicking.
    Arithmetic,
}

impl fmt::Display for RayError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            Self::OriginOutOfRange { axis } => write!(
                f,
                "ray origin {} is outside ±2^{} fixed units",
                axis_name(axis),
                crate::discrete_ray::ORIGIN_LIMIT_BITS
            ),
            Self::SegmentTooLong { axis } => {
                write!(
                    f,
                    "segment extent along {} does not fit in i32 fixed units",
                    axis_name(axis)
                )
            }
            Self::ExtentMismatch => f.write_str(
                "ray walked through a raster of other dimensions than it was set up for",
            ),
            Self::Arithmetic => f.write_str("discrete ray setup arithmetic out of range"),
        }
    }
}

impl core::error::Error for RayError {}

pub(crate) const fn axis_name(axis: u8) -> &'static str {
    match axis {
        0 => "x",
        1 => "y",
        _ => "z",
    }
}
