//! pbrt-v4 scenes: the transcription of the Cornell box renders the XML's image, and malformed
//! files are refused with their file, line and column.

use std::path::{Path, PathBuf};

use prism_core::film::Film;
use prism_mitsuba::load_scene;

use crate::common::scenes::{
    image_mean_and_standard_error, pixel_mean_and_variance, render_film, scene_from_xml,
};

/// Mean and variance of the mean of channel `c` over the square block of `block` pixels whose
/// top-left pixel is (x0, y0).
fn block_mean(film: &Film, x0: usize, y0: usize, block: usize, c: usize) -> (f64, f64) {
    let width = film.size.x as usize;
    let n = (block * block) as f64;
    let (mut sum, mut variance) = (0.0, 0.0);
    for y in y0..y0 + block {
        for x in x0..x0 + block {
            let (m, v) = pixel_mean_and_variance(film, y * width + x, c);
            sum += m;
            variance += v;
        }
    }
    (sum / n, variance / (n * n))
}

/// The largest |z| of the differences of the two films' `block` × `block` blocks in X, Y and Z.
fn largest_block_z(a: &Film, b: &Film, block: usize) -> f64 {
    assert_eq!(a.size, b.size);
    let mut largest: f64 = 0.0;
    for y0 in (0..a.size.y as usize).step_by(block) {
        for x0 in (0..a.size.x as usize).step_by(block) {
            for c in 0..3 {
                let (ma, va) = block_mean(a, x0, y0, block, c);
                let (mb, vb) = block_mean(b, x0, y0, block, c);
                largest = largest.max((ma - mb).abs() / (va + vb).sqrt());
            }
        }
    }
    largest
}

#[test]
fn the_cornell_box_in_pbrt_renders_the_xml_image() {
    let xml = load_scene(Path::new("scenes/cornell-box/scene.xml"), &[]).unwrap();
    let pbrt = load_scene(Path::new("scenes/cornell-box/scene.pbrt"), &[]).unwrap();
    assert_eq!(pbrt.scene.film.size, xml.scene.film.size);
    // Independent estimates (two seeds) of the same image: 64 blocks × 3 channels, so a bound
    // of 4.5 standard errors fails a correct transcription with probability 1.3·10⁻³.
    let spp = 16;
    let a = render_film(&xml.scene, spp, 1, None);
    let b = render_film(&pbrt.scene, spp, 2, None);
    let z = largest_block_z(&a, &b, 32);
    assert!(
        z < 4.5,
        "the pbrt and XML images differ by {z:.1} standard errors"
    );
    // The test can fail: the XML image differs from itself mirrored (the red and green walls
    // swapped), as a camera that ignored pbrt's left-handed camera space would render it.
    let mut mirrored = a.clone();
    let width = a.size.x as usize;
    for (i, pixel) in mirrored.pixels.iter_mut().enumerate() {
        let (x, y) = (i % width, i / width);
        *pixel = a.pixels[y * width + (width - 1 - x)];
    }
    assert!(largest_block_z(&mirrored, &b, 32) > 20.0);
}

/// Instances, a medium, lights of four kinds and glass, in pbrt's format and in Mitsuba's.
const INSTANCES_IN_FOG_PBRT: &str = r#"
Scale -1 1 1
LookAt 0 1.5 -6  0 0.8 0  0 1 0
Camera "perspective" "float fov" 40
Film "rgb" "integer xresolution" 32 "integer yresolution" 32
PixelFilter "box"
Sampler "independent" "integer pixelsamples" 64
Integrator "volpath" "integer maxdepth" 5
WorldBegin
LightSource "infinite" "rgb L" [0.05 0.06 0.08]
LightSource "point" "rgb I" [30 25 20] "point3 from" [2 3 -2]
AttributeBegin
    AreaLightSource "diffuse" "rgb L" [8 8 8]
    Translate 0 3 0
    Rotate 90 1 0 0
    Shape "disk" "float radius" 1
AttributeEnd
Material "diffuse" "rgb reflectance" [0.5 0.5 0.5]
Shape "trianglemesh" "point3 P" [-4 0 -4  -4 0 4  4 0 4  4 0 -4] "integer indices" [0 1 2  0 2 3]
ObjectBegin "ball"
    Material "dielectric" "float eta" 1.5
    Translate 0 0.5 0
    Shape "sphere" "float radius" 0.5
ObjectEnd
AttributeBegin
    Translate -1.5 0 0
    ObjectInstance "ball"
AttributeEnd
AttributeBegin
    Translate 1.5 0 1
    Scale 1.5 1.5 1.5
    ObjectInstance "ball"
AttributeEnd
MakeNamedMedium "fog" "string type" "homogeneous" "rgb sigma_a" [0.5 0.5 0.5] "rgb sigma_s" [2 2 2] "float g" 0.5
AttributeBegin
    MediumInterface "fog" ""
    Material "interface"
    Translate 0 1 -2
    Shape "sphere" "float radius" 1
AttributeEnd
"#;

