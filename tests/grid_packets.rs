//! Packets of rays ([`Grid::intersect_packet`]) must answer every ray exactly as the
//! single-ray walk ([`Grid::intersect`]) does — the same hit parameter, barycentrics and
//! triangle, bit for bit — on every ray set of the accelerator benchmark over the four
//! Stanford dragons, and on pinhole cameras placed anywhere around and inside awkward
//! meshes (cameras inside the grid, rays along cell faces and through cell corners, rays of
//! mixed octants in one packet).

#[path = "support/oracles/mod.rs"]
mod oracles;

use glam::Vec3;
use gridtrace::accel::{Grid, GridHit, PACKET_RAYS, Ray, Triangle};
use gridtrace::load::ply;
use gridtrace::render::sampling::Rng;
use oracles::rays::{bounce_rays, camera_rays, light_segments, outside_rays, segments};
use oracles::{DRAGON_MODELS, Mesh, dragon_path};

/// The rays (by index) whose packet answer differs from their single-ray answer, each with
/// both answers, for `rays` taken `PACKET_RAYS` at a time; and how many rays hit.
fn differences(grid: &Grid, rays: &[Ray]) -> (Vec<String>, usize) {
    let mut found = Vec::new();
    let mut hits = 0;
    let mut answers = [None; PACKET_RAYS];
    for (p, packet) in rays.chunks(PACKET_RAYS).enumerate() {
        let answers = &mut answers[..packet.len()];
        grid.intersect_packet(packet, answers);
        for (r, (ray, packed)) in packet.iter().zip(answers.iter()).enumerate() {
            let single: Option<GridHit> = grid.intersect(ray);
            hits += usize::from(single.is_some());
            if *packed != single {
                let k = p * PACKET_RAYS + r;
                found.push(format!(
                    "ray {k} {ray:?}: packet {packed:?}, single {single:?}"
                ));
            }
        }
    }
    (found, hits)
}

fn assert_same(label: &str, grid: &Grid, rays: &[Ray]) {
    let (found, hits) = differences(grid, rays);
    assert!(
        found.is_empty(),
        "{label}: {} of {} rays differ, first ones:\n{}",
        found.len(),
        rays.len(),
        found[..found.len().min(10)].join("\n")
    );
    // A comparison means something only if rays hit and miss.
    assert!(
        hits > rays.len() / 50 && hits < rays.len(),
        "{label}: {hits} of {} rays hit",
        rays.len()
    );
}

#[test]
fn packets_answer_as_single_rays_on_the_benchmark_sets_over_the_dragons() {
    for (i, model) in DRAGON_MODELS.iter().enumerate() {
        let (positions, indices) = ply::read_mesh(&dragon_path(model)).unwrap();
        let mesh = Mesh { positions, indices };
        let triangles = mesh.triangles();
        let grid = Grid::from_mesh(mesh.positions.clone(), &mesh.indices);
        let bounds = grid.bounds();
        let count = if i == 0 { 100_000 } else { 20_000 };
        let bounce = bounce_rays(&triangles, count, 2);
        let sets = [
            ("camera", camera_rays(&bounds, count)),
            ("outside", outside_rays(&bounds, count, 1)),
            (
                "shadow",
                segments(&bounce, 0.1 * bounds.extent().length(), 3),
            ),
            ("light", light_segments(&triangles, &bounds, count, 4)),
            ("bounce", bounce),
        ];
        for (set, rays) in &sets {
            assert_same(&format!("{model}, {set} rays"), &grid, rays);
        }
    }
}

fn random_direction(rng: &mut Rng) -> Vec3 {
    loop {
        let d = Vec3::new(rng.uniform(), rng.uniform(), rng.uniform()) * 2.0 - Vec3::ONE;
        if d.length_squared() > 1e-4 && d.length_squared() <= 1.0 {
            return d.normalize();
        }
    }
}

/// A closed sphere of radius 1, `rings` × `segments` quads split in two: rays cross
/// shared edges and vertices.
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
    (0..rings)
        .flat_map(|r| (0..segments).map(move |s| (r, s)))
        .flat_map(|(r, s)| {
            let (a, b) = (point(r, s), point(r + 1, s));
            let (c, d) = (point(r + 1, s + 1), point(r, s + 1));
            [Triangle::new(a, b, c), Triangle::new(a, c, d)]
        })
        .collect()
}

