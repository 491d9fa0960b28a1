//! Helpers shared by the integration tests: BSDFs queried outside a scene, scenes built in code
//! with statistics of their renders, and a writer of serialized meshes. The chi-square harness
//! itself is [`prism_core::sampling::chi2`].

pub mod bsdfs;
pub mod scenes;
pub mod serialized;
