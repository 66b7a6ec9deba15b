//! The raster side of direct volume rendering: a volume classified by a
//! transfer function ([`Render::Direct`](crate::assets::volume::Render))
//! puts every raster voxel whose sample has an opacity above 0 in the
//! raster, so that the discrete walk visits them (and skips the empty
//! space around them, which the distance field and the line level
//! describe), and keeps its samples at the voxel centres for the tracer
//! ([`DirectVolume`]).
//!
//! A voxel's sample is the placed volume's trilinear value at the voxel's
//! centre, rounded to `f32` ([`voxel_sample`]), computed once per voxel
//! ([`DirectVolume::new`], before the voxelization's passes); both passes
//! and the tracer read those samples, so the voxels in the raster are
//! exactly those of opacity above 0. Their records carry the object (and,
//! where geometry shares the voxel, are listed with it; the geometry owns
//! the voxel: the volume offers its voxels at the largest distance) and
//! the transfer function's colour of the sample.
//!
//! ```
//! use glam::DVec3;
//! use rrt_core::raster::Extent;
//! use std::sync::Arc;
//! use rrt_host::assets::volume::{Classifier, Grid, Placement, Ramp, Samples, Volume};
//! use rrt_host::frame::RasterFrame;
//! use rrt_host::scene::SceneVolume;
//! use rrt_host::voxelize::direct::DirectVolume;
//! // 4×4×4 samples of 0 and 100, one world unit apart.
//! let s = (0..64).map(|i| if i % 4 < 2 { 0 } else { 100 }).collect();
//! let v = Volume::new([4; 3], Grid::unit(), Samples::U8(s)).unwrap();
//! let tf = Classifier::direct(Ramp::new(vec![(0.0, 0.0), (100.0, 0.25)]).unwrap());
//! let volume = SceneVolume { volume: Arc::new(v), placement: Placement::IDENTITY, classifier: tf };
//! let frame = RasterFrame { extent: Extent::cube(8).unwrap(), origin: DVec3::splat(-2.5), voxel_size: 1.0 };
//! let d = DirectVolume::new(0, &volume, &frame, [255; 3], 1 << 20).unwrap().unwrap();
//! assert_eq!(d.spacing, 1.0);
//! assert_eq!(d.value([2, 2, 2]), Some(0.0));
//! assert_eq!(d.value([5, 2, 2]), Some(100.0));
//! assert_eq!(d.count_visible(), 2 * 4 * 4);
//! ```

use glam::DVec3;
use rayon::prelude::*;
use rrt_core::fixed::FRAC_BITS;
use rrt_core::store::{RecordStore, Texture};
use rrt_core::voxelize::{NORMAL_ONE, Surfel, VoxelSink};

use super::BuildError;
use super::pass::Pass;
use super::volume::sample_grid;
use crate::assets::volume::{Classifier, PlacedVolume, SampleType, VolumeError};
use crate::frame::RasterFrame;
use crate::scene::SceneVolume;

/// The sample of raster voxel `v` of a placed volume: its trilinear value
/// at the voxel's centre, rounded to `f32`; NaN outside the volume (clear
/// under every transfer function).
#[must_use]
pub fn voxel_sample(placed: &PlacedVolume<'_>, frame: &RasterFrame, v: [u32; 3]) -> f32 {
    let c = DVec3::new(f64::from(v[0]), f64::from(v[1]), f64::from(v[2])) + 0.5;
    // The rounding to f32 is the stored value's.
    placed
        .sample_world(frame.raster_to_world(c))
        .map_or(f32::NAN, |x| x as f32)
}

/// A volume rendered directly, as the tracer reads it: the samples at
/// the centres of the raster voxels its cells cover, its transfer
/// function, and which of those voxels it holds alone (no record lookup
/// needed there).
#[derive(Clone, Debug, PartialEq)]
pub struct DirectVolume {
    /// Its id in the object table.
    pub object: u32,
    /// The first raster voxel of the box of samples.
    pub first: [u32; 3],
    /// Samples per axis.
    pub dims: [u32; 3],
    /// The samples ([`voxel_sample`]), x fastest.
    pub values: Vec<f32>,
    /// The transfer function (opacity and colour ramps, floor `iso`).
    pub classifier: Classifier,
    /// The colour of samples without a colour ramp (the material's).
    pub base: [u8; 3],
    /// The world length the ramp's opacities are for: the placed
    /// volume's smallest sample spacing.
    pub spacing: f64,
    /// One bit per voxel of the box (x fastest, 64 to a word): whether
    /// the voxel's record lists this volume and no other object
    /// ([`DirectVolume::mark_alone`]; all clear before).
    alone: Vec<u64>,
}

