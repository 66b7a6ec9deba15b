//! The voxel record: what the paper stores with every non-transparent voxel.
//!
//! A [`VoxelRecord`] is 20 bytes, `#[repr(C)]`, [`bytemuck::Pod`], with no
//! padding, so a record array can be saved and loaded as plain bytes. It is
//! read only at a hit: the discrete ray itself reads the one-byte plane
//! ([`crate::raster::cell`]), and the record is found through the brick
//! directory of [`crate::store`].
//!
//! ```text
//!  offset  size  field     meaning
//!       0     4  object    object id, or (bit 31 set) the index of the voxel's object list
//!       4     4  normal    octahedral unit normal, two snorm16 (see `encode_normal`)
//!       8     3  color     linear RGB, texture already applied
//!      11     3  illum     ambient + diffuse of the visible lights, linear, saturating
//!      14     2  lights    2 bits per light (LightVisibility), lights 0..8
//!      16     2  material  index into the material table
//!      18     2  key       bits 0..9 position in the 8³ brick, bits 9..16 distance
//! ```
//!
//! # Normals
//! The true surface normal is stored in the *octahedral* encoding (Meyer et
//! al. 2010; Cigolle et al., JCGT 2014): the unit sphere is projected onto
//! the octahedron `|x| + |y| + |z| = 1`, the lower half is folded over the
//! upper one, and the resulting square `[-1, 1]²` is quantized to two
//! signed 16-bit integers (`snorm16`, ±32767). [`encode_normal`] picks, of
//! the four grid points around the exact projection, the one whose decoded
//! direction is nearest the input, all in integer arithmetic.
//!
//! **Angular error.** The angle between a normal and its
//! encoded-then-decoded copy is below 50 µrad (0.003°); it is largest near
//! the diagonals such as `(1, 1, 1)`, where the octahedron is most
//! foreshortened. `voxel::tests::octahedral_error` checks the bound in
//! integer arithmetic (`|a × b| / (|a|·|b|)` with [`isqrt`](u128::isqrt))
//! over 200,000 seeded random directions plus the axes, diagonals and the
//! fold of the octahedron; `tests/voxel_record.rs` checks it in degrees
//! with floats. That is far below the direction error of a normal sampled
//! at a voxel centre.
//!
//! # Key and overlap
//! [`VoxelRecord::key`] holds the voxel's position inside its 8×8×8 brick
//! (`x + 8·y + 64·z` of the low three bits of each coordinate, bits 0..9)
//! and the distance from the voxel centre to the surface that owns it,
//! quantized to 1/128 voxel and saturating at 127 (bits 9..16). Records of a
//! brick are sorted by the position bits; the distance bits decide which of
//! two objects offering the same voxel owns it (the nearer surface).
//!
//! # Owner and object list
//! The record's attributes are its *owner's*: of all objects whose surface
//! passes through the voxel, the one nearest the voxel centre. When only one
//! object offered the voxel (almost every voxel), [`VoxelRecord::object`] is
//! that object's id. When several did, bit 31 ([`OBJECT_LIST`]) is set and
//! the low 31 bits index the store's *object list* array, where the voxel's
//! list `[n, owner, others…]` names all `n ≥ 2` objects, the owner first,
//! the others in increasing id order (see [`crate::store`]). Object ids are
//! therefore below [`MAX_OBJECTS`] `= 2^31`. Read the owner and the list
//! through [`RecordStore::owner`](crate::store::RecordStore::owner) and
//! [`RecordStore::objects`](crate::store::RecordStore::objects), never from
//! the field directly.

use bytemuck::{Pod, Zeroable};

use crate::fixed::FRAC_BITS;
use crate::voxelize::NORMAL_ONE;

