//! Mitsuba 3's `measured` BSDF: a material of the RGL database (Dupuy & Jakob 2018, "An
//! Adaptive Parameterization for Efficient Material Acquisition and Rendering"), read from its
//! `.bsdf` file, as Mitsuba 3's `src/bsdfs/measured.cpp` evaluates and samples it.
//!
//! ```xml
//! <bsdf type="measured">
//!     <string name="filename" value="cc_amber_citrine_spec.bsdf"/>
//! </bsdf>
//! ```
//!
//! The file is a tensor file ([`crate::tensor_file`] describes the format) with the fields
//! `theta_i`, `phi_i` (the incident angles measured), `ndf` and `sigma` (the microfacet
//! distribution D and the projected area σ(ω) = ∫ D(m) ⟨ω·m⟩ dm, on grids over the unit square
//! below), `vndf` (the visible normals' density for each incident direction), `luminance` (the
//! luminance of the measured BSDF over the square of random numbers that the VNDF's warp maps to
//! normals), `spectra` with `wavelengths` (nm; the measurements over the same square, per
//! wavelength), `jacobian` (whether the spectra are to be multiplied by D(m)/(4σ(ωo))) and
//! `description`.
//!
//! A direction of elevation θ and azimuth φ maps to the unit square by u_θ = √(2θ/π),
//! u_φ = (φ + π)/2π (for isotropic materials, tabulated at one φ_i, the normal's azimuth is taken
//! relative to the incident one), so that dω = 2π² u_θ sin θ du. With h = (wo + wi)/|wo + wi|
//! and s the point of the square the VNDF's warp maps to h (by inverting it),
//!
//!   f cos θi = S(s; θo, φo, λ) · D(h) / (4σ(wo)),
//!
//! and sampling draws s by the luminance, h by the VNDF's warp and reflects wo about h:
//! p(wi) = L(s) p_vndf(u_h) / (2π² u_θ sin θ_h · 4 wo·h). Tables depending on the incident angles
//! are interpolated between them; anisotropic materials measured over a half or a quarter of the
//! azimuths are folded by symmetry. Reflection only, one-sided.

use std::f32::consts::PI;
use std::sync::Arc;

use glam::{Vec2, Vec3};

use super::{BsdfEval, BsdfFlags, BsdfSample, Bxdf, BxdfTree, LeafBsdf, mixture_sample};
use crate::sampling::marginal2d::Marginal2D;
use crate::spectrum::{N_SPECTRUM_SAMPLES, SampledSpectrum, SampledWavelengths};
use crate::tensor_file::{TensorField, parse_tensor_file};
use crate::texture::TexturePoint;

/// A measured material's tables, as its file gives them.
#[derive(Debug)]
pub struct MeasuredData {
    /// The material's description from the file.
    pub description: String,
    ndf: Marginal2D,
    sigma: Marginal2D,
    vndf: Marginal2D,
    luminance: Marginal2D,
    spectra: Marginal2D,
    isotropic: bool,
    jacobian: bool,
    /// 2 or 4 where the measurements cover half or a quarter of the azimuths, 1 otherwise.
    reduction: u32,
}

#[derive(Clone, Debug)]
pub struct Measured {
    pub data: Arc<MeasuredData>,
}

/// Takes the field `name`, checking its number of dimensions.
fn take(
    fields: &mut Vec<TensorField>,
    name: &str,
    dimensions: usize,
) -> Result<TensorField, String> {
    let index = fields
        .iter()
        .position(|f| f.name == name)
        .ok_or_else(|| format!("it has no field \"{name}\""))?;
    let field = fields.swap_remove(index);
    if field.shape.len() != dimensions {
        return Err(format!(
            "its field \"{name}\" has {} dimensions (shape {:?}) where {dimensions} are expected",
            field.shape.len(),
            field.shape
        ));
    }
    Ok(field)
}

fn f32s(field: &TensorField) -> Vec<f32> {
    field.values.iter().map(|&v| v as f32).collect()
}

