//! Integrator plugins: `path` (with Prism's `emitter_sampling`, see
//! [`prism_core::light::sampler`]), `direct`, `moment`, `aov`, the lecture's `distrib`, and
//! `volpath` and `volpathmis` for media, `ptracer`, the particle tracer, Mitsuba 0.6's
//! `bdpt`, bidirectional path tracing, `sppm`, stochastic progressive photon mapping, `vcm`,
//! vertex connection and merging, `guided_path`, Müller et al.'s practical path guiding (their
//! Mitsuba 0.6 plugin), and `stokes`, the polarized path tracer's Stokes vectors (a scene with a
//! polarizing BSDF gets the polarized path tracer in place of `path`: [`polarized_where_needed`]).

use glam::Vec3;

use crate::description::{PluginClass, PluginNode, Warning};
use crate::params::Params;
use crate::registry::{Choice, Default, Origin, ParamKind, ParamSpec, Plugin, Registry, params};
use crate::suggest::closest_match;
use prism_core::camera::Camera;
use prism_core::error::{Error, Result, SourceLocation};
use prism_core::film::output::IMAGE_CHANNELS;
use prism_core::integrator::aov::{Aov, AovKind};
use prism_core::integrator::distribution::DirectLights;
use prism_core::integrator::guided::selection::SelectionLoss;
use prism_core::integrator::guided::{Adrrs, Budget, NextEvent, SampleCombination, SpatialFilter};
use prism_core::integrator::{
    AovIntegrator, BdptIntegrator, DepthIntegrator, DirectIntegrator, DistributionIntegrator,
    GuidedPathIntegrator, Integrator, MomentIntegrator, ParticleTracer, PathIntegrator,
    PolarizedIntegrator, PolarizedPathIntegrator, PolarizedVolPathIntegrator, SppmIntegrator,
    StokesIntegrator, Tracking, VcmIntegrator, VolPathIntegrator,
};
use prism_core::light::{Light, LightSelection};

type Build = fn(&Params) -> Result<Integrator>;

