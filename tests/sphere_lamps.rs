//! Sphere lamps (lamps with a radius, not part of the meshes) against closed forms: a
//! uniformly bright sphere of radiance L and radius r whose centre is at distance d, seen
//! wholly above a surface's horizon at angle α from its normal, gives it the irradiance
//! π·L·(r/d)²·cos α; a spot cone scales that by its falloff seen from the centre. Every
//! direct-light strategy must agree, and camera rays pass a lamp the camera does not see.

#[path = "support/estimates/mod.rs"]
mod estimates;
#[path = "support/shapes/mod.rs"]
mod shapes;

use glam::Vec3;
use gridtrace::accel::Ray;
use gridtrace::render::Strategy;
use gridtrace::scene::{Light, LightKind, Material, SceneBuilder};

use estimates::{assert_matches, estimate};
use shapes::add_quad;

const STRATEGIES: [Strategy; 3] = [Strategy::Mis, Strategy::LightOnly, Strategy::BsdfOnly];

/// A 20 × 20 Lambertian floor of albedo ρ at y = 0 under one sphere lamp.
fn floor_under(lamp: LightKind, albedo: f32) -> gridtrace::scene::Scene {
    let mut b = SceneBuilder::new();
    let m = b.add_material(Material::diffuse("floor", Vec3::splat(albedo)));
    let v = |x: f32, z: f32| Vec3::new(x, 0.0, z);
    add_quad(
        &mut b,
        [
            v(-10.0, -10.0),
            v(-10.0, 10.0),
            v(10.0, 10.0),
            v(10.0, -10.0),
        ],
        m,
    );
    b.add_light(Light {
        name: "lamp".into(),
        kind: lamp,
        source: "test".into(),
    });
    b.build()
}

fn lamp(position: Vec3, spot: Option<(Vec3, f32, f32)>, camera_visible: bool) -> LightKind {
    LightKind::Sphere {
        position,
        radius: 0.3,
        radiance: Vec3::new(20.0, 10.0, 5.0),
        spot,
        camera_visible,
        soft: false,
    }
}

/// The floor's radiance at `x` on the floor under a sphere of radius 0.3 and radiance
/// (20, 10, 5) at `center`: ρ/π · π·L·(r/d)²·cos α.
fn expected(albedo: f32, center: Vec3, x: Vec3) -> Vec3 {
    let to = center - x;
    let d = to.length();
    let cos_alpha = to.y / d;
    albedo * Vec3::new(20.0, 10.0, 5.0) * (0.3 / d).powi(2) * cos_alpha
}

#[test]
fn a_floor_under_a_sphere_lamp_gets_its_cap_irradiance() {
    let center = Vec3::new(0.0, 1.5, 0.0);
    let scene = floor_under(lamp(center, None, false), 0.5);
    for x in [Vec3::ZERO, Vec3::new(1.2, 0.0, -0.7)] {
        let ray = Ray::new(x + Vec3::new(0.05, 3.0, 0.6), Vec3::new(-0.05, -3.0, -0.6));
        for strategy in STRATEGIES {
            let n = if strategy == Strategy::BsdfOnly {
                1_000_000
            } else {
                40_000
            };
            let result = estimate(&scene, ray, strategy, n);
            let want = expected(0.5, center, x).as_dvec3();
            assert_matches(&format!("at {x}, {strategy:?}"), result, want, 0.01);
        }
    }
}

/// Blender's Soft Falloff makes the lamp a disc of its radius facing the lit point: the
/// disc subtends sin²θ = r²/(d² + r²), so the floor's radiance is ρ·L·r²/(d² + r²)·cos α,
/// softer than the ball's ρ·L·(r/d)²·cos α close to the lamp; every strategy agrees.
#[test]
fn a_soft_falloff_lamp_lights_as_a_disc_facing_the_floor() {
    let center = Vec3::new(0.0, 0.5, 0.0);
    let soft = LightKind::Sphere {
        position: center,
        radius: 0.3,
        radiance: Vec3::new(20.0, 10.0, 5.0),
        spot: None,
        camera_visible: false,
        soft: true,
    };
    let scene = floor_under(soft, 0.5);
    for x in [Vec3::ZERO, Vec3::new(0.6, 0.0, -0.3)] {
        let to = center - x;
        let d2 = to.length_squared();
        let want = 0.5 * Vec3::new(20.0, 10.0, 5.0) * 0.09 / (d2 + 0.09) * (to.y / d2.sqrt());
        let ray = Ray::new(x + Vec3::new(0.05, 3.0, 0.6), Vec3::new(-0.05, -3.0, -0.6));
        for strategy in STRATEGIES {
            let n = if strategy == Strategy::BsdfOnly {
                1_000_000
            } else {
                40_000
            };
            let result = estimate(&scene, ray, strategy, n);
            assert_matches(
                &format!("soft, at {x}, {strategy:?}"),
                result,
                want.as_dvec3(),
                0.01,
            );
        }
    }
}

