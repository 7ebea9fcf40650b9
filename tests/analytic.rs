//! Scenes whose radiance has a closed form: irradiance from a rectangular emitter, an ideal
//! mirror, a glass slab, and a closed enclosure in radiative equilibrium that no object may
//! disturb. Each is checked for all three direct-light strategies where they differ.

#[path = "support/estimates/mod.rs"]
mod estimates;
#[path = "support/shapes/mod.rs"]
mod shapes;

use estimates::{assert_matches, estimate, estimate_with};
use glam::{Affine3A, DVec3, Vec3};
use gridtrace::accel::Ray;
use gridtrace::render::{
    NextEvent, NextEventOdds, Outcome, PathOptions, RenderSettings, Renderer, Strategy,
};
use gridtrace::scene::{
    AlphaMode, Light, LightKind, Material, Pbr, Scene, SceneBuilder, Texture, TextureRef,
};
use shapes::{add_box_inside, add_box_outside, add_quad, add_sphere, camera_at};

const STRATEGIES: [Strategy; 3] = [Strategy::Mis, Strategy::LightOnly, Strategy::BsdfOnly];

/// Configuration factor from a differential area to a parallel rectangle of sides `a` × `b`
/// at distance `h`, with the normal through one corner (Howell, *A Catalog of Radiation Heat
/// Transfer Configuration Factors*, case B-3).
fn corner_factor(a: f64, b: f64, h: f64) -> f64 {
    let (x, y) = (a / h, b / h);
    let (sx, sy) = ((1.0 + x * x).sqrt(), (1.0 + y * y).sqrt());
    ((x / sx) * (y / sx).atan() + (y / sy) * (x / sy).atan()) / (2.0 * std::f64::consts::PI)
}

/// Factor from a point to the rectangle [x0, x1] × [z0, z1] at height `h` above it, by adding
/// and subtracting corner rectangles with signed sides.
fn rectangle_factor(x0: f64, x1: f64, z0: f64, z1: f64, h: f64) -> f64 {
    let signed = |x: f64, z: f64| x.signum() * z.signum() * corner_factor(x.abs(), z.abs(), h);
    signed(x1, z1) - signed(x0, z1) - signed(x1, z0) + signed(x0, z0)
}

/// A Lambertian floor of albedo ρ at y = 0 under a downward-facing square emitter of
/// radiance L at height `LIGHT_HEIGHT`: the scene.
fn floor_under_a_square_light(albedo: f32, radiance: Vec3, half: f32) -> Scene {
    let mut b = SceneBuilder::new();
    let floor = b.add_material(Material::diffuse("floor", Vec3::splat(albedo)));
    let light = b.add_material(Material {
        double_sided: false,
        ..Material::diffuse("light", Vec3::ZERO).with_emission(radiance)
    });
    let v = Vec3::new;
    add_quad(
        &mut b,
        [
            v(-20., 0., -20.),
            v(-20., 0., 20.),
            v(20., 0., 20.),
            v(20., 0., -20.),
        ],
        floor,
    );
    let h = LIGHT_HEIGHT;
    add_quad(
        &mut b,
        [
            v(-half, h, -half),
            v(half, h, -half),
            v(half, h, half),
            v(-half, h, half),
        ],
        light,
    );
    b.build()
}

const LIGHT_HEIGHT: f32 = 1.0;

/// Points of the floor under the square light, and the floor's radiance there: ρ/π · E
/// with E = π·L·F, F the configuration factor to the emitter; with the ray that looks at
/// each from the side, below the light's height. Under the centre, under a corner and well
/// outside the light's footprint.
fn floor_points(albedo: f32, radiance: Vec3, half: f32) -> Vec<(Vec3, Ray, DVec3)> {
    [(0.0f32, 0.0f32), (half, half), (1.3, -0.7)]
        .into_iter()
        .map(|(x, z)| {
            let (x0, x1) = ((-half - x) as f64, (half - x) as f64);
            let (z0, z1) = ((-half - z) as f64, (half - z) as f64);
            let factor = rectangle_factor(x0, x1, z0, z1, LIGHT_HEIGHT as f64);
            let expected = radiance.as_dvec3() * albedo as f64 * factor;
            let target = Vec3::new(x, 0.0, z);
            let origin = target + Vec3::new(4.0, 0.5, 0.3);
            (target, Ray::new(origin, target - origin), expected)
        })
        .collect()
}

