//! Area emitters whose radiance is a texture: the sampled density (docs/testing.md, chi-square
//! tests) on a mesh whose uv layout does not preserve area and on a sphere lit from inside, the
//! density claimed for light samples and for points found by rays (the multiple importance sampling
//! weight), the emitted flux against its closed form (also where the texture strategy cannot reach
//! part of the surface), and the inverse uv maps of spheres and disks.
//!
//! The mesh is two quads side by side in the z = 0 plane, facing +z: quad A is [0, 1] × [0, 1]
//! with texture coordinates [0, ½] × [0, 1] (area per unit uv area J = 2), quad B is
//! [1, 4] × [0, 1] with [½, 1] × [0, 1] (J = 6), so that a density over uv is halved on A and
//! divided by 6 on B when it becomes one over area. The texture is a 2 × 2 grey image of nearest
//! texels, whose boundaries (u, v = ½) coincide with the quads' seam: every density here is
//! constant within cells of a grid of quarters in uv.

use std::sync::Arc;

use glam::{Vec2, Vec3};
use prism_core::geometry::triangle::{TriangleHit, WatertightRay};
use prism_core::geometry::{
    Disk, Primitive, Shape, ShapeGeometry, Sphere, SurfaceInteraction, SurfaceSample, TriangleMesh,
};
use prism_core::image::{Bitmap, Encoding};
use prism_core::light::area::SHAPE_STRATEGY_FRACTION;
use prism_core::light::{AreaLight, Light, LightQuery, LightSource};
use prism_core::math::{Ray, Transform};
use prism_core::sampling::chi2::{Suite, chi2_discrete};
use prism_core::sampling::rng::Pcg32;
use prism_core::spectrum::SampledWavelengths;
use prism_core::texture::{BitmapTexture, FilterType, Texture, TextureUse, UvTransform, WrapMode};

/// The chi-square tests of this module, one name per statistic: the suite of Šidák's correction.
const SUITE: Suite = Suite::new(&[
    "textured area light over uv",
    "textured sphere light over uv",
]);
const SAMPLES: usize = 1_000_000;

/// The texels (row-major, row 0 at v < ½): one black, one brighter than 1.
const TEXELS: [f32; 4] = [0.5, 4.0, 0.0, 1.5];

/// A quad [x0, x1] × [0, 1] at z = 0 with texture coordinates [u0, u1] × [0, 1].
struct Quad {
    x: (f32, f32),
    u: (f32, f32),
}

impl Quad {
    fn area(&self) -> f32 {
        self.x.1 - self.x.0
    }

    fn jacobian(&self) -> f32 {
        self.area() / (self.u.1 - self.u.0)
    }

    /// The texture coordinates of the point at `x` on the quad.
    fn u_at(&self, x: f32) -> f32 {
        self.u.0 + (x - self.x.0) / (self.x.1 - self.x.0) * (self.u.1 - self.u.0)
    }
}

const QUAD_A: Quad = Quad {
    x: (0.0, 1.0),
    u: (0.0, 0.5),
};
const QUAD_B: Quad = Quad {
    x: (1.0, 4.0),
    u: (0.5, 1.0),
};

/// The mesh of two quads, two triangles each (counter-clockwise seen from +z).
fn mesh(quads: &[Quad]) -> TriangleMesh {
    let mut positions = Vec::new();
    let mut uvs = Vec::new();
    let mut triangles = Vec::new();
    for quad in quads {
        let base = positions.len() as u32;
        for (x, u, y) in [
            (quad.x.0, quad.u.0, 0.0),
            (quad.x.1, quad.u.1, 0.0),
            (quad.x.1, quad.u.1, 1.0),
            (quad.x.0, quad.u.0, 1.0),
        ] {
            positions.push(Vec3::new(x, y, 0.0));
            uvs.push(Vec2::new(u, y));
        }
        triangles.push([base, base + 1, base + 2]);
        triangles.push([base, base + 2, base + 3]);
    }
    TriangleMesh::new(positions, None, Some(uvs), triangles, false)
}

