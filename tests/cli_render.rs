//! `rrt render`, `rrt voxelize` and `rrt info` on bad input: each case gets
//! one clear error (with the file and line where there is one), never a
//! panic or a hang, and no output file is left behind. Exit codes are
//! checked on the binary in `std-host/tests/binary.rs`.

use std::path::{Path, PathBuf};

fn data(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("data")
        .join(name)
}

/// Runs `f` in a fresh temporary folder named after `test`, removed once
/// `f` returns (left for inspection when it panics).
fn in_temp_dir(test: &str, f: impl FnOnce(&Path)) {
    let d = rrt_tests::fresh_dir("rrt-cli", test);
    f(&d);
    let _ = std::fs::remove_dir_all(&d);
}

/// Runs the command line; the error message with its sources on failure.
fn cli(args: &[&str]) -> Result<String, String> {
    rrt_tests::run_cli(args)
}

/// [`cli`] with `args` followed by `extra`.
fn cli_with(args: &[&str], extra: &[&str]) -> Result<String, String> {
    cli(&[args, extra].concat())
}

/// `data/tetra.nff`, as an argument.
fn tetra() -> String {
    data("tetra.nff").to_str().unwrap().to_owned()
}

#[track_caller]
fn fails_with(args: &[&str], expect: &str) {
    match cli(args) {
        Ok(out) => panic!("{args:?} succeeded: {out}"),
        Err(e) => assert!(e.contains(expect), "{args:?}: {e:?} lacks {expect:?}"),
    }
}

/// [`fails_with`] for `args` followed by each case's arguments.
#[track_caller]
fn each_fails(args: &[&str], cases: &[(&[&str], &str)]) {
    for &(extra, expect) in cases {
        fails_with(&[args, extra].concat(), expect);
    }
}

#[test]
fn render_writes_a_png_and_one_summary_line() {
    in_temp_dir("ok", |dir| {
        let out = dir.join("t.png");
        let render: [&str; 4] = ["render", &tetra(), "-o", out.to_str().unwrap()];
        let s = cli_with(
            &render,
            &[
                "--width",
                "40",
                "--height",
                "30",
                "--raster",
                "64",
                "--supersample",
                "2",
                "--threads",
                "2",
            ],
        )
        .unwrap();
        assert_eq!(s.lines().count(), 1, "{s}");
        for part in [
            "40×30",
            "parse ",
            "voxelize ",
            "light visibility ",
            "render ",
            "4800 primary",
            "steps/ray",
            "steps/shadow ray",
            "in shared voxels",
            "false hits",
        ] {
            assert!(s.contains(part), "{s:?} lacks {part:?}");
        }
        let img = image::open(&out).unwrap().to_rgb8();
        assert_eq!((img.width(), img.height()), (40, 30));
        assert!(!dir.join("t.png.tmp").exists());
        // Quiet: no summary.
        let small = ["--width", "8", "--height", "8", "--raster", "32", "-q"];
        let q = cli_with(&render, &small).unwrap();
        assert!(q.is_empty());
        // The modes: exact by default (every light of a verified hit
        // decided exactly), the verified and the paper's on request.
        let x = |extra: &[&str]| {
            let a = [
                "render",
                "-o",
                out.to_str().unwrap(),
                "--width",
                "16",
                "--height",
                "16",
                "--raster",
                "64",
            ];
            cli_with(&a, extra)
        };
        let s = x(&[]).unwrap();
        assert!(
            s.contains("(exact mode,") && !s.contains(" 0 shadow"),
            "{s}"
        );
        // The exact mode's shadow rays walk; the number before the label.
        let shadow_steps: f64 = s
            .split(" steps/shadow ray")
            .next()
            .and_then(|t| t.rsplit(' ').next())
            .and_then(|v| v.parse().ok())
            .unwrap_or(0.0);
        assert!(shadow_steps > 0.0, "{s}");
        let s = x(&["--mode", "verified"]).unwrap();
        assert!(s.contains("(verified mode,"), "{s}");
        let s = x(&["--mode", "paper"]).unwrap();
        assert!(
            s.contains("(paper mode,")
                && s.contains(" 0 false hits")
                && s.contains("(0 in shared voxels)"),
            "{s}"
        );
        let e = x(&["--mode", "fast"]).unwrap_err();
        assert!(e.contains("exact") && e.contains("paper"), "{e}");
        // The paper's raster renders only in the paper's mode.
        let rrt = dir.join("paper.rrt");
        let r = rrt.to_str().unwrap();
        let o = out.to_str().unwrap();
        cli(&[
            "voxelize", "-o", r, "--raster", "32", "--mode", "paper", "-q",
        ])
        .unwrap();
        let e = cli(&["render", r, "-o", o, "-q"]).unwrap_err();
        assert!(
            e.contains("exact mode") && e.contains("--mode paper"),
            "{e}"
        );
        cli(&["render", r, "-o", o, "-q", "--mode", "paper"]).unwrap();
    });
}

