//! Image textures and how materials look them up: wrap modes, nearest or bilinear filtering,
//! a texture-coordinate transform, and sRGB or linear decoding.
//!
//! Texels are kept as 16-bit unsigned normalised RGBA, decoded once from the file; whether
//! they are sRGB-encoded colour or linear data is a property of the use (glTF: base colour
//! and emission are sRGB, everything else linear), so the same image can serve both.

use std::sync::OnceLock;

use glam::{Affine2, Vec2, Vec4};

/// A decoded image.
#[derive(Clone, Debug, PartialEq)]
pub struct Texture {
    /// Name for messages (file name or image index).
    pub name: String,
    /// Width in texels.
    pub width: u32,
    /// Height in texels.
    pub height: u32,
    /// RGBA, rows top to bottom, each channel 0..=65535.
    pub texels: Vec<[u16; 4]>,
    /// A UDIM set's tiles by number, sorted, each one image (its own `tiles` empty); empty
    /// for an ordinary image.
    pub tiles: Vec<(u32, Texture)>,
}

/// The first UDIM tile number, and how many tiles a row of the UDIM grid holds.
pub const UDIM_FIRST: u32 = 1001;
const UDIM_ROW: u32 = 10;
/// The last UDIM tile number: ten columns, one hundred rows.
pub const UDIM_LAST: u32 = UDIM_FIRST + UDIM_ROW * 100 - 1;

/// How texture coordinates outside [0, 1] are brought back in (glTF sampler `wrapS/T`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Wrap {
    /// Tile.
    #[default]
    Repeat,
    /// Tile, mirroring every other tile.
    MirroredRepeat,
    /// Hold the edge texel.
    ClampToEdge,
}

/// Reconstruction filter. Without mipmaps, minification also uses these; the renderer's many
/// samples per pixel average what a mipmap would.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Filter {
    /// The nearest texel.
    Nearest,
    /// Bilinear interpolation of the four nearest texels.
    #[default]
    Linear,
}

/// How texel values are turned into numbers.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ColorSpace {
    /// sRGB transfer function on RGB (IEC 61966-2-1), alpha linear.
    Srgb,
    /// Values as stored.
    Linear,
}

/// One use of a texture by a material.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TextureRef {
    /// Index into [`super::Scene::textures`].
    pub texture: usize,
    /// Which texture-coordinate set of the mesh (`TEXCOORD_n`).
    pub texcoord: usize,
    /// Applied to the texture coordinates before lookup (`KHR_texture_transform`).
    pub transform: Affine2,
    /// Horizontal wrap.
    pub wrap_u: Wrap,
    /// Vertical wrap.
    pub wrap_v: Wrap,
    /// Reconstruction filter.
    pub filter: Filter,
}

impl TextureRef {
    /// A use of texture `texture` through texture-coordinate set 0, repeating, bilinear.
    pub fn new(texture: usize) -> TextureRef {
        TextureRef {
            texture,
            texcoord: 0,
            transform: Affine2::IDENTITY,
            wrap_u: Wrap::Repeat,
            wrap_v: Wrap::Repeat,
            filter: Filter::Linear,
        }
    }
}

impl Texture {
    /// The filtered value at texture coordinates `uv` ((0, 0) = top-left of the image, as
    /// glTF defines them), decoded in `space`.
    pub fn sample(&self, reference: &TextureRef, uv: Vec2, space: ColorSpace) -> Vec4 {
        if !self.tiles.is_empty() {
            return self.sample_tile(reference, uv, space);
        }
        if self.texels.is_empty() {
            return Vec4::ONE;
        }
        let uv = reference.transform.transform_point2(uv);
        let (w, h) = (self.width as f32, self.height as f32);
        match reference.filter {
            Filter::Nearest => {
                let x = wrap((uv.x * w).floor() as i64, self.width, reference.wrap_u);
                let y = wrap((uv.y * h).floor() as i64, self.height, reference.wrap_v);
                self.texel(x, y, space)
            }
            Filter::Linear => {
                // Texel centres sit at half-integers.
                let (fx, fy) = (uv.x * w - 0.5, uv.y * h - 0.5);
                let (x0, y0) = (fx.floor(), fy.floor());
                let (tx, ty) = (fx - x0, fy - y0);
                let xs = [x0 as i64, x0 as i64 + 1].map(|x| wrap(x, self.width, reference.wrap_u));
                let ys = [y0 as i64, y0 as i64 + 1].map(|y| wrap(y, self.height, reference.wrap_v));
                let top = self
                    .texel(xs[0], ys[0], space)
                    .lerp(self.texel(xs[1], ys[0], space), tx);
                let bottom = self
                    .texel(xs[0], ys[1], space)
                    .lerp(self.texel(xs[1], ys[1], space), tx);
                top.lerp(bottom, ty)
            }
        }
    }

