//! The integrator's scene: voxelized into caller-provided buffers with
//! every voxelizer and CSG, lit by the light pass, finished for skipping
//! walks, and traced into a 64×64 image with integer shading from the
//! records alone.
//!
//! This is the whole embedded pipeline, in the order an integrator calls
//! it: count pass → [`Sizing::records`] (the record storage needed) → fill
//! pass → [`Filler::finish`] → [`distance_field`], [`write_rank_hints`],
//! [`line_distances`] (the plane finished) → [`illuminate`] → per pixel one
//! [`DiscreteRay`] to its first hit and one record lookup.
//!
//! The scene is built as either of the host's two rasters ([`Variant`]):
//! the paper's (one object per voxel, as thick as the rays need, the
//! paper's light bits), which the example image is traced from, or the
//! exact one (every object 26-separating, object lists, the shadow
//! classification for records of exact objects), which the digests cover
//! too.
//!
//! [`Sizing::records`]: rrt_core::store::Sizing::records
//! [`Filler::finish`]: rrt_core::store::Filler::finish

use rrt_core::csg::{self, CsgNode, CsgTree, IgnoreLeaf, LeafFill, Solid};
use rrt_core::discrete_ray::{Connectivity, DiscreteRay};
use rrt_core::error::{RasterError, RayError};
use rrt_core::fixed::VOXEL;
use rrt_core::geometry::{BezierPatch, Cone, Cuboid, NORMAL_ONE, Point, Sphere, Torus, Triangle};
use rrt_core::light::{ExactRecords, LightError, LightParams, LightReport, illuminate};
use rrt_core::object_table::{
    Light, Lights, Material, Materials, Object, ObjectTable, SCALAR_ONE, Shape, VolumeRef,
};
use rrt_core::proximity::{coarse_cells, distance_field, line_distances};
use rrt_core::raster::{Extent, Raster, RasterMut};
use rrt_core::store::{
    BuildError, Counter, FillReport, Limits, ObjectAttrs, RecordStore, StoreError, directory_len,
    write_rank_hints,
};
use rrt_core::voxel::{VoxelRecord, dot_unit, normalize};
use rrt_core::voxelize::volume::{self, Block};
use rrt_core::voxelize::{Separation, VoxelSink, cone, cuboid, patch, sphere, torus, triangle};

/// The scene raster's dimensions.
pub const DIMS: [u32; 3] = [48, 48, 40];
/// Plane cells.
pub const PLANE_LEN: usize = (DIMS[0] * DIMS[1] * DIMS[2]) as usize;
/// Line-level cells.
pub const LINES_LEN: usize = rrt_core::raster::line_count(PLANE_LEN);
/// Coarse-level cells (scratch for [`line_distances`]).
pub const BRICKS_LEN: usize = coarse_cells(DIMS);
/// Directory entries: one per 8×8×8 brick plus one.
pub const DIR_LEN: usize = ((DIMS[0] / 8) * (DIMS[1] / 8) * (DIMS[2] / 8) + 1) as usize;
/// Record storage the integrator provides (the count pass says how much of
/// it the scene needs: 9,192 records for the paper's raster, 10,788 for the
/// exact one).
pub const MAX_RECORDS: usize = 12_288;
/// Object-list storage for the exact raster (`u32` entries; the fill pass
/// uses it as working space, [`Sizing::list_entries`] bounds what it
/// needs, the finished lists are the front of it).
///
/// [`Sizing::list_entries`]: rrt_core::store::Sizing::list_entries
pub const MAX_LIST_ENTRIES: usize = 2_048;
/// Object-table capacity.
pub const MAX_OBJECTS: usize = 16;
/// Image width and height.
pub const SIZE: usize = 64;
/// Bytes of the image: RGB, 8 bits per channel.
pub const IMAGE_LEN: usize = SIZE * SIZE * 3;
/// The PPM header of the image.
pub const PPM_HEADER: &[u8] = b"P6\n64 64\n255\n";

/// A filler value for the patch storage.
pub const PATCH_INIT: BezierPatch = BezierPatch {
    control: [[[0; 3]; 4]; 4],
};

/// A filler value for the record storage: the zero record.
pub const RECORD_INIT: VoxelRecord = bytemuck::zeroed();

