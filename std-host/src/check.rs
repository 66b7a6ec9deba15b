//! Invariant checkers shared by the tests and the fuzz targets (feature
//! `check`): each returns `Err` with a description of the first broken
//! invariant, so that callers can panic with it or collect it.
//!
//! * [`nff_input`] and [`toml_input`]: the scene parsers and the fit;
//! * [`nrrd_input`]: the NRRD reader and a volume's raster block;
//! * [`raster_file_input`]: the saved-raster loader, and rendering what it loads;
//! * [`path_input`]: the camera path reader;
//! * [`asset_input`]: the `.vox`, OBJ and Bézier patch readers;
//! * [`check_scene`]: the guarantees of a parsed [`Scene`](crate::scene::Scene).

use glam::DVec3;
use rrt_core::raster::Extent;

use crate::assets::volume::{Classifier, Limits, Placement, Samples, nrrd, sample_count};
use crate::fit::{FitOptions, fit};
use crate::frame::RasterFrame;
use crate::render::camera::Camera;
use crate::scene::{ParseOptions, nff};

pub use crate::scene::check_scene;

/// What a reader of the file `name` made of fuzz input: `Some` of what it
/// read, `None` when it refused the input with an error naming the file;
/// an error that does not name it is a broken guarantee.
fn read_or_refused<T, E: std::fmt::Display>(
    name: &str,
    read: Result<T, E>,
) -> Result<Option<T>, String> {
    match read {
        Ok(v) => Ok(Some(v)),
        Err(e) => {
            let msg = e.to_string();
            if msg.starts_with(name) {
                Ok(None)
            } else {
                Err(format!("error without its file: {msg}"))
            }
        }
    }
}

/// [`read_or_refused`] for a text reader `parse` of the file `name`:
/// `None` too for bytes that are not UTF-8 (never handed to it).
fn read_text_or_refused<T, E: std::fmt::Display>(
    name: &str,
    data: &[u8],
    parse: fn(&str, &str) -> Result<T, E>,
) -> Result<Option<T>, String> {
    match std::str::from_utf8(data) {
        Ok(text) => read_or_refused(name, parse(name, text)),
        Err(_) => Ok(None),
    }
}

/// Feeds arbitrary bytes (as the file `fuzz.nff`) to the NFF parser, then
/// to the camera and a 32-voxel raster fit, and checks: an error names the
/// file; a parsed scene keeps the guarantees of
/// [`Scene`](crate::scene::Scene) ([`check_scene`]) and makes a camera;
/// a fit either fails with an error or gives at most 32 voxels per axis,
/// objects with existing materials and every light. A panic or a hang
/// inside is a bug the caller sees as such.
///
/// # Errors
/// The first broken invariant.
pub fn nff_input(data: &[u8]) -> Result<(), String> {
    let opts = ParseOptions {
        max_vertices: 1 << 16,
        max_file_bytes: 1 << 20,
        view_required: true,
    };
    let Some(scene) = read_or_refused("fuzz.nff", nff::parse_bytes("fuzz.nff", data, &opts))?
    else {
        return Ok(());
    };
    check_scene(&scene).map_err(|e| format!("parsed scene breaks a guarantee: {e}"))?;
    let [w, h] = scene.view.resolution;
    Camera::new(&scene.view, w, h)
        .map_err(|e| format!("the parser accepted a view the camera refuses: {e}"))?;
    let fit_opts = FitOptions {
        max_memory: 64 << 20,
        ..FitOptions::new(32)
    };
    if let Ok(fitted) = fit(&scene, &fit_opts) {
        let dims = fitted.frame.dims();
        if !dims.iter().all(|&n| (1..=32).contains(&n)) {
            return Err(format!("fit made a {dims:?} raster for raster 32"));
        }
        if let Some(o) = fitted
            .objects
            .iter()
            .find(|o| o.material >= scene.materials.len())
        {
            return Err(format!("fitted object with a missing material: {o:?}"));
        }
        if fitted.lights.len() != scene.lights.len() {
            return Err("fit lost lights".into());
        }
    }
    Ok(())
}

