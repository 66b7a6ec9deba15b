//! Triangles, planar polygons and triangle meshes (flat or with per-vertex
//! normals, NFF `p` and `pp`).
//!
//! ```
//! use rrt_core::fixed::VOXEL;
//! use rrt_core::geometry::Triangle;
//! use rrt_core::raster::Extent;
//! use rrt_core::voxelize::{triangle, Separation, Surfel, VoxelSink};
//!
//! struct Count(u64);
//! impl VoxelSink for Count {
//!     fn offer(&mut self, _: [u32; 3], _: Surfel) { self.0 += 1; }
//! }
//! // A right triangle in the plane z = 4.5 voxels, legs of 10 voxels.
//! let z = 4 * VOXEL + VOXEL / 2;
//! let t = Triangle {
//!     vertices: [[0, 0, z], [10 * VOXEL, 0, z], [0, 10 * VOXEL, z]],
//!     normals: None,
//! };
//! let mut n = Count(0);
//! triangle::triangle(&t, Separation::Six, Extent::cube(16).unwrap(), &mut n).unwrap();
//! // One voxel per column over the triangle (plus its half-voxel rim).
//! assert!(n.0 >= 50 && n.0 <= 80, "{}", n.0);
//! ```
//!
//! # Which voxels
//! A voxel belongs to the triangle when its *probe* meets the (closed)
//! triangle: for [`Separation::TwentySix`] the voxel's closed cube, for
//! [`Separation::Six`] the octahedron inscribed in it (the points within
//! half a voxel of its centre in the L1 norm, vertices at its face centres).
//! For a plane with unit normal `n` both give exactly the thickness rule of
//! [`crate::voxelize`] (`|d| ≤ ½‖n‖∞`, resp. `½‖n‖₁`); near the triangle's
//! edges the probe reaches at most half a voxel beyond them.
//!
//! The probe contains the voxel's centre segments (the lattice steps of half
//! length from its centre), so every discrete ray of the matching
//! connectivity whose voxel-centre polyline meets the triangle visits one
//! of its voxels. The rule depends only on the point set, so a mesh (or any
//! union of voxelized surfaces) is tunnel-free across shared edges and
//! vertices whenever the union of its triangles is closed.
//!
//! # Ties
//! A plane through voxel faces (an axis-aligned face at an integer voxel
//! coordinate, say) touches the probes of the voxels on both sides; the
//! closed rule would take both layers. Instead every voxelizer that goes
//! through here decides ties as if the object were shifted by an
//! infinitesimal `ε = (ε1, ε2, ε3)`, `ε1 ≫ ε2 ≫ ε3 > 0` (simulation of
//! simplicity): a probe meets the shifted object exactly when, on every
//! separating axis `α`, the projections overlap with the bound on the side
//! `α·ε` points to made open. The shifted surface is still closed when the
//! original is, and the lattice-step argument applies to it unchanged, so
//! the result stays tunnel-free while aligned planes get one layer.
//!
//! # Algorithm
//! Separating-axis tests, evaluated scan-line style: the triangle and the
//! probe are disjoint exactly when their projections onto one of a finite
//! set of axes are (13 axes for the cube, 23 for the octahedron, plus the
//! two or four that bound the columns). Columns run along the dominant axis
//! of the normal; each axis with no component along the column bounds the
//! rows and the columns of a row, each other axis bounds the cells of a
//! column. Every bound is an exact floor/ceil division, stepped along a row
//! by an incremental quotient and remainder, without dividing again. The
//! columns whose footprint lies strictly inside the triangle's outline
//! (most of a large triangle's) are bounded by the plane's axis alone: the
//! probe meets the plane there only at points inside the triangle, where
//! every other axis holds with room to spare.
//!
//! # Accepted input and cost
//! Coordinates within [`COORD_LIMIT`](super::error::COORD_LIMIT).
//! Triangles with collinear vertices are refused
//! ([`VoxelizeError::Degenerate`]); [`mesh`] skips and counts them. Work is a
//! constant per row and per column of the clipped projection plus a constant
//! per voxel offered.

use super::error::VoxelizeError;
use super::fixmath::{
    Counter, H, IncDiv, V, ceil_div, centre, centres_within, check_point, checked_cross,
    checked_dot, clip, dist_u32, div_trunc, dot, floor_div, isqrt, low, sub, unit, window,
};
use super::sphere::{pick, place};
use super::{NORMAL_ONE, Separation, Surfel, VoxelSink};
use crate::geometry::{Point, Triangle, UnitVector};
use crate::raster::Extent;

/// Most vertices [`polygon`] accepts.
pub const MAX_POLYGON_VERTICES: usize = 64;

/// Outcome of [`mesh`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct MeshReport {
    /// Offers made (a voxel near a shared edge is offered once per
    /// triangle that reaches it).
    pub offers: u64,
    /// Degenerate (collinear) triangles skipped.
    pub degenerate: u32,
}

/// Voxelizes one triangle, clipped to `extent`. With per-vertex normals the
/// surfel normal is interpolated at the point of the triangle nearest the
/// voxel centre; without, it is the face normal `(v1 − v0) × (v2 − v0)`.
/// Returns the number of offers (each voxel once).
///
/// # Errors
/// [`VoxelizeError::Degenerate`] for collinear vertices,
/// [`VoxelizeError::OutOfRange`] beyond
/// [`COORD_LIMIT`](super::error::COORD_LIMIT).
pub fn triangle<S: VoxelSink + ?Sized>(
    tri: &Triangle,
    separation: Separation,
    extent: Extent,
    sink: &mut S,
) -> Result<u64, VoxelizeError> {
    let t = Tri::new(tri)?;
    let mut n = Counter::default();
    t.scan(separation, extent, sink, &mut n)?;
    Ok(n.0)
}

/// Whether voxel `v` belongs to the voxelized triangle (its probe meets the
/// triangle): the membership rule of [`triangle`], evaluated directly.
///
/// # Errors
/// As [`triangle`].
pub fn contains(
    tri: &Triangle,
    separation: Separation,
    v: [u32; 3],
) -> Result<bool, VoxelizeError> {
    let t = Tri::new(tri)?;
    let c = v.map(centre);
    let mut ok = true;
    t.for_axes(separation, 2, |ax| {
        let p = dot(ax.alpha, c);
        ok &= ax.lo <= p && p <= ax.hi;
    })?;
    Ok(ok)
}

