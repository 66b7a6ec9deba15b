//! Sampled and computed volumes: the NRRD and raw readers on committed
//! fixtures (written by `data/volumes/make_fixtures.py`, independently of
//! rrt) and on the real volumes of `../shared/data/volumes` (skipped when
//! absent), resampling, placement, raster blocks, classification, and
//! every kind of bad input.

use std::path::{Path, PathBuf};

use glam::DVec3;
use rrt_core::raster::Extent;
use rrt_core::store::Texture;
use rrt_core::voxelize::{NORMAL_ONE, Separation, Surfel, VoxelSink};
use rrt_host::assets::volume::classify::gray_normal;
use rrt_host::assets::volume::computed::{self, Metaball, Metaballs, ScreenedSources};
use rrt_host::assets::volume::raw::{self, RawSpec};
use rrt_host::assets::volume::resample::{Quantizer, resample_cubic};
use rrt_host::assets::volume::{
    Classifier, ColorRamp, Endian, Grid, Limits, Placement, Ramp, SampleType, Samples, Volume,
    VolumeError, nrrd,
};
use rrt_host::frame::RasterFrame;
use rrt_host::voxelize::volume::VolumeColors;

fn fixture(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("data/volumes")
        .join(name)
}

fn tmp(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("volumes");
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

/// f(i, j, k) of the fixtures.
fn f(i: u32, j: u32, k: u32) -> f64 {
    f64::from(i + 5 * j + 20 * k)
}

#[track_caller]
fn assert_fixture(v: &Volume, ty: SampleType, map: impl Fn(f64) -> f64) {
    assert_eq!(v.dims(), [5, 4, 3]);
    assert_eq!(v.sample_type(), ty);
    for k in 0..3 {
        for j in 0..4 {
            for i in 0..5 {
                let got = v.value(i, j, k).unwrap();
                assert_eq!(got, map(f(i, j, k)), "sample ({i}, {j}, {k})");
            }
        }
    }
}

fn read(name: &str) -> Volume {
    nrrd::read(fixture(name), &Limits::default()).unwrap_or_else(|e| panic!("{name}: {e}"))
}

#[test]
fn every_sample_type_and_encoding() {
    let raw = read("u8_raw.nrrd");
    assert_fixture(&raw, SampleType::U8, |x| x);
    assert_eq!(raw.spacing(), [0.5, 0.5, 1.5]);
    assert_eq!(raw.origin(), DVec3::new(1.0, 2.0, 3.0));
    assert!(raw.geometry_known());
    // Gzip and raw: the same volume.
    let gz = read("u8_gzip.nrrd");
    assert_eq!(gz, raw);
    let be = read("i16_be.nrrd");
    assert_fixture(&be, SampleType::I16, |x| x - 30.0);
    assert_eq!(be.spacing(), [1.0, 1.0, 2.0]);
    assert_eq!(be.origin(), DVec3::ZERO);
    let u16 = read("u16_gzip.nrrd");
    assert_fixture(&u16, SampleType::U16, |x| 1000.0 * x);
    assert!(!u16.geometry_known());
    assert_eq!(u16.spacing(), [1.0; 3]);
    // Detached header with a byte skip.
    let f32 = read("f32.nhdr");
    assert_fixture(&f32, SampleType::F32, |x| 0.25 * x - 3.0);
    assert_eq!(f32.spacing(), [0.25, 0.5, 0.75]);
    let header = nrrd::read_header(fixture("f32.nhdr"), &Limits::default()).unwrap();
    assert_eq!(header.data_file, Some(fixture("f32.raw")));
    assert_eq!(header.byte_skip, 16);
    // ASCII with a skipped line; raw data at the end of the file.
    assert_fixture(&read("u8_ascii.nrrd"), SampleType::U8, |x| x);
    assert_fixture(&read("u8_tail.nrrd"), SampleType::U8, |x| x);
}

#[test]
fn writer_round_trip() {
    for name in ["u8_raw.nrrd", "i16_be.nrrd", "u16_gzip.nrrd", "f32.nhdr"] {
        let v = read(name);
        for gzip in [false, true] {
            let p = tmp(&format!("rt-{gzip}-{name}.nrrd"));
            nrrd::write(&p, &v, gzip).unwrap();
            let back = nrrd::read(&p, &Limits::default()).unwrap();
            assert_eq!(back.samples(), v.samples(), "{name}");
            assert_eq!(back.grid(), v.grid(), "{name}");
        }
    }
}

#[test]
fn headerless_raw() {
    let p = tmp("engine-like.raw");
    let bytes: Vec<u8> = (0..60u32)
        .flat_map(|x| u16::try_from(x * 7).unwrap().to_be_bytes())
        .collect();
    std::fs::write(&p, &bytes).unwrap();
    let spec = RawSpec {
        dims: [5, 4, 3],
        sample_type: SampleType::U16,
        endian: Endian::Big,
        grid: Grid::axis_aligned([0.5, 0.5, 2.0], DVec3::new(-1.0, 0.0, 0.0)),
        skip: 0,
    };
    let v = raw::read(&p, &spec, &Limits::default()).unwrap();
    assert_eq!(v.value(4, 3, 2), Some(59.0 * 7.0));
    assert_eq!(v.spacing(), [0.5, 0.5, 2.0]);
    // Wrong sizes either way: located at the end of the data or of the file.
    let with_dims = |dims| raw::read(&p, &RawSpec { dims, ..spec }, &Limits::default());
    let e = with_dims([5, 4, 4]).unwrap_err();
    assert_eq!(
        e.to_string(),
        format!(
            "{}: byte 120: the file ends after 120 bytes; 0 header bytes and sizes 5×4×4 of uint16 need 160",
            p.display()
        )
    );
    let e = with_dims([5, 4, 2]).unwrap_err();
    assert!(
        e.to_string().contains("byte 80: 40 bytes more than the 80"),
        "{e}"
    );
    let e = with_dims([0, 4, 2]).unwrap_err();
    assert!(
        e.to_string().contains("each dimension must be 1 to 65536"),
        "{e}"
    );
    let missing = tmp("no-such.raw");
    let e = raw::read(&missing, &spec, &Limits::default()).unwrap_err();
    assert!(matches!(e, VolumeError::Io { .. }));
    assert!(e.to_string().contains("no-such.raw"), "{e}");
}

/// A volume file or detached data file that is a pipe, a device or a
/// folder is refused before it is opened (opening a pipe would wait for a
/// writer, a device could be read without end).
#[test]
fn volume_data_must_be_a_regular_file() {
    let header = |data: &str| {
        format!(
            "NRRD0004\ntype: uint8\ndimension: 3\nsizes: 2 2 2\nencoding: raw\ndata file: {data}\n\n"
        )
    };
    let dir = tmp("special");
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let fifo = dir.join("pipe.raw");
    let mut cases = vec![("/dev/zero".to_owned(), "not a regular file")];
    cases.push((dir.display().to_string(), "a directory, not a file"));
    if std::process::Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .is_ok_and(|s| s.success())
    {
        cases.push((fifo.display().to_string(), "not a regular file"));
    } else {
        eprintln!("mkfifo is not available: the pipe is not checked");
    }
    // The message with its causes, as the command line shows it.
    let chain = |e: VolumeError| {
        let mut s = e.to_string();
        let mut at: Option<&dyn std::error::Error> = std::error::Error::source(&e);
        while let Some(c) = at {
            s = format!("{s}: {c}");
            at = c.source();
        }
        s
    };
    for (data, why) in &cases {
        let nhdr = dir.join("v.nhdr");
        std::fs::write(&nhdr, header(data)).unwrap();
        let e = chain(nrrd::read(&nhdr, &Limits::default()).unwrap_err());
        assert!(e.contains(data) && e.contains(why), "{data}: {e}");
        let spec = RawSpec {
            dims: [2, 2, 2],
            sample_type: SampleType::U8,
            endian: Endian::Little,
            grid: Grid::unit(),
            skip: 0,
        };
        let e = chain(raw::read(Path::new(data), &spec, &Limits::default()).unwrap_err());
        assert!(e.contains(why), "{data}: {e}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// The NRRD volume `../shared/data/volumes/<name>`, which must have
/// `dims` samples, or a skip message.
#[track_caller]
fn real_volume(name: &str, dims: [u32; 3]) -> Option<Volume> {
    let v = nrrd::read(&real(name)?, &Limits::default()).unwrap();
    assert_eq!(v.dims(), dims);
    Some(v)
}

/// `v`'s samples range over `range` and average `mean` (to 1e-4).
#[track_caller]
fn assert_range_mean(v: &Volume, range: (f64, f64), mean: f64) {
    assert_eq!(v.range(), range);
    assert!((v.mean() - mean).abs() < 1e-4, "{}", v.mean());
}

/// `v` holds `want` at each sample `ijk` of `samples`.
#[track_caller]
fn assert_samples(v: &Volume, samples: &[([u32; 3], f64)]) {
    for &(ijk, want) in samples {
        assert_eq!(v.value(ijk[0], ijk[1], ijk[2]), Some(want), "{ijk:?}");
    }
}

/// `../shared/data/volumes/<name>` or a skip message.
fn real(name: &str) -> Option<PathBuf> {
    let Some(data) = rrt_tests::shared_data() else {
        eprintln!("skipped: ../shared/data is absent");
        return None;
    };
    let p = data.join("volumes").join(name);
    if p.is_file() {
        Some(p)
    } else {
        eprintln!("skipped: {} is absent", p.display());
        None
    }
}

#[test]
fn real_mri_head() {
    let Some(v) = real_volume("mri_head_colin27.nrrd", [181, 217, 181]) else {
        return;
    };
    assert_eq!(v.sample_type(), SampleType::U8);
    assert_eq!(v.spacing(), [1.0; 3]);
    assert_eq!(v.origin(), DVec3::new(-90.0, -125.0, -71.0));
    assert!(v.is_cubic());
    // The data README: min 0, max 254, mean 44.6118.
    assert_range_mean(&v, (0.0, 254.0), 44.6118);
    assert_samples(
        &v,
        &[
            ([0, 0, 0], 0.0),
            ([90, 108, 90], 33.0),
            ([100, 150, 60], 110.0),
            ([45, 60, 120], 87.0),
            ([180, 216, 180], 0.0),
        ],
    );
    // Physical (mm) lookups land on the samples.
    assert_eq!(v.sample_physical(DVec3::new(0.0, -17.0, 19.0)), Some(33.0));
    // Threshold 20 separates head from air: 3,844,205 samples.
    let c = Classifier::iso(20.0);
    assert_eq!(c.count(&v), 3_844_205);
    // Placed 1:1 in a raster whose voxels are the samples' cells: the
    // raster block holds exactly the classified samples.
    let placed = Placement::IDENTITY.place(&v);
    let frame = RasterFrame {
        extent: Extent::new(181, 217, 181).unwrap(),
        origin: DVec3::new(-90.5, -125.5, -71.5),
        voxel_size: 1.0,
    };
    let block = placed.raster_block(&frame, &c, 1 << 30).unwrap().unwrap();
    assert_eq!(block.dims, [181, 217, 181]);
    assert_eq!(block.offset, [0, 0, 0]);
    assert_eq!(block.threshold, 20 * 256);
    assert_eq!(block.count_inside(), 3_844_205);
    assert_eq!(block.at_voxel([100, 150, 60]), Some(110 * 256));
    // The head's surface layer through the core's volume voxelizer, in
    // slabs of 4 MiB: every voxel inside, with an outside 6-neighbour.
    drop(block);
    let mut layer = Collect::default();
    let n = placed
        .voxelize(&frame, &c, Separation::Six, 4 << 20, &mut layer)
        .unwrap();
    assert_eq!(n, layer.0.len() as u64);
    eprintln!("MRI head at iso 20: {n} boundary voxels (6-separating)");
    assert!(n > 100_000 && n < 3_844_205, "{n}");
    for vox in layer.0.keys().step_by(997) {
        let [i, j, k] = *vox;
        assert!(c.is_opaque(v.value(i, j, k).unwrap()));
        // A face neighbour: one step along one axis, either way.
        let neighbours = (0..3).flat_map(|axis| {
            [-1, 1].map(|step| {
                let mut p = [i, j, k].map(i64::from);
                p[axis] += step;
                p
            })
        });
        let outside = neighbours.into_iter().any(|p| {
            p.iter().any(|x| *x < 0)
                || v.value(p[0] as u32, p[1] as u32, p[2] as u32)
                    .is_none_or(|x| !c.is_opaque(x))
        });
        assert!(outside, "{vox:?}");
    }
}

#[test]
fn real_ct_engine() {
    let Some(v) = real_volume("ct_engine.nrrd", [256, 256, 110]) else {
        return;
    };
    assert!(!v.geometry_known(), "the engine has no geometry fields");
    assert_eq!(v.spacing(), [1.0; 3]);
    assert_range_mean(&v, (0.0, 255.0), 26.0058);
    assert_samples(
        &v,
        &[
            ([128, 128, 55], 16.0),
            ([100, 60, 30], 6.0),
            ([200, 180, 90], 143.0),
            ([255, 255, 109], 0.0),
        ],
    );
    assert_eq!(Classifier::iso(80.0).count(&v), 1_129_646);
}

#[test]
fn real_density_map_resampled_to_cubic_voxels() {
    let Some(v) = real_volume("density_1jzv.nrrd", [76, 96, 70]) else {
        return;
    };
    assert_eq!(v.sample_type(), SampleType::F32);
    let s = v.spacing();
    assert!((s[0] - 0.545_238_095_238_095_2).abs() < 1e-15);
    assert!((s[1] - 0.545_238_095_238_095_2).abs() < 1e-15);
    assert!((s[2] - 0.560_312_5).abs() < 1e-15);
    assert!(!v.is_cubic());
    assert_eq!(
        v.origin(),
        DVec3::new(-12.540_476_190_476_19, -2.180_952_380_952_380_8, 57.151_875)
    );
    let (lo, hi) = v.range();
    assert_eq!((lo as f32, hi as f32), (-0.993_094_2, 9.050_404));
    assert!(v.mean().abs() < 1e-3);
    assert_eq!(v.value(38, 48, 35), Some(f64::from(-0.405_932_9_f32)));
    assert_eq!(v.value(50, 10, 60), Some(f64::from(0.079_856_93_f32)));
    assert_eq!(v.value(29, 21, 10), Some(f64::from(9.050_404_f32)));
    assert_eq!(Classifier::iso(0.5).count(&v), 45_679);

    // To cubic voxels of the z spacing: z keeps its 70 samples, x and y
    // get ceil(76·0.5452/0.5603) = 74 and ceil(96·0.5452/0.5603) = 94.
    let c = resample_cubic(&v, 0.560_312_5, &Limits::default()).unwrap();
    assert!(c.is_cubic());
    assert_eq!(c.spacing(), [0.560_312_5; 3]);
    assert_eq!(c.dims(), [74, 94, 70]);
    assert_eq!(c.sample_type(), SampleType::F32);
    // Same physical box centre.
    let (a, b) = (v.physical_bounds(), c.physical_bounds());
    assert!(((a.min + a.max) - (b.min + b.max)).length() < 1e-9);
    // z planes coincide with the original's.
    assert!((c.origin().z - v.origin().z).abs() < 1e-12);
    // Every new sample is the original's trilinear value at its centre.
    for ijk in [
        [0, 0, 0],
        [37, 47, 35],
        [10, 80, 3],
        [73, 93, 69],
        [25, 18, 10],
    ] {
        let p = c.index_to_physical(DVec3::from(ijk.map(f64::from)));
        let want = v.sample_physical(p).unwrap() as f32;
        assert_eq!(
            c.value(ijk[0], ijk[1], ijk[2]),
            Some(f64::from(want)),
            "{ijk:?}"
        );
    }
    // The peak survives (slightly lowered by interpolation).
    let (_, chi) = c.range();
    assert!(chi > 7.0 && chi <= hi, "{chi}");
}

#[test]
fn resampling_reproduces_a_linear_field() {
    // g = 2x − y + 0.5z on an anisotropic grid: trilinear resampling is
    // exact wherever the new centre lies between old sample centres.
    let dims = [9, 7, 5];
    let grid = Grid::axis_aligned([0.4, 0.6, 1.1], DVec3::new(1.0, -2.0, 0.5));
    let g = |p: DVec3| 2.0 * p.x - p.y + 0.5 * p.z;
    let v = computed::sample(&g, dims, grid, &Limits::default()).unwrap();
    let c = resample_cubic(&v, 0.3, &Limits::default()).unwrap();
    let cells = v.physical_bounds();
    let inner_lo = v.origin();
    let inner_hi = v.index_to_physical(DVec3::new(8.0, 6.0, 4.0));
    let mut checked = 0;
    for k in 0..c.dims()[2] {
        for j in 0..c.dims()[1] {
            for i in 0..c.dims()[0] {
                let p = c.index_to_physical(DVec3::new(i.into(), j.into(), k.into()));
                assert!(p.cmpge(cells.min - 0.15).all() && p.cmple(cells.max + 0.15).all());
                if p.cmpge(inner_lo).all() && p.cmple(inner_hi).all() {
                    let got = c.value(i, j, k).unwrap();
                    assert!((got - g(p)).abs() < 1e-5, "({i},{j},{k}) {got} vs {}", g(p));
                    checked += 1;
                }
            }
        }
    }
    assert!(checked > 300, "{checked}");
    assert!(resample_cubic(&v, 0.0, &Limits::default()).is_err());
    assert!(resample_cubic(&v, 1e-6, &Limits::default()).is_err());
}

/// A sphere of radius 3 mm sampled on an anisotropic grid (0.5 × 0.5 ×
/// 1.25 mm), placed at scale 2 (1 mm = 2 world units) in a raster of
/// 1-unit cubic voxels: the raster block must hold a ball of radius 6
/// voxels with radial gray-level normals.
#[test]
fn anisotropic_volume_in_cubic_raster_voxels() {
    let grid = Grid::axis_aligned([0.5, 0.5, 1.25], DVec3::splat(-4.0));
    let field = |p: DVec3| 1000.0 - 100.0 * p.length();
    let v = computed::sample(&field, [17, 17, 7], grid, &Limits::default()).unwrap();
    let centre_world = DVec3::new(20.0, 21.0, 22.0);
    let placed = Placement::new(centre_world, 2.0).unwrap().place(&v);
    let frame = RasterFrame {
        extent: Extent::cube(48).unwrap(),
        origin: DVec3::ZERO,
        voxel_size: 1.0,
    };
    let c = Classifier::iso(700.0); // r = 3 mm = 6 voxels
    let block = placed.raster_block(&frame, &c, 1 << 24).unwrap().unwrap();
    let inside = block.count_inside() as f64;
    let ball = 4.0 / 3.0 * std::f64::consts::PI * 6f64.powi(3);
    assert!((inside - ball).abs() < 0.05 * ball, "{inside} vs {ball}");
    // Every inside voxel centre is within the sphere (± half a voxel), and
    // each boundary voxel's gray-level normal points away from the centre.
    let q = Quantizer::for_volume(&v);
    let at = |x: i64, y: i64, z: i64| -> f64 {
        let (Ok(x), Ok(y), Ok(z)) = (u32::try_from(x), u32::try_from(y), u32::try_from(z)) else {
            return 0.0;
        };
        block.at_voxel([x, y, z]).map_or(0.0, |s| q.value(s))
    };
    let mut boundary = 0;
    for z in 0..48u32 {
        for y in 0..48u32 {
            for x in 0..48u32 {
                if block
                    .at_voxel([x, y, z])
                    .is_none_or(|s| s < block.threshold)
                {
                    continue;
                }
                let p = DVec3::new(f64::from(x), f64::from(y), f64::from(z)) + 0.5;
                let r = (p - centre_world).length();
                assert!(r <= 6.5, "({x},{y},{z}) r = {r}");
                if r < 5.0 {
                    continue;
                }
                boundary += 1;
                let (xi, yi, zi) = (i64::from(x), i64::from(y), i64::from(z));
                let n = gray_normal(at, xi, yi, zi).unwrap();
                let radial = (p - centre_world).normalize();
                assert!(n.dot(radial) > 0.97, "({x},{y},{z}) {n} vs {radial}");
            }
        }
    }
    assert!(boundary > 200, "{boundary}");
    // Through the core's volume voxelizer: whole block or slabs, the same
    // voxels and surfels; the core's integer normals agree with the float
    // gray-level gradient of the same block to within a degree.
    for sep in [Separation::Six, Separation::TwentySix] {
        let mut whole = Collect::default();
        let n = placed
            .voxelize(&frame, &c, sep, 1 << 24, &mut whole)
            .unwrap();
        let mut slabs = Collect::default();
        let m = placed
            .voxelize(&frame, &c, sep, 18 * 18 * 2 * 4, &mut slabs)
            .unwrap();
        assert_eq!(n, whole.0.len() as u64);
        assert_eq!(m, n);
        assert_eq!(whole.0, slabs.0, "{sep:?}");
        assert!(n > 300, "{n}");
        for (v, s) in &whole.0 {
            let (x, y, z) = (i64::from(v[0]), i64::from(v[1]), i64::from(v[2]));
            let want = gray_normal(at, x, y, z).unwrap();
            let got = DVec3::from(s.normal.map(f64::from)) / f64::from(NORMAL_ONE);
            assert!(
                got.dot(want) > 1f64.to_radians().cos(),
                "{v:?} {got} {want}"
            );
            // Every boundary voxel is inside, with an outside neighbour.
            assert!(block.at_voxel(*v).unwrap() >= block.threshold);
        }
    }
    // The world box and the raster box agree.
    let wb = placed.world_bounds();
    assert_eq!(wb.min, centre_world + DVec3::new(-8.5, -8.5, -9.25));
    let (first, n) = placed.raster_box(&frame).unwrap();
    // Cells from −4.25 to 4.25 mm (x, y) and −4.625 to 4.125 mm (z):
    // centres i + ½ from 11.5 to 28.5 (x), 12.5 to 29.5 (y), 12.75 to
    // 30.25 (z).
    assert_eq!(wb.max, centre_world + DVec3::new(8.5, 8.5, 8.25));
    assert_eq!(first, [11, 12, 13]);
    assert_eq!(n, [18, 18, 17]);
}

/// The paper's Figure 1 cut: a box subtracted from a solid volume before
/// its boundary is found exposes a closed cut face whose normals point
/// into the cut.
#[test]
fn csg_cut_exposes_the_cut_face() {
    let grid = Grid::axis_aligned([1.0; 3], DVec3::ZERO);
    let ball = |p: DVec3| 1000.0 - 100.0 * (p - DVec3::splat(10.0)).length();
    let v = computed::sample(&ball, [21; 3], grid, &Limits::default()).unwrap();
    let placed = Placement::IDENTITY.place(&v);
    let frame = RasterFrame {
        extent: Extent::cube(24).unwrap(),
        origin: DVec3::splat(-1.5),
        voxel_size: 1.0,
    };
    let c = Classifier::iso(200.0); // r = 8
    // Voxel i has centre i − 1: keep x < 10 (voxels 0..=10): the half ball.
    let keep = |v: [u32; 3]| v[0] <= 10;
    let mut cut = Collect::default();
    placed
        .voxelize_where(&frame, &c, Separation::Six, 1 << 20, Some(&keep), &mut cut)
        .unwrap();
    let mut whole = Collect::default();
    placed
        .voxelize(&frame, &c, Separation::Six, 1 << 20, &mut whole)
        .unwrap();
    assert!(cut.0.keys().all(|v| v[0] <= 10));
    // The cut face: voxels at x = 10 well inside the disc, normals +x.
    let face: Vec<_> = cut
        .0
        .iter()
        .filter(|(v, _)| v[0] == 10 && (f64::from(v[1]) - 11.0).hypot(f64::from(v[2]) - 11.0) < 6.0)
        .collect();
    assert!(face.len() > 90, "{}", face.len());
    for (v, s) in &face {
        assert!(
            !whole.0.contains_key(*v),
            "{v:?} was interior before the cut"
        );
        assert!(s.normal[0] > NORMAL_ONE / 2, "{v:?} {:?}", s.normal);
    }
}

/// Every offer of a voxelizer, each voxel at most once.
#[derive(Default)]
struct Collect(std::collections::BTreeMap<[u32; 3], Surfel>);

impl VoxelSink for Collect {
    fn offer(&mut self, voxel: [u32; 3], surfel: Surfel) {
        assert!(
            self.0.insert(voxel, surfel).is_none(),
            "{voxel:?} offered twice"
        );
    }
}

#[test]
fn classification_with_ramps() {
    let v = read("u8_raw.nrrd");
    // Values 0..59: iso 30 keeps 30..59 (30 samples); the opacity ramp
    // cuts out 40..49.
    assert_eq!(Classifier::iso(30.0).count(&v), 30);
    let ramp = Ramp::new(vec![(39.5, 1.0), (40.0, 0.0), (49.0, 0.0), (49.5, 1.0)]).unwrap();
    let c = Classifier::iso(30.0).with_opacity(ramp);
    assert_eq!(c.count(&v), 20);
    let colors = ColorRamp::new(vec![(30.0, [255, 0, 0]), (59.0, [0, 0, 255])]).unwrap();
    let c = c.with_color(colors);
    assert_eq!(c.color(30.0, [1; 3]), [255, 0, 0]);
    assert_eq!(c.color(44.5, [1; 3]), [128, 0, 128]);
    assert_eq!(c.color(100.0, [1; 3]), [0, 0, 255]);
    assert_eq!(Classifier::iso(30.0).color(44.5, [1, 2, 3]), [1, 2, 3]);
    // In the raster block the cut band is below the threshold even though
    // its values are above the iso-value.
    let placed = Placement::IDENTITY.place(&v);
    let frame = RasterFrame {
        extent: Extent::new(10, 8, 18).unwrap(),
        origin: DVec3::new(0.75, 1.75, 2.25),
        voxel_size: 0.5,
    };
    let block = placed.raster_block(&frame, &c, 1 << 20).unwrap().unwrap();
    assert!(block.count_inside() > 0);
    for (n, s) in block.samples.iter().enumerate() {
        let n = n as u32;
        let [bx, by, _] = block.dims;
        let vox = [n % bx, (n / bx) % by, n / (bx * by)].map(|c| c as i64);
        let w = frame.raster_to_world(DVec3::from(std::array::from_fn::<f64, 3, _>(|a| {
            (vox[a] + block.offset[a]) as f64 + 0.5
        })));
        let val = placed.sample_world(w);
        let opaque = val.is_some_and(|x| c.is_opaque(x));
        assert_eq!(*s >= block.threshold, opaque, "voxel {vox:?} value {val:?}");
    }
    assert!(Classifier::iso(f64::NAN).validate().is_err());
    // The colour ramp as the builder's texture: each voxel centre's value.
    let colors = VolumeColors::new(placed, frame, &c);
    for vox in [[0u32, 0, 0], [3, 2, 9], [9, 7, 17], [5, 5, 5]] {
        let centre = vox.map(rrt_core::fixed::voxel_centre);
        let w = frame.raster_to_world(DVec3::from(vox.map(f64::from)) + 0.5);
        let want = placed
            .sample_world(w)
            .map_or([7; 3], |x| c.color(x, [7; 3]));
        assert_eq!(
            colors.color(centre, [0, 0, 1 << 30], [7; 3]),
            want,
            "{vox:?}"
        );
    }
    // Voxel (4, 3, 7): centre (3, 3.5, 6) is sample (4, 3, 2), value 59:
    // the ramp's end. Voxel (5, 5, 5) lies outside the volume: the base.
    let at = |v: [u32; 3]| colors.color(v.map(rrt_core::fixed::voxel_centre), [0; 3], [7; 3]);
    assert_eq!(at([4, 3, 7]), [0, 0, 255]);
    assert_eq!(at([5, 5, 5]), [7; 3]);
}

/// Metaballs sampled ball by ball give the field sampled point by point:
/// balls inside, across and outside the grid, of both signs, one too
/// small to reach a sample, on an axis-aligned grid and (the same path
/// as the generic one) on a sheared grid.
#[test]
fn metaballs_sampled_ball_by_ball_equal_the_field_sampled_point_by_point() {
    let mut seed = 0x9e37_79b9_7f4a_7c15_u64;
    let mut next = move || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as f64 / (1u64 << 53) as f64
    };
    let mut balls: Vec<Metaball> = (0..40)
        .map(|_| Metaball {
            centre: DVec3::new(next() * 4.0 - 2.0, next() * 4.0 - 2.0, next() * 4.0 - 2.0),
            radius: 0.05 + next() * 1.2,
            strength: next() * 4.0 - 1.5,
        })
        .collect();
    balls.push(Metaball {
        centre: DVec3::new(0.013, 0.017, 0.011),
        radius: 1e-3,
        strength: 5.0,
    });
    let blobs = Metaballs(balls);
    let sheared = Grid {
        origin: DVec3::splat(-1.5),
        directions: [
            DVec3::new(0.06, 0.0, 0.0),
            DVec3::new(0.01, 0.07, 0.0),
            DVec3::new(0.0, 0.0, 0.05),
        ],
    };
    for (dims, grid) in [
        (
            [61, 47, 53],
            Grid::axis_aligned([0.05, 0.06, 0.055], DVec3::splat(-1.5)),
        ),
        (
            [1, 33, 2],
            Grid::axis_aligned([0.1; 3], DVec3::new(0.3, -1.6, 0.0)),
        ),
        ([40, 40, 40], sheared),
    ] {
        let fast = blobs.sample(dims, grid, &Limits::default()).unwrap();
        let slow = computed::sample(&blobs, dims, grid, &Limits::default()).unwrap();
        let (Samples::F32(a), Samples::F32(b)) = (fast.samples(), slow.samples()) else {
            panic!("float samples expected");
        };
        assert_eq!(a.len(), b.len());
        let differ = a.iter().zip(b).filter(|(x, y)| x != y).count();
        assert_eq!(differ, 0, "{dims:?}: {differ} samples differ");
        assert!(
            a.iter().filter(|&&x| x != 0.0).count() > a.len() / 20,
            "{dims:?}"
        );
        assert_eq!(fast.range(), slow.range());
    }
}

#[test]
fn computed_datasets() {
    let blobs = Metaballs(vec![
        Metaball {
            centre: DVec3::new(-0.5, 0.0, 0.0),
            radius: 1.0,
            strength: 1.0,
        },
        Metaball {
            centre: DVec3::new(0.5, 0.2, 0.0),
            radius: 0.8,
            strength: 2.0,
        },
    ]);
    let grid = Grid::axis_aligned([0.05; 3], DVec3::splat(-1.6));
    let v = computed::sample(&blobs, [65; 3], grid, &Limits::default()).unwrap();
    assert_eq!(v.sample_type(), SampleType::F32);
    let (_, hi) = v.range();
    assert!(hi >= 2.0, "{hi}");
    // Iso 0.5 is one blob: the voxel between the balls is inside.
    let c = Classifier::iso(0.5);
    assert!(c.is_opaque(v.sample_physical(DVec3::new(0.0, 0.1, 0.0)).unwrap()));
    let inside = c.count(&v);
    assert!(inside > 5000 && inside < 65u64.pow(3) / 2, "{inside}");
    let sources = ScreenedSources {
        sources: vec![(DVec3::ZERO, 1.0), (DVec3::new(2.0, 0.0, 0.0), 0.5)],
        decay: 1.5,
        epsilon: 0.1,
    };
    let d = computed::sample(
        &sources,
        [16, 8, 8],
        Grid::axis_aligned([0.25; 3], DVec3::new(-1.0, -1.0, -1.0)),
        &Limits::default(),
    )
    .unwrap();
    assert!((d.value(4, 4, 4).unwrap() - (10.0 + 0.5 * (-2.0f64 / 1.5).exp() / 2.1)).abs() < 1e-5);
    let e = computed::sample(
        &|_: DVec3| f64::NAN,
        [2, 2, 2],
        Grid::unit(),
        &Limits::default(),
    )
    .unwrap_err();
    assert_eq!(
        e.to_string(),
        "computed volume: the field is not finite at sample (0, 0, 0)"
    );
}

// ---- bad input ----------------------------------------------------------

fn parse_err(bytes: &[u8]) -> String {
    match nrrd::parse_bytes("bad.nrrd", bytes, &Limits::default()) {
        Ok(v) => panic!("accepted: {:?}", v.dims()),
        Err(e) => e.to_string(),
    }
}

const U8_HEAD: &str = "NRRD0004\ntype: uint8\ndimension: 3\nsizes: 5 4 3\nencoding: raw\n\n";

#[test]
fn truncated_and_lying_data() {
    let good = std::fs::read(fixture("u8_raw.nrrd")).unwrap();
    let head = good.len() - 60;
    // Truncated raw data.
    let e = parse_err(&good[..good.len() - 7]);
    assert_eq!(
        e,
        format!(
            "bad.nrrd: byte {}: the data end after 53 of 60 bytes (sizes 5×4×3 of uint8): truncated file or sizes that lie",
            head + 53
        )
    );
    // Extra data: sizes that lie the other way.
    let mut long = good.clone();
    long.push(0);
    let e = parse_err(&long);
    assert!(
        e.starts_with(&format!(
            "bad.nrrd: byte {}: data continue past the 60 bytes",
            good.len()
        )),
        "{e}"
    );
    // Truncated in the header: no empty line, no data file.
    let e = parse_err(&good[..40]);
    assert!(e.contains("no empty line ending it"), "{e}");
    // Gzip: truncated stream, damaged stream, and sizes that lie.
    let gz = std::fs::read(fixture("u8_gzip.nrrd")).unwrap();
    let gz_head = gz.windows(2).position(|w| w == b"\n\n").unwrap() + 2;
    let e = parse_err(&gz[..gz.len() - 12]);
    assert!(
        e.starts_with(&format!("bad.nrrd: byte {gz_head}: gzip stream")),
        "{e}"
    );
    let mut bad = gz.clone();
    bad[gz_head + 12] ^= 0xff;
    let e = parse_err(&bad);
    assert!(
        e.starts_with(&format!("bad.nrrd: byte {gz_head}: gzip stream")),
        "{e}"
    );
    let lie = String::from_utf8_lossy(&gz[..gz_head]).replace("sizes: 5 4 3", "sizes: 5 4 4");
    let mut lying = lie.into_bytes();
    lying.extend_from_slice(&gz[gz_head..]);
    let e = parse_err(&lying);
    assert!(e.contains("decompresses to 60 of 80 bytes"), "{e}");
    let lie = String::from_utf8_lossy(&gz[..gz_head]).replace("sizes: 5 4 3", "sizes: 5 4 2");
    let mut lying = lie.into_bytes();
    lying.extend_from_slice(&gz[gz_head..]);
    let e = parse_err(&lying);
    assert!(e.contains("decompresses to more than the 40 bytes"), "{e}");
    // Raw bytes claimed gzip.
    let e = parse_err(&good.clone().replace_enc());
    assert!(e.contains("gzip stream"), "{e}");
    // ASCII: too few, too many, not numbers.
    let a = "NRRD0004\ntype: uint8\ndimension: 3\nsizes: 2 1 1\nencoding: ascii\n\n";
    assert!(parse_err(format!("{a}1").as_bytes()).contains("1 of the 2 values"));
    assert!(parse_err(format!("{a}1 2 3").as_bytes()).contains("more than the 2 values"));
    let e = parse_err(format!("{a}1 x").as_bytes());
    assert_eq!(
        e,
        format!(
            "bad.nrrd: byte {}: ascii data: `x` is not a number",
            a.len() + 2
        )
    );
}

trait ReplaceEnc {
    fn replace_enc(self) -> Vec<u8>;
}
impl ReplaceEnc for Vec<u8> {
    fn replace_enc(self) -> Vec<u8> {
        let s = self
            .windows(13)
            .position(|w| w == b"encoding: raw")
            .unwrap();
        let mut out = self[..s].to_vec();
        out.extend_from_slice(b"encoding: gzip");
        out.extend_from_slice(&self[s + 13..]);
        out
    }
}

#[test]
fn bad_headers_name_the_line() {
    let cases: &[(&str, &str)] = &[
        ("", "bad.nrrd:1: empty file: not a NRRD file"),
        (
            "NRRD0006\n",
            "bad.nrrd:1: not a NRRD file: expected the magic `NRRD0001` to `NRRD0005`, found `NRRD0006`",
        ),
        ("\u{89}PNG\r\n", "bad.nrrd:1: not a NRRD file"),
        (
            "NRRD0004\ntype: uint8\ndimension: 4\n\n",
            "bad.nrrd:3: dimension: 4 axes; only 3D volumes (dimension: 3) are supported",
        ),
        (
            "NRRD0004\ntype: int32\n\n",
            "bad.nrrd:2: type: `int32` is not supported (uint8, int16, uint16 or float)",
        ),
        (
            "NRRD0004\ntype: complex\n\n",
            "bad.nrrd:2: type: unknown type `complex`",
        ),
        (
            "NRRD0004\ntype: uint8\ndimension: 3\nsizes: 5 4 3\nencoding: zip\n\n",
            "bad.nrrd:5: encoding: unknown encoding `zip` (raw, gzip or ascii)",
        ),
        (
            "NRRD0004\ntype: uint8\ndimension: 3\nsizes: 5 4 3\nencoding: hex\n\n",
            "bad.nrrd:5: encoding: `hex` is not supported",
        ),
        (
            "NRRD0004\ntype: uint8\ndimension: 3\nsizes: 5 0 3\nencoding: raw\n\n",
            "bad.nrrd:4: sizes: 0 samples along an axis; expected 1 to 65536",
        ),
        (
            "NRRD0004\ntype: uint8\ndimension: 3\nsizes: 5 x 3\nencoding: raw\n\n",
            "bad.nrrd:4: sizes: expected positive integers, found `x`",
        ),
        (
            "NRRD0004\ntype: uint8\ndimension: 3\nsizes: 5 4 3\n\n",
            "bad.nrrd: header: missing field `encoding`",
        ),
        (
            "NRRD0004\ndimension: 3\nsizes: 5 4 3\nencoding: raw\n\n",
            "bad.nrrd: header: missing field `type`",
        ),
        (
            "NRRD0004\ntype: float\ndimension: 3\nsizes: 5 4 3\nencoding: raw\n\n",
            "bad.nrrd: header: missing field `endian` (needed for multi-byte samples in raw or gzip data)",
        ),
        (
            "NRRD0004\ntype: uint8\ndimension: 3\nsizes: 5 4 3\nendian: middle\nencoding: raw\n\n",
            "bad.nrrd:5: endian: expected `little` or `big`, found `middle`",
        ),
        (
            "NRRD0004\ntype: uint8\ndimension: 3\nsizes: 5 4 3\nencoding: raw\nspace directions: (1,0,0) (0,1,0)\n\n",
            "bad.nrrd:6: space directions: expected 3 vectors (one per axis), found 2",
        ),
        (
            "NRRD0004\ntype: uint8\ndimension: 3\nsizes: 5 4 3\nencoding: raw\nspace directions: (1,0,0) (2,0,0) (0,0,1)\n\n",
            "bad.nrrd:6: space directions: the three directions do not span space",
        ),
        (
            "NRRD0004\ntype: uint8\ndimension: 3\nsizes: 5 4 3\nencoding: raw\nspace directions: (1,0) (0,1,0) (0,0,1)\n\n",
            "bad.nrrd:6: space directions: expected 3 components (a 3D space), found 2 in `(1,0)`",
        ),
        (
            "NRRD0004\ntype: uint8\ndimension: 3\nsizes: 5 4 3\nencoding: raw\nspacings: 1 0 1\n\n",
            "bad.nrrd:6: spacings: `0` is not a finite non-zero spacing",
        ),
        (
            "NRRD0004\ntype: uint8\ndimension: 3\nsizes: 5 4 3\nencoding: raw\nspacings: 1 1e-300 1\n\n",
            "bad.nrrd:6: spacings: axis 1: step [0e0, 1e-300, 0e0] is not finite, or shorter than 1e-12",
        ),
        (
            "NRRD0004\ntype: uint8\ndimension: 3\nsizes: 5 4 3\nencoding: raw\nspace: RAST\n\n",
            "bad.nrrd:6: space: `RAST` is 4D; only 3D spaces are supported",
        ),
        (
            "NRRD0004\ntype: uint8\ndimension: 3\nsizes: 5 4 3\nencoding: raw\nspace origin: (1,2,inf)\n\n",
            "bad.nrrd:6: space origin: `inf` is not a finite number",
        ),
        (
            "NRRD0004\ntype: uint8\ndimension: 3\nsizes: 5 4 3\nencoding: gzip\nbyte skip: -1\n\n",
            "bad.nrrd:6: byte skip: -1 (data at the end of the file) needs raw encoding",
        ),
        (
            "NRRD0004\ntype: uint8\ndimension: 3\nsizes: 5 4 3\nencoding: raw\ndata file: x%03d.raw 1 3 1\n\n",
            "bad.nrrd:6: data file: `x%03d.raw 1 3 1`: only a single data file is supported",
        ),
        (
            "NRRD0004\ntype: uint8\ndimension: 3\nsizes: 5 4 3\nencoding: raw\ndata file: x.raw\n",
            "bad.nrrd:6: data file: `x.raw`: a detached header read from memory cannot open its data file",
        ),
        (
            "NRRD0004\ntype: uint8\nsizes 5 4 3\n",
            "bad.nrrd:3: expected `field: value`, found `sizes 5 4 3`",
        ),
        (
            "NRRD0004\ntype: uint8\nfoo: 1\n",
            "bad.nrrd:3: unknown NRRD field `foo`",
        ),
        (
            "NRRD0004\n\u{ff}\n",
            "bad.nrrd:2: header line is not text (UTF-8)",
        ),
    ];
    for (text, want) in cases {
        let bytes: Vec<u8> = if text.starts_with('\u{89}') {
            b"\x89PNG\r\n".to_vec()
        } else if text.contains('\u{ff}') {
            b"NRRD0004\n\xff\n".to_vec()
        } else {
            text.as_bytes().to_vec()
        };
        let e = parse_err(&bytes);
        assert!(e.starts_with(want), "{text:?}\n got: {e}\nwant: {want}");
    }
    // A header without an end stops at the limit instead of reading on.
    let mut endless = b"NRRD0004\n".to_vec();
    endless.extend(std::iter::repeat_n(b'#', 5000));
    let small = Limits {
        max_header_bytes: 1000,
        ..Limits::default()
    };
    let e = nrrd::parse_bytes("bad.nrrd", &endless, &small).unwrap_err();
    assert_eq!(
        e.to_string(),
        "bad.nrrd:2: the header runs past 1000 bytes without an empty line; not a NRRD header"
    );
    // Only the first empty line ends the header; raw data follow it.
    assert!(
        nrrd::parse_bytes(
            "ok.nrrd",
            &[U8_HEAD.as_bytes(), &[0u8; 60]].concat(),
            &Limits::default()
        )
        .is_ok()
    );
}

#[test]
fn absurd_sizes_are_refused_before_allocating() {
    // 65536³ floats = 1 PiB: refused at once, naming the sizes line.
    let h = "NRRD0004\ntype: float\ndimension: 3\nsizes: 65536 65536 65536\nendian: little\nencoding: raw\n\n";
    let e = parse_err(h.as_bytes());
    assert_eq!(
        e,
        "bad.nrrd:4: sizes 65536×65536×65536 of float take 1125899906842624 bytes, more than the limit of 4294967296 bytes"
    );
    let e = parse_err(b"NRRD0004\ntype: uint8\ndimension: 3\nsizes: 65537 1 1\nencoding: raw\n\n");
    assert!(e.contains("sizes: 65537 samples along an axis"), "{e}");
    let e = parse_err(b"NRRD0004\ntype: uint8\ndimension: 3\nsizes: 99999999999999999999999 1 1\nencoding: raw\n\n");
    assert!(
        e.starts_with("bad.nrrd:4: sizes: expected positive integers"),
        "{e}"
    );
    // A limit of the caller's choosing.
    let small = Limits {
        max_bytes: 59,
        ..Limits::default()
    };
    let e = nrrd::read(fixture("u8_raw.nrrd"), &small).unwrap_err();
    assert!(
        matches!(
            e,
            VolumeError::TooLarge {
                bytes: 60,
                limit: 59,
                ..
            }
        ),
        "{e}"
    );
    // Same for raw files, resampling and computed volumes.
    let spec = RawSpec {
        dims: [65536; 3],
        sample_type: SampleType::U16,
        endian: Endian::Little,
        grid: Grid::unit(),
        skip: 0,
    };
    assert!(matches!(
        raw::parse_bytes("big.raw", &[], &spec, &Limits::default()),
        Err(VolumeError::TooLarge { .. })
    ));
    let v = read("u8_raw.nrrd");
    assert!(matches!(
        resample_cubic(&v, 0.001, &Limits::default()),
        Err(VolumeError::TooLarge { .. })
    ));
}

#[test]
fn missing_and_bad_files() {
    let e = nrrd::read(fixture("does-not-exist.nrrd"), &Limits::default()).unwrap_err();
    assert!(matches!(e, VolumeError::Io { .. }));
    assert!(e.to_string().contains("does-not-exist.nrrd"), "{e}");
    // A detached header whose data file does not exist names that file.
    let h = tmp("lost.nhdr");
    std::fs::write(
        &h,
        "NRRD0004\ntype: uint8\ndimension: 3\nsizes: 5 4 3\nencoding: raw\ndata file: lost.raw\n",
    )
    .unwrap();
    let e = nrrd::read(&h, &Limits::default()).unwrap_err();
    assert_eq!(
        e.to_string(),
        format!("cannot read {}", tmp("lost.raw").display())
    );
    // A detached data file that is too short: offset in the data file.
    std::fs::write(tmp("short.raw"), [0u8; 50]).unwrap();
    std::fs::write(
        tmp("short.nhdr"),
        "NRRD0004\ntype: uint8\ndimension: 3\nsizes: 5 4 3\nencoding: raw\ndata file: short.raw\n",
    )
    .unwrap();
    let e = nrrd::read(tmp("short.nhdr"), &Limits::default()).unwrap_err();
    assert_eq!(
        e.to_string(),
        format!(
            "{}: byte 50: the data end after 50 of 60 bytes (sizes 5×4×3 of uint8): truncated file or sizes that lie",
            tmp("short.raw").display()
        )
    );
    // A volume built in code with the wrong sample count.
    let e = Volume::new([2, 2, 2], Grid::unit(), Samples::F32(vec![0.0; 3])).unwrap_err();
    assert_eq!(
        e.to_string(),
        "volume: 3 samples for dimensions 2×2×2 (8 expected)"
    );
    assert!(Placement::new(DVec3::ZERO, 0.0).is_err());
    assert!(Placement::new(DVec3::new(f64::NAN, 0.0, 0.0), 1.0).is_err());
}
