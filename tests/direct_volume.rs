//! Direct volume rendering with known answers: a uniform slab composited
//! along a ray (with the step correction for the length crossed), early
//! ray termination, opaque geometry inside a volume ending the
//! compositing at its depth, shadows through a volume, and a scene with a
//! volume rendered directly refused by the raster file.

use std::path::{Path, PathBuf};

use glam::DVec3;
use indicatif::ProgressBar;
use rrt_core::Connectivity;
use rrt_host::scene::Scene;
use rrt_host::trace::composite::{Composite, OPAQUE_ENOUGH, corrected_opacity};
use rrt_host::trace::{Mode, RayStats, TraceOptions, Tracer};
use rrt_host::voxelize::{BuildOptions, VoxelScene, build};
use rrt_host::world::{Bounds, Ray};

/// A scene of an 8 × 8 × 4 slab of samples of value 100 whose cells cover
/// `[0, 8] × [0, 8] × [0, 4]`, rendered directly with opacity `alpha` per
/// unit (the sample spacing) and colour white, no lights (a material of
/// kd 2: every sample shows its colour), background `bg`; `extra` adds
/// tables.
fn slab(dir: &Path, alpha: f64, bg: f64, extra: &str) -> PathBuf {
    std::fs::create_dir_all(dir).unwrap();
    std::fs::write(dir.join("slab.raw"), vec![100u8; 8 * 8 * 4]).unwrap();
    let p = dir.join("slab.toml");
    std::fs::write(
        &p,
        format!(
            r#"background = [{bg}, {bg}, {bg}]
[camera]
from = [4.3, 4.6, 20]
at = [4.3, 4.6, 0]
up = [0, 1, 0]
angle = 5
resolution = [3, 3]

[material.white]
kd = 2

[volume.slab]
raw = {{ file = "slab.raw", dims = [8, 8, 4], type = "u8" }}
translate = [0.5, 0.5, 0.5]
render = "direct"
opacity = [[0, 0], [100, {alpha}]]
colours = [[0, 1, 1, 1], [100, 1, 1, 1]]

[[object]]
material = "white"
volume = "slab"
{extra}"#
        ),
    )
    .unwrap();
    p
}

/// The exact raster over `[-2, 10]³` in 12³ voxels of 1: the voxels align
/// with the slab's cells.
fn built(path: &Path) -> VoxelScene {
    let scene = Scene::load(path).unwrap();
    let mut o = BuildOptions::new(12);
    o.fit.bounds = Some(Bounds {
        min: DVec3::splat(-2.0),
        max: DVec3::splat(10.0),
    });
    o.fit.max_memory = 1 << 28;
    build(&scene, &o, &ProgressBar::hidden()).unwrap().0
}

fn trace(vs: &VoxelScene, opts: TraceOptions, ray: Ray) -> (DVec3, RayStats) {
    let t = Tracer::new(vs, opts).unwrap();
    let mut stats = RayStats::default();
    let c = t.trace_primary(&Ray::new(ray.origin, ray.dir.normalize()), &mut stats);
    (c, stats)
}

fn close(a: DVec3, b: DVec3) -> bool {
    (a - b).abs().max_element() < 1e-9
}

