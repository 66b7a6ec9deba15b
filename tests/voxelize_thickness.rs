//! Thickness bound of the voxelized surfaces: voxels generated per unit area
//! against the minimum the connectivity needs. For a plane with unit normal
//! `n` a 6-tunnel-free surface needs `‖n‖∞` voxels per unit area (a naive
//! digital plane) and a 26-tunnel-free one `‖n‖₁` (a standard plane); for a
//! curved surface the minimum is `∫ ‖n‖ dA`. Each case prints the measured
//! ratio; every case of at least moderate size must stay within 1.5×.
//!
//! Run with `--nocapture` to see the table.

use std::collections::HashSet;

use rrt_core::fixed::VOXEL;
use rrt_core::geometry::{BezierPatch, Cone, Cuboid, Sphere, Torus, Triangle};
use rrt_core::raster::Extent;
use rrt_core::voxelize::error::VoxelizeError;
use rrt_core::voxelize::volume::Block;
use rrt_core::voxelize::{
    Separation, Surfel, VoxelSink, cone, cuboid, patch, sphere, torus, triangle, volume,
};
use rrt_tests::mesh::{fit, read_obj};
use rrt_tests::vec3::{bezier, cross, length, triangle_normal};

/// Unique voxels and total offers.
#[derive(Default)]
struct Unique {
    set: HashSet<[u32; 3]>,
    offers: u64,
}

impl VoxelSink for Unique {
    fn offer(&mut self, v: [u32; 3], _: Surfel) {
        self.set.insert(v);
        self.offers += 1;
    }
}

fn norm(sep: Separation, n: [f64; 3]) -> f64 {
    let a = n.map(f64::abs);
    let l = length(a);
    match sep {
        Separation::Six => a[0].max(a[1]).max(a[2]) / l,
        Separation::TwentySix => (a[0] + a[1] + a[2]) / l,
    }
}

/// `∫ ‖n‖ dA` over a parametric surface `f(u, v)`, `u, v ∈ [0, 1]`, by the
/// midpoint rule on a `steps²` grid (in voxels²).
fn integrate(sep: Separation, steps: u32, f: impl Fn(f64, f64) -> [f64; 3]) -> f64 {
    let h = 1.0 / f64::from(steps);
    let mut s = 0.0;
    for i in 0..steps {
        for j in 0..steps {
            let (u, v) = ((f64::from(i) + 0.5) * h, (f64::from(j) + 0.5) * h);
            let du =
                [0, 1, 2].map(|k| (f(u + h / 2.0, v)[k] - f(u - h / 2.0, v)[k]) / VOXEL as f64);
            let dv =
                [0, 1, 2].map(|k| (f(u, v + h / 2.0)[k] - f(u, v - h / 2.0)[k]) / VOXEL as f64);
            let c = cross(du, dv);
            let area = length(c);
            if area > 0.0 {
                s += area * norm(sep, c);
            }
        }
    }
    s
}

struct Report {
    rows: Vec<(String, Separation, usize, u64, f64)>,
}

impl Report {
    /// Records a case; `checked` cases must stay within 1.5×.
    fn add(&mut self, what: &str, sep: Separation, u: &Unique, minimum: f64, checked: bool) {
        let ratio = u.set.len() as f64 / minimum;
        self.rows
            .push((what.to_string(), sep, u.set.len(), u.offers, minimum));
        println!(
            "{what:<34} {:<9} voxels {:>8}  offers/voxel {:>5.2}  minimum {:>10.1}  ratio {ratio:.3}{}",
            format!("{sep:?}"),
            u.set.len(),
            u.offers as f64 / u.set.len().max(1) as f64,
            minimum,
            if checked { "" } else { "  (not asserted)" }
        );
        if checked {
            assert!(ratio <= 1.5, "{what} {sep:?}: {ratio:.3} > 1.5");
            // The minimum is a density: a layer lying on one side of a
            // curved surface (the volume's inner boundary) or discretization
            // noise may dip slightly below it, never far.
            assert!(
                ratio >= 0.9,
                "{what} {sep:?}: {ratio:.3}: thinner than the minimum?"
            );
        }
    }

    /// Records a case voxelized by `voxelize` with each separation, against
    /// `minimum(sep)`.
    fn case(
        &mut self,
        what: &str,
        checked: bool,
        voxelize: impl Fn(Separation, &mut Unique),
        minimum: impl Fn(Separation) -> f64,
    ) {
        for sep in SEPS {
            let mut u = Unique::default();
            voxelize(sep, &mut u);
            self.add(what, sep, &u, minimum(sep), checked);
        }
    }
}

