//! Mitsuba 3's `measured_polarized`: a measured polarimetric BRDF of the KAIST database (Baek et
//! al. 2020, "Image-Based Acquisition and Modeling of Polarimetric Reflectance"), read from its
//! `.pbsdf` file, evaluated and sampled as Mitsuba's `measured_polarized.cpp` does.
//!
//! ```xml
//! <bsdf type="measured_polarized">
//!     <string name="filename" value="6_gold_inpainted.pbsdf"/>
//!     <float name="alpha_sample" value="0.02"/>   <!-- GGX roughness for sampling; default 0.1 -->
//!     <float name="wavelength" value="-1"/>       <!-- nm, or -1: every wavelength -->
//! </bsdf>
//! ```
//!
//! The file is a tensor file ([`crate::tensor_file`]) with the fields `phi_d`, `theta_d`,
//! `theta_h` (shape [1, n], radians, increasing), `wvls` (shape [n], nm) and `M` (shape
//! [φ_d, θ_d, θ_h, λ, 4, 4]): the Mueller matrix of f at each node of the isotropic
//! Rusinkiewicz parametrisation, its reference directions in the plane of reflection; NaN marks
//! configurations not measured. For the view direction v and the light direction l, both
//! turned about the normal so that v has azimuth 0, h = (l + v)/|l + v|, θ_h = ∠(n, h),
//! θ_d = ∠(h, l) and φ_d the azimuth of l about h in the frame (t = (n × h) × h, n × h); the
//! matrix is interpolated multilinearly between the nodes of the four parameters (clamped at
//! the ends), zero where any wavelength's M₀₀ is NaN, and M₀₀ kept non-negative. Its reference
//! directions are then rotated to the implicit Stokes bases of the beams (the incident one
//! travelling along −l, the outgoing one along v). An unpolarized render sees M₀₀ · cos θ_l.
//! Sampling draws a cosine-weighted direction with probability 0.1, otherwise reflects v about
//! a normal drawn from the GGX distribution of roughness `alpha_sample` visible from v.
//! Reflection only, one-sided.

use std::f32::consts::TAU;

use glam::{Mat4, Vec2, Vec3};

use super::microfacet::{Microfacet, MicrofacetKind};
use super::{BsdfEval, BsdfFlags, BsdfSample, Bxdf, BxdfTree, LeafBsdf};
use crate::polarization::mueller::stokes_basis;
use crate::polarization::{FrameChange, SampledMueller};
use crate::sampling::warp::{cosine_hemisphere_pdf, sample_cosine_hemisphere};
use crate::spectrum::{N_SPECTRUM_SAMPLES, SampledSpectrum, SampledWavelengths};
use crate::tensor_file::{TensorField, parse_tensor_file_with_nans};
use crate::texture::TexturePoint;

/// The probability of sampling the cosine-weighted hemisphere rather than the GGX lobe.
const COSINE_PROBABILITY: f32 = 0.1;

/// A measured pBRDF's table, as its file gives it.
#[derive(Debug)]
pub struct MeasuredPolarizedData {
    /// The nodes of φ_d, θ_d, θ_h (radians) and λ (nm), each increasing.
    nodes: [Vec<f32>; 4],
    /// The matrices, [φ_d][θ_d][θ_h][λ][row][column].
    matrices: Vec<f32>,
}

/// The `measured_polarized` BSDF.
#[derive(Clone, Debug)]
pub struct MeasuredPolarized {
    pub data: std::sync::Arc<MeasuredPolarizedData>,
    /// The GGX roughness of the sampling lobe.
    pub alpha_sample: f32,
    /// The one wavelength (nm) to look the table up at, or None for each path's own.
    pub wavelength: Option<f32>,
}

