//! The NFF parser: the SPD scenes parse with the right counts, and every
//! kind of bad input gets one clear, located error (never a panic).

use std::path::PathBuf;
use std::time::{Duration, Instant};

use glam::DVec3;
use rrt_host::check;
use rrt_host::scene::{Material, ParseOptions, Scene, SceneError, check_scene, nff};
use rrt_tests::{Rng, shared_spd};

/// A valid view block: seven lines, so the next line is line 8.
const HEAD: &str = "v\nfrom 0 0 5\nat 0 0 0\nup 0 1 0\nangle 45\nhither 0.01\nresolution 64 48\n";

fn parse(src: &str) -> Result<Scene, SceneError> {
    Scene::parse("scene.nff", src.as_bytes())
}

#[track_caller]
fn ok(src: &str) -> Scene {
    match parse(src) {
        Ok(s) => {
            check_scene(&s).unwrap();
            s
        }
        Err(e) => panic!("expected a scene, got: {e}\n--- input:\n{src}"),
    }
}

/// The error message for `src`.
#[track_caller]
fn err(src: &str) -> String {
    match parse(src) {
        Ok(s) => panic!("expected an error, got a scene: {s:?}\n--- input:\n{src}"),
        Err(e) => e.to_string(),
    }
}

/// `HEAD` followed by `body`; returns the error message.
#[track_caller]
fn err_body(body: &str) -> String {
    err(&format!("{HEAD}{body}"))
}

fn test_data(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("data")
        .join(name)
}

// ------------------------------------------------------------ good scenes

/// A UTF-8 byte-order mark (which editors write and do not show) is
/// skipped, not an unknown directive; columns count from after it.
#[test]
fn a_byte_order_mark_is_skipped() {
    let src = format!("{HEAD}l 1 1 1\ns 0 0 0 1\n");
    assert_eq!(ok(&format!("\u{feff}{src}")), ok(&src));
    assert_eq!(
        err("\u{feff}b 0 2 0\n"),
        r#"scene.nff:1:5: background colour: expected a number from 0 to 1, found "2""#
    );
}

#[test]
fn balls1_copy_parses_with_counts_and_values() {
    let s = Scene::load(test_data("balls1.nff")).unwrap();
    check_scene(&s).unwrap();
    assert_eq!(s.spheres.len(), 10);
    assert_eq!(s.lights.len(), 3);
    assert_eq!(s.materials.len(), 2);
    assert_eq!(s.polygons.len(), 1);
    assert_eq!(s.polygons[0].count, 4);
    assert!(!s.polygons[0].patch);
    assert_eq!(s.vertices.len(), 4);
    assert_eq!(s.vertices[2], DVec3::new(-12.0, -12.0, -0.5));
    assert_eq!(s.background, DVec3::new(0.078, 0.361, 0.753));
    let v = &s.view;
    assert_eq!(v.from, DVec3::new(2.1, 1.3, 1.7));
    assert_eq!(v.at, DVec3::ZERO);
    assert_eq!(v.up, DVec3::Z);
    assert_eq!(v.angle, 45.0);
    assert_eq!(v.hither, 0.01);
    assert_eq!(v.resolution, [512, 512]);
    assert_eq!(s.lights[1].position, DVec3::new(1.0, -4.0, 4.0));
    assert_eq!(s.lights[1].colour, None);
    assert_eq!(s.lights[1].rgb(), DVec3::ONE);
    // f 1 0.75 0.33 0.8 0 100000 0 1 (floor), then f 1 0.9 0.7 0.5 0.5 3.0827 0 1.
    let floor = &s.materials[0];
    assert_eq!(floor.colour, DVec3::new(1.0, 0.75, 0.33));
    assert_eq!((floor.kd, floor.ks, floor.shine), (0.8, 0.0, 100_000.0));
    assert_eq!((floor.transmittance, floor.ior), (0.0, 1.0));
    assert_eq!(s.polygons[0].material, 0);
    assert!(s.spheres.iter().all(|sp| sp.material == 1));
    assert_eq!(s.spheres[0].shape.centre, DVec3::ZERO);
    assert_eq!(s.spheres[0].shape.radius, 0.5);
    // Locations point at the directives.
    assert_eq!(
        s.spheres[0].loc.to_string(),
        format!("{}:19:1", test_data("balls1.nff").display())
    );
    assert_eq!(s.polygons[0].loc.line, 13);
}

#[test]
fn tetra_copy_parses_with_counts() {
    let s = Scene::load(test_data("tetra.nff")).unwrap();
    check_scene(&s).unwrap();
    assert_eq!(s.polygons.len(), 16);
    assert!(s.polygons.iter().all(|p| p.count == 3 && !p.patch));
    assert_eq!(s.triangle_count(), 16);
    assert_eq!(s.lights.len(), 1);
    assert_eq!(s.materials.len(), 1);
    assert!(s.spheres.is_empty() && s.cones.is_empty());
    assert_eq!(s.view.hither, 1.0);
    let b = s.bounds();
    assert_eq!((b.min, b.max), (DVec3::splat(-1.0), DVec3::splat(1.0)));
}

