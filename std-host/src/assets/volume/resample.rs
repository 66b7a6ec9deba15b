//! Resampling to cubic voxels and placing a volume in the world.
//!
//! The 3D raster's voxels are cubes; a scan's samples often are not
//! (the density map here is 0.545 × 0.545 × 0.560 Å). There are two ways
//! to bring them together, both trilinear:
//!
//! * [`resample_cubic`] makes a new [`Volume`] with cubic cells of a given
//!   size in the data's physical units (to save, inspect or reuse);
//! * a [`PlacedVolume`] is sampled directly at the centres of the raster
//!   voxels it covers, whatever its spacing, when the scene is voxelized
//!   ([`crate::voxelize::volume`]): the volume lands at its world
//!   placement, at the raster's resolution, next to geometry.
//!
//! ```
//! use glam::DVec3;
//! use rrt_host::assets::volume::{Grid, Placement, Samples, Volume};
//! // 2×2×2 samples 10 mm apart, sample (0,0,0) at the physical origin.
//! let v = Volume::new([2, 2, 2], Grid::axis_aligned([10.0; 3], DVec3::ZERO),
//!                     Samples::U8(vec![0, 0, 0, 0, 0, 0, 0, 200])).unwrap();
//! // 1 mm = 0.1 world units; the volume's cells span −0.5..1.5 world.
//! let placed = Placement::new(DVec3::ZERO, 0.1).unwrap().place(&v);
//! assert_eq!(placed.sample_world(DVec3::splat(1.0)), Some(200.0));
//! assert_eq!(placed.sample_world(DVec3::splat(0.5)), Some(25.0));
//! ```

use glam::{DAffine3, DMat3, DVec3};
use rayon::prelude::*;

use super::{Grid, Limits, SampleType, Samples, Volume, VolumeError};
use crate::world::Bounds;

/// Largest value of a quantized sample ([`Quantizer`]).
pub const SAMPLE_MAX: u16 = u16::MAX;

/// Resamples `volume` onto an axis-aligned grid of cubic cells of edge
/// `voxel` (physical units), covering the volume's physical box (the
/// cells' box, [`Volume::physical_bounds`]) and centred on it. Each new
/// sample is the trilinear value of the old grid at its centre; where that
/// lies outside the old cells (corners of a rotated grid) it gets the
/// volume's minimum. Integer types round to nearest.
///
/// # Errors
/// [`VolumeError::Invalid`] for a voxel size that is not finite and
/// positive or a result with more than [`super::MAX_AXIS`] samples on an
/// axis; [`VolumeError::TooLarge`] when the result exceeds
/// `limits.max_bytes` (checked before allocating).
pub fn resample_cubic(volume: &Volume, voxel: f64, limits: &Limits) -> Result<Volume, VolumeError> {
    let what = || "cubic resampling".to_string();
    if !(voxel.is_finite() && voxel > 0.0) {
        return Err(VolumeError::Invalid {
            what: what(),
            msg: format!("voxel size {voxel} is not a positive number"),
        });
    }
    let b = volume.physical_bounds();
    let size = b.size();
    let mut dims = [0u32; 3];
    for axis in 0..3 {
        let n = (size[axis] / voxel - 1e-9).ceil().max(1.0);
        if n > f64::from(super::MAX_AXIS) {
            return Err(VolumeError::Invalid {
                what: what(),
                msg: format!(
                    "voxel size {voxel} gives more than {} samples along axis {axis}",
                    super::MAX_AXIS
                ),
            });
        }
        // 1 <= n <= 2^16.
        dims[axis] = n as u32;
    }
    let ty = volume.sample_type();
    let count = super::check_size(
        std::path::Path::new("resampled volume"),
        String::new(),
        dims,
        ty,
        limits,
    )?;
    let covered = DVec3::from(dims.map(f64::from)) * voxel;
    let origin = b.min + (size - covered) * 0.5 + voxel * 0.5;
    let grid = Grid::axis_aligned([voxel; 3], origin);
    let (lo, _) = volume.range();
    let [nx, ny, _] = dims;
    let at = |n: usize| -> f64 {
        // n < count <= 2^48.
        let n = n as u64;
        let i = n % u64::from(nx);
        let j = (n / u64::from(nx)) % u64::from(ny);
        let k = n / (u64::from(nx) * u64::from(ny));
        let p = origin + DVec3::new(i as f64, j as f64, k as f64) * voxel;
        volume.sample_physical(p).unwrap_or(lo)
    };
    let samples = match ty {
        SampleType::U8 => Samples::U8(
            (0..count)
                .into_par_iter()
                .map(|n| round_to(at(n)))
                .collect(),
        ),
        SampleType::I16 => Samples::I16(
            (0..count)
                .into_par_iter()
                .map(|n| round_to(at(n)))
                .collect(),
        ),
        SampleType::U16 => Samples::U16(
            (0..count)
                .into_par_iter()
                .map(|n| round_to(at(n)))
                .collect(),
        ),
        // Trilinear values of f32 samples: nearest f32.
        #[allow(clippy::cast_possible_truncation)]
        SampleType::F32 => Samples::F32((0..count).into_par_iter().map(|n| at(n) as f32).collect()),
    };
    Ok(Volume::new(dims, grid, samples)?.with_geometry_known(volume.geometry_known()))
}

