//! The measurements: instructions per discrete-ray step in each mode, and
//! the stack each public entry point uses. On a thumb target under
//! `qemu-system-arm -icount shift=0` it counts retired instructions through
//! SysTick and paints the stack; on the host it runs one workload named on
//! the command line, for callgrind to count (`bash core/on-target/measure`
//! does both and writes docs/embedded.md).
#![cfg_attr(target_os = "none", no_std, no_main)]

#[cfg(target_os = "none")]
mod firmware {
    use rrt_core::discrete_ray::{Connectivity, DiscreteRay};
    use rrt_core::packet::{LANES, RayPacket8};
    use rrt_core::proximity::{distance_field, flag_neighbourhood, line_distances};
    use rrt_core::raster::{Raster, RasterMut};
    use rrt_on_target::firmware::{exit, println, stack_use, systick};
    use rrt_on_target::rays::{Spec, spec};
    use rrt_on_target::{bench, buffer, scene, scene_storage, traversal};

    /// Free stack painted per measurement.
    const WINDOW: usize = 64 * 1024;
    /// Rays of the set whose entry points are measured one call at a time.
    const STACK_RAYS: u64 = 400;

    #[cortex_m_rt::exception]
    fn SysTick() {
        systick::on_wrap();
    }

    fn mode_name(m: Connectivity) -> &'static str {
        m.name()
    }

    #[cortex_m_rt::entry]
    fn main() -> ! {
        let plane = buffer!(u8 = 0; traversal::PLANE_LEN);
        let lines = buffer!(u8 = 0; traversal::LINES_LEN);
        if traversal::fill_raster(plane, lines).is_err() {
            exit(2);
        }
        let Ok(raster) = Raster::new(traversal::extent().unwrap_or_else(|_| exit(2)), plane) else {
            exit(2)
        };
        let Ok(lined) = raster.with_lines(lines) else {
            exit(2)
        };

        // Instructions per step.
        systick::start();
        let n = 1_000_000;
        let cal = systick::calibrate(n);
        println!("calibration {} {}", 2 * u64::from(n), cal);
        const NO_SPEC: Spec = Spec::Half {
            origin: [0; 3],
            dir: [0; 3],
        };
        let specs = buffer!(Spec = NO_SPEC; traversal::RAYS as usize);
        bench::specs(&raster, specs);
        let t = systick::ticks();
        let rays = core::hint::black_box(bench::setup(&raster, specs));
        println!("insns setup {} {}", systick::ticks() - t, rays);
        let t = systick::ticks();
        let voxels = core::hint::black_box(bench::dilated(&lined, specs));
        println!("insns dilated {} {}", systick::ticks() - t, voxels);
        for mode in Connectivity::ALL {
            for (name, f) in [
                (
                    "walk",
                    bench::walk as fn(&Raster<'_>, &[Spec], Connectivity) -> u64,
                ),
                ("packet", bench::packet),
            ] {
                let t = systick::ticks();
                let steps = core::hint::black_box(f(&raster, specs, mode));
                println!(
                    "insns {}.{} {} {}",
                    name,
                    mode_name(mode),
                    systick::ticks() - t,
                    steps
                );
            }
        }
        // The camera rays through the integrator's scene, scalar and packets.
        let mut st = scene_storage!();
        if scene::build(&mut st).is_err() {
            exit(3);
        }
        let Ok(shown) = scene::extent().and_then(|e| Raster::new(e, st.plane)) else {
            exit(3)
        };
        let cam = buffer!(([i64; 3], [i32; 3]) = ([0; 3], [0; 3]); scene::SIZE * scene::SIZE);
        bench::camera(cam);
        for (name, f) in [
            (
                "camera.setup",
                bench::camera_setup as fn(&Raster<'_>, &[([i64; 3], [i32; 3])]) -> u64,
            ),
            ("camera.walk", bench::camera_walk),
            ("camera.packet", bench::camera_packet),
        ] {
            let t = systick::ticks();
            let steps = core::hint::black_box(f(&shown, cam));
            println!("insns {} {} {}", name, systick::ticks() - t, steps);
        }
        systick::stop();

        // Stack per entry point, the largest over the calls made.
        let e = raster.extent();
        let mut worst = Worst::default();
        for i in 0..STACK_RAYS {
            let s = spec(e, traversal::SEED, i);
            let (r, b) = stack_use(WINDOW, || s.ray(e));
            let name = match s {
                rrt_on_target::rays::Spec::Half { .. } => "DiscreteRay::new",
                rrt_on_target::rays::Spec::Segment { .. } => "DiscreteRay::segment",
            };
            worst.note(name, b);
            let Ok(Some(r)) = r else { continue };
            let mut a = r;
            let (_, b) = stack_use(WINDOW, || {
                a.walk_dilated(&lined, u32::MAX, traversal::dilated_test)
            });
            worst.note("DiscreteRay::walk_dilated", b);
            for mode in Connectivity::ALL {
                let mut a = r;
                let (_, b) = stack_use(WINDOW, || a.first_hit(&raster, mode));
                worst.note("DiscreteRay::first_hit", b);
                let mut a = r;
                let (_, b) = stack_use(WINDOW, || a.first_hit_skipping(&lined, mode));
                worst.note("DiscreteRay::first_hit_skipping", b);
                let mut a = r;
                let (_, b) = stack_use(WINDOW, || a.walk(&raster, mode, 5, traversal::walk_test));
                worst.note("DiscreteRay::walk", b);
                if let Ok(mut vs) = r.voxels(&raster, mode) {
                    let (_, b) = stack_use(WINDOW, || vs.next());
                    worst.note("Voxels::next", b);
                }
            }
        }
        let mut first = 0;
        while first < STACK_RAYS {
            let rays: [Option<DiscreteRay>; LANES] =
                core::array::from_fn(|l| traversal::ray(e, first + l as u64));
            let (p, b) = stack_use(WINDOW, || RayPacket8::from_rays(e, rays));
            worst.note("RayPacket8::from_rays", b);
            if let Ok(p) = p {
                for mode in Connectivity::ALL {
                    let mut q = p.clone();
                    let (_, b) = stack_use(WINDOW, || q.first_hit(&raster, mode));
                    worst.note("RayPacket8::first_hit", b);
                    let mut q = p.clone();
                    let (_, b) = stack_use(WINDOW, || {
                        q.walk(&raster, mode, 5, |_, i, c| traversal::walk_test(i, c))
                    });
                    worst.note("RayPacket8::walk", b);
                }
            }
            first += LANES as u64;
        }
        let copy = buffer!(u8 = 0; traversal::PLANE_LEN);
        copy.copy_from_slice(raster.plane());
        if let Ok(mut r) = RasterMut::new(e, copy) {
            let (_, b) = stack_use(WINDOW, || flag_neighbourhood(&mut r));
            worst.note("flag_neighbourhood", b);
            let (_, b) = stack_use(WINDOW, || distance_field(&mut r));
            worst.note("distance_field", b);
            let mut l = [0u8; traversal::LINES_LEN];
            let mut bricks = [0u8; traversal::BRICKS_LEN];
            let (_, b) = stack_use(WINDOW, || {
                line_distances(&r.as_raster(), &mut bricks, &mut l)
            });
            worst.note("line_distances", b);
        }
        scene::voxelizer_probe(&mut |name, f| {
            let (_, b) = stack_use(WINDOW, f);
            worst.note(name, b);
        });
        let built = scene::build_with(&mut st, scene::Variant::Paper, &mut |name, f| {
            let (_, b) = stack_use(WINDOW, f);
            worst.note(name, b);
        });
        let Ok(built) = built else { exit(3) };
        let image = buffer!(u8 = 0; scene::IMAGE_LEN);
        let records = st.records.get(..built.records).unwrap_or(&[]);
        let (_, b) = stack_use(WINDOW, || {
            scene::render(st.plane, st.lines, st.dir, records, image)
        });
        worst.note("scene::render: 64x64 pixels", b);
        // The exact raster: its passes count under the same names, but for
        // the light pass, whose shadow classification is its own entry.
        let built = scene::build_with(&mut st, scene::Variant::Exact, &mut |name, f| {
            let (_, b) = stack_use(WINDOW, f);
            worst.note(name, b);
        });
        if built.is_err() {
            exit(3)
        }
        for (name, b) in worst.list.iter().flatten() {
            println!("stack {} {}", b, name);
        }
        exit(0)
    }

    /// The largest figure per entry point, in first-seen order.
    #[derive(Default)]
    struct Worst {
        list: [Option<(&'static str, usize)>; 32],
    }

    impl Worst {
        fn note(&mut self, name: &'static str, bytes: usize) {
            for slot in &mut self.list {
                match slot {
                    Some((n, b)) if *n == name => {
                        *b = (*b).max(bytes);
                        return;
                    }
                    Some(_) => {}
                    None => {
                        *slot = Some((name, bytes));
                        return;
                    }
                }
            }
        }
    }
}

#[cfg(not(target_os = "none"))]
fn main() -> std::process::ExitCode {
    use rrt_core::discrete_ray::Connectivity;
    use rrt_core::raster::Raster;
    use rrt_on_target::{bench, scene, traversal};
    let args: Vec<String> = std::env::args().skip(1).collect();
    let mode = |s: &str| Connectivity::ALL.into_iter().find(|m| m.name() == s);
    let mut plane = vec![0; traversal::PLANE_LEN];
    let mut lines = vec![0; traversal::LINES_LEN];
    if let Err(e) = traversal::fill_raster(&mut plane, &mut lines) {
        eprintln!("measure: {e}");
        return std::process::ExitCode::FAILURE;
    }
    let Ok((raster, lined)) = traversal::extent()
        .and_then(|e| Raster::new(e, &plane))
        .and_then(|r| Ok((r, r.with_lines(&lines)?)))
    else {
        return std::process::ExitCode::FAILURE;
    };
    let mut st = rrt_on_target::scene_storage!();
    if let Err(e) = scene::build(&mut st) {
        eprintln!("measure: {e:?}");
        return std::process::ExitCode::FAILURE;
    }
    let Ok(shown) = scene::extent().and_then(|e| Raster::new(e, st.plane)) else {
        return std::process::ExitCode::FAILURE;
    };
    let mut specs = vec![
        rrt_on_target::rays::Spec::Half {
            origin: [0; 3],
            dir: [0; 3]
        };
        traversal::RAYS as usize
    ];
    bench::specs(&raster, &mut specs);
    let mut cam = vec![([0i64; 3], [0i32; 3]); scene::SIZE * scene::SIZE];
    bench::camera(&mut cam);
    let steps = match args.iter().map(String::as_str).collect::<Vec<_>>()[..] {
        ["camera_setup"] => bench::camera_setup(&shown, &cam),
        ["camera_walk"] => bench::camera_walk(&shown, &cam),
        ["camera_packet"] => bench::camera_packet(&shown, &cam),
        ["setup"] => bench::setup(&raster, &specs),
        ["dilated"] => bench::dilated(&lined, &specs),
        ["walk", m] if mode(m).is_some() => {
            bench::walk(&raster, &specs, mode(m).unwrap_or_default())
        }
        ["packet", m] if mode(m).is_some() => {
            bench::packet(&raster, &specs, mode(m).unwrap_or_default())
        }
        _ => {
            eprintln!(
                "usage: measure setup | walk MODE | packet MODE | dilated | camera_setup | camera_walk | camera_packet (MODE: six, twenty-six, adaptive)"
            );
            return std::process::ExitCode::FAILURE;
        }
    };
    println!("{steps}");
    std::process::ExitCode::SUCCESS
}
