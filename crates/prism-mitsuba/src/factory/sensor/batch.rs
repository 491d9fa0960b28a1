//! Mitsuba 3's `batch` sensor (`batch.cpp`): the nested sensors side by side on the batch's
//! film, whose width must be a multiple of their number.

use super::{BATCH_SENSORS, SensorSettings, build_sensor, sensor_parts, sensor_settings, shutter};
use crate::params::Params;
use glam::Vec2;
use prism_core::camera::{BatchSensor, Camera};
use prism_core::error::{Error, Result};

/// `batch`: each nested sensor is built as it stands (its field of view read against its own
/// film, as Mitsuba's constructor reads it), then sees a film of W/n × H pixels (Mitsuba's
/// `set_size` and `parameters_changed`); its film, sampler and shutter give way to the
/// batch's.
pub(super) fn build_batch(params: &Params, _thinlens: bool) -> Result<SensorSettings> {
    let mut parts = sensor_parts(params)?;
    let children = params.children(&BATCH_SENSORS);
    if children.is_empty() {
        return Err(Error::input(
            params.location(),
            "a batch sensor needs at least one nested <sensor>",
        ));
    }
    let count = children.len() as u32;
    let size = parts.film.size;
    if !size.x.is_multiple_of(count) {
        return Err(Error::input(
            params.location(),
            format!(
                "a batch of {count} sensors needs a film whose width is a multiple of {count}, \
                 not {}",
                size.x
            ),
        )
        .with_help("each sensor gets an equal share of the film's width"));
    }
    let sub_size = Vec2::new((size.x / count) as f32, size.y as f32);
    let mut sensors = Vec::with_capacity(children.len());
    for child in children {
        let sensor = build_sensor(&child.node)?;
        if let Some(medium) = &sensor.medium {
            return Err(Error::input(
                &medium.location,
                "a sensor in a batch cannot sit in a medium of its own",
            )
            .with_help("give the batch the <medium>: all its sensors sit in it"));
        }
        let camera = match sensor.camera {
            Camera::Perspective(mut camera) => {
                camera.film_size = sub_size;
                Camera::Perspective(camera)
            }
            Camera::Orthographic(mut camera) => {
                camera.film_size = sub_size;
                Camera::Orthographic(camera)
            }
            Camera::IrradianceMeter(_) | Camera::Batch(_) => {
                return Err(Error::input(
                    &child.location,
                    format!("a batch cannot hold {}", child.node.describe()),
                )
                .with_help("nest cameras, radiance meters and distant sensors"));
            }
            camera @ (Camera::RadianceMeter(_) | Camera::Distant(_)) => camera,
        };
        parts.warnings.extend(sensor.warnings);
        sensors.push(camera);
    }
    let shutter = shutter(params)?;
    let camera = Camera::Batch(BatchSensor {
        sensors,
        sub_width: sub_size.x,
    });
    sensor_settings(params, parts, camera, shutter)
}
