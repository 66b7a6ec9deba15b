//! Textures: image maps (planar, cylindrical, spherical; wrap modes;
//! PNG and JPEG), solid textures (checker, marble, wood), colours written
//! into voxel records by the core's builder, and bad image files.

use std::f64::consts::{PI, TAU};
use std::path::{Path, PathBuf};

use glam::DVec3;
use rrt_core::fixed::voxel_centre;
use rrt_core::raster::Extent;
use rrt_core::store::Texture;
use rrt_core::voxelize::{NORMAL_ONE, Surfel, VoxelSink};
use rrt_host::assets::texture::{
    Blend, Checker, ImageTexture, Mapping, Marble, TextureError, Wood, WorldTexture, Wrap,
};
use rrt_host::frame::RasterFrame;
use rrt_host::voxelize::texture::InRaster;
use rrt_tests::store::OneObject;

fn tmp(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("textures");
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

/// A 4×2 image, every pixel different: pixel (x, y) = (60x, 100y, 7).
fn pixel(x: u32, y: u32) -> [u8; 3] {
    [(60 * x) as u8, (100 * y) as u8, 7]
}

/// Writes the 4×2 image to a file of its own per caller (tests run in
/// parallel in one process, so a shared path would race).
fn write_png(tag: &str) -> PathBuf {
    let p = tmp(&format!("4x2-{tag}.png"));
    let img = image::RgbImage::from_fn(4, 2, |x, y| image::Rgb(pixel(x, y)));
    img.save(&p).unwrap();
    p
}

const UP: DVec3 = DVec3::Z;

#[test]
fn planar_mapping_through_the_raster_frame() {
    let png = write_png("1");
    // The image spans 4 × 2 world units on the xy plane: one unit a pixel.
    let planar = Mapping::Planar {
        origin: DVec3::ZERO,
        u_axis: DVec3::new(4.0, 0.0, 0.0),
        v_axis: DVec3::new(0.0, 2.0, 0.0),
    };
    let tex = ImageTexture::open(&png, planar).unwrap();
    assert_eq!(tex.size(), [4, 2]);
    let frame = RasterFrame {
        extent: Extent::cube(16).unwrap(),
        origin: DVec3::ZERO,
        voxel_size: 1.0,
    };
    let t = InRaster::new(tex.clone(), frame, Blend::Replace);
    let n = [0, 0, NORMAL_ONE];
    // Voxel (i, j) has centre (i + ½, j + ½): pixel column i, and row 1 − j
    // (v points up the image).
    for i in 0..4 {
        for j in 0..2 {
            let c = [voxel_centre(i), voxel_centre(j), voxel_centre(5)];
            assert_eq!(t.color(c, n, [0; 3]), pixel(i, 1 - j), "voxel ({i}, {j})");
        }
    }
    // Repeat: voxel 4 is column 0 again; y = 2 is row 1 again.
    assert_eq!(
        t.color([voxel_centre(5), voxel_centre(2), 0], n, [0; 3]),
        pixel(1, 1)
    );
    // Bilinear halfway between columns 1 and 2 of the top row.
    let mid = tex.world_color(DVec3::new(2.0, 1.5, 0.0), UP, [0; 3]);
    assert_eq!(mid, [90, 0, 7]);
    // Scale 2 along u: two copies across the same 4 units; clamp and
    // mirror outside [0, 1). Along the top row, at world x:
    let twice = tex.clone().with_transform([2.0, 1.0], [0.0, 0.0]).unwrap();
    let clamp = tex.clone().with_wrap(Wrap::Clamp);
    let mirror = tex.clone().with_wrap(Wrap::Mirror);
    for (t, x, want) in [
        (&twice, 0.25, pixel(0, 0)),
        (&twice, 2.25, pixel(0, 0)),
        (&twice, 1.75, pixel(3, 0)),
        (&clamp, -7.0, pixel(0, 0)),
        (&clamp, 9.0, pixel(3, 0)),
        (&mirror, 4.5, pixel(3, 0)),
        (&mirror, 7.5, pixel(0, 0)),
    ] {
        let p = DVec3::new(x, 1.5, 0.0);
        assert_eq!(t.world_color(p, UP, [0; 3]), want, "x = {x}");
    }
    // Modulate: texel × base / 255.
    let m = InRaster::new(tex, frame, Blend::Modulate);
    let c = [voxel_centre(3), voxel_centre(0), 0];
    assert_eq!(m.color(c, n, [255, 128, 0]), [180, 50, 0]);
}

/// `tex` shows pixel `(i, row)` at `point(i, angle, at)` for each column
/// `i` (at angle `(i + ½)/4 · 2π`) and each `(at, row)` of `rows`.
#[track_caller]
fn assert_columns(tex: &ImageTexture, rows: &[(f64, u32)], point: impl Fn(u32, f64, f64) -> DVec3) {
    for i in 0..4u32 {
        let a = (f64::from(i) + 0.5) / 4.0 * TAU;
        for &(at, row) in rows {
            let p = point(i, a, at);
            assert_eq!(
                tex.world_color(p, UP, [0; 3]),
                pixel(i, row),
                "col {i} row {row} at {at}"
            );
        }
    }
}

#[test]
fn cylindrical_and_spherical_mapping() {
    let png = write_png("2");
    let cyl = ImageTexture::open(
        &png,
        Mapping::Cylindrical {
            origin: DVec3::new(1.0, 1.0, 0.0),
            axis: DVec3::new(0.0, 0.0, 4.0),
            reference: DVec3::X,
        },
    )
    .unwrap();
    // Column i at angle (i + ½)/4 · 2π; row 0 (top) at v = 0.75 (z = 3),
    // row 1 at v = 0.25 (z = 1); any radius.
    assert_columns(&cyl, &[(3.0, 0), (1.0, 1), (7.0, 0)], |i, a, z| {
        let r = 0.5 + f64::from(i);
        DVec3::new(1.0 + r * a.cos(), 1.0 + r * a.sin(), z)
    });
    // On the axis there is no angle: the base colour.
    assert_eq!(
        cyl.world_color(DVec3::new(1.0, 1.0, 2.0), UP, [9; 3]),
        [9; 3]
    );

    let sph = ImageTexture::open(
        &png,
        Mapping::Spherical {
            centre: DVec3::new(0.0, 0.0, 10.0),
            pole: DVec3::Z,
            reference: DVec3::Y,
        },
    )
    .unwrap();
    // Longitude from +y toward −x ((z × y) = −x); row 0 at 45° from the
    // north pole (v = 0.75), row 1 at 45° from the south pole.
    let rows = [(PI / 4.0, 0), (3.0 * PI / 4.0, 1)];
    assert_columns(&sph, &rows, |_, lon, polar| {
        let dir = DVec3::new(
            -polar.sin() * lon.sin(),
            polar.sin() * lon.cos(),
            polar.cos(),
        );
        DVec3::new(0.0, 0.0, 10.0) + dir * 3.0
    });
    assert_eq!(
        sph.world_color(DVec3::new(0.0, 0.0, 10.0), UP, [9; 3]),
        [9; 3]
    );

    // Unusable mappings are refused.
    let bad = |m: Mapping| {
        ImageTexture::from_rgb(1, 1, vec![[0; 3]], m)
            .unwrap_err()
            .to_string()
    };
    assert!(
        bad(Mapping::Planar {
            origin: DVec3::ZERO,
            u_axis: DVec3::X,
            v_axis: DVec3::X * 2.0
        })
        .contains("parallel")
    );
    assert!(
        bad(Mapping::Cylindrical {
            origin: DVec3::ZERO,
            axis: DVec3::Z,
            reference: DVec3::Z
        })
        .contains("reference")
    );
    assert!(
        bad(Mapping::Spherical {
            centre: DVec3::NAN,
            pole: DVec3::Z,
            reference: DVec3::X
        })
        .contains("not finite")
    );
}

#[test]
fn jpeg_and_bad_image_files() {
    let planar = Mapping::Planar {
        origin: DVec3::ZERO,
        u_axis: DVec3::X,
        v_axis: DVec3::Y,
    };
    let jpg = tmp("flat.jpg");
    image::RgbImage::from_pixel(16, 16, image::Rgb([200, 120, 40]))
        .save(&jpg)
        .unwrap();
    let t = ImageTexture::open(&jpg, planar).unwrap();
    let c = t.world_color(DVec3::new(0.5, 0.5, 0.0), UP, [0; 3]);
    for (a, b) in c.iter().zip([200u8, 120, 40]) {
        assert!(a.abs_diff(b) <= 3, "{c:?}");
    }
    // Not an image at all.
    let txt = tmp("notes.png");
    std::fs::write(&txt, "these are notes, not pixels").unwrap();
    let e = ImageTexture::open(&txt, planar).unwrap_err();
    assert!(matches!(e, TextureError::NotImage { .. }));
    assert_eq!(
        e.to_string(),
        format!(
            "{}: not an image: no PNG or JPEG signature (starts with 74 68 65 73 65 20 61 72) (textures are PNG or JPEG)",
            txt.display()
        )
    );
    // Empty, another format, a truncated PNG, a missing file.
    let empty = tmp("empty.png");
    std::fs::write(&empty, []).unwrap();
    assert!(
        ImageTexture::open(&empty, planar)
            .unwrap_err()
            .to_string()
            .contains("the file is empty")
    );
    let gif = tmp("a.gif");
    std::fs::write(&gif, b"GIF89a\x01\x00\x01\x00\x00\x00\x00;").unwrap();
    let e = ImageTexture::open(&gif, planar).unwrap_err().to_string();
    assert!(e.contains("not an image: a Gif image"), "{e}");
    let png = std::fs::read(write_png("3")).unwrap();
    let cut = tmp("cut.png");
    std::fs::write(&cut, &png[..png.len() / 2]).unwrap();
    let e = ImageTexture::open(&cut, planar).unwrap_err();
    assert!(matches!(e, TextureError::Decode { .. }), "{e}");
    assert!(
        e.to_string()
            .starts_with(&format!("{}: cannot decode", cut.display()))
    );
    let e = ImageTexture::open(tmp("missing.png"), planar).unwrap_err();
    assert!(matches!(e, TextureError::Io { .. }), "{e}");
}

#[test]
fn solid_textures() {
    let (a, b) = ([255, 255, 255], [30, 30, 30]);
    let ch = Checker::new(DVec3::new(0.5, 0.0, 0.0), 2.0, [a, b]).unwrap();
    assert_eq!(ch.world_color(DVec3::new(0.6, 0.1, 0.1), UP, [0; 3]), a);
    assert_eq!(ch.world_color(DVec3::new(2.6, 0.1, 0.1), UP, [0; 3]), b);
    assert_eq!(ch.world_color(DVec3::new(2.6, 2.1, 0.1), UP, [0; 3]), a);
    assert_eq!(ch.world_color(DVec3::new(2.6, 2.1, -0.1), UP, [0; 3]), b);
    assert_eq!(ch.world_color(DVec3::new(0.4, 0.1, 0.1), UP, [0; 3]), b);
    assert!(Checker::new(DVec3::ZERO, 0.0, [a, b]).is_err());

    // Marble without turbulence: pure sine bands along the direction.
    let vein = [20, 20, 60];
    let stone = [240, 240, 230];
    let m = Marble::new(1, DVec3::X, 4.0, 1.0, 0.0, 4, [vein, stone]).unwrap();
    assert_eq!(m.world_color(DVec3::new(1.0, 5.0, -3.0), UP, [0; 3]), stone);
    assert_eq!(m.world_color(DVec3::new(3.0, 0.0, 0.0), UP, [0; 3]), vein);
    assert_eq!(
        m.world_color(DVec3::new(4.0, 0.0, 0.0), UP, [0; 3]),
        [130, 130, 145]
    );
    // Its origin moves the pattern: the marble from (1, 0, 0) at p is the
    // marble from the world origin at p − (1, 0, 0).
    let moved = Marble::new(1, DVec3::X, 4.0, 1.0, 0.0, 4, [vein, stone])
        .unwrap()
        .with_origin(DVec3::X)
        .unwrap();
    assert_eq!(
        moved.world_color(DVec3::new(2.0, 5.0, -3.0), UP, [0; 3]),
        stone
    );
    assert_eq!(
        moved.world_color(DVec3::new(4.0, 0.0, 0.0), UP, [0; 3]),
        vein
    );
    assert!(m.clone().with_origin(DVec3::NAN).is_err());
    // With turbulence the veins wander: colours differ off the lattice,
    // depend on the seed, and stay between the two colours.
    let t1 = Marble::new(1, DVec3::X, 4.0, 0.7, 3.0, 5, [vein, stone]).unwrap();
    let t2 = Marble::new(2, DVec3::X, 4.0, 0.7, 3.0, 5, [vein, stone]).unwrap();
    let mut differ = 0;
    for i in 0..200 {
        let p = DVec3::new(
            i as f64 * 0.31,
            (i % 7) as f64 * 0.77,
            (i % 13) as f64 * 0.41,
        );
        let (c1, c2) = (t1.world_color(p, UP, [0; 3]), t2.world_color(p, UP, [0; 3]));
        assert!(c1[0] >= 20 && c1[0] <= 240 && c1[2] >= 60 && c1[2] <= 230);
        differ += usize::from(c1 != c2);
        // Deterministic.
        assert_eq!(c1, t1.world_color(p, UP, [0; 3]));
    }
    assert!(differ > 150, "{differ}");

    // Wood without turbulence: rings every 1 unit around the z axis.
    let early = [200, 150, 90];
    let late = [100, 60, 30];
    let w = Wood::new(3, DVec3::ZERO, DVec3::Z, 1.0, 1.0, 0.0, 3, [early, late]).unwrap();
    assert_eq!(w.world_color(DVec3::new(2.5, 0.0, 7.0), UP, [0; 3]), early);
    assert_eq!(
        w.world_color(DVec3::new(0.0, 3.875, -2.0), UP, [0; 3]),
        [150, 105, 60]
    );
    assert_eq!(w.ring_phase(DVec3::new(3.0, 4.0, 0.0)), 0.0);
    assert!(Wood::new(3, DVec3::ZERO, DVec3::ZERO, 1.0, 1.0, 0.0, 3, [early, late]).is_err());
    assert!(Marble::new(3, DVec3::X, 1.0, 1.0, 0.0, 0, [vein, stone]).is_err());
}

/// The builder's fill pass stores the texture's colour in each record:
/// a row of voxels through a checker of 2-voxel cells.
#[test]
fn texture_colours_land_in_voxel_records() {
    fn row(sink: &mut dyn VoxelSink) {
        for x in 0..8 {
            sink.offer(
                [x, 3, 3],
                Surfel {
                    normal: [0, 0, NORMAL_ONE],
                    distance: 0,
                },
            );
        }
    }
    let extent = Extent::cube(8).unwrap();
    let frame = RasterFrame {
        extent,
        origin: DVec3::new(-4.0, -4.0, -4.0),
        voxel_size: 0.5,
    };
    let (a, b) = ([250, 250, 250], [10, 10, 200]);
    let checker = InRaster::new(
        Checker::new(DVec3::ZERO, 1.0, [a, b]).unwrap(),
        frame,
        Blend::Replace,
    );
    let built = OneObject::textured(extent, [1, 2, 3], &checker, row);
    let store = built.store();
    // Voxel x has world x = −4 + 0.5·x + 0.25; y = z = −2.25 (cell −3,
    // odd): cells 2 voxels wide alternate starting with b at x = 0.
    for x in 0..8u32 {
        let got = store.get_voxel([x, 3, 3]).unwrap().color;
        let wx = -4.0 + 0.5 * f64::from(x) + 0.25;
        let parity = (wx.floor() as i64 + 2 * -3).rem_euclid(2);
        assert_eq!(got, if parity == 0 { a } else { b }, "voxel {x}");
        assert_eq!(
            got,
            checker.color(
                [voxel_centre(x), voxel_centre(3), voxel_centre(3)],
                [0, 0, NORMAL_ONE],
                [1, 2, 3]
            )
        );
    }
}