/// Voxelizes a planar polygon given by its vertices in order (either
/// winding; the front side is the counter-clockwise one, as for
/// [`Triangle`]). The polygon is split into triangles by ear clipping in
/// its projection onto the plane of its dominant normal axis, so it may be
/// non-convex but must be simple. Returns the number of offers.
///
/// # Errors
/// [`VoxelizeError::VertexCount`] for fewer than 3 or more than
/// [`MAX_POLYGON_VERTICES`] vertices, [`VoxelizeError::NotSimple`] when no
/// ear can be found, [`VoxelizeError::Degenerate`] for a polygon of zero
/// area, [`VoxelizeError::OutOfRange`] as for [`triangle`].
pub fn polygon<S: VoxelSink + ?Sized>(
    vertices: &[Point],
    separation: Separation,
    extent: Extent,
    sink: &mut S,
) -> Result<u64, VoxelizeError> {
    let m = vertices.len();
    if !(3..=MAX_POLYGON_VERTICES).contains(&m) {
        return Err(VoxelizeError::VertexCount);
    }
    let mut newell = [0i128; 3];
    for (i, v) in vertices.iter().enumerate() {
        let a = check_point(*v)?;
        let b = check_point(
            *vertices
                .get(i.wrapping_add(1).checked_rem(m).unwrap_or(0))
                .unwrap_or(v),
        )?;
        let c = checked_cross(a, b).ok_or(VoxelizeError::Arithmetic)?;
        for (s, x) in newell.iter_mut().zip(c) {
            *s = s.checked_add(x).ok_or(VoxelizeError::Arithmetic)?;
        }
    }
    if newell == [0; 3] {
        return Err(VoxelizeError::Degenerate);
    }
    let k = dominant(newell);
    // Orientation of the projection: positive when the polygon runs
    // counter-clockwise seen from the side its Newell normal points to.
    let flip = pick(k, newell).2 < 0;
    let proj = |i: usize| -> [i128; 2] {
        let p = vertices.get(i).copied().unwrap_or([0; 3]).map(i128::from);
        let (a, b, _) = pick(k, p);
        // pick keeps (a, b, k) right-handed for k = 0 and 2, not for k = 1.
        let b = if (k == 1) != flip {
            b.saturating_neg()
        } else {
            b
        };
        [a, b]
    };
    let mut idx = [0u8; MAX_POLYGON_VERTICES];
    for (i, slot) in idx.iter_mut().enumerate().take(m) {
        *slot = u8::try_from(i).map_err(|_| VoxelizeError::VertexCount)?;
    }
    let mut live = m;
    let mut n = Counter::default();
    let mut emit = |a: u8, b: u8, c: u8, n: &mut Counter| -> Result<(), VoxelizeError> {
        let get = |i: u8| vertices.get(usize::from(i)).copied().unwrap_or([0; 3]);
        let t = Triangle {
            vertices: [get(a), get(b), get(c)],
            normals: None,
        };
        match Tri::new(&t) {
            Ok(t) => t.scan(separation, extent, sink, n),
            Err(VoxelizeError::Degenerate) => Ok(()),
            Err(e) => Err(e),
        }
    };
    // Each pass removes one vertex, so at most m passes of O(m²).
    while live > 3 {
        let at = |i: usize| {
            idx.get(i.checked_rem(live).unwrap_or(0))
                .copied()
                .unwrap_or(0)
        };
        let mut removed = None;
        let mut collinear = None;
        for i in 0..live {
            let (ip, ic, inx) = (
                at(i.wrapping_add(live).wrapping_sub(1)),
                at(i),
                at(i.wrapping_add(1)),
            );
            let (p, c, q) = (
                proj(usize::from(ip)),
                proj(usize::from(ic)),
                proj(usize::from(inx)),
            );
            let turn = orient(p, c, q);
            if turn == 0 {
                collinear.get_or_insert(i);
                continue;
            }
            if turn < 0 {
                continue;
            }
            let blocked = (0..live).any(|j| {
                let o = at(j);
                if o == ip || o == ic || o == inx {
                    return false;
                }
                let r = proj(usize::from(o));
                if r == p || r == c || r == q {
                    return false;
                }
                orient(p, c, r) >= 0 && orient(c, q, r) >= 0 && orient(q, p, r) >= 0
            });
            if !blocked {
                emit(ip, ic, inx, &mut n)?;
                removed = Some(i);
                break;
            }
        }
        let Some(i) = removed.or(collinear) else {
            return Err(VoxelizeError::NotSimple);
        };
        // Remove position i.
        let tail = idx.get_mut(i..live).unwrap_or(&mut []);
        tail.rotate_left(1.min(tail.len()));
        live = live.saturating_sub(1);
    }
    emit(idx[0], idx[1], idx[2], &mut n)?;
    Ok(n.0)
}

/// Voxelizes a triangle mesh: `indices` names three vertices per triangle;
/// `normals`, when given, holds one unit normal per vertex (interpolated as
/// in [`triangle`]). Degenerate triangles are skipped and counted.
///
/// # Errors
/// [`VoxelizeError::IndexOutOfRange`] for an index past `vertices`,
/// [`VoxelizeError::LengthMismatch`] when `normals` and `vertices` differ in
/// length, [`VoxelizeError::OutOfRange`] as for [`triangle`]. Triangles
/// before the failing one have been offered.
pub fn mesh<S: VoxelSink + ?Sized>(
    vertices: &[Point],
    normals: Option<&[UnitVector]>,
    indices: &[[u32; 3]],
    separation: Separation,
    extent: Extent,
    sink: &mut S,
) -> Result<MeshReport, VoxelizeError> {
    if normals.is_some_and(|ns| ns.len() != vertices.len()) {
        return Err(VoxelizeError::LengthMismatch);
    }
    let mut report = MeshReport::default();
    let mut n = Counter::default();
    for (triangle, ids) in indices.iter().enumerate() {
        let fetch = |i: u32| -> Option<usize> {
            let i = usize::try_from(i).ok()?;
            (i < vertices.len()).then_some(i)
        };
        let [a, b, c] = [fetch(ids[0]), fetch(ids[1]), fetch(ids[2])];
        let (Some(a), Some(b), Some(c)) = (a, b, c) else {
            return Err(VoxelizeError::IndexOutOfRange { triangle });
        };
        let v = |i: usize| vertices.get(i).copied().unwrap_or([0; 3]);
        let t = Triangle {
            vertices: [v(a), v(b), v(c)],
            normals: normals.map(|ns| {
                let g = |i: usize| ns.get(i).copied().unwrap_or([0, 0, NORMAL_ONE]);
                [g(a), g(b), g(c)]
            }),
        };
        match Tri::new(&t) {
            Ok(t) => t.scan(separation, extent, sink, &mut n)?,
            Err(VoxelizeError::Degenerate) => {
                report.degenerate = report.degenerate.saturating_add(1);
            }
            Err(e) => return Err(e),
        }
    }
    report.offers = n.0;
    Ok(report)
}

