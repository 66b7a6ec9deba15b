//! Per-ray setup: exact integer clipping against the raster box, the entry
//! and exit voxels, the driving axis, the decision terms and the index
//! offsets. Everything here is computed once per ray.
//
// Implementation notes (not part of the rustdoc contract).
//
// The ray is P(t) = O + t·D for t in [0, t_max] (t_max = ∞ for a half-line,
// 1 for a segment), with O in fixed units (i64) and D in fixed units per
// unit t (i32). All crossing parameters are rationals num/den with den > 0.
// Bounds: |O| ≤ 2^47, |D| ≤ 2^31, box faces ≤ 2^32, so every numerator
// below is < 2^49 and every cross product < 2^81: i128 never overflows for
// accepted input. The checked operations still return an error instead of
// panicking, so the claim costs nothing if it were ever wrong.
//
// Decision terms. For each axis k let t_k be the parameter of the next
// voxel-boundary crossing on k (∞ when D_k = 0). For an ordered pair of
// axes (j, k):
//
//     before(j, k) = 2·(t_j − t_k)·|D_j|·|D_k| + (j < k ? −1 : +1)
//
// is positive exactly when axis k crosses before axis j, ties going to the
// lower axis index. It is an integer (t_j·|D_j| is the distance to the next
// boundary), never zero, and bounded by 2·S·max|D| + 1 < 2^49 because both
// next crossings lie within one voxel-crossing time of the current position.
// Crossing axis j adds S/|D_j| to t_j, i.e. adds 2·S·|D_k| to before(j, k)
// and subtracts 2·S·|D_k| from before(k, j).

use super::{Face, ORIGIN_LIMIT};
use crate::error::RayError;
use crate::fixed::{FRAC_BITS, VOXEL};
use crate::raster::Extent;

/// A non-negative rational `n / d` with `d > 0` (a ray parameter).
#[derive(Clone, Copy, Debug)]
struct Rat {
    n: i128,
    d: i128,
}

impl Rat {
    const ZERO: Self = Self { n: 0, d: 1 };
    const ONE: Self = Self { n: 1, d: 1 };

    /// `self < other`.
    fn lt(self, other: Self) -> Result<bool, RayError> {
        Ok(mul(self.n, other.d)? < mul(other.n, self.d)?)
    }
}

fn mul(a: i128, b: i128) -> Result<i128, RayError> {
    a.checked_mul(b).ok_or(RayError::Arithmetic)
}
fn add(a: i128, b: i128) -> Result<i128, RayError> {
    a.checked_add(b).ok_or(RayError::Arithmetic)
}
fn sub(a: i128, b: i128) -> Result<i128, RayError> {
    a.checked_sub(b).ok_or(RayError::Arithmetic)
}
fn floor_div(a: i128, b: i128) -> Result<i128, RayError> {
    a.checked_div_euclid(b).ok_or(RayError::Arithmetic)
}

/// Constants of one discrete ray, in the *drive frame*: frame axis 0 is the
/// driving axis `a` (largest `|D|`, lowest index on ties), frame axes 1 and 2
/// are the two minor axes `b < c` in increasing index order.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Params {
    pub(crate) extent: Extent,
    pub(crate) origin: [i64; 3],
    pub(crate) dir: [i32; 3],
    /// `perm[f]` is the real axis (0 = x) of frame axis `f`.
    pub(crate) perm: [u8; 3],
    /// Index offset of one step along each frame axis, as a wrapping
    /// two's-complement `usize` (0 on axes the ray does not move along).
    pub(crate) off: [usize; 3],
    /// `off[0] + {0, off[1], off[2], off[1] + off[2]}`: the four 26-steps.
    pub(crate) diag: [usize; 4],
    /// `2·S·|D|` per frame axis: the decision-term increments.
    pub(crate) inc: [i64; 3],
    /// 26-step thresholds: minor axis b (c) crosses no later than the
    /// driving axis iff `e1 > thr[0]` (`e2 > thr[1]`). The threshold is −2
    /// when the minor axis has the higher index (its tie bias is −1) and 0
    /// otherwise, so exact ties are taken with the driving step.
    pub(crate) thr: [i64; 2],
    /// Face of the raster box the ray entered through (`None` when it starts
    /// strictly inside the box).
    pub(crate) entry_face: Option<Face>,
    /// Voxel holding the ray just after its entry point.
    pub(crate) entry: [u32; 3],
    /// Voxel holding the ray just before its exit point.
    pub(crate) exit: [u32; 3],
}

