//! Unit tests of the discrete ray; the exhaustive ones live in `tests/`.

use std::vec;
use std::vec::Vec;

use super::*;
use crate::check::{check_adaptive_matches_six, check_lattice_counts, check_ray};
use crate::fixed::{VOXEL, voxel_centre};
use crate::proximity::flag_neighbourhood;
use crate::raster::{Extent, RasterMut, cell};

fn centre(v: [u32; 3]) -> [i64; 3] {
    v.map(voxel_centre)
}

/// Zero cells, enough for every empty raster of these tests.
static EMPTY: [u8; 4096] = [0; 4096];

/// The empty raster of extent `e` (at most 4096 voxels).
fn empty(e: Extent) -> Raster<'static> {
    Raster::new(e, &EMPTY[..e.len()]).unwrap()
}

#[track_caller]
fn path(raster: &Raster<'_>, ray: DiscreteRay, mode: Connectivity) -> Vec<[u32; 3]> {
    ray.voxels(raster, mode)
        .unwrap()
        .map(|v| raster.extent().coord(v.index).unwrap())
        .collect()
}

#[test]
fn axis_parallel_rays_visit_one_row() {
    let e = Extent::new(5, 4, 3).unwrap();
    let r = empty(e);
    for (dir, want) in [
        (
            [1, 0, 0],
            vec![[0, 2, 1], [1, 2, 1], [2, 2, 1], [3, 2, 1], [4, 2, 1]],
        ),
        (
            [-1, 0, 0],
            vec![[4, 2, 1], [3, 2, 1], [2, 2, 1], [1, 2, 1], [0, 2, 1]],
        ),
    ] {
        let o = [
            if dir[0] > 0 { -3 * VOXEL } else { 9 * VOXEL },
            voxel_centre(2),
            voxel_centre(1),
        ];
        let ray = DiscreteRay::new(e, o, dir).unwrap().unwrap();
        for mode in Connectivity::ALL {
            assert_eq!(path(&r, ray, mode), want, "{mode:?}");
            check_ray(&r, &ray, mode).unwrap();
        }
    }
}

#[test]
fn diagonal_through_corners_uses_the_tie_rule() {
    // Exactly through voxel corners: x steps before y before z.
    let e = Extent::cube(3).unwrap();
    let r = empty(e);
    let ray = DiscreteRay::new(e, [0, 0, 0], [1, 1, 1]).unwrap().unwrap();
    assert_eq!(ray.entry_face(), Some(Face::ZMin));
    assert_eq!(
        path(&r, ray, Connectivity::Six),
        vec![
            [0, 0, 0],
            [1, 0, 0],
            [1, 1, 0],
            [1, 1, 1],
            [2, 1, 1],
            [2, 2, 1],
            [2, 2, 2]
        ]
    );
    assert_eq!(
        path(&r, ray, Connectivity::TwentySix),
        vec![[0, 0, 0], [1, 1, 1], [2, 2, 2]]
    );
    for mode in Connectivity::ALL {
        check_ray(&r, &ray, mode).unwrap();
    }
}

#[test]
fn twenty_six_takes_the_first_six_voxel_of_each_slice_away_from_ties() {
    let e = Extent::cube(16).unwrap();
    let r = empty(e);
    let ray = DiscreteRay::segment(
        e,
        [VOXEL / 3, 5 * VOXEL / 7, 2 * VOXEL + 11],
        [15 * VOXEL + 7, 9 * VOXEL + 3, 13 * VOXEL],
    )
    .unwrap()
    .unwrap();
    let six = path(&r, ray, Connectivity::Six);
    let tws = path(&r, ray, Connectivity::TwentySix);
    let a = ray.driving_axis();
    let mut firsts = Vec::new();
    for v in &six {
        if firsts.last().is_none_or(|l: &[u32; 3]| l[a] != v[a]) {
            firsts.push(*v);
        }
    }
    assert_eq!(tws, firsts);
}

