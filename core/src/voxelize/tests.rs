//! The hints of every voxelizer's sink: a sink that keeps some rows and
//! layers ([`VoxelSink::rows`], [`VoxelSink::layers`]) gets exactly the
//! offers of those rows and layers that a sink keeping every voxel gets,
//! in the same order, and one that reads no surfels
//! ([`VoxelSink::reads_surfels`]) the same voxels in the same order.

use core::ops::Range;
use std::format;
use std::vec::Vec;

use super::volume::Block;
use super::*;
use crate::csg::{self, CsgNode, CsgSink, CsgTree};
use crate::fixed::VOXEL;
use crate::geometry::{BezierPatch, Cone, Cuboid, Point, Sphere, Torus, Triangle};
use crate::raster::Extent;
use crate::testkit::Rng;

/// Every offer in order; keeps the rows `rows` of the layers `layers`,
/// reads the surfels if `reads`.
struct Sequence {
    rows: Range<u32>,
    layers: Range<u32>,
    reads: bool,
    offers: Vec<(u16, [u32; 3], Surfel)>,
}

impl Sequence {
    fn new([rows, layers]: [Range<u32>; 2]) -> Self {
        Self {
            rows,
            layers,
            reads: true,
            offers: Vec::new(),
        }
    }
}

impl VoxelSink for Sequence {
    fn offer(&mut self, voxel: [u32; 3], surfel: Surfel) {
        self.offers.push((0, voxel, surfel));
    }

    fn layers(&self) -> Range<u32> {
        self.layers.clone()
    }

    fn rows(&self) -> Range<u32> {
        self.rows.clone()
    }

    fn reads_surfels(&self) -> bool {
        self.reads
    }
}

impl CsgSink for Sequence {
    fn offer_leaf(&mut self, leaf: u16, voxel: [u32; 3], surfel: Surfel) {
        self.offers.push((leaf, voxel, surfel));
    }

    fn layers(&self) -> Range<u32> {
        self.layers.clone()
    }

    fn rows(&self) -> Range<u32> {
        self.rows.clone()
    }
}

/// `run` keeping every voxel and keeping the rows and layers of `keep`:
/// the offers of those rows and layers agree.
#[track_caller]
fn assert_layers_kept(what: &str, keep: [Range<u32>; 2], run: impl Fn(&mut Sequence)) {
    let mut all = Sequence::new([0..u32::MAX, 0..u32::MAX]);
    run(&mut all);
    let mut some = Sequence::new(keep.clone());
    run(&mut some);
    let [rows, layers] = &keep;
    let inside = |o: &&(u16, [u32; 3], Surfel)| rows.contains(&o.1[1]) && layers.contains(&o.1[2]);
    let want: Vec<_> = all.offers.iter().filter(inside).collect();
    let got: Vec<_> = some.offers.iter().filter(inside).collect();
    assert_eq!(got, want, "{what}, rows and layers {keep:?}");
    let mut counting = Sequence {
        reads: false,
        ..Sequence::new(keep.clone())
    };
    run(&mut counting);
    let voxels = |o: &(u16, [u32; 3], Surfel)| (o.0, o.1);
    let want: Vec<_> = all.offers.iter().filter(inside).map(voxels).collect();
    let got: Vec<_> = counting.offers.iter().filter(inside).map(voxels).collect();
    assert_eq!(
        got, want,
        "{what}, rows and layers {keep:?}, surfels unread"
    );
}

/// A point near the raster of `n` voxels per axis, in fixed units.
fn point(rng: &mut Rng, n: i64) -> Point {
    [0; 3].map(|_| rng.range(-2 * VOXEL, (n + 2) * VOXEL))
}

/// Spheres in many windows: the offers of a window are checked over
/// centres on lattice points, voxel centres and faces, radii of whole and
/// half voxels (crossings exactly on faces) and windows of one layer or
/// row up to the whole raster.
#[test]
fn spheres_offer_the_same_voxels_in_every_window() {
    let mut rng = Rng(0x0b5e_55ed_u64);
    let extent = Extent::new(18, 20, 22).unwrap();
    for case in 0..300u32 {
        let snap = case % 4;
        let centre = [0; 3].map(|_| {
            let base = rng.range(-3 * VOXEL, 24 * VOXEL);
            match snap {
                0 => base & !(VOXEL - 1),
                1 => (base & !(VOXEL - 1)) | (VOXEL / 2),
                _ => base,
            }
        });
        let radius = match case % 3 {
            0 => (1 + rng.range(0, 9)) * VOXEL,
            1 => (1 + rng.range(0, 18)) * (VOXEL / 2),
            _ => rng.range(VOXEL / 4, 10 * VOXEL),
        };
        let ball = Sphere { centre, radius };
        let z0 = rng.below_u32(24);
        let y0 = rng.below_u32(22);
        let layers = z0..z0 + 1 + rng.below_u32(if case % 2 == 0 { 2 } else { 12 });
        let rows = match case % 5 {
            0 | 1 => 0..u32::MAX,
            _ => y0..y0 + 1 + rng.below_u32(8),
        };
        for sep in [Separation::Six, Separation::TwentySix] {
            assert_layers_kept(
                &format!("sphere {case} {ball:?} {sep:?}"),
                [rows.clone(), layers.clone()],
                |s| {
                    sphere::surface(&ball, sep, extent, s).unwrap();
                },
            );
        }
    }
}