/// The glTF spot falloff of light leaving in direction `wo`, for a cone about −Y.
fn falloff(wo: Vec3, cos_inner: f32, cos_outer: f32) -> f64 {
    let t = ((wo.dot(Vec3::NEG_Y) - cos_outer) / (cos_inner - cos_outer)).clamp(0.0, 1.0);
    (t * t) as f64
}

/// A spot cone (inner 20°, outer 40° about straight down) scales the light each direction
/// carries: the floor's radiance is ρ/π ∫ L·falloff(−ω)·cos α dω over the lamp's cap, by
/// quadrature — full inside the inner cone, dark beyond the outer, in between across it.
#[test]
fn a_spot_sphere_lamp_fades_across_its_cone() {
    let center = Vec3::new(0.0, 2.0, 0.0);
    let (cos_inner, cos_outer) = (20f32.to_radians().cos(), 40f32.to_radians().cos());
    let scene = floor_under(
        lamp(center, Some((Vec3::NEG_Y, cos_inner, cos_outer)), false),
        0.5,
    );
    for angle in [10f32, 27.0, 33.0, 55.0] {
        let x = Vec3::new(2.0 * angle.to_radians().tan(), 0.0, 0.0);
        let axis = (center - x).normalize();
        let frame = gridtrace::render::sampling::Frame::from_normal(axis);
        let sin_max = 0.3 / center.distance(x);
        let cos_max = (1.0 - sin_max * sin_max).sqrt();
        let (n_t, n_p) = (400, 400);
        let mut integral = 0.0f64;
        for i in 0..n_t {
            let cos = 1.0 - (1.0 - cos_max) * (i as f32 + 0.5) / n_t as f32;
            let sin = (1.0 - cos * cos).sqrt();
            for j in 0..n_p {
                let phi = std::f32::consts::TAU * (j as f32 + 0.5) / n_p as f32;
                let w = frame.to_world(Vec3::new(sin * phi.cos(), sin * phi.sin(), cos));
                let d_omega = (1.0 - cos_max) as f64 * std::f64::consts::TAU / (n_t * n_p) as f64;
                integral += falloff(-w, cos_inner, cos_outer) * w.y as f64 * d_omega;
            }
        }
        let want = Vec3::new(20.0, 10.0, 5.0).as_dvec3() * (0.5 / std::f64::consts::PI) * integral;
        let ray = Ray::new(x + Vec3::new(0.0, 1.0, 1.0), Vec3::new(0.0, -1.0, -1.0));
        let result = estimate(&scene, ray, Strategy::Mis, 40_000);
        if integral == 0.0 {
            assert_eq!(result.0, want, "outside the cone");
        } else {
            assert_matches(&format!("{angle}° off the axis"), result, want, 0.01);
        }
    }
}

/// A camera ray through a lamp hidden from the camera sees the floor behind it; one the
/// camera sees adds its radiance on top. Either way the floor below is lit, not shadowed:
/// lamps are not geometry, the ray goes on through them.
#[test]
fn camera_rays_pass_hidden_lamps_and_see_visible_ones() {
    let center = Vec3::new(0.0, 1.5, 0.0);
    let ray = Ray::new(center + Vec3::new(0.0, 2.0, 0.0), Vec3::NEG_Y);
    let below = expected(0.5, center, Vec3::ZERO).as_dvec3();
    for visible in [false, true] {
        let scene = floor_under(lamp(center, None, visible), 0.5);
        let (through, _) = estimate(&scene, ray, Strategy::Mis, 40_000);
        let seen = if visible {
            Vec3::new(20.0, 10.0, 5.0).as_dvec3()
        } else {
            glam::DVec3::ZERO
        };
        let floor = through - seen;
        assert!(
            (floor / below - glam::DVec3::ONE).abs().max_element() < 0.02,
            "visible {visible}: {through}, floor {below}"
        );
    }
}
