//! glTF animation evaluated at one time (glTF 2.0 §3.11): node translation, rotation, scale
//! and morph-target weights, sampled with STEP, LINEAR (rotations by slerp) or CUBICSPLINE
//! (Hermite, Appendix C) interpolation, held at the first and last keys outside them.

use std::collections::HashMap;

use glam::{Quat, Vec3};
use gltf::animation::{Interpolation, Property};

use super::accessor::{Elements, read_floats};

/// The animated values of one animation at one time.
#[derive(Default)]
pub(super) struct Pose {
    pub translation: HashMap<usize, Vec3>,
    pub rotation: HashMap<usize, Quat>,
    pub scale: HashMap<usize, Vec3>,
    pub weights: HashMap<usize, Vec<f32>>,
}

/// The animations to play: the one a user named (by name, or by index when no animation
/// has that name); otherwise every animation, as Blender exports one per action and plays
/// them together, unless two of them drive the same property of the same node (clips such
/// as "Walk" and "Run"), when only the first is played and the returned note says so.
pub(super) fn choose<'a>(
    document: &'a gltf::Document,
    wanted: Option<&str>,
) -> Result<(Vec<gltf::Animation<'a>>, Option<String>), String> {
    let Some(wanted) = wanted else {
        let all: Vec<gltf::Animation> = document.animations().collect();
        let mut driven = std::collections::HashSet::new();
        let overlapping = all.iter().any(|a| {
            a.channels()
                .any(|c| !driven.insert((c.target().node().index(), c.target().property() as u8)))
        });
        if overlapping {
            let note = format!(
                "its {} animations drive the same nodes; playing the first, '{}' (choose one with --animation)",
                all.len(),
                all[0].name().unwrap_or("0")
            );
            return Ok((all.into_iter().take(1).collect(), Some(note)));
        }
        return Ok((all, None));
    };
    let names: Vec<String> = document
        .animations()
        .map(|a| format!("'{}'", a.name().unwrap_or("")))
        .collect();
    document
        .animations()
        .find(|a| a.name() == Some(wanted))
        .or_else(|| {
            let index: usize = wanted.parse().ok()?;
            document.animations().nth(index)
        })
        .map(|a| (vec![a], None))
        .ok_or_else(|| {
            format!(
                "no animation '{wanted}' (the file has {}: {})",
                names.len(),
                names.join(", ")
            )
        })
}

/// The animations' values at `time` seconds (a later animation's value wins).
pub(super) fn evaluate(
    animations: &[gltf::Animation],
    time: f32,
    buffers: &[gltf::buffer::Data],
) -> Result<Pose, String> {
    let mut pose = Pose::default();
    for animation in animations {
        evaluate_one(animation, time, buffers, &mut pose)?;
    }
    Ok(pose)
}

fn evaluate_one(
    animation: &gltf::Animation,
    time: f32,
    buffers: &[gltf::buffer::Data],
    pose: &mut Pose,
) -> Result<(), String> {
    for channel in animation.channels() {
        let sampler = channel.sampler();
        let what = |why: String| {
            format!(
                "animation {} channel {}: {why}",
                animation.index(),
                channel.index()
            )
        };
        let input = read_floats(&sampler.input(), buffers).map_err(what)?;
        let output = read_floats(&sampler.output(), buffers).map_err(what)?;
        let node = channel.target().node().index();
        let property = channel.target().property();
        let keys = input.values.len();
        let cubic = sampler.interpolation() == Interpolation::CubicSpline;
        let per_key = if cubic { 3 } else { 1 };
        // Elements per key: a vector, a quaternion, or one weight per morph target.
        let width = match property {
            Property::MorphTargetWeights => output.values.len() / (keys * per_key).max(1),
            _ => output.components,
        };
        if keys == 0 || output.values.len() != keys * per_key * width || width == 0 {
            return Err(what(format!(
                "{keys} keys but {} output values",
                output.values.len()
            )));
        }
        // Strictly increasing and finite (a NaN compares as not increasing).
        let increasing = |w: &[f32]| w[0].partial_cmp(&w[1]) == Some(std::cmp::Ordering::Less);
        if !input.values.windows(2).all(increasing) || !input.values.iter().all(|t| t.is_finite()) {
            return Err(what("key times do not increase".into()));
        }
        let slerp = property == Property::Rotation;
        let value = sample(&input, &output, width, sampler.interpolation(), slerp, time);
        match property {
            Property::Translation => {
                pose.translation.insert(node, Vec3::from_slice(&value));
            }
            Property::Scale => {
                pose.scale.insert(node, Vec3::from_slice(&value));
            }
            Property::Rotation => {
                let q = Quat::from_slice(&value);
                let rotation = if q.length() > 0.0 && q.is_finite() {
                    q.normalize()
                } else {
                    Quat::IDENTITY
                };
                pose.rotation.insert(node, rotation);
            }
            Property::MorphTargetWeights => {
                pose.weights.insert(node, value);
            }
        }
    }
    Ok(())
}