/// The next vertex of a triangle, cyclically.
const NEXT: [usize; 3] = [1, 2, 0];

/// The axis of the largest `|n_k|` (lowest on ties).
fn dominant(n: [i128; 3]) -> usize {
    let a = n.map(i128::unsigned_abs);
    if a[0] >= a[1] && a[0] >= a[2] {
        0
    } else if a[1] >= a[2] {
        1
    } else {
        2
    }
}

/// Twice the signed area of the 2D triangle `p, q, r` (> 0 counter-clockwise).
fn orient(p: [i128; 2], q: [i128; 2], r: [i128; 2]) -> i128 {
    let u = [q[0].saturating_sub(p[0]), q[1].saturating_sub(p[1])];
    let w = [r[0].saturating_sub(p[0]), r[1].saturating_sub(p[1])];
    u[0].saturating_mul(w[1])
        .saturating_sub(u[1].saturating_mul(w[0]))
}

/// `n` shifted right until every component is below `2^31` (the same
/// direction).
fn below_2_31(n: [i128; 3]) -> [i128; 3] {
    let m = n.iter().map(|c| c.unsigned_abs()).max().unwrap_or(0);
    let shift = (128u32.saturating_sub(m.leading_zeros())).saturating_sub(31);
    n.map(|c| c >> shift)
}

/// One separating axis: the probe at centre `c` meets the triangle only if
/// `lo <= alpha·c <= hi`.
#[derive(Clone, Copy, Debug, Default)]
struct Axis {
    alpha: [i128; 3],
    lo: i128,
    hi: i128,
}

/// Most cells a triangle's probes may reach for [`Tri::scan_with`] to
/// test each instead of setting up its rows and columns.
const FEW_CELLS: u64 = 27;

/// What a walk along the columns of a row needs of a column axis
/// `α = (α_a, α_b, α_k)` ([`Tri::columns`]), the same for every row: the
/// divisor `α_k·V`, the probe's reach `α_k·H`, and the per-column steps of
/// the two incremental quotients, `(∓α_a·V) / (α_k·V)`.
#[derive(Clone, Copy, Debug)]
struct ColumnStep {
    d: i128,
    kh: i128,
    /// Step of the upper bound's quotient ([`IncDiv::step_of`] of `−α_a·V`).
    down: (i128, i128),
    /// Step of the lower bound's quotient (of `α_a·V`).
    up: (i128, i128),
}

impl ColumnStep {
    /// `None` when a product overflows or `α_k ≤ 0` (the walk then refuses
    /// the triangle, as it would on its first row).
    fn of(ax: &Axis) -> Option<Self> {
        let [pa, _, pk] = ax.alpha;
        let d = pk.checked_mul(V)?;
        let kh = pk.checked_mul(H)?;
        let dq = pa.checked_mul(V)?;
        Some(Self {
            d,
            kh,
            down: IncDiv::step_of(dq.checked_neg()?, d)?,
            up: IncDiv::step_of(dq, d)?,
        })
    }
}

/// A validated triangle.
pub(crate) struct Tri {
    v: [[i128; 3]; 3],
    /// Edges `v1 − v0, v2 − v1, v0 − v2`.
    e: [[i128; 3]; 3],
    /// `(v1 − v0) × (v2 − v0)`, nonzero.
    n: [i128; 3],
    /// Unit face normal.
    unit: [i32; 3],
    normals: Option<[UnitVector; 3]>,
    /// The barycentric numerators of a point's projection as linear
    /// functions `k + g·c` ([`Tri::barycentric`]).
    bary: [(i128, [i128; 3]); 3],
}

impl Tri {
    fn new(t: &Triangle) -> Result<Self, VoxelizeError> {
        let v = [
            check_point(t.vertices[0])?,
            check_point(t.vertices[1])?,
            check_point(t.vertices[2])?,
        ];
        Self::from_points(v, t.normals)
    }

    /// A triangle from checked points (each within `COORD_LIMIT`).
    pub(crate) fn from_points(
        v: [[i128; 3]; 3],
        normals: Option<[UnitVector; 3]>,
    ) -> Result<Self, VoxelizeError> {
        let e = [sub(v[1], v[0]), sub(v[2], v[1]), sub(v[0], v[2])];
        let n = checked_cross(e[0], sub(v[2], v[0])).ok_or(VoxelizeError::Arithmetic)?;
        if n == [0; 3] {
            return Err(VoxelizeError::Degenerate);
        }
        let n_small = below_2_31(n);
        // (p − c) × (q − c) · n = (p × q) · n + c · (n × (q − p)): the
        // numerator of vertex i, with p, q the other two vertices in order.
        let mut bary = [(0, [0; 3]); 3];
        for (i, b) in bary.iter_mut().enumerate() {
            let (p, q) = (v[NEXT[i]], v[NEXT[NEXT[i]]]);
            let k = checked_cross(p, q).and_then(|x| checked_dot(x, n_small));
            let g = checked_cross(n_small, sub(q, p));
            let (Some(k), Some(g)) = (k, g) else {
                return Err(VoxelizeError::Arithmetic);
            };
            *b = (k, g);
        }
        Ok(Self {
            v,
            e,
            n,
            unit: unit(n).ok_or(VoxelizeError::Degenerate)?,
            normals,
            bary,
        })
    }

