//! Environment maps as lights: every direct-light strategy converges to the irradiance
//! integral of the map, light-only, BSDF-only and MIS agree, and MIS beats both single
//! strategies on a map with a sun in it.

#[path = "support/estimates/mod.rs"]
mod estimates;
#[path = "support/shapes/mod.rs"]
mod shapes;

use glam::{DVec3, Vec2, Vec3};
use gridtrace::accel::Ray;
use gridtrace::render::Strategy;
use gridtrace::scene::{
    Environment, EnvironmentMap, Material, Pbr, Scene, SceneBuilder, blender_world_rotation,
    map_direction,
};

use estimates::{assert_matches, estimate};
use shapes::{add_quad, add_sphere};

/// A `width × height` map whose texels, by their world direction under `rotation`, hold a
/// sky brightening towards the zenith, a dim ground and, in the one texel nearest `sun`,
/// `sun_radiance`.
fn sky_with_sun(
    width: u32,
    height: u32,
    sun: Vec3,
    sun_radiance: f32,
    rotation: f32,
) -> Environment {
    let world_from_map = blender_world_rotation(rotation);
    let directions: Vec<Vec3> = (0..width * height)
        .map(|i| {
            let uv = Vec2::new(
                ((i % width) as f32 + 0.5) / width as f32,
                ((i / width) as f32 + 0.5) / height as f32,
            );
            world_from_map * map_direction(uv)
        })
        .collect();
    let sun = sun.normalize();
    let nearest = (0..directions.len())
        .max_by(|&a, &b| directions[a].dot(sun).total_cmp(&directions[b].dot(sun)))
        .unwrap();
    let texels = directions
        .iter()
        .enumerate()
        .map(|(i, d)| {
            if i == nearest {
                [sun_radiance, 0.9 * sun_radiance, 0.7 * sun_radiance]
            } else if d.y > 0.0 {
                [0.3 + 0.5 * d.y, 0.4 + 0.6 * d.y, 0.6 + 0.8 * d.y]
            } else {
                [0.1, 0.08, 0.05]
            }
        })
        .collect();
    let map = EnvironmentMap {
        name: "sky".into(),
        width,
        height,
        texels,
    };
    Environment::from_map(map, Vec3::ONE, world_from_map, "test sky")
}

/// Irradiance on an upward-facing point: ∫ L(ω) cos θ dω over the upper hemisphere, by the
/// midpoint rule on a fine grid of (cos θ, φ), where equal cells have equal solid angle.
fn irradiance_from_above(environment: &Environment) -> DVec3 {
    let (n_mu, n_phi) = (2000, 4000);
    let cell = 2.0 * std::f64::consts::PI / (n_mu * n_phi) as f64;
    let mut sum = DVec3::ZERO;
    for i in 0..n_mu {
        let mu = (i as f64 + 0.5) / n_mu as f64;
        let r = (1.0 - mu * mu).sqrt();
        for j in 0..n_phi {
            let phi = std::f64::consts::TAU * (j as f64 + 0.5) / n_phi as f64;
            let d = Vec3::new((r * phi.cos()) as f32, mu as f32, (r * phi.sin()) as f32);
            sum += environment.radiance(d).as_dvec3() * mu * cell;
        }
    }
    sum
}

/// A small upward-facing square of `material` at the origin under `environment`.
fn floor_under(environment: Environment, material: Material) -> Scene {
    let mut b = SceneBuilder::new();
    let m = b.add_material(material);
    let v = |x: f32, z: f32| Vec3::new(x, 0.0, z);
    add_quad(
        &mut b,
        [v(-0.5, -0.5), v(-0.5, 0.5), v(0.5, 0.5), v(0.5, -0.5)],
        m,
    );
    b.set_environment(environment);
    b.build()
}

