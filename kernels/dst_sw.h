/* DST*: the dual-split tree decoded in software (crates/accel/src/dst/traverse.rs),
 * included by render.c. The header-offset word is decoded with shifts and masks; plane
 * distances are (p - o[a]) * inv[a], exit-role distances widened by EXIT_WIDEN; every
 * comparison that can cull is written !(a > b), so a NaN distance (a ray lying in a plane)
 * never drops a child. */
#include "dst_common.h"

static inline float plane_t(const struct RayPre *r, uint32_t a, float p)
{
    return (p - r->org[a]) * r->inv[a];
}

static inline float exit_t(const struct RayPre *r, uint32_t a, float p)
{
    return plane_t(r, a, p) * EXIT_WIDEN;
}

static int traverse(const struct Ray *ray, const struct RayPre *r, int any, struct Hit *best)
{
    DST_TRAVERSE_BEGIN(ray, r);
    for (;;) {
        const struct DstNode *n = (const struct DstNode *)WORD_ADDR(node);
        uint32_t w = n->word;
        uint32_t offset = w & DST_OFFSET_MASK;
        int leaf = (w & DST_BIT_L) != 0;
        /* run: the node ends in the triangle run at `offset`; otherwise it pops. */
        int run = 0;
        if (!(w & DST_BIT_C)) {
            if (leaf) {
                /* plain leaf */
                run = 1;
            } else {
                /* splitting node: t1 where the ray leaves the near child's half-space
                 * (exit role, widened), t2 where it enters the far one */
                uint32_t a = DST_FIELD_A(w);
                uint32_t left = offset;
                uint32_t right = left + DST_FIELD_B(w);
                uint32_t near, far;
                float t1, t2;
                if (r->neg[a]) {
                    near = right;
                    far = left;
                    t1 = exit_t(r, a, n->p1);
                    t2 = plane_t(r, a, n->p0);
                } else {
                    near = left;
                    far = right;
                    t1 = exit_t(r, a, n->p0);
                    t2 = plane_t(r, a, n->p1);
                }
                int near_hit = !(t_min > t1);
                int far_hit = !(t2 > t_max);
                if (far_hit) {
                    if (near_hit) {
                        if (sp == STACK_SIZE)
                            kernel_fault(); /* deeper than any tree the converter makes */
                        stack[sp].node = far;
                        stack[sp].t_min = f_max(t_min, t2);
                        stack[sp].t_max = t_max;
                        sp++;
                    } else {
                        node = far;
                        t_min = f_max(t_min, t2);
                        continue;
                    }
                }
                if (near_hit) {
                    node = near;
                    t_max = f_min(t_max, t1);
                    continue;
                }
            }
        } else {
            /* carving node: exit planes clamp t_max, entry planes raise t_min */
            float lo, hi;
            if (DST_FIELD_A(w) == DST_A_SINGLE) {
                uint32_t a = DST_FIELD_B(w);
                float t1, t2;
                if (r->neg[a]) {
                    t1 = exit_t(r, a, n->p1);
                    t2 = plane_t(r, a, n->p0);
                } else {
                    t1 = exit_t(r, a, n->p0);
                    t2 = plane_t(r, a, n->p1);
                }
                lo = f_max(t_min, t2);
                hi = f_min(t_max, t1);
            } else {
                /* dual-axis: pair A = 00 xy, 01 xz, 11 yz -> (A >> 1, (A & 1) + 1); a plane
                 * is an exit iff its "lower bound" bit equals the ray's sign on its axis */
                uint32_t pair = DST_FIELD_A(w);
                uint32_t a0 = pair >> 1, a1 = (pair & 1u) + 1u;
                uint32_t corner = DST_FIELD_B(w);
                int first_lower = (corner & 2u) != 0, second_lower = (corner & 1u) != 0;
                float ta = plane_t(r, a0, n->p0), tb = plane_t(r, a1, n->p1);
                lo = t_min;
                hi = t_max;
                if (r->neg[a0] == first_lower)
                    hi = f_min(hi, ta * EXIT_WIDEN);
                else
                    lo = f_max(lo, ta);
                if (r->neg[a1] == second_lower)
                    hi = f_min(hi, tb * EXIT_WIDEN);
                else
                    lo = f_max(lo, tb);
            }
            if (!(lo > hi)) {
                t_min = lo;
                t_max = hi;
                if (!leaf) {
                    node = offset;
                    continue;
                }
                run = 1;
            }
        }
        if (run && test_run(offset, ray->t_min, any, &have, best, &best_t))
            return 1;
        DST_POP_OR_RETURN();
    }
}
