//! Every BSDF against its own claims, from several incident directions (DESIGN.md §6): a
//! chi-square test of `sample` against `pdf`; every sample's weight equal to eval/pdf and its
//! pdf equal to `pdf`; Helmholtz reciprocity for the reflecting BSDFs; an albedo of at most one.
//! Delta lobes cannot be tested by a histogram; their probabilities and directions are tested
//! in `tests/materials.rs`.

#[path = "common/bsdfs.rs"]
mod bsdfs;
mod common;

use bsdfs::{
    assert_albedo_at_most_one, assert_reciprocal, bsdf_from_xml, check_samples, chi2_bsdf,
    direction,
};
use common::chi2::assert_passes;
use glam::Vec3;

/// Chi-square tests in this file (for Šidák's correction): one per (BSDF, direction).
const TESTS: usize = 56;

/// Incident directions above the surface: normal, moderate, oblique and grazing.
fn upper_directions() -> [Vec3; 4] {
    [
        direction(0.0, 0.0),
        direction(35.0, 20.0),
        direction(65.0, 200.0),
        direction(85.0, 110.0),
    ]
}

/// Runs the chi-square test, the per-sample checks and the albedo bound for each direction.
fn check(name: &str, xml: &str, directions: &[Vec3], seed: u64) {
    let bsdf = bsdf_from_xml(xml);
    for (i, &wo) in directions.iter().enumerate() {
        let label = format!("{name}, wo = {wo}");
        let seed = seed * 100 + i as u64;
        match chi2_bsdf(&bsdf, wo, seed) {
            Ok(outcome) => assert_passes(&label, &outcome, TESTS),
            Err(e) => panic!("{label}: {e}"),
        }
        let stats = check_samples(&bsdf, wo, 100_000, seed + 50);
        assert_albedo_at_most_one(&label, &stats);
    }
}

#[test]
fn diffuse() {
    let xml = r#"<bsdf type="diffuse"><rgb name="reflectance" value="0.8, 0.4, 0.1"/></bsdf>"#;
    check("diffuse", xml, &upper_directions()[..2], 1);
    assert_reciprocal("diffuse", &bsdf_from_xml(xml), 1);
}

#[test]
fn roughdiffuse() {
    let xml = r#"<bsdf type="roughdiffuse"><float name="alpha" value="0.6"/>
        <rgb name="reflectance" value="0.9"/></bsdf>"#;
    check("roughdiffuse", xml, &upper_directions()[1..3], 2);
    assert_reciprocal("roughdiffuse", &bsdf_from_xml(xml), 2);
    let fast = r#"<bsdf type="roughdiffuse"><float name="alpha" value="0.6"/>
        <boolean name="use_fast_approx" value="true"/></bsdf>"#;
    assert_reciprocal("roughdiffuse (fast)", &bsdf_from_xml(fast), 3);
}

#[test]
fn roughconductor_ggx() {
    let xml = r#"<bsdf type="roughconductor"><string name="material" value="Au"/>
        <string name="distribution" value="ggx"/><float name="alpha" value="0.3"/></bsdf>"#;
    check("roughconductor ggx", xml, &upper_directions(), 3);
    assert_reciprocal("roughconductor ggx", &bsdf_from_xml(xml), 3);
}

#[test]
fn roughconductor_beckmann() {
    let xml = r#"<bsdf type="roughconductor"><string name="material" value="Cu"/>
        <float name="alpha" value="0.3"/></bsdf>"#;
    check("roughconductor beckmann", xml, &upper_directions(), 4);
    assert_reciprocal("roughconductor beckmann", &bsdf_from_xml(xml), 4);
}

#[test]
fn roughconductor_anisotropic() {
    let ggx = r#"<bsdf type="roughconductor"><string name="distribution" value="ggx"/>
        <float name="alpha_u" value="0.15"/><float name="alpha_v" value="0.5"/></bsdf>"#;
    check(
        "roughconductor ggx anisotropic",
        ggx,
        &upper_directions()[1..3],
        5,
    );
    let beckmann = r#"<bsdf type="roughconductor">
        <float name="alpha_u" value="0.5"/><float name="alpha_v" value="0.2"/></bsdf>"#;
    check(
        "roughconductor beckmann anisotropic",
        beckmann,
        &upper_directions()[1..3],
        6,
    );
    assert_reciprocal("roughconductor anisotropic", &bsdf_from_xml(beckmann), 6);
}

#[test]
fn roughdielectric() {
    let ggx = r#"<bsdf type="roughdielectric"><string name="distribution" value="ggx"/>
        <float name="alpha" value="0.3"/><float name="int_ior" value="1.5"/></bsdf>"#;
    let both_sides = [
        direction(20.0, 10.0),
        direction(70.0, 100.0),
        -direction(30.0, 250.0),
        -direction(75.0, 30.0),
    ];
    check("roughdielectric ggx", ggx, &both_sides, 7);
    let beckmann = r#"<bsdf type="roughdielectric"><float name="alpha" value="0.4"/>
        <string name="int_ior" value="water"/></bsdf>"#;
    check("roughdielectric beckmann", beckmann, &both_sides[1..3], 8);
}

#[test]
fn plastic() {
    let xml =
        r#"<bsdf type="plastic"><rgb name="diffuse_reflectance" value="0.2, 0.6, 0.9"/></bsdf>"#;
    check("plastic", xml, &upper_directions()[1..3], 9);
    assert_reciprocal("plastic", &bsdf_from_xml(xml), 9);
    let nonlinear = r#"<bsdf type="plastic"><boolean name="nonlinear" value="true"/>
        <rgb name="diffuse_reflectance" value="0.9"/></bsdf>"#;
    check("plastic nonlinear", nonlinear, &upper_directions()[3..], 10);
}

