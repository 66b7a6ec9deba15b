//! The Netpbm formats: binary PPM (`P6`, 8- or 16-bit big-endian samples,
//! encoded as for PNG) and the Portable Float Map (`PF`, 32-bit
//! little-endian floats, linear and unclamped, rows bottom to top as the
//! format defines).

use std::io::{self, Write};

use super::encoding::{Encoding, codes};
use crate::render::Image;

/// Writes `image` as binary PPM.
///
/// # Errors
/// The writer's error.
pub fn write_ppm(image: &Image, enc: Encoding, w: &mut impl Write) -> io::Result<()> {
    let c = codes(image, enc);
    let max = if enc.bits == 16 { 65535 } else { 255 };
    write!(w, "P6\n{} {}\n{max}\n", image.width, image.height)?;
    w.write_all(&c.big_endian())
}

/// Writes `image` as a Portable Float Map (scale -1: little-endian).
///
/// # Errors
/// The writer's error.
pub fn write_pfm(image: &Image, w: &mut impl Write) -> io::Result<()> {
    write!(w, "PF\n{} {}\n-1.0\n", image.width, image.height)?;
    let row = 3 * image.width as usize;
    if row == 0 {
        return Ok(());
    }
    let mut bytes = Vec::with_capacity(4 * row);
    for r in image.linear.chunks(row).rev() {
        bytes.clear();
        bytes.extend(r.iter().flat_map(|v| v.to_le_bytes()));
        w.write_all(&bytes)?;
    }
    Ok(())
}
