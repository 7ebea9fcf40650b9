//! Emissive rectangles as one light. Two triangles of an emissive mesh that follow each
//! other in its index list, share a diagonal and together make a rectangle — how Blender's
//! exporters write a plane and how a USD `RectLight` is loaded — are sampled as the
//! rectangle: uniformly over the solid angle of the whole ([`SphericalRectangle`]) where it
//! is near, else uniformly over its area. The light tree then has one light to weigh instead
//! of two, and a near lamp's direct light is free of the noise of choosing a half by bounds.
//!
//! The rectangle is the first triangle's right angle `o` and the edges from it to the two
//! shared corners; a point at rectangle coordinates (a, b) lies in the first triangle when
//! a + b ≤ 1 and in the second otherwise, and is placed on that triangle's own corners, so
//! a sample is a point of the geometry rays find.

use glam::Vec3;

use super::spherical_rectangle::SphericalRectangle;
use super::triangle::PlacedTriangle;

/// How far from a rectangle two triangles may be and still be one (relative to its size):
/// a corner this far off moves the density by as little, far below the image's noise.
const TOLERANCE: f32 = 1e-5;

/// Two emissive triangles making a rectangle.
#[derive(Clone, Copy, Debug)]
pub struct EmissiveQuad {
    /// The two triangles, as indices into the set's triangles.
    pub triangles: [usize; 2],
    /// The first triangle's right-angle corner.
    corner: Vec3,
    /// The edges from `corner` to the shared corners.
    edges: [Vec3; 2],
    /// The front normal (the first triangle's).
    pub normal: Vec3,
    /// The rectangle's area.
    pub area: f32,
    /// Which corner of each triangle carries which role: the first's (right angle, end of
    /// edge 0, end of edge 1); the second's (end of edge 0, far corner, end of edge 1).
    roles: [[usize; 3]; 2],
}

/// Where a rectangle is sampled from a point.
#[derive(Clone, Copy, Debug)]
enum Rule {
    /// Uniformly over its solid angle (sr).
    SolidAngle(SphericalRectangle),
    /// Uniformly over its area.
    Area,
}

impl EmissiveQuad {
    /// The rectangle triangles `indices` (placed as `placed`) make, if they make one: they
    /// share exactly two corners and face the same way, the first has a right angle at the
    /// corner it does not share, and the second's own corner closes the rectangle.
    pub fn pair(indices: [usize; 2], placed: [&PlacedTriangle; 2]) -> Option<EmissiveQuad> {
        let [first, second] = placed.map(|t| t.corners.map(|c| c.0));
        if placed[0].area == 0.0 || placed[1].area == 0.0 {
            return None;
        }
        let in_second = |v: Vec3| second.iter().position(|&w| w == v);
        let apart: Vec<usize> = (0..3).filter(|&i| in_second(first[i]).is_none()).collect();
        let &[o] = apart.as_slice() else {
            return None;
        };
        let (d0, d1) = ((o + 1) % 3, (o + 2) % 3);
        let (s0, s1) = (in_second(first[d0])?, in_second(first[d1])?);
        let far = 3 - s0 - s1;
        let edges = [first[d0] - first[o], first[d1] - first[o]];
        let (l0, l1) = (edges[0].length(), edges[1].length());
        let square = edges[0].dot(edges[1]).abs() <= TOLERANCE * l0 * l1;
        let closes =
            (first[o] + edges[0] + edges[1] - second[far]).length() <= TOLERANCE * (l0 + l1);
        let facing = placed[0].normal.dot(placed[1].normal) > 0.0;
        (square && closes && facing).then_some(EmissiveQuad {
            triangles: indices,
            corner: first[o],
            edges,
            normal: placed[0].normal,
            area: placed[0].area + placed[1].area,
            roles: [[o, d0, d1], [s0, far, s1]],
        })
    }

    /// How the rectangle is sampled from `p`: by solid angle when it is near (its diagonal
    /// longer than its plane's distance, the rule [`super::spherical`] gives a triangle) and
    /// that is well conditioned. It depends only on `p`, so a hit is weighed with the
    /// density a sample would have had.
    fn rule(&self, p: Vec3) -> Rule {
        let height = self.normal.dot(self.corner - p);
        let diagonal_sq = self.edges[0].length_squared() + self.edges[1].length_squared();
        if height * height >= diagonal_sq {
            return Rule::Area;
        }
        match SphericalRectangle::new(p, self.corner, self.edges) {
            Some(rect) if rect.is_well_conditioned() => Rule::SolidAngle(rect),
            _ => Rule::Area,
        }
    }

