//! The `rrt` command line. The binary (`src/bin/rrt.rs`) only parses the
//! arguments and prints errors; each subcommand lives in its own module here.

pub mod num;
pub mod ray;

use std::io::Write;

/// rrt: 3D raster (discrete) ray tracing.
#[derive(Debug, clap::Parser)]
#[command(name = "rrt", version, about, long_about = None)]
pub struct Cli {
    /// What to do.
    #[command(subcommand)]
    pub command: Command,
}

/// The subcommands.
#[derive(Debug, clap::Subcommand)]
pub enum Command {
    /// Trace one discrete ray and list its voxels, one `x y z` per line.
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
    /// Writing the output failed.
    #[error("cannot write output")]
    Io(#[from] std::io::Error),
}

/// Runs a parsed command line, writing reports to `out`.
///
/// # Errors
/// The subcommand's [`CliError`].
pub fn run(cli: &Cli, out: &mut impl Write) -> Result<(), CliError> {
    match &cli.command {
        Command::Ray(args) => ray::run(args, out),
    }
}
