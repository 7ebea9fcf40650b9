//! AgX image formation as Blender 5 implements it (its default view transform).
//!
//! Blender applies AgX through a 57³ LUT baked by Eary Chow's generator (the AgX
//! repository that Blender's `config.ocio` names), itself built on Troy Sobotka's AgX
//! (SB2383) and Jed Smith's tunable sigmoid. We evaluate the same steps in closed form:
//! 1. linear Rec.709 → linear Rec.2020, negatives lifted (Blender's lower guard rail is the
//!    identity for non-negative colours, which is all a render produces);
//! 2. the *inset* matrix, which pulls the primaries towards white and rotates them
//!    (Blender's "AgX Log" colour space: rotate [2.140, −1.228, −3.052]°, inset
//!    [0.330, 0.281, 0.125], from Rec.2020);
//! 3. per channel: log2 exposure relative to 0.18 over −10 … +6.5 stops, through the
//!    sigmoid (pivot at middle grey, slope 2.4, toe and shoulder powers 1.5), raised to the
//!    power 2.4 back to linear;
//! 4. 40 % of the hue lost by the per-channel curve is restored (HSV hue interpolated
//!    between before and after the curve);
//! 5. the *outset* matrix, the inverse of an inset by [0.323, 0.283, 0.037] without
//!    rotation, gives back chroma;
//! 6. Rec.2020 → Rec.709 with Blender's lower guard rail for the sRGB gamut (negatives
//!    offset away, luminance kept), clipped to [0, 1] for display.
//!
//! The sRGB display's encoding (the piecewise sRGB curve) is the caller's.

use glam::{DMat3, DVec2, DVec3};

/// Middle grey, the log encoding's anchor.
const MIDDLE_GREY: f64 = 0.18;
/// The log encoding's range in stops around middle grey.
const LOG2_MIN: f64 = -10.0;
const LOG2_MAX: f64 = 6.5;
/// The sigmoid's slope at its pivot, and its toe and shoulder powers.
const SLOPE: f64 = 2.4;
const POWER: f64 = 1.5;
/// The display-referred transfer the sigmoid's output is encoded with.
const DISPLAY_GAMMA: f64 = 2.4;
/// How much of the pre-curve hue is restored.
const HUE_RESTORE: f64 = 0.4;

/// Rec.2020 luminance weights computed with the CIE 2015 observer and the D65 spectrum,
/// as the guard rail uses them.
const REC2020_LUMINANCE: DVec3 = DVec3::new(
    0.258_923_535_568_984_8,
    0.610_498_534_606_652_5,
    0.130_577_929_824_362_84,
);

const D65: DVec2 = DVec2::new(0.3127, 0.3290);
const REC709: [DVec2; 3] = [
    DVec2::new(0.64, 0.33),
    DVec2::new(0.30, 0.60),
    DVec2::new(0.15, 0.06),
];
const REC2020: [DVec2; 3] = [
    DVec2::new(0.708, 0.292),
    DVec2::new(0.170, 0.797),
    DVec2::new(0.131, 0.046),
];

/// The matrices of one AgX evaluation, derived once.
pub struct Agx {
    rec2020_from_rec709: DMat3,
    rec709_from_rec2020: DMat3,
    inset: DMat3,
    outset: DMat3,
    toe_scale: f64,
    shoulder_scale: f64,
    pivot: DVec2,
}

impl Default for Agx {
    fn default() -> Self {
        Self::new()
    }
}

