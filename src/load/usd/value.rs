//! Reading typed values off the stage: scalars, vectors, arrays, tokens and asset paths
//! at a time code, whatever precision the layer stored them in.

use glam::{Vec2, Vec3};
use openusd::{sdf, usd};

/// A value read from the stage at `time`, whatever its precision.
pub(super) fn value(
    stage: &usd::Stage,
    prim: &sdf::Path,
    name: &str,
    time: usd::TimeCode,
) -> Option<sdf::Value> {
    let path = prim.append_property(name).ok()?;
    stage
        .attribute(path)
        .get_at::<sdf::Value>(time)
        .ok()
        .flatten()
}

/// A scalar as f64. Whole numbers count: openusd 0.6 reads a `.usda` time sample written
/// `50` as an Int64 whatever the attribute's declared type.
pub(super) fn as_f64(v: &sdf::Value) -> Option<f64> {
    match v {
        sdf::Value::Double(d) => Some(*d),
        sdf::Value::Float(f) => Some(*f as f64),
        sdf::Value::Half(h) => Some(h.to_f32() as f64),
        sdf::Value::Int(i) => Some(*i as f64),
        sdf::Value::Int64(i) => Some(*i as f64),
        _ => None,
    }
}

pub(super) fn as_vec3(v: &sdf::Value) -> Option<Vec3> {
    match v {
        sdf::Value::Vec3f(a) => Some(Vec3::new(a.x, a.y, a.z)),
        sdf::Value::Vec3d(a) => Some(Vec3::new(a.x as f32, a.y as f32, a.z as f32)),
        sdf::Value::Vec3h(a) => Some(Vec3::new(a.x.to_f32(), a.y.to_f32(), a.z.to_f32())),
        _ => None,
    }
}

pub(super) fn as_vec3s(v: &sdf::Value) -> Option<Vec<Vec3>> {
    match v {
        sdf::Value::Vec3fVec(a) => Some(a.iter().map(|a| Vec3::new(a.x, a.y, a.z)).collect()),
        sdf::Value::Vec3dVec(a) => Some(
            a.iter()
                .map(|a| Vec3::new(a.x as f32, a.y as f32, a.z as f32))
                .collect(),
        ),
        sdf::Value::Vec3hVec(a) => Some(
            a.iter()
                .map(|a| Vec3::new(a.x.to_f32(), a.y.to_f32(), a.z.to_f32()))
                .collect(),
        ),
        _ => None,
    }
}

pub(super) fn as_vec2s(v: &sdf::Value) -> Option<Vec<Vec2>> {
    match v {
        sdf::Value::Vec2fVec(a) => Some(a.iter().map(|a| Vec2::new(a.x, a.y)).collect()),
        sdf::Value::Vec2dVec(a) => Some(
            a.iter()
                .map(|a| Vec2::new(a.x as f32, a.y as f32))
                .collect(),
        ),
        _ => None,
    }
}

pub(super) fn as_f64s(v: &sdf::Value) -> Option<Vec<f64>> {
    match v {
        sdf::Value::FloatVec(a) => Some(a.iter().map(|&x| x as f64).collect()),
        sdf::Value::DoubleVec(a) => Some(a.clone()),
        sdf::Value::HalfVec(a) => Some(a.iter().map(|x| x.to_f32() as f64).collect()),
        _ => None,
    }
}

pub(super) fn as_ints(v: &sdf::Value) -> Option<Vec<i64>> {
    match v {
        sdf::Value::IntVec(a) => Some(a.iter().map(|&i| i as i64).collect()),
        sdf::Value::Int64Vec(a) => Some(a.clone()),
        sdf::Value::UintVec(a) => Some(a.iter().map(|&i| i as i64).collect()),
        _ => None,
    }
}

pub(super) fn as_token(v: &sdf::Value) -> Option<String> {
    match v {
        sdf::Value::Token(t) => Some(t.as_str().to_string()),
        sdf::Value::String(s) => Some(s.clone()),
        _ => None,
    }
}

pub(super) fn as_bool(v: &sdf::Value) -> Option<bool> {
    match v {
        sdf::Value::Bool(b) => Some(*b),
        sdf::Value::Int(i) => Some(*i != 0),
        _ => None,
    }
}

/// How a primvar's values map onto a mesh (UsdGeom primvar interpolation).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum Interpolation {
    /// One value for the whole mesh.
    Constant,
    /// One value per face.
    Uniform,
    /// One value per point.
    Vertex,
    /// One value per face corner.
    FaceVarying,
}