/// The node values of a parameter field: shape [1, n] (Mitsuba reads the first row), finite and
/// increasing.
fn parameter(fields: &[TensorField], name: &str, dimensions: usize) -> Result<Vec<f32>, String> {
    let field = fields
        .iter()
        .find(|f| f.name == name)
        .ok_or_else(|| format!("it has no field \"{name}\""))?;
    if field.shape.len() != dimensions || field.shape.contains(&0) {
        return Err(format!(
            "its field \"{name}\" has shape {:?} where {dimensions} non-empty dimensions are \
             expected",
            field.shape
        ));
    }
    let n = field.shape[dimensions - 1];
    let nodes: Vec<f32> = field.values[..n].iter().map(|&v| v as f32).collect();
    if nodes.iter().any(|v| !v.is_finite()) || nodes.windows(2).any(|w| !(w[0] < w[1])) {
        return Err(format!(
            "the nodes of \"{name}\" are not finite and increasing"
        ));
    }
    Ok(nodes)
}

/// The interval of `nodes` that holds `x` (clamped to the first and last) and the weight of its
/// upper node, clamped to [0, 1] (Mitsuba's `Marginal2D` lookup of a parameter).
#[inline]
fn interval(nodes: &[f32], x: f32) -> (usize, f32) {
    if nodes.len() == 1 {
        return (0, 0.0);
    }
    let below = nodes.partition_point(|&p| p < x);
    let i = below.saturating_sub(1).min(nodes.len() - 2);
    let (p0, p1) = (nodes[i], nodes[i + 1]);
    (i, ((x - p0) / (p1 - p0)).clamp(0.0, 1.0))
}

impl MeasuredPolarizedData {
    /// Reads a `.pbsdf` file; the error says what is wrong with it (without its name).
    pub fn parse(bytes: &[u8]) -> Result<MeasuredPolarizedData, String> {
        let mut fields = parse_tensor_file_with_nans(bytes)?;
        let nodes = [
            parameter(&fields, "phi_d", 2)?,
            parameter(&fields, "theta_d", 2)?,
            parameter(&fields, "theta_h", 2)?,
            parameter(&fields, "wvls", 1)?,
        ];
        let index = fields
            .iter()
            .position(|f| f.name == "M")
            .ok_or("it has no field \"M\"")?;
        let m = fields.swap_remove(index);
        let expected = [
            nodes[0].len(),
            nodes[1].len(),
            nodes[2].len(),
            nodes[3].len(),
            4,
            4,
        ];
        if m.shape != expected {
            return Err(format!(
                "its field \"M\" has shape {:?}; the nodes of phi_d, theta_d, theta_h and wvls \
                 make {expected:?}",
                m.shape
            ));
        }
        Ok(MeasuredPolarizedData {
            nodes,
            matrices: m.values.iter().map(|&v| v as f32).collect(),
        })
    }

    /// The first `entries` entries (row-major) of the matrix interpolated at `parameters`
    /// (φ_d, θ_d, θ_h, λ).
    fn lookup(&self, parameters: [f32; 4], entries: usize) -> [f32; 16] {
        let cells: [(usize, f32); 4] =
            std::array::from_fn(|d| interval(&self.nodes[d], parameters[d]));
        let mut result = [0.0f32; 16];
        // Every corner counts, even at weight 0, so that a NaN beside a node marks it as
        // Mitsuba's interpolation does.
        for corner in 0..16usize {
            let mut index = 0;
            let mut weight = 1.0;
            for (d, &(i, w)) in cells.iter().enumerate() {
                let upper = (corner >> d) & 1 == 1;
                let n = self.nodes[d].len();
                index = index * n + (i + usize::from(upper)).min(n - 1);
                weight *= if upper { w } else { 1.0 - w };
            }
            let matrix = &self.matrices[index * 16..index * 16 + 16];
            for e in 0..entries {
                result[e] += weight * matrix[e];
            }
        }
        result
    }
}

impl LeafBsdf for MeasuredPolarized {
    type Lobes<'a> = MeasuredPolarizedLobes<'a>;
    const FLAGS: BsdfFlags = BsdfFlags::GLOSSY
        .union(BsdfFlags::REFLECTION)
        .union(BsdfFlags::POLARIZING);