/// The voxelizer of `shape` into `extent` as [`Report::case`] calls it.
fn voxelizer<T>(
    voxelize: fn(&T, Separation, Extent, &mut Unique) -> Result<u64, VoxelizeError>,
    shape: &T,
    extent: Extent,
) -> impl Fn(Separation, &mut Unique) {
    move |sep, u| {
        voxelize(shape, sep, extent, u).unwrap();
    }
}

/// The point at `(a, b)` of a sphere of radius `r` voxels about the origin
/// (fixed units), `a` from pole to pole, `b` around the axis.
fn on_sphere(r: f64) -> impl Fn(f64, f64) -> [f64; 3] {
    let v = VOXEL as f64;
    move |a, b| {
        let (th, ph) = (a * std::f64::consts::PI, b * 2.0 * std::f64::consts::PI);
        [
            r * v * th.sin() * ph.cos(),
            r * v * th.sin() * ph.sin(),
            r * v * th.cos(),
        ]
    }
}

/// `∫ ‖n‖ dA` over the triangles `faces` of `verts` (fixed units), in
/// voxels².
fn mesh_minimum(sep: Separation, verts: &[[i64; 3]], faces: &[[u32; 3]]) -> f64 {
    let v = VOXEL as f64;
    let mut min = 0.0;
    for f in faces {
        let c = triangle_normal(f.map(|i| verts[i as usize].map(|c| c as f64 / v)));
        let area = 0.5 * length(c);
        if area > 0.0 {
            min += area * norm(sep, c);
        }
    }
    min
}

const SEPS: [Separation; 2] = [Separation::Six, Separation::TwentySix];

