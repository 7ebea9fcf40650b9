//! The integrator converges to the right answer: light sampling, BSDF sampling and MIS
//! agree; a closed furnace matches its closed form; images do not depend on thread count.

#[path = "support/shapes/mod.rs"]
mod shapes;

use glam::{Affine3A, Vec3};
use gridtrace::load::load_scene;
use gridtrace::render::{Guiding, Image, RenderSettings, Renderer, Strategy};
use gridtrace::scene::{
    Camera, Instance, Material, Motion, Pbr, Scene, SceneBuilder, SheenModel, TimeSlice,
};
use shapes::{add_box_inside, add_quad, add_sphere, camera_at};

/// What stands in the test room besides its diffuse walls.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Contents {
    /// Nothing.
    Empty,
    /// An ideal mirror and an ideal glass sphere (delta lobes only).
    Ideal,
    /// Glossy surfaces: a rough gold panel, a coated plastic sphere with sheen, a velvet
    /// sphere (microfibre sheen), rough glass, so every non-delta lobe meets light sampling
    /// and MIS.
    Glossy,
}

/// An open-fronted diffuse box with a small ceiling light and `contents`.
fn test_room(contents: Contents) -> Scene {
    let mut b = SceneBuilder::new();
    let white = b.add_material(Material::diffuse("white", Vec3::splat(0.7)));
    let red = b.add_material(Material::diffuse("red", Vec3::new(0.7, 0.1, 0.1)));
    // One-sided and facing down: a double-sided light just under the ceiling would light a
    // thin hidden strip that only rare paths find, a heavy tail that hides real bias.
    let light = b.add_material(Material {
        double_sided: false,
        ..Material::diffuse("light", Vec3::splat(0.5)).with_emission(Vec3::new(8.0, 7.0, 5.0))
    });
    let v = |x: f32, y: f32, z: f32| Vec3::new(x, y, z);
    add_quad(
        &mut b,
        [
            v(-1., -1., -1.),
            v(-1., -1., 1.),
            v(1., -1., 1.),
            v(1., -1., -1.),
        ],
        white,
    );
    add_quad(
        &mut b,
        [
            v(-1., 1., -1.),
            v(1., 1., -1.),
            v(1., 1., 1.),
            v(-1., 1., 1.),
        ],
        white,
    );
    add_quad(
        &mut b,
        [
            v(-1., -1., -1.),
            v(1., -1., -1.),
            v(1., 1., -1.),
            v(-1., 1., -1.),
        ],
        white,
    );
    add_quad(
        &mut b,
        [
            v(-1., -1., -1.),
            v(-1., 1., -1.),
            v(-1., 1., 1.),
            v(-1., -1., 1.),
        ],
        red,
    );
    add_quad(
        &mut b,
        [
            v(1., -1., -1.),
            v(1., -1., 1.),
            v(1., 1., 1.),
            v(1., 1., -1.),
        ],
        white,
    );
    let s = 0.3;
    add_quad(
        &mut b,
        [
            v(-s, 0.99, -s),
            v(s, 0.99, -s),
            v(s, 0.99, s),
            v(-s, 0.99, s),
        ],
        light,
    );
    if contents != Contents::Empty {
        let glossy = contents == Contents::Glossy;
        let mirror = b.add_material(Material::new(
            "mirror",
            Pbr {
                roughness: if glossy { 0.4 } else { 0.0 },
                ..Pbr::mirror(Vec3::new(1.0, 0.78, 0.34))
            },
        ));
        let glass = b.add_material(Material::new(
            "glass",
            Pbr {
                roughness: if glossy { 0.3 } else { 0.0 },
                ..Pbr::glass(1.5, Vec3::ONE)
            },
        ));
        add_quad(
            &mut b,
            [
                v(-0.9, -1., -0.9),
                v(-0.3, -1., -0.9),
                v(-0.3, 0.2, -0.9),
                v(-0.9, 0.2, -0.9),
            ],
            mirror,
        );
        add_sphere(&mut b, v(0.4, -0.6, 0.1), 0.35, glass);
        if glossy {
            let plastic = b.add_material(Material::new(
                "coated plastic",
                Pbr {
                    base_colour: Vec3::new(0.2, 0.4, 0.8),
                    metallic: 0.0,
                    roughness: 0.25,
                    clearcoat: 0.8,
                    clearcoat_roughness: 0.1,
                    sheen_colour: Vec3::new(0.5, 0.4, 0.3),
                    sheen_roughness: 0.4,
                    ..Pbr::default()
                },
            ));
            add_sphere(&mut b, v(-0.45, -0.7, 0.45), 0.3, plastic);
            let velvet = b.add_material(Material::new(
                "velvet",
                Pbr {
                    base_colour: Vec3::new(0.3, 0.05, 0.1),
                    metallic: 0.0,
                    roughness: 0.7,
                    sheen_colour: Vec3::ONE,
                    sheen_roughness: 0.3,
                    sheen_model: SheenModel::Microfiber,
                    ..Pbr::default()
                },
            ));
            add_sphere(&mut b, v(0.55, -0.78, -0.55), 0.2, velvet);
        }
    }
    b.build()
}

