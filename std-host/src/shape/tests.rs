//! Exact intersections: known values, grazing and inside-start rays for
//! every surface primitive, plus
//! seeded random rays checked against the implicit surface equations.

#![allow(clippy::needless_range_loop)]

use glam::DVec3;

use super::{Cone, Sphere, Surface, Torus, Triangle};
use crate::world::{Hit, Ray};

/// `s`'s hit, after checking that [`Surface::first_t`] gives its `t`.
fn hit_of(s: &impl Surface, r: &Ray, tmin: f64, tmax: f64) -> Option<Hit> {
    let hit = s.intersect(r, tmin, tmax);
    assert_eq!(s.first_t(r, tmin, tmax), hit.map(|h| h.t), "{r:?}");
    hit
}

fn sphere(r: &Ray, centre: DVec3, radius: f64, tmin: f64, tmax: f64) -> Option<Hit> {
    hit_of(&Sphere { centre, radius }, r, tmin, tmax)
}

fn triangle(
    r: &Ray,
    vertices: [DVec3; 3],
    normals: Option<[DVec3; 3]>,
    tmin: f64,
    tmax: f64,
) -> Option<Hit> {
    hit_of(&Triangle { vertices, normals }, r, tmin, tmax)
}

fn cone(
    r: &Ray,
    base: DVec3,
    base_radius: f64,
    apex: DVec3,
    apex_radius: f64,
    tmin: f64,
    tmax: f64,
) -> Option<Hit> {
    let c = Cone {
        base,
        base_radius,
        apex,
        apex_radius,
    };
    hit_of(&c, r, tmin, tmax)
}

fn torus(
    r: &Ray,
    centre: DVec3,
    axis: DVec3,
    major: f64,
    minor: f64,
    tmin: f64,
    tmax: f64,
) -> Option<Hit> {
    let t = Torus {
        centre,
        axis,
        major,
        minor,
    };
    hit_of(&t, r, tmin, tmax)
}

const INF: f64 = f64::INFINITY;

#[track_caller]
fn close(a: f64, b: f64, tol: f64) {
    assert!((a - b).abs() <= tol, "{a} vs {b} (tol {tol})");
}

#[track_caller]
fn close3(a: DVec3, b: DVec3, tol: f64) {
    assert!((a - b).length() <= tol, "{a} vs {b} (tol {tol})");
}

/// `h` is a hit at `t` with unit normal `normal`, both within `tol`.
#[track_caller]
fn assert_hit(h: Option<Hit>, t: f64, normal: DVec3, tol: f64) {
    let h = h.unwrap();
    close(h.t, t, tol);
    close3(h.normal, normal, tol);
}

fn ray(o: [f64; 3], d: [f64; 3]) -> Ray {
    Ray::new(DVec3::from(o), DVec3::from(d))
}

/// World-space values from the core's seeded generator, seeded per case.
struct Uniform(rrt_core::rng::Rng);
impl Uniform {
    fn unit(&mut self) -> f64 {
        (self.0.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }
    fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.unit()
    }
    fn vec(&mut self, lo: f64, hi: f64) -> DVec3 {
        DVec3::new(self.range(lo, hi), self.range(lo, hi), self.range(lo, hi))
    }
}

/// The smallest `t` in `(lo, hi)` where `f(ray.at(t))` changes sign or
/// touches 0, by fine marching then bisection: a slow, independent oracle.
fn march(r: &Ray, f: impl Fn(DVec3) -> f64, lo: f64, hi: f64, steps: usize) -> Option<f64> {
    let dt = (hi - lo) / steps as f64;
    let mut a = lo;
    let mut fa = f(r.at(a));
    for i in 1..=steps {
        let b = lo + dt * i as f64;
        let fb = f(r.at(b));
        if (fa < 0.0) != (fb < 0.0) {
            let (mut x, mut y) = (a, b);
            for _ in 0..100 {
                let m = 0.5 * (x + y);
                if (f(r.at(m)) < 0.0) == (fa < 0.0) {
                    x = m;
                } else {
                    y = m;
                }
            }
            return Some(0.5 * (x + y));
        }
        (a, fa) = (b, fb);
    }
    None
}

