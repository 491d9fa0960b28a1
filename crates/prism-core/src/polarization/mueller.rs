//! Mueller matrices: how an optical element or a scattering event changes a Stokes vector, and
//! the rotations of the reference frames both are expressed in.
//!
//! A Stokes vector s = (s₀, s₁, s₂, s₃) is a [`Vec4`]: intensity, horizontal against vertical,
//! +45° against −45° linear, and right against left circular polarization, seen from the
//! sensor looking back along the beam, relative to a reference direction (its "horizontal")
//! orthogonal to the beam. A Mueller matrix is a [`Mat4`] multiplied onto Stokes vectors from
//! the left (M₂ M₁ s: first M₁, then M₂); along a path it maps the Stokes frame of the
//! incident beam to that of the outgoing one. The elements and rotations are those of Mitsuba 3
//! (`include/mitsuba/render/mueller.h`, after Collett, "Polarized Light", 1993, ch. 5, and
//! Goldstein, "Polarized Light", 3rd ed., 2011, ch. 6); [`SampledMueller`] holds one matrix per
//! wavelength of a path.

use std::ops::{Add, Mul};

use glam::{Mat4, Vec3, Vec4};

use crate::math::Frame;
use crate::spectrum::{N_SPECTRUM_SAMPLES, SampledSpectrum};

/// A Stokes vector.
pub type Stokes = Vec4;

/// A matrix given by its rows (glam stores columns).
#[inline]
pub fn from_rows(rows: [[f32; 4]; 4]) -> Mat4 {
    Mat4::from_cols_array_2d(&rows).transpose()
}

/// The ideal depolarizer that keeps `value` of the intensity: only M₀₀ = `value` is not zero.
#[inline]
pub fn depolarizer(value: f32) -> Mat4 {
    from_rows([[value, 0.0, 0.0, 0.0], [0.0; 4], [0.0; 4], [0.0; 4]])
}

/// The ideal linear polarizer that transmits horizontal light, scaled by `value` (Collett,
/// ch. 5, eq. 13): ½ value [[1, 1, 0, 0], [1, 1, 0, 0], 0, 0].
#[inline]
pub fn linear_polarizer(value: f32) -> Mat4 {
    let a = 0.5 * value;
    from_rows([[a, a, 0.0, 0.0], [a, a, 0.0, 0.0], [0.0; 4], [0.0; 4]])
}

/// A linear retarder with its fast axis horizontal and the phase difference `phase` (radians)
/// between its fast and slow axes (Goldstein, eq. 6.43): the identity on s₀ and s₁, and a
/// rotation by `phase` of (s₂, s₃), s₃' = −sin(phase) s₂ + cos(phase) s₃. A quarter-wave plate
/// (`phase` = π/2) turns +45° linear light into left circular light, s₃ = −s₀.
#[inline]
pub fn linear_retarder(phase: f32) -> Mat4 {
    let (s, c) = phase.sin_cos();
    from_rows([
        [1.0, 0.0, 0.0, 0.0],
        [0.0, 1.0, 0.0, 0.0],
        [0.0, 0.0, c, s],
        [0.0, 0.0, -s, c],
    ])
}

/// The ideal right circular polarizer (Chipman et al., "Polarized Light and Optical Systems",
/// 2018, table 6.2): ½ [[1, 0, 0, 1], 0, 0, [1, 0, 0, 1]].
#[inline]
pub fn right_circular_polarizer() -> Mat4 {
    from_rows([
        [0.5, 0.0, 0.0, 0.5],
        [0.0; 4],
        [0.0; 4],
        [0.5, 0.0, 0.0, 0.5],
    ])
}

/// The ideal left circular polarizer (Chipman et al., table 6.2): ½ [[1, 0, 0, −1], 0, 0,
/// [−1, 0, 0, 1]].
#[inline]
pub fn left_circular_polarizer() -> Mat4 {
    from_rows([
        [0.5, 0.0, 0.0, -0.5],
        [0.0; 4],
        [0.0; 4],
        [-0.5, 0.0, 0.0, 0.5],
    ])
}

