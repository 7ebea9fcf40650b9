//! The directional half of the guide: a distribution over the sphere stored as a quadtree
//! over the square of cylindrical coordinates (cos θ, φ / 2π), a map from the sphere to
//! [0, 1]² that preserves area (Müller, Gross & Novák 2017, "Practical Path Guiding for
//! Efficient Light-Transport Simulation", §3.2 and §4).
//!
//! A [`Histogram`] gathers energy in a pass: its sums are fixed-point integers added
//! atomically, so they are the same whatever order the threads add them in. A
//! [`Distribution`] is a histogram frozen for sampling; [`Distribution::refined`] gives
//! the next pass's histogram, subdivided where the distribution holds much energy.

use std::f32::consts::PI;
use std::sync::atomic::{AtomicU32, AtomicU64, Ordering};

use glam::{Vec2, Vec3};

/// Fixed-point scale of recorded energies: 2²⁰ steps per unit.
const FIXED_SCALE: f64 = (1u64 << 20) as f64;

/// Largest energy one record adds (in units), so that 2²⁰ records at the limit still fit
/// in 64 bits.
const MAX_RECORD: f64 = (1u64 << 24) as f64;

/// A quadrant of a node whose energy is above this fraction of the total is subdivided
/// (the paper's ρ = 0.01).
const SUBDIVIDE_FRACTION: f64 = 0.01;

/// A quadrant is subdivided only when it took at least this many records in the pass, so
/// that cells stay larger than the records can resolve: finer cells would be empty by
/// chance and leave holes in the distribution.
const MIN_RECORDS: f64 = 64.0;

/// Deepest level of the quadtree (the paper's 20).
const MAX_DEPTH: u32 = 20;

/// Index of "no child": the quadrant is a leaf.
const LEAF: u32 = 0;

/// The quadrant of `p` in the unit square: bit 0 the right half, bit 1 the upper half.
fn quadrant(p: Vec2) -> usize {
    usize::from(p.x >= 0.5) + 2 * usize::from(p.y >= 0.5)
}

/// `p` in the unit square of quadrant `q`.
fn into_quadrant(p: Vec2, q: usize) -> Vec2 {
    let corner = Vec2::new((q & 1) as f32, (q >> 1) as f32);
    (p * 2.0 - corner).clamp(Vec2::ZERO, Vec2::splat(1.0 - f32::EPSILON))
}

/// The point of the unit square that the direction `d` (unit length) maps to.
pub fn to_square(d: Vec3) -> Vec2 {
    let u = (d.z.clamp(-1.0, 1.0) + 1.0) * 0.5;
    let mut v = d.y.atan2(d.x) / (2.0 * PI);
    if v < 0.0 {
        v += 1.0;
    }
    Vec2::new(u, v).clamp(Vec2::ZERO, Vec2::splat(1.0 - f32::EPSILON))
}

/// The direction that the point `p` of the unit square stands for.
pub fn to_sphere(p: Vec2) -> Vec3 {
    let z = 2.0 * p.x - 1.0;
    let r = (1.0 - z * z).max(0.0).sqrt();
    let (sin, cos) = (2.0 * PI * p.y).sin_cos();
    Vec3::new(r * cos, r * sin, z)
}

/// Solid-angle density of a density on the unit square: the map has constant Jacobian 4π.
pub const SQUARE_TO_SPHERE: f32 = 1.0 / (4.0 * PI);

/// One node of a frozen quadtree: the child of each quadrant ([`LEAF`] for none), its
/// share of the node's energy and the records that fell in it.
#[derive(Clone, Debug)]
struct Node {
    children: [u32; 4],
    energy: [f32; 4],
    records: [u32; 4],
}

/// A distribution over the sphere, sampled in proportion to the energy recorded in each
/// quadrant and uniformly within a leaf.
#[derive(Clone, Debug)]
pub struct Distribution {
    nodes: Vec<Node>,
}

impl Distribution {
    /// The uniform distribution: one node, no energy.
    pub fn uniform() -> Distribution {
        Distribution {
            nodes: vec![Node {
                children: [LEAF; 4],
                energy: [0.0; 4],
                records: [0; 4],
            }],
        }
    }

