//! [`PixelJob`]: one pixel's deterministic ray stream (Lin et al. 2020, §4.3 and §4.4).
//!
//! A job is a small state machine. [`PixelJob::next_ray`] returns the ray it wants traced,
//! [`PixelJob::submit`] hands in the answer, and the job computes its next ray from it. The
//! renderer drives it with a CPU traversal, the simulator inside a simulated thread; both see
//! the same rays because every random number is a hash of (pixel x, pixel y, sample, bounce,
//! seed, dimension) and nothing else.
//!
//! ## Shading model
//!
//! * Lambertian grey surfaces, albedo [`ALBEDO`], two-sided (the geometric normal is flipped to
//!   face the incoming ray).
//! * One light from the scene ([`dualsplit_scene::Light`]): a point light whose position is
//!   jittered uniformly over a sphere of the light's radius (radius 0 = hard shadows). Its
//!   power is `2 · intensity · d²` with `d` the distance from the light to the scene centre,
//!   so that a surface at the centre facing the light receives an irradiance of
//!   `2 · intensity` whatever the scene's scale (the "exposure" needs no tuning per scene).
//! * Rays that leave the scene see a constant sky of radiance [`SKY`]. The light is not
//!   geometry, so next-event estimation and sky hits never count the same light twice.
//! * *cast* adds a small ambient term ([`AMBIENT`] · albedo) at the primary hit so that shadowed
//!   surfaces are not pure black; *path* needs none (the bounces bring indirect light).
//!
//! ## Self-intersection
//!
//! A hit point is moved off its triangle along the (ray-facing) geometric normal by
//! `2e-5 · max(scene extent, largest |coordinate|)`: the first term covers the scene's scale,
//! the second the absolute rounding error of f32 coordinates far from the origin. Shadow and
//! bounce rays then start at `t_min = 0` from that point; a shadow ray is the segment
//! `[0, 1 − 1e-4]` of the unnormalised vector toward the light sample.

use dualsplit_geometry::{Hit, Ray, Vec3, fmath, hash_u32s};
use dualsplit_scene::Scene;
use serde::{Deserialize, Serialize};

/// The two workloads of the paper.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Workload {
    /// One primary ray per pixel and one shadow ray from its hit (Lin et al. 2020, §4.3).
    Cast,
    /// Path tracing with 5 diffuse bounces and next-event estimation (§4.4).
    Path,
}

impl Workload {
    /// Both workloads, in report order.
    pub const ALL: [Workload; 2] = [Workload::Cast, Workload::Path];

    /// Command-line name.
    pub fn name(self) -> &'static str {
        match self {
            Workload::Cast => "cast",
            Workload::Path => "path",
        }
    }

    /// Parses a command-line name (`cast` or `path`).
    pub fn parse(s: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|w| w.name() == s)
    }
}

/// What to render.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct RenderSettings {
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// Samples per pixel.
    pub spp: u32,
    /// Seed of the per-pixel hash.
    pub seed: u32,
    /// Workload.
    pub workload: Workload,
    /// Diffuse bounces after the primary hit (path workload).
    pub bounces: u32,
    /// A shadow ray toward the light sample at every hit (the default; the paper does not
    /// say whether its path tracer casts them). `false`: the light sample's contribution is
    /// added without a visibility test and no shadow ray is traced.
    #[serde(default = "shadow_rays_by_default")]
    pub shadows: bool,
}

fn shadow_rays_by_default() -> bool {
    true
}

impl RenderSettings {
    /// Defaults: 1 spp, seed 0, 5 bounces (the paper's path tracer, §4.4), a shadow ray at
    /// every hit.
    pub fn new(width: u32, height: u32, workload: Workload) -> Self {
        Self {
            width,
            height,
            spp: 1,
            seed: 0,
            workload,
            bounces: 5,
            shadows: true,
        }
    }

    /// Upper bound on the rays one pixel traces: `spp · 2` for *cast*, `spp · 2 · (bounces + 1)`
    /// for *path* (see the crate docs for the budget).
    pub fn max_rays_per_pixel(&self) -> u64 {
        let per_sample = match self.workload {
            Workload::Cast => 2,
            Workload::Path => 2 * (self.bounces as u64 + 1),
        };
        per_sample * self.spp as u64
    }
}

/// Which kind of ray a query is.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum RayKind {
    /// Camera ray (closest hit).
    Primary,
    /// Ray toward the light (any hit).
    Shadow,
    /// Diffuse bounce ray (closest hit).
    Diffuse,
}

