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
    /// `self < other`, exactly (products < 2^81, or < 2^62 in a
    /// [`narrow`] setup).
    fn lt<W: Wide>(self, other: Self) -> bool {
        W::of(self.n).mul(W::of(other.d)) < W::of(other.n).mul(W::of(self.d))
    }
}

/// The integer type the setup's products are formed in: `i128` in
/// general, `i64` when the ray and the raster are small enough that every
/// comparison's products are below 2^62 ([`narrow`]). Both give the same
/// ray: the quantities compared are exact in either, and the ones only
/// stored (a decision term, an endpoint's position times a denominator) are
/// known to fit `i64`, so a wrapping `i64` computation of them is exact.
trait Wide: Copy + Ord {
    fn of(v: i64) -> Self;
    fn mul(self, o: Self) -> Self;
    fn add(self, o: Self) -> Self;
    fn sub(self, o: Self) -> Self;
    fn to_i64(self) -> Result<i64, RayError>;
    /// `floor(self / d)` for `d > 0`.
    fn floor_div(self, d: i64) -> Result<Self, RayError>;
}

impl Wide for i64 {
    fn of(v: i64) -> Self {
        v
    }
    fn mul(self, o: Self) -> Self {
        self.wrapping_mul(o)
    }
    fn add(self, o: Self) -> Self {
        self.wrapping_add(o)
    }
    fn sub(self, o: Self) -> Self {
        self.wrapping_sub(o)
    }
    fn to_i64(self) -> Result<i64, RayError> {
        Ok(self)
    }
    fn floor_div(self, d: i64) -> Result<Self, RayError> {
        self.checked_div_euclid(d).ok_or(RayError::Arithmetic)
    }
}

impl Wide for i128 {
    fn of(v: i64) -> Self {
        i128::from(v)
    }
    fn mul(self, o: Self) -> Self {
        self.wrapping_mul(o)
    }
    fn add(self, o: Self) -> Self {
        self.wrapping_add(o)
    }
    fn sub(self, o: Self) -> Self {
        self.wrapping_sub(o)
    }
    fn to_i64(self) -> Result<i64, RayError> {
        i64::try_from(self).map_err(|_| RayError::Arithmetic)
    }
    /// In 64 bits when `self` fits.
    fn floor_div(self, d: i64) -> Result<Self, RayError> {
        match i64::try_from(self) {
            Ok(x64) => x64.checked_div_euclid(d).map(i128::from),
            Err(_) => self.checked_div_euclid(i128::from(d)),
        }
        .ok_or(RayError::Arithmetic)
    }
}

/// Whether the `i64` setup is exact for this ray: every `|O_k| < 2^30`
/// and every raster side `≤ 2^30` fixed units (16384 voxels). Then every
/// crossing numerator is below 2^31 and `|D| ≤ 2^31`, so the comparisons'
/// products are below 2^62; an endpoint lies within a voxel of the box, so
/// its position times a denominator is below 2^62; and the decision terms
/// are below 2^49 (module notes).
fn narrow(origin: [i64; 3], size: [i64; 3]) -> bool {
    const LIM: i64 = 1 << 30;
    origin.iter().all(|o| o.unsigned_abs() < LIM.unsigned_abs()) && size.iter().all(|&s| s <= LIM)
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
    if narrow(origin, size) {
        setup_in::<i64>(extent, origin, dir, segment, n, size)
    } else {
        setup_in::<i128>(extent, origin, dir, segment, n, size)
    }
}

/// [`setup`] with its products formed in `W` (see [`Wide`]).
#[inline(always)]
fn setup_in<W: Wide>(
    extent: Extent,
    origin: [i64; 3],
    dir: [i32; 3],
    segment: bool,
    n: [u32; 3],
    size: [i64; 3],
) -> Result<Option<DiscreteRay>, RayError> {
    let Some((t_in, t_out)) = clip::<W>(origin, dir, segment, size) else {
        return Ok(None);
    };
    let Ends {
        entry,
        exit,
        rem,
        dist,
    } = ends::<W>(origin, dir, n, t_in, t_out)?;

    let ad = dir.map(|v| i64::from(v.unsigned_abs()));
    let (a, b, c) = drive_frame(ad);
    // before(j, k) of the module notes: positive exactly when axis k crosses
    // before axis j, ties going to the lower axis index.
    let before = |j: usize, k: usize| -> Result<i64, RayError> {
        let raw = W::of(dist[j])
            .mul(W::of(ad[k]))
            .sub(W::of(dist[k]).mul(W::of(ad[j])));
        raw.mul(W::of(2))
            .add(W::of(if j < k { -1 } else { 1 }))
            .to_i64()
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
            entry_face: t_in
                .face
                .map(|k| Face::entered(k, dir.get(k).is_some_and(|&d| d > 0))),
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

/// Clips the ray to the raster box: `t_in = max(0, near crossings)`,
/// `t_out = min(t_max, far crossings)` (`None` for a half-line parallel to
/// every face it could leave through, which only a zero direction is).
/// `None` when the clipped ray is empty or a single point.
#[inline(always)]
fn clip<W: Wide>(
    origin: [i64; 3],
    dir: [i32; 3],
    segment: bool,
    size: [i64; 3],
) -> Option<(End, Option<End>)> {
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
                return None;
            }
            continue;
        }
        let (near, far) = if dir[k] > 0 { (0, sz) } else { (sz, 0) };
        let sign = i64::from(dir[k].signum());
        let d = i64::from(dir[k].unsigned_abs());
        let tn = Param {
            n: near.wrapping_sub(o).wrapping_mul(sign),
            d,
        };
        let tf = Param {
            n: far.wrapping_sub(o).wrapping_mul(sign),
            d,
        };
        // `>=`: on a tie the later axis wins, matching the x-before-y-before-z
        // order of simultaneous crossings (the last crossing names the face).
        if !tn.lt::<W>(t_in.t) {
            t_in = End {
                t: tn,
                face: Some(k),
            };
        }
        if t_out.is_none_or(|e| tf.lt::<W>(e.t)) {
            t_out = Some(End {
                t: tf,
                face: Some(k),
            });
        }
    }
    if let Some(e) = t_out
        && !t_in.t.lt::<W>(e.t)
    {
        return None; // empty or single-point contact
    }
    Some((t_in, t_out))
}

