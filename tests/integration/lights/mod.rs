//! Lights: closed-form images and flux identities, the emitter plugins as the scene reader
//! builds them, projected images, the `sunsky` emitter and textured area emitters.

mod closed_form;
mod plugins;
mod projected;
mod sunsky;
mod textured_emission;
