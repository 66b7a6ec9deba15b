//! The shadow classification against exact shadow segments: on random
//! scenes of small and overlapping spheres, triangles and cones, with
//! lights inside and outside the raster, every voxel classified *lit* for
//! a light has nothing but its own objects between any of its points and
//! the light, and every voxel classified *occluded* an opaque object on
//! every segment from its points to the light; the classification
//! computed on demand is the pass's; and
//! the exact mode's image with the classification (from the records or
//! on demand) is the image with an exact shadow ray for every light.

use glam::DVec3;
use indicatif::ProgressBar;
use rrt_core::discrete_ray::Connectivity;
use rrt_core::light::{ExactRecords, classify_voxel};
use rrt_core::object_table::Shape as FixedShape;
use rrt_core::voxel::LightVisibility;
use rrt_host::render::camera::Camera;
use rrt_host::render::{Image, RenderOptions, render};
use rrt_host::scene::Scene;
use rrt_host::shape::{Shape, Surface};
use rrt_host::trace::{Mode, RayStats, TraceOptions, Tracer};
use rrt_host::voxelize::light::ShadowLevel;
use rrt_host::voxelize::{BuildOptions, VoxelScene, build};
use rrt_host::world::Ray;
use rrt_tests::Rng;

/// Uniform in `[a, b)`.
fn uniform(rng: &mut Rng, a: f64, b: f64) -> f64 {
    a + (b - a) * ((rng.next_u64() >> 11) as f64 / (1u64 << 53) as f64)
}

fn point(rng: &mut Rng, a: f64, b: f64) -> DVec3 {
    DVec3::new(uniform(rng, a, b), uniform(rng, a, b), uniform(rng, a, b))
}

/// A random scene in [-1, 1]³: spheres, triangles and open cones of about
/// `size` (some translucent), two corner spheres that fix the raster's
/// box, and three lights: one inside the box, two outside.
fn random_scene(seed: u64, objects: usize, size: f64) -> String {
    let mut rng = Rng(seed);
    let mut s = String::from(
        "v\nfrom 0.3 -0.4 6\nat 0 0 0\nup 0 1 0\nangle 40\nhither 0.01\nresolution 48 48\nb 0 0 0\n",
    );
    let inside = point(&mut rng, -0.8, 0.8);
    s.push_str(&format!("l {} {} {}\n", inside.x, inside.y, inside.z));
    s.push_str("l 4 5 6\nl -7 2 -3\n");
    s.push_str("f 1 0.5 0.2 0.7 0.3 10 0 1\ns -1 -1 -1 0.05\ns 1 1 1 0.05\n");
    for i in 0..objects {
        if i % 5 == 4 {
            s.push_str("f 0.3 0.9 0.4 0.6 0.2 8 0.5 1.3\n");
        } else if i % 5 == 0 {
            s.push_str("f 1 0.5 0.2 0.7 0.3 10 0 1\n");
        }
        let c = point(&mut rng, -0.85, 0.85);
        match rng.below(3) {
            0 => {
                let r = uniform(&mut rng, 0.2, 1.0) * size;
                s.push_str(&format!("s {} {} {} {r}\n", c.x, c.y, c.z));
            }
            1 => {
                s.push_str("p 3\n");
                for _ in 0..3 {
                    let v = c + point(&mut rng, -size, size) * 2.0;
                    s.push_str(&format!("{} {} {}\n", v.x, v.y, v.z));
                }
            }
            _ => {
                let a = c + point(&mut rng, -size, size) * 2.0;
                let (r0, r1) = (
                    uniform(&mut rng, 0.0, size),
                    uniform(&mut rng, 0.1, 1.0) * size,
                );
                s.push_str(&format!(
                    "c\n{} {} {} {r0}\n{} {} {} {r1}\n",
                    c.x, c.y, c.z, a.x, a.y, a.z
                ));
            }
        }
    }
    s
}