/// The rotator by `theta` (radians): a counter-clockwise rotation of the reference frame, seen
/// from the sensor looking at the beam (Collett, ch. 5, eq. 43); with c = cos 2θ, s = sin 2θ,
/// [[1, 0, 0, 0], [0, c, s, 0], [0, −s, c, 0], [0, 0, 0, 1]]. Horizontal light (1, 1, 0, 0)
/// becomes (1, 0, −1, 0) under a rotator of +45°.
#[inline]
pub fn rotator(theta: f32) -> Mat4 {
    let (s, c) = (2.0 * theta).sin_cos();
    from_rows([
        [1.0, 0.0, 0.0, 0.0],
        [0.0, c, s, 0.0],
        [0.0, -s, c, 0.0],
        [0.0, 0.0, 0.0, 1.0],
    ])
}

/// The element `m` turned counter-clockwise by `theta` (radians) about the beam: Rᵀ(θ) M R(θ)
/// with R the [`rotator`].
#[inline]
pub fn rotated_element(theta: f32, m: Mat4) -> Mat4 {
    let r = rotator(theta);
    r.transpose() * m * r
}

/// The implicit reference direction of a Stokes vector travelling along `forward` (a unit
/// vector): the first tangent of [`Frame::from_normal`], as Mitsuba's `stokes_basis` takes the
/// first vector of its `coordinate_system`, which is the same construction.
#[inline]
pub fn stokes_basis(forward: Vec3) -> Vec3 {
    Frame::from_normal(forward).s
}

/// The angle between unit vectors, accurate near 0 and π (Mitsuba's `unit_angle`).
#[inline]
fn unit_angle(a: Vec3, b: Vec3) -> f32 {
    if a.dot(b) < 0.0 {
        std::f32::consts::PI - 2.0 * ((a + b).length() * 0.5).min(1.0).asin()
    } else {
        2.0 * ((b - a).length() * 0.5).min(1.0).asin()
    }
}

/// The matrix that re-expresses a Stokes vector travelling along `forward`, given relative to
/// the reference direction `basis_current`, relative to `basis_target` (both orthogonal to
/// `forward`): the [`rotator`] by the angle from the first to the second, signed by the turn
/// about `forward` (Mitsuba's `rotate_stokes_basis`). Horizontal light (1, 1, 0, 0) with basis
/// (1, 0, 0) along +z is +45° light (1, 0, 1, 0) in the basis (√½, −√½, 0).
#[inline]
pub fn rotate_stokes_basis(forward: Vec3, basis_current: Vec3, basis_target: Vec3) -> Mat4 {
    let (current, target) = (basis_current.normalize(), basis_target.normalize());
    let mut theta = unit_angle(current, target);
    if forward.dot(current.cross(target)) < 0.0 {
        theta = -theta;
    }
    rotator(theta)
}

/// The rotation that re-expresses a Mueller matrix acting from one reference direction to
/// another: from the frame (`in_forward`, `in_basis_current`) to (`out_forward`,
/// `out_basis_current`) into one from `in_basis_target` to `out_basis_target`, as the pair of
/// [`rotate_stokes_basis`] matrices (R_out, R_in) that give R_out M R_inᵀ (Mitsuba's
/// `rotate_mueller_basis`); [`SampledMueller::in_frames`] applies it.
#[derive(Clone, Copy, Debug)]
pub struct FrameChange {
    pub r_in: Mat4,
    pub r_out: Mat4,
}

impl FrameChange {
    /// See the type.
    #[inline]
    pub fn new(
        in_forward: Vec3,
        in_basis_current: Vec3,
        in_basis_target: Vec3,
        out_forward: Vec3,
        out_basis_current: Vec3,
        out_basis_target: Vec3,
    ) -> FrameChange {
        FrameChange {
            r_in: rotate_stokes_basis(in_forward, in_basis_current, in_basis_target),
            r_out: rotate_stokes_basis(out_forward, out_basis_current, out_basis_target),
        }
    }

    /// The same change on both sides of an element that does not deflect the beam (Mitsuba's
    /// `rotate_mueller_basis_collinear`): R M Rᵀ.
    #[inline]
    pub fn collinear(forward: Vec3, basis_current: Vec3, basis_target: Vec3) -> FrameChange {
        let r = rotate_stokes_basis(forward, basis_current, basis_target);
        FrameChange { r_in: r, r_out: r }
    }

