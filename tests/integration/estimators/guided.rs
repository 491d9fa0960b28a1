//! Practical path guiding (`guided_path`): against a closed form (a furnace), against the path
//! tracer on the Cornell box (a z-test), bit-identical for any thread count, a scene in the
//! form of the authors' rendering as written, its bad parameters refused; resumed after any
//! pass (in the library and through `prism render --resume`) equal to one render, runs of
//! sample ranges merged as documented, and states that do not fit refused. Its quadtree's
//! sampling is tested against its density beside the quadtree (`integrator::guided::quadtree`).

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicU32, Ordering};
use std::time::{Duration, Instant};

use glam::{DVec3, Mat3, UVec2, Vec3};
use prism_core::film::Film;
use prism_core::film::{CropWindow, PixelSums};
use prism_core::geometry::{Shape, Sphere};
use prism_core::integrator::guided::selection::SelectionLoss;
use prism_core::integrator::guided::{Adrrs, Budget, NextEvent, SampleCombination, SpatialFilter};
use prism_core::integrator::{GuidedPathIntegrator, Integrator, PathIntegrator};
use prism_core::render::resume::InitialState;
use prism_core::render::state::{IntegratorState, RenderIdentity, RenderState};
use prism_core::render::{
    Checkpoints, ProgressReport, RenderOptions, RenderOutput, Snapshot, StopReason, StopRule,
    render, render_with_checkpoints,
};
use prism_core::scene::Scene;

use crate::common::scenes::{
    Object, assert_identical_images, assert_mean_luminance, build, camera,
    image_mean_and_standard_error, render_film, scene_from_xml,
};

/// The guided path tracer with small spatial leaves, so that a small image trains a tree of
/// several leaves.
fn guided() -> GuidedPathIntegrator {
    GuidedPathIntegrator {
        s_tree_threshold: 500.0,
        sample_combination: SampleCombination::Discard,
        ..GuidedPathIntegrator::default()
    }
}

/// Inside a sphere of reflectance rho that emits le everywhere, the radiance is
/// le / (1 − rho) = 2 in every direction: the image's mean Y is 2 within 4 standard errors, with
/// light samples (`always`) and without (`never`), with α fixed and learned (`kl`, `var`), and
/// with Russian roulette by the learned radiance, `path`'s, and with splitting.
#[test]
fn guided_sphere_furnace_gives_le_over_one_minus_rho() {
    let cases = [
        (NextEvent::Always, SelectionLoss::None, Adrrs::Roulette),
        (NextEvent::Never, SelectionLoss::None, Adrrs::Roulette),
        (
            NextEvent::Always,
            SelectionLoss::KullbackLeibler,
            Adrrs::Roulette,
        ),
        (NextEvent::Never, SelectionLoss::Variance, Adrrs::Roulette),
        (NextEvent::Always, SelectionLoss::None, Adrrs::Off),
        (NextEvent::Never, SelectionLoss::None, Adrrs::Splitting),
    ];
    for (nee, loss, adrrs) in cases {
        let size = UVec2::new(16, 16);
        let camera = camera(
            DVec3::new(0.1, 0.2, -0.3),
            DVec3::new(0.5, 0.3, 1.0),
            DVec3::Y,
            70.0,
            size,
        );
        let sphere = Shape::Sphere(Sphere {
            center: Vec3::ZERO,
            radius: 1.0,
            rotation: Mat3::IDENTITY,
            flip_normals: true,
        });
        let object = Object {
            shape: sphere.into(),
            reflectance: 0.5,
            emission: Some(1.0),
        };
        let integrator = GuidedPathIntegrator {
            nee,
            bsdf_sampling_fraction_loss: loss,
            adrrs,
            ..guided()
        };
        let scene = build(vec![object], vec![], camera, size, integrator);
        let film = render_film(&scene, 1024, 1, None);
        assert_mean_luminance(&format!("{nee:?}, {loss:?}, {adrrs:?}"), &film, 2.0);
    }
}

