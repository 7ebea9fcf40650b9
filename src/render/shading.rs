//! What a material looks like at one surface point: textures, vertex colours and normal maps
//! resolved into a BSDF, an emitted radiance and a shading normal; and the alpha that decides
//! whether the surface is there at all.

use std::borrow::Cow;

use glam::{Vec2, Vec3, Vec4};

use super::Renderer;
use super::bsdf::Bsdf;
use super::sampler::Sampler;
use super::surface::Surface;
use crate::scene::{AlphaMode, ChannelRef, ColorSpace, Material, Mesh, Pbr, Scene, TextureRef};

/// A material evaluated at a point.
#[derive(Clone, Debug)]
pub struct Shading<'a> {
    /// The scattering model with its colour: the material's own, borrowed, unless textures
    /// vary it (a BSDF is a few hundred bytes, and copying it at every vertex showed in
    /// profiles).
    pub bsdf: Cow<'a, Bsdf>,
    /// Emitted radiance.
    pub emission: Vec3,
    /// The base colour with its texture and vertex colour (what an unlit surface shows).
    pub base_colour: Vec3,
    /// Unit shading normal, normal-mapped where the material says so (not yet turned to
    /// any side).
    pub normal: Vec3,
    /// The clear coat's own normal where its normal map gives one (on the same side as
    /// `normal`).
    pub coat_normal: Option<Vec3>,
    /// The direction an anisotropic material's glossy lobes are stretched along (world
    /// space, in the tangent plane).
    pub anisotropy_direction: Option<Vec3>,
}

impl Shading<'_> {
    /// The BSDF turned to the side of `ng` (the geometric normal on the side `wo` lies
    /// on), and the normal its glossy lobes turn about: the shading normal raised until
    /// mirror reflection stays above the surface, as Cycles does
    /// ([`valid_reflection_normal`]), while the diffuse base and sheen keep the shading
    /// normal and, where a normal map bent it away from the interpolated `smooth` normal,
    /// take the bump shadowing.
    ///
    /// A BSDF that must change is written into `changed` and borrowed from there; the
    /// caller's slot, rather than a returned `Cow`, because moving a `Cow<Bsdf>` copies
    /// all of its few hundred bytes even when it only borrows (a `memcpy` at every vertex).
    pub fn oriented<'s>(
        &'s self,
        smooth: Vec3,
        ng: Vec3,
        wo: Vec3,
        changed: &'s mut Option<Bsdf>,
    ) -> (&'s Bsdf, Vec3) {
        let side = if self.normal.dot(ng) < 0.0 { -1.0 } else { 1.0 };
        let diffuse = side * self.normal;
        let n = valid_reflection_normal(ng, wo, diffuse);
        let unchanged = self.coat_normal.is_none()
            && n == diffuse
            && self.normal == smooth
            && self.anisotropy_direction.is_none();
        if unchanged {
            return (&self.bsdf, n);
        }
        let mut bsdf = match self.coat_normal {
            Some(coat) => self
                .bsdf
                .with_coat_normal(n, valid_reflection_normal(ng, wo, side * coat)),
            None => *self.bsdf,
        };
        if n != diffuse {
            bsdf = bsdf.with_diffuse_normal(n, diffuse);
        }
        if self.normal != smooth {
            bsdf = bsdf.with_bump_shadowing(n, smooth);
        }
        if let Some(direction) = self.anisotropy_direction {
            bsdf = bsdf.with_tangent(n, direction);
        }
        (changed.insert(bsdf), n)
    }
}

/// Texture coordinates of set `set` at the surface point; zero if the mesh has none.
pub fn uv_at(mesh: &Mesh, set: usize, vertices: [usize; 3], barycentrics: Vec3) -> Vec2 {
    barycentrics.x * mesh.uv(set, vertices[0])
        + barycentrics.y * mesh.uv(set, vertices[1])
        + barycentrics.z * mesh.uv(set, vertices[2])
}