/// Along an axis the ray crosses 4 voxels of length 1 (= the sample
/// spacing): `1 − (1 − α)⁴`; along the diagonal `(1, 1, −1)` it crosses
/// a length of 4√3: `1 − (1 − α)^(4√3)`, whatever voxels the walk visits
/// (six-connected and adaptive walks visit every voxel the line passes
/// through, each standing for its chord).
#[test]
fn a_uniform_slab_composites_to_the_known_opacity() {
    let d = rrt_tests::fresh_dir("rrt-test", "dvr-slab");
    let vs = built(&slab(&d, 0.2, 0.0, ""));
    assert_eq!(vs.direct.len(), 1);
    assert_eq!(vs.direct[0].spacing, 1.0);
    let down = Ray::new(DVec3::new(4.3, 4.6, 20.0), DVec3::NEG_Z);
    let diagonal = Ray::new(DVec3::new(-1.7, -1.8, 6.0), DVec3::new(1.0, 1.0, -1.0));
    for connectivity in [Connectivity::Adaptive, Connectivity::Six] {
        for mode in [Mode::Exact, Mode::Verified, Mode::Paper] {
            let opts = TraceOptions {
                mode,
                connectivity,
                ..TraceOptions::default()
            };
            let (c, s) = trace(&vs, opts, down);
            let want = 1.0 - 0.8f64.powi(4);
            assert!(
                close(c, DVec3::splat(want)),
                "{mode:?} {connectivity:?}: {c} {want}"
            );
            assert_eq!(s.samples, 4);
            let (c, s) = trace(&vs, opts, diagonal);
            let want = 1.0 - 0.8f64.powf(4.0 * 3f64.sqrt());
            assert!(
                close(c, DVec3::splat(want)),
                "{mode:?} {connectivity:?}: {c} {want}"
            );
            // Seven voxels of the slab: 4 layers, 3 more where x or y
            // crosses a voxel boundary inside the slab.
            assert!(s.samples >= 4, "{}", s.samples);
        }
    }
    // The whole image: the centre pixel is the ray down the axis.
    let t = Tracer::new(&vs, TraceOptions::default()).unwrap();
    let cam = rrt_host::render::camera::Camera::new(&vs.view, 3, 3).unwrap();
    let opts = rrt_host::render::RenderOptions {
        supersample: 1,
        threads: 1,
        alpha: false,
    };
    let (img, stats, _) =
        rrt_host::render::render(&t, &cam, &opts, &ProgressBar::hidden()).unwrap();
    // Four layers per ray, more where an oblique ray crosses x or y.
    assert!(stats.samples >= 9 * 4, "{}", stats.samples);
    let centre = &img.linear[12..15];
    let want = 1.0 - 0.8f64.powi(4);
    assert!(
        centre.iter().all(|&c| (f64::from(c) - want).abs() < 1e-6),
        "{centre:?} {want}"
    );
}

/// Compositing stops once the opacity reaches [`OPAQUE_ENOUGH`]: through
/// a slab of 0.95 per voxel, two samples give 0.9975; nothing behind
/// (not even the white background) adds to the colour.
#[test]
fn compositing_stops_when_opaque_enough() {
    let d = rrt_tests::fresh_dir("rrt-test", "dvr-early");
    let vs = built(&slab(&d, 0.95, 1.0, ""));
    let down = Ray::new(DVec3::new(4.3, 4.6, 20.0), DVec3::NEG_Z);
    let (c, s) = trace(&vs, TraceOptions::default(), down);
    let a = 1.0 - 0.05f64 * 0.05;
    assert!(a >= OPAQUE_ENOUGH);
    assert!(close(c, DVec3::splat(a)), "{c}");
    assert_eq!(s.samples, 2);
    // With a thinner opacity the background shows through the rest.
    let vs = built(&slab(&d, 0.2, 1.0, ""));
    let (c, s) = trace(&vs, TraceOptions::default(), down);
    assert_eq!(s.samples, 4);
    assert!(close(c, DVec3::ONE), "{c}");
}

/// An opaque polygon inside the slab (at z = 2, half way down) ends the
/// compositing at its depth: two voxels of the slab in front, then the
/// polygon's colour (no lights: its ambient `I·Kd·C` with I = ½) for the
/// rest; the samples behind it do not count.
#[test]
fn opaque_geometry_inside_a_volume_ends_compositing_at_its_depth() {
    let d = rrt_tests::fresh_dir("rrt-test", "dvr-inside");
    let extra = r#"
[material.plate]
colour = [0.2, 0.4, 0.6]
kd = 1

[[object]]
material = "plate"
polygon = [[0, 0, 2], [8, 0, 2], [8, 8, 2], [0, 8, 2]]
"#;
    let vs = built(&slab(&d, 0.2, 0.0, extra));
    let down = Ray::new(DVec3::new(4.3, 4.6, 20.0), DVec3::NEG_Z);
    let a = 1.0 - 0.8f64.powi(2);
    let plate = DVec3::new(0.2, 0.4, 0.6) * 0.5;
    for mode in [Mode::Exact, Mode::Verified] {
        let opts = TraceOptions {
            mode,
            ..TraceOptions::default()
        };
        let (c, s) = trace(&vs, opts, down);
        let want = DVec3::splat(a) + plate * (1.0 - a);
        assert!(close(c, want), "{mode:?}: {c} {want}");
        assert_eq!(s.hits, 1);
    }
}