/// Means over blocks of `block`×`block` pixels, per channel.
fn block_means(image: &Image, block: u32) -> Vec<f64> {
    let mut out = Vec::new();
    for by in 0..image.height / block {
        for bx in 0..image.width / block {
            let mut sum = Vec3::ZERO.as_dvec3();
            for y in by * block..(by + 1) * block {
                for x in bx * block..(bx + 1) * block {
                    sum += image.pixel(x, y).as_dvec3();
                }
            }
            let mean = sum / (block * block) as f64;
            out.extend([mean.x, mean.y, mean.z]);
        }
    }
    out
}

/// Mean and standard error of each block statistic over independent renders (seeds).
fn estimate(
    scene: &Scene,
    camera: &Camera,
    strategy: Strategy,
    seeds: u64,
    size: u32,
    spp: u32,
) -> (Vec<f64>, Vec<f64>) {
    estimate_guided(scene, camera, strategy, Guiding::Off, seeds, size, spp)
}

/// [`estimate`], guided or not.
fn estimate_guided(
    scene: &Scene,
    camera: &Camera,
    strategy: Strategy,
    guiding: Guiding,
    seeds: u64,
    size: u32,
    spp: u32,
) -> (Vec<f64>, Vec<f64>) {
    let renderer = Renderer::new(scene);
    let runs: Vec<Vec<f64>> = (0..seeds)
        .map(|seed| {
            let settings = RenderSettings {
                width: size,
                height: size,
                samples: 0..spp,
                max_depth: 8,
                seed,
                strategy,
                guiding,
                ..RenderSettings::default()
            };
            block_means(&renderer.render(camera, &settings, &|| {}).0, size / 4)
        })
        .collect();
    let n = runs.len() as f64;
    let k = runs[0].len();
    let mean: Vec<f64> = (0..k)
        .map(|i| runs.iter().map(|r| r[i]).sum::<f64>() / n)
        .collect();
    let stderr: Vec<f64> = (0..k)
        .map(|i| {
            (runs.iter().map(|r| (r[i] - mean[i]).powi(2)).sum::<f64>() / (n - 1.0) / n).sqrt()
        })
        .collect();
    (mean, stderr)
}

/// Independent renders per estimate: the standard errors have SEEDS − 1 degrees of freedom.
/// BSDF-only sampling of a small light through a mirror and glass is heavy-tailed: with 16
/// seeds its standard error was under-estimated often enough that 1 in ~20 seed sets failed
/// (measured over 21 seed sets); 32 seeds passed 11 of 11.
const SEEDS: u64 = 32;
/// With 31 degrees of freedom, P(|t| > 5.5) ≈ 5·10⁻⁶ per comparison; over the 288
/// comparisons below, a correct integrator with Gaussian block means fails with
/// probability 0.15 % (heavy tails make it somewhat more).
const MAX_T: f64 = 5.5;

