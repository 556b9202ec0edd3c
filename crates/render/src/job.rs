use dualsplit_geometry::{Hit, Ray, Vec3, hash_u32s};
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
    /// Command-line name.
    pub fn name(self) -> &'static str {
        match self {
            Workload::Cast => "cast",
            Workload::Path => "path",
        }
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
}

impl RenderSettings {
    /// Defaults: 1 spp, seed 0, 5 bounces.
    pub fn new(width: u32, height: u32, workload: Workload) -> Self {
        Self {
            width,
            height,
            spp: 1,
            seed: 0,
            workload,
            bounces: 5,
        }
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

const ALBEDO: f32 = 0.7;
const SKY: f32 = 0.25;
const AMBIENT: f32 = 0.04;

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

/// One pixel's work: yields rays one at a time; each next ray depends on the previous
/// result. Deterministic from (pixel, sample, bounce, seed).
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
}

impl<'a> PixelJob<'a> {
    /// The job of pixel `(x, y)` (origin top-left).
    pub fn new(scene: &'a Scene, settings: &RenderSettings, x: u32, y: u32) -> Self {
        let ext = scene.bounds.extent().max_element().max(1e-6);
        let dc = (scene.light.position - scene.bounds.center())
            .length_squared()
            .max(1e-12);
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
            eps: ext * 2e-5,
            light_power: scene.light.intensity * dc * 2.0,
        };
        job.start_sample();
        job
    }

    fn rand(&self, bounce: u32, dim: u32) -> f32 {
        let px = self.y * self.settings.width + self.x;
        let h = hash_u32s(&[px, self.sample, bounce, self.settings.seed, dim]);
        (h >> 8) as f32 * (1.0 / 16_777_216.0)
    }

    fn start_sample(&mut self) {
        if self.sample >= self.settings.spp {
            self.next = None;
            return;
        }
        let cam = &self.scene.camera;
        let (w, h) = (self.settings.width as f32, self.settings.height as f32);
        let (jx, jy) = if self.settings.spp > 1 {
            (self.rand(0, 0), self.rand(0, 1))
        } else {
            (0.5, 0.5)
        };
        let sx = (2.0 * (self.x as f32 + jx) / w - 1.0) * (w / h);
        let sy = 1.0 - 2.0 * (self.y as f32 + jy) / h;
        let fwd = (cam.target - cam.eye).normalize();
        let right = fwd.cross(cam.up).normalize();
        let up = right.cross(fwd);
        let k = (cam.fov_y_deg.to_radians() * 0.5).tan();
        let dir = (fwd + right * (sx * k) + up * (sy * k)).normalize();
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

    /// Hands in the result of the ray last returned by [`PixelJob::next_ray`].
    pub fn submit(&mut self, result: TraceResult) {
        let Some(pending) = self.pending.take() else {
            return;
        };
        let query = self.next.take().expect("submit without a ray");
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
            _ => panic!("result kind does not match the ray kind"),
        }
    }

    fn on_hit(&mut self, ray: &Ray, hit: &Hit, depth: u32) {
        let tri = &self.scene.triangles[hit.prim as usize];
        let mut n = tri.normal().normalize_or_zero();
        if n.dot(ray.dir) > 0.0 {
            n = -n;
        }
        let p = ray.at(hit.t) + n * self.eps;
        if self.settings.workload == Workload::Cast {
            self.radiance += self.throughput * AMBIENT * ALBEDO;
        }
        // Next-event estimation toward a point sampled on the light sphere.
        let light = &self.scene.light;
        let (u1, u2) = (self.rand(2 * depth + 1, 0), self.rand(2 * depth + 1, 1));
        let z = 1.0 - 2.0 * u1;
        let r = (1.0 - z * z).max(0.0).sqrt();
        let phi = std::f32::consts::TAU * u2;
        let lp = light.position + Vec3::new(r * phi.cos(), r * phi.sin(), z) * light.radius;
        let to_l = lp - p;
        let d2 = to_l.length_squared();
        let cos = n.dot(to_l) / d2.sqrt();
        if cos > 0.0 && d2 > 0.0 {
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
        let dir = t * (r * phi.cos()) + b * (r * phi.sin()) + n * (1.0 - u1).max(0.0).sqrt();
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
}