/// The floor under a square light has the radiance of the configuration factor.
#[test]
fn floor_under_a_rectangular_light_matches_the_configuration_factor() {
    let (albedo, radiance, half) = (0.6f32, Vec3::new(3.0, 2.0, 1.0), 0.4f32);
    let scene = floor_under_a_square_light(albedo, radiance, half);
    for (target, ray, expected) in floor_points(albedo, radiance, half) {
        for strategy in STRATEGIES {
            let estimate = estimate(&scene, ray, strategy, 200_000);
            assert_matches(
                &format!("floor at {target}, {strategy:?}"),
                estimate,
                expected,
                0.02,
            );
        }
    }
}

/// Next-event roulette leaves every estimator unbiased: with odds taught that no light
/// sample ever reaches the floor (wrongly), the floor under the light still has the
/// radiance of the configuration factor — light samples are taken rarely and weighed up,
/// and MIS counts the odds in the light's density.
#[test]
fn next_event_roulette_with_wrong_odds_keeps_the_floor_exact() {
    let (albedo, radiance, half) = (0.6f32, Vec3::new(3.0, 2.0, 1.0), 0.4f32);
    let scene = floor_under_a_square_light(albedo, radiance, half);
    let mut outcomes = Vec::new();
    for i in 0..80 {
        for j in 0..80 {
            let point = Vec3::new(i as f32 / 20.0 - 2.0, 0.0, j as f32 / 20.0 - 2.0);
            outcomes.push(Outcome {
                point,
                reached: false,
            });
        }
    }
    let odds = NextEventOdds::learn(outcomes);
    for (target, ray, expected) in floor_points(albedo, radiance, half) {
        assert!(
            odds.at(target) < 1.0,
            "the odds at {target} are not lowered"
        );
        for strategy in STRATEGIES {
            let options = PathOptions {
                next_event: NextEvent::Roulette(&odds),
                ..PathOptions::plain(64, strategy)
            };
            let estimate = estimate_with(&scene, ray, options, 200_000);
            assert_matches(
                &format!("floor at {target}, {strategy:?}, roulette"),
                estimate,
                expected,
                0.03,
            );
        }
    }
}

