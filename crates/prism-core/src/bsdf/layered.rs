//! pbrt-v4's layered BSDFs, `coateddiffuse` and `coatedconductor`: a dielectric coating (smooth
//! or rough) over an opaque base (Lambertian, or a smooth or rough conductor), with a slab of
//! optional scattering medium between them (Pharr, Jakob & Humphreys 2023, "Physically Based
//! Rendering", 4th ed., §14.3, pbrt-v4's `LayeredBxDF`). Mitsuba 3 has no such model.
//!
//! ```xml
//! <bsdf type="coateddiffuse">
//!     <rgb name="reflectance" value="0.2, 0.5, 0.8"/>   <!-- the base's; or a texture -->
//!     <float name="alpha" value="0.1"/>                 <!-- the coating's roughness; 0: smooth -->
//!     <float name="eta" value="1.5"/>
//!     <float name="thickness" value="0.01"/>
//!     <rgb name="albedo" value="0"/>                    <!-- the medium's; 0: none -->
//!     <float name="g" value="0"/>
//!     <integer name="max_depth" value="10"/>
//!     <integer name="samples" value="1"/>
//! </bsdf>
//! ```
//! Its parameters and their defaults are listed in docs/plugins.md.
//!
//! Light enters through the coating, travels through the slab (a medium of unit extinction,
//! thickness `thickness`, single-scattering albedo `albedo` and a Henyey–Greenstein phase
//! function of `g`; transmittance e^(−Δz/|cos θ|)), bounces between the base and the coating's
//! underside, and leaves through the coating. No closed form exists, so, as in pbrt:
//!
//! * `sample` follows one random walk of at most `max_depth` events (Russian roulette after
//!   the fourth when the throughput falls below ¼) and returns its direction with the weight
//!   f·|cos θ| / p of the whole walk, an unbiased estimate whose p is the walk's density, not
//!   the marginal density of the direction;
//! * `eval` returns `samples` walks' estimate of f·|cos θi| with next-event estimation at
//!   every vertex (the walk from wo and a presampled walk from wi joined by multiple
//!   importance sampling), and as its density pbrt's estimate: 0.1/(4π) + 0.9 p̂, p̂ the
//!   entrance's reflection density plus the transmission–reflection–transmission paths'.
//!
//! One difference from pbrt-v4: at a vertex inside the layer, `eval` joins the walk to the
//! exit direction wi by two strategies, the direction presampled from wi through the coating
//! and the direction the vertex samples, weighted by the power heuristic. pbrt weights the
//! second with the coating's density of wi given that direction, which is not the density
//! with which the first strategy draws it, so its weights do not sum to one and its `eval`
//! differs from its `sample` where the coating is rough (by up to 15 % in the tests' cells).
//! Prism weights both with the first strategy's density, the coating's density of the inner
//! direction given wi, so that `eval` is an unbiased estimate of the BSDF `sample` draws from.
//!
//! `eval`'s random numbers come from a generator seeded by a hash of (wo, wi), `sample`'s
//! walk from one seeded by (wo, uc, u), so both are deterministic functions of their
//! arguments: renders stay reproducible for any thread count. A non-specular sample reports
//! `eval`'s density at its direction (pbrt's `pdfIsProportional`): multiple importance
//! sampling then weights both strategies with one function of the direction, and the weights
//! still sum to one. pbrt-v4's coated materials are two-sided: from below, both directions are
//! mirrored. The path's radiance mode is the walk's (pbrt's `TransportMode::Radiance`), the
//! walk from wi the adjoint's.

use std::f32::consts::PI;

use glam::{Vec2, Vec3};

use super::conductor::ConductorIor;
use super::layer_interface::{
    Base, DielectricInterface, InterfaceSample, Lobes, Transport, trowbridge_reitz,
};
use super::{BsdfEval, BsdfFlags, BsdfSample, Bxdf, BxdfTree, LeafBsdf};
use crate::math::Frame;
use crate::sampling::rng::{Pcg32, hash_u64s};
use crate::spectrum::{SampledSpectrum, SampledWavelengths};
use crate::texture::{Texture, TexturePoint, TextureValues};

/// The coating and the slab under it, shared by both layered BSDFs.
#[derive(Clone, Debug)]
pub struct Coating {
    /// The coating's relative index of refraction (pbrt's `eta`, `interface.eta`).
    pub eta: f32,
    /// The coating's roughness (αu, αv) (pbrt's after `remaproughness`); below 10⁻³ smooth.
    pub alpha: (f32, f32),
    /// The slab's thickness in units of its mean free path.
    pub thickness: f32,
    /// The slab's single-scattering albedo; zero everywhere: no medium, only attenuation.
    pub albedo: Texture,
    /// The Henyey–Greenstein asymmetry of the slab's medium.
    pub g: f32,
    /// The most scattering events a walk follows.
    pub max_depth: u32,
    /// How many walks `eval` averages.
    pub samples: u32,
}