/// The ray connectivity the scene is built and traced for.
pub const MODE: Connectivity = Connectivity::Adaptive;

/// The caller's buffers (static arrays on the target).
#[derive(Debug)]
pub struct Storage<'a> {
    /// One cell per voxel.
    pub plane: &'a mut [u8],
    /// The line level.
    pub lines: &'a mut [u8],
    /// The brick directory.
    pub dir: &'a mut [u32],
    /// Record storage (at least the scene's count).
    pub records: &'a mut [VoxelRecord],
    /// Object-list storage (the exact raster only).
    pub lists: &'a mut [u32],
    /// Object-table storage.
    pub objects: &'a mut [Object],
    /// Bézier-patch storage.
    pub patches: &'a mut [BezierPatch],
}

/// Why the scene could not be built or traced.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SceneError {
    /// A buffer of the wrong size.
    Raster(RasterError),
    /// The scene builder refused.
    Build(BuildError),
    /// The store did not validate.
    Store(StoreError),
    /// The light pass failed.
    Light(LightError),
    /// A ray could not be set up.
    Ray(RayError),
    /// A table was too small.
    Capacity,
}

/// `From` each error the scene's calls return, as its variant.
macro_rules! from_errors {
    ($($variant:ident($error:ty)),+) => {
        $(impl From<$error> for SceneError {
            fn from(e: $error) -> Self {
                Self::$variant(e)
            }
        })+
    };
}
from_errors!(
    Raster(RasterError),
    Build(BuildError),
    Store(StoreError),
    Light(LightError),
    Ray(RayError)
);

/// Which of the host's two rasters the scene is built as.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Variant {
    /// The paper's raster: every object as thick as the rays need
    /// ([`Separation::for_rays`] of [`MODE`]), one object per voxel, the
    /// paper's light bits from one discrete shadow ray per record and light.
    Paper,
    /// The exact raster (the host's default, for rendering with
    /// intersection verification): every object conservatively
    /// ([`Separation::TwentySix`]), a voxel several objects pass through
    /// lists all of them, and records of objects with exact geometry get the
    /// shadow classification ([`ExactRecords::Classify`]: a tube walk,
    /// [`DiscreteRay::walk_dilated`], instead of the paper's shadow ray);
    /// the volume blob and the CSG ball (no exact geometry) keep the
    /// paper's bits.
    Exact,
}

impl Variant {
    /// The separation every object is voxelized with.
    #[must_use]
    pub const fn separation(self) -> Separation {
        match self {
            Self::Paper => Separation::for_rays(MODE),
            Self::Exact => Separation::TwentySix,
        }
    }

    /// The light pass's parameters.
    #[must_use]
    pub fn light(self) -> LightParams {
        match self {
            Self::Paper => LightParams::default(),
            Self::Exact => LightParams {
                exact_records: ExactRecords::Classify,
                ..LightParams::default()
            },
        }
    }
}

/// What building the scene did.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SceneReport {
    /// Records of the scene (the first entries of the record storage).
    pub records: usize,
    /// Entries of the finished object lists (the first entries of the list
    /// storage; 0 on the paper's raster).
    pub lists: usize,
    /// The count pass's bound on the list storage the fill pass may need
    /// ([`Sizing::list_entries`]; a loose bound, and unused on the paper's
    /// raster).
    ///
    /// [`Sizing::list_entries`]: rrt_core::store::Sizing::list_entries
    pub list_bound: usize,
    /// The fill pass's counts.
    pub fill: FillReport,
    /// The light pass's counts.
    pub light: LightReport,
}

/// The scene's extent.
///
/// # Errors
/// Never for [`DIMS`].
pub fn extent() -> Result<Extent, RasterError> {
    Extent::new(DIMS[0], DIMS[1], DIMS[2])
}

/// `v` voxels in fixed units (`v` in eighths of a voxel).
const fn at(eighths: i64) -> i64 {
    eighths * (VOXEL / 8)
}

const fn p(x: i64, y: i64, z: i64) -> Point {
    [at(x), at(y), at(z)]
}

/// The materials, in object order: floor, ball, ring, cone, canopy,
/// pyramid, blob, cut ball.
const COLORS: [[u32; 3]; 8] = [
    [52_000, 52_000, 48_000],
    [60_000, 9_000, 7_000],
    [58_000, 42_000, 8_000],
    [10_000, 50_000, 14_000],
    [12_000, 22_000, 58_000],
    [62_000, 30_000, 4_000],
    [40_000, 12_000, 52_000],
    [8_000, 52_000, 56_000],
];

