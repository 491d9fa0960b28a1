//! Indices of refraction of dielectrics: Mitsuba's named constants, and dispersive indices given
//! by Sellmeier or Cauchy formulas or by a table.
//!
//! Mitsuba 3's dielectric BSDFs take a constant `int_ior`/`ext_ior` (a number or one of the names
//! of [`NAMED_IORS`]). A dispersive index is our extension, written as a spectrum:
//!
//! ```xml
//! <spectrum name="int_ior" value="400:1.5308, 500:1.5214, 600:1.5163, 700:1.5131"/>
//! <spectrum name="int_ior" type="sellmeier"> <string name="glass" value="N-SF11"/> </spectrum>
//! <spectrum name="int_ior" type="sellmeier">
//!     <float name="b1" value="1.0396"/> <float name="b2" value="0.2318"/> <float name="b3" value="1.0105"/>
//!     <float name="c1" value="0.0060"/> <float name="c2" value="0.0200"/> <float name="c3" value="103.56"/>
//! </spectrum>
//! <spectrum name="int_ior" type="cauchy"> <float name="a" value="1.5"/> <float name="b" value="0.0042"/> </spectrum>
//! ```
//! Sellmeier's C and Cauchy's B, C are in µm² and µm⁴, as in glass catalogues.

use super::spectra::PiecewiseLinear;

/// Mitsuba's named indices of refraction (`include/mitsuba/render/ior.h`): "Many values are
/// taken from Hecht, Optics, Fourth Edition. The IOR values are from measurements between 0 and
/// 20 degrees celsius at ~589 nm."
pub const NAMED_IORS: &[(&str, f32)] = &[
    ("vacuum", 1.0),
    ("helium", 1.000_036),
    ("hydrogen", 1.000_132),
    ("air", 1.000_277),
    ("carbon dioxide", 1.000_45),
    ("water", 1.3330),
    ("acetone", 1.36),
    ("ethanol", 1.361),
    ("carbon tetrachloride", 1.461),
    ("glycerol", 1.4729),
    ("benzene", 1.501),
    ("silicone oil", 1.520_45),
    ("bromine", 1.661),
    ("water ice", 1.31),
    ("fused quartz", 1.458),
    ("pyrex", 1.470),
    ("acrylic glass", 1.49),
    ("polypropylene", 1.49),
    ("bk7", 1.5046),
    ("sodium chloride", 1.544),
    ("amber", 1.55),
    ("pet", 1.5750),
    ("diamond", 2.419),
];

/// The index called `name` (case-insensitive, as Mitsuba).
pub fn named_ior(name: &str) -> Option<f32> {
    let lower = name.to_lowercase();
    NAMED_IORS
        .iter()
        .find(|(n, _)| *n == lower)
        .map(|&(_, v)| v)
}

/// Sellmeier coefficients of glasses, n²(λ) = 1 + Σᵢ Bᵢ λ² / (λ² − Cᵢ) with λ in µm.
/// Sources: SCHOTT optical glass data sheets (N-BK7, N-SF11, N-F2); Malitson 1965, "Interspecimen
/// Comparison of the Refractive Index of Fused Silica", JOSA 55 (fused silica); Peter 1923 as
/// tabulated by refractiveindex.info (diamond). The coefficients are written as published.
#[allow(clippy::excessive_precision)]
pub const SELLMEIER_GLASSES: &[(&str, [f32; 3], [f32; 3])] = &[
    (
        "N-BK7",
        [1.039_612_1, 0.231_792_34, 1.010_469_5],
        [0.006_000_698_7, 0.020_017_914, 103.560_65],
    ),
    (
        "N-SF11",
        [1.737_597, 0.313_747_35, 1.898_781],
        [0.013_188_707, 0.062_306_814, 155.236_29],
    ),
    (
        "N-F2",
        [1.397_570_4, 0.159_201_4, 1.268_654_3],
        [0.009_956_718_1, 0.054_693_058, 119.248_35],
    ),
    (
        "fused silica",
        [0.696_166_3, 0.407_942_6, 0.897_479_4],
        [0.004_679_148_3, 0.013_512_063, 97.934_003],
    ),
    (
        "diamond",
        [0.3306, 4.3356, 0.0],
        [0.030_625, 0.011_236, 0.0],
    ),
];

/// The Sellmeier coefficients of a glass of [`SELLMEIER_GLASSES`] (case-insensitive).
pub fn sellmeier_glass(name: &str) -> Option<([f32; 3], [f32; 3])> {
    SELLMEIER_GLASSES
        .iter()
        .find(|(n, _, _)| n.eq_ignore_ascii_case(name))
        .map(|&(_, b, c)| (b, c))
}

