//! Sampled and computed volumes: scalar grids read from NRRD or headerless
//! raw files, or sampled from a formula, placed in the world next to
//! geometry. Nothing here knows the raster: the raster side of volumes
//! (sampling at the raster's voxel centres, the core's volume voxelizer,
//! per-voxel colours) is [`crate::voxelize::volume`].
//!
//! The paper ray traces "3D sampled datasets (e.g. 3D MRI imaging) and
//! computed datasets" in the same 3D raster as geometric objects: a voxel
//! whose value passes the classification is non-transparent, and its normal
//! comes from the gray-level gradient over its 3×3×3 neighbourhood (after
//! Tiede et al.). This module holds the host side of that:
//!
//! * [`Volume`]: samples in their native type ([`Samples`]: `u8`, `i16`,
//!   `u16` or `f32`, so a 181×217×181 `uint8` MRI takes 7 MB, not 28), the
//!   grid geometry ([`Grid`]: where sample `(i, j, k)` lies in the data's
//!   own physical space), and trilinear sampling;
//! * [`nrrd`] and [`raw`]: the readers, with errors that name the file and
//!   the header line or byte offset at fault, and size limits checked
//!   before anything is allocated ([`Limits`]);
//! * [`resample`]: resampling an anisotropic grid to cubic voxels, and
//!   placing a volume in the world ([`Placement`], [`PlacedVolume`]);
//! * [`classify`]: the iso-value, the optional opacity and colour ramps,
//!   and the float gray-level gradient used to check the core's;
//! * [`computed`]: computed datasets (metaballs) as the same [`Volume`].
//!
//! # Conventions
//! Samples are stored x fastest: sample `(i, j, k)` is
//! `samples[i + nx·(j + ny·k)]`. Sample `(i, j, k)` sits at the *centre*
//! of its cell (NRRD's `space origin` is the position of sample
//! `(0, 0, 0)`), so the volume's cells cover index coordinates
//! `[-½, n - ½]` on each axis. Trilinear interpolation is defined between
//! sample centres and clamps to the edge sample in the outer half cell;
//! outside the cells a volume has no value ([`Volume::sample_index`]
//! returns `None`).

use std::fmt;
use std::path::{Path, PathBuf};

use glam::{DMat3, DVec3};
use rayon::prelude::*;

use crate::world::Bounds;

pub mod classify;
pub mod computed;
pub mod nrrd;
pub mod raw;
pub mod resample;

pub use classify::{Classifier, ColorRamp, Ramp, Render};
pub use resample::{PlacedVolume, Placement, SAMPLE_MAX};

/// Default limit on the bytes of samples one volume may take (4 GiB).
pub const DEFAULT_MAX_BYTES: u64 = 4 << 30;
/// Most samples along one axis of a volume (the core's raster axis limit).
pub const MAX_AXIS: u32 = rrt_core::raster::MAX_AXIS;

/// Size limits checked before anything is allocated.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Limits {
    /// Most bytes the samples of one volume may take (product of the sizes
    /// times the sample size).
    pub max_bytes: u64,
    /// Most bytes a header may take before its end (attached headers are
    /// read up to the first empty line).
    pub max_header_bytes: u64,
}

impl Default for Limits {
    fn default() -> Self {
        Self {
            max_bytes: DEFAULT_MAX_BYTES,
            max_header_bytes: 1 << 20,
        }
    }
}

/// The type of a volume's samples.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum SampleType {
    /// Unsigned 8-bit (`uint8`, `uchar`).
    U8,
    /// Signed 16-bit (`int16`, `short`).
    I16,
    /// Unsigned 16-bit (`uint16`, `ushort`).
    U16,
    /// IEEE 754 single precision (`float`).
    F32,
}

impl SampleType {
    /// Bytes per sample.
    #[must_use]
    pub const fn size(self) -> u64 {
        match self {
            Self::U8 => 1,
            Self::I16 | Self::U16 => 2,
            Self::F32 => 4,
        }
    }

    /// The NRRD name of the type.
    #[must_use]
    pub const fn name(self) -> &'static str {
        match self {
            Self::U8 => "uint8",
            Self::I16 => "int16",
            Self::U16 => "uint16",
            Self::F32 => "float",
        }
    }
}

