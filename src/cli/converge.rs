//! `prism converge`: renders a scene at 1, 2, 4, … N samples per pixel, for one or several
//! integrators and samplers, and measures the relative MSE against a reference image, so that the
//! σ²/N law of the lecture can be seen: on a log–log plot every configuration is a line of slope
//! −1 (stratification may steepen it at low counts), and the better estimator is the lower line.
//!
//! Writes `OUT.csv` (integrator, sampler, spp, seconds, relMSE) and `OUT.png`, the log–log plot
//! with each line's least-squares slope in its legend.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::time::Instant;

use clap::Args;
use plotters::prelude::*;

use prism_core::error::{Error, Result};
use prism_core::image::compare::rel_mse_rgb;
use prism_core::image::read_exr;
use prism_core::integrator::{
    DirectIntegrator, DistributionIntegrator, Integrator, PathIntegrator, Tracking,
    VolPathIntegrator,
};
use prism_core::render::{RenderOptions, render};
use prism_core::sampling::sampler::SamplerKind;
use prism_core::scene::Scene;
use prism_mitsuba::load_scene;

#[derive(Args, Debug)]
pub struct ConvergeArgs {
    /// The Mitsuba 3 XML scene file
    pub scene: PathBuf,
    /// The reference image (OpenEXR with R, G, B) of the same size, rendered with many samples
    #[arg(long, value_name = "REF.exr")]
    pub reference: PathBuf,
    /// Largest sample count; the counts are the powers of two up to it
    #[arg(long, value_name = "N", default_value_t = 256)]
    pub max_spp: u32,
    /// Integrators to compare: path, distrib [default: the scene's]
    #[arg(long, value_delimiter = ',', value_name = "NAMES")]
    pub integrators: Option<Vec<String>>,
    /// Samplers to compare: independent, stratified, multijitter, nrooks [default: the scene's]
    #[arg(long, value_delimiter = ',', value_name = "NAMES")]
    pub samplers: Option<Vec<String>>,
    /// Output name: writes NAME.csv and NAME.png
    #[arg(short, long, value_name = "NAME", default_value = "converge")]
    pub output: PathBuf,
    /// Set a scene parameter declared with `<default name=... value=...>` (repeatable)
    #[arg(short = 'D', value_name = "NAME=VALUE", value_parser = super::render::parse_define)]
    pub defines: Vec<(String, String)>,
    /// Worker threads [default: one per core]
    #[arg(long, value_name = "T")]
    pub threads: Option<usize>,
    /// Seed of the first render (each render gets its own)
    #[arg(long, value_name = "S", default_value_t = 0)]
    pub seed: u64,
}

/// The results of one configuration.
struct Series {
    label: String,
    /// (spp, seconds, relMSE)
    points: Vec<(u32, f64, f64)>,
}

impl Series {
    /// Least-squares slope of ln relMSE against ln spp.
    fn slope(&self) -> f64 {
        let points: Vec<(f64, f64)> = self
            .points
            .iter()
            .filter(|p| p.2 > 0.0)
            .map(|p| (f64::from(p.0).ln(), p.2.ln()))
            .collect();
        let n = points.len() as f64;
        let mx = points.iter().map(|p| p.0).sum::<f64>() / n;
        let my = points.iter().map(|p| p.1).sum::<f64>() / n;
        points.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum::<f64>()
            / points.iter().map(|p| (p.0 - mx).powi(2)).sum::<f64>()
    }
}

