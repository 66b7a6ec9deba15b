//! What `rrt` writes: images in the format their extension names (magic
//! bytes of each, refusals, PNG on standard output) and outputs that
//! survive an interruption (SIGINT or SIGTERM while a raster or an image
//! is being made, or while it is being written, leaves the old file byte
//! for byte and no temporary).

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

const SCENE: &str = "s 0 0 0 1\nl 3 3 3\nf 1 0.5 0.2 0.8 0.2 10 0 1\nv\nfrom 0 -4 1\nat 0 0 0\nup 0 0 1\nangle 45\nhither 0.1\nresolution 16 16\n";

fn rrt() -> Command {
    Command::new(env!("CARGO_BIN_EXE_rrt"))
}

/// A fresh folder with the test scene in it.
fn folder(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("rrt-out-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    std::fs::write(d.join("s.nff"), SCENE).unwrap();
    d
}

fn names(d: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(d)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

fn render(d: &Path, out: &str, extra: &[&str]) -> std::process::Output {
    rrt()
        .current_dir(d)
        .args(["render", "-q", "s.nff", "--raster", "32", "-o", out])
        .args(extra)
        .output()
        .unwrap()
}

#[test]
fn each_format_by_its_magic_bytes() {
    let d = folder("formats");
    for (file, extra, magic) in [
        ("a.png", &[][..], &b"\x89PNG\r\n\x1a\n"[..]),
        ("b.PNG", &["--bits", "16"][..], &b"\x89PNG\r\n\x1a\n"[..]),
        ("c.ppm", &[][..], &b"P6\n16 16\n255\n"[..]),
        ("d.ppm", &["--bits", "16"][..], &b"P6\n16 16\n65535\n"[..]),
        ("e.exr", &[][..], &[0x76, 0x2f, 0x31, 0x01][..]),
        ("f.pfm", &[][..], &b"PF\n16 16\n-1.0\n"[..]),
    ] {
        let out = render(&d, file, extra);
        assert!(
            out.status.success(),
            "{file}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        let bytes = std::fs::read(d.join(file)).unwrap();
        assert!(bytes.starts_with(magic), "{file}: {:?}", &bytes[..16]);
    }
    let size = |f: &str| std::fs::read(d.join(f)).unwrap().len();
    assert_eq!(size("c.ppm"), 13 + 16 * 16 * 3);
    assert_eq!(size("d.ppm"), 15 + 16 * 16 * 6);
    assert_eq!(size("f.pfm"), 14 + 16 * 16 * 12);
    // PNG: the sRGB chunk by default, none with --linear; 16 bits in IHDR.
    let chunk = |f: &str, c: &[u8]| std::fs::read(d.join(f)).unwrap().windows(4).any(|w| w == c);
    assert!(chunk("a.png", b"sRGB"));
    assert_eq!(std::fs::read(d.join("b.PNG")).unwrap()[24], 16);
    assert!(render(&d, "g.png", &["--linear"]).status.success());
    assert!(!chunk("g.png", b"sRGB"));
    assert_eq!(std::fs::read(d.join("g.png")).unwrap()[24], 8);
    // sRGB encoding brightens the mid-tones: the same render, brighter.
    let decode = |f: &str| image::open(d.join(f)).unwrap().to_rgb8().into_raw();
    let (srgb, lin) = (decode("a.png"), decode("g.png"));
    assert!(srgb.iter().zip(&lin).all(|(s, l)| s >= l));
    assert!(srgb.iter().zip(&lin).any(|(s, l)| s > l));
    // The same bytes each time.
    assert!(render(&d, "a2.png", &[]).status.success());
    assert_eq!(size("a.png"), size("a2.png"));
    assert_eq!(
        std::fs::read(d.join("a.png")).unwrap(),
        std::fs::read(d.join("a2.png")).unwrap()
    );
    let _ = std::fs::remove_dir_all(&d);
}

/// The float formats hold the same linear values: the OpenEXR file read
/// back by the `exr` crate equals the PFM file's floats (rows bottom to
/// top there).
#[test]
fn exr_and_pfm_hold_the_same_floats() {
    let d = folder("floats");
    assert!(render(&d, "f.exr", &[]).status.success());
    assert!(render(&d, "f.pfm", &[]).status.success());
    let pfm = std::fs::read(d.join("f.pfm")).unwrap();
    let header = b"PF\n16 16\n-1.0\n";
    assert!(pfm.starts_with(header));
    let floats: Vec<f32> = pfm[header.len()..]
        .chunks_exact(4)
        .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
        .collect();
    let pfm_at = |x: usize, y: usize| {
        let i = 3 * ((15 - y) * 16 + x);
        [floats[i], floats[i + 1], floats[i + 2]]
    };
    let exr = exr::prelude::read_first_rgba_layer_from_file(
        d.join("f.exr"),
        |size, _| vec![[0f32; 3]; size.width() * size.height()],
        |px: &mut Vec<[f32; 3]>, p, (r, g, b, _): (f32, f32, f32, f32)| {
            px[p.y() * 16 + p.x()] = [r, g, b];
        },
    )
    .unwrap();
    let size = exr.layer_data.size;
    assert_eq!((size.width(), size.height()), (16, 16));
    let px = &exr.layer_data.channel_data.pixels;
    assert!(px.iter().flatten().any(|&v| v > 0.0), "an empty image");
    for y in 0..16 {
        for x in 0..16 {
            assert_eq!(px[y * 16 + x], pfm_at(x, y), "pixel {x}, {y}");
        }
    }
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn unknown_formats_and_options_are_refused_before_work() {
    let d = folder("refuse");
    for (file, extra, expect) in [
        (
            "x.jpg",
            &[][..],
            "cannot write .jpg images; the image formats are .png",
        ),
        ("x", &[][..], "cannot write an image without an extension"),
        ("x.tiff", &[][..], ".tiff"),
        (
            "x.exr",
            &["--bits", "16"][..],
            "--bits is for .png and .ppm",
        ),
        ("x.png", &["--bits", "12"][..], "expected 8 or 16"),
    ] {
        let out = render(&d, file, extra);
        assert!(!out.status.success(), "{file}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains(expect), "{file}: {err}");
        assert_eq!(names(&d), ["s.nff"], "{file}");
    }
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn dash_writes_png_to_stdout_and_the_summary_to_stderr() {
    let d = folder("stdout");
    let out = rrt()
        .current_dir(&d)
        .args(["render", "s.nff", "--raster", "32", "-o", "-"])
        .output()
        .unwrap();
    assert!(out.status.success());
    assert!(out.stdout.starts_with(b"\x89PNG\r\n\x1a\n"));
    assert!(String::from_utf8_lossy(&out.stderr).starts_with("-: 16×16"));
    assert!(render(&d, "file.png", &[]).status.success());
    assert_eq!(out.stdout, std::fs::read(d.join("file.png")).unwrap());
    assert_eq!(names(&d), ["file.png", "s.nff"]);
    let _ = std::fs::remove_dir_all(&d);
}

/// When to send the signal: a while after the temporary file appears
/// (the work under way), or as soon as it holds bytes (the output being
/// written).
#[derive(Clone, Copy)]
enum When {
    Working,
    Writing,
}

/// Starts `args` in `d`, waits until the work is under way (`Working`: a
/// while after the start, with no temporary file beside `target`, which
/// exists only while the output is written; `Writing`: until the
/// temporary file has bytes), sends `signal`, and checks that the run
/// fails, `target` is byte for byte what it was and nothing else is left
/// in `d`.
fn interrupt(d: &Path, args: &[&str], target: &str, signal: &str) {
    interrupt_when(d, args, target, signal, When::Working);
}

fn interrupt_when(d: &Path, args: &[&str], target: &str, signal: &str, when: When) {
    let old = std::fs::read(d.join(target)).unwrap();
    let before = names(d);
    let mut child = rrt()
        .current_dir(d)
        .args(args)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let t = Instant::now();
    let temporary = || {
        names(d)
            .into_iter()
            .find(|n| n.starts_with(target) && n.ends_with(".tmp"))
    };
    match when {
        When::Working => {
            // Into the work (voxelizing or rendering): nothing beside the
            // target yet.
            std::thread::sleep(Duration::from_millis(500));
            assert!(child.try_wait().unwrap().is_none(), "finished too soon");
            assert_eq!(temporary(), None, "a temporary file before the output");
        }
        When::Writing => loop {
            let tmp = temporary();
            if tmp.is_some_and(|tmp| std::fs::metadata(d.join(tmp)).is_ok_and(|m| m.len() > 0)) {
                break;
            }
            assert!(
                t.elapsed() < Duration::from_secs(120),
                "no temporary file appeared"
            );
            assert!(child.try_wait().unwrap().is_none(), "finished too soon");
            std::thread::sleep(Duration::from_millis(1));
        },
    }
    assert!(child.try_wait().unwrap().is_none(), "finished too soon");
    let kill = Command::new("kill")
        .args([signal, &child.id().to_string()])
        .status()
        .unwrap();
    assert!(kill.success());
    let out = child.wait_with_output().unwrap();
    assert!(!out.status.success());
    assert!(
        String::from_utf8_lossy(&out.stderr).contains("interrupted"),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert_eq!(std::fs::read(d.join(target)).unwrap(), old, "{target}");
    assert_eq!(names(d), before, "a temporary file was left");
}

#[test]
fn an_interrupted_voxelize_keeps_the_old_raster() {
    let d = folder("int-rrt");
    let made = rrt()
        .current_dir(&d)
        .args(["voxelize", "-q", "s.nff", "--raster", "24", "-o", "x.rrt"])
        .status()
        .unwrap();
    assert!(made.success());
    // The built-in 91-sphereflake at raster 1024 takes seconds.
    interrupt(
        &d,
        &["voxelize", "-q", "--raster", "1024", "-o", "x.rrt"],
        "x.rrt",
        "-INT",
    );
    interrupt(
        &d,
        &["voxelize", "-q", "--raster", "1024", "-o", "x.rrt"],
        "x.rrt",
        "-TERM",
    );
    // While the new raster is being written (where rrt used to write in
    // place and leave a truncated file): a sparse scene whose raster is
    // large (a 500³ plane, 120 MiB) and quick to make, in the dense
    // layout (the sparse one writes a few KiB).
    std::fs::write(
        d.join("sparse.nff"),
        "s 0 0 0 0.05\ns 10 10 10 0.05\nl 5 5 20\nf 1 0.5 0.2 0.8 0.2 10 0 1\nv\nfrom 5 -20 5\nat 5 5 5\nup 0 0 1\nangle 45\nhither 0.1\nresolution 16 16\n",
    )
    .unwrap();
    for signal in ["-INT", "-TERM"] {
        interrupt_when(
            &d,
            &[
                "voxelize",
                "-q",
                "sparse.nff",
                "--dense",
                "--raster",
                "500",
                "-o",
                "x.rrt",
            ],
            "x.rrt",
            signal,
            When::Writing,
        );
    }
    // Still a valid raster.
    let info = rrt()
        .current_dir(&d)
        .args(["info", "x.rrt"])
        .output()
        .unwrap();
    assert!(info.status.success());
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn an_interrupted_render_keeps_the_old_image() {
    let d = folder("int-png");
    assert!(render(&d, "x.png", &[]).status.success());
    assert!(render(&d, "y.exr", &[]).status.success());
    for (target, signal) in [("x.png", "-INT"), ("y.exr", "-TERM")] {
        interrupt(
            &d,
            &[
                "render", "-q", "--raster", "1024", "--width", "400", "--height", "400", "-o",
                target,
            ],
            target,
            signal,
        );
    }
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn an_interrupted_animation_keeps_its_complete_frames_and_says_so() {
    let d = folder("int-orbit");
    let mut child = rrt()
        .current_dir(&d)
        .args([
            "render",
            "-q",
            "--orbit",
            "50",
            "--width",
            "300",
            "--height",
            "300",
            "-o",
            "f-%02d.png",
        ])
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // Frame 2's temporary file: frames 0 and 1 are complete.
    let t = Instant::now();
    while !names(&d)
        .iter()
        .any(|n| n.starts_with("f-02.png") && n.ends_with(".tmp"))
    {
        assert!(
            t.elapsed() < Duration::from_secs(120),
            "frame 2 never started"
        );
        assert!(child.try_wait().unwrap().is_none(), "finished too soon");
        std::thread::sleep(Duration::from_millis(1));
    }
    let kill = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(kill.success());
    let out = child.wait_with_output().unwrap();
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("complete outputs written before stay"),
        "{err}"
    );
    let left = names(&d);
    assert!(!left.iter().any(|n| n.ends_with(".tmp")), "{left:?}");
    // The complete frames are those a render of each frame alone writes.
    for k in ["0", "1"] {
        let name = format!("f-0{k}.png");
        let alone = format!("alone-{k}.png");
        let one = rrt()
            .current_dir(&d)
            .args([
                "render", "-q", "--orbit", "50", "--frame", k, "--width", "300", "--height", "300",
                "-o", &alone,
            ])
            .status()
            .unwrap();
        assert!(one.success());
        let read = |n: &str| std::fs::read(d.join(n)).unwrap();
        assert!(read(&name) == read(&alone), "{name}");
    }
    let _ = std::fs::remove_dir_all(&d);
}
