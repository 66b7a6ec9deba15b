//! The traversal digests: the seeded ray set walked through a raster in a
//! static buffer, scalar and packet, in all three connectivities, and
//! through the raster dilated by one voxel ([`DiscreteRay::walk_dilated`],
//! the shadow classification's tube walk).

use rrt_core::discrete_ray::{Connectivity, DiscreteRay, Face, Hit, WalkEnd};
use rrt_core::error::{RasterError, RayError};
use rrt_core::fixed::{VOXEL, voxel_centre};
use rrt_core::geometry::{Cuboid, Sphere};
use rrt_core::packet::{LANES, RayPacket8};
use rrt_core::proximity::{coarse_cells, distance_field, line_distances};
use rrt_core::raster::{Extent, Raster, RasterMut, cell, line_count};
use rrt_core::voxelize::{Separation, cuboid, sphere};

use crate::digest::{Digest, Line};
use crate::rays::{Spec, spec};
use crate::rng::Rng;

/// The seed of every input set.
pub const SEED: u64 = 0x7272_745f_6f6e_7467;
/// Rays in the set.
pub const RAYS: u64 = 10_000;
/// The traversal raster's dimensions (odd sizes: no stride is a power of
/// two).
pub const DIMS: [u32; 3] = [41, 35, 27];
/// Cells of the traversal raster's plane.
pub const PLANE_LEN: usize = (DIMS[0] * DIMS[1] * DIMS[2]) as usize;
/// Cells of its line level.
pub const LINES_LEN: usize = line_count(PLANE_LEN);
/// Cells of its coarse level (scratch for [`line_distances`]).
pub const BRICKS_LEN: usize = coarse_cells(DIMS);

/// The traversal raster's extent.
///
/// # Errors
/// Never for [`DIMS`]; the constructor's error otherwise.
pub fn extent() -> Result<Extent, RasterError> {
    Extent::new(DIMS[0], DIMS[1], DIMS[2])
}

/// Fills the traversal raster: a sphere shell, a wall with a hole, seeded
/// scattered voxels; then the proximity distance field (with its
/// PROXIMITY flags) and the line level.
///
/// # Errors
/// A plane or line level of the wrong length.
pub fn fill_raster(plane: &mut [u8], lines: &mut [u8]) -> Result<(), RasterError> {
    let e = extent()?;
    let mut r = RasterMut::new(e, plane)?;
    r.plane_mut().fill(cell::EMPTY);
    let mut sink = Mark(&mut r);
    let ball = Sphere {
        centre: [
            voxel_centre(12),
            voxel_centre(17) + VOXEL / 3,
            voxel_centre(13),
        ],
        radius: 8 * VOXEL + 12_345,
    };
    let _ = sphere::surface(&ball, Separation::Six, e, &mut sink);
    let wall = Cuboid {
        min: [30 * VOXEL + 777, 2 * VOXEL, VOXEL],
        max: [31 * VOXEL + 777, 33 * VOXEL, 25 * VOXEL],
    };
    let _ = cuboid::surface(&wall, Separation::TwentySix, e, &mut sink);
    let mut rng = Rng::new(SEED, u64::MAX);
    for (i, c) in r.plane_mut().iter_mut().enumerate() {
        // A hole through the wall.
        let [x, y, z] = e.coord(i).unwrap_or_default();
        if (29..=32).contains(&x) && (14..=19).contains(&y) && (10..=15).contains(&z) {
            *c = cell::EMPTY;
        }
        if rng.chance(1, 150) {
            *c = cell::OPAQUE;
        }
    }
    distance_field(&mut r);
    let mut bricks = [0u8; BRICKS_LEN];
    line_distances(&r.as_raster(), &mut bricks, lines)
}

struct Mark<'a, 'p>(&'a mut RasterMut<'p>);

impl rrt_core::voxelize::VoxelSink for Mark<'_, '_> {
    fn offer(&mut self, v: [u32; 3], _: rrt_core::voxelize::Surfel) {
        if let Some(c) = self.0.cell_mut(v) {
            *c = cell::OPAQUE;
        }
    }
}