/// The integrator `name`: the scene's own when it is that one, else that integrator's defaults
/// with the scene's depth limit.
fn integrator_named(name: &str, scene: &Scene) -> Result<Integrator> {
    let image = scene.integrator.image_integrator();
    let max_depth = match image {
        Integrator::Path(p) => p.max_depth,
        Integrator::PolarizedPath(p) => p.path.max_depth,
        Integrator::PolarizedVolPath(p) => p.volpath.max_depth,
        Integrator::Stokes(s) => s.nested.max_depth(),
        // Direct illumination is the path tracer's estimate of paths of two vertices.
        Integrator::Direct(_) => 2,
        Integrator::Distribution(d) => d.max_depth,
        Integrator::VolPath(v) => v.max_depth,
        Integrator::Particle(p) => p.max_depth,
        Integrator::Bdpt(b) => b.max_depth,
        Integrator::Sppm(s) => s.max_depth,
        Integrator::Vcm(v) => v.max_depth,
        Integrator::Guided(g) => g.max_depth,
        Integrator::Moment(_) | Integrator::Aov(_) | Integrator::Depth(_) => -1,
    };
    let defaults: Integrator = match name {
        "path" => PathIntegrator {
            max_depth,
            ..PathIntegrator::default()
        }
        .into(),
        "direct" => DirectIntegrator::default().into(),
        "distrib" => DistributionIntegrator {
            max_depth,
            ..DistributionIntegrator::default()
        }
        .into(),
        "volpath" => VolPathIntegrator {
            max_depth,
            ..VolPathIntegrator::default()
        }
        .into(),
        "volpathmis" => VolPathIntegrator {
            max_depth,
            tracking: Tracking::HeroMis { spectral_mis: true },
            ..VolPathIntegrator::default()
        }
        .into(),
        other => {
            return Err(Error::usage(format!("unknown integrator \"{other}\""))
                .with_help("use path, direct, distrib, volpath or volpathmis"));
        }
    };
    Ok(if integrator_label(image) == name {
        image.clone()
    } else {
        defaults
    })
}

fn sampler_named(name: &str) -> Result<SamplerKind> {
    match name {
        "independent" => Ok(SamplerKind::Independent),
        "stratified" => Ok(SamplerKind::Stratified { jitter: true }),
        "multijitter" => Ok(SamplerKind::MultiJitter { jitter: true }),
        "nrooks" => Ok(SamplerKind::NRooks),
        "ldsampler" => Ok(SamplerKind::LowDiscrepancy),
        "orthogonal" => Ok(SamplerKind::Orthogonal {
            strength: 2,
            jitter: true,
        }),
        other => Err(
            Error::usage(format!("unknown sampler \"{other}\"")).with_help(
                "use independent, stratified, multijitter, nrooks, ldsampler or orthogonal",
            ),
        ),
    }
}

fn integrator_label(integrator: &Integrator) -> &'static str {
    match integrator {
        Integrator::Path(_) | Integrator::PolarizedPath(_) => "path",
        Integrator::Stokes(_) => "stokes",
        Integrator::Direct(_) => "direct",
        Integrator::Distribution(_) => "distrib",
        Integrator::VolPath(v) if v.tracking == Tracking::Spectral => "volpath",
        Integrator::PolarizedVolPath(p) if p.volpath.tracking == Tracking::Spectral => "volpath",
        Integrator::VolPath(_) | Integrator::PolarizedVolPath(_) => "volpathmis",
        Integrator::Moment(_) => "moment",
        Integrator::Aov(_) => "aov",
        Integrator::Depth(_) => "depth",
        Integrator::Particle(_) => "ptracer",
        Integrator::Bdpt(_) => "bdpt",
        Integrator::Sppm(_) => "sppm",
        Integrator::Guided(_) => "guided_path",
        Integrator::Vcm(_) => "vcm",
    }
}

