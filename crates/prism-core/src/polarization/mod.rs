//! Polarized light: Stokes vectors, Mueller matrices per wavelength, the rotations of their
//! reference frames, and the Fresnel equations as Mueller matrices.
//!
//! The conventions are Mitsuba 3's (its documentation's "Polarization" key topic): a Stokes
//! vector is seen from the sensor looking back along the beam (s₃ > 0 is right circular
//! light), relative to a reference direction orthogonal to the beam; a beam's implicit
//! reference direction is [`mueller::stokes_basis`] of its direction of travel; Mueller matrices
//! multiply Stokes vectors from the left.
//!
//! | module | what |
//! | --- | --- |
//! | [`mueller`] | Stokes vectors, Mueller matrices of ideal elements, frame rotations, [`SampledMueller`] |
//! | [`fresnel`] | the Fresnel amplitudes and the Mueller matrices of specular reflection and refraction |

pub mod fresnel;
pub mod mueller;

pub use mueller::{FrameChange, SampledMueller, Stokes};
