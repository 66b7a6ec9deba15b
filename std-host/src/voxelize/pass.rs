//! The two voxelization passes as an object sees them: where its voxels
//! go.

use std::ops::Range;

use rrt_core::store::{Counter, Filler, ObjectAttrs};
use rrt_core::voxelize::VoxelSink;

use super::texture::InRaster;
use crate::assets::texture::AnyTexture;

/// Where an object's voxels go.
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

impl Pass<'_, '_, '_, '_> {
    /// The layers of the raster the pass keeps
    /// ([`VoxelSink::layers`]: a slab's).
    #[must_use]
    pub fn layers(&self) -> Range<u32> {
        match self {
            Self::Count(c) => c.layers(),
            Self::Fill { filler, .. } => filler.layers(),
        }
    }
}