fn texture(wrap: WrapMode) -> Texture {
    let bitmap = Bitmap {
        width: 2,
        height: 2,
        channels: 1,
        data: TEXELS.to_vec(),
        encoding: Encoding::Linear,
    };
    Texture::Bitmap(Arc::new(BitmapTexture::new(
        &bitmap,
        TextureUse::Emission,
        FilterType::Nearest,
        wrap,
        UvTransform::IDENTITY,
    )))
}

/// The texel value at `uv` (repeating).
fn texel(uv: Vec2) -> f32 {
    let i = ((uv.x.rem_euclid(1.0) * 2.0) as usize).min(1);
    let j = ((uv.y.rem_euclid(1.0) * 2.0) as usize).min(1);
    TEXELS[j * 2 + i]
}

fn u2(rng: &mut Pcg32) -> Vec2 {
    Vec2::new(rng.next_f32(), rng.next_f32())
}

/// The density over uv that the texture strategy draws from: texel value / mean.
fn texture_uv_density(uv: Vec2) -> f64 {
    let mean: f32 = TEXELS.iter().sum::<f32>() / 4.0;
    f64::from(texel(uv) / mean)
}

/// The density over area that the mixture claims at a point of `quad` with texture coordinates
/// `uv`: f / A + (1 − f) · p_uv / J.
fn expected_area_density(quad: &Quad, uv: Vec2, total_area: f32) -> f64 {
    let f = f64::from(SHAPE_STRATEGY_FRACTION);
    f / f64::from(total_area) + (1.0 - f) * texture_uv_density(uv) / f64::from(quad.jacobian())
}

/// The quad a point with this x lies on, and its texture coordinates.
fn locate(p: Vec3) -> (&'static Quad, Vec2) {
    let quad = if p.x < 1.0 { &QUAD_A } else { &QUAD_B };
    (quad, Vec2::new(quad.u_at(p.x), p.y))
}

const REFERENCE: Vec3 = Vec3::new(1.5, 0.4, 2.0);

/// Light samples are distributed over uv as the mixture of the texture's density (texel value
/// over the mean) and the area density pulled back through the uv map (J / A), and each claims
/// that density converted to solid angle. Points of the black texel, which only the shape
/// strategy finds, emit nothing and are not returned: they are the sampler's failures.
#[test]
fn textured_area_light_samples_follow_the_texture_through_the_uv_map() {
    let shapes: Vec<Primitive> = vec![Shape::Mesh(mesh(&[QUAD_A, QUAD_B])).into()];
    let light = Light::Area(AreaLight::new(0, texture(WrapMode::Repeat)));
    let lambda = SampledWavelengths::single(550.0);
    let f = f64::from(SHAPE_STRATEGY_FRACTION);
    // Cells of an 8 × 8 grid over uv, each within one texel and one quad, where the density is
    // constant: its value at the centre times the cell's area; the last cell is the failures.
    const N: usize = 8;
    let mut probabilities: Vec<f64> = (0..N * N)
        .map(|cell| {
            let uv = Vec2::new(
                ((cell % N) as f32 + 0.5) / N as f32,
                ((cell / N) as f32 + 0.5) / N as f32,
            );
            if texel(uv) == 0.0 {
                return 0.0;
            }
            let quad = if uv.x < 0.5 { &QUAD_A } else { &QUAD_B };
            let density = f * f64::from(quad.jacobian()) / 4.0 + (1.0 - f) * texture_uv_density(uv);
            density / (N * N) as f64
        })
        .collect();
    probabilities.push(1.0 - probabilities.iter().sum::<f64>());
    let outcome = chi2_discrete(SAMPLES, &probabilities, 7, |rng| {
        let Some(ls) = light.sample_incident(LightQuery {
            shapes: &shapes,
            reference: REFERENCE,
            time: 0.0,
            u_choice: rng.next_f32(),
            u: u2(rng),
            lambda: &lambda,
        }) else {
            return N * N;
        };
        let (quad, uv) = locate(ls.p);
        let d = ls.p - REFERENCE;
        let area_pdf =
            f64::from(ls.pdf) * f64::from(d.normalize().z.abs()) / f64::from(d.length_squared());
        let expected = expected_area_density(quad, uv, 4.0);
        assert!(
            (area_pdf / expected - 1.0).abs() < 1e-3,
            "at uv {uv}: pdf {area_pdf} per area instead of {expected}"
        );
        let i = ((uv.x * N as f32) as usize).min(N - 1);
        let j = ((uv.y * N as f32) as usize).min(N - 1);
        j * N + i
    })
    .unwrap();
    SUITE.assert_passes("textured area light over uv", &outcome);
}

