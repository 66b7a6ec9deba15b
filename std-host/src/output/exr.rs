//! OpenEXR: one RGB layer of 32-bit floats, linear and unclamped, the
//! `exr` crate's default lossless compression, written single-threaded so
//! the bytes depend only on the image. A band of an image (`rrt render
//! --tile`) says which in one text attribute, [`BAND_ATTRIBUTE`], of the
//! layer.

use std::io::{Cursor, Write};

use exr::meta::attribute::{AttributeValue, Text};
use exr::prelude::{
    Encoding, Image as ExrImage, Layer, LayerAttributes, SpecificChannels, Vec2, WritableImage,
};

use crate::render::Image;

/// The name of the text attribute naming a band.
pub const BAND_ATTRIBUTE: &str = "rrtBand";

/// Writes `image` as OpenEXR into `w` (encoded in memory first: the
/// encoder needs to seek).
///
/// # Errors
/// The encoder's or the writer's error.
pub fn write(image: &Image, w: &mut impl Write) -> Result<(), exr::error::Error> {
    write_floats(image.width, image.height, &image.linear, None, w)
}

/// Writes `width × height` pixels of linear floats (rows top to bottom)
/// as OpenEXR, with `band` in the [`BAND_ATTRIBUTE`] attribute when
/// given. Without `band`, the bytes are [`write()`]'s for an image with
/// these values.
///
/// # Errors
/// The encoder's or the writer's error; a `band` text that is not
/// Latin-1.
pub fn write_floats(
    width: u32,
    height: u32,
    linear: &[f32],
    band: Option<&str>,
    w: &mut impl Write,
) -> Result<(), exr::error::Error> {
    let width = width as usize;
    let px = |Vec2(x, y): Vec2<usize>| {
        let i = 3 * (y * width + x);
        (linear[i], linear[i + 1], linear[i + 2])
    };
    let channels = SpecificChannels::rgb(px);
    let size = (width, height as usize);
    let mut attributes = LayerAttributes::default();
    if let Some(text) = band {
        // One attribute: its map's order cannot vary.
        let text = Text::new_or_none(text)
            .ok_or_else(|| exr::error::Error::Invalid("band text not Latin-1".into()))?;
        attributes
            .other
            .insert(Text::from(BAND_ATTRIBUTE), AttributeValue::Text(text));
    }
    let exr = ExrImage::from_layer(Layer::new(size, attributes, Encoding::default(), channels));
    let mut buf = Cursor::new(Vec::new());
    exr.write().non_parallel().to_buffered(&mut buf)?;
    w.write_all(buf.get_ref())?;
    Ok(())
}