/// The committed copies equal the shared SPD files.
#[test]
fn test_data_copies_match_shared_spd() {
    let Some(spd) = shared_spd() else {
        return;
    };
    for name in ["balls1.nff", "tetra.nff"] {
        let ours = std::fs::read(test_data(name)).unwrap();
        let theirs = std::fs::read(spd.join(name)).unwrap();
        assert!(
            ours == theirs,
            "tests/data/{name} differs from the shared copy"
        );
    }
}

#[test]
fn every_spd_scene_parses_with_counts() {
    let Some(spd) = shared_spd() else {
        return;
    };
    let load = |name: &str| {
        let s = Scene::load(spd.join(name)).unwrap_or_else(|e| panic!("{e}"));
        check_scene(&s).unwrap();
        s
    };
    for (name, spheres) in [
        ("balls1.nff", 10),
        ("balls2.nff", 91),
        ("balls3.nff", 820),
        ("balls4.nff", 7381),
    ] {
        let s = load(name);
        assert_eq!(s.spheres.len(), spheres, "{name}");
        assert_eq!(s.lights.len(), 3, "{name}");
        assert_eq!(s.materials.len(), 2, "{name}");
        assert_eq!(s.polygons.len(), 1, "{name}");
        assert!(s.cones.is_empty(), "{name}");
    }
    let teapot = load("teapot.nff");
    assert_eq!(teapot.patch_count(), 240);
    assert_eq!(teapot.polygons.len() - teapot.patch_count(), 4);
    assert!(
        teapot
            .polygons
            .iter()
            .filter(|p| p.patch)
            .all(|p| p.count == 3)
    );
    assert!(teapot.spheres.is_empty() && teapot.cones.is_empty());
    // A patch vertex keeps its normal as written.
    let first_patch = teapot.polygons.iter().find(|p| p.patch).unwrap();
    let n = teapot.polygon_normals(first_patch).unwrap();
    assert_eq!(n[0], DVec3::new(-0.902861, -0.0, -0.429934));

    let rings = load("rings.nff");
    assert_eq!(rings.spheres.len(), 150);
    assert_eq!(rings.cones.len(), 150);
    assert_eq!(rings.polygons.len(), 1);
    let c = &rings.cones[0];
    assert_eq!(c.shape.base, DVec3::new(0.930995, 2.61313, 0.0));
    assert_eq!(c.shape.apex, DVec3::new(0.287693, 1.7277, 0.0));
    assert_eq!(
        (c.shape.base_radius, c.shape.apex_radius),
        (0.07412, 0.07412)
    );

    let tetra = load("tetra.nff");
    assert_eq!(tetra.polygons.len(), 16);
}

#[test]
fn cone_on_one_line_or_two() {
    let one = ok(&format!("{HEAD}c 0 0 0 1 0 0 2 0.5\n"));
    let two = ok(&format!("{HEAD}c\n0 0 0 1\n0 0 2 0.5\n"));
    let split = ok(&format!("{HEAD}c 0 0 0 1\n0 0 2 0.5\n"));
    assert_eq!(one.cones[0].shape.base, two.cones[0].shape.base);
    assert_eq!(one.cones[0].shape.apex, two.cones[0].shape.apex);
    assert_eq!(one.cones[0].shape.apex_radius, 0.5);
    assert_eq!(split.cones[0].shape.apex, DVec3::new(0.0, 0.0, 2.0));
    // A cone with a point apex is fine.
    ok(&format!("{HEAD}c 0 0 0 1 0 0 2 0\n"));
}

/// NFF's negative radii (an inside-out cone, only its inside visible) are
/// read as their magnitudes: rrt shades both sides of every surface, as
/// `embree_nff` does. A zero radius goes with either sign.
#[test]
fn inside_out_cones_are_their_magnitudes() {
    let outside = ok(&format!("{HEAD}c 0 0 0 1 0 0 2 0.5\n"));
    let inside = ok(&format!("{HEAD}c 0 0 0 -1 0 0 2 -0.5\n"));
    assert_eq!(outside.cones[0].shape, inside.cones[0].shape);
    let point = ok(&format!("{HEAD}c 0 0 0 -1 0 0 2 0\n"));
    assert_eq!(point.cones[0].shape.base_radius, 1.0);
    assert_eq!(point.cones[0].shape.apex_radius, 0.0);
    let base_point = ok(&format!("{HEAD}c 0 0 0 0 0 0 2 -0.5\n"));
    assert_eq!(base_point.cones[0].shape.apex_radius, 0.5);
}

