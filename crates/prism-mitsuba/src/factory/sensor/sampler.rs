//! Samplers: `independent`, `stratified`, `multijitter`, `nrooks`, `ldsampler` and `orthogonal`,
//! with their sample count and seed.

use crate::description::{PluginClass, PluginNode};
use crate::params::Params;
use crate::registry::{Default, Origin, ParamKind, ParamSpec, Plugin, Registry, params};
use prism_core::error::{Error, Result};
use prism_core::sampling::sampler::MAX_ORTHOGONAL_STRENGTH;
use prism_core::scene::{SamplerKind, SamplerSettings};

type SamplerBuild = fn(&Params) -> Result<SamplerKind>;

pub static SAMPLERS: Registry<SamplerBuild> = Registry {
    class: PluginClass::Sampler,
    plugins: &[
        Plugin {
            name: "independent",
            origin: Origin::Mitsuba3,
            summary: "Independent uniform random numbers.",
            params: &[SAMPLE_COUNT, SEED],
            build: |_| Ok(SamplerKind::Independent),
        },
        Plugin {
            name: "stratified",
            origin: Origin::Mitsuba3,
            summary: "Every dimension stratified, as Mitsuba does; `sample_count` is rounded up to a square.",
            params: &[SAMPLE_COUNT, SEED, JITTER],
            build: |params| {
                Ok(SamplerKind::Stratified {
                    jitter: params.boolean(&JITTER)?,
                })
            },
        },
        Plugin {
            name: "multijitter",
            origin: Origin::Mitsuba3,
            summary: "Correlated multi-jittered sampling, as Mitsuba does; `sample_count` is rounded up to a near-square product.",
            params: &[SAMPLE_COUNT, SEED, JITTER],
            build: |params| {
                Ok(SamplerKind::MultiJitter {
                    jitter: params.boolean(&JITTER)?,
                })
            },
        },
        Plugin {
            name: "nrooks",
            origin: Origin::Prism,
            summary: "The lecture's N-rooks sampling: each of the six primary dimensions (wavelength, \
                      time, film x and y, lens u and v) stratified into N strata, shuffled \
                      independently.",
            params: &[SAMPLE_COUNT, SEED],
            build: |_| Ok(SamplerKind::NRooks),
        },
        Plugin {
            name: "ldsampler",
            origin: Origin::Mitsuba3,
            summary: "Mitsuba 3's low-discrepancy sampler (and Mitsuba 0.6's of the same name): a scrambled (0, 2)-sequence shuffled per dimension; `sample_count` is rounded up to a square of a power of two.",
            params: &[SAMPLE_COUNT, SEED],
            build: |_| Ok(SamplerKind::LowDiscrepancy),
        },
        Plugin {
            name: "orthogonal",
            origin: Origin::Mitsuba3,
            summary: "Orthogonal array sampling (Jarosz et al. 2019), as Mitsuba 3 does: `sample_count` is rounded up to p^`strength` for a prime p.",
            params: &[SAMPLE_COUNT, SEED, JITTER, STRENGTH],
            build: |params| {
                let strength = params.integer(&STRENGTH)?;
                if !(1..=i64::from(MAX_ORTHOGONAL_STRENGTH)).contains(&strength) {
                    return Err(Error::input(
                        params.location_of(&STRENGTH),
                        format!(
                            "the orthogonal array's strength must be between 1 and {MAX_ORTHOGONAL_STRENGTH}, not {strength}"
                        ),
                    ));
                }
                Ok(SamplerKind::Orthogonal {
                    strength: strength as u32,
                    jitter: params.boolean(&JITTER)?,
                })
            },
        },
    ],
};

params! {
    STRENGTH = ParamSpec::new("strength", ParamKind::Integer, Default::Integer(2), "the orthogonal array's strength t: every t dimensions together are stratified (1 to 4)");
    SAMPLE_COUNT = ParamSpec::new("sample_count", ParamKind::Integer, Default::Integer(4), "samples per pixel (1 to 2²⁴)");
    SEED = ParamSpec::new("seed", ParamKind::Integer, Default::Integer(0), "seed of every random number (`--seed` overrides it)");
    JITTER = ParamSpec::new("jitter", ParamKind::Boolean, Default::Boolean(true), "jitter samples within their strata");
}

/// The sampler a node describes, with its seed.
pub(crate) fn build_sampler(node: &PluginNode) -> Result<(SamplerSettings, u64)> {
    let plugin = SAMPLERS.find(node)?;
    let params = Params::new(node, plugin.params);
    let kind = (plugin.build)(&params)?;
    let spp = params.integer(&SAMPLE_COUNT)?;
    if !(1..=(1 << 24)).contains(&spp) {
        return Err(Error::input(
            params.location_of(&SAMPLE_COUNT),
            format!("sample_count must be between 1 and {}, not {spp}", 1 << 24),
        ));
    }
    if kind.sample_count(spp as u32) > 1 << 24 {
        return Err(Error::input(
            params.location_of(&SAMPLE_COUNT),
            format!(
                "{} sampler rounds {spp} samples up to {}, more than {}",
                plugin.name,
                kind.sample_count(spp as u32),
                1 << 24
            ),
        )
        .with_help("ask for fewer samples, or a lower strength"));
    }
    let seed = params.integer(&SEED)?;
    params.finish()?;
    Ok((
        SamplerSettings {
            kind,
            samples_per_pixel: spp as u32,
        },
        seed as u64,
    ))
}
