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

#[cfg(target_os = "none")]
mod firmware {
    use rrt_core::geometry::BezierPatch;
    use rrt_core::object_table::Object;
    use rrt_core::voxel::VoxelRecord;
    use rrt_on_target::firmware::{exit, print};
    use rrt_on_target::{Buffers, checks, scene, take, traversal};

    static mut RAY_PLANE: [u8; traversal::PLANE_LEN] = [0; traversal::PLANE_LEN];
    static mut RAY_LINES: [u8; traversal::LINES_LEN] = [0; traversal::LINES_LEN];
    static mut SCRATCH: [u8; checks::SCRATCH_LEN] = [0; checks::SCRATCH_LEN];
    static mut PLANE: [u8; scene::PLANE_LEN] = [0; scene::PLANE_LEN];
    static mut LINES: [u8; scene::LINES_LEN] = [0; scene::LINES_LEN];
    static mut DIR: [u32; scene::DIR_LEN] = [0; scene::DIR_LEN];
    static mut RECORDS: [VoxelRecord; scene::MAX_RECORDS] =
        [scene::RECORD_INIT; scene::MAX_RECORDS];
    static mut OBJECTS: [Object; scene::MAX_OBJECTS] = [Object::UNUSED; scene::MAX_OBJECTS];
    static mut PATCHES: [BezierPatch; 1] = [scene::PATCH_INIT];
    static mut IMAGE: [u8; scene::IMAGE_LEN] = [0; scene::IMAGE_LEN];

    #[cortex_m_rt::entry]
    fn main() -> ! {
        let mut bufs = Buffers {
            ray_plane: take!(RAY_PLANE),
            ray_lines: take!(RAY_LINES),
            scratch: take!(SCRATCH),
            scene: scene::Storage {
                plane: take!(PLANE),
                lines: take!(LINES),
                dir: take!(DIR),
                records: take!(RECORDS),
                objects: take!(OBJECTS),
                patches: take!(PATCHES),
            },
            image: take!(IMAGE),
        };
        let ok = super::suite(&mut bufs, &mut |a| print!("{a}\n"));
        exit(if ok { 0 } else { 1 })
    }
}

#[cfg(not(target_os = "none"))]
fn main() -> std::process::ExitCode {
    use rrt_core::object_table::Object;
    use rrt_on_target::{checks, scene, traversal};
    let mut bufs = Buffers {
        ray_plane: &mut vec![0; traversal::PLANE_LEN],
        ray_lines: &mut vec![0; traversal::LINES_LEN],
        scratch: &mut vec![0; checks::SCRATCH_LEN],
        scene: scene::Storage {
            plane: &mut vec![0; scene::PLANE_LEN],
            lines: &mut vec![0; scene::LINES_LEN],
            dir: &mut vec![0; scene::DIR_LEN],
            records: &mut vec![scene::RECORD_INIT; scene::MAX_RECORDS],
            objects: &mut vec![Object::UNUSED; scene::MAX_OBJECTS],
            patches: &mut [scene::PATCH_INIT; 1],
        },
        image: &mut vec![0; scene::IMAGE_LEN],
    };
    if suite(&mut bufs, &mut |a| println!("{a}")) {
        std::process::ExitCode::SUCCESS
    } else {
        std::process::ExitCode::FAILURE
    }
}