#[test]
fn bad_scenes_name_the_file_and_line() {
    in_temp_dir("scenes", |dir| {
        let out = dir.join("o.png");
        let o = out.to_str().unwrap();
        // A valid view, then a bad line 8.
        let view = "v\nfrom 0 0 5\nat 0 0 0\nup 0 1 0\nangle 45\nhither 0\nresolution 8 8\n";
        let mut cases: Vec<(&str, Vec<u8>, &str)> = [
            ("radius.nff", "s 0 0 0 -1", "radius.nff:8:"),
            ("letters.nff", "s 0 x 0 1", "letters.nff:8:"),
            ("nan.nff", "s 0 0 nan 1", "nan.nff:8:"),
            ("unknown.nff", "q 1 2 3", "unknown.nff:8:"),
        ]
        .map(|(name, line, expect)| (name, format!("{view}{line}\n").into_bytes(), expect))
        .to_vec();
        cases.push(("empty.nff", Vec::new(), "empty.nff"));
        let binary = vec![0xff, 0x00, 0xfe, 0x13, 0x37, 0x00, 0x80];
        cases.push(("binary.nff", binary, "binary.nff"));
        let v = dir.join("v.rrt");
        for (name, body, expect) in cases {
            let p = dir.join(name);
            std::fs::write(&p, body).unwrap();
            let p = p.to_str().unwrap();
            fails_with(&["render", p, "-o", o, "--raster", "16"], expect);
            fails_with(&["voxelize", p, "-o", v.to_str().unwrap()], expect);
        }
        let missing = dir.join("missing.nff");
        for (input, expect) in [
            (missing.to_str().unwrap(), "cannot read"),
            (dir.to_str().unwrap(), "is a directory"),
        ] {
            fails_with(&["render", input, "-o", o], expect);
        }
        // A failed render leaves no image and no temporary file behind, and a
        // failed voxelize no raster.
        assert!(!out.exists() && !dir.join("o.png.tmp").exists());
        assert!(!v.exists());
    });
}

#[test]
fn unwritable_outputs_are_refused_before_work() {
    in_temp_dir("outputs", |dir| {
        let s = tetra();
        for (command, output, expect) in [
            ("render", dir.join("no/such/dir/x.png"), "cannot write"),
            ("render", dir.to_path_buf(), "is a directory"),
            ("voxelize", dir.join("no/such/dir/x.rrt"), "cannot write"),
        ] {
            fails_with(&[command, &s, "-o", output.to_str().unwrap()], expect);
        }
    });
}

