//! The `aov` integrator: channel names as Mitsuba writes them; depth, position, normals and
//! albedo of a plane seen head-on against closed forms; the albedo (diffuse reflectance) of
//! every BSDF. A pixel's variable is the mean of N samples of a quantity bounded on the pixel's
//! footprint by [lo, hi], so by Hoeffding's inequality it lies within
//! (hi − lo)·√(ln(2/δ)/(2N)) of its expectation except with probability δ = 10⁻⁶.

use std::path::Path;

use glam::Vec3;
use prism_core::bsdf::BsdfModel;
use prism_core::film::Film;
use prism_core::scene::Scene;
use prism_core::spectrum::cie::xyz_to_linear_srgb;
use prism_core::spectrum::{SampledSpectrum, SampledWavelengths};

use crate::common::bsdfs::{bsdf_from_xml, point, wavelengths};
use crate::common::scenes::render_film;

fn scene(xml: &str) -> Scene {
    let root = prism_mitsuba::reader::read_scene_str(xml, Path::new("aov.xml"), &[]).unwrap();
    prism_mitsuba::factory::build_scene(&root).unwrap().scene
}

/// A camera at height D above a large diffuse plane z = 0 (reflectance 0.5), looking straight
/// down with a 40° field of view on a W × W film.
const D: f64 = 2.0;
const W: usize = 8;
const FOV: f64 = 40.0;
/// Mitsuba's default `near_clip`: camera rays start on the near plane, and depth is measured
/// from there.
const NEAR_CLIP: f64 = 0.01;
const PLANE: &str = r#"<scene version="3.0.0">
    <integrator type="aov">
        <string name="aovs" value="dd.y:depth,nn:sh_normal,gn:geo_normal,p:position,alb:albedo"/>
        <integrator type="path" name="my_image"/>
    </integrator>
    <sensor type="perspective">
        <float name="fov" value="40"/>
        <transform name="to_world"><lookat origin="0, 0, 2" target="0, 0, 0" up="0, 1, 0"/></transform>
        <film type="hdrfilm"><integer name="width" value="8"/><integer name="height" value="8"/><rfilter type="box"/></film>
    </sensor>
    <shape type="rectangle">
        <transform name="to_world"><scale value="10"/></transform>
        <bsdf type="diffuse"><spectrum name="reflectance" value="0.5"/></bsdf>
    </shape>
    <emitter type="constant"><spectrum name="radiance" value="1"/></emitter>
</scene>"#;

fn channel(film: &Film, name: &str) -> Vec<f32> {
    let index = film
        .aov_names
        .iter()
        .position(|n| n == name)
        .unwrap_or_else(|| panic!("no channel {name} in {:?}", film.aov_names));
    film.aov(index)
}

/// Hoeffding's bound on the error of a mean of `n` samples within [lo, hi], at δ = 10⁻⁶.
fn hoeffding(lo: f64, hi: f64, n: u32) -> f64 {
    (hi - lo) * ((2.0f64 / 1e-6).ln() / (2.0 * f64::from(n))).sqrt()
}

#[test]
fn channel_names_are_mitsubas() {
    let names = scene(PLANE).integrator.aov_names();
    let expected = [
        "my_image.R",
        "my_image.G",
        "my_image.B",
        "my_image.A",
        "dd.y.T",
        "nn.X",
        "nn.Y",
        "nn.Z",
        "gn.X",
        "gn.Y",
        "gn.Z",
        "p.X",
        "p.Y",
        "p.Z",
        "alb.R",
        "alb.G",
        "alb.B",
    ];
    assert_eq!(names, expected);
}

