//! `rrt render`: an NFF or TOML scene or a saved raster to an image.

use std::io::Write;
use std::path::PathBuf;

use super::CliError;
use super::common::{
    ImageNeed, Loaded, Purpose, RasterArgs, ViewArgs, load_or_build, parse_depth, parse_threads,
    progress, secs,
};
use crate::output::image::{Encoding, ImageOutput};
use crate::render::camera::Camera;
use crate::render::{RenderOptions, check_sizes, render};
use crate::trace::{TraceOptions, Tracer};

/// Arguments of `rrt render`.
#[derive(Debug, Clone, clap::Args)]
pub struct RenderArgs {
    /// An NFF or TOML scene or a raster saved by `rrt voxelize`
    /// [default: the built-in 91-sphereflake, SPD balls2].
    pub scene: Option<PathBuf>,
    /// The image to write; its extension chooses the format: .png (8-bit
    /// sRGB by default), .ppm (binary), .exr or .pfm (32-bit float,
    /// linear), or - for PNG on standard output.
    #[arg(short, long, value_name = "OUT", default_value = "rrt.png")]
    pub output: PathBuf,
    /// Bits per channel of .png and .ppm output: 8 or 16.
    #[arg(long, value_name = "8|16", default_value_t = 8, value_parser = parse_bits)]
    pub bits: u8,
    /// Write the linear values to .png and .ppm instead of sRGB-encoded
    /// ones, without a colour-space chunk (viewers show it too dark; for
    /// comparisons with other renderers' linear output). .exr and .pfm
    /// are always linear.
    #[arg(long)]
    pub linear: bool,
    /// Image width in pixels, 1 to 32768 [default: the scene's
    /// resolution].
    #[arg(long, value_name = "W", value_parser = parse_positive, allow_hyphen_values = true)]
    pub width: Option<u32>,
    /// Image height in pixels, 1 to 32768 [default: the scene's
    /// resolution].
    #[arg(long, value_name = "H", value_parser = parse_positive, allow_hyphen_values = true)]
    pub height: Option<u32>,
    /// Voxelization.
    #[command(flatten)]
    pub raster: RasterArgs,
    /// Depth of the ray tree, 1 to 64 (the eye ray counts as 1).
    #[arg(long, value_name = "D", default_value_t = 3, value_parser = parse_depth, allow_hyphen_values = true)]
    pub depth: u32,
    /// K×K rays per pixel, box-filtered, K from 1 to 16 (and at most
    /// 2^32 rays in all).
    #[arg(long, value_name = "K", default_value_t = 1, value_parser = parse_positive, allow_hyphen_values = true)]
    pub supersample: u32,
    /// Threads for the voxelization, the light pass and the render, 0
    /// (one per core) to 1024; the image does not depend on it.
    #[arg(long, value_name = "T", default_value_t = 0, value_parser = parse_threads, allow_hyphen_values = true)]
    pub threads: usize,
    /// Walk primary rays in 8-ray packets (4×2 pixel blocks) instead of
    /// one by one with empty-space skipping; the image is the same.
    #[arg(long)]
    pub packets: bool,
    /// View overrides.
    #[command(flatten)]
    pub view: ViewArgs,
    /// No progress bars and no summary line.
    #[arg(long, short)]
    pub quiet: bool,
}