/// One non-transparent voxel's attributes (20 bytes, see the module docs).
///
/// ```
/// use rrt_core::voxel::VoxelRecord;
/// assert_eq!(core::mem::size_of::<VoxelRecord>(), 20);
/// let zero: VoxelRecord = bytemuck::Zeroable::zeroed();
/// assert_eq!(bytemuck::bytes_of(&zero), &[0u8; 20]);
/// ```
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Pod, Zeroable)]
pub struct VoxelRecord {
    /// The owner's index into the object table ([`crate::object_table`]),
    /// or, with bit 31 ([`OBJECT_LIST`]) set, the index of the voxel's
    /// object list (see the module docs; read it through
    /// [`RecordStore::owner`](crate::store::RecordStore::owner)).
    pub object: u32,
    /// The unit surface normal at the voxel centre, octahedral snorm16
    /// ([`encode_normal`] / [`decode_normal`]).
    pub normal: [i16; 2],
    /// Linear RGB colour (0 = 0.0, 255 = 1.0), texture already applied.
    pub color: [u8; 3],
    /// Precomputed view-independent illumination, linear RGB, saturating at
    /// 255 = 1.0: ambient plus the diffuse term of every light marked
    /// [`LightVisibility::Visible`] that the normal faces (see
    /// [`crate::light`]).
    pub illum: [u8; 3],
    /// Two bits per light source, light `i` in bits `2i..2i+2`
    /// ([`VoxelRecord::light`]).
    pub lights: u16,
    /// Index into the material table ([`crate::object_table::Materials`]).
    pub material: u16,
    /// Position in the brick (bits 0..9) and quantized surface distance
    /// (bits 9..16); see the module docs.
    pub key: u16,
}

/// Bit of [`VoxelRecord::object`] marking an index into the store's object
/// lists rather than an object id.
pub const OBJECT_LIST: u32 = 1 << 31;

/// Object ids are below this bound (the record's object field keeps bit 31
/// for [`OBJECT_LIST`]).
pub const MAX_OBJECTS: u32 = OBJECT_LIST;

/// Bits of [`VoxelRecord::key`] that hold the position inside the brick.
pub const KEY_POSITION_MASK: u16 = 0x1ff;
/// Shift of the quantized distance inside [`VoxelRecord::key`].
pub const KEY_DISTANCE_SHIFT: u32 = 9;
/// Largest quantized distance (127/128 voxel and beyond).
pub const KEY_DISTANCE_MAX: u16 = 0x7f;
/// Fixed units per step of the quantized distance: 1/128 voxel.
const DISTANCE_STEP_BITS: u32 = FRAC_BITS - 7;

/// Maximum number of lights a record has visibility bits for.
pub const MAX_LIGHTS: usize = 8;

/// What a voxel sees of one light source (2 bits in [`VoxelRecord::lights`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum LightVisibility {
    /// Blocked by an opaque voxel, or the surface faces away from the light;
    /// from the shadow classification, proven blocked by an opaque sphere
    /// at every point of the voxel ([`crate::light`]).
    #[default]
    Occluded = 0,
    /// Nothing between the voxel and the light.
    Visible = 1,
    /// Only translucent material (transmission `T > 0`) in between, or,
    /// from the shadow classification, proven neither lit nor occluded
    /// ([`crate::light::ExactRecords`]): the renderer fires a shadow ray
    /// to decide.
    Translucent = 2,
    /// Not used by this version; read as occluded.
    Reserved = 3,
}

impl LightVisibility {
    /// The value of two bits (only the low two bits of `bits` are read).
    #[must_use]
    pub const fn from_bits(bits: u16) -> Self {
        match bits & 3 {
            0 => Self::Occluded,
            1 => Self::Visible,
            2 => Self::Translucent,
            _ => Self::Reserved,
        }
    }
}

impl VoxelRecord {
    /// The visibility of light `i`; [`LightVisibility::Occluded`] for
    /// `i >= MAX_LIGHTS`.
    ///
    /// ```
    /// use rrt_core::voxel::{LightVisibility, VoxelRecord};
    /// let mut r = VoxelRecord::default();
    /// r.set_light(3, LightVisibility::Translucent);
    /// assert_eq!(r.light(3), LightVisibility::Translucent);
    /// assert_eq!(r.light(2), LightVisibility::Occluded);
    /// assert_eq!(r.lights, 2 << 6);
    /// ```
    #[must_use]
    pub fn light(&self, i: usize) -> LightVisibility {
        match light_shift(i) {
            Some(s) => LightVisibility::from_bits(self.lights >> s),
            None => LightVisibility::Occluded,
        }
    }