pub static INTEGRATORS: Registry<Build> = Registry {
    class: PluginClass::Integrator,
    plugins: &[
        Plugin {
            name: "path",
            origin: Origin::Mitsuba3,
            summary: "Path tracing with next-event estimation, multiple importance sampling \
                      (power heuristic) and Russian roulette on the path's potential.",
            params: &[
                MAX_DEPTH,
                RR_DEPTH,
                HIDE_EMITTERS,
                EMITTER_SAMPLING,
                STRICT_NORMALS,
            ],
            build: build_path,
        },
        Plugin {
            name: "direct",
            origin: Origin::Mitsuba3,
            summary: "Direct illumination: light samples and BSDF samples at the first hit, \
                      combined by multiple importance sampling (power heuristic with the sample \
                      counts).",
            params: &[
                SHADING_SAMPLES,
                EMITTER_SAMPLES,
                BSDF_SAMPLES,
                HIDE_EMITTERS,
            ],
            build: build_direct,
        },
        Plugin {
            name: "moment",
            origin: Origin::Mitsuba3,
            summary: "Runs its nested integrators on each camera ray and writes, for each one \
                      named n (unnamed ones are _arg_0, _arg_1, ...), its XYZ estimate as the \
                      EXR channels n.X, n.Y, n.Z and their second moments as m2_n.X, m2_n.Y, \
                      m2_n.Z; the image is the first one's.",
            params: &[NESTED_INTEGRATORS],
            build: build_moment,
        },
        Plugin {
            name: "aov",
            origin: Origin::Mitsuba3,
            summary: "Arbitrary output variables of the first hit (albedo, depth, position, uv, \
                      geo_normal, sh_normal, dp_du, dp_dv, prim_index, shape_index) as EXR \
                      channels, beside each nested integrator's image as n.R, n.G, n.B, n.A; \
                      the image is the first nested integrator's.",
            params: &[AOVS, NESTED_IMAGE_INTEGRATORS],
            build: build_aov,
        },
        Plugin {
            name: "depth",
            origin: Origin::Mitsuba3,
            summary: "The distance from the camera to the first surface along each camera ray \
                      (0 where it leaves the scene), as a constant spectrum.",
            params: &[],
            build: |_| Ok(Integrator::Depth(DepthIntegrator)),
        },
        Plugin {
            name: "stokes",
            origin: Origin::Mitsuba3,
            summary: "Renders its nested `path`, `volpath` or `volpathmis` integrator polarized \
                      and writes the Stokes \
                      vector at the sensor as the EXR channels S0.R, S0.G, S0.B, … S3.B (each \
                      component as linear sRGB, in the sensor's frame, as Mitsuba 3); the \
                      image is S0, the intensity.",
            params: &[NESTED_POLARIZED],
            build: build_stokes,
        },
        Plugin {
            name: "distrib",
            origin: Origin::Prism,
            summary: "The lecture's distribution ray tracer: at a vertex N = clamp(round(\
                      bounce_samples · potential), 1, bounce_samples) bounce samples and as \
                      many shadow rays per light, Russian roulette with survival \
                      s = min(1, potential / rr_threshold), where the potential is the factor \
                      the vertex's estimate carries into the pixel.",
            params: &[
                MAX_DEPTH,
                BOUNCE_SAMPLES,
                SHADOW_RAYS,
                LIGHTS,
                RR_THRESHOLD,
                HIDE_EMITTERS,
            ],
            build: build_distrib,
        },
        Plugin {
            name: "volpath",
            origin: Origin::Mitsuba3,
            summary: "Volumetric path tracing: `path` with participating media between the \
                      surfaces, free flights by spectral tracking with one majorant for the \
                      path's four wavelengths, shadow rays through media (closed-form or \
                      ratio-tracking transmittance) and the null lobes of `null`, \
                      `thindielectric` and `mask` (no bounce, as in Mitsuba 3), light and \
                      phase samples in media combined by MIS.",
            params: &[MAX_DEPTH, RR_DEPTH, HIDE_EMITTERS, EMITTER_SAMPLING],
            build: build_volpath,
        },
        Plugin {
            name: "volpathmis",
            origin: Origin::Mitsuba3,
            summary: "Volumetric path tracing with spectral MIS (Miller, Georgiev & Jarosz \
                      2019): `volpath`'s path loop with the hero wavelength's free flights, \
                      combined over the path's four wavelengths and with light samples by the \
                      balance heuristic, so chromatic media stay free of fireflies.",
            params: &[
                MAX_DEPTH,
                RR_DEPTH,
                HIDE_EMITTERS,
                EMITTER_SAMPLING,
                USE_SPECTRAL_MIS,
            ],
            build: build_volpathmis,
        },
        Plugin {
            name: "ptracer",
            origin: Origin::Mitsuba3,
            summary: "The particle tracer: light subpaths from lights chosen by power, continued \
                      by sampling the adjoint BSDF with Russian roulette, connected to the \
                      camera at every surface and splatted through the reconstruction filter \
                      (plus light-source points connected straight to the camera); no media. \
                      Its error estimate is by batch means over sample indices.",
            params: &[MAX_DEPTH, RR_DEPTH, HIDE_EMITTERS, SAMPLES_PER_PASS],
            build: build_ptracer,
        },
        Plugin {
            name: "bdpt",
            origin: Origin::Mitsuba06,
            summary: "Bidirectional path tracing (Veach 1997, ch. 10): a camera subpath and a \
                      light subpath per sample, every pair of their vertices connected, all \
                      strategies weighted by the power heuristic; the light-tracing \
                      connections (t = 1) splatted through the reconstruction filter. Surfaces, \
                      area and point lights only; its error estimate is by batch means over \
                      sample indices.",
            params: &[
                MAX_DEPTH,
                RR_DEPTH,
                HIDE_EMITTERS,
                LIGHT_IMAGE,
                SAMPLE_DIRECT,
            ],
            build: build_bdpt,
        },
        Plugin {
            name: "sppm",
            origin: Origin::Mitsuba06,
            summary: "Stochastic progressive photon mapping (Hachisuka & Jensen 2009): per \
                      pass, one camera path per pixel to its first diffuse vertex (direct light \
                      by light sampling), photons from lights chosen by power gathered there \
                      within the pixel's radius, and the radius and flux updated by the \
                      progressive rule; one set of wavelengths per pass. Biased at any finite \
                      pass count (consistent): the EXR's variance channels are infinite, not \
                      an error bar. Checkpoints and resume continue a chain of passes bit for \
                      bit; a sample range is a chain of its own, and `prism merge` averages \
                      chains weighted by their passes (the bias stays one chain's); no media.",
            params: &[
                INITIAL_RADIUS,
                ALPHA,
                PHOTON_COUNT,
                MAX_PASSES,
                GRANULARITY,
                SPPM_MAX_DEPTH,
                SPPM_RR_DEPTH,
            ],
            build: build_sppm,
        },
        Plugin {
            name: "vcm",
            origin: Origin::Prism,
            summary: "Vertex connection and merging (Georgiev et al. 2012, with SmallVCM's \
                      recursive weights; the parameters of the `vcm` plugin of UPMM, a Mitsuba \
                      0.5 fork (xiaoyu-zhang-betsy/UPMM on GitHub), with SmallVCM's `alpha`): \
                      per iteration (sample index) one light subpath per pixel, connected to the camera and kept; then one camera subpath per \
                      pixel with light sampling, connections to its pixel's light subpath and \
                      merges with every kept light vertex within the radius r_i = r_1 \
                      i^((alpha-1)/2), all weighted by the power heuristic; one set of \
                      wavelengths per iteration. Biased at any finite sample count with merging \
                      (consistent): the EXR's variance is the spread over iterations, which \
                      leaves out the bias, and a target error is refused; `use_vm` false gives \
                      unbiased bidirectional path tracing. Surfaces, area and point lights only.",
            params: &[
                MAX_DEPTH,
                RR_DEPTH,
                HIDE_EMITTERS,
                LIGHT_IMAGE,
                VCM_INITIAL_RADIUS,
                RADIUS_SCALE,
                VCM_ALPHA,
                USE_VM,
            ],
            build: build_vcm,
        },
        Plugin {
            name: "guided_path",
            origin: Origin::Mitsuba06,
            summary: "Practical path guiding (Müller, Gross & Novák 2017; the authors' Mitsuba \
                      0.6 plugin): path tracing whose directions are drawn by one-sample MIS \
                      from the BSDF and from an SD-tree of incident radiance (a spatial binary \
                      tree of directional quadtrees) learned in iterations of doubling sample \
                      counts; next-event estimation as `path`, Russian roulette by the \
                      learned radiance (`adrrs`). The image \
                      is the last iteration's (or an inverse-variance mix of the last four); \
                      bit-identical for any thread count; one-pixel reconstruction; \
                      checkpoints and resume (bit-identical with a budget in samples); a \
                      sample range is a run of its own, and `prism merge` combines the runs' \
                      final images; no media.",
            params: &[
                MAX_DEPTH,
                RR_DEPTH,
                HIDE_EMITTERS,
                STRICT_NORMALS,
                SPP_PER_PASS,
                BUDGET_TYPE,
                BUDGET,
                SAMPLE_COMBINATION,
                S_TREE_THRESHOLD,
                D_TREE_THRESHOLD,
                BSDF_SAMPLING_FRACTION,
                NEE,
                SPATIAL_FILTER,
                DO_FILTERED_SPLATTING,
                DIRECTIONAL_FILTER,
                BSDF_SAMPLING_FRACTION_LOSS,
                SD_TREE_MAX_MEMORY,
                ADRRS,
                DUMP_SD_TREE,
            ],
            build: build_guided,
        },
    ],
};

/// The units of `guided_path`'s `budget`.
#[derive(Clone, Copy, Debug)]
enum BudgetType {
    Samples,
    Seconds,
}

