//! Reference renderer: the paper's two workloads (Lin et al. 2020, §4.3 ray casting with a
//! shadow ray, §4.4 path tracing with 5 diffuse bounces), generic over the acceleration
//! structure ([`AccelKind`]: bvh2, bvh4, bvh8, dst-sw, dst), plus images and CPU throughput.
//!
//! ```text
//!   PixelJob (job.rs)          one pixel: next_ray() → trace → submit(result) → …
//!      │   randoms = hash(x, y, sample, bounce, seed, dim): any pixel regenerates alone
//!      ├─ trace_pixel (trace.rs)   one pixel to completion, every ray + result recorded
//!      ├─ render (frame.rs)        all pixels, rayon over 16×16 tiles → Frame { Image, RayCounts }
//!      ├─ bench (bench.rs)         ray sets from the jobs, checked vs BVH2, then timed
//!      └─ dualsplit-sim            the same jobs inside simulated threads
//!   Image (image.rs)           linear f32 grey → PNG (sRGB, 8-bit) / EXR (linear f32)
//! ```
//!
//! Every pixel is an independent [`PixelJob`]: it yields its rays one at a time, each next
//! ray depending on the previous result, and all random numbers come from a hash of
//! (pixel, sample, bounce, seed). The simulator runs the same jobs inside simulated threads,
//! so it traces exactly the rays the renderer traced. Every structure returns bit-identical
//! hits, so every structure renders a bit-identical image.
//!
//! ## Ray budget per pixel and sample
//!
//! * *cast* (§4.3): 1 primary ray (closest hit) and, when it hits a surface that faces the
//!   light sample, 1 shadow ray (any hit): **at most 2 rays**, exactly 2 on a lit-side hit.
//! * *path* (§4.4, `bounces = 5`, no Russian roulette): the primary ray plus up to 5 diffuse
//!   bounce rays (closest hit), and at every hit a shadow ray toward the light (next-event
//!   estimation): **at most 6 closest-hit + 6 shadow = 12 rays**. A path ends early only
//!   when a ray leaves the scene; a shadow ray is skipped only when the light sample lies
//!   behind the hit surface (`cos ≤ 0`).
//!
//! The budget for `spp` samples is `spp` times that ([`RenderSettings::max_rays_per_pixel`]).
//! The counters ([`RayCounts`]) report the rays actually traced, by kind, with hits and misses.
//!
//! ## Example
//!
//! ```
//! use dualsplit_accel::{AccelKind, BuildConfig, Structures};
//! use dualsplit_geometry::{Triangle, Vec3};
//! use dualsplit_render::{render, RenderSettings, Workload};
//! use dualsplit_scene::{LoadStats, Scene};
//!
//! let tri = Triangle::new(Vec3::new(-1.0, -1.0, 0.0), Vec3::new(1.0, -1.0, 0.0), Vec3::new(0.0, 1.0, 0.0));
//! let scene = Scene::from_triangles("tri", "tri", vec![tri], LoadStats::default()).unwrap();
//! let structures = Structures::build(&scene.triangles, &BuildConfig::default());
//! let settings = RenderSettings::new(32, 32, Workload::Path);
//! let frame = render(&scene, &structures, AccelKind::Bvh2, &settings, &|| {}).unwrap();
//! assert_eq!(frame.counts.primary.rays, 32 * 32);
//! assert!(frame.counts.rays() <= 32 * 32 * settings.max_rays_per_pixel());
//! ```

pub mod bench;
mod counts;
mod error;
mod frame;
mod image;
mod job;
mod trace;

pub use counts::{KindCounts, RayCounts};
pub use dualsplit_accel::AccelKind;
pub use error::RenderError;
pub use frame::{
    Frame, MAX_BOUNCES, MAX_PIXELS, MAX_SAMPLES, MAX_SIDE, MAX_SPP, TILE, render, render_records,
    supported, tile_count, validate, validate_frame,
};
pub use image::{Image, ImageFormat, srgb_encode};
pub use job::{
    ALBEDO, AMBIENT, FrameConstants, PixelJob, RayKind, RayQuery, RenderSettings, SKY, TraceResult,
    Workload,
};
pub use trace::{
    PixelRecord, TracedRay, run_job, run_job_by, trace_pixel, trace_query, trace_with,
};
