//! Catmull–Clark subdivision of a polygon cage (Catmull & Clark 1978) and Loop subdivision
//! of a triangle cage (Loop 1987, with his β weights), with boundaries as OpenSubdiv and
//! USD's `interpolateBoundary` define them, and the refined points moved to their limit
//! positions (Catmull–Clark: Halstead, Kass & DeRose 1993, §3; Loop: Loop 1987, §3.3), as
//! Blender's Subdivision modifier does with "Use Limit Surface" (its default). Catmull–Clark
//! surfaces take semi-sharp edge and vertex creases ([`crease`]); Loop surfaces are smooth.
//! Face-varying data (texture coordinates) is interpolated linearly within each face.

mod crease;

use std::collections::HashMap;

use glam::{Vec2, Vec3};

pub use crease::{INFINITE as INFINITE_SHARPNESS, Sharpness};

/// A polygon mesh to refine: faces as corner counts and point indices, optional texture
/// coordinates per face corner, and for each face the cage face it came from.
#[derive(Clone, Debug, Default)]
pub struct Cage {
    /// Point positions.
    pub points: Vec<Vec3>,
    /// Corners of each face.
    pub counts: Vec<usize>,
    /// Point of each face corner, face after face.
    pub indices: Vec<usize>,
    /// Texture coordinates of each face corner.
    pub uvs: Option<Vec<Vec2>>,
    /// The cage face each face came from.
    pub origin: Vec<usize>,
    /// Creased edges and vertices (Catmull–Clark only).
    pub sharpness: Sharpness,
}

/// How boundary edges and corners refine (USD `interpolateBoundary`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Boundary {
    /// Boundary edges are smooth B-spline curves; every boundary vertex, corners too,
    /// follows them.
    EdgeOnly,
    /// As `EdgeOnly`, but a vertex on a single face stays where it is (USD's default).
    EdgeAndCorner,
}

/// Faces a cage of `faces` faces has after `levels` levels (each face of n corners becomes
/// n quads, then every level multiplies by four), saturating.
pub fn refined_faces(counts: &[usize], levels: u32) -> u64 {
    if levels == 0 {
        return counts.len() as u64;
    }
    let first: u64 = counts.iter().map(|&c| c as u64).sum();
    first.saturating_mul(4u64.saturating_pow(levels - 1))
}

/// `cage` refined `levels` times, its points on the limit surface.
pub fn catmull_clark(cage: &Cage, boundary: Boundary, levels: u32) -> Cage {
    let mut mesh = cage.clone();
    for _ in 0..levels {
        mesh = refine(&mesh, boundary);
    }
    if levels > 0 {
        let mut limits = limit_positions(&mesh, boundary);
        crease::semi_sharp_limits(&mesh, boundary, &mut limits);
        mesh.points = limits;
    }
    mesh
}

/// `cage`, all triangles, refined `levels` times by Loop's scheme, its points on the limit
/// surface. Each level has four times the triangles.
pub fn loop_subdivision(cage: &Cage, boundary: Boundary, levels: u32) -> Cage {
    let mut mesh = cage.clone();
    for _ in 0..levels {
        mesh = refine_loop(&mesh, boundary);
    }
    if levels > 0 {
        mesh.points = loop_limit(&mesh, boundary);
    }
    mesh
}

/// Loop's β for an interior vertex of valence `n`.
fn loop_beta(n: usize) -> f32 {
    let n = n as f32;
    let c = 0.375 + 0.25 * (2.0 * std::f32::consts::PI / n).cos();
    (0.625 - c * c) / n
}

/// Neighbours of each point, and the two boundary neighbours of boundary points.
fn neighbours(mesh: &Cage, edges: &Edges) -> (Vec<Vec<usize>>, Vec<Vec<usize>>, Vec<usize>) {
    let n = mesh.points.len();
    let (mut ring, mut border) = (vec![Vec::new(); n], vec![Vec::new(); n]);
    for (e, &[a, b]) in edges.ends.iter().enumerate() {
        ring[a].push(b);
        ring[b].push(a);
        if edges.faces[e].len() != 2 {
            border[a].push(b);
            border[b].push(a);
        }
    }
    let mut faces = vec![0usize; n];
    for &v in &mesh.indices {
        faces[v] += 1;
    }
    (ring, border, faces)
}

