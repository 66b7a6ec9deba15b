//! A selection of rrt-core's own invariant checkers (its `check` feature),
//! run over the traversal raster, the seeded rays and voxelized closed
//! shapes, and one of this crate's: the tube walk
//! ([`DiscreteRay::walk_dilated`]) against the tube found by brute force.

use core::fmt;

use rrt_core::check::{
    check_adaptive_matches_six, check_lattice_counts, check_ray, check_skipping,
};
use rrt_core::check_packet::check_packet;
use rrt_core::check_voxelize::{PlaneSink, check_closed, probe_targets};
use rrt_core::discrete_ray::{Connectivity, DiscreteRay, WalkEnd};
use rrt_core::fixed::{VOXEL, voxel_centre};
use rrt_core::geometry::{Cone, Cuboid, Sphere};
use rrt_core::packet::{LANES, RayPacket8};
use rrt_core::proximity::flag_neighbourhood;
use rrt_core::raster::{Extent, Raster, RasterMut, cell};
use rrt_core::voxelize::{Separation, cone, cuboid, sphere};

use crate::rng::Rng;
use crate::traversal::{RAYS, SEED, dilated_test, ray, walk_limit};

/// Passed and failed runs of one checker.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Tally {
    /// The checker.
    pub name: &'static str,
    /// Runs that found no violation.
    pub passed: u32,
    /// Runs that did.
    pub failed: u32,
}

impl Tally {
    const fn new(name: &'static str) -> Self {
        Self {
            name,
            passed: 0,
            failed: 0,
        }
    }

    fn add<T, E: fmt::Debug>(
        &mut self,
        r: Result<T, E>,
        fail: &mut impl FnMut(&'static str, &dyn fmt::Debug),
    ) {
        match r {
            Ok(_) => self.passed += 1,
            Err(e) => {
                self.failed += 1;
                fail(self.name, &e);
            }
        }
    }
}

impl fmt::Display for Tally {
    /// `check <name> <passed> <failed>`: the format the run script reads.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "check {} {} {}", self.name, self.passed, self.failed)
    }
}

/// Rays given to `check_ray`: every `RAY_STRIDE`-th.
pub const RAY_STRIDE: u64 = 3;
/// Rays and packets checked by the more expensive checkers: every
/// `STRIDE`-th.
pub const STRIDE: u64 = 8;
/// Voxel-centre pairs given to [`check_lattice_counts`].
pub const LATTICE_PAIRS: u64 = 500;
/// Side of the raster the tunnel checks voxelize closed shapes into.
pub const CLOSED_SIDE: u32 = 24;
/// Cells of the tunnel checks' scratch plane.
pub const SCRATCH_LEN: usize = (CLOSED_SIDE * CLOSED_SIDE * CLOSED_SIDE) as usize;

/// Runs the checkers: `check_ray` on every [`RAY_STRIDE`]-th ray in every mode,
/// `check_adaptive_matches_six` on every ray, `check_skipping` and
/// `check_packet` on every [`STRIDE`]-th ray or packet,
/// `check_lattice_counts` on seeded voxel-centre pairs, `check_closed`
/// (no ray from inside escapes) on a sphere, a box and a capped cone in
/// both separations, and [`check_tube`] on every ray over both rasters. `raster` is the traversal raster, `lined` the same
/// with its distance field and line level; `scratch` holds
/// `CLOSED_SIDE³` cells. Each failure goes to `fail` with the checker's
/// name and the violation.
pub fn run(
    raster: &Raster<'_>,
    lined: &Raster<'_>,
    scratch: &mut [u8],
    fail: &mut impl FnMut(&'static str, &dyn fmt::Debug),
) -> [Tally; 7] {
    let e = raster.extent();
    let mut t = [
        Tally::new("check_ray"),
        Tally::new("check_adaptive_matches_six"),
        Tally::new("check_skipping"),
        Tally::new("check_packet"),
        Tally::new("check_lattice_counts"),
        Tally::new("check_closed"),
        Tally::new("check_tube"),
    ];
    for i in 0..RAYS {
        let Some(r) = ray(e, i) else { continue };
        for mode in Connectivity::ALL {
            if i.is_multiple_of(RAY_STRIDE) {
                t[0].add(check_ray(raster, &r, mode), fail);
            }
            if i.is_multiple_of(STRIDE) {
                t[2].add(check_skipping(lined, &r, mode), fail);
            }
        }
        t[1].add(check_adaptive_matches_six(raster, &r), fail);
        for rs in [raster, lined] {
            t[6].add(check_tube(rs, r).map_err(|v| (i, v)), fail);
        }
    }
    let mut first = 0;
    while first < RAYS {
        if (first / LANES as u64).is_multiple_of(STRIDE) {
            let rays: [Option<DiscreteRay>; LANES] =
                core::array::from_fn(|l| ray(e, first + l as u64));
            match RayPacket8::from_rays(e, rays) {
                Ok(p) => t[3].add(check_packet(raster, &p), fail),
                Err(err) => t[3].add(Err::<(), _>(err), fail),
            }
        }
        first += LANES as u64;
    }
    let mut rng = Rng::new(SEED, 0x01a7_71ce);
    let dims = e.dims();
    for _ in 0..LATTICE_PAIRS {
        let mut v =
            || -> [u32; 3] { core::array::from_fn(|k| rng.below(u64::from(dims[k])) as u32) };
        let (a, b) = (v(), v());
        t[4].add(check_lattice_counts(raster, a, b), fail);
    }
    closed(&mut t[5], scratch, fail);
    t
}

/// Where a tube walk left the brute-force tube.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TubeViolation {
    /// The walk failed.
    Walk(rrt_core::error::RayError),
    /// The `call`-th test call (counted over the resumed walks) was on
    /// `got` (index, cell), where the tube has `expected` next (`None`:
    /// past its end, or the walk ended before it).
    Call {
        /// The call's number.
        call: u64,
        /// The walk's voxel and cell.
        got: Option<(usize, u8)>,
        /// The tube's.
        expected: Option<(usize, u8)>,
    },
    /// The walk did not exit within the resumption limit.
    Endless,
}