/// The clipped ray's voxels and counters, per real axis.
struct Ends {
    /// The voxel holding the ray just after its entry point.
    entry: [u32; 3],
    /// The voxel holding the ray just before its exit point.
    exit: [u32; 3],
    /// Boundary crossings between them.
    rem: [u32; 3],
    /// Distance (times 1) from the origin to the entry voxel's next
    /// boundary along the ray, `t_k·|D_k|`; a positive stand-in (`S`) on
    /// axes the ray does not move along.
    dist: [i64; 3],
}

/// The entry and exit voxels, crossing counts and next-boundary distances
/// of the ray clipped to `[t_in, t_out]`.
///
/// # Errors
/// [`RayError::Arithmetic`] if an endpoint falls outside the raster or the
/// ray would move against its direction: impossible for a ray inside the
/// accepted range, and refused rather than stepped.
#[inline(always)]
fn ends<W: Wide>(
    origin: [i64; 3],
    dir: [i32; 3],
    n: [u32; 3],
    t_in: End,
    t_out: Option<End>,
) -> Result<Ends, RayError> {
    let mut entry = [0u32; 3];
    let mut exit = [0u32; 3];
    let mut rem = [0u32; 3];
    let mut dist = [S; 3];
    for k in 0..3 {
        let vi = voxel_at::<W>(origin, dir, n, t_in, k, false)?;
        let vo = match t_out {
            Some(e) => voxel_at::<W>(origin, dir, n, e, k, true)?,
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
        // Still axes keep the positive stand-in (|D| = 0 makes t = ∞).
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
    Ok(Ends {
        entry,
        exit,
        rem,
        dist,
    })
}

/// Axis `k` of the voxel holding the ray on `(t, t + ε)` (entering) or
/// `(t − ε, t)` (`leaving`) at endpoint `end`: a point on a face belongs to
/// the voxel the ray is on that side of it. No division when the endpoint
/// is the origin, a segment end, or on this axis's face.
#[inline(always)]
fn voxel_at<W: Wide>(
    origin: [i64; 3],
    dir: [i32; 3],
    n: [u32; 3],
    end: End,
    k: usize,
    leaving: bool,
) -> Result<i64, RayError> {
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
    let x = W::of(o)
        .mul(W::of(t.d))
        .add(W::of(t.n).mul(W::of(i64::from(d))));
    let x = if below { x.sub(W::of(1)) } else { x };
    Ok(x.floor_div(t.d)?.to_i64()? >> FRAC_BITS)
}

/// The drive frame `(a, b, c)`: the driving axis a (largest `|D|`, lowest
/// index on ties) and the minor axes `b < c`.
#[inline(always)]
const fn drive_frame(ad: [i64; 3]) -> (usize, usize, usize) {
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
    (a, b, c)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testkit::Rng;

    /// The `i64` setup gives the very ray the `i128` setup gives, on
    /// random rays within its domain: rays from far outside, from inside,
    /// grazing faces, axis-parallel, and segments.
    #[test]
    fn narrow_setup_is_the_wide_setup() {
        let mut rng = Rng(0x2545_f491_4f6c_dd1d);
        let mut next = move || rng.next_u64();
        let mut compared = 0u32;
        let mut some = 0u32;
        for _ in 0..200_000 {
            let r = next();
            let dims = [
                1 + (r % 300) as u32,
                1 + ((r >> 9) % 300) as u32,
                1 + ((r >> 18) % 300) as u32,
            ];
            let Ok(extent) = Extent::new(dims[0], dims[1], dims[2]) else {
                continue;
            };
            let size = dims.map(|v| i64::from(v) << FRAC_BITS);
            let pick = next();
            let origin: [i64; 3] = core::array::from_fn(|k| {
                let v = next();
                match (pick >> (2 * k)) & 3 {
                    // Anywhere in the narrow range.
                    0 => (v % (1 << 31)) as i64 - (1 << 30),
                    // On a voxel boundary near the box.
                    1 => ((v % 700) as i64 - 200) << FRAC_BITS,
                    // Inside the box.
                    _ => (v % size[k].unsigned_abs()) as i64,
                }
            });
            let dir: [i32; 3] = core::array::from_fn(|k| {
                let v = next();
                match (pick >> (6 + 2 * k)) & 3 {
                    0 => 0,
                    1 => (v as i32) >> (v % 31),
                    _ => v as i32,
                }
            });
            let segment = pick & (1 << 12) != 0;
            if !narrow(origin, size) {
                continue;
            }
            if segment
                && origin
                    .iter()
                    .zip(dir.iter())
                    .any(|(o, d)| (o + i64::from(*d)).unsigned_abs() >= 1 << 30)
            {
                continue;
            }
            let a = setup_in::<i64>(extent, origin, dir, segment, dims, size);
            let b = setup_in::<i128>(extent, origin, dir, segment, dims, size);
            assert_eq!(a, b, "{dims:?} {origin:?} {dir:?} {segment}");
            compared += 1;
            if matches!(a, Ok(Some(_))) {
                some += 1;
            }
        }
        assert!(compared > 100_000 && some > 20_000, "{compared} {some}");
    }
}
