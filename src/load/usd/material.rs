//! UsdPreviewSurface materials and their UsdUVTexture inputs, as scene materials.

use std::path::Path;

use glam::{Affine2, Vec2, Vec3};
use openusd::sdf;

use super::UsdLoader;
use super::mtlx_surface;
use super::resolver::{UDIM_TOKEN, package_file, read_asset};
use super::value::{as_f64, as_token, as_vec3};
use crate::load::images::{decode_environment, decode_texture};
use crate::scene::{
    AlphaMode, ChannelRef, ColorSpace, EnvironmentMap, Material, MaterialTextures, Pbr, Texture,
    TextureRef, UDIM_FIRST, UDIM_LAST, Wrap, f0_of_ior,
};

impl UsdLoader {
    /// The one-sided variant of material `index`, made once. UsdGeom's `doubleSided` (false
    /// by default; Blender writes true) belongs to the mesh, gridtrace's to the material:
    /// one-sided means what it does for glTF (a black back face), except for glass, whose
    /// back faces are the inside of its volume.
    pub(super) fn one_sided(&mut self, index: usize) -> usize {
        if let Some(&variant) = self.one_sided.get(&index) {
            return variant;
        }
        let mut material = self.builder.material_mut(index).clone();
        let variant = if material.pbr.transmits() {
            index
        } else {
            material.double_sided = false;
            material.name = format!("{} (one-sided)", material.name);
            self.builder.add_material(material)
        };
        self.one_sided.insert(index, variant);
        variant
    }

    /// The material bound to `prim` ([`UsdLoader::compute_bound_material`]), converted once
    /// per material; `None` when nothing is bound.
    pub(super) fn bound_material(&mut self, prim: &sdf::Path) -> Option<usize> {
        let target = self.compute_bound_material(prim)?;
        let key = target.as_str().to_string();
        if let Some(&m) = self.materials.get(&key) {
            return Some(m);
        }
        let material = self.convert_material(&target);
        let index = self.builder.add_material(material);
        self.materials.insert(key, index);
        Some(index)
    }

    pub(super) fn default_material(&mut self) -> usize {
        if let Some(m) = self.default_material {
            return m;
        }
        let m = self.builder.add_material(Material::default_grey("default"));
        self.default_material = Some(m);
        m
    }

    /// A material from its MaterialX surface (`outputs:mtlx:surface`) when that is a model
    /// gridtrace reads, the richer description where a file has both (Blender's preview
    /// surface has no transmission, its OpenPBR surface does); else from its surface
    /// shader, a `UsdPreviewSurface` mapped as glTF's materials are.
    pub(super) fn convert_material(&mut self, material: &sdf::Path) -> Material {
        let name = material.as_str().to_string();
        if let Some(shader) = self.connected_prim(material, "outputs:mtlx:surface")
            && self
                .get_token(&shader, "info:id")
                .is_some_and(|id| mtlx_surface::is_read(&id))
        {
            return self.convert_mtlx_surface(&shader, name);
        }
        let surface = self.compute_surface_source(material);
        let Some(shader) = surface else {
            self.warn(format!(
                "{name}: material has no surface shader; using grey plastic"
            ));
            return Material::default_grey(name);
        };
        let id = self.get_token(&shader, "info:id").unwrap_or_default();
        if id != "UsdPreviewSurface" && id != "ND_UsdPreviewSurface_surfaceshader" {
            self.warn(format!(
                "{name}: surface shader '{id}' is not a model gridtrace reads (UsdPreviewSurface, MaterialX open_pbr_surface, standard_surface, gltf_pbr); using grey plastic"
            ));
            return Material::default_grey(name);
        }
        self.convert_preview_surface(&shader, name)
    }

