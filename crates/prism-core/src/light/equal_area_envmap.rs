//! pbrt-v4's image infinite light: radiance arriving from infinity, given by a square image in
//! the equal-area octahedral projection (Clarberg 2008; pbrt-v4, `src/pbrt/lights.h`,
//! `ImageInfiniteLight`, and `src/pbrt/util/math.cpp`, `EqualAreaSquareToSphere`).
//!
//! ```xml
//! <emitter type="equal_area_envmap">
//!     <string name="filename" value="sky.exr"/>    <!-- required; a square image -->
//!     <float name="scale" value="1"/>              <!-- multiplies the image -->
//!     <transform name="to_world">                  <!-- rotates the map -->
//!         <rotate x="1" angle="-90"/>
//!     </transform>
//! </emitter>
//! ```
//! Its parameters and their defaults are listed in docs/plugins.md.
//!
//! # The projection
//! The image's (u, v) ∈ [0, 1]² (u to the right, v down, as pbrt indexes pixels) map to the
//! unit sphere of the map's frame: with (a, b) = (2u − 1, 2v − 1), the diamond |a| + |b| ≤ 1 is
//! the hemisphere z ≥ 0 and the four corners fold onto z < 0. With r = 1 − |1 − |a| − |b||,
//! z = ±(1 − r²), φ = π/4 · ((|b| − |a|)/r + 1) in the quadrant of (a, b), and the direction is
//! (r √(2 − r²) cos φ, r √(2 − r²) sin φ, z). The map preserves area: every pixel of an N × N
//! image covers 4π/N² sr, so dω = 4π du dv. (0.5, 0.5) looks along +z, (1, 0.5) along +x,
//! (0.5, 1) along +y, and the corners along −z.
//!
//! # Lookup and spectra
//! A direction reads the pixel it falls in, without interpolation (pbrt's `LookupNearest`);
//! nearest lookups stay inside the square, so pbrt's octahedral wrap, which continues the image
//! across its edges for filtered lookups, is never needed. Each pixel's linear RGB becomes an
//! RGB illuminant spectrum (the colour times D65 of luminance 1, as pbrt-v4's
//! `RGBIlluminantSpectrum` scaled to luminance 1), times `scale`.
//!
//! # Sampling
//! Directions are drawn from a piecewise-constant density over the pixels, each in proportion to
//! its luminance: the radiance is constant on each pixel and the projection keeps areas, so
//! the density per solid angle is p(u, v) / (4π) and a grey map's samples all carry the same
//! weight. Rays that leave the scene see the map and are weighted by multiple importance
//! sampling against these samples.

use std::f32::consts::{FRAC_PI_4, PI};

use glam::{Vec2, Vec3};

use super::{BoundingSphere, DirectionSample, Environment, LightAtInfinity};
use crate::image::Bitmap;
use crate::math::Transform;
use crate::sampling::distribution::PiecewiseConstant2D;
use crate::spectrum::cie::LINEAR_SRGB_TO_XYZ;
use crate::spectrum::{RgbIntent, SampledSpectrum, SampledWavelengths, Spectrum};

/// The direction of the point `p` ∈ [0, 1]² of the equal-area octahedral square (module
/// documentation; pbrt-v4's `EqualAreaSquareToSphere`).
pub fn equal_area_square_to_sphere(p: Vec2) -> Vec3 {
    let (a, b) = (2.0 * p.x - 1.0, 2.0 * p.y - 1.0);
    let (a_abs, b_abs) = (a.abs(), b.abs());
    // The signed distance from the diagonal |a| + |b| = 1: positive in the upper hemisphere.
    let signed_distance = 1.0 - (a_abs + b_abs);
    let r = 1.0 - signed_distance.abs();
    let phi = if r == 0.0 {
        FRAC_PI_4
    } else {
        ((b_abs - a_abs) / r + 1.0) * FRAC_PI_4
    };
    let z = (1.0 - r * r).copysign(signed_distance);
    let radius = r * (2.0 - r * r).max(0.0).sqrt();
    Vec3::new(
        phi.cos().copysign(a) * radius,
        phi.sin().copysign(b) * radius,
        z,
    )
}