impl MeasuredData {
    /// Reads an RGL `.bsdf` file; the error says what is wrong with it (without its name).
    pub fn parse(bytes: &[u8]) -> Result<MeasuredData, String> {
        let mut fields = parse_tensor_file(bytes)?;
        if fields.iter().any(|f| f.name == "rgb") && !fields.iter().any(|f| f.name == "wavelengths")
        {
            return Err(
                "it holds RGB measurements, which Mitsuba 3 renders only in its RGB variants; \
                 Prism renders spectrally: use the material's spectral file"
                    .into(),
            );
        }
        let theta_i = take(&mut fields, "theta_i", 1)?;
        let phi_i = take(&mut fields, "phi_i", 1)?;
        let ndf = take(&mut fields, "ndf", 2)?;
        let sigma = take(&mut fields, "sigma", 2)?;
        let vndf = take(&mut fields, "vndf", 4)?;
        let luminance = take(&mut fields, "luminance", 4)?;
        let spectra = take(&mut fields, "spectra", 5)?;
        let wavelengths = take(&mut fields, "wavelengths", 1)?;
        let description = take(&mut fields, "description", 1)?;
        let jacobian = take(&mut fields, "jacobian", 1)?;
        let (n_phi, n_theta) = (phi_i.shape[0], theta_i.shape[0]);
        let n_lambda = wavelengths.shape[0];
        let incident = [n_phi, n_theta];
        let consistent = vndf.shape[..2] == incident
            && luminance.shape[..2] == incident
            && spectra.shape[..2] == incident
            && spectra.shape[2] == n_lambda
            && luminance.shape[2..] == spectra.shape[3..]
            && jacobian.shape[0] == 1;
        if !consistent {
            return Err(format!(
                "its tables' shapes disagree: theta_i {n_theta}, phi_i {n_phi}, wavelengths \
                 {n_lambda}, vndf {:?}, luminance {:?}, spectra {:?}, jacobian {:?}",
                vndf.shape, luminance.shape, spectra.shape, jacobian.shape
            ));
        }
        let phi_nodes = f32s(&phi_i);
        let isotropic = n_phi <= 2;
        let reduction = if isotropic {
            1
        } else {
            let span = phi_nodes[n_phi - 1] - phi_nodes[0];
            let reduction = (2.0 * PI / span).round();
            if !(1.0..=4.0).contains(&reduction) {
                return Err(format!(
                    "its incident azimuths span {span} radians, not a whole, half or quarter turn"
                ));
            }
            reduction as u32
        };
        let incident_nodes = vec![phi_nodes, f32s(&theta_i)];
        let grid = |field: &TensorField,
                    name: &str,
                    parameters: Vec<Vec<f32>>,
                    normalize: bool,
                    sampling: bool|
         -> Result<Marginal2D, String> {
            let n = field.shape.len();
            Marginal2D::new(
                &f32s(field),
                field.shape[n - 1],
                field.shape[n - 2],
                parameters,
                normalize,
                sampling,
            )
            .map_err(|e| format!("its table \"{name}\": {e}"))
        };
        let mut spectral_nodes = incident_nodes.clone();
        spectral_nodes.push(f32s(&wavelengths));
        Ok(MeasuredData {
            description: description
                .values
                .iter()
                .map(|&c| char::from(c as u8))
                .collect(),
            ndf: grid(&ndf, "ndf", vec![], false, false)?,
            sigma: grid(&sigma, "sigma", vec![], false, false)?,
            vndf: grid(&vndf, "vndf", incident_nodes.clone(), true, true)?,
            luminance: grid(&luminance, "luminance", incident_nodes, true, true)?,
            spectra: grid(&spectra, "spectra", spectral_nodes, false, false)?,
            isotropic,
            jacobian: jacobian.values[0] != 0.0,
            reduction,
        })
    }
}

/// θ, the elevation of a unit vector, robust near the pole: 2 asin(|d − z|/2).
#[inline]
fn elevation(d: Vec3) -> f32 {
    let distance = (d.x * d.x + d.y * d.y + (d.z - 1.0) * (d.z - 1.0)).sqrt();
    2.0 * (0.5 * distance).clamp(-1.0, 1.0).asin()
}

#[inline]
fn theta_to_u(theta: f32) -> f32 {
    (theta * (2.0 / PI)).max(0.0).sqrt()
}

#[inline]
fn phi_to_u(phi: f32) -> f32 {
    (phi + PI) / (2.0 * PI)
}

#[inline]
fn u_to_theta(u: f32) -> f32 {
    u * u * (PI / 2.0)
}

#[inline]
fn u_to_phi(u: f32) -> f32 {
    (2.0 * u - 1.0) * PI
}

impl LeafBsdf for Measured {
    type Lobes<'a> = MeasuredLobes<'a>;
    const FLAGS: BsdfFlags = BsdfFlags::GLOSSY.union(BsdfFlags::REFLECTION);

