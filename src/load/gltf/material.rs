//! glTF materials and their textures, as scene materials (the README's table).

use glam::{Affine2, Vec2, Vec3};

use super::files::{image_bytes, is_data_uri};
use super::{GltfLoader, MAX_UV_SETS, ROUGHNESS_WARNING, texture_transform};
use crate::load::images::decode_texture;
use crate::scene::{AlphaMode, Filter, Material, MaterialKind, MaterialTextures, TextureRef, Wrap};

impl GltfLoader {
    pub(super) fn convert_material(&mut self, material: &gltf::Material) -> Material {
        let name = material.name().map_or_else(
            || format!("material {}", material.index().unwrap_or(0)),
            String::from,
        );
        let pbr = material.pbr_metallic_roughness();
        let [r, g, b, alpha] = pbr.base_color_factor();
        let base = Vec3::new(r, g, b);
        let emission =
            Vec3::from(material.emissive_factor()) * material.emissive_strength().unwrap_or(1.0);
        let transmission = material
            .transmission()
            .map_or(0.0, |t| t.transmission_factor());
        let kind = if transmission >= 0.5 {
            MaterialKind::Glass {
                ior: material.ior().unwrap_or(1.5),
                tint: base,
            }
        } else if pbr.metallic_factor() >= 0.5 {
            MaterialKind::Mirror { reflectance: base }
        } else {
            MaterialKind::Diffuse { albedo: base }
        };
        let textures = MaterialTextures {
            base_colour: pbr.base_color_texture().and_then(|info| {
                self.texture_ref(
                    &info.texture(),
                    info.tex_coord(),
                    info.texture_transform(),
                    &name,
                )
            }),
            emissive: material.emissive_texture().and_then(|info| {
                self.texture_ref(
                    &info.texture(),
                    info.tex_coord(),
                    info.texture_transform(),
                    &name,
                )
            }),
            metallic_roughness: pbr.metallic_roughness_texture().and_then(|info| {
                self.texture_ref(
                    &info.texture(),
                    info.tex_coord(),
                    info.texture_transform(),
                    &name,
                )
            }),
            metallic_factor: pbr.metallic_factor(),
            normal: material.normal_texture().and_then(|info| {
                let mut r = self.texture_ref(&info.texture(), info.tex_coord(), None, &name)?;
                // The gltf crate exposes KHR_texture_transform on normal textures only as JSON.
                if let Some(t) = info.extension_value("KHR_texture_transform") {
                    let pair = |key: &str, default: f32| {
                        let v = &t[key];
                        Vec2::new(
                            v[0].as_f64().map_or(default, |x| x as f32),
                            v[1].as_f64().map_or(default, |x| x as f32),
                        )
                    };
                    let rotation = t["rotation"].as_f64().unwrap_or(0.0) as f32;
                    r.transform =
                        texture_transform(pair("offset", 0.0), rotation, pair("scale", 1.0));
                    if let Some(set) = t["texCoord"]
                        .as_u64()
                        .filter(|&s| (s as usize) < MAX_UV_SETS)
                    {
                        r.texcoord = set as usize;
                    }
                }
                Some(r)
            }),
            normal_scale: material.normal_texture().map_or(1.0, |n| n.scale()),
        };
        let roughness = pbr.roughness_factor();
        let ideal = matches!(
            kind,
            MaterialKind::Mirror { .. } | MaterialKind::Glass { .. }
        ) || textures.metallic_roughness.is_some();
        if ideal && roughness > ROUGHNESS_WARNING {
            self.warn(format!(
                "material '{name}': roughness {roughness} is rendered as perfectly smooth \
                 (gridtrace's mirror and glass are ideal)"
            ));
        }
        let alpha_mode = match material.alpha_mode() {
            gltf::material::AlphaMode::Opaque => AlphaMode::Opaque,
            gltf::material::AlphaMode::Mask => AlphaMode::Mask {
                cutoff: material.alpha_cutoff().unwrap_or(0.5),
            },
            gltf::material::AlphaMode::Blend => AlphaMode::Blend,
        };
        // Beer–Lambert: a distance d through the volume leaves attenuationColor, so
        // σ = −ln(colour) / d per channel (KHR_materials_volume).
        let absorption = material.volume().map_or(Vec3::ZERO, |v| {
            let distance = v.attenuation_distance();
            if distance.is_finite() && distance > 0.0 {
                let colour = Vec3::from(v.attenuation_color()).clamp(Vec3::splat(1e-6), Vec3::ONE);
                -Vec3::new(colour.x.ln(), colour.y.ln(), colour.z.ln()) / distance
            } else {
                Vec3::ZERO
            }
        });
        // A glass object's back faces are the inside of its volume, which rays leaving it
        // must cross: glass is always two-sided (Blender writes doubleSided: false with
        // KHR_materials_volume).
        let double_sided = material.double_sided() || matches!(kind, MaterialKind::Glass { .. });
        Material {
            name,
            kind,
            emission,
            double_sided,
            textures,
            vertex_colours: false,
            alpha,
            alpha_mode,
            absorption,
        }
    }

