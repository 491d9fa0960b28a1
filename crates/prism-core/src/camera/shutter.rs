//! The shutter: when during the exposure a camera ray is taken.
//!
//! The sensor's shutter is open from `shutter_open` to `shutter_close` (Mitsuba's parameters, both
//! default 0: no motion blur). Time is a primary dimension like the others and is filtered like
//! the pixel position (the lecture's "Temporal filtering gives motion blur and can be done in the
//! same way"): by default every moment of the exposure counts equally (a box), and a temporal
//! reconstruction filter, if the sensor has one named `shutter_filter`, is stretched over the
//! interval and importance sampled, p ∝ |k|, with the weight k / (p ∫k).
//!
//! ```xml
//! <sensor type="perspective">
//!     <float name="shutter_open" value="0"/>
//!     <float name="shutter_close" value="1"/>
//!     <rfilter type="mitchell" name="shutter_filter"/>   <!-- optional -->
//! </sensor>
//! ```
//! Its parameters and their defaults are listed in docs/plugins.md.

use crate::film::{Filter, FilterSampler, Kernel};

#[derive(Clone, Debug)]
pub struct Shutter {
    pub open: f32,
    pub close: f32,
    /// The temporal filter; None for a box over the interval.
    filter: Option<FilterSampler>,
}

impl Shutter {
    /// A shutter open over [open, close] (close ≥ open, checked by the caller).
    pub fn new(open: f32, close: f32, filter: Option<Filter>) -> Shutter {
        Shutter {
            open,
            close,
            filter: filter.map(FilterSampler::new),
        }
    }

    /// A shutter that opens and closes at 0: everything is seen at time 0.
    pub fn instant() -> Shutter {
        Shutter::new(0.0, 0.0, None)
    }

    /// A time of the exposure for the uniform number `u`, and its weight.
    #[inline]
    pub fn sample(&self, u: f32) -> (f32, f32) {
        let length = self.close - self.open;
        match &self.filter {
            None => (self.open + u * length, 1.0),
            Some(sampler) => {
                let (x, weight) = sampler.sample_1d(u);
                let r = sampler.filter().radius();
                (self.open + (x + r) / (2.0 * r) * length, weight)
            }
        }
    }

    /// Density of [`Self::sample`]'s time, per unit time (for tests).
    pub fn pdf(&self, time: f32) -> f32 {
        let length = self.close - self.open;
        if !(time >= self.open && time <= self.close) || length <= 0.0 {
            return 0.0;
        }
        match &self.filter {
            None => 1.0 / length,
            Some(sampler) => {
                let r = sampler.filter().radius();
                let x = (time - self.open) / length * 2.0 * r - r;
                sampler.pdf_1d(x) * 2.0 * r / length
            }
        }
    }
}
