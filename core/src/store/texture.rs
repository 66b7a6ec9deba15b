//! Textures: the colour the fill pass gives a voxel.

/// Colour of a voxel from its centre and normal, applied by the fill pass
/// ([`Filler::textured`](super::Filler::textured)). Any
/// `Fn([i64; 3], [i32; 3], [u8; 3]) -> [u8; 3]` closure is a texture.
pub trait Texture {
    /// The colour at voxel centre `centre` (fixed units) where the surface
    /// has unit normal `normal` ([`crate::voxelize::NORMAL_ONE`]-scaled),
    /// given the object's base colour.
    fn color(&self, centre: [i64; 3], normal: [i32; 3], base: [u8; 3]) -> [u8; 3];
}

impl<F: Fn([i64; 3], [i32; 3], [u8; 3]) -> [u8; 3]> Texture for F {
    fn color(&self, centre: [i64; 3], normal: [i32; 3], base: [u8; 3]) -> [u8; 3] {
        self(centre, normal, base)
    }
}
