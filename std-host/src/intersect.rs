//! Exact intersections not yet part of the shape model ([`crate::shape`]):
//! boxes, tori and bicubic Bézier patches, in `f64`.
//!
//! These serve *intersection verification* (Yagel et al. 1992, section
//! "object-space aliasing"): when a discrete ray hits a voxel, the
//! renderer intersects the continuous ray with the voxel's object from the
//! object table, and keeps the hit only if the true intersection is there.
//! The tests use them as ground truth as well.
//!
//! Every routine takes a [`Ray`] (the direction need not be unit length;
//! `t` is in units of it) and an open interval `(tmin, tmax)`, and returns
//! the nearest intersection with `tmin < t < tmax` and the surface's true
//! unit normal there:
//! * closed surfaces (sphere, box, torus) give the outward normal, also
//!   for a ray that starts inside;
//! * triangles give the normal of their winding, `(v1 − v0) × (v2 − v0)`,
//!   or the barycentric interpolation of their vertex normals;
//! * open cones give the outward normal of the lateral surface;
//! * Bézier patches give `∂P/∂u × ∂P/∂v`.
//!
//! None of them flips the normal towards the ray: shading does that
//! ([`crate::shade::face_forward`]). Tangent (grazing) rays count as hits.
//! No input makes them panic; non-finite input gives `None`.

#![deny(missing_docs)]
// `!(x >= 0.0)` is deliberate throughout: it is true for NaN, which must
// be refused like any other out-of-range value.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

use glam::DVec3;

use crate::world::{Hit, Ray};

// --------------------------------------------------------------------- box

/// Entry and exit of the ray through the closed box: `(t_in, axis_in,
/// t_out, axis_out)`, or `None` if the line misses it.
fn slabs(ray: &Ray, min: DVec3, max: DVec3) -> Option<(f64, usize, f64, usize)> {
    let (mut t_in, mut a_in) = (f64::NEG_INFINITY, 0);
    let (mut t_out, mut a_out) = (f64::INFINITY, 0);
    for k in 0..3 {
        let (o, d) = (ray.origin[k], ray.dir[k]);
        if d == 0.0 {
            if !(o >= min[k] && o <= max[k]) {
                return None;
            }
            continue;
        }
        let (mut a, mut b) = ((min[k] - o) / d, (max[k] - o) / d);
        if a > b {
            std::mem::swap(&mut a, &mut b);
        }
        if a > t_in {
            (t_in, a_in) = (a, k);
        }
        if b < t_out {
            (t_out, a_out) = (b, k);
        }
    }
    (t_in <= t_out).then_some((t_in, a_in, t_out, a_out))
}

/// Ray–axis-aligned box (the surface of `[min, max]`): the entry point if
/// it lies in `(tmin, tmax)`, else the exit point (a ray starting inside).
/// A ray through an edge or corner hits there; a ray lying in a face's
/// plane hits where it enters the face.
#[must_use]
pub fn aabb(ray: &Ray, min: DVec3, max: DVec3, tmin: f64, tmax: f64) -> Option<Hit> {
    if !(min.cmple(max).all() && ray.origin.is_finite() && ray.dir.is_finite()) {
        return None;
    }
    let (t_in, a_in, t_out, a_out) = slabs(ray, min, max)?;
    let (t, axis, sign) = if t_in > tmin && t_in < tmax {
        (t_in, a_in, -ray.dir[a_in].signum())
    } else if t_out > tmin && t_out < tmax {
        (t_out, a_out, ray.dir[a_out].signum())
    } else {
        return None;
    };
    let mut normal = DVec3::ZERO;
    normal[axis] = sign;
    Some(Hit::new(t, normal))
}

// ------------------------------------------------------------------- torus

