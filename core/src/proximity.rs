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
    for (out, line) in lines.iter_mut().zip(plane.chunks(LINE_CELLS)) {
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
    Ok(())
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
/// The exact two-pass sequential chamfer transform with the 3×3×3 mask and
/// unit weights (exact for the chessboard metric), in place on the plane:
/// each pass reads, per row, four neighbouring rows of the previous row and
/// slice elementwise, then runs once along the row. Linear in the number of
/// voxels, no scratch memory beyond a small stack buffer.
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
    // Work on plain distances (opaque ⇔ 0) and rebuild the cells at the end.
    for c in plane.iter_mut() {
        *c = if *c & cell::OPAQUE != 0 {
            0
        } else {
            DISTANCE_LIMIT
        };
    }
    chamfer_pass(plane, nx, ny, nz, slice, false);
    chamfer_pass(plane, nx, ny, nz, slice, true);
    for c in plane.iter_mut() {
        let d = *c;
        let opaque = if d == 0 { cell::OPAQUE } else { 0 };
        let flag = if d <= 1 { cell::PROXIMITY } else { 0 };
        *c = opaque | flag | (d << cell::DISTANCE_SHIFT);
    }
}

/// Row chunk handled at once by [`chamfer_pass`] (stack buffer size).
const CHUNK: usize = 256;

/// One pass of the chamfer transform. Forward (`backward == false`): rows in
/// increasing (z, y), x increasing; the causal neighbours of a voxel are the
/// 3×3 block of the previous slice, the 3 voxels of the previous row and the
/// voxel before it in its row. Backward: the mirror image.
fn chamfer_pass(plane: &mut [u8], nx: usize, ny: usize, nz: usize, slice: usize, backward: bool) {
    let rows = ny.saturating_mul(nz);
    let Some(ny_nz) = core::num::NonZeroUsize::new(ny) else {
        return;
    };
    for i in 0..rows {
        let r = if backward {
            rows.wrapping_sub(1).wrapping_sub(i)
        } else {
            i
        };
        let (y, z) = (r % ny_nz, r / ny_nz);
        let start = r.wrapping_mul(nx);
        // The row, and the (read-only) part of the plane holding the
        // already-finished neighbour rows.
        let (done, row) = if backward {
            let Some((upto, after)) = plane.split_at_mut_checked(start.wrapping_add(nx)) else {
                return;
            };
            (after as &[u8], upto.get_mut(start..).unwrap_or(&mut []))
        } else {
            let Some((before, rest)) = plane.split_at_mut_checked(start) else {
                return;
            };
            (before as &[u8], rest.get_mut(..nx).unwrap_or(&mut []))
        };
        // Neighbour rows as offsets into `done`: previous row in this slice,
        // and the three rows around y in the previous slice.
        let base = if backward { start.wrapping_add(nx) } else { 0 };
        let row_at = |yy: usize, zz: usize| -> Option<&[u8]> {
            let s = zz.checked_mul(slice)?.checked_add(yy.checked_mul(nx)?)?;
            done.get(s.checked_sub(base)?..)?.get(..nx)
        };
        let (y_prev, z_prev) = if backward {
            (
                y.checked_add(1).filter(|&v| v < ny),
                z.checked_add(1).filter(|&v| v < nz),
            )
        } else {
            (y.checked_sub(1), z.checked_sub(1))
        };
        let mut neighbours: [Option<&[u8]>; 4] = [None; 4];
        neighbours[0] = y_prev.and_then(|yy| row_at(yy, z));
        if let Some(zz) = z_prev {
            neighbours[1] = y.checked_sub(1).and_then(|yy| row_at(yy, zz));
            neighbours[2] = row_at(y, zz);
            neighbours[3] = y
                .checked_add(1)
                .filter(|&v| v < ny)
                .and_then(|yy| row_at(yy, zz));
        }
        relax_row(row, &neighbours, backward);
    }
}

/// `row[x] = min(row[x], 1 + min over the neighbour rows of their entries
/// at x−1, x, x+1)`, then one sequential sweep along the row.
fn relax_row(row: &mut [u8], neighbours: &[Option<&[u8]>; 4], backward: bool) {
    let n = row.len();
    let mut start = 0usize;
    while start < n {
        let end = start.saturating_add(CHUNK).min(n);
        // t[j] = min of the neighbour rows at x = start − 1 + j.
        let mut t = [DISTANCE_LIMIT; CHUNK + 2];
        let lo = start.saturating_sub(1);
        let hi = end.saturating_add(1).min(n);
        let off = lo.wrapping_add(1).wrapping_sub(start); // 0 when start > 0, 1 at the row's start
        for nb in neighbours.iter().flatten() {
            if let (Some(src), Some(dst)) = (
                nb.get(lo..hi),
                t.get_mut(off..off.wrapping_add(hi.wrapping_sub(lo))),
            ) {
                for (d, &s) in dst.iter_mut().zip(src) {
                    *d = (*d).min(s);
                }
            }
        }
        if let Some(seg) = row.get_mut(start..end) {
            for (j, c) in seg.iter_mut().enumerate() {
                let a = t.get(j).copied().unwrap_or(DISTANCE_LIMIT);
                let b = t.get(j.wrapping_add(1)).copied().unwrap_or(DISTANCE_LIMIT);
                let c2 = t.get(j.wrapping_add(2)).copied().unwrap_or(DISTANCE_LIMIT);
                let m = a.min(b).min(c2).saturating_add(1);
                *c = (*c).min(m);
            }
        }
        start = end;
    }
    // Along the row: the neighbour before (after, going backward).
    let mut prev = DISTANCE_LIMIT;
    let mut sweep = |c: &mut u8| {
        let v = (*c).min(prev.saturating_add(1)).min(DISTANCE_LIMIT);
        *c = v;
        prev = v;
    };
    if backward {
        row.iter_mut().rev().for_each(&mut sweep);
    } else {
        row.iter_mut().for_each(&mut sweep);
    }
}

