//! Transforms that change over the shutter interval, for motion blur.
//!
//! Keyframe matrices are decomposed as M = T R S — translation, rotation, and a symmetric
//! stretch — by polar decomposition (Shoemake & Duff 1992, "Matrix Animation and Polar
//! Decomposition"; pbrt-v4 §3.9.2), and interpolated componentwise: T and S linearly, R by
//! spherical linear interpolation of quaternions. Interpolating the matrices themselves would
//! shrink rotating objects in between keys.

use glam::{DMat3, DMat4, DQuat, Mat3, Mat4, Quat, Vec3};

use super::transform::Transform;

/// One keyframe: the matrix at `time` and its decomposition.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Key {
    time: f32,
    translation: Vec3,
    rotation: Quat,
    stretch: Mat3,
    transform: Transform,
}

/// A transform given by keyframes; constant before the first key and after the last.
#[derive(Clone, Debug, PartialEq)]
pub struct AnimatedTransform {
    keys: Vec<Key>,
}

/// Why keyframes cannot be animated.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum AnimationError {
    /// No keys at all.
    Empty,
    /// Key `index` is not later than the key before it.
    OutOfOrder { index: usize },
    /// Key `index` is singular, projective or not finite.
    Singular { index: usize },
}

/// Polar decomposition of the linear part A = R S (R a rotation, S symmetric), by the iteration
/// R ← (R + R⁻ᵀ)/2, which converges quadratically to the orthogonal factor. A mirroring matrix
/// (det A < 0) gets R = −Q, S = −Qᵀ A, so that R is a proper rotation.
pub fn polar_decomposition(a: DMat3) -> (DMat3, DMat3) {
    let mut r = a;
    for _ in 0..100 {
        let next = (r + r.inverse().transpose()) * 0.5;
        let change = (next - r)
            .to_cols_array()
            .iter()
            .map(|v| v.abs())
            .fold(0.0, f64::max);
        r = next;
        if change < 1e-12 {
            break;
        }
    }
    if r.determinant() < 0.0 {
        r = -r;
    }
    let s = r.transpose() * a;
    (r, s)
}

impl AnimatedTransform {
    /// A transform that does not move.
    pub fn fixed(transform: Transform) -> AnimatedTransform {
        AnimatedTransform {
            keys: vec![Key {
                time: 0.0,
                translation: Vec3::ZERO,
                rotation: Quat::IDENTITY,
                stretch: Mat3::IDENTITY,
                transform,
            }],
        }
    }

    /// A transform from (time, matrix) keyframes in increasing time order.
    pub fn new(keys: &[(f64, DMat4)]) -> Result<AnimatedTransform, AnimationError> {
        if keys.is_empty() {
            return Err(AnimationError::Empty);
        }
        let mut decomposed = Vec::with_capacity(keys.len());
        for (index, &(time, matrix)) in keys.iter().enumerate() {
            if index > 0 && !(time > keys[index - 1].0) {
                return Err(AnimationError::OutOfOrder { index });
            }
            let transform = Transform::new(matrix).ok_or(AnimationError::Singular { index })?;
            let (rotation, stretch) = polar_decomposition(DMat3::from_mat4(matrix));
            decomposed.push(Key {
                time: time as f32,
                translation: matrix.w_axis.truncate().as_vec3(),
                rotation: DQuat::from_mat3(&rotation).normalize().as_quat(),
                stretch: stretch.as_mat3(),
                transform,
            });
        }
        Ok(AnimatedTransform { keys: decomposed })
    }

    /// Whether the transform changes over time.
    pub fn is_animated(&self) -> bool {
        self.keys.len() > 1
    }

    /// The transform at the first key (the only one of a fixed transform).
    pub fn first(&self) -> &Transform {
        &self.keys[0].transform
    }