/// Feeds arbitrary bytes (as the file `fuzz.path`) to the camera path
/// reader and checks: an error names the file; every view read makes a
/// camera (so the renderer never refuses a view the reader accepted) and
/// keeps its line's location.
///
/// # Errors
/// The first broken invariant.
pub fn path_input(data: &[u8]) -> Result<(), String> {
    let Ok(text) = std::str::from_utf8(data) else {
        return Ok(());
    };
    let Some(views) = read_or_refused("fuzz.path", crate::scene::path::parse("fuzz.path", text))?
    else {
        return Ok(());
    };
    let lines = u32::try_from(text.lines().count()).unwrap_or(u32::MAX);
    for v in &views {
        Camera::look_at(v.from, v.at, v.up, v.angle, 8, 8)
            .map_err(|e| format!("the reader accepted a view the camera refuses: {e} ({v:?})"))?;
        if !(1..=lines).contains(&v.loc.line) || v.loc.column != 1 {
            return Err(format!("view located outside its line: {v:?}"));
        }
    }
    if !views.windows(2).all(|w| w[0].loc.line < w[1].loc.line) {
        return Err("views out of line order".into());
    }
    Ok(())
}

/// Feeds arbitrary bytes, after a first byte choosing the reader, to the
/// `.vox` reader (as `fuzz.vox`), the OBJ reader (`fuzz.obj`) or the
/// Bézier patch reader (`fuzz.bpt`), and checks: an error names the file;
/// a `.vox` scene places at most [`vox::MAX_WORLD_VOXELS`] voxels from
/// at most [`vox::MAX_INSTANCES`] instances of models that exist, and
/// voxelizes into a 16³ raster with only voxels inside it (each at most
/// once per world voxel); an OBJ mesh has finite vertices, triangles
/// indexing them and a normal per vertex where it has normals; every
/// control point of a patch is finite.
///
/// # Errors
/// The first broken invariant.
///
/// [`vox::MAX_WORLD_VOXELS`]: crate::assets::vox::MAX_WORLD_VOXELS
/// [`vox::MAX_INSTANCES`]: crate::assets::vox::MAX_INSTANCES
pub fn asset_input(data: &[u8]) -> Result<(), String> {
    use crate::assets::vox;
    let Some((&which, data)) = data.split_first() else {
        return Ok(());
    };
    match which % 3 {
        0 => {
            let Some(scene) = read_or_refused("fuzz.vox", vox::parse_bytes("fuzz.vox", data))?
            else {
                return Ok(());
            };
            let placed = scene.world_voxel_count();
            if placed > vox::MAX_WORLD_VOXELS || scene.instances().len() > vox::MAX_INSTANCES {
                return Err(format!(
                    "{} instances placing {placed} voxels accepted",
                    scene.instances().len()
                ));
            }
            if let Some(i) = scene
                .instances()
                .iter()
                .find(|i| i.model >= scene.models().len())
            {
                return Err(format!("instance of a missing model: {i:?}"));
            }
            if placed > 1 << 20 {
                return Ok(());
            }
            struct Inside(u64, Option<[u32; 3]>);
            impl rrt_core::voxelize::VoxelSink for Inside {
                fn offer(&mut self, v: [u32; 3], _: rrt_core::voxelize::Surfel) {
                    self.0 += 1;
                    if v.iter().any(|&c| c >= 16) {
                        self.1.get_or_insert(v);
                    }
                }
            }
            let mut sink = Inside(0, None);
            let placement = crate::voxelize::vox::VoxPlacement {
                offset: [8; 3],
                scale: 1,
            };
            let n = scene.voxelize(placement, [16; 3], &mut sink);
            if let Some(v) = sink.1 {
                return Err(format!("voxel {v:?} offered outside a 16³ raster"));
            }
            if n != sink.0 || n > placed {
                return Err(format!(
                    "{n} offers reported, {} made, for {placed} world voxels",
                    sink.0
                ));
            }
            Ok(())
        }
        1 => {
            let Some(mesh) = read_text_or_refused("fuzz.obj", data, crate::scene::obj::parse)?
            else {
                return Ok(());
            };
            if let Some(p) = mesh.positions.iter().find(|p| !p.is_finite()) {
                return Err(format!("vertex {p} accepted"));
            }
            let n = mesh.positions.len();
            if let Some(t) = mesh
                .triangles
                .iter()
                .find(|t| t.iter().any(|&i| i as usize >= n))
            {
                return Err(format!("triangle {t:?} indexes past {n} vertices"));
            }
            if let Some(normals) = &mesh.normals
                && (normals.len() != n || normals.iter().any(|v| !v.is_finite()))
            {
                return Err(format!("{} normals for {n} vertices", normals.len()));
            }
            Ok(())
        }
        _ => {
            let Some(patches) = read_text_or_refused("fuzz.bpt", data, crate::scene::bpt::parse)?
            else {
                return Ok(());
            };
            if let Some(p) = patches.iter().flatten().flatten().find(|p| !p.is_finite()) {
                return Err(format!("control point {p} accepted"));
            }
            Ok(())
        }
    }
}

