//! The grid must find exactly what testing every triangle finds, for closest hits and for
//! shadow queries, on random rays and on the rays most likely to break a 3D-DDA.

use glam::{Affine3A, Quat, Vec3};
use gridtrace::accel::{Grid, Ray, SceneAccel, Triangle};
use gridtrace::render::sampling::Rng;
use gridtrace::scene::{Material, SceneBuilder};

/// Closest hit by testing every triangle: (t, triangle index).
fn brute_force(triangles: &[Triangle], ray: &Ray) -> Option<(f32, u32)> {
    let mut best: Option<(f32, u32)> = None;
    for (i, tri) in triangles.iter().enumerate() {
        let t_max = best.map_or(ray.t_max, |b| b.0);
        if let Some(hit) = tri.intersect(ray, t_max) {
            best = Some((hit.t, i as u32));
        }
    }
    best
}

fn random_point(rng: &mut Rng, lo: f32, hi: f32) -> Vec3 {
    Vec3::new(rng.uniform(), rng.uniform(), rng.uniform()) * (hi - lo) + Vec3::splat(lo)
}

fn random_direction(rng: &mut Rng) -> Vec3 {
    loop {
        let d = random_point(rng, -1.0, 1.0);
        if d.length_squared() > 1e-4 && d.length_squared() <= 1.0 {
            return d.normalize();
        }
    }
}

/// A soup of triangles of many sizes, including degenerate and tiny ones.
fn triangle_soup(rng: &mut Rng, n: usize) -> Vec<Triangle> {
    (0..n)
        .map(|i| {
            let a = random_point(rng, -1.0, 1.0);
            let scale = match i % 10 {
                0 => 1e-4,
                1 => 1.5,
                _ => 0.2,
            };
            let b = a + random_direction(rng) * scale;
            match i % 37 {
                // Zero area: a repeated vertex, and three collinear vertices.
                3 => Triangle::new(a, b, b),
                5 => Triangle::new(a, b, a + 2.0 * (b - a)),
                _ => Triangle::new(a, b, a + random_direction(rng) * scale),
            }
        })
        .collect()
}

/// A closed, finely tessellated sphere: many rays cross shared edges and vertices.
fn sphere(rings: u32, segments: u32) -> Vec<Triangle> {
    let point = |r: u32, s: u32| {
        let theta = std::f32::consts::PI * r as f32 / rings as f32;
        let phi = std::f32::consts::TAU * s as f32 / segments as f32;
        Vec3::new(
            theta.sin() * phi.cos(),
            theta.cos(),
            theta.sin() * phi.sin(),
        )
    };
    let mut tris = Vec::new();
    for r in 0..rings {
        for s in 0..segments {
            let (a, b, c, d) = (
                point(r, s),
                point(r + 1, s),
                point(r + 1, s + 1),
                point(r, s + 1),
            );
            tris.push(Triangle::new(a, b, c));
            tris.push(Triangle::new(a, c, d));
        }
    }
    tris
}

/// A flat 2D grid of triangles in the plane y = 0.25 (its bounding box has no height).
fn plane(n: u32) -> Vec<Triangle> {
    let p = |i: u32, j: u32| {
        Vec3::new(
            i as f32 / n as f32 * 2.0 - 1.0,
            0.25,
            j as f32 / n as f32 * 2.0 - 1.0,
        )
    };
    let mut tris = Vec::new();
    for i in 0..n {
        for j in 0..n {
            tris.push(Triangle::new(p(i, j), p(i + 1, j), p(i + 1, j + 1)));
            tris.push(Triangle::new(p(i, j), p(i + 1, j + 1), p(i, j + 1)));
        }
    }
    tris
}

