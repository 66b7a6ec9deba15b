//! How the integer image formats (PNG, PPM) encode linear values: sRGB
//! (the exact IEC 61966-2-1 transfer function) or linear, 8 or 16 bits,
//! clamped to `[0, 1]` and rounded to nearest.

use std::borrow::Cow;
use std::fmt;

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

/// [`quantize`]`(v, false, 255)`: the 8-bit sRGB code of `v`, found among
/// the 255 smallest values of each code ([`srgb8_thresholds`]) by a
/// binary search instead of a power per value.
///
/// ```
/// use rrt_host::output::encoding::{quantize, srgb8};
/// for v in [0.0, 0.002, 0.18, 0.5, 0.99, 1.0, 3.0, -1.0, f32::NAN] {
///     assert_eq!(u16::from(srgb8(v)), quantize(v, false, 255));
/// }
/// ```
#[must_use]
pub fn srgb8(v: f32) -> u8 {
    // No threshold is ≤ NaN or below the first: code 0; all are ≤ 1.
    let above = srgb8_thresholds().partition_point(|&t| t <= v);
    u8::try_from(above).unwrap_or(u8::MAX)
}

/// For each code `c` in 1..=255, the smallest `f32` that [`quantize`]
/// encodes as sRGB code `c` or above (8 bits): started at the exact
/// decision boundary (the inverse transfer function of `(c − ½)/255`) and
/// moved by single steps of `f32` to where [`quantize`] changes, so the
/// table agrees with it at every boundary.
#[must_use]
pub fn srgb8_thresholds() -> &'static [f32; 255] {
    static TABLE: std::sync::OnceLock<[f32; 255]> = std::sync::OnceLock::new();
    TABLE.get_or_init(|| {
        let code = |v: f32| quantize(v, false, 255);
        std::array::from_fn(|i| {
            let c = u16::try_from(i + 1).unwrap_or(u16::MAX);
            let y = (f64::from(c) - 0.5) / 255.0;
            let x = if y <= 0.040_45 {
                y / 12.92
            } else {
                ((y + 0.055) / 1.055).powf(2.4)
            };
            let mut t = x as f32;
            // A few steps at most: the boundary is exact to within rounding.
            for _ in 0..64 {
                if code(t) < c {
                    t = f32::from_bits(t.to_bits() + 1);
                } else if t > 0.0 && code(f32::from_bits(t.to_bits() - 1)) >= c {
                    t = f32::from_bits(t.to_bits() - 1);
                } else {
                    break;
                }
            }
            t
        })
    })
}

/// The image's samples as 8-bit codes (`linear` 8-bit: [`Image::rgb`]
/// exactly) or 16-bit codes, row by row.
#[must_use]
pub fn codes(image: &Image, enc: Encoding) -> Codes {
    match (enc.bits, enc.linear) {
        (8, true) => Codes::Eight(image.rgb.clone()),
        (8, false) => Codes::Eight(image.linear.iter().map(|&v| srgb8(v)).collect()),
        _ => Codes::Sixteen(
            image
                .linear
                .iter()
                .map(|&v| quantize(v, enc.linear, u16::MAX))
                .collect(),
        ),
    }
}

/// The image's alpha as RGBA samples, row by row, four per pixel: the
/// straight (not premultiplied) colour ([`crate::render::Alpha::straight`]) encoded as
/// [`codes`] encodes colours (sRGB or linear), then the coverage
/// ([`crate::render::Alpha::coverage`]), always linear, as PNG's RGBA keeps it; or the
/// linear floats of both with [`SampleKind::Float`]. `None` when the image
/// was rendered without alpha.
///
/// ```
/// use rrt_host::output::encoding::{Codes, Encoding, SampleKind, Samples, rgba};
/// use rrt_host::render::{Alpha, Image};
/// let image = Image {
///     width: 2,
///     height: 1,
///     rgb: vec![0, 0, 0, 128, 128, 128],
///     linear: vec![0.0, 0.0, 0.0, 0.5, 0.5, 0.5],
///     alpha: Some(Alpha {
///         coverage: vec![0.0, 0.5],
///         straight: vec![0.0, 0.0, 0.0, 1.0, 1.0, 1.0],
///     }),
/// };
/// let linear = SampleKind::Codes(Encoding { bits: 8, linear: true });
/// assert_eq!(
///     rgba(&image, linear),
///     Some(Samples::Codes(Codes::Eight(vec![0, 0, 0, 0, 255, 255, 255, 128])))
/// );
/// ```
#[must_use]
pub fn rgba(image: &Image, kind: SampleKind) -> Option<Samples<'static>> {
    let a = image.alpha.as_ref()?;
    let pixels = a.straight.chunks_exact(3).zip(&a.coverage);
    Some(match kind {
        SampleKind::Float => Samples::Float(Cow::Owned(
            pixels
                .flat_map(|(c, &alpha)| [c[0], c[1], c[2], alpha])
                .collect(),
        )),
        SampleKind::Codes(enc) => {
            let max = if enc.bits == 8 { 255 } else { u16::MAX };
            let samples = pixels.flat_map(|(c, &alpha)| {
                let q = |v| quantize(v, enc.linear, max);
                [q(c[0]), q(c[1]), q(c[2]), quantize(alpha, true, max)]
            });
            // 8-bit codes are at most 255.
            Samples::Codes(if enc.bits == 8 {
                Codes::Eight(samples.map(|v| v as u8).collect())
            } else {
                Codes::Sixteen(samples.collect())
            })
        }
    })
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

