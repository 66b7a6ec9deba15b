//! The two voxelization passes as an object sees them: where its voxels
//! go.

use rrt_core::store::{Counter, Filler, ObjectAttrs};

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