params! {
    MAX_DEPTH = ParamSpec::new("max_depth", ParamKind::Integer, Default::Integer(-1), "longest path: −1 unbounded, 1 emitters only, 2 direct light");
    RR_DEPTH = ParamSpec::new("rr_depth", ParamKind::Integer, Default::Integer(5), "depth from which Russian roulette may end paths");
    HIDE_EMITTERS = ParamSpec::new("hide_emitters", ParamKind::Boolean, Default::Boolean(false), "leave emitters seen directly by the camera black");
    EMITTER_SAMPLING = ParamSpec::new("emitter_sampling", ParamKind::Choice(&[Choice::new("exhaustive", &LightSelection::Exhaustive), Choice::new("power", &LightSelection::Power), Choice::new("uniform", &LightSelection::Uniform)]), Default::Str("exhaustive"), "Prism only (Mitsuba rejects it): one light per shading point chosen ∝ its importance there (power × `sampling_weight` over squared distance, times the receiver's cosine bound; pbrt-v4's `exhaustive`), ∝ its power × `sampling_weight` everywhere alike (the lecture's), or ∝ `sampling_weight` alone (Mitsuba's rule; uniform by default)");
    USE_SPECTRAL_MIS = ParamSpec::new("use_spectral_mis", ParamKind::Boolean, Default::Boolean(true), "combine the four wavelengths' free-flight densities by MIS; false weights every wavelength by the hero's densities alone");
    STRICT_NORMALS = ParamSpec::new("strict_normals", ParamKind::Boolean, Default::Boolean(false), "Mitsuba 0.6 (`strictNormals`; Mitsuba 3 has none): end paths at directions the geometric and shading normals put on different sides");
    SHADING_SAMPLES = ParamSpec::new("shading_samples", ParamKind::Integer, Default::Integer(1), "sets both emitter_samples and bsdf_samples (not with either of them)");
    EMITTER_SAMPLES = ParamSpec::new("emitter_samples", ParamKind::Integer, Default::Text("shading_samples"), "light samples per camera ray");
    BSDF_SAMPLES = ParamSpec::new("bsdf_samples", ParamKind::Integer, Default::Text("shading_samples"), "BSDF samples per camera ray");
    NESTED_INTEGRATORS = ParamSpec::nested(PluginClass::Integrator, Default::Required, "the integrators whose moments are recorded (at least one), in order");
    NESTED_POLARIZED = ParamSpec::nested(PluginClass::Integrator, Default::Required, "the integrator rendered polarized: `path`, `volpath` or `volpathmis` (Prism's polarized estimators)");
    NESTED_IMAGE_INTEGRATORS = ParamSpec::nested(PluginClass::Integrator, Default::Text("none (a black image)"), "the integrators whose images are written beside the variables, in order");
    AOVS = ParamSpec::new("aovs", ParamKind::String, Default::Required, "comma-separated name:type pairs, e.g. \"dd.y:depth,nn:sh_normal,alb:albedo\"");
    BOUNCE_SAMPLES = ParamSpec::new("bounce_samples", ParamKind::Integer, Default::Integer(4), "bounce samples at potential 1 (1 to 1024)");
    SHADOW_RAYS = ParamSpec::new("shadow_rays", ParamKind::Integer, Default::Integer(4), "shadow rays per light at potential 1 (1 to 1024)");
    LIGHTS = ParamSpec::new("lights", ParamKind::Choice(&[Choice::new("exhaustive", &DirectLights::One(LightSelection::Exhaustive)), Choice::new("power", &DirectLights::One(LightSelection::Power)), Choice::new("uniform", &DirectLights::One(LightSelection::Uniform)), Choice::new("all", &DirectLights::All)]), Default::Str("exhaustive"), "one light per vertex chosen ∝ its importance there, ∝ power or uniformly (as the path integrator's `emitter_sampling`), or every light");
    SAMPLES_PER_PASS = ParamSpec::new("samples_per_pass", ParamKind::Integer, Default::Integer(-1), "the most samples per pixel a pass of the render takes (−1: as the render driver chooses)");
    LIGHT_IMAGE = ParamSpec::new("light_image", ParamKind::Boolean, Default::Boolean(true), "Mitsuba 0.6's `lightImage`: use the strategies that connect light subpaths to the camera (t = 1)");
    SAMPLE_DIRECT = ParamSpec::new("sample_direct", ParamKind::Boolean, Default::Boolean(true), "Mitsuba 0.6's `sampleDirect`: connect each camera vertex to a point drawn by light sampling (s = 1) rather than to the light subpath's first vertex");
    INITIAL_RADIUS = ParamSpec::new("initial_radius", ParamKind::Float, Default::Float(0.0), "the search radius every pixel starts with, in world units (0: five times the scene's bounding radius over the film's larger side, as Mitsuba 0.6)");
    ALPHA = ParamSpec::new("alpha", ParamKind::Float, Default::Float(0.7), "the fraction of a pass's photons a pixel keeps, which sets how fast its radius shrinks (0 < alpha < 1)");
    PHOTON_COUNT = ParamSpec::new("photon_count", ParamKind::Integer, Default::Integer(250_000), "light subpaths traced per pass (Mitsuba 0.6 counts photons stored instead)");
    MAX_PASSES = ParamSpec::new("max_passes", ParamKind::Integer, Default::Integer(-1), "passes to render, replacing the sample count (−1: the sample count, --spp, is the number of passes)");
    GRANULARITY = ParamSpec::new("granularity", ParamKind::Integer, Default::Integer(0), "light subpaths per parallel task (0: 4096); the image does not depend on it");
    SPPM_MAX_DEPTH = ParamSpec::new("max_depth", ParamKind::Integer, Default::Integer(-1), "longest path: −1 unbounded, 2 direct light, at least 2");
    SPPM_RR_DEPTH = ParamSpec::new("rr_depth", ParamKind::Integer, Default::Integer(3), "bounces after which Russian roulette may end photons and camera paths (Mitsuba 0.6's code uses 3)");
    VCM_INITIAL_RADIUS = ParamSpec::new("initial_radius", ParamKind::Float, Default::Float(0.0), "the merge radius of the first iteration before `radius_scale`, in world units (0: three times the scene's bounding radius over the film's larger side, as the UPMM plugin)");
    RADIUS_SCALE = ParamSpec::new("radius_scale", ParamKind::Float, Default::Float(1.0), "a factor on the initial radius (positive)");
    VCM_ALPHA = ParamSpec::new("alpha", ParamKind::Float, Default::Float(0.75), "the radius schedule r_i = r_1 i^((alpha-1)/2) of iteration i (0 < alpha < 1; SmallVCM's default)");
    USE_VM = ParamSpec::new("use_vm", ParamKind::Boolean, Default::Boolean(true), "merge camera vertices with light vertices; false leaves connections only (unbiased bidirectional path tracing)");
    SPP_PER_PASS = ParamSpec::new("spp_per_pass", ParamKind::Integer, Default::Integer(4), "samples per pixel of a pass; iteration k renders 2^k passes");
    BUDGET_TYPE = ParamSpec::new("budget_type", ParamKind::Choice(&[Choice::new("spp", &BudgetType::Samples), Choice::new("seconds", &BudgetType::Seconds)]), Default::Str("spp"), "what `budget` counts: samples per pixel or seconds, over all iterations (the authors' default is seconds)");
    BUDGET = ParamSpec::new("budget", ParamKind::Float, Default::Float(-1.0), "samples per pixel or seconds over all iterations (−1: the render's sample count, or its time limit; −1 for a sample range a..b with a > 0, whose run spends b − a; the authors' default is 300 seconds)");
    SAMPLE_COMBINATION = ParamSpec::new("sample_combination", ParamKind::Choice(&[Choice::new("discard", &SampleCombination::Discard), Choice::new("automatic", &SampleCombination::Automatic), Choice::new("inversevar", &SampleCombination::InverseVariance)]), Default::Str("automatic"), "the image: the last iteration's (`discard`), the same with training stopped where the extrapolated variance grows (`automatic`), or the last four iterations' weighted by their inverse variance (`inversevar`, one estimate per pixel: no error bar)");
    S_TREE_THRESHOLD = ParamSpec::new("s_tree_threshold", ParamKind::Float, Default::Float(12_000.0), "c: a spatial leaf splits where its recorded samples exceed c·√(2^k · spp_per_pass / 4) at iteration k");
    D_TREE_THRESHOLD = ParamSpec::new("d_tree_threshold", ParamKind::Float, Default::Float(0.01), "ρ: a quadrant splits where it holds more than this share of its quadtree's flux (0 < ρ < 1)");
    BSDF_SAMPLING_FRACTION = ParamSpec::new("bsdf_sampling_fraction", ParamKind::Float, Default::Float(0.5), "α: the probability of sampling the BSDF rather than the guide (0 < α ≤ 1; 0 would leave directions the guide has not seen unsampled)");
    NEE = ParamSpec::new("nee", ParamKind::Choice(&[Choice::new("never", &NextEvent::Never), Choice::new("kickstart", &NextEvent::Kickstart), Choice::new("always", &NextEvent::Always)]), Default::Str("always"), "light samples at every vertex (`always`, as `path`), while fewer than 128 spp have been rendered (`kickstart`), or none (`never`, the authors' default)");
    SPATIAL_FILTER = ParamSpec::new("spatial_filter", ParamKind::Choice(&[Choice::new("nearest", &SpatialFilter::Nearest), Choice::new("stochastic", &SpatialFilter::StochasticBox)]), Default::Str("nearest"), "where a record is filed: the vertex's leaf, or the leaf of a point jittered within a box of that leaf's size (`box`, the deterministic box filter, is not supported)");
    DO_FILTERED_SPLATTING = ParamSpec::new("do_filtered_splatting", ParamKind::Boolean, Default::Boolean(false), "the authors' earlier switch: true files records by the stochastic box filter (as spatial_filter = stochastic)");
    DIRECTIONAL_FILTER = ParamSpec::new("directional_filter", ParamKind::Choice(&[Choice::new("nearest", &())]), Default::Str("nearest"), "records go to the quadrant of their direction (`box` is not supported)");
    BSDF_SAMPLING_FRACTION_LOSS = ParamSpec::new("bsdf_sampling_fraction_loss", ParamKind::Choice(&[Choice::new("none", &SelectionLoss::None), Choice::new("kl", &SelectionLoss::KullbackLeibler), Choice::new("var", &SelectionLoss::Variance)]), Default::Str("none"), "α fixed at bsdf_sampling_fraction (`none`), or learned per spatial leaf by Adam on the KL divergence from the integrand to the mixture (`kl`) or on the estimate's variance (`var`)");
    SD_TREE_MAX_MEMORY = ParamSpec::new("sd_tree_max_memory", ParamKind::Integer, Default::Integer(-1), "megabytes of quadtrees beyond which spatial leaves stop splitting (−1: no limit)");
    ADRRS = ParamSpec::new("adrrs", ParamKind::Choice(&[Choice::new("off", &Adrrs::Off), Choice::new("roulette", &Adrrs::Roulette), Choice::new("split", &Adrrs::Splitting)]), Default::Str("roulette"), "Russian roulette (and splitting) by the learned radiance (Vorba & Křivánek 2016): from the second iteration on, a path whose expected contribution (its throughput times the indirect radiance its vertex's spatial leaf sent back in the previous iteration) falls below ⅓ of its pixel's estimate survives with that ratio as probability (at least 0.05), and elsewhere goes on; with `split`, one above 5⁄3 of it splits into that many paths (at most 8 per camera sample); `off`, and where nothing is learned: Russian roulette as `path`");
    DUMP_SD_TREE = ParamSpec::new("dump_sd_tree", ParamKind::Boolean, Default::Boolean(false), "must be false: Prism writes no SD-tree files");
    RR_THRESHOLD = ParamSpec::new("rr_threshold", ParamKind::Float, Default::Float(0.1), "potential below which Russian roulette starts");
}

