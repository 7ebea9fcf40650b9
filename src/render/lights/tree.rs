//! Choosing a light for a shading point with a light tree (Conty Estevez & Kulla 2018,
//! "Importance Sampling of Many Lights", as pbrt-v4's `BVHLightSampler` formulates it):
//! the lights with a position sit in a binary tree whose nodes bound their lights' places,
//! emitting directions and intensity; from the root, each step goes to a child with
//! probability proportional to an importance that no light inside can exceed — peak
//! radiant intensity over squared distance, times the best cosines the bounds allow at the
//! light and at the receiver — so a point spends its samples on the lights that can matter
//! there, and never on a light whose bounds show it cannot reach it (behind a one-sided
//! emitter, outside a spot's cone).
//!
//! Lights are weighed by the intensity they can send towards the receiver, not by their
//! power: a narrow spot sends little power but lights what it hits as brightly as a point
//! of the same intensity (weighed by power, a 25° spot was chosen 21 times too rarely
//! beside a point lamp). So an importance is an irradiance bound (W/m²), exact for a lone
//! point light, and lights at infinity (the environment, a sun) compete with the tree's
//! root by the irradiance they bring (a sun's times its cosine at the receiver). The
//! probability of any light at any point is recomputed by walking its path from the root,
//! which MIS needs for lights that bounce rays find.

use glam::{Quat, Vec3};

use crate::geometry::Aabb;

/// A cone of directions: unit `axis`, and the cosine of its half-angle (−1: every
/// direction).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cone {
    /// The cone's axis.
    pub axis: Vec3,
    /// Cosine of its half-angle.
    pub cos_angle: f32,
}

impl Cone {
    /// Every direction.
    pub const ALL: Cone = Cone {
        axis: Vec3::Z,
        cos_angle: -1.0,
    };

    /// The smallest cone (by this construction) holding both (pbrt-v4 §3.8.4).
    fn union(self, other: Cone) -> Cone {
        let (a, b) = (self, other);
        let theta_a = a.cos_angle.clamp(-1.0, 1.0).acos();
        let theta_b = b.cos_angle.clamp(-1.0, 1.0).acos();
        let theta_d = angle_between(a.axis, b.axis);
        let pi = std::f32::consts::PI;
        if (theta_d + theta_b).min(pi) <= theta_a {
            return a;
        }
        if (theta_d + theta_a).min(pi) <= theta_b {
            return b;
        }
        let theta_o = 0.5 * (theta_a + theta_d + theta_b);
        if theta_o >= pi {
            return Cone::ALL;
        }
        let rotate_by = theta_o - theta_a;
        let about = a.axis.cross(b.axis);
        if about.length_squared() < 1e-12 {
            return Cone::ALL;
        }
        Cone {
            axis: (Quat::from_axis_angle(about.normalize(), rotate_by) * a.axis).normalize(),
            cos_angle: theta_o.cos(),
        }
    }
}

/// What a light (or a node's lights) can send where.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightBounds {
    /// Where its emitting points are.
    pub bounds: Aabb,
    /// The largest radiant intensity it sends in any direction (W/sr, a node's: the sum
    /// of its lights').
    pub intensity: f32,
    /// The directions its surface normals (or a spot's axis) point in.
    pub normals: Cone,
    /// Cosine of the angle beyond the normal cone within which it still emits: 0 for
    /// surfaces (a hemisphere), 1 for a hard-edged spot (nothing outside its cone).
    pub cos_emission: f32,
    /// Emits on both sides of its normals.
    pub two_sided: bool,
}

impl LightBounds {
    fn union(&self, other: &LightBounds) -> LightBounds {
        if self.intensity == 0.0 {
            return *other;
        }
        if other.intensity == 0.0 {
            return *self;
        }
        LightBounds {
            bounds: self.bounds.union(other.bounds),
            intensity: self.intensity + other.intensity,
            normals: self.normals.union(other.normals),
            cos_emission: self.cos_emission.min(other.cos_emission),
            two_sided: self.two_sided || other.two_sided,
        }
    }
}

/// A [`LightBounds`] in the form its importance is computed from, with what does not
/// depend on the receiver worked out once at build (the same numbers, so the same
/// importance to the bit).
#[derive(Clone, Copy, Debug)]
struct Reach {
    /// The bounds' centre.
    centre: Vec3,
    /// The least squared distance counted (pbrt-v4's: half the bounds' diagonal), so that
    /// receivers inside the bounds do not divide by nearly zero.
    least_distance_sq: f32,
    /// Squared radius of the bounds' bounding sphere.
    radius_sq: f32,
    normals: Cone,
    /// Sine of the normal cone's half-angle.
    sin_normals: f32,
    cos_emission: f32,
    two_sided: bool,
    intensity: f32,
}