/// Runs `rrt render`, writing the summary line to `out`.
///
/// # Errors
/// [`CliError`]: bad sizes, an unwritable output, the scene's, builder's,
/// tracer's or encoder's error.
pub fn run(args: &RenderArgs, out: &mut impl Write) -> Result<(), CliError> {
    // Sizes given on the command line are checked before any work.
    check_sizes(
        args.width.unwrap_or(1),
        args.height.unwrap_or(1),
        args.supersample,
    )?;
    let output = ImageOutput::create(
        &args.output,
        Encoding {
            bits: args.bits,
            linear: args.linear,
        },
    )?;
    // The view with the overrides, the image size and the camera, checked
    // before voxelizing and again for the render.
    let camera_of = |scene_view: &crate::scene::View| -> Result<(Camera, u32, u32), CliError> {
        let view = args.view.apply(scene_view);
        let [rw, rh] = view.resolution;
        let (w, h) = (args.width.unwrap_or(rw), args.height.unwrap_or(rh));
        check_sizes(w, h, args.supersample)?;
        Ok((Camera::new(&view, w, h)?, w, h))
    };
    let loaded = load_or_build(
        args.scene.as_ref(),
        &args.raster,
        Purpose::Render,
        &ImageNeed {
            view: &args.view,
            width: args.width,
            height: args.height,
            samples: args.supersample,
        },
        args.threads,
        !args.quiet,
        &|v| camera_of(v).map(|_| ()),
    )?;
    let scene = match &loaded {
        Loaded::Built { scene, .. } | Loaded::Saved { scene, .. } => scene,
    };
    let (camera, w, h) = camera_of(&scene.view)?;
    let tracer = Tracer::new(
        scene,
        TraceOptions {
            mode: args.raster.mode.into(),
            connectivity: args.raster.connectivity.into(),
            depth: args.depth,
            packets: args.packets,
            ..TraceOptions::default()
        },
    )?;
    let bar = progress(!args.quiet);
    let rendered = render(
        &tracer,
        &camera,
        &RenderOptions {
            supersample: args.supersample,
            threads: args.threads,
        },
        &bar,
    );
    bar.finish_and_clear();
    let (image, stats, time) = rendered?;
    let to_stdout = output.is_stdout();
    output.write(&image, out)?;
    if !args.quiet {
        // With the image on standard output, the summary goes to stderr.
        let mut stderr = std::io::stderr();
        let out: &mut dyn Write = if to_stdout { &mut stderr } else { out };
        let d = scene.extent().dims();
        let prep = match &loaded {
            Loaded::Built { report, parse, .. } => format!(
                "parse {}, voxelize {}, light visibility {}",
                secs(*parse),
                secs(report.voxelize),
                secs(report.lights)
            ),
            Loaded::Saved { load, .. } => format!("load {}", secs(*load)),
        };
        let rays = stats.rays().max(1);
        writeln!(
            out,
            "{}: {w}×{h}, raster {}×{}×{} ({} mode, {}), depth {}: {prep}, render {}; rays {} primary, {} reflected, {} refracted, {} shadow ({} lights proven lit, {:.1} steps/shadow ray); {:.1} steps/ray; {} hits ({} in shared voxels), {} false hits ({:.2}% of rays){}",
            args.output.display(),
            d[0],
            d[1],
            d[2],
            crate::trace::Mode::from(args.raster.mode).name(),
            rrt_core::Connectivity::from(args.raster.connectivity).name(),
            args.depth,
            secs(time),
            stats.primary,
            stats.reflected,
            stats.refracted,
            stats.shadow,
            stats.classified,
            stats.shadow_steps as f64 / stats.shadow.max(1) as f64,
            stats.steps as f64 / rays as f64,
            stats.hits,
            stats.shared_hits,
            stats.false_hits,
            100.0 * stats.false_hit_rays as f64
                / (stats.primary + stats.reflected + stats.refracted).max(1) as f64,
            if stats.samples > 0 {
                format!("; {} volume samples composited", stats.samples)
            } else {
                String::new()
            },
        )?;
    }
    Ok(())
}

/// Parses `--bits`: 8 or 16.
fn parse_bits(s: &str) -> Result<u8, String> {
    match s.trim() {
        "8" => Ok(8),
        "16" => Ok(16),
        _ => Err(format!("expected 8 or 16, found {s:?}")),
    }
}

/// Parses a positive whole number ("must be positive" for zero or a
/// negative number).
fn parse_positive(s: &str) -> Result<u32, String> {
    let t = s.trim();
    match t.parse::<i64>() {
        Ok(v) if v <= 0 => Err(format!("must be positive, found {t}")),
        Ok(v) => u32::try_from(v).map_err(|_| format!("{t} is too large")),
        Err(_) => Err(format!("expected a whole number, found {s:?}")),
    }
}
