//! The proximity pass of the builder: PROXIMITY flags around every record.

use super::RecordStore;
use crate::raster::{RasterMut, cell, to_usize};

/// Above one record per `DENSE_RATIO` voxels [`Filler::finish`] sets the
/// proximity flags with the whole-plane pass
/// ([`crate::proximity::flag_neighbourhood`]) instead of [`flag_proximity`].
/// Both give the same flags; the ratio only picks the faster pass.
///
/// [`Filler::finish`]: super::Filler::finish
pub const DENSE_RATIO: usize = 44;

/// Sets [`cell::PROXIMITY`] on the 26-neighbourhood (and the voxel itself)
/// of every record's voxel, in O(records): 27 cell writes per record,
/// clipped to the raster. Other bits, the reserved distance bits 2..8
/// among them, are left alone; flags already set stay set.
///
/// On a plane whose PROXIMITY bits were clear (or marked only record
/// voxels, as the fill pass leaves them) and whose OPAQUE voxels are exactly
/// the records', this gives the same flags as
/// [`crate::proximity::flag_neighbourhood`], which sweeps the whole plane:
/// this pass costs time in proportion to the records, that one to the
/// voxels.
pub fn flag_proximity(raster: &mut RasterMut<'_>, store: &RecordStore<'_>) {
    let extent = raster.extent();
    if store.extent() != extent {
        return;
    }
    let [nx, ny, nz] = extent.dims();
    let [_, sy, sz] = extent.strides();
    let plane = raster.plane_mut();
    for (v, _) in store.iter() {
        let lo = v.map(|c| c.saturating_sub(1));
        // v < n <= 2^16: +1 cannot overflow.
        let hi = [
            v[0].wrapping_add(1).min(nx.wrapping_sub(1)),
            v[1].wrapping_add(1).min(ny.wrapping_sub(1)),
            v[2].wrapping_add(1).min(nz.wrapping_sub(1)),
        ];
        let Some(base) = extent.index(lo) else {
            continue;
        };
        let (w, h, d) = (
            to_usize(hi[0].wrapping_sub(lo[0])),
            to_usize(hi[1].wrapping_sub(lo[1])),
            to_usize(hi[2].wrapping_sub(lo[2])),
        );
        // Every index below is that of a voxel inside the raster.
        for k in 0..=d {
            let zrow = base.wrapping_add(k.wrapping_mul(sz));
            for j in 0..=h {
                let row = zrow.wrapping_add(j.wrapping_mul(sy));
                if let Some(cells) = plane.get_mut(row..=row.wrapping_add(w)) {
                    for c in cells {
                        *c |= cell::PROXIMITY;
                    }
                }
            }
        }
    }
}