#[test]
fn lights_with_and_without_colour() {
    let s = ok(&format!("{HEAD}l 1 2 3\nl 4 5 6 0.5 0.25 2\ns 0 0 0 1\n"));
    assert_eq!(s.lights[0].colour, None);
    assert_eq!(s.lights[1].colour, Some(DVec3::new(0.5, 0.25, 2.0)));
    assert_eq!(s.lights[1].position, DVec3::new(4.0, 5.0, 6.0));
}

#[test]
fn comments_blank_lines_and_crlf() {
    let src = "# a scene\r\n\r\nb 0 0 0 # black\r\nv\r\nfrom 0 0 5\r\nat 0 0 0\r\n# between view lines\r\nup 0 1 0\r\nangle 45\r\nhither 0.01\r\nresolution 64 48\r\n\ts\t0 0 0   1 #sphere\r\n";
    let s = ok(src);
    assert_eq!(s.spheres.len(), 1);
    assert_eq!(s.spheres[0].loc.line, 12);
    assert_eq!(s.spheres[0].loc.column, 2);
    assert_eq!(s.view.resolution, [64, 48]);
    // No final newline.
    ok(&format!("{HEAD}s 0 0 0 1"));
}

#[test]
fn default_material_as_nff_h() {
    // No `f` at all: the default grey.
    let s = ok(&format!("{HEAD}s 0 0 0 1\n"));
    assert_eq!(s.materials, vec![Material::DEFAULT]);
    assert_eq!(s.spheres[0].material, 0);
    // Objects before the first `f` take material 0, the file's first `f`
    // (what nff.h and so embree_nff do).
    let s = ok(&format!(
        "{HEAD}s 0 0 0 1\nf 1 0 0 1 0 0 0 1\ns 1 0 0 1\nf 0 1 0 1 0 0 0 1\np 3\n0 0 0\n1 0 0\n0 1 0\n"
    ));
    assert_eq!(s.materials.len(), 2);
    assert_eq!(s.spheres[0].material, 0);
    assert_eq!(s.spheres[1].material, 0);
    assert_eq!(s.polygons[0].material, 1);
}

#[test]
fn transmitting_material_and_patch() {
    let s = ok(&format!(
        "{HEAD}f 1 1 1 0.2 0.3 20 0.7 1.5\npp 3\n0 0 0 0 0 2\n1 0 0 0 0 1\n0 1 0 0 1 1\n"
    ));
    let m = &s.materials[0];
    assert_eq!((m.transmittance, m.ior), (0.7, 1.5));
    assert_eq!(s.patch_count(), 1);
    // Normals are kept as written; fit normalises them.
    assert_eq!(
        s.polygon_normals(&s.polygons[0]).unwrap()[0],
        DVec3::new(0.0, 0.0, 2.0)
    );
}

/// A non-convex polygon (as the teeth of the SPD gears make their faces)
/// is the region its outline bounds: its triangles are that region's ears,
/// not the fan from vertex 0 (which folds back at the notches and covers
/// them), each winding like the polygon, so refraction enters and leaves
/// the same way on all of it, with the patch normals of its vertices.
#[test]
fn non_convex_polygons_are_their_ears() {
    let outline = rrt_tests::COMB;
    for patch in [false, true] {
        let mut src = format!("{HEAD}f 1 1 1 0.2 0.3 20 0.7 1.5\n");
        src += &format!("{} {}\n", if patch { "pp" } else { "p" }, outline.len());
        for (k, (x, y)) in outline.iter().enumerate() {
            if patch {
                // Normal k's x records which vertex it belongs to.
                src += &format!("{x} {y} 0 {k} 0 1\n");
            } else {
                src += &format!("{x} {y} 0\n");
            }
        }
        let s = ok(&src);
        let p = &s.polygons[0];
        let v = s.polygon_vertices(p);
        let tris: Vec<_> = s.polygon_triangles(p).collect();
        assert_eq!(tris.len(), outline.len() - 2);
        assert_eq!(p.triangle_count(), tris.len());
        let mut area = 0.0;
        for (t, tri) in tris.iter().enumerate() {
            let [a, b, c] = tri.vertices;
            let twice = (b - a).cross(c - a).z;
            assert!(twice > 0.0, "triangle {t} winds clockwise");
            area += twice / 2.0;
            // Inside the comb: not in a notch (above y = 1 between its teeth).
            let m = (a + b + c) / 3.0;
            let notch = m.y > 1.0 && ((0.5..1.0).contains(&m.x) || (2.0..3.0).contains(&m.x));
            assert!(!notch, "triangle {t} covers a notch");
            if let Some(n) = tri.normals {
                for (vertex, normal) in tri.vertices.iter().zip(n) {
                    let k = v.iter().position(|w| w == vertex).unwrap();
                    assert_eq!(normal.x, k as f64, "triangle {t}: normal not its vertex's");
                }
            } else {
                assert!(!patch);
            }
        }
        // The comb's area: 4 × 1 below its teeth, and its teeth 0.5 + 1 + 1 wide and 2 high.
        assert!(
            (area - 9.0).abs() < 1e-12,
            "the triangles cover {area}, not the comb's 9"
        );
    }
}

