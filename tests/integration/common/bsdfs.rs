//! Checks shared by the BSDF tests: the chi-square test of `sample` against `pdf`
//! (docs/testing.md, chi-square tests) and the identities a chi-square test cannot see (sample
//! weight = eval/pdf, sample pdf = pdf, reciprocity, albedo ≤ 1).

use std::f64::consts::PI;

use glam::{Vec2, Vec3};
use prism_core::bsdf::{Bsdf, BsdfEval, BsdfSample, BxdfTree, Scattering, ShadingPoint};
use prism_core::sampling::chi2::{Chi2Outcome, chi2_sphere};
use prism_core::sampling::rng::Pcg32;
use prism_core::spectrum::{SampledSpectrum, SampledWavelengths, WavelengthSampling};

/// Sphere resolution for BSDF chi-square tests: an odd number of cos θ bins (the horizon on a
/// row's middle node), twice as many φ bins.
pub const COS_BINS: usize = 101;
pub const PHI_BINS: usize = 202;
pub const SAMPLES: usize = 1_000_000;

/// Four wavelengths spread over the visible range, as a path would carry them.
pub fn wavelengths() -> SampledWavelengths {
    SampledWavelengths::sample(0.37, WavelengthSampling::CieSum)
}

/// A unit direction from spherical angles in degrees.
pub fn direction(theta_degrees: f32, phi_degrees: f32) -> Vec3 {
    let (theta, phi) = (theta_degrees.to_radians(), phi_degrees.to_radians());
    Vec3::new(
        theta.sin() * phi.cos(),
        theta.sin() * phi.sin(),
        theta.cos(),
    )
}

fn u2(rng: &mut Pcg32) -> Vec2 {
    Vec2::new(rng.next_f32(), rng.next_f32())
}

/// A BSDF queried at one point, for one `wo` and wavelengths, outside a scene.
pub struct Query<'b> {
    bsdf: &'b Bsdf,
    point: ShadingPoint,
    wo: Vec3,
    lambda: SampledWavelengths,
}

impl Query<'_> {
    pub fn eval(&self, wi: Vec3) -> BsdfEval {
        let mut lobes = BxdfTree::empty();
        Scattering::new(self.bsdf, &self.point, self.wo, &self.lambda, &mut lobes).eval(wi)
    }

    pub fn sample(&self, u_lobe: f32, u: Vec2) -> Option<BsdfSample> {
        let mut lobes = BxdfTree::empty();
        Scattering::new(self.bsdf, &self.point, self.wo, &self.lambda, &mut lobes).sample(u_lobe, u)
    }

    pub fn null_transmission(&self) -> SampledSpectrum {
        let mut lobes = BxdfTree::empty();
        Scattering::new(self.bsdf, &self.point, self.wo, &self.lambda, &mut lobes)
            .null_transmission()
    }
}

/// `bsdf.at(point, wo, lambda)`: the BSDF's scattering at a point, for the tests.
pub trait At {
    fn at(&self, point: &ShadingPoint, wo: Vec3, lambda: &SampledWavelengths) -> Query<'_>;
}

impl At for Bsdf {
    fn at(&self, point: &ShadingPoint, wo: Vec3, lambda: &SampledWavelengths) -> Query<'_> {
        Query {
            bsdf: self,
            point: *point,
            wo,
            lambda: *lambda,
        }
    }
}

/// The shading point used by the tests (world frame, uv in the middle of the unit square).
pub fn point() -> ShadingPoint {
    ShadingPoint::local(Vec2::new(0.3, 0.6))
}

/// Chi-square test of the directions `sample` draws from `wo` against `pdf`. Samples of delta
/// lobes count as failures of the smooth sampler, whose expectation is 1 − ∫pdf.
pub fn chi2_bsdf(bsdf: &Bsdf, wo: Vec3, seed: u64) -> Result<Chi2Outcome, String> {
    let (sp, lambda) = (point(), wavelengths());
    chi2_sphere(
        SAMPLES,
        COS_BINS,
        PHI_BINS,
        seed,
        |rng| {
            let u_lobe = rng.next_f32();
            let s = bsdf.at(&sp, wo, &lambda).sample(u_lobe, u2(rng))?;
            (!s.flags.is_delta()).then_some(s.wi)
        },
        |wi| f64::from(bsdf.at(&sp, wo, &lambda).eval(wi).pdf),
    )
}

/// What [`check_samples`] measured.
#[derive(Debug)]
pub struct SampleStats {
    /// The mean energy carried per sample, per wavelength (the albedo for wo), and its
    /// standard error.
    pub albedo: [f64; 4],
    pub albedo_se: [f64; 4],
}