/// Ray–torus: the surface at distance `minor` from the circle of radius
/// `major` about the unit `axis` through `centre`.
///
/// Solves the quartic in a local frame, with the ray moved to where it
/// enters the bounding sphere and its direction normalised, so the
/// coefficients stay well scaled. Roots are isolated robustly: the
/// polynomial is monotonic between consecutive roots of its derivative
/// (found the same way, recursively), so each such interval holds at most
/// one sign change, found by bisection to full precision; a critical point
/// where the polynomial vanishes (a tangent ray) is a root too.
#[must_use]
pub fn torus(
    ray: &Ray,
    centre: DVec3,
    axis: DVec3,
    major: f64,
    minor: f64,
    tmin: f64,
    tmax: f64,
) -> Option<Hit> {
    let len = ray.dir.length();
    let z = axis.try_normalize()?;
    if !(len > 0.0 && len.is_finite() && major > 0.0 && minor > 0.0 && ray.origin.is_finite()) {
        return None;
    }
    let (x, y) = z.any_orthonormal_pair();
    let to_local = |v: DVec3| DVec3::new(v.dot(x), v.dot(y), v.dot(z));
    let d = to_local(ray.dir / len);
    let o0 = to_local(ray.origin - centre);
    // Parameters along the unit direction.
    let (lo, hi) = (tmin * len, tmax * len);
    // Clip to the bounding sphere (with slack: a ray tangent to the torus'
    // outer equator is tangent to this sphere too).
    let bound = (major + minor) * (1.0 + 1e-9);
    let b = o0.dot(d);
    let disc = bound * bound - (o0 - d * b).length_squared();
    if !(disc >= 0.0) {
        return None;
    }
    let sq = disc.sqrt();
    let (s_in, s_out) = (-b - sq, -b + sq);
    let lo = lo.max(s_in - 1e-9 * bound);
    let hi = hi.min(s_out + 1e-9 * bound);
    if !(lo < hi) {
        return None;
    }
    // Shift the origin to the start of the interval.
    let shift = lo.max(s_in);
    let o = o0 + d * shift;
    let (r2, big2) = (minor * minor, major * major);
    let k = o.length_squared() + big2 - r2;
    let m = o.dot(d);
    let dxy = d.x * d.x + d.y * d.y;
    let oxy = o.x * o.x + o.y * o.y;
    let odxy = o.x * d.x + o.y * d.y;
    // (|p|² + R² − r²)² − 4R²(px² + py²), p = o + s·d, ascending powers.
    let poly = [
        k * k - 4.0 * big2 * oxy,
        4.0 * m * k - 8.0 * big2 * odxy,
        4.0 * m * m + 2.0 * k - 4.0 * big2 * dxy,
        4.0 * m,
        1.0,
    ];
    // Magnitudes of the terms summed into each coefficient: the scale of
    // their rounding errors (the constant term cancels heavily near a
    // tangent ray).
    let mag = [
        k * k + 4.0 * big2 * oxy,
        (4.0 * m * k).abs() + (8.0 * big2 * odxy).abs(),
        4.0 * m * m + 2.0 * k.abs() + 4.0 * big2 * dxy,
        (4.0 * m).abs(),
        1.0,
    ];
    let roots = poly_roots(&poly, &mag, lo - shift, hi - shift);
    let s = roots
        .iter()
        .map(|s| s + shift)
        .filter(|&s| s > tmin * len && s < tmax * len)
        .min_by(f64::total_cmp)?;
    let p = o0 + d * s;
    let ring = DVec3::new(p.x, p.y, 0.0).normalize_or(DVec3::X) * major;
    let n_local = (p - ring).normalize_or(DVec3::Z);
    let normal = x * n_local.x + y * n_local.y + z * n_local.z;
    Some(Hit::new(s / len, normal))
}

/// Up to 4 roots, unsorted.
#[derive(Clone, Copy, Debug, Default)]
struct Roots {
    r: [f64; 4],
    n: usize,
}

impl Roots {
    fn push(&mut self, x: f64) {
        if let Some(slot) = self.r.get_mut(self.n) {
            *slot = x;
            self.n += 1;
        }
    }
    fn iter(&self) -> impl Iterator<Item = f64> + '_ {
        self.r.iter().take(self.n).copied()
    }
}

fn eval(c: &[f64], x: f64) -> f64 {
    c.iter().rev().fold(0.0, |acc, &a| acc * x + a)
}

/// `Σ mag_i·|x|^i`: the scale of the rounding error of `eval(c, x)` when
/// `mag` bounds the magnitudes that went into each coefficient.
fn eval_scale(mag: &[f64], x: f64) -> f64 {
    let ax = x.abs();
    mag.iter().rev().fold(0.0, |acc, &a| acc * ax + a.abs())
}