    /// A point drawn from `p` with `u`: the triangle (0 or 1) it is on, its weights on that
    /// triangle's corners, and its solid-angle density for a point at squared distance
    /// `distance_sq` and light cosine `cos_light`, given the quad's choice probability.
    pub fn sample(&self, p: Vec3, u: glam::Vec2) -> (usize, [f32; 3], Density) {
        let (ab, density) = match self.rule(p) {
            Rule::SolidAngle(rect) => (rect.sample(u), Density::SolidAngle(rect.solid_angle())),
            Rule::Area => (u, Density::Area(self.area)),
        };
        let (a, b) = (ab.x, ab.y);
        // Which half is a coin toss for every sample: chosen by index, not by a branch.
        let half = usize::from(a + b > 1.0);
        let by_role = [[1.0 - a - b, a, b], [1.0 - b, a + b - 1.0, 1.0 - a]][half];
        let mut weights = [0.0; 3];
        for (role, &corner) in self.roles[half].iter().enumerate() {
            weights[corner] = by_role[role];
        }
        (half, weights, density)
    }

    /// The density [`EmissiveQuad::sample`] at `origin` draws a point with.
    pub fn density(&self, origin: Vec3) -> Density {
        match self.rule(origin) {
            Rule::SolidAngle(rect) => Density::SolidAngle(rect.solid_angle()),
            Rule::Area => Density::Area(self.area),
        }
    }
}

/// What a light sample's density is uniform over.
#[derive(Clone, Copy, Debug)]
pub enum Density {
    /// A solid angle (sr).
    SolidAngle(f64),
    /// An area (m²): the density in solid angle is distance² / (area · |cos θ_light|).
    Area(f32),
}

impl Density {
    /// The solid-angle density of a point at `distance_sq` and light cosine `cos_light`,
    /// chosen with probability `pmf`.
    pub fn pdf(self, pmf: f32, distance_sq: f32, cos_light: f32) -> f32 {
        match self {
            Density::SolidAngle(omega) => pmf / omega as f32,
            Density::Area(area) => pmf / area * distance_sq / cos_light.abs(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::{Affine3A, Vec2};

    fn placed(corners: [Vec3; 3]) -> PlacedTriangle {
        PlacedTriangle::new(&Affine3A::IDENTITY, corners)
    }

    /// The corners of a 2 × 1 rectangle in the plane z = `z`, in order around it.
    fn rectangle(z: f32) -> [Vec3; 4] {
        [(0.0, 0.0), (2.0, 0.0), (2.0, 1.0), (0.0, 1.0)].map(|(x, y)| Vec3::new(x, y, z))
    }

    #[test]
    fn two_halves_of_a_rectangle_pair_and_other_shapes_do_not() {
        let [a, b, c, d] = rectangle(0.0);
        // Both windings of the diagonal, corners in any rotation.
        for (first, second) in [
            ([a, b, c], [a, c, d]),
            ([b, c, d], [d, a, b]),
            ([c, a, b], [d, a, c]),
        ] {
            let quad = EmissiveQuad::pair([0, 1], [&placed(first), &placed(second)]);
            let quad = quad.unwrap_or_else(|| panic!("{first:?} {second:?} not paired"));
            assert!((quad.area - 2.0).abs() < 1e-6);
        }
        // A parallelogram, a kite, two triangles sharing one corner, and a fold.
        let sheared = Vec3::new(2.5, 1.0, 0.0);
        let cases = [
            ([a, b, sheared], [a, sheared, d + Vec3::X * 0.5]),
            ([a, b, c], [a, c, Vec3::new(-0.5, 1.5, 0.0)]),
            ([a, b, c], [c, d, Vec3::new(-1.0, 3.0, 0.0)]),
            ([a, b, c], [a, c, Vec3::new(0.0, 1.0, 0.5)]),
        ];
        for (first, second) in cases {
            assert!(
                EmissiveQuad::pair([0, 1], [&placed(first), &placed(second)]).is_none(),
                "{first:?} {second:?} paired"
            );
        }
        // Opposite windings face different ways.
        assert!(EmissiveQuad::pair([0, 1], [&placed([a, b, c]), &placed([a, d, c])]).is_none());
    }

    #[test]
    fn samples_land_on_the_rectangle_where_its_coordinates_say() {
        let [a, b, c, d] = rectangle(1.0);
        let halves = [[b, c, a], [c, d, a]];
        let quad =
            EmissiveQuad::pair([0, 1], halves.each_ref().map(|&t| placed(t)).each_ref()).unwrap();
        for u in [
            Vec2::new(0.25, 0.5),
            Vec2::new(0.75, 0.75),
            Vec2::new(0.1, 0.95),
            Vec2::new(0.9, 0.05),
        ] {
            // From far above the rectangle is sampled by area: u is the rectangle's
            // coordinates, along the first triangle's right angle's edges.
            let (half, w, density) = quad.sample(Vec3::new(1.0, 0.5, 50.0), u);
            assert!(matches!(density, Density::Area(_)));
            let point: Vec3 = (0..3).map(|k| w[k] * halves[half][k]).sum();
            let origin = quad.corner + u.x * quad.edges[0] + u.y * quad.edges[1];
            assert!(
                (point - origin).length() < 1e-6,
                "{u}: {point} against {origin}"
            );
            assert!(w.iter().all(|&x| x >= 0.0), "{w:?}");
        }
    }
}
