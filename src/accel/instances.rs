//! The top level: grids over the meshes, and the instances that place them.
//!
//! A mesh used by several instances (or moving) has its grid in object space and rays are
//! carried into each instance's space, so it is stored once (the "teapot in a stadium"
//! stays cheap). A mesh placed once and still gets its grid in world space instead, so its
//! rays need no transform: that is most objects of a Blender export. (Merging the small
//! meshes placed once into one grid was tried: the Cornell box rendered 25 % slower, its
//! large wall triangles tested again in every cell they cross.) Above the grids, a few
//! entries are tested in a list after a bounding-box check; more go into a grid of their own
//! ([`super::top_level`]). A moving instance is placed at each ray's time, inside bounds
//! that hold it over the whole shutter; a time slice of a deforming mesh is seen only by
//! rays whose time falls in it.

use glam::{Affine3A, Vec3};
use rayon::prelude::*;

use super::box_lanes::{BoxLanes, hits_box};
#[cfg(target_arch = "x86_64")]
use super::isa::{Kernel, X86Level, dispatch};
use super::placement::{
    GridSource, Placement, build_grid, grid_sources, instance_bounds, placements,
};
use super::top_level::{InstanceGrid, Mailbox};
use super::{Grid, GridHit, Ray, TraversalStats};
use crate::geometry::Aabb;
use crate::scene::{Motion, Scene, TimeSlice};

mod eye;
pub use eye::EyeGrid;

/// Up to this many entries are tested one after another; past it, the instance grid
/// visits only those near the ray (`cargo bench --bench instances`: at 11 instances the
/// list was 10 % faster per ray, at 101 the grid twice as fast).
const LIST_MAX: usize = 16;

/// How the instances are searched.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TopLevel {
    /// A list for a few entries, a grid for more.
    Automatic,
    /// Every entry in turn (each behind a bounding-box test).
    List,
    /// A uniform grid over the entries' bounds.
    Grid,
}

/// A closest hit in the scene.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SceneHit {
    /// Ray parameter (world-space ray).
    pub t: f32,
    /// Index into [`Scene::instances`].
    pub instance: u32,
    /// Triangle index within the instance's mesh.
    pub triangle: u32,
    /// Barycentric weight of the triangle's second vertex.
    pub u: f32,
    /// Barycentric weight of the triangle's third vertex.
    pub v: f32,
    /// Shutter time of the ray that found it.
    pub time: f32,
}

/// One entry of the top level: a grid and where it is placed.
struct Entry {
    /// Index into [`SceneAccel::grids`].
    grid: usize,
    /// Index into [`Scene::instances`].
    instance: u32,
    /// `None` when the grid is in world space already.
    object_from_world: Option<Affine3A>,
    world_bounds: Aabb,
    /// World-from-object over the shutter, when it moves.
    motion: Option<Motion>,
    slice: Option<TimeSlice>,
    /// The grid has one cell ([`Grid::is_one_cell`]): its blocks are tested in the top
    /// level's own code.
    one_cell: bool,
}

impl Entry {
    /// The ray in the grid's space, or `None` when the entry is not there at its time or
    /// the ray misses its bounds. `inv_direction` is the ray direction's reciprocal.
    #[inline]
    fn local_ray(&self, ray: &Ray, inv_direction: Vec3, t_max: f32) -> Option<Ray> {
        hits_box(&self.world_bounds, ray, inv_direction, t_max)
            .then(|| self.in_grid_space(ray))
            .flatten()
    }

    /// True when the grid takes world rays as they are: it is in world space, still, and
    /// there at every time.
    #[inline(always)]
    fn takes_world_rays(&self) -> bool {
        self.object_from_world.is_none() && self.motion.is_none() && self.slice.is_none()
    }

