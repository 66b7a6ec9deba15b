//! Bicubic Bézier patches, through integer forward differencing.
//!
//! ```
//! use rrt_core::fixed::VOXEL;
//! use rrt_core::geometry::BezierPatch;
//! use rrt_core::raster::Extent;
//! use rrt_core::voxelize::{patch, Separation, Surfel, VoxelSink};
//!
//! struct Count(u64);
//! impl VoxelSink for Count {
//!     fn offer(&mut self, _: [u32; 3], _: Surfel) { self.0 += 1; }
//! }
//! // A bump over a 12 × 12 voxel square.
//! let mut control = [[[0i64; 3]; 4]; 4];
//! for i in 0..4 {
//!     for j in 0..4 {
//!         let h = if (1..3).contains(&i) && (1..3).contains(&j) { 6 } else { 2 };
//!         control[i][j] = [(2 + 4 * i as i64) * VOXEL, (2 + 4 * j as i64) * VOXEL, h * VOXEL];
//!     }
//! }
//! let mut n = Count(0);
//! patch::surface(&BezierPatch { control }, Separation::Six, Extent::cube(16).unwrap(), &mut n).unwrap();
//! assert!(n.0 > 144);
//! ```
//!
//! # Which voxels
//! The patch is evaluated on an `(n+1) × (n+1)` parameter grid by forward
//! differencing in exact integers (after the paper's reference \[8\]): scaled
//! by `n³`, the Bernstein weights at `u = i/n` are the integers
//! `C(3,k)·i^k·(n−i)^(3−k)`, so the four v-curves are stepped with three
//! integer differences each, and along each grid row the u-curve through
//! their values likewise; each vertex is the exact value divided by `n⁶` and
//! rounded. `n` is chosen from the control net's second differences so that
//! the grid's triangles stay within 1/8 voxel of the patch (at most 256).
//! Every interior vertex is computed from the same integers by both rows
//! that use it, so the triangles share vertices exactly and are voxelized
//! by the lattice-step rule of [`super::triangle`]: the union is as
//! tunnel-free as the patch is closed (an open patch: rays crossing it away
//! from its boundary hit it). Normals are the exact `∂p/∂u × ∂p/∂v` at the
//! grid vertices, interpolated over each triangle; the distance is to the
//! tessellation.
//!
//! # Accepted input and cost
//! Control points within [`COORD_LIMIT`](super::error::COORD_LIMIT); a
//! patch whose control points all coincide is refused
//! ([`VoxelizeError::Degenerate`]). Work is `O(n²)` grid steps (rows of
//! quads far from the raster are culled cheaply) plus the voxels offered.

use super::error::VoxelizeError;
use super::fixmath::{V, add, bounds, check_point, cross, isqrt, round_div, sub, unit};
use super::tessellate::Emitter;
use super::triangle::Tri;
use super::{Separation, VoxelSink};
use crate::geometry::{BezierPatch, UnitVector};
use crate::raster::Extent;

/// Largest grid resolution per parameter.
pub const MAX_STEPS: u32 = 256;

/// Tolerance of the tessellation: 1/8 voxel.
const TOLERANCE: i128 = V / 8;

