//! Flash baseline: cortex-m-rt's vector table and reset handler, the
//! opaque-input helpers and a loop; no rrt-core. The other `size-*`
//! firmwares are measured against it.
#![no_std]
#![no_main]

include!("size/common.rs");

fn drive() {
    sink(u64::from(u32_at(0)) ^ u64::from(i32_at(4) as u32) ^ i64_at(8) as u64);
    let _ = point_at(16);
}