/// The sampler's value at `time`: `width` numbers.
fn sample(
    input: &Elements,
    output: &Elements,
    width: usize,
    interpolation: Interpolation,
    slerp: bool,
    time: f32,
) -> Vec<f32> {
    let times = &input.values;
    let cubic = interpolation == Interpolation::CubicSpline;
    // Key k's value (for cubic splines the middle of in-tangent, value, out-tangent).
    let element = |k: usize, part: usize| -> &[f32] {
        let start = if cubic {
            (3 * k + part) * width
        } else {
            k * width
        };
        &output.values[start..start + width]
    };
    let value = |k: usize| element(k, if cubic { 1 } else { 0 });
    let last = times.len() - 1;
    if time <= times[0] {
        return value(0).to_vec();
    }
    if time >= times[last] {
        return value(last).to_vec();
    }
    // The last key at or before `time`.
    let k = times.partition_point(|&t| t <= time) - 1;
    let dt = times[k + 1] - times[k];
    let s = (time - times[k]) / dt;
    match interpolation {
        Interpolation::Step => value(k).to_vec(),
        Interpolation::Linear if slerp => {
            let (a, b) = (Quat::from_slice(value(k)), Quat::from_slice(value(k + 1)));
            if a.length() > 0.0 && b.length() > 0.0 {
                a.normalize().slerp(b.normalize(), s).to_array().to_vec()
            } else {
                lerp(value(k), value(k + 1), s)
            }
        }
        Interpolation::Linear => lerp(value(k), value(k + 1), s),
        Interpolation::CubicSpline => {
            let (s2, s3) = (s * s, s * s * s);
            let (p0, m0) = (element(k, 1), element(k, 2));
            let (p1, m1) = (element(k + 1, 1), element(k + 1, 0));
            (0..width)
                .map(|i| {
                    (2.0 * s3 - 3.0 * s2 + 1.0) * p0[i]
                        + dt * (s3 - 2.0 * s2 + s) * m0[i]
                        + (-2.0 * s3 + 3.0 * s2) * p1[i]
                        + dt * (s3 - s2) * m1[i]
                })
                .collect()
        }
    }
}

fn lerp(a: &[f32], b: &[f32], s: f32) -> Vec<f32> {
    a.iter().zip(b).map(|(a, b)| a + (b - a) * s).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn elements(values: &[f32], components: usize) -> Elements {
        Elements {
            values: values.to_vec(),
            components,
        }
    }

    #[test]
    fn step_linear_and_hold_outside_the_keys() {
        let input = elements(&[1.0, 2.0, 4.0], 1);
        let output = elements(&[0.0, 10.0, 30.0], 1);
        let at = |i, t| sample(&input, &output, 1, i, false, t)[0];
        assert_eq!(at(Interpolation::Linear, 0.0), 0.0);
        assert_eq!(at(Interpolation::Linear, 1.5), 5.0);
        assert_eq!(at(Interpolation::Linear, 3.0), 20.0);
        assert_eq!(at(Interpolation::Step, 3.9), 10.0);
        assert_eq!(at(Interpolation::Linear, 9.0), 30.0);
    }

    #[test]
    fn rotations_slerp_at_constant_angular_speed() {
        let input = elements(&[0.0, 1.0], 1);
        let a = Quat::IDENTITY;
        let b = Quat::from_rotation_y(2.0);
        let output = elements(&[a.to_array(), b.to_array()].concat(), 4);
        let q = Quat::from_slice(&sample(
            &input,
            &output,
            4,
            Interpolation::Linear,
            true,
            0.25,
        ));
        assert!(q.angle_between(Quat::from_rotation_y(0.5)) < 1e-5);
    }

    #[test]
    fn cubic_splines_pass_through_their_keys_with_their_tangents() {
        // Keys at 0 and 2 with values 0 and 1, out-tangent 3 at the first, in-tangent 0.
        let input = elements(&[0.0, 2.0], 1);
        let output = elements(&[9.0, 0.0, 3.0, 0.0, 1.0, 9.0], 1);
        let at = |t| sample(&input, &output, 1, Interpolation::CubicSpline, false, t)[0];
        assert_eq!(at(0.0), 0.0);
        assert_eq!(at(2.0), 1.0);
        // Slope near the start is the out-tangent (per second).
        assert!(((at(0.001) - at(0.0)) / 0.001 - 3.0).abs() < 0.01);
        // The Hermite value at the middle: ½·p0 + dt·⅛·m0 + ½·p1 − dt·⅛·m1.
        assert!((at(1.0) - (0.5 + 2.0 * 0.125 * 3.0)).abs() < 1e-6);
    }
}