    /// Calls `f` with every separating axis of the probe of `sep` against
    /// the triangle, plus the axes bounding the columns along `k`.
    fn for_axes<F: FnMut(Axis)>(
        &self,
        sep: Separation,
        k: usize,
        mut f: F,
    ) -> Result<(), VoxelizeError> {
        let mut add = |alpha: [i128; 3]| -> Result<(), VoxelizeError> {
            if alpha == [0; 3] {
                return Ok(());
            }
            let p = self.v.map(|v| dot(alpha, v));
            let (tmin, tmax) = (p[0].min(p[1]).min(p[2]), p[0].max(p[1]).max(p[2]));
            let a = alpha.map(i128::unsigned_abs);
            let norm = match sep {
                Separation::TwentySix => a[0].saturating_add(a[1]).saturating_add(a[2]),
                Separation::Six => a[0].max(a[1]).max(a[2]),
            };
            let s = i128::try_from(norm)
                .ok()
                .and_then(|x| x.checked_mul(H))
                .ok_or(VoxelizeError::Arithmetic)?;
            let lo = tmin.checked_sub(s).ok_or(VoxelizeError::Arithmetic)?;
            let hi = tmax.checked_add(s).ok_or(VoxelizeError::Arithmetic)?;
            // Tie-break (see "Ties" in the module docs): the triangle is
            // shifted by an infinitesimal ε = (ε1, ε2, ε3), ε1 ≫ ε2 ≫ ε3 > 0,
            // so the bound on the side α·ε points to is open.
            let rising = alpha.iter().find(|c| **c != 0).is_some_and(|c| *c > 0);
            let (lo, hi) = if rising {
                (lo.checked_add(1).ok_or(VoxelizeError::Arithmetic)?, hi)
            } else {
                (lo, hi.checked_sub(1).ok_or(VoxelizeError::Arithmetic)?)
            };
            f(Axis { alpha, lo, hi });
            Ok(())
        };
        add(self.n)?;
        let dirs: &[[i128; 3]] = match sep {
            Separation::TwentySix => &[[1, 0, 0], [0, 1, 0], [0, 0, 1]],
            Separation::Six => &[
                [1, 1, 0],
                [1, -1, 0],
                [1, 0, 1],
                [1, 0, -1],
                [0, 1, 1],
                [0, 1, -1],
            ],
        };
        for e in &self.e {
            for d in dirs {
                add(checked_cross(*e, *d).ok_or(VoxelizeError::Arithmetic)?)?;
            }
            // The column's own 2D bound: e × k̂.
            add(checked_cross(*e, place(k, 0, 0, 1)).ok_or(VoxelizeError::Arithmetic)?)?;
        }
        match sep {
            Separation::TwentySix => {
                for d in dirs {
                    add(*d)?;
                }
            }
            Separation::Six => {
                for d in [[1, 1, 1], [1, 1, -1], [1, -1, 1], [-1, 1, 1]] {
                    add(d)?;
                }
                // The probe's outline seen along k: the diamond's edges.
                add(place(k, 1, 1, 0))?;
                add(place(k, 1, -1, 0))?;
                // And the probe's reach along each axis.
                for d in [[1, 0, 0], [0, 1, 0], [0, 0, 1]] {
                    add(d)?;
                }
            }
        }
        Ok(())
    }

    fn scan<S: VoxelSink + ?Sized>(
        &self,
        sep: Separation,
        extent: Extent,
        sink: &mut S,
        n: &mut Counter,
    ) -> Result<(), VoxelizeError> {
        self.scan_with(sep, extent, sink, n, &|t: &Self, v| t.surfel(v), true)
    }

