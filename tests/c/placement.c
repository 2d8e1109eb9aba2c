/* Fluid starts calm wherever it is placed (docs/method.md §2.7), through the C API: the sweep
 * of tests/placement.rs. A 6 × 6 × 6 block is put 0, 0.5, 1, 1.5, 2 and 3 particle radii from
 * 1. the floor and two walls of a box of wall particles,
 * 2. the floor and two walls of a box whose walls are fields,
 * 3. the top face of a closed box mesh (a static obstacle),
 * 4. the top face of a static box body, and
 * 5. the top face of a kinematic box body at rest;
 * every particle is made (pf_world_last_added_count), and each of five CFL steps stays within
 * the iteration limit and 12 outer iterations, no particle is faster than a fall at twice
 * gravity plus 5 cm/s, the mean height does not rise, and no particle leaves the container or
 * sinks into the slab. Each case runs on one and on two threads, which must agree bit for bit.
 * 6. A 10 × 6 × 6 block overlapping the slab and the container's far wall: exactly the lattice
 *    centres inside the container and outside the slab are made, none inside the slab, and
 *    particles given one by one are filtered the same way.
 * Prints one line per solid and "placement: ok" last. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"

/* Particle radius r of every world here (m), the default. */
#define R 0.025
/* Blocks are this many particles along each axis. */
#define BLOCK 6
#define STEPS 5

typedef enum {
    WALL_PARTICLES,
    WALL_FIELDS,
    OBSTACLE,
    STATIC_BODY,
    KINEMATIC_BODY,
    SOLID_KINDS
} Against;

static const char *const against_name[SOLID_KINDS] = {
    "wall particles", "wall fields", "obstacle mesh", "static body", "kinematic body",
};

/* The solid box the block rests on where it is not the container: centre and half-extents. */
static const double slab_centre[3] = {0.5, 0.1, 0.3};
static const double slab_half[3] = {0.2, 0.1, 0.2};

/* The slab as a closed mesh: vertex i has the high x, y, z where bits 0, 1, 2 of i are set;
 * two triangles per face, wound so that their normals (right-hand rule) point outward. */
static const uint32_t slab_indices[36] = {
    0, 2, 3, 0, 3, 1, /* z = lo */
    4, 5, 7, 4, 7, 6, /* z = hi */
    0, 1, 5, 0, 5, 4, /* y = lo */
    2, 6, 7, 2, 7, 3, /* y = hi */
    0, 4, 6, 0, 6, 2, /* x = lo */
    1, 3, 7, 1, 7, 5, /* x = hi */
};

static void slab_vertices(float v[24]) {
    for (int i = 0; i < 8; i++)
        for (int a = 0; a < 3; a++)
            v[3 * i + a] = (float)(slab_centre[a] + ((i >> a) & 1 ? 1.0 : -1.0) * slab_half[a]);
}

/* Six times the volume the mesh encloses: positive when its triangles face outward. */
static double six_volume(const float v[24]) {
    double sum = 0.0;
    for (int t = 0; t < 12; t++) {
        const float *a = &v[3 * slab_indices[3 * t]], *b = &v[3 * slab_indices[3 * t + 1]],
                    *c = &v[3 * slab_indices[3 * t + 2]];
        sum += a[0] * ((double)b[1] * c[2] - (double)b[2] * c[1]) +
               a[1] * ((double)b[2] * c[0] - (double)b[0] * c[2]) +
               a[2] * ((double)b[0] * c[1] - (double)b[1] * c[0]);
    }
    return sum;
}

typedef struct {
    float min[3], max[3];
} Tank;

static Tank tank_of(Against against) {
    Tank t = {{0.0f, 0.0f, 0.0f}, {0.4f, 0.4f, 0.4f}};
    if (against != WALL_PARTICLES && against != WALL_FIELDS) {
        t.max[0] = 1.0f;
        t.max[1] = 0.8f;
        t.max[2] = 0.6f;
    }
    return t;
}

static int in_tank(const Tank *t, const double p[3]) {
    for (int a = 0; a < 3; a++)
        if (!(p[a] >= (double)t->min[a] && p[a] <= (double)t->max[a])) return 0;
    return 1;
}

/* How deep p lies inside the slab (m; negative outside), or 0 where the solid is the
 * container. */
