//! Tunnel-freedom of voxelized closed shapes, as seeded property tests.
//!
//! For every closed shape, discrete rays of the matching connectivity
//! (Separation::Six ⇒ Six, and Adaptive over proximity flags;
//! Separation::TwentySix ⇒ TwentySix) are fired from voxels whose centre lies
//! inside the shape towards every voxel corner, edge midpoint and face
//! centre on a cube around the origin (so they pass straight through voxel
//! corners and edges) plus random directions; every ray must hit a surface
//! voxel before it leaves the raster. The probes are
//! `rrt_tests::tunnel::assert_tunnel_free`, over the checker
//! `rrt_core::check_voxelize::check_closed`.
//!
//! Every case derives from a printed seed: `RRT_SEED=<seed>` replays one;
//! `RRT_SCALE=<k>` runs k times as many cases.

use rrt_core::discrete_ray::Connectivity;
use rrt_core::fixed::VOXEL;
use rrt_core::geometry::{BezierPatch, Cone, Cuboid, Sphere, Torus, Triangle};
use rrt_core::raster::{Extent, Raster};
use rrt_core::voxelize::{NORMAL_ONE, Separation, cone, cuboid, patch, sphere, torus, triangle};
use rrt_tests::Rng;
use rrt_tests::mesh::{box_mesh, fit, inside_mesh, read_obj};
use rrt_tests::tunnel::{Voxelized, assert_tunnel_free_both, origins, seeds};

#[test]
fn spheres_are_tunnel_free() {
    let mut rays = 0u64;
    for seed in seeds(120) {
        let mut rng = Rng::new(seed);
        // Radii from half a voxel to 14 voxels, some on exact lattice values.
        let r = match seed % 4 {
            0 => rng.range(VOXEL / 2, 3 * VOXEL),
            1 => rng.range(1, 14) * VOXEL,
            2 => rng.range(1, 28) * VOXEL / 2,
            _ => rng.range(3 * VOXEL, 14 * VOXEL),
        };
        let n = u32::try_from(2 * (r / VOXEL) + 6).unwrap();
        let extent = Extent::cube(n).unwrap();
        let mid = i64::from(n) * VOXEL / 2;
        let jitter = |rng: &mut Rng| match seed % 3 {
            0 => mid,
            1 => mid + VOXEL / 2,
            _ => mid + rng.range(-VOXEL, VOXEL),
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
        rays += assert_tunnel_free_both(
            extent,
            &os,
            &mut rng,
            &inside,
            &format!("seed {seed}: {s:?}"),
            |sep, sink| {
                sphere::surface(&s, sep, extent, sink).unwrap();
            },
        );
    }
    println!("spheres: {rays} rays, all hit");
    assert!(rays > 100_000);
}

/// Unit icosahedron (vertices, outward faces) and octahedron.
fn platonic(ico: bool) -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
    if ico {
        let p = (1.0 + 5f64.sqrt()) / 2.0;
        let n = (1.0 + p * p).sqrt();
        let v = vec![
            [-1.0, p, 0.0],
            [1.0, p, 0.0],
            [-1.0, -p, 0.0],
            [1.0, -p, 0.0],
            [0.0, -1.0, p],
            [0.0, 1.0, p],
            [0.0, -1.0, -p],
            [0.0, 1.0, -p],
            [p, 0.0, -1.0],
            [p, 0.0, 1.0],
            [-p, 0.0, -1.0],
            [-p, 0.0, 1.0],
        ]
        .into_iter()
        .map(|c: [f64; 3]| c.map(|x| x / n))
        .collect();
        let f = vec![
            [0, 11, 5],
            [0, 5, 1],
            [0, 1, 7],
            [0, 7, 10],
            [0, 10, 11],
            [1, 5, 9],
            [5, 11, 4],
            [11, 10, 2],
            [10, 7, 6],
            [7, 1, 8],
            [3, 9, 4],
            [3, 4, 2],
            [3, 2, 6],
            [3, 6, 8],
            [3, 8, 9],
            [4, 9, 5],
            [2, 4, 11],
            [6, 2, 10],
            [8, 6, 7],
            [9, 8, 1],
        ];
        (v, f)
    } else {
        let v = vec![
            [1.0, 0.0, 0.0],
            [-1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, -1.0, 0.0],
            [0.0, 0.0, 1.0],
            [0.0, 0.0, -1.0],
        ];
        let f = vec![
            [0, 2, 4],
            [2, 1, 4],
            [1, 3, 4],
            [3, 0, 4],
            [2, 0, 5],
            [1, 2, 5],
            [3, 1, 5],
            [0, 3, 5],
        ];
        (v, f)
    }
}

