//! `rrt voxelize`: voxelize an NFF or TOML scene once and save the raster.

use std::io::Write;
use std::path::PathBuf;

use super::CliError;
use super::common::{
    ImageNeed, Loaded, Purpose, RasterArgs, ViewArgs, load_or_build, parse_threads, progress, secs,
};
use crate::fit::Bytes;
use crate::output::atomic::AtomicFile;
use crate::output::rasterfile;
use crate::progress::Unit;

/// Arguments of `rrt voxelize`.
#[derive(Debug, Clone, clap::Args)]
pub struct VoxelizeArgs {
    /// An NFF or TOML scene [default: the built-in 91-sphereflake].
    pub scene: Option<PathBuf>,
    /// The raster file to write; its name ends in .rrt.
    #[arg(short, long, value_name = "FILE.rrt")]
    pub output: PathBuf,
    /// Voxelization.
    #[command(flatten)]
    pub raster: RasterArgs,
    /// Threads for the voxelization and the light pass (or for loading a
    /// saved raster), 0 (one per core) to 1024; the saved raster does not
    /// depend on it.
    #[arg(long, value_name = "T", default_value_t = 0, value_parser = parse_threads, allow_hyphen_values = true)]
    pub threads: usize,
    /// No progress bar and no summary line.
    #[arg(long, short)]
    pub quiet: bool,
    /// Leave the large sections of the file uncompressed (larger files,
    /// no faster to load).
    #[arg(long, conflicts_with = "dense")]
    pub uncompressed: bool,
    /// Write file version 1 or 2, with the dense plane (one byte per
    /// voxel), for an rrt that reads only those.
    #[arg(long)]
    pub dense: bool,
}

/// Runs `rrt voxelize`, writing a summary line to `out`.
///
/// # Errors
/// [`CliError`]: the scene's or builder's error, a saved raster given as
/// the scene, an unwritable output.
pub fn run(args: &VoxelizeArgs, out: &mut impl Write) -> Result<(), CliError> {
    if let Some(p) = &args.scene
        && rasterfile::is_raster_file(p)
    {
        return Err(CliError::Arg {
            arg: "SCENE",
            message: format!(
                "{} is already a saved raster; give an NFF or TOML scene",
                p.display()
            ),
        });
    }
    // A raster goes to a file named as one: not to standard output (`-`,
    // which render reads as an image), nor over a scene or an image.
    let is_rrt = args
        .output
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("rrt"));
    if !is_rrt {
        return Err(CliError::Arg {
            arg: "--output",
            message: format!(
                "{}: a saved raster is written to a file whose name ends in .rrt{}",
                args.output.display(),
                if args.output.as_os_str() == "-" {
                    " (not to standard output)"
                } else {
                    ""
                }
            ),
        });
    }
    // Fail on an unwritable output before voxelizing: the temporary file
    // beside it is created now, renamed over it when the raster is
    // complete, and removed on an error or an interruption.
    let file = AtomicFile::create(&args.output).map_err(|source| CliError::Output {
        path: args.output.clone(),
        source,
    })?;
    // A saved raster is rendered from any view: its default size is fitted
    // to the scene's own view and resolution.
    let view = ViewArgs {
        from: None,
        at: None,
        up: None,
        angle: None,
    };
    let image = ImageNeed {
        view: &view,
        width: None,
        height: None,
        samples: 1,
        memory: 0,
    };
    let loaded = load_or_build(
        args.scene.as_ref(),
        &args.raster,
        Purpose::Save,
        &image,
        args.threads,
        !args.quiet,
        &|_| Ok(0),
    );
    let Loaded::Built {
        scene,
        report,
        parse,
    } = loaded?
    else {
        return Err(CliError::Arg {
            arg: "SCENE",
            message: "expected an NFF or TOML scene".into(),
        });
    };
    let t = std::time::Instant::now();
    let bar = progress(!args.quiet);
    crate::progress::phase(&bar, "saving", Unit::Bytes, 0);
    let format = if args.dense {
        rasterfile::Format::Dense
    } else {
        rasterfile::Format::Sparse {
            compress: !args.uncompressed,
        }
    };
    // The scene is the builder's, unchanged.
    let saved = rasterfile::save_built_to(&scene, file, &bar, format);
    bar.finish_and_clear();
    let bytes = saved?;
    if !args.quiet {
        let d = scene.extent().dims();
        writeln!(
            out,
            "{}: raster {}×{}×{}, {} objects, {} surface voxels, {}: parse {}, voxelize {}, light visibility {}, save {}",
            args.output.display(),
            d[0],
            d[1],
            d[2],
            report.objects,
            report.records,
            Bytes(bytes),
            secs(parse),
            secs(report.voxelize),
            secs(report.lights),
            secs(t.elapsed()),
        )?;
    }
    Ok(())
}