/// An index of refraction as a function of wavelength.
#[derive(Clone, Debug, PartialEq)]
pub enum Ior {
    Constant(f32),
    /// n²(λ) = 1 + Σᵢ Bᵢ λ² / (λ² − Cᵢ), λ in µm (Sellmeier 1871).
    Sellmeier {
        b: [f32; 3],
        c: [f32; 3],
    },
    /// n(λ) = A + B/λ² + C/λ⁴, λ in µm (Cauchy 1836).
    Cauchy {
        a: f32,
        b: f32,
        c: f32,
    },
    /// Linear interpolation of measured values, held constant beyond the first and last.
    Tabulated(PiecewiseLinear),
}

impl Ior {
    /// n at `lambda` nm.
    #[inline]
    pub fn at(&self, lambda: f32) -> f32 {
        match self {
            Ior::Constant(n) => *n,
            Ior::Sellmeier { b, c } => {
                let l2 = (lambda * 1e-3) * (lambda * 1e-3);
                let n2 = 1.0 + (0..3).map(|i| b[i] * l2 / (l2 - c[i])).sum::<f32>();
                n2.max(0.0).sqrt()
            }
            Ior::Cauchy { a, b, c } => {
                let l2 = (lambda * 1e-3) * (lambda * 1e-3);
                a + b / l2 + c / (l2 * l2)
            }
            Ior::Tabulated(table) => {
                let (lo, hi) = table.range();
                table.value(lambda.clamp(lo, hi))
            }
        }
    }

    pub fn is_constant(&self) -> bool {
        matches!(self, Ior::Constant(_))
    }

    /// The smallest index over 360–830 nm (sampled at 1 nm), to reject non-physical input.
    pub fn min_value(&self) -> f32 {
        (0..=470)
            .map(|i| self.at(super::LAMBDA_MIN + i as f32))
            .fold(
                f32::INFINITY,
                |m, v| if v.is_nan() { f32::NAN } else { m.min(v) },
            )
    }
}

/// The relative index η = n_interior / n_exterior of an interface (the exterior is the side the
/// normal points to).
#[derive(Clone, Debug, PartialEq)]
pub struct RelativeIor {
    pub interior: Ior,
    pub exterior: Ior,
}

impl RelativeIor {
    /// A constant relative index.
    pub fn constant(eta: f32) -> RelativeIor {
        RelativeIor {
            interior: Ior::Constant(eta),
            exterior: Ior::Constant(1.0),
        }
    }

    /// η at `lambda` nm.
    #[inline]
    pub fn at(&self, lambda: f32) -> f32 {
        self.interior.at(lambda) / self.exterior.at(lambda)
    }

    /// Whether η depends on the wavelength (so refraction disperses light).
    pub fn is_dispersive(&self) -> bool {
        !(self.interior.is_constant() && self.exterior.is_constant())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Catalogue values: N-BK7 n_d = 1.5168 and n_F = 1.5224 (at 587.6 and 486.1 nm); fused
    /// silica n = 1.4585 at 587.6 nm; N-SF11 n_d = 1.7847; N-F2 n_d = 1.6200.
    #[test]
    fn sellmeier_glasses_match_their_catalogue_indices() {
        let n = |glass: &str, lambda: f32| {
            let (b, c) = sellmeier_glass(glass).unwrap();
            Ior::Sellmeier { b, c }.at(lambda)
        };
        assert!((n("N-BK7", 587.56) - 1.5168).abs() < 2e-4);
        assert!((n("n-bk7", 486.13) - 1.5224).abs() < 2e-4);
        assert!((n("fused silica", 587.56) - 1.4585).abs() < 2e-4);
        assert!((n("N-SF11", 587.56) - 1.7847).abs() < 2e-4);
        assert!((n("N-F2", 587.56) - 1.6200).abs() < 2e-4);
        assert!((n("diamond", 589.0) - 2.417).abs() < 3e-3);
    }

    #[test]
    fn named_iors_are_found_case_insensitively() {
        assert_eq!(named_ior("BK7"), Some(1.5046));
        assert_eq!(named_ior("Water Ice"), Some(1.31));
        assert_eq!(named_ior("glass"), None);
    }

    #[test]
    fn cauchy_and_tables() {
        let cauchy = Ior::Cauchy {
            a: 1.5,
            b: 0.01,
            c: 0.0,
        };
        assert!((cauchy.at(500.0) - 1.54).abs() < 1e-6);
        let table = Ior::Tabulated(PiecewiseLinear::new(&[(400.0, 1.6), (700.0, 1.5)]).unwrap());
        assert_eq!(table.at(300.0), 1.6);
        assert!((table.at(550.0) - 1.55).abs() < 1e-6);
        assert_eq!(table.at(800.0), 1.5);
        assert!(
            RelativeIor {
                interior: table,
                exterior: Ior::Constant(1.0)
            }
            .is_dispersive()
        );
    }
}
