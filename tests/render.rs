//! The renderer end to end: determinism across thread counts, saved rasters
//! (round trip, corruption), intersection verification on known false
//! hits, and a fidelity floor against `embree_nff`'s images.

use std::path::{Path, PathBuf};

use glam::DVec3;
use indicatif::ProgressBar;
use rrt_core::Connectivity;
use rrt_host::output::encoding::{Codes, Encoding, codes};
use rrt_host::output::png::png_bytes;
use rrt_host::output::rasterfile;
use rrt_host::render::band::Band;
use rrt_host::render::camera::Camera;
use rrt_host::render::{Image, RenderOptions, render, render_rows};
use rrt_host::scene::Scene;
use rrt_host::trace::{Mode, RayStats, TraceOptions, Tracer};
use rrt_host::voxelize::{BuildOptions, VoxelScene, build};

fn data(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("data")
        .join(name)
}

/// The built-in scene (SPD balls2), kept in the host crate.
fn balls2() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../std-host/scenes/balls2.nff")
}

/// A fresh temporary folder for one test.
fn temp_dir(test: &str) -> rrt_tests::Scratch {
    rrt_tests::fresh_dir("rrt-test", test)
}

/// The paper's raster, for rays of connectivity `mode`.
fn voxelize(scene: &Scene, raster: u32, mode: Connectivity) -> VoxelScene {
    let mut o = BuildOptions::paper(raster);
    o.connectivity = mode;
    o.fit.max_memory = 1 << 30;
    build(scene, &o, &ProgressBar::hidden()).unwrap().0
}

/// The raster `rrt voxelize` saves: every object conservatively, with
/// object lists and the shadow classification.
fn voxelize_exact(scene: &Scene, raster: u32) -> VoxelScene {
    let mut o = BuildOptions::new(raster);
    o.fit.max_memory = 1 << 30;
    build(scene, &o, &ProgressBar::hidden()).unwrap().0
}

fn draw(
    vs: &VoxelScene,
    w: u32,
    h: u32,
    trace: TraceOptions,
    k: u32,
    threads: usize,
) -> (Image, RayStats) {
    let tracer = Tracer::new(vs, trace).unwrap();
    let cam = Camera::new(&vs.view, w, h).unwrap();
    let opts = RenderOptions {
        supersample: k,
        threads,
        alpha: false,
    };
    let (img, stats, _) = render(&tracer, &cam, &opts, &ProgressBar::hidden()).unwrap();
    (img, stats)
}

fn cli(args: &[&str]) -> Result<String, String> {
    rrt_tests::run_cli(args)
}

/// `rrt render INPUT -o OUTPUT EXTRA…`, which must succeed.
#[track_caller]
fn render_to(input: &Path, output: &Path, extra: &[&str]) {
    let args = [
        "render",
        input.to_str().unwrap(),
        "-o",
        output.to_str().unwrap(),
    ];
    cli(&[&args[..], extra].concat()).unwrap();
}

/// The report of `rrt ray --raster RASTER --origin ORIGIN --dir 1,0,0
/// EXTRA…`, which must succeed.
#[track_caller]
fn ray_along_x(raster: &Path, origin: &str, extra: &[&str]) -> String {
    let args = [
        "ray",
        "--raster",
        raster.to_str().unwrap(),
        "--origin",
        origin,
        "--dir",
        "1,0,0",
    ];
    cli(&[&args[..], extra].concat()).unwrap()
}

/// PSNR in dB of two RGB images of the same size.
fn psnr(a: &[u8], b: &[u8]) -> f64 {
    assert_eq!(a.len(), b.len());
    rrt_tests::psnr(a, b)
}

fn read_png(path: &Path) -> (u32, u32, Vec<u8>) {
    let img = image::open(path).unwrap().to_rgb8();
    (img.width(), img.height(), img.into_raw())
}

/// The PNG is byte-identical for 1, 2 and 3 threads (and so are the ray
/// counts), in the paper's and the exact mode, with and without
/// supersampling, on an image whose size is not a multiple of the tile or
/// block; and with ray packets for the primary walk instead of the
/// scalar walk (both skipping empty space).
#[test]
fn png_is_identical_for_every_thread_count() {
    let scene = Scene::load(data("balls1.nff")).unwrap();
    let paper = voxelize(&scene, 160, Connectivity::Adaptive);
    let exact = voxelize_exact(&scene, 160);
    // The parallel light pass (paper bits, shadow classification) gives
    // the same records on 1 and 3 threads.
    for threads in [1, 3] {
        for (o, vs) in [
            (BuildOptions::paper(160), &paper),
            (BuildOptions::new(160), &exact),
        ] {
            let o = BuildOptions { threads, ..o };
            let other = build(&scene, &o, &ProgressBar::hidden()).unwrap().0;
            assert_eq!(other.records, vs.records, "light pass on {threads} threads");
        }
    }
    for (mode, k) in [(Mode::Paper, 1), (Mode::Exact, 2)] {
        let vs = if mode == Mode::Paper { &paper } else { &exact };
        let trace = TraceOptions {
            mode,
            packets: true,
            ..TraceOptions::default()
        };
        let (one, s1) = draw(vs, 70, 45, trace, k, 1);
        let png1 = png_bytes(&one).unwrap();
        for threads in [2, 3] {
            let (img, s) = draw(vs, 70, 45, trace, k, threads);
            assert_eq!(
                png_bytes(&img).unwrap(),
                png1,
                "{threads} threads, {mode:?}, supersample {k}"
            );
            // The linear values behind the sRGB, 16-bit and float outputs too.
            assert_eq!(img.linear, one.linear, "{threads} threads");
            assert_eq!(s, s1);
        }
        // The scalar primary walk gives the same image as the packets.
        let scalar = TraceOptions {
            packets: false,
            ..trace
        };
        let (img, s) = draw(vs, 70, 45, scalar, k, 2);
        assert_eq!(png_bytes(&img).unwrap(), png1, "scalar walk, {mode:?}");
        // The same counts, steps included: the packet lanes skip empty
        // space exactly as the scalar walk does.
        assert_eq!(s, s1);
        assert_eq!(s1.primary, 70 * 45 * u64::from(k * k));
        assert!(s1.hits > 0 && s1.reflected > 0);
    }
}

