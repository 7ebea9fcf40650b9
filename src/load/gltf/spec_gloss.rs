//! `KHR_materials_pbrSpecularGlossiness` (archived, still common in older downloads)
//! converted to the metallic–roughness model, by the conversion Khronos published with the
//! extension ("convert between workflows"): the metalness that reproduces the diffuse and
//! specular brightness (perceived as √(0.299 r² + 0.587 g² + 0.114 b²)) given a dielectric
//! F0 of 0.04, a base colour blended from the diffuse and specular colours by metalness²,
//! and roughness = 1 − glossiness; with textures, the same conversion texel by texel.

use glam::{Vec3, Vec4};

use crate::scene::{Texture, linear_to_srgb, srgb_to_linear};

/// The extension's name.
pub const EXTENSION: &str = "KHR_materials_pbrSpecularGlossiness";

/// F0 of the dielectrics the metallic–roughness model assumes.
const DIELECTRIC_F0: f32 = 0.04;
const EPSILON: f32 = 1e-6;

/// A material's colour and scattering in the metallic–roughness model.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct MetalRough {
    pub base_colour: Vec3,
    pub alpha: f32,
    pub metallic: f32,
    pub roughness: f32,
}

/// The metallic–roughness equivalent of a diffuse colour (with alpha), a specular colour
/// (F0) and a glossiness.
pub(super) fn convert(diffuse: Vec4, specular: Vec3, glossiness: f32) -> MetalRough {
    let one_minus_specular = 1.0 - specular.max_element();
    let metallic = solve_metallic(
        brightness(diffuse.truncate()),
        brightness(specular),
        one_minus_specular,
    );
    let from_diffuse = diffuse.truncate() * one_minus_specular
        / (1.0 - DIELECTRIC_F0)
        / (1.0 - metallic).max(EPSILON);
    let from_specular =
        (specular - Vec3::splat(DIELECTRIC_F0 * (1.0 - metallic))) / metallic.max(EPSILON);
    let base_colour = from_diffuse
        .lerp(from_specular, metallic * metallic)
        .clamp(Vec3::ZERO, Vec3::ONE);
    MetalRough {
        base_colour,
        alpha: diffuse.w,
        metallic,
        roughness: (1.0 - glossiness).clamp(0.0, 1.0),
    }
}

/// Perceived brightness of a colour.
fn brightness(c: Vec3) -> f32 {
    (0.299 * c.x * c.x + 0.587 * c.y * c.y + 0.114 * c.z * c.z).sqrt()
}

/// The metalness whose mix of a dielectric and a metal gives these brightnesses: the
/// positive root of 0.04·m² + b·m + (0.04 − specular) = 0.
fn solve_metallic(diffuse: f32, specular: f32, one_minus_specular: f32) -> f32 {
    if specular < DIELECTRIC_F0 {
        return 0.0;
    }
    let a = DIELECTRIC_F0;
    let b = diffuse * one_minus_specular / (1.0 - DIELECTRIC_F0) + specular - 2.0 * DIELECTRIC_F0;
    let c = DIELECTRIC_F0 - specular;
    let discriminant = (b * b - 4.0 * a * c).max(0.0);
    ((-b + discriminant.sqrt()) / (2.0 * a)).clamp(0.0, 1.0)
}

/// A specular–glossiness texture pair baked texel by texel into a base colour texture
/// (sRGB, alpha from the diffuse texture) and a metallic–roughness texture (G roughness,
/// B metallic, linear), with the factors folded in, at the finer of the two resolutions
/// (each read at its texel nearest the same position).
pub(super) fn bake(
    diffuse: Option<&Texture>,
    spec_gloss: &Texture,
    factors: (Vec4, Vec3, f32),
    name: &str,
) -> (Texture, Texture) {
    let (diffuse_factor, specular_factor, glossiness_factor) = factors;
    let width = diffuse.map_or(0, |d| d.width).max(spec_gloss.width);
    let height = diffuse.map_or(0, |d| d.height).max(spec_gloss.height);
    // Texel (x, y) of the baked image in texture `t`.
    let at = |t: &Texture, x: u32, y: u32| {
        let tx = (u64::from(x) * u64::from(t.width) / u64::from(width)) as u32;
        let ty = (u64::from(y) * u64::from(t.height) / u64::from(height)) as u32;
        t.texels[(ty * t.width + tx) as usize]
    };
    let unit = |c: u16| f32::from(c) / 65535.0;
    let encode = |v: f32| (v.clamp(0.0, 1.0) * 65535.0).round() as u16;
    let mut base = Vec::with_capacity((width * height) as usize);
    let mut metal_rough = Vec::with_capacity((width * height) as usize);
    for y in 0..height {
        for x in 0..width {
            let sg = at(spec_gloss, x, y);
            let d = diffuse.map_or([65535; 4], |t| at(t, x, y));
            let linear = |c: u16| srgb_to_linear(unit(c));
            let diffuse = Vec4::new(linear(d[0]), linear(d[1]), linear(d[2]), 1.0)
                * diffuse_factor.with_w(1.0);
            let specular = Vec3::new(linear(sg[0]), linear(sg[1]), linear(sg[2])) * specular_factor;
            let m = convert(diffuse, specular, unit(sg[3]) * glossiness_factor);
            base.push([
                encode(linear_to_srgb(m.base_colour.x)),
                encode(linear_to_srgb(m.base_colour.y)),
                encode(linear_to_srgb(m.base_colour.z)),
                d[3],
            ]);
            metal_rough.push([0, encode(m.roughness), encode(m.metallic), 65535]);
        }
    }
    let texture = |suffix: &str, texels| Texture {
        name: format!("{name} ({suffix}, from specular-glossiness)"),
        width,
        height,
        texels,
        tiles: Vec::new(),
    };
    (
        texture("base colour", base),
        texture("metallic-roughness", metal_rough),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_plain_dielectric_keeps_its_colour_and_is_not_metal() {
        // F0 0.04 removes 4 % from the diffuse side, which the conversion gives back.
        let m = convert(Vec4::new(0.5, 0.2, 0.1, 0.7), Vec3::splat(0.04), 0.75);
        assert!(m.metallic < 1e-3, "{m:?}");
        assert!(
            (m.base_colour - Vec3::new(0.5, 0.2, 0.1))
                .abs()
                .max_element()
                < 1e-3
        );
        assert_eq!(m.alpha, 0.7);
        assert!((m.roughness - 0.25).abs() < 1e-6);
    }

    #[test]
    fn black_diffuse_with_coloured_specular_is_a_metal_of_that_colour() {
        let gold = Vec3::new(1.0, 0.77, 0.34);
        let m = convert(Vec4::new(0.0, 0.0, 0.0, 1.0), gold, 1.0);
        assert!(m.metallic > 0.99, "{m:?}");
        assert!((m.base_colour - gold).abs().max_element() < 0.02, "{m:?}");
        assert_eq!(m.roughness, 0.0);
    }

    #[test]
    fn no_specular_means_no_metal() {
        let m = convert(Vec4::new(0.8, 0.8, 0.8, 1.0), Vec3::ZERO, 0.0);
        assert_eq!(m.metallic, 0.0);
        assert!(
            (m.base_colour - Vec3::splat(0.8 / 0.96))
                .abs()
                .max_element()
                < 1e-5
        );
        assert_eq!(m.roughness, 1.0);
    }
}
