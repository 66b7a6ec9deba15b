//! The proximity distance field by slices: exact, in place, in work that a
//! caller can share among threads, and nothing written far from surfaces.
//!
//! The field of a cell is `min over opaque voxels q of max(|dx|, |dy|,
//! |dz|)`, stored where it is below [`NEAR_LIMIT`]; a transparent cell at
//! that distance or more is left [`cell::EMPTY`], so the plane's memory far
//! from surfaces is never written (an anonymous map keeps such pages
//! unbacked). It is computed in three steps, each exact:
//! 1. [`slice_distances`], per z-slice on its own: the distance to the
//!    nearest opaque voxel *of the same slice*, `d2`. Per row, the distance
//!    along the row (a ramp written only within the limit of each opaque
//!    run), then the rows relaxed from their neighbours, up the slice and
//!    down again.
//! 2. Up the slices: `F(z) = min(d2(z), 1 + min over the 3×3 cells around
//!    (x, y) of F(z − 1))` ([`relax_rows`] with the slice below) is the
//!    exact distance to the opaque voxels at or below `z`: the chessboard
//!    distance from a voxel to one in a lower slice is one more than the
//!    least of its nine neighbours' in the slice below (a step that brings
//!    every coordinate one nearer).
//! 3. Down the slices: `min(F(z), 1 + min over 3×3 of the finished slice
//!    z + 1)` ([`relax_rows`] with the slice above) is the exact distance
//!    (the second term is never below it, and holds every opaque voxel
//!    above).
//!
//! The same holds for the rows within a slice (step 1) with 1×3
//! neighbourhoods. Since distances from [`NEAR_LIMIT`] on are all one
//! value, a relaxation from a neighbour changes nothing unless an opaque
//! voxel lies within [`FIELD_REACH`] slices (rows) on that side: such
//! slices and rows are skipped, and a relaxation writes only the runs of
//! cells it changes.
//!
//! Cells hold their finished form from the first step on: the distance in
//! the distance bits, [`cell::PROXIMITY`] at distance 0 and 1,
//! [`cell::OPAQUE`] at 0 and [`cell::EMPTY`] from [`NEAR_LIMIT`] on (the
//! map is increasing once `EMPTY` is ordered last, `nearer`, so minima
//! commute with it). Steps 2 and 3 read one whole neighbouring slice and
//! write rows of another, so a caller may hand out the rows of a slice to
//! threads; step 1 is independent per slice.

use super::NEAR_LIMIT;
use crate::raster::cell;

/// How far an opaque voxel's influence reaches through the relaxations:
/// relaxing a slice (row) from its neighbour on one side changes it only
/// if an opaque voxel lies within this many slices (rows) on that side.
/// A distance of `NEAR_LIMIT − 2` or less in the neighbour is needed for
/// `1 + distance` to be stored, and the neighbour itself counts.
pub const FIELD_REACH: u32 = NEAR_LIMIT as u32 - 1;

/// One distance step in the distance bits.
const STEP: u8 = 1 << cell::DISTANCE_SHIFT;
/// The finished cell of a transparent voxel [`NEAR_LIMIT`] or more from
/// every opaque one: [`cell::EMPTY`], ordered after every other finished
/// cell ([`nearer`]).
pub(super) const FAR: u8 = cell::EMPTY;
/// The distance bits of [`NEAR_LIMIT`]: finished distances lie below.
const NEAR_BITS: u8 = NEAR_LIMIT << cell::DISTANCE_SHIFT;
/// The finished form of an opaque cell (rank hints are written later).
pub(super) const OPAQUE_CELL: u8 = cell::OPAQUE | cell::PROXIMITY;
/// Distance bits of a finished cell.
const DISTANCE_BITS: u8 = cell::DISTANCE_MASK << cell::DISTANCE_SHIFT;
/// Columns handled at once by [`relax_row`]'s stack buffer.
const CHUNK: usize = 256;

/// The nearer of two finished cells: the smaller, with [`FAR`] (0) ordered
/// after all others (`c − 1` wrapping is an order-preserving key).
#[inline]
pub(super) const fn nearer(a: u8, b: u8) -> u8 {
    let (ka, kb) = (a.wrapping_sub(1), b.wrapping_sub(1));
    // The smaller key, mapped back: a minimum, which vectorizes.
    (if ka <= kb { ka } else { kb }).wrapping_add(1)
}

