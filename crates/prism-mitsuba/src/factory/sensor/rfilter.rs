//! Reconstruction filters: `box`, `tent`, `gaussian`, `mitchell`, `catmullrom` and `lanczos`.

use crate::description::{PluginClass, PluginNode};
use crate::params::Params;
use crate::registry::{Bounds, Default, Origin, ParamKind, ParamSpec, Plugin, Registry, params};
use prism_core::error::{Error, Result};
use prism_core::film::{
    BoxFilter, Filter, GaussianFilter, LanczosFilter, MitchellFilter, TentFilter,
};

type FilterBuild = fn(&Params) -> Result<Filter>;

pub static RFILTERS: Registry<FilterBuild> = Registry {
    class: PluginClass::Rfilter,
    plugins: &[
        Plugin {
            name: "box",
            origin: Origin::Mitsuba3,
            summary: "The box filter.",
            params: &[BOX_RADIUS],
            build: |params| {
                Ok(Filter::Box(BoxFilter {
                    radius: filter_size(params, &BOX_RADIUS)?,
                }))
            },
        },
        Plugin {
            name: "tent",
            origin: Origin::Mitsuba3,
            summary: "The tent (triangle) filter.",
            params: &[TENT_RADIUS],
            build: |params| {
                Ok(Filter::Tent(TentFilter {
                    radius: filter_size(params, &TENT_RADIUS)?,
                }))
            },
        },
        Plugin {
            name: "gaussian",
            origin: Origin::Mitsuba3,
            summary: "A Gaussian truncated at 4 standard deviations (Mitsuba's default filter).",
            params: &[STDDEV],
            build: |params| {
                Ok(Filter::Gaussian(GaussianFilter {
                    stddev: filter_size(params, &STDDEV)?,
                }))
            },
        },
        Plugin {
            name: "mitchell",
            origin: Origin::Mitsuba3,
            summary: "The Mitchell–Netravali filter, radius 2.",
            params: &[MITCHELL_B, MITCHELL_C],
            build: |params| {
                Ok(Filter::Mitchell(MitchellFilter {
                    b: params.float_in(&MITCHELL_B)? as f32,
                    c: params.float_in(&MITCHELL_C)? as f32,
                }))
            },
        },
        Plugin {
            name: "catmullrom",
            origin: Origin::Mitsuba3,
            summary: "The Catmull–Rom filter: Mitchell–Netravali with B = 0, C = ½.",
            params: &[],
            build: |_| Ok(Filter::Mitchell(MitchellFilter { b: 0.0, c: 0.5 })),
        },
        Plugin {
            name: "lanczos",
            origin: Origin::Mitsuba3,
            summary: "The windowed sinc filter.",
            params: &[LOBES],
            build: |params| {
                let lobes = params.integer(&LOBES)?;
                if !(1..=32).contains(&lobes) {
                    return Err(Error::input(
                        params.location_of(&LOBES),
                        format!("lanczos needs between 1 and 32 lobes, not {lobes}"),
                    ));
                }
                Ok(Filter::Lanczos(LanczosFilter {
                    lobes: lobes as u32,
                }))
            },
        },
    ],
};

params! {
    BOX_RADIUS = ParamSpec::new("radius", ParamKind::Float, Default::Float(0.5), "half width in pixels");
    TENT_RADIUS = ParamSpec::new("radius", ParamKind::Float, Default::Float(1.0), "half width in pixels");
    STDDEV = ParamSpec::new("stddev", ParamKind::Float, Default::Float(0.5), "standard deviation in pixels");
    MITCHELL_B = ParamSpec::new("B", ParamKind::FloatIn(Bounds::UNIT), Default::Float(1.0 / 3.0), "the blur parameter B");
    MITCHELL_C = ParamSpec::new("C", ParamKind::FloatIn(Bounds::UNIT), Default::Float(1.0 / 3.0), "the ringing parameter C");
    LOBES = ParamSpec::new("lobes", ParamKind::Integer, Default::Integer(3), "lobes of the sinc (1 to 32)");
}

pub(super) fn build_filter(node: &PluginNode) -> Result<Filter> {
    let plugin = RFILTERS.find(node)?;
    let params = Params::new(node, plugin.params);
    let filter = (plugin.build)(&params)?;
    params.finish()?;
    Ok(filter)
}

/// A filter's size parameter: positive, and at most 64 pixels.
fn filter_size(params: &Params, spec: &ParamSpec) -> Result<f32> {
    let v = params.float(spec)?;
    if !(v > 0.0 && v <= 64.0) {
        return Err(Error::input(
            params.location_of(spec),
            format!(
                "the filter's \"{}\" must be positive (and at most 64 pixels), not {v}",
                spec.name
            ),
        ));
    }
    Ok(v as f32)
}