    /// For a matrix whose reference directions are the normals of the plane of incidence (the
    /// s directions of the Fresnel equations) about `normal`, on the incident beam travelling
    /// along `in_forward` and the outgoing one along `out_forward`: the change to the implicit
    /// bases of the two beams (the rotation Mitsuba's pBSDFs apply). A beam along the normal
    /// has no plane of incidence; (1, 0, 0) stands for it.
    #[inline]
    pub fn from_plane_of_incidence(
        normal: Vec3,
        in_forward: Vec3,
        out_forward: Vec3,
    ) -> FrameChange {
        let s_in = normal.cross(in_forward);
        let (s_in, s_out) = if s_in == Vec3::ZERO {
            (Vec3::X, Vec3::X)
        } else {
            (s_in.normalize(), normal.cross(out_forward).normalize())
        };
        FrameChange::new(
            in_forward,
            s_in,
            stokes_basis(in_forward),
            out_forward,
            s_out,
            stokes_basis(out_forward),
        )
    }

    /// For a matrix between the implicit bases of the local directions `in_forward` and
    /// `out_forward` (local to `frame`): the change to the implicit bases of the same beams in
    /// world space (Mitsuba's `to_world_mueller`).
    #[inline]
    pub fn local_to_world(frame: &Frame, in_forward: Vec3, out_forward: Vec3) -> FrameChange {
        let (in_world, out_world) = (frame.to_world(in_forward), frame.to_world(out_forward));
        FrameChange::new(
            in_world,
            frame.to_world(stokes_basis(in_forward)),
            stokes_basis(in_world),
            out_world,
            frame.to_world(stokes_basis(out_forward)),
            stokes_basis(out_world),
        )
    }

    /// R_out M R_inᵀ.
    #[inline]
    pub fn apply(&self, m: Mat4) -> Mat4 {
        self.r_out * m * self.r_in.transpose()
    }
}

/// [`rotate_mueller_basis`]'s single-matrix form: `m` re-expressed from the current to the
/// target reference directions of its incident and outgoing beams.
pub fn rotate_mueller_basis(
    m: Mat4,
    in_forward: Vec3,
    in_basis_current: Vec3,
    in_basis_target: Vec3,
    out_forward: Vec3,
    out_basis_current: Vec3,
    out_basis_target: Vec3,
) -> Mat4 {
    FrameChange::new(
        in_forward,
        in_basis_current,
        in_basis_target,
        out_forward,
        out_basis_current,
        out_basis_target,
    )
    .apply(m)
}

/// One Mueller matrix per wavelength of a path (the polarized counterpart of a
/// [`SampledSpectrum`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SampledMueller(pub [Mat4; N_SPECTRUM_SAMPLES]);

impl SampledMueller {
    /// The identity at every wavelength: an element that changes nothing.
    pub const IDENTITY: SampledMueller = SampledMueller([Mat4::IDENTITY; N_SPECTRUM_SAMPLES]);
    pub const ZERO: SampledMueller = SampledMueller([Mat4::ZERO; N_SPECTRUM_SAMPLES]);

    #[inline]
    pub fn from_fn(f: impl FnMut(usize) -> Mat4) -> SampledMueller {
        SampledMueller(std::array::from_fn(f))
    }

    /// The same matrix at every wavelength.
    #[inline]
    pub fn splat(m: Mat4) -> SampledMueller {
        SampledMueller([m; N_SPECTRUM_SAMPLES])
    }

    /// An element that only scales the intensity, by `value` at each wavelength (Mitsuba's
    /// `absorber`): `value` times the identity.
    #[inline]
    pub fn absorber(value: SampledSpectrum) -> SampledMueller {
        SampledMueller::from_fn(|i| Mat4::from_diagonal(Vec4::splat(value[i])))
    }

    /// The [`depolarizer`] that keeps `value`: how an element that knows nothing of polarization
    /// acts in a polarized render (Mitsuba's `unpolarized_spectrum` → `depolarizer`).
    #[inline]
    pub fn depolarizer(value: SampledSpectrum) -> SampledMueller {
        SampledMueller::from_fn(|i| depolarizer(value[i]))
    }

    /// M₀₀ at each wavelength: what the element does to unpolarized intensity, its value in an
    /// unpolarized render.
    #[inline]
    pub fn m00(&self) -> SampledSpectrum {
        SampledSpectrum::from_fn(|i| self.0[i].x_axis.x)
    }

