//! The 3D raster: dimensions, linear order, and the one-byte-per-voxel plane
//! that discrete rays read.
//!
//! The raster is the paper's "volume buffer": a 3D array of voxels with
//! independent dimensions `nx, ny, nz` and cubic voxels. Voxels are stored in
//! linear order with x fastest: voxel `(x, y, z)` is at index
//! `x + nx * (y + ny * z)`, so the strides are `1, nx, nx * ny`.
//!
//! The stepper reads only the **plane**: one [`u8`] cell per voxel, whose bits
//! are described in [`cell`]. Voxel attributes (colour, normal, …) live in a
//! separate record store that is consulted only at a hit.

use crate::error::RasterError;

/// Largest accepted size of one raster axis, in voxels.
///
/// Fixed-point positions inside a raster of this size stay below `2^32` fixed
/// units, which keeps every product in the discrete ray setup inside `i128`
/// and every per-step quantity inside `i64`.
pub const MAX_AXIS: u32 = 1 << 16;

/// Bits of a plane cell.
///
/// ```text
///   bit 0      OPAQUE     the voxel is non-transparent (holds an object)
///   bit 1      PROXIMITY  the voxel is near a non-transparent voxel: adaptive
///                         rays take 6-connected steps here
///   bits 2..8  DISTANCE   in a transparent voxel: the code of a lower
///                         bound on the proximity distance (empty-space
///                         skipping; proximity::distance decodes it), 0
///                         meaning "unknown / none" (the distance field
///                         stores distances below proximity::NEAR_LIMIT
///                         and leaves farther cells EMPTY); in an OPAQUE
///                         voxel: the rank hint of its record
///                         (crate::store::rank_hint)
/// ```
pub mod cell {
    /// The voxel is non-transparent: the default hit test.
    pub const OPAQUE: u8 = 1 << 0;
    /// The voxel lies in the 26-neighbourhood of a non-transparent voxel (or
    /// is one): adaptive rays slow down to 6-connected steps here.
    pub const PROXIMITY: u8 = 1 << 1;
    /// Shift of the proximity-distance field (the rank hint in an opaque
    /// cell).
    pub const DISTANCE_SHIFT: u32 = 2;
    /// Mask of the proximity-distance field (the rank hint in an opaque
    /// cell), after shifting.
    pub const DISTANCE_MASK: u8 = 0x3f;
    /// An empty cell: transparent and far from everything.
    pub const EMPTY: u8 = 0;
}

/// Dimensions of a raster, checked at construction.
///
/// Invariant: `1 <= nx, ny, nz <= MAX_AXIS` and `nx * ny * nz` fits in
/// `usize`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Extent {
    n: [u32; 3],
    /// Cached `nx * ny * nz`.
    len: usize,
}

impl Extent {
    /// Checked constructor.
    ///
    /// # Errors
    /// [`RasterError::ZeroDimension`], [`RasterError::DimensionTooLarge`] or
    /// [`RasterError::VolumeOverflow`].
    ///
    /// ```
    /// use rrt_core::raster::Extent;
    /// let e = Extent::new(4, 3, 2).unwrap();
    /// assert_eq!(e.len(), 24);
    /// assert!(Extent::new(0, 3, 2).is_err());
    /// ```
    pub fn new(nx: u32, ny: u32, nz: u32) -> Result<Self, RasterError> {
        let n = [nx, ny, nz];
        let mut len: usize = 1;
        for (axis, &v) in (0u8..).zip(n.iter()) {
            if v == 0 {
                return Err(RasterError::ZeroDimension { axis });
            }
            if v > MAX_AXIS {
                return Err(RasterError::DimensionTooLarge { axis, value: v });
            }
            let v = usize::try_from(v).map_err(|_| RasterError::VolumeOverflow)?;
            len = len.checked_mul(v).ok_or(RasterError::VolumeOverflow)?;
        }
        Ok(Self { n, len })
    }

    /// A cube of `n` voxels per axis.
    ///
    /// # Errors
    /// As [`Extent::new`].
    pub fn cube(n: u32) -> Result<Self, RasterError> {
        Self::new(n, n, n)
    }

    /// `[nx, ny, nz]`.
    #[must_use]
    pub const fn dims(&self) -> [u32; 3] {
        self.n
    }

    /// Number of voxels `nx * ny * nz`.
    #[must_use]
    #[allow(clippy::len_without_is_empty)] // an extent is never empty
    pub const fn len(&self) -> usize {
        self.len
    }

