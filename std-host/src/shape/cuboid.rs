//! Axis-aligned boxes, as leaves of CSG trees (a TOML `box` object is six
//! polygons).

use rrt_core::csg;
use rrt_core::geometry;

use super::{Primitive, SolidPrimitive};
use crate::frame::RasterFrame;
use crate::world::Bounds;

/// An axis-aligned box, `min < max` on every axis.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cuboid {
    /// Lowest corner.
    pub min: glam::DVec3,
    /// Highest corner.
    pub max: glam::DVec3,
}

impl Primitive for Cuboid {
    const KIND: &'static str = "box";

    fn validate(&self) -> Result<(), &'static str> {
        if !(self.min.is_finite() && self.max.is_finite()) {
            return Err("corner not finite");
        }
        if !self.min.cmplt(self.max).all() {
            return Err("min not below max on every axis");
        }
        Ok(())
    }

    fn bounds(&self) -> Bounds {
        Bounds {
            min: self.min,
            max: self.max,
        }
    }
}

impl SolidPrimitive for Cuboid {
    fn solid(&self, frame: &RasterFrame) -> Option<Box<dyn csg::Solid>> {
        Some(Box::new(geometry::Cuboid {
            min: frame.to_fixed(self.min)?,
            max: frame.to_fixed(self.max)?,
        }))
    }
}
