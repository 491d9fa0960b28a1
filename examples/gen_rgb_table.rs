//! Generates the Jakob–Hanika coefficient table shipped as `src/spectrum/srgb_to_spectrum.bin`
//! with Prism's own fitter (`prism_core::spectrum::rgb`), and reports how well it reproduces colours.
//!
//!     cargo run --release --example gen_rgb_table [-- RESOLUTION [OUTPUT]]
//!
//! The default resolution is `TABLE_RESOLUTION`; the default output is the shipped file.

use prism_core::sampling::rng::Pcg32;
use prism_core::spectrum::rgb::{RgbSigmoidPolynomial, RgbToSpectrumTable, TABLE_RESOLUTION};

fn main() -> std::io::Result<()> {
    let mut args = std::env::args().skip(1);
    let res = args
        .next()
        .and_then(|a| a.parse().ok())
        .unwrap_or(TABLE_RESOLUTION);
    let output = args.next().unwrap_or_else(|| {
        concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/crates/prism-core/src/spectrum/srgb_to_spectrum.bin"
        )
        .into()
    });
    let start = std::time::Instant::now();
    let table = RgbToSpectrumTable::generate(res);
    println!(
        "generated a {res}³ × 3 table in {:.1} s",
        start.elapsed().as_secs_f64()
    );

    // How far the colours of the table's spectra are from their targets, over random colours
    // (and, for comparison, the per-colour fits).
    let mut rng = Pcg32::seeded(1);
    let (mut worst, mut sum, mut worst_fit) = (0.0f32, 0.0f64, 0.0f32);
    let n = 4000;
    for _ in 0..n {
        let rgb = [rng.next_f32(), rng.next_f32(), rng.next_f32()];
        let error = |back: [f32; 3]| (0..3).map(|c| (back[c] - rgb[c]).abs()).fold(0.0, f32::max);
        let e = error(table.fetch(rgb).linear_srgb());
        worst = worst.max(e);
        sum += f64::from(e);
        worst_fit = worst_fit.max(error(RgbSigmoidPolynomial::fit(rgb).linear_srgb()));
    }
    println!(
        "colour error over {n} random colours (max |Δ| of linear sRGB): table mean {:.5}, max {worst:.5}; per-colour fit max {worst_fit:.5}",
        sum / f64::from(n)
    );
    let bytes = table.to_bytes();
    std::fs::write(&output, &bytes)?;
    println!("wrote {} bytes to {output}", bytes.len());
    Ok(())
}