/// Voxelizes a closed mesh with both separations and fires the probes.
fn check_mesh(
    verts: &[[i64; 3]],
    faces: &[[u32; 3]],
    extent: Extent,
    rng: &mut Rng,
    what: &str,
) -> u64 {
    let lo = [0, 1, 2].map(|k| verts.iter().map(|v| v[k]).min().unwrap());
    let hi = [0, 1, 2].map(|k| verts.iter().map(|v| v[k]).max().unwrap());
    let inside = |p: [i64; 3]| inside_mesh(verts, faces, p);
    let os = origins(extent, lo, hi, 4, rng, inside);
    assert_tunnel_free_both(extent, &os, rng, &inside, what, |sep, sink| {
        let r = triangle::mesh(verts, None, faces, sep, extent, sink).unwrap();
        assert_eq!(r.degenerate, 0);
    })
}

#[test]
fn closed_meshes_are_tunnel_free() {
    let mut rays = 0u64;
    for seed in seeds(160) {
        let mut rng = Rng::new(1000 + seed);
        let r = rng.range(3 * VOXEL / 2, 14 * VOXEL) as f64;
        let n = (2.0 * r / VOXEL as f64) as u32 + 6;
        let extent = Extent::cube(n).unwrap();
        let mid = f64::from(n) * VOXEL as f64 / 2.0;
        let (unit, faces) = platonic(seed % 2 == 0);
        let verts: Vec<[i64; 3]> = unit
            .iter()
            .map(|u| {
                let j = [0; 3].map(|_| 1.0 + rng.range(-150, 150) as f64 / 1000.0);
                let p = [0, 1, 2].map(|k| mid + r * u[k] * j[k]);
                match seed % 3 {
                    0 => p.map(|c| c as i64),
                    1 => p.map(|c| (c / VOXEL as f64).round() as i64 * VOXEL),
                    _ => p.map(|c| (c / VOXEL as f64).floor() as i64 * VOXEL + VOXEL / 2),
                }
            })
            .collect();
        rays += check_mesh(
            &verts,
            &faces,
            extent,
            &mut rng,
            &format!("seed {seed}: polyhedron {verts:?}"),
        );
    }
    println!("polyhedra: {rays} rays, all hit");
    assert!(rays > 100_000);
}

#[test]
fn box_meshes_are_tunnel_free() {
    let mut rays = 0u64;
    for seed in seeds(80) {
        let mut rng = Rng::new(2000 + seed);
        let n = 20u32;
        let extent = Extent::cube(n).unwrap();
        // Corners on voxel faces, on voxel centres, or anywhere.
        let snap = |x: i64| match seed % 3 {
            0 => x / VOXEL * VOXEL,
            1 => x / VOXEL * VOXEL + VOXEL / 2,
            _ => x,
        };
        let lo = [0; 3].map(|_| snap(rng.range(2 * VOXEL, 8 * VOXEL)));
        let hi = [0; 3].map(|_| snap(rng.range(10 * VOXEL, 17 * VOXEL)));
        let (verts, faces) = box_mesh(lo, hi);
        rays += check_mesh(
            &verts,
            &faces,
            extent,
            &mut rng,
            &format!("seed {seed}: box mesh {lo:?}..{hi:?}"),
        );
    }
    println!("box meshes: {rays} rays, all hit");
    assert!(rays > 10_000);
}

#[test]
fn bunny_is_tunnel_free() {
    let Some(data) = rrt_tests::shared_data() else {
        println!("SKIPPED: ../shared/data not found, bunny test not run");
        return;
    };
    let path = data.join("meshes/bunny.obj");
    if !path.is_file() {
        println!("SKIPPED: meshes/bunny.obj not found");
        return;
    }
    let (v, faces) = read_obj(&path);
    let mut rays = 0;
    for (i, n) in [48u32, 96].into_iter().enumerate() {
        let verts = fit(&v, n, 3);
        let mut rng = Rng::new(3000 + i as u64);
        rays += check_mesh(
            &verts,
            &faces,
            Extent::cube(n).unwrap(),
            &mut rng,
            &format!("bunny at {n}"),
        );
    }
    println!("bunny: {rays} rays, all hit");
    assert!(rays > 5_000);
}

