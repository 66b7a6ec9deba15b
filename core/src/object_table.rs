//! The object table, the material table and the light list: fixed-capacity
//! tables the record fields index.
//!
//! * [`ObjectTable`]: per object its geometric definition in fixed point
//!   ([`Shape`]) and its material, indexed by [`VoxelRecord::object`]. The
//!   host's *intersection verification* (the paper's remedy for false hits)
//!   reads it. Its storage is a caller-provided slice, like the raster
//!   plane: a million objects do not fit on a stack, so the table borrows
//!   `&mut [Object]` and [`ObjectTable::push`] hands the object back when
//!   the slice is full, as `heapless::Vec::push` does. Bézier patches
//!   (384 bytes each) live in a second slice and objects refer to them by
//!   index, which keeps [`Object`] at 128 bytes.
//! * [`Materials`]: NFF `f` entries in fixed point, capacity a const
//!   generic (a `heapless::Vec`), indexed by [`VoxelRecord::material`].
//! * [`Lights`]: up to [`MAX_LIGHTS`] point lights (the record keeps 2
//!   visibility bits per light) and the ambient intensity.
//!
//! Scalars (colour channels, coefficients, intensities) are unsigned fixed
//! point with [`SCALAR_BITS`] fractional bits: [`SCALAR_ONE`] is 1.0.
//!
//! [`VoxelRecord::object`]: crate::voxel::VoxelRecord::object
//! [`VoxelRecord::material`]: crate::voxel::VoxelRecord::material

use crate::geometry::{BezierPatch, Cone, Cuboid, Point, Sphere, Torus, Triangle};
pub use crate::voxel::MAX_LIGHTS;

/// Fractional bits of the fixed-point scalars of this module.
pub const SCALAR_BITS: u32 = 16;
/// 1.0 in the fixed-point scalars of this module.
pub const SCALAR_ONE: u32 = 1 << SCALAR_BITS;

/// A reference to a sampled volume (the volumes issue owns the data): the
/// host's index of the volume and the box it fills in raster coordinates.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct VolumeRef {
    /// The host's index of the volume data.
    pub volume: u32,
    /// The box the volume fills.
    pub bounds: Cuboid,
}

/// The geometric definition of one object, in fixed point.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Shape {
    /// A sphere (closed).
    Sphere(Sphere),
    /// A triangle, flat or with vertex normals (open).
    Triangle(Triangle),
    /// An open cone or cylinder (NFF `c`: no caps).
    Cone(Cone),
    /// An axis-aligned box (closed).
    Cuboid(Cuboid),
    /// A torus (closed).
    Torus(Torus),
    /// A bicubic Bézier patch: index into the table's patch storage (open).
    Patch(u32),
    /// A sampled volume (closed: its voxels bound a solid).
    Volume(VolumeRef),
    /// No continuous definition: the voxels are the object (CSG results,
    /// whose surface no single primitive describes). Intersection
    /// verification accepts the discrete hit as it is.
    Voxels,
}

impl Shape {
    /// Whether the shape bounds a solid, so that its back side is never lit
    /// (the light pass classifies a light the stored normal faces away
    /// from as occluded). Open shapes (triangles, patches, open cones) can be
    /// seen and lit from both sides.
    ///
    /// ```
    /// use rrt_core::geometry::Sphere;
    /// use rrt_core::object_table::Shape;
    /// assert!(Shape::Sphere(Sphere { centre: [0; 3], radius: 1 }).is_closed());
    /// assert!(!Shape::Patch(0).is_closed());
    /// ```
    #[must_use]
    pub const fn is_closed(&self) -> bool {
        match self {
            Self::Sphere(_) | Self::Cuboid(_) | Self::Torus(_) | Self::Volume(_) | Self::Voxels => {
                true
            }
            Self::Triangle(_) | Self::Cone(_) | Self::Patch(_) => false,
        }
    }

    /// Whether the shape has a continuous definition a host can intersect
    /// exactly (intersection verification): every shape but a sampled
    /// volume and bare voxels.
    ///
    /// ```
    /// use rrt_core::geometry::Sphere;
    /// use rrt_core::object_table::Shape;
    /// assert!(Shape::Sphere(Sphere { centre: [0; 3], radius: 1 }).is_exact());
    /// assert!(!Shape::Voxels.is_exact());
    /// ```
    #[must_use]
    pub const fn is_exact(&self) -> bool {
        !matches!(self, Self::Volume(_) | Self::Voxels)
    }
}

/// One entry of the object table.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Object {
    /// The geometric definition.
    pub shape: Shape,
    /// Index into the material table.
    pub material: u16,
}

