//! The integrator's example: a small scene voxelized into static buffers,
//! lit, and traced into a 64×64 image with integer shading from the
//! records, written as a binary PPM. On a thumb target under QEMU the file
//! is written over semihosting (to the emulator's working directory); on
//! the host the same code writes the path given as the first argument.
#![cfg_attr(target_os = "none", no_std, no_main)]

use rrt_on_target::scene::{self, RenderReport, SceneError, SceneReport, Storage};

/// Builds and renders the scene into `image`.
fn example(
    st: &mut Storage<'_>,
    image: &mut [u8],
) -> Result<(SceneReport, RenderReport), SceneError> {
    let built = scene::build(st)?;
    let records = st.records.get(..built.records).unwrap_or(&[]);
    let shown = scene::render(st.plane, st.lines, st.dir, records, image)?;
    Ok((built, shown))
}

#[cfg(target_os = "none")]
mod firmware {
    use rrt_on_target::firmware::{exit, println};
    use rrt_on_target::{buffer, scene, scene_storage};

    #[cortex_m_rt::entry]
    fn main() -> ! {
        // Everything the scene needs, in static memory (the two macros
        // declare static arrays): no heap, no stack arrays.
        let mut st = scene_storage!();
        let image = buffer!(u8 = 0; scene::IMAGE_LEN);
        match super::example(&mut st, image) {
            Ok((built, shown)) => {
                println!("example: {built:?}");
                println!("example: {shown:?}");
                let mut ppm = [0u8; scene::PPM_HEADER.len() + scene::IMAGE_LEN];
                ppm[..scene::PPM_HEADER.len()].copy_from_slice(scene::PPM_HEADER);
                ppm[scene::PPM_HEADER.len()..].copy_from_slice(image);
                match semihosting::fs::write(c"example.ppm", &ppm[..]) {
                    Ok(()) => exit(0),
                    Err(e) => {
                        println!("example: writing example.ppm: {e:?}");
                        exit(1)
                    }
                }
            }
            Err(e) => {
                println!("example: {e:?}");
                exit(1)
            }
        }
    }
}

#[cfg(not(target_os = "none"))]
fn main() -> std::process::ExitCode {
    use std::io::Write;
    let Some(path) = std::env::args_os().nth(1) else {
        eprintln!("usage: example OUTPUT.ppm");
        return std::process::ExitCode::FAILURE;
    };
    let mut st = rrt_on_target::scene_storage!();
    let mut image = vec![0; scene::IMAGE_LEN];
    match example(&mut st, &mut image) {
        Ok((built, shown)) => {
            println!("example: {built:?}");
            println!("example: {shown:?}");
        }
        Err(e) => {
            eprintln!("example: {e:?}");
            return std::process::ExitCode::FAILURE;
        }
    }
    // Temp file + rename: a half-written image never carries the name.
    let path = std::path::PathBuf::from(path);
    let tmp = path.with_extension("ppm.tmp");
    let written = std::fs::File::create(&tmp)
        .and_then(|mut f| {
            f.write_all(scene::PPM_HEADER)?;
            f.write_all(&image)?;
            f.sync_all()
        })
        .and_then(|()| std::fs::rename(&tmp, &path));
    match written {
        Ok(()) => std::process::ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("example: writing {}: {e}", path.display());
            std::process::ExitCode::FAILURE
        }
    }
}
