//! The meters that measure over a surface or a direction rather than through a lens: Mitsuba
//! 3's `irradiancemeter` (nested in the shape it measures on) and `distant` (the radiance
//! leaving the scene in one direction, aimed at a point, a shape or the whole scene).

use std::sync::Arc;

use super::{
    DISTANT_DIRECTION, DISTANT_TARGET, DISTANT_TO_WORLD, IRRADIANCE_TO_WORLD, SENSORS,
    SensorSettings, check_one_pixel, ray_frame, sensor_parts, sensor_settings, shutter,
    warn_wide_filter,
};
use crate::description::{PluginClass, PluginNode, Warning};
use crate::factory::shapes;
use crate::params::Params;
use prism_core::camera::{Camera, DistantSensor, DistantTarget, IrradianceMeter};
use prism_core::error::{Error, Result};
use prism_core::film::{BoxFilter, Filter};
use prism_core::geometry::{Primitive, Shape, ShapeGeometry};
use prism_core::math::Transform;

/// A top-level `<sensor type="irradiancemeter">`: it has no shape to measure on.
pub(super) fn build_irradiancemeter_alone(
    params: &Params,
    _thinlens: bool,
) -> Result<SensorSettings> {
    Err(Error::input(
        params.location(),
        "an irradiancemeter measures on a shape: it must be nested in the <shape>",
    )
    .with_help("move the <sensor type=\"irradiancemeter\"> into the <shape> it measures on"))
}

/// The sensor nested in a `<shape>` (an `irradiancemeter`, Mitsuba 3's `irradiancemeter.cpp`),
/// measuring on `shape`, the shape built in world space.
pub fn build_shape_sensor(
    node: &PluginNode,
    shape_node: &PluginNode,
    shape: &Primitive,
) -> Result<SensorSettings> {
    let plugin = SENSORS.find(node)?;
    if plugin.name != "irradiancemeter" {
        return Err(Error::input(
            &node.location,
            format!(
                "a shape can carry an irradiancemeter, not {}",
                node.describe()
            ),
        )
        .with_help("place other sensors at the top level of the scene"));
    }
    let params = Params::new(node, plugin.params);
    if params.has(&IRRADIANCE_TO_WORLD) {
        return Err(Error::input(
            params.location_of(&IRRADIANCE_TO_WORLD),
            "an irradiancemeter takes its placement from its shape: it has no \"to_world\"",
        )
        .with_help("move the transform to the shape"));
    }
    let shape = measured_shape(shape, shape_node, &node.location)?;
    let mut parts = sensor_parts(&params)?;
    if !matches!(parts.film.filter, Filter::Box(_)) {
        parts.warnings.push(Warning {
            location: params.location().clone(),
            message: "an irradiancemeter's film samples positions on its shape: Prism gives it a \
                      box filter (Mitsuba weights the positions by the film's filter, which \
                      biases the irradiance; it advises the box)"
                .into(),
        });
        parts.film.filter = Filter::Box(BoxFilter { radius: 0.5 });
    }
    let shutter = shutter(&params)?;
    let camera = Camera::IrradianceMeter(IrradianceMeter {
        shape,
        film_size: parts.film.size.as_vec2(),
    });
    let sensor = sensor_settings(&params, parts, camera, shutter)?;
    params.finish()?;
    Ok(sensor)
}

/// A shape a sensor samples by area: in world space, still, and with an area.
fn measured_shape(
    shape: &Primitive,
    shape_node: &PluginNode,
    sensor: &prism_core::error::SourceLocation,
) -> Result<Arc<Shape>> {
    let Primitive::Shape(shape) = shape else {
        return Err(Error::input(
            sensor,
            format!(
                "{} moves during the exposure: a sensor cannot measure on a moving shape",
                shape_node.describe()
            ),
        )
        .with_help("give the shape a fixed to_world"));
    };
    if !(shape.area() > 0.0) {
        return Err(Error::input(
            sensor,
            format!(
                "{} has no area for a sensor to sample points on",
                shape_node.describe()
            ),
        )
        .with_help("use a mesh, a sphere, a disk or a cylinder"));
    }
    Ok(Arc::new(shape.clone()))
}

/// `distant` (Mitsuba 3's `distant.cpp`): `to_world` or `direction` (not both), and a
/// `target` point or nested shape, or none; a film of one pixel.
pub(super) fn build_distant(params: &Params, _thinlens: bool) -> Result<SensorSettings> {
    let mut parts = sensor_parts(params)?;
    check_one_pixel(params, &parts)?;
    warn_wide_filter(params, &mut parts);
    let direction = params.vector_opt(&DISTANT_DIRECTION)?;
    let to_world = match direction {
        Some(direction) => {
            if params.property(&DISTANT_TO_WORLD).is_some() {
                return Err(Error::input(
                    params.location_of(&DISTANT_DIRECTION),
                    "a distant sensor takes either \"direction\" or \"to_world\", not both",
                ));
            }
            ray_frame(glam::DVec3::ZERO, direction).ok_or_else(|| {
                Error::input(
                    params.location_of(&DISTANT_DIRECTION),
                    format!("the distant sensor's direction {direction} has no length"),
                )
            })?
        }
        None => match params.transform_opt(&DISTANT_TO_WORLD)? {
            Some(matrix) => Transform::new(matrix).ok_or_else(|| {
                Error::input(
                    params.location_of(&DISTANT_TO_WORLD),
                    "the distant sensor's to_world cannot be inverted",
                )
            })?,
            None => Transform::IDENTITY,
        },
    };
    let target = distant_target(params)?;
    let shutter = shutter(params)?;
    let camera = Camera::Distant(DistantSensor::new(to_world, target));
    sensor_settings(params, parts, camera, shutter)
}

/// The `target` of a distant sensor: a `<point name="target">` (or a `<vector>`, as Mitsuba
/// reads either), a nested `<shape name="target">` (built in world space, sampled by area, not
/// part of the scene), or none (the scene's cross-section).
fn distant_target(params: &Params) -> Result<DistantTarget> {
    if let Some(point) = params.vector_opt(&DISTANT_TARGET)? {
        return Ok(DistantTarget::Point(point.as_vec3()));
    }
    let Some(child) = params.named_child(&DISTANT_TARGET) else {
        return Ok(DistantTarget::Scene);
    };
    if child.node.class != PluginClass::Shape {
        return Err(Error::input(
            &child.location,
            format!(
                "a distant sensor's target is a point or a shape, not {}",
                child.node.describe()
            ),
        ));
    }
    let (plugin, shape_params) = shapes::shape_params(&child.node)?;
    let shape = shapes::build_shape(plugin, &shape_params)?;
    shape_params.finish()?;
    let shape = measured_shape(&shape, &child.node, &child.location)?;
    Ok(DistantTarget::Shape(shape))
}
