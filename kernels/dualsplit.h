/* dualsplit kernels: the data layouts shared by the host (crates/sim/src/kernels.rs) and the
 * simulated threads (docs/isa.md).
 *
 * Memory map (byte addresses, docs/isa.md):
 *   0x0000_0000  the structure's memory image (MemoryImage::to_bytes): word i at byte 4i
 *   0x7000_0000  struct Params (read-only)
 *   0x7800_0000  the frame buffer, 3 f32 per pixel, row-major
 *   0x8000_0000  the program (link.ld)
 *   0xF000_0000  the thread's local store (stack), LOCAL_STORE_BYTES
 */
#ifndef DUALSPLIT_H
#define DUALSPLIT_H

#define PARAMS_ADDR 0x70000000u
#define FRAME_BUFFER_ADDR 0x78000000u
#define LOCAL_STORE_ADDR 0xF0000000u
#define LOCAL_STORE_BYTES 4096

#ifndef __ASSEMBLER__
#include <stdint.h>

/* Everything a frame needs, written by the host before the run. Mirrored field for field by
 * `dualsplit_sim::kernels::Params` (#[repr(C)], 160 bytes). Word offsets count 32-bit words
 * from image address 0. */
struct Params {
    uint32_t width;            /* image width in pixels */
    uint32_t height;           /* image height in pixels */
    uint32_t spp;              /* samples per pixel */
    uint32_t seed;             /* seed of the per-pixel hash */
    uint32_t workload;         /* 0 cast, 1 path (the kernel is built for one of them) */
    uint32_t bounces;          /* diffuse bounces after the primary hit (path) */
    float eye[3];              /* camera eye */
    float fwd[3];              /* camera basis: (target - eye).normalize() */
    float right[3];            /* fwd.cross(up).normalize() */
    float up[3];               /* right.cross(fwd) */
    float tan_half_fov;        /* tan(fov_y / 2) */
    float light_pos[3];        /* light centre */
    float light_radius;        /* light sphere radius */
    float light_power;         /* 2 * intensity * d^2 (crates/render/src/job.rs) */
    float eps;                 /* self-intersection offset along the normal */
    uint32_t nodes_start;      /* word range of the node region */
    uint32_t nodes_end;
    uint32_t indices_start;    /* word range of the triangle-index region */
    uint32_t indices_end;
    uint32_t triangles_start;  /* word range of the triangle region (9 words per triangle) */
    uint32_t triangles_end;
    uint32_t root;             /* word of the root node */
    float scene_min[3];        /* the DST's scene box (rays are clipped to it first) */
    float scene_max[3];
    uint32_t frame_buffer;     /* byte address of the frame buffer */
    uint32_t shadows;          /* 1: a shadow ray at every hit; 0: none, the light counted visible */
};

_Static_assert(sizeof(struct Params) == 160, "struct Params is 160 bytes");

/* ---- BVH images (crates/accel/src/image.rs) --------------------------------------------- */

/* A box as stored: min.xyz, max.xyz. */
struct Box {
    float lo[3];
    float hi[3];
};

/* BVH2 internal node, 52 B (crates/accel/src/bvh2/node.rs): two boxes and the packed word:
 * bits 0-29 child-block offset, bit 30 child 1 is a leaf, bit 31 child 0 is a leaf. */
struct Node2 {
    struct Box box[2];
    uint32_t packed;
};

/* BVH4 internal node, 100 B (crates/accel/src/wide/node4.rs): four boxes and the packed
 * word: bits 0-27 offset, bit 28 + k child k is a leaf. */
struct Node4 {
    struct Box box[4];
    uint32_t packed;
};

/* BVH8 internal node, 200 B (crates/accel/src/wide/node8.rs): eight boxes, the offset word
 * and the types word (bits 2k..2k+2 of slot k: 0 empty, 1 internal, 2 leaf). */
struct Node8 {
    struct Box box[8];
    uint32_t offset;
    uint32_t types;
};

_Static_assert(sizeof(struct Node2) == 52, "Node2 is 52 bytes");
_Static_assert(sizeof(struct Node4) == 100, "Node4 is 100 bytes");
_Static_assert(sizeof(struct Node8) == 200, "Node8 is 200 bytes");

#define NODE2_OFFSET_MASK ((1u << 30) - 1)
#define NODE4_OFFSET_MASK ((1u << 28) - 1)
#define NODE8_INTERNAL 1u
#define NODE8_LEAF 2u

/* Child kinds of a BVH slot. */
#define CHILD_EMPTY 0
#define CHILD_INTERNAL 1
#define CHILD_LEAF 2

/* The last entry of a triangle-index run has bit 31 set (BVH and DST images). */
#define LAST_IN_RUN 0x80000000u

/* ---- DST (crates/accel/src/dst/header.rs) ------------------------------------------------ */

/* A DST node: the header-offset word and two planes (a plain leaf is the word alone). */
struct DstNode {
    uint32_t word;
    float p0;
    float p1;
};

/* Header-offset word:  bit 31 C | 30-29 A | 28-27 B | 26 L | 25-0 offset. */
#define DST_BIT_C 0x80000000u
#define DST_BIT_L 0x04000000u
#define DST_OFFSET_MASK 0x03FFFFFFu
#define DST_FIELD_A(w) (((w) >> 29) & 3u)
#define DST_FIELD_B(w) (((w) >> 27) & 3u)
#define DST_A_SINGLE 2u

/* ---- Compressed BVH8 (crates/accel/src/cwbvh/node.rs, docs/cwbvh-encoding.md) ------------ */

/* 80-byte node (Ylitie et al. 2017): frame, child addressing, 8-bit quantized child boxes. */
struct CwNode {
    float p[3];           /* quantization origin */
    uint8_t e[3];         /* exponents: scale = 2^(e - 127) */
    uint8_t imask;        /* bit k: slot k is an internal node */
    uint32_t child_base;  /* word of the first internal child (20 words each, slot order) */
    uint32_t tri_base;    /* word of the node's first leaf run */
    uint8_t meta[8];      /* 0 empty; internal 0b001_00000 | (24 + k); leaf: count | offset */
    uint8_t q_lo[3][8];   /* quantized minima, axis by axis */
    uint8_t q_hi[3][8];   /* quantized maxima */
};

_Static_assert(sizeof(struct CwNode) == 80, "CwNode is 80 bytes");

#define CW_NODE_WORDS 20u
#define CW_META_OFFSET(m) ((uint32_t)(m) & 31u)

/* ---- Quantized DST (crates/accel/src/dstq, docs/dstq-encoding.md) ------------------------ */

/* The unit's geometry (crates/accel/src/dstq/unit.rs): clusters of at most 64 bytes, the
 * first root of a cluster at bit 128 (after its 16-byte frame). A record is named by one
 * word: its cluster's word address << DSTQ_POS_BITS | its bit position in the cluster. */
#define DSTQ_POS_BITS 9u
#define DSTQ_POS_MASK ((1u << DSTQ_POS_BITS) - 1u)
#define DSTQ_ROOT_BIT 128u

/* ---- Geometry constants (crates/geometry) ------------------------------------------------ */

/* EXIT_WIDEN = 1 + 2 * gamma(3) (crates/geometry/src/ray.rs), as f32 bits 0x3F800003. */
#define EXIT_WIDEN 0x1.000006p+0f

#endif /* __ASSEMBLER__ */
#endif
