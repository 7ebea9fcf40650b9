//! MaterialX surface shaders as scene materials: OpenPBR (`open_pbr_surface`), Autodesk
//! Standard Surface (`standard_surface`) and glTF PBR (`gltf_pbr`), read from the networks
//! Blender's USD export writes beside its preview surface and from the MaterialX documents
//! a stage references ([`super::mtlx_layer`]). Each model's inputs map onto the one
//! material description; their defaults are the models' own (OpenPBR Surface
//! specification v1.1, "Parameter reference"; Standard Surface specification v1.0.1;
//! MaterialX `gltf_pbr` node definition). Textures come from `image` and `tiledimage`
//! nodes, through `convert`, `dot` and `extract` nodes; any other node feeding an input
//! read here is named in one warning and the input keeps its default.

use glam::{Affine2, Vec2, Vec3};
use openusd::sdf;

use super::UsdLoader;
use super::network::Source;
use super::value::{as_f64, as_vec3};
use crate::scene::{
    AlphaMode, ChannelRef, Material, MaterialTextures, Pbr, SheenModel, TextureRef, Wrap,
};

/// Where one shading model keeps each quantity the material description has, with the
/// model's default for it.
struct Model {
    base_colour: (&'static str, Vec3),
    base_weight: Option<(&'static str, f32)>,
    metallic: (&'static str, f32),
    roughness: (&'static str, f32),
    ior: (&'static str, f32),
    specular: (&'static str, f32),
    specular_colour: (&'static str, Vec3),
    transmission: (&'static str, f32),
    transmission_colour: Option<&'static str>,
    coat: (&'static str, f32),
    coat_roughness: (&'static str, f32),
    /// The sheen's weight; glTF PBR has none (its colour is its weight).
    sheen: Option<&'static str>,
    sheen_colour: (&'static str, Vec3),
    sheen_roughness: (&'static str, f32),
    /// The sheen the model's specification describes.
    sheen_model: SheenModel,
    emission_colour: (&'static str, Vec3),
    emission: (&'static str, f32),
    opacity: &'static str,
    normal: &'static str,
    /// Weights of lobes gridtrace does not render, named in a warning when set.
    unread: &'static [&'static str],
}

const OPEN_PBR: Model = Model {
    base_colour: ("base_color", Vec3::splat(0.8)),
    base_weight: Some(("base_weight", 1.0)),
    metallic: ("base_metalness", 0.0),
    roughness: ("specular_roughness", 0.3),
    ior: ("specular_ior", 1.5),
    specular: ("specular_weight", 1.0),
    specular_colour: ("specular_color", Vec3::ONE),
    transmission: ("transmission_weight", 0.0),
    transmission_colour: Some("transmission_color"),
    coat: ("coat_weight", 0.0),
    coat_roughness: ("coat_roughness", 0.0),
    sheen: Some("fuzz_weight"),
    sheen_colour: ("fuzz_color", Vec3::ONE),
    sheen_roughness: ("fuzz_roughness", 0.5),
    // OpenPBR 1.1's fuzz is Zeltner et al.'s fibre layer, over the coat.
    sheen_model: SheenModel::Microfiber,
    emission_colour: ("emission_color", Vec3::ONE),
    // Blender writes its Emission Strength here, radiance × colour as in Cycles.
    emission: ("emission_luminance", 0.0),
    opacity: "geometry_opacity",
    normal: "geometry_normal",
    unread: &["subsurface_weight", "thin_film_weight"],
};

const STANDARD_SURFACE: Model = Model {
    base_colour: ("base_color", Vec3::ONE),
    base_weight: Some(("base", 0.8)),
    metallic: ("metalness", 0.0),
    roughness: ("specular_roughness", 0.2),
    ior: ("specular_IOR", 1.5),
    specular: ("specular", 1.0),
    specular_colour: ("specular_color", Vec3::ONE),
    transmission: ("transmission", 0.0),
    transmission_colour: Some("transmission_color"),
    coat: ("coat", 0.0),
    coat_roughness: ("coat_roughness", 0.1),
    sheen: Some("sheen"),
    sheen_colour: ("sheen_color", Vec3::ONE),
    sheen_roughness: ("sheen_roughness", 0.3),
    // Standard Surface 1.0.1's sheen is Estevez & Kulla's.
    sheen_model: SheenModel::Charlie,
    emission_colour: ("emission_color", Vec3::ONE),
    emission: ("emission", 0.0),
    opacity: "opacity",
    normal: "normal",
    unread: &["subsurface", "thin_film_thickness"],
};

const GLTF_PBR: Model = Model {
    base_colour: ("base_color", Vec3::ONE),
    base_weight: None,
    metallic: ("metallic", 1.0),
    roughness: ("roughness", 1.0),
    ior: ("ior", 1.5),
    specular: ("specular", 1.0),
    specular_colour: ("specular_color", Vec3::ONE),
    transmission: ("transmission", 0.0),
    transmission_colour: None,
    coat: ("clearcoat", 0.0),
    coat_roughness: ("clearcoat_roughness", 0.0),
    sheen: None,
    sheen_colour: ("sheen_color", Vec3::ZERO),
    sheen_roughness: ("sheen_roughness", 0.0),
    sheen_model: SheenModel::Charlie,
    emission_colour: ("emissive", Vec3::ZERO),
    emission: ("emissive_strength", 1.0),
    opacity: "alpha",
    normal: "normal",
    unread: &["iridescence", "thickness"],
};

/// The model a MaterialX surface shader's node definition names, if gridtrace reads it.
fn model_of(id: &str) -> Option<&'static Model> {
    match id {
        "ND_open_pbr_surface_surfaceshader" => Some(&OPEN_PBR),
        "ND_standard_surface_surfaceshader" | "ND_standard_surface_surfaceshader_100" => {
            Some(&STANDARD_SURFACE)
        }
        "ND_gltf_pbr_surfaceshader" => Some(&GLTF_PBR),
        _ => None,
    }
}

/// True when `id` names a MaterialX surface shader gridtrace reads.
pub(super) fn is_read(id: &str) -> bool {
    model_of(id).is_some()
}

/// An image node at the end of a chain, and the channel a scalar input takes from it.
pub(super) struct NodeTexture {
    pub reference: TextureRef,
    pub channel: usize,
}

impl UsdLoader {
    /// The material a MaterialX surface shader describes. `shader`'s `info:id` must be one
    /// [`is_read`] accepts.
    pub(super) fn convert_mtlx_surface(&mut self, shader: &sdf::Path, name: String) -> Material {
        let id = self.get_token(shader, "info:id").unwrap_or_default();
        let model = model_of(&id).unwrap_or(&OPEN_PBR);
        let mut textures = MaterialTextures {
            normal_scale: 1.0,
            ..MaterialTextures::default()
        };
        let transmission = self.mtlx_scalar(shader, model.transmission, &name);
        // One colour tints both the diffuse base and the transmission here: a fully
        // transmissive surface takes its transmission colour, anything else its base colour.
        let (base_colour, base_texture) = match model.transmission_colour {
            Some(input) if transmission.0 >= 1.0 => {
                self.mtlx_colour(shader, (input, Vec3::ONE), &name)
            }
            _ => {
                let (colour, texture) = self.mtlx_colour(shader, model.base_colour, &name);
                let weight = model
                    .base_weight
                    .map_or(1.0, |w| self.mtlx_scalar(shader, w, &name).0);
                (colour * weight, texture)
            }
        };
        textures.base_colour = base_texture;
        let (metallic, metallic_texture) = self.mtlx_scalar(shader, model.metallic, &name);
        let (roughness, roughness_texture) = self.mtlx_scalar(shader, model.roughness, &name);
        let (clearcoat, clearcoat_texture) = self.mtlx_scalar(shader, model.coat, &name);
        let (clearcoat_roughness, coat_roughness_texture) =
            self.mtlx_scalar(shader, model.coat_roughness, &name);
        let (specular_weight, _) = self.mtlx_scalar(shader, model.specular, &name);
        let (specular_colour, specular_texture) =
            self.mtlx_colour(shader, model.specular_colour, &name);
        let (sheen_colour, sheen_texture) = self.mtlx_colour(shader, model.sheen_colour, &name);
        let sheen_weight = model
            .sheen
            .map_or(1.0, |input| self.mtlx_scalar(shader, (input, 0.0), &name).0);
        let (mut sheen_roughness, sheen_roughness_texture) =
            self.mtlx_scalar(shader, model.sheen_roughness, &name);
        if sheen_weight <= 0.0 {
            sheen_roughness = 0.0;
        }
        let (emission_colour, emissive_texture) =
            self.mtlx_colour(shader, model.emission_colour, &name);
        let emission_strength = self.mtlx_scalar(shader, model.emission, &name).0;
        textures.metallic = metallic_texture;
        textures.roughness = roughness_texture;
        textures.transmission = transmission.1;
        textures.clearcoat = clearcoat_texture;
        textures.clearcoat_roughness = coat_roughness_texture;
        textures.specular_colour = specular_texture;
        textures.sheen_colour = sheen_texture.filter(|_| sheen_weight > 0.0);
        textures.sheen_roughness = sheen_roughness_texture;
        textures.emissive = emissive_texture.filter(|_| emission_strength > 0.0);
        textures.normal = self.mtlx_normal(shader, model.normal, &name, &mut textures.normal_scale);
        for input in model.unread {
            if self.mtlx_scalar(shader, (input, 0.0), &name).0 > 0.0 {
                self.warn(format!(
                    "{name}: {input} is set, which gridtrace does not render; left out"
                ));
            }
        }
        // Specular weight above 1 brightens the layer's F0, as Blender's "Specular IOR
        // Level" above 0.5 does (the same mapping as the preview surface's `specular`).
        let pbr = Pbr {
            base_colour,
            metallic,
            roughness,
            ior: self.mtlx_scalar(shader, model.ior, &name).0,
            specular: specular_weight.clamp(0.0, 1.0),
            specular_colour: specular_colour * specular_weight.max(1.0),
            transmission: transmission.0.clamp(0.0, 1.0),
            clearcoat,
            clearcoat_roughness,
            sheen_colour: sheen_colour * sheen_weight,
            sheen_roughness,
            sheen_model: if self.from_blender {
                SheenModel::Microfiber
            } else {
                model.sheen_model
            },
            ..Pbr::default()
        };
        let opacity = self.mtlx_opacity(shader, model.opacity, &name);
        Material {
            emission: emission_colour * emission_strength,
            textures,
            alpha: opacity,
            alpha_mode: if opacity < 1.0 {
                AlphaMode::Blend
            } else {
                AlphaMode::Opaque
            },
            ..Material::new(name, pbr)
        }
    }

    /// A colour input: its value, or white times the texture feeding it.
    fn mtlx_colour(
        &mut self,
        shader: &sdf::Path,
        (input, default): (&str, Vec3),
        material: &str,
    ) -> (Vec3, Option<TextureRef>) {
        match self.source_of(shader, &format!("inputs:{input}")) {
            Some(Source::Value(v)) => (as_vec3(&v).unwrap_or(default), None),
            Some(Source::Node { prim, .. }) => match self.node_texture(&prim, input, material) {
                Some(t) => (Vec3::ONE, Some(t.reference)),
                None => (default, None),
            },
            None => (default, None),
        }
    }

    /// A scalar input: its value, or 1 times the texture channel feeding it.
    fn mtlx_scalar(
        &mut self,
        shader: &sdf::Path,
        (input, default): (&str, f32),
        material: &str,
    ) -> (f32, Option<ChannelRef>) {
        match self.source_of(shader, &format!("inputs:{input}")) {
            Some(Source::Value(v)) => (
                as_f64(&v)
                    .map(|x| x as f32)
                    .filter(|x| x.is_finite())
                    .unwrap_or(default),
                None,
            ),
            Some(Source::Node { prim, .. }) => match self.node_texture(&prim, input, material) {
                Some(t) => (
                    1.0,
                    Some(ChannelRef {
                        texture: t.reference,
                        channel: t.channel,
                    }),
                ),
                None => (default, None),
            },
            None => (default, None),
        }
    }

    /// Coverage: a scalar (OpenPBR, glTF PBR) or the mean of a colour (Standard Surface).
    /// Textured coverage is not read.
    fn mtlx_opacity(&mut self, shader: &sdf::Path, input: &str, material: &str) -> f32 {
        match self.source_of(shader, &format!("inputs:{input}")) {
            Some(Source::Value(v)) => as_f64(&v)
                .map(|x| x as f32)
                .or_else(|| as_vec3(&v).map(|c| c.element_sum() / 3.0))
                .filter(|x| x.is_finite())
                .map_or(1.0, |x| x.clamp(0.0, 1.0)),
            Some(Source::Node { prim, .. }) => {
                let id = self.get_token(&prim, "info:id").unwrap_or_default();
                self.warn_once(format!(
                    "{material}: {input} comes from a texture ('{id}'), which is not read; the surface is opaque"
                ));
                1.0
            }
            None => 1.0,
        }
    }

    /// The normal map behind a `normalmap` node feeding `input`, and its scale. The
    /// geometry's own normal (`normal` node) is what the input means when unconnected.
    fn mtlx_normal(
        &mut self,
        shader: &sdf::Path,
        input: &str,
        material: &str,
        scale: &mut f32,
    ) -> Option<TextureRef> {
        let Source::Node { prim, .. } = self.source_of(shader, &format!("inputs:{input}"))? else {
            return None;
        };
        let id = self.get_token(&prim, "info:id").unwrap_or_default();
        if id.starts_with("ND_normal_") || id.starts_with("ND_normalize_") {
            return None;
        }
        if !id.starts_with("ND_normalmap") {
            self.warn_once(format!(
                "{material}: {input} is fed by a '{id}' node, which gridtrace does not read; using the surface's own normal"
            ));
            return None;
        }
        if let Some(s) = self
            .input_value(&prim, "inputs:scale")
            .as_ref()
            .and_then(as_f64)
        {
            *scale = s as f32;
        }
        let image = self.connected_prim(&prim, "inputs:in")?;
        self.node_texture(&image, input, material)
            .map(|t| t.reference)
    }

    /// The texture at the end of the chain of nodes from `node`: an `image` or `tiledimage`
    /// reached through `convert`, `dot` and `extract` (which picks the channel). Any other
    /// node is named in a warning.
    pub(super) fn node_texture(
        &mut self,
        node: &sdf::Path,
        input: &str,
        material: &str,
    ) -> Option<NodeTexture> {
        let mut node = node.clone();
        let mut channel = 0;
        for _ in 0..16 {
            let id = self.get_token(&node, "info:id").unwrap_or_default();
            if id.starts_with("ND_image_") || id.starts_with("ND_tiledimage_") {
                let reference = self.image_node(&node, &id, material)?;
                return Some(NodeTexture { reference, channel });
            }
            if id.starts_with("ND_extract_") {
                channel = self
                    .input_value(&node, "inputs:index")
                    .as_ref()
                    .and_then(as_f64)
                    .map_or(0, |i| i.clamp(0.0, 3.0) as usize);
            } else if !(id.starts_with("ND_convert_") || id.starts_with("ND_dot_")) {
                self.warn_once(format!(
                    "{material}: {input} is fed by a '{id}' node, which gridtrace does not read; using the input's default"
                ));
                return None;
            }
            node = self.connected_prim(&node, "inputs:in")?;
        }
        None
    }

    /// The texture of an `image` or `tiledimage` node: its file, address modes and, for a
    /// tiled image, its `uvtiling` and `uvoffset`. MaterialX texture coordinates have v up
    /// the image, as USD's st do.
    fn image_node(&mut self, node: &sdf::Path, id: &str, material: &str) -> Option<TextureRef> {
        let Some(sdf::Value::AssetPath(asset)) = self.input_value(node, "inputs:file") else {
            self.warn_once(format!("{material}: an image node has no file; ignored"));
            return None;
        };
        let texture = self.texture_file(&asset, material)?;
        let wrap = |mode: Option<String>| match mode.as_deref() {
            Some("clamp") | Some("constant") => Wrap::ClampToEdge,
            Some("mirror") => Wrap::MirroredRepeat,
            _ => Wrap::Repeat,
        };
        let token = |loader: &Self, name: &str| match loader.input_value(node, name) {
            Some(sdf::Value::String(s)) => Some(s),
            Some(sdf::Value::Token(t)) => Some(t.as_str().to_string()),
            _ => None,
        };
        let mut reference = TextureRef::new(texture);
        reference.wrap_u = wrap(token(self, "inputs:uaddressmode"));
        reference.wrap_v = wrap(token(self, "inputs:vaddressmode"));
        let vec2 = |loader: &Self, name: &str, default: Vec2| match loader.input_value(node, name) {
            Some(sdf::Value::Vec2f(v)) => Vec2::new(v.x, v.y),
            _ => default,
        };
        let flip = Affine2::from_cols(Vec2::X, Vec2::NEG_Y, Vec2::Y);
        if id.starts_with("ND_tiledimage_") {
            // st' = (st · uvtiling − uvoffset) / realworldimagesize · realworldtilesize,
            // always repeating (the node definition's graph in MaterialX's stdlib).
            let tiling = vec2(self, "inputs:uvtiling", Vec2::ONE);
            let offset = vec2(self, "inputs:uvoffset", Vec2::ZERO);
            let image = vec2(self, "inputs:realworldimagesize", Vec2::ONE);
            let tile = vec2(self, "inputs:realworldtilesize", Vec2::ONE);
            let size = if image.min_element() > 0.0 {
                tile / image
            } else {
                Vec2::ONE
            };
            let transform =
                Affine2::from_scale_angle_translation(tiling * size, 0.0, -offset * size);
            reference.transform = flip * transform * flip;
            (reference.wrap_u, reference.wrap_v) = (Wrap::Repeat, Wrap::Repeat);
        }
        if let Some(coords) = self.connected_prim(node, "inputs:texcoord") {
            let coords_id = self.get_token(&coords, "info:id").unwrap_or_default();
            if !coords_id.starts_with("ND_texcoord_") && !coords_id.starts_with("ND_geompropvalue_")
            {
                self.warn_once(format!(
                    "{material}: texture coordinates from a '{coords_id}' node are not read; using the mesh's own"
                ));
            }
        }
        Some(reference)
    }
}
