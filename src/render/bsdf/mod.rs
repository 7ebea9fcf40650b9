//! The surface scattering model: one [`Bsdf`] per shading point, made from the scene's
//! [`Pbr`] description by [`Bsdf::new`], the one place that decides which lobes a material
//! has and how they stack (glTF 2.0 Appendix B and its KHR material extensions):
//!
//! ```text
//! coat  ─ clear GGX dielectric (index 1.5, exact Fresnel × clearcoat)
//!  └ sheen ─ Charlie sheen (the microfibre sheen lies over the coat instead)
//!     └ metallic · GGX conductor (F0 = base colour; anisotropic along the tangent
//!                  frame where the material says so, as is the dielectric layer)
//!       + (1 − metallic)(1 − transmission) · [GGX dielectric layer over Lambertian base]
//!       + (1 − metallic) · transmission · rough or smooth glass (√base colour per crossing)
//! ```
//!
//! Each layer passes to what lies beneath it the energy it does not reflect towards the
//! viewer, 1 − E(μo) ([`specular::SpecularLobe::transmitted`]), as Cycles' Principled BSDF
//! does, so a white stack reflects exactly what arrives. Each lobe is reciprocal; the
//! stack, like Cycles', is not. Sampling picks a strategy in proportion to
//! each lobe's estimated albedo; every non-delta lobe takes part in `eval` and `pdf`, so
//! light sampling and MIS see all of them.
//!
//! Directions are world-space unit vectors pointing away from the surface. `n` is the
//! shading normal turned to the side `wo` lies on (see [`crate::render::integrator`]).

mod albedo;
mod fresnel;
mod glass;
mod microfacet;
mod sheen;
mod sheen_table;
mod specular;

pub use fresnel::fresnel_dielectric;

use std::f32::consts::FRAC_1_PI;

use glam::{Vec2, Vec3};

use super::sampling::{Frame, cosine_hemisphere};
use crate::scene::{Anisotropy, AnisotropyModel, Pbr, SheenModel, f0_of_ior};
use fresnel::Fresnel;
use glass::GlassLobe;
use microfacet::Ggx;
use sheen::SheenLayer;
use specular::SpecularLobe;

/// Index of the clear coat: 1.5, as `KHR_materials_clearcoat` fixes it (F0 = 0.04) and as
/// Cycles' coat defaults.
const COAT_IOR: f32 = 1.5;

/// The metal or specular lobe with Fresnel factor `fresnel`: isotropic GGX at `roughness`,
/// or anisotropic GGX stretched along local x (turned to the surface's direction by
/// [`Bsdf::with_tangent`]) by the anisotropy's model.
fn glossy_lobe(roughness: f32, anisotropy: &Anisotropy, fresnel: Fresnel) -> SpecularLobe {
    let strength = anisotropy.strength.clamp(0.0, 1.0);
    if strength == 0.0 {
        return SpecularLobe::new(roughness, fresnel);
    }
    let alpha = roughness * roughness;
    let (along, across) = match anisotropy.model {
        AnisotropyModel::Gltf => (alpha + (1.0 - alpha) * strength * strength, alpha),
        AnisotropyModel::Cycles => {
            let aspect = (1.0 - 0.9 * strength).sqrt();
            (alpha / aspect, alpha * aspect)
        }
    };
    SpecularLobe::anisotropic(Ggx::anisotropic(along, across), fresnel)
}

/// The index of refraction whose normal-incidence reflectance is `f0` < 1 (the inverse of
/// [`f0_of_ior`]).
fn ior_of_f0(f0: f32) -> f32 {
    let r = f0.clamp(0.0, 0.99).sqrt();
    (1.0 + r) / (1.0 - r)
}