/// The initial stepping state at the entry voxel.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Start {
    pub(crate) index: usize,
    /// `[before(a, b), before(a, c), before(b, c)]`.
    pub(crate) err: [i64; 3],
    /// Boundary crossings left before the exit, per frame axis.
    pub(crate) rem: [u32; 3],
}

/// Sets up the discrete ray `O + t·D`, `t ∈ [0, t_max]`, in `extent`.
/// `Ok(None)` when the ray passes through no voxel of the raster.
pub(crate) fn setup(
    extent: Extent,
    origin: [i64; 3],
    dir: [i32; 3],
    segment: bool,
) -> Result<Option<(Params, Start)>, RayError> {
    for (axis, &o) in (0u8..).zip(origin.iter()) {
        if o.unsigned_abs() > ORIGIN_LIMIT.unsigned_abs() {
            return Err(RayError::OriginOutOfRange { axis });
        }
    }
    let n = extent.dims();
    let size = n.map(|v| i128::from(v) << FRAC_BITS);
    let o = origin.map(i128::from);
    let d = dir.map(i128::from);
    let ad = dir.map(|v| i128::from(v.unsigned_abs()));

    // Clip: t_in = max(0, near crossings), t_out = min(t_max, far crossings).
    let mut t_in = Rat::ZERO;
    let mut entry_axis: Option<usize> = None;
    let mut t_out: Option<Rat> = if segment { Some(Rat::ONE) } else { None };
    for k in 0..3 {
        let (ok, dk, sk, den) = (o[k], d[k], size[k], ad[k]);
        if dk == 0 {
            // Parallel to both faces of this slab: inside iff 0 <= O < size
            // (voxels are half-open, so the top face belongs to no voxel).
            if ok < 0 || ok >= sk {
                return Ok(None);
            }
            continue;
        }
        let (near, far) = if dk > 0 { (0, sk) } else { (sk, 0) };
        let sign = dk.signum();
        let tn = Rat {
            n: mul(sub(near, ok)?, sign)?,
            d: den,
        };
        let tf = Rat {
            n: mul(sub(far, ok)?, sign)?,
            d: den,
        };
        // `>=`: on a tie the later axis wins, matching the x-before-y-before-z
        // order of simultaneous crossings (the last crossing names the face).
        if !tn.lt(t_in)? {
            t_in = tn;
            entry_axis = Some(k);
        }
        let closer = match t_out {
            None => true,
            Some(t) => tf.lt(t)?,
        };
        if closer {
            t_out = Some(tf);
        }
    }
    if let Some(t) = t_out
        && !t_in.lt(t)?
    {
        return Ok(None); // empty or single-point contact
    }

    // Voxel of the ray on (t_in, t_in + ε) and on (t_out − ε, t_out): for a
    // rising coordinate a point on a face belongs to the voxel above it on
    // entry and below it on exit; for a falling one the other way round.
    let voxel_at = |t: Rat, k: usize, leaving: bool| -> Result<i128, RayError> {
        if d[k] == 0 {
            return floor_div(o[k], i128::from(VOXEL));
        }
        let x = add(mul(o[k], t.d)?, mul(t.n, d[k])?)?;
        let den = mul(t.d, i128::from(VOXEL))?;
        // floor(X/den) or ceil(X/den) − 1 = floor((X − 1)/den).
        let lower_side = (d[k] > 0) == leaving;
        floor_div(if lower_side { sub(x, 1)? } else { x }, den)
    };
    let mut entry = [0u32; 3];
    let mut exit = [0u32; 3];
    let mut rem = [0u32; 3];
    for k in 0..3 {
        let vi = voxel_at(t_in, k, false)?;
        let vo = match t_out {
            Some(t) => voxel_at(t, k, true)?,
            None => vi, // only when D = 0: the ray never moves
        };
        let lim = i128::from(n[k]);
        if !(0..lim).contains(&vi) || !(0..lim).contains(&vo) {
            return Err(RayError::Arithmetic);
        }
        let moves = sub(vo, vi)?;
        if moves != 0 && moves.signum() != d[k].signum() {
            return Err(RayError::Arithmetic);
        }
        entry[k] = u32::try_from(vi).map_err(|_| RayError::Arithmetic)?;
        exit[k] = u32::try_from(vo).map_err(|_| RayError::Arithmetic)?;
        rem[k] = u32::try_from(moves.unsigned_abs()).map_err(|_| RayError::Arithmetic)?;
    }

    // Distance (times |D|) to the next boundary: dist_k = t_k·|D_k|, with a
    // positive stand-in on still axes (their |D| = 0 makes t_k = ∞ below).
    let mut dist = [i128::from(VOXEL); 3];
    for k in 0..3 {
        if d[k] != 0 {
            let v = i128::from(entry[k]);
            let boundary = if d[k] > 0 { add(v, 1)? } else { v };
            let b = boundary << FRAC_BITS;
            dist[k] = mul(sub(b, o[k])?, d[k].signum())?;
            if dist[k] <= 0 {
                return Err(RayError::Arithmetic);
            }
        }
    }
    let at = |v: &[i128; 3], k: usize| v.get(k).copied().ok_or(RayError::Arithmetic);
    let before = |j: usize, k: usize| -> Result<i64, RayError> {
        let raw = sub(
            mul(at(&dist, j)?, at(&ad, k)?)?,
            mul(at(&dist, k)?, at(&ad, j)?)?,
        )?;
        let v = add(mul(raw, 2)?, if j < k { -1 } else { 1 })?;
        i64::try_from(v).map_err(|_| RayError::Arithmetic)
    };

    // Drive frame.
    let a = if ad[1] > ad[0] {
        if ad[2] > ad[1] { 2 } else { 1 }
    } else if ad[2] > ad[0] {
        2
    } else {
        0
    };
    let (b, c) = match a {
        0 => (1, 2),
        1 => (0, 2),
        _ => (0, 1),
    };
    let frame = [a, b, c];
    let strides = extent.strides();
    let off = frame.map(|k| {
        let stride = strides.get(k).copied().unwrap_or(0);
        match dir.get(k).copied().unwrap_or(0) {
            0 => 0,
            v if v > 0 => stride,
            _ => stride.wrapping_neg(),
        }
    });
    let diag = [
        off[0],
        off[0].wrapping_add(off[1]),
        off[0].wrapping_add(off[2]),
        off[0].wrapping_add(off[1]).wrapping_add(off[2]),
    ];
    let mut inc = [0i64; 3];
    for (slot, &k) in inc.iter_mut().zip(frame.iter()) {
        let v = mul(mul(at(&ad, k)?, i128::from(VOXEL))?, 2)?;
        *slot = i64::try_from(v).map_err(|_| RayError::Arithmetic)?;
    }
    let err = [before(a, b)?, before(a, c)?, before(b, c)?];
    let thr = [if a < b { -2 } else { 0 }, if a < c { -2 } else { 0 }];
    let index = extent.index(entry).ok_or(RayError::Arithmetic)?;
    let entry_face = entry_axis.map(|k| Face::entered(k, dir.get(k).is_some_and(|&v| v > 0)));
    let perm = frame.map(|k| {
        if k == 0 {
            0
        } else if k == 1 {
            1
        } else {
            2
        }
    });

    Ok(Some((
        Params {
            extent,
            origin,
            dir,
            perm,
            off,
            diag,
            inc,
            thr,
            entry_face,
            entry,
            exit,
        },
        Start {
            index,
            err,
            rem: [rem[a], rem[b], rem[c]],
        },
    )))
}
