//! An accessor's elements as numbers, whatever their storage (glTF 2.0 §3.6.2): every
//! component type, normalised or not (`KHR_mesh_quantization` stores positions, normals,
//! tangents and texture coordinates as 8- and 16-bit integers), strided or packed, matrix
//! columns padded to 4 bytes, and sparse substitutions over a buffer view or over zeros
//! (an accessor without a `bufferView` is all zeros, §3.6.2.3).
//!
//! Every offset is checked against its buffer view and buffer before anything is read, and
//! the output is checked against the memory budget before it is allocated: counts come from
//! the file.

use gltf::accessor::{DataType, Dimensions};

use crate::limits::{bytes_of, check_memory};

/// An accessor's elements, `components` numbers each, in element order.
pub(super) struct Elements {
    pub values: Vec<f32>,
    pub components: usize,
}

impl Elements {
    /// Element `i` as an array of `N` numbers (missing components 0, extra ones dropped).
    pub fn get<const N: usize>(&self, i: usize) -> [f32; N] {
        let start = i * self.components;
        std::array::from_fn(|c| {
            if c < self.components {
                self.values[start + c]
            } else {
                0.0
            }
        })
    }

    /// How many elements there are.
    pub fn len(&self) -> usize {
        self.values.len() / self.components.max(1)
    }
}

/// The accessor's elements as `f32`: normalised integers mapped to [0, 1] or [−1, 1] by the
/// specification's rule (§3.11: `max(c / (2^(b−1) − 1), −1)` for signed), other integers
/// as their value.
pub(super) fn read_floats(
    accessor: &gltf::Accessor,
    buffers: &[gltf::buffer::Data],
) -> Result<Elements, String> {
    let normalized = accessor.normalized();
    let data_type = accessor.data_type();
    let values = read_with(accessor, buffers, |bytes| {
        let raw = component(data_type, bytes);
        if normalized {
            normalize(data_type, raw)
        } else {
            raw as f32
        }
    })?;
    Ok(Elements {
        values,
        components: accessor.dimensions().multiplicity(),
    })
}

/// An index accessor's values (unsigned integer scalars, §3.7.2.1).
pub(super) fn read_indices(
    accessor: &gltf::Accessor,
    buffers: &[gltf::buffer::Data],
) -> Result<Vec<u32>, String> {
    let integer = matches!(
        accessor.data_type(),
        DataType::U8 | DataType::U16 | DataType::U32
    );
    if !integer || accessor.dimensions() != Dimensions::Scalar {
        return Err(format!(
            "index accessor {} is {:?} {:?}, not unsigned integer scalars",
            accessor.index(),
            accessor.dimensions(),
            accessor.data_type()
        ));
    }
    let data_type = accessor.data_type();
    read_with(accessor, buffers, |bytes| {
        component(data_type, bytes) as u32
    })
}