    /// Sets the visibility of light `i`; does nothing for `i >= MAX_LIGHTS`.
    pub fn set_light(&mut self, i: usize, v: LightVisibility) {
        if let Some(s) = light_shift(i) {
            self.lights = (self.lights & !(3u16 << s)) | ((v as u16) << s);
        }
    }

    /// Position of the voxel inside its 8×8×8 brick, `x + 8·y + 64·z` of the
    /// coordinates' low three bits.
    #[must_use]
    pub const fn position(&self) -> u16 {
        self.key & KEY_POSITION_MASK
    }

    /// The quantized surface distance, in 1/128 voxel (saturated at 127).
    #[must_use]
    pub const fn distance(&self) -> u16 {
        self.key >> KEY_DISTANCE_SHIFT
    }

    /// The decoded unit normal, scaled by [`NORMAL_ONE`].
    #[must_use]
    pub fn normal_vector(&self) -> [i32; 3] {
        decode_normal(self.normal)
    }
}

fn light_shift(i: usize) -> Option<u32> {
    if i < MAX_LIGHTS {
        // i < 8: 2·i < 16 fits u32 and the shift stays inside u16.
        u32::try_from(i).ok().map(|i| i.wrapping_mul(2))
    } else {
        None
    }
}

/// Position of voxel `v` inside its 8×8×8 brick (the key's low 9 bits).
///
/// ```
/// use rrt_core::voxel::brick_position;
/// assert_eq!(brick_position([9, 2, 17]), 1 + 8 * 2 + 64 * 1);
/// ```
#[must_use]
pub const fn brick_position(v: [u32; 3]) -> u16 {
    // Each term is masked to 3 bits: the value is below 512 and fits u16.
    #[allow(clippy::cast_possible_truncation)]
    let p = ((v[0] & 7) | ((v[1] & 7) << 3) | ((v[2] & 7) << 6)) as u16;
    p
}

/// Quantizes a surface distance (fixed units) to the key's 7 bits:
/// 1/128 voxel per step, rounded to nearest, saturating at 127.
///
/// ```
/// use rrt_core::fixed::VOXEL;
/// use rrt_core::voxel::quantize_distance;
/// assert_eq!(quantize_distance(0), 0);
/// assert_eq!(quantize_distance((VOXEL / 2) as u32), 64);
/// assert_eq!(quantize_distance(u32::MAX), 127);
/// ```
#[must_use]
pub const fn quantize_distance(distance: u32) -> u16 {
    let q = distance.saturating_add(1 << (DISTANCE_STEP_BITS - 1)) >> DISTANCE_STEP_BITS;
    if q > KEY_DISTANCE_MAX as u32 {
        KEY_DISTANCE_MAX
    } else {
        // q <= 127 fits u16.
        #[allow(clippy::cast_possible_truncation)]
        let q = q as u16;
        q
    }
}

/// A record key from a voxel's coordinates and its surface distance.
///
/// ```
/// use rrt_core::voxel::{make_key, KEY_POSITION_MASK};
/// let k = make_key([1, 0, 0], 0);
/// assert_eq!(k & KEY_POSITION_MASK, 1);
/// ```
#[must_use]
pub const fn make_key(v: [u32; 3], distance: u32) -> u16 {
    brick_position(v) | (quantize_distance(distance) << KEY_DISTANCE_SHIFT)
}

/// The largest snorm16 value: ±1.0 on the octahedral square.
pub const SNORM16_ONE: i32 = 32767;

