//! Support code for the integration tests in `tests/` (and, for the fuzz
//! cases, the cargo-fuzz targets): the seeded RNG, the exact rational
//! oracle for discrete rays ([`oracle`]), the fuzz case types ([`fuzz`],
//! [`packet_case`], [`voxelize_case`]), tunnel-freedom probes
//! ([`tunnel::assert_tunnel_free`]), closed test meshes ([`mesh`]), the
//! location of the shared data folder, and the `rrt` command line run
//! in-process.

pub mod fuzz;
pub mod mesh;
pub mod oracle;
pub mod packet_case;
pub mod tunnel;
pub mod vec3;
pub mod voxelize_case;

use std::path::PathBuf;

/// The seeded generator of every test (the core's SplitMix64): each test
/// iteration seeds its own, so any failure can be replayed from the seed
/// printed with it.
pub use rrt_core::rng::Rng;

/// `../shared/data` beside the repository, if present.
#[must_use]
pub fn shared_data() -> Option<PathBuf> {
    let p = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../shared/data");
    p.is_dir().then_some(p)
}

/// Runs the `rrt` command line with `args` (without the program name):
/// its standard output, or its error with every source in the chain, as a
/// user would read it.
///
/// # Errors
/// The argument parser's or the command's message.
pub fn run_cli(args: &[&str]) -> Result<String, String> {
    use clap::Parser;
    let c = rrt_host::cli::Cli::try_parse_from(std::iter::once("rrt").chain(args.iter().copied()))
        .map_err(|e| e.to_string())?;
    let mut out = Vec::new();
    rrt_host::cli::run(&c, &mut out).map_err(|e| {
        let mut msg = e.to_string();
        let mut src = std::error::Error::source(&e);
        while let Some(s) = src {
            msg.push_str(&format!(": {s}"));
            src = s.source();
        }
        msg
    })?;
    String::from_utf8(out).map_err(|e| e.to_string())
}