/// The point of the equal-area octahedral square that looks along the unit direction `d`, the
/// inverse of [`equal_area_square_to_sphere`] (pbrt-v4's `EqualAreaSphereToSquare`, with the
/// arctangent itself where pbrt approximates it by a polynomial).
pub fn equal_area_sphere_to_square(d: Vec3) -> Vec2 {
    let (x, y, z) = (d.x.abs(), d.y.abs(), d.z.abs());
    let r = (1.0 - z).max(0.0).sqrt();
    let (larger, smaller) = (x.max(y), x.min(y));
    let ratio = if larger == 0.0 { 0.0 } else { smaller / larger };
    // φ / (π/2) within the quadrant, measured from the axis of the larger coordinate.
    let mut phi = ratio.atan() / (2.0 * FRAC_PI_4);
    if x < y {
        phi = 1.0 - phi;
    }
    let mut v = phi * r;
    let mut u = r - v;
    if d.z < 0.0 {
        // The lower hemisphere: the corner triangle opposite the diamond's edge.
        (u, v) = (1.0 - v, 1.0 - u);
    }
    Vec2::new(0.5 * (u.copysign(d.x) + 1.0), 0.5 * (v.copysign(d.y) + 1.0))
}

#[derive(Clone, Debug)]
pub struct EqualAreaEnvmap {
    /// The image's width and height, in pixels.
    resolution: usize,
    /// Each pixel's radiance, row-major, top row (v = 0) first.
    texels: Vec<Spectrum>,
    scale: f32,
    /// Map-to-world rotation.
    to_world: Transform,
    /// Density over (u, v) ∈ [0, 1)², one cell per pixel, ∝ the pixel's luminance.
    distribution: PiecewiseConstant2D,
    /// The scene's bounding sphere (set when the scene is assembled).
    pub scene: BoundingSphere,
}

impl EqualAreaEnvmap {
    /// The map of a square image whose values are finite and non-negative (the scene reader
    /// checks both), times `scale` ≥ 0, rotated by `to_world`. Grey images are replicated to
    /// three channels; alpha is ignored.
    pub fn new(mut bitmap: Bitmap, scale: f32, to_world: Transform) -> EqualAreaEnvmap {
        assert_eq!(bitmap.width, bitmap.height, "an equal-area map is square");
        bitmap.linearize();
        let resolution = bitmap.width;
        let rgb: Vec<[f32; 3]> = (0..resolution)
            .flat_map(|y| (0..resolution).map(move |x| (x, y)))
            .map(|(x, y)| {
                if bitmap.channels < 3 {
                    [bitmap.value(x, y, 0); 3]
                } else {
                    std::array::from_fn(|c| bitmap.value(x, y, c))
                }
            })
            .collect();
        let luminance_row = LINEAR_SRGB_TO_XYZ[1];
        let weights: Vec<f32> = rgb
            .iter()
            .map(|c| {
                (luminance_row[0] * c[0] + luminance_row[1] * c[1] + luminance_row[2] * c[2])
                    .max(0.0)
            })
            .collect();
        EqualAreaEnvmap {
            resolution,
            texels: rgb
                .iter()
                .map(|&c| Spectrum::from_rgb(c, RgbIntent::Illuminant))
                .collect(),
            scale,
            to_world,
            distribution: PiecewiseConstant2D::new(&weights, resolution, resolution),
            scene: BoundingSphere::default(),
        }
    }

    /// The point of the square (inside [0, 1)², so that it falls in a pixel) that the world
    /// direction `d` looks along.
    fn square_point(&self, d: Vec3) -> Vec2 {
        let local = self.to_world.inverse_vector(d).normalize_or_zero();
        equal_area_sphere_to_square(local).clamp(Vec2::ZERO, Vec2::splat(1.0f32.next_down()))
    }

