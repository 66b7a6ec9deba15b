//! Computed datasets: scalar fields sampled from a formula into the same
//! [`Volume`] as a scan, so they classify, place and voxelize alike (the
//! paper's "computed datasets (e.g. fluid dynamics simulations)").
//!
//! [`Metaballs`] is Blinn's blobby model with the Wyvill soft-object
//! falloff: each ball adds `strength · (1 − r²/R²)³` inside its radius
//! `R`, so touching balls melt into one smooth surface at an iso-value
//! below the strengths.
//!
//! ```
//! use glam::DVec3;
//! use rrt_host::assets::volume::computed::{Metaball, Metaballs, sample};
//! use rrt_host::assets::volume::{Classifier, Grid, Limits};
//! let blobs = Metaballs(vec![
//!     Metaball { centre: DVec3::new(-0.4, 0.0, 0.0), radius: 1.0, strength: 1.0 },
//!     Metaball { centre: DVec3::new(0.4, 0.0, 0.0), radius: 1.0, strength: 1.0 },
//! ]);
//! let grid = Grid::axis_aligned([0.05; 3], DVec3::splat(-1.5));
//! let v = sample(&blobs, [61; 3], grid, &Limits::default()).unwrap();
//! // Midway between the balls the two falloffs add up.
//! assert!((v.sample_physical(DVec3::ZERO).unwrap() - 2.0 * 0.84f64.powi(3)).abs() < 1e-6);
//! assert!(Classifier::iso(0.5).count(&v) > 0);
//! ```

use glam::DVec3;
use rayon::prelude::*;

use super::{Grid, Limits, SampleType, Samples, Volume, VolumeError};

/// A scalar field defined everywhere in physical space.
pub trait Field: Sync {
    /// The value at `p`.
    fn value(&self, p: DVec3) -> f64;
}

impl<F: Fn(DVec3) -> f64 + Sync> Field for F {
    fn value(&self, p: DVec3) -> f64 {
        self(p)
    }
}

/// One soft ball.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Metaball {
    /// Centre.
    pub centre: DVec3,
    /// Radius of influence (the field is 0 beyond it).
    pub radius: f64,
    /// Value at the centre.
    pub strength: f64,
}

/// A sum of [`Metaball`]s.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct Metaballs(pub Vec<Metaball>);

impl Metaballs {
    /// [`sample`] of these balls: the same volume, value for value, in
    /// time that follows the samples within the balls' radii rather than
    /// the samples times the balls (a sample no ball reaches is 0 without
    /// being visited; on a grid that is not axis-aligned, [`sample`]
    /// itself).
    ///
    /// # Errors
    /// As [`sample`].
    pub fn sample(
        &self,
        dims: [u32; 3],
        grid: Grid,
        limits: &Limits,
    ) -> Result<Volume, VolumeError> {
        if !grid.is_axis_aligned() {
            return sample(self, dims, grid, limits);
        }
        let count = checked_count(dims, &grid, limits)?;
        let [nx, ny, _] = dims.map(|n| n as usize);
        let m = grid.matrix();
        let spacing = grid.spacing();
        // The index range along `axis` outside which a ball's field is 0,
        // one sample wider each side than its radius so that rounding
        // cannot drop a sample it reaches (those outside have q > 1).
        let reach = |b: &Metaball, axis: usize| -> Option<(usize, usize)> {
            let o = grid.origin[axis];
            let lo = ((b.centre[axis] - b.radius - o) / spacing[axis]).floor() - 1.0;
            let hi = ((b.centre[axis] + b.radius - o) / spacing[axis]).ceil() + 1.0;
            let n = f64::from(dims[axis]);
            if !(hi >= 0.0 && lo < n) {
                return None;
            }
            // Both clamped to 0..n, n <= 2^16: exact.
            Some((lo.max(0.0) as usize, hi.min(n - 1.0) as usize))
        };
        let boxes: Vec<Option<[(usize, usize); 3]>> = self
            .0
            .iter()
            .map(|b| Some([reach(b, 0)?, reach(b, 1)?, reach(b, 2)?]))
            .collect();
        let mut values = vec![0f32; count];
        values
            .par_chunks_mut((nx * ny).max(1))
            .enumerate()
            .for_each(|(k, layer)| {
                let here: Vec<(&Metaball, [(usize, usize); 3])> = self
                    .0
                    .iter()
                    .zip(&boxes)
                    .filter_map(|(b, r)| {
                        r.filter(|r| (r[2].0..=r[2].1).contains(&k)).map(|r| (b, r))
                    })
                    .collect();
                if here.is_empty() {
                    return;
                }
                let mut sum = vec![0f64; nx];
                for (j, row) in layer.chunks_mut(nx.max(1)).enumerate() {
                    let mut touched = false;
                    for (b, r) in &here {
                        if !(r[1].0..=r[1].1).contains(&j) {
                            continue;
                        }
                        if !touched {
                            sum.fill(0.0);
                            touched = true;
                        }
                        let (i0, i1) = r[0];
                        for (i, acc) in sum.iter_mut().enumerate().take(i1 + 1).skip(i0) {
                            // As `sample` places it, and as `value` sums it.
                            let p = grid.origin + m * DVec3::new(i as f64, j as f64, k as f64);
                            *acc += b.value_at(p);
                        }
                    }
                    if touched {
                        for (out, &s) in row.iter_mut().zip(&sum) {
                            // Stored as f32, like the scans' float samples.
                            #[allow(clippy::cast_possible_truncation)]
                            let v = s as f32;
                            *out = v;
                        }
                    }
                }
            });
        finite_volume(dims, grid, values)
    }
}

