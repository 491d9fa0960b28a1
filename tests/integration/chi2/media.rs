//! Chi-square tests of the media's sampling routines: the Henyey–Greenstein, Rayleigh,
//! tabulated, blended and SGGX phase functions against their densities (and the SGGX
//! distribution's normalisations), and free-flight distances against m·exp(−m t) with the
//! probability exp(−m L) of passing the segment.

use glam::{Vec2, Vec3};
use prism_core::medium::sample_free_flight;
use prism_core::medium::{
    BlendPhase, HenyeyGreenstein, Isotropic, PhaseFunction, PhaseModel, Rayleigh, Sggx,
    TabulatedPhase,
};
use prism_core::sampling::chi2::{Suite, chi2_interval, chi2_sphere};
use prism_core::sampling::rng::Pcg32;
use prism_core::sampling::warp::sample_uniform_sphere;

/// The chi-square tests of this module, one name per statistic: the suite of Šidák's correction.
const SUITE: Suite = Suite::new(&[
    "hg g = 0.7",
    "hg g = -0.4",
    "isotropic",
    "blendphase",
    "rayleigh",
    "tabphase forward",
    "tabphase two bumps",
    "sggx diagonal",
    "sggx skewed",
    "free flight m = 0.8",
    "free flight m = 3",
]);
const SAMPLES: usize = 1_000_000;

fn phase_chi2(name: &str, phase: &PhaseFunction, wo: Vec3, seed: u64) {
    let wo = wo.normalize();
    let outcome = chi2_sphere(
        SAMPLES,
        101,
        202,
        seed,
        |rng| {
            let s = phase.sample(wo, Vec2::new(rng.next_f32(), rng.next_f32()));
            assert!(
                (s.pdf - phase.eval(wo, s.wi)).abs() <= 1e-4 * s.pdf.max(1.0),
                "{name}: the sample's pdf {} differs from the density {}",
                s.pdf,
                phase.eval(wo, s.wi)
            );
            Some(s.wi)
        },
        |wi| f64::from(phase.eval(wo, wi)),
    )
    .unwrap();
    SUITE.assert_passes(name, &outcome);
}

#[test]
fn henyey_greenstein_forward_follows_its_density() {
    phase_chi2(
        "hg g = 0.7",
        &PhaseFunction::HenyeyGreenstein(HenyeyGreenstein { g: 0.7 }),
        Vec3::new(0.3, -0.2, 0.9),
        1,
    );
}

#[test]
fn henyey_greenstein_backward_follows_its_density() {
    phase_chi2(
        "hg g = -0.4",
        &PhaseFunction::HenyeyGreenstein(HenyeyGreenstein { g: -0.4 }),
        Vec3::new(-0.5, 0.6, -0.2),
        2,
    );
}

#[test]
fn isotropic_phase_is_uniform() {
    phase_chi2(
        "isotropic",
        &PhaseFunction::Isotropic(Isotropic),
        Vec3::Z,
        3,
    );
}

#[test]
fn blendphase_follows_the_mixture_density() {
    phase_chi2(
        "blendphase",
        &PhaseFunction::Blend(BlendPhase {
            weight: 0.3,
            first: Box::new(PhaseFunction::HenyeyGreenstein(HenyeyGreenstein { g: 0.6 })),
            second: Box::new(PhaseFunction::Blend(BlendPhase {
                weight: 0.5,
                first: Box::new(PhaseFunction::Isotropic(Isotropic)),
                second: Box::new(PhaseFunction::HenyeyGreenstein(HenyeyGreenstein {
                    g: -0.8,
                })),
            })),
        }),
        Vec3::new(0.1, 0.9, 0.4),
        4,
    );
}

#[test]
fn rayleigh_follows_its_density() {
    phase_chi2(
        "rayleigh",
        &PhaseFunction::Rayleigh(Rayleigh),
        Vec3::new(0.2, -0.7, 0.3),
        5,
    );
}

#[test]
fn tabphase_follows_its_density() {
    // Mostly forward scattering, and a table with a zero stretch between two bumps.
    let forward = TabulatedPhase::new(&[0.1, 0.2, 0.4, 1.0, 3.0, 9.0]).unwrap();
    phase_chi2(
        "tabphase forward",
        &PhaseFunction::Tabulated(forward),
        Vec3::new(0.6, 0.1, -0.4),
        6,
    );
    let bumps = TabulatedPhase::new(&[2.0, 0.5, 0.0, 0.0, 0.0, 1.0, 4.0, 0.3]).unwrap();
    phase_chi2(
        "tabphase two bumps",
        &PhaseFunction::Tabulated(bumps),
        Vec3::new(-0.1, 0.2, 0.95),
        7,
    );
}