/// A boundary point's new position by the cubic B-spline rule, or `None` when it stays
/// (a corner kept by `EdgeAndCorner`, or a non-manifold point).
fn boundary_rule(
    points: &[Vec3],
    v: usize,
    border: &[usize],
    faces: usize,
    boundary: Boundary,
    (side, centre): (f32, f32),
) -> Option<Vec3> {
    let corner = faces == 1 && boundary == Boundary::EdgeAndCorner;
    if border.len() != 2 || corner {
        return None;
    }
    Some(side * (points[border[0]] + points[border[1]]) + centre * points[v])
}

/// One level of Loop subdivision.
fn refine_loop(mesh: &Cage, boundary: Boundary) -> Cage {
    let edges = edges(mesh);
    let (ring, border, faces) = neighbours(mesh, &edges);
    let p = &mesh.points;
    // Edge points: 3/8 of each end and 1/8 of each opposite corner, or the midpoint.
    let mut opposite = vec![Vec3::ZERO; edges.ends.len()];
    for (t, tri) in mesh.indices.chunks(3).enumerate() {
        for i in 0..3 {
            opposite[edges.of_corner[3 * t + i]] += p[tri[(i + 2) % 3]];
        }
    }
    let edge_points = edges.ends.iter().enumerate().map(|(e, &[a, b])| {
        if edges.faces[e].len() == 2 {
            0.375 * (p[a] + p[b]) + 0.125 * opposite[e]
        } else {
            0.5 * (p[a] + p[b])
        }
    });
    let vertex_points = (0..p.len()).map(|v| {
        if ring[v].is_empty() {
            return p[v];
        }
        if !border[v].is_empty() {
            return boundary_rule(p, v, &border[v], faces[v], boundary, (0.125, 0.75))
                .unwrap_or(p[v]);
        }
        let beta = loop_beta(ring[v].len());
        (1.0 - ring[v].len() as f32 * beta) * p[v]
            + beta * ring[v].iter().map(|&u| p[u]).sum::<Vec3>()
    });
    let base = p.len();
    let mut refined = Cage {
        points: vertex_points.chain(edge_points).collect(),
        uvs: mesh.uvs.as_ref().map(|_| Vec::new()),
        ..Cage::default()
    };
    for (t, tri) in mesh.indices.chunks(3).enumerate() {
        let e = [0, 1, 2].map(|i| base + edges.of_corner[3 * t + i]);
        let children = [
            [tri[0], e[0], e[2]],
            [tri[1], e[1], e[0]],
            [tri[2], e[2], e[1]],
            [e[0], e[1], e[2]],
        ];
        for child in children {
            refined.counts.push(3);
            refined.origin.push(mesh.origin[t]);
            refined.indices.extend(child);
        }
        if let (Some(uvs), Some(out)) = (&mesh.uvs, &mut refined.uvs) {
            let c = [uvs[3 * t], uvs[3 * t + 1], uvs[3 * t + 2]];
            let m = [
                0.5 * (c[0] + c[1]),
                0.5 * (c[1] + c[2]),
                0.5 * (c[2] + c[0]),
            ];
            out.extend([
                c[0], m[0], m[2], c[1], m[1], m[0], c[2], m[2], m[1], m[0], m[1], m[2],
            ]);
        }
    }
    refined
}

/// Limit positions of a Loop mesh: interior points `(1 − n χ) p + χ Σ neighbours` with
/// χ = 1 / (3 / (8 β) + n); boundary points by the cubic B-spline's `(e₀ + 4 p + e₁) / 6`.
fn loop_limit(mesh: &Cage, boundary: Boundary) -> Vec<Vec3> {
    let edges = edges(mesh);
    let (ring, border, faces) = neighbours(mesh, &edges);
    let p = &mesh.points;
    (0..p.len())
        .map(|v| {
            if ring[v].is_empty() {
                return p[v];
            }
            if !border[v].is_empty() {
                return boundary_rule(p, v, &border[v], faces[v], boundary, (1.0 / 6.0, 4.0 / 6.0))
                    .unwrap_or(p[v]);
            }
            let n = ring[v].len() as f32;
            let chi = 1.0 / (3.0 / (8.0 * loop_beta(ring[v].len())) + n);
            (1.0 - n * chi) * p[v] + chi * ring[v].iter().map(|&u| p[u]).sum::<Vec3>()
        })
        .collect()
}

/// Edges of a mesh: for each undirected edge its faces, and for each face corner the edge
/// that leaves it.
struct Edges {
    /// Endpoints and adjacent faces of each edge.
    ends: Vec<[usize; 2]>,
    faces: Vec<Vec<usize>>,
    /// Edge from corner i to corner i + 1 of its face.
    of_corner: Vec<usize>,
    /// Edge of each point pair, smaller index first.
    index: HashMap<(usize, usize), usize>,
}

