//! Numerical integration of smooth one-dimensional functions.

/// ∫ₐᵇ f by the composite Simpson's rule on `n` intervals (rounded up to an even number):
/// (h/3) Σ wⱼ f(a + j h) with weights 1, 4, 2, 4, …, 4, 1; exact for cubics.
pub fn simpson(f: impl Fn(f64) -> f64, a: f64, b: f64, n: usize) -> f64 {
    let n = n.max(2).next_multiple_of(2);
    let h = (b - a) / n as f64;
    let inner: f64 = (1..n)
        .map(|j| if j % 2 == 1 { 4.0 } else { 2.0 } * f(a + j as f64 * h))
        .sum();
    (f(a) + inner + f(b)) * h / 3.0
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn simpson_is_exact_for_cubics_and_converges_for_the_rest() {
        let cubic = simpson(|x| x * x * x - 2.0 * x + 1.0, -1.0, 2.0, 2);
        assert!((cubic - 3.75).abs() < 1e-12, "{cubic}");
        let sine = simpson(f64::sin, 0.0, std::f64::consts::PI, 64);
        assert!((sine - 2.0).abs() < 1e-6, "{sine}");
        assert_eq!(simpson(|x| x, 0.0, 1.0, 3), simpson(|x| x, 0.0, 1.0, 4));
    }
}