impl fmt::Display for SampleType {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// Byte order of multi-byte samples in a file.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Endian {
    /// Least significant byte first.
    Little,
    /// Most significant byte first.
    Big,
}

/// A volume's samples in their native type, x fastest.
#[derive(Clone, Debug, PartialEq)]
pub enum Samples {
    /// `uint8` samples.
    U8(Vec<u8>),
    /// `int16` samples.
    I16(Vec<i16>),
    /// `uint16` samples.
    U16(Vec<u16>),
    /// `float` samples.
    F32(Vec<f32>),
}

impl Samples {
    /// `count` binary samples of type `ty` in byte order `endian`, read
    /// by `fill` (which must fill the buffer it is given) straight into
    /// their typed vector, without a second copy; the byte order is fixed
    /// in place. The one binary sample decoder of the NRRD and raw readers.
    ///
    /// # Errors
    /// The first error of `fill`.
    pub fn read_binary<E>(
        ty: SampleType,
        endian: Endian,
        count: usize,
        mut fill: impl FnMut(&mut [u8]) -> Result<(), E>,
    ) -> Result<Self, E> {
        /// `count` samples of `T` read by `fill`, each converted from the
        /// file's byte order (`from_le` or `from_be`, as `little` says).
        fn typed<T: bytemuck::Pod, E>(
            count: usize,
            fill: &mut impl FnMut(&mut [u8]) -> Result<(), E>,
            little: bool,
            from_le: impl Fn(T) -> T,
            from_be: impl Fn(T) -> T,
        ) -> Result<Vec<T>, E> {
            let mut v = vec![T::zeroed(); count];
            fill(bytemuck::cast_slice_mut(&mut v))?;
            for x in &mut v {
                *x = if little { from_le(*x) } else { from_be(*x) };
            }
            Ok(v)
        }
        let little = endian == Endian::Little;
        let f = &mut fill;
        Ok(match ty {
            SampleType::U8 => Self::U8(typed(count, f, little, |x: u8| x, |x: u8| x)?),
            SampleType::I16 => Self::I16(typed(count, f, little, i16::from_le, i16::from_be)?),
            SampleType::U16 => Self::U16(typed(count, f, little, u16::from_le, u16::from_be)?),
            SampleType::F32 => Self::F32(
                typed(count, f, little, u32::from_le, u32::from_be)?
                    .into_iter()
                    .map(f32::from_bits)
                    .collect(),
            ),
        })
    }

    /// Number of samples.
    #[must_use]
    pub fn len(&self) -> usize {
        match self {
            Self::U8(v) => v.len(),
            Self::I16(v) => v.len(),
            Self::U16(v) => v.len(),
            Self::F32(v) => v.len(),
        }
    }

    /// True when there are no samples.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The sample type.
    #[must_use]
    pub const fn sample_type(&self) -> SampleType {
        match self {
            Self::U8(_) => SampleType::U8,
            Self::I16(_) => SampleType::I16,
            Self::U16(_) => SampleType::U16,
            Self::F32(_) => SampleType::F32,
        }
    }

    /// Sample `index` as `f64`, or `None` past the end.
    #[inline]
    #[must_use]
    pub fn get(&self, index: usize) -> Option<f64> {
        match self {
            Self::U8(v) => v.get(index).map(|&x| f64::from(x)),
            Self::I16(v) => v.get(index).map(|&x| f64::from(x)),
            Self::U16(v) => v.get(index).map(|&x| f64::from(x)),
            Self::F32(v) => v.get(index).map(|&x| f64::from(x)),
        }
    }