    /// True when no energy was recorded, so sampling is uniform.
    pub fn is_uniform(&self) -> bool {
        self.nodes[0].energy.iter().all(|&e| e == 0.0)
    }

    /// Draws a point of the unit square from `u` ∈ [0, 1)², and its density there. The
    /// horizontal half is chosen first, then the vertical one within it, each by
    /// rescaling `u`, so that nearby `u` stay nearby.
    pub fn sample_square(&self, mut u: Vec2) -> (Vec2, f32) {
        let (mut node, mut origin, mut size, mut pdf) = (0usize, Vec2::ZERO, 1.0f32, 1.0f32);
        loop {
            let e = self.nodes[node].energy;
            let total = e[0] + e[1] + e[2] + e[3];
            if total <= 0.0 {
                return (within(origin, size, u), pdf);
            }
            let left = (e[0] + e[2]) / total;
            let (column, ux) = choose(u.x, left);
            let (below, above) = if column == 0 {
                (e[0], e[2])
            } else {
                (e[1], e[3])
            };
            let (row, uy) = choose(u.y, below / (below + above));
            let q = column + 2 * row;
            pdf *= 4.0 * e[q] / total;
            size *= 0.5;
            origin += Vec2::new(column as f32, row as f32) * size;
            u = Vec2::new(ux, uy);
            match self.nodes[node].children[q] {
                LEAF => return (within(origin, size, u), pdf),
                child => node = child as usize,
            }
        }
    }

    /// Density of [`Distribution::sample_square`] at `p`.
    pub fn pdf_square(&self, mut p: Vec2) -> f32 {
        let (mut node, mut pdf) = (0usize, 1.0f32);
        loop {
            let e = self.nodes[node].energy;
            let total = e[0] + e[1] + e[2] + e[3];
            if total <= 0.0 {
                return pdf;
            }
            let q = quadrant(p);
            pdf *= 4.0 * e[q] / total;
            match self.nodes[node].children[q] {
                LEAF => return pdf,
                child => {
                    node = child as usize;
                    p = into_quadrant(p, q);
                }
            }
        }
    }

    /// Draws a direction, and its solid-angle density. The density is looked up again at
    /// the direction: a point drawn within a hair of a cell's edge can come back from the
    /// sphere in the neighbouring cell, and the estimator must use the density that
    /// [`Distribution::pdf`] gives for the direction it traces.
    pub fn sample(&self, u: Vec2) -> (Vec3, f32) {
        let d = to_sphere(self.sample_square(u).0);
        (d, self.pdf(d))
    }

    /// Solid-angle density of [`Distribution::sample`] at the unit direction `d`.
    pub fn pdf(&self, d: Vec3) -> f32 {
        self.pdf_square(to_square(d)) * SQUARE_TO_SPHERE
    }

    /// An empty histogram for the next pass: this tree's quadrants subdivided where they
    /// hold more than [`SUBDIVIDE_FRACTION`] of the energy and [`MIN_RECORDS`] records, and
    /// merged where they hold less (the paper's §4: a leaf with much energy is split, and
    /// its quarters, which get a quarter each, are judged again).
    pub fn refined(&self) -> Histogram {
        let total: f64 = self.nodes[0].energy.iter().map(|&e| f64::from(e)).sum();
        let mut nodes = vec![HistogramNode::new()];
        if total > 0.0 {
            self.refine_from(&mut nodes, 0, Some(0), total, 1, (0.0, 0.0));
        }
        Histogram { nodes }
    }

    /// Fills node `at` of `out` from node `from` of this tree (`None`: a leaf quadrant
    /// being split, whose energy and records `parent_share` are spread evenly over its
    /// quarters).
    fn refine_from(
        &self,
        out: &mut Vec<HistogramNode>,
        at: usize,
        from: Option<usize>,
        total: f64,
        depth: u32,
        parent_share: (f64, f64),
    ) {
        for q in 0..4 {
            let (energy, records, child) = match from {
                Some(n) => (
                    f64::from(self.nodes[n].energy[q]),
                    f64::from(self.nodes[n].records[q]),
                    match self.nodes[n].children[q] {
                        LEAF => None,
                        c => Some(c as usize),
                    },
                ),
                None => (parent_share.0 / 4.0, parent_share.1 / 4.0, None),
            };
            if depth < MAX_DEPTH && energy / total > SUBDIVIDE_FRACTION && records >= MIN_RECORDS {
                let index = out.len();
                out.push(HistogramNode::new());
                out[at].children[q] = index as u32;
                let share = if child.is_none() {
                    (energy, records)
                } else {
                    (0.0, 0.0)
                };
                self.refine_from(out, index, child, total, depth + 1, share);
            }
        }
    }
}

