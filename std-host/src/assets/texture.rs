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

use std::f64::consts::{PI, TAU};
use std::path::{Path, PathBuf};

use glam::DVec3;

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
    /// A parameter is unusable.
    #[error("{what}: {msg}")]
    Invalid {
        /// The texture and parameter.
        what: &'static str,
        /// What is wrong.
        msg: String,
    },
}

fn invalid(what: &'static str, msg: String) -> TextureError {
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

/// What happens outside `[0, 1)` in texture coordinates.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub enum Wrap {
    /// Tile the image.
    #[default]
    Repeat,
    /// Mirror every other tile.
    Mirror,
    /// Extend the edge pixels.
    Clamp,
}

impl Wrap {
    /// `t` brought into `[0, 1]`.
    #[must_use]
    pub fn apply(self, t: f64) -> f64 {
        match self {
            Self::Repeat => t - t.floor(),
            Self::Mirror => {
                let m = t.rem_euclid(2.0);
                if m > 1.0 { 2.0 - m } else { m }
            }
            Self::Clamp => t.clamp(0.0, 1.0),
        }
    }
}

/// How world points get texture coordinates.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Mapping {
    /// Projection onto a plane: `u = (p − origin)·u_axis / |u_axis|²`,
    /// likewise `v`: the image spans `u_axis` × `v_axis` in the world.
    Planar {
        /// World point of texture coordinates (0, 0).
        origin: DVec3,
        /// The image's width in the world (direction and length).
        u_axis: DVec3,
        /// The image's height in the world (direction and length).
        v_axis: DVec3,
    },
    /// Around an axis: `u` is the angle about `axis` from `reference`
    /// (counter-clockwise seen from the axis' tip) over 2π, `v` the
    /// height along `axis` over its length.
    Cylindrical {
        /// A point on the axis (height 0).
        origin: DVec3,
        /// The axis; its length is the height of one image.
        axis: DVec3,
        /// The direction of `u = 0` (its part across the axis is used).
        reference: DVec3,
    },
    /// Around a centre: `u` is the longitude about `pole` from
    /// `reference` over 2π, `v` the latitude from the south pole (0) to
    /// the north pole (1).
    Spherical {
        /// The centre.
        centre: DVec3,
        /// The direction of the north pole.
        pole: DVec3,
        /// The direction of longitude 0 (its part across the pole is
        /// used).
        reference: DVec3,
    },
}

/// An orthonormal frame `(e1, e2, axis)` from an axis and a reference
/// direction across it.
fn frame_of(axis: DVec3, reference: DVec3) -> Option<(DVec3, DVec3, DVec3)> {
    let a = axis.try_normalize()?;
    let e1 = (reference - a * reference.dot(a)).try_normalize()?;
    Some((e1, a.cross(e1), a))
}

