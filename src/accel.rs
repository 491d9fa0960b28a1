//! `--accel`: which structure answers the renderer's ray queries, our BVH or, for comparison,
//! Embree (in builds with the cargo feature `embree`, whose `embree` module builds its scene).

use std::str::FromStr;
use std::sync::Arc;

use prism_core::error::{Error, Result};
use prism_core::geometry::{ExternalRayQueries, Geometry, Primitive};

/// Which structure answers the ray queries.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Accel {
    /// Our wide BVH ([`prism_core::geometry::bvh`]).
    #[default]
    Bvh,
    /// Embree 3's BVH (only in builds with the cargo feature `embree`).
    Embree,
}

impl Accel {
    /// Whether this build can use the structure: Embree needs the cargo feature `embree`.
    pub fn check_available(self) -> Result<()> {
        if self == Accel::Embree && !cfg!(feature = "embree") {
            return Err(embree_unavailable());
        }
        Ok(())
    }

    /// Makes this structure answer the geometry's queries (Embree's is built here; our BVH is
    /// kept, so that both can be compared on the same geometry). Instances keep their own BVH
    /// either way.
    pub fn apply(self, geometry: &mut Geometry) -> Result<()> {
        match self {
            Accel::Bvh => geometry.set_external(None),
            Accel::Embree => geometry.set_external(Some(embree_queries(geometry)?)),
        }
        Ok(())
    }

    /// The structure answering a geometry's queries.
    pub fn of(geometry: &Geometry) -> Accel {
        match geometry.external_name() {
            Some(_) => Accel::Embree,
            None => Accel::Bvh,
        }
    }
}

fn embree_unavailable() -> Error {
    Error::usage("this prism was built without Embree, so --accel embree is not available")
        .with_help(
            "run tools/install-embree, then rebuild with `cargo build --release --features embree`",
        )
}

#[cfg(feature = "embree")]
fn embree_queries(geometry: &Geometry) -> Result<Arc<dyn ExternalRayQueries<Primitive>>> {
    Ok(Arc::new(crate::embree::EmbreeScene::new(
        &geometry.primitives,
    )?))
}

#[cfg(not(feature = "embree"))]
fn embree_queries(_: &Geometry) -> Result<Arc<dyn ExternalRayQueries<Primitive>>> {
    Err(embree_unavailable())
}

impl FromStr for Accel {
    type Err = String;

    fn from_str(text: &str) -> std::result::Result<Accel, String> {
        match text {
            "bvh" => Ok(Accel::Bvh),
            "embree" => Ok(Accel::Embree),
            _ => Err(format!(
                "unknown acceleration structure \"{text}\": expected bvh or embree"
            )),
        }
    }
}
