//! `rrt ray`: the report format and the handling of bad arguments, through
//! the library's command-line entry point.

use clap::Parser;
use rrt_host::cli::{Cli, run};

fn ray(args: &[&str]) -> Result<String, String> {
    let cli = Cli::try_parse_from(
        std::iter::once("rrt")
            .chain(std::iter::once("ray"))
            .chain(args.iter().copied()),
    )
    .map_err(|e| e.to_string())?;
    let mut out = Vec::new();
    run(&cli, &mut out).map_err(|e| e.to_string())?;
    Ok(String::from_utf8(out).unwrap())
}

#[test]
fn report_states_the_fixed_point_ray_then_its_voxels() {
    let out = ray(&[
        "--dims",
        "4,4,4",
        "--origin",
        "-1,0.5,0.5",
        "--dir",
        "1,0.5,0.25",
        "--connectivity",
        "six",
    ])
    .unwrap();
    let lines: Vec<&str> = out.lines().collect();
    assert_eq!(
        lines[0],
        "origin_fx=-65536,32768,32768 dir_fx=65536,32768,16384 frac_bits=16 voxel=corner"
    );
    // Enters at (0, 1, 0.75): on a y face, so in y voxel 1; then x and z
    // cross together (x first), then x and y together (x first).
    assert_eq!(
        &lines[1..],
        ["0 1 0", "1 1 0", "1 1 1", "2 1 1", "2 2 1", "3 2 1", "miss"]
    );
}

#[test]
fn twenty_six_and_adaptive_use_the_driving_axis() {
    let out = ray(&[
        "--dims",
        "8,8,8",
        "--origin",
        "0,0,0",
        "--dir",
        "1,1,1",
        "--connectivity",
        "twenty-six",
    ])
    .unwrap();
    let voxels: Vec<&str> = out.lines().skip(1).collect();
    assert_eq!(voxels.len(), 9);
    assert_eq!(voxels[0], "0 0 0");
    assert_eq!(voxels[7], "7 7 7");
    assert_eq!(voxels[8], "miss");
    // Adaptive in an empty raster steps like twenty-six.
    let ada = ray(&["--dims", "8,8,8", "--origin", "0,0,0", "--dir", "1,1,1"]).unwrap();
    assert_eq!(ada, out);
}

#[test]
fn rays_that_miss_the_box_print_only_miss() {
    let out = ray(&["--dims", "4,4,4", "--origin", "-1,-1,-1", "--dir", "-1,0,0"]).unwrap();
    assert_eq!(out.lines().nth(1), Some("miss"));
    assert_eq!(out.lines().count(), 2);
}

#[test]
fn huge_rasters_are_walked_without_allocating() {
    let out = ray(&[
        "--dims",
        "65536,65536,65536",
        "--origin",
        "0.5,0.5,0.5",
        "--dir",
        "0,0,1",
    ])
    .unwrap();
    assert_eq!(out.lines().count(), 1 + 65536 + 1);
}

#[test]
fn bad_arguments_are_refused_with_a_reason() {
    for (args, needle) in [
        (
            vec!["--dims", "4,0,4", "--origin", "0,0,0", "--dir", "1,1,1"],
            "dimension y is zero",
        ),
        (
            vec!["--dims", "65537,4,4", "--origin", "0,0,0", "--dir", "1,1,1"],
            "exceeds the limit",
        ),
        (
            vec!["--dims", "4,4", "--origin", "0,0,0", "--dir", "1,1,1"],
            "three comma-separated values",
        ),
        (
            vec!["--dims", "4,4,4", "--origin", "0,x,0", "--dir", "1,1,1"],
            "y: expected a decimal number",
        ),
        (
            vec!["--dims", "4,4,4", "--origin", "0,0,0", "--dir", "1,1,nan"],
            "z: expected a decimal number",
        ),
        (
            vec![
                "--dims",
                "4,4,4",
                "--origin",
                "99999999999,0,0",
                "--dir",
                "1,1,1",
            ],
            "outside the accepted range",
        ),
        (
            vec!["--dims", "4,4,4", "--origin", "0,0,0", "--dir", "40000,1,1"],
            "does not fit",
        ),
        (
            vec![
                "--dims",
                "4,4,4",
                "--origin",
                "0,0,0",
                "--dir",
                "1,1,1",
                "--connectivity",
                "eight",
            ],
            "invalid value",
        ),
        (vec!["--dims", "4,4,4", "--origin", "0,0,0"], "--dir"),
    ] {
        let err = ray(&args).unwrap_err();
        assert!(err.contains(needle), "{args:?}: {err}");
    }
}
