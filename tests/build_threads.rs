//! The voxelized scene does not depend on the number of threads: the
//! plane (with its distance field and rank hints), the line level, the
//! brick directory, the records, the object lists and the saved raster
//! file are the same bytes built on 1, 2 and 3 threads, for the exact
//! raster and the paper's; and the plane is the one the core's one-thread
//! passes finish.

use std::path::{Path, PathBuf};

use indicatif::ProgressBar;
use rrt_core::proximity::distance_field;
use rrt_core::raster::{RasterMut, cell};
use rrt_core::store::write_rank_hints;
use rrt_core::voxel::VoxelRecord;
use rrt_host::output::rasterfile;
use rrt_host::scene::Scene;
use rrt_host::voxelize::{BuildOptions, VoxelScene, build};
use rrt_tests::fresh_dir;

fn data(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("data")
        .join(name)
}

/// Overlapping objects of every kind: two spheres through each other and
/// through a checkered floor, a box, a torus and a capped cone touching
/// them, a textured volume, and a CSG cut.
const SCENE: &str = r#"
[camera]
from = [6, -8, 5]
at = [0, 0, 0.5]
angle = 40
resolution = [32, 32]

[[light]]
position = [5, -5, 10]

[[light]]
position = [-6, 2, 4]

[material.red]
colour = [1, 0, 0]

[material.green]
colour = [0, 1, 0]

[material.floor]
[material.floor.texture.checker]
size = 0.7
colours = [[230, 30, 20], [240, 220, 40]]

[material.wood]
[material.wood.texture.wood]
origin = [0, 0, 0]
direction = [0, 0, 1]
period = 0.3
colours = [[120, 70, 20], [200, 150, 90]]

[volume.blob]
metaballs = { dims = [24, 24, 24], min = [-1, -1, -1], max = [1, 1, 1], balls = [[0, 0, 0, 1.0, 1.0]] }
iso = 0.3
translate = [1.5, 1.5, 1]

[solid.ball]
sphere = { centre = [-2, 2, 1], radius = 1.2 }

[solid.cut]
box = { min = [-2, 1.5, 1], max = [-0.5, 4, 3] }
material = "green"

[[object]]
material = "floor"
polygon = [[-4, -4, 0.2], [4, -4, 0.2], [4, 4, 0.2], [-4, 4, 0.2]]

[[object]]
material = "red"
sphere = { centre = [0, 0, 1], radius = 1.1 }

[[object]]
material = "green"
sphere = { centre = [0.8, -0.5, 1.4], radius = 0.9 }

[[object]]
material = "wood"
box = { min = [-1, -1, 0], max = [0, 0, 1] }

[[object]]
material = "green"
torus = { centre = [2, -2, 0.5], axis = [0, 0.6, 0.8], major = 0.8, minor = 0.3 }

[[object]]
material = "red"
cone = { base = [-2, -2, 0], base_radius = 0.5, apex = [-1, -1, 2.5], apex_radius = 0.1, capped = true }

[[object]]
material = "wood"
volume = "blob"

[[object]]
material = "red"
csg = { difference = ["ball", "cut"] }
"#;

/// The bytes of a built scene and of its saved file.
#[derive(Debug, PartialEq)]
struct Bytes {
    plane: Vec<u8>,
    lines: Vec<u8>,
    directory: Vec<u32>,
    records: Vec<VoxelRecord>,
    lists: Vec<u32>,
    file: Vec<u8>,
}

fn bytes(vs: &VoxelScene, dir: &Path, name: &str) -> Bytes {
    let path = dir.join(format!("{name}.rrt"));
    rasterfile::save(vs, &path).unwrap();
    Bytes {
        plane: vs.plane.to_vec(),
        lines: vs.lines.clone(),
        directory: vs.directory.clone(),
        records: vs.records.clone(),
        lists: vs.lists.clone(),
        file: std::fs::read(&path).unwrap(),
    }
}

/// The plane of `vs` finished again by the core's one-thread passes from
/// its opaque voxels alone: the distance field and the rank hints.
fn serial_finish(vs: &VoxelScene) -> Vec<u8> {
    let mut plane: Vec<u8> = vs.plane.iter().map(|c| c & cell::OPAQUE).collect();
    let mut raster = RasterMut::new(vs.extent(), &mut plane).unwrap();
    distance_field(&mut raster);
    write_rank_hints(&mut raster, &vs.store().unwrap());
    plane
}

/// The plane of `vs` is the one [`serial_finish`] makes.
#[track_caller]
fn assert_same_cells(vs: &VoxelScene, what: &str) {
    let want = serial_finish(vs);
    if let Some(i) = (0..want.len()).find(|&i| vs.plane[i] != want[i]) {
        panic!(
            "{what}: voxel {:?} is {:#04x}, the core's one-thread passes make it {:#04x}",
            vs.extent().coord(i),
            vs.plane[i],
            want[i]
        );
    }
}

