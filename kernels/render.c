/* The renderer of a simulated thread: the paper's two workloads (Lin et al. 2020, §4.3 ray
 * casting with a shadow ray, §4.4 path tracing with 5 diffuse bounces and a shadow ray at
 * every hit), the same camera, random numbers and shading as crates/render/src/job.rs, on one
 * of the traversals (bvh.h, dst_sw.h, dst.h, cwbvh.h, dstq.h).
 *
 * Build flags (Makefile):
 *   -DWORKLOAD_PATH=0|1         cast or path
 *   -DACCEL_BVH -DBVH_ARITY=N   BVH2/4/8 ... -DBVH_WIDE_BOX=1 for the "+" configurations
 *   -DACCEL_DST_SW              DST* (software decoder)
 *   -DACCEL_DST                 DST (the dual-split instruction)
 *   -DACCEL_CWBVH               CWBVH, CWBVH+ (the quantized wide box instruction)
 *   -DACCEL_DSTQ                DST-Q (the quantized dual-split instruction)
 *   -DKERNEL_PARITY=0|1         1: the traversals as the paper describes them (bvh.h: every
 *                               box slot tested; dst_common.h: the scene-box clip on rt.box)
 *   -DPIPE_LOADS=0|1            1: node words reach the pipelines through rt.ldp and the
 *                               register forms (rt.h), else through the memory operand
 *
 * A thread takes pixels from global register 0 until they run out. */
#ifndef KERNEL_PARITY
#define KERNEL_PARITY 0
#endif
#ifndef PIPE_LOADS
#define PIPE_LOADS 0
#endif

#include "dualsplit.h"
#include "fmath.h"
#include "rt.h"

#define PARAMS ((const struct Params *)PARAMS_ADDR)
#define WORD_ADDR(i) ((const uint32_t *)(uintptr_t)((i) * 4u))

/* A kernel bug or a tree deeper than the traversal stack: store to the read-only parameter
 * block (the simulator stops with a fault naming this pc), then end the thread. */
static inline void kernel_fault(void)
{
    *(volatile uint32_t *)PARAMS_ADDR = 0;
    __builtin_trap();
}

/* ---- vectors (glam's Vec3 arithmetic, operation for operation) -------------------------- */

struct Vec3 {
    float x, y, z;
};

static inline struct Vec3 v3(float x, float y, float z)
{
    struct Vec3 v = {x, y, z};
    return v;
}

static inline struct Vec3 v_load(const float *p)
{
    return v3(p[0], p[1], p[2]);
}

static inline struct Vec3 v_add(struct Vec3 a, struct Vec3 b)
{
    return v3(a.x + b.x, a.y + b.y, a.z + b.z);
}

static inline struct Vec3 v_sub(struct Vec3 a, struct Vec3 b)
{
    return v3(a.x - b.x, a.y - b.y, a.z - b.z);
}

static inline struct Vec3 v_scale(struct Vec3 a, float s)
{
    return v3(a.x * s, a.y * s, a.z * s);
}

static inline struct Vec3 v_neg(struct Vec3 a)
{
    return v3(-a.x, -a.y, -a.z);
}

static inline float v_dot(struct Vec3 a, struct Vec3 b)
{
    return a.x * b.x + a.y * b.y + a.z * b.z;
}

static inline struct Vec3 v_cross(struct Vec3 a, struct Vec3 b)
{
    return v3(a.y * b.z - b.y * a.z, a.z * b.x - b.z * a.x, a.x * b.y - b.x * a.y);
}

/* glam's normalize: self * (1 / length) */
static inline struct Vec3 v_normalize(struct Vec3 a)
{
    return v_scale(a, 1.0f / f_sqrt(v_dot(a, a)));
}

/* glam's normalize_or_zero: zero when 1 / length is not finite and positive */
static inline struct Vec3 v_normalize_or_zero(struct Vec3 a)
{
    float rcp = 1.0f / f_sqrt(v_dot(a, a));
    if (f_abs(rcp) < __builtin_inff() && rcp > 0.0f)
        return v_scale(a, rcp);
    return v3(0.0f, 0.0f, 0.0f);
}

static inline int v_is_zero(struct Vec3 a)
{
    return a.x == 0.0f && a.y == 0.0f && a.z == 0.0f;
}

/* ---- rays ------------------------------------------------------------------------------- */

struct Ray {
    struct Vec3 org;
    struct Vec3 dir;
    float t_min;
    float t_max;
};

/* What the software parts of a traversal need of the ray (dualsplit_geometry::RayPre). */
struct RayPre {
    float org[3];
    float inv[3];
    int neg[3];
};

