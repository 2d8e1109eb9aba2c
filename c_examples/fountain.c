/* A fountain through the projfluid C API: a disc emitter 1 m above the floor of a
 * 1 m x 1.2 m x 1 m basin pours water straight down at 2 m/s into a shallow pool, and a
 * drain, a sink box over one corner of the floor, removes the water that reaches it.
 * Prints the emitted, removed and fluid particle counts every 0.1 s.
 *
 * Build (static):  cc -std=c11 -O2 -I include c_examples/fountain.c \
 *                      target/release/libprojfluid.a -lm -lpthread -ldl -o fountain
 * Usage: fountain [seconds]   (default 1) */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>

#include "projfluid.h"

/* Prints the last error and exits when a call fails. */
static void check(PfStatus status, const char *what) {
    if (status != PF_OK) {
        fprintf(stderr, "fountain: %s failed with %s: %s\n", what, pf_status_name((int)status),
                pf_last_error_message());
        exit(1);
    }
}

int main(int argc, char **argv) {
    double seconds = argc > 1 ? atof(argv[1]) : 1.0;
    PfParams params;
    check(pf_params_default(&params), "pf_params_default"); /* r = 0.025 m */
    PfWorld *world = NULL;
    check(pf_world_create(&params, &world), "pf_world_create");

    /* The basin, its walls two layers thick (one lets the jet push a particle through the
     * floor) r/4 outside the nominal box, and a pool 0.2 m deep. */
    const float lo[3] = {-0.00625f, -0.00625f, -0.00625f};
    const float hi[3] = {1.00625f, 1.20625f, 1.00625f};
    check(pf_world_add_container_box(world, lo, hi, 2), "pf_world_add_container_box");
    const float start[3] = {0.05f, 0.05f, 0.05f};
    const size_t count[3] = {19, 4, 19};
    check(pf_world_add_fluid_box(world, start, count, NULL), "pf_world_add_fluid_box");

    /* The fountain: a disc of radius 0.1 m pouring down at 2 m/s, forever (INFINITY). */
    const double nozzle[3] = {0.5, 1.0, 0.5}, down[3] = {0.0, -1.0, 0.0};
    size_t emitter = 0, drain = 0;
    check(pf_world_add_emitter_disc(world, nozzle, down, 0.1, 2.0, INFINITY, &emitter),
          "pf_world_add_emitter_disc");
    /* The drain over the corner at the origin, reaching below the floor. */
    const double drain_lo[3] = {-0.1, -0.1, -0.1}, drain_hi[3] = {0.2, 0.15, 0.2};
    check(pf_world_add_sink(world, drain_lo, drain_hi, &drain), "pf_world_add_sink");
    /* Anything that leaves the basin would be removed too. */
    const double dom_lo[3] = {-0.1, -0.1, -0.1}, dom_hi[3] = {1.1, 1.3, 1.1};
    check(pf_world_set_domain(world, dom_lo, dom_hi), "pf_world_set_domain");

    size_t fluid = 0;
    check(pf_world_fluid_count(world, &fluid), "pf_world_fluid_count");
    printf("fountain: %zu fluid particles in the pool, emitter %zu, drain %zu, %.2f s "
           "(projfluid %s)\n",
           fluid, emitter, drain, seconds, pf_version_string());

    uint64_t emitted = 0, removed = 0;
    double t = 0.0;
    while (t < seconds - 1e-9) {
        double span = fmin(0.1, seconds - t);
        check(pf_world_advance(world, span), "pf_world_advance");
        check(pf_world_time(world, &t), "pf_world_time");
        check(pf_world_emitted_count(world, &emitted), "pf_world_emitted_count");
        check(pf_world_removed_count(world, &removed), "pf_world_removed_count");
        check(pf_world_fluid_count(world, &fluid), "pf_world_fluid_count");
        printf("t = %.2f s  emitted %6llu  removed %6llu  fluid %6zu\n", t,
               (unsigned long long)emitted, (unsigned long long)removed, fluid);
    }

    PfStepStats stats;
    check(pf_world_last_step_stats(world, &stats), "pf_world_last_step_stats");
    printf("final: steps %llu, emitted %llu, removed %llu, fluid %zu, escaped %zu, nan %zu\n",
           (unsigned long long)stats.step_count, (unsigned long long)emitted,
           (unsigned long long)removed, fluid, stats.escaped_count, stats.nan_count);
    pf_world_destroy(world);
    return stats.escaped_count == 0 && stats.nan_count == 0 ? 0 : 1;
}
