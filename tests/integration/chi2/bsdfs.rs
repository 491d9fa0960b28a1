//! Every BSDF against its own claims, from several incident directions (docs/testing.md,
//! chi-square tests): a chi-square test of `sample` against `pdf`; every sample's weight equal to
//! eval/pdf and its pdf equal to `pdf`; Helmholtz reciprocity for the reflecting BSDFs; an
//! albedo of at most one. Delta lobes cannot be tested by a histogram; their probabilities and
//! directions are tested in `materials`.

use glam::Vec3;
use prism_core::sampling::chi2::assert_passes;

use crate::common::bsdfs::{
    assert_albedo_at_most_one, assert_reciprocal, bsdf_from_xml, check_samples, chi2_bsdf,
    direction, integrate_eval,
};

/// An incident direction by its spherical angles in degrees, or the opposite of one (below the
/// surface).
#[derive(Clone, Copy, Debug)]
enum Wo {
    Above(f32, f32),
    Below(f32, f32),
}

impl Wo {
    fn direction(self) -> Vec3 {
        match self {
            Wo::Above(theta, phi) => direction(theta, phi),
            Wo::Below(theta, phi) => -direction(theta, phi),
        }
    }
}

// Incident directions above the surface.
const NORMAL: Wo = Wo::Above(0.0, 0.0);
const MODERATE: Wo = Wo::Above(35.0, 20.0);
const OBLIQUE: Wo = Wo::Above(65.0, 200.0);
const GRAZING: Wo = Wo::Above(85.0, 110.0);

/// Every direction above the surface: normal, moderate, oblique and grazing.
const UPPER: [Wo; 4] = [NORMAL, MODERATE, OBLIQUE, GRAZING];

/// Directions on both sides, for BSDFs that transmit.
const BOTH_SIDES: [Wo; 4] = [
    Wo::Above(20.0, 10.0),
    Wo::Above(70.0, 100.0),
    Wo::Below(30.0, 250.0),
    Wo::Below(75.0, 30.0),
];

/// Directions on both sides for the thin principled BSDF.
const THIN_SIDES: [Wo; 3] = [
    Wo::Above(20.0, 10.0),
    Wo::Above(70.0, 100.0),
    Wo::Below(35.0, 250.0),
];

/// One BSDF of the test named `test`, checked from each of `directions`: a chi-square test, the
/// per-sample checks and, where `energy_bound`, the albedo bound; and, where `reciprocal`,
/// Helmholtz reciprocity.
struct Case {
    test: &'static str,
    name: &'static str,
    xml: &'static str,
    directions: &'static [Wo],
    seed: u64,
    energy_bound: bool,
    reciprocal: bool,
}

impl Case {
    /// A case whose albedo is bounded and which is not tested for reciprocity.
    const fn new(
        test: &'static str,
        name: &'static str,
        xml: &'static str,
        directions: &'static [Wo],
        seed: u64,
    ) -> Case {
        Case {
            test,
            name,
            xml,
            directions,
            seed,
            energy_bound: true,
            reciprocal: false,
        }
    }

    /// This case, tested for reciprocity too.
    const fn reciprocal(self) -> Case {
        Case {
            reciprocal: true,
            ..self
        }
    }

    /// This case without the albedo bound.
    const fn unbounded(self) -> Case {
        Case {
            energy_bound: false,
            ..self
        }
    }
}

/// Chi-square tests in this module (for Šidák's correction): one per (case, direction).
const TESTS: usize = {
    let mut count = 0;
    let mut i = 0;
    while i < CASES.len() {
        count += CASES[i].directions.len();
        i += 1;
    }
    count
};

/// Where the `bumpmap` case's XML names its height map, a file its test writes.
const HEIGHT_MAP: &str = "{height map}";

