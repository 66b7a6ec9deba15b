//! Headerless raw volumes: the caller gives dimensions, sample type, byte
//! order and geometry ([`RawSpec`]); the file must hold exactly the
//! samples (after an optional number of header bytes to skip).
//!
//! ```no_run
//! use rrt_host::assets::volume::raw::{self, RawSpec};
//! use rrt_host::assets::volume::{Endian, Grid, Limits, SampleType};
//! let spec = RawSpec {
//!     dims: [256, 256, 110],
//!     sample_type: SampleType::U8,
//!     endian: Endian::Little,
//!     grid: Grid::unit(),
//!     skip: 0,
//! };
//! let engine = raw::read("engine.256x256x110", &spec, &Limits::default())?;
//! # Ok::<(), rrt_host::assets::volume::VolumeError>(())
//! ```

use std::io::{BufReader, Read};
use std::path::Path;

use super::{DimsFmt, Endian, Grid, Limits, SampleType, Samples, Volume, VolumeError, check_size};

/// What a headerless raw file holds.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RawSpec {
    /// Samples per axis, x fastest.
    pub dims: [u32; 3],
    /// Sample type.
    pub sample_type: SampleType,
    /// Byte order of multi-byte samples.
    pub endian: Endian,
    /// Spacing and origin (e.g. [`Grid::axis_aligned`]).
    pub grid: Grid,
    /// Bytes to skip at the start of the file (a foreign header).
    pub skip: u64,
}

/// Reads the raw file at `path` as described by `spec`.
///
/// # Errors
/// [`VolumeError::Invalid`] for a spec with a zero or too large dimension
/// or an unusable grid; [`VolumeError::TooLarge`] when the samples exceed
/// `limits` (before allocating); [`VolumeError::Data`] when the file is
/// not exactly `skip` plus the samples' bytes long (the offset says where
/// the data end or where the extra bytes start); [`VolumeError::Io`].
pub fn read(
    path: impl AsRef<Path>,
    spec: &RawSpec,
    limits: &Limits,
) -> Result<Volume, VolumeError> {
    let path = path.as_ref();
    let (file, len) = VolumeError::open(path)?;
    decode(path, BufReader::new(file), len, spec, limits)
}

/// Reads raw samples held in memory, named `name` in errors.
///
/// # Errors
/// As [`read`].
pub fn parse_bytes(
    name: &str,
    bytes: &[u8],
    spec: &RawSpec,
    limits: &Limits,
) -> Result<Volume, VolumeError> {
    let len = u64::try_from(bytes.len()).unwrap_or(u64::MAX);
    decode(Path::new(name), bytes, len, spec, limits)
}

fn decode<R: Read>(
    path: &Path,
    mut reader: R,
    len: u64,
    spec: &RawSpec,
    limits: &Limits,
) -> Result<Volume, VolumeError> {
    let what = || {
        format!(
            "{} (raw {} {})",
            path.display(),
            DimsFmt(spec.dims),
            spec.sample_type
        )
    };
    if spec.dims.iter().any(|&n| n == 0 || n > super::MAX_AXIS) {
        return Err(VolumeError::Invalid {
            what: what(),
            msg: format!("each dimension must be 1 to {}", super::MAX_AXIS),
        });
    }
    spec.grid
        .validate()
        .map_err(|msg| VolumeError::Invalid { what: what(), msg })?;
    let count = check_size(path, String::new(), spec.dims, spec.sample_type, limits)?;
    let need = super::sample_count(spec.dims).saturating_mul(spec.sample_type.size());
    let expect = spec.skip.saturating_add(need);
    if len != expect {
        let (offset, msg) = if len < expect {
            (
                len,
                format!(
                    "the file ends after {len} bytes; {} header bytes and sizes {} of {} need {expect}",
                    spec.skip,
                    DimsFmt(spec.dims),
                    spec.sample_type
                ),
            )
        } else {
            (
                expect,
                format!(
                    "{} bytes more than the {expect} that {} header bytes and sizes {} of {} take: wrong sizes or type",
                    len - expect,
                    spec.skip,
                    DimsFmt(spec.dims),
                    spec.sample_type
                ),
            )
        };
        return Err(VolumeError::data(path, offset, msg));
    }
    let io = VolumeError::io(path);
    std::io::copy(&mut reader.by_ref().take(spec.skip), &mut std::io::sink()).map_err(io)?;
    let samples = Samples::read_binary(spec.sample_type, spec.endian, count, |buf| {
        reader.read_exact(buf).map_err(io)
    })?;
    Volume::new(spec.dims, spec.grid, samples)
}
