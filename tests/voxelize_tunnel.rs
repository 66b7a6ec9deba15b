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

use rrt_core::check_voxelize::PlaneSink;
use rrt_core::discrete_ray::Connectivity;
use rrt_core::fixed::VOXEL;
use rrt_core::geometry::{BezierPatch, Cone, Cuboid, Sphere, Torus, Triangle};
use rrt_core::raster::{Extent, Raster};
use rrt_core::voxelize::{NORMAL_ONE, Separation, cone, cuboid, patch, sphere, torus, triangle};
use rrt_tests::Rng;
use rrt_tests::mesh::{box_mesh, fit, inside_mesh, read_obj};
use rrt_tests::tunnel::{Voxelized, assert_tunnel_free_both, origins, seeds};
use rrt_tests::vec3::{bezier, cross, dot, length, sub, triangle_normal};

/// Runs `case` for each of `n` seeds (see [`seeds`]) with a generator
/// seeded `first + seed`, sums the rays each fires, prints the total and
/// requires more than `at_least`.
#[track_caller]
fn soak(what: &str, n: u64, first: u64, at_least: u64, mut case: impl FnMut(u64, &mut Rng) -> u64) {
    let mut rays = 0u64;
    for seed in seeds(n) {
        let mut rng = Rng::new(first + seed);
        rays += case(seed, &mut rng);
    }
    println!("{what}: {rays} rays, all hit");
    assert!(rays > at_least);
}