/// The tube walk checked against brute force: ray `r` walked through
/// `raster` by [`DiscreteRay::walk_dilated`] with [`dilated_test`], resumed
/// after each hit until it exits, must call its test exactly on the
/// voxels of the ray's 6-connected path that have an opaque voxel of the
/// plane within chessboard distance 1 (looked up cell by cell), in path
/// order, each with the plane's own cell. This is what the shadow
/// classification's proof rests on (`rrt_core::light`, *Shadow
/// classification*). Returns the number of calls.
///
/// # Errors
/// The first difference.
pub fn check_tube(raster: &Raster<'_>, r: DiscreteRay) -> Result<u64, TubeViolation> {
    let e = raster.extent();
    let plane = raster.plane();
    let [nx, ny, nz] = e.dims();
    let near = |[x, y, z]: [u32; 3]| {
        let span = |c: u32, n: u32| c.saturating_sub(1)..=(c + 1).min(n - 1);
        span(z, nz).any(|w| {
            span(y, ny).any(|v| {
                span(x, nx).any(|u| {
                    e.index([u, v, w])
                        .and_then(|i| plane.get(i))
                        .is_some_and(|&c| c & cell::OPAQUE != 0)
                })
            })
        })
    };
    let mut expected = r.path(Connectivity::Six).filter_map(|v| {
        let c = plane.get(v.index).copied()?;
        near(e.coord(v.index)?).then_some((v.index, c))
    });
    let mut walker = r;
    let mut calls = 0u64;
    let mut bad = None;
    let mut exited = false;
    for _ in 0..walk_limit(&r) {
        let end = walker.walk_dilated(raster, u32::MAX, |i, c| {
            let want = expected.next();
            if bad.is_none() && want != Some((i, c)) {
                bad = Some(TubeViolation::Call {
                    call: calls,
                    got: Some((i, c)),
                    expected: want,
                });
            }
            calls += 1;
            dilated_test(i, c)
        });
        match end {
            Ok(WalkEnd::Exit) => {
                exited = true;
                break;
            }
            Ok(_) => {}
            Err(err) => return Err(TubeViolation::Walk(err)),
        }
    }
    if let Some(v) = bad {
        return Err(v);
    }
    if !exited {
        return Err(TubeViolation::Endless);
    }
    match expected.next() {
        None => Ok(calls),
        Some(w) => Err(TubeViolation::Call {
            call: calls,
            got: None,
            expected: Some(w),
        }),
    }
}

/// Tunnel checks: every ray from a shape's centre towards the corners,
/// edge midpoints and face centres around it hits the shape's voxels.
fn closed(t: &mut Tally, scratch: &mut [u8], fail: &mut impl FnMut(&'static str, &dyn fmt::Debug)) {
    let Ok(e) = Extent::cube(CLOSED_SIDE) else {
        return;
    };
    let c = voxel_centre(CLOSED_SIDE / 2) - VOXEL / 2 + 4321;
    let centre = [c, c + 999, c - 1234];
    for sep in [Separation::Six, Separation::TwentySix] {
        let mode = match sep {
            Separation::Six => Connectivity::Six,
            Separation::TwentySix => Connectivity::TwentySix,
        };
        for shape in 0..3 {
            let Some(plane) = scratch.get_mut(..e.len()) else {
                return;
            };
            plane.fill(cell::EMPTY);
            let Some(mut sink) = PlaneSink::new(e, plane) else {
                return;
            };
            let r = match shape {
                0 => sphere::surface(
                    &Sphere {
                        centre,
                        radius: 7 * VOXEL + 3333,
                    },
                    sep,
                    e,
                    &mut sink,
                ),
                1 => cuboid::surface(
                    &Cuboid {
                        min: centre.map(|x| x - 6 * VOXEL - 777),
                        max: centre.map(|x| x + 5 * VOXEL + 123),
                    },
                    sep,
                    e,
                    &mut sink,
                ),
                _ => cone::capped(
                    &Cone {
                        base: [centre[0] - VOXEL, centre[1], centre[2] - 7 * VOXEL],
                        base_radius: 6 * VOXEL,
                        apex: [
                            centre[0] + VOXEL,
                            centre[1] + 2 * VOXEL,
                            centre[2] + 8 * VOXEL,
                        ],
                        apex_radius: 2 * VOXEL + 5000,
                    },
                    sep,
                    e,
                    &mut sink,
                ),
            };
            if r.is_err() {
                t.add(r, fail);
                continue;
            }
            let Ok(mut rm) = RasterMut::new(e, plane) else {
                return;
            };
            flag_neighbourhood(&mut rm);
            let raster = rm.as_raster();
            // The origin voxel must be inside the shape: only rays whose
            // first voxel is the centre's own are fired.
            let own = e.index(centre.map(|x| (x / VOXEL) as u32));
            let res = check_closed(&raster, centre, mode, probe_targets(centre, 10), |v| {
                e.index(v) == own
            });
            match res {
                Ok(0) => t.add(
                    Err::<(), _>("no ray fired: the shape misses its centre"),
                    fail,
                ),
                other => t.add(other, fail),
            }
        }
    }
}
