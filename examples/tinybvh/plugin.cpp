/*
 * tinybvh as an rtbench engine plugin (include/rtbench_engine.h, ABI version 1).
 *
 * tinybvh (J. Bikker, MIT licence) is a single C++ header. This file is compiled against the copy
 * of the header that the `tinybvh-rs` crate ships (build.sh finds it through `cargo metadata`),
 * with AVX2 and FMA enabled for this library alone: the rest of rtbench keeps its own code
 * generation. rtbench's `tinybvh` engine loads the result.
 *
 * Settings:
 *   layout   bvh8_cpu (default) | bvh4_cpu | cwbvh | bvh
 *            bvh8_cpu: 8-wide nodes, AVX2 traversal, 4-triangle SoA leaves (Fuetterling et al.,
 *                      "Accelerated Single Ray Tracing for Wide Vector Units", HPG 2017)
 *            bvh4_cpu: 4-wide nodes, SSE traversal
 *            cwbvh:    compressed wide BVH8 (Ylitie, Karras and Laine 2017), tinybvh's CPU
 *                      traversal; it has no any-hit query, so occluded() runs a closest-hit one
 *            bvh:      tinybvh's binary BVH ("Wald" layout), scalar traversal
 *   quality  default | hq   (hq: tinybvh's spatial-split builder, BuildHQ)
 *
 * Rays: tinybvh has no tmin, and treats t > 0 as in front. A ray is passed from org + tmin*dir
 * with the interval (0, tmax - tmin), and the hit's t is shifted back (kept inside the open
 * interval against rounding). The direction is passed as it is, not normalised, so t is
 * rtbench's parameter. Rays with a non-finite origin or direction, or an empty interval, miss.
 *
 * tinybvh counts nothing in its release traversal: the plugin reports no counters.
 */
#define TINYBVH_IMPLEMENTATION
#include "tiny_bvh.h"

#include "rtbench_engine.h"

#include <cmath>
#include <cstdio>
#include <cstring>
#include <new>
#include <vector>

namespace {

enum class Layout { Bvh8Cpu, Bvh4Cpu, Cwbvh, Bvh };

struct Engine {
    Layout layout = Layout::Bvh8Cpu;
    // tinybvh may keep a view of the vertices (refitting, the binary BVH's traversal): they live
    // as long as the engine.
    std::vector<tinybvh::bvhvec4> verts;
    tinybvh::BVH8_CPU *bvh8 = nullptr;
    tinybvh::BVH4_CPU *bvh4 = nullptr;
    tinybvh::BVH8_CWBVH *cwbvh = nullptr;
    tinybvh::BVH *bvh = nullptr;
    uint64_t bytes = 0;