/// A Lambertian floor of albedo ρ under a map shows ρ/π · E, with E the cosine-weighted
/// integral of the map over the sky, for every strategy; a ray that misses sees the map.
#[test]
fn a_diffuse_floor_under_a_map_shows_its_cosine_weighted_integral() {
    let albedo = 0.5f32;
    let environment = sky_with_sun(32, 16, Vec3::new(0.6, 0.5, -0.3), 400.0, 30.0);
    let expected = irradiance_from_above(&environment) * (albedo as f64 / std::f64::consts::PI);
    let scene = floor_under(
        environment.clone(),
        Material::diffuse("floor", Vec3::splat(albedo)),
    );
    let ray = Ray::new(Vec3::new(0.1, 2.0, 0.05), Vec3::NEG_Y);
    for (strategy, n) in [
        (Strategy::Mis, 100_000),
        (Strategy::LightOnly, 100_000),
        (Strategy::BsdfOnly, 1_000_000),
    ] {
        let result = estimate(&scene, ray, strategy, n);
        assert_matches(&format!("floor, {strategy:?}"), result, expected, 0.01);
    }
    let up = Vec3::new(0.3, 1.0, -0.2).normalize();
    let (seen, _) = estimate(
        &scene,
        Ray::new(Vec3::new(3.0, 0.0, 0.0), up),
        Strategy::Mis,
        2,
    );
    assert_eq!(seen, environment.radiance(up).as_dvec3());
}

/// White furnace through the map's own sampling (not the constant path): a convex white
/// Lambertian ball in a uniform map reflects all it receives, E = πL, so it shows exactly
/// the sky's radiance L and is invisible against it, for every strategy.
#[test]
fn a_white_ball_in_a_uniform_map_disappears() {
    let (albedo, sky) = (1.0f32, [1.0f32, 2.0, 0.5]);
    let map = EnvironmentMap {
        name: "uniform".into(),
        width: 8,
        height: 4,
        texels: vec![sky; 32],
    };
    let mut b = SceneBuilder::new();
    let white = b.add_material(Material::diffuse("ball", Vec3::splat(albedo)));
    add_sphere(&mut b, Vec3::ZERO, 1.0, white);
    b.set_environment(Environment::from_map(
        map,
        Vec3::ONE,
        blender_world_rotation(75.0),
        "uniform",
    ));
    let mut scene = b.build();
    // Flat facets, so the cosine lobe stays above each facet (see the constant-sky test).
    scene.meshes[0].normals.clear();
    let ray = Ray::new(Vec3::new(0.2, 0.1, 5.0), Vec3::NEG_Z);
    let expected = (Vec3::from(sky) * albedo).as_dvec3();
    for strategy in [Strategy::Mis, Strategy::LightOnly, Strategy::BsdfOnly] {
        let result = estimate(&scene, ray, strategy, 100_000);
        assert_matches(&format!("ball, {strategy:?}"), result, expected, 0.01);
    }
}

/// Glossy plastic (a 4 % layer of roughness 0.2 over a diffuse base) under a sky with a
/// sun: light sampling finds the sun for the diffuse base, BSDF sampling finds the sky in
/// the sharp reflection, and MIS must do better than either alone. Variances are of one
/// path's estimate along a fixed ray; the three means must agree.
#[test]
fn mis_beats_light_and_bsdf_sampling_on_a_sunny_map() {
    let environment = sky_with_sun(64, 32, Vec3::new(0.7, 0.6, 0.2), 1000.0, 0.0);
    let plastic = Material::new(
        "plastic",
        Pbr {
            base_colour: Vec3::splat(0.5),
            metallic: 0.0,
            roughness: 0.2,
            ..Pbr::default()
        },
    );
    let scene = floor_under(environment, plastic);
    // At 45°, the mirror direction looks at the sky towards −Z, far from the sun.
    let ray = Ray::new(Vec3::new(0.0, 1.0, 1.0), Vec3::new(0.0, -1.0, -1.0));
    let n = 200_000;
    let run = |strategy| {
        let (mean, stderr) = estimate(&scene, ray, strategy, n);
        let variance = (stderr * stderr * n as f64).element_sum() / 3.0;
        (mean, stderr, variance)
    };
    let (mis, light, bsdf) = (
        run(Strategy::Mis),
        run(Strategy::LightOnly),
        run(Strategy::BsdfOnly),
    );
    println!(
        "per-path variance: MIS {:.4}, light only {:.4} ({:.1}×), BSDF only {:.4} ({:.1}×)",
        mis.2,
        light.2,
        light.2 / mis.2,
        bsdf.2,
        bsdf.2 / mis.2
    );
    for (name, other) in [("light only", light), ("BSDF only", bsdf)] {
        let gap = (mis.0 - other.0).abs();
        let tolerance = 4.0 * (mis.1 * mis.1 + other.1 * other.1).map(f64::sqrt) + 1e-5;
        assert!(
            gap.cmple(tolerance).all(),
            "MIS {} vs {name} {}",
            mis.0,
            other.0
        );
        assert!(
            mis.2 < other.2,
            "MIS variance {} not below {name}'s {}",
            mis.2,
            other.2
        );
    }
}
