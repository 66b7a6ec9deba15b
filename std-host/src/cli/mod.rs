//! The `rrt` command line. The binary (`src/bin/rrt.rs`) only parses the
//! arguments and prints errors; each subcommand lives in its own module here.

pub mod common;
pub mod frames;
pub mod info;
pub mod num;
pub mod ray;
pub mod render;
pub mod stitch;
pub mod voxelize;

use std::io::Write;

/// rrt: 3D raster (discrete) ray tracing. A scene (NFF or TOML) is
/// voxelized once into a raster of surface voxels; rays are traced as
/// integer 3D lines through it.
#[derive(Debug, clap::Parser)]
#[command(name = "rrt", version, long_about = None)]
pub struct Cli {
    /// What to do.
    #[command(subcommand)]
    pub command: Command,
}

/// The subcommands.
#[derive(Debug, clap::Subcommand)]
pub enum Command {
    /// Render an NFF or TOML scene or a saved raster to an image: PNG,
    /// PPM, OpenEXR or PFM by the output's extension (no scene: the
    /// built-in 91-sphereflake to rrt.png).
    Render(Box<render::RenderArgs>),
    /// Join the bands written by `rrt render --tile I/N`, in order, into
    /// the whole image, byte for byte the file one render writes; refuses
    /// files that are not the bands of one image, each once, in order.
    Stitch(stitch::StitchArgs),
    /// Voxelize an NFF or TOML scene once and save the raster, with light
    /// visibility and precomputed illumination, for `rrt render`.
    Voxelize(voxelize::VoxelizeArgs),
    /// Print what a saved raster holds, from its header and meta section
    /// (their checksums checked); `--check` checks every section and
    /// loads the raster.
    Info(info::InfoArgs),
    /// Trace one discrete ray and list its voxels, one `x y z` per line,
    /// through an empty raster (`--dims`) or a saved one (`--raster`).
    Ray(ray::RayArgs),
}

/// A failure of a subcommand.
#[derive(Debug, thiserror::Error)]
pub enum CliError {
    /// A bad argument value.
    #[error("{arg}: {message}")]
    Arg {
        /// The argument.
        arg: &'static str,
        /// What is wrong.
        message: String,
    },
    /// Writing the report failed.
    #[error("cannot write output")]
    Io(#[from] std::io::Error),
    /// The output file cannot be written.
    #[error("cannot write {}", path.display())]
    Output {
        /// The file.
        path: std::path::PathBuf,
        /// Why.
        #[source]
        source: std::io::Error,
    },
    /// The scene file.
    #[error(transparent)]
    Scene(#[from] crate::scene::SceneError),
    /// Voxelizing the scene.
    #[error(transparent)]
    Build(#[from] crate::voxelize::BuildError),
    /// The view.
    #[error(transparent)]
    Camera(#[from] crate::render::camera::CameraError),
    /// Setting up the tracer.
    #[error(transparent)]
    Trace(#[from] crate::trace::TraceError),
    /// Setting up the tracer over a saved raster that cannot be rendered
    /// so.
    #[error("{}: {why}", path.display())]
    SavedTrace {
        /// The saved raster.
        path: std::path::PathBuf,
        /// Why.
        why: crate::trace::TraceError,
    },
    /// Rendering.
    #[error(transparent)]
    Render(#[from] crate::render::RenderError),
    /// Writing the image.
    #[error(transparent)]
    Image(#[from] crate::output::image::OutputError),
    /// A saved raster.
    #[error(transparent)]
    RasterFile(#[from] crate::output::rasterfile::RasterFileError),
    /// Joining bands.
    #[error(transparent)]
    Stitch(#[from] crate::output::stitch::StitchError),
    /// The thread pool could not be started.
    #[error("cannot start {threads} threads")]
    Threads {
        /// How many (0: one per core).
        threads: usize,
        /// Why.
        #[source]
        source: rayon::ThreadPoolBuildError,
    },
}

/// Runs a parsed command line, writing reports to `out`.
///
/// # Errors
/// The subcommand's [`CliError`].
pub fn run(cli: &Cli, out: &mut impl Write) -> Result<(), CliError> {
    match &cli.command {
        Command::Ray(args) => ray::run(args, out),
        Command::Render(args) => render::run(args, out),
        Command::Stitch(args) => stitch::run(args, out),
        Command::Voxelize(args) => voxelize::run(args, out),
        Command::Info(args) => info::run(args, out),
    }
}