/// A Lambertian floor at y = 0 lit by punctual lights alone: its radiance is ρ/π · E, with
/// E = I·cos θ / d² for a point or spot light (times the spot's falloff) and E = E⊥·cos θ for a
/// directional light. Every path gets the same direct light, so the only noise left is the
/// choice between lights. (The floor is small because a directional light's power, and so
/// how often it is picked, grows with the scene's area.)
#[test]
fn floor_under_punctual_lights_gets_inverse_square_cosine_irradiance() {
    let albedo = 0.7f32;
    let floor_scene = |lights: &[LightKind], area_light: Option<Vec3>| {
        let mut b = SceneBuilder::new();
        let floor = b.add_material(Material::diffuse("floor", Vec3::splat(albedo)));
        let v = Vec3::new;
        add_quad(
            &mut b,
            [
                v(-4., 0., -4.),
                v(-4., 0., 4.),
                v(4., 0., 4.),
                v(4., 0., -4.),
            ],
            floor,
        );
        if let Some(radiance) = area_light {
            let light = b.add_material(Material {
                double_sided: false,
                ..Material::diffuse("light", Vec3::ZERO).with_emission(radiance)
            });
            // Off to the side, so it shadows none of the punctual lights at the test point.
            let (h, s, c) = (1.0, 0.4, -1.5);
            add_quad(
                &mut b,
                [
                    v(c - s, h, -s),
                    v(c + s, h, -s),
                    v(c + s, h, s),
                    v(c - s, h, s),
                ],
                light,
            );
        }
        for (i, &kind) in lights.iter().enumerate() {
            b.add_light(Light {
                name: format!("light {i}"),
                kind,
                source: "test".into(),
            });
        }
        b.build()
    };
    let view = |x: f32, z: f32| {
        let target = Vec3::new(x, 0.0, z);
        let origin = target + Vec3::new(4.0, 0.5, 0.3);
        Ray::new(origin, target - origin)
    };
    let intensity = Vec3::new(5.0, 3.0, 1.0);
    let position = Vec3::new(0.3, 2.0, -0.2);
    let point = LightKind::Point {
        position,
        intensity,
        range: None,
    };
    let (inner, outer) = (20f32.to_radians(), 30f32.to_radians());
    let spot = LightKind::Spot {
        position,
        direction: Vec3::NEG_Y,
        intensity,
        cos_inner: inner.cos(),
        cos_outer: outer.cos(),
        range: None,
    };
    let sun_direction = Vec3::new(1.0, -2.0, 0.5).normalize();
    let irradiance = Vec3::new(2.0, 2.5, 3.0);
    let sun = LightKind::Directional {
        direction: sun_direction,
        irradiance,
    };

    // E at floor point (x, z) from a light at `position` shining with `i` towards it.
    let inverse_square = |x: f32, z: f32, falloff: f32| {
        let to_light = position - Vec3::new(x, 0.0, z);
        let d = to_light.length();
        (intensity * falloff * (to_light.y / d) / (d * d)).as_dvec3()
    };
    let rho_over_pi = albedo as f64 / std::f64::consts::PI;
    for strategy in STRATEGIES {
        let scene = floor_scene(&[point], None);
        for (x, z) in [(0.3, -0.2), (1.5, 0.7), (-2.0, -1.0)] {
            let expected = rho_over_pi * inverse_square(x, z, 1.0);
            let (mean, _) = estimate(&scene, view(x, z), strategy, 64);
            assert!(
                (mean / expected - 1.0).abs().max_element() < 1e-4,
                "point at ({x}, {z}), {strategy:?}: {mean} vs {expected}"
            );
        }
        let scene = floor_scene(&[spot], None);
        // Angles off the spot's axis: inside the inner cone, in the falloff, outside.
        for degrees in [10.0f32, 25.0, 40.0] {
            let r = position.y * degrees.to_radians().tan();
            let (x, z) = (position.x + r, position.z);
            let t = ((degrees.to_radians().cos() - outer.cos()) / (inner.cos() - outer.cos()))
                .clamp(0.0, 1.0);
            let expected = rho_over_pi * inverse_square(x, z, t * t);
            let (mean, _) = estimate(&scene, view(x, z), strategy, 64);
            assert!(
                (mean - expected).abs().max_element() < 1e-4 * expected.max_element().max(1e-3),
                "spot at {degrees}°, {strategy:?}: {mean} vs {expected}"
            );
        }
        let scene = floor_scene(&[sun], None);
        let expected = rho_over_pi * (irradiance * -sun_direction.y).as_dvec3();
        let (mean, _) = estimate(&scene, view(1.0, 1.0), strategy, 64);
        assert!(
            (mean / expected - 1.0).abs().max_element() < 1e-4,
            "sun, {strategy:?}: {mean} vs {expected}"
        );

        // All three with an area light: the light choice is random now, the sum must hold.
        let radiance = Vec3::new(3.0, 2.0, 1.0);
        let scene = floor_scene(&[point, spot, sun], Some(radiance));
        let (x, z) = (0.5, 0.1);
        let area = radiance.as_dvec3()
            * albedo as f64
            * rectangle_factor(-1.9 - 0.5, -1.1 - 0.5, -0.4 - 0.1, 0.4 - 0.1, 1.0);
        let r = (Vec3::new(x, 0.0, z) - position).length();
        let spot_cos = (position.y / r).clamp(-1.0, 1.0);
        let t = ((spot_cos - outer.cos()) / (inner.cos() - outer.cos())).clamp(0.0, 1.0);
        let expected = area
            + rho_over_pi * (inverse_square(x, z, 1.0) + inverse_square(x, z, t * t))
            + rho_over_pi * (irradiance * -sun_direction.y).as_dvec3();
        let estimate = estimate(&scene, view(x, z), strategy, 200_000);
        assert_matches(
            &format!("all lights, {strategy:?}"),
            estimate,
            expected,
            0.01,
        );
    }
}

