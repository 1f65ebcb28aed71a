//! Errors of rendering and plotting.

/// What can go wrong when rendering: inputs that do not fit together, or a failed encoding.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum VizError {
    /// A side of the image is zero, or the image has too many pixels.
    #[error(
        "image size {width} x {height} is not usable: each side must be at least 1 and the image at most {max_pixels} pixels"
    )]
    ImageSize {
        /// The width asked for.
        width: u32,
        /// The height asked for.
        height: u32,
        /// The most pixels an image may have.
        max_pixels: u64,
    },
    /// The exposure is not finite and positive.
    #[error("exposure {exposure} must be finite and positive")]
    InvalidExposure {
        /// The exposure given.
        exposure: f64,
    },
    /// The ambient term is not finite.
    #[error("ambient term [{r}, {g}, {b}] must be finite")]
    InvalidAmbient {
        /// Red.
        r: f64,
        /// Green.
        g: f64,
        /// Blue.
        b: f64,
    },
    /// The camera cannot give a picture.
    #[error("camera is unusable: {reason}")]
    InvalidCamera {
        /// Why.
        reason: &'static str,
    },
    /// The radiosity has a list for another number of surfaces than the mesh.
    #[error("radiosity is given for {found} surfaces but the mesh has {expected}")]
    SurfaceCount {
        /// The mesh's surfaces.
        expected: usize,
        /// The radiosity's lists.
        found: usize,
    },
    /// A mesh names a surface the scene does not have.
    #[error(
        "mesh {mesh_index} belongs to surface {surface}, but the scene has only {surfaces} surfaces"
    )]
    UnknownSurface {
        /// The mesh's place in the scene mesh.
        mesh_index: usize,
        /// The surface it names.
        surface: usize,
        /// The scene's surfaces.
        surfaces: usize,
    },
    /// A surface's radiosity has another number of values than its mesh has vertices.
    #[error("surface {surface} has {found} radiosity values for {expected} mesh vertices")]
    VertexCount {
        /// The surface.
        surface: usize,
        /// Its mesh's vertices.
        expected: usize,
        /// Its radiosity values.
        found: usize,
    },
    /// A triangle refers to a vertex the mesh does not have.
    #[error("surface {surface}: triangle {triangle} refers to a vertex that does not exist")]
    InvalidTriangle {
        /// The surface.
        surface: usize,
        /// The triangle.
        triangle: usize,
    },
    /// A vertex's radiosity or position is NaN or infinite.
    #[error("surface {surface}: vertex {vertex} has a radiosity or position that is not finite")]
    NotFinite {
        /// The surface.
        surface: usize,
        /// The vertex.
        vertex: usize,
    },
    /// The image encoder failed.
    #[error("PNG encoding failed: {0}")]
    Png(#[from] image::ImageError),
    /// The chart library could not draw a chart (its font did not load, or a backend failed).
    #[error("chart drawing failed: {0}")]
    Chart(String),
}
