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
    ///
    /// The watertight test of Woop, Benthin and Wald (JCGT 2013): the
    /// vertices are taken relative to the ray's origin and sheared so that
    /// the ray runs along an axis; the three edge functions are then 2D
    /// cross products of vertex pairs, each edge's computed from its two
    /// vertices alone. So no vertex is privileged (a vertex far from the
    /// others costs no precision near them), and triangles that share an
    /// edge compute that edge's function to the same value up to sign: a
    /// ray through a shared edge meets at least one of them, however large
    /// the coordinates.
    #[inline(always)]
    fn crossing(&self, ray: &Ray, tmin: f64, tmax: f64) -> Option<(f64, f64, f64)> {
        let a = ray.dir.abs();
        // The driving axis kz; kx, ky follow it cyclically, swapped when the
        // ray runs down kz, so that the shear keeps the winding.
        let down = |k: f64| k < 0.0;
        if a.x >= a.y && a.x >= a.z {
            if down(ray.dir.x) {
                self.sheared::<2, 1, 0>(ray, tmin, tmax)
            } else {
                self.sheared::<1, 2, 0>(ray, tmin, tmax)
            }
        } else if a.y >= a.z {
            if down(ray.dir.y) {
                self.sheared::<0, 2, 1>(ray, tmin, tmax)
            } else {
                self.sheared::<2, 0, 1>(ray, tmin, tmax)
            }
        } else if down(ray.dir.z) {
            self.sheared::<1, 0, 2>(ray, tmin, tmax)
        } else {
            self.sheared::<0, 1, 2>(ray, tmin, tmax)
        }
    }

    /// [`Self::crossing`] for the axes `KX`, `KY`, `KZ` (the driving axis).
    #[inline(always)]
    fn sheared<const KX: usize, const KY: usize, const KZ: usize>(
        &self,
        ray: &Ray,
        tmin: f64,
        tmax: f64,
    ) -> Option<(f64, f64, f64)> {
        let d = ray.dir.to_array();
        let (sx, sy) = (d[KX] / d[KZ], d[KY] / d[KZ]);
        let [p0, p1, p2] = self.vertices.map(|v| (v - ray.origin).to_array());
        let shear = |p: [f64; 3]| (p[KX] - sx * p[KZ], p[KY] - sy * p[KZ]);
        let ((ax, ay), (bx, by), (cx, cy)) = (shear(p0), shear(p1), shear(p2));
        // Twice the signed areas of the sub-triangles the ray's point
        // makes with each edge: the weights of vertices 0, 1 and 2. Seen
        // from either side: the weights share a sign (edges included).
        let w0 = cx * by - cy * bx;
        let w1 = ax * cy - ay * cx;
        if (w0 < 0.0 && w1 > 0.0) || (w0 > 0.0 && w1 < 0.0) {
            return None;
        }
        let w2 = bx * ay - by * ax;
        if (w0 < 0.0 || w1 < 0.0 || w2 < 0.0) && (w0 > 0.0 || w1 > 0.0 || w2 > 0.0) {
            return None;
        }
        let det = w0 + w1 + w2;
        // A ray in the triangle's plane (or a triangle with no area) misses:
        // the projected area vanishes against the products it is made of.
        let scale = (cx * by).abs()
            + (cy * bx).abs()
            + (ax * cy).abs()
            + (ay * cx).abs()
            + (bx * ay).abs()
            + (by * ax).abs();
        if !(det.abs() > 1e-14 * scale) {
            return None;
        }
        // The parameter from the plane through the vertex nearest the
        // origin: its rounding grows with that vertex's distance, where an
        // interpolation of the three vertices' depths would grow with the
        // farthest's.
        let [v0, v1, v2] = self.vertices;
        let n = (v1 - v0).cross(v2 - v0);
        let near =
            [p1, p2]
                .into_iter()
                .map(DVec3::from_array)
                .fold(DVec3::from_array(p0), |a, b| {
                    if b.abs().max_element() < a.abs().max_element() {
                        b
                    } else {
                        a
                    }
                });
        let t = n.dot(near) / n.dot(ray.dir);
        if !(t > tmin && t < tmax) {
            return None;
        }
        let inv = 1.0 / det;
        Some((t, w1 * inv, w2 * inv))
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

    /// Ray–triangle (the watertight test), edges included. With `normals`, the
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