    fn lobes<'a>(
        &'a self,
        _at: TexturePoint,
        lambda: &SampledWavelengths,
    ) -> MeasuredPolarizedLobes<'a> {
        MeasuredPolarizedLobes {
            data: &self.data,
            lambda: self
                .wavelength
                .map_or(*lambda.lambdas(), |l| [l; N_SPECTRUM_SAMPLES]),
            alpha_sample: self.alpha_sample,
        }
    }
}

/// The measured pBRDF for a path's wavelengths.
#[derive(Clone, Copy, Debug)]
pub struct MeasuredPolarizedLobes<'a> {
    data: &'a MeasuredPolarizedData,
    lambda: [f32; N_SPECTRUM_SAMPLES],
    alpha_sample: f32,
}

/// A direction turned by `angle` about the normal.
#[inline]
fn rotate_z(v: Vec3, angle: f32) -> Vec3 {
    let (sin, cos) = angle.sin_cos();
    Vec3::new(cos * v.x - sin * v.y, sin * v.x + cos * v.y, v.z)
}

/// The view direction `v` and the light direction `l` in the tables' terms.
struct Configuration {
    /// The azimuth of v, by which both were turned.
    phi: f32,
    v: Vec3,
    l: Vec3,
    /// (φ_d, θ_d, θ_h).
    angles: [f32; 3],
}

impl Configuration {
    fn new(v: Vec3, l: Vec3) -> Configuration {
        let phi = v.y.atan2(v.x).rem_euclid(TAU);
        let (v, l) = (rotate_z(v, -phi), rotate_z(l, -phi));
        let h = (l + v).normalize();
        let b = Vec3::Z.cross(h).try_normalize().unwrap_or(Vec3::Y);
        let t = b.cross(h).normalize();
        let theta_d = h.dot(l).clamp(-1.0, 1.0).acos();
        let theta_h = h.z.clamp(-1.0, 1.0).acos();
        let projected = (l - l.dot(h) * h).try_normalize().unwrap_or(t);
        let phi_d = projected
            .dot(b)
            .clamp(-1.0, 1.0)
            .atan2(projected.dot(t).clamp(-1.0, 1.0));
        Configuration {
            phi,
            v,
            l,
            angles: [phi_d, theta_d, theta_h],
        }
    }
}

impl MeasuredPolarizedLobes<'_> {
    /// The first `entries` entries of the matrix at each wavelength for `c`, zero where some
    /// wavelength's M₀₀ is NaN, with M₀₀ kept non-negative.
    fn matrices(&self, c: &Configuration, entries: usize) -> [[f32; 16]; N_SPECTRUM_SAMPLES] {
        let [phi_d, theta_d, theta_h] = c.angles;
        let mut m = self
            .lambda
            .map(|l| self.data.lookup([phi_d, theta_d, theta_h, l], entries));
        if m.iter().any(|m| m[0].is_nan()) {
            return [[0.0; 16]; N_SPECTRUM_SAMPLES];
        }
        for m in &mut m {
            m[0] = m[0].max(0.0);
        }
        m
    }
}