const FLOOR: Cuboid = Cuboid {
    min: p(0, 0, 0),
    max: p(384, 384, 20),
};
const BALL: Sphere = Sphere {
    centre: p(120, 250, 80),
    radius: at(60),
};
const RING: Torus = Torus {
    centre: p(280, 250, 60),
    axis: [0, NORMAL_ONE / 2, 929_887_697],
    major: at(44),
    minor: at(16),
};
const CONE: Cone = Cone {
    base: p(300, 100, 20),
    base_radius: at(40),
    apex: p(300, 100, 150),
    apex_radius: 0,
};
const PYRAMID: [Point; 4] = [
    p(40, 40, 20),
    p(160, 50, 20),
    p(90, 150, 20),
    p(95, 85, 130),
];
const PYRAMID_FACES: [[usize; 3]; 4] = [[0, 2, 1], [0, 1, 3], [1, 2, 3], [2, 0, 3]];
const CUT_BALL: Sphere = Sphere {
    centre: p(190, 300, 200),
    radius: at(44),
};
const CUT: Cuboid = Cuboid {
    min: p(190, 250, 150),
    max: p(260, 360, 260),
};
/// The blob's samples: 12³, placed at voxel (18, 14, 2).
const BLOB_DIMS: [u32; 3] = [12, 12, 12];
const BLOB_OFFSET: [i64; 3] = [18, 14, 2];

fn canopy() -> BezierPatch {
    BezierPatch {
        control: core::array::from_fn(|i| {
            core::array::from_fn(|j| {
                let (i, j) = (i as i64, j as i64);
                let lift = if (1..3).contains(&i) { 90 } else { 0 };
                p(24 + 112 * i, 330 + 16 * j, 160 + lift + 30 * j)
            })
        }),
    }
}

fn blob() -> [u16; 1728] {
    let mut s = [0u16; 1728];
    for (i, v) in s.iter_mut().enumerate() {
        let q = [(i % 12) as i64, ((i / 12) % 12) as i64, (i / 144) as i64];
        // Two overlapping spheres of gray levels, in integers.
        let d1: i64 = (0..3).map(|k| (2 * q[k] - [9, 11, 9][k]).pow(2)).sum();
        let d2: i64 = (0..3).map(|k| (2 * q[k] - [15, 13, 13][k]).pow(2)).sum();
        *v = (3000 - 40 * d1.min(d2)).clamp(0, 3000) as u16;
    }
    s
}

/// The checkerboard texture of the floor (two-voxel squares).
fn checker(centre: [i64; 3], _normal: [i32; 3], base: [u8; 3]) -> [u8; 3] {
    let sq = |c: i64| c.div_euclid(2 * VOXEL);
    if (sq(centre[0]) + sq(centre[1])) % 2 == 0 {
        base
    } else {
        base.map(|c| c / 3)
    }
}

/// The number of objects; ids are assigned in this order: floor, ball,
/// ring, cone, canopy, four pyramid faces, blob, cut ball.
const OBJECTS: u32 = 11;

/// Offers object `id` (all but the cut ball), voxelized with `sep`, to
/// `sink`.
fn offer(id: u32, e: Extent, sep: Separation, sink: &mut dyn VoxelSink) -> Result<(), SceneError> {
    let r = match id {
        0 => cuboid::solid(&FLOOR, sep, e, sink),
        1 => sphere::surface(&BALL, sep, e, sink),
        2 => torus::surface(&RING, sep, e, sink),
        3 => cone::capped(&CONE, sep, e, sink),
        4 => patch::surface(&canopy(), sep, e, sink),
        5..=8 => {
            let f = PYRAMID_FACES[(id - 5) as usize];
            let t = Triangle {
                vertices: f.map(|k| PYRAMID[k]),
                normals: None,
            };
            triangle::triangle(&t, sep, e, sink)
        }
        _ => {
            let samples = blob();
            let b = Block {
                samples: &samples,
                dims: BLOB_DIMS,
                offset: BLOB_OFFSET,
            };
            volume::boundary(&b, 1500u16, sep, e, sink)
        }
    };
    // A voxelizer refusing one of these constant shapes is a bug: report it
    // as a capacity-free build error through the count.
    r.map(|_| ()).map_err(|_| SceneError::Capacity)
}