impl Reach {
    fn of(b: &LightBounds) -> Reach {
        let cos_o = b.normals.cos_angle;
        Reach {
            centre: 0.5 * (b.bounds.min + b.bounds.max),
            least_distance_sq: 0.5 * (b.bounds.max - b.bounds.min).length(),
            radius_sq: (0.25 * (b.bounds.max - b.bounds.min).length_squared()).max(0.0),
            normals: b.normals,
            sin_normals: (1.0 - cos_o * cos_o).max(0.0).sqrt(),
            cos_emission: b.cos_emission,
            two_sided: b.two_sided,
            intensity: b.intensity,
        }
    }

    /// An upper bound on the irradiance the lights inside can bring to a receiver at `p`
    /// with normal `n` (zero `n`: no receiver cosine; pbrt-v4 §12.6.3 with intensity for
    /// power).
    fn importance(&self, p: Vec3, n: Vec3) -> f32 {
        let d2 = p.distance_squared(self.centre).max(self.least_distance_sq);
        if d2 == 0.0 || !d2.is_finite() {
            return 0.0;
        }
        let wi = (p - self.centre) / d2.sqrt();
        let mut cos_w = self.normals.axis.dot(wi);
        if self.two_sided {
            cos_w = cos_w.abs();
        }
        let sin_w = (1.0 - cos_w * cos_w).max(0.0).sqrt();
        // The directions from the box to p lie within θb of wi.
        let (sin_b, cos_b) = self.subtended(p);
        let (sin_o, cos_o) = (self.sin_normals, self.normals.cos_angle);
        // θ' = max(0, θw − θo − θb): the smallest angle between an emitting direction and a
        // direction towards p.
        let (sin_x, cos_x) = minus_clamped(sin_w, cos_w, sin_o, cos_o);
        let (_, cos_p) = minus_clamped(sin_x, cos_x, sin_b, cos_b);
        if cos_p < self.cos_emission {
            return 0.0;
        }
        let mut importance = self.intensity * cos_p.max(0.0) / d2;
        if n != Vec3::ZERO {
            let cos_i = wi.dot(n).abs();
            let sin_i = (1.0 - cos_i * cos_i).max(0.0).sqrt();
            importance *= minus_clamped(sin_i, cos_i, sin_b, cos_b).1.max(0.0);
        }
        importance.max(0.0)
    }

    /// (sin, cos) of the half-angle of the cone from `p` that holds the bounds' bounding
    /// sphere (every direction when `p` is inside it).
    fn subtended(&self, p: Vec3) -> (f32, f32) {
        let d2 = p.distance_squared(self.centre);
        if d2 <= self.radius_sq {
            return (0.0, -1.0);
        }
        let sin2 = self.radius_sq / d2;
        (sin2.sqrt(), (1.0 - sin2).max(0.0).sqrt())
    }
}

/// (sin, cos) of max(0, θa − θb) from the sines and cosines of θa and θb.
fn minus_clamped(sin_a: f32, cos_a: f32, sin_b: f32, cos_b: f32) -> (f32, f32) {
    if cos_a > cos_b {
        (0.0, 1.0)
    } else {
        (sin_a * cos_b - cos_a * sin_b, cos_a * cos_b + sin_a * sin_b)
    }
}

fn angle_between(a: Vec3, b: Vec3) -> f32 {
    // Stable for nearly parallel and nearly opposite vectors.
    if a.dot(b) < 0.0 {
        std::f32::consts::PI - 2.0 * ((a + b).length() / 2.0).clamp(-1.0, 1.0).asin()
    } else {
        2.0 * ((b - a).length() / 2.0).clamp(-1.0, 1.0).asin()
    }
}

/// Most lights in a leaf, among which the choice is by each light's own importance
/// (Cycles' light tree keeps up to eight emitters in a leaf, `light_tree.h`): exact for a
/// point, and a scene with a handful of lamps gets every one weighed on its own instead of
/// through bounds that lump a spot with a lamp it cannot stand in for.
const LEAF_LIGHTS: usize = 8;

#[derive(Clone, Debug)]
struct Node {
    /// What the node's lights can send where.
    reach: Reach,
    /// A leaf's first light in `leaf_lights`, or an inner node's second child (the first
    /// follows it).
    index: u32,
    /// A leaf's number of lights; 0 for an inner node.
    count: u32,
}

