//! Materials against what a chi-square test cannot see: identities of the models (Lambert
//! integrates to ρ, microfacet distributions are normalised and pass the weak white furnace,
//! Fresnel at normal incidence), the delta lobes of mirrors and glass, furnaces (a glass sphere
//! and a mirror sphere in a uniform environment render the environment's radiance), textures,
//! and the errors bad input gets. Tolerances come from quadrature error or standard errors.

use std::f64::consts::PI;
use std::path::{Path, PathBuf};

use glam::{Vec2, Vec3};
use prism_core::bsdf::fresnel::fresnel_conductor;
use prism_core::bsdf::microfacet::{Microfacet, MicrofacetKind};
use prism_core::bsdf::{Bsdf, BsdfFlags, BsdfModel};
use prism_core::sampling::chi2::{assert_passes, chi2_discrete};
use prism_core::sampling::rng::Pcg32;
use prism_core::spectrum::SampledWavelengths;
use prism_core::spectrum::conductors::CONDUCTORS;
use prism_core::texture::TextureValues;

use crate::common::bsdfs::{
    At, bsdf_from_xml, direction, integrate_eval, point, try_bsdf_from_xml, wavelengths,
};
use crate::common::scenes::{image_mean_and_standard_error, render_film};

fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("prism-materials-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

#[test]
fn lambert_integrates_to_rho() {
    let bsdf = bsdf_from_xml(
        r#"<bsdf type="diffuse"><rgb name="reflectance" value="0.8, 0.4, 0.1"/></bsdf>"#,
    );
    let Bsdf::Diffuse(diffuse) = &bsdf else {
        panic!("expected diffuse")
    };
    let rho = diffuse.reflectance.eval(point().uv, &wavelengths());
    for wo in [direction(0.0, 0.0), direction(70.0, 30.0)] {
        let integral = integrate_eval(&bsdf, wo, 800, 64);
        for c in 0..4 {
            assert!(
                (integral[c] - f64::from(rho[c])).abs() < 1e-4,
                "∫f cos = {} but ρ = {}",
                integral[c],
                rho[c]
            );
        }
    }
}

/// ∫ g(m) dm over the upper hemisphere by the midpoint rule in (θ, φ), fine enough for
/// α ≥ 0.1 (hundreds of nodes across the narrowest peak): errors below 3·10⁻⁶ here, so the
/// tolerance 2·10⁻⁵ catches a 1 % error in Λ (and Mitsuba's 0.35 % rational fit of Beckmann's).
fn integrate_hemisphere(g: impl Fn(Vec3) -> f64) -> f64 {
    let (n_theta, n_phi) = (3000, 192);
    let (dt, dp) = (0.5 * PI / n_theta as f64, 2.0 * PI / n_phi as f64);
    let mut sum = 0.0;
    for i in 0..n_theta {
        let theta = (i as f64 + 0.5) * dt;
        let (s, c) = theta.sin_cos();
        for j in 0..n_phi {
            let phi = (j as f64 + 0.5) * dp;
            let m = Vec3::new((s * phi.cos()) as f32, (s * phi.sin()) as f32, c as f32);
            sum += g(m) * s;
        }
    }
    sum * dt * dp
}

/// Heitz 2014, §3: ∫ D(m) cos θm dm = 1 (the microsurface projects onto unit area), and the weak
/// white furnace ∫ G₁(wo, m) max(0, wo·m) D(m) dm = cos θo (the visible projected area is the
/// macrosurface's), which holds only with the masking function that belongs to D.
#[test]
fn microfacet_distributions_are_normalised_and_pass_the_weak_white_furnace() {
    for kind in [MicrofacetKind::Ggx, MicrofacetKind::Beckmann] {
        for (au, av) in [(0.1, 0.1), (0.5, 0.5), (0.15, 0.6)] {
            let d = Microfacet::new(kind, au, av);
            let projected = integrate_hemisphere(|m| f64::from(d.d(m) * m.z));
            assert!(
                (projected - 1.0).abs() < 2e-5,
                "{kind:?} α = ({au}, {av}): ∫D cos = {projected}"
            );
            for wo in [
                direction(0.0, 0.0),
                direction(40.0, 30.0),
                direction(75.0, 100.0),
            ] {
                let visible =
                    integrate_hemisphere(|m| f64::from(d.g1(wo, m) * wo.dot(m).max(0.0) * d.d(m)))
                        / f64::from(wo.z);
                assert!(
                    (visible - 1.0).abs() < 2e-5,
                    "{kind:?} α = ({au}, {av}), wo = {wo}: weak white furnace gives {visible}"
                );
            }
        }
    }
}

/// The probability with which a delta-only BSDF reflects at wo (from its samples' pdfs).
fn reflection_probability(bsdf: &Bsdf, wo: Vec3) -> f32 {
    let s = bsdf
        .at(&point(), wo, &wavelengths())
        .sample(0.0, Vec2::splat(0.5))
        .unwrap();
    assert!(s.flags.contains(BsdfFlags::REFLECTION));
    s.pdf
}

#[test]
fn fresnel_at_normal_incidence() {
    for (tag, ior, eta) in [
        ("float", "1.5", 1.5f32),
        ("string", "water", 1.333),
        ("string", "diamond", 2.419),
    ] {
        let xml = format!(
            r#"<bsdf type="dielectric"><{tag} name="int_ior" value="{ior}"/><float name="ext_ior" value="1"/></bsdf>"#
        );
        let r = reflection_probability(&bsdf_from_xml(&xml), Vec3::Z);
        let expected = ((eta - 1.0) / (eta + 1.0)).powi(2);
        assert!((r - expected).abs() < 1e-6, "η = {eta}: {r} vs {expected}");
    }
    // Gold at normal incidence: ((n − 1)² + k²) / ((n + 1)² + k²) with the tabulated n, k.
    let gold =
        bsdf_from_xml(r#"<bsdf type="conductor"><string name="material" value="Au"/></bsdf>"#);
    let table = CONDUCTORS.iter().find(|c| c.name == "Au").unwrap().samples;
    for lambda in [420.0f32, 550.0, 680.0] {
        let w = SampledWavelengths::single(lambda);
        let s = gold
            .at(&point(), Vec3::Z, &w)
            .sample(0.5, Vec2::splat(0.5))
            .unwrap();
        let i = table.partition_point(|s| s.0 <= lambda) - 1;
        let t = (lambda - table[i].0) / (table[i + 1].0 - table[i].0);
        let n = table[i].1 + t * (table[i + 1].1 - table[i].1);
        let k = table[i].2 + t * (table[i + 1].2 - table[i].2);
        let expected = ((n - 1.0).powi(2) + k * k) / ((n + 1.0).powi(2) + k * k);
        assert!(
            (s.weight[0] - expected).abs() < 1e-5,
            "gold at {lambda} nm: {} vs {expected}",
            s.weight[0]
        );
        assert_eq!(fresnel_conductor(1.0, n, k), s.weight[0]);
    }
}

/// The smooth dielectric chooses reflection with probability F (a chi-square test of the
/// choice), reflects to the mirror direction, refracts by Snell's law, and conserves energy.
#[test]
fn smooth_dielectric_lobes() {
    let bsdf = bsdf_from_xml(
        r#"<bsdf type="dielectric"><float name="int_ior" value="1.5"/><float name="ext_ior" value="1"/></bsdf>"#,
    );
    let lambda = wavelengths();
    let directions = [
        direction(60.0, 30.0),
        -direction(30.0, 200.0),
        -direction(50.0, 10.0),
    ];
    let reflectance =
        |wo: Vec3| prism_core::bsdf::fresnel::fresnel_dielectric(wo.z, 1.5).reflectance;
    // Beyond the critical angle from inside everything reflects: no test of a choice.
    let chi2_tests = directions
        .iter()
        .filter(|&&wo| reflectance(wo) < 1.0)
        .count();
    for (k, wo) in directions.into_iter().enumerate() {
        let f = reflectance(wo);
        let outcome = chi2_discrete(
            100_000,
            &[f64::from(f), f64::from(1.0 - f)],
            k as u64,
            |rng| {
                let s = bsdf
                    .at(&point(), wo, &lambda)
                    .sample(rng.next_f32(), Vec2::ZERO)
                    .unwrap();
                usize::from(s.flags.contains(BsdfFlags::TRANSMISSION))
            },
        );
        if f < 1.0 {
            assert_passes("dielectric lobe choice", &outcome.unwrap(), chi2_tests);
        }
        let mut rng = Pcg32::seeded(10 + k as u64);
        for _ in 0..1000 {
            let s = bsdf
                .at(&point(), wo, &lambda)
                .sample(rng.next_f32(), Vec2::ZERO)
                .unwrap();
            // Energy: weight · η² (the radiance compression undone) is 1 for either lobe.
            assert!((s.weight[0] * s.eta * s.eta - 1.0).abs() < 1e-5, "{s:?}");
            if s.flags.contains(BsdfFlags::REFLECTION) {
                assert!((s.wi - Vec3::new(-wo.x, -wo.y, wo.z)).length() < 1e-6);
            } else {
                let (eta_i, eta_t) = if wo.z > 0.0 { (1.0, 1.5) } else { (1.5, 1.0) };
                let sin_o = (1.0 - wo.z * wo.z).sqrt();
                let sin_i = (1.0 - s.wi.z * s.wi.z).sqrt();
                assert!((eta_i * sin_o - eta_t * sin_i).abs() < 1e-5, "Snell");
                assert!(s.wi.z * wo.z < 0.0 && (s.wi.x * wo.x) <= 0.0);
            }
        }
    }
}

#[test]
fn thin_dielectric_and_conductor_lobes() {
    let thin = bsdf_from_xml(
        r#"<bsdf type="thindielectric"><float name="int_ior" value="1.5"/><float name="ext_ior" value="1"/></bsdf>"#,
    );
    let wo = direction(45.0, 60.0);
    let r = prism_core::bsdf::fresnel::fresnel_dielectric(wo.z, 1.5).reflectance;
    let r2 = 2.0 * r / (1.0 + r);
    let reflected = thin
        .at(&point(), wo, &wavelengths())
        .sample(0.0, Vec2::ZERO)
        .unwrap();
    assert!((reflected.pdf - r2).abs() < 1e-6);
    let passed = thin
        .at(&point(), -wo, &wavelengths())
        .sample(0.999, Vec2::ZERO)
        .unwrap();
    assert!(passed.flags.contains(BsdfFlags::NULL) && passed.wi == wo);
    assert!((passed.weight[0] * passed.pdf - (1.0 - r2)).abs() < 1e-6);
    let mirror = bsdf_from_xml(r#"<bsdf type="conductor"/>"#);
    let s = mirror
        .at(&point(), wo, &wavelengths())
        .sample(0.3, Vec2::ZERO)
        .unwrap();
    assert_eq!(s.weight, prism_core::spectrum::SampledSpectrum::ONE);
    assert!((s.wi - Vec3::new(-wo.x, -wo.y, wo.z)).length() < 1e-6);
    assert!(
        mirror
            .at(&point(), -wo, &wavelengths())
            .sample(0.3, Vec2::ZERO)
            .is_none()
    );
}

/// A scene inside a sphere of inward normals, reflectance 0 and radiance 1 (a uniform
/// environment of radiance 1 for everything inside), with a unit sphere of the given BSDF in
/// front of the camera.
fn furnace_scene(bsdf: &str) -> String {
    format!(
        r#"<scene version="3.0.0">
    <integrator type="path"/>
    <sensor type="perspective">
        <float name="fov" value="35"/>
        <transform name="to_world"><lookat origin="0.3, 0.2, -4" target="0, 0, 0" up="0, 1, 0"/></transform>
        <film type="hdrfilm"><integer name="width" value="12"/><integer name="height" value="12"/><rfilter type="box"/></film>
    </sensor>
    <shape type="sphere">
        <float name="radius" value="20"/>
        <boolean name="flip_normals" value="true"/>
        <bsdf type="diffuse"><rgb name="reflectance" value="0"/></bsdf>
        <emitter type="area"><spectrum name="radiance" value="1"/></emitter>
    </shape>
    <shape type="sphere">
        <float name="radius" value="1"/>
        {bsdf}
    </shape>
</scene>"#
    )
}

/// Renders `xml` and returns the image's mean luminance and its standard error.
fn render_mean(xml: &str, spp: u32, seed: u64) -> (f64, f64) {
    let root = prism_mitsuba::reader::read_scene_str(xml, Path::new("furnace.xml"), &[]).unwrap();
    let loaded = prism_mitsuba::factory::build_scene(&root).unwrap();
    let film = render_film(&loaded.scene, spp, seed, None);
    image_mean_and_standard_error(&film, 1)
}

/// A lossless sphere in a uniform environment of radiance L looks like the environment: every
/// path ends in the environment with throughput 1 (for glass, the radiance scaling by 1/η²
/// entering and η² leaving cancels), so the image is L everywhere, at unbounded depth.
#[test]
fn glass_and_mirror_spheres_vanish_in_a_furnace() {
    for (name, bsdf, spp) in [
        ("mirror", r#"<bsdf type="conductor"/>"#, 64),
        ("glass", r#"<bsdf type="dielectric"/>"#, 64),
        (
            "diamond",
            r#"<bsdf type="dielectric"><string name="int_ior" value="diamond"/></bsdf>"#,
            64,
        ),
        // Refraction keeps only the hero wavelength, whose estimate of Y varies with it.
        (
            "dispersive flint glass",
            r#"<bsdf type="dielectric"><spectrum type="sellmeier" name="int_ior"><string name="glass" value="N-SF11"/></spectrum></bsdf>"#,
            1024,
        ),
        ("thin glass", r#"<bsdf type="thindielectric"/>"#, 64),
        ("null", r#"<bsdf type="null"/>"#, 64),
    ] {
        let (mean, se) = render_mean(&furnace_scene(bsdf), spp, 3);
        assert!(
            (mean - 1.0).abs() < 4.0 * se,
            "{name} sphere in a furnace: mean Y {mean} ± {se}, expected 1"
        );
        assert!(
            se < 2.5e-3,
            "{name}: standard error {se} too large to see a 1 % bias"
        );
    }
}

/// A 2 × 2 uncompressed 24-bit BMP of one grey code (rows of 6 bytes padded to 8).
fn grey_bmp(code: u8) -> Vec<u8> {
    let mut bytes = b"BM".to_vec();
    for v in [54u32 + 16, 0, 54, 40, 2, 2] {
        bytes.extend(v.to_le_bytes());
    }
    bytes.extend([1, 0, 24, 0]);
    bytes.extend([0u8; 24]);
    for _ in 0..2 {
        bytes.extend([code; 6]);
        bytes.extend([0, 0]);
    }
    bytes
}

/// A diffuse sphere textured with a BMP (Mitsuba's projector docs scene uses one) renders as
/// the same sphere with the texel's colour given as `<rgb>`: decoded from sRGB, or as stored
/// when `raw`. In the furnace a convex diffuse sphere shows ρ, so a texel read with the wrong
/// encoding (0.216 against 0.502) moves the mean by far more than its standard error.
#[test]
fn a_bmp_texture_renders_as_its_colour() {
    let dir = temp_dir("bmp");
    let bmp = dir.join("grey.bmp");
    std::fs::write(&bmp, grey_bmp(128)).unwrap();
    let code = 128.0 / 255.0_f64;
    let linear = ((code + 0.055) / 1.055).powf(2.4);
    for (raw, value) in [(false, linear), (true, code)] {
        let textured = furnace_scene(&format!(
            r#"<bsdf type="diffuse"><texture type="bitmap" name="reflectance">
                <string name="filename" value="{}"/><boolean name="raw" value="{raw}"/>
            </texture></bsdf>"#,
            bmp.display()
        ));
        let plain = furnace_scene(&format!(
            r#"<bsdf type="diffuse"><rgb name="reflectance" value="{value}"/></bsdf>"#
        ));
        let (mean, se) = render_mean(&textured, 16, 3);
        let (expected, expected_se) = render_mean(&plain, 16, 3);
        let tolerance = 4.0 * se.hypot(expected_se) + 1e-5;
        assert!(
            (mean - expected).abs() < tolerance,
            "raw = {raw}: BMP texture mean {mean} ± {se}, <rgb> {value}: {expected}"
        );
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// The `null` BSDF passes light unchanged from both sides, and nothing can be evaluated.
#[test]
fn null_lobe_passes_straight_through() {
    let bsdf = bsdf_from_xml(r#"<bsdf type="null"/>"#);
    assert_eq!(bsdf.flags(), BsdfFlags::NULL);
    for wo in [direction(30.0, 40.0), -direction(80.0, 200.0)] {
        let at = bsdf.at(&point(), wo, &wavelengths());
        let s = at.sample(0.7, Vec2::new(0.2, 0.9)).unwrap();
        assert_eq!(s.wi, -wo);
        assert_eq!(
            (s.weight.0, s.pdf, s.flags),
            ([1.0; 4], 1.0, BsdfFlags::NULL)
        );
        assert_eq!(at.eval(-wo).pdf, 0.0);
    }
}

/// What a shadow ray carries through a surface with null lobes (Mitsuba 3's
/// `eval_null_transmission`) is what BSDF sampling carries through it on average: the weights of
/// its null samples averaged over the lobe choice, stratified in `u_lobe` (the choice is a step
/// function of it, so the average is exact to 1/N). Zero for a BSDF without null lobes.
#[test]
fn null_transmission_is_the_mean_weight_of_null_samples() {
    let n = 20_000;
    for (name, xml) in [
        ("null", r#"<bsdf type="null"/>"#),
        ("thin glass", r#"<bsdf type="thindielectric"/>"#),
        (
            "thin dispersive glass, tinted",
            r#"<bsdf type="thindielectric"><spectrum type="sellmeier" name="int_ior"><string name="glass" value="N-SF11"/></spectrum><rgb name="specular_transmittance" value="0.9, 0.5, 0.2"/></bsdf>"#,
        ),
        (
            "mask of a two-sided diffuse",
            r#"<bsdf type="mask"><float name="opacity" value="0.3"/><bsdf type="twosided"><bsdf type="diffuse"/></bsdf></bsdf>"#,
        ),
        (
            "mask of thin glass",
            r#"<bsdf type="mask"><float name="opacity" value="0.6"/><bsdf type="thindielectric"/></bsdf>"#,
        ),
        (
            "blend of thin glass and diffuse",
            r#"<bsdf type="blendbsdf"><float name="weight" value="0.7"/><bsdf type="thindielectric"/><bsdf type="diffuse"/></bsdf>"#,
        ),
        (
            "normal-mapped thin glass",
            r#"<bsdf type="normalmap"><texture type="checkerboard" name="normalmap"><rgb name="color0" value="0.7, 0.5, 0.9"/><rgb name="color1" value="0.7, 0.5, 0.9"/></texture><bsdf type="thindielectric"/></bsdf>"#,
        ),
        ("diffuse", r#"<bsdf type="diffuse"/>"#),
    ] {
        let bsdf = bsdf_from_xml(xml);
        for wo in [
            direction(0.0, 0.0),
            direction(60.0, 30.0),
            -direction(80.0, 200.0),
        ] {
            let at = bsdf.at(&point(), wo, &wavelengths());
            let mut mean = [0.0f64; 4];
            for i in 0..n {
                let u_lobe = (i as f32 + 0.5) / n as f32;
                let Some(s) = at.sample(u_lobe, Vec2::new(0.3, 0.7)) else {
                    continue;
                };
                if s.flags.contains(BsdfFlags::NULL) {
                    assert!((s.wi + wo).length() < 1e-6, "{name}: a null sample turns");
                    for (m, w) in mean.iter_mut().zip(s.weight.0) {
                        *m += f64::from(w) / n as f64;
                    }
                }
            }
            let expected = at.null_transmission();
            for c in 0..4 {
                assert!(
                    (mean[c] - f64::from(expected[c])).abs() < 1e-3,
                    "{name} at wo {wo}: null samples carry {:?} on average, null transmission {:?}",
                    mean,
                    expected.0
                );
            }
        }
    }
}

/// Passing through a `null` surface counts as a bounce, as in Mitsuba 3's `path`: Mitsuba 3.9.1
/// renders a light behind a null rectangle black at `max_depth` 1 and at its radiance at 2.
/// Both integrators agree; shadow rays stop at the surface, so the light is found by BSDF
/// sampling alone, with weight 1.
#[test]
fn a_null_surface_counts_as_a_bounce() {
    for integrator in ["path", "distrib"] {
        for (max_depth, expected) in [(1, 0.0), (2, 1.0), (-1, 1.0)] {
            let xml = format!(
                r#"<scene version="3.0.0">
    <integrator type="{integrator}"><integer name="max_depth" value="{max_depth}"/></integrator>
    <sensor type="perspective">
        <float name="fov" value="10"/>
        <transform name="to_world"><lookat origin="0, 0, 0" target="0, 0, 1" up="0, 1, 0"/></transform>
        <film type="hdrfilm"><integer name="width" value="8"/><integer name="height" value="8"/><rfilter type="box"/></film>
    </sensor>
    <shape type="rectangle">
        <transform name="to_world"><translate z="2"/></transform>
        <bsdf type="null"/>
    </shape>
    <shape type="rectangle">
        <transform name="to_world"><scale value="0.5"/><rotate y="1" angle="180"/><translate z="5"/></transform>
        <emitter type="area"><spectrum name="radiance" value="1"/></emitter>
    </shape>
</scene>"#
            );
            let (mean, se) = render_mean(&xml, 64, 5);
            assert!(
                (mean - expected).abs() <= 4.0 * se,
                "{integrator}, max_depth {max_depth}: mean Y {mean} ± {se}, expected {expected}"
            );
        }
    }
}

/// A light seen through a fully transparent mask keeps its radiance: the null pass is a delta
/// lobe, so the emitter it leads to is not weighted against light sampling (which cannot reach
/// it: `path`'s shadow rays stop at masks).
#[test]
fn lights_seen_through_a_transparent_mask_keep_their_radiance() {
    let xml = r#"<scene version="3.0.0">
    <sensor type="perspective">
        <float name="fov" value="10"/>
        <transform name="to_world"><lookat origin="0, 0, 0" target="0, 0, 1" up="0, 1, 0"/></transform>
        <film type="hdrfilm"><integer name="width" value="8"/><integer name="height" value="8"/><rfilter type="box"/></film>
    </sensor>
    <shape type="rectangle">
        <transform name="to_world"><translate z="2"/></transform>
        <bsdf type="mask"><float name="opacity" value="0"/><bsdf type="diffuse"/></bsdf>
    </shape>
    <shape type="rectangle">
        <transform name="to_world"><scale value="0.5"/><rotate y="1" angle="180"/><translate z="5"/></transform>
        <emitter type="area"><spectrum name="radiance" value="1"/></emitter>
    </shape>
</scene>"#;
    let (mean, se) = render_mean(xml, 64, 5);
    assert!(
        (mean - 1.0).abs() < 4.0 * se,
        "light through a transparent mask: mean Y {mean} ± {se}, expected 1"
    );
}

#[test]
fn textures_vary_with_uv() {
    let bsdf = bsdf_from_xml(
        r#"<bsdf type="diffuse"><texture type="checkerboard" name="reflectance">
            <rgb name="color0" value="0.8"/><rgb name="color1" value="0.1"/>
            <transform name="to_uv"><scale x="2" y="2"/></transform></texture></bsdf>"#,
    );
    let Bsdf::Diffuse(d) = &bsdf else { panic!() };
    let lambda = wavelengths();
    assert_eq!(d.reflectance.eval(Vec2::new(0.1, 0.1), &lambda)[0], 0.8);
    assert_eq!(d.reflectance.eval(Vec2::new(0.3, 0.1), &lambda)[0], 0.1);
    // A texture declared at the top level and referenced by id, here as a roughness: read as a
    // number, the checkerboard has Mitsuba 3's opposite phase (color0 where the halves differ).
    let referenced = bsdf_from_xml(
        r#"<texture type="checkerboard" id="checks"><float name="color0" value="0.3"/></texture>
           <bsdf type="roughconductor"><ref name="alpha" id="checks"/></bsdf>"#,
    );
    let Bsdf::RoughConductor(rc) = &referenced else {
        panic!()
    };
    assert_eq!(rc.roughness.alpha_u.eval_1(Vec2::new(0.1, 0.1)), 0.2);
    assert_eq!(rc.roughness.alpha_v.eval_1(Vec2::new(0.7, 0.1)), 0.3);

    // A 2 × 1 PNG, left texel grey, right texel red: decoded to linear and upsampled.
    let dir = temp_dir("bitmap");
    let png = dir.join("t.png");
    prism_core::image::write_png_srgb(&png, 2, 1, &[0.5, 0.5, 0.5, 1.0, 0.0, 0.0]).unwrap();
    let xml = |raw: bool, filter: &str| {
        format!(
            r#"<bsdf type="diffuse"><texture type="bitmap" name="reflectance">
                <string name="filename" value="{}"/><boolean name="raw" value="{raw}"/>
                <string name="filter_type" value="{filter}"/><string name="wrap_mode" value="clamp"/>
            </texture></bsdf>"#,
            png.display()
        )
    };
    let texture = |raw, filter| match bsdf_from_xml(&xml(raw, filter)) {
        Bsdf::Diffuse(d) => d.reflectance,
        _ => panic!(),
    };
    // The PNG stores linear 0.5 as the sRGB code 188: decoded, 0.5 again (to 8-bit precision);
    // raw, 188/255.
    let decoded = texture(false, "nearest");
    let grey = decoded.eval(Vec2::new(0.25, 0.5), &lambda)[0];
    assert!((grey - 0.5).abs() < 4e-3, "{grey} vs 0.5");
    let raw = texture(true, "nearest").eval(Vec2::new(0.25, 0.5), &lambda)[0];
    assert!((raw - 188.0 / 255.0).abs() < 1e-6, "raw {raw}");
    let red = decoded.eval(Vec2::new(0.75, 0.5), &SampledWavelengths::single(650.0))[0];
    let blue = decoded.eval(Vec2::new(0.75, 0.5), &SampledWavelengths::single(450.0))[0];
    assert!(
        red > 0.8 && blue < 0.1,
        "red texel: {red} at 650 nm, {blue} at 450 nm"
    );
    // Bilinear filtering halfway between the texel centres averages their spectra.
    let mid =
        texture(false, "bilinear").eval(Vec2::new(0.5, 0.5), &SampledWavelengths::single(650.0))[0];
    let left = decoded.eval(Vec2::new(0.25, 0.5), &SampledWavelengths::single(650.0))[0];
    assert!((mid - 0.5 * (left + red)).abs() < 1e-5);
    std::fs::remove_dir_all(&dir).ok();
}

/// Errors for bad input: a message with the location of the offending element and a hint.
fn assert_bsdf_error(xml: &str, says: &[&str]) {
    let error = match try_bsdf_from_xml(xml) {
        Ok(bsdf) => panic!("expected an error for {xml}, got {bsdf:?}"),
        Err(e) => e,
    };
    let text = format!("{error}");
    assert!(text.contains("test.xml:1:"), "no location in: {text}");
    for phrase in says {
        assert!(text.contains(phrase), "expected \"{phrase}\" in: {text}");
    }
}

#[test]
fn bad_input_gets_clear_errors() {
    assert_bsdf_error(
        r#"<bsdf type="conductor"><string name="material" value="Unobtainium"/></bsdf>"#,
        &[
            "unknown conductor material \"Unobtainium\"",
            "Au",
            "Cu",
            "none",
        ],
    );
    assert_bsdf_error(
        r#"<bsdf type="dielectric"><string name="int_ior" value="glass"/></bsdf>"#,
        &[
            "unknown index of refraction \"glass\"",
            "bk7",
            "water",
            "diamond",
        ],
    );
    for alpha in ["0", "-0.1"] {
        assert_bsdf_error(
            &format!(r#"<bsdf type="roughconductor"><float name="alpha" value="{alpha}"/></bsdf>"#),
            &["alpha", "greater than 0"],
        );
    }
    assert_bsdf_error(
        r#"<bsdf type="roughdielectric"><float name="alpha_u" value="0.1"/></bsdf>"#,
        &["alpha_v"],
    );
    assert_bsdf_error(
        r#"<bsdf type="dielectric"><float name="int_ior" value="-1.5"/></bsdf>"#,
        &["positive"],
    );
    assert_bsdf_error(
        r#"<bsdf type="dielectric"><spectrum type="sellmeier" name="int_ior"><float name="b1" value="1"/><float name="c1" value="0.25"/></spectrum></bsdf>"#,
        &["positive and finite", "pole"],
    );
    assert_bsdf_error(
        r#"<bsdf type="mask"><float name="opacity" value="1.5"/><bsdf type="diffuse"/></bsdf>"#,
        &["opacity", "[0, 1]"],
    );
    assert_bsdf_error(
        r#"<bsdf type="diffuse"><texture type="bitmap" name="reflectance"><string name="filename" value="/nonexistent/wood.png"/></texture></bsdf>"#,
        &["not found", "wood.png"],
    );
    let dir = temp_dir("corrupt");
    let corrupt = dir.join("corrupt.png");
    std::fs::write(&corrupt, b"\x89PNG\r\n\x1a\nnot an image").unwrap();
    assert_bsdf_error(
        &format!(
            r#"<bsdf type="diffuse"><texture type="bitmap" name="reflectance"><string name="filename" value="{}"/></texture></bsdf>"#,
            corrupt.display()
        ),
        &["could not read the image", "corrupt.png"],
    );
    std::fs::remove_dir_all(&dir).ok();
    assert_bsdf_error(
        r#"<bsdf type="twosided"><bsdf type="dielectric"/></bsdf>"#,
        &["cannot be nested in \"twosided\""],
    );
    assert_bsdf_error(
        r#"<bsdf type="roughconductor"><string name="distribution" value="phong"/></bsdf>"#,
        &[
            "unknown value \"phong\" for parameter \"distribution\"",
            "beckmann, ggx",
        ],
    );
    assert_bsdf_error(
        r#"<bsdf type="blendbsdf"><bsdf type="diffuse"/><bsdf type="conductor"/></bsdf>"#,
        &["needs a \"weight\""],
    );
    assert_bsdf_error(
        r#"<bsdf type="ward"><string name="variant" value="ward-dur"/></bsdf>"#,
        &[
            "unknown value \"ward-dur\" for parameter \"variant\"",
            "ward-duer",
        ],
    );
    assert_bsdf_error(
        r#"<bsdf type="pplastic"><float name="int_ior" value="1"/><float name="ext_ior" value="1"/></bsdf>"#,
        &["same index of refraction"],
    );
    assert_bsdf_error(
        r#"<bsdf type="principled"><float name="eta" value="1.5"/><float name="specular" value="0.5"/></bsdf>"#,
        &["either \"eta\" or \"specular\"", "not both"],
    );
    assert_bsdf_error(
        r#"<bsdf type="principledthin"><float name="diff_trans" value="2.5"/></bsdf>"#,
        &["diff_trans", "[0, 2]"],
    );
    assert_bsdf_error(
        r#"<bsdf type="twosided"><bsdf type="principledthin"/></bsdf>"#,
        &["cannot be nested in \"twosided\""],
    );
}

/// An `<rgb>` where a number is wanted is read as Mitsuba 3's spectral variants read it: the
/// mean of its upsampled spectrum at 16 wavelengths over 360–830 nm. Mitsuba 3.9.1
/// (`scalar_spectral`) gives a mask of opacity (0.2, 0.4, 0.6) the opacity 0.333194. Prism's
/// coefficient table is its own fit of the same model (Prism gives 0.333186): the tolerance
/// 10⁻⁴ allows for the two fits, not for another way of reading the colour (the luminance
/// 0.372 or the RGB mean 0.4 would fail). Grey is exact.
#[test]
fn a_colour_read_as_a_number_is_its_mean() {
    let opacity = |rgb: &str| {
        let bsdf = bsdf_from_xml(&format!(
            r#"<bsdf type="mask"><rgb name="opacity" value="{rgb}"/><bsdf type="diffuse"/></bsdf>"#
        ));
        let Bsdf::Mask(mask) = &bsdf else { panic!() };
        mask.opacity.eval_1(Vec2::ZERO)
    };
    assert_eq!(opacity("0.5"), 0.5);
    let colour = opacity("0.2, 0.4, 0.6");
    assert!((colour - 0.333_194).abs() < 1e-4, "{colour}");
}

/// Mitsuba 0.6's `ext_eta` on conductors divides η and k by the exterior index: the same
/// reflectance as the relative index given directly.
#[test]
fn conductor_exterior_index_divides_eta_and_k() {
    let weight = |body: &str, wo: Vec3| {
        let bsdf = bsdf_from_xml(&format!(r#"<bsdf type="conductor">{body}</bsdf>"#));
        let s = bsdf
            .at(&point(), wo, &wavelengths())
            .sample(0.5, Vec2::new(0.3, 0.6));
        s.unwrap().weight
    };
    for wo in [
        direction(0.0, 0.0),
        direction(60.0, 10.0),
        direction(85.0, 0.0),
    ] {
        let outside = weight(
            r#"<float name="eta" value="2"/><float name="k" value="3"/><float name="ext_eta" value="1.5"/>"#,
            wo,
        );
        let relative = weight(
            r#"<float name="eta" value="1.3333334"/><float name="k" value="2"/>"#,
            wo,
        );
        for c in 0..4 {
            assert!(
                (outside[c] - relative[c]).abs() < 1e-6,
                "{outside:?} {relative:?}"
            );
        }
    }
    // A name, as Mitsuba 0.6's lookupIOR reads it.
    let water = bsdf_from_xml(
        r#"<bsdf type="roughconductor"><string name="ext_eta" value="water"/></bsdf>"#,
    );
    let Bsdf::RoughConductor(rc) = &water else {
        panic!()
    };
    assert_eq!(rc.ext_eta, 1.333);
}

/// `rawconstant` is used as it is: the same value at every wavelength, as a number, and as a raw
/// RGB triple for a normal map.
#[test]
fn rawconstant_is_not_upsampled() {
    let bsdf = bsdf_from_xml(
        r#"<bsdf type="roughconductor"><texture type="rawconstant" name="alpha"><float name="value" value="0.3"/></texture>
           <texture type="rawconstant" name="specular_reflectance"><float name="value" value="0.7"/></texture></bsdf>"#,
    );
    let Bsdf::RoughConductor(rc) = &bsdf else {
        panic!()
    };
    assert_eq!(rc.roughness.alpha_u.eval_1(Vec2::ZERO), 0.3);
    let lambda = wavelengths();
    assert_eq!(
        rc.specular_reflectance.eval(Vec2::ZERO, &lambda).0,
        [0.7; 4]
    );
    let normals = bsdf_from_xml(
        r#"<bsdf type="normalmap"><texture type="rawconstant" name="normalmap"><vector name="value" x="0.25" y="0.5" z="1"/></texture>
           <bsdf type="diffuse"/></bsdf>"#,
    );
    let Bsdf::NormalMap(n) = &normals else {
        panic!()
    };
    assert_eq!(
        n.normals.eval_3(Vec2::new(0.7, 0.2)),
        Vec3::new(0.25, 0.5, 1.0)
    );
}

/// A texel and the same colour given as `<rgb>` are one spectrum: both go through the one
/// coefficient table, so a one-colour PNG renders exactly as its decoded colour does. Mitsuba
/// 3.9.1 (`scalar_spectral`) gives this texel (sRGB 200, 120, 60) the reflectances 0.063548,
/// 0.208657 and 0.655589 at 450, 550 and 650 nm, and its `<rgb>` the same.
#[test]
fn a_texel_is_the_spectrum_of_its_colour() {
    let codes = [200u8, 120, 60];
    let linear = codes.map(|c| prism_core::image::srgb::decode(f32::from(c) / 255.0));
    let dir = temp_dir("one-colour");
    let png = dir.join("one.png");
    let pixels: Vec<f32> = (0..4).flat_map(|_| linear).collect();
    prism_core::image::write_png_srgb(&png, 2, 2, &pixels).unwrap();
    let texture = bsdf_from_xml(&format!(
        r#"<bsdf type="diffuse"><texture type="bitmap" name="reflectance"><string name="filename" value="{}"/></texture></bsdf>"#,
        png.display()
    ));
    let colour = bsdf_from_xml(&format!(
        r#"<bsdf type="diffuse"><rgb name="reflectance" value="{:?}, {:?}, {:?}"/></bsdf>"#,
        linear[0], linear[1], linear[2]
    ));
    let (Bsdf::Diffuse(texture), Bsdf::Diffuse(colour)) = (&texture, &colour) else {
        panic!()
    };
    let mitsuba = [(450.0, 0.063_548), (550.0, 0.208_657), (650.0, 0.655_589)];
    for (lambda, reference) in mitsuba {
        let lambda = SampledWavelengths::single(lambda);
        for uv in [Vec2::new(0.5, 0.5), Vec2::new(0.1, 0.9)] {
            let texel = texture.reflectance.eval(uv, &lambda)[0];
            let value = colour.reflectance.eval(uv, &lambda)[0];
            // The bilinear weights sum to 1 up to rounding: a few ulps.
            assert!(
                (texel - value).abs() <= 4.0 * f32::EPSILON * value,
                "{texel} {value}"
            );
            // Prism's table is its own fit of Mitsuba's model; the two agree to 0.03 % here.
            // The 0.25 % by which texels once came out darker (a 32³ table) would fail.
            assert!(
                (texel / reference - 1.0).abs() < 1e-3,
                "{texel} vs Mitsuba's {reference}"
            );
        }
    }
}

/// Unpolarised Fresnel reflectance of a smooth dielectric with relative index `eta`, seen from
/// outside at cos θ = `mu` (Born & Wolf §1.5.2), in double precision for the closed forms below.
fn dielectric_reflectance(mu: f64, eta: f64) -> f64 {
    let sin2_t = (1.0 - mu * mu) / (eta * eta);
    let cos_t = (1.0 - sin2_t).sqrt();
    let r_s = (mu - eta * cos_t) / (mu + eta * cos_t);
    let r_p = (eta * mu - cos_t) / (eta * mu + cos_t);
    0.5 * (r_s * r_s + r_p * r_p)
}

/// `pplastic`'s base reflects (1 − F(cos θo)) ρ (1 − F̄) of the light, F̄ = 2∫F(μ)μ dμ the
/// coating's hemispherical reflectance: its two refractions are smooth and independent. F̄ by a
/// 20 000-node midpoint rule (error below 10⁻⁸); the tolerance is the hemisphere quadrature's
/// error (Lambert's law integrates to ρ within 10⁻⁴ at this resolution).
#[test]
fn pplastic_base_albedo_is_its_closed_form() {
    let bsdf = bsdf_from_xml(
        r#"<bsdf type="pplastic"><rgb name="diffuse_reflectance" value="0.8"/>
            <rgb name="specular_reflectance" value="0"/><float name="int_ior" value="1.5"/></bsdf>"#,
    );
    let Bsdf::PolarizedPlastic(pplastic) = &bsdf else {
        panic!("expected pplastic")
    };
    let rho = pplastic
        .diffuse_reflectance
        .eval(point().uv, &wavelengths());
    let n = 20_000;
    let mean_reflectance = (0..n)
        .map(|i| {
            let mu = (i as f64 + 0.5) / n as f64;
            2.0 * dielectric_reflectance(mu, 1.5) * mu / n as f64
        })
        .sum::<f64>();
    for wo in [direction(0.0, 0.0), direction(60.0, 30.0)] {
        let integral = integrate_eval(&bsdf, wo, 800, 64);
        let outside = 1.0 - dielectric_reflectance(f64::from(wo.z), 1.5);
        for c in 0..4 {
            let expected = outside * f64::from(rho[c]) * (1.0 - mean_reflectance);
            assert!(
                (integral[c] - expected).abs() < 2e-4,
                "wo = {wo}: ∫f cos = {} but the closed form gives {expected}",
                integral[c]
            );
        }
    }
}

/// Dür's Ward lobe seen from the normal reflects ρ_s/α² ∫₀¹ e^(−t/α²)/(1 + t)² dt (with
/// t = tan²θ_h and dω_i = 4 cos θ_h dω_h, θ_h ≤ 45°); → ρ_s as α → 0. The 1-D integral by a
/// 20 000-node midpoint rule; the tolerance is the hemisphere quadrature's error at 2000 × 128
/// cells (below 10⁻⁴ for this lobe, as for Lambert's law at 800 × 64).
#[test]
fn ward_duer_albedo_at_normal_incidence_is_its_closed_form() {
    let (alpha, rho_s) = (0.3f64, 0.5f64);
    let bsdf = bsdf_from_xml(&format!(
        r#"<bsdf type="ward"><string name="variant" value="ward-duer"/>
            <float name="alpha" value="{alpha}"/><spectrum name="specular_reflectance" value="{rho_s}"/>
            <spectrum name="diffuse_reflectance" value="0"/></bsdf>"#
    ));
    let n = 20_000;
    let a2 = alpha * alpha;
    let expected = rho_s / a2
        * (0..n)
            .map(|i| {
                let t = (i as f64 + 0.5) / n as f64;
                (-t / a2).exp() / ((1.0 + t) * (1.0 + t)) / n as f64
            })
            .sum::<f64>();
    let integral = integrate_eval(&bsdf, direction(0.0, 0.0), 2000, 128);
    for value in integral {
        assert!(
            (value - expected).abs() < 2e-4,
            "∫f cos = {value} but the closed form gives {expected}"
        );
    }
}

/// `principled` with `spec_trans` 1 and a white base is Walter et al.'s rough dielectric: its
/// diffuse, sheen and clearcoat weights vanish, √c = 1, and its lobe probabilities become F and
/// 1 − F. Its value and density equal `roughdielectric`'s (GGX, α = roughness², the same η)
/// from both sides, to rounding.
#[test]
fn transmitting_principled_is_a_rough_dielectric() {
    let principled = bsdf_from_xml(
        r#"<bsdf type="principled"><spectrum name="base_color" value="1"/>
            <float name="spec_trans" value="1"/><float name="roughness" value="0.5"/>
            <float name="eta" value="1.45"/></bsdf>"#,
    );
    let dielectric = bsdf_from_xml(
        r#"<bsdf type="roughdielectric"><string name="distribution" value="ggx"/>
            <float name="alpha" value="0.25"/><float name="int_ior" value="1.45"/>
            <float name="ext_ior" value="1"/></bsdf>"#,
    );
    let (sp, lambda) = (point(), wavelengths());
    let mut rng = Pcg32::seeded(31);
    for _ in 0..4000 {
        let u = |rng: &mut Pcg32| Vec2::new(rng.next_f32(), rng.next_f32());
        let sphere = |u: Vec2| {
            let z = 1.0 - 2.0 * u.x;
            let r = (1.0 - z * z).max(0.0).sqrt();
            let phi = 2.0 * std::f32::consts::PI * u.y;
            Vec3::new(r * phi.cos(), r * phi.sin(), z)
        };
        let (wo, wi) = (sphere(u(&mut rng)), sphere(u(&mut rng)));
        if wo.z.abs() < 1e-2 || wi.z.abs() < 1e-2 {
            continue;
        }
        let a = principled.at(&sp, wo, &lambda).eval(wi);
        let b = dielectric.at(&sp, wo, &lambda).eval(wi);
        let close = |x: f32, y: f32| (x - y).abs() <= 1e-4 * x.abs().max(y.abs()) + 1e-6;
        assert!(
            close(a.pdf, b.pdf),
            "pdf {} but roughdielectric's {} at wo = {wo}, wi = {wi}",
            a.pdf,
            b.pdf
        );
        for c in 0..4 {
            assert!(
                close(a.value[c], b.value[c]),
                "value {} but roughdielectric's {} at wo = {wo}, wi = {wi}",
                a.value[c],
                b.value[c]
            );
        }
    }
}

/// An `<rgb>` η or k is read as Mitsuba 3.9.1's spectral variants read it: each component
/// clamped to [0, 1], then upsampled as a reflectance. The expected values are Mitsuba's, from
/// its fitted coefficients for these colours (`mi.traverse(bsdf)["eta.value"]`, evaluated at
/// each wavelength); the two renderers' coefficient tables differ by about 10⁻³.
#[test]
fn rgb_conductor_indices_are_clamped_as_mitsuba_reads_them() {
    let bsdf = bsdf_from_xml(
        r#"<bsdf type="conductor"><rgb name="eta" value="0.200438, 0.924033, 1.10221"/>
           <rgb name="k" value="3.91295, 2.45285, 2.14219"/></bsdf>"#,
    );
    let Bsdf::Conductor(c) = &bsdf else { panic!() };
    let value = |t: &prism_core::texture::Texture, lambda: f32| match t {
        prism_core::texture::Texture::Constant(s) => s.value(lambda),
        other => panic!("{other:?}"),
    };
    for (lambda, mitsuba_eta) in [(450.0, 0.97995), (550.0, 0.90732), (650.0, 0.06969)] {
        let eta = value(&c.eta, lambda);
        assert!((eta - mitsuba_eta).abs() < 0.01, "η({lambda}) = {eta}");
        assert_eq!(value(&c.k, lambda), 1.0);
    }
    // A <spectrum> keeps its values.
    let bsdf = bsdf_from_xml(
        r#"<bsdf type="conductor"><spectrum name="eta" value="0.924"/><spectrum name="k" value="2.45"/></bsdf>"#,
    );
    let Bsdf::Conductor(c) = &bsdf else { panic!() };
    assert_eq!((value(&c.eta, 500.0), value(&c.k, 500.0)), (0.924, 2.45));
}
