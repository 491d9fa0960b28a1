//! Phase functions: the angular distribution of light scattered in a medium (Mitsuba 3's
//! `isotropic`, `hg`, `rayleigh`, `tabphase`, `blendphase` and `sggx`).
//!
//! Conventions follow the BSDFs': `wo` points back along the path (towards the camera), `wi`
//! towards where the light comes from, both unit vectors in world space. Every phase function
//! here is a normalised density on the sphere, p(wo, wi), so its value and its sampling density
//! agree and a sample's weight p/pdf is 1.
//!
//! A microflake phase function (`sggx`) also scales the medium's coefficients by the flakes'
//! projected area in the direction of travel ([`PhaseFunction::projected_area`]); for the
//! others it is 1.

use std::f32::consts::PI;

use glam::{Vec2, Vec3};

use crate::dispatch::plugin_class;
use crate::math::Frame;
use crate::sampling::distribution::PiecewiseLinear1D;
use crate::sampling::warp::{sample_cosine_hemisphere, sample_uniform_sphere, uniform_sphere_pdf};

plugin_class! {
    /// What every phase function answers: its value, which is also its sampling density, and
    /// a sample.
    pub trait PhaseModel {
        /// p(wo, wi), which is also the density [`PhaseModel::sample`] draws `wi` with.
        fn eval(&self, wo: Vec3, wi: Vec3) -> f32;

        /// Draws `wi` given `wo` from the uniform numbers `u`.
        fn sample(&self, wo: Vec3, u: Vec2) -> PhaseSample;
    }

    /// A phase function as the scene describes it.
    #[derive(Clone, Debug, PartialEq)]
    pub enum PhaseFunction {
        Isotropic(Isotropic),
        HenyeyGreenstein(HenyeyGreenstein),
        Rayleigh(Rayleigh),
        Tabulated(TabulatedPhase),
        Blend(BlendPhase),
        Sggx(Sggx),
    }
}

impl PhaseFunction {
    /// The projected area σ(w) of a microflake medium's flakes seen along `w` (unit), by which
    /// the medium's coefficients are multiplied (Mitsuba 3 scales them so for phase functions
    /// flagged `Microflake`; `blendphase` reports 1, as Mitsuba's does); 1 for the others.
    #[inline]
    pub fn projected_area(&self, w: Vec3) -> f32 {
        match self {
            PhaseFunction::Sggx(sggx) => sggx.projected_area(w),
            PhaseFunction::Isotropic(_)
            | PhaseFunction::HenyeyGreenstein(_)
            | PhaseFunction::Rayleigh(_)
            | PhaseFunction::Tabulated(_)
            | PhaseFunction::Blend(_) => 1.0,
        }
    }

    /// A bound on [`Self::projected_area`] over all directions.
    pub fn max_projected_area(&self) -> f32 {
        match self {
            PhaseFunction::Sggx(sggx) => sggx.max_projected_area(),
            PhaseFunction::Isotropic(_)
            | PhaseFunction::HenyeyGreenstein(_)
            | PhaseFunction::Rayleigh(_)
            | PhaseFunction::Tabulated(_)
            | PhaseFunction::Blend(_) => 1.0,
        }
    }
}

/// A direction drawn from a phase function.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PhaseSample {
    /// The incident direction (world space, unit).
    pub wi: Vec3,
    /// Density of `wi` per unit solid angle, which is also the phase function's value there.
    pub pdf: f32,
}

/// p = 1/(4π).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Isotropic;

impl PhaseModel for Isotropic {
    #[inline]
    fn eval(&self, _wo: Vec3, _wi: Vec3) -> f32 {
        uniform_sphere_pdf()
    }

    #[inline]
    fn sample(&self, _wo: Vec3, u: Vec2) -> PhaseSample {
        PhaseSample {
            wi: sample_uniform_sphere(u),
            pdf: uniform_sphere_pdf(),
        }
    }
}

/// Henyey & Greenstein 1941: p(θ) = (1 − g²) / (4π (1 + g² + 2g cos θ)^{3/2}), with θ the angle
/// between `wo` and `wi` (pbrt-v4 §11.3.1), so that g > 0 scatters forward (`wi` close to the
/// direction the path came from, −`wo`); |g| < 1.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HenyeyGreenstein {
    pub g: f32,
}

/// The Henyey–Greenstein density for cos θ = wo·wi.
#[inline]
pub fn henyey_greenstein(cos_theta: f32, g: f32) -> f32 {
    let denom = 1.0 + g * g + 2.0 * g * cos_theta;
    (1.0 - g * g) / (4.0 * PI * denom * denom.max(0.0).sqrt())
}