impl Object {
    /// A filler value for unused storage slots (never read by the table).
    ///
    /// ```
    /// use rrt_core::object_table::{Object, ObjectTable};
    /// let mut storage = [Object::UNUSED; 4];
    /// let table = ObjectTable::new(&mut storage, &mut []);
    /// assert_eq!(table.len(), 0);
    /// ```
    pub const UNUSED: Self = Self {
        shape: Shape::Voxels,
        material: 0,
    };
}

/// A fixed-capacity vector over a caller-provided slice.
#[derive(Debug)]
struct SliceVec<'a, T> {
    buf: &'a mut [T],
    /// Invariant: `len <= buf.len()`.
    len: usize,
}

impl<'a, T: Copy> SliceVec<'a, T> {
    fn new(buf: &'a mut [T]) -> Self {
        Self { buf, len: 0 }
    }
    fn is_full(&self) -> bool {
        self.len >= self.buf.len()
    }
    fn push(&mut self, item: T) -> Result<usize, T> {
        match self.buf.get_mut(self.len) {
            Some(slot) => {
                *slot = item;
                let i = self.len;
                // len < buf.len() <= usize::MAX.
                self.len = self.len.wrapping_add(1);
                Ok(i)
            }
            None => Err(item),
        }
    }
    fn as_slice(&self) -> &[T] {
        self.buf.get(..self.len).unwrap_or(&[])
    }
}

/// The object table: [`Object`]s (and the Bézier patches they refer to)
/// in caller-provided storage, indexed by object id.
///
/// ```
/// use rrt_core::geometry::Sphere;
/// use rrt_core::object_table::{Object, ObjectTable, Shape};
/// let mut storage = [Object::UNUSED; 1];
/// let mut table = ObjectTable::new(&mut storage, &mut []);
/// let s = Object { shape: Shape::Sphere(Sphere { centre: [0; 3], radius: 5 }), material: 0 };
/// assert_eq!(table.push(s), Ok(0));
/// assert_eq!(table.push(s), Err(s)); // full: the object comes back
/// assert_eq!(table.get(0), Some(&s));
/// ```
#[derive(Debug)]
pub struct ObjectTable<'a> {
    objects: SliceVec<'a, Object>,
    patches: SliceVec<'a, BezierPatch>,
}

impl<'a> ObjectTable<'a> {
    /// An empty table over `objects` and `patches` (their contents are
    /// overwritten as entries are pushed).
    pub fn new(objects: &'a mut [Object], patches: &'a mut [BezierPatch]) -> Self {
        Self {
            objects: SliceVec::new(objects),
            patches: SliceVec::new(patches),
        }
    }

    /// Appends `object` and returns its id.
    ///
    /// # Errors
    /// Gives `object` back when the table is full, or when the id would not
    /// be below [`MAX_OBJECTS`](crate::voxel::MAX_OBJECTS) (the record's
    /// object field keeps bit 31 for object lists), or when it is a
    /// [`Shape::Patch`] whose index is not a stored patch (use
    /// [`ObjectTable::push_patch`]).
    pub fn push(&mut self, object: Object) -> Result<u32, Object> {
        if let Shape::Patch(p) = object.shape
            && usize::try_from(p).map_or(true, |p| p >= self.patches.len)
        {
            return Err(object);
        }
        if u32::try_from(self.objects.len).map_or(true, |n| n >= crate::voxel::MAX_OBJECTS) {
            return Err(object);
        }
        let i = self.objects.push(object)?;
        u32::try_from(i).map_err(|_| object)
    }

    /// Stores a Bézier patch and appends an object referring to it; returns
    /// the object id.
    ///
    /// # Errors
    /// Gives the patch back when either the object or the patch storage is
    /// full.
    #[allow(clippy::result_large_err)] // the patch comes back, as heapless::Vec::push does
    pub fn push_patch(&mut self, patch: BezierPatch, material: u16) -> Result<u32, BezierPatch> {
        if self.objects.is_full() || self.patches.is_full() {
            return Err(patch);
        }
        let p = self.patches.push(patch)?;
        let p = u32::try_from(p).map_err(|_| patch)?;
        self.push(Object {
            shape: Shape::Patch(p),
            material,
        })
        .map_err(|_| patch)
    }

    /// The object with id `id`.
    #[must_use]
    pub fn get(&self, id: u32) -> Option<&Object> {
        self.objects.as_slice().get(usize::try_from(id).ok()?)
    }

    /// The Bézier patch of a [`Shape::Patch`] index.
    #[must_use]
    pub fn patch(&self, index: u32) -> Option<&BezierPatch> {
        self.patches.as_slice().get(usize::try_from(index).ok()?)
    }