/// The tree over the lights with a place, and the lights at infinity beside it.
#[derive(Clone, Debug, Default)]
pub struct LightTree {
    nodes: Vec<Node>,
    /// The leaves' lights, leaf by leaf.
    leaf_lights: Vec<(usize, Reach)>,
    /// For each light: its path from the root (bit i: second child at depth i), depth and
    /// place in `leaf_lights`, or `None` for a light at infinity or without intensity.
    paths: Vec<Option<(u64, u8, u32)>>,
    /// The lights at infinity.
    infinite: Vec<(usize, Distant)>,
    /// Where each light at infinity is in `infinite`.
    infinite_slot: Vec<Option<usize>>,
    /// The one light there is, when there is one with a place and none at infinity (a
    /// room lit by one lamp): chosen everywhere with probability 1, with no walk and no
    /// importance. Where it can bring nothing (a spot's outside, a lamp's back) its own
    /// sample says so; MIS stays consistent because `pmf` says 1 wherever `choose` does.
    alone: Option<usize>,
}

/// A light for the tree.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum TreeInput {
    /// A light with a place, and what it can send where.
    Placed(LightBounds),
    /// A light at infinity.
    Infinite(Distant),
}

/// A light at infinity, for the tree: the irradiance it brings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Distant {
    /// Irradiance on a surface facing it (W/m²).
    pub irradiance: f32,
    /// The one direction it comes from (unit, towards the light), or `None` when it comes
    /// from everywhere (an environment).
    pub towards: Option<Vec3>,
}

impl Distant {
    /// The irradiance it can bring to a receiver with normal `n` (zero: no cosine).
    fn importance(&self, n: Vec3) -> f32 {
        match self.towards {
            Some(w) if n != Vec3::ZERO => self.irradiance * w.dot(n).abs(),
            _ => self.irradiance,
        }
    }
}

impl LightTree {
    /// Builds the tree over `lights` (indexed as the caller indexes its lights); lights
    /// that send nothing are never chosen.
    pub fn build(lights: &[TreeInput]) -> LightTree {
        let mut tree = LightTree {
            nodes: Vec::new(),
            leaf_lights: Vec::new(),
            paths: vec![None; lights.len()],
            infinite: Vec::new(),
            infinite_slot: vec![None; lights.len()],
            alone: None,
        };
        let mut placed = Vec::new();
        for (i, light) in lights.iter().enumerate() {
            match *light {
                TreeInput::Infinite(d) if d.irradiance > 0.0 && d.irradiance.is_finite() => {
                    tree.infinite_slot[i] = Some(tree.infinite.len());
                    tree.infinite.push((i, d));
                }
                TreeInput::Placed(b) if b.intensity > 0.0 && b.intensity.is_finite() => {
                    placed.push((i, b))
                }
                _ => {}
            }
        }
        if !placed.is_empty() {
            tree.build_node(&mut placed, 0, 0);
        }
        if let ([(light, _)], []) = (placed.as_slice(), tree.infinite.as_slice()) {
            tree.alone = Some(*light);
        }
        tree
    }

    /// Adds the node over `lights`, reached by `path` at `depth`; returns its index.
    fn build_node(&mut self, lights: &mut [(usize, LightBounds)], path: u64, depth: u8) -> usize {
        let index = self.nodes.len();
        let bounds = lights[1..].iter().fold(lights[0].1, |b, (_, l)| b.union(l));
        // Median splits halve the count, so paths fit their 64 bits below 2^66 lights.
        if lights.len() <= LEAF_LIGHTS {
            let first = self.leaf_lights.len() as u32;
            for (k, &(light, _)) in lights.iter().enumerate() {
                self.paths[light] = Some((path, depth, first + k as u32));
            }
            (self.leaf_lights).extend(lights.iter().map(|(l, b)| (*l, Reach::of(b))));
            self.nodes.push(Node {
                reach: Reach::of(&bounds),
                index: first,
                count: lights.len() as u32,
            });
            return index;
        }
        self.nodes.push(Node {
            reach: Reach::of(&bounds),
            index: 0,
            count: 0,
        });
        // Median split of the centroids along their widest axis: a balanced tree, so paths
        // stay short however many lights there are.
        let centroid = |b: &LightBounds| 0.5 * (b.bounds.min + b.bounds.max);
        let spread = lights.iter().fold(Aabb::EMPTY, |a, (_, l)| {
            a.union(Aabb {
                min: centroid(l),
                max: centroid(l),
            })
        });
        let axis = (spread.max - spread.min).max_position();
        let middle = lights.len() / 2;
        lights.select_nth_unstable_by(middle, |a, b| {
            centroid(&a.1)[axis].total_cmp(&centroid(&b.1)[axis])
        });
        let (first, second) = lights.split_at_mut(middle);
        self.build_node(first, path, depth + 1);
        let second_index = self.build_node(second, path | (1 << depth), depth + 1);
        self.nodes[index].index = second_index as u32;
        index
    }