/// The point at `u` ∈ [0, 1)² of the cell at `origin` of side `size`, kept inside the
/// cell where rounding would put it on the next cell's edge. Cell corners are dyadic
/// fractions, exact in `f32` to the tree's depth.
fn within(origin: Vec2, size: f32, u: Vec2) -> Vec2 {
    let end = origin + Vec2::splat(size);
    (origin + u * size).min(Vec2::new(end.x.next_down(), end.y.next_down()))
}

/// `u` split at `p`: which side (0 below `p`) and `u` rescaled to [0, 1) within it.
fn choose(u: f32, p: f32) -> (usize, f32) {
    let below_one = 1.0 - f32::EPSILON;
    if u < p {
        (0, (u / p).min(below_one))
    } else {
        (1, ((u - p) / (1.0 - p)).clamp(0.0, below_one))
    }
}

/// A node of a histogram being filled.
#[derive(Debug)]
struct HistogramNode {
    children: [u32; 4],
    energy: [AtomicU64; 4],
    records: [AtomicU32; 4],
}

impl HistogramNode {
    fn new() -> HistogramNode {
        HistogramNode {
            children: [LEAF; 4],
            energy: Default::default(),
            records: Default::default(),
        }
    }
}

/// Energy gathered over the sphere during one pass, in the quadrants of a fixed tree.
#[derive(Debug)]
pub struct Histogram {
    nodes: Vec<HistogramNode>,
}

impl Histogram {
    /// Adds `energy` (≥ 0) arriving from the unit direction `d`, and one record, to the leaf
    /// quadrant it falls in (the nodes above it sum their quadrants when the histogram is
    /// frozen: two atomic additions a record instead of two per level, which took a tenth
    /// of a guided render's training). Non-finite or negative energies count as none.
    pub fn record(&self, d: Vec3, energy: f32) {
        let units = if energy > 0.0 && energy.is_finite() {
            (f64::from(energy).min(MAX_RECORD) * FIXED_SCALE).round() as u64
        } else {
            0
        };
        let (mut node, mut p) = (0usize, to_square(d));
        loop {
            let q = quadrant(p);
            match self.nodes[node].children[q] {
                LEAF => {
                    self.nodes[node].energy[q].fetch_add(units, Ordering::Relaxed);
                    self.nodes[node].records[q].fetch_add(1, Ordering::Relaxed);
                    return;
                }
                child => {
                    node = child as usize;
                    p = into_quadrant(p, q);
                }
            }
        }
    }

