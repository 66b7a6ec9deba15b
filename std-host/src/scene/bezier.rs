//! Bicubic Bézier patches: the Bernstein evaluation of a patch and its
//! tessellation into polygonal patches (NFF `pp`) with the patch's exact
//! normals.

use glam::DVec3;

use super::bpt;

fn bernstein(t: f64) -> ([f64; 4], [f64; 4]) {
    let s = 1.0 - t;
    (
        [s * s * s, 3.0 * t * s * s, 3.0 * t * t * s, t * t * t],
        [
            -3.0 * s * s,
            3.0 * s * s - 6.0 * t * s,
            6.0 * t * s - 3.0 * t * t,
            3.0 * t * t,
        ],
    )
}

/// The point and unit normal (`∂u × ∂v`, zero where degenerate) of a
/// bicubic patch at `(u, v)`.
#[must_use]
pub fn patch_point(c: &bpt::Control, u: f64, v: f64) -> (DVec3, DVec3) {
    let (bu, du) = bernstein(u);
    let (bv, dv) = bernstein(v);
    let mut p = DVec3::ZERO;
    let mut pu = DVec3::ZERO;
    let mut pv = DVec3::ZERO;
    for i in 0..4 {
        for j in 0..4 {
            let q = c[i][j];
            p += q * bu[i] * bv[j];
            pu += q * du[i] * bv[j];
            pv += q * bu[i] * dv[j];
        }
    }
    (p, pu.cross(pv).normalize_or_zero())
}

/// Patch `c` as `steps × steps` quads with the patch's normals at their
/// corners; a corner with a degenerate normal (a pole) takes its quad's
/// average of the others, and quads without any usable normal are flat
/// (all-zero normals are replaced by the quad's plane normal).
pub fn tessellate(c: &bpt::Control, steps: u32) -> Vec<([DVec3; 4], [DVec3; 4])> {
    let n = steps as usize;
    let grid: Vec<(DVec3, DVec3)> = (0..=n)
        .flat_map(|i| {
            (0..=n).map(move |j| patch_point(c, i as f64 / n as f64, j as f64 / n as f64))
        })
        .collect();
    let at = |i: usize, j: usize| grid[i * (n + 1) + j];
    let mut out = Vec::with_capacity(n * n);
    for i in 0..n {
        for j in 0..n {
            let k = [at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)];
            let quad = k.map(|x| x.0);
            let mut normals = k.map(|x| x.1);
            let sum: DVec3 = normals.iter().copied().sum();
            let fill = sum.try_normalize().unwrap_or_else(|| {
                (quad[2] - quad[0])
                    .cross(quad[3] - quad[1])
                    .try_normalize()
                    .unwrap_or(DVec3::Z)
            });
            for m in &mut normals {
                if m.length_squared() < 0.5 {
                    *m = fill;
                }
            }
            out.push((quad, normals));
        }
    }
    out
}
