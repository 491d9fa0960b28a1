//! pbrt-v4's layered BSDFs (`coateddiffuse`, `coatedconductor`) against their own claims.
//!
//! Their `eval` and `sample` are stochastic (random walks through the layer), so the shared
//! checks of `bsdfs` (sample weight = eval/pdf, sample pdf = pdf) do not hold, and pbrt's
//! density is an estimate for multiple importance sampling, not the density samples are drawn
//! with. What can be tested exactly, and is:
//!
//! * for a smooth coating over a white Lambertian base in a thin, non-scattering slab the
//!   density of sampled directions has a closed form (each bounce off the base draws a cosine
//!   direction, which leaves with probability T(w) = 1 − F(w)), so a chi-square test checks
//!   the walk's sampling: p(wi) = (1 − F(wo)) T(wi) cos θi / (π (1 − F̄)), F̄ = 2∫F(μ)μ dμ,
//!   the specular reflection (probability F(wo)) counting as the failures;
//! * `sample` and `eval` estimate the same BSDF: the weights of the samples falling in each
//!   cell of a coarse grid, averaged, equal ∫ eval over the cell (a z-test per cell, with the
//!   standard errors of both sides). This is how the one deliberate difference from pbrt-v4
//!   was found: pbrt weights next-event estimation through a rough coating with a density
//!   that is not the other strategy's, and its eval then falls up to 15 % off its samples;
//!   with pbrt's weights this test fails;
//! * the white furnace: the energy reflected is at most one, and one where nothing absorbs;
//! * a non-specular sample reports `eval`'s density at its direction, so that multiple
//!   importance sampling weights both strategies with one function.

use std::f64::consts::PI;

use glam::{Vec2, Vec3};
use prism_core::bsdf::Bsdf;
use prism_core::bsdf::fresnel::fresnel_dielectric;
use prism_core::sampling::chi2::{Suite, chi2_sphere};
use prism_core::sampling::rng::Pcg32;

use crate::common::bsdfs::{
    At, COS_BINS, PHI_BINS, SAMPLES, bsdf_from_xml, direction, point, wavelengths,
};

const SUITE: Suite = Suite::new(&[
    "coateddiffuse smooth, normal",
    "coateddiffuse smooth, oblique",
]);

fn u2(rng: &mut Pcg32) -> Vec2 {
    Vec2::new(rng.next_f32(), rng.next_f32())
}

/// 2∫₀¹ F(μ) μ dμ for light arriving from outside an interface of index `eta`, by the midpoint
/// rule.
fn hemispherical_fresnel(eta: f32) -> f64 {
    let n = 200_000;
    (0..n)
        .map(|i| {
            let mu = (i as f64 + 0.5) / n as f64;
            2.0 * f64::from(fresnel_dielectric(mu as f32, eta).reflectance) * mu / n as f64
        })
        .sum()
}

#[test]
fn a_smooth_coating_over_a_white_base_samples_its_closed_form_density() {
    let bsdf = bsdf_from_xml(
        r#"<bsdf type="coateddiffuse"><rgb name="reflectance" value="1"/>
        <float name="thickness" value="0.0001"/><integer name="max_depth" value="100"/></bsdf>"#,
    );
    let eta = 1.5f32;
    let f_bar = hemispherical_fresnel(eta);
    let (sp, lambda) = (point(), wavelengths());
    for (name, wo, seed) in [
        ("coateddiffuse smooth, normal", direction(0.0, 0.0), 1),
        ("coateddiffuse smooth, oblique", direction(70.0, 40.0), 2),
    ] {
        let entering = 1.0 - f64::from(fresnel_dielectric(wo.z, eta).reflectance);
        let outcome = chi2_sphere(
            SAMPLES,
            COS_BINS,
            PHI_BINS,
            seed,
            |rng| {
                let s = bsdf.at(&sp, wo, &lambda).sample(rng.next_f32(), u2(rng))?;
                (!s.flags.is_delta()).then_some(s.wi)
            },
            |wi| {
                if wi.z <= 0.0 {
                    return 0.0;
                }
                let leaving = 1.0 - f64::from(fresnel_dielectric(wi.z, eta).reflectance);
                entering * leaving * f64::from(wi.z) / (PI * (1.0 - f_bar))
            },
        )
        .unwrap_or_else(|e| panic!("{name}: {e}"));
        SUITE.assert_passes(name, &outcome);
    }
}

