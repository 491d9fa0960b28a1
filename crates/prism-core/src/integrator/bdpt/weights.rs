//! The multiple importance sampling weights of bidirectional path tracing (Veach 1997, §10.2–10.3;
//! pbrt-v4's `MISWeight`), by the power heuristic over every strategy that could have made the
//! same path.
//!
//! A path x₀ … x_k (x₀ on a light, x_k the camera) made by strategy (s, t) — s vertices from the
//! light subpath, t from the camera subpath — was drawn with density p_s. Every vertex stores two
//! densities per unit area (per unit solid angle for a direction at infinity): `pdf_fwd`, that of
//! its own subpath drawing it, and `pdf_rev`, that of the other subpath drawing it from the
//! vertex beyond it. The ratios of the neighbouring strategies' densities follow from them:
//!
//! ```text
//! p_{s+1} / p_s = p←(x_s) / p→(x_s)   (moving the light subpath's end one vertex further),
//! p_{s−1} / p_s = p→(x_{s−1}) / p←(x_{s−1}),
//! ```
//!
//! so walking from the connection along each subpath multiplies the ratios up, and the power
//! heuristic's weight is w_s = 1 / (1 + Σ_{i≠s} (p_i / p_s)²). A strategy that would have to
//! connect at a vertex with a delta lobe (or at a delta light) has density zero and is left out
//! of the sum; the delta densities themselves are stored as zero and counted as one in the
//! ratios, since they appear in the numerator and the denominator alike (pbrt's `remap0`).
//! Strategies the integrator does not use (t = 1 without `lightImage`, and s = 1, t = 1, which
//! Prism does not trace, as pbrt) are left out of the sum, so the weights of the strategies used
//! still sum to one.

/// What the weights need of one vertex of a strategy's path, with its connection's densities
/// already updated.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct MisVertex {
    /// Density of the vertex drawn by its own subpath.
    pub pdf_fwd: f32,
    /// Density of the vertex drawn by the other subpath.
    pub pdf_rev: f32,
    /// Whether the vertex scattered by a delta lobe (no connection can be made there).
    pub delta: bool,
    /// For the first light vertex: whether the light is a delta one (a point).
    pub delta_light: bool,
}

/// A density of zero, which stands for a delta, as one (pbrt's `remap0`).
#[inline]
fn remap(pdf: f32) -> f32 {
    if pdf != 0.0 { pdf } else { 1.0 }
}

/// The power heuristic's weight of the strategy whose light subpath is `light` (s vertices,
/// y₀ first) and camera subpath is `camera` (t vertices, the camera first), the connection
/// vertices' densities already updated for this strategy; `light_image` says whether the
/// strategies t = 1 are used.
pub fn mis_weight(camera: &[MisVertex], light: &[MisVertex], light_image: bool) -> f32 {
    let (s, t) = (light.len(), camera.len());
    if s + t == 2 {
        return 1.0;
    }
    let mut sum = 0.0f64;
    // Strategies that take camera vertices into the light subpath: (s + t − i, i).
    let mut ratio = 1.0f64;
    for i in (1..t).rev() {
        ratio *= f64::from(remap(camera[i].pdf_rev)) / f64::from(remap(camera[i].pdf_fwd));
        if (i > 1 || light_image) && !camera[i].delta && !camera[i - 1].delta {
            sum += ratio * ratio;
        }
    }
    // Strategies that take light vertices into the camera subpath: (i, s + t − i).
    ratio = 1.0;
    for i in (0..s).rev() {
        ratio *= f64::from(remap(light[i].pdf_rev)) / f64::from(remap(light[i].pdf_fwd));
        let delta_before = if i > 0 {
            light[i - 1].delta
        } else {
            light[0].delta_light
        };
        if !light[i].delta && !delta_before {
            sum += ratio * ratio;
        }
    }
    let weight = 1.0 / (1.0 + sum);
    if weight.is_finite() {
        weight as f32
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A full path x₀ … x_{n−1} (x₀ on the light, x_{n−1} the camera), with the densities of
    /// each vertex drawn from the light's side (`from_light`) and from the camera's
    /// (`from_camera`), which delta flags, and whether the light is a delta one.
    struct FullPath {
        from_light: Vec<f32>,
        from_camera: Vec<f32>,
        delta: Vec<bool>,
        delta_light: bool,
    }

    impl FullPath {
        /// The subpaths of strategy (s, t): light vertices x₀ … x_{s−1} and camera vertices
        /// x_{n−1} … x_s, each with its own subpath's density forward.
        fn split(&self, s: usize) -> (Vec<MisVertex>, Vec<MisVertex>) {
            let n = self.from_light.len();
            let vertex = |i: usize, light_side: bool| MisVertex {
                pdf_fwd: if light_side {
                    self.from_light[i]
                } else {
                    self.from_camera[i]
                },
                pdf_rev: if light_side {
                    self.from_camera[i]
                } else {
                    self.from_light[i]
                },
                delta: self.delta[i],
                delta_light: i == 0 && self.delta_light,
            };
            let light = (0..s).map(|i| vertex(i, true)).collect();
            let camera = (s..n).rev().map(|i| vertex(i, false)).collect();
            (light, camera)
        }

        /// Whether strategy (s, t) can make the path: it connects at non-delta vertices (or, for
        /// s = 0, finds a light that is not a delta one), and is one the integrator traces.
        fn possible(&self, s: usize, light_image: bool) -> bool {
            let n = self.from_light.len();
            let t = n - s;
            if t == 0 || (s == 1 && t == 1) || (t == 1 && !light_image) {
                return false;
            }
            if s == 0 {
                return !self.delta_light;
            }
            !self.delta[s - 1] && !self.delta[s]
        }
    }

    /// A small deterministic generator of densities spread over several orders of magnitude.
    fn densities(seed: &mut u64, n: usize) -> Vec<f32> {
        (0..n)
            .map(|_| {
                *seed = seed
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                let u = (*seed >> 40) as f32 / (1u64 << 24) as f32;
                10f32.powf(4.0 * u - 2.0)
            })
            .collect()
    }

    /// For fixed paths of two to seven vertices, some with delta vertices or a delta light, the
    /// weights of all the strategies that can make the path sum to one, with and without the
    /// light-tracing strategies.
    #[test]
    fn weights_of_one_path_sum_to_one() {
        let mut seed = 7u64;
        for n in 2..=7 {
            for case in 0..6 {
                let mut delta = vec![false; n];
                if case >= 2 && n > 3 {
                    delta[1 + case % (n - 2)] = true;
                }
                let delta_light = case % 3 == 1;
                let mut from_light = densities(&mut seed, n);
                let mut from_camera = densities(&mut seed, n);
                for i in 0..n {
                    if delta[i] {
                        // A delta vertex's neighbours are drawn through a delta.
                        if i + 1 < n {
                            from_light[i + 1] = 0.0;
                        }
                        from_camera[i - 1] = 0.0;
                    }
                }
                let path = FullPath {
                    from_light,
                    from_camera,
                    delta,
                    delta_light,
                };
                for light_image in [true, false] {
                    let mut total = 0.0f64;
                    let mut any = false;
                    for s in 0..=n {
                        if !path.possible(s, light_image) {
                            continue;
                        }
                        any = true;
                        let (light, camera) = path.split(s);
                        total += f64::from(mis_weight(&camera, &light, light_image));
                    }
                    if any {
                        assert!(
                            (total - 1.0).abs() < 1e-5,
                            "n {n} case {case} light_image {light_image}: {total}"
                        );
                    }
                }
            }
        }
    }
}
