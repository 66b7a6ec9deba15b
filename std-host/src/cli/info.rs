//! `rrt info`: what a saved raster holds.

use std::io::Write;
use std::path::PathBuf;

use super::CliError;
use crate::fit::Bytes;
use crate::output::rasterfile;
use crate::world::Coord;
use rrt_core::light::ExactRecords;
use rrt_core::voxelize::Separation;

/// Arguments of `rrt info`.
#[derive(Debug, Clone, clap::Args)]
pub struct InfoArgs {
    /// A raster saved by `rrt voxelize`.
    pub file: PathBuf,
    /// Check every section's checksum and load the raster, decoding and
    /// checking everything in it.
    #[arg(long)]
    pub check: bool,
    /// No progress bar while the file is checked.
    #[arg(long, short)]
    pub quiet: bool,
}

/// Runs `rrt info`: reads the header and meta section (with `--check`,
/// checks every section's checksum and loads the raster), then writes the
/// report to `out`.
///
/// # Errors
/// [`CliError`] for a file that is not a valid raster or whose checksums
/// do not match.
pub fn run(args: &InfoArgs, out: &mut impl Write) -> Result<(), CliError> {
    let i = if args.check {
        let bar = super::common::progress(!args.quiet);
        crate::progress::phase(&bar, "checking", crate::progress::Unit::Bytes, 0);
        let checked = rasterfile::inspect(&args.file, Some(&bar));
        bar.finish_and_clear();
        checked?
    } else {
        rasterfile::inspect(&args.file, None)?
    };
    let [nx, ny, nz] = i.dims;
    let max =
        i.origin + glam::DVec3::new(f64::from(nx), f64::from(ny), f64::from(nz)) * i.voxel_size;
    let voxels = u64::from(nx) * u64::from(ny) * u64::from(nz);
    writeln!(
        out,
        "file: {} ({}, format version {}{})",
        args.file.display(),
        Bytes(i.file_bytes),
        i.version,
        match (i.version, i.compressed) {
            (3, true) => ", sparse, compressed",
            (3, false) => ", sparse",
            _ => ", dense",
        }
    )?;
    writeln!(out, "dimensions: {nx}×{ny}×{nz} voxels ({voxels})")?;
    writeln!(
        out,
        "world bounds: [{}, {}, {}] to [{}, {}, {}]",
        Coord(i.origin.x),
        Coord(i.origin.y),
        Coord(i.origin.z),
        Coord(max.x),
        Coord(max.y),
        Coord(max.z)
    )?;
    writeln!(out, "voxel size: {}", Coord(i.voxel_size))?;
    writeln!(
        out,
        "separation: {}",
        match i.separation {
            Separation::Six => "6-tunnel-free (six, adaptive rays)",
            Separation::TwentySix => "26-tunnel-free (all rays)",
        }
    )?;
    writeln!(
        out,
        "kind: {}",
        match (i.exact, i.exact_records) {
            (false, _) => "the paper's raster (one object per voxel): renders in the paper's mode",
            (_, ExactRecords::Classify) => {
                "exact (object lists, the shadow classification): renders in every mode"
            }
            (_, ExactRecords::Skip) => {
                "exact (object lists, no light bits for exact objects): renders in every mode, with a shadow ray for every light"
            }
            _ => "exact (object lists, the paper's light bits): renders in every mode",
        }
    )?;
    writeln!(
        out,
        "voxels: {} surface voxels ({:.3}% of the raster)",
        i.records,
        100.0 * i.records as f64 / voxels.max(1) as f64
    )?;
    writeln!(
        out,
        "objects: {}, materials: {}, lights: {}",
        i.objects, i.materials, i.lights
    )?;
    if i.list_entries > 0 {
        writeln!(
            out,
            "object lists: {} entries (voxels several objects share)",
            i.list_entries
        )?;
        writeln!(
            out,
            "memory: {} (plane, line level, brick directory, records, object lists)",
            Bytes(i.memory)
        )?;
    } else {
        writeln!(
            out,
            "memory: {} (plane, line level, brick directory, records)",
            Bytes(i.memory)
        )?;
    }
    if i.version == 3 {
        writeln!(
            out,
            "plane: made on load from the records, {} bricks stored",
            i.plane_bricks
        )?;
    }
    if args.check {
        writeln!(
            out,
            "checksums: header and all sections match; the raster loads"
        )?;
    } else {
        writeln!(out, "checksums: not checked (rrt info --check)")?;
    }
    Ok(())
}
