//! Mitsuba's `blackbody` spectrum: Planck's law for the spectral radiance of a black body.
//!
//! ```xml
//! <emitter type="area">
//!     <spectrum type="blackbody" name="radiance">
//!         <float name="temperature" value="5000"/>   <!-- kelvin; required, > 0 -->
//!     </spectrum>
//! </emitter>
//! ```
//!
//! Mitsuba 3 (3.9.1, spectral variants) does not normalise the spectrum: its values are the
//! physical spectral radiance in W m⁻² sr⁻¹ nm⁻¹, zero outside 360–830 nm, so a 3000 K body has
//! about 400 at 555 nm (checked against Mitsuba 3.9.1). Scenes are then in metres and watts; a
//! `scale` is not available (Mitsuba's plugin takes only `temperature`).

use super::{LAMBDA_MAX, LAMBDA_MIN};

/// Speed of light in vacuum, m/s (exact, SI 2019).
const C: f64 = 2.997_924_58e8;
/// Planck constant, J s (the CODATA 2014 value Mitsuba uses).
const H: f64 = 6.626_070_04e-34;
/// Boltzmann constant, J/K (CODATA 2014, as in Mitsuba).
const K_B: f64 = 1.380_648_52e-23;

/// A black body at a fixed temperature.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Blackbody {
    /// Temperature in kelvin, finite and positive (checked by the scene reader).
    pub temperature: f32,
}

impl Blackbody {
    /// Planck's law, B(λ, T) = 2hc² / (λ⁵ (e^{hc/(λ k T)} − 1)) with λ in metres, per nanometre
    /// (× 10⁻⁹): W m⁻² sr⁻¹ nm⁻¹ at `lambda` nm; zero outside 360–830 nm as in Mitsuba 3.
    pub fn value(&self, lambda: f32) -> f32 {
        if !(LAMBDA_MIN..=LAMBDA_MAX).contains(&lambda) {
            return 0.0;
        }
        let l = f64::from(lambda) * 1e-9;
        let exponent = H * C / (l * K_B * f64::from(self.temperature));
        (1e-9 * 2.0 * H * C * C / (l.powi(5) * exponent.exp_m1())) as f32
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Values printed by Mitsuba 3.9.1 (scalar_spectral) for `blackbody` at 3000 K and 6500 K.
    #[test]
    fn matches_mitsuba() {
        let cases = [
            (3000.0, 360.0, 32.2656),
            (3000.0, 555.0, 399.639),
            (3000.0, 830.0, 938.497),
            (6500.0, 400.0, 46138.8),
            (6500.0, 700.0, 31327.1),
        ];
        for (temperature, lambda, expected) in cases {
            let b = Blackbody { temperature }.value(lambda);
            assert!(
                (b / expected - 1.0).abs() < 1e-4,
                "{temperature} K, {lambda} nm: {b} vs {expected}"
            );
        }
        let b = Blackbody {
            temperature: 3000.0,
        };
        assert_eq!(b.value(359.9), 0.0);
        assert_eq!(b.value(830.1), 0.0);
    }

    /// Wien's displacement law: the peak is at b / T with b = 2.897771955 mm K.
    #[test]
    fn peak_follows_wien() {
        let b = Blackbody {
            temperature: 5000.0,
        };
        let peak = (400..=800)
            .map(|l| l as f32)
            .max_by(|x, y| b.value(*x).total_cmp(&b.value(*y)))
            .unwrap();
        assert!(
            (f64::from(peak) - 2.897_771_955e6 / 5000.0).abs() <= 1.0,
            "{peak}"
        );
    }
}
