/*
 * c-bvh: a small BVH as an rtbench engine plugin (include/rtbench_engine.h, ABI version 1).
 *
 * Binary BVH over triangles and spheres (cones are tessellated by rtbench), built top-down with
 * a 16-bin SAH, leaves of at most `leaf` primitives (setting leaf=N, default 4); traversal with a
 * stack, nearer child first. Triangles: Moller-Trumbore. Counters: nodes_visited,
 * primitive_tests.
 *
 * Build by hand:
 *   cc -O2 -shared -fPIC -Iinclude examples/c-bvh/bvh.c -o libc_bvh.so -lm
 * The tests build it with the `cc` crate, and also build faulty variants of it
 * (-DRTB_FAULT_NAN, _SEGV, _ID, _T, _ABI, _BARY, _PRIM0, _STDOUT, _ESC) to check that rtbench
 * catches each fault.
 */
#include "rtbench_engine.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct {
    float lo[3], hi[3];
    uint32_t first; /* inner: left child (right = first + 1); leaf: first index into order */
    uint32_t count; /* 0: inner node */
} node;

typedef struct {
    uint32_t ntri, nsph;
    float *tri; /* 9 per triangle */
    float *sph; /* 4 per sphere */
    uint32_t *order;
    node *nodes;
    uint32_t nnodes;
    uint32_t leaf;
} bvh;

typedef struct {
    float lo[3], hi[3], c[3];
} pbox;

static void prim_box(const bvh *b, uint32_t id, pbox *o) {
    int k;
    if (id < b->ntri) {
        const float *t = b->tri + 9 * (size_t)id;
        for (k = 0; k < 3; k++) {
            float x = t[k], y = t[3 + k], z = t[6 + k];
            o->lo[k] = fminf(x, fminf(y, z));
            o->hi[k] = fmaxf(x, fmaxf(y, z));
        }
    } else {
        const float *s = b->sph + 4 * (size_t)(id - b->ntri);
        for (k = 0; k < 3; k++) {
            o->lo[k] = s[k] - s[3];
            o->hi[k] = s[k] + s[3];
        }
    }
    for (k = 0; k < 3; k++) o->c[k] = 0.5f * (o->lo[k] + o->hi[k]);
}

static float area(const float *lo, const float *hi) {
    float d0 = hi[0] - lo[0], d1 = hi[1] - lo[1], d2 = hi[2] - lo[2];
    if (d0 < 0 || d1 < 0 || d2 < 0) return 0;
    return d0 * d1 + d1 * d2 + d2 * d0;
}

#define BINS 16

