//! Motion during the shutter: transforms at evenly spaced instants, and the part of the
//! shutter in which a time slice of a deforming mesh is seen.
//!
//! Shutter time is a fraction in [0, 1): 0 when the shutter opens, 1 when it closes. Each
//! camera sample draws one time, and every ray of its path sees the scene at that time.

use glam::{Affine3A, Vec3A};

use crate::geometry::Aabb;

/// Transforms at `keys.len()` ≥ 2 instants spread evenly over the shutter, interpolated
/// linearly (matrix by matrix) between neighbours.
///
/// Linear interpolation of matrices moves every point along a straight line between two
/// keys, so a box's image at any time lies within the union of its images at the keys,
/// and the bounds stay exact; rotations are followed by adding keys, not by slerp.
#[derive(Clone, Debug, PartialEq)]
pub struct Motion {
    keys: Vec<Affine3A>,
}

impl Motion {
    /// Motion through `keys` (at least two), or `None` when they are all the same.
    pub fn from_keys(keys: Vec<Affine3A>) -> Option<Motion> {
        (keys.len() >= 2 && keys.iter().any(|k| *k != keys[0])).then_some(Motion { keys })
    }

    /// The transforms at the instants, first at the shutter's opening.
    pub fn keys(&self) -> &[Affine3A] {
        &self.keys
    }

    /// The transform at shutter time `time` in [0, 1] (clamped).
    pub fn at(&self, time: f32) -> Affine3A {
        let last = self.keys.len() - 1;
        let x = time.clamp(0.0, 1.0) * last as f32;
        let i = (x as usize).min(last - 1);
        let f = x - i as f32;
        let (a, b) = (&self.keys[i], &self.keys[i + 1]);
        Affine3A {
            matrix3: a.matrix3 * (1.0 - f) + b.matrix3 * f,
            translation: a.translation + (b.translation - a.translation) * f,
        }
    }

    /// Bounds of `object` (in object space) over the whole shutter.
    pub fn bounds(&self, object: &Aabb) -> Aabb {
        self.keys
            .iter()
            .fold(Aabb::EMPTY, |b, key| b.union(object.transformed(key)))
    }

    /// Largest distance any corner of `object` travels between two keys, for messages and
    /// tests.
    pub fn largest_step(&self, object: &Aabb) -> f32 {
        let corners = (0..8).map(|i| {
            Vec3A::new(
                if i & 1 == 0 {
                    object.min.x
                } else {
                    object.max.x
                },
                if i & 2 == 0 {
                    object.min.y
                } else {
                    object.max.y
                },
                if i & 4 == 0 {
                    object.min.z
                } else {
                    object.max.z
                },
            )
        });
        corners
            .flat_map(|c| {
                self.keys
                    .windows(2)
                    .map(move |w| (w[1].transform_point3a(c) - w[0].transform_point3a(c)).length())
            })
            .fold(0.0, f32::max)
    }
}

/// The part of the shutter, [start, end), in which something is seen: one time slice of a
/// deforming mesh, which is rebuilt at each key and shown around its instant.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TimeSlice {
    /// First time in the slice.
    pub start: f32,
    /// First time after it.
    pub end: f32,
}

impl TimeSlice {
    /// Slice `index` of `count` keys spread evenly over the shutter: the times nearer to
    /// its key than to any other (the first and last reach the shutter's ends).
    pub fn around_key(index: usize, count: usize) -> TimeSlice {
        let step = 1.0 / (count - 1).max(1) as f32;
        let start = if index == 0 {
            f32::NEG_INFINITY
        } else {
            (index as f32 - 0.5) * step
        };
        let end = if index + 1 >= count {
            f32::INFINITY
        } else {
            (index as f32 + 0.5) * step
        };
        TimeSlice { start, end }
    }

    /// True when the slice holds shutter time `time`.
    pub fn contains(&self, time: f32) -> bool {
        self.start <= time && time < self.end
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    #[test]
    fn keys_interpolate_linearly_and_bound_the_sweep() {
        let keys = vec![
            Affine3A::from_translation(Vec3::ZERO),
            Affine3A::from_translation(Vec3::new(2.0, 0.0, 0.0)),
            Affine3A::from_translation(Vec3::new(2.0, 4.0, 0.0)),
        ];
        let motion = Motion::from_keys(keys).unwrap();
        assert_eq!(motion.at(0.25).translation, Vec3A::new(1.0, 0.0, 0.0));
        assert_eq!(motion.at(0.75).translation, Vec3A::new(2.0, 2.0, 0.0));
        assert_eq!(motion.at(1.0).translation, Vec3A::new(2.0, 4.0, 0.0));
        let unit = Aabb {
            min: Vec3::ZERO,
            max: Vec3::ONE,
        };
        let b = motion.bounds(&unit);
        assert_eq!((b.min, b.max), (Vec3::ZERO, Vec3::new(3.0, 5.0, 1.0)));
        assert_eq!(motion.largest_step(&unit), 4.0);
        assert!(Motion::from_keys(vec![Affine3A::IDENTITY; 3]).is_none());
    }

    #[test]
    fn slices_cover_the_shutter_once() {
        let slices: Vec<TimeSlice> = (0..5).map(|i| TimeSlice::around_key(i, 5)).collect();
        for k in 0..=1000 {
            let t = k as f32 / 1000.0;
            assert_eq!(
                slices.iter().filter(|s| s.contains(t)).count(),
                1,
                "t = {t}"
            );
        }
        assert!(slices[2].contains(0.5) && !slices[2].contains(0.625));
    }
}