/// Builds the integrator a node describes.
pub fn build_integrator(node: &PluginNode) -> Result<Integrator> {
    let plugin = INTEGRATORS.find(node)?;
    let params = Params::new(node, plugin.params);
    let integrator = (plugin.build)(&params)?;
    params.finish()?;
    Ok(integrator)
}

/// Refuses a scene integrator whose extra channels would take the name of an image channel.
pub fn check_channel_names(integrator: &Integrator, location: &SourceLocation) -> Result<()> {
    match integrator
        .aov_names()
        .into_iter()
        .find(|name| IMAGE_CHANNELS.contains(&name.as_str()))
    {
        Some(name) => Err(Error::input(
            location,
            format!("the integrator's channel \"{name}\" would replace the image's own"),
        )
        .with_help(format!(
            "rename the variable or nested integrator; the image's channels are {}",
            IMAGE_CHANNELS.join(", ")
        ))),
        None => Ok(()),
    }
}

/// `stokes`: its one nested integrator, `path`, `volpath` or `volpathmis`, rendered polarized.
fn build_stokes(params: &Params) -> Result<Integrator> {
    let nested = params.children(&NESTED_POLARIZED);
    let [child] = nested.as_slice() else {
        return Err(Error::input(
            params.location(),
            format!(
                "the stokes integrator needs exactly one nested integrator, found {}",
                nested.len()
            ),
        )
        .with_help("nest the integrator to render polarized: <integrator type=\"path\"/>"));
    };
    let nested = match build_integrator(&child.node)? {
        Integrator::Path(path) => PolarizedIntegrator::Path(PolarizedPathIntegrator { path }),
        Integrator::VolPath(volpath) => {
            PolarizedIntegrator::VolPath(PolarizedVolPathIntegrator { volpath })
        }
        _ => {
            return Err(Error::input(
                &child.location,
                format!(
                    "Prism renders only `path`, `volpath` and `volpathmis` polarized, so {} \
                     cannot be nested in \"stokes\"",
                    child.node.describe()
                ),
            )
            .with_help("nest <integrator type=\"path\"/> or <integrator type=\"volpath\"/>"));
        }
    };
    Ok(Integrator::Stokes(StokesIntegrator {
        nested,
        sensor_up: Vec3::Y,
    }))
}

