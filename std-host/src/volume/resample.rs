//! Resampling to cubic voxels, placing a volume in the world, and the
//! scalar grid over the raster voxels a placed volume covers.
//!
//! The 3D raster's voxels are cubes; a scan's samples often are not
//! (the density map here is 0.545 × 0.545 × 0.560 Å). There are two ways
//! to bring them together, both trilinear:
//!
//! * [`resample_cubic`] makes a new [`Volume`] with cubic cells of a given
//!   size in the data's physical units (to save, inspect or reuse);
//! * [`PlacedVolume::raster_block`] samples the placed volume directly at
//!   the centres of the raster voxels it covers, whatever its spacing, and
//!   gives the grid the core's volume voxelizer takes: one `u16` per
//!   raster voxel and a threshold ([`RasterBlock`]). This is what a scene
//!   uses: the volume lands at its world placement, at the raster's
//!   resolution, next to geometry.
//!
//! ```
//! use glam::DVec3;
//! use rrt_core::raster::Extent;
//! use rrt_host::frame::RasterFrame;
//! use rrt_host::volume::{Classifier, Grid, Placement, Samples, Volume};
//! // 2×2×2 samples 10 mm apart, sample (0,0,0) at the physical origin.
//! let v = Volume::new([2, 2, 2], Grid::axis_aligned([10.0; 3], DVec3::ZERO),
//!                     Samples::U8(vec![0, 0, 0, 0, 0, 0, 0, 200])).unwrap();
//! // 1 mm = 0.1 world units; the volume's cells span −0.5..1.5 world.
//! let placed = Placement::new(DVec3::ZERO, 0.1).unwrap().place(&v);
//! assert_eq!(placed.sample_world(DVec3::splat(1.0)), Some(200.0));
//! assert_eq!(placed.sample_world(DVec3::splat(0.5)), Some(25.0));
//! // A raster of 0.25-unit voxels from −1 to 3.
//! let frame = RasterFrame { extent: Extent::cube(16).unwrap(),
//!                           origin: DVec3::splat(-1.0), voxel_size: 0.25 };
//! let block = placed.raster_block(&frame, &Classifier::iso(100.0), 1 << 20).unwrap().unwrap();
//! assert_eq!(block.offset, [2, 2, 2]);
//! assert_eq!(block.dims, [8, 8, 8]);
//! ```

#![deny(missing_docs)]

use std::ops::Range;

use glam::{DAffine3, DMat3, DVec3};
use rayon::prelude::*;
use rrt_core::voxelize::volume::{self, Block};
use rrt_core::voxelize::{Separation, Surfel, VoxelSink};

use super::{Classifier, DimsFmt, Grid, Limits, SampleType, Samples, Volume, VolumeError};
use crate::frame::RasterFrame;
use crate::world::Bounds;

/// A predicate on raster voxels: which to keep (see
/// [`PlacedVolume::voxelize_where`]).
pub type Keep<'k> = &'k (dyn Fn([u32; 3]) -> bool + Sync);

/// Largest value of the raster grid's samples.
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

/// The scalar grid of a placed volume over a box of raster voxels, in the
/// form the core's volume voxelizer takes
/// (`rrt_core::voxelize::volume::Block { samples, dims, offset }` and a
/// threshold of the same type).
///
/// Sample `(i, j, k)` (x fastest) belongs to raster voxel
/// `offset + (i, j, k)`. Its value is the placed volume's trilinear value
/// at that voxel's centre, quantized to `u16` ([`Quantizer`]) and then
/// moved to the right side of `threshold`: a voxel is at or above the
/// threshold exactly when the classifier calls its value non-transparent
/// ([`Classifier::is_opaque`]). So the inside set is decided in `f64`,
/// and quantization only touches the gray-level gradient (by at most one
/// quantum). Voxels outside the volume are 0, below any threshold.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct RasterBlock {
    /// The samples, x fastest.
    pub samples: Vec<u16>,
    /// Samples per axis.
    pub dims: [u32; 3],
    /// Raster voxel of sample `(0, 0, 0)`.
    pub offset: [i64; 3],
    /// Samples at or above this are non-transparent (at least 1).
    pub threshold: u16,
}

impl RasterBlock {
    /// Sample `(i, j, k)`, `None` outside.
    #[must_use]
    pub fn get(&self, i: u32, j: u32, k: u32) -> Option<u16> {
        let [nx, ny, nz] = self.dims;
        if i >= nx || j >= ny || k >= nz {
            return None;
        }
        let lin = u64::from(i) + u64::from(nx) * (u64::from(j) + u64::from(ny) * u64::from(k));
        self.samples.get(usize::try_from(lin).ok()?).copied()
    }