/// Pixel (i, j) sees the square of the plane x ∈ h·[2i/W − 1, 2(i+1)/W − 1] (likewise y, the
/// signs depending on the camera's orientation), h = D tan(fov/2), uniformly (a box filter,
/// and the plane is perpendicular to the view axis, so film and plane are related linearly).
/// Depth is the distance from the near plane along the ray, √(x² + y² + D²)·(1 − near/D), there
/// (its mean by a 256² midpoint rule), the position's mean is the
/// square's centre, both normals are +z exactly, and the albedo is the sRGB of the reflectance
/// 0.5 at each sample's wavelengths (its mean by a midpoint rule over the wavelength sample).
#[test]
fn depth_position_normals_and_albedo_of_a_plane() {
    let scene = scene(PLANE);
    let spp = 256;
    let film = render_film(&scene, spp, 5, None);
    let (depth, px, py, pz) = (
        channel(&film, "dd.y.T"),
        channel(&film, "p.X"),
        channel(&film, "p.Y"),
        channel(&film, "p.Z"),
    );
    let h = D * (0.5 * FOV).to_radians().tan();
    let edge = |i: usize| h * (2.0 * i as f64 / W as f64 - 1.0);
    for j in 0..W {
        for i in 0..W {
            let pixel = j * W + i;
            let (x0, x1, y0, y1) = (edge(i), edge(i + 1), edge(j), edge(j + 1));
            let steps = 256;
            let mut mean = 0.0;
            let (mut lo, mut hi) = (f64::INFINITY, 0.0f64);
            for a in 0..steps {
                for b in 0..steps {
                    let x = x0 + (x1 - x0) * (a as f64 + 0.5) / steps as f64;
                    let y = y0 + (y1 - y0) * (b as f64 + 0.5) / steps as f64;
                    let d = (x * x + y * y + D * D).sqrt() * (1.0 - NEAR_CLIP / D);
                    mean += d / (steps * steps) as f64;
                    lo = lo.min(d);
                    hi = hi.max(d);
                }
            }
            let got = f64::from(depth[pixel]);
            let tolerance = hoeffding(lo, hi, spp) + 1e-5;
            assert!(
                (got - mean).abs() < tolerance,
                "pixel {pixel}: depth {got}, closed form {mean} (± {tolerance})"
            );
            // The centre's coordinates up to sign (the film's orientation is not the point).
            let tolerance = hoeffding(0.0, x1 - x0, spp) + 1e-5;
            for (got, centre) in [(px[pixel], 0.5 * (x0 + x1)), (py[pixel], 0.5 * (y0 + y1))] {
                let (got, centre) = (f64::from(got).abs(), centre.abs());
                assert!(
                    (got - centre).abs() < tolerance,
                    "pixel {pixel}: position {got}, closed form {centre} (± {tolerance})"
                );
            }
            assert!(pz[pixel].abs() < 1e-5, "pixel {pixel}: z = {}", pz[pixel]);
        }
    }
    for name in ["nn", "gn"] {
        let normal = [".X", ".Y", ".Z"].map(|c| channel(&film, &format!("{name}{c}")));
        let [x, y, z] = &normal;
        for (pixel, ((&x, &y), &z)) in x.iter().zip(y).zip(z).enumerate() {
            let n = Vec3::new(x, y, z);
            assert!((n - Vec3::Z).length() < 1e-6, "pixel {pixel}: {name} = {n}");
        }
    }

    let steps = 1 << 16;
    let (mut mean, mut lo, mut hi) = ([0.0f64; 3], [f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    for i in 0..steps {
        let u = (i as f32 + 0.5) / steps as f32;
        let lambda = SampledWavelengths::sample(u, scene.film.wavelength_sampling);
        let rgb = xyz_to_linear_srgb(lambda.to_xyz(&SampledSpectrum::splat(0.5)));
        for c in 0..3 {
            let v = f64::from(rgb[c]);
            mean[c] += v / steps as f64;
            lo[c] = lo[c].min(v);
            hi[c] = hi[c].max(v);
        }
    }
    for (c, axis) in ["R", "G", "B"].iter().enumerate() {
        let albedo = channel(&film, &format!("alb.{axis}"));
        let tolerance = hoeffding(lo[c], hi[c], spp) + 1e-5;
        for (pixel, &got) in albedo.iter().enumerate() {
            assert!(
                (f64::from(got) - mean[c]).abs() < tolerance,
                "pixel {pixel}: albedo {axis} {got}, closed form {} (± {tolerance})",
                mean[c]
            );
        }
    }
    // The image is the nested path tracer's: coverage 1, and its colour beside it.
    assert!(channel(&film, "my_image.A").iter().all(|&a| a == 1.0));
}

/// Mitsuba's `eval_diffuse_reflectance` for each BSDF: the diffuse part's reflectance, zero for
/// conductors and dielectrics, the side's for `twosided`, the nested one's for adapters.
#[test]
fn albedo_of_every_bsdf() {
    let diffuse = r#"<bsdf type="diffuse"><spectrum name="reflectance" value="0.3"/></bsdf>"#;
    let cases: Vec<(String, f32)> = vec![
        (diffuse.to_string(), 0.3),
        (
            r#"<bsdf type="roughdiffuse"><spectrum name="reflectance" value="0.3"/></bsdf>"#.into(),
            0.3,
        ),
        (
            r#"<bsdf type="plastic"><spectrum name="diffuse_reflectance" value="0.3"/></bsdf>"#
                .into(),
            0.3,
        ),
        (
            r#"<bsdf type="roughplastic"><spectrum name="diffuse_reflectance" value="0.3"/></bsdf>"#
                .into(),
            0.3,
        ),
        (
            r#"<bsdf type="phong"><spectrum name="diffuse_reflectance" value="0.3"/><spectrum name="specular_reflectance" value="0.2"/></bsdf>"#
                .into(),
            0.3,
        ),
        (
            r#"<bsdf type="pplastic"><spectrum name="diffuse_reflectance" value="0.3"/></bsdf>"#
                .into(),
            0.3,
        ),
        (
            r#"<bsdf type="ward"><spectrum name="diffuse_reflectance" value="0.3"/><spectrum name="specular_reflectance" value="0.2"/></bsdf>"#
                .into(),
            0.3,
        ),
        (
            r#"<bsdf type="principled"><spectrum name="base_color" value="0.3"/><float name="metallic" value="0.5"/></bsdf>"#
                .into(),
            0.3,
        ),
        (
            r#"<bsdf type="principledthin"><spectrum name="base_color" value="0.3"/></bsdf>"#
                .into(),
            0.3,
        ),
        (r#"<bsdf type="null"/>"#.into(), 0.0),
        (r#"<bsdf type="conductor"/>"#.into(), 0.0),
        (r#"<bsdf type="roughconductor"/>"#.into(), 0.0),
        (r#"<bsdf type="dielectric"/>"#.into(), 0.0),
        (r#"<bsdf type="roughdielectric"/>"#.into(), 0.0),
        (r#"<bsdf type="thindielectric"/>"#.into(), 0.0),
        (
            format!(r#"<bsdf type="mask"><float name="opacity" value="0.25"/>{diffuse}</bsdf>"#),
            0.3,
        ),
        (
            format!(
                r#"<bsdf type="blendbsdf"><float name="weight" value="0.25"/>{diffuse}<bsdf type="conductor"/></bsdf>"#
            ),
            0.75 * 0.3,
        ),
        (
            format!(
                r#"<bsdf type="bumpmap"><texture type="checkerboard"/>{diffuse}</bsdf>"#
            ),
            0.3,
        ),
    ];
    let lambda = wavelengths();
    let above = Vec3::new(0.3, 0.2, 0.9).normalize();
    for (xml, expected) in cases {
        let albedo = bsdf_from_xml(&xml).diffuse_reflectance(&point(), above, &lambda);
        for i in 0..4 {
            assert!(
                (albedo[i] - expected).abs() < 1e-6,
                "{xml}: albedo {} at wavelength {i}, expected {expected}",
                albedo[i]
            );
        }
    }
    let twosided = bsdf_from_xml(&format!(
        r#"<bsdf type="twosided">{diffuse}<bsdf type="diffuse"><spectrum name="reflectance" value="0.6"/></bsdf></bsdf>"#
    ));
    let below = Vec3::new(above.x, above.y, -above.z);
    for (wo, expected) in [(above, 0.3), (below, 0.6)] {
        let albedo = twosided.diffuse_reflectance(&point(), wo, &lambda);
        assert!(
            (albedo[0] - expected).abs() < 1e-6,
            "twosided from {wo}: {}",
            albedo[0]
        );
    }
}