static double depth_in_slab(Against against, const double p[3]) {
    if (against == WALL_PARTICLES || against == WALL_FIELDS) return 0.0;
    double depth = INFINITY;
    for (int a = 0; a < 3; a++) {
        double d = slab_half[a] - fabs(p[a] - slab_centre[a]);
        if (d < depth) depth = d;
    }
    return depth;
}

/* A world with the solid of `against` and an empty container, on `threads` threads. */
static PfWorld *solids(Against against, uint32_t threads) {
    PfParams params;
    OK(pf_params_default(&params));
    CHECK(params.particle_radius == R);
    params.threads = threads;
    PfWorld *w = NULL;
    OK(pf_world_create(&params, &w));
    CHECK(w != NULL);
    Tank tank = tank_of(against);
    if (against == WALL_FIELDS)
        OK(pf_world_add_container_field(w, tank.min, tank.max));
    else
        OK(pf_world_add_container_box(w, tank.min, tank.max, 1));
    if (against == OBSTACLE) {
        float v[24];
        slab_vertices(v);
        CHECK(six_volume(v) > 0.0);
        size_t before = 0, after = 0;
        OK(pf_world_boundary_count(w, &before));
        OK(pf_world_add_mesh(w, v, 8, slab_indices, 12));
        OK(pf_world_boundary_count(w, &after));
        CHECK(after > before);
    } else if (against == STATIC_BODY || against == KINEMATIC_BODY) {
        PfPose pose;
        OK(pf_pose_identity(&pose));
        memcpy(pose.position, slab_centre, sizeof pose.position);
        size_t id = 99, bodies = 0;
        int kind = against == STATIC_BODY ? PF_BODY_STATIC : PF_BODY_KINEMATIC;
        OK(pf_world_add_body_box(w, kind, slab_half, 0.0, &pose, &id));
        CHECK(id == 0);
        OK(pf_world_body_count(w, &bodies));
        CHECK(bodies == 1);
    }
    return w;
}

/* The first particle's centre of a block whose lowest layer lies `gap` (m) above the solid of
 * `against` (and, for the container, `gap` from two of its walls as well). */
static void block_start(Against against, double gap, float start[3]) {
    if (against == WALL_PARTICLES || against == WALL_FIELDS) {
        start[0] = start[1] = start[2] = (float)gap;
        return;
    }
    double width = (BLOCK - 1) * 2.0 * R;
    start[0] = (float)(slab_centre[0] - width / 2.0);
    start[1] = (float)(slab_centre[1] + slab_half[1] + gap);
    start[2] = (float)(slab_centre[2] - width / 2.0);
}

/* The fluid's positions and velocities, read into buffers of 3·n floats. */
static size_t read_state(const PfWorld *w, float **x, float **v) {
    size_t n = 0, needed = 0;
    OK(pf_world_fluid_count(w, &n));
    CHECK(n > 0);
    *x = malloc(3 * n * sizeof **x);
    *v = malloc(3 * n * sizeof **v);
    CHECK(*x != NULL && *v != NULL);
    OK(pf_world_get_positions(w, *x, 3 * n, &needed));
    CHECK(needed == 3 * n);
    OK(pf_world_get_velocities(w, *v, 3 * n, &needed));
    CHECK(needed == 3 * n);
    return n;
}

static double mean_height(const float *x, size_t n) {
    double sum = 0.0;
    for (size_t i = 0; i < n; i++) sum += x[3 * i + 1];
    return sum / (double)n;
}

/* The worst a solid kind saw over its cases. */
typedef struct {
    size_t outer;
    double fastest, fastest_over_bound, rise, depth;
} Worst;

/* Places the block `gap_r` radii from the solid of `against` on `threads` threads, takes five
 * steps, checks each and writes the final positions' digest to `hash`. */
