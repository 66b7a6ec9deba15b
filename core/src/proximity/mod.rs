//! Proximity flags: the voxels around every non-transparent voxel, where
//! adaptive discrete rays slow down to 6-connected steps.
//!
//! [`flag_neighbourhood`] sets [`cell::PROXIMITY`] on every voxel within
//! chessboard distance 1 of a non-transparent ([`cell::OPAQUE`]) voxel: its
//! whole 26-neighbourhood and the voxel itself. With these flags an
//! [`Adaptive`](crate::discrete_ray::Connectivity::Adaptive) ray hits exactly
//! the voxel a 6-connected ray hits (see [`crate::discrete_ray`]).
//!
//! The pass is a separable dilation: two in-place sweeps along each axis,
//! each reading only bytes the same sweep has not yet written, so it needs no
//! scratch memory and touches each cell a constant number of times.
//!
//! [`distance_field`] generalizes the flag to a saturating chessboard
//! distance (Cohen & Sheffer's proximity clouds) for empty-space skipping,
//! and [`line_distances`] condenses it into the raster's line level: one
//! stand-in cell per 64 plane cells, which skipping walks read instead of
//! the plane far from surfaces.

pub mod field;

use crate::error::RasterError;
use crate::raster::{LINE_CELLS, Raster, RasterMut, cell, check_line_count, to_usize};

/// Sets [`cell::PROXIMITY`] on every voxel within chessboard distance 1 of an
/// [`cell::OPAQUE`] voxel, and clears it everywhere else.
///
/// ```
/// use rrt_core::proximity::flag_neighbourhood;
/// use rrt_core::raster::{cell, Extent, RasterMut};
/// let e = Extent::cube(5).unwrap();
/// let mut plane = vec![cell::EMPTY; e.len()];
/// plane[e.index([2, 2, 2]).unwrap()] = cell::OPAQUE;
/// let mut r = RasterMut::new(e, &mut plane).unwrap();
/// flag_neighbourhood(&mut r);
/// assert_ne!(r.cell([1, 3, 1]).unwrap() & cell::PROXIMITY, 0);
/// assert_eq!(r.cell([0, 2, 2]).unwrap() & cell::PROXIMITY, 0);
/// ```
pub fn flag_neighbourhood(raster: &mut RasterMut<'_>) {
    let Some(([nx, _, _], slice)) = layout(raster) else {
        return;
    };
    let plane = raster.plane_mut();
    for c in plane.iter_mut() {
        *c = (*c & !cell::PROXIMITY)
            | if *c & cell::OPAQUE != 0 {
                cell::PROXIMITY
            } else {
                0
            };
    }
    // Along x: within each row of nx cells.
    for row in plane.chunks_exact_mut(nx) {
        dilate_lines(row, 1);
    }
    // Along y: rows of nx cells within each z-slice.
    for s in plane.chunks_exact_mut(slice) {
        dilate_lines(s, nx);
    }
    // Along z: whole slices.
    dilate_lines(plane, slice);
}

/// The raster's dimensions and the cells of one z-slice; `None` for a
/// slice of no cells. Both dimensions are non-zero and their product fits
/// (it divides the plane length); checked anyway so that no chunking can be
/// asked for size 0.
fn layout(raster: &RasterMut<'_>) -> Option<([usize; 3], usize)> {
    let dims = raster.extent().dims().map(to_usize);
    let [nx, ny, _] = dims;
    let slice = nx.checked_mul(ny).filter(|&s| s != 0 && nx != 0)?;
    Some((dims, slice))
}

/// Dilates the PROXIMITY bit by one unit along an axis whose consecutive
/// elements are `width` cells apart, treating `data` as `len / width` lines.
fn dilate_lines(data: &mut [u8], width: usize) {
    if width == 0 || data.len() <= width {
        return;
    }
    // Towards +: line i |= line i-1, sweeping down so i-1 is still original.
    let mut end = data.len();
    while let Some(start) = end.checked_sub(width) {
        let Some(prev_start) = start.checked_sub(width) else {
            break;
        };
        if let Some((lo, hi)) = data.split_at_mut_checked(start) {
            let prev = lo.get(prev_start..).unwrap_or(&[]);
            let cur = hi.get_mut(..width).unwrap_or(&mut []);
            or_proximity(cur, prev);
        }
        end = start;
    }
    // Towards −: line i |= line i+1, sweeping up so i+1 is not yet rewritten
    // by this sweep (it already holds the + dilation, which is what we want).
    let mut start = 0usize;
    while let Some(next) = start.checked_add(width) {
        if next >= data.len() {
            break;
        }
        if let Some((lo, hi)) = data.split_at_mut_checked(next) {
            let cur = lo.get_mut(start..).unwrap_or(&mut []);
            let following = hi.get(..width).unwrap_or(&[]);
            or_proximity(cur, following);
        }
        start = next;
    }
}