#[test]
fn boxes_are_tunnel_free() {
    let mut rays = 0u64;
    for seed in seeds(100) {
        let mut rng = Rng::new(4000 + seed);
        let extent = Extent::cube(18).unwrap();
        let snap = |x: i64| match seed % 3 {
            0 => x / VOXEL * VOXEL,
            1 => x / VOXEL * VOXEL + VOXEL / 2,
            _ => x,
        };
        // Thin boxes too: down to a fraction of a voxel.
        let lo = [0; 3].map(|_| snap(rng.range(2 * VOXEL, 8 * VOXEL)));
        let hi = [0, 1, 2].map(|k| lo[k] + 1 + snap(rng.range(VOXEL / 4, 8 * VOXEL)));
        let b = Cuboid { min: lo, max: hi };
        let inside = |p: [i64; 3]| (0..3).all(|k| p[k] > lo[k] && p[k] < hi[k]);
        let os = origins(extent, lo, hi, 4, &mut rng, inside);
        rays += assert_tunnel_free_both(
            extent,
            &os,
            &mut rng,
            &inside,
            &format!("seed {seed}: {b:?}"),
            |sep, sink| {
                cuboid::surface(&b, sep, extent, sink).unwrap();
            },
        );
    }
    println!("boxes: {rays} rays, all hit");
    assert!(rays > 50_000);
}

fn unit_axis(rng: &mut Rng) -> [f64; 3] {
    loop {
        let a = [0; 3].map(|_| rng.range(-1000, 1000) as f64);
        let l = (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt();
        if l > 100.0 {
            return a.map(|c| c / l);
        }
    }
}

#[test]
fn tori_are_tunnel_free() {
    let mut rays = 0u64;
    for seed in seeds(60) {
        let mut rng = Rng::new(5000 + seed);
        let minor = rng.range(VOXEL, 4 * VOXEL);
        let major = minor + rng.range(VOXEL / 2, 8 * VOXEL);
        let n = u32::try_from(2 * (major + minor) / VOXEL + 6).unwrap();
        let extent = Extent::cube(n).unwrap();
        let mid = i64::from(n) * VOXEL / 2 + rng.range(-VOXEL, VOXEL);
        let a = if seed % 3 == 0 {
            [0.0, 0.0, 1.0]
        } else {
            unit_axis(&mut rng)
        };
        let t = Torus {
            centre: [mid; 3],
            axis: a.map(|c| (c * f64::from(NORMAL_ONE)) as i32),
            major,
            minor,
        };
        let inside = |p: [i64; 3]| {
            let w = [0, 1, 2].map(|k| (p[k] - mid) as f64);
            let h = w[0] * a[0] + w[1] * a[1] + w[2] * a[2];
            let rho = ((w[0] * w[0] + w[1] * w[1] + w[2] * w[2]) - h * h)
                .max(0.0)
                .sqrt();
            // Keep a 1/16 voxel margin: the tessellation lies inside.
            ((rho - major as f64).powi(2) + h * h).sqrt() < minor as f64 - VOXEL as f64 / 16.0
        };
        let r = major + minor;
        let os = origins(extent, [mid - r; 3], [mid + r; 3], 5, &mut rng, inside);
        rays += assert_tunnel_free_both(
            extent,
            &os,
            &mut rng,
            &inside,
            &format!("seed {seed}: {t:?}"),
            |sep, sink| {
                torus::surface(&t, sep, extent, sink).unwrap();
            },
        );
    }
    println!("tori: {rays} rays, all hit");
    assert!(rays > 50_000);
}

#[test]
fn capped_cones_are_tunnel_free() {
    let mut rays = 0u64;
    for seed in seeds(80) {
        let mut rng = Rng::new(6000 + seed);
        let n = 24u32;
        let extent = Extent::cube(n).unwrap();
        let pt = |rng: &mut Rng| [0; 3].map(|_| rng.range(7 * VOXEL, 17 * VOXEL));
        let (b, a) = (pt(&mut rng), pt(&mut rng));
        let r0 = rng.range(if seed % 4 == 0 { 0 } else { VOXEL / 2 }, 6 * VOXEL);
        let r1 = if seed % 5 == 0 {
            r0
        } else {
            rng.range(VOXEL / 2, 6 * VOXEL)
        };
        let c = Cone {
            base: b,
            base_radius: r0,
            apex: a,
            apex_radius: r1,
        };
        let axis = [0, 1, 2].map(|k| (a[k] - b[k]) as f64);
        let len = (axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]).sqrt();
        if len < VOXEL as f64 {
            continue;
        }
        let inside = |p: [i64; 3]| {
            let w = [0, 1, 2].map(|k| (p[k] - b[k]) as f64);
            let t = (w[0] * axis[0] + w[1] * axis[1] + w[2] * axis[2]) / len;
            let rho = ((w[0] * w[0] + w[1] * w[1] + w[2] * w[2]) - t * t)
                .max(0.0)
                .sqrt();
            let r = r0 as f64 + (r1 - r0) as f64 * t / len;
            t > 0.0 && t < len && rho < r - VOXEL as f64 / 16.0
        };
        let os = origins(
            extent,
            [0; 3],
            [i64::from(n) * VOXEL - 1; 3],
            5,
            &mut rng,
            inside,
        );
        rays += assert_tunnel_free_both(
            extent,
            &os,
            &mut rng,
            &inside,
            &format!("seed {seed}: {c:?}"),
            |sep, sink| {
                cone::capped(&c, sep, extent, sink).unwrap();
            },
        );
    }
    println!("capped cones: {rays} rays, all hit");
    assert!(rays > 50_000);
}

