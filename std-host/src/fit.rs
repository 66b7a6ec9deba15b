//! Fitting the 3D raster to a scene: world coordinates to fixed-point
//! raster coordinates, once.
//!
//! The raster's box is the box around all geometry ([`Scene::bounds`]:
//! spheres ± radius, polygon vertices, cone end discs ± radius) grown by a
//! margin of a few voxels on every side, or exactly the box the caller
//! gives. Voxels are cubes: `raster N` is the number of voxels along the
//! box's longest axis, and each other axis gets `ceil(extent / voxel)`
//! voxels (plus the margins), the geometry centred in it.
//!
//! [`fit`] then converts every object to the core's fixed-point geometry
//! ([`rrt_core::geometry`]: positions in 1/65536 voxel, unit normals
//! scaled by 2^30): spheres, triangles (polygons fan-triangulated, `pp`
//! patches with their vertex normals normalised) and open cones; and
//! every light to a fixed-point position (lights may lie outside the
//! raster). [`RasterFrame`] keeps the mapping both ways.
//!
//! Before anything is allocated, [`MemoryEstimate`] bounds what the
//! voxelized raster will take, and [`fit`] refuses a raster that would
//! exceed the caller's limit ([`default_max_memory`]: half the machine's
//! RAM).

#![deny(missing_docs)]

use std::f64::consts::PI;
use std::fmt;

use glam::DVec3;
use rrt_core::geometry::Point;
use rrt_core::object_table as table;
use rrt_core::raster::{Extent, LINE_CELLS, MAX_AXIS};

use crate::frame::RasterFrame;
use crate::scene::{Object, Scene, SourceLoc};
use crate::shape::{Shape, Surface, Unfit};
use crate::world::Bounds;

/// Bytes per voxel record, for the memory estimate.
pub const RECORD_BYTES: u64 = 20;
/// Voxels per brick of the brick directory, for the memory estimate.
pub const BRICK_VOXELS: u64 = 512;
/// Bytes per brick directory entry.
pub const BRICK_ENTRY_BYTES: u64 = 4;
/// Upper bound on the voxels per voxel² of surface for the thickest
/// (26-tunnel-free) voxelization: a standard digital surface is
/// `|nx| + |ny| + |nz| ≤ √3` voxels thick.
pub const SURFACE_VOXELS_PER_AREA: f64 = 1.8;
/// Margin in voxels around computed bounds by default.
pub const DEFAULT_MARGIN: u32 = 2;
/// Machine memory assumed when `/proc/meminfo` cannot be read.
pub const FALLBACK_TOTAL_MEMORY: u64 = 8 << 30;

/// How to fit the raster.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FitOptions {
    /// Voxels along the longest axis (1 to 65536).
    pub raster: u32,
    /// World box to fill instead of the geometry's bounds (used exactly,
    /// without margin).
    pub bounds: Option<Bounds>,
    /// Voxels of margin around computed bounds on every side.
    pub margin: u32,
    /// Refuse rasters whose estimated memory exceeds this many bytes.
    pub max_memory: u64,
    /// Count sphere interiors in the memory estimate (a voxelizer that
    /// fills solids); surfaces are always counted.
    pub solid_spheres: bool,
}

impl FitOptions {
    /// `raster` voxels along the longest axis, computed bounds with the
    /// default margin, half the machine's memory as the limit, solid
    /// spheres counted.
    #[must_use]
    pub fn new(raster: u32) -> Self {
        Self {
            raster,
            bounds: None,
            margin: DEFAULT_MARGIN,
            max_memory: default_max_memory(),
            solid_spheres: true,
        }
    }
}

