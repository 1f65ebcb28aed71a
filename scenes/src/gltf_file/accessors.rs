//! Reading accessors with every offset and length checked against the buffers, so that a
//! truncated or lying file is an error that names the accessor, never a panic or garbage.

use gltf::accessor::{Accessor, DataType, Dimensions};
use gltf::buffer::View;

/// The bytes of each buffer of the file, by index, at least as long as the file declares.
pub(crate) type Buffers = [Vec<u8>];

/// `accessor`'s elements as 3-vectors of `f32`, widened; sparse substitutions applied.
pub(crate) fn vec3_f32(buffers: &Buffers, accessor: &Accessor) -> Result<Vec<[f64; 3]>, String> {
    if accessor.data_type() != DataType::F32 || accessor.dimensions() != Dimensions::Vec3 {
        return Err(format!(
            "holds {:?} {:?}, not VEC3 FLOAT (quantized positions, KHR_mesh_quantization, are not \
             read)",
            accessor.dimensions(),
            accessor.data_type()
        ));
    }
    let read = |bytes: &[u8]| {
        let f = |k: usize| f64::from(f32::from_le_bytes([0, 1, 2, 3].map(|i| bytes[4 * k + i])));
        [f(0), f(1), f(2)]
    };
    elements(buffers, accessor, 12, read)
}

/// `accessor`'s elements as vertex indices (unsigned bytes, shorts or ints).
pub(crate) fn indices(buffers: &Buffers, accessor: &Accessor) -> Result<Vec<u32>, String> {
    if accessor.dimensions() != Dimensions::Scalar {
        return Err(format!(
            "holds {:?} values, not SCALAR indices",
            accessor.dimensions()
        ));
    }
    let size = match accessor.data_type() {
        DataType::U8 => 1,
        DataType::U16 => 2,
        DataType::U32 => 4,
        other => return Err(format!("holds {other:?} values, not unsigned indices")),
    };
    elements(buffers, accessor, size, |b| unsigned(b, size))
}

/// A little-endian unsigned integer of `size` bytes (1, 2 or 4).
fn unsigned(bytes: &[u8], size: usize) -> u32 {
    (0..size).fold(0u32, |v, i| v | (u32::from(bytes[i]) << (8 * i)))
}

/// `accessor`'s `count` elements of `size` bytes each, read by `read`: from its view (zeros
/// without one), then its sparse substitutions.
fn elements<T: Copy + Default>(
    buffers: &Buffers,
    accessor: &Accessor,
    size: usize,
    read: impl Fn(&[u8]) -> T,
) -> Result<Vec<T>, String> {
    let count = accessor.count();
    let mut out = match accessor.view() {
        Some(view) => strided(buffers, &view, accessor.offset(), count, size)?
            .map(&read)
            .collect(),
        None => vec![T::default(); count],
    };
    if let Some(sparse) = accessor.sparse() {
        let n = sparse.count();
        let indices = sparse.indices();
        let index_size = indices.index_type().size();
        let at: Vec<u32> = strided(buffers, &indices.view(), indices.offset(), n, index_size)?
            .map(|b| unsigned(b, index_size))
            .collect();
        let values = sparse.values();
        let values = strided(buffers, &values.view(), values.offset(), n, size)?;
        for (i, bytes) in at.into_iter().zip(values) {
            let slot = out.get_mut(i as usize).ok_or_else(|| {
                format!("has a sparse substitution at element {i}, past its {count} elements")
            })?;
            *slot = read(bytes);
        }
    }
    Ok(out)
}

/// `count` runs of `size` bytes from `offset` into `view`, at the view's stride (or packed).
fn strided<'b>(
    buffers: &'b Buffers,
    view: &View,
    offset: usize,
    count: usize,
    size: usize,
) -> Result<impl Iterator<Item = &'b [u8]> + use<'b>, String> {
    let buffer = view.buffer().index();
    let data = buffers
        .get(buffer)
        .ok_or_else(|| format!("reads buffer {buffer}, which the file does not have"))?;
    let view_end = view.offset().checked_add(view.length());
    let bytes = view_end
        .and_then(|end| data.get(view.offset()..end))
        .ok_or_else(|| {
            format!(
                "reads buffer view {} (bytes {} to {} of buffer {buffer}), but the buffer holds {} \
                 bytes: is the file truncated?",
                view.index(),
                view.offset(),
                view.offset().saturating_add(view.length()),
                data.len()
            )
        })?;
    let stride = view.stride().unwrap_or(size);
    if stride < size {
        return Err(format!(
            "has elements of {size} bytes, but its buffer view {} strides {stride}",
            view.index()
        ));
    }
    let end = match count {
        0 => Some(offset),
        _ => (count - 1)
            .checked_mul(stride)
            .and_then(|s| s.checked_add(offset))
            .and_then(|s| s.checked_add(size)),
    };
    let bytes = end.and_then(|end| bytes.get(offset..end)).ok_or_else(|| {
        format!(
            "needs {count} elements of {size} bytes from byte {offset} of buffer view {}, which \
             holds {} bytes",
            view.index(),
            bytes.len()
        )
    })?;
    Ok((0..count).map(move |k| &bytes[k * stride..k * stride + size]))
}