impl PhaseModel for HenyeyGreenstein {
    #[inline]
    fn eval(&self, wo: Vec3, wi: Vec3) -> f32 {
        henyey_greenstein(wo.dot(wi), self.g)
    }

    /// By inverting the CDF of cos θ (pbrt-v4 §11.3.1):
    /// cos θ = −(1 + g² − ((1 − g²)/(1 + g − 2g·u₀))²) / (2g), φ = 2π·u₁.
    fn sample(&self, wo: Vec3, u: Vec2) -> PhaseSample {
        let g = self.g;
        let cos_theta = if g.abs() < 1e-3 {
            1.0 - 2.0 * u.x
        } else {
            let s = (1.0 - g * g) / (1.0 + g - 2.0 * g * u.x);
            (-(1.0 + g * g - s * s) / (2.0 * g)).clamp(-1.0, 1.0)
        };
        let sin_theta = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
        let phi = 2.0 * PI * u.y;
        let local = Vec3::new(sin_theta * phi.cos(), sin_theta * phi.sin(), cos_theta);
        let wi = Frame::from_normal(wo).to_world(local).normalize();
        PhaseSample {
            wi,
            pdf: henyey_greenstein(cos_theta, g),
        }
    }
}

/// The direction at polar angle θ from `axis` (cos θ given) and azimuth 2π·`u_phi` around it.
#[inline]
fn direction_around(axis: Vec3, cos_theta: f32, u_phi: f32) -> Vec3 {
    let sin_theta = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
    let phi = 2.0 * PI * u_phi;
    let local = Vec3::new(sin_theta * phi.cos(), sin_theta * phi.sin(), cos_theta);
    Frame::from_normal(axis).to_world(local).normalize()
}

/// Rayleigh scattering by particles much smaller than the wavelength, Mitsuba 3's `rayleigh`:
/// p(θ) = 3 (1 + cos²θ) / (16π), symmetric between forward and backward (Chandrasekhar 1960,
/// "Radiative Transfer", §17; the wavelength dependence of the scattering coefficient belongs to
/// the medium's σ_s, not to the phase function).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Rayleigh;

/// The Rayleigh density for cos θ.
#[inline]
pub fn rayleigh(cos_theta: f32) -> f32 {
    3.0 / (16.0 * PI) * (1.0 + cos_theta * cos_theta)
}

impl PhaseModel for Rayleigh {
    #[inline]
    fn eval(&self, wo: Vec3, wi: Vec3) -> f32 {
        rayleigh(wo.dot(wi))
    }

    /// By inverting the CDF of μ = cos θ, F(μ) = (μ³ + 3μ + 4)/8: the cubic μ³ + 3μ − 2z = 0
    /// with z = 2(2u₀ − 1) has the one real root μ = ∛(z + √(z² + 1)) + ∛(z − √(z² + 1))
    /// (Cardano; as Mitsuba 3), and φ = 2π·u₁.
    fn sample(&self, wo: Vec3, u: Vec2) -> PhaseSample {
        let z = 2.0 * (2.0 * u.x - 1.0);
        let root = (z * z + 1.0).sqrt();
        let cos_theta = ((z + root).cbrt() + (z - root).cbrt()).clamp(-1.0, 1.0);
        let wi = direction_around(wo, cos_theta, u.y);
        PhaseSample {
            wi,
            pdf: rayleigh(cos_theta),
        }
    }
}

/// A phase function tabulated over the cosine of the scattering angle, Mitsuba 3's `tabphase`:
/// the values at equally spaced cosines from −1 to 1, interpolated linearly and normalised.
///
/// The table's cosine is that of the physics convention, where 1 is forward scattering: with
/// `wo` and `wi` both pointing away from the scattering point, cos θ = −wo·wi. The density per
/// unit solid angle is p(cos θ)/(2π), p the normalised piecewise-linear density on [−1, 1], and a
/// sample draws cos θ from p and the azimuth uniformly.
#[derive(Clone, Debug, PartialEq)]
pub struct TabulatedPhase {
    cosines: PiecewiseLinear1D,
}

impl TabulatedPhase {
    /// The phase function through `values` (at least two, finite, non-negative, not all zero);
    /// None otherwise.
    pub fn new(values: &[f32]) -> Option<TabulatedPhase> {
        PiecewiseLinear1D::new(values, -1.0, 1.0).map(|cosines| TabulatedPhase { cosines })
    }
}

