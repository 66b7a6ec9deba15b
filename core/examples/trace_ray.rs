//! One discrete ray through a voxelized sphere, with `rrt-core` alone, the
//! way firmware uses it: every buffer is provided by the caller (here a
//! `static`-sized array on the stack), nothing is allocated, no float is
//! used.
//!
//! ```sh
//! cargo run -p rrt-core --example trace_ray
//! ```
//!
//! It voxelizes a sphere of radius 5 voxels into a 16³ raster, sets the
//! proximity flags, then traces one ray from outside the box: the voxels
//! of its 6-connected path up to the sphere, and the first hit of each
//! connectivity.

use rrt_core::discrete_ray::{Connectivity, DiscreteRay};
use rrt_core::fixed::{VOXEL, voxel_centre};
use rrt_core::geometry::Sphere;
use rrt_core::proximity::flag_neighbourhood;
use rrt_core::raster::{Extent, Raster, RasterMut, cell};
use rrt_core::voxelize::{Separation, Surfel, VoxelSink, sphere};

/// Raster side in voxels.
const N: u32 = 16;

/// A sink that marks every offered voxel opaque in the plane: the least a
/// voxelizer needs (the core's `store::Counter` does this and counts the
/// records a scene will need).
struct MarkOpaque<'a>(RasterMut<'a>);

impl VoxelSink for MarkOpaque<'_> {
    fn offer(&mut self, voxel: [u32; 3], _surfel: Surfel) {
        if let Some(c) = self.0.cell_mut(voxel) {
            *c |= cell::OPAQUE;
        }
    }
}

fn main() -> Result<(), Box<dyn core::error::Error>> {
    // The plane: one byte per voxel, owned by the caller.
    let mut plane = [cell::EMPTY; (N * N * N) as usize];
    let extent = Extent::cube(N)?;

    // Voxelize a sphere at the raster's centre, 26-tunnel-free (thick
    // enough for every connectivity), then flag its neighbourhood so that
    // adaptive rays slow down to 6-steps near it.
    let ball = Sphere {
        centre: [voxel_centre(8), voxel_centre(8), voxel_centre(8)],
        radius: 5 * VOXEL,
    };
    let mut sink = MarkOpaque(RasterMut::new(extent, &mut plane)?);
    let offers = sphere::surface(&ball, Separation::TwentySix, extent, &mut sink)?;
    flag_neighbourhood(&mut sink.0);
    println!("sphere: {offers} surface voxels in a {N}³ raster");

    // A ray from outside the box, in fixed point: origin (-2, 2.5, 4.25)
    // voxels, direction (1, 0.5, 0.3125).
    let raster = Raster::new(extent, &plane)?;
    let origin = [-2 * VOXEL, 5 * VOXEL / 2, 17 * VOXEL / 4];
    let dir = [VOXEL as i32, (VOXEL / 2) as i32, (5 * VOXEL / 16) as i32];
    let Some(ray) = DiscreteRay::new(extent, origin, dir)? else {
        println!("the ray misses the raster box");
        return Ok(());
    };

    println!("6-connected path, up to the first opaque voxel:");
    for visit in ray.voxels(&raster, Connectivity::Six)? {
        let v = extent
            .coord(visit.index)
            .ok_or("voxel outside the raster")?;
        let opaque = visit.cell & cell::OPAQUE != 0;
        println!(
            "  {:2} {:2} {:2}{}",
            v[0],
            v[1],
            v[2],
            if opaque { "  opaque" } else { "" }
        );
        if opaque {
            break;
        }
    }

    for mode in [
        Connectivity::Six,
        Connectivity::TwentySix,
        Connectivity::Adaptive,
    ] {
        // A ray is `Copy`: each walk starts from the same state.
        let mut walk = ray;
        match walk.first_hit(&raster, mode)? {
            Some(hit) => println!(
                "{mode:?}: hit voxel {:?} after {} voxels, entered through {:?}",
                hit.voxel, hit.steps, hit.face
            ),
            None => println!("{mode:?}: miss"),
        }
    }
    Ok(())
}
