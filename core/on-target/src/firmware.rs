//! The firmware side: output over semihosting, exit codes, static buffers.
#![allow(unsafe_code)]

pub use semihosting::{print, println};

/// Ends the emulation with `code` (QEMU exits with it).
pub fn exit(code: i32) -> ! {
    semihosting::process::exit(code)
}

/// A `&'static mut` to a `static mut` array, for `main` to call once per
/// buffer.
#[macro_export]
macro_rules! take {
    ($name:ident) => {{
        // SAFETY: called once, from `main`, before anything else can
        // refer to the static.
        #[allow(unsafe_code)]
        unsafe {
            &mut *(&raw mut $name)
        }
    }};
}
