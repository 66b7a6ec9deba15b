//! Unit tests of proximity flags, the distance field and the line level.

use std::vec;
use std::vec::Vec;

use super::*;
use crate::raster::line_count;
use crate::raster::{Extent, Raster};
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
            // Stored below the near limit; empty from it on.
            let stored = if w < NEAR_LIMIT { w } else { 0 };
            assert_eq!(
                distance(c),
                stored,
                "case {case} dims {dims:?} voxel {:?}",
                e.coord(i)
            );
            if w >= NEAR_LIMIT {
                assert_eq!(c, cell::EMPTY, "case {case}");
            }
            assert_eq!(c & cell::OPAQUE != 0, w == 0, "case {case}");
            // The flag is exactly what flag_neighbourhood sets.
            assert_eq!(
                c & cell::PROXIMITY,
                flags[i] & cell::PROXIMITY,
                "case {case}"
            );
        }
        check_line_level(e, &plane, &want, &std::format!("case {case}"));
    }
}

/// The coarse level and line level of a finished `plane` of `e` whose
/// exact distances (saturated at [`DISTANCE_LIMIT`]) are `want`: each
/// brick's coarse distance is the brute-force chessboard distance over
/// the bricks, and each stand-in is the larger of the coarse bound and the
/// line's least stored distance (EMPTY at [`NEAR_LIMIT`]), EMPTY where a
/// cell is within 1 or the bound is below 2; never above the line's
/// least exact distance.
fn check_line_level(e: Extent, plane: &[u8], want: &[u8], what: &str) {
    let raster = Raster::new(e, plane).unwrap();
    let ce = coarse_extent(e).unwrap();
    let mut bricks = vec![0xffu8; ce.len()];
    let mut lines = vec![0xffu8; line_count(e.len())];
    line_distances(&raster, &mut bricks, &mut lines).unwrap();
    // Brute force over the bricks.
    let occupied: Vec<[u32; 3]> = (0..e.len())
        .filter(|&i| want[i] == 0)
        .map(|i| e.coord(i).unwrap().map(|c| c / COARSE_EDGE))
        .collect();
    let brick_want = brute(ce, &occupied);
    let brick_bound = |k: u8| {
        let k = u32::from(k.min(NEAR_LIMIT));
        u8::try_from(if k == 0 {
            0
        } else {
            (8 * (k - 1) + 1).min(u32::from(DISTANCE_LIMIT))
        })
        .unwrap()
    };
    for (b, (&got, &w)) in bricks.iter().zip(&brick_want).enumerate() {
        assert_eq!(got, brick_bound(w), "{what}: brick {b}");
    }
    let [nx, ny, _] = e.dims();
    let [cx, cy, _] = ce.dims();
    for (l, &got) in lines.iter().enumerate() {
        let cells = l * LINE_CELLS..((l + 1) * LINE_CELLS).min(e.len());
        let exact = cells.clone().map(|i| want[i]).min().unwrap();
        let bound = cells
            .clone()
            .map(|i| {
                let i = u32::try_from(i).unwrap();
                let (x, y, z) = (i % nx, i / nx % ny, i / nx / ny);
                let b = (z / 8 * cy + y / 8) * cx + x / 8;
                brick_bound(brick_want[b as usize])
            })
            .min()
            .unwrap();
        let expect = if bound >= NEAR_LIMIT {
            distance_cell(bound)
        } else if exact <= 1 {
            cell::EMPTY
        } else {
            let d = exact.min(NEAR_LIMIT).max(bound);
            distance_cell(d)
        };
        assert_eq!(got, expect, "{what}: line {l}");
        assert!(distance(got) <= exact, "{what}: line {l} above its cells");
    }
}