    /// A `UsdPreviewSurface` (or MaterialX's node of it), mapped as glTF's materials are.
    fn convert_preview_surface(&mut self, shader: &sdf::Path, name: String) -> Material {
        let mut textures = MaterialTextures {
            normal_scale: 1.0,
            ..MaterialTextures::default()
        };
        // A connected input is a texture (its scale as the factor), or the mesh's
        // displayColor through a primvar reader; else a constant.
        let reads_display_colour = self.reads_display_colour(shader, "inputs:diffuseColor");
        let diffuse = if reads_display_colour {
            Vec3::ONE
        } else {
            match self.texture_input(shader, "inputs:diffuseColor", ColorSpace::Srgb, &name) {
                Some((r, scale)) => {
                    textures.base_colour = Some(r);
                    scale
                }
                None => self.constant_colour(shader, "inputs:diffuseColor", Vec3::splat(0.18)),
            }
        };
        let emission =
            match self.texture_input(shader, "inputs:emissiveColor", ColorSpace::Srgb, &name) {
                Some((r, scale)) => {
                    textures.emissive = Some(r);
                    scale
                }
                None => self.constant_colour(shader, "inputs:emissiveColor", Vec3::ZERO),
            };
        if let Some((r, _)) = self.texture_input(shader, "inputs:normal", ColorSpace::Linear, &name)
        {
            textures.normal = Some(r);
        }
        let mut alpha_mode = AlphaMode::Opaque;
        let mut opacity = self.input_f32(shader, "inputs:opacity").unwrap_or(1.0);
        if let Some((r, _)) =
            self.texture_input(shader, "inputs:opacity", ColorSpace::Linear, &name)
        {
            // Opacity from a texture's alpha (Blender's wiring) cuts out at the threshold,
            // or blends without one. The base-colour texture carries that alpha here.
            if textures.base_colour.is_none_or(|b| b.texture == r.texture) {
                textures.base_colour.get_or_insert(r);
                let threshold = self
                    .input_f32(shader, "inputs:opacityThreshold")
                    .unwrap_or(0.0);
                alpha_mode = if threshold > 0.0 {
                    AlphaMode::Mask { cutoff: threshold }
                } else {
                    AlphaMode::Blend
                };
            } else {
                self.warn(format!(
                    "{name}: opacity from a texture other than the diffuse one is not supported"
                ));
            }
            opacity = 1.0;
        }
        let ior = self.constant_scalar(shader, "inputs:ior", 1.5, &name);
        let (metallic, metallic_texture) = self.scalar_input(shader, "inputs:metallic", 0.0, &name);
        let (roughness, roughness_texture) =
            self.scalar_input(shader, "inputs:roughness", 0.5, &name);
        let (clearcoat, clearcoat_texture) =
            self.scalar_input(shader, "inputs:clearcoat", 0.0, &name);
        let (clearcoat_roughness, clearcoat_roughness_texture) =
            self.scalar_input(shader, "inputs:clearcoatRoughness", 0.01, &name);
        textures.metallic = metallic_texture;
        textures.roughness = roughness_texture;
        textures.clearcoat = clearcoat_texture;
        textures.clearcoat_roughness = clearcoat_roughness_texture;
        let mut pbr = Pbr {
            base_colour: diffuse,
            metallic,
            roughness,
            ior,
            clearcoat,
            clearcoat_roughness,
            // UsdPreviewSurface: below full opacity the surface refracts with `ior`.
            transmission: (1.0 - opacity).clamp(0.0, 1.0),
            ..Pbr::default()
        };
        if self.input_f32(shader, "inputs:useSpecularWorkflow") == Some(1.0) {
            // The specular workflow gives F0 directly and has no metals.
            self.warn_if_connected(shader, "inputs:specularColor", &name);
            let specular = self.constant_colour(shader, "inputs:specularColor", Vec3::ZERO);
            pbr.metallic = 0.0;
            textures.metallic = None;
            pbr.specular_colour = specular / f0_of_ior(ior).max(1e-4);
        } else if let Some(level) = self.input_f32(shader, "inputs:specular") {
            // Blender writes its "Specular IOR Level" here (not a UsdPreviewSurface input):
            // 0.5 is the plain F0 of the ior, and the level scales F0 by 2·level.
            let scale = (2.0 * level).max(0.0);
            pbr.specular = scale.min(1.0);
            pbr.specular_colour = Vec3::splat(scale.max(1.0));
        }
        Material {
            emission,
            textures,
            alpha_mode,
            vertex_colours: reads_display_colour,
            ..Material::new(name, pbr)
        }
    }

