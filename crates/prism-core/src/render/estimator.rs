//! The estimate of one camera sample: its wavelengths, film position, time and lens position
//! drawn from the sampler, its camera ray, and the integrator's radiance along it times the
//! ray's weight and the sensor's spectral response, in CIE XYZ (with the coverage alpha where
//! the film records it, and a spectral film's bands).

use glam::{UVec2, Vec2};

use super::particles::Splatting;
use crate::camera::{CameraModel, CameraRay};
use crate::film::spectral_bands::band_values;
use crate::film::{FilterMis, FilterSampler};
use crate::integrator::{ParticleTracer, PreparedIntegrator, RayCount};
use crate::math::Ray;
use crate::sampling::sampler::Sampler;
use crate::scene::Scene;
use crate::spectrum::{SampledSpectrum, SampledWavelengths};

/// How a camera sample's film position is drawn.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum OffsetDraw {
    /// From the reconstruction filter around the pixel's centre, with the weight k / (p ∫k) of
    /// the one-pixel estimator.
    Filter,
    /// As filter MIS draws its shared samples ([`FilterMis::draw_offset`]), with no one-pixel
    /// weight (1): each sample feeds the pixels around by the balance heuristic instead.
    Shared,
}

/// A camera sample drawn, with its ray: what the film needs of it once the integrator has
/// estimated the radiance along the ray.
pub(super) struct CameraSampleRay {
    pub(super) ray: Ray,
    pub(super) lambda: SampledWavelengths,
    /// Film offset from the pixel's centre.
    offset: Vec2,
    /// The weight the one-pixel estimator gives the sample (1 for a shared sample).
    filter_weight: f32,
    /// The shutter's filter weight.
    time_weight: f32,
    /// The camera ray's weight (1 for most cameras).
    ray_weight: f32,
}

/// What every camera sample of a render uses: the scene, its integrator prepared for the
/// scene's world, the sampler of the reconstruction filter, and filter MIS's weights when the
/// samples are shared between pixels.
pub struct SampleEstimator<'a> {
    pub(super) scene: &'a Scene,
    pub(super) integrator: PreparedIntegrator<'a>,
    filter: FilterSampler,
    pub(super) shared: Option<FilterMis>,
    /// Whether each sample also writes its coverage alpha, after the integrator's channels.
    alpha: bool,
}

impl<'a> SampleEstimator<'a> {
    pub fn new(scene: &'a Scene) -> SampleEstimator<'a> {
        let film = &scene.film;
        SampleEstimator {
            scene,
            integrator: scene.integrator.prepare(&scene.world),
            filter: FilterSampler::new(film.filter),
            shared: film
                .reconstruction
                .shares_samples(film.filter)
                .then(|| FilterMis::new(film.filter, film.size.x, film.size.y)),
            alpha: scene.exr_output.pixel_format.has_alpha(),
        }
    }

    /// The particle tracer, where the scene's integrator is one: its samples are light
    /// subpaths splatted onto the film, not camera samples.
    pub fn particle_tracer(&self) -> Option<&ParticleTracer> {
        self.integrator.particle_tracer()
    }

    /// The estimator whose samples are splatted, where the scene's integrator is one: the
    /// particle tracer, bidirectional path tracing or vertex connection and merging.
    pub(super) fn splatting(&self) -> Option<Splatting<'_>> {
        if let Some(vcm) = self.integrator.vcm() {
            return Some(Splatting::Vcm(vcm));
        }
        match (self.particle_tracer(), self.integrator.bidirectional()) {
            (Some(ptracer), _) => Some(Splatting::Particle(ptracer)),
            (None, Some(bdpt)) => Some(Splatting::Bidirectional(bdpt)),
            (None, None) => None,
        }
    }

    /// How the render draws its camera samples' film positions: as filter MIS shares them, or
    /// from the filter for the one-pixel estimator.
    pub fn offset_draw(&self) -> OffsetDraw {
        if self.shared.is_some() {
            OffsetDraw::Shared
        } else {
            OffsetDraw::Filter
        }
    }

    /// The film position (full film, pixels) of a camera sample of `pixel` drawn with `u`
    /// through the reconstruction filter, and the filter weight the one-pixel estimator gives
    /// it.
    #[inline]
    pub(super) fn film_position(&self, pixel: UVec2, u: Vec2) -> (Vec2, f32) {
        let (offset, filter_weight) = self.filter.sample(u);
        (pixel.as_vec2() + Vec2::splat(0.5) + offset, filter_weight)
    }

    /// How many extra channels each sample writes: the integrator's, the alpha, the bands.
    pub fn aov_count(&self) -> usize {
        self.integrator.aov_count() + usize::from(self.alpha) + self.scene.film.bands.len()
    }