// ------------------------------------------------------------- bad input

/// A non-convex polygon of more than 65536 vertices is refused at its
/// vertex count (cutting it into ears would cost time and memory that grow
/// with it); a convex one of that size is its fan.
#[test]
fn huge_non_convex_polygons_are_refused_at_their_count() {
    let n = rrt_host::scene::polygon::MAX_NONCONVEX_VERTICES + 4;
    let outline = |teeth: bool| {
        let mut src = format!("f 1 1 1 0.2 0.3 20 0 0\np {n}\n");
        for k in 0..n {
            let a = std::f64::consts::TAU * k as f64 / n as f64;
            let r = if teeth && k % 2 == 0 { 0.8 } else { 1.0 };
            src += &format!("{} {} 0\n", r * a.cos(), r * a.sin());
        }
        src
    };
    assert_eq!(
        err_body(&outline(true)),
        "scene.nff:9:3: polygon vertex count: non-convex, with more than 65536 vertices (the \
         most a non-convex polygon may have): split it into smaller polygons"
    );
    let s = ok(&format!("{HEAD}{}", outline(false)));
    assert_eq!(s.polygon_triangles(&s.polygons[0]).count(), n - 2);
}

/// The non-convex polygons of a scene share one budget of ear-clipping
/// work, the squares of their vertex counts adding up to at most 2^32: a
/// non-convex polygon of 65536 vertices spends it all, and the next
/// non-convex polygon, however small, is refused at its vertex count.
/// Convex polygons cost nothing.
#[test]
fn non_convex_polygons_share_one_budget() {
    let n = rrt_host::scene::polygon::MAX_NONCONVEX_VERTICES;
    let mut src = format!("f 1 1 1 0.2 0.3 20 0 0\np {n}\n");
    for k in 0..n {
        let a = std::f64::consts::TAU * k as f64 / n as f64;
        let r = if k % 2 == 0 { 0.8 } else { 1.0 };
        src += &format!("{} {} 0\n", r * a.cos(), r * a.sin());
    }
    src += "p 4\n0 0 1\n1 0 1\n1 1 1\n0 1 1\n";
    let comb_line = 9 + n + 1 + 4 + 1;
    src += &format!("p {}\n", rrt_tests::COMB.len());
    for (x, y) in rrt_tests::COMB {
        src += &format!("{x} {y} 2\n");
    }
    assert_eq!(
        err_body(&src),
        format!(
            "scene.nff:{comb_line}:3: polygon vertex count: non-convex, and cutting it into \
             triangles would take the scene's non-convex polygons past their budget (the squares \
             of their vertex counts may add up to 2^32, one polygon of 65536 vertices): split \
             them into smaller polygons"
        )
    );
}

#[test]
fn negative_radius_names_file_line_field() {
    assert_eq!(
        err_body("s 0 0 0 -1\n"),
        r#"scene.nff:8:9: sphere radius: expected a positive number, found "-1""#
    );
    assert_eq!(
        err_body("s 0 0 0 0\n"),
        r#"scene.nff:8:9: sphere radius: expected a positive number, found "0""#
    );
}

#[test]
fn truncated_lines() {
    assert_eq!(
        err_body("s 0 0 0\n"),
        "scene.nff:8:8: sphere radius: expected a number, found end of line"
    );
    assert_eq!(
        err_body("f 1 1 1 1 0 0 0\ns 0 0 0 1\n"),
        "scene.nff:8:16: material index of refraction: expected a number, found end of line"
    );
    assert_eq!(
        err_body("l 1 2 3 4 5\ns 0 0 0 1\n"),
        "scene.nff:8:12: light colour: expected a number, found end of line"
    );
    assert_eq!(
        err_body("p 3\n0 0 0\n1 0\n0 1 0\n"),
        "scene.nff:10:4: polygon vertex: expected a number, found end of line"
    );
    assert_eq!(
        err_body("pp 3\n0 0 0 0 0 1\n1 0 0 0 0 1\n0 1 0 0 0\n"),
        "scene.nff:11:10: patch normal: expected a number, found end of line"
    );
    // Fewer vertex lines than announced: refused from the count when the
    // file is too short, else at the end of the file.
    assert_eq!(
        err_body("p 3\n0 0 0\n1 0 0\n"),
        "scene.nff:8:3: polygon vertex count: 3 vertices announced, but only 2 lines remain in the file"
    );
    assert_eq!(
        err_body("p 3\n0 0 0\n1 0 0\n# the end\n"),
        "scene.nff:10:6: polygon vertex: expected a line `vert.x vert.y vert.z`, found end of file"
    );
    assert_eq!(
        err_body("c 0 0 0 1\n"),
        "scene.nff:8:10: cone apex: expected apex.x apex.y apex.z apex_radius, found end of file"
    );
    assert_eq!(
        err("v\nfrom 0 0 5\nat 0 0 0\n"),
        "scene.nff:3:9: view: expected an `up` line, found end of file"
    );
}

