//! Chi-square tests (docs/testing.md) of every sampling routine of the core: each draws 10^6
//! samples and compares their histogram with the density the routine claims.

use std::f64::consts::PI;

use glam::{Mat3, Vec2, Vec3};
use prism_core::geometry::TriangleMesh;
use prism_core::geometry::{ShapeGeometry, ShapeSampling, Sphere};
use prism_core::light::{LightBounds, LightSampler, LightSelection, Receiver};
use prism_core::sampling::chi2::{
    Cells, Suite, chi2_discrete, chi2_interval, chi2_rectangle, chi2_sphere,
};
use prism_core::sampling::distribution::PiecewiseLinear1D;
use prism_core::sampling::rng::Pcg32;
use prism_core::sampling::warp;
use prism_core::spectrum::WavelengthSampling;

/// The chi-square tests of this module, one name per statistic: the suite of Šidák's correction.
const SUITE: Suite = Suite::new(&[
    "cosine hemisphere",
    "uniform sphere",
    "concentric disk",
    "wavelengths p ~ x+y+z",
    "wavelengths balanced",
    "wavelengths uniform",
    "wavelengths cosh^-2",
    "light selection",
    "light selection Uniform with weights",
    "light selection Power with weights",
    "light selection Exhaustive with weights",
    "triangle mesh area",
    "triangle mesh position, triangle number reused",
    "sphere cone",
    "sphere from inside",
    "piecewise linear",
]);
const SAMPLES: usize = 1_000_000;

fn u2(rng: &mut Pcg32) -> Vec2 {
    Vec2::new(rng.next_f32(), rng.next_f32())
}

#[test]
fn cosine_hemisphere_sampling_follows_cos_theta_over_pi() {
    let outcome = chi2_sphere(
        SAMPLES,
        101,
        202,
        1,
        |rng| Some(warp::sample_cosine_hemisphere(u2(rng))),
        |w| f64::from(w.z.max(0.0)) / PI,
    )
    .unwrap();
    SUITE.assert_passes("cosine hemisphere", &outcome);
}

#[test]
fn uniform_sphere_sampling_is_uniform() {
    let outcome = chi2_sphere(
        SAMPLES,
        101,
        202,
        2,
        |rng| Some(warp::sample_uniform_sphere(u2(rng))),
        |_| 1.0 / (4.0 * PI),
    )
    .unwrap();
    SUITE.assert_passes("uniform sphere", &outcome);
}

/// A uniform point on the disk has (r², φ) uniform on [0, 1) × [0, 2π); testing in those
/// coordinates keeps the disk's edge, where the density jumps, off the cells' interiors. The
/// claimed density is the warp's own per unit area, halved by the change of variables
/// (dA = r dr dφ = ½ d(r²) dφ).
#[test]
fn concentric_disk_sampling_is_uniform() {
    let outcome = chi2_rectangle(
        SAMPLES,
        Cells {
            x: (0.0, 1.0),
            y: (0.0, 2.0 * PI),
            nx: 40,
            ny: 40,
        },
        3,
        |rng| {
            let p = warp::sample_uniform_disk_concentric(u2(rng)).as_dvec2();
            let phi = p.y.atan2(p.x).rem_euclid(2.0 * PI);
            Some((p.length_squared().min(1.0 - 1e-12), phi))
        },
        |r2, phi| {
            let r = r2.sqrt();
            let p = glam::DVec2::new(r * phi.cos(), r * phi.sin()).as_vec2();
            0.5 * f64::from(warp::uniform_disk_pdf(p))
        },
    )
    .unwrap();
    SUITE.assert_passes("concentric disk", &outcome);
}

#[test]
fn piecewise_linear_sampling_follows_its_density() {
    // Rising, flat, zero over two intervals, and a spike at the end.
    let values = [0.5, 2.0, 2.0, 0.0, 0.0, 0.7, 5.0];
    let distribution = PiecewiseLinear1D::new(&values, 0.5, 3.5).unwrap();
    // A sample may be the domain's end, 3.5, which the half-open histogram leaves out: it is
    // counted in the last bin.
    let outcome = chi2_interval(
        SAMPLES,
        0.5,
        3.5,
        120,
        17,
        |rng| Some(f64::from(distribution.sample(rng.next_f32())).min(3.5 - 1e-9)),
        |x| f64::from(distribution.pdf(x as f32)),
    )
    .unwrap();
    SUITE.assert_passes("piecewise linear", &outcome);
    // The density interpolates the values linearly and integrates to one: ∫ = Σ trapezoids.
    let integral: f32 = values.windows(2).map(|w| 0.5 * (w[0] + w[1]) * 0.5).sum();
    assert!((distribution.pdf(0.75) - 1.25 / integral).abs() < 1e-5);
    assert_eq!(distribution.pdf(2.25), 0.0);
    assert_eq!(distribution.pdf(3.6), 0.0);
    assert!(PiecewiseLinear1D::new(&[1.0], 0.0, 1.0).is_none());
    assert!(PiecewiseLinear1D::new(&[0.0, 0.0], 0.0, 1.0).is_none());
    assert!(PiecewiseLinear1D::new(&[1.0, -1.0, 2.0], 0.0, 1.0).is_none());
    assert!(PiecewiseLinear1D::new(&[1.0, f32::NAN], 0.0, 1.0).is_none());
}

