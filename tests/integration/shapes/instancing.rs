//! Instancing (`shapegroup` and `instance`): an instanced scene renders as the same shapes
//! written out one by one, each instance keeps its group's materials, and the instances of a
//! group share its geometry.

use std::path::Path;
use std::sync::Arc;

use prism_core::geometry::Primitive;
use prism_core::math::special::regularized_gamma_q;
use prism_core::scene::Scene;
use prism_mitsuba::factory::build_scene;
use prism_mitsuba::reader::read_scene_str;

use crate::common::scenes::{pixel_mean_and_variance, render_film};

/// A floor under a sky and a sun, seen from above, with `shapes` on it.
fn scene_with(shapes: &str) -> Scene {
    let text = format!(
        r#"<scene version="3.0.0">
    <integrator type="path"><integer name="max_depth" value="3"/></integrator>
    <sensor type="perspective">
        <float name="fov" value="50"/>
        <transform name="to_world"><lookat origin="0, 4, 6" target="0, 0.5, 0" up="0, 1, 0"/></transform>
        <film type="hdrfilm"><integer name="width" value="32"/><integer name="height" value="32"/><rfilter type="box"/></film>
    </sensor>
    <emitter type="constant"><rgb name="radiance" value="1, 1, 1"/></emitter>
    <emitter type="directional"><vector name="direction" value="-1, -2, -1"/><rgb name="irradiance" value="3, 3, 3"/></emitter>
    <shape type="rectangle">
        <transform name="to_world"><scale value="6"/><rotate x="1" angle="-90"/></transform>
    </shape>
    {shapes}
</scene>"#
    );
    let root = read_scene_str(&text, &Path::new(".").join("scene.xml"), &[]).unwrap();
    build_scene(&root).unwrap().scene
}

/// The group's members, each followed by `placement` (a sequence of transform operations).
fn members(placement: &str) -> String {
    format!(
        r#"<shape type="sphere">
            <transform name="to_world"><scale value="0.5"/><translate y="1.3"/>{placement}</transform>
            <bsdf type="diffuse"><rgb name="reflectance" value="0.8, 0.1, 0.1"/></bsdf>
        </shape>
        <shape type="cube">
            <transform name="to_world"><scale x="0.5" y="0.4" z="0.3"/><translate y="0.4"/>{placement}</transform>
            <bsdf type="roughconductor"><string name="material" value="Au"/><float name="alpha" value="0.2"/></bsdf>
        </shape>"#
    )
}

const PLACEMENTS: [&str; 3] = [
    r#"<translate x="-1.8"/>"#,
    r#"<rotate y="1" angle="40"/><scale value="0.7"/><translate z="-1.5"/>"#,
    r#"<rotate y="1" angle="-25"/><scale value="1.2"/><translate x="1.8" z="0.4"/>"#,
];

fn instanced_scene() -> Scene {
    let mut shapes = format!(
        r#"<shape type="shapegroup" id="sphere_on_box">{}</shape>"#,
        members("")
    );
    for placement in PLACEMENTS {
        shapes += &format!(
            r#"<shape type="instance"><ref id="sphere_on_box"/><transform name="to_world">{placement}</transform></shape>"#
        );
    }
    scene_with(&shapes)
}

fn flattened_scene() -> Scene {
    scene_with(&PLACEMENTS.map(members).concat())
}

/// The instanced and the flattened scene, rendered with independent seeds, agree pixel by pixel
/// within their noise: for each of X, Y and Z, Σ (a − b)² / (σ_a² + σ_b²) over the pixels is χ²
/// with one degree of freedom per pixel, and its p-value must be above 10⁻³ (Šidák-corrected
/// over the three). A wrong material or a misplaced shape changes pixels by many standard
/// errors.
#[test]
fn an_instanced_scene_renders_as_its_flattened_copy() {
    let instanced = render_film(&instanced_scene(), 256, 1, None);
    let flattened = render_film(&flattened_scene(), 256, 2, None);
    let significance = 1.0 - (1.0 - 1e-3f64).powf(1.0 / 3.0);
    for c in 0..3 {
        let mut statistic = 0.0;
        for i in 0..instanced.pixels.len() {
            let (a, va) = pixel_mean_and_variance(&instanced, i, c);
            let (b, vb) = pixel_mean_and_variance(&flattened, i, c);
            if va + vb > 0.0 {
                statistic += (a - b) * (a - b) / (va + vb);
            }
        }
        let dof = instanced.pixels.len() as f64;
        let p = regularized_gamma_q(dof / 2.0, statistic / 2.0);
        assert!(
            p > significance,
            "channel {c}: chi² {statistic} over {dof} pixels, p = {p}"
        );
    }
}

/// The instances of a group share one object (its shapes and hierarchy), and their hits are
/// recorded as the group's shapes, which come after the scene's primitives with their own
/// materials.
#[test]
fn instances_share_their_group() {
    let scene = instanced_scene();
    let primitives = &scene.world.geometry.primitives;
    let instances: Vec<_> = primitives
        .iter()
        .filter_map(|p| match p {
            Primitive::Instance(instance) => Some(instance),
            Primitive::Shape(_) => None,
        })
        .collect();
    assert_eq!(instances.len(), PLACEMENTS.len());
    for instance in &instances {
        assert!(Arc::ptr_eq(&instance.object, &instances[0].object));
        assert_eq!(instance.first_shape, Some(primitives.len() as u32));
    }
    assert_eq!(instances[0].object.primitives.len(), 2);
    let group_shapes = &scene.world.shape_info[primitives.len()..];
    assert_eq!(group_shapes.len(), 2);
    assert_ne!(group_shapes[0].material, group_shapes[1].material);
    assert!(group_shapes.iter().all(|info| info.light.is_none()));
}