/// The integrator a scene renders with: `path`, `volpath` and `volpathmis` become their
/// polarized estimators where the scene holds a polarizing BSDF (`polarizing`), as Mitsuba's
/// polarized variants render them; any other integrator is kept.
pub fn polarized_where_needed(integrator: Integrator, polarizing: bool) -> Integrator {
    match integrator {
        Integrator::Path(path) if polarizing => {
            Integrator::PolarizedPath(PolarizedPathIntegrator { path })
        }
        Integrator::VolPath(volpath) if polarizing => {
            Integrator::PolarizedVolPath(PolarizedVolPathIntegrator { volpath })
        }
        other => other,
    }
}

/// Gives the `stokes` integrator the up direction of the sensor it renders through, which
/// its Stokes frame follows.
pub fn aim_stokes(integrator: &mut Integrator, camera: &Camera) {
    let Integrator::Stokes(stokes) = integrator else {
        return;
    };
    let to_world = match camera {
        Camera::Perspective(c) => c.to_world.at(0.0),
        Camera::Orthographic(c) => c.to_world.at(0.0),
        Camera::RadianceMeter(c) => c.to_world.at(0.0),
        Camera::Distant(c) => c.to_world,
        Camera::IrradianceMeter(_) | Camera::Batch(_) => {
            stokes.sensor_up = Vec3::Y;
            return;
        }
    };
    stokes.sensor_up = to_world.vector(Vec3::Y).normalize();
}

/// `max_depth`: −1 (unbounded) or at least 0.
fn max_depth(params: &Params) -> Result<i32> {
    let max_depth = params.integer(&MAX_DEPTH)?;
    if max_depth < -1 || max_depth > i64::from(i32::MAX) {
        return Err(Error::input(
            params.location_of(&MAX_DEPTH),
            format!("max_depth must be -1 (unbounded) or at least 0, not {max_depth}"),
        ));
    }
    Ok(max_depth as i32)
}

/// `rr_depth`: at least 1.
fn rr_depth(params: &Params) -> Result<i32> {
    let rr_depth = params.integer(&RR_DEPTH)?;
    if rr_depth < 1 || rr_depth > i64::from(i32::MAX) {
        return Err(Error::input(
            params.location_of(&RR_DEPTH),
            format!("rr_depth must be at least 1, not {rr_depth}"),
        ));
    }
    Ok(rr_depth as i32)
}

/// A count that must be at least 1 (and sensible).
fn count(params: &Params, spec: &ParamSpec) -> Result<u32> {
    let value = params.integer(spec)?;
    if !(1..=1024).contains(&value) {
        return Err(Error::input(
            params.location_of(spec),
            format!("\"{}\" must be between 1 and 1024, not {value}", spec.name),
        ));
    }
    Ok(value as u32)
}

fn build_path(params: &Params) -> Result<Integrator> {
    Ok(Integrator::Path(PathIntegrator {
        strict_normals: params.boolean(&STRICT_NORMALS)?,
        ..path_settings(params)?
    }))
}

/// The settings `path` shares with `volpath` and `volpathmis`.
fn path_settings(params: &Params) -> Result<PathIntegrator> {
    let max_depth = max_depth(params)?;
    let rr_depth = rr_depth(params)?;
    let light_selection = params.choice(&EMITTER_SAMPLING)?;
    Ok(PathIntegrator {
        max_depth,
        rr_depth,
        hide_emitters: params.boolean(&HIDE_EMITTERS)?,
        light_selection,
        strict_normals: false,
    })
}

fn build_ptracer(params: &Params) -> Result<Integrator> {
    let samples_per_pass = match params.integer(&SAMPLES_PER_PASS)? {
        -1 => None,
        n if (1..=i64::from(u32::MAX)).contains(&n) => Some(n as u32),
        n => {
            return Err(Error::input(
                params.location_of(&SAMPLES_PER_PASS),
                format!("samples_per_pass must be -1 or at least 1, not {n}"),
            ));
        }
    };
    Ok(Integrator::Particle(ParticleTracer {
        max_depth: max_depth(params)?,
        rr_depth: rr_depth(params)?,
        hide_emitters: params.boolean(&HIDE_EMITTERS)?,
        samples_per_pass,
    }))
}

fn build_bdpt(params: &Params) -> Result<Integrator> {
    Ok(Integrator::Bdpt(BdptIntegrator {
        max_depth: max_depth(params)?,
        rr_depth: rr_depth(params)?,
        hide_emitters: params.boolean(&HIDE_EMITTERS)?,
        light_image: params.boolean(&LIGHT_IMAGE)?,
        sample_direct: params.boolean(&SAMPLE_DIRECT)?,
    }))
}