const CASES: &[Case] = &[
    Case::new(
        "diffuse",
        "diffuse",
        r#"<bsdf type="diffuse"><rgb name="reflectance" value="0.8, 0.4, 0.1"/></bsdf>"#,
        &[NORMAL, MODERATE],
        1,
    )
    .reciprocal(),
    Case::new(
        "roughdiffuse",
        "roughdiffuse",
        r#"<bsdf type="roughdiffuse"><float name="alpha" value="0.6"/>
        <rgb name="reflectance" value="0.9"/></bsdf>"#,
        &[MODERATE, OBLIQUE],
        2,
    )
    .reciprocal(),
    Case::new(
        "diffusetransmission",
        "diffusetransmission",
        r#"<bsdf type="diffusetransmission"><rgb name="reflectance" value="0.7, 0.2, 0.1"/>
        <rgb name="transmittance" value="0.2, 0.5, 0.8"/></bsdf>"#,
        &BOTH_SIDES,
        29,
    ),
    Case::new(
        "roughconductor_ggx",
        "roughconductor ggx",
        r#"<bsdf type="roughconductor"><string name="material" value="Au"/>
        <string name="distribution" value="ggx"/><float name="alpha" value="0.3"/></bsdf>"#,
        &UPPER,
        3,
    )
    .reciprocal(),
    Case::new(
        "roughconductor_beckmann",
        "roughconductor beckmann",
        r#"<bsdf type="roughconductor"><string name="material" value="Cu"/>
        <float name="alpha" value="0.3"/></bsdf>"#,
        &UPPER,
        4,
    )
    .reciprocal(),
    Case::new(
        "roughconductor_anisotropic",
        "roughconductor ggx anisotropic",
        r#"<bsdf type="roughconductor"><string name="distribution" value="ggx"/>
        <float name="alpha_u" value="0.15"/><float name="alpha_v" value="0.5"/></bsdf>"#,
        &[MODERATE, OBLIQUE],
        5,
    ),
    Case::new(
        "roughconductor_anisotropic",
        "roughconductor beckmann anisotropic",
        r#"<bsdf type="roughconductor">
        <float name="alpha_u" value="0.5"/><float name="alpha_v" value="0.2"/></bsdf>"#,
        &[MODERATE, OBLIQUE],
        6,
    )
    .reciprocal(),
    Case::new(
        "roughdielectric",
        "roughdielectric ggx",
        r#"<bsdf type="roughdielectric"><string name="distribution" value="ggx"/>
        <float name="alpha" value="0.3"/><float name="int_ior" value="1.5"/></bsdf>"#,
        &BOTH_SIDES,
        7,
    ),
    Case::new(
        "roughdielectric",
        "roughdielectric beckmann",
        r#"<bsdf type="roughdielectric"><float name="alpha" value="0.4"/>
        <string name="int_ior" value="water"/></bsdf>"#,
        &[BOTH_SIDES[1], BOTH_SIDES[2]],
        8,
    ),
    Case::new(
        "plastic",
        "plastic",
        r#"<bsdf type="plastic"><rgb name="diffuse_reflectance" value="0.2, 0.6, 0.9"/></bsdf>"#,
        &[MODERATE, OBLIQUE],
        9,
    )
    .reciprocal(),
    Case::new(
        "plastic",
        "plastic nonlinear",
        r#"<bsdf type="plastic"><boolean name="nonlinear" value="true"/>
        <rgb name="diffuse_reflectance" value="0.9"/></bsdf>"#,
        &[GRAZING],
        10,
    ),
    Case::new(
        "roughplastic",
        "roughplastic ggx",
        r#"<bsdf type="roughplastic"><string name="distribution" value="ggx"/>
        <float name="alpha" value="0.3"/><rgb name="diffuse_reflectance" value="0.7, 0.3, 0.1"/></bsdf>"#,
        &UPPER,
        11,
    )
    .reciprocal(),
    Case::new(
        "roughplastic",
        "roughplastic beckmann",
        r#"<bsdf type="roughplastic"><float name="alpha" value="0.2"/>
        <boolean name="nonlinear" value="true"/><rgb name="diffuse_reflectance" value="0.95"/></bsdf>"#,
        &[MODERATE, OBLIQUE],
        12,
    ),
    Case::new(
        "phong",
        "phong",
        r#"<bsdf type="phong"><float name="exponent" value="20"/>
        <rgb name="specular_reflectance" value="0.4"/><rgb name="diffuse_reflectance" value="0.5"/></bsdf>"#,
        &[MODERATE, OBLIQUE, GRAZING],
        13,
    )
    .reciprocal(),
    Case::new(
        "pplastic",
        "pplastic ggx",
        r#"<bsdf type="pplastic"><string name="distribution" value="ggx"/>
        <float name="alpha" value="0.3"/><rgb name="diffuse_reflectance" value="0.7, 0.3, 0.1"/></bsdf>"#,
        &UPPER,
        19,
    )
    .reciprocal(),
    Case::new(
        "pplastic",
        "pplastic beckmann anisotropic",
        r#"<bsdf type="pplastic"><float name="alpha_u" value="0.1"/>
        <float name="alpha_v" value="0.4"/><rgb name="diffuse_reflectance" value="1"/>
        <rgb name="specular_reflectance" value="0.8"/></bsdf>"#,
        &[MODERATE, OBLIQUE],
        20,
    )
    .reciprocal(),
    Case::new(
        "ward",
        "ward balanced",
        r#"<bsdf type="ward"><float name="alpha_u" value="0.1"/>
        <float name="alpha_v" value="0.3"/><rgb name="specular_reflectance" value="0.6"/>
        <rgb name="diffuse_reflectance" value="0.3"/></bsdf>"#,
        &[MODERATE, OBLIQUE, GRAZING],
        21,
    )
    .reciprocal(),
    Case::new(
        "ward",
        "ward",
        r#"<bsdf type="ward"><string name="variant" value="ward"/>
            <float name="alpha" value="0.25"/><rgb name="specular_reflectance" value="0.5"/></bsdf>"#,
        &[NORMAL, MODERATE],
        22,
    )
    .reciprocal(),
    Case::new(
        "ward",
        "ward-duer",
        r#"<bsdf type="ward"><string name="variant" value="ward-duer"/>
            <float name="alpha" value="0.25"/><rgb name="specular_reflectance" value="0.5"/></bsdf>"#,
        &[NORMAL, MODERATE],
        23,
    )
    .reciprocal(),
    Case::new(
        "principled",
        "principled",
        r#"<bsdf type="principled"><rgb name="base_color" value="0.8, 0.3, 0.1"/></bsdf>"#,
        &UPPER,
        24,
    )
    .reciprocal(),
    // Burley's sheen and clearcoat are added on top of the other lobes, so the model can reflect
    // more than it receives (here 1.04 at 65°, as in Mitsuba): no energy bound.
    Case::new(
        "principled",
        "principled, every reflecting lobe",
        r#"<bsdf type="principled"><rgb name="base_color" value="0.2, 0.5, 0.9"/>
        <float name="metallic" value="0.4"/><float name="roughness" value="0.3"/>
        <float name="anisotropic" value="0.6"/><float name="spec_tint" value="0.5"/>
        <float name="sheen" value="0.7"/><float name="sheen_tint" value="0.4"/>
        <float name="clearcoat" value="0.8"/><float name="clearcoat_gloss" value="0.6"/>
        <float name="flatness" value="0.5"/></bsdf>"#,
        &UPPER,
        25,
    )
    .unbounded()
    .reciprocal(),
    Case::new(
        "principled",
        "principled, transmitting",
        r#"<bsdf type="principled"><rgb name="base_color" value="0.9, 0.7, 0.6"/>
        <float name="spec_trans" value="0.7"/><float name="roughness" value="0.4"/>
        <float name="metallic" value="0.1"/><float name="clearcoat" value="0.5"/>
        <float name="eta" value="1.4"/></bsdf>"#,
        &BOTH_SIDES,
        26,
    ),
    Case::new(
        "principledthin",
        "principledthin, diffuse",
        r#"<bsdf type="principledthin"><rgb name="base_color" value="0.7, 0.4, 0.2"/>
        <float name="diff_trans" value="0.8"/><float name="sheen" value="0.5"/>
        <float name="flatness" value="0.4"/></bsdf>"#,
        &THIN_SIDES,
        27,
    ),
    Case::new(
        "principledthin",
        "principledthin, specular",
        r#"<bsdf type="principledthin"><rgb name="base_color" value="0.9, 0.8, 0.6"/>
        <float name="spec_trans" value="0.8"/><float name="diff_trans" value="0.3"/>
        <float name="roughness" value="0.4"/><float name="anisotropic" value="0.5"/>
        <float name="spec_tint" value="0.3"/><float name="eta" value="1.33"/></bsdf>"#,
        &THIN_SIDES,
        28,
    ),
    // A fibre along y: directions on both sides of the shading normal, away from the fibre's
    // axis, where the model is undefined.
    Case::new(
        "hair",
        "hair, melanin",
        r#"<bsdf type="hair"><float name="eumelanin" value="0.3"/>
        <float name="pheomelanin" value="0.5"/></bsdf>"#,
        &[MODERATE, OBLIQUE, Wo::Below(50.0, 300.0)],
        29,
    ),
    Case::new(
        "hair",
        "hair, sigma_a",
        r#"<bsdf type="hair"><rgb name="sigma_a" value="0.1, 0.3, 0.9"/>
        <float name="longitudinal_roughness" value="0.6"/><float name="azimuthal_roughness" value="0.8"/>
        <float name="scale_tilt" value="6"/><float name="int_ior" value="1.4"/></bsdf>"#,
        &[NORMAL, GRAZING],
        30,
    ),
    Case::new(
        "adapters",
        "mask",
        r#"<bsdf type="mask"><float name="opacity" value="0.7"/>
        <bsdf type="roughconductor"><float name="alpha" value="0.4"/></bsdf></bsdf>"#,
        &[Wo::Above(40.0, 0.0)],
        14,
    ),
    Case::new(
        "adapters",
        "blendbsdf",
        r#"<bsdf type="blendbsdf"><float name="weight" value="0.3"/>
        <bsdf type="roughconductor"><float name="alpha" value="0.3"/></bsdf>
        <bsdf type="plastic"/></bsdf>"#,
        &[MODERATE, OBLIQUE],
        15,
    ),
    Case::new(
        "adapters",
        "twosided",
        r#"<bsdf type="mask"><float name="opacity" value="0.9"/><bsdf type="twosided">
        <bsdf type="roughconductor"><string name="distribution" value="ggx"/><float name="alpha" value="0.3"/></bsdf>
        <bsdf type="diffuse"/></bsdf></bsdf>"#,
        &[Wo::Above(50.0, 70.0), Wo::Below(50.0, 70.0)],
        16,
    ),
    // The map tilts the normal by 55° towards (1, 1, 0): directions on that side stay above both
    // the surface and the tilted frame.
    Case::new(
        "adapters",
        "normalmap",
        r#"<bsdf type="normalmap"><texture type="checkerboard" name="normalmap">
        <float name="color0" value="0.6"/><float name="color1" value="0.6"/></texture>
        <bsdf type="roughplastic"><float name="alpha" value="0.3"/></bsdf></bsdf>"#,
        &[Wo::Above(35.0, 20.0), Wo::Above(60.0, 45.0)],
        17,
    ),
    Case::new(
        "bumpmap",
        "bumpmap",
        r#"<bsdf type="bumpmap"><texture type="bitmap"><string name="filename" value="{height map}"/>
            <boolean name="raw" value="true"/></texture><float name="scale" value="0.05"/>
            <bsdf type="roughplastic"><float name="alpha" value="0.3"/></bsdf></bsdf>"#,
        &[MODERATE, OBLIQUE],
        18,
    ),
];