#[test]
fn absurd_sizes_are_refused_up_front() {
    in_temp_dir("sizes", |dir| {
        let o = dir.join("o.png");
        let s = tetra();
        each_fails(
            &["render", &s, "-o", o.to_str().unwrap()],
            &[
                (&["--raster", "0"], "--raster"),
                (&["--raster", "70000"], "--raster"),
                (&["--width", "0"], "--width <W>': must be positive, found 0"),
                (&["--width", "100000"], "width: expected 1 to 32768 pixels"),
                (&["--height", "4000000000"], "height"),
                (
                    &["--supersample", "0"],
                    "--supersample <K>': must be positive, found 0",
                ),
                (&["--supersample", "17"], "supersample: expected 1 to 16"),
                (
                    &[
                        "--width",
                        "32768",
                        "--height",
                        "32768",
                        "--supersample",
                        "16",
                    ],
                    "more than 4294967296",
                ),
                (&["--depth", "0"], "--depth"),
                (&["--bounds", "1,2,3"], "six comma-separated"),
                // A box so small that the objects reaching out of it are
                // beyond its raster's fixed point: the box is named.
                (
                    &["--bounds", "0,0,0,1e-9,1e-9,1e-9"],
                    "is too small for the objects that reach outside it; give a larger box or a smaller --raster",
                ),
                (&["--max-memory", "lots"], "expected a size"),
                // A raster that does not fit the memory limit: refused before
                // allocating, with the estimate.
                (
                    &["--raster", "65536", "--max-memory", "1G"],
                    "more than the limit of 1.0 GiB",
                ),
                // So is an image, and a band of one by its own rows.
                (
                    &[
                        "--width",
                        "16384",
                        "--height",
                        "16384",
                        "--max-memory",
                        "1G",
                    ],
                    "--width/--height: a 16384×16384 image needs about 5.2 GiB, more than the memory limit of 1.0 GiB",
                ),
                (
                    &[
                        "--width",
                        "32768",
                        "--height",
                        "32768",
                        "--tile",
                        "1/64",
                        "--max-memory",
                        "100M",
                    ],
                    "a 32768×512 image needs about 336.0 MiB",
                ),
                // An image the scene's view sizes is named by the view.
                (&["--max-memory", "1K"], "--max-memory: the view at "),
            ],
        );
        let v = dir.join("v.rrt");
        fails_with(
            &[
                "voxelize",
                &s,
                "-o",
                v.to_str().unwrap(),
                "--raster",
                "4096",
                "--max-memory",
                "64M",
            ],
            "more than the limit of 64.0 MiB",
        );
        assert!(!o.exists());
    });
}

/// The paper's raster voxelized for adaptive rays is too thin for
/// 26-connected rays (an exact raster is thick enough for all);
/// `--raster` and `--bounds` do not apply to a saved raster.
#[test]
fn saved_raster_options_are_checked() {
    in_temp_dir("saved", |dir| {
        let rrt = dir.join("t.rrt");
        let r = rrt.to_str().unwrap();
        let o = dir.join("o.png");
        let o = o.to_str().unwrap();
        let voxelize = |out: &str, extra: &[&str]| {
            cli_with(&["voxelize", &tetra(), "-o", out, "--raster", "32"], extra).unwrap();
        };
        voxelize(r, &["--mode", "paper", "-q"]);
        // What the raster was voxelized for is the file's: it is named.
        let thin = format!(
            "{r}: the raster was voxelized for 6-connected or adaptive rays; 26-connected rays would pass through"
        );
        let paper = format!(
            "{r}: the exact mode verifies hits against every object of a voxel, but this raster was voxelized for the paper's mode"
        );
        fails_with(&["render", r, "-o", o], &paper);
        fails_with(
            &["render", r, "-o", o, "--path", dir.to_str().unwrap()],
            &format!("{}: is a directory, not a camera path", dir.display()),
        );
        each_fails(
            &["render", r, "-o", o, "--mode", "paper"],
            &[
                (&["--connectivity", "twenty-six"], &thin),
                (&["--raster", "64"], "--raster: "),
                (&["--bounds", "0,0,0,1,1,1"], "--bounds: "),
            ],
        );
        fails_with(
            &["voxelize", r, "-o", dir.join("again.rrt").to_str().unwrap()],
            "already a saved raster",
        );
        let small = ["--width", "16", "--height", "16"];
        let paper = ["--mode", "paper", "-q"];
        cli_with(&["render", r, "-o", o], &[&small[..], &paper].concat()).unwrap();
        // Twenty-six-connected rays on a raster voxelized for them are fine
        // in the paper's mode; the verifying modes refuse them, before any
        // work: they step diagonally past voxels verification would need.
        let r26 = dir.join("t26.rrt");
        let r26 = r26.to_str().unwrap();
        let twenty_six = ["--connectivity", "twenty-six", "-q"];
        voxelize(r26, &twenty_six);
        cli_with(
            &["render", r26, "-o", o],
            &[&small[..], &twenty_six, &["--mode", "paper"][..]].concat(),
        )
        .unwrap();
        for mode in ["exact", "verified"] {
            fails_with(
                &[&["render", r26, "-o", o, "--mode", mode][..], &twenty_six].concat(),
                &format!(
                    "26-connected rays step diagonally past voxels the ray passes through, so the {mode} mode's verification would miss the objects there"
                ),
            );
        }
        fails_with(
            &["render", &tetra(), "-o", o, "--connectivity", "twenty-six"],
            "so the exact mode's verification would miss",
        );
    });
}

