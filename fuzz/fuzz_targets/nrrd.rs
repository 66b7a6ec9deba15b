//! Arbitrary bytes into the NRRD reader (`rrt_host::check::nrrd_input`
//! holds the checks, shared with `tests/fuzz_regressions.rs`): nothing may
//! panic, hang or allocate past the size limits; an error names the file
//! (and line or byte offset); a volume keeps its invariants, samples within
//! its range, reads back what it writes and makes a raster block.

#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Err(broken) = rrt_host::check::nrrd_input(data) {
        panic!("{broken}");
    }
});
