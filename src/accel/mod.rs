//! Ray–scene intersection: the Möller–Trumbore triangle test, a uniform grid per mesh,
//! and a small top-level structure over the instances.

pub mod grid;
mod instances;
mod ray;
mod triangle;

pub use grid::{Grid, GridHit, GridStats, TraversalCounts, TraversalStats};
pub use instances::{SceneAccel, SceneHit};
pub use ray::Ray;
pub use triangle::{Triangle, TriangleHit};