/// Names of the per-mode digests, `[kind][mode]`.
const NAMES: [[&str; 3]; 6] = [
    [
        "ray.six.voxels",
        "ray.twenty-six.voxels",
        "ray.adaptive.voxels",
    ],
    ["ray.six.hits", "ray.twenty-six.hits", "ray.adaptive.hits"],
    ["ray.six.walk", "ray.twenty-six.walk", "ray.adaptive.walk"],
    [
        "ray.six.skipping",
        "ray.twenty-six.skipping",
        "ray.adaptive.skipping",
    ],
    [
        "packet.six.hits",
        "packet.twenty-six.hits",
        "packet.adaptive.hits",
    ],
    [
        "packet.six.walk",
        "packet.twenty-six.walk",
        "packet.adaptive.walk",
    ],
];

const fn mode_index(mode: Connectivity) -> usize {
    match mode {
        Connectivity::Six => 0,
        Connectivity::TwentySix => 1,
        Connectivity::Adaptive => 2,
    }
}

/// The budget of ray `i`'s budgeted walks: the same for the eight rays of
/// one packet.
#[must_use]
pub const fn budget(i: u64) -> u32 {
    1 + ((i / LANES as u64) % 7) as u32
}

/// The hit test of the budgeted walks: opaque, and not every such voxel
/// (so some walks resume past opaque voxels, as after a false hit).
#[must_use]
pub const fn walk_test(index: usize, c: u8) -> bool {
    c & cell::OPAQUE != 0 && index % 3 != 1
}

/// The hit test of the tube walks ([`DiscreteRay::walk_dilated`], whose
/// test sees the plane's own cell, often a transparent neighbour of an
/// opaque voxel): as [`walk_test`].
#[must_use]
pub const fn dilated_test(index: usize, c: u8) -> bool {
    walk_test(index, c)
}

/// A walk outcome as a word.
#[must_use]
pub const fn end_word(e: WalkEnd) -> u64 {
    match e {
        WalkEnd::Hit => 1,
        WalkEnd::Exit => 2,
        WalkEnd::Budget => 3,
    }
}

/// Ray `i` of the set over the traversal raster (`None` when it misses
/// the raster or is refused).
#[must_use]
pub fn ray(e: Extent, i: u64) -> Option<DiscreteRay> {
    spec(e, SEED, i).ray(e).ok().flatten()
}

/// The digest of every ray's setup: refused (with the error), missing the
/// raster, or its entry and exit voxels, entry face, crossings, driving
/// axis and whole initial state.
pub fn setup(e: Extent) -> Line {
    let mut d = Digest::new();
    for i in 0..RAYS {
        let s = spec(e, SEED, i);
        match s {
            Spec::Half { origin, dir } => {
                d.words(&origin.map(|c| c as u64));
                d.words(&dir.map(|c| i64::from(c) as u64));
            }
            Spec::Segment { from, to } => {
                d.words(&from.map(|c| c as u64));
                d.words(&to.map(|c| !(c as u64)));
            }
        }
        match s.ray(e) {
            Err(err) => d.debug(&err),
            Ok(None) => d.word(0),
            Ok(Some(r)) => {
                d.item();
                d.words(&r.origin().map(|c| c as u64));
                d.words(&r.dir().map(|c| i64::from(c) as u64));
                d.words(&r.entry_voxel().map(u64::from));
                d.words(&r.exit_voxel().map(u64::from));
                d.words(&r.crossings().map(u64::from));
                d.word(face_word(r.entry_face()) | (r.driving_axis() as u64) << 8);
                for mode in Connectivity::ALL {
                    state(&mut d, &r, mode);
                }
            }
        }
    }
    Line::of("ray.setup", &d)
}

/// Upper bound on the walks of one ray until it exits (each walk visits
/// at least one voxel); a ray that needs more is a failure, digested as
/// such.
#[must_use]
pub fn walk_limit(r: &DiscreteRay) -> u32 {
    r.crossings().iter().fold(3u32, |a, &c| a.saturating_add(c))
}

