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

use crate::raster::{RasterMut, cell, to_usize};

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
    let [nx, ny, _] = raster.extent().dims().map(to_usize);
    // Both non-zero and their product fits (it divides the plane length);
    // checked anyway so that no chunking below can be asked for size 0.
    let Some(slice) = nx.checked_mul(ny).filter(|&s| s != 0 && nx != 0) else {
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