    /// A UDIM set looked up: the tile holding the (transformed) coordinates, numbered
    /// 1001 + ⌊s⌋ + 10·⌊t⌋ in USD's st (t = 1 − v here), read at the coordinates' fraction
    /// with the reference's wrap modes applied within the tile (filtering at a repeating
    /// tile's edge reads its opposite edge, as Cycles does). Where no tile is, the value is
    /// neutral (1), as for an image that could not be read.
    fn sample_tile(&self, reference: &TextureRef, uv: Vec2, space: ColorSpace) -> Vec4 {
        let uv = reference.transform.transform_point2(uv);
        let st = Vec2::new(uv.x, 1.0 - uv.y);
        let cell = st.floor();
        if !(0.0..UDIM_ROW as f32).contains(&cell.x) || !(0.0..100.0).contains(&cell.y) {
            return Vec4::ONE;
        }
        let number = UDIM_FIRST + cell.x as u32 + UDIM_ROW * cell.y as u32;
        let Ok(i) = self.tiles.binary_search_by_key(&number, |(n, _)| *n) else {
            return Vec4::ONE;
        };
        let local = st - cell;
        let inside = TextureRef {
            transform: Affine2::IDENTITY,
            ..*reference
        };
        self.tiles[i]
            .1
            .sample(&inside, Vec2::new(local.x, 1.0 - local.y), space)
    }

    /// Mean of all texels in `space`: what a texture contributes on average, for choosing
    /// textured lights by power. A UDIM set's is the mean of its tiles'.
    pub fn mean(&self, space: ColorSpace) -> Vec4 {
        if !self.tiles.is_empty() {
            let sum: Vec4 = self.tiles.iter().map(|(_, t)| t.mean(space)).sum();
            return sum / self.tiles.len() as f32;
        }
        if self.texels.is_empty() {
            return Vec4::ONE;
        }
        let mut sum = glam::DVec4::ZERO;
        for y in 0..self.height {
            for x in 0..self.width {
                sum += self.texel(x, y, space).as_dvec4();
            }
        }
        (sum / self.texels.len() as f64).as_vec4()
    }

    fn texel(&self, x: u32, y: u32, space: ColorSpace) -> Vec4 {
        let [r, g, b, a] = self.texels[(y * self.width + x) as usize];
        let alpha = a as f32 / 65535.0;
        match space {
            ColorSpace::Linear => Vec4::new(
                r as f32 / 65535.0,
                g as f32 / 65535.0,
                b as f32 / 65535.0,
                alpha,
            ),
            ColorSpace::Srgb => {
                let table = srgb_table();
                Vec4::new(
                    table[r as usize],
                    table[g as usize],
                    table[b as usize],
                    alpha,
                )
            }
        }
    }
}

/// The texel index for integer coordinate `i` on an axis of `size` texels.
fn wrap(i: i64, size: u32, mode: Wrap) -> u32 {
    let n = size as i64;
    let i = match mode {
        Wrap::Repeat => i.rem_euclid(n),
        Wrap::ClampToEdge => i.clamp(0, n - 1),
        Wrap::MirroredRepeat => {
            let period = i.rem_euclid(2 * n);
            if period < n {
                period
            } else {
                2 * n - 1 - period
            }
        }
    };
    i as u32
}

/// sRGB decoding of every 16-bit value, computed once.
fn srgb_table() -> &'static [f32] {
    static TABLE: OnceLock<Vec<f32>> = OnceLock::new();
    TABLE.get_or_init(|| {
        (0..=u16::MAX)
            .map(|v| srgb_to_linear(v as f32 / 65535.0))
            .collect()
    })
}

/// The sRGB encoding of a linear value (IEC 61966-2-1), clamped to [0, 1].
pub fn linear_to_srgb(x: f32) -> f32 {
    let x = if x.is_nan() { 0.0 } else { x.clamp(0.0, 1.0) };
    if x <= 0.003_130_8 {
        12.92 * x
    } else {
        (1.055 * x.powf(1.0 / 2.4) - 0.055).min(1.0)
    }
}

