//! The command line's fixed sets of names (`--gltf-light-units`, `--filter`,
//! `--view-transform`): clap's view of enums the library owns, each variant named as the
//! library names it in render records.

use clap::ValueEnum;

use crate::load::GltfLightUnits;
use crate::output::ViewTransform;
use crate::render::FilterKind;

/// What glTF light intensities mean.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, ValueEnum)]
pub enum LightUnitsChoice {
    /// The glTF specification: candela and lux, at 683 lm/W (Blender's "Standard").
    #[default]
    Standard,
    /// Watts per steradian and W/m² as written (Blender's "Unitless").
    Unitless,
    /// Blender's "Raw": point and spot lights in watts of emitted power, directional in W/m².
    Raw,
}

impl From<LightUnitsChoice> for GltfLightUnits {
    fn from(choice: LightUnitsChoice) -> GltfLightUnits {
        match choice {
            LightUnitsChoice::Standard => GltfLightUnits::Standard,
            LightUnitsChoice::Unitless => GltfLightUnits::Unitless,
            LightUnitsChoice::Raw => GltfLightUnits::Raw,
        }
    }
}

/// `--soft-falloff`: whether Blender's Soft Falloff is followed.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, ValueEnum)]
pub enum SoftFalloffChoice {
    /// As the file's writer means: on for files Blender wrote.
    #[default]
    Auto,
    /// Lamps with a radius are balls.
    Off,
}

/// `--guiding`: whether paths are guided ([`crate::render::Guiding`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, ValueEnum)]
pub enum GuidingChoice {
    /// Paths are guided.
    On,
    /// Paths sample BSDFs alone.
    #[default]
    Off,
}

/// A feature that is on unless turned off (`--next-event-roulette`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, ValueEnum)]
pub enum Switch {
    /// The feature is used.
    #[default]
    On,
    /// The feature is not used.
    Off,
}

/// `--progress`: how progress is reported for programs (the Blender add-on).
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum ProgressChoice {
    /// One JSON object per pass on stderr: `{"pass":K,"of":N,"seconds":T}` (K samples per
    /// pixel of N taken).
    Json,
}

#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, ValueEnum)]
pub enum FilterChoice {
    /// Uniform over a square `width` pixels wide (1: the pixel itself).
    #[default]
    Box,
    /// A Gaussian of σ = width/4, truncated at ±1.5·width (Cycles' definition).
    Gaussian,
    /// The 4-term Blackman–Harris window (Harris 1978) spanning ±width pixels: Cycles'
    /// definition, whose default "1.5 px" spans three pixels.
    BlackmanHarris,
}

impl From<FilterChoice> for FilterKind {
    fn from(choice: FilterChoice) -> FilterKind {
        match choice {
            FilterChoice::Box => FilterKind::Box,
            FilterChoice::Gaussian => FilterKind::Gaussian,
            FilterChoice::BlackmanHarris => FilterKind::BlackmanHarris,
        }
    }
}

/// How a PNG shows the linear image.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, ValueEnum)]
pub enum ViewChoice {
    /// The sRGB transfer curve alone: values above 1 clip.
    #[default]
    Standard,
    /// Blender's default since 4.0: a log-sigmoid image formation that rolls highlights off
    /// towards white (see `output/agx.rs`).
    Agx,
}

impl From<ViewChoice> for ViewTransform {
    fn from(choice: ViewChoice) -> ViewTransform {
        match choice {
            ViewChoice::Standard => ViewTransform::Standard,
            ViewChoice::Agx => ViewTransform::Agx,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The name a user types is the name the render record keeps, so a record can be
    /// read back as the option that made it.
    #[test]
    fn each_choice_is_named_as_the_library_names_it() {
        fn name_of(choice: impl ValueEnum) -> String {
            choice.to_possible_value().unwrap().get_name().to_string()
        }
        for &c in LightUnitsChoice::value_variants() {
            assert_eq!(name_of(c), GltfLightUnits::from(c).name());
        }
        for &c in FilterChoice::value_variants() {
            assert_eq!(name_of(c), FilterKind::from(c).name());
        }
        for &c in ViewChoice::value_variants() {
            assert_eq!(name_of(c), ViewTransform::from(c).name());
        }
    }
}