#[test]
fn wavelength_sampling_follows_the_sum_of_the_colour_matching_functions() {
    let sampling = WavelengthSampling::CieSum;
    let outcome = chi2_interval(
        SAMPLES,
        360.0,
        830.0,
        235,
        4,
        |rng| Some(f64::from(sampling.sample(rng.next_f32()))),
        |l| f64::from(sampling.pdf(l as f32)),
    )
    .unwrap();
    SUITE.assert_passes("wavelengths p ~ x+y+z", &outcome);
    // The tabulated density is x̄+ȳ+z̄ normalised: compare a few points with the CIE tables.
    let sum = |l: f32| prism_core::spectrum::cie::cie_xyz(l).iter().sum::<f32>();
    let normalisation = sampling.pdf(555.5) / (0.5 * (sum(555.0) + sum(556.0)));
    for l in [400.5f32, 450.5, 600.5, 700.5] {
        let expected = 0.5 * (sum(l - 0.5) + sum(l + 0.5)) * normalisation;
        assert!((sampling.pdf(l) - expected).abs() <= 1e-5 * expected, "{l}");
    }
}

#[test]
fn balanced_wavelength_sampling_follows_its_density() {
    let sampling = WavelengthSampling::Balanced;
    let outcome = chi2_interval(
        SAMPLES,
        360.0,
        830.0,
        235,
        6,
        |rng| Some(f64::from(sampling.sample(rng.next_f32()))),
        |l| f64::from(sampling.pdf(l as f32)),
    )
    .unwrap();
    SUITE.assert_passes("wavelengths balanced", &outcome);
    // The tabulated density is D65 · sqrt(3 ȳ²/I_Y² + Σ_c c̄²/I_c²) normalised, the c̄ linear
    // sRGB: compare ratios between cells with the formula (the I_c cancel only in part, so
    // compute them here too).
    use prism_core::spectrum::cie::{XYZ_TO_LINEAR_SRGB, cie_xyz, d65_normalized, mul3};
    let responses = |l: f32| {
        let xyz = cie_xyz(l);
        let rgb = mul3(&XYZ_TO_LINEAR_SRGB, xyz);
        [xyz[1], rgb[0], rgb[1], rgb[2]].map(f64::from)
    };
    let mut means = [0.0f64; 4];
    for i in 0..=4700 {
        let l = 360.0 + i as f32 * 0.1;
        let w = if i == 0 || i == 4700 { 0.05 } else { 0.1 };
        for (m, r) in means.iter_mut().zip(responses(l)) {
            *m += w * f64::from(d65_normalized(l)) * r;
        }
    }
    let shape = |l: f32| {
        let r = responses(l);
        let sum = 3.0 * (r[0] / means[0]).powi(2)
            + (1..4).map(|c| (r[c] / means[c]).powi(2)).sum::<f64>();
        f64::from(d65_normalized(l)) * sum.sqrt()
    };
    let cell = |l: f32| 0.5 * (shape(l - 0.5) + shape(l + 0.5));
    let normalisation = f64::from(sampling.pdf(555.5)) / cell(555.5);
    for l in [400.5f32, 450.5, 600.5, 700.5] {
        let expected = cell(l) * normalisation;
        let got = f64::from(sampling.pdf(l));
        assert!(
            (got - expected).abs() <= 1e-3 * expected,
            "{l}: {got} vs {expected}"
        );
    }
}

#[test]
fn uniform_wavelength_sampling_follows_its_density() {
    let sampling = WavelengthSampling::Uniform;
    let outcome = chi2_interval(
        SAMPLES,
        360.0,
        830.0,
        235,
        7,
        |rng| Some(f64::from(sampling.sample(rng.next_f32()))),
        |l| f64::from(sampling.pdf(l as f32)),
    )
    .unwrap();
    SUITE.assert_passes("wavelengths uniform", &outcome);
}