/// A shadow ray through a volume rendered directly takes its
/// transmittance (the exact mode): a plate under the slab, lit from
/// straight above through the 4 units of 0.2, gets `0.8⁴` of the light.
#[test]
fn shadows_through_a_volume_take_its_transmittance() {
    let d = rrt_tests::fresh_dir("rrt-test", "dvr-shadow");
    let plate = |z: f64| {
        format!(
            "[[light]]\nposition = [4.3, 4.6, 9.5]\n[material.plate]\ncolour = [0.8, 0.8, 0.8]\nkd = 1\n[[object]]\nmaterial = \"plate\"\npolygon = [[-1, -1, {z}], [9, -1, {z}], [9, 9, {z}], [-1, 9, {z}]]\n"
        )
    };
    let vs = built(&slab(&d, 0.2, 0.0, &plate(-1.0)));
    let t = Tracer::new(&vs, TraceOptions::default()).unwrap();
    let mut stats = RayStats::default();
    // From below, straight up at the plate: the light is on the other
    // side of the plate (N·L < 0 for the seen side): nothing but ambient.
    let up = Ray::new(DVec3::new(4.3, 4.6, -1.9), DVec3::Z);
    let c = t.trace_primary(&up, &mut stats);
    // I = 1/2 for one light: ambient 0.5·0.8.
    assert!(close(c, DVec3::splat(0.4)), "{c}");
    // From above, through the slab: ambient + diffuse through 0.8⁴,
    // seen through the slab's 1 − 0.8⁴.
    let down = Ray::new(DVec3::new(4.3, 4.6, 9.0), DVec3::NEG_Z);
    let c = t.trace_primary(&down, &mut stats);
    let to_light = (DVec3::new(4.3, 4.6, 9.5) - DVec3::new(4.3, 4.6, -1.0)).normalize();
    assert!(close(to_light, DVec3::Z));
    let tr = 0.8f64.powi(4);
    let plate_colour = 0.4 + 0.5 * 0.8 * tr;
    let want = (1.0 - tr) * 1.0 + tr * plate_colour;
    // The slab's samples: flat gray levels inside, so unlit white; at
    // the slab's faces the gradient is 0 too (outside neighbours count as
    // the sample itself).
    assert!(close(c, DVec3::splat(want)), "{c} {want}");
    assert!(stats.shadow > 0);
}

/// The composite of a slab one spacing thick is the transfer function's
/// opacity; the correction is exact for any split of a length.
#[test]
fn the_step_correction_adds_up_over_any_split() {
    assert!((corrected_opacity(0.3, 1.0, 1.0) - 0.3).abs() < 1e-15);
    assert_eq!(corrected_opacity(0.3, 0.0, 1.0), 0.0);
    assert_eq!(corrected_opacity(1.0, 0.1, 1.0), 1.0);
    let mut a = Composite::default();
    for len in [0.25, 0.5, 1.0, 0.75, 1.5] {
        a.add(DVec3::ONE, corrected_opacity(0.3, len, 0.5));
    }
    let want = 1.0 - 0.7f64.powf(4.0 / 0.5);
    assert!((a.alpha - want).abs() < 1e-12);
    assert!((a.colour.x - want).abs() < 1e-12);
}

