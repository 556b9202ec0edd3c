/* CWBVH and CWBVH+: the compressed 8-wide BVH (crates/accel/src/cwbvh/traverse.rs), included
 * by render.c. One rt.qboxn per node dequantizes and tests its 8 child boxes (CWBVH+: on 8
 * quantized ray-box pipelines in one issue; CWBVH: the same instruction on one pipeline, the
 * tests one after another); the hits of occupied slots are ordered as bvh.h orders them.
 *
 * Per internal node: continue with the nearest hit child and push the others far-first
 * (ties in slot order); a popped entry beyond cull_limit(best) is dropped. A leaf child's
 * run starts at the node's triangle base plus its meta offset (no leaf word); its triangles
 * are tested on [t_min, best_t], keeping the closest by (t, id). */

/* Entries of the traversal stack: the entry distance and the word of the child (its node,
 * or for a leaf its run, with bit 31 set). */
struct Entry {
    float t;
    uint32_t word;
};

#define ENTRY_LEAF 0x80000000u
#define STACK_SIZE 256
_Static_assert(STACK_SIZE * sizeof(struct Entry) <= LOCAL_STORE_BYTES * 5 / 8,
               "the traversal stack leaves room for the renderer's frames");

static int traverse(const struct Ray *ray, const struct RayPre *pre, int any, struct Hit *best)
{
    (void)pre;
    struct Entry stack[STACK_SIZE];
    int sp = 0;
    int have = 0;
    float best_t = ray->t_max;
    float limit = cull_limit(best_t);
    const float t_min = ray->t_min;
    int have_cur = 1;
    struct Entry cur = {t_min, PARAMS->root};
    for (;;) {
        struct Entry e;
        if (have_cur) {
            e = cur;
            have_cur = 0;
        } else {
            for (;;) {
                if (sp == 0)
                    return have;
                e = stack[--sp];
                if (e.t <= limit)
                    break;
            }
        }
        if (e.word & ENTRY_LEAF) {
            for (const uint32_t *idx = WORD_ADDR(e.word & ~ENTRY_LEAF);; idx++) {
                uint32_t entry = *idx;
                uint32_t prim = entry & ~LAST_IN_RUN;
                float t = RT_TRI(triangle(prim), t_min, best_t);
                if (t == t && (!have || !closer_than(best, t, prim))) {
                    best->t = t;
                    best->prim = prim;
                    have = 1;
                    if (any)
                        return 1;
                    best_t = t;
                    limit = cull_limit(best_t);
                }
                if (entry & LAST_IN_RUN)
                    break;
            }
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
/* Slot k: an occupied slot whose box was hit joins the order (the nearest in `cur`, the
 * others on the stack, nearest on top); an internal slot advances the child word. The hit
 * bit of an empty slot is ignored (its decoded box is empty, but a NaN plane would let it
 * through). */
#define SLOT(k)                                                                        \
    do {                                                                               \
        uint32_t m = node->meta[k];                                                    \
        int internal = (imask >> (k)) & 1u;                                            \
        if (m != 0 && ((mask >> (k)) & 1u)) {                                          \
            float entry = rt_boxget(k);                                                \
            struct Entry c = {entry, internal ? child                                  \
                                              : (tri_base + CW_META_OFFSET(m)) | ENTRY_LEAF}; \
            if (!have_cur) {                                                           \
                cur = c;                                                               \
                have_cur = 1;                                                          \
            } else if (entry < cur.t) {                                                \
                stack[sp++] = cur;                                                     \
                cur = c;                                                               \
            } else {                                                                   \
                int j = sp++;                                                          \
                while (j > base && stack[j - 1].t <= entry) {                          \
                    stack[j] = stack[j - 1];                                           \
                    j--;                                                               \
                }                                                                      \
                stack[j] = c;                                                          \
            }                                                                          \
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
