//! Arbitrary bytes into the TOML scene parser (without reading files) and
//! the raster fit (`rrt_host::check::toml_input` holds the checks, shared
//! with `tests/fuzz_regressions.rs`): nothing may panic or hang; an error
//! names the file; a scene that parses keeps every guarantee documented on
//! `Scene`.

#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Err(broken) = rrt_host::check::toml_input(data) {
        panic!("{broken}");
    }
});