/// Fires rays across an open surface through points `p` (fixed units) with
/// unit normal `nrm`, at angles of at least `min_deg` to the surface,
/// starting 3 voxels before it; each must hit. Returns rays fired.
fn cross_open(
    raster: &Raster<'_>,
    mode: Connectivity,
    p: [f64; 3],
    nrm: [f64; 3],
    rng: &mut Rng,
    what: &str,
) -> u64 {
    let mut fired = 0;
    for _ in 0..8 {
        // A direction within 45° of the normal, either side.
        let t = unit_axis(rng);
        let side = if rng.chance(1, 2) { 1.0 } else { -1.0 };
        let mut d = [0, 1, 2].map(|k| side * nrm[k] + 0.9 * t[k]);
        let dn = d[0] * nrm[0] + d[1] * nrm[1] + d[2] * nrm[2];
        let l = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
        if (dn / l).abs() < std::f64::consts::FRAC_1_SQRT_2 {
            continue;
        }
        d = d.map(|c| c / l);
        let o = [0, 1, 2].map(|k| (p[k] - 3.0 * VOXEL as f64 * d[k]) as i64);
        let dir = d.map(|c| (c * f64::from(1 << 24)) as i32);
        match rrt_core::check_voxelize::ray_hits(raster, o, dir, mode) {
            Ok(_) => fired += 1,
            Err(v) => panic!("{what}: ray through {p:?} missed: {v:?}"),
        }
    }
    fired
}

#[test]
fn open_triangles_are_hit_away_from_their_boundary() {
    let mut rays = 0u64;
    for seed in seeds(150) {
        let mut rng = Rng::new(7000 + seed);
        let n = 32u32;
        let extent = Extent::cube(n).unwrap();
        let pt = |rng: &mut Rng| [0; 3].map(|_| rng.range(6 * VOXEL, 26 * VOXEL));
        let vs = [pt(&mut rng), pt(&mut rng), pt(&mut rng)];
        let f = vs.map(|v| v.map(|c| c as f64));
        let e1 = [0, 1, 2].map(|k| f[1][k] - f[0][k]);
        let e2 = [0, 1, 2].map(|k| f[2][k] - f[0][k]);
        let c = [
            e1[1] * e2[2] - e1[2] * e2[1],
            e1[2] * e2[0] - e1[0] * e2[2],
            e1[0] * e2[1] - e1[1] * e2[0],
        ];
        let cl = (c[0] * c[0] + c[1] * c[1] + c[2] * c[2]).sqrt();
        if cl < 1.0 {
            continue;
        }
        let nrm = c.map(|x| x / cl);
        let t = Triangle {
            vertices: vs,
            normals: None,
        };
        for sep in [Separation::Six, Separation::TwentySix] {
            let v = Voxelized::new(extent, |sink| {
                triangle::triangle(&t, sep, extent, sink).unwrap();
            });
            let flagged = v.flagged();
            let r = Raster::new(extent, &flagged).unwrap();
            let modes: &[Connectivity] = match sep {
                Separation::Six => &[Connectivity::Six, Connectivity::Adaptive],
                Separation::TwentySix => &[Connectivity::TwentySix],
            };
            for _ in 0..20 {
                // A point at least 1.25 voxels (> √3/2 / sin 45°) from every edge.
                let (a, b) = (
                    rng.range(0, 1000) as f64 / 1000.0,
                    rng.range(0, 1000) as f64 / 1000.0,
                );
                let (a, b) = if a + b > 1.0 {
                    (1.0 - a, 1.0 - b)
                } else {
                    (a, b)
                };
                let p = [0, 1, 2].map(|k| f[0][k] + a * e1[k] + b * e2[k]);
                let edge_dist = (0..3)
                    .map(|i| {
                        let (s, e) = (f[i], f[(i + 1) % 3]);
                        let d = [0, 1, 2].map(|k| e[k] - s[k]);
                        let w = [0, 1, 2].map(|k| p[k] - s[k]);
                        let dd = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
                        let tt = ((w[0] * d[0] + w[1] * d[1] + w[2] * d[2]) / dd).clamp(0.0, 1.0);
                        let q = [0, 1, 2].map(|k| w[k] - tt * d[k]);
                        (q[0] * q[0] + q[1] * q[1] + q[2] * q[2]).sqrt()
                    })
                    .fold(f64::INFINITY, f64::min);
                if edge_dist < 1.25 * VOXEL as f64 {
                    continue;
                }
                for &mode in modes {
                    rays += cross_open(
                        &r,
                        mode,
                        p,
                        nrm,
                        &mut rng,
                        &format!("seed {seed} {sep:?} {mode:?}: {t:?}"),
                    );
                }
            }
        }
    }
    println!("open triangles: {rays} rays, all hit");
    assert!(rays > 10_000);
}

