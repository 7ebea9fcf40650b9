//! Auxiliary layers: albedo, normal and depth against what the scene says analytically,
//! directly and through a mirror; and layers of split renders merging like the beauty.

#[path = "support/binary/mod.rs"]
mod binary;
#[path = "support/shapes/mod.rs"]
mod shapes;

use std::path::Path;

use glam::{Affine3A, Vec2, Vec3};
use gridtrace::output::merge::MERGE_TOLERANCE;
use gridtrace::output::read_exr_pixels;
use gridtrace::render::{AovSet, Image, RayGenerator, RenderSettings, Renderer};
use gridtrace::scene::{
    Camera, Filter, Material, Mesh, Pbr, Scene, SceneBuilder, Texture, TextureRef,
};
use shapes::{add_quad, add_sphere, camera_at};

const SIZE: u32 = 48;

/// A 4×4 texture of four 2×2 blocks: red, green, blue and sRGB mid-grey.
fn checker() -> Texture {
    let full = 65535u16;
    let grey = 32768u16;
    let colour = |col: u32, row: u32| match (col / 2, row / 2) {
        (0, 0) => [full, 0, 0, full],
        (1, 0) => [0, full, 0, full],
        (0, 1) => [0, 0, full, full],
        _ => [grey, grey, grey, full],
    };
    Texture {
        name: "checker".into(),
        width: 4,
        height: 4,
        texels: (0..16).map(|i| colour(i % 4, i / 4)).collect(),
        tiles: Vec::new(),
    }
}

/// The linear colour of the checker at texture coordinates `uv` (v down the image), by the
/// sRGB transfer function (IEC 61966-2-1), computed here, not by the renderer's decoder.
fn checker_at(uv: Vec2) -> Vec3 {
    let srgb = |c: f32| {
        if c <= 0.04045 {
            c / 12.92
        } else {
            ((c + 0.055) / 1.055).powf(2.4)
        }
    };
    let grey = srgb(32768.0 / 65535.0);
    match ((uv.x * 2.0).floor() as i32, (uv.y * 2.0).floor() as i32) {
        (0, 0) => Vec3::X,
        (1, 0) => Vec3::Y,
        (0, 1) => Vec3::Z,
        _ => Vec3::splat(grey),
    }
}

/// The textured Lambertian square [-1, 1]² in the plane z = `z` (facing +Z), with u along
/// +X and v along −Y, through nearest-texel lookups.
fn add_textured_square(b: &mut SceneBuilder, transform: Affine3A) {
    let texture = b.add_texture(checker());
    let mut material = Material::diffuse("checker", Vec3::ONE);
    let mut lookup = TextureRef::new(texture);
    lookup.filter = Filter::Nearest;
    material.textures.base_colour = Some(lookup);
    let material = b.add_material(material);
    let positions = vec![
        Vec3::new(-1.0, -1.0, 0.0),
        Vec3::new(1.0, -1.0, 0.0),
        Vec3::new(1.0, 1.0, 0.0),
        Vec3::new(-1.0, 1.0, 0.0),
    ];
    let indices = vec![[0, 1, 2], [0, 2, 3]];
    let uvs = positions.iter().map(|p| square_uv(*p)).collect();
    let mesh = b.add_full_mesh(Mesh {
        name: "square".into(),
        normals: Mesh::compute_vertex_normals(&positions, &indices),
        positions,
        uvs: vec![uvs],
        colours: Vec::new(),
        tangents: Vec::new(),
        indices,
        material,
    });
    b.add_instance(mesh, transform, "square");
}

/// The square's texture coordinates at a point of its plane (object space).
fn square_uv(p: Vec3) -> Vec2 {
    Vec2::new((p.x + 1.0) / 2.0, (1.0 - p.y) / 2.0)
}

fn render_aovs(scene: &Scene, camera: &Camera, spp: u32) -> Image {
    let renderer = Renderer::new(scene);
    let settings = RenderSettings {
        width: SIZE,
        height: SIZE,
        samples: 0..spp,
        aovs: AovSet::ALL,
        ..RenderSettings::default()
    };
    renderer.render(camera, &settings, &|| {}).0
}

