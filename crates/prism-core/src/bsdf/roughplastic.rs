//! Mitsuba's `roughplastic` BSDF: a diffuse base under a rough dielectric coating (Weidlich &
//! Wilkie 2007, with Mitsuba 3's tabulated coating transmittance, `roughplastic.cpp`).
//!
//! ```xml
//! <bsdf type="roughplastic">
//!     <string name="distribution" value="beckmann"/>   <!-- or ggx -->
//!     <float name="alpha" value="0.1"/>                <!-- isotropic only, as Mitsuba -->
//!     <rgb name="diffuse_reflectance" value="0.5"/>    <!-- or a texture -->
//!     <string name="int_ior" value="polypropylene"/>
//!     <string name="ext_ior" value="air"/>
//!     <rgb name="specular_reflectance" value="1"/>     <!-- optional factor -->
//!     <boolean name="nonlinear" value="false"/>
//! </bsdf>
//! ```
//! f cos θi = F(wo·h) D(h) G(wo, wi, h) s / (4 cos θo)                       (glossy coating)
//!          + ρ_eff T(cos θo) T(cos θi) cos θi / (π η²)                     (diffuse base)
//!
//! where T(μ) is the rough interface's directional transmittance, tabulated at 64 values of μ by
//! integrating over the visible normals with a Gauss–Legendre rule (as Mitsuba's
//! `eval_transmittance`), and ρ_eff = ρ/(1 − R_i) (or ρ/(1 − ρ R_i) with `nonlinear`), R_i the
//! coating's hemispherical reflectance from inside. The glossy lobe is sampled by visible
//! normals, the base by the cosine; a lobe is chosen in proportion to its albedo estimate at wo,
//! (1 − T(cos θo)) s̄ and T(cos θo) ρ̄_eff T̄ / η² with T̄ = 2∫T(μ)μ dμ. One-sided.

use std::f32::consts::FRAC_1_PI;

use glam::{Vec2, Vec3};
use rayon::prelude::*;

use super::dielectric::optional_factor;
use super::fresnel::{fresnel_dielectric, reflect, refract};
use super::glossydiffuse::{GLOSSY_OVER_DIFFUSE, GlossyDiffuseLobes};
use super::microfacet::{GaussLegendre, Microfacet, MicrofacetKind};
use super::plastic::effective_diffuse;
use super::{BsdfFlags, LeafBsdf, choice_probability};
use crate::spectrum::{SampledSpectrum, SampledWavelengths};
use crate::texture::Texture;
use crate::texture::TexturePoint;
use crate::texture::TextureValues;

/// Entries of the transmittance table (Mitsuba's MI_ROUGH_TRANSMITTANCE_RES).
const TABLE_SIZE: usize = 64;

#[derive(Clone, Debug)]
pub struct RoughPlastic {
    eta: f32,
    distribution: Microfacet,
    diffuse_reflectance: Texture,
    specular_reflectance: Option<Texture>,
    nonlinear: bool,
    inv_eta2: f32,
    /// T(μ) at μ = j/63 (μ = 10⁻⁶ for j = 0).
    external_transmittance: [f32; TABLE_SIZE],
    /// The coating's hemispherical reflectance from inside, R_i.
    internal_reflectance: f32,
    /// 2∫T(μ) μ dμ.
    mean_transmittance: f32,
}

/// The directional albedo of a rough dielectric interface with relative index `eta` seen at
/// cos θ = `mu`: its reflected part ∫ F G₁(wr, m) over visible normals and its transmitted part
/// ∫ (1 − F) G₁(wt, m) (Mitsuba's `eval_reflectance` and `eval_transmittance`, with 32 × 32
/// Gauss–Legendre nodes for η > 1 and 128 × 128 for η < 1, where total internal reflection
/// makes the integrand discontinuous).
fn rough_interface_albedo(distribution: &Microfacet, mu: f32, eta: f32) -> (f64, f64) {
    let nodes = GaussLegendre::new(if eta > 1.0 { 32 } else { 128 });
    let wo = Vec3::new((1.0 - mu * mu).max(0.0).sqrt(), 0.0, mu);
    let (mut reflected, mut transmitted) = (0.0, 0.0);
    for (x, wx) in nodes.points() {
        for (y, wy) in nodes.points() {
            let m = distribution.sample_visible(wo, Vec2::new(x as f32, y as f32));
            let fresnel = fresnel_dielectric(wo.dot(m), eta);
            let wr = reflect(wo, m);
            if wr.z > 0.0 {
                reflected += wx * wy * f64::from(fresnel.reflectance * distribution.g1(wr, m));
            }
            let wt = refract(wo, m, fresnel.cos_theta_t, fresnel.eta_ti);
            if fresnel.reflectance < 1.0 && wt.z * wo.z < 0.0 {
                transmitted +=
                    wx * wy * f64::from((1.0 - fresnel.reflectance) * distribution.g1(wt, m));
            }
        }
    }
    (reflected, transmitted)
}