/// With alpha asked for, the colours are the same bytes; the coverage is 1
/// where rays end on a sphere (matte or mirror) and 0 where they see the
/// background (a pixel's share of its rays with supersampling), the
/// straight colour is the colour where the coverage is 1 or 0 and over
/// the background gives it elsewhere; all of it the same bits on 1, 2 and
/// 3 threads.
#[test]
fn alpha_is_the_coverage_for_every_thread_count() {
    // A matte sphere and a mirror sphere, background all around.
    let dir = temp_dir("alpha");
    let nff = dir.join("two.nff");
    std::fs::write(
        &nff,
        "b 0.1 0.3 0.7\nv\nfrom 0 -6 1\nat 0 0 0\nup 0 0 1\nangle 40\nhither 0.01\nresolution 70 45\n\
         l 3 -4 5\nf 1 0.5 0.2 0.8 0.2 20 0 1\ns -0.9 0 0 0.8\nf 0.9 0.9 0.9 0.1 0.9 50 0 1\ns 0.9 0 0 0.8\n",
    )
    .unwrap();
    let scene = Scene::load(&nff).unwrap();
    let exact = voxelize_exact(&scene, 96);
    let bg = exact.background.as_vec3().to_array();
    let bits = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
    let tracer = Tracer::new(&exact, TraceOptions::default()).unwrap();
    let cam = Camera::new(&exact.view, 70, 45).unwrap();
    for k in [1, 2] {
        let (plain, _) = draw(&exact, 70, 45, TraceOptions::default(), k, 1);
        assert!(plain.alpha.is_none());
        let with = |threads| {
            let opts = RenderOptions {
                supersample: k,
                threads,
                alpha: true,
            };
            render(&tracer, &cam, &opts, &ProgressBar::hidden())
                .unwrap()
                .0
        };
        let one = with(1);
        assert_eq!(one.rgb, plain.rgb);
        assert_eq!(bits(&one.linear), bits(&plain.linear));
        let a = one.alpha.as_ref().unwrap();
        assert_eq!(a.coverage.len(), 70 * 45);
        for threads in [2, 3] {
            let other = with(threads);
            let b = other.alpha.as_ref().unwrap();
            assert_eq!(bits(&b.coverage), bits(&a.coverage), "{threads} threads");
            assert_eq!(bits(&b.straight), bits(&a.straight), "{threads} threads");
        }
        let count = |f: &dyn Fn(f32) -> bool| a.coverage.iter().filter(|&&c| f(c)).count();
        let (full, empty) = (count(&|c| c == 1.0), count(&|c| c == 0.0));
        let partial = a.coverage.len() - full - empty;
        assert!(full > 0 && empty > 0, "{full} {empty}");
        if k == 1 {
            assert_eq!(partial, 0);
        } else {
            assert!(partial > 0);
            assert!(count(&|c| ![0.0, 0.25, 0.5, 0.75, 1.0].contains(&c)) == 0);
        }
        for (p, &c) in a.coverage.iter().enumerate() {
            let (s, l) = (&a.straight[3 * p..3 * p + 3], &one.linear[3 * p..3 * p + 3]);
            if c == 0.0 {
                assert_eq!(l, bg, "{p}");
            }
            if c == 0.0 || c == 1.0 {
                assert_eq!(bits(s), bits(l), "{p}");
            }
            for ((s, l), b) in s.iter().zip(l).zip(bg) {
                assert!((s * c + b * (1.0 - c) - l).abs() < 1e-5, "{p}");
            }
        }
    }
}

/// A volume rendered directly, mixed with a sphere and a mirror (eye,
/// reflected and shadow rays composite it): the image is byte-identical for
/// 1, 2 and 3 threads, in every mode, and the volume is composited.
#[test]
fn direct_volume_png_is_identical_for_every_thread_count() {
    let d = temp_dir("dvr-threads");
    let p = d.join("dvr.toml");
    std::fs::write(
        &p,
        r#"
[camera]
from = [3, 4, 2.5]
at = [0, 0, 0.5]
angle = 40
resolution = [40, 30]

[[light]]
position = [4, 3, 6]

[material.cloud]
colour = [0.9, 0.6, 0.3]
ks = 0.2
shine = 10

[material.ball]
colour = [0.2, 0.5, 0.9]

[material.mirror]
colour = [0.2, 0.2, 0.2]
kd = 0.2
ks = 0.8

[volume.cloud]
metaballs = { dims = [24, 24, 24], min = [-1, -1, 0], max = [1, 1, 2], balls = [[-0.3, 0, 0.8, 0.8, 1], [0.4, 0.2, 1.2, 0.6, 1]] }
opacity = [[0.2, 0], [0.5, 0.1], [1.5, 0.6]]
colours = [[0.2, 1, 0.8, 0.5], [1.5, 0.9, 0.3, 0.2]]

[[object]]
material = "cloud"
volume = "cloud"

[[object]]
material = "ball"
sphere = { centre = [0.2, 0.1, 0.9], radius = 0.35 }

[[object]]
material = "mirror"
polygon = [[-2, -1.5, 0], [2, -1.5, 0], [2, -1.5, 2.5], [-2, -1.5, 2.5]]
"#,
    )
    .unwrap();
    let scene = Scene::load(&p).unwrap();
    assert!(scene.volumes[0].data.classifier.is_direct());
    let exact = voxelize_exact(&scene, 64);
    let paper = voxelize(&scene, 64, Connectivity::Adaptive);
    assert_eq!(exact.direct.len(), 1);
    for (mode, vs) in [
        (Mode::Exact, &exact),
        (Mode::Verified, &exact),
        (Mode::Paper, &paper),
    ] {
        let trace = TraceOptions {
            mode,
            ..TraceOptions::default()
        };
        let (one, s1) = draw(vs, 40, 30, trace, 2, 1);
        assert!(s1.samples > 0 && s1.reflected > 0, "{mode:?}: {s1:?}");
        let png1 = png_bytes(&one).unwrap();
        for threads in [2, 3] {
            let (img, s) = draw(vs, 40, 30, trace, 2, threads);
            assert_eq!(
                png_bytes(&img).unwrap(),
                png1,
                "{threads} threads, {mode:?}"
            );
            assert_eq!(img.linear, one.linear, "{threads} threads, {mode:?}");
            assert_eq!(s, s1);
        }
    }
}