/// Unpolarised Fresnel reflectance of a smooth interface from outside (index 1) into index
/// `eta` at incidence angle θ (Hecht, *Optics*, §4.6.2), written out independently of the
/// renderer's own.
fn fresnel(cos_i: f64, eta: f64) -> f64 {
    let sin_t = (1.0 - cos_i * cos_i).sqrt() / eta;
    let cos_t = (1.0 - sin_t * sin_t).sqrt();
    let rs = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    let rp = (cos_t - eta * cos_i) / (cos_t + eta * cos_i);
    0.5 * (rs * rs + rp * rp)
}

/// A large emitter of radiance `radiance` in the plane z = `z`, facing +Z, that emits only.
fn add_backdrop(b: &mut SceneBuilder, z: f32, radiance: Vec3) {
    let light = b.add_material(Material {
        double_sided: false,
        ..Material::diffuse("backdrop", Vec3::ZERO).with_emission(radiance)
    });
    let v = |x: f32, y: f32| Vec3::new(x, y, z);
    add_quad(
        b,
        [v(-50., -50.), v(50., -50.), v(50., 50.), v(-50., 50.)],
        light,
    );
}

/// A smooth conductor of F0 = ρ shows a uniform emitter at exactly F·L, with Schlick's
/// F = ρ + (1 − ρ)(1 − cos θ)⁵ at the 45° the camera ray meets it.
#[test]
fn mirror_reflects_its_reflectance_times_the_radiance() {
    let (reflectance, radiance) = (Vec3::new(0.9, 0.5, 0.2), Vec3::new(1.0, 2.0, 3.0));
    let mut b = SceneBuilder::new();
    add_backdrop(&mut b, -3.0, radiance);
    let mirror = b.add_material(Material::new("mirror", Pbr::mirror(reflectance)));
    // A mirror in the plane x = z, facing (1, 0, 1)/√2: rays along −X turn to −Z.
    let v = Vec3::new;
    add_quad(
        &mut b,
        [
            v(-1., -1., -1.),
            v(1., -1., 1.),
            v(1., 1., 1.),
            v(-1., 1., -1.),
        ],
        mirror,
    );
    let scene = b.build();
    let ray = Ray::new(v(5.0, 0.1, 0.0), v(-1.0, 0.0, 0.0));
    let schlick = (1.0 - std::f32::consts::FRAC_1_SQRT_2).powi(5);
    let fresnel = reflectance + (Vec3::ONE - reflectance) * schlick;
    let expected = (fresnel * radiance).as_dvec3();
    for strategy in STRATEGIES {
        let (mean, _) = estimate(&scene, ray, strategy, 16);
        assert!(
            (mean - expected).abs().max_element() < 1e-5,
            "{strategy:?}: {mean} vs {expected}"
        );
    }
}

/// A glass slab of index η and transmission tint t in front of a uniform emitter: each face
/// reflects F (unpolarised Fresnel) and transmits 1 − F, and light bounces between the faces
/// any number of times, so the transmitted radiance is L·t·(1 − F)²·Σ F^2k
/// = L·t·(1 − F)/(1 + F): each crossing tints by √t, so one way through tints by t.
#[test]
fn glass_slab_transmits_the_fresnel_series() {
    let (eta, radiance) = (1.5f32, Vec3::new(2.0, 1.0, 0.5));
    for tint in [Vec3::ONE, Vec3::new(0.9, 0.7, 0.4)] {
        let mut b = SceneBuilder::new();
        add_backdrop(&mut b, -5.0, radiance);
        let glass = b.add_material(Material::new("glass", Pbr::glass(eta, tint)));
        // A 40 × 40 × 0.5 slab: the box [-1, 1]³ wound outwards, squashed in z.
        add_box_outside(
            &mut b,
            glass,
            Affine3A::from_scale(Vec3::new(20.0, 20.0, 0.25)),
        );
        let scene = b.build();
        for degrees in [0.0f32, 30.0, 60.0] {
            let theta = degrees.to_radians();
            let direction = Vec3::new(theta.sin(), 0.0, -theta.cos());
            let ray = Ray::new(Vec3::new(0.0, 0.0, 2.0) - 2.0 * direction, direction);
            let f = fresnel(theta.cos() as f64, eta as f64);
            let expected = (radiance * tint).as_dvec3() * (1.0 - f) / (1.0 + f);
            for strategy in STRATEGIES {
                let estimate = estimate(&scene, ray, strategy, 200_000);
                assert_matches(
                    &format!("slab at {degrees}°, tint {tint}, {strategy:?}"),
                    estimate,
                    expected,
                    0.005,
                );
            }
        }
    }
}

