//! Why a store is refused or a scene cannot be built.

use core::fmt;

/// Why a directory and record array do not form a valid store.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum StoreError {
    /// The raster has more bricks than `usize` can count.
    TooManyBricks,
    /// The directory does not have one entry per brick plus one.
    DirectoryLength {
        /// Bricks + 1.
        expected: usize,
        /// The slice length given.
        found: usize,
    },
    /// The first entry is not 0.
    DirectoryStart,
    /// An entry is smaller than the one before it, or a brick holds more
    /// records than it has voxels.
    DirectoryOrder {
        /// The brick whose range is wrong.
        brick: usize,
    },
    /// The last entry is not the number of records.
    DirectoryEnd {
        /// The last entry.
        last: u32,
        /// The number of records.
        records: usize,
    },
    /// A brick's records are not sorted by position, repeat a position, or
    /// name a voxel outside the raster.
    BadKey {
        /// Index of the offending record.
        record: usize,
    },
    /// A record's object list is not where the previous list ended, runs
    /// past the array, names fewer than two objects, an id of 2^31 or more,
    /// or repeats or misorders its other objects.
    BadList {
        /// Index of the offending record.
        record: usize,
    },
    /// The object lists end before the end of the list array.
    ListsEnd {
        /// Entries the records' lists use.
        used: usize,
        /// Entries in the array.
        len: usize,
    },
    /// The list array is longer than 31-bit indices reach.
    ListsTooLong {
        /// Entries in the array.
        len: usize,
    },
}

impl fmt::Display for StoreError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            Self::TooManyBricks => f.write_str("raster has too many bricks to address"),
            Self::DirectoryLength { expected, found } => write!(
                f,
                "brick directory has {found} entries, expected {expected} (bricks + 1)"
            ),
            Self::DirectoryStart => f.write_str("brick directory does not start at 0"),
            Self::DirectoryOrder { brick } => {
                write!(f, "brick directory entry {brick} is out of order")
            }
            Self::DirectoryEnd { last, records } => write!(
                f,
                "brick directory ends at {last}, but there are {records} records"
            ),
            Self::BadKey { record } => write!(
                f,
                "record {record} has a position that is unsorted, repeated or outside the raster"
            ),
            Self::BadList { record } => write!(
                f,
                "record {record} has an object list that is misplaced, too short, out of range or unsorted"
            ),
            Self::ListsEnd { used, len } => write!(
                f,
                "the object lists use {used} entries, but the list array has {len}"
            ),
            Self::ListsTooLong { len } => write!(
                f,
                "the list array has {len} entries, more than 31-bit indices reach"
            ),
        }
    }
}

impl core::error::Error for StoreError {}

/// Why a scene could not be built.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum BuildError {
    /// The directory slice does not have one entry per brick plus one.
    DirectoryLength {
        /// Bricks + 1 (or `usize::MAX` if even that overflows).
        expected: usize,
        /// The slice length given.
        found: usize,
    },
    /// More non-transparent voxels than a `u32` directory can address.
    TooManyRecords,
    /// The record slice is smaller than the count pass found.
    RecordStorage {
        /// Records needed.
        needed: usize,
        /// Records given.
        found: usize,
    },
    /// [`ObjectAttrs::object`](super::ObjectAttrs::object) is not below
    /// [`Limits::objects`](super::Limits::objects) (nor below
    /// [`MAX_OBJECTS`](crate::voxel::MAX_OBJECTS), which then is the limit).
    ObjectOutOfRange {
        /// The object id.
        object: u32,
        /// The limit.
        limit: u32,
    },
    /// [`ObjectAttrs::material`](super::ObjectAttrs::material) is not below
    /// [`Limits::materials`](super::Limits::materials).
    MaterialOutOfRange {
        /// The material index.
        material: u16,
        /// The limit.
        limit: u32,
    },
    /// The fill pass offered voxels before any
    /// [`Filler::begin_object`](super::Filler::begin_object).
    OfferWithoutObject {
        /// How many offers.
        offers: u64,
    },
    /// The fill pass offered voxels the count pass did not: the two passes
    /// did not voxelize the same scene.
    PassMismatch {
        /// How many such offers.
        uncounted: u64,
    },
    /// The fill pass left counted voxels without a record.
    FillIncomplete {
        /// Records written.
        filled: usize,
        /// Records counted.
        expected: usize,
    },
    /// The object lists did not fit the list storage given to
    /// [`Sizing::fill`](super::Sizing::fill) (at most
    /// [`Sizing::list_entries`](super::Sizing::list_entries) entries are
    /// ever needed).
    ListStorage {
        /// Entries of list storage needed, at least.
        needed: usize,
        /// Entries of list storage given.
        found: usize,
    },
    /// A slab's first layer is not a multiple of the brick edge (8).
    SlabOrigin {
        /// The first layer given.
        z0: u32,
    },
    /// A band's first row or layer is not a multiple of the brick edge
    /// (8), or it holds more than one brick layer.
    BandShape {
        /// The first row given.
        y0: u32,
        /// The first layer given.
        z0: u32,
        /// The layers the band's raster holds.
        layers: u32,
    },
}

impl fmt::Display for BuildError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            Self::DirectoryLength { expected, found } => write!(
                f,
                "brick directory has {found} entries, expected {expected} (bricks + 1)"
            ),
            Self::TooManyRecords => {
                f.write_str("more non-transparent voxels than a u32 directory addresses")
            }
            Self::RecordStorage { needed, found } => {
                write!(
                    f,
                    "record storage holds {found} records, the scene needs {needed}"
                )
            }
            Self::ObjectOutOfRange { object, limit } => {
                write!(f, "object id {object} is not below the table size {limit}")
            }
            Self::MaterialOutOfRange { material, limit } => {
                write!(f, "material {material} is not below the table size {limit}")
            }
            Self::OfferWithoutObject { offers } => {
                write!(f, "{offers} voxels offered before any begin_object")
            }
            Self::PassMismatch { uncounted } => write!(
                f,
                "the fill pass offered {uncounted} voxels the count pass did not"
            ),
            Self::FillIncomplete { filled, expected } => write!(
                f,
                "the fill pass wrote {filled} records, the count pass found {expected}"
            ),
            Self::ListStorage { needed, found } => write!(
                f,
                "the object lists need at least {needed} entries of list storage, {found} given"
            ),
            Self::SlabOrigin { z0 } => write!(
                f,
                "a slab starts at layer {z0}, not at a multiple of the brick edge 8"
            ),
            Self::BandShape { y0, z0, layers } => write!(
                f,
                "a band starts at row {y0} and layer {z0} and holds {layers} layers: \
                 it must start at multiples of the brick edge 8 and hold at most 8 layers"
            ),
        }
    }
}

impl core::error::Error for BuildError {}