/// NFF triangles of the mesh of a surface of revolution about the z axis
/// through `c`: `nu` segments around and `nv` bands, ring `j` (parameter
/// `v = j / nv`) at distance and height `surface(v)` from the axis and
/// `c`, each vertex's distance from the axis jittered by up to `jitter`
/// (so neighbouring triangles meet at varied angles); the last ring is
/// the first when `closed` (a torus), and triangles with two equal
/// vertices (at a pole) are left out.
fn revolution_mesh(
    rng: &mut Rng,
    c: DVec3,
    (nu, nv, closed): (usize, usize, bool),
    jitter: f64,
    surface: impl Fn(f64) -> (f64, f64),
) -> String {
    let rings = if closed { nv } else { nv + 1 };
    let ring: Vec<Vec<DVec3>> = (0..rings)
        .map(|j| {
            let (r, h) = surface(j as f64 / nv as f64);
            (0..nu)
                .map(|i| {
                    let a = std::f64::consts::TAU * i as f64 / nu as f64;
                    let r = r * (1.0 + uniform(rng, -jitter, jitter));
                    c + DVec3::new(r * a.cos(), r * a.sin(), h)
                })
                .collect()
        })
        .collect();
    let mut s = String::new();
    let mut tri = |p: [DVec3; 3]| {
        if p[0] == p[1] || p[1] == p[2] || p[2] == p[0] {
            return;
        }
        s.push_str("p 3\n");
        for v in p {
            s.push_str(&format!("{} {} {}\n", v.x, v.y, v.z));
        }
    };
    for j in 0..nv {
        for i in 0..nu {
            let k = (i + 1) % nu;
            let (a, b) = (ring[j][i], ring[j][k]);
            let next = &ring[(j + 1) % rings];
            let (d, e) = (next[i], next[k]);
            tri([a, b, e]);
            tri([a, e, d]);
        }
    }
    s
}

/// A random scene of meshes in [-1, 1]³: a floor of two triangles, a
/// faceted ball and a faceted ring (a torus: it shadows itself) as
/// triangle meshes, a sphere, two corner spheres that fix the raster's
/// box, and three lights: one inside the box, two outside.
fn mesh_scene(seed: u64) -> String {
    let mut rng = Rng(seed);
    let mut s = String::from(
        "v\nfrom 0.3 -2.4 5\nat 0 0 -0.2\nup 0 0 1\nangle 40\nhither 0.01\nresolution 48 48\nb 0 0 0\n",
    );
    let inside = point(&mut rng, -0.3, 0.3) + DVec3::new(0.0, 0.0, 0.5);
    s.push_str(&format!("l {} {} {}\n", inside.x, inside.y, inside.z));
    s.push_str("l 4 -5 6\nl -7 2 3\n");
    s.push_str("f 1 0.5 0.2 0.7 0.3 10 0 1\ns -1 -1 -1 0.05\ns 1 1 1 0.05\n");
    s.push_str("p 3\n-1 -1 -0.9\n1 -1 -0.9\n1 1 -0.9\np 3\n-1 -1 -0.9\n1 1 -0.9\n-1 1 -0.9\n");
    let ball = point(&mut rng, -0.3, 0.3) + DVec3::new(-0.35, 0.0, -0.4);
    let r = uniform(&mut rng, 0.25, 0.4);
    let (nu, nv) = (8 + rng.below(10) as usize, 5 + rng.below(6) as usize);
    s.push_str(&revolution_mesh(
        &mut rng,
        ball,
        (nu, nv, false),
        0.06,
        |v| {
            let a = std::f64::consts::PI * v;
            (r * a.sin(), -r * a.cos())
        },
    ));
    let ring = point(&mut rng, -0.2, 0.2) + DVec3::new(0.4, 0.1, -0.5);
    let (big, small) = (uniform(&mut rng, 0.25, 0.35), uniform(&mut rng, 0.07, 0.12));
    let (nu, nv) = (10 + rng.below(8) as usize, 6 + rng.below(4) as usize);
    s.push_str(&revolution_mesh(
        &mut rng,
        ring,
        (nu, nv, true),
        0.03,
        |v| {
            let a = std::f64::consts::TAU * v;
            (big + small * a.cos(), small * a.sin())
        },
    ));
    let c = point(&mut rng, -0.5, 0.5);
    s.push_str(&format!("s {} {} {} 0.12\n", c.x, c.y, c.z));
    s
}