/// A sphere of radius R lighting its inside (flipped normals), textured with the same image,
/// seen from a point inside: the shape strategy is then uniform in area, whose density over uv
/// is J / (4πR²) = (π/2) sin πv (J = 2π²R² sin πv), so a cell [u₀, u₁] × [v₀, v₁] gets
/// (u₁ − u₀)(cos πv₀ − cos πv₁)/2 of it; the texture strategy is constant on each cell.
#[test]
fn textured_sphere_light_samples_follow_the_texture() {
    let radius = 0.8f32;
    let center = Vec3::new(0.1, -0.2, 0.3);
    let shapes: Vec<Primitive> = vec![
        Shape::Sphere(Sphere {
            center,
            radius,
            rotation: glam::Mat3::IDENTITY,
            flip_normals: true,
        })
        .into(),
    ];
    let light = Light::Area(AreaLight::new(0, texture(WrapMode::Repeat)));
    let lambda = SampledWavelengths::single(550.0);
    let reference = center + Vec3::new(0.2, 0.1, -0.3);
    let f = f64::from(SHAPE_STRATEGY_FRACTION);
    let area = 4.0 * std::f64::consts::PI * f64::from(radius).powi(2);
    const N: usize = 8;
    let mut probabilities: Vec<f64> = (0..N * N)
        .map(|cell| {
            let (i, j) = (cell % N, cell / N);
            let uv = Vec2::new((i as f32 + 0.5) / N as f32, (j as f32 + 0.5) / N as f32);
            if texel(uv) == 0.0 {
                return 0.0;
            }
            let (v0, v1) = (j as f64 / N as f64, (j + 1) as f64 / N as f64);
            let shape = ((std::f64::consts::PI * v0).cos() - (std::f64::consts::PI * v1).cos())
                / (2.0 * N as f64);
            f * shape + (1.0 - f) * texture_uv_density(uv) / (N * N) as f64
        })
        .collect();
    probabilities.push(1.0 - probabilities.iter().sum::<f64>());
    let outcome = chi2_discrete(SAMPLES, &probabilities, 9, |rng| {
        let Some(ls) = light.sample_incident(LightQuery {
            shapes: &shapes,
            reference,
            time: 0.0,
            u_choice: rng.next_f32(),
            u: u2(rng),
            lambda: &lambda,
        }) else {
            return N * N;
        };
        // θ from atan2(√(x² + y²), z), which keeps its precision at the poles (acos z loses it).
        let outward = (ls.p - center).normalize();
        let local = outward.as_dvec3();
        let mut phi = local.y.atan2(local.x);
        if phi < 0.0 {
            phi += 2.0 * std::f64::consts::PI;
        }
        let theta = local.x.hypot(local.y).atan2(local.z);
        let uv = Vec2::new(
            (phi / (2.0 * std::f64::consts::PI)) as f32,
            (theta / std::f64::consts::PI) as f32,
        );
        let d = ls.p - reference;
        let area_pdf = f64::from(ls.pdf) * f64::from(d.normalize().dot(outward).abs())
            / f64::from(d.length_squared());
        let jacobian = 2.0 * std::f64::consts::PI.powi(2) * f64::from(radius).powi(2) * theta.sin();
        let expected = f / area + (1.0 - f) * texture_uv_density(uv) / jacobian;
        // The point, from which uv is recomputed here, is stored in single precision.
        assert!(
            (area_pdf / expected - 1.0).abs() < 2e-3,
            "at uv {uv}: pdf {area_pdf} per area instead of {expected}"
        );
        let i = ((uv.x * N as f32) as usize).min(N - 1);
        let j = ((uv.y * N as f32) as usize).min(N - 1);
        j * N + i
    })
    .unwrap();
    SUITE.assert_passes("textured sphere light over uv", &outcome);
}

