//! Practical path guiding (Müller, Gross & Novák 2017, "Practical Path Guiding for Efficient
//! Light-Transport Simulation"; the authors' Mitsuba 0.6 integrator `guided_path`, with the
//! defaults of Müller's 2019 course notes, "Practical Path Guiding in Production"): a path
//! tracer whose directions are drawn partly from a distribution of incident radiance learned
//! while rendering, the SD-tree ([`sd_tree`], [`quadtree`]).
//!
//! Its parameters (`sppPerPass`, `budgetType`, `budget`, `sampleCombination`,
//! `sTreeThreshold`, `dTreeThreshold`, `bsdfSamplingFraction`, `nee`, `spatialFilter`,
//! `sdTreeMaxMemory`, `maxDepth`, `rrDepth`, `strictNormals`, `hideEmitters`, and Prism's
//! `adrrs`) and their
//! defaults are listed in docs/plugins.md. The render driver (`render::guided`) runs the
//! iterations, and saves a run in checkpoints and continues it on resume (the tree's bytes:
//! [`encoding`]).
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
//! density by the power heuristic, as is the emission a sampled direction finds.
//!
//! **Russian roulette** (`adrrs`, [`weight_window`]): once the tree has learned, a path at a
//! vertex with a smooth lobe measures its throughput times the indirect radiance the vertex's
//! leaf sent back in the previous iteration against its pixel's estimate from that iteration,
//! and survives (or, with `split`, splits) by the weight window of Vorba & Křivánek 2016;
//! elsewhere, and with `off`, Russian roulette is `path`'s. A path split at a vertex goes on as
//! several, each drawing its own direction there and recording its own vertices.
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

pub mod encoding;
pub mod quadtree;
pub mod sd_tree;
pub mod selection;
pub mod vertex_guide;
pub mod weight_window;

use std::f32::consts::PI;

use glam::{Vec2, Vec3};

use crate::bsdf::{BsdfFlags, BxdfTree, Scattering};
use crate::geometry::SurfaceInteraction;
use crate::integrator::SampleContext;
use crate::integrator::mis::{
    ScatterOrigin, Strategies, emission_found, power_heuristic, sample_light, unoccluded,
};
use crate::integrator::transmittance::ShadowTransmittance;
use crate::integrator::vertex::{
    CERTAIN_SURVIVAL_DEPTH, MAX_SURVIVAL, allows_next_vertex, normals_agree, path_estimate,
    russian_roulette, surface_scattering, wavelengths_after,
};
use crate::light::Receiver;
use crate::math::Ray;
use crate::spectrum::{SampledSpectrum, SampledWavelengths};
use sd_tree::{SdTree, SpatialLeaf, orientation};
use selection::{SelectionLoss, SelectionSample};
use vertex_guide::VertexGuide;
use weight_window::Window;

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

/// How paths are ended or split by the learned radiance ([`weight_window`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Adrrs {
    /// Russian roulette as `path`'s.
    Off,
    /// Russian roulette by the weight window where the learned radiance is known, as `path`'s
    /// elsewhere.
    Roulette,
    /// Russian roulette and splitting by the weight window, into at most
    /// [`weight_window::MAX_SPLIT`] paths per camera sample.
    Splitting,
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
    /// Whether Russian roulette (and splitting) follow the learned radiance where it is known.
    pub adrrs: Adrrs,
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
            adrrs: Adrrs::Roulette,
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
    /// The indirect radiance the vertex sends towards its path's previous vertex,
    /// L_i f cos θ / p(ω), where the record is a vertex's.
    pub reflected: Option<f32>,
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
    /// The sample's weight f cos θ / p.
    scatter: SampledSpectrum,
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

    /// Drops the vertices from `count` on.
    fn truncate(&mut self, count: usize) {
        self.count = count.min(self.count);
        self.last_is_current = false;
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

/// What every vertex of a path works with.
struct PathSetup<'g> {
    guide: &'g Guide<'g>,
    strategies: Strategies,
    /// Whether the emission a vertex's own sample finds is left out of its record.
    own_emission_is_direct: bool,
    learns_alpha: bool,
    /// The pixel's estimate, where the weight window ([`weight_window`]) applies.
    pixel_estimate: Option<f32>,
}

