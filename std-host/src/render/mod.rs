//! The image: primary rays for every pixel, in parallel, deterministic.
//!
//! The image is cut into tiles of [`TILE_W`] × [`TILE_H`] pixels. The
//! threads of a rayon pool take them in scanline order from one shared
//! counter, so at any moment they work on neighbouring tiles, whose rays
//! read largely the same raster lines: the threads share those lines in
//! the last-level cache instead of each streaming its own part of the
//! raster. Each tile is cut into 4×2 pixel blocks
//! traced through [`Tracer::trace_block`] (eight rays: the lanes of a ray
//! packet). With supersampling `K`, each pixel gets `K × K` rays at the
//! sub-pixel offsets of [`crate::render::camera::sample_offset`] (row by row), and
//! their colours are averaged (a box filter) before the 8-bit conversion.
//!
//! **Alpha.** On request ([`RenderOptions::alpha`]) the image also has
//! each pixel's coverage, the mean of its rays' coverage
//! ([`Traced::alpha`]: 1 − the ray's transmittance to the background), and
//! its colour without the background in straight (not premultiplied)
//! alpha, as PNG's RGBA keeps it ([`Alpha`]).
//!
//! **Determinism.** Every pixel's colour and coverage depend only on its own
//! rays, and its samples are summed in a fixed order; tiles are written in
//! place. The image is therefore byte-identical for every thread count.
//! The ray counts are integer sums, identical as well.
//!
//! **Bands.** [`render_rows`] renders only some rows of the image (a
//! [`band::Band`]): the tiles and 4×2 blocks are those of the whole image
//! (its grid, clipped to the rows), the camera is the whole image's, and
//! a pixel's colour depends only on its own rays (a packet's lanes agree
//! bit for bit with scalar rays), so a band's pixels are byte-identical to
//! the same rows of the whole image.

pub mod band;
pub mod camera;

use std::sync::Mutex;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::{Duration, Instant};

use indicatif::ProgressBar;

use self::camera::{Camera, sample_offset};
use crate::trace::shading;
use crate::trace::{BLOCK, BLOCK_H, BLOCK_W, RayStats, Traced, Tracer};
use crate::world::Ray;

/// Tile width in pixels (a multiple of the block width).
pub const TILE_W: u32 = 32;
/// Tile height in pixels (a multiple of the block height).
pub const TILE_H: u32 = 8;
/// Largest image side accepted (as a scene's resolution).
pub const MAX_SIDE: u32 = crate::scene::nff::MAX_RESOLUTION;
/// Largest supersampling factor accepted (K × K rays per pixel).
pub const MAX_SUPERSAMPLE: u32 = 16;
/// Most primary rays one render may trace (`width · height · K²`).
pub const MAX_PRIMARY_RAYS: u64 = 1 << 32;

/// An 8-bit RGB image, rows top to bottom.
#[derive(Clone, Debug, PartialEq)]
pub struct Image {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// `3 · width · height` bytes, RGB, rows top to bottom: the linear
    /// colour clamped to `[0, 1]` and rounded to 8 bits
    /// ([`shading::to_rgb8`]).
    pub rgb: Vec<u8>,
    /// `3 · width · height` linear RGB values, unclamped (each pixel's
    /// mean of its samples, as `f32`), for the sRGB, 16-bit and HDR
    /// outputs.
    pub linear: Vec<f32>,
    /// The coverage and the straight colour, when asked for
    /// ([`RenderOptions::alpha`]).
    pub alpha: Option<Alpha>,
}

/// An image's alpha: per pixel, how much of it the background is not,
/// and its colour without the background.
///
/// Compositing the straight colour over the scene's background,
/// `straight · alpha + background · (1 − alpha)`, gives the image's
/// [`Image::linear`] colour (to rounding); where `alpha` is 1 the straight
/// colour is that colour exactly, and where it is 0 (nothing but the
/// background) it is the background.
#[derive(Clone, Debug, PartialEq)]
pub struct Alpha {
    /// `width · height` coverages in `[0, 1]`, rows top to bottom: the
    /// mean of the pixel's rays' [`Traced::alpha`] (0 where every ray sees
    /// the background, 1 where every ray ends on a surface or in a volume
    /// opaque enough to end it, the opacity composited in between).
    pub coverage: Vec<f32>,
    /// `3 · width · height` linear RGB values, unclamped: the pixel's
    /// colour without the background in straight alpha (the mean of its
    /// rays' [`Traced::foreground`] divided by the coverage); the
    /// background's colour where the coverage is 0.
    pub straight: Vec<f32>,
}

