//! Tunnel-freedom of voxelized closed shapes, as seeded property tests.
//!
//! For every closed shape, discrete rays of the matching connectivity
//! (Separation::Six ⇒ Six, and Adaptive over proximity flags;
//! Separation::TwentySix ⇒ TwentySix) are fired from voxels whose centre lies
//! inside the shape towards every voxel corner, edge midpoint and face
//! centre on a cube around the origin (so they pass straight through voxel
//! corners and edges) plus random directions; every ray must hit a surface
//! voxel before it leaves the raster. The shared checker is
//! `rrt_core::check_voxelize`.
//!
//! Every case derives from a printed seed: `RRT_SEED=<seed>` replays one.

use rrt_core::check_voxelize::{PlaneSink, check_closed, probe_targets};
use rrt_core::discrete_ray::Connectivity;
use rrt_core::fixed::{VOXEL, voxel_centre};
use rrt_core::geometry::Sphere;
use rrt_core::proximity::flag_neighbourhood;
use rrt_core::raster::{Extent, Raster, RasterMut};
use rrt_core::voxelize::{Separation, sphere};
use rrt_tests::Rng;

/// Seeds to run: `RRT_SEED` alone if set, else `0..n`.
fn seeds(n: u64) -> Vec<u64> {
    match std::env::var("RRT_SEED") {
        Ok(s) => vec![s.parse().expect("RRT_SEED is a number")],
        Err(_) => (0..n).collect(),
    }
}

/// A closed shape voxelized into a fresh plane, with a predicate telling
/// which voxel centres lie inside it.
pub struct Voxelized {
    pub extent: Extent,
    pub plane: Vec<u8>,
}

impl Voxelized {
    pub fn new(extent: Extent, fill: impl FnOnce(&mut PlaneSink<'_>)) -> Self {
        let mut plane = vec![0u8; extent.len()];
        let mut sink = PlaneSink::new(extent, &mut plane).unwrap();
        fill(&mut sink);
        assert_eq!(sink.outside, 0, "offer outside the raster");
        Self { extent, plane }
    }

    /// Fires the probe rays from `origins` in the connectivities matching
    /// `sep`, each ray only if the centre of its first voxel satisfies
    /// `inside`; panics naming `what` on a tunnel. Returns the number of rays
    /// fired.
    #[track_caller]
    pub fn check(
        &mut self,
        sep: Separation,
        origins: &[[i64; 3]],
        rng: &mut Rng,
        inside: &dyn Fn([i64; 3]) -> bool,
        what: &str,
    ) -> u64 {
        let modes: &[Connectivity] = match sep {
            Separation::Six => &[Connectivity::Six, Connectivity::Adaptive],
            Separation::TwentySix => &[Connectivity::TwentySix, Connectivity::Six],
        };
        let mut flagged = self.plane.clone();
        flag_neighbourhood(&mut RasterMut::new(self.extent, &mut flagged).unwrap());
        let raster = Raster::new(self.extent, &flagged).unwrap();
        let mut fired = 0u64;
        for &o in origins {
            let random: Vec<[i64; 3]> = (0..64)
                .map(|_| {
                    let d = [0; 3].map(|_| rng.range_i64(-(1 << 24), 1 << 24));
                    [o[0] + d[0], o[1] + d[1], o[2] + d[2]]
                })
                .collect();
            for &mode in modes {
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
}

/// Up to `n` ray origins in voxels whose centre satisfies `inside`: voxel
/// centres, low corners (whose rays start in a direction-dependent voxel,
/// which `Voxelized::check` tests again) and random points.
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
        let p = [0, 1, 2].map(|k| rng.range_i64(lo[k], hi[k]));
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

#[test]
fn spheres_are_tunnel_free() {
    let mut rays = 0u64;
    for seed in seeds(120) {
        let mut rng = Rng::new(seed);
        // Radii from half a voxel to 14 voxels, some on exact lattice values.
        let r = match seed % 4 {
            0 => rng.range_i64(VOXEL / 2, 3 * VOXEL),
            1 => rng.range_i64(1, 14) * VOXEL,
            2 => rng.range_i64(1, 28) * VOXEL / 2,
            _ => rng.range_i64(3 * VOXEL, 14 * VOXEL),
        };
        let n = u32::try_from(2 * (r / VOXEL) + 6).unwrap();
        let extent = Extent::cube(n).unwrap();
        let mid = i64::from(n) * VOXEL / 2;
        let jitter = |rng: &mut Rng| match seed % 3 {
            0 => mid,
            1 => mid + VOXEL / 2,
            _ => mid + rng.range_i64(-VOXEL, VOXEL),
        };
        let c = [jitter(&mut rng), jitter(&mut rng), jitter(&mut rng)];
        let s = Sphere {
            centre: c,
            radius: r,
        };
        let inside = |p: [i64; 3]| {
            let d: i128 = (0..3).map(|k| i128::from(p[k] - c[k]).pow(2)).sum();
            d < i128::from(r).pow(2)
        };
        let lo = c.map(|v| v - r);
        let hi = c.map(|v| v + r);
        let os = origins(extent, lo, hi, 4, &mut rng, inside);
        for sep in [Separation::Six, Separation::TwentySix] {
            let mut v = Voxelized::new(extent, |sink| {
                sphere::surface(&s, sep, extent, sink).unwrap();
            });
            rays += v.check(sep, &os, &mut rng, &inside, &format!("seed {seed}: {s:?}"));
        }
    }
    println!("spheres: {rays} rays, all hit");
    assert!(rays > 100_000);
}
