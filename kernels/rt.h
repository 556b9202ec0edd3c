/* The ray-tracing instructions of docs/isa.md as inline functions (RISC-V custom-0 0x0B,
 * custom-1 0x2B, custom-2 0x5B and custom-3 0x7B opcodes, emitted with .insn). Every
 * instruction that reads or writes the thread's ray registers, latches, pipeline input
 * registers or global registers is `asm volatile`, so the compiler keeps them in program
 * order; the memory the box, triangle and DST instructions read is the read-only structure
 * image. */
#ifndef RT_H
#define RT_H

#include <stdint.h>

/* ---- custom-0: ray registers, reciprocal, atomic increment ---------------------------- */

/* R.o = (x, y, z) */
static inline void rt_setorg(float x, float y, float z)
{
    __asm__ volatile(".insn r4 0x0B, 0, 0, x0, %0, %1, %2" : : "f"(x), "f"(y), "f"(z));
}

/* R.inv = (x, y, z): 1/dir per component */
static inline void rt_setinv(float x, float y, float z)
{
    __asm__ volatile(".insn r4 0x0B, 1, 0, x0, %0, %1, %2" : : "f"(x), "f"(y), "f"(z));
}

/* R.shear = (Sx, Sy, Sz) */
static inline void rt_setshear(float x, float y, float z)
{
    __asm__ volatile(".insn r4 0x0B, 2, 0, x0, %0, %1, %2" : : "f"(x), "f"(y), "f"(z));
}

/* R.k = kx | ky << 2 | kz << 4 */
static inline void rt_setk(uint32_t k)
{
    __asm__ volatile(".insn r 0x0B, 3, 0, x0, %0, x0" : : "r"(k));
}

/* 1.0f / x, correctly rounded, on the reciprocal unit */
static inline float rt_rcp(float x)
{
    float r;
    __asm__(".insn r 0x0B, 4, 0, %0, %1, x0" : "=f"(r) : "f"(x));
    return r;
}

/* G[g] += 1, returning the old value */
static inline uint32_t rt_atominc(uint32_t g)
{
    uint32_t r;
    __asm__ volatile(".insn r 0x0B, 5, 0, %0, %1, x0" : "=r"(r) : "r"(g));
    return r;
}

/* K = (x, y, sample): the random key of the pixel sample that rt_rand reads */
static inline void rt_srand(uint32_t x, uint32_t y, uint32_t sample)
{
    __asm__ volatile(".insn r4 0x0B, 6, 0, x0, %0, %1, %2" : : "r"(x), "r"(y), "r"(sample));
}

/* The renderer's random number hash(K.x, K.y, K.sample, bounce, seed, dim) in [0, 1), on the
 * FP adder as TRaX's RAND (dim a constant 0-127, in funct7: a macro). */
#define rt_rand(dim, bounce, seed)                                                   \
    ({                                                                               \
        float r_;                                                                    \
        __asm__ volatile(".insn r 0x0B, 7, %3, %0, %1, %2"                           \
                         : "=f"(r_)                                                  \
                         : "r"(bounce), "r"(seed), "i"(dim));                        \
        r_;                                                                          \
    })

/* ---- custom-1: ray-box, ray-triangle, dual-split --------------------------------------- */

/* Slab test of the box at `box` (min xyz, max xyz) on [t_lo, t_hi]: the entry distance when
 * the ray meets it, else NaN. */
static inline float rt_box(const void *box, float t_lo, float t_hi)
{
    float r;
    __asm__ volatile(".insn r4 0x2B, 0, 0, %0, %1, %2, %3"
                     : "=f"(r)
                     : "r"(box), "f"(t_lo), "f"(t_hi));
    return r;
}

/* `rt.box` on N consecutive boxes at once (N = 2, 4, 8 -> funct2 = 0, 1, 2): bit k of the
 * result is set when box k is hit; the entries go to the box latch (rt_boxget). The funct2
 * must be a constant, so this is a macro. */
#define RT_BOXN_F2(n) ((n) == 2 ? 0 : (n) == 4 ? 1 : 2)
#define rt_boxn(n, boxes, t_lo, t_hi)                                                \
    ({                                                                               \
        uint32_t mask_;                                                              \
        __asm__ volatile(".insn r4 0x2B, 1, %4, %0, %1, %2, %3"                      \
                         : "=r"(mask_)                                               \
                         : "r"(boxes), "f"(t_lo), "f"(t_hi), "i"(RT_BOXN_F2(n)));    \
        mask_;                                                                       \
    })

/* Entry distance of box k of the last rt_boxn (k a constant 0-7; rt_boxexit is k = 8). */
#define rt_boxget(k)                                                                 \
    ({                                                                               \
        float entry_;                                                                \
        __asm__ volatile(".insn r 0x2B, 2, %1, %0, x0, x0" : "=f"(entry_) : "i"(k)); \
        entry_;                                                                      \
    })

