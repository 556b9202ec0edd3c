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

/// `RTC_BUILD_QUALITY_MEDIUM` of `enum RTCBuildQuality` (binned SAH; the default).
pub const RTC_BUILD_QUALITY_MEDIUM: c_uint = 1;
/// `RTC_BUILD_MAX_PRIMITIVES_PER_LEAF`: the most primitives `rtcBuildBVH` puts in a leaf.
pub const RTC_BUILD_MAX_PRIMITIVES_PER_LEAF: usize = 32;

/// `RTCBVH`: an opaque handle owning a builder's memory.
#[allow(clippy::upper_case_acronyms)]
pub type RTCBVH = *mut c_void;
/// `RTCThreadLocalAllocator`: an opaque handle.
pub type RTCThreadLocalAllocator = *mut c_void;

/// `struct RTCBounds` (16-byte aligned, 32 bytes).
#[repr(C, align(16))]
#[derive(Clone, Copy, Debug, Default)]
pub struct RTCBounds {
    pub lower_x: f32,
    pub lower_y: f32,
    pub lower_z: f32,
    pub align0: f32,
    pub upper_x: f32,
    pub upper_y: f32,
    pub upper_z: f32,
    pub align1: f32,
}

/// `struct RTCBuildPrimitive` (32-byte aligned, 32 bytes).
#[repr(C, align(32))]
#[derive(Clone, Copy, Debug, Default)]
pub struct RTCBuildPrimitive {
    pub lower_x: f32,
    pub lower_y: f32,
    pub lower_z: f32,
    pub geom_id: c_uint,
    pub upper_x: f32,
    pub upper_y: f32,
    pub upper_z: f32,
    pub prim_id: c_uint,
}

/// `RTCCreateNodeFunction`.
pub type RTCCreateNodeFunction =
    unsafe extern "C" fn(RTCThreadLocalAllocator, c_uint, *mut c_void) -> *mut c_void;
/// `RTCSetNodeChildrenFunction`.
pub type RTCSetNodeChildrenFunction =
    unsafe extern "C" fn(*mut c_void, *mut *mut c_void, c_uint, *mut c_void);
/// `RTCSetNodeBoundsFunction`.
pub type RTCSetNodeBoundsFunction =
    unsafe extern "C" fn(*mut c_void, *mut *const RTCBounds, c_uint, *mut c_void);
/// `RTCCreateLeafFunction`.
pub type RTCCreateLeafFunction = unsafe extern "C" fn(
    RTCThreadLocalAllocator,
    *const RTCBuildPrimitive,
    usize,
    *mut c_void,
) -> *mut c_void;

/// `RTCSplitPrimitiveFunction`: a primitive's boxes left and right of a plane.
pub type RTCSplitPrimitiveFunction = unsafe extern "C" fn(
    *const RTCBuildPrimitive,
    c_uint,
    f32,
    *mut RTCBounds,
    *mut RTCBounds,
    *mut c_void,
);

/// `struct RTCBuildArguments` (Embree 3.13's `rtcore_builder.h`), with the progress callback
/// always null.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct RTCBuildArguments {
    pub byte_size: usize,
    pub build_quality: c_uint,
    pub build_flags: c_uint,
    pub max_branching_factor: c_uint,
    pub max_depth: c_uint,
    pub sah_block_size: c_uint,
    pub min_leaf_size: c_uint,
    pub max_leaf_size: c_uint,
    pub traversal_cost: f32,
    pub intersection_cost: f32,
    pub bvh: RTCBVH,
    pub primitives: *mut RTCBuildPrimitive,
    pub primitive_count: usize,
    pub primitive_array_capacity: usize,
    pub create_node: Option<RTCCreateNodeFunction>,
    pub set_node_children: Option<RTCSetNodeChildrenFunction>,
    pub set_node_bounds: Option<RTCSetNodeBoundsFunction>,
    pub create_leaf: Option<RTCCreateLeafFunction>,
    /// Null unless the build makes spatial splits (high quality).
    pub split_primitive: Option<RTCSplitPrimitiveFunction>,
    /// `RTCProgressMonitorFunction`, always null here.
    pub build_progress: *const c_void,
    pub user_ptr: *mut c_void,
}

const _: () = assert!(std::mem::size_of::<RTCBounds>() == 32);
const _: () = assert!(std::mem::size_of::<RTCBuildPrimitive>() == 32);
const _: () = assert!(std::mem::size_of::<RTCBuildArguments>() == 136);

#[link(name = "embree3")]
unsafe extern "C" {
    pub fn rtcNewBVH(device: RTCDevice) -> RTCBVH;
    pub fn rtcBuildBVH(args: *const RTCBuildArguments) -> *mut c_void;
    pub fn rtcThreadLocalAlloc(
        allocator: RTCThreadLocalAllocator,
        bytes: usize,
        align: usize,
    ) -> *mut c_void;
    pub fn rtcReleaseBVH(bvh: RTCBVH);

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