/// The finished cell of a transparent voxel at distance `d ≥ 1`.
#[inline]
const fn at_distance(d: u8) -> u8 {
    if d >= NEAR_LIMIT {
        return FAR;
    }
    let bits = d << cell::DISTANCE_SHIFT;
    if d <= 1 { bits | cell::PROXIMITY } else { bits }
}

/// The finished cell one step beyond a neighbour whose finished cell is
/// `n`: distance `distance(n) + 1` ([`FAR`] from [`NEAR_LIMIT`] on, and
/// beyond a far cell), with PROXIMITY at 1.
#[inline]
const fn one_beyond(n: u8) -> u8 {
    // Selects only (no early return), so that it vectorizes.
    let bits = (n & DISTANCE_BITS).wrapping_add(STEP);
    let flagged = if bits == STEP {
        bits | cell::PROXIMITY
    } else {
        bits
    };
    if n != FAR && bits < NEAR_BITS {
        flagged
    } else {
        FAR
    }
}

/// `seg[j] = nearer(seg[j], offer[j])`, writing `seg` only if a cell
/// changes (so unchanged memory is only read).
#[inline]
fn lower(seg: &mut [u8], offer: &[u8]) {
    // Whether an offer is nearer than its cell, without an early exit (a
    // reduction, which vectorizes).
    let changed = seg.iter().zip(offer).fold(false, |acc, (&c, &o)| {
        acc | (o.wrapping_sub(1) < c.wrapping_sub(1))
    });
    if changed {
        for (c, &o) in seg.iter_mut().zip(offer) {
            *c = nearer(*c, o);
        }
    }
}

/// A box of cells of a slice: the columns `x[0]..x[1]` of the rows
/// `y[0]..y[1]`; empty when either range is.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct Area {
    /// Columns, half-open.
    pub x: [usize; 2],
    /// Rows, half-open.
    pub y: [usize; 2],
}

impl Area {
    /// No cell.
    pub const EMPTY: Self = Self {
        x: [0, 0],
        y: [0, 0],
    };

    /// Whether the box holds no cell.
    #[must_use]
    pub const fn is_empty(&self) -> bool {
        self.x[0] >= self.x[1] || self.y[0] >= self.y[1]
    }

    /// The smallest box holding both.
    #[must_use]
    pub fn union(self, other: Self) -> Self {
        if self.is_empty() {
            return other;
        }
        if other.is_empty() {
            return self;
        }
        Self {
            x: [self.x[0].min(other.x[0]), self.x[1].max(other.x[1])],
            y: [self.y[0].min(other.y[0]), self.y[1].max(other.y[1])],
        }
    }

    /// The box grown by `by` cells on every side, clipped to a slice of
    /// `nx × ny` cells.
    #[must_use]
    pub fn grown(self, by: usize, nx: usize, ny: usize) -> Self {
        if self.is_empty() {
            return self;
        }
        Self {
            x: [
                self.x[0].saturating_sub(by),
                self.x[1].saturating_add(by).min(nx),
            ],
            y: [
                self.y[0].saturating_sub(by),
                self.y[1].saturating_add(by).min(ny),
            ],
        }
    }

    /// Where a relaxation from neighbours whose opaque voxels lie in
    /// `self` can change anything: the box grown by [`FIELD_REACH`].
    #[must_use]
    pub fn reached(self, nx: usize, ny: usize) -> Self {
        self.grown(reach(), nx, ny)
    }
}

/// Step 1 on one z-slice `slice` of rows of `nx` cells (every cell read
/// only for its [`cell::OPAQUE`] bit): each cell gets its finished form
/// for the distance to the nearest opaque voxel of the slice (see the
/// [module docs](self)). Returns the box of the slice's opaque voxels
/// (empty without one). A slice whose length is not a multiple of `nx`
/// (or `nx` = 0) is left as it is.
pub fn slice_distances(slice: &mut [u8], nx: usize) -> Area {
    slice_distances_in(slice, nx, |_| true)
}

