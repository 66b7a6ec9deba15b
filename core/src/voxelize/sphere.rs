//! Spheres: the surface shell and the solid ball.
//!
//! ```
//! use rrt_core::geometry::Sphere;
//! use rrt_core::fixed::{voxel_centre, VOXEL};
//! use rrt_core::raster::Extent;
//! use rrt_core::voxelize::{sphere, Separation, Surfel, VoxelSink};
//!
//! struct Count(u32);
//! impl VoxelSink for Count {
//!     fn offer(&mut self, _: [u32; 3], _: Surfel) { self.0 += 1; }
//! }
//! let s = Sphere { centre: [voxel_centre(8); 3], radius: 5 * VOXEL };
//! let mut n = Count(0);
//! let offers = sphere::surface(&s, Separation::Six, Extent::cube(16).unwrap(), &mut n).unwrap();
//! assert_eq!(u64::from(n.0), offers);
//! assert!(offers > 200 && offers < 400);
//! ```
//!
//! # Which voxels
//! * [`Separation::TwentySix`]: every voxel whose closed cube meets the
//!   sphere.
//! * [`Separation::Six`]: every voxel one of whose three axis-parallel
//!   *centre segments* (from face centre to opposite face centre) meets the
//!   sphere; each such voxel is offered once.
//!
//! These are the *lattice-step rule* (see [`super::triangle`]: a voxel belongs
//! to the surface when a lattice step of half length from its centre reaches
//! the surface); for a plane they are exactly the thickness rule. Any
//! discrete ray of the matching connectivity whose voxel centres pass from
//! inside the sphere to outside meets one of them, so the shell is
//! tunnel-free by construction (see `tests/voxelize_tunnel.rs`).
//!
//! [`solid`] adds every voxel whose centre lies inside the sphere, with
//! distance 0.
//!
//! # Accepted input and cost
//! Centre coordinates and the radius within
//! [`COORD_LIMIT`](super::error::COORD_LIMIT); the radius must be positive.
//! The sphere is clipped to the raster. Work is one square root per column
//! of the clipped projection (three projections for Six) plus a constant
//! per voxel offered.
//
// Implementation notes.
//
// TwentySix, column (x, y) along z: with a_min/a_max the smallest/largest
// lateral distance from the centre to the column's square, a cell [z0, z1]
// meets the sphere iff a_min² + dz_min² ≤ R² ≤ a_max² + dz_max², dz_min/max
// the nearest/farthest z-distance from Cz to [z0, z1]. The first condition
// holds on the cells overlapping [Cz − H_in, Cz + H_in], H_in =
// ⌊√(R² − a_min²)⌋ (exact: dz_min is an integer); the second fails exactly
// on the cells strictly inside (Cz − H_out, Cz + H_out), H_out =
// ⌈√(R² − a_max²)⌉. So each column is one interval minus one interval.
//
// Six, centre lines along axis k through (a, b): the line meets the sphere
// at Cz ± √D, D = R² − lateral²; the cells whose closed k-range holds one of
// the two points are the voxels of that line. √D is irrational unless D is
// a square; then no face (an integer) lies strictly between Cz + ⌊√D⌋ and
// the crossing, so the floor of ⌊√D⌋'s cell is the crossing's cell. A voxel
// found on axis k is skipped when an axis j < k also reaches it (a closed
// test on its centre segment), so each voxel is offered once.

use super::error::VoxelizeError;
use super::fixmath::{
    Counter, H, V, ceil_sqrt, cell_floor, cells_overlapping, centre, centres_within, check_point,
    clip, dist_u32, isqrt, radial, split, sub, window,
};
use super::{NORMAL_ONE, Separation, Surfel, VoxelSink};
use crate::geometry::Sphere;
use crate::raster::Extent;

/// Voxelizes the surface of `sphere` into `sink`, clipped to `extent`.
/// Returns the number of offers (each voxel is offered once).
///
/// # Errors
/// [`VoxelizeError::NonPositiveRadius`] for a radius ≤ 0,
/// [`VoxelizeError::OutOfRange`] beyond
/// [`COORD_LIMIT`](super::error::COORD_LIMIT).
pub fn surface<S: VoxelSink + ?Sized>(
    sphere: &Sphere,
    separation: Separation,
    extent: Extent,
    sink: &mut S,
) -> Result<u64, VoxelizeError> {
    shell(sphere, separation, extent, sink, false)
}