    fn lobes<'a>(&'a self, _at: TexturePoint, lambda: &SampledWavelengths) -> MeasuredLobes<'a> {
        MeasuredLobes {
            data: &self.data,
            lambda: *lambda.lambdas(),
        }
    }
}

/// The measured lobe for a path's wavelengths.
#[derive(Clone, Copy, Debug)]
pub struct MeasuredLobes<'a> {
    data: &'a MeasuredData,
    lambda: [f32; N_SPECTRUM_SAMPLES],
}

/// The incident direction in the tables' terms.
struct Incidence {
    /// Signs that fold the azimuth into the measured range (applied to x and y).
    fold: Vec2,
    wo: Vec3,
    theta: f32,
    phi: f32,
}

impl MeasuredLobes<'_> {
    fn incidence(&self, wo: Vec3) -> Incidence {
        let mut fold = Vec2::ONE;
        if self.data.reduction >= 2 {
            let sy = if wo.y >= 0.0 { -1.0 } else { 1.0 };
            let sx = if self.data.reduction == 4 {
                if wo.x >= 0.0 { -1.0 } else { 1.0 }
            } else {
                sy
            };
            fold = Vec2::new(sx, sy);
        }
        let wo = Vec3::new(wo.x * fold.x, wo.y * fold.y, wo.z);
        Incidence {
            fold,
            wo,
            theta: elevation(wo),
            phi: wo.y.atan2(wo.x),
        }
    }

    /// The position of the half vector `m` on the square.
    fn half_vector_position(&self, incidence: &Incidence, m: Vec3) -> Vec2 {
        let phi_m = m.y.atan2(m.x);
        let phi = if self.data.isotropic {
            phi_m - incidence.phi
        } else {
            phi_m
        };
        let u = phi_to_u(phi);
        Vec2::new(theta_to_u(elevation(m)), u - u.floor())
    }

    /// f cos θi at the point `s` of the square of random numbers.
    fn value(&self, incidence: &Incidence, s: Vec2, u_m: Vec2) -> SampledSpectrum {
        let data = self.data;
        let (phi, theta) = (incidence.phi, incidence.theta);
        let mut value =
            SampledSpectrum::from_fn(|i| data.spectra.eval(s, &[phi, theta, self.lambda[i]]));
        if data.jacobian {
            let u_wo = Vec2::new(theta_to_u(theta), phi_to_u(phi));
            value *= data.ndf.eval(u_m, &[]) / (4.0 * data.sigma.eval(u_wo, &[]));
        }
        value
    }

    /// |dω/du| of the square's map, times the reflection's 4 wo·m.
    fn jacobian(u_m: Vec2, m: Vec3, wo: Vec3) -> f32 {
        let sin_theta_m = (1.0 - m.z * m.z).max(0.0).sqrt();
        (2.0 * PI * PI * u_m.x * sin_theta_m).max(1e-6) * 4.0 * wo.dot(m)
    }
}

impl Bxdf for MeasuredLobes<'_> {
    fn eval(&self, _tree: &BxdfTree, wo: Vec3, wi: Vec3) -> BsdfEval {
        if !(wo.z > 0.0 && wi.z > 0.0) {
            return BsdfEval::ZERO;
        }
        let incidence = self.incidence(wo);
        let wi = Vec3::new(wi.x * incidence.fold.x, wi.y * incidence.fold.y, wi.z);
        let m = (incidence.wo + wi).normalize();
        let u_m = self.half_vector_position(&incidence, m);
        let params = [incidence.phi, incidence.theta];
        let (s, vndf_pdf) = self.data.vndf.invert(u_m, &params);
        let value = self.value(&incidence, s, u_m);
        let pdf =
            vndf_pdf * self.data.luminance.eval(s, &params) / Self::jacobian(u_m, m, incidence.wo);
        if !(value.is_finite() && pdf.is_finite()) {
            return BsdfEval::ZERO;
        }
        BsdfEval { value, pdf }
    }

    fn sample(&self, _tree: &BxdfTree, wo: Vec3, _u_lobe: f32, u: Vec2) -> Option<BsdfSample> {
        if !(wo.z > 0.0) {
            return None;
        }
        let incidence = self.incidence(wo);
        let params = [incidence.phi, incidence.theta];
        let (s, luminance_pdf) = self.data.luminance.sample(Vec2::new(u.y, u.x), &params);
        let (u_m, vndf_pdf) = self.data.vndf.sample(s, &params);
        let mut phi_m = u_to_phi(u_m.y);
        if self.data.isotropic {
            phi_m += incidence.phi;
        }
        let (sin_phi, cos_phi) = phi_m.sin_cos();
        let (sin_theta, cos_theta) = u_to_theta(u_m.x).sin_cos();
        let m = Vec3::new(cos_phi * sin_theta, sin_phi * sin_theta, cos_theta);
        let folded = 2.0 * m.dot(incidence.wo) * m - incidence.wo;
        let wi = Vec3::new(
            folded.x * incidence.fold.x,
            folded.y * incidence.fold.y,
            folded.z,
        );
        if !(wi.z > 0.0) {
            return None;
        }
        let pdf = vndf_pdf * luminance_pdf / Self::jacobian(u_m, m, incidence.wo);
        let value = self.value(&incidence, s, u_m);
        if !value.is_finite() {
            return None;
        }
        mixture_sample(wi, value, pdf, Measured::FLAGS)
    }
}

