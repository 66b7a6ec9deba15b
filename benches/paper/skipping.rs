//! Empty-space skipping by the proximity distances and the line level.

use crate::common::*;

pub(crate) fn skipping(ctx: &mut Ctx) -> Res<()> {
    let cfg = ctx.cfg.clone();
    let mut rows = Vec::new();
    let mut min_saving = f64::INFINITY;
    let mut min_saving_large = f64::INFINITY;
    let mut min_line_saving_large = f64::INFINITY;
    let mut left: Vec<(u32, f64, f64)> = Vec::new();
    for &r in &cfg.rasters {
        for (name, stem, _, _, _) in FLAKES {
            ctx.log(&format!("skipping: {stem} at {r}"));
            let s = Scene::load(ctx.spd(stem))?;
            let b = build_nff(&s, r, Connectivity::Adaptive, 1, None)?;
            let rays = camera_rays(&s.view, cfg.image)?;
            let dr = discrete_rays(&b.scene, &rays)?;
            // The plane alone, and the plane with its line level (what the
            // renderer walks).
            let with_lines = b.scene.raster()?;
            let plane_only = Raster::new(with_lines.extent(), with_lines.plane())?;
            let mut t = [Vec::new(), Vec::new(), Vec::new()];
            let mut first: Vec<Walked> = Vec::new();
            for rep in 0..3 * cfg.reps {
                for (i, (raster, skip)) in [
                    (&plane_only, false),
                    (&plane_only, true),
                    (&with_lines, true),
                ]
                .into_iter()
                .enumerate()
                {
                    let w = walk_all(raster, &dr, Connectivity::Adaptive, skip)?;
                    t[i].push(w.secs);
                    if rep == 0 {
                        first.push(w);
                    }
                }
            }
            let same = first[0]
                .hits
                .iter()
                .zip(&first[1].hits)
                .zip(&first[2].hits)
                .filter(|((a, b), c)| a == b && a == c)
                .count();
            let nr = rays.len().max(1) as f64;
            let saving = first[0].steps as f64 / first[1].steps.max(1) as f64;
            let line_saving = first[0].steps as f64 / first[2].steps.max(1) as f64;
            min_saving = min_saving.min(line_saving);
            if r >= 1024 || cfg.quick {
                min_saving_large = min_saving_large.min(saving);
                min_line_saving_large = min_line_saving_large.min(line_saving);
            }
            let [tn, ts, tl] = [median(&t[0]), median(&t[1]), median(&t[2])];
            left.push((r, first[2].steps as f64 / nr, first[0].steps as f64 / nr));
            rows.push(vec![
                format!("{name} at {r}"),
                f(first[0].steps as f64 / nr, 1),
                f(first[1].steps as f64 / nr, 1),
                f(saving, 2),
                f(first[2].steps as f64 / nr, 1),
                f(line_saving, 2),
                secs(tn),
                secs(ts),
                secs(tl),
                f(tn / ts, 2),
                f(tn / tl, 2),
                f(100.0 * same as f64 / nr, 2),
            ]);
        }
    }
    let md = &mut ctx.md;
    md.h2("Skipping: proximity distances");
    md.para(&format!(
        "Camera rays ({0}×{0}, SPD view) walked adaptively to their first non-transparent voxel, \
         one thread, setup excluded (medians of three times the repetitions, interleaved): \
         without skipping (`walk`), with skipping by the proximity distance field of the plane \
         alone (`walk_skipping`: a 26-run at distance d ≥ 4 jumps d − 1 steps at once; the plane \
         stores distances only within 15 voxels of a surface, so it jumps only there), and with \
         skipping through the plane's **line level** as the renderer walks (one stand-in cell per \
         64 plane cells, a lower bound on their distances from the coarse level over 8³ bricks and \
         the line's stored distances, read instead of the plane where it is 8 or more; in nearer \
         lines an empty plane cell counts as 16). Skipping must not change the hit \
         (**same hit %** = 100: all three walks agree).",
        cfg.image
    ));
    md.table(
        &[
            "scene, raster",
            "steps/ray",
            "skipping steps/ray",
            "steps saved ×",
            "line level steps/ray",
            "line level saved ×",
            "walk s",
            "skipping walk s",
            "line level walk s",
            "skipping time ×",
            "line level time ×",
            "same hit %",
        ],
        &rows,
    );
    ctx.targets.push(vec![
        format!(
            "skipping through the line level the renderer walks saves ≥ 5× of camera-ray steps on \
             the sphereflakes (smallest over rasters {})",
            if cfg.quick {
                "of the quick run".to_string()
            } else {
                "≥ 1024".to_string()
            }
        ),
        format!(
            "{}× (the plane's distances alone: {}×)",
            f(min_line_saving_large, 2),
            f(min_saving_large, 2)
        ),
        yes(min_line_saving_large >= 5.0),
    ]);
    if min_line_saving_large < 5.0 {
        let per: Vec<String> = cfg
            .rasters
            .iter()
            .map(|&r| {
                let sel: Vec<&(u32, f64, f64)> = left.iter().filter(|l| l.0 == r).collect();
                let k = sel.len().max(1) as f64;
                format!(
                    "raster {r}: {} steps/ray without skipping, {} with",
                    f(sel.iter().map(|l| l.2).sum::<f64>() / k, 1),
                    f(sel.iter().map(|l| l.1).sum::<f64>() / k, 1)
                )
            })
            .collect();
        ctx.notes.push(format!(
            "**Skipping** through the line level misses 5× by a factor of {} (Skipping section). \
             Mean camera-ray steps on the flakes: {}. A line's stand-in is a lower bound (the \
             coarse level's over 8³ bricks where the line is 16 or more voxels from every surface, \
             else the smallest stored distance of its cells, an empty cell counting as 16), so its \
             jumps are shorter than an exact distance's would be; the plane stores distances only \
             within 15 voxels of a surface so that its memory far from surfaces is never written \
             (Rasters at scale). The other steps left are single steps near surfaces (distance \
             below 4, no jump) and the ever shorter jumps on the approach to a surface, such as \
             the floor under a grazing camera ray.",
            f(5.0 / min_line_saving_large, 2),
            per.join("; ")
        ));
    }
    ctx.targets.push(vec![
        "skipping saving, smallest over all rasters measured".into(),
        format!("{}×", f(min_saving, 2)),
        yes(min_saving >= 5.0),
    ]);
    Ok(())
}
