//! Scenes for dualsplit: triangle soups with a camera and a light.
//!
//! A scene is addressed by a *spec*: a file path (`.obj`, `.ply`, either also `.gz`, `.gltf`,
//! `.glb`) or `builtin:NAME?key=value&...` (see [`builtin`]). [`load()`] resolves a spec into a
//! [`Scene`]. Builtins come with their own camera and light; files get the preset of their
//! stem ([`Camera::preset_for`], see `docs/scenes.md`) or a fit to their bounds.
//!
//! ```no_run
//! let scene = dualsplit_scene::load("builtin:cornell").unwrap();
//! assert!(scene.triangles.len() > 0);
//! ```
//!
//! ## Budgets
//!
//! Scene files are untrusted: every load works within a [`Limits`] (a triangle budget and
//! a byte budget, see [`limits`]), and only regular files are read. [`load()`] uses the
//! defaults; [`load_with`] takes others.
//!
//! ## Degenerate and non-finite triangles
//!
//! One rule everywhere: triangles with a non-finite coordinate (NaN or ±∞) are **dropped**
//! at load time and counted in [`LoadStats::non_finite`]; zero-area triangles are **kept**
//! (they are real input and never hit by the watertight test) and counted in
//! [`LoadStats::degenerate`]. A scene with no triangle left is an error ([`SceneError::Empty`]).
//!
//! ## Extent
//!
//! A scene wider than [`Scene::MAX_EXTENT`] (2^60 ≈ 1.15e18) on some axis is refused with
//! [`SceneError::Extent`], which names the extent and the bounds; one that reaches farther
//! than [`Scene::MAX_COORDINATE`] (also 2^60) from the origin on some axis, however small,
//! with [`SceneError::Far`]. Coordinates up to ±3.4e38 are valid f32, but their sums and
//! differences overflow: a box from −3e38 to 3e38 has an infinite extent, a single point
//! at 3e38 an infinite centre, a surface area overflows from about 1.8e19 across, the
//! fitted camera sits about 2.3 extents from the scene's centre, and a ray test multiplies
//! two vertex offsets from the ray's origin. Within both limits every one of these stays
//! finite.
//!
//! Triangle ids follow the file: the loaders emit triangles in face order of the file, each
//! polygon fan-triangulated in place (see [`load`](mod@load)), and dropping keeps that order.
//! So a triangle's id is its face index in the file after triangulation, minus the number of
//! non-finite triangles before it: ids equal file face indices whenever
//! [`LoadStats::non_finite`] is zero.

pub mod builtin;
mod camera;
mod error;
pub mod limits;
pub mod load;
pub mod make;

pub use camera::{Camera, CameraError, Light, MAX_VIEW_COORDINATE, parse_vec3};
pub use error::{FileError, SceneError};
pub use limits::Limits;

use dualsplit_geometry::{Aabb, Triangle};

/// Counts gathered while loading.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize)]
pub struct LoadStats {
    /// Triangles in the source (after triangulating polygons), before dropping.
    pub source_triangles: u64,
    /// Zero-area triangles (kept).
    pub degenerate: u64,
    /// Triangles with a NaN or infinite coordinate (dropped).
    pub non_finite: u64,
    /// Polygons with more than three vertices that were fan-triangulated.
    pub polygons_triangulated: u64,
    /// glTF primitives skipped because their mode is not `TRIANGLES` (points, lines, strips,
    /// fans).
    pub primitives_skipped: u64,
}

/// A loaded scene: the triangle soup, its bounds, and a default camera and light.
#[derive(Clone, Debug)]
pub struct Scene {
    /// A short display name (file stem or builtin name).
    pub name: String,
    /// The spec the scene was loaded from.
    pub spec: String,
    /// The triangles; a triangle's id is its index here.
    pub triangles: Vec<Triangle>,
    /// Bounds of all triangles.
    pub bounds: Aabb,
    /// Default camera (fit to bounds, or a preset for known scenes).
    pub camera: Camera,
    /// Default light.
    pub light: Light,
    /// What loading found.
    pub stats: LoadStats,
}

impl Scene {
    /// Widest extent (`max − min` of the bounds) a scene may have on any axis: 2^60 ≈
    /// 1.15e18 (see the crate docs, "Extent").
    pub const MAX_EXTENT: f32 = (1u64 << 60) as f32;

    /// Farthest a scene's bounds may reach from the origin on any axis: 2^60 ≈ 1.15e18 (see
    /// the crate docs, "Extent").
    pub const MAX_COORDINATE: f32 = (1u64 << 60) as f32;