/// Voxelizes the solid ball: the surface shell of [`surface`] plus every
/// voxel whose centre lies inside the sphere, offered with distance 0.
/// Returns the number of offers (each voxel is offered once).
///
/// # Errors
/// As [`surface`].
pub fn solid<S: VoxelSink + ?Sized>(
    sphere: &Sphere,
    separation: Separation,
    extent: Extent,
    sink: &mut S,
) -> Result<u64, VoxelizeError> {
    shell(sphere, separation, extent, sink, true)
}

/// [`surface`], and with `fill` the voxels inside too ([`solid`]).
fn shell<S: VoxelSink + ?Sized>(
    sphere: &Sphere,
    separation: Separation,
    extent: Extent,
    sink: &mut S,
    fill: bool,
) -> Result<u64, VoxelizeError> {
    let b = Ball::new(sphere, window(extent, sink))?;
    let mut n = Counter::default();
    if b.outside_window() {
        return Ok(0);
    }
    match separation {
        Separation::TwentySix => b.twenty_six(sink, &mut n, fill),
        Separation::Six => {
            for axis in 0..3 {
                b.six_axis(axis, sink, &mut n);
            }
            if fill {
                b.six_interior(sink, &mut n);
            }
        }
    }
    Ok(n.0)
}

/// Whether voxel `v`'s closed cube (TwentySix) or one of its centre segments
/// (Six) meets the sphere: the membership rule of [`surface`], for tests.
///
/// # Errors
/// As [`surface`].
pub fn contains(
    sphere: &Sphere,
    separation: Separation,
    v: [u32; 3],
) -> Result<bool, VoxelizeError> {
    let c = check_point(sphere.centre)?;
    let r = radius(sphere.radius)?;
    let w = sub(v.map(centre), c);
    let r2 = r.saturating_mul(r);
    Ok(match separation {
        Separation::TwentySix => {
            let (mut lo, mut hi) = (0i128, 0i128);
            for wk in w {
                let near = wk.unsigned_abs().saturating_sub(H.unsigned_abs());
                let far = wk.unsigned_abs().saturating_add(H.unsigned_abs());
                let (near, far) = (near.cast_signed(), far.cast_signed());
                lo = lo.saturating_add(near.saturating_mul(near));
                hi = hi.saturating_add(far.saturating_mul(far));
            }
            lo <= r2 && r2 <= hi
        }
        Separation::Six => (0..3).any(|k| segment_meets(w, k, r2)),
    })
}

/// Whether the centre segment along `k` of the voxel at offset `w` from the
/// sphere's centre meets the sphere of squared radius `r2`. Every caller's
/// `w` is a voxel centre (below 2^49) less a checked centre (at most
/// [`COORD_LIMIT`](super::error::COORD_LIMIT) = 2^40), so `|w_j| < 2^50`:
/// squares and their sums stay below 2^102 and the arithmetic is exact
/// without saturating.
#[inline]
fn segment_meets(w: [i128; 3], k: usize, r2: i128) -> bool {
    let mut lat = 0i128;
    let mut wk = 0i128;
    for (j, c) in w.iter().enumerate() {
        if j == k {
            wk = c.wrapping_abs();
        } else {
            lat = lat.wrapping_add(c.wrapping_mul(*c));
        }
    }
    let near = wk.wrapping_sub(H).max(0);
    let far = wk.wrapping_add(H);
    lat.wrapping_add(near.wrapping_mul(near)) <= r2 && r2 <= lat.wrapping_add(far.wrapping_mul(far))
}

fn radius(r: i64) -> Result<i128, VoxelizeError> {
    if r <= 0 {
        return Err(VoxelizeError::NonPositiveRadius);
    }
    super::fixmath::check_coord(r)
}

/// A validated sphere with its raster.
struct Ball {
    c: [i128; 3],
    r: i128,
    r2: i128,
    /// The cells scanned along each axis ([`window`]).
    win: [(u32, u32); 3],
}

impl Ball {
    fn new(s: &Sphere, win: [(u32, u32); 3]) -> Result<Self, VoxelizeError> {
        let c = check_point(s.centre)?;
        let r = radius(s.radius)?;
        // r ≤ 2^40: r² ≤ 2^80.
        Ok(Self {
            c,
            r,
            r2: r.saturating_mul(r),
            win,
        })
    }

