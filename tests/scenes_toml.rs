//! TOML scenes: the scenes of `scenes/` parse and build; every kind of
//! object reaches the raster (asserted on the records); bad scenes give one
//! error naming the file, line and key.

use std::path::{Path, PathBuf};

use glam::DVec3;
use indicatif::ProgressBar;
use rrt_host::output::rasterfile;
use rrt_host::scene::Scene;
use rrt_host::shape::Shape;
use rrt_host::trace::{Verdict, verify};
use rrt_host::voxelize::{BuildOptions, VoxelScene, build, derive_plane, plane_matches_records};
use rrt_host::world::Ray;

fn scenes_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../scenes")
}

fn temp_dir(test: &str) -> rrt_tests::Scratch {
    rrt_tests::fresh_dir("rrt-toml", test)
}

fn built(scene: &Scene, raster: u32) -> VoxelScene {
    build(scene, &BuildOptions::new(raster), &ProgressBar::hidden())
        .unwrap_or_else(|e| panic!("{}: {e}", scene.file))
        .0
}

/// World centre of each record with its object id and colour.
fn records(vs: &VoxelScene) -> Vec<(DVec3, u32, [u8; 3])> {
    let store = vs.store().unwrap();
    store
        .iter()
        .map(|(v, r)| {
            let p = vs
                .frame
                .raster_to_world(DVec3::from(v.map(f64::from)) + 0.5);
            (p, r.object, r.color)
        })
        .collect()
}

#[test]
fn whitted_scene_has_both_checker_colours_on_the_board() {
    let scene = Scene::load(scenes_dir().join("fig6-whitted.toml")).unwrap();
    assert_eq!(scene.spheres.len(), 2);
    assert_eq!(scene.textures.len(), 1);
    let vs = built(&scene, 64);
    let board = records(&vs)
        .into_iter()
        .filter(|(p, _, _)| p.z.abs() < 0.2)
        .collect::<Vec<_>>();
    let red = board.iter().filter(|r| r.2 == [230, 30, 20]).count();
    let yellow = board.iter().filter(|r| r.2 == [240, 220, 40]).count();
    assert!(red > 100 && yellow > 100, "red {red} yellow {yellow}");
    // The checker's squares: a voxel centre's colour follows its square.
    for (p, _, c) in &board {
        let sq = (p.x / 0.6).floor() + (p.y / 0.6).floor() + (p.z / 0.6).floor();
        let near_edge = [p.x, p.y, p.z]
            .iter()
            .any(|v| (v / 0.6 - (v / 0.6).round()).abs() < 0.02);
        if !near_edge && (*c == [230, 30, 20] || *c == [240, 220, 40]) {
            let want = if sq.rem_euclid(2.0) == 0.0 {
                [230, 30, 20]
            } else {
                [240, 220, 40]
            };
            assert_eq!(*c, want, "at {p}");
        }
    }
}

const FEATURES: &str = r#"
[camera]
from = [6, -8, 5]
at = [0, 0, 0.5]
angle = 40
resolution = [32, 32]

[[light]]
position = [5, -5, 10]

[material.red]
colour = [1, 0, 0]

[material.green]
colour = [0, 1, 0]

[material.wood]
[material.wood.texture.wood]
origin = [0, 0, 0]
direction = [0, 0, 1]
period = 0.3
colours = [[120, 70, 20], [200, 150, 90]]

[volume.blob]
metaballs = { dims = [24, 24, 24], min = [-1, -1, -1], max = [1, 1, 1], balls = [[0, 0, 0, 1.0, 1.0]] }
iso = 0.3
translate = [3, 3, 1]

[solid.ball]
sphere = { centre = [-3, 3, 1], radius = 1 }

[solid.cut]
box = { min = [-3, 2, 1], max = [-1.5, 4.5, 2.5] }
material = "green"

[[object]]
material = "red"
box = { min = [-1, -1, 0], max = [0, 0, 1] }

[[object]]
material = "green"
torus = { centre = [2, -2, 0.5], axis = [0, 0, 1], major = 0.8, minor = 0.3 }

[[object]]
material = "red"
cone = { base = [-2, -2, 0], base_radius = 0.5, apex = [-2, -2, 1.5], apex_radius = 0.1, capped = true }

[[object]]
material = "green"
bezier = { file = "flat.bpt", steps = 4 }

[[object]]
material = "red"
mesh = { file = "tri.obj" }
transform = { translate = [0, 2, 0] }

[[object]]
material = "wood"
volume = "blob"

[[object]]
material = "red"
csg = { difference = ["ball", "cut"] }
"#;