/// Runs every case of the test `test`, each BSDF built from its XML as `xml` rewrites it.
fn check_cases(test: &str, xml: impl Fn(&str) -> String) {
    let cases: Vec<&Case> = CASES.iter().filter(|case| case.test == test).collect();
    assert!(!cases.is_empty(), "no case belongs to the test {test}");
    for case in cases {
        let bsdf = bsdf_from_xml(&xml(case.xml));
        for (i, wo) in case.directions.iter().enumerate() {
            let wo = wo.direction();
            let label = format!("{}, wo = {wo}", case.name);
            let seed = case.seed * 100 + i as u64;
            match chi2_bsdf(&bsdf, wo, seed) {
                Ok(outcome) => assert_passes(&label, &outcome, TESTS),
                Err(e) => panic!("{label}: {e}"),
            }
            let stats = check_samples(&bsdf, wo, 100_000, seed + 50);
            if case.energy_bound {
                assert_albedo_at_most_one(&label, &stats);
            }
        }
        if case.reciprocal {
            assert_reciprocal(case.name, &bsdf, case.seed);
        }
    }
}

/// Runs every case of the test `test` as its table gives it.
fn check(test: &str) {
    check_cases(test, str::to_string);
}

#[test]
fn diffuse() {
    check("diffuse");
}