/// Real roots in `[lo, hi]` of the polynomial with ascending coefficients
/// `c` (degree ≤ 4), by recursive isolation between critical points.
/// `mag[i]` bounds the magnitudes summed into `c[i]`, for the tolerance of
/// tangent (double) roots.
fn poly_roots(c: &[f64], mag: &[f64], lo: f64, hi: f64) -> Roots {
    let mut out = Roots::default();
    let deg = c.iter().rposition(|&a| a != 0.0).unwrap_or(0);
    let c = &c[..=deg.min(c.len().saturating_sub(1))];
    if deg == 0 {
        return out;
    }
    if deg == 1 {
        let x = -c[0] / c[1];
        if x >= lo && x <= hi {
            out.push(x);
        }
        return out;
    }
    let mut dc = [0.0; 4];
    let mut dmag = [0.0; 4];
    for (i, (a, m)) in c.iter().zip(mag).enumerate().skip(1) {
        dc[i - 1] = a * i as f64;
        dmag[i - 1] = m.abs() * i as f64;
    }
    let crit = poly_roots(&dc[..deg], &dmag[..deg], lo, hi);
    let mut pts = [0.0; 6];
    let mut n = 0;
    pts[n] = lo;
    n += 1;
    let mut cs = crit.r;
    let cs = &mut cs[..crit.n];
    cs.sort_by(f64::total_cmp);
    for &mut x in cs {
        pts[n] = x;
        n += 1;
    }
    pts[n] = hi;
    n += 1;
    let tiny = |x: f64| eval(c, x).abs() <= 1e-13 * eval_scale(mag, x);
    for w in pts[..n].windows(2) {
        let (a, b) = (w[0], w[1]);
        let (fa, fb) = (eval(c, a), eval(c, b));
        if fa == 0.0 {
            out.push(a);
        } else if (fa < 0.0) != (fb < 0.0) && fb != 0.0 {
            out.push(bisect(c, a, b, fa < 0.0));
        }
    }
    if eval(c, hi) == 0.0 {
        out.push(hi);
    }
    // Tangencies: a critical point where the polynomial (nearly) vanishes
    // without changing sign.
    for x in crit.iter() {
        if tiny(x) && out.iter().all(|r| (r - x).abs() > 1e-9 * (1.0 + x.abs())) {
            out.push(x);
        }
    }
    out
}

/// The sign change of `c` in `[a, b]`, `a_negative` telling the sign at `a`.
fn bisect(c: &[f64], mut a: f64, mut b: f64, a_negative: bool) -> f64 {
    for _ in 0..200 {
        let m = 0.5 * (a + b);
        if m <= a || m >= b {
            break;
        }
        if (eval(c, m) < 0.0) == a_negative {
            a = m;
        } else {
            b = m;
        }
    }
    0.5 * (a + b)
}

// ------------------------------------------------------------ Bézier patch

/// A bicubic Bézier patch's control points, `control[i][j]` for
/// `u = i/3`, `v = j/3`.
pub type PatchControl = [[DVec3; 4]; 4];

fn bernstein(t: f64) -> [f64; 4] {
    let s = 1.0 - t;
    [s * s * s, 3.0 * t * s * s, 3.0 * t * t * s, t * t * t]
}

fn bernstein_d(t: f64) -> [f64; 4] {
    let s = 1.0 - t;
    [
        -3.0 * s * s,
        3.0 * s * s - 6.0 * t * s,
        6.0 * t * s - 3.0 * t * t,
        3.0 * t * t,
    ]
}

/// The patch point and its partial derivatives at `(u, v)`.
#[must_use]
pub fn patch_eval(c: &PatchControl, u: f64, v: f64) -> (DVec3, DVec3, DVec3) {
    let (bu, bv, du, dv) = (bernstein(u), bernstein(v), bernstein_d(u), bernstein_d(v));
    let mut p = DVec3::ZERO;
    let mut pu = DVec3::ZERO;
    let mut pv = DVec3::ZERO;
    for i in 0..4 {
        for j in 0..4 {
            let q = c[i][j];
            p += q * (bu[i] * bv[j]);
            pu += q * (du[i] * bv[j]);
            pv += q * (bu[i] * dv[j]);
        }
    }
    (p, pu, pv)
}

/// The unit normal `∂P/∂u × ∂P/∂v` at `(u, v)`; where it vanishes (a
/// collapsed edge), the normal a little towards the patch centre.
#[must_use]
pub fn patch_normal(c: &PatchControl, u: f64, v: f64) -> DVec3 {
    let (_, pu, pv) = patch_eval(c, u, v);
    if let Some(n) = pu.cross(pv).try_normalize() {
        return n;
    }
    let (u2, v2) = (u + (0.5 - u) * 1e-4, v + (0.5 - v) * 1e-4);
    let (_, pu, pv) = patch_eval(c, u2, v2);
    pu.cross(pv).normalize_or(DVec3::Z)
}

