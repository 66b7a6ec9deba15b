//! Verification over object lists: on random scenes of small and
//! overlapping spheres and triangles (objects 1–3 voxels across, voxels
//! shared by several objects), the renderer's verified hit equals the
//! brute-force nearest exact intersection over every object, for random
//! rays; saved rasters keep the lists.

use glam::DVec3;
use indicatif::ProgressBar;
use rrt_host::output::rasterfile;
use rrt_host::scene::Scene;
use rrt_host::trace::{Mode, RayStats, TraceOptions, Tracer};
use rrt_host::voxelize::{BuildOptions, VoxelScene, build};
use rrt_host::world::Ray;

/// A small deterministic generator (xorshift64*).
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_f491_4f6c_dd1d)
    }
    /// Uniform in `[a, b)`.
    fn range(&mut self, a: f64, b: f64) -> f64 {
        a + (b - a) * ((self.next() >> 11) as f64 / (1u64 << 53) as f64)
    }
    fn point(&mut self, a: f64, b: f64) -> DVec3 {
        DVec3::new(self.range(a, b), self.range(a, b), self.range(a, b))
    }
    fn dir(&mut self) -> DVec3 {
        loop {
            let d = self.point(-1.0, 1.0);
            if d.length_squared() > 1e-3 && d.length_squared() <= 1.0 {
                return d.normalize();
            }
        }
    }
}

const HEADER: &str = "v\nfrom 0 0 6\nat 0 0 0\nup 0 1 0\nangle 40\nhither 0.01\nresolution 32 32\nb 0 0 0\nl 4 5 6\nf 1 0.5 0.2 0.7 0.3 10 0 1\n";

/// `spheres` spheres of radius `r0..r1` and `triangles` triangles of edge
/// about `e` in the cube [-1, 1]³, overlapping at random, plus two
/// corner spheres that fix the raster's box.
fn random_scene(seed: u64, spheres: usize, triangles: usize, r0: f64, r1: f64, e: f64) -> String {
    let mut rng = Rng(seed);
    let mut s = String::from(HEADER);
    s.push_str("s -1 -1 -1 0.05\ns 1 1 1 0.05\n");
    for _ in 0..spheres {
        let c = rng.point(-0.9, 0.9);
        let r = rng.range(r0, r1);
        s.push_str(&format!("s {} {} {} {r}\n", c.x, c.y, c.z));
    }
    for _ in 0..triangles {
        let c = rng.point(-0.9, 0.9);
        s.push_str("p 3\n");
        for _ in 0..3 {
            let v = c + rng.point(-e, e);
            s.push_str(&format!("{} {} {}\n", v.x, v.y, v.z));
        }
    }
    s
}

fn exact_build(nff: &str, raster: u32) -> VoxelScene {
    let scene = Scene::parse("random.nff", nff.as_bytes()).unwrap();
    let mut o = BuildOptions::new(raster);
    o.fit.max_memory = 1 << 30;
    build(&scene, &o, &ProgressBar::hidden()).unwrap().0
}

/// The nearest exact intersection of `ray` with any object (t ≥ 0).
fn brute_force(vs: &VoxelScene, ray: &Ray) -> Option<(u32, f64)> {
    let mut best: Option<(u32, f64)> = None;
    for (i, o) in vs.objects.iter().enumerate() {
        if let Some(h) = o.shape.intersect(ray, 0.0, f64::INFINITY)
            && best.is_none_or(|(_, t)| h.t < t)
        {
            best = Some((u32::try_from(i).unwrap(), h.t));
        }
    }
    best
}

