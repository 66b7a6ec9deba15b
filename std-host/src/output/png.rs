//! PNG: 8- or 16-bit RGB, sRGB-encoded with an `sRGB` chunk (rendering
//! intent perceptual), or the linear values without a colour chunk. The
//! linear 8-bit form is exactly what [`png_bytes`] gives. Encoding is
//! deterministic (fixed compression level and filter).

use std::io::Write;

use image::ImageEncoder;
use image::codecs::png::PngEncoder;

use super::encoding::{Codes, Encoding, codes};
use crate::render::Image;

/// Encodes `image` as PNG into `w`.
///
/// # Errors
/// The encoder's or the writer's error.
pub fn write(image: &Image, enc: Encoding, w: &mut impl Write) -> Result<(), png::EncodingError> {
    if enc.bits == 8 && enc.linear {
        return PngEncoder::new(w)
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
    e.set_compression(png::Compression::Balanced);
    e.set_filter(png::Filter::Adaptive);
    if !enc.linear {
        e.set_source_srgb(png::SrgbRenderingIntent::Perceptual);
    }
    let mut writer = e.write_header()?;
    writer.write_image_data(&c.big_endian())?;
    writer.finish()
}

/// Encodes `image` as linear 8-bit PNG bytes in memory, exactly as
/// [`write`] with `linear` 8-bit does (for tests and comparisons).
///
/// # Errors
/// The encoder's error.
pub fn png_bytes(image: &Image) -> Result<Vec<u8>, image::ImageError> {
    let mut out = Vec::new();
    PngEncoder::new(&mut out).write_image(
        &image.rgb,
        image.width,
        image.height,
        image::ExtendedColorType::Rgb8,
    )?;
    Ok(out)
}