// ------------------------------------------------------------------ sphere

/// The unit sphere about the origin, from `o` along `d`, over `(0, ∞)`.
fn unit_sphere(o: [f64; 3], d: [f64; 3]) -> Option<Hit> {
    sphere(&ray(o, d), DVec3::ZERO, 1.0, 0.0, INF)
}

#[test]
fn sphere_known_values() {
    let h = unit_sphere([0.0, 0.0, -5.0], [0.0, 0.0, 1.0]).unwrap();
    assert_eq!(h.t, 4.0);
    assert_eq!(h.normal, -DVec3::Z);
    // t is in units of the direction.
    let h = unit_sphere([0.0, 0.0, -5.0], [0.0, 0.0, 2.0]).unwrap();
    assert_eq!(h.t, 2.0);
    // Off-centre: x = 0.6 meets the unit sphere at z = −0.8.
    let h = unit_sphere([0.6, 0.0, -5.0], [0.0, 0.0, 1.0]);
    assert_hit(h, 4.2, DVec3::new(0.6, 0.0, -0.8), 1e-15);
    // Pointing away, or the interval excludes both roots (open bounds).
    let r = ray([0.0, 0.0, -5.0], [0.0, 0.0, 1.0]);
    assert!(unit_sphere([0.0, 0.0, -5.0], [0.0, 0.0, -1.0]).is_none());
    assert!(sphere(&r, DVec3::ZERO, 1.0, 0.0, 4.0).is_none());
    assert_eq!(sphere(&r, DVec3::ZERO, 1.0, 4.0, INF).unwrap().t, 6.0);
}

#[test]
fn sphere_inside_start_hits_far_side_with_outward_normal() {
    let h = sphere(
        &ray([0.0, 0.0, 0.0], [1.0, 0.0, 0.0]),
        DVec3::ZERO,
        2.0,
        0.0,
        INF,
    )
    .unwrap();
    assert_eq!(h.t, 2.0);
    assert_eq!(h.normal, DVec3::X);
    // Starting on the surface and leaving it: no re-hit with tmin > 0.
    let r = ray([2.0, 0.0, 0.0], [1.0, 0.0, 0.0]);
    assert!(sphere(&r, DVec3::ZERO, 2.0, 1e-9, INF).is_none());
}

#[test]
fn sphere_grazing() {
    // Tangent at (0, 1, 0): a double root, a hit.
    let h = unit_sphere([-5.0, 1.0, 0.0], [1.0, 0.0, 0.0]);
    assert_hit(h, 5.0, DVec3::Y, 1e-14);
    assert!(unit_sphere([-5.0, 1.0 + 1e-9, 0.0], [1.0, 0.0, 0.0]).is_none());
    let h = unit_sphere([-5.0, 1.0 - 1e-9, 0.0], [1.0, 0.0, 0.0]).unwrap();
    close(h.t, 5.0, 1e-4);
}

#[test]
fn sphere_far_and_small_keeps_precision() {
    let c = DVec3::new(0.0, 0.0, 1e6);
    let h = sphere(&ray([0.0, 0.0, 0.0], [0.0, 0.0, 1.0]), c, 1e-3, 0.0, INF).unwrap();
    close(h.t, 1e6 - 1e-3, 1e-9);
}

#[test]
fn sphere_random_rays_land_on_surface() {
    for seed in 0..2000 {
        let mut g = Uniform(rrt_core::rng::Rng::new(seed));
        let c = g.vec(-5.0, 5.0);
        let r = g.range(0.1, 3.0);
        let o = g.vec(-10.0, 10.0);
        let target = c + g.vec(-1.0, 1.0) * r;
        let ry = Ray::new(o, (target - o) * g.range(0.1, 3.0));
        let f = |p: DVec3| (p - c).length() - r;
        let expect = march(&ry, f, 0.0, 20.0, 20_000);
        let got = sphere(&ry, c, r, 0.0, INF);
        match (got, expect) {
            (Some(h), Some(t)) => {
                close(h.t, t, 1e-6 * (1.0 + t));
                close(f(ry.at(h.t)), 0.0, 1e-9);
                close3(h.normal, (ry.at(h.t) - c) / r, 1e-9);
            }
            (None, None) => {}
            (got, expect) => panic!("seed {seed}: {got:?} vs {expect:?}"),
        }
    }
}