    /// The radiance seen by a ray leaving the scene in the unit direction `d` (world): the
    /// pixel it falls in.
    pub fn radiance(&self, d: Vec3, lambda: &SampledWavelengths) -> SampledSpectrum {
        let p = self.square_point(d);
        let n = self.resolution;
        let (x, y) = (
            ((p.x * n as f32) as usize).min(n - 1),
            ((p.y * n as f32) as usize).min(n - 1),
        );
        self.texels[y * n + x].sample(lambda) * self.scale
    }

    /// Density per unit solid angle of [`LightAtInfinity::sample_direction`]'s direction `d`
    /// (world, unit): the square's density over its 4π sr.
    pub fn pdf(&self, d: Vec3) -> f32 {
        self.distribution.pdf(self.square_point(d)) / (4.0 * PI)
    }
}

impl LightAtInfinity for EqualAreaEnvmap {
    const IS_DELTA: bool = false;

    fn sample_direction(&self, u: Vec2, lambda: &SampledWavelengths) -> Option<DirectionSample> {
        let p = self.distribution.sample(u);
        let wi = self
            .to_world
            .vector(equal_area_square_to_sphere(p))
            .normalize();
        // The density and radiance of the direction as rounded, exactly what MIS evaluates
        // for it when BSDF sampling finds it.
        let pdf = self.pdf(wi);
        if !(pdf > 0.0 && pdf.is_finite()) {
            return None;
        }
        Some(DirectionSample {
            wi,
            radiance: self.radiance(wi, lambda),
            pdf,
        })
    }