impl Bxdf for MeasuredPolarizedLobes<'_> {
    fn eval(&self, _tree: &BxdfTree, wo: Vec3, wi: Vec3) -> BsdfEval {
        if !(wo.z > 0.0 && wi.z > 0.0) {
            return BsdfEval::ZERO;
        }
        let m = self.matrices(&Configuration::new(wo, wi), 1);
        BsdfEval {
            value: SampledSpectrum::from_fn(|i| m[i][0] * wi.z),
            pdf: self.pdf(wo, wi),
        }
    }

    fn sample(&self, tree: &BxdfTree, wo: Vec3, u_lobe: f32, u: Vec2) -> Option<BsdfSample> {
        if !(wo.z > 0.0) {
            return None;
        }
        let wi = if u_lobe < COSINE_PROBABILITY {
            sample_cosine_hemisphere(u)
        } else {
            let m = self.microfacet().sample_visible(wo, u);
            2.0 * wo.dot(m) * m - wo
        };
        let eval = self.eval(tree, wo, wi);
        if !(eval.pdf > 0.0) {
            return None;
        }
        Some(BsdfSample::new(
            wi,
            eval.value * (1.0 / eval.pdf),
            eval.pdf,
            BsdfFlags::GLOSSY.union(BsdfFlags::REFLECTION),
        ))
    }

    /// The measured matrix with its reference directions, the normals of the planes that hold
    /// each beam and the other's direction, rotated to the implicit bases of −wi and wo.
    fn mueller(
        &self,
        _tree: &BxdfTree,
        wo: Vec3,
        wi: Vec3,
        _lobe: BsdfFlags,
    ) -> Option<SampledMueller> {
        if !(wo.z > 0.0 && wi.z > 0.0) {
            return None;
        }
        let c = Configuration::new(wo, wi);
        let incident = -c.l;
        let t_in = (c.l - c.v).cross(incident).try_normalize()?;
        let x_in = t_in.cross(incident).normalize().cross(incident);
        let t_out = (c.v - c.l).cross(c.v).try_normalize()?;
        let x_out = t_out.cross(c.v).normalize().cross(c.v);
        let change = FrameChange::new(
            -wi,
            rotate_z(x_in, c.phi),
            stokes_basis(-wi),
            wo,
            rotate_z(x_out, c.phi),
            stokes_basis(wo),
        );
        let m = self.matrices(&c, 16);
        Some(SampledMueller::from_fn(|i| {
            change.apply(Mat4::from_cols_array(&m[i]).transpose())
        }))
    }
}