/// Octahedral projection of the direction `n` (any non-zero vector; only
/// its direction matters), unquantized: returns `(u, v)` scaled by `scale`
/// as the exact rationals `num / den`, `den > 0`.
fn project(n: [i64; 3]) -> ([i128; 2], i128) {
    let [x, y, z] = n.map(i128::from);
    // |components| <= 2^47 (callers pass i32 or small values): no overflow.
    let l1 = x
        .saturating_abs()
        .saturating_add(y.saturating_abs())
        .saturating_add(z.saturating_abs());
    if z >= 0 {
        ([x, y], l1)
    } else {
        let sx = if x < 0 { -1 } else { 1 };
        let sy = if y < 0 { -1 } else { 1 };
        (
            [
                l1.saturating_sub(y.saturating_abs()).saturating_mul(sx),
                l1.saturating_sub(x.saturating_abs()).saturating_mul(sy),
            ],
            l1,
        )
    }
}

/// The unnormalized direction of an octahedral pair, components in
/// `[-32767, 32767]` (`|x| + |y| + |z| = 32767`): what [`decode_normal`]
/// normalizes. Hosts that normalize in floating point start from this.
///
/// ```
/// use rrt_core::voxel::{encode_normal, unfold};
/// use rrt_core::voxelize::NORMAL_ONE;
/// assert_eq!(unfold(encode_normal([0, 0, -NORMAL_ONE])), [0, 0, -32767]);
/// ```
#[must_use]
pub fn unfold(e: [i16; 2]) -> [i64; 3] {
    let one = i64::from(SNORM16_ONE);
    let c = |v: i16| i64::from(v).clamp(one.wrapping_neg(), one);
    let (u, v) = (c(e[0]), c(e[1]));
    // |u|, |v| <= 32767: no overflow in i64.
    let z = one.wrapping_sub(u.abs()).wrapping_sub(v.abs());
    if z >= 0 {
        [u, v, z]
    } else {
        let su = if u < 0 { -1 } else { 1 };
        let sv = if v < 0 { -1 } else { 1 };
        [
            one.wrapping_sub(v.abs()).wrapping_mul(su),
            one.wrapping_sub(u.abs()).wrapping_mul(sv),
            z,
        ]
    }
}

/// Encodes a direction as an octahedral snorm16 pair.
///
/// `n` need not be normalized (a [`NORMAL_ONE`]-scaled unit vector is the
/// usual input); the zero vector encodes as `+z`. Of the four grid points
/// around the exact projection the one whose direction is nearest `n` is
/// chosen, which keeps the angular error below 50 µrad (module docs).
///
/// ```
/// use rrt_core::voxel::{decode_normal, encode_normal};
/// use rrt_core::voxelize::NORMAL_ONE;
/// assert_eq!(encode_normal([0, 0, NORMAL_ONE]), [0, 0]);
/// assert_eq!(encode_normal([NORMAL_ONE, 0, 0]), [32767, 0]);
/// assert_eq!(decode_normal(encode_normal([0, -NORMAL_ONE, 0])), [0, -NORMAL_ONE, 0]);
/// ```
#[must_use]
pub fn encode_normal(n: [i32; 3]) -> [i16; 2] {
    let n = n.map(i64::from);
    if n == [0, 0, 0] {
        return [0, 0];
    }
    let (p, den) = project(n);
    let one = i128::from(SNORM16_ONE);
    // Floor of p·32767/den per axis; |p| <= den so the result is in ±32767.
    // For i32 inputs both sides fit in 64 bits (|p|·32767 < 2^49): the
    // 64-bit division gives the same floor.
    let den = den.max(1);
    let fl = p.map(|pi| {
        let num = pi.saturating_mul(one);
        match (i64::try_from(num), i64::try_from(den)) {
            (Ok(a), Ok(b)) => a.checked_div_euclid(b).map_or(0, i128::from),
            _ => num.div_euclid(den),
        }
    });
    let n = to_31_bits(n);
    let mut best = [0i16; 2];
    let mut best_score: Option<(u128, u128)> = None;
    for du in 0..2i128 {
        for dv in 0..2i128 {
            let cand = [
                clamp_snorm(fl[0].saturating_add(du)),
                clamp_snorm(fl[1].saturating_add(dv)),
            ];
            let d = unfold(cand);
            let score = cos2_score(n, d);
            let better = match (score, best_score) {
                (Some(_), None) => true,
                // a = (dot², |d|²): compare dot_a²/|d_a|² > dot_b²/|d_b|².
                // dot² < 2^96 and |d|² < 2^31 (cos2_score): the products
                // stay below 2^127 and never wrap.
                (Some((na, da)), Some((nb, db))) => na.wrapping_mul(db) > nb.wrapping_mul(da),
                (None, _) => false,
            };
            if better {
                best = cand;
                best_score = score;
            }
        }
    }
    best
}