    /// The sample of raster voxel `v`, `None` outside the block.
    #[must_use]
    pub fn at_voxel(&self, v: [u32; 3]) -> Option<u16> {
        let mut l = [0u32; 3];
        for axis in 0..3 {
            let d = i64::from(v[axis]) - self.offset[axis];
            l[axis] = u32::try_from(d).ok()?;
        }
        self.get(l[0], l[1], l[2])
    }

    /// Number of samples at or above the threshold.
    #[must_use]
    pub fn count_inside(&self) -> u64 {
        self.samples
            .iter()
            .filter(|&&s| s >= self.threshold)
            .count() as u64
    }
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
        let hi = DVec3::from(self.volume.dims().map(f64::from)) - 0.5;
        let mut b = Bounds::EMPTY;
        for corner in 0..8u8 {
            let c = DVec3::new(
                if corner & 1 == 0 { -0.5 } else { hi.x },
                if corner & 2 == 0 { -0.5 } else { hi.y },
                if corner & 4 == 0 { -0.5 } else { hi.z },
            );
            let p = self.index_to_world(c);
            b.min = b.min.min(p);
            b.max = b.max.max(p);
        }
        b
    }

    /// The volume's trilinear value at a world point, `None` outside its
    /// cells.
    #[must_use]
    pub fn sample_world(&self, p: DVec3) -> Option<f64> {
        self.volume.sample_index(self.world_to_index(p))
    }

    /// The raster voxels whose centres may lie in the volume: the box
    /// around [`PlacedVolume::world_bounds`] in raster coordinates,
    /// clipped to the raster, as `(first voxel, voxels per axis)`; `None`
    /// when the volume misses the raster.
    #[must_use]
    pub fn raster_box(&self, frame: &RasterFrame) -> Option<([u32; 3], [u32; 3])> {
        let b = self.world_bounds();
        let lo = frame.world_to_raster(b.min);
        let hi = frame.world_to_raster(b.max);
        let dims = frame.dims();
        let mut first = [0u32; 3];
        let mut n = [0u32; 3];
        for axis in 0..3 {
            // Centres i + ½ in [lo, hi]: i from ceil(lo − ½) to floor(hi − ½).
            let a = (lo[axis] - 0.5).ceil().max(0.0);
            let z = (hi[axis] - 0.5).floor().min(f64::from(dims[axis]) - 1.0);
            // NaN bounds fail too.
            if a.partial_cmp(&z)
                .is_none_or(|o| o == std::cmp::Ordering::Greater)
            {
                return None;
            }
            // 0 <= a <= z < 2^16.
            first[axis] = a as u32;
            n[axis] = (z - a) as u32 + 1;
        }
        Some((first, n))
    }

    /// The scalar grid over every raster voxel the volume covers
    /// ([`PlacedVolume::raster_box`]), classified by `classifier`
    /// ([`RasterBlock`]); `None` when the volume misses the raster.
    ///
    /// # Errors
    /// [`VolumeError::Invalid`] for a classifier with a non-finite
    /// iso-value; [`VolumeError::TooLarge`] when the block would take more
    /// than `max_bytes` (2 bytes per voxel), checked before allocating
    /// (use [`PlacedVolume::raster_slabs`] to bound memory instead).
    pub fn raster_block(
        &self,
        frame: &RasterFrame,
        classifier: &Classifier,
        max_bytes: u64,
    ) -> Result<Option<RasterBlock>, VolumeError> {
        let Some((first, n)) = self.raster_box(frame) else {
            return Ok(None);
        };
        self.block_for(frame, classifier, first, n, None, max_bytes)
            .map(Some)
    }

    /// The grid in slabs along z of at most `max_bytes` each, for volumes
    /// whose whole block would not fit: each slab carries one layer of
    /// halo above and below (so boundary tests and gradients see the true
    /// neighbours) and the z range of raster voxels it owns. Voxelize each
    /// slab through a [`ClipZ`] sink with that range, and the union equals
    /// the voxelization of the whole block.
    ///
    /// # Errors
    /// As [`PlacedVolume::raster_block`]; [`VolumeError::TooLarge`] also
    /// when not even a 3-layer slab fits `max_bytes`.
    pub fn raster_slabs<'s>(
        &'s self,
        frame: &'s RasterFrame,
        classifier: &'s Classifier,
        max_bytes: u64,
    ) -> Result<
        impl Iterator<Item = Result<(RasterBlock, Range<u32>), VolumeError>> + 's,
        VolumeError,
    > {
        self.slabs(frame, classifier, max_bytes, None)
    }

    fn slabs<'s>(
        &'s self,
        frame: &'s RasterFrame,
        classifier: &'s Classifier,
        max_bytes: u64,
        keep: Option<Keep<'s>>,
    ) -> Result<
        impl Iterator<Item = Result<(RasterBlock, Range<u32>), VolumeError>> + 's,
        VolumeError,
    > {
        classifier.validate()?;
        let boxed = self.raster_box(frame);
        let (first, n) = boxed.unwrap_or(([0; 3], [0; 3]));
        let layer = u64::from(n[0]) * u64::from(n[1]) * 2;
        let layers = max_bytes.checked_div(layer).unwrap_or(3);
        if boxed.is_some() && layers < 3 {
            return Err(VolumeError::TooLarge {
                path: "raster slab".into(),
                at: String::new(),
                dims: DimsFmt([n[0], n[1], 3]),
                ty: SampleType::U16,
                bytes: layer.saturating_mul(3),
                limit: max_bytes,
            });
        }
        // Owned layers per slab: two are halo.
        let own = u32::try_from(layers.saturating_sub(2))
            .unwrap_or(u32::MAX)
            .max(1);
        let z0 = first[2];
        let z1 = first[2] + n[2];
        let starts = (z0..z1).step_by(usize::try_from(own).unwrap_or(usize::MAX));
        Ok(starts.map(move |s| {
            let e = s.saturating_add(own).min(z1);
            let lo = s.saturating_sub(1).max(z0);
            let hi = e.saturating_add(1).min(z1);
            let block = self.block_for(
                frame,
                classifier,
                [first[0], first[1], lo],
                [n[0], n[1], hi - lo],
                keep,
                max_bytes,
            )?;
            Ok((block, s..e))
        }))
    }

    /// Voxelizes the placed volume into `sink` with the core's volume
    /// voxelizer (`rrt_core::voxelize::volume::boundary`: the boundary
    /// layer of the classified voxels, gray-level gradient normals), in z
    /// slabs of at most `max_block_bytes` each ([`PlacedVolume::raster_slabs`]),
    /// so memory stays bounded whatever the volume's size. The voxels and
    /// surfels are the same as for one whole block. Returns the voxels
    /// offered (each once).
    ///
    /// # Errors
    /// As [`PlacedVolume::raster_slabs`]; [`VolumeError::Invalid`] if the
    /// core refuses a block (offsets beyond its coordinate limit).
    pub fn voxelize<S: VoxelSink + ?Sized>(
        &self,
        frame: &RasterFrame,
        classifier: &Classifier,
        separation: Separation,
        max_block_bytes: u64,
        sink: &mut S,
    ) -> Result<u64, VolumeError> {
        self.voxelize_where(frame, classifier, separation, max_block_bytes, None, sink)
    }

    /// [`PlacedVolume::voxelize`] keeping only the raster voxels for which
    /// `keep` is true: the others count as transparent *before* the
    /// boundary layer is found, so a CSG cut (the paper's box subtracted
    /// from the MRI head) exposes a closed cut surface, whose gray-level
    /// normals point out of the remaining volume into the cut.
    ///
    /// # Errors
    /// As [`PlacedVolume::voxelize`].
    pub fn voxelize_where<S: VoxelSink + ?Sized>(
        &self,
        frame: &RasterFrame,
        classifier: &Classifier,
        separation: Separation,
        max_block_bytes: u64,
        keep: Option<Keep<'_>>,
        sink: &mut S,
    ) -> Result<u64, VolumeError> {
        struct Count<'s, S: ?Sized>(&'s mut S, u64);
        impl<S: VoxelSink + ?Sized> VoxelSink for Count<'_, S> {
            fn offer(&mut self, voxel: [u32; 3], surfel: Surfel) {
                self.1 += 1;
                self.0.offer(voxel, surfel);
            }
        }
        let mut counted = Count(sink, 0);
        for slab in self.slabs(frame, classifier, max_block_bytes, keep)? {
            let (block, z) = slab?;
            let core_block = Block {
                samples: &block.samples,
                dims: block.dims,
                offset: block.offset,
            };
            let mut clip = ClipZ {
                z,
                sink: &mut counted,
            };
            volume::boundary(
                &core_block,
                block.threshold,
                separation,
                frame.extent,
                &mut clip,
            )
            .map_err(|e| VolumeError::Invalid {
                what: "volume voxelization".into(),
                msg: e.to_string(),
            })?;
        }
        Ok(counted.1)
    }

    fn block_for(
        &self,
        frame: &RasterFrame,
        classifier: &Classifier,
        first: [u32; 3],
        n: [u32; 3],
        keep: Option<Keep<'_>>,
        max_bytes: u64,
    ) -> Result<RasterBlock, VolumeError> {
        classifier.validate()?;
        let voxels = super::sample_count(n);
        let bytes = voxels.saturating_mul(2);
        if bytes > max_bytes {
            return Err(VolumeError::TooLarge {
                path: "raster block".into(),
                at: String::new(),
                dims: DimsFmt(n),
                ty: SampleType::U16,
                bytes,
                limit: max_bytes,
            });
        }
        let count = usize::try_from(voxels).map_err(|_| VolumeError::Invalid {
            what: "raster block".into(),
            msg: "too many voxels for this machine".into(),
        })?;
        let quant = Quantizer::for_volume(self.volume);
        let threshold = quant.quantize(classifier.iso).max(1);
        let mut samples = vec![0u16; count];
        let layer = usize::try_from(u64::from(n[0]) * u64::from(n[1])).unwrap_or(usize::MAX);
        let to_index = self.world_to_index;
        samples
            .par_chunks_mut(layer.max(1))
            .enumerate()
            .for_each(|(k, plane)| {
                let kz = f64::from(first[2]) + k as f64 + 0.5;
                for (jn, row) in plane.chunks_mut(n[0].max(1) as usize).enumerate() {
                    let jy = f64::from(first[1]) + jn as f64 + 0.5;
                    for (i, out) in row.iter_mut().enumerate() {
                        let ix = f64::from(first[0]) + i as f64 + 0.5;
                        let w = frame.raster_to_world(DVec3::new(ix, jy, kz));
                        let Some(v) = self.volume.sample_index(to_index.transform_point3(w)) else {
                            continue;
                        };
                        if let Some(keep) = keep {
                            // Voxel coordinates below 2^16 + 2^16: fit u32.
                            let vox = [
                                first[0] + i as u32,
                                first[1] + jn as u32,
                                first[2] + k as u32,
                            ];
                            if !keep(vox) {
                                continue;
                            }
                        }
                        let q = quant.quantize(v);
                        *out = if classifier.is_opaque(v) {
                            q.max(threshold)
                        } else {
                            q.min(threshold - 1)
                        };
                    }
                }
            });
        Ok(RasterBlock {
            samples,
            dims: n,
            offset: first.map(i64::from),
            threshold,
        })
    }
}