    /// The ray in the grid's space, or `None` when the entry is not there at its time (its
    /// bounds already known to be met). The common case, a grid that takes world rays,
    /// inline; the others out of line.
    #[inline(always)]
    fn in_grid_space(&self, ray: &Ray) -> Option<Ray> {
        if self.takes_world_rays() {
            return Some(*ray);
        }
        self.moved_into_grid_space(ray)
    }

    /// [`Entry::in_grid_space`] for a grid in object space, moving, or in a time slice.
    #[inline(never)]
    fn moved_into_grid_space(&self, ray: &Ray) -> Option<Ray> {
        if self.slice.as_ref().is_some_and(|s| !s.contains(ray.time)) {
            return None;
        }
        Some(match (&self.motion, &self.object_from_world) {
            (Some(motion), _) => to_object(ray, &motion.at(ray.time).inverse()),
            (None, Some(object_from_world)) => to_object(ray, object_from_world),
            (None, None) => *ray,
        })
    }
}

/// The box among `set` (box `i` in bit `i`, at least one) whose entry distance in `start`
/// is least; the lowest index among equals.
#[inline(always)]
fn nearest_of(set: u32, start: &[f32]) -> usize {
    let mut nearest = set.trailing_zeros() as usize;
    let mut rest = set & (set - 1);
    while rest != 0 {
        let i = rest.trailing_zeros() as usize;
        rest &= rest - 1;
        if start[i] < start[nearest] {
            nearest = i;
        }
    }
    nearest
}

/// Ray queries over a whole scene.
pub struct SceneAccel {
    grids: Vec<Grid>,
    entries: Vec<Entry>,
    /// `None`: test the entries as a list.
    instance_grid: Option<InstanceGrid>,
    /// A list's bounds, tested against each ray all at once (up to [`LIST_MAX`] entries).
    list_bounds: Option<Box<BoxLanes>>,
}

impl SceneAccel {
    /// Builds the grids (in parallel) and the top level, choosing list or grid by count.
    pub fn build(scene: &Scene) -> SceneAccel {
        SceneAccel::build_with(scene, TopLevel::Automatic)
    }

    /// Builds the grids and the top level asked for.
    pub fn build_with(scene: &Scene, top_level: TopLevel) -> SceneAccel {
        let placement = placements(scene);
        let sources = grid_sources(scene, &placement);
        let grids: Vec<Grid> = sources
            .par_iter()
            .map(|source| build_grid(scene, source))
            .collect();
        let mut entries = Vec::new();
        for (grid, source) in sources.iter().enumerate() {
            match source {
                GridSource::Mesh(mesh) => {
                    for (i, inst) in scene.instances.iter().enumerate() {
                        if inst.mesh == *mesh && placement[i] == Placement::Object {
                            entries.push(Entry {
                                grid,
                                instance: i as u32,
                                object_from_world: (inst.world_from_object != Affine3A::IDENTITY)
                                    .then(|| inst.world_from_object.inverse()),
                                world_bounds: instance_bounds(scene, inst),
                                motion: inst.motion.clone(),
                                slice: inst.slice,
                                one_cell: grids[grid].is_one_cell(),
                            });
                        }
                    }
                }
                GridSource::Instance(i) => entries.push(Entry {
                    grid,
                    instance: *i as u32,
                    object_from_world: None,
                    world_bounds: instance_bounds(scene, &scene.instances[*i]),
                    motion: None,
                    slice: scene.instances[*i].slice,
                    one_cell: grids[grid].is_one_cell(),
                }),
            }
        }
        let use_grid = match top_level {
            TopLevel::Automatic => entries.len() > LIST_MAX,
            TopLevel::List => false,
            TopLevel::Grid => true,
        };
        let instance_grid = use_grid
            .then(|| {
                let bounds: Vec<Aabb> = entries.iter().map(|e| e.world_bounds).collect();
                InstanceGrid::build(&bounds)
            })
            .flatten();
        let list_bounds = instance_grid
            .is_none()
            .then(|| BoxLanes::new(entries.iter().map(|e| e.world_bounds)))
            .flatten()
            .map(Box::new);
        SceneAccel {
            grids,
            entries,
            instance_grid,
            list_bounds,
        }
    }