/// A flat grid of `n` × `n` quads in the plane y = 0 over [−1, 1]², with a small triangle
/// above and below so that the grid has depth: the plane lies on cell faces.
fn plane(n: u32) -> Vec<Triangle> {
    let at = |i: u32, j: u32| {
        Vec3::new(
            2.0 * i as f32 / n as f32 - 1.0,
            0.0,
            2.0 * j as f32 / n as f32 - 1.0,
        )
    };
    let mut tris: Vec<Triangle> = (0..n)
        .flat_map(|i| (0..n).map(move |j| (i, j)))
        .flat_map(|(i, j)| {
            let (a, b, c, d) = (at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
            [Triangle::new(a, b, c), Triangle::new(a, c, d)]
        })
        .collect();
    for y in [-0.5f32, 0.5] {
        tris.push(Triangle::new(
            Vec3::new(-0.1, y, 0.0),
            Vec3::new(0.1, y, 0.0),
            Vec3::new(0.0, y, 0.1),
        ));
    }
    tris
}

/// An 8 × 8 tile of a pinhole camera at `eye` looking along `forward` with a field of
/// `spread` radians, the tile's corner at (`x0`, `y0`) of a `side` × `side` image.
fn tile(eye: Vec3, forward: Vec3, spread: f32, side: usize, x0: usize, y0: usize) -> Vec<Ray> {
    let up = if forward.y.abs() > 0.9 {
        Vec3::X
    } else {
        Vec3::Y
    };
    let right = forward.cross(up).normalize();
    let up = right.cross(forward);
    let half = (0.5 * spread).tan();
    (0..PACKET_RAYS)
        .map(|i| {
            let (px, py) = (x0 + i % 8, y0 + i / 8);
            let x = ((px as f32 + 0.5) / side as f32 * 2.0 - 1.0) * half;
            let y = ((py as f32 + 0.5) / side as f32 * 2.0 - 1.0) * half;
            Ray::new(eye, forward + x * right + y * up)
        })
        .collect()
}

/// Packets from cameras at random places (outside the grid and inside it), looking at the
/// mesh, along the grid's axes and anywhere, with narrow and wide fields; some with a short
/// reach, some with rays of other octants mixed in.
fn awkward_packets(grid: &Grid, rng: &mut Rng, packets: usize) -> Vec<Ray> {
    let bounds = grid.bounds();
    let center = bounds.center();
    let radius = bounds.extent().length();
    let axes = [Vec3::X, Vec3::Y, Vec3::Z, -Vec3::X, -Vec3::Y, -Vec3::Z];
    let mut rays = Vec::new();
    for p in 0..packets {
        let eye = match p % 3 {
            0 => center + random_direction(rng) * radius,
            _ => center + random_direction(rng) * 0.5 * radius * rng.uniform(),
        };
        let forward = match p % 4 {
            0 => (center - eye).normalize_or(Vec3::X),
            1 => axes[p / 4 % 6],
            _ => random_direction(rng),
        };
        let spread = [0.01, 0.3, 1.2, 2.5][p / 2 % 4];
        let side = 8 * (1 + (rng.uniform() * 16.0) as usize);
        let (x0, y0) = (
            8 * ((rng.uniform() * (side / 8) as f32) as usize).min(side / 8 - 1),
            8 * ((rng.uniform() * (side / 8) as f32) as usize).min(side / 8 - 1),
        );
        let mut packet = tile(eye, forward, spread, side, x0, y0);
        if p % 5 == 0 {
            let reach = rng.uniform() * radius;
            packet.iter_mut().for_each(|r| *r = r.with_t_max(reach));
        }
        if p % 7 == 0 {
            for r in packet.iter_mut().step_by(5) {
                r.direction = random_direction(rng);
            }
        }
        rays.extend(packet);
    }
    rays
}

#[test]
fn packets_answer_as_single_rays_from_awkward_cameras() {
    let mut rng = Rng::new(7, 7);
    let soup: Vec<Triangle> = (0..3000)
        .map(|_| {
            let a = Vec3::new(rng.uniform(), rng.uniform(), rng.uniform()) * 2.0 - Vec3::ONE;
            let scale = 0.05 + 0.3 * rng.uniform();
            Triangle::new(
                a,
                a + random_direction(&mut rng) * scale,
                a + random_direction(&mut rng) * scale,
            )
        })
        .collect();
    for (name, triangles) in [
        ("sphere", sphere(40, 80)),
        ("plane", plane(30)),
        ("soup", soup),
    ] {
        let grid = Grid::build(triangles);
        let rays = awkward_packets(&grid, &mut rng, 600);
        assert_same(name, &grid, &rays);
    }
}
