//! For the bare-metal targets: the memory map of the board model the
//! firmware runs on (QEMU's MPS2 boards, or the micro:bit with feature
//! `microbit`), and cortex-m-rt's linker script.

use std::env;
use std::fs;
use std::path::PathBuf;

fn main() {
    println!("cargo:rerun-if-changed=build.rs");
    if env::var("CARGO_CFG_TARGET_OS").as_deref() != Ok("none") {
        return;
    }
    // MPS2 AN385/AN386/AN500 (QEMU): 4 MiB SSRAM at 0 holds the image, 4 MiB
    // SSRAM at 0x2000_0000 is data. micro:bit (nRF51822): 256 KiB flash,
    // 16 KiB RAM.
    let memory = if env::var_os("CARGO_FEATURE_MICROBIT").is_some() {
        "MEMORY\n{\n  FLASH : ORIGIN = 0x00000000, LENGTH = 256K\n  RAM : ORIGIN = 0x20000000, LENGTH = 16K\n}\n"
    } else {
        "MEMORY\n{\n  FLASH : ORIGIN = 0x00000000, LENGTH = 4M\n  RAM : ORIGIN = 0x20000000, LENGTH = 4M\n}\n"
    };
    let out = PathBuf::from(env::var_os("OUT_DIR").expect("cargo sets OUT_DIR"));
    fs::write(out.join("memory.x"), memory).expect("OUT_DIR is writable");
    println!("cargo:rustc-link-search={}", out.display());
    println!("cargo:rustc-link-arg-bins=-Tlink.x");
    println!("cargo:rerun-if-env-changed=CARGO_FEATURE_MICROBIT");
}
