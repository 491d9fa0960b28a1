//! RGB → spectrum upsampling by the sigmoid-polynomial model of Jakob & Hanika 2019, "A Low-
//! Dimensional Function Space for Efficient Spectral Upsampling" (Computer Graphics Forum 38(2)).
//!
//! A reflectance is s(c₀λ² + c₁λ + c₂) with the sigmoid s(x) = ½ + x / (2√(1 + x²)), so it is
//! smooth and stays in [0, 1]. The coefficients for an sRGB colour are found by Gauss–Newton
//! iterations that match the colour in CIELAB under D65 (the paper's §4 objective); we solve per
//! colour when a scene is loaded, continuing from grey towards the target so that the iteration
//! never starts far from its solution (the paper builds its table the same way, outward from the
//! grey axis). Grey colours get the exact constant spectrum, so grey stays neutral.

use std::sync::OnceLock;

use super::cie::{LINEAR_SRGB_TO_XYZ, cie_xyz, d65_normalized, mul3};
use super::cie_tables::CIE_Y_INTEGRAL;
use super::{LAMBDA_MAX, LAMBDA_MIN};

/// s(c₀λ² + c₁λ + c₂) with λ in nm.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RgbSigmoidPolynomial {
    pub c0: f32,
    pub c1: f32,
    pub c2: f32,
}

/// The sigmoid of the model, with the limits at ±∞.
#[inline]
pub fn sigmoid(x: f32) -> f32 {
    if x.is_infinite() {
        return if x > 0.0 { 1.0 } else { 0.0 };
    }
    0.5 + x / (2.0 * (1.0 + x * x).sqrt())
}

impl RgbSigmoidPolynomial {
    /// The constant spectrum `v` (v in [0, 1]), exactly: c₂ = s⁻¹(v) = (v − ½)/√(v(1 − v)).
    pub fn constant(v: f32) -> Self {
        let c2 = if v <= 0.0 {
            f32::NEG_INFINITY
        } else if v >= 1.0 {
            f32::INFINITY
        } else {
            (v - 0.5) / (v * (1.0 - v)).sqrt()
        };
        RgbSigmoidPolynomial {
            c0: 0.0,
            c1: 0.0,
            c2,
        }
    }

    #[inline]
    pub fn eval(&self, lambda: f32) -> f32 {
        if self.c0 == 0.0 && self.c1 == 0.0 {
            return sigmoid(self.c2);
        }
        sigmoid((self.c0 * lambda + self.c1) * lambda + self.c2)
    }

    /// The spectrum whose colour under D65 is the linear sRGB reflectance `rgb` (components in
    /// [0, 1]; values outside are clamped).
    pub fn fit(rgb: [f32; 3]) -> Self {
        let rgb = rgb.map(|c| c.clamp(0.0, 1.0));
        if rgb[0] == rgb[1] && rgb[1] == rgb[2] {
            return Self::constant(rgb[0]);
        }
        let target = rgb.map(f64::from);
        // Continuation from grey: solve for colours on the segment from the grey of the same
        // mean to the target, each solution starting the next iteration.
        let mean = (target[0] + target[1] + target[2]) / 3.0;
        let mut coefficients = [0.0f64, 0.0, logit_of_constant(mean)];
        const STEPS: usize = 8;
        for step in 1..=STEPS {
            let t = step as f64 / STEPS as f64;
            let partial = std::array::from_fn(|c| mean + t * (target[c] - mean));
            coefficients = gauss_newton(partial, coefficients);
        }
        to_nanometre_coefficients(coefficients)
    }
}

/// s⁻¹(v) for the model's sigmoid, finite for v strictly inside (0, 1).
fn logit_of_constant(v: f64) -> f64 {
    let v = v.clamp(1e-6, 1.0 - 1e-6);
    (v - 0.5) / (v * (1.0 - v)).sqrt()
}

/// The optimisation works with λ normalised to t = (λ − 360)/470 in [0, 1]; this rewrites
/// a t² + b t + c as c₀λ² + c₁λ + c₂.
fn to_nanometre_coefficients([a, b, c]: [f64; 3]) -> RgbSigmoidPolynomial {
    let (min, range) = (f64::from(LAMBDA_MIN), f64::from(LAMBDA_MAX - LAMBDA_MIN));
    RgbSigmoidPolynomial {
        c0: (a / (range * range)) as f32,
        c1: (b / range - 2.0 * a * min / (range * range)) as f32,
        c2: (a * min * min / (range * range) - b * min / range + c) as f32,
    }
}

/// Quadrature for the colour of a reflectance under D65: wavelengths (as t in [0,1]) and the
/// XYZ weights x̄·D65·Δλ / ∫ȳ at each (trapezoid rule on the 1 nm tables).
struct ColourQuadrature {
    t: Vec<f64>,
    weights: Vec<[f64; 3]>,
}

fn quadrature() -> &'static ColourQuadrature {
    static TABLE: OnceLock<ColourQuadrature> = OnceLock::new();
    TABLE.get_or_init(|| {
        let n = 471;
        let mut t = Vec::with_capacity(n);
        let mut weights = Vec::with_capacity(n);
        for i in 0..n {
            let lambda = LAMBDA_MIN + i as f32;
            let edge = if i == 0 || i == n - 1 { 0.5 } else { 1.0 };
            let illuminant = f64::from(d65_normalized(lambda)) * edge / CIE_Y_INTEGRAL;
            let cmf = cie_xyz(lambda);
            t.push(i as f64 / (n - 1) as f64);
            weights.push(cmf.map(|c| f64::from(c) * illuminant));
        }
        ColourQuadrature { t, weights }
    })
}