fn edges(mesh: &Cage) -> Edges {
    let mut index: HashMap<(usize, usize), usize> = HashMap::new();
    let mut ends = Vec::new();
    let mut faces: Vec<Vec<usize>> = Vec::new();
    let mut of_corner = Vec::with_capacity(mesh.indices.len());
    let mut start = 0;
    for (face, &count) in mesh.counts.iter().enumerate() {
        for i in 0..count {
            let (a, b) = (
                mesh.indices[start + i],
                mesh.indices[start + (i + 1) % count],
            );
            let key = (a.min(b), a.max(b));
            let edge = *index.entry(key).or_insert_with(|| {
                ends.push([a, b]);
                faces.push(Vec::new());
                ends.len() - 1
            });
            faces[edge].push(face);
            of_corner.push(edge);
        }
        start += count;
    }
    Edges {
        ends,
        faces,
        of_corner,
        index,
    }
}

/// Where each face's corners start in a mesh whose faces have `counts` corners.
fn face_starts(counts: &[usize]) -> Vec<usize> {
    counts
        .iter()
        .scan(0, |s, &c| {
            let start = *s;
            *s += c;
            Some(start)
        })
        .collect()
}

/// One level of Catmull–Clark.
fn refine(mesh: &Cage, boundary: Boundary) -> Cage {
    let edges = edges(mesh);
    let starts = face_starts(&mesh.counts);
    let corners = |f: usize| &mesh.indices[starts[f]..starts[f] + mesh.counts[f]];
    let face_points: Vec<Vec3> = (0..mesh.counts.len())
        .map(|f| {
            let c = corners(f);
            c.iter().map(|&v| mesh.points[v]).sum::<Vec3>() / c.len().max(1) as f32
        })
        .collect();
    let sharpness = edge_sharpness(mesh, &edges);
    let edge_points: Vec<Vec3> = (0..edges.ends.len())
        .map(|e| {
            let [a, b] = edges.ends[e];
            let mid = 0.5 * (mesh.points[a] + mesh.points[b]);
            if sharpness[e] >= 1.0 {
                mid
            } else {
                let [f, g] = [edges.faces[e][0], edges.faces[e][1]];
                let smooth = 0.5 * mid + 0.25 * (face_points[f] + face_points[g]);
                crease::edge_point(smooth, mid, sharpness[e])
            }
        })
        .collect();
    // Per vertex: incident faces, incident edges.
    let n = mesh.points.len();
    let mut vertex_faces = vec![Vec::new(); n];
    for f in 0..mesh.counts.len() {
        for &v in corners(f) {
            vertex_faces[v].push(f);
        }
    }
    let mut vertex_edges = vec![Vec::new(); n];
    for (e, [a, b]) in edges.ends.iter().enumerate() {
        vertex_edges[*a].push(e);
        vertex_edges[*b].push(e);
    }
    let corners_sharpness = vertex_sharpness(mesh, &edges, boundary);
    let vertex_points: Vec<Vec3> = (0..n)
        .map(|v| {
            let p = mesh.points[v];
            let incident = &vertex_edges[v];
            if incident.is_empty() {
                return p;
            }
            let smooth = || {
                let valence = incident.len() as f32;
                let f = vertex_faces[v]
                    .iter()
                    .map(|&f| face_points[f])
                    .sum::<Vec3>()
                    / vertex_faces[v].len() as f32;
                let r = incident
                    .iter()
                    .map(|&e| 0.5 * (mesh.points[edges.ends[e][0]] + mesh.points[edges.ends[e][1]]))
                    .sum::<Vec3>()
                    / valence;
                (f + 2.0 * r + (valence - 3.0) * p) / valence
            };
            let around = incident_sharpness(mesh, &edges, &sharpness, incident, v);
            crease::vertex_point(p, corners_sharpness[v], &around, smooth)
        })
        .collect();

    // New points: vertices, then edges, then faces.
    let (edge_base, face_base) = (n, n + edges.ends.len());
    let mut points = vertex_points;
    points.extend(edge_points);
    points.extend(face_points);
    let mut refined = Cage {
        points,
        uvs: mesh.uvs.as_ref().map(|_| Vec::new()),
        sharpness: crease::refine(&mesh.sharpness, |a, b| {
            edge_base + edges.index[&(a.min(b), a.max(b))]
        }),
        ..Cage::default()
    };
    for (f, (&count, &start)) in mesh.counts.iter().zip(&starts).enumerate() {
        let face_uv = mesh
            .uvs
            .as_ref()
            .map(|uvs| uvs[start..start + count].iter().sum::<Vec2>() / count as f32);
        for i in 0..count {
            let previous = (i + count - 1) % count;
            let corner = start + i;
            refined.counts.push(4);
            refined.origin.push(mesh.origin[f]);
            refined.indices.extend([
                mesh.indices[corner],
                edge_base + edges.of_corner[corner],
                face_base + f,
                edge_base + edges.of_corner[start + previous],
            ]);
            if let (Some(uvs), Some(out), Some(centre)) = (&mesh.uvs, &mut refined.uvs, face_uv) {
                let here = uvs[corner];
                out.extend([
                    here,
                    0.5 * (here + uvs[start + (i + 1) % count]),
                    centre,
                    0.5 * (here + uvs[start + previous]),
                ]);
            }
        }
    }
    refined
}

