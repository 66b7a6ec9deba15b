//! rrt-core on the hardware it is for: the code that runs both under a
//! Cortex-M emulator and on the host, so that the two can be compared
//! digest by digest (see `README.md` and `docs/embedded.md`).
//!
//! Everything here is `no_std`, integer-only and draws its inputs from one
//! seed ([`traversal::SEED`]): the firmware (`src/bin/*.rs` built for a
//! thumb target) and the host (the same binaries built for the host) run
//! this very code and print the same lines.
#![no_std]
#![deny(unsafe_code)]

pub mod bench;
pub mod checks;
pub mod digest;
pub mod rays;
pub mod rng;
pub mod scene;
pub mod traversal;
pub mod voxelizers;

#[cfg(target_os = "none")]
pub mod firmware;

use core::fmt;

use rrt_core::raster::Raster;

use crate::digest::{Digest, Line};

/// A buffer of `$len` values `$init` that lives for the whole run, as a
/// `&'static mut`: on a thumb target a static array of the firmware (one
/// per expansion, taken with [`take!`]: evaluate each expansion once, from
/// `main`), on the host a leaked vector.
#[cfg(target_os = "none")]
#[macro_export]
macro_rules! buffer {
    ($ty:ty = $init:expr; $len:expr) => {{
        static mut BUFFER: [$ty; $len] = [$init; $len];
        $crate::take!(BUFFER)
    }};
}

/// A buffer of `$len` values `$init` that lives for the whole run, as a
/// `&'static mut`: on a thumb target a static array of the firmware, on the
/// host a leaked vector.
#[cfg(not(target_os = "none"))]
#[macro_export]
macro_rules! buffer {
    ($ty:ty = $init:expr; $len:expr) => {
        ::std::vec::Vec::<$ty>::leak(::std::vec![$init; $len])
    };
}

/// The scene's buffers, a [`scene::Storage`] of [`buffer!`]s (static
/// arrays on a thumb target: evaluate it once, from `main`).
#[macro_export]
macro_rules! scene_storage {
    () => {
        $crate::scene::Storage {
            plane: $crate::buffer!(u8 = 0; $crate::scene::PLANE_LEN),
            lines: $crate::buffer!(u8 = 0; $crate::scene::LINES_LEN),
            dir: $crate::buffer!(u32 = 0; $crate::scene::DIR_LEN),
            records: $crate::buffer!(
                ::rrt_core::voxel::VoxelRecord = $crate::scene::RECORD_INIT;
                $crate::scene::MAX_RECORDS
            ),
            lists: $crate::buffer!(u32 = 0; $crate::scene::MAX_LIST_ENTRIES),
            objects: $crate::buffer!(
                ::rrt_core::object_table::Object = ::rrt_core::object_table::Object::UNUSED;
                $crate::scene::MAX_OBJECTS
            ),
            patches: $crate::buffer!(::rrt_core::geometry::BezierPatch = $crate::scene::PATCH_INIT; 1),
        }
    };
}

/// The buffers of the whole suite (static arrays on the target).
#[derive(Debug)]
pub struct Buffers<'a> {
    /// The traversal raster's plane ([`traversal::PLANE_LEN`] cells).
    pub ray_plane: &'a mut [u8],
    /// Its line level ([`traversal::LINES_LEN`] cells).
    pub ray_lines: &'a mut [u8],
    /// Scratch plane of the tunnel checks ([`checks::CLOSED_SIDE`]³ cells).
    pub scratch: &'a mut [u8],
    /// The scene's buffers.
    pub scene: scene::Storage<'a>,
    /// The image ([`scene::IMAGE_LEN`] bytes).
    pub image: &'a mut [u8],
}

/// One line of the suite's output.
#[derive(Clone, Copy, Debug)]
pub enum Event<'a> {
    /// A digest.
    Digest(Line),
    /// A checker's tally.
    Check(checks::Tally),
    /// A checker found a violation (or a part could not run).
    Failure(&'static str, &'a dyn fmt::Debug),
}

impl fmt::Display for Event<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Digest(l) => l.fmt(f),
            Self::Check(t) => t.fmt(f),
            Self::Failure(what, e) => write!(f, "failure {what} {e:?}"),
        }
    }
}

