//! glTF materials and their textures, as scene materials (docs/manual/materials.md's table).

use glam::{Affine2, Vec2, Vec3, Vec4};

use super::files::{image_bytes, is_data_uri};
use super::{GltfLoader, MAX_UV_SETS, spec_gloss, texture_transform};
use crate::limits::check_memory;
use crate::load::images::decode_texture;
use crate::scene::{
    AlphaMode, Anisotropy, AnisotropyModel, ChannelRef, Filter, Material, MaterialTextures, Pbr,
    SheenModel, TextureRef, Wrap,
};

impl GltfLoader {
    /// A glTF material as the one PBR description: `pbrMetallicRoughness`, emission with
    /// `KHR_materials_emissive_strength`, and the `KHR_materials_{ior, specular,
    /// transmission, clearcoat, sheen, volume}` extensions (docs/manual/materials.md's table).
    pub(super) fn convert_material(
        &mut self,
        document: &gltf::Document,
        material: &gltf::Material,
    ) -> Material {
        let name = material.name().map_or_else(
            || format!("material {}", material.index().unwrap_or(0)),
            String::from,
        );
        let info_ref = |loader: &mut GltfLoader, info: gltf::texture::Info| {
            loader.texture_ref(
                document,
                &info.texture(),
                info.tex_coord(),
                info.texture_transform(),
                &name,
            )
        };
        let pbr_gltf = material.pbr_metallic_roughness();
        let [r, g, b, mut alpha] = pbr_gltf.base_color_factor();
        let mut pbr = Pbr {
            base_colour: Vec3::new(r, g, b),
            metallic: pbr_gltf.metallic_factor(),
            roughness: pbr_gltf.roughness_factor(),
            ior: material.ior().unwrap_or(1.5),
            transmission: material
                .transmission()
                .map_or(0.0, |t| t.transmission_factor()),
            ..Pbr::default()
        };
        let emission =
            Vec3::from(material.emissive_factor()) * material.emissive_strength().unwrap_or(1.0);
        let metallic_roughness = pbr_gltf
            .metallic_roughness_texture()
            .and_then(|info| info_ref(self, info));
        let mut textures = MaterialTextures {
            base_colour: pbr_gltf
                .base_color_texture()
                .and_then(|info| info_ref(self, info)),
            emissive: material
                .emissive_texture()
                .and_then(|info| info_ref(self, info)),
            metallic: metallic_roughness.map(|texture| ChannelRef {
                texture,
                channel: 2,
            }),
            roughness: metallic_roughness.map(|texture| ChannelRef {
                texture,
                channel: 1,
            }),
            transmission: material
                .transmission()
                .and_then(|t| t.transmission_texture())
                .and_then(|info| info_ref(self, info))
                .map(|texture| ChannelRef {
                    texture,
                    channel: 0,
                }),
            normal: material.normal_texture().and_then(|info| {
                let mut r =
                    self.texture_ref(document, &info.texture(), info.tex_coord(), None, &name)?;
                // The gltf crate exposes KHR_texture_transform on normal textures only as JSON.
                if let Some(t) = info.extension_value("KHR_texture_transform") {
                    json_texture_transform(t, &mut r);
                }
                Some(r)
            }),
            normal_scale: material.normal_texture().map_or(1.0, |n| n.scale()),
            ..MaterialTextures::default()
        };
        if let Some(specular) = material.extension_value("KHR_materials_specular") {
            pbr.specular = json_f32(&specular["specularFactor"], 1.0).max(0.0);
            pbr.specular_colour = json_vec3(&specular["specularColorFactor"], Vec3::ONE);
            textures.specular = self
                .json_texture(document, &specular["specularTexture"], &name)
                .map(|texture| ChannelRef {
                    texture,
                    channel: 3,
                });
            textures.specular_colour =
                self.json_texture(document, &specular["specularColorTexture"], &name);
        }
        if let Some(coat) = material.extension_value("KHR_materials_clearcoat") {
            pbr.clearcoat = json_f32(&coat["clearcoatFactor"], 0.0);
            pbr.clearcoat_roughness = json_f32(&coat["clearcoatRoughnessFactor"], 0.0);
            textures.clearcoat = self
                .json_texture(document, &coat["clearcoatTexture"], &name)
                .map(|texture| ChannelRef {
                    texture,
                    channel: 0,
                });
            textures.clearcoat_roughness = self
                .json_texture(document, &coat["clearcoatRoughnessTexture"], &name)
                .map(|texture| ChannelRef {
                    texture,
                    channel: 1,
                });
            textures.clearcoat_normal =
                self.json_texture(document, &coat["clearcoatNormalTexture"], &name);
            textures.clearcoat_normal_scale =
                json_f32(&coat["clearcoatNormalTexture"]["scale"], 1.0);
        }
        if let Some(anisotropy) = material.extension_value("KHR_materials_anisotropy") {
            pbr.anisotropy = Anisotropy {
                strength: json_f32(&anisotropy["anisotropyStrength"], 0.0).clamp(0.0, 1.0),
                rotation: json_f32(&anisotropy["anisotropyRotation"], 0.0),
                model: if self.from_blender {
                    AnisotropyModel::Cycles
                } else {
                    AnisotropyModel::Gltf
                },
            };
            textures.anisotropy =
                self.json_texture(document, &anisotropy["anisotropyTexture"], &name);
        }
        if let Some(sheen) = material.extension_value("KHR_materials_sheen") {
            pbr.sheen_colour = json_vec3(&sheen["sheenColorFactor"], Vec3::ZERO);
            pbr.sheen_roughness = json_f32(&sheen["sheenRoughnessFactor"], 0.0);
            // Blender's exporter writes the Principled BSDF's sheen, which is Cycles'.
            if self.from_blender {
                pbr.sheen_model = SheenModel::Microfiber;
            }
            textures.sheen_colour = self.json_texture(document, &sheen["sheenColorTexture"], &name);
            textures.sheen_roughness = self
                .json_texture(document, &sheen["sheenRoughnessTexture"], &name)
                .map(|texture| ChannelRef {
                    texture,
                    channel: 3,
                });
        }
        if let Some(sg) = material.extension_value(spec_gloss::EXTENSION) {
            // It replaces pbrMetallicRoughness (the extension's specification).
            let [dr, dg, db, da] = json_vec4(&sg["diffuseFactor"], [1.0; 4]);
            let factors = (
                Vec4::new(dr, dg, db, da),
                json_vec3(&sg["specularFactor"], Vec3::ONE),
                json_f32(&sg["glossinessFactor"], 1.0),
            );
            let m = spec_gloss::convert(factors.0, factors.1, factors.2);
            (pbr.base_colour, pbr.metallic, pbr.roughness, alpha) =
                (m.base_colour, m.metallic, m.roughness, m.alpha);
            let diffuse = self.json_texture(document, &sg["diffuseTexture"], &name);
            let spec_gloss_texture =
                self.json_texture(document, &sg["specularGlossinessTexture"], &name);
            textures.base_colour = diffuse;
            (textures.metallic, textures.roughness) = (None, None);
            if let Some(sg_ref) = spec_gloss_texture {
                self.bake_spec_gloss(&name, diffuse, sg_ref, factors, &mut pbr, &mut textures);
            }
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
        // A transmitting object's back faces are the inside of its volume, which rays
        // leaving it must cross: it is always two-sided (Blender writes doubleSided: false
        // with KHR_materials_volume).
        let double_sided = material.double_sided() || pbr.transmits();
        Material {
            name,
            pbr,
            emission,
            double_sided,
            textures,
            vertex_colours: false,
            alpha,
            alpha_mode,
            absorption,
            camera_visible: true,
            lamp: false,
            unlit: material.extension_value("KHR_materials_unlit").is_some(),
        }
    }

    /// A texture named by a texture-info object inside an extension's JSON (the gltf crate
    /// parses only some extensions); `None` when absent or unusable.
    fn json_texture(
        &mut self,
        document: &gltf::Document,
        info: &gltf::json::Value,
        material: &str,
    ) -> Option<TextureRef> {
        let index = info["index"].as_u64()?;
        let Some(texture) = document.textures().nth(index as usize) else {
            self.warn(format!(
                "material '{material}': texture {index} does not exist; ignored"
            ));
            return None;
        };
        let set = info["texCoord"]
            .as_u64()
            .unwrap_or(0)
            .min(u64::from(u32::MAX)) as u32;
        let mut r = self.texture_ref(document, &texture, set, None, material)?;
        if let Some(t) = info["extensions"].get("KHR_texture_transform") {
            json_texture_transform(t, &mut r);
        }
        Some(r)
    }

    /// A specular–glossiness texture (and the diffuse texture beside it) baked into base
    /// colour and metallic–roughness textures that carry the whole material, the factors
    /// included. With the diffuse texture on other coordinates the two cannot be baked
    /// together: the specular–glossiness texture is then left out, with a warning, and the
    /// factors and diffuse texture stand (a diffuse texture alone multiplies the converted
    /// base colour, exact while the conversion finds no metal, as for F0 = 0.04).
    fn bake_spec_gloss(
        &mut self,
        name: &str,
        diffuse: Option<TextureRef>,
        sg_ref: TextureRef,
        factors: (Vec4, Vec3, f32),
        pbr: &mut Pbr,
        textures: &mut MaterialTextures,
    ) {
        let same_place =
            |d: &TextureRef| d.texcoord == sg_ref.texcoord && d.transform == sg_ref.transform;
        if !diffuse.as_ref().is_none_or(same_place) {
            self.warn(format!(
                "material '{name}': its diffuse and specular-glossiness textures use different coordinates; the specular-glossiness texture is not read"
            ));
            return;
        }
        let spec_gloss_texture = self.builder.texture(sg_ref.texture);
        let diffuse_texture = diffuse.map(|d| self.builder.texture(d.texture));
        let texels = u64::from(
            diffuse_texture
                .map_or(0, |d| d.width)
                .max(spec_gloss_texture.width),
        ) * u64::from(
            diffuse_texture
                .map_or(0, |d| d.height)
                .max(spec_gloss_texture.height),
        );
        if let Err(e) = check_memory(|| format!("material '{name}'"), texels.saturating_mul(16)) {
            self.warn(format!("{e}; the specular-glossiness texture is not read"));
            return;
        }
        let (base, metal_rough) =
            spec_gloss::bake(diffuse_texture, spec_gloss_texture, factors, name);
        let base = self.builder.add_texture(base);
        let metal_rough = self.builder.add_texture(metal_rough);
        (pbr.base_colour, pbr.metallic, pbr.roughness) = (Vec3::ONE, 1.0, 1.0);
        let place = diffuse.unwrap_or(sg_ref);
        textures.base_colour = Some(TextureRef {
            texture: base,
            ..place
        });
        let channel = |channel| ChannelRef {
            texture: TextureRef {
                texture: metal_rough,
                ..place
            },
            channel,
        };
        (textures.metallic, textures.roughness) = (Some(channel(2)), Some(channel(1)));
    }

    /// A material's use of a texture: its image (decoded once), sampler, coordinate set and
    /// `KHR_texture_transform`. `None`, with a warning, when the image cannot be used; the
    /// material then shows its constant factors, as if the texture were white (or flat).
    pub(super) fn texture_ref(
        &mut self,
        document: &gltf::Document,
        texture: &gltf::Texture,
        tex_coord: u32,
        transform: Option<gltf::texture::TextureTransform>,
        material: &str,
    ) -> Option<TextureRef> {
        let image = texture_images(document, texture)
            .iter()
            .find_map(|image| self.image_texture(image))?;
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

    /// The scene texture of a glTF image, decoded on first use: once per image, and once
    /// per file however its URI is spelt (`t.png`, `./t.png`, `%74.png`).
    pub(super) fn image_texture(&mut self, image: &gltf::Image) -> Option<usize> {
        if let Some(&known) = self.images.get(&image.index()) {
            return known;
        }
        let file = match image.source() {
            gltf::image::Source::Uri { uri, .. } if !is_data_uri(uri) => {
                self.files.resolve(uri).ok()
            }
            _ => None,
        };
        if let Some(&known) = file.as_ref().and_then(|f| self.image_files.get(f)) {
            self.images.insert(image.index(), known);
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
        if let Some(file) = file {
            self.image_files.insert(file, decoded);
        }
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

/// Image extensions gridtrace decodes, in order of preference over `source` (each names an
/// image in its `source`; `source` itself is then a fallback, or absent).
const IMAGE_EXTENSIONS: [&str; 2] = ["KHR_texture_basisu", "EXT_texture_webp"];

/// The images a texture may show, best first: the image extensions' (KTX2, WebP), then
/// its own `source`, which the extensions keep as a fallback for readers without them.
fn texture_images<'a>(
    document: &'a gltf::Document,
    texture: &gltf::Texture,
) -> Vec<gltf::Image<'a>> {
    IMAGE_EXTENSIONS
        .iter()
        .filter_map(|name| texture.extension_value(name)?["source"].as_u64())
        .chain(texture.source().map(|s| s.index() as u64))
        .filter_map(|i| document.images().nth(i as usize))
        .collect()
}

/// A number in extension JSON, or `default` when absent or not finite.
fn json_f32(value: &gltf::json::Value, default: f32) -> f32 {
    value
        .as_f64()
        .map(|x| x as f32)
        .filter(|x| x.is_finite())
        .unwrap_or(default)
}

/// A three-number array in extension JSON, or `default`.
fn json_vec3(value: &gltf::json::Value, default: Vec3) -> Vec3 {
    match value.as_array().map(Vec::as_slice) {
        Some([x, y, z]) => Vec3::new(
            json_f32(x, default.x),
            json_f32(y, default.y),
            json_f32(z, default.z),
        ),
        _ => default,
    }
}

/// A four-number array in extension JSON, or `default`.
fn json_vec4(value: &gltf::json::Value, default: [f32; 4]) -> [f32; 4] {
    match value.as_array().map(Vec::as_slice) {
        Some(v @ [_, _, _, _]) => std::array::from_fn(|i| json_f32(&v[i], default[i])),
        _ => default,
    }
}

/// Applies a `KHR_texture_transform` given as JSON (offset, rotation, scale, texCoord).
fn json_texture_transform(t: &gltf::json::Value, r: &mut TextureRef) {
    let pair = |key: &str, default: f32| {
        let v = &t[key];
        Vec2::new(json_f32(&v[0], default), json_f32(&v[1], default))
    };
    let rotation = json_f32(&t["rotation"], 0.0);
    r.transform = texture_transform(pair("offset", 0.0), rotation, pair("scale", 1.0));
    if let Some(set) = t["texCoord"]
        .as_u64()
        .filter(|&s| (s as usize) < MAX_UV_SETS)
    {
        r.texcoord = set as usize;
    }
}