/// Where each point of a refined (all-quad) mesh lies on the limit surface: interior
/// points by Halstead et al.'s mask `(n² p + 4 Σ eᵢ + Σ fᵢ) / (n (n + 5))` over edge
/// neighbours e and face-diagonal neighbours f; smooth boundary points by the cubic
/// B-spline's `(e₀ + 4 p + e₁) / 6`; corners stay.
fn limit_positions(mesh: &Cage, boundary: Boundary) -> Vec<Vec3> {
    let edges = edges(mesh);
    let (ring, _, _) = neighbours(mesh, &edges);
    let sharpness = edge_sharpness(mesh, &edges);
    let corners_sharpness = vertex_sharpness(mesh, &edges, boundary);
    let mut vertex_edges = vec![Vec::new(); mesh.points.len()];
    for (e, [a, b]) in edges.ends.iter().enumerate() {
        vertex_edges[*a].push(e);
        vertex_edges[*b].push(e);
    }
    let p = &mesh.points;
    let mut diagonal_sum = vec![Vec3::ZERO; p.len()];
    for quad in mesh.indices.chunks(4) {
        for i in 0..4 {
            diagonal_sum[quad[i]] += p[quad[(i + 2) % 4]];
        }
    }
    (0..p.len())
        .map(|v| {
            if ring[v].is_empty() {
                return p[v];
            }
            let smooth = || {
                let k = ring[v].len() as f32;
                let edge_sum: Vec3 = ring[v].iter().map(|&u| p[u]).sum();
                (k * k * p[v] + 4.0 * edge_sum + diagonal_sum[v]) / (k * (k + 5.0))
            };
            let around = incident_sharpness(mesh, &edges, &sharpness, &vertex_edges[v], v);
            crease::limit_point(p[v], corners_sharpness[v], &around, smooth)
        })
        .collect()
}

/// Each edge's sharpness: infinite on the boundary (an edge of one face, or of more than
/// two), else its crease's.
fn edge_sharpness(mesh: &Cage, edges: &Edges) -> Vec<f32> {
    (0..edges.ends.len())
        .map(|e| {
            let [a, b] = edges.ends[e];
            if edges.faces[e].len() != 2 {
                crease::INFINITE
            } else {
                mesh.sharpness.edge(a, b)
            }
        })
        .collect()
}

/// Each point's vertex sharpness: its corner crease's, or infinite where the boundary pins
/// it — a point on a single face under `EdgeAndCorner`, or a non-manifold point (not two
/// boundary edges).
fn vertex_sharpness(mesh: &Cage, edges: &Edges, boundary: Boundary) -> Vec<f32> {
    let (_, border, faces) = neighbours(mesh, edges);
    (0..mesh.points.len())
        .map(|v| {
            let pinned = !border[v].is_empty()
                && (border[v].len() != 2 || (faces[v] == 1 && boundary == Boundary::EdgeAndCorner));
            if pinned {
                crease::INFINITE
            } else {
                mesh.sharpness.point(v)
            }
        })
        .collect()
}

