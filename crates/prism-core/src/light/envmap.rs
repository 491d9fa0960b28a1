//! Mitsuba's `envmap` emitter: radiance arriving from infinity, given by a latitude-longitude
//! image (OpenEXR, Radiance HDR, PNG or JPEG).
//!
//! ```xml
//! <emitter type="envmap">
//!     <string name="filename" value="sky.exr"/>    <!-- required; at least 2 × 3 pixels -->
//!     <float name="scale" value="1"/>              <!-- multiplies the image -->
//!     <transform name="to_world">                  <!-- rotates the map -->
//!         <rotate y="1" angle="90"/>
//!     </transform>
//! </emitter>
//! ```
//! Its parameters and their defaults are listed in docs/plugins.md.
//!
//! # Mitsuba's conventions, reproduced exactly
//! * Orientation: in the map's frame +y is up. The image coordinates (u, v) ∈ [0, 1]² (u to the
//!   right, v down) are the angles φ = 2πu and θ = πv of the direction
//!   (sin φ sin θ, cos θ, −cos φ sin θ): the top row looks up (+y), the middle of the image looks
//!   along −z, a quarter to the right along +x.
//! * Lookup: the pixels are the nodes of a bilinear interpolation, pixel (x, y) at
//!   u = (x + ½)/W, v = y/(H − 1), periodic in u: the first and last rows are the poles.
//! * Spectra (spectral variants): each pixel's linear RGB c becomes the scale f = 2 max c and the
//!   sigmoid polynomial s of c / f (Jakob & Hanika 2019, from the shared table of
//!   [`crate::spectrum::rgb`]); s and f are interpolated separately
//!   and L = s · f · scale · D65, with D65 of luminance 1, as for other RGB emission. PNG and JPEG
//!   values are decoded from the sRGB curve first; alpha is ignored.
//!
//! # Sampling
//! Directions are drawn from a piecewise-constant density on the image's cells (the squares
//! between four pixel nodes), each cell weighted by the integral over it of the interpolated
//! luminance times sin θ: p(u, v) ∝ L sin θ cell by cell, the density the lecture's importance
//! sampling asks for, since dω = 2π² sin θ du dv. The density per solid angle is
//! p(u, v) / (2π² sin θ). Rays that leave the scene see the map and are weighted by multiple
//! importance sampling against these samples.

use std::f32::consts::PI;

use glam::{Vec2, Vec3};

use super::{BoundingSphere, DirectionSample, Environment, LightAtInfinity};
use crate::image::Bitmap;
use crate::math::Transform;
use crate::sampling::distribution::PiecewiseConstant2D;
use crate::spectrum::cie::{LINEAR_SRGB_TO_XYZ, d65_normalized};
use crate::spectrum::rgb::{RgbSigmoidPolynomial, RgbToSpectrumTable};
use crate::spectrum::{SampledSpectrum, SampledWavelengths};

/// One pixel's spectrum: `scale` · `polynomial`(λ) (before the map's scale and D65).
#[derive(Clone, Copy, Debug)]
struct Texel {
    polynomial: RgbSigmoidPolynomial,
    scale: f32,
}

#[derive(Clone, Debug)]
pub struct EnvironmentMap {
    width: usize,
    height: usize,
    /// Row-major, top row (θ = 0) first.
    texels: Vec<Texel>,
    /// Mitsuba's `scale`.
    scale: f32,
    /// Map-to-world rotation.
    to_world: Transform,
    /// Density over (s, v) ∈ [0, 1)², s = u − ½/W (mod 1), so that cell i of a row spans the
    /// pixel nodes i and i + 1: `width` × (`height` − 1) cells.
    distribution: PiecewiseConstant2D,
    /// The scene's bounding sphere (set when the scene is assembled).
    pub scene: BoundingSphere,
}

/// `x` wrapped into [0, 1) (x − ⌊x⌋ alone rounds tiny negative x up to 1).
fn wrap(x: f32) -> f32 {
    let w = x - x.floor();
    if w < 1.0 { w } else { 0.0 }
}

