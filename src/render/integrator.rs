//! Unidirectional path tracing with next-event estimation on area lights and multiple
//! importance sampling (Veach 1997, ch. 9; pbrt-v4 §13.4).
//!
//! At each vertex the shading normal is turned to the side of the surface the path arrives
//! from; a scattered direction that the shading normal allows but the geometric normal
//! does not (a light leak) ends the path.

use glam::{Vec2, Vec3};

use super::Renderer;
use super::aov::Features;
use super::guiding::{Guide, GuidedBsdf, Record};
use super::next_event::{NextEventOdds, Outcome};
use super::sampler::Sampler;
use super::sampling::power_heuristic;
use super::shading::Shading;
use super::surface::{Surface, surface_at};
use crate::accel::{EyeGrid, Ray, SceneHit};
use crate::geometry::offset_ray_origin;

/// How direct light is estimated. Only [`Strategy::Mis`] is meant for images; the other two
/// exist to check that all three converge to the same answer.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Strategy {
    /// Light sampling and BSDF sampling combined with the power heuristic.
    #[default]
    Mis,
    /// Emission is found only by sampling lights (and after delta bounces).
    LightOnly,
    /// Emission is found only by hitting it with BSDF-sampled rays.
    BsdfOnly,
}

/// Shadow segments end this fraction short of the light point.
const SHADOW_EPSILON: f32 = 1e-4;

/// The largest f32 below 1: a number rescaled into [0, 1) stays below 1.
const ONE_MINUS_EPSILON: f32 = 1.0 - f32::EPSILON / 2.0;

/// Path depth at which Russian roulette starts.
const ROULETTE_DEPTH: u32 = 3;

/// Most surfaces a ray may pass through (alpha cutouts) before it is given up on.
const MAX_PASS_THROUGHS: u32 = 256;

/// How the path reached its current vertex.
#[derive(Clone, Copy)]
enum Arrival {
    /// From the camera or through a delta lobe: emission is counted in full.
    Specular,
    /// From a non-delta BSDF sample with this solid-angle pdf, at a vertex that took its
    /// next-event estimate with these odds.
    Scattered { pdf: f32, light_odds: f32 },
}

/// Whether a path draws directions from a guide, and whether it teaches one.
#[derive(Clone, Copy)]
pub enum PathGuiding<'a> {
    /// BSDF sampling alone.
    Off,
    /// Directions from the BSDF and the guide.
    Sample(&'a Guide),
    /// As [`PathGuiding::Sample`], and the path's radiance is recorded into the guide.
    Train(&'a Guide),
}

impl<'a> PathGuiding<'a> {
    fn guide(self) -> Option<&'a Guide> {
        match self {
            PathGuiding::Off => None,
            PathGuiding::Sample(g) | PathGuiding::Train(g) => Some(g),
        }
    }
}

/// The radiance estimate of one path and what it cost.
#[derive(Clone, Copy, Debug, Default)]
pub struct PathResult {
    /// Radiance along the camera ray.
    pub radiance: Vec3,
    /// True when the camera ray hit geometry (for the alpha channel).
    pub hit: bool,
    /// Rays traced: closest-hit and shadow.
    pub rays: u64,
    /// What the path saw at its first rough surface (when asked for).
    pub features: Features,
}

/// Whether a path takes every next-event estimate, and whether it records what they found.
#[derive(Clone, Copy)]
pub enum NextEvent<'a> {
    /// At every vertex whose BSDF is not a delta.
    Always,
    /// As [`NextEvent::Always`], recording each light sample's [`Outcome`].
    Learn,
    /// With the odds learned at the vertex ([`super::next_event`]).
    Roulette(&'a NextEventOdds),
}

impl NextEvent<'_> {
    fn odds_at(self, p: Vec3) -> f32 {
        match self {
            NextEvent::Always | NextEvent::Learn => 1.0,
            NextEvent::Roulette(odds) => odds.at(p),
        }
    }
}