#[cfg(test)]
mod tests {
    use std::vec;
    use std::vec::Vec;

    use super::*;
    use crate::raster::Extent;
    use crate::raster::line_count;
    use crate::testkit::Rng;

    /// Chessboard distance to the nearest opaque voxel, by brute force.
    fn brute(e: Extent, opaque: &[[u32; 3]]) -> Vec<u8> {
        let [nx, ny, nz] = e.dims();
        let mut out = vec![DISTANCE_LIMIT; e.len()];
        for z in 0..nz {
            for y in 0..ny {
                for x in 0..nx {
                    let d = opaque
                        .iter()
                        .map(|o| o[0].abs_diff(x).max(o[1].abs_diff(y)).max(o[2].abs_diff(z)))
                        .min()
                        .unwrap_or(u32::MAX);
                    out[e.index([x, y, z]).unwrap()] =
                        u8::try_from(d.min(u32::from(DISTANCE_LIMIT))).unwrap();
                }
            }
        }
        out
    }

    #[test]
    fn distance_field_is_the_exact_chessboard_distance() {
        let mut rng = Rng(0x1234_5678_9abc_def0u64);
        let mut next = |m: u32| rng.below_u32(m);
        for case in 0..60 {
            let dims = [1 + next(20), 1 + next(20), 1 + next(20)];
            let e = Extent::new(dims[0], dims[1], dims[2]).unwrap();
            let count = next(6);
            let opaque: Vec<[u32; 3]> = (0..count)
                .map(|_| [next(dims[0]), next(dims[1]), next(dims[2])])
                .collect();
            let mut plane = vec![cell::EMPTY; e.len()];
            for o in &opaque {
                plane[e.index(*o).unwrap()] = cell::OPAQUE;
            }
            let mut flags = plane.clone();
            flag_neighbourhood(&mut RasterMut::new(e, &mut flags).unwrap());
            distance_field(&mut RasterMut::new(e, &mut plane).unwrap());
            let want = brute(e, &opaque);
            for (i, (&c, &w)) in plane.iter().zip(&want).enumerate() {
                assert_eq!(
                    distance(c),
                    w,
                    "case {case} dims {dims:?} voxel {:?}",
                    e.coord(i)
                );
                assert_eq!(c & cell::OPAQUE != 0, w == 0, "case {case}");
                // The flag is exactly what flag_neighbourhood sets.
                assert_eq!(
                    c & cell::PROXIMITY,
                    flags[i] & cell::PROXIMITY,
                    "case {case}"
                );
            }
            // The line level: each line's smallest distance when that is at
            // least 2, else EMPTY.
            let mut lines = vec![0xffu8; line_count(e.len())];
            line_distances(
                &RasterMut::new(e, &mut plane).unwrap().as_raster(),
                &mut lines,
            )
            .unwrap();
            for (l, &got) in lines.iter().enumerate() {
                let m = want
                    .iter()
                    .skip(l * LINE_CELLS)
                    .take(LINE_CELLS)
                    .min()
                    .copied()
                    .unwrap();
                let expect = if m >= 2 {
                    m << cell::DISTANCE_SHIFT
                } else {
                    cell::EMPTY
                };
                assert_eq!(got, expect, "case {case} line {l}");
            }
        }
    }

    #[test]
    fn distances_saturate_at_the_limit() {
        let e = Extent::new(150, 3, 2).unwrap();
        let mut plane = vec![cell::EMPTY; e.len()];
        plane[e.index([0, 1, 1]).unwrap()] = cell::OPAQUE;
        distance_field(&mut RasterMut::new(e, &mut plane).unwrap());
        let at = |x| distance(plane[e.index([x, 0, 0]).unwrap()]);
        assert_eq!(
            (at(1), at(62), at(63), at(64), at(149)),
            (1, 62, 63, 63, 63)
        );
        let mut empty = vec![cell::EMPTY; e.len()];
        distance_field(&mut RasterMut::new(e, &mut empty).unwrap());
        assert!(
            empty
                .iter()
                .all(|&c| distance(c) == DISTANCE_LIMIT && c & cell::PROXIMITY == 0)
        );
    }
}