/// Rounds a value interpolated between samples of an integer type back to
/// that type (always in range: it lies between two of its values).
fn round_to<T: TryFrom<i64> + Default>(v: f64) -> T {
    // Between two samples of T: |v| < 2^16, exact.
    T::try_from(v.round() as i64).unwrap_or_default()
}

/// Where a volume sits in the world: a world point is
/// `translation + scale · rotation · physical` (physical: the data's own
/// coordinates, [`Volume::index_to_physical`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Placement {
    /// Physical → world.
    to_world: DAffine3,
}

impl Placement {
    /// The physical coordinates are world coordinates.
    pub const IDENTITY: Self = Self {
        to_world: DAffine3::IDENTITY,
    };

    /// World = `translation + scale · physical`.
    ///
    /// # Errors
    /// [`VolumeError::Invalid`] unless everything is finite and `scale`
    /// is positive.
    pub fn new(translation: DVec3, scale: f64) -> Result<Self, VolumeError> {
        Self::from_affine(DAffine3::from_scale_rotation_translation(
            DVec3::splat(scale),
            glam::DQuat::IDENTITY,
            translation,
        ))
        .and_then(|p| {
            if scale > 0.0 {
                Ok(p)
            } else {
                Err(VolumeError::Invalid {
                    what: "volume placement".into(),
                    msg: format!("scale {scale} is not positive"),
                })
            }
        })
    }

    /// Any invertible affine map physical → world (rotations, mirrors,
    /// non-uniform scales).
    ///
    /// # Errors
    /// [`VolumeError::Invalid`] for a map that is not finite or not
    /// invertible.
    pub fn from_affine(to_world: DAffine3) -> Result<Self, VolumeError> {
        let det = to_world.matrix3.determinant();
        if !to_world.is_finite() || !det.is_finite() || det.abs() < 1e-300 {
            return Err(VolumeError::Invalid {
                what: "volume placement".into(),
                msg: "the map to the world is not finite or not invertible".into(),
            });
        }
        Ok(Self { to_world })
    }

    /// Scales (uniformly) and translates `volume` so that its physical box
    /// fits `target` exactly along its tightest axis, centred in it.
    ///
    /// # Errors
    /// [`VolumeError::Invalid`] for an empty or non-finite target box.
    pub fn fit_into(volume: &Volume, target: Bounds) -> Result<Self, VolumeError> {
        let t = target.size();
        if target.is_empty() || !t.is_finite() || t.min_element() <= 0.0 {
            return Err(VolumeError::Invalid {
                what: "volume placement".into(),
                msg: format!("target box {} to {} has no size", target.min, target.max),
            });
        }
        let b = volume.physical_bounds();
        let s = (t / b.size()).min_element();
        let centre_phys = (b.min + b.max) * 0.5;
        let centre_world = (target.min + target.max) * 0.5;
        Self::new(centre_world - centre_phys * s, s)
    }