    /// Smallest and largest sample (NaN samples skipped; `(0, 0)` when
    /// every sample is NaN or there is none), over all threads of the
    /// current rayon pool.
    #[must_use]
    pub fn range(&self) -> (f64, f64) {
        fn of<T: Copy + Sync>(v: &[T], f: impl Fn(T) -> f64 + Sync) -> (f64, f64) {
            v.par_chunks(1 << 16)
                .map(|c| {
                    c.iter()
                        .map(|&x| f(x))
                        .filter(|x| !x.is_nan())
                        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), x| {
                            (lo.min(x), hi.max(x))
                        })
                })
                .reduce(
                    || (f64::INFINITY, f64::NEG_INFINITY),
                    |a, b| (a.0.min(b.0), a.1.max(b.1)),
                )
        }
        let (lo, hi) = match self {
            Self::U8(v) => of(v, f64::from),
            Self::I16(v) => of(v, f64::from),
            Self::U16(v) => of(v, f64::from),
            Self::F32(v) => of(v, f64::from),
        };
        if lo > hi { (0.0, 0.0) } else { (lo, hi) }
    }

    /// Every sample as `f64`, in order.
    pub fn iter(&self) -> Box<dyn Iterator<Item = f64> + '_> {
        match self {
            Self::U8(v) => Box::new(v.iter().map(|&x| f64::from(x))),
            Self::I16(v) => Box::new(v.iter().map(|&x| f64::from(x))),
            Self::U16(v) => Box::new(v.iter().map(|&x| f64::from(x))),
            Self::F32(v) => Box::new(v.iter().map(|&x| f64::from(x))),
        }
    }
}

/// Where the samples lie in the data's own physical space (millimetres for
/// a scan, ångström for a density map): sample `(i, j, k)` is at
/// `origin + i·directions[0] + j·directions[1] + k·directions[2]`.
///
/// This is NRRD's `space origin` and `space directions` (each direction is
/// one index step, so an axis-aligned grid has the spacings on the
/// diagonal).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Grid {
    /// Position of sample `(0, 0, 0)`.
    pub origin: DVec3,
    /// One index step along each axis, in physical units.
    pub directions: [DVec3; 3],
}

impl Grid {
    /// An axis-aligned grid with the given spacings, sample `(0, 0, 0)` at
    /// `origin`.
    #[must_use]
    pub fn axis_aligned(spacing: [f64; 3], origin: DVec3) -> Self {
        Self {
            origin,
            directions: [
                DVec3::X * spacing[0],
                DVec3::Y * spacing[1],
                DVec3::Z * spacing[2],
            ],
        }
    }

    /// Unit spacing, sample `(0, 0, 0)` at the physical origin: what a file
    /// without geometry fields gets.
    #[must_use]
    pub fn unit() -> Self {
        Self::axis_aligned([1.0; 3], DVec3::ZERO)
    }

    /// The index → physical matrix (columns are the directions).
    #[must_use]
    pub fn matrix(&self) -> DMat3 {
        DMat3::from_cols(self.directions[0], self.directions[1], self.directions[2])
    }

    /// Length of each direction: the spacing along each index axis.
    #[must_use]
    pub fn spacing(&self) -> [f64; 3] {
        self.directions.map(DVec3::length)
    }

    /// True when each direction lies along its own coordinate axis.
    #[must_use]
    pub fn is_axis_aligned(&self) -> bool {
        let [a, b, c] = self.directions;
        a.y == 0.0 && a.z == 0.0 && b.x == 0.0 && b.z == 0.0 && c.x == 0.0 && c.y == 0.0
    }

    /// Checks the grid is usable: finite and not degenerate (the directions
    /// span space, each step at least 1e-12 long).
    ///
    /// # Errors
    /// A description of what is wrong.
    pub fn validate(&self) -> Result<(), String> {
        // In scientific notation: a step of 1e-300 is not 300 digits.
        let e = |v: DVec3| format!("[{:e}, {:e}, {:e}]", v.x, v.y, v.z);
        if !self.origin.is_finite() {
            return Err(format!("origin {} is not finite", e(self.origin)));
        }
        for (axis, d) in self.directions.iter().enumerate() {
            if !d.is_finite() || d.length() < 1e-12 {
                return Err(format!(
                    "axis {axis}: step {} is not finite, or shorter than 1e-12",
                    e(*d)
                ));
            }
        }
        let m = self.matrix();
        let det = m.determinant();
        let scale = self.spacing().iter().product::<f64>();
        if !det.is_finite() || det.abs() <= scale * 1e-9 {
            return Err("the three directions do not span space".into());
        }
        Ok(())
    }
}