/// The accessor's components, each converted by `convert` from its little-endian bytes.
fn read_with<T: Copy + Default>(
    accessor: &gltf::Accessor,
    buffers: &[gltf::buffer::Data],
    convert: impl Fn(&[u8]) -> T,
) -> Result<Vec<T>, String> {
    let layout = Layout::of(accessor);
    let count = accessor.count();
    // The bytes first: a count the buffer cannot hold is the file's error, not the budget's.
    let dense = match accessor.view() {
        Some(view) => {
            let stride = view.stride().unwrap_or(layout.element_size);
            if stride < layout.element_size {
                return Err(format!(
                    "buffer view {} has byte stride {stride}, smaller than accessor {}'s {}-byte elements (they would overlap)",
                    view.index(),
                    accessor.index(),
                    layout.element_size
                ));
            }
            let bytes = view_bytes(
                &view,
                accessor.offset(),
                stride,
                count,
                layout.element_size,
                buffers,
            )
            .map_err(|why| format!("accessor {} {why}", accessor.index()))?;
            Some((bytes, stride))
        }
        None => {
            check_zero_filled(accessor, buffers)?;
            None
        }
    };
    let total = (count as u64).saturating_mul(layout.components() as u64);
    check_memory(
        || format!("accessor {}", accessor.index()),
        bytes_of::<T>(total),
    )
    .map_err(|e| e.to_string())?;
    let mut values = vec![T::default(); total as usize];
    if let Some((bytes, stride)) = dense {
        for (i, out) in values.chunks_exact_mut(layout.components()).enumerate() {
            layout.read_element(&bytes[i * stride..], out, &convert);
        }
    }
    if let Some(sparse) = accessor.sparse() {
        let what = |why: String| format!("sparse accessor {}: {why}", accessor.index());
        let n = sparse.count();
        let indices = sparse.indices();
        let index_type = match indices.index_type() {
            gltf::accessor::sparse::IndexType::U8 => DataType::U8,
            gltf::accessor::sparse::IndexType::U16 => DataType::U16,
            gltf::accessor::sparse::IndexType::U32 => DataType::U32,
        };
        let index_size = index_type.size();
        let index_bytes = view_bytes(
            &indices.view(),
            indices.offset(),
            index_size,
            n,
            index_size,
            buffers,
        )
        .map_err(what)?;
        let value_view = sparse.values().view();
        let value_bytes = view_bytes(
            &value_view,
            sparse.values().offset(),
            layout.element_size,
            n,
            layout.element_size,
            buffers,
        )
        .map_err(what)?;
        for k in 0..n {
            let target = component(index_type, &index_bytes[k * index_size..]) as usize;
            if target >= count {
                return Err(what(format!(
                    "sparse index {k} substitutes an element past its {count} elements"
                )));
            }
            let out = &mut values[target * layout.components()..(target + 1) * layout.components()];
            layout.read_element(&value_bytes[k * layout.element_size..], out, &convert);
        }
    }
    Ok(values)
}

/// Fewest elements an accessor without a buffer view may always have.
const ZERO_FILLED_FLOOR: usize = 1 << 16;

/// Refuses an accessor without a buffer view (all zeros but for its sparse substitutes,
/// glTF 2.0 §3.6.2.3) holding more elements than the file's buffers hold bytes (and more
/// than [`ZERO_FILLED_FLOOR`]): every element that matters is set by sparse data or named
/// by an index, each taking at least a byte of some buffer, so a larger count only makes
/// a tiny file allocate without bound.
fn check_zero_filled(
    accessor: &gltf::Accessor,
    buffers: &[gltf::buffer::Data],
) -> Result<(), String> {
    let held: usize = buffers.iter().map(|b| b.0.len()).sum();
    let most = held.max(ZERO_FILLED_FLOOR);
    if accessor.count() > most {
        return Err(format!(
            "accessor {} has no buffer view and {} elements, more than the {most} its file's buffers could set",
            accessor.index(),
            accessor.count()
        ));
    }
    Ok(())
}

/// Where an accessor's components sit inside one element.
struct Layout {
    data_type: DataType,
    rows: usize,
    columns: usize,
    /// Bytes from one column to the next: matrix columns start on 4-byte boundaries.
    column_stride: usize,
    element_size: usize,
}

impl Layout {
    fn of(accessor: &gltf::Accessor) -> Layout {
        let data_type = accessor.data_type();
        let (rows, columns) = match accessor.dimensions() {
            Dimensions::Mat2 => (2, 2),
            Dimensions::Mat3 => (3, 3),
            Dimensions::Mat4 => (4, 4),
            other => (other.multiplicity(), 1),
        };
        let packed = rows * data_type.size();
        let column_stride = if columns > 1 {
            packed.next_multiple_of(4)
        } else {
            packed
        };
        Layout {
            data_type,
            rows,
            columns,
            column_stride,
            element_size: column_stride * columns,
        }
    }

    fn components(&self) -> usize {
        self.rows * self.columns
    }

