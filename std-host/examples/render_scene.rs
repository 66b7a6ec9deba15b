//! Voxelize a scene and render it to a PNG through `rrt-host`.
//!
//! ```sh
//! cargo run --release -p rrt-host --example render_scene -- [out.png] [scene.nff|scene.toml]
//! ```
//!
//! Without a scene it renders a small built-in one (a ball over a floor).

use indicatif::ProgressBar;
use rrt_host::output::{encoding::Encoding, image::ImageOutput};
use rrt_host::render::camera::Camera;
use rrt_host::render::{RenderOptions, render};
use rrt_host::scene::Scene;
use rrt_host::trace::{TraceOptions, Tracer};
use rrt_host::voxelize::{BuildOptions, build};

const BALL: &str = "v\nfrom 0 -4 1.5\nat 0 0 0.5\nup 0 0 1\nangle 40\nhither 0.1\nresolution 256 256\n\
                    l 3 -4 6\nf 0.9 0.4 0.2 0.8 0.2 20 0 1\ns 0 0 0.7 0.7\n\
                    f 0.8 0.8 0.8 0.9 0 1 0 1\np 4\n-2 -2 0\n2 -2 0\n2 2 0\n-2 2 0\n";

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let out = args.next().unwrap_or_else(|| "render_scene.png".into());
    let scene = match args.next() {
        Some(path) => Scene::load(path)?,
        None => Scene::parse("ball.nff", BALL.as_bytes())?,
    };
    let quiet = ProgressBar::hidden();

    // Voxelize once: 512 voxels along the scene's longest axis, with
    // object lists and the shadow classification.
    let (voxels, report) = build(&scene, &BuildOptions::new(512), &quiet)?;
    // Trace in the exact mode (the default), at the scene's resolution.
    let tracer = Tracer::new(&voxels, TraceOptions::default())?;
    let [w, h] = voxels.view.resolution;
    let camera = Camera::new(&voxels.view, w, h)?;
    let (image, stats, _) = render(&tracer, &camera, &RenderOptions::default(), &quiet)?;
    ImageOutput::create(out.as_ref(), Encoding::default())?
        .write(&image, &mut std::io::stdout())?;

    println!(
        "{out}: {w}×{h}, {} surface voxels, {} rays",
        report.records,
        stats.rays()
    );
    Ok(())
}
