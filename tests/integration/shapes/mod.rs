//! Shapes and meshes: curves, the cylinder, ellipsoids, SDF grids, instancing, mesh attributes, serialized meshes and the tensor forms of ellipsoids and SDF grids.

mod bspline_curve;
mod cylinder;
mod ellipsoids;
mod instancing;
mod linear_curve;
mod mesh_attribute;
mod sdf_grid;
mod serialized;
mod tensors;
