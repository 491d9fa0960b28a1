//! `strict_normals` on `path` (Mitsuba 0.6) against a closed form: a diffuse plane of
//! reflectance ρ whose shading normals lean by α from its geometric normal, under a constant
//! environment of radiance L, direct light only, seen head-on. The BSDF lives in the shading
//! frame, so without strict normals the light of the whole shading hemisphere arrives (some of
//! it from below the plane) and the plane's radiance is ρL. With strict normals only directions
//! above both the geometric and the shading plane count: the irradiance of a uniform hemisphere
//! on a plane tilted by α is πL(1 + cos α)/2 (the sky view factor), so the radiance is
//! ρL(1 + cos α)/2.

use std::path::Path;

use crate::common::scenes::{assert_mean_luminance, render_film};

fn scene(strict: bool, dir: &Path) -> prism_core::scene::Scene {
    let alpha = 60f64.to_radians();
    let (s, c) = (alpha.sin(), alpha.cos());
    let obj = format!(
        "v -10 -10 0\nv 10 -10 0\nv 10 10 0\nv -10 10 0\nvn {s} 0 {c}\nf 1//1 2//1 3//1\nf 1//1 3//1 4//1\n"
    );
    std::fs::write(dir.join("plane.obj"), obj).unwrap();
    let xml = format!(
        r#"<scene version="3.0.0">
    <integrator type="path">
        <integer name="max_depth" value="2"/>
        <boolean name="strict_normals" value="{strict}"/>
    </integrator>
    <sensor type="perspective">
        <float name="fov" value="30"/>
        <transform name="to_world"><lookat origin="0, 0, 2" target="0, 0, 0" up="0, 1, 0"/></transform>
        <film type="hdrfilm"><integer name="width" value="16"/><integer name="height" value="16"/><rfilter type="box"/></film>
    </sensor>
    <shape type="obj">
        <string name="filename" value="plane.obj"/>
        <bsdf type="diffuse"><spectrum name="reflectance" value="0.5"/></bsdf>
    </shape>
    <emitter type="constant"><spectrum name="radiance" value="1"/></emitter>
</scene>"#
    );
    let path = dir.join("scene.xml");
    std::fs::write(&path, &xml).unwrap();
    let root = prism_mitsuba::reader::read_scene_str(&xml, &path, &[]).unwrap();
    prism_mitsuba::factory::build_scene(&root).unwrap().scene
}

#[test]
fn strict_normals_drop_the_light_below_the_geometric_plane() {
    let dir = std::env::temp_dir().join(format!("prism-strict-normals-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let loose = render_film(&scene(false, &dir), 1024, 11, None);
    assert_mean_luminance("without strict normals", &loose, 0.5);
    let strict = render_film(&scene(true, &dir), 1024, 12, None);
    let expected = 0.5 * (1.0 + 60f64.to_radians().cos()) / 2.0;
    assert_mean_luminance("with strict normals", &strict, expected);
    std::fs::remove_dir_all(&dir).ok();
}