/// A 3D scalar grid: dimensions, geometry and samples.
///
/// Invariant: `samples.len() == nx·ny·nz`, every dimension in
/// `1..=MAX_AXIS`, and the grid passes [`Grid::validate`].
#[derive(Clone, Debug, PartialEq)]
pub struct Volume {
    dims: [u32; 3],
    grid: Grid,
    samples: Samples,
    /// Inverse of the grid matrix (physical → index).
    inverse: DMat3,
    /// Whether the file gave the geometry (`false`: unit spacing assumed).
    geometry_known: bool,
    /// Smallest and largest sample, found once ([`Volume::range`]).
    range: (f64, f64),
}

impl Volume {
    /// A volume from its parts. Infinite `float` samples are taken as the
    /// largest finite `float` of their sign (a trilinear interpolation with
    /// an infinity in it would give ∞ or NaN, not a value between
    /// its samples); NaN samples stay NaN, which is transparent.
    ///
    /// # Errors
    /// [`VolumeError::Invalid`] when a dimension is 0 or above
    /// [`MAX_AXIS`], the sample count is not the product of the
    /// dimensions, or the grid is not usable.
    pub fn new(dims: [u32; 3], grid: Grid, mut samples: Samples) -> Result<Self, VolumeError> {
        let invalid = |msg: String| VolumeError::Invalid {
            what: "volume".into(),
            msg,
        };
        if dims.iter().any(|&n| n == 0 || n > MAX_AXIS) {
            return Err(invalid(format!(
                "dimensions {}: each must be 1 to {MAX_AXIS}",
                DimsFmt(dims)
            )));
        }
        let count = sample_count(dims);
        if u64::try_from(samples.len()).ok() != Some(count) {
            return Err(invalid(format!(
                "{} samples for dimensions {} ({count} expected)",
                samples.len(),
                DimsFmt(dims)
            )));
        }
        grid.validate().map_err(invalid)?;
        if let Samples::F32(v) = &mut samples {
            v.par_chunks_mut(1 << 16).for_each(|c| {
                for x in c.iter_mut().filter(|x| x.is_infinite()) {
                    *x = f32::MAX.copysign(*x);
                }
            });
        }
        Ok(Self {
            dims,
            inverse: grid.matrix().inverse(),
            grid,
            range: samples.range(),
            samples,
            geometry_known: true,
        })
    }

    /// Marks whether the geometry came from the data (a file without
    /// geometry fields gets unit spacing and says so here).
    #[must_use]
    pub fn with_geometry_known(mut self, known: bool) -> Self {
        self.geometry_known = known;
        self
    }

    /// Samples per axis.
    #[must_use]
    pub const fn dims(&self) -> [u32; 3] {
        self.dims
    }

    /// The grid geometry.
    #[must_use]
    pub const fn grid(&self) -> &Grid {
        &self.grid
    }

    /// Spacing along each index axis, in physical units.
    #[must_use]
    pub fn spacing(&self) -> [f64; 3] {
        self.grid.spacing()
    }

    /// Position of sample `(0, 0, 0)`.
    #[must_use]
    pub const fn origin(&self) -> DVec3 {
        self.grid.origin
    }

    /// False when the data gave no geometry and unit spacing was assumed.
    #[must_use]
    pub const fn geometry_known(&self) -> bool {
        self.geometry_known
    }

    /// The samples.
    #[must_use]
    pub const fn samples(&self) -> &Samples {
        &self.samples
    }

    /// The sample type.
    #[must_use]
    pub const fn sample_type(&self) -> SampleType {
        self.samples.sample_type()
    }

    /// True when the spacing is the same on all axes (within 1e-9
    /// relative) and the grid is axis-aligned.
    #[must_use]
    pub fn is_cubic(&self) -> bool {
        let [a, b, c] = self.spacing();
        let tol = a.max(b).max(c) * 1e-9;
        self.grid.is_axis_aligned() && (a - b).abs() <= tol && (a - c).abs() <= tol
    }

    /// Linear index of sample `(i, j, k)`, or `None` outside.
    #[inline]
    #[must_use]
    pub fn index(&self, i: u32, j: u32, k: u32) -> Option<usize> {
        let [nx, ny, nz] = self.dims;
        if i >= nx || j >= ny || k >= nz {
            return None;
        }
        // Below the sample count, which fits usize (the samples exist).
        let lin = u64::from(i) + u64::from(nx) * (u64::from(j) + u64::from(ny) * u64::from(k));
        usize::try_from(lin).ok()
    }

