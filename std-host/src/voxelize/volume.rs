//! The raster side of volumes: a placed, classified volume sampled at the
//! raster's voxel centres and voxelized by the core's volume voxelizer.
//!
//! [`PlacedVolume::raster_block`] samples the placed volume at the centres
//! of the raster voxels it covers, whatever its spacing, and gives the grid
//! the core's volume voxelizer takes: one `u16` per raster voxel and a
//! threshold ([`RasterBlock`]). [`PlacedVolume::voxelize`] runs the core's
//! volume voxelizer over it in bounded slabs; [`VolumeColors`] colours the
//! voxels from the classifier's colour ramp; the builder puts a scene's
//! volume object through the count or the fill pass here.
//!
//! ```
//! use glam::DVec3;
//! use rrt_core::raster::Extent;
//! use rrt_host::frame::RasterFrame;
//! use rrt_host::assets::volume::{Classifier, Grid, Placement, Samples, Volume};
//! // 2×2×2 samples 10 mm apart, sample (0,0,0) at the physical origin.
//! let v = Volume::new([2, 2, 2], Grid::axis_aligned([10.0; 3], DVec3::ZERO),
//!                     Samples::U8(vec![0, 0, 0, 0, 0, 0, 0, 200])).unwrap();
//! // 1 mm = 0.1 world units; the volume's cells span −0.5..1.5 world.
//! let placed = Placement::new(DVec3::ZERO, 0.1).unwrap().place(&v);
//! // A raster of 0.25-unit voxels from −1 to 3.
//! let frame = RasterFrame { extent: Extent::cube(16).unwrap(),
//!                           origin: DVec3::splat(-1.0), voxel_size: 0.25 };
//! let block = placed.raster_block(&frame, &Classifier::iso(100.0), 1 << 20).unwrap().unwrap();
//! assert_eq!(block.offset, [2, 2, 2]);
//! assert_eq!(block.dims, [8, 8, 8]);
//! ```

use std::ops::Range;

use glam::DVec3;
use rayon::prelude::*;
use rrt_core::store::Texture;
use rrt_core::voxelize::volume::{self, Block};
use rrt_core::voxelize::{Separation, Surfel, VoxelSink};

use super::BuildError;
use super::pass::Pass;
use crate::assets::volume::resample::Quantizer;
use crate::assets::volume::{
    Classifier, DimsFmt, PlacedVolume, SampleType, VolumeError, sample_count,
};
use crate::frame::RasterFrame;
use crate::scene::VolumeObject;

/// A zeroed grid of `dims` samples of type `T` (`ty` names it), checked
/// against `max_bytes` before allocating; `what` names the grid in errors.
pub(super) fn sample_grid<T: Clone + Default>(
    dims: [u32; 3],
    ty: SampleType,
    what: &str,
    max_bytes: u64,
) -> Result<Vec<T>, VolumeError> {
    let voxels = sample_count(dims);
    let size = u64::try_from(std::mem::size_of::<T>()).unwrap_or(u64::MAX);
    let bytes = voxels.saturating_mul(size);
    if bytes > max_bytes {
        return Err(VolumeError::TooLarge {
            path: what.into(),
            at: String::new(),
            dims: DimsFmt(dims),
            ty,
            bytes,
            limit: max_bytes,
        });
    }
    let count = usize::try_from(voxels).map_err(|_| VolumeError::Invalid {
        what: what.into(),
        msg: "too many voxels for this machine".into(),
    })?;
    Ok(vec![T::default(); count])
}

/// A predicate on raster voxels: which to keep (see
/// [`PlacedVolume::voxelize_where`]).
pub type Keep<'k> = &'k (dyn Fn([u32; 3]) -> bool + Sync);

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