/// An exact raster (object lists) whose records of exact objects hold
/// `records`: the shadow classification (what `rrt voxelize` saves) or
/// nothing (what `rrt render SCENE` builds for the exact mode).
fn exact(nff: &str, raster: u32, records: ExactRecords) -> VoxelScene {
    let scene = Scene::parse("random.nff", nff.as_bytes()).unwrap();
    let mut o = BuildOptions::new(raster);
    o.fit.max_memory = 1 << 30;
    o.light.exact_records = records;
    let vs = build(&scene, &o, &ProgressBar::hidden()).unwrap().0;
    assert_eq!(vs.exact_records, records);
    vs
}

/// The corners, the centre and four random points of voxel `v`'s cube,
/// in world coordinates.
fn cube_points(vs: &VoxelScene, v: [u32; 3], rng: &mut Rng) -> Vec<DVec3> {
    let lo = vs.frame.origin + DVec3::from(v.map(f64::from)) * vs.frame.voxel_size;
    let mut points: Vec<DVec3> = (0..8)
        .map(|c| {
            let corner = DVec3::new(
                f64::from(c & 1),
                f64::from((c >> 1) & 1),
                f64::from((c >> 2) & 1),
            );
            lo + corner * vs.frame.voxel_size
        })
        .collect();
    points.push(lo + DVec3::splat(0.5 * vs.frame.voxel_size));
    for _ in 0..4 {
        points.push(lo + point(rng, 0.0, 1.0) * vs.frame.voxel_size);
    }
    points
}

/// Every voxel classified lit for a light: segments from its corners, its
/// centre and random points of its cube to the light meet no object but
/// the voxel's own. Returns the (voxel, light) pairs checked.
fn check_lit_voxels(vs: &VoxelScene, seed: u64) -> usize {
    let store = vs.store().unwrap();
    let mut rng = Rng(seed);
    let mut lit = 0;
    for (v, rec) in store.iter() {
        let own = store.objects(rec);
        if !own.iter().all(|&o| vs.objects[o as usize].shape.is_exact()) {
            continue;
        }
        let points = cube_points(vs, v, &mut rng);
        for (k, light) in vs.lights.iter().enumerate() {
            if rec.light(k) != LightVisibility::Visible {
                continue;
            }
            lit += 1;
            for &p in &points {
                let to = light.position - p;
                let dist = to.length();
                let ray = Ray::new(p, to / dist);
                for (id, o) in vs.objects.iter().enumerate() {
                    if own.contains(&(id as u32)) {
                        continue;
                    }
                    let hit = o.shape.intersect(&ray, 0.0, dist);
                    assert!(
                        hit.is_none(),
                        "seed {seed}: voxel {v:?} (objects {own:?}) classified lit for light {k}, \
                         but object {id} ({}) meets the segment from {p} at {hit:?}",
                        o.shape.kind()
                    );
                }
            }
        }
    }
    lit
}

#[test]
fn lit_voxels_have_only_their_own_objects_between_them_and_each_light() {
    let mut lit = 0;
    for seed in 0..12u64 {
        let (objects, size, raster) = match seed % 3 {
            0 => (30, 0.04, 40),
            1 => (12, 0.15, 32),
            _ => (60, 0.02, 48),
        };
        let vs = exact(
            &random_scene(seed, objects, size),
            raster,
            ExactRecords::Classify,
        );
        lit += check_lit_voxels(&vs, seed);
    }
    eprintln!("{lit} lit (voxel, light) pairs checked");
    // The proof does fire: most voxels of these sparse scenes are lit.
    assert!(lit > 2_000, "{lit} lit (voxel, light) pairs");
}