fn cornell_box(size: u32) -> Scene {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/cornell-box/scene.xml");
    let defines = [
        ("resx".to_string(), size.to_string()),
        ("resy".to_string(), size.to_string()),
    ];
    prism_mitsuba::load_scene(&path, &defines).unwrap().scene
}

/// On the Cornell box the image means of X, Y and Z agree with the path tracer's within 4
/// combined standard errors (the guided image is the last iteration's, 516 of 1024 samples per
/// pixel), with Russian roulette by the learned radiance and with splitting too, and the
/// combined standard error is small enough to see a 4 % difference.
#[test]
fn guided_and_path_agree_on_the_cornell_box() {
    let mut scene = cornell_box(32);
    let path = render_film(&scene, 1024, 3, None);
    for adrrs in [Adrrs::Roulette, Adrrs::Splitting] {
        scene.integrator = Integrator::from(GuidedPathIntegrator { adrrs, ..guided() });
        let guided = render_film(&scene, 1024, 4, None);
        for c in 0..3 {
            let (a, sa) = image_mean_and_standard_error(&guided, c);
            let (b, sb) = image_mean_and_standard_error(&path, c);
            let se = (sa * sa + sb * sb).sqrt();
            assert!(
                se < 0.01 * b,
                "{adrrs:?}, channel {c}: standard error {se} of {b}"
            );
            assert!(
                (a - b).abs() < 4.0 * se,
                "{adrrs:?}, channel {c}: guided {a} ± {sa}, path {b} ± {sb}"
            );
        }
    }
}

/// The same image, bit for bit, on one thread and on two: with the nearest and the stochastic
/// spatial filter and with `kickstart` light samples, with the inverse-variance mix, with α
/// learned, and with paths split by the learned radiance.
#[test]
fn guided_is_deterministic_for_any_thread_count() {
    let variants = [
        guided(),
        GuidedPathIntegrator {
            spatial_filter: SpatialFilter::StochasticBox,
            nee: NextEvent::Kickstart,
            ..guided()
        },
        GuidedPathIntegrator {
            sample_combination: SampleCombination::InverseVariance,
            ..guided()
        },
        GuidedPathIntegrator {
            bsdf_sampling_fraction_loss: SelectionLoss::KullbackLeibler,
            ..guided()
        },
        GuidedPathIntegrator {
            adrrs: Adrrs::Splitting,
            ..guided()
        },
    ];
    for integrator in variants {
        let mut scene = cornell_box(20);
        scene.integrator = Integrator::from(integrator.clone());
        let one = render_film(&scene, 28, 7, Some(1));
        let two = render_film(&scene, 28, 7, Some(2));
        let same = one
            .pixels
            .iter()
            .zip(&two.pixels)
            .all(|(a, b)| a.mean() == b.mean() && a.samples == b.samples);
        assert!(same, "{integrator:?}: the images differ");
        assert!(mean_y(&one) > 0.0, "{integrator:?}: black");
    }
}

fn mean_y(film: &Film) -> f64 {
    film.pixels.iter().map(|p| p.mean()[1]).sum::<f64>() / film.pixels.len() as f64
}