    /// The transform at `time`.
    pub fn at(&self, time: f32) -> Transform {
        let keys = &self.keys;
        let last = keys.len() - 1;
        if keys.len() == 1 || !(time > keys[0].time) {
            return keys[0].transform;
        }
        if time >= keys[last].time {
            return keys[last].transform;
        }
        let i = keys.partition_point(|k| k.time <= time) - 1;
        let (a, b) = (&keys[i], &keys[i + 1]);
        let t = (time - a.time) / (b.time - a.time);
        Self::interpolate(a, b, t)
    }

    fn interpolate(a: &Key, b: &Key, t: f32) -> Transform {
        let translation = a.translation.lerp(b.translation, t);
        let rotation = a.rotation.slerp(b.rotation, t);
        let stretch = a.stretch * (1.0 - t) + b.stretch * t;
        let linear = Mat3::from_quat(rotation) * stretch;
        let matrix = Mat4::from_cols(
            linear.x_axis.extend(0.0),
            linear.y_axis.extend(0.0),
            linear.z_axis.extend(0.0),
            translation.extend(1.0),
        );
        Transform::new(matrix.as_dmat4()).unwrap_or(a.transform)
    }

    /// The key times.
    pub fn key_times(&self) -> impl Iterator<Item = f32> + '_ {
        self.keys.iter().map(|k| k.time)
    }

    /// The largest rotation angle (radians) between consecutive keys.
    fn largest_key_rotation(&self) -> f32 {
        self.keys
            .windows(2)
            .map(|w| w[0].rotation.angle_between(w[1].rotation))
            .fold(0.0, f32::max)
    }

    /// Bounds of the object-space box [lo, hi] swept over [t0, t1]. Corners move on straight
    /// lines between keys when the rotation does not change, so the boxes at the keys (and at t0,
    /// t1) bound the sweep exactly; when it rotates, boxes at 64 times per key interval are
    /// united and padded by the longest arc a corner can travel between two of them.
    pub fn swept_bounds(&self, lo: Vec3, hi: Vec3, t0: f32, t1: f32) -> (Vec3, Vec3) {
        const STEPS: usize = 64;
        let corners: Vec<Vec3> = (0..8)
            .map(|i| {
                Vec3::new(
                    if i & 1 == 0 { lo.x } else { hi.x },
                    if i & 2 == 0 { lo.y } else { hi.y },
                    if i & 4 == 0 { lo.z } else { hi.z },
                )
            })
            .collect();
        let mut times: Vec<f32> = vec![t0, t1];
        times.extend(self.key_times().filter(|&t| t > t0 && t < t1));
        let rotation = self.largest_key_rotation();
        if rotation > 0.0 {
            times.extend((0..=STEPS).map(|i| t0 + (t1 - t0) * i as f32 / STEPS as f32));
            for w in self.keys.windows(2) {
                let (a, b) = (w[0].time.max(t0), w[1].time.min(t1));
                if a < b {
                    times.extend((0..=STEPS).map(|i| a + (b - a) * i as f32 / STEPS as f32));
                }
            }
        }
        let (mut min, mut max) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
        let mut largest_reach = 0.0f32;
        for &t in &times {
            let transform = self.at(t);
            for &c in &corners {
                let p = transform.point(c);
                min = min.min(p);
                max = max.max(p);
                largest_reach = largest_reach.max((p - transform.point(Vec3::ZERO)).length());
            }
        }
        if rotation > 0.0 {
            // Between two sampled times a corner at distance ρ from the rotation centre turns by
            // at most rotation / STEPS, travelling at most ρ·rotation/STEPS along its arc.
            let pad = largest_reach * rotation / STEPS as f32 * 1.5 + 1e-6 * largest_reach;
            min -= Vec3::splat(pad);
            max += Vec3::splat(pad);
        }
        (min, max)
    }

    /// Whether every key is a similarity (rotation, translation and uniform scale), so that
    /// solid angles and area ratios are the same in object and world space.
    pub fn is_similarity(&self) -> bool {
        self.keys.iter().all(|k| {
            let s = k.stretch;
            let scale = s.x_axis.x;
            let tolerance = 1e-4 * scale.abs().max(1e-12);
            (s - Mat3::from_diagonal(Vec3::splat(scale)))
                .to_cols_array()
                .iter()
                .all(|v| v.abs() <= tolerance)
        })
    }

    /// The uniform scale of a similarity at `time` (see [`Self::is_similarity`]).
    pub fn uniform_scale(&self, time: f32) -> f32 {
        self.at(time).vector(Vec3::X).length()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    fn keys(a: DMat4, b: DMat4) -> AnimatedTransform {
        AnimatedTransform::new(&[(0.0, a), (1.0, b)]).unwrap()
    }

    #[test]
    fn decomposition_reproduces_the_keys() {
        let m = DMat4::from_translation(DVec3::new(1.0, -2.0, 3.0))
            * DMat4::from_axis_angle(DVec3::new(1.0, 2.0, 0.5).normalize(), 0.7)
            * DMat4::from_scale(DVec3::new(2.0, 0.5, 1.5));
        let animated = keys(DMat4::IDENTITY, m);
        let at_end = animated.at(1.0);
        let p = Vec3::new(0.3, -0.7, 2.0);
        assert!((at_end.point(p) - m.as_mat4().transform_point3(p)).length() < 1e-4);
        // Mirrored keys keep their orientation too.
        let mirror = DMat4::from_scale(DVec3::new(-1.0, 1.0, 1.0));
        let animated = keys(mirror, mirror);
        assert!((animated.at(0.5).point(p) - Vec3::new(-0.3, -0.7, 2.0)).length() < 1e-5);
    }

    #[test]
    fn rotation_is_interpolated_on_the_sphere() {
        let quarter = DMat4::from_rotation_z(std::f64::consts::FRAC_PI_2);
        let animated = keys(DMat4::IDENTITY, quarter);
        let half = animated.at(0.5);
        let p = half.point(Vec3::X);
        // 45 degrees, and still unit length (matrix interpolation would give length 0.707).
        assert!((p - Vec3::new(0.5f32.sqrt(), 0.5f32.sqrt(), 0.0)).length() < 1e-5);
        assert_eq!(animated.at(-1.0), *animated.first());
    }

    #[test]
    fn keys_out_of_order_or_singular_are_refused() {
        let m = DMat4::IDENTITY;
        assert_eq!(
            AnimatedTransform::new(&[(1.0, m), (0.5, m)]),
            Err(AnimationError::OutOfOrder { index: 1 })
        );
        assert_eq!(
            AnimatedTransform::new(&[(0.0, m), (1.0, DMat4::from_scale(DVec3::ZERO))]),
            Err(AnimationError::Singular { index: 1 })
        );
        assert_eq!(AnimatedTransform::new(&[]), Err(AnimationError::Empty));
    }

    /// The swept bounds contain the object at every time of the interval.
    #[test]
    fn swept_bounds_contain_the_moving_box() {
        let end = DMat4::from_translation(DVec3::new(3.0, 0.0, 1.0))
            * DMat4::from_rotation_y(2.5)
            * DMat4::from_scale(DVec3::splat(1.5));
        let animated = keys(DMat4::from_translation(DVec3::new(0.0, 1.0, 0.0)), end);
        let (lo, hi) = (Vec3::new(-1.0, -0.5, -2.0), Vec3::new(1.0, 0.5, 2.0));
        let (min, max) = animated.swept_bounds(lo, hi, 0.0, 1.0);
        for i in 0..=10_000 {
            let t = i as f32 / 10_000.0;
            let transform = animated.at(t);
            for c in 0..8 {
                let corner = Vec3::new(
                    if c & 1 == 0 { lo.x } else { hi.x },
                    if c & 2 == 0 { lo.y } else { hi.y },
                    if c & 4 == 0 { lo.z } else { hi.z },
                );
                let p = transform.point(corner);
                assert!(
                    p.cmpge(min - 1e-5).all() && p.cmple(max + 1e-5).all(),
                    "t {t}: {p}"
                );
            }
        }
    }
}