/// What an image file's samples are: integer codes in an [`Encoding`]
/// (PNG, PPM) or 32-bit floats, linear and unclamped (OpenEXR, PFM).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SampleKind {
    /// Integer codes.
    Codes(Encoding),
    /// 32-bit floats.
    Float,
}

impl fmt::Display for SampleKind {
    /// `8-bit sRGB`, `16-bit linear`, `32-bit float`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Codes(e) => write!(
                f,
                "{}-bit {}",
                e.bits,
                if e.linear { "linear" } else { "sRGB" }
            ),
            Self::Float => f.write_str("32-bit float"),
        }
    }
}

impl SampleKind {
    /// The kind [`SampleKind`]'s `Display` names, or `None`.
    #[must_use]
    pub fn parse(s: &str) -> Option<Self> {
        let codes = |bits, linear| Some(Self::Codes(Encoding { bits, linear }));
        match s {
            "8-bit sRGB" => codes(8, false),
            "8-bit linear" => codes(8, true),
            "16-bit sRGB" => codes(16, false),
            "16-bit linear" => codes(16, true),
            "32-bit float" => Some(Self::Float),
            _ => None,
        }
    }
}

/// An image's samples as a file stores them, row by row (3 per pixel, 4
/// with alpha: [`rgba`]).
#[derive(Debug, Clone, PartialEq)]
pub enum Samples<'a> {
    /// Integer codes ([`codes`]).
    Codes(Codes),
    /// Linear, unclamped floats ([`Image::linear`]).
    Float(Cow<'a, [f32]>),
}

impl Samples<'_> {
    /// The image's samples of `kind`.
    #[must_use]
    pub fn of(image: &Image, kind: SampleKind) -> Samples<'_> {
        match kind {
            SampleKind::Codes(enc) => Samples::Codes(codes(image, enc)),
            SampleKind::Float => Samples::Float(Cow::Borrowed(&image.linear)),
        }
    }

    /// How many samples (three or four per pixel).
    #[must_use]
    pub fn len(&self) -> usize {
        match self {
            Self::Codes(Codes::Eight(v)) => v.len(),
            Self::Codes(Codes::Sixteen(v)) => v.len(),
            Self::Float(v) => v.len(),
        }
    }

    /// Whether there are none.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Appends `more`'s samples (of the same kind; `false`, and nothing
    /// appended, otherwise).
    pub fn append(&mut self, more: Samples<'_>) -> bool {
        match (self, more) {
            (Self::Codes(Codes::Eight(a)), Samples::Codes(Codes::Eight(b))) => a.extend(b),
            (Self::Codes(Codes::Sixteen(a)), Samples::Codes(Codes::Sixteen(b))) => a.extend(b),
            (Self::Float(a), Samples::Float(b)) => a.to_mut().extend_from_slice(&b),
            _ => return false,
        }
        true
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
        for k in [
            "8-bit sRGB",
            "8-bit linear",
            "16-bit sRGB",
            "16-bit linear",
            "32-bit float",
        ] {
            assert_eq!(SampleKind::parse(k).unwrap().to_string(), k);
        }
        assert_eq!(SampleKind::parse("12-bit"), None);
        for i in 0..=4096 {
            let c = quantize(i as f32 / 4096.0, false, u16::MAX);
            assert!(c >= last);
            last = c;
        }
    }

    /// The table's codes are `quantize`'s: on both sides of every
    /// threshold (eight `f32` steps each way), at every threshold's
    /// exact code, and on random values and random bit patterns (NaN,
    /// infinities and subnormals among them).
    #[test]
    fn srgb8_is_quantize() {
        let t = srgb8_thresholds();
        for (i, &x) in t.iter().enumerate() {
            assert_eq!(usize::from(srgb8(x)), i + 1, "threshold {i}");
            for k in 1..=8u32 {
                for v in [
                    f32::from_bits(x.to_bits() + k),
                    f32::from_bits(x.to_bits().saturating_sub(k)),
                ] {
                    assert_eq!(u16::from(srgb8(v)), quantize(v, false, 255), "{v:e}");
                }
            }
        }
        assert!(t.windows(2).all(|w| w[0] < w[1]));
        let mut s = 0x2545_f491_4f6c_dd1du64;
        for _ in 0..200_000 {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            let unit = (s >> 40) as f32 / (1u64 << 24) as f32 * 1.2 - 0.1;
            let bits = f32::from_bits((s >> 8) as u32);
            for v in [unit, bits] {
                assert_eq!(u16::from(srgb8(v)), quantize(v, false, 255), "{v:e}");
            }
        }
    }
}
