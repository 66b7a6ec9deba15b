//! Constructive solid geometry by voxel Booleans (the paper's *voxblt*).
//!
//! A [`CsgTree`] combines [`Solid`]s with union, intersection and
//! difference, voxel by voxel: each voxel centre is classified against the
//! tree, and the result's **boundary layer**, the voxels inside the result
//! with at least one of their 26 neighbours outside it, is handed to a
//! [`CsgSink`] (the scene builder through [`LeafFill`], or any
//! [`VoxelSink`] through [`IgnoreLeaf`]). Any discrete ray, even a
//! 26-connected one, that goes from a voxel outside the result to one inside
//! steps from a voxel to one of its 26 neighbours, so it enters through the
//! boundary layer: the result is 26-tunnel-free for rays from outside.
//!
//! # Evaluation
//! Each [`Solid`] gives, at a point, a signed distance (negative inside)
//! and the unit outward normal of the nearest surface point. The tree
//! combines them as usual for distance fields: union takes the smaller
//! distance, intersection the larger, and `A − B` is `max(d_A, −d_B)`. The
//! operand whose value is taken *decides*: its normal (negated when it
//! comes through the subtracted side of a difference) and its leaf, so the
//! result's surface voxels carry the attributes of the solid that forms
//! that part of the boundary (the cut face of a sphere minus a box has the
//! box's attributes and the box's normal flipped).
//!
//! # Trees without a heap
//! The caller provides the nodes in a slice: a node's children must have
//! smaller indices than the node itself, and the last node is the root.
//! That order rules out cycles by construction; [`CsgTree::new`] checks it,
//! the leaf indices and the leaves' bounds, and evaluation needs only a
//! fixed array of [`MAX_NODES`] values on the stack.
//!
//! # Cost
//! One tree evaluation per voxel of the tree's bounding box (clipped to the
//! raster), plus 26 per voxel less than two voxels inside the surface (the
//! only ones that can have an outside neighbour when distances are
//! 1-Lipschitz, as [`Solid`] requires). Solids are volumes, so this is
//! linear in the volume of the box, as the paper's voxblt is.

use core::fmt;
use core::ops::Range;

use crate::fixed::{HALF_VOXEL, VOXEL, voxel_centre};
use crate::geometry::{Cone, Cuboid, Point, Sphere, Torus, UnitVector};
use crate::raster::Extent;
use crate::store::{BuildError, Filler, ObjectAttrs};
use crate::voxel::normalize;
use crate::voxelize::{NORMAL_ONE, Surfel, VoxelSink};

/// Most nodes a [`CsgTree`] may have.
pub const MAX_NODES: usize = 64;

/// A solid's answer at one point.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct SolidSample {
    /// Signed distance to the surface in fixed units, negative inside (a
    /// 1-Lipschitz lower bound of the true distance is enough).
    pub distance: i64,
    /// Unit outward normal ([`NORMAL_ONE`]-scaled) of the surface point
    /// nearest the query point.
    pub normal: UnitVector,
}

/// A solid that CSG can combine: a signed distance field with normals.
///
/// Contract: `sample(p).distance` is negative inside, positive outside,
/// and 1-Lipschitz (`|d(p) − d(q)| ≤ |p − q|`); every point with `d ≤ 0`
/// lies inside [`Solid::bounds`]. A sampled volume implements it with the
/// classification threshold as the zero level (distance estimated from the
/// gray level, scaled so the Lipschitz bound holds) and the normal from the
/// gray-level gradient, as the paper's 3×3×3 gradient does.
pub trait Solid {
    /// The signed distance and normal at `p` (fixed units), or `None` where
    /// the solid cannot say (treated as far outside).
    fn sample(&self, p: Point) -> Option<SolidSample>;
    /// The box `(min, max)` holding the solid, or `None` for a degenerate
    /// (empty) solid: zero or negative radius, an inverted box.
    fn bounds(&self) -> Option<(Point, Point)>;
}

