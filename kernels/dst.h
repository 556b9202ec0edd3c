/* DST: the dual-split tree traversed with the rt.dst instruction (the pipeline of Lin et al.
 * 2020, Fig. 6; crates/accel/src/dst/pipeline.rs, `traverse_pipeline`), included by
 * render.c. The instruction decodes the node and returns the 2-bit code and the next offset;
 * the loop keeps the stack and tests the triangle runs. */
#include "dst_common.h"

static int traverse(const struct Ray *ray, const struct RayPre *r, int any, struct Hit *best)
{
    DST_TRAVERSE_BEGIN(ray, r);
    for (;;) {
        uint32_t out = RT_DST(WORD_ADDR(node), t_min, t_max);
        uint32_t code = out & 3u;
        uint32_t offset = out >> 2;
        DST_FOLLOW(code, offset);
    }
}