fn or_proximity(dst: &mut [u8], src: &[u8]) {
    for (d, s) in dst.iter_mut().zip(src) {
        *d |= s & cell::PROXIMITY;
    }
}

/// Largest proximity distance the plane stores (6 bits); larger distances
/// saturate to it.
pub const DISTANCE_LIMIT: u8 = cell::DISTANCE_MASK;

/// The proximity distance stored in a cell: a lower bound on the chessboard
/// distance from the voxel to the nearest [`cell::OPAQUE`] voxel (0 = no
/// information). Always 0 for an opaque cell, whose distance bits hold its
/// record's rank hint instead ([`crate::store::rank_hint`]).
///
/// ```
/// use rrt_core::proximity::distance;
/// use rrt_core::raster::cell;
/// assert_eq!(distance(5 << 2), 5);
/// assert_eq!(distance((5 << 2) | cell::OPAQUE), 0);
/// ```
#[must_use]
pub const fn distance(c: u8) -> u8 {
    if c & cell::OPAQUE != 0 {
        0
    } else {
        (c >> cell::DISTANCE_SHIFT) & cell::DISTANCE_MASK
    }
}

/// The cell `c` as it reads in the raster *dilated by one voxel*, where a
/// voxel is non-transparent when a non-transparent voxel lies within
/// chessboard distance 1 of it (`c` has [`cell::PROXIMITY`] or
/// [`cell::OPAQUE`]): then [`cell::OPAQUE`] and [`cell::PROXIMITY`];
/// otherwise the distance to the dilated voxels is the cell's distance
/// less one, so a distance of 2 gives [`cell::PROXIMITY`] and a larger one
/// that distance less one. A cell with no distance (0) reads as flagged,
/// never skipped. For a plane with its distance field, or any line
/// stand-in, this is the dilated raster's cell exactly (or with a smaller
/// distance where the stored one saturated), so walks over the view keep
/// the guarantees they have over a plane
/// ([`DiscreteRay::walk_dilated`](crate::discrete_ray::DiscreteRay::walk_dilated)).
///
/// ```
/// use rrt_core::proximity::{dilated, distance};
/// use rrt_core::raster::cell;
/// assert_eq!(dilated(cell::PROXIMITY | (1 << 2)), cell::OPAQUE | cell::PROXIMITY);
/// assert_eq!(dilated(2 << 2), cell::PROXIMITY | (1 << 2));
/// assert_eq!(distance(dilated(9 << 2)), 8);
/// ```
#[must_use]
pub const fn dilated(c: u8) -> u8 {
    if c & (cell::OPAQUE | cell::PROXIMITY) != 0 {
        return cell::OPAQUE | cell::PROXIMITY;
    }
    let d = (c >> cell::DISTANCE_SHIFT) & cell::DISTANCE_MASK;
    if d <= 2 {
        cell::PROXIMITY | (d.saturating_sub(1) << cell::DISTANCE_SHIFT)
    } else {
        d.wrapping_sub(1) << cell::DISTANCE_SHIFT
    }
}

/// Computes the raster's line level ([`Raster::with_lines`]): per line of
/// [`LINE_CELLS`] consecutive plane cells, a stand-in cell carrying the
/// smallest proximity distance of the line's cells when that is at least 2
/// and no cell of the line is opaque or flagged, else [`cell::EMPTY`] (read
/// the plane). O(plane), after [`distance_field`].
///
/// ```
/// use rrt_core::proximity::{distance, distance_field, line_distances};
/// use rrt_core::raster::{cell, line_count, Extent, RasterMut};
/// let e = Extent::new(128, 4, 4).unwrap();
/// let mut plane = vec![cell::EMPTY; e.len()];
/// plane[e.index([100, 0, 0]).unwrap()] = cell::OPAQUE;
/// let mut r = RasterMut::new(e, &mut plane).unwrap();
/// distance_field(&mut r);
/// let mut lines = vec![0u8; line_count(e.len())];
/// line_distances(&r.as_raster(), &mut lines).unwrap();
/// let line = |v| lines[e.index(v).unwrap() / 64];
/// // x = 64..128 of row (y, z) = (0, 3): 3 to 36 voxels from the opaque one.
/// assert_eq!(distance(line([64, 0, 3])), 3);
/// // x = 0..64 of that row: 37 voxels and more.
/// assert_eq!(distance(line([0, 0, 3])), 37);
/// // The opaque voxel's own line: read the plane.
/// assert_eq!(line([64, 0, 0]), cell::EMPTY);
/// ```
///
/// # Errors
/// [`RasterError::LineLength`] unless `lines.len()` is
/// [`line_count`](crate::raster::line_count)`(plane length)`.
pub fn line_distances(raster: &Raster<'_>, lines: &mut [u8]) -> Result<(), RasterError> {
    let plane = raster.plane();
    check_line_count(plane.len(), lines.len())?;
    line_stand_ins(plane, lines);
    Ok(())
}