/// [`slice_distances`] for a slice whose rows `y` with `may_hold(y)`
/// false are known to hold only [`cell::EMPTY`] cells (a fresh plane
/// where the caller knows which rows its opaque voxels lie in): those rows
/// are not read unless an opaque row is within reach. The same result as
/// [`slice_distances`] when that holds.
pub fn slice_distances_in(slice: &mut [u8], nx: usize, may_hold: impl Fn(usize) -> bool) -> Area {
    if nx == 0 || !slice.len().is_multiple_of(nx) {
        return Area::EMPTY;
    }
    let rows = slice.len().checked_div(nx).unwrap_or(0);
    // Along each row, then up the slice: from the row below when an opaque
    // row is near below (`last`: the latest one), over the columns the
    // opaque voxels so far reach (`seen`).
    let mut seen = Area::EMPTY;
    let mut last: Option<usize> = None;
    for y in 0..rows {
        let start = y.wrapping_mul(nx);
        let Some((done, rest)) = slice.split_at_mut_checked(start) else {
            break;
        };
        let row = rest.get_mut(..nx).unwrap_or(&mut []);
        let opaque = if may_hold(y) {
            row_distances(row)
        } else {
            None
        };
        if let Some(l) = last
            && reaches(y.wrapping_sub(l))
        {
            let below = done.get(start.wrapping_sub(nx)..).unwrap_or(&[]);
            relax_row(row, below, seen.reached(nx, rows).x);
        }
        if let Some(x) = opaque {
            seen = seen.union(Area {
                x,
                y: [y, y.wrapping_add(1)],
            });
            last = Some(y);
        }
    }
    if seen.is_empty() {
        return seen;
    }
    // Down the slice: from the row above when an opaque row is near above.
    let columns = seen.reached(nx, rows).x;
    let mut next: Option<usize> = None;
    for y in (0..rows).rev() {
        let start = y.wrapping_mul(nx);
        if let Some(n) = next
            && reaches(n.wrapping_sub(y))
        {
            let (head, above) = slice.split_at_mut(start.wrapping_add(nx));
            let above = above.get(..nx).unwrap_or(&[]);
            relax_row(head.get_mut(start..).unwrap_or(&mut []), above, columns);
        }
        let row = slice.get(start..start.wrapping_add(nx)).unwrap_or(&[]);
        if (seen.y[0]..seen.y[1]).contains(&y) && may_hold(y) && row.contains(&OPAQUE_CELL) {
            next = Some(y);
        }
    }
    seen
}

/// [`FIELD_REACH`] as an index distance.
#[inline]
const fn reach() -> usize {
    FIELD_REACH as usize
}