/// The raster lists a volume rendered directly in exactly the voxels
/// whose sample (the one the tracer composites) has an opacity above 0,
/// the voxels it owns with the transfer function's colour of that sample,
/// and marks alone ([`DirectVolume::alone`]) exactly those whose record
/// lists it and nothing else: a volume whose cells do not line up with
/// the voxels (values varying along every axis, half of them clear), with
/// a sphere inside that shares some of its voxels, on one thread and on
/// three (the passes in pieces).
///
/// [`DirectVolume::alone`]: rrt_host::voxelize::direct::DirectVolume::alone
#[test]
fn the_raster_holds_the_visible_samples_with_their_colours() {
    let d = rrt_tests::fresh_dir("rrt-test", "dvr-visible");
    let (nx, ny, nz) = (9usize, 7usize, 5usize);
    let raw: Vec<u8> = (0..nx * ny * nz)
        .map(|i| {
            let (x, y, z) = (i % nx, (i / nx) % ny, i / (nx * ny));
            ((x * 29 + y * 13 + z * 41) % 256) as u8
        })
        .collect();
    std::fs::write(d.join("v.raw"), raw).unwrap();
    let p = d.join("v.toml");
    std::fs::write(
        &p,
        r#"[camera]
from = [4, 3, 20]
at = [4, 3, 2]
up = [0, 1, 0]
angle = 30
resolution = [4, 4]

[volume.v]
raw = { file = "v.raw", dims = [9, 7, 5], type = "u8" }
scale = 0.83
translate = [0.37, 0.21, 0.55]
render = "direct"
opacity = [[0, 0], [120, 0], [255, 0.6]]
colours = [[0, 0, 0, 1], [128, 1, 0.5, 0], [255, 1, 1, 1]]

[material.m]
kd = 1

[[object]]
material = "m"
volume = "v"

[[object]]
material = "m"
sphere = { centre = [4.1, 3.2, 2.3], radius = 1.3 }
"#,
    )
    .unwrap();
    let scene = Scene::load(&p).unwrap();
    let mut first = None;
    for threads in [1, 3] {
        let mut o = BuildOptions::new(12);
        o.threads = threads;
        o.fit.max_memory = 1 << 28;
        let vs = build(&scene, &o, &ProgressBar::hidden()).unwrap().0;
        let store = vs.store().unwrap();
        let [dv] = vs.direct.as_slice() else {
            panic!("one volume rendered directly: {}", vs.direct.len());
        };
        let dims = vs.extent().dims();
        let (mut visible, mut clear, mut shared) = (0, 0, 0);
        for z in 0..dims[2] {
            for y in 0..dims[1] {
                for x in 0..dims[0] {
                    let v = [x, y, z];
                    let value = dv.value(v).map(f64::from);
                    let alpha = value.map_or(0.0, |s| dv.classifier.sample_opacity(s));
                    let rec = store.get_voxel(v);
                    let objects = rec.map_or(&[][..], |r| store.objects(r));
                    let listed = objects.contains(&dv.object);
                    assert_eq!(listed, alpha > 0.0, "{v:?}: {value:?}, {objects:?}");
                    assert_eq!(dv.alone(v), objects == [dv.object], "{v:?}: {objects:?}");
                    if let Some(r) = rec
                        && store.owner(r) == dv.object
                    {
                        let want = dv.classifier.color(value.unwrap(), dv.base);
                        assert_eq!(r.color, want, "{v:?}: {value:?}");
                    }
                    visible += u32::from(listed);
                    shared += u32::from(listed && objects.len() > 1);
                    clear += u32::from(value.is_some() && !listed);
                }
            }
        }
        assert!(
            visible > 50 && clear > 50 && shared > 5,
            "{visible} visible, {clear} clear, {shared} shared"
        );
        let records: Vec<_> = store.records().to_vec();
        match &first {
            None => first = Some(records),
            Some(r) => assert!(r == &records, "records differ on {threads} threads"),
        }
    }
}

/// A raster with a volume rendered directly cannot be saved: `rrt
/// voxelize` says so before voxelizing, and the library's writer refuses
/// it.
#[test]
fn a_volume_rendered_directly_is_not_saved() {
    let d = rrt_tests::fresh_dir("rrt-test", "dvr-save");
    let p = slab(&d, 0.2, 0.0, "");
    let out = d.join("slab.rrt");
    let err = rrt_tests::run_cli(&["voxelize", p.to_str().unwrap(), "-o", out.to_str().unwrap()])
        .unwrap_err();
    assert!(
        err.contains("slab.toml:") && err.contains("cannot be saved"),
        "{err}"
    );
    assert!(!out.exists());
    let vs = built(&p);
    let err = rrt_host::output::rasterfile::save(&vs, &out).unwrap_err();
    assert!(
        err.to_string()
            .contains("cannot save a volume rendered directly"),
        "{err}"
    );
    assert!(!out.exists());
}