fn features_dir(test: &str) -> rrt_tests::Scratch {
    let d = temp_dir(test);
    let bpt = "1\n3 3\n".to_string()
        + &(0..16)
            .map(|k| format!("{} {} 0\n", f64::from(k / 4) - 1.5, f64::from(k % 4) - 1.5))
            .collect::<String>();
    std::fs::write(d.join("flat.bpt"), bpt).unwrap();
    std::fs::write(d.join("tri.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 1\nf 1 2 3\n").unwrap();
    std::fs::write(d.join("features.toml"), FEATURES).unwrap();
    d
}

#[test]
fn every_object_kind_reaches_the_raster() {
    let d = features_dir("kinds");
    let scene = Scene::load(d.join("features.toml")).unwrap();
    // Box: 6 polygons; Bézier: 4 × 4 patch quads; mesh: 1 triangle.
    assert_eq!(scene.polygons.len(), 6 + 16 + 1);
    assert!(scene.polygons[6..22].iter().all(|p| p.patch));
    // The torus is a primitive; the capped cone a one-solid CSG tree,
    // beside the cut ball.
    assert_eq!(scene.tori.len(), 1);
    assert_eq!(scene.csgs.len(), 2);
    assert_eq!(scene.volumes.len(), 1);
    rrt_host::check::check_scene(&scene).unwrap();
    let vs = built(&scene, 96);
    let recs = records(&vs);
    let n_objects = vs.objects.len();
    // The torus is the last primitive; then the volume, then the CSG trees
    // in scene order: cone, ball.
    let volume_id = u32::try_from(n_objects - 3).unwrap();
    let torus_id = volume_id - 1;
    let ball_id = volume_id + 2;
    let of = |id: u32| recs.iter().filter(|r| r.1 == id).collect::<Vec<_>>();
    let blob = of(volume_id);
    assert!(blob.len() > 50, "volume voxels {}", blob.len());
    // The metaball's iso-surface f = 0.3 lies at r = sqrt(1 − 0.3^(1/3)).
    let r = (1.0 - 0.3f64.cbrt()).sqrt();
    for (p, _, _) in &blob {
        let d = (*p - DVec3::new(3.0, 3.0, 1.0)).length();
        assert!((d - r).abs() < 0.15, "blob voxel at distance {d}, want {r}");
    }
    let torus = of(torus_id);
    assert!(torus.len() > 50);
    assert!(torus.iter().all(|t| t.2 == [0, 255, 0]));
    // Wood colours the volume (not the flat material colour).
    assert!(blob.iter().any(|t| t.2 != blob[0].2));
    // The ball minus the box: no ball voxel deep inside the cut, and the
    // cut face carries the cutting solid's (green) material.
    let ball = of(ball_id);
    assert!(ball.len() > 100);
    let vsz = vs.frame.voxel_size;
    for (p, _, _) in &ball {
        let inside = p.x > -3.0 + 2.0 * vsz
            && p.x < -1.5 - 2.0 * vsz
            && p.y > 2.0 + 2.0 * vsz
            && p.z > 1.0 + 2.0 * vsz;
        assert!(!inside, "ball voxel at {p} inside the cut");
    }
    assert!(ball.iter().any(|b| b.2 == [0, 255, 0]));
    assert!(ball.iter().any(|b| b.2 == [255, 0, 0]));
}

/// The builder's plane is the plane made again from its records
/// (`derive_plane`: the records' voxels opaque with their rank hints, the
/// distance field, the proximity flags), byte for byte, for every kind of
/// object and the scenes of `scenes/`, in the exact and the paper's mode:
/// so a saved raster stores no plane bricks, and a loaded one renders as
/// the built one.
#[test]
fn built_planes_are_their_records_planes() {
    let d = features_dir("planes");
    let mut scenes = vec![Scene::load(d.join("features.toml")).unwrap()];
    let mut names: Vec<PathBuf> = std::fs::read_dir(scenes_dir())
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .collect();
    names.sort();
    for name in names {
        scenes.push(Scene::load(&name).unwrap_or_else(|e| panic!("{}: {e}", name.display())));
    }
    let mut compared = 0;
    for scene in &scenes {
        for opts in [BuildOptions::new(48), BuildOptions::paper(48)] {
            let vs = build(scene, &opts, &ProgressBar::hidden())
                .unwrap_or_else(|e| panic!("{}: {e}", scene.file))
                .0;
            let [_, _, nz] = vs.extent().dims();
            let store = vs.store().unwrap();
            let (derived, z0) = derive_plane(&store, [0, nz]).unwrap();
            assert_eq!(z0, 0);
            assert!(
                derived[..] == vs.plane[..],
                "{} (exact: {}): the built plane is not its records' plane",
                scene.file,
                vs.exact
            );
            // What saving a built raster checks instead.
            assert!(plane_matches_records(&vs.plane, &store));
            compared += 1;
        }
    }
    assert!(compared >= 12, "{compared} scenes compared");
}

/// The plane the builder and the loader make (the distance field on the
/// thread pool, over the rows and boxes the records' bricks allow) is the
/// core's plain distance field of the records' voxels (every slice read,
/// on one thread) with their rank hints, byte for byte: for scenes of a
/// few spheres far apart (most of the raster far from every surface),
/// large ones spanning many bricks, spheres cut by the raster's faces,
/// rasters whose sides are not multiples of the brick edge, and the runs of
/// slices a loader makes one at a time.
#[test]
fn built_and_loaded_planes_are_the_plain_distance_field() {
    use rrt_core::proximity::distance_field;
    use rrt_core::raster::{RasterMut, cell};
    use rrt_core::store::write_rank_hints;
    let mut state = 0x9e37_79b9_7f4a_7c15u64;
    let mut unit = move || {
        state = state.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = state;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    };
    for case in 0..12 {
        let count = 1 + case % 5;
        let mut text = String::from(
            "v\nfrom 0 -30 10\nat 0 0 0\nup 0 0 1\nangle 40\nhither 1\nresolution 8 8\n\
             b 0 0 0\nl 5 -20 30\nf 1 1 1 1 0 10 0 1\ns 1 -2 0 1.5\n",
        );
        for _ in 0..count {
            // Centres anywhere in the box (spheres at its faces are cut);
            // radii from a fraction of a voxel to a third of the box.
            let c = [unit(), unit(), unit()].map(|u| (u - 0.5) * 20.0);
            let r = 0.05 + unit().powi(3) * 7.0;
            text.push_str(&format!("s {} {} {} {r}\n", c[0], c[1], c[2]));
        }
        let scene = Scene::parse("spheres.nff", text.as_bytes()).unwrap();
        let raster = [40, 61, 97, 130][case % 4];
        let mut opts = if case % 3 == 0 {
            BuildOptions::paper(raster)
        } else {
            BuildOptions::new(raster)
        };
        // A box cutting the spheres above z = 6.5.
        opts.fit.bounds = Some(rrt_host::world::Bounds {
            min: DVec3::splat(-10.0),
            max: DVec3::new(10.0, 10.0, 6.5),
        });
        let vs = build(&scene, &opts, &ProgressBar::hidden())
            .unwrap_or_else(|e| panic!("case {case}: {e}"))
            .0;
        let store = vs.store().unwrap();
        let extent = store.extent();
        let [_, _, nz] = extent.dims();
        // The records' voxels opaque, every other cell empty.
        let mut plain = vec![cell::EMPTY; extent.len()];
        for (v, _) in store.iter() {
            plain[extent.index(v).unwrap()] = cell::OPAQUE;
        }
        let mut r = RasterMut::new(extent, &mut plain).unwrap();
        distance_field(&mut r);
        write_rank_hints(&mut r, &store);
        assert!(
            vs.plane[..] == plain[..],
            "case {case}: the built plane is not the plain distance field"
        );
        let slice = (extent.dims()[0] * extent.dims()[1]) as usize;
        for part in [[0, nz], [nz / 3, nz / 3 + 1], [nz / 2, nz]] {
            let (derived, z0) = derive_plane(&store, part).unwrap();
            let (a, b) = (part[0] as usize, part[1] as usize);
            let from = (part[0] - z0) as usize * slice;
            assert!(
                derived[from..from + (b - a) * slice] == plain[a * slice..b * slice],
                "case {case}: slices {a}..{b} made on load differ from the plain field"
            );
        }
    }
}

#[test]
fn toml_scene_renders_through_the_cli() {
    let d = features_dir("cli");
    let out = d.join("out.png");
    let c = <rrt_host::cli::Cli as clap::Parser>::try_parse_from([
        "rrt",
        "render",
        d.join("features.toml").to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--raster",
        "64",
        "--quiet",
    ])
    .unwrap();
    rrt_host::cli::run(&c, &mut Vec::new()).unwrap();
    let img = image::open(&out).unwrap().to_rgb8();
    assert_eq!(img.dimensions(), (32, 32));
    // Something besides the background (black) was hit.
    assert!(img.pixels().filter(|p| p.0 != [0, 0, 0]).count() > 50);
}

fn error_of(name: &str, text: &str) -> String {
    let d = temp_dir(name);
    let p = d.join("bad.toml");
    std::fs::write(&p, text).unwrap();
    Scene::load(&p).unwrap_err().to_string()
}

const CAMERA: &str =
    "[camera]\nfrom = [0, -5, 1]\nat = [0, 0, 0]\nangle = 40\nresolution = [8, 8]\n";

fn assert_located(msg: &str, line: u32, key: &str) {
    assert!(
        msg.contains(&format!("bad.toml:{line}:")),
        "want line {line}: {msg}"
    );
    assert!(msg.contains(key), "want key {key}: {msg}");
}

#[test]
fn unknown_key_is_named_with_its_line() {
    let msg = error_of(
        "unknown",
        &format!(
            "{CAMERA}[material.m]\nshininess = 3\n[[object]]\nmaterial = \"m\"\nsphere = {{ centre = [0,0,0], radius = 1 }}\n"
        ),
    );
    assert_located(&msg, 7, "shininess");
}

#[test]
fn wrong_type_is_named_with_its_line() {
    let msg = error_of(
        "type",
        &format!(
            "{CAMERA}[material.m]\n[[object]]\nmaterial = \"m\"\nsphere = {{ centre = [0,0,0], radius = \"big\" }}\n"
        ),
    );
    assert_located(&msg, 9, "radius");
}

#[test]
fn missing_file_is_named_with_its_line_and_key() {
    let msg = error_of(
        "path",
        &format!(
            "{CAMERA}[material.m]\n[[object]]\nmaterial = \"m\"\nmesh = {{ file = \"nowhere.obj\" }}\n"
        ),
    );
    assert_located(&msg, 9, "object[0].mesh.file");
    assert!(msg.contains("nowhere.obj: no such file"), "{msg}");
    // A directory or a device is named for what it is.
    let msg = error_of(
        "path-dir",
        &format!("{CAMERA}[material.m]\n[[object]]\nmaterial = \"m\"\nmesh = {{ file = \".\" }}\n"),
    );
    assert_located(&msg, 9, "object[0].mesh.file");
    assert!(msg.contains(": is a directory, not a file"), "{msg}");
    let msg = error_of(
        "path-dev",
        &format!(
            "{CAMERA}[material.m]\n[[object]]\nmaterial = \"m\"\nmesh = {{ file = \"/dev/null\" }}\n"
        ),
    );
    assert!(msg.contains("/dev/null: is not a regular file"), "{msg}");
}

#[test]
fn huge_volume_is_refused_before_allocating() {
    let msg = error_of(
        "huge",
        &format!(
            "{CAMERA}[material.m]\n[volume.v]\nmetaballs = {{ dims = [60000, 60000, 60000], min = [0,0,0], max = [1,1,1], balls = [] }}\niso = 1\n[[object]]\nmaterial = \"m\"\nvolume = \"v\"\n"
        ),
    );
    assert_located(&msg, 8, "volume.v.metaballs");
}

#[test]
fn metaballs_box_must_have_max_above_min() {
    let msg = error_of(
        "metaballs-box",
        &format!(
            "{CAMERA}[material.m]\n[volume.v]\nmetaballs = {{ dims = [8, 8, 8], min = [1,1,1], max = [-1,1,2], balls = [] }}\niso = 1\n[[object]]\nmaterial = \"m\"\nvolume = \"v\"\n"
        ),
    );
    assert_located(&msg, 8, "volume.v.metaballs.max");
    assert!(msg.contains("max above min on every axis"), "{msg}");
}

#[test]
fn unknown_material_and_solid_are_named() {
    let msg = error_of(
        "material",
        &format!(
            "{CAMERA}[[object]]\nmaterial = \"nope\"\nsphere = {{ centre = [0,0,0], radius = 1 }}\n"
        ),
    );
    assert_located(&msg, 7, "object[0].material");
    assert!(msg.contains("no [material.nope]"), "{msg}");
    let msg = error_of(
        "solid",
        &format!(
            "{CAMERA}[material.m]\n[[object]]\nmaterial = \"m\"\ncsg = {{ union = [\"a\", \"b\"] }}\n"
        ),
    );
    assert_located(&msg, 9, "object[0].csg");
    assert!(msg.contains("no [solid.a]"), "{msg}");
}

#[test]
fn two_shapes_in_one_object_are_refused() {
    let msg = error_of(
        "two",
        &format!(
            "{CAMERA}[material.m]\n[[object]]\nmaterial = \"m\"\nsphere = {{ centre = [0,0,0], radius = 1 }}\nbox = {{ min = [0,0,0], max = [1,1,1] }}\n"
        ),
    );
    assert_located(&msg, 7, "exactly one of");
}

/// The scenes that need `../shared/data`: parse them all, build the
/// teapot's at a small raster (the head's volume is read, not built: it
/// takes seconds).
#[test]
fn shared_data_scenes_parse() {
    if rrt_tests::shared_data().is_none() {
        eprintln!("skipped: ../shared/data is absent");
        return;
    }
    for f in [
        "fig1-head.toml",
        "fig2-teapot.toml",
        "fig4-balls3.toml",
        "fig5-balls2.toml",
    ] {
        let s = Scene::load(scenes_dir().join(f)).unwrap_or_else(|e| panic!("{f}: {e}"));
        rrt_host::check::check_scene(&s).unwrap();
    }
    let s = Scene::load(scenes_dir().join("fig4-balls3.toml")).unwrap();
    assert_eq!(s.spheres.len(), 820);
    let s = Scene::load(scenes_dir().join("fig2-teapot.toml")).unwrap();
    assert_eq!(s.polygons.len(), 992 + 3);
    let vs = built(&s, 48);
    assert!(records(&vs).iter().any(|r| r.1 < 992));
}

#[test]
fn scene_files_are_not_read_outside_the_options() {
    let opts = rrt_host::scene::toml::Options {
        read_files: false,
        ..Default::default()
    };
    let e = rrt_host::scene::toml::parse(
        "x.toml",
        &format!("{CAMERA}[[object]]\nnff = \"a.nff\"\n"),
        Path::new("."),
        &opts,
    )
    .unwrap_err()
    .to_string();
    assert!(e.starts_with("x.toml:7:"), "{e}");
}

/// Exact shadows keep the shadows of objects without exact geometry: a
/// metaball volume over a floor, lit from one side, shadows the floor
/// beside it in the verified and the exact mode.
#[test]
fn exact_shadows_keep_volume_shadows() {
    use rrt_host::render::camera::Camera;
    use rrt_host::render::{RenderOptions, render};
    use rrt_host::trace::{Mode, TraceOptions, Tracer};
    let d = temp_dir("exact-volume");
    let p = d.join("s.toml");
    std::fs::write(
        &p,
        r#"
[camera]
from = [0, 0, 10]
at = [0, 0, 0]
up = [0, 1, 0]
angle = 40
resolution = [33, 33]

[[light]]
position = [10, 0, 20]

[material.grey]
colour = [0.8, 0.8, 0.8]

[volume.blob]
metaballs = { dims = [24, 24, 24], min = [-1, -1, -1], max = [1, 1, 1], balls = [[0, 0, 0, 1.0, 1.0]] }
iso = 0.3
translate = [0, 0, 2]

[[object]]
material = "grey"
polygon = [[-4, -4, 0], [4, -4, 0], [4, 4, 0], [-4, 4, 0]]

[[object]]
material = "grey"
volume = "blob"
"#,
    )
    .unwrap();
    let scene = Scene::load(&p).unwrap();
    let vs = built(&scene, 128);
    let camera = Camera::new(&scene.view, 33, 33).unwrap();
    let draw = |exact_shadows: bool| {
        let opts = TraceOptions {
            mode: if exact_shadows {
                Mode::Exact
            } else {
                Mode::Verified
            },
            ..TraceOptions::default()
        };
        let tracer = Tracer::new(&vs, opts).unwrap();
        let (img, _, _) = render(
            &tracer,
            &camera,
            &RenderOptions {
                supersample: 1,
                threads: 1,
                alpha: false,
            },
            &ProgressBar::hidden(),
        )
        .unwrap();
        img
    };
    for exact in [false, true] {
        let img = draw(exact);
        let px = |x: usize, y: usize| img.rgb[3 * (y * 33 + x)];
        // The blob (radius about 0.58 at height 2) covers the image's
        // centre, about 3 pixels each way. Its shadow from the light at
        // (10, 0, 20) falls around (−1.1, 0, 0), 5 pixels from the centre
        // towards −x; the floor as far the other way is lit. Which image
        // side −x is does not matter here.
        let (a, b) = (px(11, 16), px(21, 16));
        let (dark, lit) = (a.min(b), a.max(b));
        assert!(lit > 40, "exact {exact}: floor not lit ({a}, {b})");
        // In shadow only the ambient term is left (0.5 · 0.8 of 255 = 102).
        assert!(
            dark <= 104 && dark + 40 < lit,
            "exact {exact}: no volume shadow ({a}, {b})"
        );
    }
}

#[test]
fn a_torus_is_verified_against_the_exact_torus_and_saved_as_one() {
    const TORUS: &str = r#"
[camera]
from = [0, -6, 4]
at = [0, 0, 0]
angle = 40
resolution = [8, 8]

[material.m]

[[object]]
material = "m"
torus = { centre = [0, 0, 0], axis = [0, 0, 1], major = 1.5, minor = 0.5 }
"#;
    let d = temp_dir("torus");
    std::fs::write(d.join("torus.toml"), TORUS).unwrap();
    let scene = Scene::load(d.join("torus.toml")).unwrap();
    let vs = built(&scene, 64);
    let Shape::Torus(t) = vs.objects[0].shape else {
        panic!("torus object {:?}", vs.objects[0])
    };
    // Every voxel of the torus: the continuous ray from above through its
    // centre verifies on the exact surface, (|p_xy| − R)² + z² = r².
    let mut hits = 0;
    for (v, rec) in vs.store().unwrap().iter() {
        assert_eq!(rec.object, 0);
        let centre = vs
            .frame
            .raster_to_world(DVec3::from(v.map(f64::from)) + 0.5);
        let ray = Ray::new(centre + DVec3::Z * (2.0 * vs.frame.voxel_size), -DVec3::Z);
        if let Verdict::Hit(h) = verify(&vs.frame, &vs.objects[0], &ray, v, 0.0) {
            let p = ray.at(h.t);
            let ring = DVec3::new(p.x, p.y, 0.0).length() - t.major;
            assert!((ring.hypot(p.z) - t.minor).abs() < 1e-9, "{p}");
            hits += 1;
        }
    }
    assert!(hits > 100, "{hits} verified hits");
    // Saved and loaded, the world object is the same torus.
    let rrt = d.join("torus.rrt");
    rasterfile::save(&vs, &rrt).unwrap();
    assert_eq!(rasterfile::load(&rrt).unwrap().objects, vs.objects);
}

/// `msg` names `line:column` and the key path `key`.
fn assert_at(msg: &str, line: u32, column: u32, key: &str) {
    assert!(
        msg.contains(&format!("bad.toml:{line}:{column}: {key}: ")),
        "want {line}:{column} {key}: {msg}"
    );
}

#[test]
fn a_bad_value_is_located_at_itself_with_its_key_path() {
    let sphere = |r: &str| {
        format!(
            "[[object]]\nmaterial = \"m\"\nsphere = {{ centre = [0,0,0], radius = 1 }}\n[[object]]\nmaterial = \"m\"\n\nsphere = {{ centre = [0,0,0], radius = {r} }}\n"
        )
    };
    // A primitive's value in an inline table, in the second object.
    let msg = error_of("radius", &format!("{CAMERA}[material.m]\n{}", sphere("-2")));
    assert_at(&msg, 13, 39, "object[1].sphere.radius");
    assert!(msg.contains("expected a number > 0"), "{msg}");
    // A camera value.
    let msg = error_of(
        "resolution",
        &format!(
            "[camera]\nfrom = [0, -5, 1]\nat = [0, 0, 0]\nangle = 40\nresolution = [0, 0]\n[material.m]\n{}",
            sphere("1")
        ),
    );
    assert_at(&msg, 5, 14, "camera.resolution");
    let msg = error_of(
        "angle",
        &format!(
            "[camera]\nfrom = [0, -5, 1]\nat = [0, 0, 0]\n  angle = 190\nresolution = [8, 8]\n[material.m]\n{}",
            sphere("1")
        ),
    );
    assert_at(&msg, 4, 11, "camera.angle");
    // An `up` parallel to the view: at itself when given, named as the
    // default (at the camera table) when not.
    let view = |up: &str| {
        format!(
            "[camera]\nfrom = [0, 0, 5]\nat = [0, 0, 0]\nangle = 40\nresolution = [8, 8]\n{up}[material.m]\n{}",
            sphere("1")
        )
    };
    let msg = error_of("up", &view("up = [0, 0, -2]\n"));
    assert_at(&msg, 6, 6, "camera.up");
    assert!(
        msg.ends_with("parallel to the view direction (camera.at − camera.from)"),
        "{msg}"
    );
    let msg = error_of("up", &view(""));
    assert_at(&msg, 1, 1, "camera.up");
    assert!(msg.contains("the default [0, 0, 1] is parallel"), "{msg}");
    // A negative hither, as NFF refuses it.
    let msg = error_of(
        "hither",
        &format!(
            "[camera]\nfrom = [0, -5, 1]\nat = [0, 0, 0]\nangle = 40\nhither = -1\nresolution = [8, 8]\n[material.m]\n{}",
            sphere("1")
        ),
    );
    assert_at(&msg, 5, 10, "camera.hither");
    assert!(msg.contains("expected a distance ≥ 0"), "{msg}");
    // A material's value.
    let msg = error_of(
        "ks",
        &format!("{CAMERA}[material.m]\nkd = 0.5\nks = -1\n{}", sphere("1")),
    );
    assert_at(&msg, 8, 6, "material.m.ks");
    // A light's value, in the second light.
    let msg = error_of(
        "light",
        &format!(
            "{CAMERA}[[light]]\nposition = [1, 1, 1]\n[[light]]\nposition = [1, nan, 1]\n[material.m]\n{}",
            sphere("1")
        ),
    );
    assert_at(&msg, 9, 12, "light[1].position");
    // A top-level value.
    let msg = error_of(
        "background",
        &format!(
            "background = [2, 0, 0]\n{CAMERA}[material.m]\n{}",
            sphere("1")
        ),
    );
    assert_at(&msg, 1, 14, "background");
}

#[test]
fn an_unknown_key_inside_an_inline_table_names_its_table() {
    let msg = error_of(
        "inline",
        &format!(
            "{CAMERA}[material.m]\n[[object]]\nmaterial = \"m\"\nbox = {{ min = [0,0,0], scale = 2 }}\n"
        ),
    );
    assert_at(&msg, 9, 24, "object[0].box.scale");
    assert!(msg.contains("unknown field `scale`"), "{msg}");
    // A wrong type two inline tables deep.
    let msg = error_of(
        "deep",
        &format!(
            "{CAMERA}[material.m]\ntexture = {{ checker = {{ size = \"big\", colours = [[0,0,0],[1,1,1]] }} }}\n[[object]]\nmaterial = \"m\"\nsphere = {{ centre = [0,0,0], radius = 1 }}\n"
        ),
    );
    assert!(
        msg.contains("bad.toml:7:") && msg.contains("material.m.texture.checker.size"),
        "{msg}"
    );
}

#[test]
fn an_opacity_ramp_alone_classifies_a_volume() {
    let volume = |class: &str| {
        format!(
            "{CAMERA}[material.m]\n[volume.v]\nmetaballs = {{ dims = [8, 8, 8], min = [-1, -1, -1], max = [1, 1, 1], balls = [[0, 0, 0, 1.0, 1.0]] }}\n{class}\n[[object]]\nmaterial = \"m\"\nvolume = \"v\"\n"
        )
    };
    let d = temp_dir("opacity");
    let p = d.join("ok.toml");
    std::fs::write(&p, volume("opacity = [[0.2, 0], [0.6, 1]]")).unwrap();
    let scene = Scene::load(&p).unwrap();
    let c = &scene.volumes[0].data.classifier;
    for (v, opaque) in [
        (-5.0, false),
        (0.1, false),
        (0.39, false),
        (0.41, true),
        (3.0, true),
    ] {
        assert_eq!(c.is_opaque(v), opaque, "{v}");
    }
    let msg = error_of("noiso", &volume("colours = [[0, 1, 1, 1], [1, 0, 0, 0]]"));
    assert!(
        msg.contains("bad.toml:") && msg.contains("volume.v.iso: missing"),
        "{msg}"
    );
}

/// A volume has no exact normal: its hits are shaded with the stored
/// normals interpolated at the hit point, so that a sampled sphere is not
/// faceted. Against the true sphere's normal, over a row of rays a
/// fiftieth of a voxel apart, the interpolated normals are closer than
/// each hit voxel's own, and jump between neighbouring rays less often:
/// no longer at every voxel edge, only where the hit point itself jumps
/// (the ray's first voxel changing layer).
#[test]
fn volume_hits_have_interpolated_normals() {
    use rrt_host::trace::{RayStats, TraceOptions, Tracer};
    use rrt_host::world::Ray;
    let d = temp_dir("smooth-volume");
    let p = d.join("s.toml");
    std::fs::write(
        &p,
        r#"
[camera]
from = [0, 0, 10]
at = [0, 0, 0]
up = [0, 1, 0]
angle = 30
resolution = [16, 16]

[[light]]
position = [10, 0, 20]

[material.grey]
colour = [0.8, 0.8, 0.8]

[volume.blob]
metaballs = { dims = [40, 40, 40], min = [-1.5, -1.5, -1.5], max = [1.5, 1.5, 1.5], balls = [[0, 0, 0, 1.0, 1.0]] }
iso = 0.3

[[object]]
material = "grey"
volume = "blob"
"#,
    )
    .unwrap();
    let scene = Scene::load(&p).unwrap();
    let vs = built(&scene, 48);
    let tracer = Tracer::new(&vs, TraceOptions::default()).unwrap();
    let store = vs.store().unwrap();
    let mut stats = RayStats::default();
    let mut err = [Vec::new(), Vec::new()];
    let mut turns = [Vec::new(), Vec::new()];
    let mut prev: Option<[DVec3; 2]> = None;
    for i in 0..400 {
        let x = -0.6 + 1.2 * f64::from(i) / 400.0;
        let ray = Ray::new(DVec3::new(x, 0.13, 10.0), DVec3::NEG_Z);
        let Some(h) = tracer.hit(&ray, &mut stats) else {
            prev = None;
            continue;
        };
        let truth = h.point.normalize();
        let rec = store.get_voxel(h.voxel).unwrap();
        let voxel = DVec3::from(rrt_core::voxel::unfold(rec.normal).map(|c| c as f64)).normalize();
        let normals = [h.normal, voxel];
        for k in 0..2 {
            err[k].push(normals[k].angle_between(truth).to_degrees());
            if let Some(q) = prev {
                turns[k].push(q[k].angle_between(normals[k]).to_degrees());
            }
        }
        prev = Some(normals);
    }
    assert!(err[0].len() > 300, "{} hits", err[0].len());
    let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
    // Facet edges: neighbouring rays whose normals differ by over 2°.
    let jumps = |v: &[f64]| v.iter().filter(|&&t| t > 2.0).count();
    let (e_smooth, e_voxel) = (mean(&err[0]), mean(&err[1]));
    let (j_smooth, j_voxel) = (jumps(&turns[0]), jumps(&turns[1]));
    eprintln!(
        "mean error: interpolated {e_smooth:.2}°, voxel {e_voxel:.2}°; \
         jumps over 2° between neighbouring rays: {j_smooth}, {j_voxel}"
    );
    assert!(e_smooth < 0.6 * e_voxel, "{e_smooth} vs {e_voxel}");
    assert!(j_smooth < j_voxel, "{j_smooth} vs {j_voxel}");
}

/// A scene whose second object's shape is `shape`, with `extra` after it
/// (more tables: lights, materials, solids, volumes).
fn second_object(shape: &str, extra: &str) -> String {
    format!(
        "{CAMERA}[[light]]\nposition = [1, 1, 1]\n[material.m]\n[[object]]\nmaterial = \"m\"\nsphere = {{ centre = [0,0,0], radius = 1 }}\n[[object]]\nmaterial = \"m\"\n{shape}\n{extra}"
    )
}

/// Every kind of bad value is reported at the value itself (the line and
/// column of `needle`, its first occurrence in the scene) with its full key
/// path, inside inline tables and arrays too.
#[test]
fn every_bad_value_is_located_at_itself() {
    let metaballs = "[volume.v]\nmetaballs = { dims = [8, 8, 8], min = [-1, -1, -1], max = [1, 1, 1], balls = [[0, 0, 0, 1, 1]] }\n";
    let volume = |class: &str| second_object("volume = \"v\"", &format!("{metaballs}{class}\n"));
    let solids = "[solid.a]\nsphere = { centre = [0,0,0], radius = 1 }\n[solid.b]\nbox = { min = [0,0,0], max = [1,1,1] }\n";
    let texture = |t: &str| {
        second_object(
            "sphere = { centre = [3,0,0], radius = 1 }",
            &format!("[material.t]\ntexture = {{ {t} }}\n"),
        )
    };
    let raw = |r: &str| {
        volume("").replace(metaballs, &format!("[volume.v]\nraw = {{ {r} }}\n")) + "iso = 1\n"
    };
    let cases: Vec<(&str, String, &str, &str, &str)> = vec![
        // (name, scene, needle, key path, message)
        (
            "light colour",
            second_object(
                "sphere = { centre = [3,0,0], radius = 1 }",
                "[[light]]\nposition = [2, 2, 2]\ncolour = [1, -1, 1]\n",
            ),
            "[1, -1, 1]",
            "light[1].colour",
            "expected channels ≥ 0",
        ),
        (
            "far sphere",
            second_object("sphere = { centre = [0,0,0], radius = 3e60 }", ""),
            "3e60",
            "object[1].sphere.radius",
            "expected a number > 0, at most 1e60",
        ),
        (
            "far vertex",
            second_object("polygon = [[0,0,0], [1,0,0], [0,1e61,0]]", ""),
            "[0,1e61,0]",
            "object[1].polygon[2]",
            "expected finite numbers within ±1e60",
        ),
        (
            "polygon vertex",
            second_object("polygon = [[0,0,0], [1,0,0], [0,nan,0]]", ""),
            "[0,nan,0]",
            "object[1].polygon[2]",
            "expected finite numbers within ±1e60",
        ),
        (
            "box",
            second_object("box = { min = [0,0,0], max = [1,-1,1] }", ""),
            "[1,-1,1]",
            "object[1].box.max",
            "expected min < max",
        ),
        (
            "cone apex",
            second_object(
                "cone = { base = [2,2,2], base_radius = 1, apex = [2, 2, 2], apex_radius = 0.5 }",
                "",
            ),
            "[2, 2, 2]",
            "object[1].cone.apex",
            "equals the base",
        ),
        (
            "cone radius",
            second_object(
                "cone = { base = [0,0,0], base_radius = -1, apex = [0,0,1], apex_radius = 0.5 }",
                "",
            ),
            "-1",
            "object[1].cone.base_radius",
            "expected a number ≥ 0",
        ),
        (
            "torus",
            second_object("torus = { centre = [0,0,0], major = 1, minor = -2 }", ""),
            "-2",
            "object[1].torus.minor",
            "expected a number > 0",
        ),
        (
            "transform scale",
            second_object(
                "polygon = [[0,0,0], [1,0,0], [0,1,0]]\ntransform = { scale = 0 }",
                "",
            ),
            "0 }",
            "object[1].transform.scale",
            "expected a number > 0",
        ),
        (
            "transform angle",
            second_object(
                "polygon = [[0,0,0], [1,0,0], [0,1,0]]\ntransform = { rotate_y = inf }",
                "",
            ),
            "inf",
            "object[1].transform.rotate_y",
            "expected a finite angle",
        ),
        (
            "csg leaf",
            second_object(
                "csg = { difference = [\"a\", { union = [\"b\", \"zz\"] }] }",
                solids,
            ),
            "\"zz\"",
            "object[1].csg.difference[1].union[1]",
            "no [solid.zz] in this scene",
        ),
        (
            "csg operands",
            second_object("csg = { union = [\"a\"] }", solids),
            "[\"a\"]",
            "object[1].csg.union",
            "2 or more operands",
        ),
        (
            "csg too many operands",
            second_object(
                &format!("csg = {{ union = [{}] }}", vec!["\"a\""; 65].join(", ")),
                solids,
            ),
            "[\"a\", \"a\"",
            "object[1].csg.union",
            "65 operands: a CSG tree holds at most 64 nodes",
        ),
        (
            "csg operand type",
            second_object(
                "csg = { difference = [\"a\", { union = [\"b\", 7] }] }",
                solids,
            ),
            "7",
            "object[1].csg.difference[1].union[1]",
            "invalid type: integer `7`, expected a solid's name or an operation",
        ),
        (
            "csg nested key",
            second_object(
                "csg = { difference = [\"a\", { unon = [\"b\", \"a\"] }] }",
                solids,
            ),
            "unon",
            "object[1].csg.difference[1].unon",
            "unknown field `unon`, expected one of `union`, `intersection`, `difference`",
        ),
        (
            "solid",
            second_object(
                "csg = { union = [\"a\", \"b\"] }",
                &solids.replace("max = [1,1,1]", "max = [1,1,-1]"),
            ),
            "[1,1,-1]",
            "solid.b.box.max",
            "expected min < max",
        ),
        (
            "checker",
            texture("checker = { size = -1, colours = [[1,2,3],[4,5,6]] }"),
            "-1",
            "material.t.texture.checker.size",
            "expected a number > 0",
        ),
        (
            "marble",
            texture(
                "marble = { period = 1, direction = [0.0, 0, 0], colours = [[1,2,3],[4,5,6]] }",
            ),
            "[0.0, 0, 0]",
            "material.t.texture.marble.direction",
            "expected a non-zero vector",
        ),
        (
            "wood",
            texture("wood = { period = 1, octaves = 17, colours = [[1,2,3],[4,5,6]] }"),
            "17",
            "material.t.texture.wood.octaves",
            "expected 1 to 16",
        ),
        (
            "image wrap",
            texture(
                "image = { file = \"x.png\", wrap = \"tile\", planar = { origin = [0,0,0], u = [1,0,0], v = [0,1,0] } }",
            ),
            "\"tile\"",
            "material.t.texture.image.wrap",
            "expected repeat, mirror or clamp",
        ),
        (
            "metaball",
            volume("iso = 0.5").replace("[[0, 0, 0, 1, 1]]", "[[0, 0, 0, 1, 1], [0, 0, 0, -1, 1]]"),
            "[0, 0, 0, -1, 1]",
            "volume.v.metaballs.balls[1]",
            "radius > 0",
        ),
        (
            "opacity",
            volume("opacity = [[0, 0], [1, 2]]"),
            "[1, 2]",
            "volume.v.opacity[1]",
            "alpha in [0, 1]",
        ),
        (
            "opacity order",
            volume("render = \"direct\"\nopacity = [[0, 0], [0.5, 0.1], [0.5, 0.2]]"),
            "0.5, 0.2",
            "volume.v.opacity[2][0]",
            "increase along the ramp",
        ),
        (
            "opacity range",
            volume("render = \"direct\"\nopacity = [[0, 0], [0.5, -0.1]]"),
            "[0.5, -0.1]",
            "volume.v.opacity[1]",
            "alpha in [0, 1]",
        ),
        (
            "render",
            volume("opacity = [[0, 0], [1, 0.5]]\nrender = \"cloud\""),
            "\"cloud\"",
            "volume.v.render",
            "expected \"iso\" or \"direct\"",
        ),
        (
            "render without a transfer function",
            volume("iso = 0.5\nrender = \"direct\""),
            "\"direct\"",
            "volume.v.render",
            "needs a transfer function",
        ),
        (
            "direct CSG leaf",
            second_object(
                "csg = { difference = [\"a\", \"b\"] }",
                &format!(
                    "{metaballs}opacity = [[0, 0], [1, 0.5]]\n[solid.a]\nvolume = \"v\"\n[solid.b]\nbox = {{ min = [0,0,0], max = [1,1,1] }}\n"
                ),
            ),
            "\"v\"\n[solid.b]",
            "solid.a.volume",
            "a CSG leaf takes an iso-surface volume",
        ),
        (
            "colours",
            volume("iso = 0.5\ncolours = [[1, 0, 0, 0], [0.5, 1, 1, 1]]"),
            "0.5, 1",
            "volume.v.colours[1][0]",
            "increase along the ramp",
        ),
        (
            "fit",
            volume("iso = 0.5\nfit = { min = [0, 0, 0], max = [1, 1, 0] }"),
            "[1, 1, 0]",
            "volume.v.fit.max",
            "expected min < max",
        ),
        (
            "scale",
            volume("iso = 0.5\nscale = -1"),
            "-1\n",
            "volume.v.scale",
            "expected a number > 0",
        ),
        (
            "tiny scale",
            volume("iso = 0.5\nscale = 1e-300"),
            "1e-300\n",
            "volume.v.scale",
            "not finite or not invertible",
        ),
        (
            "raw dims",
            raw("file = \"x.raw\", dims = [0, 2, 2], type = \"u8\""),
            "[0, 2, 2]",
            "volume.v.raw.dims",
            "expected 1 to 65536",
        ),
        (
            "raw spacing",
            raw("file = \"x.raw\", dims = [2, 2, 2], type = \"u8\", spacing = [1, 1e-300, 1]"),
            "[1, 1e-300, 1]",
            "volume.v.raw.spacing",
            "expected numbers from 1e-12 to 1e60",
        ),
        (
            "raw type",
            raw("file = \"x.raw\", dims = [2, 2, 2], type = \"double\""),
            "\"double\"",
            "volume.v.raw.type",
            "float (float32, f32)",
        ),
    ];
    for (name, text, needle, key, msg) in cases {
        let at = text
            .find(needle)
            .unwrap_or_else(|| panic!("{name}: no {needle:?}"));
        let line = text[..at].matches('\n').count() + 1;
        let column = at - text[..at].rfind('\n').map_or(0, |i| i + 1) + 1;
        let err = error_of(&format!("at-{}", name.replace(' ', "-")), &text);
        assert!(
            err.contains(&format!("bad.toml:{line}:{column}: {key}: ")),
            "{name}: want {line}:{column} {key}: {err}"
        );
        assert!(err.contains(msg), "{name}: want {msg:?}: {err}");
    }
}

/// A directory named like a TOML scene is refused as a directory, not
/// as an NFF file.
#[test]
fn a_directory_is_not_called_an_nff_file() {
    let scratch = temp_dir("dir-scene");
    let d = scratch.join("scene.toml");
    std::fs::create_dir_all(&d).unwrap();
    let msg = Scene::load(&d).unwrap_err().to_string();
    assert_eq!(
        msg,
        format!("{}: is a directory, not a TOML scene", d.display())
    );
}

/// The files a TOML scene refers to are not scenes: given as one, each is
/// refused with the TOML that draws it, not read as NFF (an OBJ mesh's
/// `v x y z` lines read as a broken NFF view).
#[test]
fn meshes_models_and_volumes_are_not_read_as_nff() {
    let d = temp_dir("not-a-scene");
    let cases = [
        (
            "teapot.obj",
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
            "an OBJ mesh, not a scene: a TOML scene draws it with [[object]] mesh = { file = \"teapot.obj\" }",
        ),
        (
            "teapot.BPT",
            "1\n3 3\n",
            "a Bézier patch file, not a scene: a TOML scene draws it with [[object]] bezier = { file = \"teapot.BPT\" }",
        ),
        (
            "m.vox",
            "VOX ",
            "a MagicaVoxel model, not a scene: a TOML scene draws it with [[object]] vox = { file = \"m.vox\" }",
        ),
        (
            "h.nrrd",
            "NRRD0004\n",
            "a NRRD volume, not a scene: a TOML scene draws it with [volume.NAME] file = \"h.nrrd\", iso or opacity, and [[object]] volume = \"NAME\"",
        ),
        (
            "e.raw",
            "",
            "raw volume samples, not a scene: a TOML scene draws it with [volume.NAME] raw = { file = \"e.raw\", dims, type }, iso or opacity, and [[object]] volume = \"NAME\"",
        ),
    ];
    for (name, text, want) in cases {
        let p = d.join(name);
        std::fs::write(&p, text).unwrap();
        let msg = Scene::load(&p).unwrap_err().to_string();
        assert_eq!(msg, format!("{}: {want}", p.display()));
    }
    // Included as an NFF file, too.
    let p = d.join("inc.toml");
    std::fs::write(&p, format!("{CAMERA}[[object]]\nnff = \"teapot.obj\"\n")).unwrap();
    let msg = Scene::load(&p).unwrap_err().to_string();
    assert!(
        msg.ends_with(&format!(
            "object[0].nff: {}: an OBJ mesh, not an NFF scene: draw it with [[object]] mesh = {{ file = \"teapot.obj\" }}",
            d.join("teapot.obj").display()
        )),
        "{msg}"
    );
    // Other names are still NFF.
    let p = d.join("scene.txt");
    std::fs::write(&p, "v 0 0 0\n").unwrap();
    let msg = Scene::load(&p).unwrap_err().to_string();
    assert!(
        msg.contains("scene.txt:1:3: view: expected end of line"),
        "{msg}"
    );
}

/// A capped cone or CSG solid too thin for the raster's fixed point is
/// refused at its own definition (the object's shape key, or the tree's
/// `[solid.NAME]`) as a degenerate solid, not as a broken raster's "CSG
/// leaf 0".
#[test]
fn degenerate_solids_are_named_at_their_definition() {
    let d = temp_dir("degenerate-solid");
    let cone = "cone = { base = [0,0,0], base_radius = 1, apex = [0,0,1e-300], apex_radius = 1, capped = true }";
    let p = d.join("cone.toml");
    let text = second_object(cone, "");
    std::fs::write(&p, &text).unwrap();
    let line = text.lines().position(|l| l == cone).unwrap() + 1;
    let scene = Scene::load(&p).unwrap();
    let e = build(&scene, &BuildOptions::new(64), &ProgressBar::hidden())
        .err()
        .unwrap()
        .to_string();
    // At the `cone` key's value: column 8, after `cone = `.
    assert_eq!(
        e,
        format!(
            "{}:{line}:8: capped cone: too thin or too small to have an inside at the raster's precision (a degenerate solid)",
            p.display()
        )
    );
    // A leaf of a tree: at its shape's value in its [solid.NAME].
    let leaf = "cone = { base = [0,0,0], base_radius = 1, apex = [0,0,1e-300], apex_radius = 1 }";
    let solids =
        format!("[solid.a]\nsphere = {{ centre = [0,0,0], radius = 1 }}\n[solid.b]\n{leaf}\n");
    let p = d.join("tree.toml");
    let text = second_object("csg = { union = [\"a\", \"b\"] }", &solids);
    std::fs::write(&p, &text).unwrap();
    let line = text.lines().position(|l| l == leaf).unwrap() + 1;
    let scene = Scene::load(&p).unwrap();
    let e = build(&scene, &BuildOptions::new(64), &ProgressBar::hidden())
        .err()
        .unwrap()
        .to_string();
    assert!(
        e.starts_with(&format!("{}:{line}:8: capped cone: too thin", p.display())),
        "{e}"
    );
}

/// Every `[solid.NAME]` is checked, whether a tree uses it or not: a bad
/// value, an unknown material or volume, a solid without a shape.
#[test]
fn unused_solids_are_checked() {
    let cases = [
        (
            "cone = { base = [0,0,0], base_radius = nan, apex = [0,0,1], apex_radius = 1 }",
            "solid.u.cone.base_radius",
        ),
        (
            "material = \"nosuch\"\nsphere = { centre = [0,0,0], radius = 1 }",
            "no [material.nosuch]",
        ),
        ("volume = \"nosuch\"", "no [volume.nosuch]"),
        (
            "",
            "expected exactly one of sphere, box, cone, torus, volume",
        ),
    ];
    for (body, want) in cases {
        let msg = error_of("unused-solid", &one_object(&format!("[solid.u]\n{body}\n")));
        assert!(
            msg.contains(want) && msg.contains("solid.u"),
            "{body}: {msg}"
        );
    }
    // A solid without a material is fine: a tree gives it one.
    let d = temp_dir("unused-solid-ok");
    let p = d.join("ok.toml");
    std::fs::write(
        &p,
        one_object("[solid.u]\nsphere = { centre = [0,0,0], radius = 1 }\n"),
    )
    .unwrap();
    Scene::load(&p).unwrap();
}

/// A scene of one sphere, then `extra`.
fn one_object(extra: &str) -> String {
    format!(
        "{CAMERA}[[light]]\nposition = [1, 1, 1]\n[material.m]\n[[object]]\nmaterial = \"m\"\nsphere = {{ centre = [0,0,0], radius = 1 }}\n{extra}"
    )
}

/// A marble's `origin` moves its pattern; a non-finite one is refused at
/// its key.
#[test]
fn marble_origin_moves_the_pattern() {
    let marble = |origin: &str| {
        format!(
            "{CAMERA}[[light]]\nposition = [1, -4, 3]\n[material.m.texture.marble]\nperiod = 0.5\ncolours = [[20, 20, 60], [240, 240, 230]]\n{origin}\n[[object]]\nmaterial = \"m\"\nsphere = {{ centre = [0,0,0], radius = 1 }}\n"
        )
    };
    let image = |origin: &str| {
        let d = temp_dir("marble-origin");
        let p = d.join("m.toml");
        std::fs::write(&p, marble(origin)).unwrap();
        let scene = Scene::load(&p).unwrap();
        let (vs, _) = build(&scene, &BuildOptions::new(24), &ProgressBar::hidden()).unwrap();
        records(&vs)
    };
    let at_zero = image("");
    assert_eq!(image("origin = [0, 0, 0]"), at_zero);
    assert_ne!(image("origin = [0.1, 0.2, 0.3]"), at_zero);
    let msg = error_of("marble-origin-nan", &marble("origin = [nan, 0, 0]"));
    assert!(msg.contains("material.m.texture.marble.origin"), "{msg}");
}

/// An error of a file a scene refers to keeps its cause: the reason a
/// data file cannot be read, the decoder's reason an image is refused.
#[test]
fn file_errors_keep_their_cause() {
    let d = temp_dir("causes");
    std::fs::write(
        d.join("v.nhdr"),
        "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 2 2 2\nencoding: raw\ndata file: gone.raw\n\n",
    )
    .unwrap();
    let p = d.join("vol.toml");
    std::fs::write(
        &p,
        second_object("volume = \"v\"", "[volume.v]\nfile = \"v.nhdr\"\niso = 1\n"),
    )
    .unwrap();
    let msg = Scene::load(&p).unwrap_err().to_string();
    assert!(
        msg.contains(&format!(
            "volume.v.file: cannot read {}: ",
            d.join("gone.raw").display()
        )) && msg.contains("No such file"),
        "{msg}"
    );
    // A PNG cut in half.
    let mut png = Vec::new();
    image::RgbImage::from_pixel(16, 16, image::Rgb([9, 9, 9]))
        .write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png)
        .unwrap();
    std::fs::write(d.join("half.png"), &png[..png.len() / 2]).unwrap();
    let p = d.join("tex.toml");
    let texture = "[material.t]\n[material.t.texture.image]\nfile = \"half.png\"\nplanar = { origin = [0,0,0], u = [1,0,0], v = [0,1,0] }\n";
    std::fs::write(
        &p,
        second_object("sphere = { centre = [0,0,0], radius = 1 }", texture),
    )
    .unwrap();
    let msg = Scene::load(&p).unwrap_err().to_string();
    let shown = format!(
        "{}: cannot decode the image: ",
        d.join("half.png").display()
    );
    assert!(msg.contains(&shown) && !msg.ends_with(&shown), "{msg}");
}

