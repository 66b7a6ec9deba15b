//! The voxelizers' membership rules against independent float oracles.
//!
//! `triangle::contains` evaluates separating-axis tests in exact integers;
//! here the same question (does the voxel's probe, its closed cube for
//! TwentySix or its inscribed octahedron for Six, meet the closed
//! triangle?) is answered by clipping the triangle against the probe's
//! faces (Sutherland–Hodgman, in f64). Cases within 1e-6 voxel of a tie are
//! decided both ways and skipped when the two disagree. The scan-line
//! voxelizer itself is compared with `contains` in the core's unit tests.

use rrt_core::fixed::VOXEL;
use rrt_core::geometry::Triangle;
use rrt_core::voxelize::{Separation, triangle};
use rrt_tests::Rng;

/// Half-spaces `n·p ≤ d` bounding the probe around `c` (voxel units),
/// grown by `grow`.
fn probe(sep: Separation, c: [f64; 3], grow: f64) -> Vec<([f64; 3], f64)> {
    let h = 0.5 + grow;
    let mut out = Vec::new();
    match sep {
        Separation::TwentySix => {
            for k in 0..3 {
                for s in [1.0, -1.0] {
                    let mut n = [0.0; 3];
                    n[k] = s;
                    out.push((n, s * c[k] + h));
                }
            }
        }
        Separation::Six => {
            for sx in [1.0, -1.0] {
                for sy in [1.0, -1.0] {
                    for sz in [1.0, -1.0] {
                        let n = [sx, sy, sz];
                        out.push((n, n[0] * c[0] + n[1] * c[1] + n[2] * c[2] + h));
                    }
                }
            }
        }
    }
    out
}

/// Whether the polygon clipped by all half-spaces is non-empty.
fn overlaps(poly: &[[f64; 3]], planes: &[([f64; 3], f64)]) -> bool {
    let mut p: Vec<[f64; 3]> = poly.to_vec();
    for (n, d) in planes {
        let f = |q: &[f64; 3]| n[0] * q[0] + n[1] * q[1] + n[2] * q[2] - d;
        let mut out = Vec::new();
        for i in 0..p.len() {
            let (a, b) = (p[i], p[(i + 1) % p.len()]);
            let (fa, fb) = (f(&a), f(&b));
            if fa <= 0.0 {
                out.push(a);
            }
            if (fa < 0.0 && fb > 0.0) || (fa > 0.0 && fb < 0.0) {
                let t = fa / (fa - fb);
                out.push([0, 1, 2].map(|k| a[k] + t * (b[k] - a[k])));
            }
        }
        if out.is_empty() {
            return false;
        }
        p = out;
    }
    true
}

#[test]
fn triangle_membership_matches_clipping() {
    let mut checked = 0u64;
    let mut skipped = 0u64;
    for seed in 0..300u64 {
        let mut rng = Rng::new(9000 + seed);
        let snap = |x: i64| match seed % 4 {
            0 => x / VOXEL * VOXEL,
            1 => x / (VOXEL / 2) * (VOXEL / 2),
            _ => x,
        };
        let vs = [0; 3].map(|_| [0; 3].map(|_| snap(rng.range(VOXEL, 9 * VOXEL))));
        let t = Triangle {
            vertices: vs,
            normals: None,
        };
        let f = vs.map(|v| v.map(|c| c as f64 / VOXEL as f64));
        for sep in [Separation::Six, Separation::TwentySix] {
            let Ok(_) = triangle::contains(&t, sep, [0, 0, 0]) else {
                break; // degenerate
            };
            for z in 0..10u32 {
                for y in 0..10u32 {
                    for x in 0..10u32 {
                        let c = [x, y, z].map(|i| f64::from(i) + 0.5);
                        let inner = overlaps(&f, &probe(sep, c, -1e-6));
                        let outer = overlaps(&f, &probe(sep, c, 1e-6));
                        if inner != outer {
                            skipped += 1;
                            continue;
                        }
                        let got = triangle::contains(&t, sep, [x, y, z]).unwrap();
                        assert_eq!(
                            got,
                            inner,
                            "seed {seed} {sep:?} voxel {:?}: {t:?}",
                            [x, y, z]
                        );
                        checked += 1;
                    }
                }
            }
        }
    }
    println!("triangle membership: {checked} voxels checked, {skipped} ties skipped");
    assert!(checked > 500_000);
}
