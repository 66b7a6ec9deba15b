//! The shadow classification's brick level: one proof for a whole brick.
//!
//! The classification of a voxel `v` for a light `L` (module docs,
//! *Shadow classification*) walks the tube of the segment from `v`'s
//! centre to `L`, voxel by voxel. Neighbouring voxels' tubes are nearly
//! the same, so on a surface of one object most of those walks repeat each
//! other. The brick level does the walk once per brick of
//! [`COARSE_EDGE`]³ voxels, on the grid of bricks: each brick's *owner*
//! ([`NO_RECORD`], the one object every record of the brick holds alone,
//! or [`SEVERAL`]), and a plane over the bricks (opaque where a brick holds
//! records, with its distance field, so that the brick walk skips empty
//! space).
//!
//! **What it proves.** For a brick `B` whose owner is object `A`, walk the
//! tube of the segment from `B`'s centre to `L` over the bricks. If every
//! brick of that tube holds no record or only records of `A` alone, then
//! every voxel of `B` (whose only object is `A`) is classified
//! [`LightVisibility::Visible`](crate::voxel::LightVisibility::Visible):
//!
//! * a point of a segment from any point of `B`'s cube to `L` lies within
//!   half a brick (chessboard) of the segment from `B`'s centre, so a voxel
//!   within one voxel of such a segment lies within ¾ brick of it, hence in
//!   a brick within chessboard distance 1 of a brick of its 6-connected
//!   line: the brick tube holds the voxel tube of every voxel of `B`;
//! * so every non-transparent voxel of a voxel's tube lies in a brick of
//!   the brick tube, whose records hold only `A`: exactly what the
//!   voxel-level walk would have found.
//!
//! The brick proof is therefore never `Visible` where the voxel walk is
//! not: it only spares walks, and a classification with or without it is
//! the same (a property test checks it). Where it fails (a brick of
//! several objects, or another object near the tube) the voxel walk
//! decides as before.
//!
//! The owners are made from the records, so the level assumes what a
//! built or derived raster guarantees: the plane's opaque voxels are the
//! records' voxels. (An opaque cell without a record is stepped over by a
//! renderer's exact shadow ray too.)

use super::{LightError, Piece, to_light};
use crate::discrete_ray::{DiscreteRay, WalkEnd};
use crate::fixed::voxel_centre;
use crate::proximity::{COARSE_EDGE, coarse_extent, distance_field};
use crate::raster::{Extent, Raster, RasterMut, cell, to_usize};
use crate::store::RecordStore;

/// Owner of a brick that holds no record.
pub const NO_RECORD: u32 = 0;

/// Owner of a brick whose records hold more than one object (or a record
/// holds several).
pub const SEVERAL: u32 = u32::MAX;

/// Bits of [`COARSE_EDGE`]: a brick coordinate is a voxel coordinate
/// shifted right by this.
const EDGE_BITS: u32 = COARSE_EDGE.trailing_zeros();

/// Fills `owners` (one entry per brick of `store`'s extent, in the order
/// of [`coarse_extent`]: x fastest) with each brick's owner: [`NO_RECORD`],
/// `id + 1` when every record of the brick holds object `id` alone, or
/// [`SEVERAL`]; and `plane` (as long) with [`cell::OPAQUE`] where a brick
/// holds a record, then its distance field. Returns `false`, filling
/// nothing, when the buffers do not have the brick count's length.
///
/// Work: one look at every record and the distance field over the bricks.
///
/// ```
/// use rrt_core::light::bricks::{shadow_bricks, NO_RECORD, SEVERAL};
/// use rrt_core::proximity::coarse_extent;
/// use rrt_core::raster::Extent;
/// use rrt_core::store::RecordStore;
/// use rrt_core::voxel::VoxelRecord;
/// let e = Extent::new(16, 8, 8).unwrap();
/// // Brick 0 holds one voxel of object 4; brick 1 voxels of objects 4 and 5.
/// let recs = [
///     VoxelRecord { key: 1, object: 4, ..Default::default() },
///     VoxelRecord { key: 1, object: 4, ..Default::default() },
///     VoxelRecord { key: 2, object: 5, ..Default::default() },
/// ];
/// let store = RecordStore::new(e, &[0, 1, 3], &recs).unwrap();
/// let n = coarse_extent(e).unwrap().len();
/// let (mut owners, mut plane) = (vec![0; n], vec![0; n]);
/// assert!(shadow_bricks(&store, &mut owners, &mut plane));
/// assert_eq!(owners, [5, SEVERAL]);
/// ```
pub fn shadow_bricks(store: &RecordStore<'_>, owners: &mut [u32], plane: &mut [u8]) -> bool {
    let Ok(bricks) = coarse_extent(store.extent()) else {
        return false;
    };
    if owners.len() != bricks.len() || plane.len() != bricks.len() {
        return false;
    }
    let dir = store.directory();
    let records = store.records();
    for (b, (owner, c)) in owners.iter_mut().zip(plane.iter_mut()).enumerate() {
        let lo = dir.get(b).map_or(0, |&d| to_usize(d));
        let hi = dir.get(b.wrapping_add(1)).map_or(lo, |&d| to_usize(d));
        let mut o = NO_RECORD;
        for rec in records.get(lo..hi).unwrap_or(&[]) {
            let id = match store.objects(rec) {
                [id] => id.checked_add(1).unwrap_or(SEVERAL),
                _ => SEVERAL,
            };
            o = if o == NO_RECORD || o == id {
                id
            } else {
                SEVERAL
            };
            if o == SEVERAL {
                break;
            }
        }
        *owner = o;
        *c = if o == NO_RECORD {
            cell::EMPTY
        } else {
            cell::OPAQUE
        };
    }
    if let Ok(mut r) = RasterMut::new(bricks, plane) {
        distance_field(&mut r);
    }
    true
}