fn assert_agree(name: &str, a: &(Vec<f64>, Vec<f64>), b: &(Vec<f64>, Vec<f64>)) {
    let mut worst = (0.0f64, 0usize);
    for i in 0..a.0.len() {
        let sigma = (a.1[i].powi(2) + b.1[i].powi(2)).sqrt().max(1e-9);
        let z = (a.0[i] - b.0[i]).abs() / sigma;
        if z > worst.0 {
            worst = (z, i);
        }
    }
    let i = worst.1;
    assert!(
        worst.0 < MAX_T,
        "{name}: block statistic {i} differs by {:.1} standard errors: {:.5} ± {:.5} vs {:.5} ± {:.5}",
        worst.0,
        a.0[i],
        a.1[i],
        b.0[i],
        b.1[i]
    );
}

#[test]
fn light_sampling_bsdf_sampling_and_mis_converge_to_the_same_image() {
    for contents in [Contents::Empty, Contents::Ideal, Contents::Glossy] {
        let scene = test_room(contents);
        let camera = camera_at(3.4, 40.0);
        let mis = estimate(&scene, &camera, Strategy::Mis, SEEDS, 32, 16);
        let light = estimate(&scene, &camera, Strategy::LightOnly, SEEDS, 32, 16);
        let bsdf = estimate(&scene, &camera, Strategy::BsdfOnly, SEEDS, 32, 16);
        assert!(mis.0.iter().all(|&m| m > 0.0), "every block receives light");
        let name = format!("{contents:?}");
        assert_agree(&format!("{name}: MIS vs light sampling"), &mis, &light);
        assert_agree(&format!("{name}: MIS vs BSDF sampling"), &mis, &bsdf);
        assert_agree(&format!("{name}: light vs BSDF sampling"), &light, &bsdf);
        // MIS should be the least noisy of the three.
        let total = |e: &(Vec<f64>, Vec<f64>)| e.1.iter().sum::<f64>();
        assert!(
            total(&mis) < total(&bsdf),
            "MIS noise {} vs BSDF-only {}",
            total(&mis),
            total(&bsdf)
        );
    }
}

/// Guided paths converge to the unguided image, whichever way direct light is found: the
/// guide changes where directions come from, and every estimator weighs them by the
/// mixture's density.
#[test]
fn guided_light_sampling_bsdf_sampling_and_mis_converge_to_the_unguided_image() {
    for contents in [Contents::Ideal, Contents::Glossy] {
        let scene = test_room(contents);
        let camera = camera_at(3.4, 40.0);
        let unguided = estimate(&scene, &camera, Strategy::Mis, SEEDS, 32, 16);
        let name = format!("{contents:?}");
        for strategy in [Strategy::Mis, Strategy::LightOnly, Strategy::BsdfOnly] {
            let guided = estimate_guided(&scene, &camera, strategy, Guiding::On, SEEDS, 32, 16);
            assert_agree(
                &format!("{name}: unguided MIS vs guided {strategy:?}"),
                &unguided,
                &guided,
            );
        }
    }
}

/// The test room during a shutter: the ceiling light slides and turns in the second half
/// (so its mean place is not its place at mid-shutter), the floor slides,
/// and one wall is a deforming mesh in two time slices (each placed differently).
fn moving_room() -> Scene {
    let mut scene = test_room(Contents::Glossy);
    let light = scene
        .instances
        .iter()
        .position(|i| scene.materials[scene.meshes[i.mesh].material].is_emissive())
        .unwrap();
    let slide = |x: f32, turn: f32| {
        Affine3A::from_translation(Vec3::new(x, 0.0, 0.0)) * Affine3A::from_rotation_y(turn)
    };
    scene.instances[light].motion =
        Motion::from_keys(vec![slide(0.0, 0.0), slide(0.0, 0.0), slide(0.6, 0.5)]);
    scene.instances[0].motion =
        Motion::from_keys(vec![slide(0.0, 0.0), slide(0.2, 0.0), slide(0.1, 0.0)]);
    let wall = scene.instances[2].clone();
    scene.instances[2].slice = Some(TimeSlice::around_key(0, 2));
    scene.instances.push(Instance {
        world_from_object: Affine3A::from_translation(Vec3::new(0.0, 0.0, -0.2)),
        slice: Some(TimeSlice::around_key(1, 2)),
        ..wall
    });
    scene
}