#[test]
fn visible_wavelength_sampling_follows_its_density() {
    let sampling = WavelengthSampling::Visible;
    let outcome = chi2_interval(
        SAMPLES,
        360.0,
        830.0,
        235,
        5,
        |rng| Some(f64::from(sampling.sample(rng.next_f32()))),
        |l| f64::from(sampling.pdf(l as f32)),
    )
    .unwrap();
    SUITE.assert_passes("wavelengths cosh^-2", &outcome);
}

#[test]
fn light_selection_is_proportional_to_power() {
    let powers = [1.0f32, 5.0, 0.5, 3.0, 0.0, 12.0];
    let sampler = LightSampler::new(&powers);
    let total: f32 = powers.iter().sum();
    let probabilities: Vec<f64> = powers.iter().map(|&p| f64::from(p / total)).collect();
    let anywhere = Receiver::point(Vec3::ZERO);
    let outcome = chi2_discrete(SAMPLES, &probabilities, 6, |rng| {
        let (index, pmf) = sampler.sample(rng.next_f32(), &anywhere).unwrap();
        assert_eq!(
            pmf,
            sampler.pmf(index, &anywhere),
            "the pmf returned with a sample is the reported pmf"
        );
        index
    })
    .unwrap();
    SUITE.assert_passes("light selection", &outcome);
}

/// Mitsuba's `sampling_weight`s: uniform selection picks light i with P(i) = wᵢ/Σw, selection by
/// power with P(i) = Φᵢwᵢ/ΣΦw, by importance (point lights on the x axis, seen from a point in
/// a medium) with P(i) = (Φᵢwᵢ/dᵢ²)/Σ(Φw/d²); a light of weight 0 is never picked.
#[test]
fn light_selection_follows_the_sampling_weights() {
    let powers = [1.0f32, 5.0, 0.5, 3.0, 2.0, 12.0];
    let weights = [2.0f32, 0.25, 1.0, 0.0, 3.0, 1.0];
    let receiver = Receiver::point(Vec3::new(-1.0, 0.5, 0.0));
    let places: Vec<Vec3> = (0..powers.len())
        .map(|i| Vec3::new(i as f32, 0.0, 0.0))
        .collect();
    let bounds: Vec<_> = places
        .iter()
        .map(|&c| Some(LightBounds::at_point(c, 0.0)))
        .collect();
    for selection in [
        LightSelection::Uniform,
        LightSelection::Power,
        LightSelection::Exhaustive,
    ] {
        let sampler = LightSampler::with_selection(&powers, &weights, &bounds, selection);
        let shares: Vec<f64> = powers
            .iter()
            .zip(&weights)
            .zip(&places)
            .map(|((&p, &w), &c)| match selection {
                LightSelection::Uniform => f64::from(w),
                LightSelection::Power => f64::from(p * w),
                LightSelection::Exhaustive => {
                    f64::from(p * w) / (c - receiver.p).as_dvec3().length_squared()
                }
            })
            .collect();
        let total: f64 = shares.iter().sum();
        let probabilities: Vec<f64> = shares.iter().map(|s| s / total).collect();
        let outcome = chi2_discrete(SAMPLES, &probabilities, 8, |rng| {
            let (index, pmf) = sampler.sample(rng.next_f32(), &receiver).unwrap();
            assert_ne!(index, 3, "a light of weight 0 is never chosen");
            assert_eq!(pmf, sampler.pmf(index, &receiver));
            assert!((f64::from(pmf) - probabilities[index]).abs() < 1e-6);
            index
        })
        .unwrap();
        SUITE.assert_passes(
            &format!("light selection {selection:?} with weights"),
            &outcome,
        );
    }
}

/// A unit square split into four triangles of unequal area around an off-centre point.
fn uneven_square_mesh() -> TriangleMesh {
    let c = Vec3::new(0.2, 0.7, 0.0);
    TriangleMesh::new(
        vec![Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::Y, c],
        None,
        None,
        vec![[0, 1, 4], [1, 2, 4], [2, 3, 4], [3, 0, 4]],
        false,
    )
}

