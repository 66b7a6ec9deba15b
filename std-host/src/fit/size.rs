//! The raster's frame for a scene: the box around all geometry grown by a
//! margin (or the caller's box), cubic voxels, `raster N` voxels along the
//! longest axis and the geometry centred.

use glam::DVec3;
use rrt_core::raster::{Extent, MAX_AXIS};

use super::memory::SurfaceMeasure;
use super::{FitError, FitOptions};
use crate::frame::RasterFrame;
use crate::scene::{Scene, View};

/// Margin in voxels around computed bounds by default.
pub const DEFAULT_MARGIN: u32 = 2;

/// The raster's frame for `scene` (no allocation, no conversion).
///
/// # Errors
/// As [`fit`](super::fit()), less the memory and range checks.
pub fn frame(scene: &Scene, opts: &FitOptions) -> Result<RasterFrame, FitError> {
    let n = opts.raster;
    if n == 0 || n > MAX_AXIS {
        return Err(FitError::RasterSize(n));
    }
    let (bounds, margin) = match opts.bounds {
        Some(b) => {
            if !(b.within_world() && b.min.cmplt(b.max).all()) {
                return Err(FitError::BadBounds {
                    min: b.min,
                    max: b.max,
                });
            }
            (b, 0)
        }
        None => (scene.bounds(), opts.margin),
    };
    let inner = u64::from(n).saturating_sub(2 * u64::from(margin));
    if inner == 0 {
        return Err(FitError::RasterBelowMargin { raster: n, margin });
    }
    let size = bounds.size();
    let longest = size.max_element();
    if !(longest > 0.0 && longest.is_finite() && bounds.within_world()) {
        return Err(FitError::NoExtent {
            file: scene.file.to_string(),
            min: bounds.min,
            max: bounds.max,
        });
    }
    let voxel = longest / inner as f64;
    let axis = size
        .to_array()
        .iter()
        .position(|&s| s == longest)
        .unwrap_or(0);
    let mut dims = [n; 3];
    for (k, d) in dims.iter_mut().enumerate() {
        if k != axis {
            // Tolerate rounding just above a whole number of voxels.
            let cells = (size[k] / voxel - 1e-9).ceil().max(0.0);
            let total = cells + 2.0 * f64::from(margin);
            *d = (total as u32).clamp(1, n);
        }
    }
    let extent = Extent::new(dims[0], dims[1], dims[2]).map_err(|_| FitError::RasterSize(n))?;
    let centre = (bounds.min + bounds.max) * 0.5;
    let origin = centre - DVec3::from(dims.map(f64::from)) * (voxel * 0.5);
    Ok(RasterFrame {
        extent,
        origin,
        voxel_size: voxel,
    })
}

/// The fewest voxels along the longest axis [`default_raster`] picks.
pub const MIN_DEFAULT_RASTER: u32 = 64;
/// The most voxels along the longest axis [`default_raster`] picks.
pub const MAX_DEFAULT_RASTER: u32 = 1024;
/// Rays per image for each estimated surface voxel of the default raster
/// ([`default_raster`]): where objects have exact geometry the image is
/// the same at any raster, and a finer one costs more to voxelize, to
/// classify for shadows and to walk than its smaller voxels save in
/// intersection tests, until voxels crowd with objects ([`CROWDING`]).
/// Set where the whole job (build and render) was fastest on the SPD
/// scenes (`BENCHMARKS.md`, *The default raster where objects have exact
/// geometry*).
pub const RAYS_PER_VOXEL: f64 = 16.0;
/// The fewest estimated surface voxels per surface primitive
/// [`default_raster`] accepts, in units of the 8 voxels a tiny primitive's
/// conservative voxelization takes: with fewer, voxels hold so many
/// objects that verifying them costs more than a finer raster saves.
pub const CROWDING: f64 = 4.0;
/// The most estimated surface voxels per ray of the image, beyond those
/// of [`MIN_DEFAULT_RASTER`] (the few every object takes however coarse
/// the raster), that the crowding floor ([`CROWDING`]) adds: beyond,
/// building the raster costs more than the render saves on voxels with
/// fewer objects (scenes of tens of thousands of small primitives).
pub const MAX_VOXELS_PER_RAY: f64 = 2.0;
/// The most primitives [`default_raster`] lets a small one (at most two
/// voxels long) share its voxel-sized cell with on average (`Σ n² / Σ n`
/// over the cells, `n` the small primitives whose box centre a cell
/// holds), where a raster at most twice as fine brings it there:
/// primitives clustered more tightly than the average over the scene
/// shows (leaves on a tree) get the finer raster.
pub const CLUSTERING: f64 = 64.0;