    /// Builds a scene from triangles, dropping non-finite ones (counted), counting degenerate
    /// ones, and fitting a default camera and light to the bounds. A scene wider than
    /// [`Scene::MAX_EXTENT`] is [`SceneError::Extent`]; one reaching beyond
    /// ±[`Scene::MAX_COORDINATE`] is [`SceneError::Far`].
    pub fn from_triangles(
        name: impl Into<String>,
        spec: impl Into<String>,
        triangles: Vec<Triangle>,
        mut stats: LoadStats,
    ) -> Result<Self, SceneError> {
        let spec = spec.into();
        stats.source_triangles = stats.source_triangles.max(triangles.len() as u64);
        // Parallel passes (millions of triangles for the big scenes); order is kept and the
        // bounds are exact min/max, so the result does not depend on the thread count.
        use rayon::prelude::*;
        let before = triangles.len();
        // One pass: all finite?, degenerate count, bounds.
        let (finite, degenerate, bounds) = triangles
            .par_iter()
            .with_min_len(1 << 12)
            .fold(
                || (true, 0u64, Aabb::EMPTY),
                |(f, d, b), t| {
                    if t.is_finite() {
                        (f, d + u64::from(t.is_degenerate()), b.union(t.bounds()))
                    } else {
                        (false, d, b)
                    }
                },
            )
            .reduce(
                || (true, 0, Aabb::EMPTY),
                |x, y| (x.0 && y.0, x.1 + y.1, x.2.union(y.2)),
            );
        let triangles: Vec<Triangle> = if finite {
            triangles
        } else {
            triangles
                .into_par_iter()
                .filter(|t| t.is_finite())
                .collect()
        };
        stats.non_finite += (before - triangles.len()) as u64;
        stats.degenerate = degenerate;
        if triangles.is_empty() {
            return Err(SceneError::Empty { spec });
        }
        let extent = bounds.max - bounds.min;
        if !extent.cmple(glam::Vec3::splat(Self::MAX_EXTENT)).all() {
            return Err(SceneError::Extent {
                spec,
                min: bounds.min.to_array(),
                max: bounds.max.to_array(),
                extent: extent.to_array(),
                limit: Self::MAX_EXTENT,
            });
        }
        let reach = bounds.min.abs().max(bounds.max.abs());
        if !reach.cmple(glam::Vec3::splat(Self::MAX_COORDINATE)).all() {
            return Err(SceneError::Far {
                spec,
                min: bounds.min.to_array(),
                max: bounds.max.to_array(),
                limit: Self::MAX_COORDINATE,
            });
        }
        let camera = Camera::fit(&bounds);
        let light = Light::fit(&bounds);
        Ok(Self {
            name: name.into(),
            spec,
            triangles,
            bounds,
            camera,
            light,
            stats,
        })
    }

    /// A 64-bit content hash of the triangle data (for result caches).
    pub fn content_hash(&self) -> String {
        use sha2::{Digest, Sha256};
        let mut h = Sha256::new();
        for t in &self.triangles {
            for p in &t.v {
                h.update(p.x.to_le_bytes());
                h.update(p.y.to_le_bytes());
                h.update(p.z.to_le_bytes());
            }
        }
        let d = h.finalize();
        d[..8].iter().map(|b| format!("{b:02x}")).collect()
    }
}

/// Loads a scene from a spec: a file path or `builtin:NAME?params`, within the default
/// [`Limits`].
pub fn load(spec: &str) -> Result<Scene, SceneError> {
    load_with(spec, &Limits::default())
}

/// [`load()`] within `limits` (see [`limits`]).
pub fn load_with(spec: &str, limits: &Limits) -> Result<Scene, SceneError> {
    if let Some(rest) = spec.strip_prefix("builtin:") {
        builtin::generate_with(rest, limits)
    } else {
        let path = std::path::Path::new(spec);
        let mut scene = load::load_file_with(path, limits)?;
        let stem = file_stem(path);
        scene.camera = Camera::preset_for(stem, &scene.bounds);
        scene.light = Light::preset_for(stem, &scene.bounds);
        Ok(scene)
    }
}

/// The file name without its scene extensions (`.ply`, `.obj`, `.gz`, ...): the key of the
/// camera and light presets (`dragon_box.ply.gz` → `dragon_box`).
pub fn file_stem(path: &std::path::Path) -> &str {
    let mut name = path.file_name().and_then(|n| n.to_str()).unwrap_or("");
    for ext in [".gz", ".obj", ".ply", ".gltf", ".glb"] {
        if let Some(s) = name.strip_suffix(ext) {
            name = s;
        }
    }
    name
}