/// Writes a tensor file (the format [`crate::tensor_file`] reads): named fields of u8 (type 1)
/// or f32 (type 10) values with their shapes. For tests that need a `.bsdf` file.
#[cfg(test)]
pub(crate) fn write_tensor_file(fields: &[(&str, Vec<usize>, TensorValues)]) -> Vec<u8> {
    let header: usize = 12
        + 2
        + 4
        + fields
            .iter()
            .map(|(name, shape, _)| 2 + name.len() + 2 + 1 + 8 + 8 * shape.len())
            .sum::<usize>();
    let mut out = b"tensor_file\0".to_vec();
    out.extend(1u16.to_le_bytes());
    out.extend((fields.len() as u32).to_le_bytes());
    let mut offset = header;
    for (name, shape, values) in fields {
        out.extend((name.len() as u16).to_le_bytes());
        out.extend(name.as_bytes());
        out.extend((shape.len() as u16).to_le_bytes());
        let (element, size) = match values {
            TensorValues::U8(v) => (1u8, v.len()),
            TensorValues::F32(v) => (10u8, 4 * v.len()),
        };
        out.push(element);
        out.extend((offset as u64).to_le_bytes());
        for &d in shape {
            out.extend((d as u64).to_le_bytes());
        }
        offset += size;
    }
    for (_, _, values) in fields {
        match values {
            TensorValues::U8(v) => out.extend(v),
            TensorValues::F32(v) => v.iter().for_each(|x| out.extend(x.to_le_bytes())),
        }
    }
    out
}

/// The values of a field [`write_tensor_file`] writes.
#[cfg(test)]
pub(crate) enum TensorValues {
    U8(Vec<u8>),
    F32(Vec<f32>),
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bsdf::fresnel::reflect;
    use crate::sampling::chi2::{Suite, chi2_sphere};
    use crate::sampling::rng::Pcg32;
    use crate::spectrum::WavelengthSampling;

    /// The analytic material the synthetic file tabulates: GGX of roughness α with separable
    /// Smith shadowing and a Fresnel factor rising linearly from 0.3 at 360 nm to 0.8 at 830 nm.
    struct Ggx {
        alpha: f32,
    }

    impl Ggx {
        fn d(&self, m: Vec3) -> f32 {
            let a2 = self.alpha * self.alpha;
            let cos2 = m.z * m.z;
            let tan2 = (1.0 - cos2) / cos2;
            1.0 / (PI * a2 * cos2 * cos2 * (1.0 + tan2 / a2).powi(2))
        }

        fn lambda(&self, w: Vec3) -> f32 {
            let tan2 = (1.0 - w.z * w.z) / (w.z * w.z);
            0.5 * ((1.0 + self.alpha * self.alpha * tan2).sqrt() - 1.0)
        }

        fn g1(&self, w: Vec3) -> f32 {
            if w.z <= 0.0 {
                0.0
            } else {
                1.0 / (1.0 + self.lambda(w))
            }
        }

        /// σ(ω) = ∫ D(m) ⟨ω·m⟩ dm = cos θ (1 + Λ(ω)).
        fn sigma(&self, w: Vec3) -> f32 {
            w.z * (1.0 + self.lambda(w))
        }

        fn fresnel(lambda: f32) -> f32 {
            0.3 + 0.5 * (lambda - 360.0) / 470.0
        }