pub fn run(args: &ConvergeArgs) -> Result<()> {
    if !(1..=1 << 20).contains(&args.max_spp) {
        return Err(Error::usage("--max-spp must be between 1 and 2^20"));
    }
    if args.threads == Some(0) {
        return Err(Error::usage("--threads must be at least 1"));
    }
    let reference = read_exr(&args.reference).map_err(|mut e| {
        e.kind = prism_core::error::ErrorKind::Input;
        e
    })?;
    let loaded = load_scene(&args.scene, &args.defines)?;
    for warning in &loaded.warnings {
        eprintln!("{warning}");
    }
    let mut scene = loaded.scene;
    let size = scene.film.crop.size;
    if (reference.width, reference.height) != (size.x as usize, size.y as usize) {
        return Err(Error::usage(format!(
            "the reference is {}×{} pixels but the scene renders {}×{}",
            reference.width, reference.height, size.x, size.y
        ))
        .with_help("render the reference from the same scene (and the same -D values)"));
    }
    let integrators: Vec<Integrator> = match &args.integrators {
        Some(names) => names
            .iter()
            .map(|n| integrator_named(n, &scene))
            .collect::<Result<_>>()?,
        None => vec![scene.integrator.clone()],
    };
    let samplers: Vec<SamplerKind> = match &args.samplers {
        Some(names) => names
            .iter()
            .map(|n| sampler_named(n))
            .collect::<Result<_>>()?,
        None => vec![scene.sampler.kind],
    };

    let mut all = Vec::new();
    let mut seed = args.seed;
    for integrator in &integrators {
        for &kind in &samplers {
            scene.integrator = integrator.clone();
            scene.sampler.kind = kind;
            let label = format!("{} / {}", integrator_label(integrator), kind.name());
            let mut series = Series {
                label,
                points: Vec::new(),
            };
            let mut spp = 1;
            while spp <= args.max_spp {
                let start = Instant::now();
                let output = render(&scene, &RenderOptions::fixed(spp, seed, args.threads))?;
                let seconds = start.elapsed().as_secs_f64();
                let error = rel_mse_rgb(&output.film.linear_srgb(), &reference)?;
                eprintln!(
                    "{}: {spp} spp in {seconds:.2} s, relMSE {error:.4e}",
                    series.label
                );
                series
                    .points
                    .push((output.samples.end - output.samples.start, seconds, error));
                seed += 1;
                spp *= 2;
            }
            all.push(series);
        }
    }

    let csv_path = args.output.with_extension("csv");
    write_csv(&csv_path, &all)?;
    let png_path = args.output.with_extension("png");
    plot(&png_path, &all).map_err(|e| {
        Error::io(
            &png_path,
            &std::io::Error::other(e.to_string()),
            "draw the plot",
        )
    })?;
    for series in &all {
        eprintln!("{}: relMSE ∝ spp^{:.2}", series.label, series.slope());
    }
    eprintln!(
        "prism: wrote {} and {}",
        csv_path.display(),
        png_path.display()
    );
    Ok(())
}

fn write_csv(path: &Path, all: &[Series]) -> Result<()> {
    let mut text = String::from("integrator,sampler,spp,seconds,relmse\n");
    for series in all {
        let (integrator, sampler) = series
            .label
            .split_once(" / ")
            .unwrap_or((&series.label, ""));
        for (spp, seconds, error) in &series.points {
            text.push_str(&format!(
                "{integrator},{sampler},{spp},{seconds:.6},{error:.6e}\n"
            ));
        }
    }
    std::fs::File::create(path)
        .and_then(|mut f| f.write_all(text.as_bytes()))
        .map_err(|e| Error::io(path, &e, "write"))
}

/// The font of the plot's labels, embedded so no system fonts are needed: DejaVu Sans Mono
/// (Bitstream Vera licence, see assets/fonts/LICENSE-DejaVu.txt).
const FONT: &[u8] = include_bytes!("../../assets/fonts/DejaVuSansMono.ttf");

fn plot(path: &Path, all: &[Series]) -> std::result::Result<(), Box<dyn std::error::Error>> {
    plotters::style::register_font("sans-serif", FontStyle::Normal, FONT)
        .map_err(|_| "the embedded font is invalid")?;
    let root = BitMapBackend::new(path, (1400, 600)).into_drawing_area();
    root.fill(&WHITE)?;
    let (left, right) = root.split_horizontally(700);
    draw_panel(
        &left,
        all,
        "relative MSE against samples per pixel",
        "samples per pixel",
        |p| f64::from(p.0),
        true,
    )?;
    draw_panel(
        &right,
        all,
        "relative MSE against render time",
        "seconds",
        |p| p.1,
        false,
    )?;
    root.present()?;
    Ok(())
}