/// How to render.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RenderOptions {
    /// Rays per pixel along each axis (`K × K` in all).
    pub supersample: u32,
    /// Worker threads; 0 for rayon's default (one per core).
    pub threads: usize,
    /// Keep each pixel's coverage and straight colour ([`Image::alpha`]).
    pub alpha: bool,
}

impl Default for RenderOptions {
    fn default() -> Self {
        Self {
            supersample: 1,
            threads: 0,
            alpha: false,
        }
    }
}

/// Why rendering failed.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum RenderError {
    /// A size out of range.
    #[error("{what}: {message}")]
    Size {
        /// The option.
        what: &'static str,
        /// What is wrong.
        message: String,
    },
    /// The image does not fit in memory.
    #[error("cannot allocate {bytes} bytes for the image")]
    Memory {
        /// The allocation refused.
        bytes: u64,
    },
    /// The thread pool could not be started.
    #[error("cannot start {threads} render threads")]
    Threads {
        /// How many.
        threads: usize,
        /// Why.
        #[source]
        source: rayon::ThreadPoolBuildError,
    },
}

/// Checks image size and supersampling against the limits.
///
/// # Errors
/// [`RenderError::Size`] naming the option.
pub fn check_sizes(width: u32, height: u32, supersample: u32) -> Result<(), RenderError> {
    for (what, v) in [("width", width), ("height", height)] {
        if !(1..=MAX_SIDE).contains(&v) {
            return Err(RenderError::Size {
                what,
                message: format!("expected 1 to {MAX_SIDE} pixels, found {v}"),
            });
        }
    }
    if !(1..=MAX_SUPERSAMPLE).contains(&supersample) {
        return Err(RenderError::Size {
            what: "supersample",
            message: format!(
                "expected 1 to {MAX_SUPERSAMPLE} rays per pixel side, found {supersample}"
            ),
        });
    }
    let rays = u64::from(width) * u64::from(height) * u64::from(supersample).pow(2);
    if rays > MAX_PRIMARY_RAYS {
        return Err(RenderError::Size {
            what: "supersample",
            message: format!(
                "{width}×{height} pixels with {supersample}×{supersample} rays each is {rays} primary rays, more than {MAX_PRIMARY_RAYS}"
            ),
        });
    }
    Ok(())
}

/// Renders the camera's image with `tracer`. `progress` counts tiles.
///
/// # Errors
/// [`RenderError`]: sizes out of range, no threads.
pub fn render(
    tracer: &Tracer<'_>,
    camera: &Camera,
    opts: &RenderOptions,
    progress: &ProgressBar,
) -> Result<(Image, RayStats, Duration), RenderError> {
    render_rows(tracer, camera, opts, 0..camera.height, progress)
}