    /// [`Tri::scan`] with the surfel of each voxel computed by `surfel`
    /// (surfaces tessellated into triangles use their own exact normals).
    /// `plain` says that `surfel` is [`Tri::surfel`], which a flat
    /// triangle across its columns' axis gives without barycentrics in the
    /// columns inside its outline ([`Tri::plane_surfel`]).
    pub(crate) fn scan_with<S, F>(
        &self,
        sep: Separation,
        extent: Extent,
        sink: &mut S,
        n: &mut Counter,
        surfel: &F,
        plain: bool,
    ) -> Result<(), VoxelizeError>
    where
        S: VoxelSink + ?Sized,
        F: Fn(&Self, [u32; 3]) -> Surfel,
    {
        let reads = sink.reads_surfels();
        // Quick reject: the probe reaches at most half a voxel beyond the
        // triangle's bounding box.
        let win = window(extent, sink);
        for (k, (start, end)) in win.iter().enumerate() {
            let lo = self.v.iter().map(|p| p[k]).min().unwrap_or(0);
            let hi = self.v.iter().map(|p| p[k]).max().unwrap_or(0);
            if hi.saturating_add(H) < low(*start) || lo.saturating_sub(H) > low(*end) {
                return Ok(());
            }
        }
        let k = dominant(self.n);
        let (na, nb, nk) = pick(k, win);
        // Axes in (a, b, k) coordinates, split by role.
        let mut rows = [Axis::default(); 32];
        let mut cols = [Axis::default(); 32];
        let (mut nr, mut nc) = (0usize, 0usize);
        self.for_axes(sep, k, |ax| {
            let (a, b, c) = pick(k, ax.alpha);
            let mut ax = Axis {
                alpha: [a, b, c],
                ..ax
            };
            if c < 0 || (c == 0 && a < 0) || (c == 0 && a == 0 && b < 0) {
                ax = Axis {
                    alpha: ax.alpha.map(i128::saturating_neg),
                    lo: ax.hi.saturating_neg(),
                    hi: ax.lo.saturating_neg(),
                };
            }
            let (list, len) = if ax.alpha[2] == 0 {
                (&mut rows, &mut nr)
            } else {
                (&mut cols, &mut nc)
            };
            if let Some(slot) = list.get_mut(*len) {
                *slot = ax;
                *len = len.saturating_add(1);
            }
        })?;
        let rows = rows.get(..nr).unwrap_or(&[]);
        let cols = cols.get(..nc).unwrap_or(&[]);
        // A triangle whose probes reach only a few cells (the tessellation
        // of a thin cylinder, a small disc): each cell's centre against
        // every axis, in the scan's order, instead of the rows' and
        // columns' set-up. The cells are the scan's: those whose centre
        // meets every axis. (Not for a plain flat triangle, whose scan
        // gives the cells inside its outline the plane's surfel.)
        if !(plain && self.normals.is_none())
            && let Some(cells) = self.few_cells(k, win)
        {
            let [(a0, a1), (b0, b1), (k0, k1)] = cells;
            for bi in b0..=b1 {
                for ai in a0..=a1 {
                    for ki in k0..=k1 {
                        let c = [centre(ai), centre(bi), centre(ki)];
                        let inside = rows.iter().chain(cols).all(|ax| {
                            let p = dot(ax.alpha, c);
                            ax.lo <= p && p <= ax.hi
                        });
                        if inside {
                            let v = place(k, ai, bi, ki);
                            let s = if reads { surfel(self, v) } else { Surfel::NONE };
                            sink.offer(v, s);
                            n.bump();
                        }
                    }
                }
            }
            return Ok(());
        }
        // What every row's walk along the columns needs of each column axis.
        let mut steps = [None::<ColumnStep>; 32];
        for (ax, st) in cols.iter().zip(steps.iter_mut()) {
            *st = ColumnStep::of(ax);
        }
        let steps = steps.get(..nc).unwrap_or(&[]);

        // Rows: the b-axis bounds (axes with only a b component).
        let (mut b_lo, mut b_hi) = (i128::MIN, i128::MAX);
        for ax in rows.iter().filter(|ax| ax.alpha[0] == 0) {
            let (l, h) =
                centre_range(ax.alpha[1], 0, ax.lo, ax.hi).ok_or(VoxelizeError::Arithmetic)?;
            b_lo = b_lo.max(l);
            b_hi = b_hi.min(h);
        }
        let Some((b0, b1)) = clip(b_lo, b_hi, nb) else {
            return Ok(());
        };
        let inner = Outline::new(self, k);
        // A voxel of a column inside the outline of a triangle across the
        // columns' axis projects onto the plane inside the triangle.
        let across = {
            let (x, y, _) = pick(k, self.n);
            x == 0 && y == 0
        };
        let plane_surfels = plain && across && self.normals.is_none();
        for bi in b0..=b1 {
            let cb = centre(bi);
            let (mut a_lo, mut a_hi) = (i128::MIN, i128::MAX);
            for ax in rows.iter().filter(|ax| ax.alpha[0] != 0) {
                let q = ax.alpha[1].saturating_mul(cb);
                let (l, h) =
                    centre_range(ax.alpha[0], q, ax.lo, ax.hi).ok_or(VoxelizeError::Arithmetic)?;
                a_lo = a_lo.max(l);
                a_hi = a_hi.min(h);
            }
            let Some((a0, a1)) = clip(a_lo, a_hi, na) else {
                continue;
            };
            // The columns whose footprint lies strictly inside the
            // triangle's outline need the plane's axis only; the others
            // all axes.
            let (i0, i1) = inner
                .as_ref()
                .and_then(|o| o.columns(cb))
                .map_or((1, 0), |(l, h)| {
                    (l.max(i128::from(a0)), h.min(i128::from(a1)))
                });
            let whole = (i128::from(a0), i128::from(a1));
            let (all, plane_only) = (cols.len(), cols.len().min(1));
            let runs = if i0 > i1 {
                [(whole, all), ((1, 0), all), ((1, 0), all)]
            } else {
                [
                    ((whole.0, i0.saturating_sub(1)), all),
                    ((i0, i1), plane_only),
                    ((i1.saturating_add(1), whole.1), all),
                ]
            };
            for (run, ((lo, hi), used)) in runs.into_iter().enumerate() {
                let axes = cols.get(..used).unwrap_or(cols);
                let axis_steps = steps.get(..used).unwrap_or(steps);
                let (Ok(lo), Ok(hi)) = (u32::try_from(lo), u32::try_from(hi)) else {
                    continue;
                };
                if lo > hi {
                    continue;
                }
                let plane = plane_surfels && run == 1;
                self.columns(k, (lo, hi), bi, axes, axis_steps, nk, &mut |v| {
                    let s = match (reads, plane) {
                        (false, _) => Surfel::NONE,
                        (true, true) => self.plane_surfel(v),
                        (true, false) => surfel(self, v),
                    };
                    sink.offer(v, s);
                    n.bump();
                })?;
            }
        }
        Ok(())
    }

    /// The cells, in `(a, b, k)` order of the columns along `k`, whose
    /// centres lie within half a voxel of the triangle's bounding box and
    /// in the window `win`, when there are at most [`FEW_CELLS`] of them
    /// (every cell of the triangle is one: the axis-aligned axes bound each
    /// probe to that box); `None` when there are more. An empty box gives
    /// an empty range (`(1, 0)`) on some axis.
    fn few_cells(&self, k: usize, win: [(u32, u32); 3]) -> Option<[(u32, u32); 3]> {
        let (wa, wb, wk) = pick(k, win);
        let mut out = [(1u32, 0u32); 3];
        let mut count = 1u64;
        for (j, (slot, w)) in out.iter_mut().zip([wa, wb, wk]).enumerate() {
            let axis = match j {
                0 => pick(k, [0, 1, 2]).0,
                1 => pick(k, [0, 1, 2]).1,
                _ => k,
            };
            let lo = self.v.iter().map(|p| p[axis]).min().unwrap_or(0);
            let hi = self.v.iter().map(|p| p[axis]).max().unwrap_or(0);
            let (l, h) = centres_within(lo.saturating_sub(H), hi.saturating_add(H));
            match clip(l, h, w) {
                Some((l, h)) => {
                    *slot = (l, h);
                    count = count.saturating_mul(u64::from(h.saturating_sub(l)).saturating_add(1));
                }
                None => return Some([(1, 0); 3]),
            }
        }
        (count <= FEW_CELLS).then_some(out)
    }

