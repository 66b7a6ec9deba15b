//! Arbitrary bytes into the `.vox`, OBJ and Bézier patch readers (the
//! first byte picks one; `rrt_host::check::asset_input` holds the checks,
//! shared with `tests/fuzz_regressions.rs`): nothing may panic, hang or
//! allocate past the size limits; an error names the file; what is read
//! keeps its invariants, and a `.vox` scene voxelizes inside its raster.

#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Err(broken) = rrt_host::check::asset_input(data) {
        panic!("{broken}");
    }
});