const INSTANCES_IN_FOG_XML: &str = r#"<scene version="3.0.0">
    <integrator type="volpath"><integer name="max_depth" value="6"/></integrator>
    <sensor type="perspective">
        <float name="fov" value="40"/>
        <string name="fov_axis" value="smaller"/>
        <transform name="to_world"><lookat origin="0, 1.5, -6" target="0, 0.8, 0" up="0, 1, 0"/></transform>
        <sampler type="independent"><integer name="sample_count" value="64"/></sampler>
        <film type="hdrfilm">
            <integer name="width" value="32"/><integer name="height" value="32"/>
            <rfilter type="box"/>
        </film>
    </sensor>
    <emitter type="constant"><rgb name="radiance" value="0.05, 0.06, 0.08"/></emitter>
    <emitter type="point">
        <rgb name="intensity" value="30, 25, 20"/>
        <point name="position" value="2, 3, -2"/>
    </emitter>
    <shape type="disk">
        <transform name="to_world">
            <rotate x="1" angle="90"/><translate y="3"/>
        </transform>
        <emitter type="area"><rgb name="radiance" value="8, 8, 8"/></emitter>
    </shape>
    <shape type="rectangle">
        <transform name="to_world"><scale value="4"/><rotate x="1" angle="-90"/></transform>
        <bsdf type="diffuse"><rgb name="reflectance" value="0.5, 0.5, 0.5"/></bsdf>
    </shape>
    <shape type="shapegroup" id="ball">
        <shape type="sphere">
            <point name="center" value="0, 0.5, 0"/>
            <float name="radius" value="0.5"/>
            <bsdf type="dielectric">
                <float name="int_ior" value="1.5"/><float name="ext_ior" value="1"/>
            </bsdf>
        </shape>
    </shape>
    <shape type="instance">
        <ref id="ball"/>
        <transform name="to_world"><translate x="-1.5"/></transform>
    </shape>
    <shape type="instance">
        <ref id="ball"/>
        <transform name="to_world"><scale value="1.5"/><translate x="1.5" z="1"/></transform>
    </shape>
    <shape type="sphere">
        <point name="center" value="0, 1, -2"/>
        <float name="radius" value="1"/>
        <bsdf type="null"/>
        <medium type="homogeneous" name="interior">
            <rgb name="sigma_a" value="0.5, 0.5, 0.5"/>
            <rgb name="sigma_s" value="2, 2, 2"/>
            <phase type="hg"><float name="g" value="0.5"/></phase>
        </medium>
    </shape>
</scene>"#;

#[test]
fn instances_in_fog_render_as_the_xml() {
    let xml = scene_from_xml(INSTANCES_IN_FOG_XML, "fog.xml").unwrap();
    let root = prism_mitsuba::pbrt::read_pbrt_str(INSTANCES_IN_FOG_PBRT, Path::new("fog.pbrt"))
        .unwrap()
        .root;
    let pbrt = prism_mitsuba::factory::build_scene(&root).unwrap().scene;
    // 16 blocks × 3 channels: 4.5 standard errors fail a correct translation with probability
    // 3·10⁻⁴; at 256 samples per pixel the area light 10 % dimmer gives 6.8.
    let a = render_film(&xml, 256, 1, None);
    let b = render_film(&pbrt, 256, 2, None);
    let z = largest_block_z(&a, &b, 8);
    assert!(
        z < 4.5,
        "the pbrt and XML images differ by {z:.1} standard errors"
    );
}

/// A white coated sphere in a white furnace: pbrt-v4's `coateddiffuse` over a white base under
/// a smooth coating loses no energy, so the sphere has the environment's radiance.
const COATED_SPHERE_IN_A_FURNACE: &str = r#"
LookAt 0 0 5  0 0 0  0 1 0
Camera "perspective" "float fov" 20
Film "rgb" "integer xresolution" 24 "integer yresolution" 24
Sampler "independent" "integer pixelsamples" 64
Integrator "path" "integer maxdepth" 200
WorldBegin
LightSource "infinite" "rgb L" [1 1 1]
Material "coateddiffuse" "rgb reflectance" [1 1 1] "float thickness" 0.0001
    "integer maxdepth" 100
Shape "sphere" "float radius" 0.8
"#;

#[test]
fn a_white_coated_sphere_vanishes_in_a_white_furnace() {
    let root =
        prism_mitsuba::pbrt::read_pbrt_str(COATED_SPHERE_IN_A_FURNACE, Path::new("furnace.pbrt"))
            .unwrap()
            .root;
    let scene = prism_mitsuba::factory::build_scene(&root).unwrap().scene;
    let film = render_film(&scene, 64, 3, None);
    // Every ray from the corner escapes at once: the environment's radiance, without noise.
    let (background, _) = block_mean(&film, 0, 0, 2, 1);
    assert!(background > 0.5, "background {background}");
    // The 8 × 8 pixels in the middle all see the sphere.
    let (sphere, variance) = block_mean(&film, 8, 8, 8, 1);
    let z = (sphere - background) / variance.sqrt();
    assert!(
        z.abs() < 4.5 && variance.sqrt() < 0.01 * background,
        "the sphere's Y {sphere} ± {} against the environment's {background}",
        variance.sqrt()
    );
}