    /// Offers the cells of columns `a0 ..= a1` of row `bi` (along `k`, up
    /// to `nk`) that satisfy every axis of `axes`: per axis,
    /// floor((hi − q − α_k·H) / (α_k·V)) and floor((q + α_k·H − lo) /
    /// (α_k·V)) (= −ceil of the low bound), with q = α_a·c_a + α_b·c_b
    /// stepping by α_a·V per column.
    #[allow(clippy::too_many_arguments)] // one row's context
    fn columns(
        &self,
        k: usize,
        (a0, a1): (u32, u32),
        bi: u32,
        axes: &[Axis],
        steps: &[Option<ColumnStep>],
        nk: (u32, u32),
        offer: &mut impl FnMut([u32; 3]),
    ) -> Result<(), VoxelizeError> {
        let cb = centre(bi);
        let mut his = [None::<IncDiv>; 32];
        let mut los = [None::<IncDiv>; 32];
        let ca0 = centre(a0);
        for (((ax, st), hi), lo) in axes
            .iter()
            .zip(steps)
            .zip(his.iter_mut())
            .zip(los.iter_mut())
        {
            let [pa, pb, _] = ax.alpha;
            let q = pa
                .checked_mul(ca0)
                .and_then(|x| x.checked_add(pb.checked_mul(cb)?));
            let (Some(q), Some(st)) = (q, st) else {
                return Err(VoxelizeError::Arithmetic);
            };
            let nhi = ax.hi.checked_sub(q).and_then(|x| x.checked_sub(st.kh));
            let nlo = q.checked_add(st.kh).and_then(|x| x.checked_sub(ax.lo));
            let (Some(nhi), Some(nlo)) = (nhi, nlo) else {
                return Err(VoxelizeError::Arithmetic);
            };
            *hi = Some(IncDiv::with_step(nhi, st.down, st.d).ok_or(VoxelizeError::Arithmetic)?);
            *lo = Some(IncDiv::with_step(nlo, st.up, st.d).ok_or(VoxelizeError::Arithmetic)?);
        }
        let m = axes.len();
        for ai in a0..=a1 {
            let (mut k_lo, mut k_hi) = (i128::MIN, i128::MAX);
            for (hi, lo) in his.iter_mut().zip(los.iter_mut()).take(m) {
                if let (Some(hi), Some(lo)) = (hi.as_mut(), lo.as_mut()) {
                    k_hi = k_hi.min(hi.q);
                    k_lo = k_lo.max(lo.q.saturating_neg());
                    hi.step();
                    lo.step();
                }
            }
            let Some((k0, k1)) = clip(k_lo, k_hi, nk) else {
                continue;
            };
            for ki in k0..=k1 {
                offer(place(k, ai, bi, ki));
            }
        }
        Ok(())
    }

    /// The surfel of voxel `v` whose centre projects onto the plane inside
    /// the triangle, for a triangle without vertex normals: what
    /// [`Tri::surfel`] gives there.
    fn plane_surfel(&self, v: [u32; 3]) -> Surfel {
        Surfel {
            normal: self.unit,
            distance: dist_u32(self.plane_distance(v.map(centre))),
        }
    }

    /// The distance of point `c` from the plane along the unit normal.
    fn plane_distance(&self, c: [i128; 3]) -> i128 {
        let u = self.unit.map(i128::from);
        dot(u, sub(c, self.v[0])) >> 30
    }

    /// Nearest point data for voxel `v`: distance and normal.
    pub(crate) fn surfel(&self, v: [u32; 3]) -> Surfel {
        let c = v.map(centre);
        let a = self.barycentric(c);
        if a.iter().all(|x| *x >= 0) {
            // Inside: the plane distance along the unit normal.
            let normal = self.interpolate(a).unwrap_or(self.unit);
            return Surfel {
                normal,
                distance: dist_u32(self.plane_distance(c)),
            };
        }
        // Outside: nearest point on an edge opposite a negative weight.
        let mut best: Option<(i128, [i128; 3], usize, i128, i128)> = None;
        for (i, ai) in a.iter().enumerate() {
            if *ai >= 0 {
                continue;
            }
            let p = NEXT.get(i).copied().unwrap_or(0);
            let q = NEXT.get(p).copied().unwrap_or(0);
            let e = sub(self.v[q], self.v[p]);
            let w = sub(c, self.v[p]);
            let num = dot(w, e).max(0);
            let den = dot(e, e).max(1);
            let num = num.min(den);
            let foot = [0, 1, 2].map(|j| {
                self.v[p][j].saturating_add(div_trunc(e[j].saturating_mul(num), den).unwrap_or(0))
            });
            let d = sub(c, foot);
            let d2 = dot(d, d);
            if best.is_none_or(|b| d2 < b.0) {
                best = Some((d2, foot, p, num, den));
            }
        }
        let Some((d2, _, p, num, den)) = best else {
            return Surfel {
                normal: self.unit,
                distance: 0,
            };
        };
        let mut w = [0i128; 3];
        // Weights of the edge's two ends, scaled to den.
        if let Some(slot) = w.get_mut(p) {
            *slot = den.saturating_sub(num);
        }
        if let Some(slot) = w.get_mut(NEXT.get(p).copied().unwrap_or(0)) {
            *slot = num;
        }
        Surfel {
            normal: self.interpolate(w).unwrap_or(self.unit),
            distance: dist_u32(isqrt(d2)),
        }
    }

    /// The barycentric numerators of the projection of point `c` onto the
    /// plane: `(v_j − c) × (v_k − c) · n` for vertex `i` and the other two
    /// vertices `j, k` in order, scaled by `n` shifted below `2^31`. For a
    /// voxel centre of any raster (below `2^32` per axis) and vertices
    /// within `COORD_LIMIT` no term saturates, so the linear form is exact.
    fn barycentric(&self, c: [i128; 3]) -> [i128; 3] {
        self.bary.map(|(k, g)| k.saturating_add(dot(g, c)))
    }

    /// Normal interpolated with non-negative weights `w` (any common scale).
    fn interpolate(&self, w: [i128; 3]) -> Option<[i32; 3]> {
        let ns = self.normals?;
        let m = w.iter().map(|x| x.unsigned_abs()).max().unwrap_or(0);
        let shift = (128u32.saturating_sub(m.leading_zeros())).saturating_sub(60);
        let w = w.map(|x| x >> shift);
        let mut s = [0i128; 3];
        for (wi, ni) in w.iter().zip(ns) {
            for (sj, nj) in s.iter_mut().zip(ni) {
                // |wi| < 2^60, |nj| ≤ 2^30: products < 2^90, sums < 2^92.
                *sj = sj.saturating_add(wi.saturating_mul(i128::from(nj)));
            }
        }
        unit(s)
    }
}

/// The triangle's outline seen along the column axis: per edge `e`, the
/// components `(α_a, α_b)` of the axis `e × k̂` and the triangle's extent
/// `[tmin, tmax]` along it. A column whose footprint (the square of side
/// `V` about its centre in `(a, b)`) lies strictly inside the outline
/// holds the triangle's cells exactly where the probe meets the plane:
/// the probe meets the plane only above its footprint, so at points inside
/// the triangle, and every other separating axis holds there with room to
/// spare (no tie), or is parallel to the normal and says what it says.
struct Outline {
    edges: [(i128, i128, i128, i128); 3],
}