impl PhaseModel for TabulatedPhase {
    #[inline]
    fn eval(&self, wo: Vec3, wi: Vec3) -> f32 {
        self.cosines.pdf((-wo.dot(wi)).clamp(-1.0, 1.0)) / (2.0 * PI)
    }

    fn sample(&self, wo: Vec3, u: Vec2) -> PhaseSample {
        let cos_theta = self.cosines.sample(u.x);
        // Forward scattering continues the path's direction, −wo.
        let wi = direction_around(-wo, cos_theta, u.y);
        PhaseSample {
            wi,
            pdf: self.eval(wo, wi),
        }
    }
}

/// (1 − weight)·first + weight·second, Mitsuba's `blendphase`; weight in [0, 1].
#[derive(Clone, Debug, PartialEq)]
pub struct BlendPhase {
    pub weight: f32,
    pub first: Box<PhaseFunction>,
    pub second: Box<PhaseFunction>,
}

impl PhaseModel for BlendPhase {
    fn eval(&self, wo: Vec3, wi: Vec3) -> f32 {
        (1.0 - self.weight) * self.first.eval(wo, wi) + self.weight * self.second.eval(wo, wi)
    }

    /// Chooses the first component with probability 1 − weight by u₀ (rescaled to [0, 1) for
    /// the chosen one), so the mixture's density is the blend of the components'.
    fn sample(&self, wo: Vec3, u: Vec2) -> PhaseSample {
        let weight = self.weight;
        let (chosen, u0) = if u.x < 1.0 - weight {
            (&self.first, u.x / (1.0 - weight))
        } else {
            (&self.second, (u.x - (1.0 - weight)) / weight)
        };
        let sample = chosen.sample(wo, Vec2::new(u0.min(1.0 - f32::EPSILON), u.y));
        PhaseSample {
            wi: sample.wi,
            pdf: self.eval(wo, sample.wi),
        }
    }
}

/// The SGGX microflake phase function (Heitz, Dupuy, Crassin & Dachsbacher 2015, "The SGGX
/// Microflake Distribution"), Mitsuba 3's `sggx`: specular flakes whose normals follow the
/// distribution of normals of an ellipsoid, given by a symmetric positive-definite matrix S.
///
/// * Projected area along ω (unit): σ(ω) = √(ωᵀ S ω) (eq. 9).
/// * Normal distribution: D(m) = 1 / (π √|S| (mᵀ S⁻¹ m)²) = |S|^{3/2} / (π (mᵀ adj(S) m)²)
///   (eq. 10), normalised so that ∫ ⟨ω, m⟩₊ D(m) dm = σ(ω).
/// * Phase function of specular flakes: p(wo, wi) = D(h) / (4 σ(wo)), h = (wo + wi)/|wo + wi|
///   (eq. 14, with the Jacobian 1/(4 wo·h) of reflection; a density over wi).
/// * Sampling: a normal from the distribution of visible normals ⟨wo, m⟩₊ D(m) / σ(wo), drawn
///   as a cosine-distributed direction mapped through the matrix of S in a frame about wo
///   (Appendix, "Sampling visible normals"), then wi the reflection of wo about it.
///
/// S is the same everywhere (Mitsuba gives it as a six-channel grid; a grid of one voxel is
/// such a constant).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sggx {
    /// S_xx, S_yy, S_zz, S_xy, S_xz, S_yz.
    s: [f32; 6],
}

const XX: usize = 0;
const YY: usize = 1;
const ZZ: usize = 2;
const XY: usize = 3;
const XZ: usize = 4;
const YZ: usize = 5;

impl Sggx {
    /// The phase function of the matrix with entries `s` = [S_xx, S_yy, S_zz, S_xy, S_xz,
    /// S_yz]; None unless they are finite and the matrix is positive definite (Sylvester's
    /// criterion: its three leading minors are positive).
    pub fn new(s: [f32; 6]) -> Option<Sggx> {
        let sggx = Sggx { s };
        let minor2 = s[XX] * s[YY] - s[XY] * s[XY];
        let positive = s.iter().all(|v| v.is_finite())
            && s[XX] > 0.0
            && minor2 > 0.0
            && sggx.determinant() > 0.0;
        positive.then_some(sggx)
    }

    /// |S|.
    fn determinant(&self) -> f32 {
        let s = &self.s;
        s[XX] * s[YY] * s[ZZ]
            - s[XX] * s[YZ] * s[YZ]
            - s[YY] * s[XZ] * s[XZ]
            - s[ZZ] * s[XY] * s[XY]
            + 2.0 * s[XY] * s[XZ] * s[YZ]
    }

