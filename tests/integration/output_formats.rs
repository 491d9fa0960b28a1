//! The EXR `prism render` writes as the film's `pixel_format` and `component_format` (or
//! `--half`) ask: its channels, which of them are half floats, the render's metadata in the
//! header, the coverage alpha, and `prism compare` and `prism merge` over every variant.
//!
//! The scene is `tests/data/mitsuba-sphere.xml`: a diffuse sphere of radius 0.8 seen from 5
//! units away under a 30° field of view on a 16 × 12 film with a box filter, lit by a point
//! light, with no environment.

use std::path::{Path, PathBuf};
use std::process::Command;

use prism_core::film::RenderMetadata;
use prism_core::image::{Attribute, ChannelImage, ExrHeader, read_exr_with_header};

const SCENE: &str = "tests/data/mitsuba-sphere.xml";

/// A scratch directory for one test.
fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("prism-output-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Runs `prism ARGS` from the repository root, which must succeed.
fn prism(args: &[&str]) {
    let output = Command::new(env!("CARGO_BIN_EXE_prism"))
        .args(args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("the prism binary runs");
    assert!(
        output.status.success(),
        "prism {args:?} failed: {}",
        String::from_utf8_lossy(&output.stderr)
    );
}

/// Renders the sphere to `out` with `--spp`, seed 3, two threads and the extra `args`.
fn render(out: &Path, spp: u32, args: &[&str]) -> (ChannelImage, ExrHeader) {
    render_seeded(out, spp, 3, args)
}

/// As [`render`], with random numbers of `seed`.
fn render_seeded(out: &Path, spp: u32, seed: u64, args: &[&str]) -> (ChannelImage, ExrHeader) {
    let (spp, seed) = (spp.to_string(), seed.to_string());
    let mut all = vec![
        "render",
        SCENE,
        "-q",
        "--spp",
        &spp,
        "--seed",
        &seed,
        "--threads",
        "2",
        "-o",
        out.to_str().unwrap(),
    ];
    all.extend(args);
    prism(&all);
    read_exr_with_header(out).unwrap()
}

fn sorted_names(image: &ChannelImage) -> Vec<&str> {
    let mut names: Vec<&str> = image.channels.iter().map(|(n, _)| n.as_str()).collect();
    names.sort();
    names
}

fn bits(values: &[f32]) -> Vec<u32> {
    values.iter().map(|v| v.to_bits()).collect()
}

#[test]
fn each_pixel_format_writes_its_channels_of_the_same_image() {
    let dir = scratch("formats");
    let define = |format: &str| format!("pixel_format={format}");
    let statistics = ["relative_error.Y", "variance.X", "variance.Y", "variance.Z"];
    let with = |colour: &[&'static str]| {
        let mut names: Vec<&str> = colour.to_vec();
        names.extend(statistics);
        names.sort();
        names
    };
    let formats: [(&str, Vec<&str>); 6] = [
        ("rgb", with(&["R", "G", "B", "X", "Y", "Z"])),
        ("rgba", with(&["R", "G", "B", "X", "Y", "Z", "A"])),
        ("xyz", with(&["X", "Y", "Z"])),
        ("xyza", with(&["X", "Y", "Z", "A"])),
        ("luminance", vec!["Y", "relative_error.Y", "variance.Y"]),
        (
            "luminance_alpha",
            vec!["A", "Y", "relative_error.Y", "variance.Y"],
        ),
    ];
    let (rgb, _) = render(&dir.join("rgb.exr"), 4, &["-D", &define("rgb")]);
    for (format, names) in formats {
        let (image, header) = render(
            &dir.join(format!("{format}.exr")),
            4,
            &["-D", &define(format)],
        );
        assert_eq!(sorted_names(&image), names, "{format}");
        assert!(header.half_channels.is_empty(), "{format}");
        for name in ["Y", "variance.Y", "relative_error.Y"] {
            let (a, b) = (image.channel(name).unwrap(), rgb.channel(name).unwrap());
            assert_eq!(bits(a), bits(b), "{format}: {name}");
        }
    }
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn half_floats_round_the_colours_and_keep_the_statistics() {
    let dir = scratch("half");
    let (full, _) = render(&dir.join("full.exr"), 4, &[]);
    let (half, header) = render(&dir.join("half.exr"), 4, &["--half"]);
    let (film_half, film_header) = render(
        &dir.join("film-half.exr"),
        4,
        &["-D", "component_format=float16"],
    );
    let mut half_channels = header.half_channels.clone();
    half_channels.sort();
    assert_eq!(half_channels, ["B", "G", "R", "X", "Y", "Z"]);
    // Rounding to the nearest half float moves a value by at most half a unit in its last
    // place: 2⁻¹¹ of it for normal values, 2⁻²⁵ below 2⁻¹⁴.
    for (name, values) in &full.channels {
        let read = half.channel(name).unwrap();
        if half_channels.contains(name) {
            for (&h, &v) in read.iter().zip(values) {
                let bound = (v.abs() * 2f32.powi(-11)).max(2f32.powi(-25));
                assert!((h - v).abs() <= bound, "{name}: {h} for {v}");
            }
            assert_ne!(bits(read), bits(values), "{name} is not rounded");
        } else {
            assert_eq!(bits(read), bits(values), "{name}");
        }
    }
    assert_eq!(film_half, half);
    assert_eq!(film_header.half_channels, header.half_channels);
    let size = |name: &str| std::fs::metadata(dir.join(name)).unwrap().len();
    assert!(size("half.exr") < size("full.exr"));
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn the_header_records_the_render() {
    let dir = scratch("metadata");
    let (_, header) = render(&dir.join("a.exr"), 5, &[]);
    let metadata = RenderMetadata::of(&header).expect("the header records the render");
    assert_eq!((metadata.spp, metadata.seed), (5, 3));
    assert!(metadata.seconds.is_some_and(|s| s > 0.0 && s < 60.0));
    assert_eq!(
        header.attribute("prism.version"),
        Some(&Attribute::Text(env!("CARGO_PKG_VERSION").into()))
    );
    std::fs::remove_dir_all(dir).unwrap();
}

/// The mean coverage alpha is the fraction of the film the sphere's silhouette covers: a
/// circle of radius r = 8 · tan(asin(0.8/5)) / tan(15°) = 4.8393 pixels, π r² / 192 = 0.38320.
/// Each of the ≈ 35 pixels on the outline has an alpha of variance at most 1/(4N) with N
/// samples, so the mean's standard error is at most √(35/(4N)) / 192 = 9.6·10⁻⁴ at N = 256;
/// the tolerance is four of those. Pixels inside are covered by every sample, corners by none.
/// Mitsuba 3 gives this scene's 16-sample alpha a mean of 0.3867 (tests/data/README.md).
#[test]
fn the_coverage_alpha_is_the_silhouettes_share_of_each_pixel() {
    let dir = scratch("alpha");
    let (image, _) = render(&dir.join("a.exr"), 256, &["-D", "pixel_format=rgba"]);
    let alpha = image.channel("A").unwrap();
    let mean = alpha.iter().map(|&a| f64::from(a)).sum::<f64>() / alpha.len() as f64;
    let radius = 8.0 * (0.8f64 / 5.0).asin().tan() / 15f64.to_radians().tan();
    let expected = std::f64::consts::PI * radius * radius / 192.0;
    assert!(
        (mean - expected).abs() < 4.0 * 9.6e-4,
        "{mean} vs {expected}"
    );
    assert_eq!(alpha[6 * 16 + 8], 1.0);
    assert_eq!(alpha[0], 0.0);
    assert!(alpha.iter().all(|&a| (0.0..=1.0).contains(&a)));
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn compare_reads_luminance_and_half_files() {
    let dir = scratch("compare");
    render(&dir.join("lum-a.exr"), 4, &["-D", "pixel_format=luminance"]);
    render_seeded(&dir.join("half.exr"), 4, 4, &["--half"]);
    let alpha = ["-D", "pixel_format=luminance_alpha"];
    render_seeded(&dir.join("lum-b.exr"), 4, 5, &alpha);
    let path = |name: &str| dir.join(name).to_str().unwrap().to_string();
    let output = Command::new(env!("CARGO_BIN_EXE_prism"))
        .args(["compare", &path("lum-a.exr"), &path("half.exr")])
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&output.stdout);
    assert!(output.status.success(), "{text}");
    assert!(
        text.contains("       Y") && text.contains("z-test of Y"),
        "{text}"
    );
    prism(&["compare", &path("lum-b.exr"), &path("lum-a.exr")]);
    std::fs::remove_dir_all(dir).unwrap();
}

/// Merged states give the EXR of one render of all their samples, the coverage alpha
/// included (it travels in the states as an extra channel), whatever format the parts'
/// EXR files had.
#[test]
fn merge_keeps_the_alpha_of_the_states() {
    let dir = scratch("merge");
    let file = |name: &str| dir.join(name).to_str().unwrap().to_string();
    let rgba = ["-D", "pixel_format=rgba"];
    let (whole, _) = render(&dir.join("whole.exr"), 8, &rgba);
    for (range, name) in [("0..3", "a"), ("3..8", "b")] {
        let state = file(&format!("{name}.state"));
        let mut args = rgba.to_vec();
        args.extend(["--half", "--sample-range", range, "--checkpoint", &state]);
        render(&dir.join(format!("{name}.exr")), 8, &args);
    }
    prism(&[
        "merge",
        &file("a.state"),
        &file("b.state"),
        "-o",
        &file("merged.exr"),
    ]);
    let (merged, header) = read_exr_with_header(&dir.join("merged.exr")).unwrap();
    assert_eq!(sorted_names(&merged), sorted_names(&whole));
    for (name, values) in &whole.channels {
        assert_eq!(bits(merged.channel(name).unwrap()), bits(values), "{name}");
    }
    let metadata = RenderMetadata::of(&header).unwrap();
    assert_eq!(
        (metadata.spp, metadata.seed, metadata.seconds),
        (8, 3, None)
    );
    std::fs::remove_dir_all(dir).unwrap();
}

/// Mitsuba 0.6's `ldrfilm` with an alpha channel: its 8-bit alpha is the coverage the EXR
/// holds as `A`, rounded to 8 bits.
#[test]
fn an_ldrfilm_alpha_is_the_coverage() {
    let dir = scratch("ldr-alpha");
    let scene = std::fs::read_to_string(SCENE)
        .unwrap()
        .replace(r#"<film type="hdrfilm">"#, r#"<film type="ldrfilm">"#)
        .replace(
            r#"<string name="component_format" value="$component_format"/>"#,
            "",
        )
        .replace("$pixel_format", "rgba");
    let path = dir.join("scene.xml");
    std::fs::write(&path, scene).unwrap();
    let out = dir.join("a.exr");
    prism(&[
        "render",
        path.to_str().unwrap(),
        "-q",
        "--spp",
        "16",
        "-o",
        out.to_str().unwrap(),
    ]);
    let (image, _) = read_exr_with_header(&out).unwrap();
    let coverage = image.channel("A").unwrap();
    assert!(coverage.contains(&0.0) && coverage.contains(&1.0));
    let png = prism_core::image::read_bitmap(&dir.join("a.png")).unwrap();
    assert_eq!(png.channels, 4);
    for (i, &a) in coverage.iter().enumerate() {
        let stored = png.data[4 * i + 3];
        assert!(
            (stored - a).abs() <= 0.5 / 255.0 + 1e-6,
            "pixel {i}: {stored} for {a}"
        );
    }
    std::fs::remove_dir_all(dir).unwrap();
}