    /// The lights of leaf `node`.
    fn leaf(&self, node: &Node) -> &[(usize, Reach)] {
        &self.leaf_lights[node.index as usize..(node.index + node.count) as usize]
    }

    /// Each of leaf `node`'s lights' importance for the receiver, and their sum.
    fn leaf_weights(&self, node: &Node, p: Vec3, n: Vec3) -> ([f32; LEAF_LIGHTS], f32) {
        let mut weights = [0.0f32; LEAF_LIGHTS];
        for (w, (_, b)) in weights.iter_mut().zip(self.leaf(node)) {
            *w = b.importance(p, n);
        }
        (weights, weights.iter().sum())
    }

    /// The weight of the tree at a receiver — its root's importance, or when the root is a
    /// leaf the sum of its lights' (then also returned, one by one) — and the total with
    /// the lights at infinity.
    fn tree_weight(&self, p: Vec3, n: Vec3) -> (f32, f32, Option<[f32; LEAF_LIGHTS]>) {
        let (tree, weights) = match self.nodes.first() {
            None => (0.0, None),
            Some(root) if root.count > 0 => {
                let (weights, sum) = self.leaf_weights(root, p, n);
                (sum, Some(weights))
            }
            Some(root) => (root.reach.importance(p, n), None),
        };
        let distant: f32 = self.infinite.iter().map(|(_, d)| d.importance(n)).sum();
        (tree, tree + distant, weights)
    }

    /// A light for a receiver at `p` with normal `n`, and the probability it was chosen
    /// with; `u` in [0, 1).
    pub fn choose(&self, p: Vec3, n: Vec3, u: f32) -> Option<(usize, f32)> {
        if let Some(light) = self.alone {
            return Some((light, 1.0));
        }
        let (tree, total, root_weights) = self.tree_weight(p, n);
        if !(total > 0.0 && total.is_finite()) {
            return None;
        }
        // The lights at infinity first, then the tree.
        let mut start = 0.0;
        for &(light, d) in &self.infinite {
            let pmf = d.importance(n) / total;
            if u < start + pmf || tree == 0.0 && start + pmf >= 1.0 - 1e-6 {
                return Some((light, pmf));
            }
            start += pmf;
        }
        if tree == 0.0 {
            return None;
        }
        let share = tree / total;
        let mut u = ((u - start) / share).clamp(0.0, 1.0 - f32::EPSILON);
        let mut pmf = share;
        let mut node = 0;
        loop {
            let here = &self.nodes[node];
            if here.count > 0 {
                let (weights, sum) = match root_weights {
                    Some(weights) => (weights, tree),
                    None => self.leaf_weights(here, p, n),
                };
                return choose_in_leaf(self.leaf(here), &weights, sum, u, pmf);
            }
            let (first, second) = (node + 1, here.index as usize);
            let a = self.nodes[first].reach.importance(p, n);
            let b = self.nodes[second].reach.importance(p, n);
            if a + b == 0.0 || !(a + b).is_finite() {
                return None;
            }
            let p_first = a / (a + b);
            if u < p_first {
                u = (u / p_first).min(1.0 - f32::EPSILON);
                pmf *= p_first;
                node = first;
            } else {
                u = ((u - p_first) / (1.0 - p_first)).min(1.0 - f32::EPSILON);
                pmf *= 1.0 - p_first;
                node = second;
            }
        }
    }

