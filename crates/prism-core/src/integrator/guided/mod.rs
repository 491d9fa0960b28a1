//! Practical path guiding (Müller, Gross & Novák 2017, "Practical Path Guiding for Efficient
//! Light-Transport Simulation"; the authors' Mitsuba 0.6 integrator `guided_path`, with the
//! defaults of Müller's 2019 course notes, "Practical Path Guiding in Production"): a path
//! tracer whose directions are drawn partly from a distribution of incident radiance learned
//! while rendering, the SD-tree ([`sd_tree`], [`quadtree`]).
//!
//! Its parameters (`sppPerPass`, `budgetType`, `budget`, `sampleCombination`,
//! `sTreeThreshold`, `dTreeThreshold`, `bsdfSamplingFraction`, `nee`, `spatialFilter`,
//! `sdTreeMaxMemory`, `maxDepth`, `rrDepth`, `strictNormals`, `hideEmitters`) and their
//! defaults are listed in docs/plugins.md. The render driver (`render::guided`) runs the
//! iterations.
//!
//! **Iterations.** Iteration k renders 2ᵏ passes of `sppPerPass` samples per pixel (the last
//! one takes what is left of the budget, at least half of it). Each iteration's paths sample
//! from the SD-tree learned in the iteration before and record into a fresh one; the image is
//! the last iteration's (`discard`, `automatic`, which may also stop training early when the
//! extrapolated variance grows) or the inverse-variance-weighted mean of the last four
//! (`inversevar`). The first iteration has nothing to learn from and samples the BSDF alone.
//!
//! **A vertex** with a smooth lobe draws its direction by one-sample MIS between the BSDF,
//! with probability α, and the quadtree of the spatial leaf holding the vertex (of the
//! orientation class of its surface's front side, [`sd_tree`]), with probability 1 − α
//! (folded onto the side of the surface the path arrived from where the BSDF only reflects,
//! [`vertex_guide`]), and weighs the sample by the mixture's density
//! p(ω) = α p_bsdf(ω) + (1 − α) p_guide(ω), so the estimator f cos θ L / p is unbiased for any
//! learned distribution (α > 0 keeps p > 0 wherever the BSDF scatters). α is
//! `bsdfSamplingFraction`, or, with a `bsdfSamplingFractionLoss`, learned per spatial leaf and
//! orientation class from the records filed there ([`selection`]). A delta lobe drawn from
//! the BSDF keeps its own weight divided by α; BSDFs without smooth lobes are
//! sampled as the path tracer samples them. Next-event estimation (`nee`, by default
//! `always`) takes one light sample per vertex as `path` does, weighed against the mixture's
//! density by the power heuristic, as is the emission a sampled direction finds; Russian
//! roulette is `path`'s.
//!
//! **Recording.** Where the path has gone on from a vertex with a smooth lobe, the radiance
//! its later vertices bring back, divided by the throughput to the vertex, estimates the
//! incident radiance L_i along the sampled direction ω (per wavelength; their mean is
//! recorded). The vertex records L_i / p(ω) at ω in its leaf's recording quadtree, with
//! statistical weight 1. With next-event estimation on (`always`), the emission the vertex's
//! own sample finds is left out of its record: it is the light samples' part, so the guide
//! learns the indirect light (as the authors' code does); with `nee` = `never` it is
//! recorded, and with `kickstart` (light samples only while fewer than 128 samples per pixel
//! have been rendered) the light sample is recorded as a sample of its own, both with weight
//! ½. `spatialFilter` = `stochastic` jitters the point a record is filed under by up to half
//! its leaf's extent (the authors' stochastic box filter).
//!
//! The tree is read-only while a pass renders: each tile collects its records, and they are
//! filed into the tree after the pass in the order of the tiles, so the image is bit-identical
//! for any thread count.
//!
//! No participating media: scenes with media are refused when read.

pub mod quadtree;
pub mod sd_tree;
pub mod selection;
pub mod vertex_guide;

use std::f32::consts::PI;

use glam::{Vec2, Vec3};

