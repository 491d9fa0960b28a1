//! The integrators' estimators against closed forms and against each other, their error, and
//! the `aov` and `moment` integrators, the particle tracer, bidirectional path tracing, photon
//! mapping, vertex connection and merging, and path guiding.

mod aov;
mod bdpt;
mod closed_form;
mod convergence;
mod depth;
mod direct;
mod guarantees;
mod guided;
mod moment;
mod ptracer;
mod sppm;
mod strict_normals;
mod vcm;
