/* BVH2/4/8 traversal (crates/accel/src/wide/traverse.rs), included by render.c.
 *
 * BVH_ARITY = 2, 4 or 8. BVH_WIDE_BOX = 0: each child box is tested with its own rt.box
 * (one ray-box pipeline per TM); 1: the "+" configurations, one rt.boxn tests all of a
 * node's boxes and rt.boxget reads the entries.
 *
 * Per internal node: slab-test every non-empty child box against [t_min, cull_limit(best)],
 * continue with the nearest hit child and push the others far-first (ties in slot order);
 * a popped entry beyond cull_limit(best) is dropped. Per leaf: read the leaf word, then test
 * the triangles of its index run on [t_min, best_t], keeping the closest by (t, id). */

#if BVH_ARITY == 2
typedef struct Node2 Node;
#define NODE_WORDS 13u
#elif BVH_ARITY == 4
typedef struct Node4 Node;
#define NODE_WORDS 25u
#elif BVH_ARITY == 8
typedef struct Node8 Node;
#define NODE_WORDS 50u
#else
#error "BVH_ARITY must be 2, 4 or 8"
#endif

#include "bvh_common.h"

static inline uint32_t node_offset(const Node *n)
{
#if BVH_ARITY == 2
    return n->packed & NODE2_OFFSET_MASK;
#elif BVH_ARITY == 4
    return n->packed & NODE4_OFFSET_MASK;
#else
    return n->offset;
#endif
}

#if BVH_ARITY != 8
/* The kind the packed word gives slot k of a BVH2/4 node: leaf or internal (an empty slot
 * reads as internal). */
static inline int packed_kind(const Node *n, int k)
{
#if BVH_ARITY == 2
    uint32_t bit = 31 - k;
#else
    uint32_t bit = 28 + k;
#endif
    return (n->packed >> bit) & 1u ? CHILD_LEAF : CHILD_INTERNAL;
}
#endif

/* The kind of slot k: empty (degenerate box, min.x > max.x), leaf or internal. */
static inline int child_kind(const Node *n, int k)
{
#if BVH_ARITY == 8
    uint32_t t = (n->types >> (2 * k)) & 3u;
    return t == NODE8_INTERNAL ? CHILD_INTERNAL : t == NODE8_LEAF ? CHILD_LEAF : CHILD_EMPTY;
#else
    if (n->box[k].lo[0] > n->box[k].hi[0])
        return CHILD_EMPTY;
    return packed_kind(n, k);
#endif
}

#if KERNEL_PARITY
/* The kind of slot k without looking at its box: the box test decides whether the slot is
 * hit (an empty slot's degenerate box misses). In BVH2/4 an empty slot reads as internal
 * here; empty slots follow the children (the builders fill slots 0..n), so no child lies
 * after one and the size taken for it never moves a child's address. */
static inline int child_kind_no_box(const Node *n, int k)
{
#if BVH_ARITY == 8
    return child_kind(n, k);
#else
    return packed_kind(n, k);
#endif
}
#endif

#if KERNEL_PARITY && KERNEL_SORT_ALL
/* kernels.child_order = "all-slots" (a reading of §4.4's "additional operations for child
 * node ordering", not a source): every slot's entry distance, a miss as +inf, is sorted by a
 * sorting network keyed on (entry, slot), which gives the insertion order of BVH_ORDER
 * (nearest first, ties in slot order) at a fixed cost per node. */
struct Slot {
    float t;
    uint32_t word;
    uint32_t slot;
};

#define SORT_CE(s, a, b)                                                               \
    do {                                                                               \
        if (s[b].t < s[a].t || (s[b].t == s[a].t && s[b].slot < s[a].slot)) {          \
            struct Slot x_ = s[a];                                                     \
            s[a] = s[b];                                                               \
            s[b] = x_;                                                                 \
        }                                                                              \
    } while (0)

/* Optimal networks: 1, 5 and 19 compare-exchanges (Knuth, TAOCP vol. 3, §5.3.4). */
#if BVH_ARITY == 2
#define SORT_SLOTS(s) SORT_CE(s, 0, 1)
#elif BVH_ARITY == 4
#define SORT_SLOTS(s)                                                                  \
    do {                                                                               \
        SORT_CE(s, 0, 1);                                                              \
        SORT_CE(s, 2, 3);                                                              \
        SORT_CE(s, 0, 2);                                                              \
        SORT_CE(s, 1, 3);                                                              \
        SORT_CE(s, 1, 2);                                                              \
    } while (0)
#else
#define SORT_SLOTS(s)                                                                  \
    do {                                                                               \
        SORT_CE(s, 0, 2);                                                              \
        SORT_CE(s, 1, 3);                                                              \
        SORT_CE(s, 4, 6);                                                              \
        SORT_CE(s, 5, 7);                                                              \
        SORT_CE(s, 0, 4);                                                              \
        SORT_CE(s, 1, 5);                                                              \
        SORT_CE(s, 2, 6);                                                              \
        SORT_CE(s, 3, 7);                                                              \
        SORT_CE(s, 0, 1);                                                              \
        SORT_CE(s, 2, 3);                                                              \
        SORT_CE(s, 4, 5);                                                              \
        SORT_CE(s, 6, 7);                                                              \
        SORT_CE(s, 2, 4);                                                              \
        SORT_CE(s, 3, 5);                                                              \
        SORT_CE(s, 1, 4);                                                              \
        SORT_CE(s, 3, 6);                                                              \
        SORT_CE(s, 1, 2);                                                              \
        SORT_CE(s, 3, 4);                                                              \
        SORT_CE(s, 5, 6);                                                              \
    } while (0)
