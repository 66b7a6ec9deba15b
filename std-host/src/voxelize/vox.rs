//! MagicaVoxel models in the raster: each world cell of a model as
//! `scale³` raster voxels at a placement, with the palette colours.

use std::collections::HashMap;
use std::sync::Arc;

use rrt_core::fixed::FRAC_BITS;
use rrt_core::store::Texture;
use rrt_core::voxelize::{Surfel, VoxelSink};

use super::BuildError;
use super::pass::Pass;
use crate::assets::vox::VoxScene;
use crate::frame::RasterFrame;
use crate::scene::VoxObject;

/// Where a scene's world cells go in the raster: cell `c` covers raster
/// voxels `offset + c·scale + [0, scale)³`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct VoxPlacement {
    /// Raster voxel of world cell (0, 0, 0).
    pub offset: [i64; 3],
    /// Raster voxels per cell edge (at least 1).
    pub scale: u32,
}

impl VoxScene {
    /// Offers every voxel of the scene to `sink` at `placement` (each
    /// world cell as `scale³` raster voxels, all with the cell's normal,
    /// distance 0), clipped to a raster of `dims` voxels and to the rows
    /// and layers the sink keeps; returns the offers made. Colour them
    /// through [`VoxScene::colors`] with the same placement (the
    /// builder's `Filler::textured`). Work: the world voxels plus the
    /// offers.
    pub fn voxelize<S: VoxelSink + ?Sized>(
        &self,
        placement: VoxPlacement,
        dims: [u32; 3],
        sink: &mut S,
    ) -> u64 {
        let s = i64::from(placement.scale.max(1));
        let (rows, layers) = (sink.rows(), sink.layers());
        // Raster voxels kept along each axis: `lo[a] .. hi[a]`.
        let lo = [0, i64::from(rows.start), i64::from(layers.start)];
        let hi = [
            i64::from(dims[0]),
            i64::from(rows.end.min(dims[1])),
            i64::from(layers.end.min(dims[2])),
        ];
        let mut n = 0u64;
        self.for_each_world_voxel(|v| {
            // The cell's voxels kept, per axis (empty when it misses).
            let span: [(i64, i64); 3] = std::array::from_fn(|a| {
                let base = placement.offset[a].saturating_add(v.cell[a].saturating_mul(s));
                (base.max(lo[a]), base.saturating_add(s).min(hi[a]))
            });
            if span.iter().any(|(a, b)| a >= b) {
                return;
            }
            for z in span[2].0..span[2].1 {
                for y in span[1].0..span[1].1 {
                    for x in span[0].0..span[0].1 {
                        // Within 0 .. dims: each fits in u32.
                        sink.offer(
                            [x, y, z].map(|c| u32::try_from(c).unwrap_or(u32::MAX)),
                            Surfel {
                                normal: v.normal,
                                distance: 0,
                            },
                        );
                        n += 1;
                    }
                }
            }
        });
        n
    }

    /// The per-voxel colours at `placement`, as a core [`Texture`].
    #[must_use]
    pub fn colors(&self, placement: VoxPlacement) -> VoxColors {
        VoxColors {
            placement,
            cells: self.world_colors(),
        }
    }
}

/// The palette colour of each placed world cell, looked up from a raster
/// voxel centre (a core [`Texture`]); the base colour elsewhere.
#[derive(Clone, Debug)]
pub struct VoxColors {
    placement: VoxPlacement,
    cells: Arc<HashMap<[i64; 3], [u8; 3]>>,
}

impl Texture for VoxColors {
    fn color(&self, centre: [i64; 3], _normal: [i32; 3], base: [u8; 3]) -> [u8; 3] {
        let s = i64::from(self.placement.scale.max(1));
        let cell: [i64; 3] = std::array::from_fn(|a| {
            (centre[a] >> FRAC_BITS)
                .saturating_sub(self.placement.offset[a])
                .div_euclid(s)
        });
        self.cells.get(&cell).copied().unwrap_or(base)
    }
}

/// Most raster voxels per `.vox` cell edge.
pub const MAX_VOX_SCALE: u32 = 4096;

/// The raster placement of a `.vox` model: its origin's voxel, and
/// `cell / voxel size` voxels (rounded, at least 1) per cell.
///
/// # Errors
/// [`FitError::OutOfRange`](crate::fit::FitError::OutOfRange) for a model
/// too far out or cells too large.
pub fn placement(v: &VoxObject, frame: &RasterFrame) -> Result<VoxPlacement, BuildError> {
    let scale = (v.cell / frame.voxel_size).round().max(1.0);
    if scale.is_nan() || scale > f64::from(MAX_VOX_SCALE) {
        return Err(BuildError::VoxCell {
            loc: v.loc.clone(),
            voxels: scale,
        });
    }
    let o = frame.world_to_raster(v.position).floor();
    if !(o.is_finite() && o.abs().max_element() < f64::from(1u32 << 30)) {
        return Err(BuildError::out_of_range(
            &v.loc,
            "vox model (its position, moved by the file's scene-graph translations)",
        ));
    }
    Ok(VoxPlacement {
        offset: [o.x as i64, o.y as i64, o.z as i64],
        scale: scale as u32,
    })
}

/// Voxelizes a `.vox` model into `pass`, with its palette colours.
///
/// # Errors
/// As [`placement`]; the store's.
pub(super) fn voxelize_object(
    v: &VoxObject,
    frame: &RasterFrame,
    pass: Pass<'_, '_, '_, '_>,
) -> Result<(), BuildError> {
    let placement = placement(v, frame)?;
    match pass {
        Pass::Count(c) => {
            v.vox.voxelize(placement, frame.dims(), c);
        }
        Pass::Fill { filler, attrs, .. } => {
            filler.begin_object(attrs)?;
            let colors = v.vox.colors(placement);
            let mut s = filler.textured(&colors);
            v.vox.voxelize(placement, frame.dims(), &mut s);
        }
    }
    Ok(())
}