    /// The objects pushed so far, in id order.
    #[must_use]
    pub fn objects(&self) -> &[Object] {
        self.objects.as_slice()
    }

    /// Number of objects.
    #[must_use]
    pub const fn len(&self) -> usize {
        self.objects.len
    }

    /// Whether the table holds no object.
    #[must_use]
    pub const fn is_empty(&self) -> bool {
        self.objects.len == 0
    }

    /// How many objects the storage holds.
    #[must_use]
    pub const fn capacity(&self) -> usize {
        self.objects.buf.len()
    }

    /// The id bound for [`crate::store::Limits::objects`] (`len`, below
    /// [`MAX_OBJECTS`](crate::voxel::MAX_OBJECTS) by construction).
    #[must_use]
    pub fn id_limit(&self) -> u32 {
        u32::try_from(self.objects.len).unwrap_or(u32::MAX)
    }
}

/// A material (NFF `f`), fixed point with [`SCALAR_BITS`] fractional bits.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct Material {
    /// Base colour, linear RGB (`SCALAR_ONE` = 1.0).
    pub color: [u32; 3],
    /// Diffuse coefficient Kd.
    pub kd: u32,
    /// Specular coefficient Ks (also the mirror reflection weight).
    pub ks: u32,
    /// Phong exponent ("Shine").
    pub shine: u32,
    /// Transmission T: a voxel of a material with `T > 0` lets shadow rays
    /// through as [`Translucent`](crate::voxel::LightVisibility::Translucent).
    pub transmission: u32,
    /// Index of refraction.
    pub ior: u32,
}

impl Material {
    /// The base colour as the record's 8-bit linear RGB (rounded,
    /// saturating at 255).
    ///
    /// ```
    /// use rrt_core::object_table::{Material, SCALAR_ONE};
    /// let m = Material { color: [SCALAR_ONE, SCALAR_ONE / 2, 0], ..Default::default() };
    /// assert_eq!(m.color_u8(), [255, 128, 0]);
    /// ```
    #[must_use]
    pub fn color_u8(&self) -> [u8; 3] {
        self.color.map(|c| {
            // c·255 < 2^40; rounded division by 2^16.
            let v = (u64::from(c).saturating_mul(255).saturating_add(1 << 15)) >> SCALAR_BITS;
            u8::try_from(v.min(255)).unwrap_or(u8::MAX)
        })
    }
}

/// The material table: up to `N` materials (at most 65,536, the record's
/// `u16` index).
///
/// ```
/// use rrt_core::object_table::{Material, Materials};
/// let mut m: Materials<2> = Materials::new();
/// assert_eq!(m.push(Material::default()), Ok(0));
/// assert_eq!(m.push(Material::default()), Ok(1));
/// assert!(m.push(Material::default()).is_err());
/// ```
#[derive(Clone, Debug, Default)]
pub struct Materials<const N: usize> {
    list: heapless::Vec<Material, N>,
}

impl<const N: usize> Materials<N> {
    /// An empty table.
    #[must_use]
    pub const fn new() -> Self {
        Self {
            list: heapless::Vec::new(),
        }
    }

    /// Appends a material and returns its index.
    ///
    /// # Errors
    /// Gives the material back when the table is full or the index would not
    /// fit `u16`.
    pub fn push(&mut self, m: Material) -> Result<u16, Material> {
        let i = u16::try_from(self.list.len()).map_err(|_| m)?;
        self.list.push(m)?;
        Ok(i)
    }

    /// The material at `index`.
    #[must_use]
    pub fn get(&self, index: u16) -> Option<&Material> {
        self.list.get(usize::from(index))
    }

    /// Number of materials.
    #[must_use]
    pub fn len(&self) -> usize {
        self.list.len()
    }

    /// Whether the table is empty.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.list.is_empty()
    }

    /// The bound for [`crate::store::Limits::materials`].
    #[must_use]
    pub fn index_limit(&self) -> u32 {
        u32::try_from(self.list.len()).unwrap_or(u32::MAX)
    }
}

/// A point light.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct Light {
    /// Position in raster fixed units (may lie outside the raster).
    pub position: Point,
    /// Colour, linear RGB (`SCALAR_ONE` = 1.0).
    pub color: [u32; 3],
    /// Intensity (SPD: `sqrt(nl) / (2·nl)` for `nl` lights; the host
    /// computes it and passes fixed point).
    pub intensity: u32,
}