static void build_node(bvh *b, const pbox *boxes, uint32_t ni, uint32_t first, uint32_t count,
                       int depth) {
    node *n = &b->nodes[ni];
    float clo[3] = {INFINITY, INFINITY, INFINITY}, chi[3] = {-INFINITY, -INFINITY, -INFINITY};
    uint32_t i;
    int k;
    for (k = 0; k < 3; k++) {
        n->lo[k] = INFINITY;
        n->hi[k] = -INFINITY;
    }
    for (i = first; i < first + count; i++) {
        const pbox *p = &boxes[b->order[i]];
        for (k = 0; k < 3; k++) {
            n->lo[k] = fminf(n->lo[k], p->lo[k]);
            n->hi[k] = fmaxf(n->hi[k], p->hi[k]);
            clo[k] = fminf(clo[k], p->c[k]);
            chi[k] = fmaxf(chi[k], p->c[k]);
        }
    }
    n->first = first;
    n->count = count;
    if (count <= b->leaf || depth >= 60) return; /* depth 60 bounds the traversal stack */
    /* 16-bin SAH over the axes. */
    float best = INFINITY;
    int best_axis = -1, best_split = 0;
    for (k = 0; k < 3; k++) {
        float ext = chi[k] - clo[k];
        if (!(ext > 0)) continue;
        uint32_t cnt[BINS] = {0};
        float blo[BINS][3], bhi[BINS][3];
        int j, m;
        for (j = 0; j < BINS; j++)
            for (m = 0; m < 3; m++) {
                blo[j][m] = INFINITY;
                bhi[j][m] = -INFINITY;
            }
        for (i = first; i < first + count; i++) {
            const pbox *p = &boxes[b->order[i]];
            int bin = (int)((p->c[k] - clo[k]) / ext * BINS);
            if (bin >= BINS) bin = BINS - 1;
            if (bin < 0) bin = 0;
            cnt[bin]++;
            for (m = 0; m < 3; m++) {
                blo[bin][m] = fminf(blo[bin][m], p->lo[m]);
                bhi[bin][m] = fmaxf(bhi[bin][m], p->hi[m]);
            }
        }
        /* Sweep from the right, then from the left. */
        float right_area[BINS];
        uint32_t right_cnt[BINS];
        float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
        uint32_t c = 0;
        for (j = BINS - 1; j > 0; j--) {
            for (m = 0; m < 3; m++) {
                lo[m] = fminf(lo[m], blo[j][m]);
                hi[m] = fmaxf(hi[m], bhi[j][m]);
            }
            c += cnt[j];
            right_area[j] = area(lo, hi);
            right_cnt[j] = c;
        }
        for (m = 0; m < 3; m++) {
            lo[m] = INFINITY;
            hi[m] = -INFINITY;
        }
        c = 0;
        for (j = 0; j < BINS - 1; j++) {
            for (m = 0; m < 3; m++) {
                lo[m] = fminf(lo[m], blo[j][m]);
                hi[m] = fmaxf(hi[m], bhi[j][m]);
            }
            c += cnt[j];
            if (c == 0 || right_cnt[j + 1] == 0) continue;
            float cost = area(lo, hi) * c + right_area[j + 1] * right_cnt[j + 1];
            if (cost < best) {
                best = cost;
                best_axis = k;
                best_split = j + 1;
            }
        }
    }
    uint32_t mid;
    if (best_axis < 0) return; /* all centroids equal: one leaf */
    if (best >= area(n->lo, n->hi) * count && count <= 4 * b->leaf) return; /* no split pays */
    {
        float ext = chi[best_axis] - clo[best_axis];
        uint32_t l = first, r = first + count;
        while (l < r) {
            const pbox *p = &boxes[b->order[l]];
            int bin = (int)((p->c[best_axis] - clo[best_axis]) / ext * BINS);
            if (bin >= BINS) bin = BINS - 1;
            if (bin < best_split) {
                l++;
            } else {
                uint32_t t = b->order[l];
                b->order[l] = b->order[--r];
                b->order[r] = t;
            }
        }
        mid = l;
    }
    if (mid == first || mid == first + count) return;
    uint32_t left = b->nnodes;
    b->nnodes += 2;
    n->first = left;
    n->count = 0;
    build_node(b, boxes, left, first, mid - first, depth + 1);
    build_node(b, boxes, left + 1, mid, first + count - mid, depth + 1);
}

static void *bvh_build(const rtb_scene *s, char *error, size_t error_len) {
    uint32_t i, leaf = 4;
#if defined(RTB_FAULT_STDOUT)
    printf("c-bvh: building");
#elif defined(RTB_FAULT_ESC)
    snprintf(error, error_len, "\033[31mred\033[0m failure\a");
    return NULL;
#endif
    for (i = 0; i < s->setting_count; i++) {
        if (strcmp(s->settings[i].key, "leaf") == 0) {
            int v = atoi(s->settings[i].value);
            if (v < 1 || v > 64) {
                snprintf(error, error_len, "leaf=%s: expected 1..64", s->settings[i].value);
                return NULL;
            }
            leaf = (uint32_t)v;
        } else {
            snprintf(error, error_len, "unknown setting '%s' (known: leaf)", s->settings[i].key);
            return NULL;
        }
    }
    bvh *b = calloc(1, sizeof *b);
    if (!b) return NULL;
    b->ntri = s->triangle_count;
    b->nsph = s->sphere_count;
    b->leaf = leaf;
    uint32_t n = b->ntri + b->nsph;
    b->tri = malloc(sizeof(float) * 9 * (size_t)(b->ntri ? b->ntri : 1));
    b->sph = malloc(sizeof(float) * 4 * (size_t)(b->nsph ? b->nsph : 1));
    b->order = malloc(sizeof(uint32_t) * (size_t)(n ? n : 1));
    b->nodes = malloc(sizeof(node) * (size_t)(2 * n + 1));
    pbox *boxes = malloc(sizeof(pbox) * (size_t)(n ? n : 1));
    if (!b->tri || !b->sph || !b->order || !b->nodes || !boxes) {
        snprintf(error, error_len, "out of memory for %u primitives", n);
        free(boxes);
        free(b->tri);
        free(b->sph);
        free(b->order);
        free(b->nodes);
        free(b);
        return NULL;
    }
    if (b->ntri) memcpy(b->tri, s->triangles, sizeof(float) * 9 * (size_t)b->ntri);
    if (b->nsph) memcpy(b->sph, s->spheres, sizeof(float) * 4 * (size_t)b->nsph);
    for (i = 0; i < n; i++) {
        b->order[i] = i;
        prim_box(b, i, &boxes[i]);
    }
    b->nnodes = 1;
    if (n == 0) {
        int k;
        for (k = 0; k < 3; k++) {
            b->nodes[0].lo[k] = INFINITY;
            b->nodes[0].hi[k] = -INFINITY;
        }
        b->nodes[0].first = 0;
        b->nodes[0].count = 0;
        /* An inner node with no children would be read; mark as an empty leaf instead. */
        b->nodes[0].count = 0xFFFFFFFFu;
    } else {
        build_node(b, boxes, 0, 0, n, 0);
    }
    free(boxes);
    return b;
}

