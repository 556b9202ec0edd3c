/* What both wide-BVH traversals share (bvh.h: BVH2/4/8; cwbvh.h: the compressed BVH8;
 * crates/accel/src/wide/traverse.rs): the stack of (entry distance, word) entries, the start
 * of each iteration (the nearest hit child, else the next stacked entry that can still hold
 * a closer hit), the leaf's triangle run and the ordering of a node's hit children.
 * Macros, so that both loops compile exactly as if written out. */

/* Entries of the traversal stack: the entry distance and the word of the child (a node, or
 * for a leaf the word in ENTRY_LEAF's bits below: bvh.h its leaf word, cwbvh.h its run). */
struct Entry {
    float t;
    uint32_t word;
};

#define ENTRY_LEAF 0x80000000u
#define STACK_SIZE 256
_Static_assert(STACK_SIZE * sizeof(struct Entry) <= LOCAL_STORE_BYTES * 5 / 8,
               "the traversal stack leaves room for the renderer's frames");

/* The start of `traverse` (return type int, parameters `ray`, `any`, `best`): the stack, the
 * best hit so far, the cull limit, and the current entry `cur`, the root. */
#define BVH_TRAVERSE_BEGIN(ray)                                                        \
    struct Entry stack[STACK_SIZE];                                                    \
    int sp = 0;                                                                        \
    int have = 0;                                                                      \
    float best_t = (ray)->t_max;                                                       \
    float limit = cull_limit(best_t);                                                  \
    const float t_min = (ray)->t_min;                                                  \
    /* The current entry: the root node. */                                            \
    int have_cur = 1;                                                                  \
    struct Entry cur = {t_min, PARAMS->root}

/* The entry to visit in `e`: `cur` when a child was kept there, else the next stacked entry
 * not beyond the cull limit; returns `have` from `traverse` when the stack runs out. */
#define BVH_NEXT_ENTRY(e)                                                              \
    do {                                                                               \
        if (have_cur) {                                                                \
            e = cur;                                                                   \
            have_cur = 0;                                                              \
        } else {                                                                       \
            for (;;) {                                                                 \
                if (sp == 0)                                                           \
                    return have;                                                       \
                e = stack[--sp];                                                       \
                if (e.t <= limit)                                                      \
                    break;                                                             \
            }                                                                          \
        }                                                                              \
    } while (0)

/* Tests the triangle run at word `run` on [t_min, best_t], keeping the closest by (t, id);
 * an any-hit traversal returns 1 at its first hit. */
#define BVH_TEST_RUN(run)                                                              \
    do {                                                                               \
        for (const uint32_t *idx = WORD_ADDR(run);; idx++) {                           \
            uint32_t entry = *idx;                                                     \
            uint32_t prim = entry & ~LAST_IN_RUN;                                      \
            float t = RT_TRI(triangle(prim), t_min, best_t);                           \
            if (t == t && (!have || !closer_than(best, t, prim))) {                    \
                best->t = t;                                                           \
                best->prim = prim;                                                     \
                have = 1;                                                              \
                if (any)                                                               \
                    return 1;                                                          \
                best_t = t;                                                            \
                limit = cull_limit(best_t);                                            \
            }                                                                          \
            if (entry & LAST_IN_RUN)                                                   \
                break;                                                                 \
        }                                                                              \
    } while (0)

/* A hit child, entry distance `entry`, word `word`, joins the traversal order: the nearest
 * in `cur`, the others on the stack above `base`, nearest on top (ties in slot order). */
#define BVH_ORDER(entry, word)                                                         \
    do {                                                                               \
        struct Entry c = {entry, word};                                                \
        if (!have_cur) {                                                               \
            cur = c;                                                                   \
            have_cur = 1;                                                              \
        } else if (entry < cur.t) {                                                    \
            /* A later slot is nearer only when strictly nearer. */                    \
            stack[sp++] = cur;                                                         \
            cur = c;                                                                   \
        } else {                                                                       \
            /* Below the stacked entries that are nearer or equally near. */           \
            int j = sp++;                                                              \
            while (j > base && stack[j - 1].t <= entry) {                              \
                stack[j] = stack[j - 1];                                               \
                j--;                                                                   \
            }                                                                          \
            stack[j] = c;                                                              \
        }                                                                              \
    } while (0)