    /// Cells per axis of the instance grid, when the entries are in one.
    pub fn instance_grid_resolution(&self) -> Option<glam::UVec3> {
        self.instance_grid.as_ref().map(InstanceGrid::resolution)
    }

    /// The closest hit along `ray`.
    pub fn intersect(&self, ray: &Ray) -> Option<SceneHit> {
        self.intersect_counting(ray, &mut ())
    }

    /// [`SceneAccel::intersect`], reporting its work to `stats`.
    pub fn intersect_counting(
        &self,
        ray: &Ray,
        stats: &mut impl TraversalStats,
    ) -> Option<SceneHit> {
        if self.is_one_entry() {
            stats.test_instance();
            let hit =
                self.ask_one_entry(ray, None, |grid, ray| grid.intersect_counting(ray, stats))?;
            return Some(self.scene_hit(0, hit, ray));
        }
        dispatch(
            X86Level::Avx2,
            TopIntersect {
                accel: self,
                ray,
                stats: stats.lend(),
            },
        )
    }

    #[inline(always)]
    fn intersect_portable(&self, ray: &Ray, stats: &mut impl TraversalStats) -> Option<SceneHit> {
        let mut best: Option<(u32, GridHit)> = None;
        let mut t_max = ray.t_max;
        let inv_direction = ray.direction.recip();
        let mut test = |e: u32, t_max: &mut f32, stats: &mut _| {
            if let Some(hit) = self.intersect_entry(e as usize, ray, inv_direction, *t_max, stats) {
                *t_max = hit.t;
                best = Some((e, hit));
            }
        };
        match (&self.instance_grid, &self.list_bounds) {
            (None, Some(bounds)) => {
                let slabs = bounds.slabs(ray, inv_direction);
                for _ in &self.entries {
                    stats.test_instance();
                }
                // Only the entries whose bounds the ray meets, nearest entry first: a hit
                // in a near entry ends the ray before the far ones, which are then not
                // searched at all.
                let mut met = slabs.met();
                while met != 0 {
                    let e = nearest_of(met, &slabs.start);
                    met &= !(1 << e);
                    // Every entry left starts at or beyond this one's start.
                    if slabs.start[e] > t_max {
                        break;
                    }
                    // A hit found since may have brought the end before this entry.
                    if !slabs.hits(e, t_max) {
                        continue;
                    }
                    let entry = &self.entries[e];
                    if let Some(hit) = entry
                        .in_grid_space(ray)
                        .and_then(|local| self.nearest_in(entry, &local.with_t_max(t_max), stats))
                    {
                        t_max = hit.t;
                        best = Some((e as u32, hit));
                    }
                }
            }
            (None, None) => {
                for e in 0..self.entries.len() as u32 {
                    test(e, &mut t_max, stats);
                }
            }
            (Some(instance_grid), _) => {
                let mut mailbox = Mailbox::new();
                instance_grid.walk(ray, |ids, limit| {
                    for &e in ids {
                        if mailbox.first_visit(e) {
                            test(e, &mut t_max, stats);
                        }
                    }
                    // Entries of later cells lie beyond this one.
                    t_max <= limit
                });
            }
        }
        best.map(|(e, hit)| self.scene_hit(e as usize, hit, ray))
    }

    /// `hit`, found in entry `e` by `ray`, as a hit in the scene.
    #[inline(always)]
    fn scene_hit(&self, e: usize, hit: GridHit, ray: &Ray) -> SceneHit {
        SceneHit {
            t: hit.t,
            instance: self.entries[e].instance,
            triangle: hit.triangle,
            u: hit.u,
            v: hit.v,
            time: ray.time,
        }
    }

