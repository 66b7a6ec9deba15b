//! Fitting the raster to real scenes: dimensions, fixed-point geometry
//! inside the raster, memory estimates and refusals, and the camera, the
//! object table's sources and the exact intersections working together.

use std::path::PathBuf;

use glam::DVec3;
use rrt_core::fixed::VOXEL;
use rrt_core::geometry::NORMAL_ONE;
use rrt_core::object_table::Shape;
use rrt_host::fit::{self, FitOptions, Fitted};
use rrt_host::render::camera::Camera;
use rrt_host::scene::Scene;
use rrt_host::shape::{self, Surface};
use rrt_tests::shared_spd;

fn test_data(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("data")
        .join(name)
}

fn opts(n: u32) -> FitOptions {
    FitOptions {
        max_memory: 16 << 30,
        ..FitOptions::new(n)
    }
}

/// Every object of a fit with computed bounds lies inside the raster, at
/// least the margin away from its faces (to rounding), and patch normals
/// are unit vectors.
#[track_caller]
fn check_inside(f: &Fitted, margin: u32) {
    let size = f.frame.dims().map(|n| i64::from(n) * VOXEL);
    let m = i64::from(margin) * VOXEL - 1;
    let inside = |lo: [i64; 3], hi: [i64; 3]| (0..3).all(|k| lo[k] >= m && hi[k] <= size[k] - m);
    for o in &f.objects {
        let ok = match o.entry {
            Shape::Sphere(s) => inside(
                s.centre.map(|c| c - s.radius),
                s.centre.map(|c| c + s.radius),
            ),
            Shape::Triangle(t) => {
                if let Some(ns) = t.normals {
                    for n in ns {
                        let len = n.map(|c| f64::from(c) / f64::from(NORMAL_ONE));
                        let l = DVec3::from(len).length();
                        assert!((l - 1.0).abs() < 1e-8, "normal {n:?}");
                    }
                }
                t.vertices.iter().all(|&v| inside(v, v))
            }
            Shape::Cone(c) => {
                let r = c.base_radius.max(c.apex_radius);
                let lo = [0, 1, 2].map(|k| c.base[k].min(c.apex[k]) - r);
                let hi = [0, 1, 2].map(|k| c.base[k].max(c.apex[k]) + r);
                inside(lo, hi)
            }
            other => panic!("an NFF scene made a {other:?} entry"),
        };
        assert!(ok, "{o:?} outside {:?}", f.frame.dims());
    }
}

#[test]
fn balls1_fits_and_ray_casts() {
    let s = Scene::load(test_data("balls1.nff")).unwrap();
    let f = fit::fit(&s, &opts(256)).unwrap();
    // The floor (24 × 24 at z = −0.5) is the longest extent; the top
    // sphere reaches z = 0.544331 + 0.166667.
    let dims = f.frame.dims();
    assert_eq!(dims[0], 256);
    assert_eq!(dims[1], 256);
    let voxel = 24.0 / 252.0;
    assert!((f.frame.voxel_size - voxel).abs() < 1e-12);
    let z_extent = 0.544331 + 0.166667 + 0.5;
    assert_eq!(dims[2], (z_extent / voxel).ceil() as u32 + 4);
    assert_eq!(f.objects.len(), 10 + 2);
    assert_eq!(f.lights.len(), 3);
    assert_eq!(f.dropped, fit::Dropped::default());
    check_inside(&f, fit::DEFAULT_MARGIN);
    // The light at (4, 3, 2) lies inside the raster's x–y range but above it.
    let l = f.frame.fixed_to_world(f.lights[0].position);
    assert!((l - DVec3::new(4.0, 3.0, 2.0)).length() < 1e-5);
    assert!(f.lights[0].position[2] > i64::from(dims[2]) * VOXEL);

    // Cast the camera's rays against the exact objects behind the table.
    let cam = Camera::new(&s.view, 33, 33).unwrap();
    let mut hits = 0;
    for y in 0..33 {
        for x in 0..33 {
            let ray = cam.primary(x, y);
            let nearest = f
                .objects
                .iter()
                .filter_map(|o| o.shape.intersect(&ray, 0.0, f64::INFINITY).map(|h| (h, o)))
                .min_by(|a, b| a.0.t.total_cmp(&b.0.t));
            let Some((h, o)) = nearest else { continue };
            hits += 1;
            let p = ray.at(h.t);
            match o.shape {
                shape::Shape::Sphere(sp) => {
                    assert!(((p - sp.centre).length() - sp.radius).abs() < 1e-9);
                }
                shape::Shape::Triangle(_) => assert!((p.z + 0.5).abs() < 1e-9),
                other => unreachable!("balls1 has no {}", other.kind()),
            }
        }
    }
    // The floor fills the lower part of the view, the flake the middle.
    assert!(hits > 33 * 33 / 2, "{hits}");
    // The centre pixel looks at the big sphere's centre: hits it first.
    let ray = cam.primary(16, 16);
    let h = s.spheres[0]
        .shape
        .intersect(&ray, 0.0, f64::INFINITY)
        .unwrap();
    assert!((h.t - (s.view.from.length() - 0.5)).abs() < 1e-9);
}

