//! Path guiding: where unidirectional sampling finds light badly — a diffuse surface lit
//! through glass, a room lit through a window — the incident radiance learned in short
//! training passes proposes directions beside the BSDF (Müller, Gross & Novák 2017,
//! "Practical Path Guiding for Efficient Light-Transport Simulation").
//!
//! The guide is an SD-tree: a binary tree over the scene's bounds (halving x, y, z in
//! turn) whose leaves, the regions, each hold a directional [`quadtree`]. The image's
//! first samples are the training passes ([`train`]): their paths draw from the guide as
//! it stands and record, at every guided vertex, the radiance that reached it; after each
//! pass the regions that gathered many records are split and every quadtree is rebuilt
//! from its energy (§3–4 of the paper).
//!
//! The project's guarantees hold: energies are summed as integers, so the guide — and the
//! image — are the same for any thread count; and a process rendering a later range of
//! samples first traces the training samples before it, so every sample is the same
//! whichever process renders it, and split renders still merge exactly.

mod fraction;
mod mixture;
mod quadtree;
mod train;

pub use mixture::GuidedBsdf;
pub use train::guiding_at;

use std::sync::atomic::{AtomicU64, Ordering};

use glam::Vec3;

use crate::geometry::Aabb;
use fraction::Scores;
use quadtree::{Distribution, Histogram};

/// Whether paths are guided.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Guiding {
    /// Paths sample BSDFs only.
    #[default]
    Off,
    /// A guide is trained before the first sample and then proposes directions.
    On,
}

/// A region splits once one pass gave it more records than this times √(2^pass) (the
/// paper's c = 12,000, lowered for the smaller images and shorter training here: 1,000
/// lowered the error on the lamp shade by a fifth against 4,000, measured with
/// tools/dev/efficiency_ab.py).
const SPLIT_RECORDS: f64 = 1000.0;

/// Deepest level of the spatial tree.
const MAX_SPATIAL_DEPTH: u32 = 24;
// A region is found by reading one bit of a 32-bit fraction per level of an axis.
const _: () = assert!(MAX_SPATIAL_DEPTH <= 3 * 32);

/// One leaf of the spatial tree: the distribution paths draw from and the share of
/// directions it proposes ([`fraction`]), the histogram and scores that gather the current
/// pass's records, and how many records it took.
#[derive(Debug)]
struct Region {
    distribution: Distribution,
    fraction: f32,
    histogram: Histogram,
    scores: Scores,
    records: AtomicU64,
}

impl Region {
    fn new(distribution: Distribution, fraction: f32) -> Region {
        Region {
            histogram: distribution.refined(),
            distribution,
            fraction,
            scores: Scores::default(),
            records: AtomicU64::new(0),
        }
    }
}

/// A node of the spatial tree: an inner node halves its box along `axis`; a leaf names
/// its region and its depth.
#[derive(Clone, Copy, Debug)]
enum SpatialNode {
    Inner { axis: u8, children: [u32; 2] },
    Leaf { region: u32, depth: u32 },
}

/// The trained (or training) guide of a scene.
#[derive(Debug)]
pub struct Guide {
    bounds: Aabb,
    nodes: Vec<SpatialNode>,
    regions: Vec<Region>,
}

/// Where a guided vertex records what reached it, kept along the path until its end.
#[derive(Clone, Copy, Debug)]
pub struct Record {
    /// Where the vertex lies.
    point: Vec3,
    /// The direction the path left the vertex in.
    direction: Vec3,
    /// The density it was drawn with (the mixture's), and the guide's and the BSDF's
    /// there.
    pdf: f32,
    guide_pdf: f32,
    bsdf_pdf: f32,
    /// The throughput before and after the bounce at the vertex.
    beta_before: Vec3,
    beta: Vec3,
    /// The path's radiance before anything the bounce found.
    radiance_before: Vec3,
}

