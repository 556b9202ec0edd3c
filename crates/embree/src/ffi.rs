//! The few declarations of Embree 3's C API (`embree3/rtcore*.h`, version 3.13) that the
//! scene wrapper calls, written by hand. Layouts follow Debian's build: one instance level
//! (`RTC_MAX_INSTANCE_LEVEL_COUNT 1`) and no curve minimum width (`EMBREE_MIN_WIDTH 0`);
//! `build.rs` refuses the library when its `rtcore_config.h` says otherwise.

use std::ffi::{c_char, c_uint, c_void};

/// `RTCDevice`: an opaque handle.
pub type RTCDevice = *mut c_void;
/// `RTCScene`: an opaque handle.
pub type RTCScene = *mut c_void;
/// `RTCGeometry`: an opaque handle.
pub type RTCGeometry = *mut c_void;

/// `RTC_GEOMETRY_TYPE_TRIANGLE` of `enum RTCGeometryType`.
pub const RTC_GEOMETRY_TYPE_TRIANGLE: c_uint = 0;
/// `RTC_BUFFER_TYPE_INDEX` of `enum RTCBufferType`.
pub const RTC_BUFFER_TYPE_INDEX: c_uint = 0;
/// `RTC_BUFFER_TYPE_VERTEX` of `enum RTCBufferType`.
pub const RTC_BUFFER_TYPE_VERTEX: c_uint = 1;
/// `RTC_FORMAT_UINT3` of `enum RTCFormat`.
pub const RTC_FORMAT_UINT3: c_uint = 0x5003;
/// `RTC_FORMAT_FLOAT3` of `enum RTCFormat`.
pub const RTC_FORMAT_FLOAT3: c_uint = 0x9003;
/// `RTC_SCENE_FLAG_ROBUST` of `enum RTCSceneFlags`.
pub const RTC_SCENE_FLAG_ROBUST: c_uint = 1 << 2;
/// `RTC_BUILD_QUALITY_HIGH` of `enum RTCBuildQuality`.
pub const RTC_BUILD_QUALITY_HIGH: c_uint = 2;
/// `RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT` of `enum RTCIntersectContextFlags`.
pub const RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT: c_uint = 0;
/// `RTC_INVALID_GEOMETRY_ID`: `geomID` of a ray that hit nothing.
pub const RTC_INVALID_GEOMETRY_ID: c_uint = u32::MAX;
/// `RTC_DEVICE_PROPERTY_VERSION` of `enum RTCDeviceProperty` (e.g. 31305 for 3.13.5).
pub const RTC_DEVICE_PROPERTY_VERSION: c_uint = 0;
/// `RTC_DEVICE_PROPERTY_BACKFACE_CULLING_ENABLED` of `enum RTCDeviceProperty`.
pub const RTC_DEVICE_PROPERTY_BACKFACE_CULLING_ENABLED: c_uint = 65;

/// `struct RTCRay` (16-byte aligned, 48 bytes).
#[repr(C, align(16))]
#[derive(Clone, Copy, Debug, Default)]
pub struct RTCRay {
    pub org_x: f32,
    pub org_y: f32,
    pub org_z: f32,
    pub tnear: f32,
    pub dir_x: f32,
    pub dir_y: f32,
    pub dir_z: f32,
    pub time: f32,
    /// End of the segment; on a hit, the hit distance; after `rtcOccluded1` on an occluded
    /// ray, `-∞`.
    pub tfar: f32,
    pub mask: c_uint,
    pub id: c_uint,
    pub flags: c_uint,
}

/// `struct RTCHit` (16-byte aligned, 32 bytes with one instance level).
#[repr(C, align(16))]
#[derive(Clone, Copy, Debug, Default)]
pub struct RTCHit {
    pub ng_x: f32,
    pub ng_y: f32,
    pub ng_z: f32,
    pub u: f32,
    pub v: f32,
    pub prim_id: c_uint,
    pub geom_id: c_uint,
    pub inst_id: [c_uint; 1],
}

/// `struct RTCRayHit`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default)]
pub struct RTCRayHit {
    pub ray: RTCRay,
    pub hit: RTCHit,
}

/// `struct RTCIntersectContext` with one instance level and no minimum width.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct RTCIntersectContext {
    pub flags: c_uint,
    /// `RTCFilterFunctionN`, always null here.
    pub filter: *const c_void,
    pub inst_id: [c_uint; 1],
}

impl RTCIntersectContext {
    /// What the header's inline `rtcInitIntersectContext` sets: incoherent, no filter, no
    /// instance.
    pub fn new() -> Self {
        Self {
            flags: RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT,
            filter: std::ptr::null(),
            inst_id: [RTC_INVALID_GEOMETRY_ID],
        }
    }
}

const _: () = assert!(std::mem::size_of::<RTCRay>() == 48);
const _: () = assert!(std::mem::size_of::<RTCHit>() == 32);
const _: () = assert!(std::mem::size_of::<RTCRayHit>() == 80);
const _: () = assert!(std::mem::size_of::<RTCIntersectContext>() == 24);

#[link(name = "embree3")]
unsafe extern "C" {
    pub fn rtcNewDevice(config: *const c_char) -> RTCDevice;
    pub fn rtcReleaseDevice(device: RTCDevice);
    pub fn rtcGetDeviceError(device: RTCDevice) -> c_uint;
    pub fn rtcGetDeviceProperty(device: RTCDevice, prop: c_uint) -> isize;

    pub fn rtcNewScene(device: RTCDevice) -> RTCScene;
    pub fn rtcSetSceneFlags(scene: RTCScene, flags: c_uint);
    pub fn rtcSetSceneBuildQuality(scene: RTCScene, quality: c_uint);
    pub fn rtcAttachGeometry(scene: RTCScene, geometry: RTCGeometry) -> c_uint;
    pub fn rtcCommitScene(scene: RTCScene);
    pub fn rtcReleaseScene(scene: RTCScene);

    pub fn rtcNewGeometry(device: RTCDevice, ty: c_uint) -> RTCGeometry;
    pub fn rtcSetNewGeometryBuffer(
        geometry: RTCGeometry,
        ty: c_uint,
        slot: c_uint,
        format: c_uint,
        byte_stride: usize,
        item_count: usize,
    ) -> *mut c_void;
    pub fn rtcSetGeometryBuildQuality(geometry: RTCGeometry, quality: c_uint);
    pub fn rtcCommitGeometry(geometry: RTCGeometry);
    pub fn rtcReleaseGeometry(geometry: RTCGeometry);

    pub fn rtcIntersect1(
        scene: RTCScene,
        context: *mut RTCIntersectContext,
        rayhit: *mut RTCRayHit,
    );
    pub fn rtcOccluded1(scene: RTCScene, context: *mut RTCIntersectContext, ray: *mut RTCRay);
}