    /// Whether no cell of the window meets the closed ball: then no rule
    /// offers anything (every voxel offered overlaps the ball's box).
    fn outside_window(&self) -> bool {
        (0..3).any(|k| {
            let (lo, hi) = cells_overlapping(
                self.c[k].saturating_sub(self.r),
                self.c[k].saturating_add(self.r),
            );
            clip(lo, hi, self.win[k]).is_none()
        })
    }

    /// The attributes of voxel `v`: radial normal and `| |w| − R |`.
    #[inline]
    fn surfel(&self, v: [u32; 3]) -> Surfel {
        // |w_k| < 2^41 + 2^33: products below fit easily in i128.
        let w = [0, 1, 2].map(|k| centre(v[k]).wrapping_sub(self.c[k]));
        let (rho, normal) = radial(w);
        Surfel {
            normal: normal.unwrap_or([0, 0, NORMAL_ONE]),
            distance: dist_u32(rho.wrapping_sub(self.r)),
        }
    }

    #[inline]
    fn offer<S: VoxelSink + ?Sized>(&self, v: [u32; 3], sink: &mut S, n: &mut Counter) {
        sink.offer(v, self.surfel_for(v, sink));
        n.bump();
    }

    /// [`Ball::surfel`], or [`Surfel::NONE`] for a sink that does not read
    /// surfels.
    #[inline]
    fn surfel_for<S: VoxelSink + ?Sized>(&self, v: [u32; 3], sink: &S) -> Surfel {
        if sink.reads_surfels() {
            self.surfel(v)
        } else {
            Surfel::NONE
        }
    }

    /// TwentySix shell (and, with `fill`, the cells wholly inside). Columns
    /// run along x, the raster's fastest axis, so consecutive offers touch
    /// neighbouring plane bytes.
    fn twenty_six<S: VoxelSink + ?Sized>(&self, sink: &mut S, n: &mut Counter, fill: bool) {
        const K: usize = 0;
        let (ca, cb, ck) = pick(K, self.c);
        let (na, nb, nk) = pick(K, self.win);
        let (bl, bh) = cells_overlapping(cb.saturating_sub(self.r), cb.saturating_add(self.r));
        let Some((b0, b1)) = clip(bl, bh, nb) else {
            return;
        };
        // Below, the distances from near_far are below 2^50 (a voxel face
        // less a checked centre) and r2 ≤ 2^80: their squares and the
        // differences are exact without saturating.
        for bi in b0..=b1 {
            let (ab_min, ab_max) = near_far(cb, bi);
            let eb = self.r2.wrapping_sub(ab_min.wrapping_mul(ab_min));
            if eb < 0 {
                continue;
            }
            let sa = isqrt(eb);
            let (al, ah) = cells_overlapping(ca.saturating_sub(sa), ca.saturating_add(sa));
            let Some((a0, a1)) = clip(al, ah, na) else {
                continue;
            };
            for ai in a0..=a1 {
                let (aa_min, aa_max) = near_far(ca, ai);
                let d_in = eb.wrapping_sub(aa_min.wrapping_mul(aa_min));
                if d_in < 0 {
                    continue;
                }
                let h_in = isqrt(d_in);
                let (kl, kh) = cells_overlapping(ck.saturating_sub(h_in), ck.saturating_add(h_in));
                let d_out = self
                    .r2
                    .wrapping_sub(aa_max.wrapping_mul(aa_max))
                    .wrapping_sub(ab_max.wrapping_mul(ab_max));
                // Cells strictly inside the open ball: el ..= eh (empty when
                // the column's far corner is outside the sphere).
                let (el, eh) = if d_out > 0 {
                    let h_out = ceil_sqrt(d_out);
                    (
                        cell_floor(ck.saturating_sub(h_out)).saturating_add(1),
                        super::fixmath::cell_ceil(ck.saturating_add(h_out)).saturating_sub(2),
                    )
                } else {
                    (1, 0)
                };
                let Some((k0, k1)) = clip(kl, kh, nk) else {
                    continue;
                };
                // The cells wholly inside are skipped (surface) or filled
                // (solid) without testing each.
                let [below, inside, above] = split(k0, k1, el, eh);
                for (k0, k1) in below.into_iter().chain(above) {
                    for ki in k0..=k1 {
                        self.offer(place(K, ai, bi, ki), sink, n);
                    }
                }
                if let (true, Some((k0, k1))) = (fill, inside) {
                    for ki in k0..=k1 {
                        let v = place(K, ai, bi, ki);
                        let s = self.surfel_for(v, sink);
                        sink.offer(v, Surfel { distance: 0, ..s });
                        n.bump();
                    }
                }
            }
        }
    }