    /// True when `input` is connected to a `UsdPrimvarReader_float3` of `displayColor`:
    /// the colour is then the mesh's own per-vertex or per-face display colour (what the
    /// USD working group's assets and many converters write).
    fn reads_display_colour(&self, shader: &sdf::Path, input: &str) -> bool {
        let Some(node) = self.connected_prim(shader, input) else {
            return false;
        };
        let id = self.get_token(&node, "info:id");
        let varname = match self.input_value(&node, "inputs:varname") {
            Some(sdf::Value::Token(t)) => Some(t.as_str().to_string()),
            Some(sdf::Value::String(s)) => Some(s),
            _ => None,
        };
        id.as_deref() == Some("UsdPrimvarReader_float3")
            && varname
                .as_deref()
                .is_some_and(|v| v == "displayColor" || v == "primvars:displayColor")
    }

    /// A scalar input: its constant (or `default`), or a texture channel with the texture's
    /// `scale` for that channel as the factor.
    fn scalar_input(
        &mut self,
        shader: &sdf::Path,
        input: &str,
        default: f32,
        material: &str,
    ) -> (f32, Option<ChannelRef>) {
        if let Some(node) = self.connected_prim(shader, input)
            && self.get_token(&node, "info:id").as_deref() != Some("UsdUVTexture")
        {
            return match self.node_texture(&node, input, material) {
                Some(t) => (
                    1.0,
                    Some(ChannelRef {
                        texture: t.reference,
                        channel: t.channel,
                    }),
                ),
                None => (self.input_f32(shader, input).unwrap_or(default), None),
            };
        }
        let channel =
            self.connected_output(shader, input)
                .and_then(|output| match output.as_str() {
                    "outputs:r" => Some(0),
                    "outputs:g" => Some(1),
                    "outputs:b" => Some(2),
                    "outputs:a" => Some(3),
                    _ => None,
                });
        if let Some(channel) = channel
            && let Some((texture, _)) =
                self.texture_input(shader, input, ColorSpace::Linear, material)
        {
            let node = self.connected_prim(shader, input);
            let factor = match node.and_then(|n| self.input_value(&n, "inputs:scale")) {
                Some(sdf::Value::Vec4f(v)) => [v.x, v.y, v.z, v.w][channel],
                _ => 1.0,
            };
            return (factor, Some(ChannelRef { texture, channel }));
        }
        (self.constant_scalar(shader, input, default, material), None)
    }

    pub(super) fn constant_colour(
        &mut self,
        shader: &sdf::Path,
        input: &str,
        default: Vec3,
    ) -> Vec3 {
        self.input_value(shader, input)
            .as_ref()
            .and_then(as_vec3)
            .unwrap_or(default)
    }

    pub(super) fn constant_scalar(
        &mut self,
        shader: &sdf::Path,
        input: &str,
        default: f32,
        material: &str,
    ) -> f32 {
        self.warn_if_connected(shader, input, material);
        self.input_f32(shader, input).unwrap_or(default)
    }