/* The exit distance of the last rt_box (its slab interval's far end, hit or miss). */
static inline float rt_boxexit(void)
{
    float r;
    __asm__ volatile(".insn r 0x2B, 2, 8, %0, x0, x0" : "=f"(r));
    return r;
}

/* Watertight test of the triangle at `tri` (v0, v1, v2) on [t_lo, t_hi]: t of the hit, else
 * NaN. */
static inline float rt_tri(const void *tri, float t_lo, float t_hi)
{
    float r;
    __asm__ volatile(".insn r4 0x2B, 3, 0, %0, %1, %2, %3"
                     : "=f"(r)
                     : "r"(tri), "f"(t_lo), "f"(t_hi));
    return r;
}

/* One dual-split pipeline step on the node at `node`: code | offset << 2; the rest goes to
 * the DST latch (rt_dst_tmin, rt_dst_tmax, rt_dst_offset_stack). */
static inline uint32_t rt_dst(const void *node, float t_min, float t_max)
{
    uint32_t r;
    __asm__ volatile(".insn r4 0x2B, 4, 0, %0, %1, %2, %3"
                     : "=r"(r)
                     : "r"(node), "f"(t_min), "f"(t_max));
    return r;
}

static inline float rt_dst_tmin(void)
{
    float r;
    __asm__ volatile(".insn r 0x2B, 5, 0, %0, x0, x0" : "=f"(r));
    return r;
}

static inline float rt_dst_tmax(void)
{
    float r;
    __asm__ volatile(".insn r 0x2B, 5, 1, %0, x0, x0" : "=f"(r));
    return r;
}

static inline uint32_t rt_dst_offset_stack(void)
{
    uint32_t r;
    __asm__ volatile(".insn r 0x2B, 5, 2, %0, x0, x0" : "=r"(r));
    return r;
}
/* The return code of the last rt_dstqp. */
static inline uint32_t rt_dst_code(void)
{
    uint32_t r;
    __asm__ volatile(".insn r 0x2B, 5, 3, %0, x0, x0" : "=r"(r));
    return r;
}


/* The 8 child boxes of the 80-byte compressed-BVH8 node at `node`, dequantized and tested on
 * [t_lo, t_hi] by the quantized ray-box pipelines: bit k of the result is set when child k
 * is hit; the entries go to the box latch (rt_boxget). */
static inline uint32_t rt_qboxn(const void *node, float t_lo, float t_hi)
{
    uint32_t r;
    __asm__ volatile(".insn r4 0x2B, 6, 0, %0, %1, %2, %3"
                     : "=r"(r)
                     : "r"(node), "f"(t_lo), "f"(t_hi));
    return r;
}

/* ---- custom-2: loads into the pipeline input registers P ------------------------------ */

/* P[k] = the word at `p`, an ordinary load (k a constant 0-31); the register forms below read
 * P. A macro: k is the rd field. */
#define rt_ldp(k, p)                                                                 \
    __asm__ volatile(".insn i 0x5B, 0, x%1, %0" : : "m"(*(const uint32_t *)(p)), "i"(k))

/* P[32 + k] = the word at `p` (k a constant 0-15). */
#define rt_ldph(k, p)                                                                \
    __asm__ volatile(".insn i 0x5B, 1, x%1, %0" : : "m"(*(const uint32_t *)(p)), "i"(k))

/* ---- custom-3: the register forms, node words from P ---------------------------------- */

/* rt_box on the box in P[0..6]. */
static inline float rt_boxp(float t_lo, float t_hi)
{
    float r;
    __asm__ volatile(".insn r4 0x7B, 0, 0, %0, x0, %1, %2" : "=f"(r) : "f"(t_lo), "f"(t_hi));
    return r;
}

/* rt_boxn on the N boxes in P[0..6N] (N = 2, 4, 8 -> funct2 = 0, 1, 2). */
#define rt_boxnp(n, t_lo, t_hi)                                                      \
    ({                                                                               \
        uint32_t mask_;                                                              \
        __asm__ volatile(".insn r4 0x7B, 1, %3, %0, x0, %1, %2"                      \
                         : "=r"(mask_)                                               \
                         : "f"(t_lo), "f"(t_hi), "i"(RT_BOXN_F2(n)));                \
        mask_;                                                                       \
    })

/* rt_tri on the triangle in P[0..9]. */
static inline float rt_trip(float t_lo, float t_hi)
{
    float r;
    __asm__ volatile(".insn r4 0x7B, 3, 0, %0, x0, %1, %2" : "=f"(r) : "f"(t_lo), "f"(t_hi));
    return r;
}

/* rt_dst on the node in P[0..3]. */
static inline uint32_t rt_dstp(float t_min, float t_max)
{
    uint32_t r;
    __asm__ volatile(".insn r4 0x7B, 4, 0, %0, x0, %1, %2" : "=r"(r) : "f"(t_min), "f"(t_max));
    return r;
}