    /// Calls `f(ai, bi, da, db, d)` for every column of voxels along axis
    /// `k` whose centre line meets the closed ball: `ai`, `bi` are its
    /// coordinates on the other two axes (as [`pick`] orders them), `da`,
    /// `db` its centre's offsets from the sphere's centre there, and
    /// `d = R² − da² − db² ≥ 0`.
    #[inline(always)]
    fn centre_columns(&self, k: usize, mut f: impl FnMut(u32, u32, i128, i128, i128)) {
        let (ca, cb, _) = pick(k, self.c);
        let (na, nb, _) = pick(k, self.win);
        let (bl, bh) = centres_within(cb.saturating_sub(self.r), cb.saturating_add(self.r));
        let Some((b0, b1)) = clip(bl, bh, nb) else {
            return;
        };
        // Below, |db|, |da| < 2^50 (a voxel centre less a checked centre)
        // and r2 ≤ 2^80: exact without saturating.
        for bi in b0..=b1 {
            let db = centre(bi).wrapping_sub(cb);
            let eb = self.r2.wrapping_sub(db.wrapping_mul(db));
            if eb < 0 {
                continue;
            }
            let sa = isqrt(eb);
            let (al, ah) = centres_within(ca.saturating_sub(sa), ca.saturating_add(sa));
            let Some((a0, a1)) = clip(al, ah, na) else {
                continue;
            };
            for ai in a0..=a1 {
                let da = centre(ai).wrapping_sub(ca);
                let d = eb.wrapping_sub(da.wrapping_mul(da));
                if d >= 0 {
                    f(ai, bi, da, db, d);
                }
            }
        }
    }

    /// Six shell, the voxels found along centre lines parallel to `k`.
    fn six_axis<S: VoxelSink + ?Sized>(&self, k: usize, sink: &mut S, n: &mut Counter) {
        let (_, _, ck) = pick(k, self.c);
        let (_, _, nk) = pick(k, self.win);
        self.centre_columns(k, |ai, bi, _, _, d| {
            // d ≤ r2 ≤ 2^80: s ≤ 2^40 and s² is exact.
            let s = isqrt(d);
            let exact = s.wrapping_mul(s) == d;
            // Up to four cells: each crossing's cell, and the cell below
            // when the crossing lies exactly on a face.
            let hi = ck.saturating_add(s);
            let lo = if exact {
                ck.saturating_sub(s)
            } else {
                ck.saturating_sub(s).saturating_sub(1)
            };
            // V is a power of two: `p & (V − 1)` is `p mod V`.
            let on_face = |p: i128| exact && p & V.wrapping_sub(1) == 0;
            let cells = [
                Some(cell_floor(hi)),
                on_face(hi).then(|| cell_floor(hi).saturating_sub(1)),
                Some(cell_floor(lo)),
                on_face(lo).then(|| cell_floor(lo).saturating_sub(1)),
            ];
            for (i, cell) in cells.iter().enumerate() {
                let Some(cell) = *cell else {
                    continue;
                };
                if cells.iter().take(i).any(|c| *c == Some(cell)) {
                    continue;
                }
                let Some((kc, _)) = clip(cell, cell, nk) else {
                    continue;
                };
                let v = place(k, ai, bi, kc);
                let w = [0, 1, 2].map(|j| centre(v[j]).wrapping_sub(self.c[j]));
                if (0..k).any(|j| segment_meets(w, j, self.r2)) {
                    continue;
                }
                self.offer(v, sink, n);
            }
        });
    }