        /// f cos θi.
        fn eval(&self, wo: Vec3, wi: Vec3, lambda: f32) -> f32 {
            let h = (wo + wi).normalize();
            Self::fresnel(lambda) * self.d(h) * self.g1(wo) * self.g1(wi) / (4.0 * wo.z)
        }
    }

    fn spherical(theta: f32, phi: f32) -> Vec3 {
        Vec3::new(
            theta.sin() * phi.cos(),
            theta.sin() * phi.sin(),
            theta.cos(),
        )
    }

    /// Tabulates `ggx` as an isotropic RGL file: `n_theta` incident elevations over 0–80°,
    /// grids of `n` × `n`, two wavelengths.
    fn synthetic_file(ggx: &Ggx, n: usize, n_theta: usize) -> Vec<u8> {
        let (nx, ny) = (n, n);
        let theta_i: Vec<f32> = (0..n_theta)
            .map(|k| (80.0f32 * k as f32 / (n_theta - 1) as f32).to_radians())
            .collect();
        let node = |i: usize, n: usize| i as f32 / (n - 1) as f32;
        let over_square = |f: &dyn Fn(f32, f32) -> f32| -> Vec<f32> {
            (0..ny * nx)
                .map(|i| f(node(i % nx, nx), node(i / nx, ny)))
                .collect()
        };
        let ndf = over_square(&|ux, _| ggx.d(spherical(u_to_theta(ux), 0.0)));
        let sigma = over_square(&|ux, _| ggx.sigma(spherical(u_to_theta(ux), 0.0)));
        let mut vndf = Vec::new();
        for &t in &theta_i {
            let wo = spherical(t, 0.0);
            vndf.extend(over_square(&|ux, uy| {
                let (theta_m, phi_m) = (u_to_theta(ux), u_to_phi(uy));
                let m = spherical(theta_m, phi_m);
                wo.dot(m).max(0.0) * ggx.d(m) / ggx.sigma(wo) * 2.0 * PI * PI * ux * theta_m.sin()
            }));
        }
        let warp =
            Marginal2D::new(&vndf, nx, ny, vec![vec![0.0], theta_i.clone()], true, true).unwrap();
        let mut luminance = Vec::new();
        let mut spectra = Vec::new();
        for &t in &theta_i {
            let wo = spherical(t, 0.0);
            let shadowing = over_square(&|sx, sy| {
                let (u_m, _) = warp.sample(Vec2::new(sx, sy), &[0.0, t]);
                let m = spherical(u_to_theta(u_m.x), u_to_phi(u_m.y));
                ggx.g1(reflect(wo, m))
            });
            luminance.extend(&shadowing);
            for lambda in [360.0, 830.0] {
                spectra.extend(shadowing.iter().map(|g| Ggx::fresnel(lambda) * g));
            }
        }
        write_tensor_file(&[
            (
                "description",
                vec![9],
                TensorValues::U8(b"synthetic".to_vec()),
            ),
            ("jacobian", vec![1], TensorValues::U8(vec![1])),
            ("theta_i", vec![n_theta], TensorValues::F32(theta_i)),
            ("phi_i", vec![1], TensorValues::F32(vec![0.0])),
            (
                "wavelengths",
                vec![2],
                TensorValues::F32(vec![360.0, 830.0]),
            ),
            ("ndf", vec![ny, nx], TensorValues::F32(ndf)),
            ("sigma", vec![ny, nx], TensorValues::F32(sigma)),
            ("vndf", vec![1, n_theta, ny, nx], TensorValues::F32(vndf)),
            (
                "luminance",
                vec![1, n_theta, ny, nx],
                TensorValues::F32(luminance),
            ),
            (
                "spectra",
                vec![1, n_theta, 2, ny, nx],
                TensorValues::F32(spectra),
            ),
        ])
    }

    fn synthetic() -> (Ggx, Measured) {
        let ggx = Ggx { alpha: 0.3 };
        let data = MeasuredData::parse(&synthetic_file(&ggx, 64, 12)).unwrap();
        assert_eq!(data.description, "synthetic");
        (
            ggx,
            Measured {
                data: Arc::new(data),
            },
        )
    }

    fn wavelengths() -> SampledWavelengths {
        SampledWavelengths::sample(0.37, WavelengthSampling::CieSum)
    }