/// What a path is asked to do.
#[derive(Clone, Copy)]
pub struct PathOptions<'a> {
    /// Most scattering events.
    pub max_depth: u32,
    /// The direct-light estimator.
    pub strategy: Strategy,
    /// Report the path's [`Features`] (which changes no random number, so not the
    /// radiance).
    pub want_features: bool,
    /// The guide, if any.
    pub guiding: PathGuiding<'a>,
    /// How next-event estimates are taken.
    pub next_event: NextEvent<'a>,
    /// The grid of the camera's eye, asked first for the path's first ray (the same answer
    /// as the scene's grids, sooner).
    pub eye: Option<&'a EyeGrid>,
}

impl PathOptions<'_> {
    /// Every next-event estimate, no guide, no features.
    pub fn plain(max_depth: u32, strategy: Strategy) -> PathOptions<'static> {
        PathOptions {
            max_depth,
            strategy,
            want_features: false,
            guiding: PathGuiding::Off,
            next_event: NextEvent::Always,
            eye: None,
        }
    }
}

/// A scattering vertex, as the bounce from it needs it.
struct Vertex<'a> {
    surface: &'a Surface,
    /// Geometric and shading normals on the side the path arrived from.
    ng: Vec3,
    ns: Vec3,
    /// Towards where the path came from.
    wo: Vec3,
    /// True when a refraction here enters an absorbing volume (through the front face).
    entering: bool,
    /// The volume's absorption coefficient.
    absorption: Vec3,
}

/// The state a path carries from vertex to vertex.
struct Path {
    ray: Ray,
    /// Throughput from the camera.
    beta: Vec3,
    arrival: Arrival,
    /// Absorption coefficient of the glass volume the path is inside, if any.
    medium: Option<Vec3>,
    /// Distance from the last scattering vertex, across surfaces alpha let the ray through.
    travelled: f32,
    /// Distance along the path from the camera, for the depth layer.
    path_length: f32,
    /// Scattering events so far.
    depth: u32,
    /// Surfaces passed since the last scattering event.
    pass_throughs: u32,
    /// Where the path last scattered (the camera at first): light densities are seen
    /// from there.
    vertex: Vec3,
    /// Its shading normal, which the light tree weighs lights with (none at the camera).
    vertex_normal: Vec3,
    /// Features still to be found: the path has not reached a rough surface yet.
    seeking: bool,
    result: PathResult,
    /// Guided vertices of a training path, completed when it ends.
    records: Vec<Record>,
    /// What its light samples found, when asked to learn.
    outcomes: Vec<Outcome>,
}

impl Path {
    fn new(ray: Ray, want_features: bool) -> Path {
        Path {
            ray,
            beta: Vec3::ONE,
            arrival: Arrival::Specular,
            medium: None,
            travelled: 0.0,
            path_length: 0.0,
            depth: 0,
            pass_throughs: 0,
            vertex: ray.origin,
            vertex_normal: Vec3::ZERO,
            seeking: want_features,
            result: PathResult::default(),
            records: Vec::new(),
            outcomes: Vec::new(),
        }
    }

    /// The last scattering vertex, its normal and the distance travelled since: where
    /// emission the path finds is weighed from.
    fn from(&self) -> (Vec3, Vec3, f32) {
        (self.vertex, self.vertex_normal, self.travelled)
    }

    /// Moves along the ray to its hit at parameter `t`, through the volume it is in.
    fn travel(&mut self, t: f32) {
        let segment = t * self.ray.direction.length();
        self.travelled += segment;
        self.path_length += segment;
        if let Some(sigma) = self.medium {
            self.beta *= (-sigma * segment).exp();
        }
    }

    /// Goes on past `s` in the same direction; false once too many surfaces were passed.
    fn pass_through(&mut self, s: &Surface) -> bool {
        self.pass_throughs += 1;
        if self.pass_throughs > MAX_PASS_THROUGHS {
            return false;
        }
        let ng = s.geometric_normal;
        self.ray = Ray::new(
            offset_ray_origin(s.point, s.point_error, ng, self.ray.direction),
            self.ray.direction,
        )
        .at_time(s.time);
        true
    }

