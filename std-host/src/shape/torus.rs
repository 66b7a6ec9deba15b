//! Tori, as leaves of CSG trees.

use glam::DVec3;
use rrt_core::csg;
use rrt_core::geometry;

use super::{Primitive, SolidPrimitive, positive};
use crate::frame::{RasterFrame, unit_to_fixed};
use crate::world::Bounds;

/// A torus (closed): the points at distance `minor` from the circle of
/// radius `major` about the unit `axis` through `centre`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Torus {
    /// Centre.
    pub centre: DVec3,
    /// Unit axis.
    pub axis: DVec3,
    /// Radius of the centre circle (> 0).
    pub major: f64,
    /// Radius of the tube (> 0).
    pub minor: f64,
}

impl Primitive for Torus {
    const KIND: &'static str = "torus";

    fn validate(&self) -> Result<(), &'static str> {
        if !self.centre.is_finite() {
            return Err("centre not finite");
        }
        if !self.axis.is_normalized() {
            return Err("axis not a unit vector");
        }
        if !(positive(self.major) && positive(self.minor)) {
            return Err("radius not a finite number > 0");
        }
        Ok(())
    }

    fn bounds(&self) -> Bounds {
        let r = self.major + self.minor;
        Bounds {
            min: self.centre - r,
            max: self.centre + r,
        }
    }
}

impl SolidPrimitive for Torus {
    fn solid(&self, frame: &RasterFrame) -> Option<Box<dyn csg::Solid>> {
        Some(Box::new(geometry::Torus {
            centre: frame.to_fixed(self.centre)?,
            axis: unit_to_fixed(self.axis)?,
            major: frame.length_to_fixed(self.major, 1)?,
            minor: frame.length_to_fixed(self.minor, 1)?,
        }))
    }
}