    /// The probability that [`LightTree::choose`] picks `light` for a receiver at `p` with
    /// normal `n`.
    pub fn pmf(&self, light: usize, p: Vec3, n: Vec3) -> f32 {
        if let Some(alone) = self.alone {
            return if alone == light { 1.0 } else { 0.0 };
        }
        let (tree, total, root_weights) = self.tree_weight(p, n);
        if !(total > 0.0 && total.is_finite()) {
            return 0.0;
        }
        if let Some(slot) = self.infinite_slot[light] {
            return self.infinite[slot].1.importance(n) / total;
        }
        let Some((path, depth, slot)) = self.paths[light] else {
            return 0.0;
        };
        let mut pmf = tree / total;
        let mut node = 0;
        for level in 0..depth {
            let here = &self.nodes[node];
            let (first, second) = (node + 1, here.index as usize);
            let a = self.nodes[first].reach.importance(p, n);
            let b = self.nodes[second].reach.importance(p, n);
            if a + b == 0.0 || !(a + b).is_finite() {
                return 0.0;
            }
            if path & (1 << level) == 0 {
                pmf *= a / (a + b);
                node = first;
            } else {
                pmf *= b / (a + b);
                node = second;
            }
        }
        let sum = match root_weights {
            Some(_) => tree,
            None => self.leaf_weights(&self.nodes[node], p, n).1,
        };
        if !(sum > 0.0 && sum.is_finite()) {
            return 0.0;
        }
        let own = self.leaf_lights[slot as usize].1.importance(p, n);
        pmf * own / sum
    }
}

