//! Fitting: the frame, fixed point, the object table and the memory
//! estimate.

use super::*;
use rrt_core::fixed::VOXEL;
use rrt_core::geometry::NORMAL_ONE;

use super::memory::OBJECT_BYTES;
use crate::memory::FALLBACK_TOTAL_MEMORY;
use crate::shape::{Sphere, Triangle};
use crate::world::Ray;

fn scene(body: &str) -> Scene {
    let head = "v\nfrom 0 0 10\nat 0 0 0\nup 0 1 0\nangle 45\nhither 0\nresolution 8 8\n";
    Scene::parse("t.nff", format!("{head}{body}").as_bytes()).unwrap()
}

fn opts(n: u32) -> FitOptions {
    FitOptions {
        max_memory: u64::MAX,
        ..FitOptions::new(n)
    }
}

#[test]
fn cubic_voxels_longest_axis_and_margin() {
    // Box (−2, −1, −0.5)..(2, 1, 0.5): 4 × 2 × 1.
    let s = scene("p 4\n-2 -1 -0.5\n2 -1 -0.5\n2 1 0.5\n-2 1 0.5\n");
    let f = frame(&s, &opts(104)).unwrap();
    // 100 voxels inside the margins along x: voxel = 0.04.
    assert!((f.voxel_size - 0.04).abs() < 1e-15);
    assert_eq!(f.dims(), [104, 54, 29]);
    // Centred: the geometry's centre is the raster's centre.
    let wb = f.world_bounds();
    assert!(((wb.min + wb.max) * 0.5).length() < 1e-12);
    // Two voxels of margin along the longest axis.
    assert!((wb.min.x - (-2.0 - 0.08)).abs() < 1e-12);
    assert!(wb.min.cmple(DVec3::new(-2.08, -1.08, -0.58) + 1e-12).all());
}

#[test]
fn explicit_bounds_are_used_exactly() {
    let s = scene("s 0 0 0 1\n");
    let b = Bounds {
        min: DVec3::new(0.0, 0.0, 0.0),
        max: DVec3::new(8.0, 4.0, 2.0),
    };
    let f = frame(
        &s,
        &FitOptions {
            bounds: Some(b),
            ..opts(64)
        },
    )
    .unwrap();
    assert_eq!(f.dims(), [64, 32, 16]);
    assert_eq!(f.voxel_size, 0.125);
    assert_eq!(f.world_bounds(), b);
    let bad = Bounds {
        min: DVec3::ONE,
        max: DVec3::new(2.0, 1.0, 2.0),
    };
    let e = frame(
        &s,
        &FitOptions {
            bounds: Some(bad),
            ..opts(64)
        },
    )
    .unwrap_err();
    assert_eq!(
        e.to_string(),
        "bounds [1, 1, 1] to [2, 1, 2]: expected corners within ±1e60 with min < max on every axis"
    );
}

#[test]
fn absurd_raster_sizes() {
    let s = scene("s 0 0 0 1\n");
    for (n, want) in [
        (
            0,
            "raster 0: expected 1 to 65536 voxels along the longest axis",
        ),
        (
            65537,
            "raster 65537: expected 1 to 65536 voxels along the longest axis",
        ),
        (
            4,
            "raster 4: too small for a margin of 2 voxels on each side; use at least 5",
        ),
    ] {
        assert_eq!(frame(&s, &opts(n)).unwrap_err().to_string(), want);
    }
    assert_eq!(frame(&s, &opts(5)).unwrap().dims(), [5, 5, 5]);
    assert_eq!(frame(&s, &opts(65536)).unwrap().dims(), [65536; 3]);
}

#[test]
fn fixed_point_round_trip() {
    let s = scene("s 0 0 0 1\n");
    let f = frame(&s, &opts(36)).unwrap();
    // 32 voxels over the diameter 2: voxel 1/16, origin −1 − 2/16.
    assert_eq!(f.voxel_size, 0.0625);
    assert_eq!(f.origin, DVec3::splat(-1.125));
    assert_eq!(f.to_fixed(DVec3::ZERO), Some([18 * VOXEL; 3]));
    assert_eq!(f.length_to_fixed(1.0, 0), Some(16 * VOXEL));
    let p = DVec3::new(0.3, -0.7, 0.123_456);
    let back = f.fixed_to_world(f.to_fixed(p).unwrap());
    assert!((back - p).abs().max_element() <= 0.5 * f.voxel_size / VOXEL as f64 + 1e-15);
    assert!((f.raster_to_world(f.world_to_raster(p)) - p).length() < 1e-15);
    assert_eq!(f.to_fixed(DVec3::new(1e30, 0.0, 0.0)), None);
    assert_eq!(f.to_fixed(DVec3::NAN), None);
}

