//! Materials: the four surface models gridtrace renders, plus emission.

use glam::Vec3;

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
}

impl Material {
    /// A non-emissive, double-sided material of the given kind.
    pub fn new(name: impl Into<String>, kind: MaterialKind) -> Material {
        Material {
            name: name.into(),
            kind,
            emission: Vec3::ZERO,
            double_sided: true,
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
}