    /// Sample `(i, j, k)` as `f64`, or `None` outside.
    #[inline]
    #[must_use]
    pub fn value(&self, i: u32, j: u32, k: u32) -> Option<f64> {
        self.samples.get(self.index(i, j, k)?)
    }

    /// Smallest and largest sample (NaN samples are skipped; a volume of
    /// only NaN gives `(0, 0)`), found once when the volume was made.
    #[must_use]
    pub const fn range(&self) -> (f64, f64) {
        self.range
    }

    /// Mean of the samples (NaN samples skipped).
    #[must_use]
    pub fn mean(&self) -> f64 {
        let (sum, n) = self
            .samples
            .iter()
            .filter(|v| !v.is_nan())
            .fold((0.0, 0u64), |(s, n), v| (s + v, n + 1));
        if n == 0 { 0.0 } else { sum / n as f64 }
    }

    /// Continuous index coordinates → physical position.
    #[must_use]
    pub fn index_to_physical(&self, p: DVec3) -> DVec3 {
        self.grid.origin + self.grid.matrix() * p
    }

    /// Physical position → continuous index coordinates.
    #[must_use]
    pub fn physical_to_index(&self, p: DVec3) -> DVec3 {
        self.inverse * (p - self.grid.origin)
    }

    /// The box in physical space around the volume's cells (index
    /// coordinates `[-½, n - ½]` on every axis).
    #[must_use]
    pub fn physical_bounds(&self) -> Bounds {
        Bounds::around(self.cell_corners().map(|c| self.index_to_physical(c)))
    }

    /// The eight corners of the cells' box in index coordinates,
    /// `[-½, n - ½]` on every axis.
    #[must_use]
    pub fn cell_corners(&self) -> [DVec3; 8] {
        let hi = DVec3::from(self.dims.map(f64::from)) - 0.5;
        std::array::from_fn(|corner| {
            DVec3::new(
                if corner & 1 == 0 { -0.5 } else { hi.x },
                if corner & 2 == 0 { -0.5 } else { hi.y },
                if corner & 4 == 0 { -0.5 } else { hi.z },
            )
        })
    }

    /// Trilinear value at continuous index coordinates `p`: `None` outside
    /// the cells (`[-½, n - ½]` per axis) or for a NaN coordinate; in the
    /// outer half cell the edge sample's value is extended.
    #[must_use]
    pub fn sample_index(&self, p: DVec3) -> Option<f64> {
        let mut base = [0u32; 3];
        let mut frac = [0.0f64; 3];
        for axis in 0..3 {
            let n = f64::from(self.dims[axis]);
            let x = p[axis];
            // `!(a <= x)` is also true for NaN.
            if !(-0.5..=n - 0.5).contains(&x) {
                return None;
            }
            let c = x.clamp(0.0, n - 1.0);
            let f = c.floor();
            // 0 <= f <= n - 1 < 2^16: exact.
            let b = f as u32;
            if b + 1 >= self.dims[axis] {
                base[axis] = self.dims[axis] - 1;
                frac[axis] = 0.0;
            } else {
                base[axis] = b;
                frac[axis] = c - f;
            }
        }
        let [i, j, k] = base;
        let step = |axis: usize, v: u32| -> u32 { if frac[axis] > 0.0 { v + 1 } else { v } };
        let (i1, j1, k1) = (step(0, i), step(1, j), step(2, k));
        let v = |a, b, c| self.value(a, b, c).unwrap_or(0.0);
        let [fx, fy, fz] = frac;
        let lerp = |a: f64, b: f64, t: f64| if t == 0.0 { a } else { a + (b - a) * t };
        let c00 = lerp(v(i, j, k), v(i1, j, k), fx);
        let c10 = lerp(v(i, j1, k), v(i1, j1, k), fx);
        let c01 = lerp(v(i, j, k1), v(i1, j, k1), fx);
        let c11 = lerp(v(i, j1, k1), v(i1, j1, k1), fx);
        let c0 = lerp(c00, c10, fy);
        let c1 = lerp(c01, c11, fy);
        Some(lerp(c0, c1, fz))
    }

    /// Trilinear value at a physical position (see
    /// [`Volume::sample_index`]).
    #[must_use]
    pub fn sample_physical(&self, p: DVec3) -> Option<f64> {
        self.sample_index(self.physical_to_index(p))
    }
}