/// Rays of every awkward kind for `grid`.
fn awkward_rays(grid: &Grid, rng: &mut Rng, n: usize) -> Vec<Ray> {
    let b = grid.bounds();
    let res = grid.resolution();
    let cell = grid.cell_size();
    let lattice = |rng: &mut Rng| {
        let c = Vec3::new(
            (rng.uniform() * (res.x + 1) as f32).floor(),
            (rng.uniform() * (res.y + 1) as f32).floor(),
            (rng.uniform() * (res.z + 1) as f32).floor(),
        );
        b.min + c * cell
    };
    let center = b.center();
    let radius = b.extent().length();
    let mut rays = Vec::new();
    for i in 0..n {
        let ray = match i % 6 {
            // From a sphere around the grid towards a random point inside it.
            0 => {
                let origin = center + random_direction(rng) * radius;
                Ray::new(origin, random_point(rng, -1.0, 1.0) - origin)
            }
            // Starting inside the grid.
            1 => Ray::new(random_point(rng, -1.0, 1.0), random_direction(rng)),
            // Axis-parallel, from inside or outside.
            2 => {
                let axis = [Vec3::X, Vec3::Y, Vec3::Z, -Vec3::X, -Vec3::Y, -Vec3::Z][i / 6 % 6];
                Ray::new(random_point(rng, -1.5, 1.5), axis)
            }
            // Through a cell corner (a lattice point of the grid).
            3 => {
                let origin = center + random_direction(rng) * radius;
                Ray::new(origin, lattice(rng) - origin)
            }
            // Along a cell edge: on lattice coordinates in two axes, parallel to the third.
            4 => {
                let axis = [Vec3::X, Vec3::Y, Vec3::Z][i / 6 % 3];
                let p = lattice(rng);
                Ray::new(p - axis * 3.0, axis)
            }
            // A short segment, as shadow rays are.
            _ => {
                let origin = random_point(rng, -1.0, 1.0);
                Ray {
                    t_max: rng.uniform(),
                    ..Ray::new(origin, random_direction(rng))
                }
            }
        };
        rays.push(ray);
    }
    rays
}

fn check_grid(name: &str, triangles: Vec<Triangle>, rays_count: usize, seed: u64) {
    let grid = Grid::build(triangles.clone());
    grid.validate()
        .unwrap_or_else(|e| panic!("{name}: invalid grid: {e}"));
    let mut rng = Rng::new(seed, 99);
    let rays = awkward_rays(&grid, &mut rng, rays_count);
    let mut disagreements = Vec::new();
    let mut hits = 0;
    for ray in &rays {
        let expected = brute_force(&triangles, ray);
        let got = grid.intersect(ray).map(|h| (h.t, h.triangle));
        let same = match (expected, got) {
            (None, None) => true,
            (Some((te, _)), Some((tg, _))) => (te - tg).abs() <= 1e-6 * te.abs().max(1e-3),
            _ => false,
        };
        hits += usize::from(expected.is_some());
        if !same {
            disagreements.push(format!(
                "closest {ray:?}: brute force {expected:?}, grid {got:?}"
            ));
        }
        if grid.occluded(ray) != expected.is_some() {
            disagreements.push(format!(
                "occluded {ray:?}: brute force {}, grid {}",
                expected.is_some(),
                expected.is_none()
            ));
        }
    }
    assert!(
        disagreements.is_empty(),
        "{name}: {} disagreement(s) in {} rays, first ones:\n{}",
        disagreements.len(),
        rays.len(),
        disagreements[..disagreements.len().min(10)].join("\n")
    );
    // The test means something only if rays hit and miss.
    assert!(
        hits > rays.len() / 20 && hits < rays.len(),
        "{name}: {hits} of {} rays hit",
        rays.len()
    );
}

#[test]
fn grid_equals_brute_force_on_a_triangle_soup() {
    let mut rng = Rng::new(1, 1);
    check_grid("soup", triangle_soup(&mut rng, 3000), 30_000, 1);
}

#[test]
fn grid_equals_brute_force_on_a_closed_sphere() {
    check_grid("sphere", sphere(40, 80), 30_000, 2);
}

#[test]
fn grid_equals_brute_force_on_a_flat_plane() {
    check_grid("plane", plane(20), 20_000, 3);
}

/// A flat mesh lying exactly on a face between two layers of cells must be found from
/// both sides.
#[test]
fn grid_equals_brute_force_on_a_plane_on_a_cell_face() {
    for step in 0..20 {
        let h = 0.5 + 0.05 * step as f32;
        let mut tris = plane(20);
        let bracket = |y: f32| {
            Triangle::new(
                Vec3::new(-0.1, y, 0.0),
                Vec3::new(0.1, y, 0.0),
                Vec3::new(0.0, y, 0.1),
            )
        };
        tris.push(bracket(0.25 - h));
        tris.push(bracket(0.25 + h));
        let grid = Grid::build(tris.clone());
        if grid.resolution().y.is_multiple_of(2) {
            check_grid("plane on a cell face", tris, 20_000, 6);
            return;
        }
    }
    panic!("no bracket height gave an even number of layers");
}