/// Why a raster cannot be fitted.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum FitError {
    /// `raster N` out of range.
    #[error("raster {0}: expected 1 to {MAX_AXIS} voxels along the longest axis")]
    RasterSize(u32),
    /// `raster N` leaves nothing inside the margins.
    #[error("raster {raster}: too small for a margin of {margin} voxels on each side; use at least {}", 2 * u64::from(*margin) + 1)]
    RasterBelowMargin {
        /// The raster size.
        raster: u32,
        /// The margin.
        margin: u32,
    },
    /// Explicit bounds that are not a box.
    #[error("bounds {min} to {max}: expected finite corners with min < max on every axis")]
    BadBounds {
        /// Lowest corner.
        min: DVec3,
        /// Highest corner.
        max: DVec3,
    },
    /// The geometry has no extent (or is not finite).
    #[error("{file}: the geometry's bounds {min} to {max} have no size to fit a raster to")]
    NoExtent {
        /// The scene file.
        file: String,
        /// Lowest corner.
        min: DVec3,
        /// Highest corner.
        max: DVec3,
    },
    /// The estimated memory exceeds the limit.
    #[error("raster {dims}: needs about {} ({estimate}), more than the limit of {}; use a smaller raster or a larger memory limit", Bytes(estimate.total()), Bytes(*limit))]
    TooMuchMemory {
        /// Voxels per axis, e.g. `1024×1024×87`.
        dims: Dims,
        /// The estimate.
        estimate: MemoryEstimate,
        /// The limit in bytes.
        limit: u64,
    },
    /// A light or object lies too far from the raster for fixed point.
    #[error("{loc}: {what} lies more than 2^31 voxels from the raster")]
    OutOfRange {
        /// Where it is defined.
        loc: SourceLoc,
        /// What it is.
        what: &'static str,
    },
}

/// Voxel counts per axis, printed as `nx×ny×nz`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Dims(pub [u32; 3]);

impl fmt::Display for Dims {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}×{}×{}", self.0[0], self.0[1], self.0[2])
    }
}

/// A byte count printed with a binary unit (`1.5 GiB`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Bytes(pub u64);

impl fmt::Display for Bytes {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        const UNITS: [&str; 5] = ["KiB", "MiB", "GiB", "TiB", "PiB"];
        if self.0 < 1024 {
            return write!(f, "{} B", self.0);
        }
        let mut v = self.0 as f64 / 1024.0;
        let mut unit = UNITS[0];
        for u in &UNITS[1..] {
            if v < 1024.0 {
                break;
            }
            v /= 1024.0;
            unit = u;
        }
        write!(f, "{v:.1} {unit}")
    }
}

/// An upper-bound estimate of a voxelized raster's memory.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct MemoryEstimate {
    /// Voxels in the raster.
    pub voxels: u64,
    /// The plane: one byte per voxel.
    pub plane: u64,
    /// The plane's line level: one byte per 64 voxels.
    pub lines: u64,
    /// The brick directory: [`BRICK_ENTRY_BYTES`] per [`BRICK_VOXELS`] voxels.
    pub directory: u64,
    /// Upper bound on the non-transparent voxels (at most `voxels`).
    pub record_voxels: u64,
    /// Their records: [`RECORD_BYTES`] each.
    pub records: u64,
}

impl MemoryEstimate {
    /// Total bytes (saturating).
    #[must_use]
    pub fn total(&self) -> u64 {
        self.plane
            .saturating_add(self.lines)
            .saturating_add(self.directory)
            .saturating_add(self.records)
    }
}

impl fmt::Display for MemoryEstimate {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "plane {}, line level {}, brick directory {}, records for up to {} voxels {}",
            Bytes(self.plane),
            Bytes(self.lines),
            Bytes(self.directory),
            self.record_voxels,
            Bytes(self.records)
        )
    }
}

/// One object of the object table: its exact world geometry and, made of
/// it, the core's fixed-point geometry in the raster.
#[derive(Clone, Debug, PartialEq)]
pub struct FittedObject {
    /// The world geometry (what intersection verification intersects).
    pub shape: Shape,
    /// The core's object-table entry: the fixed-point geometry the
    /// voxelizer draws and the light pass reads.
    pub entry: table::Shape,
    /// Index into `Scene::materials`.
    pub material: usize,
    /// What the scene calls it (`sphere`, `cone`, `polygon`), for messages.
    pub kind: &'static str,
    /// Where the scene object is defined.
    pub loc: SourceLoc,
}

