//! Memory for the raster plane: an anonymous memory map, with transparent
//! huge pages up to [`HUGE_PAGES_UP_TO`] bytes and normal pages beyond.
//!
//! The plane is one byte per voxel (a 2048³ raster is 8 GiB). Its pages
//! come zeroed and are only backed by memory when touched, and only the
//! rows within the distance field's reach of a surface are ever touched.
//! Discrete rays read the plane in long strides, so TLB misses dominate a
//! cold walk, and 2 MiB pages cut them; but a 2 MiB page spans whole
//! slices of a large raster, so one surface voxel brings it all in. A
//! small plane is mostly touched anyway and gets huge pages; a large one
//! gets 4 KiB pages (one or a few rows each), so that its memory follows
//! the surfaces. `madvise` is a hint: where it is refused the map works
//! with the kernel's default pages.
//!
//! A page that is read before it is first written is mapped to the
//! kernel's shared zero page, and the write then copies it, which flushes
//! that page from the TLB of every CPU the process has run on (an
//! interrupt to each, costly in a virtual machine). Where the writes to
//! come are known, [`Plane::back_for_writing`] backs their pages first.

use std::ops::{Deref, DerefMut, Range};

use memmap2::{Advice, MmapMut, MmapOptions};

/// The largest plane, in bytes, that asks for transparent huge pages.
pub const HUGE_PAGES_UP_TO: usize = 256 << 20;

/// A zero-initialised byte buffer in an anonymous memory map.
#[derive(Debug)]
pub struct Plane {
    map: MmapMut,
}

impl Plane {
    /// `len` zero bytes (at least 1).
    ///
    /// # Errors
    /// The system's refusal to map that much memory.
    pub fn zeroed(len: usize) -> std::io::Result<Self> {
        let map = MmapOptions::new().len(len.max(1)).map_anon()?;
        // A hint only: keep going with the default pages where it is
        // refused.
        let _ = map.advise(if len <= HUGE_PAGES_UP_TO {
            Advice::HugePage
        } else {
            Advice::NoHugePage
        });
        Ok(Self { map })
    }

    /// Asks the kernel to back the pages of the bytes `range` with
    /// writable memory now (`MADV_POPULATE_WRITE`), as writing each would,
    /// leaving their contents alone, in a plane of normal pages (larger
    /// than [`HUGE_PAGES_UP_TO`]). A plane of huge pages is left to its
    /// faults: its zero page is copied once per 2 MiB, and asking for its
    /// huge pages at once stalled some loads. A hint: where it is refused,
    /// or outside Linux, the pages are backed when first touched.
    pub fn back_for_writing(&self, range: Range<usize>) {
        #[cfg(target_os = "linux")]
        if !self.asks_for_huge_pages() && range.start < range.end && range.end <= self.map.len() {
            let _ =
                self.map
                    .advise_range(Advice::PopulateWrite, range.start, range.end - range.start);
        }
        #[cfg(not(target_os = "linux"))]
        let _ = range;
    }

    /// Whether the plane asked for transparent huge pages (it is at most
    /// [`HUGE_PAGES_UP_TO`] bytes long); [`Plane::back_for_writing`] then
    /// does nothing.
    #[must_use]
    pub fn asks_for_huge_pages(&self) -> bool {
        self.map.len() <= HUGE_PAGES_UP_TO
    }

    /// The plane's length in bytes.
    #[must_use]
    pub fn len(&self) -> usize {
        self.map.len()
    }

    /// Whether the plane is empty (never, by construction).
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.map.is_empty()
    }
}

impl Deref for Plane {
    type Target = [u8];
    fn deref(&self) -> &[u8] {
        &self.map
    }
}

impl DerefMut for Plane {
    fn deref_mut(&mut self) -> &mut [u8] {
        &mut self.map
    }
}
