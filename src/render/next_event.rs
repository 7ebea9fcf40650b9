//! Next-event roulette: where a short pre-pass found that no light sample ever reached its
//! light — a room lit only through glass, the floor under a glass ball — the next-event
//! estimate is taken with a small probability and weighed by its inverse (Russian roulette,
//! Arvo & Kirk 1990, "Particle transport and image synthesis", applied to the shadow ray;
//! the odds are learned per region of space, as Vévoda, Kondapaneni & Křivánek 2018,
//! "Bayesian online regression for adaptive direct illumination sampling", learn
//! visibility per region).
//!
//! The estimate stays unbiased wherever the odds are wrong: a skipped light sample is
//! made up for by the weight of the ones taken, and MIS counts the odds in the light
//! sampling density, so emission found by BSDF sampling takes over where light samples
//! are rare.
//!
//! The pre-pass traces one path through every [`stride`]-th pixel of every
//! [`stride`]-th row, from a random stream of its own, whatever range of samples the
//! render takes; records are gathered in pixel order and the regions cut from them by
//! medians, so every process of a split render, on any number of threads, holds the same
//! odds, and split renders still merge exactly.

use glam::Vec3;
use rayon::prelude::*;

use crate::geometry::Aabb;
use crate::render::sampler::Sampler;
use crate::render::sampling::mix64;
use crate::render::{CameraSampling, RenderSettings, Renderer};

/// Mixed into the seed so that the pre-pass's random stream is none of the image's.
const PRE_PASS_SEED: u64 = 0x6e65_7874_2d65_7665;

/// Odds of taking the next-event estimate in a region where none of the pre-pass's light
/// samples reached its light.
pub const UNSEEN_ODDS: f32 = 1.0 / 16.0;

/// A region needs this many records before its odds are lowered: with no success among
/// 256 tries, the chance of success is below 1.2 % with 95 % confidence (so a penumbra,
/// where light arrives a few times in a hundred, keeps its light samples).
const MIN_RECORDS: usize = 256;

/// Regions are halved until they hold at most this many records.
const MAX_LEAF_RECORDS: usize = 512;

/// Deepest level of the tree (a bound on recursion for degenerate point sets).
const MAX_DEPTH: u32 = 32;

/// The pre-pass samples at most about this many pixels: more lowers the stride.
const MAX_PRE_PASS_PIXELS: u64 = 1 << 16;

/// The spacing, in pixels and rows, of the pre-pass's paths for a `width` × `height`
/// image: every second pixel of every second row, sparser for images above
/// [`MAX_PRE_PASS_PIXELS`] samples.
pub fn stride(width: u32, height: u32) -> u32 {
    let pixels = u64::from(width) * u64::from(height);
    let mut stride = 2u32;
    while pixels / u64::from(stride * stride) > MAX_PRE_PASS_PIXELS {
        stride += 1;
    }
    stride
}

/// What one light sample of the pre-pass found.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Outcome {
    /// Where it was taken.
    pub point: Vec3,
    /// True when it brought light: the light faced the point, the BSDF passed it and
    /// nothing blocked the shadow ray.
    pub reached: bool,
}

impl Renderer<'_> {
    /// Traces the pre-pass of a render with `settings` and learns the odds from it.
    pub(crate) fn learn_next_event_odds(
        &self,
        view: &CameraSampling,
        settings: &RenderSettings,
    ) -> NextEventOdds {
        let seed = mix64(settings.seed ^ PRE_PASS_SEED);
        let (width, height) = (settings.width as usize, settings.height as usize);
        let step = stride(settings.width, settings.height) as usize;
        let rows: Vec<usize> = (0..height).step_by(step).collect();
        let outcomes: Vec<Vec<Outcome>> = rows
            .into_par_iter()
            .map(|y| {
                let mut outcomes = Vec::new();
                for x in (0..width).step_by(step) {
                    let mut sampler = Sampler::for_sample(seed, (y * width + x) as u64, 0);
                    let ray = view.ray(x, y, &mut sampler);
                    outcomes.extend(self.light_sample_outcomes(
                        ray,
                        &mut sampler,
                        settings.max_depth,
                        settings.strategy,
                    ));
                }
                outcomes
            })
            .collect();
        NextEventOdds::learn(outcomes.concat())
    }
}