/// A light in fixed-point raster coordinates.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FittedLight {
    /// Position in fixed units (anywhere within [`MAX_FIXED`](crate::frame::MAX_FIXED)).
    pub position: Point,
    /// Colour (white if the file gives none).
    pub colour: DVec3,
}

/// Objects left out of the object table.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Dropped {
    /// Triangles and cones that have no area once in fixed point.
    pub degenerate: usize,
    /// Objects entirely outside explicit bounds.
    pub outside: usize,
}

/// A scene fitted to a raster.
#[derive(Clone, Debug, PartialEq)]
pub struct Fitted {
    /// The mapping between world and raster.
    pub frame: RasterFrame,
    /// The object table: spheres, then cones, then polygon triangles, each
    /// in file order.
    pub objects: Vec<FittedObject>,
    /// Lights in file order.
    pub lights: Vec<FittedLight>,
    /// The memory estimate that was checked.
    pub memory: MemoryEstimate,
    /// What was left out.
    pub dropped: Dropped,
}

/// Fits a raster to `scene`, checks the memory estimate, and converts the
/// geometry and lights to fixed point.
///
/// # Errors
/// [`FitError`]: an absurd raster size, bad explicit bounds, geometry
/// without extent, an estimate above `opts.max_memory`, or a light or
/// object too far from the raster.
pub fn fit(scene: &Scene, opts: &FitOptions) -> Result<Fitted, FitError> {
    let frame = frame(scene, opts)?;
    let memory = estimate_memory(scene, &frame, opts.solid_spheres);
    if memory.total() > opts.max_memory {
        return Err(FitError::TooMuchMemory {
            dims: Dims(frame.dims()),
            estimate: memory,
            limit: opts.max_memory,
        });
    }
    let mut table = Table {
        frame: &frame,
        world: frame.world_bounds(),
        objects: Vec::with_capacity(
            scene.spheres.len() + scene.cones.len() + scene.triangle_count() + scene.tori.len(),
        ),
        dropped: Dropped::default(),
    };
    table.add_all(&scene.spheres)?;
    table.add_all(&scene.cones)?;
    for p in &scene.polygons {
        if table.outside(scene.polygon_bounds(p)) {
            table.dropped.outside += p.count.saturating_sub(2);
            continue;
        }
        for t in scene.polygon_triangles(p) {
            table.add(t, p.material, "polygon", &p.loc)?;
        }
    }
    table.add_all(&scene.tori)?;
    let lights = scene
        .lights
        .iter()
        .map(|l| {
            Ok(FittedLight {
                position: frame.to_fixed(l.position).ok_or(FitError::OutOfRange {
                    loc: l.loc.clone(),
                    what: "light",
                })?,
                colour: l.rgb(),
            })
        })
        .collect::<Result<_, FitError>>()?;
    let Table {
        objects, dropped, ..
    } = table;
    Ok(Fitted {
        frame,
        objects,
        lights,
        memory,
        dropped,
    })
}

/// The object table as [`fit`] fills it.
struct Table<'f> {
    frame: &'f RasterFrame,
    /// The raster's world box.
    world: Bounds,
    objects: Vec<FittedObject>,
    dropped: Dropped,
}

