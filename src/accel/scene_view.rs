//! The scene seen from one eye point: a [`ViewGrid`] over every entry of the top level, for
//! the rays a pinhole camera sends ([`super::grid`]'s view module says how it works).

use super::{Ray, SceneAccel, SceneHit, View, ViewGrid};

/// A [`ViewGrid`] over a scene's grids, and the instance each of them places.
#[derive(Clone, Debug)]
pub struct SceneView {
    grid: ViewGrid,
    instances: Vec<u32>,
}

impl SceneView {
    /// The view grid of `accel`'s scene, or `None` when some entry is not a still grid in
    /// world space (its rays would need carrying into its space or time) or the view has
    /// too many triangles near the eye's plane.
    pub fn build(accel: &SceneAccel, view: View) -> Option<SceneView> {
        let (grids, instances): (Vec<_>, Vec<_>) = accel.world_grids()?.into_iter().unzip();
        Some(SceneView {
            grid: ViewGrid::build(&grids, view)?,
            instances,
        })
    }

    /// The grid.
    pub fn grid(&self) -> &ViewGrid {
        &self.grid
    }

    /// The closest hit along `ray`: from the view grid for a ray it covers (from the eye,
    /// within the window), else from `accel`, the scene the view was built of.
    #[inline]
    pub fn intersect(&self, accel: &SceneAccel, ray: &Ray) -> Option<SceneHit> {
        match self.grid.intersect(ray) {
            Some(answer) => answer.map(|hit| SceneHit {
                t: hit.t,
                instance: self.instances[hit.source as usize],
                triangle: hit.triangle,
                u: hit.u,
                v: hit.v,
                time: ray.time,
            }),
            None => accel.intersect(ray),
        }
    }
}
