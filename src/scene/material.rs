//! Materials: one physically based surface description, plus emission, alpha and textures.

use glam::Vec3;

use super::TextureRef;

/// How a surface scatters light: the glTF 2.0 metallic-roughness model with its KHR material
/// extensions (glTF 2.0 Appendix B; `KHR_materials_{ior,specular,transmission,clearcoat,sheen}`),
/// which is also what Blender's Principled BSDF and USD's `UsdPreviewSurface` describe. Loaders
/// fill it; [`crate::render::Bsdf::new`] is the one place that turns it into lobes.
///
/// Roughness is perceptual (GGX α = roughness²). Zero roughness gives exact delta lobes, so
/// the ideal models are special cases: [`Pbr::diffuse`], [`Pbr::mirror`], [`Pbr::glass`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pbr {
    /// Diffuse albedo of dielectrics, F0 of metals, transmission tint of glass.
    pub base_colour: Vec3,
    /// 0: dielectric, 1: conductor; blends linearly in between.
    pub metallic: f32,
    /// Perceptual roughness of the specular, metal and transmission lobes.
    pub roughness: f32,
    /// Index of refraction of the dielectric (1.5 by default).
    pub ior: f32,
    /// Strength of the dielectric specular layer (`KHR_materials_specular`'s
    /// `specularFactor`; 0 leaves a pure Lambertian base). Also its reflectance at grazing
    /// angles.
    pub specular: f32,
    /// Tint of the dielectric layer's F0 (`specularColorFactor`).
    pub specular_colour: Vec3,
    /// Fraction of the dielectric that transmits instead of being diffuse.
    pub transmission: f32,
    /// Weight of a clear dielectric coat (IOR 1.5) over everything.
    pub clearcoat: f32,
    /// Perceptual roughness of the coat.
    pub clearcoat_roughness: f32,
    /// Colour of the sheen layer (zero: no sheen).
    pub sheen_colour: Vec3,
    /// Roughness of the sheen.
    pub sheen_roughness: f32,
    /// Which sheen the file was authored against.
    pub sheen_model: SheenModel,
    /// Stretch of the metal and specular lobes along a direction of the surface.
    pub anisotropy: Anisotropy,
}

/// Anisotropic reflection, as `KHR_materials_anisotropy` and Blender's Principled BSDF
/// (Anisotropic, Anisotropic Rotation) describe it: the glossy lobes are wider along one
/// direction of the surface, given by the mesh's tangent frame.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Anisotropy {
    /// 0: isotropic; up to 1: fully stretched.
    pub strength: f32,
    /// The direction of the stretch: radians from the tangent towards the bitangent.
    pub rotation: f32,
    /// How the strength widens the lobes.
    pub model: AnisotropyModel,
}

/// How an anisotropy strength s turns roughness r (α = r²) into the widths along and
/// across its direction.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum AnisotropyModel {
    /// `KHR_materials_anisotropy`: α along = mix(α, 1, s²), α across = α.
    #[default]
    Gltf,
    /// Cycles' Principled BSDF (files Blender wrote, whose strength is Blender's
    /// Anisotropic): α along = α/√(1 − 0.9 s), α across = α·√(1 − 0.9 s).
    Cycles,
}

/// The two sheens files are authored against: they differ in shape (Charlie peaks at
/// grazing half vectors, the microfibre layer also scatters back) and in what a roughness
/// means, so a velvet authored for one looks wrong in the other.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum SheenModel {
    /// `KHR_materials_sheen`: the "Charlie" distribution (Estevez & Kulla 2017), α =
    /// roughness².
    #[default]
    Charlie,
    /// Cycles' Principled BSDF (files Blender wrote): Zeltner, Burley & Chiang's (2022)
    /// layer of fibres along the normal, as a linearly transformed cosine, on top of the
    /// coat.
    Microfiber,
}

impl Default for Pbr {
    /// glTF's defaults: white, metallic 1 and roughness 1 as `pbrMetallicRoughness` says,
    /// IOR 1.5 with the full specular layer, no transmission, coat or sheen.
    fn default() -> Pbr {
        Pbr {
            base_colour: Vec3::ONE,
            metallic: 1.0,
            roughness: 1.0,
            ior: 1.5,
            specular: 1.0,
            specular_colour: Vec3::ONE,
            transmission: 0.0,
            clearcoat: 0.0,
            clearcoat_roughness: 0.0,
            sheen_colour: Vec3::ZERO,
            sheen_roughness: 0.0,
            sheen_model: SheenModel::Charlie,
            anisotropy: Anisotropy::default(),
        }
    }
}