/// The raster and the image count together against `--max-memory`: with
/// a limit that each fits alone (a 512² image takes about 5.2 MiB, balls1's
/// raster 96 under 0.6 MiB) but not both, a scene and its saved raster are
/// refused, naming both; with room for both, they render.
#[test]
fn the_raster_and_the_image_share_the_memory_limit() {
    in_temp_dir("shared-limit", |dir| {
        let rrt = dir.join("t.rrt");
        let r = rrt.to_str().unwrap();
        let scene = data("balls1.nff");
        let scene = scene.to_str().unwrap();
        cli(&["voxelize", scene, "-o", r, "--raster", "96", "-q"]).unwrap();
        let o = dir.join("o.png");
        let o = o.to_str().unwrap();
        let size = ["--width", "512", "--height", "512", "-q", "-o", o];
        let raster = ["--raster", "96"];
        let tight = ["--max-memory", "5400K"];
        fails_with(
            &[&["render", scene][..], &raster, &size, &tight].concat(),
            ", the image 5.2 MiB), more than the limit of 5.3 MiB",
        );
        fails_with(
            &[&["render", r][..], &size, &tight].concat(),
            "t.rrt: the raster takes 257.0 KiB once loaded and the image 5.2 MiB, together more than the limit of 5.3 MiB",
        );
        assert!(!Path::new(o).exists());
        let room = ["--max-memory", "6M"];
        cli(&[&["render", scene][..], &raster, &size, &room].concat()).unwrap();
        cli(&[&["render", r][..], &size, &room].concat()).unwrap();
        assert!(Path::new(o).exists());
    });
}

/// A saved raster is refused when loading it would need more memory than
/// `--max-memory`, as a scene's raster is, before it is made; and a raster
/// saved for the verified mode renders the scene's verified image, byte
/// for byte (it keeps the paper's light bits, which that mode reads).
#[test]
fn saved_rasters_keep_the_memory_limit_and_the_verified_image() {
    in_temp_dir("saved-limit", |dir| {
        let rrt = dir.join("t.rrt");
        let r = rrt.to_str().unwrap();
        let scene = data("balls1.nff");
        let scene = scene.to_str().unwrap();
        let small = ["--width", "24", "--height", "24", "-q"];
        cli(&[
            "voxelize", scene, "-o", r, "--raster", "96", "--mode", "verified", "-q",
        ])
        .unwrap();
        let o = dir.join("o.png");
        let o = o.to_str().unwrap();
        fails_with(
            &[&["render", r, "-o", o, "--max-memory", "64K"][..], &small].concat(),
            "more than the limit of 64.0 KiB",
        );
        assert!(!Path::new(o).exists());
        let image = |args: &[&str], out: &str| {
            let out = dir.join(out);
            let out = out.to_str().unwrap();
            cli_with(
                &[
                    &["render"][..],
                    args,
                    &["-o", out, "--mode", "verified"],
                    &small,
                ]
                .concat(),
                &[],
            )
            .unwrap();
            std::fs::read(out).unwrap()
        };
        let saved = image(&[r], "saved.ppm");
        let direct = image(&[scene, "--raster", "96"], "scene.ppm");
        assert_eq!(saved, direct);
    });
}

