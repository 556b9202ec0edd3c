//! Reference renderer: the paper's two workloads (§4.3 ray casting with a shadow ray, §4.4
//! path tracing with 5 diffuse bounces), generic over the acceleration structure.
//!
//! Every pixel is an independent [`PixelJob`]: it yields its rays one at a time, each next
//! ray depending on the previous result, and all random numbers come from a hash of
//! (pixel, sample, bounce, seed). The simulator runs the same jobs inside simulated threads,
//! so it traces exactly the rays the renderer traced.
//!
//! Ray budget per pixel and sample: *cast* traces 1 primary ray and, when it hits, 1 shadow
//! ray (≤ 2 rays). *path* traces 1 primary ray and up to 5 diffuse bounce rays (a path ends
//! early only when a ray leaves the scene), and a shadow ray toward the light at every hit
//! (≤ 6 closest-hit + 6 shadow = 12 rays). No Russian roulette.

mod job;

pub use job::{PixelJob, RayKind, RayQuery, RenderSettings, TraceResult, Workload};