/// Voxelizes `patch`, clipped to `extent`. Returns the number of offers
/// (voxels along shared grid edges are offered once per triangle).
///
/// # Errors
/// See the module documentation.
pub fn surface<S: VoxelSink + ?Sized>(
    patch: &BezierPatch,
    separation: Separation,
    extent: Extent,
    sink: &mut S,
) -> Result<u64, VoxelizeError> {
    let mut p = [[[0i128; 3]; 4]; 4];
    for (row, src) in p.iter_mut().zip(patch.control.iter()) {
        for (pt, s) in row.iter_mut().zip(src.iter()) {
            *pt = check_point(*s)?;
        }
    }
    let first = p[0][0];
    if p.iter().flatten().all(|q| *q == first) {
        return Err(VoxelizeError::Degenerate);
    }
    let n = steps(&p);
    let mut em = Emitter::new(separation, extent, sink);
    let (lo, hi) = bounds(p.iter().flatten());
    if em.culled(lo, hi, V) {
        return Ok(0);
    }
    let nn = i128::from(n);
    let n6 = nn.pow(6);
    // v-curves: one forward-difference state per control row a.
    let mut vfd = [Fd::default(); 4];
    for (a, fd) in vfd.iter_mut().enumerate() {
        let row = p.get(a).copied().unwrap_or_default();
        *fd = Fd::new(|j| bernstein(&row, j, n));
    }
    let surfel = |t: &Tri, v: [u32; 3]| t.surfel(v);
    for j in 0..n {
        let cur = vfd.map(|f| f.value);
        for f in &mut vfd {
            f.step();
        }
        let nxt = vfd.map(|f| f.value);
        let mut r0 = Fd::new(|i| bernstein(&cur, i, n));
        let mut r1 = Fd::new(|i| bernstein(&nxt, i, n));
        let vert = |x: [i128; 3]| x.map(|c| round_div(c, n6));
        let (mut a0, mut a1) = (vert(r0.value), vert(r1.value));
        for i in 0..n {
            r0.step();
            r1.step();
            let (b0, b1) = (vert(r0.value), vert(r1.value));
            let quad = [a0, b0, b1, a1];
            let (qlo, qhi) = bounds(&quad);
            if !em.culled(qlo, qhi, TOLERANCE) {
                let nrm = [
                    (i, j),
                    (i.saturating_add(1), j),
                    (i.saturating_add(1), j.saturating_add(1)),
                    (i, j.saturating_add(1)),
                ]
                .map(|(a, b)| normal(&p, a, b, n));
                let normals = if nrm.iter().all(Option::is_some) {
                    Some(nrm.map(|x| x.unwrap_or_default()))
                } else {
                    None
                };
                em.quad(quad, normals, &surfel)?;
            }
            a0 = b0;
            a1 = b1;
        }
    }
    Ok(em.n.0)
}

/// Control point `(a, b)` (zero past the net; indices stay below 4).
fn at(p: &[[[i128; 3]; 4]; 4], a: usize, b: usize) -> [i128; 3] {
    p.get(a).and_then(|r| r.get(b)).copied().unwrap_or([0; 3])
}

/// Grid steps per parameter. Linear interpolation over a grid triangle
/// (legs `h = 1/n`, circumradius `h/√2`) errs by at most `R²/2 · M = h²/4 ·
/// M`, `M` bounding the second directional derivative: `M ≤ max(|p_uu|,
/// |p_vv|) + |p_uv| ≤ 6·max(Δuu, Δvv) + 9·Δuv` over the control net (L1
/// norms, which bound the Euclidean ones). So `n² ≥ M / (4·tolerance)`.
fn steps(p: &[[[i128; 3]; 4]; 4]) -> u32 {
    let l1 = |v: [i128; 3]| {
        v.iter()
            .fold(0i128, |s, x| s.saturating_add(x.saturating_abs()))
    };
    // a − 2b + c, and a − b − c + d.
    let second =
        |a: [i128; 3], b: [i128; 3], c: [i128; 3]| add(sub(a, b.map(|x| x.saturating_mul(2))), c);
    let twist = |a: [i128; 3], b: [i128; 3], c: [i128; 3], d: [i128; 3]| add(sub(sub(a, b), c), d);
    let (mut duu, mut dvv, mut duv) = (0i128, 0i128, 0i128);
    for a in 0..4usize {
        for b in 0..4usize {
            // a, b < 4: the index sums cannot wrap.
            let (a1, a2, b1, b2) = (
                a.wrapping_add(1),
                a.wrapping_add(2),
                b.wrapping_add(1),
                b.wrapping_add(2),
            );
            if a2 < 4 {
                duu = duu.max(l1(second(at(p, a2, b), at(p, a1, b), at(p, a, b))));
            }
            if b2 < 4 {
                dvv = dvv.max(l1(second(at(p, a, b2), at(p, a, b1), at(p, a, b))));
            }
            if a1 < 4 && b1 < 4 {
                duv = duv.max(l1(twist(
                    at(p, a1, b1),
                    at(p, a1, b),
                    at(p, a, b1),
                    at(p, a, b),
                )));
            }
        }
    }
    let m = duu
        .max(dvv)
        .saturating_mul(6)
        .saturating_add(duv.saturating_mul(9));
    let need = isqrt(m.checked_div(TOLERANCE.saturating_mul(4)).unwrap_or(0)).saturating_add(1);
    u32::try_from(need.clamp(1, i128::from(MAX_STEPS))).unwrap_or(MAX_STEPS)
}

