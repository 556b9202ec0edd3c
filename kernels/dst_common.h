/* What the DST traversals share (crates/accel/src/dst/traverse.rs, `Tracer`): the clip to
 * the scene box, the triangle runs, the stack, the loop's start and the pop rule. Included
 * by dst_sw.h, dst.h and dstq.h. Each stack entry carries its node and its interval
 * [t_min, t_max]. */

struct Entry {
    uint32_t node;
    float t_min;
    float t_max;
};

#define STACK_SIZE 192
_Static_assert(STACK_SIZE * sizeof(struct Entry) <= LOCAL_STORE_BYTES * 5 / 8,
               "the traversal stack leaves room for the renderer's frames");

#if !KERNEL_PARITY
/* RayPre::slab of the scene box on [t_lo, t_hi]: the clipped interval, non-empty when the
 * ray meets the box. Near and far planes by the ray's signs; far planes widened; NaN plane
 * distances ignored (f_max/f_min return the other operand). */
static void scene_slab(const struct RayPre *r, float t_lo, float t_hi, float *entry,
                       float *exit)
{
    const struct Params *P = PARAMS;
    float lo = t_lo, hi = t_hi;
    for (int a = 0; a < 3; a++) {
        float near = r->neg[a] ? P->scene_max[a] : P->scene_min[a];
        lo = f_max(lo, (near - r->org[a]) * r->inv[a]);
    }
    for (int a = 0; a < 3; a++) {
        float far = r->neg[a] ? P->scene_min[a] : P->scene_max[a];
        hi = f_min(hi, (far - r->org[a]) * r->inv[a] * EXIT_WIDEN);
    }
    *entry = lo;
    *exit = hi;
}
#endif

/* The start of both traversals: the ray's interval clipped to the scene box in *t_min,
 * *t_max; 0 when the tree is empty or the ray misses the box (nothing to traverse). With
 * KERNEL_PARITY the ray-box pipeline clips (one rt.box on the scene box, whose 6 words
 * scene_min, scene_max follow each other in the parameter block; rt_boxexit, rt.boxget 8,
 * reads the exit distance), else the slab test runs in software. */
static inline int dst_clip(const struct Ray *ray, const struct RayPre *r, float *t_min,
                           float *t_max)
{
    const struct Params *P = PARAMS;
    if (P->nodes_end == P->nodes_start)
        return 0;
#if KERNEL_PARITY
    (void)r;
    float entry = RT_BOX(P->scene_min, ray->t_min, cull_limit(ray->t_max));
    if (entry != entry)
        return 0;
    *t_min = entry;
    *t_max = rt_boxexit();
    return 1;
#else
    scene_slab(r, ray->t_min, cull_limit(ray->t_max), t_min, t_max);
    return !(*t_min > *t_max);
#endif
}

/* Intersects the triangle run starting at index entry `first` on [ray.t_min, best_t];
 * returns 1 when an any-hit traversal is done. */
static inline int test_run(uint32_t first, float t_lo, int any, int *have, struct Hit *best,
                           float *best_t)
{
    for (const uint32_t *idx = WORD_ADDR(PARAMS->indices_start + first);; idx++) {
        uint32_t entry = *idx;
        uint32_t prim = entry & ~LAST_IN_RUN;
        float t = RT_TRI(triangle(prim), t_lo, *best_t);
        if (t == t) {
            if (any) {
                best->t = t;
                best->prim = prim;
                *have = 1;
                return 1;
            }
            if (!*have || !closer_than(best, t, prim)) {
                best->t = t;
                best->prim = prim;
                *have = 1;
                *best_t = t;
            }
        }
        if (entry & LAST_IN_RUN)
            return 0;
    }
}

/* The start of both traversals' `traverse` (return type int, parameters `ray` and `r`):
 * returns 0 when there is nothing to traverse (dst_clip), else declares the loop's state:
 * the current node (the root) and its interval t_min, t_max; the stack `stack` with `sp`
 * entries; whether a hit was found (`have`) and the best hit's t (`best_t`, starting at the
 * ray's t_max). A macro, so that both loops compile exactly as if written out. */
#define DST_TRAVERSE_BEGIN(ray, r)                                                        \
    float t_min, t_max;                                                                   \
    if (!dst_clip((ray), (r), &t_min, &t_max))                                            \
        return 0;                                                                         \
    struct Entry stack[STACK_SIZE];                                                       \
    int sp = 0;                                                                           \
    int have = 0;                                                                         \
    float best_t = (ray)->t_max;                                                          \
    uint32_t node = PARAMS->root

/* The end of a node that continues nowhere: pops the next entry that can still hold a
 * closer hit (t_min not beyond cull_limit(best_t)) into node, t_min and t_max, clamping its
 * t_max; returns `have` from `traverse` when the stack runs out. Uses the state declared by
 * DST_TRAVERSE_BEGIN. */
#define DST_POP_OR_RETURN()                                                               \
    do {                                                                                  \
        float limit = cull_limit(best_t);                                                 \
        for (;;) {                                                                        \
            if (sp == 0)                                                                  \
                return have;                                                              \
            struct Entry e = stack[--sp];                                                 \
            if (!(e.t_min > limit)) {                                                     \
                node = e.node;                                                            \
                t_min = e.t_min;                                                          \
                t_max = f_min(e.t_max, limit);                                            \
                break;                                                                    \
            }                                                                             \
        }                                                                                 \
    } while (0)

/* The return codes of the dual-split pipeline (rt.dst, rt.dstqp). */
#define CODE_MISS 0u
#define CODE_ONE_CHILD 1u
#define CODE_BOTH_CHILDREN 2u
#define CODE_LEAF 3u

/* What a pipeline traversal (dst.h, dstq.h) does with a step's `code` and `next` (the next
 * node, or the run's index entry), the rest read from the DST latch: continue at one child,
 * push the far child and continue at the near one, or test the run; then pop. Uses the
 * state declared by DST_TRAVERSE_BEGIN; `continue`s the traversal's loop. */
#define DST_FOLLOW(code, next)                                                            \
    if ((code) == CODE_ONE_CHILD) {                                                       \
        node = (next);                                                                    \
        t_min = rt_dst_tmin();                                                            \
        t_max = rt_dst_tmax();                                                            \
        continue;                                                                         \
    }                                                                                     \
    if ((code) == CODE_BOTH_CHILDREN) {                                                   \
        if (sp == STACK_SIZE)                                                             \
            kernel_fault(); /* deeper than any tree the converter makes */                \
        stack[sp].node = rt_dst_offset_stack();                                           \
        stack[sp].t_min = rt_dst_tmin();                                                  \
        stack[sp].t_max = t_max;                                                          \
        sp++;                                                                             \
        node = (next);                                                                    \
        t_max = rt_dst_tmax();                                                            \
        continue;                                                                         \
    }                                                                                     \
    if ((code) == CODE_LEAF && test_run((next), ray->t_min, any, &have, best, &best_t))   \
        return 1;                                                                         \
    DST_POP_OR_RETURN()