impl PlacedVolume<'_> {
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
        self.slabs(frame, classifier, max_bytes, None, 0..u32::MAX)
    }

    /// [`PlacedVolume::raster_slabs`] owning only the layers `owned` of
    /// the raster (each slab still with its halo).
    fn slabs<'s>(
        &'s self,
        frame: &'s RasterFrame,
        classifier: &'s Classifier,
        max_bytes: u64,
        keep: Option<Keep<'s>>,
        owned: Range<u32>,
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
        let (box0, box1) = (first[2], first[2] + n[2]);
        let z0 = box0.max(owned.start);
        let z1 = box1.min(owned.end);
        let starts = (z0..z1).step_by(usize::try_from(own).unwrap_or(usize::MAX));
        Ok(starts.map(move |s| {
            let e = s.saturating_add(own).min(z1);
            let lo = s.saturating_sub(1).max(box0);
            let hi = e.saturating_add(1).min(box1);
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

            fn layers(&self) -> Range<u32> {
                self.0.layers()
            }

            fn rows(&self) -> Range<u32> {
                self.0.rows()
            }

            fn reads_surfels(&self) -> bool {
                self.0.reads_surfels()
            }
        }
        let layers = sink.layers();
        let mut counted = Count(sink, 0);
        for slab in self.slabs(frame, classifier, max_block_bytes, keep, layers)? {
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
        let mut samples = sample_grid::<u16>(n, SampleType::U16, "raster block", max_bytes)?;
        let quant = Quantizer::for_volume(self.volume());
        let threshold = quant.quantize(classifier.iso).max(1);
        let layer = usize::try_from(u64::from(n[0]) * u64::from(n[1])).unwrap_or(usize::MAX);
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
                        let Some(v) = self.volume().sample_index(self.world_to_index(w)) else {
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

    fn reads_surfels(&self) -> bool {
        self.sink.reads_surfels()
    }

    fn layers(&self) -> Range<u32> {
        let l = self.sink.layers();
        let end = l.end.min(self.z.end);
        l.start.max(self.z.start).min(end)..end
    }

    fn rows(&self) -> Range<u32> {
        self.sink.rows()
    }
}

/// The per-voxel colour of a classified volume, as a core [`Texture`]:
/// the voxel centre goes to the world through the raster frame, the
/// volume is sampled there (trilinear), and the classifier's colour ramp
/// gives the colour (the base colour where there is no ramp or no value).
/// Computed once per voxel while the raster is filled.
#[derive(Clone, Debug)]
pub struct VolumeColors<'a> {
    placed: PlacedVolume<'a>,
    frame: RasterFrame,
    classifier: &'a Classifier,
}

impl<'a> VolumeColors<'a> {
    /// The colours of `placed` under `classifier`, for the raster `frame`.
    #[must_use]
    pub const fn new(
        placed: PlacedVolume<'a>,
        frame: RasterFrame,
        classifier: &'a Classifier,
    ) -> Self {
        Self {
            placed,
            frame,
            classifier,
        }
    }
}

impl Texture for VolumeColors<'_> {
    fn color(&self, centre: [i64; 3], _normal: [i32; 3], base: [u8; 3]) -> [u8; 3] {
        let p = self.frame.fixed_to_world(centre);
        match self.placed.sample_world(p) {
            Some(v) => self.classifier.color(v, base),
            None => base,
        }
    }
}

/// Most bytes of the resampled block a volume is voxelized through at once.
pub const MAX_BLOCK_BYTES: u64 = 256 << 20;

/// Voxelizes a volume object into `pass`, with `keep` choosing voxels (a
/// CSG cut). In the fill pass its voxels take the colour of the material's
/// texture if it has one, else the classifier's colour ramp (else the
/// material colour).
///
/// # Errors
/// The volume's refusal (a block beyond the limits), the store's.
pub(super) fn voxelize_object(
    v: &VolumeObject,
    frame: &RasterFrame,
    separation: Separation,
    keep: Option<Keep<'_>>,
    pass: Pass<'_, '_, '_, '_>,
) -> Result<(), BuildError> {
    let placed = v.data.placed();
    let classifier = &v.data.classifier;
    let err = |e: VolumeError| BuildError::Raster(format!("{}: volume: {e}", v.loc));
    match pass {
        Pass::Count(c) => {
            placed
                .voxelize_where(frame, classifier, separation, MAX_BLOCK_BYTES, keep, c)
                .map_err(err)?;
        }
        Pass::Fill {
            filler,
            attrs,
            texture,
            ..
        } => {
            filler.begin_object(attrs)?;
            if let Some(t) = texture {
                let mut s = filler.textured(t);
                placed
                    .voxelize_where(frame, classifier, separation, MAX_BLOCK_BYTES, keep, &mut s)
                    .map_err(err)?;
            } else {
                let colors = VolumeColors::new(placed, *frame, classifier);
                let mut s = filler.textured(&colors);
                placed
                    .voxelize_where(frame, classifier, separation, MAX_BLOCK_BYTES, keep, &mut s)
                    .map_err(err)?;
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use glam::DVec3;
    use rrt_core::raster::Extent;

    use super::*;
    use crate::assets::volume::{Classifier, Grid, Placement, Samples, Volume};

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