fn material(id: u32) -> u16 {
    match id {
        0..=4 => id as u16,
        5..=8 => 5,
        9 => 6,
        _ => 7,
    }
}

/// The object table entries, in id order.
fn push_objects(t: &mut ObjectTable<'_>) -> Result<(), SceneError> {
    for (shape, material) in [
        (Shape::Cuboid(FLOOR), 0),
        (Shape::Sphere(BALL), 1),
        (Shape::Torus(RING), 2),
        (Shape::Cone(CONE), 3),
    ] {
        push(t, shape, material)?;
    }
    t.push_patch(canopy(), 4)
        .map_err(|_| SceneError::Capacity)?;
    for f in PYRAMID_FACES {
        let tri = Triangle {
            vertices: f.map(|k| PYRAMID[k]),
            normals: None,
        };
        push(t, Shape::Triangle(tri), 5)?;
    }
    let lo = BLOB_OFFSET.map(|o| o * VOXEL);
    let bounds = Cuboid {
        min: lo,
        max: core::array::from_fn(|k| lo[k] + i64::from(BLOB_DIMS[k]) * VOXEL),
    };
    push(t, Shape::Volume(VolumeRef { volume: 0, bounds }), 6)?;
    push(t, Shape::Voxels, 7)
}

/// One object table entry.
fn push(t: &mut ObjectTable<'_>, shape: Shape, material: u16) -> Result<(), SceneError> {
    t.push(Object { shape, material })
        .map(|_| ())
        .map_err(|_| SceneError::Capacity)
}

fn materials() -> Result<Materials<8>, SceneError> {
    let mut m = Materials::new();
    for color in COLORS {
        m.push(Material {
            color,
            kd: SCALAR_ONE * 4 / 5,
            ks: SCALAR_ONE / 5,
            shine: 20 * SCALAR_ONE,
            transmission: 0,
            ior: SCALAR_ONE,
        })
        .map_err(|_| SceneError::Capacity)?;
    }
    Ok(m)
}

fn lights() -> Result<Lights, SceneError> {
    // SPD intensity for two lights: sqrt(2) / 4.
    let i = 23_170;
    let mut l = Lights::new(i);
    for position in [p(-80, -200, 560), p(400, 120, 300)] {
        l.push(Light {
            position,
            color: [SCALAR_ONE; 3],
            intensity: i,
        })
        .map_err(|_| SceneError::Capacity)?;
    }
    Ok(l)
}

/// The CSG object (a ball with a box cut out), offered to `f`.
fn with_cut_ball<R>(f: impl FnOnce(&CsgTree<'_>) -> R) -> Result<R, SceneError> {
    let leaves: [&dyn Solid; 2] = [&CUT_BALL, &CUT];
    let nodes = [
        CsgNode::Leaf(0),
        CsgNode::Leaf(1),
        CsgNode::Difference(0, 1),
    ];
    let tree = CsgTree::new(&nodes, &leaves).map_err(|_| SceneError::Capacity)?;
    Ok(f(&tree))
}

/// Builds the scene into `st` as the paper's raster: voxelized, finished
/// (distance field, rank hints, line level), lit.
///
/// # Errors
/// A [`SceneError`] when a buffer is too small or a pass refuses.
pub fn build(st: &mut Storage<'_>) -> Result<SceneReport, SceneError> {
    build_with(st, Variant::Paper, &mut |_, pass| pass())
}

/// A hook around each stage of [`build_with`]: called with the stage's
/// name and the stage, which it must run exactly once.
pub type Probe<'p> = dyn FnMut(&'static str, &mut dyn FnMut()) + 'p;