#[test]
fn roughplastic() {
    let ggx = r#"<bsdf type="roughplastic"><string name="distribution" value="ggx"/>
        <float name="alpha" value="0.3"/><rgb name="diffuse_reflectance" value="0.7, 0.3, 0.1"/></bsdf>"#;
    check("roughplastic ggx", ggx, &upper_directions(), 11);
    assert_reciprocal("roughplastic ggx", &bsdf_from_xml(ggx), 11);
    let beckmann = r#"<bsdf type="roughplastic"><float name="alpha" value="0.2"/>
        <boolean name="nonlinear" value="true"/><rgb name="diffuse_reflectance" value="0.95"/></bsdf>"#;
    check(
        "roughplastic beckmann",
        beckmann,
        &upper_directions()[1..3],
        12,
    );
}

#[test]
fn phong() {
    let xml = r#"<bsdf type="phong"><float name="exponent" value="20"/>
        <rgb name="specular_reflectance" value="0.4"/><rgb name="diffuse_reflectance" value="0.5"/></bsdf>"#;
    check("phong", xml, &upper_directions()[1..4], 13);
    assert_reciprocal("phong", &bsdf_from_xml(xml), 13);
}

#[test]
fn pplastic() {
    let ggx = r#"<bsdf type="pplastic"><string name="distribution" value="ggx"/>
        <float name="alpha" value="0.3"/><rgb name="diffuse_reflectance" value="0.7, 0.3, 0.1"/></bsdf>"#;
    check("pplastic ggx", ggx, &upper_directions(), 19);
    assert_reciprocal("pplastic ggx", &bsdf_from_xml(ggx), 19);
    let anisotropic = r#"<bsdf type="pplastic"><float name="alpha_u" value="0.1"/>
        <float name="alpha_v" value="0.4"/><rgb name="diffuse_reflectance" value="1"/>
        <rgb name="specular_reflectance" value="0.8"/></bsdf>"#;
    check(
        "pplastic beckmann anisotropic",
        anisotropic,
        &upper_directions()[1..3],
        20,
    );
    assert_reciprocal("pplastic anisotropic", &bsdf_from_xml(anisotropic), 20);
}

#[test]
fn ward() {
    let balanced = r#"<bsdf type="ward"><float name="alpha_u" value="0.1"/>
        <float name="alpha_v" value="0.3"/><rgb name="specular_reflectance" value="0.6"/>
        <rgb name="diffuse_reflectance" value="0.3"/></bsdf>"#;
    check("ward balanced", balanced, &upper_directions()[1..4], 21);
    assert_reciprocal("ward balanced", &bsdf_from_xml(balanced), 21);
    for (i, variant) in ["ward", "ward-duer"].into_iter().enumerate() {
        let xml = format!(
            r#"<bsdf type="ward"><string name="variant" value="{variant}"/>
            <float name="alpha" value="0.25"/><rgb name="specular_reflectance" value="0.5"/></bsdf>"#
        );
        let seed = 22 + i as u64;
        check(variant, &xml, &upper_directions()[..2], seed);
        assert_reciprocal(variant, &bsdf_from_xml(&xml), seed);
    }
}

#[test]
fn adapters() {
    let mask = r#"<bsdf type="mask"><float name="opacity" value="0.7"/>
        <bsdf type="roughconductor"><float name="alpha" value="0.4"/></bsdf></bsdf>"#;
    check("mask", mask, &[direction(40.0, 0.0)], 14);
    let blend = r#"<bsdf type="blendbsdf"><float name="weight" value="0.3"/>
        <bsdf type="roughconductor"><float name="alpha" value="0.3"/></bsdf>
        <bsdf type="plastic"/></bsdf>"#;
    check("blendbsdf", blend, &upper_directions()[1..3], 15);
    let twosided = r#"<bsdf type="mask"><float name="opacity" value="0.9"/><bsdf type="twosided">
        <bsdf type="roughconductor"><string name="distribution" value="ggx"/><float name="alpha" value="0.3"/></bsdf>
        <bsdf type="diffuse"/></bsdf></bsdf>"#;
    check(
        "twosided",
        twosided,
        &[direction(50.0, 70.0), -direction(50.0, 70.0)],
        16,
    );
    let normalmap = r#"<bsdf type="normalmap"><texture type="checkerboard" name="normalmap">
        <float name="color0" value="0.6"/><float name="color1" value="0.6"/></texture>
        <bsdf type="roughplastic"><float name="alpha" value="0.3"/></bsdf></bsdf>"#;
    // The map tilts the normal by 55° towards (1, 1, 0): directions on that side stay above both
    // the surface and the tilted frame.
    check(
        "normalmap",
        normalmap,
        &[direction(35.0, 20.0), direction(60.0, 45.0)],
        17,
    );
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
    let xml = format!(
        r#"<bsdf type="bumpmap"><texture type="bitmap"><string name="filename" value="{}"/>
            <boolean name="raw" value="true"/></texture><float name="scale" value="0.05"/>
            <bsdf type="roughplastic"><float name="alpha" value="0.3"/></bsdf></bsdf>"#,
        path.display()
    );
    check("bumpmap", &xml, &upper_directions()[1..3], 18);
    std::fs::remove_file(&path).ok();
}