/// A folder of its own for a test's files.
fn folder(name: &str) -> PathBuf {
    let folder = std::env::temp_dir().join(format!("prism-pbrt-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&folder).unwrap();
    folder
}

/// The error message of loading `text` as `name`, in a folder of its own.
fn error_of(name: &str, text: &str) -> String {
    let folder = folder(name);
    let path = folder.join(format!("{name}.pbrt"));
    std::fs::write(&path, text).unwrap();
    let message = match load_scene(&path, &[]) {
        Ok(_) => panic!("{name}: the scene loaded"),
        Err(error) => error.to_string(),
    };
    std::fs::remove_dir_all(&folder).unwrap();
    message
}

#[test]
fn errors_name_the_file_line_and_column() {
    let cases = [
        (
            "unknown_directive",
            "WorldBegin\n  Shape \"sphere\"\n  Sphere \"float radius\" 2\n",
            "unknown_directive.pbrt:3:3: unknown directive \"Sphere\"",
        ),
        (
            "bad_type",
            "WorldBegin\nShape \"sphere\" \"float radius\" \"two\"\n",
            "bad_type.pbrt:2:31: parameter \"float radius\" expects finite numbers",
        ),
        (
            "wrong_type",
            "WorldBegin\nShape \"sphere\" \"integer radius\" 2\n",
            "wrong_type.pbrt:2:16: Shape \"sphere\": parameter \"integer radius\" must be of type float",
        ),
        (
            "unterminated",
            "WorldBegin\nShape \"sphere\" \"float radius 2\n",
            "unterminated.pbrt:2:16: unterminated string",
        ),
        (
            "missing_include",
            "WorldBegin\n  Include \"geometry/missing.pbrt\"\n",
            "missing_include.pbrt:2:11: file \"geometry/missing.pbrt\" not found",
        ),
        (
            "unsupported_parameter",
            "WorldBegin\nShape \"sphere\" \"float radius\" 1 \"float zmax\" 0.5\n",
            "unsupported_parameter.pbrt:2:33: Shape \"sphere\": parameter \"float zmax\" cuts the shape",
        ),
        (
            "unread_parameter",
            "WorldBegin\nMaterial \"diffuse\" \"float sigma\" 20\n",
            "unread_parameter.pbrt:2:20: Material \"diffuse\": parameter \"float sigma\" is not read by Prism",
        ),
        (
            "dispersive_coating",
            "WorldBegin\nMaterial \"coateddiffuse\" \"spectrum eta\" \"glass-BK7\"\n",
            "dispersive_coating.pbrt:2:26: Material \"coateddiffuse\": parameter \"spectrum eta\" must be a number",
        ),
        (
            "coated_conductor_by_reflectance",
            "WorldBegin\nMaterial \"coatedconductor\" \"rgb reflectance\" [0.9 0.5 0.2]\n",
            "coated_conductor_by_reflectance.pbrt:2:28: Material \"coatedconductor\": parameter \"rgb reflectance\" is not read by Prism",
        ),
    ];
    for (name, text, expected) in cases {
        let message = error_of(name, text);
        assert!(message.contains(expected), "{name}: {message}");
    }
}

#[test]
fn an_error_in_an_included_file_names_that_file() {
    let folder = folder("include");
    std::fs::create_dir_all(folder.join("geometry")).unwrap();
    std::fs::write(
        folder.join("geometry/shapes.pbrt"),
        "# shapes\nShape \"sphere\"\nShape \"curve\"\n",
    )
    .unwrap();
    let path = folder.join("scene.pbrt");
    std::fs::write(&path, "WorldBegin\nInclude \"geometry/shapes.pbrt\"\n").unwrap();
    let message = load_scene(&path, &[]).err().expect("refused").to_string();
    std::fs::remove_dir_all(&folder).unwrap();
    assert!(
        message.contains("shapes.pbrt:3:1: Shape \"curve\": Prism has no shape"),
        "{message}"
    );
}

#[test]
fn the_fuzzing_seeds_are_scenes_that_load() {
    let mut count = 0;
    for entry in std::fs::read_dir("fuzz/seeds/pbrt_scene").unwrap() {
        let path = entry.unwrap().path();
        if let Err(error) = load_scene(&path, &[]) {
            panic!("{}: {error}", path.display());
        }
        count += 1;
    }
    assert!(count >= 2);
}

/// A xorshift generator, for the mutations below.
fn xorshift(state: &mut u64) -> u64 {
    *state ^= *state << 13;
    *state ^= *state >> 7;
    *state ^= *state << 17;
    *state
}

#[test]
fn mutated_scenes_are_read_or_refused_without_a_panic() {
    // The fuzzing target's check on 20,000 fixed mutations of its seeds (cut, deleted and
    // replaced bytes, inserted tokens), so that every test run fuzzes a little.
    let seeds = [
        std::fs::read("fuzz/seeds/pbrt_scene/directives.pbrt").unwrap(),
        std::fs::read("fuzz/seeds/pbrt_scene/cornell.pbrt").unwrap(),
    ];
    let tokens: [&[u8]; 12] = [
        b"\"",
        b"[",
        b"]",
        b"-1",
        b"1e30",
        b"AttributeEnd",
        b"ObjectEnd",
        b"Scale 0 0 0 ",
        b"\"float xradius\" 1",
        b"\"integer xsamples\" 3",
        b"\"blackbody L\" 1",
        b"\"integer indices\" [0 1 9]",
    ];
    let mut state = 12345;
    for i in 0..20_000 {
        let mut data = seeds[i % 2].clone();
        for _ in 0..1 + xorshift(&mut state) % 4 {
            let at = xorshift(&mut state) as usize % (data.len() + 1);
            match xorshift(&mut state) % 4 {
                0 => data.truncate(at),
                1 if at < data.len() => {
                    data.remove(at);
                }
                2 => {
                    let token = tokens[xorshift(&mut state) as usize % tokens.len()];
                    data.splice(at..at, token.iter().copied());
                }
                _ if at < data.len() => data[at] = (xorshift(&mut state) % 128) as u8,
                _ => {}
            }
        }
        let Ok(text) = String::from_utf8(data) else {
            continue;
        };
        let outcome = std::panic::catch_unwind(|| {
            let path = Path::new("/nonexistent-prism-test/scene.pbrt");
            if let Ok(scene) = prism_mitsuba::pbrt::read_pbrt_str(&text, path) {
                let _ = prism_mitsuba::factory::build_scene(&scene.root);
            }
        });
        assert!(outcome.is_ok(), "mutation {i} panics:\n{text}");
    }
}

#[test]
fn spectra_may_be_read_from_files() {
    use prism_mitsuba::description::{PropertyValue, SpectrumValue};
    let folder = folder("spectra");
    std::fs::create_dir_all(folder.join("spds")).unwrap();
    std::fs::write(
        folder.join("spds/lamp.spd"),
        "# a lamp\n400 1\n500 2 # peak\n600 1\n",
    )
    .unwrap();
    std::fs::write(folder.join("spds/bad.spd"), "400 1\n500\n").unwrap();
    let path = folder.join("scene.pbrt");
    let scene = "WorldBegin\nAreaLightSource \"diffuse\" \"spectrum L\" \"spds/lamp.spd\" \"float scale\" 3\nShape \"sphere\"\n";
    let read = prism_mitsuba::pbrt::read_pbrt_str(scene, &path);
    let bad = prism_mitsuba::pbrt::read_pbrt_str(
        "WorldBegin\nLightSource \"point\" \"spectrum I\" \"spds/bad.spd\"\n",
        &path,
    );
    std::fs::remove_dir_all(&folder).unwrap();
    let root = read.unwrap().root;
    let shape = &root.children[2].node;
    let emitter = &shape.children[1].node;
    let PropertyValue::Spectrum(SpectrumValue::Samples(samples)) = &emitter.properties[0].value
    else {
        panic!("{:?}", emitter.properties);
    };
    // The file's shape, scaled to pbrt's luminance: 3 / luminance of the file's samples.
    assert_eq!(samples.len(), 3);
    assert!((samples[1].1 / samples[0].1 - 2.0).abs() < 1e-12);
    let message = bad.err().expect("refused").to_string();
    assert!(
        message.contains("scene.pbrt:2:21:")
            && message.contains("does not hold (wavelength, value) pairs"),
        "{message}"
    );
}

/// A grey square filling an orthographic view under a white sky, its reflectance a `mix` of
/// 0.8 and 0.1 whose `amount` is a `scale` of 0.25 by a checkerboard of 1 and ½: the four
/// quarters of the image reflect 0.75 · 0.8 + 0.25 · 0.1 = 0.625 and
/// 0.875 · 0.8 + 0.125 · 0.1 = 0.7125, on the diagonals.
const MIXED_SQUARE: &str = r#"
LookAt 0 0 -5  0 0 0  0 1 0
Camera "orthographic"
Film "rgb" "integer xresolution" 16 "integer yresolution" 16
PixelFilter "box"
Sampler "independent" "integer pixelsamples" 64
Integrator "path" "integer maxdepth" 1
WorldBegin
LightSource "infinite" "rgb L" [1 1 1]
Texture "checks" "float" "checkerboard" "float tex1" 1 "float tex2" 0.5
    "float uscale" 2 "float vscale" 2
Texture "amount" "float" "scale" "float tex" 0.25 "texture scale" "checks"
Texture "albedo" "spectrum" "mix" "rgb tex1" [0.8 0.8 0.8] "rgb tex2" [0.1 0.1 0.1]
    "texture amount" "amount"
Material "diffuse" "texture reflectance" "albedo"
Shape "trianglemesh" "point3 P" [-1 -1 0  1 -1 0  1 1 0  -1 1 0]
    "point2 uv" [0 0  1 0  1 1  0 1] "integer indices" [0 1 2  0 2 3]
"#;

#[test]
fn scale_and_mix_textures_render_pbrts_values() {
    let root = prism_mitsuba::pbrt::read_pbrt_str(MIXED_SQUARE, Path::new("mixed.pbrt"))
        .unwrap()
        .root;
    let scene = prism_mitsuba::factory::build_scene(&root).unwrap().scene;
    let film = render_film(&scene, 64, 4, None);
    // A diffuse surface under a uniform sky of luminance 1 has the luminance of its
    // reflectance; the sky is sampled over the whole sphere, so the estimate is noisy.
    let quarter = |x0: usize, y0: usize| block_mean(&film, x0, y0, 8, 1);
    let z = |(mean, variance): (f64, f64), expected: f64| (mean - expected) / variance.sqrt();
    let (a, b) = (quarter(0, 0), quarter(8, 0));
    let (first, second) = if a.0 < b.0 {
        (0.625, 0.7125)
    } else {
        (0.7125, 0.625)
    };
    // 4 quarters: 4 standard errors fail a correct texture with probability 2.5·10⁻⁴; the
    // two values differ by more than 20 standard errors.
    for (value, expected) in [
        (a, first),
        (quarter(8, 8), first),
        (b, second),
        (quarter(0, 8), second),
    ] {
        assert!(
            z(value, expected).abs() < 4.0 && z(value, 0.7125 + 0.625 - expected).abs() > 8.0,
            "a quarter's Y {} ± {} where {expected} is expected",
            value.0,
            value.1.sqrt()
        );
    }
}

/// A diffuse square in the plane x = 0 (normal ±x), seen from +x under a uniform sky of
/// luminance 1, whose reflectance is the spectrum texture `texture` (named "r") defined after
/// `transform`.
fn textured_square(transform: &str, texture: &str) -> String {
    format!(
        r#"
LookAt 5 0 0  0 0 0  0 1 0
Camera "orthographic"
Film "rgb" "integer xresolution" 8 "integer yresolution" 8
PixelFilter "box"
Sampler "independent" "integer pixelsamples" 64
Integrator "path" "integer maxdepth" 1
WorldBegin
LightSource "infinite" "rgb L" [1 1 1]
AttributeBegin
{transform}
{texture}
AttributeEnd
Material "diffuse" "texture reflectance" "r"
Shape "trianglemesh" "point3 P" [0 -2 -2  0 2 -2  0 2 2  0 -2 2] "integer indices" [0 1 2  0 2 3]
"#
    )
}

#[test]
fn a_direction_mix_renders_the_blend_of_the_normals_angle() {
    // Under a uniform sky of luminance 1 a diffuse surface has the luminance of its
    // reflectance, here a · 0.8 + (1 − a) · 0.2 with a = |n · dir| and n = ±x.
    let mix = |dir: &str| {
        format!(
            "Texture \"r\" \"spectrum\" \"directionmix\" \"rgb tex1\" [0.8 0.8 0.8] \"rgb tex2\" [0.2 0.2 0.2] {dir}"
        )
    };
    let cases = [
        ("", mix("\"vector3 dir\" [-3 0 0]"), 1.0),
        ("", mix(""), 0.0),
        ("", mix("\"vector3 dir\" [1 1 0]"), 0.5_f64.sqrt()),
        // (1, 0, 0) turned by 60° about z: a = cos 60°.
        ("Rotate 60 0 0 1", mix("\"vector3 dir\" [1 0 0]"), 0.5),
        // (0, 1, 0) taken to (1, 3, 0) (pbrt lists the matrix by columns): a = 1/√10.
        (
            "Transform [1 0 0 0  1 3 0 0  0 0 1 0  0 0 0 1]",
            mix(""),
            0.1_f64.sqrt(),
        ),
    ];
    let path = Path::new("directionmix.pbrt");
    for (k, (transform, texture, amount)) in cases.iter().enumerate() {
        let root = prism_mitsuba::pbrt::read_pbrt_str(&textured_square(transform, texture), path)
            .unwrap_or_else(|e| panic!("{texture}: {e}"))
            .root;
        let scene = prism_mitsuba::factory::build_scene(&root).unwrap().scene;
        let film = render_film(&scene, 64, 20 + k as u64, None);
        let (mean, variance) = block_mean(&film, 0, 0, 8, 1);
        let expected = amount * 0.8 + (1.0 - amount) * 0.2;
        // 5 estimates: 4.5 standard errors fail a correct texture with probability 3·10⁻⁵;
        // the standard error is below a tenth of the smallest step between the cases (0.05).
        let z = (mean - expected) / variance.sqrt();
        assert!(
            z.abs() < 4.5 && variance.sqrt() < 0.005,
            "{transform} {texture}: Y {mean} ± {} where {expected} is expected",
            variance.sqrt()
        );
    }
}

/// A grey square (reflectance ½) in the plane x = 0, seen from +x, under pbrt's image infinite
/// light `light` (an equal-area map, scale 2), in an orthographic view that it fills.
fn square_under_sky(light: &str) -> String {
    format!(
        r#"
LookAt 5 0 0  0 0 0  0 1 0
Camera "orthographic"
Film "rgb" "integer xresolution" 8 "integer yresolution" 8
PixelFilter "box"
Sampler "independent" "integer pixelsamples" 64
Integrator "path" "integer maxdepth" 1
WorldBegin
AttributeBegin
{light}
AttributeEnd
Material "diffuse" "rgb reflectance" [0.5 0.5 0.5]
Shape "trianglemesh" "point3 P" [0 -2 -2  0 2 -2  0 2 2  0 -2 2] "integer indices" [0 1 2  0 2 3]
"#
    )
}

#[test]
fn image_infinite_lights_are_equal_area_maps_in_pbrts_orientation() {
    // White and black halves of a 16 × 16 map: the right half (u > ½) is the hemisphere
    // x > 0 and the lower half (v > ½, the image's lower rows) y > 0; and a white map.
    let folder = folder("sky");
    let n = 16;
    let write = |name: &str, white: &dyn Fn(usize, usize) -> bool| {
        let rgb: Vec<f32> = (0..n * n)
            .flat_map(|i| [if white(i % n, i / n) { 1.0 } else { 0.0 }; 3])
            .collect();
        prism_core::image::write_png_srgb(&folder.join(name), n, n, &rgb).unwrap();
    };
    write("right.png", &|x, _| x >= n / 2);
    write("lower.png", &|_, y| y >= n / 2);
    write("white.png", &|_, _| true);
    let image = |name: &str, rotation: &str| {
        format!(
            "{rotation}\nLightSource \"infinite\" \"string filename\" \"{name}\" \"float scale\" 2"
        )
    };
    // The square facing +x has the luminance ½ · 2 · (1/π) ∫ cos θ dω over its white
    // directions: 1 for the whole hemisphere x > 0, ½ for its half with y > 0.
    let cases = [
        (image("right.png", ""), 1.0),
        (image("right.png", "Rotate 180 0 1 0"), 0.0),
        (image("right.png", "Rotate 90 0 0 1"), 0.5),
        (image("lower.png", ""), 0.5),
        (image("lower.png", "Rotate -90 0 0 1"), 1.0),
        (image("white.png", "Rotate 30 1 1 0"), 1.0),
        // The uniform light of the same colour: pbrt-v4's constant map.
        (
            "LightSource \"infinite\" \"rgb L\" [1 1 1] \"float scale\" 2".to_string(),
            1.0,
        ),
    ];
    let path = folder.join("sky.pbrt");
    let renders: Vec<(f64, f64)> = cases
        .iter()
        .enumerate()
        .map(|(k, (light, _))| {
            let root = prism_mitsuba::pbrt::read_pbrt_str(&square_under_sky(light), &path)
                .unwrap_or_else(|e| panic!("{light}: {e}"))
                .root;
            let scene = prism_mitsuba::factory::build_scene(&root).unwrap().scene;
            let film = render_film(&scene, 64, 10 + k as u64, None);
            block_mean(&film, 0, 0, 8, 1)
        })
        .collect();
    let stretched = prism_mitsuba::pbrt::read_pbrt_str(
        &square_under_sky(&image("white.png", "Scale 2 1 1")),
        &path,
    )
    .map(|scene| prism_mitsuba::factory::build_scene(&scene.root).map(|_| ()));
    let not_square = {
        let rgb = vec![1.0; 3 * 2 * n * n];
        prism_core::image::write_png_srgb(&folder.join("wide.png"), 2 * n, n, &rgb).unwrap();
        prism_mitsuba::pbrt::read_pbrt_str(&square_under_sky(&image("wide.png", "")), &path)
            .map(|scene| prism_mitsuba::factory::build_scene(&scene.root).map(|_| ()))
    };
    std::fs::remove_dir_all(&folder).unwrap();
    // 6 noisy estimates: 4.5 standard errors fail a correct light with probability 4·10⁻⁵;
    // the black hemisphere gives exactly nothing.
    for ((light, expected), (mean, variance)) in cases.iter().zip(&renders) {
        if *expected == 0.0 {
            assert_eq!(*mean, 0.0, "{light}");
            continue;
        }
        let z = (mean - expected) / variance.sqrt();
        assert!(
            z.abs() < 4.5 && variance.sqrt() < 0.05 * expected,
            "{light}: Y {mean} ± {} where {expected} is expected",
            variance.sqrt()
        );
    }
    let message = stretched.unwrap().expect_err("refused").to_string();
    assert!(
        message.contains("sky.pbrt:11:1:") && message.contains("stretches directions"),
        "{message}"
    );
    let message = not_square.unwrap().expect_err("refused").to_string();
    assert!(
        message.contains("sky.pbrt:11:") && message.contains("an equal-area map is square"),
        "{message}"
    );
}

/// A ball of fog lit by a sky and a lamp, its medium given by `medium` (named "fog").
fn fog_ball(medium: &str) -> String {
    format!(
        r#"
LookAt 0 0 -4  0 0 0  0 1 0
Camera "perspective" "float fov" 40
Film "rgb" "integer xresolution" 24 "integer yresolution" 24
PixelFilter "box"
Sampler "independent" "integer pixelsamples" 128
Integrator "volpath" "integer maxdepth" 8
WorldBegin
LightSource "infinite" "rgb L" [0.2 0.25 0.3]
LightSource "point" "rgb I" [20 18 15] "point3 from" [2 3 -2]
{medium}
AttributeBegin
    MediumInterface "fog" ""
    Material "interface"
    Shape "sphere" "float radius" 1
AttributeEnd
"#
    )
}

/// Coloured σ_a and σ_s, which pbrt's grid medium scales by the density.
#[test]
fn a_constant_uniform_grid_renders_as_a_homogeneous_medium() {
    // A grid of 8³ voxels over [−1.5, 1.5]³: the ball lies more than half a voxel inside its
    // faces, where pbrt's density is the voxels' value.
    let grid = |density: f64| {
        let values = vec![density.to_string(); 512].join(" ");
        format!(
            "MakeNamedMedium \"fog\" \"string type\" \"uniformgrid\" \"integer nx\" 8 \"integer ny\" 8 \"integer nz\" 8 \"float density\" [{values}] \"point3 p0\" [-1.5 -1.5 -1.5] \"point3 p1\" [1.5 1.5 1.5] \"rgb sigma_a\" [0.6 0.3 0.1] \"rgb sigma_s\" [0.4 0.9 1.6] \"float scale\" 2 \"float g\" 0.3"
        )
    };
    let homogeneous = "MakeNamedMedium \"fog\" \"string type\" \"homogeneous\" \"rgb sigma_a\" [0.6 0.3 0.1] \"rgb sigma_s\" [0.4 0.9 1.6] \"float scale\" 2 \"float g\" 0.3";
    let render = |medium: &str, seed: u64| {
        let root = prism_mitsuba::pbrt::read_pbrt_str(&fog_ball(medium), Path::new("fog.pbrt"))
            .unwrap()
            .root;
        let scene = prism_mitsuba::factory::build_scene(&root).unwrap().scene;
        render_film(&scene, 128, seed, None)
    };
    let reference = render(homogeneous, 1);
    // 9 blocks × 3 channels: 4.5 standard errors fail a correct translation with probability
    // 2·10⁻⁴.
    let z = largest_block_z(&reference, &render(&grid(1.0), 2), 8);
    assert!(
        z < 4.5,
        "the grid and the homogeneous medium differ by {z:.1} standard errors"
    );
    // The test can fail: a grid of half the density is told apart.
    let z = largest_block_z(&reference, &render(&grid(0.5), 3), 8);
    assert!(
        z > 8.0,
        "half the density differs by only {z:.1} standard errors"
    );
}

/// A ball of radius 1 filled with pbrt's grid medium of density `density` (8³ voxels over
/// [−1.5, 1.5]³), σ_a = 0 and the colour `sigma_s`, lit from above by a distant light; in pbrt-v4's
/// format, and in Mitsuba 3's with the colour grid `sigma_t` = d · `sigma_s` in a `.vol` file
/// named `grid` and albedo 1.
fn lit_fog(density: &[f32], sigma_s: [f32; 3], grid: &str) -> (String, String) {
    let values: Vec<String> = density.iter().map(|d| d.to_string()).collect();
    let [r, g, b] = sigma_s;
    let pbrt = format!(
        r#"
LookAt 0 0 -4  0 0 0  0 1 0
Camera "perspective" "float fov" 40
Film "rgb" "integer xresolution" 16 "integer yresolution" 16
PixelFilter "box"
Sampler "independent" "integer pixelsamples" 64
Integrator "volpath" "integer maxdepth" 8
WorldBegin
LightSource "distant" "point3 from" [0 4 0] "point3 to" [0 0 0] "rgb L" [3 3 3]
MakeNamedMedium "fog" "string type" "uniformgrid" "integer nx" 8 "integer ny" 8 "integer nz" 8 "float density" [{}] "point3 p0" [-1.5 -1.5 -1.5] "point3 p1" [1.5 1.5 1.5] "rgb sigma_a" [0 0 0] "rgb sigma_s" [{r} {g} {b}]
AttributeBegin
    MediumInterface "fog" ""
    Material "interface"
    Shape "sphere" "float radius" 1
AttributeEnd
"#,
        values.join(" ")
    );
    let xml = format!(
        r#"<scene version="3.0.0">
    <integrator type="volpath"><integer name="max_depth" value="9"/></integrator>
    <sensor type="perspective">
        <float name="fov" value="40"/>
        <transform name="to_world"><lookat origin="0, 0, -4" target="0, 0, 0" up="0, 1, 0"/></transform>
        <film type="hdrfilm"><integer name="width" value="16"/><integer name="height" value="16"/><rfilter type="box"/></film>
    </sensor>
    <emitter type="directional">
        <vector name="direction" x="0" y="-1" z="0"/>
        <rgb name="irradiance" value="3"/>
    </emitter>
    <shape type="sphere">
        <bsdf type="null"/>
        <medium type="heterogeneous" name="interior">
            <volume type="gridvolume" name="sigma_t">
                <string name="filename" value="{grid}"/>
                <transform name="to_world"><scale value="3"/><translate x="-1.5" y="-1.5" z="-1.5"/></transform>
            </volume>
            <float name="albedo" value="1"/>
        </medium>
    </shape>
</scene>"#
    );
    (pbrt, xml)
}

/// Mitsuba's `.vol` file of the colour grid d · `rgb` (8³ voxels, x fastest).
fn colour_vol(density: &[f32], rgb: [f32; 3]) -> Vec<u8> {
    let mut vol = b"VOL\x03".to_vec();
    for v in [1i32, 8, 8, 8, 3] {
        vol.extend(v.to_le_bytes());
    }
    for v in [-1.5f32, -1.5, -1.5, 1.5, 1.5, 1.5] {
        vol.extend(v.to_le_bytes());
    }
    for d in density {
        for c in rgb {
            vol.extend((d * c).to_le_bytes());
        }
    }
    vol
}

#[test]
fn a_coloured_uniform_grid_renders_as_mitsubas_colour_grid() {
    // A density between 0.3 and 1.5 everywhere: a colour grid of one chromaticity upsamples to
    // that colour's spectrum times the density (Mitsuba 3 interpolates the voxels' spectra and
    // scales separately, which agree where no voxel is black), pbrt's σ_s(λ) d(p).
    let density: Vec<f32> = (0..512)
        .map(|i| 0.3 + 1.2 * ((i * 37 % 17) as f32 / 16.0))
        .collect();
    let sigma_s = [0.4, 1.0, 2.2];
    let folder = folder("colour-grid");
    std::fs::write(folder.join("fog.vol"), colour_vol(&density, sigma_s)).unwrap();
    let render = |text: &str, pbrt: bool, seed: u64| {
        let scene = if pbrt {
            let root = prism_mitsuba::pbrt::read_pbrt_str(text, &folder.join("fog.pbrt"))
                .unwrap()
                .root;
            prism_mitsuba::factory::build_scene(&root).unwrap().scene
        } else {
            scene_from_xml(text, folder.join("fog.xml").to_str().unwrap()).unwrap()
        };
        render_film(&scene, 512, seed, None)
    };
    let (pbrt, xml) = lit_fog(&density, sigma_s, "fog.vol");
    let reference = render(&xml, false, 1);
    let pbrt_film = render(&pbrt, true, 2);
    // The other colour order, which the comparison must tell apart.
    let (swapped, _) = lit_fog(&density, [2.2, 1.0, 0.4], "fog.vol");
    let swapped_film = render(&swapped, true, 3);
    std::fs::remove_dir_all(&folder).unwrap();
    // pbrt's camera sees the world mirrored left to right against Mitsuba's with the same
    // `LookAt`, so the images' means are compared: X, Y and Z, 4.5 standard errors (a false
    // alarm with probability 2·10⁻⁵).
    let largest_z = |film: &Film| {
        (0..3)
            .map(|c| {
                let (a, sa) = image_mean_and_standard_error(&reference, c);
                let (b, sb) = image_mean_and_standard_error(film, c);
                (a - b).abs() / (sa * sa + sb * sb).sqrt()
            })
            .fold(0.0, f64::max)
    };
    let z = largest_z(&pbrt_film);
    assert!(
        z < 4.5,
        "pbrt's grid and Mitsuba's differ by {z:.1} standard errors"
    );
    let z = largest_z(&swapped_film);
    assert!(
        z > 8.0,
        "the other colour order differs by only {z:.1} standard errors"
    );
    // Mitsuba 3.9.1's image means of the XML scene (`scalar_spectral`, 32 × 32 pixels, whose
    // box-filtered mean is the 16 × 16 image's; two renders of 1024 spp, seeds 11 and 12, their
    // RGB taken to XYZ by the sRGB matrix; the standard errors from the two renders' difference).
    let mitsuba = [
        (0.052237, 0.000075),
        (0.058552, 0.000068),
        (0.083536, 0.000274),
    ];
    for (c, (expected, se)) in mitsuba.into_iter().enumerate() {
        let (mean, prism_se) = image_mean_and_standard_error(&reference, c);
        let z = (mean - expected) / prism_se.hypot(se);
        assert!(
            z.abs() < 4.5,
            "channel {c}: Prism {mean} ± {prism_se}, Mitsuba {expected} ± {se} ({z:.1} standard errors)"
        );
    }
}

/// pbrt-v4 reads a medium's RGB σ_a and σ_s as unbounded spectra (2·max(rgb) times the spectrum
/// fitted to rgb / (2·max(rgb))), also where every component is at most 1, which Prism's XML
/// reads as a reflectance: the reader gives the medium pbrt's spectrum.
#[test]
fn medium_coefficients_are_pbrts_unbounded_spectra() {
    use glam::Vec3;
    use prism_core::spectrum::{RgbIntent, SampledWavelengths, Spectrum, WavelengthSampling};
    let (sigma_a, sigma_s) = ([0.05f32, 0.1, 0.3], [0.2f32, 0.5, 0.9]);
    let medium = format!(
        "MakeNamedMedium \"fog\" \"string type\" \"homogeneous\" \"rgb sigma_a\" [{} {} {}] \"rgb sigma_s\" [{} {} {}] \"float scale\" 2",
        sigma_a[0], sigma_a[1], sigma_a[2], sigma_s[0], sigma_s[1], sigma_s[2]
    );
    let root = prism_mitsuba::pbrt::read_pbrt_str(&fog_ball(&medium), Path::new("fog.pbrt"))
        .unwrap()
        .root;
    let scene = prism_mitsuba::factory::build_scene(&root).unwrap().scene;
    let fog = &scene.world.media[0];
    let unbounded = |rgb| Spectrum::from_rgb(rgb, RgbIntent::Unbounded);
    let albedo = |rgb| Spectrum::from_rgb(rgb, RgbIntent::Albedo);
    let mut largest_albedo_difference = 0.0f32;
    for u in [0.05, 0.3, 0.55, 0.8] {
        let lambda = SampledWavelengths::sample(u, WavelengthSampling::Uniform);
        let c = fog.coefficients(Vec3::ZERO, Vec3::Z, &lambda);
        for i in 0..4 {
            let l = lambda.lambda(i);
            let (a, s) = (unbounded(sigma_a).value(l), unbounded(sigma_s).value(l));
            let expected = [2.0 * (a + s), 2.0 * s];
            for (got, want) in [c.sigma_t[i], c.sigma_s[i]].into_iter().zip(expected) {
                assert!(
                    (got - want).abs() <= 2e-3 * want,
                    "at {l} nm: {got} against pbrt's {want}"
                );
            }
            let reflectance = albedo(sigma_s).value(l);
            largest_albedo_difference = largest_albedo_difference.max((reflectance - s).abs() / s);
        }
    }
    // The test can fail: read as reflectances, the coefficients would differ.
    assert!(
        largest_albedo_difference > 0.05,
        "the two upsamplings differ by only {largest_albedo_difference}"
    );
}
