//! `paper --quick` runs the whole benchmark pipeline on a tiny
//! configuration and writes a well-formed report: every section, every
//! table's cells numbers (or dimensions, labels, "–"), every plot.
//! No timing is asserted.

use std::path::PathBuf;
use std::process::Command;

fn shared_data() -> Option<PathBuf> {
    let p = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../shared/data");
    p.join("spd").is_dir().then_some(p)
}

/// A table cell is a number (with thousands separators or a trailing ×),
/// raster dimensions `a×b×c`, a dash for "not measured", or yes/no.
fn cell_ok(c: &str) -> bool {
    let c = c.trim();
    if c == "–" || c == "yes" || c == "no" {
        return true;
    }
    let n = c.trim_end_matches('×').replace(',', "");
    if n.parse::<f64>().is_ok_and(f64::is_finite) {
        return true;
    }
    let dims: Vec<&str> = c.split('×').collect();
    dims.len() == 3 && dims.iter().all(|d| d.parse::<u32>().is_ok())
}

#[test]
fn quick_run_writes_a_well_formed_report() {
    let Some(data) = shared_data() else {
        eprintln!("skipped: ../shared/data is absent");
        return;
    };
    let dir = std::env::temp_dir().join(format!("rrt-paper-quick-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let out = dir.join("BENCHMARKS.md");
    let status = Command::new(env!("CARGO_BIN_EXE_paper"))
        .arg("--quick")
        .arg("--out")
        .arg(&out)
        .arg("--data")
        .arg(&data)
        .status()
        .unwrap();
    assert!(status.success());
    let md = std::fs::read_to_string(&out).unwrap();
    for section in [
        "## Targets",
        "## Table 1",
        "## Table 2 and Figure 7",
        "### Voxelization",
        "### Ray tracing",
        "## Connectivity",
        "## Verification and supersampling",
        "## Skipping",
        "## Against Embree",
        "## Python",
        "## The whole job against Embree",
    ] {
        assert!(md.contains(section), "missing section {section}");
    }
    for scene in ["balls2", "balls3", "balls4", "MRI head", "teapot"] {
        assert!(md.contains(scene), "Table 1 lacks {scene}");
    }
    // The hand-recorded measurements close the report, marked as such;
    // their tables are prose (units in the cells) and are not checked.
    let recorded = md
        .find("\n## Recorded by hand on ")
        .expect("the recorded section closes the report");
    assert!(md[recorded..].contains("not regenerated"));
    // Every generated table: as many cells per row as in its header; every
    // cell but the first (a label) of every row after the separator parses.
    let mut tables = 0;
    let lines: Vec<&str> = md[..recorded].lines().collect();
    let mut i = 0;
    while i < lines.len() {
        if lines[i].starts_with('|') {
            let head: Vec<&str> = lines[i].trim_matches('|').split('|').collect();
            assert!(lines[i + 1].contains("---"), "{}", lines[i + 1]);
            let mut j = i + 2;
            let mut rows = 0;
            while j < lines.len() && lines[j].starts_with('|') {
                let cells: Vec<&str> = lines[j].trim_matches('|').split('|').collect();
                assert_eq!(cells.len(), head.len(), "{}", lines[j]);
                if head[0].trim() == "target" {
                    // Label and measurement are prose; "met" is yes/no/–.
                    assert!(cell_ok(cells[2]), "{}", lines[j]);
                } else {
                    for c in &cells[1..] {
                        assert!(cell_ok(c), "cell {c:?} in {}", lines[j]);
                    }
                }
                rows += 1;
                j += 1;
            }
            assert!(rows > 0, "empty table {}", lines[i]);
            tables += 1;
            i = j;
        } else {
            i += 1;
        }
    }
    assert!(tables >= 8, "{tables} tables");
    for png in ["figure7.png", "voxelization.png", "embree.png", "head.png"] {
        let p = dir.join("docs/bench").join(png);
        let img = image::open(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
        assert!(img.width() > 0 && img.height() > 0);
        assert!(
            md.contains(&format!("docs/bench/{png}")),
            "{png} not linked"
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}