#[test]
fn tetra_fits() {
    let s = Scene::load(test_data("tetra.nff")).unwrap();
    let f = fit::fit(&s, &opts(100)).unwrap();
    assert_eq!(f.frame.dims(), [100, 100, 100]);
    assert_eq!(f.objects.len(), 16);
    assert!(
        f.objects
            .iter()
            .all(|o| matches!(o.entry, Shape::Triangle(t) if t.normals.is_none()))
    );
    check_inside(&f, fit::DEFAULT_MARGIN);
}

#[test]
fn spd_scenes_fit_with_memory_estimates() {
    let Some(spd) = shared_spd() else {
        return;
    };
    for (name, objects) in [
        ("balls4.nff", 7381 + 2),
        ("teapot.nff", 240 + 4 * 2),
        ("rings.nff", 150 + 150 + 2),
        ("tetra.nff", 16),
    ] {
        let s = Scene::load(spd.join(name)).unwrap();
        for n in [256, 1024, 2048] {
            let f = fit::fit(&s, &opts(n)).unwrap_or_else(|e| panic!("{name} at {n}: {e}"));
            assert_eq!(f.objects.len(), objects, "{name}");
            assert_eq!(f.frame.dims().into_iter().max(), Some(n));
            check_inside(&f, fit::DEFAULT_MARGIN);
            eprintln!(
                "{name} raster {n}: {:?} voxel {:.5}, estimate {} ({})",
                f.frame.dims(),
                f.frame.voxel_size,
                fit::Bytes(f.memory.total()),
                f.memory
            );
        }
    }
    // The teapot's patches keep unit normals; rings' cones are cylinders.
    let teapot = fit::fit(&Scene::load(spd.join("teapot.nff")).unwrap(), &opts(256)).unwrap();
    let patches = teapot
        .objects
        .iter()
        .filter(|o| matches!(o.entry, Shape::Triangle(t) if t.normals.is_some()))
        .count();
    assert_eq!(patches, 240);
    let rings = fit::fit(&Scene::load(spd.join("rings.nff")).unwrap(), &opts(256)).unwrap();
    assert!(
        rings
            .objects
            .iter()
            .any(|o| matches!(o.entry, Shape::Cone(c) if c.base_radius == c.apex_radius))
    );

    // balls4 at 2048: the estimate is an upper bound well below the
    // machine, and a small limit is refused before allocating.
    let balls4 = Scene::load(spd.join("balls4.nff")).unwrap();
    let f = fit::fit(&balls4, &opts(2048)).unwrap();
    let m = f.memory;
    assert_eq!(m.plane, m.voxels);
    assert!(m.record_voxels < m.voxels / 10);
    // The floor alone is 2044² voxel² of surface.
    assert!(m.record_voxels as f64 >= 2044.0 * 2044.0);
    assert!(m.total() > 256 << 20);
    let small = FitOptions {
        max_memory: 256 << 20,
        ..opts(2048)
    };
    let Err(e) = fit::fit(&balls4, &small) else {
        panic!("balls4 at 2048 fitted under 256 MiB");
    };
    let msg = e.to_string();
    assert!(
        msg.starts_with(&format!(
            "raster 2048×2048×{}: needs about ",
            f.frame.dims()[2]
        )),
        "{msg}"
    );
    assert!(
        msg.ends_with(
            "more than the limit of 256.0 MiB; use a smaller raster or a larger memory limit"
        ),
        "{msg}"
    );
}

