//! PNG: 8- or 16-bit RGB, sRGB-encoded with an `sRGB` chunk (rendering
//! intent perceptual), or the linear values without a colour chunk. The
//! linear 8-bit form is exactly what [`png_bytes`] gives. Encoding is
//! deterministic: the fast deflate level (larger files than the balanced
//! one, encoded in a fraction of its time) and adaptive filtering, fixed. A band of an image
//! (`rrt render --tile`) says which in a `tEXt` chunk with the keyword
//! [`BAND_KEYWORD`].

use std::io::Write;

use image::ImageEncoder;
use image::codecs::png::PngEncoder;

use super::encoding::{Codes, Encoding, codes};
use crate::render::Image;

/// The keyword of the `tEXt` chunk naming a band.
pub const BAND_KEYWORD: &str = "rrt-band";

/// Encodes `image` as PNG into `w`.
///
/// # Errors
/// The encoder's or the writer's error.
pub fn write(image: &Image, enc: Encoding, w: &mut impl Write) -> Result<(), png::EncodingError> {
    write_codes(image.width, image.height, &codes(image, enc), enc, None, w)
}

/// Encodes `width × height` pixels of integer codes (`enc`'s bits, sRGB
/// or linear) as PNG into `w`, with `band` in a `tEXt` chunk
/// ([`BAND_KEYWORD`]) when given. Without `band`, the bytes are
/// [`write()`]'s for an image with these codes.
///
/// # Errors
/// The encoder's or the writer's error.
pub fn write_codes(
    width: u32,
    height: u32,
    codes: &Codes,
    enc: Encoding,
    band: Option<&str>,
    w: &mut impl Write,
) -> Result<(), png::EncodingError> {
    let mut e = png::Encoder::new(w, width, height);
    e.set_color(png::ColorType::Rgb);
    e.set_depth(match codes {
        Codes::Eight(_) => png::BitDepth::Eight,
        Codes::Sixteen(_) => png::BitDepth::Sixteen,
    });
    // The fast deflate level, as `image`'s encoder (for linear 8-bit PNG).
    e.set_compression(png::Compression::Fast);
    e.set_filter(png::Filter::Adaptive);
    if !enc.linear {
        e.set_source_srgb(png::SrgbRenderingIntent::Perceptual);
    }
    if let Some(text) = band {
        e.add_text_chunk(BAND_KEYWORD.to_string(), text.to_string())?;
    }
    let mut writer = e.write_header()?;
    writer.write_image_data(&codes.big_endian())?;
    writer.finish()
}

/// Encodes `image` as linear 8-bit PNG bytes in memory, exactly as
/// [`write()`] with `linear` 8-bit does (for tests and comparisons).
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