impl Guide {
    /// An untrained guide over `bounds`: one region, uniform.
    pub fn new(bounds: Aabb) -> Guide {
        let extent = (bounds.max - bounds.min).max_element().max(1e-3);
        let pad = Vec3::splat(extent * 1e-3);
        Guide {
            bounds: Aabb {
                min: bounds.min - pad,
                max: bounds.max + pad,
            },
            nodes: vec![SpatialNode::Leaf {
                region: 0,
                depth: 0,
            }],
            regions: vec![Region::new(Distribution::uniform(), fraction::INITIAL)],
        }
    }

    /// The leaf holding `point` (points outside the bounds go to the nearest one): its
    /// region, and how many times each axis was halved on the way down. Each inner node
    /// halves its box, so the way down is the binary digits of the point's place in the
    /// bounds, one more digit of an axis at each node that splits it: read as bits of a
    /// 32-bit fraction, with no arithmetic per level (the exact digits that doubling the
    /// place and taking its whole part would give).
    fn leaf(&self, point: Vec3) -> (u32, [u32; 3]) {
        let p = ((point - self.bounds.min) / (self.bounds.max - self.bounds.min))
            .clamp(Vec3::ZERO, Vec3::splat(1.0 - f32::EPSILON));
        let fraction = p
            .to_array()
            .map(|c| (f64::from(c) * 4_294_967_296.0) as u32);
        let mut digits = [0u32; 3];
        let mut node = 0usize;
        loop {
            match self.nodes[node] {
                SpatialNode::Leaf { region, .. } => return (region, digits),
                SpatialNode::Inner { axis, children } => {
                    let a = axis as usize;
                    let upper = (fraction[a] << digits[a]) >> 31;
                    digits[a] += 1;
                    node = children[upper as usize] as usize;
                }
            }
        }
    }

    /// The region holding `point`.
    fn region_index(&self, point: Vec3) -> u32 {
        self.leaf(point).0
    }

    /// The region a record is added to: the one at a point drawn uniformly from a box the
    /// size of the record's own region centred on its vertex (the paper's §5.2 stochastic
    /// box filter), so that records near a region's faces also teach its neighbours. The
    /// point is drawn from numbers hashed from the record itself, so it does not depend on
    /// which thread adds it.
    fn splat_region(&self, r: &Record) -> u32 {
        self.region_index(r.point + self.splat_offset(r))
    }

    /// The offset of [`Guide::splat_region`]'s point from the record's vertex: uniform in a
    /// box the size of the vertex's region, centred on it.
    fn splat_offset(&self, r: &Record) -> Vec3 {
        let size = self.region_size(r.point);
        let bits = |v: Vec3| v.to_array().map(f32::to_bits);
        let [x, y, z] = bits(r.point);
        let [a, b, c] = bits(r.direction);
        let key = (u64::from(x) << 32 | u64::from(y))
            ^ (u64::from(z) << 32 | u64::from(a))
            ^ u64::from(b).rotate_left(17)
            ^ u64::from(c).rotate_left(41);
        let h = crate::render::sampling::mix64(key);
        let unit = |shift: u32| ((h >> shift) & 0x1f_ffff) as f32 / 2_097_152.0 - 0.5;
        Vec3::new(unit(0), unit(21), unit(42)) * size
    }

    /// The size of the region holding `point`.
    fn region_size(&self, point: Vec3) -> Vec3 {
        let halvings = self.leaf(point).1;
        (self.bounds.max - self.bounds.min) / Vec3::from(halvings.map(|d| (1u32 << d) as f32))
    }

    /// The directional distribution at `point` and the share of directions it proposes
    /// there.
    pub fn at(&self, point: Vec3) -> (&Distribution, f32) {
        let r = &self.regions[self.region_index(point) as usize];
        (&r.distribution, r.fraction)
    }

