//! [`render`]: a whole frame, parallel over square tiles on every core (rayon).
//!
//! Pixels are independent [`PixelJob`]s, so the tile order, the thread count and the work
//! stealing change nothing: the image and the counters are the same bits on any machine
//! with the same float semantics.

use crate::trace::{run_job_by, trace_with};
use crate::{Image, PixelJob, PixelRecord, RayCounts, RenderError, RenderSettings, trace_pixel};
use dualsplit_accel::{AccelKind, NoObserver, TraversalSet};
use dualsplit_scene::Scene;
use rayon::prelude::*;

/// Tile edge in pixels.
pub const TILE: u32 = 16;

/// A rendered frame: the linear image and the ray counters.
#[derive(Clone, Debug, PartialEq)]
pub struct Frame {
    /// Linear radiance per pixel.
    pub image: Image,
    /// Rays by kind, hits and misses, over the whole frame.
    pub counts: RayCounts,
}

/// Number of tiles [`render`] splits a frame into (the progress callback is called once per
/// tile).
pub fn tile_count(settings: &RenderSettings) -> u64 {
    settings.width.div_ceil(TILE) as u64 * settings.height.div_ceil(TILE) as u64
}

/// Most pixels per side of a frame.
pub const MAX_SIDE: u32 = 1 << 16;

/// Most pixels in a frame: 2^28 (16384 × 16384). [`render`] holds about 9 bytes per pixel
/// at once (the tiles' values, the image, its 8-bit encoding), so a frame at the limit needs
/// about 2.4 GB.
pub const MAX_PIXELS: u64 = 1 << 28;

/// Most samples per pixel.
pub const MAX_SPP: u32 = 1 << 16;

/// Most samples in a frame (pixels × samples per pixel): 2^36, a 1024 × 1024 frame at
/// [`MAX_SPP`]. Beyond it a frame takes days; the bound also keeps every per-frame counter
/// far from overflowing.
pub const MAX_SAMPLES: u64 = 1 << 36;

/// Most diffuse bounces of the path workload.
pub const MAX_BOUNCES: u32 = 1 << 10;

/// Checks the settings, the scene's camera and its light; every renderer entry point calls
/// it. The limits are [`MAX_SIDE`], [`MAX_PIXELS`], [`MAX_SPP`], [`MAX_SAMPLES`] and
/// [`MAX_BOUNCES`]; an error says which one and its value.
pub fn validate(scene: &Scene, settings: &RenderSettings) -> Result<(), RenderError> {
    validate_frame(settings)?;
    let c = &scene.camera;
    let cam_err = |reason| RenderError::Camera {
        eye: c.eye.to_array(),
        target: c.target.to_array(),
        up: c.up.to_array(),
        fov_y_deg: c.fov_y_deg,
        reason,
    };
    if !(c.eye.is_finite() && c.target.is_finite() && c.up.is_finite() && c.fov_y_deg.is_finite()) {
        return Err(cam_err("non-finite value"));
    }
    let far = |p: glam::Vec3| p.abs().max_element() > dualsplit_scene::MAX_VIEW_COORDINATE;
    if far(c.eye) || far(c.target) {
        return Err(cam_err(
            "a coordinate of the eye or target lies beyond ±2^62 (MAX_VIEW_COORDINATE)",
        ));
    }
    if !(c.fov_y_deg > 0.0 && c.fov_y_deg < 180.0) {
        return Err(cam_err(
            "the field of view must lie strictly between 0° and 180°",
        ));
    }
    let fwd = (c.target - c.eye).normalize_or_zero();
    if fwd == glam::Vec3::ZERO {
        return Err(cam_err("eye and target coincide"));
    }
    if fwd.cross(c.up).normalize_or_zero() == glam::Vec3::ZERO {
        return Err(cam_err("the view direction is parallel to the up vector"));
    }
    let l = &scene.light;
    let light_err = |reason| RenderError::Light {
        reason,
        position: l.position.to_array(),
        radius: l.radius,
        intensity: l.intensity,
    };
    if !(l.position.is_finite()
        && l.radius.is_finite()
        && l.radius >= 0.0
        && l.intensity.is_finite()
        && l.intensity >= 0.0)
    {
        return Err(light_err(
            "non-finite value, negative radius or negative intensity",
        ));
    }
    // Within ±2^62 and a radius of 2^60 the distance² to any point of the scene (within
    // ±2^60) stays finite, so every shadow ray and its 1/d² are computed.
    if far(l.position) || l.radius > Scene::MAX_COORDINATE {
        return Err(light_err(
            "the position lies beyond ±2^62 (MAX_VIEW_COORDINATE) or the radius exceeds 2^60",
        ));
    }
    if !crate::FrameConstants::new(scene).light_power.is_finite() {
        return Err(light_err(
            "its power 2 · intensity · d² (d: its distance to the scene centre) overflows f32: lower the intensity",
        ));
    }
    Ok(())
}

