//! The TOML schema: what each table and key may hold (serde; unknown keys
//! are refused). [`ShapeDef`] is an object's one shape key.

use std::collections::BTreeMap;
use std::fmt;
use std::marker::PhantomData;

use ::toml::Spanned;
use serde::Deserialize;
use serde::de::{self, Deserializer, IgnoredAny, MapAccess, SeqAccess, Visitor};

/// An array of exactly `N` elements: every fixed-length array of the
/// schema is one. serde's `[T; N]` reads the first `N` elements of a TOML
/// array and ignores the rest, so `centre = [0, 0, 0, 5]` would pass; this
/// refuses too few and too many alike ("invalid length 4, expected an
/// array of length 3"), located at the array with its key path.
#[derive(Clone, Copy)]
pub(super) struct Exact<T, const N: usize>(pub(super) [T; N]);

impl<T, const N: usize> std::ops::Deref for Exact<T, N> {
    type Target = [T; N];
    fn deref(&self) -> &[T; N] {
        &self.0
    }
}

impl<T: Copy, const N: usize> Exact<T, N> {
    /// The elements of a list of arrays, as plain arrays.
    pub(super) fn plain(list: &[Self]) -> Vec<[T; N]> {
        list.iter().map(|a| a.0).collect()
    }
}

impl<T: Copy + Default, const N: usize> Default for Exact<T, N> {
    fn default() -> Self {
        Self([T::default(); N])
    }
}

impl<'de, T: Deserialize<'de> + Copy + Default, const N: usize> Deserialize<'de> for Exact<T, N> {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct Elems<T, const N: usize>(PhantomData<T>);
        impl<'de, T: Deserialize<'de> + Copy + Default, const N: usize> Visitor<'de> for Elems<T, N> {
            type Value = Exact<T, N>;
            fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                write!(f, "an array of length {N}")
            }
            fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Self::Value, A::Error> {
                let mut out = [T::default(); N];
                for (i, slot) in out.iter_mut().enumerate() {
                    *slot = seq
                        .next_element()?
                        .ok_or_else(|| de::Error::invalid_length(i, &self))?;
                }
                let mut len = N;
                while seq.next_element::<IgnoredAny>()?.is_some() {
                    len += 1;
                }
                if len > N {
                    return Err(de::Error::invalid_length(len, &self));
                }
                Ok(Exact(out))
            }
        }
        d.deserialize_seq(Elems::<T, N>(PhantomData))
    }
}