impl RoughPlastic {
    /// Builds the BSDF and its tables (a fraction of a second: 64 × 32² visible-normal samples
    /// for T, 64 × 128² for R_i).
    pub fn new(
        eta: f32,
        kind: MicrofacetKind,
        alpha: f32,
        diffuse_reflectance: Texture,
        specular_reflectance: Option<Texture>,
        nonlinear: bool,
    ) -> RoughPlastic {
        let distribution = Microfacet::new(kind, alpha, alpha);
        let mus: Vec<f32> = (0..TABLE_SIZE)
            .map(|j| (j as f32 / (TABLE_SIZE - 1) as f32).max(1e-6))
            .collect();
        let external: Vec<f32> = mus
            .par_iter()
            .map(|&mu| rough_interface_albedo(&distribution, mu, eta).1 as f32)
            .collect();
        let internal: f64 = mus
            .par_iter()
            .map(|&mu| rough_interface_albedo(&distribution, mu, 1.0 / eta).0 * f64::from(mu))
            .sum::<f64>()
            * 2.0
            / TABLE_SIZE as f64;
        let mut external_transmittance = [0.0; TABLE_SIZE];
        external_transmittance.copy_from_slice(&external);
        // 2∫T(μ)μ dμ by the trapezoid rule on the table's nodes.
        let h = 1.0 / (TABLE_SIZE - 1) as f32;
        let mean_transmittance = 2.0
            * h
            * (0..TABLE_SIZE)
                .map(|j| {
                    let w = if j == 0 || j == TABLE_SIZE - 1 {
                        0.5
                    } else {
                        1.0
                    };
                    w * external_transmittance[j] * j as f32 * h
                })
                .sum::<f32>();
        RoughPlastic {
            eta,
            distribution,
            diffuse_reflectance,
            specular_reflectance,
            nonlinear,
            inv_eta2: 1.0 / (eta * eta),
            external_transmittance,
            internal_reflectance: internal as f32,
            mean_transmittance,
        }
    }

    /// T(μ) by linear interpolation in the table.
    #[inline]
    fn transmittance(&self, mu: f32) -> f32 {
        let x = mu.clamp(0.0, 1.0) * (TABLE_SIZE - 1) as f32;
        let i = (x as usize).min(TABLE_SIZE - 2);
        let t = x - i as f32;
        self.external_transmittance[i] * (1.0 - t) + self.external_transmittance[i + 1] * t
    }
}

impl LeafBsdf for RoughPlastic {
    type Lobes<'a> = RoughPlasticLobes<'a>;
    const FLAGS: BsdfFlags = GLOSSY_OVER_DIFFUSE;

    /// The diffuse reflectance under the coating.
    fn albedo(&self, at: TexturePoint, lambda: &SampledWavelengths) -> SampledSpectrum {
        self.diffuse_reflectance.eval(at, lambda)
    }

    #[inline]
    fn lobes<'a>(&'a self, at: TexturePoint, lambda: &SampledWavelengths) -> RoughPlasticLobes<'a> {
        let rho = self.diffuse_reflectance.eval(at, lambda);
        RoughPlasticLobes {
            plastic: self,
            diffuse: effective_diffuse(rho, self.internal_reflectance, self.nonlinear),
            specular_reflectance: optional_factor(&self.specular_reflectance, at, lambda),
        }
    }
}

/// The glossy coating and the base under it, at a point.
#[derive(Clone, Copy, Debug)]
pub struct RoughPlasticLobes<'a> {
    plastic: &'a RoughPlastic,
    /// The effective diffuse reflectance of the base.
    diffuse: SampledSpectrum,
    specular_reflectance: SampledSpectrum,
}

impl GlossyDiffuseLobes for RoughPlasticLobes<'_> {
    #[inline]
    fn value(&self, wo: Vec3, wi: Vec3) -> SampledSpectrum {
        let p = self.plastic;
        let h = (wo + wi).normalize();
        let d = p.distribution.d(h);
        let glossy = if d > 0.0 {
            let f = fresnel_dielectric(wo.dot(h), p.eta).reflectance;
            self.specular_reflectance * (f * d * p.distribution.g(wo, wi, h) / (4.0 * wo.z))
        } else {
            SampledSpectrum::ZERO
        };
        let base = self.diffuse
            * (p.inv_eta2 * FRAC_1_PI * wi.z * p.transmittance(wo.z) * p.transmittance(wi.z));
        glossy + base
    }

    /// In proportion to the albedo estimates of the two lobes at wo.
    #[inline]
    fn glossy_probability(&self, wo: Vec3) -> f32 {
        let p = self.plastic;
        let t_o = p.transmittance(wo.z);
        let glossy = (1.0 - t_o) * self.specular_reflectance.average();
        let base = t_o * self.diffuse.average() * p.mean_transmittance * p.inv_eta2;
        choice_probability(glossy, base)
    }

    #[inline]
    fn sample_glossy(&self, wo: Vec3, u: Vec2) -> Vec3 {
        reflect(wo, self.plastic.distribution.sample_visible(wo, u))
    }

    #[inline]
    fn glossy_pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        let h = (wo + wi).normalize();
        let glossy = self.plastic.distribution.pdf_visible(wo, h) / (4.0 * wo.dot(h));
        glossy.max(0.0)
    }
}
