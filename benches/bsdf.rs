//! BSDF queries per second: the lobes at a point (textures evaluated) followed by `sample`
//! (choose a lobe, draw a direction, return weight and pdf) or by `eval` (value and pdf
//! together, what next-event estimation asks of the BSDF for a light sample's direction), for
//! the materials a path tracer meets most: diffuse, the GGX
//! microfacet models at α = 0.3 (roughconductor with gold's spectral indices, roughdielectric,
//! roughplastic) and the smooth dielectric and plastic, whose delta lobes are only sampled.
//!
//! The BSDFs are built from Mitsuba XML by the scene factory, as a scene file would make them.
//! Each benchmark runs over a fixed, seeded set of 4,096 queries (wavelengths drawn as a path
//! draws them, random numbers, `wo` cosine-distributed over the upper hemisphere and, for
//! transmitting BSDFs, mirrored to the lower one for every second query, as paths inside glass
//! see it; `wi` for `eval` uniform over the sphere for transmitting BSDFs and over the upper
//! hemisphere for reflecting ones). Criterion reports queries (elements) per second.

mod common;

use std::hint::black_box;
use std::path::Path;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use glam::{Vec2, Vec3};
use prism_core::bsdf::{Bsdf, BsdfFlags, BsdfModel, BxdfTree, Scattering, ShadingPoint};
use prism_core::sampling::rng::Pcg32;
use prism_core::sampling::warp::{sample_cosine_hemisphere, sample_uniform_sphere};
use prism_core::spectrum::{SampledWavelengths, WavelengthSampling};
use prism_mitsuba::description::PluginClass;
use prism_mitsuba::factory::materials::build_bsdf;
use prism_mitsuba::factory::textures::TextureCache;
use prism_mitsuba::reader::read_scene_str;

/// Queries per iteration.
const QUERIES: usize = 4096;

/// The benchmarked BSDFs: a name and the `<bsdf>` element that describes it.
const BSDFS: [(&str, &str); 6] = [
    (
        "diffuse",
        r#"<bsdf type="diffuse"><rgb name="reflectance" value="0.8, 0.4, 0.1"/></bsdf>"#,
    ),
    (
        "roughconductor",
        r#"<bsdf type="roughconductor"><string name="material" value="Au"/>
            <string name="distribution" value="ggx"/><float name="alpha" value="0.3"/></bsdf>"#,
    ),
    (
        "roughdielectric",
        r#"<bsdf type="roughdielectric"><string name="distribution" value="ggx"/>
            <float name="alpha" value="0.3"/><float name="int_ior" value="1.5"/></bsdf>"#,
    ),
    (
        "roughplastic",
        r#"<bsdf type="roughplastic"><string name="distribution" value="ggx"/>
            <float name="alpha" value="0.3"/>
            <rgb name="diffuse_reflectance" value="0.7, 0.3, 0.1"/></bsdf>"#,
    ),
    ("dielectric", r#"<bsdf type="dielectric"/>"#),
    (
        "plastic",
        r#"<bsdf type="plastic"><rgb name="diffuse_reflectance" value="0.2, 0.6, 0.9"/></bsdf>"#,
    ),
];

/// The BSDF a `<bsdf>` element describes, built by the scene factory.
fn bsdf_from_xml(xml: &str) -> Bsdf {
    let text = format!(r#"<scene version="3.0.0">{xml}</scene>"#);
    let root = read_scene_str(&text, Path::new("bench.xml"), &[]).unwrap_or_else(|e| panic!("{e}"));
    let node = &root
        .children
        .iter()
        .find(|c| c.node.class == PluginClass::Bsdf)
        .expect("the XML declares a <bsdf>")
        .node;
    build_bsdf(node, &mut TextureCache::default()).unwrap_or_else(|e| panic!("{e}"))
}

/// The inputs of one `sample` and one `eval`/`pdf` call.
struct Query {
    lambda: SampledWavelengths,
    wo: Vec3,
    wi: Vec3,
    u_lobe: f32,
    u: Vec2,
}

fn queries(transmits: bool) -> Vec<Query> {
    let mut rng = Pcg32::seeded(11);
    let u2 = |rng: &mut Pcg32| Vec2::new(rng.next_f32(), rng.next_f32());
    (0..QUERIES)
        .map(|i| {
            let mut wo = sample_cosine_hemisphere(u2(&mut rng));
            let mut wi = sample_uniform_sphere(u2(&mut rng));
            if transmits {
                if i % 2 == 1 {
                    wo.z = -wo.z;
                }
            } else {
                wi.z = wi.z.abs();
            }
            Query {
                lambda: SampledWavelengths::sample(rng.next_f32(), WavelengthSampling::CieSum),
                wo,
                wi,
                u_lobe: rng.next_f32(),
                u: u2(&mut rng),
            }
        })
        .collect()
}

fn bsdfs(c: &mut Criterion) {
    let sp = ShadingPoint::local(Vec2::new(0.3, 0.6));
    for (name, xml) in BSDFS {
        let bsdf = bsdf_from_xml(xml);
        let queries = queries(bsdf.flags().contains(BsdfFlags::TRANSMISSION));
        let mut group = c.benchmark_group(format!("bsdf/{name}"));
        group.throughput(Throughput::Elements(QUERIES as u64));
        group.bench_function("sample", |b| {
            b.iter(|| {
                for q in &queries {
                    let mut lobes = BxdfTree::empty();
                    let scattering = Scattering::new(&bsdf, &sp, q.wo, &q.lambda, &mut lobes);
                    black_box(scattering.sample(q.u_lobe, q.u));
                }
            });
        });
        // Delta lobes have nothing to evaluate.
        if bsdf.flags().has_smooth_lobe() {
            group.bench_function("eval_pdf", |b| {
                b.iter(|| {
                    for q in &queries {
                        let mut lobes = BxdfTree::empty();
                        let scattering = Scattering::new(&bsdf, &sp, q.wo, &q.lambda, &mut lobes);
                        black_box(scattering.eval(q.wi));
                    }
                });
            });
        }
        group.finish();
    }
}

criterion_group! {
    name = benches;
    config = common::criterion()
        .sample_size(50);
    targets = bsdfs
}
criterion_main!(benches);
