//! From radiosity to display values: exposure, the sRGB transfer curve and 8-bit output.

use penumbra_scenes::Rgb;

/// Which luminance percentile of the lit (non-emitting) pixels automatic exposure looks at.
pub(crate) const AUTO_EXPOSURE_PERCENTILE: f64 = 0.95;
/// The display value, before the sRGB curve, that automatic exposure maps that percentile to:
/// bright but short of clipping.
pub(crate) const AUTO_EXPOSURE_TARGET: f64 = 0.8;

/// Relative luminance of a linear RGB colour (Rec. 709 / sRGB primaries).
pub fn luminance(c: Rgb) -> f64 {
    0.2126 * c.r + 0.7152 * c.g + 0.0722 * c.b
}

/// The sRGB transfer curve (IEC 61966-2-1) from linear to encoded values, both in `[0, 1]`:
/// linear below 0.0031308, a 1/2.4 power above. Input outside `[0, 1]` is clamped; NaN gives 0.
pub fn srgb_encode(linear: f64) -> f64 {
    if linear.is_nan() || linear <= 0.0 {
        return 0.0;
    }
    if linear >= 1.0 {
        return 1.0;
    }
    if linear <= 0.003_130_8 {
        12.92 * linear
    } else {
        1.055 * linear.powf(1.0 / 2.4) - 0.055
    }
}

/// An 8-bit sRGB pixel of `linear * exposure`. NaN displays as black.
pub fn to_srgb8(linear: Rgb, exposure: f64) -> [u8; 3] {
    // In [0, 255] after the clamp in `srgb_encode`, so the cast is exact.
    let encode = |v: f64| (srgb_encode(v * exposure) * 255.0).round() as u8;
    [encode(linear.r), encode(linear.g), encode(linear.b)]
}

/// The exposure that maps the [`AUTO_EXPOSURE_PERCENTILE`] of `luminances` to
/// [`AUTO_EXPOSURE_TARGET`]; `None` when there are no values or that percentile is not
/// positive. The slice is reordered.
pub(crate) fn auto_exposure(luminances: &mut [f64]) -> Option<f64> {
    let reference = percentile(luminances, AUTO_EXPOSURE_PERCENTILE)?;
    let exposure = AUTO_EXPOSURE_TARGET / reference;
    (reference > 0.0 && exposure.is_finite()).then_some(exposure)
}

/// The value at quantile `q` in `[0, 1]` (nearest rank), reordering `values`.
fn percentile(values: &mut [f64], q: f64) -> Option<f64> {
    if values.is_empty() {
        return None;
    }
    let rank = ((values.len() - 1) as f64 * q).round() as usize;
    let (_, value, _) = values.select_nth_unstable_by(rank, f64::total_cmp);
    Some(*value)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn srgb_curve_at_known_points() {
        assert_eq!(srgb_encode(0.0), 0.0);
        assert!((srgb_encode(0.003_130_8) - 0.040_45).abs() < 1e-6);
        assert_eq!(srgb_encode(1.0), 1.0);
        assert!((srgb_encode(1.0 - 1e-12) - 1.0).abs() < 1e-11);
        // Middle grey (18%) encodes to about 46%.
        assert!((srgb_encode(0.18) - 0.4614).abs() < 1e-3);
        // The two pieces meet continuously.
        let below = srgb_encode(0.003_130_8 - 1e-12);
        let above = srgb_encode(0.003_130_8 + 1e-12);
        assert!((above - below).abs() < 1e-7);
        assert_eq!(srgb_encode(-1.0), 0.0);
        assert_eq!(srgb_encode(7.0), 1.0);
    }

    #[test]
    fn eight_bit_output() {
        assert_eq!(to_srgb8(Rgb::new(0.0, 1.0, 2.0), 1.0), [0, 255, 255]);
        assert_eq!(to_srgb8(Rgb::splat(f64::NAN), 1.0), [0, 0, 0]);
        assert_eq!(to_srgb8(Rgb::splat(0.5), 2.0), [255, 255, 255]);
    }

    #[test]
    fn auto_exposure_maps_the_percentile() {
        let mut values: Vec<f64> = (0..=100).map(f64::from).collect();
        let exposure = auto_exposure(&mut values).expect("positive values");
        assert!((exposure * 95.0 - AUTO_EXPOSURE_TARGET).abs() < 1e-12);
        assert_eq!(auto_exposure(&mut []), None);
        assert_eq!(auto_exposure(&mut [0.0, 0.0]), None);
    }
}
