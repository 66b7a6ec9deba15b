//! # rrt-host: 3D raster ray tracing on a host
//!
//! Everything around the integer core [`rrt_core`], with `std` and `f64`:
//! the pipeline of Yagel, Cohen and Kaufman's *discrete ray tracing*
//! (1992), one module per phase, the data flowing one way.
//!
//! ```text
//!  parse          fit              voxelize (+ light)        trace              render         output
//!  scene::Scene ─▶ fit::Fitted ─▶ voxelize::VoxelScene ─▶ trace::Tracer ─▶ render::Image ─▶ output::image
//!                                       │     ▲
//!                                       ▼     │
//!                                 output::rasterfile (save, load)
//! ```
//!
//! * [`scene`] (parse): NFF and TOML scenes in world coordinates, and the
//!   [`assets`] they name: textures, sampled and computed volumes,
//!   MagicaVoxel models. None of them knows the raster.
//! * [`shape`]: the shape model. Each primitive is described once, with
//!   its validation, fixed-point geometry, core voxelizer call,
//!   object-table entry, exact intersection and saved form.
//! * [`fit`]: the raster's frame ([`frame::RasterFrame`]), the memory
//!   estimate checked against the limit, every primitive and light in
//!   fixed point.
//! * [`voxelize`]: the count and fill passes over the object table, the
//!   light pass (visibility bits, precomputed illumination), the proximity
//!   field and the line level: a [`voxelize::VoxelScene`], everything that
//!   does not depend on the view.
//! * [`trace`]: the recursive discrete ray tracer: the discrete walk,
//!   intersection verification, shading.
//! * [`render`]: the camera, tiles on rayon's threads, 4×2 blocks of
//!   primary rays, supersampling.
//! * [`output`]: images (PNG, PPM, OpenEXR, PFM), and saved rasters
//!   (versioned, checksummed), which are read back to render a voxelized
//!   scene from any view; every file through a temporary renamed over it.
//! * [`progress`]: the phases' progress bars.
//! * [`cli`]: the `rrt` command line; the binary only parses arguments.
//! * [`world`] and [`frame`]: world-space bounds, rays and hits, and the
//!   raster's frame, shared by the phases.
//! * [`memory`]: the machine's memory, the default limit that scenes,
//!   rasters and images are checked against, byte counts in messages.
//! * `check` (feature `check`): invariant checkers shared by the tests and
//!   the fuzz targets.
//!
//! # Guarantees
//! * **Located errors.** Bad input (a scene, an asset, a saved raster, an
//!   argument) gives one error naming the file and, where there is one, the
//!   line, column and key or field. Sizes are checked before anything is
//!   allocated: a file, volume or raster larger than its limit is refused,
//!   not attempted.
//! * **No panic on input.** No input makes the library panic, hang or
//!   abort on allocation; the fuzz targets hold the readers to it.
//! * **Deterministic.** Images, voxelized rasters and saved files are
//!   byte-identical for every thread count: each record's light and each
//!   pixel's colour depend only on unchanged inputs, and sums are taken in
//!   a fixed order.
//! * **Nothing lost.** Outputs are written to a temporary file beside the
//!   target and renamed over it.
//!
//! # Example
//! A sphere from NFF text, voxelized in a 64-voxel raster and rendered:
//!
//! ```
//! use indicatif::ProgressBar;
//! use rrt_host::render::camera::Camera;
//! use rrt_host::render::{RenderOptions, render};
//! use rrt_host::scene::Scene;
//! use rrt_host::trace::{TraceOptions, Tracer};
//! use rrt_host::voxelize::{BuildOptions, build};
//!
//! let nff = "v\nfrom 0 -4 1\nat 0 0 0\nup 0 0 1\nangle 40\nhither 0.1\nresolution 24 16\n\
//!            l 2 -3 4\nf 1 0 0 1 0 0 0 1\ns 0 0 0 1\n";
//! let scene = Scene::parse("ball.nff", nff.as_bytes())?;
//! let (voxels, report) = build(&scene, &BuildOptions::new(64), &ProgressBar::hidden())?;
//! assert!(report.records > 0);
//! let tracer = Tracer::new(&voxels, TraceOptions::default())?;
//! let [w, h] = voxels.view.resolution;
//! let camera = Camera::new(&voxels.view, w, h)?;
//! let (image, stats, _) = render(&tracer, &camera, &RenderOptions::default(), &ProgressBar::hidden())?;
//! assert_eq!(image.rgb.len(), 3 * 24 * 16);
//! assert!(stats.hits > 0);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

pub mod assets;
#[cfg(any(test, feature = "check"))]
pub mod check;
pub mod cli;
pub mod fit;
pub mod frame;
pub mod memory;
pub mod output;
pub mod progress;
pub mod render;
pub mod scene;
pub mod shape;
pub mod trace;
pub mod voxelize;
pub mod world;