#[test]
fn letters_where_numbers_belong() {
    assert_eq!(
        err_body("s 0 x 0 1\n"),
        r#"scene.nff:8:5: sphere centre: expected a number, found "x""#
    );
    assert_eq!(
        err_body("b 0 0 zero\n"),
        r#"scene.nff:8:7: background colour: expected a number, found "zero""#
    );
    assert_eq!(
        err_body("s 0 0 0 1,5\n"),
        r#"scene.nff:8:9: sphere radius: expected a number, found "1,5""#
    );
    // The next directive where a field belongs (a line too short).
    assert_eq!(
        err_body("p 3\n0 0 0\n1 0 0\ns 0 0 0 1\n"),
        r#"scene.nff:11:1: polygon vertex: expected a number, found "s""#
    );
}

#[test]
fn nan_and_inf_are_refused() {
    for (tok, col) in [
        ("NaN", 9),
        ("nan", 9),
        ("inf", 9),
        ("-inf", 9),
        ("infinity", 9),
        ("1e999", 9),
    ] {
        assert_eq!(
            err_body(&format!("s 0 0 0 {tok}\n")),
            format!("scene.nff:8:{col}: sphere radius: expected a finite number, found \"{tok}\""),
        );
    }
    assert_eq!(
        err("v\nfrom 0 0 nan\n"),
        r#"scene.nff:2:10: view from: expected a finite number, found "nan""#
    );
    assert_eq!(
        err_body("p 3\n0 0 0\n1 inf 0\n0 1 0\n"),
        r#"scene.nff:10:3: polygon vertex: expected a finite number, found "inf""#
    );
}

#[test]
fn numbers_beyond_the_world_limit_are_refused() {
    // Squares of such numbers overflow the exact arithmetic: refused at
    // the number, whatever field it is; the limit itself is accepted.
    assert_eq!(
        err_body("s 0 0 0 1e61\n"),
        r#"scene.nff:8:9: sphere radius: expected a number within ±1e60, found "1e61""#
    );
    assert_eq!(
        err("v\nfrom 0 -2e100 0\n"),
        r#"scene.nff:2:8: view from: expected a number within ±1e60, found "-2e100""#
    );
    assert_eq!(
        err_body("l 1e300 0 0\n"),
        r#"scene.nff:8:3: light position: expected a number within ±1e60, found "1e300""#
    );
    assert!(parse(&format!("{HEAD}s 0 0 0 1e60\n")).is_ok());
}

#[test]
fn bad_counts() {
    const E: &str = "expected a whole number of vertices, at least 3";
    assert_eq!(
        err_body("p -3\n"),
        format!("scene.nff:8:3: polygon vertex count: {E}, found \"-3\"")
    );
    assert_eq!(
        err_body("p 0\n"),
        format!("scene.nff:8:3: polygon vertex count: {E}, found \"0\"")
    );
    assert_eq!(
        err_body("p 2\n0 0 0\n1 1 1\n"),
        format!("scene.nff:8:3: polygon vertex count: {E}, found \"2\"")
    );
    assert_eq!(
        err_body("pp 3.5\n"),
        format!("scene.nff:8:4: patch vertex count: {E}, found \"3.5\"")
    );
    assert_eq!(
        err_body("p 99999999999999999999999\n"),
        format!("scene.nff:8:3: polygon vertex count: {E}, found \"99999999999999999999999\"")
    );
    assert_eq!(
        err_body("p\n"),
        format!("scene.nff:8:2: polygon vertex count: {E}, found end of line")
    );
    assert_eq!(
        err_body("p 3 0 0 0\n"),
        r#"scene.nff:8:5: polygon vertex count: expected end of line, found "0""#
    );
}

/// A huge count is refused from the input's size, before any allocation.
#[test]
fn absurd_count_refused_before_allocating() {
    let started = Instant::now();
    assert_eq!(
        err_body("p 2000000000\n0 0 0\n1 0 0\n0 1 0\n"),
        "scene.nff:8:3: polygon vertex count: 2000000000 vertices announced, but only 3 lines remain in the file"
    );
    assert_eq!(
        err_body(&format!("pp {}\n", u64::MAX)),
        format!(
            "scene.nff:8:4: patch vertex count: {} vertices announced, but only 0 lines remain in the file",
            u64::MAX
        )
    );
    assert!(started.elapsed() < Duration::from_secs(1));
}

