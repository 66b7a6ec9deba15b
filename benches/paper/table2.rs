//! The paper's Table 2 and Figure 7: random spheres, voxelization and ray tracing against ARTS-style uniform grids.

use rrt_benches::unit;

use crate::common::*;

/// A random-sphere NFF scene: `n` spheres of radius 10 with centres
/// uniform in `[10, 246]³`, seen from outside the 256³ box.
pub(crate) fn random_spheres(n: usize, seed: u64) -> (String, Vec<arts::Sphere>) {
    let mut rng = rrt_benches::Rng(seed ^ (n as u64).wrapping_mul(0x9e37_79b9_7f4a_7c15));
    let mut s = String::new();
    let c = DVec3::splat(128.0);
    let from = c + DVec3::new(0.45, -0.78, 0.45).normalize() * 600.0;
    let _ = writeln!(
        s,
        "v\nfrom {} {} {}\nat 128 128 128\nup 0 0 1\nangle 40\nhither 1\nresolution 512 512",
        from.x, from.y, from.z
    );
    let _ = writeln!(s, "b 0.1 0.1 0.1");
    let _ = writeln!(s, "l {} {} {}", from.x + 200.0, from.y, from.z + 300.0);
    let _ = writeln!(s, "f 0.8 0.6 0.4 0.7 0.3 20 0 1");
    let mut spheres = Vec::with_capacity(n);
    for _ in 0..n {
        let p = DVec3::new(unit(&mut rng), unit(&mut rng), unit(&mut rng)) * 236.0 + 10.0;
        let _ = writeln!(s, "s {} {} {} 10", p.x, p.y, p.z);
        spheres.push(arts::Sphere {
            centre: p,
            radius: 10.0,
        });
    }
    (s, spheres)
}

