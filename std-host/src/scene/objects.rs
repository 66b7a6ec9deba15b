//! The objects a scene has beyond NFF's: volumes, MagicaVoxel models, CSG
//! trees (tori and capped cones are one-solid trees), and textures.
//!
//! They are what the TOML front-end ([`super::toml`]) reads; voxelization
//! ([`crate::voxelize`]) puts them in the same raster as the primitives,
//! through the same two passes.

use std::sync::Arc;

use glam::DVec3;
use rrt_core::csg::CsgNode;

use super::SourceLoc;
use crate::assets::texture::{AnyTexture, Blend};
use crate::assets::volume::{Classifier, PlacedVolume, Placement, Volume};
use crate::assets::vox::VoxScene;
use crate::shape::{Cone, Cuboid, Primitive, SolidPrimitive, Sphere, Torus};
use crate::world::Bounds;

/// A classified volume placed in the world: the data, where it goes and
/// which of its samples are non-transparent (and their colours).
#[derive(Clone, Debug, PartialEq)]
pub struct SceneVolume {
    /// The samples (shared: a volume can be an object, a CSG leaf and a
    /// texture at once without a second copy).
    pub volume: Arc<Volume>,
    /// Physical → world.
    pub placement: Placement,
    /// Iso-value and ramps.
    pub classifier: Classifier,
}

impl SceneVolume {
    /// The volume at its placement.
    #[must_use]
    pub fn placed(&self) -> PlacedVolume<'_> {
        self.placement.place(&self.volume)
    }

    /// The world box around the volume's cells.
    #[must_use]
    pub fn world_bounds(&self) -> Bounds {
        self.placed().world_bounds()
    }

    /// The smallest world distance between neighbouring samples (along
    /// one of the data's axes): the length the opacities of direct volume
    /// rendering are for.
    #[must_use]
    pub fn sample_spacing(&self) -> f64 {
        let m = self.placed().index_to_world_matrix();
        [m.x_axis, m.y_axis, m.z_axis]
            .map(DVec3::length)
            .into_iter()
            .fold(f64::INFINITY, f64::min)
    }
}

/// A sampled or computed volume as an object: its boundary layer, normals
/// from the gray-level gradient, colours from the classifier's colour ramp
/// (or the material's colour and texture without one).
#[derive(Clone, Debug, PartialEq)]
pub struct VolumeObject {
    /// The classified, placed data.
    pub data: SceneVolume,
    /// Index into [`Scene::materials`](super::Scene::materials) (shading coefficients, and the
    /// colour where the classifier has no colour ramp).
    pub material: usize,
    /// Where the object is defined.
    pub loc: SourceLoc,
}

/// A MagicaVoxel model placed in the world: world cell `c` of the model
/// (MagicaVoxel's frame, z up, see [`crate::assets::vox`]) covers the cube
/// `position + cell · (c + [0, 1)³)`.
#[derive(Clone, Debug, PartialEq)]
pub struct VoxObject {
    /// The model's voxels, palette and scene graph.
    pub vox: Arc<VoxScene>,
    /// World position of cell (0, 0, 0)'s lowest corner.
    pub position: DVec3,
    /// World edge length of a cell (> 0).
    pub cell: f64,
    /// Index into [`Scene::materials`](super::Scene::materials) (shading coefficients; the colours
    /// come from the palette).
    pub material: usize,
    /// Where the object is defined.
    pub loc: SourceLoc,
}

impl VoxObject {
    /// The world box around the model's cells, `None` for a model without
    /// voxels.
    #[must_use]
    pub fn world_bounds(&self) -> Option<Bounds> {
        let (lo, hi) = self.vox.world_bounds()?;
        let corner = |c: [i64; 3]| self.position + DVec3::from(c.map(|v| v as f64)) * self.cell;
        Some(Bounds {
            min: corner(lo),
            max: corner(hi.map(|v| v + 1)),
        })
    }
}

/// A solid a CSG tree combines: a primitive of the shape model
/// ([`crate::shape`]) or a classified volume.
#[derive(Clone, Debug, PartialEq)]
pub enum Solid {
    /// A ball.
    Sphere(Sphere),
    /// An axis-aligned box.
    Cuboid(Cuboid),
    /// A cone or cylinder closed by its end discs.
    Cone(Cone),
    /// A solid torus.
    Torus(Torus),
    /// The non-transparent samples of a classified volume.
    Volume(SceneVolume),
}