/// Cubic Bernstein weights scaled by `n³` at step `i`: `C(3,k)·i^k·(n−i)^(3−k)`.
fn cubic_weights(i: u32, n: u32) -> [i128; 4] {
    let (a, b) = (i128::from(i), i128::from(n.saturating_sub(i)));
    // a, b ≤ 2^8 + 3: every product below 2^27.
    let m = |x: i128, y: i128| x.saturating_mul(y);
    [
        m(m(b, b), b),
        m(m(m(3, a), b), b),
        m(m(m(3, a), a), b),
        m(m(a, a), a),
    ]
}

/// Quadratic Bernstein weights scaled by `n²` at step `i`.
fn quadratic_weights(i: u32, n: u32) -> [i128; 3] {
    let (a, b) = (i128::from(i), i128::from(n.saturating_sub(i)));
    let m = |x: i128, y: i128| x.saturating_mul(y);
    [m(b, b), m(m(2, a), b), m(a, a)]
}

/// `n³ · curve(i/n)` for a cubic with control points `c`: the exact integer
/// `Σ C(3,k)·i^k·(n−i)^(3−k)·c_k`.
fn bernstein(c: &[[i128; 3]; 4], i: u32, n: u32) -> [i128; 3] {
    let w = cubic_weights(i, n);
    [0, 1, 2].map(|k| {
        c.iter().zip(w).fold(0i128, |s, (p, wk)| {
            s.saturating_add(p[k].saturating_mul(wk))
        })
    })
}

/// Forward differencing of a cubic sampled at integer steps: value and its
/// first three differences, exact.
#[derive(Clone, Copy, Debug, Default)]
struct Fd {
    value: [i128; 3],
    d1: [i128; 3],
    d2: [i128; 3],
    d3: [i128; 3],
}

impl Fd {
    /// From the samples at steps 0..=3 (`f` may be evaluated past the end of
    /// the grid; a cubic has no end).
    fn new(f: impl Fn(u32) -> [i128; 3]) -> Self {
        let [p0, p1, p2, p3] = [f(0), f(1), f(2), f(3)];
        let lin = |a: [i128; 3], b: [i128; 3], wa: i128, wb: i128| {
            [0, 1, 2].map(|k| {
                a[k].saturating_mul(wa)
                    .saturating_add(b[k].saturating_mul(wb))
            })
        };
        Self {
            value: p0,
            d1: lin(p1, p0, 1, -1),
            d2: add(lin(p2, p1, 1, -2), p0),
            d3: add(lin(p3, p2, 1, -3), lin(p1, p0, 3, -1)),
        }
    }

    fn step(&mut self) {
        for k in 0..3 {
            self.value[k] = self.value[k].saturating_add(self.d1[k]);
            self.d1[k] = self.d1[k].saturating_add(self.d2[k]);
            self.d2[k] = self.d2[k].saturating_add(self.d3[k]);
        }
    }
}