/// The lobes of one material at one point, with their weights.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bsdf {
    /// Lambertian albedo of the dielectric base, before the specular layer takes its share.
    diffuse: Vec3,
    /// The dielectric specular layer over the diffuse base, and its weight.
    specular: Option<(SpecularLobe, f32)>,
    /// The conductor and its weight.
    metal: Option<(SpecularLobe, f32)>,
    /// The transmitting dielectric and its weight.
    glass: Option<(GlassLobe, f32)>,
    /// The clear coat over everything.
    coat: Option<SpecularLobe>,
    /// The coat's own frame, in the local frame of the shading normal, when a coat normal
    /// map tilts it (`KHR_materials_clearcoat`'s `clearcoatNormalTexture`).
    coat_frame: Option<Frame>,
    /// The sheen: between the coat and the rest, or over the coat (microfibre).
    sheen: Option<SheenLayer>,
    /// The cosine lobes' (diffuse base and sheen) own normal, when the shading normal has
    /// been raised for the glossy lobes ([`Bsdf::with_diffuse_normal`]): world space, and
    /// as a frame in the local frame of the glossy normal.
    diffuse_normal: Option<(Vec3, Frame)>,
    /// The interpolated normal before normal mapping (glossy frame) and the α² of the
    /// shadowing that softens the cosine lobes' terminator on normal-mapped surfaces.
    bump: Option<(Vec3, f32)>,
}

/// A direction drawn from a BSDF.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BsdfSample {
    /// Incident direction (towards the next vertex).
    pub wi: Vec3,
    /// f·|cos θi| / pdf: what the path throughput is multiplied by.
    pub weight: Vec3,
    /// Solid-angle density of `wi`; for delta lobes the discrete probability of the lobe.
    pub pdf: f32,
    /// True for a delta lobe, which light sampling can never produce.
    pub is_delta: bool,
    /// True when `wi` crosses the surface.
    pub is_transmission: bool,
}

/// The ways [`Bsdf::sample`] draws a direction.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Strategy {
    /// Cosine-weighted: the diffuse base and the sheen.
    Cosine,
    Coat,
    Metal,
    Specular,
    Glass,
    /// The microfibre sheen's own transformed cosine.
    Sheen,
}

const STRATEGIES: [Strategy; 6] = [
    Strategy::Cosine,
    Strategy::Coat,
    Strategy::Metal,
    Strategy::Specular,
    Strategy::Glass,
    Strategy::Sheen,
];

impl Bsdf {
    /// The lobes of `pbr` for a ray arriving on the `front` side of the surface (which for
    /// transmission decides whether it enters or leaves).
    pub fn new(pbr: &Pbr, front: bool) -> Bsdf {
        let metallic = pbr.metallic.clamp(0.0, 1.0);
        let transmission = pbr.transmission.clamp(0.0, 1.0);
        let roughness = pbr.roughness.clamp(0.0, 1.0);
        let dielectric = (1.0 - metallic) * (1.0 - transmission);
        let base = pbr.base_colour.clamp(Vec3::ZERO, Vec3::ONE);
        let positive = |w: f32| (w > 0.0).then_some(w);
        // The specular layer as Cycles' Principled BSDF makes it (svm/closure.h): the
        // specular weight (KHR_materials_specular's specular, Blender's Specular IOR Level)
        // moves F0 = F0(ior)·specular along the exact Fresnel curve F_η of the index with
        // that F0, and the specular colour (Specular Tint) remaps the curve to start at
        // F0·colour and still rise to 1 at grazing angles:
        // F = F0·colour + (1 − F0·colour)·(F_η − F0)/(1 − F0). A specular colour of 0 keeps
        // that grazing rise; glTF's F0 = min(F0(ior)·colour, 1)·specular is the same at
        // normal incidence.
        let glossy = |fresnel| glossy_lobe(roughness, &pbr.anisotropy, fresnel);
        let f0 = (f0_of_ior(pbr.ior) * pbr.specular.clamp(0.0, 1.0)).min(0.99);
        let specular = positive(dielectric).filter(|_| f0 > 0.0).map(|w| {
            let tinted = (f0 * pbr.specular_colour.max(Vec3::ZERO)).min(Vec3::ONE);
            let scale = (Vec3::ONE - tinted) / (1.0 - f0);
            let fresnel = Fresnel::Dielectric {
                eta: ior_of_f0(f0),
                scale,
                offset: tinted - scale * f0,
            };
            (glossy(fresnel), w)
        });
        let metal = positive(metallic).map(|w| {
            let fresnel = Fresnel::Schlick { f0: base, f90: 1.0 };
            (glossy(fresnel), w)
        });
        // Each crossing tints by √(base colour), as Cycles' Principled BSDF does
        // (`svm/closure.h`: the glass's transmission tint is sqrt(base colour)), so light
        // through a closed object is tinted by the base colour once, and a single sheet by
        // its square root.
        let eta = if front { pbr.ior } else { 1.0 / pbr.ior };
        let tint = base.powf(0.5);
        let glass = positive((1.0 - metallic) * transmission)
            .map(|w| (GlassLobe::new(roughness, eta, tint), w));
        let coat = positive(pbr.clearcoat.min(1.0)).map(|c| {
            let fresnel = Fresnel::Dielectric {
                eta: COAT_IOR,
                scale: Vec3::splat(c),
                offset: Vec3::ZERO,
            };
            SpecularLobe::new(pbr.clearcoat_roughness.clamp(0.0, 1.0), fresnel)
        });
        let sheen = (pbr.sheen_colour.max_element() > 0.0).then(|| SheenLayer {
            colour: pbr.sheen_colour.clamp(Vec3::ZERO, Vec3::ONE),
            roughness: pbr.sheen_roughness.clamp(0.0, 1.0),
            model: pbr.sheen_model,
        });
        Bsdf {
            diffuse: base * dielectric,
            specular,
            metal,
            glass,
            coat,
            coat_frame: None,
            sheen,
            diffuse_normal: None,
            bump: None,
        }
    }