/// Voxelizes a closed shape with both separations (`voxelize`) and fires
/// the tunnel probes from up to `n` origins in its box `lo..hi` (voxels
/// whose centre satisfies `inside`). Returns the number of rays fired.
#[track_caller]
fn probe_closed(
    extent: Extent,
    (lo, hi): ([i64; 3], [i64; 3]),
    n: usize,
    rng: &mut Rng,
    inside: impl Fn([i64; 3]) -> bool,
    what: &str,
    voxelize: impl Fn(Separation, &mut PlaneSink<'_>),
) -> u64 {
    let os = origins(extent, lo, hi, n, rng, &inside);
    assert_tunnel_free_both(extent, &os, rng, &inside, what, voxelize)
}

#[test]
fn spheres_are_tunnel_free() {
    soak("spheres", 120, 0, 100_000, |seed, rng| {
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
        let c = [jitter(rng), jitter(rng), jitter(rng)];
        let s = Sphere {
            centre: c,
            radius: r,
        };
        let inside = |p: [i64; 3]| {
            let d: i128 = (0..3).map(|k| i128::from(p[k] - c[k]).pow(2)).sum();
            d < i128::from(r).pow(2)
        };
        let bounds = (c.map(|v| v - r), c.map(|v| v + r));
        probe_closed(
            extent,
            bounds,
            4,
            rng,
            inside,
            &format!("seed {seed}: {s:?}"),
            |sep, sink| {
                sphere::surface(&s, sep, extent, sink).unwrap();
            },
        )
    });
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
        // Vertices ±x, ±y, ±z; the faces around +z (4) and −z (5) follow
        // the ring +x, +y, −x, −y counter-clockwise seen from outside.
        let v = (0..6)
            .map(|i| {
                let mut c = [0.0; 3];
                c[i / 2] = if i % 2 == 0 { 1.0 } else { -1.0 };
                c
            })
            .collect();
        let ring = [0, 2, 1, 3];
        let edges = || (0..4).map(move |i| (ring[i], ring[(i + 1) % 4]));
        let f = edges()
            .map(|(a, b)| [a, b, 4])
            .chain(edges().map(|(a, b)| [b, a, 5]))
            .collect();
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
    probe_closed(extent, (lo, hi), 4, rng, inside, what, |sep, sink| {
        let r = triangle::mesh(verts, None, faces, sep, extent, sink).unwrap();
        assert_eq!(r.degenerate, 0);
    })
}

#[test]
fn closed_meshes_are_tunnel_free() {
    soak("polyhedra", 160, 1000, 100_000, |seed, rng| {
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
        let what = format!("seed {seed}: polyhedron {verts:?}");
        check_mesh(&verts, &faces, extent, rng, &what)
    });
}

/// `x` on a voxel face (`seed % 3 == 0`), on a voxel centre (1) or
/// anywhere (2).
fn snap(seed: u64, x: i64) -> i64 {
    match seed % 3 {
        0 => x / VOXEL * VOXEL,
        1 => x / VOXEL * VOXEL + VOXEL / 2,
        _ => x,
    }
}

#[test]
fn box_meshes_are_tunnel_free() {
    soak("box meshes", 80, 2000, 10_000, |seed, rng| {
        let extent = Extent::cube(20).unwrap();
        // Corners on voxel faces, on voxel centres, or anywhere.
        let lo = [0; 3].map(|_| snap(seed, rng.range(2 * VOXEL, 8 * VOXEL)));
        let hi = [0; 3].map(|_| snap(seed, rng.range(10 * VOXEL, 17 * VOXEL)));
        let (verts, faces) = box_mesh(lo, hi);
        let what = format!("seed {seed}: box mesh {lo:?}..{hi:?}");
        check_mesh(&verts, &faces, extent, rng, &what)
    });
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
    soak("boxes", 100, 4000, 50_000, |seed, rng| {
        let extent = Extent::cube(18).unwrap();
        // Thin boxes too: down to a fraction of a voxel.
        let lo = [0; 3].map(|_| snap(seed, rng.range(2 * VOXEL, 8 * VOXEL)));
        let hi = [0, 1, 2].map(|k| lo[k] + 1 + snap(seed, rng.range(VOXEL / 4, 8 * VOXEL)));
        let b = Cuboid { min: lo, max: hi };
        let inside = |p: [i64; 3]| (0..3).all(|k| p[k] > lo[k] && p[k] < hi[k]);
        probe_closed(
            extent,
            (lo, hi),
            4,
            rng,
            inside,
            &format!("seed {seed}: {b:?}"),
            |sep, sink| {
                cuboid::surface(&b, sep, extent, sink).unwrap();
            },
        )
    });
}

fn unit_axis(rng: &mut Rng) -> [f64; 3] {
    loop {
        let a = [0; 3].map(|_| rng.range(-1000, 1000) as f64);
        let l = length(a);
        if l > 100.0 {
            return a.map(|c| c / l);
        }
    }
}

#[test]
fn tori_are_tunnel_free() {
    soak("tori", 60, 5000, 50_000, |seed, rng| {
        let minor = rng.range(VOXEL, 4 * VOXEL);
        let major = minor + rng.range(VOXEL / 2, 8 * VOXEL);
        let n = u32::try_from(2 * (major + minor) / VOXEL + 6).unwrap();
        let extent = Extent::cube(n).unwrap();
        let mid = i64::from(n) * VOXEL / 2 + rng.range(-VOXEL, VOXEL);
        let a = if seed % 3 == 0 {
            [0.0, 0.0, 1.0]
        } else {
            unit_axis(rng)
        };
        let t = Torus {
            centre: [mid; 3],
            axis: a.map(|c| (c * f64::from(NORMAL_ONE)) as i32),
            major,
            minor,
        };
        let inside = |p: [i64; 3]| {
            let w = [0, 1, 2].map(|k| (p[k] - mid) as f64);
            let h = dot(w, a);
            let rho = (dot(w, w) - h * h).max(0.0).sqrt();
            // Keep a 1/16 voxel margin: the tessellation lies inside.
            ((rho - major as f64).powi(2) + h * h).sqrt() < minor as f64 - VOXEL as f64 / 16.0
        };
        let r = major + minor;
        let bounds = ([mid - r; 3], [mid + r; 3]);
        probe_closed(
            extent,
            bounds,
            5,
            rng,
            inside,
            &format!("seed {seed}: {t:?}"),
            |sep, sink| {
                torus::surface(&t, sep, extent, sink).unwrap();
            },
        )
    });
}

#[test]
fn capped_cones_are_tunnel_free() {
    soak("capped cones", 80, 6000, 50_000, |seed, rng| {
        let n = 24u32;
        let extent = Extent::cube(n).unwrap();
        let pt = |rng: &mut Rng| [0; 3].map(|_| rng.range(7 * VOXEL, 17 * VOXEL));
        let (b, a) = (pt(rng), pt(rng));
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
        let len = length(axis);
        if len < VOXEL as f64 {
            return 0;
        }
        let inside = |p: [i64; 3]| {
            let w = [0, 1, 2].map(|k| (p[k] - b[k]) as f64);
            let t = dot(w, axis) / len;
            let rho = (dot(w, w) - t * t).max(0.0).sqrt();
            let r = r0 as f64 + (r1 - r0) as f64 * t / len;
            t > 0.0 && t < len && rho < r - VOXEL as f64 / 16.0
        };
        let bounds = ([0; 3], [i64::from(n) * VOXEL - 1; 3]);
        probe_closed(
            extent,
            bounds,
            5,
            rng,
            inside,
            &format!("seed {seed}: {c:?}"),
            |sep, sink| {
                cone::capped(&c, sep, extent, sink).unwrap();
            },
        )
    });
}

/// Fires rays across the open surface `voxelize` makes with each
/// separation, in each connectivity it must stop (6-separating surfaces
/// stop six and adaptive rays, 26-separating ones twenty-six rays), through
/// 20 points per separation that `sample` draws (a point in fixed units and
/// the unit normal there, or `None` to pass). Each ray must hit; `what`
/// names the case otherwise. Returns the number of rays fired.
fn probe_open(
    extent: Extent,
    rng: &mut Rng,
    voxelize: impl Fn(Separation, &mut PlaneSink<'_>),
    mut sample: impl FnMut(&mut Rng) -> Option<([f64; 3], [f64; 3])>,
    what: &dyn Fn(Separation, Connectivity) -> String,
) -> u64 {
    let mut rays = 0;
    for sep in [Separation::Six, Separation::TwentySix] {
        let v = Voxelized::new(extent, |sink| voxelize(sep, sink));
        let flagged = v.flagged();
        let r = Raster::new(extent, &flagged).unwrap();
        let modes: &[Connectivity] = match sep {
            Separation::Six => &[Connectivity::Six, Connectivity::Adaptive],
            Separation::TwentySix => &[Connectivity::TwentySix],
        };
        for _ in 0..20 {
            if let Some((p, nrm)) = sample(rng) {
                rays += cross_open(&r, modes, p, nrm, rng, &|mode| what(sep, mode));
            }
        }
    }
    rays
}

/// Fires rays of each connectivity in `modes` across an open surface
/// through point `p` (fixed units) with unit normal `nrm`, within 45° of
/// the normal, starting 3 voxels before the surface; each must hit
/// (`what(mode)` names the case otherwise). Returns rays fired.
fn cross_open(
    raster: &Raster<'_>,
    modes: &[Connectivity],
    p: [f64; 3],
    nrm: [f64; 3],
    rng: &mut Rng,
    what: &dyn Fn(Connectivity) -> String,
) -> u64 {
    let mut fired = 0;
    for &mode in modes {
        for _ in 0..8 {
            // A direction within 45° of the normal, either side.
            let t = unit_axis(rng);
            let side = if rng.chance(1, 2) { 1.0 } else { -1.0 };
            let mut d = [0, 1, 2].map(|k| side * nrm[k] + 0.9 * t[k]);
            let dn = dot(d, nrm);
            let l = length(d);
            if (dn / l).abs() < std::f64::consts::FRAC_1_SQRT_2 {
                continue;
            }
            d = d.map(|c| c / l);
            let o = [0, 1, 2].map(|k| (p[k] - 3.0 * VOXEL as f64 * d[k]) as i64);
            let dir = d.map(|c| (c * f64::from(1 << 24)) as i32);
            match rrt_core::check_voxelize::ray_hits(raster, o, dir, mode) {
                Ok(_) => fired += 1,
                Err(v) => panic!("{}: ray through {p:?} missed: {v:?}", what(mode)),
            }
        }
    }
    fired
}

#[test]
fn open_triangles_are_hit_away_from_their_boundary() {
    soak("open triangles", 150, 7000, 10_000, |seed, rng| {
        let extent = Extent::cube(32).unwrap();
        let pt = |rng: &mut Rng| [0; 3].map(|_| rng.range(6 * VOXEL, 26 * VOXEL));
        let vs = [pt(rng), pt(rng), pt(rng)];
        let f = vs.map(|v| v.map(|c| c as f64));
        let (e1, e2) = (sub(f[1], f[0]), sub(f[2], f[0]));
        let c = triangle_normal(f);
        let cl = length(c);
        if cl < 1.0 {
            return 0;
        }
        let nrm = c.map(|x| x / cl);
        let t = Triangle {
            vertices: vs,
            normals: None,
        };
        // Points at least 1.25 voxels (> √3/2 / sin 45°) from every edge.
        let sample = |rng: &mut Rng| {
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
                    let d = sub(e, s);
                    let w = sub(p, s);
                    let tt = (dot(w, d) / dot(d, d)).clamp(0.0, 1.0);
                    length([0, 1, 2].map(|k| w[k] - tt * d[k]))
                })
                .fold(f64::INFINITY, f64::min);
            if edge_dist < 1.25 * VOXEL as f64 {
                return None;
            }
            Some((p, nrm))
        };
        let voxelize = |sep, sink: &mut PlaneSink<'_>| {
            triangle::triangle(&t, sep, extent, sink).unwrap();
        };
        let what =
            |sep: Separation, mode: Connectivity| format!("seed {seed} {sep:?} {mode:?}: {t:?}");
        probe_open(extent, rng, voxelize, sample, &what)
    });
}

#[test]
fn patches_are_hit_away_from_their_boundary() {
    soak("patches", 40, 8000, 3_000, |seed, rng| {
        let extent = Extent::cube(32).unwrap();
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
        let eval = |u: f64, v: f64| bezier(&control, u, v);
        let sample = |rng: &mut Rng| {
            let (u, w) = (
                rng.range(25, 75) as f64 / 100.0,
                rng.range(25, 75) as f64 / 100.0,
            );
            let h = 1e-4;
            let pu = sub(eval(u + h, w), eval(u - h, w));
            let pv = sub(eval(u, w + h), eval(u, w - h));
            let c = cross(pu, pv);
            let cl = length(c);
            Some((eval(u, w), c.map(|x| x / cl)))
        };
        let voxelize = |sep, sink: &mut PlaneSink<'_>| {
            patch::surface(&bp, sep, extent, sink).unwrap();
        };
        let what =
            |sep: Separation, mode: Connectivity| format!("seed {seed} {sep:?} {mode:?}: patch");
        probe_open(extent, rng, voxelize, sample, &what)
    });
}