impl Solid {
    /// The primitive, `None` for a volume.
    #[must_use]
    pub fn primitive(&self) -> Option<&dyn SolidPrimitive> {
        match self {
            Self::Sphere(s) => Some(s),
            Self::Cuboid(s) => Some(s),
            Self::Cone(s) => Some(s),
            Self::Torus(s) => Some(s),
            Self::Volume(_) => None,
        }
    }

    /// The world box holding the solid.
    #[must_use]
    pub fn world_bounds(&self) -> Bounds {
        match self {
            Self::Sphere(s) => s.bounds(),
            Self::Cuboid(s) => s.bounds(),
            Self::Cone(s) => s.bounds(),
            Self::Torus(s) => s.bounds(),
            Self::Volume(v) => v.world_bounds(),
        }
    }

    /// The kind, for messages.
    #[must_use]
    pub const fn kind(&self) -> &'static str {
        match self {
            Self::Sphere(_) => Sphere::KIND,
            Self::Cuboid(_) => Cuboid::KIND,
            Self::Cone(_) => Cone::KIND,
            Self::Torus(_) => Torus::KIND,
            Self::Volume(_) => "volume",
        }
    }

    /// Checks the world-space invariants of the primitive, or the
    /// classifier of the volume.
    ///
    /// # Errors
    /// What is wrong, for a message.
    pub fn validate(&self) -> Result<(), String> {
        match self {
            Self::Sphere(s) => s.validate().map_err(String::from),
            Self::Cuboid(s) => s.validate().map_err(String::from),
            Self::Cone(s) => s.validate().map_err(String::from),
            Self::Torus(s) => s.validate().map_err(String::from),
            Self::Volume(v) => v.classifier.validate().map_err(|e| e.to_string()),
        }
    }
}

/// A leaf of a CSG tree: a solid and the material its part of the result's
/// surface gets.
#[derive(Clone, Debug, PartialEq)]
pub struct CsgLeaf {
    /// The solid.
    pub shape: Solid,
    /// Index into [`Scene::materials`](super::Scene::materials).
    pub material: usize,
    /// Where the solid is defined.
    pub loc: SourceLoc,
}

/// A CSG tree: core nodes ([`CsgNode`], children before parents, the root
/// last) over world-space leaves. Voxelized by voxel Booleans
/// ([`rrt_core::csg`]); each surface voxel of the result carries the
/// attributes of the leaf that forms the surface there.
#[derive(Clone, Debug, PartialEq)]
pub struct Csg {
    /// The nodes; `Leaf(i)` refers to `leaves[i]`.
    pub nodes: Vec<CsgNode>,
    /// The solids.
    pub leaves: Vec<CsgLeaf>,
    /// Where the CSG object is defined.
    pub loc: SourceLoc,
}

impl Csg {
    /// A world box holding the result (as [`rrt_core::csg::CsgTree::bounds`]
    /// does in the raster): `None` when it is provably empty.
    #[must_use]
    pub fn world_bounds(&self) -> Option<Bounds> {
        let mut b: Vec<Option<Bounds>> = Vec::with_capacity(self.nodes.len());
        for n in &self.nodes {
            let get = |k: u16| b.get(usize::from(k)).copied().flatten();
            let v = match *n {
                CsgNode::Leaf(l) => self
                    .leaves
                    .get(usize::from(l))
                    .map(|leaf| leaf.shape.world_bounds()),
                CsgNode::Union(x, y) => match (get(x), get(y)) {
                    (Some(p), Some(q)) => {
                        let mut u = p;
                        u.include_bounds(q);
                        Some(u)
                    }
                    (p, q) => p.or(q),
                },
                CsgNode::Intersection(x, y) => match (get(x), get(y)) {
                    (Some(p), Some(q)) => {
                        let o = Bounds {
                            min: p.min.max(q.min),
                            max: p.max.min(q.max),
                        };
                        (!o.is_empty()).then_some(o)
                    }
                    _ => None,
                },
                CsgNode::Difference(x, _) => get(x),
            };
            b.push(v);
        }
        b.last().copied().flatten()
    }
}

/// What a texture computes.
#[derive(Clone, Debug, PartialEq)]
pub enum TextureKind {
    /// An image map or a solid texture ([`crate::assets::texture`]).
    World(AnyTexture),
}

/// A texture of a material.
#[derive(Clone, Debug, PartialEq)]
pub struct SceneTexture {
    /// The colour function.
    pub kind: TextureKind,
    /// How it meets the material's colour.
    pub blend: Blend,
    /// Where it is defined.
    pub loc: SourceLoc,
}