#[test]
fn sphere_refusal_only_where_there_is_no_hit() {
    // Rays aimed at points around the sphere, many of them clear misses,
    // some from inside, some pointing away: a refused ray has no hit for
    // any tmax; a NaN sphere (the tracer's table for other objects)
    // refuses nothing.
    let nan = Sphere {
        centre: DVec3::NAN,
        radius: f64::NAN,
    };
    let mut refused = 0;
    for seed in 0..4000 {
        let mut g = Uniform(rrt_core::rng::Rng::new(seed));
        let s = Sphere {
            centre: g.vec(-5.0, 5.0),
            radius: g.range(0.01, 3.0),
        };
        let o = g.vec(-10.0, 10.0);
        let target = s.centre + g.vec(-3.0, 3.0) * s.radius;
        let ry = Ray::new(o, (target - o) * g.range(0.1, 3.0));
        for tmin in [-1.0, 0.0, 1e-3] {
            assert!(!nan.refuses(&ry, tmin));
            if s.refuses(&ry, tmin) {
                refused += 1;
                assert_eq!(s.first_t(&ry, tmin, INF), None, "seed {seed}");
                assert!(s.intersect(&ry, tmin, INF).is_none(), "seed {seed}");
            } else if s.first_t(&ry, tmin, INF).is_none() {
                // Not refused: the full form decides.
                assert!(s.intersect(&ry, tmin, INF).is_none(), "seed {seed}");
            }
        }
    }
    assert!(
        refused > 1000,
        "only {refused} refusals: the test lost its misses"
    );
}

// ---------------------------------------------------------------- triangle

#[test]
fn triangle_known_values_and_barycentrics() {
    let v = [DVec3::ZERO, DVec3::X, DVec3::Y];
    let h = triangle(&ray([0.25, 0.5, 3.0], [0.0, 0.0, -1.0]), v, None, 0.0, INF).unwrap();
    assert_eq!(h.t, 3.0);
    assert_eq!((h.u, h.v), (0.25, 0.5));
    // Winding v0 → v1 → v2 counter-clockwise seen from +z.
    assert_eq!(h.normal, DVec3::Z);
    // From below: the same normal (not flipped).
    let h = triangle(&ray([0.25, 0.25, -1.0], [0.0, 0.0, 2.0]), v, None, 0.0, INF).unwrap();
    assert_eq!((h.t, h.normal), (0.5, DVec3::Z));
}

#[test]
fn triangle_interpolates_vertex_normals() {
    let v = [DVec3::ZERO, DVec3::X, DVec3::Y];
    let n = [
        DVec3::Z,
        DVec3::new(1.0, 0.0, 1.0),
        DVec3::new(0.0, 1.0, 1.0),
    ];
    // Straight down onto the triangle with vertex normals `n`.
    let down =
        |x: f64, y: f64, n| triangle(&ray([x, y, 1.0], [0.0, 0.0, -1.0]), v, Some(n), 0.0, INF);
    let h = down(0.25, 0.5, n).unwrap();
    let expect = (n[0] * 0.25 + n[1] * 0.25 + n[2] * 0.5).normalize();
    close3(h.normal, expect, 1e-15);
    // At a vertex, that vertex's normal.
    let h = down(1.0, 0.0, n).unwrap();
    close3(h.normal, n[1].normalize(), 1e-15);
    // Normals that cancel fall back to the face normal.
    let opposite = [DVec3::Z, -DVec3::Z, DVec3::Z];
    let h = down(0.5, 0.0, [opposite[0], opposite[1], DVec3::ZERO]).unwrap();
    assert_eq!(h.normal, DVec3::Z);
}