impl Agx {
    /// AgX with Blender 5's parameters.
    pub fn new() -> Agx {
        let rec2020_from_rec709 = xyz_from_rgb(REC2020, D65).inverse() * xyz_from_rgb(REC709, D65);
        // Blender's config.ocio, colour space "AgX Log" (row-major, out = M·in).
        let inset = DMat3::from_cols_array(&[
            0.856_627_153_315_983,
            0.137_318_972_929_847,
            0.111_898_212_999_95,
            0.095_121_240_538_158_8,
            0.761_241_990_602_591,
            0.076_799_418_603_190_3,
            0.048_251_606_145_858_3,
            0.101_439_036_467_562,
            0.811_302_368_396_859,
        ]);
        let outset_primaries = [0.323_174_38, 0.283_256_05, 0.037_432_6];
        let scaled =
            std::array::from_fn(|i| D65 + (REC2020[i] - D65) * (1.0 - outset_primaries[i]));
        let outset = (xyz_from_rgb(REC2020, D65).inverse() * xyz_from_rgb(scaled, D65)).inverse();
        let pivot = DVec2::new(
            -LOG2_MIN / (LOG2_MAX - LOG2_MIN),
            MIDDLE_GREY.powf(1.0 / DISPLAY_GAMMA),
        );
        Agx {
            rec2020_from_rec709,
            rec709_from_rec2020: rec2020_from_rec709.inverse(),
            inset,
            outset,
            // Each side's scale makes it meet its corner: (0, 0) for the toe, (1, 1) for
            // the shoulder.
            toe_scale: -sigmoid_scale(pivot),
            shoulder_scale: sigmoid_scale(DVec2::ONE - pivot),
            pivot,
        }
    }

    /// Scene-linear Rec.709 to display-linear Rec.709 in [0, 1].
    pub fn form(&self, rgb: DVec3) -> DVec3 {
        let rec2020 = (self.rec2020_from_rec709 * rgb).max(DVec3::ZERO);
        let inset = self.inset * rec2020;
        let hue_before = hsv(inset).x;
        let curved = DVec3::from_array(inset.to_array().map(|c| self.curve(c)));
        let after = hsv(curved);
        let hue = lerp_hue(hue_before, after.x, HUE_RESTORE);
        let restored = from_hsv(DVec3::new(hue, after.y, after.z));
        let rec709 = self.rec709_from_rec2020 * (self.outset * restored);
        self.lower_guard_rail(rec709).clamp(DVec3::ZERO, DVec3::ONE)
    }

    /// One channel through the log encoding, the sigmoid and back to linear.
    fn curve(&self, linear: f64) -> f64 {
        if linear <= 0.0 || linear.is_nan() {
            return 0.0;
        }
        let x = ((linear / MIDDLE_GREY).log2() - LOG2_MIN) / (LOG2_MAX - LOG2_MIN);
        let scale = if x < self.pivot.x {
            self.toe_scale
        } else {
            self.shoulder_scale
        };
        let t = SLOPE * (x - self.pivot.x) / scale;
        let y = scale * t / (1.0 + t.powf(POWER)).powf(1.0 / POWER) + self.pivot.y;
        y.max(0.0).powf(DISPLAY_GAMMA)
    }

    /// Offsets a colour with negative components to the nearest non-negative one and
    /// rescales it so that its Rec.2020 luminance (compensated for the luminance its
    /// negative part hides) does not grow (Blender's sRGB lower guard rail).
    fn lower_guard_rail(&self, rgb: DVec3) -> DVec3 {
        let offset = (-rgb.min_element()).max(0.0);
        if offset == 0.0 {
            return rgb;
        }
        let luminance = |c: DVec3| {
            let y = (self.rec2020_from_rec709 * c).dot(REC2020_LUMINANCE);
            let inverse = DVec3::splat(c.max_element()) - c;
            let y_inverse = (self.rec2020_from_rec709 * inverse).dot(REC2020_LUMINANCE);
            let compensated = inverse.max_element() - y_inverse + y;
            let t = y.max(0.0).powf(0.08).clamp(0.0, 1.0);
            compensated + (y - compensated) * t
        };
        let before = luminance(rgb);
        let lifted = rgb + DVec3::splat(offset);
        let after = luminance(lifted);
        if after > before {
            lifted * (before / after.max(1e-100))
        } else {
            lifted
        }
    }
}

/// The sigmoid's scale for one side, so that it meets the corner `reach` away from the
/// pivot (Jed Smith's tunable sigmoid with zero-length linear section).
fn sigmoid_scale(reach: DVec2) -> f64 {
    let run = SLOPE * reach.x;
    (run.powf(-POWER) * ((run / reach.y).powf(POWER) - 1.0)).powf(-1.0 / POWER)
}

