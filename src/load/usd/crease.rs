//! A subdivision surface's creases as UsdGeomMesh stores them: `creaseIndices` in runs of
//! `creaseLengths` points, each run's edges sharp by `creaseSharpnesses` (one value per run,
//! or one per edge), and `cornerIndices` with `cornerSharpnesses`. Blender writes an edge
//! crease c as sharpness 10·c² and a vertex crease of 1 as 10 (infinitely sharp).

use openusd::sdf;

use super::UsdLoader;
use super::value::{as_f64s, as_ints};
use crate::load::subdivision::{INFINITE_SHARPNESS, Sharpness};

impl UsdLoader {
    /// The creases of the mesh at `path` over `points` points; malformed crease data is
    /// left out with a warning naming what is wrong (the surface is then smooth there).
    pub(super) fn creases(&mut self, path: &sdf::Path, points: usize) -> Sharpness {
        let mut sharpness = Sharpness::default();
        match self.edge_creases(path, points) {
            Ok(edges) => sharpness.edges = edges,
            Err(why) => self.warn(format!(
                "{}: edge creases not applied: {why}",
                path.as_str()
            )),
        }
        match self.corner_creases(path, points) {
            Ok(corners) => sharpness.points = corners,
            Err(why) => self.warn(format!(
                "{}: corner creases not applied: {why}",
                path.as_str()
            )),
        }
        if let Some(method) = self.get_token(path, "creaseMethod")
            && method != "uniform"
            && !sharpness.is_empty()
        {
            self.warn(format!(
                "{}: creaseMethod '{method}' is not supported; creases decay uniformly",
                path.as_str()
            ));
        }
        sharpness
    }

    fn ints(&self, path: &sdf::Path, name: &str) -> Vec<i64> {
        self.get(path, name)
            .as_ref()
            .and_then(as_ints)
            .unwrap_or_default()
    }

    fn floats(&self, path: &sdf::Path, name: &str) -> Vec<f64> {
        self.get(path, name)
            .as_ref()
            .and_then(as_f64s)
            .unwrap_or_default()
    }

    fn edge_creases(
        &self,
        path: &sdf::Path,
        points: usize,
    ) -> Result<std::collections::HashMap<(usize, usize), f32>, String> {
        let indices = point_indices(&self.ints(path, "creaseIndices"), points)?;
        let lengths = self.ints(path, "creaseLengths");
        let values = self.floats(path, "creaseSharpnesses");
        let mut edges = std::collections::HashMap::new();
        if indices.is_empty() {
            return Ok(edges);
        }
        if lengths.iter().any(|&l| l < 2) {
            return Err("a creaseLengths entry is below 2".into());
        }
        let total: i64 = lengths.iter().sum();
        if total != indices.len() as i64 {
            return Err(format!(
                "creaseLengths add up to {total}, creaseIndices has {}",
                indices.len()
            ));
        }
        let edge_count = indices.len() - lengths.len();
        let per_edge = values.len() == edge_count && values.len() != lengths.len();
        if values.len() != lengths.len() && !per_edge {
            return Err(format!(
                "{} creaseSharpnesses for {} creases of {edge_count} edges",
                values.len(),
                lengths.len()
            ));
        }
        let (mut start, mut edge) = (0, 0);
        for (run, &length) in lengths.iter().enumerate() {
            let run_points = &indices[start..start + length as usize];
            for pair in run_points.windows(2) {
                let value = values[if per_edge { edge } else { run }];
                let s = sharpness_of(value);
                if s > 0.0 {
                    edges.insert((pair[0].min(pair[1]), pair[0].max(pair[1])), s);
                }
                edge += 1;
            }
            start += length as usize;
        }
        Ok(edges)
    }

    fn corner_creases(
        &self,
        path: &sdf::Path,
        points: usize,
    ) -> Result<std::collections::HashMap<usize, f32>, String> {
        let indices = point_indices(&self.ints(path, "cornerIndices"), points)?;
        let values = self.floats(path, "cornerSharpnesses");
        if values.len() != indices.len() {
            return Err(format!(
                "{} cornerSharpnesses for {} cornerIndices",
                values.len(),
                indices.len()
            ));
        }
        Ok(indices
            .into_iter()
            .zip(values)
            .map(|(v, s)| (v, sharpness_of(s)))
            .filter(|&(_, s)| s > 0.0)
            .collect())
    }
}

/// Point indices, each checked against the mesh's `points`.
fn point_indices(indices: &[i64], points: usize) -> Result<Vec<usize>, String> {
    indices
        .iter()
        .map(|&i| {
            usize::try_from(i)
                .ok()
                .filter(|&i| i < points)
                .ok_or_else(|| format!("point index {i} is outside the {points} points"))
        })
        .collect()
}

/// A sharpness clamped to [0, infinite]; not a number is smooth.
fn sharpness_of(value: f64) -> f32 {
    if value.is_nan() {
        0.0
    } else {
        (value as f32).clamp(0.0, INFINITE_SHARPNESS)
    }
}
