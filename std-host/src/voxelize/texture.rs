//! Textures in the raster: a [`WorldTexture`] as the core's [`Texture`]
//! hook, which the fill pass calls once per voxel with the voxel centre in
//! fixed point.
//!
//! ```
//! use glam::DVec3;
//! use rrt_core::fixed::voxel_centre;
//! use rrt_core::raster::Extent;
//! use rrt_core::store::Texture;
//! use rrt_host::frame::RasterFrame;
//! use rrt_host::assets::texture::{Blend, Checker};
//! use rrt_host::voxelize::texture::InRaster;
//! let frame = RasterFrame { extent: Extent::cube(64).unwrap(),
//!                           origin: DVec3::ZERO, voxel_size: 0.125 };
//! let checker = Checker::new(DVec3::ZERO, 1.0, [[255, 255, 255], [200, 0, 0]]).unwrap();
//! let checker = InRaster::new(checker, frame, Blend::Replace);
//! // Voxel (3, 3, 3): world (0.4375, …): the white cell; voxel 11: red.
//! let c = |i| [voxel_centre(i); 3];
//! assert_eq!(checker.color(c(3), [0, 0, 1 << 30], [9; 3]), [255, 255, 255]);
//! assert_eq!(checker.color([voxel_centre(11), voxel_centre(3), voxel_centre(3)],
//!                          [0, 0, 1 << 30], [9; 3]), [200, 0, 0]);
//! ```

use std::collections::BTreeMap;

use glam::DVec3;
use rrt_core::store::Texture;
use rrt_core::voxelize::NORMAL_ONE;

use crate::assets::texture::{AnyTexture, Blend, WorldTexture};
use crate::frame::RasterFrame;
use crate::scene::{Scene, TextureKind};

/// A [`WorldTexture`] in a raster: the core's [`Texture`].
#[derive(Clone, Debug)]
pub struct InRaster<T> {
    /// The texture.
    pub texture: T,
    /// The raster's place in the world.
    pub frame: RasterFrame,
    /// How the texture meets the base colour.
    pub blend: Blend,
}

impl<T: WorldTexture> Texture for InRaster<T> {
    fn color(&self, centre: [i64; 3], normal: [i32; 3], base: [u8; 3]) -> [u8; 3] {
        let p = self.frame.fixed_to_world(centre);
        let n = DVec3::from(normal.map(f64::from)) / f64::from(NORMAL_ONE);
        self.blend.apply(self.texture.world_color(p, n, base), base)
    }
}

impl<T> InRaster<T> {
    /// `texture` in the raster `frame`, meeting the base colour by `blend`.
    #[must_use]
    pub const fn new(texture: T, frame: RasterFrame, blend: Blend) -> Self {
        Self {
            texture,
            frame,
            blend,
        }
    }
}

/// Each texture of a scene once, in the raster, and which material has
/// which.
#[derive(Debug)]
pub struct MaterialTextures<'s> {
    textures: Vec<InRaster<AnyTexture>>,
    of_material: &'s BTreeMap<usize, usize>,
}

impl<'s> MaterialTextures<'s> {
    /// The textures of `scene` in the raster `frame`.
    #[must_use]
    pub fn new(scene: &'s Scene, frame: RasterFrame) -> Self {
        Self {
            textures: scene
                .textures
                .iter()
                .map(|t| match &t.kind {
                    TextureKind::World(w) => InRaster::new(w.clone(), frame, t.blend),
                })
                .collect(),
            of_material: &scene.material_textures,
        }
    }

    /// The texture of scene material `m`, if it has one.
    #[must_use]
    pub fn of(&self, m: usize) -> Option<&InRaster<AnyTexture>> {
        self.textures.get(*self.of_material.get(&m)?)
    }
}