impl Table<'_> {
    /// Whether world box `b` lies entirely outside the raster.
    fn outside(&self, b: Bounds) -> bool {
        b.max.cmplt(self.world.min).any() || b.min.cmpgt(self.world.max).any()
    }

    /// Adds `shape` of a scene object (`kind` at `loc`), or counts it as
    /// dropped when nothing of it is left in fixed point.
    fn add<S: Surface>(
        &mut self,
        shape: S,
        material: usize,
        kind: &'static str,
        loc: &SourceLoc,
    ) -> Result<(), FitError> {
        match shape.to_fixed(self.frame) {
            Ok(fixed) => self.objects.push(FittedObject {
                shape: shape.into(),
                entry: S::entry(fixed),
                material,
                kind,
                loc: loc.clone(),
            }),
            Err(Unfit::Degenerate) => self.dropped.degenerate += 1,
            Err(Unfit::OutOfRange) => {
                return Err(FitError::OutOfRange {
                    loc: loc.clone(),
                    what: kind,
                });
            }
        }
        Ok(())
    }

    /// Adds every object of `list` that does not lie outside the raster.
    fn add_all<S: Surface>(&mut self, list: &[Object<S>]) -> Result<(), FitError> {
        for o in list {
            if self.outside(o.shape.bounds()) {
                self.dropped.outside += 1;
                continue;
            }
            self.add(o.shape, o.material, S::KIND, &o.loc)?;
        }
        Ok(())
    }
}

