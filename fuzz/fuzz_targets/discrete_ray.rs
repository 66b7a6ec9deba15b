//! Fuzzes the discrete ray: arbitrary rasters, cells and rays (including
//! out-of-range and degenerate ones) against the exact oracle and every
//! invariant checker. Crashes replay with `cargo test -p rrt-tests --test
//! fuzz_regressions` once copied to tests/fuzz_regressions/discrete_ray/.
#![no_main]

use libfuzzer_sys::fuzz_target;
use rrt_tests::fuzz::{RayCase, run_ray_case};

fuzz_target!(|case: RayCase| run_ray_case(&case));