/// A TOML scene's own data counts against `--max-memory` before it is
/// read or made: the samples of all its volumes together (each within the
/// limit alone) and the vertices a Bézier tessellation would make, each
/// refused at its key with the limit; under a limit the data fits, the
/// scene renders.
#[test]
fn a_scenes_volumes_and_vertices_keep_the_memory_limit() {
    in_temp_dir("scene-memory", |dir| {
        let ball = "balls = [[0, 0, 0, 1, 1]]";
        let head = "[camera]\nfrom = [0, -6, 1]\nat = [0, 0, 0]\nangle = 40\nresolution = [16, 16]\n\
                    [material.m]\ncolour = [0.8, 0.3, 0.3]\n";
        // Two volumes of 64³ float samples: 1 MiB each.
        let mut volumes = head.to_string();
        for (i, x) in [-1.5, 1.5].iter().enumerate() {
            volumes += &format!(
                "[volume.v{i}]\nmetaballs = {{ dims = [64, 64, 64], min = [-1.2, -1.2, -1.2], max = [1.2, 1.2, 1.2], {ball} }}\n\
                 iso = 0.3\ntranslate = [{x}, 0, 0]\n[[object]]\nmaterial = \"m\"\nvolume = \"v{i}\"\n"
            );
        }
        let v = dir.join("volumes.toml");
        std::fs::write(&v, &volumes).unwrap();
        let v = v.to_str().unwrap();
        let o = dir.join("o.png");
        let o = o.to_str().unwrap();
        let q = ["-o", o, "-q", "--max-memory"];
        fails_with(
            &[&["render", v][..], &q, &["1536K"]].concat(),
            "volumes.toml:16:22: volume.v1.metaballs.dims: computed volume: sizes 64×64×64 of float take 1.0 MiB beside the 1.0 MiB of the volumes and textures read before, more than the memory limit of 1.5 MiB (--max-memory)",
        );
        fails_with(
            &[&["render", v][..], &q, &["512K"]].concat(),
            "volume.v0.metaballs.dims: computed volume: sizes 64×64×64 of float take 1.0 MiB, more than the memory limit of 512.0 KiB (--max-memory)",
        );
        assert!(!Path::new(o).exists());
        cli(&[&["render", v][..], &q, &["64M"]].concat()).unwrap();
        assert!(Path::new(o).exists());
        // One patch at 64 steps: 64² quads of 4 vertices, 48 bytes each.
        let bpt = "1\n3 3\n".to_string()
            + &(0..16)
                .map(|k| format!("{} {} 0\n", f64::from(k / 4) - 1.5, f64::from(k % 4) - 1.5))
                .collect::<String>();
        std::fs::write(dir.join("flat.bpt"), bpt).unwrap();
        let b = dir.join("patch.toml");
        std::fs::write(
            &b,
            head.to_string()
                + "[[object]]\nmaterial = \"m\"\nbezier = { file = \"flat.bpt\", steps = 64 }\n",
        )
        .unwrap();
        let b = b.to_str().unwrap();
        fails_with(
            &[&["render", b][..], &q, &["512K"]].concat(),
            "16384 vertices take 768.0 KiB, more than the memory limit of 512.0 KiB (--max-memory)",
        );
    });
}