/// The product of the dimensions (cannot overflow: each is below 2^32).
#[must_use]
pub fn sample_count(dims: [u32; 3]) -> u64 {
    u64::from(dims[0])
        .saturating_mul(u64::from(dims[1]))
        .saturating_mul(u64::from(dims[2]))
}

/// Dimensions printed as `nx×ny×nz`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct DimsFmt(pub [u32; 3]);

impl fmt::Display for DimsFmt {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}×{}×{}", self.0[0], self.0[1], self.0[2])
    }
}

/// Why a volume cannot be read or built. Every message names the file (or
/// the thing being built) and, where there is one, the header line or the
/// byte offset at fault.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum VolumeError {
    /// The file cannot be opened or read.
    #[error("cannot read {}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The cause.
        #[source]
        source: std::io::Error,
    },
    /// A header line is wrong.
    #[error("{}:{line}: {msg}", path.display())]
    Header {
        /// The header file.
        path: PathBuf,
        /// 1-based line number.
        line: usize,
        /// What is wrong.
        msg: String,
    },
    /// A required header field is missing.
    #[error("{}: header: missing field `{field}`{hint}", path.display())]
    Missing {
        /// The header file.
        path: PathBuf,
        /// The field.
        field: &'static str,
        /// Why it is needed (may be empty).
        hint: &'static str,
    },
    /// The samples take more memory than the limit (checked before
    /// allocating).
    #[error("{}{at}: sizes {dims} of {ty} take {bytes} bytes, more than the limit of {limit} bytes", path.display())]
    TooLarge {
        /// The file.
        path: PathBuf,
        /// Where the sizes are given (`:line` or empty).
        at: String,
        /// The dimensions.
        dims: DimsFmt,
        /// The sample type.
        ty: SampleType,
        /// Bytes the samples would take (saturating).
        bytes: u64,
        /// The limit.
        limit: u64,
    },
    /// The data do not match what the header promises.
    #[error("{}: byte {offset}: {msg}", path.display())]
    Data {
        /// The data file.
        path: PathBuf,
        /// Byte offset in the data file (of the compressed stream for
        /// compressed encodings) where the problem shows.
        offset: u64,
        /// What is wrong.
        msg: String,
    },
    /// A volume built in code (or from options) is inconsistent.
    #[error("{what}: {msg}")]
    Invalid {
        /// What was being built.
        what: String,
        /// What is wrong.
        msg: String,
    },
}

impl VolumeError {
    /// [`VolumeError::Io`] on `path`, for `map_err`.
    pub(crate) fn io(path: &Path) -> impl Fn(std::io::Error) -> Self + Copy + '_ {
        move |source| Self::Io {
            path: path.to_path_buf(),
            source,
        }
    }

    /// [`VolumeError::Header`] at line `line` of `path`.
    pub(crate) fn header(path: &Path, line: usize, msg: String) -> Self {
        Self::Header {
            path: path.to_path_buf(),
            line,
            msg,
        }
    }

    /// [`VolumeError::Data`] at byte `offset` of `path`.
    pub(crate) fn data(path: &Path, offset: u64, msg: String) -> Self {
        Self::Data {
            path: path.to_path_buf(),
            offset,
            msg,
        }
    }

    /// `path` opened, and its length.
    pub(crate) fn open(path: &Path) -> Result<(std::fs::File, u64), Self> {
        // Checked before opening: opening a pipe waits for a writer.
        let meta = std::fs::metadata(path).map_err(Self::io(path))?;
        if !meta.is_file() {
            let what = if meta.is_dir() {
                "a directory, not a file"
            } else {
                "not a regular file (a pipe, socket or device)"
            };
            return Err(Self::io(path)(std::io::Error::new(
                std::io::ErrorKind::InvalidInput,
                what,
            )));
        }
        let file = std::fs::File::open(path).map_err(Self::io(path))?;
        let len = file.metadata().map_err(Self::io(path))?.len();
        Ok((file, len))
    }
}

