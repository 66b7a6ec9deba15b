//! Arbitrary bytes into the camera path reader (`rrt render --path`;
//! `rrt_host::check::path_input` holds the checks, shared with
//! `tests/fuzz_regressions.rs`): nothing may panic or hang; an error names
//! the file; every view read makes a camera.

#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Err(broken) = rrt_host::check::path_input(data) {
        panic!("{broken}");
    }
});