/// What a raster is for, to [`default_raster`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RasterNeed<'v> {
    /// The view the raster will be seen from.
    pub view: &'v View,
    /// Image width and height in pixels.
    pub image: [u32; 2],
    /// Rays per pixel (supersampling `k` gives `k²`).
    pub samples: u32,
    /// Whether hits are the voxels themselves (the paper's mode), so that
    /// voxels must be no larger than a pixel's footprint.
    pub discrete: bool,
}

/// Most voxels per sample spacing the default raster gives a scene whose
/// only voxel objects are sampled volumes' iso-surfaces.
pub const VOXELS_PER_SAMPLE: f64 = 8.0;

/// The raster size (voxels along the scene's longest axis) used when none
/// is given: fitted to the scene and the image, between
/// [`MIN_DEFAULT_RASTER`] and [`MAX_DEFAULT_RASTER`].
///
/// Objects with exact geometry are rendered exactly whatever the raster
/// (verification), so for them the raster is an acceleration structure:
/// the size is the largest whose estimated surface voxels
/// ([`SurfaceMeasure::voxels`]) do not exceed the rays per image over
/// [`RAYS_PER_VOXEL`] (more voxels cost more to build and to walk than
/// they save), but at least the size at which voxels do not crowd
/// ([`CROWDING`]) while that adds at most [`MAX_VOXELS_PER_RAY`]
/// estimated surface voxels per ray, and finer where small primitives cluster
/// ([`CLUSTERING`]); a scene without surface primitives (volumes, `.vox`
/// models, CSG only) starts from [`MIN_DEFAULT_RASTER`]. Where voxels are the picture (the paper's mode;
/// volumes, `.vox` models and CSG results, which have no exact geometry),
/// a voxel is in addition no larger than a pixel's footprint at the
/// scene's nearest point to the eye, but for that no smaller than
/// 1/[`VOXELS_PER_SAMPLE`] of the finest sample spacing where sampled
/// volumes are the only such objects. With volumes rendered directly, a
/// voxel is no smaller than their finest sample spacing.
#[must_use]
pub fn default_raster(scene: &Scene, need: &RasterNeed<'_>) -> u32 {
    let bounds = scene.bounds();
    let longest = bounds.size().max_element();
    if !(longest > 0.0 && longest.is_finite()) {
        return MIN_DEFAULT_RASTER;
    }
    let inner = |r: u32| f64::from(r.saturating_sub(2 * DEFAULT_MARGIN).max(1));
    let surface = SurfaceMeasure::of(scene);
    let voxels_at = |r: u32| surface.voxels(longest / inner(r));
    let [w, h] = need.image.map(f64::from);
    let rays = w * h * f64::from(need.samples).powi(2);
    let (lo, hi) = (MIN_DEFAULT_RASTER, MAX_DEFAULT_RASTER);
    // The largest size within the ray budget, the smallest that does not
    // crowd, and the largest within the build budget (all monotone in the
    // size: bisect). Without surface primitives there is nothing for the
    // raster to accelerate.
    let within = if surface.objects == 0 {
        lo
    } else {
        last_true(lo, hi, |r| voxels_at(r) * RAYS_PER_VOXEL <= rays.max(1.0))
    };
    // Voxels beyond those of the smallest raster (the ones every object
    // takes however coarse the raster), per ray.
    let least = voxels_at(lo);
    let built = last_true(lo, hi, |r| {
        voxels_at(r) - least <= MAX_VOXELS_PER_RAY * rays.max(1.0)
    });
    let crowd = 8.0 * CROWDING * surface.objects as f64;
    let uncrowded = if least < crowd {
        last_true(lo, hi, |r| voxels_at(r) < crowd).saturating_add(1)
    } else {
        lo
    };
    let mut r = within.max(uncrowded.min(hi).min(built));
    r = unclustered(
        scene,
        surface.objects,
        &bounds,
        |r| longest / inner(r),
        r,
        hi,
    );
    let voxel_objects =
        !(scene.volumes.is_empty() && scene.voxes.is_empty() && scene.csgs.is_empty());
    if need.discrete || voxel_objects {
        let mut pixel = pixel_raster(&bounds, longest, need);
        // Iso-surfaces of sampled volumes, the only voxel objects: voxels
        // finer than VOXELS_PER_SAMPLE a sample spacing add records, not
        // detail (an eye inside the scene's box asks for the largest
        // raster however coarse the data).
        if !need.discrete && scene.voxes.is_empty() && scene.csgs.is_empty() {
            let spacing = scene
                .volumes
                .iter()
                .map(|v| v.data.sample_spacing())
                .fold(f64::INFINITY, f64::min);
            let finest =
                (longest / spacing * VOXELS_PER_SAMPLE).ceil() + f64::from(2 * DEFAULT_MARGIN);
            if finest.is_finite() && finest < f64::from(pixel) {
                // Below pixel ≤ 2^16.
                pixel = finest as u32;
            }
        }
        r = r.max(pixel);
    }
    // Volumes rendered directly are pictures of their samples: voxels
    // finer than the finest sample spacing add records, not detail.
    let spacing = scene
        .volumes
        .iter()
        .filter(|v| v.data.classifier.is_direct())
        .map(|v| v.data.sample_spacing())
        .fold(f64::INFINITY, f64::min);
    if spacing > 0.0 && spacing.is_finite() {
        let samples = (longest / spacing).ceil() + f64::from(2 * DEFAULT_MARGIN);
        if samples < f64::from(r) {
            // Below r ≤ 2^16.
            r = samples as u32;
        }
    }
    r.clamp(lo, hi)
}