/// What a ray sees of the square (in object space through `object_from_world`): its
/// object-space point and the distance along the ray, if it hits.
fn hit_square(origin: Vec3, direction: Vec3, object_from_world: Affine3A) -> Option<(Vec3, f32)> {
    let o = object_from_world.transform_point3(origin);
    let d = object_from_world.transform_vector3(direction.normalize());
    let t = -o.z / d.z;
    let p = o + t * d;
    (t > 0.0 && p.x.abs() < 1.0 && p.y.abs() < 1.0).then_some((p, t))
}

/// For each pixel whose four corners' rays (after `bend`, which maps a camera ray to the
/// ray that reaches the square and the distance already travelled) all land in one texel
/// block of the square: (pixel index, expected albedo, expected depth at the centre).
fn covered_pixels(
    camera: &Camera,
    square: Affine3A,
    bend: impl Fn(Vec3, Vec3) -> Option<(Vec3, Vec3, f32)>,
) -> Vec<(usize, Vec3, f32)> {
    let generator = RayGenerator::new(camera, SIZE, SIZE);
    let object_from_world = square.inverse();
    let look = |x: f32, y: f32| {
        let ray = generator.generate_through_lens(x, y, Vec2::splat(0.5), 0.0);
        let (origin, direction, before) = bend(ray.origin, ray.direction)?;
        hit_square(origin, direction, object_from_world).map(|(p, t)| (p, t + before))
    };
    let mut pixels = Vec::new();
    for y in 0..SIZE {
        for x in 0..SIZE {
            let corners: Option<Vec<Vec3>> = [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0)]
                .iter()
                .map(|(dx, dy)| look(x as f32 + dx, y as f32 + dy).map(|h| h.0))
                .collect();
            let Some(corners) = corners else { continue };
            let colours: Vec<Vec3> = corners.iter().map(|p| checker_at(square_uv(*p))).collect();
            if colours.iter().any(|c| *c != colours[0]) {
                continue;
            }
            let (_, depth) = look(x as f32 + 0.5, y as f32 + 0.5).unwrap();
            pixels.push(((y * SIZE + x) as usize, colours[0], depth));
        }
    }
    pixels
}

/// Checks albedo (exactly the texel colour), depth (within 0.2 % of the centre's: the
/// distance varies that little across a pixel here), normal (the square's) and coverage.
fn check_square(image: &Image, expected: &[(usize, Vec3, f32)], normal: Vec3) {
    assert!(
        expected.len() > 300,
        "only {} pixels to check",
        expected.len()
    );
    let aovs = &image.aovs;
    for &(i, albedo, depth) in expected {
        let got = aovs.albedo.as_ref().unwrap()[i];
        assert!(
            (got - albedo).abs().max_element() < 1e-4,
            "pixel {i}: albedo {got}, texture {albedo}"
        );
        let d = aovs.depth.as_ref().unwrap()[i];
        assert!(
            (d / depth - 1.0).abs() < 2e-3,
            "pixel {i}: depth {d}, expected {depth}"
        );
        let n = aovs.normal.as_ref().unwrap()[i];
        assert!(
            (n - normal).length() < 1e-4,
            "pixel {i}: normal {n}, expected {normal}"
        );
        assert_eq!(aovs.coverage.as_ref().unwrap()[i], 1.0);
    }
}

#[test]
fn albedo_depth_and_normal_of_a_textured_plane_are_its_texture_distance_and_normal() {
    let mut b = SceneBuilder::new();
    add_textured_square(&mut b, Affine3A::IDENTITY);
    let scene = b.build();
    let camera = camera_at(2.0, 50.0);
    let image = render_aovs(&scene, &camera, 8);
    let expected = covered_pixels(&camera, Affine3A::IDENTITY, |o, d| Some((o, d, 0.0)));
    check_square(&image, &expected, Vec3::Z);
    // The camera sees all four colours.
    for colour in [Vec3::X, Vec3::Y, Vec3::Z] {
        assert!(expected.iter().any(|e| e.1 == colour), "{colour} not seen");
    }
}

