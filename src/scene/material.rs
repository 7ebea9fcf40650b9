//! Materials: the four surface models gridtrace renders, plus emission.

use glam::Vec3;

use super::TextureRef;

/// How a surface scatters light.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum MaterialKind {
    /// Lambertian reflection, f = albedo/π.
    Diffuse {
        /// Reflectance in [0, 1] per channel.
        albedo: Vec3,
    },
    /// Ideal specular reflection.
    Mirror {
        /// Reflectance per channel.
        reflectance: Vec3,
    },
    /// Ideal smooth dielectric: Fresnel-weighted reflection and refraction.
    Glass {
        /// Relative index of refraction inside / outside.
        ior: f32,
        /// Transmission colour.
        tint: Vec3,
    },
}

impl MaterialKind {
    /// The colour the model is tinted by: albedo, reflectance or transmission tint.
    pub fn colour(&self) -> Vec3 {
        match *self {
            MaterialKind::Diffuse { albedo } => albedo,
            MaterialKind::Mirror { reflectance } => reflectance,
            MaterialKind::Glass { tint, .. } => tint,
        }
    }

    /// The same model with its colour replaced.
    pub fn with_colour(self, colour: Vec3) -> MaterialKind {
        match self {
            MaterialKind::Diffuse { .. } => MaterialKind::Diffuse { albedo: colour },
            MaterialKind::Mirror { .. } => MaterialKind::Mirror {
                reflectance: colour,
            },
            MaterialKind::Glass { ior, .. } => MaterialKind::Glass { ior, tint: colour },
        }
    }
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

/// What textures and vertex attributes change over a material's surface (glTF's
/// metallic-roughness model). All `None`: the material is uniform.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct MaterialTextures {
    /// sRGB colour and linear alpha multiplying the model's colour and `alpha`.
    pub base_colour: Option<TextureRef>,
    /// sRGB colour multiplying `emission`.
    pub emissive: Option<TextureRef>,
    /// Linear; blue = metallic (× `metallic_factor`): where the product reaches 0.5 the
    /// surface is a mirror, elsewhere diffuse. Glass stays glass.
    pub metallic_roughness: Option<TextureRef>,
    /// The glTF `metallicFactor`, which the metallic texture multiplies.
    pub metallic_factor: f32,
    /// Tangent-space normal map (linear, +Y up, OpenGL convention as glTF defines).
    pub normal: Option<TextureRef>,
    /// Scales the normal map's X and Y.
    pub normal_scale: f32,
}

impl MaterialTextures {
    /// True when any texture is used.
    pub fn any(&self) -> bool {
        self.base_colour.is_some()
            || self.emissive.is_some()
            || self.metallic_roughness.is_some()
            || self.normal.is_some()
    }
}

/// A named material. Any material may also emit; emissive surfaces become area lights.
#[derive(Clone, Debug, PartialEq)]
pub struct Material {
    /// Name for messages.
    pub name: String,
    /// The scattering model.
    pub kind: MaterialKind,
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
}

impl Material {
    /// A non-emissive, double-sided material of the given kind.
    pub fn new(name: impl Into<String>, kind: MaterialKind) -> Material {
        Material {
            name: name.into(),
            kind,
            emission: Vec3::ZERO,
            double_sided: true,
            textures: MaterialTextures::default(),
            vertex_colours: false,
            alpha: 1.0,
            alpha_mode: AlphaMode::Opaque,
            absorption: Vec3::ZERO,
        }
    }

    /// A double-sided Lambertian material.
    pub fn diffuse(name: impl Into<String>, albedo: Vec3) -> Material {
        Material::new(name, MaterialKind::Diffuse { albedo })
    }

    /// The same material emitting `radiance`.
    pub fn with_emission(mut self, radiance: Vec3) -> Material {
        self.emission = radiance;
        self
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
        self.textures.any() || self.vertex_colours
    }
}