    /// Index strides `[1, nx, nx * ny]`.
    #[must_use]
    pub fn strides(&self) -> [usize; 3] {
        let [nx, ny, _] = self.n;
        // Both fit: their product with nz is `len`, which fits.
        let nx = to_usize(nx);
        [1, nx, nx.wrapping_mul(to_usize(ny))]
    }

    /// Whether `(x, y, z)` lies inside the raster.
    #[must_use]
    pub const fn contains(&self, v: [u32; 3]) -> bool {
        v[0] < self.n[0] && v[1] < self.n[1] && v[2] < self.n[2]
    }

    /// Linear index of voxel `(x, y, z)`: `x + nx * (y + ny * z)`, or `None`
    /// outside the raster.
    ///
    /// ```
    /// use rrt_core::raster::Extent;
    /// let e = Extent::new(4, 3, 2).unwrap();
    /// assert_eq!(e.index([1, 2, 1]), Some(1 + 4 * (2 + 3 * 1)));
    /// assert_eq!(e.index([4, 0, 0]), None);
    /// ```
    #[must_use]
    pub fn index(&self, v: [u32; 3]) -> Option<usize> {
        if !self.contains(v) {
            return None;
        }
        let [nx, ny, _] = self.n;
        // In range, so the result is below `len` and nothing overflows.
        let yz = to_usize(v[1]).wrapping_add(to_usize(ny).wrapping_mul(to_usize(v[2])));
        Some(to_usize(v[0]).wrapping_add(to_usize(nx).wrapping_mul(yz)))
    }

    /// Voxel coordinates of a linear index, or `None` past the end.
    ///
    /// ```
    /// use rrt_core::raster::Extent;
    /// let e = Extent::new(4, 3, 2).unwrap();
    /// assert_eq!(e.coord(e.index([3, 1, 1]).unwrap()), Some([3, 1, 1]));
    /// ```
    #[must_use]
    pub fn coord(&self, index: usize) -> Option<[u32; 3]> {
        if index >= self.len {
            return None;
        }
        let [nx, ny, _] = self.n;
        let nx = core::num::NonZeroUsize::new(to_usize(nx))?;
        let ny = core::num::NonZeroUsize::new(to_usize(ny))?;
        let x = index % nx;
        let yz = index / nx;
        let y = yz % ny;
        let z = yz / ny;
        Some([
            u32::try_from(x).ok()?,
            u32::try_from(y).ok()?,
            u32::try_from(z).ok()?,
        ])
    }
}

/// `u32 -> usize`; every supported target has `usize` of at least 32 bits.
#[inline]
pub(crate) const fn to_usize(v: u32) -> usize {
    // Lossless: rrt-core requires a target with usize >= 32 bits (checked below).
    v as usize
}

const _: () = assert!(
    usize::BITS >= 32,
    "rrt-core needs usize of at least 32 bits"
);

/// A read-only raster: an [`Extent`] over a caller-provided plane of one cell
/// per voxel.
///
/// ```
/// use rrt_core::raster::{cell, Extent, Raster};
/// let mut plane = [cell::EMPTY; 8];
/// plane[7] = cell::OPAQUE;
/// let r = Raster::new(Extent::cube(2).unwrap(), &plane).unwrap();
/// assert_eq!(r.cell([1, 1, 1]), Some(cell::OPAQUE));
/// ```
#[derive(Clone, Copy, Debug)]
pub struct Raster<'a> {
    extent: Extent,
    /// Invariant: `plane.len() == extent.len()`.
    plane: &'a [u8],
    /// Empty, or one stand-in cell per line (invariant: then
    /// `lines.len() == line_count(plane.len())`).
    lines: &'a [u8],
}

impl<'a> Raster<'a> {
    /// Wraps `plane` as the raster of `extent`.
    ///
    /// # Errors
    /// [`RasterError::PlaneLength`] unless `plane.len() == extent.len()`.
    pub fn new(extent: Extent, plane: &'a [u8]) -> Result<Self, RasterError> {
        if plane.len() != extent.len() {
            return Err(RasterError::PlaneLength {
                expected: extent.len(),
                found: plane.len(),
            });
        }
        Ok(Self {
            extent,
            plane,
            lines: &[],
        })
    }