/// A scene in the form of the authors' (Mitsuba 0.5, their parameter names and values) renders
/// as written: its budget of 12 samples per pixel in passes of 1 gives iterations of 1, 2 and
/// then the remaining 9 passes, the last of which is the image.
#[test]
fn guided_scene_of_the_authors_form_renders_as_written() {
    let xml = r#"<scene version="0.5.0">
        <integrator type="guided_path">
            <integer name="sppPerPass" value="1"/>
            <string name="nee" value="never"/>
            <string name="budgetType" value="spp"/>
            <float name="budget" value="12"/>
            <boolean name="strictNormals" value="true"/>
            <integer name="sTreeThreshold" value="1024"/>
            <float name="dTreeThreshold" value="0.01"/>
            <float name="bsdfSamplingFraction" value="0.5"/>
            <string name="sampleCombination" value="discard"/>
            <boolean name="doFilteredSplatting" value="true"/>
            <integer name="maxDepth" value="40"/>
            <integer name="rrDepth" value="5"/>
        </integrator>
        <sensor type="perspective">
            <transform name="toWorld"><lookAt origin="0, 0, -3" target="0, 0, 0" up="0, 1, 0"/></transform>
            <film type="hdrfilm"><integer name="width" value="12"/><integer name="height" value="12"/></film>
        </sensor>
        <shape type="sphere"><bsdf type="diffuse"/></shape>
        <emitter type="constant"><spectrum name="radiance" value="1"/></emitter>
    </scene>"#;
    let scene = scene_from_xml(xml, "guided-authors.xml").unwrap();
    let Integrator::Guided(integrator) = &scene.integrator else {
        panic!("not guided_path: {:?}", scene.integrator);
    };
    assert_eq!(integrator.spp_per_pass, 1);
    assert_eq!(integrator.nee, NextEvent::Never);
    assert_eq!(integrator.spatial_filter, SpatialFilter::StochasticBox);
    assert_eq!(integrator.max_depth, 40);
    let output = render(&scene, &RenderOptions::fixed(1, 0, None)).unwrap();
    assert_eq!(output.samples, 0..12);
    assert!(output.film.pixels.iter().all(|p| p.samples == 9));
    assert!(mean_y(&output.film) > 0.0);
}