struct Hit {
    float t;
    uint32_t prim;
};

/* cull_limit (crates/geometry/src/hit.rs): best_t widened by a relative 2^-12. */
static inline float cull_limit(float best_t)
{
    return best_t + f_abs(best_t) * (1.0f / 4096.0f) + 0x1p-126f;
}

/* Hit::closer_than: smaller t wins, equal t goes to the smaller triangle id. */
static inline int closer_than(const struct Hit *h, float t, uint32_t prim)
{
    return h->t < t || (h->t == t && h->prim < prim);
}

/* The triangle of id `prim` in the image. */
static inline const float *triangle(uint32_t prim)
{
    return (const float *)WORD_ADDR(PARAMS->triangles_start + 9u * prim);
}

/* RayPre::new: 1/dir, the direction signs and the watertight test's axes and shear; loads
 * the ray registers. */
static void set_ray(const struct Ray *ray, struct RayPre *pre)
{
    float d[3] = {ray->dir.x, ray->dir.y, ray->dir.z};
    for (int a = 0; a < 3; a++) {
        pre->org[a] = a == 0 ? ray->org.x : a == 1 ? ray->org.y : ray->org.z;
        pre->inv[a] = rt_rcp(d[a]);
        pre->neg[a] = __builtin_signbitf(d[a]) != 0;
    }
    float ax = f_abs(d[0]), ay = f_abs(d[1]), az = f_abs(d[2]);
    uint32_t kz;
    if (ax >= ay && ax >= az)
        kz = 0;
    else if (ay >= az)
        kz = 1;
    else
        kz = 2;
    uint32_t kx = kz == 2 ? 0 : kz + 1;
    uint32_t ky = kx == 2 ? 0 : kx + 1;
    if (d[kz] < 0.0f) {
        uint32_t t = kx;
        kx = ky;
        ky = t;
    }
    rt_setorg(pre->org[0], pre->org[1], pre->org[2]);
    rt_setinv(pre->inv[0], pre->inv[1], pre->inv[2]);
    rt_setshear(d[kx] / d[kz], d[ky] / d[kz], 1.0f / d[kz]);
    rt_setk(kx | ky << 2 | kz << 4);
}

/* ---- traversal -------------------------------------------------------------------------- */

#if defined(ACCEL_BVH)
#include "bvh.h"
#elif defined(ACCEL_DST_SW)
#include "dst_sw.h"
#elif defined(ACCEL_DST)
#include "dst.h"
#elif defined(ACCEL_CWBVH)
#include "cwbvh.h"
#elif defined(ACCEL_DSTQ)
#include "dstq.h"
#else
#error "choose a traversal: -DACCEL_BVH, -DACCEL_DST_SW, -DACCEL_DST, -DACCEL_CWBVH or -DACCEL_DSTQ"
#endif

/* Closest hit of `ray`: 1 and the hit, or 0. */
static int closest_hit(const struct Ray *ray, struct Hit *hit)
{
    struct RayPre pre;
    set_ray(ray, &pre);
    return traverse(ray, &pre, 0, hit);
}

/* True when anything blocks the segment [t_min, t_max] of `ray`. */
static int any_hit(const struct Ray *ray)
{
    struct RayPre pre;
    struct Hit hit;
    set_ray(ray, &pre);
    return traverse(ray, &pre, 1, &hit);
}

/* ---- shading (crates/render/src/job.rs) -------------------------------------------------- */

#define ALBEDO 0.7f
#define SKY 0.25f
#define AMBIENT 0.04f
#define PI_F 3.14159265358979323846264338327950288f
#define TAU_F 6.28318530717958647692528676655900577f

/* The renderer's random number of dimension dim at `bounce` of the current sample
 * (crates/render/src/job.rs `rand`): rt.rand's unit computes it from the key rt.srand set
 * for the sample (docs/isa.md). */
#define RAND(bounce, dim) rt_rand(dim, (uint32_t)(bounce), P->seed)