#[test]
fn triangle_edges_parallel_and_degenerate() {
    let v = [DVec3::ZERO, DVec3::X, DVec3::Y];
    let down = [0.0, 0.0, -1.0];
    // On the hypotenuse u + v = 1 and on the edges: hits.
    assert!(triangle(&ray([0.5, 0.5, 1.0], down), v, None, 0.0, INF).is_some());
    assert!(triangle(&ray([0.0, 0.3, 1.0], down), v, None, 0.0, INF).is_some());
    // Just outside: misses.
    assert!(triangle(&ray([0.5, 0.5 + 1e-12, 1.0], down), v, None, 0.0, INF).is_none());
    assert!(triangle(&ray([-1e-12, 0.3, 1.0], down), v, None, 0.0, INF).is_none());
    // A grazing ray in the triangle's plane, and a zero-area triangle.
    assert!(triangle(&ray([-1.0, 0.2, 0.0], [1.0, 0.0, 0.0]), v, None, 0.0, INF).is_none());
    let flat = [DVec3::ZERO, DVec3::X, DVec3::X * 2.0];
    assert!(triangle(&ray([0.5, 0.0, 1.0], down), flat, None, 0.0, INF).is_none());
    // A ray starting on the triangle: excluded by tmin, included below it.
    let r = ray([0.2, 0.2, 0.0], [0.0, 0.0, 1.0]);
    assert!(triangle(&r, v, None, 0.0, INF).is_none());
    assert_eq!(triangle(&r, v, None, -1.0, INF).unwrap().t, 0.0);
}

#[test]
fn triangle_random_rays_against_plane_and_barycentrics() {
    for seed in 0..2000 {
        let mut g = Uniform(rrt_core::rng::Rng::new(seed));
        let v = [g.vec(-3.0, 3.0), g.vec(-3.0, 3.0), g.vec(-3.0, 3.0)];
        let o = g.vec(-10.0, 10.0);
        let target = v[0] + (v[1] - v[0]) * g.range(-0.2, 1.0) + (v[2] - v[0]) * g.range(-0.2, 1.0);
        let r = Ray::new(o, target - o);
        let Some(h) = triangle(&r, v, None, 0.0, INF) else {
            continue;
        };
        let p = r.at(h.t);
        let q = v[0] * (1.0 - h.u - h.v) + v[1] * h.u + v[2] * h.v;
        close3(p, q, 1e-9 * (1.0 + p.length()));
        assert!(h.u >= 0.0 && h.v >= 0.0 && h.u + h.v <= 1.0, "seed {seed}");
        close(h.normal.dot(v[1] - v[0]), 0.0, 1e-9);
        close(h.normal.dot(v[2] - v[0]), 0.0, 1e-9);
    }
}

/// A vertex far from the others costs no precision near them: a sliver
/// with one vertex up to 1e15 away answers rays near its narrow end as the
/// same triangle with its vertices listed in any order, and as the exact
/// inside test (the sliver's edges there are the lines through (1, -1) and
/// (0, 1) towards the far vertex).
#[test]
fn triangle_with_a_far_vertex_keeps_precision_near_the_others() {
    let down = [0.0, 0.0, -1.0];
    for far in [1e6, 1e9, 1e12, 1e15] {
        let v = [
            DVec3::new(-far, -far, 0.0),
            DVec3::new(1.0, -1.0, 0.0),
            DVec3::Y,
        ];
        let orders = [[0, 1, 2], [1, 2, 0], [2, 0, 1], [2, 1, 0]];
        for i in 0..=40 {
            for j in 0..=40 {
                let (x, y) = (-1.0 + 0.05 * f64::from(i), -1.0 + 0.05 * f64::from(j));
                let r = ray([x, y, 2.0], down);
                let hits: Vec<_> = orders
                    .iter()
                    .map(|o| triangle(&r, o.map(|k| v[k]), None, 0.0, INF).map(|h| h.t))
                    .collect();
                assert!(
                    hits.iter().all(|h| *h == hits[0]),
                    "far {far}, ({x}, {y}): {hits:?}"
                );
                if let Some(t) = hits[0] {
                    close(t, 2.0, 1e-12);
                }
            }
        }
    }
}

