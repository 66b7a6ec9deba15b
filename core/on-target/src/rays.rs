//! The seeded ray set: half-lines and segments in every kind of position
//! the traversal has a rule for.

use rrt_core::discrete_ray::{DiscreteRay, ORIGIN_LIMIT};
use rrt_core::error::RayError;
use rrt_core::fixed::{HALF_VOXEL, VOXEL};
use rrt_core::raster::Extent;

use crate::rng::Rng;

/// How one ray of the set is set up.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Spec {
    /// [`DiscreteRay::new`]`(origin, dir)`.
    Half {
        /// Fixed-point origin.
        origin: [i64; 3],
        /// Fixed-point direction.
        dir: [i32; 3],
    },
    /// [`DiscreteRay::segment`]`(from, to)`.
    Segment {
        /// Start.
        from: [i64; 3],
        /// End.
        to: [i64; 3],
    },
}

impl Spec {
    /// Sets the ray up over `extent`.
    ///
    /// # Errors
    /// As the constructor does.
    pub fn ray(&self, extent: Extent) -> Result<Option<DiscreteRay>, RayError> {
        match *self {
            Self::Half { origin, dir } => DiscreteRay::new(extent, origin, dir),
            Self::Segment { from, to } => DiscreteRay::segment(extent, from, to),
        }
    }
}

/// The kinds of rays, drawn in turn (`i % KINDS`).
pub const KINDS: u64 = 16;

/// Ray `i` of the set for `seed` over `extent`. Kinds, by `i % 16`:
///
/// * 0..=4, 12..=15: from a point near or outside the box towards a point
///   inside it, at sub-voxel positions, with direction magnitudes from a
///   few fixed units to the full `i32` range;
/// * 5: from inside, any direction;
/// * 6: axis-aligned, often on voxel faces;
/// * 7: diagonals (two or three equal components) from lattice points:
///   exact edge and corner crossings, where the tie rule decides;
/// * 8: segments between voxel centres;
/// * 9: segments between arbitrary points, either end possibly outside;
/// * 10: origins on a face, edge or corner of the raster box;
/// * 11: degenerate and limit cases: zero directions, unit directions,
///   `i32::MIN`/`MAX` components, origins at and beyond
///   [`ORIGIN_LIMIT`], segments too long for `i32`, zero-length segments,
///   rays grazing the box.
#[must_use]
pub fn spec(extent: Extent, seed: u64, i: u64) -> Spec {
    let mut r = Rng::new(seed, i);
    let n = extent.dims().map(|d| i64::from(d) * VOXEL);
    let inside = |r: &mut Rng| -> [i64; 3] { core::array::from_fn(|k| r.range(0, n[k] - 1)) };
    let near = |r: &mut Rng| -> [i64; 3] {
        core::array::from_fn(|k| r.range(-4 * VOXEL - n[k] / 2, n[k] + n[k] / 2 + 4 * VOXEL))
    };
    let lattice = |r: &mut Rng, frac: i64| -> [i64; 3] {
        core::array::from_fn(|k| r.range(-2, n[k] / VOXEL + 2) * VOXEL + frac)
    };
    match i % KINDS {
        5 => Spec::Half {
            origin: inside(&mut r),
            dir: random_dir(&mut r),
        },
        6 => {
            let axis = r.below(3) as usize;
            let mut origin = if r.chance(1, 2) {
                lattice(&mut r, 0)
            } else {
                inside(&mut r)
            };
            let mut dir = [0i32; 3];
            let mag = magnitude(&mut r);
            dir[axis] = (r.sign() * mag) as i32;
            if r.chance(1, 2) {
                // Start outside the box on the driving axis.
                origin[axis] = if dir[axis] > 0 {
                    -3 * VOXEL
                } else {
                    n[axis] + 3 * VOXEL
                };
            }
            Spec::Half { origin, dir }
        }
        7 => {
            let frac = if r.chance(3, 4) { 0 } else { HALF_VOXEL };
            let origin = lattice(&mut r, frac);
            let m = r.range(1, 1 << 20);
            let mut dir = [0i32; 3];
            for d in &mut dir {
                *d = (r.sign() * m) as i32;
            }
            if r.chance(1, 3) {
                // Two equal components: edge crossings only.
                let k = r.below(3) as usize;
                dir[k] = (r.sign() * r.range(0, m)) as i32;
            }
            Spec::Half { origin, dir }
        }
        8 => {
            let c = |r: &mut Rng| -> [i64; 3] {
                core::array::from_fn(|k| r.range(0, n[k] / VOXEL - 1) * VOXEL + HALF_VOXEL)
            };
            Spec::Segment {
                from: c(&mut r),
                to: c(&mut r),
            }
        }
        9 => Spec::Segment {
            from: near(&mut r),
            to: near(&mut r),
        },
        10 => {
            let mut origin = inside(&mut r);
            // One, two or three coordinates on the box's faces.
            let faces = r.range(1, 3);
            for _ in 0..faces {
                let k = r.below(3) as usize;
                origin[k] = if r.chance(1, 2) { 0 } else { n[k] };
            }
            Spec::Half {
                origin,
                dir: random_dir(&mut r),
            }
        }
        11 => {
            let o = inside(&mut r);
            degenerate(&mut r, n, o)
        }
        _ => {
            let from = near(&mut r);
            let to = inside(&mut r);
            let mag = magnitude(&mut r);
            Spec::Half {
                origin: from,
                dir: scaled(core::array::from_fn(|k| to[k] - from[k]), mag),
            }
        }
    }
}