const UP: UnitVector = [0, 0, NORMAL_ONE];

fn sub(a: Point, b: Point) -> [i64; 3] {
    [
        a[0].saturating_sub(b[0]),
        a[1].saturating_sub(b[1]),
        a[2].saturating_sub(b[2]),
    ]
}

/// Euclidean length in fixed units (saturating).
fn length(v: [i64; 3]) -> i64 {
    let s = v
        .iter()
        .map(|c| u128::from(c.unsigned_abs()).saturating_mul(u128::from(c.unsigned_abs())))
        .fold(0u128, u128::saturating_add);
    i64::try_from(s.isqrt()).unwrap_or(i64::MAX)
}

/// `v · u` for a unit `u`, in `v`'s units.
fn dot_unit_len(v: [i64; 3], u: UnitVector) -> i64 {
    let s = v
        .iter()
        .zip(u.iter())
        .map(|(a, b)| i128::from(*a).saturating_mul(i128::from(*b)))
        .fold(0i128, i128::saturating_add);
    i64::try_from(s >> 30).unwrap_or(if s < 0 { i64::MIN } else { i64::MAX })
}

/// `u · s` for a unit `u` and a length `s`.
fn scale_unit(u: UnitVector, s: i64) -> [i64; 3] {
    u.map(|c| {
        let p = i128::from(c).saturating_mul(i128::from(s)) >> 30;
        i64::try_from(p).unwrap_or(if p < 0 { i64::MIN } else { i64::MAX })
    })
}

fn widen(lo: Point, hi: Point, r: i64) -> (Point, Point) {
    (
        lo.map(|c| c.saturating_sub(r)),
        hi.map(|c| c.saturating_add(r)),
    )
}

impl Solid for Sphere {
    fn sample(&self, p: Point) -> Option<SolidSample> {
        let d = sub(p, self.centre);
        Some(SolidSample {
            distance: length(d).saturating_sub(self.radius),
            normal: normalize(d).unwrap_or(UP),
        })
    }
    fn bounds(&self) -> Option<(Point, Point)> {
        (self.radius > 0).then(|| widen(self.centre, self.centre, self.radius))
    }
}

impl Solid for Cuboid {
    fn sample(&self, p: Point) -> Option<SolidSample> {
        // Per axis: how far outside the slab (negative inside), and which
        // face is nearer.
        let mut q = [0i64; 3];
        let mut sign = [1i64; 3];
        for k in 0..3 {
            let (pk, lo, hi) = (
                p.get(k).copied()?,
                self.min.get(k).copied()?,
                self.max.get(k).copied()?,
            );
            let below = lo.saturating_sub(pk);
            let above = pk.saturating_sub(hi);
            let (slot, s) = (q.get_mut(k)?, sign.get_mut(k)?);
            if below > above {
                *slot = below;
                *s = -1;
            } else {
                *slot = above;
            }
        }
        if q.iter().any(|c| *c > 0) {
            let out: [i64; 3] = core::array::from_fn(|k| {
                q.get(k)
                    .copied()
                    .unwrap_or(0)
                    .max(0)
                    .saturating_mul(sign.get(k).copied().unwrap_or(1))
            });
            Some(SolidSample {
                distance: length(out),
                normal: normalize(out).unwrap_or(UP),
            })
        } else {
            let (k, m) = q
                .iter()
                .copied()
                .enumerate()
                .max_by_key(|&(_, v)| v)
                .unwrap_or((2, 0));
            let mut normal = [0i32; 3];
            if let Some(n) = normal.get_mut(k) {
                *n = if sign.get(k).copied().unwrap_or(1) < 0 {
                    NORMAL_ONE.wrapping_neg()
                } else {
                    NORMAL_ONE
                };
            }
            Some(SolidSample {
                distance: m,
                normal,
            })
        }
    }
    fn bounds(&self) -> Option<(Point, Point)> {
        self.min
            .iter()
            .zip(self.max.iter())
            .all(|(a, b)| a < b)
            .then_some((self.min, self.max))
    }
}