#[test]
fn vertex_total_is_capped() {
    let opts = ParseOptions {
        max_vertices: 10,
        ..ParseOptions::default()
    };
    let tri = "p 4\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n";
    let src = format!("{HEAD}{tri}{tri}{tri}");
    let e = nff::parse_bytes("scene.nff", src.as_bytes(), &opts).unwrap_err();
    assert_eq!(
        e.to_string(),
        "scene.nff:18:3: polygon vertex count: 4 more vertices would make 12, more than the limit of 10 vertices per scene"
    );
    let src = format!("{HEAD}{tri}{tri}");
    let s = nff::parse_bytes("scene.nff", src.as_bytes(), &opts).unwrap();
    assert_eq!(s.vertices.len(), 8);
}

#[test]
fn unknown_directives_with_location() {
    assert_eq!(
        err_body("  sphere 0 0 0 1\n"),
        r#"scene.nff:8:3: unknown directive "sphere": NFF has b, v, l, f, c, s, p, pp and # comments"#
    );
    assert_eq!(
        err_body("S 0 0 0 1\n"),
        r#"scene.nff:8:1: unknown directive "S": NFF has b, v, l, f, c, s, p, pp and # comments"#
    );
    // One vertex too many for the announced count.
    assert_eq!(
        err_body("p 3\n0 0 0\n1 0 0\n0 1 0\n1 1 0\n"),
        r#"scene.nff:12:1: unknown directive "1": NFF has b, v, l, f, c, s, p, pp and # comments"#
    );
    // A view keyword outside a view.
    assert_eq!(
        err_body("from 1 2 3\n"),
        "scene.nff:8:1: `from` outside a view: it belongs on the lines after `v`, in the order from, at, up, angle, hither, resolution"
    );
}

#[test]
fn trailing_tokens() {
    assert_eq!(
        err_body("s 0 0 0 1 2\n"),
        r#"scene.nff:8:11: sphere: expected end of line, found "2""#
    );
    assert_eq!(
        err_body("p 3\n0 0 0 9\n1 0 0\n0 1 0\n"),
        r#"scene.nff:9:7: polygon vertex: expected end of line, found "9""#
    );
    assert_eq!(
        err("v extra\n"),
        r#"scene.nff:1:3: view: expected end of line, found "extra""#
    );
}

#[test]
fn view_lines_in_order() {
    assert_eq!(
        err("v\nat 0 0 0\nfrom 0 0 5\n"),
        r#"scene.nff:2:1: view: expected a `from` line, found "at""#
    );
    assert_eq!(
        err("v\nfrom 0 0 5\nat 0 0 0\nup 0 1 0\nhither 1\nangle 45\nresolution 8 8\n"),
        r#"scene.nff:5:1: view: expected an `angle` line, found "hither""#
    );
    assert_eq!(
        err("v\nfrom 0 0 5\nat 0 0 0\nup 0 1 0\nangle 45\nhither 1\ns 0 0 0 1\n"),
        r#"scene.nff:7:1: view: expected a `resolution` line, found "s""#
    );
    assert_eq!(
        err("v\nfrom 0 0 5\nat 0 0 5\n"),
        "scene.nff:3:1: view at: equals `from`: the view has no direction"
    );
    assert_eq!(
        err("v\nfrom 0 0 5\nat 0 0 0\nup 0 0 2\n"),
        "scene.nff:4:1: view up: zero or parallel to the view direction (at − from): the image has no up"
    );
    assert_eq!(
        err("v\nfrom 0 0 5\nat 0 0 0\nup 0 0 0\n"),
        "scene.nff:4:1: view up: zero or parallel to the view direction (at − from): the image has no up"
    );
    // Directions however short are directions: the camera of each view
    // is the one of the same view with unit vectors.
    let view = |from: &str, up: &str| {
        let src = format!(
            "v\nfrom {from}\nat 0 0 0\nup {up}\nangle 45\nhither 1\nresolution 8 8\ns 0 0 0 1\n"
        );
        let v = parse(&src).unwrap().view;
        let camera = rrt_host::render::camera::Camera::new(&v, 8, 8).unwrap();
        [0, 7].map(|p| camera.primary(p, p).dir)
    };
    assert_eq!(view("0 0 5", "0 1e-300 0"), view("0 0 5", "0 1 0"));
    assert_eq!(view("0 0 1e-300", "0 1 0"), view("0 0 1", "0 1 0"));
    for a in ["0", "180", "-10", "400"] {
        assert_eq!(
            err(&format!("v\nfrom 0 0 5\nat 0 0 0\nup 0 1 0\nangle {a}\n")),
            format!(
                "scene.nff:5:7: view angle: expected an angle in degrees between 0 and 180 (exclusive), found \"{a}\""
            )
        );
    }
    for (r, col) in [
        ("0 64", 12),
        ("64 0", 15),
        ("70000 64", 12),
        ("64 40000", 15),
        ("64.5 64", 12),
        ("-1 5", 12),
    ] {
        let bad = r
            .split(' ')
            .find(|t| ["0", "70000", "40000", "64.5", "-1"].contains(t))
            .unwrap();
        assert_eq!(
            err(&format!(
                "v\nfrom 0 0 5\nat 0 0 0\nup 0 1 0\nangle 45\nhither 1\nresolution {r}\n"
            )),
            format!(
                "scene.nff:7:{col}: view resolution: expected a whole number of pixels from 1 to 32768, found \"{bad}\""
            )
        );
    }
    assert_eq!(
        err("v\nfrom 0 0 5\nat 0 0 0\nup 0 1 0\nangle 45\nhither -1\n"),
        r#"scene.nff:6:8: view hither: expected a distance ≥ 0, found "-1""#
    );
}

