//! Where a light is and how much it could give a point: the bounds behind choosing lights by
//! their importance at the shading point (Conty Estevez and Kulla 2018, "Importance Sampling of
//! Many Lights with Adaptive Tree Splitting", §4.3; pbrt-v4, §12.6.3, `LightBounds::Importance`).
//!
//! A light at a finite place is bounded by a box (a point for point, spot and projector lights)
//! with bounding sphere (c, r), and carries its power Φ. Seen from a receiver p with normal n at
//! distance d = |c − p| > r, the light subtends at most the cone of half-angle θ_b around the
//! direction ω = (c − p)/d, sin θ_b = r/d. Every direction towards the light is then within θ_b
//! of ω, so the receiver's cosine is at most cos(max(0, θᵢ − θ_b)) ≤ min(1, cos θᵢ + sin θ_b),
//! cos θᵢ = |n · ω| (pbrt-v4 takes the first bound; the second costs one square root and one
//! division in all), and the importance is
//!
//! ```text
//!     I(p, n) = Φ · min(1, (|n · (c − p)| + r) / d) / d²,
//! ```
//!
//! the irradiance a point source of power Φ at c would give, with its cosine widened by the
//! light's extent; inside the bounding sphere (d ≤ r) it is Φ / r². Emitters are counted as
//! radiating in every direction: their own orientation is not bounded (pbrt-v4's cone of normals
//! θ_o, θ_e is left at π), which keeps I positive wherever the light can give light. Without a
//! normal (a point in a medium) the cosine factor is 1.

use glam::Vec3;

/// A light's bounding sphere and power.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightBounds {
    /// Centre c of the bounding sphere.
    pub center: Vec3,
    /// Radius r of the bounding sphere.
    pub radius: f32,
    /// The power Φ (luminance-weighted, times the light's sampling weight).
    pub power: f32,
}

/// The point light arrives at, and its shading normal if it lies on a surface (pbrt-v4's
/// `LightSampleContext`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Receiver {
    pub p: Vec3,
    pub n: Option<Vec3>,
}

impl Receiver {
    /// A receiver on a surface with (unit) shading normal `n`.
    pub fn surface(p: Vec3, n: Vec3) -> Receiver {
        Receiver { p, n: Some(n) }
    }

    /// A receiver without a surface (in a medium).
    pub fn point(p: Vec3) -> Receiver {
        Receiver { p, n: None }
    }
}

impl LightBounds {
    /// The bounds of a light occupying the box [lo, hi], of power `power`.
    pub fn around_box(lo: Vec3, hi: Vec3, power: f32) -> LightBounds {
        LightBounds {
            center: 0.5 * (lo + hi),
            radius: (0.5 * (hi - lo)).length(),
            power,
        }
    }

    /// The bounds of a light at the single point `p`.
    pub fn at_point(p: Vec3, power: f32) -> LightBounds {
        LightBounds {
            center: p,
            radius: 0.0,
            power,
        }
    }

    /// I(p, n) of the module's text: 0 only for a light of no power, or for a point light in the
    /// receiver's tangent plane.
    #[inline]
    pub fn importance(&self, receiver: &Receiver) -> f32 {
        if !(self.power > 0.0) {
            return 0.0;
        }
        let to_light = self.center - receiver.p;
        // Below the smallest distance at which the product keeps its precision, the light is as
        // good as reached.
        let distance_squared = to_light
            .length_squared()
            .max(self.radius * self.radius)
            .max(1e-12);
        let Some(n) = receiver.n else {
            return self.power / distance_squared;
        };
        let inverse_distance = distance_squared.sqrt().recip();
        let cosine = ((n.dot(to_light).abs() + self.radius) * inverse_distance).min(1.0);
        self.power * cosine * inverse_distance * inverse_distance
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The importance bounds the irradiance cosine: for points spread over a sphere light, the
    /// receiver's |cos| towards each is at most the importance's cosine factor.
    #[test]
    fn the_receiver_cosine_bounds_every_direction_to_the_light() {
        let bounds =
            LightBounds::around_box(Vec3::new(1.0, 2.0, 0.5), Vec3::new(1.6, 2.4, 1.5), 3.0);
        let r = bounds.radius;
        let receiver = Receiver::surface(Vec3::new(0.2, -0.3, 0.1), Vec3::new(0.0, 0.6, 0.8));
        let d2 = (bounds.center - receiver.p).length_squared();
        let bound = bounds.importance(&receiver) * d2 / bounds.power;
        let n = receiver.n.unwrap();
        let mut largest = 0.0f32;
        for i in 0..64 {
            for j in 0..32 {
                let (phi, cos_theta) = (
                    i as f32 / 64.0 * std::f32::consts::TAU,
                    j as f32 / 16.0 - 1.0,
                );
                let sin_theta = (1.0 - cos_theta * cos_theta).sqrt();
                let q = bounds.center
                    + r * Vec3::new(sin_theta * phi.cos(), sin_theta * phi.sin(), cos_theta);
                largest = largest.max(n.dot((q - receiver.p).normalize()).abs());
            }
        }
        assert!(largest <= bound + 1e-5, "{largest} > {bound}");
        assert!(bound < 1.0, "the bound is not trivial here: {bound}");
    }

    #[test]
    fn near_and_inside_the_light_the_distance_is_clamped() {
        let bounds = LightBounds::around_box(Vec3::splat(-1.0), Vec3::splat(1.0), 6.0);
        let inside = Receiver::surface(Vec3::new(0.5, 0.0, 0.0), Vec3::X);
        assert!((bounds.importance(&inside) - 6.0 / 3.0).abs() < 1e-5);
        let far = Receiver::point(Vec3::new(10.0, 0.0, 0.0));
        assert!((bounds.importance(&far) - 6.0 / 100.0).abs() < 1e-6);
        let point = LightBounds::at_point(Vec3::ZERO, 1.0);
        let tangent = Receiver::surface(Vec3::new(1.0, 0.0, 0.0), Vec3::Y);
        assert_eq!(point.importance(&tangent), 0.0);
        assert!(point.importance(&Receiver::point(Vec3::ZERO)).is_finite());
    }
}