static void place_and_check(Against against, double gap_r, uint32_t threads, Worst *worst,
                            char hash[65]) {
    PfWorld *w = solids(against, threads);
    float start[3];
    block_start(against, gap_r * R, start);
    const size_t count[3] = {BLOCK, BLOCK, BLOCK};
    OK(pf_world_add_fluid_box(w, start, count, NULL));
    size_t added = 0, fluid = 0;
    OK(pf_world_last_added_count(w, &added));
    OK(pf_world_fluid_count(w, &fluid));
    if (added != BLOCK * BLOCK * BLOCK || fluid != added)
        FAIL("%s, %.2f r, %u threads: %zu particles made, %zu fluid, expected %d",
             against_name[against], gap_r, threads, added, fluid, BLOCK * BLOCK * BLOCK);

    const Tank tank = tank_of(against);
    const double g = 9.81;
    float *x = NULL, *v = NULL;
    size_t n = read_state(w, &x, &v);
    const double start_height = mean_height(x, n);
    free(x);
    free(v);
    for (int step = 1; step <= STEPS; step++) {
        OK(pf_world_step(w, 0.0));
        PfStepStats st;
        OK(pf_world_last_step_stats(w, &st));
        CHECK(st.step_count == (uint64_t)step);
        /* Before placement settled new fluid, these steps took 200 outer iterations (the
         * limit, twice) and threw particles at 6–90 m/s. */
        if (st.hit_max_iterations || st.outer_iterations > 12)
            FAIL("%s, %.2f r, %u threads, step %d: %zu outer iterations%s",
                 against_name[against], gap_r, threads, step, st.outer_iterations,
                 st.hit_max_iterations ? ", iteration limit hit" : "");
        if (st.escaped_count != 0 || st.nan_count != 0)
            FAIL("%s, %.2f r, %u threads, step %d: %zu escaped, %zu not finite",
                 against_name[against], gap_r, threads, step, st.escaped_count, st.nan_count);
        if (st.outer_iterations > worst->outer) worst->outer = st.outer_iterations;

        n = read_state(w, &x, &v);
        CHECK(n == added);
        double fastest = 0.0;
        for (size_t i = 0; i < n; i++) {
            const float *u = &v[3 * i];
            double speed = sqrt((double)u[0] * u[0] + (double)u[1] * u[1] + (double)u[2] * u[2]);
            if (speed > fastest) fastest = speed;
        }
        /* A block resting on a solid collapses sideways under its own weight: no particle may
         * be faster than a fall at twice gravity, plus 5 cm/s. */
        double time = 0.0;
        OK(pf_world_time(w, &time));
        CHECK(time == st.time && time > 0.0);
        const double bound = 2.0 * g * time + 0.05;
        if (!(fastest <= bound))
            FAIL("%s, %.2f r, %u threads, step %d: %.6g m/s > %.6g m/s", against_name[against],
                 gap_r, threads, step, fastest, bound);
        if (fastest > worst->fastest) worst->fastest = fastest;
        if (fastest / bound > worst->fastest_over_bound) worst->fastest_over_bound = fastest / bound;
        const double height = mean_height(x, n);
        if (!(height <= start_height + 1e-4))
            FAIL("%s, %.2f r, %u threads, step %d: the centre of mass rose from %.9g m to %.9g m",
                 against_name[against], gap_r, threads, step, start_height, height);
        if (height - start_height > worst->rise) worst->rise = height - start_height;
        for (size_t i = 0; i < n; i++) {
            const double p[3] = {x[3 * i], x[3 * i + 1], x[3 * i + 2]};
            if (!in_tank(&tank, p))
                FAIL("%s, %.2f r, %u threads, step %d: particle %zu at (%.9g, %.9g, %.9g) left "
                     "the box",
                     against_name[against], gap_r, threads, step, i, p[0], p[1], p[2]);
            const double depth = depth_in_slab(against, p);
            if (!(depth < 0.2 * R))
                FAIL("%s, %.2f r, %u threads, step %d: particle %zu at (%.9g, %.9g, %.9g) lies "
                     "%.6g m inside the solid",
                     against_name[against], gap_r, threads, step, i, p[0], p[1], p[2], depth);
            if (depth > worst->depth) worst->depth = depth;
        }
        free(x);
        free(v);
    }
    OK(pf_world_positions_hash(w, hash, 65, NULL));
    CHECK(strlen(hash) == 64);
    pf_world_destroy(w);
}

/* A block overlapping the slab and the container's far wall: the particles whose centres lie
 * in a solid are not made, and the call counts those it made. */