    fn lobes<'a>(measured: &'a Measured, lambda: &SampledWavelengths) -> MeasuredLobes<'a> {
        measured.lobes(TexturePoint::from(Vec2::ZERO), lambda)
    }

    /// The tabulated material reproduces the analytic one: f cos θi within 3 % of its peak
    /// value for each wo, over directions where the lobe holds most of its energy, and its
    /// sampling density is GGX's visible-normal density times the luminance's.
    #[test]
    fn reproduces_the_analytic_bsdf() {
        let (ggx, measured) = synthetic();
        let lambda = wavelengths();
        let lobes = lobes(&measured, &lambda);
        let tree = BxdfTree::empty();
        let mut rng = Pcg32::seeded(5);
        for (theta_o, phi_o) in [
            (10.0f32, 30.0f32),
            (35.0, 200.0),
            (60.0, 100.0),
            (75.0, 300.0),
        ] {
            let wo = spherical(theta_o.to_radians(), phi_o.to_radians());
            let peak = ggx.eval(wo, Vec3::new(-wo.x, -wo.y, wo.z), 830.0);
            for _ in 0..400 {
                let wi = crate::sampling::warp::sample_cosine_hemisphere(Vec2::new(
                    rng.next_f32(),
                    rng.next_f32(),
                ));
                let eval = lobes.eval(&tree, wo, wi);
                for i in 0..N_SPECTRUM_SAMPLES {
                    let expected = ggx.eval(wo, wi, lambda.lambda(i));
                    assert!(
                        (eval.value[i] - expected).abs() < 0.03 * peak,
                        "wo = {wo}, wi = {wi}, λ = {}: {} but GGX {expected} (peak {peak})",
                        lambda.lambda(i),
                        eval.value[i]
                    );
                }
            }
        }
    }

    const SUITE: Suite = Suite::new(&["measured θo = 20°", "measured θo = 55°"]);

    /// Sampling follows the density `eval` reports, and a sample's weight is eval/pdf.
    #[test]
    fn sampling_follows_its_density() {
        let (_, measured) = synthetic();
        let lambda = wavelengths();
        let lobes = lobes(&measured, &lambda);
        let tree = BxdfTree::empty();
        for (name, theta, seed) in [
            ("measured θo = 20°", 20.0f32, 1),
            ("measured θo = 55°", 55.0, 2),
        ] {
            let wo = spherical(theta.to_radians(), 1.0);
            let outcome = chi2_sphere(
                1_000_000,
                101,
                202,
                seed,
                |rng| {
                    let u = Vec2::new(rng.next_f32(), rng.next_f32());
                    lobes.sample(&tree, wo, 0.5, u).map(|s| s.wi)
                },
                |wi| f64::from(lobes.eval(&tree, wo, wi).pdf),
            )
            .unwrap();
            SUITE.assert_passes(name, &outcome);
            let mut rng = Pcg32::seeded(seed + 10);
            for _ in 0..2000 {
                let u = Vec2::new(rng.next_f32(), rng.next_f32());
                let Some(s) = lobes.sample(&tree, wo, 0.5, u) else {
                    continue;
                };
                let eval = lobes.eval(&tree, wo, s.wi);
                assert!(
                    (eval.pdf - s.pdf).abs() < 2e-3 * s.pdf,
                    "{} vs {}",
                    eval.pdf,
                    s.pdf
                );
                for i in 0..N_SPECTRUM_SAMPLES {
                    let expected = eval.value[i] / s.pdf;
                    assert!((s.weight[i] - expected).abs() < 2e-3 * expected + 1e-6);
                }
            }
        }
    }

    /// Damaged files are errors that say what is wrong, never panics.
    #[test]
    fn damaged_files_are_errors() {
        let file = synthetic_file(&Ggx { alpha: 0.5 }, 16, 4);
        for cut in [0, 11, 40, 300, file.len() / 2, file.len() - 1] {
            assert!(MeasuredData::parse(&file[..cut]).is_err());
        }
        let mut rng = Pcg32::seeded(3);
        for _ in 0..200 {
            let mut damaged = file.clone();
            let at = (rng.next_u32() as usize) % 600;
            damaged[at] ^= 1 << (rng.next_u32() % 8);
            let _ = MeasuredData::parse(&damaged);
        }
        let rgb = write_tensor_file(&[("rgb", vec![1], TensorValues::F32(vec![0.5]))]);
        assert!(MeasuredData::parse(&rgb).unwrap_err().contains("RGB"));
        let missing = write_tensor_file(&[("theta_i", vec![1], TensorValues::F32(vec![0.0]))]);
        assert!(MeasuredData::parse(&missing).unwrap_err().contains("phi_i"));
    }
}
