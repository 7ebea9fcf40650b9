//! Semi-sharp creases of Catmull–Clark surfaces (DeRose, Kass & Truong 1998, "Subdivision
//! Surfaces in Character Animation", §3), with the uniform decay OpenSubdiv and USD use by
//! default (`creaseMethod = "uniform"`): an edge or vertex of sharpness s refines by the
//! sharp rule while s ≥ 1, its children have sharpness s − 1, and a sharpness between 0 and
//! 1 blends the sharp and smooth rules. Sharpness 10 or more is infinite and never decays.
//! Boundary edges are infinitely sharp, so one set of rules covers boundaries too.

use std::collections::HashMap;

use glam::Vec3;

use super::{Boundary, Cage};

/// Sharpness that never decays (OpenSubdiv's `SHARPNESS_INFINITE`).
pub const INFINITE: f32 = 10.0;

/// The creased edges and vertices of a mesh; what is not listed is smooth.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Sharpness {
    /// Edge (its two points, smaller index first) → sharpness.
    pub edges: HashMap<(usize, usize), f32>,
    /// Point → vertex (corner) sharpness.
    pub points: HashMap<usize, f32>,
}

impl Sharpness {
    /// The sharpness of the edge between `a` and `b`.
    pub fn edge(&self, a: usize, b: usize) -> f32 {
        self.edges
            .get(&(a.min(b), a.max(b)))
            .copied()
            .unwrap_or(0.0)
    }

    /// The corner sharpness of point `v`.
    pub fn point(&self, v: usize) -> f32 {
        self.points.get(&v).copied().unwrap_or(0.0)
    }

    /// True when nothing is creased.
    pub fn is_empty(&self) -> bool {
        self.edges.is_empty() && self.points.is_empty()
    }
}

/// The sharpness one level down: s − 1, or infinite for infinite.
pub fn decay(s: f32) -> f32 {
    if s >= INFINITE {
        INFINITE
    } else {
        (s - 1.0).max(0.0)
    }
}

/// The rule a vertex refines by.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Rule {
    /// No or one sharp edge (a dart): the smooth mask.
    Smooth,
    /// Exactly two sharp edges, to these neighbours: the crease (B-spline curve) mask.
    Crease(Vec3, Vec3),
    /// A sharp vertex or three or more sharp edges: the point stays.
    Corner,
}

fn rule(vertex_sharpness: f32, edges: impl Iterator<Item = (Vec3, f32)>) -> Rule {
    if vertex_sharpness > 0.0 {
        return Rule::Corner;
    }
    let sharp: Vec<Vec3> = edges.filter(|&(_, s)| s > 0.0).map(|(p, _)| p).collect();
    match sharp.as_slice() {
        [] | [_] => Rule::Smooth,
        [a, b] => Rule::Crease(*a, *b),
        _ => Rule::Corner,
    }
}

/// A vertex's refined position: `p` with vertex sharpness `vertex_sharpness`, its incident
/// edges as (other end, sharpness), and `smooth` the smooth rule's answer. When the rule of
/// the vertex and of its child differ (a sharpness decays to 0 in this step), the two
/// answers are blended by the mean sharpness of what decays, clamped to 1 (OpenSubdiv's
/// transitional weight).
pub fn vertex_point(
    p: Vec3,
    vertex_sharpness: f32,
    edges: &[(Vec3, f32)],
    smooth: impl Fn() -> Vec3,
) -> Vec3 {
    let mask = |rule: Rule| match rule {
        Rule::Smooth => smooth(),
        Rule::Crease(a, b) => 0.125 * (a + b) + 0.75 * p,
        Rule::Corner => p,
    };
    let parent = rule(vertex_sharpness, edges.iter().copied());
    let child = rule(
        decay(vertex_sharpness),
        edges.iter().map(|&(q, s)| (q, decay(s))),
    );
    if parent == child {
        return mask(parent);
    }
    let decaying: Vec<f32> = std::iter::once(vertex_sharpness)
        .chain(edges.iter().map(|&(_, s)| s))
        .filter(|&s| s > 0.0 && decay(s) == 0.0)
        .collect();
    let weight = if decaying.is_empty() {
        0.0
    } else {
        (decaying.iter().sum::<f32>() / decaying.len() as f32).min(1.0)
    };
    weight * mask(parent) + (1.0 - weight) * mask(child)
}