impl Solid for Torus {
    fn sample(&self, p: Point) -> Option<SolidSample> {
        let d = sub(p, self.centre);
        let h = dot_unit_len(d, self.axis);
        let radial = sub(d, scale_unit(self.axis, h));
        // The nearest point of the tube's centre circle.
        let k = match normalize(radial) {
            Some(u) => scale_unit(u, self.major),
            // On the axis: every circle point is equally near; pick one.
            None => [self.major, 0, 0],
        };
        let q = sub(d, k);
        Some(SolidSample {
            distance: length(q).saturating_sub(self.minor),
            normal: normalize(q).unwrap_or(self.axis),
        })
    }
    fn bounds(&self) -> Option<(Point, Point)> {
        (self.minor > 0 && self.major >= 0 && normalize(self.axis.map(i64::from)).is_some()).then(
            || {
                widen(
                    self.centre,
                    self.centre,
                    self.major.saturating_add(self.minor),
                )
            },
        )
    }
}

/// A [`Cone`] as a solid is the capped cone (or cylinder) it bounds: the
/// open surface of NFF `c` closed by the base and apex discs.
impl Solid for Cone {
    fn sample(&self, p: Point) -> Option<SolidSample> {
        let axis = sub(self.apex, self.base);
        let h = length(axis);
        let a = normalize(axis)?;
        let d = sub(p, self.base);
        let s = dot_unit_len(d, a);
        let w = sub(d, scale_unit(a, s));
        let r = length(w);
        let (rb, ra) = (self.base_radius, self.apex_radius);
        let dr = ra.saturating_sub(rb);
        let l = length([h, dr, 0]);
        if l == 0 {
            return None;
        }
        // Radius at s, in i128: rb + dr·s/h.
        let radius_at = i128::from(rb).saturating_add(
            i128::from(dr)
                .saturating_mul(i128::from(s))
                .checked_div(i128::from(h))
                .unwrap_or(0),
        );
        // Side distance (r − R(s))·h/L, 1-Lipschitz.
        let side = i128::from(r)
            .saturating_sub(radius_at)
            .saturating_mul(i128::from(h))
            .checked_div(i128::from(l))
            .unwrap_or(0);
        let side = i64::try_from(side).unwrap_or(i64::MAX);
        let bottom = s.saturating_neg();
        let top = s.saturating_sub(h);
        let neg_a = a.map(i32::wrapping_neg);
        let (distance, normal) = if side >= bottom && side >= top {
            // Outward side normal (r̂·h − â·dr)/L.
            let n = match normalize(w) {
                Some(rh) => {
                    let v: [i64; 3] = core::array::from_fn(|k| {
                        let rk = i128::from(rh.get(k).copied().unwrap_or(0));
                        let ak = i128::from(a.get(k).copied().unwrap_or(0));
                        let x = rk
                            .saturating_mul(i128::from(h))
                            .saturating_sub(ak.saturating_mul(i128::from(dr)))
                            .checked_div(i128::from(l))
                            .unwrap_or(0);
                        i64::try_from(x).unwrap_or(0)
                    });
                    normalize(v).unwrap_or(a)
                }
                None => a,
            };
            (side, n)
        } else if bottom >= top {
            (bottom, neg_a)
        } else {
            (top, a)
        };
        Some(SolidSample { distance, normal })
    }
    fn bounds(&self) -> Option<(Point, Point)> {
        if self.base_radius < 0 || self.apex_radius < 0 || self.base == self.apex {
            return None;
        }
        if self.base_radius == 0 && self.apex_radius == 0 {
            return None;
        }
        let lo = per_axis(self.base, self.apex, i64::min);
        let hi = per_axis(self.base, self.apex, i64::max);
        Some(widen(lo, hi, self.base_radius.max(self.apex_radius)))
    }
}