fn build_vcm(params: &Params) -> Result<Integrator> {
    let refuse =
        |spec: &ParamSpec, message: String| Err(Error::input(params.location_of(spec), message));
    let initial_radius = params.float(&VCM_INITIAL_RADIUS)?;
    if !(initial_radius.is_finite() && initial_radius >= 0.0) {
        return refuse(
            &VCM_INITIAL_RADIUS,
            format!(
                "initial_radius must be 0 (automatic) or a positive length, not {initial_radius}"
            ),
        );
    }
    let radius_scale = params.float(&RADIUS_SCALE)?;
    if !(radius_scale.is_finite() && radius_scale > 0.0) {
        return refuse(
            &RADIUS_SCALE,
            format!("radius_scale must be positive, not {radius_scale}"),
        );
    }
    let alpha = params.float(&VCM_ALPHA)?;
    if !(alpha > 0.0 && alpha < 1.0) {
        return refuse(
            &VCM_ALPHA,
            format!("alpha must lie strictly between 0 and 1, not {alpha}"),
        );
    }
    Ok(Integrator::Vcm(VcmIntegrator {
        max_depth: max_depth(params)?,
        rr_depth: rr_depth(params)?,
        hide_emitters: params.boolean(&HIDE_EMITTERS)?,
        light_image: params.boolean(&LIGHT_IMAGE)?,
        initial_radius: (initial_radius > 0.0).then_some(initial_radius as f32),
        radius_scale: radius_scale as f32,
        alpha: alpha as f32,
        merging: params.boolean(&USE_VM)?,
    }))
}

fn build_sppm(params: &Params) -> Result<Integrator> {
    let refuse =
        |spec: &ParamSpec, message: String| Err(Error::input(params.location_of(spec), message));
    let initial_radius = params.float(&INITIAL_RADIUS)?;
    if !(initial_radius.is_finite() && initial_radius >= 0.0) {
        return refuse(
            &INITIAL_RADIUS,
            format!(
                "initial_radius must be 0 (automatic) or a positive length, not {initial_radius}"
            ),
        );
    }
    let alpha = params.float(&ALPHA)?;
    if !(alpha > 0.0 && alpha < 1.0) {
        return refuse(
            &ALPHA,
            format!("alpha must lie strictly between 0 and 1, not {alpha}"),
        );
    }
    let photon_count = params.integer(&PHOTON_COUNT)?;
    if !(1..=i64::from(u32::MAX)).contains(&photon_count) {
        return refuse(
            &PHOTON_COUNT,
            format!("photon_count must be at least 1, not {photon_count}"),
        );
    }
    let max_passes = match params.integer(&MAX_PASSES)? {
        -1 => None,
        n if (1..=i64::from(u32::MAX)).contains(&n) => Some(n as u32),
        n => {
            return refuse(
                &MAX_PASSES,
                format!("max_passes must be -1 or at least 1, not {n}"),
            );
        }
    };
    let granularity = match params.integer(&GRANULARITY)? {
        0 => None,
        n if (1..=i64::from(u32::MAX)).contains(&n) => Some(n as u32),
        n => {
            return refuse(
                &GRANULARITY,
                format!("granularity must be 0 (automatic) or at least 1, not {n}"),
            );
        }
    };
    let max_depth = params.integer(&SPPM_MAX_DEPTH)?;
    if !(max_depth == -1 || (2..=i64::from(i32::MAX)).contains(&max_depth)) {
        return refuse(
            &SPPM_MAX_DEPTH,
            format!("max_depth must be -1 (unbounded) or at least 2, not {max_depth}"),
        );
    }
    let rr_depth = params.integer(&SPPM_RR_DEPTH)?;
    if !(1..=i64::from(i32::MAX)).contains(&rr_depth) {
        return refuse(
            &SPPM_RR_DEPTH,
            format!("rr_depth must be at least 1, not {rr_depth}"),
        );
    }
    Ok(Integrator::Sppm(SppmIntegrator {
        initial_radius: (initial_radius > 0.0).then_some(initial_radius as f32),
        alpha: alpha as f32,
        photon_count: photon_count as u32,
        max_passes,
        granularity,
        max_depth: max_depth as i32,
        rr_depth: rr_depth as i32,
    }))
}

/// The parameters of `guided_path`'s that name a value Prism does not implement, with why.
const UNSUPPORTED_GUIDING: [(&ParamSpec, &str, &str); 3] = [
    (
        &SPATIAL_FILTER,
        "box",
        "the box filter files each record into every leaf it overlaps; use \"stochastic\"",
    ),
    (
        &DIRECTIONAL_FILTER,
        "box",
        "records go to the quadrant of their direction only",
    ),
    (&DUMP_SD_TREE, "true", "Prism writes no SD-tree files"),
];