/// Checks `dims` × `ty` against `limits` before allocating.
pub(crate) fn check_size(
    path: &std::path::Path,
    at: String,
    dims: [u32; 3],
    ty: SampleType,
    limits: &Limits,
) -> Result<usize, VolumeError> {
    let count = sample_count(dims);
    let bytes = count.saturating_mul(ty.size());
    if bytes > limits.max_bytes {
        return Err(VolumeError::TooLarge {
            path: path.to_path_buf(),
            at,
            dims: DimsFmt(dims),
            ty,
            bytes,
            limit: limits.max_bytes,
        });
    }
    usize::try_from(count).map_err(|_| VolumeError::TooLarge {
        path: path.to_path_buf(),
        at: String::new(),
        dims: DimsFmt(dims),
        ty,
        bytes,
        limit: limits.max_bytes,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ramp_volume() -> Volume {
        // value = i + 10 j + 100 k on a 4×3×2 grid.
        let mut s = Vec::new();
        for k in 0..2u16 {
            for j in 0..3u16 {
                for i in 0..4u16 {
                    s.push(i + 10 * j + 100 * k);
                }
            }
        }
        Volume::new(
            [4, 3, 2],
            Grid::axis_aligned([1.0, 2.0, 3.0], DVec3::new(10.0, 20.0, 30.0)),
            Samples::U16(s),
        )
        .unwrap()
    }

    #[test]
    fn trilinear_is_exact_on_a_linear_field() {
        let v = ramp_volume();
        assert_eq!(v.value(3, 2, 1), Some(123.0));
        assert_eq!(
            v.sample_index(DVec3::new(1.5, 0.25, 0.5)),
            Some(1.5 + 2.5 + 50.0)
        );
        // Physical: x = 10 + i, y = 20 + 2 j, z = 30 + 3 k.
        let p = DVec3::new(12.0, 23.0, 31.5);
        assert!((v.sample_physical(p).unwrap() - (2.0 + 15.0 + 50.0)).abs() < 1e-9);
        // Outer half cell extends the edge; beyond it, nothing.
        assert_eq!(v.sample_index(DVec3::new(3.4, 0.0, 0.0)), Some(3.0));
        assert_eq!(v.sample_index(DVec3::new(-0.5, 0.0, 0.0)), Some(0.0));
        assert_eq!(v.sample_index(DVec3::new(3.6, 0.0, 0.0)), None);
        assert_eq!(v.sample_index(DVec3::new(f64::NAN, 0.0, 0.0)), None);
        let b = v.physical_bounds();
        assert_eq!(b.min, DVec3::new(9.5, 19.0, 28.5));
        assert_eq!(b.max, DVec3::new(13.5, 25.0, 34.5));
        assert_eq!(v.range(), (0.0, 123.0));
        assert!(!v.is_cubic());
    }

    /// Infinite samples interpolate as the largest finite floats: every
    /// point between an infinite sample and a 0 lies above any iso value,
    /// none is NaN (transparent), and the range is finite.
    #[test]
    fn infinite_samples_are_the_largest_finite_floats() {
        let s = vec![f32::INFINITY, 0.0, f32::NEG_INFINITY, f32::NAN];
        let v = Volume::new([4, 1, 1], Grid::unit(), Samples::F32(s)).unwrap();
        let max = f64::from(f32::MAX);
        assert_eq!(v.range(), (-max, max));
        for k in 0..=10 {
            let x = f64::from(k) / 10.0;
            let at = v.sample_index(DVec3::new(x, 0.0, 0.0)).unwrap();
            assert!(at.is_finite() && at >= 0.0, "{x}: {at}");
            assert!(x == 1.0 || at > 1e37, "{x}: {at}");
        }
        assert!(v.value(3, 0, 0).unwrap().is_nan());
    }

    #[test]
    fn bad_parts_are_refused() {
        let g = Grid::unit();
        assert!(Volume::new([2, 2, 2], g, Samples::U8(vec![0; 7])).is_err());
        assert!(Volume::new([0, 2, 2], g, Samples::U8(vec![])).is_err());
        let flat = Grid {
            origin: DVec3::ZERO,
            directions: [DVec3::X, DVec3::X, DVec3::Z],
        };
        let e = Volume::new([1, 1, 1], flat, Samples::U8(vec![0])).unwrap_err();
        assert!(e.to_string().contains("span"), "{e}");
    }
}
