//! Russian roulette and splitting driven by the learned radiance (Vorba & Křivánek 2016,
//! "Adjoint-Driven Russian Roulette and Splitting in Light Transport Simulation", §4): at a
//! vertex x the path's expected contribution to its pixel is its throughput τ times the
//! radiance L_o(x) that leaves x towards the path's previous vertex; measured against the
//! pixel's estimate I, the ratio r = τ L_o(x) / I says whether the path will bring about its
//! share (r ≈ 1), little (r ≪ 1) or much (r ≫ 1).
//!
//! The weight window keeps r within [2 / (1 + s), 2s / (1 + s)] (s = 5: [⅓, 5⁄3]): below it the
//! path survives with probability q = r (at least [`MIN_SURVIVAL`]) and its throughput is
//! divided by q; above it the path splits into n = ⌊r⌉ (at most [`MAX_SPLIT`]) paths that each
//! carry τ / n. Both keep the estimator unbiased for any L_o and I, so rough learned values
//! cost variance, not bias.

/// The ratio of the window's upper bound to its lower bound (the authors' s).
const WINDOW_RATIO: f32 = 5.0;
/// The lowest survival probability, which bounds the weight a survivor carries where the
/// learned radiance underestimates the truth.
pub const MIN_SURVIVAL: f32 = 0.05;
/// The most paths a camera sample's path splits into, at a vertex and over all its vertices.
pub const MAX_SPLIT: u32 = 8;

/// What the window makes of a path at a vertex.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Window {
    /// The path goes on as it is.
    Keep,
    /// The path survives with this probability.
    Roulette(f32),
    /// The path splits into this many paths.
    Split(u32),
}

/// The window's verdict for a path of mean throughput `throughput` at a vertex that sends
/// `reflected` (L_o) towards it, in a pixel whose estimate is `pixel`; None where either
/// estimate is missing (zero, negative or not finite), and the path is left to the ordinary
/// Russian roulette.
pub fn window(throughput: f32, reflected: f32, pixel: f32) -> Option<Window> {
    if !(reflected > 0.0 && pixel > 0.0 && reflected.is_finite() && pixel.is_finite()) {
        return None;
    }
    let r = throughput * reflected / pixel;
    if !r.is_finite() {
        return None;
    }
    let lower = 2.0 / (1.0 + WINDOW_RATIO);
    let upper = lower * WINDOW_RATIO;
    Some(if r < lower {
        Window::Roulette(r.max(MIN_SURVIVAL))
    } else if r > upper {
        Window::Split((r.round() as u32).clamp(2, MAX_SPLIT))
    } else {
        Window::Keep
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Within [⅓, 5⁄3] the path goes on; below, it survives with probability r (at least
    /// the floor); above, it splits into ⌊r⌉ paths, at most eight; without estimates the
    /// window has no verdict.
    #[test]
    fn window_keeps_the_expected_contribution_near_the_pixels() {
        assert_eq!(window(1.0, 1.0, 1.0), Some(Window::Keep));
        assert_eq!(window(0.5, 0.7, 1.0), Some(Window::Keep));
        assert_eq!(window(0.5, 3.2, 1.0), Some(Window::Keep));
        assert_eq!(window(0.25, 1.0, 1.0), Some(Window::Roulette(0.25)));
        assert_eq!(window(1.0, 1e-3, 1.0), Some(Window::Roulette(MIN_SURVIVAL)));
        assert_eq!(window(1.0, 2.0, 1.0), Some(Window::Split(2)));
        assert_eq!(window(1.0, 3.6, 1.0), Some(Window::Split(4)));
        assert_eq!(window(2.0, 100.0, 1.0), Some(Window::Split(MAX_SPLIT)));
        assert_eq!(window(1.0, 0.0, 1.0), None);
        assert_eq!(window(1.0, 1.0, 0.0), None);
        assert_eq!(window(1.0, f32::NAN, 1.0), None);
        assert_eq!(window(f32::INFINITY, 1.0, 1.0), None);
    }
}