/// Radiative equilibrium: inside a closed box whose walls emit (1 − a)·L* and reflect with
/// albedo a, radiance is L* everywhere. Any object whose emission is (1 − ρ)·L* for its
/// reflectance ρ leaves that equilibrium alone, and so does lossless glass, which emits
/// nothing: every pixel must show L*, whatever it looks at. More would be energy created,
/// less energy lost (a wrong Fresnel branch, a missing η² or a bad MIS weight shows here).
#[test]
fn objects_in_radiative_equilibrium_are_invisible() {
    let equilibrium = 1.0f32;
    let emitting = |name: &str, pbr: Pbr, reflectance: f32| Material {
        emission: Vec3::splat((1.0 - reflectance) * equilibrium),
        ..Material::new(name, pbr)
    };
    let mut b = SceneBuilder::new();
    let walls = b.add_material(emitting("walls", Pbr::diffuse(Vec3::splat(0.5)), 0.5));
    let diffuse = b.add_material(emitting("diffuse", Pbr::diffuse(Vec3::splat(0.9)), 0.9));
    // A white conductor reflects everything at every angle, so it emits nothing.
    let mirror = b.add_material(emitting("mirror", Pbr::mirror(Vec3::ONE), 1.0));
    let glass = b.add_material(Material::new("glass", Pbr::glass(1.5, Vec3::ONE)));
    add_box_inside(&mut b, walls);
    add_sphere(&mut b, Vec3::new(-0.45, -0.4, -0.4), 0.35, diffuse);
    add_sphere(&mut b, Vec3::new(0.45, -0.4, -0.4), 0.35, mirror);
    add_sphere(&mut b, Vec3::new(0.0, 0.4, -0.3), 0.4, glass);
    let scene = b.build();
    let renderer = Renderer::new(&scene);
    for strategy in STRATEGIES {
        let settings = RenderSettings {
            width: 32,
            height: 32,
            samples: 0..256,
            max_depth: 1000,
            seed: 5,
            strategy,
            ..RenderSettings::default()
        };
        let (image, stats) = renderer.render(&camera_at(0.9, 70.0), &settings, &|| {});
        assert_eq!(stats.nonfinite, 0);
        // Pixels are independent estimates; compare 8×8 blocks with their spread.
        for by in 0..4 {
            for bx in 0..4 {
                let values: Vec<f64> = (0..64)
                    .map(|i| image.pixel(bx * 8 + i % 8, by * 8 + i / 8).x as f64)
                    .collect();
                let mean = values.iter().sum::<f64>() / 64.0;
                let stderr =
                    (values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / 63.0 / 64.0).sqrt();
                assert!(
                    (mean - equilibrium as f64).abs() < 5.0 * stderr.max(1e-6),
                    "{strategy:?}, block ({bx}, {by}): {mean:.4} ± {stderr:.4}, expected {equilibrium}"
                );
            }
        }
        let mean = image.mean();
        assert!(
            (mean - Vec3::splat(equilibrium)).abs().max_element() < 0.01,
            "{strategy:?}: image mean {mean}"
        );
    }
}

