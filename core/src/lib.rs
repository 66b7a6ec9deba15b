//! # rrt-core: 3D raster ray tracing without floats, heap or panics
//!
//! The core of **rrt**, an implementation of *discrete ray tracing* (Yagel,
//! Cohen & Kaufman, "Discrete Ray Tracing", IEEE CG&A 1992). A scene is first
//! scan-converted (*voxelized*) into a 3D raster of voxels; rays are then
//! traced as integer 3D discrete lines through that raster, and the first
//! non-transparent voxel met is the hit.
//!
//! ## Guarantees
//! * `#![no_std]`, no `alloc`: the caller provides all storage (raster
//!   planes, record arrays, tables).
//! * Integer and fixed-point arithmetic only: no `f32`/`f64` anywhere.
//! * No `unsafe` code.
//! * **No input panics, allocates or loops forever.** Fallible functions
//!   return [`Result`] or [`Option`] with small `Copy` errors
//!   ([`error`]); walks are bounded by the ray's length and a step budget.
//!   A panic reachable from the public API is a bug; the `panic-never`
//!   check in `core/panic-never` links the traversal API with a panic
//!   handler that cannot be linked.
//!
//! ## Glossary (after the paper)
//! * **voxel**: the atomic volume element; it holds one object's attributes.
//! * **3D raster**: the array of voxels ([`raster`]). The stepper reads only
//!   its *plane*, one byte per voxel ([`raster::cell`]).
//! * **discrete ray**: a 3D discrete line between the ray's two endpoints
//!   on the raster box ([`discrete_ray`]).
//! * **6- / 26-connected**: consecutive voxels share a face / share at least
//!   a corner ([`Connectivity`]).
//! * **proximity flag**: marks voxels near a surface so that adaptive rays
//!   take 6-steps there ([`proximity`]).
//! * **tunnel-free**: a voxelized surface no discrete ray of a given
//!   connectivity passes through.
//! * **hit**: where the discrete ray meets a non-transparent voxel;
//!   *intersection* is the continuous ray meeting the continuous object, which
//!   *intersection verification* checks through the *object table*.
//!
//! ## Fixed point
//! Raster coordinates are integers with [`fixed::FRAC_BITS`] fractional bits
//! per voxel; voxel `i` spans `[i, i + 1)` voxel units on each axis (the
//! corner convention).

#![no_std]
#![cfg_attr(
    not(test),
    deny(
        clippy::unwrap_used,
        clippy::expect_used,
        clippy::panic,
        clippy::unreachable,
        clippy::todo,
        clippy::unimplemented,
        clippy::arithmetic_side_effects,
        clippy::cast_possible_truncation,
        clippy::cast_possible_wrap,
        clippy::cast_sign_loss
    )
)]

#[cfg(test)]
extern crate std;

#[cfg(any(test, feature = "check"))]
pub mod check;
#[cfg(any(test, feature = "check"))]
pub mod check_packet;
#[cfg(any(test, feature = "check"))]
pub mod check_voxelize;
pub mod connectivity;
pub mod csg;
pub mod discrete_ray;
pub mod error;
pub mod fixed;
pub mod geometry;
pub mod light;
pub mod object_table;
pub mod packet;
pub mod proximity;
pub mod raster;
pub mod rng;
pub mod store;
#[cfg(test)]
mod testkit;
pub mod voxel;
pub mod voxelize;

pub use connectivity::Connectivity;
pub use discrete_ray::{DiscreteRay, Face, Hit, WalkEnd};
pub use error::{RasterError, RayError};
pub use raster::{Extent, Raster, RasterMut};