#[test]
fn distances_stop_at_the_near_limit() {
    let e = Extent::new(150, 3, 2).unwrap();
    let mut plane = vec![cell::EMPTY; e.len()];
    plane[e.index([0, 1, 1]).unwrap()] = cell::OPAQUE;
    distance_field(&mut RasterMut::new(e, &mut plane).unwrap());
    let at = |x| plane[e.index([x, 0, 0]).unwrap()];
    assert_eq!(
        (at(1), at(15), at(16), at(149)),
        (1 << 2 | cell::PROXIMITY, 15 << 2, cell::EMPTY, cell::EMPTY)
    );
    let mut empty = vec![cell::EMPTY; e.len()];
    distance_field(&mut RasterMut::new(e, &mut empty).unwrap());
    assert!(empty.iter().all(|&c| c == cell::EMPTY));
}

/// A lone voxel in rasters larger than the near limit and several bricks
/// wide: the field is empty from the limit on, and the line level bounds
/// those lines from the coarse level (jumps up to the most a cell holds),
/// including rasters whose rows are not whole lines.
#[test]
fn far_lines_are_bounded_by_the_coarse_level() {
    for dims in [
        [64, 64, 64],
        [192, 40, 30],
        [200, 30, 20],
        [37, 90, 41],
        [5, 7, 300],
    ] {
        let e = Extent::new(dims[0], dims[1], dims[2]).unwrap();
        let at = [[3, 5, 6], [150, 2, 19], [36, 0, 20], [4, 6, 150]];
        for v in at.into_iter().filter(|&v| e.contains(v)) {
            let mut plane = vec![cell::EMPTY; e.len()];
            plane[e.index(v).unwrap()] = cell::OPAQUE;
            distance_field(&mut RasterMut::new(e, &mut plane).unwrap());
            let want = brute(e, &[v]);
            for (i, &c) in plane.iter().enumerate() {
                if want[i] >= NEAR_LIMIT {
                    assert_eq!(c, cell::EMPTY, "{dims:?} {v:?} {:?}", e.coord(i));
                }
            }
            check_line_level(e, &plane, &want, &std::format!("{dims:?} {v:?}"));
        }
    }
}

/// The line level made in parts from any first line (as threads share it
/// out) is the line level made at once, for rows of whole lines and not.
#[test]
fn line_level_in_parts_is_the_whole() {
    for dims in [[192, 40, 30], [128, 17, 9], [200, 30, 20]] {
        let e = Extent::new(dims[0], dims[1], dims[2]).unwrap();
        let mut plane = vec![cell::EMPTY; e.len()];
        for v in [[3, 5, 6], [150, 2, 19], [100, 16, 8]] {
            if let Some(i) = e.index(v) {
                plane[i] = cell::OPAQUE;
            }
        }
        distance_field(&mut RasterMut::new(e, &mut plane).unwrap());
        let raster = Raster::new(e, &plane).unwrap();
        let mut bricks = vec![0u8; coarse_extent(e).unwrap().len()];
        let mut whole = vec![0u8; line_count(e.len())];
        line_distances(&raster, &mut bricks, &mut whole).unwrap();
        for part in [1, 5, 7, 64] {
            let mut lines = vec![0xffu8; whole.len()];
            for (k, l) in lines.chunks_mut(part).enumerate() {
                line_stand_ins(&raster, &bricks, k * part, l).unwrap();
            }
            assert_eq!(lines, whole, "{dims:?} in parts of {part}");
        }
    }
}