    /// Six solid: voxels with centre inside and no centre segment reaching
    /// the sphere (`|w|² + 2h‖w‖∞ + h² < R²`), offered with distance 0.
    /// Columns run along x.
    fn six_interior<S: VoxelSink + ?Sized>(&self, sink: &mut S, n: &mut Counter) {
        const K: usize = 0;
        let (_, _, ck) = pick(K, self.c);
        let (_, _, nk) = pick(K, self.win);
        self.centre_columns(K, |ai, bi, da, db, ek| {
            let sk = isqrt(ek);
            let (kl, kh) = centres_within(ck.saturating_sub(sk), ck.saturating_add(sk));
            let Some((k0, k1)) = clip(kl, kh, nk) else {
                return;
            };
            for ki in k0..=k1 {
                // |da|, |db|, |dk| < 2^50: every term below 2^100, exact.
                let dk = centre(ki).wrapping_sub(ck);
                let m = da.abs().max(db.abs()).max(dk.abs());
                let w2 = da
                    .wrapping_mul(da)
                    .wrapping_add(db.wrapping_mul(db))
                    .wrapping_add(dk.wrapping_mul(dk));
                let reach = w2
                    .wrapping_add(m.wrapping_mul(V))
                    .wrapping_add(H.wrapping_mul(H));
                if reach < self.r2 {
                    let v = place(K, ai, bi, ki);
                    let s = self.surfel_for(v, sink);
                    sink.offer(v, Surfel { distance: 0, ..s });
                    n.bump();
                }
            }
        });
    }
}

/// The coordinates of `p` on the two axes other than `k` (in increasing
/// order) and on `k`.
#[inline]
pub(crate) fn pick<T: Copy>(k: usize, p: [T; 3]) -> (T, T, T) {
    let [x, y, z] = p;
    match k {
        0 => (y, z, x),
        1 => (x, z, y),
        _ => (x, y, z),
    }
}

/// The inverse of [`pick`]: the point with `a`, `b` on the axes other than
/// `k` and `c` on `k`.
#[inline]
pub(crate) fn place<T: Copy>(k: usize, a: T, b: T, c: T) -> [T; 3] {
    match k {
        0 => [c, a, b],
        1 => [a, c, b],
        _ => [a, b, c],
    }
}

