//! Tunnel-freedom probes: a closed shape voxelized into a fresh plane,
//! rays fired from inside it in every direction that must all meet the
//! surface ([`assert_tunnel_free`]), the origins to fire them from, and the
//! seeds a test runs.

use rrt_core::check_voxelize::{PlaneSink, check_closed, probe_targets};
use rrt_core::discrete_ray::Connectivity;
use rrt_core::fixed::{VOXEL, voxel_centre};
use rrt_core::proximity::flag_neighbourhood;
use rrt_core::raster::{Extent, Raster, RasterMut};
use rrt_core::voxelize::Separation;

use crate::Rng;

/// Seeds to run: `RRT_SEED` alone if set, else `0..n` (times `RRT_SCALE`
/// when set, for longer soak runs, e.g. `RRT_SCALE=20` in release mode).
pub fn seeds(n: u64) -> Vec<u64> {
    let scale: u64 = std::env::var("RRT_SCALE")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(1);
    match std::env::var("RRT_SEED") {
        Ok(s) => vec![s.parse().expect("RRT_SEED is a number")],
        Err(_) => (0..n * scale).collect(),
    }
}

/// A shape voxelized into a fresh plane.
pub struct Voxelized {
    /// The raster's extent.
    pub extent: Extent,
    /// The plane, opaque where the shape was offered.
    pub plane: Vec<u8>,
}

impl Voxelized {
    /// The plane `fill` voxelizes into (through a `PlaneSink`); panics if
    /// it offers a voxel outside `extent`.
    #[must_use]
    pub fn new(extent: Extent, fill: impl FnOnce(&mut PlaneSink<'_>)) -> Self {
        let mut plane = vec![0u8; extent.len()];
        let mut sink = PlaneSink::new(extent, &mut plane).unwrap();
        fill(&mut sink);
        assert_eq!(sink.outside, 0, "offer outside the raster");
        Self { extent, plane }
    }

    /// A copy of the plane with the proximity flags set around every
    /// voxel, as adaptive rays need it.
    #[must_use]
    pub fn flagged(&self) -> Vec<u8> {
        let mut flagged = self.plane.clone();
        flag_neighbourhood(&mut RasterMut::new(self.extent, &mut flagged).unwrap());
        flagged
    }
}

/// The connectivities a surface voxelized with `sep` must stop: 6-tunnel-free
/// surfaces stop six and adaptive rays, 26-tunnel-free ones twenty-six rays
/// (and, being thicker, six rays too).
#[must_use]
pub fn stopped_by(sep: Separation) -> &'static [Connectivity] {
    match sep {
        Separation::Six => &[Connectivity::Six, Connectivity::Adaptive],
        Separation::TwentySix => &[Connectivity::TwentySix, Connectivity::Six],
    }
}

/// Asserts that the closed surface in `shape` has no tunnel: fires the probe
/// rays (`check_closed`'s lattice targets and 64 random ones) from every
/// origin in `origins`, in each connectivity of [`stopped_by`]`(sep)`, each
/// ray only if the centre of its first voxel satisfies `inside`, and panics
/// naming `what` on the first ray that leaves the inside without meeting an
/// opaque voxel. Returns the number of rays fired.
#[track_caller]
pub fn assert_tunnel_free(
    shape: &Voxelized,
    sep: Separation,
    origins: &[[i64; 3]],
    rng: &mut Rng,
    inside: &dyn Fn([i64; 3]) -> bool,
    what: &str,
) -> u64 {
    let flagged = shape.flagged();
    let raster = Raster::new(shape.extent, &flagged).unwrap();
    let mut fired = 0u64;
    for &o in origins {
        let random: Vec<[i64; 3]> = (0..64)
            .map(|_| {
                let d = [0; 3].map(|_| rng.range(-(1 << 24), 1 << 24));
                [o[0] + d[0], o[1] + d[1], o[2] + d[2]]
            })
            .collect();
        for &mode in stopped_by(sep) {
            let targets = probe_targets(o, 3).chain(random.iter().copied());
            let ok = |v: [u32; 3]| inside(v.map(voxel_centre));
            match check_closed(&raster, o, mode, targets, ok) {
                Ok(n) => fired += u64::from(n),
                Err(v) => panic!("{what}: {sep:?} surface has a tunnel: {v:?}"),
            }
        }
    }
    fired
}

/// [`assert_tunnel_free`] for a closed shape voxelized by `voxelize` with
/// each separation in turn (6-, then 26-tunnel-free), from the same
/// origins. Returns the number of rays fired.
#[track_caller]
pub fn assert_tunnel_free_both(
    extent: Extent,
    origins: &[[i64; 3]],
    rng: &mut Rng,
    inside: &dyn Fn([i64; 3]) -> bool,
    what: &str,
    voxelize: impl Fn(Separation, &mut PlaneSink<'_>),
) -> u64 {
    [Separation::Six, Separation::TwentySix]
        .into_iter()
        .map(|sep| {
            let shape = Voxelized::new(extent, |sink| voxelize(sep, sink));
            assert_tunnel_free(&shape, sep, origins, rng, inside, what)
        })
        .sum()
}

/// Up to `n` ray origins in voxels whose centre satisfies `inside`: voxel
/// centres, low corners (whose rays start in a direction-dependent voxel,
/// which [`assert_tunnel_free`] tests again) and random points.
pub fn origins(
    extent: Extent,
    lo: [i64; 3],
    hi: [i64; 3],
    n: usize,
    rng: &mut Rng,
    inside: impl Fn([i64; 3]) -> bool,
) -> Vec<[i64; 3]> {
    let mut out = Vec::new();
    let cell = |p: i64| p.div_euclid(VOXEL);
    for attempt in 0..n * 40 {
        if out.len() >= n {
            break;
        }
        let p = [0, 1, 2].map(|k| rng.range(lo[k], hi[k]));
        let v = p.map(cell);
        if v.iter()
            .zip(extent.dims())
            .any(|(&c, d)| c < 0 || c >= i64::from(d))
        {
            continue;
        }
        let centre = v.map(|c| voxel_centre(c as u32));
        if !inside(centre) {
            continue;
        }
        // Origin at the centre, at the voxel's low corner, or anywhere in it.
        out.push(match attempt % 3 {
            0 => centre,
            1 => v.map(|c| c * VOXEL),
            _ => p,
        });
    }
    out
}