/// One node of a [`CsgTree`]; children are node indices, smaller than the
/// node's own.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum CsgNode {
    /// A solid: index into the tree's leaves.
    Leaf(u16),
    /// Points in either child.
    Union(u16, u16),
    /// Points in both children.
    Intersection(u16, u16),
    /// Points in the first child and not in the second.
    Difference(u16, u16),
}

/// Why a tree was refused.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum CsgError {
    /// No node.
    Empty,
    /// More than [`MAX_NODES`] nodes.
    TooManyNodes,
    /// A child index is not smaller than its node's (out of range, a cycle,
    /// or a forward reference).
    ChildOrder {
        /// The node.
        node: usize,
    },
    /// A leaf index is past the leaves slice.
    LeafOutOfRange {
        /// The node.
        node: usize,
    },
    /// A leaf solid is degenerate (no bounds: zero or negative radius,
    /// inverted box).
    Degenerate {
        /// The leaf index.
        leaf: u16,
    },
}

impl fmt::Display for CsgError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            Self::Empty => f.write_str("CSG tree has no node"),
            Self::TooManyNodes => write!(f, "CSG tree has more than {MAX_NODES} nodes"),
            Self::ChildOrder { node } => write!(
                f,
                "CSG node {node} refers to a child that is not an earlier node"
            ),
            Self::LeafOutOfRange { node } => {
                write!(f, "CSG node {node} refers to a missing leaf")
            }
            Self::Degenerate { leaf } => write!(f, "CSG leaf {leaf} is a degenerate solid"),
        }
    }
}

impl core::error::Error for CsgError {}

/// A validated CSG tree over caller-provided nodes and solids.
///
/// ```
/// use rrt_core::csg::{CsgNode, CsgTree, Solid};
/// use rrt_core::geometry::{Cuboid, Sphere};
/// let v = 1i64 << 16;
/// let ball = Sphere { centre: [8 * v; 3], radius: 6 * v };
/// let cut = Cuboid { min: [8 * v, 0, 0], max: [16 * v; 3] };
/// let leaves: [&dyn Solid; 2] = [&ball, &cut];
/// let nodes = [CsgNode::Leaf(0), CsgNode::Leaf(1), CsgNode::Difference(0, 1)];
/// let tree = CsgTree::new(&nodes, &leaves).unwrap();
/// assert!(tree.contains([4 * v, 8 * v, 8 * v]));
/// assert!(!tree.contains([12 * v, 8 * v, 8 * v]));
/// // A cycle (a node referring to itself) is refused.
/// assert!(CsgTree::new(&[CsgNode::Union(0, 0)], &leaves).is_err());
/// ```
#[derive(Clone, Copy)]
pub struct CsgTree<'a> {
    /// Invariant: 1..=MAX_NODES nodes, children before parents, leaf
    /// indices valid, every leaf has bounds.
    nodes: &'a [CsgNode],
    leaves: &'a [&'a dyn Solid],
}

impl fmt::Debug for CsgTree<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("CsgTree")
            .field("nodes", &self.nodes)
            .field("leaves", &self.leaves.len())
            .finish()
    }
}

/// The tree's value at a point: distance, normal and deciding leaf.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct CsgSample {
    /// Signed distance (negative inside the result).
    pub distance: i64,
    /// Outward unit normal of the result's surface, from the deciding leaf
    /// (negated through subtracted operands).
    pub normal: UnitVector,
    /// The deciding leaf.
    pub leaf: u16,
}

const FAR: CsgSample = CsgSample {
    distance: i64::MAX,
    normal: UP,
    leaf: 0,
};