/// Exact unit normal `∂p/∂u × ∂p/∂v` at grid vertex `(i, j)`; `None` where
/// it vanishes (a collapsed patch edge).
fn normal(p: &[[[i128; 3]; 4]; 4], i: u32, j: u32, n: u32) -> Option<UnitVector> {
    let (wu2, wu3) = (quadratic_weights(i, n), cubic_weights(i, n));
    let (wv2, wv3) = (quadratic_weights(j, n), cubic_weights(j, n));
    let mut du = [0i128; 3];
    let mut dv = [0i128; 3];
    for a in 0..4usize {
        for b in 0..4usize {
            // a, b < 4: a + 1, b + 1 cannot wrap.
            let (a1, b1) = (a.wrapping_add(1), b.wrapping_add(1));
            let pab = at(p, a, b);
            if let (true, Some(wa), Some(wb)) = (a1 < 4, wu2.get(a), wv3.get(b)) {
                let q = at(p, a1, b);
                for (d, (x, y)) in du.iter_mut().zip(q.iter().zip(pab)) {
                    *d = d.saturating_add(
                        x.saturating_sub(y).saturating_mul(*wa).saturating_mul(*wb),
                    );
                }
            }
            if let (true, Some(wa), Some(wb)) = (b1 < 4, wu3.get(a), wv2.get(b)) {
                let q = at(p, a, b1);
                for (d, (x, y)) in dv.iter_mut().zip(q.iter().zip(pab)) {
                    *d = d.saturating_add(
                        x.saturating_sub(y).saturating_mul(*wa).saturating_mul(*wb),
                    );
                }
            }
        }
    }
    let shrink = |v: [i128; 3]| {
        let m = v.iter().map(|x| x.unsigned_abs()).max().unwrap_or(0);
        let s = (128u32.saturating_sub(m.leading_zeros())).saturating_sub(60);
        v.map(|x| x >> s)
    };
    unit(cross(shrink(du), shrink(dv)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fixed::VOXEL;
    use crate::testkit::{assert_refused, voxelized};
    use crate::voxelize::fixmath::centre;

    /// `N⁶ · patch(a/N, b/N)`, exactly.
    fn eval(p: &[[[i128; 3]; 4]; 4], a: u32, b: u32, n: u32) -> [i128; 3] {
        let rows = [0, 1, 2, 3].map(|r| bernstein(&p[r], b, n));
        bernstein(&rows, a, n)
    }

    #[test]
    fn forward_differencing_is_exact() {
        let mut c = [[[0i128; 3]; 4]; 4];
        for (a, row) in c.iter_mut().enumerate() {
            for (b, q) in row.iter_mut().enumerate() {
                *q = [
                    (a * 7 + b * 3) as i128 * 1000 + 17,
                    (a * b) as i128 * 999,
                    (a + b * b) as i128 * 12345,
                ];
            }
        }
        let n = 9;
        let mut fd = Fd::new(|j| bernstein(&c[2], j, n));
        for j in 0..=n {
            assert_eq!(fd.value, bernstein(&c[2], j, n));
            fd.step();
        }
    }

    #[test]
    fn vertices_lie_on_the_patch_and_voxels_near_it() {
        let mut control = [[[0i64; 3]; 4]; 4];
        for i in 0..4 {
            for j in 0..4 {
                let h = [3, 9, 1, 6][(i + 2 * j) % 4];
                control[i][j] = [
                    (2 + 5 * i as i64) * VOXEL + 333,
                    (2 + 5 * j as i64) * VOXEL,
                    h * VOXEL + 77,
                ];
            }
        }
        let bp = BezierPatch { control };
        let e = Extent::cube(20).unwrap();
        let (r, c) = voxelized(surface, &bp, Separation::TwentySix, e);
        r.unwrap();
        assert!(c.0.len() > 300);
        // Every voxel lies within half a cube diagonal (+ tolerance) of the
        // patch: check against a dense exact sampling (N = 60).
        let pc = bp.control.map(|r| r.map(|q| q.map(i128::from)));
        let n = 60u32;
        let n6 = i128::from(n).pow(6);
        let samples: std::vec::Vec<[i128; 3]> = (0..=n)
            .flat_map(|a| (0..=n).map(move |b| (a, b)))
            .map(|(a, b)| eval(&pc, a, b, n).map(|x| x / n6))
            .collect();
        for v in c.0.keys() {
            let cen = v.map(centre);
            let d2 = samples
                .iter()
                .map(|s| (0..3).map(|k| (s[k] - cen[k]).pow(2)).sum::<i128>())
                .min()
                .unwrap();
            // 0.87 + 1/8 + sampling gap (≤ 0.3 voxel) in voxels.
            assert!(isqrt(d2) < 85_000, "{v:?} at {}", isqrt(d2));
        }
        let flat = BezierPatch {
            control: [[[5; 3]; 4]; 4],
        };
        assert_refused(surface, &flat, VoxelizeError::Degenerate);
    }
}
