//! Image formation: closed forms of filters, lens and motion blur, filter MIS, the samplers and
//! the sensor plugins.

mod closed_form;
mod filter_mis;
mod samplers;
mod sensors;
