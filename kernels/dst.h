/* DST: the dual-split tree traversed with the rt.dst instruction (the pipeline of Lin et al.
 * 2020, Fig. 6; crates/accel/src/dst/pipeline.rs, `traverse_pipeline`), included by
 * render.c. The instruction decodes the node and returns the 2-bit code and the next offset;
 * the loop keeps the stack and tests the triangle runs. */
#include "dst_common.h"

#define CODE_MISS 0u
#define CODE_ONE_CHILD 1u
#define CODE_BOTH_CHILDREN 2u
#define CODE_LEAF 3u

static int traverse(const struct Ray *ray, const struct RayPre *r, int any, struct Hit *best)
{
    DST_TRAVERSE_BEGIN(ray, r);
    for (;;) {
        uint32_t out = RT_DST(WORD_ADDR(node), t_min, t_max);
        uint32_t code = out & 3u;
        uint32_t offset = out >> 2;
        if (code == CODE_ONE_CHILD) {
            node = offset;
            t_min = rt_dst_tmin();
            t_max = rt_dst_tmax();
            continue;
        }
        if (code == CODE_BOTH_CHILDREN) {
            if (sp == STACK_SIZE)
                kernel_fault(); /* deeper than any tree the converter makes */
            stack[sp].node = rt_dst_offset_stack();
            stack[sp].t_min = rt_dst_tmin();
            stack[sp].t_max = t_max;
            sp++;
            node = offset;
            t_max = rt_dst_tmax();
            continue;
        }
        if (code == CODE_LEAF && test_run(offset, ray->t_min, any, &have, best, &best_t))
            return 1;
        DST_POP_OR_RETURN();
    }
}