    /// The `UsdUVTexture` feeding `input`, as a texture reference and the colour factor its
    /// `scale` gives; `None` when the input is not connected (or cannot be used, with a
    /// warning). The texture's `st` may pass through a `UsdTransform2d` and comes from a
    /// `UsdPrimvarReader_float2` of `st` (the set the loader reads).
    pub(super) fn texture_input(
        &mut self,
        shader: &sdf::Path,
        input: &str,
        space: ColorSpace,
        material: &str,
    ) -> Option<(TextureRef, Vec3)> {
        let node = self.connected_prim(shader, input)?;
        if self.get_token(&node, "info:id").as_deref() != Some("UsdUVTexture") {
            // A MaterialX document's UsdPreviewSurface reads MaterialX image nodes; any
            // other node is named in a warning there.
            let texture = self.node_texture(&node, input, material)?;
            return Some((texture.reference, Vec3::ONE));
        }
        let asset = match self.input_value(&node, "inputs:file") {
            Some(sdf::Value::AssetPath(a)) => a,
            _ => {
                self.warn(format!(
                    "{material}: {input}'s texture has no file; ignored"
                ));
                return None;
            }
        };
        let file = asset.as_str().to_string();
        let texture = self.texture_file(&asset, material)?;
        if matches!(space, ColorSpace::Srgb)
            && self
                .input_token(&node, "inputs:sourceColorSpace")
                .as_deref()
                == Some("raw")
        {
            self.warn(format!(
                "{material}: {input} reads '{file}' as raw data; treated as sRGB colour"
            ));
        }
        let scale = match self.input_value(&node, "inputs:scale") {
            Some(sdf::Value::Vec4f(v)) => Vec3::new(v.x, v.y, v.z),
            _ => Vec3::ONE,
        };
        let wrap = |mode: Option<String>| match mode.as_deref() {
            Some("clamp") => Wrap::ClampToEdge,
            Some("mirror") => Wrap::MirroredRepeat,
            _ => Wrap::Repeat,
        };
        let mut reference = TextureRef::new(texture);
        reference.wrap_u = wrap(self.input_token(&node, "inputs:wrapS"));
        reference.wrap_v = wrap(self.input_token(&node, "inputs:wrapT"));
        // USD's st has v up the image, ours down: uv → st → UsdTransform2d → uv.
        let flip = Affine2::from_cols(Vec2::X, Vec2::NEG_Y, Vec2::Y);
        let st = self.connected_prim(&node, "inputs:st");
        if let Some(st) = st
            && self.get_token(&st, "info:id").as_deref() == Some("UsdTransform2d")
        {
            let scale = match self.input_value(&st, "inputs:scale") {
                Some(sdf::Value::Vec2f(v)) => Vec2::new(v.x, v.y),
                _ => Vec2::ONE,
            };
            let translation = match self.input_value(&st, "inputs:translation") {
                Some(sdf::Value::Vec2f(v)) => Vec2::new(v.x, v.y),
                _ => Vec2::ZERO,
            };
            let rotation = self
                .input_f32(&st, "inputs:rotation")
                .unwrap_or(0.0)
                .to_radians();
            let transform = Affine2::from_scale_angle_translation(scale, rotation, translation);
            reference.transform = flip * transform * flip;
        }
        let factor = if matches!(space, ColorSpace::Srgb) {
            scale
        } else {
            Vec3::ONE
        };
        Some((reference, factor))
    }

    /// The scene texture of the image at `asset`, decoded once per resolved file.
    pub(super) fn texture_file(&mut self, asset: &sdf::AssetPath, material: &str) -> Option<usize> {
        // The file, not its spelling: `./t.png` and `sub/../t.png` decode once.
        let resolved = asset.resolved_path().unwrap_or(asset.as_str());
        let key = std::fs::canonicalize(resolved)
            .map_or_else(|_| resolved.to_string(), |p| p.display().to_string());
        if let Some(&known) = self.textures.get(&key) {
            return known;
        }
        let file = asset.as_str().to_string();
        let read = if resolved.contains(UDIM_TOKEN) {
            self.udim_tiles(resolved, &file)
        } else {
            self.read_asset(asset).and_then(|bytes| {
                decode_texture(file.clone(), &bytes).map_err(|e| format!("'{file}' {e}"))
            })
        };
        let decoded = match read {
            Ok(texture) => Some(self.builder.add_texture(texture)),
            Err(why) => {
                self.warn(format!(
                    "{material}: texture {why}; using a neutral texture"
                ));
                None
            }
        };
        self.textures.insert(key, decoded);
        decoded
    }

