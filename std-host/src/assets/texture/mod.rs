//! Textures, precomputed at voxelization: 2D image maps with planar,
//! cylindrical and spherical mapping, and 3D solid textures (checkerboard,
//! marble, wood).
//!
//! The paper stores "the texture color for that voxel" in each surface
//! voxel: "since the texture mapping is view-independent, it is
//! precomputed during the voxelization algorithm from a 2D texture/photo
//! map or a 3D texture". Here each texture is a [`WorldTexture`], a colour
//! as a function of the world position (and normal) of a voxel centre; in
//! the raster ([`crate::voxelize::texture::InRaster`]) it becomes the
//! core's [`Texture`](rrt_core::store::Texture) hook, which the scene
//! builder's fill pass calls once per voxel (`Filler::textured`). Nothing
//! is recomputed per view. Nothing here knows the raster.
//!
//! ```
//! use glam::DVec3;
//! use rrt_host::assets::texture::{Blend, Checker, WorldTexture};
//! let checker = Checker::new(DVec3::ZERO, 1.0, [[255, 255, 255], [200, 0, 0]]).unwrap();
//! // (0.4375, 0.4375, 0.4375) lies in the white cell, x = 1.4375 in the red one.
//! let white = checker.world_color(DVec3::splat(0.4375), DVec3::Z, [9; 3]);
//! assert_eq!(white, [255, 255, 255]);
//! let red = checker.world_color(DVec3::new(1.4375, 0.4375, 0.4375), DVec3::Z, [9; 3]);
//! assert_eq!(Blend::Modulate.apply(red, [255, 128, 0]), [200, 0, 0]);
//! ```
//!
//! # Conventions
//! Texture coordinates `(u, v)` run over `[0, 1)` across one copy of the
//! image; `v` points up the image (row 0 of the file is the top, `v` near
//! 1). Every 2D mapping then applies `scale` and `offset`
//! (`uv' = uv · scale + offset`, so scale 4 tiles the image 4 times) and
//! the [`Wrap`] rule. Image lookups are bilinear between pixel centres.

mod image_map;
mod solid;

use std::path::PathBuf;

use glam::DVec3;

pub use self::image_map::{ImageTexture, MAX_IMAGE_PIXELS, Mapping, Wrap};
pub use self::solid::{Checker, Marble, Perlin, Wood};

/// Why a texture cannot be made.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum TextureError {
    /// The image file cannot be opened or read.
    #[error("cannot read {}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The cause.
        #[source]
        source: std::io::Error,
    },
    /// The file is not a PNG or JPEG image.
    #[error("{}: not an image: {detail} (textures are PNG or JPEG)", path.display())]
    NotImage {
        /// The file.
        path: PathBuf,
        /// What was found instead.
        detail: String,
    },
    /// The image is damaged, too large or in an unsupported variant.
    #[error("{}: cannot decode the image", path.display())]
    Decode {
        /// The file.
        path: PathBuf,
        /// The decoder's error.
        #[source]
        source: image::ImageError,
    },
    /// The image has more pixels than [`MAX_IMAGE_PIXELS`]: refused before
    /// it is decoded.
    #[error(
        "{}: the image is {width}×{height}, {} pixels, more than the {} a texture may have",
        path.display(),
        u64::from(*width) * u64::from(*height),
        image_map::MAX_IMAGE_PIXELS
    )]
    TooLarge {
        /// The file.
        path: PathBuf,
        /// Its width in pixels.
        width: u32,
        /// Its height in pixels.
        height: u32,
    },
    /// Reading and decoding the image would take more memory than the
    /// limit: refused from the file's size and the image's header.
    #[error(
        "{}: {what} takes about {} to read and decode, more than the memory limit of {} (--max-memory)",
        path.display(),
        crate::memory::Bytes(*bytes),
        crate::memory::Bytes(*limit)
    )]
    TooMuchMemory {
        /// The file.
        path: PathBuf,
        /// What takes the memory (`the 4096×4096 image`).
        what: String,
        /// The bytes it takes.
        bytes: u64,
        /// The limit.
        limit: u64,
    },
    /// A parameter is unusable.
    #[error("{what}: {msg}")]
    Invalid {
        /// The texture and parameter.
        what: &'static str,
        /// What is wrong.
        msg: String,
    },
}

pub(super) fn invalid(what: &'static str, msg: String) -> TextureError {
    TextureError::Invalid { what, msg }
}

/// A colour as a function of a world position and the unit surface
/// normal there.
pub trait WorldTexture: Sync {
    /// The colour at world point `p` with unit normal `n`, given the
    /// object's base colour.
    fn world_color(&self, p: DVec3, n: DVec3, base: [u8; 3]) -> [u8; 3];
}

/// How a texture's colour combines with the object's base colour.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub enum Blend {
    /// The texture's colour.
    #[default]
    Replace,
    /// Texture × base / 255 per channel (a white texel keeps the base).
    Modulate,
}

impl Blend {
    /// The colour of texel `t` on an object of base colour `base`.
    #[must_use]
    pub fn apply(self, t: [u8; 3], base: [u8; 3]) -> [u8; 3] {
        match self {
            Self::Replace => t,
            Self::Modulate => {
                let mut out = [0u8; 3];
                for ((o, a), b) in out.iter_mut().zip(t).zip(base) {
                    // (a·b + 127) / 255 ≤ 255.
                    *o = ((u16::from(a) * u16::from(b) + 127) / 255) as u8;
                }
                out
            }
        }
    }
}

/// Any of the textures, for scenes that choose one at run time.
#[derive(Clone, Debug, PartialEq)]
pub enum AnyTexture {
    /// An image map.
    Image(ImageTexture),
    /// A checkerboard.
    Checker(Checker),
    /// Marble.
    Marble(Marble),
    /// Wood.
    Wood(Wood),
}

impl WorldTexture for AnyTexture {
    fn world_color(&self, p: DVec3, n: DVec3, base: [u8; 3]) -> [u8; 3] {
        match self {
            Self::Image(t) => t.world_color(p, n, base),
            Self::Checker(t) => t.world_color(p, n, base),
            Self::Marble(t) => t.world_color(p, n, base),
            Self::Wood(t) => t.world_color(p, n, base),
        }
    }
}