use crate::bsdf::{BsdfFlags, BxdfTree};
use crate::integrator::SampleContext;
use crate::integrator::mis::{
    ScatterOrigin, Strategies, emission_found, power_heuristic, sample_light, unoccluded,
};
use crate::integrator::transmittance::ShadowTransmittance;
use crate::integrator::vertex::{
    allows_next_vertex, normals_agree, path_estimate, russian_roulette, surface_scattering,
    wavelengths_after,
};
use crate::light::Receiver;
use crate::math::Ray;
use crate::spectrum::{SampledSpectrum, SampledWavelengths};
use sd_tree::{SdTree, SpatialLeaf, orientation};
use selection::{SelectionLoss, SelectionSample};
use vertex_guide::VertexGuide;

/// How the iterations' images make the final one.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SampleCombination {
    /// The last iteration's image alone.
    Discard,
    /// The last iteration's image, training stopped early where the extrapolated variance of
    /// the next iteration's image grows (the authors' default).
    Automatic,
    /// The last four iterations' images weighted by their inverse mean pixel variance.
    InverseVariance,
}

/// What the render may spend.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Budget {
    /// Samples per pixel over all iterations (None: the render's sample count).
    Samples(Option<u32>),
    /// Seconds over all iterations (None: the render's time limit).
    Seconds(Option<f64>),
}

/// When paths take light samples.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum NextEvent {
    Never,
    /// While fewer than 128 samples per pixel have been rendered.
    Kickstart,
    Always,
}

/// Where a vertex's record is filed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SpatialFilter {
    /// In the leaf holding the vertex.
    Nearest,
    /// In the leaf holding the vertex jittered uniformly within a box of its leaf's size.
    StochasticBox,
}

#[derive(Clone, Debug)]
pub struct GuidedPathIntegrator {
    /// Longest path in vertices after the camera; negative for unbounded.
    pub max_depth: i32,
    /// Depth from which Russian roulette is used.
    pub rr_depth: i32,
    /// Whether emitters seen directly by the camera are left black.
    pub hide_emitters: bool,
    /// Whether directions the geometric and shading normals disagree about end the path.
    pub strict_normals: bool,
    /// Samples per pixel of a pass; iteration k renders 2ᵏ passes.
    pub spp_per_pass: u32,
    pub budget: Budget,
    pub sample_combination: SampleCombination,
    /// c of the spatial split threshold c·√(2ᵏ · `spp_per_pass` / 4).
    pub s_tree_threshold: f32,
    /// ρ, the share of a quadtree's flux above which a quadrant is split.
    pub d_tree_threshold: f32,
    /// α, the probability of sampling the BSDF rather than the guide, where it is not learned.
    pub bsdf_sampling_fraction: f32,
    /// The loss α is learned by per spatial leaf (`bsdfSamplingFractionLoss`, [`selection`]).
    pub bsdf_sampling_fraction_loss: SelectionLoss,
    pub nee: NextEvent,
    pub spatial_filter: SpatialFilter,
    /// Megabytes beyond which the spatial tree stops splitting (None: no limit).
    pub sd_tree_max_memory: Option<u32>,
}

impl Default for GuidedPathIntegrator {
    fn default() -> Self {
        GuidedPathIntegrator {
            max_depth: -1,
            rr_depth: 5,
            hide_emitters: false,
            strict_normals: false,
            spp_per_pass: 4,
            budget: Budget::Samples(None),
            sample_combination: SampleCombination::Automatic,
            s_tree_threshold: 12_000.0,
            d_tree_threshold: 0.01,
            bsdf_sampling_fraction: 0.5,
            bsdf_sampling_fraction_loss: SelectionLoss::None,
            nee: NextEvent::Always,
            spatial_filter: SpatialFilter::Nearest,
            sd_tree_max_memory: None,
        }
    }
}

/// What the paths of a pass guide themselves by and record.
pub struct Guide<'a> {
    pub tree: &'a SdTree,
    /// Whether the tree has learned from an iteration (before that, paths sample the BSDF).
    pub trained: bool,
    /// Whether paths take light samples.
    pub light_samples: bool,
    /// The statistical weight of the records, or None where the pass records nothing.
    pub record_weight: Option<f32>,
}