    /// Albedo and normal of every surface on the way, so a path that ends at a mirror or
    /// in glass still reports the last surface it met; a rough surface ends the search.
    fn note_features(&mut self, shading: &Shading, s: &Surface, wo: Vec3, unlit: bool) {
        if !self.seeking {
            return;
        }
        let n = if shading.normal.dot(wo) < 0.0 {
            -shading.normal
        } else {
            shading.normal
        };
        self.result.features = Features {
            albedo: shading.base_colour,
            normal: n,
            position: s.point,
            distance: self.path_length,
            surface: true,
        };
        self.seeking = shading.bsdf.is_delta() && !unlit;
    }

    /// Samples the next direction at `vertex` and moves the path onto it; false when the
    /// path ends (no direction, a leak through the geometric surface, Russian roulette).
    fn extend(
        &mut self,
        vertex: &Vertex,
        scatter: &GuidedBsdf,
        sampler: &mut Sampler,
        guiding: PathGuiding,
        light_odds: f32,
    ) -> bool {
        let s = vertex.surface;
        let Some((sample, (guide_pdf, bsdf_pdf))) =
            scatter.sample_with_densities(vertex.ns, vertex.wo, sampler)
        else {
            return false;
        };
        let side = sample.wi.dot(vertex.ng);
        if (sample.is_transmission && side >= 0.0) || (!sample.is_transmission && side <= 0.0) {
            return false;
        }
        let beta_before = self.beta;
        self.beta *= sample.weight;
        if matches!(guiding, PathGuiding::Train(_)) && scatter.guide.is_some() && !sample.is_delta {
            self.records.push(Guide::record(
                vertex.surface.point,
                sample.wi,
                (sample.pdf, guide_pdf, bsdf_pdf),
                (beta_before, self.beta),
                self.result.radiance,
            ));
        }
        if sample.is_transmission {
            // Entering through the front face puts the path inside the volume.
            self.medium = vertex.entering.then_some(vertex.absorption);
        }
        self.arrival = if sample.is_delta {
            Arrival::Specular
        } else {
            Arrival::Scattered {
                pdf: sample.pdf,
                light_odds,
            }
        };
        self.ray = Ray::new(
            offset_ray_origin(s.point, s.point_error, vertex.ng, sample.wi),
            sample.wi,
        )
        .at_time(s.time);
        self.vertex = s.point;
        self.vertex_normal = vertex.ns;
        self.travelled = 0.0;
        self.depth += 1;
        self.pass_throughs = 0;

        // Possibly terminate the path with Russian roulette. Paths survive with the
        // square root of the throughput, as in Cycles
        // (`path_state_continuation_probability`): later than with the throughput
        // itself, which lowered the error at equal time by 10–25 % on the reference
        // scenes (tools/blender/efficiency.py).
        if self.depth >= ROULETTE_DEPTH {
            let rr = self.beta.max_element().sqrt();
            if rr < 1.0 {
                let q = (1.0 - rr).clamp(0.05, 0.95);
                if sampler.uniform() < q {
                    return false;
                }
                self.beta /= 1.0 - q;
            }
        }
        self.beta.is_finite() && self.beta != Vec3::ZERO
    }
}

