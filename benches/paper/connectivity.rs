//! 26-rays against 6-rays and adaptive rays: traversal, whole renders, misses.

use crate::common::*;

pub(crate) fn connectivity(ctx: &mut Ctx) -> Res<()> {
    let cfg = ctx.cfg.clone();
    let modes = [
        Connectivity::Six,
        Connectivity::TwentySix,
        Connectivity::Adaptive,
    ];
    let mut rows = Vec::new();
    let mut rrows = Vec::new();
    let mut best_speedup: f64 = 0.0;
    let mut worst_miss: f64 = 0.0;
    let mut worst_penalty: f64 = f64::NEG_INFINITY;
    for &r in &cfg.rasters {
        for (name, stem, _, _, _) in FLAKES {
            ctx.log(&format!("connectivity: {stem} at {r}"));
            let s = Scene::load(ctx.spd(stem))?;
            let b = build_nff(&s, r, Connectivity::TwentySix, 1, None)?;
            let rays = camera_rays(&s.view, cfg.image)?;
            let dr = discrete_rays(&b.scene, &rays)?;
            let mut t = [Vec::new(), Vec::new(), Vec::new()];
            let mut tr = [Vec::new(), Vec::new(), Vec::new()];
            let mut walks: Vec<Walked> = Vec::new();
            let mut rstats = [RayStats::default(); 3];
            // Walks are short: three times the repetitions, interleaved.
            for rep in 0..3 * cfg.reps {
                for (mi, &m) in modes.iter().enumerate() {
                    let w = walk_all(&b.scene.raster()?, &dr, m, false)?;
                    t[mi].push(w.secs);
                    if rep == 0 {
                        walks.push(w);
                    }
                }
            }
            for _ in 0..cfg.reps {
                for (mi, &m) in modes.iter().enumerate() {
                    let out =
                        render_scene(&b.scene, &s.view, cfg.image, depth3(m, Mode::Paper), 1, 1)?;
                    tr[mi].push(out.secs);
                    rstats[mi] = out.stats;
                }
            }
            let six_hits = walks[0].hits.iter().filter(|h| h.is_some()).count();
            let miss26 = walks[0]
                .hits
                .iter()
                .zip(&walks[1].hits)
                .filter(|(a, b)| a.is_some() && a != b)
                .count();
            // The surface voxel a 6-ray hits, missed: the 26-ray hits
            // nothing, or a voxel neither equal nor adjacent to it (it
            // slipped through the surface layer the 6-ray hit).
            let extent = b.scene.extent();
            let far = |a: usize, b: usize| match (extent.coord(a), extent.coord(b)) {
                (Some(p), Some(q)) => (0..3).any(|k| p[k].abs_diff(q[k]) > 1),
                _ => true,
            };
            let miss_surface = walks[0]
                .hits
                .iter()
                .zip(&walks[1].hits)
                .filter(|(a, b)| match (a, b) {
                    (Some(_), None) => true,
                    (Some(a), Some(b)) => far(*a, *b),
                    _ => false,
                })
                .count();
            let missa = walks[0]
                .hits
                .iter()
                .zip(&walks[2].hits)
                .filter(|(a, b)| a.is_some() && a != b)
                .count();
            let nr = rays.len().max(1) as f64;
            let [t6, t26, ta] = [median(&t[0]), median(&t[1]), median(&t[2])];
            let speedup = t6 / t26;
            let miss = 100.0 * miss_surface as f64 / six_hits.max(1) as f64;
            let miss_voxel = 100.0 * miss26 as f64 / six_hits.max(1) as f64;
            let penalty = 100.0 * (ta / t26 - 1.0);
            best_speedup = best_speedup.max(speedup);
            worst_miss = worst_miss.max(miss);
            worst_penalty = worst_penalty.max(penalty);
            rows.push(vec![
                format!("{name} at {r}"),
                secs(t6),
                f(walks[0].steps as f64 / nr, 1),
                secs(t26),
                f(walks[1].steps as f64 / nr, 1),
                secs(ta),
                f(walks[2].steps as f64 / nr, 1),
                f(speedup, 2),
                f(miss_voxel, 2),
                f(miss, 2),
                f(100.0 * missa as f64 / six_hits.max(1) as f64, 3),
                f(penalty, 1),
            ]);
            let [r6, r26, ra] = [median(&tr[0]), median(&tr[1]), median(&tr[2])];
            rrows.push(vec![
                format!("{name} at {r}"),
                secs(r6),
                f(steps_per_ray(&rstats[0]), 1),
                secs(r26),
                f(steps_per_ray(&rstats[1]), 1),
                secs(ra),
                f(steps_per_ray(&rstats[2]), 1),
                f(r6 / r26, 2),
                f(100.0 * (ra / r26 - 1.0), 1),
            ]);
        }
    }
    let md = &mut ctx.md;
    md.h2("Connectivity: 26-rays against 6-rays, adaptive");
    md.para(&format!(
        "Rasters voxelized 26-tunnel-free (so all three ray kinds may be used), {0}×{0} camera \
         rays of the SPD view, one thread. **Traversal**: each ray's fixed-point walk to its first \
         non-transparent voxel *without* skipping (the paper's traversal), setup excluded; \
         medians of three times the repetitions, the modes interleaved. \
         Of the 6-rays that hit: **26 other voxel**, those whose 26-ray's first hit is another \
         voxel (it stepped diagonally past the 6-ray's voxel, usually onto a neighbour in the \
         same surface layer); **26 misses surface**, those whose 26-ray hits nothing or a voxel \
         neither equal nor 26-adjacent to the 6-ray's (it slipped through the surface layer the \
         6-ray hit: the paper's miss); **adaptive ≠ \
         6**: adaptive rays whose first hit is another voxel than the 6-ray's (should be 0). **Penalty**: adaptive time over 26 − 1. \
         Paper: speed-up up to 1.84, under 1.5 % of 26-rays miss, penalty under 2.9 %.",
        cfg.image
    ));
    md.table(
        &[
            "scene, raster",
            "6 s",
            "6 steps/ray",
            "26 s",
            "26 steps/ray",
            "adaptive s",
            "adaptive steps/ray",
            "speed-up 26 over 6",
            "26 other voxel %",
            "26 misses surface %",
            "adaptive ≠ 6 %",
            "penalty %",
        ],
        &rows,
    );
    md.para(
        "Whole renders (depth 3, one thread) with each connectivity; here 26 and adaptive runs \
         skip empty space by the proximity distances, six does not:",
    );
    md.table(
        &[
            "scene, raster",
            "6 render s",
            "6 steps/ray",
            "26 render s",
            "26 steps/ray",
            "adaptive render s",
            "adaptive steps/ray",
            "render speed-up 26 over 6",
            "render penalty %",
        ],
        &rrows,
    );
    md.para(&format!(
        "Traversal speed-up of 26 over 6: up to **{}** (paper: up to 1.84); 26-ray misses: at \
         most **{} %** (paper: < 1.5 %); adaptive penalty over 26: at most **{} %** (paper: < \
         2.9 %).",
        f(best_speedup, 2),
        f(worst_miss, 2),
        f(worst_penalty, 1)
    ));
    Ok(())
}