/// A node of the tree: inner nodes split space at `at` along `axis`; a subtree whose
/// regions all keep odds 1 is one node, so that lit parts of a scene are found in few
/// steps.
#[derive(Clone, Copy, Debug)]
enum Node {
    Inner {
        axis: u8,
        at: f32,
        below: u32,
        above: u32,
    },
    Leaf {
        region: u32,
    },
    Always,
}

/// A leaf with lowered odds: the box of its records, a little grown, and its odds. Points
/// outside the box were not seen by the pre-pass and take the estimate always.
#[derive(Clone, Copy, Debug)]
struct Region {
    bounds: Aabb,
    odds: f32,
}

/// The learned odds of taking the next-event estimate, by region of space.
#[derive(Debug)]
pub struct NextEventOdds {
    nodes: Vec<Node>,
    regions: Vec<Region>,
}

impl NextEventOdds {
    /// Cuts space into regions of the pre-pass's `outcomes`, in the order they were made.
    pub fn learn(mut outcomes: Vec<Outcome>) -> NextEventOdds {
        let mut odds = NextEventOdds {
            nodes: Vec::new(),
            regions: Vec::new(),
        };
        odds.build(&mut outcomes, 0);
        odds
    }

    /// True when some region's odds are below 1 (else the odds change nothing).
    pub fn lowers_any(&self) -> bool {
        !self.regions.is_empty()
    }

    /// The odds of taking the next-event estimate at `p`.
    pub fn at(&self, p: Vec3) -> f32 {
        let Some(mut node) = self.nodes.first().copied() else {
            return 1.0;
        };
        loop {
            match node {
                Node::Inner {
                    axis,
                    at,
                    below,
                    above,
                } => {
                    let next = if p[axis as usize] < at { below } else { above };
                    node = self.nodes[next as usize];
                }
                Node::Leaf { region } => {
                    let r = self.regions[region as usize];
                    let inside = p.cmpge(r.bounds.min).all() && p.cmple(r.bounds.max).all();
                    return if inside { r.odds } else { 1.0 };
                }
                Node::Always => return 1.0,
            }
        }
    }

    /// Adds the subtree over `outcomes` and returns its index.
    fn build(&mut self, outcomes: &mut [Outcome], depth: u32) -> u32 {
        let index = self.nodes.len() as u32;
        let bounds = Aabb::from_points(outcomes.iter().map(|o| o.point));
        let extent = bounds.max - bounds.min;
        let axis = extent.max_position();
        if outcomes.len() <= MAX_LEAF_RECORDS || depth == MAX_DEPTH || extent[axis] <= 0.0 {
            match region_of(outcomes, bounds) {
                Some(region) => {
                    self.nodes.push(Node::Leaf {
                        region: self.regions.len() as u32,
                    });
                    self.regions.push(region);
                }
                None => self.nodes.push(Node::Always),
            }
            return index;
        }
        let middle = outcomes.len() / 2;
        outcomes.select_nth_unstable_by(middle, |a, b| a.point[axis].total_cmp(&b.point[axis]));
        let at = outcomes[middle].point[axis];
        // Records equal to the median may fall on either side; a point on the plane is
        // looked up above, and falls back to odds 1 if outside that leaf's box.
        let (below, above) = outcomes.split_at_mut(middle);
        self.nodes.push(Node::Leaf { region: 0 });
        let below = self.build(below, depth + 1);
        let above = self.build(above, depth + 1);
        if let (Node::Always, Node::Always) =
            (self.nodes[below as usize], self.nodes[above as usize])
        {
            self.nodes.truncate(index as usize);
            self.nodes.push(Node::Always);
            return index;
        }
        self.nodes[index as usize] = Node::Inner {
            axis: axis as u8,
            at,
            below,
            above,
        };
        index
    }
}