impl<'a> CsgTree<'a> {
    /// Validates `nodes` (root last) over `leaves`.
    ///
    /// # Errors
    /// A [`CsgError`] naming the first problem.
    pub fn new(nodes: &'a [CsgNode], leaves: &'a [&'a dyn Solid]) -> Result<Self, CsgError> {
        if nodes.is_empty() {
            return Err(CsgError::Empty);
        }
        if nodes.len() > MAX_NODES {
            return Err(CsgError::TooManyNodes);
        }
        for (node, n) in nodes.iter().enumerate() {
            match *n {
                CsgNode::Leaf(l) => {
                    let solid = leaves
                        .get(usize::from(l))
                        .ok_or(CsgError::LeafOutOfRange { node })?;
                    if solid.bounds().is_none() {
                        return Err(CsgError::Degenerate { leaf: l });
                    }
                }
                CsgNode::Union(a, b) | CsgNode::Intersection(a, b) | CsgNode::Difference(a, b) => {
                    if usize::from(a) >= node || usize::from(b) >= node {
                        return Err(CsgError::ChildOrder { node });
                    }
                }
            }
        }
        Ok(Self { nodes, leaves })
    }

    /// The tree's value at `p`.
    #[must_use]
    pub fn sample(&self, p: Point) -> CsgSample {
        let mut vals = [FAR; MAX_NODES];
        for (i, n) in self.nodes.iter().enumerate() {
            let get = |k: u16| vals.get(usize::from(k)).copied().unwrap_or(FAR);
            let v = match *n {
                CsgNode::Leaf(l) => self
                    .leaves
                    .get(usize::from(l))
                    .and_then(|s| s.sample(p))
                    .map_or(FAR, |s| CsgSample {
                        distance: s.distance,
                        normal: s.normal,
                        leaf: l,
                    }),
                CsgNode::Union(a, b) => {
                    let (a, b) = (get(a), get(b));
                    if b.distance < a.distance { b } else { a }
                }
                CsgNode::Intersection(a, b) => {
                    let (a, b) = (get(a), get(b));
                    if b.distance > a.distance { b } else { a }
                }
                CsgNode::Difference(a, b) => {
                    let (a, b) = (get(a), get(b));
                    let nb = b.distance.saturating_neg();
                    if nb > a.distance {
                        CsgSample {
                            distance: nb,
                            normal: b.normal.map(i32::wrapping_neg),
                            leaf: b.leaf,
                        }
                    } else {
                        a
                    }
                }
            };
            if let Some(slot) = vals.get_mut(i) {
                *slot = v;
            }
        }
        self.nodes
            .len()
            .checked_sub(1)
            .and_then(|r| vals.get(r).copied())
            .unwrap_or(FAR)
    }

    /// Whether `p` lies in the result (distance ≤ 0).
    #[must_use]
    pub fn contains(&self, p: Point) -> bool {
        self.sample(p).distance <= 0
    }

    /// A box holding the result, or `None` if it is provably empty (an
    /// intersection of disjoint boxes).
    #[must_use]
    pub fn bounds(&self) -> Option<(Point, Point)> {
        let mut b: [Option<(Point, Point)>; MAX_NODES] = [None; MAX_NODES];
        for (i, n) in self.nodes.iter().enumerate() {
            let get = |k: u16| b.get(usize::from(k)).copied().flatten();
            let v = match *n {
                CsgNode::Leaf(l) => self.leaves.get(usize::from(l)).and_then(|s| s.bounds()),
                CsgNode::Union(x, y) => match (get(x), get(y)) {
                    (Some(p), Some(q)) => Some(hull(p, q)),
                    (p, q) => p.or(q),
                },
                CsgNode::Intersection(x, y) => match (get(x), get(y)) {
                    (Some(p), Some(q)) => overlap(p, q),
                    _ => None,
                },
                CsgNode::Difference(x, _) => get(x),
            };
            if let Some(slot) = b.get_mut(i) {
                *slot = v;
            }
        }
        self.nodes
            .len()
            .checked_sub(1)
            .and_then(|r| b.get(r).copied().flatten())
    }
}

/// `f` of `a` and `b` on each axis.
fn per_axis(a: Point, b: Point, f: fn(i64, i64) -> i64) -> Point {
    core::array::from_fn(|k| {
        f(
            a.get(k).copied().unwrap_or(0),
            b.get(k).copied().unwrap_or(0),
        )
    })
}

fn hull(p: (Point, Point), q: (Point, Point)) -> (Point, Point) {
    (per_axis(p.0, q.0, i64::min), per_axis(p.1, q.1, i64::max))
}

fn overlap(p: (Point, Point), q: (Point, Point)) -> Option<(Point, Point)> {
    let lo = per_axis(p.0, q.0, i64::max);
    let hi = per_axis(p.1, q.1, i64::min);
    lo.iter()
        .zip(hi.iter())
        .all(|(a, b)| a <= b)
        .then_some((lo, hi))
}

/// Receives the CSG result's boundary voxels with the deciding leaf.
pub trait CsgSink {
    /// Voxel `voxel` of the result's boundary layer, whose surface is
    /// formed there by leaf `leaf`.
    fn offer_leaf(&mut self, leaf: u16, voxel: [u32; 3], surfel: Surfel);