/// Ray `r`'s resume state, as its public behaviour shows it: the current
/// voxel ([`DiscreteRay::hit`]: coordinates, index, face, steps), whether
/// it is done, the last move, and the next [`PEEK`] voxels a walk from
/// this state visits in an empty raster (which depend on every stepping
/// variable). The private state itself is not digested: its `Debug` form
/// holds index offsets as wrapped `usize`, which print differently on 32-
/// and 64-bit targets while stepping identically.
pub fn state(d: &mut Digest, r: &DiscreteRay, mode: Connectivity) {
    hit(d, &r.hit());
    d.word(u64::from(r.is_done()));
    d.word(moved_word(r.last_move()));
    for v in r.path(mode).take(PEEK) {
        d.index(v.index);
        d.word(moved_word(v.moved) ^ face_word(v.face) << 32);
    }
}

/// A hit: voxel, index, face and steps.
pub fn hit(d: &mut Digest, h: &Hit) {
    let [x, y, z] = h.voxel.map(u64::from);
    d.word(x | y << 21 | z << 42);
    d.index(h.index);
    d.word(face_word(h.face) | u64::from(h.steps) << 8);
}

/// A face as a small number (0 for none).
#[must_use]
pub const fn face_word(f: Option<Face>) -> u64 {
    match f {
        None => 0,
        Some(Face::XMin) => 1,
        Some(Face::XMax) => 2,
        Some(Face::YMin) => 3,
        Some(Face::YMax) => 4,
        Some(Face::ZMin) => 5,
        Some(Face::ZMax) => 6,
    }
}

/// A move (−1, 0 or 1 per axis) as a small number.
#[must_use]
pub fn moved_word(m: [i8; 3]) -> u64 {
    m.iter()
        .fold(0u64, |a, &c| a << 2 | u64::from((c + 1) as u8 & 3))
}

/// Voxels of the continuation digested with each state.
pub const PEEK: usize = 3;

/// Ray `r`'s voxels in `mode`, into `d`.
pub fn voxels(d: &mut Digest, raster: &Raster<'_>, r: DiscreteRay, mode: Connectivity) {
    match r.voxels(raster, mode) {
        Err(e) => d.debug(&e),
        Ok(vs) => {
            for v in vs {
                d.item();
                d.index(v.index);
                d.word(u64::from(v.cell) | moved_word(v.moved) << 8 | face_word(v.face) << 16);
            }
        }
    }
}

/// Ray `r`'s hits in `mode`, resumed after each, with the whole state
/// after each and at the end, into `d`.
pub fn hits(d: &mut Digest, raster: &Raster<'_>, r: DiscreteRay, mode: Connectivity, skip: bool) {
    resumed(d, r, |d, r| {
        let h = if skip {
            r.first_hit_skipping(raster, mode)?
        } else {
            r.first_hit(raster, mode)?
        };
        if let Some(h) = h {
            d.item();
            hit(d, &h);
        }
        state(d, r, mode);
        Ok(h.is_none())
    });
}

/// Ray `r`'s budgeted walks with [`walk_test`] until it exits: each
/// outcome, the current voxel and the whole state, into `d`.
pub fn walks(d: &mut Digest, raster: &Raster<'_>, r: DiscreteRay, mode: Connectivity, budget: u32) {
    resumed(d, r, |d, r| {
        let e = r.walk(raster, mode, budget, walk_test)?;
        d.item();
        d.word(end_word(e));
        state(d, r, mode);
        Ok(e == WalkEnd::Exit)
    });
}

/// Ray `r`'s tube walk ([`DiscreteRay::walk_dilated`], no budget) with
/// [`dilated_test`], resumed after each hit until it exits: every voxel
/// the test is called on (index and plane cell, with the test's answer)
/// and each hit voxel, into `d`. It records neither the step count nor
/// the resume state, which the line level changes (its jumps are single
/// steps), so it is the same over `raster` with and without a line level.
pub fn tube(d: &mut Digest, raster: &Raster<'_>, r: DiscreteRay) {
    resumed(d, r, |d, r| {
        let e = r.walk_dilated(raster, u32::MAX, |i, c| {
            let hit = dilated_test(i, c);
            d.item();
            d.index(i);
            d.word(u64::from(c) | u64::from(hit) << 8);
            hit
        })?;
        d.word(end_word(e));
        let h = r.hit();
        let [x, y, z] = h.voxel.map(u64::from);
        d.word(x | y << 21 | z << 42);
        d.index(h.index);
        Ok(e == WalkEnd::Exit)
    });
}

