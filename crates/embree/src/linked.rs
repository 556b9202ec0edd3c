//! The scene on the linked `libembree3`: every call into the C library, each `unsafe` block
//! with the reason it is sound.

use crate::ffi::{self, RTCDevice, RTCScene};
use crate::{EmbreeError, EmbreeOptions, ErrorCode};
use dualsplit_geometry::{Hit, PrimId, Ray, Triangle};
use std::ffi::CString;

/// Oldest library the declarations in `ffi.rs` were checked against (3.13.0).
const MIN_VERSION: isize = 31300;

/// A committed Embree scene and the device that owns it.
pub(crate) struct Scene {
    device: RTCDevice,
    scene: RTCScene,
    triangles: usize,
    version: isize,
}

// SAFETY: Embree's device and committed scene are reference-counted C objects with no
// thread affinity; the API documents `rtcIntersect1`/`rtcOccluded1` on a committed scene as
// safe to call from any number of threads at once, and nothing mutates the scene after
// `rtcCommitScene` (the wrapper has no `&mut` method). Release happens once, in `Drop`.
unsafe impl Send for Scene {}
// SAFETY: as for `Send`: shared references only issue concurrent read-only queries.
unsafe impl Sync for Scene {}

/// Owns a device until a scene takes it over (or for the life of a tree build), so every
/// early return releases it.
pub(crate) struct DeviceGuard(pub(crate) RTCDevice);

/// The device configuration of a scene built with `options` (Embree's `key=value` pairs).
fn device_config(options: &EmbreeOptions) -> String {
    let mut config = "verbose=0".to_string();
    if let Some(n) = options.build_threads {
        config += &format!(",threads={n}");
    }
    if options.avx2_at_most {
        config += ",max_isa=avx2";
    }
    config
}

/// A new device with configuration `config` (`key=value` pairs, no NUL).
pub(crate) fn new_device(config: &str) -> Result<DeviceGuard, EmbreeError> {
    let config = CString::new(config).expect("the configuration string has no NUL");
    // SAFETY: `config` is a NUL-terminated string that outlives the call.
    let device = unsafe { ffi::rtcNewDevice(config.as_ptr()) };
    if device.is_null() {
        return Err(call_error(device, "rtcNewDevice"));
    }
    Ok(DeviceGuard(device))
}

impl Drop for DeviceGuard {
    fn drop(&mut self) {
        // SAFETY: `self.0` is a device from `rtcNewDevice`, not yet released; this drop holds
        // the only reference the wrapper took.
        unsafe { ffi::rtcReleaseDevice(self.0) }
    }
}

/// The device's last error as an [`EmbreeError`], or `Ok` when there is none.
fn check(device: RTCDevice, call: &'static str) -> Result<(), EmbreeError> {
    // SAFETY: `device` is a live device (or null, which Embree accepts and answers with the
    // thread's error from `rtcNewDevice`).
    let code = unsafe { ffi::rtcGetDeviceError(device) };
    if code == 0 {
        Ok(())
    } else {
        Err(EmbreeError::Call {
            call,
            code: ErrorCode::from_raw(code),
        })
    }
}

pub(crate) fn call_error(device: RTCDevice, call: &'static str) -> EmbreeError {
    // SAFETY: as in `check`.
    let code = unsafe { ffi::rtcGetDeviceError(device) };
    EmbreeError::Call {
        call,
        code: ErrorCode::from_raw(code),
    }
}