#[test]
fn voxelizers_offer_the_same_voxels_in_the_rows_and_layers_a_sink_keeps() {
    let mut rng = Rng(0x5eed_1a7e_u64);
    let n = 24i64;
    let extent = Extent::new(20, 22, 24).unwrap();
    for case in 0..40 {
        let sep = if case % 2 == 0 {
            Separation::Six
        } else {
            Separation::TwentySix
        };
        let z0 = rng.below_u32(26);
        let layers = z0..z0 + 1 + rng.below_u32(12);
        // Every row in a third of the cases (a slab), some rows otherwise
        // (a band).
        let y0 = rng.below_u32(24);
        let rows = if case % 3 == 0 {
            0..u32::MAX
        } else {
            y0..y0 + 1 + rng.below_u32(12)
        };
        let keep = [rows, layers];
        let r = |rng: &mut Rng| rng.range(VOXEL / 3, 9 * VOXEL);
        let ball = Sphere {
            centre: point(&mut rng, n),
            radius: r(&mut rng),
        };
        assert_layers_kept("sphere", keep.clone(), |s| {
            sphere::surface(&ball, sep, extent, s).unwrap();
            sphere::solid(&ball, sep, extent, s).unwrap();
        });
        let tri = Triangle {
            vertices: [0; 3].map(|_| point(&mut rng, n)),
            normals: None,
        };
        assert_layers_kept("triangle", keep.clone(), |s| {
            let _ = triangle::triangle(&tri, sep, extent, s);
        });
        let poly: Vec<Point> = (0..5).map(|_| point(&mut rng, n)).collect();
        assert_layers_kept("polygon", keep.clone(), |s| {
            let _ = triangle::polygon(&poly, sep, extent, s);
        });
        let faces = [[0, 1, 2], [0, 2, 3], [1, 3, 4]];
        assert_layers_kept("mesh", keep.clone(), |s| {
            let _ = triangle::mesh(&poly, None, &faces, sep, extent, s);
        });
        let cone = Cone {
            base: point(&mut rng, n),
            base_radius: r(&mut rng) / 2,
            apex: point(&mut rng, n),
            apex_radius: r(&mut rng) / 2,
        };
        assert_layers_kept("cone", keep.clone(), |s| {
            let _ = cone::surface(&cone, sep, extent, s);
            let _ = cone::capped(&cone, sep, extent, s);
        });
        let axis = [0; 3].map(|_| i32::try_from(rng.range(-1000, 1000)).unwrap());
        let ring = Torus {
            centre: point(&mut rng, n),
            axis: normalize_axis(axis),
            major: r(&mut rng),
            minor: r(&mut rng) / 3 + 1,
        };
        assert_layers_kept("torus", keep.clone(), |s| {
            let _ = torus::surface(&ring, sep, extent, s);
        });
        let mut control = [[[0i64; 3]; 4]; 4];
        for row in &mut control {
            for p in row.iter_mut() {
                *p = point(&mut rng, n);
            }
        }
        let bezier = BezierPatch { control };
        assert_layers_kept("patch", keep.clone(), |s| {
            let _ = patch::surface(&bezier, sep, extent, s);
        });
        let (a, b) = (point(&mut rng, n), point(&mut rng, n));
        let cube = Cuboid {
            min: [0, 1, 2].map(|k| a[k].min(b[k])),
            max: [0, 1, 2].map(|k| a[k].max(b[k]) + 1),
        };
        assert_layers_kept("cuboid", keep.clone(), |s| {
            let _ = cuboid::surface(&cube, sep, extent, s);
            let _ = cuboid::solid(&cube, sep, extent, s);
        });
        let dims = [9, 10, 11];
        let samples: Vec<u16> = (0..9 * 10 * 11)
            .map(|_| u16::try_from(rng.below(4)).unwrap())
            .collect();
        let block = Block {
            samples: &samples,
            dims,
            offset: [0; 3].map(|_| rng.range(-4, 16)),
        };
        assert_layers_kept("volume", keep.clone(), |s| {
            volume::boundary(&block, 2, sep, extent, s).unwrap();
        });
        let nodes = [
            CsgNode::Leaf(0),
            CsgNode::Leaf(1),
            CsgNode::Difference(0, 1),
        ];
        let leaves: [&dyn csg::Solid; 2] = [&ball, &cube];
        let tree = CsgTree::new(&nodes, &leaves).unwrap();
        assert_layers_kept("csg", keep.clone(), |s| {
            csg::voxelize(&tree, extent, s);
        });
    }
}

/// `a` scaled to a unit vector of [`NORMAL_ONE`] (the z axis for zero).
fn normalize_axis(a: [i32; 3]) -> [i32; 3] {
    crate::voxel::normalize(a.map(i64::from)).unwrap_or([0, 0, NORMAL_ONE])
}