/// Ray `r`'s budgeted tube walks with [`dilated_test`] until it exits:
/// each outcome and the whole resume state, into `d`.
pub fn dilated_walks(d: &mut Digest, raster: &Raster<'_>, r: DiscreteRay, budget: u32) {
    resumed(d, r, |d, r| {
        let e = r.walk_dilated(raster, budget, dilated_test)?;
        d.item();
        d.word(end_word(e));
        state(d, r, Connectivity::Adaptive);
        Ok(e == WalkEnd::Exit)
    });
}

/// Ray `r` resumed up to [`walk_limit`] times by `step`, which records its
/// outcome into `d` and says whether the ray is done; an error ends the
/// record with the error, running out of the limit with `u64::MAX`.
fn resumed(
    d: &mut Digest,
    mut r: DiscreteRay,
    mut step: impl FnMut(&mut Digest, &mut DiscreteRay) -> Result<bool, RayError>,
) {
    for _ in 0..walk_limit(&r) {
        match step(d, &mut r) {
            Ok(false) => {}
            Ok(true) => return,
            Err(e) => {
                d.debug(&e);
                return;
            }
        }
    }
    d.word(u64::MAX);
}

/// Every traversal digest, in a fixed order: `ray.setup`, then per mode the
/// scalar voxels, hits, budgeted walks and skipping hits, then the tube
/// walks ([`tube`] over the plane and over the line level, and
/// [`dilated_walks`] with the line level), then per mode the packet hits
/// and budgeted walks. The packet digests are built so that they equal
/// the scalar `hits` and `walk` digests of the same mode (each lane's
/// record is its ray's record, combined in ray order), and the two tube
/// digests so that they equal each other.
pub fn digests(raster: &Raster<'_>, lined: &Raster<'_>, out: &mut impl FnMut(Line)) {
    let e = raster.extent();
    out(setup(e));
    for mode in Connectivity::ALL {
        let m = mode_index(mode);
        let mut all = [Digest::new(); 4];
        for i in 0..RAYS {
            let Some(r) = ray(e, i) else {
                for d in &mut all[1..] {
                    d.word(Digest::new().value());
                }
                continue;
            };
            voxels(&mut all[0], raster, r, mode);
            let mut one = [Digest::new(); 3];
            hits(&mut one[0], raster, r, mode, false);
            walks(&mut one[1], raster, r, mode, budget(i));
            hits(&mut one[2], lined, r, mode, true);
            for (d, o) in all[1..].iter_mut().zip(&one) {
                fold(d, o);
            }
        }
        for (k, d) in all.iter().enumerate() {
            out(Line::of(NAMES[k][m], d));
        }
    }
    let mut all = [Digest::new(); 3];
    for i in 0..RAYS {
        let Some(r) = ray(e, i) else {
            for d in &mut all {
                d.word(Digest::new().value());
            }
            continue;
        };
        let mut one = [Digest::new(); 3];
        tube(&mut one[0], raster, r);
        tube(&mut one[1], lined, r);
        dilated_walks(&mut one[2], lined, r, budget(i));
        for (d, o) in all.iter_mut().zip(&one) {
            fold(d, o);
        }
    }
    for (name, d) in [
        "ray.dilated.tube",
        "ray.dilated.tube.lines",
        "ray.dilated.walk",
    ]
    .into_iter()
    .zip(&all)
    {
        out(Line::of(name, d));
    }
    for mode in Connectivity::ALL {
        let m = mode_index(mode);
        let (h, w) = packet_digests(raster, mode);
        out(Line::of(NAMES[4][m], &h));
        out(Line::of(NAMES[5][m], &w));
    }
}

/// Folds one ray's record into a set's digest.
fn fold(set: &mut Digest, one: &Digest) {
    set.word(one.value());
    set.add_items(one.items());
}

