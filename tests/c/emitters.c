/* Emitters, sinks, the domain and removal by id through the C API.
 * 1. A disc and a rectangular emitter pour into a basin with a pool and a drain (a sink):
 *    the emitted count grows, the sink removes particles, and fluid = initial + emitted −
 *    removed throughout; removal by id takes the named particles only.
 * 2. Every kind of misuse is rejected with its status and a message naming the argument,
 *    changing nothing (counts, time, positions bit for bit, the next index given).
 * Prints "emitters: ok N" with N the number of rejected calls checked. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "check.h"

typedef struct {
    size_t fluid;
    uint64_t emitted, removed;
    double time;
    char hash[65];
} Snapshot;

static Snapshot snapshot(const PfWorld *w) {
    Snapshot s;
    OK(pf_world_fluid_count(w, &s.fluid));
    OK(pf_world_emitted_count(w, &s.emitted));
    OK(pf_world_removed_count(w, &s.removed));
    OK(pf_world_time(w, &s.time));
    OK(pf_world_positions_hash(w, s.hash, sizeof s.hash, NULL));
    return s;
}

static int rejected = 0;

/* A rejected call: expected status, a message naming `word`, and no change to the world. */
#define REJECT(w, expected, word, call)                                                   \
    do {                                                                                  \
        Snapshot before_ = snapshot(w);                                                   \
        EXPECT(expected, call);                                                           \
        if (strstr(pf_last_error_message(), (word)) == NULL)                              \
            FAIL("%s: the message does not name %s", #call, (word));                      \
        Snapshot now_ = snapshot(w);                                                      \
        if (now_.fluid != before_.fluid || now_.emitted != before_.emitted ||             \
            now_.removed != before_.removed || now_.time != before_.time ||               \
            strcmp(now_.hash, before_.hash) != 0)                                         \
            FAIL("%s changed the world", #call);                                          \
        rejected++;                                                                       \
    } while (0)

/* fluid = initial + emitted − removed (removal by id counts as removed). */
static void balanced(const PfWorld *w, size_t initial) {
    Snapshot s = snapshot(w);
    CHECK((uint64_t)s.fluid + s.removed == (uint64_t)initial + s.emitted);
}

static void misuse(PfWorld *w) {
    const double pos[3] = {0.5, 1.0, 0.5}, down[3] = {0.0, -1.0, 0.0};
    const double nan3[3] = {0.1, NAN, 0.1}, zero[3] = {0.0, 0.0, 0.0};
    const double lo[3] = {0.0, 0.0, 0.0}, hi[3] = {0.2, 0.15, 0.2};
    const double inverted[3] = {0.2, -0.15, 0.2};
    size_t id = 99;
    const int null = PF_ERROR_NULL_POINTER, bad = PF_ERROR_INVALID_ARGUMENT;

    /* Emitters. */
    REJECT(w, null, "world", pf_world_add_emitter_disc(NULL, pos, down, 0.1, 2.0, 0.0, &id));
    REJECT(w, null, "position", pf_world_add_emitter_disc(w, NULL, down, 0.1, 2.0, 0.0, &id));
    REJECT(w, null, "direction", pf_world_add_emitter_disc(w, pos, NULL, 0.1, 2.0, 0.0, &id));
    REJECT(w, null, "out_id", pf_world_add_emitter_disc(w, pos, down, 0.1, 2.0, 0.0, NULL));
    REJECT(w, bad, "position", pf_world_add_emitter_disc(w, nan3, down, 0.1, 2.0, 0.0, &id));
    REJECT(w, bad, "direction", pf_world_add_emitter_disc(w, pos, nan3, 0.1, 2.0, 0.0, &id));
    REJECT(w, bad, "direction", pf_world_add_emitter_disc(w, pos, zero, 0.1, 2.0, 0.0, &id));
    const double speeds[] = {0.0, -1.0, NAN, INFINITY};
    for (int i = 0; i < 4; i++)
        REJECT(w, bad, "speed", pf_world_add_emitter_disc(w, pos, down, 0.1, speeds[i], 0.0, &id));
    REJECT(w, bad, "end_time", pf_world_add_emitter_disc(w, pos, down, 0.1, 2.0, NAN, &id));
    const double radii[] = {0.0, -0.1, NAN, INFINITY};
    for (int i = 0; i < 4; i++)
        REJECT(w, bad, "radius", pf_world_add_emitter_disc(w, pos, down, radii[i], 2.0, 0.0, &id));
    REJECT(w, bad, "zero area", pf_world_add_emitter_disc(w, pos, down, 0.01, 2.0, 0.0, &id));
    REJECT(w, bad, "half_a", pf_world_add_emitter_rect(w, pos, down, 0.0, 0.1, 2.0, 0.0, &id));
    REJECT(w, bad, "half_b", pf_world_add_emitter_rect(w, pos, down, 0.1, NAN, 2.0, 0.0, &id));
    REJECT(w, bad, "zero area", pf_world_add_emitter_rect(w, pos, down, 0.01, 0.1, 2.0, 0.0, &id));
    REJECT(w, bad, "speed", pf_world_add_emitter_rect(w, pos, down, 0.1, 0.1, -2.0, 0.0, &id));
    REJECT(w, null, "world", pf_world_add_emitter_rect(NULL, pos, down, 0.1, 0.1, 2.0, 0.0, &id));
    REJECT(w, null, "out_id", pf_world_add_emitter_rect(w, pos, down, 0.1, 0.1, 2.0, 0.0, NULL));
    CHECK(id == 99);

    /* Sinks and the domain. */
    REJECT(w, null, "world", pf_world_add_sink(NULL, lo, hi, &id));
    REJECT(w, null, "min", pf_world_add_sink(w, NULL, hi, &id));
    REJECT(w, null, "max", pf_world_add_sink(w, lo, NULL, &id));
    REJECT(w, null, "out_id", pf_world_add_sink(w, lo, hi, NULL));
    REJECT(w, bad, "min", pf_world_add_sink(w, nan3, hi, &id));
    REJECT(w, bad, "max", pf_world_add_sink(w, lo, inverted, &id));
    REJECT(w, null, "world", pf_world_set_domain(NULL, lo, hi));
    REJECT(w, null, "min", pf_world_set_domain(w, NULL, hi));
    REJECT(w, bad, "max", pf_world_set_domain(w, lo, nan3));
    REJECT(w, bad, "max", pf_world_set_domain(w, lo, inverted));
    REJECT(w, null, "world", pf_world_clear_domain(NULL));
    CHECK(id == 99);

    /* Removal by id and the counts. */
    size_t removed = 99, fluid = 0;
    OK(pf_world_fluid_count(w, &fluid));
    uint64_t *ids = malloc(fluid * sizeof *ids);
    CHECK(ids != NULL);
    OK(pf_world_get_ids(w, ids, fluid, NULL));
    const uint64_t twice[2] = {ids[1], ids[1]}, unknown[1] = {UINT64_C(1) << 40};
    REJECT(w, null, "world", pf_world_remove_particles(NULL, ids, 1, &removed));
    REJECT(w, null, "ids", pf_world_remove_particles(w, NULL, 1, &removed));
    REJECT(w, null, "removed", pf_world_remove_particles(w, ids, 1, NULL));
    REJECT(w, bad, "ids", pf_world_remove_particles(w, twice, 2, &removed));
    REJECT(w, bad, "ids", pf_world_remove_particles(w, unknown, 1, &removed));
    CHECK(removed == 99);
    uint64_t count = 0;
    REJECT(w, null, "world", pf_world_emitted_count(NULL, &count));
    REJECT(w, null, "out", pf_world_emitted_count(w, NULL));
    REJECT(w, null, "world", pf_world_removed_count(NULL, &count));
    REJECT(w, null, "out", pf_world_removed_count(w, NULL));
    /* Nothing to remove is fine; a removed id cannot be removed again. */
    OK(pf_world_remove_particles(w, NULL, 0, &removed));
    CHECK(removed == 0);
    OK(pf_world_remove_particles(w, ids, 1, &removed));
    CHECK(removed == 1);
    REJECT(w, bad, "removed already", pf_world_remove_particles(w, ids, 1, &removed));
    free(ids);
}

int main(void) {
    PfParams params;
    OK(pf_params_default(&params));
    params.threads = 2;
    PfWorld *w = NULL;
    OK(pf_world_create(&params, &w));
    const float lo[3] = {-0.00625f, -0.00625f, -0.00625f};
    const float hi[3] = {1.00625f, 1.20625f, 1.00625f};
    OK(pf_world_add_container_box(w, lo, hi, 1));
    const float start[3] = {0.05f, 0.05f, 0.05f};
    const size_t pool[3] = {19, 3, 19};
    OK(pf_world_add_fluid_box(w, start, pool, NULL));
    size_t initial = 0;
    OK(pf_world_fluid_count(w, &initial));

    misuse(w);

    const double pos[3] = {0.5, 1.0, 0.5}, down[3] = {0.0, -1.0, 0.0};
    const double side[3] = {0.3, 0.9, 0.5}, right[3] = {1.0, 0.0, 0.0};
    size_t disc = 99, rect = 99, sink = 99;
    OK(pf_world_add_emitter_disc(w, pos, down, 0.1, 2.0, INFINITY, &disc));
    OK(pf_world_add_emitter_rect(w, side, right, 0.05, 0.1, 1.0, 0.1, &rect));
    CHECK(disc == 0 && rect == 1);
    const double drain_lo[3] = {-0.1, -0.1, -0.1}, drain_hi[3] = {0.2, 0.15, 0.2};
    OK(pf_world_add_sink(w, drain_lo, drain_hi, &sink));
    CHECK(sink == 0);
    const double dom_lo[3] = {-0.1, -0.1, -0.1}, dom_hi[3] = {1.1, 1.3, 1.1};
    OK(pf_world_set_domain(w, dom_lo, dom_hi));
    OK(pf_world_clear_domain(w));
    OK(pf_world_set_domain(w, dom_lo, dom_hi));
    balanced(w, initial);

    uint64_t emitted = 0, last = 0, removed = 0;
    for (int k = 1; k <= 4; k++) {
        OK(pf_world_advance(w, 0.05));
        OK(pf_world_emitted_count(w, &emitted));
        CHECK(emitted > last);
        last = emitted;
        balanced(w, initial);
    }
    OK(pf_world_removed_count(w, &removed));
    CHECK(removed > 1);
    PfStepStats stats;
    OK(pf_world_last_step_stats(w, &stats));
    CHECK(stats.escaped_count == 0 && stats.nan_count == 0);

    /* Removal by id takes exactly the particles named. */
    size_t fluid = 0, n = 0;
    OK(pf_world_fluid_count(w, &fluid));
    uint64_t *ids = malloc(fluid * sizeof *ids);
    CHECK(ids != NULL);
    OK(pf_world_get_ids(w, ids, fluid, NULL));
    const uint64_t doomed[3] = {ids[fluid - 1], ids[0], ids[fluid / 2]};
    OK(pf_world_remove_particles(w, doomed, 3, &n));
    CHECK(n == 3);
    OK(pf_world_fluid_count(w, &n));
    CHECK(n == fluid - 3);
    OK(pf_world_get_ids(w, ids, fluid, NULL));
    for (size_t i = 0; i < n; i++)
        CHECK(ids[i] != doomed[0] && ids[i] != doomed[1] && ids[i] != doomed[2]);
    free(ids);
    balanced(w, initial);

    pf_world_destroy(w);
    printf("emitters: ok %d rejected calls checked\n", rejected);
    return 0;
}