/// Where a path (or one of the paths it split into) stands on its way to its next vertex.
#[derive(Clone, Copy, Debug)]
struct Walk {
    ray: Ray,
    /// The wavelengths the walk began with: its estimate is for them.
    started: SampledWavelengths,
    lambda: SampledWavelengths,
    throughput: SampledSpectrum,
    eta_scale: f32,
    previous: Option<ScatterOrigin>,
    depth: i32,
    /// The most paths the walk may still split into, over all its later vertices.
    splits_left: u32,
}

/// A vertex with a smooth or delta lobe, its scattering and its guide.
struct Vertex<'v, 't, 'w> {
    si: SurfaceInteraction,
    scattering: Scattering<'t, 'w>,
    /// The spatial leaf the vertex samples from and records into, where its BSDF has a smooth
    /// lobe.
    leaf: Option<SpatialLeaf>,
    /// The orientation class of the surface's front side.
    class: u32,
    trees: Option<VertexGuide<'v>>,
    /// The probability of sampling the BSDF rather than the guide.
    alpha: f32,
}

impl GuidedPathIntegrator {
    /// The estimate along the camera ray `ray` at `wavelengths`, guided by `guide`, in a pixel
    /// whose estimate from the previous iteration is `pixel_estimate` (where known); the path's
    /// records go to `records`.
    pub fn radiance(
        &self,
        ctx: &mut SampleContext,
        ray: Ray,
        wavelengths: &SampledWavelengths,
        guide: &Guide,
        pixel_estimate: Option<f32>,
        records: &mut Vec<Record>,
    ) -> SampledSpectrum {
        if self.max_depth == 0 {
            return SampledSpectrum::ZERO;
        }
        let setup = PathSetup {
            guide,
            strategies: Strategies {
                light_samples: if guide.light_samples { 1.0 } else { 0.0 },
                bsdf_samples: 1.0,
            },
            // With light samples always on, what a vertex's own sample finds is theirs to learn.
            own_emission_is_direct: guide.light_samples && self.nee == NextEvent::Always,
            learns_alpha: self.bsdf_sampling_fraction_loss != SelectionLoss::None,
            pixel_estimate: pixel_estimate.filter(|_| self.adrrs != Adrrs::Off && guide.trained),
        };
        let walk = Walk {
            ray,
            started: *wavelengths,
            lambda: *wavelengths,
            throughput: SampledSpectrum::ONE,
            eta_scale: 1.0,
            previous: None,
            depth: 0,
            splits_left: match self.adrrs {
                Adrrs::Splitting => weight_window::MAX_SPLIT,
                Adrrs::Off | Adrrs::Roulette => 1,
            },
        };
        let mut recording = RecordingVertices::new();
        self.walk(ctx, &setup, walk, 0, &mut recording, records)
    }

