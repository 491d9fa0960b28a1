//! Scenes Mitsuba 3 renders although they are not strictly well-formed: comments holding `--`,
//! shapes of zero area that do not emit, and OBJ files that are not UTF-8. Each is read, and
//! renders as if the oddity were absent.

use std::path::{Path, PathBuf};

use prism_mitsuba::{LoadedScene, load_scene};

use crate::common::scenes::{assert_mean_luminance, render_film};

/// A scratch folder with `files` in it, removed on drop.
struct Folder(PathBuf);

impl Folder {
    fn new(name: &str, files: &[(&str, &[u8])]) -> Folder {
        let dir =
            std::env::temp_dir().join(format!("prism-leniency-{name}-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        for (file, contents) in files {
            std::fs::write(dir.join(file), contents).unwrap();
        }
        Folder(dir)
    }

    fn load(&self) -> LoadedScene {
        load_scene(&self.0.join("scene.xml"), &[]).unwrap_or_else(|e| panic!("{e}"))
    }

    fn path(&self) -> &Path {
        &self.0
    }
}

impl Drop for Folder {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// A 16 × 16 camera looking down -z at the origin from z = 5 under a constant white
/// environment of luminance 1, with `shapes` added.
fn furnace(shapes: &str) -> String {
    format!(
        r#"<scene version="3.0.0">
    <integrator type="path"/>
    <sensor type="perspective">
        <transform name="to_world"><lookat origin="0, 0, 5" target="0, 0, 0" up="0, 1, 0"/></transform>
        <film type="hdrfilm"><integer name="width" value="16"/><integer name="height" value="16"/></film>
    </sensor>
    <emitter type="constant"/>
{shapes}
</scene>
"#
    )
}

#[test]
fn comments_with_double_hyphens_are_read() {
    let scene = furnace(
        "    <!-- ---------- a rule of hyphens ---------- -->\n    <!-- the sphere -- radius 1 --->\n    <shape type=\"sphere\"/>",
    );
    let folder = Folder::new("comments", &[("scene.xml", scene.as_bytes())]);
    assert_eq!(folder.load().scene.world.geometry.primitive_count(), 1);
}

#[test]
fn shapes_of_zero_area_contribute_nothing() {
    // Degenerate OBJ triangles (three points on a line, and one point) across the whole view;
    // the sphere behind the camera keeps the geometry non-empty.
    let scene = furnace(
        r#"    <shape type="obj"><string name="filename" value="flat.obj"/><bsdf type="diffuse"/></shape>
    <shape type="sphere"><transform name="to_world"><translate z="10"/></transform></shape>"#,
    );
    let folder = Folder::new(
        "zero-area",
        &[
            ("scene.xml", scene.as_bytes()),
            (
                "flat.obj",
                b"v -3 0 0\nv 0 0 0\nv 3 0 0\nf 1 2 3\nf 2 2 2\n",
            ),
        ],
    );
    let loaded = folder.load();
    assert_eq!(loaded.scene.world.geometry.primitive_count(), 1);
    // Every camera ray escapes to the environment: the image is its luminance, 1.
    let film = render_film(&loaded.scene, 256, 1, Some(1));
    assert_mean_luminance("zero-area shapes in a furnace", &film, 1.0);
}

#[test]
fn an_emitter_of_zero_area_is_refused() {
    let scene = furnace(
        "    <shape type=\"obj\">\n        <string name=\"filename\" value=\"flat.obj\"/>\n        <emitter type=\"area\"/>\n    </shape>",
    );
    let folder = Folder::new(
        "zero-area-emitter",
        &[
            ("scene.xml", scene.as_bytes()),
            ("flat.obj", b"v -3 0 0\nv 0 0 0\nv 3 0 0\nf 1 2 3\n"),
        ],
    );
    let Err(error) = load_scene(&folder.path().join("scene.xml"), &[]) else {
        panic!("an emitting shape of zero area was accepted");
    };
    let text = error.to_string();
    assert!(text.contains("scene.xml:10:9"), "{text}");
    assert!(text.contains("has no area, so it cannot emit"), "{text}");
}

#[test]
fn an_obj_in_latin1_is_read() {
    let scene =
        furnace("    <shape type=\"obj\"><string name=\"filename\" value=\"latin1.obj\"/></shape>");
    let obj: &[u8] = b"# mod\xe8le export\xe9\nmtllib sc\xe8ne.mtl\no pi\xe8ce\nusemtl m\xe9tal\n\
        v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    let folder = Folder::new(
        "latin1",
        &[("scene.xml", scene.as_bytes()), ("latin1.obj", obj)],
    );
    let (low, high) = folder.load().scene.world.geometry.bounds().unwrap();
    assert_eq!(
        (low.to_array(), high.to_array()),
        ([0.0; 3], [1.0, 1.0, 0.0])
    );
}
