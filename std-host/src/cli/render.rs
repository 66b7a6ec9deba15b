//! `rrt render`: an NFF or TOML scene or a saved raster to an image.

use std::io::Write;
use std::path::PathBuf;

use super::CliError;
use super::common::{
    ImageNeed, Loaded, Purpose, RasterArgs, ViewArgs, load_or_build, parse_depth, parse_min_weight,
    parse_threads, progress, secs,
};
use super::frames::{Frames, Names, TileArg, parse_frame_count, parse_tile};
use crate::fit::{Bytes, default_max_memory};
use crate::output::band::BandTag;
use crate::output::image::{Encoding, Format, ImageOutput};
use crate::render::camera::Camera;
use crate::render::{RenderOptions, check_sizes, image_bytes, render_rows};
use crate::scene::View;
use crate::trace::{TraceOptions, Tracer};

/// Arguments of `rrt render`.
#[derive(Debug, Clone, clap::Args)]
pub struct RenderArgs {
    /// An NFF or TOML scene or a raster saved by `rrt voxelize`
    /// [default: the built-in 91-sphereflake, SPD balls2].
    pub scene: Option<PathBuf>,
    /// The image to write; its extension chooses the format: .png (8-bit
    /// sRGB by default), .ppm (binary), .exr or .pfm (32-bit float,
    /// linear), or - for PNG on standard output. With --orbit or --path,
    /// a file name pattern: %d, or %0Nd (N from 1 to 20), for the frame
    /// number zero-padded to N digits (%% is a %), required when several
    /// frames are written.
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
    /// Reflected and refracted rays whose weight in the pixel (the
    /// product of the `Ks` and `T` factors on their way to the eye) is
    /// below W are not traced, 0 to 1 (0: the whole ray tree to
    /// `--depth`); the summary line counts them. The default, 2^-16, is
    /// below one step of a 16-bit linear image for a ray that sees at
    /// most white. A material with both `Ks` and `T` doubles the ray tree
    /// at every level until the weights fall below W.
    #[arg(long, value_name = "W", default_value_t = crate::trace::DEFAULT_MIN_WEIGHT, value_parser = parse_min_weight, allow_hyphen_values = true)]
    pub min_weight: f64,
    /// K×K rays per pixel, box-filtered, K from 1 to 16 (and at most
    /// 2^32 rays in all).
    #[arg(long, value_name = "K", default_value_t = 1, value_parser = parse_positive, allow_hyphen_values = true)]
    pub supersample: u32,
    /// Threads for loading a saved raster or for the voxelization and the
    /// light pass, and for the render, 0 (one per core) to 1024; the image
    /// does not depend on it.
    #[arg(long, value_name = "T", default_value_t = 0, value_parser = parse_threads, allow_hyphen_values = true)]
    pub threads: usize,
    /// Walk primary rays in 8-ray packets (4×2 pixel blocks) instead of
    /// one by one (both skip empty space); the image is the same.
    #[arg(long)]
    pub packets: bool,
    /// View overrides.
    #[command(flatten)]
    pub view: ViewArgs,
    /// Render only band I of N horizontal bands of equal height (to a
    /// row), I from 0 (the top band) to N − 1, N from 1 to the image's
    /// height: the band's rows, byte for byte as in the whole image, in
    /// a file that says which band it is (PNG, PPM, OpenEXR; PFM bands
    /// cannot say); `rrt stitch` joins the bands.
    #[arg(long, value_name = "I/N", value_parser = parse_tile)]
    pub tile: Option<TileArg>,
    /// An animation of N frames, 1 to 2^64 − 1, from one voxelization:
    /// frame k has the eye turned by 360°·k/N about the up axis through
    /// `at` (frame 0 is the view itself). -o is then a file name pattern
    /// with the frame number: %d, or %0Nd zero-padded to N digits (%% is
    /// a %).
    #[arg(long, value_name = "N", value_parser = parse_frame_count, conflicts_with = "path")]
    pub orbit: Option<u64>,
    /// An animation along a camera path: one view per line of FILE, ten
    /// whitespace-separated numbers `fx fy fz ax ay az ux uy uz angle`
    /// (from, at, up, angle in degrees), # comments and blank lines
    /// allowed; frame k is the k-th view (from 0), with the scene's
    /// resolution. -o as for --orbit.
    #[arg(long, value_name = "FILE", conflicts_with_all = ["from", "at", "up", "angle"])]
    pub path: Option<PathBuf>,
    /// Render only frame K of the animation, K from 0 to its frame count
    /// − 1 (frames rendered apart are byte-identical to one process's).
    #[arg(long, value_name = "K")]
    pub frame: Option<u64>,
    /// No progress bars and no summary line.
    #[arg(long, short)]
    pub quiet: bool,
}