#endif
#endif

static int traverse(const struct Ray *ray, const struct RayPre *pre, int any, struct Hit *best)
{
    (void)pre;
    BVH_TRAVERSE_BEGIN(ray);
    for (;;) {
        struct Entry e;
        BVH_NEXT_ENTRY(e);
        if (e.word & ENTRY_LEAF) {
            uint32_t run = *WORD_ADDR(e.word & ~ENTRY_LEAF);
            BVH_TEST_RUN(run);
            continue;
        }
        const Node *node = (const Node *)WORD_ADDR(e.word);
        /* The hit children: the nearest in `cur`, the others on the stack above `base`,
         * nearest on top; ordered by entry distance, ties in slot order. */
        if (sp > STACK_SIZE - BVH_ARITY)
            kernel_fault(); /* deeper than any tree the builder makes */
        int base = sp;
        (void)base; /* BVH_ORDER's; the all-slots order pushes without it */
        uint32_t addr = node_offset(node);
#if BVH_WIDE_BOX
        uint32_t mask = RT_BOXN(BVH_ARITY, node->box, t_min, limit);
#endif
#if BVH_WIDE_BOX
#define BOX_ENTRY(k) ((mask >> (k)) & 1u ? rt_boxget(k) : __builtin_nanf(""))
#else
#define BOX_ENTRY(k) RT_BOX(&node->box[k], t_min, limit)
#endif
/* A hit child (entry distance `entry`, slot kind `kind`, first word `addr`) joins the
 * traversal order (BVH_ORDER). */
#define ORDER_HIT(entry, kind) BVH_ORDER(entry, kind == CHILD_LEAF ? addr | ENTRY_LEAF : addr)
#if KERNEL_PARITY && KERNEL_SORT_ALL
        /* Every slot's box is tested (as below) and its entry noted for the sort. */
        struct Slot slots[BVH_ARITY];
#define CHILD(k)                                                                       \
    do {                                                                               \
        int kind = child_kind_no_box(node, k);                                         \
        float entry = BOX_ENTRY(k);                                                    \
        slots[k].t = entry == entry ? entry : __builtin_inff();                        \
        slots[k].word = kind == CHILD_LEAF ? addr | ENTRY_LEAF : addr;                 \
        slots[k].slot = k;                                                             \
        addr += kind == CHILD_INTERNAL ? NODE_WORDS : kind == CHILD_LEAF ? 1u : 0u;    \
    } while (0)
#elif KERNEL_PARITY
/* Every slot's box is tested, empty slots included ("ray-box intersection tests are executed
 * serially for each box in a BVH node", Lin et al. 2020, §4), and the hits are ordered
 * ("additional operations for child node ordering", §4.4). */
#define CHILD(k)                                                                       \
    do {                                                                               \
        int kind = child_kind_no_box(node, k);                                         \
        float entry = BOX_ENTRY(k);                                                    \
        if (entry == entry) {                                                          \
            ORDER_HIT(entry, kind);                                                    \
        }                                                                              \
        addr += kind == CHILD_INTERNAL ? NODE_WORDS : kind == CHILD_LEAF ? 1u : 0u;    \
    } while (0)
#else
#define CHILD(k)                                                                       \
    do {                                                                               \
        int kind = child_kind(node, k);                                                \
        if (kind != CHILD_EMPTY) {                                                     \
            float entry = BOX_ENTRY(k);                                                \
            if (entry == entry) {                                                      \
                ORDER_HIT(entry, kind);                                                \
            }                                                                          \
        }                                                                              \
        addr += kind == CHILD_INTERNAL ? NODE_WORDS : kind == CHILD_LEAF ? 1u : 0u;    \
    } while (0)
#endif
        CHILD(0);
        CHILD(1);
#if BVH_ARITY >= 4
        CHILD(2);
        CHILD(3);
#endif
#if BVH_ARITY == 8
        CHILD(4);
        CHILD(5);
        CHILD(6);
        CHILD(7);
#endif
#undef CHILD
#undef BOX_ENTRY
#if KERNEL_PARITY && KERNEL_SORT_ALL
        SORT_SLOTS(slots);
        /* The hits (misses sorted last): the nearest to `cur`, the others pushed
         * far-first, as BVH_ORDER leaves them. */
        if (slots[0].t != __builtin_inff()) {
            for (int i = BVH_ARITY - 1; i > 0; i--) {
                if (slots[i].t != __builtin_inff()) {
                    struct Entry c = {slots[i].t, slots[i].word};
                    stack[sp++] = c;
                }
            }
            struct Entry c = {slots[0].t, slots[0].word};
            cur = c;
            have_cur = 1;
        }
#endif
    }
}