/// Renders rows `rows` of the camera's image (top row 0) with `tracer`:
/// an image of the camera's width and `rows.len()` rows, byte-identical
/// to those rows of [`render`]'s image (module docs). `progress` counts
/// tiles.
///
/// # Errors
/// [`RenderError`]: sizes out of range, rows empty or outside the image,
/// no threads.
pub fn render_rows(
    tracer: &Tracer<'_>,
    camera: &Camera,
    opts: &RenderOptions,
    rows: std::ops::Range<u32>,
    progress: &ProgressBar,
) -> Result<(Image, RayStats, Duration), RenderError> {
    let (w, h, k) = (camera.width, camera.height, opts.supersample);
    check_sizes(w, h, k)?;
    if rows.is_empty() || rows.end > h {
        return Err(RenderError::Size {
            what: "rows",
            message: format!(
                "expected a non-empty range of the image's rows 0..{h}, found {}..{}",
                rows.start, rows.end
            ),
        });
    }
    // The whole image's tile grid, its rows of tiles that meet `rows`.
    let tiles_x = w.div_ceil(TILE_W);
    let first_ty = rows.start / TILE_H;
    let tiles_y = rows.end.div_ceil(TILE_H) - first_ty;
    let tiles = u64::from(tiles_x) * u64::from(tiles_y);
    crate::progress::phase(progress, "rendering", crate::progress::Unit::Tiles, tiles);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(opts.threads)
        .build()
        .map_err(|source| RenderError::Threads {
            threads: opts.threads,
            source,
        })?;
    let bh = rows.end - rows.start;
    let n = w as usize * bh as usize;
    // The image is allocated before any ray (fallibly: a size the machine
    // cannot hold is an error, not an abort); tiles are written into it as
    // they finish.
    let image = Mutex::new(Image {
        width: w,
        height: bh,
        rgb: zeroed(3 * n)?,
        linear: zeroed(3 * n)?,
        alpha: if opts.alpha {
            Some(Alpha {
                coverage: zeroed(n)?,
                straight: zeroed(3 * n)?,
            })
        } else {
            None
        },
    });
    let t0 = Instant::now();
    // Every thread takes the next tile in scanline order from one counter
    // (module docs: neighbouring tiles share the raster lines they read).
    let next = AtomicU64::new(0);
    let per_thread: Vec<RayStats> = pool.broadcast(|_| {
        let mut stats = RayStats::default();
        loop {
            let t = next.fetch_add(1, Ordering::Relaxed);
            if t >= tiles {
                break stats;
            }
            let tx = u32::try_from(t % u64::from(tiles_x)).unwrap_or(0);
            let ty = first_ty + u32::try_from(t / u64::from(tiles_x)).unwrap_or(0);
            let tile = Tile {
                x0: tx * TILE_W,
                y0: ty * TILE_H,
                rows: rows.clone(),
            };
            let (pixels, s) = render_tile(tracer, camera, k, &tile);
            stats.add(&s);
            // A poisoned lock means another tile's thread panicked, which
            // the broadcast passes on.
            if let Ok(mut image) = image.lock() {
                place(&mut image, &tile, &pixels);
            }
            progress.inc(1);
        }
    });
    let elapsed = t0.elapsed();
    let mut stats = RayStats::default();
    for s in &per_thread {
        stats.add(s);
    }
    let image = image.into_inner().map_err(|_| RenderError::Size {
        what: "image",
        message: "a render thread failed".to_string(),
    })?;
    Ok((image, stats, elapsed))
}

/// Bytes of memory [`render_rows`] needs for an image `width` pixels
/// wide of `rows` rows, with alpha or not: the image it returns (8-bit
/// RGB and linear `f32` RGB per pixel, coverage and straight colour with
/// alpha), which it allocates before tracing any ray.
#[must_use]
pub fn image_bytes(width: u32, rows: u32, alpha: bool) -> u64 {
    let per_pixel = 3 + 12 + if alpha { 4 + 12 } else { 0 };
    u64::from(width) * u64::from(rows) * per_pixel
}

/// `len` zeroed values, or [`RenderError::Memory`] when they cannot be
/// allocated.
fn zeroed<T: Copy + Default>(len: usize) -> Result<Vec<T>, RenderError> {
    let mut v = Vec::new();
    v.try_reserve_exact(len).map_err(|_| RenderError::Memory {
        bytes: u64::try_from(len.saturating_mul(size_of::<T>())).unwrap_or(u64::MAX),
    })?;
    v.resize(len, T::default());
    Ok(v)
}