    /// The same BSDF with the clear coat around its own unit normal `coat_normal` (world
    /// space, on the side of `n`), for evaluation around the shading normal `n`.
    pub fn with_coat_normal(mut self, n: Vec3, coat_normal: Vec3) -> Bsdf {
        if self.coat.is_some() {
            let local = Frame::from_normal(n).to_local(coat_normal);
            self.coat_frame = local.try_normalize().map(Frame::from_normal);
        }
        self
    }

    /// The same BSDF with its glossy lobes around `n` (a shading normal raised so that
    /// mirror reflection stays above the surface, [`crate::render::shading::valid_reflection_normal`])
    /// and its diffuse base and sheen around the unraised `diffuse_normal`, as Cycles'
    /// Principled BSDF sets them up (`svm/closure.h`: the diffuse closure keeps N).
    pub fn with_diffuse_normal(mut self, n: Vec3, diffuse_normal: Vec3) -> Bsdf {
        let local = Frame::from_normal(n).to_local(diffuse_normal);
        if let Some(local) = local.try_normalize() {
            self.diffuse_normal = Some((diffuse_normal, Frame::from_normal(local)));
        }
        self
    }

    /// The same BSDF on a normal-mapped surface whose interpolated normal was `smooth`
    /// (world space, `n` the glossy normal): its cosine lobes are shadowed by
    /// G1(α², |smooth·wi|) with α² = min(tan²θd / 8, 1), θd between `smooth` and the
    /// diffuse normal — Conty Estevez et al. 2019, "A Microfacet-Based Shadowing Function
    /// to Solve the Bump Terminator Problem", as Cycles applies it (`bump_shadowing_term`)
    /// with its material's Bump Map Correction (on by default).
    pub fn with_bump_shadowing(mut self, n: Vec3, smooth: Vec3) -> Bsdf {
        let diffuse = self.diffuse_normal.map_or(n, |(d, _)| d);
        let cos_d = smooth.dot(diffuse).abs();
        if cos_d < 1.0 && cos_d > 0.0 {
            let tan2 = 1.0 / (cos_d * cos_d) - 1.0;
            let alpha2 = (0.125 * tan2).clamp(0.0, 1.0);
            self.bump = Some((Frame::from_normal(n).to_local(smooth), alpha2));
        }
        self
    }

    /// The bump shadowing of the cosine lobes towards local `wi`.
    fn bump_shadowing(&self, wi: Vec3) -> f32 {
        let Some((smooth, alpha2)) = self.bump else {
            return 1.0;
        };
        let cos_i = smooth.dot(wi).abs();
        if cos_i >= 1.0 {
            return 1.0;
        }
        if cos_i < 1e-6 {
            return 0.0;
        }
        let tan2 = 1.0 / (cos_i * cos_i) - 1.0;
        2.0 / (1.0 + (1.0 + alpha2 * tan2).sqrt())
    }