    /// True for a scene of one entry (a model on its own) in a list: its grid clips each ray
    /// to its box, so the box lanes would only repeat that test, and its queries go to the
    /// grid at once.
    #[inline(always)]
    fn is_one_entry(&self) -> bool {
        self.instance_grid.is_none() && self.entries.len() == 1
    }

    /// True when anything blocks `ray` within (`t_min`, `t_max`).
    pub fn occluded(&self, ray: &Ray) -> bool {
        self.occluded_counting(ray, &mut ())
    }

    /// [`SceneAccel::occluded`], reporting its work to `stats`.
    pub fn occluded_counting(&self, ray: &Ray, stats: &mut impl TraversalStats) -> bool {
        if self.is_one_entry() {
            stats.test_instance();
            return self.ask_one_entry(ray, false, |grid, ray| grid.occluded_counting(ray, stats));
        }
        dispatch(
            X86Level::Avx2,
            TopOccluded {
                accel: self,
                ray,
                stats: stats.lend(),
            },
        )
    }

    #[inline(always)]
    fn occluded_portable(&self, ray: &Ray, stats: &mut impl TraversalStats) -> bool {
        let inv_direction = ray.direction.recip();
        match (&self.instance_grid, &self.list_bounds) {
            (None, Some(bounds)) => {
                let slabs = bounds.slabs(ray, inv_direction);
                for _ in &self.entries {
                    stats.test_instance();
                }
                let mut met = slabs.met();
                while met != 0 {
                    let entry = &self.entries[met.trailing_zeros() as usize];
                    met &= met - 1;
                    if entry
                        .in_grid_space(ray)
                        .is_some_and(|local| self.blocked_in(entry, &local, stats))
                    {
                        return true;
                    }
                }
                false
            }
            (None, None) => {
                (0..self.entries.len()).any(|e| self.occluded_by(e, ray, inv_direction, stats))
            }
            (Some(instance_grid), _) => {
                let mut mailbox = Mailbox::new();
                let mut blocked = false;
                instance_grid.walk(ray, |ids, _| {
                    blocked = ids.iter().any(|&e| {
                        mailbox.first_visit(e)
                            && self.occluded_by(e as usize, ray, inv_direction, stats)
                    });
                    blocked
                });
                blocked
            }
        }
    }

    /// The nearest hit in entry `e` before `t_max`.
    #[inline]
    fn intersect_entry(
        &self,
        e: usize,
        ray: &Ray,
        inv_direction: Vec3,
        t_max: f32,
        stats: &mut impl TraversalStats,
    ) -> Option<GridHit> {
        stats.test_instance();
        let entry = &self.entries[e];
        let local = entry.local_ray(ray, inv_direction, t_max)?;
        self.nearest_in(entry, &local.with_t_max(t_max), stats)
    }

    /// The nearest hit in `entry`'s grid along `ray`, already in the grid's space: a grid
    /// of one cell tested here ([`Grid::intersect_one_cell`]), any other walked.
    #[inline(always)]
    fn nearest_in(
        &self,
        entry: &Entry,
        ray: &Ray,
        stats: &mut impl TraversalStats,
    ) -> Option<GridHit> {
        let grid = &self.grids[entry.grid];
        if entry.one_cell {
            grid.intersect_one_cell(ray, stats)
        } else {
            grid.intersect_counting(ray, stats)
        }
    }

    /// True when `entry`'s grid blocks `ray`, already in the grid's space, as
    /// [`SceneAccel::nearest_in`] asks it.
    #[inline(always)]
    fn blocked_in(&self, entry: &Entry, ray: &Ray, stats: &mut impl TraversalStats) -> bool {
        let grid = &self.grids[entry.grid];
        if entry.one_cell {
            grid.occluded_one_cell(ray, stats)
        } else {
            grid.occluded_counting(ray, stats)
        }
    }