    /// The coverage alpha of a camera ray, as Mitsuba 3's path tracer defines it: 1 where it
    /// meets a surface, or wherever the environment light shows (the scene has one and the
    /// integrator does not hide emitters), else 0.
    fn coverage(&self, ray: &Ray, count: &mut RayCount) -> f32 {
        let world = &self.scene.world;
        if world.environment.is_some() && !self.scene.integrator.hides_emitters() {
            return 1.0;
        }
        count.rays += 1;
        f32::from(u8::from(world.geometry.occluded(ray)))
    }

    /// Draws sample `index` of `pixel` (full-film coordinates): its wavelengths, film
    /// position (drawn as `draw` says), time and lens position, and its camera ray; writes the
    /// coverage alpha, where the film records it, to its place in `aovs`.
    #[inline]
    pub(super) fn camera_sample(
        &self,
        sampler: &mut Sampler,
        pixel: UVec2,
        index: u32,
        draw: OffsetDraw,
        count: &mut RayCount,
        aovs: &mut [f32],
    ) -> CameraSampleRay {
        let scene = self.scene;
        sampler.start_pixel_sample(pixel, index);
        let primary = sampler.camera_sample();
        let lambda = SampledWavelengths::sample(primary.wavelength, scene.film.wavelength_sampling);
        let (offset, filter_weight) = match (draw, &self.shared) {
            (OffsetDraw::Shared, Some(mis)) => (mis.draw_offset(pixel, primary.film), 1.0),
            _ => self.filter.sample(primary.film),
        };
        let (time, time_weight) = scene.shutter.sample(primary.time);
        let film_position = pixel.as_vec2() + Vec2::splat(0.5) + offset;
        let CameraRay {
            ray,
            weight: ray_weight,
        } = scene.camera.generate_ray(film_position, primary.lens, time);
        if self.alpha {
            aovs[self.integrator.aov_count()] = self.coverage(&ray, count);
        }
        CameraSampleRay {
            ray,
            lambda,
            offset,
            filter_weight,
            time_weight,
            ray_weight,
        }
    }

    /// The sample `sample` with the integrator's `radiance` along its ray: the film offset from
    /// the pixel's centre, the filter weight the one-pixel estimator gives it, and its CIE XYZ
    /// weighted by the shutter's filter; its extra channels in `aovs` are weighted alike and
    /// the spectral film's bands written after the alpha.
    #[inline]
    pub(super) fn film_sample(
        &self,
        sample: &CameraSampleRay,
        mut radiance: SampledSpectrum,
        aovs: &mut [f32],
    ) -> (Vec2, f32, [f32; 3]) {
        let scene = self.scene;
        let lambda = &sample.lambda;
        if let Some(response) = &scene.film.response {
            radiance *= response.sample(lambda);
        }
        let bands = &mut aovs[self.integrator.aov_count() + usize::from(self.alpha)..];
        if !bands.is_empty() {
            band_values(&scene.film.bands, lambda, &radiance, bands);
            for v in bands.iter_mut() {
                *v *= sample.ray_weight;
            }
        }
        for v in aovs.iter_mut() {
            *v *= sample.time_weight;
        }
        let xyz = lambda
            .to_xyz(&radiance)
            .map(|v| v * sample.ray_weight * sample.time_weight);
        (sample.offset, sample.filter_weight, xyz)
    }

    /// Traces sample `index` of `pixel` (full-film coordinates), its film position drawn as
    /// `draw` says: its film offset from the pixel's centre, the filter weight the one-pixel
    /// estimator gives it, and its CIE XYZ weighted by the shutter's filter; its extra
    /// channels, weighted alike, go to `aovs`.
    #[inline]
    pub(super) fn trace(
        &self,
        sampler: &mut Sampler,
        pixel: UVec2,
        index: u32,
        draw: OffsetDraw,
        count: &mut RayCount,
        aovs: &mut [f32],
    ) -> (Vec2, f32, [f32; 3]) {
        let sample = self.camera_sample(sampler, pixel, index, draw, count, aovs);
        let radiance = self.integrator.radiance(
            sample.ray,
            &sample.lambda,
            sampler,
            count,
            &mut aovs[..self.integrator.aov_count()],
        );
        self.film_sample(&sample, radiance, aovs)
    }

    /// Sample `index` of `pixel` (full-film coordinates), its film position drawn as `draw`
    /// says: its CIE XYZ times its one-pixel weight (its one-pixel estimate; 1 for a shared
    /// sample, which feeds the pixels around instead); the sample's extra channels, weighted
    /// alike, go to `aovs`.
    #[inline]
    pub fn estimate(
        &self,
        sampler: &mut Sampler,
        pixel: UVec2,
        index: u32,
        draw: OffsetDraw,
        count: &mut RayCount,
        aovs: &mut [f32],
    ) -> [f32; 3] {
        let (_, weight, xyz) = self.trace(sampler, pixel, index, draw, count, aovs);
        for v in aovs.iter_mut() {
            *v *= weight;
        }
        xyz.map(|v| v * weight)
    }
}
