//! `paper`: reproduces the measurements of Yagel, Cohen & Kaufman,
//! "Discrete Ray Tracing" (1992) on this machine, and compares with Embree,
//! writing `BENCHMARKS.md` and PNG plots.
//!
//! ```sh
//! RUSTFLAGS="-C target-cpu=x86-64-v3" cargo run --release -p rrt-benches --bin paper -- --out BENCHMARKS.md
//! cargo run --release -p rrt-benches --bin paper -- --quick --out /tmp/b.md   # tiny, < 1 min
//! cargo run --release -p rrt-benches --bin paper -- --section dvr --out /tmp/dvr.md   # one section
//! ```
//!
//! The peers are compiled with `-march=native`; `x86-64-v3` (AVX2, FMA,
//! BMI2) gives our code the same kind of instruction set. Without it the
//! bench measures the portable baseline build, and says so.
//!
//! Every time is a median over repetitions that are interleaved round by
//! round with whatever they are compared to, so ratios come from one run
//! under the same machine load.

mod arts;
mod common;
mod connectivity;
mod dvr;
mod embree;
mod head;
mod plot;
mod python;
mod scale;
mod skipping;
mod table1;
mod table2;
mod verification;
mod whole;

use clap::Parser;

use common::*;

/// Reproduce the paper's measurements and compare with Embree.
#[derive(Debug, Parser)]
#[command(version, about)]
struct Args {
    /// The Markdown report to write.
    #[arg(long, default_value = "BENCHMARKS.md")]
    out: PathBuf,
    /// Folder for the PNG plots [default: docs/bench beside the report].
    #[arg(long)]
    plots: Option<PathBuf>,
    /// A tiny configuration (small rasters and images, one repetition)
    /// that checks the pipeline in well under a minute.
    #[arg(long)]
    quick: bool,
    /// The shared data folder (spd/, volumes/) [default: ../shared/data
    /// beside the workspace].
    #[arg(long)]
    data: Option<PathBuf>,
    /// The `embree_nff` binary [default: /tmp/peers-build/embree_nff,
    /// built with ../shared/peers/run_peers.sh when missing, full runs only].
    #[arg(long)]
    embree: Option<PathBuf>,
    /// Skip the Embree comparison.
    #[arg(long)]
    no_embree: bool,
    /// Timed repetitions per measurement [default: 5, quick: 1].
    #[arg(long)]
    reps: Option<usize>,
    /// Seed of the random sphere scenes.
    #[arg(long, default_value_t = 1992)]
    seed: u64,
    /// Run only this section (repeatable): table1, table2, connectivity,
    /// verification, skipping, embree, dvr, python, whole, scale [default: all].
    #[arg(long = "section", value_name = "NAME")]
    sections: Vec<String>,
}

fn main() {
    if let Err(e) = run() {
        eprintln!("paper: {e}");
        std::process::exit(1);
    }
}