impl Outline {
    /// `None` where the arithmetic would not fit (no column is then
    /// taken as inside).
    fn new(t: &Tri, k: usize) -> Option<Self> {
        let kk = place(k, 0, 0, 1);
        let mut edges = [(0, 0, 0, 0); 3];
        for (slot, e) in edges.iter_mut().zip(&t.e) {
            let alpha = checked_cross(*e, kk)?;
            let mut p = [0i128; 3];
            for (pi, v) in p.iter_mut().zip(&t.v) {
                *pi = checked_dot(alpha, *v)?;
            }
            let (pa, pb, _) = pick(k, alpha);
            *slot = (pa, pb, p[0].min(p[1]).min(p[2]), p[0].max(p[1]).max(p[2]));
        }
        Some(Self { edges })
    }

    /// The columns `lo ..= hi` of the row with centre coordinate `cb`
    /// whose footprint lies strictly inside the outline; `None` when there
    /// are none (or the arithmetic would not fit).
    fn columns(&self, cb: i128) -> Option<(i128, i128)> {
        let (mut lo, mut hi) = (i128::MIN, i128::MAX);
        for &(pa, pb, tmin, tmax) in &self.edges {
            // The footprint's reach along the axis.
            let r = i128::try_from(pa.unsigned_abs().checked_add(pb.unsigned_abs())?)
                .ok()?
                .checked_mul(H)?;
            let q = pb.checked_mul(cb)?;
            // tmin < α_a·c_a + q − r and α_a·c_a + q + r < tmax.
            let l = tmin.checked_add(r)?.checked_sub(q)?;
            let h = tmax.checked_sub(r)?.checked_sub(q)?;
            if pa == 0 {
                if l < 0 && 0 < h {
                    continue;
                }
                return None;
            }
            let (p, l, h) = if pa > 0 {
                (pa, l, h)
            } else {
                (pa.checked_neg()?, h.checked_neg()?, l.checked_neg()?)
            };
            // l < p·(iV + H) < h.
            let (d, ph) = (p.checked_mul(V)?, p.checked_mul(H)?);
            let i_lo = floor_div(l.checked_sub(ph)?, d)?.checked_add(1)?;
            let i_hi = ceil_div(h.checked_sub(ph)?, d)?.checked_sub(1)?;
            lo = lo.max(i_lo);
            hi = hi.min(i_hi);
        }
        (lo <= hi).then_some((lo, hi))
    }
}