/// A sink that passes on only the voxels whose z lies in a range (the
/// voxels a [`PlacedVolume::raster_slabs`] slab owns).
#[derive(Debug)]
pub struct ClipZ<'s, S: VoxelSink + ?Sized> {
    /// The z range passed on.
    pub z: Range<u32>,
    /// The sink.
    pub sink: &'s mut S,
}

impl<S: VoxelSink + ?Sized> VoxelSink for ClipZ<'_, S> {
    fn offer(&mut self, voxel: [u32; 3], surfel: Surfel) {
        if self.z.contains(&voxel[2]) {
            self.sink.offer(voxel, surfel);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rrt_core::raster::Extent;

    fn ball(n: u32) -> Volume {
        let c = (f64::from(n) - 1.0) / 2.0;
        let mut s = Vec::new();
        for k in 0..n {
            for j in 0..n {
                for i in 0..n {
                    let r = DVec3::new(f64::from(i), f64::from(j), f64::from(k)) - DVec3::splat(c);
                    s.push((200.0 - 10.0 * r.length()).clamp(0.0, 255.0) as u8);
                }
            }
        }
        Volume::new([n; 3], Grid::unit(), Samples::U8(s)).unwrap()
    }

    #[test]
    fn block_classifies_exactly() {
        let v = ball(16);
        let placed = Placement::IDENTITY.place(&v);
        let frame = RasterFrame {
            extent: Extent::cube(20).unwrap(),
            origin: DVec3::splat(-2.5),
            voxel_size: 1.0,
        };
        let c = Classifier::iso(150.0);
        let b = placed.raster_block(&frame, &c, 1 << 20).unwrap().unwrap();
        // Raster voxel i has centre i − 2: sample i − 2.
        assert_eq!(b.offset, [2, 2, 2]);
        assert_eq!(b.dims, [16, 16, 16]);
        assert_eq!(b.count_inside(), c.count(&v));
        assert_eq!(
            b.at_voxel([9, 9, 9]),
            Some(v.value(7, 7, 7).unwrap() as u16 * 256)
        );
        // Slabs: same samples for the owned layers.
        let slabs: Vec<_> = placed
            .raster_slabs(&frame, &c, 16 * 16 * 2 * 5)
            .unwrap()
            .map(Result::unwrap)
            .collect();
        assert_eq!(slabs.len(), 6);
        let mut owned = 0;
        for (s, z) in &slabs {
            for k in z.clone() {
                for j in 2..18 {
                    for i in 2..18 {
                        assert_eq!(s.at_voxel([i, j, k]), b.at_voxel([i, j, k]));
                        owned += 1;
                    }
                }
            }
        }
        assert_eq!(owned, 16 * 16 * 16);
        assert!(placed.raster_slabs(&frame, &c, 16 * 16 * 2 * 2).is_err());
        assert!(placed.raster_block(&frame, &c, 100).is_err());
    }
}
