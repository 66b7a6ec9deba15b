//! Triangles: the triangles of NFF polygons (`p`) and polygonal patches
//! (`pp`, which carry vertex normals), as [`crate::scene::polygon`] cuts
//! them, and of OBJ faces.

use glam::DVec3;
use rrt_core::geometry::{self, Point};
use rrt_core::object_table as table;
use rrt_core::voxelize::triangle;

use super::{Primitive, Slots, Surface, Unfit, get, put};
use crate::frame::{RasterFrame, unit_to_fixed};
use crate::world::{Bounds, Hit, Ray};

/// A triangle of a polygon (open: seen and lit from both sides),
/// with the patch's vertex normals (as written, not normalised) if it
/// comes from a `pp`. Saved as kind 3 (v0, v1, v2) or, with normals,
/// kind 4 (v0, v1, v2, n0, n1, n2).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Triangle {
    /// Vertices, in the polygon's winding.
    pub vertices: [DVec3; 3],
    /// Per-vertex normals, interpolated by [`Surface::intersect`].
    pub normals: Option<[DVec3; 3]>,
}

/// The saved kind of a flat triangle.
const FLAT: u32 = 3;
/// The saved kind of a triangle with vertex normals.
const SMOOTH: u32 = 4;

impl Triangle {
    /// Where `ray` crosses the triangle in `(tmin, tmax)`: `(t, u, v)`, the
    /// parameter and the barycentrics of vertices 1 and 2 of
    /// [`Surface::intersect`]'s hit.
    #[inline(always)]
    fn crossing(&self, ray: &Ray, tmin: f64, tmax: f64) -> Option<(f64, f64, f64)> {
        let [v0, v1, v2] = self.vertices;
        let e1 = v1 - v0;
        let e2 = v2 - v0;
        let p = ray.dir.cross(e2);
        let det = e1.dot(p);
        // A ray in the plane (|det| ≤ 1e-14·|e1|·|e2|·|dir|) misses; that
        // test's square roots are taken last, for rays that pass the others
        // (with det = 0 the barycentric tests below fail on NaN or ∞).
        let inv = 1.0 / det;
        let s = ray.origin - v0;
        let u = s.dot(p) * inv;
        if !(0.0..=1.0).contains(&u) {
            return None;
        }
        let q = s.cross(e1);
        let v = ray.dir.dot(q) * inv;
        if !(v >= 0.0 && u + v <= 1.0) {
            return None;
        }
        let t = e2.dot(q) * inv;
        if !(t > tmin && t < tmax) {
            return None;
        }
        let scale = e1.length() * e2.length() * ray.dir.length();
        if !(det.abs() > 1e-14 * scale) {
            return None;
        }
        Some((t, u, v))
    }
}

impl Primitive for Triangle {
    const KIND: &'static str = "triangle";

    fn validate(&self) -> Result<(), &'static str> {
        if !self.vertices.iter().all(|v| v.is_finite()) {
            return Err("vertex not finite");
        }
        if !self.normals.is_none_or(|n| n.iter().all(|v| v.is_finite())) {
            return Err("normal not finite");
        }
        Ok(())
    }

    fn bounds(&self) -> Bounds {
        Bounds::around(self.vertices)
    }
}

impl Surface for Triangle {
    type Fixed = geometry::Triangle;

    /// Degenerate when it has no area in fixed point. The normals are
    /// normalised and scaled by 2^30; a triangle with a normal that cannot
    /// be (zero) is flat.
    fn to_fixed(&self, frame: &RasterFrame) -> Result<geometry::Triangle, Unfit> {
        let mut vertices = [[0; 3]; 3];
        for (f, &v) in vertices.iter_mut().zip(&self.vertices) {
            *f = frame.to_fixed(v).ok_or(Unfit::OutOfRange)?;
        }
        if twice_area(vertices) == 0 {
            return Err(Unfit::Degenerate);
        }
        let normals = self.normals.and_then(|n| {
            Some([
                unit_to_fixed(n[0])?,
                unit_to_fixed(n[1])?,
                unit_to_fixed(n[2])?,
            ])
        });
        Ok(geometry::Triangle { vertices, normals })
    }

    // Voxelized by `triangle::triangle`, flat or with interpolated normals.
    core_surface!(
        geometry::Triangle,
        table::Shape::Triangle,
        triangle::triangle
    );

    /// Ray–triangle (Möller–Trumbore), edges included. With `normals`, the
    /// normal is the normalised barycentric interpolation
    /// `w·n0 + u·n1 + v·n2` (`w = 1 − u − v`, as `embree_nff`); without, or
    /// if that interpolation vanishes, the face normal `(v1−v0) × (v2−v0)`.
    /// A ray in the triangle's plane and a zero-area triangle miss.
    fn intersect(&self, ray: &Ray, tmin: f64, tmax: f64) -> Option<Hit> {
        let (t, u, v) = self.crossing(ray, tmin, tmax)?;
        let [v0, v1, v2] = self.vertices;
        let face = (v1 - v0).cross(v2 - v0).normalize_or(DVec3::Z);
        let normal = self
            .normals
            .and_then(|[n0, n1, n2]| (n0 * (1.0 - u - v) + n1 * u + n2 * v).try_normalize())
            .unwrap_or(face);
        Some(Hit { t, normal, u, v })
    }

    fn first_t(&self, ray: &Ray, tmin: f64, tmax: f64) -> Option<f64> {
        self.crossing(ray, tmin, tmax).map(|(t, _, _)| t)
    }

    fn save(&self, slots: &mut Slots) -> u32 {
        for (k, &v) in self.vertices.iter().enumerate() {
            put(slots, 3 * k, v);
        }
        match self.normals {
            Some(n) => {
                for (k, &v) in n.iter().enumerate() {
                    put(slots, 9 + 3 * k, v);
                }
                SMOOTH
            }
            None => FLAT,
        }
    }

    fn load(kind: u32, slots: &Slots) -> Option<Self> {
        (kind == FLAT || kind == SMOOTH).then(|| Self {
            vertices: [get(slots, 0), get(slots, 3), get(slots, 6)],
            normals: (kind == SMOOTH).then(|| [get(slots, 9), get(slots, 12), get(slots, 15)]),
        })
    }
}

/// `|(v1 − v0) × (v2 − v0)|`'s L1 norm, in i128: 0 exactly when the
/// triangle has no area.
fn twice_area(v: [Point; 3]) -> i128 {
    let d = |a: Point, b: Point| [0, 1, 2].map(|k| i128::from(b[k]) - i128::from(a[k]));
    let (e1, e2) = (d(v[0], v[1]), d(v[0], v[2]));
    let c = [
        e1[1] * e2[2] - e1[2] * e2[1],
        e1[2] * e2[0] - e1[0] * e2[2],
        e1[0] * e2[1] - e1[1] * e2[0],
    ];
    c[0].abs() + c[1].abs() + c[2].abs()
}
