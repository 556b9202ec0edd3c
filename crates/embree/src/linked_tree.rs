//! [`crate::tree::build_tree`] on the linked library: `rtcBuildBVH` with callbacks that
//! write nodes and leaves into Embree's thread-local memory, then one walk that copies them
//! out before the memory is released.

use crate::EmbreeError;
use crate::ffi::{self, RTCBounds, RTCBuildPrimitive, RTCThreadLocalAllocator};
use crate::linked::{call_error, new_device};
use crate::tree::{BuiltTree, Child, TreeArgs, clipped_bounds};
use dualsplit_geometry::{Aabb, Triangle, Vec3};
use std::ffi::{c_uint, c_void};

/// Most children of a node the callbacks store ([`TreeArgs::branching`] is checked).
const MAX_CHILDREN: usize = 8;

/// An internal node as the callbacks write it (tag 0).
#[repr(C)]
struct RawNode {
    tag: u32,
    count: u32,
    children: [*mut c_void; MAX_CHILDREN],
    bounds: [RTCBounds; MAX_CHILDREN],
}

/// A leaf as the callbacks write it (tag 1).
#[repr(C)]
struct RawLeaf {
    tag: u32,
    count: u32,
    prims: [u32; ffi::RTC_BUILD_MAX_PRIMITIVES_PER_LEAF],
}

/// Writes `value` into a block of Embree's thread-local memory sized and aligned for it;
/// the block, or null when Embree has no memory.
///
/// # Safety
/// `alloc` must be the allocator Embree passed the calling callback.
unsafe fn place<T>(alloc: RTCThreadLocalAllocator, value: T) -> *mut c_void {
    // SAFETY: the caller's contract; the block is sized and aligned for a `T` and written
    // whole before it is returned.
    unsafe {
        let p =
            ffi::rtcThreadLocalAlloc(alloc, std::mem::size_of::<T>(), std::mem::align_of::<T>())
                .cast::<T>();
        if !p.is_null() {
            p.write(value);
        }
        p.cast()
    }
}

/// `RTCCreateNodeFunction`: a fresh [`RawNode`] in the builder's memory.
unsafe extern "C" fn create_node(
    alloc: RTCThreadLocalAllocator,
    count: c_uint,
    _: *mut c_void,
) -> *mut c_void {
    let node = RawNode {
        tag: 0,
        count: count.min(MAX_CHILDREN as u32),
        children: [std::ptr::null_mut(); MAX_CHILDREN],
        bounds: [RTCBounds::default(); MAX_CHILDREN],
    };
    // SAFETY: `alloc` is the allocator Embree passes this callback.
    unsafe { place(alloc, node) }
}

/// `RTCSetNodeChildrenFunction`: the node's child pointers.
unsafe extern "C" fn set_children(
    node: *mut c_void,
    children: *mut *mut c_void,
    count: c_uint,
    _: *mut c_void,
) {
    // SAFETY: `node` is a `RawNode` from `create_node` (Embree passes back what it returned)
    // and `children` holds `count` pointers, at most the branching factor (≤ 8, checked).
    unsafe {
        let n = &mut *node.cast::<RawNode>();
        for i in 0..(count as usize).min(MAX_CHILDREN) {
            n.children[i] = *children.add(i);
        }
    }
}

/// `RTCSetNodeBoundsFunction`: the node's child boxes.
unsafe extern "C" fn set_bounds(
    node: *mut c_void,
    bounds: *mut *const RTCBounds,
    count: c_uint,
    _: *mut c_void,
) {
    // SAFETY: as in `set_children`; `bounds` holds `count` pointers to valid boxes.
    unsafe {
        let n = &mut *node.cast::<RawNode>();
        for i in 0..(count as usize).min(MAX_CHILDREN) {
            n.bounds[i] = **bounds.add(i);
        }
    }
}