impl DirectVolume {
    /// The samples of `volume` (placed, under its transfer function) over
    /// the raster `frame`, for object `object`; `None` when the volume
    /// misses the raster.
    ///
    /// # Errors
    /// [`VolumeError::TooLarge`] when the samples would take more than
    /// `max_bytes` (4 bytes per voxel of the volume's box), checked before
    /// allocating; [`VolumeError::Invalid`] for a classifier that is not
    /// valid or a degenerate placement.
    pub fn new(
        object: u32,
        volume: &SceneVolume,
        frame: &RasterFrame,
        base: [u8; 3],
        max_bytes: u64,
    ) -> Result<Option<Self>, VolumeError> {
        let classifier = &volume.classifier;
        let placed = volume.placed();
        let spacing = volume.sample_spacing();
        classifier.validate()?;
        if !(spacing.is_finite() && spacing > 0.0) {
            return Err(VolumeError::Invalid {
                what: "direct volume rendering".into(),
                msg: format!("sample spacing {spacing} in the world"),
            });
        }
        let Some((first, dims)) = placed.raster_box(frame) else {
            return Ok(None);
        };
        let mut values =
            sample_grid::<f32>(dims, SampleType::F32, "direct volume samples", max_bytes)?;
        let row = dims[0].max(1) as usize;
        let layer = row * dims[1].max(1) as usize;
        values
            .par_chunks_mut(layer)
            .enumerate()
            .for_each(|(k, plane)| {
                for (j, r) in plane.chunks_mut(row).enumerate() {
                    for (i, out) in r.iter_mut().enumerate() {
                        // Inside the box: below 2^16 per axis.
                        let v = [
                            first[0] + i as u32,
                            first[1] + j as u32,
                            first[2] + k as u32,
                        ];
                        *out = voxel_sample(&placed, frame, v);
                    }
                }
            });
        Ok(Some(Self {
            object,
            first,
            dims,
            values,
            classifier: classifier.clone(),
            base,
            spacing,
            alone: Vec::new(),
        }))
    }

    /// The position of raster voxel `v` among the samples (`None`
    /// outside the box).
    fn local(&self, v: [u32; 3]) -> Option<usize> {
        let mut l = [0u64; 3];
        for axis in 0..3 {
            let d = v[axis].checked_sub(self.first[axis])?;
            if d >= self.dims[axis] {
                return None;
            }
            l[axis] = u64::from(d);
        }
        let [nx, ny, _] = self.dims.map(u64::from);
        usize::try_from(l[0] + nx * (l[1] + ny * l[2])).ok()
    }

    /// Marks the voxels whose record in `store` lists this volume and
    /// nothing else ([`DirectVolume::alone`]).
    pub fn mark_alone(&mut self, store: &RecordStore<'_>) {
        let mut alone = vec![0u64; self.values.len().div_ceil(64)];
        for (v, rec) in store.iter() {
            if store.objects(rec) == [self.object]
                && let Some(i) = self.local(v)
                && let Some(w) = alone.get_mut(i / 64)
            {
                *w |= 1 << (i % 64);
            }
        }
        self.alone = alone;
    }

    /// Whether raster voxel `v`'s record lists this volume and no other
    /// object (after [`DirectVolume::mark_alone`]; false before, and
    /// outside the box): then the tracer needs no record to composite it.
    #[must_use]
    pub fn alone(&self, v: [u32; 3]) -> bool {
        self.local(v)
            .and_then(|i| self.alone.get(i / 64).map(|w| w >> (i % 64) & 1 != 0))
            .unwrap_or(false)
    }

    /// The sample of raster voxel `v` (`None` outside the box; NaN where
    /// the volume has no value).
    #[must_use]
    pub fn value(&self, v: [u32; 3]) -> Option<f32> {
        self.values.get(self.local(v)?).copied()
    }

