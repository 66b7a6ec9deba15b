//! Support code for the integration tests in `tests/` (and, for the fuzz
//! cases, the cargo-fuzz targets): the seeded RNG, the exact rational
//! oracle for discrete rays ([`oracle`]), the fuzz case types ([`fuzz`],
//! [`packet_case`], [`voxelize_case`]), tunnel-freedom probes
//! ([`tunnel::assert_tunnel_free`]), closed test meshes ([`mesh`]), the
//! float vectors of the test-side geometry ([`vec3`]), one object through
//! both builder passes ([`store::OneObject`]), the location of the shared
//! data folder, small helpers (random planes, soak counts, PSNR, fresh
//! folders), and the `rrt` command line run in-process.

pub mod fuzz;
pub mod mesh;
pub mod oracle;
pub mod packet_case;
pub mod store;
pub mod tunnel;
pub mod vec3;
pub mod voxelize_case;

use std::path::PathBuf;

/// The seeded generator of every test (the core's SplitMix64): each test
/// iteration seeds its own, so any failure can be replayed from the seed
/// printed with it.
pub use rrt_core::rng::Rng;

/// A comb in the plane z = 0, counter-clockwise seen from +z: three teeth
/// (x in [0, 0.5], [1, 2], [3, 4]) rising from y = 1 to 3 over a base
/// from y = 0 to 1, with notches between them (x in (0.5, 1) and (2, 3)
/// above y = 1). Area 9. The fan from its first vertex folds back at the
/// notches and covers them.
pub const COMB: [(f64, f64); 12] = [
    (0.0, 0.0),
    (4.0, 0.0),
    (4.0, 3.0),
    (3.0, 3.0),
    (3.0, 1.0),
    (2.0, 1.0),
    (2.0, 3.0),
    (1.0, 3.0),
    (1.0, 1.0),
    (0.5, 1.0),
    (0.5, 3.0),
    (0.0, 3.0),
];

/// The number the environment variable `var` holds, if it is set to one
/// (the case counts of the soak tests).
#[must_use]
pub fn env_count(var: &str) -> Option<u64> {
    std::env::var(var).ok().and_then(|v| v.parse().ok())
}

/// The seed `RRT_SEED` names, if any: a failure a test replays first.
#[must_use]
pub fn replay_seed() -> Option<u64> {
    env_count("RRT_SEED")
}

/// A plane of `len` cells, each opaque (and nothing else) with probability
/// `num / den`.
pub fn random_opaque(rng: &mut Rng, len: usize, num: u64, den: u64) -> Vec<u8> {
    (0..len)
        .map(|_| {
            if rng.chance(num, den) {
                rrt_core::raster::cell::OPAQUE
            } else {
                0
            }
        })
        .collect()
}

/// The peak signal-to-noise ratio in dB of two 8-bit images (∞ for equal
/// ones), over the pixels both have.
#[must_use]
pub fn psnr(a: &[u8], b: &[u8]) -> f64 {
    let mse = a
        .iter()
        .zip(b)
        .map(|(&x, &y)| (f64::from(x) - f64::from(y)).powi(2))
        .sum::<f64>()
        / a.len() as f64;
    if mse == 0.0 {
        f64::INFINITY
    } else {
        10.0 * (255.0f64 * 255.0 / mse).log10()
    }
}

/// A test's temporary folder, removed with everything in it when dropped
/// (at the end of the test, whether it passes or panics); a path through
/// `Deref`.
#[derive(Debug)]
pub struct Scratch(tempfile::TempDir);

impl std::ops::Deref for Scratch {
    type Target = std::path::Path;
    fn deref(&self) -> &std::path::Path {
        self.0.path()
    }
}

impl AsRef<std::path::Path> for Scratch {
    fn as_ref(&self) -> &std::path::Path {
        self.0.path()
    }
}

/// A fresh, empty temporary folder `<prefix>-<test>-<random>`, removed
/// when the returned guard is dropped.
///
/// # Panics
/// If it cannot be made.
#[must_use]
pub fn fresh_dir(prefix: &str, test: &str) -> Scratch {
    Scratch(
        tempfile::Builder::new()
            .prefix(&format!("{prefix}-{test}-"))
            .tempdir()
            .unwrap(),
    )
}

/// `../shared/data` beside the repository, if present.
#[must_use]
pub fn shared_data() -> Option<PathBuf> {
    let p = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../shared/data");
    p.is_dir().then_some(p)
}

/// A binary PPM (P6, maxval 255) as written by `embree_nff`.
///
/// # Panics
/// On a file that is not such a PPM (a test's fixture is broken).
#[must_use]
pub fn read_ppm(path: &std::path::Path) -> (u32, u32, Vec<u8>) {
    let bytes = std::fs::read(path).unwrap();
    let mut fields = Vec::new();
    let mut at = 0;
    while fields.len() < 4 {
        while bytes[at].is_ascii_whitespace() {
            at += 1;
        }
        let start = at;
        while !bytes[at].is_ascii_whitespace() {
            at += 1;
        }
        fields.push(std::str::from_utf8(&bytes[start..at]).unwrap().to_owned());
    }
    assert_eq!((fields[0].as_str(), fields[3].as_str()), ("P6", "255"));
    let (w, h) = (fields[1].parse().unwrap(), fields[2].parse().unwrap());
    let pixels = bytes[at + 1..].to_vec();
    assert_eq!(pixels.len(), 3 * (w * h) as usize);
    (w, h, pixels)
}

/// `../shared/data/spd` (the SPD scenes), or `None` with a skip message
/// when the shared data is absent.
#[must_use]
pub fn shared_spd() -> Option<PathBuf> {
    let Some(data) = shared_data() else {
        eprintln!("skipped: ../shared/data not present");
        return None;
    };
    Some(data.join("spd"))
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