/// The checks of the `scene_toml` fuzz target (shared with
/// `tests/fuzz_regressions.rs`) on arbitrary bytes: the TOML scene parser
/// (with no file reads) must not panic; an error must name the input file
/// (`fuzz.toml`); a scene that parses must keep every guarantee of
/// [`crate::scene::Scene`] and fit a small raster or return a `FitError`.
///
/// # Errors
/// A description of the first broken guarantee.
pub fn toml_input(data: &[u8]) -> Result<(), String> {
    let Ok(text) = std::str::from_utf8(data) else {
        return Ok(());
    };
    let opts = crate::scene::toml::Options {
        read_files: false,
        ..crate::scene::toml::Options::default()
    };
    match crate::scene::toml::parse("fuzz.toml", text, std::path::Path::new("."), &opts) {
        Err(e) => {
            let msg = e.to_string();
            if msg.starts_with("fuzz.toml") {
                Ok(())
            } else {
                Err(format!("error does not name the file: {msg}"))
            }
        }
        Ok(scene) => {
            check_scene(&scene)?;
            let _ = fit(&scene, &FitOptions::new(16));
            Ok(())
        }
    }
}

/// The limits the checker reads with: 1 MiB of samples, 64 KiB of header.
pub const FUZZ_LIMITS: Limits = Limits {
    max_bytes: 1 << 20,
    max_header_bytes: 1 << 16,
};

/// Feeds arbitrary bytes (as the file `fuzz.nrrd`) to the NRRD reader and
/// checks: an error names the file; a volume keeps its invariants (sample
/// count = product of the sizes, within the limit; a usable grid), samples
/// trilinearly within its value range, writes and reads back unchanged,
/// and makes a raster block in a small raster. A panic or a hang inside is
/// a bug the caller sees as such.
///
/// # Errors
/// The first broken invariant.
pub fn nrrd_input(data: &[u8]) -> Result<(), String> {
    let Some(v) = read_or_refused(
        "fuzz.nrrd",
        nrrd::parse_bytes("fuzz.nrrd", data, &FUZZ_LIMITS),
    )?
    else {
        return Ok(());
    };
    let dims = v.dims();
    let count = sample_count(dims);
    if u64::try_from(v.samples().len()).ok() != Some(count) {
        return Err(format!("{} samples for {dims:?}", v.samples().len()));
    }
    if count.saturating_mul(v.sample_type().size()) > FUZZ_LIMITS.max_bytes {
        return Err(format!(
            "{dims:?} of {} passed the size limit",
            v.sample_type()
        ));
    }
    v.grid()
        .validate()
        .map_err(|e| format!("accepted an unusable grid: {e}"))?;
    let (lo, hi) = v.range();
    let n = DVec3::from(dims.map(f64::from));
    for t in [0.0, 0.3, 0.5, 0.77, 1.0] {
        let p = n * t - 0.5;
        let Some(x) = v.sample_index(p) else {
            return Err(format!("no value inside the cells at index {p}"));
        };
        let all_finite = v.samples().iter().all(f64::is_finite);
        if all_finite && !(x >= lo - 1e-9 * lo.abs().max(1.0) && x <= hi + 1e-9 * hi.abs().max(1.0))
        {
            return Err(format!("trilinear value {x} outside the range {lo}..{hi}"));
        }
    }
    if v.sample_index(n + 1.0).is_some() {
        return Err("a value outside the cells".into());
    }
    let back = nrrd::parse_bytes("fuzz.nrrd", &nrrd::to_bytes(&v, true), &FUZZ_LIMITS)
        .map_err(|e| format!("written volume does not read back: {e}"))?;
    let same = match (v.samples(), back.samples()) {
        (Samples::F32(a), Samples::F32(b)) => {
            a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits())
        }
        (a, b) => a == b,
    };
    if !same || back.dims() != dims {
        return Err("written volume reads back different".into());
    }
    // A small raster around the volume's world box: a block or an error.
    let placed = Placement::IDENTITY.place(&v);
    let b = placed.world_bounds();
    let size = b.size().max_element();
    if size.is_finite() && size > 0.0 {
        let frame = RasterFrame {
            extent: Extent::cube(8).map_err(|e| format!("{e:?}"))?,
            origin: b.min,
            voxel_size: size / 8.0,
        };
        let c = Classifier::iso(0.5 * (lo + hi));
        if let Ok(Some(block)) = placed.raster_block(&frame, &c, 1 << 20)
            && (block.samples.len() > 512 || block.threshold == 0)
        {
            return Err(format!(
                "block of {} samples, threshold {}",
                block.samples.len(),
                block.threshold
            ));
        }
    }
    Ok(())
}