/// The scene-independent part of [`validate`]: frame size, samples and bounces, so a caller
/// can refuse a frame before it loads the scene.
pub fn validate_frame(settings: &RenderSettings) -> Result<(), RenderError> {
    let bad = |reason: String| RenderError::Settings {
        width: settings.width,
        height: settings.height,
        spp: settings.spp,
        reason,
    };
    if settings.width == 0 || settings.height == 0 {
        return Err(bad("the image has no pixel".into()));
    }
    if settings.spp == 0 {
        return Err(bad("at least one sample per pixel is needed".into()));
    }
    if settings.width > MAX_SIDE || settings.height > MAX_SIDE {
        return Err(bad(format!("at most {MAX_SIDE} pixels per side")));
    }
    let pixels = u64::from(settings.width) * u64::from(settings.height);
    if pixels > MAX_PIXELS {
        return Err(bad(format!(
            "{pixels} pixels; at most {MAX_PIXELS} (16384x16384) in a frame, \
             whose buffers take about 2.4 GB"
        )));
    }
    if settings.spp > MAX_SPP {
        return Err(bad(format!("at most {MAX_SPP} samples per pixel")));
    }
    if pixels * u64::from(settings.spp) > MAX_SAMPLES {
        return Err(bad(format!(
            "{} samples; at most {MAX_SAMPLES} (pixels x samples per pixel) in a frame",
            pixels * u64::from(settings.spp)
        )));
    }
    if settings.bounces > MAX_BOUNCES {
        return Err(bad(format!(
            "{} bounces; at most {MAX_BOUNCES}",
            settings.bounces
        )));
    }
    Ok(())
}

/// The pixel rectangles of the tiles, row-major.
fn tiles(settings: &RenderSettings) -> Vec<(u32, u32, u32, u32)> {
    let mut v = Vec::with_capacity(tile_count(settings) as usize);
    for ty in (0..settings.height).step_by(TILE as usize) {
        for tx in (0..settings.width).step_by(TILE as usize) {
            v.push((
                tx,
                ty,
                (tx + TILE).min(settings.width),
                (ty + TILE).min(settings.height),
            ));
        }
    }
    v
}

/// Renders a frame of `scene` with `settings.workload` on structure `kind`, in parallel over
/// [`TILE`]×[`TILE`] tiles; `progress` is called once per finished tile (from any thread).
///
/// Every [`AccelKind`] returns a bit-identical [`Frame`]: the structures return bit-identical
/// hits (the geometry crate's robustness rules), and the jobs depend on nothing else.
/// `structures` is every structure of the scene or one tree ([`TraversalSet`]); a `kind` it
/// lacks is a [`RenderError::Unsupported`].
pub fn render<S: TraversalSet>(
    scene: &Scene,
    structures: &S,
    kind: AccelKind,
    settings: &RenderSettings,
    progress: &(dyn Fn() + Sync),
) -> Result<Frame, RenderError> {
    validate(scene, settings)?;
    supported(structures, kind)?;
    let done: Vec<(Vec<f32>, RayCounts)> = tiles(settings)
        .into_par_iter()
        .map(|(x0, y0, x1, y1)| {
            let mut counts = RayCounts::default();
            let mut px = Vec::with_capacity(((x1 - x0) * (y1 - y0)) as usize);
            let mut tracer = structures.tracer(kind);
            for y in y0..y1 {
                for x in x0..x1 {
                    let job = PixelJob::new(scene, settings, x, y);
                    px.push(run_job_by(
                        job,
                        |q| trace_with(&mut tracer, q),
                        &mut counts,
                        |_, _| {},
                    ));
                }
            }
            progress();
            (px, counts)
        })
        .collect();
    let mut image = Image::new(settings.width, settings.height);
    let mut counts = RayCounts::default();
    for ((x0, y0, x1, _), (px, c)) in tiles(settings).into_iter().zip(done) {
        let w = (x1 - x0) as usize;
        for (row, vals) in px.chunks(w).enumerate() {
            let start = (y0 as usize + row) * settings.width as usize + x0 as usize;
            image.pixels[start..start + w].copy_from_slice(vals);
        }
        counts.add(&c);
    }
    Ok(Frame { image, counts })
}

/// Traces every pixel of the frame with [`trace_pixel`] (in parallel over rows) and returns
/// the records in row-major order. Memory grows with the ray count: meant for tests, the
/// simulator's reference streams and small frames.
pub fn render_records<S: TraversalSet>(
    scene: &Scene,
    structures: &S,
    kind: AccelKind,
    settings: &RenderSettings,
) -> Result<Vec<PixelRecord>, RenderError> {
    validate(scene, settings)?;
    supported(structures, kind)?;
    Ok((0..settings.height)
        .into_par_iter()
        .flat_map_iter(|y| {
            (0..settings.width)
                .map(move |x| trace_pixel(structures, kind, scene, settings, x, y, &mut NoObserver))
        })
        .collect())
}

/// Ok when `structures` has traversal `kind`, else [`RenderError::Unsupported`].
pub fn supported<S: TraversalSet>(structures: &S, kind: AccelKind) -> Result<(), RenderError> {
    if structures.supports(kind) {
        Ok(())
    } else {
        Err(RenderError::Unsupported {
            accel: kind.name(),
            available: structures.kind_names(),
        })
    }
}
