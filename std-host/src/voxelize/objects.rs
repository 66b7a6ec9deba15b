//! Objects whose voxels are the object: sampled and computed volumes,
//! MagicaVoxel models and CSG trees (the paper's voxel Booleans), as the
//! build pipeline ([`super::build`]) voxelizes them next to the fitted
//! primitives, in the same raster and the same two passes.
//!
//! Each is offered to the count pass and to the fill pass through the same
//! deterministic walk, so both passes see the same voxels. In the fill
//! pass a volume's voxels take the colour of the material's texture if it
//! has one, else the classifier's colour ramp (else the material colour);
//! a `.vox` model's voxels take their palette colours; a CSG result's
//! voxels take the material of the leaf that forms the surface there.
//! None of them has exact geometry: their world object is
//! [`crate::shape::Shape::Voxels`], whose hits verification keeps.

#![deny(missing_docs)]

use rrt_core::csg::{self, CsgNode, CsgTree, IgnoreLeaf, LeafFill};
use rrt_core::fixed::voxel_centre;
use rrt_core::store::{Counter, Filler, ObjectAttrs};
use rrt_core::voxelize::Separation;

use super::BuildError;
use super::texture::InRaster;
use super::volume::{Keep, VolumeColors};
use super::vox::VoxPlacement;
use crate::fit::FitError;
use crate::frame::RasterFrame;
use crate::scene::{Csg, Solid, SourceLoc, VolumeObject, VoxObject};
use crate::texture::AnyTexture;

/// Most bytes of the resampled block a volume is voxelized through at once.
pub const MAX_BLOCK_BYTES: u64 = 256 << 20;

/// Most raster voxels per `.vox` cell edge.
pub const MAX_VOX_SCALE: u32 = 4096;

fn out_of_range(loc: &SourceLoc, what: &'static str) -> BuildError {
    BuildError::Fit(FitError::OutOfRange {
        loc: loc.clone(),
        what,
    })
}

fn csg_error(loc: &SourceLoc, e: &csg::CsgError) -> BuildError {
    BuildError::Raster(format!("{loc}: CSG tree: {e}"))
}

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
                .ok_or_else(|| out_of_range(&l.loc, "CSG solid"))
        })
        .collect::<Result<Vec<_>, _>>()?;
    Ok(Prepared {
        nodes,
        solids,
        volume_cut,
    })
}

/// The raster voxels whose centres lie inside a CSG tree, over the tree's
/// bounding box clipped to the raster (one byte per voxel of that box).
struct Mask {
    lo: [u32; 3],
    n: [u32; 3],
    inside: Vec<bool>,
}

