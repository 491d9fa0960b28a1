//! Chi-square tests of the media's sampling routines: the Henyey–Greenstein, Rayleigh,
//! tabulated and blended phase functions against their densities, and free-flight distances against m·exp(−m t) with the
//! probability exp(−m L) of passing the segment.

use glam::{Vec2, Vec3};
use prism_core::medium::sample_free_flight;
use prism_core::medium::{
    BlendPhase, HenyeyGreenstein, Isotropic, PhaseFunction, PhaseModel, Rayleigh, TabulatedPhase,
};
use prism_core::sampling::chi2::{Suite, chi2_interval, chi2_sphere};

/// The chi-square tests of this module, one name per statistic: the suite of Šidák's correction.
const SUITE: Suite = Suite::new(&[
    "hg g = 0.7",
    "hg g = -0.4",
    "isotropic",
    "blendphase",
    "rayleigh",
    "tabphase forward",
    "tabphase two bumps",
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