#[test]
fn with_motion_blur_light_sampling_bsdf_sampling_and_mis_still_agree() {
    let scene = moving_room();
    assert!(scene.has_moving_geometry());
    let camera = camera_at(3.4, 40.0);
    let mis = estimate(&scene, &camera, Strategy::Mis, SEEDS, 32, 16);
    let light = estimate(&scene, &camera, Strategy::LightOnly, SEEDS, 32, 16);
    let bsdf = estimate(&scene, &camera, Strategy::BsdfOnly, SEEDS, 32, 16);
    assert_agree("motion: MIS vs light sampling", &mis, &light);
    assert_agree("motion: MIS vs BSDF sampling", &mis, &bsdf);
    assert_agree("motion: light vs BSDF sampling", &light, &bsdf);
    // And the blur is there: the image differs from the still room's.
    let still = estimate(
        &test_room(Contents::Glossy),
        &camera,
        Strategy::Mis,
        4,
        32,
        16,
    );
    assert!(
        still
            .0
            .iter()
            .zip(&mis.0)
            .any(|(a, b)| (a - b).abs() > 0.05)
    );
}

/// A closed box whose inward-facing walls all emit `le` and reflect with `albedo`.
fn furnace(le: f32, albedo: f32) -> Scene {
    let mut b = SceneBuilder::new();
    let wall = b.add_material(
        Material::diffuse("wall", Vec3::splat(albedo)).with_emission(Vec3::splat(le)),
    );
    add_box_inside(&mut b, wall);
    b.build()
}

/// Renders a furnace from its centre and returns the pixel mean and its standard error.
/// The furnace is grey, so one channel per pixel: pixels are independent samples.
fn furnace_mean(scene: &Scene, strategy: Strategy, seed: u64) -> (f64, f64) {
    let renderer = Renderer::new(scene);
    let settings = RenderSettings {
        width: 24,
        height: 24,
        samples: 0..64,
        max_depth: 1000,
        seed,
        strategy,
        ..RenderSettings::default()
    };
    let (image, stats) = renderer.render(&camera_at(0.0, 60.0), &settings, &|| {});
    assert_eq!(stats.nonfinite, 0);
    let values: Vec<f64> = image.pixels.iter().map(|p| p.x as f64).collect();
    let n = values.len() as f64;
    let mean = values.iter().sum::<f64>() / n;
    let stderr = (values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0) / n).sqrt();
    (mean, stderr)
}

/// Inside a closed box whose walls all emit Le and reflect with albedo a, every ray sees
/// L = Le + a·L, so L = Le / (1 − a), at every pixel.
#[test]
fn white_furnace_matches_its_closed_form() {
    for (le, albedo) in [(0.5f32, 0.6f32), (1.0, 0.9)] {
        let scene = furnace(le, albedo);
        let expected = (le / (1.0 - albedo)) as f64;
        for strategy in [Strategy::Mis, Strategy::LightOnly, Strategy::BsdfOnly] {
            let (mean, stderr) = furnace_mean(&scene, strategy, 3);
            assert!(
                (mean - expected).abs() < 4.0 * stderr,
                "Le={le}, a={albedo}, {strategy:?}: mean {mean:.4} ± {stderr:.4}, expected {expected:.4}"
            );
            assert!(
                (mean / expected - 1.0).abs() < 0.03,
                "{strategy:?}: {mean} ± {stderr} vs {expected}"
            );
        }
    }
}