impl Mask {
    fn new(tree: &CsgTree<'_>, dims: [u32; 3]) -> Self {
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
            let v = rrt_core::fixed::VOXEL;
            let l = (a[k].div_euclid(v) - 1).clamp(0, i64::from(dims[k]));
            let h = (b[k].div_euclid(v) + 2).clamp(0, i64::from(dims[k]));
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

/// Where an extra object's voxels go.
pub enum Pass<'a, 'p, 'd, 'r> {
    /// The count pass.
    Count(&'a mut Counter<'p, 'd>),
    /// The fill pass: the object's attributes (object id, material,
    /// colour), the attributes of each CSG leaf, and the texture of the
    /// object's material, if any.
    Fill {
        /// The filler.
        filler: &'a mut Filler<'p, 'd, 'r>,
        /// The object's attributes.
        attrs: ObjectAttrs,
        /// Per CSG leaf (for CSG objects).
        leaves: Vec<ObjectAttrs>,
        /// The material's texture.
        texture: Option<&'a InRaster<AnyTexture>>,
    },
}

fn store_err(e: rrt_core::store::BuildError) -> BuildError {
    BuildError::Store(e)
}

/// Voxelizes a volume object, with `keep` choosing voxels (a CSG cut).
fn volume_into(
    v: &VolumeObject,
    frame: &RasterFrame,
    separation: Separation,
    keep: Option<Keep<'_>>,
    pass: Pass<'_, '_, '_, '_>,
) -> Result<(), BuildError> {
    let placed = v.data.placed();
    let classifier = &v.data.classifier;
    let err = |e: crate::volume::VolumeError| BuildError::Raster(format!("{}: volume: {e}", v.loc));
    match pass {
        Pass::Count(c) => {
            placed
                .voxelize_where(frame, classifier, separation, MAX_BLOCK_BYTES, keep, c)
                .map_err(err)?;
        }
        Pass::Fill {
            filler,
            attrs,
            texture,
            ..
        } => {
            filler.begin_object(attrs).map_err(store_err)?;
            if let Some(t) = texture {
                let mut s = filler.textured(t);
                placed
                    .voxelize_where(frame, classifier, separation, MAX_BLOCK_BYTES, keep, &mut s)
                    .map_err(err)?;
            } else {
                let colors = VolumeColors::new(placed, *frame, classifier);
                let mut s = filler.textured(&colors);
                placed
                    .voxelize_where(frame, classifier, separation, MAX_BLOCK_BYTES, keep, &mut s)
                    .map_err(err)?;
            }
        }
    }
    Ok(())
}

/// Voxelizes a volume object.
///
/// # Errors
/// The volume's refusal (a block beyond the limits), the store's.
pub fn volume(
    v: &VolumeObject,
    frame: &RasterFrame,
    separation: Separation,
    pass: Pass<'_, '_, '_, '_>,
) -> Result<(), BuildError> {
    volume_into(v, frame, separation, None, pass)
}

/// The raster placement of a `.vox` model: its origin's voxel, and
/// `cell / voxel size` voxels (rounded, at least 1) per cell.
///
/// # Errors
/// [`FitError::OutOfRange`] for a model too far out or cells too large.
pub fn vox_placement(v: &VoxObject, frame: &RasterFrame) -> Result<VoxPlacement, BuildError> {
    let scale = (v.cell / frame.voxel_size).round().max(1.0);
    if scale.is_nan() || scale > f64::from(MAX_VOX_SCALE) {
        return Err(out_of_range(&v.loc, "vox cell"));
    }
    let o = frame.world_to_raster(v.position).floor();
    if !(o.is_finite() && o.abs().max_element() < f64::from(1u32 << 30)) {
        return Err(out_of_range(&v.loc, "vox position"));
    }
    Ok(VoxPlacement {
        offset: [o.x as i64, o.y as i64, o.z as i64],
        scale: scale as u32,
    })
}

/// Voxelizes a `.vox` model with its palette colours.
///
/// # Errors
/// As [`vox_placement`]; the store's.
pub fn vox(
    v: &VoxObject,
    frame: &RasterFrame,
    pass: Pass<'_, '_, '_, '_>,
) -> Result<(), BuildError> {
    let placement = vox_placement(v, frame)?;
    match pass {
        Pass::Count(c) => {
            v.vox.voxelize(placement, c);
        }
        Pass::Fill { filler, attrs, .. } => {
            filler.begin_object(attrs).map_err(store_err)?;
            let colors = v.vox.colors(placement);
            let mut s = filler.textured(&colors);
            v.vox.voxelize(placement, &mut s);
        }
    }
    Ok(())
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
pub fn csg(
    c: &Csg,
    frame: &RasterFrame,
    separation: Separation,
    pass: Pass<'_, '_, '_, '_>,
) -> Result<(), BuildError> {
    let p = prepare(c, frame)?;
    let leaves: Vec<&dyn csg::Solid> = p.solids.iter().map(AsRef::as_ref).collect();
    let tree = CsgTree::new(&p.nodes, &leaves).map_err(|e| csg_error(&c.loc, &e))?;
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
        let mask = Mask::new(&tree, extent.dims());
        let keep = move |vx: [u32; 3]| mask.contains(vx) != cut;
        return volume_into(v, frame, separation, Some(&keep), pass);
    }
    match pass {
        Pass::Count(counter) => {
            csg::voxelize(&tree, extent, &mut IgnoreLeaf(counter));
        }
        Pass::Fill { filler, leaves, .. } => {
            let mut sink = LeafFill::new(filler, &leaves).map_err(store_err)?;
            csg::voxelize(&tree, extent, &mut sink);
        }
    }
    Ok(())
}

/// A world texture in the raster (the fill pass's view of it).
#[must_use]
pub fn in_raster(
    t: &AnyTexture,
    frame: RasterFrame,
    blend: crate::texture::Blend,
) -> InRaster<AnyTexture> {
    InRaster::new(t.clone(), frame, blend)
}
