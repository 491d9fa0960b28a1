//! Light samples per second: for each kind of light, a point on it (or a direction) sampled from
//! a shading point, with the radiance arriving and the density, as next-event estimation asks
//! for them; and the whole step the path integrator takes, choosing one light of the scene by
//! power (the alias table) and sampling it.
//!
//! The lights, built from Mitsuba XML by the scene factory:
//! - `sphere`: a spherical area light, sampled by the cone it subtends;
//! - `rectangle`: a rectangular area light (two triangles), sampled by area;
//! - `mesh`: an emitting cube (twelve triangles), a triangle chosen by area, then a point on it;
//! - `point`: a point light (a delta: no random numbers);
//! - `envmap`: a 512 × 256 environment map of a sky with a small bright sun, sampled ∝ luminance
//!   · sin θ through its marginal and conditional distributions;
//! - `select_and_sample`: one of all five chosen by power, then sampled.
//!
//! Each benchmark runs over a fixed, seeded set of 4,096 shading points on the floor below the
//! lights, with wavelengths and random numbers; Criterion reports samples (elements) per second.

mod common;

use std::hint::black_box;
use std::path::Path;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use glam::{Vec2, Vec3};
use prism_core::geometry::{Primitive, Shape};
use prism_core::image::{ChannelImage, write_exr};
use prism_core::light::{Light, LightQuery, LightSource, Receiver};
use prism_core::sampling::rng::Pcg32;
use prism_core::scene::Scene;
use prism_core::spectrum::{SampledWavelengths, WavelengthSampling};
use prism_mitsuba::factory::build_scene;
use prism_mitsuba::reader::read_scene_str;

/// Samples per iteration.
const POINTS: usize = 4096;

/// The lights above a floor at y = 0; `sky.exr` is written beside the (virtual) scene file.
const SCENE: &str = r#"<scene version="3.0.0">
    <sensor type="perspective"><film type="hdrfilm">
        <integer name="width" value="4"/><integer name="height" value="4"/>
    </film></sensor>
    <shape type="sphere">
        <point name="center" x="0" y="3" z="0"/><float name="radius" value="0.5"/>
        <emitter type="area"><rgb name="radiance" value="10"/></emitter>
    </shape>
    <shape type="rectangle">
        <transform name="to_world">
            <scale value="0.5"/><rotate x="1" angle="90"/><translate x="2" y="3"/>
        </transform>
        <emitter type="area"><rgb name="radiance" value="10"/></emitter>
    </shape>
    <shape type="cube">
        <transform name="to_world"><scale value="0.3"/><translate x="-2" y="3"/></transform>
        <emitter type="area"><rgb name="radiance" value="10"/></emitter>
    </shape>
    <emitter type="point">
        <point name="position" x="0" y="4" z="2"/><rgb name="intensity" value="10"/>
    </emitter>
    <emitter type="envmap"><string name="filename" value="sky.exr"/></emitter>
</scene>"#;

/// Writes the sky: a blue gradient, brighter towards the zenith (the image's top rows), and a
/// sun of radiance 10⁴ a few pixels wide, 30° above the horizon.
fn write_sky(path: &Path) {
    let (width, height) = (512, 256);
    let mut channels = [Vec::new(), Vec::new(), Vec::new()];
    for y in 0..height {
        for x in 0..width {
            let up = 1.0 - y as f32 / height as f32;
            let sun = (x as i32 - 128).abs() < 3 && (y as i32 - 85).abs() < 3;
            let rgb = if sun {
                [1e4; 3]
            } else {
                [0.2 + 0.3 * up, 0.4 + 0.4 * up, 0.8 + 0.6 * up]
            };
            for (channel, value) in channels.iter_mut().zip(rgb) {
                channel.push(value);
            }
        }
    }
    let [r, g, b] = channels;
    let image = ChannelImage {
        width,
        height,
        channels: vec![("R".into(), r), ("G".into(), g), ("B".into(), b)],
    };
    write_exr(path, &image).unwrap_or_else(|e| panic!("{e}"));
}

fn load_scene() -> Scene {
    let folder = Path::new(env!("CARGO_MANIFEST_DIR")).join("target/bench-scenes");
    std::fs::create_dir_all(&folder).expect("create target/bench-scenes");
    write_sky(&folder.join("sky.exr"));
    let root =
        read_scene_str(SCENE, &folder.join("lights.xml"), &[]).unwrap_or_else(|e| panic!("{e}"));
    build_scene(&root).unwrap_or_else(|e| panic!("{e}")).scene
}

/// The benchmark's name for a light of the scene.
fn kind(scene: &Scene, light: &Light) -> &'static str {
    match light {
        Light::Area(area) => match &scene.world.geometry.primitives[area.shape as usize] {
            Primitive::Shape(Shape::Sphere(_)) => "sphere",
            Primitive::Shape(Shape::Mesh(mesh)) if mesh.triangles().len() == 2 => "rectangle",
            _ => "mesh",
        },
        Light::Point(_) => "point",
        Light::Envmap(_) => "envmap",
        _ => unreachable!("the scene declares no other lights"),
    }
}

/// A shading point and the random numbers of one light sample there.
struct Query {
    p: Vec3,
    lambda: SampledWavelengths,
    u_light: f32,
    u_choice: f32,
    u: Vec2,
}

impl Query {
    /// What a light is asked for this sample, at time 0 among the scene's `shapes`.
    fn light_query<'a>(&'a self, shapes: &'a [Primitive]) -> LightQuery<'a> {
        LightQuery {
            shapes,
            reference: self.p,
            time: 0.0,
            u_choice: self.u_choice,
            u: self.u,
            lambda: &self.lambda,
        }
    }
}

fn queries() -> Vec<Query> {
    let mut rng = Pcg32::seeded(5);
    (0..POINTS)
        .map(|_| Query {
            p: Vec3::new(6.0 * rng.next_f32() - 3.0, 0.0, 6.0 * rng.next_f32() - 3.0),
            lambda: SampledWavelengths::sample(rng.next_f32(), WavelengthSampling::CieSum),
            u_light: rng.next_f32(),
            u_choice: rng.next_f32(),
            u: Vec2::new(rng.next_f32(), rng.next_f32()),
        })
        .collect()
}

fn lights(c: &mut Criterion) {
    let scene = load_scene();
    let integrator = scene.integrator.prepare(&scene.world);
    let light_sampler = integrator.light_sampler();
    let queries = queries();
    let shapes = &scene.world.geometry.primitives;
    let mut group = c.benchmark_group("lights");
    group.throughput(Throughput::Elements(POINTS as u64));
    for light in &scene.world.lights {
        group.bench_function(kind(&scene, light), |b| {
            b.iter(|| {
                for q in &queries {
                    black_box(light.sample_incident(q.light_query(shapes)));
                }
            });
        });
    }
    group.bench_function("select_and_sample", |b| {
        b.iter(|| {
            for q in &queries {
                if let Some((index, pmf)) = light_sampler.sample(q.u_light, &Receiver::point(q.p)) {
                    let light = &scene.world.lights[index];
                    black_box(pmf);
                    black_box(light.sample_incident(q.light_query(shapes)));
                }
            }
        });
    });
    group.finish();
}

criterion_group! {
    name = benches;
    config = common::criterion()
        .sample_size(50);
    targets = lights
}
criterion_main!(benches);