static int hit_tri(const float *t, const rtb_ray *r, float tmax, float *ot, float *ou,
                   float *ov) {
    float e1[3], e2[3], p[3], q[3], s[3];
    int k;
    for (k = 0; k < 3; k++) {
        e1[k] = t[3 + k] - t[k];
        e2[k] = t[6 + k] - t[k];
        s[k] = r->org[k] - t[k];
    }
    p[0] = r->dir[1] * e2[2] - r->dir[2] * e2[1];
    p[1] = r->dir[2] * e2[0] - r->dir[0] * e2[2];
    p[2] = r->dir[0] * e2[1] - r->dir[1] * e2[0];
    float det = e1[0] * p[0] + e1[1] * p[1] + e1[2] * p[2];
    if (det == 0.0f) return 0;
    float inv = 1.0f / det;
    float u = (s[0] * p[0] + s[1] * p[1] + s[2] * p[2]) * inv;
    if (u < 0.0f || u > 1.0f) return 0;
    q[0] = s[1] * e1[2] - s[2] * e1[1];
    q[1] = s[2] * e1[0] - s[0] * e1[2];
    q[2] = s[0] * e1[1] - s[1] * e1[0];
    float v = (r->dir[0] * q[0] + r->dir[1] * q[1] + r->dir[2] * q[2]) * inv;
    if (v < 0.0f || u + v > 1.0f) return 0;
    float tt = (e2[0] * q[0] + e2[1] * q[1] + e2[2] * q[2]) * inv;
    if (!(tt > r->tmin && tt < tmax)) return 0;
    *ot = tt;
    *ou = u;
    *ov = v;
    return 1;
}

static int hit_sphere(const float *s, const rtb_ray *r, float tmax, float *ot) {
    float oc[3] = {r->org[0] - s[0], r->org[1] - s[1], r->org[2] - s[2]};
    float a = r->dir[0] * r->dir[0] + r->dir[1] * r->dir[1] + r->dir[2] * r->dir[2];
    float hb = oc[0] * r->dir[0] + oc[1] * r->dir[1] + oc[2] * r->dir[2];
    float c = oc[0] * oc[0] + oc[1] * oc[1] + oc[2] * oc[2] - s[3] * s[3];
    float disc = hb * hb - a * c;
    if (disc < 0.0f || a == 0.0f) return 0;
    float sq = sqrtf(disc);
    float t0 = (-hb - sq) / a, t1 = (-hb + sq) / a;
    if (t0 > r->tmin && t0 < tmax) {
        *ot = t0;
        return 1;
    }
    if (t1 > r->tmin && t1 < tmax) {
        *ot = t1;
        return 1;
    }
    return 0;
}

static int slab(const node *n, const float *o, const float *inv, float tmin, float tmax,
                float *tnear) {
    int k;
    for (k = 0; k < 3; k++) {
        float t0 = (n->lo[k] - o[k]) * inv[k], t1 = (n->hi[k] - o[k]) * inv[k];
        if (t0 > t1) {
            float x = t0;
            t0 = t1;
            t1 = x;
        }
        /* NaN (0 * inf) keeps the old bounds: fmaxf/fminf ignore a NaN argument. */
        tmin = fmaxf(tmin, t0);
        tmax = fminf(tmax, t1 * 1.00000024f);
    }
    *tnear = tmin;
    return tmin <= tmax;
}

