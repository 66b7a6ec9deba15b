//! Per-ray setup: exact integer clipping against the raster box, the entry
//! and exit voxels, the driving axis, the decision terms and the index
//! offsets. Everything here is computed once per ray.
//
// Implementation notes (not part of the rustdoc contract).
//
// The ray is P(t) = O + t·D for t in [0, t_max] (t_max = ∞ for a half-line,
// 1 for a segment), with O in fixed units (i64) and D in fixed units per
// unit t (i32). Crossing parameters are rationals num/den with 0 ≤ num,
// 0 < den ≤ 2^31. Bounds: |O| ≤ 2^47, box faces ≤ 2^32 fixed units, so every
// numerator is < 2^49, every cross product < 2^81 and every position times
// a denominator < 2^82: i128 holds them all exactly, and the i128
// operations below cannot wrap (they are wrapping only so that no panic path
// exists). Divisions are needed only for the voxel of an endpoint on an axis
// other than the one whose face the ray crosses there; they are done as
// floor(floor(X / den) / 2^16), in 64 bits when X fits (origins within about
// 2^32 fixed units of the raster), else in 128 bits.
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

use super::{DiscreteRay, Face, ORIGIN_LIMIT, State};
use crate::error::RayError;
use crate::fixed::FRAC_BITS;
use crate::raster::Extent;

/// One voxel edge in fixed units, as i64.
const S: i64 = 1 << FRAC_BITS;

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

/// `n / d`, `d > 0`.
#[derive(Clone, Copy, Debug)]
struct Param {
    n: i64,
    d: i64,
}

impl Param {
    /// `self < other`, exactly (products < 2^81).
    fn lt(self, other: Self) -> bool {
        i128::from(self.n).wrapping_mul(i128::from(other.d))
            < i128::from(other.n).wrapping_mul(i128::from(self.d))
    }
}

/// `floor(x / d)` for `d > 0`, in 64 bits when `x` fits.
fn floor_div(x: i128, d: i64) -> Result<i128, RayError> {
    match i64::try_from(x) {
        Ok(x64) => x64.checked_div_euclid(d).map(i128::from),
        Err(_) => x.checked_div_euclid(i128::from(d)),
    }
    .ok_or(RayError::Arithmetic)
}

/// An endpoint of the clipped ray: its parameter, and the axis whose face
/// the ray crosses there (`None` for the origin inside the box, or for a
/// segment's end inside it).
#[derive(Clone, Copy, Debug)]
struct End {
    t: Param,
    face: Option<usize>,
}