    /// The transfer function's opacity of raster voxel `v` (0 outside).
    #[must_use]
    pub fn opacity(&self, v: [u32; 3]) -> f64 {
        self.value(v)
            .map_or(0.0, |x| self.classifier.sample_opacity(f64::from(x)))
    }

    /// The gray-level gradient at raster voxel `v` by central differences
    /// of the neighbouring voxels' samples (a neighbour outside the box or
    /// without a value counts as `v`'s own sample), in gray levels per
    /// raster voxel.
    #[must_use]
    pub fn gradient(&self, v: [u32; 3]) -> DVec3 {
        let own = self.value(v).filter(|x| !x.is_nan()).unwrap_or(0.0);
        let at = |axis: usize, d: i32| {
            let mut w = v;
            w[axis] = match v[axis].checked_add_signed(d) {
                Some(x) => x,
                None => return own,
            };
            self.value(w).filter(|x| !x.is_nan()).unwrap_or(own)
        };
        let g = |axis| 0.5 * (f64::from(at(axis, 1)) - f64::from(at(axis, -1)));
        DVec3::new(g(0), g(1), g(2))
    }

    /// Number of voxels of opacity above 0 (the voxels it puts in the
    /// raster).
    #[must_use]
    pub fn count_visible(&self) -> u64 {
        self.values
            .iter()
            .filter(|&&x| self.classifier.sample_opacity(f64::from(x)) > 0.0)
            .count() as u64
    }
}

/// Offers every voxel of opacity above 0 of a directly rendered volume,
/// as its samples `d` give them, to `sink`, over the layers it keeps, in
/// z, y, x order, at the largest distance (so that geometry sharing a
/// voxel owns it).
fn offer_visible<S: VoxelSink + ?Sized>(d: &DirectVolume, sink: &mut S) {
    let layers = sink.layers();
    let z0 = d.first[2].max(layers.start);
    let z1 = d.first[2].saturating_add(d.dims[2]).min(layers.end);
    let surfel = Surfel {
        normal: [0, 0, NORMAL_ONE],
        distance: u32::MAX,
    };
    let [nx, ny, _] = d.dims.map(|n| n as usize);
    for z in z0..z1 {
        // z − first ≥ 0 and below the box's depth: in the samples.
        let layer = (z - d.first[2]) as usize * nx * ny;
        for (j, row) in d
            .values
            .get(layer..layer + nx * ny)
            .unwrap_or(&[])
            .chunks(nx.max(1))
            .enumerate()
        {
            let y = d.first[1] + j as u32;
            for (i, &s) in row.iter().enumerate() {
                if d.classifier.sample_opacity(f64::from(s)) > 0.0 {
                    sink.offer([d.first[0] + i as u32, y, z], surfel);
                }
            }
        }
    }
}

/// The colours of a directly rendered volume's voxels: the transfer
/// function's colour of each voxel's sample, as the tracer composites it
/// (the base colour where there is no colour ramp, or outside the box).
struct SampleColors<'a>(&'a DirectVolume);

impl Texture for SampleColors<'_> {
    fn color(&self, centre: [i64; 3], _normal: [i32; 3], base: [u8; 3]) -> [u8; 3] {
        // A voxel's centre is (v + ½) voxels in fixed point: v is its floor.
        let v = centre.map(|c| u32::try_from(c >> FRAC_BITS).unwrap_or(u32::MAX));
        self.0
            .value(v)
            .map_or(base, |x| self.0.classifier.color(f64::from(x), base))
    }
}

/// Voxelizes a directly rendered volume object into `pass` from its
/// samples over the raster `d` ([`DirectVolume::new`]): every voxel of
/// opacity above 0, coloured by the transfer function (or the material's
/// texture). Both passes read the same samples, which the tracer reads.
///
/// # Errors
/// The store's.
pub(super) fn voxelize_object(
    d: &DirectVolume,
    pass: Pass<'_, '_, '_, '_>,
) -> Result<(), BuildError> {
    match pass {
        Pass::Count(c) => offer_visible(d, c),
        Pass::Fill {
            filler,
            attrs,
            texture,
            ..
        } => {
            filler.begin_object(attrs)?;
            if let Some(t) = texture {
                offer_visible(d, &mut filler.textured(t));
            } else {
                offer_visible(d, &mut filler.textured(&SampleColors(d)));
            }
        }
    }
    Ok(())
}