/// `scene` voxelized with `opts` on `threads` threads.
fn build_on(scene: &Scene, opts: BuildOptions, threads: usize) -> VoxelScene {
    build(
        scene,
        &BuildOptions { threads, ..opts },
        &ProgressBar::hidden(),
    )
    .unwrap()
    .0
}

#[test]
fn rasters_and_saved_files_are_identical_for_every_thread_count() {
    let dir = fresh_dir("rrt-build-threads", "scene");
    let path = dir.join("scene.toml");
    std::fs::write(&path, SCENE).unwrap();
    let scene = Scene::load(&path).unwrap();
    // Several brick layers high (the last one partial), so 2, 3 and 8
    // threads cut the raster into slabs, and fewer than half the pieces 8
    // threads want, so then the slabs into bands of brick rows too.
    for (what, opts) in [
        ("exact", BuildOptions::new(120)),
        ("paper", BuildOptions::paper(120)),
    ] {
        let one = build_on(&scene, opts, 1);
        assert!(one.extent().dims()[2] > 3 * 8, "{:?}", one.extent());
        assert!(one.extent().dims()[2] <= 2 * 8 * 8, "{:?}", one.extent());
        assert_eq!(one.exact, what == "exact");
        if one.exact {
            assert!(!one.lists.is_empty(), "overlapping objects have lists");
        }
        assert_same_cells(&one, what);
        let want = bytes(&one, &dir, &format!("{what}-1"));
        for threads in [2, 3, 8] {
            let vs = build_on(&scene, opts, threads);
            let got = bytes(&vs, &dir, &format!("{what}-{threads}"));
            // Field by field, for a readable failure.
            assert!(got.plane == want.plane, "{what}, {threads} threads: plane");
            assert!(got.lines == want.lines, "{what}, {threads} threads: lines");
            assert_eq!(got.directory, want.directory, "{what}, {threads} threads");
            assert!(
                got.records == want.records,
                "{what}, {threads} threads: records"
            );
            assert_eq!(got.lists, want.lists, "{what}, {threads} threads");
            assert!(
                got.file == want.file,
                "{what}, {threads} threads: saved file"
            );
        }
    }
}

#[test]
fn an_spd_scene_is_identical_for_every_thread_count() {
    // Many small objects over a floor (a flat raster: its two brick
    // layers are cut into bands), the paper's raster and the exact one.
    let scene = Scene::load(data("balls1.nff")).unwrap();
    let dir = fresh_dir("rrt-build-threads", "balls1");
    for opts in [BuildOptions::paper(200), BuildOptions::new(200)] {
        let one = build_on(&scene, opts, 1);
        assert_same_cells(&one, "balls1");
        let want = bytes(&one, &dir, "one");
        let vs = build_on(&scene, opts, 2);
        assert!(bytes(&vs, &dir, "two") == want, "exact {}", opts.exact);
    }
}

#[test]
fn a_sparse_scene_is_identical_for_every_thread_count() {
    // Small balls scattered through a raster of odd sizes (no side a
    // multiple of the brick edge), some alone in their slices, some
    // sharing brick rows or layers far apart: the field, worked out only
    // where opaque voxels are near (rows and boxes of slices), must equal
    // the core's passes over the whole plane.
    let mut rng = rrt_core::rng::Rng::new(0x5ca7_7e4d);
    let mut nff = String::from(
        "v\nfrom 300 -200 250\nat 50 30 20\nup 0 0 1\nangle 40\nhither 1\nresolution 32 32\n\
         l 400 -300 500\nf 0.8 0.6 0.4 1 0 0 0 1\n",
    );
    for _ in 0..40 {
        let c = [rng.range(2, 98), rng.range(2, 58), rng.range(2, 38)];
        let r = 0.3 + f64::from(rng.below_u32(12)) / 10.0;
        nff.push_str(&format!("s {} {} {} {r}\n", c[0], c[1], c[2]));
    }
    let scene = Scene::parse("sparse.nff", nff.as_bytes()).unwrap();
    let dir = fresh_dir("rrt-build-threads", "sparse");
    for opts in [BuildOptions::paper(203), BuildOptions::new(203)] {
        let one = build_on(&scene, opts, 1);
        assert_same_cells(&one, "sparse");
        let want = bytes(&one, &dir, "one");
        for threads in [2, 3] {
            let vs = build_on(&scene, opts, threads);
            assert!(bytes(&vs, &dir, "more") == want, "exact {}", opts.exact);
        }
    }
}
