//! Mitsuba's tensor parameters, which only scene dictionaries (Python's `load_dict` with numpy
//! arrays) can give: `sdfgrid`'s `grid` and `ellipsoids`' `data`, `centers`/`scales`/
//! `quaternions` and `opacities`. Each must give exactly the shape its file form gives (every
//! hit of many rays equal bit for bit), and every malformed tensor an error at its key path.

use glam::Vec3;
use prism_core::geometry::Geometry;
use prism_core::math::Ray;
use prism_core::medium::volume::parse_vol;
use prism_core::sampling::rng::Pcg32;
use prism_mitsuba::dict::{Dict, DictValue, read_scene_dict};
use prism_mitsuba::factory::build_scene;

fn text(v: &str) -> DictValue {
    DictValue::String(v.to_string())
}

fn dict(entries: Vec<(&str, DictValue)>) -> DictValue {
    DictValue::Dict(Dict {
        entries: entries
            .into_iter()
            .map(|(k, v)| (k.to_string(), v))
            .collect(),
    })
}

/// `values` as nested lists of the shape `shape` (last index fastest), as numpy's `tolist()`.
fn nested(shape: &[usize], values: &[f64]) -> DictValue {
    match shape.split_first() {
        None => DictValue::Float(values[0]),
        Some((&n, inner)) => {
            let step = inner.iter().product::<usize>();
            DictValue::List(
                (0..n)
                    .map(|i| nested(inner, &values[i * step..(i + 1) * step]))
                    .collect(),
            )
        }
    }
}

/// A scene of a sensor and the shape `shape`, read from its dictionary.
fn geometry_of(shape: DictValue) -> prism_core::error::Result<Geometry> {
    let root = Dict {
        entries: vec![
            ("type".into(), text("scene")),
            ("sensor".into(), dict(vec![("type", text("perspective"))])),
            ("shape".into(), shape),
        ],
    };
    let node = read_scene_dict(&root)?;
    Ok(build_scene(&node)?.scene.world.geometry)
}

