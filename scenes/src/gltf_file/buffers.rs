//! The bytes of a glTF file's buffers: the GLB's binary chunk, `data:` URIs, or files beside it.

use std::path::Path;

use base64::Engine;
use gltf::buffer::Source;
use percent_encoding::percent_decode_str;

/// Every buffer of `document`, in order, each at least as long as the file declares. `dir` is
/// where relative URIs are looked for; `blob` is a GLB's binary chunk.
pub(crate) fn read_buffers(
    document: &gltf::Document,
    dir: &Path,
    mut blob: Option<Vec<u8>>,
) -> Result<Vec<Vec<u8>>, String> {
    let mut buffers = Vec::new();
    for buffer in document.buffers() {
        let i = buffer.index();
        let data = match buffer.source() {
            Source::Bin => blob.take().ok_or_else(|| {
                format!("buffer {i} is the GLB's binary chunk, but the file has none")
            })?,
            Source::Uri(uri) => read_uri(uri, dir).map_err(|e| format!("buffer {i}: {e}"))?,
        };
        if data.len() < buffer.length() {
            return Err(format!(
                "buffer {i} holds {} bytes, but the file declares {}: is it truncated?",
                data.len(),
                buffer.length()
            ));
        }
        buffers.push(data);
    }
    Ok(buffers)
}

/// The bytes a buffer's URI names: base64 data, or a file relative to `dir`.
fn read_uri(uri: &str, dir: &Path) -> Result<Vec<u8>, String> {
    if let Some(rest) = uri.strip_prefix("data:") {
        let (_, data) = rest
            .split_once(";base64,")
            .ok_or("a data URI that is not base64")?;
        return base64::engine::general_purpose::STANDARD
            .decode(data)
            .map_err(|e| format!("its base64 data cannot be decoded: {e}"));
    }
    if uri.contains("://") {
        return Err(format!(
            "{uri:?} is not a file beside the scene; only relative paths and data URIs are read"
        ));
    }
    let name = percent_decode_str(uri).decode_utf8_lossy();
    let path = dir.join(name.as_ref());
    std::fs::read(&path).map_err(|e| format!("cannot read {}: {e}", path.display()))
}