/// The edges `incident` to point `v` as (other end's position, sharpness).
fn incident_sharpness(
    mesh: &Cage,
    edges: &Edges,
    sharpness: &[f32],
    incident: &[usize],
    v: usize,
) -> Vec<(Vec3, f32)> {
    incident
        .iter()
        .map(|&e| {
            let [a, b] = edges.ends[e];
            (mesh.points[if a == v { b } else { a }], sharpness[e])
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cube() -> Cage {
        let points = (0..8)
            .map(|i| {
                let bit = |b: usize| if i & (1 << b) != 0 { 1.0 } else { -1.0 };
                Vec3::new(bit(0), bit(1), bit(2))
            })
            .collect();
        let faces = [
            [0, 4, 6, 2],
            [1, 3, 7, 5],
            [0, 1, 5, 4],
            [2, 6, 7, 3],
            [0, 2, 3, 1],
            [4, 5, 7, 6],
        ];
        Cage {
            points,
            counts: vec![4; 6],
            indices: faces.concat(),
            uvs: None,
            origin: (0..6).collect(),
            sharpness: Sharpness::default(),
        }
    }

    /// The limit point at the middle of a face of the cube [−1, 1]³ is 68/81 from the
    /// centre at every level: after one level it is a regular point with edge neighbours
    /// at x = 3/4 and diagonal ones at the cube's corners moved to 5/9, and the mask gives
    /// (16 + 4 · 4 · 3/4 + 4 · 5/9) / 36 = 68/81. The surface shrinks as levels grow.
    #[test]
    fn a_cube_refines_to_its_limit_surface() {
        let mut previous = f32::INFINITY;
        for levels in 1..=4 {
            let refined = catmull_clark(&cube(), Boundary::EdgeAndCorner, levels);
            assert_eq!(refined.counts.len() as u64, refined_faces(&[4; 6], levels));
            let along_x = refined
                .points
                .iter()
                .map(|p| p.x)
                .fold(f32::NEG_INFINITY, f32::max);
            assert!(
                (along_x - 68.0 / 81.0).abs() < 1e-5,
                "level {levels}: {along_x}"
            );
            let spread = refined
                .points
                .iter()
                .map(|p| p.length())
                .fold(0.0f32, f32::max);
            assert!(spread <= previous + 1e-6);
            previous = spread;
        }
    }

    /// The cube with every edge creased to `sharpness`.
    fn creased_cube(sharpness: f32) -> Cage {
        let mut cage = cube();
        for face in cage.indices.clone().chunks(4) {
            for i in 0..4 {
                let (a, b) = (face[i], face[(i + 1) % 4]);
                cage.sharpness.edges.insert((a.min(b), a.max(b)), sharpness);
            }
        }
        cage
    }

    /// A cube whose every edge is infinitely sharp stays a cube: each face refines flat
    /// between straight creases.
    #[test]
    fn a_cube_with_sharp_edges_stays_a_cube() {
        let cage = creased_cube(INFINITE_SHARPNESS);
        let refined = catmull_clark(&cage, Boundary::EdgeAndCorner, 3);
        for p in &refined.points {
            assert!((p.abs().max_element() - 1.0).abs() < 1e-6, "{p}");
        }
    }

    /// Where a semi-sharp crease outlives the levels refined, a point's limit is the limit
    /// of the same point refined until the crease has decayed: sharpness 2.5 on every
    /// edge and 1.5 at one corner, limits at level 1 against level 4.
    #[test]
    fn semi_sharp_limits_are_those_of_deeper_refinement() {
        let mut cage = creased_cube(2.5);
        cage.sharpness.points.insert(0, 1.5);
        let shallow = catmull_clark(&cage, Boundary::EdgeAndCorner, 1);
        let deep = catmull_clark(&cage, Boundary::EdgeAndCorner, 4);
        for (v, p) in shallow.points.iter().enumerate() {
            assert!(
                p.abs_diff_eq(deep.points[v], 1e-5),
                "{v}: {p} vs {}",
                deep.points[v]
            );
        }
        // And the creases mattered: the smooth cube's limit is elsewhere.
        let smooth = catmull_clark(&cube(), Boundary::EdgeAndCorner, 1);
        assert!(smooth.points[0].distance(shallow.points[0]) > 0.1);
    }

    /// An open grid's boundary stays a B-spline of its boundary points, its corners fixed.
    #[test]
    fn an_open_quad_keeps_its_corners_with_edge_and_corner() {
        let quad = Cage {
            points: vec![Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::Y],
            counts: vec![4],
            indices: vec![0, 1, 2, 3],
            uvs: Some(vec![Vec2::ZERO, Vec2::X, Vec2::ONE, Vec2::Y]),
            origin: vec![0],
            sharpness: Sharpness::default(),
        };
        let refined = catmull_clark(&quad, Boundary::EdgeAndCorner, 2);
        for corner in &quad.points {
            assert!(refined.points.iter().any(|p| p.distance(*corner) < 1e-6));
        }
        // Flat stays flat; texture coordinates follow positions on a unit square.
        assert!(refined.points.iter().all(|p| p.z == 0.0));
        let uvs = refined.uvs.unwrap();
        assert_eq!(uvs.len(), refined.indices.len());
        let smooth = catmull_clark(&quad, Boundary::EdgeOnly, 2);
        assert!(!smooth.points.iter().any(|p| p.distance(Vec3::ZERO) < 1e-6));
    }

    fn icosahedron() -> Cage {
        let t = (1.0 + 5f32.sqrt()) / 2.0;
        let points: Vec<Vec3> = [
            (-1.0, t, 0.0),
            (1.0, t, 0.0),
            (-1.0, -t, 0.0),
            (1.0, -t, 0.0),
            (0.0, -1.0, t),
            (0.0, 1.0, t),
            (0.0, -1.0, -t),
            (0.0, 1.0, -t),
            (t, 0.0, -1.0),
            (t, 0.0, 1.0),
            (-t, 0.0, -1.0),
            (-t, 0.0, 1.0),
        ]
        .iter()
        .map(|&(x, y, z)| Vec3::new(x, y, z).normalize())
        .collect();
        let faces = [
            [0, 11, 5],
            [0, 5, 1],
            [0, 1, 7],
            [0, 7, 10],
            [0, 10, 11],
            [1, 5, 9],
            [5, 11, 4],
            [11, 10, 2],
            [10, 7, 6],
            [7, 1, 8],
            [3, 9, 4],
            [3, 4, 2],
            [3, 2, 6],
            [3, 6, 8],
            [3, 8, 9],
            [4, 9, 5],
            [2, 4, 11],
            [6, 2, 10],
            [8, 6, 7],
            [9, 8, 1],
        ];
        Cage {
            points,
            counts: vec![3; 20],
            indices: faces.concat(),
            uvs: None,
            origin: (0..20).collect(),
            sharpness: Sharpness::default(),
        }
    }

    /// Loop's limit of a regular icosahedron inscribed in the unit sphere: the twelve
    /// original points (valence 5, neighbours at cos θ = 1/√5) end at radius
    /// 1 − 5χ + 5χ/√5 from the limit mask, whatever the level (one limit point), every
    /// level has four times the triangles, and nothing leaves the sphere.
    #[test]
    fn loop_refines_an_icosahedron_symmetrically_to_one_limit() {
        let one = loop_subdivision(&icosahedron(), Boundary::EdgeAndCorner, 1);
        let three = loop_subdivision(&icosahedron(), Boundary::EdgeAndCorner, 3);
        assert_eq!(three.counts.len(), 20 * 64);
        let radius = three.points[0].length();
        for v in 0..12 {
            assert!((three.points[v].length() - radius).abs() < 1e-5);
            assert!(one.points[v].distance(three.points[v]) < 1e-5, "point {v}");
        }
        let chi = 1.0 / (3.0 / (8.0 * loop_beta(5)) + 5.0);
        let exact = 1.0 - 5.0 * chi + 5.0 * chi / 5f32.sqrt();
        assert!((radius - exact).abs() < 1e-5, "{radius} vs {exact}");
        assert!(three.points.iter().all(|p| p.length() < 1.0));
    }

    /// A flat triangulated square stays flat, keeps the two corners that lie on a single
    /// triangle with `EdgeAndCorner` (the other two are boundary points of two triangles,
    /// smoothed like any) and carries its texture coordinates per corner.
    #[test]
    fn loop_keeps_a_flat_square_flat_with_its_corners() {
        let square = Cage {
            points: vec![Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::Y],
            counts: vec![3, 3],
            indices: vec![0, 1, 2, 0, 2, 3],
            uvs: Some(vec![
                Vec2::ZERO,
                Vec2::X,
                Vec2::ONE,
                Vec2::ZERO,
                Vec2::ONE,
                Vec2::Y,
            ]),
            origin: vec![0, 1],
            sharpness: Sharpness::default(),
        };
        let refined = loop_subdivision(&square, Boundary::EdgeAndCorner, 2);
        assert_eq!(refined.counts.len(), 32);
        assert!(refined.points.iter().all(|p| p.z == 0.0));
        for corner in [square.points[1], square.points[3]] {
            assert!(refined.points.iter().any(|p| p.distance(corner) < 1e-6));
        }
        assert!(!refined.points.iter().any(|p| p.distance(Vec3::ZERO) < 1e-6));
        assert_eq!(refined.uvs.unwrap().len(), 96);
    }
}