    /// The physical → world map.
    #[must_use]
    pub const fn to_world(&self) -> DAffine3 {
        self.to_world
    }

    /// `volume` at this placement.
    #[must_use]
    pub fn place(self, volume: &Volume) -> PlacedVolume<'_> {
        let index_to_world = self.to_world
            * DAffine3::from_mat3_translation(volume.grid().matrix(), volume.origin());
        PlacedVolume {
            volume,
            placement: self,
            world_to_index: index_to_world.inverse(),
            index_to_world,
        }
    }
}

/// A volume at a placement in the world (cheap to copy: it borrows the
/// volume).
#[derive(Clone, Copy, Debug)]
pub struct PlacedVolume<'a> {
    volume: &'a Volume,
    placement: Placement,
    index_to_world: DAffine3,
    world_to_index: DAffine3,
}

/// The linear map from a volume's values to the `u16` grid:
/// `q(v) = round((v − lo) · scale)`, clamped to `0..=65535`.
///
/// `uint8` maps `v ↦ 256·v` (room for 8 fractional bits of the trilinear
/// value), `uint16` is exact, `int16` shifts by 32768, `float` maps the
/// volume's range onto the whole `u16` range.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Quantizer {
    /// Value mapped to 0.
    pub lo: f64,
    /// Quanta per value unit.
    pub scale: f64,
}

impl Quantizer {
    /// The quantizer for `volume`'s type (and range, for `float`).
    #[must_use]
    pub fn for_volume(volume: &Volume) -> Self {
        match volume.sample_type() {
            SampleType::U8 => Self {
                lo: 0.0,
                scale: 256.0,
            },
            SampleType::U16 => Self {
                lo: 0.0,
                scale: 1.0,
            },
            SampleType::I16 => Self {
                lo: -32768.0,
                scale: 1.0,
            },
            SampleType::F32 => {
                let (lo, hi) = volume.range();
                let span = hi - lo;
                Self {
                    lo,
                    scale: if span > 0.0 && span.is_finite() {
                        f64::from(SAMPLE_MAX) / span
                    } else {
                        1.0
                    },
                }
            }
        }
    }

    /// `q(v)`, clamped; NaN gives 0.
    #[must_use]
    pub fn quantize(&self, v: f64) -> u16 {
        let q = ((v - self.lo) * self.scale).round();
        if q.is_nan() {
            return 0;
        }
        // Clamped to the u16 range first.
        q.clamp(0.0, f64::from(SAMPLE_MAX)) as u16
    }

    /// The value a quantum `q` stands for.
    #[must_use]
    pub fn value(&self, q: u16) -> f64 {
        self.lo + f64::from(q) / self.scale
    }
}

impl<'a> PlacedVolume<'a> {
    /// The volume.
    #[must_use]
    pub const fn volume(&self) -> &'a Volume {
        self.volume
    }

    /// The placement.
    #[must_use]
    pub const fn placement(&self) -> Placement {
        self.placement
    }

    /// Continuous index coordinates → world.
    #[must_use]
    pub fn index_to_world(&self, p: DVec3) -> DVec3 {
        self.index_to_world.transform_point3(p)
    }

    /// World → continuous index coordinates.
    #[must_use]
    pub fn world_to_index(&self, p: DVec3) -> DVec3 {
        self.world_to_index.transform_point3(p)
    }

    /// The index → world linear part (for transforming gradients:
    /// a world gradient is `inverse-transpose · index gradient`).
    #[must_use]
    pub fn index_to_world_matrix(&self) -> DMat3 {
        self.index_to_world.matrix3
    }

    /// The world box around the volume's cells.
    #[must_use]
    pub fn world_bounds(&self) -> Bounds {
        Bounds::around(self.volume.cell_corners().map(|c| self.index_to_world(c)))
    }

    /// The volume's trilinear value at a world point, `None` outside its
    /// cells.
    #[must_use]
    pub fn sample_world(&self, p: DVec3) -> Option<f64> {
        self.volume.sample_index(self.world_to_index(p))
    }
}