/// Nearest and farthest distance from coordinate `c` to cell `i`'s closed
/// range `[iV, (i+1)V]`.
#[inline]
fn near_far(c: i128, i: u32) -> (i128, i128) {
    let lo = super::fixmath::low(i);
    let hi = lo.wrapping_add(V);
    let near = if c < lo {
        lo.wrapping_sub(c)
    } else if c > hi {
        c.wrapping_sub(hi)
    } else {
        0
    };
    let far = c.wrapping_sub(lo).abs().max(hi.wrapping_sub(c).abs());
    (near, far)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testkit::{Offers, Rng, assert_refused, voxelized_in_4};
    use std::vec::Vec;

    fn brute(s: &Sphere, sep: Separation, e: Extent) -> Vec<[u32; 3]> {
        let [nx, ny, nz] = e.dims();
        let mut out = Vec::new();
        for z in 0..nz {
            for y in 0..ny {
                for x in 0..nx {
                    if contains(s, sep, [x, y, z]).unwrap() {
                        out.push([x, y, z]);
                    }
                }
            }
        }
        out
    }

    #[test]
    fn scan_matches_membership_and_offers_once() {
        let e = Extent::new(14, 13, 12).unwrap();
        let mut rng = Rng(7u64);
        let mut next = |m: i64| rng.range(0, m - 1);
        for case in 0..60 {
            // Centres on lattice points, centres, faces and random points;
            // some partly outside the raster.
            let snap = case % 4;
            let mut p = [0i64; 3];
            for pk in &mut p {
                let base = next(16 * 65536) - 2 * 65536;
                *pk = match snap {
                    0 => base & !0xffff,
                    1 => (base & !0xffff) | 0x8000,
                    _ => base,
                };
            }
            let r = match case % 3 {
                0 => (1 + next(6)) * 65536,
                1 => 1 + next(7 * 65536),
                _ => (1 + next(12)) * 32768,
            };
            let s = Sphere {
                centre: p,
                radius: r,
            };
            for sep in [Separation::Six, Separation::TwentySix] {
                for solid_too in [false, true] {
                    let mut c = Offers::default();
                    let offers = if solid_too {
                        solid(&s, sep, e, &mut c).unwrap()
                    } else {
                        surface(&s, sep, e, &mut c).unwrap()
                    };
                    assert_eq!(
                        offers as usize,
                        c.0.values().map(|v| v.1 as usize).sum::<usize>()
                    );
                    assert!(
                        c.0.values().all(|v| v.1 == 1),
                        "case {case}: a voxel offered twice"
                    );
                    let want = brute(&s, sep, e);
                    for v in &want {
                        assert!(
                            c.0.contains_key(v),
                            "case {case} {sep:?}: missing {v:?} of {s:?}"
                        );
                    }
                    if !solid_too {
                        assert_eq!(c.0.len(), want.len(), "case {case} {sep:?}: extra voxels");
                    } else {
                        // Extra voxels of the solid have their centre inside.
                        for (v, (sf, _)) in &c.0 {
                            if !want.contains(v) {
                                let w = [0, 1, 2].map(|k| centre(v[k]) - i128::from(p[k]));
                                let d2: i128 = w.iter().map(|c| c * c).sum();
                                assert!(d2 <= i128::from(r) * i128::from(r));
                                assert_eq!(sf.distance, 0);
                            }
                        }
                    }
                }
            }
        }
    }

    /// The shell's arithmetic wraps instead of saturating because nothing
    /// accepted can overflow: at the extremes of the accepted range (centre
    /// and radius up to `COORD_LIMIT`, any voxel of a 2^32 axis) the
    /// membership test equals one in checked arithmetic, which would panic
    /// on an overflow.
    #[test]
    fn membership_arithmetic_never_overflows() {
        let limit = crate::voxelize::error::COORD_LIMIT;
        let mut rng = Rng(0x5e6_3e75);
        let checked = |w: [i128; 3], k: usize, r2: i128| -> bool {
            let mut lat = 0i128;
            for (j, c) in w.iter().enumerate() {
                if j != k {
                    lat = lat.checked_add(c.checked_mul(*c).unwrap()).unwrap();
                }
            }
            let wk = w[k].checked_abs().unwrap();
            let near = wk.checked_sub(H).unwrap().max(0);
            let far = wk.checked_add(H).unwrap();
            lat.checked_add(near.checked_mul(near).unwrap()).unwrap() <= r2
                && r2 <= lat.checked_add(far.checked_mul(far).unwrap()).unwrap()
        };
        let extremes = [-limit, -limit + 1, -1, 0, 1, limit - 1, limit];
        for case in 0..4000 {
            let pick = |rng: &mut Rng| {
                if case % 2 == 0 {
                    extremes[rng.range(0, 6) as usize]
                } else {
                    rng.range(-limit, limit)
                }
            };
            let c = [pick(&mut rng), pick(&mut rng), pick(&mut rng)];
            let r = pick(&mut rng).unsigned_abs().max(1) as i64;
            let v = [0, 1, 2].map(|_| match rng.range(0, 3) {
                0 => 0,
                1 => u32::MAX,
                _ => rng.range(0, i64::from(u32::MAX)) as u32,
            });
            let w = [0, 1, 2].map(|k| centre(v[k]) - i128::from(c[k]));
            let r2 = i128::from(r) * i128::from(r);
            for k in 0..3 {
                assert_eq!(
                    segment_meets(w, k, r2),
                    checked(w, k, r2),
                    "{c:?} {r} {v:?}"
                );
            }
        }
    }

    #[test]
    fn surfel_is_radial() {
        let s = Sphere {
            centre: [0; 3],
            radius: 3 * V as i64,
        };
        // A sink keeping every voxel.
        struct All;
        impl VoxelSink for All {
            fn offer(&mut self, _: [u32; 3], _: Surfel) {}
        }
        let b = Ball::new(&s, window(Extent::cube(8).unwrap(), &All)).unwrap();
        let sf = b.surfel([3, 0, 0]);
        assert!(sf.normal[0] > 1 << 29);
        // centre (3.5, .5, .5): |w| = sqrt(12.75) ≈ 3.5707 voxels
        let d = i64::from(sf.distance);
        assert!((d - 37401).abs() < 4, "{d}");
    }

    #[test]
    fn bad_input() {
        let z = Sphere {
            centre: [0; 3],
            radius: 0,
        };
        assert_refused(surface, &z, VoxelizeError::NonPositiveRadius);
        let big = Sphere {
            centre: [i64::MAX, 0, 0],
            radius: 5,
        };
        assert_refused(solid, &big, VoxelizeError::OutOfRange);
        let far = Sphere {
            centre: [1 << 40, 1 << 40, 1 << 40],
            radius: 1 << 40,
        };
        assert_eq!(voxelized_in_4(surface, &far, Separation::TwentySix), Ok(0));
    }
}
