//! The digest suite: traversal, packets, voxelizers, the scene and the
//! invariant checkers, printed one line each. Built for a thumb target it
//! runs under QEMU and prints over semihosting; built for the host it
//! prints the same lines (the run script compares them).
#![cfg_attr(target_os = "none", no_std, no_main)]

use rrt_on_target::{Buffers, Event};

/// Prints the suite's lines and a summary; returns whether every check
/// passed.
fn suite(bufs: &mut Buffers<'_>, println: &mut dyn FnMut(core::fmt::Arguments<'_>)) -> bool {
    let (mut digests, mut passed, mut failed) = (0u32, 0u32, 0u32);
    rrt_on_target::run(bufs, &mut |e| {
        match e {
            Event::Digest(_) => digests += 1,
            Event::Check(t) => {
                passed += t.passed;
                failed += t.failed;
            }
            Event::Failure(..) => failed += 1,
        }
        println(format_args!("{e}"));
    });
    println(format_args!(
        "summary: {digests} digests, checks {passed} passed, {failed} failed"
    ));
    failed == 0
}

/// The suite's buffers (static arrays on a thumb target: call it once).
fn buffers() -> Buffers<'static> {
    use rrt_on_target::{buffer, checks, scene, scene_storage, traversal};
    Buffers {
        ray_plane: buffer!(u8 = 0; traversal::PLANE_LEN),
        ray_lines: buffer!(u8 = 0; traversal::LINES_LEN),
        scratch: buffer!(u8 = 0; checks::SCRATCH_LEN),
        scene: scene_storage!(),
        image: buffer!(u8 = 0; scene::IMAGE_LEN),
    }
}

#[cfg(target_os = "none")]
#[cortex_m_rt::entry]
fn main() -> ! {
    use rrt_on_target::firmware::{exit, print};
    let ok = suite(&mut buffers(), &mut |a| print!("{a}\n"));
    exit(if ok { 0 } else { 1 })
}

#[cfg(not(target_os = "none"))]
fn main() -> std::process::ExitCode {
    if suite(&mut buffers(), &mut |a| println!("{a}")) {
        std::process::ExitCode::SUCCESS
    } else {
        std::process::ExitCode::FAILURE
    }
}