    /// The same raster with a *line level*: one stand-in cell per line of
    /// [`LINE_CELLS`] consecutive cells of the plane, as
    /// [`crate::proximity::line_distances`] computes it. Skipping walks
    /// ([`crate::discrete_ray::DiscreteRay::walk_skipping`]) read a line's
    /// stand-in instead of the plane where it says the whole line is at
    /// distance 8 or more from every non-transparent voxel: the level is
    /// 1/64 of the plane and stays in cache where the plane does not.
    ///
    /// Through a line level, an [`cell::EMPTY`] plane cell reads as at
    /// distance [`crate::proximity::NEAR_LIMIT`], which is what the
    /// distance field ([`crate::proximity::distance_field`]) leaves empty.
    ///
    /// **Contract:** the plane holds its distance field, and every stand-in
    /// must be [`cell::EMPTY`] or a transparent, unflagged cell whose
    /// distance is at most that of every cell of its line. Otherwise
    /// skipping walks may report other hits than plain walks (never a
    /// panic).
    ///
    /// # Errors
    /// [`RasterError::LineLength`] unless `lines.len()` is
    /// [`line_count`]`(plane length)`.
    pub fn with_lines(self, lines: &'a [u8]) -> Result<Self, RasterError> {
        check_line_count(self.plane.len(), lines.len())?;
        Ok(Self { lines, ..self })
    }

    /// The raster's dimensions.
    #[must_use]
    pub const fn extent(&self) -> Extent {
        self.extent
    }

    /// The plane, one cell per voxel in linear order.
    #[must_use]
    pub const fn plane(&self) -> &'a [u8] {
        self.plane
    }

    /// The line level (empty when the raster has none).
    #[must_use]
    pub const fn lines(&self) -> &'a [u8] {
        self.lines
    }

    /// The cell of voxel `v`, or `None` outside the raster.
    #[must_use]
    pub fn cell(&self, v: [u32; 3]) -> Option<u8> {
        self.plane.get(self.extent.index(v)?).copied()
    }
}

/// Cells per line of the line level ([`Raster::with_lines`]): one 64-byte
/// cache line of the plane.
pub const LINE_CELLS: usize = 64;

/// Bits of [`LINE_CELLS`]: cell `i` lies in line `i >> LINE_BITS`.
pub const LINE_BITS: u32 = LINE_CELLS.trailing_zeros();

/// Number of lines of a plane of `len` cells: `ceil(len / LINE_CELLS)`.
///
/// ```
/// use rrt_core::raster::line_count;
/// assert_eq!((line_count(0), line_count(64), line_count(65)), (0, 1, 2));
/// ```
#[must_use]
pub const fn line_count(len: usize) -> usize {
    len.div_ceil(LINE_CELLS)
}

/// [`RasterError::LineLength`] unless `lines` is [`line_count`]`(plane)`.
pub(crate) const fn check_line_count(plane: usize, lines: usize) -> Result<(), RasterError> {
    let expected = line_count(plane);
    if lines == expected {
        Ok(())
    } else {
        Err(RasterError::LineLength {
            expected,
            found: lines,
        })
    }
}

/// A writable raster, used by voxelizers and the proximity pass.
#[derive(Debug)]
pub struct RasterMut<'a> {
    extent: Extent,
    /// Invariant: `plane.len() == extent.len()`.
    plane: &'a mut [u8],
}

impl<'a> RasterMut<'a> {
    /// Wraps `plane` as the writable raster of `extent`.
    ///
    /// # Errors
    /// [`RasterError::PlaneLength`] unless `plane.len() == extent.len()`.
    pub fn new(extent: Extent, plane: &'a mut [u8]) -> Result<Self, RasterError> {
        if plane.len() != extent.len() {
            return Err(RasterError::PlaneLength {
                expected: extent.len(),
                found: plane.len(),
            });
        }
        Ok(Self { extent, plane })
    }

    /// The raster's dimensions.
    #[must_use]
    pub const fn extent(&self) -> Extent {
        self.extent
    }

    /// A read-only view.
    #[must_use]
    pub fn as_raster(&self) -> Raster<'_> {
        Raster {
            extent: self.extent,
            plane: self.plane,
            lines: &[],
        }
    }

    /// The plane, mutably.
    pub fn plane_mut(&mut self) -> &mut [u8] {
        self.plane
    }

    /// The cell of voxel `v`, or `None` outside the raster.
    #[must_use]
    pub fn cell(&self, v: [u32; 3]) -> Option<u8> {
        self.plane.get(self.extent.index(v)?).copied()
    }

    /// Mutable access to the cell of voxel `v`, or `None` outside the raster.
    pub fn cell_mut(&mut self, v: [u32; 3]) -> Option<&mut u8> {
        let i = self.extent.index(v)?;
        self.plane.get_mut(i)
    }
}