/// The raster's frame for `scene` (no allocation, no conversion).
///
/// # Errors
/// As [`fit`], less the memory and range checks.
pub fn frame(scene: &Scene, opts: &FitOptions) -> Result<RasterFrame, FitError> {
    let n = opts.raster;
    if n == 0 || n > MAX_AXIS {
        return Err(FitError::RasterSize(n));
    }
    let (bounds, margin) = match opts.bounds {
        Some(b) => {
            if !(b.min.is_finite() && b.max.is_finite() && b.min.cmplt(b.max).all()) {
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
    if !(longest > 0.0 && longest.is_finite() && bounds.min.is_finite()) {
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

/// Upper-bound memory estimate for `scene` voxelized into `frame`,
/// computed from the world geometry without allocating.
///
/// The plane takes 1 byte per voxel, its line level 1 byte per 64 voxels
/// and the brick directory 4 bytes per 512 voxels. Non-transparent voxels are bounded by surface area `A`
/// and boundary length `P` (in voxel units): a surface generates at most
/// `1.8·(A + P + 3)` voxels in the thickest (26-tunnel-free)
/// voxelization, the `P` and constant terms covering edges and tiny
/// objects; solid spheres add their volume, `4/3·π·(r + 1)³`. The count is
/// capped at the raster's voxel count, and each such voxel costs a 20-byte
/// record.
#[must_use]
pub fn estimate_memory(scene: &Scene, frame: &RasterFrame, solid_spheres: bool) -> MemoryEstimate {
    let [nx, ny, nz] = frame.dims().map(u64::from);
    let voxels = nx.saturating_mul(ny).saturating_mul(nz);
    let s = frame.voxel_size;
    let surface = |area: f64, perimeter: f64| {
        SURFACE_VOXELS_PER_AREA * (area / (s * s) + perimeter / s + 3.0)
    };
    let mut count = 0.0;
    for sp in &scene.spheres {
        let r = sp.shape.radius;
        count += surface(4.0 * PI * r * r, 0.0);
        if solid_spheres {
            let rv = r / s + 1.0;
            count += 4.0 / 3.0 * PI * rv * rv * rv;
        }
    }
    for c in &scene.cones {
        let slant = (c.shape.apex - c.shape.base)
            .length()
            .hypot(c.shape.apex_radius - c.shape.base_radius);
        let area = PI * (c.shape.base_radius + c.shape.apex_radius) * slant;
        count += surface(area, 2.0 * PI * (c.shape.base_radius + c.shape.apex_radius));
    }
    for p in &scene.polygons {
        let v = scene.polygon_vertices(p);
        let Some(&v0) = v.first() else { continue };
        for w in v.windows(2).skip(1) {
            let area = 0.5 * (w[0] - v0).cross(w[1] - v0).length();
            let perimeter = (w[0] - v0).length() + (w[1] - w[0]).length() + (v0 - w[1]).length();
            count += surface(area, perimeter);
        }
    }
    for t in &scene.tori {
        let (big, small) = (t.shape.major, t.shape.minor);
        count += surface(4.0 * PI * PI * big * small, 0.0);
    }
    let record_voxels = if count.is_finite() && count < voxels as f64 {
        count.ceil() as u64
    } else {
        voxels
    };
    MemoryEstimate {
        voxels,
        plane: voxels,
        lines: voxels.div_ceil(LINE_CELLS as u64),
        directory: voxels
            .div_ceil(BRICK_VOXELS)
            .saturating_mul(BRICK_ENTRY_BYTES),
        record_voxels,
        records: record_voxels.saturating_mul(RECORD_BYTES),
    }
}

/// `MemTotal` from the text of `/proc/meminfo`, in bytes.
///
/// ```
/// use rrt_host::fit::parse_meminfo;
/// let text = "MemTotal:       24554812 kB\nMemFree:         1000 kB\n";
/// assert_eq!(parse_meminfo(text), Some(24554812 * 1024));
/// assert_eq!(parse_meminfo("nonsense"), None);
/// ```
#[must_use]
pub fn parse_meminfo(text: &str) -> Option<u64> {
    let line = text.lines().find(|l| l.starts_with("MemTotal:"))?;
    let mut words = line["MemTotal:".len()..].split_whitespace();
    let value: u64 = words.next()?.parse().ok()?;
    let scale = match words.next() {
        Some("kB") => 1024,
        None => 1,
        Some(_) => return None,
    };
    value.checked_mul(scale)
}

/// The machine's memory from `/proc/meminfo`, if readable.
#[must_use]
pub fn total_memory() -> Option<u64> {
    parse_meminfo(&std::fs::read_to_string("/proc/meminfo").ok()?)
}

/// The default memory limit: half the machine's memory, or half of
/// [`FALLBACK_TOTAL_MEMORY`] where it cannot be read.
#[must_use]
pub fn default_max_memory() -> u64 {
    total_memory().unwrap_or(FALLBACK_TOTAL_MEMORY) / 2
}

#[cfg(test)]
mod tests {
    use super::*;
    use rrt_core::fixed::VOXEL;
    use rrt_core::geometry::NORMAL_ONE;

    use crate::shape::{Sphere, Triangle};
    use crate::world::Ray;

    fn scene(body: &str) -> Scene {
        let head = "v\nfrom 0 0 10\nat 0 0 0\nup 0 1 0\nangle 45\nhither 0\nresolution 8 8\n";
        Scene::parse("t.nff", format!("{head}{body}").as_bytes()).unwrap()
    }

    fn opts(n: u32) -> FitOptions {
        FitOptions {
            max_memory: u64::MAX,
            ..FitOptions::new(n)
        }
    }

    #[test]
    fn cubic_voxels_longest_axis_and_margin() {
        // Box (−2, −1, −0.5)..(2, 1, 0.5): 4 × 2 × 1.
        let s = scene("p 4\n-2 -1 -0.5\n2 -1 -0.5\n2 1 0.5\n-2 1 0.5\n");
        let f = frame(&s, &opts(104)).unwrap();
        // 100 voxels inside the margins along x: voxel = 0.04.
        assert!((f.voxel_size - 0.04).abs() < 1e-15);
        assert_eq!(f.dims(), [104, 54, 29]);
        // Centred: the geometry's centre is the raster's centre.
        let wb = f.world_bounds();
        assert!(((wb.min + wb.max) * 0.5).length() < 1e-12);
        // Two voxels of margin along the longest axis.
        assert!((wb.min.x - (-2.0 - 0.08)).abs() < 1e-12);
        assert!(wb.min.cmple(DVec3::new(-2.08, -1.08, -0.58) + 1e-12).all());
    }

    #[test]
    fn explicit_bounds_are_used_exactly() {
        let s = scene("s 0 0 0 1\n");
        let b = Bounds {
            min: DVec3::new(0.0, 0.0, 0.0),
            max: DVec3::new(8.0, 4.0, 2.0),
        };
        let f = frame(
            &s,
            &FitOptions {
                bounds: Some(b),
                ..opts(64)
            },
        )
        .unwrap();
        assert_eq!(f.dims(), [64, 32, 16]);
        assert_eq!(f.voxel_size, 0.125);
        assert_eq!(f.world_bounds(), b);
        let bad = Bounds {
            min: DVec3::ONE,
            max: DVec3::new(2.0, 1.0, 2.0),
        };
        let e = frame(
            &s,
            &FitOptions {
                bounds: Some(bad),
                ..opts(64)
            },
        )
        .unwrap_err();
        assert_eq!(
            e.to_string(),
            "bounds [1, 1, 1] to [2, 1, 2]: expected finite corners with min < max on every axis"
        );
    }

    #[test]
    fn absurd_raster_sizes() {
        let s = scene("s 0 0 0 1\n");
        assert_eq!(
            frame(&s, &opts(0)).unwrap_err().to_string(),
            "raster 0: expected 1 to 65536 voxels along the longest axis"
        );
        assert_eq!(
            frame(&s, &opts(65537)).unwrap_err().to_string(),
            "raster 65537: expected 1 to 65536 voxels along the longest axis"
        );
        assert_eq!(
            frame(&s, &opts(4)).unwrap_err().to_string(),
            "raster 4: too small for a margin of 2 voxels on each side; use at least 5"
        );
        assert_eq!(frame(&s, &opts(5)).unwrap().dims(), [5, 5, 5]);
        assert_eq!(frame(&s, &opts(65536)).unwrap().dims(), [65536; 3]);
    }

    #[test]
    fn fixed_point_round_trip() {
        let s = scene("s 0 0 0 1\n");
        let f = frame(&s, &opts(36)).unwrap();
        // 32 voxels over the diameter 2: voxel 1/16, origin −1 − 2/16.
        assert_eq!(f.voxel_size, 0.0625);
        assert_eq!(f.origin, DVec3::splat(-1.125));
        assert_eq!(f.to_fixed(DVec3::ZERO), Some([18 * VOXEL; 3]));
        assert_eq!(f.length_to_fixed(1.0, 0), Some(16 * VOXEL));
        let p = DVec3::new(0.3, -0.7, 0.123_456);
        let back = f.fixed_to_world(f.to_fixed(p).unwrap());
        assert!((back - p).abs().max_element() <= 0.5 * f.voxel_size / VOXEL as f64 + 1e-15);
        assert!((f.raster_to_world(f.world_to_raster(p)) - p).length() < 1e-15);
        assert_eq!(f.to_fixed(DVec3::new(1e30, 0.0, 0.0)), None);
        assert_eq!(f.to_fixed(DVec3::NAN), None);
    }

    #[test]
    fn objects_lights_and_normals() {
        let s = scene(
            "l 100 0 0\nl 0 0 2 0.5 0.5 1\nf 1 1 1 1 0 0 0 1\ns 0 0 0 1\nc 0 0 0 0.5 0 0 0.5 0.25\n\
             p 4\n-1 -1 0\n1 -1 0\n1 1 0\n-1 1 0\npp 3\n0 0 0 0 0 3\n1 0 0 0 4 3\n0 1 0 0 0 1\n",
        );
        let fitted = fit(&s, &opts(36)).unwrap();
        let f = fitted.frame;
        assert_eq!(fitted.objects.len(), 1 + 1 + 2 + 1);
        let table::Shape::Sphere(sp) = fitted.objects[0].entry else {
            panic!()
        };
        assert_eq!(sp.centre, f.to_fixed(DVec3::ZERO).unwrap());
        assert_eq!(sp.radius, 16 * VOXEL);
        let table::Shape::Cone(c) = fitted.objects[1].entry else {
            panic!()
        };
        assert_eq!((c.base_radius, c.apex_radius), (8 * VOXEL, 4 * VOXEL));
        // The quad's fan: (0, 1, 2) and (0, 2, 3), winding kept.
        let table::Shape::Triangle(t1) = fitted.objects[3].entry else {
            panic!()
        };
        let expect = [0, 2, 3].map(|k| f.to_fixed(s.vertices[k]).unwrap());
        assert_eq!(t1.vertices, expect);
        assert_eq!(t1.normals, None);
        assert_eq!(
            fitted.objects[3].shape,
            Shape::Triangle(Triangle {
                vertices: [0, 2, 3].map(|k| s.vertices[k]),
                normals: None,
            })
        );
        assert_eq!(
            (fitted.objects[3].kind, fitted.objects[3].loc.line),
            ("polygon", 13)
        );
        // Patch normals normalised and scaled by 2^30.
        let table::Shape::Triangle(pt) = fitted.objects[4].entry else {
            panic!()
        };
        let n = pt.normals.unwrap();
        assert_eq!(n[0], [0, 0, NORMAL_ONE]);
        assert_eq!(
            n[1],
            [
                0,
                (0.8 * f64::from(NORMAL_ONE)).round() as i32,
                (0.6 * f64::from(NORMAL_ONE)).round() as i32
            ]
        );
        // Lights outside the raster are fine.
        assert_eq!(fitted.lights.len(), 2);
        assert_eq!(
            fitted.lights[0].position,
            f.to_fixed(DVec3::new(100.0, 0.0, 0.0)).unwrap()
        );
        assert!(fitted.lights[0].position[0] > i64::from(f.dims()[0]) * VOXEL);
        assert_eq!(fitted.lights[1].colour, DVec3::new(0.5, 0.5, 1.0));
        assert_eq!(fitted.dropped, Dropped::default());
    }

    #[test]
    fn far_light_is_refused_with_its_location() {
        let s = scene("l 1e30 0 0\ns 0 0 0 1\n");
        assert_eq!(
            fit(&s, &opts(36)).unwrap_err().to_string(),
            "t.nff:8:1: light lies more than 2^31 voxels from the raster"
        );
    }

    #[test]
    fn degenerate_and_outside_objects_are_dropped() {
        // A polygon whose middle fan triangle collapses (collinear 0, 1, 2),
        // and a sphere outside explicit bounds.
        let s = scene("p 4\n0 0 0\n1 0 0\n2 0 0\n1 1 0\ns 50 50 50 1\n");
        let b = Bounds {
            min: DVec3::splat(-1.0),
            max: DVec3::splat(3.0),
        };
        let fitted = fit(
            &s,
            &FitOptions {
                bounds: Some(b),
                ..opts(32)
            },
        )
        .unwrap();
        assert_eq!(
            fitted.dropped,
            Dropped {
                degenerate: 1,
                outside: 1
            }
        );
        assert_eq!(fitted.objects.len(), 1);
    }

    #[test]
    fn memory_estimate_and_refusal() {
        // A unit square of 100 × 100 voxels in a 104 × 104 × 5 raster.
        let s = scene("p 4\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n");
        let f = frame(&s, &opts(104)).unwrap();
        assert_eq!(f.dims(), [104, 104, 4]);
        let m = estimate_memory(&s, &f, true);
        assert_eq!(m.voxels, 104 * 104 * 4);
        assert_eq!(m.plane, m.voxels);
        assert_eq!(m.lines, m.voxels.div_ceil(64));
        assert_eq!(m.directory, 4 * m.voxels.div_ceil(512));
        // Two triangles of area 5000 and perimeter 100 + 100 + 141.4.
        let per_tri = 1.8 * (5000.0 + 200.0 + 100.0 * 2f64.sqrt() + 3.0);
        assert_eq!(m.record_voxels, (2.0 * per_tri).ceil() as u64);
        assert_eq!(m.records, 20 * m.record_voxels);
        assert!(
            m.record_voxels >= 100 * 100,
            "at least one layer of the square"
        );

        // 43264 + 676 + 340 + 19240·20 = 429080 bytes = 419.0 KiB.
        assert_eq!(m.total(), 429_080);
        let e = fit(
            &s,
            &FitOptions {
                max_memory: 256 << 10,
                ..opts(104)
            },
        )
        .unwrap_err();
        assert_eq!(
            e.to_string(),
            "raster 104×104×4: needs about 419.0 KiB (plane 42.2 KiB, line level 676 B, brick \
             directory 340 B, records for up to 19240 voxels 375.8 KiB), more than the limit of 256.0 KiB; use a \
             smaller raster or a larger memory limit"
        );
        assert!(
            fit(
                &s,
                &FitOptions {
                    max_memory: m.total() - 1,
                    ..opts(104)
                }
            )
            .is_err()
        );
        assert!(
            fit(
                &s,
                &FitOptions {
                    max_memory: m.total(),
                    ..opts(104)
                }
            )
            .is_ok()
        );
        // Records never exceed one per voxel: 40 small spheres in 5³.
        let many: String = (0..40)
            .map(|i| format!("s {} 0 0 0.1\n", f64::from(i) * 0.01))
            .collect();
        let many = scene(&many);
        let f = frame(&many, &opts(5)).unwrap();
        assert_eq!(f.dims(), [5, 5, 5]);
        assert_eq!(estimate_memory(&many, &f, true).record_voxels, 125);
    }

    #[test]
    fn byte_units() {
        assert_eq!(Bytes(0).to_string(), "0 B");
        assert_eq!(Bytes(1023).to_string(), "1023 B");
        assert_eq!(Bytes(1536).to_string(), "1.5 KiB");
        assert_eq!(Bytes(3 << 30).to_string(), "3.0 GiB");
        // Past PiB, the count stays in PiB.
        assert_eq!(Bytes(u64::MAX).to_string(), "16384.0 PiB");
    }

    #[test]
    fn machine_memory() {
        assert_eq!(
            parse_meminfo("MemFree: 5 kB\nMemTotal: 10 kB\n"),
            Some(10240)
        );
        assert_eq!(parse_meminfo("MemTotal: 10 MB\n"), None);
        assert_eq!(parse_meminfo("MemTotal: lots kB\n"), None);
        assert_eq!(parse_meminfo(&format!("MemTotal: {} kB\n", u64::MAX)), None);
        let half = default_max_memory();
        match total_memory() {
            Some(t) => assert_eq!(half, t / 2),
            None => assert_eq!(half, FALLBACK_TOTAL_MEMORY / 2),
        }
        assert!(half > 0);
    }

    #[test]
    fn objects_keep_the_exact_world_geometry() {
        let s = scene("s 0 0 0 1\npp 3\n0 0 2 0 0 1\n1 0 2 1 0 1\n0 1 2 0 1 1\n");
        let fitted = fit(&s, &opts(36)).unwrap();
        let down = Ray::new(DVec3::new(0.2, 0.2, 5.0), -DVec3::Z);
        let h = fitted.objects[1]
            .shape
            .intersect(&down, 0.0, f64::INFINITY)
            .unwrap();
        assert!((h.t - 3.0).abs() < 1e-12);
        let expect =
            (DVec3::Z * 0.6 + DVec3::new(1.0, 0.0, 1.0) * 0.2 + DVec3::new(0.0, 1.0, 1.0) * 0.2)
                .normalize();
        assert!((h.normal - expect).length() < 1e-12);
        let h = fitted.objects[0]
            .shape
            .intersect(&down, 0.0, f64::INFINITY)
            .unwrap();
        assert!((h.t - (5.0 - (1.0f64 - 0.08).sqrt())).abs() < 1e-12);
        // The same ray in raster units meets the sphere at the same t.
        let r = fitted.frame.ray_to_raster(&down);
        let ball = Sphere {
            centre: fitted.frame.world_to_raster(DVec3::ZERO),
            radius: 1.0 / fitted.frame.voxel_size,
        };
        let h2 = ball.intersect(&r, 0.0, f64::INFINITY).unwrap();
        assert!((h2.t - h.t).abs() < 1e-9);
    }
}