impl RayKind {
    /// All kinds, in report order.
    pub const ALL: [RayKind; 3] = [RayKind::Primary, RayKind::Shadow, RayKind::Diffuse];

    /// Display name.
    pub fn name(self) -> &'static str {
        match self {
            RayKind::Primary => "primary",
            RayKind::Shadow => "shadow",
            RayKind::Diffuse => "diffuse",
        }
    }
}

/// A ray the job wants traced.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RayQuery {
    /// The ray.
    pub ray: Ray,
    /// Its kind; shadow rays want [`TraceResult::Occluded`], the others [`TraceResult::Closest`].
    pub kind: RayKind,
}

/// The answer to a [`RayQuery`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum TraceResult {
    /// Closest hit (primary and diffuse rays).
    Closest(Option<Hit>),
    /// Whether anything blocks the segment (shadow rays).
    Occluded(bool),
}

impl TraceResult {
    /// True for a closest hit that found a triangle or an occluded shadow ray.
    pub fn is_hit(&self) -> bool {
        match self {
            TraceResult::Closest(h) => h.is_some(),
            TraceResult::Occluded(o) => *o,
        }
    }

    /// Bitwise equality: `t`, `u`, `v` compared by their bits, so `-0.0 ≠ 0.0` and NaN equals
    /// itself. This is the equality the cross-structure checks use.
    pub fn bit_eq(&self, other: &TraceResult) -> bool {
        match (self, other) {
            (TraceResult::Closest(None), TraceResult::Closest(None)) => true,
            (TraceResult::Closest(Some(a)), TraceResult::Closest(Some(b))) => {
                a.prim == b.prim
                    && a.t.to_bits() == b.t.to_bits()
                    && a.u.to_bits() == b.u.to_bits()
                    && a.v.to_bits() == b.v.to_bits()
            }
            (TraceResult::Occluded(a), TraceResult::Occluded(b)) => a == b,
            _ => false,
        }
    }
}

/// Surface albedo (grey Lambertian).
pub const ALBEDO: f32 = 0.7;
/// Radiance of the constant sky seen by rays that leave the scene.
pub const SKY: f32 = 0.25;
/// Ambient term of the *cast* workload (multiplied by the albedo).
pub const AMBIENT: f32 = 0.04;

#[derive(Clone, Copy, Debug)]
enum Pending {
    /// Waiting for a closest-hit result at path depth `depth`.
    Closest { depth: u32 },
    /// Waiting for a shadow answer carrying `contrib` if unoccluded, then continue at `depth`.
    Shadow {
        depth: u32,
        contrib: f32,
        hit_p: Vec3,
        n: Vec3,
    },
}

/// The per-frame constants every [`PixelJob`] of a scene derives from it: the camera basis,
/// the self-intersection offset and the light's power. The simulated threads' kernels get
/// exactly these values in their parameter block (`kernels/dualsplit.h`), so they need no
/// `tan` and compute the same rays.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FrameConstants {
    /// Camera eye.
    pub eye: Vec3,
    /// `(target − eye).normalize()`.
    pub fwd: Vec3,
    /// `fwd × up`, normalised.
    pub right: Vec3,
    /// `right × fwd`.
    pub up: Vec3,
    /// `tan(fov_y / 2)`.
    pub tan_half_fov: f32,
    /// Self-intersection offset along the normal (see the module docs).
    pub eps: f32,
    /// The light's power `2 · intensity · d²` (see the module docs).
    pub light_power: f32,
}

impl FrameConstants {
    /// The constants of `scene`.
    pub fn new(scene: &Scene) -> Self {
        let b = &scene.bounds;
        let ext = b.extent().max_element();
        let mag = b.min.abs().max(b.max.abs()).max_element();
        let eps = (ext.max(mag) * 2e-5).max(1e-9);
        // Distance² from the light to the scene centre, floored at (1 % of the extent)² so a
        // light placed at the centre still lights the scene.
        let dc = (scene.light.position - b.center())
            .length_squared()
            .max((ext * 0.01).powi(2))
            .max(1e-12);
        let c = &scene.camera;
        let fwd = (c.target - c.eye).normalize();
        let right = fwd.cross(c.up).normalize();
        let up = right.cross(fwd);
        Self {
            eye: c.eye,
            fwd,
            right,
            up,
            tan_half_fov: (c.fov_y_deg.to_radians() * 0.5).tan(),
            eps,
            light_power: scene.light.intensity * dc * 2.0,
        }
    }
}

/// The pinhole camera's basis, computed once per job.
#[derive(Clone, Copy, Debug)]
struct CameraBasis {
    eye: Vec3,
    fwd: Vec3,
    right: Vec3,
    up: Vec3,
    /// `tan(fov_y / 2)`.
    k: f32,
}