#[test]
fn roughdiffuse() {
    check("roughdiffuse");
    let fast = r#"<bsdf type="roughdiffuse"><float name="alpha" value="0.6"/>
        <boolean name="use_fast_approx" value="true"/></bsdf>"#;
    assert_reciprocal("roughdiffuse (fast)", &bsdf_from_xml(fast), 3);
}

#[test]
fn diffusetransmission() {
    check("diffusetransmission");
    // A white furnace: what is not reflected is transmitted.
    let white = bsdf_from_xml(
        r#"<bsdf type="diffusetransmission"><rgb name="reflectance" value="0.4"/>
        <rgb name="transmittance" value="0.6"/></bsdf>"#,
    );
    for wo in BOTH_SIDES {
        let stats = check_samples(&white, wo.direction(), 100_000, 31);
        for c in 0..4 {
            assert!(
                (stats.albedo[c] - 1.0).abs() <= 4.0 * stats.albedo_se[c] + 1e-4,
                "diffusetransmission from {wo:?}: albedo {} ± {}",
                stats.albedo[c],
                stats.albedo_se[c]
            );
        }
    }
}

#[test]
fn roughconductor_ggx() {
    check("roughconductor_ggx");
}

#[test]
fn roughconductor_beckmann() {
    check("roughconductor_beckmann");
}