/// A small scene with every kind of NFF object, two lights and a
/// translucent material: the valid rasters [`raster_file_input`] mutates.
const RASTER_FUZZ_SCENE: &str = "v\nfrom 0 -5 2\nat 0 0 0.5\nup 0 0 1\nangle 40\nhither 0.1\nresolution 8 8\n\
    b 0.1 0.2 0.3\nl 3 -4 6\nl -3 -2 4 0.5 0.5 1\n\
    f 0.9 0.4 0.2 0.8 0.2 20 0 1\ns 0 0 0.7 0.7\ns 0.9 0.2 0.3 0.3\n\
    f 0.2 0.8 0.4 0.5 0.3 10 0.5 1.3\nc -1 0 0 0.3 -1 0 1 0.1\n\
    f 0.8 0.8 0.8 0.9 0 1 0 1\np 4\n-2 -2 0\n2 -2 0\n2 2 0\n-2 2 0\n\
    pp 3\n0 1 0.2 0 0 1\n1 1 0.2 0 0.6 0.8\n0 1.5 1 0 -0.6 0.8\n";

/// The saved bytes of [`RASTER_FUZZ_SCENE`] on a 12-voxel raster: exact
/// and the paper's, each in version 3 (compressed) and in the dense
/// version (2 and 1); made once.
fn raster_fuzz_bases() -> Result<&'static [Vec<u8>; 4], String> {
    use crate::output::rasterfile::{Format, save_bytes_as};
    use crate::scene::Scene;
    use crate::voxelize::{BuildOptions, build};
    static BASES: std::sync::OnceLock<Result<[Vec<u8>; 4], String>> = std::sync::OnceLock::new();
    BASES
        .get_or_init(|| {
            let scene = Scene::parse("fuzz-base.nff", RASTER_FUZZ_SCENE.as_bytes())
                .map_err(|e| e.to_string())?;
            let quiet = indicatif::ProgressBar::hidden();
            let mut bases = [Vec::new(), Vec::new(), Vec::new(), Vec::new()];
            let formats = [
                Format::default(),
                Format::default(),
                Format::Dense,
                Format::Dense,
            ];
            let builds = [BuildOptions::new(12), BuildOptions::paper(12)];
            for (i, b) in bases.iter_mut().enumerate() {
                let opts = BuildOptions {
                    threads: 1,
                    ..builds[i % 2]
                };
                let (voxels, _) = build(&scene, &opts, &quiet).map_err(|e| e.to_string())?;
                *b = save_bytes_as(&voxels, std::path::Path::new("fuzz-base.rrt"), formats[i])
                    .map_err(|e| e.to_string())?;
            }
            Ok(bases)
        })
        .as_ref()
        .map_err(Clone::clone)
}

