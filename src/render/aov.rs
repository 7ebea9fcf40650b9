//! Auxiliary layers (AOVs): what each camera path saw at its first rough surface, and how
//! spread out a pixel's radiance samples are.
//!
//! The features are those a denoiser is fed (Intel Open Image Denoise's documentation,
//! "Auxiliary feature images"): the albedo and the shading normal of the first surface that
//! is not a perfect mirror or glass — a path through a mirror reports the surface seen in
//! it — plus the distance travelled to that surface and its position. A path that leaves
//! the scene before reaching one reports the environment's colour (clamped to 1) as albedo
//! and no surface. Like the beauty, every layer is the mean over the pixel's samples, so
//! layers of parts rendered apart merge exactly as the beauty does.

use glam::{DVec3, Vec3};

/// Which auxiliary layers a render keeps.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct AovSet {
    /// Reflectance of the first rough surface (its base colour with textures).
    pub albedo: bool,
    /// Its world-space shading normal, turned towards the path.
    pub normal: bool,
    /// Length of the path from the camera to it.
    pub depth: bool,
    /// Its world-space position.
    pub position: bool,
    /// Per-channel sample variance of the pixel's radiance.
    pub variance: bool,
}

/// The layer names `--aov` accepts, in the order they are written.
pub const AOV_NAMES: [&str; 5] = ["albedo", "normal", "depth", "position", "variance"];

impl AovSet {
    /// Every layer.
    pub const ALL: AovSet = AovSet {
        albedo: true,
        normal: true,
        depth: true,
        position: true,
        variance: true,
    };

    /// Parses a comma-separated list of [`AOV_NAMES`] (or `all`).
    pub fn parse(text: &str) -> Result<AovSet, String> {
        let mut set = AovSet::default();
        for name in text.split(',').map(str::trim).filter(|n| !n.is_empty()) {
            match name {
                "all" => set = AovSet::ALL,
                "albedo" => set.albedo = true,
                "normal" => set.normal = true,
                "depth" => set.depth = true,
                "position" => set.position = true,
                "variance" => set.variance = true,
                other => {
                    return Err(format!(
                        "'{other}' is not a layer gridtrace writes (choose from {}, or all)",
                        AOV_NAMES.join(", ")
                    ));
                }
            }
        }
        Ok(set)
    }

    /// True when some layer is kept.
    pub fn any(&self) -> bool {
        *self != AovSet::default()
    }

    /// Both sets' layers.
    pub fn union(self, other: AovSet) -> AovSet {
        AovSet {
            albedo: self.albedo || other.albedo,
            normal: self.normal || other.normal,
            depth: self.depth || other.depth,
            position: self.position || other.position,
            variance: self.variance || other.variance,
        }
    }

    /// The kept layers' names, comma-separated, in [`AOV_NAMES`] order.
    pub fn label(&self) -> String {
        let kept = [
            self.albedo,
            self.normal,
            self.depth,
            self.position,
            self.variance,
        ];
        AOV_NAMES
            .iter()
            .zip(kept)
            .filter(|(_, k)| *k)
            .map(|(n, _)| *n)
            .collect::<Vec<_>>()
            .join(",")
    }
}

/// What one camera path saw at its first rough surface.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Features {
    /// Albedo (or the environment's colour, clamped to 1, when no surface was reached).
    pub albedo: Vec3,
    /// Unit shading normal facing the path; zero when no surface was reached.
    pub normal: Vec3,
    /// World-space position.
    pub position: Vec3,
    /// Path length from the camera.
    pub distance: f32,
    /// True when the path reached a surface (depth and position are meaningful).
    pub surface: bool,
}

/// The sums of one pixel's features and of its radiance squared, in f64 so that sums of
/// parts equal the sum of one render to within f32 rounding (as [`super::PixelAccumulator`]).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FeatureAccumulator {
    albedo: DVec3,
    normal: DVec3,
    position: DVec3,
    distance: f64,
    surfaces: u64,
    squares: DVec3,
}

impl FeatureAccumulator {
    /// Adds one sample's features and radiance (a non-finite radiance counts as black, as
    /// in the beauty).
    pub fn add(&mut self, features: &Features, radiance: Vec3) {
        self.albedo += features.albedo.as_dvec3();
        self.normal += features.normal.as_dvec3();
        if features.surface {
            self.position += features.position.as_dvec3();
            self.distance += f64::from(features.distance);
            self.surfaces += 1;
        }
        if radiance.is_finite() {
            let r = radiance.as_dvec3();
            self.squares += r * r;
        }
    }