/// One of a leaf's `lights` in proportion to its `weights` (summing to `sum`), for `u` in
/// [0, 1), and the probability of the whole choice given `pmf`, that of reaching the leaf.
fn choose_in_leaf(
    lights: &[(usize, Reach)],
    weights: &[f32; LEAF_LIGHTS],
    sum: f32,
    u: f32,
    pmf: f32,
) -> Option<(usize, f32)> {
    if !(sum > 0.0 && sum.is_finite()) {
        return None;
    }
    let weights = &weights[..lights.len()];
    let target = u * sum;
    let mut start = 0.0;
    // The last light with weight takes what rounding leaves at the top.
    let last = weights.iter().rposition(|&w| w > 0.0)?;
    for (k, &w) in weights.iter().enumerate() {
        if w > 0.0 && (target < start + w || k == last) {
            return Some((lights[k].0, pmf * w / sum));
        }
        start += w;
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::sampling::Rng;

    fn point_light(p: Vec3, intensity: f32) -> TreeInput {
        TreeInput::Placed(LightBounds {
            bounds: Aabb { min: p, max: p },
            intensity,
            normals: Cone::ALL,
            cos_emission: 0.0,
            two_sided: false,
        })
    }

    /// A hard-edged spot at `p` shining down −Y with a cone of `degrees` half-angle.
    fn spot_down(p: Vec3, intensity: f32, degrees: f32) -> TreeInput {
        TreeInput::Placed(LightBounds {
            bounds: Aabb { min: p, max: p },
            intensity,
            normals: Cone {
                axis: -Vec3::Y,
                cos_angle: degrees.to_radians().cos(),
            },
            cos_emission: 1.0,
            two_sided: false,
        })
    }

    #[test]
    fn choices_happen_as_often_as_their_probability_says() {
        let mut lights: Vec<TreeInput> = (0..40)
            .map(|i| {
                let x = i as f32 * 0.37;
                point_light(
                    Vec3::new(x.sin() * 5.0, x.cos() * 3.0, i as f32 * 0.1),
                    1.0 + (i % 7) as f32,
                )
            })
            .collect();
        lights.push(TreeInput::Infinite(Distant {
            irradiance: 0.05,
            towards: None,
        }));
        lights.push(TreeInput::Placed(LightBounds {
            bounds: Aabb {
                min: Vec3::new(-1.0, 2.0, -1.0),
                max: Vec3::new(1.0, 2.0, 1.0),
            },
            intensity: 10.0,
            normals: Cone {
                axis: -Vec3::Y,
                cos_angle: 1.0,
            },
            cos_emission: 0.0,
            two_sided: false,
        }));
        let tree = LightTree::build(&lights);
        let (p, n) = (Vec3::new(0.3, 0.1, 0.2), Vec3::Y);
        let total: f32 = (0..lights.len()).map(|i| tree.pmf(i, p, n)).sum();
        assert!((total - 1.0).abs() < 1e-4, "probabilities sum to {total}");
        let samples = 200_000;
        let mut counts = vec![0u64; lights.len()];
        let mut rng = Rng::new(1, 2);
        for _ in 0..samples {
            let (light, pmf) = tree.choose(p, n, rng.uniform()).unwrap();
            assert!((pmf - tree.pmf(light, p, n)).abs() <= 1e-4 * pmf);
            counts[light] += 1;
        }
        for (i, &c) in counts.iter().enumerate() {
            let expected = tree.pmf(i, p, n) as f64 * samples as f64;
            let sigma = expected.sqrt().max(1.0);
            assert!(
                (c as f64 - expected).abs() < 5.0 * sigma,
                "light {i}: {c} vs {expected:.0}"
            );
        }
        // Well behind the one-sided panel (above it, it faces down) nothing of it can
        // arrive; close by, its bounds cannot tell.
        assert_eq!(
            tree.pmf(lights.len() - 1, Vec3::new(0.0, 10.0, 0.0), Vec3::Y),
            0.0
        );
        assert!(tree.pmf(lights.len() - 1, Vec3::new(0.0, 0.0, 0.0), Vec3::Y) > 0.0);
    }

    #[test]
    fn a_spot_is_never_chosen_outside_its_cone() {
        let spot = spot_down(Vec3::Y, 100.0, 30.0);
        let tree = LightTree::build(&[spot, point_light(Vec3::new(5.0, 1.0, 0.0), 1.0)]);
        assert!(tree.pmf(0, Vec3::new(0.3, 0.0, 0.0), Vec3::Y) > 0.9);
        assert_eq!(tree.pmf(0, Vec3::new(2.0, 0.0, 0.0), Vec3::Y), 0.0);
    }

    #[test]
    fn a_lone_light_is_chosen_everywhere() {
        // A lone spot, beside a light that brings nothing: chosen with probability 1 inside
        // its cone and outside it (where its own sample brings nothing), never anything
        // else, `pmf` agreeing with `choose`; with a sun beside it the walk (and the sun)
        // decide again.
        let spot = spot_down(Vec3::Y, 100.0, 30.0);
        let dark = point_light(Vec3::new(5.0, 1.0, 0.0), 0.0);
        let tree = LightTree::build(&[dark, spot]);
        assert_eq!(tree.alone, Some(1));
        let (inside, outside) = (Vec3::new(0.3, 0.0, 0.0), Vec3::new(2.0, 0.0, 0.0));
        for p in [inside, outside] {
            for u in [0.0, 0.5, 0.999] {
                assert_eq!(tree.choose(p, Vec3::Y, u), Some((1, 1.0)));
            }
            assert_eq!(tree.pmf(1, p, Vec3::Y), 1.0);
            assert_eq!(tree.pmf(0, p, Vec3::Y), 0.0);
        }
        let sun = TreeInput::Infinite(Distant {
            irradiance: 0.5,
            towards: Some(Vec3::Y),
        });
        let with_sun = LightTree::build(&[spot, sun]);
        assert_eq!(with_sun.alone, None);
        let shared = with_sun.pmf(0, inside, Vec3::Y);
        assert!(shared > 0.0 && shared < 1.0, "{shared}");
    }

    #[test]
    fn a_few_lamps_are_weighed_by_the_irradiance_each_brings() {
        // A spot and a point lamp of the same intensity, a point lamp twice as far and a
        // sun: within a leaf each is weighed exactly, so the probabilities are the
        // irradiances, whatever power the spot's narrow cone holds.
        let spot = spot_down(Vec3::new(0.0, 2.0, 0.0), 5.0, 20.0);
        let near = point_light(Vec3::new(0.0, 2.0, 1.0), 5.0);
        let far = point_light(Vec3::new(0.0, 4.0, 0.0), 5.0);
        let sun = TreeInput::Infinite(Distant {
            irradiance: 0.5,
            towards: Some(Vec3::new(0.6, 0.8, 0.0)),
        });
        let tree = LightTree::build(&[spot, near, far, sun]);
        let (p, n) = (Vec3::ZERO, Vec3::Y);
        let irradiance = [
            5.0 / 4.0,
            5.0 / 5.0 * (2.0 / 5f32.sqrt()),
            5.0 / 16.0,
            0.5 * 0.8,
        ];
        let total: f32 = irradiance.iter().sum();
        for (light, e) in irradiance.iter().enumerate() {
            let pmf = tree.pmf(light, p, n);
            assert!(
                (pmf - e / total).abs() < 1e-5,
                "light {light}: {pmf} vs {}",
                e / total
            );
        }
        // A receiver tilted away from the sun weighs it by its cosine.
        let tilted = Vec3::new(-0.8, 0.6, 0.0);
        let sun_share = tree.pmf(3, p, tilted);
        let others: f32 = (0..3).map(|l| tree.pmf(l, p, tilted)).sum();
        assert!((sun_share + others - 1.0).abs() < 1e-5);
        assert!(sun_share < 0.05, "sun at 90° to the normal: {sun_share}");
    }
}