#[test]
fn objects_lights_and_normals() {
    let s = scene(
        "l 100 0 0\nl 0 0 2 0.5 0.5 1\nf 1 1 1 1 0 0 0 1\ns 0 0 0 1\nc 0 0 0 0.5 0 0 0.5 0.25\n\
         p 4\n-1 -1 0\n1 -1 0\n1 1 0\n-1 1 0\npp 3\n0 0 0 0 0 3\n1 0 0 0 4 3\n0 1 0 0 0 1\n",
    );
    let fitted = fit(&s, &opts(36)).unwrap();
    let f = fitted.frame;
    assert_eq!(fitted.objects.len(), 1 + 1 + 2 + 1);
    let table::Shape::Sphere(sp) = fitted.objects[0].entry else {
        panic!()
    };
    assert_eq!(sp.centre, f.to_fixed(DVec3::ZERO).unwrap());
    assert_eq!(sp.radius, 16 * VOXEL);
    let table::Shape::Cone(c) = fitted.objects[1].entry else {
        panic!()
    };
    assert_eq!((c.base_radius, c.apex_radius), (8 * VOXEL, 4 * VOXEL));
    // The quad's fan: (0, 1, 2) and (0, 2, 3), winding kept.
    let table::Shape::Triangle(t1) = fitted.objects[3].entry else {
        panic!()
    };
    let expect = [0, 2, 3].map(|k| f.to_fixed(s.vertices[k]).unwrap());
    assert_eq!(t1.vertices, expect);
    assert_eq!(t1.normals, None);
    assert_eq!(
        fitted.objects[3].shape,
        Shape::Triangle(Triangle {
            vertices: [0, 2, 3].map(|k| s.vertices[k]),
            normals: None,
        })
    );
    assert_eq!(
        (fitted.objects[3].kind, fitted.objects[3].loc.line),
        ("polygon", 13)
    );
    // Patch normals normalised and scaled by 2^30.
    let table::Shape::Triangle(pt) = fitted.objects[4].entry else {
        panic!()
    };
    let n = pt.normals.unwrap();
    assert_eq!(n[0], [0, 0, NORMAL_ONE]);
    assert_eq!(
        n[1],
        [
            0,
            (0.8 * f64::from(NORMAL_ONE)).round() as i32,
            (0.6 * f64::from(NORMAL_ONE)).round() as i32
        ]
    );
    // Lights outside the raster are fine.
    assert_eq!(fitted.lights.len(), 2);
    assert_eq!(
        fitted.lights[0].position,
        f.to_fixed(DVec3::new(100.0, 0.0, 0.0)).unwrap()
    );
    assert!(fitted.lights[0].position[0] > i64::from(f.dims()[0]) * VOXEL);
    assert_eq!(fitted.lights[1].colour, DVec3::new(0.5, 0.5, 1.0));
    assert_eq!(fitted.dropped, Dropped::default());
}

/// A light too far for fixed point near the raster (a sun) is taken by its
/// direction: 2^44 voxels from the raster's centre towards it; a light
/// within that distance keeps its rounded position.
#[test]
fn a_far_light_is_taken_by_its_direction() {
    let s = scene("l 1e30 -2e30 3e30\nl 1e9 0 0\ns 0 0 0 1\n");
    let fitted = fit(&s, &opts(36)).unwrap();
    let f = fitted.frame;
    let far = DVec3::from(fitted.lights[0].position.map(|v| v as f64)) / VOXEL as f64;
    let centre = DVec3::from(f.dims().map(f64::from)) * 0.5;
    let to = far - centre;
    assert!((to.length() / 2f64.powi(44) - 1.0).abs() < 1e-9, "{to}");
    let want = DVec3::new(1.0, -2.0, 3.0).normalize();
    assert!(to.normalize().angle_between(want) < 1e-12);
    // Beyond the 2^31 voxels of other points, within 2^44.
    let near = DVec3::new(1e9, 0.0, 0.0);
    assert!(f.to_fixed(near).is_none());
    let q = f.world_to_raster(near) * VOXEL as f64;
    assert_eq!(
        fitted.lights[1].position,
        q.to_array().map(|v| v.round() as i64)
    );
}

#[test]
fn degenerate_and_outside_objects_are_dropped() {
    // A polygon whose middle fan triangle collapses (collinear 0, 1, 2),
    // and a sphere outside explicit bounds.
    let s = scene("p 4\n0 0 0\n1 0 0\n2 0 0\n1 1 0\ns 50 50 50 1\n");
    let b = Bounds {
        min: DVec3::splat(-1.0),
        max: DVec3::splat(3.0),
    };
    let fitted = fit(
        &s,
        &FitOptions {
            bounds: Some(b),
            ..opts(32)
        },
    )
    .unwrap();
    assert_eq!(
        fitted.dropped,
        Dropped {
            degenerate: 1,
            outside: 1
        }
    );
    assert_eq!(fitted.objects.len(), 1);
}

