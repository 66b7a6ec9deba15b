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

#[test]
fn discrete_ray_inputs_replay() {
    for (name, bytes) in inputs("discrete_ray") {
        let case = RayCase::arbitrary_take_rest(Unstructured::new(&bytes))
            .unwrap_or_else(|e| panic!("{name}: does not decode: {e}"));
        eprintln!("{name}: {case:?}");
        run_ray_case(&case);
    }
}

#[test]
fn nff_inputs_replay() {
    for (name, bytes) in inputs("nff") {
        if let Err(broken) = rrt_host::check::nff_input(&bytes) {
            panic!("{name}: {broken}");
        }
    }
}

#[test]
fn voxelize_inputs_replay() {
    for (name, bytes) in inputs("voxelize") {
        let input = rrt_tests::voxelize_case::Input::arbitrary_take_rest(Unstructured::new(&bytes))
            .unwrap_or_else(|e| panic!("{name}: does not decode: {e}"));
        eprintln!("{name}: {input:?}");
        rrt_tests::voxelize_case::run(input);
    }
}

#[test]
fn nrrd_inputs_replay() {
    for (name, bytes) in inputs("nrrd") {
        if let Err(broken) = rrt_host::check::nrrd_input(&bytes) {
            panic!("{name}: {broken}");
        }
    }
}

#[test]
fn scene_toml_inputs_replay() {
    for (name, bytes) in inputs("scene_toml") {
        if let Err(broken) = rrt_host::check::toml_input(&bytes) {
            panic!("{name}: {broken}");
        }
    }
}