impl Mapping {
    /// Checks the mapping's vectors are finite and usable.
    ///
    /// # Errors
    /// [`TextureError::Invalid`] naming the parameter.
    pub fn validate(&self) -> Result<(), TextureError> {
        let finite = |name: &'static str, v: DVec3| {
            if v.is_finite() {
                Ok(())
            } else {
                Err(invalid(name, format!("{v} is not finite")))
            }
        };
        match *self {
            Self::Planar {
                origin,
                u_axis,
                v_axis,
            } => {
                finite("planar mapping origin", origin)?;
                finite("planar mapping u axis", u_axis)?;
                finite("planar mapping v axis", v_axis)?;
                if u_axis.length_squared() == 0.0 || v_axis.length_squared() == 0.0 {
                    return Err(invalid(
                        "planar mapping",
                        "the u and v axes must be non-zero".into(),
                    ));
                }
                if u_axis.cross(v_axis).length() <= 1e-12 * u_axis.length() * v_axis.length() {
                    return Err(invalid(
                        "planar mapping",
                        "the u and v axes are parallel".into(),
                    ));
                }
            }
            Self::Cylindrical {
                origin,
                axis,
                reference,
            } => {
                finite("cylindrical mapping origin", origin)?;
                finite("cylindrical mapping axis", axis)?;
                finite("cylindrical mapping reference", reference)?;
                if frame_of(axis, reference).is_none() {
                    return Err(invalid(
                        "cylindrical mapping",
                        "the axis must be non-zero and the reference not along it".into(),
                    ));
                }
            }
            Self::Spherical {
                centre,
                pole,
                reference,
            } => {
                finite("spherical mapping centre", centre)?;
                finite("spherical mapping pole", pole)?;
                finite("spherical mapping reference", reference)?;
                if frame_of(pole, reference).is_none() {
                    return Err(invalid(
                        "spherical mapping",
                        "the pole must be non-zero and the reference not along it".into(),
                    ));
                }
            }
        }
        Ok(())
    }

    /// Texture coordinates of world point `p` (before scale, offset and
    /// wrap); `None` on a cylinder's axis or at a sphere's centre.
    #[must_use]
    pub fn uv(&self, p: DVec3) -> Option<[f64; 2]> {
        match *self {
            Self::Planar {
                origin,
                u_axis,
                v_axis,
            } => {
                let d = p - origin;
                Some([
                    d.dot(u_axis) / u_axis.length_squared(),
                    d.dot(v_axis) / v_axis.length_squared(),
                ])
            }
            Self::Cylindrical {
                origin,
                axis,
                reference,
            } => {
                let (e1, e2, _) = frame_of(axis, reference)?;
                let d = p - origin;
                let (x, y) = (d.dot(e1), d.dot(e2));
                if x == 0.0 && y == 0.0 {
                    return None;
                }
                Some([
                    y.atan2(x).rem_euclid(TAU) / TAU,
                    d.dot(axis) / axis.length_squared(),
                ])
            }
            Self::Spherical {
                centre,
                pole,
                reference,
            } => {
                let (e1, e2, a) = frame_of(pole, reference)?;
                let d = (p - centre).try_normalize()?;
                let lon = d.dot(e2).atan2(d.dot(e1)).rem_euclid(TAU);
                let lat = d.dot(a).clamp(-1.0, 1.0).acos();
                Some([lon / TAU, 1.0 - lat / PI])
            }
        }
    }
}

/// An RGB image mapped onto surfaces.
#[derive(Clone, Debug, PartialEq)]
pub struct ImageTexture {
    width: u32,
    height: u32,
    pixels: Vec<[u8; 3]>,
    mapping: Mapping,
    /// `uv' = uv · scale + offset`.
    pub scale: [f64; 2],
    /// See `scale`.
    pub offset: [f64; 2],
    /// Outside `[0, 1)`.
    pub wrap: Wrap,
}

/// Largest image accepted, in pixels (256 megapixels).
pub const MAX_IMAGE_PIXELS: u64 = 1 << 28;

impl ImageTexture {
    /// Reads a PNG or JPEG file (format told by its content, not its
    /// name).
    ///
    /// # Errors
    /// [`TextureError::Io`], [`TextureError::NotImage`] for a file that is
    /// not a PNG or JPEG, [`TextureError::Decode`] for a damaged one or one
    /// above [`MAX_IMAGE_PIXELS`], [`TextureError::Invalid`] for a bad
    /// mapping.
    pub fn open(path: impl AsRef<Path>, mapping: Mapping) -> Result<Self, TextureError> {
        let path = path.as_ref();
        let bytes = std::fs::read(path).map_err(|source| TextureError::Io {
            path: path.to_path_buf(),
            source,
        })?;
        Self::from_bytes(path, &bytes, mapping)
    }