/// The same on meshes, where the tubes of most voxels run through the
/// neighbouring triangles' voxels, which the proof clears.
#[test]
fn lit_mesh_voxels_have_only_their_own_objects_between_them_and_each_light() {
    let mut lit = 0;
    for seed in 100..106u64 {
        let raster = [32, 40, 48][seed as usize % 3];
        let vs = exact(&mesh_scene(seed), raster, ExactRecords::Classify);
        lit += check_lit_voxels(&vs, seed);
    }
    eprintln!("{lit} lit (voxel, light) pairs checked");
    assert!(lit > 2_000, "{lit} lit (voxel, light) pairs");
}

/// On meshes, the triangles' proofs light voxels that the spheres' alone
/// leave undecided, and never undecide one: [`classify_voxel`] with the
/// triangles' geometry against without it, for every record of exact
/// objects and every light.
#[test]
fn triangles_clear_of_the_cube_leave_mesh_voxels_lit() {
    let (mut gained, mut lit) = (0, 0);
    for seed in 110..114u64 {
        let vs = exact(&mesh_scene(seed), 40, ExactRecords::Skip);
        let raster = vs.raster().unwrap();
        let store = vs.store().unwrap();
        for (v, rec) in store.iter() {
            for light in &vs.lights {
                let light = vs.frame.to_fixed(light.position).unwrap();
                let with = |id: u32| fixed_shape(&vs, id);
                let spheres =
                    |id: u32| fixed_shape(&vs, id).filter(|s| matches!(s, FixedShape::Sphere(_)));
                let a =
                    classify_voxel(&raster, &store, None, with, |_| None, v, rec, light).unwrap();
                let b = classify_voxel(&raster, &store, None, spheres, |_| None, v, rec, light)
                    .unwrap();
                if b == LightVisibility::Visible {
                    assert_eq!(a, b, "seed {seed}: voxel {v:?}");
                }
                lit += usize::from(a == LightVisibility::Visible);
                gained +=
                    usize::from(a == LightVisibility::Visible && b != LightVisibility::Visible);
            }
        }
    }
    eprintln!("{gained} of {lit} lit (voxel, light) pairs lit by the triangles' proofs");
    assert!(gained > lit / 4, "{gained} of {lit}");
}

/// Every voxel classified occluded for a light: the segments from its
/// corners, its centre and random points of its cube to the light each
/// meet an object that lets no light through, from outside it. Returns
/// the (voxel, light) pairs checked.
fn check_occluded_voxels(vs: &VoxelScene, seed: u64) -> usize {
    let store = vs.store().unwrap();
    let mut rng = Rng(seed);
    let mut occluded = 0;
    for (v, rec) in store.iter() {
        let own = store.objects(rec);
        if !own.iter().all(|&o| vs.objects[o as usize].shape.is_exact()) {
            continue;
        }
        let points = cube_points(vs, v, &mut rng);
        for (k, light) in vs.lights.iter().enumerate() {
            if rec.light(k) != LightVisibility::Occluded {
                continue;
            }
            occluded += 1;
            for &p in &points {
                let to = light.position - p;
                let dist = to.length();
                let ray = Ray::new(p, to / dist);
                let blocked = vs.objects.iter().any(|o| {
                    vs.materials[usize::from(o.material)].transmittance == 0.0
                        && o.shape
                            .intersect(&ray, 0.0, dist)
                            .is_some_and(|h| h.t > 1e-9 * dist)
                });
                assert!(
                    blocked,
                    "seed {seed}: voxel {v:?} (objects {own:?}) classified occluded for light \
                     {k}, but no opaque object meets the segment from {p}"
                );
            }
        }
    }
    occluded
}

/// Scenes of larger spheres (a few voxels across) shadow some voxels
/// wholly: every voxel the classification calls occluded is.
#[test]
fn occluded_voxels_have_an_opaque_object_between_them_and_each_light() {
    let mut occluded = 0;
    for seed in 60..66u64 {
        let vs = exact(&random_scene(seed, 25, 0.3), 40, ExactRecords::Classify);
        occluded += check_occluded_voxels(&vs, seed);
        // Large objects: the lit proofs still hold.
        check_lit_voxels(&vs, seed);
    }
    eprintln!("{occluded} occluded (voxel, light) pairs checked");
    assert!(occluded > 200, "{occluded} occluded (voxel, light) pairs");
}