/// Fires `n` random rays (from outside the scene and from inside it) and
/// checks every verified hit against brute force; returns the stats.
fn check_rays(vs: &VoxelScene, seed: u64, n: usize, packets: bool) -> RayStats {
    let tracer = Tracer::new(
        vs,
        TraceOptions {
            mode: Mode::Verified,
            packets,
            ..TraceOptions::default()
        },
    )
    .unwrap();
    let mut rng = Rng(seed);
    let mut stats = RayStats::default();
    // The margin by which a hit may be accepted ahead of the walk, in world
    // units: a few hundred-thousandths of a voxel.
    let tol = 1e-4 * vs.frame.voxel_size;
    let mut hits = 0;
    for k in 0..n {
        let (origin, dir) = if k % 2 == 0 {
            let o = rng.dir() * 3.0;
            let target = rng.point(-1.0, 1.0);
            (o, (target - o).normalize())
        } else {
            (rng.point(-1.0, 1.0), rng.dir())
        };
        let ray = Ray::new(origin, dir);
        let got = tracer.hit(&ray, &mut stats);
        let want = brute_force(vs, &ray);
        match (got, want) {
            (None, None) => {}
            (Some(g), Some((obj, t))) => {
                hits += 1;
                assert!(g.verified, "ray {k} {ray:?}: unverified hit {g:?}");
                assert!(
                    (g.t - t).abs() <= tol,
                    "ray {k} {ray:?}: hit object {} at t {}, brute force object {obj} at t {t}",
                    g.object,
                    g.t
                );
                if g.object != obj {
                    // Only a tie may name another object.
                    let other = vs.objects[g.object as usize]
                        .shape
                        .intersect(&ray, 0.0, f64::INFINITY)
                        .unwrap();
                    assert!(
                        (other.t - t).abs() <= tol,
                        "ray {k}: object {} not at t",
                        g.object
                    );
                }
            }
            (g, w) => panic!("ray {k} {ray:?}: renderer {g:?}, brute force {w:?}"),
        }
    }
    assert!(hits > n / 50, "only {hits} of {n} rays hit");
    stats
}

#[test]
fn verified_hits_equal_brute_force_on_small_overlapping_objects() {
    // Raster 40 over [-1, 1]³ plus margins: a voxel is about 0.05, so the
    // spheres (radius 0.02..0.08) are 1–3 voxels across and crowd voxels.
    for seed in [1, 2, 3] {
        let nff = random_scene(seed, 60, 30, 0.02, 0.08, 0.12);
        let vs = exact_build(&nff, 40);
        assert!(!vs.lists.is_empty(), "seed {seed}: no voxel is shared");
        let stats = check_rays(&vs, seed * 77, 3000, false);
        assert!(stats.shared_hits > 0, "seed {seed}: {stats:?}");
    }
}

#[test]
fn verified_hits_equal_brute_force_on_crowded_voxels() {
    // Many objects far smaller than a voxel: most voxels hold several.
    let nff = random_scene(9, 120, 60, 0.01, 0.04, 0.05);
    let vs = exact_build(&nff, 24);
    let stats = check_rays(&vs, 5, 3000, false);
    assert!(stats.shared_hits > 0, "{stats:?}");
}

#[test]
fn verified_hits_equal_brute_force_on_larger_objects() {
    let nff = random_scene(4, 25, 15, 0.1, 0.4, 0.5);
    let vs = exact_build(&nff, 64);
    check_rays(&vs, 11, 2000, false);
}