#[test]
fn same_seed_same_image_whatever_the_thread_count() {
    let scene = load_scene(std::path::Path::new("tests/data/scenes/window_room.glb"))
        .unwrap()
        .scene;
    let camera = scene.cameras[0].clone();
    let renderer = Renderer::new(&scene);
    let settings = RenderSettings {
        // Large enough that some region learns a share above 0 within the first training
        // passes (at 40 × 40 none may: then guiding would change nothing).
        width: 48,
        height: 48,
        // Past the first training passes, where the guide's shares are still 0.
        samples: 0..8,
        seed: 42,
        ..Default::default()
    };
    let render = |threads: usize, settings: &RenderSettings| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| renderer.render(&camera, settings, &|| {}).0)
    };
    let one = render(1, &settings);
    let three = render(3, &settings);
    let guided = RenderSettings {
        guiding: Guiding::On,
        ..settings.clone()
    };
    let guided_one = render(1, &guided);
    let guided_three = render(3, &guided);
    let bits = |image: &Image| {
        image
            .pixels
            .iter()
            .flat_map(|p| p.to_array().map(f32::to_bits))
            .collect::<Vec<_>>()
    };
    assert_eq!(
        bits(&one),
        bits(&three),
        "1 and 3 threads give different images"
    );
    assert_eq!(
        bits(&guided_one),
        bits(&guided_three),
        "guided, 1 and 3 threads give different images"
    );
    assert_ne!(bits(&one), bits(&guided_one), "guiding changes nothing");
    // Every light sample in the room ends at the pane, so next-event roulette (on by
    // default) takes part in the renders above: it leaves out shadow rays.
    let rays = |settings: &RenderSettings| renderer.render(&camera, settings, &|| {}).1.rays;
    let every_light_sample = RenderSettings {
        next_event_roulette: false,
        ..settings.clone()
    };
    assert!(rays(&settings) < rays(&every_light_sample) * 3 / 4);
    assert!(one.mean().max_element() > 0.0);
    let other = render(
        2,
        &RenderSettings {
            seed: 43,
            ..settings
        },
    );
    assert_ne!(bits(&one), bits(&other), "the seed changes nothing");
}

#[test]
fn a_scene_without_emitters_renders_black() {
    let mut b = SceneBuilder::new();
    let white = b.add_material(Material::diffuse("white", Vec3::splat(0.8)));
    add_box_inside(&mut b, white);
    let scene = b.build();
    assert!(!scene.has_emitters());
    let renderer = Renderer::new(&scene);
    let settings = RenderSettings {
        width: 8,
        height: 8,
        samples: 0..2,
        ..Default::default()
    };
    let (image, _) = renderer.render(&camera_at(0.0, 60.0), &settings, &|| {});
    assert_eq!(image.mean(), Vec3::ZERO);
    assert!(image.alpha.iter().all(|&a| a == 1.0));
}

/// The scene with every instance scaled by `s` about the origin.
fn scaled(mut scene: Scene, s: f32) -> Scene {
    for inst in &mut scene.instances {
        inst.world_from_object = Affine3A::from_scale(Vec3::splat(s)) * inst.world_from_object;
    }
    scene
}

/// Rays leave surfaces by the hit point's rounding-error bound, which scales with the
/// coordinates; a fixed epsilon would make tiny scenes leak light and huge ones
/// self-intersect (darken). The furnace and the room must not care about their size.
#[test]
fn images_do_not_depend_on_the_scene_scale() {
    for s in [1e-3f32, 1e4] {
        let (mean, stderr) = furnace_mean(&scaled(furnace(0.5, 0.6), s), Strategy::Mis, 5);
        assert!(
            (mean - 1.25).abs() < 4.0 * stderr,
            "furnace at scale {s}: {mean:.4} ± {stderr:.4}, expected 1.25"
        );
    }
    let reference = estimate(
        &test_room(Contents::Ideal),
        &camera_at(3.4, 40.0),
        Strategy::Mis,
        SEEDS,
        32,
        16,
    );
    for s in [1e-3f32, 1e4] {
        let camera = Camera {
            world_from_camera: Affine3A::from_translation(Vec3::new(0.0, 0.0, 3.4 * s)),
            ..camera_at(0.0, 40.0)
        };
        let at_scale = estimate(
            &scaled(test_room(Contents::Ideal), s),
            &camera,
            Strategy::Mis,
            SEEDS,
            32,
            16,
        );
        assert_agree(&format!("room at scale {s} vs 1"), &reference, &at_scale);
    }
}

