//! Any bytes given as the `.vol` file of an `sdfgrid` give a grid, traced by a few rays, or an
//! error; never a panic.
#![no_main]

use glam::{UVec3, Vec3};
use libfuzzer_sys::fuzz_target;
use prism_core::geometry::shape::{SdfGrid, SdfNormals};
use prism_core::math::{Ray, Transform};
use prism_core::medium::volume::parse_vol;

fuzz_target!(|data: &[u8]| {
    let Ok(file) = parse_vol(data) else {
        return;
    };
    let [x, y, z] = file.resolution.map(|n| n as u32);
    if file.channels != 1 || x.max(y).max(z) > 64 {
        return;
    }
    for normals in [SdfNormals::Smooth, SdfNormals::Analytic] {
        let Some(grid) =
            SdfGrid::new(UVec3::new(x, y, z), file.data.clone(), Transform::IDENTITY, normals)
        else {
            return;
        };
        for (o, d) in [
            (Vec3::new(0.5, 0.5, 2.0), -Vec3::Z),
            (Vec3::new(-1.0, 0.3, 0.6), Vec3::new(1.0, 0.1, 0.05)),
            (Vec3::splat(0.5), Vec3::new(0.3, -0.7, 0.2)),
        ] {
            let ray = Ray::new(o, d, f32::INFINITY, 0.0);
            let _ = grid.intersect(&ray, f32::INFINITY);
        }
    }
});