    ~Engine() {
        delete bvh8;
        delete bvh4;
        delete cwbvh;
        delete bvh;
    }
    bool empty() const { return verts.empty(); }
};

void say(char *error, size_t len, const char *msg) {
    if (error && len > 0) std::snprintf(error, len, "%s", msg);
}

bool finite3(const float *v) {
    return std::isfinite(v[0]) && std::isfinite(v[1]) && std::isfinite(v[2]);
}

/* The ray in tinybvh's form, from org + tmin*dir; false if it cannot hit anything. Only the
 * fields the traversals read are set (no memset of the whole ray: it is per-ray cost that the
 * comparison with the other engines would charge to tinybvh). */
bool to_tiny(const rtb_ray &r, tinybvh::Ray &out) {
    if (!finite3(r.org) || !finite3(r.dir) || std::isnan(r.tmin) || std::isnan(r.tmax) ||
        !(r.tmin < r.tmax) || (r.dir[0] == 0.0f && r.dir[1] == 0.0f && r.dir[2] == 0.0f))
        return false;
    const float t0 = r.tmin > 0.0f ? r.tmin : 0.0f;
    out.O = tinybvh::bvhvec3(r.org[0] + t0 * r.dir[0], r.org[1] + t0 * r.dir[1],
                             r.org[2] + t0 * r.dir[2]);
    out.D = tinybvh::bvhvec3(r.dir[0], r.dir[1], r.dir[2]);
    out.rD = tinybvh::tinybvh_rcp(out.D);
    out.mask = RAY_MASK_INTERSECT_ALL;
    out.instIdx = 0;
    const float span = r.tmax - t0;
    out.hit.t = span < BVH_FAR ? span : BVH_FAR;
    out.hit.prim = RTB_MISS;
    out.hit.u = out.hit.v = 0.0f;
    return true;
}

size_t node_bytes(const Engine &e) {
    switch (e.layout) {
    case Layout::Bvh8Cpu:
        return (size_t)e.bvh8->usedBlocks * 16;
    case Layout::Bvh4Cpu:
        return (size_t)e.bvh4->usedBlocks * 16;
    case Layout::Cwbvh:
        return (size_t)e.cwbvh->usedBlocks * 16 + (size_t)e.cwbvh->idxCount * 3 * 16;
    case Layout::Bvh:
        return (size_t)e.bvh->usedNodes * sizeof(tinybvh::BVH::BVHNode) +
               (size_t)e.bvh->idxCount * 4;
    }
    return 0;
}

void *build(const rtb_scene *scene, char *error, size_t error_len) {
    Layout layout = Layout::Bvh8Cpu;
    bool hq = false;
    for (uint32_t i = 0; i < scene->setting_count; i++) {
        const char *k = scene->settings[i].key, *v = scene->settings[i].value;
        if (std::strcmp(k, "layout") == 0) {
            if (std::strcmp(v, "bvh8_cpu") == 0) layout = Layout::Bvh8Cpu;
            else if (std::strcmp(v, "bvh4_cpu") == 0) layout = Layout::Bvh4Cpu;
            else if (std::strcmp(v, "cwbvh") == 0) layout = Layout::Cwbvh;
            else if (std::strcmp(v, "bvh") == 0) layout = Layout::Bvh;
            else {
                say(error, error_len, "layout: expected bvh8_cpu, bvh4_cpu, cwbvh or bvh");
                return nullptr;
            }
        } else if (std::strcmp(k, "quality") == 0) {
            if (std::strcmp(v, "hq") == 0) hq = true;
            else if (std::strcmp(v, "default") == 0) hq = false;
            else {
                say(error, error_len, "quality: expected default or hq");
                return nullptr;
            }
        } else {
            char msg[160];
            std::snprintf(msg, sizeof msg, "unknown setting '%s' (layout, quality)", k);
            say(error, error_len, msg);
            return nullptr;
        }
    }
    Engine *e = new (std::nothrow) Engine();
    if (!e) {
        say(error, error_len, "out of memory");
        return nullptr;
    }
    e->layout = layout;
    const uint32_t n = scene->triangle_count;
    // tinybvh builds nothing over no triangles (its builders index the first one): an empty
    // scene is an engine that misses every ray.
    if (n == 0) return e;
    e->verts.resize((size_t)n * 3);
    for (size_t i = 0; i < (size_t)n * 3; i++) {
        const float *p = scene->triangles + 3 * i;
        e->verts[i] = tinybvh::bvhvec4(p[0], p[1], p[2], 0.0f);
    }
    const tinybvh::bvhvec4 *v = e->verts.data();
    switch (layout) {
    case Layout::Bvh8Cpu:
        e->bvh8 = new tinybvh::BVH8_CPU();
        if (hq) e->bvh8->BuildHQ(v, n);
        else e->bvh8->Build(v, n);
        break;
    case Layout::Bvh4Cpu:
        e->bvh4 = new tinybvh::BVH4_CPU();
        if (hq) e->bvh4->BuildHQ(v, n);
        else e->bvh4->Build(v, n);
        break;
    case Layout::Cwbvh:
        e->cwbvh = new tinybvh::BVH8_CWBVH();
        if (hq) e->cwbvh->BuildHQ(v, n);
        else e->cwbvh->Build(v, n);
        break;
    case Layout::Bvh:
        e->bvh = new tinybvh::BVH();
        if (hq) e->bvh->BuildHQ(v, n);
        else e->bvh->Build(v, n);
        break;
    }
    e->bytes = node_bytes(*e) + e->verts.size() * sizeof(tinybvh::bvhvec4);
    return e;
}

/* Closest hit of one ray (tinybvh's ray, already set up); hit.t < the initial t if found. */
void closest(const Engine &e, tinybvh::Ray &r) {
    switch (e.layout) {
    case Layout::Bvh8Cpu:
        e.bvh8->Intersect(r);
        break;
    case Layout::Bvh4Cpu:
        e.bvh4->Intersect(r);
        break;
    case Layout::Cwbvh:
        e.cwbvh->Intersect(r);
        break;
    case Layout::Bvh:
        e.bvh->Intersect(r);
        break;
    }
}

bool any(const Engine &e, const tinybvh::Ray &r) {
    switch (e.layout) {
    case Layout::Bvh8Cpu:
        return e.bvh8->IsOccluded(r);
    case Layout::Bvh4Cpu:
        return e.bvh4->IsOccluded(r);
    case Layout::Cwbvh:
        return e.cwbvh->IsOccluded(r);
    case Layout::Bvh:
        return e.bvh->IsOccluded(r);
    }
    return false;
}

void intersect(const void *engine, const rtb_ray *rays, rtb_hit *hits, size_t count,
               uint64_t *) {
    const Engine &e = *static_cast<const Engine *>(engine);
    for (size_t i = 0; i < count; i++) {
        const rtb_ray &q = rays[i];
        hits[i].prim = RTB_MISS;
        hits[i].t = 0.0f;
        hits[i].u = hits[i].v = 0.0f;
        tinybvh::Ray r;
        if (e.empty() || !to_tiny(q, r)) continue;
        const float start = r.hit.t;
        closest(e, r);
        if (!(r.hit.t < start) || r.hit.prim >= e.verts.size() / 3) continue;
        const float t0 = q.tmin > 0.0f ? q.tmin : 0.0f;
        float t = t0 + r.hit.t;
        // The shift back may round onto an end of the open interval.
        if (!(t > q.tmin)) t = std::nextafter(q.tmin, INFINITY);
        if (!(t < q.tmax)) t = std::nextafter(q.tmax, -INFINITY);
        if (!(t > q.tmin)) continue;
        hits[i].t = t;
        hits[i].prim = r.hit.prim;
        hits[i].u = r.hit.u;
        hits[i].v = r.hit.v;
    }
}

void occluded(const void *engine, const rtb_ray *rays, uint8_t *occ, size_t count, uint64_t *) {
    const Engine &e = *static_cast<const Engine *>(engine);
    for (size_t i = 0; i < count; i++) {
        tinybvh::Ray r;
        occ[i] = (!e.empty() && to_tiny(rays[i], r) && any(e, r)) ? 1 : 0;
    }
}

uint64_t structure_bytes(const void *engine) {
    return static_cast<const Engine *>(engine)->bytes;
}

void destroy(void *engine) { delete static_cast<Engine *>(engine); }

#define STR2(x) #x
#define STR(x) STR2(x)
const char VERSION[] = STR(TINY_BVH_VERSION_MAJOR) "." STR(TINY_BVH_VERSION_MINOR) "." STR(
    TINY_BVH_VERSION_SUB);

const rtb_plugin TABLE = {
    RTBENCH_ENGINE_ABI_VERSION,
    "tinybvh",
    VERSION,
    RTB_PRIM_TRIANGLES,
    0,
    nullptr,
    build,
    intersect,
    occluded,
    structure_bytes,
    destroy,
};

} // namespace

extern "C" {
RTB_EXPORT uint32_t rtbench_engine_abi_version(void) { return RTBENCH_ENGINE_ABI_VERSION; }
RTB_EXPORT const rtb_plugin *rtbench_engine_plugin(void) { return &TABLE; }
}