/* rt_qboxn on the node in P[0..20]. */
static inline uint32_t rt_qboxnp(float t_lo, float t_hi)
{
    uint32_t r;
    __asm__ volatile(".insn r4 0x7B, 6, 0, %0, x0, %1, %2" : "=r"(r) : "f"(t_lo), "f"(t_hi));
    return r;
}

/* One quantized dual-split pipeline step on the DST-Q record named `at` (its cluster's word
 * address << 9 | its bit position in the cluster; the cluster's frame in P[32..36], the
 * three words from the one holding the record's first bit in P[36..39]): the name of the record to
 * continue at, or the triangle run's index entry; the rest goes to the DST latch
 * (rt_dst_code, rt_dst_tmin, rt_dst_tmax, rt_dst_offset_stack: the far child's name). */
static inline uint32_t rt_dstqp(uint32_t at, float t_min, float t_max)
{
    uint32_t r;
    __asm__ volatile(".insn r4 0x7B, 7, 0, %0, %1, %2, %3"
                     : "=r"(r)
                     : "r"(at), "f"(t_min), "f"(t_max));
    return r;
}

/* ---- how the kernels reach the pipelines ----------------------------------------------- */

/* RT_BOX, RT_BOXN, RT_TRI, RT_DST: with PIPE_LOADS, one rt.ldp per node word into P, then the
 * register form (the LOADPIPEGLB form of SimTRaX's ISA); else the memory-operand form. */
#define PIPE_LD(k, p)                                                                \
    do {                                                                             \
        if ((k) < 32)                                                                \
            rt_ldp((k) & 31, (p) + (k));                                             \
        else                                                                         \
            rt_ldph((k) & 15, (p) + (k));                                            \
    } while (0)
#define PIPE_LD3(k, p)                                                               \
    PIPE_LD(k, p);                                                                   \
    PIPE_LD((k) + 1, p);                                                             \
    PIPE_LD((k) + 2, p)
#define PIPE_LD6(k, p) PIPE_LD3(k, p); PIPE_LD3((k) + 3, p)
#define PIPE_LD12(k, p) PIPE_LD6(k, p); PIPE_LD6((k) + 6, p)
#define PIPE_LD24(k, p) PIPE_LD12(k, p); PIPE_LD12((k) + 12, p)
#define PIPE_LD4(k, p) PIPE_LD3(k, p); PIPE_LD((k) + 3, p)
#define PIPE_LD20(k, p) PIPE_LD12(k, p); PIPE_LD6((k) + 12, p); PIPE_LD((k) + 18, p); PIPE_LD((k) + 19, p)

#if PIPE_LOADS
#define RT_BOX(box, t_lo, t_hi)                                                      \
    ({                                                                               \
        const uint32_t *w_ = (const uint32_t *)(box);                                \
        PIPE_LD6(0, w_);                                                             \
        rt_boxp(t_lo, t_hi);                                                         \
    })
#define RT_BOXN(n, boxes, t_lo, t_hi)                                                \
    ({                                                                               \
        const uint32_t *w_ = (const uint32_t *)(boxes);                              \
        PIPE_LD12(0, w_);                                                            \
        if ((n) >= 4) {                                                              \
            PIPE_LD12(12, w_);                                                       \
        }                                                                            \
        if ((n) == 8) {                                                              \
            PIPE_LD24(24, w_);                                                       \
        }                                                                            \
        rt_boxnp(n, t_lo, t_hi);                                                     \
    })
#define RT_TRI(tri, t_lo, t_hi)                                                      \
    ({                                                                               \
        const uint32_t *w_ = (const uint32_t *)(tri);                                \
        PIPE_LD6(0, w_);                                                             \
        PIPE_LD3(6, w_);                                                             \
        rt_trip(t_lo, t_hi);                                                         \
    })
#define RT_DST(node, t_min, t_max)                                                   \
    ({                                                                               \
        const uint32_t *w_ = (const uint32_t *)(node);                               \
        PIPE_LD3(0, w_);                                                             \
        rt_dstp(t_min, t_max);                                                       \
    })
#define RT_QBOXN(node, t_lo, t_hi)                                                   \
    ({                                                                               \
        const uint32_t *w_ = (const uint32_t *)(node);                               \
        PIPE_LD20(0, w_);                                                            \
        rt_qboxnp(t_lo, t_hi);                                                       \
    })
#else
#define RT_QBOXN(node, t_lo, t_hi) rt_qboxn(node, t_lo, t_hi)
#define RT_BOX(box, t_lo, t_hi) rt_box(box, t_lo, t_hi)
#define RT_BOXN(n, boxes, t_lo, t_hi) rt_boxn(n, boxes, t_lo, t_hi)
#define RT_TRI(tri, t_lo, t_hi) rt_tri(tri, t_lo, t_hi)
#define RT_DST(node, t_min, t_max) rt_dst(node, t_min, t_max)
#endif

#endif