/// For the row of cells between θ₀ = π j/rows and θ₁ = π (j + 1)/rows, with t = (θ − θ₀)/Δθ:
/// (∫₀¹ (1 − t) sin θ dt, ∫₀¹ t sin θ dt), the weights of the row's upper and lower pixel
/// nodes in the cell mean of (linearly interpolated luminance) · sin θ. With
/// I₀ = ∫₀¹ sin θ dt = (cos θ₀ − cos θ₁)/Δθ and, by parts,
/// I₁ = ∫₀¹ t sin θ dt = (sin θ₁ − sin θ₀)/Δθ² − cos θ₁/Δθ, they are (I₀ − I₁, I₁); in double
/// precision, as I₁ cancels for fine maps.
fn sin_theta_moments(j: usize, rows: usize) -> (f64, f64) {
    let delta = std::f64::consts::PI / rows as f64;
    let (theta0, theta1) = (delta * j as f64, delta * (j + 1) as f64);
    let i0 = (theta0.cos() - theta1.cos()) / delta;
    let i1 = (theta1.sin() - theta0.sin()) / (delta * delta) - theta1.cos() / delta;
    (i0 - i1, i1)
}

/// Luminance of a linear sRGB colour (the Y row of the sRGB-to-XYZ matrix).
fn luminance(rgb: [f32; 3]) -> f32 {
    let y = LINEAR_SRGB_TO_XYZ[1];
    y[0] * rgb[0] + y[1] * rgb[1] + y[2] * rgb[2]
}

/// The linear RGB of pixel (x, y): grey images are replicated, alpha is dropped.
fn pixel_rgb(bitmap: &Bitmap, x: usize, y: usize) -> [f32; 3] {
    if bitmap.channels < 3 {
        [bitmap.value(x, y, 0); 3]
    } else {
        std::array::from_fn(|c| bitmap.value(x, y, c))
    }
}

impl EnvironmentMap {
    /// The map of an image of at least 2 × 3 pixels whose values are finite and non-negative
    /// (the scene reader checks both); `scale` ≥ 0 and a rotation `to_world`.
    pub fn new(mut bitmap: Bitmap, scale: f32, to_world: Transform) -> EnvironmentMap {
        bitmap.linearize();
        let (width, height) = (bitmap.width, bitmap.height);
        let rgb: Vec<[f32; 3]> = (0..height)
            .flat_map(|y| (0..width).map(move |x| (x, y)))
            .map(|(x, y)| pixel_rgb(&bitmap, x, y))
            .collect();
        // Mitsuba's normalisation: largest component ½, so the spectrum stays smooth.
        let normalise = |c: [f32; 3]| {
            let s = 2.0 * c[0].max(c[1]).max(c[2]);
            (c.map(|v| v / s.max(1e-8)), s)
        };
        let table = RgbToSpectrumTable::srgb();
        let texels = rgb
            .iter()
            .map(|&c| {
                let (normalised, scale) = normalise(c);
                Texel {
                    polynomial: table.fetch(normalised),
                    scale,
                }
            })
            .collect();

        let rows = height - 1;
        let lum: Vec<f64> = rgb
            .iter()
            .map(|&c| f64::from(luminance(c).max(0.0)))
            .collect();
        let mut weights = Vec::with_capacity(width * rows);
        for j in 0..rows {
            let (upper, lower) = sin_theta_moments(j, rows);
            for i in 0..width {
                let i1 = (i + 1) % width;
                // Averaged over s, the bilinear luminance is linear in v between the rows' means.
                let top = 0.5 * (lum[j * width + i] + lum[j * width + i1]);
                let bottom = 0.5 * (lum[(j + 1) * width + i] + lum[(j + 1) * width + i1]);
                weights.push((top * upper + bottom * lower) as f32);
            }
        }
        EnvironmentMap {
            width,
            height,
            texels,
            scale,
            to_world,
            distribution: PiecewiseConstant2D::new(&weights, width, rows),
            scene: BoundingSphere::default(),
        }
    }