impl Metaball {
    /// This ball's part of the field at `p`.
    fn value_at(&self, p: DVec3) -> f64 {
        let q = (p - self.centre).length_squared() / (self.radius * self.radius);
        if q >= 1.0 {
            0.0
        } else {
            self.strength * (1.0 - q).powi(3)
        }
    }
}

impl Field for Metaballs {
    fn value(&self, p: DVec3) -> f64 {
        self.0.iter().map(|b| b.value_at(p)).sum()
    }
}

/// A "simulated density": the steady-state concentration around point
/// sources in a medium with uniform decay, `Σ qᵢ · exp(−|p − sᵢ| / λ) /
/// (|p − sᵢ| + ε)` (the screened-Poisson Green's function, regularised at
/// the sources by `ε`).
#[derive(Clone, Debug, PartialEq)]
pub struct ScreenedSources {
    /// `(position, strength)` of each source.
    pub sources: Vec<(DVec3, f64)>,
    /// Decay length `λ`.
    pub decay: f64,
    /// Regularisation `ε` (the value at a source is `q / ε`).
    pub epsilon: f64,
}

impl Field for ScreenedSources {
    fn value(&self, p: DVec3) -> f64 {
        self.sources
            .iter()
            .map(|(s, q)| {
                let r = (p - *s).length();
                q * (-r / self.decay).exp() / (r + self.epsilon)
            })
            .sum()
    }
}

/// The sample count of a computed volume of `dims` on `grid`, checked
/// against `limits` before anything is allocated.
fn checked_count(dims: [u32; 3], grid: &Grid, limits: &Limits) -> Result<usize, VolumeError> {
    if dims.iter().any(|&n| n == 0 || n > super::MAX_AXIS) {
        return Err(VolumeError::Invalid {
            what: "computed volume".into(),
            msg: format!("each dimension must be 1 to {}", super::MAX_AXIS),
        });
    }
    grid.validate().map_err(|msg| VolumeError::Invalid {
        what: "computed volume".into(),
        msg,
    })?;
    super::check_size(
        std::path::Path::new("computed volume"),
        String::new(),
        dims,
        SampleType::F32,
        limits,
    )
}

/// Samples `field` at every point of `grid` (`dims` samples per axis) into
/// a `float` volume.
///
/// # Errors
/// [`VolumeError::TooLarge`] beyond `limits` (before allocating);
/// [`VolumeError::Invalid`] for bad dimensions or grid, or a field value
/// that is not finite (named with its sample).
pub fn sample<F: Field + ?Sized>(
    field: &F,
    dims: [u32; 3],
    grid: Grid,
    limits: &Limits,
) -> Result<Volume, VolumeError> {
    let count = checked_count(dims, &grid, limits)?;
    let [nx, ny, _] = dims.map(u64::from);
    let m = grid.matrix();
    let values: Vec<f32> = (0..count)
        .into_par_iter()
        .map(|n| {
            let n = n as u64;
            let idx = DVec3::new(
                (n % nx) as f64,
                ((n / nx) % ny) as f64,
                (n / (nx * ny)) as f64,
            );
            // Stored as f32, like the scans' float samples.
            #[allow(clippy::cast_possible_truncation)]
            let v = field.value(grid.origin + m * idx) as f32;
            v
        })
        .collect();
    finite_volume(dims, grid, values)
}

/// The volume of `values`, refused if one of them is not finite (named
/// with its sample).
fn finite_volume(dims: [u32; 3], grid: Grid, values: Vec<f32>) -> Result<Volume, VolumeError> {
    let [nx, ny, _] = dims.map(u64::from);
    if let Some(bad) = values.iter().position(|v| !v.is_finite()) {
        let n = bad as u64;
        return Err(VolumeError::Invalid {
            what: "computed volume".into(),
            msg: format!(
                "the field is not finite at sample ({}, {}, {})",
                n % nx,
                (n / nx) % ny,
                n / (nx * ny)
            ),
        });
    }
    Volume::new(dims, grid, Samples::F32(values))
}
