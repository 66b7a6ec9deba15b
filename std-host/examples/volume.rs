//! A volume from an in-memory array of samples, classified, voxelized and
//! rendered: the way to ray trace data that is not in a file (a simulation,
//! a scan already in memory).
//!
//! ```sh
//! cargo run --release -p rrt-host --example volume -- [out.png]
//! ```
//!
//! The samples are a 64³ `u8` field of two blended blobs; samples at or above
//! the iso-value 128 are the object, coloured by a ramp over the sample
//! values, its normals from the gray-level gradient.

use std::sync::Arc;

use glam::DVec3;
use indicatif::ProgressBar;
use rrt_host::assets::volume::{Classifier, ColorRamp, Grid, Placement, Samples, Volume};
use rrt_host::output::{encoding::Encoding, image::ImageOutput};
use rrt_host::render::camera::Camera;
use rrt_host::render::{RenderOptions, render};
use rrt_host::scene::{Scene, SceneVolume, SourceLoc, VolumeObject};
use rrt_host::trace::{TraceOptions, Tracer};
use rrt_host::voxelize::{BuildOptions, build};
use rrt_host::world::Bounds;

/// The view, one light, a material and a floor; the volume is added below.
const STAGE: &str = "v\nfrom 0 -3.2 1.6\nat 0 0 0.7\nup 0 0 1\nangle 40\nhither 0.1\nresolution 256 256\n\
                     b 0.1 0.1 0.15\nl 3 -4 6\nf 0.8 0.8 0.8 0.8 0.1 10 0 1\n\
                     p 4\n-1.5 -1.5 0\n1.5 -1.5 0\n1.5 1.5 0\n-1.5 1.5 0\n";

/// Samples per axis.
const N: u32 = 64;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let out = std::env::args()
        .nth(1)
        .unwrap_or_else(|| "volume.png".into());

    // The data: x fastest, then y, then z.
    let n = f64::from(N);
    let blob = |p: DVec3, c: DVec3, r: f64| (-(p - c).length_squared() / (r * r)).exp();
    let mut samples = Vec::with_capacity((N * N * N) as usize);
    for z in 0..N {
        for y in 0..N {
            for x in 0..N {
                let p = DVec3::new(f64::from(x), f64::from(y), f64::from(z)) / n;
                let v = blob(p, DVec3::new(0.4, 0.5, 0.4), 0.22)
                    + blob(p, DVec3::new(0.62, 0.5, 0.62), 0.16);
                samples.push((v.min(1.0) * 255.0) as u8);
            }
        }
    }
    let volume = Volume::new([N; 3], Grid::unit(), Samples::U8(samples))?;

    // Its place in the world (fitted into a box on the floor) and its
    // classification: the object is every sample ≥ 128.
    let placement = Placement::fit_into(
        &volume,
        Bounds {
            min: DVec3::new(-1.0, -1.0, 0.0),
            max: DVec3::new(1.0, 1.0, 2.0),
        },
    )?;
    let ramp = ColorRamp::new(vec![(128.0, [40, 90, 200]), (255.0, [250, 230, 120])])?;
    let classifier = Classifier::iso(128.0).with_color(ramp);

    let mut scene = Scene::parse("stage.nff", STAGE.as_bytes())?;
    scene.volumes.push(VolumeObject {
        data: SceneVolume {
            volume: Arc::new(volume),
            placement,
            classifier,
        },
        material: 0,
        loc: SourceLoc::new("examples/volume.rs", line!(), 0),
    });

    let quiet = ProgressBar::hidden();
    let (voxels, report) = build(&scene, &BuildOptions::new(256), &quiet)?;
    let tracer = Tracer::new(&voxels, TraceOptions::default())?;
    let [w, h] = voxels.view.resolution;
    let camera = Camera::new(&voxels.view, w, h)?;
    let (image, _, _) = render(&tracer, &camera, &RenderOptions::default(), &quiet)?;
    ImageOutput::create(out.as_ref(), Encoding::default())?
        .write(&image, &mut std::io::stdout())?;
    println!("{out}: {w}×{h}, {} surface voxels", report.records);
    Ok(())
}