/// The scene's view rendered `size`² with `opts`: the image and counts.
fn draw(vs: &VoxelScene, opts: TraceOptions, size: u32) -> (Image, RayStats) {
    let tracer = Tracer::new(vs, opts).unwrap();
    let cam = Camera::new(&vs.view, size, size).unwrap();
    let (image, stats, _) = render(
        &tracer,
        &cam,
        &RenderOptions::default(),
        &ProgressBar::hidden(),
    )
    .unwrap();
    (image, stats)
}

#[test]
fn classified_shadows_render_as_exact_shadow_rays() {
    let mut occluded = 0;
    for seed in 20..30u64 {
        // Small objects, larger ones that shadow whole voxels, meshes.
        let nff = if seed < 26 {
            random_scene(seed, 40, 0.05)
        } else if seed < 28 {
            random_scene(seed, 25, 0.3)
        } else {
            mesh_scene(seed)
        };
        let vs = exact(&nff, 40, ExactRecords::Classify);
        let rays_only = exact(&nff, 40, ExactRecords::Skip);
        let without = TraceOptions {
            classify_on_demand: false,
            ..TraceOptions::default()
        };
        // The pass's classification, the one computed on demand, and an
        // exact shadow ray for every light of every hit.
        let (a, sa) = draw(&vs, TraceOptions::default(), 48);
        let (b, sb) = draw(&rays_only, TraceOptions::default(), 48);
        let (c, sc) = draw(&rays_only, without, 48);
        for (img, name) in [(&b, "on demand"), (&c, "shadow rays")] {
            assert_eq!(a.rgb, img.rgb, "seed {seed}: {name}");
            assert_eq!(a.linear, img.linear, "seed {seed}: {name}");
        }
        assert!(
            sa.classified > 0 && sc.classified == 0,
            "seed {seed}: {sa:?}"
        );
        // The same function of (voxel, light) either way.
        assert_eq!(sa.classified, sb.classified, "seed {seed}");
        assert_eq!(sa.occluded, sb.occluded, "seed {seed}");
        assert_eq!(sa.shadow, sb.shadow, "seed {seed}");
        assert_eq!(
            sa.classified + sa.occluded + sa.shadow,
            sc.shadow,
            "seed {seed}"
        );
        assert_eq!(sc.occluded, 0, "seed {seed}");
        occluded += sa.occluded;
    }
    // Some lights of hits were proven occluded, without a shadow ray.
    assert!(occluded > 0);
}

/// The render-time shadow rays of the paper's and the verified modes (the
/// classification's uncertain voxels, translucent occluders) walk
/// adaptively by default, skipping empty space: the images are those of
/// 6-connected shadow rays, in fewer steps.
#[test]
fn adaptive_shadow_rays_render_as_six_connected_ones() {
    let mut walked = 0;
    for seed in 60..66u64 {
        let nff = random_scene(seed, 40, if seed % 2 == 0 { 0.05 } else { 0.3 });
        let vs = exact(&nff, 48, ExactRecords::Classify);
        for mode in [Mode::Paper, Mode::Verified] {
            let adaptive = TraceOptions {
                mode,
                ..TraceOptions::default()
            };
            assert_eq!(adaptive.light.mode, Connectivity::Adaptive);
            let mut six = adaptive;
            six.light.mode = Connectivity::Six;
            let (a, sa) = draw(&vs, adaptive, 48);
            let (b, sb) = draw(&vs, six, 48);
            assert_eq!(a.rgb, b.rgb, "seed {seed}, {mode:?}");
            assert_eq!(a.linear, b.linear, "seed {seed}, {mode:?}");
            assert_eq!(sa.shadow, sb.shadow, "seed {seed}, {mode:?}");
            assert!(sa.shadow_steps <= sb.shadow_steps, "seed {seed}, {mode:?}");
            walked += sa.shadow;
        }
    }
    // Shadow rays were fired at render time.
    assert!(walked > 1000, "{walked} shadow rays");
}