impl Scene {
    pub(crate) fn new(
        triangles: &[Triangle],
        options: &EmbreeOptions,
    ) -> Result<Self, EmbreeError> {
        let vertices = triangles
            .len()
            .checked_mul(3)
            .filter(|&n| n <= u32::MAX as usize)
            .ok_or(EmbreeError::TooLarge {
                triangles: triangles.len(),
            })?;
        let device = new_device(&device_config(options))?;
        let d = device.0;

        // SAFETY: `d` is a live device; property queries have no other precondition.
        let version = unsafe { ffi::rtcGetDeviceProperty(d, ffi::RTC_DEVICE_PROPERTY_VERSION) };
        if !(MIN_VERSION..40000).contains(&version) {
            return Err(EmbreeError::Unsupported(format!(
                "version {} (the bindings are for 3.13 and later 3.x)",
                version_string(version)
            )));
        }
        // SAFETY: as above.
        let culling = unsafe {
            ffi::rtcGetDeviceProperty(d, ffi::RTC_DEVICE_PROPERTY_BACKFACE_CULLING_ENABLED)
        };
        if culling != 0 {
            return Err(EmbreeError::Unsupported(
                "built with back-face culling; dualsplit's triangles are two-sided".into(),
            ));
        }

        // SAFETY: `d` is a live device.
        let geometry = unsafe { ffi::rtcNewGeometry(d, ffi::RTC_GEOMETRY_TYPE_TRIANGLE) };
        if geometry.is_null() {
            return Err(call_error(d, "rtcNewGeometry"));
        }
        let filled = fill_buffers(geometry, triangles, vertices);
        let committed = filled.and_then(|()| {
            if options.high_quality {
                // SAFETY: `geometry` is live and not yet committed.
                unsafe { ffi::rtcSetGeometryBuildQuality(geometry, ffi::RTC_BUILD_QUALITY_HIGH) };
            }
            // SAFETY: `geometry` is live and its buffers are written, the order Embree asks for.
            unsafe { ffi::rtcCommitGeometry(geometry) };
            check(d, "rtcCommitGeometry")
        });
        let scene = match committed {
            // SAFETY: `d` is a live device.
            Ok(()) => unsafe { ffi::rtcNewScene(d) },
            Err(e) => {
                // SAFETY: `geometry` is live and attached nowhere; this drops our reference.
                unsafe { ffi::rtcReleaseGeometry(geometry) };
                return Err(e);
            }
        };
        if scene.is_null() {
            // SAFETY: as above.
            unsafe { ffi::rtcReleaseGeometry(geometry) };
            return Err(call_error(d, "rtcNewScene"));
        }
        let mut flags = 0;
        if options.robust {
            flags |= ffi::RTC_SCENE_FLAG_ROBUST;
        }
        // SAFETY: `scene` and `geometry` are live. Attaching takes the scene's own reference
        // to the geometry, so ours is released right after; the scene keeps it alive.
        unsafe {
            ffi::rtcSetSceneFlags(scene, flags);
            if options.high_quality {
                ffi::rtcSetSceneBuildQuality(scene, ffi::RTC_BUILD_QUALITY_HIGH);
            }
            ffi::rtcAttachGeometry(scene, geometry);
            ffi::rtcReleaseGeometry(geometry);
            ffi::rtcCommitScene(scene);
        }
        if let Err(e) = check(d, "rtcCommitScene") {
            // SAFETY: `scene` is live and ours.
            unsafe { ffi::rtcReleaseScene(scene) };
            return Err(e);
        }
        let device = std::mem::ManuallyDrop::new(device);
        Ok(Self {
            device: device.0,
            scene,
            triangles: triangles.len(),
            version,
        })
    }

    #[inline]
    pub(crate) fn intersect(&self, ray: &Ray) -> Option<Hit> {
        let mut rh = ffi::RTCRayHit {
            ray: rtc_ray(ray),
            hit: ffi::RTCHit {
                geom_id: ffi::RTC_INVALID_GEOMETRY_ID,
                prim_id: ffi::RTC_INVALID_GEOMETRY_ID,
                inst_id: [ffi::RTC_INVALID_GEOMETRY_ID],
                ..Default::default()
            },
        };
        let mut ctx = ffi::RTCIntersectContext::new();
        // SAFETY: `self.scene` is committed and alive for `&self`; `ctx` and `rh` are
        // initialised, correctly laid out (asserted sizes, 16-byte alignment) and exclusively
        // borrowed for the call, which only writes into them.
        unsafe { ffi::rtcIntersect1(self.scene, &mut ctx, &mut rh) };
        (rh.hit.geom_id != ffi::RTC_INVALID_GEOMETRY_ID).then_some(Hit {
            t: rh.ray.tfar,
            prim: PrimId(rh.hit.prim_id),
            u: rh.hit.u,
            v: rh.hit.v,
        })
    }