    /// Decodes a PNG or JPEG held in memory, named `path` in errors.
    ///
    /// # Errors
    /// As [`ImageTexture::open`].
    pub fn from_bytes(path: &Path, bytes: &[u8], mapping: Mapping) -> Result<Self, TextureError> {
        let format = match image::guess_format(bytes) {
            Ok(f @ (image::ImageFormat::Png | image::ImageFormat::Jpeg)) => f,
            Ok(other) => {
                return Err(TextureError::NotImage {
                    path: path.to_path_buf(),
                    detail: format!("a {other:?} image"),
                });
            }
            Err(_) => {
                let head: String = bytes
                    .iter()
                    .take(8)
                    .map(|b| format!("{b:02x}"))
                    .collect::<Vec<_>>()
                    .join(" ");
                return Err(TextureError::NotImage {
                    path: path.to_path_buf(),
                    detail: if bytes.is_empty() {
                        "the file is empty".into()
                    } else {
                        format!("no PNG or JPEG signature (starts with {head})")
                    },
                });
            }
        };
        let mut reader = image::ImageReader::with_format(std::io::Cursor::new(bytes), format);
        let mut limits = image::Limits::default();
        limits.max_alloc = Some(MAX_IMAGE_PIXELS * 4);
        reader.limits(limits);
        let img = reader.decode().map_err(|source| TextureError::Decode {
            path: path.to_path_buf(),
            source,
        })?;
        let rgb = img.to_rgb8();
        Self::from_rgb(
            rgb.width(),
            rgb.height(),
            rgb.pixels().map(|p| p.0).collect(),
            mapping,
        )
    }

    /// An image from its pixels (row 0 at the top, `width` per row).
    ///
    /// # Errors
    /// [`TextureError::Invalid`] for an empty image, a pixel count that is
    /// not `width · height`, or a bad mapping.
    pub fn from_rgb(
        width: u32,
        height: u32,
        pixels: Vec<[u8; 3]>,
        mapping: Mapping,
    ) -> Result<Self, TextureError> {
        if width == 0 || height == 0 {
            return Err(invalid("image texture", "the image is empty".into()));
        }
        if u64::try_from(pixels.len()).ok() != Some(u64::from(width) * u64::from(height)) {
            return Err(invalid(
                "image texture",
                format!("{} pixels for {width}×{height}", pixels.len()),
            ));
        }
        mapping.validate()?;
        Ok(Self {
            width,
            height,
            pixels,
            mapping,
            scale: [1.0, 1.0],
            offset: [0.0, 0.0],
            wrap: Wrap::Repeat,
        })
    }

    /// With `uv' = uv · scale + offset`.
    ///
    /// # Errors
    /// [`TextureError::Invalid`] unless both are finite and the scales
    /// non-zero.
    pub fn with_transform(
        mut self,
        scale: [f64; 2],
        offset: [f64; 2],
    ) -> Result<Self, TextureError> {
        if !scale.iter().chain(&offset).all(|x| x.is_finite()) || scale.contains(&0.0) {
            return Err(invalid(
                "image texture",
                format!(
                    "scale {scale:?} / offset {offset:?}: expected finite numbers, scales non-zero"
                ),
            ));
        }
        self.scale = scale;
        self.offset = offset;
        Ok(self)
    }

    /// With the wrap rule.
    #[must_use]
    pub fn with_wrap(mut self, wrap: Wrap) -> Self {
        self.wrap = wrap;
        self
    }

    /// Width and height in pixels.
    #[must_use]
    pub const fn size(&self) -> [u32; 2] {
        [self.width, self.height]
    }

    /// The mapping.
    #[must_use]
    pub const fn mapping(&self) -> &Mapping {
        &self.mapping
    }

    fn pixel(&self, x: u32, y: u32) -> [f64; 3] {
        let i = u64::from(y.min(self.height - 1)) * u64::from(self.width)
            + u64::from(x.min(self.width - 1));
        let p = usize::try_from(i)
            .ok()
            .and_then(|i| self.pixels.get(i))
            .copied()
            .unwrap_or([0; 3]);
        p.map(f64::from)
    }

