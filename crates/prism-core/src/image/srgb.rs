//! The sRGB transfer curve of IEC 61966-2-1, in both directions: the only place Prism encodes
//! or decodes it (PNG output, 8- and 16-bit textures and environment maps, `#rrggbb` colours).

/// Encoded → linear: v/12.92 for v ≤ 0.04045, else ((v + 0.055)/1.055)^2.4.
#[inline]
pub fn decode(v: f32) -> f32 {
    if v <= 0.04045 {
        v / 12.92
    } else {
        ((v + 0.055) / 1.055).powf(2.4)
    }
}

/// Linear → encoded, the exact piecewise form: 12.92 x for x ≤ 0.0031308, else
/// 1.055 x^(1/2.4) − 0.055. The standard's constants are rounded, so the pieces meet at the knee
/// only to within 3·10⁻⁸ (the power piece starts that much lower), far below 8-bit resolution.
#[inline]
pub fn encode(linear: f32) -> f32 {
    if linear <= 0.003_130_8 {
        12.92 * linear
    } else {
        1.055 * linear.powf(1.0 / 2.4) - 0.055
    }
}

/// One 8-bit sRGB value from a linear one: clamp to [0, 1] (NaN to 0), encode, round to nearest.
pub fn encode_u8(linear: f32) -> u8 {
    let clamped = if linear.is_nan() {
        0.0
    } else {
        linear.clamp(0.0, 1.0)
    };
    (encode(clamped) * 255.0).round() as u8
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn encode_is_continuous_at_the_knee() {
        let knee = 0.003_130_8f32;
        let below = encode(knee);
        let above = encode(knee.next_up());
        assert!((above - below).abs() < 1e-7, "{below} vs {above}");
        assert!((below - 0.040_449_936).abs() < 1e-9);
        assert_eq!(encode(0.0), 0.0);
        assert!((encode(1.0) - 1.0).abs() < 1e-6);
    }

    #[test]
    fn decode_inverts_encode() {
        for i in 0..=1000 {
            let x = i as f32 / 1000.0;
            let back = decode(encode(x));
            assert!((back - x).abs() <= 2e-6 * x.max(1e-3), "{x} -> {back}");
        }
    }
}