/// `rrt voxelize` then `rrt render FILE.rrt` writes the same PNG as
/// `rrt render SCENE` with the same raster; view overrides apply to a saved
/// raster; `rrt info` reports it.
/// A band's pixels are the same rows of the whole image, bit for bit,
/// whatever the split (bands cutting the 8-row tiles and the 2-row ray
/// blocks), with packets or scalar walks, with and without supersampling.
#[test]
fn bands_are_the_rows_of_the_whole_image() {
    let scene = Scene::load(balls2()).unwrap();
    let paper = voxelize(&scene, 64, Connectivity::Adaptive);
    let exact = voxelize_exact(&scene, 64);
    let (w, h) = (37, 23);
    let mut checked = 0;
    for (mode, vs) in [(Mode::Paper, &paper), (Mode::Exact, &exact)] {
        for (packets, k) in [(true, 1), (false, 2)] {
            let trace = TraceOptions {
                mode,
                packets,
                ..TraceOptions::default()
            };
            let (whole, _) = draw(vs, w, h, trace, k, 2);
            let tracer = Tracer::new(vs, trace).unwrap();
            let cam = Camera::new(&vs.view, w, h).unwrap();
            let opts = RenderOptions {
                supersample: k,
                threads: 2,
                alpha: false,
            };
            for n in [2, 3, 5, 7, 23] {
                for i in 0..n {
                    let rows = Band::new(i, n, h).unwrap().rows(h);
                    let (band, ..) =
                        render_rows(&tracer, &cam, &opts, rows.clone(), &ProgressBar::hidden())
                            .unwrap();
                    let (a, b) = (3 * (w * rows.start) as usize, 3 * (w * rows.end) as usize);
                    assert_eq!(band.height, rows.end - rows.start);
                    assert_eq!(band.rgb, whole.rgb[a..b], "{mode:?} band {i}/{n}");
                    let same_bits = band
                        .linear
                        .iter()
                        .zip(&whole.linear[a..b])
                        .all(|(x, y)| x.to_bits() == y.to_bits());
                    assert!(same_bits, "{mode:?} band {i}/{n} linear");
                    checked += 1;
                }
            }
        }
    }
    println!("{checked} bands checked against their whole images");
    let tracer = Tracer::new(&exact, TraceOptions::default()).unwrap();
    let cam = Camera::new(&exact.view, w, h).unwrap();
    for bad in [0..0, 5..5, 20..24] {
        let e = render_rows(
            &tracer,
            &cam,
            &RenderOptions::default(),
            bad.clone(),
            &ProgressBar::hidden(),
        );
        assert!(e.is_err(), "{bad:?}");
    }
}