/// The packet digests of `mode`: the rays in packets of eight, walked to
/// each hit and resumed, and walked with the budgets and test of the
/// scalar walks.
pub fn packet_digests(raster: &Raster<'_>, mode: Connectivity) -> (Digest, Digest) {
    let e = raster.extent();
    let mut hits_set = Digest::new();
    let mut walk_set = Digest::new();
    let mut first = 0u64;
    while first < RAYS {
        let rays: [Option<DiscreteRay>; LANES] = core::array::from_fn(|l| {
            let i = first + l as u64;
            if i < RAYS { ray(e, i) } else { None }
        });
        let count = (RAYS - first).min(LANES as u64) as usize;
        let (h, w) = match RayPacket8::from_rays(e, rays) {
            Ok(p) => (
                packet_hits(raster, p.clone(), mode),
                packet_walks(raster, p, mode, budget(first)),
            ),
            Err(err) => {
                let mut d = Digest::new();
                d.debug(&err);
                ([d; LANES], [d; LANES])
            }
        };
        for l in 0..count {
            fold(&mut hits_set, &h[l]);
            fold(&mut walk_set, &w[l]);
        }
        first += LANES as u64;
    }
    (hits_set, walk_set)
}

fn packet_limit(p: &RayPacket8) -> u32 {
    (0..LANES)
        .filter_map(|l| p.lane_ray(l))
        .map(|r| walk_limit(&r))
        .max()
        .unwrap_or(0)
}

/// Per lane, the record [`hits`] makes for its ray.
fn packet_hits(raster: &Raster<'_>, p: RayPacket8, mode: Connectivity) -> [Digest; LANES] {
    packet_resumed(p, |p, d, pending| {
        let mask = p.first_hit(raster, mode)?;
        for (l, dl) in d.iter_mut().enumerate() {
            if mask & (1 << l) != 0 {
                if let (Some(h), Some(r)) = (p.hit(l), p.lane_ray(l)) {
                    dl.item();
                    hit(dl, &h);
                    state(dl, &r, mode);
                }
            } else if *pending & (1 << l) != 0 {
                // This lane exited.
                if let Some(r) = p.lane_ray(l) {
                    state(dl, &r, mode);
                }
                *pending &= !(1 << l);
            }
        }
        Ok(())
    })
}

/// Per lane, the record [`walks`] makes for its ray.
fn packet_walks(
    raster: &Raster<'_>,
    p: RayPacket8,
    mode: Connectivity,
    budget: u32,
) -> [Digest; LANES] {
    packet_resumed(p, |p, d, live| {
        let end = p.walk(raster, mode, budget, |_, i, c| walk_test(i, c))?;
        for (l, dl) in d.iter_mut().enumerate() {
            if *live & (1 << l) == 0 {
                continue;
            }
            let (Some(e), Some(r)) = (end.lane(l), p.lane_ray(l)) else {
                continue;
            };
            dl.item();
            dl.word(end_word(e));
            state(dl, &r, mode);
            if e == WalkEnd::Exit {
                *live &= !(1 << l);
            }
        }
        Ok(())
    })
}

/// Per lane, the record of packet `p` resumed up to [`packet_limit`]
/// times by `step`, which records the outcome of the lanes still live (a
/// mask it clears lanes from as they finish); an error ends every lane's
/// record with the error, running out of the limit the records of the
/// lanes still live with `u64::MAX`.
fn packet_resumed(
    mut p: RayPacket8,
    mut step: impl FnMut(&mut RayPacket8, &mut [Digest; LANES], &mut u8) -> Result<(), RayError>,
) -> [Digest; LANES] {
    let mut d = [Digest::new(); LANES];
    let mut live = p.lanes();
    for _ in 0..packet_limit(&p) {
        if let Err(e) = step(&mut p, &mut d, &mut live) {
            for dl in &mut d {
                dl.debug(&e);
            }
            return d;
        }
        if live == 0 {
            return d;
        }
    }
    for (l, dl) in d.iter_mut().enumerate() {
        if live & (1 << l) != 0 {
            dl.word(u64::MAX);
        }
    }
    d
}