    /// The estimate of the path `w` from its ray on, for the wavelengths it began with; where
    /// the weight window splits it, the sum of its branches'. Files the records of the
    /// recording vertices from `first_record` on when the path ends, and drops them.
    fn walk(
        &self,
        ctx: &mut SampleContext,
        setup: &PathSetup,
        mut w: Walk,
        first_record: usize,
        recording: &mut RecordingVertices,
        records: &mut Vec<Record>,
    ) -> SampledSpectrum {
        let world = ctx.world();
        let guide = setup.guide;
        let mut result = SampledSpectrum::ZERO;
        let mut lobes = BxdfTree::empty();
        loop {
            let hit = ctx.intersect(&w.ray);
            if !(self.hide_emitters && w.depth == 0) {
                let found = w.throughput
                    * emission_found(
                        ctx,
                        &w.ray,
                        hit.as_ref(),
                        w.previous.as_ref(),
                        &w.lambda,
                        setup.strategies,
                    );
                if !found.is_black() {
                    result += found;
                    recording.add(found, setup.own_emission_is_direct);
                }
            }
            let Some(si) = hit else {
                break;
            };
            let wo = -w.ray.d.normalize();
            if !allows_next_vertex(self.max_depth, w.depth)
                || (self.strict_normals && !normals_agree(&si, wo))
            {
                break;
            }
            let scattering = surface_scattering(world, &si, wo, &mut w.lambda, &mut lobes);
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
                Some(l) if setup.learns_alpha && guide.trained => {
                    guide.tree.leaf(l.index).selection.fraction()
                }
                _ => self.bsdf_sampling_fraction,
            };
            let vertex = Vertex {
                si,
                scattering,
                leaf,
                class,
                trees,
                alpha,
            };
            let mixture = |bsdf_pdf: f32, wi: Vec3| match trees {
                Some(tree) => alpha * bsdf_pdf + (1.0 - alpha) * tree.pdf(wi),
                None => bsdf_pdf,
            };

            if guide.light_samples && smooth {
                let si = &vertex.si;
                let receiver = Receiver::surface(si.p, si.shading.n);
                let mut light_direction = Vec3::ZERO;
                let light = sample_light(ctx, &receiver, si.time, &w.lambda, |ctx, ls| {
                    if self.strict_normals && !normals_agree(si, ls.wi) {
                        return None;
                    }
                    let mut f = unoccluded(ctx, si, &vertex.scattering, ls)?;
                    f.pdf = mixture(f.pdf, ls.wi);
                    light_direction = ls.wi;
                    Some((f, ShadowTransmittance::ONE))
                });
                if let Some(light) = light {
                    let contribution = w.throughput * light.weighted(setup.strategies);
                    result += contribution;
                    recording.add(contribution, false);
                    if let (Some(weight), Some(leaf)) = (guide.record_weight, leaf)
                        && self.nee == NextEvent::Kickstart
                        && !light.is_delta
                    {
                        let mis = power_heuristic(light.light_pdf, light.direction_pdf);
                        records.push(Record {
                            leaf: leaf.index,
                            point: direction_to_square(light_direction),
                            flux: (light.radiance * mis).average() / light.light_pdf,
                            reflected: None,
                            weight: weight * 0.5,
                            selection: None,
                        });
                    }
                }
            }

            let verdict = match (setup.pixel_estimate, leaf) {
                (Some(pixel), Some(l)) => weight_window::window(
                    w.throughput.average(),
                    guide.tree.leaf(l.index).reflected(),
                    pixel,
                ),
                _ => None,
            };
            match verdict {
                Some(Window::Roulette(survival)) => {
                    if ctx.sampler.next_1d() >= survival {
                        break;
                    }
                    w.throughput *= 1.0 / survival;
                }
                Some(Window::Split(n)) if w.splits_left >= 2 => {
                    let n = n.min(w.splits_left);
                    let share = 1.0 / n as f32;
                    for _ in 0..n {
                        let first = recording.count;
                        let mut branch = Walk {
                            started: w.lambda,
                            throughput: w.throughput * share,
                            splits_left: w.splits_left / n,
                            ..w
                        };
                        if self.scatter(ctx, setup, &vertex, &mut branch, recording) {
                            result += self.walk(ctx, setup, branch, first, recording, records);
                        }
                    }
                    break;
                }
                Some(Window::Keep | Window::Split(_)) | None => {}
            }
            if !self.scatter(ctx, setup, &vertex, &mut w, recording) {
                break;
            }
            match verdict {
                None if w.depth >= self.rr_depth => {
                    let Some(factor) = russian_roulette(ctx, w.throughput, w.eta_scale) else {
                        break;
                    };
                    w.throughput *= factor;
                }
                // A path the window keeps survives with at most MAX_SURVIVAL from
                // CERTAIN_SURVIVAL_DEPTH on: where the learned radiance stays in the window
                // bounce after bounce (a white furnace), nothing else would end it.
                Some(Window::Keep | Window::Split(_)) if w.depth >= CERTAIN_SURVIVAL_DEPTH => {
                    if ctx.sampler.next_1d() >= MAX_SURVIVAL {
                        break;
                    }
                    w.throughput *= 1.0 / MAX_SURVIVAL;
                }
                _ => {}
            }
        }
        self.file_records(ctx, guide, recording, first_record, records);
        path_estimate(result, &w.started, &w.lambda)
    }

    /// Draws the next direction at `vertex`, by one-sample MIS of the BSDF and the guide, and
    /// moves the path `w` onto it (its recording vertex pushed); false where the path ends
    /// there.
    fn scatter(
        &self,
        ctx: &mut SampleContext,
        setup: &PathSetup,
        vertex: &Vertex,
        w: &mut Walk,
        recording: &mut RecordingVertices,
    ) -> bool {
        let (si, scattering, alpha) = (&vertex.si, &vertex.scattering, vertex.alpha);
        let u_choice = if vertex.trees.is_some() {
            ctx.sampler.next_1d()
        } else {
            0.0
        };
        let u_lobe = ctx.sampler.next_1d();
        let u = ctx.sampler.next_2d();
        let (wi, weight, pdf, delta, eta, next_lambda, selection) = match vertex.trees {
            Some(tree) if u_choice >= alpha => {
                let wi = tree.sample(u);
                let f = scattering.eval(wi);
                let guide_pdf = tree.pdf(wi);
                let pdf = alpha * f.pdf + (1.0 - alpha) * guide_pdf;
                if !(pdf > 0.0) {
                    return false;
                }
                let selection = setup.learns_alpha.then_some((f.value, f.pdf, guide_pdf));
                (
                    wi,
                    f.value * (1.0 / pdf),
                    pdf,
                    false,
                    1.0,
                    w.lambda,
                    selection,
                )
            }
            _ => {
                let Some(bs) = scattering.sample(u_lobe, u) else {
                    return false;
                };
                let next_lambda = wavelengths_after(&w.lambda, &bs);
                let delta = bs.flags.is_delta();
                let (weight, pdf, selection) = match vertex.trees {
                    Some(_) if delta => (bs.weight * (1.0 / alpha), bs.pdf * alpha, None),
                    Some(tree) => {
                        let guide_pdf = tree.pdf(bs.wi);
                        let pdf = alpha * bs.pdf + (1.0 - alpha) * guide_pdf;
                        let selection =
                            setup
                                .learns_alpha
                                .then_some((bs.weight * bs.pdf, bs.pdf, guide_pdf));
                        (bs.weight * (bs.pdf / pdf), pdf, selection)
                    }
                    None => (bs.weight, bs.pdf, None),
                };
                (bs.wi, weight, pdf, delta, bs.eta, next_lambda, selection)
            }
        };
        if self.strict_normals && !normals_agree(si, wi) {
            return false;
        }
        w.lambda = next_lambda;
        w.throughput *= weight;
        w.eta_scale *= eta;
        if w.throughput.is_black() || !w.throughput.is_finite() {
            return false;
        }
        recording.push(
            vertex
                .leaf
                .filter(|_| setup.guide.record_weight.is_some() && !delta)
                .map(|leaf| RecordingVertex {
                    leaf,
                    class: vertex.class,
                    p: si.p,
                    point: direction_to_square(wi),
                    throughput: w.throughput,
                    scatter: weight,
                    radiance: SampledSpectrum::ZERO,
                    pdf,
                    selection,
                }),
        );
        w.ray = si.spawn_ray(wi);
        w.previous = Some(ScatterOrigin {
            receiver: Receiver::surface(si.p, si.shading.n),
            pdf,
            specular: delta,
        });
        w.depth += 1;
        true
    }

    /// Files the records of the recording vertices from `first` on and drops them.
    fn file_records(
        &self,
        ctx: &mut SampleContext,
        guide: &Guide,
        recording: &mut RecordingVertices,
        first: usize,
        records: &mut Vec<Record>,
    ) {
        if let Some(weight) = guide.record_weight {
            let weight = if self.nee == NextEvent::Kickstart && guide.light_samples {
                weight * 0.5
            } else {
                weight
            };
            for v in recording.vertices[first..recording.count].iter().flatten() {
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
                    reflected: Some((incident * v.scatter).average()),
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
        recording.truncate(first);
    }
}