/// Draws `n` samples from `wo` and checks each: a unit direction; for a smooth lobe, pdf equal
/// to `pdf(wo, wi)` and weight equal to `eval(wo, wi)/pdf`; no NaN. Returns the albedo estimate.
pub fn check_samples(bsdf: &Bsdf, wo: Vec3, n: usize, seed: u64) -> SampleStats {
    let (sp, lambda) = (point(), wavelengths());
    let mut rng = Pcg32::seeded(seed);
    let (mut sum, mut sum2) = ([0.0f64; 4], [0.0f64; 4]);
    for _ in 0..n {
        let u_lobe = rng.next_f32();
        let Some(s) = bsdf.at(&sp, wo, &lambda).sample(u_lobe, u2(&mut rng)) else {
            continue;
        };
        assert!(
            (s.wi.length() - 1.0).abs() < 1e-4,
            "sample {:?} is not a unit vector",
            s.wi
        );
        assert!(
            s.weight.is_finite() && s.pdf > 0.0 && s.pdf.is_finite(),
            "bad sample {s:?} for wo = {wo}"
        );
        // Energy: radiance refracted into a denser medium is compressed into a smaller solid
        // angle (weights scaled by 1/η²), so the energy carried is weight · η².
        let energy = f64::from(s.eta * s.eta);
        for c in 0..4 {
            assert!(s.weight[c] >= 0.0, "negative weight {s:?}");
            sum[c] += f64::from(s.weight[c]) * energy;
            sum2[c] += (f64::from(s.weight[c]) * energy).powi(2);
        }
        if s.flags.is_delta() {
            continue;
        }
        let pdf = bsdf.at(&sp, wo, &lambda).eval(s.wi).pdf;
        assert!(
            (pdf - s.pdf).abs() <= 2e-3 * s.pdf + 1e-6,
            "sample pdf {} but pdf() {pdf} at wi = {} (wo = {wo})",
            s.pdf,
            s.wi
        );
        let f = bsdf.at(&sp, wo, &lambda).eval(s.wi).value;
        for c in 0..4 {
            let expected = f[c] / s.pdf;
            assert!(
                (s.weight[c] - expected).abs() <= 2e-3 * expected.abs() + 1e-5,
                "weight {} but eval/pdf = {expected} at wi = {} (wo = {wo})",
                s.weight[c],
                s.wi
            );
        }
    }
    let nf = n as f64;
    let albedo = sum.map(|s| s / nf);
    let albedo_se =
        std::array::from_fn(|c| ((sum2[c] / nf - albedo[c].powi(2)).max(0.0) / nf).sqrt());
    SampleStats { albedo, albedo_se }
}

/// Asserts that the albedo for wo is at most 1 (within 4 standard errors and 10⁻³).
pub fn assert_albedo_at_most_one(name: &str, stats: &SampleStats) {
    for c in 0..4 {
        assert!(
            stats.albedo[c] <= 1.0 + 4.0 * stats.albedo_se[c] + 1e-3,
            "{name}: albedo {} ± {} above 1",
            stats.albedo[c],
            stats.albedo_se[c]
        );
    }
}

/// Asserts f(wo, wi) = f(wi, wo) (Helmholtz reciprocity of a BRDF) on random pairs of upper
/// hemisphere directions, comparing eval(wo, wi)/cos θi with eval(wi, wo)/cos θo.
pub fn assert_reciprocal(name: &str, bsdf: &Bsdf, seed: u64) {
    let (sp, lambda) = (point(), wavelengths());
    let mut rng = Pcg32::seeded(seed);
    for _ in 0..2000 {
        let a = prism_core::sampling::warp::sample_cosine_hemisphere(u2(&mut rng));
        let b = prism_core::sampling::warp::sample_cosine_hemisphere(u2(&mut rng));
        if a.z < 1e-3 || b.z < 1e-3 {
            continue;
        }
        let fab = bsdf.at(&sp, a, &lambda).eval(b).value * (1.0 / b.z);
        let fba = bsdf.at(&sp, b, &lambda).eval(a).value * (1.0 / a.z);
        for c in 0..4 {
            assert!(
                (fab[c] - fba[c]).abs() <= 1e-3 * fab[c].abs().max(fba[c].abs()) + 1e-6,
                "{name}: f({a}, {b}) = {} but f({b}, {a}) = {}",
                fab[c],
                fba[c]
            );
        }
    }
}

/// ∫ f(wo, wi) cos θi dωi over the sphere by a midpoint rule in (cos θ, φ), per wavelength.
pub fn integrate_eval(bsdf: &Bsdf, wo: Vec3, n_cos: usize, n_phi: usize) -> [f64; 4] {
    let (sp, lambda) = (point(), wavelengths());
    let mut sum = [0.0f64; 4];
    let cell = (2.0 / n_cos as f64) * (2.0 * PI / n_phi as f64);
    for i in 0..n_cos {
        let z = -1.0 + (i as f64 + 0.5) * 2.0 / n_cos as f64;
        let r = (1.0 - z * z).max(0.0).sqrt();
        for j in 0..n_phi {
            let phi = (j as f64 + 0.5) * 2.0 * PI / n_phi as f64;
            let wi = Vec3::new((r * phi.cos()) as f32, (r * phi.sin()) as f32, z as f32);
            let f = bsdf.at(&sp, wo, &lambda).eval(wi).value;
            for c in 0..4 {
                sum[c] += f64::from(f[c]) * cell;
            }
        }
    }
    sum
}

/// The BSDF a `<bsdf>` element describes, built by the scene factory (a `twosided` wrapper
/// becomes a [`prism_core::bsdf::TwoSided`]). Panics on invalid XML: the tests' own input.
pub fn bsdf_from_xml(xml: &str) -> Bsdf {
    try_bsdf_from_xml(xml).unwrap_or_else(|e| panic!("{e}"))
}

/// As [`bsdf_from_xml`], returning the factory's error.
pub fn try_bsdf_from_xml(xml: &str) -> prism_core::error::Result<Bsdf> {
    use prism_mitsuba::description::PluginClass;
    use prism_mitsuba::factory::materials::build_bsdf;
    use prism_mitsuba::factory::textures::TextureCache;
    let text = format!("<scene version=\"3.0.0\">{xml}</scene>");
    let root = prism_mitsuba::reader::read_scene_str(&text, std::path::Path::new("test.xml"), &[])?;
    let child = root
        .children
        .iter()
        .find(|c| c.node.class == PluginClass::Bsdf)
        .expect("the XML declares a <bsdf>");
    build_bsdf(&child.node, &mut TextureCache::default())
}