/// Runs `rrt render`, writing one summary line per image to `out`.
///
/// # Errors
/// [`CliError`]: bad sizes, bands, frames or file name patterns, a bad
/// camera path, an unwritable output, the scene's, builder's, tracer's or
/// encoder's error.
pub fn run(args: &RenderArgs, out: &mut impl Write) -> Result<(), CliError> {
    // Sizes and tracing options given on the command line are checked
    // before any work.
    check_sizes(
        args.width.unwrap_or(1),
        args.height.unwrap_or(1),
        args.supersample,
    )?;
    let trace_options = TraceOptions {
        mode: args.raster.mode.into(),
        connectivity: args.raster.connectivity.into(),
        depth: args.depth,
        min_weight: args.min_weight,
        packets: args.packets,
        ..TraceOptions::default()
    };
    trace_options.check()?;
    let frames = match (args.orbit, &args.path) {
        (Some(n), _) => Frames::Orbit(n),
        (None, Some(p)) => Frames::Path(crate::scene::path::load(p, &p.display().to_string())?),
        (None, None) if args.frame.is_some() => {
            return Err(CliError::Arg {
                arg: "--frame",
                message: "a frame of an animation: give --orbit N or --path FILE".to_string(),
            });
        }
        (None, None) => Frames::Still,
    };
    let chosen = frames.chosen(args.frame)?;
    let names = Names::new(&args.output, frames.animated(), chosen.end - chosen.start)?;
    if let (Some(t), Some(h)) = (args.tile, args.height) {
        t.band(h)?;
    }
    let encoding = Encoding {
        bits: args.bits,
        linear: args.linear,
    };
    // The first image's output is opened before any work (an unwritable
    // path or an unknown format is reported at once), the others as their
    // turn comes.
    let first = ImageOutput::create(&names.path(chosen.start), encoding)?;
    let format = first.format();
    let mut first_output = Some(first);
    // Frame k's view, image size and camera, checked before voxelizing
    // (the first frame) and again for each render.
    let camera_of = |scene_view: &crate::scene::View,
                     k: u64|
     -> Result<(Camera, View, u32, u32, u64), CliError> {
        let view = frames.view(k, &args.view.apply(scene_view));
        let [rw, rh] = view.resolution;
        let (w, h) = (args.width.unwrap_or(rw), args.height.unwrap_or(rh));
        check_sizes(w, h, args.supersample)?;
        let rows = match args.tile {
            Some(t) => {
                let r = t.band(h)?.rows(h);
                r.end - r.start
            }
            None => h,
        };
        // Named by what set the size: the arguments, or the scene.
        let sized_by = (args.width.is_none() || args.height.is_none()).then_some(&view.loc);
        let bytes = check_image_memory(w, rows, args.bits, format, &args.raster, sized_by)?;
        Ok((Camera::new(&view, w, h)?, view, w, h, bytes))
    };
    // The raster is fitted to the base view (the scene's with the
    // overrides), whichever frames are rendered.
    let loaded = load_or_build(
        args.scene.as_ref(),
        &args.raster,
        Purpose::Render,
        &ImageNeed {
            view: &args.view,
            width: args.width,
            height: args.height,
            samples: args.supersample,
            memory: 0,
        },
        args.threads,
        !args.quiet,
        &|v| camera_of(v, chosen.start).map(|c| c.4),
    )?;
    let scene = match &loaded {
        Loaded::Built { scene, .. } | Loaded::Saved { scene, .. } => scene,
    };
    let tracer = Tracer::new(scene, trace_options).map_err(|why| match (&loaded, &args.scene) {
        // What the raster was voxelized for is the saved file's.
        (Loaded::Saved { .. }, Some(path)) => CliError::SavedTrace {
            path: path.clone(),
            why,
        },
        _ => why.into(),
    })?;
    let mut prep = Some(match &loaded {
        Loaded::Built { report, parse, .. } => format!(
            "parse {}, voxelize {}, light visibility {}",
            secs(*parse),
            secs(report.voxelize),
            secs(report.lights)
        ),
        Loaded::Saved { load, .. } => format!("load {}", secs(*load)),
    });
    // Bands name their scene (read once: it reads every record).
    let fingerprint = args.tile.map(|_| scene.fingerprint()).unwrap_or_default();
    for k in chosen {
        let (camera, view, w, h, _) = camera_of(&scene.view, k)?;
        let output = match first_output.take() {
            Some(o) => o,
            None => ImageOutput::create(&names.path(k), encoding)?,
        };
        let band = args.tile.map(|t| t.band(h)).transpose()?;
        let rows = band.map_or(0..h, |b| b.rows(h));
        let bar = progress(!args.quiet);
        let rendered = render_rows(
            &tracer,
            &camera,
            &RenderOptions {
                supersample: args.supersample,
                threads: args.threads,
                alpha: false,
            },
            rows.clone(),
            &bar,
        );
        bar.finish_and_clear();
        let (image, stats, time) = rendered?;
        let tag = band.map(|band| {
            BandTag {
                band,
                width: w,
                height: h,
                kind: output.kind(),
                render: render_key(args, &view, scene, &fingerprint),
            }
            .to_string()
        });
        let to_stdout = output.is_stdout();
        let path = output.path().to_path_buf();
        output.write_band(&image, tag.as_deref(), out)?;
        if !args.quiet {
            // With the image on standard output, the summary goes to stderr.
            let mut stderr = std::io::stderr();
            let out: &mut dyn Write = if to_stdout { &mut stderr } else { out };
            let size = match band {
                Some(b) => format!(
                    "{w}×{h} band {}/{} (rows {}..{})",
                    b.index, b.count, rows.start, rows.end
                ),
                None => format!("{w}×{h}"),
            };
            let frame = if frames.animated() {
                format!("frame {k} of {}, ", frames.count())
            } else {
                String::new()
            };
            let prep = prep.take().unwrap_or_else(|| "raster reused".to_string());
            summary(
                out,
                args,
                scene,
                &path,
                &format!("{frame}{size}"),
                &prep,
                &stats,
                time,
            )?;
        }
    }
    Ok(())
}