/// A scene without objects says so in TOML's terms, not NFF's.
#[test]
fn a_scene_without_objects_names_the_object_table() {
    let msg = error_of(
        "no-objects",
        &format!("{CAMERA}[[light]]\nposition = [1, 1, 1]\n[material.m]\n"),
    );
    assert!(
        msg.ends_with("bad.toml: no objects: the scene has no [[object]] table"),
        "{msg}"
    );
}

/// toml's own errors name the table a key is missing from, and nothing
/// for a document without its `[camera]`.
#[test]
fn missing_keys_name_their_table() {
    let msg = error_of(
        "no-angle",
        &format!(
            "{}[material.m]\n[[object]]\nmaterial = \"m\"\nsphere = {{ centre = [0,0,0], radius = 1 }}\n",
            CAMERA.replace("angle = 40\n", "")
        ),
    );
    assert!(
        msg.contains("bad.toml:1:1: camera: missing field `angle`"),
        "{msg}"
    );
    let msg = error_of(
        "no-camera",
        "[[light]]\nposition = [1, 1, 1]\n[material.m]\n[[object]]\nmaterial = \"m\"\nsphere = { centre = [0,0,0], radius = 1 }\n",
    );
    assert!(
        msg.contains("bad.toml:1:1: missing field `camera`: every scene needs a [camera] table"),
        "{msg}"
    );
    let msg = error_of(
        "no-radius",
        &second_object("sphere = { centre = [0,0,0] }", ""),
    );
    assert!(
        msg.contains(": object[1].sphere: missing field `radius`"),
        "{msg}"
    );
}