#[test]
fn memory_estimate_and_refusal() {
    // A unit square of 100 × 100 voxels in a 104 × 104 × 5 raster.
    let s = scene("p 4\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n");
    let f = frame(&s, &opts(104)).unwrap();
    assert_eq!(f.dims(), [104, 104, 4]);
    let m = estimate_memory(&s, &f, true);
    assert_eq!(m.voxels, 104 * 104 * 4);
    assert_eq!(m.plane, m.voxels);
    assert_eq!(m.lines, m.voxels.div_ceil(64));
    assert_eq!(m.directory, (4 + 5) * m.voxels.div_ceil(512));
    // Two triangles of area 5000 and perimeter 100 + 100 + 141.4.
    let per_tri = 1.8 * (5000.0 + 200.0 + 100.0 * 2f64.sqrt() + 3.0);
    assert_eq!(m.record_voxels, (2.0 * per_tri).ceil() as u64);
    assert_eq!(m.records, 20 * m.record_voxels);
    assert!(
        m.record_voxels >= 100 * 100,
        "at least one layer of the square"
    );

    // The object table: the two triangles.
    assert_eq!((m.objects, m.object_table), (2, 2 * OBJECT_BYTES));
    // The scene's own data: the square's four vertices.
    assert_eq!(m.scene, 4 * crate::scene::toml::VERTEX_BYTES);
    // 43264 + 676 + 765 + 19240·20 = 429505 bytes, the objects and the
    // scene's data.
    assert_eq!(m.total(), 429_505 + 2 * OBJECT_BYTES + m.scene);
    let e = fit(
        &s,
        &FitOptions {
            max_memory: 256 << 10,
            ..opts(104)
        },
    )
    .unwrap_err();
    assert_eq!(
        e.to_string(),
        format!(
            "raster 104×104×4: needs about {} (plane 42.2 KiB, line level 676 B, brick \
             directory and level 765 B, records for up to 19240 voxels 375.8 KiB, object table \
             of 2 objects {}, the scene's volumes and vertices 192 B), more than the limit of \
             256.0 KiB; use a smaller raster or a larger memory limit",
            Bytes(m.total()),
            Bytes(2 * OBJECT_BYTES)
        )
    );
    assert!(
        fit(
            &s,
            &FitOptions {
                max_memory: m.total() - 1,
                ..opts(104)
            }
        )
        .is_err()
    );
    assert!(
        fit(
            &s,
            &FitOptions {
                max_memory: m.total(),
                ..opts(104)
            }
        )
        .is_ok()
    );
    // Records never exceed one per voxel: 40 small spheres in 5³.
    let many: String = (0..40)
        .map(|i| format!("s {} 0 0 0.1\n", f64::from(i) * 0.01))
        .collect();
    let many = scene(&many);
    let f = frame(&many, &opts(5)).unwrap();
    assert_eq!(f.dims(), [5, 5, 5]);
    assert_eq!(estimate_memory(&many, &f, true).record_voxels, 125);
}

#[test]
fn byte_units() {
    assert_eq!(Bytes(0).to_string(), "0 B");
    assert_eq!(Bytes(1023).to_string(), "1023 B");
    assert_eq!(Bytes(1536).to_string(), "1.5 KiB");
    assert_eq!(Bytes(3 << 30).to_string(), "3.0 GiB");
    // Past PiB, the count stays in PiB.
    assert_eq!(Bytes(u64::MAX).to_string(), "16384.0 PiB");
}

#[test]
fn machine_memory() {
    assert_eq!(
        parse_meminfo("MemFree: 5 kB\nMemTotal: 10 kB\n"),
        Some(10240)
    );
    assert_eq!(parse_meminfo("MemTotal: 10 MB\n"), None);
    assert_eq!(parse_meminfo("MemTotal: lots kB\n"), None);
    assert_eq!(parse_meminfo(&format!("MemTotal: {} kB\n", u64::MAX)), None);
    let half = default_max_memory();
    match total_memory() {
        Some(t) => assert_eq!(half, t / 2),
        None => assert_eq!(half, FALLBACK_TOTAL_MEMORY / 2),
    }
    assert!(half > 0);
}

