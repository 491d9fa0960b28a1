//! Shapes and meshes: curves, the cylinder, ellipsoids, instancing, mesh attributes and serialized meshes.

mod bspline_curve;
mod cylinder;
mod ellipsoids;
mod instancing;
mod linear_curve;
mod mesh_attribute;
mod serialized;