/// Splits a curve of 4 control points at 1/2 (de Casteljau).
fn split4(p: [DVec3; 4]) -> ([DVec3; 4], [DVec3; 4]) {
    let m01 = (p[0] + p[1]) * 0.5;
    let m12 = (p[1] + p[2]) * 0.5;
    let m23 = (p[2] + p[3]) * 0.5;
    let a = (m01 + m12) * 0.5;
    let b = (m12 + m23) * 0.5;
    let mid = (a + b) * 0.5;
    ([p[0], m01, a, mid], [mid, b, m23, p[3]])
}

/// One piece of a subdivided patch: its control points and parameter box.
#[derive(Clone, Copy)]
struct PatchNode {
    c: PatchControl,
    u0: f64,
    u1: f64,
    v0: f64,
    v1: f64,
}

impl PatchNode {
    fn bounds(&self) -> (DVec3, DVec3) {
        let mut lo = DVec3::INFINITY;
        let mut hi = DVec3::NEG_INFINITY;
        for row in &self.c {
            for &p in row {
                lo = lo.min(p);
                hi = hi.max(p);
            }
        }
        (lo, hi)
    }

    /// Largest distance of a control point from the bilinear patch through
    /// the corners: 0 for a bilinear (e.g. flat, evenly spaced) piece.
    fn deviation(&self) -> f64 {
        let c = &self.c;
        let (p00, p30, p03, p33) = (c[0][0], c[3][0], c[0][3], c[3][3]);
        let mut dev: f64 = 0.0;
        for (i, row) in c.iter().enumerate() {
            for (j, &p) in row.iter().enumerate() {
                let (s, t) = (i as f64 / 3.0, j as f64 / 3.0);
                let bilinear = p00 * ((1.0 - s) * (1.0 - t))
                    + p30 * (s * (1.0 - t))
                    + p03 * ((1.0 - s) * t)
                    + p33 * (s * t);
                dev = dev.max((p - bilinear).length());
            }
        }
        dev
    }

    fn split(&self) -> [Self; 4] {
        // Split along u (the first index), then each half along v.
        let mut lo = [[DVec3::ZERO; 4]; 4];
        let mut hi = [[DVec3::ZERO; 4]; 4];
        for j in 0..4 {
            let (a, b) = split4([self.c[0][j], self.c[1][j], self.c[2][j], self.c[3][j]]);
            for i in 0..4 {
                lo[i][j] = a[i];
                hi[i][j] = b[i];
            }
        }
        let um = 0.5 * (self.u0 + self.u1);
        let vm = 0.5 * (self.v0 + self.v1);
        let half_v = |c: &PatchControl| {
            let mut a = [[DVec3::ZERO; 4]; 4];
            let mut b = [[DVec3::ZERO; 4]; 4];
            for i in 0..4 {
                let (x, y) = split4(c[i]);
                a[i] = x;
                b[i] = y;
            }
            (a, b)
        };
        let (lo_a, lo_b) = half_v(&lo);
        let (hi_a, hi_b) = half_v(&hi);
        let node = |c, u0, u1, v0, v1| Self { c, u0, u1, v0, v1 };
        [
            node(lo_a, self.u0, um, self.v0, vm),
            node(lo_b, self.u0, um, vm, self.v1),
            node(hi_a, um, self.u1, self.v0, vm),
            node(hi_b, um, self.u1, vm, self.v1),
        ]
    }
}

/// Deepest subdivision: pieces of 1/2^12 of the parameter range.
const PATCH_MAX_DEPTH: u32 = 12;

struct PatchSearch<'a> {
    patch: &'a PatchControl,
    ray: Ray,
    /// Two unit normals of planes whose intersection is the ray's line.
    planes: [DVec3; 2],
    tmin: f64,
    best: Option<Hit>,
    /// Convergence tolerance on the distance from the ray, and box slack.
    tol: f64,
}

