//! rrt on a host: NFF scenes, the camera, shading, fitting the raster to a
//! scene, exact reference intersections, and (to come) the renderer and
//! the `rrt` CLI.

#![forbid(unsafe_code)]

pub mod camera;
pub mod fit;
pub mod intersect;
pub mod scene;
pub mod shade;
