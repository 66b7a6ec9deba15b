//! How the integer image formats (PNG, PPM) encode linear values: sRGB
//! (the exact IEC 61966-2-1 transfer function) or linear, 8 or 16 bits,
//! clamped to `[0, 1]` and rounded to nearest.

use crate::render::Image;

/// How integer formats encode the values.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Encoding {
    /// Bits per channel: 8 or 16 (integer formats only).
    pub bits: u8,
    /// Write the linear values rather than sRGB-encoded ones.
    pub linear: bool,
}

impl Default for Encoding {
    fn default() -> Self {
        Self {
            bits: 8,
            linear: false,
        }
    }
}

/// The exact sRGB encoding (IEC 61966-2-1) of a linear value, clamped to
/// `[0, 1]`; NaN gives 0.
///
/// ```
/// use rrt_host::output::encoding::srgb_encode;
/// assert_eq!(srgb_encode(0.0), 0.0);
/// assert_eq!(srgb_encode(1.0), 1.0);
/// assert!((srgb_encode(0.5) - 0.735_356_98).abs() < 1e-8);
/// ```
#[must_use]
pub fn srgb_encode(v: f64) -> f64 {
    if v.is_nan() || v <= 0.0 {
        return 0.0;
    }
    if v >= 1.0 {
        return 1.0;
    }
    if v <= 0.003_130_8 {
        12.92 * v
    } else {
        1.055 * v.powf(1.0 / 2.4) - 0.055
    }
}

/// One linear value to an integer code in `0..=max`: sRGB-encoded unless
/// `linear`, clamped, rounded to nearest.
#[must_use]
pub fn quantize(v: f32, linear: bool, max: u16) -> u16 {
    let v = f64::from(v);
    let e = if linear {
        if v.is_nan() { 0.0 } else { v.clamp(0.0, 1.0) }
    } else {
        srgb_encode(v)
    };
    // In [0.5, max + 0.5]: the truncation cannot overflow.
    (e * f64::from(max) + 0.5) as u16
}

/// The image's samples as 8-bit codes (`linear` 8-bit: [`Image::rgb`]
/// exactly) or 16-bit codes, row by row.
#[must_use]
pub fn codes(image: &Image, enc: Encoding) -> Codes {
    match (enc.bits, enc.linear) {
        (8, true) => Codes::Eight(image.rgb.clone()),
        (8, false) => Codes::Eight(
            image
                .linear
                .iter()
                .map(|&v| quantize(v, false, 255) as u8)
                .collect(),
        ),
        _ => Codes::Sixteen(
            image
                .linear
                .iter()
                .map(|&v| quantize(v, enc.linear, u16::MAX))
                .collect(),
        ),
    }
}

/// Integer samples of an image.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Codes {
    /// 8 bits per channel.
    Eight(Vec<u8>),
    /// 16 bits per channel.
    Sixteen(Vec<u16>),
}

impl Codes {
    /// The samples as big-endian bytes (PNG and PPM order).
    #[must_use]
    pub fn big_endian(&self) -> Vec<u8> {
        match self {
            Self::Eight(v) => v.clone(),
            Self::Sixteen(v) => v.iter().flat_map(|c| c.to_be_bytes()).collect(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn srgb_is_exact_and_monotone() {
        // The linear segment and the curve meet at 0.0031308.
        assert!((srgb_encode(0.003_130_8) - 0.040_449_936).abs() < 1e-8);
        assert_eq!(quantize(0.5, false, 255), 188);
        assert_eq!(quantize(0.5, true, 255), 128);
        assert_eq!(quantize(f32::NAN, false, 255), 0);
        assert_eq!(quantize(7.0, false, u16::MAX), u16::MAX);
        let mut last = 0;
        for i in 0..=4096 {
            let c = quantize(i as f32 / 4096.0, false, u16::MAX);
            assert!(c >= last);
            last = c;
        }
    }
}
