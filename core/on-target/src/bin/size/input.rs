// Opaque inputs and a sink: what the flash-size firmwares and
// `core/panic-never` drive rrt-core with, so that the optimizer can assume
// nothing about the inputs and keep every result. Included with `include!`.

use core::ptr::{addr_of, addr_of_mut, read_volatile, write_volatile};

/// Opaque inputs: the optimizer must assume any bytes here.
static mut INPUT: [u8; 256] = [0; 256];
/// Results, so that nothing is optimized away.
static mut SINK: u64 = 0;

fn input<const N: usize>(at: usize) -> [u8; N] {
    let mut out = [0u8; N];
    for (i, b) in out.iter_mut().enumerate() {
        // SAFETY: in-bounds volatile reads of a static byte array.
        *b = unsafe { read_volatile(addr_of!(INPUT).cast::<u8>().add((at + i) % 256)) };
    }
    out
}
fn u32_at(at: usize) -> u32 {
    u32::from_le_bytes(input(at))
}
fn i32_at(at: usize) -> i32 {
    i32::from_le_bytes(input(at))
}
fn i64_at(at: usize) -> i64 {
    i64::from_le_bytes(input(at))
}
fn point_at(at: usize) -> [i64; 3] {
    [i64_at(at), i64_at(at + 8), i64_at(at + 16)]
}
fn sink(v: u64) {
    // SAFETY: a volatile read-modify-write of a static.
    unsafe { write_volatile(addr_of_mut!(SINK), read_volatile(addr_of!(SINK)) ^ v) };
}