/// `reference` looked up at the surface point.
pub fn texture_at(
    scene: &Scene,
    mesh: &Mesh,
    reference: &TextureRef,
    vertices: [usize; 3],
    barycentrics: Vec3,
    space: ColorSpace,
) -> Vec4 {
    let uv = uv_at(mesh, reference.texcoord, vertices, barycentrics);
    scene.textures[reference.texture].sample(reference, uv, space)
}

impl Renderer<'_> {
    /// The material of `s` evaluated there, for a ray arriving on the `front` side.
    pub(super) fn shade(&self, s: &Surface, front: bool) -> Shading<'_> {
        let material = &self.scene.materials[s.material];
        if !material.varies() {
            return Shading {
                bsdf: Cow::Borrowed(&self.bsdfs[s.material][usize::from(!front)]),
                emission: material.emission,
                base_colour: material.pbr.base_colour,
                normal: s.shading_normal,
                coat_normal: None,
                anisotropy_direction: None,
            };
        }
        let mesh = self.mesh_of(s);
        let lookup = |r: &TextureRef, space| {
            texture_at(self.scene, mesh, r, s.vertices, s.barycentrics, space)
        };
        let channel = |c: &Option<ChannelRef>| {
            c.as_ref().map_or(1.0, |c| {
                lookup(&c.texture, ColorSpace::Linear)[c.channel.min(3)]
            })
        };
        let textures = &material.textures;
        let mut pbr = material.pbr;
        if let Some(r) = &textures.base_colour {
            pbr.base_colour *= lookup(r, ColorSpace::Srgb).truncate();
        }
        if material.vertex_colours {
            pbr.base_colour *= self.vertex_colour(mesh, s).truncate();
        }
        pbr.metallic *= channel(&textures.metallic);
        pbr.roughness *= channel(&textures.roughness);
        pbr.transmission *= channel(&textures.transmission);
        pbr.clearcoat *= channel(&textures.clearcoat);
        pbr.clearcoat_roughness *= channel(&textures.clearcoat_roughness);
        pbr.specular *= channel(&textures.specular);
        pbr.sheen_roughness *= channel(&textures.sheen_roughness);
        if let Some(r) = &textures.specular_colour {
            pbr.specular_colour *= lookup(r, ColorSpace::Srgb).truncate();
        }
        if let Some(r) = &textures.sheen_colour {
            pbr.sheen_colour *= lookup(r, ColorSpace::Srgb).truncate();
        }
        let mut emission = material.emission;
        if let Some(r) = &textures.emissive {
            emission *= lookup(r, ColorSpace::Srgb).truncate();
        }
        let mapped = |texture: &Option<TextureRef>, scale: f32| match texture {
            Some(r) if !mesh.tangents.is_empty() => {
                let texel = lookup(r, ColorSpace::Linear);
                Some(self.normal_mapped(s, mesh, texel, scale))
            }
            _ => None,
        };
        let normal = mapped(&textures.normal, textures.normal_scale).unwrap_or(s.shading_normal);
        let anisotropy_direction = (pbr.anisotropy.strength > 0.0)
            .then(|| self.anisotropy_direction(s, mesh, &mut pbr, lookup))
            .flatten();
        Shading {
            bsdf: Cow::Owned(Bsdf::new(&pbr, front)),
            emission,
            base_colour: pbr.base_colour,
            normal,
            coat_normal: mapped(&textures.clearcoat_normal, textures.clearcoat_normal_scale),
            anisotropy_direction,
        }
    }

    /// True when the surface at `s` is really there for a ray: cutouts (alpha mask) are
    /// holes, a blended surface is there with probability alpha, and a lamp's shape is
    /// never there (rays collect its light and pass).
    pub(super) fn is_present(&self, s: &Surface, sampler: &mut Sampler) -> bool {
        let material = &self.scene.materials[s.material];
        if material.lamp {
            return false;
        }
        match material.alpha_mode {
            AlphaMode::Opaque => true,
            AlphaMode::Mask { cutoff } => self.alpha_at(material, s) >= cutoff,
            AlphaMode::Blend => sampler.uniform() < self.alpha_at(material, s),
        }
    }

    fn alpha_at(&self, material: &Material, s: &Surface) -> f32 {
        let mesh = self.mesh_of(s);
        let mut alpha = material.alpha;
        if let Some(r) = &material.textures.base_colour {
            alpha *= texture_at(
                self.scene,
                mesh,
                r,
                s.vertices,
                s.barycentrics,
                ColorSpace::Linear,
            )
            .w;
        }
        if material.vertex_colours {
            alpha *= self.vertex_colour(mesh, s).w;
        }
        alpha
    }

    fn mesh_of(&self, s: &Surface) -> &Mesh {
        &self.scene.meshes[self.scene.instances[s.instance].mesh]
    }

    fn vertex_colour(&self, mesh: &Mesh, s: &Surface) -> Vec4 {
        if mesh.colours.is_empty() {
            return Vec4::ONE;
        }
        let [a, b, c] = s.vertices;
        let w = s.barycentrics;
        w.x * mesh.colours[a] + w.y * mesh.colours[b] + w.z * mesh.colours[c]
    }

    /// The world tangent and bitangent at `s`, orthogonal to its shading normal, from the
    /// mesh's tangents (glTF: the bitangent is sign·N×T); `None` without tangents.
    fn tangent_frame(&self, s: &Surface, mesh: &Mesh) -> Option<(Vec3, Vec3)> {
        if mesh.tangents.is_empty() {
            return None;
        }
        let [a, b, c] = s.vertices;
        let w = s.barycentrics;
        let tangent = w.x * mesh.tangents[a] + w.y * mesh.tangents[b] + w.z * mesh.tangents[c];
        let frame = &self.frames[s.instance];
        let n = s.shading_normal;
        let t = frame.world_from_object.matrix3 * tangent.truncate();
        let t = (t - n * n.dot(t)).try_normalize()?;
        // A mirroring instance transform flips the bitangent's handedness.
        let handedness =
            mesh.tangents[a].w.signum() * frame.world_from_object.matrix3.determinant().signum();
        Some((t, handedness * n.cross(t)))
    }

    /// The direction of anisotropy at `s` (`KHR_materials_anisotropy`): the texture's RG
    /// direction in the tangent frame (default +T), turned by the rotation towards the
    /// bitangent; the texture's blue scales the strength in `pbr`. `None` without tangents
    /// (the lobes then keep an arbitrary axis).
    fn anisotropy_direction(
        &self,
        s: &Surface,
        mesh: &Mesh,
        pbr: &mut Pbr,
        lookup: impl Fn(&TextureRef, ColorSpace) -> Vec4,
    ) -> Option<Vec3> {
        let (t, b) = self.tangent_frame(s, mesh)?;
        let mut direction = Vec2::X;
        if let Some(r) = &self.scene.materials[s.material].textures.anisotropy {
            let texel = lookup(r, ColorSpace::Linear);
            direction = Vec2::new(2.0 * texel.x - 1.0, 2.0 * texel.y - 1.0)
                .try_normalize()
                .unwrap_or(Vec2::X);
            pbr.anisotropy.strength *= texel.z;
        }
        let turned = Vec2::from_angle(pbr.anisotropy.rotation).rotate(direction);
        Some(turned.x * t + turned.y * b)
    }

    /// The shading normal bent by a tangent-space normal-map texel (glTF: RGB = XYZ in
    /// [-1, 1], X along the tangent, Y along sign·N×T, XY scaled by `scale`).
    fn normal_mapped(&self, s: &Surface, mesh: &Mesh, texel: Vec4, scale: f32) -> Vec3 {
        let n = s.shading_normal;
        let Some((t, bitangent)) = self.tangent_frame(s, mesh) else {
            return n;
        };
        let m = Vec3::new(
            (2.0 * texel.x - 1.0) * scale,
            (2.0 * texel.y - 1.0) * scale,
            2.0 * texel.z - 1.0,
        );
        (m.x * t + m.y * bitangent + m.z * n)
            .try_normalize()
            .unwrap_or(n)
    }
}