    /// Turns the metal and specular lobes' anisotropy to `tangent` (world space) around the
    /// shading normal `n` the BSDF is evaluated with; isotropic lobes are unchanged.
    pub fn with_tangent(mut self, n: Vec3, tangent: Vec3) -> Bsdf {
        let local = Frame::from_normal(n).to_local(tangent);
        let Some(axis) = Vec2::new(local.x, local.y).try_normalize() else {
            return self;
        };
        for lobe in [&mut self.specular, &mut self.metal].into_iter().flatten() {
            lobe.0 = lobe.0.turned(axis);
        }
        self
    }

    /// A direction of the glossy frame in the cosine lobes' frame.
    fn in_diffuse_frame(&self, w: Vec3) -> Vec3 {
        self.diffuse_normal.map_or(w, |(_, f)| f.to_local(w))
    }

    /// A direction of the shading frame in the coat's frame.
    fn in_coat_frame(&self, w: Vec3) -> Vec3 {
        self.coat_frame.map_or(w, |f| f.to_local(w))
    }

    /// A direction of the coat's frame in the shading frame.
    fn in_shading_frame(&self, w: Vec3) -> Vec3 {
        self.coat_frame.map_or(w, |f| f.to_world(w))
    }

    /// Names of the lobes, for `--inspect` and messages.
    pub fn lobe_names(&self) -> Vec<&'static str> {
        let mut names = Vec::new();
        let sharp = |delta: bool, smooth, rough| if delta { smooth } else { rough };
        if let Some(c) = &self.coat {
            names.push(sharp(c.is_delta(), "smooth coat", "rough coat"));
        }
        if let Some(sheen) = &self.sheen {
            names.push(match sheen.model {
                SheenModel::Charlie => "sheen",
                SheenModel::Microfiber => "microfibre sheen",
            });
        }
        if let Some((m, _)) = &self.metal {
            names.push(sharp(m.is_delta(), "mirror conductor", "GGX conductor"));
        }
        if let Some((s, _)) = &self.specular {
            names.push(sharp(
                s.is_delta(),
                "smooth specular layer",
                "GGX specular layer",
            ));
        }
        if self.diffuse.max_element() > 0.0 {
            names.push("Lambertian");
        }
        if let Some((g, _)) = &self.glass {
            names.push(sharp(g.is_delta(), "smooth glass", "rough glass"));
        }
        names
    }

    /// True when light passes through the surface here (a glass lobe): its back face is
    /// then the inside of a volume, whatever the material's sidedness.
    pub fn transmits(&self) -> bool {
        self.glass.is_some()
    }

    /// True when every lobe is a delta (light sampling is useless there).
    pub fn is_delta(&self) -> bool {
        !self.has_cosine_lobes()
            && self.sheen.is_none()
            && self.coat.is_none_or(|c| c.is_delta())
            && self.metal.is_none_or(|(m, _)| m.is_delta())
            && self.specular.is_none_or(|(s, _)| s.is_delta())
            && self.glass.is_none_or(|(g, _)| g.is_delta())
    }

    /// True when the only lobe is the Lambertian base: the common case, which needs no
    /// local frame and no strategy weights.
    fn is_lambertian(&self) -> bool {
        self.specular.is_none()
            && self.metal.is_none()
            && self.glass.is_none()
            && self.coat.is_none()
            && self.sheen.is_none()
            && self.bump.is_none()
    }

    /// True when the cosine strategy (Lambertian base, Charlie sheen) has anything to draw.
    /// True when the BSDF scatters diffusely (a Lambertian base or sheen beneath the coat):
    /// where path guiding pays, since a narrow glossy or glass lobe already samples its
    /// directions well.
    pub fn is_guidable(&self) -> bool {
        self.has_cosine_lobes()
    }

    fn has_cosine_lobes(&self) -> bool {
        self.diffuse.max_element() > 0.0 || self.sheen.is_some_and(|s| !s.over_coat())
    }

    /// The factor the coat and sheen leave to what lies beneath them, for `wo` in the
    /// shading frame.
    fn beneath_top(&self, wo: Vec3) -> Vec3 {
        let mut factor = Vec3::ONE;
        if let Some(coat) = &self.coat {
            factor *= coat.transmitted(self.in_coat_frame(wo).z.max(0.0));
        }
        if let Some(sheen) = &self.sheen {
            factor *= sheen.transmitted(self.in_diffuse_frame(wo));
        }
        factor
    }

    /// f(wo, wi)·|cos θi| in the local frame, for every non-delta lobe, each lobe's
    /// cosine taken about its own normal.
    fn eval_local(&self, wo: Vec3, wi: Vec3) -> Vec3 {
        if wo.z <= 0.0 {
            return Vec3::ZERO;
        }
        let beneath = self.beneath_top(wo);
        let mut f = Vec3::ZERO;
        if let Some((glass, w)) = &self.glass {
            f += beneath * glass.eval(wo, wi) * (*w * wi.z.abs());
        }
        if wi.z <= 0.0 {
            return f;
        }
        let coat_wo = self.in_coat_frame(wo);
        let (diffuse_wo, diffuse_wi) = (self.in_diffuse_frame(wo), self.in_diffuse_frame(wi));
        let sheen_over_coat = self.sheen.filter(|s| s.over_coat());
        if let Some(coat) = &self.coat {
            let factor = sheen_over_coat.map_or(Vec3::ONE, |s| s.transmitted(diffuse_wo));
            f += factor * coat.eval(coat_wo, self.in_coat_frame(wi)) * wi.z;
        }
        let shadowing = self.bump_shadowing(wi);
        let diffuse_cos = diffuse_wi.z.max(0.0) * shadowing;
        if let Some(sheen) = &self.sheen {
            let factor = match (&self.coat, sheen.over_coat()) {
                (Some(c), false) => c.transmitted(coat_wo.z.max(0.0)),
                _ => Vec3::ONE,
            };
            if diffuse_wo.z > 0.0 && diffuse_cos > 0.0 {
                f += factor * sheen.eval(diffuse_wo, diffuse_wi) * shadowing;
            }
        }
        if let Some((metal, w)) = &self.metal {
            f += beneath * metal.eval(wo, wi) * (*w * wi.z);
        }
        let mut base = self.diffuse * (FRAC_1_PI * diffuse_cos);
        if let Some((specular, w)) = &self.specular {
            base *= specular.transmitted(wo.z);
            f += beneath * specular.eval(wo, wi) * (*w * wi.z);
        }
        f + beneath * base
    }

    /// How often each strategy is chosen, in proportion to the albedo it covers at `wo`.
    fn strategy_weights(&self, wo: Vec3) -> [f32; 6] {
        let mean = |v: Vec3| v.element_sum() / 3.0;
        let mu_o = wo.z;
        let mut top = 1.0;
        let mut coat = 0.0;
        let mut cosine = 0.0;
        let mut sheen_weight = 0.0;
        let sheen_albedo = self.sheen.map(|s| {
            let e = s.colour.max_element() * s.white_albedo(self.in_diffuse_frame(wo));
            (s, e)
        });
        if let Some((_, e)) = sheen_albedo.filter(|(s, _)| s.over_coat()) {
            sheen_weight = e;
            top = 1.0 - e;
        }
        if let Some(c) = &self.coat {
            let coat_mu = self.in_coat_frame(wo).z;
            coat = if coat_mu > 0.0 {
                top * mean(c.albedo(coat_mu))
            } else {
                0.0
            };
            top -= coat;
        }
        if let Some((_, e)) = sheen_albedo.filter(|(s, _)| !s.over_coat()) {
            cosine += top * e;
            top *= 1.0 - e;
        }
        let metal = self
            .metal
            .map_or(0.0, |(m, w)| top * w * mean(m.albedo(mu_o)));
        let mut specular = 0.0;
        let mut under = Vec3::ONE;
        if let Some((s, w)) = &self.specular {
            let e = s.albedo(mu_o);
            specular = top * w * mean(e);
            under = Vec3::ONE - e;
        }
        cosine += top * mean(self.diffuse * under);
        // Glass passes or reflects almost everything, whatever its tint.
        let glass = self.glass.map_or(0.0, |(_, w)| top * w);
        [cosine, coat, metal, specular, glass, sheen_weight].map(|w| w.max(0.0))
    }

    /// Solid-angle pdf of `wi` over the non-delta strategies, local frame.
    fn pdf_local(&self, wo: Vec3, wi: Vec3, weights: &[f32; 6]) -> f32 {
        let total: f32 = weights.iter().sum();
        if total <= 0.0 || wo.z <= 0.0 {
            return 0.0;
        }
        let mut pdf = 0.0;
        for (strategy, &w) in STRATEGIES.iter().zip(weights) {
            if w == 0.0 {
                continue;
            }
            let p = match strategy {
                // Cosine lobes reflect only above both their normal and the glossy one.
                Strategy::Cosine if wi.z > 0.0 => self.in_diffuse_frame(wi).z.max(0.0) * FRAC_1_PI,
                Strategy::Cosine => 0.0,
                Strategy::Coat => self.coat.map_or(0.0, |c| {
                    c.pdf_visible(self.in_coat_frame(wo), self.in_coat_frame(wi))
                }),
                Strategy::Metal => self.metal.map_or(0.0, |(m, _)| m.pdf_visible(wo, wi)),
                Strategy::Specular => self.specular.map_or(0.0, |(s, _)| s.pdf_visible(wo, wi)),
                Strategy::Glass => self.glass.map_or(0.0, |(g, _)| g.pdf(wo, wi)),
                Strategy::Sheen if wi.z > 0.0 => self
                    .microfiber(wo)
                    .map_or(0.0, |m| m.pdf(self.in_diffuse_frame(wi))),
                Strategy::Sheen => 0.0,
            };
            pdf += w * p;
        }
        pdf / total
    }

    /// f(wo, wi)·|cos θi| over the non-delta lobes (each lobe's cosine about its own
    /// normal); zero for delta lobes.
    pub fn eval(&self, n: Vec3, wo: Vec3, wi: Vec3) -> Vec3 {
        if self.is_lambertian() {
            let cos = self.diffuse_normal.map_or(n, |(d, _)| d).dot(wi);
            return if n.dot(wo) > 0.0 && n.dot(wi) > 0.0 && cos > 0.0 {
                self.diffuse * (FRAC_1_PI * cos)
            } else {
                Vec3::ZERO
            };
        }
        let frame = Frame::from_normal(n);
        self.eval_local(frame.to_local(wo), frame.to_local(wi))
    }

    /// Solid-angle pdf with which [`Bsdf::sample`] picks `wi` by its non-delta strategies.
    pub fn pdf(&self, n: Vec3, wo: Vec3, wi: Vec3) -> f32 {
        if self.is_lambertian() {
            let black = self.diffuse == Vec3::ZERO || n.dot(wo) <= 0.0;
            let d = self.diffuse_normal.map_or(n, |(d, _)| d);
            return if black || n.dot(wi) <= 0.0 {
                0.0
            } else {
                d.dot(wi).max(0.0) * FRAC_1_PI
            };
        }
        let frame = Frame::from_normal(n);
        let wo = frame.to_local(wo);
        let weights = self.strategy_weights(wo);
        self.pdf_local(wo, frame.to_local(wi), &weights)
    }

    /// Draws an incident direction. `u` places it within the chosen strategy, `u_lobe`
    /// chooses the strategy (and then reflection or refraction at glass).
    pub fn sample(&self, n: Vec3, wo: Vec3, u: Vec2, u_lobe: f32) -> Option<BsdfSample> {
        let frame = Frame::from_normal(n);
        let wo = frame.to_local(wo);
        if wo.z <= 0.0 {
            return None;
        }
        if self.is_lambertian() {
            let wi = cosine_hemisphere(u);
            let pdf = wi.z * FRAC_1_PI;
            let wi = match self.diffuse_normal {
                Some((d, _)) => Frame::from_normal(d).to_world(wi),
                None => frame.to_world(wi),
            };
            let above = pdf > 0.0 && n.dot(wi) > 0.0;
            return (above && self.diffuse != Vec3::ZERO).then_some(BsdfSample {
                wi,
                weight: self.diffuse,
                pdf,
                is_delta: false,
                is_transmission: false,
            });
        }
        let weights = self.strategy_weights(wo);
        let total: f32 = weights.iter().sum();
        if total <= 0.0 {
            return None;
        }
        // Choose a strategy, and keep the remainder of `u_lobe` uniform for the next choice.
        let mut target = u_lobe * total;
        let mut chosen = Strategy::Cosine;
        let mut probability = 0.0;
        for (strategy, &w) in STRATEGIES.iter().zip(&weights) {
            if w > 0.0 {
                chosen = *strategy;
                probability = w / total;
                if target < w {
                    break;
                }
                target -= w;
            }
        }
        let u_rest = (target / (probability * total)).clamp(0.0, 1.0 - f32::EPSILON);
        let delta = self.sample_delta(chosen, wo, u_rest);
        if let Some((wi, value, p, is_transmission)) = delta {
            return Some(BsdfSample {
                wi: frame.to_world(wi),
                weight: value / (p * probability),
                pdf: p * probability,
                is_delta: true,
                is_transmission,
            });
        }
        let wi = match chosen {
            Strategy::Cosine => Some(cosine_hemisphere(u)).map(|wi| {
                self.diffuse_normal
                    .map_or(wi, |(_, frame)| frame.to_world(wi))
            }),
            Strategy::Coat => self
                .coat
                .and_then(|c| c.sample_visible(self.in_coat_frame(wo), u))
                .map(|wi| self.in_shading_frame(wi)),
            Strategy::Metal => self.metal.and_then(|(m, _)| m.sample_visible(wo, u)),
            Strategy::Specular => self.specular.and_then(|(s, _)| s.sample_visible(wo, u)),
            Strategy::Glass => self.glass.and_then(|(g, _)| g.sample_rough(wo, u, u_rest)),
            Strategy::Sheen => self.microfiber(wo).map(|m| {
                let wi = m.sample(u);
                self.diffuse_normal
                    .map_or(wi, |(_, frame)| frame.to_world(wi))
            }),
        }?;
        let pdf = self.pdf_local(wo, wi, &weights);
        let f = self.eval_local(wo, wi);
        if pdf <= 0.0 || f == Vec3::ZERO {
            return None;
        }
        let is_transmission = wi.z < 0.0;
        Some(BsdfSample {
            wi: frame.to_world(wi),
            weight: f / pdf,
            pdf,
            is_delta: false,
            is_transmission,
        })
    }

    /// The direction, value f·|cos| (the delta's integral), choice probability within the
    /// strategy and crossing of a delta lobe, when `strategy` is one.
    fn sample_delta(
        &self,
        strategy: Strategy,
        wo: Vec3,
        u_choice: f32,
    ) -> Option<(Vec3, Vec3, f32, bool)> {
        let mirror = Vec3::new(-wo.x, -wo.y, wo.z);
        let mu = wo.z;
        match strategy {
            Strategy::Coat => {
                let c = self.coat.filter(|c| c.is_delta())?;
                let wo = self.in_coat_frame(wo);
                let wi = self.in_shading_frame(Vec3::new(-wo.x, -wo.y, wo.z));
                (wi.z > 0.0).then_some((wi, c.albedo(wo.z), 1.0, false))
            }
            Strategy::Metal => {
                let (m, w) = self.metal.filter(|(m, _)| m.is_delta())?;
                Some((mirror, self.beneath_top(wo) * m.albedo(mu) * w, 1.0, false))
            }
            Strategy::Specular => {
                let (s, w) = self.specular.filter(|(s, _)| s.is_delta())?;
                Some((mirror, self.beneath_top(wo) * s.albedo(mu) * w, 1.0, false))
            }
            Strategy::Glass => {
                let (g, w) = self.glass.filter(|(g, _)| g.is_delta())?;
                let s = g.sample_delta(wo, u_choice)?;
                let beneath = self.beneath_top(wo);
                Some((
                    s.wi,
                    beneath * s.value * w,
                    s.probability,
                    s.is_transmission,
                ))
            }
            Strategy::Cosine | Strategy::Sheen => None,
        }
    }

    /// The microfibre sheen's lobe seen from `wo` (shading frame), when it has one.
    fn microfiber(&self, wo: Vec3) -> Option<sheen::Microfiber> {
        self.sheen?.microfiber(self.in_diffuse_frame(wo))
    }
}

#[cfg(test)]
mod tests;