    /// Each matrix times the factor of its wavelength.
    #[inline]
    pub fn scaled(&self, factor: SampledSpectrum) -> SampledMueller {
        SampledMueller::from_fn(|i| self.0[i] * factor[i])
    }

    /// Each matrix re-expressed in other reference frames ([`FrameChange::apply`]).
    #[inline]
    pub fn in_frames(&self, change: &FrameChange) -> SampledMueller {
        SampledMueller::from_fn(|i| change.apply(self.0[i]))
    }

    /// The Stokes vector at each wavelength that the matrices give to unpolarized light of the
    /// intensities `intensity` (s = M (I, 0, 0, 0): the first column scaled).
    #[inline]
    pub fn apply_unpolarized(&self, intensity: SampledSpectrum) -> [Stokes; N_SPECTRUM_SAMPLES] {
        std::array::from_fn(|i| self.0[i].x_axis * intensity[i])
    }

    /// Each matrix scaled so that its M₀₀ is `value` at its wavelength: the polarization of an
    /// element whose matrix is known up to a positive factor, with the intensity an unpolarized
    /// evaluation gave. Zero where M₀₀ is not a positive number.
    #[inline]
    pub fn with_m00(&self, value: SampledSpectrum) -> SampledMueller {
        SampledMueller::from_fn(|i| {
            let m00 = self.0[i].x_axis.x;
            if m00 > 0.0 && m00.is_finite() {
                self.0[i] * (value[i] / m00)
            } else {
                Mat4::ZERO
            }
        })
    }

    pub fn is_finite(&self) -> bool {
        self.0.iter().all(|m| m.is_finite())
    }
}

impl Add for SampledMueller {
    type Output = SampledMueller;

    #[inline]
    fn add(self, rhs: SampledMueller) -> SampledMueller {
        SampledMueller::from_fn(|i| self.0[i] + rhs.0[i])
    }
}

impl Mul for SampledMueller {
    type Output = SampledMueller;

