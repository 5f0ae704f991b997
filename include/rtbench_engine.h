/*
 * rtbench_engine.h — the C ABI of rtbench engine plugins, version 1.
 *
 * A plugin is a shared library (.so) that exports two functions:
 *
 *   uint32_t rtbench_engine_abi_version(void);        returns RTBENCH_ENGINE_ABI_VERSION
 *   const rtb_plugin *rtbench_engine_plugin(void);    returns the plugin's function table
 *
 * rtbench loads it with `--engines plugin:PATH[:key=value...]` (or `plugin:NAME`, looked up as
 * NAME, libNAME.so or NAME.so in $RTBENCH_PLUGIN_DIR, else ./plugins). It calls
 * rtbench_engine_abi_version() first and refuses the plugin unless the numbers are equal; only
 * then does it call rtbench_engine_plugin(). The table must stay valid until the library is
 * unloaded (a `static const` table is the usual way).
 *
 * Everything here is plain C99: fixed-size integers, floats, pointers. No allocation crosses the
 * boundary: rtbench owns the arrays it passes, the plugin owns its engine.
 *
 * Threads: rtbench calls `intersect` and `occluded` on one engine from several threads at once
 * (each call with its own arrays and counters). They must not modify shared engine state.
 * `build` and `destroy` are never called concurrently with anything else on that engine.
 *
 * What rtbench checks: every hit a plugin returns must have a finite t inside the ray's open
 * interval (tmin, tmax) and a primitive id below the number of primitives passed; a hit that
 * breaks this fails the run with a one-line reason (the results of that run are discarded). A
 * plugin that crashes takes down only its own run: each run executes in a child process.
 */
#ifndef RTBENCH_ENGINE_H
#define RTBENCH_ENGINE_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* The version of this header. Changed whenever a struct or a signature below changes. */
#define RTBENCH_ENGINE_ABI_VERSION 1u

/* Primitive kinds, as bits of rtb_plugin.prim_kinds. Triangles are mandatory. Polygons are
 * always given as triangles (rtbench cuts them exactly by ear clipping, as for every engine).
 * A plugin that does not set RTB_PRIM_SPHERES (or RTB_PRIM_CONES) gets those primitives
 * tessellated into triangles; rtbench reports how many and the geometric error (build stats
 * `tessellated_spheres`, `tessellated_cones`, `tessellation_max_error`). */
#define RTB_PRIM_TRIANGLES 1u
#define RTB_PRIM_SPHERES 2u
#define RTB_PRIM_CONES 4u

/* Id of "no hit" in rtb_hit.prim. */
#define RTB_MISS 0xFFFFFFFFu

/* One ray: points org + t*dir for tmin < t < tmax (an open interval). dir is not necessarily
 * unit length; tmax may be +infinity. 32 bytes, the layout rtbench uses internally (so batches
 * are passed without copying). */
typedef struct rtb_ray {
    float org[3]; /* origin x, y, z */
    float tmin;   /* lower end of the interval (exclusive) */
    float dir[3]; /* direction x, y, z */
    float tmax;   /* upper end of the interval (exclusive); may be INFINITY */
} rtb_ray;

/* One closest hit. For a miss set prim = RTB_MISS (t, u, v are then ignored). */
typedef struct rtb_hit {
    float t;       /* ray parameter of the hit, tmin < t < tmax */
    uint32_t prim; /* primitive id (see rtb_scene), or RTB_MISS */
    float u;       /* triangles: barycentric weight of vertex 1 (b); 0 for other kinds */
    float v;       /* triangles: barycentric weight of vertex 2 (c); 0 for other kinds */
} rtb_hit;

/* A key=value setting from the command line (`plugin:PATH:leaf=4` gives key "leaf", value "4").
 * Both strings are NUL-terminated and valid only during build(). */
typedef struct rtb_setting {
    const char *key;
    const char *value;
} rtb_setting;

/* The scene rtbench passes to build(). All arrays are valid only during build(): copy what
 * you need. Primitive ids number the triangles first, then the spheres, then the cones:
 *   triangle i  -> id i
 *   sphere j    -> id triangle_count + j
 *   cone k      -> id triangle_count + sphere_count + k
 * sphere_count (cone_count) is 0 unless the plugin takes spheres (cones). */
typedef struct rtb_scene {
    uint32_t triangle_count;
    const float *triangles; /* 9 floats each: a.xyz, b.xyz, c.xyz */
    uint32_t sphere_count;
    const float *spheres;   /* 4 floats each: center.xyz, radius */
    uint32_t cone_count;
    const float *cones;     /* 8 floats each: base.xyz, base radius, apex.xyz, apex radius;
                               an open cone (no caps); radii may be equal (a cylinder) */
    float bounds_min[3];    /* bounds of all primitives */
    float bounds_max[3];
    uint32_t setting_count; /* settings not used by rtbench itself */
    const rtb_setting *settings;
} rtb_scene;

/* The plugin's function table. */
typedef struct rtb_plugin {
    /* RTBENCH_ENGINE_ABI_VERSION again: checked a second time against the table itself. */
    uint32_t abi_version;
    /* Name and version of the engine, NUL-terminated, static (e.g. "c-bvh", "1.0"). */
    const char *name;
    const char *version;
    /* Bits RTB_PRIM_*: which primitive kinds build() accepts. RTB_PRIM_TRIANGLES must be set. */
    uint32_t prim_kinds;
    /* Names of the plugin's counters (static strings, counter_count of them). rtbench passes
     * every query call an array of counter_count uint64_t, zeroed, and adds them up over calls
     * and threads. Names "nodes_visited", "box_tests", "primitive_tests", "primitive_hits" fill
     * rtbench's common counters; any other name is reported as an engine counter. May be 0/NULL. */
    uint32_t counter_count;
    const char *const *counter_names;

    /* Builds the acceleration structure. Returns an opaque engine, or NULL with a NUL-terminated
     * one-line reason written to error (at most error_len bytes including the NUL), e.g. for an
     * unknown setting. */
    void *(*build)(const rtb_scene *scene, char *error, size_t error_len);
    /* Closest hit of each of the count rays: hits[i] for rays[i]. */
    void (*intersect)(const void *engine, const rtb_ray *rays, rtb_hit *hits, size_t count,
                      uint64_t *counters);
    /* Any hit: occluded[i] = 1 if some primitive lies in (tmin, tmax) of rays[i], else 0. */
    void (*occluded)(const void *engine, const rtb_ray *rays, uint8_t *occluded, size_t count,
                     uint64_t *counters);
    /* Bytes of the acceleration structure (nodes, index lists, the plugin's own copy of the
     * geometry if it keeps one). */
    uint64_t (*structure_bytes)(const void *engine);
    /* Frees the engine. */
    void (*destroy)(void *engine);
} rtb_plugin;

/* The two exported entry points (declared here so a plugin's definitions are checked). */
#if defined(_WIN32)
#define RTB_EXPORT __declspec(dllexport)
#else
#define RTB_EXPORT __attribute__((visibility("default")))
#endif
RTB_EXPORT uint32_t rtbench_engine_abi_version(void);
RTB_EXPORT const rtb_plugin *rtbench_engine_plugin(void);

#ifdef __cplusplus
}
#endif

#endif /* RTBENCH_ENGINE_H */