#[test]
fn saved_raster_renders_like_the_scene() {
    let dir = temp_dir("roundtrip");
    let rrt = dir.join("b1.rrt");
    let (direct, saved) = (dir.join("direct.png"), dir.join("saved.png"));
    let scene = data("balls1.nff");
    let s = scene.to_str().unwrap();
    let common = ["--width", "48", "--height", "40", "-q"];
    cli(&[
        "voxelize",
        s,
        "-o",
        rrt.to_str().unwrap(),
        "--raster",
        "128",
        "-q",
    ])
    .unwrap();
    render_to(
        &scene,
        &direct,
        &[&["--raster", "128"][..], &common].concat(),
    );
    render_to(&rrt, &saved, &common);
    assert_eq!(
        std::fs::read(&direct).unwrap(),
        std::fs::read(&saved).unwrap()
    );

    // The loaded scene equals the built one.
    let built = voxelize_exact(&Scene::load(&scene).unwrap(), 128);
    let loaded = rasterfile::load(&rrt).unwrap();
    assert_eq!(&built.plane[..], &loaded.plane[..]);
    assert_eq!(built.directory, loaded.directory);
    assert_eq!(built.records, loaded.records);
    assert_eq!(built.lists, loaded.lists);
    assert_eq!(built.objects, loaded.objects);
    assert_eq!(built.frame, loaded.frame);
    assert_eq!(built.lights, loaded.lights);

    // Another view of the saved raster.
    let moved = dir.join("moved.png");
    let view_args = ["--from", "-2.1,1.3,1.7", "--angle", "50"];
    render_to(&rrt, &moved, &[&view_args[..], &common].concat());
    assert_ne!(
        std::fs::read(&moved).unwrap(),
        std::fs::read(&saved).unwrap()
    );
    let mut view = loaded.view.clone();
    view.from = DVec3::new(-2.1, 1.3, 1.7);
    view.angle = 50.0;
    let tracer = Tracer::new(&loaded, TraceOptions::default()).unwrap();
    let cam = Camera::new(&view, 48, 40).unwrap();
    let (img, _, _) = render(
        &tracer,
        &cam,
        &RenderOptions::default(),
        &ProgressBar::hidden(),
    )
    .unwrap();
    // The CLI's default PNG is sRGB-encoded.
    let Codes::Eight(srgb) = codes(&img, Encoding::default()) else {
        panic!("8-bit codes expected");
    };
    assert_eq!(read_png(&moved).2, srgb);

    let info = cli(&["info", rrt.to_str().unwrap()]).unwrap();
    let d = loaded.extent().dims();
    assert!(
        info.contains(&format!("dimensions: {}×{}×{} voxels", d[0], d[1], d[2])),
        "{info}"
    );
    assert!(
        info.contains(&format!("voxels: {} surface voxels", loaded.records.len())),
        "{info}"
    );
    assert!(
        info.contains("objects: 12, materials: 2, lights: 3"),
        "{info}"
    );
    assert!(info.contains("voxel size: "), "{info}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// Truncated, corrupt, wrong-version and foreign files are refused with a
/// message naming the file and the problem; none panics.
#[test]
fn damaged_raster_files_are_refused() {
    let dir = temp_dir("damaged");
    let good = dir.join("good.rrt");
    let scene = Scene::load(data("tetra.nff")).unwrap();
    let vs = voxelize(&scene, 48, Connectivity::Adaptive);
    // The dense layout (version 2) first, then the sparse one (version 3).
    let bytes = rasterfile::save_bytes_as(&vs, &good, rasterfile::Format::Dense).unwrap();
    std::fs::write(&good, &bytes).unwrap();
    let load = |name: &str, b: &[u8]| -> String {
        let p = dir.join(name);
        std::fs::write(&p, b).unwrap();
        let e = rasterfile::load(&p).unwrap_err().to_string();
        assert!(e.starts_with(&p.display().to_string()), "{e}");
        // `rrt render` says the same: a file named `.rrt` is read as a
        // raster, whatever it holds (a truncated magic, a scene, nothing).
        let out = dir.join("x.png");
        let r = cli(&[
            "render",
            p.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
            "-q",
        ]);
        assert!(r.unwrap_err().contains(&e), "{name}");
        e
    };
    assert!(rasterfile::load(&good).is_ok());

    let e = load("half.rrt", &bytes[..bytes.len() / 2]);
    assert!(e.contains("truncated"), "{e}");
    let e = load("header-only.rrt", &bytes[..100]);
    assert!(e.contains("truncated"), "{e}");
    // The last byte (padding after the last section) gone, or bytes added
    // after the end: not the file that was written.
    assert_eq!(bytes.len() % 64, 0);
    let e = load("short.rrt", &bytes[..bytes.len() - 1]);
    assert!(e.contains("truncated: the file has"), "{e}");
    let e = load("long.rrt", &[&bytes[..], &[0u8; 64]].concat());
    assert!(e.contains("64 bytes after the end of the raster"), "{e}");

    let mut v4 = bytes.clone();
    v4[8] = 4;
    let e = load("v4.rrt", &v4);
    assert!(
        e.contains("raster file version 4; this rrt reads versions 1 to 3"),
        "{e}"
    );
    // A version 1 file relabelled version 2 (which has 8 sections): its
    // header no longer checks out.
    let mut v2 = bytes.clone();
    v2[8] = 2;
    let e = load("v2.rrt", &v2);
    assert!(
        e.contains("corrupt: the header checksum") || e.contains("sections"),
        "{e}"
    );

    let mut bad_header = bytes.clone();
    bad_header[20] ^= 0x40;
    let e = load("header.rrt", &bad_header);
    assert!(e.contains("corrupt: the header checksum"), "{e}");

    // A flipped bit in the plane and one near the end (records or tables).
    let mut plane = bytes.clone();
    plane[384 + 100] ^= 1;
    let e = load("plane.rrt", &plane);
    assert!(e.contains("corrupt: the plane checksum"), "{e}");
    let mut tail = bytes.clone();
    let n = tail.len();
    tail[n - 70] ^= 0x10;
    let e = load("tail.rrt", &tail);
    assert!(e.contains("corrupt:") && e.contains("checksum"), "{e}");

    // Version 3: a flipped byte in each section is refused, naming the
    // section and its bytes.
    let sparse = rasterfile::save_bytes(&vs, &good).unwrap();
    assert_eq!(u32::from_le_bytes(sparse[8..12].try_into().unwrap()), 3);
    for (k, name) in [
        "meta",
        "plane bricks",
        "directory",
        "records",
        "objects",
        "materials",
        "lights",
    ]
    .iter()
    .enumerate()
    {
        let at = 16 + 32 * k;
        let off = u64::from_le_bytes(sparse[at + 16..at + 24].try_into().unwrap()) as usize;
        let len = u64::from_le_bytes(sparse[at + 24..at + 32].try_into().unwrap()) as usize;
        if len == 0 {
            continue;
        }
        let mut bad = sparse.clone();
        bad[off + len / 2] ^= 0x08;
        let e = load(&format!("v3-{k}.rrt"), &bad);
        assert!(
            e.contains(&format!(
                "corrupt: the {name} checksum does not match (bytes {off} to {})",
                off + len
            )),
            "{e}"
        );
    }
    let e = load("v3-short.rrt", &sparse[..sparse.len() - 64]);
    assert!(e.contains("truncated"), "{e}");

    // Checksums intact, contents no view or world frame the scene formats
    // allow: refused by the loader (and `rrt info --check`), not rendered
    // black or refused later without the file's name.
    let meta = u64::from_le_bytes(sparse[32..40].try_into().unwrap()) as usize;
    for (name, at, value, expect) in [
        (
            "width",
            160,
            40000u32.to_le_bytes().to_vec(),
            "view resolution 40000×",
        ),
        (
            "height",
            164,
            0u32.to_le_bytes().to_vec(),
            "expected 1 to 32768 pixels",
        ),
        (
            "hither",
            152,
            f64::NAN.to_le_bytes().to_vec(),
            "view hither NaN",
        ),
        (
            "angle",
            144,
            180f64.to_le_bytes().to_vec(),
            "view angle 180",
        ),
        ("up", 120, [0u8; 24].to_vec(), "view up: zero or parallel"),
        ("voxel", 40, 1e308f64.to_le_bytes().to_vec(), "world frame"),
        ("tiny", 40, 1e-320f64.to_le_bytes().to_vec(), "world frame"),
        ("origin", 16, 1e308f64.to_le_bytes().to_vec(), "world frame"),
    ] {
        let mut bad = sparse.clone();
        bad[meta + at..meta + at + value.len()].copy_from_slice(&value);
        rasterfile::reseal(&mut bad);
        let e = load(&format!("meta-{name}.rrt"), &bad);
        assert!(e.contains(expect), "{name}: {e}");
        let p = dir.join(format!("meta-{name}.rrt"));
        let check = cli(&["info", "--check", p.to_str().unwrap()]).unwrap_err();
        assert!(check.contains(expect), "{name}: {check}");
    }

    let e = load("nff.rrt", &std::fs::read(data("tetra.nff")).unwrap());
    assert!(e.contains("not an rrt raster file"), "{e}");
    let e = load("empty.rrt", b"");
    assert!(e.contains("not an rrt raster file"), "{e}");
    let e = load("magic.rrt", b"RRTRAS");
    assert!(e.contains("truncated"), "{e}");

    let e = cli(&["info", dir.join("missing.rrt").to_str().unwrap()]).unwrap_err();
    assert!(e.contains("missing.rrt: cannot open"), "{e}");
    let folder = dir.join("folder.rrt");
    std::fs::create_dir(&folder).unwrap();
    let e = cli(&["info", folder.to_str().unwrap()]).unwrap_err();
    assert!(e.contains("folder.rrt: cannot read: a directory"), "{e}");
    // A raster through a pipe is read once, in full, and checked.
    let fifo = dir.join("pipe.rrt");
    if std::process::Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .is_ok_and(|s| s.success())
    {
        let (f, bytes) = (fifo.clone(), sparse.clone());
        let writer = std::thread::spawn(move || std::fs::write(f, bytes));
        let out = cli(&["info", "--check", fifo.to_str().unwrap()]).unwrap();
        writer.join().unwrap().unwrap();
        assert!(out.contains("the raster loads"), "{out}");
    } else {
        eprintln!("mkfifo is not available: the pipe is not checked");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// A sphere in a coarse raster: rays just outside its silhouette hit the
/// voxel shell (a false hit, Figure 3's point B) and verification rejects
/// them. `rrt ray --raster` shows one such ray, and a render counts them.
#[test]
fn verification_rejects_known_false_hits() {
    let dir = temp_dir("verify");
    let nff = "v\nfrom 0 0 10\nat 0 0 0\nup 0 1 0\nangle 30\nhither 0\nresolution 64 64\n\
               l 5 5 10\nf 1 0 0 1 0 0 0 1\ns 0 0 0 1\n";
    let scene = Scene::parse("sphere.nff", nff.as_bytes()).unwrap();
    // Raster 20 with 2 voxels of margin: 16 voxels over the diameter, the
    // sphere's centre at voxel coordinate 10, radius 8 voxels.
    let vs = voxelize_exact(&scene, 20);
    assert_eq!(vs.extent().dims(), [20, 20, 20]);
    let rrt = dir.join("sphere.rrt");
    rasterfile::save(&vs, &rrt).unwrap();
    // Along +x at (y, z) = (17.99, 10.95): 8.046 voxels from the sphere's
    // axis, so the continuous ray misses it, through the voxel (9, 17, 10),
    // whose centre segment along y crosses the sphere (from 7.04 to 8.03
    // voxels from its centre): a shell voxel.
    let out = ray_along_x(&rrt, "0,17.99,10.95", &["--connectivity", "six"]);
    let lines: Vec<&str> = out.lines().collect();
    assert!(
        lines
            .iter()
            .any(|l| l.starts_with("hit ") && l.ends_with("object 0 verify rejected: false hit")),
        "{out}"
    );
    assert_eq!(lines.last(), Some(&"miss"), "{out}");
    // Through the middle: the first hit is accepted.
    let out = ray_along_x(&rrt, "0,10.2,10.1", &[]);
    assert!(
        out.lines()
            .last()
            .unwrap()
            .ends_with("object 0 verify accepted"),
        "{out}"
    );

    let paper_opts = TraceOptions {
        mode: Mode::Paper,
        ..TraceOptions::default()
    };
    let (basic, sb) = draw(&vs, 64, 64, paper_opts, 1, 1);
    let verified_opts = TraceOptions {
        mode: Mode::Verified,
        ..TraceOptions::default()
    };
    let (verified, sv) = draw(&vs, 64, 64, verified_opts, 1, 1);
    assert_eq!(sb.false_hits, 0);
    assert!(sv.false_hits > 0, "{sv:?}");
    // Every false hit on a lone sphere is a silhouette ray that misses it:
    // the verified image has that many fewer sphere pixels.
    let lit = |img: &Image| img.rgb.chunks(3).filter(|p| p[0] > 0).count() as u64;
    assert_eq!(sb.hits - sv.hits, lit(&basic) - lit(&verified));
    assert!(sv.hits < sb.hits);
    let _ = std::fs::remove_dir_all(&dir);
}

/// Fidelity floor against `embree_nff` (256², depth 3; the images and the
/// command that made them are in `tests/data/README.md`), with a raster of
/// twice the image's size, in every mode: the paper's (on its raster), the
/// verified and the exact mode (on the exact raster, the default). The
/// floors sit about 1.5 dB under what was measured when they were set
/// (printed by the test).
#[test]
fn psnr_floor_against_embree_nff() {
    let cases: [(&str, PathBuf, [f64; 3]); 3] = [
        // (ground truth, scene, floors: paper, verified, exact)
        ("tetra-256.png", data("tetra.nff"), [27.5, 50.0, 80.0]),
        ("balls1-256.png", data("balls1.nff"), [22.0, 25.5, 96.5]),
        ("balls2-256.png", balls2(), [19.0, 23.5, 82.5]),
    ];
    for (gt, scene, floors) in cases {
        let (w, h, expect) = read_png(&data("embree").join(gt));
        let loaded = Scene::load(&scene).unwrap();
        let raw = voxelize(&loaded, 512, Connectivity::Adaptive);
        let exact = voxelize_exact(&loaded, 512);
        let mut got = [0.0; 3];
        for ((mode, floor), p) in [Mode::Paper, Mode::Verified, Mode::Exact]
            .into_iter()
            .zip(floors)
            .zip(&mut got)
        {
            let vs = if mode == Mode::Paper { &raw } else { &exact };
            let opts = TraceOptions {
                mode,
                ..TraceOptions::default()
            };
            let (img, _) = draw(vs, w, h, opts, 1, 0);
            *p = psnr(&img.rgb, &expect);
            eprintln!("{gt}: raster 512, {mode:?}: PSNR {p:.2} dB (floor {floor})");
            assert!(*p >= floor, "{gt} {mode:?}: PSNR {p:.2} dB < {floor}");
            if mode == Mode::Exact {
                // No acne: pixel by pixel, away from silhouettes (where a
                // pixel-centre ray grazing an edge may go either way),
                // the exact image is the exact tracer's within 2 levels.
                let px = |img: &[u8], x: u32, y: u32| -> [u8; 3] {
                    let i = 3 * (y * w + x) as usize;
                    [img[i], img[i + 1], img[i + 2]]
                };
                let mut off = Vec::new();
                for y in 1..h - 1 {
                    for x in 1..w - 1 {
                        let e = px(&expect, x, y);
                        let edge =
                            [(0i32, 1i32), (0, -1), (1, 0), (-1, 0)]
                                .iter()
                                .any(|&(dx, dy)| {
                                    let n =
                                        px(&expect, (x as i32 + dx) as u32, (y as i32 + dy) as u32);
                                    e.iter().zip(n).any(|(a, b)| a.abs_diff(b) > 24)
                                });
                        let o = px(&img.rgb, x, y);
                        if !edge && e.iter().zip(o).any(|(a, b)| a.abs_diff(b) > 2) {
                            off.push((x, y, e, o));
                        }
                    }
                }
                assert!(
                    off.len() * 1000 <= (w * h) as usize,
                    "{gt}: {} pixels away from edges differ by more than 2 levels: {:?}",
                    off.len(),
                    &off[..off.len().min(8)]
                );
            }
        }
        // The exact mode is the best picture.
        assert!(
            got[2] >= got[1] && got[2] >= got[0],
            "{gt}: exact {:.2} below verified {:.2} or paper {:.2}",
            got[2],
            got[1],
            got[0]
        );
    }
}

/// The exact mode against `embree_nff` where the ground truth has shapes
/// the sphereflakes lack: the teapot's patches with interpolated normals
/// (their self-shadowing included) and the rings' cylinders (64², depth
/// 3; `tests/data/embree/*-64.ppm`; the scenes from `../shared/data`,
/// skipped without it), on a raster far coarser than the image, where
/// voxels hold many objects. The floors sit about 1.5 dB under what was
/// measured when they were set (the cylinders' PSNR is lower because
/// `embree_nff` intersects them in single precision); the teapot's image
/// was Embree's, byte for byte.
#[test]
fn exact_mode_matches_embree_nff_on_patches_and_cylinders() {
    let Some(spd) = rrt_tests::shared_spd() else {
        return;
    };
    for (scene, gt, floor) in [
        ("teapot.nff", "teapot-64.ppm", 90.0),
        ("rings.nff", "rings-64.ppm", 49.5),
    ] {
        let (w, h, expect) = rrt_tests::read_ppm(&data("embree").join(gt));
        let vs = voxelize_exact(&Scene::load(spd.join(scene)).unwrap(), 96);
        let (img, _) = draw(&vs, w, h, TraceOptions::default(), 1, 0);
        let p = psnr(&img.rgb, &expect);
        eprintln!("{scene}: raster 96, exact: PSNR {p:.2} dB (floor {floor})");
        assert!(p >= floor, "{scene}: PSNR {p:.2} dB < {floor}");
    }
}

/// A scene spanning 60 orders of magnitude, to the edge of the world
/// limit: a sphere beside its light and a second sphere 10⁶⁰ away. The surface offset of rays leaving a
/// hit scales with the scene's size but never exceeds a tenth of the
/// object hit, so the near sphere is lit exactly as without the far one
/// at a sane distance (the raster only accelerates in the exact mode).
#[test]
fn a_far_object_does_not_change_the_lighting_of_a_near_one() {
    let scene = |far: &str| {
        let src = format!(
            "v\nfrom 0 -5 0\nat 0 0 0\nup 0 0 1\nangle 40\nhither 1\nresolution 48 48\n\
             l 3 -4 8\nf 1 0.5 0.3 0.8 0 0 0 1\ns 0 0 0 1\ns {far} 0 0 1\n"
        );
        Scene::parse("far.nff", src.as_bytes()).unwrap()
    };
    let image = |far: &str| {
        let vs = voxelize_exact(&scene(far), 64);
        draw(&vs, 48, 48, TraceOptions::default(), 1, 1)
    };
    let (near, near_stats) = image("1e3");
    let (far, far_stats) = image("1e60");
    assert!(near_stats.hits > 100, "{near_stats:?}");
    assert_eq!(near_stats.hits, far_stats.hits);
    assert!(
        psnr(&near.rgb, &far.rgb) > 50.0,
        "{} dB",
        psnr(&near.rgb, &far.rgb)
    );
    // Lit: the brightest pixel is well above the ambient-only colour.
    let brightest = far.rgb.chunks(3).map(|p| p[0]).max().unwrap_or(0);
    assert!(brightest > 150, "{brightest}");
}

/// Up to the world limit the image does not depend on the scene's scale:
/// the same scene (the eye inside a sphere enclosing a ball, a cone and a
/// triangle, and a light, all within 20 units) in units scaled by 10³⁰ and
/// 10⁵⁸ (so reaching 2·10⁵⁹, near the limit) renders as at
/// scale 1; no square or product overflows on the way.
#[test]
fn the_image_does_not_depend_on_the_scale_up_to_the_world_limit() {
    let scene = |k: f64| {
        let f = |v: f64| format!("{:e}", v * k);
        let src = format!(
            "v\nfrom 0 {} {}\nat 0 0 0\nup 0 0 1\nangle 50\nhither 0\nresolution 32 32\n\
             l {} {} {}\nf 1 0.5 0.3 0.8 0.2 10 0 1\ns 0 0 0 {}\ns 0 0 0 1e0\n\
             c\n{} 0 {} {}\n{} 0 {} {}\np 3\n{} {} {}\n{} {} {}\n{} {} {}\n",
            f(-5.0),
            f(1.0),
            f(3.0),
            f(-4.0),
            f(4.0),
            f(20.0),
            f(2.0),
            f(-1.0),
            f(0.5),
            f(2.0),
            f(1.0),
            f(0.2),
            f(-3.0),
            f(1.0),
            f(-2.0),
            f(-1.0),
            f(1.0),
            f(-2.0),
            f(-2.0),
            f(1.0),
            f(2.0),
        );
        let mut s = Scene::parse("scale.nff", src.as_bytes()).unwrap();
        s.spheres[1].shape.radius = k;
        s
    };
    let image = |k: f64| {
        let vs = voxelize_exact(&scene(k), 64);
        draw(&vs, 32, 32, TraceOptions::default(), 1, 0)
    };
    let (one, one_stats) = image(1.0);
    assert!(one_stats.hits >= 32 * 32, "{one_stats:?}");
    for k in [1e30, 1e58] {
        let (img, stats) = image(k);
        assert_eq!(stats.hits, one_stats.hits, "scale {k:e}");
        let worst = one
            .rgb
            .iter()
            .zip(&img.rgb)
            .map(|(a, b)| a.abs_diff(*b))
            .max()
            .unwrap_or(0);
        assert!(worst <= 1, "scale {k:e}: a channel differs by {worst}");
    }
}

/// The surface offset is a function of the geometry, not of the raster:
/// a floor seen from just above it, shaded by a triangle between it and
/// a high light (a far sphere stretching the scene; found by comparing
/// random scenes with `embree_nff`), renders the same at every raster.
#[test]
fn the_exact_image_does_not_depend_on_the_raster() {
    let src = "b 0.0415 0.549 0.11\nv\nfrom -0.869620009 0.0154632577 2.22250965\n\
               at 1.72284136 -1.22532696 2.21596876\nup 0 0 1\nangle 60\nhither 0.001\n\
               resolution 64 64\nl -708.517148 -166.856652 8796.5013\n\
               f 0.2339 0.8514 0.7634 0.492 0.6863 30 0 1\np 3\n\
               0.0995441969 0.408773773 3.09741412\n-1.23000645 -0.99763821 3.37274623\n\
               -1.13923163 0.388852666 4.66083503\nf 0.1695 0.9887 0.9302 0.8824 0 3 0 1\n\
               p 4\n7307.92944 7307.92944 2.21596876\n-7307.92944 7307.92944 2.21596876\n\
               -7307.92944 -7307.92944 2.21596876\n7307.92944 -7307.92944 2.21596876\n\
               f 0.4225 0.1009 0.4723 0.4252 0 1 0 1\n\
               s -558.467808 -156380.646 -19475.2945 2.03843015\n";
    let scene = Scene::parse("raster.nff", src.as_bytes()).unwrap();
    assert_same_image_at_rasters(&scene, 64, &[64, 100, 400]);
}

/// Asserts that `scene`'s exact image, `size` pixels square, is the same
/// at every raster of `rasters` as at the first.
#[track_caller]
fn assert_same_image_at_rasters(scene: &Scene, size: u32, rasters: &[u32]) {
    let image = |n: u32| {
        let vs = voxelize_exact(scene, n);
        draw(&vs, size, size, TraceOptions::default(), 1, 1).0.rgb
    };
    let first = image(rasters[0]);
    for &n in &rasters[1..] {
        let differ = image(n).iter().zip(&first).filter(|(a, b)| a != b).count();
        assert_eq!(
            differ, 0,
            "raster {n} against {}: {differ} channels differ",
            rasters[0]
        );
    }
}

/// The colour of an untextured object is its material's, not the 8-bit
/// colour its voxels store: whichever voxel a hit is found from (one the
/// object owns, one it shares, or one of a sphere smaller than a voxel,
/// which owns none), at every raster. Colours 0.9 and 0.7 lie on ties of
/// the 8-bit rounding, where two roundings of one colour differed.
#[test]
fn the_exact_colour_does_not_depend_on_the_voxels() {
    let src = "v\nfrom 0 -6 1.5\nat 0 0 0.3\nup 0 0 1\nangle 40\nhither 0.01\n\
               resolution 48 48\nb 0.1 0.2 0.3\nl 4 -4 6\nl -3 -5 4\n\
               f 1 0.9 0.7 0.5 0.4 20 0 1\ns 0 0 0.5 0.5\n\
               f 0.3 0.7 0.9 0.8 0 1 0 1\ns 0.9 -0.3 0.1 0.1\ns 0.62 -0.42 0.05 0.05\n\
               s -0.7 -0.2 0.08 0.08\ns -0.61 -0.29 0.03 0.03\n\
               f 0.9 0.9 0.7 0.6 0.2 5 0 1\np 4\n-3 -3 0\n3 -3 0\n3 3 0\n-3 3 0\n";
    let scene = Scene::parse("colour.nff", src.as_bytes()).unwrap();
    assert_same_image_at_rasters(&scene, 48, &[12, 40, 200]);
}

/// A cone flatter than a fixed-point unit (an annulus: radii 1 and 0.5,
/// height down to 1e-100) keeps the voxels its surface passes through and
/// is intersected as the annulus it nearly is: it renders as the cone of
/// height 1e-6, which the quadratic still resolves, pixel for pixel.
#[test]
fn a_cone_flatter_than_fixed_point_renders_as_its_annulus() {
    let image = |h: &str| {
        let src = format!(
            "v\nfrom 0 -6 2\nat 0 0 0\nup 0 0 1\nangle 40\nhither 1\nresolution 48 48\n\
             l 3 -4 8\nf 0.8 0.5 0.3 1 0 0 0 0\nc\n0 0 0 1\n0 0 {h} 0.5\n"
        );
        let scene = Scene::parse("flat.nff", src.as_bytes()).unwrap();
        let (img, stats) = draw(
            &voxelize_exact(&scene, 64),
            48,
            48,
            TraceOptions::default(),
            1,
            1,
        );
        assert!(stats.hits > 60, "height {h}: {stats:?}");
        img.rgb
    };
    let resolved = image("1e-6");
    for h in ["1e-9", "1e-20", "1e-100"] {
        let differ = image(h)
            .iter()
            .zip(&resolved)
            .filter(|(a, b)| a != b)
            .count();
        assert_eq!(differ, 0, "height {h}: {differ} channels differ");
    }
}

/// An eye a hair above a floor that lies on a voxel face: rounded to fixed
/// point, the discrete rays start across the face, below the floor, but
/// the floor is still the hit of every ray (found by comparing random
/// scenes with `embree_nff`).
#[test]
fn an_eye_just_above_a_floor_sees_it() {
    let src = "b 0.5 0.2 0.5\nv\nfrom 0.3 0.2 -0.9999\nat 0.3 0.2 -2\nup 0 1 0\nangle 40\n\
               hither 0\nresolution 32 32\nl 0.3 0.2 1\nf 0.7 0.8 0.1 0.7 0 10 0 1\n\
               p 4\n4300 4300 -1\n-4300 4300 -1\n-4300 -4300 -1\n4300 -4300 -1\n";
    let scene = Scene::parse("floor.nff", src.as_bytes()).unwrap();
    for raster in [96, 64, 300] {
        let vs = voxelize_exact(&scene, raster);
        let (_, stats) = draw(&vs, 32, 32, TraceOptions::default(), 1, 1);
        assert_eq!(stats.hits, 32 * 32, "raster {raster}: {stats:?}");
    }
}

/// A cone far smaller than a fixed-point unit of a coarse raster (a far
/// sphere stretches the scene): its base and apex round to one point,
/// yet it keeps the voxels it lies in and renders the same at every
/// raster (found by comparing random scenes with `embree_nff`).
#[test]
fn an_object_smaller_than_fixed_point_keeps_its_voxels() {
    let src = "b 0.1 0.1 0.5\nv\nfrom 0 -0.5 0.05\nat 0 0 0.05\nup 0 0 1\nangle 30\nhither 0\n\
               resolution 32 32\nl 1 -2 3\nf 0.9 0.5 0.2 0.9 0 10 0 1\n\
               c\n0 0 0 0.05\n0 0 0.1 0.02\ns 0 0 -4000000 1\n";
    let scene = Scene::parse("cone.nff", src.as_bytes()).unwrap();
    let images: Vec<(Vec<u8>, u64)> = [8, 64, 1024]
        .into_iter()
        .map(|n| {
            let vs = voxelize_exact(&scene, n);
            let (img, stats) = draw(&vs, 32, 32, TraceOptions::default(), 1, 1);
            (img.rgb, stats.hits)
        })
        .collect();
    assert!(images[0].1 > 50, "{}", images[0].1);
    for (n, (img, hits)) in [64, 1024].iter().zip(&images[1..]) {
        assert_eq!(*hits, images[0].1, "raster {n}");
        assert_eq!(img, &images[0].0, "raster {n}");
    }
}

/// A light as far as the sun (here 1e12 scene sizes away) is taken by its
/// direction instead of being refused for fixed point: the exact image is
/// the one lit from a light 1e5 away in the same direction (whose
/// direction differs by 1e-4 radians at most: no channel by more than one
/// level), at a coarse and a fine raster; the paper's mode renders it too,
/// from the light bits.
#[test]
fn a_light_as_far_as_the_sun_lights_the_scene() {
    let scene = |d: &str| {
        let src = format!(
            "v\nfrom 0 -6 3\nat 0 0 0\nup 0 0 1\nangle 40\nhither 0.01\nresolution 48 48\n\
             b 0.1 0.2 0.6\nl {d} -{d} {d}\nf 1 0.5 0.3 1 0 0 0 1\ns 0 0 0 1\n\
             f 0.8 0.8 0.8 1 0 0 0 1\np 4\n-4 -4 -1\n4 -4 -1\n4 4 -1\n-4 4 -1\n"
        );
        Scene::parse("sun.nff", src.as_bytes()).unwrap()
    };
    let image = |d: &str, raster: u32| {
        let vs = voxelize_exact(&scene(d), raster);
        draw(&vs, 48, 48, TraceOptions::default(), 1, 1).0.rgb
    };
    for raster in [64, 1024] {
        let near = image("1e5", raster);
        let sun = image("1e12", raster);
        let most = near
            .iter()
            .zip(&sun)
            .map(|(a, b)| a.abs_diff(*b))
            .max()
            .unwrap_or(0);
        assert!(most <= 1, "raster {raster}: a channel differs by {most}");
        let lit = sun.chunks(3).filter(|p| p[0] > 100).count();
        assert!(lit > 300, "raster {raster}: {lit} lit pixels");
    }
    let paper = voxelize(&scene("1e12"), 64, Connectivity::Adaptive);
    let opts = TraceOptions {
        mode: Mode::Paper,
        ..TraceOptions::default()
    };
    let (img, stats) = draw(&paper, 48, 48, opts, 1, 1);
    assert!(stats.hits > 1000, "{stats:?}");
    let lit = img.rgb.chunks(3).filter(|p| p[0] > 100).count();
    assert!(lit > 300, "paper mode: {lit} lit pixels");
}

/// A ground made huge to look infinite (here 2·10⁶ wide under a sphere of
/// radius 1) does not push the rays leaving it off the sphere's shadow:
/// seen from above, where the ground fills the view, the image is the one
/// with a ground 20 wide, shadow included, but for pixels on the shadow's
/// edge (the offset of leaving rays is at most a tenth of the smallest
/// object's size, not 10⁻⁵ of the scene's, which here is larger than the
/// sphere).
#[test]
fn a_huge_ground_keeps_the_shadows_on_it() {
    let image = |half: &str| {
        let src = format!(
            "v\nfrom 0 -3 9\nat 0 0 0\nup 0 0 1\nangle 40\nhither 0.01\nresolution 64 64\n\
             b 0.1 0.2 0.6\nl 3 -2 12\nf 1 0.5 0.3 0.8 0 0 0 1\ns 0 0 1.5 1\n\
             f 0.8 0.8 0.8 1 0 0 0 1\np 4\n-{half} -{half} 0\n{half} -{half} 0\n\
             {half} {half} 0\n-{half} {half} 0\n"
        );
        let scene = Scene::parse("ground.nff", src.as_bytes()).unwrap();
        let vs = voxelize_exact(&scene, 64);
        draw(&vs, 64, 64, TraceOptions::default(), 1, 1).0.rgb
    };
    // Ground pixels in the sphere's shadow (grey, lit by the ambient
    // light only: the darkest grey) and lit (grey, brighter).
    let shadow = |img: &[u8]| {
        let grey = || img.chunks(3).filter(|p| p[0] == p[1] && p[1] == p[2]);
        let ambient = grey().map(|p| p[0]).min().unwrap_or(0);
        (
            grey().filter(|p| p[0] == ambient).count(),
            grey().filter(|p| p[0] > ambient.saturating_add(20)).count(),
        )
    };
    let small = image("10");
    let huge = image("1e6");
    let (dark, lit) = shadow(&small);
    assert!(dark > 40 && lit > 2000, "{dark} in shadow, {lit} lit");
    let (huge_dark, _) = shadow(&huge);
    assert!(
        huge_dark.abs_diff(dark) * 10 <= dark,
        "{huge_dark} pixels in shadow, {dark} with the small ground"
    );
    let differ = small
        .chunks(3)
        .zip(huge.chunks(3))
        .filter(|(a, b)| a.iter().zip(*b).any(|(x, y)| x.abs_diff(*y) > 8))
        .count();
    assert!(differ * 100 <= 64 * 64, "{differ} pixels differ");
}

/// A non-convex polygon is the region its outline bounds: seen face-on in
/// the exact mode, every pixel whose primary ray meets the polygon's plane
/// clearly inside the comb (more than 0.03 from its outline) shows it, and
/// every one clearly outside (the notches between its teeth among them)
/// the background. A fan from the first vertex covers the notches.
#[test]
fn non_convex_polygons_cover_their_outline_only() {
    let outline = rrt_tests::COMB;
    let mut src = String::from(
        "v\nfrom 2 1.5 12\nat 2 1.5 0\nup 0 1 0\nangle 25\nhither 0\nresolution 96 80\n\
         b 0 0 0\nl 2 1.5 20\nf 1 1 1 1 0 1 0 0\n",
    );
    src += &format!("p {}\n", outline.len());
    for (x, y) in outline {
        src += &format!("{x} {y} 0\n");
    }
    let scene = Scene::parse("comb.nff", src.as_bytes()).unwrap();
    let vs = voxelize_exact(&scene, 128);
    let (w, h) = (96, 80);
    let (img, _) = draw(&vs, w, h, TraceOptions::default(), 1, 1);
    let cam = Camera::new(&scene.view, w, h).unwrap();
    let inside = |p: DVec3| {
        let mut inside = false;
        for (a, b) in outline.iter().zip(outline.iter().cycle().skip(1)) {
            if (a.1 > p.y) != (b.1 > p.y) && p.x < a.0 + (p.y - a.1) * (b.0 - a.0) / (b.1 - a.1) {
                inside = !inside;
            }
        }
        inside
    };
    let near_edge = |p: DVec3| {
        outline
            .iter()
            .zip(outline.iter().cycle().skip(1))
            .any(|(a, b)| {
                let (a, b) = (DVec3::new(a.0, a.1, 0.0), DVec3::new(b.0, b.1, 0.0));
                let t = ((p - a).dot(b - a) / (b - a).length_squared()).clamp(0.0, 1.0);
                (a + (b - a) * t).distance(p) < 0.03
            })
    };
    let (mut lit, mut dark) = (0, 0);
    for y in 0..h {
        for x in 0..w {
            let ray = cam.primary(x, y);
            let p = ray.origin - ray.dir * (ray.origin.z / ray.dir.z);
            if near_edge(p) {
                continue;
            }
            let k = 3 * (y * w + x) as usize;
            let shown = img.rgb[k..k + 3].iter().any(|&c| c > 0);
            assert_eq!(shown, inside(p), "pixel ({x}, {y}) at {p}");
            if shown {
                lit += 1;
            } else if p.x > 0.0 && p.x < 4.0 && p.y > 1.0 && p.y < 3.0 {
                dark += 1;
            }
        }
    }
    assert!(lit > 1000, "{lit} pixels show the comb");
    assert!(
        dark > 300,
        "{dark} pixels of the notches show the background"
    );
}