/* any = 1: stop at the first hit. Returns 1 if hit. */
static int trace(const bvh *b, const rtb_ray *r, int any, rtb_hit *out, uint64_t *ctr) {
    float inv[3];
    int k;
    for (k = 0; k < 3; k++) inv[k] = 1.0f / r->dir[k];
    float best = r->tmax;
    uint32_t best_id = RTB_MISS;
    float bu = 0, bv = 0;
    uint32_t stack[128];
    int sp = 0;
    float tn;
    if (b->nodes[0].count == 0xFFFFFFFFu) return 0;
    if (!slab(&b->nodes[0], r->org, inv, r->tmin, best, &tn)) return 0;
    stack[sp++] = 0;
    while (sp > 0) {
        const node *n = &b->nodes[stack[--sp]];
        ctr[0]++;
        if (n->count > 0) {
            uint32_t i;
            for (i = n->first; i < n->first + n->count; i++) {
                uint32_t id = b->order[i];
                float t, u = 0, v = 0;
                int h;
                ctr[1]++;
                if (id < b->ntri)
                    h = hit_tri(b->tri + 9 * (size_t)id, r, best, &t, &u, &v);
                else
                    h = hit_sphere(b->sph + 4 * (size_t)(id - b->ntri), r, best, &t);
                if (h) {
                    best = t;
                    best_id = id;
                    bu = u;
                    bv = v;
                    if (any) {
                        out->t = best;
                        out->prim = best_id;
                        return 1;
                    }
                }
            }
            continue;
        }
        const node *l = &b->nodes[n->first], *rr = &b->nodes[n->first + 1];
        float tl, tr;
        int hl = slab(l, r->org, inv, r->tmin, best, &tl);
        int hr = slab(rr, r->org, inv, r->tmin, best, &tr);
        if (hl && hr) {
            if (tl <= tr) {
                stack[sp++] = n->first + 1;
                stack[sp++] = n->first;
            } else {
                stack[sp++] = n->first;
                stack[sp++] = n->first + 1;
            }
        } else if (hl) {
            stack[sp++] = n->first;
        } else if (hr) {
            stack[sp++] = n->first + 1;
        }
    }
    out->t = best;
    out->prim = best_id;
    out->u = bu;
    out->v = bv;
    return best_id != RTB_MISS;
}

static void bvh_intersect(const void *e, const rtb_ray *rays, rtb_hit *hits, size_t count,
                          uint64_t *ctr) {
    const bvh *b = e;
    size_t i;
    for (i = 0; i < count; i++) {
        hits[i].prim = RTB_MISS;
        hits[i].t = INFINITY;
        hits[i].u = hits[i].v = 0;
        trace(b, &rays[i], 0, &hits[i], ctr);
#if defined(RTB_FAULT_NAN)
        if (hits[i].prim != RTB_MISS) hits[i].t = NAN;
#elif defined(RTB_FAULT_ID)
        if (hits[i].prim != RTB_MISS) hits[i].prim = b->ntri + b->nsph + 5;
#elif defined(RTB_FAULT_T)
        if (hits[i].prim != RTB_MISS) hits[i].t = rays[i].tmin - 1.0f;
#elif defined(RTB_FAULT_SEGV)
        if (i == count / 2) *(volatile int *)0 = 1;
#elif defined(RTB_FAULT_BARY)
        if (hits[i].prim != RTB_MISS) hits[i].u = i % 2 ? INFINITY : 1e30f;
#elif defined(RTB_FAULT_PRIM0)
        if (hits[i].prim != RTB_MISS) hits[i].prim = 0;
#elif defined(RTB_FAULT_STDOUT)
        if (i == 0) printf("c-bvh: %zu rays\n", count);
#endif
    }
}

static void bvh_occluded(const void *e, const rtb_ray *rays, uint8_t *occ, size_t count,
                         uint64_t *ctr) {
    const bvh *b = e;
    size_t i;
    for (i = 0; i < count; i++) {
        rtb_hit h;
        occ[i] = (uint8_t)trace(b, &rays[i], 1, &h, ctr);
    }
}

static uint64_t bvh_bytes(const void *e) {
    const bvh *b = e;
    return (uint64_t)b->nnodes * sizeof(node) + (uint64_t)(b->ntri + b->nsph) * 4 +
           (uint64_t)b->ntri * 36 + (uint64_t)b->nsph * 16;
}

static void bvh_destroy(void *e) {
    bvh *b = e;
    if (!b) return;
    free(b->tri);
    free(b->sph);
    free(b->order);
    free(b->nodes);
    free(b);
}

static const char *const counter_names[] = {"nodes_visited", "primitive_tests"};

static const rtb_plugin plugin = {
    RTBENCH_ENGINE_ABI_VERSION,
    "c-bvh",
    "1.0",
    RTB_PRIM_TRIANGLES | RTB_PRIM_SPHERES,
    2,
    counter_names,
    bvh_build,
    bvh_intersect,
    bvh_occluded,
    bvh_bytes,
    bvh_destroy,
};

RTB_EXPORT uint32_t rtbench_engine_abi_version(void) {
#ifdef RTB_FAULT_ABI
    return RTBENCH_ENGINE_ABI_VERSION + 98u;
#else
    return RTBENCH_ENGINE_ABI_VERSION;
#endif
}

RTB_EXPORT const rtb_plugin *rtbench_engine_plugin(void) { return &plugin; }