/// The RGB → XYZ matrix of a colour space with these xy primaries and white point.
fn xyz_from_rgb(primaries: [DVec2; 3], white: DVec2) -> DMat3 {
    let xyz = |c: DVec2| DVec3::new(c.x / c.y, 1.0, (1.0 - c.x - c.y) / c.y);
    let m = DMat3::from_cols(xyz(primaries[0]), xyz(primaries[1]), xyz(primaries[2]));
    let scale = m.inverse() * xyz(white);
    DMat3::from_cols(m.x_axis * scale.x, m.y_axis * scale.y, m.z_axis * scale.z)
}

/// Hue in [0, 1), saturation and value of an RGB triple (hexcone model).
fn hsv(c: DVec3) -> DVec3 {
    let max = c.max_element();
    let delta = max - c.min_element();
    if delta <= 0.0 || max <= 0.0 {
        return DVec3::new(0.0, 0.0, max);
    }
    let h = if c.x == max {
        (c.y - c.z) / delta
    } else if c.y == max {
        2.0 + (c.z - c.x) / delta
    } else {
        4.0 + (c.x - c.y) / delta
    };
    DVec3::new((h / 6.0).rem_euclid(1.0), delta / max, max)
}

/// The inverse of [`hsv`].
fn from_hsv(c: DVec3) -> DVec3 {
    let (h, s, v) = (c.x.rem_euclid(1.0) * 6.0, c.y, c.z);
    let sector = h.floor();
    let f = h - sector;
    let (p, q, t) = (v * (1.0 - s), v * (1.0 - s * f), v * (1.0 - s * (1.0 - f)));
    match sector as u8 {
        0 => DVec3::new(v, t, p),
        1 => DVec3::new(q, v, p),
        2 => DVec3::new(p, v, t),
        3 => DVec3::new(p, q, v),
        4 => DVec3::new(t, p, v),
        _ => DVec3::new(v, p, q),
    }
}

/// Interpolates hues in [0, 1) along the shorter way round the circle.
fn lerp_hue(from: f64, to: f64, t: f64) -> f64 {
    let mut to = to;
    if to - from > 0.5 {
        to -= 1.0;
    } else if to - from < -0.5 {
        to += 1.0;
    }
    (from + t * (to - from)).rem_euclid(1.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn derived_matrices_keep_white_and_match_the_published_ones() {
        let agx = Agx::new();
        for m in [agx.rec2020_from_rec709, agx.inset, agx.outset] {
            assert!((m * DVec3::ONE - DVec3::ONE).abs().max_element() < 1e-6);
        }
        // ITU-R BT.2087's Rec.709 → Rec.2020 matrix, first row.
        let row = agx.rec2020_from_rec709.row(0);
        assert!(
            (row - DVec3::new(0.6274, 0.3293, 0.0433))
                .abs()
                .max_element()
                < 1e-4
        );
    }

    #[test]
    fn the_sigmoid_passes_through_its_pivot_and_corners() {
        let agx = Agx::new();
        let grey = agx.form(DVec3::splat(MIDDLE_GREY));
        assert!((grey - DVec3::splat(MIDDLE_GREY)).abs().max_element() < 1e-9);
        let top = MIDDLE_GREY * LOG2_MAX.exp2();
        assert!((agx.curve(top) - 1.0).abs() < 1e-9);
        let bottom = MIDDLE_GREY * LOG2_MIN.exp2();
        assert!(agx.curve(bottom).abs() < 1e-9);
        assert_eq!(agx.form(DVec3::ZERO), DVec3::ZERO);
    }

    #[test]
    fn hsv_round_trips() {
        for c in [
            DVec3::new(0.2, 0.5, 0.9),
            DVec3::new(3.0, 0.1, 0.4),
            DVec3::new(0.5, 0.5, 0.1),
        ] {
            assert!((from_hsv(hsv(c)) - c).abs().max_element() < 1e-12);
        }
        assert!((lerp_hue(0.95, 0.05, 0.5) - 0.0).abs() < 1e-12);
    }
}