/// Alpha in front of an emitter: a black surface with alpha α blended stochastically shows
/// (1 − α)·L; a cutout shows L where alpha is under the cutoff and black elsewhere.
#[test]
fn alpha_blend_and_cutout_let_the_right_share_through() {
    let radiance = Vec3::new(1.0, 2.0, 3.0);
    for (mode, alpha, through) in [
        (AlphaMode::Blend, 0.25f32, 0.75f64),
        (AlphaMode::Mask { cutoff: 0.5 }, 0.2, 1.0),
        (AlphaMode::Mask { cutoff: 0.5 }, 0.8, 0.0),
    ] {
        let mut b = SceneBuilder::new();
        add_backdrop(&mut b, -3.0, radiance);
        let veil = b.add_material(Material {
            alpha,
            alpha_mode: mode,
            ..Material::diffuse("veil", Vec3::ZERO)
        });
        let v = Vec3::new;
        add_quad(
            &mut b,
            [
                v(-2., -2., 0.),
                v(2., -2., 0.),
                v(2., 2., 0.),
                v(-2., 2., 0.),
            ],
            veil,
        );
        let scene = b.build();
        let ray = Ray::new(v(0.1, 0.2, 2.0), v(0.0, 0.0, -1.0));
        let expected = radiance.as_dvec3() * through;
        for strategy in STRATEGIES {
            let (mean, stderr) = estimate(&scene, ray, strategy, 100_000);
            for c in 0..3 {
                assert!(
                    (mean[c] - expected[c]).abs() <= 4.0 * stderr[c] + 1e-6,
                    "{mode:?} α={alpha}, {strategy:?}: {mean} ± {stderr}, expected {expected}"
                );
            }
        }
    }
}

/// Beer–Lambert inside glass: with A = exp(−σ·d) along the path through a slab of
/// thickness d at normal incidence, the Fresnel series becomes
/// L·(1 − F)²·A / (1 − F²·A²).
#[test]
fn absorbing_glass_slab_follows_beer_lambert() {
    let (eta, radiance) = (1.5f32, Vec3::new(2.0, 1.0, 0.5));
    let sigma = Vec3::new(0.2, 1.0, 3.0);
    let thickness = 0.5f32;
    let mut b = SceneBuilder::new();
    add_backdrop(&mut b, -5.0, radiance);
    let glass = b.add_material(Material {
        absorption: sigma,
        ..Material::new("glass", Pbr::glass(eta, Vec3::ONE))
    });
    add_box_outside(
        &mut b,
        glass,
        Affine3A::from_scale(Vec3::new(20.0, 20.0, 0.5 * thickness)),
    );
    let scene = b.build();
    let ray = Ray::new(Vec3::new(0.1, 0.2, 3.0), Vec3::NEG_Z);
    let f = fresnel(1.0, eta as f64);
    let a = (-sigma.as_dvec3() * thickness as f64).exp();
    let expected = radiance.as_dvec3() * (1.0 - f) * (1.0 - f) * a / (DVec3::ONE - f * f * a * a);
    for strategy in STRATEGIES {
        let estimate = estimate(&scene, ray, strategy, 200_000);
        assert_matches(
            &format!("absorbing slab, {strategy:?}"),
            estimate,
            expected,
            0.005,
        );
    }
}

/// Vertex colours multiply the albedo: the floor under the square light, coloured.
#[test]
fn vertex_colours_multiply_the_albedo() {
    let (albedo, radiance, colour) = (
        0.6f32,
        Vec3::splat(2.0),
        glam::Vec4::new(0.5, 1.0, 0.25, 1.0),
    );
    let mut b = SceneBuilder::new();
    let floor = b.add_material(Material {
        vertex_colours: true,
        ..Material::diffuse("floor", Vec3::splat(albedo))
    });
    let light = b.add_material(Material {
        double_sided: false,
        ..Material::diffuse("light", Vec3::ZERO).with_emission(radiance)
    });
    let v = Vec3::new;
    let mesh = add_floor(&mut b, 20.0, floor);
    add_quad(
        &mut b,
        [
            v(-0.4, 1., -0.4),
            v(0.4, 1., -0.4),
            v(0.4, 1., 0.4),
            v(-0.4, 1., 0.4),
        ],
        light,
    );
    let mut scene = b.build();
    scene.meshes[mesh].colours = vec![colour; 4];
    let target = v(0.0, 0.0, 0.0);
    let origin = target + v(4.0, 0.5, 0.3);
    let factor = rectangle_factor(-0.4, 0.4, -0.4, 0.4, 1.0);
    let expected = (radiance * albedo * colour.truncate()).as_dvec3() * factor;
    let estimate = estimate(
        &scene,
        Ray::new(origin, target - origin),
        Strategy::Mis,
        100_000,
    );
    assert_matches("coloured floor", estimate, expected, 0.02);
}

