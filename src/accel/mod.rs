//! Ray–scene intersection: the Möller–Trumbore triangle test, a uniform grid per mesh,
//! and a top level over the instances (a list, or a grid of their own when there are many);
//! and a grid of one eye point's view, for the rays of a pinhole camera ([`ViewGrid`]).

mod box_lanes;
mod grid;
mod huge_pages;
mod instances;
mod isa;
mod placement;
mod ray;
mod top_level;
mod triangle;

pub use grid::{
    Grid, GridHit, GridStats, TraversalCounts, TraversalStats, View, ViewGrid, ViewHit,
};
pub use instances::{EyeGrid, SceneAccel, SceneHit, TopLevel};
pub use ray::Ray;
pub use triangle::{Triangle, TriangleHit};

/// γ(3): the relative rounding error of a slab distance.
pub(crate) const SLAB_ROUNDING: f32 = crate::geometry::gamma(3);