/// The layered BSDFs whose `sample` and `eval` are compared, each from one direction.
const CASES: &[(&str, &str, (f32, f32))] = &[
    (
        "rough coating over a black base",
        r#"<bsdf type="coateddiffuse"><rgb name="reflectance" value="0"/>
        <float name="alpha" value="0.4"/></bsdf>"#,
        (40.0, 30.0),
    ),
    (
        "rough coating over a coloured base",
        r#"<bsdf type="coateddiffuse"><rgb name="reflectance" value="0.8, 0.4, 0.1"/>
        <float name="alpha" value="0.4"/><integer name="max_depth" value="100"/></bsdf>"#,
        (40.0, 30.0),
    ),
    (
        "smooth coating over a scattering slab",
        r#"<bsdf type="coateddiffuse"><rgb name="reflectance" value="0.5"/>
        <float name="thickness" value="0.3"/><rgb name="albedo" value="0.9, 0.6, 0.3"/>
        <float name="g" value="0.4"/></bsdf>"#,
        (60.0, 200.0),
    ),
    (
        "rough coating over a rough conductor in a scattering slab",
        r#"<bsdf type="coatedconductor"><string name="material" value="Au"/>
        <float name="conductor_alpha" value="0.3"/><float name="interface_alpha" value="0.5"/>
        <float name="thickness" value="0.2"/><rgb name="albedo" value="0.7"/>
        <float name="g" value="-0.3"/></bsdf>"#,
        (25.0, 100.0),
    ),
    (
        "smooth coating over a rough conductor",
        r#"<bsdf type="coatedconductor"><string name="material" value="Cu"/>
        <float name="conductor_alpha" value="0.4"/></bsdf>"#,
        (50.0, 300.0),
    ),
];

/// Cells of the grid over the upper hemisphere on which sample and eval are compared.
const COARSE_COS: usize = 6;
const COARSE_PHI: usize = 8;

#[test]
fn sample_and_eval_estimate_the_same_bsdf() {
    let (sp, lambda) = (point(), wavelengths());
    let cell_of = |w: Vec3| {
        let i = ((w.z * COARSE_COS as f32) as usize).min(COARSE_COS - 1);
        let phi = f64::from(w.y).atan2(f64::from(w.x)).rem_euclid(2.0 * PI);
        let j = ((phi / (2.0 * PI) * COARSE_PHI as f64) as usize).min(COARSE_PHI - 1);
        i * COARSE_PHI + j
    };
    let cells = COARSE_COS * COARSE_PHI;
    for (case, &(name, xml, (theta, phi))) in CASES.iter().enumerate() {
        let bsdf: Bsdf = bsdf_from_xml(xml);
        let wo = direction(theta, phi);
        // Sample side: the mean of weight · [wi in cell], per cell and wavelength.
        let n = 400_000;
        let mut sum = vec![[0.0f64; 4]; cells];
        let mut sum2 = vec![[0.0f64; 4]; cells];
        let mut rng = Pcg32::seeded(100 + case as u64);
        for _ in 0..n {
            let Some(s) = bsdf
                .at(&sp, wo, &lambda)
                .sample(rng.next_f32(), u2(&mut rng))
            else {
                continue;
            };
            if s.flags.is_delta() || s.wi.z <= 0.0 {
                continue;
            }
            let cell = cell_of(s.wi);
            for c in 0..4 {
                let w = f64::from(s.weight[c]);
                sum[cell][c] += w;
                sum2[cell][c] += w * w;
            }
        }
        // Eval side: the midpoint rule over each cell, its points' spread as the error.
        let (m_cos, m_phi) = (24, 24);
        for cell in 0..cells {
            let (i, j) = (cell / COARSE_PHI, cell % COARSE_PHI);
            let area = (1.0 / COARSE_COS as f64) * (2.0 * PI / COARSE_PHI as f64);
            let (mut e_sum, mut e_sum2) = ([0.0f64; 4], [0.0f64; 4]);
            for a in 0..m_cos {
                let z = (i as f64 + (a as f64 + 0.5) / m_cos as f64) / COARSE_COS as f64;
                let r = (1.0 - z * z).sqrt();
                for b in 0..m_phi {
                    let p =
                        (j as f64 + (b as f64 + 0.5) / m_phi as f64) * 2.0 * PI / COARSE_PHI as f64;
                    let wi = Vec3::new((r * p.cos()) as f32, (r * p.sin()) as f32, z as f32);
                    let value = bsdf.at(&sp, wo, &lambda).eval(wi).value;
                    for c in 0..4 {
                        let v = f64::from(value[c]) * area;
                        e_sum[c] += v;
                        e_sum2[c] += v * v;
                    }
                }
            }
            let m = (m_cos * m_phi) as f64;
            for c in 0..4 {
                let sampled = sum[cell][c] / n as f64;
                let sampled_se =
                    ((sum2[cell][c] / n as f64 - sampled * sampled).max(0.0) / n as f64).sqrt();
                let evaluated = e_sum[c] / m;
                let evaluated_se = ((e_sum2[c] / m - evaluated * evaluated).max(0.0) / m).sqrt();
                let se = (sampled_se.powi(2) + evaluated_se.powi(2)).sqrt();
                assert!(
                    (sampled - evaluated).abs() <= 5.0 * se + 0.02 * evaluated.abs() + 1e-5,
                    "{name}, cell {cell}, wavelength {c}: samples carry {sampled} ± {sampled_se}, \
                     eval integrates to {evaluated} ± {evaluated_se}"
                );
            }
        }
    }
}