#[test]
fn view_and_background_at_most_once() {
    assert_eq!(
        err(&format!("{HEAD}{HEAD}")),
        "scene.nff:8:1: view (v): a second one; the first is on line 1"
    );
    assert_eq!(
        err_body("b 0 0 0\nb 1 1 1\n"),
        "scene.nff:9:1: background (b): a second one; the first is on line 8"
    );
}

#[test]
fn missing_view_or_objects() {
    assert_eq!(
        err("s 0 0 0 1\n"),
        "scene.nff: no view: an NFF scene needs a `v` block (v, from, at, up, angle, hither, resolution)"
    );
    assert_eq!(
        err(&format!("b 0 0 0\n{HEAD}l 1 1 1\nf 1 1 1 1 0 0 0 1\n")),
        "scene.nff: no objects: the scene has no s, c, p or pp"
    );
}

#[test]
fn out_of_range_values() {
    assert_eq!(
        err_body("b 0 1.5 0\n"),
        r#"scene.nff:8:5: background colour: expected a number from 0 to 1, found "1.5""#
    );
    assert_eq!(
        err_body("f 1 1 1 -1 0 0 0 1\n"),
        r#"scene.nff:8:9: material Kd: expected a number ≥ 0, found "-1""#
    );
    assert_eq!(
        err_body("f 1 1 1 1 0 0 1.5 1\n"),
        r#"scene.nff:8:15: material T: expected a number from 0 to 1, found "1.5""#
    );
    assert_eq!(
        err_body("f 1 1 1 1 0 0 0.5 0\n"),
        r#"scene.nff:8:19: material index of refraction: expected a number > 0 (the material transmits: T > 0), found "0""#
    );
    assert_eq!(
        err_body("l 0 0 0 1 -1 1\n"),
        r#"scene.nff:8:11: light colour: expected a number ≥ 0, found "-1""#
    );
    assert_eq!(
        err_body("c 0 0 0 -1 0 0 1 1\n"),
        r#"scene.nff:8:18: cone apex radius: expected a number ≤ 0 (the base radius is negative: an inside-out cone), found "1""#
    );
    assert_eq!(
        err_body("c 0 0 0 1 0 0 1 -0.5\n"),
        r#"scene.nff:8:17: cone apex radius: expected a number ≥ 0 (the base radius is positive), found "-0.5""#
    );
    assert_eq!(
        err_body("c 0 0 0 1 0 0 0 1\n"),
        "scene.nff:8:1: cone: base and apex coincide: the cone has no axis"
    );
    assert_eq!(
        err_body("c 0 0 0 0 0 0 1 0\n"),
        "scene.nff:8:1: cone: both radii are 0: the cone has no surface"
    );
    assert_eq!(
        err_body("pp 3\n0 0 0 0 0 1\n1 0 0 0 0 0\n0 1 0 0 0 1\n"),
        "scene.nff:10:7: patch normal: zero (or too large) vector: it has no direction"
    );
}

