//! Image maps: a 2D image wrapped onto surfaces by a planar, cylindrical
//! or spherical mapping, looked up bilinearly between pixel centres.

use std::f64::consts::{PI, TAU};
use std::path::Path;

use glam::DVec3;

use super::{TextureError, WorldTexture, invalid};

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
        for (name, v) in self.named_vectors() {
            if !v.is_finite() {
                return Err(invalid(name, format!("{v} is not finite")));
            }
        }
        let usable = match *self {
            Self::Planar { u_axis, v_axis, .. } => {
                if u_axis.length_squared() == 0.0 || v_axis.length_squared() == 0.0 {
                    Err("the u and v axes must be non-zero")
                } else if u_axis.cross(v_axis).length() <= 1e-12 * u_axis.length() * v_axis.length()
                {
                    Err("the u and v axes are parallel")
                } else {
                    Ok(())
                }
            }
            Self::Cylindrical {
                axis, reference, ..
            } => frame_of(axis, reference)
                .map(|_| ())
                .ok_or("the axis must be non-zero and the reference not along it"),
            Self::Spherical {
                pole, reference, ..
            } => frame_of(pole, reference)
                .map(|_| ())
                .ok_or("the pole must be non-zero and the reference not along it"),
        };
        usable.map_err(|why| invalid(self.name(), why.into()))
    }

    /// The mapping's kind, as its parameters are named.
    fn name(&self) -> &'static str {
        match self {
            Self::Planar { .. } => "planar mapping",
            Self::Cylindrical { .. } => "cylindrical mapping",
            Self::Spherical { .. } => "spherical mapping",
        }
    }

    /// The mapping's vectors, each with its parameter's name.
    fn named_vectors(&self) -> [(&'static str, DVec3); 3] {
        match *self {
            Self::Planar {
                origin,
                u_axis,
                v_axis,
            } => [
                ("planar mapping origin", origin),
                ("planar mapping u axis", u_axis),
                ("planar mapping v axis", v_axis),
            ],
            Self::Cylindrical {
                origin,
                axis,
                reference,
            } => [
                ("cylindrical mapping origin", origin),
                ("cylindrical mapping axis", axis),
                ("cylindrical mapping reference", reference),
            ],
            Self::Spherical {
                centre,
                pole,
                reference,
            } => [
                ("spherical mapping centre", centre),
                ("spherical mapping pole", pole),
                ("spherical mapping reference", reference),
            ],
        }
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
    /// not a PNG or JPEG, [`TextureError::TooLarge`] for one above
    /// [`MAX_IMAGE_PIXELS`] (refused from its header), [`TextureError::Decode`]
    /// for a damaged one, [`TextureError::Invalid`] for a bad mapping.
    pub fn open(path: impl AsRef<Path>, mapping: Mapping) -> Result<Self, TextureError> {
        Self::open_within(path, mapping, u64::MAX)
    }

    /// [`ImageTexture::open`], refusing an image that would take more than
    /// `max_memory` bytes while it is read and decoded (the file, the
    /// decoder's pixels and the texture's: [`ImageTexture::decode_bytes`]),
    /// told from the file's size and the image's header before its pixels
    /// are decoded.
    ///
    /// # Errors
    /// As [`ImageTexture::open`], and [`TextureError::TooMuchMemory`].
    pub fn open_within(
        path: impl AsRef<Path>,
        mapping: Mapping,
        max_memory: u64,
    ) -> Result<Self, TextureError> {
        let path = path.as_ref();
        let io = |source| TextureError::Io {
            path: path.to_path_buf(),
            source,
        };
        let size = std::fs::metadata(path).map_err(io)?.len();
        if size > max_memory {
            return Err(TextureError::TooMuchMemory {
                path: path.to_path_buf(),
                what: format!("the file of {size} bytes"),
                bytes: size,
                limit: max_memory,
            });
        }
        let bytes = std::fs::read(path).map_err(io)?;
        Self::decode_within(path, &bytes, mapping, max_memory)
    }

    /// Bytes that decoding a `width`×`height` image whose decoder gives
    /// `decoded` bytes of pixels takes at its peak, beside the file's
    /// bytes: the decoder's pixels, their 8-bit RGB form and the
    /// texture's pixels (3 bytes each).
    #[must_use]
    pub fn decode_bytes(width: u32, height: u32, decoded: u64) -> u64 {
        let rgb = u64::from(width)
            .saturating_mul(u64::from(height))
            .saturating_mul(3);
        decoded.saturating_add(rgb.saturating_mul(2))
    }

    /// The bytes the texture's pixels take.
    #[must_use]
    pub fn bytes(&self) -> u64 {
        (self.pixels.len() as u64).saturating_mul(3)
    }

    /// Decodes a PNG or JPEG held in memory, named `path` in errors.
    ///
    /// # Errors
    /// As [`ImageTexture::open`].
    pub fn from_bytes(path: &Path, bytes: &[u8], mapping: Mapping) -> Result<Self, TextureError> {
        Self::decode_within(path, bytes, mapping, u64::MAX)
    }

    /// [`ImageTexture::from_bytes`] within `max_memory`, `bytes` included
    /// ([`ImageTexture::open_within`]).
    fn decode_within(
        path: &Path,
        bytes: &[u8],
        mapping: Mapping,
        max_memory: u64,
    ) -> Result<Self, TextureError> {
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
        let reader = || {
            let mut reader = image::ImageReader::with_format(std::io::Cursor::new(bytes), format);
            let mut limits = image::Limits::default();
            limits.max_alloc = Some(MAX_IMAGE_PIXELS * 4);
            reader.limits(limits);
            reader
        };
        let decode_err = |source| TextureError::Decode {
            path: path.to_path_buf(),
            source,
        };
        // The size from the header, before anything is decoded.
        let decoder = reader().into_decoder().map_err(decode_err)?;
        let (width, height) = image::ImageDecoder::dimensions(&decoder);
        let decoded = image::ImageDecoder::total_bytes(&decoder);
        drop(decoder);
        if u64::from(width) * u64::from(height) > MAX_IMAGE_PIXELS {
            return Err(TextureError::TooLarge {
                path: path.to_path_buf(),
                width,
                height,
            });
        }
        let need = (bytes.len() as u64).saturating_add(Self::decode_bytes(width, height, decoded));
        if need > max_memory {
            return Err(TextureError::TooMuchMemory {
                path: path.to_path_buf(),
                what: format!("the {width}×{height} image"),
                bytes: need,
                limit: max_memory,
            });
        }
        let rgb = reader().decode().map_err(decode_err)?.into_rgb8();
        let (width, height) = rgb.dimensions();
        let pixels = rgb
            .as_raw()
            .chunks_exact(3)
            .map(|p| [p[0], p[1], p[2]])
            .collect();
        drop(rgb);
        Self::from_rgb(width, height, pixels, mapping)
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

#[cfg(test)]
mod tests {
    use super::*;

    /// The signature and header chunk of a PNG of `width`×`height`
    /// `depth`-bit gray pixels, a data chunk of no pixels (an empty zlib
    /// stream) and the end chunk.
    fn png_header(width: u32, height: u32, depth: u8) -> Vec<u8> {
        fn crc32(bytes: &[u8]) -> u32 {
            let mut c = u32::MAX;
            for &b in bytes {
                c ^= u32::from(b);
                for _ in 0..8 {
                    c = if c & 1 != 0 {
                        0xedb8_8320 ^ (c >> 1)
                    } else {
                        c >> 1
                    };
                }
            }
            !c
        }
        let chunk = |kind: &[u8], data: &[u8]| {
            let mut body = kind.to_vec();
            body.extend_from_slice(data);
            let mut out = u32::try_from(data.len()).unwrap().to_be_bytes().to_vec();
            out.extend_from_slice(&body);
            out.extend_from_slice(&crc32(&body).to_be_bytes());
            out
        };
        let mut ihdr = width.to_be_bytes().to_vec();
        ihdr.extend_from_slice(&height.to_be_bytes());
        ihdr.extend_from_slice(&[depth, 0, 0, 0, 0]);
        let mut png = b"\x89PNG\r\n\x1a\n".to_vec();
        png.extend(chunk(b"IHDR", &ihdr));
        png.extend(chunk(
            b"IDAT",
            &[0x78, 0x9c, 0x03, 0x00, 0x00, 0x00, 0x00, 0x01],
        ));
        png.extend(chunk(b"IEND", &[]));
        png
    }

    /// An image whose header says it has more than [`MAX_IMAGE_PIXELS`]
    /// pixels (a few bytes of PNG, gigabytes decoded) is refused before
    /// anything is decoded, naming the file and the size.
    #[test]
    fn an_image_above_the_pixel_limit_is_refused_from_its_header() {
        let mapping = Mapping::Planar {
            origin: DVec3::ZERO,
            u_axis: DVec3::X,
            v_axis: DVec3::Y,
        };
        let path = Path::new("huge.png");
        let err = ImageTexture::from_bytes(path, &png_header(23_000, 23_000, 16), mapping)
            .expect_err("refused");
        assert!(
            matches!(
                err,
                TextureError::TooLarge {
                    width: 23_000,
                    height: 23_000,
                    ..
                }
            ),
            "{err}"
        );
        assert!(
            err.to_string()
                .starts_with("huge.png: the image is 23000×23000"),
            "{err}"
        );
        // At the limit the header passes, and the missing pixels are a
        // decoding error.
        let err = ImageTexture::from_bytes(path, &png_header(16_384, 16_384, 8), mapping)
            .expect_err("refused");
        assert!(matches!(err, TextureError::Decode { .. }), "{err}");
    }

    #[test]
    fn wrap_rules() {
        assert_eq!(Wrap::Repeat.apply(1.25), 0.25);
        assert_eq!(Wrap::Repeat.apply(-0.25), 0.75);
        assert_eq!(Wrap::Mirror.apply(1.25), 0.75);
        assert_eq!(Wrap::Clamp.apply(-3.0), 0.0);
    }
}
