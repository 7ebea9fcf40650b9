//! The render identity: everything that decides a sample's value, which `merge` compares
//! between parts. Built here and nowhere else, so that what a render records and what a
//! merge checks cannot drift apart.

use glam::Vec3;

use super::camera::camera_label;
use super::environment::{EnvironmentSetting, EnvironmentSource};
use super::motion::Shutter;
use crate::load::LoadOptions;
use crate::record::RenderIdentity;
use crate::render::{FilterKind, Guiding, RenderSettings};
use crate::scene::Camera;

/// What the render's options say beyond the settings: how the scene was read, with what
/// shutter and environment.
pub struct IdentityInputs<'a> {
    /// SHA-256 of the scene file.
    pub scene_sha256: String,
    /// SHA-256 over the files the scene read.
    pub dependencies_sha256: String,
    /// The loader's options.
    pub load: &'a LoadOptions,
    /// The open shutter, if any.
    pub shutter: Option<Shutter>,
    /// The environment the render uses.
    pub environment: &'a EnvironmentSetting,
    /// `--exposure`, in stops.
    pub exposure: f32,
}

/// The identity of a render of `camera` with `settings`.
pub fn render_identity(
    inputs: IdentityInputs,
    camera: &Camera,
    settings: &RenderSettings,
) -> RenderIdentity {
    RenderIdentity {
        version: env!("CARGO_PKG_VERSION").to_string(),
        scene_sha256: inputs.scene_sha256,
        dependencies_sha256: inputs.dependencies_sha256,
        camera: camera_label(camera),
        width: settings.width,
        height: settings.height,
        seed: settings.seed,
        max_depth: settings.max_depth,
        options: format!(
            "{}{} {} {}{}{}",
            load_label(inputs.load),
            shutter_label(inputs.shutter),
            environment_label(inputs.environment),
            filter_label(settings.filter, settings.filter_width),
            guiding_label(settings.guiding),
            if settings.next_event_roulette {
                ""
            } else {
                " next-event-roulette=off"
            }
        ),
        exposure: inputs.exposure,
        aovs: settings.aovs.label(),
    }
}

/// Path guiding, with a leading space; nothing when off.
fn guiding_label(guiding: Guiding) -> &'static str {
    match guiding {
        Guiding::On => " guiding=on",
        Guiding::Off => "",
    }
}

/// The loader options that change the scene.
fn load_label(options: &LoadOptions) -> String {
    let mut label = format!("gltf-light-units={}", options.gltf_light_units.name());
    if let Some(frame) = options.frame {
        label += &format!(" frame={frame} fps={}", options.frames_per_second());
    }
    if let Some(animation) = &options.animation {
        label += &format!(" animation={animation}");
    }
    if let Some(variant) = &options.material_variant {
        label += &format!(" material-variant={variant}");
    }
    if let Some(levels) = options.subdivision_level {
        label += &format!(" subdivision-level={levels}");
    }
    if options.hard_falloff {
        label += " soft-falloff=off";
    }
    label
}

/// The shutter, with a leading space; nothing for a still render, whose record predates
/// motion blur.
fn shutter_label(shutter: Option<Shutter>) -> String {
    shutter.map_or_else(String::new, |s| {
        format!(" shutter={}..{} motion-steps={}", s.open, s.close, s.steps)
    })
}

fn environment_label(setting: &EnvironmentSetting) -> String {
    let source = match &setting.source {
        EnvironmentSource::None => "none".to_string(),
        EnvironmentSource::Constant(Vec3 { x, y, z }) => format!("{x},{y},{z}"),
        EnvironmentSource::File { path, sha256 } => {
            format!("{} sha256={sha256}", path.display())
        }
        EnvironmentSource::Studio => "studio".to_string(),
        EnvironmentSource::Scene => "scene".to_string(),
    };
    format!(
        "environment={source} strength={} rotation={}{}",
        setting.strength,
        setting.rotation,
        if setting.hidden { " hidden" } else { "" }
    )
}

fn filter_label(filter: FilterKind, width: f32) -> String {
    format!("filter={}:{width}", filter.name())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_frame_is_part_of_the_render_identity() {
        let mut options = LoadOptions::default();
        let still = load_label(&options);
        options.frame = Some(12.0);
        let frame12 = load_label(&options);
        options.frame = Some(12.5);
        assert_ne!(still, frame12);
        assert_ne!(frame12, load_label(&options));
        let frame12_5 = load_label(&options);
        options.fps = Some(30.0);
        assert_ne!(frame12_5, load_label(&options));
        let fps30 = load_label(&options);
        options.animation = Some("Walk".into());
        assert_ne!(fps30, load_label(&options));
    }

    /// Parts written before and after any change to this module must still merge: the
    /// text of a given set of options is fixed.
    #[test]
    fn the_options_text_is_the_one_records_hold() {
        let load = LoadOptions {
            frame: Some(6.0),
            subdivision_level: Some(1),
            ..LoadOptions::default()
        };
        let environment = EnvironmentSetting {
            source: EnvironmentSource::Constant(Vec3::new(0.3, 0.45, 0.7)),
            strength: 2.0,
            rotation: 30.0,
            hidden: true,
        };
        let inputs = IdentityInputs {
            scene_sha256: "s".into(),
            dependencies_sha256: "d".into(),
            load: &load,
            shutter: Some(Shutter {
                open: -0.25,
                close: 0.25,
                steps: 5,
            }),
            environment: &environment,
            exposure: 0.0,
        };
        let settings = RenderSettings {
            filter: FilterKind::BlackmanHarris,
            filter_width: 1.5,
            ..RenderSettings::default()
        };
        let camera = Camera::framing(
            &crate::geometry::Aabb::from_points([Vec3::ZERO, Vec3::ONE]),
            1.0,
        );
        let identity = render_identity(inputs, &camera, &settings);
        assert_eq!(
            identity.options,
            "gltf-light-units=standard frame=6 fps=24 subdivision-level=1 \
             shutter=-0.25..0.25 motion-steps=5 \
             environment=0.3,0.45,0.7 strength=2 rotation=30 hidden filter=blackman-harris:1.5"
        );
    }
}
