//! The fixed-seed ray sets the accelerators are compared and timed on.

use glam::Vec3;
use gridtrace::accel::{Ray, Triangle};
use gridtrace::geometry::Aabb;
use gridtrace::geometry::{interpolate_with_error, offset_ray_origin};
use gridtrace::render::sampling::{Frame, Rng, cosine_hemisphere, uniform_triangle};

fn unit_vector(rng: &mut Rng) -> Vec3 {
    let z = 1.0 - 2.0 * rng.uniform();
    let r = (1.0 - z * z).max(0.0).sqrt();
    let phi = std::f32::consts::TAU * rng.uniform();
    Vec3::new(r * phi.cos(), r * phi.sin(), z)
}

/// Rays from a sphere around the box (radius: the box's diagonal) towards uniform random
/// points inside it, as primary rays approach a model.
pub fn outside_rays(bounds: &Aabb, count: usize, seed: u64) -> Vec<Ray> {
    let mut rng = Rng::new(seed, 1);
    let center = bounds.center();
    let radius = bounds.extent().length();
    (0..count)
        .map(|_| {
            let origin = center + radius * unit_vector(&mut rng);
            let target = bounds.min
                + Vec3::new(rng.uniform(), rng.uniform(), rng.uniform()) * bounds.extent();
            Ray::new(origin, (target - origin).normalize())
        })
        .collect()
}

/// 'Bounce' rays: from uniform random points of random triangles, in cosine-distributed
/// directions about the geometric normal, on either side at random, starting off the
/// surface by the point's rounding-error bound, exactly as the renderer's secondary rays do.
pub fn bounce_rays(triangles: &[Triangle], count: usize, seed: u64) -> Vec<Ray> {
    let mut rng = Rng::new(seed, 2);
    let live: Vec<&Triangle> = triangles.iter().filter(|t| !t.is_degenerate()).collect();
    (0..count)
        .map(|_| {
            let (tri, b) = surface_point(&live, &mut rng);
            let corners = tri.vertices().map(|v| (v, Vec3::ZERO));
            let (p, error) = interpolate_with_error(corners, b);
            let side = if rng.uniform() < 0.5 { 1.0 } else { -1.0 };
            let n = side * tri.e1.cross(tri.e2).normalize();
            let direction = Frame::from_normal(n).to_world(cosine_hemisphere(rng.uniform2()));
            let direction = direction.normalize();
            Ray::new(offset_ray_origin(p, error, n, direction), direction)
        })
        .collect()
}

/// A uniform random point of a triangle chosen uniformly at random (not by area): the
/// triangle and the point's barycentrics.
fn surface_point<'a>(live: &[&'a Triangle], rng: &mut Rng) -> (&'a Triangle, [f32; 3]) {
    let tri = live[((rng.uniform() * live.len() as f32) as usize).min(live.len() - 1)];
    let b = uniform_triangle(rng.uniform2());
    (tri, [1.0 - b.x - b.y, b.x, b.y])
}

/// The same rays cut to segments of random length up to `max_length`, as shadow rays are.
pub fn segments(rays: &[Ray], max_length: f32, seed: u64) -> Vec<Ray> {
    let mut rng = Rng::new(seed, 3);
    rays.iter()
        .map(|r| r.with_t_max(max_length * rng.uniform().max(1e-3)))
        .collect()
}

/// Shadow segments as the renderer's light sampling makes them: from uniform random points of
/// random triangles ([`surface_point`]) whose outward side (the winding's, `e1 × e2`) faces a square light above the
/// box, towards a uniform random point of the light ([`light_segment`]). (For the benchmark
/// and `tools/dev/grid-ab`; the cross-check does not use them.)
#[allow(dead_code)]
pub fn light_segments(triangles: &[Triangle], bounds: &Aabb, count: usize, seed: u64) -> Vec<Ray> {
    let mut rng = Rng::new(seed, 4);
    let live: Vec<&Triangle> = triangles.iter().filter(|t| !t.is_degenerate()).collect();
    let mut segments = Vec::with_capacity(count);
    while segments.len() < count {
        let (tri, b) = surface_point(&live, &mut rng);
        let n = tri.e1.cross(tri.e2).normalize();
        segments.extend(light_segment(tri, b, n, bounds, &mut rng));
    }
    segments
}