/// [`build`] as `variant`, each stage run through `probe` (the stack
/// measurement wraps them; [`build`] just runs them).
///
/// # Errors
/// As [`build`].
pub fn build_with(
    st: &mut Storage<'_>,
    variant: Variant,
    probe: &mut Probe<'_>,
) -> Result<SceneReport, SceneError> {
    let e = extent()?;
    let sep = variant.separation();
    if directory_len(e) != Some(st.dir.len()) {
        return Err(SceneError::Capacity);
    }
    // Count pass.
    let mut counter = Counter::new(RasterMut::new(e, st.plane)?, st.dir)?;
    let mut done: Result<(), SceneError> = Ok(());
    probe("Counter: count pass, every object", &mut || {
        done = (0..OBJECTS - 1)
            .try_for_each(|id| offer(id, e, sep, &mut counter))
            .and_then(|()| {
                with_cut_ball(|t| csg::voxelize(t, e, &mut IgnoreLeaf(&mut counter))).map(|_| ())
            });
    });
    done?;
    let sizing = counter.finish()?;
    let records = sizing.records();
    let list_bound = sizing.list_entries();
    // Fill pass.
    let mats = materials()?;
    let limits = Limits {
        objects: OBJECTS,
        materials: mats.index_limit(),
    };
    let mut filler = match variant {
        Variant::Paper => sizing.fill(st.records, limits)?,
        Variant::Exact => sizing.fill_with_lists(st.records, st.lists, limits)?,
    };
    let attrs = |id: u32| {
        let m = material(id);
        ObjectAttrs {
            object: id,
            material: m,
            color: mats.get(m).map(Material::color_u8).unwrap_or_default(),
        }
    };
    let mut done: Result<(), SceneError> = Ok(());
    probe("Filler: fill pass, every object", &mut || {
        done = (|| {
            for id in 0..OBJECTS - 1 {
                filler.begin_object(attrs(id))?;
                if id == 0 {
                    let tex = checker;
                    offer(id, e, sep, &mut filler.textured(&tex))?;
                } else {
                    offer(id, e, sep, &mut filler)?;
                }
            }
            let leaf_attrs = [attrs(OBJECTS - 1); 2];
            let mut leaf_fill = LeafFill::new(&mut filler, &leaf_attrs)?;
            with_cut_ball(|t| csg::voxelize(t, e, &mut leaf_fill))?;
            Ok(())
        })();
    });
    done?;
    let mut filler = Some(filler);
    let mut finished = None;
    probe("Filler::finish", &mut || {
        finished = filler.take().map(|f| f.finish())
    });
    let built = finished.ok_or(SceneError::Capacity)??;
    let fill = built.report();
    let lists = built.lists().len();
    // Finish the plane for skipping walks (the light pass changes no cell
    // and no record's place; its walks read the distance field, which the
    // shadow classification needs).
    let (mut raster, mut store) = built.into_parts();
    probe("distance_field + write_rank_hints", &mut || {
        distance_field(&mut raster);
        write_rank_hints(&mut raster, &store.as_store());
    });
    let mut bricks = [0u8; BRICKS_LEN];
    line_distances(&raster.as_raster(), &mut bricks, st.lines)?;
    // Light pass.
    let raster = raster.as_raster().with_lines(st.lines)?;
    let mut table = ObjectTable::new(st.objects, st.patches);
    push_objects(&mut table)?;
    let lights = lights()?;
    let params = variant.light();
    let mut light = Err(SceneError::Capacity);
    probe(
        match variant {
            Variant::Paper => "illuminate",
            Variant::Exact => "illuminate: shadow classification",
        },
        &mut || {
            light = illuminate(&raster, &mut store, &table, &mats, &lights, &params)
                .map_err(SceneError::from);
        },
    );
    let light = light?;
    Ok(SceneReport {
        records,
        lists,
        list_bound,
        fill,
        light,
    })
}

/// Runs each of the scene's voxelizers, and its CSG object, once through
/// `probe`, into a sink that only counts (what the stack measurement
/// wraps: the voxelizer's own depth, through a `dyn VoxelSink`).
pub fn voxelizer_probe(probe: &mut Probe<'_>) {
    struct Count(u64);
    impl VoxelSink for Count {
        fn offer(&mut self, _: [u32; 3], _: rrt_core::voxelize::Surfel) {
            self.0 += 1;
        }
    }
    let Ok(e) = extent() else { return };
    let names = [
        (0, "cuboid::solid"),
        (1, "sphere::surface"),
        (2, "torus::surface"),
        (3, "cone::capped"),
        (4, "patch::surface"),
        (5, "triangle::triangle"),
        (9, "volume::boundary"),
    ];
    for (id, name) in names {
        let mut c = Count(0);
        probe(name, &mut || {
            let _ = offer(id, e, Variant::Paper.separation(), &mut c);
        });
    }
    let mut c = Count(0);
    probe("csg::voxelize", &mut || {
        let _ = with_cut_ball(|t| csg::voxelize(t, e, &mut IgnoreLeaf(&mut c)));
    });
}

