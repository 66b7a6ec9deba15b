//! The memory estimate: an upper bound on what a voxelized raster takes,
//! from the world geometry, before anything is allocated.

use std::f64::consts::PI;
use std::fmt;

use crate::memory::Bytes;

use rrt_core::raster::LINE_CELLS;
use rrt_core::store;
use rrt_core::voxel::VoxelRecord;

use crate::frame::RasterFrame;
use crate::scene::Scene;

/// Bytes per voxel record ([`VoxelRecord`]).
pub const RECORD_BYTES: u64 = size_of::<VoxelRecord>() as u64;
/// Voxels per brick of the brick directory ([`store::BRICK_VOXELS`]).
pub const BRICK_VOXELS: u64 = store::BRICK_VOXELS as u64;
/// Bytes per brick directory entry (a `u32` record offset).
pub const BRICK_ENTRY_BYTES: u64 = size_of::<u32>() as u64;
/// Bytes per brick of the shadow classification's brick level (a plane
/// byte and a `u32` owner, [`rrt_core::light::bricks`]).
pub const BRICK_LEVEL_BYTES: u64 = 1 + size_of::<u32>() as u64;
/// Upper bound on the voxels per voxel² of surface for the thickest
/// (26-tunnel-free) voxelization: a standard digital surface is
/// `|nx| + |ny| + |nz| ≤ √3` voxels thick.
pub const SURFACE_VOXELS_PER_AREA: f64 = 1.8;

/// Bytes an object takes in the tables a build makes of it: its fitted
/// form ([`FittedObject`](super::FittedObject)), the core's object-table
/// entry and the renderer's world object (its shape and material index).
pub const OBJECT_BYTES: u64 = (size_of::<super::FittedObject>()
    + size_of::<rrt_core::object_table::Object>()
    + size_of::<(crate::shape::Shape, u16)>()) as u64;

/// Voxel counts per axis, printed as `nx×ny×nz`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Dims(pub [u32; 3]);

impl fmt::Display for Dims {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}×{}×{}", self.0[0], self.0[1], self.0[2])
    }
}

/// An upper-bound estimate of a voxelized raster's memory.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct MemoryEstimate {
    /// Voxels in the raster.
    pub voxels: u64,
    /// The plane: one byte per voxel.
    pub plane: u64,
    /// The plane's line level: one byte per 64 voxels.
    pub lines: u64,
    /// The brick directory and the shadow classification's brick level:
    /// [`BRICK_ENTRY_BYTES`] + [`BRICK_LEVEL_BYTES`] per [`BRICK_VOXELS`]
    /// voxels.
    pub directory: u64,
    /// Upper bound on the non-transparent voxels (at most `voxels`).
    pub record_voxels: u64,
    /// Their records: [`RECORD_BYTES`] each.
    pub records: u64,
    /// Surface primitives of the object table (spheres, cones, polygon
    /// triangles, tori).
    pub objects: u64,
    /// Their entries: [`OBJECT_BYTES`] each.
    pub object_table: u64,
    /// The scene's own data, already in memory: its volumes' samples and
    /// its vertices ([`Scene::data_bytes`]).
    pub scene: u64,
    /// The image the raster is rendered into, held beside it
    /// ([`super::FitOptions::image`]).
    pub image: u64,
}

impl MemoryEstimate {
    /// Total bytes (saturating).
    #[must_use]
    pub fn total(&self) -> u64 {
        self.plane
            .saturating_add(self.lines)
            .saturating_add(self.directory)
            .saturating_add(self.records)
            .saturating_add(self.object_table)
            .saturating_add(self.scene)
            .saturating_add(self.image)
    }
}

impl fmt::Display for MemoryEstimate {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "plane {}, line level {}, brick directory and level {}, records for up to {} voxels {}, object table of {} objects {}{}{}",
            Bytes(self.plane),
            Bytes(self.lines),
            Bytes(self.directory),
            self.record_voxels,
            Bytes(self.records),
            self.objects,
            Bytes(self.object_table),
            if self.scene > 0 {
                format!(", the scene's volumes and vertices {}", Bytes(self.scene))
            } else {
                String::new()
            },
            if self.image > 0 {
                format!(", the image {}", Bytes(self.image))
            } else {
                String::new()
            }
        )
    }
}

/// The surface primitives' extent, in world units: what bounds the
/// surface voxels of a raster of any voxel size
/// ([`SurfaceMeasure::voxels`]).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SurfaceMeasure {
    /// Total surface area (world units²).
    pub area: f64,
    /// Total length of boundary edges and rims (world units).
    pub perimeter: f64,
    /// Surface primitives (spheres, cones, polygon triangles, tori).
    pub objects: usize,
}