    #[inline]
    fn mul(self, rhs: SampledMueller) -> SampledMueller {
        SampledMueller::from_fn(|i| self.0[i] * rhs.0[i])
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f32::consts::{FRAC_PI_2, FRAC_PI_4};

    fn close(a: Vec4, b: Vec4) -> bool {
        (a - b).abs().max_element() < 1e-5
    }

    /// Malus's law: unpolarized light through two ideal polarizers whose axes differ by θ keeps
    /// ½ cos²θ of its intensity (½ at the first, cos²θ at the second).
    #[test]
    fn two_polarizers_follow_malus_law() {
        let unpolarized = Vec4::new(1.0, 0.0, 0.0, 0.0);
        for degrees in [0.0f32, 10.0, 30.0, 45.0, 60.0, 89.0, 90.0, 135.0] {
            let theta = degrees.to_radians();
            let first = linear_polarizer(1.0);
            let second = rotated_element(theta, linear_polarizer(1.0));
            let out = second * first * unpolarized;
            let expected = 0.5 * theta.cos().powi(2);
            assert!((out.x - expected).abs() < 1e-6, "{degrees}°: {}", out.x);
            // What passes is fully polarized along the second polarizer.
            let along = Vec4::new(1.0, (2.0 * theta).cos(), (2.0 * theta).sin(), 0.0) * expected;
            assert!(close(out, along), "{degrees}°: {out}");
        }
    }

    /// A quarter-wave plate at 45° to horizontal light makes it right circular (s₃ = +s₀);
    /// +45° light through a plate with a horizontal fast axis comes out left circular (s₃ =
    /// −s₀), the example of Mitsuba 3's polarization guide.
    #[test]
    fn quarter_wave_plate_makes_circular_light() {
        let horizontal = Vec4::new(1.0, 1.0, 0.0, 0.0);
        let plate = rotated_element(FRAC_PI_4, linear_retarder(FRAC_PI_2));
        assert!(close(plate * horizontal, Vec4::new(1.0, 0.0, 0.0, 1.0)));
        let diagonal = Vec4::new(1.0, 0.0, 1.0, 0.0);
        let out = linear_retarder(FRAC_PI_2) * diagonal;
        assert!(close(out, Vec4::new(1.0, 0.0, 0.0, -1.0)), "{out}");
        // The circular polarizers pass their own handedness and block the other.
        let right = Vec4::new(1.0, 0.0, 0.0, 1.0);
        let left = Vec4::new(1.0, 0.0, 0.0, -1.0);
        assert!(close(right_circular_polarizer() * right, right));
        assert!(close(right_circular_polarizer() * left, Vec4::ZERO));
        assert!(close(left_circular_polarizer() * left, left));
        assert!(close(left_circular_polarizer() * right, Vec4::ZERO));
    }

    /// The examples of Mitsuba's documentation of `rotator` and `rotate_stokes_basis`, and the
    /// inverse of a basis change is the change back.
    #[test]
    fn frame_rotations_follow_mitsuba() {
        let horizontal = Vec4::new(1.0, 1.0, 0.0, 0.0);
        assert!(close(
            rotator(FRAC_PI_4) * horizontal,
            Vec4::new(1.0, 0.0, -1.0, 0.0)
        ));
        let h = std::f32::consts::FRAC_1_SQRT_2;
        let r = rotate_stokes_basis(Vec3::Z, Vec3::X, Vec3::new(h, -h, 0.0));
        assert!(
            close(r * horizontal, Vec4::new(1.0, 0.0, 1.0, 0.0)),
            "{}",
            r * horizontal
        );
        let back = rotate_stokes_basis(Vec3::Z, Vec3::new(h, -h, 0.0), Vec3::X);
        assert!((back * r).abs_diff_eq(Mat4::IDENTITY, 1e-6));
        // A basis change along −z turns the other way.
        let r = rotate_stokes_basis(-Vec3::Z, Vec3::X, Vec3::new(h, -h, 0.0));
        assert!(close(r * horizontal, Vec4::new(1.0, 0.0, -1.0, 0.0)));
        // The same reference direction changes nothing, even when it is reversed (a frame
        // turned by 180° describes the same polarization).
        assert!(rotate_stokes_basis(Vec3::Z, Vec3::X, Vec3::X).abs_diff_eq(Mat4::IDENTITY, 1e-6));
        assert!(rotate_stokes_basis(Vec3::Z, Vec3::X, -Vec3::X).abs_diff_eq(Mat4::IDENTITY, 1e-6));
        // The implicit basis is orthogonal to the beam.
        for forward in [
            Vec3::Z,
            -Vec3::Z,
            Vec3::new(0.6, 0.0, 0.8),
            Vec3::new(0.0, -0.8, -0.6),
        ] {
            let basis = stokes_basis(forward);
            assert!(basis.dot(forward).abs() < 1e-6 && (basis.length() - 1.0).abs() < 1e-6);
        }
    }

    /// Turning a polarizer by θ is the same as turning the frame of the light the other way.
    #[test]
    fn a_rotated_polarizer_is_a_rotated_frame() {
        let theta = 0.3f32;
        let m = rotated_element(theta, linear_polarizer(1.0));
        let via_frames = FrameChange {
            r_in: rotator(-theta),
            r_out: rotator(-theta),
        };
        assert!(m.abs_diff_eq(via_frames.apply(linear_polarizer(1.0)), 1e-6));
        let change = FrameChange::collinear(Vec3::Z, Vec3::X, Vec3::new(0.0, 1.0, 0.0));
        let m = change.apply(linear_polarizer(1.0));
        // Horizontal in the old frame is vertical in the new one.
        let vertical = Vec4::new(1.0, -1.0, 0.0, 0.0);
        assert!(close(m * vertical, vertical));
    }

    #[test]
    fn sampled_matrices_act_per_wavelength() {
        let value = SampledSpectrum([0.1, 0.2, 0.3, 0.4]);
        let m = SampledMueller::splat(linear_polarizer(1.0)).scaled(value);
        assert_eq!(m.m00(), value * 0.5);
        let s = (m * SampledMueller::absorber(value)).apply_unpolarized(SampledSpectrum::ONE);
        for i in 0..4 {
            assert!(close(
                s[i],
                Vec4::new(1.0, 1.0, 0.0, 0.0) * 0.5 * value[i] * value[i]
            ));
        }
        assert_eq!(SampledMueller::depolarizer(value).m00(), value);
    }
}
