//! `rrt stitch`: bands written by `rrt render --tile I/N` joined into the
//! whole image.

use std::io::Write;
use std::path::PathBuf;

use super::CliError;
use crate::fit::default_max_memory;
use crate::output::stitch::stitch;

/// Arguments of `rrt stitch`.
#[derive(Debug, Clone, clap::Args)]
pub struct StitchArgs {
    /// The whole image; its extension chooses the format: .png or .ppm
    /// for bands of integer codes (the same bit depth and encoding), .exr
    /// or .pfm for bands of floats, or - for PNG on standard output.
    #[arg(short, long, value_name = "OUT")]
    pub output: PathBuf,
    /// The bands, in order: band 0 (the top one) to band N − 1, all N of
    /// them, each once; .png, .ppm or .exr files written by `rrt render
    /// --tile` for one image (PFM bands cannot say which band they are).
    #[arg(value_name = "BAND", required = true)]
    pub bands: Vec<PathBuf>,
    /// Refuse an image needing more memory than this to stitch (bytes, or
    /// with K, M, G, T suffixes; binary units), checked from the bands'
    /// headers before any pixels are read [default: half of the
    /// machine's RAM].
    #[arg(long, value_name = "SIZE", value_parser = super::common::parse_memory)]
    pub max_memory: Option<u64>,
    /// No summary line.
    #[arg(long, short)]
    pub quiet: bool,
}

/// Runs `rrt stitch`, writing a summary line to `out` (to stderr when the
/// image goes to standard output).
///
/// # Errors
/// [`CliError::Stitch`]: a file that is not a band of the image or out of
/// place (naming it and what is wrong), an output that cannot hold the
/// bands' samples, or the output's error.
pub fn run(args: &StitchArgs, out: &mut impl Write) -> Result<(), CliError> {
    let limit = args.max_memory.unwrap_or_else(default_max_memory);
    let done = stitch(&args.bands, &args.output, limit, out)?;
    if !args.quiet {
        let mut stderr = std::io::stderr();
        let out: &mut dyn Write = if args.output.as_os_str() == "-" {
            &mut stderr
        } else {
            out
        };
        writeln!(
            out,
            "{}: {}×{} from {} bands, {}",
            args.output.display(),
            done.size[0],
            done.size[1],
            done.bands,
            done.kind
        )?;
    }
    Ok(())
}