fn build_guided(params: &Params) -> Result<Integrator> {
    let refuse =
        |spec: &ParamSpec, message: String| Err(Error::input(params.location_of(spec), message));
    for (spec, value, why) in UNSUPPORTED_GUIDING {
        let given = match spec.kind {
            ParamKind::Boolean => params.boolean(spec)?.then_some("true"),
            _ => params.string_opt(spec)?,
        };
        if given.is_some_and(|v| v.eq_ignore_ascii_case(value)) {
            return refuse(
                spec,
                format!("{} = \"{value}\" is not supported: {why}", spec.name),
            );
        }
    }
    params.choice::<()>(&DIRECTIONAL_FILTER)?;
    let spp_per_pass = params.integer(&SPP_PER_PASS)?;
    if !(1..=1 << 16).contains(&spp_per_pass) {
        return refuse(
            &SPP_PER_PASS,
            format!("spp_per_pass must be between 1 and 65536, not {spp_per_pass}"),
        );
    }
    let budget = params.float(&BUDGET)?;
    if !(budget == -1.0 || (budget > 0.0 && budget.is_finite())) {
        return refuse(
            &BUDGET,
            format!("budget must be -1 (the render's) or positive, not {budget}"),
        );
    }
    let budget = match params.choice::<BudgetType>(&BUDGET_TYPE)? {
        BudgetType::Samples => {
            if budget > 0.0 && !(budget >= 1.0 && budget <= f64::from(u32::MAX / 2)) {
                return refuse(
                    &BUDGET,
                    format!("a budget of samples per pixel must be at least 1, not {budget}"),
                );
            }
            Budget::Samples((budget > 0.0).then_some(budget.round() as u32))
        }
        BudgetType::Seconds => Budget::Seconds((budget > 0.0).then_some(budget)),
    };
    let s_tree_threshold = params.float(&S_TREE_THRESHOLD)?;
    if !(s_tree_threshold > 0.0 && s_tree_threshold.is_finite()) {
        return refuse(
            &S_TREE_THRESHOLD,
            format!("s_tree_threshold must be positive, not {s_tree_threshold}"),
        );
    }
    let d_tree_threshold = params.float(&D_TREE_THRESHOLD)?;
    if !(d_tree_threshold > 0.0 && d_tree_threshold < 1.0) {
        return refuse(
            &D_TREE_THRESHOLD,
            format!("d_tree_threshold must lie strictly between 0 and 1, not {d_tree_threshold}"),
        );
    }
    let bsdf_sampling_fraction = params.float(&BSDF_SAMPLING_FRACTION)?;
    if !(bsdf_sampling_fraction > 0.0 && bsdf_sampling_fraction <= 1.0) {
        return refuse(
            &BSDF_SAMPLING_FRACTION,
            format!(
                "bsdf_sampling_fraction must be in (0, 1], not {bsdf_sampling_fraction}: without \
                 BSDF samples the directions the guide has not learned would never be sampled"
            ),
        );
    }
    let sd_tree_max_memory = match params.integer(&SD_TREE_MAX_MEMORY)? {
        -1 => None,
        n if (1..=i64::from(u32::MAX)).contains(&n) => Some(n as u32),
        n => {
            return refuse(
                &SD_TREE_MAX_MEMORY,
                format!("sd_tree_max_memory must be -1 (no limit) or at least 1, not {n}"),
            );
        }
    };
    let spatial_filter =
        if !params.has(&SPATIAL_FILTER) && params.boolean(&DO_FILTERED_SPLATTING)? {
            SpatialFilter::StochasticBox
        } else {
            params.choice(&SPATIAL_FILTER)?
        };
    Ok(Integrator::Guided(GuidedPathIntegrator {
        max_depth: max_depth(params)?,
        rr_depth: rr_depth(params)?,
        hide_emitters: params.boolean(&HIDE_EMITTERS)?,
        strict_normals: params.boolean(&STRICT_NORMALS)?,
        spp_per_pass: spp_per_pass as u32,
        budget,
        sample_combination: params.choice(&SAMPLE_COMBINATION)?,
        s_tree_threshold: s_tree_threshold as f32,
        d_tree_threshold: d_tree_threshold as f32,
        bsdf_sampling_fraction: bsdf_sampling_fraction as f32,
        bsdf_sampling_fraction_loss: params.choice(&BSDF_SAMPLING_FRACTION_LOSS)?,
        nee: params.choice(&NEE)?,
        spatial_filter,
        sd_tree_max_memory,
        adrrs: params.choice(&ADRRS)?,
    }))
}

/// A sample count of `direct`: 0 to 1024.
fn shading_count(params: &Params, spec: &ParamSpec, default: i64) -> Result<u32> {
    let value = params.integer_opt(spec)?.unwrap_or(default);
    if !(0..=1024).contains(&value) {
        return Err(Error::input(
            params.location_of(spec),
            format!("\"{}\" must be between 0 and 1024, not {value}", spec.name),
        ));
    }
    Ok(value as u32)
}

fn build_direct(params: &Params) -> Result<Integrator> {
    if params.has(&SHADING_SAMPLES) {
        for spec in [&EMITTER_SAMPLES, &BSDF_SAMPLES] {
            if params.has(spec) {
                return Err(Error::input(
                    params.location_of(spec),
                    format!("\"{}\" cannot be given with \"shading_samples\"", spec.name),
                )
                .with_help("give either shading_samples, or emitter_samples and bsdf_samples"));
            }
        }
    }
    let shading_samples = shading_count(params, &SHADING_SAMPLES, 1)?;
    let emitter_samples = shading_count(params, &EMITTER_SAMPLES, i64::from(shading_samples))?;
    let bsdf_samples = shading_count(params, &BSDF_SAMPLES, i64::from(shading_samples))?;
    if emitter_samples + bsdf_samples == 0 {
        return Err(Error::input(
            params.location(),
            "the direct integrator needs at least one emitter or BSDF sample",
        ));
    }
    Ok(Integrator::Direct(DirectIntegrator {
        emitter_samples,
        bsdf_samples,
        hide_emitters: params.boolean(&HIDE_EMITTERS)?,
    }))
}

/// Mitsuba 3's `direct` weighs each light sample by 1/`emitter_samples`, except a sample of a
/// delta light (its `mis` is 1 when `ds.delta`, without the weight), so with n > 1 emitter
/// samples its delta lights come out n times too bright. Prism does not copy that defect; this
/// is the warning, at the integrator's sample count, for a `direct` `node` with several emitter
/// samples in a scene with delta lights.
pub fn direct_delta_light_warning(
    node: &PluginNode,
    integrator: &Integrator,
    lights: &[Light],
) -> Option<Warning> {
    let Integrator::Direct(direct) = integrator else {
        return None;
    };
    let mut kinds: Vec<&str> = lights.iter().filter_map(delta_light_name).collect();
    kinds.sort_unstable();
    kinds.dedup();
    if direct.emitter_samples < 2 || kinds.is_empty() {
        return None;
    }
    let location = [EMITTER_SAMPLES.name, SHADING_SAMPLES.name]
        .iter()
        .find_map(|name| node.properties.iter().find(|p| p.name == *name))
        .map_or(&node.location, |property| &property.location);
    let n = direct.emitter_samples;
    Some(Warning {
        location: location.clone(),
        message: format!(
            "direct with {n} emitter samples in a scene with {} lights: Mitsuba 3 counts each \
             sample of a point, spot, projector or directional light with weight 1 instead of \
             1/{n}, so its image of them is {n} times too bright; Prism weighs every light \
             sample 1/{n}",
            kinds.join(", ")
        ),
    })
}

/// The Mitsuba name of a delta light (a point or a direction), None for other lights.
fn delta_light_name(light: &Light) -> Option<&'static str> {
    match light {
        Light::Point(_) => Some("point"),
        Light::Spot(_) => Some("spot"),
        Light::Projector(_) => Some("projector"),
        Light::Directional(_) => Some("directional"),
        Light::Area(_)
        | Light::DirectionalArea(_)
        | Light::Constant(_)
        | Light::Envmap(_)
        | Light::EqualAreaEnvmap(_)
        | Light::Sunsky(_) => None,
    }
}