/// A glass ball whose metallic value comes from a texture (metallic factor 1, as glTF's
/// default, times a texel of 0) is glass wherever the texture says so, though its factors
/// alone say metal: one-sided as a loader makes such a material, it renders exactly as
/// the same glass with a factor of 0, two-sided. (Classified by its factors, its inside
/// was a one-sided metal's black back face and the ball rendered dark.)
#[test]
fn glass_made_by_a_metallic_texture_is_glass_inside_too() {
    use gridtrace::scene::{ChannelRef, Texture, TextureRef};
    let render = |textured: bool| {
        let mut b = SceneBuilder::new();
        let white = b.add_material(Material::diffuse("white", Vec3::splat(0.7)));
        let light =
            b.add_material(Material::diffuse("light", Vec3::ZERO).with_emission(Vec3::splat(4.0)));
        let glass = if textured {
            let zero = b.add_texture(Texture {
                name: "metallic 0".into(),
                width: 1,
                height: 1,
                texels: vec![[0, 65535, 0, 65535]],
                tiles: Vec::new(),
            });
            let mut material = Material::new(
                "textured glass",
                Pbr {
                    metallic: 1.0,
                    ..Pbr::glass(1.5, Vec3::ONE)
                },
            );
            material.textures.metallic = Some(ChannelRef {
                texture: TextureRef::new(zero),
                channel: 2,
            });
            material.double_sided = false;
            material
        } else {
            Material::new("glass", Pbr::glass(1.5, Vec3::ONE))
        };
        let glass = b.add_material(glass);
        let v = |x: f32, y: f32, z: f32| Vec3::new(x, y, z);
        add_quad(
            &mut b,
            [
                v(-4., -1., -4.),
                v(-4., -1., 4.),
                v(4., -1., 4.),
                v(4., -1., -4.),
            ],
            white,
        );
        add_quad(
            &mut b,
            [
                v(-1., 3., -1.),
                v(1., 3., -1.),
                v(1., 3., 1.),
                v(-1., 3., 1.),
            ],
            light,
        );
        add_sphere(&mut b, Vec3::ZERO, 0.8, glass);
        let scene = b.build();
        let settings = RenderSettings {
            width: 32,
            height: 32,
            samples: 0..16,
            ..Default::default()
        };
        Renderer::new(&scene)
            .render(&camera_at(4.0, 40.0), &settings, &|| {})
            .0
    };
    let (textured, constant) = (render(true), render(false));
    // Below the ball's centre the floor is seen through it, lit only by the few paths that
    // reach the light back through the ball: many of those 56 pixels catch one at 16
    // samples, none would behind an opaque black inside.
    let lit = (12..20)
        .flat_map(|x| (17..24).map(move |y| (x, y)))
        .filter(|&(x, y)| constant.pixel(x, y).min_element() > 0.0)
        .count();
    assert!(
        lit >= 10,
        "the floor is not seen through constant glass: {lit} of 56 pixels lit"
    );
    let differing = (0..32 * 32)
        .filter(|&i| textured.pixels[i] != constant.pixels[i])
        .count();
    assert_eq!(
        differing,
        0,
        "textured glass renders differently from constant glass in {differing} pixels \
         (means {} against {})",
        textured.mean(),
        constant.mean()
    );
}