    /// The bilinear colour at texture coordinates `(u, v)` after scale,
    /// offset and wrap.
    #[must_use]
    pub fn at_uv(&self, uv: [f64; 2]) -> [u8; 3] {
        let u = self.wrap.apply(uv[0] * self.scale[0] + self.offset[0]);
        let v = self.wrap.apply(uv[1] * self.scale[1] + self.offset[1]);
        let (w, h) = (f64::from(self.width), f64::from(self.height));
        // Continuous pixel coordinates, pixel centres at +½; v up.
        let x = u * w - 0.5;
        let y = (1.0 - v) * h - 0.5;
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0, y - y0);
        let repeat = self.wrap == Wrap::Repeat;
        let idx = |c: f64, n: u32| -> u32 {
            let n = i64::from(n);
            // |c| ≤ n + 1.
            let c = c as i64;
            let c = if repeat {
                c.rem_euclid(n)
            } else {
                c.clamp(0, n - 1)
            };
            u32::try_from(c).unwrap_or(0)
        };
        let (xa, xb) = (idx(x0, self.width), idx(x0 + 1.0, self.width));
        let (ya, yb) = (idx(y0, self.height), idx(y0 + 1.0, self.height));
        let (p00, p10, p01, p11) = (
            self.pixel(xa, ya),
            self.pixel(xb, ya),
            self.pixel(xa, yb),
            self.pixel(xb, yb),
        );
        let mut out = [0u8; 3];
        for c in 0..3 {
            let top = p00[c] + (p10[c] - p00[c]) * fx;
            let bot = p01[c] + (p11[c] - p01[c]) * fx;
            // Between two u8 values.
            out[c] = (top + (bot - top) * fy).round().clamp(0.0, 255.0) as u8;
        }
        out
    }
}

impl WorldTexture for ImageTexture {
    fn world_color(&self, p: DVec3, _n: DVec3, base: [u8; 3]) -> [u8; 3] {
        self.mapping.uv(p).map_or(base, |uv| self.at_uv(uv))
    }
}

/// A 3D checkerboard: cubes of edge `size` alternating two colours, the
/// cube with its low corner at `origin` taking the first.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Checker {
    origin: DVec3,
    size: f64,
    colors: [[u8; 3]; 2],
}

impl Checker {
    /// A checkerboard.
    ///
    /// # Errors
    /// [`TextureError::Invalid`] unless `origin` is finite and `size`
    /// finite and positive.
    pub fn new(origin: DVec3, size: f64, colors: [[u8; 3]; 2]) -> Result<Self, TextureError> {
        if !(origin.is_finite() && size.is_finite() && size > 0.0) {
            return Err(invalid(
                "checker",
                format!("origin {origin} / size {size}: expected finite, size positive"),
            ));
        }
        Ok(Self {
            origin,
            size,
            colors,
        })
    }
}

impl WorldTexture for Checker {
    fn world_color(&self, p: DVec3, _n: DVec3, _base: [u8; 3]) -> [u8; 3] {
        let c = ((p - self.origin) / self.size).floor();
        let parity = (c.x + c.y + c.z).rem_euclid(2.0);
        self.colors[usize::from(parity >= 1.0)]
    }
}

/// Ken Perlin's improved gradient noise (2002) with a seeded permutation:
/// values in about `[-1, 1]`, 0 at integer lattice points.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Perlin {
    perm: [u8; 512],
}

impl Perlin {
    /// The noise for `seed` (a SplitMix64-driven Fisher–Yates shuffle of
    /// 0..256).
    #[must_use]
    pub fn new(seed: u64) -> Self {
        let mut p: [u8; 256] = std::array::from_fn(|i| i as u8);
        let mut s = seed;
        let mut next = || {
            s = s.wrapping_add(0x9E37_79B9_7F4A_7C15);
            let mut z = s;
            z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
            z ^ (z >> 31)
        };
        for i in (1..256usize).rev() {
            let j = (next() % (i as u64 + 1)) as usize;
            p.swap(i, j);
        }
        let mut perm = [0u8; 512];
        for (i, slot) in perm.iter_mut().enumerate() {
            *slot = p[i & 255];
        }
        Self { perm }
    }

    fn grad(hash: u8, x: f64, y: f64, z: f64) -> f64 {
        let h = hash & 15;
        let u = if h < 8 { x } else { y };
        let v = if h < 4 {
            y
        } else if h == 12 || h == 14 {
            x
        } else {
            z
        };
        (if h & 1 == 0 { u } else { -u }) + (if h & 2 == 0 { v } else { -v })
    }