    fn environment(&self) -> Option<Environment<'_>> {
        Some(Environment::EqualAreaEnvmap(self))
    }

    /// Φ = π R² ∫ Y(L) dω = π R² · 4π · the mean luminance of the pixels: the flux entering
    /// the scene's bounding sphere, as for [`super::ConstantLight`].
    fn flux(&self) -> f32 {
        let integral = 4.0 * PI * self.distribution.integral() as f32 * self.scale;
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
    use crate::light::{ConstantLight, LightSource};

    /// pbrt-v4's orientation: the centre looks along +z, the middle of the right edge along
    /// +x, the middle of the bottom edge along +y, the corners along −z.
    #[test]
    fn the_square_maps_to_the_sphere_as_in_pbrt() {
        let cases = [
            (Vec2::new(0.5, 0.5), Vec3::Z),
            (Vec2::new(1.0, 0.5), Vec3::X),
            (Vec2::new(0.0, 0.5), -Vec3::X),
            (Vec2::new(0.5, 1.0), Vec3::Y),
            (Vec2::new(0.5, 0.0), -Vec3::Y),
            (Vec2::new(0.0, 0.0), -Vec3::Z),
            (Vec2::new(1.0, 1.0), -Vec3::Z),
            // Halfway from the centre to the right edge: r = ½, z = ¾, φ = 0.
            (
                Vec2::new(0.75, 0.5),
                Vec3::new(0.5 * 1.75f32.sqrt(), 0.0, 0.75),
            ),
        ];
        for (p, d) in cases {
            let found = equal_area_square_to_sphere(p);
            assert!((found - d).length() < 1e-6, "{p} -> {found}, not {d}");
        }
    }

    #[test]
    fn sphere_to_square_inverts_square_to_sphere() {
        for k in 0..400 {
            let p = Vec2::new(
                ((k % 20) as f32 + 0.37) / 20.0,
                ((k / 20) as f32 + 0.61) / 20.0,
            );
            let d = equal_area_square_to_sphere(p);
            assert!((d.length() - 1.0).abs() < 1e-5, "{p} -> {d}");
            let back = equal_area_sphere_to_square(d);
            assert!((back - p).length() < 1e-5, "{p} -> {d} -> {back}");
        }
    }

    /// Equal area: the solid angle of a cell of the square, from its corners' directions as a
    /// sum of spherical triangles, is 4π times the cell's area.
    #[test]
    fn cells_of_equal_area_cover_equal_solid_angles() {
        // The solid angle of the spherical triangle (a, b, c) (Van Oosterom & Strackee 1983).
        let triangle = |a: Vec3, b: Vec3, c: Vec3| {
            let numerator = a.dot(b.cross(c)).abs();
            let denominator = 1.0 + a.dot(b) + b.dot(c) + c.dot(a);
            2.0 * numerator.atan2(denominator)
        };
        let n = 64;
        let cell = 1.0 / n as f32;
        let mut largest_error: f32 = 0.0;
        for (i, j) in [(0, 0), (10, 3), (31, 32), (32, 32), (63, 5), (40, 50)] {
            // Subdivided 8 × 8 so that the triangles follow the curved edges.
            let sub = 8;
            let h = cell / sub as f32;
            let mut omega = 0.0;
            for s in 0..sub {
                for t in 0..sub {
                    let corner = |ds: usize, dt: usize| {
                        equal_area_square_to_sphere(Vec2::new(
                            i as f32 * cell + (s + ds) as f32 * h,
                            j as f32 * cell + (t + dt) as f32 * h,
                        ))
                    };
                    let (a, b, c, d) = (corner(0, 0), corner(1, 0), corner(1, 1), corner(0, 1));
                    omega += triangle(a, b, c) + triangle(a, c, d);
                }
            }
            let expected = 4.0 * PI * cell * cell;
            largest_error = largest_error.max((omega / expected - 1.0).abs());
        }
        assert!(largest_error < 2e-3, "relative error {largest_error}");
    }

    fn bitmap(n: usize, f: impl Fn(usize, usize) -> [f32; 3]) -> Bitmap {
        Bitmap {
            width: n,
            height: n,
            channels: 3,
            data: (0..n)
                .flat_map(|y| (0..n).map(move |x| (x, y)))
                .flat_map(|(x, y)| f(x, y))
                .collect(),
            encoding: Encoding::Linear,
        }
    }

    /// A map of one colour is a uniform environment: the radiance, the density 1/(4π) and the
    /// power of `constant` with the same colour (closed form: 4π² R² times the luminance).
    #[test]
    fn a_constant_map_is_a_uniform_environment() {
        let colour = [0.3, 0.5, 0.2];
        let mut map = EqualAreaEnvmap::new(bitmap(8, |_, _| colour), 2.0, Transform::IDENTITY);
        let mut uniform = ConstantLight::new(Spectrum::from_rgb(
            colour.map(|c| 2.0 * c),
            RgbIntent::Illuminant,
        ));
        map.scene.radius = 3.0;
        uniform.scene.radius = 3.0;
        let lambda = SampledWavelengths::sample(0.3, crate::spectrum::WavelengthSampling::Uniform);
        for k in 0..50 {
            let u = Vec2::new((k % 7) as f32 / 7.0 + 0.05, (k / 7) as f32 / 8.0 + 0.01);
            let s = map.sample_direction(u, &lambda).expect("a sample");
            assert!((s.pdf - 1.0 / (4.0 * PI)).abs() < 1e-6, "pdf {}", s.pdf);
            let expected = uniform.radiance(&lambda);
            for i in 0..4 {
                assert!(
                    (s.radiance[i] / expected[i] - 1.0).abs() < 1e-5,
                    "{:?} against {expected:?}",
                    s.radiance
                );
            }
        }
        // The map weighs pixels by the luminance of their RGB, `constant` by that of the
        // upsampled spectrum, which the fit reproduces to about 10⁻⁴.
        let ratio = map.power(&[]) / uniform.power(&[]);
        assert!((ratio - 1.0).abs() < 1e-3, "power ratio {ratio}");
    }
}