/* One pixel: every sample's path, the radiance averaged over the samples. */
static float render_pixel(const struct Params *P, uint32_t x, uint32_t y)
{
    float w = (float)P->width, h = (float)P->height, k = P->tan_half_fov;
    struct Vec3 fwd = v_load(P->fwd), right = v_load(P->right), up = v_load(P->up);
    struct Vec3 light_pos = v_load(P->light_pos);
    float radiance = 0.0f;
    uint32_t sample;
    for (sample = 0; sample < P->spp; sample++) {
        float jx = 0.5f, jy = 0.5f;
        rt_srand(x, y, sample);
        if (P->spp > 1) {
            jx = RAND(0, 0);
            jy = RAND(0, 1);
        }
        float sx = (2.0f * ((float)x + jx) / w - 1.0f) * (w / h);
        float sy = 1.0f - 2.0f * ((float)y + jy) / h;
        struct Ray ray;
        ray.org = v_load(P->eye);
        ray.dir = v_normalize(v_add(v_add(fwd, v_scale(right, sx * k)), v_scale(up, sy * k)));
        ray.t_min = 0.0f;
        ray.t_max = __builtin_inff();
        float throughput = 1.0f;
        for (uint32_t depth = 0;; depth++) {
            struct Hit hit;
            if (!closest_hit(&ray, &hit)) {
                radiance += throughput * SKY;
                break;
            }
            /* The ray-facing geometric normal and the offset hit point. */
            const float *tri = triangle(hit.prim);
            struct Vec3 v0 = v_load(tri), v1 = v_load(tri + 3), v2 = v_load(tri + 6);
            struct Vec3 n = v_normalize_or_zero(v_cross(v_sub(v1, v0), v_sub(v2, v0)));
            if (v_is_zero(n))
                n = v_neg(v_normalize_or_zero(ray.dir));
            if (v_dot(n, ray.dir) > 0.0f)
                n = v_neg(n);
            struct Vec3 p = v_add(v_add(ray.org, v_scale(ray.dir, hit.t)), v_scale(n, P->eps));
            if (!WORKLOAD_PATH)
                radiance += throughput * AMBIENT * ALBEDO;
            /* Next-event estimation toward a point sampled uniformly on the light sphere. */
            float u1 = RAND(2 * depth + 1, 0);
            float u2 = RAND(2 * depth + 1, 1);
            float z = 1.0f - 2.0f * u1;
            float r = f_sqrt(f_max(1.0f - z * z, 0.0f));
            float sphi, cphi;
            f_sincos(TAU_F * u2, &sphi, &cphi);
            struct Vec3 lp = v_add(light_pos, v_scale(v3(r * cphi, r * sphi, z), P->light_radius));
            struct Vec3 to_l = v_sub(lp, p);
            float d2 = v_dot(to_l, to_l);
            float cosl = d2 > 0.0f ? v_dot(n, to_l) / f_sqrt(d2) : 0.0f;
            if (cosl > 0.0f) {
                float contrib = throughput * ALBEDO / PI_F * P->light_power * cosl / d2;
                struct Ray shadow = {p, to_l, 0.0f, 1.0f - 1e-4f};
                if (!P->shadows || !any_hit(&shadow))
                    radiance += contrib;
            }
            if (!WORKLOAD_PATH || depth >= P->bounces)
                break;
            /* Cosine-weighted diffuse bounce; the pdf cancels cos/pi, leaving the albedo. */
            u1 = RAND(2 * depth + 2, 0);
            u2 = RAND(2 * depth + 2, 1);
            r = f_sqrt(u1);
            f_sincos(TAU_F * u2, &sphi, &cphi);
            /* glam's any_orthonormal_pair (Duff et al. 2017) */
            float sign = f_signum(n.z);
            float a = -1.0f / (sign + n.z);
            float b = n.x * n.y * a;
            struct Vec3 t1 = v3(1.0f + sign * n.x * n.x * a, sign * b, -sign * n.x);
            struct Vec3 b1 = v3(b, sign + n.y * n.y * a, -n.y);
            struct Vec3 dir = v_add(v_add(v_scale(t1, r * cphi), v_scale(b1, r * sphi)),
                                    v_scale(n, f_sqrt(f_max(1.0f - u1, 0.0f))));
            throughput *= ALBEDO;
            ray.org = p;
            ray.dir = dir;
            ray.t_min = 0.0f;
            ray.t_max = __builtin_inff();
        }
    }
    return radiance / (float)(sample > 1 ? sample : 1);
}

void kernel_main(void)
{
    const struct Params *P = PARAMS;
    if (P->workload != WORKLOAD_PATH)
        kernel_fault(); /* the host loaded the other workload's kernel */
    uint32_t pixels = P->width * P->height;
    float *fb = (float *)(uintptr_t)P->frame_buffer;
    for (;;) {
        uint32_t i = rt_atominc(0);
        if (i >= pixels)
            break;
        float L = render_pixel(P, i % P->width, i / P->width);
        fb[3 * i + 0] = L;
        fb[3 * i + 1] = L;
        fb[3 * i + 2] = L;
    }
}