impl PatchSearch<'_> {
    fn tmax(&self, tmax: f64) -> f64 {
        self.best.map_or(tmax, |h| h.t)
    }

    fn visit(&mut self, node: &PatchNode, depth: u32, tmax: f64) {
        let (lo, hi) = node.bounds();
        let slack = DVec3::splat(self.tol * 4.0);
        let Some((t_in, _, t_out, _)) = slabs(&self.ray, lo - slack, hi + slack) else {
            return;
        };
        let limit = self.tmax(tmax);
        if t_in >= limit || t_out <= self.tmin {
            return;
        }
        let diag = (hi - lo).length();
        let flat = node.deviation() <= 0.05 * diag;
        if flat || depth == PATCH_MAX_DEPTH {
            self.newton(node, limit);
        }
        if depth < PATCH_MAX_DEPTH {
            let mut kids = node.split();
            // Nearest boxes first, so that later ones are pruned.
            let key = |n: &PatchNode| {
                let (lo, hi) = n.bounds();
                slabs(&self.ray, lo - slack, hi + slack).map_or(f64::INFINITY, |s| s.0)
            };
            kids.sort_by(|a, b| key(a).total_cmp(&key(b)));
            for kid in &kids {
                self.visit(kid, depth + 1, tmax);
            }
        }
    }

    /// Damped Newton (Levenberg–Marquardt) on the distance of `P(u, v)`
    /// from the ray's two planes, started at the node's centre; records a
    /// root inside the node, nearer than `limit`.
    fn newton(&mut self, node: &PatchNode, limit: f64) {
        let (mut u, mut v) = (0.5 * (node.u0 + node.u1), 0.5 * (node.v0 + node.v1));
        let [n1, n2] = self.planes;
        let o = self.ray.origin;
        let margin = 1e-9;
        for _ in 0..60 {
            let (p, pu, pv) = patch_eval(self.patch, u, v);
            let f = [n1.dot(p - o), n2.dot(p - o)];
            if f[0].hypot(f[1]) <= self.tol {
                let inside = u >= node.u0 - margin
                    && u <= node.u1 + margin
                    && v >= node.v0 - margin
                    && v <= node.v1 + margin;
                let (u, v) = (u.clamp(0.0, 1.0), v.clamp(0.0, 1.0));
                let p = patch_eval(self.patch, u, v).0;
                let t = (p - o).dot(self.ray.dir) / self.ray.dir.length_squared();
                if inside && t > self.tmin && t < limit {
                    self.best = Some(Hit {
                        t,
                        normal: patch_normal(self.patch, u, v),
                        u,
                        v,
                    });
                }
                return;
            }
            let j = [[n1.dot(pu), n1.dot(pv)], [n2.dot(pu), n2.dot(pv)]];
            // (JᵀJ + λI) Δ = −Jᵀf
            let a = j[0][0] * j[0][0] + j[1][0] * j[1][0];
            let b = j[0][0] * j[0][1] + j[1][0] * j[1][1];
            let d = j[0][1] * j[0][1] + j[1][1] * j[1][1];
            let lambda = 1e-12 * (a + d) + f64::MIN_POSITIVE;
            let (a, d) = (a + lambda, d + lambda);
            let g0 = j[0][0] * f[0] + j[1][0] * f[1];
            let g1 = j[0][1] * f[0] + j[1][1] * f[1];
            let det = a * d - b * b;
            if !(det > 0.0) || !det.is_finite() {
                return;
            }
            let du = -(d * g0 - b * g1) / det;
            let dv = -(a * g1 - b * g0) / det;
            u += du;
            v += dv;
            // Far outside the node: another node owns that root.
            let (wu, wv) = (node.u1 - node.u0, node.v1 - node.v0);
            if !(u > node.u0 - wu && u < node.u1 + wu && v > node.v0 - wv && v < node.v1 + wv) {
                return;
            }
        }
    }
}

/// Ray–bicubic Bézier patch.
///
/// The patch is subdivided (de Casteljau) into pieces whose control-point
/// boxes the ray meets, nearest first; on each piece that is nearly
/// bilinear, a damped Newton iteration (Levenberg–Marquardt, so that
/// tangent rays converge too) solves for the point of the patch on the
/// ray, and keeps it if it lies in that piece. Pieces are searched down to
/// 1/4096 of the parameter range, pruned by the nearest hit so far, so two
/// close intersections are told apart. Returns `(u, v)` in the [`Hit`].
#[must_use]
pub fn bezier_patch(ray: &Ray, control: &PatchControl, tmin: f64, tmax: f64) -> Option<Hit> {
    let dir = ray.dir.try_normalize()?;
    if !ray.origin.is_finite() || !control.iter().flatten().all(|p| p.is_finite()) {
        return None;
    }
    let (n1, n2) = dir.any_orthonormal_pair();
    let root = PatchNode {
        c: *control,
        u0: 0.0,
        u1: 1.0,
        v0: 0.0,
        v1: 1.0,
    };
    let (lo, hi) = root.bounds();
    let size = (hi - lo).length().max(f64::MIN_POSITIVE);
    let mut search = PatchSearch {
        patch: control,
        ray: *ray,
        planes: [n1, n2],
        tmin,
        best: None,
        tol: 1e-12 * size.max((ray.origin - lo).length()),
    };
    search.visit(&root, 0, tmax);
    search.best
}

#[cfg(test)]
mod tests;