/// Writes a tile's pixels (of [`render_tile`]) into `image`, which holds
/// the tile's rows `tile.rows`.
fn place(image: &mut Image, tile: &Tile, pixels: &[Pixel]) {
    let w = image.width as usize;
    let tw = TILE_W.min(image.width - tile.x0) as usize;
    // The tile's first row within the band.
    let y0 = (tile.y0.max(tile.rows.start) - tile.rows.start) as usize;
    for (j, row) in pixels.chunks(tw).enumerate() {
        let first = (y0 + j) * w + tile.x0 as usize;
        for (i, p) in row.iter().enumerate() {
            let at = 3 * (first + i);
            if let Some(c) = image.rgb.get_mut(at..at + 3) {
                c.copy_from_slice(&p.rgb);
            }
            if let Some(c) = image.linear.get_mut(at..at + 3) {
                c.copy_from_slice(&p.linear);
            }
            if let Some(a) = image.alpha.as_mut() {
                if let Some(c) = a.coverage.get_mut(first + i) {
                    *c = p.coverage;
                }
                if let Some(c) = a.straight.get_mut(at..at + 3) {
                    c.copy_from_slice(&p.straight);
                }
            }
        }
    }
}

/// One pixel of a tile: its samples' means.
struct Pixel {
    /// [`Image::rgb`]'s value.
    rgb: [u8; 3],
    /// [`Image::linear`]'s value.
    linear: [f32; 3],
    /// [`Alpha::coverage`]'s value.
    coverage: f32,
    /// [`Alpha::straight`]'s value.
    straight: [f32; 3],
}

/// One tile's pixels, row by row, and its ray counts.
type TileResult = (Vec<Pixel>, RayStats);

/// A tile of the whole image's grid, clipped to the rows rendered.
struct Tile {
    /// The tile's top left pixel in the whole image.
    x0: u32,
    y0: u32,
    /// The rows rendered.
    rows: std::ops::Range<u32>,
}

/// Renders the tile's pixels in its rows: the blocks of the whole
/// image's tile (from its top left pixel), lanes outside the rows empty.
fn render_tile(tracer: &Tracer<'_>, camera: &Camera, k: u32, tile: &Tile) -> TileResult {
    let x0 = tile.x0;
    let x1 = (x0 + TILE_W).min(camera.width);
    let y1 = (tile.y0 + TILE_H).min(camera.height).min(tile.rows.end);
    let y0 = tile.y0.max(tile.rows.start);
    let tw = (x1 - x0) as usize;
    let mut sums = vec![Traced::default(); tw * (y1 - y0) as usize];
    let mut stats = RayStats::default();
    // The blocks of the whole tile's grid that meet the rows.
    let first_by = tile.y0 + (y0 - tile.y0) / BLOCK_H * BLOCK_H;
    for by in (first_by..y1).step_by(BLOCK_H as usize) {
        for bx in (x0..x1).step_by(BLOCK_W as usize) {
            let lane_pixel = |lane: u32| {
                let (x, y) = (bx + lane % BLOCK_W, by + lane / BLOCK_W);
                (x < x1 && (y0..y1).contains(&y)).then_some((x, y))
            };
            for j in 0..k {
                for i in 0..k {
                    let (ox, oy) = (sample_offset(i, k), sample_offset(j, k));
                    let rays: [Option<Ray>; BLOCK] = std::array::from_fn(|lane| {
                        let (x, y) = lane_pixel(lane as u32)?;
                        Some(camera.ray(f64::from(x) + ox, f64::from(y) + oy))
                    });
                    let traced = tracer.trace_block(&rays, &mut stats);
                    for (lane, c) in traced.iter().enumerate() {
                        if let Some((x, y)) = lane_pixel(lane as u32) {
                            let s = &mut sums[(y - y0) as usize * tw + (x - x0) as usize];
                            s.colour += c.colour;
                            s.foreground += c.foreground;
                            s.alpha += c.alpha;
                        }
                    }
                }
            }
        }
    }
    let n = f64::from(k * k);
    (
        sums.iter()
            .map(|s| {
                let c = s.colour / n;
                let alpha = s.alpha / n;
                let straight = if alpha > 0.0 {
                    s.foreground / n / alpha
                } else {
                    c
                };
                Pixel {
                    rgb: shading::to_rgb8(c),
                    linear: c.as_vec3().to_array(),
                    coverage: alpha as f32,
                    straight: straight.as_vec3().to_array(),
                }
            })
            .collect(),
        stats,
    )
}