/// One pixel's work: yields rays one at a time; each next ray depends on the previous
/// result. Deterministic from (pixel, sample, bounce, seed).
///
/// ```
/// # use dualsplit_geometry::{Triangle, Vec3};
/// # use dualsplit_scene::{Scene, LoadStats};
/// use dualsplit_render::{PixelJob, RenderSettings, TraceResult, Workload};
/// # let tri = Triangle::new(Vec3::new(-1.0, -1.0, 0.0), Vec3::new(1.0, -1.0, 0.0), Vec3::new(0.0, 1.0, 0.0));
/// # let scene = Scene::from_triangles("t", "t", vec![tri], LoadStats::default()).unwrap();
/// let settings = RenderSettings::new(4, 4, Workload::Cast);
/// let mut job = PixelJob::new(&scene, &settings, 1, 2);
/// let mut rays = 0;
/// while let Some(q) = job.next_ray() {
///     rays += 1;
///     // A real caller traces `q.ray`; here every ray misses.
///     job.submit(match q.kind {
///         dualsplit_render::RayKind::Shadow => TraceResult::Occluded(false),
///         _ => TraceResult::Closest(None),
///     });
/// }
/// assert_eq!(rays, 1); // the primary ray missed: no shadow ray
/// assert_eq!(job.radiance(), dualsplit_render::SKY);
/// ```
#[derive(Clone, Debug)]
pub struct PixelJob<'a> {
    scene: &'a Scene,
    settings: RenderSettings,
    x: u32,
    y: u32,
    sample: u32,
    throughput: f32,
    radiance: f32,
    next: Option<RayQuery>,
    pending: Option<Pending>,
    eps: f32,
    light_power: f32,
    cam: CameraBasis,
}

impl<'a> PixelJob<'a> {
    /// The job of pixel `(x, y)` (origin top-left).
    pub fn new(scene: &'a Scene, settings: &RenderSettings, x: u32, y: u32) -> Self {
        let fc = FrameConstants::new(scene);
        let mut job = Self {
            scene,
            settings: *settings,
            x,
            y,
            sample: 0,
            throughput: 1.0,
            radiance: 0.0,
            next: None,
            pending: None,
            eps: fc.eps,
            light_power: fc.light_power,
            cam: CameraBasis {
                eye: fc.eye,
                fwd: fc.fwd,
                right: fc.right,
                up: fc.up,
                k: fc.tan_half_fov,
            },
        };
        job.start_sample();
        job
    }

    /// The random number of dimension `dim` at `bounce` of the current sample, in `[0, 1)`.
    /// Bounce 0 is the camera (pixel jitter), `2d + 1` the light sample at depth `d`, `2d + 2`
    /// the diffuse bounce leaving depth `d`.
    fn rand(&self, bounce: u32, dim: u32) -> f32 {
        let h = hash_u32s(&[self.x, self.y, self.sample, bounce, self.settings.seed, dim]);
        (h >> 8) as f32 * (1.0 / 16_777_216.0)
    }

    fn start_sample(&mut self) {
        if self.sample >= self.settings.spp {
            self.next = None;
            self.pending = None;
            return;
        }
        let (w, h) = (self.settings.width as f32, self.settings.height as f32);
        let (jx, jy) = if self.settings.spp > 1 {
            (self.rand(0, 0), self.rand(0, 1))
        } else {
            (0.5, 0.5)
        };
        let cam = self.cam;
        let sx = (2.0 * (self.x as f32 + jx) / w - 1.0) * (w / h);
        let sy = 1.0 - 2.0 * (self.y as f32 + jy) / h;
        let dir = (cam.fwd + cam.right * (sx * cam.k) + cam.up * (sy * cam.k)).normalize();
        self.throughput = 1.0;
        self.next = Some(RayQuery {
            ray: Ray::new(cam.eye, dir),
            kind: RayKind::Primary,
        });
        self.pending = Some(Pending::Closest { depth: 0 });
    }

    /// The next ray to trace, or `None` when the pixel is finished.
    pub fn next_ray(&mut self) -> Option<RayQuery> {
        self.next
    }

