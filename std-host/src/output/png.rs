//! PNG: 8- or 16-bit RGB, sRGB-encoded with an `sRGB` chunk (rendering
//! intent perceptual), or the linear values without a colour chunk. The
//! linear 8-bit form is exactly what [`png_bytes`] gives. Encoding is
//! deterministic: the fast deflate level (larger files than the balanced
//! one, encoded in a fraction of its time) and adaptive filtering, fixed.

use std::io::Write;

use image::ImageEncoder;
use image::codecs::png::{CompressionType, FilterType, PngEncoder};

use super::encoding::{Codes, Encoding, codes};
use crate::render::Image;

/// Encodes `image` as PNG into `w`.
///
/// # Errors
/// The encoder's or the writer's error.
pub fn write(image: &Image, enc: Encoding, w: &mut impl Write) -> Result<(), png::EncodingError> {
    if enc.bits == 8 && enc.linear {
        return encoder(w)
            .write_image(
                &image.rgb,
                image.width,
                image.height,
                image::ExtendedColorType::Rgb8,
            )
            .map_err(|e| match e {
                image::ImageError::IoError(io) => png::EncodingError::IoError(io),
                other => png::EncodingError::IoError(std::io::Error::other(other)),
            });
    }
    let c = codes(image, enc);
    let mut e = png::Encoder::new(w, image.width, image.height);
    e.set_color(png::ColorType::Rgb);
    e.set_depth(match c {
        Codes::Eight(_) => png::BitDepth::Eight,
        Codes::Sixteen(_) => png::BitDepth::Sixteen,
    });
    e.set_compression(png::Compression::Fast);
    e.set_filter(png::Filter::Adaptive);
    if !enc.linear {
        e.set_source_srgb(png::SrgbRenderingIntent::Perceptual);
    }
    let mut writer = e.write_header()?;
    writer.write_image_data(&c.big_endian())?;
    writer.finish()
}

/// The `image` crate's PNG encoder at the same settings as the sRGB path.
fn encoder<W: Write>(w: W) -> PngEncoder<W> {
    PngEncoder::new_with_quality(w, CompressionType::Fast, FilterType::Adaptive)
}

/// Encodes `image` as linear 8-bit PNG bytes in memory, exactly as
/// [`write`] with `linear` 8-bit does (for tests and comparisons).
///
/// # Errors
/// The encoder's error.
pub fn png_bytes(image: &Image) -> Result<Vec<u8>, image::ImageError> {
    let mut out = Vec::new();
    encoder(&mut out).write_image(
        &image.rgb,
        image.width,
        image.height,
        image::ExtendedColorType::Rgb8,
    )?;
    Ok(out)
}