impl Coating {
    /// The coating's index, 0 read as 1 (as pbrt reads it).
    fn interface_eta(&self) -> f32 {
        if self.eta == 0.0 { 1.0 } else { self.eta }
    }

    fn lobes(&self, base: Base, at: TexturePoint, lambda: &SampledWavelengths) -> LayeredLobes {
        LayeredLobes {
            top: DielectricInterface {
                eta: self.interface_eta(),
                distribution: trowbridge_reitz(self.alpha.0, self.alpha.1),
            },
            bottom: base,
            thickness: self.thickness.max(f32::MIN_POSITIVE),
            albedo: clamp_unit(self.albedo.eval(at, lambda)),
            g: self.g.clamp(-1.0, 1.0),
            max_depth: self.max_depth,
            samples: self.samples.max(1),
        }
    }

    /// The flags of a coating over a base whose lobe is `base` (pbrt's `LayeredBxDF::Flags`):
    /// reflection, specular where the coating is smooth, diffuse where the base is or the slab
    /// scatters, glossy otherwise.
    fn flags(&self, base: BsdfFlags) -> BsdfFlags {
        let mut flags = BsdfFlags::REFLECTION;
        if self.interface_eta() == 1.0 || trowbridge_reitz(self.alpha.0, self.alpha.1).is_none() {
            flags = flags.union(BsdfFlags::SPECULAR);
        }
        let scatters = self.albedo.max_value() > 0.0;
        if base.contains(BsdfFlags::DIFFUSE) || scatters {
            flags.union(BsdfFlags::DIFFUSE)
        } else if base.contains(BsdfFlags::GLOSSY) || !flags.contains(BsdfFlags::SPECULAR) {
            flags.union(BsdfFlags::GLOSSY)
        } else {
            flags
        }
    }
}

fn clamp_unit(s: SampledSpectrum) -> SampledSpectrum {
    SampledSpectrum::from_fn(|i| s[i].clamp(0.0, 1.0))
}

/// pbrt-v4's `coateddiffuse`: a coating over a Lambertian base.
#[derive(Clone, Debug)]
pub struct CoatedDiffuse {
    pub reflectance: Texture,
    pub coating: Coating,
}

impl LeafBsdf for CoatedDiffuse {
    type Lobes<'a> = LayeredLobes;
    const FLAGS: BsdfFlags = BsdfFlags::REFLECTION.union(BsdfFlags::DIFFUSE);

    fn flags(&self) -> BsdfFlags {
        self.coating.flags(BsdfFlags::DIFFUSE)
    }

    /// The base's reflectance.
    fn albedo(&self, at: TexturePoint, lambda: &SampledWavelengths) -> SampledSpectrum {
        clamp_unit(self.reflectance.eval(at, lambda))
    }

    fn lobes(&self, at: TexturePoint, lambda: &SampledWavelengths) -> LayeredLobes {
        let base = Base::Diffuse {
            reflectance: clamp_unit(self.reflectance.eval(at, lambda)),
        };
        self.coating.lobes(base, at, lambda)
    }
}

/// pbrt-v4's `coatedconductor`: a coating over a conductor of index η + ik, whose index is
/// relative to the coating's (pbrt divides both parts by the coating's η).
#[derive(Clone, Debug)]
pub struct CoatedConductor {
    pub eta: Texture,
    pub k: Texture,
    /// The conductor's roughness (αu, αv); below 10⁻³ smooth.
    pub conductor_alpha: (f32, f32),
    pub coating: Coating,
}

impl LeafBsdf for CoatedConductor {
    type Lobes<'a> = LayeredLobes;
    const FLAGS: BsdfFlags = BsdfFlags::REFLECTION;

    fn flags(&self) -> BsdfFlags {
        let (u, v) = self.conductor_alpha;
        let base = if trowbridge_reitz(u, v).is_some() {
            BsdfFlags::GLOSSY
        } else {
            BsdfFlags::SPECULAR
        };
        self.coating.flags(base)
    }

    fn lobes(&self, at: TexturePoint, lambda: &SampledWavelengths) -> LayeredLobes {
        let (u, v) = self.conductor_alpha;
        let base = Base::Conductor {
            ior: ConductorIor::at(&self.eta, &self.k, self.coating.interface_eta(), at, lambda),
            distribution: trowbridge_reitz(u, v),
        };
        self.coating.lobes(base, at, lambda)
    }
}