impl Renderer<'_> {
    /// Estimates the radiance arriving along `ray` (pointing into the scene).
    pub fn trace_path(
        &self,
        ray: Ray,
        sampler: &mut Sampler,
        max_depth: u32,
        strategy: Strategy,
    ) -> PathResult {
        self.trace_path_with(ray, sampler, PathOptions::plain(max_depth, strategy))
    }

    /// [`Renderer::trace_path`] as `options` ask: with features, drawing directions at
    /// diffuse vertices also from a guide ([`super::guiding`]), with next-event roulette
    /// ([`super::next_event`]).
    pub fn trace_path_with(
        &self,
        ray: Ray,
        sampler: &mut Sampler,
        options: PathOptions,
    ) -> PathResult {
        self.trace(ray, sampler, options).result
    }

    /// The outcomes of the light samples of one path that takes every estimate.
    pub(crate) fn light_sample_outcomes(
        &self,
        ray: Ray,
        sampler: &mut Sampler,
        max_depth: u32,
        strategy: Strategy,
    ) -> Vec<Outcome> {
        let options = PathOptions {
            next_event: NextEvent::Learn,
            ..PathOptions::plain(max_depth, strategy)
        };
        self.trace(ray, sampler, options).outcomes
    }

    /// Follows one path from `ray` to its end.
    fn trace(&self, ray: Ray, sampler: &mut Sampler, options: PathOptions) -> Path {
        let strategy = options.strategy;
        let mut path = Path::new(ray, options.want_features);
        loop {
            path.result.rays += 1;
            let eye = options.eye.filter(|_| path.depth == 0);
            let hit = self.accel.intersect_from(eye, &path.ray);
            self.add_sphere_lamps(&mut path, hit.as_ref(), strategy);
            let Some(hit) = hit else {
                self.leave_scene(&mut path, strategy);
                break;
            };
            path.travel(hit.t);
            let s = surface_at(self.scene, &self.frames, &hit);
            let material = &self.scene.materials[s.material];
            let hidden = path.depth == 0 && !material.camera_visible;
            if material.lamp && !hidden && s.geometric_normal.dot(path.ray.direction) < 0.0 {
                // A lamp's shape: its light, weighed like any emitter's, and the ray goes on.
                let cos_o = -s.geometric_normal.dot(path.ray.direction.normalize());
                let weight =
                    self.emission_weight_at(&hit, path.from(), cos_o, path.arrival, strategy);
                path.result.radiance += weight * path.beta * self.shade(&s, true).emission;
            }
            if hidden || !self.is_present(&s, sampler) {
                // A cutout, a blended surface the ray passes, a lamp or a surface the
                // camera does not see: go on in the same direction.
                if !path.pass_through(&s) {
                    break;
                }
                continue;
            }
            if !self.scatter_at(&mut path, &hit, &s, sampler, options) {
                break;
            }
        }
        if let PathGuiding::Train(guide) = options.guiding {
            guide.add_path(&path.records, path.result.radiance);
        }
        path
    }

    /// Sphere lamps the path's segment passes before its hit (`None`: the segment leaves
    /// the scene), which it goes on through.
    fn add_sphere_lamps(&self, path: &mut Path, hit: Option<&SceneHit>, strategy: Strategy) {
        if !self.lights.has_spheres() {
            return;
        }
        let length = path.ray.direction.length();
        let t_max = hit.map_or(f32::INFINITY, |h| h.t * length);
        let (origin, d) = (path.ray.origin, path.ray.direction / length);
        let (arrival, medium, beta) = (path.arrival, path.medium, path.beta);
        let radiance = &mut path.result.radiance;
        self.lights.spheres_along(
            path.vertex,
            path.vertex_normal,
            origin,
            d,
            t_max,
            path.depth == 0,
            |l, light_pdf, t| {
                let weight = emission_weight(arrival, strategy, || light_pdf);
                let through = medium.map_or(Vec3::ONE, |sigma| (-sigma * t).exp());
                *radiance += weight * beta * through * l;
            },
        );
    }

    /// The path leaves the scene: the environment, weighed like any emitter, unless it is
    /// hidden from camera rays.
    fn leave_scene(&self, path: &mut Path, strategy: Strategy) {
        let (environment, light_pdf) =
            self.lights
                .environment(path.vertex, path.vertex_normal, path.ray.direction);
        if path.depth == 0 && !self.environment_visible {
            return;
        }
        if path.seeking {
            path.result.features = Features {
                albedo: environment.min(Vec3::ONE),
                ..Features::default()
            };
        }
        if environment != Vec3::ZERO {
            let weight = emission_weight(path.arrival, strategy, || light_pdf);
            path.result.radiance += weight * path.beta * environment;
        }
    }

    /// The path meets the surface `s` of `hit`: its emission, direct light and the next
    /// direction. False when the path ends here.
    fn scatter_at(
        &self,
        path: &mut Path,
        hit: &SceneHit,
        s: &Surface,
        sampler: &mut Sampler,
        options: PathOptions,
    ) -> bool {
        let material = &self.scene.materials[s.material];
        path.result.hit |= path.depth == 0;
        let wo = -path.ray.direction.normalize();
        let cos_o = s.geometric_normal.dot(wo);
        let front = cos_o > 0.0;
        let shading = self.shade(s, front);
        path.note_features(&shading, s, wo, material.unlit);
        if material.unlit {
            if matches!(path.arrival, Arrival::Specular) {
                path.result.radiance += path.beta * shading.base_colour;
            }
            return false;
        }

        // Emission reached by the previous bounce.
        if material.is_emissive() && (front || material.double_sided) {
            let weight =
                self.emission_weight_at(hit, path.from(), cos_o, path.arrival, options.strategy);
            path.result.radiance += weight * path.beta * shading.emission;
        }
        // A one-sided surface's back is black, but for glass it is the inside of the
        // volume. Whether this point is glass is read from the material as textured here
        // (a glTF metallic texture can make a metal factor 0), not from its factors.
        let two_sided = material.double_sided || shading.bsdf.transmits();
        if path.depth == options.max_depth || (!front && !two_sided) {
            return false;
        }

        let ng = if front {
            s.geometric_normal
        } else {
            -s.geometric_normal
        };
        let mut changed = None;
        let (bsdf, ns) = shading.oriented(s.shading_normal, ng, wo, &mut changed);
        let (guide, fraction) = match options.guiding.guide() {
            Some(g) if bsdf.is_guidable() => {
                let (distribution, fraction) = g.at(s.point);
                // A region whose share is 0 samples the BSDF alone, but goes on recording
                // while training, to score the shares again.
                let training = matches!(options.guiding, PathGuiding::Train(_));
                (
                    (fraction > 0.0 || training).then_some(distribution),
                    fraction,
                )
            }
            _ => (None, 0.0),
        };
        let scatter = GuidedBsdf {
            bsdf,
            guide,
            fraction,
        };

        // Sample a light for the next-event estimate. Punctual lights can only be found
        // this way, so even the BSDF-only estimator samples them.
        let takes_light = !bsdf.is_delta()
            && (options.strategy != Strategy::BsdfOnly || self.lights.punctual_len() > 0);
        let light_odds = if takes_light {
            options.next_event.odds_at(s.point)
        } else {
            1.0
        };
        // The light choice's number also decides the roulette, so that every sample of a
        // pixel draws the same sets in the same order, keeping them stratified.
        let (u, u_light) = if takes_light {
            sampler.uniform3()
        } else {
            (Vec2::ZERO, 1.0)
        };
        if takes_light && u_light < light_odds {
            path.result.rays += 1;
            let numbers = ((u_light / light_odds).min(ONE_MINUS_EPSILON), u);
            let light = self.direct_light(
                &scatter,
                s,
                (ng, ns, wo),
                (light_odds, numbers),
                sampler,
                options.strategy,
            );
            if let NextEvent::Learn = options.next_event {
                path.outcomes.push(Outcome {
                    point: s.point,
                    reached: light != Vec3::ZERO,
                });
            }
            path.result.radiance += path.beta * light / light_odds;
        }
        let vertex = Vertex {
            surface: s,
            ng,
            ns,
            wo,
            entering: front && material.absorption != Vec3::ZERO,
            absorption: material.absorption,
        };
        path.extend(&vertex, &scatter, sampler, options.guiding, light_odds)
    }

    /// One light-sampling estimate of reflected direct light at `s` (its oriented geometric
    /// and shading normals and the direction out), MIS-weighted when asked, as if light
    /// samples were taken with `light_odds` (the caller divides by them), from the numbers
    /// `(u_light, u)` for the light's choice and the point on it.
    ///
    /// Delta lights are sampled even by the BSDF-only estimator, since nothing else finds
    /// them; it samples nothing else.
    fn direct_light(
        &self,
        bsdf: &GuidedBsdf,
        s: &Surface,
        (ng, ns, wo): (Vec3, Vec3, Vec3),
        (light_odds, (u_light, u)): (f32, (f32, Vec2)),
        sampler: &mut Sampler,
        strategy: Strategy,
    ) -> Vec3 {
        let sample = if strategy == Strategy::BsdfOnly {
            self.lights.sample_punctual(s.point, u_light)
        } else {
            self.lights
                .sample(self.scene, s.point, ns, s.time, u_light, u)
        };
        let Some(ls) = sample else {
            return Vec3::ZERO;
        };
        // A light seen through the surface counts only for lobes that transmit; the
        // geometric and shading normals must agree on which side it is.
        if ls.radiance == Vec3::ZERO || (ng.dot(ls.wi) > 0.0) != (ns.dot(ls.wi) > 0.0) {
            return Vec3::ZERO;
        }
        let f = bsdf.bsdf.eval(ns, wo, ls.wi);
        if f == Vec3::ZERO {
            return Vec3::ZERO;
        }
        // Both ends leave their surface by their own error bounds; the segment stops just
        // short of the light point (pbrt-v4's 1 − 10⁻⁴), which already lies off the light.
        let origin = offset_ray_origin(s.point, s.point_error, ng, ls.wi);
        let target = offset_ray_origin(ls.point, ls.point_error, ls.normal, -ls.wi);
        let shadow = Ray {
            origin,
            direction: target - origin,
            t_min: 0.0,
            t_max: 1.0 - SHADOW_EPSILON,
            time: s.time,
        };
        if self.occluded(&shadow, sampler) {
            return Vec3::ZERO;
        }
        let weight = match strategy {
            Strategy::Mis if !ls.is_delta => {
                power_heuristic(light_odds * ls.pdf, bsdf.pdf(ns, wo, ls.wi))
            }
            _ => 1.0,
        };
        f * ls.radiance * (weight / ls.pdf)
    }

    /// True when something blocks `shadow`. Surfaces that alpha hides do not; when the scene
    /// has any, the segment is walked hit by hit.
    fn occluded(&self, shadow: &Ray, sampler: &mut Sampler) -> bool {
        if !self.has_cutouts {
            return self.accel.occluded(shadow);
        }
        let mut ray = *shadow;
        for _ in 0..=MAX_PASS_THROUGHS {
            let Some(hit) = self.accel.intersect(&ray) else {
                return false;
            };
            let s = surface_at(self.scene, &self.frames, &hit);
            if self.is_present(&s, sampler) {
                return true;
            }
            // Go on from just past this surface towards the same end point.
            ray.t_min = hit.t;
        }
        true
    }
}