/// The density a ray hit reports for multiple importance sampling equals the one the light
/// sample claims: at points of both quads and all four texels.
#[test]
fn textured_area_light_pdf_at_ray_hits_matches_the_sampled_density() {
    let shapes: Vec<Primitive> = vec![Shape::Mesh(mesh(&[QUAD_A, QUAD_B])).into()];
    let Light::Area(light) = Light::Area(AreaLight::new(0, texture(WrapMode::Repeat))) else {
        unreachable!()
    };
    for &(x, y) in &[(0.3, 0.2), (0.7, 0.8), (1.4, 0.3), (3.5, 0.9), (2.2, 0.6)] {
        let p = Vec3::new(x, y, 0.0);
        let Primitive::Shape(shape) = &shapes[0] else {
            unreachable!()
        };
        let si = shape_hit(shape, REFERENCE, p - REFERENCE);
        let (quad, uv) = locate(p);
        assert!((si.uv - uv).length() < 1e-5, "uv {} instead of {uv}", si.uv);
        let d = p - REFERENCE;
        let expected = expected_area_density(quad, uv, 4.0) * f64::from(d.length_squared())
            / f64::from(d.normalize().z.abs());
        let pdf = light.pdf_from(&shapes, REFERENCE, 0.0, &SurfaceSample::at(&si));
        assert!(
            (f64::from(pdf) / expected - 1.0).abs() < 1e-4,
            "at {p}: pdf {pdf} instead of {expected}"
        );
    }
}

/// The surface interaction where the ray o + t·d meets the mesh (by brute force over its
/// triangles).
fn shape_hit(shape: &Shape, o: Vec3, d: Vec3) -> SurfaceInteraction {
    let Shape::Mesh(mesh) = shape else {
        unreachable!()
    };
    let ray = WatertightRay::new(o, d);
    (0..mesh.triangles().len())
        .find_map(|t| {
            let [p0, p1, p2] = mesh.vertices(t);
            let hit = ray.intersect(f32::INFINITY, p0, p1, p2)?;
            Some(mesh.interaction(&Ray::new(o, d, f32::INFINITY, 0.0), t as u32, &hit, 0))
        })
        .expect("the ray meets the mesh")
}

/// The flux Φ = π ∫ L dA, estimated as π L / p_A over light samples (failed samples count 0),
/// against its closed form Σ over quads and texels of J · (uv area) · texel · π, within 4σ.
fn assert_flux(quads: &[Quad], wrap: WrapMode, name: &str) {
    let shapes: Vec<Primitive> = vec![Shape::Mesh(mesh(quads)).into()];
    let light = Light::Area(AreaLight::new(0, texture(wrap)));
    let lambda = SampledWavelengths::single(550.0);
    let mut rng = Pcg32::new(11, 0);
    let n = 400_000;
    let (mut sum, mut sum2) = (0.0f64, 0.0f64);
    for _ in 0..n {
        let value = light
            .sample_incident(LightQuery {
                shapes: &shapes,
                reference: REFERENCE,
                time: 0.0,
                u_choice: rng.next_f32(),
                u: u2(&mut rng),
                lambda: &lambda,
            })
            .map_or(0.0, |ls| {
                let d = ls.p - REFERENCE;
                let area_pdf = f64::from(ls.pdf) * f64::from(d.normalize().z.abs())
                    / f64::from(d.length_squared());
                std::f64::consts::PI * f64::from(ls.radiance[0]) / area_pdf
            });
        sum += value;
        sum2 += value * value;
    }
    let mean = sum / n as f64;
    let standard_error = ((sum2 / n as f64 - mean * mean) / (n - 1) as f64).sqrt();
    // Texels are constant on quarters of the uv period, so the midpoint rule on a grid of
    // eighths is exact.
    let expected: f64 = quads
        .iter()
        .map(|quad| {
            let steps = ((quad.u.1 - quad.u.0) * 8.0).round() as usize;
            let cells: f64 = (0..steps)
                .flat_map(|i| (0..8).map(move |j| (i, j)))
                .map(|(i, j)| {
                    let uv = Vec2::new(quad.u.0 + (i as f32 + 0.5) / 8.0, (j as f32 + 0.5) / 8.0);
                    f64::from(texel(uv)) / 64.0
                })
                .sum();
            std::f64::consts::PI * f64::from(quad.jacobian()) * cells
        })
        .sum();
    assert!(
        (mean - expected).abs() < 4.0 * standard_error,
        "{name}: flux {mean} ± {standard_error} instead of {expected}"
    );
    assert!(standard_error < 0.01 * expected, "{name}: too noisy");
}

