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
//! [`distance_field`] generalizes the flag to a chessboard distance
//! (Cohen & Sheffer's proximity clouds) for empty-space skipping, stored
//! near surfaces only (below [`NEAR_LIMIT`]), so that the plane's memory
//! far from them is never written. Farther jumps come from the coarse
//! level ([`coarse_level`]: the same field over bricks of [`COARSE_EDGE`]³
//! voxels), and [`line_distances`] condenses both into the raster's line
//! level: one stand-in cell per 64 plane cells, which skipping walks read
//! instead of the plane far from surfaces.

pub mod field;

use crate::error::RasterError;
use crate::raster::{Extent, LINE_CELLS, Raster, RasterMut, cell, check_line_count, to_usize};

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

/// Distance codes below this are the distance itself; from it on, a code
/// `k` stands for `EXACT_CODES + CODE_STEP·(k − EXACT_CODES)` ([`distance`]).
const EXACT_CODES: u8 = 32;

/// Voxels between the distances of consecutive codes from [`EXACT_CODES`] on.
const CODE_STEP: u8 = 4;

/// Largest proximity distance a cell can hold: that of the largest code of
/// its 6 distance bits ([`distance`]). Line stand-ins saturate to it.
pub const DISTANCE_LIMIT: u8 = EXACT_CODES + CODE_STEP * (cell::DISTANCE_MASK - EXACT_CODES);

/// The transparent, unflagged cell holding the largest distance a cell
/// can hold that is at most `d` ([`distance`] reads it back): `d` itself
/// below 32, every fourth distance from there up to [`DISTANCE_LIMIT`].
/// The distances the distance field stores ([`NEAR_LIMIT`] and below) are
/// all exact.
///
/// ```
/// use rrt_core::proximity::{distance, distance_cell, DISTANCE_LIMIT};
/// assert_eq!(distance(distance_cell(9)), 9);
/// assert_eq!(distance(distance_cell(35)), 32);
/// assert_eq!(distance(distance_cell(36)), 36);
/// assert_eq!(distance(distance_cell(255)), DISTANCE_LIMIT);
/// ```
#[must_use]
pub const fn distance_cell(d: u8) -> u8 {
    let code = if d < EXACT_CODES {
        d
    } else {
        // d − 32 ≤ 223: the sum stays below 256.
        let k = (d.wrapping_sub(EXACT_CODES) / CODE_STEP).wrapping_add(EXACT_CODES);
        if k > cell::DISTANCE_MASK {
            cell::DISTANCE_MASK
        } else {
            k
        }
    };
    code << cell::DISTANCE_SHIFT
}

/// The distance field ([`distance_field`]) stores the distances below
/// this in the plane; a transparent cell at this distance or more from
/// every opaque voxel is left [`cell::EMPTY`]. A skipping walk through a
/// line level reads such a cell as this distance
/// ([`Raster::with_lines`]).
pub const NEAR_LIMIT: u8 = 16;