    /// Hands in the result of the ray last returned by [`PixelJob::next_ray`]. Does nothing
    /// once the job is finished.
    ///
    /// # Panics
    ///
    /// When the result's kind does not match the ray's ([`TraceResult::Occluded`] for a shadow
    /// ray, [`TraceResult::Closest`] otherwise): that is a bug in the caller.
    pub fn submit(&mut self, result: TraceResult) {
        let Some(pending) = self.pending.take() else {
            return;
        };
        let Some(query) = self.next.take() else {
            return;
        };
        match (pending, result) {
            (Pending::Closest { depth }, TraceResult::Closest(hit)) => match hit {
                None => {
                    self.radiance += self.throughput * SKY;
                    self.finish_sample();
                }
                Some(hit) => self.on_hit(&query.ray, &hit, depth),
            },
            (
                Pending::Shadow {
                    depth,
                    contrib,
                    hit_p,
                    n,
                },
                TraceResult::Occluded(occ),
            ) => {
                if !occ {
                    self.radiance += contrib;
                }
                self.continue_path(depth, hit_p, n);
            }
            (_, result) => panic!(
                "PixelJob::submit: result {result:?} does not match the {:?} ray it answers",
                query.kind
            ),
        }
    }

    fn on_hit(&mut self, ray: &Ray, hit: &Hit, depth: u32) {
        let tri = &self.scene.triangles[hit.prim.index()];
        let mut n = tri.normal().normalize_or_zero();
        if n == Vec3::ZERO {
            // A sliver whose normal underflows: shade it as if it faced the ray.
            n = -ray.dir.normalize_or_zero();
        }
        if n.dot(ray.dir) > 0.0 {
            n = -n;
        }
        let p = ray.at(hit.t) + n * self.eps;
        if self.settings.workload == Workload::Cast {
            self.radiance += self.throughput * AMBIENT * ALBEDO;
        }
        // Next-event estimation toward a point sampled uniformly on the light sphere.
        let light = &self.scene.light;
        let (u1, u2) = (self.rand(2 * depth + 1, 0), self.rand(2 * depth + 1, 1));
        let z = 1.0 - 2.0 * u1;
        let r = (1.0 - z * z).max(0.0).sqrt();
        let phi = std::f32::consts::TAU * u2;
        let (sin_phi, cos_phi) = fmath::sin_cos(phi);
        let lp = light.position + Vec3::new(r * cos_phi, r * sin_phi, z) * light.radius;
        let to_l = lp - p;
        let d2 = to_l.length_squared();
        let cos = if d2 > 0.0 {
            n.dot(to_l) / d2.sqrt()
        } else {
            0.0
        };
        if cos > 0.0 && !self.settings.shadows {
            // No shadow rays: the light sample counts as visible.
            self.radiance +=
                self.throughput * ALBEDO / std::f32::consts::PI * self.light_power * cos / d2;
            self.continue_path(depth, p, n);
        } else if cos > 0.0 {
            let contrib =
                self.throughput * ALBEDO / std::f32::consts::PI * self.light_power * cos / d2;
            self.next = Some(RayQuery {
                ray: Ray::segment(p, to_l, 0.0, 1.0 - 1e-4),
                kind: RayKind::Shadow,
            });
            self.pending = Some(Pending::Shadow {
                depth,
                contrib,
                hit_p: p,
                n,
            });
        } else {
            self.continue_path(depth, p, n);
        }
    }

    fn continue_path(&mut self, depth: u32, p: Vec3, n: Vec3) {
        if self.settings.workload == Workload::Cast || depth >= self.settings.bounces {
            self.finish_sample();
            return;
        }
        // Cosine-weighted diffuse bounce; the pdf cancels cos/π, leaving the albedo.
        let (u1, u2) = (self.rand(2 * depth + 2, 0), self.rand(2 * depth + 2, 1));
        let r = u1.sqrt();
        let phi = std::f32::consts::TAU * u2;
        let (t, b) = n.any_orthonormal_pair();
        let (sin_phi, cos_phi) = fmath::sin_cos(phi);
        let dir = t * (r * cos_phi) + b * (r * sin_phi) + n * (1.0 - u1).max(0.0).sqrt();
        self.throughput *= ALBEDO;
        self.next = Some(RayQuery {
            ray: Ray::new(p, dir),
            kind: RayKind::Diffuse,
        });
        self.pending = Some(Pending::Closest { depth: depth + 1 });
    }

    fn finish_sample(&mut self) {
        self.sample += 1;
        self.start_sample();
    }

    /// Accumulated radiance divided by the samples taken so far (grey, linear).
    pub fn radiance(&self) -> f32 {
        self.radiance / self.sample.max(1) as f32
    }

    /// Pixel coordinates.
    pub fn pixel(&self) -> (u32, u32) {
        (self.x, self.y)
    }

    /// True when every sample is finished.
    pub fn is_done(&self) -> bool {
        self.next.is_none()
    }
}