    /// The noise at `p` (0 for a non-finite point).
    #[must_use]
    pub fn noise(&self, p: DVec3) -> f64 {
        if !p.is_finite() {
            return 0.0;
        }
        let f = p.floor();
        // Lattice cell modulo 256 (rem_euclid keeps it in 0..256).
        let cell = |v: f64| (v.rem_euclid(256.0)) as usize & 255;
        let (xi, yi, zi) = (cell(f.x), cell(f.y), cell(f.z));
        let (x, y, z) = (p.x - f.x, p.y - f.y, p.z - f.z);
        let fade = |t: f64| t * t * t * (t * (t * 6.0 - 15.0) + 10.0);
        let (u, v, w) = (fade(x), fade(y), fade(z));
        let pm = |i: usize| usize::from(self.perm[i & 511]);
        let a = pm(xi) + yi;
        let (aa, ab) = (pm(a) + zi, pm(a + 1) + zi);
        let b = pm(xi + 1) + yi;
        let (ba, bb) = (pm(b) + zi, pm(b + 1) + zi);
        let h = |i: usize| self.perm[i & 511];
        let lerp = |t: f64, a: f64, b: f64| a + t * (b - a);
        lerp(
            w,
            lerp(
                v,
                lerp(
                    u,
                    Self::grad(h(aa), x, y, z),
                    Self::grad(h(ba), x - 1.0, y, z),
                ),
                lerp(
                    u,
                    Self::grad(h(ab), x, y - 1.0, z),
                    Self::grad(h(bb), x - 1.0, y - 1.0, z),
                ),
            ),
            lerp(
                v,
                lerp(
                    u,
                    Self::grad(h(aa + 1), x, y, z - 1.0),
                    Self::grad(h(ba + 1), x - 1.0, y, z - 1.0),
                ),
                lerp(
                    u,
                    Self::grad(h(ab + 1), x, y - 1.0, z - 1.0),
                    Self::grad(h(bb + 1), x - 1.0, y - 1.0, z - 1.0),
                ),
            ),
        )
    }

    /// Turbulence: `Σ |noise(p·2ⁱ)| / 2ⁱ` over `octaves` octaves.
    #[must_use]
    pub fn turbulence(&self, p: DVec3, octaves: u32) -> f64 {
        let mut sum = 0.0;
        let mut f = 1.0;
        for _ in 0..octaves {
            sum += self.noise(p * f).abs() / f;
            f *= 2.0;
        }
        sum
    }
}

fn mix(a: [u8; 3], b: [u8; 3], t: f64) -> [u8; 3] {
    let t = t.clamp(0.0, 1.0);
    let mut out = [0u8; 3];
    for ((o, x), y) in out.iter_mut().zip(a).zip(b) {
        // Between two u8 values.
        *o = (f64::from(x) + (f64::from(y) - f64::from(x)) * t)
            .round()
            .clamp(0.0, 255.0) as u8;
    }
    out
}

fn check_noise_params(
    what: &'static str,
    period: f64,
    turbulence: f64,
    octaves: u32,
    scale: f64,
) -> Result<(), TextureError> {
    if !(period.is_finite() && period > 0.0 && scale.is_finite() && scale > 0.0) {
        return Err(invalid(
            what,
            format!("period {period} / noise scale {scale}: expected finite positive numbers"),
        ));
    }
    if !turbulence.is_finite() || !(1..=16).contains(&octaves) {
        return Err(invalid(
            what,
            format!(
                "turbulence {turbulence} / octaves {octaves}: expected a finite turbulence and 1 to 16 octaves"
            ),
        ));
    }
    Ok(())
}

/// Marble: veins across `direction`, `sin(2π·(p·d)/period + turbulence ·
/// turb(p/noise_scale))`, mapped from `[-1, 1]` onto `vein` … `stone`.
#[derive(Clone, Debug, PartialEq)]
pub struct Marble {
    noise: Perlin,
    direction: DVec3,
    period: f64,
    noise_scale: f64,
    turbulence: f64,
    octaves: u32,
    colors: [[u8; 3]; 2],
}