#[test]
fn patches_are_hit_away_from_their_boundary() {
    let mut rays = 0u64;
    for seed in seeds(40) {
        let mut rng = Rng::new(8000 + seed);
        let n = 32u32;
        let extent = Extent::cube(n).unwrap();
        let mut control = [[[0i64; 3]; 4]; 4];
        for (i, row) in control.iter_mut().enumerate() {
            for (j, q) in row.iter_mut().enumerate() {
                *q = [
                    (6 + 6 * i as i64) * VOXEL + rng.range(-VOXEL, VOXEL),
                    (6 + 6 * j as i64) * VOXEL + rng.range(-VOXEL, VOXEL),
                    16 * VOXEL + rng.range(-4 * VOXEL, 4 * VOXEL),
                ];
            }
        }
        let bp = BezierPatch { control };
        let eval = |u: f64, v: f64| -> [f64; 3] {
            let b = |t: f64| {
                [
                    (1.0 - t).powi(3),
                    3.0 * t * (1.0 - t).powi(2),
                    3.0 * t * t * (1.0 - t),
                    t.powi(3),
                ]
            };
            let (bu, bv) = (b(u), b(v));
            let mut out = [0.0; 3];
            for a in 0..4 {
                for c in 0..4 {
                    for k in 0..3 {
                        out[k] += bu[a] * bv[c] * control[a][c][k] as f64;
                    }
                }
            }
            out
        };
        for sep in [Separation::Six, Separation::TwentySix] {
            let v = Voxelized::new(extent, |sink| {
                patch::surface(&bp, sep, extent, sink).unwrap();
            });
            let flagged = v.flagged();
            let r = Raster::new(extent, &flagged).unwrap();
            let modes: &[Connectivity] = match sep {
                Separation::Six => &[Connectivity::Six, Connectivity::Adaptive],
                Separation::TwentySix => &[Connectivity::TwentySix],
            };
            for _ in 0..20 {
                let (u, w) = (
                    rng.range(25, 75) as f64 / 100.0,
                    rng.range(25, 75) as f64 / 100.0,
                );
                let p = eval(u, w);
                let h = 1e-4;
                let pu = [0, 1, 2].map(|k| eval(u + h, w)[k] - eval(u - h, w)[k]);
                let pv = [0, 1, 2].map(|k| eval(u, w + h)[k] - eval(u, w - h)[k]);
                let c = [
                    pu[1] * pv[2] - pu[2] * pv[1],
                    pu[2] * pv[0] - pu[0] * pv[2],
                    pu[0] * pv[1] - pu[1] * pv[0],
                ];
                let cl = (c[0] * c[0] + c[1] * c[1] + c[2] * c[2]).sqrt();
                let nrm = c.map(|x| x / cl);
                for &mode in modes {
                    rays += cross_open(
                        &r,
                        mode,
                        p,
                        nrm,
                        &mut rng,
                        &format!("seed {seed} {sep:?} {mode:?}: patch"),
                    );
                }
            }
        }
    }
    println!("patches: {rays} rays, all hit");
    assert!(rays > 3_000);
}