/// A leaf's region with lowered odds, when many records all failed (else none: odds 1).
fn region_of(outcomes: &[Outcome], bounds: Aabb) -> Option<Region> {
    let unseen = outcomes.len() >= MIN_RECORDS && !outcomes.iter().any(|o| o.reached);
    let grow = (bounds.max - bounds.min) * 0.05 + Vec3::splat(1e-4);
    unseen.then_some(Region {
        bounds: Aabb {
            min: bounds.min - grow,
            max: bounds.max + grow,
        },
        odds: UNSEEN_ODDS,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn grid_outcomes(reached: impl Fn(Vec3) -> bool) -> Vec<Outcome> {
        let mut outcomes = Vec::new();
        for i in 0..64 {
            for j in 0..64 {
                let point = Vec3::new(i as f32 / 16.0, j as f32 / 16.0, 0.0);
                outcomes.push(Outcome {
                    point,
                    reached: reached(point),
                });
            }
        }
        outcomes
    }

    #[test]
    fn regions_where_no_light_sample_arrived_have_low_odds() {
        // Light arrives only where x < 2: the other half of the square is in shadow.
        let odds = NextEventOdds::learn(grid_outcomes(|p| p.x < 2.0));
        assert!(odds.lowers_any());
        assert_eq!(odds.at(Vec3::new(3.5, 1.0, 0.0)), UNSEEN_ODDS);
        assert_eq!(odds.at(Vec3::new(3.9, 3.9, 0.0)), UNSEEN_ODDS);
        assert_eq!(odds.at(Vec3::new(0.5, 1.0, 0.0)), 1.0);
        assert_eq!(odds.at(Vec3::new(1.9, 2.5, 0.0)), 1.0);
    }

    #[test]
    fn points_the_pre_pass_never_saw_take_the_estimate() {
        let odds = NextEventOdds::learn(grid_outcomes(|_| false));
        assert_eq!(odds.at(Vec3::new(2.0, 2.0, 0.0)), UNSEEN_ODDS);
        assert_eq!(odds.at(Vec3::new(2.0, 2.0, 5.0)), 1.0);
        assert_eq!(odds.at(Vec3::new(-3.0, 2.0, 0.0)), 1.0);
        assert_eq!(NextEventOdds::learn(Vec::new()).at(Vec3::ZERO), 1.0);
    }

    #[test]
    fn a_lit_scene_is_one_node() {
        let odds = NextEventOdds::learn(grid_outcomes(|p| p.x < 3.9));
        assert_eq!(odds.nodes.len(), 1);
        assert!(!odds.lowers_any());
        assert_eq!(odds.at(Vec3::new(3.95, 1.0, 0.0)), 1.0);
    }

    #[test]
    fn few_records_keep_the_estimate() {
        let outcomes = grid_outcomes(|_| false)
            .into_iter()
            .take(MIN_RECORDS - 1)
            .collect();
        assert!(!NextEventOdds::learn(outcomes).lowers_any());
    }

    #[test]
    fn many_equal_points_end_in_one_leaf() {
        let outcomes = vec![
            Outcome {
                point: Vec3::ONE,
                reached: false,
            };
            10_000
        ];
        let odds = NextEventOdds::learn(outcomes);
        assert_eq!((odds.nodes.len(), odds.regions.len()), (1, 1));
        assert_eq!(odds.at(Vec3::ONE), UNSEEN_ODDS);
    }

    #[test]
    fn strides_keep_the_pre_pass_small() {
        assert_eq!(stride(128, 128), 2);
        assert_eq!(stride(512, 512), 2);
        let s = stride(3840, 2160);
        assert!(3840 * 2160 / (s * s) <= MAX_PRE_PASS_PIXELS as u32);
        assert!(3840 * 2160 / ((s - 1) * (s - 1)) > MAX_PRE_PASS_PIXELS as u32);
    }
}
