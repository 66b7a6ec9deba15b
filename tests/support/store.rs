//! One textured object through the core's two-pass record builder, over
//! owned storage: what the texture and `.vox` tests read back.

use rrt_core::raster::{Extent, RasterMut};
use rrt_core::store::{Counter, Limits, ObjectAttrs, RecordStore, Texture, directory_len};
use rrt_core::voxel::VoxelRecord;
use rrt_core::voxelize::VoxelSink;

/// A built raster of one object, owning its buffers.
pub struct OneObject {
    /// The raster's extent.
    pub extent: Extent,
    /// The plane.
    pub plane: Vec<u8>,
    /// The brick directory.
    pub dir: Vec<u32>,
    /// The records.
    pub records: Vec<VoxelRecord>,
}

impl OneObject {
    /// Builds object 0 (material 0, base colour `color`): `voxelize` offers
    /// its voxels in both passes, the fill pass through `texture`.
    ///
    /// # Panics
    /// If the builder refuses it.
    pub fn textured(
        extent: Extent,
        color: [u8; 3],
        texture: &impl Texture,
        voxelize: impl Fn(&mut dyn VoxelSink),
    ) -> Self {
        let mut plane = vec![0u8; extent.len()];
        let mut dir = vec![0u32; directory_len(extent).unwrap()];
        let mut counter =
            Counter::new(RasterMut::new(extent, &mut plane).unwrap(), &mut dir).unwrap();
        voxelize(&mut counter);
        let sizing = counter.finish().unwrap();
        let mut records = vec![VoxelRecord::default(); sizing.records()];
        let limits = Limits {
            objects: 1,
            materials: 1,
        };
        let mut filler = sizing.fill(&mut records, limits).unwrap();
        let attrs = ObjectAttrs {
            object: 0,
            material: 0,
            color,
        };
        filler.begin_object(attrs).unwrap();
        voxelize(&mut filler.textured(texture));
        filler.finish().unwrap();
        Self {
            extent,
            plane,
            dir,
            records,
        }
    }

    /// The record store.
    ///
    /// # Panics
    /// Never for a store the builder made.
    #[must_use]
    pub fn store(&self) -> RecordStore<'_> {
        RecordStore::new(self.extent, &self.dir, &self.records).unwrap()
    }
}
