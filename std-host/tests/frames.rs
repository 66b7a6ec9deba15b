//! Frames and bands as independent jobs, through the binary: bands
//! (`--tile I/N`) stitched are the whole image byte for byte, frames of an
//! animation rendered by separate processes (`--frame K`) are one
//! process's frames byte for byte, frame 0 is the plain render, and bad
//! camera paths, bands, frames and stitches are refused with one clear
//! error.

use std::path::{Path, PathBuf};
use std::process::Command;

/// A sphere on a floor: small and quick.
const SCENE: &str = "\
l 3 -3 4
f 1 0.5 0.2 0.8 0.2 10 0 1
s 0 0 0.6 0.6
f 0.4 0.6 0.9 0.9 0 1 0 1
p 4
-2 -2 0
2 -2 0
2 2 0
-2 2 0
v
from 0.5 -4 1.5
at 0 0 0.4
up 0 0 1
angle 40
hither 0.1
resolution 24 18
";

/// A fresh folder holding the scene (`s.nff`) and its saved raster
/// (`s.rrt`).
fn folder(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("rrt-frames-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    std::fs::write(d.join("s.nff"), SCENE).unwrap();
    ok(
        &d,
        &["voxelize", "-q", "s.nff", "--raster", "40", "-o", "s.rrt"],
    );
    d
}

fn rrt(dir: &Path, args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_rrt"))
        .current_dir(dir)
        .args(args)
        .output()
        .unwrap()
}

/// Runs `rrt args…` in `dir`, which must succeed.
#[track_caller]
fn ok(dir: &Path, args: &[&str]) {
    let out = rrt(dir, args);
    assert!(
        out.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// Runs `rrt args…` in `dir`, which must fail with one line on stderr
/// holding `want`, and no panic.
#[track_caller]
fn fails(dir: &Path, args: &[&str], want: &str) {
    let out = rrt(dir, args);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "{args:?} succeeded");
    assert!(err.contains(want), "{args:?}: {err:?} lacks {want:?}");
    assert!(!err.contains("panicked"), "{args:?}: {err}");
}

fn read(dir: &Path, name: &str) -> Vec<u8> {
    std::fs::read(dir.join(name)).unwrap_or_else(|e| panic!("{name}: {e}"))
}

#[track_caller]
fn same(dir: &Path, a: &str, b: &str) {
    assert!(read(dir, a) == read(dir, b), "{a} and {b} differ");
}

/// Renders `input` whole to `whole` and in `n` bands `band-I.EXT`, and
/// returns the bands' names.
fn bands(dir: &Path, input: &str, ext: &str, n: u32, extra: &[&str]) -> Vec<String> {
    (0..n)
        .map(|i| {
            let name = format!("band-{i}.{ext}");
            let tile = format!("{i}/{n}");
            ok(
                dir,
                &[
                    &["render", "-q", input, "-o", &name, "--tile", &tile][..],
                    extra,
                ]
                .concat(),
            );
            name
        })
        .collect()
}

fn stitch(dir: &Path, out: &str, bands: &[String]) -> std::process::Output {
    let mut args = vec!["stitch", "-q", "-o", out];
    args.extend(bands.iter().map(String::as_str));
    rrt(dir, &args)
}

#[test]
fn bands_stitch_into_the_whole_image_byte_for_byte() {
    let d = folder("bands");
    for (ext, extra, n) in [
        ("png", &["--supersample", "2"][..], 3),
        ("png", &["--bits", "16"][..], 18),
        ("ppm", &["--linear", "--supersample", "3"][..], 4),
        ("exr", &["--supersample", "2"][..], 5),
    ] {
        let whole = format!("whole.{ext}");
        ok(
            &d,
            &[&["render", "-q", "s.rrt", "-o", &whole][..], extra].concat(),
        );
        let names = bands(&d, "s.rrt", ext, n, extra);
        let joined = format!("joined.{ext}");
        let out = stitch(&d, &joined, &names);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        same(&d, &whole, &joined);
        if ext == "exr" {
            // The same floats make the PFM file of one render.
            ok(
                &d,
                &[&["render", "-q", "s.rrt", "-o", "whole.pfm"][..], extra].concat(),
            );
            assert!(stitch(&d, "joined.pfm", &names).status.success());
            same(&d, "whole.pfm", "joined.pfm");
        }
    }
    // A PFM band holds the same rows (stored bottom to top) as the whole
    // PFM image.
    ok(&d, &["render", "-q", "s.rrt", "-o", "whole.pfm"]);
    ok(
        &d,
        &["render", "-q", "s.rrt", "-o", "b.pfm", "--tile", "1/3"],
    );
    let (whole, band) = (read(&d, "whole.pfm"), read(&d, "b.pfm"));
    let row = 24 * 12;
    let whole_rows = &whole[whole.len() - 18 * row..];
    let band_rows = &band[band.len() - 6 * row..];
    // Rows 6..12 of 18, counted from the bottom: rows 6..12 as well.
    assert_eq!(band_rows, &whole_rows[6 * row..12 * row]);
    // A scene file in bands: each process voxelizes it alike.
    ok(&d, &["render", "-q", "s.nff", "-o", "scene.png"]);
    let names = bands(&d, "s.nff", "png", 2, &[]);
    assert!(stitch(&d, "scene-joined.png", &names).status.success());
    same(&d, "scene.png", "scene-joined.png");
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn orbit_frames_apart_are_one_processs_frames() {
    let d = folder("orbit");
    // A saved raster, and a scene file in the paper's mode without
    // --raster, whose default raster depends on the view: the animation's
    // raster is fitted to the base view in every process.
    for (input, extra) in [("s.rrt", &[][..]), ("s.nff", &["--mode", "paper"][..])] {
        let stem = input.replace('.', "-");
        let pattern = format!("{stem}-%02d.png");
        ok(
            &d,
            &[
                &["render", "-q", input, "--orbit", "5", "-o", &pattern][..],
                extra,
            ]
            .concat(),
        );
        for k in 0..5 {
            let single = format!("{stem}-single-{k}.png");
            let frame = k.to_string();
            ok(
                &d,
                &[
                    &[
                        "render", "-q", input, "--orbit", "5", "--frame", &frame, "-o", &single,
                    ][..],
                    extra,
                ]
                .concat(),
            );
            same(&d, &single, &format!("{stem}-0{k}.png"));
        }
        assert!(read(&d, &format!("{stem}-01.png")) != read(&d, &format!("{stem}-00.png")));
        // Frame 0 is the plain render.
        let plain = format!("{stem}-plain.png");
        ok(
            &d,
            &[&["render", "-q", input, "-o", &plain][..], extra].concat(),
        );
        same(&d, &plain, &format!("{stem}-00.png"));
        // Bands of a frame stitch into that frame.
        let names: Vec<String> = (0..3)
            .map(|i| {
                let name = format!("{stem}-3-band{i}.png");
                let tile = format!("{i}/3");
                ok(
                    &d,
                    &[
                        &["render", "-q", input, "--orbit", "5", "--frame", "3"][..],
                        &["--tile", &tile, "-o", &name],
                        extra,
                    ]
                    .concat(),
                );
                name
            })
            .collect();
        let joined = format!("{stem}-3-joined.png");
        assert!(stitch(&d, &joined, &names).status.success());
        same(&d, &joined, &format!("{stem}-03.png"));
    }
    // A frame of the saved raster is the plain render of its view.
    let path =
        "0.5 -4 1.5  0 0 0.4  0 0 1  40\n# the second view\n\n3 1 2  0 0 0.3  0 0 1 35 # closer\n";
    std::fs::write(d.join("p.txt"), path).unwrap();
    ok(
        &d,
        &["render", "-q", "s.rrt", "--path", "p.txt", "-o", "p-%d.png"],
    );
    ok(
        &d,
        &[
            "render", "-q", "s.rrt", "--path", "p.txt", "--frame", "1", "-o", "p1.png",
        ],
    );
    same(&d, "p1.png", "p-1.png");
    ok(
        &d,
        &[
            "render",
            "-q",
            "s.rrt",
            "-o",
            "view1.png",
            "--from",
            "3,1,2",
            "--at",
            "0,0,0.3",
            "--up",
            "0,0,1",
            "--angle",
            "35",
        ],
    );
    same(&d, "view1.png", "p-1.png");
    ok(&d, &["render", "-q", "s.rrt", "-o", "view0.png"]);
    same(&d, "view0.png", "p-0.png");
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn bad_camera_paths_are_refused_with_their_location() {
    let d = folder("paths");
    for (text, want) in [
        (
            "0 -4 1 0 0 0 0 0 1 45\n0 -4 1 0 0 0 0 0 1\n",
            "p.txt:2:19: path view angle: expected a number, found end of line",
        ),
        (
            "# c\n0 -4 1 0 zero 0 0 0 1 45\n",
            "p.txt:2:10: path view at y: expected a number, found \"zero\"",
        ),
        (
            "1 1 1 1 1 1 0 0 1 45\n",
            "p.txt:1:7: path view at: equals `from`",
        ),
        (
            "0 -4 0 0 0 0 0 3 0 45\n",
            "p.txt:1:14: path view up: zero or parallel to the view direction",
        ),
        (
            "0 -4 1 0 0 0 0 0 1 0\n",
            "p.txt:1:20: path view angle: expected an angle in degrees between 0 and 180",
        ),
        ("\n# only comments\n", "p.txt: no views"),
    ] {
        std::fs::write(d.join("p.txt"), text).unwrap();
        fails(
            &d,
            &["render", "-q", "s.rrt", "--path", "p.txt", "-o", "f-%d.png"],
            want,
        );
        assert!(!d.join("f-0.png").exists());
    }
    fails(
        &d,
        &[
            "render",
            "-q",
            "s.rrt",
            "--path",
            "missing.txt",
            "-o",
            "f-%d.png",
        ],
        "cannot read missing.txt",
    );
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn bad_frames_bands_and_patterns_are_refused() {
    let d = folder("bad");
    let render = ["render", "-q", "s.rrt"];
    for (extra, want) in [
        (
            &["--tile", "0/0", "-o", "a.png"][..],
            "expected at least 1 band, found 0",
        ),
        (
            &["--tile", "3/3", "-o", "a.png"],
            "band 3 of 3 does not exist: bands are numbered 0 (the top one) to 2",
        ),
        (
            &["--tile", "0/19", "-o", "a.png"],
            "19 bands of an image 18 rows high",
        ),
        (
            &["--tile", "0/4294967295", "-o", "a.png"],
            "4294967295 bands of an image 18 rows high",
        ),
        (&["--tile", "1/x", "-o", "a.png"], "expected I/N"),
        (
            &["--orbit", "0", "-o", "a%d.png"],
            "expected at least 1 frame, found 0",
        ),
        (
            &["--orbit", "4", "--frame", "4", "-o", "a%d.png"],
            "frame 4 of 4 does not exist: frames are numbered 0 to 3",
        ),
        (
            &["--frame", "0", "-o", "a.png"],
            "give --orbit N or --path FILE",
        ),
        (
            &["--orbit", "3", "-o", "a.png"],
            "has no frame number, but 3 frames are written",
        ),
        (&["--orbit", "3", "-o", "a%d-%d.png"], "has 2 frame numbers"),
        (
            &["--orbit", "3", "-o", "a%q.png"],
            "the % at character 2 starts neither %d, %0Nd",
        ),
        (
            &["--orbit", "3", "-o", "-"],
            "cannot all go to standard output",
        ),
        (
            &["--orbit", "3", "--path", "p.txt", "-o", "a%d.png"],
            "cannot be used with",
        ),
    ] {
        fails(&d, &[&render[..], extra].concat(), want);
    }
    // A huge animation costs nothing before its one frame is rendered.
    ok(
        &d,
        &[
            &render[..],
            &[
                "--orbit",
                "18446744073709551615",
                "--frame",
                "18446744073709551614",
                "-o",
                "h%d.png",
            ],
        ]
        .concat(),
    );
    assert!(d.join("h18446744073709551614.png").is_file());
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn stitch_refuses_what_is_not_one_image_in_order() {
    let d = folder("stitch");
    let three = bands(&d, "s.rrt", "png", 3, &[]);
    let [b0, b1, b2] = [&three[0], &three[1], &three[2]].map(String::as_str);
    // Other images' bands, renamed so as not to clash.
    let other = |extra: &[&str], tile: &str, name: &str| {
        let args = [
            &["render", "-q", "s.rrt", "--tile", tile, "-o", name][..],
            extra,
        ]
        .concat();
        ok(&d, &args);
        name.to_string()
    };
    let wide = other(&["--width", "30"], "1/3", "wide.png");
    let deep = other(&["--bits", "16"], "1/3", "deep.png");
    let ppm = other(&[], "1/3", "b1.ppm");
    let half = other(&[], "1/2", "half.png");
    let turned = other(&["--from", "1,-4,1.5"], "1/3", "turned.png");
    let pfm = other(&[], "1/3", "b1.pfm");
    let exr = other(&[], "1/3", "b1.exr");
    // The same view, sampling, mode and raster dimensions, but another
    // scene: the sphere's colour, or the light, differs.
    let recoloured = SCENE.replace("f 1 0.5 0.2", "f 1 0.5 0.3");
    let relit = SCENE.replace("l 3 -3 4", "l 3 -3 4.5");
    for (name, scene) in [("recoloured", &recoloured), ("relit", &relit)] {
        std::fs::write(d.join(format!("{name}.nff")), scene).unwrap();
        let (nff, rrt) = (format!("{name}.nff"), format!("{name}.rrt"));
        ok(&d, &["voxelize", "-q", &nff, "--raster", "40", "-o", &rrt]);
        let band = format!("{name}.png");
        ok(&d, &["render", "-q", &rrt, "--tile", "1/3", "-o", &band]);
    }
    // A band of the scene file and bands of its saved raster are bands of
    // one image.
    ok(
        &d,
        &[
            "render",
            "-q",
            "s.nff",
            "--raster",
            "40",
            "--tile",
            "1/3",
            "-o",
            "from-scene.png",
        ],
    );
    ok(&d, &["render", "-q", "s.rrt", "-o", "whole.png"]);
    std::fs::write(d.join("junk.png"), b"not a png").unwrap();
    for (files, want) in [
        (
            vec![b0, &wide, b2],
            "wide.png: image size 30x18, but band-0.png has 24x18",
        ),
        (
            vec![b0, &deep, b2],
            "deep.png: samples 16-bit sRGB, but band-0.png has 8-bit sRGB",
        ),
        (
            vec![b0, &ppm, b2],
            "b1.ppm: format PPM, but band-0.png has PNG",
        ),
        (
            vec![b0, &exr, b2],
            "b1.exr: format OpenEXR, but band-0.png has PNG",
        ),
        (
            vec![b0, &half, b2],
            "half.png: a split into 2 bands, but band-0.png has 3 (bands of different splits overlap)",
        ),
        (
            vec![b0, &turned, b2],
            "turned.png: render \"view from 1,-4,1.5 at 0,0,0.4 up 0,0,1 angle 40\", but band-0.png has \"view from 0.5,-4,1.5 at 0,0,0.4 up 0,0,1 angle 40\": not bands of one image",
        ),
        (
            vec![b0, "recoloured.png", b2],
            "recoloured.png: render \"scene ",
        ),
        (vec![b0, "relit.png", b2], "relit.png: render \"scene "),
        (
            vec![b0, b2, b1],
            "band-2.png: band 2 of 3 given before band 1 (band-1.png): list the bands in order",
        ),
        (vec![b0, b1, b1, b2], "band-1.png: band 1 of 3 again"),
        (
            vec![b0, b2],
            "band-2.png: band 2 of 3, but band 1 is missing",
        ),
        (
            vec![b0, b1],
            "band-1.png: the last band given is 1 of 3: bands 2 to 2 are missing",
        ),
        (
            vec![b1, b2],
            "band-1.png: band 1 of 3, but band 0 is missing",
        ),
        (
            vec!["whole.png"],
            "whole.png: not a band: the file does not say which band",
        ),
        (
            vec![&pfm],
            "b1.pfm: a PFM file has no place to say which band it is",
        ),
        (vec!["junk.png"], "junk.png: not a readable PNG file"),
        (
            vec!["s.nff"],
            "s.nff: not a band file: bands are .png, .ppm or .exr",
        ),
        (vec!["nothing.png"], "cannot read nothing.png"),
    ] {
        let mut args = vec!["stitch", "-o", "out.png"];
        args.extend(files);
        fails(&d, &args, want);
        assert!(!d.join("out.png").exists());
    }
    fails(
        &d,
        &["stitch", "-o", "out.exr", b0, b1, b2],
        "out.exr: cannot hold the bands' samples (8-bit sRGB in band-0.png); stitch them into .png or .ppm",
    );
    fails(&d, &["stitch", "-o", "out.png"], "required");
    // The output one of the bands: refused, the band kept.
    let band1 = read(&d, b1);
    fails(
        &d,
        &["stitch", "-o", &format!("./{b1}"), b0, b1, b2],
        &format!("./{b1}: is the band {b1} too: the whole image would replace it"),
    );
    assert!(read(&d, b1) == band1);
    // The three in order make the whole image.
    ok(&d, &["stitch", "-o", "out.png", b0, b1, b2]);
    same(&d, "out.png", "whole.png");
    ok(&d, &["stitch", "-o", "mixed.png", b0, "from-scene.png", b2]);
    same(&d, "mixed.png", "whole.png");
    let _ = std::fs::remove_dir_all(&d);
}

/// A band description for a `width`×`height` image of one band of
/// `kind`.
fn whole_band_tag(width: u32, height: u32, kind: &str) -> String {
    format!("band 0/1 rows 0..{height} of {width}x{height}, {kind}; view x")
}

#[test]
fn stitch_refuses_an_image_too_large_before_reading_pixels() {
    let d = std::env::temp_dir().join(format!("rrt-frames-{}-huge", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    // A PNG saying it is the one band of a 32768×32768 16-bit image, with
    // no pixels: stitching it would allocate gigabytes before finding out.
    let side = 32_768;
    {
        let file = std::fs::File::create(d.join("huge.png")).unwrap();
        let mut e = png::Encoder::new(std::io::BufWriter::new(file), side, side);
        e.set_color(png::ColorType::Rgb);
        e.set_depth(png::BitDepth::Sixteen);
        e.add_text_chunk(
            "rrt-band".to_string(),
            whole_band_tag(side, side, "16-bit linear"),
        )
        .unwrap();
        let mut w = e.write_header().unwrap();
        // An empty zlib stream: the decoder reads the header, the
        // pixels are missing.
        w.write_chunk(png::chunk::IDAT, &[0x78, 0x9c, 3, 0, 0, 0, 0, 1])
            .unwrap();
        drop(w);
    }
    // A PPM saying the same, with 100 bytes of samples.
    let mut ppm = format!(
        "P6\n# rrt {}\n{side} {side}\n65535\n",
        whole_band_tag(side, side, "16-bit sRGB")
    )
    .into_bytes();
    ppm.extend([0u8; 100]);
    std::fs::write(d.join("huge.ppm"), &ppm).unwrap();
    for (band, out) in [("huge.png", "out.png"), ("huge.ppm", "out.ppm")] {
        fails(
            &d,
            &["stitch", "--max-memory", "1G", "-o", out, band],
            &format!("{band}: a 32768x32768 image of 16-bit"),
        );
        fails(
            &d,
            &["stitch", "--max-memory", "1G", "-o", out, band],
            "more than the memory limit of 1.0 GiB (--max-memory)",
        );
        assert!(!d.join(out).exists());
    }
    // Within the limit, the PPM's length says it lacks its samples before
    // they are allocated.
    fails(
        &d,
        &["stitch", "--max-memory", "1T", "-o", "out.ppm", "huge.ppm"],
        "huge.ppm: 100 bytes of samples, expected 6442450944",
    );
    let names: Vec<_> = std::fs::read_dir(&d)
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .collect();
    assert!(names.iter().all(|n| n.starts_with("huge.")), "{names:?}");
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn stitch_refuses_a_band_whose_description_lies_about_its_samples() {
    let d = folder("lying");
    let names = bands(&d, "s.rrt", "exr", 2, &[]);
    // OpenEXR bands saying they hold 8-bit codes (the same length, so the
    // files stay readable): refused naming the band, not the output.
    let mut lying = Vec::new();
    for (i, n) in names.iter().enumerate() {
        let bytes = read(&d, n);
        let text = b"32-bit float; ";
        let at = bytes
            .windows(text.len())
            .position(|w| w == text)
            .expect("the band description");
        let mut bytes = bytes;
        bytes[at..at + text.len()].copy_from_slice(b"8-bit linear; ");
        let name = format!("lying-{i}.exr");
        std::fs::write(d.join(&name), bytes).unwrap();
        lying.push(name);
    }
    fails(
        &d,
        &["stitch", "-o", "out.png", &lying[0], &lying[1]],
        "lying-0.exr: says it holds 8-bit linear samples, but OpenEXR bands hold 32-bit floats",
    );
    assert!(!d.join("out.png").exists());
    // A PNG band with two descriptions.
    {
        let file = std::fs::File::create(d.join("twice.png")).unwrap();
        let mut e = png::Encoder::new(std::io::BufWriter::new(file), 2, 2);
        e.set_color(png::ColorType::Rgb);
        for view in ["x", "y"] {
            e.add_text_chunk(
                "rrt-band".to_string(),
                format!("band 0/1 rows 0..2 of 2x2, 8-bit linear; view {view}"),
            )
            .unwrap();
        }
        let mut w = e.write_header().unwrap();
        w.write_image_data(&[0; 12]).unwrap();
    }
    fails(
        &d,
        &["stitch", "-o", "out.png", "twice.png"],
        "twice.png: two `rrt-band` descriptions",
    );
    assert!(!d.join("out.png").exists());
    let _ = std::fs::remove_dir_all(&d);
}