impl Marble {
    /// Marble with veins repeating every `period` world units along
    /// `direction`, distorted by `turbulence` × the turbulence of the
    /// noise at scale `noise_scale` (world units per noise cell) over
    /// `octaves` octaves; colours `[vein, stone]`.
    ///
    /// # Errors
    /// [`TextureError::Invalid`] for a zero direction, non-positive period
    /// or scale, or octaves outside 1..=16.
    pub fn new(
        seed: u64,
        direction: DVec3,
        period: f64,
        noise_scale: f64,
        turbulence: f64,
        octaves: u32,
        colors: [[u8; 3]; 2],
    ) -> Result<Self, TextureError> {
        check_noise_params("marble", period, turbulence, octaves, noise_scale)?;
        let direction = direction.try_normalize().ok_or_else(|| {
            invalid(
                "marble",
                format!("direction {direction} is not a usable vector"),
            )
        })?;
        Ok(Self {
            noise: Perlin::new(seed),
            direction,
            period,
            noise_scale,
            turbulence,
            octaves,
            colors,
        })
    }
}

impl WorldTexture for Marble {
    fn world_color(&self, p: DVec3, _n: DVec3, _base: [u8; 3]) -> [u8; 3] {
        let t = self.noise.turbulence(p / self.noise_scale, self.octaves);
        let s = (TAU * p.dot(self.direction) / self.period + self.turbulence * t).sin();
        mix(self.colors[0], self.colors[1], (s + 1.0) / 2.0)
    }
}

/// Wood: rings around an axis every `period` world units, each ring a
/// ramp from `early` to `late` wood, the radius disturbed by noise.
#[derive(Clone, Debug, PartialEq)]
pub struct Wood {
    noise: Perlin,
    origin: DVec3,
    axis: DVec3,
    period: f64,
    noise_scale: f64,
    turbulence: f64,
    octaves: u32,
    colors: [[u8; 3]; 2],
}

impl Wood {
    /// Wood with rings around the line through `origin` along `axis`,
    /// `period` apart, their radius disturbed by `turbulence · period` ×
    /// the turbulence at scale `noise_scale`; colours `[early, late]`.
    ///
    /// # Errors
    /// As [`Marble::new`].
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        seed: u64,
        origin: DVec3,
        axis: DVec3,
        period: f64,
        noise_scale: f64,
        turbulence: f64,
        octaves: u32,
        colors: [[u8; 3]; 2],
    ) -> Result<Self, TextureError> {
        check_noise_params("wood", period, turbulence, octaves, noise_scale)?;
        let axis = axis
            .try_normalize()
            .ok_or_else(|| invalid("wood", format!("axis {axis} is not a usable vector")))?;
        if !origin.is_finite() {
            return Err(invalid("wood", format!("origin {origin} is not finite")));
        }
        Ok(Self {
            noise: Perlin::new(seed),
            origin,
            axis,
            period,
            noise_scale,
            turbulence,
            octaves,
            colors,
        })
    }

    /// Position within the ring at `p`, in `[0, 1)`.
    #[must_use]
    pub fn ring_phase(&self, p: DVec3) -> f64 {
        let d = p - self.origin;
        let r = (d - self.axis * d.dot(self.axis)).length();
        let t = r / self.period
            + self.turbulence * self.noise.turbulence(p / self.noise_scale, self.octaves);
        t - t.floor()
    }
}

impl WorldTexture for Wood {
    fn world_color(&self, p: DVec3, _n: DVec3, _base: [u8; 3]) -> [u8; 3] {
        // Early wood for the first three quarters of a ring, then a ramp
        // to late wood.
        let f = self.ring_phase(p);
        mix(self.colors[0], self.colors[1], (f - 0.75) / 0.25)
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn perlin_is_zero_on_the_lattice_and_bounded() {
        let n = Perlin::new(7);
        assert_eq!(n.noise(DVec3::new(3.0, -2.0, 5.0)), 0.0);
        let mut max: f64 = 0.0;
        for i in 0..2000 {
            let p = DVec3::new(i as f64 * 0.137, i as f64 * 0.071 - 9.0, i as f64 * 0.019);
            max = max.max(n.noise(p).abs());
        }
        assert!(max > 0.2 && max <= 1.1, "{max}");
        assert_ne!(Perlin::new(1), Perlin::new(2));
    }

    #[test]
    fn wrap_rules() {
        assert_eq!(Wrap::Repeat.apply(1.25), 0.25);
        assert_eq!(Wrap::Repeat.apply(-0.25), 0.75);
        assert_eq!(Wrap::Mirror.apply(1.25), 0.75);
        assert_eq!(Wrap::Clamp.apply(-3.0), 0.0);
    }
}