/// The camera: eye and the direction of pixel `(i, j)` (row `j` from the
/// top), in fixed units.
#[must_use]
pub fn camera(i: usize, j: usize) -> ([i64; 3], [i32; 3]) {
    let eye = p(196, -260, 250);
    // Forward (0, 60, -24)/|.|, right +x, up (0, 24, 60)/|.|, all
    // 2^30-scaled, then 2^20-scaled below.
    let f = normalize([0, 60, -24]).unwrap_or([0, NORMAL_ONE, 0]);
    let u = normalize([0, 24, 60]).unwrap_or([0, 0, NORMAL_ONE]);
    let r = [NORMAL_ONE, 0, 0];
    // Half-width of the view: 0.45 of the focal length (about 48°).
    let x = 2 * i as i64 - (SIZE as i64 - 1);
    let y = (SIZE as i64 - 1) - 2 * j as i64;
    let dir = core::array::from_fn(|k| {
        let s = i64::from(f[k]) * 2 * SIZE as i64 * 100
            + (i64::from(r[k]) * x + i64::from(u[k]) * y) * 90;
        (s >> 20) as i32
    });
    (eye, dir)
}

/// Linear → display: gamma 2 by an integer square root.
fn encode(lin: u32) -> u8 {
    (lin.min(255) * 255).isqrt() as u8
}

/// The colour of a pixel whose ray hit `rec` along `dir`: the record's
/// precomputed illumination plus a quarter of its colour scaled by how
/// squarely the surface faces the eye (either side of an open surface).
#[must_use]
pub fn shade(rec: &VoxelRecord, dir: [i32; 3]) -> [u8; 3] {
    let view = normalize(dir.map(|c| -i64::from(c))).unwrap_or([0, 0, NORMAL_ONE]);
    let facing = dot_unit(rec.normal_vector(), view).unsigned_abs();
    core::array::from_fn(|k| {
        let head = (u64::from(rec.color[k]) * u64::from(facing)) >> 32;
        encode(u32::from(rec.illum[k]) + head as u32)
    })
}

/// The background of row `j`: a sky darkening upwards.
#[must_use]
pub fn sky(j: usize) -> [u8; 3] {
    let t = j as u32;
    [encode(20 + t), encode(30 + t), encode(70 + t)]
}

/// What tracing the image did.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RenderReport {
    /// Pixels whose ray hit a voxel.
    pub hits: u32,
    /// Voxels visited by all pixel rays.
    pub visits: u64,
    /// Hits whose voxel had no record (a plane that does not match the
    /// store; 0 for a built scene).
    pub missing: u32,
}

/// Traces the 64×64 image of the scene built in `st` (with `records`
/// records) into `image` (RGB rows, top first).
///
/// # Errors
/// A buffer of the wrong size, a store that does not validate.
pub fn render(
    plane: &[u8],
    lines: &[u8],
    dir: &[u32],
    records: &[VoxelRecord],
    image: &mut [u8],
) -> Result<RenderReport, SceneError> {
    let e = extent()?;
    let raster = Raster::new(e, plane)?.with_lines(lines)?;
    let store = RecordStore::new(e, dir, records)?;
    if image.len() != IMAGE_LEN {
        return Err(SceneError::Capacity);
    }
    let mut report = RenderReport::default();
    for (n, px) in image.chunks_exact_mut(3).enumerate() {
        let (i, j) = (n % SIZE, n / SIZE);
        let (eye, d) = camera(i, j);
        let mut rgb = sky(j);
        if let Some(mut ray) = DiscreteRay::new(e, eye, d)? {
            if let Some(h) = ray.first_hit_skipping(&raster, MODE)? {
                report.hits += 1;
                let c = plane.get(h.index).copied().unwrap_or(0);
                match store.get_hinted(h.voxel, c) {
                    Some(rec) => rgb = shade(rec, d),
                    None => report.missing += 1,
                }
            }
            report.visits += u64::from(ray.steps());
        }
        px.copy_from_slice(&rgb);
    }
    Ok(report)
}