#[test]
fn triangle_mesh_area_sampling_is_uniform() {
    let mesh = uneven_square_mesh();
    let outcome = chi2_rectangle(
        SAMPLES,
        Cells {
            x: (0.0, 1.0),
            y: (0.0, 1.0),
            nx: 40,
            ny: 40,
        },
        7,
        |rng| {
            let s = mesh.sample_area(rng.next_f32(), u2(rng))?;
            assert!((s.pdf - 1.0).abs() < 1e-5);
            Some((f64::from(s.p.x), f64::from(s.p.y)))
        },
        |_, _| 1.0,
    )
    .unwrap();
    SUITE.assert_passes("triangle mesh area", &outcome);
}

/// Mitsuba's `sample_position` picks the triangle with the second number and reuses it for the
/// point within: the points are still uniform over the square, triangle by triangle (an
/// uneven square of four triangles, on a grid that cuts across their edges).
#[test]
fn triangle_mesh_position_sampling_with_a_reused_number_is_uniform() {
    let mesh = uneven_square_mesh();
    let outcome = chi2_rectangle(
        SAMPLES,
        Cells {
            x: (0.0, 1.0),
            y: (0.0, 1.0),
            nx: 40,
            ny: 40,
        },
        9,
        |rng| {
            let s = mesh.sample_position(u2(rng))?;
            assert!((s.pdf - 1.0).abs() < 1e-5);
            Some((f64::from(s.p.x), f64::from(s.p.y)))
        },
        |_, _| 1.0,
    )
    .unwrap();
    SUITE.assert_passes("triangle mesh position, triangle number reused", &outcome);
}

fn sphere() -> Sphere {
    Sphere {
        center: Vec3::new(0.0, 0.0, 3.0),
        radius: 1.0,
        rotation: Mat3::IDENTITY,
        flip_normals: false,
    }
}

/// Directions uniform in the cone about the axis towards the centre have (cos θ, φ) uniform on
/// [cos θmax, 1] × [0, 2π) in the cone's frame; those are the test's coordinates, so the cone's
/// edge, where the solid-angle density jumps to zero, is the domain's edge. The claimed density
/// is the cone warp's (dω = d(cos θ) dφ).
#[test]
fn sphere_cone_sampling_is_uniform_over_the_visible_cone() {
    let s = sphere();
    let reference = Vec3::ZERO;
    let cos_max = (1.0 - 1.0 / 9.0f64).sqrt();
    let frame = prism_core::math::Frame::from_normal(Vec3::Z);
    let outcome = chi2_rectangle(
        SAMPLES,
        Cells {
            x: (cos_max, 1.0),
            y: (0.0, 2.0 * PI),
            nx: 30,
            ny: 60,
        },
        8,
        |rng| {
            let sample = s.sample_from(reference, 0.5, u2(rng), ShapeSampling::SolidAngle)?;
            let claimed = s.pdf_from(reference, sample.p, sample.n, ShapeSampling::SolidAngle);
            assert!((claimed - sample.pdf).abs() <= 1e-4 * claimed);
            let w = frame
                .to_local((sample.p - reference).normalize())
                .as_dvec3();
            let phi = w.y.atan2(w.x).rem_euclid(2.0 * PI);
            Some((w.z.clamp(cos_max, 1.0 - 1e-12), phi))
        },
        |cos_theta, phi| {
            let sin_theta = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
            let w = glam::DVec3::new(sin_theta * phi.cos(), sin_theta * phi.sin(), cos_theta);
            f64::from(warp::uniform_cone_pdf(w.as_vec3(), cos_max as f32))
        },
    )
    .unwrap();
    SUITE.assert_passes("sphere cone", &outcome);
}

#[test]
fn sphere_sampling_from_inside_converts_area_to_solid_angle() {
    let s = sphere();
    let reference = Vec3::new(0.3, -0.2, 3.4);
    // From inside, every direction hits the sphere once: p_ω = d² / (|cos| A).
    let outcome = chi2_sphere(
        SAMPLES,
        101,
        202,
        9,
        |rng| {
            let sample = s.sample_from(reference, 0.5, u2(rng), ShapeSampling::SolidAngle)?;
            Some((sample.p - reference).normalize())
        },
        |w| {
            let w = w.as_dvec3();
            let o = reference.as_dvec3() - s.center.as_dvec3();
            // Distance to the sphere along w from inside: t = -o·w + sqrt((o·w)² - |o|² + r²).
            let b = o.dot(w);
            let t = -b + (b * b - o.length_squared() + 1.0).sqrt();
            let p = o + w * t;
            let cos = p.normalize().dot(w).abs();
            t * t / (cos * 4.0 * PI)
        },
    )
    .unwrap();
    SUITE.assert_passes("sphere from inside", &outcome);
}
