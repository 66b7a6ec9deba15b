//! The raster's frame for a scene: the box around all geometry grown by a
//! margin (or the caller's box), cubic voxels, `raster N` voxels along the
//! longest axis and the geometry centred.

use glam::DVec3;
use rrt_core::raster::{Extent, MAX_AXIS};

use super::{FitError, FitOptions};
use crate::frame::RasterFrame;
use crate::scene::Scene;

/// Margin in voxels around computed bounds by default.
pub const DEFAULT_MARGIN: u32 = 2;

/// The raster's frame for `scene` (no allocation, no conversion).
///
/// # Errors
/// As [`fit`](super::fit()), less the memory and range checks.
pub fn frame(scene: &Scene, opts: &FitOptions) -> Result<RasterFrame, FitError> {
    let n = opts.raster;
    if n == 0 || n > MAX_AXIS {
        return Err(FitError::RasterSize(n));
    }
    let (bounds, margin) = match opts.bounds {
        Some(b) => {
            if !(b.min.is_finite() && b.max.is_finite() && b.min.cmplt(b.max).all()) {
                return Err(FitError::BadBounds {
                    min: b.min,
                    max: b.max,
                });
            }
            (b, 0)
        }
        None => (scene.bounds(), opts.margin),
    };
    let inner = u64::from(n).saturating_sub(2 * u64::from(margin));
    if inner == 0 {
        return Err(FitError::RasterBelowMargin { raster: n, margin });
    }
    let size = bounds.size();
    let longest = size.max_element();
    if !(longest > 0.0 && longest.is_finite() && bounds.min.is_finite()) {
        return Err(FitError::NoExtent {
            file: scene.file.to_string(),
            min: bounds.min,
            max: bounds.max,
        });
    }
    let voxel = longest / inner as f64;
    let axis = size
        .to_array()
        .iter()
        .position(|&s| s == longest)
        .unwrap_or(0);
    let mut dims = [n; 3];
    for (k, d) in dims.iter_mut().enumerate() {
        if k != axis {
            // Tolerate rounding just above a whole number of voxels.
            let cells = (size[k] / voxel - 1e-9).ceil().max(0.0);
            let total = cells + 2.0 * f64::from(margin);
            *d = (total as u32).clamp(1, n);
        }
    }
    let extent = Extent::new(dims[0], dims[1], dims[2]).map_err(|_| FitError::RasterSize(n))?;
    let centre = (bounds.min + bounds.max) * 0.5;
    let origin = centre - DVec3::from(dims.map(f64::from)) * (voxel * 0.5);
    Ok(RasterFrame {
        extent,
        origin,
        voxel_size: voxel,
    })
}