    /// The layers whose voxels the sink keeps, as
    /// [`VoxelSink::layers`]: [`voxelize`] classifies only those.
    fn layers(&self) -> Range<u32> {
        0..u32::MAX
    }

    /// The rows whose voxels the sink keeps, as [`VoxelSink::rows`]:
    /// [`voxelize`] classifies only those.
    fn rows(&self) -> Range<u32> {
        0..u32::MAX
    }
}

/// Adapts any [`VoxelSink`] (a [`crate::store::Counter`], a test set) to
/// [`CsgSink`], dropping the leaf.
#[derive(Debug)]
pub struct IgnoreLeaf<'s, S: VoxelSink>(pub &'s mut S);

impl<S: VoxelSink> CsgSink for IgnoreLeaf<'_, S> {
    fn offer_leaf(&mut self, _leaf: u16, voxel: [u32; 3], surfel: Surfel) {
        self.0.offer(voxel, surfel);
    }

    fn layers(&self) -> Range<u32> {
        self.0.layers()
    }

    fn rows(&self) -> Range<u32> {
        self.0.rows()
    }
}

/// Feeds a CSG result into the fill pass, each voxel with the attributes
/// of its deciding leaf.
#[derive(Debug)]
pub struct LeafFill<'s, 'p, 'd, 'r> {
    filler: &'s mut Filler<'p, 'd, 'r>,
    attrs: &'s [ObjectAttrs],
    /// Offers whose leaf has no attributes.
    missing: u64,
}

impl<'s, 'p, 'd, 'r> LeafFill<'s, 'p, 'd, 'r> {
    /// Wraps `filler`; leaf `i`'s voxels get `attrs[i]`.
    ///
    /// # Errors
    /// The first [`BuildError::ObjectOutOfRange`] or
    /// [`BuildError::MaterialOutOfRange`] among `attrs`.
    pub fn new(
        filler: &'s mut Filler<'p, 'd, 'r>,
        attrs: &'s [ObjectAttrs],
    ) -> Result<Self, BuildError> {
        for a in attrs {
            filler.begin_object(*a)?;
        }
        Ok(Self {
            filler,
            attrs,
            missing: 0,
        })
    }

    /// Offers dropped because their leaf had no entry in `attrs`.
    #[must_use]
    pub const fn missing(&self) -> u64 {
        self.missing
    }
}

impl CsgSink for LeafFill<'_, '_, '_, '_> {
    fn offer_leaf(&mut self, leaf: u16, voxel: [u32; 3], surfel: Surfel) {
        let Some(a) = self.attrs.get(usize::from(leaf)) else {
            self.missing = self.missing.saturating_add(1);
            return;
        };
        // Validated in `new`: cannot fail.
        if self.filler.begin_object(*a).is_ok() {
            self.filler.offer(voxel, surfel);
        }
    }

