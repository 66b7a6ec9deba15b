//! Saved rasters into the loader (`rrt_host::check::raster_file_input`
//! holds the checks, shared with `tests/fuzz_regressions.rs`): arbitrary
//! bytes, and valid files with changed bytes, with and without their
//! checksums recomputed. Nothing may panic, hang or allocate past the
//! file's size; an error names the file; a corrupted file is refused; what
//! loads saves and loads again the same, and renders.

#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Err(broken) = rrt_host::check::raster_file_input(data) {
        panic!("{broken}");
    }
});