/// The shading normal `n` raised towards the geometric normal `ng` (both on the side of
/// `wo`) just enough that the mirror reflection of `wo` leaves the surface at least as
/// steeply as min(0.9·cos θo, 0.01) above it; `n` itself when it already does. Normal maps
/// and coarse smooth shading tilt normals away from the viewer, whose glossy lobes would
/// otherwise reflect into the surface and render black. This is Cycles' rule
/// (`ensure_valid_specular_reflection`, bsdf_util.h): in the plane of `ng` and `n`, with
/// a = Ix² + Iz², b = 2(a + Iz·t), c = (Iz + t)², the raised normal's height solves
/// 4a·Nz⁴ − 2b·Nz² + c = 0, the root chosen by the sign of Ix.
pub fn valid_reflection_normal(ng: Vec3, wo: Vec3, n: Vec3) -> Vec3 {
    let reflected = 2.0 * n.dot(wo) * n - wo;
    let iz = wo.dot(ng).max(0.0);
    let threshold = (0.9 * iz).min(0.01);
    if ng.dot(reflected) >= threshold {
        return n;
    }
    let x = (n - n.dot(ng) * ng).try_normalize().unwrap_or(n);
    let ix = wo.dot(x);
    let a = ix * ix + iz * iz;
    let b = 2.0 * (a + iz * threshold);
    let c = (threshold + iz) * (threshold + iz);
    if a <= 0.0 {
        return n;
    }
    let root = (b * b - 4.0 * a * c).max(0.0).sqrt();
    let nz2 = (if ix < 0.0 { b + root } else { b - root }) * 0.25 / a;
    let nx = (1.0 - nz2).max(0.0).sqrt();
    (nx * x + nz2.max(0.0).sqrt() * ng)
        .try_normalize()
        .unwrap_or(ng)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The raised normal lifts the mirror reflection to the threshold and no further, stays
    /// in the plane of the two normals, and leaves a normal that already reflects above the
    /// surface alone.
    #[test]
    fn raised_normals_reflect_just_above_the_surface() {
        let ng = Vec3::Z;
        for (tilt_degrees, view_degrees) in [(45.0f32, 30.0f32), (15.0, 80.0), (60.0, 0.0)] {
            let (tilt, view) = (tilt_degrees.to_radians(), view_degrees.to_radians());
            // The normal leans away from the viewer, who looks from +x.
            let n = Vec3::new(-tilt.sin(), 0.0, tilt.cos());
            let wo = Vec3::new(view.sin(), 0.0, view.cos());
            let raised = valid_reflection_normal(ng, wo, n);
            let reflected = 2.0 * raised.dot(wo) * raised - wo;
            let threshold = (0.9 * wo.z).min(0.01);
            let before = (2.0 * n.dot(wo) * n - wo).z;
            if before >= threshold {
                assert_eq!(raised, n);
                continue;
            }
            assert!((raised.length() - 1.0).abs() < 1e-5);
            assert!(raised.y.abs() < 1e-6, "{raised}");
            assert!(
                (reflected.z - threshold).abs() < 1e-3,
                "tilt {tilt_degrees}°, view {view_degrees}°: {reflected}"
            );
            assert!(raised.dot(wo) > 0.0);
        }
        let straight = Vec3::new(0.1, 0.0, 1.0).normalize();
        assert_eq!(valid_reflection_normal(ng, Vec3::Z, straight), straight);
    }
}
