//! Errors of rendering and plotting.

/// What can go wrong when rendering: inputs that do not fit together, or a failed encoding.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum VizError {
    #[error(
        "image size {width} x {height} is not usable: each side must be at least 1 and the image at most {max_pixels} pixels"
    )]
    ImageSize {
        width: u32,
        height: u32,
        max_pixels: u64,
    },
    #[error("exposure {exposure} must be finite and positive")]
    InvalidExposure { exposure: f64 },
    #[error("ambient term [{r}, {g}, {b}] must be finite")]
    InvalidAmbient { r: f64, g: f64, b: f64 },
    #[error("camera is unusable: {reason}")]
    InvalidCamera { reason: &'static str },
    #[error("radiosity is given for {found} surfaces but the mesh has {expected}")]
    SurfaceCount { expected: usize, found: usize },
    #[error(
        "mesh {mesh_index} belongs to surface {surface}, but the scene has only {surfaces} surfaces"
    )]
    UnknownSurface {
        mesh_index: usize,
        surface: usize,
        surfaces: usize,
    },
    #[error("surface {surface} has {found} radiosity values for {expected} mesh vertices")]
    VertexCount {
        surface: usize,
        expected: usize,
        found: usize,
    },
    #[error("surface {surface}: triangle {triangle} refers to a vertex that does not exist")]
    InvalidTriangle { surface: usize, triangle: usize },
    #[error("surface {surface}: vertex {vertex} has a radiosity or position that is not finite")]
    NotFinite { surface: usize, vertex: usize },
    #[error("PNG encoding failed: {0}")]
    Png(#[from] image::ImageError),
}