/// The nested integrators of `spec`, each with the name its channels carry: its `name`
/// attribute, or `_arg_i` for the i-th unnamed one (as Mitsuba names unnamed nested objects).
fn named_integrators(params: &Params, spec: &ParamSpec) -> Result<Vec<(String, Integrator)>> {
    let children = params.children(spec);
    let mut integrators: Vec<(String, Integrator)> = Vec::with_capacity(children.len());
    let mut unnamed = 0;
    for child in children {
        let name = match &child.name {
            Some(name) => name.clone(),
            None => {
                unnamed += 1;
                format!("_arg_{}", unnamed - 1)
            }
        };
        if integrators.iter().any(|(n, _)| *n == name) {
            return Err(Error::input(
                &child.location,
                format!(
                    "two nested integrators of {} are named \"{name}\"",
                    params.node().describe()
                ),
            )
            .with_help(
                "give each nested integrator its own name (unnamed ones are called _arg_0, \
                 _arg_1, ... in order)",
            ));
        }
        integrators.push((name, build_integrator(&child.node)?));
    }
    Ok(integrators)
}

fn build_moment(params: &Params) -> Result<Integrator> {
    let integrators = named_integrators(params, &NESTED_INTEGRATORS)?;
    if integrators.is_empty() {
        return Err(Error::input(
            params.location(),
            "the moment integrator needs at least one nested integrator",
        )
        .with_help(
            "nest the integrator whose moments you want, e.g. <integrator type=\"path\"/>",
        ));
    }
    Ok(MomentIntegrator { integrators }.into())
}

/// Mitsuba's AOV types that Prism cannot produce, and why.
const UNSUPPORTED_AOVS: [(&str, &str); 3] = [
    ("duv_dx", "Prism's cameras trace no ray differentials"),
    ("duv_dy", "Prism's cameras trace no ray differentials"),
    (
        "boundary_test",
        "it serves differentiable rendering, which Prism does not do",
    ),
];

/// `aovs`: `name:type` pairs separated by commas (or spaces, as Mitsuba's tokenizer allows).
fn parse_aovs(params: &Params) -> Result<Vec<Aov>> {
    let location = params.location_of(&AOVS);
    let Some(list) = params.string_opt(&AOVS)? else {
        return Err(Error::input(
            params.location(),
            "the aov integrator needs \"aovs\", the variables to write",
        )
        .with_help("add e.g. <string name=\"aovs\" value=\"nn:sh_normal,alb:albedo\"/>"));
    };
    let names: Vec<&str> = AovKind::ALL.iter().map(|(name, _)| *name).collect();
    let mut aovs = Vec::new();
    for item in list.split([',', ' ']).filter(|item| !item.is_empty()) {
        let (name, kind) = match item.split(':').collect::<Vec<&str>>()[..] {
            [name, kind] if !name.is_empty() && !kind.is_empty() => (name, kind),
            _ => {
                return Err(Error::input(
                    location,
                    format!("\"{item}\" in \"aovs\" is not a name:type pair"),
                )
                .with_help("write each variable as name:type, e.g. nn:sh_normal"));
            }
        };
        if let Some((_, why)) = UNSUPPORTED_AOVS.iter().find(|(n, _)| *n == kind) {
            return Err(Error::input(
                location,
                format!("the AOV type \"{kind}\" is not supported: {why}"),
            )
            .with_help(format!("remove \"{item}\" from \"aovs\"")));
        }
        let Some((_, kind)) = AovKind::ALL.iter().find(|(n, _)| *n == kind) else {
            let mut error =
                Error::input(location, format!("unknown AOV type \"{kind}\" in \"aovs\""));
            error = match closest_match(kind, &names) {
                Some(close) => error.with_help(format!("did you mean \"{close}\"?")),
                None => error.with_help(format!("the types are {}", names.join(", "))),
            };
            return Err(error);
        };
        aovs.push(Aov {
            name: name.to_string(),
            kind: *kind,
        });
    }
    Ok(aovs)
}

fn build_aov(params: &Params) -> Result<Integrator> {
    let aovs = parse_aovs(params)?;
    let integrators = named_integrators(params, &NESTED_IMAGE_INTEGRATORS)?;
    let integrator = AovIntegrator { aovs, integrators };
    let names = integrator.aov_names();
    if names.is_empty() {
        return Err(Error::input(
            params.location_of(&AOVS),
            "the aov integrator has nothing to write: \"aovs\" is empty and no integrator is nested",
        ));
    }
    for (i, name) in names.iter().enumerate() {
        if names[..i].contains(name) {
            return Err(Error::input(
                params.location_of(&AOVS),
                format!("two of the aov integrator's channels are named \"{name}\""),
            )
            .with_help("give each variable and nested integrator its own name"));
        }
    }
    Ok(integrator.into())
}

fn build_volpath(params: &Params) -> Result<Integrator> {
    let path = path_settings(params)?;
    Ok(Integrator::VolPath(VolPathIntegrator {
        max_depth: path.max_depth,
        rr_depth: path.rr_depth,
        hide_emitters: path.hide_emitters,
        light_selection: path.light_selection,
        tracking: Tracking::Spectral,
    }))
}

fn build_volpathmis(params: &Params) -> Result<Integrator> {
    let Integrator::VolPath(volpath) = build_volpath(params)? else {
        unreachable!("build_volpath builds a volumetric path integrator");
    };
    Ok(Integrator::VolPath(VolPathIntegrator {
        tracking: Tracking::HeroMis {
            spectral_mis: params.boolean(&USE_SPECTRAL_MIS)?,
        },
        ..volpath
    }))
}

fn build_distrib(params: &Params) -> Result<Integrator> {
    let lights = params.choice(&LIGHTS)?;
    let rr_threshold = params.float(&RR_THRESHOLD)?;
    if !(rr_threshold > 0.0 && rr_threshold.is_finite()) {
        return Err(Error::input(
            params.location_of(&RR_THRESHOLD),
            format!("rr_threshold must be positive, not {rr_threshold}"),
        ));
    }
    Ok(Integrator::Distribution(DistributionIntegrator {
        max_depth: max_depth(params)?,
        bounce_samples: count(params, &BOUNCE_SAMPLES)?,
        shadow_rays: count(params, &SHADOW_RAYS)?,
        lights,
        rr_threshold: rr_threshold as f32,
        hide_emitters: params.boolean(&HIDE_EMITTERS)?,
    }))
}