impl Pbr {
    /// A pure Lambertian reflector, f = albedo/π: no specular layer.
    pub fn diffuse(albedo: Vec3) -> Pbr {
        Pbr {
            base_colour: albedo,
            metallic: 0.0,
            specular: 0.0,
            ..Pbr::default()
        }
    }

    /// A smooth conductor with F0 = `reflectance` (Schlick's Fresnel towards white).
    pub fn mirror(reflectance: Vec3) -> Pbr {
        Pbr {
            base_colour: reflectance,
            metallic: 1.0,
            roughness: 0.0,
            ..Pbr::default()
        }
    }

    /// A smooth dielectric that reflects by Fresnel's equations and transmits the rest,
    /// tinted by `tint`.
    pub fn glass(ior: f32, tint: Vec3) -> Pbr {
        Pbr {
            base_colour: tint,
            metallic: 0.0,
            roughness: 0.0,
            ior,
            transmission: 1.0,
            ..Pbr::default()
        }
    }

    /// True when light can pass through the surface (into a volume behind it), by the
    /// constant factors alone: what loaders use to make constant glass two-sided. Textures
    /// can change the answer point by point; the renderer asks the textured BSDF
    /// ([`crate::render::Bsdf::transmits`]).
    pub fn transmits(&self) -> bool {
        self.transmission > 0.0 && self.metallic < 1.0
    }
}

/// Normal-incidence reflectance of a dielectric of index `ior` in air, ((η − 1)/(η + 1))²
/// (Fresnel's equations at θ = 0).
pub fn f0_of_ior(ior: f32) -> f32 {
    ((ior - 1.0) / (ior + 1.0)).powi(2)
}

/// How a material's alpha (base alpha × texture alpha × vertex alpha) hides the surface.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum AlphaMode {
    /// Alpha is ignored.
    #[default]
    Opaque,
    /// The surface exists where alpha ≥ `cutoff` and is absent elsewhere (a cutout).
    Mask {
        /// Threshold.
        cutoff: f32,
    },
    /// The surface is there with probability alpha: stochastic transparency, which converges
    /// to alpha blending without sorting anything.
    Blend,
}

/// One channel of a texture, for a scalar input (glTF packs metallic in blue and roughness
/// in green of one texture; USD connects each input to an output `r`, `g`, `b` or `a`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ChannelRef {
    /// The texture.
    pub texture: TextureRef,
    /// 0 = red … 3 = alpha.
    pub channel: usize,
}

/// What textures and vertex attributes change over a material's surface. Each texture
/// multiplies the matching [`Pbr`] factor, as glTF defines. All `None`: the material is
/// uniform.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct MaterialTextures {
    /// sRGB colour and linear alpha multiplying the base colour and `alpha`.
    pub base_colour: Option<TextureRef>,
    /// sRGB colour multiplying `emission`.
    pub emissive: Option<TextureRef>,
    /// Linear, multiplies [`Pbr::metallic`].
    pub metallic: Option<ChannelRef>,
    /// Linear, multiplies [`Pbr::roughness`].
    pub roughness: Option<ChannelRef>,
    /// Linear, multiplies [`Pbr::transmission`].
    pub transmission: Option<ChannelRef>,
    /// Linear, multiplies [`Pbr::clearcoat`].
    pub clearcoat: Option<ChannelRef>,
    /// Linear, multiplies [`Pbr::clearcoat_roughness`].
    pub clearcoat_roughness: Option<ChannelRef>,
    /// Linear, multiplies [`Pbr::specular`] (`KHR_materials_specular`'s alpha channel).
    pub specular: Option<ChannelRef>,
    /// sRGB colour multiplying [`Pbr::specular_colour`].
    pub specular_colour: Option<TextureRef>,
    /// sRGB colour multiplying [`Pbr::sheen_colour`].
    pub sheen_colour: Option<TextureRef>,
    /// Linear, multiplies [`Pbr::sheen_roughness`] (`KHR_materials_sheen`'s alpha channel).
    pub sheen_roughness: Option<ChannelRef>,
    /// Tangent-space normal map (linear, +Y up, OpenGL convention as glTF defines).
    pub normal: Option<TextureRef>,
    /// Scales the normal map's X and Y.
    pub normal_scale: f32,
    /// The clear coat's own tangent-space normal map (`clearcoatNormalTexture`).
    pub clearcoat_normal: Option<TextureRef>,
    /// Scales the coat normal map's X and Y.
    pub clearcoat_normal_scale: f32,
    /// `anisotropyTexture`: RG the direction in the tangent frame ([-1, 1]), B × strength.
    pub anisotropy: Option<TextureRef>,
}