/// The smallest raster size from `r` on, at most `2·r` and `hi`, at which
/// the clustering of `scene`'s `n` surface primitives' small ones ([`clustering`], with
/// voxels of edge `voxel(size)`) is at most [`CLUSTERING`]; `r` where it
/// already is, or where no such size brings it there (primitives packed
/// more tightly than any of those rasters resolves, which a finer raster
/// only makes slower). Sizes are tried in steps of a tenth. Scenes of more
/// than [`CLUSTER_SAMPLE`] primitives are measured on every `k`-th one
/// (the least `k` that keeps the sample within it).
fn unclustered(
    scene: &Scene,
    n: usize,
    bounds: &crate::world::Bounds,
    voxel: impl Fn(u32) -> f64,
    r: u32,
    hi: u32,
) -> u32 {
    if n == 0 {
        return r;
    }
    let stride = n.div_ceil(CLUSTER_SAMPLE).max(1);
    let ok = |size: u32| {
        clustering(primitive_boxes(scene), stride, bounds.min, voxel(size)) <= CLUSTERING
    };
    if ok(r) {
        return r;
    }
    let top = r.saturating_mul(2).min(hi);
    let mut size = r;
    while size < top {
        size = size.saturating_add(size.div_ceil(10)).min(top);
        if ok(size) {
            return size;
        }
    }
    r
}

/// The most primitives [`clustering`] bins at once (8 MiB of cell keys).
const CLUSTER_SAMPLE: usize = 1 << 20;

/// The centre and longest side of the box of each of `scene`'s surface
/// primitives (spheres, cones, the triangles of polygons, tori), as
/// [`SurfaceMeasure`] counts them, in that order.
fn primitive_boxes(scene: &Scene) -> impl Iterator<Item = (DVec3, f64)> + '_ {
    use crate::shape::Primitive;
    let of = |b: crate::world::Bounds| (0.5 * (b.min + b.max), (b.max - b.min).max_element());
    let triangles = scene
        .polygons
        .iter()
        .flat_map(move |p| scene.polygon_triangles(p).map(move |t| of(t.bounds())));
    scene
        .spheres
        .iter()
        .map(move |o| of(o.shape.bounds()))
        .chain(scene.cones.iter().map(move |o| of(o.shape.bounds())))
        .chain(triangles)
        .chain(scene.tori.iter().map(move |o| of(o.shape.bounds())))
}

