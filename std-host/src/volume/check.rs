//! The NRRD reader's invariant checker, shared by the `nrrd` fuzz target
//! and the replay test (feature `check`).

#![deny(missing_docs)]

use glam::DVec3;
use rrt_core::raster::Extent;

use super::{Classifier, Limits, Placement, Samples, nrrd};
use crate::frame::RasterFrame;

/// The limits the checker reads with: 1 MiB of samples, 64 KiB of header.
pub const FUZZ_LIMITS: Limits = Limits {
    max_bytes: 1 << 20,
    max_header_bytes: 1 << 16,
};

/// Feeds arbitrary bytes (as the file `fuzz.nrrd`) to the NRRD reader and
/// checks: an error names the file; a volume keeps its invariants (sample
/// count = product of the sizes, within the limit; a usable grid), samples
/// trilinearly within its value range, writes and reads back unchanged,
/// and makes a raster block in a small raster. A panic or a hang inside is
/// a bug the caller sees as such.
///
/// # Errors
/// The first broken invariant.
pub fn nrrd_input(data: &[u8]) -> Result<(), String> {
    let v = match nrrd::parse_bytes("fuzz.nrrd", data, &FUZZ_LIMITS) {
        Ok(v) => v,
        Err(e) => {
            let msg = e.to_string();
            return if msg.starts_with("fuzz.nrrd") {
                Ok(())
            } else {
                Err(format!("error without its file: {msg}"))
            };
        }
    };
    let dims = v.dims();
    let count = super::sample_count(dims);
    if u64::try_from(v.samples().len()).ok() != Some(count) {
        return Err(format!("{} samples for {dims:?}", v.samples().len()));
    }
    if count.saturating_mul(v.sample_type().size()) > FUZZ_LIMITS.max_bytes {
        return Err(format!(
            "{dims:?} of {} passed the size limit",
            v.sample_type()
        ));
    }
    v.grid()
        .validate()
        .map_err(|e| format!("accepted an unusable grid: {e}"))?;
    let (lo, hi) = v.range();
    let n = DVec3::from(dims.map(f64::from));
    for t in [0.0, 0.3, 0.5, 0.77, 1.0] {
        let p = n * t - 0.5;
        let Some(x) = v.sample_index(p) else {
            return Err(format!("no value inside the cells at index {p}"));
        };
        let all_finite = v.samples().iter().all(f64::is_finite);
        if all_finite && !(x >= lo - 1e-9 * lo.abs().max(1.0) && x <= hi + 1e-9 * hi.abs().max(1.0))
        {
            return Err(format!("trilinear value {x} outside the range {lo}..{hi}"));
        }
    }
    if v.sample_index(n + 1.0).is_some() {
        return Err("a value outside the cells".into());
    }
    let back = nrrd::parse_bytes("fuzz.nrrd", &nrrd::to_bytes(&v, true), &FUZZ_LIMITS)
        .map_err(|e| format!("written volume does not read back: {e}"))?;
    let same = match (v.samples(), back.samples()) {
        (Samples::F32(a), Samples::F32(b)) => {
            a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits())
        }
        (a, b) => a == b,
    };
    if !same || back.dims() != dims {
        return Err("written volume reads back different".into());
    }
    // A small raster around the volume's world box: a block or an error.
    let placed = Placement::IDENTITY.place(&v);
    let b = placed.world_bounds();
    let size = b.size().max_element();
    if size.is_finite() && size > 0.0 {
        let frame = RasterFrame {
            extent: Extent::cube(8).map_err(|e| format!("{e:?}"))?,
            origin: b.min,
            voxel_size: size / 8.0,
        };
        let c = Classifier::iso(0.5 * (lo + hi));
        if let Ok(Some(block)) = placed.raster_block(&frame, &c, 1 << 20)
            && (block.samples.len() > 512 || block.threshold == 0)
        {
            return Err(format!(
                "block of {} samples, threshold {}",
                block.samples.len(),
                block.threshold
            ));
        }
    }
    Ok(())
}