/// The energy a layered BSDF reflects from `wo`: the mean sample weight, and its standard
/// error, per wavelength.
fn albedo(bsdf: &Bsdf, wo: Vec3, n: usize, seed: u64) -> ([f64; 4], [f64; 4]) {
    let (sp, lambda) = (point(), wavelengths());
    let mut rng = Pcg32::seeded(seed);
    let (mut sum, mut sum2) = ([0.0f64; 4], [0.0f64; 4]);
    for _ in 0..n {
        let Some(s) = bsdf
            .at(&sp, wo, &lambda)
            .sample(rng.next_f32(), u2(&mut rng))
        else {
            continue;
        };
        for c in 0..4 {
            let w = f64::from(s.weight[c]);
            sum[c] += w;
            sum2[c] += w * w;
        }
    }
    let mean = sum.map(|s| s / n as f64);
    let se = std::array::from_fn(|c| {
        ((sum2[c] / n as f64 - mean[c].powi(2)).max(0.0) / n as f64).sqrt()
    });
    (mean, se)
}

#[test]
fn the_white_furnace_reflects_everything_where_nothing_absorbs() {
    // A smooth coating loses nothing: a white base under a thin slab, or a white base under a
    // white scattering slab, reflects all the light (the walk's depth bound loses ~10⁻⁴).
    for (name, xml) in [
        (
            "white base",
            r#"<bsdf type="coateddiffuse"><rgb name="reflectance" value="1"/>
            <float name="thickness" value="0.0001"/><integer name="max_depth" value="100"/></bsdf>"#,
        ),
        (
            "white base and slab",
            r#"<bsdf type="coateddiffuse"><rgb name="reflectance" value="1"/>
            <float name="thickness" value="0.5"/><rgb name="albedo" value="1"/>
            <float name="g" value="0.5"/><integer name="max_depth" value="400"/></bsdf>"#,
        ),
    ] {
        let bsdf = bsdf_from_xml(xml);
        for (k, theta) in [0.0f32, 45.0, 80.0].into_iter().enumerate() {
            let (mean, se) = albedo(&bsdf, direction(theta, 10.0), 200_000, 7 + k as u64);
            for c in 0..4 {
                assert!(
                    (mean[c] - 1.0).abs() <= 4.0 * se[c] + 2e-3,
                    "{name} at {theta}°: albedo {} ± {}",
                    mean[c],
                    se[c]
                );
            }
        }
    }
    // A rough coating loses the light its microfacets shadow, and a conductor absorbs: at most
    // one.
    for (name, xml) in [
        (
            "rough coating",
            r#"<bsdf type="coateddiffuse"><rgb name="reflectance" value="1"/>
            <float name="alpha" value="0.5"/><integer name="max_depth" value="100"/></bsdf>"#,
        ),
        (
            "rough conductor",
            r#"<bsdf type="coatedconductor"><string name="material" value="Ag"/>
            <float name="conductor_alpha" value="0.2"/><float name="interface_alpha" value="0.2"/></bsdf>"#,
        ),
    ] {
        let bsdf = bsdf_from_xml(xml);
        for (k, theta) in [0.0f32, 60.0, 85.0].into_iter().enumerate() {
            let (mean, se) = albedo(&bsdf, direction(theta, 70.0), 200_000, 17 + k as u64);
            for c in 0..4 {
                assert!(
                    mean[c] <= 1.0 + 4.0 * se[c],
                    "{name} at {theta}°: albedo {} ± {} above 1",
                    mean[c],
                    se[c]
                );
            }
        }
    }
}

#[test]
fn a_sample_reports_the_density_eval_gives_its_direction() {
    let (sp, lambda) = (point(), wavelengths());
    for (case, &(name, xml, (theta, phi))) in CASES.iter().enumerate() {
        let bsdf = bsdf_from_xml(xml);
        // From below too: pbrt's coated materials are two-sided.
        for wo in [direction(theta, phi), -direction(theta, phi)] {
            let mut rng = Pcg32::seeded(200 + case as u64);
            let mut smooth = 0;
            for _ in 0..2000 {
                let query = bsdf.at(&sp, wo, &lambda);
                let Some(s) = query.sample(rng.next_f32(), u2(&mut rng)) else {
                    continue;
                };
                assert!(
                    s.wi.z * wo.z > 0.0,
                    "{name}: {s:?} leaves on the other side"
                );
                assert!(s.weight.is_finite() && s.pdf > 0.0, "{name}: {s:?}");
                if s.flags.is_delta() {
                    continue;
                }
                smooth += 1;
                let eval = query.eval(s.wi);
                assert_eq!(
                    eval.pdf, s.pdf,
                    "{name}: sample pdf against eval's at {}",
                    s.wi
                );
                assert_eq!(eval, query.eval(s.wi), "{name}: eval is not a function");
            }
            assert!(smooth >= 50, "{name}: only {smooth} smooth samples");
        }
    }
}