/// An edge's refined point: the smooth rule's `smooth`, the midpoint `mid` from sharpness 1
/// on, linear between.
pub fn edge_point(smooth: Vec3, mid: Vec3, sharpness: f32) -> Vec3 {
    smooth.lerp(mid, sharpness.clamp(0.0, 1.0))
}

/// A vertex's limit position by the rule it has at the last level: corners stay, a crease
/// follows its cubic B-spline curve `(a + 4p + b) / 6`, and `smooth` otherwise.
pub fn limit_point(
    p: Vec3,
    vertex_sharpness: f32,
    edges: &[(Vec3, f32)],
    smooth: impl Fn() -> Vec3,
) -> Vec3 {
    match rule(vertex_sharpness, edges.iter().copied()) {
        Rule::Smooth => smooth(),
        Rule::Crease(a, b) => (a + 4.0 * p + b) / 6.0,
        Rule::Corner => p,
    }
}

/// The creases of the mesh one level down: each creased edge (a, b), split at its new
/// point `mid_of(edge)`, passes its decayed sharpness to both halves; each sharp vertex
/// keeps its index and decays.
pub fn refine(sharpness: &Sharpness, mid_of: impl Fn(usize, usize) -> usize) -> Sharpness {
    let mut child = Sharpness::default();
    for (&(a, b), &s) in &sharpness.edges {
        let s = decay(s);
        if s > 0.0 {
            let m = mid_of(a, b);
            child.edges.insert((a.min(m), a.max(m)), s);
            child.edges.insert((b.min(m), b.max(m)), s);
        }
    }
    for (&v, &s) in &sharpness.points {
        let s = decay(s);
        if s > 0.0 {
            child.points.insert(v, s);
        }
    }
    child
}

/// True when a sharpness is finite and not yet decayed: the rule it gives will change.
fn semi_sharp(s: f32) -> bool {
    s > 0.0 && s < INFINITE
}

/// Replaces the limit positions of the points where a semi-sharp crease outlives the levels
/// refined. The rule at the last level does not give their limit (the crease will still
/// decay), so each such point's incident faces — all its limit depends on — are refined
/// alone, keeping only the faces around it, until its sharpness has decayed; then its
/// limit mask applies. This is the exact limit surface, as Blender's "Use Limit Surface"
/// evaluates it.
pub(super) fn semi_sharp_limits(mesh: &Cage, boundary: Boundary, limits: &mut [Vec3]) {
    if mesh.sharpness.is_empty() {
        return;
    }
    let starts = super::face_starts(&mesh.counts);
    let mut faces_of: HashMap<usize, Vec<usize>> = HashMap::new();
    for (f, (&count, &start)) in mesh.counts.iter().zip(&starts).enumerate() {
        for &v in &mesh.indices[start..start + count] {
            faces_of.entry(v).or_default().push(f);
        }
    }
    let mut affected: Vec<usize> = mesh
        .sharpness
        .points
        .iter()
        .filter(|&(_, &s)| semi_sharp(s))
        .map(|(&v, _)| v)
        .chain(
            mesh.sharpness
                .edges
                .iter()
                .filter(|&(_, &s)| semi_sharp(s))
                .flat_map(|(&(a, b), _)| [a, b]),
        )
        .collect();
    affected.sort_unstable();
    affected.dedup();
    for v in affected {
        let faces = faces_of.get(&v).map_or(&[][..], Vec::as_slice);
        let mut local = neighbourhood(mesh, &starts, faces, v);
        // Sharpness below 10 decays to 0 within 10 levels.
        for _ in 0..INFINITE as usize {
            let centre = 0;
            let still = semi_sharp(local.sharpness.point(centre))
                || local
                    .sharpness
                    .edges
                    .iter()
                    .any(|(&(a, b), &s)| (a == centre || b == centre) && semi_sharp(s));
            if !still {
                break;
            }
            let refined = super::refine(&local, boundary);
            let around: Vec<usize> = (0..refined.counts.len()).collect();
            let starts: Vec<usize> = (0..refined.counts.len()).map(|f| 4 * f).collect();
            let keep: Vec<usize> = around
                .into_iter()
                .filter(|&f| refined.indices[4 * f..4 * f + 4].contains(&centre))
                .collect();
            local = neighbourhood(&refined, &starts, &keep, centre);
        }
        limits[v] = super::limit_positions(&local, boundary)[0];
    }
}