    /// `query` asked of the grid of a scene's one entry ([`SceneAccel::is_one_entry`]) for
    /// `ray` in its space; `missing` when the entry is not there at the ray's time. A grid
    /// that takes world rays as they are is given the caller's ray itself rather than a
    /// copy: the grid then reads the ray the caller wrote, not one written just before
    /// (docs/design/grid.md, "The top level"; measured at f44f9f7). (Passing the ray on the same way to the entries of
    /// a list or an instance grid measured 0.93–0.95 the speed of the instances benchmark:
    /// not done.)
    #[inline(always)]
    fn ask_one_entry<T>(&self, ray: &Ray, missing: T, query: impl FnOnce(&Grid, &Ray) -> T) -> T {
        let entry = &self.entries[0];
        let grid = &self.grids[entry.grid];
        if entry.takes_world_rays() {
            return query(grid, ray);
        }
        match entry.in_grid_space(ray) {
            Some(local) => query(grid, &local),
            None => missing,
        }
    }

    /// True when entry `e` blocks the ray.
    #[inline]
    fn occluded_by(
        &self,
        e: usize,
        ray: &Ray,
        inv_direction: Vec3,
        stats: &mut impl TraversalStats,
    ) -> bool {
        stats.test_instance();
        let entry = &self.entries[e];
        entry
            .local_ray(ray, inv_direction, ray.t_max)
            .is_some_and(|local| self.blocked_in(entry, &local, stats))
    }
}

/// The ray in object space. The direction is transformed without normalising, so the
/// ray parameter `t` means the same point in both spaces.
fn to_object(ray: &Ray, object_from_world: &Affine3A) -> Ray {
    Ray {
        origin: object_from_world.transform_point3(ray.origin),
        direction: object_from_world.transform_vector3(ray.direction),
        ..*ray
    }
}

/// The top level's closest-hit query as a [`Kernel`]: compiled for AVX2, where the list's
/// box lanes are vectors of eight (the same operations on each lane, so the same answer;
/// AVX-512 gained nothing here).
/// Its counter is lent by value ([`TraversalStats::lend`]), as the grid's queries take theirs.
struct TopIntersect<'a, S> {
    accel: &'a SceneAccel,
    ray: &'a Ray,
    stats: S,
}

impl<S: TraversalStats> Kernel for TopIntersect<'_, S> {
    type Output = Option<SceneHit>;
    #[inline(always)]
    fn run<const FUSED: bool>(mut self) -> Option<SceneHit> {
        self.accel.intersect_portable(self.ray, &mut self.stats)
    }
}

/// The top level's shadow query as a [`Kernel`], like [`TopIntersect`].
struct TopOccluded<'a, S> {
    accel: &'a SceneAccel,
    ray: &'a Ray,
    stats: S,
}

impl<S: TraversalStats> Kernel for TopOccluded<'_, S> {
    type Output = bool;
    #[inline(always)]
    fn run<const FUSED: bool>(mut self) -> bool {
        self.accel.occluded_portable(self.ray, &mut self.stats)
    }
}

#[cfg(test)]
mod tests {
    use glam::Quat;

    use super::*;
    use crate::render::sampling::Rng;
    use crate::scene::{Material, SceneBuilder};

