//! Arbitrary bytes into the NFF parser, then into the camera and the
//! raster fit (`rrt_host::check::nff_input` holds the checks, shared with
//! `tests/nff.rs`): nothing may panic or hang; an error names the file; a
//! scene that parses keeps every guarantee documented on `Scene`, makes a
//! camera, and fits a small raster or returns a `FitError`.

#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Err(broken) = rrt_host::check::nff_input(data) {
        panic!("{broken}");
    }
});
