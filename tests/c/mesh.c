/* A closed box given as a triangle mesh (8 vertices, 12 triangles, mixed winding) is added as
 * an obstacle inside a container; a block of water falls onto it. Checks that the mesh
 * became boundary particles (reproducibly), that no fluid escapes the container or ends up
 * inside the obstacle, and that nothing turns non-finite.
 * Usage: mesh [seconds]   (default 0.25; the valgrind run uses less) */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>

#include "check.h"

/* The obstacle: a box from (0.2, 0.1, 0.2) to (0.4, 0.2, 0.4) m. */
static const float lo_obs[3] = {0.2f, 0.1f, 0.2f}, hi_obs[3] = {0.4f, 0.2f, 0.4f};

static void box_vertices(float v[24]) {
    for (int i = 0; i < 8; i++) {
        v[3 * i + 0] = (i & 1) ? hi_obs[0] : lo_obs[0];
        v[3 * i + 1] = (i & 2) ? hi_obs[1] : lo_obs[1];
        v[3 * i + 2] = (i & 4) ? hi_obs[2] : lo_obs[2];
    }
}

/* Two triangles per face; the faces are wound inconsistently on purpose. */
static const uint32_t box_indices[36] = {
    0, 1, 3, 3, 2, 0, /* z = lo */
    4, 6, 7, 7, 5, 4, /* z = hi */
    0, 4, 5, 5, 1, 0, /* y = lo */
    2, 3, 7, 7, 6, 2, /* y = hi */
    0, 6, 2, 0, 4, 6, /* x = lo */
    1, 3, 7, 7, 5, 1, /* x = hi */
};

static PfWorld *make_world(size_t *boundary_before, size_t *boundary_after) {
    PfParams params;
    OK(pf_params_default(&params));
    params.threads = 2;
    PfWorld *w = NULL;
    OK(pf_world_create(&params, &w));
    const float lo[3] = {0.0f, 0.0f, 0.0f}, hi[3] = {0.6f, 0.6f, 0.6f};
    OK(pf_world_add_container_box(w, lo, hi, 1));
    OK(pf_world_boundary_count(w, boundary_before));
    float v[24];
    box_vertices(v);
    OK(pf_world_add_mesh(w, v, 8, box_indices, 12));
    OK(pf_world_boundary_count(w, boundary_after));
    /* Water above the obstacle, wider than it, so that some flows around it. */
    const float start[3] = {0.15f, 0.3f, 0.15f};
    const size_t count[3] = {7, 3, 7};
    OK(pf_world_add_fluid_box(w, start, count, NULL));
    return w;
}

int main(int argc, char **argv) {
    double seconds = argc > 1 ? atof(argv[1]) : 0.25;

    size_t before = 0, after = 0;
    PfWorld *w = make_world(&before, &after);
    /* The surface is 0.16 m²; with r = 0.025 m Poisson-disk sampling gives roughly
     * 0.6 samples per r², about 150 particles (at most about 0.16 / (pi r^2 / 4) + edges). */
    size_t added = after - before;
    CHECK(after > before);
    CHECK(added > 100 && added < 400);

    /* The same mesh gives the same particles in another world. */
    size_t before2 = 0, after2 = 0;
    PfWorld *w2 = make_world(&before2, &after2);
    CHECK(before2 == before && after2 == after);
    pf_world_destroy(w2);

    OK(pf_world_advance(w, seconds));
    PfStepStats st;
    OK(pf_world_last_step_stats(w, &st));
    CHECK(st.step_count > 0);
    CHECK(st.escaped_count == 0 && st.nan_count == 0);

    size_t n = 0;
    OK(pf_world_fluid_count(w, &n));
    CHECK(n == 7 * 3 * 7);
    float *pos = malloc(3 * n * sizeof *pos);
    CHECK(pos != NULL);
    OK(pf_world_get_positions(w, pos, 3 * n, NULL));
    /* No particle inside the obstacle (deeper than r/2 below its surface). */
    const float margin = 0.0125f;
    size_t inside = 0, on_top = 0;
    float lowest = INFINITY;
    for (size_t i = 0; i < n; i++) {
        const float *p = pos + 3 * i;
        int in = 1;
        for (int a = 0; a < 3; a++) {
            CHECK(isfinite(p[a]));
            in = in && p[a] > lo_obs[a] + margin && p[a] < hi_obs[a] - margin;
        }
        inside += (size_t)in;
        on_top += (size_t)(p[0] > lo_obs[0] && p[0] < hi_obs[0] && p[2] > lo_obs[2] &&
                           p[2] < hi_obs[2] && p[1] > hi_obs[1]);
        if (p[1] < lowest) lowest = p[1];
    }
    if (inside != 0) FAIL("%zu fluid particles ended up inside the obstacle", inside);
    /* Something rests on the obstacle. When simulated long enough, water also flowed past it. */
    CHECK(on_top > 0);
    if (seconds >= 0.25) CHECK(lowest < lo_obs[1]);

    printf("mesh: ok, %zu boundary particles from the mesh, %zu fluid, %zu on top, "
           "t = %.3f s\n",
           added, n, on_top, st.time);
    free(pos);
    pf_world_destroy(w);
    return 0;
}
