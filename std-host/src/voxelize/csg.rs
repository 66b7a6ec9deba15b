//! CSG trees in the raster: the paper's voxel Booleans
//! ([`rrt_core::csg`]) over the leaves' core solids; each surface voxel of
//! the result carries the attributes of the leaf that forms the surface
//! there. A volume cut by a tree (the paper's box cut out of the head) is
//! the volume with the voxels inside (or outside) the rest of the tree
//! transparent.

use std::ops::Range;

use rrt_core::csg::{self, CsgNode, CsgTree, IgnoreLeaf, LeafFill};
use rrt_core::fixed::{VOXEL, voxel_centre};
use rrt_core::voxelize::Separation;

use super::pass::Pass;
use super::{BuildError, volume};
use crate::frame::RasterFrame;
use crate::scene::{Csg, Solid, VolumeObject};

/// A CSG tree in the raster: its nodes and core solids. For a tree whose
/// first operand is a volume (the paper's box cut out of the head), the
/// rest of the tree, re-indexed, and the top operation.
struct Prepared {
    nodes: Vec<CsgNode>,
    solids: Vec<Box<dyn csg::Solid>>,
    /// `Some(true)` for `volume − rest`, `Some(false)` for `volume ∩ rest`.
    volume_cut: Option<bool>,
}

fn prepare(c: &Csg, frame: &RasterFrame) -> Result<Prepared, BuildError> {
    let volume_cut = match (c.leaves.first().map(|l| &l.shape), c.nodes.last()) {
        (Some(Solid::Volume(_)), Some(CsgNode::Difference(..))) => Some(true),
        (Some(Solid::Volume(_)), Some(CsgNode::Intersection(..))) => Some(false),
        _ => None,
    };
    let (nodes, leaves) = match volume_cut {
        None => (c.nodes.clone(), &c.leaves[..]),
        Some(_) => {
            // nodes = [Leaf(0) (the volume), rest…, top]: the rest shifted
            // down by one node and one leaf.
            let inner = c
                .nodes
                .get(1..c.nodes.len().saturating_sub(1))
                .unwrap_or(&[]);
            let dec = |k: u16| k.saturating_sub(1);
            let nodes = inner
                .iter()
                .map(|n| match *n {
                    CsgNode::Leaf(l) => CsgNode::Leaf(dec(l)),
                    CsgNode::Union(a, b) => CsgNode::Union(dec(a), dec(b)),
                    CsgNode::Intersection(a, b) => CsgNode::Intersection(dec(a), dec(b)),
                    CsgNode::Difference(a, b) => CsgNode::Difference(dec(a), dec(b)),
                })
                .collect();
            (nodes, c.leaves.get(1..).unwrap_or(&[]))
        }
    };
    let solids = leaves
        .iter()
        .map(|l| {
            l.shape
                .primitive()
                .and_then(|p| p.solid(frame))
                .ok_or_else(|| BuildError::out_of_range(&l.loc, "CSG solid"))
        })
        .collect::<Result<Vec<_>, _>>()?;
    Ok(Prepared {
        nodes,
        solids,
        volume_cut,
    })
}

/// The raster voxels whose centres lie inside a CSG tree, over the tree's
/// bounding box clipped to the raster and, along z, to `layers` (one byte
/// per voxel of that box).
struct Mask {
    lo: [u32; 3],
    n: [u32; 3],
    inside: Vec<bool>,
}

impl Mask {
    fn new(tree: &CsgTree<'_>, dims: [u32; 3], layers: Range<u32>) -> Self {
        let empty = Self {
            lo: [0; 3],
            n: [0; 3],
            inside: Vec::new(),
        };
        let Some((a, b)) = tree.bounds() else {
            return empty;
        };
        let mut lo = [0u32; 3];
        let mut n = [0u32; 3];
        for k in 0..3 {
            let v = VOXEL;
            let (start, end) = if k == 2 {
                let end = i64::from(layers.end).min(i64::from(dims[k]));
                (i64::from(layers.start).min(end), end)
            } else {
                (0, i64::from(dims[k]))
            };
            let l = (a[k].div_euclid(v) - 1).clamp(start, end);
            let h = (b[k].div_euclid(v) + 2).clamp(start, end);
            lo[k] = u32::try_from(l).unwrap_or(0);
            n[k] = u32::try_from(h - l).unwrap_or(0);
        }
        let len = n.iter().map(|&x| x as usize).product();
        let mut inside = Vec::with_capacity(len);
        for z in 0..n[2] {
            for y in 0..n[1] {
                for x in 0..n[0] {
                    let v = [lo[0] + x, lo[1] + y, lo[2] + z];
                    inside.push(tree.contains(v.map(voxel_centre)));
                }
            }
        }
        Self { lo, n, inside }
    }