    #[inline]
    pub(crate) fn occluded(&self, ray: &Ray) -> bool {
        let mut r = rtc_ray(ray);
        let mut ctx = ffi::RTCIntersectContext::new();
        // SAFETY: as in `intersect`.
        unsafe { ffi::rtcOccluded1(self.scene, &mut ctx, &mut r) };
        r.tfar == f32::NEG_INFINITY
    }

    pub(crate) fn version(&self) -> String {
        version_string(self.version)
    }

    pub(crate) fn triangles(&self) -> usize {
        self.triangles
    }
}

impl Drop for Scene {
    fn drop(&mut self) {
        // SAFETY: both handles are live and held once by this value; the scene goes first, as
        // it refers to the device.
        unsafe {
            ffi::rtcReleaseScene(self.scene);
            ffi::rtcReleaseDevice(self.device);
        }
    }
}

/// Writes the vertex buffer (three vertices per triangle, in order) and the index buffer
/// (`3i, 3i+1, 3i+2`) of a fresh triangle geometry.
fn fill_buffers(
    geometry: ffi::RTCGeometry,
    triangles: &[Triangle],
    vertices: usize,
) -> Result<(), EmbreeError> {
    // SAFETY: `geometry` is a live triangle geometry; Embree allocates `vertices` items of 12
    // bytes (plus the padding it needs) and returns the buffer or null.
    let vb = unsafe {
        ffi::rtcSetNewGeometryBuffer(
            geometry,
            ffi::RTC_BUFFER_TYPE_VERTEX,
            0,
            ffi::RTC_FORMAT_FLOAT3,
            12,
            vertices,
        )
    };
    // SAFETY: as above, `triangles.len()` items of three u32.
    let ib = unsafe {
        ffi::rtcSetNewGeometryBuffer(
            geometry,
            ffi::RTC_BUFFER_TYPE_INDEX,
            0,
            ffi::RTC_FORMAT_UINT3,
            12,
            triangles.len(),
        )
    };
    if vb.is_null() || ib.is_null() {
        return Err(EmbreeError::Call {
            call: "rtcSetNewGeometryBuffer",
            code: ErrorCode::OutOfMemory,
        });
    }
    // SAFETY: `vb` points to at least `3 · vertices` f32 (12-byte items), aligned to 16 bytes
    // by Embree's allocator, owned by the geometry and not touched by Embree until commit;
    // nothing else aliases it while this slice lives.
    let vs = unsafe { std::slice::from_raw_parts_mut(vb.cast::<f32>(), 3 * vertices) };
    for (dst, tri) in vs.chunks_exact_mut(9).zip(triangles) {
        for (k, p) in tri.v.iter().enumerate() {
            dst[3 * k..3 * k + 3].copy_from_slice(&p.to_array());
        }
    }
    // SAFETY: as for `vs`, `3 · triangles.len()` u32.
    let is = unsafe { std::slice::from_raw_parts_mut(ib.cast::<u32>(), 3 * triangles.len()) };
    for (i, v) in is.iter_mut().enumerate() {
        // `i < 3 · len ≤ u32::MAX`, checked by the caller.
        *v = i as u32;
    }
    Ok(())
}

fn rtc_ray(ray: &Ray) -> ffi::RTCRay {
    ffi::RTCRay {
        org_x: ray.origin.x,
        org_y: ray.origin.y,
        org_z: ray.origin.z,
        tnear: ray.t_min,
        dir_x: ray.dir.x,
        dir_y: ray.dir.y,
        dir_z: ray.dir.z,
        time: 0.0,
        tfar: ray.t_max,
        mask: u32::MAX,
        id: 0,
        flags: 0,
    }
}

fn version_string(v: isize) -> String {
    format!("{}.{}.{}", v / 10000, v / 100 % 100, v % 100)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn device_config_names_each_option() {
        assert_eq!(device_config(&EmbreeOptions::default()), "verbose=0");
        let o = EmbreeOptions {
            build_threads: Some(3),
            avx2_at_most: true,
            ..EmbreeOptions::default()
        };
        assert_eq!(device_config(&o), "verbose=0,threads=3,max_isa=avx2");
    }
}