/// A layered BSDF at a point: the coating on top (z = thickness), the base at z = 0.
#[derive(Clone, Copy, Debug)]
pub struct LayeredLobes {
    top: DielectricInterface,
    bottom: Base,
    thickness: f32,
    albedo: SampledSpectrum,
    g: f32,
    max_depth: u32,
    samples: u32,
}

/// The walk's random numbers (pbrt's `r()`), from a generator seeded by a hash of the
/// directions and numbers the walk starts from.
struct Walk(Pcg32);

impl Walk {
    fn seeded(a: [f32; 3], b: [f32; 3]) -> Walk {
        let hash = |v: [f32; 3]| hash_u64s(&v.map(|x| u64::from(x.to_bits())));
        Walk(Pcg32::new(hash(a), hash(b)))
    }

    fn next(&mut self) -> f32 {
        self.0.next_f32()
    }

    fn next2(&mut self) -> Vec2 {
        let u = self.next();
        Vec2::new(u, self.next())
    }
}

/// The slab's transmittance over a height `dz` along `w` (pbrt's `LayeredBxDF::Tr`).
fn transmittance(dz: f32, w: Vec3) -> f32 {
    if dz.abs() <= f32::MIN_POSITIVE {
        1.0
    } else {
        (-(dz / w.z).abs()).exp()
    }
}

/// Veach's power heuristic with one sample per strategy.
fn power_heuristic(f: f32, g: f32) -> f32 {
    let (f2, g2) = (f * f, g * g);
    if f2.is_infinite() {
        1.0
    } else if f2 + g2 > 0.0 {
        f2 / (f2 + g2)
    } else {
        0.0
    }
}

/// The Henyey–Greenstein density for wo·wi = `cos_theta` with both pointing away from the
/// scattering point (pbrt's convention): (1 − g²) / (4π (1 + g² + 2g cos θ)^{3/2}).
fn henyey_greenstein(cos_theta: f32, g: f32) -> f32 {
    let denominator = 1.0 + g * g + 2.0 * g * cos_theta;
    (1.0 - g * g) / (4.0 * PI * denominator * denominator.max(0.0).sqrt())
}

/// Draws wi around `wo` from the Henyey–Greenstein density, with that density: the inverse of
/// its CDF in cos θ, then a uniform azimuth.
fn sample_henyey_greenstein(wo: Vec3, g: f32, u: Vec2) -> (Vec3, f32) {
    let cos_theta = if g.abs() < 1e-3 {
        1.0 - 2.0 * u.x
    } else {
        -(1.0 + g * g - ((1.0 - g * g) / (1.0 + g - 2.0 * g * u.x)).powi(2)) / (2.0 * g)
    }
    .clamp(-1.0, 1.0);
    let sin_theta = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
    let phi = 2.0 * PI * u.y;
    let frame = Frame::from_normal(wo);
    let wi = frame.to_world(Vec3::new(
        sin_theta * phi.cos(),
        sin_theta * phi.sin(),
        cos_theta,
    ));
    (wi, henyey_greenstein(cos_theta, g))
}

/// pbrt-v4's fraction of `eval`'s density that is uniform over the sphere.
const UNIFORM_PDF_SHARE: f32 = 0.1;

impl LayeredLobes {
    fn scatters(&self) -> bool {
        self.albedo.max_value() > 0.0
    }