/// Parameters outside their ranges, and values of the authors' Prism does not implement, are
/// refused when the scene is read, at the parameter's file:line:col and naming it.
#[test]
fn guided_refuses_bad_parameters() {
    let cases = [
        (
            r#"<integer name="spp_per_pass" value="0"/>"#,
            "spp_per_pass",
        ),
        (r#"<float name="budget" value="-2"/>"#, "budget"),
        (r#"<float name="budget" value="0.5"/>"#, "budget"),
        (
            r#"<string name="budget_type" value="passes"/>"#,
            "budget_type",
        ),
        (
            r#"<string name="sample_combination" value="mean"/>"#,
            "sample_combination",
        ),
        (
            r#"<float name="s_tree_threshold" value="0"/>"#,
            "s_tree_threshold",
        ),
        (
            r#"<float name="d_tree_threshold" value="1"/>"#,
            "d_tree_threshold",
        ),
        (
            r#"<float name="bsdf_sampling_fraction" value="0"/>"#,
            "bsdf_sampling_fraction",
        ),
        (
            r#"<float name="bsdf_sampling_fraction" value="1.5"/>"#,
            "bsdf_sampling_fraction",
        ),
        (r#"<string name="nee" value="sometimes"/>"#, "nee"),
        (
            r#"<string name="spatial_filter" value="box"/>"#,
            "spatial_filter",
        ),
        (
            r#"<string name="directional_filter" value="box"/>"#,
            "directional_filter",
        ),
        (
            r#"<string name="bsdf_sampling_fraction_loss" value="kld"/>"#,
            "bsdf_sampling_fraction_loss",
        ),
        (
            r#"<boolean name="dump_sd_tree" value="true"/>"#,
            "dump_sd_tree",
        ),
        (
            r#"<integer name="sd_tree_max_memory" value="0"/>"#,
            "sd_tree_max_memory",
        ),
        (r#"<integer name="max_depth" value="-2"/>"#, "max_depth"),
        (r#"<string name="adrrs" value="on"/>"#, "adrrs"),
    ];
    for (parameter, name) in cases {
        let xml = format!(
            "<scene version=\"3.0.0\">\n<integrator type=\"guided_path\">\n{parameter}\n\
             </integrator>\n<shape type=\"sphere\"><bsdf type=\"diffuse\"/></shape></scene>"
        );
        let error = match scene_from_xml(&xml, "guided-test.xml") {
            Ok(_) => panic!("{parameter} was accepted"),
            Err(error) => error.to_string(),
        };
        assert!(error.contains(name), "{parameter}: {error}");
        assert!(error.contains("guided-test.xml:3:"), "{parameter}: {error}");
    }
}

/// A target error is refused with a message naming guided_path, and so is a sample range that
/// is no whole number of passes or whose run would have a budget of its own.
#[test]
fn guided_refuses_a_target_error_and_ranges_it_cannot_render() {
    let mut scene = cornell_box(8);
    scene.integrator = Integrator::from(guided());
    let target = RenderOptions {
        stop: StopRule {
            target_error: Some(0.01),
            ..StopRule::samples(4)
        },
        ..RenderOptions::fixed(4, 0, None)
    };
    let error = render(&scene, &target).err().expect("accepted").to_string();
    assert!(
        error.contains("guided_path") && error.contains("target error"),
        "{error}"
    );
    let uneven = RenderOptions {
        first_sample: 2,
        ..RenderOptions::fixed(8, 0, None)
    };
    let error = render(&scene, &uneven).err().expect("accepted").to_string();
    assert!(error.contains("multiple of sppPerPass"), "{error}");
    scene.integrator = Integrator::from(GuidedPathIntegrator {
        budget: Budget::Samples(Some(8)),
        ..guided()
    });
    let later = RenderOptions {
        first_sample: 4,
        ..RenderOptions::fixed(8, 0, None)
    };
    let error = render(&scene, &later).err().expect("accepted").to_string();
    assert!(error.contains("budget at -1"), "{error}");
}

/// Raises the render's interrupt flag when its `after`-th pass is done, so that the render
/// stops with exactly that many passes (the next one sees the flag before its first row).
#[derive(Debug)]
struct InterruptAfter {
    after: u32,
    passes: AtomicU32,
    flag: Arc<AtomicBool>,
}

impl ProgressReport for InterruptAfter {
    fn begin(&self, _total: Option<u64>) {}
    fn advance(&self, _samples: u64) {}
    fn pass_done(&self, _spp: u32, _error: f64) {
        if self.passes.fetch_add(1, Ordering::SeqCst) + 1 == self.after {
            self.flag.store(true, Ordering::SeqCst);
        }
    }
    fn end(&self) {}
}

/// Renders `scene` (`spp` samples, seed 5, `threads`) from `first_sample`, continuing
/// `initial`, interrupted after `after` passes if given.
fn render_part(
    scene: &Scene,
    spp: u32,
    threads: usize,
    first_sample: u32,
    initial: Option<InitialState>,
    after: Option<u32>,
) -> prism_core::error::Result<RenderOutput> {
    let flag = Arc::new(AtomicBool::new(false));
    let mut options = RenderOptions::fixed(spp, 5, Some(threads));
    options.first_sample = first_sample;
    options.initial = initial;
    if let Some(after) = after {
        options.interrupt = Some(flag.clone());
        options.progress = Some(Arc::new(InterruptAfter {
            after,
            passes: AtomicU32::new(0),
            flag,
        }));
    }
    render(scene, &options)
}

/// Interrupts the run of `scene` (`spp` samples per pixel in passes of `spp_per_pass`) after
/// each of the passes `points`, on one thread and on two, resumes it, and checks that it ends
/// with the film and the state of one uninterrupted run, which it returns.
fn assert_resumed_equals_one_render(
    scene: &Scene,
    spp: u32,
    spp_per_pass: u32,
    points: &[u32],
) -> RenderOutput {
    let whole = render_part(scene, spp, 2, 0, None, None).unwrap();
    assert_eq!(whole.samples, 0..spp);
    assert!(whole.integrator_state.is_some());
    for threads in [1, 2] {
        for &after in points {
            let part = render_part(scene, spp, threads, 0, None, Some(after)).unwrap();
            assert_eq!(part.stop, StopReason::Interrupted);
            assert_eq!(part.samples, 0..after * spp_per_pass);
            let rest = render_part(
                scene,
                spp,
                threads,
                part.samples.end,
                Some(part.initial_state()),
                None,
            )
            .unwrap();
            assert_eq!(rest.stop, StopReason::Completed);
            assert_eq!(rest.samples, part.samples.end..spp);
            let what = format!(
                "{:?}, {threads} threads, after pass {after}",
                scene.integrator
            );
            assert!(
                rest.film.pixels == whole.film.pixels,
                "{what}: the films differ"
            );
            assert!(
                rest.film.aovs == whole.film.aovs,
                "{what}: the channels differ"
            );
            assert!(
                rest.integrator_state == whole.integrator_state,
                "{what}: the states differ"
            );
        }
    }
    whole
}

/// Interrupted after any pass (within an iteration and at its end), on one thread and on
/// two, then resumed, a run ends with the film and the state of one uninterrupted run: with
/// `discard`; with the inverse-variance mix, `kickstart` light samples, the stochastic filter
/// and α learned; and with splitting by the learned radiance (`automatic`). One run is
/// interrupted twice.
#[test]
fn guided_resumed_after_any_pass_equals_one_render() {
    let variants = [
        guided(),
        GuidedPathIntegrator {
            sample_combination: SampleCombination::InverseVariance,
            nee: NextEvent::Kickstart,
            spatial_filter: SpatialFilter::StochasticBox,
            bsdf_sampling_fraction_loss: SelectionLoss::KullbackLeibler,
            ..guided()
        },
        GuidedPathIntegrator {
            sample_combination: SampleCombination::Automatic,
            adrrs: Adrrs::Splitting,
            spp_per_pass: 2,
            ..guided()
        },
    ];
    for integrator in variants {
        let mut scene = cornell_box(12);
        scene.integrator = Integrator::from(integrator.clone());
        // 7 passes: iterations of 1, 2 and 4.
        let spp = 7 * integrator.spp_per_pass;
        let whole = assert_resumed_equals_one_render(
            &scene,
            spp,
            integrator.spp_per_pass,
            &[1, 2, 3, 4, 5, 6],
        );
        let first = render_part(&scene, spp, 2, 0, None, Some(2)).unwrap();
        let second = render_part(
            &scene,
            spp,
            1,
            first.samples.end,
            Some(first.initial_state()),
            Some(3),
        )
        .unwrap();
        assert_eq!(
            second.samples,
            2 * integrator.spp_per_pass..5 * integrator.spp_per_pass
        );
        let rest = render_part(
            &scene,
            spp,
            2,
            second.samples.end,
            Some(second.initial_state()),
            None,
        )
        .unwrap();
        assert!(
            rest.film.pixels == whole.film.pixels,
            "{integrator:?}: twice interrupted"
        );
    }
}

/// A checkpoint is written after every pass when due (here always) and at the end: each holds
/// the samples so far, the image the render would give if it stopped there, and a state from
/// which the run, resumed, ends as one uninterrupted render.
#[test]
fn guided_checkpoints_resume_to_one_render() {
    let mut scene = cornell_box(8);
    scene.integrator = Integrator::from(GuidedPathIntegrator {
        sample_combination: SampleCombination::InverseVariance,
        ..guided()
    });
    let whole = render_part(&scene, 28, 2, 0, None, None).unwrap();
    let mut saved: Vec<(std::ops::Range<u32>, InitialState)> = Vec::new();
    let mut write = |snapshot: &Snapshot| {
        saved.push((snapshot.samples.clone(), snapshot.initial_state()));
        Ok(())
    };
    let checkpoints = Checkpoints {
        every: Duration::ZERO,
        write: &mut write,
    };
    let options = RenderOptions::fixed(28, 5, Some(2));
    let output = render_with_checkpoints(&scene, &options, Some(checkpoints)).unwrap();
    assert!(output.film.pixels == whole.film.pixels);
    // One after each of the 7 passes, and the last again at the end.
    let ends: Vec<u32> = saved.iter().map(|(samples, _)| samples.end).collect();
    assert_eq!(ends, [4, 8, 12, 16, 20, 24, 28, 28]);
    for (samples, initial) in saved.into_iter().take(6) {
        let part = render_part(&scene, 28, 2, 0, None, Some(samples.end / 4)).unwrap();
        assert!(
            part.film.pixels == initial.pixels,
            "the image after {samples:?}"
        );
        let rest = render_part(&scene, 28, 1, samples.end, Some(initial), None).unwrap();
        assert!(
            rest.film.pixels == whole.film.pixels,
            "resumed after {samples:?}"
        );
    }
}

/// `automatic` stops training where the extrapolated variance grows, from 256 samples per
/// pixel on: on a 4 × 4 image in passes of 64 samples, a run of 100 passes stops after
/// iterations of 1, 2, 4 and 8 passes and renders the other 85 from the tree it has (the
/// image holds 85 · 64 samples per pixel, where the iterations would end with one of 69
/// passes). Interrupted in any iteration and resumed, that run too equals one render.
#[test]
fn guided_resumed_after_training_stopped_equals_one_render() {
    let mut scene = cornell_box(4);
    let integrator = GuidedPathIntegrator {
        sample_combination: SampleCombination::Automatic,
        spp_per_pass: 64,
        ..guided()
    };
    scene.integrator = Integrator::from(integrator);
    let whole = assert_resumed_equals_one_render(&scene, 6400, 64, &[1, 3, 7, 15, 16, 60, 99]);
    assert!(
        whole.film.pixels.iter().all(|p| p.samples == 85 * 64),
        "training did not stop after the fourth iteration"
    );
}

/// A render state of `output` (a run of `scene`'s samples `range`), as the command line
/// writes it.
fn state_of(scene: &Scene, output: &RenderOutput) -> RenderState {
    RenderState {
        identity: RenderIdentity {
            scene: 1,
            seed: 5,
            sampler: "independent".into(),
            samples_per_pixel: 32,
            film_size: scene.film.size,
            crop: CropWindow {
                offset: UVec2::ZERO,
                size: scene.film.crop.size,
            },
        },
        ranges: vec![output.samples.clone()],
        pixels: output.film.pixels.clone(),
        aov_names: output.film.aov_names.clone(),
        aovs: output.film.aovs.clone(),
        integrator_state: output.integrator_state.clone(),
    }
}

/// Runs of the sample ranges 0..8 and 8..32 are independent runs (the second is not the end
/// of a run of 0..32), and `prism merge` of their states gives, with `discard`, the sums of
/// their final images, and with `inversevar` the mean of their images weighted 1/4 and 3/4
/// (their ranges' samples), one value per pixel. The merged state is refused on resume, and
/// states of runs that combine their images differently are not merged.
#[test]
fn guided_runs_of_sample_ranges_merge_as_documented() {
    for combination in [
        SampleCombination::Discard,
        SampleCombination::InverseVariance,
    ] {
        let mut scene = cornell_box(10);
        scene.integrator = Integrator::from(GuidedPathIntegrator {
            sample_combination: combination,
            ..guided()
        });
        let a = render_part(&scene, 8, 2, 0, None, None).unwrap();
        let mut options = RenderOptions::fixed(32, 5, Some(2));
        options.first_sample = 8;
        let b = render(&scene, &options).unwrap();
        assert_eq!(b.samples, 8..32);
        let paths = [Path::new("a.state"), Path::new("b.state")];
        let merged =
            RenderState::merge(&[state_of(&scene, &a), state_of(&scene, &b)], &paths).unwrap();
        assert_eq!(merged.ranges, vec![0..32]);
        let expected: Vec<PixelSums> = a
            .film
            .pixels
            .iter()
            .zip(&b.film.pixels)
            .map(|(p, q)| match combination {
                SampleCombination::InverseVariance => {
                    let (m, n) = (p.mean(), q.mean());
                    let mut sums = PixelSums::default();
                    sums.add_total([0, 1, 2].map(|c| 0.25 * m[c] + 0.75 * n[c]));
                    sums
                }
                _ => {
                    let mut sums = *p;
                    sums.merge(q);
                    sums
                }
            })
            .collect();
        assert!(
            merged.pixels == expected,
            "{combination:?}: not the documented merge"
        );
        let initial = InitialState {
            pixels: merged.pixels.clone(),
            aovs: merged.aovs.clone(),
            integrator: merged.integrator_state.clone(),
        };
        let error = render_part(&scene, 64, 2, 32, Some(initial), None)
            .err()
            .expect("a merged state was resumed")
            .to_string();
        assert!(error.contains("merge"), "{error}");
        let mut other = state_of(&scene, &b);
        other.integrator_state = Some(IntegratorState {
            integrator: "guided_path".into(),
            bytes: b"PPG\0\x01\0\0\0\x01\x01".to_vec(),
        });
        let error = RenderState::merge(&[state_of(&scene, &a), other], &paths)
            .unwrap_err()
            .to_string();
        assert!(error.contains("sampleCombination"), "{error}");
    }
}

/// A guided run's state that is cut short or damaged is refused with a message naming it, never
/// a panic; a state of another crop or sample count, of a `path` render, and a guided state
/// given to `path` are refused too.
#[test]
fn guided_refuses_states_that_do_not_fit() {
    let mut scene = cornell_box(6);
    scene.integrator = Integrator::from(guided());
    let part = render_part(&scene, 16, 1, 0, None, Some(2)).unwrap();
    let initial = part.initial_state();
    let bytes = initial.integrator.clone().unwrap().bytes;
    let resume = |bytes: Vec<u8>| {
        let mut damaged = initial.clone();
        damaged.integrator = Some(IntegratorState {
            integrator: "guided_path".into(),
            bytes,
        });
        render_part(&scene, 16, 1, 8, Some(damaged), None)
            .err()
            .map(|e| e.to_string())
    };
    assert_eq!(resume(bytes.clone()), None, "the state itself is refused");
    let lengths = (0..bytes.len()).filter(|n| *n < 64 || n % 61 == 0);
    for n in lengths {
        let error = resume(bytes[..n].to_vec()).unwrap_or_else(|| panic!("cut to {n} accepted"));
        assert!(
            error.contains("guided_path state is damaged"),
            "cut to {n}: {error}"
        );
    }
    let mut longer = bytes.clone();
    longer.push(0);
    let error = resume(longer).expect("a longer state was accepted");
    assert!(error.contains("follow its end"), "{error}");
    for (at, value, says) in [
        (0, b'X', "tag"),
        (4, 9, "version 9"),
        (9, 7, "sample combination"),
    ] {
        let mut damaged = bytes.clone();
        damaged[at] = value;
        let error = resume(damaged).expect("a damaged state was accepted");
        assert!(error.contains(says), "{error}");
    }
    let mut larger = cornell_box(7);
    larger.integrator = Integrator::from(guided());
    let error = render_part(&larger, 16, 1, 8, Some(initial.clone()), None)
        .err()
        .expect("resumed with another crop")
        .to_string();
    assert!(error.contains("6×6 crop"), "{error}");
    let error = render_part(&scene, 32, 1, 8, Some(initial.clone()), None)
        .err()
        .expect("resumed with another sample count")
        .to_string();
    assert!(
        error.contains("planned for 16 samples per pixel"),
        "{error}"
    );
    let sums = InitialState::sums(initial.pixels.clone(), initial.aovs.clone());
    let error = render_part(&scene, 16, 1, 8, Some(sums), None)
        .err()
        .expect("resumed from a state without guided_path's")
        .to_string();
    assert!(
        error.contains("cannot resume this guided_path render"),
        "{error}"
    );
    let mut path = cornell_box(6);
    path.integrator = Integrator::from(PathIntegrator::default());
    let error = render_part(&path, 16, 1, 8, Some(initial), None)
        .err()
        .expect("path resumed a guided_path state")
        .to_string();
    assert!(error.contains("guided_path render"), "{error}");
}

/// `prism render` of the Cornell box lit through a gap with `guided_path`, checkpointing,
/// stopped by SIGINT with its state saved, then resumed with `--resume`, writes the image of
/// one uninterrupted render bit for bit; runs of two sample ranges merge with `prism merge`,
/// and the merged state is refused by `--resume`.
#[test]
fn guided_checkpoint_and_resume_through_the_command_line() {
    let dir = std::env::temp_dir().join(format!("prism-guided-resume-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/guided/cornell-gap.xml");
    let arguments = |output: &Path, spp: u32, extra: &[&str]| -> Vec<String> {
        let mut a: Vec<String> = vec![
            "render".into(),
            scene.to_str().unwrap().into(),
            "-D".into(),
            "resx=16".into(),
            "-D".into(),
            "resy=16".into(),
            "--spp".into(),
            spp.to_string(),
            "--threads".into(),
            "2".into(),
            "--quiet".into(),
            "-o".into(),
            output.to_str().unwrap().into(),
        ];
        a.extend(extra.iter().map(|s| s.to_string()));
        a
    };
    let prism = |arguments: &[String]| {
        let output = Command::new(env!("CARGO_BIN_EXE_prism"))
            .args(arguments)
            .output()
            .unwrap();
        (
            output.status.code().unwrap_or(-1),
            String::from_utf8_lossy(&output.stderr).into_owned(),
        )
    };
    // Long enough (a few seconds) to be interrupted after its first checkpoint.
    let spp = 4000;
    let reference = dir.join("reference.exr");
    let (status, text) = prism(&arguments(&reference, spp, &[]));
    assert_eq!(status, 0, "{text}");
    let output = dir.join("image.exr");
    let state = dir.join("image.state");
    let state_arg = state.to_str().unwrap();
    let mut child = Command::new(env!("CARGO_BIN_EXE_prism"))
        .args(arguments(
            &output,
            spp,
            &["--checkpoint", state_arg, "--checkpoint-every", "0.05"],
        ))
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let start = Instant::now();
    while !state.exists() && start.elapsed() < Duration::from_secs(60) {
        std::thread::sleep(Duration::from_millis(5));
    }
    assert!(state.exists(), "no checkpoint was written in a minute");
    let killed = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(killed.success());
    let status = child.wait().unwrap();
    assert_eq!(status.code(), Some(130), "the render was not interrupted");
    let (status, text) = prism(&arguments(&output, spp, &["--resume", state_arg]));
    assert_eq!(status, 0, "{text}");
    assert_identical_images(&output, &reference);

    let mut states: Vec<PathBuf> = Vec::new();
    for (name, range) in [("a", "0..16"), ("b", "16..32")] {
        let part = dir.join(format!("{name}.state"));
        let exr = dir.join(format!("{name}.exr"));
        let extra = [
            "--sample-range",
            range,
            "--checkpoint",
            part.to_str().unwrap(),
        ];
        let (status, text) = prism(&arguments(&exr, 32, &extra));
        assert_eq!(status, 0, "{text}");
        states.push(part);
    }
    let merged_state = dir.join("merged.state");
    let merged = dir.join("merged.exr");
    let (status, text) = prism(&[
        "merge".into(),
        states[0].to_str().unwrap().into(),
        states[1].to_str().unwrap().into(),
        "-o".into(),
        merged.to_str().unwrap().into(),
        "--state".into(),
        merged_state.to_str().unwrap().into(),
    ]);
    assert_eq!(status, 0, "{text}");
    let (status, text) = prism(&arguments(
        &dir.join("more.exr"),
        32,
        &[
            "--sample-range",
            "0..64",
            "--resume",
            merged_state.to_str().unwrap(),
        ],
    ));
    assert_eq!(status, 2, "{text}");
    assert!(text.contains("merge of runs"), "{text}");
}