/// Refuses an image of `width` × `rows` pixels whose memory (the
/// rendered image, [`image_bytes`], and its encoding in `format`:
/// `bits`-bit codes, or OpenEXR's, made whole in memory) is more than
/// `--max-memory` allows; named by the scene's view at `sized_by` when
/// the scene's resolution set the size, by `--width/--height` otherwise.
/// Returns those bytes.
fn check_image_memory(
    width: u32,
    rows: u32,
    bits: u8,
    format: Format,
    raster: &RasterArgs,
    sized_by: Option<&crate::scene::SourceLoc>,
) -> Result<u64, CliError> {
    let limit = raster.max_memory.unwrap_or_else(default_max_memory);
    let pixels = u64::from(width) * u64::from(rows);
    let codes = match format {
        // The float samples, the encoder's blocks, compressed and not,
        // and the file's bytes, which it writes into memory first (it
        // seeks): about 13 bytes a pixel measured, 24 counted.
        Format::Exr => pixels * 24,
        // The encoder's samples and their byte order: two copies of 3
        // codes.
        _ => pixels * 6 * u64::from(bits.div_ceil(8)),
    };
    let needed = image_bytes(width, rows, false).saturating_add(codes);
    if needed > limit {
        let (needed, limit) = (Bytes(needed), Bytes(limit));
        return Err(match sized_by {
            Some(loc) => CliError::Arg {
                arg: "--max-memory",
                message: format!(
                    "the view at {loc} asks for a {width}×{rows} image, which needs about {needed}, more than the limit of {limit}; give --width and --height"
                ),
            },
            None => CliError::Arg {
                arg: "--width/--height",
                message: format!(
                    "a {width}×{rows} image needs about {needed}, more than the memory limit of {limit} (--max-memory)"
                ),
            },
        });
    }
    Ok(needed)
}

/// What every band of one image shares, for its [`BandTag`]: the view,
/// the sampling, the ray tree, the mode, the raster's dimensions and the
/// scene's [fingerprint](crate::voxelize::VoxelScene::fingerprint), so
/// that bands of different scenes are not joined.
fn render_key(
    args: &RenderArgs,
    view: &View,
    scene: &crate::voxelize::VoxelScene,
    fingerprint: &str,
) -> String {
    let v = |p: glam::DVec3| format!("{},{},{}", p.x, p.y, p.z);
    let d = scene.extent().dims();
    format!(
        "view from {} at {} up {} angle {}; supersample {}; depth {}, min weight {:e}; {} mode, {}; raster {}x{}x{}; scene {}",
        v(view.from),
        v(view.at),
        v(view.up),
        view.angle,
        args.supersample,
        args.depth,
        args.min_weight,
        crate::trace::Mode::from(args.raster.mode).name(),
        rrt_core::Connectivity::from(args.raster.connectivity).name(),
        d[0],
        d[1],
        d[2],
        fingerprint
    )
}

/// Writes one image's summary line.
#[allow(clippy::too_many_arguments)]
fn summary(
    out: &mut dyn Write,
    args: &RenderArgs,
    scene: &crate::voxelize::VoxelScene,
    path: &std::path::Path,
    size: &str,
    prep: &str,
    stats: &crate::trace::RayStats,
    time: std::time::Duration,
) -> Result<(), CliError> {
    let d = scene.extent().dims();
    let rays = stats.rays().max(1);
    writeln!(
        out,
        "{}: {size}, raster {}×{}×{} ({} mode, {}), depth {}: {prep}, render {}; rays {} primary, {} reflected, {} refracted{}, {} shadow ({} lights proven lit, {} proven occluded, {} blocked by the last blocker, {:.1} steps/shadow ray walked); {:.1} steps/ray; {} hits ({} in shared voxels), {} false hits ({:.2}% of rays){}",
        path.display(),
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
        if stats.pruned > 0 {
            format!(
                " ({} more not traced: weight below {:e})",
                stats.pruned, args.min_weight
            )
        } else {
            String::new()
        },
        stats.shadow,
        stats.classified,
        stats.occluded,
        stats.last_blocker,
        stats.shadow_steps as f64 / (stats.shadow - stats.last_blocker).max(1) as f64,
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
