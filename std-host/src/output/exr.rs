//! OpenEXR: one RGB layer of 32-bit floats, linear and unclamped, the
//! `exr` crate's default lossless compression, written single-threaded so
//! the bytes depend only on the image.

use std::io::{Cursor, Write};

use exr::prelude::{Image as ExrImage, SpecificChannels, Vec2, WritableImage};

use crate::render::Image;

/// Writes `image` as OpenEXR into `w` (encoded in memory first: the
/// encoder needs to seek).
///
/// # Errors
/// The encoder's or the writer's error.
pub fn write(image: &Image, w: &mut impl Write) -> Result<(), exr::error::Error> {
    let width = image.width as usize;
    let px = |Vec2(x, y): Vec2<usize>| {
        let i = 3 * (y * width + x);
        (image.linear[i], image.linear[i + 1], image.linear[i + 2])
    };
    let channels = SpecificChannels::rgb(px);
    let exr = ExrImage::from_channels((width, image.height as usize), channels);
    let mut buf = Cursor::new(Vec::new());
    exr.write().non_parallel().to_buffered(&mut buf)?;
    w.write_all(buf.get_ref())?;
    Ok(())
}