    /// An octahedron of radius 1 at the origin, added to `b`'s meshes.
    fn add_octahedron(b: &mut SceneBuilder) -> usize {
        let white = b.add_material(Material::diffuse("white", Vec3::splat(0.5)));
        let corners = vec![
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(-1.0, 0.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
            Vec3::new(0.0, -1.0, 0.0),
            Vec3::new(0.0, 0.0, 1.0),
            Vec3::new(0.0, 0.0, -1.0),
        ];
        let faces = vec![
            [0, 2, 4],
            [2, 1, 4],
            [1, 3, 4],
            [3, 0, 4],
            [2, 0, 5],
            [1, 2, 5],
            [3, 1, 5],
            [0, 3, 5],
        ];
        b.add_mesh("octahedron", corners, faces, white)
    }

    /// The portable queries (compiled for baseline x86-64 here) find what the queries
    /// compiled for this processor find, over a list of eleven entries (so both groups of
    /// box lanes are used): the same nearest hit for every ray, the same shadow answers.
    #[test]
    fn the_portable_top_level_finds_what_the_fast_one_finds() {
        let mut rng = Rng::new(41, 1);
        let mut b = SceneBuilder::new();
        // An octahedron, used ten times, and a wall placed once.
        let octahedron = add_octahedron(&mut b);
        let white = b.add_material(Material::diffuse("white", Vec3::splat(0.5)));
        let wall = b.add_mesh(
            "wall",
            vec![
                Vec3::new(-6.0, -6.0, -4.0),
                Vec3::new(6.0, -6.0, -4.0),
                Vec3::new(6.0, 6.0, -4.0),
                Vec3::new(-6.0, 6.0, -4.0),
            ],
            vec![[0, 1, 2], [0, 2, 3]],
            white,
        );
        b.add_instance(wall, Affine3A::IDENTITY, "wall");
        for i in 0..10 {
            let mut u = || rng.uniform() * 2.0 - 1.0;
            let at = Vec3::new(u(), u(), u()) * 4.0;
            let turn = Quat::from_euler(glam::EulerRot::YXZ, 3.0 * u(), u(), u());
            let scale = Vec3::splat(0.5 + 0.4 * u());
            b.add_instance(
                octahedron,
                Affine3A::from_scale_rotation_translation(scale, turn, at),
                format!("octahedron {i}"),
            );
        }
        let scene = b.build();
        let accel = SceneAccel::build(&scene);
        assert!(
            accel.list_bounds.is_some(),
            "the entries should form a list"
        );
        let mut hits = 0;
        for k in 0..20_000 {
            let mut u = || rng.uniform() * 2.0 - 1.0;
            let origin = Vec3::new(u(), u(), u()) * 7.0;
            let mut direction = Vec3::new(u(), u(), u()).normalize();
            if k % 5 == 0 {
                // Along an axis: the other slabs' distances are infinite or NaN.
                direction = Vec3::new(direction.x.signum(), 0.0, 0.0);
            }
            let ray = Ray::new(origin, direction);
            let fast = accel.intersect(&ray);
            assert_eq!(
                fast,
                accel.intersect_portable(&ray, &mut ()),
                "ray {k}: {ray:?}"
            );
            hits += usize::from(fast.is_some());
            let segment = ray.with_t_max(1.0 + (k % 9) as f32);
            assert_eq!(
                accel.occluded(&segment),
                accel.occluded_portable(&segment, &mut ()),
                "shadow ray {k}: {segment:?}"
            );
        }
        assert!((2_000..18_000).contains(&hits), "{hits} hits");
    }

    /// A scene of one entry, whose queries go to its grid at once (and, when the grid takes
    /// world rays as they are, with the caller's own ray), finds exactly what the list's
    /// box lanes (the portable query) and the instance grid find: for a mesh placed once,
    /// placed once and moving, and seen in one time slice only; closest hits and shadow
    /// answers, at every shutter time, for rays from outside and inside and segments of
    /// every length.
    #[test]
    fn one_entry_finds_what_the_instance_grid_finds() {
        let mut rng = Rng::new(43, 2);
        let placed = Affine3A::from_scale_rotation_translation(
            Vec3::new(1.5, 0.7, 1.0),
            Quat::from_rotation_y(0.4),
            Vec3::new(0.3, -0.2, 0.1),
        );
        for case in ["placed once", "moving", "one time slice"] {
            let mut b = SceneBuilder::new();
            let octahedron = add_octahedron(&mut b);
            b.add_instance(octahedron, placed, case);
            let mut scene = b.build();
            match case {
                "moving" => {
                    let moved = Affine3A::from_translation(Vec3::new(0.8, 0.0, 0.0)) * placed;
                    scene.instances[0].motion = Motion::from_keys(vec![placed, moved]);
                }
                "one time slice" => scene.instances[0].slice = Some(TimeSlice::around_key(1, 3)),
                _ => {}
            }
            let one = SceneAccel::build(&scene);
            let grid = SceneAccel::build_with(&scene, TopLevel::Grid);
            assert!(
                one.list_bounds.is_some() && one.entries.len() == 1,
                "{case}"
            );
            assert!(grid.instance_grid.is_some(), "{case}");
            assert_eq!(
                one.entries[0].takes_world_rays(),
                case == "placed once",
                "{case}"
            );
            let (mut hits, mut blocked) = (0, 0);
            for k in 0..10_000 {
                let mut u = || rng.uniform() * 2.0 - 1.0;
                let origin = Vec3::new(u(), u(), u()) * if k % 2 == 0 { 3.0 } else { 0.8 };
                let direction = Vec3::new(u(), u(), u()).normalize();
                let ray = Ray::new(origin, direction).at_time(rng.uniform());
                let segment = ray.with_t_max(3.0 * rng.uniform());
                let answers =
                    |accel: &SceneAccel| (accel.intersect(&ray), accel.occluded(&segment));
                let (found, answer) = answers(&one);
                assert_eq!((found, answer), answers(&grid), "{case}, ray {k}: {ray:?}");
                let portable = (
                    one.intersect_portable(&ray, &mut ()),
                    one.occluded_portable(&segment, &mut ()),
                );
                assert_eq!((found, answer), portable, "{case}, ray {k}: {ray:?}");
                hits += usize::from(found.is_some());
                blocked += usize::from(answer);
            }
            assert!(
                (1_000..9_000).contains(&hits) && (500..9_000).contains(&blocked),
                "{case}: {hits} hits, {blocked} blocked"
            );
        }
    }

    #[test]
    fn the_nearest_box_is_taken_first_and_the_lowest_index_among_equals() {
        let start = [3.0, 1.0, 2.0, 1.0, 0.5];
        assert_eq!(nearest_of(0b01111, &start), 1);
        assert_eq!(nearest_of(0b00101, &start), 2);
        assert_eq!(nearest_of(0b01101, &start), 3);
        assert_eq!(nearest_of(0b11111, &start), 4);
        assert_eq!(nearest_of(0b00001, &start), 0);
    }

    /// An entry whose grid takes world rays as they are, met after a nearer hit in an entry
    /// before it, is searched only up to that hit (as a list passing each such entry the
    /// caller's ray unchanged would not): a small octahedron (entry 0) inside a large one
    /// (entry 1, placed once and so also in world space), and rays from between them aimed
    /// at the small one, which is what they hit.
    #[test]
    fn an_entry_met_after_a_nearer_hit_is_searched_only_up_to_it() {
        let mut b = SceneBuilder::new();
        let small = add_octahedron(&mut b);
        let large = add_octahedron(&mut b);
        b.add_instance(small, Affine3A::IDENTITY, "small");
        b.add_instance(large, Affine3A::from_scale(Vec3::splat(5.0)), "large");
        let scene = b.build();
        let accel = SceneAccel::build(&scene);
        assert!(accel.entries.iter().all(Entry::takes_world_rays));
        assert_eq!(accel.entries[0].instance, 0);
        let mut rng = Rng::new(47, 3);
        for k in 0..1_000 {
            let mut u = || rng.uniform() * 2.0 - 1.0;
            let origin = Vec3::new(u(), u(), u()).normalize() * 2.0;
            let target = Vec3::new(u(), u(), u()) * 0.2;
            let ray = Ray::new(origin, target - origin);
            let hit = accel.intersect(&ray).expect("the small octahedron is hit");
            assert_eq!(hit.instance, 0, "ray {k}: {ray:?} {hit:?}");
            assert!(hit.t < 1.0, "ray {k}: {hit:?}");
        }
    }
}