/// Triangles that share an edge leave no crack along it, whatever the
/// coordinates: a square of side 2e16 cut along its diagonal is met by
/// every ray through points on and near that diagonal, at the square's
/// plane.
#[test]
fn triangles_sharing_an_edge_leave_no_crack() {
    for size in [1.0, 1e3, 1e9, 1e16, 1e40] {
        let q = [
            DVec3::new(-size, -size, 0.0),
            DVec3::new(size, -size, 0.0),
            DVec3::new(size, size, 0.0),
            DVec3::new(-size, size, 0.0),
        ];
        let halves = [[q[0], q[1], q[2]], [q[0], q[2], q[3]]];
        let mut g = Uniform(rrt_core::rng::Rng::new(7));
        for _ in 0..2000 {
            // A point on the diagonal, or a rounding step off it, near the
            // centre, seen from a random point above.
            let s = g.range(-0.5, 0.5) * size.min(4.0);
            let p = DVec3::new(s, s * (1.0 + g.range(-1e-15, 1e-15)), 0.0);
            let o = p + g.vec(-3.0, 3.0).with_z(g.range(1.0, 5.0));
            let r = Ray::new(o, p - o);
            let hit = halves
                .iter()
                .filter_map(|&v| triangle(&r, v, None, 0.0, INF))
                .map(|h| h.t)
                .next();
            let t = hit.unwrap_or_else(|| panic!("size {size}: crack at {p}"));
            close(t, 1.0, 1e-9);
        }
    }
}

// -------------------------------------------------------------------- cone

/// The cylinder of radius 1 from the origin to (0, 0, 2), open at both
/// ends, from `o` along `d`, over `(0, ∞)`.
fn cylinder(o: [f64; 3], d: [f64; 3]) -> Option<Hit> {
    cone(&ray(o, d), DVec3::ZERO, 1.0, TOP, 1.0, 0.0, INF)
}

/// The top of [`cylinder`].
const TOP: DVec3 = DVec3::new(0.0, 0.0, 2.0);

/// The cone of radius 1 at z = 0 narrowing to a point at z = 1, from `o`
/// along `d`, over `(0, ∞)`.
fn pointed(o: [f64; 3], d: [f64; 3]) -> Option<Hit> {
    cone(&ray(o, d), DVec3::ZERO, 1.0, DVec3::Z, 0.0, 0.0, INF)
}

#[test]
fn cylinder_known_values_inside_start_and_open_ends() {
    let h = cylinder([-5.0, 0.0, 1.0], [1.0, 0.0, 0.0]);
    assert_hit(h, 4.0, -DVec3::X, 1e-15);
    // Inside: the far wall, normal outward.
    let h = cylinder([0.0, 0.0, 1.0], [1.0, 0.0, 0.0]);
    assert_hit(h, 1.0, DVec3::X, 1e-15);
    // Along the axis inside: out through the open ends.
    assert!(cylinder([0.0, 0.0, 1.0], [0.0, 0.0, 1.0]).is_none());
    // Above or below the finite cylinder: misses.
    assert!(cylinder([-5.0, 0.0, 2.5], [1.0, 0.0, 0.0]).is_none());
    // Entering through the open top end, then hitting the wall inside.
    let h = cylinder([0.0, 0.0, 3.0], [0.5, 0.0, -1.0]);
    assert_hit(h, 2.0, DVec3::X, 1e-15);
    // Radii sign as embree_nff: absolute values.
    let r = ray([-5.0, 0.0, 1.0], [1.0, 0.0, 0.0]);
    let h = cone(&r, DVec3::ZERO, -1.0, TOP, -1.0, 0.0, INF).unwrap();
    close(h.t, 4.0, 1e-15);
}

#[test]
fn cylinder_grazing() {
    let h = cylinder([-5.0, 1.0, 1.0], [1.0, 0.0, 0.0]);
    assert_hit(h, 5.0, DVec3::Y, 1e-12);
    assert!(cylinder([-5.0, 1.0 + 1e-9, 1.0], [1.0, 0.0, 0.0]).is_none());
    // Parallel to the axis, on the wall: no isolated intersection.
    assert!(cylinder([1.0, 0.0, -1.0], [0.0, 0.0, 1.0]).is_none());
}