impl MaterialTextures {
    /// True when any texture is used.
    pub fn any(&self) -> bool {
        self.base_colour.is_some()
            || self.emissive.is_some()
            || self.metallic.is_some()
            || self.roughness.is_some()
            || self.transmission.is_some()
            || self.clearcoat.is_some()
            || self.clearcoat_roughness.is_some()
            || self.specular.is_some()
            || self.specular_colour.is_some()
            || self.sheen_colour.is_some()
            || self.sheen_roughness.is_some()
            || self.normal.is_some()
            || self.clearcoat_normal.is_some()
            || self.anisotropy.is_some()
    }
}

/// A named material. Any material may also emit; emissive surfaces become area lights.
#[derive(Clone, Debug, PartialEq)]
pub struct Material {
    /// Name for messages.
    pub name: String,
    /// The scattering model.
    pub pbr: Pbr,
    /// Emitted radiance (W·sr⁻¹·m⁻²); zero for non-emitters.
    pub emission: Vec3,
    /// When false, the back face neither emits nor scatters light (it absorbs).
    pub double_sided: bool,
    /// Textures over the surface.
    pub textures: MaterialTextures,
    /// When true, vertex colours (`COLOR_0`) multiply the colour and alpha.
    pub vertex_colours: bool,
    /// Base alpha (glTF `baseColorFactor`'s fourth component).
    pub alpha: f32,
    /// What alpha does.
    pub alpha_mode: AlphaMode,
    /// Absorption coefficient (per scene unit) inside a glass volume: Beer–Lambert
    /// attenuation exp(−σ·d) along paths through it. Zero: clear.
    pub absorption: Vec3,
    /// When false, camera rays pass through the surface as if it were not there, while it
    /// still scatters, emits and casts shadows for every other ray: a lamp's shape, which
    /// Cycles does not show to the camera.
    pub camera_visible: bool,
    /// `KHR_materials_unlit`: the surface is its base colour (× texture × vertex colour),
    /// seen as that radiance by camera rays and through mirrors and glass (delta bounces);
    /// it scatters nothing and lights nothing else, and casts shadows like any opaque
    /// surface. Blender's glTF importer shows it to camera rays only.
    pub unlit: bool,
    /// A lamp's shape (USD `RectLight`, `DiskLight`): it emits, and every ray passes
    /// through it, so it scatters nothing and casts no shadow — Cycles' area lights are
    /// lights, not geometry. Light sampling and rays that pass it still find its emission.
    pub lamp: bool,
}

impl Material {
    /// A non-emissive, double-sided material scattering as `pbr` says.
    pub fn new(name: impl Into<String>, pbr: Pbr) -> Material {
        Material {
            name: name.into(),
            pbr,
            emission: Vec3::ZERO,
            double_sided: true,
            textures: MaterialTextures::default(),
            vertex_colours: false,
            alpha: 1.0,
            alpha_mode: AlphaMode::Opaque,
            absorption: Vec3::ZERO,
            camera_visible: true,
            unlit: false,
            lamp: false,
        }
    }

    /// A double-sided Lambertian material.
    pub fn diffuse(name: impl Into<String>, albedo: Vec3) -> Material {
        Material::new(name, Pbr::diffuse(albedo))
    }

    /// The material of surfaces whose file gives none (or none gridtrace can use): grey
    /// plastic, Blender's default material (base 0.8, roughness 0.5, the 4 % dielectric
    /// layer), which is also what model viewers show. glTF's own default material is a white
    /// rough metal, which nobody means by leaving the material out.
    pub fn default_grey(name: impl Into<String>) -> Material {
        Material::new(
            name,
            Pbr {
                base_colour: Vec3::splat(0.8),
                metallic: 0.0,
                roughness: 0.5,
                ..Pbr::default()
            },
        )
    }

    /// The same material emitting `radiance`.
    pub fn with_emission(mut self, radiance: Vec3) -> Material {
        self.emission = radiance;
        self
    }

    /// Power emitted per unit area (W/m², mean over channels): π × radiance from each
    /// emitting side. Textured emission scales it by the texture's mean.
    pub fn exitance(&self) -> f32 {
        let sides = if self.double_sided { 2.0 } else { 1.0 };
        sides * std::f32::consts::PI * self.emission.element_sum() / 3.0
    }

    /// True when the material emits light.
    pub fn is_emissive(&self) -> bool {
        self.emission.max_element() > 0.0
    }

    /// True when some hits on it may be ignored because of alpha.
    pub fn is_cutout(&self) -> bool {
        self.alpha_mode != AlphaMode::Opaque
    }

    /// True when shading must look at textures or vertex attributes.
    pub fn varies(&self) -> bool {
        // An anisotropic lobe turns with the surface's tangent frame.
        self.textures.any() || self.vertex_colours || self.pbr.anisotropy.strength > 0.0
    }
}