impl MeasuredPolarizedLobes<'_> {
    fn microfacet(&self) -> Microfacet {
        Microfacet::new(MicrofacetKind::Ggx, self.alpha_sample, self.alpha_sample)
    }

    /// The density of [`Bxdf::sample`]: 0.1 p_cos(wi) + 0.9 D_wo(h) / (4 wi·h).
    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        let h = (wo + wi).normalize();
        let microfacet = self.microfacet().pdf_visible(wo, h) / (4.0 * wi.dot(h));
        let pdf = COSINE_PROBABILITY * cosine_hemisphere_pdf(wi)
            + (1.0 - COSINE_PROBABILITY) * microfacet;
        if pdf.is_finite() { pdf } else { 0.0 }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bsdf::measured::{TensorValues, write_tensor_file};
    use crate::sampling::rng::Pcg32;
    use std::f32::consts::{FRAC_PI_2, FRAC_PI_4, PI};

    /// The synthetic table's entries a, b, s of [[1, a, 0, 0], [a, 1, 0, 0], [0, 0, b, s],
    /// [0, 0, −s, b]] (the form of a Fresnel reflection), scaled by c(θ_h, λ).
    const A: f32 = 0.5;
    const B: f32 = 0.7;
    const S: f32 = 0.2;

    /// c(θ_h, λ) = (0.1 + 0.15 θ_h / (π/2)) (1 + (λ − 450) / 1000): linear in each, so the
    /// interpolation is exact between the nodes; at most 0.3, so that c π < 1.
    fn scale(theta_h: f32, lambda: f32) -> f32 {
        (0.1 + 0.15 * theta_h / FRAC_PI_2) * (1.0 + (lambda.clamp(450.0, 650.0) - 450.0) / 1000.0)
    }

    const PHI_D: [f32; 3] = [-PI, 0.0, PI];
    const THETA: [f32; 3] = [0.0, FRAC_PI_4, FRAC_PI_2];
    const LAMBDA: [f32; 3] = [450.0, 550.0, 650.0];

    /// A `.pbsdf` file of the synthetic table; `nan_theta_h` marks its last θ_h node as not
    /// measured.
    fn synthetic(nan_last_theta_h: bool) -> Vec<u8> {
        let mut m = Vec::new();
        for _ in PHI_D {
            for _ in THETA {
                for (h, &theta_h) in THETA.iter().enumerate() {
                    for &lambda in &LAMBDA {
                        let c = if nan_last_theta_h && h == 2 {
                            f32::NAN
                        } else {
                            scale(theta_h, lambda)
                        };
                        let rows = [
                            [1.0, A, 0.0, 0.0],
                            [A, 1.0, 0.0, 0.0],
                            [0.0, 0.0, B, S],
                            [0.0, 0.0, -S, B],
                        ];
                        m.extend(rows.iter().flatten().map(|v| v * c));
                    }
                }
            }
        }
        write_tensor_file(&[
            ("phi_d", vec![1, 3], TensorValues::F32(PHI_D.to_vec())),
            ("theta_d", vec![1, 3], TensorValues::F32(THETA.to_vec())),
            ("theta_h", vec![1, 3], TensorValues::F32(THETA.to_vec())),
            ("wvls", vec![3], TensorValues::F32(LAMBDA.to_vec())),
            ("M", vec![3, 3, 3, 3, 4, 4], TensorValues::F32(m)),
        ])
    }

    fn lobes(data: &MeasuredPolarizedData) -> MeasuredPolarizedLobes<'_> {
        MeasuredPolarizedLobes {
            data,
            lambda: [430.0, 500.0, 600.0, 700.0],
            alpha_sample: 0.3,
        }
    }

    fn direction(theta: f32, phi: f32) -> Vec3 {
        let (sin, cos) = theta.sin_cos();
        Vec3::new(sin * phi.cos(), sin * phi.sin(), cos)
    }

    #[test]
    fn eval_gives_the_tabulated_intensity() {
        let data = MeasuredPolarizedData::parse(&synthetic(false)).unwrap();
        let lobes = lobes(&data);
        let tree = BxdfTree::empty();
        for (wo, wi) in [
            (direction(0.3, 0.2), direction(0.9, 2.5)),
            (direction(1.2, -1.0), direction(0.1, 0.4)),
            (direction(0.5, 0.0), direction(0.5, PI)),
        ] {
            let theta_h = (wo + wi).normalize().z.acos();
            let value = lobes.eval(&tree, wo, wi).value;
            for (i, &lambda) in lobes.lambda.iter().enumerate() {
                let expected = scale(theta_h, lambda) * wi.z;
                assert!(
                    (value[i] - expected).abs() < 1e-5,
                    "{value:?} against {expected}"
                );
            }
        }
        assert_eq!(
            lobes.eval(&tree, direction(0.3, 0.0), -direction(0.3, 1.0)),
            BsdfEval::ZERO
        );
    }

    /// The rotation to the beams' bases mixes S₁ and S₂ only: M₀₀, the linear polarization
    /// |(M₁₀, M₂₀)| = a c given to unpolarized light, and M₃₃ = b c stay as tabulated.
    #[test]
    fn the_matrix_keeps_its_rotation_invariants() {
        let data = MeasuredPolarizedData::parse(&synthetic(false)).unwrap();
        let lobes = lobes(&data);
        let tree = BxdfTree::empty();
        let mut rng = Pcg32::seeded(7);
        for _ in 0..50 {
            let wo = direction(1.4 * rng.next_f32(), TAU * rng.next_f32());
            let wi = direction(1.4 * rng.next_f32(), TAU * rng.next_f32());
            let theta_h = (wo + wi).normalize().z.acos();
            let m = lobes.mueller(&tree, wo, wi, BsdfFlags::NONE).unwrap();
            for (i, &lambda) in lobes.lambda.iter().enumerate() {
                let c = scale(theta_h, lambda);
                let cols = m.0[i];
                let linear = (cols.x_axis.y.powi(2) + cols.x_axis.z.powi(2)).sqrt();
                assert!((cols.x_axis.x - c).abs() < 1e-5);
                assert!((linear - A * c).abs() < 1e-5);
                assert!((cols.w_axis.w - B * c).abs() < 1e-5);
            }
        }
    }

    /// A configuration beside a node marked NaN reflects nothing, as in Mitsuba.
    #[test]
    fn unmeasured_configurations_reflect_nothing() {
        let data = MeasuredPolarizedData::parse(&synthetic(true)).unwrap();
        let lobes = lobes(&data);
        let tree = BxdfTree::empty();
        let grazing_half_vector = (direction(1.5, 0.0), direction(1.5, 0.1));
        let value = lobes.eval(&tree, grazing_half_vector.0, grazing_half_vector.1);
        assert_eq!(value.value, SampledSpectrum::ZERO);
        let near_normal = lobes.eval(&tree, direction(0.1, 0.0), direction(0.1, PI));
        assert!(near_normal.value[0] > 0.0);
    }

    /// A white furnace: the sampling weights average ∫ f cos θi dωi, which is c π ≤ 0.95 here
    /// and agrees with a uniform-hemisphere estimate of the same integral from `eval`.
    #[test]
    fn a_furnace_never_gains_energy() {
        let data = MeasuredPolarizedData::parse(&synthetic(false)).unwrap();
        let lobes = lobes(&data);
        let tree = BxdfTree::empty();
        let mut rng = Pcg32::seeded(11);
        for wo in [
            direction(0.2, 0.5),
            direction(1.0, 2.0),
            direction(1.4, -1.0),
        ] {
            let n = 200_000;
            let (mut sampled, mut sampled2, mut uniform, mut uniform2) = (0.0, 0.0, 0.0, 0.0);
            for _ in 0..n {
                let u = Vec2::new(rng.next_f32(), rng.next_f32());
                if let Some(s) = lobes.sample(&tree, wo, rng.next_f32(), u) {
                    let w = f64::from(s.weight[3]);
                    sampled += w;
                    sampled2 += w * w;
                }
                let wi = direction(rng.next_f32().acos(), TAU * rng.next_f32());
                let v = f64::from(lobes.eval(&tree, wo, wi).value[3]) * std::f64::consts::TAU;
                uniform += v;
                uniform2 += v * v;
            }
            let n = f64::from(n);
            let (sampled, uniform) = (sampled / n, uniform / n);
            let se = ((sampled2 / n - sampled * sampled) / n
                + (uniform2 / n - uniform * uniform) / n)
                .sqrt();
            assert!(sampled <= 0.95 && sampled > 0.3, "albedo {sampled}");
            assert!(
                (sampled - uniform).abs() < 4.0 * se,
                "{sampled} against {uniform} ± {se}"
            );
        }
    }

    #[test]
    fn inconsistent_files_are_refused() {
        let good = synthetic(false);
        assert!(MeasuredPolarizedData::parse(&good).is_ok());
        let wrong_shape = write_tensor_file(&[
            ("phi_d", vec![1, 3], TensorValues::F32(PHI_D.to_vec())),
            ("theta_d", vec![1, 3], TensorValues::F32(THETA.to_vec())),
            ("theta_h", vec![1, 3], TensorValues::F32(THETA.to_vec())),
            ("wvls", vec![3], TensorValues::F32(LAMBDA.to_vec())),
            (
                "M",
                vec![3, 3, 3, 2, 4, 4],
                TensorValues::F32(vec![0.0; 3 * 3 * 3 * 2 * 16]),
            ),
        ]);
        let error = MeasuredPolarizedData::parse(&wrong_shape).unwrap_err();
        assert!(
            error.contains("\"M\" has shape [3, 3, 3, 2, 4, 4]"),
            "{error}"
        );
        let decreasing = write_tensor_file(&[
            ("phi_d", vec![1, 3], TensorValues::F32(vec![0.0, 1.0, 0.5])),
            ("theta_d", vec![1, 3], TensorValues::F32(THETA.to_vec())),
            ("theta_h", vec![1, 3], TensorValues::F32(THETA.to_vec())),
            ("wvls", vec![3], TensorValues::F32(LAMBDA.to_vec())),
            (
                "M",
                vec![3, 3, 3, 3, 4, 4],
                TensorValues::F32(vec![0.0; 81 * 16]),
            ),
        ]);
        let error = MeasuredPolarizedData::parse(&decreasing).unwrap_err();
        assert!(
            error.contains("\"phi_d\" are not finite and increasing"),
            "{error}"
        );
        let error = MeasuredPolarizedData::parse(&good[..good.len() - 4]).unwrap_err();
        assert!(error.contains("truncated"), "{error}");
    }
}