/// The memory an image needs counts its format's encoding: OpenEXR is made
/// whole in memory, so a limit a PNG of the same size fits is refused for
/// it up front.
#[test]
fn the_image_memory_counts_the_format() {
    in_temp_dir("exr-limit", |dir| {
        let png = dir.join("o.png");
        let exr = dir.join("o.exr");
        let args = |out: &Path| {
            let out = out.to_str().unwrap().to_owned();
            let mut a: Vec<String> = ["render", &tetra(), "-o", &out, "--raster", "32", "-q"]
                .iter()
                .map(|s| (*s).to_owned())
                .collect();
            a.extend(["--width", "512", "--height", "512", "--max-memory", "8M"].map(String::from));
            a
        };
        let run = |out: &Path| {
            let a = args(out);
            cli(&a.iter().map(String::as_str).collect::<Vec<_>>())
        };
        run(&png).unwrap();
        let e = run(&exr).unwrap_err();
        assert!(e.contains("more than the memory limit of 8.0 MiB"), "{e}");
        assert!(!exr.exists());
    });
}

/// Reflected plus refracted rays, and the rays not traced, from a summary
/// line.
fn secondary_rays(summary: &str) -> (u64, u64) {
    let count = |after: &str, word: &str| -> u64 {
        let rest = &summary[summary.find(after).unwrap() + after.len()..];
        let end = rest.find(word).unwrap_or_else(|| panic!("{summary}"));
        rest[..end].trim().parse().unwrap()
    };
    let traced = count("primary, ", " reflected") + count("reflected, ", " refracted");
    let pruned = if summary.contains("not traced") {
        count("refracted (", " more not traced")
    } else {
        0
    };
    (traced, pruned)
}

#[test]
fn rays_lighter_than_the_min_weight_are_counted_not_traced() {
    // The eye inside a glass sphere with glass spheres around: the ray
    // tree doubles at every level until the weights fall.
    let scene = "\
b 0.1 0.1 0.2
l 0.5 -1 1
f 0.9 0.9 1 0.1 0.5 50 0.9 1.5
s 0 0 0 5
s 0.5 0.5 0 1
s -1 1 0.5 0.8
s 1 -1 -0.5 0.7
v
from 0 -3 0
at 0 0 0
up 0 0 1
angle 60
hither 0.1
resolution 4 4
";
    in_temp_dir("min-weight", |dir| {
        let nff = dir.join("trap.nff");
        std::fs::write(&nff, scene).unwrap();
        let nff = nff.to_str().unwrap();
        let render = |depth: &str, weight: &str, out: &str| {
            let out = dir.join(out);
            let args = ["render", nff, "-o", out.to_str().unwrap()];
            let extra = ["--raster", "48", "--depth", depth, "--min-weight", weight];
            let s = cli_with(&args, &extra).unwrap();
            (secondary_rays(&s), std::fs::read(out).unwrap(), s)
        };
        // The whole tree, then rays lighter than 1/20 not traced.
        let ((all, none), _, s) = render("12", "0", "all.png");
        assert_eq!(none, 0, "{s}");
        assert!(all > 1000, "{s}");
        let ((heavy, light), _, s) = render("12", "0.05", "heavy.png");
        assert!(light > 0 && heavy < all, "{s}");
        assert!(s.contains("weight below 5e-2"), "{s}");
        // At depth 3 no ray is as light as the default's 2^-16: the image
        // is the whole tree's.
        let ((_, light), with, _) = render("3", "1.52587890625e-5", "default.png");
        let (_, whole, _) = render("3", "0", "whole.png");
        assert_eq!(light, 0);
        assert!(with == whole);
        fails_with(
            &["render", nff, "--min-weight", "2"],
            "expected a number from 0 to 1, found 2",
        );
        // A negative value is read as the option's value, and refused.
        fails_with(
            &["render", nff, "--min-weight", "-0.5"],
            "expected a number from 0 to 1, found -0.5",
        );
        let (_, minus_zero, _) = render("3", "-0", "minus-zero.png");
        assert!(minus_zero == whole);
    });
}