#[test]
fn through_a_mirror_the_layers_show_the_mirrored_surface() {
    // The camera looks down −Z at a mirror tilted 45° about X, which sends its rays down
    // −Y onto the square lying at y = −3 facing up.
    let mut b = SceneBuilder::new();
    let mirror = b.add_material(Material {
        pbr: Pbr::mirror(Vec3::ONE),
        ..Material::diffuse("mirror", Vec3::ONE)
    });
    let s = 3.0f32;
    let (c, h) = (Vec3::new(0.0, 0.0, -2.0), std::f32::consts::FRAC_1_SQRT_2);
    // Mirror normal (0, −h, h): faces the camera (+Z) and the floor (−Y).
    let (u, v) = (Vec3::X * s, Vec3::new(0.0, h, h) * s);
    add_quad(&mut b, [c - u - v, c + u - v, c + u + v, c - u + v], mirror);
    let square = Affine3A::from_translation(Vec3::new(0.0, -3.0, -2.0))
        * Affine3A::from_rotation_x(-std::f32::consts::FRAC_PI_2);
    add_textured_square(&mut b, square);
    let scene = b.build();
    let camera = camera_at(2.0, 30.0);
    let image = render_aovs(&scene, &camera, 8);
    let normal = Vec3::new(0.0, -h, h);
    let expected = covered_pixels(&camera, square, |o, d| {
        // Reflect in the mirror plane through c.
        let d = d.normalize();
        let t = (c - o).dot(normal) / d.dot(normal);
        (t > 0.0).then(|| {
            let p = o + t * d;
            (p, d - 2.0 * d.dot(normal) * normal, t)
        })
    });
    check_square(&image, &expected, Vec3::Y);
}

#[test]
fn normals_of_a_sphere_are_its_analytic_normals() {
    let mut b = SceneBuilder::new();
    let grey = b.add_material(Material::diffuse("grey", Vec3::splat(0.5)));
    add_sphere(&mut b, Vec3::ZERO, 1.0, grey);
    let scene = b.build();
    let camera = camera_at(3.0, 45.0);
    let image = render_aovs(&scene, &camera, 16);
    let generator = RayGenerator::new(&camera, SIZE, SIZE);
    // Where a ray meets the unit sphere (nearest root), if it does with some margin.
    let meet = |x: f32, y: f32, radius: f32| {
        let ray = generator.generate_through_lens(x, y, Vec2::splat(0.5), 0.0);
        let d = ray.direction.normalize();
        let b = ray.origin.dot(d);
        let disc = b * b - (ray.origin.length_squared() - radius * radius);
        (disc > 0.0).then(|| ray.origin + (-b - disc.sqrt()) * d)
    };
    let (mut checked, mut worst) = (0, 0.0f32);
    for y in 0..SIZE {
        for x in 0..SIZE {
            let inside = [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0)]
                .iter()
                .all(|(dx, dy)| meet(x as f32 + dx, y as f32 + dy, 0.97).is_some());
            if !inside {
                continue;
            }
            let expected = meet(x as f32 + 0.5, y as f32 + 0.5, 1.0)
                .unwrap()
                .normalize();
            let got = image.aovs.normal.as_ref().unwrap()[(y * SIZE + x) as usize];
            worst = worst.max((got - expected).length());
            checked += 1;
        }
    }
    // The sphere is 16 × 32 flat-ish facets with interpolated normals: their normals
    // differ from the true sphere's by up to ~0.05 in the middle of a facet.
    assert!(checked > 400, "{checked}");
    assert!(worst < 0.06, "largest normal difference {worst}");
}