#[test]
fn lattice_endpoints_give_the_papers_counts() {
    let e = Extent::new(20, 17, 9).unwrap();
    let r = empty(e);
    for (a, b) in [
        ([0, 0, 0], [19, 16, 8]),
        ([3, 4, 5], [3, 4, 5]),
        ([19, 0, 8], [0, 16, 0]),
        ([5, 5, 5], [12, 5, 1]),
    ] {
        check_lattice_counts(&r, a, b).unwrap();
    }
}

#[test]
fn zero_direction_visits_its_origin_voxel_only() {
    let e = Extent::cube(4).unwrap();
    let r = empty(e);
    let ray = DiscreteRay::new(e, centre([1, 2, 3]), [0, 0, 0])
        .unwrap()
        .unwrap();
    assert_eq!(path(&r, ray, Connectivity::Adaptive), vec![[1, 2, 3]]);
    assert!(
        DiscreteRay::new(e, [-1, 0, 0], [0, 0, 0])
            .unwrap()
            .is_none()
    );
}

#[test]
fn rays_that_miss_or_graze_have_no_voxels() {
    let e = Extent::cube(4).unwrap();
    let n = 4 * VOXEL;
    // Along the top face (y = n belongs to no voxel).
    assert!(
        DiscreteRay::new(e, [-VOXEL, n, VOXEL], [1, 0, 0])
            .unwrap()
            .is_none()
    );
    // Along the bottom face: inside (voxels are half-open).
    assert!(
        DiscreteRay::new(e, [-VOXEL, 0, VOXEL], [1, 0, 0])
            .unwrap()
            .is_some()
    );
    // Touching the box at a corner only.
    assert!(
        DiscreteRay::new(e, [-VOXEL, n - VOXEL, VOXEL], [1, 1, 0])
            .unwrap()
            .is_none()
    );
    // Through that corner and on into the box.
    assert!(
        DiscreteRay::new(e, [-VOXEL, n + VOXEL, VOXEL], [1, -1, 0])
            .unwrap()
            .is_some()
    );
    // Backwards.
    assert!(
        DiscreteRay::new(e, [-VOXEL, VOXEL, VOXEL], [-5, 1, 1])
            .unwrap()
            .is_none()
    );
}

#[test]
fn hits_resume_after_the_hit_voxel() {
    let e = Extent::cube(8).unwrap();
    let mut plane = vec![0u8; e.len()];
    for x in [2, 3, 6] {
        plane[e.index([x, 4, 4]).unwrap()] = cell::OPAQUE;
    }
    let r = Raster::new(e, &plane).unwrap();
    let mut ray = DiscreteRay::new(
        e,
        [0, centre([0, 4, 4])[1], voxel_centre(4)],
        [1 << 20, 0, 0],
    )
    .unwrap()
    .unwrap();
    let xs: Vec<u32> = core::iter::from_fn(|| ray.first_hit(&r, Connectivity::Six).unwrap())
        .map(|h| h.voxel[0])
        .collect();
    assert_eq!(xs, vec![2, 3, 6]);
    assert!(ray.is_done());
}

#[test]
fn adaptive_finds_what_six_finds_near_a_thin_diagonal_wall() {
    // A one-voxel-thick diagonal wall, 6-connected along x/y only: 26-rays can
    // slip through its diagonal gaps, 6-rays and adaptive rays cannot.
    let e = Extent::cube(16).unwrap();
    let mut plane = vec![0u8; e.len()];
    for z in 0..16 {
        for i in 0..16 {
            plane[e.index([i, 15 - i, z]).unwrap()] = cell::OPAQUE;
        }
    }
    let mut rm = RasterMut::new(e, &mut plane).unwrap();
    flag_neighbourhood(&mut rm);
    let r = rm.as_raster();
    let mut twenty_six_missed = 0;
    for k in 0..64i64 {
        let o = [k * VOXEL / 5, k * VOXEL / 7, 8 * VOXEL + 3];
        let ray = DiscreteRay::new(e, o, [1 << 20, 1 << 20, 1 << 16])
            .unwrap()
            .unwrap();
        check_adaptive_matches_six(&r, &ray).unwrap();
        for mode in Connectivity::ALL {
            check_ray(&r, &ray, mode).unwrap();
        }
        let mut tws = ray;
        let mut six = ray;
        if tws
            .first_hit(&r, Connectivity::TwentySix)
            .unwrap()
            .is_none()
            && six.first_hit(&r, Connectivity::Six).unwrap().is_some()
        {
            twenty_six_missed += 1;
        }
    }
    assert!(
        twenty_six_missed > 0,
        "the wall should be leaky for 26-rays"
    );
}