/// Cell range `i` with centre `c = iV + H` satisfying `lo ≤ p·c + q ≤ hi`
/// (`p > 0`).
fn centre_range(p: i128, q: i128, lo: i128, hi: i128) -> Option<(i128, i128)> {
    let d = p.checked_mul(V)?;
    let ph = p.checked_mul(H)?;
    let l = ceil_div(lo.checked_sub(q)?.checked_sub(ph)?, d)?;
    let h = floor_div(hi.checked_sub(q)?.checked_sub(ph)?, d)?;
    Some((l, h))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testkit::{Offers, Rng, assert_offers_are, voxelized};
    use std::format;
    use std::vec::Vec;

    #[test]
    fn few_cells_and_scan_offer_the_members_in_scan_order() {
        // Every offer in order.
        struct Seq(Vec<[u32; 3]>);
        impl VoxelSink for Seq {
            fn offer(&mut self, v: [u32; 3], _: Surfel) {
                self.0.push(v);
            }
        }
        let e = Extent::new(9, 10, 11).unwrap();
        let mut rng = Rng(0xfe_ce11);
        let mut few = 0;
        for case in 0..400 {
            // Small triangles (a few cells) and large ones.
            let reach = if case % 2 == 0 { 2 * 65536 } else { 9 * 65536 };
            let base = [0; 3].map(|_| rng.range(-65536, 9 * 65536));
            let vs = [0; 3].map(|_| base.map(|b| b + rng.range(0, reach)));
            let t = Triangle {
                vertices: vs,
                normals: None,
            };
            let Ok(tri) = Tri::new(&t) else {
                continue;
            };
            let k = dominant(tri.n);
            for sep in [Separation::Six, Separation::TwentySix] {
                let mut got = Seq(Vec::new());
                let mut n = Counter::default();
                tri.scan_with(sep, e, &mut got, &mut n, &|t: &Tri, v| t.surfel(v), false)
                    .unwrap();
                let win = window(e, &got);
                few += usize::from(tri.few_cells(k, win).is_some());
                let (na, nb, nk) = pick(k, [e.dims()[0], e.dims()[1], e.dims()[2]]);
                let mut want = Vec::new();
                for bi in 0..nb {
                    for ai in 0..na {
                        for ki in 0..nk {
                            let v = place(k, ai, bi, ki);
                            if contains(&t, sep, v).unwrap() {
                                want.push(v);
                            }
                        }
                    }
                }
                assert_eq!(got.0, want, "case {case} {sep:?} {t:?}");
                assert_eq!(n.0, want.len() as u64);
            }
        }
        assert!(few > 100, "{few} triangles took the few cells' path");
    }

    #[test]
    fn scan_matches_membership() {
        let e = Extent::new(12, 11, 10).unwrap();
        let mut rng = Rng(3);
        for case in 0..150 {
            let mut vs = [[0i64; 3]; 3];
            for v in &mut vs {
                for c in v.iter_mut() {
                    let x = rng.range(0, 14 * 65536 - 1) - 65536;
                    *c = match case % 4 {
                        0 => x & !0x7fff,
                        1 => x & !0xffff,
                        _ => x,
                    };
                }
            }
            if case % 5 == 0 {
                // Axis-aligned: all on one plane.
                let z = vs[0][2];
                for v in &mut vs {
                    v[2] = z;
                }
            }
            let t = Triangle {
                vertices: vs,
                normals: None,
            };
            if Tri::new(&t).is_err() {
                continue;
            }
            for sep in [Separation::Six, Separation::TwentySix] {
                let (r, c) = voxelized(triangle, &t, sep, e);
                r.unwrap();
                let inside = |v| contains(&t, sep, v).unwrap();
                assert_offers_are(&c, e, inside, &format!("case {case} {sep:?} {t:?}"));
                // The columns inside the outline give Tri::surfel's surfels.
                let tri = Tri::new(&t).unwrap();
                for (v, (s, _)) in &c.0 {
                    assert_eq!(*s, tri.surfel(*v), "case {case} {sep:?} {v:?}");
                }
            }
        }
    }

    #[test]
    fn plane_thickness_is_the_rule() {
        // A large triangle: away from its edges, a voxel belongs to it
        // exactly when |d| ≤ ½‖n̂‖ (∞-norm for Six, 1-norm for TwentySix),
        // i.e. |n·(c − v0)| ≤ ½·‖n‖·V in exact integers.
        let v = 65536i64;
        let t = Triangle {
            vertices: [
                [-40 * v, -40 * v, 3 * v + 123],
                [80 * v, -30 * v, 9 * v + 7],
                [-30 * v, 80 * v, 14 * v],
            ],
            normals: None,
        };
        let tr = Tri::new(&t).unwrap();
        let n = tr.n;
        let a = n.map(i128::abs);
        for (sep, norm) in [
            (Separation::Six, a[0].max(a[1]).max(a[2])),
            (Separation::TwentySix, a[0] + a[1] + a[2]),
        ] {
            for x in 5..15u32 {
                for y in 5..15u32 {
                    for z in 0..24u32 {
                        let c = [x, y, z].map(centre);
                        let d = dot(n, sub(c, tr.v[0]));
                        if 2 * d.abs() == norm * V {
                            continue; // a tie: decided by the perturbation
                        }
                        let rule = 2 * d.abs() <= norm * V;
                        assert_eq!(
                            contains(&t, sep, [x, y, z]).unwrap(),
                            rule,
                            "{sep:?} {x} {y} {z}"
                        );
                    }
                }
            }
        }
    }

    #[test]
    fn polygon_and_mesh() {
        let v = 65536i64;
        // An L-shaped (non-convex) polygon in z = 2.5.
        let z = 2 * v + v / 2;
        let l = [
            [v, v, z],
            [9 * v, v, z],
            [9 * v, 4 * v, z],
            [4 * v, 4 * v, z],
            [4 * v, 9 * v, z],
            [v, 9 * v, z],
        ];
        let e = Extent::cube(12).unwrap();
        let mut c = Offers::default();
        polygon(&l, Separation::Six, e, &mut c).unwrap();
        // The notch (6..8, 6..8) stays empty; the arms are covered.
        assert!(!c.0.contains_key(&[6, 6, 2]));
        assert!(c.0.contains_key(&[2, 7, 2]) && c.0.contains_key(&[7, 2, 2]));
        let mut rev = l;
        rev.reverse();
        let mut c2 = Offers::default();
        polygon(&rev, Separation::Six, e, &mut c2).unwrap();
        let mut a: Vec<_> = c.0.keys().collect();
        let mut b: Vec<_> = c2.0.keys().collect();
        a.sort();
        b.sort();
        assert_eq!(a, b);
        assert_eq!(
            polygon(&l[..2], Separation::Six, e, &mut c),
            Err(VoxelizeError::VertexCount)
        );
        // A symmetric bow tie has no area; an asymmetric one is not simple:
        // refused or split into some triangles, never a panic.
        let bow = [[v, v, z], [5 * v, 5 * v, z], [5 * v, v, z], [v, 5 * v, z]];
        assert_eq!(
            polygon(&bow, Separation::Six, e, &mut c),
            Err(VoxelizeError::Degenerate)
        );
        let bow = [[v, v, z], [7 * v, 5 * v, z], [7 * v, v, z], [v, 3 * v, z]];
        let r = polygon(&bow, Separation::Six, e, &mut c);
        assert!(matches!(r, Ok(_) | Err(VoxelizeError::NotSimple)), "{r:?}");

        let verts = [[v, v, z], [5 * v, v, z], [v, 5 * v, z], [3 * v, 3 * v, z]];
        let r = mesh(
            &verts,
            None,
            &[[0, 1, 2], [0, 1, 3]],
            Separation::Six,
            e,
            &mut c,
        )
        .unwrap();
        assert_eq!(r.degenerate, 0);
        let r = mesh(&verts, None, &[[0, 0, 2]], Separation::Six, e, &mut c).unwrap();
        assert_eq!(r.degenerate, 1);
        assert_eq!(
            mesh(&verts, None, &[[0, 1, 9]], Separation::Six, e, &mut c),
            Err(VoxelizeError::IndexOutOfRange { triangle: 0 })
        );
    }

    #[test]
    fn barycentric_is_the_cross_product() {
        let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
        let mut compared = 0;
        for _ in 0..2000 {
            let mut coord = |scale: u64| {
                let r = rng.next_u64();
                let m = (r >> 1) % scale;
                if r & 1 == 0 { m as i128 } else { -(m as i128) }
            };
            let big = if compared % 2 == 0 { 1 << 20 } else { 1 << 40 };
            let v: [[i128; 3]; 3] = core::array::from_fn(|_| core::array::from_fn(|_| coord(big)));
            let Ok(t) = Tri::from_points(v, None) else {
                continue;
            };
            for _ in 0..8 {
                let c: [i128; 3] = core::array::from_fn(|_| {
                    centre(u32::try_from(coord(1 << 16).unsigned_abs()).unwrap())
                });
                let direct = [0, 1, 2].map(|i| {
                    let p = sub(v[NEXT[i]], c);
                    let q = sub(v[NEXT[NEXT[i]]], c);
                    checked_dot(checked_cross(p, q).unwrap(), below_2_31(t.n)).unwrap()
                });
                assert_eq!(t.barycentric(c), direct, "{v:?} {c:?}");
                compared += 1;
            }
        }
        assert!(compared > 10_000, "{compared}");
    }

    #[test]
    fn surfel_normals() {
        let v = 65536i64;
        let one = NORMAL_ONE;
        let t = Triangle {
            vertices: [[0, 0, 2 * v], [8 * v, 0, 2 * v], [0, 8 * v, 2 * v]],
            normals: Some([[0, 0, one], [one, 0, 0], [0, one, 0]]),
        };
        let tr = Tri::new(&t).unwrap();
        // Near v0 the normal is near v0's.
        let s = tr.surfel([0, 0, 2]);
        assert!(s.normal[2] > one / 2, "{s:?}");
        assert_eq!(s.distance, (v / 2) as u32);
        // Near v1 (x = 7.5) mostly +x.
        let s = tr.surfel([7, 0, 2]);
        assert!(s.normal[0] > s.normal[2], "{s:?}");
        // Outside beyond the hypotenuse: distance to the edge.
        let s = tr.surfel([6, 6, 2]);
        assert!(s.distance > 0);
        let flat = Tri::new(&Triangle { normals: None, ..t }).unwrap();
        assert_eq!(flat.surfel([1, 1, 5]).normal, [0, 0, one]);
    }
}