static void overlap(Against against) {
    PfWorld *w = solids(against, 1);
    const Tank tank = tank_of(against);
    /* A 10 × 6 × 6 block whose first two columns lie inside the slab up to its third layer,
     * the third column on the slab's face, and whose last column reaches beyond the
     * container's far wall. The start is given in floats: 0.6f puts the ninth column, on the
     * wall in tests/placement.rs, 2.4e-8 m beyond it, so it is not made either (252 of 360
     * particles, 288 in Rust); the expected count follows the library's arithmetic. */
    const float start[3] = {
        (float)(slab_centre[0] + 0.1),
        (float)(slab_centre[1] + slab_half[1] - 0.12),
        (float)(slab_centre[2] - 0.1),
    };
    const size_t count[3] = {10, 6, 6};
    /* The lattice centres as the library computes them: start + (i, j, k)·2r in doubles. */
    const double d = 2.0 * R;
    size_t expected = 0;
    for (size_t k = 0; k < count[2]; k++)
        for (size_t j = 0; j < count[1]; j++)
            for (size_t i = 0; i < count[0]; i++) {
                const double p[3] = {
                    (double)start[0] + (double)i * d,
                    (double)start[1] + (double)j * d,
                    (double)start[2] + (double)k * d,
                };
                /* A centre on the slab's surface is not inside it. */
                if (in_tank(&tank, p) && depth_in_slab(against, p) <= 1e-12) expected++;
            }
    CHECK(expected > 0 && expected < 10 * 6 * 6 - 36);
    OK(pf_world_add_fluid_box(w, start, count, NULL));
    size_t added = 0, fluid = 0;
    OK(pf_world_last_added_count(w, &added));
    OK(pf_world_fluid_count(w, &fluid));
    if (added != expected || fluid != expected)
        FAIL("%s: %zu particles made, %zu fluid, %zu lattice centres outside the solids",
             against_name[against], added, fluid, expected);
    float *x = NULL, *v = NULL;
    size_t n = read_state(w, &x, &v);
    CHECK(n == expected);
    for (size_t i = 0; i < n; i++) {
        const double p[3] = {x[3 * i], x[3 * i + 1], x[3 * i + 2]};
        CHECK(v[3 * i] == 0.0f && v[3 * i + 1] == 0.0f && v[3 * i + 2] == 0.0f);
        if (!in_tank(&tank, p))
            FAIL("%s: particle %zu at (%.9g, %.9g, %.9g) outside the box", against_name[against],
                 i, p[0], p[1], p[2]);
        /* Inside counts from 1e-6 m beneath the surface (the library's surface tolerance). */
        if (depth_in_slab(against, p) > 1e-6)
            FAIL("%s: particle %zu at (%.9g, %.9g, %.9g) inside the solid",
                 against_name[against], i, p[0], p[1], p[2]);
    }
    free(x);
    free(v);
    /* Particles given one by one are filtered the same way. */
    const float two[6] = {
        (float)slab_centre[0], (float)slab_centre[1], (float)slab_centre[2],
        (float)slab_centre[0], (float)(slab_centre[1] + slab_half[1] + 0.2), (float)slab_centre[2],
    };
    OK(pf_world_add_fluid_particles(w, two, 2));
    OK(pf_world_last_added_count(w, &added));
    CHECK(added == 1);
    OK(pf_world_fluid_count(w, &fluid));
    CHECK(fluid == expected + 1);
    pf_world_destroy(w);
    printf("overlap %s: %zu of 360 made\n", against_name[against], expected);
}

int main(void) {
    static const double gaps[] = {0.0, 0.5, 1.0, 1.5, 2.0, 3.0};
    const int n_gaps = (int)(sizeof gaps / sizeof gaps[0]);
    for (int s = 0; s < SOLID_KINDS; s++) {
        Against against = (Against)s;
        Worst worst = {0, 0.0, 0.0, -INFINITY, -INFINITY};
        for (int gi = 0; gi < n_gaps; gi++) {
            char one[65], two[65];
            place_and_check(against, gaps[gi], 1, &worst, one);
            place_and_check(against, gaps[gi], 2, &worst, two);
            if (strcmp(one, two) != 0)
                FAIL("%s, %.1f r: one and two threads differ (%s vs %s)", against_name[against],
                     gaps[gi], one, two);
        }
        printf("%s: %d gaps x 1 and 2 threads, worst outer iterations %zu, fastest %.4f m/s "
               "(%.0f%% of the bound), mean height change at most %+.3g m",
               against_name[against], n_gaps, worst.outer, worst.fastest,
               100.0 * worst.fastest_over_bound, worst.rise);
        if (against == WALL_PARTICLES || against == WALL_FIELDS)
            printf("\n");
        else
            printf(", nearest the slab %.2f r\n", -worst.depth / R);
    }
    overlap(OBSTACLE);
    overlap(STATIC_BODY);
    overlap(KINEMATIC_BODY);
    printf("placement: ok\n");
    return 0;
}