impl SurfaceMeasure {
    /// The measure of `scene`'s spheres, cones, polygons (as their
    /// triangles) and tori; volumes, `.vox` models and CSG trees are not
    /// counted.
    #[must_use]
    pub fn of(scene: &Scene) -> Self {
        let mut m = Self::default();
        let mut add = |area: f64, perimeter: f64| {
            m.area += area;
            m.perimeter += perimeter;
            m.objects += 1;
        };
        for sp in &scene.spheres {
            let r = sp.shape.radius;
            add(4.0 * PI * r * r, 0.0);
        }
        for c in &scene.cones {
            let slant = (c.shape.apex - c.shape.base)
                .length()
                .hypot(c.shape.apex_radius - c.shape.base_radius);
            let area = PI * (c.shape.base_radius + c.shape.apex_radius) * slant;
            add(area, 2.0 * PI * (c.shape.base_radius + c.shape.apex_radius));
        }
        for t in scene
            .polygons
            .iter()
            .flat_map(|p| scene.polygon_triangles(p))
        {
            let [a, b, c] = t.vertices;
            let area = 0.5 * (b - a).cross(c - a).length();
            let perimeter = (b - a).length() + (c - b).length() + (a - c).length();
            add(area, perimeter);
        }
        for t in &scene.tori {
            add(torus_area(t.shape.major, t.shape.minor), 0.0);
        }
        m
    }

    /// An upper bound on the surface voxels these primitives generate with
    /// voxels of edge `voxel` in the thickest (26-tunnel-free)
    /// voxelization: `1.8·(A + P + 3)` per primitive, `A` its area and `P`
    /// its perimeter in voxel units (the `P` and constant terms covering
    /// edges and tiny objects).
    #[must_use]
    pub fn voxels(&self, voxel: f64) -> f64 {
        SURFACE_VOXELS_PER_AREA
            * (self.area / (voxel * voxel) + self.perimeter / voxel + 3.0 * self.objects as f64)
    }
}

/// The area of the torus swept by a circle of radius `minor` about an
/// axis at distance `major` from its centre: `4π²·R·r` for a ring torus
/// (`R ≥ r`); for a spindle torus (`R < r`), whose tube passes through
/// the axis, the area the sweep covers, `2π·r²·∫|c + cos v| dv` with
/// `c = R/r` (`8π·r²`, a sphere twice, for `R = 0`).
fn torus_area(major: f64, minor: f64) -> f64 {
    if major >= minor {
        return 4.0 * PI * PI * major * minor;
    }
    let c = (major / minor).max(0.0);
    // The tube crosses the axis where cos v = −c.
    let theta = (-c).acos();
    let turn = 4.0 * c * theta + 4.0 * theta.sin() - 2.0 * PI * c;
    2.0 * PI * minor * minor * turn
}

/// Upper-bound memory estimate for `scene` voxelized into `frame`,
/// computed from the world geometry without allocating.
///
/// The plane takes 1 byte per voxel, its line level 1 byte per 64 voxels
/// and the brick directory and brick level 9 bytes per 512 voxels. Non-transparent voxels are bounded by surface area `A`
/// and boundary length `P` (in voxel units): a surface generates at most
/// `1.8·(A + P + 3)` voxels in the thickest (26-tunnel-free)
/// voxelization, the `P` and constant terms covering edges and tiny
/// objects; solid spheres add their volume, `4/3·π·(r + 1)³`. The count is
/// capped at the raster's voxel count, and each such voxel costs a 20-byte
/// record.
/// The scene's own data ([`Scene::data_bytes`]), already in memory, is
/// counted with them.
#[must_use]
pub fn estimate_memory(scene: &Scene, frame: &RasterFrame, solid_spheres: bool) -> MemoryEstimate {
    let [nx, ny, nz] = frame.dims().map(u64::from);
    let voxels = nx.saturating_mul(ny).saturating_mul(nz);
    let s = frame.voxel_size;
    let measure = SurfaceMeasure::of(scene);
    let mut count = measure.voxels(s);
    if solid_spheres {
        for sp in &scene.spheres {
            let rv = sp.shape.radius / s + 1.0;
            count += 4.0 / 3.0 * PI * rv * rv * rv;
        }
    }
    let record_voxels = if count.is_finite() && count < voxels as f64 {
        count.ceil() as u64
    } else {
        voxels
    };
    MemoryEstimate {
        voxels,
        plane: voxels,
        lines: voxels.div_ceil(LINE_CELLS as u64),
        directory: voxels
            .div_ceil(BRICK_VOXELS)
            .saturating_mul(BRICK_ENTRY_BYTES + BRICK_LEVEL_BYTES),
        record_voxels,
        records: record_voxels.saturating_mul(RECORD_BYTES),
        objects: measure.objects as u64,
        object_table: (measure.objects as u64).saturating_mul(OBJECT_BYTES),
        scene: scene.data_bytes(),
        image: 0,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The torus's area is the sweep's, `2π·r·∫|R + r·cos v| dv`, for ring
    /// and spindle tori alike: continuous where the tube touches the axis,
    /// a sphere twice when it is centred on it.
    #[test]
    fn spindle_tori_have_the_area_of_their_sweep() {
        let swept = |big: f64, small: f64| {
            let n = 200_000;
            let dv = 2.0 * PI / f64::from(n);
            let sum: f64 = (0..n)
                .map(|k| (big + small * ((f64::from(k) + 0.5) * dv).cos()).abs())
                .sum();
            2.0 * PI * small * sum * dv
        };
        for (big, small) in [
            (2.0, 0.5),
            (1.0, 1.0),
            (0.3, 1.0),
            (0.999, 1.0),
            (1e-6, 1.0),
            (0.0, 2.0),
        ] {
            let (a, b) = (torus_area(big, small), swept(big, small));
            assert!(
                (a - b).abs() <= 1e-6 * b,
                "R {big}, r {small}: {a} against {b}"
            );
        }
        assert!((torus_area(0.0, 1.0) - 8.0 * PI).abs() < 1e-12);
    }
}
