//! `prism render --denoise`: the finished image denoised by Open Image Denoise
//! ([`crate::denoise`]) and written as the EXR's channels `denoised.R`, `denoised.G`,
//! `denoised.B` and as the 8-bit image. The noisy channels stay as they are, with their variance
//! and relative error: the error bars are the noisy estimate's, not the denoised image's.
//!
//! The denoiser is guided by the albedo and shading normal of the surface each pixel sees first.
//! A scene whose integrator is `aov` with an `albedo` and a `sh_normal` variable has them in its
//! film, averaged over the image's samples. For any other scene they are rendered after the
//! image, with the scene's sampler, filter and seed, by an `aov` integrator alone at
//! [`GUIDE_SPP`] samples per pixel: camera rays to their first hit, which cost little beside the
//! image's paths and leave the guides free of noise but at edges (antialiasing, defocus), so
//! that the denoiser may keep their detail. These are written too, as `denoise.albedo.R`, `.G`, `.B` and
//! `denoise.normal.X`, `.Y`, `.Z`.

use std::path::Path;

use crate::denoise::{DenoiseInput, denoise};
use prism_core::error::Result;
use prism_core::film::output::ALPHA_CHANNEL;
use prism_core::film::{Film, FilmImages, ImageOutput};
use prism_core::image::write_exr_with;
use prism_core::integrator::Integrator;
use prism_core::integrator::aov::{Aov, AovIntegrator, AovKind};
use prism_core::render::{RenderOptions, render};
use prism_core::scene::Scene;

/// Samples per pixel of the guides rendered for a scene that has none.
pub const GUIDE_SPP: u32 = 16;

/// The denoiser's guides: albedo and shading normal, three interleaved values per pixel.
struct Guides {
    albedo: Vec<f32>,
    normal: Vec<f32>,
    /// Whether they were rendered here at [`GUIDE_SPP`] (and so are treated as free of noise
    /// and written to the EXR) rather than taken from the scene's film.
    rendered: bool,
}

/// Denoises the rendered `film` of `scene` and writes the EXR (the film's channels and the
/// denoised ones) and the 8-bit image (denoised) as `output` asks. The scene's integrator is
/// lent to the guides' render and given back.
pub fn write_denoised_images(
    scene: &mut Scene,
    film: &Film,
    seed: u64,
    threads: Option<usize>,
    exr_path: &Path,
    ldr_path: &Path,
    output: &ImageOutput,
) -> Result<()> {
    let guides = match film_guides(scene, film) {
        Some(guides) => guides,
        None => render_guides(scene, seed, threads)?,
    };
    let (width, height) = (film.crop.size.x as usize, film.crop.size.y as usize);
    let images = FilmImages::of(film);
    let denoised = denoise(&DenoiseInput {
        width,
        height,
        color: &images.rgb,
        albedo: &guides.albedo,
        normal: &guides.normal,
        clean_guides: guides.rendered,
        threads,
    })?;

    let mut channels: Vec<(String, Vec<f32>)> = (film.aov_names.iter().cloned())
        .enumerate()
        .map(|(c, name)| (name, film.aov(c)))
        .collect();
    channels.extend(planar("denoised", ["R", "G", "B"], &denoised));
    if guides.rendered {
        channels.extend(planar("denoise.albedo", ["R", "G", "B"], &guides.albedo));
        channels.extend(planar("denoise.normal", ["X", "Y", "Z"], &guides.normal));
    }
    let (image, header) = images.exr(channels, &output.exr, output.metadata.as_ref());
    write_exr_with(exr_path, &image, &header)?;
    let alpha = (film.aov_names.iter())
        .position(|name| name == ALPHA_CHANNEL)
        .map(|c| film.aov(c));
    let rgb: Vec<[f32; 3]> = (denoised.chunks_exact(3))
        .map(|v| [v[0], v[1], v[2]])
        .collect();
    output.ldr.write(
        ldr_path,
        film.crop.size.x,
        film.crop.size.y,
        &rgb,
        alpha.as_deref(),
    )
}

/// The guides in the film of a scene whose `aov` integrator has an `albedo` and a `sh_normal`
/// variable (the first of each).
fn film_guides(scene: &Scene, film: &Film) -> Option<Guides> {
    let Integrator::Aov(integrator) = &scene.integrator else {
        return None;
    };
    let interleaved = |kind: AovKind| -> Option<Vec<f32>> {
        let aov = integrator.aovs.iter().find(|aov| aov.kind == kind)?;
        let channels = (kind.channels().iter())
            .map(|c| {
                let name = format!("{}.{c}", aov.name);
                let index = film.aov_names.iter().position(|n| *n == name)?;
                Some(film.aov(index))
            })
            .collect::<Option<Vec<_>>>()?;
        Some(interleave(&channels))
    };
    Some(Guides {
        albedo: interleaved(AovKind::Albedo)?,
        normal: interleaved(AovKind::ShadingNormal)?,
        rendered: false,
    })
}

/// The guides rendered by an `aov` integrator alone at [`GUIDE_SPP`] samples per pixel.
fn render_guides(scene: &mut Scene, seed: u64, threads: Option<usize>) -> Result<Guides> {
    let aov = |name: &str, kind| Aov {
        name: name.into(),
        kind,
    };
    let guides = AovIntegrator {
        aovs: vec![
            aov("albedo", AovKind::Albedo),
            aov("normal", AovKind::ShadingNormal),
        ],
        integrators: Vec::new(),
    };
    let image_integrator = std::mem::replace(&mut scene.integrator, guides.into());
    let spp = scene.sampler.kind.sample_count(GUIDE_SPP);
    let rendered = render(scene, &RenderOptions::fixed(spp, seed, threads));
    scene.integrator = image_integrator;
    let film = rendered?.film;
    let channel = |name: &str| {
        let index = film.aov_names.iter().position(|n| n == name);
        film.aov(index.expect("the guides' render has their channels"))
    };
    let albedo = ["albedo.R", "albedo.G", "albedo.B"].map(channel);
    let normal = ["normal.X", "normal.Y", "normal.Z"].map(channel);
    Ok(Guides {
        albedo: interleave(&albedo),
        normal: interleave(&normal),
        rendered: true,
    })
}

/// Three channels of one value per pixel as one array of three interleaved values per pixel.
fn interleave(channels: &[Vec<f32>]) -> Vec<f32> {
    let pixels = channels.first().map_or(0, Vec::len);
    (0..pixels)
        .flat_map(|i| channels.iter().map(move |c| c[i]))
        .collect()
}

/// Named EXR channels `prefix.suffix` of an array of three interleaved values per pixel.
fn planar(prefix: &str, suffixes: [&str; 3], values: &[f32]) -> Vec<(String, Vec<f32>)> {
    (suffixes.iter().enumerate())
        .map(|(c, suffix)| {
            let channel = values.iter().skip(c).step_by(3).copied().collect();
            (format!("{prefix}.{suffix}"), channel)
        })
        .collect()
}