/// A point, vector or colour: exactly three numbers.
pub(super) type V3 = Exact<f64, 3>;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct Doc {
    pub(super) camera: Spanned<CameraDef>,
    #[serde(default)]
    pub(super) background: Option<V3>,
    #[serde(default)]
    pub(super) light: Vec<Spanned<LightDef>>,
    #[serde(default)]
    pub(super) material: BTreeMap<String, Spanned<MaterialDef>>,
    #[serde(default)]
    pub(super) volume: BTreeMap<String, Spanned<VolumeDef>>,
    #[serde(default)]
    pub(super) solid: BTreeMap<String, Spanned<SolidDef>>,
    #[serde(default)]
    pub(super) object: Vec<Spanned<ObjectDef>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct CameraDef {
    pub(super) from: V3,
    pub(super) at: V3,
    #[serde(default = "default_up")]
    pub(super) up: V3,
    pub(super) angle: f64,
    #[serde(default = "default_hither")]
    pub(super) hither: f64,
    pub(super) resolution: Exact<u32, 2>,
}

const fn default_up() -> V3 {
    Exact([0.0, 0.0, 1.0])
}
const fn default_hither() -> f64 {
    1.0
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct LightDef {
    pub(super) position: V3,
    #[serde(default)]
    pub(super) colour: Option<V3>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct MaterialDef {
    #[serde(default = "default_colour")]
    pub(super) colour: V3,
    #[serde(default = "one")]
    pub(super) kd: f64,
    #[serde(default)]
    pub(super) ks: f64,
    #[serde(default = "one")]
    pub(super) shine: f64,
    #[serde(default)]
    pub(super) transmittance: f64,
    #[serde(default = "one")]
    pub(super) ior: f64,
    #[serde(default)]
    pub(super) texture: Option<Spanned<TextureDef>>,
}

const fn default_colour() -> V3 {
    Exact([0.8, 0.8, 0.8])
}
const fn one() -> f64 {
    1.0
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct TextureDef {
    #[serde(default)]
    pub(super) modulate: bool,
    #[serde(default)]
    pub(super) checker: Option<CheckerDef>,
    #[serde(default)]
    pub(super) marble: Option<NoiseDef>,
    #[serde(default)]
    pub(super) wood: Option<NoiseDef>,
    #[serde(default)]
    pub(super) image: Option<ImageDef>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct CheckerDef {
    #[serde(default)]
    pub(super) origin: V3,
    pub(super) size: f64,
    pub(super) colours: Exact<Exact<u8, 3>, 2>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct NoiseDef {
    #[serde(default)]
    pub(super) seed: u64,
    #[serde(default)]
    pub(super) origin: V3,
    #[serde(default = "default_up")]
    pub(super) direction: V3,
    pub(super) period: f64,
    #[serde(default = "one")]
    pub(super) noise_scale: f64,
    #[serde(default = "one")]
    pub(super) turbulence: f64,
    #[serde(default = "default_octaves")]
    pub(super) octaves: u32,
    pub(super) colours: Exact<Exact<u8, 3>, 2>,
}

const fn default_octaves() -> u32 {
    4
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct ImageDef {
    pub(super) file: Spanned<String>,
    #[serde(default)]
    pub(super) wrap: Option<String>,
    #[serde(default)]
    pub(super) planar: Option<PlanarDef>,
    #[serde(default)]
    pub(super) cylindrical: Option<AxisDef>,
    #[serde(default)]
    pub(super) spherical: Option<AxisDef>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct PlanarDef {
    pub(super) origin: V3,
    pub(super) u: V3,
    pub(super) v: V3,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct AxisDef {
    pub(super) centre: V3,
    pub(super) axis: V3,
    pub(super) reference: V3,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct VolumeDef {
    #[serde(default)]
    pub(super) file: Option<Spanned<String>>,
    #[serde(default)]
    pub(super) raw: Option<RawDef>,
    #[serde(default)]
    pub(super) metaballs: Option<MetaballsDef>,
    /// Required unless `opacity` is given.
    #[serde(default)]
    pub(super) iso: Option<f64>,
    #[serde(default)]
    pub(super) opacity: Option<Vec<Exact<f64, 2>>>,
    #[serde(default)]
    pub(super) colours: Option<Vec<Exact<f64, 4>>>,
    /// `"iso"` or `"direct"`; the default is `"direct"` when an opacity
    /// point lies strictly between 0 and 1, else `"iso"`.
    #[serde(default)]
    pub(super) render: Option<String>,
    #[serde(default)]
    pub(super) fit: Option<BoxDef>,
    #[serde(default)]
    pub(super) translate: Option<V3>,
    #[serde(default)]
    pub(super) scale: Option<f64>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawDef {
    pub(super) file: Spanned<String>,
    pub(super) dims: Exact<u32, 3>,
    #[serde(rename = "type")]
    pub(super) sample_type: String,
    #[serde(default = "default_spacing")]
    pub(super) spacing: V3,
    #[serde(default)]
    pub(super) big_endian: bool,
    #[serde(default)]
    pub(super) skip: u64,
}

const fn default_spacing() -> V3 {
    Exact([1.0, 1.0, 1.0])
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct MetaballsDef {
    pub(super) dims: Exact<u32, 3>,
    pub(super) min: V3,
    pub(super) max: V3,
    /// `[x, y, z, radius, strength]` each.
    pub(super) balls: Vec<Exact<f64, 5>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct BoxDef {
    pub(super) min: V3,
    pub(super) max: V3,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct SphereDef {
    pub(super) centre: V3,
    pub(super) radius: f64,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct ConeDef {
    pub(super) base: V3,
    pub(super) base_radius: f64,
    pub(super) apex: V3,
    pub(super) apex_radius: f64,
    #[serde(default)]
    pub(super) capped: bool,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct TorusDef {
    pub(super) centre: V3,
    #[serde(default = "default_up")]
    pub(super) axis: V3,
    pub(super) major: f64,
    pub(super) minor: f64,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct SolidDef {
    #[serde(default)]
    pub(super) material: Option<Spanned<String>>,
    #[serde(default)]
    pub(super) sphere: Option<SphereDef>,
    #[serde(default, rename = "box")]
    pub(super) cuboid: Option<BoxDef>,
    #[serde(default)]
    pub(super) cone: Option<ConeDef>,
    #[serde(default)]
    pub(super) torus: Option<TorusDef>,
    #[serde(default)]
    pub(super) volume: Option<Spanned<String>>,
}

/// An operand of a CSG operation: a solid's name or a nested operation.
/// Read by hand rather than as an untagged enum, whose only error is
/// "data did not match any variant", at the whole operand list: a wrong
/// type is named at the operand itself, and a nested operation's own
/// errors (an unknown key, a wrong type inside it) at theirs.
pub(super) enum CsgExpr {
    Leaf(String),
    Op(CsgOp),
}

impl<'de> Deserialize<'de> for CsgExpr {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct Operand;
        impl<'de> Visitor<'de> for Operand {
            type Value = CsgExpr;
            fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                f.write_str(
                    "a solid's name or an operation ({ union = [...] }, { intersection = [...] } \
                     or { difference = [...] })",
                )
            }
            fn visit_str<E: de::Error>(self, name: &str) -> Result<CsgExpr, E> {
                Ok(CsgExpr::Leaf(name.to_owned()))
            }
            fn visit_map<A: MapAccess<'de>>(self, map: A) -> Result<CsgExpr, A::Error> {
                CsgOp::deserialize(de::value::MapAccessDeserializer::new(map)).map(CsgExpr::Op)
            }
        }
        d.deserialize_any(Operand)
    }
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct CsgOp {
    #[serde(default)]
    pub(super) union: Option<Vec<CsgExpr>>,
    #[serde(default)]
    pub(super) intersection: Option<Vec<CsgExpr>>,
    #[serde(default)]
    pub(super) difference: Option<Vec<CsgExpr>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct TransformDef {
    #[serde(default)]
    pub(super) translate: V3,
    #[serde(default = "one")]
    pub(super) scale: f64,
    #[serde(default)]
    pub(super) rotate_x: f64,
    #[serde(default)]
    pub(super) rotate_y: f64,
    #[serde(default)]
    pub(super) rotate_z: f64,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct BezierDef {
    pub(super) file: Spanned<String>,
    #[serde(default = "default_steps")]
    pub(super) steps: u32,
}

const fn default_steps() -> u32 {
    8
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct MeshDef {
    pub(super) file: Spanned<String>,
    #[serde(default)]
    pub(super) smooth: bool,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct VoxDef {
    pub(super) file: Spanned<String>,
    #[serde(default)]
    pub(super) position: V3,
    #[serde(default = "one")]
    pub(super) cell: f64,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct ObjectDef {
    #[serde(default)]
    pub(super) material: Option<Spanned<String>>,
    #[serde(default)]
    pub(super) transform: Option<TransformDef>,
    #[serde(default)]
    pub(super) sphere: Option<SphereDef>,
    #[serde(default)]
    pub(super) cone: Option<ConeDef>,
    #[serde(default)]
    pub(super) polygon: Option<Vec<V3>>,
    #[serde(default, rename = "box")]
    pub(super) cuboid: Option<BoxDef>,
    #[serde(default)]
    pub(super) torus: Option<TorusDef>,
    #[serde(default)]
    pub(super) bezier: Option<BezierDef>,
    #[serde(default)]
    pub(super) mesh: Option<MeshDef>,
    #[serde(default)]
    pub(super) nff: Option<Spanned<String>>,
    #[serde(default)]
    pub(super) volume: Option<Spanned<String>>,
    #[serde(default)]
    pub(super) vox: Option<VoxDef>,
    #[serde(default)]
    pub(super) csg: Option<Spanned<CsgOp>>,
}

/// The shape key of an object.
#[derive(Clone, Copy)]
pub(super) enum ShapeDef<'d> {
    Sphere(&'d SphereDef),
    Cone(&'d ConeDef),
    Polygon(&'d [V3]),
    Box(&'d BoxDef),
    Torus(&'d TorusDef),
    Bezier(&'d BezierDef),
    Mesh(&'d MeshDef),
    Nff(&'d Spanned<String>),
    Volume(&'d Spanned<String>),
    Vox(&'d VoxDef),
    Csg(&'d Spanned<CsgOp>),
}

/// The shape keys, for messages.
pub(super) const SHAPE_KEYS: &str =
    "sphere, cone, polygon, box, torus, bezier, mesh, nff, volume, vox, csg";

impl ShapeDef<'_> {
    /// The object key that gives this shape.
    pub(super) const fn key(self) -> &'static str {
        match self {
            Self::Sphere(_) => "sphere",
            Self::Cone(_) => "cone",
            Self::Polygon(_) => "polygon",
            Self::Box(_) => "box",
            Self::Torus(_) => "torus",
            Self::Bezier(_) => "bezier",
            Self::Mesh(_) => "mesh",
            Self::Nff(_) => "nff",
            Self::Volume(_) => "volume",
            Self::Vox(_) => "vox",
            Self::Csg(_) => "csg",
        }
    }
}

impl ObjectDef {
    /// The shape keys the object gives, in the order of [`SHAPE_KEYS`].
    pub(super) fn shapes(&self) -> Vec<ShapeDef<'_>> {
        [
            self.sphere.as_ref().map(ShapeDef::Sphere),
            self.cone.as_ref().map(ShapeDef::Cone),
            self.polygon.as_deref().map(ShapeDef::Polygon),
            self.cuboid.as_ref().map(ShapeDef::Box),
            self.torus.as_ref().map(ShapeDef::Torus),
            self.bezier.as_ref().map(ShapeDef::Bezier),
            self.mesh.as_ref().map(ShapeDef::Mesh),
            self.nff.as_ref().map(ShapeDef::Nff),
            self.volume.as_ref().map(ShapeDef::Volume),
            self.vox.as_ref().map(ShapeDef::Vox),
            self.csg.as_ref().map(ShapeDef::Csg),
        ]
        .into_iter()
        .flatten()
        .collect()
    }
}