/// A sample of incident radiance to file in the recording tree of spatial leaf `leaf`.
#[derive(Clone, Copy, Debug)]
pub struct Record {
    pub leaf: u32,
    /// The direction, on the unit square.
    pub point: Vec2,
    /// L_i / p(ω).
    pub flux: f32,
    pub weight: f32,
    /// What the record brings to the leaf's learned α, where it is learned.
    pub selection: Option<SelectionSample>,
}

/// The point of the unit square (cylindrical coordinates) of the unit direction `d`.
#[inline]
pub fn direction_to_square(d: Vec3) -> Vec2 {
    if !d.is_finite() {
        return Vec2::ZERO;
    }
    let phi = d.y.atan2(d.x);
    let phi = if phi < 0.0 { phi + 2.0 * PI } else { phi };
    Vec2::new(
        (d.z.clamp(-1.0, 1.0) + 1.0) * 0.5,
        (phi / (2.0 * PI)).clamp(0.0, 1.0),
    )
}

/// The unit direction of the point `p` of the unit square.
#[inline]
pub fn square_to_direction(p: Vec2) -> Vec3 {
    let cos_theta = 2.0 * p.x - 1.0;
    let sin_theta = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
    let (sin_phi, cos_phi) = (2.0 * PI * p.y).sin_cos();
    Vec3::new(sin_theta * cos_phi, sin_theta * sin_phi, cos_theta)
}

/// Vertices a path records at most (the authors' limit).
const MAX_RECORDED_VERTICES: usize = 32;

/// A vertex that will record the radiance its path brings back.
#[derive(Clone, Copy, Debug)]
struct RecordingVertex {
    leaf: SpatialLeaf,
    /// The orientation class of the surface's front side.
    class: u32,
    p: Vec3,
    point: Vec2,
    /// The path's throughput once the vertex's sample is taken.
    throughput: SampledSpectrum,
    /// The radiance the path has brought back through the vertex.
    radiance: SampledSpectrum,
    pdf: f32,
    /// f cos θ at the sampled direction, and the BSDF's and the guide's densities there, where
    /// the vertex trains its leaf's α.
    selection: Option<(SampledSpectrum, f32, f32)>,
}

/// The recording vertices of a path.
struct RecordingVertices {
    vertices: [Option<RecordingVertex>; MAX_RECORDED_VERTICES],
    count: usize,
    /// Whether the last vertex is the one the current ray left from.
    last_is_current: bool,
}

impl RecordingVertices {
    fn new() -> Self {
        RecordingVertices {
            vertices: [None; MAX_RECORDED_VERTICES],
            count: 0,
            last_is_current: false,
        }
    }

    /// Adds `radiance` to every vertex's, except (with `skip_current`) the one the current ray
    /// left from.
    fn add(&mut self, radiance: SampledSpectrum, skip_current: bool) {
        let end = if skip_current && self.last_is_current {
            self.count - 1
        } else {
            self.count
        };
        for v in self.vertices[..end].iter_mut().flatten() {
            v.radiance += radiance;
        }
    }

    fn push(&mut self, vertex: Option<RecordingVertex>) {
        self.last_is_current = false;
        if let Some(v) = vertex
            && self.count < MAX_RECORDED_VERTICES
        {
            self.vertices[self.count] = Some(v);
            self.count += 1;
            self.last_is_current = true;
        }
    }
}

/// `radiance` / `throughput` per wavelength, where the throughput is not negligible: the
/// incident radiance a recording vertex brings.
fn incident_radiance(
    radiance: SampledSpectrum,
    throughput: SampledSpectrum,
    pdf: f32,
) -> SampledSpectrum {
    SampledSpectrum::from_fn(|i| {
        if throughput[i] * pdf > 1e-4 {
            radiance[i] / throughput[i]
        } else {
            0.0
        }
    })
}