/// The geometry of an XML scene holding `shape`, with `file` written beside it as `name`.
fn xml_geometry(shape: &str, name: &str, file: &[u8], tag: &str) -> Geometry {
    let dir = std::env::temp_dir().join(format!("prism-tensors-{tag}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join(name), file).unwrap();
    let xml = format!("<scene version=\"3.0.0\"><sensor type=\"perspective\"/>{shape}</scene>");
    let scene =
        crate::common::scenes::scene_from_xml(&xml, dir.join("scene.xml").to_str().unwrap())
            .unwrap_or_else(|e| panic!("{e}"));
    std::fs::remove_dir_all(&dir).unwrap();
    scene.world.geometry
}

/// Asserts that rays from around `center` hit `a` and `b` alike, bit for bit, and that enough
/// of them hit anything for the comparison to mean something.
fn assert_same_hits(a: &Geometry, b: &Geometry, center: Vec3, spread: f32) {
    let mut rng = Pcg32::seeded(11);
    let mut hits = 0;
    for _ in 0..2000 {
        let mut point = || Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) - 0.5;
        let origin = center + point().normalize_or_zero() * 4.0 * spread;
        let target = center + point() * spread;
        let ray = Ray::new(origin, target - origin, f32::INFINITY, 0.0);
        let (ha, hb) = (a.intersect(&ray), b.intersect(&ray));
        assert_eq!(ha.is_some(), hb.is_some(), "ray {ray:?}");
        if let (Some(ha), Some(hb)) = (ha, hb) {
            assert_eq!(ha.t.to_bits(), hb.t.to_bits(), "ray {ray:?}");
            assert_eq!(ha.n, hb.n);
            assert_eq!(ha.shading.n, hb.shading.n);
            hits += 1;
        }
    }
    assert!(hits > 300, "{hits} hits: the test sees too few");
}

#[test]
fn a_grid_tensor_is_the_grid_of_its_vol_file() {
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/references/sdfgrid.vol");
    let bytes = std::fs::read(&path).expect("the test's grid file");
    let file = parse_vol(&bytes).unwrap();
    let [x, y, z] = file.resolution;
    let values: Vec<f64> = file.data.iter().map(|&v| f64::from(v)).collect();
    let from_file = xml_geometry(
        r#"<shape type="sdfgrid"><string name="filename" value="g.vol"/>
            <transform name="to_world"><scale x="2" y="1.5" z="1"/></transform></shape>"#,
        "g.vol",
        &bytes,
        "sdf",
    );
    let to_world = DictValue::Matrix([
        [2.0, 0.0, 0.0, 0.0],
        [0.0, 1.5, 0.0, 0.0],
        [0.0, 0.0, 1.0, 0.0],
        [0.0, 0.0, 0.0, 1.0],
    ]);
    let from_tensor = geometry_of(dict(vec![
        ("type", text("sdfgrid")),
        ("grid", nested(&[z, y, x, 1], &values)),
        ("to_world", to_world),
    ]))
    .unwrap();
    assert_same_hits(&from_file, &from_tensor, Vec3::new(1.0, 0.75, 0.5), 1.0);
}

/// Three ellipsoids in a PLY file of Mitsuba's minimal layout (scales as logarithms, the
/// quaternion w first), and the same as Mitsuba's tensor rows (scales, quaternion x, y, z, w).
fn ellipsoid_rows() -> (Vec<u8>, Vec<f64>) {
    let rows: [[f32; 10]; 3] = [
        [0.0, 0.0, 0.0, 0.3, 0.1, 0.2, 0.9, 0.1, 0.3, 0.2],
        [1.0, 0.2, -0.4, 0.15, 0.25, 0.1, 0.2, -0.7, 0.1, 0.5],
        [-0.8, 0.5, 0.3, 0.2, 0.2, 0.35, 1.0, 0.0, 0.0, 0.0],
    ];
    let names = [
        "x", "y", "z", "nx", "ny", "nz", "scale_0", "scale_1", "scale_2", "rot_0", "rot_1",
        "rot_2", "rot_3",
    ];
    let mut ply = format!(
        "ply\nformat binary_little_endian 1.0\nelement vertex {}\n",
        rows.len()
    );
    for name in names {
        ply += &format!("property float {name}\n");
    }
    ply += "end_header\n";
    let mut ply = ply.into_bytes();
    let mut tensor = Vec::new();
    for [cx, cy, cz, sx, sy, sz, w, qx, qy, qz] in rows {
        let logs = [sx.ln(), sy.ln(), sz.ln()];
        for v in [
            cx, cy, cz, 0.0, 0.0, 1.0, logs[0], logs[1], logs[2], w, qx, qy, qz,
        ] {
            ply.extend_from_slice(&v.to_le_bytes());
        }
        // The file's scales are exp(ln s) in f32, which the tensor must hold exactly.
        let scales = logs.map(f32::exp);
        tensor.extend([cx, cy, cz, scales[0], scales[1], scales[2], qx, qy, qz, w].map(f64::from));
    }
    (ply, tensor)
}

#[test]
fn ellipsoid_tensors_are_the_ellipsoids_of_their_file() {
    let (ply, data) = ellipsoid_rows();
    let from_file = xml_geometry(
        r#"<shape type="ellipsoids"><string name="filename" value="e.ply"/>
            <float name="extent" value="2"/></shape>"#,
        "e.ply",
        &ply,
        "ellipsoids",
    );
    let center = Vec3::new(0.0, 0.2, 0.0);
    for shape in [vec![10 * 3], vec![3, 10]] {
        let from_data = geometry_of(dict(vec![
            ("type", text("ellipsoids")),
            ("data", nested(&shape, &data)),
            ("extent", DictValue::Float(2.0)),
            // An attribute Mitsuba keeps and Prism reads past.
            ("sh_coeffs", nested(&[3, 3], &[0.5; 9])),
        ]))
        .unwrap();
        assert_same_hits(&from_file, &from_data, center, 1.2);
    }
    let column = |start: usize, width: usize| -> Vec<f64> {
        data.chunks(10)
            .flat_map(|row| row[start..start + width].to_vec())
            .collect()
    };
    let from_columns = geometry_of(dict(vec![
        ("type", text("ellipsoids")),
        ("centers", nested(&[3, 3], &column(0, 3))),
        ("scales", nested(&[3, 3], &column(3, 3))),
        ("quaternions", nested(&[3, 4], &column(6, 4))),
        ("extent", DictValue::Float(2.0)),
    ]))
    .unwrap();
    assert_same_hits(&from_file, &from_columns, center, 1.2);
}

/// Four ellipsoids' quaternions make a 4 × 4 list, which a dictionary reads as a matrix: as a
/// tensor parameter it is still the quaternions, row by row.
#[test]
fn a_four_by_four_tensor_is_not_taken_for_a_transform() {
    let centers: Vec<f64> = (0..4)
        .flat_map(|i| [f64::from(i) * 2.0, 0.0, 0.0])
        .collect();
    let quaternions = [0.0, 0.0, 0.0, 1.0].repeat(4);
    let mut rows = [[0.0; 4]; 4];
    for (row, q) in rows.iter_mut().zip(quaternions.chunks(4)) {
        row.copy_from_slice(q);
    }
    let geometry = geometry_of(dict(vec![
        ("type", text("ellipsoids")),
        ("centers", nested(&[4, 3], &centers)),
        ("scales", nested(&[4, 3], &[0.1, 0.2, 0.3].repeat(4))),
        ("quaternions", DictValue::Matrix(rows)),
        ("extent", DictValue::Float(1.0)),
    ]))
    .unwrap();
    assert_eq!(geometry.primitive_count(), 4);
    // The identity rotation leaves radius 0.3 along z.
    let hit = geometry
        .intersect(&Ray::new(
            Vec3::new(6.0, 0.0, 5.0),
            -Vec3::Z,
            f32::INFINITY,
            0.0,
        ))
        .unwrap();
    assert!((hit.t - 4.7).abs() < 1e-5, "{}", hit.t);
}

#[test]
fn opacities_clamp_the_extent_as_a_files_do() {
    // Opacity 0.5 gives the extent 3 √(2 ln 50) / 3; 0.005 (at most 0.01) removes the ellipsoid.
    let data = [
        [0.0, 0.0, 0.0, 1.0, 1.0, 1.0, 0.0, 0.0, 0.0, 1.0],
        [5.0, 0.0, 0.0, 1.0, 1.0, 1.0, 0.0, 0.0, 0.0, 1.0],
    ]
    .concat();
    for opacities in [nested(&[2, 1], &[0.5, 0.005]), nested(&[2], &[0.5, 0.005])] {
        let geometry = geometry_of(dict(vec![
            ("type", text("ellipsoids")),
            ("data", nested(&[2, 10], &data)),
            ("opacities", opacities),
            ("extent_adaptive_clamping", DictValue::Boolean(true)),
        ]))
        .unwrap();
        assert_eq!(geometry.primitive_count(), 1);
        let hit = geometry
            .intersect(&Ray::new(Vec3::Z * 10.0, -Vec3::Z, f32::INFINITY, 0.0))
            .unwrap();
        let radius = (2.0 * 50f32.ln()).sqrt();
        assert!((hit.t - (10.0 - radius)).abs() < 1e-5, "{} {radius}", hit.t);
    }
}

/// A plugin dictionary's entries.
type Entries = Vec<(&'static str, DictValue)>;

/// Every malformed tensor, and tensors combined as Mitsuba refuses, is an error at the key path
/// of the entry, saying what is wrong.
#[test]
fn malformed_tensors_are_refused_at_their_key_path() {
    let data = nested(
        &[1, 10],
        &[0.0, 0.0, 0.0, 1.0, 1.0, 1.0, 0.0, 0.0, 0.0, 1.0],
    );
    let cases: Vec<(Entries, &str, &str)> = vec![
        (
            vec![
                ("type", text("sdfgrid")),
                ("grid", nested(&[2, 2, 2], &[1.0; 8])),
            ],
            "scene.shape.grid",
            "(z, y, x, 1)",
        ),
        (
            vec![
                ("type", text("sdfgrid")),
                (
                    "grid",
                    nested(&[2, 2, 2, 1], &[-1.0, 1.0, -1.0, 1.0, -1.0, 1.0, -1.0, 1.0]),
                ),
                ("filename", text("g.vol")),
            ],
            "scene.shape.grid",
            "both",
        ),
        (
            vec![("type", text("sdfgrid")), ("grid", DictValue::Float(1.0))],
            "scene.shape.grid",
            "must be a tensor",
        ),
        (
            vec![
                ("type", text("ellipsoids")),
                ("data", nested(&[1, 9], &[1.0; 9])),
            ],
            "scene.shape.data",
            "(N, 10)",
        ),
        (
            vec![
                ("type", text("ellipsoids")),
                ("data", data.clone()),
                ("scale_factor", DictValue::Float(2.0)),
            ],
            "scene.shape.scale_factor",
            "PLY file",
        ),
        (
            vec![
                ("type", text("ellipsoids")),
                ("data", data.clone()),
                ("centers", nested(&[1, 3], &[0.0; 3])),
            ],
            "scene.shape.centers",
            "with \"data\"",
        ),
        (
            vec![
                ("type", text("ellipsoids")),
                ("centers", nested(&[1, 3], &[0.0; 3])),
            ],
            "scene.shape",
            "needs \"scales\"",
        ),
        (
            vec![
                ("type", text("ellipsoids")),
                (
                    "data",
                    nested(
                        &[1, 10],
                        &[0.0, 0.0, 0.0, 1.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0],
                    ),
                ),
            ],
            "scene.shape.data",
            "scale that is not positive",
        ),
        (
            vec![
                ("type", text("ellipsoids")),
                ("data", data),
                ("opacities", nested(&[2], &[0.5, 0.5])),
                ("extent_adaptive_clamping", DictValue::Boolean(true)),
            ],
            "scene.shape.opacities",
            "(1, 1) or (1)",
        ),
        (
            vec![
                ("type", text("sdfgrid")),
                (
                    "grid",
                    DictValue::List(vec![nested(&[2], &[1.0, 2.0]), nested(&[1], &[1.0])]),
                ),
            ],
            "scene.shape.grid",
            "not a value Prism reads",
        ),
    ];
    for (entries, key_path, words) in cases {
        let error = match geometry_of(dict(entries)) {
            Ok(_) => panic!("{key_path}: expected an error"),
            Err(e) => e,
        };
        assert_eq!(
            error.location.as_ref().map(|l| l.to_string()).as_deref(),
            Some(key_path),
            "{error}"
        );
        assert!(error.to_string().contains(words), "{key_path}: {error}");
    }
}