    /// A record of a bounce at a vertex at `point` in `direction`, drawn with density
    /// `pdf` (the guide's `guide_pdf` and the BSDF's `bsdf_pdf` there), the throughput going
    /// from `beta_before` to `beta`, to be completed when the path ends.
    pub fn record(
        point: Vec3,
        direction: Vec3,
        (pdf, guide_pdf, bsdf_pdf): (f32, f32, f32),
        (beta_before, beta): (Vec3, Vec3),
        radiance_before: Vec3,
    ) -> Record {
        Record {
            point,
            direction,
            pdf,
            guide_pdf,
            bsdf_pdf,
            beta_before,
            beta,
            radiance_before,
        }
    }

    /// Adds what each recorded vertex of a finished path received: the radiance gathered
    /// after its bounce, divided by the throughput up to it (an estimate of the incident
    /// radiance from its direction) and by the density of that direction, so that a
    /// quadrant's sum estimates its integral of incident radiance (the paper's §3.3).
    /// Divided by the throughput before the bounce instead, it is the vertex's estimate of
    /// its own integral, which scores the region's shares ([`fraction`]).
    pub fn add_path(&self, records: &[Record], radiance: Vec3) {
        let per = |gained: Vec3, beta: Vec3| {
            Vec3::select(beta.cmpgt(Vec3::ZERO), gained / beta, Vec3::ZERO).element_sum() / 3.0
        };
        for r in records {
            let gained = radiance - r.radiance_before;
            let region = &self.regions[self.splat_region(r) as usize];
            region.records.fetch_add(1, Ordering::Relaxed);
            region
                .histogram
                .record(r.direction, per(gained, r.beta) / r.pdf);
            let estimate = per(gained, r.beta_before);
            region
                .scores
                .add(estimate, r.guide_pdf, r.bsdf_pdf, region.fraction);
        }
    }

    /// Ends training pass `pass` (from 0): every region samples what it gathered from now
    /// on, with the share its records scored best, regions with many records are split
    /// (their halves start from the same distribution and share), and fresh histograms are
    /// made, refined where energy was found.
    pub fn end_pass(&mut self, pass: u32) {
        for region in &mut self.regions {
            let learned = region.histogram.freeze();
            if !learned.is_uniform() {
                region.distribution = learned;
            }
            let records = region.records.load(Ordering::Relaxed);
            region.fraction = region.scores.choose(records, region.fraction);
        }
        let limit = SPLIT_RECORDS * 2f64.powf(f64::from(pass) * 0.5);
        let mut node = 0;
        while node < self.nodes.len() {
            if let SpatialNode::Leaf { region, depth } = self.nodes[node] {
                self.split_if_full(node, region, depth, limit);
            }
            node += 1;
        }
        for region in &mut self.regions {
            region.histogram = region.distribution.refined();
            region.scores = Scores::default();
            region.records.store(0, Ordering::Relaxed);
        }
    }

    /// Splits leaf `node` (of region `region`) in two along the axis after its parent's,
    /// halving its record count, while the count is above `limit`.
    fn split_if_full(&mut self, node: usize, region: u32, depth: u32, limit: f64) {
        let records = self.regions[region as usize]
            .records
            .load(Ordering::Relaxed);
        if (records as f64) <= limit || depth >= MAX_SPATIAL_DEPTH {
            return;
        }
        let axis = (depth % 3) as u8;
        let half = records / 2;
        let twin = self.regions.len() as u32;
        let parent = &self.regions[region as usize];
        let (distribution, fraction) = (parent.distribution.clone(), parent.fraction);
        self.regions.push(Region::new(distribution, fraction));
        self.regions[region as usize]
            .records
            .store(half, Ordering::Relaxed);
        self.regions[twin as usize]
            .records
            .store(half, Ordering::Relaxed);
        let first = self.nodes.len() as u32;
        let depth = depth + 1;
        self.nodes.push(SpatialNode::Leaf { region, depth });
        self.nodes.push(SpatialNode::Leaf {
            region: twin,
            depth,
        });
        self.nodes[node] = SpatialNode::Inner {
            axis,
            children: [first, first + 1],
        };
        // The halves are judged by the loop in `end_pass`, which reaches them later.
    }
}

#[cfg(test)]
mod tests;
