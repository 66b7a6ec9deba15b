//! The Netpbm formats: binary PPM (`P6`, 8- or 16-bit big-endian samples,
//! encoded as for PNG) and the Portable Float Map (`PF`, 32-bit
//! little-endian floats, linear and unclamped, rows bottom to top as the
//! format defines). A band of an image (`rrt render --tile`) says which in
//! a PPM header comment, `# rrt band …` after the magic number; PFM has no
//! place for it.

use std::io::{self, Write};

use super::encoding::{Codes, Encoding, codes};
use crate::render::Image;

/// What starts the PPM header comment naming a band.
pub const BAND_COMMENT: &str = "# rrt ";

/// Writes `image` as binary PPM.
///
/// # Errors
/// The writer's error.
pub fn write_ppm(image: &Image, enc: Encoding, w: &mut impl Write) -> io::Result<()> {
    write_ppm_codes(image.width, image.height, &codes(image, enc), None, w)
}

/// Writes `width × height` pixels of integer codes as binary PPM, with
/// `band` in a header comment ([`BAND_COMMENT`]) when given.
///
/// # Errors
/// The writer's error.
pub fn write_ppm_codes(
    width: u32,
    height: u32,
    codes: &Codes,
    band: Option<&str>,
    w: &mut impl Write,
) -> io::Result<()> {
    let max = match codes {
        Codes::Eight(_) => 255,
        Codes::Sixteen(_) => 65535,
    };
    w.write_all(b"P6\n")?;
    if let Some(text) = band {
        writeln!(w, "{BAND_COMMENT}{text}")?;
    }
    write!(w, "{width} {height}\n{max}\n")?;
    w.write_all(&codes.big_endian())
}

/// Writes `image` as a Portable Float Map (scale -1: little-endian).
///
/// # Errors
/// The writer's error.
pub fn write_pfm(image: &Image, w: &mut impl Write) -> io::Result<()> {
    write_pfm_floats(image.width, image.height, &image.linear, w)
}

/// Writes `width × height` pixels of linear floats, rows top to bottom,
/// as a Portable Float Map.
///
/// # Errors
/// The writer's error.
pub fn write_pfm_floats(
    width: u32,
    height: u32,
    linear: &[f32],
    w: &mut impl Write,
) -> io::Result<()> {
    write!(w, "PF\n{width} {height}\n-1.0\n")?;
    let row = 3 * width as usize;
    if row == 0 {
        return Ok(());
    }
    let mut bytes = Vec::with_capacity(4 * row);
    for r in linear.chunks(row).rev() {
        bytes.clear();
        bytes.extend(r.iter().flat_map(|v| v.to_le_bytes()));
        w.write_all(&bytes)?;
    }
    Ok(())
}