/// The two matrices of Mitsuba 3's own SGGX chi-square tests: a diagonal one (flakes flattened
/// across x) and a skewed one with every off-diagonal entry set.
fn sggx_matrices() -> [(&'static str, Sggx); 2] {
    [
        (
            "sggx diagonal",
            Sggx::new([0.15, 1.0, 0.8, 0.0, 0.0, 0.0]).unwrap(),
        ),
        (
            "sggx skewed",
            Sggx::new([1.0, 0.35, 0.32, 0.52, 0.44, 0.2]).unwrap(),
        ),
    ]
}

#[test]
fn sggx_follows_its_density() {
    for ((name, sggx), (wo, seed)) in sggx_matrices().into_iter().zip([
        (Vec3::new(0.3, 0.2, 0.9), 81),
        (Vec3::new(-0.7, 0.1, 0.4), 82),
    ]) {
        phase_chi2(name, &PhaseFunction::Sggx(sggx), wo, seed);
    }
}

/// Over uniform directions on the sphere (10⁶ of them), for several wo: the phase function
/// integrates to 1 over wi, and ⟨wo, m⟩₊ D(m) integrates to the projected area σ(wo) (through
/// the phase function at wi = reflect(wo, m): D(m) = 4 σ(wo) p(wo, wi), so the second integral
/// is ∫ ⟨wo, m⟩₊ 4 σ(wo) p(wo, 2(wo·m)m − wo) dm). Each within 5 standard errors, the errors
/// below 1 %; the projected area is bounded by the majorant's bound.
#[test]
fn sggx_is_normalised() {
    let n = 1_000_000;
    for (name, sggx) in sggx_matrices() {
        let phase = PhaseFunction::Sggx(sggx);
        for (k, wo) in [
            Vec3::Z,
            Vec3::new(0.6, -0.3, 0.5),
            Vec3::new(-0.2, 0.9, -0.4),
        ]
        .into_iter()
        .enumerate()
        {
            let wo = wo.normalize();
            let sigma = phase.projected_area(wo);
            assert!(sigma > 0.0 && sigma <= phase.max_projected_area());
            let mut rng = Pcg32::seeded(90 + k as u64);
            let (mut sum, mut sum2, mut visible, mut visible2) = (0.0f64, 0.0, 0.0f64, 0.0);
            for _ in 0..n {
                let w = sample_uniform_sphere(Vec2::new(rng.next_f32(), rng.next_f32()));
                let p = 4.0 * std::f64::consts::PI * f64::from(phase.eval(wo, w));
                sum += p;
                sum2 += p * p;
                let cos = wo.dot(w);
                let v = if cos > 0.0 {
                    let wi = (2.0 * cos * w - wo).normalize();
                    4.0 * std::f64::consts::PI * f64::from(cos * 4.0 * sigma * phase.eval(wo, wi))
                } else {
                    0.0
                };
                visible += v;
                visible2 += v * v;
            }
            let nf = f64::from(n);
            for (what, total, total2, expected) in [
                ("∫ p dwi", sum, sum2, 1.0),
                ("∫ ⟨wo, m⟩ D(m) dm", visible, visible2, f64::from(sigma)),
            ] {
                let mean = total / nf;
                let se = ((total2 / nf - mean * mean) / (nf - 1.0)).sqrt();
                assert!(
                    se < 0.01 * expected,
                    "{name}, wo {wo}: {what} has the error {se}"
                );
                assert!(
                    (mean - expected).abs() < 5.0 * se,
                    "{name}, wo {wo}: {what} = {mean} ± {se}, expected {expected}"
                );
            }
        }
    }
}

#[test]
fn tabphase_scatters_forward_where_its_table_is_large_at_cosine_one() {
    // Physics convention: the table's last value is forward scattering, wi = −wo.
    let forward = TabulatedPhase::new(&[0.0, 0.0, 1.0]).unwrap();
    let wo = Vec3::new(0.0, 0.0, 1.0);
    assert!(forward.eval(wo, -wo) > 0.3);
    assert_eq!(forward.eval(wo, wo), 0.0);
    let s = forward.sample(wo, Vec2::new(0.99, 0.3));
    assert!(
        s.wi.dot(-wo) > 0.8,
        "a sample near u = 1 is close to forward: {:?}",
        s.wi
    );
}

/// Distances on [t_start, t_start + L) have density m·exp(−m (t − t_start)); a flight that
/// passes the segment (probability exp(−m L)) is placed uniformly in a unit bin after it.
fn free_flight_chi2(name: &str, majorant: f32, seed: u64) {
    let (t_start, length) = (0.5f32, 4.0f32);
    let lo = f64::from(t_start);
    let end = lo + f64::from(length);
    let m = f64::from(majorant);
    let outcome = chi2_interval(
        SAMPLES,
        lo,
        end + 1.0,
        100,
        seed,
        |rng| {
            let u = rng.next_f32();
            Some(
                match sample_free_flight(t_start, t_start + length, majorant, u) {
                    Some(t) => f64::from(t),
                    None => end + f64::from(rng.next_f32()),
                },
            )
        },
        |t| {
            if t < end {
                m * (-m * (t - lo)).exp()
            } else {
                (-m * f64::from(length)).exp()
            }
        },
    )
    .unwrap();
    SUITE.assert_passes(name, &outcome);
}

#[test]
fn free_flights_follow_the_exponential_density() {
    free_flight_chi2("free flight m = 0.8", 0.8, 5);
}

#[test]
fn dense_free_flights_follow_the_exponential_density() {
    free_flight_chi2("free flight m = 3", 3.0, 6);
}