    /// The distribution of the energy recorded: each quadrant with a child holds the sum
    /// of the child's quadrants, found from the last node back (children come after their
    /// parents), in integers, so exactly.
    pub fn freeze(&self) -> Distribution {
        let mut sums: Vec<([u64; 4], [u32; 4])> = self
            .nodes
            .iter()
            .map(|n| {
                (
                    std::array::from_fn(|q| n.energy[q].load(Ordering::Relaxed)),
                    std::array::from_fn(|q| n.records[q].load(Ordering::Relaxed)),
                )
            })
            .collect();
        for i in (0..self.nodes.len()).rev() {
            for q in 0..4 {
                let child = self.nodes[i].children[q];
                if child != LEAF {
                    let (energy, records) = sums[child as usize];
                    sums[i].0[q] = energy.iter().sum();
                    sums[i].1[q] = records.iter().sum();
                }
            }
        }
        Distribution {
            nodes: self
                .nodes
                .iter()
                .zip(sums)
                .map(|(n, (energy, records))| Node {
                    children: n.children,
                    energy: energy.map(|e| (e as f64 / FIXED_SCALE) as f32),
                    records,
                })
                .collect(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Energy piled towards one direction over a faint floor.
    fn radiance(d: Vec3) -> f32 {
        let towards = Vec3::new(0.3, -0.5, 0.81).normalize();
        0.01 + 50.0 * d.dot(towards).max(0.0).powi(20)
    }

    /// A distribution learned from [`radiance`] over five passes, refined after each.
    fn peaked() -> Distribution {
        let mut histogram = Distribution::uniform().refined();
        let mut distribution = Distribution::uniform();
        for _ in 0..5 {
            for i in 0..64_000u32 {
                let u = Vec2::new(
                    (i as f32 + 0.5) / 64_000.0,
                    ((i * 40503) % 64_000) as f32 / 64_000.0,
                );
                let d = to_sphere(u);
                histogram.record(d, radiance(d));
            }
            distribution = histogram.freeze();
            histogram = distribution.refined();
        }
        assert!(
            distribution.nodes.len() > 10,
            "the tree was refined: {} nodes",
            distribution.nodes.len()
        );
        distribution
    }

    #[test]
    fn the_square_and_the_sphere_map_back_and_forth() {
        for i in 0..100 {
            let p = Vec2::new((i % 10) as f32 / 10.0 + 0.03, (i / 10) as f32 / 10.0 + 0.07);
            let back = to_square(to_sphere(p));
            assert!((back - p).abs().max_element() < 1e-5, "{p} → {back}");
        }
    }

    #[test]
    fn the_density_integrates_to_one_and_matches_sampling() {
        let d = peaked();
        // ∫ pdf over the square by a fine midpoint sum.
        let n = 1024;
        let mut integral = 0.0f64;
        for i in 0..n {
            for j in 0..n {
                let p = Vec2::new((i as f32 + 0.5) / n as f32, (j as f32 + 0.5) / n as f32);
                integral += f64::from(d.pdf_square(p));
            }
        }
        integral /= (n * n) as f64;
        assert!((integral - 1.0).abs() < 1e-3, "∫ pdf = {integral}");
        // Every sample's reported density is the density at the point drawn.
        for i in 0..2000u32 {
            let u = Vec2::new(
                (i as f32 + 0.5) / 2000.0,
                ((i * 7919) % 2000) as f32 / 2000.0 + 0.0001,
            );
            let (p, pdf) = d.sample_square(u);
            let at = d.pdf_square(p);
            assert!(
                (pdf - at).abs() <= 1e-3 * at,
                "sample {p}: {pdf} vs pdf {at}"
            );
        }
    }

    #[test]
    fn a_peak_few_records_saw_is_not_resolved_finer_than_they_can() {
        let histogram = Distribution::uniform().refined();
        let peak = Vec3::new(0.2, 0.3, 0.93).normalize();
        for i in 0..10 {
            histogram.record(peak, 1000.0 + i as f32);
        }
        histogram.record(-peak, 1.0);
        let refined = histogram.freeze().refined();
        assert_eq!(
            refined.nodes.len(),
            1,
            "10 records split the root's quadrants"
        );
    }

    #[test]
    fn nothing_recorded_is_uniform() {
        let d = Distribution::uniform().refined().freeze();
        assert!(d.is_uniform());
        let (_, pdf) = d.sample(Vec2::new(0.3, 0.6));
        assert!((pdf - SQUARE_TO_SPHERE).abs() < 1e-7);
    }

    #[test]
    fn sums_do_not_depend_on_the_order_of_records() {
        let a = Distribution::uniform().refined();
        let b = Distribution::uniform().refined();
        let dirs: Vec<(Vec3, f32)> = (0..500)
            .map(|i| {
                let p = Vec2::new((i as f32 * 0.618).fract(), (i as f32 * 0.377).fract());
                (to_sphere(p), 0.1 + (i as f32 * 1.7).sin().abs() * 1000.0)
            })
            .collect();
        dirs.iter().for_each(|&(d, e)| a.record(d, e));
        dirs.iter().rev().for_each(|&(d, e)| b.record(d, e));
        let (a, b) = (a.freeze(), b.freeze());
        for (x, y) in a.nodes.iter().zip(&b.nodes) {
            assert_eq!(x.energy, y.energy);
        }
    }
}
