// Shared by the flash-size firmwares: opaque inputs, a sink, the panic
// handler and the entry point. Included with `include!` so that each
// firmware is one self-contained binary.

use core::panic::PanicInfo;

include!("input.rs");

#[panic_handler]
fn panic(_: &PanicInfo<'_>) -> ! {
    loop {
        core::hint::spin_loop();
    }
}

#[cortex_m_rt::entry]
fn main() -> ! {
    loop {
        drive();
    }
}