impl GuidedPathIntegrator {
    /// The estimate along the camera ray `ray` at `wavelengths`, guided by `guide`; the path's
    /// records go to `records`.
    pub fn radiance(
        &self,
        ctx: &mut SampleContext,
        ray: Ray,
        wavelengths: &SampledWavelengths,
        guide: &Guide,
        records: &mut Vec<Record>,
    ) -> SampledSpectrum {
        if self.max_depth == 0 {
            return SampledSpectrum::ZERO;
        }
        let world = ctx.world();
        let learns_alpha = self.bsdf_sampling_fraction_loss != SelectionLoss::None;
        let strategies = Strategies {
            light_samples: if guide.light_samples { 1.0 } else { 0.0 },
            bsdf_samples: 1.0,
        };
        // With light samples always on, what a vertex's own sample finds is theirs to learn.
        let own_emission_is_direct = guide.light_samples && self.nee == NextEvent::Always;
        let mut ray = ray;
        let mut lambda = *wavelengths;
        let mut result = SampledSpectrum::ZERO;
        let mut throughput = SampledSpectrum::ONE;
        let mut eta_scale = 1.0f32;
        let mut previous: Option<ScatterOrigin> = None;
        let mut depth = 0i32;
        let mut recording = RecordingVertices::new();
        let mut lobes = BxdfTree::empty();
        loop {
            let hit = ctx.intersect(&ray);
            if !(self.hide_emitters && depth == 0) {
                let found = throughput
                    * emission_found(
                        ctx,
                        &ray,
                        hit.as_ref(),
                        previous.as_ref(),
                        &lambda,
                        strategies,
                    );
                if !found.is_black() {
                    result += found;
                    recording.add(found, own_emission_is_direct);
                }
            }
            let Some(si) = hit else {
                break;
            };
            let wo = -ray.d.normalize();
            if !allows_next_vertex(self.max_depth, depth)
                || (self.strict_normals && !normals_agree(&si, wo))
            {
                break;
            }
            let scattering = surface_scattering(world, &si, wo, &mut lambda, &mut lobes);
            let smooth = scattering.flags().has_smooth_lobe();
            let side = wo.dot(si.shading.n);
            let front = if side < 0.0 {
                -si.shading.n
            } else {
                si.shading.n
            };
            let class = orientation(front);
            let leaf = smooth.then(|| guide.tree.leaf_at(si.p, class));
            let reflects_only = !scattering.flags().contains(BsdfFlags::TRANSMISSION);
            let trees = leaf.filter(|_| guide.trained).map(|l| {
                let tree = &guide.tree.leaf(l.index).sampling;
                if reflects_only && side != 0.0 {
                    VertexGuide::folded(tree, front)
                } else {
                    VertexGuide::sphere(tree)
                }
            });
            let alpha = match leaf {
                Some(l) if learns_alpha && guide.trained => {
                    guide.tree.leaf(l.index).selection.fraction()
                }
                _ => self.bsdf_sampling_fraction,
            };
            let mixture = |bsdf_pdf: f32, wi: Vec3| match trees {
                Some(tree) => alpha * bsdf_pdf + (1.0 - alpha) * tree.pdf(wi),
                None => bsdf_pdf,
            };

            if guide.light_samples && smooth {
                let receiver = Receiver::surface(si.p, si.shading.n);
                let mut light_direction = Vec3::ZERO;
                let light = sample_light(ctx, &receiver, si.time, &lambda, |ctx, ls| {
                    if self.strict_normals && !normals_agree(&si, ls.wi) {
                        return None;
                    }
                    let mut f = unoccluded(ctx, &si, &scattering, ls)?;
                    f.pdf = mixture(f.pdf, ls.wi);
                    light_direction = ls.wi;
                    Some((f, ShadowTransmittance::ONE))
                });
                if let Some(light) = light {
                    let contribution = throughput * light.weighted(strategies);
                    result += contribution;
                    recording.add(contribution, false);
                    if let (Some(weight), Some(leaf)) = (guide.record_weight, leaf)
                        && self.nee == NextEvent::Kickstart
                        && !light.is_delta
                    {
                        let w = power_heuristic(light.light_pdf, light.direction_pdf);
                        records.push(Record {
                            leaf: leaf.index,
                            point: direction_to_square(light_direction),
                            flux: (light.radiance * w).average() / light.light_pdf,
                            weight: weight * 0.5,
                            selection: None,
                        });
                    }
                }
            }

            // The next direction, by one-sample MIS of the BSDF and the guide.
            let u_choice = if trees.is_some() {
                ctx.sampler.next_1d()
            } else {
                0.0
            };
            let u_lobe = ctx.sampler.next_1d();
            let u = ctx.sampler.next_2d();
            let (wi, weight, pdf, delta, eta, next_lambda, selection) = match trees {
                Some(tree) if u_choice >= alpha => {
                    let wi = tree.sample(u);
                    let f = scattering.eval(wi);
                    let guide_pdf = tree.pdf(wi);
                    let pdf = alpha * f.pdf + (1.0 - alpha) * guide_pdf;
                    if !(pdf > 0.0) {
                        break;
                    }
                    let selection = learns_alpha.then_some((f.value, f.pdf, guide_pdf));
                    (
                        wi,
                        f.value * (1.0 / pdf),
                        pdf,
                        false,
                        1.0,
                        lambda,
                        selection,
                    )
                }
                _ => {
                    let Some(bs) = scattering.sample(u_lobe, u) else {
                        break;
                    };
                    let next_lambda = wavelengths_after(&lambda, &bs);
                    let delta = bs.flags.is_delta();
                    let (weight, pdf, selection) = match trees {
                        Some(_) if delta => (bs.weight * (1.0 / alpha), bs.pdf * alpha, None),
                        Some(tree) => {
                            let guide_pdf = tree.pdf(bs.wi);
                            let pdf = alpha * bs.pdf + (1.0 - alpha) * guide_pdf;
                            let selection =
                                learns_alpha.then_some((bs.weight * bs.pdf, bs.pdf, guide_pdf));
                            (bs.weight * (bs.pdf / pdf), pdf, selection)
                        }
                        None => (bs.weight, bs.pdf, None),
                    };
                    (bs.wi, weight, pdf, delta, bs.eta, next_lambda, selection)
                }
            };
            if self.strict_normals && !normals_agree(&si, wi) {
                break;
            }
            lambda = next_lambda;
            throughput *= weight;
            eta_scale *= eta;
            if throughput.is_black() || !throughput.is_finite() {
                break;
            }
            recording.push(
                leaf.filter(|_| guide.record_weight.is_some() && !delta)
                    .map(|leaf| RecordingVertex {
                        leaf,
                        class,
                        p: si.p,
                        point: direction_to_square(wi),
                        throughput,
                        radiance: SampledSpectrum::ZERO,
                        pdf,
                        selection,
                    }),
            );
            ray = si.spawn_ray(wi);
            previous = Some(ScatterOrigin {
                receiver: Receiver::surface(si.p, si.shading.n),
                pdf,
                specular: delta,
            });
            depth += 1;

            if depth >= self.rr_depth {
                let Some(factor) = russian_roulette(ctx, throughput, eta_scale) else {
                    break;
                };
                throughput *= factor;
            }
        }
        if let Some(weight) = guide.record_weight {
            let weight = if self.nee == NextEvent::Kickstart && guide.light_samples {
                weight * 0.5
            } else {
                weight
            };
            for v in recording.vertices[..recording.count].iter().flatten() {
                let leaf = match self.spatial_filter {
                    SpatialFilter::Nearest => v.leaf.index,
                    SpatialFilter::StochasticBox => {
                        let jitter = Vec3::new(
                            ctx.sampler.next_1d(),
                            ctx.sampler.next_1d(),
                            ctx.sampler.next_1d(),
                        ) - Vec3::splat(0.5);
                        guide
                            .tree
                            .leaf_at(guide.tree.clamp(v.p + jitter * v.leaf.size), v.class)
                            .index
                    }
                };
                let incident = incident_radiance(v.radiance, v.throughput, v.pdf);
                records.push(Record {
                    leaf,
                    point: v.point,
                    flux: incident.average() / v.pdf,
                    weight,
                    selection: v.selection.map(|(bsdf_value, bsdf_pdf, guide_pdf)| {
                        SelectionSample {
                            integrand: (incident * bsdf_value).average(),
                            pdf: v.pdf,
                            bsdf_pdf,
                            guide_pdf,
                        }
                    }),
                });
            }
        }
        path_estimate(result, wavelengths, &lambda)
    }
}