/// A TOML polygon is cut as an NFF one: a non-convex outline into its
/// ears (each winding like the polygon, together its area), a convex one
/// into its fan.
#[test]
fn toml_polygons_are_cut_as_nff_polygons() {
    let d = temp_dir("toml-comb");
    let p = d.join("s.toml");
    std::fs::write(
        &p,
        r#"
[camera]
from = [2, 1.5, 10]
at = [2, 1.5, 0]
up = [0, 1, 0]
angle = 40
resolution = [16, 16]

[[light]]
position = [2, 1.5, 20]

[material.grey]
colour = [0.8, 0.8, 0.8]

[[object]]
material = "grey"
polygon = [[0, 0, 0], [4, 0, 0], [4, 3, 0], [3, 3, 0], [3, 1, 0], [2, 1, 0], [2, 3, 0], [0, 3, 0]]

[[object]]
material = "grey"
polygon = [[0, 0, 1], [4, 0, 1], [4, 3, 1], [0, 3, 1]]
"#,
    )
    .unwrap();
    let scene = Scene::load(&p).unwrap();
    let comb = &scene.polygons[0];
    assert!(comb.cut.is_some(), "the comb is cut into ears");
    let tris: Vec<_> = scene.polygon_triangles(comb).collect();
    assert_eq!(tris.len(), 6);
    let mut area = 0.0;
    for t in &tris {
        let [a, b, c] = t.vertices;
        let twice = (b - a).cross(c - a).z;
        assert!(twice > 0.0);
        area += twice / 2.0;
    }
    // 4 × 1 below the notch, 1 × 2 and 2 × 2 beside it.
    assert!((area - 10.0).abs() < 1e-12, "{area}");
    let quad = &scene.polygons[1];
    assert!(quad.cut.is_none(), "a convex polygon is its fan");
    assert_eq!(scene.polygon_triangles(quad).count(), 2);
}

