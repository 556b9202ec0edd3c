/* CWBVH and CWBVH+: the compressed 8-wide BVH (crates/accel/src/cwbvh/traverse.rs), included
 * by render.c. One rt.qboxn per node dequantizes and tests its 8 child boxes (CWBVH+: on 8
 * quantized ray-box pipelines in one issue; CWBVH: the same instruction on one pipeline, the
 * tests one after another); the hits of occupied slots are ordered as bvh.h orders them.
 *
 * Per internal node: continue with the nearest hit child and push the others far-first
 * (ties in slot order); a popped entry beyond cull_limit(best) is dropped. A leaf child's
 * run starts at the node's triangle base plus its meta offset (no leaf word); its triangles
 * are tested on [t_min, best_t], keeping the closest by (t, id). */

#include "bvh_common.h"

static int traverse(const struct Ray *ray, const struct RayPre *pre, int any, struct Hit *best)
{
    (void)pre;
    BVH_TRAVERSE_BEGIN(ray);
    for (;;) {
        struct Entry e;
        BVH_NEXT_ENTRY(e);
        if (e.word & ENTRY_LEAF) {
            BVH_TEST_RUN(e.word & ~ENTRY_LEAF);
            continue;
        }
        const struct CwNode *node = (const struct CwNode *)WORD_ADDR(e.word);
        if (sp > STACK_SIZE - 8)
            kernel_fault(); /* deeper than any tree the builder makes */
        int base = sp;
        uint32_t mask = RT_QBOXN(node, t_min, limit);
        uint32_t imask = node->imask;
        uint32_t child = node->child_base;
        uint32_t tri_base = node->tri_base;
/* Slot k: an occupied slot whose box was hit joins the order (BVH_ORDER); an internal slot
 * advances the child word. The hit bit of an empty slot is ignored (its decoded box is
 * empty, but a NaN plane would let it through). */
#define SLOT(k)                                                                        \
    do {                                                                               \
        uint32_t m = node->meta[k];                                                    \
        int internal = (imask >> (k)) & 1u;                                            \
        if (m != 0 && ((mask >> (k)) & 1u)) {                                          \
            float entry = rt_boxget(k);                                                \
            BVH_ORDER(entry, internal ? child : (tri_base + CW_META_OFFSET(m)) | ENTRY_LEAF); \
        }                                                                              \
        child += internal ? CW_NODE_WORDS : 0u;                                        \
    } while (0)
        SLOT(0);
        SLOT(1);
        SLOT(2);
        SLOT(3);
        SLOT(4);
        SLOT(5);
        SLOT(6);
        SLOT(7);
#undef SLOT
    }
}
