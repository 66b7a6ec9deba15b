//! Errors and accepted input ranges of the voxelizers.

use core::fmt;

/// Largest accepted magnitude of any coordinate, radius or length handed to a
/// voxelizer, in fixed units: `2^40` (`2^24` voxels, 256 times the largest
/// raster axis). Within it every intermediate product of the voxelizers fits
/// in `i128`; larger input is refused with [`VoxelizeError::OutOfRange`].
pub const COORD_LIMIT: i64 = 1 << 40;

/// Why a voxelizer refused an object. Objects partly or wholly outside the
/// raster are not errors: they are clipped (possibly to nothing).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum VoxelizeError {
    /// A coordinate, radius or length exceeds [`COORD_LIMIT`].
    OutOfRange,
    /// A radius that must be positive is zero or negative.
    NonPositiveRadius,
    /// The object has no extent: a triangle whose vertices are collinear, a
    /// box with `max <= min` on an axis, a cone with coinciding base and
    /// apex centres, a patch whose control points all coincide.
    Degenerate,
    /// A polygon has fewer than 3 or more than
    /// [`crate::voxelize::triangle::MAX_POLYGON_VERTICES`] vertices.
    VertexCount,
    /// A polygon is not simple (its projection onto its plane crosses
    /// itself), so it cannot be split into triangles.
    NotSimple,
    /// A mesh index points past the end of the vertex (or normal) slice.
    IndexOutOfRange {
        /// Position of the offending triangle in the index slice.
        triangle: usize,
    },
    /// A slice does not have the length its dimensions call for (mesh
    /// normals, volume samples).
    LengthMismatch,
    /// An intermediate value left its integer type. The documented input
    /// ranges rule this out; it is reported instead of panicking.
    Arithmetic,
}

impl fmt::Display for VoxelizeError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            Self::OutOfRange => write!(
                f,
                "coordinate or length beyond ±2^40 fixed units (2^24 voxels)"
            ),
            Self::NonPositiveRadius => f.write_str("radius is zero or negative"),
            Self::Degenerate => f.write_str("degenerate object (no area or no extent)"),
            Self::VertexCount => f.write_str("polygon vertex count out of range"),
            Self::NotSimple => f.write_str("polygon is not simple"),
            Self::IndexOutOfRange { triangle } => {
                write!(f, "mesh triangle {triangle} has an index out of range")
            }
            Self::LengthMismatch => f.write_str("slice length does not match the dimensions"),
            Self::Arithmetic => f.write_str("voxelizer arithmetic out of range"),
        }
    }
}

impl core::error::Error for VoxelizeError {}