/// An NFF file a TOML scene draws brings its objects, lights and
/// materials; its view is ignored, so it need not have one (while the
/// same file alone, as a scene, is refused for the missing view).
#[test]
fn an_included_nff_file_needs_no_view() {
    let d = temp_dir("include-no-view");
    std::fs::write(
        d.join("part.nff"),
        "l 1 -4 6\nf 0.9 0.2 0.1 0.8 0.2 10 0 1\ns 0 0 0 1\ns 2 0 0 0.5\n",
    )
    .unwrap();
    std::fs::write(
        d.join("s.toml"),
        format!("{CAMERA}[[object]]\nnff = \"part.nff\"\n"),
    )
    .unwrap();
    let scene = Scene::load(d.join("s.toml")).unwrap();
    assert_eq!(scene.spheres.len(), 2);
    assert_eq!(scene.lights.len(), 1);
    assert_eq!(scene.view.from, glam::DVec3::new(0.0, -5.0, 1.0));
    let e = Scene::load(d.join("part.nff")).unwrap_err().to_string();
    assert!(e.contains("no view"), "{e}");
}

/// Image textures count against the memory limit like volumes and
/// meshes: a 2048×2048 image (about 36 MiB to read and decode, 12 MiB
/// kept) is refused under a 32 MiB limit before it is decoded, at its key;
/// two of them do not fit 40 MiB, the first one's pixels held.
#[test]
fn image_textures_keep_the_memory_limit() {
    let d = temp_dir("texture-memory");
    image::RgbImage::from_pixel(2048, 2048, image::Rgb([90, 120, 150]))
        .save(d.join("big.png"))
        .unwrap();
    let material = |name: &str| {
        format!(
            "[material.{name}.texture.image]\nfile = \"big.png\"\nplanar = {{ origin = [-1, 0, -1], u = [2, 0, 0], v = [0, 0, 2] }}\n"
        )
    };
    let text = format!(
        "{CAMERA}[[light]]\nposition = [1, 1, 1]\n{}{}[[object]]\nmaterial = \"a\"\nsphere = {{ centre = [0,0,0], radius = 1 }}\n",
        material("a"),
        material("b")
    );
    let p = d.join("t.toml");
    std::fs::write(&p, &text).unwrap();
    let load = |mib: u64| {
        let opts = rrt_host::scene::toml::Options {
            max_memory: mib << 20,
            ..Default::default()
        };
        rrt_host::scene::toml::parse(&p.display().to_string(), &text, &d, &opts)
    };
    let e = load(32).unwrap_err().to_string();
    assert!(
        e.contains(":9:8: material.a.texture.image.file: ")
            && e.contains("the 2048×2048 image takes about 36.")
            && e.contains("more than the memory limit of 32.0 MiB"),
        "{e}"
    );
    let e = load(40).unwrap_err().to_string();
    assert!(
        e.contains("material.b.texture.image.file: ")
            && e.contains("beside the 12.0 MiB of the volumes and textures read before"),
        "{e}"
    );
    let scene = load(128).unwrap();
    assert_eq!(scene.textures.len(), 2);
}