#[test]
fn textured_area_light_flux_matches_its_closed_form() {
    assert_flux(&[QUAD_A, QUAD_B], WrapMode::Repeat, "uv within [0, 1]²");
}

/// Quad B's texture coordinates run on to u = 1.5, where the repeating texture lights it but
/// the texture strategy never reaches: the shape strategy of the mixture keeps the estimate
/// unbiased.
#[test]
fn textured_area_light_flux_is_unbiased_beyond_the_unit_square() {
    let wide_b = Quad {
        x: (1.0, 4.0),
        u: (0.5, 1.5),
    };
    assert_flux(&[QUAD_A, wide_b], WrapMode::Repeat, "uv beyond [0, 1]²");
}

/// A sphere's and a disk's inverse uv maps: the point `at_uv` returns is reported back with the
/// same uv by a ray hit there, and the Jacobian is |∂p/∂u × ∂p/∂v| of that hit.
#[test]
fn sphere_and_disk_points_at_uv_invert_their_parametrisation() {
    let sphere = Shape::Sphere(Sphere {
        center: Vec3::new(0.2, -0.1, 0.3),
        radius: 0.7,
        rotation: glam::Mat3::from_rotation_y(0.4),
        flip_normals: false,
    });
    let disk = Shape::Disk(Disk::new(
        Transform::new(
            glam::DMat4::from_translation(glam::DVec3::new(0.0, 0.0, 0.5))
                * glam::DMat4::from_scale(glam::DVec3::new(2.0, 1.0, 1.0)),
        )
        .unwrap(),
        false,
    ));
    let mut rng = Pcg32::new(3, 0);
    for shape in [&sphere, &disk] {
        for _ in 0..200 {
            let uv = Vec2::new(0.02 + 0.96 * rng.next_f32(), 0.02 + 0.96 * rng.next_f32());
            let (s, jacobian) = shape.at_uv(uv).expect("the whole unit square is mapped");
            // A ray from outside along the normal back onto the point.
            let origin = s.p + s.n * 0.5;
            let ray = Ray::new(origin, -s.n, f32::INFINITY, 0.0);
            let t = shape.intersect_analytic(&ray, f32::INFINITY).expect("hit");
            let hit = TriangleHit {
                t,
                b0: 0.0,
                b1: 0.0,
                b2: 0.0,
            };
            let si = shape.interaction(&ray, 0, &hit, 0);
            let back = si.uv;
            let du = (back.x - uv.x).abs().min(1.0 - (back.x - uv.x).abs());
            assert!(
                du < 1e-4 && (back.y - uv.y).abs() < 1e-4,
                "uv {uv} came back as {back}"
            );
            let expected = si.dp_du.cross(si.dp_dv).length();
            assert!(
                (jacobian / expected - 1.0).abs() < 1e-3,
                "Jacobian {jacobian} instead of {expected} at {uv}"
            );
        }
    }
}