/// The brick level of a raster (module docs): its owners and the plane of
/// bricks made by [`shadow_bricks`].
#[derive(Clone, Copy, Debug)]
pub struct ShadowBricks<'a> {
    /// The plane over the bricks, with its distance field.
    bricks: Raster<'a>,
    owners: &'a [u32],
    /// The raster's extent, in voxels.
    extent: Extent,
}

impl<'a> ShadowBricks<'a> {
    /// The level of a raster of `extent` from the buffers [`shadow_bricks`]
    /// filled; `None` when their lengths are not the brick count.
    #[must_use]
    pub fn new(extent: Extent, plane: &'a [u8], owners: &'a [u32]) -> Option<Self> {
        let bricks = coarse_extent(extent).ok()?;
        if owners.len() != bricks.len() {
            return None;
        }
        Some(Self {
            bricks: Raster::new(bricks, plane).ok()?,
            owners,
            extent,
        })
    }

    /// The raster's extent, in voxels.
    #[must_use]
    pub const fn extent(&self) -> Extent {
        self.extent
    }

    /// The index (in the owners' order) of the brick holding voxel `v`.
    #[must_use]
    pub fn brick_of(&self, v: [u32; 3]) -> Option<usize> {
        self.bricks.extent().index(v.map(|c| c >> EDGE_BITS))
    }

    /// The owner of brick `b` ([`NO_RECORD`], `id + 1` or [`SEVERAL`]).
    #[must_use]
    pub fn owner(&self, b: usize) -> u32 {
        self.owners.get(b).copied().unwrap_or(SEVERAL)
    }

    /// Whether the brick holding voxel `v` has one owner and every brick
    /// within chessboard distance 1 of its centre's 6-connected segment to
    /// the light at `light` (fixed units of the voxel raster) holds no
    /// record or only that owner's (module docs): then every voxel of the
    /// brick is classified lit for the light.
    ///
    /// # Errors
    /// [`LightError::Ray`] for a light beyond the fixed-point range.
    pub fn proves_lit(&self, v: [u32; 3], light: [i64; 3]) -> Result<bool, LightError> {
        let Some(b) = self.brick_of(v) else {
            return Ok(false);
        };
        let owner = self.owner(b);
        if owner == NO_RECORD || owner == SEVERAL {
            return Ok(false);
        }
        let extent = self.bricks.extent();
        let dims = extent.dims();
        let strides = extent.strides();
        let owners = self.owners;
        // Whether a brick within 1 of path brick `index` holds records of
        // another object.
        let mut foreign = |index: usize, _: u8| -> bool {
            let Some(u) = extent.coord(index) else {
                return true;
            };
            let range = |k: usize| {
                let lo = u[k].saturating_sub(1);
                let hi = u[k].saturating_add(1).min(dims[k].saturating_sub(1));
                lo..=hi
            };
            for z in range(2) {
                for y in range(1) {
                    for x in range(0) {
                        let i = to_usize(x)
                            .wrapping_add(to_usize(y).wrapping_mul(strides[1]))
                            .wrapping_add(to_usize(z).wrapping_mul(strides[2]));
                        let o = owners.get(i).copied().unwrap_or(SEVERAL);
                        if o != NO_RECORD && o != owner {
                            return true;
                        }
                    }
                }
            }
            false
        };
        // Brick units: the brick's centre, and the light scaled down by
        // the brick's edge (rounded down by less than 2^-16 brick, far
        // inside the quarter brick the proof leaves spare).
        let origin = self.bricks.extent().coord(b).unwrap_or([0; 3]);
        let centre = origin.map(voxel_centre);
        let light = light.map(|c| c >> EDGE_BITS);
        let outcome = to_light(extent, centre, light, |ray: Option<DiscreteRay>| {
            let Some(mut ray) = ray else {
                return Ok(Piece::Clear);
            };
            Ok(
                match ray.walk_dilated(&self.bricks, u32::MAX, &mut foreign)? {
                    WalkEnd::Hit => Piece::Blocked,
                    WalkEnd::Exit | WalkEnd::Budget => Piece::Clear,
                },
            )
        })?;
        Ok(outcome == Piece::Clear)
    }
}