    /// One element from `bytes` (which hold at least `element_size` bytes) into `out`.
    fn read_element<T>(&self, bytes: &[u8], out: &mut [T], convert: &impl Fn(&[u8]) -> T) {
        let size = self.data_type.size();
        for column in 0..self.columns {
            for row in 0..self.rows {
                let at = column * self.column_stride + row * size;
                out[column * self.rows + row] = convert(&bytes[at..at + size]);
            }
        }
    }
}

/// The bytes of `count` elements of `element_size` bytes, `stride` apart, starting `offset`
/// bytes into `view`: checked to lie inside the view and the view inside its buffer.
fn view_bytes<'a>(
    view: &gltf::buffer::View,
    offset: usize,
    stride: usize,
    count: usize,
    element_size: usize,
    buffers: &'a [gltf::buffer::Data],
) -> Result<&'a [u8], String> {
    // In u128: counts and offsets come from the file and may be anything up to 2^64.
    let needed = match count as u128 {
        0 => 0,
        n => offset as u128 + stride as u128 * (n - 1) + element_size as u128,
    };
    let buffer = buffers
        .get(view.buffer().index())
        .map_or(&[][..], |b| &b.0[..]);
    let view_end = view.offset() as u128 + view.length() as u128;
    if needed > view.length() as u128 || view_end > buffer.len() as u128 {
        return Err(format!(
            "needs {needed} bytes but buffer view {} holds {} (buffer {} has {})",
            view.index(),
            view.length(),
            view.buffer().index(),
            buffer.len()
        ));
    }
    let start = view.offset() + offset;
    Ok(&buffer[start..view.offset() + view.length()])
}

/// A component's value from its little-endian bytes.
fn component(data_type: DataType, b: &[u8]) -> f64 {
    match data_type {
        DataType::I8 => f64::from(b[0] as i8),
        DataType::U8 => f64::from(b[0]),
        DataType::I16 => f64::from(i16::from_le_bytes([b[0], b[1]])),
        DataType::U16 => f64::from(u16::from_le_bytes([b[0], b[1]])),
        DataType::U32 => f64::from(u32::from_le_bytes([b[0], b[1], b[2], b[3]])),
        DataType::F32 => f64::from(f32::from_le_bytes([b[0], b[1], b[2], b[3]])),
    }
}

/// A normalised integer already widened to `f32` (as decoders give it) mapped like
/// [`read_floats`] maps stored ones.
pub(super) fn normalize_as(data_type: DataType, c: f32) -> f32 {
    normalize(data_type, f64::from(c))
}

/// A normalised integer as a number in [0, 1] (unsigned) or [−1, 1] (signed), glTF 2.0 §3.11.
fn normalize(data_type: DataType, c: f64) -> f32 {
    let v = match data_type {
        DataType::I8 => (c / 127.0).max(-1.0),
        DataType::U8 => c / 255.0,
        DataType::I16 => (c / 32767.0).max(-1.0),
        DataType::U16 => c / 65535.0,
        DataType::U32 => c / f64::from(u32::MAX),
        DataType::F32 => c,
    };
    v as f32
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn normalised_integers_follow_the_specification() {
        assert_eq!(normalize(DataType::I8, -128.0), -1.0);
        assert_eq!(normalize(DataType::I8, 127.0), 1.0);
        assert_eq!(normalize(DataType::U16, 65535.0), 1.0);
        assert_eq!(normalize(DataType::I16, -32768.0), -1.0);
        assert!((normalize(DataType::U8, 128.0) - 128.0 / 255.0).abs() < 1e-7);
    }

    #[test]
    fn components_read_little_endian() {
        assert_eq!(component(DataType::I16, &[0xfe, 0xff]), -2.0);
        assert_eq!(component(DataType::U32, &[1, 0, 0, 1]), 16_777_217.0);
        assert_eq!(component(DataType::F32, &1.5f32.to_le_bytes()), 1.5);
    }
}
