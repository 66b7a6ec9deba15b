//! Memory for the raster plane: an anonymous memory map asking the kernel
//! for transparent huge pages.
//!
//! The plane is one byte per voxel (a 2048³ raster is 8 GiB) and discrete
//! rays read it in long strides, so TLB misses dominate a cold walk; 2 MiB
//! pages cut them. The pages come zeroed and are only backed by memory
//! when touched. `madvise` is a hint: where huge pages are unavailable the
//! map works with normal pages.

use std::ops::{Deref, DerefMut};

use memmap2::{Advice, MmapMut, MmapOptions};

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
        // A hint only: keep going with normal pages where it is refused.
        let _ = map.advise(Advice::HugePage);
        Ok(Self { map })
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