/// The sRGB electro-optical transfer function (IEC 61966-2-1).
pub fn srgb_to_linear(v: f32) -> f32 {
    if v <= 0.04045 {
        v / 12.92
    } else {
        ((v + 0.055) / 1.055).powf(2.4)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn checker() -> Texture {
        // 2×2: black, white / white, black (8-bit values scaled to 16 bits).
        let (k, w) = ([0, 0, 0, 65535], [65535, 65535, 65535, 65535]);
        Texture {
            name: "checker".into(),
            width: 2,
            height: 2,
            texels: vec![k, w, w, k],
            tiles: Vec::new(),
        }
    }

    /// One texel of one grey level.
    fn grey(level: u16) -> Texture {
        Texture {
            name: format!("grey {level}"),
            width: 1,
            height: 1,
            texels: vec![[level, level, level, 65535]],
            tiles: Vec::new(),
        }
    }

    #[test]
    fn udim_tiles_are_found_by_their_number_in_st() {
        // Tiles 1001 (s 0–1, t 0–1), 1002 (s 1–2) and 1011 (t 1–2); here v = 1 − t.
        let set = Texture {
            name: "set".into(),
            width: 1,
            height: 1,
            texels: Vec::new(),
            tiles: vec![(1001, grey(0)), (1002, grey(32768)), (1011, grey(65535))],
        };
        let at = |u: f32, v: f32| {
            set.sample(&TextureRef::new(0), Vec2::new(u, v), ColorSpace::Linear)
                .x
        };
        assert_eq!(at(0.5, 0.5), 0.0);
        assert!((at(1.5, 0.25) - 0.5).abs() < 1e-4);
        assert_eq!(at(0.5, -0.5), 1.0);
        // No tile 1012, and nothing left of s = 0: neutral.
        assert_eq!(at(1.5, -0.5), 1.0);
        assert_eq!(at(-0.5, 0.5), 1.0);
        assert!((set.mean(ColorSpace::Linear).x - 0.5).abs() < 1e-4);
    }

    #[test]
    fn wrap_modes_fold_coordinates_back() {
        assert_eq!(wrap(-1, 4, Wrap::Repeat), 3);
        assert_eq!(wrap(5, 4, Wrap::Repeat), 1);
        assert_eq!(wrap(-1, 4, Wrap::ClampToEdge), 0);
        assert_eq!(wrap(9, 4, Wrap::ClampToEdge), 3);
        assert_eq!(wrap(4, 4, Wrap::MirroredRepeat), 3);
        assert_eq!(wrap(-1, 4, Wrap::MirroredRepeat), 0);
        assert_eq!(wrap(7, 4, Wrap::MirroredRepeat), 0);
        assert_eq!(wrap(8, 4, Wrap::MirroredRepeat), 0);
    }

    #[test]
    fn nearest_and_bilinear_lookups() {
        let t = checker();
        let mut r = TextureRef::new(0);
        r.filter = Filter::Nearest;
        assert_eq!(
            t.sample(&r, Vec2::new(0.25, 0.25), ColorSpace::Linear).x,
            0.0
        );
        assert_eq!(
            t.sample(&r, Vec2::new(0.75, 0.25), ColorSpace::Linear).x,
            1.0
        );
        assert_eq!(
            t.sample(&r, Vec2::new(1.25, 0.25), ColorSpace::Linear).x,
            0.0
        );
        r.filter = Filter::Linear;
        // Texel centres give the texel; the middle of the image averages all four.
        assert_eq!(
            t.sample(&r, Vec2::new(0.75, 0.25), ColorSpace::Linear).x,
            1.0
        );
        let mid = t.sample(&r, Vec2::new(0.5, 0.5), ColorSpace::Linear).x;
        assert!((mid - 0.5).abs() < 1e-6, "{mid}");
        // Halfway between a black and a white centre along x.
        let edge = t.sample(&r, Vec2::new(0.5, 0.25), ColorSpace::Linear).x;
        assert!((edge - 0.5).abs() < 1e-6, "{edge}");
    }

    #[test]
    fn srgb_decoding_matches_the_standard() {
        assert_eq!(srgb_to_linear(0.0), 0.0);
        assert!((srgb_to_linear(1.0) - 1.0).abs() < 1e-6);
        // 8-bit 188 is ~0.5 linear.
        assert!((srgb_to_linear(188.0 / 255.0) - 0.5029).abs() < 1e-3);
        let t = Texture {
            name: "grey".into(),
            width: 1,
            height: 1,
            texels: vec![[188 * 257, 188 * 257, 188 * 257, 65535]],
            tiles: Vec::new(),
        };
        let v = t.sample(&TextureRef::new(0), Vec2::ZERO, ColorSpace::Srgb);
        assert!((v.x - 0.5029).abs() < 1e-3 && v.w == 1.0, "{v}");
    }

    #[test]
    fn transform_applies_before_lookup() {
        let t = checker();
        let mut r = TextureRef::new(0);
        r.filter = Filter::Nearest;
        r.transform = Affine2::from_translation(Vec2::new(0.5, 0.0));
        assert_eq!(
            t.sample(&r, Vec2::new(0.25, 0.25), ColorSpace::Linear).x,
            1.0
        );
    }
}
