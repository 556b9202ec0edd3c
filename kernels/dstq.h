/* DST-Q: the quantized dual-split tree traversed with rt.dstqp (the quantized dual-split
 * pipeline; crates/accel/src/dstq/unit.rs), included by render.c. The loop is dst.h's with
 * records named by one word, their cluster's word address << 9 | their bit position in the
 * cluster: when the traversal enters a cluster other than the one whose frame it holds, it
 * loads that cluster's 4 frame words into P[32..36]; per record it loads the 3 words from
 * the one holding the record's first bit into P[36..39] (above the words the triangle
 * test's loads use, so the frame stays across leaves); the instruction decodes the record,
 * dequantizes its planes and returns the next record's name (or the triangle run's index
 * entry), its code in the DST latch. DST-Q has only this load form (docs/isa.md), so the
 * PIPE_LOADS=0 variants build the same node loop (their triangle tests still follow
 * PIPE_LOADS). */
#include "dst_common.h"

static int traverse(const struct Ray *ray, const struct RayPre *r, int any, struct Hit *best)
{
    DST_TRAVERSE_BEGIN(ray, r);
    node = DSTQ_ROOT_BIT; /* the root cluster is at word 0 */
    uint32_t frame_cluster = ~0u;
    for (;;) {
        uint32_t cluster = node >> DSTQ_POS_BITS;
        if (cluster != frame_cluster) {
            const uint32_t *f = WORD_ADDR(cluster);
            rt_ldph(0, f);
            rt_ldph(1, f + 1);
            rt_ldph(2, f + 2);
            rt_ldph(3, f + 3);
            frame_cluster = cluster;
        }
        const uint32_t *w = WORD_ADDR(cluster + ((node & DSTQ_POS_MASK) >> 5));
        rt_ldph(4, w);
        rt_ldph(5, w + 1);
        rt_ldph(6, w + 2);
        uint32_t next = rt_dstqp(node, t_min, t_max);
        uint32_t code = rt_dst_code();
        DST_FOLLOW(code, next);
    }
}