/// The faces `faces` of `mesh` (whose face f starts at `starts[f]`) as a mesh of their own,
/// point `v` first, with the creases among their points.
fn neighbourhood(mesh: &Cage, starts: &[usize], faces: &[usize], v: usize) -> Cage {
    let mut local_of: HashMap<usize, usize> = HashMap::from([(v, 0)]);
    let mut local = Cage {
        points: vec![mesh.points[v]],
        ..Cage::default()
    };
    for &f in faces {
        let count = mesh.counts[f];
        local.counts.push(count);
        local.origin.push(0);
        for &p in &mesh.indices[starts[f]..starts[f] + count] {
            let next = local_of.len();
            let i = *local_of.entry(p).or_insert_with(|| {
                local.points.push(mesh.points[p]);
                next
            });
            local.indices.push(i);
        }
    }
    for (&(a, b), &s) in &mesh.sharpness.edges {
        if let (Some(&a), Some(&b)) = (local_of.get(&a), local_of.get(&b)) {
            local.sharpness.edges.insert((a.min(b), a.max(b)), s);
        }
    }
    if let Some(&s) = mesh.sharpness.points.get(&v) {
        local.sharpness.points.insert(0, s);
    }
    local
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sharpness_decays_by_one_and_infinite_stays() {
        assert_eq!(decay(2.5), 1.5);
        assert_eq!(decay(0.5), 0.0);
        assert_eq!(decay(INFINITE), INFINITE);
    }

    /// A crease of sharpness 0.5 that decays this step: half the crease mask, half the
    /// smooth one; a sharpness of 1 decays too but is fully sharp this step.
    #[test]
    fn a_decaying_crease_blends_by_its_sharpness() {
        let p = Vec3::ZERO;
        let (a, b) = (Vec3::X, Vec3::new(-1.0, 2.0, 0.0));
        let smooth = || Vec3::new(0.0, 0.0, 1.0);
        let crease = 0.125 * (a + b);
        for (s, weight) in [(0.5, 0.5), (1.0, 1.0), (2.0, 1.0)] {
            let got = vertex_point(p, 0.0, &[(a, s), (b, s), (Vec3::Y, 0.0)], smooth);
            let want = weight * crease + (1.0 - weight) * smooth();
            assert!(got.abs_diff_eq(want, 1e-6), "s {s}: {got} vs {want}");
        }
        // One sharp edge is a dart: smooth.
        assert_eq!(
            vertex_point(p, 0.0, &[(a, 3.0), (b, 0.0)], smooth),
            smooth()
        );
        // Three sharp edges, or a sharp vertex: a corner.
        let three = [(a, 3.0), (b, 3.0), (Vec3::Y, 3.0)];
        assert_eq!(vertex_point(p, 0.0, &three, smooth), p);
        assert_eq!(vertex_point(p, 4.0, &[(a, 0.0)], smooth), p);
    }
}