/// The memory a raster loaded by [`raster_file_input`] may need.
pub const RASTER_FUZZ_MEMORY: u64 = 64 << 20;

/// Fuzz input as a raster file named `fuzz.rrt`, loaded with a memory
/// limit of [`RASTER_FUZZ_MEMORY`]. The first byte chooses what the rest
/// is: (0) the file's bytes; (1, 2) changes to a valid exact (1) or paper
/// (2) raster of version 3, five bytes each (a little-endian `u32` offset
/// into the file, a byte to xor there), after which the checksums are
/// recomputed ([`reseal`](crate::output::rasterfile::reseal)) so that the
/// loader's checks behind them are reached; (3) the same changes to the
/// exact raster without recomputing them; (4, 5) as (1, 2) on the dense
/// versions 2 and 1. Checks: an error names the file; a corrupted file (3)
/// is refused unless what it loads is what was saved (changes in padding
/// only); a loaded raster saves to bytes that load again and save the
/// same, and renders a small image in its mode without panicking and
/// without NaN pixels. A panic or a hang inside is a bug the caller sees
/// as such.
///
/// # Errors
/// The first broken invariant.
pub fn raster_file_input(data: &[u8]) -> Result<(), String> {
    use crate::output::rasterfile::{load_bytes_within, reseal, save_bytes};
    use crate::render::{RenderOptions, render};
    use crate::trace::{Mode, TraceOptions, Tracer};
    let Some((&mode, rest)) = data.split_first() else {
        return Ok(());
    };
    let bases = raster_fuzz_bases()?;
    let bytes = match mode % 6 {
        0 => rest.to_vec(),
        m => {
            let base = match m {
                1 | 3 => 0,
                2 => 1,
                4 => 2,
                _ => 3,
            };
            let mut b = bases[base].clone();
            for change in rest.chunks_exact(5) {
                let at = u32::from_le_bytes([change[0], change[1], change[2], change[3]]);
                let at = usize::try_from(at).unwrap_or(0) % b.len().max(1);
                if let Some(x) = b.get_mut(at) {
                    *x ^= change[4];
                }
            }
            if m != 3 {
                reseal(&mut b);
            }
            b
        }
    };
    let name = std::path::Path::new("fuzz.rrt");
    let load = |b: &[u8]| load_bytes_within(name, b, RASTER_FUZZ_MEMORY);
    let Some(scene) = read_or_refused("fuzz.rrt", load(&bytes))? else {
        return Ok(());
    };
    let saved =
        save_bytes(&scene, name).map_err(|e| format!("a loaded raster does not save: {e}"))?;
    if mode % 6 == 3 && saved != bases[0] {
        return Err("a file with a changed checksummed byte was loaded".into());
    }
    let again = load(&saved).map_err(|e| format!("saved raster does not load: {e}"))?;
    if save_bytes(&again, name).ok().as_ref() != Some(&saved) {
        return Err("a loaded raster saves differently the second time".into());
    }
    let opts = TraceOptions {
        mode: if scene.exact {
            Mode::Exact
        } else {
            Mode::Paper
        },
        depth: 2,
        ..TraceOptions::default()
    };
    let Ok(tracer) = Tracer::new(&scene, opts) else {
        return Ok(());
    };
    let Ok(camera) = Camera::new(&scene.view, 6, 5) else {
        return Ok(());
    };
    let quiet = indicatif::ProgressBar::hidden();
    let threads = RenderOptions {
        supersample: 1,
        threads: 1,
        alpha: false,
    };
    let (image, _, _) = render(&tracer, &camera, &threads, &quiet)
        .map_err(|e| format!("a loaded raster does not render: {e}"))?;
    // Lights may be as bright as a scene makes them (an f32 pixel may
    // overflow to infinity), but never undefined.
    if image.linear.iter().any(|v| v.is_nan()) {
        return Err("a loaded raster renders NaN pixels".into());
    }
    Ok(())
}