/// Renders `vs` from its view at `angle` degrees on `threads` threads,
/// `n × n` pixels, with alpha.
fn render_alpha(vs: &VoxelScene, angle: f64, n: u32, threads: usize) -> rrt_host::render::Image {
    let t = Tracer::new(vs, TraceOptions::default()).unwrap();
    let view = rrt_host::scene::View {
        angle,
        ..vs.view.clone()
    };
    let cam = rrt_host::render::camera::Camera::new(&view, n, n).unwrap();
    let opts = rrt_host::render::RenderOptions {
        supersample: 1,
        threads,
        alpha: true,
    };
    rrt_host::render::render(&t, &cam, &opts, &ProgressBar::hidden())
        .unwrap()
        .0
}

/// A pixel's coverage through a volume rendered directly is the opacity
/// composited along its ray: `1 − 0.8⁴` down the slab's axis, 0 beside
/// it, 1 where compositing stopped (opaque enough) or geometry ended it;
/// the straight colour is the samples' (white) and over the background
/// gives the pixel's colour; the same bits on 1 and 2 threads.
#[test]
fn alpha_through_a_volume_is_the_opacity_composited() {
    let d = rrt_tests::fresh_dir("rrt-test", "dvr-alpha");
    let vs = built(&slab(&d, 0.2, 0.25, ""));
    // Wide enough (60°) for the corners to miss the slab and the raster.
    let img = render_alpha(&vs, 60.0, 9, 1);
    let a = img.alpha.as_ref().unwrap();
    let centre = 4 * 9 + 4;
    let want = 1.0 - 0.8f64.powi(4);
    assert!((f64::from(a.coverage[centre]) - want).abs() < 1e-6);
    assert_eq!(a.coverage[0], 0.0);
    assert_eq!(&a.straight[..3], &[0.25; 3]);
    assert_eq!(&img.linear[..3], &[0.25; 3]);
    let partial = a.coverage.iter().filter(|&&c| c > 0.0 && c < 1.0).count();
    assert!(partial >= 9, "{:?}", a.coverage);
    for (p, &c) in a.coverage.iter().enumerate() {
        let s = &a.straight[3 * p..3 * p + 3];
        let l = &img.linear[3 * p..3 * p + 3];
        if c > 0.0 {
            assert!(s.iter().all(|&v| (v - 1.0).abs() < 1e-5), "{p}: {s:?}");
        }
        for (s, l) in s.iter().zip(l) {
            let over = s * c + 0.25 * (1.0 - c);
            assert!((over - l).abs() < 1e-5, "{p}: {over} {l}");
        }
    }
    let two = render_alpha(&vs, 60.0, 9, 2);
    assert_eq!(two.rgb, img.rgb);
    let bits = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
    let b = two.alpha.as_ref().unwrap();
    assert_eq!(bits(&b.coverage), bits(&a.coverage));
    assert_eq!(bits(&b.straight), bits(&a.straight));
    // Opaque enough: compositing stops and the pixel is covered, its
    // straight colour the pixel's colour exactly.
    let vs = built(&slab(&d, 0.95, 0.25, ""));
    let img = render_alpha(&vs, 5.0, 3, 2);
    let a = img.alpha.as_ref().unwrap();
    assert!(a.coverage.iter().all(|&c| c == 1.0), "{:?}", a.coverage);
    assert_eq!(bits(&a.straight), bits(&img.linear));
    // An opaque plate inside the slab ends every ray: covered.
    let extra = "[material.plate]\ncolour = [0.2, 0.4, 0.6]\n[[object]]\nmaterial = \"plate\"\npolygon = [[0, 0, 2], [8, 0, 2], [8, 8, 2], [0, 8, 2]]\n";
    let vs = built(&slab(&d, 0.2, 0.25, extra));
    let img = render_alpha(&vs, 5.0, 3, 1);
    let a = img.alpha.as_ref().unwrap();
    assert!(a.coverage.iter().all(|&c| c == 1.0), "{:?}", a.coverage);
    assert_eq!(bits(&a.straight), bits(&img.linear));
}