    /// The tiles of the UDIM set `pattern` (resolved, `<UDIM>` in place of the tile number)
    /// as one texture: every file beside it whose name has a tile number (1001–2000)
    /// there, each read through the file-access policy. `authored` names it in messages.
    fn udim_tiles(&mut self, pattern: &str, authored: &str) -> Result<Texture, String> {
        let (folder, name) = pattern.rsplit_once('/').unwrap_or((".", pattern));
        let (before, after) = name.split_once(UDIM_TOKEN).unwrap_or((name, ""));
        if !Path::new(folder).is_absolute() {
            return Err(format!(
                "'{authored}' does not resolve from the layer that names it"
            ));
        }
        if folder.contains('[') || folder.contains(UDIM_TOKEN) {
            return Err(format!(
                "'{authored}': UDIM tiles inside a package, or a folder per tile, are not read"
            ));
        }
        let entries = std::fs::read_dir(folder)
            .map_err(|e| format!("'{authored}': its folder cannot be listed ({e})"))?;
        let mut numbers: Vec<u32> = entries
            .filter_map(|e| e.ok()?.file_name().into_string().ok())
            .filter_map(|file| {
                let digits = file.strip_prefix(before)?.strip_suffix(after)?;
                let number: u32 = digits.parse().ok()?;
                (digits.len() == 4 && (UDIM_FIRST..=UDIM_LAST).contains(&number)).then_some(number)
            })
            .collect();
        numbers.sort_unstable();
        if numbers.is_empty() {
            return Err(format!(
                "'{authored}': no UDIM tile (1001, 1002, …) is beside it"
            ));
        }
        let mut tiles = Vec::with_capacity(numbers.len());
        for number in numbers {
            let path = format!("{folder}/{before}{number}{after}");
            let file = self
                .roots
                .resolve(Path::new("/"), &path)
                .map_err(|e| format!("'{authored}' tile {number}: {e}"))?;
            self.texture_paths.push(file);
            let bytes =
                read_asset(&path).map_err(|e| format!("'{authored}' tile {number}: {e}"))?;
            let tile = decode_texture(format!("{authored} tile {number}"), &bytes)
                .map_err(|e| format!("'{authored}' tile {number} {e}"))?;
            tiles.push((number, tile));
        }
        let (width, height) = (tiles[0].1.width, tiles[0].1.height);
        Ok(Texture {
            name: authored.to_string(),
            width,
            height,
            texels: Vec::new(),
            tiles,
        })
    }

    /// The environment map in the image at `asset`, or `None` with a warning naming `prim`.
    pub(super) fn environment_file(
        &mut self,
        asset: &sdf::AssetPath,
        prim: &str,
    ) -> Option<EnvironmentMap> {
        let file = asset.as_str().to_string();
        let map = self.read_asset(asset).and_then(|bytes| {
            decode_environment(file.clone(), &bytes).map_err(|e| format!("'{file}' {e}"))
        });
        match map {
            Ok(map) => Some(map),
            Err(why) => {
                self.warn(format!(
                    "{prim}: dome texture {why}; the dome light is skipped"
                ));
                None
            }
        }
    }

    /// The bytes of an asset the stage resolved against the layer that authored it (as
    /// `SdfComputeAssetPathRelativeToLayer` anchors), from a file or from inside a `.usdz`,
    /// through the file-access policy. The error names the authored path.
    fn read_asset(&mut self, asset: &sdf::AssetPath) -> Result<Vec<u8>, String> {
        let authored = asset.as_str();
        let Some(resolved) = asset.resolved_path().filter(|r| !r.is_empty()) else {
            return Err(format!(
                "'{authored}' does not resolve from the layer that names it (missing, or outside the scene's folders)"
            ));
        };
        let outer = package_file(resolved);
        let file =
            self.roots
                .resolve(Path::new("/"), outer)
                .map_err(|e| match outer == resolved {
                    true => e.naming(authored).to_string(),
                    false => format!("'{authored}': {e}"),
                })?;
        self.texture_paths.push(file);
        read_asset(resolved).map_err(|e| format!("'{authored}' ({resolved}): {e}"))
    }

    fn input_f32(&self, prim: &sdf::Path, input: &str) -> Option<f32> {
        self.input_value(prim, input)
            .as_ref()
            .and_then(as_f64)
            .map(|v| v as f32)
    }

    fn input_token(&self, prim: &sdf::Path, input: &str) -> Option<String> {
        self.input_value(prim, input).as_ref().and_then(as_token)
    }

    /// Networks feeding a scalar input are not read: say so.
    pub(super) fn warn_if_connected(&mut self, shader: &sdf::Path, input: &str, material: &str) {
        if self.connected_prim(shader, input).is_some() {
            self.warn(format!(
                "{material}: {input} is connected to a shader network, which is not read for this input; using its constant value"
            ));
        }
    }
}