    fn layers(&self) -> Range<u32> {
        self.filler.layers()
    }

    fn rows(&self) -> Range<u32> {
        self.filler.rows()
    }
}

/// What [`voxelize`] did.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct CsgReport {
    /// Voxels of the (clipped) bounding box classified.
    pub classified: u64,
    /// Tree evaluations, neighbour tests included.
    pub evaluations: u64,
    /// Boundary voxels offered.
    pub voxels: u64,
}

/// Voxel range `[lo, hi]` covering fixed-point interval `[a, b]`, clipped
/// to `start..end`; `None` if empty.
fn voxel_range(a: i64, b: i64, (start, end): (u32, u32)) -> Option<(u32, u32)> {
    let top = i64::from(end).checked_sub(1)?;
    let lo = a
        .saturating_sub(HALF_VOXEL)
        .div_euclid(VOXEL)
        .max(i64::from(start));
    let hi = b.saturating_add(HALF_VOXEL).div_euclid(VOXEL).min(top);
    if lo > hi {
        return None;
    }
    Some((u32::try_from(lo).ok()?, u32::try_from(hi).ok()?))
}

/// Voxels deeper than this inside the result cannot have an outside
/// neighbour (neighbour centres are at most √3 voxels away and distances
/// are 1-Lipschitz): 2 voxels.
const DEEP: i64 = 2 * VOXEL;

/// Offers the boundary layer of `tree` inside `extent` to `sink`
/// (module docs).
pub fn voxelize(tree: &CsgTree<'_>, extent: Extent, sink: &mut impl CsgSink) -> CsgReport {
    let mut report = CsgReport::default();
    let Some((lo, hi)) = tree.bounds() else {
        return report;
    };
    let win = crate::voxelize::window_of(extent, sink.rows(), sink.layers());
    let mut range = [(0u32, 0u32); 3];
    for k in 0..3 {
        let (Some(a), Some(b), Some(n), Some(slot)) =
            (lo.get(k), hi.get(k), win.get(k), range.get_mut(k))
        else {
            return report;
        };
        match voxel_range(*a, *b, *n) {
            Some(r) => *slot = r,
            None => return report,
        }
    }
    let [(x0, x1), (y0, y1), (z0, z1)] = range;
    for z in z0..=z1 {
        for y in y0..=y1 {
            for x in x0..=x1 {
                let v = [x, y, z];
                let c = v.map(voxel_centre);
                let s = tree.sample(c);
                report.classified = report.classified.saturating_add(1);
                report.evaluations = report.evaluations.saturating_add(1);
                if s.distance > 0 || s.distance <= DEEP.wrapping_neg() {
                    continue;
                }
                if has_outside_neighbour(tree, c, &mut report) {
                    report.voxels = report.voxels.saturating_add(1);
                    sink.offer_leaf(
                        s.leaf,
                        v,
                        Surfel {
                            normal: s.normal,
                            distance: u32::try_from(s.distance.unsigned_abs()).unwrap_or(u32::MAX),
                        },
                    );
                }
            }
        }
    }
    report
}

fn has_outside_neighbour(tree: &CsgTree<'_>, c: Point, report: &mut CsgReport) -> bool {
    for dz in [-VOXEL, 0, VOXEL] {
        for dy in [-VOXEL, 0, VOXEL] {
            for dx in [-VOXEL, 0, VOXEL] {
                if dx == 0 && dy == 0 && dz == 0 {
                    continue;
                }
                // c < 2^33: adding one voxel cannot overflow.
                let p = [
                    c[0].saturating_add(dx),
                    c[1].saturating_add(dy),
                    c[2].saturating_add(dz),
                ];
                report.evaluations = report.evaluations.saturating_add(1);
                if tree.sample(p).distance > 0 {
                    return true;
                }
            }
        }
    }
    false
}

#[cfg(test)]
mod tests;
