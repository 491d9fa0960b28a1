//! A fingerprint of a scene: a 64-bit hash of its description (plugins, parameters, values —
//! not where the files are) and of the contents of every file it names, so that a render state
//! can tell whether it belongs to the scene it is resumed or merged with, on any machine.

use prism_core::film::Reconstruction;
use prism_core::scene::Scene;
use prism_core::spectrum::WavelengthSampling;

use crate::description::{PluginNode, PropertyValue};

/// FNV-1a, 64 bits (Fowler, Noll & Vo): simple and stable across platforms and versions.
#[derive(Clone, Copy, Debug)]
pub struct Fnv64(u64);

impl Default for Fnv64 {
    fn default() -> Self {
        Fnv64(0xcbf2_9ce4_8422_2325)
    }
}

impl Fnv64 {
    pub fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.0 ^= u64::from(b);
            self.0 = self.0.wrapping_mul(0x0100_0000_01b3);
        }
    }

    pub fn write_str(&mut self, text: &str) {
        self.write(&(text.len() as u64).to_le_bytes());
        self.write(text.as_bytes());
    }

    pub fn finish(self) -> u64 {
        self.0
    }
}

/// Draws the scene's wavelengths from `density` in place of the film's own. The density joins
/// the scene's fingerprint, so a render state records it: resuming or merging with another
/// density is refused.
pub fn override_wavelengths(scene: &mut Scene, density: WavelengthSampling) {
    scene.film.wavelength_sampling = density;
    mix_into_fingerprint(scene, "wavelength_sampling", density.name());
}

/// Sets the film's reconstruction in place of the scene's (a command-line override), and mixes
/// it into the fingerprint so that a render state records it.
pub fn override_reconstruction(scene: &mut Scene, reconstruction: Reconstruction) {
    scene.film.reconstruction = reconstruction;
    mix_into_fingerprint(scene, "reconstruction", reconstruction.name());
}

/// The fingerprint of a scene seen through its sensor `index`: the description's, mixed with the
/// index but for the first sensor.
pub fn with_sensor(description: u64, index: usize) -> u64 {
    if index == 0 {
        return description;
    }
    let mut hash = Fnv64::default();
    hash.write(&description.to_le_bytes());
    hash.write_str("sensor");
    hash.write(&(index as u64).to_le_bytes());
    hash.finish()
}

fn mix_into_fingerprint(scene: &mut Scene, setting: &str, value: &str) {
    let mut hash = Fnv64::default();
    hash.write(&scene.fingerprint.to_le_bytes());
    hash.write_str(setting);
    hash.write_str(value);
    scene.fingerprint = hash.finish();
}

/// Hashes a plugin tree: each node's class, type, properties and children, recursively, and the
/// bytes of every file a `filename` property names (files that cannot be read hash as absent:
/// building the scene reports them).
pub fn scene_fingerprint(root: &PluginNode) -> u64 {
    let mut hash = Fnv64::default();
    add_node(&mut hash, root);
    hash.finish()
}

fn add_node(hash: &mut Fnv64, node: &PluginNode) {
    hash.write_str(node.class.tag());
    hash.write_str(&node.plugin_type);
    for property in &node.properties {
        hash.write_str(&property.name);
        match &property.value {
            // A mesh's arrays: their bits, without formatting millions of numbers.
            PropertyValue::Numbers(values) => {
                hash.write(&(values.len() as u64).to_le_bytes());
                for value in values {
                    hash.write(&value.to_le_bytes());
                }
            }
            PropertyValue::Tensor { shape, values } => {
                for &n in shape {
                    hash.write(&(n as u64).to_le_bytes());
                }
                hash.write(&(values.len() as u64).to_le_bytes());
                for value in values {
                    hash.write(&value.to_le_bytes());
                }
            }
            value => hash.write_str(&format!("{value:?}")),
        }
        if property.name == "filename"
            && let PropertyValue::String(name) = &property.value
            && let Ok(path) = node.resolve_file(name, &property.location)
            && let Ok(bytes) = crate::file_cache::read(&path)
        {
            hash.write(&bytes);
        }
    }
    for child in &node.children {
        hash.write_str(child.name.as_deref().unwrap_or(""));
        add_node(hash, &child.node);
    }
}