    /// Adds another accumulator of the same pixel.
    pub fn merge(&mut self, other: &FeatureAccumulator) {
        self.albedo += other.albedo;
        self.normal += other.normal;
        self.position += other.position;
        self.distance += other.distance;
        self.surfaces += other.surfaces;
        self.squares += other.squares;
    }

    /// Sum of the squared radiance samples.
    pub fn squares(&self) -> DVec3 {
        self.squares
    }

    /// The accumulator of `spp` samples whose resolved layers hold `pixel` (absent layers
    /// count as zero) and whose beauty mean was `mean`: what a merge starts from.
    pub fn from_means(pixel: &AovPixel, mean: Vec3, spp: u32) -> FeatureAccumulator {
        let n = f64::from(spp);
        let surfaces = (f64::from(pixel.coverage) * n).round();
        let m = mean.as_dvec3();
        FeatureAccumulator {
            albedo: pixel.albedo.as_dvec3() * n,
            normal: pixel.normal.as_dvec3() * n,
            position: pixel.position.as_dvec3() * surfaces,
            distance: f64::from(pixel.depth) * surfaces,
            surfaces: surfaces as u64,
            squares: pixel.variance.as_dvec3() * (n - 1.0).max(0.0) + m * m * n,
        }
    }

    /// The layers' values over `spp` samples whose radiance summed to `sum`.
    pub fn resolve(&self, spp: u32, sum: DVec3) -> AovPixel {
        let n = f64::from(spp.max(1));
        let surfaces = self.surfaces.max(1) as f64;
        AovPixel {
            albedo: (self.albedo / n).as_vec3(),
            normal: (self.normal / n).as_vec3(),
            position: (self.position / surfaces).as_vec3(),
            depth: if self.surfaces == 0 {
                NO_SURFACE_DEPTH
            } else {
                (self.distance / surfaces) as f32
            },
            coverage: (self.surfaces as f64 / n) as f32,
            variance: sample_variance(sum, self.squares, spp),
        }
    }
}

/// Depth written where no sample reached a surface: far, and finite so compositing filters
/// stay finite (Blender's Z pass uses the same 10¹⁰).
pub const NO_SURFACE_DEPTH: f32 = 1e10;

/// The unbiased sample variance per channel of `n` samples with this sum and sum of
/// squares; zero for fewer than two samples.
pub fn sample_variance(sum: DVec3, squares: DVec3, n: u32) -> Vec3 {
    if n < 2 {
        return Vec3::ZERO;
    }
    let n = f64::from(n);
    ((squares - sum * sum / n) / (n - 1.0))
        .max(DVec3::ZERO)
        .as_vec3()
}

/// One pixel of every layer.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct AovPixel {
    /// Mean albedo.
    pub albedo: Vec3,
    /// Mean shading normal (not renormalised: an edge pixel averages both sides).
    pub normal: Vec3,
    /// Mean position of the samples that reached a surface.
    pub position: Vec3,
    /// Mean path length of the samples that reached a surface, or [`NO_SURFACE_DEPTH`].
    pub depth: f32,
    /// Fraction of the samples that reached a surface.
    pub coverage: f32,
    /// Sample variance of the radiance per channel.
    pub variance: Vec3,
}

/// The auxiliary layers of an image, row-major like its pixels; `None` for layers not kept.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct AovImage {
    /// Albedo.
    pub albedo: Option<Vec<Vec3>>,
    /// Shading normal.
    pub normal: Option<Vec<Vec3>>,
    /// Path length to the first rough surface.
    pub depth: Option<Vec<f32>>,
    /// World position of the first rough surface.
    pub position: Option<Vec<Vec3>>,
    /// Fraction of samples that reached a surface (kept with depth or position, which are
    /// averaged over those samples).
    pub coverage: Option<Vec<f32>>,
    /// Radiance sample variance per channel (the variance of the pixel's mean is this over
    /// the sample count).
    pub variance: Option<Vec<Vec3>>,
    /// The beauty before denoising, with its alpha.
    pub noisy: Option<(Vec<Vec3>, Vec<f32>)>,
}

