//! Mitsuba 3's `moment` integrator: runs its nested integrators on the same camera ray, one after
//! the other, and writes for each nested integrator `n` its sample's CIE XYZ estimate as the
//! extra channels `n.X`, `n.Y`, `n.Z` (after `n.`-prefixed copies of that integrator's own extra
//! channels), then for every one of those channels `c` the square of the sample's value as
//! `m2_c`. The image is the first nested integrator's.
//!
//! ```xml
//! <integrator type="moment">
//!     <integrator type="path" name="pt"/>      <!-- channels pt.X ... m2_pt.Z -->
//!     <integrator type="direct"/>              <!-- unnamed: _arg_0.X ... m2__arg_0.Z -->
//! </integrator>
//! ```
//!
//! With N samples of values vᵢ (filter-weighted as the image is), a pixel's `c` is Σvᵢ/N and its
//! `m2_c` is Σvᵢ²/N, so the variance of one sample is m2 − c², and of the pixel's mean
//! (m2 − c²)/(N − 1) (the sample variance; see `film::stats`).

use crate::integrator::{Integrator, SampleContext};
use crate::math::Ray;
use crate::spectrum::{SampledSpectrum, SampledWavelengths};

#[derive(Clone, Debug)]
pub struct MomentIntegrator {
    /// The nested integrators with the names their channels carry, in the scene's order.
    pub integrators: Vec<(String, Integrator)>,
}

impl MomentIntegrator {
    /// The channel names: the first moments of every nested integrator, then their `m2_`
    /// counterparts in the same order.
    pub fn aov_names(&self) -> Vec<String> {
        let mut names = Vec::new();
        for (name, integrator) in &self.integrators {
            names.extend(integrator.aov_names().iter().map(|a| format!("{name}.{a}")));
            names.extend(["X", "Y", "Z"].map(|c| format!("{name}.{c}")));
        }
        let second: Vec<String> = names.iter().map(|n| format!("m2_{n}")).collect();
        names.extend(second);
        names
    }

    /// The first nested integrator's radiance; every nested integrator's moments go to `aovs`.
    pub(super) fn radiance(
        ctx: &mut SampleContext,
        ray: Ray,
        lambda: &SampledWavelengths,
        aovs: &mut [f32],
    ) -> SampledSpectrum {
        let (first, second) = aovs.split_at_mut(aovs.len() / 2);
        let mut image = SampledSpectrum::ZERO;
        let mut offset = 0;
        for (i, nested) in ctx.prepared.nested.iter().enumerate() {
            let k = nested.aov_count();
            let own = &mut first[offset..offset + k + 3];
            let radiance = nested.radiance(ray, lambda, ctx.sampler, ctx.count, &mut own[..k]);
            own[k..].copy_from_slice(&lambda.to_xyz(&radiance));
            for (m2, v) in second[offset..offset + k + 3].iter_mut().zip(own.iter()) {
                *m2 = v * v;
            }
            offset += k + 3;
            if i == 0 {
                image = radiance;
            }
        }
        image
    }
}
