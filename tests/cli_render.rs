//! `rrt render`, `rrt voxelize` and `rrt info` on bad input: each case gets
//! one clear error (with the file and line where there is one), never a
//! panic or a hang, and no output file is left behind. Exit codes are
//! checked on the binary in `std-host/tests/binary.rs`.

use std::path::PathBuf;

fn data(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("data")
        .join(name)
}

fn temp_dir(test: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("rrt-cli-{}-{test}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Runs the command line; the error message with its sources on failure.
fn cli(args: &[&str]) -> Result<String, String> {
    rrt_tests::run_cli(args)
}

#[track_caller]
fn fails_with(args: &[&str], expect: &str) {
    match cli(args) {
        Ok(out) => panic!("{args:?} succeeded: {out}"),
        Err(e) => assert!(e.contains(expect), "{args:?}: {e:?} lacks {expect:?}"),
    }
}

#[test]
fn render_writes_a_png_and_one_summary_line() {
    let dir = temp_dir("ok");
    let out = dir.join("t.png");
    let s = cli(&[
        "render",
        data("tetra.nff").to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
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
    ])
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
        "hits",
        "false hits",
    ] {
        assert!(s.contains(part), "{s:?} lacks {part:?}");
    }
    let img = image::open(&out).unwrap().to_rgb8();
    assert_eq!((img.width(), img.height()), (40, 30));
    assert!(!dir.join("t.png.tmp").exists());
    // Quiet: no summary.
    let q = cli(&[
        "render",
        data("tetra.nff").to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--width",
        "8",
        "--height",
        "8",
        "--raster",
        "32",
        "-q",
    ])
    .unwrap();
    assert!(q.is_empty());
    // The modes: exact by default (every light of a verified hit decided
    // exactly), the verified and the paper's on request.
    let x = |extra: &[&str]| {
        let mut a = vec![
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
        a.extend_from_slice(extra);
        cli(&a)
    };
    let s = x(&[]).unwrap();
    assert!(
        s.contains("(exact mode,") && !s.contains(" 0 shadow"),
        "{s}"
    );
    let s = x(&["--mode", "verified"]).unwrap();
    assert!(s.contains("(verified mode,"), "{s}");
    let s = x(&["--mode", "paper"]).unwrap();
    assert!(
        s.contains("(paper mode,") && s.contains(" 0 false hits"),
        "{s}"
    );
    let e = x(&["--mode", "fast"]).unwrap_err();
    assert!(e.contains("exact") && e.contains("paper"), "{e}");
    // The paper's raster renders only in the paper's mode.
    let rrt = dir.join("paper.rrt");
    cli(&[
        "voxelize",
        "-o",
        rrt.to_str().unwrap(),
        "--raster",
        "32",
        "--mode",
        "paper",
        "-q",
    ])
    .unwrap();
    let r = rrt.to_str().unwrap();
    let o = out.to_str().unwrap();
    let e = cli(&["render", r, "-o", o, "-q"]).unwrap_err();
    assert!(
        e.contains("exact mode") && e.contains("--mode paper"),
        "{e}"
    );
    cli(&["render", r, "-o", o, "-q", "--mode", "paper"]).unwrap();
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn bad_scenes_name_the_file_and_line() {
    let dir = temp_dir("scenes");
    let out = dir.join("o.png");
    let o = out.to_str().unwrap();
    let cases: [(&str, &[u8], &str); 6] = [
        (
            "radius.nff",
            b"v\nfrom 0 0 5\nat 0 0 0\nup 0 1 0\nangle 45\nhither 0\nresolution 8 8\ns 0 0 0 -1\n",
            "radius.nff:8:",
        ),
        (
            "letters.nff",
            b"v\nfrom 0 0 5\nat 0 0 0\nup 0 1 0\nangle 45\nhither 0\nresolution 8 8\ns 0 x 0 1\n",
            "letters.nff:8:",
        ),
        (
            "nan.nff",
            b"v\nfrom 0 0 5\nat 0 0 0\nup 0 1 0\nangle 45\nhither 0\nresolution 8 8\ns 0 0 nan 1\n",
            "nan.nff:8:",
        ),
        (
            "unknown.nff",
            b"v\nfrom 0 0 5\nat 0 0 0\nup 0 1 0\nangle 45\nhither 0\nresolution 8 8\nq 1 2 3\n",
            "unknown.nff:8:",
        ),
        ("empty.nff", b"", "empty.nff"),
        (
            "binary.nff",
            &[0xff, 0x00, 0xfe, 0x13, 0x37, 0x00, 0x80],
            "binary.nff",
        ),
    ];
    for (name, body, expect) in cases {
        let p = dir.join(name);
        std::fs::write(&p, body).unwrap();
        fails_with(
            &["render", p.to_str().unwrap(), "-o", o, "--raster", "16"],
            expect,
        );
        fails_with(
            &[
                "voxelize",
                p.to_str().unwrap(),
                "-o",
                dir.join("v.rrt").to_str().unwrap(),
            ],
            expect,
        );
    }
    fails_with(
        &["render", dir.join("missing.nff").to_str().unwrap(), "-o", o],
        "cannot read",
    );
    fails_with(
        &["render", dir.to_str().unwrap(), "-o", o],
        "is a directory",
    );
    // A failed render leaves no image and no temporary file behind, and a
    // failed voxelize no raster.
    assert!(!out.exists() && !dir.join("o.png.tmp").exists());
    assert!(!dir.join("v.rrt").exists());
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn unwritable_outputs_are_refused_before_work() {
    let dir = temp_dir("outputs");
    let scene = data("tetra.nff");
    let s = scene.to_str().unwrap();
    fails_with(
        &[
            "render",
            s,
            "-o",
            dir.join("no/such/dir/x.png").to_str().unwrap(),
        ],
        "cannot write",
    );
    fails_with(
        &["render", s, "-o", dir.to_str().unwrap()],
        "is a directory",
    );
    fails_with(
        &[
            "voxelize",
            s,
            "-o",
            dir.join("no/such/dir/x.rrt").to_str().unwrap(),
        ],
        "cannot write",
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn absurd_sizes_are_refused_up_front() {
    let dir = temp_dir("sizes");
    let o = dir.join("o.png");
    let o = o.to_str().unwrap();
    let scene = data("tetra.nff");
    let s = scene.to_str().unwrap();
    fails_with(&["render", s, "-o", o, "--raster", "0"], "--raster");
    fails_with(&["render", s, "-o", o, "--raster", "70000"], "--raster");
    fails_with(
        &["render", s, "-o", o, "--width", "0"],
        "--width <W>': must be positive, found 0",
    );
    fails_with(
        &["render", s, "-o", o, "--width", "100000"],
        "width: expected 1 to 32768 pixels",
    );
    fails_with(&["render", s, "-o", o, "--height", "4000000000"], "height");
    fails_with(
        &["render", s, "-o", o, "--supersample", "0"],
        "--supersample <K>': must be positive, found 0",
    );
    fails_with(
        &["render", s, "-o", o, "--supersample", "17"],
        "supersample: expected 1 to 16",
    );
    fails_with(
        &[
            "render",
            s,
            "-o",
            o,
            "--width",
            "32768",
            "--height",
            "32768",
            "--supersample",
            "16",
        ],
        "more than 4294967296",
    );
    fails_with(&["render", s, "-o", o, "--depth", "0"], "--depth");
    fails_with(
        &["render", s, "-o", o, "--bounds", "1,2,3"],
        "six comma-separated",
    );
    fails_with(
        &["render", s, "-o", o, "--max-memory", "lots"],
        "expected a size",
    );
    // A raster that does not fit the memory limit: refused before
    // allocating, with the estimate.
    fails_with(
        &[
            "render",
            s,
            "-o",
            o,
            "--raster",
            "65536",
            "--max-memory",
            "1G",
        ],
        "more than the limit of 1.0 GiB",
    );
    fails_with(
        &[
            "voxelize",
            s,
            "-o",
            dir.join("v.rrt").to_str().unwrap(),
            "--raster",
            "4096",
            "--max-memory",
            "64M",
        ],
        "more than the limit of 64.0 MiB",
    );
    assert!(!dir.join("o.png").exists());
    let _ = std::fs::remove_dir_all(&dir);
}

/// The paper's raster voxelized for adaptive rays is too thin for
/// 26-connected rays (an exact raster is thick enough for all);
/// `--raster` and `--bounds` do not apply to a saved raster.
#[test]
fn saved_raster_options_are_checked() {
    let dir = temp_dir("saved");
    let rrt = dir.join("t.rrt");
    let r = rrt.to_str().unwrap();
    let o = dir.join("o.png");
    let o = o.to_str().unwrap();
    cli(&[
        "voxelize",
        data("tetra.nff").to_str().unwrap(),
        "-o",
        r,
        "--raster",
        "32",
        "--mode",
        "paper",
        "-q",
    ])
    .unwrap();
    fails_with(
        &[
            "render",
            r,
            "-o",
            o,
            "--connectivity",
            "twenty-six",
            "--mode",
            "paper",
        ],
        "26-connected rays would pass through",
    );
    fails_with(&["render", r, "-o", o, "--raster", "64"], "--raster: ");
    fails_with(
        &["render", r, "-o", o, "--bounds", "0,0,0,1,1,1"],
        "--bounds: ",
    );
    fails_with(
        &["voxelize", r, "-o", dir.join("again.rrt").to_str().unwrap()],
        "already a saved raster",
    );
    cli(&[
        "render", r, "-o", o, "--width", "16", "--height", "16", "-q", "--mode", "paper",
    ])
    .unwrap();
    // Twenty-six-connected rays on a raster voxelized for them are fine.
    let r26 = dir.join("t26.rrt");
    cli(&[
        "voxelize",
        data("tetra.nff").to_str().unwrap(),
        "-o",
        r26.to_str().unwrap(),
        "--raster",
        "32",
        "--connectivity",
        "twenty-six",
        "-q",
    ])
    .unwrap();
    cli(&[
        "render",
        r26.to_str().unwrap(),
        "-o",
        o,
        "--width",
        "16",
        "--height",
        "16",
        "--connectivity",
        "twenty-six",
        "-q",
    ])
    .unwrap();
    let _ = std::fs::remove_dir_all(&dir);
}