/// Steps 2 and 3: relaxes the cells `area` of a slice of rows of `nx`
/// cells from the finished neighbouring slice `neighbour` (the whole
/// slice below for step 2, above for step 3): each cell becomes the least
/// of itself and one beyond the nine cells around it in `neighbour`.
/// `rows` holds the slice's rows from row `y0` on (all of them, or a
/// caller's share: only the rows of `area` among them are relaxed). The
/// relaxation changes nothing outside the box of the opaque voxels in the
/// slices on that side within [`FIELD_REACH`], [grown](Area::reached) by
/// it: that box is the `area` to give (or any larger one).
pub fn relax_rows(rows: &mut [u8], neighbour: &[u8], nx: usize, y0: usize, area: Area) {
    if nx == 0 || area.is_empty() {
        return;
    }
    let ny = neighbour.len().checked_div(nx).unwrap_or(0);
    let held = rows.len().checked_div(nx).unwrap_or(0);
    let first = y0.max(area.y[0]);
    let end = y0.saturating_add(held).min(area.y[1]).min(ny);
    if first >= end {
        return;
    }
    let at = |yy: usize| neighbour.get(yy.checked_mul(nx)?..)?.get(..nx);
    let stop = area.x[1].min(nx);
    let mut start = area.x[0];
    // Buffers shared by the chunks; each use writes (or reads) only the
    // chunk's first `len` cells, so a narrow area costs what it covers.
    let mut ring = [[FAR; CHUNK]; 3];
    let mut offer = [FAR; CHUNK];
    let mut t = [FAR; CHUNK + 2];
    let slot = |yy: usize| yy.wrapping_add(1) % 3;
    // Column chunks; within one, the rows in order, each relaxed from the
    // neighbour rows around it, each of those reduced once ([`beyond`]) and
    // kept for the three rows it borders.
    while start < stop {
        let chunk_end = start.saturating_add(CHUNK).min(stop);
        let len = chunk_end.wrapping_sub(start);
        let mut reduce = |row: Option<&[u8]>, r: &mut [u8; CHUNK]| match row {
            Some(row) => beyond(row, start, chunk_end, r, &mut t),
            None => r.get_mut(..len).unwrap_or(&mut []).fill(FAR),
        };
        if let Some(r) = ring.get_mut(slot(first.wrapping_sub(1))) {
            reduce(first.checked_sub(1).and_then(at), r);
        }
        if let Some(r) = ring.get_mut(slot(first)) {
            reduce(at(first), r);
        }
        for y in first..end {
            let next = y.saturating_add(1);
            if let Some(r) = ring.get_mut(slot(next)) {
                reduce(at(next), r);
            }
            let base = y.wrapping_sub(y0).wrapping_mul(nx);
            let Some(seg) = rows.get_mut(base.wrapping_add(start)..base.wrapping_add(chunk_end))
            else {
                continue;
            };
            let [r0, r1, r2] = &ring;
            let (r0, r1, r2) = (
                r0.get(..len).unwrap_or(&[]),
                r1.get(..len).unwrap_or(&[]),
                r2.get(..len).unwrap_or(&[]),
            );
            for (((o, &a), &b), &c) in offer.iter_mut().zip(r0).zip(r1).zip(r2) {
                *o = nearer(a, nearer(b, c));
            }
            lower(seg, offer.get(..len).unwrap_or(&[]));
        }
        start = chunk_end;
    }
}

/// `out[j] = one_beyond(min of row at x − 1, x, x + 1)` for `x = start + j`
/// over the columns `start..end` (at most [`CHUNK`]) of a neighbour row:
/// what the row offers each cell of the rows beside it. Since
/// [`one_beyond`] is increasing, the least of three such values is one
/// beyond the least of the nine cells, so each neighbour row is reduced
/// once for the three rows it borders. Writes `out[..end − start]`; `t`
/// is scratch.
fn beyond(row: &[u8], start: usize, end: usize, out: &mut [u8; CHUNK], t: &mut [u8; CHUNK + 2]) {
    let n = row.len();
    let len = end.wrapping_sub(start).min(CHUNK);
    // t[j] = the row's cell at x = start − 1 + j (FAR beyond the row).
    let lo = start.saturating_sub(1);
    let hi = end.saturating_add(1).min(n);
    // 0 when start > 0, 1 at the row's start.
    let off = lo.wrapping_add(1).wrapping_sub(start);
    let width = hi.wrapping_sub(lo);
    if off != 0 || width < len.wrapping_add(2) {
        // A neighbour beyond the row's ends: FAR.
        t.get_mut(..len.wrapping_add(2))
            .unwrap_or(&mut [])
            .fill(FAR);
    }
    if let (Some(src), Some(dst)) = (row.get(lo..hi), t.get_mut(off..off.wrapping_add(width))) {
        dst.copy_from_slice(src);
    }
    let (a, b, c) = (
        t.get(..len).unwrap_or(&[]),
        t.get(1..len.wrapping_add(1)).unwrap_or(&[]),
        t.get(2..len.wrapping_add(2)).unwrap_or(&[]),
    );
    for (((o, &a), &b), &c) in out.iter_mut().zip(a).zip(b).zip(c) {
        *o = one_beyond(nearer(a, nearer(b, c)));
    }
}

/// Whether relaxing slice (row) `i` from its neighbour on one side can
/// change it, given the nearest slice (row) with an opaque voxel on that
/// side (counting the neighbour itself) at distance `gap`: only within
/// [`FIELD_REACH`].
#[must_use]
pub const fn reaches(gap: usize) -> bool {
    gap >= 1 && gap <= reach()
}