/// The fixed-point shape of object `id` that the classification reads:
/// a sphere, or a triangle's vertices, as the fit rounds them.
fn fixed_shape(vs: &VoxelScene, id: u32) -> Option<FixedShape> {
    match vs.objects[id as usize].shape {
        Shape::Sphere(s) => s.to_fixed(&vs.frame).ok().map(FixedShape::Sphere),
        Shape::Triangle(t) => t.to_fixed(&vs.frame).ok().map(FixedShape::Triangle),
        _ => None,
    }
}

/// The classification computed on demand is the pass's: for every record
/// of exact objects and every light, [`classify_voxel`] gives the bits the
/// pass stored; on the random scenes and on meshes.
#[test]
fn on_demand_classification_is_the_pass_classification() {
    let mut compared = 0;
    for seed in 40..48u64 {
        let nff = if seed < 46 {
            random_scene(seed, 50, 0.05)
        } else {
            mesh_scene(seed)
        };
        let vs = exact(&nff, 40, ExactRecords::Classify);
        let raster = vs.raster().unwrap();
        let store = vs.store().unwrap();
        let level = ShadowLevel::of(&store).unwrap();
        let bricks = level.bricks(&store);
        assert!(bricks.is_some());
        let lights: Vec<[i64; 3]> = vs
            .lights
            .iter()
            .map(|l| vs.frame.to_fixed(l.position).unwrap())
            .collect();
        for (v, rec) in store.iter() {
            if !store
                .objects(rec)
                .iter()
                .all(|&o| vs.objects[o as usize].shape.is_exact())
            {
                continue;
            }
            for (k, &light) in lights.iter().enumerate() {
                let shape = |id: u32| fixed_shape(&vs, id);
                let blocker = |id: u32| {
                    let o = &vs.objects[id as usize];
                    match o.shape {
                        Shape::Sphere(s)
                            if vs.materials[usize::from(o.material)].transmittance == 0.0 =>
                        {
                            s.to_fixed(&vs.frame).ok()
                        }
                        _ => None,
                    }
                };
                let got =
                    classify_voxel(&raster, &store, None, shape, blocker, v, rec, light).unwrap();
                assert_eq!(got, rec.light(k), "seed {seed}: voxel {v:?}, light {k}");
                // With the brick level, as a renderer asks: the same.
                let got = classify_voxel(
                    &raster,
                    &store,
                    bricks.as_ref(),
                    shape,
                    blocker,
                    v,
                    rec,
                    light,
                )
                .unwrap();
                assert_eq!(
                    got,
                    rec.light(k),
                    "seed {seed}: voxel {v:?}, light {k}, bricks"
                );
                compared += 1;
            }
        }
    }
    assert!(compared > 5_000, "{compared} (voxel, light) pairs");
}

#[test]
fn the_last_blocker_changes_no_image() {
    for seed in 30..36u64 {
        // Dense scenes, so that neighbouring shadow rays share blockers.
        let nff = random_scene(seed, 80, 0.08);
        let vs = exact(&nff, 40, ExactRecords::Skip);
        let with = |last_blocker| TraceOptions {
            last_blocker,
            ..TraceOptions::default()
        };
        let (a, sa) = draw(&vs, with(true), 64);
        let (b, sb) = draw(&vs, with(false), 64);
        assert_eq!(a.rgb, b.rgb, "seed {seed}");
        assert_eq!(a.linear, b.linear, "seed {seed}");
        assert!(
            sa.last_blocker > 0 && sb.last_blocker == 0,
            "seed {seed}: {sa:?}"
        );
        assert_eq!(sa.shadow, sb.shadow, "seed {seed}");
        assert!(
            sa.shadow_steps < sb.shadow_steps,
            "seed {seed}: {sa:?} {sb:?}"
        );
    }
}