#[test]
fn thickness_within_one_and_a_half_of_the_minimum() {
    let mut rep = Report { rows: Vec::new() };
    let v = VOXEL as f64;
    // Spheres.
    for r in [3.0, 5.0, 10.0, 20.0, 40.0] {
        let n = (2.0 * r) as u32 + 6;
        let e = Extent::cube(n).unwrap();
        let c = (f64::from(n) / 2.0 * v) as i64 + 1234;
        let s = Sphere {
            centre: [c, c - 777, c + 4321],
            radius: (r * v) as i64,
        };
        // Below 5 voxels the shell is mostly curvature: reported only.
        rep.case(
            &format!("sphere r={r}"),
            r >= 5.0,
            voxelizer(sphere::surface, &s, e),
            |sep| integrate(sep, 400, on_sphere(r)),
        );
    }
    // Boxes: faces in general position, exactly on voxel faces and exactly
    // through voxel centres (ties, decided by the infinitesimal shift: one
    // layer per face).
    let e = Extent::cube(48).unwrap();
    for (what, b, checked) in [
        (
            "box 40x30x20",
            Cuboid {
                min: [3 * VOXEL + 100; 3],
                max: [43 * VOXEL + 7, 33 * VOXEL + 5000, 23 * VOXEL + 999],
            },
            true,
        ),
        (
            "box 40x30x20 on voxel faces",
            Cuboid {
                min: [3 * VOXEL; 3],
                max: [43 * VOXEL, 33 * VOXEL, 23 * VOXEL],
            },
            true,
        ),
        (
            "box 40x30x20 through centres",
            Cuboid {
                min: [3 * VOXEL + VOXEL / 2; 3],
                max: [
                    43 * VOXEL + VOXEL / 2,
                    33 * VOXEL + VOXEL / 2,
                    23 * VOXEL + VOXEL / 2,
                ],
            },
            true,
        ),
    ] {
        let d = [0, 1, 2].map(|k| (b.max[k] - b.min[k]) as f64 / v);
        rep.case(what, checked, voxelizer(cuboid::surface, &b, e), |_| {
            2.0 * (d[0] * d[1] + d[1] * d[2] + d[2] * d[0])
        });
    }
    // A large tilted triangle.
    let t = Triangle {
        vertices: [
            [4 * VOXEL, 5 * VOXEL, 10 * VOXEL],
            [90 * VOXEL, 12 * VOXEL, 40 * VOXEL + 999],
            [20 * VOXEL, 88 * VOXEL, 70 * VOXEL],
        ],
        normals: None,
    };
    let e = Extent::cube(96).unwrap();
    rep.case(
        "triangle (area ~4000)",
        true,
        voxelizer(triangle::triangle, &t, e),
        |sep| mesh_minimum(sep, &t.vertices, &[[0, 1, 2]]),
    );
    // A torus.
    let (big, small) = (20.0, 7.0);
    let tz = Torus {
        centre: [32 * VOXEL + 99; 3],
        axis: [0, 300, 500],
        major: (big * v) as i64,
        minor: (small * v) as i64,
    };
    let e = Extent::cube(64).unwrap();
    let ax = [0.0, 300.0 / 583.095_189_484_53, 500.0 / 583.095_189_484_53];
    let uu = [1.0, 0.0, 0.0];
    let vv = cross(ax, uu);
    let ring = |a: f64, b: f64| {
        let (th, ph) = (
            a * 2.0 * std::f64::consts::PI,
            b * 2.0 * std::f64::consts::PI,
        );
        let rho = big + small * ph.cos();
        [0, 1, 2]
            .map(|k| v * (rho * (th.cos() * uu[k] + th.sin() * vv[k]) + small * ph.sin() * ax[k]))
    };
    let surface = voxelizer(torus::surface, &tz, e);
    rep.case("torus 20/7", true, surface, |sep| integrate(sep, 600, ring));
    // An open cylinder.
    let cy = Cone {
        base: [30 * VOXEL; 3],
        base_radius: 12 * VOXEL,
        apex: [50 * VOXEL, 40 * VOXEL, 60 * VOXEL],
        apex_radius: 12 * VOXEL,
    };
    let e = Extent::cube(80).unwrap();
    let a = [20.0f64, 10.0, 30.0];
    let al = length(a);
    let w = a.map(|c| c / al);
    let p = [w[1], -w[0], 0.0];
    let pl = (p[0] * p[0] + p[1] * p[1]).sqrt();
    let p = p.map(|c| c / pl);
    let q = cross(w, p);
    let wall = |s: f64, t: f64| {
        let th = t * 2.0 * std::f64::consts::PI;
        [0, 1, 2].map(|k| v * (30.0 + s * a[k] + 12.0 * (th.cos() * p[k] + th.sin() * q[k])))
    };
    let surface = voxelizer(cone::surface, &cy, e);
    rep.case("open cylinder r=12", true, surface, |sep| {
        integrate(sep, 600, wall)
    });
    // A Bézier patch.
    let mut control = [[[0i64; 3]; 4]; 4];
    for (i, row) in control.iter_mut().enumerate() {
        for (j, cp) in row.iter_mut().enumerate() {
            let h = [10, 30, 5, 22][(i + 2 * j) % 4];
            *cp = [
                (4 + 25 * i as i64) * VOXEL,
                (4 + 25 * j as i64) * VOXEL + 3 * i as i64 * VOXEL,
                h * VOXEL + 77,
            ];
        }
    }
    let bp = BezierPatch { control };
    let e = Extent::cube(84).unwrap();
    rep.case(
        "bezier patch ~75x80",
        true,
        voxelizer(patch::surface, &bp, e),
        |sep| integrate(sep, 400, |s, t| bezier(&control, s, t)),
    );
    // A sampled ball (iso-radius 20).
    let n = 48u32;
    let mut s = Vec::new();
    for k in 0..n {
        for j in 0..n {
            for i in 0..n {
                let r2: f64 = [i, j, k]
                    .iter()
                    .map(|c| (f64::from(*c) - 23.5).powi(2))
                    .sum();
                s.push((30_000.0 - 50.0 * r2).max(0.0) as u16);
            }
        }
    }
    let blk = Block {
        samples: &s,
        dims: [n; 3],
        offset: [0; 3],
    };
    let thr = (30_000.0 - 50.0 * 400.0) as u16;
    rep.case(
        "volume ball iso r=20",
        true,
        |sep, u| {
            volume::boundary(&blk, thr, sep, Extent::cube(n).unwrap(), u).unwrap();
        },
        |sep| integrate(sep, 400, on_sphere(20.0)),
    );
    // The bunny, when the shared data is there.
    if let Some(data) = rrt_tests::shared_data()
        && let path = data.join("meshes/bunny.obj")
        && path.is_file()
    {
        let (verts, faces) = read_obj(&path);
        let verts = fit(&verts, 160, 3);
        rep.case(
            "bunny mesh at 160",
            true,
            |sep, u| {
                triangle::mesh(&verts, None, &faces, sep, Extent::cube(160).unwrap(), u).unwrap();
            },
            |sep| mesh_minimum(sep, &verts, &faces),
        );
    } else {
        println!("SKIPPED: bunny (../shared/data/meshes/bunny.obj not found)");
    }
    assert!(rep.rows.len() >= 18);
}