/// `RTCCreateLeafFunction`: a [`RawLeaf`] of the primitives' ids.
unsafe extern "C" fn create_leaf(
    alloc: RTCThreadLocalAllocator,
    prims: *const RTCBuildPrimitive,
    count: usize,
    _: *mut c_void,
) -> *mut c_void {
    let count = count.min(ffi::RTC_BUILD_MAX_PRIMITIVES_PER_LEAF);
    let mut leaf = RawLeaf {
        tag: 1,
        count: count as u32,
        prims: [0; ffi::RTC_BUILD_MAX_PRIMITIVES_PER_LEAF],
    };
    for (i, id) in leaf.prims[..count].iter_mut().enumerate() {
        // SAFETY: `prims` holds `count` primitives (at most the leaf limit, ≤ 32, checked).
        *id = unsafe { (*prims.add(i)).prim_id };
    }
    // SAFETY: `alloc` is the allocator Embree passes this callback.
    unsafe { place(alloc, leaf) }
}

/// `RTCSplitPrimitiveFunction`: the boxes of the parts of the primitive's triangle on either
/// side of the plane `x[dim] = pos`, each within the primitive's box cut at the plane
/// ([`clipped_bounds`]; that cut box itself where the part is empty by rounding).
unsafe extern "C" fn split_primitive(
    prim: *const RTCBuildPrimitive,
    dim: c_uint,
    pos: f32,
    left: *mut RTCBounds,
    right: *mut RTCBounds,
    user: *mut c_void,
) {
    // SAFETY: `user` is the `&[Triangle]` that `build_tree` passes as the user pointer,
    // live for the build; `prim` is a primitive of the build, whose id indexes it (ids
    // are set by `build_tree` and kept by Embree through splits); `left` and `right`
    // are Embree's boxes to write.
    unsafe {
        let triangles = &*user.cast::<&[Triangle]>();
        let p = &*prim;
        let b = Aabb {
            min: Vec3::new(p.lower_x, p.lower_y, p.lower_z),
            max: Vec3::new(p.upper_x, p.upper_y, p.upper_z),
        };
        let d = (dim as usize).min(2);
        let pos = pos.clamp(b.min[d], b.max[d]);
        let (mut l, mut r) = (b, b);
        l.max[d] = pos;
        r.min[d] = pos;
        let t = &triangles[p.prim_id as usize];
        *left = bounds(clipped_bounds(t, &l).unwrap_or(l));
        *right = bounds(clipped_bounds(t, &r).unwrap_or(r));
    }
}

/// The `RTCBounds` of a box.
fn bounds(b: Aabb) -> RTCBounds {
    RTCBounds {
        lower_x: b.min.x,
        lower_y: b.min.y,
        lower_z: b.min.z,
        upper_x: b.max.x,
        upper_y: b.max.y,
        upper_z: b.max.z,
        ..Default::default()
    }
}

/// The box of an `RTCBounds`.
fn aabb(b: &RTCBounds) -> Aabb {
    Aabb {
        min: Vec3::new(b.lower_x, b.lower_y, b.lower_z),
        max: Vec3::new(b.upper_x, b.upper_y, b.upper_z),
    }
}