/// A square floor of half-side `half` in the plane y = 0, facing +Y, as one mesh with its
/// own instance (so that per-vertex attributes can be set on it); returns the mesh.
fn add_floor(b: &mut SceneBuilder, half: f32, material: usize) -> usize {
    let v = |x: f32, z: f32| Vec3::new(x, 0.0, z);
    let mesh = b.add_mesh(
        "floor",
        vec![
            v(-half, -half),
            v(-half, half),
            v(half, half),
            v(half, -half),
        ],
        vec![[0, 1, 2], [0, 2, 3]],
        material,
    );
    b.add_instance(mesh, Affine3A::IDENTITY, "floor");
    mesh
}

/// Builds `b` with a 10 × 10 floor of `material` facing +Y, with UVs along (x, z) (u along
/// +X, v along +Z: down the image, so the image's up is −Z) and tangents along +X, and a
/// 1 × 1 texture encoding the tangent-space normal `mapped` as glTF does; returns the scene
/// and the texture for a normal-map slot.
fn normal_mapped_floor(mut b: SceneBuilder, material: usize, mapped: Vec3) -> (Scene, usize) {
    let mesh = add_floor(&mut b, 5.0, material);
    let encoded = (0.5 * mapped + Vec3::splat(0.5)) * 65535.0;
    let texture = b.add_texture(Texture {
        name: "tilt".into(),
        width: 1,
        height: 1,
        texels: vec![[
            encoded.x.round() as u16,
            encoded.y.round() as u16,
            encoded.z.round() as u16,
            65535,
        ]],
        tiles: Vec::new(),
    });
    let mut scene = b.build();
    let m = &mut scene.meshes[mesh];
    m.uvs = vec![
        m.positions
            .iter()
            .map(|p| glam::Vec2::new(p.x, p.z))
            .collect(),
    ];
    m.tangents = vec![glam::Vec4::new(1.0, 0.0, 0.0, 1.0); 4];
    (scene, texture)
}

/// A constant normal map tilts the shading normal by a known angle: under a directional
/// light the floor's radiance is ρ/π · E · (n′·l) · G1 for the tilted n′, G1 being the
/// bump-terminator shadowing of the mapped surface (Conty Estevez et al. 2019, as Cycles):
/// 2/(1 + √(1 + α²·tan²θ)) with α² = tan²(tilt)/8 and θ between l and the smooth normal.
/// Tilting along the red channel turns the normal towards the tangent (+u); along green,
/// towards the image's up (−v in glTF's downward-v texture space).
#[test]
fn a_constant_normal_map_tilts_the_shading_normal() {
    let albedo = 0.5f32;
    let irradiance = Vec3::splat(2.0);
    let tilt = 30f32.to_radians();
    // (tangent-space normal, direction the light travels): each case lit at 15° off n′.
    let cases = [
        (
            Vec3::new(tilt.sin(), 0.0, tilt.cos()),
            Vec3::new(-1.0, -1.0, 0.0),
        ),
        (
            Vec3::new(0.0, tilt.sin(), tilt.cos()),
            Vec3::new(0.0, -1.0, 1.0),
        ),
    ];
    for (mapped, travel) in cases {
        let mut b = SceneBuilder::new();
        let floor = b.add_material(Material::diffuse("floor", Vec3::splat(albedo)));
        let v = Vec3::new;
        b.add_light(Light {
            name: "sun".into(),
            kind: LightKind::Directional {
                direction: travel.normalize(),
                irradiance,
            },
            source: "test".into(),
        });
        let (mut scene, texture) = normal_mapped_floor(b, floor, mapped);
        scene.materials[floor].textures.normal = Some(TextureRef::new(texture));
        scene.materials[floor].textures.normal_scale = 1.0;
        // The world normal: T = +X, B = w·N×T = −Z, N = +Y.
        let n = (mapped.x * Vec3::X + mapped.y * Vec3::NEG_Z + mapped.z * Vec3::Y).normalize();
        let l = -travel.normalize();
        let alpha2 = tilt.tan().powi(2) / 8.0;
        let tan2 = 1.0 / l.y.powi(2) - 1.0;
        let shadowing = 2.0 / (1.0 + (1.0 + alpha2 * tan2).sqrt());
        let expected =
            (irradiance * albedo / std::f32::consts::PI * n.dot(l) * shadowing).as_dvec3();
        let target = v(0.2, 0.0, 0.1);
        let ray = Ray::new(target + v(0.3, 2.0, 0.4), v(-0.3, -2.0, -0.4));
        let (mean, _) = estimate(&scene, ray, Strategy::Mis, 16);
        assert!(
            (mean / expected - 1.0).abs().max_element() < 1e-3,
            "tilt {mapped}: {mean} vs {expected} (unmapped would be {})",
            expected * (Vec3::Y.dot(l) / (n.dot(l) * shadowing)) as f64
        );
    }
}

