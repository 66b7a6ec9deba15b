//! The raster's frame for a scene: the box around all geometry grown by a
//! margin (or the caller's box), cubic voxels, `raster N` voxels along the
//! longest axis and the geometry centred.

use glam::DVec3;
use rrt_core::raster::{Extent, MAX_AXIS};

use super::memory::SurfaceMeasure;
use super::{FitError, FitOptions};
use crate::frame::RasterFrame;
use crate::scene::{Scene, View};

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
            if !(b.within_world() && b.min.cmplt(b.max).all()) {
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
    if !(longest > 0.0 && longest.is_finite() && bounds.within_world()) {
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

/// The fewest voxels along the longest axis [`default_raster`] picks.
pub const MIN_DEFAULT_RASTER: u32 = 64;
/// The most voxels along the longest axis [`default_raster`] picks.
pub const MAX_DEFAULT_RASTER: u32 = 1024;
/// Rays per image for each estimated surface voxel of the default raster
/// ([`default_raster`]): where objects have exact geometry the image is
/// the same at any raster, and a finer one costs more to voxelize, to
/// classify for shadows and to walk than its smaller voxels save in
/// intersection tests, until voxels crowd with objects ([`CROWDING`]).
/// Set where the whole job (build and render) was fastest on the SPD
/// scenes (`BENCHMARKS.md`, *The default raster where objects have exact
/// geometry*).
pub const RAYS_PER_VOXEL: f64 = 16.0;
/// The fewest estimated surface voxels per surface primitive
/// [`default_raster`] accepts, in units of the 8 voxels a tiny primitive's
/// conservative voxelization takes: with fewer, voxels hold so many
/// objects that verifying them costs more than a finer raster saves.
pub const CROWDING: f64 = 8.0;

/// What a raster is for, to [`default_raster`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RasterNeed<'v> {
    /// The view the raster will be seen from.
    pub view: &'v View,
    /// Image width and height in pixels.
    pub image: [u32; 2],
    /// Rays per pixel (supersampling `k` gives `k²`).
    pub samples: u32,
    /// Whether hits are the voxels themselves (the paper's mode), so that
    /// voxels must be no larger than a pixel's footprint.
    pub discrete: bool,
}

/// The raster size (voxels along the scene's longest axis) used when none
/// is given: fitted to the scene and the image, between
/// [`MIN_DEFAULT_RASTER`] and [`MAX_DEFAULT_RASTER`].
///
/// Objects with exact geometry are rendered exactly whatever the raster
/// (verification), so for them the raster is an acceleration structure:
/// the size is the largest whose estimated surface voxels
/// ([`SurfaceMeasure::voxels`]) do not exceed the rays per image over
/// [`RAYS_PER_VOXEL`] (more voxels cost more to build and to walk than
/// they save), but at least the size at which voxels do not crowd
/// ([`CROWDING`]); a scene without surface primitives (volumes, `.vox`
/// models, CSG only) starts from [`MIN_DEFAULT_RASTER`]. Where voxels are the picture (the paper's mode;
/// volumes, `.vox` models and CSG results, which have no exact geometry),
/// a voxel is in addition no larger than a pixel's footprint at the
/// scene's nearest point to the eye. With volumes rendered directly, a
/// voxel is no smaller than their finest sample spacing.
#[must_use]
pub fn default_raster(scene: &Scene, need: &RasterNeed<'_>) -> u32 {
    let bounds = scene.bounds();
    let longest = bounds.size().max_element();
    if !(longest > 0.0 && longest.is_finite()) {
        return MIN_DEFAULT_RASTER;
    }
    let inner = |r: u32| f64::from(r.saturating_sub(2 * DEFAULT_MARGIN).max(1));
    let surface = SurfaceMeasure::of(scene);
    let voxels_at = |r: u32| surface.voxels(longest / inner(r));
    let [w, h] = need.image.map(f64::from);
    let rays = w * h * f64::from(need.samples).powi(2);
    let (lo, hi) = (MIN_DEFAULT_RASTER, MAX_DEFAULT_RASTER);
    // The largest size within the ray budget, and the smallest that does
    // not crowd (both monotone in the size: bisect). Without surface
    // primitives there is nothing for the raster to accelerate.
    let within = if surface.objects == 0 {
        lo
    } else {
        last_true(lo, hi, |r| voxels_at(r) * RAYS_PER_VOXEL <= rays.max(1.0))
    };
    let crowd = 8.0 * CROWDING * surface.objects as f64;
    let uncrowded = if voxels_at(lo) < crowd {
        last_true(lo, hi, |r| voxels_at(r) < crowd).saturating_add(1)
    } else {
        lo
    };
    let mut r = within.max(uncrowded.min(hi));
    let voxel_objects =
        !(scene.volumes.is_empty() && scene.voxes.is_empty() && scene.csgs.is_empty());
    if need.discrete || voxel_objects {
        r = r.max(pixel_raster(&bounds, longest, need));
    }
    // Volumes rendered directly are pictures of their samples: voxels
    // finer than the finest sample spacing add records, not detail.
    let spacing = scene
        .volumes
        .iter()
        .filter(|v| v.data.classifier.is_direct())
        .map(|v| v.data.sample_spacing())
        .fold(f64::INFINITY, f64::min);
    if spacing > 0.0 && spacing.is_finite() {
        let samples = (longest / spacing).ceil() + f64::from(2 * DEFAULT_MARGIN);
        if samples < f64::from(r) {
            // Below r ≤ 2^16.
            r = samples as u32;
        }
    }
    r.clamp(lo, hi)
}

/// The largest `r` in `lo..=hi` with `ok(r)` for a predicate true up to
/// some size and false after it; `lo` if it is false everywhere.
fn last_true(lo: u32, hi: u32, ok: impl Fn(u32) -> bool) -> u32 {
    let (mut a, mut b) = (lo, hi);
    if !ok(a) {
        return lo;
    }
    while a < b {
        let m = a + (b - a).div_ceil(2);
        if ok(m) { a = m } else { b = m - 1 }
    }
    a
}

/// The raster size whose voxels are as large as a pixel's footprint at
/// the point of `bounds` nearest the eye (the longest axis `longest`
/// over that footprint); [`MAX_DEFAULT_RASTER`] when the eye is inside.
fn pixel_raster(bounds: &crate::world::Bounds, longest: f64, need: &RasterNeed<'_>) -> u32 {
    let eye = need.view.from;
    let nearest = eye.clamp(bounds.min, bounds.max);
    let d = (nearest - eye).length();
    let rows = f64::from(need.image[1].max(2) - 1);
    let pitch = 2.0 * (need.view.angle.to_radians() * 0.5).tan() / rows;
    let footprint = d * pitch / f64::from(need.samples.max(1));
    if !(footprint > 0.0 && footprint.is_finite()) {
        return MAX_DEFAULT_RASTER;
    }
    let r = (longest / footprint).ceil() + f64::from(2 * DEFAULT_MARGIN);
    if r >= f64::from(MAX_DEFAULT_RASTER) {
        MAX_DEFAULT_RASTER
    } else {
        r as u32
    }
}