fn run() -> Res<()> {
    let args = Args::parse();
    let cfg = Config::new(args.quick, args.reps);
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("..");
    let data = args
        .data
        .clone()
        .unwrap_or_else(|| root.join("../shared/data"));
    if !data.join("spd").is_dir() {
        return Err(format!("{}: no spd/ folder (use --data)", data.display()).into());
    }
    let out_dir = args
        .out
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .map_or_else(|| PathBuf::from("."), Path::to_path_buf);
    let plots = args
        .plots
        .clone()
        .unwrap_or_else(|| out_dir.join("docs/bench"));
    std::fs::create_dir_all(&plots)?;
    let plots_link = match plots.strip_prefix(&out_dir) {
        Ok(rel) => rel.display().to_string(),
        Err(_) => std::fs::canonicalize(&plots)?.display().to_string(),
    };
    let mut ctx = Ctx {
        cfg,
        data,
        plots,
        plots_link,
        md: Md::default(),
        targets: Vec::new(),
        notes: Vec::new(),
        seed: args.seed,
        embree_bin: args.embree.clone(),
        no_embree: args.no_embree,
    };
    let t_start = Instant::now();
    let load_start = load_average();
    let mut body = Md::default();
    std::mem::swap(&mut body, &mut ctx.md);

    let sections: [(&str, &str, Section); 10] = [
        ("Table 1", "table1", table1::table1),
        ("Table 2", "table2", table2::table2),
        ("connectivity", "connectivity", connectivity::connectivity),
        ("verification", "verification", verification::verification),
        ("skipping", "skipping", skipping::skipping),
        ("Embree", "embree", embree::embree),
        ("direct volume rendering", "dvr", dvr::dvr),
        ("Python", "python", python::python),
        ("whole job", "whole", whole::whole),
        ("rasters at scale", "scale", scale::scale),
    ];
    if let Some(bad) = args
        .sections
        .iter()
        .find(|s| !sections.iter().any(|(_, key, _)| key == s))
    {
        return Err(format!(
            "--section {bad}: expected one of {}",
            sections.map(|(_, key, _)| key).join(", ")
        )
        .into());
    }
    let chosen = |key: &str| args.sections.is_empty() || args.sections.iter().any(|s| s == key);
    for (name, _, section) in sections.into_iter().filter(|(_, key, _)| chosen(key)) {
        ctx.log(&format!("{name} …"));
        let t = Instant::now();
        if let Err(e) = section(&mut ctx) {
            return Err(format!("{name}: {e}").into());
        }
        ctx.log(&format!(
            "{name} done in {:.1} s",
            t.elapsed().as_secs_f64()
        ));
    }
    let total = t_start.elapsed().as_secs_f64();

    // Header, targets, then the sections.
    let mut md = Md::default();
    md.line("# Benchmarks: the paper's measurements on this machine");
    md.line("");
    md.para(&format!(
        "Generated by `{}cargo run --release -p rrt-benches --bin paper -- --out BENCHMARKS.md{}` \
         (source: `benches/paper/`), which ran for {:.0} s. Do not edit by hand.",
        if V3 {
            "RUSTFLAGS=\"-C target-cpu=x86-64-v3\" "
        } else {
            ""
        },
        if ctx.cfg.quick { " --quick" } else { "" },
        total
    ));
    md.para(&format!(
        "Machine: {}, {} hardware threads, shared with other jobs (load average at the start: {}, at the end: {}). \
         {}; {}. Every time is the median of {} repetitions, interleaved round by round with what it \
         is compared to, so ratios are taken under the same load; absolute times swing with the \
         load. Paper figures are from a 1992 workstation (about 20 MIPS): compare ratios and \
         trends, not seconds.",
        cpu_name(),
        std::thread::available_parallelism().map_or(0, std::num::NonZero::get),
        load_start,
        load_average(),
        rustc_version(),
        if V3 {
            "our code built for x86-64-v3 (AVX2, FMA, BMI2), the peers with `-march=native`"
        } else {
            "our code built for baseline x86-64 (no AVX2), the peers with `-march=native`: \
             the command above with `RUSTFLAGS=\"-C target-cpu=x86-64-v3\"` compares like with like"
        },
        ctx.cfg.reps
    ));
    if !args.sections.is_empty() {
        md.para(&format!(
            "**Sections run**: {} (`--section`); the others are not in this file.",
            args.sections.join(", ")
        ));
    }
    if ctx.cfg.quick {
        md.para("**Quick mode**: tiny rasters and images, for checking the command only; these figures mean nothing.");
    }
    md.para(
        "Steps per ray count the voxels a ray visits (an empty-space jump counts as one); \
         for renders they are over all rays traced (primary, reflected, refracted and \
         render-time shadow rays).",
    );
    md.h2("Targets");
    md.table(&["target", "measured", "met"], &ctx.targets);
    for n in &ctx.notes {
        md.para(n);
    }
    md.0.push_str(&body.0);
    let mut out = md.0;
    out.push_str(&ctx.md.0);
    // The hand-recorded measurements, copied unchanged and marked as such.
    out.push_str(RECORDED);
    std::fs::write(&args.out, out)?;
    ctx.log(&format!("wrote {} in {total:.1} s", args.out.display()));
    Ok(())
}

/// Measurements recorded by hand, not regenerated by this program: the
/// report ends with them, under a heading that says so and when.
const RECORDED: &str = include_str!("recorded.md");

/// Whether this bench was compiled with the x86-64-v3 instruction set.
const V3: bool = cfg!(all(
    target_feature = "avx2",
    target_feature = "fma",
    target_feature = "bmi2"
));

fn cpu_name() -> String {
    std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("model name"))
                .and_then(|l| l.split(':').nth(1))
                .map(|s| s.trim().to_string())
        })
        .unwrap_or_else(|| "unknown CPU".into())
}

fn load_average() -> String {
    std::fs::read_to_string("/proc/loadavg")
        .ok()
        .map(|s| s.split_whitespace().take(3).collect::<Vec<_>>().join(" "))
        .unwrap_or_else(|| "unknown".into())
}

fn rustc_version() -> String {
    Command::new("rustc")
        .arg("--version")
        .output()
        .ok()
        .and_then(|o| String::from_utf8(o.stdout).ok())
        .map_or_else(|| "rustc unknown".into(), |s| s.trim().to_string())
}