#[test]
fn a_small_sphere_in_a_voxel_of_a_triangle_is_found() {
    // A triangle in the plane z = 0 and spheres of a tenth of a voxel just
    // in front of it and just behind it: all share the triangle's voxels.
    let mut nff = String::from(HEADER);
    nff.push_str("s -1 -1 -1 0.05\ns 1 1 1 0.05\n");
    nff.push_str("p 3\n-0.8 -0.8 0\n0.8 -0.8 0\n0 0.8 0\n");
    nff.push_str("s 0.1 0 0.02 0.004\ns -0.1 0 -0.02 0.004\n");
    let vs = exact_build(&nff, 40);
    let tracer = Tracer::new(
        &vs,
        TraceOptions {
            mode: Mode::Verified,
            ..TraceOptions::default()
        },
    )
    .unwrap();
    let mut stats = RayStats::default();
    let kind = |id: u32| vs.objects[id as usize].shape.kind();
    let down = |x: f64| Ray::new(DVec3::new(x, 0.0, 3.0), DVec3::NEG_Z);
    // The sphere in front of the plane is hit first.
    let front = tracer.hit(&down(0.1), &mut stats).unwrap();
    assert_eq!(kind(front.object), "sphere", "{front:?}");
    assert!((front.t - (3.0 - 0.024)).abs() < 1e-9, "{front:?}");
    // Behind the plane: the triangle is.
    let h = tracer.hit(&down(-0.1), &mut stats).unwrap();
    assert_eq!(kind(h.object), "triangle", "{h:?}");
    assert!((h.t - 3.0).abs() < 1e-9, "{h:?}");
    // From below, the one behind is the nearer.
    let up = Ray::new(DVec3::new(-0.1, 0.0, -3.0), DVec3::Z);
    let back = tracer.hit(&up, &mut stats).unwrap();
    assert_eq!(kind(back.object), "sphere", "{back:?}");
    assert_ne!(back.object, front.object);
    assert!((back.t - (3.0 - 0.024)).abs() < 1e-9, "{back:?}");
    assert!(stats.shared_hits >= 1, "{stats:?}");
}

#[test]
fn object_lists_survive_a_saved_raster() {
    let nff = random_scene(6, 60, 30, 0.02, 0.08, 0.12);
    let vs = exact_build(&nff, 32);
    assert!(!vs.lists.is_empty());
    let dir = std::env::temp_dir().join(format!("rrt-test-{}-lists", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("lists.rrt");
    // Version 3 (the default) and the dense version 2; the lists
    // section's offset in the section table of each.
    for (format, version, table_offset) in [
        (rasterfile::Format::default(), 3, 16 + 32 * 7 + 16),
        (rasterfile::Format::Dense, 2, 16 + 24 * 7 + 8),
    ] {
        let bytes = rasterfile::save_bytes_as(&vs, &path, format).unwrap();
        std::fs::write(&path, &bytes).unwrap();
        assert_eq!(rasterfile::info(&path).unwrap().version, version);
        let back = rasterfile::load(&path).unwrap();
        assert_eq!(back.lists, vs.lists);
        assert_eq!(back.records, vs.records);
        check_rays(&back, 3, 500, false);
        // A damaged list is refused with the file's name, not used.
        let mut bytes = bytes;
        let off = u64::from_le_bytes(bytes[table_offset..table_offset + 8].try_into().unwrap());
        bytes[usize::try_from(off).unwrap() + 9] ^= 0x10;
        let bad = dir.join("bad.rrt");
        std::fs::write(&bad, &bytes).unwrap();
        let e = rasterfile::load(&bad).unwrap_err().to_string();
        assert!(e.contains("bad.rrt") && e.contains("lists"), "{e}");
    }
    // The paper's raster (one object per voxel) is version 3 too, or 1 in
    // the dense layout.
    let scene = Scene::parse("random.nff", nff.as_bytes()).unwrap();
    let mut o = BuildOptions::paper(32);
    o.fit.max_memory = 1 << 30;
    let raw = build(&scene, &o, &ProgressBar::hidden()).unwrap().0;
    assert!(raw.lists.is_empty());
    rasterfile::save(&raw, &path).unwrap();
    assert_eq!(rasterfile::info(&path).unwrap().version, 3);
    assert!(!rasterfile::info(&path).unwrap().exact);
    let dense = rasterfile::save_bytes_as(&raw, &path, rasterfile::Format::Dense).unwrap();
    std::fs::write(&path, dense).unwrap();
    assert_eq!(rasterfile::info(&path).unwrap().version, 1);
    let _ = std::fs::remove_dir_all(&dir);
}