/// A scene of volumes alone gets the raster of a pixel's footprint (not
/// the largest default, which the surface primitives' ray budget would
/// allow for a scene without any).
#[test]
fn a_volume_alone_gets_the_pixel_footprint_raster() {
    use rrt_host::fit::{MAX_DEFAULT_RASTER, MIN_DEFAULT_RASTER, RasterNeed, default_raster};
    let dir = rrt_tests::fresh_dir("fit", "volume_alone");
    let path = dir.join("blob.toml");
    std::fs::write(
        &path,
        "[camera]\nfrom = [0, -6, 2]\nat = [0, 0, 0]\nangle = 40\nresolution = [64, 48]\n\
         [volume.v]\nmetaballs = { dims = [32, 32, 32], min = [-1, -1, -1], max = [1, 1, 1], balls = [[0, 0, 0, 0.8, 1]] }\n\
         iso = 0.5\n[material.m]\ncolour = [1, 1, 1]\n[[object]]\nmaterial = \"m\"\nvolume = \"v\"\n",
    )
    .unwrap();
    let scene = Scene::load(&path).unwrap();
    let size = |w: u32, h: u32| {
        default_raster(
            &scene,
            &RasterNeed {
                view: &scene.view,
                image: [w, h],
                samples: 1,
                discrete: false,
            },
        )
    };
    assert_eq!(size(64, 48), MIN_DEFAULT_RASTER);
    // Larger images, finer voxels, up to 8 voxels per sample spacing (the
    // box holds the 32 samples' cells along its longest axis; and the
    // margins).
    let (a, b) = (size(512, 384), size(2048, 1536));
    assert!(MIN_DEFAULT_RASTER < a && a < b, "{a} {b}");
    assert_eq!(size(8192, 6144), 32 * 8 + 4);
    assert!(b <= MAX_DEFAULT_RASTER);
    // An eye inside the volume's box: a pixel's footprint there is 0, and
    // the samples bound the raster.
    let inside = rrt_host::scene::View {
        from: DVec3::new(0.0, 0.0, 0.9),
        ..scene.view.clone()
    };
    let r = default_raster(
        &scene,
        &RasterNeed {
            view: &inside,
            image: [64, 48],
            samples: 1,
            discrete: false,
        },
    );
    assert_eq!(r, 32 * 8 + 4);
}

/// A spindle torus (its tube wider than its distance from the axis) is
/// about the size of a sphere of the tube's radius, and gets about that
/// sphere's default raster, not the largest (its area, taken as the ring
/// torus's `4π²·R·r`, would vanish with `R`).
#[test]
fn a_spindle_torus_gets_a_sphere_sized_raster() {
    use rrt_host::fit::{RasterNeed, default_raster};
    let dir = rrt_tests::fresh_dir("fit", "spindle_torus");
    let size = |shape: &str| {
        let path = dir.join("t.toml");
        std::fs::write(
            &path,
            format!(
                "[camera]\nfrom = [0, -6, 2]\nat = [0, 0, 0]\nangle = 40\nresolution = [64, 64]\n\
                 [material.m]\n[[object]]\nmaterial = \"m\"\n{shape}\n"
            ),
        )
        .unwrap();
        let scene = Scene::load(&path).unwrap();
        default_raster(
            &scene,
            &RasterNeed {
                view: &scene.view,
                image: [64, 64],
                samples: 1,
                discrete: false,
            },
        )
    };
    let sphere = size("sphere = { centre = [0, 0, 0], radius = 1 }");
    for major in ["1e-6", "0.1", "0.5"] {
        let torus = size(&format!(
            "torus = {{ centre = [0, 0, 0], axis = [0, 0, 1], major = {major}, minor = 1 }}"
        ));
        assert!(
            torus <= 2 * sphere,
            "major {major}: {torus} against the sphere's {sphere}"
        );
    }
}
