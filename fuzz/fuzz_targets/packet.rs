//! Fuzzes the ray packet: arbitrary rasters, cells, distance fields and
//! line levels, up to eight lanes (degenerate, out-of-range, part-walked)
//! and scripts of walks, plain and skipping, each lane checked against its
//! scalar discrete ray after every walk. Crashes replay with
//! `cargo test -p rrt-tests --test packet` once copied to
//! tests/fuzz_regressions/packet/.
#![no_main]

use libfuzzer_sys::fuzz_target;
use rrt_tests::packet_case::{PacketCase, run_packet_case};

fuzz_target!(|case: PacketCase| run_packet_case(&case));
