//! Replays the inputs cargo-fuzz found (and a few seeds) through the same
//! decoding and checkers as the fuzz targets in `fuzz/`.
//!
//! Each file under `tests/fuzz_regressions/<target>/` is raw fuzzer input.
//! Inputs that once crashed keep a comment in `README.md` beside them with
//! the root cause and the fix.

use std::path::Path;

use arbitrary::{Arbitrary, Unstructured};
use rrt_tests::fuzz::{RayCase, run_ray_case};

fn inputs(target: &str) -> Vec<(String, Vec<u8>)> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("fuzz_regressions")
        .join(target);
    let mut out: Vec<(String, Vec<u8>)> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_none_or(|x| x != "md"))
        .map(|p| {
            (
                p.file_name().unwrap().to_string_lossy().into_owned(),
                std::fs::read(&p).unwrap(),
            )
        })
        .collect();
    out.sort();
    assert!(!out.is_empty(), "no inputs in {}", dir.display());
    out
}

/// Replays the inputs of `target` as their `Arbitrary` decoding, each
/// printed, through `run`.
fn replay_decoded<T: for<'a> Arbitrary<'a> + std::fmt::Debug>(target: &str, run: impl Fn(T)) {
    for (name, bytes) in inputs(target) {
        let case = T::arbitrary_take_rest(Unstructured::new(&bytes))
            .unwrap_or_else(|e| panic!("{name}: does not decode: {e}"));
        eprintln!("{name}: {case:?}");
        run(case);
    }
}

/// Replays the inputs of `target` through the checker `check`.
fn replay_checked(target: &str, check: fn(&[u8]) -> Result<(), String>) {
    for (name, bytes) in inputs(target) {
        if let Err(broken) = check(&bytes) {
            panic!("{name}: {broken}");
        }
    }
}

#[test]
fn discrete_ray_inputs_replay() {
    replay_decoded("discrete_ray", |case: RayCase| run_ray_case(&case));
}

#[test]
fn nff_inputs_replay() {
    replay_checked("nff", rrt_host::check::nff_input);
}

#[test]
fn voxelize_inputs_replay() {
    replay_decoded("voxelize", rrt_tests::voxelize_case::run);
}

#[test]
fn nrrd_inputs_replay() {
    replay_checked("nrrd", rrt_host::check::nrrd_input);
}

#[test]
fn camera_path_inputs_replay() {
    replay_checked("camera_path", rrt_host::check::path_input);
}

#[test]
fn scene_toml_inputs_replay() {
    replay_checked("scene_toml", rrt_host::check::toml_input);
}

#[test]
fn raster_file_inputs_replay() {
    replay_checked("raster_file", rrt_host::check::raster_file_input);
}

#[test]
fn asset_inputs_replay() {
    replay_checked("assets", rrt_host::check::asset_input);
}