/// The light sources (at most [`MAX_LIGHTS`]) and the ambient intensity.
///
/// ```
/// use rrt_core::object_table::{Light, Lights, MAX_LIGHTS, SCALAR_ONE};
/// let mut l = Lights::new(SCALAR_ONE / 2);
/// for _ in 0..MAX_LIGHTS {
///     l.push(Light::default()).unwrap();
/// }
/// assert!(l.push(Light::default()).is_err());
/// ```
#[derive(Clone, Debug, Default)]
pub struct Lights {
    /// Ambient intensity `I_a` (SPD uses the lights' intensity).
    pub ambient: u32,
    list: heapless::Vec<Light, MAX_LIGHTS>,
}

impl Lights {
    /// No lights yet, ambient intensity `ambient`.
    #[must_use]
    pub const fn new(ambient: u32) -> Self {
        Self {
            ambient,
            list: heapless::Vec::new(),
        }
    }

    /// Adds a light; its index is its slot in [`VoxelRecord::lights`].
    ///
    /// # Errors
    /// Gives the light back when [`MAX_LIGHTS`] are already there.
    ///
    /// [`VoxelRecord::lights`]: crate::voxel::VoxelRecord::lights
    pub fn push(&mut self, light: Light) -> Result<(), Light> {
        self.list.push(light)
    }

    /// The lights, in index order.
    #[must_use]
    pub fn as_slice(&self) -> &[Light] {
        self.list.as_slice()
    }

    /// Number of lights.
    #[must_use]
    pub fn len(&self) -> usize {
        self.list.len()
    }

    /// Whether there is no light.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.list.is_empty()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sphere(r: i64) -> Object {
        Object {
            shape: Shape::Sphere(Sphere {
                centre: [0; 3],
                radius: r,
            }),
            material: 1,
        }
    }

    #[test]
    fn object_size_stays_small() {
        assert!(core::mem::size_of::<Object>() <= 128);
        assert_eq!(core::mem::size_of::<BezierPatch>(), 384);
    }

    #[test]
    fn table_capacity_errors_give_the_item_back() {
        let mut objs = [Object::UNUSED; 3];
        let mut patches = [BezierPatch {
            control: [[[0; 3]; 4]; 4],
        }; 1];
        let mut t = ObjectTable::new(&mut objs, &mut patches);
        assert!(t.is_empty());
        assert_eq!(t.capacity(), 3);
        assert_eq!(t.push(sphere(1)), Ok(0));
        // A patch reference that is not stored is refused.
        let dangling = Object {
            shape: Shape::Patch(0),
            material: 0,
        };
        assert_eq!(t.push(dangling), Err(dangling));
        let p = BezierPatch {
            control: [[[7; 3]; 4]; 4],
        };
        assert_eq!(t.push_patch(p, 2), Ok(1));
        assert_eq!(t.get(1).unwrap().shape, Shape::Patch(0));
        assert_eq!(t.patch(0), Some(&p));
        // Patch storage full.
        assert_eq!(t.push_patch(p, 2), Err(p));
        assert_eq!(t.push(sphere(2)), Ok(2));
        // Object storage full.
        assert_eq!(t.push(sphere(3)), Err(sphere(3)));
        assert_eq!(t.len(), 3);
        assert_eq!(t.id_limit(), 3);
        assert_eq!(t.get(3), None);
        assert_eq!(t.objects().len(), 3);
    }

    #[test]
    fn empty_storage_is_a_full_table() {
        let mut t = ObjectTable::new(&mut [], &mut []);
        assert_eq!(t.push(sphere(1)), Err(sphere(1)));
        assert_eq!(t.get(0), None);
    }

    #[test]
    fn materials_and_lights_capacity() {
        let mut m: Materials<1> = Materials::new();
        let mat = Material {
            kd: SCALAR_ONE,
            ..Material::default()
        };
        assert_eq!(m.push(mat), Ok(0));
        assert_eq!(m.push(mat), Err(mat));
        assert_eq!(m.get(0), Some(&mat));
        assert_eq!(m.get(1), None);
        assert_eq!(m.index_limit(), 1);
        let mut l = Lights::new(0);
        for i in 0..MAX_LIGHTS {
            l.push(Light {
                intensity: i as u32,
                ..Light::default()
            })
            .unwrap();
        }
        assert_eq!(l.len(), 8);
        let extra = Light {
            intensity: 99,
            ..Light::default()
        };
        assert_eq!(l.push(extra), Err(extra));
    }

    #[test]
    fn shapes_open_and_closed() {
        let c = Cuboid {
            min: [0; 3],
            max: [1; 3],
        };
        assert!(Shape::Cuboid(c).is_closed());
        assert!(
            Shape::Volume(VolumeRef {
                volume: 0,
                bounds: c
            })
            .is_closed()
        );
        assert!(
            !Shape::Cone(Cone {
                base: [0; 3],
                base_radius: 1,
                apex: [1; 3],
                apex_radius: 1
            })
            .is_closed()
        );
    }
}