/// A convex Lambertian polyhedron (a flat-shaded sphere) under a uniform environment of
/// radiance L receives E = πL at every point and sees nothing else, so it shows ρ·L; rays
/// that miss see L.
#[test]
fn a_diffuse_sphere_under_a_uniform_sky_shows_albedo_times_sky() {
    let (albedo, sky) = (0.6f32, Vec3::new(1.0, 2.0, 0.5));
    let mut b = SceneBuilder::new();
    let white = b.add_material(Material::diffuse("ball", Vec3::splat(albedo)));
    add_sphere(&mut b, Vec3::ZERO, 1.0, white);
    b.add_environment(sky);
    let mut scene = b.build();
    // Flat facets: with interpolated normals a cosine lobe around the shading normal pokes
    // below the facet, and the true answer is a little under ρ·L.
    scene.meshes[0].normals.clear();
    for strategy in STRATEGIES {
        let on_ball = Ray::new(Vec3::new(0.2, 0.1, 5.0), Vec3::new(0.0, 0.0, -1.0));
        let expected = (sky * albedo).as_dvec3();
        let on_ball = estimate(&scene, on_ball, strategy, 100_000);
        assert_matches(&format!("ball, {strategy:?}"), on_ball, expected, 0.01);
        let past = Ray::new(Vec3::new(3.0, 0.0, 5.0), Vec3::new(0.0, 0.0, -1.0));
        let (mean, _) = estimate(&scene, past, strategy, 4);
        assert_eq!(mean, sky.as_dvec3(), "{strategy:?}");
    }
}

/// A clear coat's own normal map (`clearcoatNormalTexture`) tilts the coat alone: a smooth
/// coat over a black base under a uniform sky shows F(wo·n′)·L_sky, with n′ the mapped coat
/// normal and F the exact Fresnel reflectance of index 1.5 — not F(wo·n).
#[test]
fn a_coat_normal_map_tilts_the_coat() {
    let sky = Vec3::new(1.0, 2.0, 0.5);
    let tilt = 30f32.to_radians();
    let mapped = Vec3::new(tilt.sin(), 0.0, tilt.cos());
    let mut b = SceneBuilder::new();
    let floor = b.add_material(Material::new(
        "coat",
        Pbr {
            base_colour: Vec3::ZERO,
            metallic: 0.0,
            specular: 0.0,
            clearcoat: 1.0,
            clearcoat_roughness: 0.0,
            ..Pbr::default()
        },
    ));
    let v = Vec3::new;
    b.add_environment(sky);
    let (mut scene, texture) = normal_mapped_floor(b, floor, mapped);
    scene.materials[floor].textures.clearcoat_normal = Some(TextureRef::new(texture));
    scene.materials[floor].textures.clearcoat_normal_scale = 1.0;
    // T = +X, B = −Z, N = +Y: the coat normal leans towards +X.
    let n = (mapped.x * Vec3::X + mapped.z * Vec3::Y).normalize();
    // Seen at 71° from the floor's normal, 41° from the coat's.
    let direction = v(-2.0, -0.7, 0.0);
    let wo = -direction.normalize();
    let expected = sky.as_dvec3() * fresnel(wo.dot(n) as f64, 1.5);
    let untilted = sky.as_dvec3() * fresnel(wo.dot(Vec3::Y) as f64, 1.5);
    let target = v(0.2, 0.0, 0.1);
    let (mean, _) = estimate(
        &scene,
        Ray::new(target - direction, direction),
        Strategy::Mis,
        16,
    );
    assert!(
        (mean / expected - 1.0).abs().max_element() < 1e-3,
        "{mean} vs {expected} (an untilted coat would show {untilted})"
    );
    assert!((untilted / expected).x > 2.0, "the tilt must matter here");
}