#[test]
fn cone_known_values() {
    // Radius 1 at z = 0 down to a point at z = 1.
    let h = pointed([-5.0, 0.0, 0.5], [1.0, 0.0, 0.0]);
    assert_hit(h, 4.5, DVec3::new(-1.0, 0.0, 1.0).normalize(), 1e-15);
    // A ray lying on a generator (x = z − 1): no isolated intersection.
    let h = pointed([-2.0, 0.0, -1.0], [1.0, 0.0, 1.0]);
    assert!(h.is_none(), "{h:?}");
    // Parallel to that generator, inside it (x = z − 0.5): the quadratic
    // degenerates to a linear equation; the far side at z = 0.75, t = 2.25.
    let h = pointed([-2.0, 0.0, -1.5], [1.0, 0.0, 1.0]);
    assert_hit(h, 2.25, DVec3::new(1.0, 0.0, 1.0).normalize(), 1e-12);
}

#[test]
fn cone_random_rays_land_on_surface() {
    for seed in 0..2000 {
        let mut g = Uniform(rrt_core::rng::Rng::new(seed));
        let b = g.vec(-2.0, 2.0);
        let a = g.vec(-2.0, 2.0);
        let (r0, r1) = (g.range(0.0, 1.0), g.range(0.1, 1.0));
        let o = g.vec(-6.0, 6.0);
        let target = b + (a - b) * g.range(0.0, 1.0) + g.vec(-1.0, 1.0);
        let ry = Ray::new(o, target - o);
        let Some(h) = cone(&ry, b, r0, a, r1, 0.0, INF) else {
            continue;
        };
        let axis = (a - b).normalize();
        let q = ry.at(h.t) - b;
        let y = q.dot(axis);
        let height = (a - b).length();
        assert!((-1e-9..=height + 1e-9).contains(&y), "seed {seed}");
        let radius = r0 + (r1 - r0) * y / height;
        close((q - axis * y).length(), radius, 1e-8);
        // The normal is perpendicular to the generator through the point.
        let radial = (q - axis * y).normalize();
        let generator = (a + radial * r1) - (b + radial * r0);
        close(h.normal.dot(generator), 0.0, 1e-8);
        assert!(h.normal.dot(radial) > 0.0, "outward");
    }
}

// ------------------------------------------------------------------- torus

/// R = 2, r = 0.5 about z through the origin.
fn ring(r: &Ray) -> Option<Hit> {
    torus(r, DVec3::ZERO, DVec3::Z, 2.0, 0.5, 0.0, INF)
}

#[test]
fn torus_known_values() {
    let h = ring(&ray([-5.0, 0.0, 0.0], [1.0, 0.0, 0.0]));
    assert_hit(h, 2.5, -DVec3::X, 1e-12);
    // From the centre: the inner side of the tube, facing the hole.
    let h = ring(&ray([0.0, 0.0, 0.0], [1.0, 0.0, 0.0]));
    assert_hit(h, 1.5, -DVec3::X, 1e-12);
    // From above, down onto the tube's top.
    let h = ring(&ray([2.0, 0.0, 5.0], [0.0, 0.0, -2.0]));
    assert_hit(h, 2.25, DVec3::Z, 1e-12);
    // Down the axis, through the hole.
    assert!(ring(&ray([0.0, 0.0, 5.0], [0.0, 0.0, -1.0])).is_none());
    // Across the hole at a height above the tube.
    assert!(ring(&ray([-5.0, 0.0, 0.6], [1.0, 0.0, 0.0])).is_none());
    // The interval skips the first two roots.
    let h = torus(
        &ray([-5.0, 0.0, 0.0], [1.0, 0.0, 0.0]),
        DVec3::ZERO,
        DVec3::Z,
        2.0,
        0.5,
        4.0,
        INF,
    )
    .unwrap();
    close(h.t, 6.5, 1e-12);
}

#[test]
fn torus_inside_start() {
    let h = ring(&ray([2.0, 0.0, 0.0], [1.0, 0.0, 0.0]));
    assert_hit(h, 0.5, DVec3::X, 1e-12);
    let h = ring(&ray([0.0, 2.0, 0.0], [0.0, 0.0, 1.0]));
    assert_hit(h, 0.5, DVec3::Z, 1e-12);
}