#[test]
fn objects_keep_the_exact_world_geometry() {
    let s = scene("s 0 0 0 1\npp 3\n0 0 2 0 0 1\n1 0 2 1 0 1\n0 1 2 0 1 1\n");
    let fitted = fit(&s, &opts(36)).unwrap();
    let down = Ray::new(DVec3::new(0.2, 0.2, 5.0), -DVec3::Z);
    let h = fitted.objects[1]
        .shape
        .intersect(&down, 0.0, f64::INFINITY)
        .unwrap();
    assert!((h.t - 3.0).abs() < 1e-12);
    let expect =
        (DVec3::Z * 0.6 + DVec3::new(1.0, 0.0, 1.0) * 0.2 + DVec3::new(0.0, 1.0, 1.0) * 0.2)
            .normalize();
    assert!((h.normal - expect).length() < 1e-12);
    let h = fitted.objects[0]
        .shape
        .intersect(&down, 0.0, f64::INFINITY)
        .unwrap();
    assert!((h.t - (5.0 - (1.0f64 - 0.08).sqrt())).abs() < 1e-12);
    // The same ray in raster units meets the sphere at the same t.
    let r = fitted.frame.ray_to_raster(&down);
    let ball = Sphere {
        centre: fitted.frame.world_to_raster(DVec3::ZERO),
        radius: 1.0 / fitted.frame.voxel_size,
    };
    let h2 = ball.intersect(&r, 0.0, f64::INFINITY).unwrap();
    assert!((h2.t - h.t).abs() < 1e-9);
}

#[test]
fn geometry_without_a_box_says_why() {
    // Scenes built in code: the readers refuse such numbers themselves.
    let e = |radius: f64| {
        let mut s = scene("s 1 1 1 1\n");
        s.spheres[0].shape.radius = radius;
        fit(&s, &opts(64)).unwrap_err().to_string()
    };
    for r in [1e61, 1e308] {
        assert!(
            e(r).starts_with("t.nff:8:1: sphere reaches beyond ±1e60 world units"),
            "{}",
            e(r)
        );
    }
    // Geometry the object checks do not name (volumes, `.vox` models, CSG).
    let bounds = |min: f64, max: f64| {
        FitError::NoExtent {
            file: "x.toml".into(),
            min: DVec3::splat(min),
            max: DVec3::splat(max),
        }
        .to_string()
    };
    assert_eq!(
        bounds(-1e308, 1e308),
        "x.toml: the geometry's bounds (-1e308, -1e308, -1e308) to (1e308, 1e308, 1e308) are too far apart to fit a raster to"
    );
    assert!(
        bounds(-1e61, 1.0).starts_with(
            "x.toml: the geometry's bounds (-1e61, -1e61, -1e61) to (1, 1, 1) reach beyond ±1e60 world units"
        ),
        "{}",
        bounds(-1e61, 1.0)
    );
    let empty = FitError::NoExtent {
        file: "x.toml".into(),
        min: DVec3::INFINITY,
        max: DVec3::NEG_INFINITY,
    };
    assert!(
        empty
            .to_string()
            .starts_with("x.toml: nothing to fit a raster to: every object is empty"),
        "{empty}"
    );
}

#[test]
fn objects_and_lights_beyond_the_world_limit_are_refused() {
    // Within explicit bounds the raster is small, but the exact intersection
    // of a sphere of radius 1e100 would square it: refused by the object's
    // place, as is a light as far.
    let b = Some(Bounds {
        min: DVec3::splat(-2.0),
        max: DVec3::splat(2.0),
    });
    let mut s = scene("s 0 0 0 1\nl 1 1 1\n");
    s.spheres[0].shape.radius = 1e100;
    let e = fit(
        &s,
        &FitOptions {
            bounds: b,
            ..opts(16)
        },
    )
    .unwrap_err();
    assert!(
        matches!(&e, FitError::BeyondWorld { what: "sphere", .. }),
        "{e}"
    );
    assert!(
        e.to_string()
            .starts_with("t.nff:8:1: sphere reaches beyond ±1e60 world units"),
        "{e}"
    );
    let mut s = scene("s 0 0 0 1\nl 1 1 1\n");
    s.lights[0].position = DVec3::new(0.0, 0.0, -1e61);
    let e = fit(&s, &opts(16)).unwrap_err();
    assert!(
        matches!(&e, FitError::BeyondWorld { what: "light", .. }),
        "{e}"
    );
    // At the limit itself, everything is accepted.
    let mut s = scene("s 0 0 0 1\nl 1 1 1\n");
    s.lights[0].position = DVec3::new(0.0, 0.0, -1e60);
    assert!(fit(&s, &opts(16)).is_ok());
    let huge = Bounds {
        min: DVec3::splat(-1e61),
        max: DVec3::splat(2.0),
    };
    assert!(matches!(
        fit(
            &s,
            &FitOptions {
                bounds: Some(huge),
                ..opts(16)
            }
        ),
        Err(FitError::BadBounds { .. })
    ));
}