    fn contains(&self, v: [u32; 3]) -> bool {
        let mut i = 0usize;
        let mut stride = 1usize;
        for ((&c, &lo), &n) in v.iter().zip(&self.lo).zip(&self.n) {
            let Some(d) = c.checked_sub(lo).filter(|&d| d < n) else {
                return false;
            };
            i += d as usize * stride;
            stride *= n as usize;
        }
        self.inside.get(i).copied().unwrap_or(false)
    }
}

/// Voxelizes a CSG tree by voxel Booleans ([`rrt_core::csg`]), or, for a
/// volume cut by a tree (the volume is leaf 0, the first operand of the
/// top difference or intersection), the volume with the voxels inside
/// (or outside) the rest of the tree transparent; its fill-pass
/// attributes are then `attrs` (those of leaf 0's material).
///
/// # Errors
/// A solid beyond the fixed-point range, a tree the core refuses, the
/// store's.
pub(super) fn voxelize_object(
    c: &Csg,
    frame: &RasterFrame,
    separation: Separation,
    pass: Pass<'_, '_, '_, '_>,
) -> Result<(), BuildError> {
    let p = prepare(c, frame)?;
    let leaves: Vec<&dyn csg::Solid> = p.solids.iter().map(AsRef::as_ref).collect();
    let tree = CsgTree::new(&p.nodes, &leaves).map_err(|e| match e {
        csg::CsgError::Degenerate { leaf } => {
            // A volume cut by the tree is not among the core's leaves.
            let skipped = c.leaves.len().saturating_sub(p.solids.len());
            let leaf = c.leaves.get(usize::from(leaf) + skipped);
            BuildError::DegenerateSolid {
                loc: leaf.map_or_else(|| c.loc.clone(), |l| l.loc.clone()),
                what: match leaf.map(|l| &l.shape) {
                    Some(Solid::Sphere(_)) => "sphere",
                    Some(Solid::Cuboid(_)) => "box",
                    Some(Solid::Cone(_)) => "capped cone",
                    Some(Solid::Torus(_)) => "torus",
                    Some(Solid::Volume(_)) | None => "solid",
                },
            }
        }
        e => BuildError::csg(&c.loc, &e),
    })?;
    let extent = frame.extent;
    let volume_leaf = match c.leaves.first() {
        Some(l) => match &l.shape {
            Solid::Volume(data) => Some(VolumeObject {
                data: data.clone(),
                material: l.material,
                loc: l.loc.clone(),
            }),
            _ => None,
        },
        None => None,
    };
    if let (Some(cut), Some(v)) = (p.volume_cut, volume_leaf.as_ref()) {
        // The volume reads `keep` one layer beyond the layers it voxelizes.
        let layers = pass.layers();
        let around = layers.start.saturating_sub(1)..layers.end.saturating_add(1);
        let mask = Mask::new(&tree, extent.dims(), around);
        let keep = move |vx: [u32; 3]| mask.contains(vx) != cut;
        return volume::voxelize_object(v, frame, separation, Some(&keep), pass);
    }
    match pass {
        Pass::Count(counter) => {
            csg::voxelize(&tree, extent, &mut IgnoreLeaf(counter));
        }
        Pass::Fill { filler, leaves, .. } => {
            let mut sink = LeafFill::new(filler, &leaves)?;
            csg::voxelize(&tree, extent, &mut sink);
        }
    }
    Ok(())
}