    /// f(wo, wi) without the cosine for wo above the coating: pbrt's `LayeredBxDF::f`, for a
    /// base that does not transmit (so only reflection has a value).
    fn f(&self, wo: Vec3, wi: Vec3) -> SampledSpectrum {
        if wo.z * wi.z <= 0.0 {
            return SampledSpectrum::ZERO;
        }
        let mode = Transport::Radiance;
        let (top, bottom, thickness) = (&self.top, &self.bottom, self.thickness);
        let n = self.samples as f32;
        let mut f = SampledSpectrum::splat(n * top.f(wo, wi, mode));
        let mut r = Walk::seeded(wo.to_array(), wi.to_array());
        for _ in 0..self.samples {
            let uc = r.next();
            let Some(wos) = top.sample(wo, uc, r.next2(), mode, Lobes::TRANSMISSION) else {
                continue;
            };
            let uc = r.next();
            let Some(wis) = top.sample(wi, uc, r.next2(), mode.adjoint(), Lobes::TRANSMISSION)
            else {
                continue;
            };
            let mut beta = wos.f * (wos.wi.z.abs() / wos.pdf);
            let mut z = thickness;
            let mut w = wos.wi;
            for depth in 0..self.max_depth {
                if depth > 3 && beta.max_value() < 0.25 {
                    let q = (1.0 - beta.max_value()).max(0.0);
                    if r.next() < q {
                        break;
                    }
                    beta *= 1.0 / (1.0 - q);
                }
                if !self.scatters() {
                    z = if z == thickness { 0.0 } else { thickness };
                    beta *= transmittance(thickness, w);
                } else {
                    let dz = -(1.0 - r.next()).ln() * w.z.abs();
                    let zp = if w.z > 0.0 { z + dz } else { z - dz };
                    if zp == z {
                        continue;
                    }
                    if 0.0 < zp && zp < thickness {
                        // A scattering event in the slab: light from wi through the coating.
                        let phase = henyey_greenstein((-w).dot(-wis.wi), self.g);
                        let weight = if top.is_specular() {
                            1.0
                        } else {
                            power_heuristic(wis.pdf, phase)
                        };
                        f += beta
                            * self.albedo
                            * wis.f
                            * (phase * weight * transmittance(zp - thickness, wis.wi) / wis.pdf);
                        let (next, pdf) = sample_henyey_greenstein(-w, self.g, r.next2());
                        if !(pdf > 0.0) || next.z == 0.0 {
                            continue;
                        }
                        beta *= self.albedo;
                        w = next;
                        z = zp;
                        if w.z > 0.0 && !top.is_specular() {
                            let f_exit = top.f(-w, wi, mode);
                            if f_exit > 0.0 {
                                // The density with which `wis` draws −w (see above).
                                let exit_pdf = top.pdf(wi, -w, Lobes::TRANSMISSION);
                                let weight = power_heuristic(pdf, exit_pdf);
                                f += beta * (transmittance(zp - thickness, w) * f_exit * weight);
                            }
                        }
                        continue;
                    }
                    z = zp.clamp(0.0, thickness);
                }
                if z == thickness {
                    // Reflection off the coating's underside.
                    let uc = r.next();
                    let Some(bs) = top.sample(-w, uc, r.next2(), mode, Lobes::REFLECTION) else {
                        break;
                    };
                    beta = beta * bs.f * (bs.wi.z.abs() / bs.pdf);
                    w = bs.wi;
                } else {
                    if !bottom.is_specular() {
                        // Light from wi through the coating, reflected by the base.
                        let weight = if top.is_specular() {
                            1.0
                        } else {
                            power_heuristic(wis.pdf, bottom.pdf(-w, -wis.wi))
                        };
                        f += beta
                            * bottom.f(-w, -wis.wi)
                            * wis.f
                            * (wis.wi.z.abs() * weight * transmittance(thickness, wis.wi)
                                / wis.pdf);
                    }
                    let Some(bs) = bottom.sample(-w, r.next2()) else {
                        break;
                    };
                    beta = beta * bs.f * (bs.wi.z.abs() / bs.pdf);
                    w = bs.wi;
                    if !top.is_specular() {
                        let f_exit = top.f(-w, wi, mode);
                        if f_exit > 0.0 {
                            let weight = if bottom.is_specular() {
                                1.0
                            } else {
                                power_heuristic(bs.pdf, top.pdf(wi, -w, Lobes::TRANSMISSION))
                            };
                            f += beta * (transmittance(thickness, bs.wi) * f_exit * weight);
                        }
                    }
                }
            }
        }
        f * (1.0 / n)
    }