fn clamp_snorm(v: i128) -> i16 {
    let one = i128::from(SNORM16_ONE);
    let c = v.clamp(one.wrapping_neg(), one);
    i16::try_from(c).unwrap_or(0)
}

/// `n` scaled down (arithmetic shift) so that every `|n_i| < 2^31`.
fn to_31_bits(n: [i64; 3]) -> [i64; 3] {
    let m = n.iter().map(|v| v.unsigned_abs()).max().unwrap_or(0);
    let shift = (64u32.saturating_sub(m.leading_zeros())).saturating_sub(31);
    n.map(|v| v >> shift)
}

/// `(dot², |d|²)` for `dot = n·d > 0`, else `None`, for `n` scaled by
/// [`to_31_bits`], so that `dot² · |d|²` fits in u128.
fn cos2_score(n: [i64; 3], d: [i64; 3]) -> Option<(u128, u128)> {
    // |n_i| < 2^31, |d_i| <= 2^15: each product < 2^46, the sum < 2^48.
    let dot: i64 = n
        .iter()
        .zip(d.iter())
        .map(|(a, b)| a.saturating_mul(*b))
        .fold(0i64, i64::saturating_add);
    if dot <= 0 {
        return None;
    }
    let dot = dot.unsigned_abs();
    let d2: u64 = d
        .iter()
        .map(|v| v.unsigned_abs().saturating_mul(v.unsigned_abs()))
        .fold(0u64, u64::saturating_add);
    // dot < 2^48: dot² < 2^96 (one 64 × 64-bit product); |d|² ≤ 32767² <
    // 2^31: products compared stay below 2^127.
    Some((
        u128::from(dot).wrapping_mul(u128::from(dot)),
        u128::from(d2),
    ))
}

/// Decodes an octahedral snorm16 pair to a unit vector scaled by
/// [`NORMAL_ONE`] (Euclidean length within one unit of `NORMAL_ONE`).
/// Every input decodes (−32768 reads as −32767).
///
/// ```
/// use rrt_core::voxel::decode_normal;
/// use rrt_core::voxelize::NORMAL_ONE;
/// assert_eq!(decode_normal([0, 0]), [0, 0, NORMAL_ONE]);
/// let [x, y, z] = decode_normal([i16::MIN, i16::MAX]).map(i64::from);
/// let len2 = x * x + y * y + z * z;
/// let one = i64::from(NORMAL_ONE);
/// assert!((len2 - one * one).abs() < 4 * one);
/// ```
#[must_use]
pub fn decode_normal(e: [i16; 2]) -> [i32; 3] {
    // unfold gives |x| + |y| + |z| = 32767, so |v|² = L lies in
    // [32767²/3, 32767²] ⊂ [2^28, 2^30): L·2^34 < 2^64, and
    // len = ⌊2^17·|v|⌋ ≥ 2^31 is within 2^-31 of 2^17·|v| relatively.
    // Each component c·2^47/len (c·2^47 < 2^62) is then within 0.25 of
    // c·2^30/|v| before rounding: 64-bit integer work only, where
    // `normalize` needs 128 bits for arbitrary inputs.
    let v = unfold(e);
    let l2 = v
        .iter()
        .map(|c| c.unsigned_abs().saturating_mul(c.unsigned_abs()))
        .fold(0u64, u64::saturating_add);
    let len = crate::voxelize::isqrt_u64(l2.checked_shl(34).unwrap_or(0));
    if len == 0 {
        return [0, 0, NORMAL_ONE];
    }
    v.map(|c| {
        let q = (c.unsigned_abs() << 47)
            .saturating_add(len >> 1)
            .checked_div(len)
            .unwrap_or(0);
        let q = i32::try_from(q).unwrap_or(NORMAL_ONE);
        if c < 0 { q.wrapping_neg() } else { q }
    })
}