#[test]
fn torus_grazing() {
    // Along the top circle's tangent: touches at (2, 0, 0.5) only. The
    // contact is of order 4 (the quartic behaves like y⁴/16 there), so
    // rounding of about 1e-16 moves the root by about its fourth root.
    let h = ring(&ray([2.0, -5.0, 0.5], [0.0, 1.0, 0.0]));
    assert_hit(h, 5.0, DVec3::Z, 1e-4);
    // Tangent to the outer equator at (2.5, 0, 0).
    let h = ring(&ray([2.5, -5.0, 0.0], [0.0, 1.0, 0.0])).unwrap();
    close(h.t, 5.0, 1e-6);
    close3(h.normal, DVec3::X, 1e-5);
    // Just outside each: misses.
    assert!(ring(&ray([2.0, -5.0, 0.5 + 1e-7], [0.0, 1.0, 0.0])).is_none());
    assert!(ring(&ray([2.5 + 1e-7, -5.0, 0.0], [0.0, 1.0, 0.0])).is_none());
    // Just inside: two close roots; the nearer one.
    let h = ring(&ray([2.5 - 1e-6, -5.0, 0.0], [0.0, 1.0, 0.0])).unwrap();
    assert!(h.t < 5.0 && h.t > 4.99, "{}", h.t);
}

#[test]
fn torus_random_rays_against_implicit_surface() {
    for seed in 0..1500 {
        let mut g = Uniform(rrt_core::rng::Rng::new(seed));
        let c = g.vec(-3.0, 3.0);
        let axis = g.vec(-1.0, 1.0).normalize();
        let (big, small) = (g.range(0.5, 3.0), g.range(0.05, 0.6));
        let o = g.vec(-8.0, 8.0);
        let target = c + g.vec(-1.0, 1.0) * (big + small);
        let r = Ray::new(o, (target - o) * g.range(0.5, 2.0));
        let f = |p: DVec3| {
            let q = p - c;
            let h = q.dot(axis);
            let rho = (q - axis * h).length();
            (rho - big).hypot(h) - small
        };
        let expect = march(&r, f, 0.0, 40.0, 40_000);
        match (torus(&r, c, axis, big, small, 0.0, INF), expect) {
            (Some(h), Some(t)) => {
                close(h.t, t, 1e-6 * (1.0 + t));
                close(f(r.at(h.t)), 0.0, 1e-9);
                // The normal is the direction from the tube's centre circle.
                let q = r.at(h.t) - c;
                let hgt = q.dot(axis);
                let ring_pt = (q - axis * hgt).normalize() * big;
                close3(h.normal, (q - ring_pt).normalize(), 1e-7);
            }
            (None, None) => {}
            // A graze the marcher's sampling stepped over.
            (Some(h), None) if f(r.at(h.t)).abs() < 1e-9 => {}
            (got, expect) => panic!("seed {seed}: {got:?} vs {expect:?}"),
        }
    }
}

#[test]
fn torus_far_away_keeps_precision() {
    let c = DVec3::new(1e4, -2e4, 5e3);
    let r = Ray::new(DVec3::ZERO, c + DVec3::new(-2.5, 0.0, 0.0));
    let h = torus(&r, c, DVec3::Z, 2.0, 0.5, 0.0, INF).unwrap();
    // Hits the outer equator at c − (2.5, 0, 0) exactly at t = 1.
    close(h.t, 1.0, 1e-12);
}

#[test]
fn non_finite_input_is_a_miss() {
    let nan = ray([f64::NAN, 0.0, 0.0], [1.0, 0.0, 0.0]);
    let zero = ray([0.0, 0.0, -5.0], [0.0, 0.0, 0.0]);
    for r in [nan, zero] {
        assert!(sphere(&r, DVec3::ZERO, 1.0, 0.0, INF).is_none());
        assert!(triangle(&r, [DVec3::ZERO, DVec3::X, DVec3::Y], None, 0.0, INF).is_none());
        assert!(cone(&r, DVec3::ZERO, 1.0, DVec3::Z, 1.0, 0.0, INF).is_none());
        assert!(ring(&r).is_none());
    }
}