/// One log–log panel of relMSE against `x` (samples per pixel or seconds).
fn draw_panel(
    area: &DrawingArea<BitMapBackend, plotters::coord::Shift>,
    all: &[Series],
    caption: &str,
    x_name: &str,
    x_of: impl Fn(&(u32, f64, f64)) -> f64,
    with_law: bool,
) -> std::result::Result<(), Box<dyn std::error::Error>> {
    let points: Vec<(f64, f64)> = all
        .iter()
        .flat_map(|s| s.points.iter())
        .filter(|p| p.2 > 0.0 && x_of(p) > 0.0)
        .map(|p| (x_of(p), p.2))
        .collect();
    let fold = |f: fn(f64, f64) -> f64, start: f64, get: fn(&(f64, f64)) -> f64| {
        points.iter().map(get).fold(start, f)
    };
    let (x_min, x_max) = (
        fold(f64::min, f64::INFINITY, |p| p.0),
        fold(f64::max, 0.0, |p| p.0),
    );
    let (y_min, y_max) = (
        fold(f64::min, f64::INFINITY, |p| p.1),
        fold(f64::max, 0.0, |p| p.1),
    );
    if points.is_empty() {
        return Ok(());
    }
    // Axis labels at the sample counts (powers of two) or at 1-2-5 steps of time.
    let keys: Vec<f64> = if with_law {
        (0..31)
            .map(|k| f64::from(1u32 << k))
            .filter(|v| *v <= x_max * 1.2)
            .collect()
    } else {
        (-4..6)
            .flat_map(|e| [1.0, 2.0, 5.0].map(|m| m * 10f64.powi(e)))
            .filter(|v| *v >= x_min * 0.7 && *v <= x_max * 1.4)
            .collect()
    };
    let mut builder = ChartBuilder::on(area);
    builder
        .caption(caption, ("sans-serif", 22))
        .margin(16)
        .x_label_area_size(48)
        .y_label_area_size(80);
    let y_range = (y_min * 0.7..y_max * 1.4).log_scale();
    let x_range = if with_law {
        x_min * 0.9..x_max * 1.2
    } else {
        x_min * 0.7..x_max * 1.4
    };
    let mut chart =
        builder.build_cartesian_2d(x_range.log_scale().with_key_points(keys), y_range)?;
    chart
        .configure_mesh()
        .x_desc(x_name)
        .y_desc("relMSE")
        .x_label_formatter(&|x| {
            if *x >= 1.0 {
                format!("{x:.0}")
            } else {
                format!("{x:.2}")
            }
        })
        .y_label_formatter(&|y| format!("{y:.0e}"))
        .label_style(("sans-serif", 15))
        .light_line_style(WHITE.mix(0.0))
        .draw()?;
    let palette = [
        RED,
        BLUE,
        GREEN,
        MAGENTA,
        CYAN,
        BLACK,
        RGBColor(230, 140, 0),
        RGBColor(120, 80, 40),
    ];
    for (i, series) in all.iter().enumerate() {
        let color = palette[i % palette.len()];
        let data: Vec<(f64, f64)> = series
            .points
            .iter()
            .filter(|p| p.2 > 0.0 && x_of(p) > 0.0)
            .map(|p| (x_of(p), p.2))
            .collect();
        chart
            .draw_series(LineSeries::new(data.clone(), color.stroke_width(2)))?
            .label(format!("{} (slope {:.2})", series.label, series.slope()))
            .legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 20, y)], color.stroke_width(2))
            });
        chart.draw_series(data.into_iter().map(|p| Circle::new(p, 3, color.filled())))?;
    }
    if with_law && let Some(first) = all.first().and_then(|s| s.points.first()) {
        // The σ²/N law through the first configuration's first point.
        let start = (f64::from(first.0), first.2 * 1.6);
        let line = vec![start, (x_max, start.1 * start.0 / x_max)];
        chart
            .draw_series(LineSeries::new(line, BLACK.mix(0.5).stroke_width(1)))?
            .label("slope −1 (σ²/N)")
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], BLACK.mix(0.5)));
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::LowerLeft)
        .label_font(("sans-serif", 15))
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .draw()?;
    Ok(())
}