/// Normalizes `v` to a unit vector scaled by [`NORMAL_ONE`], in integer
/// arithmetic (the [`isqrt`](u128::isqrt) of the squared length after scaling
/// the largest component to 40 bits). `None` for the zero vector.
///
/// Each component is within one unit (2^-30) of the exact value, and the
/// result's direction is that of `v` up to 2^-39 rad.
///
/// ```
/// use rrt_core::voxel::normalize;
/// use rrt_core::voxelize::NORMAL_ONE;
/// assert_eq!(normalize([0, 3, 0]), Some([0, NORMAL_ONE, 0]));
/// assert_eq!(normalize([3, 4, 0]), Some([644245094, 858993459, 0]));
/// assert_eq!(normalize([0, 0, 0]), None);
/// ```
#[must_use]
pub fn normalize(v: [i64; 3]) -> Option<[i32; 3]> {
    let m = v.iter().map(|c| c.unsigned_abs()).max()?;
    if m == 0 {
        return None;
    }
    let bits = 64u32.saturating_sub(m.leading_zeros());
    let w: [i128; 3] = if bits < 40 {
        let s = 40u32.saturating_sub(bits);
        // |c| < 2^bits, so c·2^s < 2^40.
        v.map(|c| i128::from(c) << s)
    } else {
        let s = bits.saturating_sub(40);
        v.map(|c| i128::from(c) >> s)
    };
    // |w_i| <= 2^40: the squared length is below 3·2^80.
    let len2: u128 = w
        .iter()
        .map(|c| c.unsigned_abs().saturating_mul(c.unsigned_abs()))
        .fold(0u128, u128::saturating_add);
    let len = i128::try_from(crate::voxelize::isqrt_u128(len2)).ok()?;
    if len == 0 {
        return None;
    }
    let one = i128::from(NORMAL_ONE);
    let mut out = [0i32; 3];
    for (o, c) in out.iter_mut().zip(w.iter()) {
        // |c|·2^30 < 2^71; |c| <= len, so the quotient is within ±2^30.
        let q = div_round(c.saturating_mul(one), len);
        *o = i32::try_from(q).ok()?;
    }
    Some(out)
}

/// `a / b` rounded to nearest (halves away from zero), `b > 0`.
pub(crate) fn div_round(a: i128, b: i128) -> i128 {
    let half = b >> 1;
    let q = a
        .unsigned_abs()
        .saturating_add(half.unsigned_abs())
        .checked_div(b.unsigned_abs())
        .unwrap_or(0);
    let q = i128::try_from(q).unwrap_or(i128::MAX);
    if a >= 0 { q } else { q.wrapping_neg() }
}