    /// Image coordinates of a unit direction in the map's frame; θ = atan2(sin θ, cos θ) rather
    /// than acos(cos θ), which loses the angle near the poles, and v stays below 1 so that a
    /// direction at the pole still falls in the last row of sampling cells.
    fn direction_to_uv(d: Vec3) -> Vec2 {
        let u = d.x.atan2(-d.z) / (2.0 * PI);
        let theta = (d.x * d.x + d.z * d.z).sqrt().atan2(d.y);
        Vec2::new(wrap(u), (theta / PI).min(1.0f32.next_down()))
    }

    /// The direction (map frame) of image coordinates.
    fn uv_to_direction(uv: Vec2) -> Vec3 {
        let (sin_theta, cos_theta) = (PI * uv.y).sin_cos();
        let (sin_phi, cos_phi) = (2.0 * PI * uv.x).sin_cos();
        Vec3::new(sin_phi * sin_theta, cos_theta, -cos_phi * sin_theta)
    }

    /// Half a pixel in u: the offset between the sampling grid's s and the image's u.
    fn half_texel(&self) -> f32 {
        0.5 / self.width as f32
    }

    /// The radiance at image coordinates `uv`: bilinear interpolation between the four
    /// surrounding pixel nodes, of the sigmoid values and of the scales separately (Mitsuba's
    /// `eval_spectrum`), times the map's scale and D65.
    fn lookup(&self, uv: Vec2, lambda: &SampledWavelengths) -> SampledSpectrum {
        let x = wrap(uv.x - self.half_texel()) * self.width as f32;
        let y = uv.y.clamp(0.0, 1.0) * (self.height - 1) as f32;
        let (ix, iy) = (
            (x as usize).min(self.width - 1),
            (y as usize).min(self.height - 2),
        );
        let (fx, fy) = (x - ix as f32, y - iy as f32);
        let ix1 = (ix + 1) % self.width;
        let row0 = iy * self.width;
        let row1 = row0 + self.width;
        let corners = [
            (self.texels[row0 + ix], (1.0 - fx) * (1.0 - fy)),
            (self.texels[row0 + ix1], fx * (1.0 - fy)),
            (self.texels[row1 + ix], (1.0 - fx) * fy),
            (self.texels[row1 + ix1], fx * fy),
        ];
        let scale: f32 = corners.iter().map(|(t, w)| t.scale * w).sum();
        if scale == 0.0 {
            return SampledSpectrum::ZERO;
        }
        let scale = scale * self.scale;
        SampledSpectrum::from_fn(|i| {
            let l = lambda.lambda(i);
            let s: f32 = corners.iter().map(|(t, w)| t.polynomial.eval(l) * w).sum();
            s * scale * d65_normalized(l)
        })
    }

    /// The radiance seen by a ray leaving the scene in the unit direction `d` (world).
    pub fn radiance(&self, d: Vec3, lambda: &SampledWavelengths) -> SampledSpectrum {
        let local = self.to_world.inverse_vector(d).normalize_or_zero();
        self.lookup(Self::direction_to_uv(local), lambda)
    }

    /// Density per unit solid angle of [`Self::sample_incident`]'s direction `d` (world, unit).
    pub fn pdf(&self, d: Vec3) -> f32 {
        let local = self.to_world.inverse_vector(d).normalize_or_zero();
        let sin_theta = (local.x * local.x + local.z * local.z).sqrt();
        if !(sin_theta > 0.0) {
            return 0.0;
        }
        let uv = Self::direction_to_uv(local);
        let s = wrap(uv.x - self.half_texel());
        self.distribution.pdf(Vec2::new(s, uv.y)) / (2.0 * PI * PI * sin_theta)
    }
}

impl LightAtInfinity for EnvironmentMap {
    const IS_DELTA: bool = false;

    fn sample_direction(&self, u: Vec2, lambda: &SampledWavelengths) -> Option<DirectionSample> {
        let p = self.distribution.sample(u);
        let uv = Vec2::new(wrap(p.x + self.half_texel()), p.y);
        let local = Self::uv_to_direction(uv);
        let wi = self.to_world.vector(local).normalize();
        // The density of the direction as rounded, exactly what MIS evaluates for it when BSDF
        // sampling finds it (near the poles sin θ of uv and of wi differ in their last digits).
        let pdf = self.pdf(wi);
        if !(pdf > 0.0 && pdf.is_finite()) {
            return None;
        }
        let radiance = self.lookup(uv, lambda);
        Some(DirectionSample { wi, radiance, pdf })
    }