/// Runs every part of the suite and reports each line to `out`: the
/// traversal digests, the voxelizer digests, the scene digests (and the
/// image in `image`), then the invariant checkers.
pub fn run(bufs: &mut Buffers<'_>, out: &mut dyn FnMut(Event<'_>)) {
    let Buffers {
        ray_plane,
        ray_lines,
        scratch,
        scene,
        image,
    } = bufs;
    match traversal::fill_raster(ray_plane, ray_lines) {
        Ok(()) => {}
        Err(e) => {
            out(Event::Failure("traversal raster", &e));
            return;
        }
    }
    let (raster, lined) = match rasters(ray_plane, ray_lines) {
        Ok(r) => r,
        Err(e) => {
            out(Event::Failure("traversal raster", &e));
            return;
        }
    };
    let mut plane = Digest::new();
    for &c in raster.plane() {
        plane.word(u64::from(c));
    }
    for &c in raster.lines() {
        plane.word(u64::from(c));
    }
    let mut digest = |l: Line| out(Event::Digest(l));
    digest(Line::of("ray.raster", &plane));
    traversal::digests(&raster, &lined, &mut digest);
    voxelizers::digests(&mut digest);
    scene_digests(scene, image, out);
    let tallies = checks::run(&raster, &lined, scratch, &mut |name, e| {
        out(Event::Failure(name, e));
    });
    for t in tallies {
        out(Event::Check(t));
    }
}

fn rasters<'a>(
    plane: &'a [u8],
    lines: &'a [u8],
) -> Result<(Raster<'a>, Raster<'a>), rrt_core::RasterError> {
    let raster = Raster::new(traversal::extent()?, plane)?;
    let lined = raster.with_lines(lines)?;
    Ok((raster, lined))
}

/// Builds and renders the scene, reporting `scene.*` and `example.image`;
/// then builds it again as the exact raster (object lists, the shadow
/// classification), reporting `scene.exact.*`.
pub fn scene_digests(
    st: &mut scene::Storage<'_>,
    image: &mut [u8],
    out: &mut dyn FnMut(Event<'_>),
) {
    let Some(report) = built_digests(st, scene::Variant::Paper, out) else {
        return;
    };
    let records = st.records.get(..report.records).unwrap_or(&[]);
    match scene::render(st.plane, st.lines, st.dir, records, image) {
        Ok(r) => {
            let mut d = Digest::new();
            d.debug(&r);
            for &b in image.iter() {
                d.word(u64::from(b));
            }
            d.add_items(u64::from(r.hits));
            out(Event::Digest(Line::of("example.image", &d)));
        }
        Err(e) => out(Event::Failure("scene render", &e)),
    }
    built_digests(st, scene::Variant::Exact, out);
}

/// Builds the scene into `st` as `variant` and reports its digests: the
/// reports (`scene.reports`), plane and line level (`scene.plane`), and
/// directory, records and object lists (`scene.records`), each name with
/// `.exact` after `scene` for the exact raster. `None` (and a failure)
/// when the build fails.
fn built_digests(
    st: &mut scene::Storage<'_>,
    variant: scene::Variant,
    out: &mut dyn FnMut(Event<'_>),
) -> Option<scene::SceneReport> {
    let names = match variant {
        scene::Variant::Paper => ["scene.reports", "scene.plane", "scene.records"],
        scene::Variant::Exact => [
            "scene.exact.reports",
            "scene.exact.plane",
            "scene.exact.records",
        ],
    };
    let report = match scene::build_with(st, variant, &mut |_, pass| pass()) {
        Ok(r) => r,
        Err(e) => {
            out(Event::Failure(
                match variant {
                    scene::Variant::Paper => "scene build",
                    scene::Variant::Exact => "scene build (exact)",
                },
                &e,
            ));
            return None;
        }
    };
    let records = st.records.get(..report.records).unwrap_or(&[]);
    let lists = st.lists.get(..report.lists).unwrap_or(&[]);
    let mut d = Digest::new();
    d.debug(&report);
    out(Event::Digest(Line::of(names[0], &d)));
    let mut d = Digest::new();
    for &c in st.plane.iter() {
        d.word(u64::from(c));
    }
    for &c in st.lines.iter() {
        d.word(u64::from(c));
    }
    out(Event::Digest(Line::of(names[1], &d)));
    let mut d = Digest::new();
    for &w in st.dir.iter() {
        d.word(u64::from(w));
    }
    for r in records {
        d.item();
        for w in bytemuck::bytes_of(r).chunks(4) {
            let mut b = [0u8; 4];
            b[..w.len()].copy_from_slice(w);
            d.word(u64::from(u32::from_le_bytes(b)));
        }
    }
    for &w in lists {
        d.word(u64::from(w));
    }
    out(Event::Digest(Line::of(names[2], &d)));
    Some(report)
}