impl Renderer<'_> {
    /// The weight of the emission of the surface `hit` found by a ray that arrived as
    /// `arrival` from `from` (the last scattering vertex, its normal and the distance
    /// travelled since), leaving the surface at cosine `cos_o`.
    fn emission_weight_at(
        &self,
        hit: &SceneHit,
        from: (Vec3, Vec3, f32),
        cos_o: f32,
        arrival: Arrival,
        strategy: Strategy,
    ) -> f32 {
        let (vertex, vertex_normal, travelled) = from;
        emission_weight(arrival, strategy, || {
            self.lights.pdf(
                hit.instance,
                hit.triangle,
                hit.time,
                vertex,
                vertex_normal,
                travelled,
                cos_o,
            )
        })
    }
}

/// The weight of emission found by a ray that arrived as `arrival`, from a light that
/// light sampling would have drawn with solid-angle density `light_pdf()` (times the odds
/// of the estimate at the vertex left): full after the camera or a delta lobe, and
/// otherwise as the strategy says (the power heuristic for MIS). The density, a walk of
/// the light tree, is worked out only for MIS.
fn emission_weight(arrival: Arrival, strategy: Strategy, light_pdf: impl FnOnce() -> f32) -> f32 {
    match (arrival, strategy) {
        (Arrival::Specular, _) | (_, Strategy::BsdfOnly) => 1.0,
        (Arrival::Scattered { .. }, Strategy::LightOnly) => 0.0,
        (Arrival::Scattered { pdf, light_odds }, Strategy::Mis) => {
            power_heuristic(pdf, light_odds * light_pdf())
        }
    }
}