/// How many primitives a small one shares its cell with on average
/// (itself included), over the primitives `boxes` (box centre, longest
/// side) at most two voxels long, binned by their centres into cells of
/// edge `voxel` from `origin`: `m = Σ n² / Σ n` over the cells, `n` the
/// small primitives in a cell; 0 without any. Such primitives cover few
/// voxels, so those that share a cell crowd the same voxels' object lists.
/// With `stride` `k > 1`, only every `k`-th primitive is binned and `m` is
/// estimated as `1 + k·(m_k − 1)` from the sample's `m_k` (a cell's
/// sampled count has mean `n/k` and variance about `n/k`).
fn clustering(
    boxes: impl Iterator<Item = (DVec3, f64)>,
    stride: usize,
    origin: DVec3,
    voxel: f64,
) -> f64 {
    if !(voxel > 0.0 && voxel.is_finite()) {
        return 0.0;
    }
    let stride = stride.max(1);
    // Cells of a raster of at most 2^16 voxels a side: 21 bits each.
    let cell = |x: f64| ((x / voxel).floor().clamp(0.0, f64::from((1u32 << 21) - 1))) as u64;
    let mut keys: Vec<u64> = boxes
        .step_by(stride)
        .filter(|&(_, side)| side <= 2.0 * voxel)
        .map(|(c, _)| {
            let d = c - origin;
            cell(d.x) | cell(d.y) << 21 | cell(d.z) << 42
        })
        .collect();
    if keys.is_empty() {
        return 0.0;
    }
    keys.sort_unstable();
    let squares: f64 = keys
        .chunk_by(|a, b| a == b)
        .map(|run| (run.len() as f64).powi(2))
        .sum();
    let sampled = squares / keys.len() as f64;
    1.0 + stride as f64 * (sampled - 1.0)
}

/// The largest `r` in `lo..=hi` with `ok(r)` for a predicate true up to
/// some size and false after it; `lo` if it is false everywhere.
fn last_true(lo: u32, hi: u32, ok: impl Fn(u32) -> bool) -> u32 {
    let (mut a, mut b) = (lo, hi);
    if !ok(a) {
        return lo;
    }
    while a < b {
        let m = a + (b - a).div_ceil(2);
        if ok(m) { a = m } else { b = m - 1 }
    }
    a
}