#[test]
fn grid_equals_brute_force_on_a_single_and_tiny_triangles() {
    check_grid(
        "one triangle",
        vec![Triangle::new(
            Vec3::splat(-1.0),
            Vec3::new(1.0, -1.0, 0.0),
            Vec3::ONE,
        )],
        5000,
        4,
    );
    let mut rng = Rng::new(5, 5);
    let tiny: Vec<Triangle> = (0..500)
        .map(|_| {
            let a = random_point(&mut rng, -1.0, 1.0);
            Triangle::new(
                a,
                a + random_direction(&mut rng) * 1e-3,
                a + random_direction(&mut rng) * 1e-3,
            )
        })
        .chain([Triangle::new(
            Vec3::splat(-1.0),
            Vec3::new(1.0, -1.0, 1.0),
            Vec3::new(0.0, 1.0, 0.0),
        )])
        .collect();
    check_grid("tiny", tiny, 20_000, 5);
}

#[test]
fn grids_of_degenerate_triangles_only_are_never_hit() {
    let grid = Grid::build(vec![Triangle::new(Vec3::ZERO, Vec3::X, Vec3::X * 2.0)]);
    grid.validate().unwrap();
    assert!(
        grid.intersect(&Ray::new(Vec3::new(0.5, 0.0, 1.0), -Vec3::Z))
            .is_none()
    );
    assert!(
        Grid::build(Vec::new())
            .intersect(&Ray::new(Vec3::ZERO, Vec3::X))
            .is_none()
    );
}

/// Instances: rays carried into object space find what brute force finds in world space.
#[test]
fn scene_accel_equals_brute_force_over_instances() {
    let mut b = SceneBuilder::new();
    let white = b.add_material(Material::diffuse("white", Vec3::splat(0.5)));
    let tris = sphere(12, 24);
    let positions: Vec<Vec3> = tris.iter().flat_map(|t| t.vertices()).collect();
    let indices: Vec<[u32; 3]> = (0..tris.len() as u32)
        .map(|i| [3 * i, 3 * i + 1, 3 * i + 2])
        .collect();
    let mesh = b.add_mesh("sphere", positions.clone(), indices, white);
    let transforms = [
        Affine3A::IDENTITY,
        Affine3A::from_scale_rotation_translation(
            Vec3::splat(0.5),
            Quat::from_rotation_y(0.7),
            Vec3::new(2.5, 0.0, 0.0),
        ),
        // A mirroring, non-uniform scale.
        Affine3A::from_scale_rotation_translation(
            Vec3::new(-1.0, 0.3, 1.2),
            Quat::from_rotation_z(0.3),
            Vec3::new(0.0, 2.0, 1.0),
        ),
    ];
    for (i, m) in transforms.iter().enumerate() {
        b.add_instance(mesh, *m, format!("instance {i}"));
    }
    let scene = b.build();
    let accel = SceneAccel::build(&scene);
    let world: Vec<(usize, Triangle)> = transforms
        .iter()
        .enumerate()
        .flat_map(|(i, m)| {
            tris.iter().map(move |t| {
                (
                    i,
                    Triangle::new(
                        m.transform_point3(t.v0),
                        m.transform_point3(t.v0 + t.e1),
                        m.transform_point3(t.v0 + t.e2),
                    ),
                )
            })
        })
        .collect();
    let world_tris: Vec<Triangle> = world.iter().map(|w| w.1).collect();
    let mut rng = Rng::new(7, 7);
    let mut hits = 0;
    for _ in 0..20_000 {
        let origin = random_point(&mut rng, -3.0, 5.0);
        let ray = Ray::new(origin, random_point(&mut rng, -1.0, 3.0) - origin);
        let expected = brute_force(&world_tris, &ray);
        let got = accel.intersect(&ray);
        match (expected, got) {
            (None, None) => {}
            (Some((t, i)), Some(h)) => {
                hits += 1;
                assert!(
                    (t - h.t).abs() <= 1e-4 * t,
                    "{ray:?}: brute force t={t}, accel t={}",
                    h.t
                );
                // Away from shared edges the same instance must be found.
                if (t - h.t).abs() < 1e-6 * t {
                    assert_eq!(world[i as usize].0 as u32, h.instance, "{ray:?}");
                }
            }
            _ => panic!("{ray:?}: brute force {expected:?}, accel {got:?}"),
        }
        assert_eq!(accel.occluded(&ray), expected.is_some(), "{ray:?}");
    }
    assert!(hits > 1000, "only {hits} hits");
}
