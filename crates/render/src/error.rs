//! Typed errors of the renderer.

use std::path::PathBuf;

/// Everything that can go wrong while rendering, writing an image or measuring throughput.
#[derive(Debug, thiserror::Error)]
pub enum RenderError {
    /// Width, height or samples per pixel is zero, or the frame breaks a limit of
    /// [`validate`](crate::validate).
    #[error("invalid render settings: {width}x{height} at {spp} spp ({reason})")]
    Settings {
        /// Width in pixels.
        width: u32,
        /// Height in pixels.
        height: u32,
        /// Samples per pixel.
        spp: u32,
        /// What is wrong, with the limit it breaks.
        reason: String,
    },
    /// The camera cannot form a view basis (eye on target, view parallel to up, bad field of
    /// view, non-finite values).
    #[error(
        "invalid camera (eye {eye:?}, target {target:?}, up {up:?}, fov {fov_y_deg}°): {reason}"
    )]
    Camera {
        /// Eye position.
        eye: [f32; 3],
        /// Target point.
        target: [f32; 3],
        /// Up vector.
        up: [f32; 3],
        /// Vertical field of view in degrees.
        fov_y_deg: f32,
        /// What is wrong.
        reason: &'static str,
    },
    /// The light has a non-finite position or one beyond ±2^60, a negative radius or one
    /// above 2^60, a negative intensity, or a power (`2 · intensity · d²`) that overflows.
    #[error(
        "invalid light (position {position:?}, radius {radius}, intensity {intensity}): {reason}"
    )]
    Light {
        /// What is wrong.
        reason: &'static str,
        /// Centre.
        position: [f32; 3],
        /// Radius.
        radius: f32,
        /// Intensity.
        intensity: f32,
    },
    /// A structure returned a different result than the reference (BVH2, or the first
    /// traversal of a single tree) for a benchmark ray.
    #[error(
        "{accel}: {ray_kind} ray #{index} gives {got}, the reference gives {expected} (ray {ray}); refusing to time it"
    )]
    Mismatch {
        /// Structure name.
        accel: &'static str,
        /// Ray kind name.
        ray_kind: &'static str,
        /// Index of the ray in its set.
        index: usize,
        /// The ray, formatted.
        ray: String,
        /// The reference's result, formatted.
        expected: String,
        /// The structure's result, formatted.
        got: String,
    },
    /// The structures given have no traversal of this kind (one saved tree holds one
    /// structure).
    #[error("no {accel} traversal here: the structures given have {available}")]
    Unsupported {
        /// The traversal asked for.
        accel: &'static str,
        /// The traversals there are, comma-separated.
        available: String,
    },
    /// Writing an image failed.
    #[error("{path}: {message}")]
    Write {
        /// The output file.
        path: PathBuf,
        /// What failed.
        message: String,
    },
    /// The output file's extension is neither `.png` nor `.exr`.
    #[error("{path}: unknown image format (expected .png or .exr)")]
    UnknownFormat {
        /// The output file.
        path: PathBuf,
    },
}