/// The raster size whose voxels are as large as a pixel's footprint at
/// the point of `bounds` nearest the eye (the longest axis `longest`
/// over that footprint); [`MAX_DEFAULT_RASTER`] when the eye is inside.
fn pixel_raster(bounds: &crate::world::Bounds, longest: f64, need: &RasterNeed<'_>) -> u32 {
    let eye = need.view.from;
    let nearest = eye.clamp(bounds.min, bounds.max);
    let d = (nearest - eye).length();
    let rows = f64::from(need.image[1].max(2) - 1);
    let pitch = 2.0 * (need.view.angle.to_radians() * 0.5).tan() / rows;
    let footprint = d * pitch / f64::from(need.samples.max(1));
    if !(footprint > 0.0 && footprint.is_finite()) {
        return MAX_DEFAULT_RASTER;
    }
    let r = (longest / footprint).ceil() + f64::from(2 * DEFAULT_MARGIN);
    if r >= f64::from(MAX_DEFAULT_RASTER) {
        MAX_DEFAULT_RASTER
    } else {
        r as u32
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `n³` spheres of radius `radius` on a grid of spacing `spacing`
    /// about (5, 5, 5), and a sphere of radius 10 about the origin that
    /// sets the scene's box.
    fn cluster(n: usize, spacing: f64, radius: f64) -> Scene {
        let mut s = String::from(
            "v\nfrom 0 -60 0\nat 0 0 0\nup 0 0 1\nangle 40\nhither 1\nresolution 64 64\ns 0 0 0 10\n",
        );
        for i in 0..n * n * n {
            let p = [i % n, i / n % n, i / (n * n)].map(|k| 5.0 + spacing * k as f64);
            s.push_str(&format!("s {} {} {} {radius}\n", p[0], p[1], p[2]));
        }
        Scene::parse("cluster.nff", s.as_bytes()).unwrap()
    }

    /// 27,000 spheres of radius 0.2 one unit apart: the crowding floor
    /// wants 864,000 estimated surface voxels. A 256² image lets it add at
    /// most [`MAX_VOXELS_PER_RAY`] per ray to those of the smallest
    /// raster, so the raster is the largest within that; a 1024² image
    /// allows more, and the crowding floor decides.
    #[test]
    fn the_crowding_floor_stops_at_the_build_budget() {
        let mut text = String::from(
            "v\nfrom 15 -80 15\nat 15 15 15\nup 0 0 1\nangle 40\nhither 1\nresolution 64 64\n",
        );
        for i in 0..27_000 {
            let p = [i % 30, i / 30 % 30, i / 900].map(f64::from);
            text.push_str(&format!("s {} {} {} 0.2\n", p[0], p[1], p[2]));
        }
        let scene = Scene::parse("grid.nff", text.as_bytes()).unwrap();
        let longest = scene.bounds().size().max_element();
        let surface = SurfaceMeasure::of(&scene);
        let voxels = |r: u32| surface.voxels(longest / f64::from(r - 2 * DEFAULT_MARGIN));
        let crowd = 8.0 * CROWDING * surface.objects as f64;
        let size = |side: u32| {
            let need = RasterNeed {
                view: &scene.view,
                image: [side, side],
                samples: 1,
                discrete: false,
            };
            (default_raster(&scene, &need), f64::from(side * side))
        };
        let added = |r: u32| voxels(r) - voxels(MIN_DEFAULT_RASTER);
        let (r, rays) = size(256);
        assert!(added(r) <= MAX_VOXELS_PER_RAY * rays, "{r}");
        assert!(added(r + 1) > MAX_VOXELS_PER_RAY * rays, "{r}");
        assert!(voxels(r) < crowd, "{r}");
        let (r, rays) = size(1024);
        assert!(voxels(r) >= crowd && voxels(r - 1) < crowd, "{r}");
        assert!(added(r) <= MAX_VOXELS_PER_RAY * rays, "{r}");
    }

    #[test]
    fn clustering_counts_the_small_primitives_sharing_a_cell() {
        let at = |x: f64, side: f64| (DVec3::splat(x), side);
        // Four in one cell, one alone: (16 + 1) / 5.
        let p = [0.1, 0.2, 0.3, 0.4, 5.5].map(|x| at(x, 0.05));
        let m = |voxel: f64| clustering(p.iter().copied(), 1, DVec3::ZERO, voxel);
        assert!((m(1.0) - 17.0 / 5.0).abs() < 1e-12);
        // Each in its own cell.
        assert_eq!(m(0.09), 1.0);
        // Primitives over two voxels long do not count.
        assert_eq!(m(0.02), 0.0);
        assert_eq!(clustering(std::iter::empty(), 1, DVec3::ZERO, 1.0), 0.0);
        // Sampled: a thousand in one cell, every tenth binned, estimate
        // 1 + 10·(100 − 1); a thousand in cells of their own stay at 1.
        let one = (0..1000).map(|i| (DVec3::splat(f64::from(i) * 1e-4), 1e-5));
        assert_eq!(clustering(one, 10, DVec3::ZERO, 1.0), 991.0);
        let apart = (0..1000).map(|i| (DVec3::splat(f64::from(i)), 1e-5));
        assert_eq!(clustering(apart, 10, DVec3::ZERO, 0.5), 1.0);
    }

    /// 729 tiny spheres packed in a box 0.16 across share the voxels of a
    /// coarse raster of the 20-unit scene; the smallest raster up to twice
    /// as fine where they share a cell with at most [`CLUSTERING`] is
    /// chosen, and a cluster no such raster resolves keeps the size.
    #[test]
    fn clustered_small_primitives_get_a_finer_raster() {
        let scene = cluster(9, 0.02, 0.001);
        let bounds = scene.bounds();
        let longest = bounds.size().max_element();
        let voxel = |r: u32| longest / f64::from(r - 2 * DEFAULT_MARGIN);
        let n = SurfaceMeasure::of(&scene).objects;
        assert_eq!((n, primitive_boxes(&scene).count()), (730, 730));
        let m = |r: u32| clustering(primitive_boxes(&scene), 1, bounds.min, voxel(r));
        assert!(m(100) > CLUSTERING, "{}", m(100));
        let r = unclustered(&scene, n, &bounds, voxel, 100, 1024);
        assert!(r > 100 && r <= 200, "{r}");
        assert!(m(r) <= CLUSTERING, "{}", m(r));
        // A size before it in the steps of a tenth is still clustered.
        assert!(m(r - r.div_ceil(11)) > CLUSTERING || r <= 111, "{r}");
        // Already fine enough: unchanged.
        assert_eq!(unclustered(&scene, n, &bounds, voxel, r, 1024), r);
        // Packed a thousand times tighter: no raster up to twice as fine
        // resolves them, so the size stays.
        let tight = cluster(9, 2e-5, 1e-6);
        let tb = tight.bounds();
        assert_eq!(unclustered(&tight, n, &tb, voxel, 100, 1024), 100);
        // Never past `hi`.
        assert!(unclustered(&scene, n, &bounds, voxel, 100, 120) <= 120);
    }
}