pub(crate) fn table2(ctx: &mut Ctx) -> Res<()> {
    let cfg = ctx.cfg.clone();
    let paper: [(usize, f64, f64); 6] = [
        (10, 0.07, 20.2),
        (100, 0.74, 23.9),
        (200, 1.49, 30.1),
        (400, 2.98, 30.4),
        (1000, 7.46, 28.9),
        (5000, 36.01, 21.5),
    ];
    let bounds = Bounds {
        min: DVec3::ZERO,
        max: DVec3::splat(256.0),
    };
    let mut rows_vox = Vec::new();
    let mut rows_rt = Vec::new();
    let mut fig_rrt = Vec::new();
    let mut fig_render = Vec::new();
    let mut fig_vox = Vec::new();
    let mut fig_arts: Vec<Vec<(f64, f64)>> = vec![Vec::new(); cfg.grids.len()];
    let mut fig_arts_build: Vec<Vec<(f64, f64)>> = vec![Vec::new(); cfg.grids.len()];
    let mut ratios_same_res = Vec::new();
    let mut per_voxel = Vec::new();
    let mut largest = None;
    // Two threads against one, per phase: (spheres, phase, speed-up), for
    // phases that take at least `MEASURABLE` s on one thread.
    const MEASURABLE: f64 = 0.1;
    let mut speedups: Vec<(usize, &str, f64)> = Vec::new();
    for &n in &cfg.counts {
        ctx.log(&format!("Table 2: {n} spheres"));
        let (text, spheres) = random_spheres(n, ctx.seed);
        let scene = Scene::parse(&format!("random-{n}.nff"), text.as_bytes())?;
        let mut vox = Vec::new();
        let mut light = Vec::new();
        let mut vox2 = Vec::new();
        let mut light2 = Vec::new();
        let mut built = None;
        for _ in 0..cfg.reps {
            let b = build_nff(&scene, 256, Connectivity::Adaptive, 1, Some(bounds))?;
            vox.push(b.report.voxelize.as_secs_f64());
            light.push(b.report.lights.as_secs_f64());
            built = Some(b);
            let b2 = build_nff(&scene, 256, Connectivity::Adaptive, 2, Some(bounds))?;
            vox2.push(b2.report.voxelize.as_secs_f64());
            light2.push(b2.report.lights.as_secs_f64());
        }
        let b = built.ok_or("no build")?;
        let vs = b.scene.frame.voxel_size;
        if (vs - 1.0).abs() > 1e-9 {
            return Err(format!("random scene raster voxel size {vs}, expected 1").into());
        }
        let rays = camera_rays(&scene.view, cfg.t2_image)?;
        let dr = discrete_rays(&b.scene, &rays)?;
        let grids: Vec<(arts::Grid, f64)> = cfg
            .grids
            .iter()
            .map(|&g| {
                let t = Instant::now();
                let grid = arts::Grid::build(&spheres, g, DVec3::ZERO, 256.0);
                (grid, t.elapsed().as_secs_f64())
            })
            .collect();
        let mut t_rrt = Vec::new();
        let mut t_render = Vec::new();
        let mut t_arts = vec![Vec::new(); grids.len()];
        let mut t_build = vec![Vec::new(); grids.len()];
        let mut rrt_walk = None;
        let mut arts_res: Vec<(Vec<Option<f64>>, u64, u64)> = Vec::new();
        let mut render_stats = RayStats::default();
        for rep in 0..cfg.reps {
            // RRT: the tracer's own setup and skipping walk, from world rays.
            let t = Instant::now();
            let tracer = Tracer::new(&b.scene, depth3(Connectivity::Adaptive, Mode::Paper))?;
            let raster = b.scene.raster()?;
            let mut hits = Vec::with_capacity(rays.len());
            let mut steps = 0u64;
            for r in &rays {
                let hit = tracer.discrete_ray(r).and_then(|mut d| {
                    let end = d
                        .walk_skipping(&raster, Connectivity::Adaptive, u32::MAX, |_, c| {
                            c & cell::OPAQUE != 0
                        })
                        .ok()?;
                    steps += u64::from(d.steps());
                    (end == WalkEnd::Hit).then(|| d.hit().voxel)
                });
                hits.push(hit);
            }
            t_rrt.push(t.elapsed().as_secs_f64());
            rrt_walk = Some((hits, steps));
            let out = render_scene(
                &b.scene,
                &scene.view,
                cfg.t2_image,
                depth3(Connectivity::Adaptive, Mode::Paper),
                1,
                1,
            )?;
            t_render.push(out.secs);
            render_stats = out.stats;
            for (gi, (grid, build_s)) in grids.iter().enumerate() {
                if rep > 0 {
                    let t = Instant::now();
                    let g2 = arts::Grid::build(&spheres, cfg.grids[gi], DVec3::ZERO, 256.0);
                    t_build[gi].push(t.elapsed().as_secs_f64());
                    drop(g2);
                } else {
                    t_build[gi].push(*build_s);
                }
                let mut mb = grid.mailbox();
                let t = Instant::now();
                let mut res = Vec::with_capacity(rays.len());
                let (mut cells, mut tests) = (0u64, 0u64);
                for (id, r) in rays.iter().enumerate() {
                    let (hit, c, k) = grid.trace(r.origin, r.dir, id as u32, &mut mb);
                    cells += u64::from(c);
                    tests += u64::from(k);
                    res.push(hit);
                }
                t_arts[gi].push(t.elapsed().as_secs_f64());
                if rep == 0 {
                    arts_res.push((res, cells, tests));
                }
            }
        }
        drop(dr);
        let (hits, steps) = rrt_walk.ok_or("no walk")?;
        // Agreement with the finest grid's exact hits: both miss, or both hit
        // and the hit voxel's centre lies within 2 voxels of the exact point.
        let (exact, _, _) = arts_res.last().ok_or("no ARTS result")?;
        let mut agree = 0usize;
        for ((h, t), r) in hits.iter().zip(exact).zip(&rays) {
            match (h, t) {
                (None, None) => agree += 1,
                (Some(v), Some(t)) => {
                    let p = r.origin + r.dir * *t;
                    let c = DVec3::new(f64::from(v[0]), f64::from(v[1]), f64::from(v[2])) + 0.5;
                    if (p - c).abs().max_element() <= 2.0 {
                        agree += 1;
                    }
                }
                _ => {}
            }
        }
        let nr = rays.len().max(1) as f64;
        let vox_m = median(&vox);
        let rrt_m = median(&t_rrt);
        let paper_row = paper.iter().find(|p| p.0 == n);
        let (vox2_m, light2_m) = (median(&vox2), median(&light2));
        for (phase, one, two) in [
            ("voxelization", vox_m, vox2_m),
            ("light pass", median(&light), light2_m),
        ] {
            if one >= MEASURABLE && two > 0.0 {
                speedups.push((n, phase, one / two));
            }
        }
        // Per generated voxel, fixed costs included: voxelization and the
        // light pass on two threads.
        per_voxel.push(1e9 * (vox2_m + light2_m) / b.report.records.max(1) as f64);
        if n == *cfg.counts.last().unwrap_or(&0) {
            largest = Some((n, vox2_m + light2_m, median(&vox) + median(&light)));
        }
        rows_vox.push(vec![
            n.to_string(),
            b.report.records.to_string(),
            secs(vox_m),
            secs(median(&light)),
            f(1e9 * vox_m / b.report.records.max(1) as f64, 1),
            secs(vox2_m),
            secs(light2_m),
            f(per_voxel.last().copied().unwrap_or(f64::NAN), 1),
            paper_row.map_or("–".into(), |p| f(p.1, 2)),
        ]);
        let mut row = vec![
            n.to_string(),
            secs(rrt_m),
            f(steps as f64 / nr, 1),
            f(100.0 * agree as f64 / nr, 2),
            secs(median(&t_render)),
            f(steps_per_ray(&render_stats), 1),
        ];
        for (gi, (_, cells, tests)) in arts_res.iter().enumerate() {
            let a = median(&t_arts[gi]);
            row.push(secs(a));
            row.push(f(*cells as f64 / nr, 1));
            row.push(f(*tests as f64 / nr, 2));
            fig_arts[gi].push((n as f64, a));
            fig_arts_build[gi].push((n as f64, median(&t_build[gi])));
            if cfg.grids[gi] == 256 {
                ratios_same_res.push(a / rrt_m);
            }
        }
        row.push(paper_row.map_or("–".into(), |p| f(p.2, 1)));
        rows_rt.push(row);
        fig_rrt.push((n as f64, rrt_m));
        fig_render.push((n as f64, median(&t_render)));
        fig_vox.push((n as f64, vox_m));
    }
    let md = &mut ctx.md;
    md.h2("Table 2 and Figure 7: random spheres against ARTS");
    md.para(&format!(
        "The paper's Table 2 and Figure 7: n spheres of radius 10, centres uniform in [10, 246]³ \
         (seeded SplitMix64, seed {}), in a 256³ raster over the world box [0, 256]³ (voxel = 1 \
         world unit), the paper's raster and light bits. Voxelization: both passes of the \
         builder (count, fill), the proximity flags and the distance field; the light pass (one \
         light) apart; on one thread, then on two (`--threads 2`), with the time per generated \
         voxel of both together, fixed costs included.",
        ctx.seed
    ));
    md.h3("Voxelization");
    md.table(
        &[
            "spheres",
            "surface voxels",
            "voxelize s",
            "light pass s",
            "ns per voxel",
            "voxelize s, 2 threads",
            "light pass s, 2 threads",
            "ns per voxel, both, 2 threads",
            "paper voxelize s",
        ],
        &rows_vox,
    );
    if let Some((n, two, one)) = largest {
        ctx.targets.push(vec![
            format!("Table 2, {n} spheres: voxelization + light pass ≤ 0.3 s on 2 threads"),
            format!("{} s (1 thread: {} s)", secs(two), secs(one)),
            yes(two <= 0.3),
        ]);
    }
    let (lo, hi) = per_voxel
        .iter()
        .fold((f64::INFINITY, 0.0f64), |(a, b), &v| (a.min(v), b.max(v)));
    let mid = 0.5 * (lo + hi);
    ctx.targets.push(vec![
        "Table 2: time per generated voxel (voxelization + light pass, 2 threads) flat within ±50 %"
            .into(),
        format!("{}–{} ns: ±{} %", f(lo, 1), f(hi, 1), f(100.0 * (hi - lo) / (2.0 * mid), 0)),
        yes(hi <= 1.5 * mid && lo >= 0.5 * mid),
    ]);
    if let Some(&(n, phase, worst)) = speedups.iter().min_by(|a, b| a.2.total_cmp(&b.2)) {
        let range = |name: &str| {
            let r: Vec<f64> = speedups
                .iter()
                .filter(|s| s.1 == name)
                .map(|s| s.2)
                .collect();
            let lo = r.iter().copied().fold(f64::INFINITY, f64::min);
            let hi = r.iter().copied().fold(0.0, f64::max);
            format!("{name} {}–{}×", f(lo, 2), f(hi, 2))
        };
        ctx.targets.push(vec![
            format!(
                "two threads ≥ 1.8× one thread on every preprocessing phase (Table 2, each \
                 phase of ≥ {MEASURABLE} s on one thread)"
            ),
            format!(
                "smallest {}× ({phase}, {n} spheres); {}, {}",
                f(worst, 2),
                range("voxelization"),
                range("light pass")
            ),
            yes(worst >= 1.8),
        ]);
    }
    md.h3("Ray tracing");
    let mut head: Vec<String> = vec![
        "spheres".into(),
        "rrt first hit s".into(),
        "rrt steps/ray".into(),
        "rrt = exact %".into(),
        "rrt render s".into(),
        "render steps/ray".into(),
    ];
    for g in &cfg.grids {
        head.push(format!("ARTS{g} s"));
        head.push(format!("ARTS{g} cells/ray"));
        head.push(format!("ARTS{g} tests/ray"));
    }
    head.push("paper rrt s".into());
    let head_ref: Vec<&str> = head.iter().map(String::as_str).collect();
    md.para(&format!(
        "Same rays for both: the {0}×{0} camera rays of the scene's view (from outside the box, \
         40°), one thread. **rrt first hit**: per ray the tracer's fixed-point setup and its \
         adaptive walk with skipping to the first non-transparent voxel. **ARTSg**: a uniform \
         grid of g³ cells of object lists (a sphere is listed in every cell its surface's box \
         distance allows), walked by a float Amanatides & Woo 3D-DDA from the box entry, exact \
         f64 ray-sphere tests with a mailbox, stopping in the first cell whose exit lies beyond \
         the nearest hit found (`benches/paper/arts.rs`); grid build times are in the \
         voxelization plot. Both return a ray's first surface; **rrt = exact** is the share of \
         rays where rrt and ARTS{1} agree (both miss, or rrt's hit voxel lies within 2 voxels of \
         the exact point). **rrt render**: the whole image shaded, depth 3 (primary, reflected \
         and shadow rays as Table 1), for scale; the paper's Table 2 row is its ray tracing time.",
        cfg.t2_image,
        cfg.grids.last().copied().unwrap_or(0)
    ));
    md.table(&head_ref, &rows_rt);
    let mean_ratio = if ratios_same_res.is_empty() {
        f64::NAN
    } else {
        ratios_same_res.iter().sum::<f64>() / ratios_same_res.len() as f64
    };
    md.para(&format!(
        "ARTS256 / rrt first-hit time, mean over the sphere counts: **{}** (paper, ARTS at the \
         raster's resolution against RRT: 9.1).",
        f(mean_ratio, 2)
    ));
    let mut series = vec![Series {
        label: "rrt first hit (adaptive + skipping)".into(),
        points: fig_rrt,
        dashed: false,
    }];
    for (gi, g) in cfg.grids.iter().enumerate() {
        series.push(Series {
            label: format!("ARTS{g} (float 3D-DDA, exact tests)"),
            points: fig_arts[gi].clone(),
            dashed: true,
        });
    }
    series.push(Series {
        label: "rrt render, depth 3".into(),
        points: fig_render,
        dashed: false,
    });
    let fig7 = ctx.plots.join("figure7.png");
    plot::log_log(
        &fig7,
        &format!(
            "Figure 7: ray tracing {0}×{0} camera rays, spheres of radius 10 in 256³",
            cfg.t2_image
        ),
        "spheres",
        "seconds",
        &series,
    )?;
    let mut vseries = vec![Series {
        label: "rrt voxelization (2 passes + distance field)".into(),
        points: fig_vox,
        dashed: false,
    }];
    for (gi, g) in cfg.grids.iter().enumerate() {
        vseries.push(Series {
            label: format!("ARTS{g} grid build"),
            points: fig_arts_build[gi].clone(),
            dashed: true,
        });
    }
    let vfig = ctx.plots.join("voxelization.png");
    plot::log_log(
        &vfig,
        "Preprocessing: voxelization vs ARTS grid build, 256³",
        "spheres",
        "seconds",
        &vseries,
    )?;
    let link = ctx.plots_link.clone();
    let md = &mut ctx.md;
    md.para(&format!(
        "![Figure 7]({link}/figure7.png)\n\n![Voxelization]({link}/voxelization.png)"
    ));
    Ok(())
}