/// The line level of a part of a plane: `cells` are consecutive cells of
/// a plane with its distance field, starting at a line boundary, and
/// `lines` gets one stand-in per [`LINE_CELLS`] of them (the last line may
/// be shorter), as [`line_distances`] computes them; stand-ins beyond the
/// cells are left alone. A caller with threads hands out aligned parts.
pub fn line_stand_ins(cells: &[u8], lines: &mut [u8]) {
    for (out, line) in lines.iter_mut().zip(cells.chunks(LINE_CELLS)) {
        // Without OPAQUE or PROXIMITY in any cell, every cell is its distance
        // bits alone, and the smallest cell holds the smallest distance.
        let any = line.iter().fold(0u8, |a, &c| a | c);
        let least = line.iter().fold(u8::MAX, |a, &c| a.min(c));
        *out = if any & (cell::OPAQUE | cell::PROXIMITY) != 0 || distance(least) < 2 {
            cell::EMPTY
        } else {
            least
        };
    }
}

/// Computes the proximity distance field: every cell gets the chessboard
/// (L∞) distance from its voxel to the nearest [`cell::OPAQUE`] voxel,
/// saturated at [`DISTANCE_LIMIT`], in its distance bits, and
/// [`cell::PROXIMITY`] where that distance is at most 1 (exactly what
/// [`flag_neighbourhood`] sets). A raster without opaque voxels gets the
/// limit everywhere. Opaque cells get distance bits 0, which clears their
/// rank hints: write them afterwards ([`crate::store::write_rank_hints`]).
///
/// Cohen & Sheffer's proximity clouds, generalizing the paper's one-bit flag:
/// a 26-connected ray at a voxel of distance `d` can take `d − 1` steps at
/// once without passing a non-transparent or flagged voxel (see
/// [`crate::discrete_ray::DiscreteRay::first_hit_skipping`]).
///
/// Computed by slices ([`field`]: the distances within each slice, then up
/// and down the slices), in place, with no scratch memory beyond a small
/// stack buffer. Every cell is written once; beyond that the work follows
/// the opaque voxels: rows and slices with no opaque voxel within
/// [`field::FIELD_REACH`] are only filled with the limit. A caller with
/// threads runs the same steps on its own ([`field`]), with the same
/// result.
///
/// ```
/// use rrt_core::proximity::{distance, distance_field};
/// use rrt_core::raster::{cell, Extent, RasterMut};
/// let e = Extent::cube(9).unwrap();
/// let mut plane = vec![cell::EMPTY; e.len()];
/// plane[e.index([4, 4, 4]).unwrap()] = cell::OPAQUE;
/// let mut r = RasterMut::new(e, &mut plane).unwrap();
/// distance_field(&mut r);
/// assert_eq!(distance(r.cell([0, 2, 7]).unwrap()), 4);
/// assert_ne!(r.cell([5, 3, 4]).unwrap() & cell::PROXIMITY, 0);
/// ```
pub fn distance_field(raster: &mut RasterMut<'_>) {
    let Some(([nx, ny, nz], slice)) = layout(raster) else {
        return;
    };
    let plane = raster.plane_mut();
    // Step 1 per slice, and step 2 as soon as the slice below is done, over
    // the box the opaque voxels below reach (`seen`: those so far).
    let mut seen = field::Area::EMPTY;
    let mut last: Option<usize> = None;
    for z in 0..nz {
        let start = z.wrapping_mul(slice);
        let Some((done, rest)) = plane.split_at_mut_checked(start) else {
            return;
        };
        let Some(cur) = rest.get_mut(..slice) else {
            return;
        };
        let opaque = field::slice_distances(cur, nx);
        if let Some(l) = last
            && field::reaches(z.wrapping_sub(l))
        {
            let below = done.get(start.wrapping_sub(slice)..).unwrap_or(&[]);
            field::relax_rows(cur, below, nx, 0, seen.reached(nx, ny));
        }
        if !opaque.is_empty() {
            seen = seen.union(opaque);
            last = Some(z);
        }
    }
    // Step 3, down the slices.
    let area = seen.reached(nx, ny);
    let mut next: Option<usize> = None;
    for z in (0..nz).rev() {
        let start = z.wrapping_mul(slice);
        let end = start.wrapping_add(slice);
        let Some((head, above)) = plane.split_at_mut_checked(end) else {
            return;
        };
        let Some(cur) = head.get_mut(start..) else {
            return;
        };
        if let Some(n) = next
            && field::reaches(n.wrapping_sub(z))
        {
            field::relax_rows(cur, above.get(..slice).unwrap_or(&[]), nx, 0, area);
        }
        if cur.contains(&field::OPAQUE_CELL) {
            next = Some(z);
        }
    }
}

#[cfg(test)]
mod tests;