    /// pbrt's estimate of the density of sampling wi from wo above the coating
    /// (`LayeredBxDF::PDF`), for a base that does not transmit.
    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        let uniform = 1.0 / (4.0 * PI);
        if wo.z * wi.z <= 0.0 {
            return UNIFORM_PDF_SHARE * uniform;
        }
        let (top, bottom) = (&self.top, &self.bottom);
        let mode = Transport::Radiance;
        let mut r = Walk::seeded(wi.to_array(), wo.to_array());
        let n = self.samples as f32;
        let mut sum = n * top.pdf(wo, wi, Lobes::REFLECTION);
        for _ in 0..self.samples {
            // The transmission–reflection–transmission paths.
            let uc = r.next();
            let wos = top.sample(wo, uc, r.next2(), mode, Lobes::TRANSMISSION);
            let uc = r.next();
            let wis = top.sample(wi, uc, r.next2(), mode.adjoint(), Lobes::TRANSMISSION);
            let (Some(wos), Some(wis)) = (wos, wis) else {
                continue;
            };
            if top.is_specular() {
                sum += bottom.pdf(-wos.wi, -wis.wi);
                continue;
            }
            let Some(rs) = bottom.sample(-wos.wi, r.next2()) else {
                continue;
            };
            if bottom.is_specular() {
                sum += top.pdf(-rs.wi, wi, Lobes::ALL);
            } else {
                let r_pdf = bottom.pdf(-wos.wi, -wis.wi);
                sum += power_heuristic(wis.pdf, r_pdf) * r_pdf;
                let t_pdf = top.pdf(-rs.wi, wi, Lobes::ALL);
                sum += power_heuristic(rs.pdf, t_pdf) * t_pdf;
            }
        }
        UNIFORM_PDF_SHARE * uniform + (1.0 - UNIFORM_PDF_SHARE) * sum / n
    }

    /// One random walk from wo above the coating: pbrt's `LayeredBxDF::Sample_f`. The sample's
    /// f is without the cosine, its pdf the walk's.
    fn walk(&self, wo: Vec3, uc: f32, u: Vec2) -> Option<InterfaceSample> {
        let mode = Transport::Radiance;
        let (top, bottom, thickness) = (&self.top, &self.bottom, self.thickness);
        let bs = top.sample(wo, uc, u, mode, Lobes::ALL)?;
        if !bs.transmission {
            return Some(bs);
        }
        let mut w = bs.wi;
        let mut specular_path = bs.specular;
        let mut r = Walk::seeded(wo.to_array(), [uc, u.x, u.y]);
        let mut f = bs.f * bs.wi.z.abs();
        let mut pdf = bs.pdf;
        let mut z = thickness;
        for depth in 0..self.max_depth {
            let rr_beta = f.max_value() / pdf;
            if depth > 3 && rr_beta < 0.25 {
                let q = (1.0 - rr_beta).max(0.0);
                if r.next() < q {
                    return None;
                }
                pdf *= 1.0 - q;
            }
            if w.z == 0.0 {
                return None;
            }
            if self.scatters() {
                let dz = -(1.0 - r.next()).ln() * w.z.abs();
                let zp = if w.z > 0.0 { z + dz } else { z - dz };
                if zp == z {
                    return None;
                }
                if 0.0 < zp && zp < thickness {
                    let (next, phase_pdf) = sample_henyey_greenstein(-w, self.g, r.next2());
                    if !(phase_pdf > 0.0) || next.z == 0.0 {
                        return None;
                    }
                    f = f * self.albedo * phase_pdf;
                    pdf *= phase_pdf;
                    specular_path = false;
                    w = next;
                    z = zp;
                    continue;
                }
                z = zp.clamp(0.0, thickness);
            } else {
                z = if z == thickness { 0.0 } else { thickness };
                f *= transmittance(thickness, w);
            }
            let uc = r.next();
            let u = r.next2();
            let bs = if z == 0.0 {
                bottom.sample(-w, u)?
            } else {
                top.sample(-w, uc, u, mode, Lobes::ALL)?
            };
            f *= bs.f;
            pdf *= bs.pdf;
            specular_path &= bs.specular;
            w = bs.wi;
            if bs.transmission {
                return Some(InterfaceSample {
                    f,
                    wi: w,
                    pdf,
                    specular: specular_path,
                    transmission: false,
                });
            }
            f *= bs.wi.z.abs();
        }
        None
    }
}

impl Bxdf for LayeredLobes {
    fn eval(&self, _tree: &BxdfTree, wo: Vec3, wi: Vec3) -> BsdfEval {
        let (wo, wi) = if wo.z < 0.0 { (-wo, -wi) } else { (wo, wi) };
        if wo.z == 0.0 {
            return BsdfEval::ZERO;
        }
        BsdfEval {
            value: self.f(wo, wi) * wi.z.abs(),
            pdf: self.pdf(wo, wi),
        }
    }

    fn sample(&self, _tree: &BxdfTree, wo: Vec3, u_lobe: f32, u: Vec2) -> Option<BsdfSample> {
        let flip = wo.z < 0.0;
        let wo = if flip { -wo } else { wo };
        if wo.z == 0.0 {
            return None;
        }
        let s = self.walk(wo, u_lobe, u)?;
        let weight = s.f * (s.wi.z.abs() / s.pdf);
        if !(s.pdf > 0.0) || !weight.is_finite() {
            return None;
        }
        let (flags, pdf) = if s.specular {
            (BsdfFlags::SPECULAR, s.pdf)
        } else {
            (BsdfFlags::GLOSSY, self.pdf(wo, s.wi))
        };
        let wi = if flip { -s.wi } else { s.wi };
        Some(BsdfSample::new(
            wi,
            weight,
            pdf,
            flags.union(BsdfFlags::REFLECTION),
        ))
    }
}