fn sigmoid64(x: f64) -> f64 {
    0.5 + x / (2.0 * (1.0 + x * x).sqrt())
}

/// XYZ of the reflectance with normalised coefficients under D65 of luminance 1.
fn xyz_of(coefficients: &[f64; 3]) -> [f64; 3] {
    let q = quadrature();
    let mut xyz = [0.0; 3];
    for (t, w) in q.t.iter().zip(&q.weights) {
        let s = sigmoid64((coefficients[0] * t + coefficients[1]) * t + coefficients[2]);
        for c in 0..3 {
            xyz[c] += s * w[c];
        }
    }
    xyz
}

/// CIELAB relative to the D65 white of luminance 1 (CIE 15:2004, §8.2.1).
fn lab(xyz: [f64; 3]) -> [f64; 3] {
    let white = mul3(&LINEAR_SRGB_TO_XYZ, [1.0, 1.0, 1.0]).map(f64::from);
    let f = |r: f64| {
        const DELTA: f64 = 6.0 / 29.0;
        if r > DELTA * DELTA * DELTA {
            r.cbrt()
        } else {
            r / (3.0 * DELTA * DELTA) + 4.0 / 29.0
        }
    };
    let (fx, fy, fz) = (
        f(xyz[0] / white[0]),
        f(xyz[1] / white[1]),
        f(xyz[2] / white[2]),
    );
    [116.0 * fy - 16.0, 500.0 * (fx - fy), 200.0 * (fy - fz)]
}

/// Minimises |Lab(target) − Lab(model)|² by Gauss–Newton with a central-difference Jacobian.
fn gauss_newton(rgb: [f64; 3], mut coefficients: [f64; 3]) -> [f64; 3] {
    let rgb32 = rgb.map(|c| c as f32);
    let target = lab(mul3(&LINEAR_SRGB_TO_XYZ, rgb32).map(f64::from));
    let residual = |c: &[f64; 3]| {
        let model = lab(xyz_of(c));
        [
            target[0] - model[0],
            target[1] - model[1],
            target[2] - model[2],
        ]
    };
    for _ in 0..30 {
        let r = residual(&coefficients);
        if r.iter().map(|v| v * v).sum::<f64>() < 1e-10 {
            break;
        }
        // J[i][j] = ∂r_i/∂c_j.
        let mut jacobian = [[0.0f64; 3]; 3];
        for j in 0..3 {
            let h = 1e-5 * coefficients[j].abs().max(1.0);
            let (mut plus, mut minus) = (coefficients, coefficients);
            plus[j] += h;
            minus[j] -= h;
            let (rp, rm) = (residual(&plus), residual(&minus));
            for i in 0..3 {
                jacobian[i][j] = (rp[i] - rm[i]) / (2.0 * h);
            }
        }
        // Solve J Δ = r, then c ← c − Δ.
        let Some(delta) = solve3(jacobian, r) else {
            break;
        };
        for j in 0..3 {
            coefficients[j] -= delta[j];
        }
        if coefficients.iter().any(|c| !c.is_finite() || c.abs() > 1e4) {
            break;
        }
    }
    coefficients
}

/// Solves the 3×3 system A x = b by Cramer's rule; None when A is (nearly) singular.
fn solve3(a: [[f64; 3]; 3], b: [f64; 3]) -> Option<[f64; 3]> {
    let det = |m: [[f64; 3]; 3]| {
        m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
            - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
            + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
    };
    let d = det(a);
    if d.abs() < 1e-300 || !d.is_finite() {
        return None;
    }
    Some(std::array::from_fn(|column| {
        let mut m = a;
        for row in 0..3 {
            m[row][column] = b[row];
        }
        det(m) / d
    }))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn srgb_of(poly: &RgbSigmoidPolynomial) -> [f32; 3] {
        let mut xyz = [0.0f64; 3];
        let q = quadrature();
        for (i, w) in q.weights.iter().enumerate() {
            let s = f64::from(poly.eval(LAMBDA_MIN + i as f32));
            for c in 0..3 {
                xyz[c] += s * w[c];
            }
        }
        super::super::cie::xyz_to_linear_srgb(xyz.map(|v| v as f32))
    }

    #[test]
    fn fits_reproduce_their_colours() {
        for rgb in [
            [0.725, 0.71, 0.68],
            [0.63, 0.065, 0.05],
            [0.14, 0.45, 0.091],
            [0.5, 0.353, 0.118],
            [0.2, 0.3, 0.9],
            [0.05, 0.05, 0.06],
        ] {
            let poly = RgbSigmoidPolynomial::fit(rgb);
            let back = srgb_of(&poly);
            for c in 0..3 {
                assert!(
                    (back[c] - rgb[c]).abs() < 2e-3,
                    "{rgb:?} -> {back:?} ({poly:?})"
                );
            }
            for l in [360.0, 450.0, 600.0, 829.0] {
                let v = poly.eval(l);
                assert!((0.0..=1.0).contains(&v));
            }
        }
    }

    #[test]
    fn grey_is_exactly_constant() {
        for v in [0.0, 0.18, 0.5, 1.0] {
            let poly = RgbSigmoidPolynomial::fit([v, v, v]);
            for l in [360.0, 555.0, 829.0] {
                assert!((poly.eval(l) - v).abs() < 1e-6);
            }
        }
    }
}