    /// A material's use of a texture: its image (decoded once), sampler, coordinate set and
    /// `KHR_texture_transform`. `None`, with a warning, when the image cannot be used; the
    /// material then shows its constant factors, as if the texture were white (or flat).
    pub(super) fn texture_ref(
        &mut self,
        texture: &gltf::Texture,
        tex_coord: u32,
        transform: Option<gltf::texture::TextureTransform>,
        material: &str,
    ) -> Option<TextureRef> {
        let image = self.image_texture(&texture.source())?;
        let texcoord = transform
            .as_ref()
            .and_then(|t| t.tex_coord())
            .unwrap_or(tex_coord) as usize;
        if texcoord >= MAX_UV_SETS {
            self.warn(format!(
                "material '{material}': TEXCOORD_{texcoord} is not supported (sets 0 to {}); ignoring the texture",
                MAX_UV_SETS - 1
            ));
            return None;
        }
        let wrap = |mode: gltf::texture::WrappingMode| match mode {
            gltf::texture::WrappingMode::ClampToEdge => Wrap::ClampToEdge,
            gltf::texture::WrappingMode::MirroredRepeat => Wrap::MirroredRepeat,
            gltf::texture::WrappingMode::Repeat => Wrap::Repeat,
        };
        let sampler = texture.sampler();
        let filter = match sampler.mag_filter() {
            Some(gltf::texture::MagFilter::Nearest) => Filter::Nearest,
            _ => Filter::Linear,
        };
        let transform = transform.map_or(Affine2::IDENTITY, |t| {
            texture_transform(Vec2::from(t.offset()), t.rotation(), Vec2::from(t.scale()))
        });
        Some(TextureRef {
            texture: image,
            texcoord,
            transform,
            wrap_u: wrap(sampler.wrap_s()),
            wrap_v: wrap(sampler.wrap_t()),
            filter,
        })
    }

    /// The scene texture of a glTF image, decoded on first use.
    pub(super) fn image_texture(&mut self, image: &gltf::Image) -> Option<usize> {
        if let Some(&known) = self.images.get(&image.index()) {
            return known;
        }
        let name = image.name().map_or_else(
            || format!("image {}", image.index()),
            |n| format!("image {} '{n}'", image.index()),
        );
        let decoded = if self.missing_images.contains(&image.index()) {
            None
        } else {
            match image_bytes(image, &self.buffers, &mut self.files)
                .and_then(|bytes| decode_texture(name.clone(), &bytes))
            {
                Ok(texture) => Some(self.builder.add_texture(texture)),
                Err(why) => {
                    self.warn(format!("{name}: {why}; using a neutral texture"));
                    None
                }
            }
        };
        self.images.insert(image.index(), decoded);
        decoded
    }

    /// An image file that cannot be read (missing, or refused by the file-access policy)
    /// is worth one clear warning, whether or not a texture uses it.
    pub(super) fn warn_about_unreadable_images(&mut self, document: &gltf::Document) {
        for image in document.images() {
            if let gltf::image::Source::Uri { uri, .. } = image.source()
                && !is_data_uri(uri)
                && let Err(why) = self.files.resolve(uri)
            {
                self.missing_images.insert(image.index());
                self.warn(format!(
                    "image {}: {why}; using a neutral texture",
                    image.index()
                ));
            }
        }
    }
}