    /// aᵀ S b.
    fn form(&self, a: Vec3, b: Vec3) -> f32 {
        let s = &self.s;
        let sb = Vec3::new(
            s[XX] * b.x + s[XY] * b.y + s[XZ] * b.z,
            s[XY] * b.x + s[YY] * b.y + s[YZ] * b.z,
            s[XZ] * b.x + s[YZ] * b.y + s[ZZ] * b.z,
        );
        a.dot(sb)
    }

    /// σ(w) = √(wᵀ S w).
    #[inline]
    pub fn projected_area(&self, w: Vec3) -> f32 {
        self.form(w, w).max(0.0).sqrt()
    }

    /// √ of Gershgorin's bound on the largest eigenvalue of S, maxᵢ (S_ii + Σ_{j≠i} |S_ij|):
    /// at least σ(w) for every unit w.
    pub fn max_projected_area(&self) -> f32 {
        let s = &self.s;
        let rows = [
            s[XX] + s[XY].abs() + s[XZ].abs(),
            s[YY] + s[XY].abs() + s[YZ].abs(),
            s[ZZ] + s[XZ].abs() + s[YZ].abs(),
        ];
        rows[0].max(rows[1]).max(rows[2]).sqrt()
    }

    /// D(m) for a unit normal m.
    fn ndf(&self, m: Vec3) -> f32 {
        let s = &self.s;
        let adjugate_form = m.x * m.x * (s[YY] * s[ZZ] - s[YZ] * s[YZ])
            + m.y * m.y * (s[XX] * s[ZZ] - s[XZ] * s[XZ])
            + m.z * m.z * (s[XX] * s[YY] - s[XY] * s[XY])
            + 2.0
                * (m.x * m.y * (s[XZ] * s[YZ] - s[ZZ] * s[XY])
                    + m.x * m.z * (s[XY] * s[YZ] - s[YY] * s[XZ])
                    + m.y * m.z * (s[XY] * s[XZ] - s[XX] * s[YZ]));
        let det = self.determinant();
        det * det.sqrt() / (PI * adjugate_form * adjugate_form)
    }

    /// A normal from the distribution of normals visible from `wo`, from the uniform numbers
    /// `u` (the paper's Appendix, with the frame (k, j, i) = (s, t, wo)).
    fn sample_visible_normal(&self, wo: Vec3, u: Vec2) -> Vec3 {
        let frame = Frame::from_normal(wo);
        let (k, j, i) = (frame.s, frame.t, frame.n);
        let (s_jj, s_ii) = (self.form(j, j), self.form(i, i));
        let (s_kj, s_ki, s_ji) = (self.form(k, j), self.form(k, i), self.form(j, i));
        let inv_sqrt_s_ii = 1.0 / s_ii.max(f32::MIN_POSITIVE).sqrt();
        let tmp = (s_jj * s_ii - s_ji * s_ji).max(f32::MIN_POSITIVE).sqrt();
        let sqrt_det = self.determinant().abs().sqrt();
        let m_k = Vec3::new(sqrt_det / tmp, 0.0, 0.0);
        let m_j = Vec3::new(
            -inv_sqrt_s_ii * (s_ki * s_ji - s_kj * s_ii) / tmp,
            inv_sqrt_s_ii * tmp,
            0.0,
        );
        let m_i = inv_sqrt_s_ii * Vec3::new(s_ki, s_ji, s_ii);
        let c = sample_cosine_hemisphere(u);
        let local = (c.x * m_k + c.y * m_j + c.z * m_i).normalize();
        (local.x * k + local.y * j + local.z * i).normalize()
    }
}

impl PhaseModel for Sggx {
    #[inline]
    fn eval(&self, wo: Vec3, wi: Vec3) -> f32 {
        let h = wo + wi;
        let length = h.length();
        if !(length > 0.0) {
            return 0.0;
        }
        let sigma = self.projected_area(wo);
        if !(sigma > 0.0) {
            return 0.0;
        }
        self.ndf(h / length) / (4.0 * sigma)
    }

    fn sample(&self, wo: Vec3, u: Vec2) -> PhaseSample {
        let m = self.sample_visible_normal(wo, u);
        let wi = (2.0 * wo.dot(m) * m - wo).normalize();
        PhaseSample {
            wi,
            pdf: self.eval(wo, wi),
        }
    }
}
