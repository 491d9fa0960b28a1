//! The `depth` integrator: the distance to the first surface, as a constant spectrum, against
//! its closed form on a plane seen head-on; zero where the rays leave the scene.

use prism_core::scene::Scene;

use crate::common::scenes::{
    assert_mean_luminance, image_mean_and_standard_error, render_film, scene_from_xml,
};

fn scene(body: &str) -> Scene {
    let xml = format!(
        r#"<scene version="3.0.0">
    <integrator type="depth"/>
    <sensor type="perspective">
        <float name="fov" value="40"/>
        <transform name="to_world"><lookat origin="0, 0, 2" target="0, 0, 0" up="0, 1, 0"/></transform>
        <film type="hdrfilm"><integer name="width" value="8"/><integer name="height" value="8"/><rfilter type="box"/></film>
    </sensor>
    {body}
</scene>"#
    );
    scene_from_xml(&xml, "depth.xml").unwrap()
}

/// A camera at height D = 2 looks straight down at the plane z = 0 with a 40° field of view.
/// Camera rays start on the near plane (Mitsuba's default `near_clip` 0.01), so the ray through
/// the screen point (x, y) at unit distance has depth (D − 0.01)·√(1 + x² + y²), and the
/// luminance of a constant spectrum t is t: the image's mean Y is the mean of the depth over
/// the screen square |x|, |y| ≤ tan 20°.
#[test]
fn depth_is_the_distance_to_the_first_surface() {
    let plane = scene(
        r#"<shape type="rectangle"><transform name="to_world"><scale value="10"/></transform></shape>"#,
    );
    let film = render_film(&plane, 256, 3, None);
    let half = 20f64.to_radians().tan();
    let n = 400;
    let mut sum = 0.0;
    for i in 0..n {
        for j in 0..n {
            let x = half * (2.0 * (i as f64 + 0.5) / n as f64 - 1.0);
            let y = half * (2.0 * (j as f64 + 0.5) / n as f64 - 1.0);
            sum += (1.0 + x * x + y * y).sqrt();
        }
    }
    let expected = (2.0 - 0.01) * sum / (n * n) as f64;
    assert_mean_luminance("depth of a plane", &film, expected);
}

#[test]
fn depth_is_zero_where_rays_leave_the_scene() {
    let empty = scene(
        r#"<shape type="sphere"><transform name="to_world"><translate x="50"/></transform></shape>"#,
    );
    let film = render_film(&empty, 4, 1, None);
    let (mean, _) = image_mean_and_standard_error(&film, 1);
    assert_eq!(mean, 0.0);
}