#[test]
fn missing_file_directory_empty_binary() {
    let dir = std::env::temp_dir().join(format!("rrt-nff-test-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();

    let missing = dir.join("no-such.nff");
    let e = Scene::load(&missing).unwrap_err();
    assert_eq!(e.to_string(), format!("cannot read {}", missing.display()));
    let source = std::error::Error::source(&e).expect("an io::Error source");
    assert!(source.to_string().contains("No such file"), "{source}");

    let e = Scene::load(&dir).unwrap_err();
    assert_eq!(
        e.to_string(),
        format!("{}: is a directory, not an NFF file", dir.display())
    );

    let empty = dir.join("empty.nff");
    std::fs::write(&empty, "").unwrap();
    assert_eq!(
        Scene::load(&empty).unwrap_err().to_string(),
        format!("{}: empty file: no NFF directives", empty.display())
    );
    assert_eq!(
        err("  \n\n# only a comment\n\t\n"),
        "scene.nff: empty file: no NFF directives"
    );

    let binary = dir.join("garbage.nff");
    std::fs::write(&binary, b"b 0 0 0\n\x7fELF\x02\x01\x01\x00\x00").unwrap();
    assert_eq!(
        Scene::load(&binary).unwrap_err().to_string(),
        format!(
            "{}:2:8: not a text file: a NUL byte (binary data?)",
            binary.display()
        )
    );
    assert_eq!(
        Scene::parse("scene.nff", b"s 0 0 \xff\xfe 1\n")
            .unwrap_err()
            .to_string(),
        "scene.nff:1:7: not a text file: invalid UTF-8 (binary data?)"
    );
    // Valid UTF-8 that is not NFF.
    assert_eq!(
        err("ünïcødé\n"),
        r#"scene.nff:1:1: unknown directive "ünïcødé": NFF has b, v, l, f, c, s, p, pp and # comments"#
    );
    // A long garbage token is cut in the message.
    let long = "x".repeat(1000);
    let msg = err(&long);
    assert!(msg.len() < 200, "{msg}");
    assert!(msg.contains("xxxx…\""), "{msg}");

    let big = dir.join("big.nff");
    std::fs::write(&big, format!("{HEAD}s 0 0 0 1\n")).unwrap();
    let opts = ParseOptions {
        max_file_bytes: 16,
        ..ParseOptions::default()
    };
    assert_eq!(
        nff::load(&big, &opts).unwrap_err().to_string(),
        format!(
            "{}: 79 bytes, more than the limit of 16 bytes for an NFF file",
            big.display()
        )
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Random corruptions of real scenes: the parser returns a scene that
/// keeps its guarantees, or an error that names the file; it never panics
/// and stays fast. Each case is seeded, so a failure can be replayed.
#[test]
fn corrupted_scenes_never_panic() {
    let bases: Vec<Vec<u8>> = ["balls1.nff", "tetra.nff"]
        .iter()
        .map(|n| std::fs::read(test_data(n)).unwrap())
        .chain([
            format!("{HEAD}c 0 0 0 1 0 0 2 0.5\npp 3\n0 0 0 0 0 1\n1 0 0 0 0 1\n0 1 0 0 0 1\nl 1 1 1 1 1 1\n")
                .into_bytes(),
        ])
        .collect();
    const PIECES: [&[u8]; 14] = [
        b" ",
        b"\n",
        b"#",
        b"-",
        b"nan",
        b"1e999",
        b"p 3\n",
        b"pp 2000000000\n",
        b"v\n",
        b"\xff",
        b"\0",
        b"c\n",
        b"0.5 ",
        b"\r\n",
    ];
    let started = Instant::now();
    let (mut oks, mut errs) = (0, 0);
    for seed in 0..3000u64 {
        let mut rng = Rng::new(seed);
        let mut data = bases[rng.below(bases.len() as u64) as usize].clone();
        for _ in 0..=rng.below(4) {
            let at = rng.below(data.len() as u64 + 1) as usize;
            match rng.below(5) {
                0 => data.truncate(at),
                1 if at < data.len() => data[at] = rng.next_u64() as u8,
                2 if at < data.len() => {
                    data.remove(at);
                }
                3 => {
                    let piece = PIECES[rng.below(PIECES.len() as u64) as usize];
                    data.splice(at..at, piece.iter().copied());
                }
                _ => {
                    // Duplicate a slice (repeats directives and vertex lines).
                    let end = (at + rng.below(64) as usize).min(data.len());
                    let copy = data[at..end].to_vec();
                    data.splice(at..at, copy);
                }
            }
        }
        // The fuzz target's checks: parse, camera, fit.
        check::nff_input(&data).unwrap_or_else(|e| panic!("seed {seed}: {e}"));
        match Scene::parse("fuzz.nff", &data) {
            Ok(_) => oks += 1,
            Err(_) => errs += 1,
        }
    }
    // Pure garbage, too.
    for seed in 0..500u64 {
        let mut rng = Rng::new(1_000_000 + seed);
        let data: Vec<u8> = (0..rng.below(300)).map(|_| rng.next_u64() as u8).collect();
        check::nff_input(&data).unwrap_or_else(|e| panic!("garbage seed {seed}: {e}"));
    }
    assert!(oks > 100 && errs > 100, "{oks} parsed, {errs} refused");
    assert!(started.elapsed() < Duration::from_secs(30));
}
