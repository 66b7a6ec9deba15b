//! How a band file (`rrt render --tile`) says which band of which image
//! it holds, so that `rrt stitch` can check what it joins: one line of
//! ASCII text, kept where the format keeps text (a PNG `tEXt` chunk, a
//! PPM header comment, an OpenEXR attribute; PFM has none):
//!
//! ```text
//! band 1/4 rows 5..11 of 37x23, 8-bit sRGB; <render>
//! ```
//!
//! the band's index (from 0) and count, its rows (end excluded) and the
//! whole image's width and height, the samples' kind, and a description
//! of the render that every band of one image shares (the view, the
//! sampling, the mode, the raster, the scene's fingerprint).

use std::fmt;

use super::encoding::SampleKind;
use crate::render::band::Band;
use crate::render::check_sizes;

/// Which band of which image a file holds.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct BandTag {
    /// The band.
    pub band: Band,
    /// The whole image's width in pixels.
    pub width: u32,
    /// The whole image's height in pixels.
    pub height: u32,
    /// What the samples are.
    pub kind: SampleKind,
    /// What every band of the image shares: one line of ASCII text.
    pub render: String,
}

impl BandTag {
    /// The band's rows of the whole image.
    #[must_use]
    pub fn rows(&self) -> std::ops::Range<u32> {
        self.band.rows(self.height)
    }

    /// Reads the tag's text; `None` unless it is exactly what
    /// [`BandTag`]'s `Display` writes for a valid band.
    #[must_use]
    pub fn parse(text: &str) -> Option<Self> {
        let pair = |s: &str, sep: &str| -> Option<(u32, u32)> {
            let (a, b) = s.split_once(sep)?;
            Some((whole(a)?, whole(b)?))
        };
        let rest = text.strip_prefix("band ")?;
        let (band, rest) = rest.split_once(" rows ")?;
        let (index, count) = pair(band, "/")?;
        let (rows, rest) = rest.split_once(" of ")?;
        let (start, end) = pair(rows, "..")?;
        let (size, rest) = rest.split_once(", ")?;
        let (width, height) = pair(size, "x")?;
        let (kind, render) = rest.split_once("; ")?;
        check_sizes(width, height, 1).ok()?;
        let tag = Self {
            band: Band::new(index, count, height).ok()?,
            width,
            height,
            kind: SampleKind::parse(kind)?,
            render: render.to_string(),
        };
        let ascii_line = render.bytes().all(|b| (b' '..=b'~').contains(&b));
        (tag.rows() == (start..end) && ascii_line).then_some(tag)
    }
}

/// A whole number written in decimal digits only.
fn whole(s: &str) -> Option<u32> {
    if s.is_empty() || !s.bytes().all(|b| b.is_ascii_digit()) {
        return None;
    }
    s.parse().ok()
}

impl fmt::Display for BandTag {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let rows = self.rows();
        write!(
            f,
            "band {}/{} rows {}..{} of {}x{}, {}; {}",
            self.band.index,
            self.band.count,
            rows.start,
            rows.end,
            self.width,
            self.height,
            self.kind,
            self.render
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::output::encoding::Encoding;

    #[test]
    fn the_text_reads_back() {
        let tag = BandTag {
            band: Band::new(1, 4, 23).unwrap(),
            width: 37,
            height: 23,
            kind: SampleKind::Codes(Encoding::default()),
            render: "view from 0,-4,1; supersample 2".to_string(),
        };
        let text = tag.to_string();
        assert_eq!(
            text,
            "band 1/4 rows 5..11 of 37x23, 8-bit sRGB; view from 0,-4,1; supersample 2"
        );
        assert_eq!(BandTag::parse(&text), Some(tag));
        for bad in [
            "",
            "band 1/4 rows 5..12 of 37x23, 8-bit sRGB; x",
            "band 4/4 rows 23..23 of 37x23, 8-bit sRGB; x",
            "band 1/4 rows 5..11 of 37x23, 9-bit sRGB; x",
            "band 1/4 rows 5..11 of 0x23, 8-bit sRGB; x",
            "band +1/4 rows 5..11 of 37x23, 8-bit sRGB; x",
            "band 1/4 rows 5..11 of 37x23, 8-bit sRGB; x\ny",
        ] {
            assert_eq!(BandTag::parse(bad), None, "{bad}");
        }
    }
}