/// `row[x] = min(row[x], one_beyond(min of neighbour at x − 1, x, x + 1))`
/// for the columns `x0..x1` of `row`, with a neighbour row of its length
/// (step 1's relaxation of a row from the row below or above it).
fn relax_row(row: &mut [u8], neighbour: &[u8], [x0, x1]: [usize; 2]) {
    let stop = x1.min(row.len());
    let mut start = x0;
    let mut offered = [FAR; CHUNK];
    let mut t = [FAR; CHUNK + 2];
    while start < stop {
        let end = start.saturating_add(CHUNK).min(stop);
        beyond(neighbour, start, end, &mut offered, &mut t);
        if let Some(seg) = row.get_mut(start..end) {
            lower(seg, offered.get(..end.wrapping_sub(start)).unwrap_or(&[]));
        }
        start = end;
    }
}

/// Step 1 along one row: opaque cells become [`OPAQUE_CELL`], the others
/// the finished form of their distance along the row. Returns the columns
/// from the first opaque voxel to the last (half-open), if any.
fn row_distances(row: &mut [u8]) -> Option<[usize; 2]> {
    let n = row.len();
    let mut first: Option<usize> = None;
    let mut prev: Option<usize> = None;
    let mut from = 0usize;
    loop {
        let next = next_opaque(row, from);
        let end = next.unwrap_or(n);
        if let Some(gap) = row.get_mut(from..end) {
            fill_gap(gap, prev.is_some(), next.is_some());
        }
        let Some(j) = next else {
            return Some([first?, prev?.wrapping_add(1)]);
        };
        first = first.or(Some(j));
        if let Some(c) = row.get_mut(j) {
            *c = OPAQUE_CELL;
        }
        prev = Some(j);
        from = j.wrapping_add(1);
    }
}

/// The first cell at or after `from` with [`cell::OPAQUE`].
fn next_opaque(row: &[u8], from: usize) -> Option<usize> {
    let rest = row.get(from..)?;
    // Sixteen cells at a time, then the one that has it.
    const WORD: usize = 16;
    const ONES: u128 = u128::from_le_bytes([cell::OPAQUE; WORD]);
    let mut base = 0usize;
    for w in rest.chunks_exact(WORD) {
        let bytes: [u8; WORD] = w.try_into().unwrap_or([0; WORD]);
        if u128::from_le_bytes(bytes) & ONES != 0 {
            break;
        }
        base = base.wrapping_add(WORD);
    }
    let at = rest
        .get(base..)?
        .iter()
        .position(|&c| c & cell::OPAQUE != 0)?;
    Some(from.wrapping_add(base).wrapping_add(at))
}

/// The cells between two opaque ones (`left`, `right`: whether there is
/// one just before, just after the gap): the finished form of the distance
/// to the nearer. Only the cells within [`FIELD_REACH`] of an end are
/// computed; the rest are far, written only where they are not already.
fn fill_gap(gap: &mut [u8], left: bool, right: bool) {
    let n = gap.len();
    let reach = reach();
    let head = if left { reach.min(n) } else { 0 };
    let tail = if right {
        reach.min(n.wrapping_sub(head))
    } else {
        0
    };
    let (a, rest) = gap.split_at_mut(head);
    let mid = rest.len().wrapping_sub(tail);
    let (m, b) = rest.split_at_mut(mid);
    // Distances 1, 2, … from the left; the right end may be nearer.
    for (i, c) in a.iter_mut().enumerate() {
        let from_left = i.wrapping_add(1);
        let from_right = if right { n.wrapping_sub(i) } else { usize::MAX };
        *c = at_distance(u8::try_from(from_left.min(from_right)).unwrap_or(NEAR_LIMIT));
    }
    if m.iter().fold(0u8, |acc, &c| acc | c) != FAR {
        m.fill(FAR);
    }
    // Distances …, 2, 1 to the right end (the left one is farther here).
    let t = b.len();
    for (i, c) in b.iter_mut().enumerate() {
        let d = t.wrapping_sub(i);
        *c = at_distance(u8::try_from(d).unwrap_or(NEAR_LIMIT));
    }
}