/// The tree over `boxes`; with `split`, the high-quality build with spatial splits of those
/// triangles (`boxes[i]` is `split[i]`'s box).
pub(crate) fn build_tree(
    boxes: &[Aabb],
    args: &TreeArgs,
    split: Option<&[Triangle]>,
) -> Result<BuiltTree, EmbreeError> {
    // Released when `guard` drops, after the tree is copied out.
    let guard = new_device("verbose=0")?;
    let device = guard.0;
    let mut prims: Vec<RTCBuildPrimitive> = boxes
        .iter()
        .enumerate()
        .map(|(i, b)| RTCBuildPrimitive {
            lower_x: b.min.x,
            lower_y: b.min.y,
            lower_z: b.min.z,
            geom_id: 0,
            upper_x: b.max.x,
            upper_y: b.max.y,
            upper_z: b.max.z,
            prim_id: i as u32,
        })
        .collect();
    let count = prims.len();
    // Room for the references spatial splits add.
    if split.is_some() {
        prims.resize(2 * count, prims[0]);
    }
    let mut triangles: &[Triangle] = split.unwrap_or_default();
    // SAFETY: `device` is live.
    let bvh = unsafe { ffi::rtcNewBVH(device) };
    if bvh.is_null() {
        return Err(call_error(device, "rtcNewBVH"));
    }
    let a = ffi::RTCBuildArguments {
        byte_size: std::mem::size_of::<ffi::RTCBuildArguments>(),
        build_quality: match split {
            Some(_) => ffi::RTC_BUILD_QUALITY_HIGH,
            None => ffi::RTC_BUILD_QUALITY_MEDIUM,
        },
        build_flags: 0,
        max_branching_factor: args.branching,
        max_depth: 64,
        sah_block_size: args.sah_block,
        min_leaf_size: args.min_leaf,
        max_leaf_size: args.max_leaf,
        traversal_cost: args.traversal_cost,
        intersection_cost: args.intersection_cost,
        bvh,
        primitives: prims.as_mut_ptr(),
        primitive_count: count,
        primitive_array_capacity: prims.len(),
        create_node: Some(create_node),
        set_node_children: Some(set_children),
        set_node_bounds: Some(set_bounds),
        create_leaf: Some(create_leaf),
        split_primitive: split.map(|_| split_primitive as ffi::RTCSplitPrimitiveFunction),
        build_progress: std::ptr::null(),
        user_ptr: (&raw mut triangles).cast(),
    };
    // SAFETY: `a` is a complete `RTCBuildArguments` whose primitive array (`prims`,
    // 32-byte aligned elements, `count` of them in use and room for as many more) is live
    // and exclusively lent for the call, whose callbacks write only memory they allocated
    // from Embree's allocator or the two boxes Embree hands the split callback, and whose
    // user pointer is `triangles`, live for the call.
    let root = unsafe { ffi::rtcBuildBVH(&a) };
    let tree = if root.is_null() {
        Err(call_error(device, "rtcBuildBVH"))
    } else {
        // SAFETY: the nodes and leaves live in `bvh`'s memory until `rtcReleaseBVH`
        // below; every pointer reached from `root` was returned by `create_node` or
        // `create_leaf`.
        Ok(unsafe { walk(root) })
    };
    // SAFETY: `bvh` is live and released once; nothing refers to its memory afterwards.
    unsafe { ffi::rtcReleaseBVH(bvh) };
    tree
}

/// Copies the tree below `root` out of Embree's memory, nodes in depth-first order.
///
/// # Safety
/// `root` and every child pointer below it must be a live [`RawNode`] or [`RawLeaf`].
unsafe fn walk(root: *mut c_void) -> BuiltTree {
    let mut t = BuiltTree {
        nodes: Vec::new(),
        leaves: Vec::new(),
        root: Child::Leaf(0),
    };
    // (pointer, where its reference goes: the node and slot of its parent, or the root)
    let mut todo: Vec<(*mut c_void, Option<(usize, usize)>)> = vec![(root, None)];
    while let Some((p, parent)) = todo.pop() {
        // SAFETY: the caller's contract; both kinds start with the `u32` tag.
        let child = unsafe {
            if *p.cast::<u32>() == 1 {
                let l = &*p.cast::<RawLeaf>();
                // Spatial splits can give a leaf two parts of one triangle: kept once.
                let mut ids: Vec<u32> = Vec::with_capacity(l.count as usize);
                for &id in &l.prims[..l.count as usize] {
                    if !ids.contains(&id) {
                        ids.push(id);
                    }
                }
                t.leaves.push(ids);
                Child::Leaf(t.leaves.len() as u32 - 1)
            } else {
                let n = &*p.cast::<RawNode>();
                let at = t.nodes.len();
                t.nodes.push(
                    n.bounds[..n.count as usize]
                        .iter()
                        .map(|b| (aabb(b), Child::Leaf(u32::MAX)))
                        .collect(),
                );
                for k in (0..n.count as usize).rev() {
                    todo.push((n.children[k], Some((at, k))));
                }
                Child::Node(at as u32)
            }
        };
        match parent {
            Some((node, slot)) => t.nodes[node][slot].1 = child,
            None => t.root = child,
        }
    }
    t
}