/// Sets up the discrete ray `O + t·D`, `t ∈ [0, t_max]`, in `extent`.
/// `Ok(None)` when the ray passes through no voxel of the raster.
pub(crate) fn setup(
    extent: Extent,
    origin: [i64; 3],
    dir: [i32; 3],
    segment: bool,
) -> Result<Option<DiscreteRay>, RayError> {
    for (axis, &o) in (0u8..).zip(origin.iter()) {
        if o.unsigned_abs() > ORIGIN_LIMIT.unsigned_abs() {
            return Err(RayError::OriginOutOfRange { axis });
        }
    }
    let n = extent.dims();
    let size = n.map(|v| i64::from(v) << FRAC_BITS);
    let ad = dir.map(|v| i64::from(v.unsigned_abs()));

    // Clip: t_in = max(0, near crossings), t_out = min(t_max, far crossings).
    // `near - o` and `far - o` are below 2^48 + 2^32 in magnitude.
    let mut t_in = End {
        t: Param { n: 0, d: 1 },
        face: None,
    };
    let mut t_out: Option<End> = segment.then_some(End {
        t: Param { n: 1, d: 1 },
        face: None,
    });
    for k in 0..3 {
        let (o, sz) = (origin[k], size[k]);
        if dir[k] == 0 {
            // Parallel to both faces of this slab: inside iff 0 <= O < size
            // (voxels are half-open, so the top face belongs to no voxel).
            if o < 0 || o >= sz {
                return Ok(None);
            }
            continue;
        }
        let (near, far) = if dir[k] > 0 { (0, sz) } else { (sz, 0) };
        let sign = i64::from(dir[k].signum());
        let tn = Param {
            n: near.wrapping_sub(o).wrapping_mul(sign),
            d: ad[k],
        };
        let tf = Param {
            n: far.wrapping_sub(o).wrapping_mul(sign),
            d: ad[k],
        };
        // `>=`: on a tie the later axis wins, matching the x-before-y-before-z
        // order of simultaneous crossings (the last crossing names the face).
        if !tn.lt(t_in.t) {
            t_in = End {
                t: tn,
                face: Some(k),
            };
        }
        if t_out.is_none_or(|e| tf.lt(e.t)) {
            t_out = Some(End {
                t: tf,
                face: Some(k),
            });
        }
    }
    if let Some(e) = t_out
        && !t_in.t.lt(e.t)
    {
        return Ok(None); // empty or single-point contact
    }

    // The voxel holding the ray on (t, t + ε) (entering) or (t − ε, t)
    // (leaving): a point on a face belongs to the voxel the ray is on that
    // side of it. Per axis, no division when the endpoint is the origin, a
    // segment end, or on this axis's face.
    let voxel_at = |end: End, k: usize, leaving: bool| -> Result<i64, RayError> {
        let (o, d, nk) = (origin[k], dir[k], i64::from(n[k]));
        if d == 0 {
            return Ok(o >> FRAC_BITS);
        }
        // A point on a boundary belongs to the voxel below it when the ray
        // comes from below and is leaving, or comes from above and is entering.
        let below = (d > 0) == leaving;
        if end.face == Some(k) {
            return Ok(if below { nk.wrapping_sub(1) } else { 0 });
        }
        let t = end.t;
        if t.d == 1 && (t.n == 0 || t.n == 1) {
            // The origin (t = 0) or a segment's end (t = 1): an exact point.
            let p = if t.n == 0 {
                o
            } else {
                o.wrapping_add(i64::from(d))
            };
            return Ok(if below { p.wrapping_sub(1) } else { p } >> FRAC_BITS);
        }
        // P·den = O·den + num·D, exact in i128 (< 2^82).
        let x = i128::from(o)
            .wrapping_mul(i128::from(t.d))
            .wrapping_add(i128::from(t.n).wrapping_mul(i128::from(d)));
        let q = floor_div(if below { x.wrapping_sub(1) } else { x }, t.d)? >> FRAC_BITS;
        i64::try_from(q).map_err(|_| RayError::Arithmetic)
    };

    let mut entry = [0u32; 3];
    let mut exit = [0u32; 3];
    let mut rem = [0u32; 3];
    let mut dist = [S; 3];
    for k in 0..3 {
        let vi = voxel_at(t_in, k, false)?;
        let vo = match t_out {
            Some(e) => voxel_at(e, k, true)?,
            None => vi, // only when D = 0: the ray never moves
        };
        let lim = i64::from(n[k]);
        if !(0..lim).contains(&vi) || !(0..lim).contains(&vo) {
            return Err(RayError::Arithmetic);
        }
        let moves = vo.wrapping_sub(vi);
        if moves != 0 && moves.signum() != i64::from(dir[k].signum()) {
            return Err(RayError::Arithmetic);
        }
        entry[k] = u32::try_from(vi).map_err(|_| RayError::Arithmetic)?;
        exit[k] = u32::try_from(vo).map_err(|_| RayError::Arithmetic)?;
        rem[k] = u32::try_from(moves.unsigned_abs()).map_err(|_| RayError::Arithmetic)?;
        // Distance (times 1) to the next boundary along the ray on this axis:
        // t_k·|D_k|. Still axes keep a positive stand-in (|D| = 0 makes t = ∞).
        if dir[k] != 0 {
            let boundary = (if dir[k] > 0 { vi.wrapping_add(1) } else { vi }) << FRAC_BITS;
            dist[k] = boundary
                .wrapping_sub(origin[k])
                .wrapping_mul(i64::from(dir[k].signum()));
            if dist[k] <= 0 {
                return Err(RayError::Arithmetic);
            }
        }
    }

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
    let before = |j: usize, k: usize| -> Result<i64, RayError> {
        let raw = i128::from(dist[j])
            .wrapping_mul(i128::from(ad[k]))
            .wrapping_sub(i128::from(dist[k]).wrapping_mul(i128::from(ad[j])));
        let v = raw.wrapping_mul(2).wrapping_add(if j < k { -1 } else { 1 });
        i64::try_from(v).map_err(|_| RayError::Arithmetic)
    };
    let strides = extent.strides();
    let step = |k: usize| match dir[k] {
        0 => 0,
        v if v > 0 => strides[k],
        _ => strides[k].wrapping_neg(),
    };
    let off = [step(a), step(b), step(c)];
    let diag = [
        off[0],
        off[0].wrapping_add(off[1]),
        off[0].wrapping_add(off[2]),
        off[0].wrapping_add(off[1]).wrapping_add(off[2]),
    ];
    // 2·S·|D| < 2^48.
    let inc = [
        ad[a] << (FRAC_BITS + 1),
        ad[b] << (FRAC_BITS + 1),
        ad[c] << (FRAC_BITS + 1),
    ];
    let index = extent.index(entry).ok_or(RayError::Arithmetic)?;
    let to_u8 = |k: usize| {
        if k == 0 {
            0
        } else if k == 1 {
            1
        } else {
            2
        }
    };

    Ok(Some(DiscreteRay {
        p: Params {
            extent,
            origin,
            dir,
            perm: [to_u8(a), to_u8(b), to_u8(c)],
            off,
            diag,
            inc,
            thr: [if a < b { -2 } else { 0 }, if a < c { -2 } else { 0 }],
            entry_face: t_in.face.map(|k| Face::entered(k, dir[k] > 0)),
            entry,
            exit,
        },
        s: State {
            index,
            err: [before(a, b)?, before(a, c)?, before(b, c)?],
            rem: [rem[a], rem[b], rem[c]],
            steps: 0,
            last: 0,
            tie: false,
            fresh: true,
            done: false,
        },
    }))
}