    fn environment(&self) -> Option<Environment<'_>> {
        Some(Environment::Envmap(self))
    }

    /// Φ = π R² ∫ Y(L) dω, with ∫ Y(L) dω = 2π² ∫∫ Y sin θ du dv the integral of the sampling
    /// weights: the flux entering the scene's bounding sphere, as for [`super::ConstantLight`];
    /// exact for grey maps, and for colours up to the luminance of interpolated spectra.
    fn flux(&self) -> f32 {
        let integral = 2.0 * PI * PI * self.distribution.integral() as f32 * self.scale;
        PI * self.scene.radius * self.scene.radius * integral
    }

    fn scene(&self) -> &BoundingSphere {
        &self.scene
    }

    fn scene_mut(&mut self) -> &mut BoundingSphere {
        &mut self.scene
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::image::Encoding;
    use crate::light::LightSource;

    fn bitmap(width: usize, height: usize, f: impl Fn(usize, usize) -> [f32; 3]) -> Bitmap {
        let data = (0..height)
            .flat_map(|y| (0..width).map(move |x| (x, y)))
            .flat_map(|(x, y)| f(x, y))
            .collect();
        Bitmap {
            width,
            height,
            channels: 3,
            data,
            encoding: Encoding::Linear,
        }
    }

    #[test]
    fn uv_and_directions_follow_mitsuba() {
        let cases = [
            (Vec2::new(0.0, 0.5), Vec3::new(0.0, 0.0, -1.0)),
            (Vec2::new(0.25, 0.5), Vec3::X),
            (Vec2::new(0.5, 0.5), Vec3::Z),
            (Vec2::new(0.75, 0.5), -Vec3::X),
            (Vec2::new(0.3, 0.0), Vec3::Y),
        ];
        for (uv, d) in cases {
            let back = EnvironmentMap::uv_to_direction(uv);
            assert!((back - d).length() < 1e-6, "{uv} -> {back}, not {d}");
        }
        for k in 0..100 {
            let uv = Vec2::new((k % 10) as f32 / 10.0 + 0.03, (k / 10) as f32 / 10.0 + 0.04);
            let d = EnvironmentMap::uv_to_direction(uv);
            let back = EnvironmentMap::direction_to_uv(d);
            assert!((back - uv).length() < 1e-5, "{uv} -> {d} -> {back}");
        }
    }

    /// A pixel's value is reproduced at its node, and halfway between two grey nodes the
    /// spectrum is their mean.
    #[test]
    fn lookup_interpolates_between_pixel_nodes() {
        let map = EnvironmentMap::new(
            bitmap(4, 3, |x, y| [(x + 4 * y) as f32; 3]),
            2.0,
            Transform::IDENTITY,
        );
        let lambda = SampledWavelengths::single(560.0);
        let d65 = d65_normalized(560.0);
        let at = |u: f32, v: f32| map.lookup(Vec2::new(u, v), &lambda)[0] / (2.0 * d65);
        assert!((at(2.5 / 4.0, 0.5) - 6.0).abs() < 1e-4);
        assert!((at(3.0 / 4.0, 0.5) - 6.5).abs() < 1e-4);
        assert!((at(2.5 / 4.0, 0.75) - 8.0).abs() < 1e-4);
        // Periodic in u: between the last column (7) and the first (4) of the middle row.
        assert!((at(0.0, 0.5) - 5.5).abs() < 1e-4);
    }

    /// The power of a uniform map is that of a constant environment, 4π² R² L.
    #[test]
    fn uniform_map_has_the_power_of_a_constant_environment() {
        let mut map = EnvironmentMap::new(bitmap(8, 5, |_, _| [0.5; 3]), 3.0, Transform::IDENTITY);
        map.scene.radius = 2.0;
        let expected = 4.0 * PI * PI * 4.0 * 1.5;
        assert!(
            (map.power(&[]) / expected - 1.0).abs() < 1e-4,
            "{}",
            map.power(&[])
        );
    }
}