/// The proximity distance stored in a cell: a lower bound on the chessboard
/// distance from the voxel to the nearest [`cell::OPAQUE`] voxel (0 = no
/// information; in a plane with its distance field, an [`cell::EMPTY`]
/// cell is at [`NEAR_LIMIT`] or more). Always 0 for an opaque cell, whose
/// distance bits hold its record's rank hint instead
/// ([`crate::store::rank_hint`]).
///
/// The 6 distance bits hold a code: codes below 32 are the distance
/// itself, a larger code `k` stands for `32 + 4·(k − 32)`, up to
/// [`DISTANCE_LIMIT`] (156), so that a line stand-in far from every
/// surface allows jumps past the 63 voxels 6 bits could count
/// ([`distance_cell`] writes a distance).
///
/// ```
/// use rrt_core::proximity::distance;
/// use rrt_core::raster::cell;
/// assert_eq!(distance(5 << 2), 5);
/// assert_eq!(distance(33 << 2), 36);
/// assert_eq!(distance((5 << 2) | cell::OPAQUE), 0);
/// ```
#[must_use]
pub const fn distance(c: u8) -> u8 {
    if c & cell::OPAQUE != 0 {
        return 0;
    }
    let code = (c >> cell::DISTANCE_SHIFT) & cell::DISTANCE_MASK;
    if code < EXACT_CODES {
        code
    } else {
        // code ≤ 63: at most 156.
        CODE_STEP
            .wrapping_mul(code.wrapping_sub(EXACT_CODES))
            .wrapping_add(EXACT_CODES)
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
/// distance where the stored one is a bound: a stand-in, or an empty cell
/// read through the line level), so walks over the view keep the
/// guarantees they have over a plane
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
    let d = distance(c);
    if d <= 2 {
        cell::PROXIMITY | (d.saturating_sub(1) << cell::DISTANCE_SHIFT)
    } else {
        distance_cell(d.wrapping_sub(1))
    }
}

/// Edge of the coarse level's bricks, in voxels ([`coarse_level`]).
pub const COARSE_EDGE: u32 = 8;

/// Cells of the coarse level of a raster of `dims` voxels (saturating):
/// the length of the `bricks` buffer [`line_distances`] takes, as a
/// constant for static storage.
///
/// ```
/// use rrt_core::proximity::coarse_cells;
/// assert_eq!(coarse_cells([41, 35, 27]), 6 * 5 * 4);
/// ```
#[must_use]
pub const fn coarse_cells(dims: [u32; 3]) -> usize {
    let [x, y, z] = dims;
    (x.div_ceil(COARSE_EDGE) as usize)
        .saturating_mul(y.div_ceil(COARSE_EDGE) as usize)
        .saturating_mul(z.div_ceil(COARSE_EDGE) as usize)
}

/// The coarse level's extent: `ceil(n / 8)` bricks per axis (never
/// empty).
///
/// # Errors
/// None for a valid extent (kept fallible for the checked constructor).
pub fn coarse_extent(extent: Extent) -> Result<Extent, RasterError> {
    let [x, y, z] = extent.dims().map(|n| n.div_ceil(COARSE_EDGE));
    Extent::new(x, y, z)
}

/// Computes the raster's coarse level: per brick of [`COARSE_EDGE`]³
/// voxels (x fastest, as the plane), a lower bound on the chessboard
/// distance from each of its voxels to an opaque voxel, at most
/// [`DISTANCE_LIMIT`]: 0 where the brick holds one, `8·(k − 1) + 1` at
/// brick distance `k ≥ 1` from the nearest brick that does (the marks'
/// distance field over the bricks, [`coarse_field`]). [`line_distances`]
/// turns it into jumps.
///
/// ```
/// use rrt_core::proximity::{coarse_extent, coarse_level};
/// use rrt_core::raster::{cell, Extent, Raster};
/// let e = Extent::new(64, 8, 8).unwrap();
/// let mut plane = vec![cell::EMPTY; e.len()];
/// plane[e.index([3, 0, 0]).unwrap()] = cell::OPAQUE;
/// let mut bricks = vec![0u8; coarse_extent(e).unwrap().len()];
/// coarse_level(&Raster::new(e, &plane).unwrap(), &mut bricks).unwrap();
/// // Bricks 0..8 along x: the opaque voxel's, then 1, 9, 17, … voxels away.
/// assert_eq!(bricks, [0, 1, 9, 17, 25, 33, 41, 49]);
/// ```
///
/// # Errors
/// [`RasterError::LineLength`] unless `bricks.len()` is the coarse
/// extent's length.
pub fn coarse_level(raster: &Raster<'_>, bricks: &mut [u8]) -> Result<(), RasterError> {
    let extent = raster.extent();
    let coarse = coarse_extent(extent)?;
    check_len(coarse.len(), bricks.len())?;
    bricks.fill(cell::EMPTY);
    let [nx, ny, _] = extent.dims().map(to_usize);
    let [cx, cy, _] = coarse.dims().map(to_usize);
    let edge = to_usize(COARSE_EDGE);
    for (row, cells) in raster.plane().chunks(nx.max(1)).enumerate() {
        let base = brick_row(row, [ny, cx, cy]);
        for (x, &c) in cells.iter().enumerate() {
            if c & cell::OPAQUE != 0
                && let Some(b) = bricks.get_mut(base.wrapping_add(div(x, edge)))
            {
                *b = cell::OPAQUE;
            }
        }
    }
    coarse_field(extent, bricks)
}

/// `a / b`, 0 for `b = 0`.
#[inline]
const fn div(a: usize, b: usize) -> usize {
    match a.checked_div(b) {
        Some(q) => q,
        None => 0,
    }
}

/// The index in the coarse level of the first brick of plane row `row`
/// (rows of `ny` per slice; `cx × cy` bricks per coarse slice).
#[inline]
const fn brick_row(row: usize, [ny, cx, cy]: [usize; 3]) -> usize {
    let edge = COARSE_EDGE as usize;
    let (y, z) = (
        match row.checked_rem(ny) {
            Some(r) => r,
            None => 0,
        },
        div(row, ny),
    );
    div(z, edge)
        .wrapping_mul(cy)
        .wrapping_add(div(y, edge))
        .wrapping_mul(cx)
}

/// The coarse level from its marks: `bricks` holds [`cell::OPAQUE`] in the
/// bricks of `extent` that hold an opaque voxel (other bits ignored), and
/// gets the coarse level ([`coarse_level`]): their distance field
/// ([`distance_field`] over the bricks) made bounds ([`coarse_bounds`]).
/// A caller that knows the occupied bricks (a record store's directory)
/// marks them and calls this.
///
/// # Errors
/// [`RasterError::LineLength`] unless `bricks.len()` is the coarse
/// extent's length.
pub fn coarse_field(extent: Extent, bricks: &mut [u8]) -> Result<(), RasterError> {
    let coarse = coarse_extent(extent)?;
    check_len(coarse.len(), bricks.len())?;
    distance_field(&mut RasterMut::new(coarse, bricks)?);
    coarse_bounds(bricks);
    Ok(())
}

/// Turns the bricks' distance field (cells of [`distance_field`] over the
/// bricks) into the coarse level's bounds in voxels ([`coarse_level`]), in
/// place. A caller computing the field its own way (on threads) ends with
/// this.
pub fn coarse_bounds(bricks: &mut [u8]) {
    for b in bricks {
        *b = brick_bound(*b);
    }
}

/// [`RasterError::LineLength`] unless `found == expected`.
const fn check_len(expected: usize, found: usize) -> Result<(), RasterError> {
    if expected == found {
        Ok(())
    } else {
        Err(RasterError::LineLength { expected, found })
    }
}

/// The least distance from a voxel of a brick whose coarse cell is `c` to
/// an opaque voxel: 0 in an occupied brick, `8·(k − 1) + 1` at coarse
/// distance `k` (`k` from [`NEAR_LIMIT`] on for an [`cell::EMPTY`] cell),
/// at most [`DISTANCE_LIMIT`].
#[inline]
fn brick_bound(c: u8) -> u8 {
    let k = if c & cell::OPAQUE != 0 {
        0
    } else if c == cell::EMPTY {
        NEAR_LIMIT
    } else {
        distance(c)
    };
    if k == 0 {
        return 0;
    }
    let d = COARSE_EDGE
        .saturating_mul(u32::from(k).saturating_sub(1))
        .saturating_add(1);
    u8::try_from(d.min(u32::from(DISTANCE_LIMIT))).unwrap_or(DISTANCE_LIMIT)
}

/// Computes the raster's coarse level into `bricks` ([`coarse_level`])
/// and its line level ([`Raster::with_lines`]) from a plane with its
/// distance field ([`distance_field`]): per line of [`LINE_CELLS`] consecutive plane cells,
/// a stand-in cell with no flags carrying a lower bound on the distance of
/// every cell of the line, at least 2, or [`cell::EMPTY`] (read the plane)
/// when a cell of the line is opaque or flagged. The bound is the larger
/// of the coarse level's (the least over the bricks the line crosses) and
/// the line's least cell, an [`cell::EMPTY`] cell counting as
/// [`NEAR_LIMIT`]; a line the coarse level puts [`NEAR_LIMIT`] or more
/// from every opaque voxel is decided without reading its cells.
///
/// **Contract:** the plane holds its distance field; a skipping walk
/// through the line level relies on it (it reads an [`cell::EMPTY`] plane
/// cell as [`NEAR_LIMIT`]).
///
/// ```
/// use rrt_core::proximity::{coarse_extent, distance, distance_field, line_distances};
/// use rrt_core::raster::{cell, line_count, Extent, RasterMut};
/// let e = Extent::new(256, 4, 4).unwrap();
/// let mut plane = vec![cell::EMPTY; e.len()];
/// plane[e.index([200, 0, 0]).unwrap()] = cell::OPAQUE;
/// let mut r = RasterMut::new(e, &mut plane).unwrap();
/// distance_field(&mut r);
/// let r = r.as_raster();
/// let mut bricks = vec![0u8; coarse_extent(e).unwrap().len()];
/// let mut lines = vec![0u8; line_count(e.len())];
/// line_distances(&r, &mut bricks, &mut lines).unwrap();
/// let line = |v| lines[e.index(v).unwrap() / 64];
/// // x = 128..192 of row (y, z) = (0, 3): 9 to 72 voxels from the opaque one.
/// assert_eq!(distance(line([128, 0, 3])), 9);
/// // x = 0..64 of that row: 137 voxels and more; the coarse level bounds
/// // it by 121 (16 bricks or more away), which a cell holds as 120.
/// assert_eq!(distance(line([0, 0, 3])), 120);
/// // The opaque voxel's own line: read the plane.
/// assert_eq!(line([192, 0, 0]), cell::EMPTY);
/// ```
///
/// # Errors
/// [`RasterError::LineLength`] unless `lines.len()` is
/// [`line_count`](crate::raster::line_count)`(plane length)` and
/// `bricks.len()` the coarse extent's length.
pub fn line_distances(
    raster: &Raster<'_>,
    bricks: &mut [u8],
    lines: &mut [u8],
) -> Result<(), RasterError> {
    check_line_count(raster.plane().len(), lines.len())?;
    coarse_level(raster, bricks)?;
    line_stand_ins(raster, bricks, 0, lines)
}

/// Lines in a row of the longest raster axis ([`MAX_AXIS`](crate::raster::MAX_AXIS)).
const MAX_LINES_PER_ROW: usize = crate::raster::MAX_AXIS as usize / LINE_CELLS;

/// The stand-in of the line of plane cells `cells` whose bricks' coarse
/// level is at least `bound`: that bound where it is [`NEAR_LIMIT`] or
/// more (the plane is not read), else the least distance of the cells
/// (an empty cell counting as `NEAR_LIMIT`) or `bound` if larger, and
/// [`cell::EMPTY`] (read the plane) where a cell is opaque or flagged or
/// the distance is below 2.
#[inline]
fn stand_in(cells: &[u8], bound: u8) -> u8 {
    if bound >= NEAR_LIMIT {
        return distance_cell(bound);
    }
    // Without OPAQUE or PROXIMITY in any cell, every cell is its distance
    // bits alone (EMPTY the farthest), and the nearest cell holds the least
    // distance.
    let any = cells.iter().fold(0u8, |a, &c| a | c);
    // `nearer` over the line, as a plain minimum of `c − 1` (wrapping:
    // EMPTY last), which vectorizes.
    let least = cells
        .iter()
        .fold(u8::MAX, |a, &c| a.min(c.wrapping_sub(1)))
        .wrapping_add(1);
    let d = if least == cell::EMPTY {
        NEAR_LIMIT
    } else {
        distance(least)
    };
    let d = d.max(bound);
    if any & (cell::OPAQUE | cell::PROXIMITY) != 0 || d < 2 {
        cell::EMPTY
    } else {
        distance_cell(d)
    }
}

/// The stand-ins of the lines `first..first + lines.len()` of the line
/// level ([`line_distances`]) from the raster's coarse level `bricks`
/// ([`coarse_level`], or [`coarse_field`] of the occupied bricks), into
/// `lines`; lines beyond the plane's are left alone. A caller with threads
/// hands out parts.
///
/// # Errors
/// [`RasterError::LineLength`] unless `bricks.len()` is the coarse
/// extent's length.
pub fn line_stand_ins(
    raster: &Raster<'_>,
    bricks: &[u8],
    first: usize,
    lines: &mut [u8],
) -> Result<(), RasterError> {
    let extent = raster.extent();
    let coarse = coarse_extent(extent)?;
    check_len(coarse.len(), bricks.len())?;
    let plane = raster.plane();
    let [nx, ny, _] = extent.dims().map(to_usize);
    let [cx, cy, _] = coarse.dims().map(to_usize);
    let edge = to_usize(COARSE_EDGE);
    let len = plane.len();
    let Some(mut start) = first.checked_mul(LINE_CELLS) else {
        return Ok(());
    };
    if nx == 0 {
        return Ok(());
    }
    // The first cell's position, then advanced line by line (no division
    // per line).
    let (mut x, row) = (start.checked_rem(nx).unwrap_or(0), div(start, nx));
    let (mut y, mut z) = (row.checked_rem(ny).unwrap_or(0), div(row, ny));
    if nx.is_multiple_of(LINE_CELLS) && LINE_CELLS.is_multiple_of(edge) {
        // Every line lies in one row and covers whole bricks: the rows of
        // a brick row share their lines' coarse bounds, made once.
        let per_row = div(nx, LINE_CELLS);
        let span = div(LINE_CELLS, edge);
        let mut shared = [DISTANCE_LIMIT; MAX_LINES_PER_ROW];
        let mut made: Option<usize> = None;
        let mut j = div(x, LINE_CELLS);
        for out in lines.iter_mut() {
            if start >= len {
                break;
            }
            let brick_row = div(z, edge).wrapping_mul(cy).wrapping_add(div(y, edge));
            if made != Some(brick_row) {
                let base = brick_row.wrapping_mul(cx);
                let row = bricks.get(base..base.wrapping_add(cx)).unwrap_or(&[]);
                for (b, piece) in shared.iter_mut().zip(row.chunks(span)) {
                    *b = piece.iter().fold(DISTANCE_LIMIT, |a, &c| a.min(c));
                }
                made = Some(brick_row);
            }
            let bound = shared.get(j).copied().unwrap_or(0);
            let end = start.saturating_add(LINE_CELLS);
            *out = stand_in(plane.get(start..end).unwrap_or(&[]), bound);
            start = end;
            j = j.wrapping_add(1);
            if j == per_row {
                j = 0;
                (y, z) = next_row(y, z, ny);
            }
        }
        return Ok(());
    }
    for out in lines.iter_mut() {
        if start >= len {
            break;
        }
        let end = start.saturating_add(LINE_CELLS).min(len);
        // The coarse bound: the least over the bricks of each row piece.
        let mut bound = DISTANCE_LIMIT;
        let (mut at, mut px, mut py, mut pz) = (start, x, y, z);
        while at < end {
            let piece = nx.saturating_sub(px).min(end.wrapping_sub(at)).max(1);
            let base = div(pz, edge)
                .wrapping_mul(cy)
                .wrapping_add(div(py, edge))
                .wrapping_mul(cx);
            let first_brick = base.wrapping_add(div(px, edge));
            let last_brick = base.wrapping_add(div(px.wrapping_add(piece).wrapping_sub(1), edge));
            let least = bricks.get(first_brick..=last_brick).unwrap_or(&[]);
            bound = least.iter().fold(bound, |a, &b| a.min(b));
            at = at.wrapping_add(piece);
            px = 0;
            (py, pz) = next_row(py, pz, ny);
        }
        *out = stand_in(plane.get(start..end).unwrap_or(&[]), bound);
        start = end;
        x = x.wrapping_add(LINE_CELLS);
        while x >= nx {
            x = x.wrapping_sub(nx);
            (y, z) = next_row(y, z, ny);
        }
    }
    Ok(())
}

/// The row after row `y` of slice `z` (rows of `ny` per slice).
#[inline]
const fn next_row(y: usize, z: usize, ny: usize) -> (usize, usize) {
    let y = y.wrapping_add(1);
    if y >= ny {
        (0, z.wrapping_add(1))
    } else {
        (y, z)
    }
}

/// Computes the proximity distance field: every cell whose voxel lies
/// within [`NEAR_LIMIT`]` − 1` (chessboard, L∞) of a [`cell::OPAQUE`]
/// voxel gets that distance in its distance bits, and [`cell::PROXIMITY`]
/// where it is at most 1 (exactly what [`flag_neighbourhood`] sets); every
/// other transparent cell is [`cell::EMPTY`], and is written only if it
/// was not (so a zeroed plane's memory far from surfaces stays untouched).
/// A raster without opaque voxels is all empty. Opaque cells get distance
/// bits 0, which clears their rank hints: write them afterwards
/// ([`crate::store::write_rank_hints`]).
///
/// Cohen & Sheffer's proximity clouds, generalizing the paper's one-bit flag:
/// a 26-connected ray at a voxel of distance `d` can take `d − 1` steps at
/// once without passing a non-transparent or flagged voxel (see
/// [`crate::discrete_ray::DiscreteRay::first_hit_skipping`]).
///
/// Computed by slices ([`field`]: the distances within each slice, then up
/// and down the slices), in place, with no scratch memory beyond a small
/// stack buffer. Every cell is read; the writes and the relaxations follow
/// the opaque voxels: rows and slices with no opaque voxel within
/// [`field::FIELD_REACH`] are only read. A caller with threads runs the
/// same steps on its own ([`field`]), with the same result.
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
