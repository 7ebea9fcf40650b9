//! `EXT_mesh_gpu_instancing`: one node drawing its mesh many times, each copy placed by
//! per-instance `TRANSLATION`, `ROTATION` (a unit quaternion, float or normalised
//! integers) and `SCALE` accessors, applied before the node's own transform.

use glam::{Mat4, Quat, Vec3};

use super::accessor::read_floats;
use crate::limits::{bytes_of, check_memory};

/// The extension's name.
pub const EXTENSION: &str = "EXT_mesh_gpu_instancing";

/// The node's instance transforms (each T · R · S), or `None` when the node has none.
pub(super) fn instance_transforms(
    node: &gltf::Node,
    document: &gltf::Document,
    buffers: &[gltf::buffer::Data],
) -> Result<Option<Vec<Mat4>>, String> {
    let Some(extension) = node.extension_value(EXTENSION) else {
        return Ok(None);
    };
    let attribute = |name: &str| -> Result<Option<super::accessor::Elements>, String> {
        let Some(index) = extension["attributes"][name].as_u64() else {
            return Ok(None);
        };
        let accessor = document.accessors().nth(index as usize).ok_or(format!(
            "{EXTENSION}: {name} accessor {index} does not exist"
        ))?;
        read_floats(&accessor, buffers)
            .map(Some)
            .map_err(|why| format!("{EXTENSION}: {name}: {why}"))
    };
    let translation = attribute("TRANSLATION")?;
    let rotation = attribute("ROTATION")?;
    let scale = attribute("SCALE")?;
    let counts: Vec<usize> = [&translation, &rotation, &scale]
        .iter()
        .filter_map(|a| a.as_ref().map(|a| a.len()))
        .collect();
    let Some(&count) = counts.first() else {
        return Err(format!(
            "{EXTENSION} without TRANSLATION, ROTATION or SCALE"
        ));
    };
    if counts.iter().any(|&n| n != count) {
        return Err(format!(
            "{EXTENSION}: its attributes have different counts ({counts:?})"
        ));
    }
    check_memory(
        || format!("{EXTENSION} instances"),
        bytes_of::<Mat4>(count as u64),
    )
    .map_err(|e| e.to_string())?;
    let transforms = (0..count)
        .map(|i| {
            let t = translation
                .as_ref()
                .map_or(Vec3::ZERO, |a| Vec3::from(a.get::<3>(i)));
            let r = rotation.as_ref().map_or(Quat::IDENTITY, |a| {
                let q = Quat::from_array(a.get::<4>(i));
                let length = q.length();
                if length.is_finite() && length > 0.0 {
                    q / length
                } else {
                    Quat::IDENTITY
                }
            });
            let s = scale
                .as_ref()
                .map_or(Vec3::ONE, |a| Vec3::from(a.get::<3>(i)));
            Mat4::from_scale_rotation_translation(s, r, t)
        })
        .collect();
    Ok(Some(transforms))
}