#[test]
fn layers_of_parts_merge_like_the_beauty() {
    let dir = tempfile::tempdir().unwrap();
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/cornell_box.glb");
    let run = |extra: &[&str]| {
        let mut args = vec![
            scene.to_str().unwrap(),
            "--width",
            "24",
            "--aov",
            "all",
            "-q",
        ];
        args.extend_from_slice(extra);
        let out = binary::gridtrace(&args, dir.path());
        assert!(out.status.success(), "{}", binary::stderr(&out));
    };
    run(&["--samples", "0..5", "-o", "a.exr"]);
    run(&["--samples", "5..12", "-o", "b.exr"]);
    run(&["--spp", "12", "-o", "whole.exr"]);
    let out = binary::gridtrace(&["merge", "b.exr", "a.exr", "-o", "merged.exr"], dir.path());
    assert!(out.status.success(), "{}", binary::stderr(&out));
    let read = |name: &str| read_exr_pixels(&dir.path().join(name)).unwrap();
    let (merged, whole) = (read("merged.exr"), read("whole.exr"));
    let close = |a: f32, b: f32, relative: f32| (a - b).abs() <= relative * a.abs().max(b.abs());
    let close3 = |a: Vec3, b: Vec3, relative: f32| (0..3).all(|c| close(a[c], b[c], relative));
    let (m, w) = (&merged.aovs, &whole.aovs);
    assert_eq!(m.set(), AovSet::ALL);
    for i in 0..merged.rgb.len() {
        assert!(close3(merged.rgb[i], whole.rgb[i], MERGE_TOLERANCE));
        let (mp, wp) = (m.pixel(i), w.pixel(i));
        for (a, b) in [
            (mp.albedo, wp.albedo),
            (mp.normal, wp.normal),
            (mp.position, wp.position),
        ] {
            assert!(
                (a - b).abs().max_element() <= 4e-7 * b.abs().max_element().max(1.0),
                "{i}: {a} {b}"
            );
        }
        assert!(close(mp.depth, wp.depth, MERGE_TOLERANCE), "{i}");
        assert_eq!(mp.coverage, wp.coverage);
        // Variance is rebuilt from f32 means and variances: exact up to the cancellation of
        // Σx² − n·mean², which costs about mean²/variance units in the last place.
        let mean = whole.rgb[i];
        for c in 0..3 {
            let slack = 4.0 * f32::EPSILON * (mean[c] * mean[c] * 12.0 / 11.0 + wp.variance[c]);
            assert!(
                (mp.variance[c] - wp.variance[c]).abs() <= slack + 1e-6 * wp.variance[c],
                "{i}: variance {} vs {}",
                mp.variance[c],
                wp.variance[c]
            );
        }
    }
}

#[test]
fn a_part_with_more_channels_than_gridtrace_writes_is_refused_before_its_pixels() {
    use exr::prelude::*;
    let dir = tempfile::tempdir().unwrap();
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/cornell_box.glb");
    let out = binary::gridtrace(
        &[
            scene.to_str().unwrap(),
            "--width",
            "8",
            "--spp",
            "1",
            "-q",
            "-o",
            "part.exr",
        ],
        dir.path(),
    );
    assert!(out.status.success(), "{}", binary::stderr(&out));
    let header = gridtrace::output::read_exr_header(&dir.path().join("part.exr")).unwrap();
    let record = &header.text["gridtrace/record"];
    // The same record over 40 channels of 8×8 zeros.
    let channels: Vec<AnyChannel<FlatSamples>> = (0..40)
        .map(|c| {
            AnyChannel::new(
                format!("layer{c}.Y").as_str(),
                FlatSamples::F32(vec![0.0; 64]),
            )
        })
        .collect();
    let layer = Layer::new(
        (8, 8),
        LayerAttributes::default(),
        Encoding::default(),
        AnyChannels::sort(channels.into()),
    );
    let mut image = exr::image::Image::from_layer(layer);
    image.attributes.other.insert(
        Text::from("gridtrace/record"),
        AttributeValue::Text(Text::from(record.as_str())),
    );
    image.write().to_file(dir.path().join("wide.exr")).unwrap();
    let err = gridtrace::output::merge::read_part(&dir.path().join("wide.exr")).unwrap_err();
    assert!(err.to_string().contains("40 channels"), "{err}");
}