/// Each of a pinhole camera's rays ([`camera_rays`]) that hits the mesh, followed by the light
/// segment from its hit on the side it sees, when that side faces the light: the order in
/// which the renderer traces them, so that the segment starts in cells the camera ray has
/// just read. `nearest` gives a ray's hit: parameter, barycentrics `u`, `v` and triangle.
/// (For `tools/dev/grid-ab`'s `seen` set, which times each pair together.)
#[allow(dead_code)]
pub fn seen_light_pairs(
    triangles: &[Triangle],
    bounds: &Aabb,
    count: usize,
    seed: u64,
    nearest: impl Fn(&Ray) -> Option<(f32, f32, f32, u32)>,
) -> Vec<Ray> {
    let mut rng = Rng::new(seed, 5);
    let mut pairs = Vec::with_capacity(2 * count);
    for ray in camera_rays(bounds, 16 * count) {
        if pairs.len() == 2 * count {
            break;
        }
        let Some((_, u, v, id)) = nearest(&ray) else {
            continue;
        };
        let tri = &triangles[id as usize];
        let n = tri.e1.cross(tri.e2).normalize();
        let seen = if n.dot(ray.direction) > 0.0 { -n } else { n };
        if let Some(segment) = light_segment(tri, [1.0 - u - v, u, v], seen, bounds, &mut rng) {
            pairs.extend([ray, segment]);
        }
    }
    pairs
}

/// The segment from the point of `tri` at barycentrics `b` to a uniform random point of a
/// square light above the box (a fifth of its width across, half its height above it), as
/// `direct_light` makes it: the origin off the surface by the point's rounding-error bound
/// on the side of `n`, the segment stopped short of the light by 10⁻⁴ of its length. `None`
/// when that side faces away from the light.
fn light_segment(
    tri: &Triangle,
    b: [f32; 3],
    n: Vec3,
    bounds: &Aabb,
    rng: &mut Rng,
) -> Option<Ray> {
    let extent = bounds.extent();
    let offset = Vec3::new(rng.uniform() * 2.0 - 1.0, 0.0, rng.uniform() * 2.0 - 1.0);
    let half = 0.1 * extent.x;
    let light = bounds.center() + Vec3::Y * extent.y + offset * half;
    let corners = tri.vertices().map(|v| (v, Vec3::ZERO));
    let (p, error) = interpolate_with_error(corners, b);
    let towards = light - p;
    (n.dot(towards) > 0.0).then(|| {
        let origin = offset_ray_origin(p, error, n, towards);
        Ray {
            t_max: 1.0 - 1e-4,
            ..Ray::new(origin, light - origin)
        }
    })
}

/// A pinhole camera's rays: from one point framing the box, through a square image whose
/// side is a multiple of 8, tile by tile (8 × 8 pixels, the tiles row by row), as a
/// renderer traces them and as packet queries take them: every 64 rays from the first are
/// one tile. The last rows are cut where `count` ends. (For the benchmark and `tools/dev/grid-ab`;
/// the cross-check does not use them.)
#[allow(dead_code)]
pub fn camera_rays(bounds: &Aabb, count: usize) -> Vec<Ray> {
    const TILE: usize = 8;
    let center = bounds.center();
    let radius = 0.5 * bounds.extent().length();
    let eye = center + Vec3::new(0.6, 0.4, 1.0).normalize() * 2.6 * radius;
    let forward = (center - eye).normalize();
    let right = forward.cross(Vec3::Y).normalize();
    let up = right.cross(forward);
    let tiles = ((count as f32).sqrt() / TILE as f32).ceil() as usize;
    let side = tiles * TILE;
    (0..tiles * tiles)
        .flat_map(|tile| {
            let (tx, ty) = (tile % tiles * TILE, tile / tiles * TILE);
            (0..TILE * TILE).map(move |i| (tx + i % TILE, ty + i / TILE))
        })
        .take(count)
        .map(|(i, j)| {
            let x = (i as f32 + 0.5) / side as f32 * 2.0 - 1.0;
            let y = (j as f32 + 0.5) / side as f32 * 2.0 - 1.0;
            let direction = forward + 0.42 * (x * right + y * up);
            Ray::new(eye, direction.normalize())
        })
        .collect()
}