/// Dot product of two [`NORMAL_ONE`]-scaled vectors, scaled by `NORMAL_ONE`
/// (so two unit vectors give a value in `[-NORMAL_ONE, NORMAL_ONE]`,
/// saturating for longer inputs).
///
/// ```
/// use rrt_core::voxel::dot_unit;
/// use rrt_core::voxelize::NORMAL_ONE;
/// assert_eq!(dot_unit([NORMAL_ONE, 0, 0], [NORMAL_ONE, 0, 0]), NORMAL_ONE);
/// assert_eq!(dot_unit([NORMAL_ONE, 0, 0], [0, NORMAL_ONE, 0]), 0);
/// ```
#[must_use]
pub fn dot_unit(a: [i32; 3], b: [i32; 3]) -> i32 {
    let s: i64 = a
        .iter()
        .zip(b.iter())
        // Each product is below 2^62 in magnitude; the sum saturates.
        .map(|(x, y)| i64::from(*x).saturating_mul(i64::from(*y)))
        .fold(0i64, i64::saturating_add);
    let q = s >> 30;
    i32::try_from(q.clamp(i64::from(i32::MIN), i64::from(i32::MAX))).unwrap_or(0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use core::mem::{align_of, offset_of, size_of};

    #[test]
    fn layout() {
        assert_eq!(size_of::<VoxelRecord>(), 20);
        assert_eq!(align_of::<VoxelRecord>(), 4);
        assert_eq!(offset_of!(VoxelRecord, object), 0);
        assert_eq!(offset_of!(VoxelRecord, normal), 4);
        assert_eq!(offset_of!(VoxelRecord, color), 8);
        assert_eq!(offset_of!(VoxelRecord, illum), 11);
        assert_eq!(offset_of!(VoxelRecord, lights), 14);
        assert_eq!(offset_of!(VoxelRecord, material), 16);
        assert_eq!(offset_of!(VoxelRecord, key), 18);
    }

    #[test]
    fn byte_view() {
        let r = VoxelRecord {
            object: 0x0403_0201,
            normal: [0x0605, 0x0807],
            color: [9, 10, 11],
            illum: [12, 13, 14],
            lights: 0x100f,
            material: 0x1211,
            key: 0x1413,
        };
        let bytes = bytemuck::bytes_of(&r);
        // Little-endian fields laid out back to back, no padding.
        let expected: [u8; 20] = if cfg!(target_endian = "little") {
            [
                1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 16, 17, 18, 19, 20,
            ]
        } else {
            [
                4, 3, 2, 1, 6, 5, 8, 7, 9, 10, 11, 12, 13, 14, 16, 15, 18, 17, 20, 19,
            ]
        };
        assert_eq!(bytes, &expected);
        let back: VoxelRecord = bytemuck::pod_read_unaligned(bytes);
        assert_eq!(back, r);
        assert_eq!(bytemuck::bytes_of(&VoxelRecord::zeroed()), &[0u8; 20]);
        let arr = [r, VoxelRecord::default()];
        assert_eq!(bytemuck::cast_slice::<VoxelRecord, u8>(&arr).len(), 40);
    }

    #[test]
    fn light_bits() {
        let mut r = VoxelRecord::default();
        for i in 0..MAX_LIGHTS {
            r.set_light(i, LightVisibility::Visible);
        }
        assert_eq!(r.lights, 0x5555);
        r.set_light(7, LightVisibility::Translucent);
        r.set_light(0, LightVisibility::Occluded);
        assert_eq!(r.light(7), LightVisibility::Translucent);
        assert_eq!(r.light(0), LightVisibility::Occluded);
        assert_eq!(r.light(1), LightVisibility::Visible);
        r.set_light(8, LightVisibility::Visible);
        assert_eq!(r.light(8), LightVisibility::Occluded);
        assert_eq!(r.lights, 0x9554);
    }

    #[test]
    fn key_parts() {
        let k = make_key([7, 7, 7], 3 * 512);
        assert_eq!(k & KEY_POSITION_MASK, 511);
        let r = VoxelRecord {
            key: k,
            ..VoxelRecord::default()
        };
        assert_eq!(r.position(), 511);
        assert_eq!(r.distance(), 3);
    }

    /// sin of the angle between `a` and `b`, in nanoradians (small angles),
    /// computed as `|a × b| / (|a|·|b|)` in integers. Panics if they point
    /// more than 90° apart.
    fn angle_nrad(a: [i32; 3], b: [i32; 3]) -> u128 {
        let a = a.map(i128::from);
        let b = b.map(i128::from);
        let dot = a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
        assert!(dot > 0, "{a:?} vs {b:?}");
        let c = [
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ];
        let c2: u128 = c.iter().map(|v| v.unsigned_abs().pow(2)).sum();
        let la = a
            .iter()
            .map(|v| v.unsigned_abs().pow(2))
            .sum::<u128>()
            .isqrt();
        let lb = b
            .iter()
            .map(|v| v.unsigned_abs().pow(2))
            .sum::<u128>()
            .isqrt();
        c2.isqrt() * 1_000_000_000 / (la * lb)
    }

    fn roundtrip_error(n: [i32; 3]) -> u128 {
        let d = decode_normal(encode_normal(n));
        angle_nrad(n, d)
    }

    #[test]
    fn octahedral_error() {
        let mut worst = 0u128;
        let mut worst_n = [0; 3];
        let mut check = |n: [i32; 3]| {
            let e = roundtrip_error(n);
            if e > worst {
                worst = e;
                worst_n = n;
            }
        };
        // Axes, diagonals and directions on the fold (z = 0) and near it.
        for s in [
            [1, 0, 0],
            [0, 1, 0],
            [0, 0, 1],
            [1, 1, 1],
            [1, -1, 0],
            [3, 1, 0],
        ] {
            for signs in 0..8u32 {
                let v: [i64; 3] = core::array::from_fn(|k| {
                    let sign = if signs >> k & 1 == 1 { -1 } else { 1 };
                    sign * s[k]
                });
                if let Some(n) = normalize(v) {
                    check(n);
                }
            }
        }
        for i in 0..2000i64 {
            for z in [-1i64, 0, 1] {
                if let Some(n) = normalize([1000 - i, i - 1000 + 17, z]) {
                    check(n);
                }
            }
        }
        // Seeded random directions, uniform in the ball (rejection).
        let mut rng = crate::rng::Rng::new(42);
        let mut n_done = 0;
        while n_done < 200_000 {
            let mut r = || (rng.next_u64() >> 33) as i64 - (1 << 30);
            let v = [r(), r(), r()];
            let l2: i128 = v.iter().map(|c| i128::from(*c).pow(2)).sum();
            if !((1i128 << 40)..=(1i128 << 60)).contains(&l2) {
                continue;
            }
            check(normalize(v).unwrap());
            n_done += 1;
        }
        std::println!("octahedral snorm16 worst angular error: {worst} nrad at {worst_n:?}");
        // Bound stated in the module docs: 50 µrad.
        assert!(worst < 50_000, "worst error {worst} nrad at {worst_n:?}");
    }

    #[test]
    fn decode_is_unit_for_all_extremes() {
        let one = i128::from(NORMAL_ONE);
        for u in [i16::MIN, -32767, -16384, -1, 0, 1, 16383, 32767] {
            for v in [i16::MIN, -32767, -20000, -1, 0, 1, 12345, 32767] {
                let d = decode_normal([u, v]).map(i128::from);
                let l2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
                assert!((l2 - one * one).abs() < 4 * one, "{u},{v}: {d:?}");
                // Re-encoding a decoded normal is exact.
                let back = encode_normal(d.map(|c| c as i32));
                let same = decode_normal(back);
                assert_eq!(same, d.map(|c| c as i32));
            }
        }
    }

    #[test]
    fn normalize_precision() {
        let one = i128::from(NORMAL_ONE);
        for v in [
            [1i64, 1, 1],
            [i64::MAX, 0, -1],
            [-(1 << 47), 1 << 47, 5],
            [7, -3, 2],
        ] {
            let n = normalize(v).unwrap().map(i128::from);
            let l2 = n[0] * n[0] + n[1] * n[1] + n[2] * n[2];
            assert!((l2 - one * one).abs() <= 4 * one, "{v:?}: {n:?}");
        }
        assert_eq!(normalize([i64::MIN, 0, 0]), Some([-NORMAL_ONE, 0, 0]));
    }

    #[test]
    fn decode_is_normalize_of_unfold_within_one_unit() {
        // Every 97th code on each axis, and the extremes.
        let codes = || {
            (i16::MIN..=i16::MAX)
                .step_by(97)
                .chain([i16::MAX, -1, 0, 1])
        };
        for u in codes() {
            for v in codes() {
                let fast = decode_normal([u, v]);
                let slow = normalize(unfold([u, v])).unwrap();
                for (f, s) in fast.iter().zip(slow.iter()) {
                    assert!(
                        (i64::from(*f) - i64::from(*s)).abs() <= 1,
                        "{u} {v}: {fast:?} {slow:?}"
                    );
                }
            }
        }
    }

    #[test]
    fn zero_encodes_as_up() {
        assert_eq!(encode_normal([0, 0, 0]), [0, 0]);
        assert_eq!(decode_normal([0, 0]), [0, 0, NORMAL_ONE]);
    }
}
