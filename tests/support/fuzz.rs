//! Fuzz cases shared by the cargo-fuzz targets (`fuzz/`) and the stable
//! replay test (`tests/fuzz_regressions.rs`): the same `Arbitrary`
//! decoding and the same checkers run in both, so a crash file found by
//! the fuzzer replays exactly under `cargo test`.

use arbitrary::Arbitrary;
use rrt_core::check::{check_adaptive_matches_six, check_skipping};
use rrt_core::discrete_ray::{Connectivity, DiscreteRay};
use rrt_core::error::RayError;
use rrt_core::fixed::VOXEL;
use rrt_core::proximity::{coarse_extent, distance_field, flag_neighbourhood, line_distances};
use rrt_core::raster::{Extent, RasterMut, cell, line_count};

use crate::oracle::{Case, check_exact};

/// One fixed-point coordinate, biased towards the interesting ones (the
/// discrete-ray and the packet fuzz cases').
#[derive(Arbitrary, Debug, Clone, Copy)]
pub enum Coord {
    /// Any value (mostly beyond `ORIGIN_LIMIT`: must be refused).
    Raw(i64),
    /// Near the box, in fixed units.
    Near(i32),
    /// On a voxel boundary (faces, edges and corners).
    Lattice(i8),
    /// At a voxel centre.
    Centre(i8),
}

impl Coord {
    fn fixed(self) -> i64 {
        match self {
            Self::Raw(v) => v,
            Self::Near(v) => i64::from(v),
            Self::Lattice(v) => i64::from(v) * VOXEL,
            Self::Centre(v) => i64::from(v) * VOXEL + VOXEL / 2,
        }
    }
}

/// One direction component.
#[derive(Arbitrary, Debug, Clone, Copy)]
pub enum Component {
    /// Any `i32`.
    Raw(i32),
    /// A small value (±1 of the last fractional bit and around).
    Small(i8),
    /// Whole voxels (equal magnitudes give exact diagonals).
    Voxels(i8),
}

impl Component {
    fn fixed(self) -> i32 {
        match self {
            Self::Raw(v) => v,
            Self::Small(v) => i32::from(v),
            Self::Voxels(v) => i32::from(v) * (1 << 16),
        }
    }
}

/// The ray a fuzz case describes, with its origin and direction in fixed
/// point: from `origin` along `dir`, or with `segment` the segment from
/// `origin` to `origin + dir`.
pub(crate) fn decode_ray(
    extent: Extent,
    origin: [Coord; 3],
    dir: [Component; 3],
    segment: bool,
) -> ([i64; 3], [i32; 3], Result<Option<DiscreteRay>, RayError>) {
    let origin = origin.map(Coord::fixed);
    let dir = dir.map(Component::fixed);
    let ray = if segment {
        let to = [0, 1, 2].map(|k| origin[k].wrapping_add(i64::from(dir[k])));
        DiscreteRay::segment(extent, origin, to)
    } else {
        DiscreteRay::new(extent, origin, dir)
    };
    (origin, dir, ray)
}

/// A plane of `len` cells: the OPAQUE and PROXIMITY bits of `cells`,
/// repeated (empty for no cells).
pub(crate) fn repeated_cells(cells: &[u8], len: usize) -> Vec<u8> {
    (0..len)
        .map(|i| {
            cells
                .get(i % cells.len().max(1))
                .map_or(0, |b| b & (cell::OPAQUE | cell::PROXIMITY))
        })
        .collect()
}

/// A discrete ray through a small raster with random cells.
#[derive(Arbitrary, Debug, Clone)]
pub struct RayCase {
    /// Raster dimensions, each taken modulo 32, plus one.
    pub dims: [u8; 3],
    /// Cell bits, repeated over the plane (bit 0 OPAQUE, bit 1 PROXIMITY).
    pub cells: Vec<u8>,
    /// Origin.
    pub origin: [Coord; 3],
    /// Direction, or segment extent.
    pub dir: [Component; 3],
    /// A segment rather than a half-line.
    pub segment: bool,
}

/// Runs the oracle and every discrete-ray checker on `case`; panics on
/// the first violation (the fuzzer reports the panic as a crash).
pub fn run_ray_case(case: &RayCase) {
    let dims = case.dims.map(|d| u32::from(d % 32) + 1);
    let Ok(extent) = Extent::new(dims[0], dims[1], dims[2]) else {
        unreachable!("dims in 1..=32")
    };
    let (origin, dir, set_up) = decode_ray(extent, case.origin, case.dir, case.segment);
    let c = Case {
        dims,
        origin,
        dir,
        segment: case.segment,
    };
    // Out-of-range inputs must be refused with the documented errors.
    match set_up {
        Ok(_) => {}
        Err(RayError::OriginOutOfRange { .. } | RayError::SegmentTooLong { .. }) => return,
        Err(e) => panic!("setup failed for an accepted input: {e:?} {c:?}"),
    }
    let mut plane = repeated_cells(&case.cells, extent.len());
    check_exact(&c, Some(&plane), "fuzz");
    // With proper proximity flags, Adaptive must hit what Six hits.
    let mut raster = RasterMut::new(extent, &mut plane).expect("plane length");
    flag_neighbourhood(&mut raster);
    let r = raster.as_raster();
    if let Ok(Some(ray)) = set_up
        && let Err(v) = check_adaptive_matches_six(&r, &ray)
    {
        panic!("adaptive missed a six hit: {v:?} {c:?}");
    }
    // With proximity distances, skipping finds the same hits and states,
    // from the plane alone and through its line level.
    distance_field(&mut raster);
    let r = raster.as_raster();
    let mut lines = vec![0u8; line_count(r.plane().len())];
    let mut bricks = vec![0u8; coarse_extent(extent).expect("coarse extent").len()];
    line_distances(&r, &mut bricks, &mut lines).expect("line level length");
    let with_lines = r.with_lines(&lines).expect("line level length");
    if let Ok(Some(ray)) = set_up {
        for raster in [r, with_lines] {
            for mode in Connectivity::ALL {
                if let Err(v) = check_skipping(&raster, &ray, mode) {
                    panic!("skipping diverged in {mode:?}: {v:?} {c:?}");
                }
            }
        }
    }
}