#[test]
fn walking_another_raster_is_an_error() {
    let e = Extent::cube(4).unwrap();
    let other = Extent::cube(5).unwrap();
    let plane = vec![0u8; other.len()];
    let r = Raster::new(other, &plane).unwrap();
    let mut ray = DiscreteRay::new(e, [0, 0, 0], [1, 2, 3]).unwrap().unwrap();
    assert_eq!(
        ray.first_hit(&r, Connectivity::Six),
        Err(RayError::ExtentMismatch)
    );
}

#[test]
fn extreme_inputs_are_refused_or_traced() {
    let e = Extent::cube(4096).unwrap();
    // No plane needed to set up.
    assert_eq!(
        DiscreteRay::new(e, [ORIGIN_LIMIT + 1, 0, 0], [1, 0, 0]),
        Err(RayError::OriginOutOfRange { axis: 0 })
    );
    let far = DiscreteRay::new(
        e,
        [-ORIGIN_LIMIT, -ORIGIN_LIMIT, -ORIGIN_LIMIT],
        [i32::MAX, i32::MAX, i32::MAX],
    )
    .unwrap()
    .unwrap();
    assert_eq!(far.entry_voxel(), [0, 0, 0]);
    assert_eq!(far.exit_voxel(), [4095, 4095, 4095]);
    let tiny = DiscreteRay::new(e, [-ORIGIN_LIMIT, 5, 7], [i32::MAX, 1, 1]).unwrap();
    assert!(tiny.is_some());
    assert_eq!(
        DiscreteRay::segment(e, [0, 0, 0], [i64::from(i32::MAX) + 1, 0, 0]),
        Err(RayError::SegmentTooLong { axis: 0 })
    );
    let min =
        DiscreteRay::new(e, [4096 * VOXEL + 5, 3, 3], [i32::MIN, i32::MIN, i32::MIN]).unwrap();
    assert!(min.is_none() || min.unwrap().entry_voxel()[0] == 4095);
}

#[test]
fn adaptive_finishes_an_edge_crossing_before_a_diagonal_step() {
    // Found by the oracle test: x and y cross together at every integer x,
    // and at x = 5 z crosses too. A 6-step to the tie voxel (4, 1, 2) out of
    // a flagged voxel used to be followed by a 26-step that owed two y
    // crossings and landed off the 6-ray at (5, 2, 1).
    let e = Extent::new(9, 7, 5).unwrap();
    let plane: Vec<u8> = (0..e.len())
        .map(|i| if i % 3 == 0 { cell::PROXIMITY } else { 0 })
        .collect();
    let r = Raster::new(e, &plane).unwrap();
    let ray = DiscreteRay::segment(e, [2 * VOXEL, 0, 4 * VOXEL], [8 * VOXEL, 6 * VOXEL, 0])
        .unwrap()
        .unwrap();
    let six = path(&r, ray, Connectivity::Six);
    let ada = path(&r, ray, Connectivity::Adaptive);
    let mut it = six.iter();
    assert!(
        ada.iter().all(|v| it.any(|s| s == v)),
        "adaptive {ada:?} not within six {six:?}"
    );
    assert!(!ada.contains(&[5, 2, 1]));
    for mode in Connectivity::ALL {
        check_ray(&r, &ray, mode).unwrap();
    }
}