#[test]
fn roughconductor_anisotropic() {
    check("roughconductor_anisotropic");
}

#[test]
fn roughdielectric() {
    check("roughdielectric");
}

#[test]
fn plastic() {
    check("plastic");
}

#[test]
fn roughplastic() {
    check("roughplastic");
}

#[test]
fn phong() {
    check("phong");
}

#[test]
fn pplastic() {
    check("pplastic");
}

#[test]
fn ward() {
    check("ward");
}

#[test]
fn principled() {
    check("principled");
}

#[test]
fn principledthin() {
    check("principledthin");
}

#[test]
fn adapters() {
    check("adapters");
}

#[test]
fn hair() {
    check("hair");
}

/// A fibre that absorbs nothing returns all the light it receives (Chiang et al.'s terms sum to
/// 1 and each lobe is normalised), and one that absorbs returns less: ∫ f cos dωi over the
/// sphere, by a midpoint rule fine enough for the narrowest lobe here (v = 0.02).
#[test]
fn hair_furnace() {
    let clear = bsdf_from_xml(
        r#"<bsdf type="hair"><rgb name="sigma_a" value="0"/>
        <float name="longitudinal_roughness" value="0.25"/></bsdf>"#,
    );
    let absorbing = bsdf_from_xml(r#"<bsdf type="hair"/>"#);
    for wo in [MODERATE, OBLIQUE, Wo::Below(70.0, 150.0)] {
        let wo = wo.direction();
        let albedo = integrate_eval(&clear, wo, 1200, 600);
        for a in albedo {
            assert!((a - 1.0).abs() < 5e-3, "clear fibre, wo = {wo}: albedo {a}");
        }
        let albedo = integrate_eval(&absorbing, wo, 1200, 600);
        for a in albedo {
            assert!(a > 0.0 && a < 0.9, "absorbing fibre, wo = {wo}: albedo {a}");
        }
    }
}

/// A bump map needs a height texture with a gradient: a small EXR of sinusoidal heights.
#[test]
fn bumpmap() {
    let (w, h) = (16, 16);
    let heights: Vec<f32> = (0..w * h)
        .map(|i| 0.5 + 0.5 * ((i % w) as f32 * 0.7).sin() * ((i / w) as f32 * 0.4).cos())
        .collect();
    let path = std::env::temp_dir().join(format!("prism-bump-{}.exr", std::process::id()));
    let image = prism_core::image::ChannelImage {
        width: w,
        height: h,
        channels: ["R", "G", "B"]
            .iter()
            .map(|c| (c.to_string(), heights.clone()))
            .collect(),
    };
    prism_core::image::write_exr(&path, &image).unwrap();
    check_cases("bumpmap", |xml| {
        xml.replace(HEIGHT_MAP, &path.display().to_string())
    });
    std::fs::remove_file(&path).ok();
}
