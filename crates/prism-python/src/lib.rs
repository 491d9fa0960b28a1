//! The native module of the `prism_renderer` Python package: a thin layer over the renderer's
//! Rust API (scene loading from files and dictionaries, rendering, the film's images and their
//! comparison, ray queries and what a scene is made of) with no rendering logic of its own. The Python package around it
//! (`python/prism_renderer`) adds the keyword-argument forms and the progress bar; its `.pyi`
//! stubs document every call.

mod dict;
mod error;
mod image;
mod image_files;
mod parameters;
mod render;
mod render_state;
mod scene;
mod transform;

use pyo3::prelude::*;

#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("PrismError", m.py().get_type::<error::PrismError>())?;
    m.add_class::<scene::Scene>()?;
    m.add_class::<transform::Transform>()?;
    m.add_class::<image::Image>()?;
    m.add_class::<image::Comparison>()?;
    m.add_class::<image::ChannelDifference>()?;
    m.add_class::<image::ZTest>()?;
    m.add_class::<parameters::SceneParameters>()?;
    m.add_class::<render_state::RenderState>()?;
    m.add_class::<scene::ray_queries::Ray3f>()?;
    m.add_class::<scene::ray_queries::SurfaceInteraction>()?;
    m.add_class::<scene::introspection::BoundingBox3f>()?;
    m.add_class::<scene::introspection::Shape>()?;
    m.add_class::<scene::introspection::Emitter>()?;
    m.add_class::<scene::introspection::Sensor>()?;
    m.add_function(wrap_pyfunction!(scene::load_file, m)?)?;
    m.add_function(wrap_pyfunction!(scene::load_dict, m)?)?;
    m.add_function(wrap_pyfunction!(scene::load_string, m)?)?;
    m.add_function(wrap_pyfunction!(render::render, m)?)?;
    m.add_function(wrap_pyfunction!(render_state::merge, m)?)?;
    m.add_function(wrap_pyfunction!(parameters::traverse, m)?)?;
    m.add_function(wrap_pyfunction!(image::compare, m)?)?;
    m.add_function(wrap_pyfunction!(image_files::read_image, m)?)?;
    m.add_function(wrap_pyfunction!(image_files::write_image, m)?)?;
    Ok(())
}