/// A direction magnitude: a few fixed units up to the full `i32` range.
fn magnitude(r: &mut Rng) -> i64 {
    match r.below(4) {
        0 => r.range(1, 64),
        1 => r.range(64, 1 << 16),
        2 => r.range(1 << 16, 1 << 24),
        _ => r.range(1 << 24, i64::from(i32::MAX)),
    }
}

/// A random direction, some components possibly zero.
fn random_dir(r: &mut Rng) -> [i32; 3] {
    let mag = magnitude(r);
    core::array::from_fn(|_| {
        if r.chance(1, 8) {
            0
        } else {
            r.range(-mag, mag) as i32
        }
    })
}

/// `v` scaled so that its largest component has magnitude `mag` (integer
/// division: a direction close to `v`'s).
fn scaled(v: [i64; 3], mag: i64) -> [i32; 3] {
    let big = v.iter().map(|c| c.unsigned_abs()).max().unwrap_or(0);
    if big == 0 {
        return [0; 3];
    }
    v.map(|c| {
        let s = i128::from(c) * i128::from(mag) / i128::from(big);
        s.clamp(i128::from(i32::MIN), i128::from(i32::MAX)) as i32
    })
}

fn degenerate(r: &mut Rng, n: [i64; 3], inside: [i64; 3]) -> Spec {
    let k = r.below(3) as usize;
    match r.below(10) {
        0 => Spec::Half {
            origin: inside,
            dir: [0; 3],
        },
        1 => {
            let mut dir = [0i32; 3];
            dir[k] = r.sign() as i32;
            Spec::Half {
                origin: inside,
                dir,
            }
        }
        2 => Spec::Half {
            origin: inside,
            dir: core::array::from_fn(|_| if r.chance(1, 2) { i32::MIN } else { i32::MAX }),
        },
        3 => {
            // At (or one unit past) the origin limit.
            let mut origin = inside;
            origin[k] = r.sign() * (ORIGIN_LIMIT + r.range(0, 1));
            let mut dir = random_dir(r);
            dir[k] = if origin[k] > 0 { -i32::MAX } else { i32::MAX };
            Spec::Half { origin, dir }
        }
        4 => {
            let mut to = inside;
            to[k] = inside[k] + r.sign() * (1 << 40);
            Spec::Segment { from: inside, to }
        }
        5 => Spec::Segment {
            from: inside,
            to: inside,
        },
        6 => {
            // Along an edge of the box: touches it in a line, no voxel.
            let mut origin = [0i64; 3];
            let j = (k + 1) % 3;
            origin[j] = if r.chance(1, 2) { 0 } else { n[j] };
            origin[(k + 2) % 3] = if r.chance(1, 2) { 0 } else { n[(k + 2) % 3] };
            origin[k] = -VOXEL;
            let mut dir = [0i32; 3];
            dir[k] = VOXEL as i32;
            Spec::Half { origin, dir }
        }
        7 => {
            // Outside a slab the ray is parallel to.
            let mut origin = inside;
            origin[k] = n[k] + r.range(0, 2) * HALF_VOXEL;
            let mut dir = random_dir(r);
            dir[k] = 0;
            Spec::Half { origin, dir }
        }
        8 => {
            // Pointing away from the box.
            let mut origin = inside;
            origin[k] = -VOXEL;
            let mut dir = random_dir(r);
            dir[k] = -(1 + r.range(0, 1000)) as i32;
            Spec::Half { origin, dir }
        }
        _ => Spec::Half {
            origin: core::array::from_fn(|j| r.range(-(1 << 40), 1 << 40) + n[j] / 2),
            dir: random_dir(r),
        },
    }
}
