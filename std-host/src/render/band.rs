//! Horizontal bands of an image, rendered as independent jobs and joined
//! by `rrt stitch`.
//!
//! Band `i` of `n` (numbered from 0, the top band) of an image `h` rows
//! high holds rows `⌊i·h/n⌋` to `⌊(i+1)·h/n⌋` (end excluded): the bands
//! cover every row once, in order, and their heights differ by at most
//! one row. The split depends only on `i`, `n` and `h`.

use std::ops::Range;

/// Band `index` of `count` horizontal bands of an image.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Band {
    /// Which band, from 0 (the top one) to `count − 1`.
    pub index: u32,
    /// How many bands the image is cut into.
    pub count: u32,
}

/// Why a band cannot be cut.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum BandError {
    /// No bands.
    #[error("expected at least 1 band, found 0")]
    NoBands,
    /// The index is not below the count.
    #[error("band {index} of {count} does not exist: bands are numbered 0 (the top one) to {last}", last = count - 1)]
    Index {
        /// The index asked for.
        index: u32,
        /// The count.
        count: u32,
    },
    /// More bands than rows.
    #[error("{count} bands of an image {height} rows high: at most one band per row")]
    TooMany {
        /// The count.
        count: u32,
        /// The image's height.
        height: u32,
    },
}

impl Band {
    /// Band `index` of `count`, checked against an image `height` rows
    /// high.
    ///
    /// # Errors
    /// [`BandError`]: no bands, the index out of range, more bands than
    /// rows.
    pub fn new(index: u32, count: u32, height: u32) -> Result<Self, BandError> {
        if count == 0 {
            return Err(BandError::NoBands);
        }
        if index >= count {
            return Err(BandError::Index { index, count });
        }
        if count > height {
            return Err(BandError::TooMany { count, height });
        }
        Ok(Self { index, count })
    }

    /// The rows of an image `height` rows high that the band holds.
    ///
    /// ```
    /// use rrt_host::render::band::Band;
    /// let rows: Vec<_> = (0..3).map(|i| Band::new(i, 3, 10).unwrap().rows(10)).collect();
    /// assert_eq!(rows, [0..3, 3..6, 6..10]);
    /// ```
    #[must_use]
    pub fn rows(self, height: u32) -> Range<u32> {
        let at = |i: u32| {
            let r = u64::from(i) * u64::from(height) / u64::from(self.count.max(1));
            u32::try_from(r).unwrap_or(height)
        };
        at(self.index)..at(self.index.saturating_add(1))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bands_cover_every_row_once_in_order() {
        for h in [1u32, 2, 7, 8, 23, 100, 32768] {
            for n in [1u32, 2, 3, 7, 8, 23, 100].into_iter().filter(|&n| n <= h) {
                let mut next = 0;
                let (mut lo, mut hi) = (u32::MAX, 0);
                for i in 0..n {
                    let r = Band::new(i, n, h).unwrap().rows(h);
                    assert_eq!(r.start, next, "h {h} n {n} i {i}");
                    assert!(!r.is_empty());
                    lo = lo.min(r.len() as u32);
                    hi = hi.max(r.len() as u32);
                    next = r.end;
                }
                assert_eq!(next, h);
                assert!(hi - lo <= 1, "h {h} n {n}: {lo}..{hi}");
            }
        }
    }

    #[test]
    fn bad_bands_are_refused() {
        assert_eq!(Band::new(0, 0, 10), Err(BandError::NoBands));
        let e = Band::new(4, 4, 10).unwrap_err();
        assert_eq!(
            e.to_string(),
            "band 4 of 4 does not exist: bands are numbered 0 (the top one) to 3"
        );
        assert_eq!(
            Band::new(0, 11, 10),
            Err(BandError::TooMany {
                count: 11,
                height: 10
            })
        );
        assert!(Band::new(u32::MAX - 1, u32::MAX, 10).is_err());
    }
}