impl AovImage {
    /// Empty layers for `pixels` pixels, one for each kept AOV.
    pub fn with_layers(set: AovSet, pixels: usize) -> AovImage {
        let layer3 = |kept: bool| kept.then(|| vec![Vec3::ZERO; pixels]);
        let layer1 = |kept: bool| kept.then(|| vec![0.0f32; pixels]);
        AovImage {
            albedo: layer3(set.albedo),
            normal: layer3(set.normal),
            depth: layer1(set.depth),
            position: layer3(set.position),
            coverage: layer1(set.depth || set.position),
            variance: layer3(set.variance),
            noisy: None,
        }
    }

    /// Which AOVs the image holds.
    pub fn set(&self) -> AovSet {
        AovSet {
            albedo: self.albedo.is_some(),
            normal: self.normal.is_some(),
            depth: self.depth.is_some(),
            position: self.position.is_some(),
            variance: self.variance.is_some(),
        }
    }

    /// Pixel `i` of every layer (absent layers read as zero).
    pub fn pixel(&self, i: usize) -> AovPixel {
        let at3 = |layer: &Option<Vec<Vec3>>| layer.as_ref().map_or(Vec3::ZERO, |l| l[i]);
        let at1 = |layer: &Option<Vec<f32>>| layer.as_ref().map_or(0.0, |l| l[i]);
        AovPixel {
            albedo: at3(&self.albedo),
            normal: at3(&self.normal),
            position: at3(&self.position),
            depth: at1(&self.depth),
            coverage: at1(&self.coverage),
            variance: at3(&self.variance),
        }
    }

    /// Sets pixel `i` of every kept layer.
    pub fn set_pixel(&mut self, i: usize, p: &AovPixel) {
        let put3 = |layer: &mut Option<Vec<Vec3>>, v: Vec3| {
            if let Some(l) = layer {
                l[i] = v;
            }
        };
        put3(&mut self.albedo, p.albedo);
        put3(&mut self.normal, p.normal);
        put3(&mut self.position, p.position);
        put3(&mut self.variance, p.variance);
        let put1 = |layer: &mut Option<Vec<f32>>, v: f32| {
            if let Some(l) = layer {
                l[i] = v;
            }
        };
        put1(&mut self.depth, p.depth);
        put1(&mut self.coverage, p.coverage);
    }

    /// Radiance scaled by `factor` (exposure): the variance scales by its square, the
    /// noisy beauty by it; the features do not change.
    pub fn scale_radiance(&mut self, factor: f32) {
        if let Some(v) = &mut self.variance {
            v.iter_mut().for_each(|p| *p *= factor * factor);
        }
        if let Some((noisy, _)) = &mut self.noisy {
            noisy.iter_mut().for_each(|p| *p *= factor);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_parse_and_print_in_one_order() {
        let set = AovSet::parse("variance, albedo,depth").unwrap();
        assert_eq!(set.label(), "albedo,depth,variance");
        assert_eq!(AovSet::parse("all").unwrap(), AovSet::ALL);
        assert!(
            AovSet::parse("albedo,beauty")
                .unwrap_err()
                .contains("'beauty'")
        );
        assert!(!AovSet::parse("").unwrap().any());
    }

    #[test]
    fn resolved_layers_rebuild_the_sums() {
        let mut acc = FeatureAccumulator::default();
        let mut sum = DVec3::ZERO;
        for i in 0..23 {
            let f = Features {
                albedo: Vec3::splat(0.1 * (i % 5) as f32),
                normal: Vec3::Y,
                position: Vec3::new(i as f32, 2.0, 3.0),
                distance: 1.5 + i as f32,
                surface: i % 4 != 0,
            };
            let radiance = Vec3::new(i as f32 * 0.3, 1.0, 0.0);
            acc.add(&f, radiance);
            sum += radiance.as_dvec3();
        }
        let pixel = acc.resolve(23, sum);
        assert_eq!(pixel.variance.z, 0.0);
        assert!(pixel.variance.x > 0.0 && pixel.variance.y.abs() < 1e-6);
        let mean = (sum / 23.0).as_vec3();
        let again = FeatureAccumulator::from_means(&pixel, mean, 23).resolve(23, sum);
        assert_eq!(again.coverage, pixel.coverage);
        assert!((again.depth - pixel.depth).abs() <= pixel.depth * 1e-6);
        assert!((again.variance - pixel.variance).abs().max_element() < 1e-5);
    }
}