/// The reference: the whole-plane two-pass sequential chamfer transform
/// (3×3×3 mask, unit weights) that the slices replaced, kept to check that
/// they give the same bytes.
fn chamfer_field(raster: &mut RasterMut<'_>) {
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
        *c = if d >= NEAR_LIMIT {
            cell::EMPTY
        } else {
            opaque | flag | (d << cell::DISTANCE_SHIFT)
        };
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

/// A plane of `e` with opaque voxels (and junk in the other cells' bits,
/// which the field must ignore): a few scattered ones, runs along each
/// axis, or dense noise, by `kind`.
fn random_plane(rng: &mut Rng, e: Extent, kind: u32) -> Vec<u8> {
    let [nx, ny, nz] = e.dims();
    let mut plane: Vec<u8> = (0..e.len())
        .map(|_| {
            if kind.is_multiple_of(2) {
                0
            } else {
                u8::try_from(rng.below(256)).unwrap() & !cell::OPAQUE
            }
        })
        .collect();
    let set = |v: [u32; 3], plane: &mut Vec<u8>| {
        if let Some(i) = e.index(v) {
            plane[i] |= cell::OPAQUE;
        }
    };
    match kind / 2 % 3 {
        0 => {
            for _ in 0..rng.below(6) {
                let v = [rng.below_u32(nx), rng.below_u32(ny), rng.below_u32(nz)];
                set(v, &mut plane);
            }
        }
        1 => {
            for _ in 0..rng.below(4) {
                let mut v = [rng.below_u32(nx), rng.below_u32(ny), rng.below_u32(nz)];
                let axis = usize::try_from(rng.below(3)).unwrap();
                for _ in 0..rng.below(40) {
                    set(v, &mut plane);
                    v[axis] += 1;
                }
            }
        }
        _ => {
            let density = 1 + rng.below(40);
            for i in 0..e.len() {
                if rng.below(1000) < density {
                    let v = e.coord(i).unwrap();
                    set(v, &mut plane);
                }
            }
        }
    }
    plane
}

#[test]
fn distance_field_gives_the_bytes_of_the_whole_plane_chamfer() {
    let mut rng = Rng(0x0d15_7a9c_e5eb_u64);
    for case in 0..300u32 {
        // Small rasters, and some longer than the limit along one axis (the
        // skipped slices and rows) or wider than the stack buffer.
        let long = |rng: &mut Rng| 1 + rng.below_u32(if case % 5 == 0 { 300 } else { 24 });
        let dims = [long(&mut rng), long(&mut rng), long(&mut rng)];
        let Ok(e) = Extent::new(dims[0], dims[1], dims[2]) else {
            continue;
        };
        if e.len() > 400_000 {
            continue;
        }
        let plane = random_plane(&mut rng, e, case);
        let mut want = plane.clone();
        chamfer_field(&mut RasterMut::new(e, &mut want).unwrap());
        let mut got = plane.clone();
        distance_field(&mut RasterMut::new(e, &mut got).unwrap());
        if let Some(i) = (0..e.len()).find(|&i| got[i] != want[i]) {
            panic!(
                "case {case} dims {dims:?}: voxel {:?}: {:#04x}, the chamfer's {:#04x}",
                e.coord(i),
                got[i],
                want[i]
            );
        }
        // Again over the finished plane: the same.
        distance_field(&mut RasterMut::new(e, &mut got).unwrap());
        assert_eq!(got, want, "case {case}: a second run");
    }
}

#[test]
fn distance_field_is_exact_where_the_relaxations_are_skipped() {
    // Long thin rasters with one or two opaque voxels: the only paths to
    // the cells 62 and 63 voxels away run along the long axis, through the
    // last slices (rows) a relaxation may not skip.
    for (dims, at) in [
        ([1, 1, 150], [[0, 0, 3], [0, 0, 140]]),
        ([2, 3, 150], [[1, 2, 10], [1, 2, 10]]),
        ([1, 150, 1], [[0, 5, 0], [0, 80, 0]]),
        ([3, 150, 2], [[2, 140, 1], [2, 140, 1]]),
        ([150, 1, 1], [[7, 0, 0], [7, 0, 0]]),
        ([70, 70, 1], [[0, 0, 0], [69, 69, 0]]),
        ([2, 70, 70], [[0, 0, 0], [1, 69, 69]]),
    ] {
        let e = Extent::new(dims[0], dims[1], dims[2]).unwrap();
        let mut plane = vec![cell::EMPTY; e.len()];
        for v in at {
            plane[e.index(v).unwrap()] = cell::OPAQUE;
        }
        let mut want = plane.clone();
        chamfer_field(&mut RasterMut::new(e, &mut want).unwrap());
        distance_field(&mut RasterMut::new(e, &mut plane).unwrap());
        assert_eq!(plane, want, "{dims:?} {at:?}");
        assert_eq!(
            brute(e, &at)
                .iter()
                .map(|&d| if d < NEAR_LIMIT { d } else { 0 })
                .collect::<Vec<_>>(),
            plane.iter().map(|&c| distance(c)).collect::<Vec<_>>()
        );
    }
}

#[test]
fn field_steps_shared_out_by_rows_give_the_whole_field() {
    // The steps a threaded caller runs (slices apart, then rows of each
    // slice apart) against the one call.
    let mut rng = Rng(0x0005_1ab5_u64);
    for case in 0..40u32 {
        // Some rows longer than a relaxation's column chunk.
        let dims = [
            1 + rng.below_u32(if case % 8 == 0 { 600 } else { 40 }),
            1 + rng.below_u32(40),
            1 + rng.below_u32(90),
        ];
        let e = Extent::new(dims[0], dims[1], dims[2]).unwrap();
        let plane = random_plane(&mut rng, e, case);
        let mut want = plane.clone();
        distance_field(&mut RasterMut::new(e, &mut want).unwrap());
        if case % 8 == 0 {
            assert_eq!(want, {
                let mut c = plane.clone();
                chamfer_field(&mut RasterMut::new(e, &mut c).unwrap());
                c
            });
        }
        let [nx, ny, nz] = dims.map(|d| d as usize);
        let slice = nx * ny;
        let mut got = plane;
        let opaque: Vec<field::Area> = got
            .chunks_exact_mut(slice)
            .map(|s| field::slice_distances(s, nx))
            .collect();
        let band = 1 + rng.below(5) as usize;
        // The opaque voxels' box over the slices `zs`, reached.
        let reached = |zs: core::ops::Range<usize>| {
            zs.fold(field::Area::EMPTY, |a, z| a.union(opaque[z]))
                .reached(nx, ny)
        };
        let relax = |got: &mut Vec<u8>, z: usize, from: usize, area: field::Area| {
            let src = got[from * slice..][..slice].to_vec();
            for (i, rows) in got[z * slice..][..slice].chunks_mut(band * nx).enumerate() {
                field::relax_rows(rows, &src, nx, i * band, area);
            }
        };
        let reach = field::FIELD_REACH as usize;
        for z in 1..nz {
            let area = reached(z.saturating_sub(reach)..z);
            relax(&mut got, z, z - 1, area);
        }
        for z in (0..nz.saturating_sub(1)).rev() {
            let area = reached(z + 1..(z + 1 + reach).min(nz));
            relax(&mut got, z, z + 1, area);
        }
        assert_eq!(got, want, "case {case} dims {dims:?} band {band}");
    }
}

/// The distance codes: every distance is written as the largest distance
/// a cell holds that is not above it, every code reads back as itself,
/// and the distances the field stores are exact.
#[test]
fn distance_codes_round_down_and_read_back() {
    let held: Vec<u8> = (0..=cell::DISTANCE_MASK)
        .map(|k| distance(k << cell::DISTANCE_SHIFT))
        .collect();
    assert!(held.windows(2).all(|w| w[0] < w[1]), "{held:?}");
    assert_eq!(held.last(), Some(&DISTANCE_LIMIT));
    for d in 0..=u8::MAX {
        let c = distance_cell(d);
        assert_eq!(c & (cell::OPAQUE | cell::PROXIMITY), 0, "{d}");
        let want = held.iter().copied().filter(|&h| h <= d).max().unwrap();
        assert_eq!(distance(c), want, "{d}");
        if d <= NEAR_LIMIT {
            assert_eq!(distance(c), d);
        }
    }
    for k in 0..=cell::DISTANCE_MASK {
        let c = k << cell::DISTANCE_SHIFT;
        assert_eq!(distance_cell(distance(c)), c, "code {k}");
    }
}
