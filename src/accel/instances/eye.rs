//! Camera rays through the grid of the camera's eye ([`ViewGrid`]) over a whole scene.
//!
//! The view grid answers a ray from the eye exactly as the scene's grids do (the same
//! triangle, `t`, `u` and `v`), and leaves to them the rays it cannot answer so (a tie at
//! the nearest distance, a ray not from the eye or outside its window). So asking it first
//! changes no image: whether a render, or a farm task, builds one is a matter of speed only.

use super::{SceneAccel, SceneHit};
use crate::accel::{GridHit, Ray, View, ViewGrid};

/// The grid of one eye point over every entry of a scene.
pub struct EyeGrid {
    /// Its sources are the scene's entries, in order.
    grid: ViewGrid,
}

impl EyeGrid {
    /// Bytes held.
    pub fn bytes(&self) -> usize {
        self.grid.bytes()
    }

    /// True when the grid answers `ray` itself, rather than leaving it to the scene's grids.
    pub fn answers(&self, ray: &Ray) -> bool {
        self.grid.intersect(ray).is_some()
    }
}

impl SceneAccel {
    /// Triangles in the scene's grids (each grid once, however many instances place it).
    pub fn triangles(&self) -> usize {
        self.grids.iter().map(|g| g.triangles()).sum()
    }

    /// The grid of `view` over the scene; `None` when some entry does not take world rays
    /// as they are (an instance in object space, moving or in a time slice) or too many
    /// triangles lie near the eye ([`ViewGrid::build`]).
    pub fn eye_grid(&self, view: View) -> Option<EyeGrid> {
        if !self.entries.iter().all(|e| e.takes_world_rays()) {
            return None;
        }
        let grids: Vec<_> = self.entries.iter().map(|e| &self.grids[e.grid]).collect();
        ViewGrid::build(&grids, view).map(|grid| EyeGrid { grid })
    }

    /// [`SceneAccel::intersect`], asking `eye` first: the same answer.
    #[inline]
    pub fn intersect_from(&self, eye: Option<&EyeGrid>, ray: &Ray) -> Option<SceneHit> {
        match eye.and_then(|eye| eye.grid.intersect(ray)) {
            Some(answer) => answer.map(|hit| {
                let found = GridHit {
                    t: hit.t,
                    u: hit.u,
                    v: hit.v,
                    triangle: hit.triangle,
                };
                self.scene_hit(hit.source as usize, found, ray)
            }),
            None => self.intersect(ray),
        }
    }
}
